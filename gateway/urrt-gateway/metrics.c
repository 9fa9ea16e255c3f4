/* SPDX-License-Identifier: MIT */
/* metrics.c: see metrics.h. */
#define _GNU_SOURCE
#include "metrics.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "port.h"

/* A failing write is logged at once, then at most this often. */
#define METRICS_ERROR_LOG_US (60u * 1000000u)
/* The text of one robot at most, and of everything else. */
#define METRICS_ROBOT_BYTES 4096u
#define METRICS_BASE_BYTES 16384u
#define METRICS_INPUT_BYTES 1024u

struct gw_metrics {
    gateway *gw;
    const gw_config *cfg;
    lcm_out *lcm;
    can_out *can;
    plc_in *inputs;
    char *tmp_path;           /* PATH.tmp: same directory, so the rename is atomic */
    uint64_t interval_us;
    uint64_t next_us;
    uint64_t write_errors;
    uint64_t error_logged_us;
    char *buf;
    size_t size, len;
    bool overflow;            /* the text did not fit: not written (a bug of the sizes above) */
};

static void put(gw_metrics *m, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(gw_metrics *m, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (m->overflow) {
        return;
    }
    va_start(ap, fmt);
    n = vsnprintf(m->buf + m->len, m->size - m->len, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= m->size - m->len) {
        m->overflow = true;
        return;
    }
    m->len += (size_t)n;
}

static void family(gw_metrics *m, const char *name, const char *type, const char *help)
{
    put(m, "# HELP %s %s\n# TYPE %s %s\n", name, help, name, type);
}

/* One sample per robot of a robot's counter. */
typedef uint64_t (*robot_value_fn)(const gw_robot *robot);
static uint64_t connects(const gw_robot *r) { return urrt_link_get_stats(r->link)->connects; }
static uint64_t reconnects(const gw_robot *r) { return urrt_link_get_stats(r->link)->reconnects; }
static uint64_t packets(const gw_robot *r) { return urrt_link_get_stats(r->link)->packets; }
static uint64_t silences(const gw_robot *r) { return urrt_link_get_stats(r->link)->silences; }
static uint64_t late(const gw_robot *r) { return r->late_packets; }
static uint64_t mismatches(const gw_robot *r) { return r->mismatches; }

static void robot_counter(gw_metrics *m, const char *name, const char *help, robot_value_fn value)
{
    family(m, name, "counter", help);
    for (unsigned i = 0; i < m->gw->robot_count; i++) {
        const gw_robot *r = &m->gw->robots[i];
        put(m, "%s{robot=\"%s\"} %" PRIu64 "\n", name, r->cfg->name, value(r));
    }
}

static void robots(gw_metrics *m, uint64_t now)
{
    static const urrt_link_state states[] = {URRT_LINK_IDLE, URRT_LINK_CONNECTING, URRT_LINK_WAITING, URRT_LINK_UP};
    const gateway *gw = m->gw;
    family(m, "urrt_robot_up", "gauge", "1 while the robot's data flows (a packet came on this connection)");
    for (unsigned i = 0; i < gw->robot_count; i++) {
        put(m, "urrt_robot_up{robot=\"%s\"} %d\n", gw->robots[i].cfg->name,
            urrt_link_get_state(gw->robots[i].link) == URRT_LINK_UP);
    }
    family(m, "urrt_robot_link_state", "gauge", "1 for the state the robot's link is in, 0 for the others");
    for (unsigned i = 0; i < gw->robot_count; i++) {
        urrt_link_state s = urrt_link_get_state(gw->robots[i].link);
        for (size_t k = 0; k < sizeof states / sizeof states[0]; k++) {
            put(m, "urrt_robot_link_state{robot=\"%s\",state=\"%s\"} %d\n", gw->robots[i].cfg->name,
                urrt_link_state_name(states[k]), s == states[k]);
        }
    }
    family(m, "urrt_robot_data_age_seconds", "gauge",
           "how old the robot's newest data is at most; absent before the first packet");
    for (unsigned i = 0; i < gw->robot_count; i++) {
        int64_t age = gw_robot_data_age_us(&gw->robots[i], now);
        if (age >= 0) {
            put(m, "urrt_robot_data_age_seconds{robot=\"%s\"} %.6f\n", gw->robots[i].cfg->name, (double)age / 1e6);
        }
    }
    robot_counter(m, "urrt_robot_connects_total", "connections on which data came", connects);
    robot_counter(m, "urrt_robot_reconnects_total", "connects after a lost connection", reconnects);
    robot_counter(m, "urrt_robot_packets_total", "packets read from the robot", packets);
    robot_counter(m, "urrt_robot_stale_total", "connections dropped because the robot fell silent "
                  "(silence_timeout)", silences);
    robot_counter(m, "urrt_robot_late_packets_total", "packets not published: their data was older than "
                  "silence_timeout when read", late);
    robot_counter(m, "urrt_robot_mismatched_packets_total", "packets not of the configured version's length",
                  mismatches);
}

static void lcm(gw_metrics *m)
{
    const gateway *gw = m->gw;
    lcm_out_counts c[GW_MAX_ROBOTS];
    for (unsigned i = 0; i < gw->robot_count; i++) {
        lcm_out_get_counts(m->lcm, i, &c[i]);
    }
    family(m, "urrt_lcm_messages_total", "counter", "LCM messages published, per robot and channel");
    for (unsigned i = 0; i < gw->robot_count; i++) {
        for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
            put(m, "urrt_lcm_messages_total{robot=\"%s\",channel=\"%s\"} %" PRIu64 "\n", gw->robots[i].cfg->name,
                m->cfg->lcm.channel[k], c[i].published[k]);
        }
    }
    family(m, "urrt_lcm_send_errors_total", "counter", "LCM messages lost: publishing failed");
    for (unsigned i = 0; i < gw->robot_count; i++) {
        put(m, "urrt_lcm_send_errors_total{robot=\"%s\"} %" PRIu64 "\n", gw->robots[i].cfg->name, c[i].errors);
    }
    family(m, "urrt_lcm_stale_dropped_total", "counter", "LCM messages not published: the data was stale");
    for (unsigned i = 0; i < gw->robot_count; i++) {
        put(m, "urrt_lcm_stale_dropped_total{robot=\"%s\"} %" PRIu64 "\n", gw->robots[i].cfg->name,
            c[i].stale_dropped);
    }
}

