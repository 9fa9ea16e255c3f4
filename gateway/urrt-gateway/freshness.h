/* SPDX-License-Identifier: MIT */
/*
 * freshness.h: how old a robot packet's data is when the gateway reads it.
 *
 * Two clocks judge it, because each sees what the other cannot:
 *
 * - The host's clock bounds the time a packet waited on this host. The link
 *   tells when the socket's queue was last seen empty before the packet's
 *   first byte was read (urrt_link_packet_empty_us); every byte arrived
 *   after that, so rx - empty is an upper bound on the wait in the socket. A
 *   gateway that keeps up sees about one period; one that falls behind (too
 *   slow, stopped, starved of CPU) sees its backlog, growing slowly or
 *   suddenly, exactly.
 *
 * - The controller's clock (the packet's time column) sees delays before the
 *   host: a controller or a network that held packets back. offset = rx -
 *   controller time is smallest for a packet that came at once; the floor of
 *   the offsets may rise by at most GW_AGE_DRIFT_PPM of the host time that
 *   passed (a controller clock that runs that much slower than the host's
 *   still passes), and falls at once to any lower offset. A packet's lag on
 *   this clock is its offset above the floor.
 *
 * The packet's lag is the larger of the two; its data is taken to be from
 * rx - lag, and its age at any later instant is now - (rx - lag). A new
 * connection, or a controller clock that went back (a restart), starts the
 * floor again, from the first packet that was the newest when read: the
 * packets of a burst before it (a controller or a network that held them
 * back, then sent them at once) are each younger than the one before, so
 * none of them can anchor the floor, and their lag is GW_AGE_UNKNOWN.
 *
 * Blind spot, stated so that nobody relies on it: a delay that grows before
 * the host (in the controller or the network, not in this host's socket)
 * more slowly than GW_AGE_DRIFT_PPM is followed, not caught.
 *
 * Pure arithmetic with time as an argument: tested on a fake clock
 * (tests/gateway/test_freshness.c).
 */
#ifndef URRT_GW_FRESHNESS_H
#define URRT_GW_FRESHNESS_H

#include <stdbool.h>
#include <stdint.h>

/* 0.1 %: crystal clocks differ by well under 100 ppm. */
#define GW_AGE_DRIFT_PPM 1000
/* The lag of a packet whose age cannot be judged: older than any bound. */
#define GW_AGE_UNKNOWN UINT64_MAX

typedef struct gw_age {
    bool anchored;            /* a floor exists on this connection */
    int64_t floor_us;         /* lowest offset, as of floor_at_us */
    uint64_t floor_at_us;
    int64_t last_controller_us;
} gw_age;

/* Forget the floor: a new connection. */
void gw_age_reset(gw_age *age);

/* The lag of a packet read at rx_us (microseconds, monotonic) whose first
 * byte arrived after empty_us, with the controller's time controller_us
 * (microseconds; has_clock false when the packet has no usable time);
 * newest: nothing newer had arrived when it was read. */
uint64_t gw_age_lag_us(gw_age *age, uint64_t rx_us, uint64_t empty_us, bool has_clock, int64_t controller_us,
                       bool newest);

/*
 * How often a message goes out, for the --summary line: the messages between
 * two of them divided by the exact time between those two, measured over at
 * least GW_METER_MIN_SPAN_US. A count per one-second window would show a
 * 1 Hz message that is on time as 0, 1 or 2 per second by where the window
 * falls; this shows 1.0, and 500 at 500 Hz. A measured stream with nothing
 * for twice its period (and at least the span) reads 0, and its next
 * measurement starts at its next message, so that the pause does not dilute
 * it.
 */
#define GW_METER_MIN_SPAN_US 900000u

typedef struct gw_meter {
    uint64_t count;           /* messages so far */
    uint64_t last_us;         /* time of the latest */
    bool marked;              /* a measurement has started */
    uint64_t mark_count;      /* count at the message it started at */
    uint64_t mark_us;         /* that message's time */
    bool measured;            /* rate holds a measurement */
    double rate;              /* per second, as last measured */
} gw_meter;

/* One message at now_us (monotonic; times never go back). */
void gw_meter_event(gw_meter *m, uint64_t now_us);
/* Messages per second as of now_us: measured anew when a span is complete,
 * else as last measured; 0 once stopped; -1 before the first measurement
 * (not yet known, which is not 0). */
double gw_meter_rate(gw_meter *m, uint64_t now_us);

#endif
