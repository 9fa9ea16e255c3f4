/* SPDX-License-Identifier: MIT */
/* lcm_out.c: the LCM output of urrt-gateway (lcm_out.h). */
#define _GNU_SOURCE
#include "lcm_out.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/lcm.h>

#include "rtde_only.h"
#include "urrt_gateway_t.h"
#include "urrt_joints_t.h"
#include "urrt_rtde_t.h"
#include "urrt_state_t.h"
#include "urrt_status_t.h"
#include "urrt_tool_t.h"

/* Every message fits: the largest is a state_t with URRT_MAX_DOUBLES
 * columns (about 2.2 KiB) or a gateway_t with long names and counters. */
#define LCM_OUT_BUFFER 65536
#define LCM_OUT_MAX_COUNTERS 64
/* Publishing that fails for this long recreates the LCM instance. */
#define LCM_OUT_FAILING_RESET_US 2000000u
#define LCM_OUT_RETRY_MIN_MS 1000u
#define LCM_OUT_RETRY_MAX_MS 30000u
#define LCM_OUT_ERROR_LOG_US (10u * 1000000u)
/* Decimation: a packet this close before its slot still takes it, so that
 * rounding of the controller's clock does not push it to the next packet. */
#define LCM_OUT_SLOT_TOLERANCE_US 100

typedef struct lcm_robot {
    char *channel[GW_KIND_COUNT];
    /* NAME.RTDE: the rtde_values' elements, named once at start */
    char **rtde_names;
    double *rtde_values;
    int16_t rtde_count;
    bool scheduled[GW_KIND_COUNT];
    int64_t next_due_us[GW_KIND_COUNT]; /* controller time of the next slot */
    int64_t last_time_us;
    uint64_t published[GW_KIND_COUNT];
    uint64_t stale_dropped;           /* too old by the moment of sending: not published */
    uint64_t errors;
    gw_meter sent[GW_KIND_COUNT];    /* messages/s for the summary line */
    uint64_t report_due_us;
    uint64_t report_us;
    uint64_t report_packets;
    double packet_rate;
    bool reported_fresh;
} lcm_robot;

struct lcm_out {
    gateway *gw;
    const gw_lcm_config *cfg;
    lcm_t *lcm;
    uint64_t retry_us;
    uint32_t retry_ms;
    uint64_t create_failures;
    uint64_t failing_since_us;    /* 0 while publishing works */
    uint64_t errors_total;
    uint64_t errors_logged;
    uint64_t error_log_us;
    lcm_robot *robots;
    /* The robots' earliest report or stale moment as of the last tick,
     * lowered by each packet (one robot's: set by each): never later than
     * the true one, so that the deadline the loop asks at every wake-up
     * costs nothing per robot (a tick that comes early finds nothing due
     * and looks again). */
    uint64_t robots_due_us;
    uint8_t *buf;
    /* Messages are filled in place, so that nothing is built per packet. */
    urrt_state_t state;
    urrt_joints_t joints;
    urrt_tool_t tool;
    urrt_status_t status;
    urrt_rtde_t rtde;
    urrt_gateway_t report;
    double extra[URRT_MAX_DOUBLES];
    gw_counter counters[LCM_OUT_MAX_COUNTERS];
    char *counter_names[LCM_OUT_MAX_COUNTERS];
    int64_t counter_values[LCM_OUT_MAX_COUNTERS];
    char counter_text[GW_KIND_COUNT][32];
};

/* ---- opening and publishing ---------------------------------------------------- */

