/* SPDX-License-Identifier: MIT */
/*
 * gateway.h: the core of urrt-gateway: robots, outputs, one wait loop.
 *
 * Each robot has a link (port.h), reading RealTime or, with source = rtde,
 * an RTDE session through the link's source seam (rtde_source.h). Every
 * complete packet of the expected length (every RTDE data package) is
 * decoded once and handed to every output through one dispatch
 * (gw_output.packet); every output also gets a tick when it is due, may
 * register a descriptor of its own (gw_watch) and adds counters to each
 * robot's status. The outputs are LCM (lcm_out.h) and CAN (can_out.h), each
 * registered with gw_add_output().
 *
 * Nothing here allocates after gw_init(): the per-packet path only reads
 * and writes memory the gateway already owns.
 */
#ifndef URRT_GATEWAY_H
#define URRT_GATEWAY_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "freshness.h"
#include "port.h"
#include "rtde_source.h"
#include "urrt.h"

#define GW_MAX_OUTPUTS 8
/* An output's tick runs whenever its deadline has passed, when a robot's
 * link state or freshness changed, and at least this often: a safety net,
 * which may come late, by a packet's period while a robot sends and by
 * GW_TICK_MAX_US at most (wait_and_service in gateway.c). */
#define GW_TICK_MAX_US 100000u

typedef struct gateway gateway;

/*
 * A descriptor the loop waits on: a robot's link, or an output's. The loop
 * waits with epoll, level-triggered, on a set that changes only when a
 * descriptor does: the owner reports its descriptor with gw_watch_set after
 * each call that may change it (an open, a close, the events it waits for),
 * and the loop makes a system call only when something changed. After a
 * wait that found the descriptor ready (readable, writable, an error, a
 * hang-up), the loop calls ready(). Where a robot's socket, waiting for
 * input, is all there is to wait on (one robot, no output descriptor
 * waiting), the loop waits in that socket's read instead
 * (urrt_link_service_waiting): one system call a packet, not two.
 */
typedef struct gw_watch {
    void (*ready)(void *ctx, uint64_t now_us);
    void *ctx;
    /* As registered (gateway.c's): */
    int fd;
    short events;
    uint64_t opened;
} gw_watch;

void gw_watch_init(gw_watch *w, void (*ready)(void *ctx, uint64_t now_us), void *ctx);
/* fd: the descriptor to wait on now, -1 for none; events: poll's (POLLIN,
 * POLLOUT); opened: the owner's count of descriptors opened, so that a new
 * socket that got a closed one's number is registered anew. The owner
 * holds one descriptor at a time and reports -1 only once it has closed it
 * (a closed descriptor leaves the epoll set by itself). */
void gw_watch_set(gateway *gw, gw_watch *w, int fd, short events, uint64_t opened);

typedef struct gw_robot {
    gateway *gw;
    unsigned index;
    const gw_robot_config *cfg;
    urrt_link *link;
    gw_watch watch;            /* the link's socket */
    rtde_source *rtde;         /* source = rtde: the session on link; NULL for RealTime */
    urrt_state state;          /* the last packet decoded */
    uint64_t sequence;         /* packets dispatched to the outputs */
    uint64_t mismatches;       /* packets not of the expected length */
    uint64_t decode_errors;
    uint64_t data_us;          /* the last dispatched packet's data is no older than now -
                                * data_us (freshness.h); 0: none yet */
    uint64_t newest_data_us;   /* the same for the last packet read, dispatched or not; 0: none */
    uint64_t connects_seen;    /* link connects when the last packet came */
    uint64_t mismatch_logged_us;
    uint64_t mismatches_logged;
    bool mismatch;             /* the last packet had the wrong length */
    gw_age age;                /* how old each packet's data is when read */
    uint64_t late_packets;     /* data older than the silence timeout when read: not dispatched */
    bool late;                 /* the last packet was late */
    char last_error[160];
} gw_robot;

