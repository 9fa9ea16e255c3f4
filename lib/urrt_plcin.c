/* SPDX-License-Identifier: MIT */
/* urrt_plcin.c: see urrt_plcin.h. */
#include "urrt_plcin.h"

#include "urrt_double_internal.h"

void urrt_plcin_init(urrt_plcin *p)
{
    if (p != 0) {
        p->rx_us = 0;
        p->seen_us = URRT_CANTX_NEVER;
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

/* A double's bits: compared as integers, a Cortex-M4 does no floating-point
 * arithmetic in software for it. */
typedef union {
    double d;
    uint64_t u;
} bits_of;

/* The integer a signal's raw value stands for when its scaling is the
 * identity (factor 1, offset 0, an integer raw type): the physical value is
 * the raw integer itself (sign-extended), with no scaling to compute; false
 * for any other signal, and for an unsigned 64-bit raw past INT64_MAX. */
static bool identity_value(const urrt_can_signal *sig, uint64_t raw, int64_t *v)
{
    bits_of factor, offset;
    uint64_t sign;
    factor.d = sig->factor;
    offset.d = sig->offset;
    if (factor.u != UINT64_C(0x3FF0000000000000) || (offset.u << 1) != 0u || sig->length == 0u ||
        sig->length > 64u || (sig->type != URRT_CAN_UNSIGNED && sig->type != URRT_CAN_SIGNED)) {
        return false;
    }
    if (sig->length <= 32u) {
        /* The usual signal, in 32-bit arithmetic: (r ^ sign) - sign sign-extends
         * a signed one without a conversion the standard leaves open. */
        uint32_t r = (uint32_t)raw & (UINT32_MAX >> (32u - sig->length));
        uint32_t sign32 = UINT32_C(1) << (sig->length - 1u);
        *v = sig->type == URRT_CAN_SIGNED ? (int64_t)(r ^ sign32) - (int64_t)sign32 : (int64_t)r;
        return true;
    }
    if (sig->length < 64u) {
        raw &= (UINT64_C(1) << sig->length) - 1u;
        sign = UINT64_C(1) << (sig->length - 1u);
        if (sig->type == URRT_CAN_SIGNED && (raw & sign) != 0u) {
            raw |= ~((UINT64_C(1) << sig->length) - 1u);
        }
    } else if (sig->type == URRT_CAN_UNSIGNED && raw > (uint64_t)INT64_MAX) {
        return false;
    }
    *v = (int64_t)raw;
    return true;
}

/* v within the signal's min..max: compared as integers where a limit is an
 * integer (the usual case), as doubles where it is not. */
static bool within(const urrt_can_signal *sig, int64_t v)
{
    bits_of lo, hi;
    int64_t l, h;
    bool above, below;
    lo.d = sig->min;
    hi.d = sig->max;
    above = urrt_int_of_double_bits(lo.u, &l) ? v >= l : (double)v >= sig->min;
    below = urrt_int_of_double_bits(hi.u, &h) ? v <= h : (double)v <= sig->max;
    return above && below;
}

/* Bit i of absent (none past 63), from one 32-bit half: a 64-bit shift by
 * a variable amount is several instructions on a 32-bit core. */
static bool absent_bit(uint64_t absent, size_t i)
{
    uint32_t half = i < 32u ? (uint32_t)absent : (uint32_t)(absent >> 32);
    return i < 64u && (half >> (i % 32u) & 1u) != 0u;
}

/* A bit-mask signal's bits in the register's word: its raw shifted up by
 * its first bit; in 32-bit arithmetic when they end by bit 31 (a bit
 * register word, the usual case), as 64-bit shifts by a variable amount
 * are several instructions each on a 32-bit core. */
static uint64_t mask_bits(const urrt_can_signal *sig, uint64_t raw)
{
    unsigned first = URRT_CAN_SIG_MASK_FIRST(sig->flags);
    uint64_t bits;
    if (sig->length >= 1u && first + sig->length <= 32u) {
        return (uint64_t)(((uint32_t)raw & (UINT32_MAX >> (32u - sig->length))) << first);
    }
    bits = sig->length >= 64u ? raw : raw & ((UINT64_C(1) << sig->length) - 1u);
    return first < 64u ? bits << first : 0u;
}

static enum take none(urrt_rtde_in *in, size_t k, enum take why)
{
    urrt_rtde_in_unset(in, k);
    return why;
}

static enum take set_int(urrt_rtde_in *in, size_t k, int64_t v)
{
    return urrt_rtde_in_set_int(in, k, v) == URRT_OK ? TAKEN : REFUSED;
}

/* A bit mask's word: the bit-register words are UINT32, so that a mask past
 * bit 31 is refused there. */
static enum take set_mask(urrt_rtde_in *in, size_t k, uint64_t word)
{
    return set_int(in, k, word > (uint64_t)INT64_MAX ? -1 : (int64_t)word);
}

/* Register k (d->regs[k]) from signal i alone: an input in register order
 * (in_register_order), the usual one. take_register's rules for a
 * register one signal writes, without its gathering over the signals. */
static enum take take_one(const urrt_plcin_desc *d, urrt_rtde_in *in, size_t k, size_t i, const uint64_t *raws,
                          uint64_t absent)
{
    const urrt_can_signal *sig = &d->signals[i];
    int64_t whole;
    double value;
    if (absent_bit(absent, i)) {
        return none(in, k, ABSENT);
    }
    if ((sig->flags & URRT_CAN_SIG_BITMASK) != 0) {
        return set_mask(in, k, mask_bits(sig, raws[i]));
    }
    if (identity_value(sig, raws[i], &whole)) {
        return within(sig, whole) ? set_int(in, k, whole) : none(in, k, REFUSED);
    }
    value = urrt_can_from_raw(sig, raws[i]);
    if (!(value >= sig->min) || !(value <= sig->max)) {
        return none(in, k, REFUSED);
    }
    return urrt_rtde_in_set_double(in, k, value) == URRT_OK ? TAKEN : REFUSED;
}

/* Register k (d->regs[k]) from the signals that write it: bit masks' bits
 * or-ed into one word, any other value through its signal's scaling and
 * limits. */
static enum take take_register(const urrt_plcin_desc *d, urrt_rtde_in *in, size_t k, const uint64_t *raws,
                               uint64_t absent)
{
    uint64_t word = 0;
    double value = 0;
    int64_t whole = 0;
    bool mask = false, integer = false;
    size_t i;
    for (i = 0; i < d->signal_count; i++) {
        const urrt_can_signal *sig = &d->signals[i];
        if (d->vars[i] != d->regs[k]) {
            continue;
        }
        if (absent_bit(absent, i)) {
            return none(in, k, ABSENT);
        }
        if ((sig->flags & URRT_CAN_SIG_BITMASK) != 0) {
            mask = true;
            word |= mask_bits(sig, raws[i]);
            continue;
        }
        if (identity_value(sig, raws[i], &whole)) {
            integer = true;
            if (!within(sig, whole)) {
                return none(in, k, REFUSED);
            }
            continue;
        }
        value = urrt_can_from_raw(sig, raws[i]);
        if (!(value >= sig->min) || !(value <= sig->max)) {
            return none(in, k, REFUSED);
        }
    }
    if (integer) {
        return set_int(in, k, whole);
    }
    if (mask) {
        return set_mask(in, k, word);
    }
    return urrt_rtde_in_set_double(in, k, value) == URRT_OK ? TAKEN : REFUSED;
}

static bool given(const urrt_rtde_in *in, size_t k)
{
    return ((unsigned)in->given[k / 8u] >> (k % 8u) & 1u) != 0;
}

/* Register k's packed bytes (at most 8: a DOUBLE's) as one number, to see
 * a change. */
static uint64_t packed(const urrt_rtde_in *in, size_t k)
{
    size_t at = in->offset[k];
    size_t end = k + 1u < in->count ? in->offset[k + 1u] : in->data_size;
    uint64_t bytes = 0;
    size_t b;
    for (b = at; b < end && b < at + 8u; b++) {
        bytes = bytes << 8 | in->data[b];
    }
    return bytes;
}

/* Register k from raws (from signal k alone when ordered): whether its
 * value changed, came or went. */
static bool take_changed(const urrt_plcin_desc *d, urrt_rtde_in *in, size_t k, bool ordered, const uint64_t *raws,
                         uint64_t absent, size_t *refused)
{
    bool had = given(in, k);
    uint64_t before = had ? packed(in, k) : 0u; /* a register without a value: any value is news */
    enum take took = ordered ? take_one(d, in, k, k, raws, absent) : take_register(d, in, k, raws, absent);
    *refused += took == REFUSED;
    if (!given(in, k)) {
        return had;
    }
    return !had || packed(in, k) != before;
}

/* Signal i writes register i, and no other signal writes it (the registers
 * are distinct): the usual input, one signal per register in recipe order,
 * taken in one pass over the signals instead of one per register. */
static bool in_register_order(const urrt_plcin_desc *d)
{
    size_t i;
    if (d->signal_count != d->reg_count) {
        return false;
    }
    for (i = 0; i < d->reg_count; i++) {
        if (d->vars[i] != d->regs[i]) {
            return false;
        }
    }
    return true;
}

size_t urrt_plcin_take(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in, const uint64_t *raws,
                       uint64_t absent, uint64_t at_us)
{
    size_t refused = 0;
    bool changed = false;
    bool ordered;
    size_t k;
    if (d == 0 || p == 0 || in == 0 || raws == 0 || d->reg_count != in->count) {
        return 0;
    }
    ordered = in_register_order(d);
    for (k = 0; k < d->reg_count; k++) {
        changed = take_changed(d, in, k, ordered, raws, absent, &refused) || changed;
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
        /* The first instant it is timed out: older than timeout_ms, not as old. */
        uint64_t timeout = p->rx_us + (uint64_t)d->timeout_ms * 1000u + 1u;
        due = timeout < due ? timeout : due;
    }
    if (ready && urrt_plcin_writing(d, p)) {
        uint64_t refresh = p->sent_us + period_us;
        due = refresh < due ? refresh : due;
    }
    return due;
}

/* ---- through a CANopen node ------------------------------------------------------ */

/* The node's own reason for the input to be silent, in urrt_co_rpdo_status's
 * order but for the RPDO's deadline and for no data yet, which are not. */
static urrt_plcin_why node_why(const urrt_plcin_rpdo *r, uint64_t now_us)
{
    switch (urrt_co_rpdo_status(r->co, r->rpdo, now_us)) {
    case URRT_CO_RPDO_NOT_OPERATIONAL: return URRT_PLCIN_NOT_OPERATIONAL;
    /* Before "heartbeat lost", which it would hide: a manager that switched the
     * RPDO off has said its registers are not written. */
    case URRT_CO_RPDO_NOT_VALID: return URRT_PLCIN_RPDO_OFF;
    case URRT_CO_RPDO_HEARTBEAT_LOST: return URRT_PLCIN_HEARTBEAT_LOST;
    default: return URRT_PLCIN_STILL;
    }
}

void urrt_plcin_node(const urrt_plcin_desc *d, const urrt_plcin_rpdo *r, urrt_plcin *p, urrt_rtde_in *in,
                     uint64_t now_us, urrt_plcin_look *look)
{
    uint64_t timeout_us, newest = URRT_CANTX_NEVER;
    uint32_t absent = 0;
    const uint64_t *written;
    urrt_plcin_why why;
    size_t i;
    if (look == 0) {
        return;
    }
    look->took = false;
    look->refused = 0;
    look->why = URRT_PLCIN_STILL;
    if (d == 0 || r == 0 || p == 0 || in == 0 || r->co == 0 || r->co->rx_storage == 0 ||
        r->co->rx_storage->written_us == 0 || d->signal_count > URRT_CO_RPDO_MAX_MAPPED ||
        (size_t)r->first_var + d->signal_count > r->co->rx_storage->var_count) {
        return;
    }
    timeout_us = (uint64_t)d->timeout_ms * 1000u;
    written = r->co->rx_storage->written_us + r->first_var;
    /* One pass: the newest write, and the variables never written or too old
     * (absent: at most 8 of them, bits of a 32-bit word). */
    for (i = 0; i < d->signal_count; i++) {
        uint64_t w = written[i];
        if (w == URRT_CANTX_NEVER) {
            absent |= UINT32_C(1) << i;
            continue;
        }
        newest = newest == URRT_CANTX_NEVER || w > newest ? w : newest;
        absent |= (uint32_t)(since(now_us, w) > timeout_us) << i;
    }
    why = node_why(r, now_us);
    if (why == URRT_PLCIN_STILL && newest != URRT_CANTX_NEVER && newest != p->seen_us &&
        since(now_us, newest) <= timeout_us) {
        uint64_t raws[URRT_CO_RPDO_MAX_MAPPED];
        for (i = 0; i < d->signal_count; i++) {
            raws[i] = r->co->vars[r->first_var + i];
        }
        look->refused = urrt_plcin_take(d, p, in, raws, absent, newest);
        look->took = true;
    }
    p->seen_us = newest;
    if (why == URRT_PLCIN_STILL && urrt_plcin_timed_out(d, p, now_us)) {
        why = URRT_PLCIN_NO_WRITE;
    }
    if (p->fresh && why != URRT_PLCIN_STILL) {
        urrt_plcin_silent(d, p, in);
        look->why = why;
    }
}