static void try_open(lcm_out *out, uint64_t now_us)
{
    out->lcm = lcm_create(out->cfg->url);
    if (out->lcm != NULL) {
        urrt_log(out->create_failures > 0 ? URRT_LOG_NOTICE : URRT_LOG_INFO, "lcm: publishing on %s",
                 out->cfg->url);
        out->create_failures = 0;
        out->retry_ms = LCM_OUT_RETRY_MIN_MS;
        out->failing_since_us = 0;
        return;
    }
    out->create_failures++;
    if (out->create_failures == 1 || out->create_failures % 10 == 0) {
        urrt_log(URRT_LOG_ERR,
                 "lcm: cannot open %s (%" PRIu64 " attempts); retrying every %u s. For udpm the host "
                 "needs a multicast route, e.g. `ip route add 224.0.0.0/4 dev lo` on a box without a LAN",
                 out->cfg->url, out->create_failures, (unsigned)(out->retry_ms / 1000u));
    }
    out->retry_us = now_us + (uint64_t)out->retry_ms * 1000u;
    out->retry_ms = out->retry_ms * 2u > LCM_OUT_RETRY_MAX_MS ? LCM_OUT_RETRY_MAX_MS : out->retry_ms * 2u;
}

static void publish_failed(lcm_out *out, gw_robot *robot, const char *channel, const char *why,
                           uint64_t now_us)
{
    lcm_robot *lr = &out->robots[robot->index];
    lr->errors++;
    out->errors_total++;
    snprintf(robot->last_error, sizeof robot->last_error, "lcm: %s: %s", channel, why);
    if (out->errors_logged == 0 || now_us >= out->error_log_us + LCM_OUT_ERROR_LOG_US) {
        urrt_log(URRT_LOG_WARNING, "lcm: publishing %s failed: %s (%" PRIu64 " messages lost so far)",
                 channel, why, out->errors_total);
        out->errors_logged = out->errors_total;
        out->error_log_us = now_us;
    }
    if (out->lcm == NULL) {
        return;
    }
    if (out->failing_since_us == 0) {
        out->failing_since_us = now_us;
    } else if (now_us - out->failing_since_us >= LCM_OUT_FAILING_RESET_US) {
        urrt_log(URRT_LOG_WARNING, "lcm: publishing has failed for %u s: reopening %s",
                 (unsigned)(LCM_OUT_FAILING_RESET_US / 1000000u), out->cfg->url);
        lcm_destroy(out->lcm);
        out->lcm = NULL;
        out->retry_ms = LCM_OUT_RETRY_MIN_MS;
        out->retry_us = now_us;
        out->failing_since_us = 0;
    }
}

static void publish(lcm_out *out, gw_robot *robot, gw_kind kind, int length, uint64_t now_us)
{
    lcm_robot *lr = &out->robots[robot->index];
    const char *channel = lr->channel[kind];
    if (length < 0) {
        publish_failed(out, robot, channel, "message does not fit the encode buffer", now_us);
        return;
    }
    if (out->lcm == NULL) {
        publish_failed(out, robot, channel, "LCM is not open", now_us);
        return;
    }
    if (lcm_publish(out->lcm, channel, out->buf, (unsigned)length) != 0) {
        publish_failed(out, robot, channel, strerror(errno), now_us);
        return;
    }
    lr->published[kind]++;
    gw_meter_event(&lr->sent[kind], now_us);
    if (out->failing_since_us != 0) {
        urrt_log(URRT_LOG_NOTICE, "lcm: publishing works again (%" PRIu64 " messages lost)", out->errors_total);
        out->failing_since_us = 0;
        out->errors_logged = 0;
    }
}

/* ---- per packet ---------------------------------------------------------------- */

/* A packet's message is sent only if its data is still fresh now, just
 * before the send: the process may have been stopped or preempted since
 * the packet was read, or the messages before it may have taken long. */
static void publish_data(lcm_out *out, gw_robot *robot, gw_kind kind, int length, const gw_packet *pkt)
{
    uint64_t now_us = urrt_port_monotonic_us();
    if (!gw_robot_data_fresh(robot, pkt->data_us, now_us)) {
        out->robots[robot->index].stale_dropped++;
        return;
    }
    publish(out, robot, kind, length, now_us);
}

