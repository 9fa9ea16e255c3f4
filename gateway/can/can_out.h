/* SPDX-License-Identifier: MIT */
/*
 * can_out.h: the CAN output of urrt-gateway. It joins the mapping
 * (can_map.h: what goes into which frame, and when) to the CAN link
 * (port.h), as one gw_output next to the LCM one.
 */
#ifndef URRT_GATEWAY_CAN_OUT_H
#define URRT_GATEWAY_CAN_OUT_H

#include "can_map.h"
#include "gateway.h"

typedef struct can_out can_out;

/* Opens the link [can] names. NULL (logged) when it can never work: a bad
 * interface name, an FD mapping on a classic-MTU interface. An interface
 * that is merely down or missing is retried while the gateway runs. */
can_out *can_out_new(gateway *gw, struct can_map *map);
gw_output can_out_output(can_out *out);

#endif
