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

/* Who else receives on the link (the PLC's [input] frames, plc_in.h): its
 * ids join the link's filter beside a CANopen node's, each frame received
 * goes to frame() first (true: taken; false: the node's, if any), link()
 * hears the link's state at every tick of the output, and node() (with a
 * CANopen node) runs after the node handled a frame or ran. Each may be
 * NULL. */
typedef struct can_out_receiver {
    bool (*frame)(void *ctx, const urrt_can_frame *frame, uint64_t rx_us);
    void (*link)(void *ctx, bool up, uint64_t bus_off, uint64_t now_us);
    void (*node)(void *ctx, uint64_t now_us);
    void *ctx;
    const uint32_t *ids;     /* as urrt_canlink_config.rx_ids; copied */
    size_t id_count;
} can_out_receiver;
/* False (logged) when the link cannot take the ids. */
bool can_out_set_receiver(can_out *out, const can_out_receiver *receiver);

/* What the metrics (metrics.h) and systemd's status (notify.h) say of it. */
typedef struct can_out_info {
    const urrt_canlink_stats *link;
    bool up;                 /* the interface is open and up */
    bool node;               /* a CANopen node runs: nmt and emcys hold */
    urrt_co_nmt nmt;
    uint64_t emcys;          /* EMCY frames the node sent */
} can_out_info;
void can_out_get_info(const can_out *out, can_out_info *info);

#endif