/* Whether this packet takes a slot of kind: every packet, or the first
 * packet at or after each 1/hz step of the controller's clock. A gap or a
 * clock that went back (a controller restart) starts the grid again. */
static bool due(const gw_rate *rate, lcm_robot *lr, gw_kind kind, int64_t t_us)
{
    int64_t period;
    if (rate->mode == GW_RATE_OFF) {
        return false;
    }
    if (rate->mode == GW_RATE_EVERY) {
        return true;
    }
    period = (int64_t)llround(1e6 / rate->hz);
    if (!lr->scheduled[kind] || t_us < lr->last_time_us || t_us >= lr->next_due_us[kind] + period) {
        lr->scheduled[kind] = true;
        lr->next_due_us[kind] = t_us + period;
        return true;
    }
    if (t_us + LCM_OUT_SLOT_TOLERANCE_US >= lr->next_due_us[kind]) {
        lr->next_due_us[kind] += period;
        return true;
    }
    return false;
}

static int16_t enum_number(const urrt_state *st, urrt_field_id id, const double *value)
{
    if (!urrt_has(st, id) || isnan(*value)) {
        return URRT_STATUS_T_ABSENT;
    }
    if (*value <= -32767.0) {
        return -32767;
    }
    if (*value >= 32767.0) {
        return 32767;
    }
    return (int16_t)lrint(*value);
}

static char *enum_name(const urrt_state *st, urrt_field_id id, double value)
{
    if (!urrt_has(st, id)) {
        return (char *)"";
    }
    return (char *)urrt_enum_name(urrt_field_enum(id, st->generation), value);
}

static int64_t bits(const urrt_state *st, urrt_field_id id, double value)
{
    uint64_t mask;
    if (!urrt_has(st, id) || urrt_bitmask(value, &mask) != URRT_OK || mask > (uint64_t)INT64_MAX) {
        return URRT_STATUS_T_NO_BITS;
    }
    return (int64_t)mask;
}

