/* SPDX-License-Identifier: MIT */
/*
 * can_run: a finished CAN mapping (can_map.h) as the tables of
 * lib/urrt_cantx.h, and the CAN core over them: the map's frames in
 * configuration order, then the heartbeat. These are the tables
 * urrt-gateway runs on and --print-c-tables writes for a firmware; the core
 * packs with every signal's scale prepared (urrt_cantx_prepare), as a
 * firmware's does.
 *
 * Built once, when the configuration is loaded (config.c), so that
 * --check-config proves they build; the map must outlive them (the frames'
 * signal tables are the map's). The run knows nothing of a CAN link or a
 * clock: callers pass the time and the link's counters in and send what
 * comes out.
 */
#ifndef URRT_GATEWAY_CAN_RUN_H
#define URRT_GATEWAY_CAN_RUN_H

#include <stddef.h>
#include <stdint.h>

#include "can_map.h"
#include "port.h"
#include "urrt_cantx.h"
#include "urrt_rtde.h"

#define CAN_RUN_STARTUP_MS 5000u /* "starting" lasts at most this long without data */

struct can_run;

/* The tables of a map can_map_finish accepted: NULL with the reason in err
 * (out of memory, or a table lib/ refuses: a check missing in can_map). */
struct can_run *can_run_build(const struct can_map *map, char *err, size_t errlen);
void can_run_free(struct can_run *run);

/* Robot `robot`'s package has these RTDE-only values (NULL: a RealTime
 * packet, none): its frames' RTDE-only signals carry them until the next.
 * Call it before urrt_cantx_on_packet with the package's state. */
void can_run_rtde(struct can_run *run, size_t robot, const urrt_rtde_values *values);

/* The CAN core over the tables, and the heartbeat's index in them. */
urrt_cantx *can_run_tx(struct can_run *run);
size_t can_run_heartbeat_index(const struct can_run *run);

/* Restarts the schedule at now_us (urrt_cantx_start). */
void can_run_start(struct can_run *run, uint64_t now_us);

/* The CAN link's counters (NULL: unchanged), then every frame due at now_us
 * through emit (urrt_cantx_run). */
void can_run_due(struct can_run *run, uint64_t now_us, const urrt_canlink_stats *stats, urrt_cantx_emit_fn emit,
                 void *ctx);

/* The CAN link's counters, for the heartbeat's flags and a CANopen node's
 * EMCYs (urrt_cantx_set_link). */
void can_run_set_link(struct can_run *run, const urrt_canlink_stats *stats);

/* The heartbeat as it would go out at now_us with these link counters,
 * without sending it (urrt_cantx_peek): for status displays and tests. */
void can_run_heartbeat_frame(struct can_run *run, uint64_t now_us, const urrt_canlink_stats *stats,
                             urrt_can_frame *frame);

/* The heartbeat's gateway state at now_us. */
urrt_cantx_state can_run_state(const struct can_run *run, uint64_t now_us);

/* Values packed with an outcome other than OK, since start. */
uint64_t can_run_clamped(const struct can_run *run);

#endif
