/* SPDX-License-Identifier: MIT */
/* gateway.c: robots, outputs and the wait loop of urrt-gateway (gateway.h). */
#define _GNU_SOURCE
#include "gateway.h"

#include "plc_in.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <unistd.h>

/* A wrong-length stream is logged at once, then at most this often. */
#define GW_MISMATCH_LOG_US (10u * 1000000u)
/* Ready descriptors taken per wait: more wait for the next one. */
#define GW_WAIT_EVENTS 64

/* A robot link's deadline, and the loop that last serviced it (a link is
 * serviced at most once a loop: its read budget is its share). */
struct gw_link_due {
    uint64_t due_us;
    uint64_t loop;
};

static uint64_t bound_us(const gw_robot *robot)
{
    return (uint64_t)robot->cfg->link.silence_timeout_ms * 1000u;
}

bool gw_robot_data_fresh(const gw_robot *robot, uint64_t data_us, uint64_t now_us)
{
    return bound_us(robot) == 0 || now_us <= data_us || now_us - data_us <= bound_us(robot);
}

bool gw_robot_fresh(const gw_robot *robot, uint64_t now_us)
{
    /* Up means a packet came on this connection: a connection made after
     * the last packet read, which has sent nothing yet, is not. */
    if (urrt_link_get_state(robot->link) != URRT_LINK_UP || robot->data_us == 0 || robot->mismatch ||
        robot->late) {
        return false;
    }
    return gw_robot_data_fresh(robot, robot->data_us, now_us);
}

uint64_t gw_wall_us(uint64_t mono_us)
{
    uint64_t mono = urrt_port_monotonic_us();
    uint64_t wall = urrt_port_realtime_us();
    return mono >= mono_us ? wall - (mono - mono_us) : wall + (mono_us - mono);
}

int64_t gw_robot_data_age_us(const gw_robot *robot, uint64_t now_us)
{
    if (robot->newest_data_us == 0) {
        return -1;
    }
    return now_us > robot->newest_data_us ? (int64_t)(now_us - robot->newest_data_us) : 0;
}

unsigned gw_counters(const gateway *gw, const gw_robot *robot, gw_counter *out, unsigned max)
{
    unsigned n = 0;
    if (max > 0) {
        out[n++] = (gw_counter){"late_packets", robot->late_packets};
    }
    for (unsigned i = 0; i < gw->output_count && n < max; i++) {
        if (gw->outputs[i].counters != NULL) {
            n += gw->outputs[i].counters(gw->outputs[i].ctx, robot, out + n, max - n);
        }
    }
    return n;
}

static void on_mismatch(gw_robot *robot, size_t length, uint64_t rx_us)
{
    const char *versions = urrt_versions_of((uint32_t)length);
    robot->mismatches++;
    robot->mismatch = true;
    snprintf(robot->last_error, sizeof robot->last_error,
             "%zu-byte packets (%s), expected %" PRIu32 " (version %s)", length,
             versions != NULL ? versions : "no known controller", robot->cfg->expected_length,
             robot->cfg->expected);
    if (robot->mismatches_logged == 0 || rx_us >= robot->mismatch_logged_us + GW_MISMATCH_LOG_US) {
        urrt_log(URRT_LOG_WARNING,
                 "robot %s: %s: %" PRIu64 " packet%s not published so far; fix \"version\" in the "
                 "configuration (or set it to auto)",
                 robot->cfg->name, robot->last_error, robot->mismatches, robot->mismatches == 1 ? "" : "s");
        robot->mismatch_logged_us = rx_us;
        robot->mismatches_logged = robot->mismatches;
    }
}

/* The lag of a packet's data when read (freshness.h), on both clocks. */
static uint64_t packet_lag(gw_robot *robot, const urrt_state *st, uint64_t rx_us, bool new_connection)
{
    int64_t t_us = 0;
    bool has_clock = urrt_has(st, URRT_F_TIME) && urrt_time_us(st->time[0], &t_us) == URRT_OK;
    uint64_t lag;
    if (new_connection) {
        gw_age_reset(&robot->age);
    }
    lag = gw_age_lag_us(&robot->age, rx_us, urrt_link_packet_empty_us(robot->link), has_clock,
                        has_clock ? t_us : 0, urrt_link_packet_newest(robot->link));
    return lag == GW_AGE_UNKNOWN || lag < rx_us ? lag : rx_us - 1; /* data_us 0 means "none" */
}