/* Same name, same size: the .lcm files and urrt.h cannot drift apart. */
#define COPY(msg, st, name)                                                                     \
    do {                                                                                        \
        _Static_assert(sizeof((msg)->name) == sizeof((st)->name), "size of " #name " differs"); \
        memcpy(&(msg)->name, (st)->name, sizeof((msg)->name));                                  \
    } while (0)

static int encode_state(lcm_out *out, const gw_packet *pkt)
{
    urrt_state_t *msg = &out->state;
    const urrt_state *st = pkt->state;
    /* An RTDE package's size is its recipe's: no RealTime version has it. */
    const char *versions = pkt->rtde == NULL ? urrt_versions_of(st->length) : NULL;
    msg->utime = (int64_t)pkt->rx_wall_us;
    msg->length = (int32_t)st->length;
    msg->doubles = (int16_t)st->doubles;
    msg->generation = (int8_t)st->generation;
    msg->versions = (char *)(versions != NULL ? versions : "");
    msg->present = (int64_t)st->present;
    msg->sequence = (int64_t)pkt->sequence;
#define COPY_FIELD(ID, name, count, c1, c3, unit, since, desc) COPY(msg, st, name);
    URRT_FIELDS(COPY_FIELD)
#undef COPY_FIELD
    msg->extra_columns = (int16_t)st->extra_columns;
    for (unsigned i = 0; i < st->extra_columns; i++) {
        urrt_read_column(pkt->bytes, pkt->length, URRT_WIRE_COLUMNS + 1u + i, &out->extra[i]);
    }
    msg->extra = out->extra;
    return urrt_state_t_encode(out->buf, 0, LCM_OUT_BUFFER, msg);
}

static int encode_joints(lcm_out *out, const gw_packet *pkt)
{
    urrt_joints_t *msg = &out->joints;
    const urrt_state *st = pkt->state;
    msg->utime = (int64_t)pkt->rx_wall_us;
    msg->controller_time = st->time[0];
    msg->sequence = (int64_t)pkt->sequence;
    COPY(msg, st, q_target);
    COPY(msg, st, qd_target);
    COPY(msg, st, qdd_target);
    COPY(msg, st, i_target);
    COPY(msg, st, m_target);
    COPY(msg, st, q_actual);
    COPY(msg, st, qd_actual);
    COPY(msg, st, i_actual);
    COPY(msg, st, i_control);
    COPY(msg, st, v_actual);
    COPY(msg, st, motor_temperatures);
    return urrt_joints_t_encode(out->buf, 0, LCM_OUT_BUFFER, msg);
}

static int encode_tool(lcm_out *out, const gw_packet *pkt)
{
    urrt_tool_t *msg = &out->tool;
    const urrt_state *st = pkt->state;
    msg->utime = (int64_t)pkt->rx_wall_us;
    msg->controller_time = st->time[0];
    msg->sequence = (int64_t)pkt->sequence;
    COPY(msg, st, tool_vector_actual);
    COPY(msg, st, tcp_speed_actual);
    COPY(msg, st, tool_vector_target);
    COPY(msg, st, tcp_speed_target);
    COPY(msg, st, tcp_force);
    COPY(msg, st, tool_accelerometer);
    COPY(msg, st, elbow_position);
    COPY(msg, st, elbow_velocity);
    COPY(msg, st, payload_mass);
    COPY(msg, st, payload_cog);
    COPY(msg, st, payload_inertia);
    COPY(msg, st, tool_vector);
    COPY(msg, st, tcp_speed);
    return urrt_tool_t_encode(out->buf, 0, LCM_OUT_BUFFER, msg);
}

static int encode_status(lcm_out *out, const gw_packet *pkt)
{
    urrt_status_t *msg = &out->status;
    const urrt_state *st = pkt->state;
    msg->utime = (int64_t)pkt->rx_wall_us;
    msg->controller_time = st->time[0];
    msg->sequence = (int64_t)pkt->sequence;
    msg->generation = (int8_t)st->generation;
    msg->robot_mode = enum_number(st, URRT_F_ROBOT_MODE, st->robot_mode);
    msg->robot_mode_name = enum_name(st, URRT_F_ROBOT_MODE, st->robot_mode[0]);
    for (unsigned j = 0; j < 6; j++) {
        msg->joint_modes[j] = enum_number(st, URRT_F_JOINT_MODES, &st->joint_modes[j]);
        msg->joint_mode_names[j] = enum_name(st, URRT_F_JOINT_MODES, st->joint_modes[j]);
    }
    msg->safety_mode = enum_number(st, URRT_F_SAFETY_MODE, st->safety_mode);
    msg->safety_mode_name = enum_name(st, URRT_F_SAFETY_MODE, st->safety_mode[0]);
    msg->safety_status = enum_number(st, URRT_F_SAFETY_STATUS, st->safety_status);
    msg->safety_status_name = enum_name(st, URRT_F_SAFETY_STATUS, st->safety_status[0]);
    msg->program_state = enum_number(st, URRT_F_PROGRAM_STATE, st->program_state);
    msg->program_state_name = enum_name(st, URRT_F_PROGRAM_STATE, st->program_state[0]);
    msg->digital_inputs = bits(st, URRT_F_DIGITAL_INPUT_BITS, st->digital_input_bits[0]);
    msg->digital_outputs = bits(st, URRT_F_DIGITAL_OUTPUTS, st->digital_outputs[0]);
    msg->speed_scaling = st->speed_scaling[0];
    msg->v_main = st->v_main[0];
    msg->v_robot = st->v_robot[0];
    msg->i_robot = st->i_robot[0];
    msg->linear_momentum_norm = st->linear_momentum_norm[0];
    msg->controller_timer = st->controller_timer[0];
    return urrt_status_t_encode(out->buf, 0, LCM_OUT_BUFFER, msg);
}

/* NAME.RTDE: the package's RTDE-only values, each element a double read as
 * the CAN output reads it (rtde_only: exact for every type but a 64-bit
 * integer past 2^53; NaN where the package did not have it). */
static int encode_rtde(lcm_out *out, gw_robot *robot, const gw_packet *pkt)
{
    lcm_robot *lr = &out->robots[robot->index];
    urrt_rtde_t *msg = &out->rtde;
    const gw_robot_config *cfg = robot->cfg;
    unsigned n = 0;
    msg->utime = (int64_t)pkt->rx_wall_us;
    msg->controller_time = pkt->state->time[0];
    msg->sequence = (int64_t)pkt->sequence;
    for (size_t i = 0; i < cfg->rtde_value_count; i++) {
        for (unsigned e = 0; e < rtde_only_elements(cfg->rtde_values[i]); e++) {
            lr->rtde_values[n++] = rtde_only_element(pkt->rtde, cfg->rtde_values[i], e);
        }
    }
    msg->count = lr->rtde_count;
    msg->names = lr->rtde_names;
    msg->values = lr->rtde_values;
    return urrt_rtde_t_encode(out->buf, 0, LCM_OUT_BUFFER, msg);
}

/* NAME.RTDE's element names: "safety_status_bits", "tcp_offset[3]". */
static bool name_rtde_values(lcm_robot *lr, const gw_robot_config *cfg)
{
    unsigned total = 0, n = 0;
    for (size_t i = 0; i < cfg->rtde_value_count; i++) {
        total += rtde_only_elements(cfg->rtde_values[i]);
    }
    lr->rtde_names = calloc(total + 1, sizeof *lr->rtde_names);
    lr->rtde_values = calloc(total + 1, sizeof *lr->rtde_values);
    if (lr->rtde_names == NULL || lr->rtde_values == NULL) {
        return false;
    }
    for (size_t i = 0; i < cfg->rtde_value_count; i++) {
        char name[URRT_RTDE_NAME_MAX];
        unsigned count = rtde_only_elements(cfg->rtde_values[i]);
        urrt_rtde_var_name(cfg->rtde_values[i], name, sizeof name);
        for (unsigned e = 0; e < count; e++) {
            int r = count == 1 ? asprintf(&lr->rtde_names[n], "%s", name)
                               : asprintf(&lr->rtde_names[n], "%s[%u]", name, e);
            if (r < 0) {
                lr->rtde_names[n] = NULL;
                return false;
            }
            n++;
        }
    }
    lr->rtde_count = (int16_t)total;
    return true;
}

/* When a robot's data goes stale (UINT64_MAX: it has none). */
static uint64_t stale_us(const gw_robot *robot)
{
    return robot->data_us != 0 ? robot->data_us + (uint64_t)robot->cfg->link.silence_timeout_ms * 1000u + 1u
                               : UINT64_MAX;
}

static void on_packet(void *ctx, gw_robot *robot, const gw_packet *pkt)
{
    lcm_out *out = ctx;
    lcm_robot *lr = &out->robots[robot->index];
    const gw_rate *rates = out->cfg->rate;
    int64_t t_us;
    /* The controller's clock paces decimation; should it be unreadable, the
     * host's clock does. */
    if (urrt_time_us(pkt->state->time[0], &t_us) != URRT_OK) {
        t_us = (int64_t)pkt->rx_us;
    }

    if (due(&rates[GW_KIND_STATE], lr, GW_KIND_STATE, t_us)) {
        publish_data(out, robot, GW_KIND_STATE, encode_state(out, pkt), pkt);
    }
    if (due(&rates[GW_KIND_JOINTS], lr, GW_KIND_JOINTS, t_us)) {
        publish_data(out, robot, GW_KIND_JOINTS, encode_joints(out, pkt), pkt);
    }
    if (due(&rates[GW_KIND_TOOL], lr, GW_KIND_TOOL, t_us)) {
        publish_data(out, robot, GW_KIND_TOOL, encode_tool(out, pkt), pkt);
    }
    if (due(&rates[GW_KIND_STATUS], lr, GW_KIND_STATUS, t_us)) {
        publish_data(out, robot, GW_KIND_STATUS, encode_status(out, pkt), pkt);
    }
    if (pkt->rtde != NULL && lr->rtde_count > 0 && due(&rates[GW_KIND_RTDE], lr, GW_KIND_RTDE, t_us)) {
        publish_data(out, robot, GW_KIND_RTDE, encode_rtde(out, robot, pkt), pkt);
    }
    lr->last_time_us = t_us;
    if (lr->reported_fresh) {
        uint64_t stale = stale_us(robot);
        /* One robot's due moment is the earliest: set anew, it moves on
         * with the data, so that a loop waiting in the robot's read needs
         * no new timeout for an old one coming near. */
        if (out->gw->robot_count == 1) {
            out->robots_due_us = lr->report_due_us;
        }
        out->robots_due_us = stale < out->robots_due_us ? stale : out->robots_due_us;
    }
}

/* ---- the gateway report ---------------------------------------------------------- */

static void report(lcm_out *out, gw_robot *robot, uint64_t now_us)
{
    lcm_robot *lr = &out->robots[robot->index];
    urrt_gateway_t *msg = &out->report;
    const urrt_link_stats *ls = urrt_link_get_stats(robot->link);
    urrt_link_state state = urrt_link_get_state(robot->link);
    const char *versions = ls->last_length != 0 ? urrt_versions_of(ls->last_length) : NULL;
    char controller[64];
    uint64_t published = 0;
    unsigned n;

    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        published += lr->published[k];
    }
    msg->utime = (int64_t)gw_wall_us(now_us); /* the instant data_fresh is judged at */
    msg->robot = robot->cfg->name;
    msg->host = robot->cfg->host;
    msg->port = robot->cfg->port;
    msg->link_state = (int8_t)state;
    msg->link_state_name = (char *)urrt_link_state_name(state);
    msg->data_fresh = gw_robot_fresh(robot, now_us);
    msg->data_age_us = gw_robot_data_age_us(robot, now_us);
    msg->expected = robot->cfg->expected;
    msg->length = (int32_t)ls->last_length;
    msg->versions = (char *)(versions != NULL ? versions : "");
    msg->generation = (int8_t)(ls->last_length != 0 ? urrt_generation_of(ls->last_length) : URRT_GEN_UNKNOWN);
    if (robot->rtde != NULL) {
        /* RTDE names the controller's version itself; its package sizes are the recipe's. */
        const uint32_t *v = rtde_source_session(robot->rtde)->controller;
        snprintf(controller, sizeof controller, v[0] != 0 ? "%u.%u.%u.%u" : "", (unsigned)v[0], (unsigned)v[1],
                 (unsigned)v[2], (unsigned)v[3]);
        msg->versions = controller;
        msg->generation = (int8_t)(v[0] != 0 ? URRT_GEN_3X : URRT_GEN_UNKNOWN);
    }
    /* Over at least half a second: reports sent early, when the data starts
     * or stops, would give a rate of a few packets in a few microseconds. */
    if (lr->report_us == 0) {
        lr->report_us = now_us;
        lr->report_packets = ls->packets;
    } else if (now_us - lr->report_us >= 500000u) {
        lr->packet_rate = (double)(ls->packets - lr->report_packets) * 1e6 / (double)(now_us - lr->report_us);
        lr->report_us = now_us;
        lr->report_packets = ls->packets;
    }
    msg->packet_rate = lr->packet_rate;
    msg->packets = (int64_t)ls->packets;
    msg->bytes = (int64_t)ls->bytes;
    msg->connects = (int64_t)ls->connects;
    msg->reconnects = (int64_t)ls->reconnects;
    msg->disconnects = (int64_t)ls->disconnects;
    msg->connect_failures = (int64_t)ls->connect_failures;
    msg->silences = (int64_t)ls->silences;
    msg->resyncs = (int64_t)ls->resyncs;
    msg->skipped_bytes = (int64_t)ls->skipped;
    msg->partial_drops = (int64_t)ls->partial_drops;
    msg->version_mismatches = (int64_t)robot->mismatches;
    msg->published = (int64_t)published;
    msg->publish_errors = (int64_t)lr->errors;
    msg->last_error = robot->last_error;
    n = gw_counters(out->gw, robot, out->counters, LCM_OUT_MAX_COUNTERS);
    for (unsigned i = 0; i < n; i++) {
        out->counter_names[i] = (char *)out->counters[i].name;
        out->counter_values[i] = (int64_t)out->counters[i].value;
    }
    msg->n_counters = (int16_t)n;
    msg->counter_names = out->counter_names;
    msg->counter_values = out->counter_values;
    lr->reported_fresh = msg->data_fresh;
    publish(out, robot, GW_KIND_GATEWAY, urrt_gateway_t_encode(out->buf, 0, LCM_OUT_BUFFER, msg), now_us);
}

