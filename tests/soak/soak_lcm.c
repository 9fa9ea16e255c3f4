/* SPDX-License-Identifier: MIT */
/*
 * soak_lcm: the soak's LCM checker, independent of the gateway's counters.
 *
 *   soak_lcm URL PREFIX BOUND_US MARGIN_US READY_FILE
 *
 * Subscribes to PREFIX.* and judges every message by two clocks that are not
 * the gateway's: the simulator's time column (--clock realtime: the wall
 * clock at the packet's scheduled send instant) and LCM's recv_utime (the
 * kernel's receive time on the same clock). A data message (STATE, JOINTS,
 * TOOL, STATUS) is stale when recv_utime - time > BOUND_US + MARGIN_US. A
 * GATEWAY report lies when it says data_fresh while the newest data received
 * before it was more than BOUND_US + MARGIN_US old at the report's utime.
 *
 * Commands on stdin, one per line (the soak driver writes them):
 *   phase NAME WALL_US   messages received from WALL_US on belong to NAME
 *   end WALL_US          the simulator stopped at WALL_US: wait (at most 10 s)
 *                        for the first report judged after it, whose counters
 *                        are final, compare them with what was received,
 *                        print the results and exit
 *
 * Output (stdout, one fact per line, parsed by soak.py):
 *   stale CH RECV_UTIME AGE_US PHASE             the first 20 stale messages
 *   lie RECV_UTIME NEWEST_AGE_US PHASE           the first 20 untrue reports
 *   phase I NAME state N joints N tool N status N gateway N oldest_us A stale S lies L
 *   delivery KIND received N published N         per data kind, over the whole run
 *   report KEY VALUE ...                         the final report's counters
 */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "urrt_gateway_t.h"
#include "urrt_joints_t.h"
#include "urrt_state_t.h"
#include "urrt_status_t.h"
#include "urrt_tool_t.h"

/* 500 Hz x 4 kinds for 50 s: a checker held up that long still loses nothing. */
#define SUB_QUEUE 100000
#define MAX_PHASES 4096
#define MAX_REPORTED 20
#define END_WAIT_US 10000000

enum { K_STATE, K_JOINTS, K_TOOL, K_STATUS, K_GATEWAY, K_COUNT };
static const char *const kind_name[K_COUNT] = { "state", "joints", "tool", "status", "gateway" };
static const char *const kind_suffix[K_COUNT] = { "STATE", "JOINTS", "TOOL", "STATUS", "GATEWAY" };

typedef struct phase {
    char name[32];
    int64_t start_us;
    uint64_t count[K_COUNT];
    int64_t oldest_us;
    uint64_t stale, lies;
} phase;

static phase phases[MAX_PHASES];
static int n_phases;
static const char *prefix;
static size_t prefix_len;
static int64_t bound_us, margin_us;
static int64_t newest_stamp_us;     /* newest data received so far, simulator clock */
static uint64_t total[K_COUNT];
static unsigned reported_stale, reported_lies;
static int64_t end_us = -1;         /* set by "end" */
static int final_seen;
static int64_t published[K_COUNT];
static char final_report[1024];

static int64_t wall_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

/* Messages go to the phase that had begun when they were received. */
static phase *phase_at(int64_t recv_us)
{
    for (int i = n_phases - 1; i > 0; i--)
        if (phases[i].start_us <= recv_us)
            return &phases[i];
    return &phases[0];
}

static void data_message(phase *p, const char *channel, int64_t recv_us, double time_s)
{
    int64_t stamp = llround(time_s * 1e6);
    int64_t age = recv_us - stamp;
    if (stamp > newest_stamp_us)
        newest_stamp_us = stamp;
    if (age > p->oldest_us)
        p->oldest_us = age;
    if (age > bound_us + margin_us) {
        p->stale++;
        if (reported_stale++ < MAX_REPORTED)
            printf("stale %s %lld %lld %s\n", channel, (long long)recv_us, (long long)age, p->name);
    }
}