static void on_late(gw_robot *robot, uint64_t lag_us)
{
    robot->late_packets++;
    if (!robot->late && lag_us == GW_AGE_UNKNOWN) {
        urrt_log(URRT_LOG_WARNING, "robot %s: a connection began with a burst of packets: their age cannot be "
                 "judged until the newest has come, so they are not published (late_packets %" PRIu64 "); "
                 "something between the robot and the gateway held them back", robot->cfg->name,
                 robot->late_packets);
    } else if (!robot->late) {
        urrt_log(URRT_LOG_WARNING, "robot %s: data %.0f ms old when read, older than silence_timeout (%u ms): "
                 "not published (late_packets %" PRIu64 "); the gateway was stopped, starved of CPU, slower "
                 "than the robot, or the link to the robot held data back: give it a core, publish less "
                 "(rates in [lcm]), or check the network",
                 robot->cfg->name, (double)lag_us / 1000.0, (unsigned)robot->cfg->link.silence_timeout_ms,
                 robot->late_packets);
    }
    robot->late = true;
}

static void dispatch(gw_robot *robot, const uint8_t *bytes, size_t length, uint64_t rx_us, bool new_connection);

/* The one per-packet path: check, decode once, hand to every output. */
static void on_packet(void *ctx, const uint8_t *bytes, size_t length, uint64_t rx_us)
{
    gw_robot *robot = ctx;
    uint64_t connects = urrt_link_get_stats(robot->link)->connects;
    bool new_connection = connects != robot->connects_seen;
    int r;

    robot->connects_seen = connects;
    if (robot->rtde != NULL) {
        /* Decoded by the session already, through the recipe: nothing to
         * check against a version's length. */
        robot->state = *rtde_source_state(robot->rtde);
        dispatch(robot, bytes, length, rx_us, new_connection);
        return;
    }
    if (robot->cfg->expected_length != 0 && length != robot->cfg->expected_length) {
        /* Not decoded: the host's clock alone says how old it is. */
        robot->newest_data_us = urrt_link_packet_empty_us(robot->link);
        on_mismatch(robot, length, rx_us);
        return;
    }
    if (robot->mismatch) {
        urrt_log(URRT_LOG_NOTICE, "robot %s: %zu-byte packets again, as expected", robot->cfg->name, length);
        robot->mismatch = false;
        robot->mismatches_logged = 0;
    }
    r = urrt_decode(bytes, length, &robot->state);
    if (r < 0) {
        /* The framer only yields plausible packets: this is a bug if seen. */
        robot->decode_errors++;
        snprintf(robot->last_error, sizeof robot->last_error, "decode: %s", urrt_strerror(r));
        return;
    }
    dispatch(robot, bytes, length, rx_us, new_connection);
}

/* A decoded packet (robot->state): judged fresh or late, then handed to
 * every output. The controller's timestamp is the data's time, whichever
 * source brought it. */
static void dispatch(gw_robot *robot, const uint8_t *bytes, size_t length, uint64_t rx_us, bool new_connection)
{
    gateway *gw = robot->gw;
    gw_packet pkt;
    uint64_t lag = packet_lag(robot, &robot->state, rx_us, new_connection);
    if (lag == GW_AGE_UNKNOWN) {
        on_late(robot, lag);
        return;
    }
    robot->newest_data_us = rx_us - lag;
    if (!gw_robot_data_fresh(robot, rx_us - lag, rx_us)) {
        on_late(robot, lag);
        return;
    }
    if (robot->late) {
        urrt_log(URRT_LOG_NOTICE, "robot %s: data fresh again (late_packets %" PRIu64 ")", robot->cfg->name,
                 robot->late_packets);
    }
    robot->late = false;
    robot->data_us = rx_us - lag;
    robot->sequence++;
    pkt.bytes = bytes;
    pkt.length = length;
    pkt.state = &robot->state;
    pkt.rtde = robot->rtde != NULL ? rtde_source_values(robot->rtde) : NULL;
    pkt.rx_us = rx_us;
    pkt.data_us = robot->data_us;
    pkt.rx_wall_us = gw_wall_us(rx_us);
    pkt.sequence = robot->sequence;
    for (unsigned i = 0; i < gw->output_count; i++) {
        gw->outputs[i].packet(gw->outputs[i].ctx, robot, &pkt);
    }
}

