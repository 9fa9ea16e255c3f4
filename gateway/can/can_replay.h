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

/* Sends the capture's frames, run's (the tables of map; NULL: no CAN
 * output configured), on map's [can] interface (log:PATH is the usual
 * choice). Returns a CLI_EXIT_* status; reasons go to the log. */
int can_replay(const struct can_map *map, struct can_run *run, const char *capture_path);

#endif
