/* SPDX-License-Identifier: MIT */
/*
 * can_replay: `urrt-gateway --replay CAPTURE CONFIG`. A raw capture of a
 * robot's RealTime stream (`urrt-dump -w`, `nc ROBOT 30003 > FILE`) through
 * the CAN side of CONFIG as the first robot's packets, clocked by the
 * packets' own controller time, not by this host's: the frames a PLC would
 * have received, in order and bit for bit, at once. A firmware built from
 * `--print-c-tables` and fed the same bytes sends the same frames
 * (make check-fw-gateway). LCM is not involved.
 */
#ifndef URRT_GATEWAY_CAN_REPLAY_H
#define URRT_GATEWAY_CAN_REPLAY_H

#include "can_map.h"
#include "can_run.h"
#include "co_run.h"

/* Sends the capture's frames, run's (the tables of map; NULL: no CAN
 * output configured), or with node (NULL: none) the CANopen node's over
 * them, booted at the first packet's time, on map's [can] interface
 * (log:PATH is the usual choice; each line carries the frame's time on the
 * capture's clock). rx_path (NULL: none) names the frames the node
 * received, candump -l lines ("(SEC.USEC) can0 605#4000100000000000")
 * timed on the capture's clock: each goes to urrt_co_on_frame at its time,
 * between the packets, as a firmware's CAN receive interrupt would hand it
 * over (with no node, to the first robot's [input]s of their ids).
 * inputs_path (NULL: none; an RTDE capture only) gets the input packages the
 * gateway would write for the first robot's [input]s (lib/urrt_plcin's
 * rules, looked at after each received frame, at each packet and at each of
 * their deadlines), one line each, "(SEC.USEC) HEX", each session of the
 * capture taken as accepting every input recipe once its output recipe is
 * in, with ids after the output recipe's, in order. Returns a CLI_EXIT_*
 * status; reasons go to the log. */
int can_replay(const struct can_map *map, struct can_run *run, struct co_run *node, const char *capture_path,
               const char *rx_path, const char *inputs_path);

#endif