/* The robot's RTDE session on its link, with the configuration's recipe. */
static bool rtde_attach(gw_robot *robot)
{
    char why[256];
    rtde_source_input inputs[URRT_RTDE_IN_MAX_RECIPES];
    rtde_source_config rc = {.name = robot->cfg->name,
                             .vars = robot->cfg->recipe,
                             .optional = robot->cfg->recipe_optional,
                             .count = robot->cfg->recipe_count,
                             .frequency = robot->cfg->rtde_frequency,
                             .inputs = inputs};
    /* The [input]s' registers, one input recipe per frame (plc_in.h). */
    rc.input_count = plc_in_recipes(&robot->gw->cfg->can, robot->index, inputs, URRT_RTDE_IN_MAX_RECIPES);
    robot->rtde = rtde_source_new(&rc, why, sizeof why);
    if (robot->rtde == NULL) {
        urrt_log(URRT_LOG_ERR, "robot %s: %s", robot->cfg->name, why);
        return false;
    }
    return rtde_source_attach(robot->rtde, robot->link);
}

/* A robot's link: serviced, its socket kept registered, its deadline
 * noted, and a change of its state or freshness made news for the outputs.
 * With wait_until, the service waits in the link's read until then at most,
 * or, where the link cannot, does nothing and returns false. */
static bool service_robot(gw_robot *robot, uint64_t now, uint64_t wait_until);

static void robot_ready(void *ctx, uint64_t now_us)
{
    (void)service_robot(ctx, now_us, 0);
}

bool gw_init(gateway *gw, const gw_config *cfg)
{
    memset(gw, 0, sizeof *gw);
    gw->cfg = cfg;
    gw->summary = cfg->summary;
    gw->epoll_fd = epoll_create1(EPOLL_CLOEXEC);
    if (gw->epoll_fd < 0) {
        urrt_log(URRT_LOG_ERR, "epoll_create1: %s; raise the limit on open files (ulimit -n)", strerror(errno));
        return false;
    }
    gw->robots = calloc(cfg->robot_count, sizeof *gw->robots);
    gw->link_due = calloc(cfg->robot_count, sizeof *gw->link_due);
    if (gw->robots == NULL || gw->link_due == NULL) {
        urrt_log(URRT_LOG_ERR, "out of memory");
        gw_close(gw);
        return false;
    }
    gw->robot_count = cfg->robot_count;
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        gw_robot *robot = &gw->robots[i];
        robot->gw = gw;
        robot->index = i;
        robot->cfg = &cfg->robots[i];
        urrt_state_clear(&robot->state);
        gw_watch_init(&robot->watch, robot_ready, robot);
        robot->link = urrt_link_new(&robot->cfg->link);
        if (robot->link == NULL || (robot->cfg->source == GW_SOURCE_RTDE && !rtde_attach(robot))) {
            gw_close(gw);
            return false;
        }
    }
    return true;
}

bool gw_add_output(gateway *gw, const gw_output *output)
{
    if (gw->output_count == GW_MAX_OUTPUTS || output->packet == NULL || output->tick == NULL) {
        urrt_log(URRT_LOG_ERR, "output %s cannot be added", output->name);
        return false;
    }
    gw->outputs[gw->output_count++] = *output;
    return true;
}

static void print_summary(gateway *gw, uint64_t now_us)
{
    char line[1024];
    for (unsigned i = 0; i < gw->robot_count; i++) {
        const gw_robot *robot = &gw->robots[i];
        const urrt_link_stats *ls = urrt_link_get_stats(robot->link);
        int64_t age = gw_robot_data_age_us(robot, now_us);
        char age_text[32];
        int n;
        if (age < 0) {
            snprintf(age_text, sizeof age_text, "-");
        } else if (age < 10000) {
            snprintf(age_text, sizeof age_text, "%.2f ms", (double)age / 1000.0);
        } else {
            snprintf(age_text, sizeof age_text, "%.1f s", (double)age / 1e6);
        }
        n = snprintf(line, sizeof line, "%s %s%s age %s reconnects %" PRIu64 " resyncs %" PRIu64
                     " mismatches %" PRIu64 " late %" PRIu64 " |",
                     robot->cfg->name, urrt_link_state_name(urrt_link_get_state(robot->link)),
                     gw_robot_fresh(robot, now_us) ? "" : " (no data)", age_text, ls->reconnects,
                     ls->resyncs, robot->mismatches, robot->late_packets);
        for (unsigned o = 0; o < gw->output_count && n > 0 && (size_t)n < sizeof line; o++) {
            if (gw->outputs[o].summary != NULL) {
                n += gw->outputs[o].summary(gw->outputs[o].ctx, robot, now_us, line + n, sizeof line - (size_t)n);
            }
        }
        puts(line);
    }
    fflush(stdout);
}

