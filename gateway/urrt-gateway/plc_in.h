/* SPDX-License-Identifier: MIT */
/*
 * plc_in.h: the PLC's answers. Each [input NAME] frame received on the CAN
 * link (can_out hands them over) writes its robot's input registers through
 * that robot's RTDE session (rtde_source.h, one input recipe per frame), and
 * only while the PLC's data is fresh:
 *
 *   a frame of the right length   its signals decoded (factor and offset
 *                                  applied inversely, masks bit for bit), each
 *                                  value checked (min..max, then lib's check
 *                                  of the register's type) and, when every
 *                                  register of the frame holds one, the input
 *                                  package sent at once if a value changed
 *   fresh and unchanged            the package again at [can] inputs_min_rate,
 *                                  so that the program's rtde_set_watchdog
 *                                  sees a living PLC
 *   a robot link that came back    the current values at once, once the new
 *                                  session accepted the recipe
 *   the PLC silent                 (no frame for timeout_ms, the CAN interface
 *                                  down, a bus-off) the frame's on_silence:
 *                                  stop (values forgotten, nothing sent: the
 *                                  watchdog acts), hold, or value V
 *
 * Nothing is sent for a register the PLC never wrote (no invented zeros at
 * start-up), nor for one whose last value was refused. A gw_output: its
 * tick judges timeouts and the minimum rate, its deadline is the earliest
 * of them, its counters go to GATEWAY and the metrics file.
 */
#ifndef URRT_GATEWAY_PLC_IN_H
#define URRT_GATEWAY_PLC_IN_H

#include <stdbool.h>
#include <stdint.h>

#include "can_map.h"
#include "co_run.h"
#include "gateway.h"

typedef struct plc_in plc_in;

/* The [input]s of map, onto gw's robots' RTDE sessions (their sources were
 * made with these recipes: plc_in_recipes). With node (a [canopen]
 * configuration's), each [input] is the node's RPDO of its number: its
 * values come from the node's variables (RPDOs and SDO writes, see
 * plc_in_node), and the node's state and the manager's heartbeat count as
 * silence too. NULL (logged) when out of memory. */
plc_in *plc_in_new(gateway *gw, const struct can_map *map, struct co_run *node);
gw_output plc_in_output(plc_in *in);

/* Robot `robot`'s input recipes, one per [input] of it, in the map's order,
 * for its rtde_source_config: at most max; returns how many. The vars point
 * into the map. */
size_t plc_in_recipes(const struct can_map *map, size_t robot, rtde_source_input *out, size_t max);

/* A frame the CAN link received at rx_us: true when it is an [input]'s
 * (taken), false for anyone else's. */
bool plc_in_on_frame(void *in, const urrt_can_frame *frame, uint64_t rx_us);

/* With a CANopen node: it handled a frame, or ran; what it stored since is
 * taken, its state judged. */
void plc_in_node(void *in, uint64_t now_us);

/* The CAN link cannot receive (down, or a bus-off counted since the last
 * call): every [input] is silent now. */
void plc_in_link(void *in, bool up, uint64_t bus_off, uint64_t now_us);

/* One [input]'s counters, for the metrics file. */
typedef struct plc_in_counts {
    uint64_t frames;      /* frames received on its id */
    uint64_t bad_frames;  /* of them, of another length (or FD where classic is configured): not used */
    uint64_t refused;     /* values refused: outside min..max, or not one its register takes */
    uint64_t written;     /* input packages sent */
    uint64_t silences;    /* times the PLC fell silent (timeout, interface down, bus-off) */
    bool fresh;           /* its data is fresh now */
} plc_in_counts;
size_t plc_in_count(const plc_in *in);
const struct can_map_frame *plc_in_frame(const plc_in *in, size_t i);
void plc_in_get_counts(const plc_in *in, size_t i, plc_in_counts *out);

#endif
