/* SPDX-License-Identifier: MIT */
/*
 * test_freshness: the age estimator of gateway/urrt-gateway/freshness.h on a fake clock.
 * Streams are simulated packet by packet: the controller stamps each packet
 * with its own clock, the host reads it some time later, and the socket was
 * last seen empty at a time the simulation knows. Each case asserts the lag
 * the estimator gives against the true one.
 */
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include "freshness.h"

#define MS 1000u
#define S 1000000u
#define BOUND (100u * MS)

/* A 500 Hz stream read promptly: sent at k * period (controller clock with
 * a fixed offset from the host's), read 80 us later, one packet per read. */
typedef struct stream {
    gw_age age;
    uint64_t host0;        /* host time of the controller's zero */
    double rate;           /* controller seconds per host second */
    uint64_t period_us;
    uint64_t k;            /* next packet */
    uint64_t prev_read_us; /* the previous read emptied the socket just before this */
} stream;

static void stream_init(stream *s, double rate)
{
    gw_age_reset(&s->age);
    s->host0 = 5000u * S;
    s->rate = rate;
    s->period_us = 2 * MS;
    s->k = 0;
    s->prev_read_us = s->host0;
}

/* Host time at which packet k was sent. */
static uint64_t sent_at(const stream *s, uint64_t k)
{
    return s->host0 + k * s->period_us;
}

/* Packet k read at rx (the socket last empty at empty; newest: nothing
 * newer had arrived): its lag. */
static uint64_t read_in_burst(stream *s, uint64_t k, uint64_t rx, uint64_t empty, bool newest)
{
    int64_t controller = (int64_t)((double)(k * s->period_us) * s->rate);
    return gw_age_lag_us(&s->age, rx, empty, true, controller, newest);
}

/* A packet read on its own, the newest when read. */
static uint64_t read_packet(stream *s, uint64_t k, uint64_t rx, uint64_t empty)
{
    return read_in_burst(s, k, rx, empty, true);
}

/* n packets read promptly; the largest lag seen. */
static uint64_t run_prompt(stream *s, uint64_t n)
{
    uint64_t worst = 0;
    for (uint64_t i = 0; i < n; i++, s->k++) {
        uint64_t rx = sent_at(s, s->k) + 80;
        uint64_t lag = read_packet(s, s->k, rx, s->prev_read_us);
        s->prev_read_us = rx - 5;
        if (lag > worst) {
            worst = lag;
        }
    }
    return worst;
}

static void prompt_reader(void)
{
    stream s;
    uint64_t worst;
    stream_init(&s, 1.0);
    worst = run_prompt(&s, 5000);
    CHECK(worst <= s.period_us + 100, "a prompt reader: lag within a period (%llu us)", (unsigned long long)worst);
}

/* The gateway is stopped for a second: the packets sent meanwhile wait in
 * the socket and are read in a burst after it. */
static void stopped_gateway(void)
{
    stream s;
    uint64_t stop_k, resume, late = 0, fresh_after = 0;
    stream_init(&s, 1.0);
    run_prompt(&s, 1000);
    stop_k = s.k;
    resume = sent_at(&s, stop_k) + 1 * S;
    /* The burst: 500 packets read 10 us apart, in reads of 13 packets. */
    for (uint64_t i = 0; i < 500; i++) {
        uint64_t rx = resume + i * 10;
        uint64_t empty = s.prev_read_us; /* not empty again until the backlog is read */
        uint64_t lag = read_in_burst(&s, stop_k + i, rx, empty, i == 499);
        uint64_t truth = rx - sent_at(&s, stop_k + i);
        CHECK(lag + 100 >= truth, "stopped: lag %llu under the truth %llu", (unsigned long long)lag,
                    (unsigned long long)truth);
        late += lag > BOUND;
    }
    CHECK(late >= 450, "stopped 1 s: the backlog is late (%llu of 500 over the bound)", (unsigned long long)late);
    s.k = stop_k + 500;
    s.prev_read_us = resume + 5000;
    /* Read promptly again. */
    for (uint64_t i = 0; i < 100; i++, s.k++) {
        uint64_t rx = sent_at(&s, s.k) + 80;
        fresh_after += read_packet(&s, s.k, rx, s.prev_read_us) <= BOUND;
        s.prev_read_us = rx - 5;
    }
    CHECK(fresh_after == 100, "after the backlog: fresh again (%llu of 100)", (unsigned long long)fresh_after);
}

/* A gateway slower than its robot: it reads 400 of every 500 packets' worth
 * per second, so each packet waits 0.5 ms longer than the one before. The
 * socket is never empty again once the lag starts. */
