/* SPDX-License-Identifier: MIT */
/*
 * bench_relay: the floor under urrt-gateway in bench-gateway. It reads each
 * robot's TCP stream, frames it and publishes each packet's raw bytes once
 * per message the gateway would send, and does nothing else: no encode, no
 * clocks, no checks.
 *
 *   bench_relay [--rtde] HOST LCM_URL PREFIX EVERY KIND[,KIND...] PORT...
 *
 * One robot per PORT, robot r's messages on PREFIX_r.KIND for each KIND, in
 * the order given; every EVERY-th packet of a robot (1: each) goes out.
 * RealTime: lib's framer (urrt_framer_feed), no decode. --rtde: lib's RTDE
 * client (lib/urrt_rtde) does the handshake the gateway does, with the recipe
 * the gateway asks for (every variable RealTime has too, narrowed to what the
 * controller's version has, as the gateway narrows its optional ones), and
 * decodes each data package into a urrt_state as the gateway must; the
 * package's raw bytes are published. What is compared is the loop and its
 * I/O: one robot is read with a blocking read (the wait is the read, one
 * system call a packet); several are waited for with epoll, one read per
 * ready socket. Ends at end of every stream or on SIGTERM (exit status 0,
 * so that a tool around it writes its figures).
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "urrt.h"
#include "urrt_rtde.h"

#define MAX_KINDS 4
#define MAX_ROBOTS 64

typedef struct {
    int fd;
    urrt_framer fr;     /* RealTime */
    urrt_rtde rtde;     /* --rtde */
    long count;         /* packets so far */
    char channel[MAX_KINDS][96];
} robot;

static robot robots[MAX_ROBOTS];
static int kinds;
static long every = 1;
static bool rtde;
static lcm_t *lcm;
static urrt_state state;
static urrt_rtde_values values;
static volatile sig_atomic_t stop;

static void on_term(int sig)
{
    (void)sig;
    stop = 1;
}

static void publish(robot *r, const uint8_t *pkt, size_t len)
{
    if (r->count++ % every != 0) {
        return;
    }
    for (int k = 0; k < kinds; k++) {
        lcm_publish(lcm, r->channel[k], pkt, (unsigned)len);
    }
}

static bool write_all(int fd, const uint8_t *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        p += w;
        n -= (size_t)w;
    }
    return true;
}

/* The session's requests due now, written whole (only in the handshake). */
static bool rtde_requests(robot *r)
{
    static uint8_t out[URRT_RTDE_REQUEST_MAX];
    int n;
    while ((n = urrt_rtde_output(&r->rtde, out, sizeof out)) > 0) {
        if (!write_all(r->fd, out, (size_t)n)) return false;
    }
    return n == 0;
}

/* The gateway's narrowing: what this controller's version lacks, left out. */
static void rtde_narrow(robot *r)
{
    uint16_t vars[URRT_RTDE_MAPPED_COUNT];
    size_t n = 0;
    const uint32_t *v = r->rtde.controller;
    for (int i = 0; i < URRT_RTDE_MAPPED_COUNT; i++) {
        if (i == URRT_RTDE_V_TIMESTAMP || urrt_rtde_var_available(i, v[0], v[1], v[2]) != 0) {
            vars[n++] = (uint16_t)i;
        }
    }
    if (n != URRT_RTDE_MAPPED_COUNT) {
        urrt_rtde_set_recipe(&r->rtde, vars, n);
    }
}

/* Feeds what one read returned; false when the session ended. */
static bool feed(robot *r, const uint8_t *p, size_t left)
{
    while (left > 0) {
        size_t used = 0;
        if (!rtde) {
            size_t len;
            if (urrt_framer_feed(&r->fr, p, left, &used) > 0) {
                const uint8_t *pkt = urrt_framer_packet(&r->fr, &len);
                publish(r, pkt, len);
            }
        } else {
            urrt_rtde_event ev;
            int k = urrt_rtde_feed(&r->rtde, p, left, &used, &ev, &state, &values);
            if (k == URRT_RTDE_EV_DATA) {
                publish(r, r->rtde.buf, r->rtde.data_size);
            } else if (k == URRT_RTDE_EV_DROP || k == URRT_RTDE_EV_CONFIG || k < 0) {
                fprintf(stderr, "bench_relay: RTDE: %s\n", urrt_rtde_strerror(k < 0 ? k : ev.error));
                return false;
            } else if (k > 0) {
                if (k == URRT_RTDE_EV_CONTROLLER) rtde_narrow(r);
                if (!rtde_requests(r)) return false;
            }
        }
        p += used;
        left -= used;
    }
    return true;
}