void gw_watch_init(gw_watch *w, void (*ready)(void *ctx, uint64_t now_us), void *ctx)
{
    *w = (gw_watch){.ready = ready, .ctx = ctx, .fd = -1};
}

void gw_watch_set(gateway *gw, gw_watch *w, int fd, short events, uint64_t opened)
{
    struct epoll_event ev = {.events = ((events & POLLIN) != 0 ? (uint32_t)EPOLLIN : 0u) |
                                       ((events & POLLOUT) != 0 ? (uint32_t)EPOLLOUT : 0u),
                             .data.ptr = w};
    bool registered = w->fd >= 0 && fd == w->fd && opened == w->opened;
    if (registered && events == w->events) {
        return;
    }
    gw->watched -= w->fd >= 0 && w->events != 0 ? 1u : 0u;
    gw->watched += fd >= 0 && events != 0 ? 1u : 0u;
    /* Level-triggered: a link that stops at its read budget, or CAN at its
     * receive burst, is reported again at the next wait, whatever its owner
     * noted of what it left. Edge-triggered would spare one readiness check
     * per ready socket and wait: bench-gateway sees no difference. */
    if (fd >= 0 && epoll_ctl(gw->epoll_fd, registered ? EPOLL_CTL_MOD : EPOLL_CTL_ADD, fd, &ev) != 0 &&
        (registered || errno != EEXIST || epoll_ctl(gw->epoll_fd, EPOLL_CTL_MOD, fd, &ev) != 0)) {
        /* Still serviced at its deadlines, later than it could be. */
        urrt_log(URRT_LOG_ERR, "epoll_ctl (descriptor %d): %s", fd, strerror(errno));
    }
    w->fd = fd;
    w->events = events;
    w->opened = opened;
}

static bool service_robot(gw_robot *robot, uint64_t now, uint64_t wait_until)
{
    gateway *gw = robot->gw;
    urrt_link_state state = urrt_link_get_state(robot->link);
    bool fresh = gw_robot_fresh(robot, now);
    short events = 0;
    int fd;

    if (wait_until == 0) {
        urrt_link_service(robot->link, now, on_packet, robot);
    } else if (urrt_link_service_waiting(robot->link, wait_until, on_packet, robot)) {
        now = urrt_port_monotonic_us();
    } else {
        return false;
    }
    fd = urrt_link_poll_fd(robot->link, &events);
    gw_watch_set(gw, &robot->watch, fd, events, urrt_link_get_stats(robot->link)->sockets);
    gw->link_due[robot->index].due_us = urrt_link_deadline(robot->link);
    gw->link_due[robot->index].loop = gw->loops;
    if (gw->link_due[robot->index].due_us < gw->links_due_us) {
        gw->links_due_us = gw->link_due[robot->index].due_us;
    }
    if (state != urrt_link_get_state(robot->link) || fresh != gw_robot_fresh(robot, now)) {
        gw->news = true;
    }
    return true;
}

/* The robot whose socket, waiting for input alone, is all the loop waits
 * on, or NULL. */
static gw_robot *sole_reader(gateway *gw)
{
    gw_robot *robot = &gw->robots[0];
    return gw->robot_count == 1 && gw->watched == 1 && robot->watch.fd >= 0 && robot->watch.events == POLLIN
               ? robot
               : NULL;
}

/* The earliest deadline of the links, the outputs and the summary (not
 * the ticks of every output, tick_all_us). The outputs' are kept for
 * tick_outputs. */
static uint64_t next_deadline(gateway *gw)
{
    uint64_t deadline = gw->links_due_us;
    for (unsigned o = 0; o < gw->output_count; o++) {
        const gw_output *out = &gw->outputs[o];
        gw->output_due[o] = out->deadline != NULL ? out->deadline(out->ctx) : UINT64_MAX;
        deadline = gw->output_due[o] < deadline ? gw->output_due[o] : deadline;
    }
    if (gw->summary && gw->next_summary_us < deadline) {
        deadline = gw->next_summary_us;
    }
    return deadline;
}

/* Waits until a descriptor is ready or the deadline, and runs the ready
 * ones' owners; returns the time read after the wait. The ticks of every
 * output (tick_all_us) end a wait in epoll, not one in the sole robot's
 * read: a fixed moment there would need the read's timeout set anew as it
 * came near, a system call or two every GW_TICK_MAX_US, while the robot's
 * next packet brings the ticks a packet's period late (and a silent
 * robot's wait ends GW_TICK_MAX_US after it began at the latest). */