static void on_tick(void *ctx, uint64_t now_us)
{
    lcm_out *out = ctx;
    const gw_rate *rate = &out->cfg->rate[GW_KIND_GATEWAY];
    uint64_t period_us = rate->mode == GW_RATE_HZ ? (uint64_t)llround(1e6 / rate->hz) : 0;

    if (out->lcm == NULL && now_us >= out->retry_us) {
        try_open(out, now_us);
    }
    if (period_us == 0) {
        return;
    }
    for (unsigned i = 0; i < out->gw->robot_count; i++) {
        gw_robot *robot = &out->gw->robots[i];
        lcm_robot *lr = &out->robots[i];
        /* Reports come on their period, and at once when the data stops or
         * starts, so that a subscriber need not wait for the next one. */
        if (now_us >= lr->report_due_us || gw_robot_fresh(robot, now_us) != lr->reported_fresh) {
            report(out, robot, now_us);
            lr->report_due_us = lr->report_due_us + period_us > now_us ? lr->report_due_us + period_us
                                                                      : now_us + period_us;
        }
    }
    out->robots_due_us = UINT64_MAX;
    for (unsigned i = 0; i < out->gw->robot_count; i++) {
        const lcm_robot *lr = &out->robots[i];
        /* The moment the data goes stale is news too. */
        uint64_t stale = lr->reported_fresh ? stale_us(&out->gw->robots[i]) : UINT64_MAX;
        uint64_t d = lr->report_due_us < stale ? lr->report_due_us : stale;
        out->robots_due_us = d < out->robots_due_us ? d : out->robots_due_us;
    }
}

