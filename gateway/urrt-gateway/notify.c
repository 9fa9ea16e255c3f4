/* SPDX-License-Identifier: MIT */
/* notify.c: see notify.h. */
#define _GNU_SOURCE
#include "notify.h"

#include <errno.h>
#include <inttypes.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "port.h"

/* STATUS= is looked at by people: once a second is enough. */
#define NOTIFY_STATUS_US 1000000u
/* A failing send is logged at once, then at most this often. */
#define NOTIFY_ERROR_LOG_US (60u * 1000000u)

struct gw_notify {
    gateway *gw;
    can_out *can;
    int fd;
    struct sockaddr_un addr;
    socklen_t addr_len;
    uint64_t ping_us;        /* half of WATCHDOG_USEC; 0: no watchdog */
    uint64_t next_ping_us;
    uint64_t next_status_us;
    uint64_t errors;
    uint64_t error_logged_us;
    char status[200];        /* the last STATUS= sent */
};

/* $NOTIFY_SOCKET into n->addr: "/path" or "@abstract". */
static bool notify_address(gw_notify *n, const char *name)
{
    size_t len = strlen(name);
    memset(&n->addr, 0, sizeof n->addr);
    n->addr.sun_family = AF_UNIX;
    if ((name[0] != '/' && name[0] != '@') || len < 2 || len > sizeof n->addr.sun_path) {
        return false;
    }
    memcpy(n->addr.sun_path, name, len);
    if (name[0] == '@') {
        n->addr.sun_path[0] = '\0'; /* abstract: the name's bytes, no terminator */
        n->addr_len = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + len);
    } else {
        n->addr_len = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + len + (len < sizeof n->addr.sun_path));
    }
    return true;
}

/* $WATCHDOG_USEC when it is meant for this process (WATCHDOG_PID unset or
 * ours); 0 otherwise. */
static uint64_t watchdog_us(void)
{
    const char *usec = getenv("WATCHDOG_USEC"), *pid = getenv("WATCHDOG_PID");
    char *end;
    unsigned long long v;
    if (usec == NULL || (pid != NULL && strtoll(pid, NULL, 10) != (long long)getpid())) {
        return 0;
    }
    errno = 0;
    v = strtoull(usec, &end, 10);
    if (errno != 0 || end == usec || *end != '\0' || v == 0) {
        urrt_log(URRT_LOG_WARNING, "systemd: WATCHDOG_USEC=\"%s\" is not a number of microseconds: no watchdog "
                 "pings (WatchdogSec= in the unit sets it)", usec);
        return 0;
    }
    return (uint64_t)v;
}

static void notify_send(gw_notify *n, const char *text)
{
    uint64_t now = urrt_port_monotonic_us();
    if (sendto(n->fd, text, strlen(text), MSG_NOSIGNAL, (const struct sockaddr *)&n->addr, n->addr_len) >= 0) {
        return;
    }
    n->errors++;
    if (n->errors == 1 || now >= n->error_logged_us + NOTIFY_ERROR_LOG_US) {
        urrt_log(URRT_LOG_WARNING, "systemd: cannot notify %s: %s (%" PRIu64 " message%s lost); systemd may "
                 "restart the gateway when its watchdog pings are missing", getenv("NOTIFY_SOCKET"),
                 strerror(errno), n->errors, n->errors == 1 ? "" : "s");
        n->error_logged_us = now;
    }
}

gw_notify *gw_notify_new(gateway *gw, can_out *can)
{
    const char *name = getenv("NOTIFY_SOCKET");
    gw_notify *n;
    if (name == NULL || name[0] == '\0') {
        return NULL;
    }
    if ((n = calloc(1, sizeof *n)) == NULL) {
        urrt_log(URRT_LOG_WARNING, "systemd: out of memory: not notifying %s", name);
        return NULL;
    }
    if (!notify_address(n, name)) {
        urrt_log(URRT_LOG_WARNING, "systemd: NOTIFY_SOCKET=\"%s\" is not an AF_UNIX socket (/path or @name, at "
                 "most %zu bytes): not notifying; start the gateway from its unit", name, sizeof n->addr.sun_path);
        free(n);
        return NULL;
    }
    n->fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (n->fd < 0) {
        urrt_log(URRT_LOG_WARNING, "systemd: cannot open a socket for NOTIFY_SOCKET: %s: not notifying",
                 strerror(errno));
        free(n);
        return NULL;
    }
    n->gw = gw;
    n->can = can;
    n->ping_us = watchdog_us() / 2u;
    n->next_ping_us = urrt_port_monotonic_us(); /* the first at once: READY=1 is not a ping */
    n->next_status_us = n->next_ping_us;
    return n;
}

