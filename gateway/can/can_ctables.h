/* SPDX-License-Identifier: MIT */
/*
 * can_ctables: `urrt-gateway --print-c-tables`. The CAN frames of a
 * configuration as C source of lib/urrt_cantx.h tables (the very tables
 * urrt-gateway runs on, can_run.h), with their storage (the prepared
 * scales too) and an init function that checks the tables and prepares the
 * scales, so that a firmware sends the same frames, packed as cheaply,
 * without a mapping written by hand; with [canopen], the CANopen node's
 * urrt_co_desc too; for a robot read over RTDE (source = rtde), the
 * recipe its firmware asks for and how its RTDE-only values reach the
 * frames; with [input]s, the frames the PLC sends (urrt_gateway_inputs:
 * id, kind, length, timeout_ms, on_silence and its value, the signals as
 * urrt_can_signal tables, the register each writes as lib/urrt_rtde.h's
 * URRT_RTDE_V_ id and the input recipe), in a type the file defines, since
 * lib/ has none.
 * docs/firmware.md shows one in use.
 */
#ifndef URRT_GATEWAY_CAN_CTABLES_H
#define URRT_GATEWAY_CAN_CTABLES_H

#include <stdbool.h>
#include <stdio.h>

#include "can_map.h"
#include "can_run.h"
#include "co_run.h"

/* How a robot's data reaches the firmware. */
struct can_ctables_robot {
    bool rtde;        /* source = rtde: lib/urrt_rtde.h's client; else the RealTime stream */
    double frequency; /* RTDE: Hz asked for, 0 for the controller's maximum */
    uint16_t port;    /* the robot's TCP port, which a firmware checks before it writes */
};

/* Writes the C source of run, the tables of map, and with node (NULL:
 * none) the CANopen node's description over them (urrt_gateway_node,
 * urrt_gateway_co_init; source: the configuration's path, for the header
 * comment). robots: how each of map's robots is read, in map's order
 * (NULL: all by RealTime); for an RTDE robot the source also holds the
 * recipe a firmware asks for (the timestamp and what its CAN signals need)
 * and the fill functions that read its RTDE-only values as rtde_only.h
 * does; an [input] of a robot that is not read over RTDE is an #error in
 * the source. Without [input]s nothing of theirs is written, not even
 * their type. 0, or -1 when the stream failed. */
int can_ctables_write(FILE *out, const struct can_map *map, struct can_run *run, struct co_run *node,
                      const struct can_ctables_robot *robots, const char *source);

#endif