static uint64_t on_deadline(void *ctx)
{
    lcm_out *out = ctx;
    uint64_t d = out->lcm == NULL ? out->retry_us : UINT64_MAX;
    if (out->cfg->rate[GW_KIND_GATEWAY].mode == GW_RATE_HZ && out->robots_due_us < d) {
        d = out->robots_due_us;
    }
    return d;
}

static unsigned on_counters(void *ctx, const gw_robot *robot, gw_counter *counters, unsigned max)
{
    lcm_out *out = ctx;
    const lcm_robot *lr = &out->robots[robot->index];
    unsigned n = 0;
    for (unsigned k = 0; k < GW_KIND_COUNT && n < max; k++) {
        counters[n].name = out->counter_text[k];
        counters[n].value = lr->published[k];
        n++;
    }
    if (n < max) {
        counters[n++] = (gw_counter){"lcm.stale_dropped", lr->stale_dropped};
    }
    return n;
}

static int on_summary(void *ctx, const gw_robot *robot, uint64_t now_us, char *buf, size_t size)
{
    lcm_out *out = ctx;
    lcm_robot *lr = &out->robots[robot->index];
    size_t n = 0;
    for (unsigned k = 0; k < GW_KIND_COUNT && n < size; k++) {
        double rate = gw_meter_rate(&lr->sent[k], now_us);
        if (out->cfg->rate[k].mode == GW_RATE_OFF || (k == GW_KIND_RTDE && lr->rtde_count == 0)) {
            continue;
        }
        if (rate < 0) {
            n += (size_t)snprintf(buf + n, size - n, " %s -/s", lr->channel[k]); /* not measured yet */
        } else {
            /* A slow channel with its tenths: 1.0/s, 0.5/s; a fast one as 500/s. */
            n += (size_t)snprintf(buf + n, size - n, rate < 9.95 ? " %s %.1f/s" : " %s %.0f/s", lr->channel[k], rate);
        }
    }
    if (n < size) {
        n += (size_t)snprintf(buf + n, size - n, " | stale %" PRIu64 " lost %" PRIu64 "%s", lr->stale_dropped, lr->errors,
                              out->lcm == NULL ? " (LCM not open)" : "");
    }
    return n < size ? (int)n : (int)size - 1;
}

