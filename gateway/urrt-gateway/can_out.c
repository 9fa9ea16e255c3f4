/* SPDX-License-Identifier: MIT */
/* can_out.c: see can_out.h. */
#include "can_out.h"

#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct can_out {
    gateway *gw;
    struct can_run *run;
    urrt_cantx *tx;         /* run's CAN core */
    urrt_co *node;          /* the CANopen node over tx, or NULL: tx runs alone */
    uint64_t node_us;       /* the node's latest time: a frame received earlier is handed over at it */
    uint32_t rx_seen;       /* the node's rx_changes the link's filter was set at */
    urrt_canlink *link;
    gw_watch watch;         /* the link's socket, in the loop's wait */
    uint64_t refused;       /* frames the link refused (cannot happen with a checked map) */
    uint64_t emcys;         /* EMCY frames the node sent (metrics.h) */
    can_out_receiver receiver; /* the [input]s' (frame NULL: none); ids owned */
    bool robot_up[GW_MAX_ROBOTS];
};

/* The link's filter: the node's ids, then the receiver's. */
static int set_rx_ids(can_out *out)
{
    uint32_t ids[URRT_CANLINK_RX_IDS_MAX];
    size_t n = out->node != NULL ? urrt_co_rx_ids(out->node, ids) : 0;
    for (size_t i = 0; i < out->receiver.id_count && n < URRT_CANLINK_RX_IDS_MAX; i++) {
        ids[n++] = out->receiver.ids[i];
    }
    return urrt_canlink_set_rx_ids(out->link, ids, n);
}

/* The link's filter follows the node's ids: a manager moved the SYNC
 * (0x1005), an RPDO (0x1400 sub 1) or named a heartbeat to watch (0x1016),
 * or a reset moved them back. */
static void follow_rx_ids(can_out *out)
{
    uint32_t ids[URRT_CO_RX_IDS_MAX];
    size_t n = urrt_co_rx_ids(out->node, ids);
    if (set_rx_ids(out) == 0) {
        char list[8 * URRT_CO_RX_IDS_MAX + 1] = "";
        size_t used = 0;
        for (size_t i = 0; i < n && used < sizeof list; i++) {
            int w = snprintf(list + used, sizeof list - used, " 0x%03X", (unsigned)ids[i]);
            used += w > 0 ? (size_t)w : 0;
        }
        out->rx_seen = out->node->rx_changes;
        urrt_log(URRT_LOG_NOTICE, "CANopen: the node's receive ids changed (a manager's write to 0x1005, 0x1400+n "
                 "or 0x1016, or a reset): the CAN link receives%s", list);
    }
}

static void emit(void *ctx, const urrt_can_frame *frame, uint64_t now_us)
{
    can_out *out = ctx;
    /* Before the frame: the SDO answer that confirms a write to 0x1005 (or
     * the boot-up after a reset) leaves only once the filter lets the new
     * SYNC id in, so that a manager's SYNC right after it is heard. */
    if (out->node != NULL && out->node->rx_changes != out->rx_seen) {
        follow_rx_ids(out);
    }
    if (out->node != NULL && !frame->extended && frame->id == (out->node->emcy_cob_id & 0x7FFu)) {
        out->emcys++;
    }
    if (urrt_canlink_send(out->link, frame, now_us) < 0) {
        out->refused++;
    }
}

/* The node's view of the link: frames lost on the way in (the socket's
 * queue overflowed) are a CAN overrun as much as those lost on the way out,
 * and the controller's error passive state is the node's EMCY 0x8120. */
static void node_link(can_out *out)
{
    urrt_canlink_stats stats = *urrt_canlink_get_stats(out->link);
    stats.dropped += stats.rx_overflows;
    can_run_set_link(out->run, &stats);
    urrt_co_set_error_passive(out->node, stats.error_passive);
}

/* Nothing is scheduled while the link is down: frames would only be
 * dropped, and a heartbeat dropped there would take its "interface was
 * down" flag with it. The first heartbeat after the outage carries it. */
