/* SPDX-License-Identifier: MIT */
/*
 * rtde_only: the RTDE-only values (lib/urrt_rtde.h's variables RealTime does
 * not have: output_int_register_24, safety_status_bits, ...) as the
 * gateway's outputs carry them: CAN signals, CANopen objects, NAME.RTDE. The one place the gateway keeps what the
 * library's variable table does not say: each value's unit, and which are bit
 * masks (unit "bits": sent bit for bit, never scaled or limited); and how a
 * value is read out of a package's urrt_rtde_values, as a double for a
 * quantity or as its 64 bits for a mask (exact to bit 63, which a double
 * holding the integer is not past 2^53).
 */
#ifndef URRT_GATEWAY_RTDE_ONLY_H
#define URRT_GATEWAY_RTDE_ONLY_H

#include <stdbool.h>
#include <stdint.h>

#include "urrt_rtde.h"

/* Whether var is an RTDE-only variable (not one that fills a urrt_state field). */
bool rtde_only(int var);

/* Elements of the value: 3 or 6 for a vector, else 1; 0 for no RTDE-only var. */
unsigned rtde_only_elements(int var);

/* The value's unit as the field table writes units ("m, rad" for a pose:
 * elements 0-2 in m, 3-5 in rad; "bits" for a mask; "" for a count, a
 * register or a ratio). */
const char *rtde_only_unit(int var);

/* Whether the value is a bit mask (its unit is "bits"). */
bool rtde_only_is_mask(int var);

/* Element elem of the value in *v as a double: exact for every type but a
 * 64-bit integer past 2^53; NaN when the package did not have it. */
double rtde_only_element(const urrt_rtde_values *v, int var, unsigned elem);

/* A mask's bits in *v, all 64 of a UINT64; 0 when the package did not have it. */
uint64_t rtde_only_mask(const urrt_rtde_values *v, int var);

#endif