static void on_close(void *ctx)
{
    lcm_out *out = ctx;
    if (out->lcm != NULL) {
        lcm_destroy(out->lcm);
    }
    for (unsigned i = 0; i < out->gw->robot_count; i++) {
        for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
            free(out->robots[i].channel[k]);
        }
        for (int16_t e = 0; out->robots[i].rtde_names != NULL && e <= out->robots[i].rtde_count; e++) {
            free(out->robots[i].rtde_names[e]);
        }
        free(out->robots[i].rtde_names);
        free(out->robots[i].rtde_values);
    }
    free(out->robots);
    free(out->buf);
    free(out);
}

lcm_out *lcm_out_new(gateway *gw, const gw_lcm_config *cfg)
{
    lcm_out *out = calloc(1, sizeof *out);
    if (out == NULL) {
        return NULL;
    }
    out->gw = gw;
    out->cfg = cfg;
    out->buf = malloc(LCM_OUT_BUFFER);
    out->robots = calloc(gw->robot_count, sizeof *out->robots);
    if (out->buf == NULL || out->robots == NULL) {
        free(out->buf);
        free(out->robots);
        free(out);
        return NULL;
    }
    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        snprintf(out->counter_text[k], sizeof out->counter_text[k], "lcm.published.%s", gw_kind_name(k));
    }
    for (unsigned i = 0; i < gw->robot_count; i++) {
        for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
            if (asprintf(&out->robots[i].channel[k], "%s.%s", gw->robots[i].cfg->name, cfg->channel[k]) < 0) {
                out->robots[i].channel[k] = NULL;
                on_close(out);
                return NULL;
            }
        }
        if (!name_rtde_values(&out->robots[i], gw->robots[i].cfg)) {
            on_close(out);
            return NULL;
        }
    }
    out->retry_ms = LCM_OUT_RETRY_MIN_MS;
    try_open(out, urrt_port_monotonic_us());
    return out;
}

void lcm_out_get_counts(const lcm_out *out, unsigned robot, lcm_out_counts *counts)
{
    const lcm_robot *lr = &out->robots[robot];
    memcpy(counts->published, lr->published, sizeof counts->published);
    counts->errors = lr->errors;
    counts->stale_dropped = lr->stale_dropped;
}

gw_output lcm_out_output(lcm_out *out)
{
    return (gw_output){
        .name = "lcm",
        .ctx = out,
        .packet = on_packet,
        .tick = on_tick,
        .deadline = on_deadline,
        .counters = on_counters,
        .summary = on_summary,
        .close = on_close,
    };
}
