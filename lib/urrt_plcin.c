/* SPDX-License-Identifier: MIT */
/* urrt_plcin.c: see urrt_plcin.h. */
#include "urrt_plcin.h"

void urrt_plcin_init(urrt_plcin *p)
{
    if (p != 0) {
        p->rx_us = 0;
        p->sent_us = 0;
        p->session = 0;
        p->ever = false;
        p->fresh = false;
        p->changed = false;
    }
}

/* Microseconds from then to now; 0 for a now before then (a caller's write
 * stamped later than its loop's clock is not in the past). */
static uint64_t since(uint64_t now_us, uint64_t then_us)
{
    return now_us > then_us ? now_us - then_us : 0;
}

bool urrt_plcin_raws(const urrt_plcin_desc *d, const uint8_t *data, unsigned len, bool fd, uint64_t *raws)
{
    size_t i;
    if (d == 0 || data == 0 || raws == 0 || len != d->len || fd != ((d->flags & URRT_CANTX_FD) != 0) ||
        d->signal_count > URRT_PLCIN_MAX_SIGNALS) {
        return false;
    }
    for (i = 0; i < d->signal_count; i++) {
        raws[i] = 0;
        if (urrt_can_get_raw(&d->signals[i], data, len, &raws[i]) != 0) {
            return false;
        }
    }
    return true;
}

enum take { TAKEN, REFUSED, ABSENT };

static enum take none(urrt_rtde_in *in, size_t k, enum take why)
{
    urrt_rtde_in_unset(in, k);
    return why;
}

/* Register k (d->regs[k]) from the signals that write it. */
static enum take take_register(const urrt_plcin_desc *d, urrt_rtde_in *in, size_t k, const uint64_t *raws,
                               uint64_t absent)
{
    uint64_t word = 0;
    double value = 0;
    bool mask = false;
    size_t i;
    for (i = 0; i < d->signal_count; i++) {
        const urrt_can_signal *sig = &d->signals[i];
        if (d->vars[i] != d->regs[k]) {
            continue;
        }
        if (i < 64u && (absent >> i & 1u) != 0) {
            return none(in, k, ABSENT);
        }
        if ((sig->flags & URRT_CAN_SIG_BITMASK) != 0) {
            uint64_t bits = sig->length >= 64u ? raws[i] : raws[i] & ((UINT64_C(1) << sig->length) - 1u);
            unsigned first = URRT_CAN_SIG_MASK_FIRST(sig->flags);
            mask = true;
            word |= first < 64u ? bits << first : 0u;
            continue;
        }
        value = urrt_can_from_raw(sig, raws[i]);
        if (!(value >= sig->min) || !(value <= sig->max)) {
            return none(in, k, REFUSED);
        }
    }
    if (mask) {
        /* The bit-register words are UINT32: a mask past bit 31 is refused there. */
        return urrt_rtde_in_set_int(in, k, word > (uint64_t)INT64_MAX ? -1 : (int64_t)word) == URRT_OK ? TAKEN
                                                                                                       : REFUSED;
    }
    return urrt_rtde_in_set_double(in, k, value) == URRT_OK ? TAKEN : REFUSED;
}

static bool given(const urrt_rtde_in *in, size_t k)
{
    return ((unsigned)in->given[k / 8u] >> (k % 8u) & 1u) != 0;
}

/* Register k from raws: whether its value changed, came or went. */
static bool take_changed(const urrt_plcin_desc *d, urrt_rtde_in *in, size_t k, const uint64_t *raws,
                         uint64_t absent, size_t *refused)
{
    size_t at = in->offset[k];
    size_t end = k + 1u < in->count ? in->offset[k + 1u] : in->data_size;
    uint8_t before[8];
    bool had = given(in, k);
    bool same = true;
    size_t b;
    for (b = 0; b < end - at && b < sizeof before; b++) {
        before[b] = in->data[at + b];
    }
    *refused += take_register(d, in, k, raws, absent) == REFUSED;
    for (b = 0; b < end - at && b < sizeof before; b++) {
        same = same && before[b] == in->data[at + b];
    }
    return had != given(in, k) || (given(in, k) && !same);
}

size_t urrt_plcin_take(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in, const uint64_t *raws,
                       uint64_t absent, uint64_t at_us)
{
    size_t refused = 0;
    bool changed = false;
    size_t k;
    if (d == 0 || p == 0 || in == 0 || raws == 0 || d->reg_count != in->count) {
        return 0;
    }
    for (k = 0; k < d->reg_count; k++) {
        changed = take_changed(d, in, k, raws, absent, &refused) || changed;
    }
    /* A package is news when a value changed, came or went, or the PLC was silent. */
    p->changed = p->changed || changed || !p->fresh;
    p->ever = true;
    p->fresh = true;
    p->rx_us = at_us;
    return refused;
}

bool urrt_plcin_timed_out(const urrt_plcin_desc *d, const urrt_plcin *p, uint64_t now_us)
{
    return d != 0 && p != 0 && p->fresh && since(now_us, p->rx_us) > (uint64_t)d->timeout_ms * 1000u;
}

void urrt_plcin_silent(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in)
{
    size_t k;
    if (d == 0 || p == 0 || !p->fresh) {
        return;
    }
    p->fresh = false;
    if (in == 0) {
        return;
    }
    if (d->silence == URRT_PLCIN_STOP) {
        urrt_rtde_in_forget(in);
    } else if (d->silence == URRT_PLCIN_VALUE) {
        for (k = 0; k < in->count; k++) {
            (void)urrt_rtde_in_set_double(in, k, d->silence_value); /* one every register takes: the desc's promise */
        }
        p->changed = true;
    }
}

bool urrt_plcin_writing(const urrt_plcin_desc *d, const urrt_plcin *p)
{
    return d != 0 && p != 0 && p->ever && (p->fresh || d->silence != URRT_PLCIN_STOP);
}

bool urrt_plcin_due(const urrt_plcin_desc *d, const urrt_plcin *p, bool ready, uint32_t session, uint64_t now_us,
                    uint64_t period_us)
{
    if (!ready || !urrt_plcin_writing(d, p)) {
        return false;
    }
    return p->changed || session != p->session || since(now_us, p->sent_us) >= period_us;
}

void urrt_plcin_sent(urrt_plcin *p, bool ok, uint32_t session, uint64_t now_us)
{
    if (p == 0) {
        return;
    }
    p->sent_us = now_us;
    if (ok) {
        p->session = session;
        p->changed = false;
    }
}

uint64_t urrt_plcin_deadline(const urrt_plcin_desc *d, const urrt_plcin *p, bool ready, uint64_t period_us)
{
    uint64_t due = URRT_CANTX_NEVER;
    if (d == 0 || p == 0) {
        return due;
    }
    if (p->fresh) {
        uint64_t timeout = p->rx_us + (uint64_t)d->timeout_ms * 1000u;
        due = timeout < due ? timeout : due;
    }
    if (ready && urrt_plcin_writing(d, p)) {
        uint64_t refresh = p->sent_us + period_us;
        due = refresh < due ? refresh : due;
    }
    return due;
}
