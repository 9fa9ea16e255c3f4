/* SPDX-License-Identifier: MIT */
/* can_in.c: see can_in.h. */
#include "can_in.h"

void can_in_desc(const struct can_map_frame *f, uint16_t *vars, urrt_plcin_desc *d)
{
    for (size_t i = 0; i < f->count; i++) {
        vars[i] = (uint16_t)f->meta[i].var;
    }
    *d = (urrt_plcin_desc){
        .signals = f->sigs,
        .vars = vars,
        .regs = f->regs,
        .signal_count = (uint16_t)f->count,
        .reg_count = (uint16_t)f->reg_count,
        .len = f->len,
        .flags = (uint8_t)((f->extended ? URRT_CANTX_EXTENDED : 0u) | (f->fd ? URRT_CANTX_FD : 0u)),
        .id = f->id,
        .timeout_ms = f->timeout_ms,
        .silence = (uint8_t)f->silence,
        .robot = (uint8_t)f->robot_index,
        .silence_value = f->silence_value,
    };
}