static uint64_t wait_and_service(gateway *gw, uint64_t deadline, uint64_t now)
{
    struct epoll_event events[GW_WAIT_EVENTS];
    gw_robot *sole = sole_reader(gw);
    uint64_t read_until = deadline < now + GW_TICK_MAX_US ? deadline : now + GW_TICK_MAX_US;
    int timeout_ms;
    int n;
    if (sole != NULL && service_robot(sole, now, read_until)) {
        return urrt_port_monotonic_us();
    }
    /* At most GW_TICK_MAX_US ahead, so the timeout fits an int; rounded
     * up: waking a little late is harmless, early wakes spin. */
    deadline = gw->tick_all_us < deadline ? gw->tick_all_us : deadline;
    timeout_ms = deadline <= now ? 0 : (int)((deadline - now + 999u) / 1000u);
    n = epoll_wait(gw->epoll_fd, events, GW_WAIT_EVENTS, timeout_ms);
    if (n < 0 && errno != EINTR) {
        urrt_log(URRT_LOG_ERR, "epoll_wait: %s", strerror(errno));
    }
    now = urrt_port_monotonic_us();
    for (int i = 0; i < n; i++) {
        gw_watch *w = events[i].data.ptr;
        w->ready(w->ctx, now);
    }
    return now;
}

/* The links whose deadline has passed and that no event brought, looked
 * for only once the earliest deadline noted has come; then that deadline
 * anew. A link's deadline moves later with every read (its silence
 * timeout) and is not followed there: the earliest noted is never later
 * than the true one, and a wake-up costs nothing per robot. */
static void service_due_links(gateway *gw, uint64_t now)
{
    uint64_t earliest = UINT64_MAX;
    if (now < gw->links_due_us) {
        return;
    }
    for (unsigned i = 0; i < gw->robot_count; i++) {
        if (gw->link_due[i].due_us <= now && gw->link_due[i].loop != gw->loops) {
            (void)service_robot(&gw->robots[i], now, 0);
        }
        earliest = gw->link_due[i].due_us < earliest ? gw->link_due[i].due_us : earliest;
    }
    gw->links_due_us = earliest;
}

static void tick_outputs(gateway *gw, uint64_t now)
{
    bool all = gw->news || now >= gw->tick_all_us;
    for (unsigned o = 0; o < gw->output_count; o++) {
        if (all || now >= gw->output_due[o]) {
            gw->outputs[o].tick(gw->outputs[o].ctx, now);
        }
    }
    if (all) {
        gw->news = false;
        gw->tick_all_us = now + GW_TICK_MAX_US;
    }
}

static void summary_if_due(gateway *gw, uint64_t now)
{
    if (gw->summary && now >= gw->next_summary_us) {
        print_summary(gw, now);
        gw->next_summary_us += 1000000u;
        if (gw->next_summary_us <= now) {
            gw->next_summary_us = now + 1000000u;
        }
    }
}

void gw_run(gateway *gw, volatile sig_atomic_t *running)
{
    uint64_t now = urrt_port_monotonic_us();

    gw->next_summary_us = now + 1000000u;
    gw->tick_all_us = now; /* every output ticks once at the start */
    gw->loops = 1;         /* link_due[].loop 0: not serviced yet */
    gw->links_due_us = 0;  /* every link is serviced at the start */
    while (*running) {
        service_due_links(gw, wait_and_service(gw, next_deadline(gw), now));
        /* The outputs judge freshness after the reads: a report must not
         * say "stale" about an instant before the packets just read. */
        now = urrt_port_monotonic_us();
        tick_outputs(gw, now);
        summary_if_due(gw, now);
        gw->loops++;
    }
}

void gw_close(gateway *gw)
{
    for (unsigned o = 0; o < gw->output_count; o++) {
        if (gw->outputs[o].close != NULL) {
            gw->outputs[o].close(gw->outputs[o].ctx);
        }
    }
    gw->output_count = 0;
    for (unsigned i = 0; i < gw->robot_count; i++) {
        urrt_link_free(gw->robots[i].link);
        rtde_source_free(gw->robots[i].rtde);
    }
    free(gw->robots);
    free(gw->link_due);
    gw->robots = NULL;
    gw->link_due = NULL;
    gw->robot_count = 0;
    if (gw->epoll_fd >= 0) {
        close(gw->epoll_fd);
        gw->epoll_fd = -1;
    }
}
