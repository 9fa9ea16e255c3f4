/* SPDX-License-Identifier: MIT */
/*
 * can_in: what an [input NAME] frame (can_map.h) carries, as values of its
 * RTDE input recipe (lib/urrt_rtde_in.h). Without a loop, a link or a
 * clock: urrt-gateway's plc_in.c feeds it the frames the CAN link received
 * (or the raw values a CANopen node's RPDOs and SDO writes stored), and the
 * fuzz harness feeds it anything.
 *
 * A value is taken as the PLC sent it or not at all: a mask's bits gathered
 * from its signals' bits= (bits no signal carries are 0), any other value
 * through its one signal's scaling (physical = raw x factor + offset) and
 * within the signal's min..max, then lib's check of the register's type
 * (urrt_rtde_in_set_*); a value refused, or absent, leaves its register
 * without a value, so that nothing is written for it until a good one
 * comes. Never clamped.
 */
#ifndef URRT_GATEWAY_CAN_IN_H
#define URRT_GATEWAY_CAN_IN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "can_map.h"
#include "urrt_rtde_in.h"

/* The most signals an [input] frame holds: one per bit of a 64-byte frame. */
#define CAN_IN_MAX_SIGNALS (8u * URRT_CAN_MAX_LEN)

/* The raw value of each of f's signals (raws[i] for signal i) in a received
 * frame; false (raws untouched) for a frame of another length or kind
 * (classic, FD) than f's: not used. */
bool can_in_raws(const struct can_map_frame *f, const urrt_can_frame *frame, uint64_t raws[CAN_IN_MAX_SIGNALS]);

/* Every register of f's recipe (in, made from f->regs) from raws, bit i of
 * absent saying signal i has no value (a CANopen variable too old): the
 * number of values refused (outside min..max, or not one the register
 * takes); absent ones are not counted. */
size_t can_in_take(const struct can_map_frame *f, urrt_rtde_in *in, const uint64_t *raws, uint64_t absent);

#endif
