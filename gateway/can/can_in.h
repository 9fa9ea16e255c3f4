/* SPDX-License-Identifier: MIT */
/*
 * can_in: an [input NAME] (can_map.h) as lib/urrt_plcin.h describes an
 * input, so that the gateway takes a PLC's frames, and a CANopen node's
 * RPDO variables, by the very code a firmware runs (what is taken, refused
 * and when a package is due are lib's rules). urrt-gateway's plc_in.c and
 * the fuzz harness use it.
 */
#ifndef URRT_GATEWAY_CAN_IN_H
#define URRT_GATEWAY_CAN_IN_H

#include <stdint.h>

#include "can_map.h"
#include "urrt_plcin.h"

/* d for f, with vars (f->count entries, the caller's, as long as d is used)
 * holding the register each signal writes; d points into f. */
void can_in_desc(const struct can_map_frame *f, uint16_t *vars, urrt_plcin_desc *d);

#endif
