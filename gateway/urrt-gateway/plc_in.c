/* SPDX-License-Identifier: MIT */
/* plc_in.c: see plc_in.h. */
#include "plc_in.h"

#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_in.h"
#include "urrt_rtde_in.h"

/* A frame's log lines (refused values, wrong lengths) at most this often. */
#define PLC_IN_LOG_US (10u * 1000000u)

/* One [input]: its frame, its robot's session, and what the PLC last said
 * (lib's state of it: when it is fresh and its package due is lib's rule). */
struct plc_group {
    const struct can_map_frame *f;
    urrt_plcin_desc desc;     /* f as lib describes an input */
    uint16_t *vars;           /* desc's: the register of each signal */
    urrt_plcin st;
    gw_robot *robot;
    size_t recipe;            /* its input recipe's index in the robot's source */
    size_t input;             /* its index among the [input]s: with [canopen], RPDO input + 1 */
    uint64_t logged_us;       /* the last refused value or bad frame logged */
    plc_in_counts counts;
};

struct plc_in {
    const struct can_map *map;
    struct co_run *node;      /* with [canopen]: the [input]s are its RPDOs; NULL: plain frames */
    struct plc_group *groups;
    size_t count;
    uint64_t period_us;       /* 1 / inputs_min_rate */
    uint64_t bus_off_seen;
    uint64_t due_us;          /* the earliest timeout or refresh */
};

size_t plc_in_recipes(const struct can_map *map, size_t robot, rtde_source_input *out, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < map->input_count; i++) {
        if (map->inputs[i].robot_index == robot && n < max) {
            out[n].vars = map->inputs[i].regs;
            out[n++].count = map->inputs[i].reg_count;
        }
    }
    return n;
}

static urrt_rtde_in *recipe_of(const struct plc_group *g)
{
    return g->robot->rtde != NULL ? rtde_source_in(g->robot->rtde, g->recipe) : NULL;
}

static void names_of(const struct can_map_frame *f, char *out, size_t size)
{
    size_t used = 0;
    out[0] = '\0';
    for (size_t k = 0; k < f->reg_count && used < size; k++) {
        char name[URRT_RTDE_NAME_MAX];
        int w;
        (void)urrt_rtde_var_name(f->regs[k], name, sizeof name);
        w = snprintf(out + used, size - used, "%s%s", k ? ", " : "", name);
        used += w > 0 ? (size_t)w : 0;
    }
}

/* ---- sending ---------------------------------------------------------------------- */

/* Whether the group's package can go now: its robot's session streams with
 * the recipe accepted. */
static bool ready(const struct plc_group *g)
{
    return g->robot->rtde != NULL && rtde_source_input_ready(g->robot->rtde, g->recipe);
}

/* The session's number: the current values go at once to a new one. */
static uint32_t session_of(const struct plc_group *g)
{
    return g->robot->rtde != NULL ? (uint32_t)rtde_source_input_sessions(g->robot->rtde) : 0;
}

/* The package, when lib says it is due. One that cannot go now (a register
 * without a value, the robot link's queue full) is tried again a period
 * later; a session that is not ready is waited for: its start is news,
 * which ticks every output. */
static void send_due(plc_in *in, struct plc_group *g, uint64_t now_us)
{
    uint32_t session = session_of(g);
    bool sent;
    if (!urrt_plcin_due(&g->desc, &g->st, ready(g), session, now_us, in->period_us)) {
        return;
    }
    sent = rtde_source_send_input(g->robot->rtde, g->recipe) == 1;
    urrt_plcin_sent(&g->st, sent, session, now_us);
    g->counts.written += sent;
}

/* The earliest of the groups' deadlines: the output's, kept here so that
 * asking costs nothing. */
static void plan(plc_in *in)
{
    uint64_t due = UINT64_MAX;
    for (size_t i = 0; i < in->count; i++) {
        const struct plc_group *g = &in->groups[i];
        uint64_t d = urrt_plcin_deadline(&g->desc, &g->st, ready(g), in->period_us);
        due = d < due ? d : due;
    }
    in->due_us = due;
}

/* ---- silence ----------------------------------------------------------------------- */

