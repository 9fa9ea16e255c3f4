/* SPDX-License-Identifier: MIT */
/*
 * gateway.h: the core of urrt-gateway: robots, outputs, one poll loop.
 *
 * Each robot has a link (port.h), reading RealTime or, with source = rtde,
 * an RTDE session through the link's source seam (rtde_source.h). Every
 * complete packet of the expected length (every RTDE data package) is
 * decoded once and handed to every output through one dispatch
 * (gw_output.packet); every output also gets a periodic tick, may add
 * descriptors to the poll set and counters to each robot's status. The
 * outputs are LCM (lcm_out.h) and CAN (can_out.h), each registered with
 * gw_add_output().
 *
 * Nothing here allocates after gw_init(): the per-packet path only reads
 * and writes memory the gateway already owns.
 */
#ifndef URRT_GATEWAY_H
#define URRT_GATEWAY_H

#include <poll.h>
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
#define GW_MAX_POLL 256
/* An output's tick runs at least this often, and whenever its deadline has
 * passed. */
#define GW_TICK_MAX_US 100000u

typedef struct gateway gateway;

typedef struct gw_robot {
    gateway *gw;
    unsigned index;
    const gw_robot_config *cfg;
    urrt_link *link;
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
    /* Periodic work (status reports, retries); now is monotonic. */
    void (*tick)(void *ctx, uint64_t now_us);
    /* Optional: descriptors to wait on (at most max), their number. */
    unsigned (*poll_fds)(void *ctx, struct pollfd *fds, unsigned max);
    /* Optional: after the wait, with the descriptors it gave (revents set). */
    void (*service)(void *ctx, const struct pollfd *fds, unsigned count, uint64_t now_us);
    /* Optional: monotonic time its tick is due at the latest. */
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
