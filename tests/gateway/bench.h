/* SPDX-License-Identifier: MIT */
/*
 * What the gateway's CAN benchmarks share (tests/gateway/can/bench_can.c,
 * tests/gateway/canopen/bench_canopen.c): the clock, a frame sink, and the
 * packet both measure their floor with, urrt_decode of it.
 */
#ifndef URRT_TEST_GATEWAY_BENCH_H
#define URRT_TEST_GATEWAY_BENCH_H

#include <stdint.h>
#include <time.h>

#include "urrt.h"
#include "urrt_can.h"

#define BENCH_PACKET_LEN 1220

static volatile uint64_t sink;

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* An emit function: counts the frames in *(uint64_t *)ctx, reads each. */
static void count_frame(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)now_us;
    *(uint64_t *)ctx += 1;
    sink += f->data[0];
}

/* A packet as a robot sends it, BENCH_PACKET_LEN bytes, decoded into st:
 * every value finite (NaN, which a robot does not send, takes the packing's
 * slower path); small integers keep every value inside its signal's range
 * and bit masks integral. -1 if it cannot be built. */
static int bench_packet(urrt_state *st, uint8_t *packet, size_t size)
{
    urrt_state_clear(st);
    for (int i = 0; i < URRT_FIELD_COUNT; i++) {
        double *v = (double *)(uintptr_t)urrt_field_values(st, (urrt_field_id)i);
        for (unsigned k = 0; k < urrt_field((urrt_field_id)i)->count; k++) {
            v[k] = 1.0 + k;
        }
    }
    return urrt_encode(st, BENCH_PACKET_LEN, packet, size) < 0 || urrt_decode(packet, BENCH_PACKET_LEN, st) < 0
               ? -1
               : 0;
}

#endif