static void slow_gateway(void)
{
    stream s;
    uint64_t first_late = 0, missed = 0, host_missed = 0, start_empty;
    stream_init(&s, 1.0);
    run_prompt(&s, 100);
    start_empty = s.prev_read_us;
    for (uint64_t i = 0; i < 2000; i++, s.k++) {
        uint64_t truth = i * 500;
        uint64_t rx = sent_at(&s, s.k) + 80 + truth;
        uint64_t lag = read_packet(&s, s.k, rx, start_empty);
        gw_age no_clock;
        gw_age_reset(&no_clock);
        /* The host's bound alone sees it too, whatever the controller's clock says. */
        host_missed += truth > gw_age_lag_us(&no_clock, rx, start_empty, false, 0, false);
        missed += truth > lag + 100;
        if (first_late == 0 && lag > BOUND) {
            first_late = truth;
        }
    }
    CHECK(missed == 0, "slowly growing lag: never estimated below the truth (%llu packets)", (unsigned long long)missed);
    CHECK(host_missed == 0, "slowly growing lag: the host's clock alone bounds it (%llu packets under)",
          (unsigned long long)host_missed);
    CHECK(first_late > 0 && first_late <= BOUND + s.period_us,
          "slowly growing lag: late once the true lag passes the bound (at %llu us)", (unsigned long long)first_late);
}

/* The same slow lag where the host cannot see it (the controller or the
 * network holds the packets back; the host reads each at once): the
 * controller's clock catches it. */
static void upstream_lag(void)
{
    stream s;
    uint64_t first_late = 0, allowance = 0, start;
    stream_init(&s, 1.0);
    run_prompt(&s, 100);
    start = sent_at(&s, s.k);
    for (uint64_t i = 0; i < 2000; i++, s.k++) {
        uint64_t truth = i * 100; /* 5 % of the period more each packet */
        uint64_t rx = sent_at(&s, s.k) + 80 + truth;
        uint64_t lag = read_packet(&s, s.k, rx, rx - 50);
        if (first_late == 0 && lag > BOUND) {
            first_late = truth;
            /* The floor may have risen by the drift allowance meanwhile. */
            allowance = (rx - start) / (1000000u / GW_AGE_DRIFT_PPM);
        }
    }
    CHECK(first_late > BOUND - s.period_us && first_late <= BOUND + allowance + s.period_us,
          "a lag growing upstream of the host: late once it passes the bound plus the drift allowance "
          "(%llu us) (at %llu us)", (unsigned long long)allowance, (unsigned long long)first_late);
}

/* Clocks that differ in rate: a controller 500 ppm slow or fast for an hour
 * is never taken for a lag. */
static void clock_drift(void)
{
    for (int sign = -1; sign <= 1; sign += 2) {
        stream s;
        uint64_t worst;
        stream_init(&s, 1.0 + sign * 500e-6);
        worst = run_prompt(&s, 3600u * 500u);
        CHECK(worst <= s.period_us + 200, "a controller clock %s by 500 ppm for an hour: lag %llu us",
              sign < 0 ? "slow" : "fast", (unsigned long long)worst);
    }
}

/* A controller that restarted: its clock starts again from zero. */
static void controller_restart(void)
{
    stream s;
    uint64_t lag;
    stream_init(&s, 1.0);
    run_prompt(&s, 1000);
    s.host0 = sent_at(&s, s.k) + 30 * S; /* it comes back 30 s later, from time 0 */
    s.k = 0;
    s.prev_read_us = s.host0;
    lag = run_prompt(&s, 10);
    CHECK(lag <= s.period_us + 100, "a controller restart (clock back to 0): fresh at once (lag %llu us)",
          (unsigned long long)lag);
}

/* A connection that begins with a burst: something between the robot and
 * the gateway held 50 packets back for 100 ms, then they all came at once,
 * right after the connect (so the host saw no wait). Each is younger than
 * the one before; only the newest may anchor the floor, and the ones before
 * it must not pass as fresh. Found by the soak (docs/soak.md). */
static void burst_at_connect(void)
{
    stream s;
    uint64_t connect, judged_fresh = 0, unknown = 0, lag_newest, after;
    stream_init(&s, 1.0);
    s.k = 1000;
    connect = sent_at(&s, s.k + 49) + 100 * MS; /* the newest was sent 100 ms before the connect */
    for (uint64_t i = 0; i < 50; i++) {
        uint64_t rx = connect + 100 + i * 10;
        uint64_t lag = read_in_burst(&s, s.k + i, rx, connect, i == 49);
        unknown += lag == GW_AGE_UNKNOWN;
        judged_fresh += lag <= BOUND && i < 49;
        if (i == 49) {
            lag_newest = lag;
        }
    }
    CHECK(unknown == 49 && judged_fresh == 0, "a burst at the connect: the 49 before the newest are of unknown "
          "age (%llu unknown, %llu judged fresh)", (unsigned long long)unknown, (unsigned long long)judged_fresh);
    CHECK(lag_newest == 100 + 49 * 10, "the newest of the burst anchors the floor: its lag is its wait since "
          "the connect (%llu us)", (unsigned long long)lag_newest);
    s.k += 50;
    s.prev_read_us = connect + 600;
    after = run_prompt(&s, 100);
    CHECK(after <= s.period_us + 200, "then packets read promptly are judged by that floor (lag %llu us)",
          (unsigned long long)after);
}

