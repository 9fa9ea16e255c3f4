/* SPDX-License-Identifier: MIT */
/*
 * can_out.h: the CAN output of urrt-gateway, one gw_output beside the LCM
 * one (lcm_out.h). It joins the CAN core over the configuration's tables
 * (can_run.h: what goes into which frame, and when) to the CAN link
 * (port.h): packets and robot link changes in, frames out.
 */
#ifndef URRT_GATEWAY_CAN_OUT_H
#define URRT_GATEWAY_CAN_OUT_H

#include "can_map.h"
#include "can_run.h"
#include "co_run.h"
#include "gateway.h"

typedef struct can_out can_out;

/* Opens the link map's [can] names and starts run's schedule, or with a
 * CANopen node (co_run.h; NULL: none) the node over it: its boot-up, its
 * received frames (the link filters the node's ids), its EMCYs. NULL (logged)
 * when it can never work: a bad interface name, an FD mapping on a
 * classic-MTU interface. An interface that is merely down or missing is
 * retried while the gateway runs. */
can_out *can_out_new(gateway *gw, const struct can_map *map, struct can_run *run, struct co_run *node);
gw_output can_out_output(can_out *out);

#endif
