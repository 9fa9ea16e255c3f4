/* SPDX-License-Identifier: MIT */
/*
 * lcm_sub: a test subscriber built on the generated C types. Every message
 * on the channels matching REGEX is decoded with the type its fingerprint
 * names (a message no urrt type decodes is reported as such) and written as
 * one JSON object per line, with the channel, the type and every field.
 *
 *   lcm_sub URL REGEX SECONDS [READY_FILE]
 *   lcm_sub --fingerprints      each type's fingerprint, as encoded
 *
 * READY_FILE is created once the subscription is in place. Runs for SECONDS
 * and exits; SIGTERM/SIGINT end it early. Lines are written whole as each
 * message comes, so that a test can wait for the messages it needs. The
 * subscription queue holds what a test may receive in a burst: LCM's
 * default of 30 loses messages after a stopped gateway catches up, and a
 * test must compare what it received with what the gateway published.
 */
#define _GNU_SOURCE
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/lcm.h>

#include "urrt.h"
#include "urrt_gateway_t.h"
#include "urrt_joints_t.h"
#include "urrt_rtde_t.h"
#include "urrt_state_t.h"
#include "urrt_status_t.h"
#include "urrt_tool_t.h"

#define SUB_QUEUE 100000

static volatile sig_atomic_t running = 1;
static void on_signal(int sig) { (void)sig; running = 0; }

static FILE *out;
static unsigned long undecodable;

static void num(double v)
{
    if (isnan(v)) {
        fputs("NaN", out);
    } else if (isinf(v)) {
        fputs(v > 0 ? "Infinity" : "-Infinity", out);
    } else {
        fprintf(out, "%.17g", v);
    }
}

static void str(const char *s)
{
    fputc('"', out);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') {
            fputc('\\', out);
        }
        if ((unsigned char)*s < 0x20) {
            fprintf(out, "\\u%04x", *s);
        } else {
            fputc(*s, out);
        }
    }
    fputc('"', out);
}