static void can(gw_metrics *m)
{
    /* Label values in Prometheus' style: lower case, '_'. */
    static const struct { urrt_co_nmt state; const char *label; } states[] = {
        {URRT_CO_INITIALISING, "initialising"},
        {URRT_CO_PRE_OPERATIONAL, "pre_operational"},
        {URRT_CO_OPERATIONAL, "operational"},
        {URRT_CO_STOPPED, "stopped"},
    };
    can_out_info ci;
    can_out_get_info(m->can, &ci);
    family(m, "urrt_can_up", "gauge", "1 while the CAN interface is open and up");
    put(m, "urrt_can_up %d\n", ci.up);
    family(m, "urrt_can_frames_sent_total", "counter", "CAN frames the driver took");
    put(m, "urrt_can_frames_sent_total %" PRIu64 "\n", ci.link->sent);
    family(m, "urrt_can_frames_dropped_total", "counter", "CAN frames replaced, too old or lost to an outage");
    put(m, "urrt_can_frames_dropped_total %" PRIu64 "\n", ci.link->dropped);
    family(m, "urrt_can_send_errors_total", "counter", "CAN frames lost to an unexpected error");
    put(m, "urrt_can_send_errors_total %" PRIu64 "\n", ci.link->send_errors);
    family(m, "urrt_can_bus_off_recoveries_total", "counter", "recoveries from bus off");
    put(m, "urrt_can_bus_off_recoveries_total %" PRIu64 "\n", ci.link->bus_off);
    if (!ci.node) {
        return;
    }
    family(m, "urrt_canopen_nmt_state", "gauge", "1 for the CANopen node's NMT state, 0 for the others");
    for (size_t k = 0; k < sizeof states / sizeof states[0]; k++) {
        put(m, "urrt_canopen_nmt_state{state=\"%s\"} %d\n", states[k].label, ci.nmt == states[k].state);
    }
    family(m, "urrt_canopen_emcy_total", "counter", "EMCY frames the CANopen node sent");
    put(m, "urrt_canopen_emcy_total %" PRIu64 "\n", ci.emcys);
}

/* One sample per [input] of one of its counters. */
typedef uint64_t (*input_value_fn)(const plc_in_counts *c);
static uint64_t in_frames(const plc_in_counts *c) { return c->frames; }
static uint64_t in_bad(const plc_in_counts *c) { return c->bad_frames; }
static uint64_t in_refused(const plc_in_counts *c) { return c->refused; }
static uint64_t in_written(const plc_in_counts *c) { return c->written; }
static uint64_t in_silences(const plc_in_counts *c) { return c->silences; }
static uint64_t in_fresh(const plc_in_counts *c) { return c->fresh; }

static void input_family(gw_metrics *m, const char *name, const char *type, const char *help, input_value_fn value)
{
    family(m, name, type, help);
    for (size_t i = 0; i < plc_in_count(m->inputs); i++) {
        const struct can_map_frame *f = plc_in_frame(m->inputs, i);
        plc_in_counts c;
        plc_in_get_counts(m->inputs, i, &c);
        put(m, "%s{robot=\"%s\",input=\"%s\"} %" PRIu64 "\n", name, m->gw->robots[f->robot_index].cfg->name,
            f->name, value(&c));
    }
}