/* One read of robot r; false at its end. */
static bool service(robot *r)
{
    static uint8_t buf[65536];
    ssize_t n = read(r->fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) return true;
    return n > 0 && feed(r, buf, (size_t)n);
}

int main(int argc, char **argv)
{
    int a = 1;
    if (a < argc && strcmp(argv[a], "--rtde") == 0) {
        rtde = true;
        a++;
    }
    int n = argc - a - 5;
    if (n < 1 || n > MAX_ROBOTS) {
        fprintf(stderr, "usage: bench_relay [--rtde] HOST LCM_URL PREFIX EVERY KIND[,KIND...] PORT...\n");
        return 2;
    }
    const char *host = argv[a], *url = argv[a + 1], *prefix = argv[a + 2];
    every = atol(argv[a + 3]);
    char kind_list[128];
    const char *kind_name[MAX_KINDS];
    snprintf(kind_list, sizeof kind_list, "%s", argv[a + 4]);
    for (char *save = NULL, *t = strtok_r(kind_list, ",", &save); t != NULL && kinds < MAX_KINDS;
         t = strtok_r(NULL, ",", &save)) {
        kind_name[kinds++] = t;
    }
    struct sigaction sa = {.sa_handler = on_term}; /* no SA_RESTART: a blocking read ends */
    sigaction(SIGTERM, &sa, NULL);
    lcm = lcm_create(url);
    if (every < 1 || kinds < 1 || lcm == NULL) {
        fprintf(stderr, "bench_relay: bad EVERY, KIND or LCM URL\n");
        return 1;
    }
    uint16_t vars[URRT_RTDE_MAPPED_COUNT];
    for (int i = 0; i < URRT_RTDE_MAPPED_COUNT; i++) vars[i] = (uint16_t)i;
    for (int r = 0; r < n; r++) {
        robot *rb = &robots[r];
        struct sockaddr_in sa_in = {.sin_family = AF_INET, .sin_port = htons((uint16_t)atoi(argv[a + 5 + r]))};
        for (int k = 0; k < kinds; k++) {
            snprintf(rb->channel[k], sizeof rb->channel[k], "%s_%d.%s", prefix, r, kind_name[k]);
        }
        rb->fd = socket(AF_INET, SOCK_STREAM, 0);
        if (inet_pton(AF_INET, host, &sa_in.sin_addr) != 1 ||
            connect(rb->fd, (struct sockaddr *)&sa_in, sizeof sa_in) != 0) {
            perror("bench_relay: connect");
            return 1;
        }
        urrt_framer_init(&rb->fr);
        if (rtde) {
            urrt_rtde_init(&rb->rtde);
            if (urrt_rtde_begin(&rb->rtde, vars, URRT_RTDE_MAPPED_COUNT, 0.0) != URRT_OK || !rtde_requests(rb)) {
                fprintf(stderr, "bench_relay: RTDE handshake\n");
                return 1;
            }
        }
    }
    if (n == 1) {
        while (!stop && service(&robots[0])) {
        }
    } else {
        int ep = epoll_create1(0), open = n;
        for (int r = 0; r < n; r++) {
            struct epoll_event e = {.events = EPOLLIN, .data.u32 = (uint32_t)r};
            epoll_ctl(ep, EPOLL_CTL_ADD, robots[r].fd, &e);
        }
        struct epoll_event ev[MAX_ROBOTS];
        while (!stop && open > 0) {
            int m = epoll_wait(ep, ev, MAX_ROBOTS, -1);
            for (int i = 0; i < m; i++) {
                robot *rb = &robots[ev[i].data.u32];
                if (!service(rb)) {
                    epoll_ctl(ep, EPOLL_CTL_DEL, rb->fd, NULL);
                    open--;
                }
            }
        }
        close(ep);
    }
    for (int r = 0; r < n; r++) close(robots[r].fd);
    lcm_destroy(lcm);
    return 0;
}
