/* SPDX-License-Identifier: MIT */
/*
 * What the C tests share besides check.h: big-endian byte writers (the
 * robot's wire order, for packets built by hand) and one deterministic
 * pseudo-random sequence (tests must not flake: every run sees the same
 * numbers). Freestanding, so that the bare-metal drivers of tests/target
 * include it too.
 */
#ifndef URRT_TEST_TESTUTIL_H
#define URRT_TEST_TESTUTIL_H

#include <stdint.h>

static inline void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static inline void put_be64(uint8_t *p, uint64_t v)
{
    put_be32(p, (uint32_t)(v >> 32));
    put_be32(p + 4, (uint32_t)v);
}

static inline uint64_t get_be64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) {
        v = (v << 8) | p[i];
    }
    return v;
}

/* xorshift64 (Marsaglia): full period over the non-zero states, no
 * multiplications (cheap on a Cortex-M0). One sequence per test program. */
static uint64_t test_rng_state = 0x9E3779B97F4A7C15u;

static inline void test_rng_seed(uint64_t seed)
{
    test_rng_state = seed != 0 ? seed : 0x9E3779B97F4A7C15u;
}

static inline uint64_t test_rng(void)
{
    test_rng_state ^= test_rng_state << 13;
    test_rng_state ^= test_rng_state >> 7;
    test_rng_state ^= test_rng_state << 17;
    return test_rng_state;
}

#endif