/* "robots up 1/2, oldest data 3.2 ms, CAN up operational" */
static void status_line(const gw_notify *n, uint64_t now, char *buf, size_t size)
{
    const gateway *gw = n->gw;
    unsigned up = 0;
    int64_t oldest = -1;
    int len;
    for (unsigned i = 0; i < gw->robot_count; i++) {
        int64_t age = gw_robot_data_age_us(&gw->robots[i], now);
        up += urrt_link_get_state(gw->robots[i].link) == URRT_LINK_UP;
        oldest = age > oldest ? age : oldest;
    }
    len = snprintf(buf, size, "robots up %u/%u, oldest data ", up, gw->robot_count);
    if (len < 0 || (size_t)len >= size) {
        return;
    }
    if (oldest < 0) {
        len += snprintf(buf + len, size - (size_t)len, "none");
    } else if (oldest < 10000000) {
        len += snprintf(buf + len, size - (size_t)len, "%.1f ms", (double)oldest / 1000.0);
    } else {
        len += snprintf(buf + len, size - (size_t)len, "%.0f s", (double)oldest / 1e6);
    }
    if (n->can != NULL && len > 0 && (size_t)len < size) {
        can_out_info ci;
        can_out_get_info(n->can, &ci);
        snprintf(buf + len, size - (size_t)len, ", CAN %s%s%s", ci.up ? "up" : "DOWN", ci.node ? " " : "",
                 ci.node ? urrt_co_state_name(ci.nmt) : "");
    }
}

static void on_packet(void *ctx, gw_robot *robot, const gw_packet *pkt)
{
    (void)ctx, (void)robot, (void)pkt;
}

/* One datagram: the ping when due, the status when due and changed. */
static void on_tick(void *ctx, uint64_t now_us)
{
    gw_notify *n = ctx;
    char msg[sizeof n->status + 32];
    size_t len = 0;
    if (n->ping_us != 0 && now_us >= n->next_ping_us) {
        len += (size_t)snprintf(msg, sizeof msg, "WATCHDOG=1\n");
        n->next_ping_us = now_us + n->ping_us;
    }
    if (now_us >= n->next_status_us) {
        char status[sizeof n->status];
        status_line(n, now_us, status, sizeof status);
        if (strcmp(status, n->status) != 0) {
            memcpy(n->status, status, sizeof status);
            len += (size_t)snprintf(msg + len, sizeof msg - len, "STATUS=%s\n", status);
        }
        n->next_status_us = now_us + NOTIFY_STATUS_US;
    }
    if (len > 0) {
        notify_send(n, msg);
    }
}

static uint64_t on_deadline(void *ctx)
{
    gw_notify *n = ctx;
    return n->ping_us != 0 && n->next_ping_us < n->next_status_us ? n->next_ping_us : n->next_status_us;
}

gw_output gw_notify_output(gw_notify *n)
{
    gw_output o = {.name = "systemd", .ctx = n, .packet = on_packet, .tick = on_tick, .deadline = on_deadline};
    return o;
}

void gw_notify_ready(gw_notify *n)
{
    if (n != NULL) {
        notify_send(n, "READY=1\n");
    }
}

void gw_notify_stopping(gw_notify *n)
{
    if (n != NULL) {
        notify_send(n, "STOPPING=1\nSTATUS=stopping\n");
    }
}

void gw_notify_free(gw_notify *n)
{
    if (n != NULL) {
        close(n->fd);
        free(n);
    }
}
