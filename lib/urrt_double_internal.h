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
 * is 0. Worked on the two 32-bit halves: a 32-bit core (a range check per
 * value received, urrt_plcin.c) would otherwise shift 64-bit words by
 * variable amounts, several instructions each. */
static inline bool urrt_int_of_double_bits(uint64_t bits, int64_t *v)
{
    uint32_t hi = (uint32_t)(bits >> 32), lo = (uint32_t)bits;
    unsigned exponent = (unsigned)(hi >> 20) & 0x7FFu;
    uint32_t top = (hi & 0xFFFFFu) | 0x100000u; /* the mantissa's upper 21 bits, its implicit 1 */
    uint64_t m;
    unsigned s;
    if (exponent < 1023u) {
        *v = 0;
        return exponent == 0u && (hi & 0xFFFFFu) == 0u && lo == 0u; /* a zero; else below 1 (or a denormal) */
    }
    if (exponent > 1062u) {
        return false; /* 2^40 or more, infinite, NaN */
    }
    /* value = mantissa (53 bits) >> s, s = 1075 - exponent = 13..52: no fraction
     * when the s bits shifted out are zero */
    if (exponent <= 1043u) {
        s = 1043u - exponent; /* the whole value in top (below 2^21): lo all fraction */
        if (lo != 0u || (top & ((UINT32_C(1) << s) - 1u)) != 0u) {
            return false;
        }
        m = top >> s;
    } else {
        s = 1075u - exponent; /* 13..31 */
        if ((lo & ((UINT32_C(1) << s) - 1u)) != 0u) {
            return false;
        }
        m = (uint64_t)top << (32u - s) | lo >> s;
    }
    *v = (hi >> 31) != 0u ? -(int64_t)m : (int64_t)m;
    return true;
}

#endif
