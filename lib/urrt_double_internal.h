/* SPDX-License-Identifier: MIT */
/*
 * urrt_double_internal.h: exact conversions between integers and the bits
 * of IEEE-754 doubles, with integer operations only, so that a core without
 * a double-precision FPU (Cortex-M0, M3, M4) runs no floating-point routine
 * of libgcc for them. A seam between lib/ files (urrt_rtde_in.c, which packs
 * register values, and urrt_plcin.c, which checks a value against a
 * signal's limits), not for callers.
 */
#ifndef URRT_DOUBLE_INTERNAL_H
#define URRT_DOUBLE_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

/* An integer as the bits of the double of the same value, if it has one
 * exactly (every integer up to 2^53 in magnitude, larger ones with enough
 * trailing zero bits); false otherwise. */
static inline bool urrt_double_bits_of_int(int64_t v, uint64_t *bits)
{
    uint64_t sign = v < 0 ? UINT64_C(1) << 63 : 0u;
    uint64_t m = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
    unsigned top = 0;
    if (m == 0) {
        *bits = 0; /* +0.0 */
        return true;
    }
    while ((m >> top) > 1u) {
        top++;
    }
    if (top > 52u) {
        if ((m & ((UINT64_C(1) << (top - 52u)) - 1u)) != 0) {
            return false;
        }
        m >>= top - 52u;
    } else {
        m <<= 52u - top;
    }
    *bits = sign | (uint64_t)(1023u + top) << 52 | (m & ((UINT64_C(1) << 52) - 1u));
    return true;
}

/* A double's bits as an integer, if it is one exactly and its magnitude is
 * below 2^40 (past every integer register's range); false otherwise. -0.0
 * is 0. */
static inline bool urrt_int_of_double_bits(uint64_t bits, int64_t *v)
{
    unsigned exponent = (unsigned)(bits >> 52) & 0x7FFu;
    uint64_t m = bits & ((UINT64_C(1) << 52) - 1u);
    int shift;
    if (exponent == 0) {
        *v = 0;
        return m == 0; /* a zero, or a denormal (no integer) */
    }
    if (exponent == 0x7FFu) {
        return false; /* infinite, NaN */
    }
    shift = (int)exponent - 1075; /* value = (m | 2^52) * 2^shift */
    m |= UINT64_C(1) << 52;
    if (shift >= -52 + 40) {
        return false; /* 2^40 or more */
    }
    if (shift < -52) {
        return false; /* below 1 in magnitude, not zero */
    }
    if ((m & ((UINT64_C(1) << (unsigned)-shift) - 1u)) != 0) {
        return false; /* a fraction (shift is -52..-13 here) */
    }
    m >>= (unsigned)-shift;
    *v = (bits >> 63) != 0 ? -(int64_t)m : (int64_t)m;
    return true;
}

#endif