#define D(m, f) (fputs(",\"" #f "\":", out), num((m)->f))
#define I(m, f) fprintf(out, ",\"" #f "\":%lld", (long long)(m)->f)
#define S(m, f) (fputs(",\"" #f "\":", out), str((m)->f))
#define DA(m, f)                                                          \
    do {                                                                  \
        fputs(",\"" #f "\":[", out);                                      \
        for (size_t i_ = 0; i_ < sizeof((m)->f) / sizeof((m)->f[0]); i_++) { \
            if (i_) fputc(',', out);                                      \
            num((m)->f[i_]);                                              \
        }                                                                 \
        fputc(']', out);                                                  \
    } while (0)
#define IA(m, f)                                                          \
    do {                                                                  \
        fputs(",\"" #f "\":[", out);                                      \
        for (size_t i_ = 0; i_ < sizeof((m)->f) / sizeof((m)->f[0]); i_++) \
            fprintf(out, "%s%lld", i_ ? "," : "", (long long)(m)->f[i_]); \
        fputc(']', out);                                                  \
    } while (0)
#define SA(m, f, n)                                                       \
    do {                                                                  \
        fputs(",\"" #f "\":[", out);                                      \
        for (int i_ = 0; i_ < (n); i_++) {                                \
            if (i_) fputc(',', out);                                      \
            str((m)->f[i_]);                                              \
        }                                                                 \
        fputc(']', out);                                                  \
    } while (0)

/* Scalars in state_t are the fields of count 1; the X-macro says which. */
static void state_fields(const urrt_state_t *m)
{
#define X_FIELD(ID, name, count, c1, c3, unit, since, desc)                 \
    do {                                                                    \
        const double *p_ = (const double *)(const void *)&m->name;         \
        size_t n_ = sizeof(m->name) / sizeof(double);                       \
        fputs(",\"" #name "\":", out);                                      \
        if (count == 1) {                                                   \
            num(p_[0]);                                                     \
        } else {                                                            \
            fputc('[', out);                                                \
            for (size_t i_ = 0; i_ < n_; i_++) {                            \
                if (i_) fputc(',', out);                                    \
                num(p_[i_]);                                                \
            }                                                               \
            fputc(']', out);                                                \
        }                                                                   \
    } while (0);
    URRT_FIELDS(X_FIELD)
#undef X_FIELD
}

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)user;
    const void *data = rbuf->data;
    int size = (int)rbuf->data_size;
    urrt_state_t st;
    urrt_joints_t jo;
    urrt_tool_t to;
    urrt_status_t su;
    urrt_gateway_t gw;
    urrt_rtde_t rt;

    fputs("{\"ch\":", out);
    str(channel);
    fprintf(out, ",\"recv_utime\":%lld,\"size\":%d", (long long)rbuf->recv_utime, size);
    if (urrt_state_t_decode(data, 0, size, &st) == size) {
        fputs(",\"type\":\"state_t\"", out);
        I(&st, utime); I(&st, length); I(&st, doubles); I(&st, generation); S(&st, versions);
        I(&st, present); I(&st, sequence);
        state_fields(&st);
        I(&st, extra_columns);
        fputs(",\"extra\":[", out);
        for (int i = 0; i < st.extra_columns; i++) {
            if (i) fputc(',', out);
            num(st.extra[i]);
        }
        fputc(']', out);
        urrt_state_t_decode_cleanup(&st);
    } else if (urrt_joints_t_decode(data, 0, size, &jo) == size) {
        fputs(",\"type\":\"joints_t\"", out);
        I(&jo, utime); D(&jo, controller_time); I(&jo, sequence);
        DA(&jo, q_target); DA(&jo, qd_target); DA(&jo, qdd_target); DA(&jo, i_target); DA(&jo, m_target);
        DA(&jo, q_actual); DA(&jo, qd_actual); DA(&jo, i_actual); DA(&jo, i_control); DA(&jo, v_actual);
        DA(&jo, motor_temperatures);
        urrt_joints_t_decode_cleanup(&jo);
    } else if (urrt_tool_t_decode(data, 0, size, &to) == size) {
        fputs(",\"type\":\"tool_t\"", out);
        I(&to, utime); D(&to, controller_time); I(&to, sequence);
        DA(&to, tool_vector_actual); DA(&to, tcp_speed_actual); DA(&to, tool_vector_target);
        DA(&to, tcp_speed_target); DA(&to, tcp_force); DA(&to, tool_accelerometer); DA(&to, elbow_position);
        DA(&to, elbow_velocity); D(&to, payload_mass); DA(&to, payload_cog); DA(&to, payload_inertia);
        DA(&to, tool_vector); DA(&to, tcp_speed);
        urrt_tool_t_decode_cleanup(&to);
    } else if (urrt_status_t_decode(data, 0, size, &su) == size) {
        fputs(",\"type\":\"status_t\"", out);
        I(&su, utime); D(&su, controller_time); I(&su, sequence); I(&su, generation);
        I(&su, robot_mode); S(&su, robot_mode_name); IA(&su, joint_modes); SA(&su, joint_mode_names, 6);
        I(&su, safety_mode); S(&su, safety_mode_name); I(&su, safety_status); S(&su, safety_status_name);
        I(&su, program_state); S(&su, program_state_name); I(&su, digital_inputs); I(&su, digital_outputs);
        D(&su, speed_scaling); D(&su, v_main); D(&su, v_robot); D(&su, i_robot);
        D(&su, linear_momentum_norm); D(&su, controller_timer);
        urrt_status_t_decode_cleanup(&su);
    } else if (urrt_gateway_t_decode(data, 0, size, &gw) == size) {
        fputs(",\"type\":\"gateway_t\"", out);
        I(&gw, utime); S(&gw, robot); S(&gw, host); I(&gw, port); I(&gw, link_state); S(&gw, link_state_name);
        I(&gw, data_fresh); I(&gw, data_age_us); S(&gw, expected); I(&gw, length); S(&gw, versions);
        I(&gw, generation); D(&gw, packet_rate); I(&gw, packets); I(&gw, bytes); I(&gw, connects);
        I(&gw, reconnects); I(&gw, disconnects); I(&gw, connect_failures); I(&gw, silences); I(&gw, resyncs);
        I(&gw, skipped_bytes); I(&gw, partial_drops); I(&gw, version_mismatches); I(&gw, published);
        I(&gw, publish_errors); S(&gw, last_error);
        fputs(",\"counters\":{", out);
        for (int i = 0; i < gw.n_counters; i++) {
            if (i) fputc(',', out);
            str(gw.counter_names[i]);
            fprintf(out, ":%lld", (long long)gw.counter_values[i]);
        }
        fputc('}', out);
        urrt_gateway_t_decode_cleanup(&gw);
    } else if (urrt_rtde_t_decode(data, 0, size, &rt) == size) {
        fputs(",\"type\":\"rtde_t\"", out);
        I(&rt, utime); D(&rt, controller_time); I(&rt, sequence); I(&rt, count);
        SA(&rt, names, rt.count);
        fputs(",\"values\":[", out);
        for (int i = 0; i < rt.count; i++) {
            if (i) fputc(',', out);
            num(rt.values[i]);
        }
        fputc(']', out);
        urrt_rtde_t_decode_cleanup(&rt);
    } else {
        fputs(",\"type\":null", out);
        undecodable++;
    }
    fputs("}\n", out);
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--fingerprints") == 0) {
        /* What the encoder writes first: the same number Java's LCM_FINGERPRINT holds. */
        printf("gateway_t %llx\n", (unsigned long long)__urrt_gateway_t_get_hash());
        printf("joints_t %llx\n", (unsigned long long)__urrt_joints_t_get_hash());
        printf("rtde_t %llx\n", (unsigned long long)__urrt_rtde_t_get_hash());
        printf("state_t %llx\n", (unsigned long long)__urrt_state_t_get_hash());
        printf("status_t %llx\n", (unsigned long long)__urrt_status_t_get_hash());
        printf("tool_t %llx\n", (unsigned long long)__urrt_tool_t_get_hash());
        return 0;
    }
    if (argc < 4 || argc > 5) {
        fprintf(stderr, "usage: lcm_sub URL REGEX SECONDS [READY_FILE]\n");
        return 2;
    }
    double seconds = atof(argv[3]);
    struct timespec t0, t;
    lcm_t *lcm = lcm_create(argv[1]);
    out = stdout;
    if (lcm == NULL) {
        fprintf(stderr, "lcm_sub: cannot open %s\n", argv[1]);
        return 1;
    }
    signal(SIGTERM, on_signal);
    signal(SIGINT, on_signal);
    setvbuf(out, NULL, _IOLBF, 1 << 16);
    lcm_subscription_set_queue_capacity(lcm_subscribe(lcm, argv[2], on_message, NULL), SUB_QUEUE);
    if (argc == 5) {
        FILE *f = fopen(argv[4], "w");
        if (f != NULL) {
            fclose(f);
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &t0);
    while (running) {
        clock_gettime(CLOCK_MONOTONIC, &t);
        if ((double)(t.tv_sec - t0.tv_sec) + (double)(t.tv_nsec - t0.tv_nsec) / 1e9 >= seconds) {
            break;
        }
        lcm_handle_timeout(lcm, 50);
    }
    fflush(out);
    fprintf(stderr, "lcm_sub: %lu undecodable messages\n", undecodable);
    lcm_destroy(lcm);
    return 0;
}
