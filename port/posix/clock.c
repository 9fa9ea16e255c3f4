/* SPDX-License-Identifier: MIT */
/* clock.c: the port's clocks on POSIX. */
#define _GNU_SOURCE
#include <time.h>

#include "port.h"

static uint64_t read_us(clockid_t id)
{
    struct timespec ts;
    /* Cannot fail for these clocks on Linux; a zero is easier to spot than garbage. */
    if (clock_gettime(id, &ts) != 0) {
        return 0;
    }
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

uint64_t urrt_port_monotonic_us(void)
{
    return read_us(CLOCK_MONOTONIC);
}

uint64_t urrt_port_realtime_us(void)
{
    return read_us(CLOCK_REALTIME);
}
