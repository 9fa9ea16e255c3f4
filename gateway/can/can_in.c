/* SPDX-License-Identifier: MIT */
/* can_in.c: see can_in.h. */
#include "can_in.h"

#include <math.h>

#include "urrt_can.h"

bool can_in_raws(const struct can_map_frame *f, const urrt_can_frame *frame, uint64_t raws[CAN_IN_MAX_SIGNALS])
{
    if (frame->len != f->len || frame->fd != f->fd || f->count > CAN_IN_MAX_SIGNALS) {
        return false;
    }
    for (size_t i = 0; i < f->count; i++) {
        raws[i] = 0;
        (void)urrt_can_get_raw(&f->sigs[i], frame->data, frame->len, &raws[i]); /* can_map_finish checked the layout */
    }
    return true;
}

enum take { TAKEN, REFUSED, ABSENT };

/* lib keeps no value for a register whose value it refuses: NaN, which no
 * register takes, leaves register k without one. */
static enum take none(urrt_rtde_in *in, size_t k, enum take why)
{
    (void)urrt_rtde_in_set_double(in, k, NAN);
    return why;
}

/* Register k from the signals that write it. */
static enum take take_register(const struct can_map_frame *f, urrt_rtde_in *in, size_t k, const uint64_t *raws,
                               uint64_t absent)
{
    uint64_t word = 0;
    double value = 0;
    bool mask = false;
    for (size_t i = 0; i < f->count; i++) {
        const urrt_can_signal *sig = &f->sigs[i];
        if (f->meta[i].var != f->regs[k]) {
            continue;
        }
        if (i < 64 && (absent >> i & 1u) != 0) {
            return none(in, k, ABSENT);
        }
        if (f->meta[i].bitmask) {
            mask = true;
            word |= (sig->length >= 64 ? raws[i] : raws[i] & ((UINT64_C(1) << sig->length) - 1u))
                    << URRT_CAN_SIG_MASK_FIRST(sig->flags);
            continue;
        }
        value = urrt_can_from_raw(sig, raws[i]);
        if (!(value >= sig->min) || !(value <= sig->max)) {
            return none(in, k, REFUSED);
        }
    }
    if (mask) {
        return urrt_rtde_in_set_int(in, k, (int64_t)word) == URRT_OK ? TAKEN : REFUSED;
    }
    return urrt_rtde_in_set_double(in, k, value) == URRT_OK ? TAKEN : REFUSED;
}

size_t can_in_take(const struct can_map_frame *f, urrt_rtde_in *in, const uint64_t *raws, uint64_t absent)
{
    size_t refused = 0;
    for (size_t k = 0; k < f->reg_count; k++) {
        refused += take_register(f, in, k, raws, absent) == REFUSED;
    }
    return refused;
}