static int64_t counter(const urrt_gateway_t *g, const char *name)
{
    for (int i = 0; i < g->n_counters; i++)
        if (strcmp(g->counter_names[i], name) == 0)
            return g->counter_values[i];
    return -1;
}

static void gateway_report(phase *p, int64_t recv_us, const urrt_gateway_t *g)
{
    if (g->data_fresh && g->utime - newest_stamp_us > bound_us + margin_us) {
        p->lies++;
        if (reported_lies++ < MAX_REPORTED)
            printf("lie %lld %lld %s\n", (long long)recv_us, (long long)(g->utime - newest_stamp_us), p->name);
    }
    if (end_us < 0 || final_seen || g->data_fresh || g->utime <= end_us)
        return;
    final_seen = 1;
    for (int k = 0; k < K_GATEWAY; k++) {
        char name[64];
        snprintf(name, sizeof name, "lcm.published.%s", kind_name[k]);
        published[k] = counter(g, name);
    }
    snprintf(final_report, sizeof final_report,
             "report packets %lld connects %lld reconnects %lld silences %lld resyncs %lld skipped_bytes %lld "
             "partial_drops %lld version_mismatches %lld late_packets %lld stale_dropped %lld publish_errors %lld",
             (long long)g->packets, (long long)g->connects, (long long)g->reconnects, (long long)g->silences,
             (long long)g->resyncs, (long long)g->skipped_bytes, (long long)g->partial_drops,
             (long long)g->version_mismatches, (long long)counter(g, "late_packets"),
             (long long)counter(g, "lcm.stale_dropped"), (long long)g->publish_errors);
}

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)user;
    if (strncmp(channel, prefix, prefix_len) != 0 || channel[prefix_len] != '.')
        return;
    int kind = 0;
    while (kind < K_COUNT && strcmp(channel + prefix_len + 1, kind_suffix[kind]) != 0)
        kind++;
    if (kind == K_COUNT)
        return;
    int64_t recv = rbuf->recv_utime;
    phase *p = phase_at(recv);
    int size = (int)rbuf->data_size;
    const void *d = rbuf->data;
    union {
        urrt_state_t st;
        urrt_joints_t jo;
        urrt_tool_t to;
        urrt_status_t su;
        urrt_gateway_t gw;
    } m;
    int ok = 0;
    switch (kind) {
    case K_STATE:
        if ((ok = urrt_state_t_decode(d, 0, size, &m.st) == size)) {
            data_message(p, channel, recv, m.st.time);
            urrt_state_t_decode_cleanup(&m.st);
        }
        break;
    case K_JOINTS:
        if ((ok = urrt_joints_t_decode(d, 0, size, &m.jo) == size)) {
            data_message(p, channel, recv, m.jo.controller_time);
            urrt_joints_t_decode_cleanup(&m.jo);
        }
        break;
    case K_TOOL:
        if ((ok = urrt_tool_t_decode(d, 0, size, &m.to) == size)) {
            data_message(p, channel, recv, m.to.controller_time);
            urrt_tool_t_decode_cleanup(&m.to);
        }
        break;
    case K_STATUS:
        if ((ok = urrt_status_t_decode(d, 0, size, &m.su) == size)) {
            data_message(p, channel, recv, m.su.controller_time);
            urrt_status_t_decode_cleanup(&m.su);
        }
        break;
    default:
        if ((ok = urrt_gateway_t_decode(d, 0, size, &m.gw) == size)) {
            gateway_report(p, recv, &m.gw);
            urrt_gateway_t_decode_cleanup(&m.gw);
        }
        break;
    }
    if (!ok) {
        printf("undecodable %s %d bytes\n", channel, size);
        return;
    }
    p->count[kind]++;
    total[kind]++;
}