/* No usable controller clock: the host's bound alone. */
static void no_clock(void)
{
    gw_age age;
    gw_age_reset(&age);
    CHECK(gw_age_lag_us(&age, 10 * S, 10 * S - 300, false, 0, false) == 300, "no controller clock: the host's wait");
    CHECK(gw_age_lag_us(&age, 10 * S, 10 * S + 300, false, 0, true) == 0, "an empty time after the read: no wait");
}


/* ---- the summary's rate meter ------------------------------------------------ */

/* A deterministic jitter of up to +-max_us. */
static int64_t jitter(uint32_t *seed, int64_t max_us)
{
    *seed = *seed * 1103515245u + 12345u;
    return (int64_t)((*seed >> 8) % (uint32_t)(2 * max_us + 1)) - max_us;
}

/* A stream of period_us (with jitter) read once a second at phase_us past
 * each second, for seconds: every reading after the first measurement is
 * within tolerance of the true rate, none is 0, and none comes before it
 * says "not measured" (-1). Returns the number of readings that measured. */
static int meter_stream(uint64_t period_us, int64_t jitter_us, uint64_t phase_us, unsigned seconds, double tolerance)
{
    gw_meter m = {0};
    uint32_t seed = (uint32_t)(period_us + phase_us);
    uint64_t t0 = 1000u * S, nominal = t0 + S / 3u, read = t0 + S + phase_us;
    uint64_t at = nominal; /* the next message's time: nominal, jittered (the order is kept) */
    double want = 1e6 / (double)period_us;
    int measured = 0, bad = 0;
    for (unsigned i = 0; i < seconds; i++, read += S) {
        double rate;
        for (; at <= read; nominal += period_us, at = (uint64_t)((int64_t)nominal + jitter(&seed, jitter_us))) {
            gw_meter_event(&m, at);
        }
        rate = gw_meter_rate(&m, read);
        if (rate < 0 && measured == 0) {
            continue;
        }
        measured++;
        if (rate < want * (1 - tolerance) || rate > want * (1 + tolerance)) {
            bad++;
            printf("  reading %u: %.3f/s, want %.3f/s\n", i, rate, want);
        }
    }
    CHECK(bad == 0, "a %.1f Hz stream read at +%llu ms: every reading within %.0f %% (%d of %d not)", want,
          (unsigned long long)(phase_us / MS), tolerance * 100, bad, measured);
    return measured;
}

static void meter_rates(void)
{
    /* A 1 Hz message (GATEWAY's default) counted in 1 s windows reads 0, 1
     * or 2 by where the window falls: every phase, with 20 ms of jitter,
     * and finely where the readings fall among the messages (at +333 ms). */
    for (uint64_t phase = 0; phase < S; phase += phase >= 300 * MS && phase < 370 * MS ? 5 * MS : 50 * MS) {
        CHECK(meter_stream(S, 20 * MS, phase, 30, 0.05) >= 27, "1 Hz at +%llu ms: measured from the third second on",
              (unsigned long long)(phase / MS));
    }
    meter_stream(S / 2, 10 * MS, 300 * MS, 20, 0.05);   /* 2 Hz */
    meter_stream(100 * MS, 5 * MS, 700 * MS, 20, 0.05); /* 10 Hz */
    meter_stream(2 * MS, 0, 0, 20, 0.01);              /* 500 Hz */
    meter_stream(2 * MS, 300, 999 * MS, 20, 0.01);     /* 500 Hz with jitter */
}

static void meter_stop_and_resume(void)
{
    gw_meter m = {0};
    uint64_t t = 1000u * S;
    CHECK(gw_meter_rate(&m, t) == -1.0, "nothing yet: not measured");
    gw_meter_event(&m, t);
    CHECK(gw_meter_rate(&m, t + S / 2) == -1.0, "one message: not measured");
    for (int i = 1; i <= 5; i++) {
        gw_meter_event(&m, t + (uint64_t)i * S);
    }
    CHECK(gw_meter_rate(&m, t + 5 * S + S / 2) == 1.0, "1 Hz: exactly 1.0");
    /* Stopped: 0 once twice the period has passed, not before. */
    CHECK(gw_meter_rate(&m, t + 6 * S + S / 2) == 1.0, "1.5 periods without a message: still 1.0");
    CHECK(gw_meter_rate(&m, t + 7 * S + 1) == 0.0, "more than 2 periods without one: 0");
    CHECK(gw_meter_rate(&m, t + 9 * S) == 0.0, "still 0");
    /* Resumed at 500 Hz 5 s later: the pause does not dilute the next measurement. */
    t += 12 * S;
    for (int i = 0; i <= 500; i++) {
        gw_meter_event(&m, t + (uint64_t)i * 2 * MS);
    }
    CHECK(gw_meter_rate(&m, t + S + 1 * MS) == 500.0, "resumed at 500 Hz: 500 (%.3f)", gw_meter_rate(&m, t + S + MS));
}

int main(void)
{
    prompt_reader();
    stopped_gateway();
    slow_gateway();
    upstream_lag();
    clock_drift();
    controller_restart();
    burst_at_connect();
    no_clock();
    meter_rates();
    meter_stop_and_resume();
    return check_report();
}