static void run_due(can_out *out, uint64_t now_us)
{
    if (urrt_canlink_get_state(out->link) != URRT_CANLINK_UP) {
        return;
    }
    if (out->node != NULL) {
        node_link(out);
        out->node_us = now_us > out->node_us ? now_us : out->node_us;
        urrt_co_run(out->node, out->node_us, emit, out);
        if (out->receiver.node != NULL) {
            out->receiver.node(out->receiver.ctx, out->node_us);
        }
        return;
    }
    can_run_due(out->run, now_us, urrt_canlink_get_stats(out->link), emit, out);
}

/* A frame the link let through its filter (NMT, SYNC, this node's SDO):
 * the node answers at once, at the time it was received (its clock never
 * goes back: a frame read after a run is handed over at that run's time). */
static void on_frame(void *ctx, const urrt_can_frame *frame, uint64_t rx_us)
{
    can_out *out = ctx;
    unsigned flags = frame->extended ? URRT_CO_RX_EXTENDED : 0u;
    if ((out->receiver.frame != NULL && out->receiver.frame(out->receiver.ctx, frame, rx_us)) || out->node == NULL) {
        return;
    }
    out->node_us = rx_us > out->node_us ? rx_us : out->node_us;
    urrt_co_on_frame(out->node, frame->id, flags, frame->data, frame->len, out->node_us, emit, out);
    if (out->receiver.node != NULL) {
        out->receiver.node(out->receiver.ctx, out->node_us);
    }
}

/* After each call into the link: its socket (reopened, or waiting to
 * write) stays the one the loop waits on. */
static void keep_watch(can_out *out)
{
    short events = 0;
    int fd = urrt_canlink_poll_fd(out->link, &events);
    gw_watch_set(out->gw, &out->watch, fd, events, urrt_canlink_get_stats(out->link)->opens);
}

static void on_packet(void *ctx, gw_robot *robot, const gw_packet *pkt)
{
    can_out *out = ctx;
    /* The core judges staleness by the data's age, not by the read: a
     * backlog read just now is as old as its data. Frames are due by the
     * clock now, just before they are sent. The RTDE-only values go with
     * the package they came in, and are as old as it. */
    can_run_rtde(out->run, robot->index, pkt->rtde);
    urrt_cantx_on_packet(out->tx, robot->index, pkt->state, pkt->data_us);
    out->robot_up[robot->index] = true;
    run_due(out, urrt_port_monotonic_us());
    keep_watch(out);
}

static void on_tick(void *ctx, uint64_t now_us)
{
    can_out *out = ctx;
    for (unsigned i = 0; i < out->gw->robot_count; i++) {
        bool up = urrt_link_get_state(out->gw->robots[i].link) == URRT_LINK_UP;
        if (up != out->robot_up[i]) {
            out->robot_up[i] = up;
            urrt_cantx_robot_link(out->tx, i, up);
        }
    }
    urrt_canlink_service(out->link, now_us);
    if (out->receiver.link != NULL) {
        out->receiver.link(out->receiver.ctx, urrt_canlink_get_state(out->link) == URRT_CANLINK_UP,
                           urrt_canlink_get_stats(out->link)->bus_off, now_us);
    }
    run_due(out, now_us);
    keep_watch(out);
}

static void on_ready(void *ctx, uint64_t now_us)
{
    can_out *out = ctx;
    urrt_canlink_service(out->link, now_us);
    keep_watch(out);
}

static uint64_t on_deadline(void *ctx)
{
    can_out *out = ctx;
    uint64_t map_due = out->node != NULL ? urrt_co_deadline(out->node) : urrt_cantx_deadline(out->tx);
    uint64_t link_due = urrt_canlink_deadline(out->link);
    return map_due < link_due ? map_due : link_due;
}

static unsigned on_counters(void *ctx, const gw_robot *robot, gw_counter *counters, unsigned max)
{
    can_out *out = ctx;
    const urrt_canlink_stats *s = urrt_canlink_get_stats(out->link);
    const gw_counter all[] = {
        {"can_up", urrt_canlink_get_state(out->link) == URRT_CANLINK_UP},
        {"can_sent", s->sent},
        {"can_dropped", s->dropped},
        {"can_send_errors", s->send_errors + out->refused},
        {"can_down_events", s->down_events},
        {"can_error_frames", s->error_frames},
        {"can_bus_off", s->bus_off},
        {"can_restarts", s->restarts},
        {"can_clamped", can_run_clamped(out->run)},
        {"can_received", s->received},          /* where the link receives: a node, [input]s */
        {"can_rx_overflows", s->rx_overflows},
    };
    bool receives = out->node != NULL || out->receiver.frame != NULL;
    unsigned count = sizeof all / sizeof all[0] - (receives ? 0u : 2u);
    unsigned n = 0;
    (void)robot;
    for (; n < max && n < count; n++) {
        counters[n] = all[n];
    }
    return n;
}