/* One command line from the driver; returns 0 on a malformed line. */
static int command(const char *line)
{
    char name[32];
    long long at;
    if (sscanf(line, "phase %31s %lld", name, &at) == 2 && n_phases < MAX_PHASES) {
        phase *p = &phases[n_phases++];
        snprintf(p->name, sizeof p->name, "%s", name);
        p->start_us = at;
        return 1;
    }
    if (sscanf(line, "end %lld", &at) == 1) {
        end_us = at;
        return 1;
    }
    return 0;
}

static void print_results(void)
{
    for (int i = 0; i < n_phases; i++) {
        const phase *p = &phases[i];
        printf("phase %d %s state %llu joints %llu tool %llu status %llu gateway %llu oldest_us %lld stale %llu "
               "lies %llu\n", i, p->name, (unsigned long long)p->count[K_STATE],
               (unsigned long long)p->count[K_JOINTS], (unsigned long long)p->count[K_TOOL],
               (unsigned long long)p->count[K_STATUS], (unsigned long long)p->count[K_GATEWAY],
               (long long)p->oldest_us, (unsigned long long)p->stale, (unsigned long long)p->lies);
    }
    for (int k = 0; k < K_GATEWAY; k++)
        printf("delivery %s received %llu published %lld\n", kind_name[k], (unsigned long long)total[k],
               final_seen ? (long long)published[k] : -1LL);
    if (final_seen)
        printf("%s\n", final_report);
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: soak_lcm URL PREFIX BOUND_US MARGIN_US READY_FILE\n");
        return 2;
    }
    prefix = argv[2];
    prefix_len = strlen(prefix);
    bound_us = atoll(argv[3]);
    margin_us = atoll(argv[4]);
    snprintf(phases[0].name, sizeof phases[0].name, "start");
    n_phases = 1;
    lcm_t *lcm = lcm_create(argv[1]);
    if (lcm == NULL) {
        fprintf(stderr, "soak_lcm: cannot open %s\n", argv[1]);
        return 1;
    }
    setvbuf(stdout, NULL, _IOLBF, 1 << 16);
    char regex[256];
    snprintf(regex, sizeof regex, "%s\\..*", prefix);
    lcm_subscription_t *sub = lcm_subscribe(lcm, regex, on_message, NULL);
    lcm_subscription_set_queue_capacity(sub, SUB_QUEUE);
    FILE *ready = fopen(argv[5], "w");
    if (ready != NULL)
        fclose(ready);

    char buf[4096];
    size_t have = 0;
    int stdin_open = 1;
    int64_t end_deadline = 0;
    for (;;) {
        struct pollfd pfd[2] = { { lcm_get_fileno(lcm), POLLIN, 0 }, { STDIN_FILENO, POLLIN, 0 } };
        int r = poll(pfd, stdin_open ? 2 : 1, 50);
        if (r < 0 && errno != EINTR)
            break;
        if (r > 0 && (pfd[0].revents & POLLIN))
            lcm_handle(lcm);
        if (stdin_open && r > 0 && (pfd[1].revents & (POLLIN | POLLHUP))) {
            ssize_t n = read(STDIN_FILENO, buf + have, sizeof buf - 1 - have);
            if (n <= 0) {
                stdin_open = 0;
                if (end_us < 0)
                    end_us = wall_us();
            } else {
                have += (size_t)n;
                buf[have] = '\0';
                char *nl;
                while ((nl = strchr(buf, '\n')) != NULL) {
                    *nl = '\0';
                    if (!command(buf))
                        fprintf(stderr, "soak_lcm: ignored \"%s\"\n", buf);
                    have -= (size_t)(nl + 1 - buf);
                    memmove(buf, nl + 1, have + 1);
                }
            }
        }
        if (end_us >= 0 && end_deadline == 0)
            end_deadline = wall_us() + END_WAIT_US;
        if (final_seen || (end_deadline && wall_us() > end_deadline))
            break;
    }
    /* What is still queued was received before the end: count it too. */
    while (lcm_handle_timeout(lcm, 0) > 0)
        ;
    print_results();
    lcm_destroy(lcm);
    return 0;
}