static void inputs(gw_metrics *m)
{
    input_family(m, "urrt_input_frames_total", "counter", "frames the PLC sent on the [input]'s id", in_frames);
    input_family(m, "urrt_input_bad_frames_total", "counter", "of them, not of the configured length or kind: not "
                 "used", in_bad);
    input_family(m, "urrt_input_refused_total", "counter", "values refused: outside min..max, or not one the "
                 "register takes", in_refused);
    input_family(m, "urrt_input_written_total", "counter", "RTDE input packages written with the [input]'s "
                 "registers", in_written);
    input_family(m, "urrt_input_silences_total", "counter", "times the PLC fell silent (timeout, CAN down, "
                 "bus-off)", in_silences);
    input_family(m, "urrt_input_fresh", "gauge", "1 while the [input]'s data is fresh", in_fresh);
    family(m, "urrt_input_register_refused", "gauge", "1 for the last input register the controller refused to "
           "let this client write, and why (in_use, not_found)");
    for (unsigned i = 0; i < m->gw->robot_count; i++) {
        const gw_robot *r = &m->gw->robots[i];
        char name[URRT_RTDE_NAME_MAX];
        int var = -1;
        int why = r->rtde != NULL ? rtde_source_input_refusal(r->rtde, &var) : 0;
        if (why != 0 && urrt_rtde_var_name(var, name, sizeof name) > 0) {
            put(m, "urrt_input_register_refused{robot=\"%s\",register=\"%s\",reason=\"%s\"} 1\n", r->cfg->name,
                name, why == URRT_RTDE_E_IN_USE ? "in_use" : "not_found");
        }
    }
}

static bool write_all(int fd, const char *buf, size_t len)
{
    while (len > 0) {
        ssize_t n = write(fd, buf, len);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            return false;
        }
        buf += n;
        len -= (size_t)n;
    }
    return true;
}

/* PATH.tmp, then renamed onto PATH; 0644 whatever the umask: the collector
 * runs as another user. False with errno set. */
static bool write_file(gw_metrics *m)
{
    int fd = open(m->tmp_path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
    bool ok;
    int saved;
    if (fd < 0) {
        return false;
    }
    ok = fchmod(fd, 0644) == 0 && write_all(fd, m->buf, m->len);
    saved = errno;
    ok = close(fd) == 0 && ok;
    if (ok && rename(m->tmp_path, m->cfg->metrics_file) == 0) {
        return true;
    }
    saved = ok ? errno : saved;
    unlink(m->tmp_path);
    errno = saved;
    return false;
}

static void on_tick(void *ctx, uint64_t now_us)
{
    gw_metrics *m = ctx;
    if (now_us < m->next_us) {
        return;
    }
    m->next_us = now_us + m->interval_us;
    m->len = 0;
    m->overflow = false;
    robots(m, now_us);
    lcm(m);
    if (m->can != NULL) {
        can(m);
    }
    if (m->inputs != NULL) {
        inputs(m);
    }
    family(m, "urrt_metrics_write_errors_total", "counter", "times this file could not be written");
    put(m, "urrt_metrics_write_errors_total %" PRIu64 "\n", m->write_errors);
    if (m->overflow) {
        errno = ENOBUFS;
    } else if (write_file(m)) {
        return;
    }
    m->write_errors++;
    if (m->write_errors == 1 || now_us >= m->error_logged_us + METRICS_ERROR_LOG_US) {
        urrt_log(URRT_LOG_WARNING, "metrics: cannot write %s (through %s): %s (%" PRIu64 " time%s so far); the "
                 "directory must exist and be writable by the gateway (docs/gateway.md, Metrics)",
                 m->cfg->metrics_file, m->tmp_path, strerror(errno), m->write_errors, m->write_errors == 1 ? "" : "s");
        m->error_logged_us = now_us;
    }
}

static void on_packet(void *ctx, gw_robot *robot, const gw_packet *pkt)
{
    (void)ctx, (void)robot, (void)pkt;
}

static uint64_t on_deadline(void *ctx)
{
    return ((const gw_metrics *)ctx)->next_us;
}

static void on_close(void *ctx)
{
    gw_metrics *m = ctx;
    free(m->tmp_path);
    free(m->buf);
    free(m);
}

gw_metrics *gw_metrics_new(gateway *gw, const gw_config *cfg, lcm_out *lcm_output, can_out *can_output,
                           plc_in *inputs_output)
{
    gw_metrics *m = calloc(1, sizeof *m);
    if (m == NULL || asprintf(&m->tmp_path, "%s.tmp", cfg->metrics_file) < 0) {
        urrt_log(URRT_LOG_ERR, "metrics: out of memory");
        free(m);
        return NULL;
    }
    m->size = METRICS_BASE_BYTES + (size_t)gw->robot_count * METRICS_ROBOT_BYTES +
              cfg->can.input_count * METRICS_INPUT_BYTES;
    if ((m->buf = malloc(m->size)) == NULL) {
        urrt_log(URRT_LOG_ERR, "metrics: out of memory");
        free(m->tmp_path);
        free(m);
        return NULL;
    }
    m->gw = gw;
    m->cfg = cfg;
    m->lcm = lcm_output;
    m->can = can_output;
    m->inputs = inputs_output;
    m->interval_us = (uint64_t)cfg->metrics_interval_ms * 1000u;
    m->next_us = urrt_port_monotonic_us(); /* the first file at once */
    return m;
}

gw_output gw_metrics_output(gw_metrics *m)
{
    gw_output o = {.name = "metrics", .ctx = m, .packet = on_packet, .tick = on_tick, .deadline = on_deadline,
                   .close = on_close};
    return o;
}