static int on_summary(void *ctx, const gw_robot *robot, uint64_t now_us, char *buf, size_t size)
{
    can_out *out = ctx;
    const urrt_canlink_stats *s = urrt_canlink_get_stats(out->link);
    (void)robot;
    return snprintf(buf, size, " | CAN %s %s%s%s, sent %llu, dropped %llu, bus-off %llu",
                    urrt_canlink_get_state(out->link) == URRT_CANLINK_UP ? "up" : "DOWN",
                    urrt_cantx_state_name(can_run_state(out->run, now_us)), out->node != NULL ? ", node " : "",
                    out->node != NULL ? urrt_co_state_name(urrt_co_state(out->node)) : "", (unsigned long long)s->sent,
                    (unsigned long long)s->dropped, (unsigned long long)s->bus_off);
}

static void on_close(void *ctx)
{
    can_out *out = ctx;
    urrt_canlink_free(out->link);
    free((void *)out->receiver.ids);
    free(out);
}

bool can_out_set_receiver(can_out *out, const can_out_receiver *receiver)
{
    uint32_t *ids = malloc((receiver->id_count ? receiver->id_count : 1) * sizeof *ids);
    if (ids == NULL) {
        urrt_log(URRT_LOG_ERR, "CAN output: out of memory for the receive ids");
        return false;
    }
    memcpy(ids, receiver->ids, receiver->id_count * sizeof *ids);
    free((void *)out->receiver.ids);
    out->receiver = *receiver;
    out->receiver.ids = ids;
    urrt_canlink_set_rx(out->link, on_frame, out);
    return set_rx_ids(out) == 0;
}

can_out *can_out_new(gateway *gw, const struct can_map *map, struct can_run *run, struct co_run *node)
{
    urrt_canlink_config cfg;
    can_out *out = calloc(1, sizeof *out);
    if (out == NULL) {
        urrt_log(URRT_LOG_ERR, "CAN output: out of memory");
        return NULL;
    }
    urrt_canlink_config_defaults(&cfg);
    can_map_link_config(map, &cfg);
    if (node != NULL) {
        cfg.rx_ids = co_run_rx_ids(node, &cfg.rx_id_count); /* the node's own ids, filtered by the kernel */
    }
    out->link = urrt_canlink_new(&cfg);
    if (out->link == NULL) {
        free(out);
        return NULL;
    }
    out->gw = gw;
    gw_watch_init(&out->watch, on_ready, out);
    out->run = run;
    out->tx = can_run_tx(run);
    out->node = node != NULL ? co_run_node(node) : NULL;
    if (out->node != NULL) {
        urrt_canlink_set_rx(out->link, on_frame, out);
        out->rx_seen = out->node->rx_changes; /* the ids the link was opened with */
        out->node_us = urrt_port_monotonic_us();
        urrt_co_start(out->node, out->node_us, emit, out); /* boot-up; starts tx */
    } else {
        can_run_start(run, urrt_port_monotonic_us());
    }
    return out;
}

void can_out_get_info(const can_out *out, can_out_info *info)
{
    info->link = urrt_canlink_get_stats(out->link);
    info->up = urrt_canlink_get_state(out->link) == URRT_CANLINK_UP;
    info->node = out->node != NULL;
    info->nmt = out->node != NULL ? urrt_co_state(out->node) : URRT_CO_INITIALISING;
    info->emcys = out->emcys;
}

gw_output can_out_output(can_out *out)
{
    gw_output o = {
        .name = "can",
        .ctx = out,
        .packet = on_packet,
        .tick = on_tick,
        .deadline = on_deadline,
        .counters = on_counters,
        .summary = on_summary,
        .close = on_close,
    };
    return o;
}