/* One packet, as every output receives it. */
typedef struct gw_packet {
    const uint8_t *bytes;      /* valid during the call only */
    size_t length;
    const urrt_state *state;   /* decoded */
    const urrt_rtde_values *rtde; /* source = rtde: the RTDE-only values; NULL for RealTime */
    uint64_t rx_us;            /* monotonic time the bytes were read */
    uint64_t data_us;          /* the data is no older than now - data_us (<= rx_us) */
    uint64_t rx_wall_us;       /* the same instant on the wall clock (utime) */
    uint64_t sequence;         /* robot->sequence for this packet */
} gw_packet;

/* A named counter an output adds to each robot's status. */
typedef struct gw_counter {
    const char *name;
    uint64_t value;
} gw_counter;

typedef struct gw_output {
    const char *name;
    void *ctx;
    /* Every packet of every robot, in order. Must not block or allocate. */
    void (*packet)(void *ctx, gw_robot *robot, const gw_packet *pkt);
    /* Periodic work (status reports, retries); now is monotonic. Runs when
     * its deadline has passed, after a wake-up in which a robot's link
     * state or gw_robot_fresh changed, and at least every GW_TICK_MAX_US
     * (above): not at every wake-up. An output with a descriptor of its
     * own (the CAN socket) keeps it registered with a gw_watch. */
    void (*tick)(void *ctx, uint64_t now_us);
    /* Optional: monotonic time its tick is due at the latest. Asked at
     * every wake-up: its cost must not grow with the robots. */
    uint64_t (*deadline)(void *ctx);
    /* Optional: counters for a robot's status (at most max), their number. */
    unsigned (*counters)(void *ctx, const gw_robot *robot, gw_counter *out, unsigned max);
    /* Optional: appends to a robot's one-line summary; returns chars written. */
    int (*summary)(void *ctx, const gw_robot *robot, uint64_t now_us, char *buf, size_t size);
    /* Optional: at exit. */
    void (*close)(void *ctx);
} gw_output;

struct gateway {
    const gw_config *cfg;
    gw_robot *robots;
    unsigned robot_count;
    gw_output outputs[GW_MAX_OUTPUTS];
    unsigned output_count;
    bool summary;              /* print one line per robot each second on stdout */
    uint64_t next_summary_us;
    uint64_t loops;
    /* The loop's (gateway.c): */
    int epoll_fd;
    unsigned watched;          /* watches registered with events: one robot's alone waits in its read */
    struct gw_link_due *link_due; /* per robot, apart from gw_robot */
    uint64_t links_due_us;     /* never later than the earliest link_due */
    uint64_t output_due[GW_MAX_OUTPUTS];
    uint64_t tick_all_us;      /* every output ticks by then */
    bool news;                 /* a robot's link state or freshness changed: every output ticks */
};

/* Creates a link per robot. False (logged) when one cannot be created. */
bool gw_init(gateway *gw, const gw_config *cfg);
bool gw_add_output(gateway *gw, const gw_output *output);
/* Runs until *running is cleared. */
void gw_run(gateway *gw, volatile sig_atomic_t *running);
void gw_close(gateway *gw);

/* Packets arrive, have the expected length, the last one was not late, and
 * its data is no older than the silence timeout: only then may state be
 * published. */
bool gw_robot_fresh(const gw_robot *robot, uint64_t now_us);
/* Whether a packet's data, no older than now - data_us, is still within the
 * robot's bound: every output asks just before it sends. */
bool gw_robot_data_fresh(const gw_robot *robot, uint64_t data_us, uint64_t now_us);
/* How old the data of the last packet read is at most (microseconds), -1
 * before the first. */
int64_t gw_robot_data_age_us(const gw_robot *robot, uint64_t now_us);
/* The wall-clock time (utime) of a monotonic instant, so that a message
 * stamped with it and the freshness judged at that instant agree. */
uint64_t gw_wall_us(uint64_t mono_us);
/* Every output's counters for a robot. */
unsigned gw_counters(const gateway *gw, const gw_robot *robot, gw_counter *out, unsigned max);

#endif