/* The PLC fell silent (lib applied on_silence): counted and logged. */
static void said_silent(struct plc_group *g, const char *why)
{
    static const char *const does[] = {
        [URRT_PLCIN_STOP] = "nothing more is written (on_silence = stop): the robot program's "
                            "rtde_set_watchdog acts",
        [URRT_PLCIN_HOLD] = "their last values go on being written (on_silence = hold)",
        [URRT_PLCIN_VALUE] = "the on_silence value goes to them",
    };
    char names[512];
    g->counts.silences++;
    names_of(g->f, names, sizeof names);
    urrt_log(URRT_LOG_WARNING, "[input %s]: the PLC is silent (%s): %s: %s", g->f->name, why, names,
             does[g->f->silence]);
}

/* The PLC is silent for a reason of the gateway's (a timeout, the CAN link). */
static void fall_silent(struct plc_group *g, const char *why)
{
    /* on_silence value: one every register takes (can_map_finish checked it). */
    urrt_plcin_silent(&g->desc, &g->st, recipe_of(g));
    said_silent(g, why);
}

/* ---- receiving --------------------------------------------------------------------- */

static void log_limited(struct plc_group *g, uint64_t now_us, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void log_limited(struct plc_group *g, uint64_t now_us, const char *fmt, ...)
{
    char text[400];
    va_list ap;
    if (g->logged_us != 0 && now_us - g->logged_us < PLC_IN_LOG_US) {
        return;
    }
    g->logged_us = now_us;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    urrt_log(URRT_LOG_WARNING, "[input %s]: %s", g->f->name, text);
}

/* lib took what the PLC wrote: refusals counted and logged (at most every
 * PLC_IN_LOG_US), its return said, the package sent if it is due. */
static void took(plc_in *in, struct plc_group *g, size_t refused, bool was_silent, uint64_t now_us)
{
    if (refused > 0) {
        g->counts.refused += refused;
        log_limited(g, now_us, "%zu value%s refused (outside min..max, or not one the register takes): nothing is "
                    "written for %s until a good one comes (%" PRIu64 " refused so far)", refused,
                    refused == 1 ? "" : "s", refused == 1 ? "it" : "them", g->counts.refused);
    }
    if (was_silent) {
        urrt_log(URRT_LOG_NOTICE, "[input %s]: the PLC writes again", g->f->name);
    }
    send_due(in, g, now_us);
}

/* A frame's values, received at rx_us (see urrt_plcin_take). */
static void take_values(plc_in *in, struct plc_group *g, const uint64_t *raws, uint64_t rx_us)
{
    urrt_rtde_in *recipe = recipe_of(g);
    uint64_t now = urrt_port_monotonic_us();
    bool was_silent = g->st.ever && !g->st.fresh;
    if (recipe != NULL) {
        took(in, g, urrt_plcin_take(&g->desc, &g->st, recipe, raws, 0, rx_us < now ? rx_us : now), was_silent, now);
    }
}

static void take_frame(plc_in *in, struct plc_group *g, const urrt_can_frame *frame, uint64_t rx_us)
{
    uint64_t raws[URRT_PLCIN_MAX_SIGNALS];
    g->counts.frames++;
    if (!urrt_plcin_raws(&g->desc, frame->data, frame->len, frame->fd, raws)) {
        g->counts.bad_frames++;
        log_limited(g, urrt_port_monotonic_us(), "a %s frame of %u bytes on 0x%X, configured %s of %u: not used (%"
                    PRIu64 " so far)", frame->fd ? "CAN FD" : "classic", (unsigned)frame->len, (unsigned)frame->id,
                    g->f->fd ? "CAN FD" : "classic", (unsigned)g->f->len, g->counts.bad_frames);
        return;
    }
    take_values(in, g, raws, rx_us);
}

/* ---- through the CANopen node: its RPDOs and SDO writes ---------------------------- */

/* [input] g through the node: lib's look (urrt_plcin_node), its take
 * counted and logged as a frame's, its silence said. */
static void node_group(plc_in *in, struct plc_group *g, uint64_t now_us)
{
    static const char *const why_text[] = {
        [URRT_PLCIN_NOT_OPERATIONAL] = "the CANopen node is not OPERATIONAL",
        [URRT_PLCIN_RPDO_OFF] = "the manager switched the RPDO off (0x1400+n sub 1, bit 31)",
        [URRT_PLCIN_HEARTBEAT_LOST] = "the manager's heartbeat is lost (0x1016)",
    };
    urrt_plcin_rpdo rpdo = {co_run_node(in->node), (uint16_t)co_run_input_first_var(in->node, g->input),
                            (uint8_t)g->input};
    urrt_rtde_in *recipe = recipe_of(g);
    bool was_silent = g->st.ever && !g->st.fresh;
    urrt_plcin_look look;
    char buf[64];
    if (recipe == NULL) {
        return;
    }
    urrt_plcin_node(&g->desc, &rpdo, &g->st, recipe, now_us, &look);
    if (look.took) {
        g->counts.frames++;
        took(in, g, look.refused, was_silent, now_us);
    }
    if (look.why == URRT_PLCIN_NO_WRITE) {
        snprintf(buf, sizeof buf, "no RPDO%zu or SDO write for %u ms", g->input + 1u, (unsigned)g->f->timeout_ms);
        said_silent(g, buf);
    } else if (look.why != URRT_PLCIN_STILL) {
        said_silent(g, why_text[look.why]);
    }
}

void plc_in_node(void *ctx, uint64_t now_us)
{
    plc_in *in = ctx;
    for (size_t i = 0; in->node != NULL && i < in->count; i++) {
        node_group(in, &in->groups[i], now_us);
    }
    plan(in);
}

bool plc_in_on_frame(void *ctx, const urrt_can_frame *frame, uint64_t rx_us)
{
    plc_in *in = ctx;
    const struct can_map_frame *f = can_map_input_of(in->map, frame->id, frame->extended);
    if (f == NULL || in->node != NULL) {
        return false; /* with [canopen], the node takes its RPDOs */
    }
    take_frame(in, &in->groups[f - in->map->inputs], frame, rx_us);
    plan(in);
    return true;
}

void plc_in_link(void *ctx, bool up, uint64_t bus_off, uint64_t now_us)
{
    plc_in *in = ctx;
    const char *why = !up                          ? "the CAN interface is down"
                      : bus_off != in->bus_off_seen ? "the CAN controller went bus-off"
                                                    : NULL;
    (void)now_us;
    in->bus_off_seen = bus_off;
    for (size_t i = 0; why != NULL && i < in->count; i++) {
        if (in->groups[i].st.fresh) {
            fall_silent(&in->groups[i], why);
        }
    }
    plan(in);
}

/* ---- the output -------------------------------------------------------------------- */

static void on_tick(void *ctx, uint64_t now_us)
{
    plc_in *in = ctx;
    for (size_t i = 0; i < in->count; i++) {
        struct plc_group *g = &in->groups[i];
        if (in->node != NULL) {
            node_group(in, g, now_us);
        } else if (urrt_plcin_timed_out(&g->desc, &g->st, now_us)) {
            char why[64];
            snprintf(why, sizeof why, "no frame for %u ms", (unsigned)g->f->timeout_ms);
            fall_silent(g, why);
        }
        send_due(in, g, now_us);
    }
    plan(in);
}

/* Packets carry the robot's state; what the PLC wrote comes from the CAN link. */
static void on_packet(void *ctx, gw_robot *robot, const gw_packet *pkt)
{
    (void)ctx, (void)robot, (void)pkt;
}

static uint64_t on_deadline(void *ctx)
{
    return ((plc_in *)ctx)->due_us;
}

static unsigned on_counters(void *ctx, const gw_robot *robot, gw_counter *out, unsigned max)
{
    plc_in *in = ctx;
    uint64_t frames = 0, bad = 0, refused = 0, written = 0, silences = 0, in_use = 0, not_found = 0;
    unsigned groups = 0;
    for (size_t i = 0; i < in->count; i++) {
        const struct plc_group *g = &in->groups[i];
        const urrt_rtde_in *recipe = recipe_of(g);
        if (g->robot != robot) {
            continue;
        }
        groups++;
        frames += g->counts.frames;
        bad += g->counts.bad_frames;
        refused += g->counts.refused;
        written += g->counts.written;
        silences += g->counts.silences;
        in_use += recipe != NULL ? recipe->stats.in_use : 0;
        not_found += recipe != NULL ? recipe->stats.not_found : 0;
    }
    const gw_counter all[] = {
        {"inputs_frames", frames},     {"inputs_bad_frames", bad},  {"inputs_refused", refused},
        {"inputs_written", written},   {"inputs_silences", silences},
        {"inputs_busy", robot->rtde != NULL ? rtde_source_input_busy(robot->rtde) : 0},
        {"inputs_in_use", in_use},     {"inputs_not_found", not_found},
    };
    unsigned n = 0;
    for (; groups > 0 && n < max && n < sizeof all / sizeof all[0]; n++) {
        out[n] = all[n];
    }
    return n;
}

static int on_summary(void *ctx, const gw_robot *robot, uint64_t now_us, char *buf, size_t size)
{
    plc_in *in = ctx;
    unsigned fresh = 0, total = 0;
    uint64_t written = 0, refused = 0;
    (void)now_us;
    for (size_t i = 0; i < in->count; i++) {
        if (in->groups[i].robot == robot) {
            total++;
            fresh += in->groups[i].st.fresh;
            written += in->groups[i].counts.written;
            refused += in->groups[i].counts.refused;
        }
    }
    return total == 0 ? 0
                      : snprintf(buf, size, " | inputs %u/%u fresh, written %" PRIu64 ", refused %" PRIu64, fresh,
                                 total, written, refused);
}

static void on_close(void *ctx)
{
    plc_in *in = ctx;
    for (size_t i = 0; i < in->count; i++) {
        free(in->groups[i].vars);
    }
    free(in->groups);
    free(in);
}

plc_in *plc_in_new(gateway *gw, const struct can_map *map, struct co_run *node)
{
    plc_in *in = calloc(1, sizeof *in);
    size_t per_robot[GW_MAX_ROBOTS] = {0};
    if (in == NULL || (in->groups = calloc(map->input_count ? map->input_count : 1, sizeof *in->groups)) == NULL) {
        urrt_log(URRT_LOG_ERR, "PLC inputs: out of memory");
        free(in);
        return NULL;
    }
    in->map = map;
    in->node = node;
    in->count = map->input_count;
    in->period_us = (uint64_t)(1e6 / map->inputs_min_rate_hz);
    in->due_us = UINT64_MAX;
    for (size_t i = 0; i < in->count; i++) {
        struct plc_group *g = &in->groups[i];
        size_t r = map->inputs[i].robot_index;
        g->f = &map->inputs[i];
        g->vars = malloc((g->f->count ? g->f->count : 1) * sizeof *g->vars);
        if (g->vars == NULL) {
            urrt_log(URRT_LOG_ERR, "PLC inputs: out of memory");
            in->count = i;
            on_close(in);
            return NULL;
        }
        can_in_desc(g->f, g->vars, &g->desc);
        urrt_plcin_init(&g->st);
        g->robot = &gw->robots[r];
        g->recipe = per_robot[r]++;
        g->input = i;
    }
    return in;
}

gw_output plc_in_output(plc_in *in)
{
    gw_output o = {
        .name = "inputs",
        .ctx = in,
        .packet = on_packet,
        .tick = on_tick,
        .deadline = on_deadline,
        .counters = on_counters,
        .summary = on_summary,
        .close = on_close,
    };
    return o;
}

size_t plc_in_count(const plc_in *in)
{
    return in->count;
}

const struct can_map_frame *plc_in_frame(const plc_in *in, size_t i)
{
    return i < in->count ? in->groups[i].f : NULL;
}

void plc_in_get_counts(const plc_in *in, size_t i, plc_in_counts *out)
{
    memset(out, 0, sizeof *out);
    if (i < in->count) {
        *out = in->groups[i].counts;
        out->fresh = in->groups[i].st.fresh;
    }
}
