/* SPDX-License-Identifier: MIT */
/*
 * check-can: lib/urrt_can (bit placement by hand-worked vectors, rounding,
 * saturation, NaN, layout checks, frame bit lengths). Freestanding apart
 * from check.h's printing, so that check-lib-m4 and check-lib-be run it on
 * emulated cores too. The gateway's mapping on top of it is
 * tests/gateway/can/test_can_map.c; bulk packing is checked against
 * python3-canmatrix by tests/gateway/can/test_dbc.py.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "testutil.h"
#include "urrt.h"
#include "urrt_can.h"

/* ---- helpers ----------------------------------------------------------------- */

static urrt_can_signal sig_make(unsigned start, unsigned length, urrt_can_byte_order order, urrt_can_value_type type,
                                double factor, double offset)
{
    urrt_can_signal s;
    memset(&s, 0, sizeof s);
    s.start = (uint16_t)start;
    s.length = (uint8_t)length;
    s.byte_order = (uint8_t)order;
    s.type = (uint8_t)type;
    s.factor = factor;
    s.offset = offset;
    if (urrt_can_signal_range(&s, &s.min, &s.max) < 0) {
        s.min = s.max = 0;
    }
    return s;
}

static uint64_t to_raw(const urrt_can_signal *s, double v, int *outcome)
{
    uint64_t raw = 0xDEADBEEF;
    *outcome = urrt_can_to_raw(s, v, &raw);
    return raw;
}

#define CHECK_RAW(sig, value, want_raw, want_outcome)                                                  \
    do {                                                                                              \
        int outcome_;                                                                                 \
        uint64_t raw_ = to_raw(&(sig), (value), &outcome_);                                           \
        CHECK(raw_ == (uint64_t)(want_raw) && outcome_ == (want_outcome),                             \
              "value %.17g: raw 0x%llX outcome %d, want 0x%llX outcome %d", (double)(value),          \
              (unsigned long long)raw_, outcome_, (unsigned long long)(uint64_t)(want_raw), (want_outcome)); \
    } while (0)

static bool bytes_are(const uint8_t *data, const uint8_t *want, unsigned len)
{
    return memcmp(data, want, len) == 0;
}

static void hex(const uint8_t *d, unsigned len, char *out)
{
    unsigned i;
    for (i = 0; i < len; i++) {
        sprintf(out + 2 * i, "%02X", d[i]);
    }
    out[2 * len] = '\0';
}

/* ---- lib: bit placement ------------------------------------------------------- */

/* The pictures in urrt_can.h: 0xABC as 12 bits at start 12. */
static void placement_pictures(void)
{
    uint8_t d[64];
    char h[130];
    uint64_t raw;
    urrt_can_signal intel = sig_make(12, 12, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal moto = sig_make(12, 12, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    const uint8_t want_intel[8] = {0x00, 0xC0, 0xAB, 0, 0, 0, 0, 0};
    const uint8_t want_moto[8] = {0x00, 0x15, 0x78, 0, 0, 0, 0, 0};
    unsigned lsb, msb, need;
    memset(d, 0, sizeof d);
    CHECK_EQ_INT(urrt_can_put_raw(&intel, 0xABC, d, 8), 0);
    hex(d, 8, h);
    CHECK(bytes_are(d, want_intel, 8), "intel 0xABC@12: %s", h);
    memset(d, 0, sizeof d);
    CHECK_EQ_INT(urrt_can_put_raw(&moto, 0xABC, d, 8), 0);
    hex(d, 8, h);
    CHECK(bytes_are(d, want_moto, 8), "motorola 0xABC@12: %s", h);
    CHECK_EQ_INT(urrt_can_get_raw(&moto, d, 8, &raw), 0);
    CHECK_EQ_INT(raw, 0xABC);
    CHECK_EQ_INT(urrt_can_signal_span(&intel, &lsb, &msb, &need), 0);
    CHECK(lsb == 12 && msb == 23 && need == 3, "intel span %u %u %u", lsb, msb, need);
    CHECK_EQ_INT(urrt_can_signal_span(&moto, &lsb, &msb, &need), 0);
    CHECK(lsb == 17 && msb == 12 && need == 3, "motorola span %u %u %u", lsb, msb, need);
}

/* Whole bytes: 16 bits in bytes 2-3, both orders. */
static void placement_whole_bytes(void)
{
    uint8_t d[64];
    urrt_can_signal moto = sig_make(23, 16, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal intel = sig_make(16, 16, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&moto, 0x1234, d, 8);
    CHECK(d[2] == 0x12 && d[3] == 0x34 && d[1] == 0 && d[4] == 0, "motorola 16@23: %02X %02X", d[2], d[3]);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&intel, 0x1234, d, 8);
    CHECK(d[2] == 0x34 && d[3] == 0x12 && d[1] == 0 && d[4] == 0, "intel 16@16: %02X %02X", d[2], d[3]);
}

/* 64 bits: the whole classic payload. */
static void placement_64_bits(void)
{
    uint8_t d[64];
    char h[130];
    uint64_t raw;
    urrt_can_signal moto = sig_make(7, 64, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal intel = sig_make(0, 64, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    const uint8_t be[8] = {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF};
    const uint8_t le[8] = {0xEF, 0xCD, 0xAB, 0x89, 0x67, 0x45, 0x23, 0x01};
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&moto, UINT64_C(0x0123456789ABCDEF), d, 8);
    hex(d, 8, h);
    CHECK(bytes_are(d, be, 8), "motorola 64@7: %s", h);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&intel, UINT64_C(0x0123456789ABCDEF), d, 8);
    hex(d, 8, h);
    CHECK(bytes_are(d, le, 8), "intel 64@0: %s", h);
    CHECK_EQ_INT(urrt_can_get_raw(&intel, le, 8, &raw), 0);
    CHECK(raw == UINT64_C(0x0123456789ABCDEF), "intel 64 read back %llX", (unsigned long long)raw);
    /* 64 bits at the end of an FD frame, unaligned for Intel. */
    urrt_can_signal tail = sig_make(8 * 56 + 0, 64, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    CHECK_EQ_INT(urrt_can_signal_check(&tail, 64), 0);
    CHECK_EQ_INT(urrt_can_signal_check(&tail, 48), URRT_CAN_E_PAST_END);
    urrt_can_signal odd = sig_make(3, 64, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    CHECK_EQ_INT(urrt_can_signal_check(&odd, 8), URRT_CAN_E_PAST_END);
    CHECK_EQ_INT(urrt_can_signal_check(&odd, 9), 0);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&odd, ~UINT64_C(0), d, 9);
    CHECK(d[0] == 0xF8 && d[7] == 0xFF && d[8] == 0x07, "intel 64@3: %02X..%02X %02X", d[0], d[7], d[8]);
}

/* Single bits and short Motorola runs across a byte boundary. */
static void placement_single_bits(void)
{
    uint8_t d[64];
    urrt_can_signal bit63i = sig_make(63, 1, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal bit63m = sig_make(63, 1, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal m10 = sig_make(1, 10, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal m4 = sig_make(3, 4, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&bit63i, 1, d, 8);
    CHECK(d[7] == 0x80, "bit 63 intel: %02X", d[7]);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&bit63m, 1, d, 8);
    CHECK(d[7] == 0x80, "bit 63 motorola: %02X", d[7]);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&m10, 0x2AA, d, 8); /* 10 1010 1010 */
    CHECK(d[0] == 0x02 && d[1] == 0xAA, "motorola 10@1: %02X %02X", d[0], d[1]);
    memset(d, 0, sizeof d);
    urrt_can_put_raw(&m4, 0xF, d, 8);
    CHECK(d[0] == 0x0F && d[1] == 0, "motorola 4@3: %02X", d[0]);
}

/* Bits outside the signal are left alone. */
static void placement_keeps_other_bits(void)
{
    uint8_t d[64];
    urrt_can_signal moto = sig_make(12, 12, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    memset(d, 0xFF, sizeof d);
    urrt_can_put_raw(&moto, 0, d, 8);
    CHECK(d[0] == 0xFF && d[1] == 0xE0 && d[2] == 0x01 && d[3] == 0xFF, "clear motorola 12@12: %02X %02X %02X",
          d[0], d[1], d[2]);
}

/* Signed read-back is sign-extended. */
static void placement_signed_read_back(void)
{
    uint8_t d[64];
    uint64_t raw;
    urrt_can_signal s = sig_make(4, 12, URRT_CAN_INTEL, URRT_CAN_SIGNED, 0.5, 10);
    double v;
    memset(d, 0, sizeof d);
    CHECK_EQ_INT(urrt_can_pack(&s, -10.0, d, 8), URRT_CAN_PACK_OK); /* raw -40 */
    CHECK_EQ_INT(urrt_can_get_raw(&s, d, 8, &raw), 0);
    CHECK(raw == 0xFD8, "raw -40 in 12 bits: %llX", (unsigned long long)raw);
    CHECK_EQ_INT(urrt_can_unpack(&s, d, 8, &v), 0);
    CHECK(v == -10.0, "unpack %g", v);
    CHECK(urrt_can_from_raw(&s, 0x800) == -2048 * 0.5 + 10, "most negative %g", urrt_can_from_raw(&s, 0x800));
}

static void test_placement(void)
{
    placement_pictures();
    placement_whole_bytes();
    placement_64_bits();
    placement_single_bits();
    placement_keeps_other_bits();
    placement_signed_read_back();
}

/* ---- lib: values ------------------------------------------------------------------ */

/* The raw type's range applies even where min/max are wider than it
 * (a descriptor built by hand, not by the configuration). */
static void values_raw_type_range(urrt_can_signal u8)
{
    urrt_can_signal wide = u8;
    wide.min = -1e9;
    wide.max = 1e9;
    CHECK_RAW(wide, 300, 255, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(wide, -3, 0, URRT_CAN_PACK_SATURATED);
}

/* Physical limits inside the raw range. */
static void values_physical_limits(void)
{
    urrt_can_signal pct = sig_make(0, 8, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 0.5, 0);
    pct.min = 0;
    pct.max = 100;
    CHECK_RAW(pct, 150, 200, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(pct, 99.74, 199, URRT_CAN_PACK_OK); /* 199.48 rounds to 199 */
    CHECK_RAW(pct, 99.75, 200, URRT_CAN_PACK_OK); /* 199.5 rounds away from zero */
}

/* Scaling: factor 0.01, offset -40 (a temperature byte pair). */
static void values_scaling(void)
{
    urrt_can_signal t = sig_make(0, 16, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 0.01, -40);
    CHECK_RAW(t, 25.0, 6500, URRT_CAN_PACK_OK);
    CHECK_RAW(t, -40.0, 0, URRT_CAN_PACK_OK);
    CHECK_RAW(t, -41.0, 0, URRT_CAN_PACK_SATURATED);
    CHECK(fabs(t.max - 615.35) < 1e-9, "max %.17g", t.max);
}

/* Negative factor: the range is ordered, the sign flips. */
static void values_negative_factor(void)
{
    urrt_can_signal n = sig_make(0, 8, URRT_CAN_INTEL, URRT_CAN_SIGNED, -0.5, 0);
    CHECK(n.min == -63.5 && n.max == 64, "negative factor range %g %g", n.min, n.max);
    CHECK_RAW(n, 10, 0xEC, URRT_CAN_PACK_OK); /* raw -20 */
    CHECK_RAW(n, 64, 0x80, URRT_CAN_PACK_OK);
}

/* NaN: outcome NAN; integers carry physical 0 clamped into [min, max],
 * or the configured invalid raw. */
static void values_nan(void)
{
    urrt_can_signal t = sig_make(0, 8, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, -40);
    CHECK_RAW(t, NAN, 40, URRT_CAN_PACK_NAN);
    t.min = 10;
    CHECK_RAW(t, NAN, 50, URRT_CAN_PACK_NAN);
    t.flags = URRT_CAN_SIG_INVALID_RAW;
    t.invalid_raw = 0xFF;
    CHECK_RAW(t, NAN, 0xFF, URRT_CAN_PACK_NAN);
    CHECK_RAW(t, -NAN, 0xFF, URRT_CAN_PACK_NAN);
    t.invalid_raw = 0x1FF; /* does not fit 8 bits */
    CHECK_EQ_INT(urrt_can_to_raw(&t, 1, &(uint64_t){0}), URRT_CAN_E_SIGNAL);
}

/* 64-bit integers at the edges of what a double holds. */
static void values_64_bit_edges(void)
{
    urrt_can_signal u64 = sig_make(0, 64, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal s64 = sig_make(0, 64, URRT_CAN_INTEL, URRT_CAN_SIGNED, 1, 0);
    CHECK_RAW(u64, 18446744073709549568.0, UINT64_C(0xFFFFFFFFFFFFF800), URRT_CAN_PACK_OK);
    CHECK_RAW(u64, 18446744073709551616.0, UINT64_MAX, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(u64, 1e19 * 10, UINT64_MAX, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(s64, -9223372036854775808.0, UINT64_C(0x8000000000000000), URRT_CAN_PACK_OK);
    CHECK_RAW(s64, 9223372036854775808.0, UINT64_C(0x7FFFFFFFFFFFFFFF), URRT_CAN_PACK_SATURATED);
    CHECK_RAW(s64, -9223372036854777856.0, UINT64_C(0x8000000000000000), URRT_CAN_PACK_SATURATED);
    CHECK_RAW(s64, -1.0, UINT64_MAX, URRT_CAN_PACK_OK);
    CHECK(urrt_can_from_raw(&s64, UINT64_C(0x8000000000000000)) == -9223372036854775808.0, "s64 min");
    CHECK(urrt_can_from_raw(&s64, UINT64_MAX) == -1.0, "s64 -1");
    CHECK(urrt_can_from_raw(&u64, UINT64_MAX) == 18446744073709551616.0, "u64 max");
}

/* Tiny factors: the scaled value overflows to infinity, which saturates. */
static void values_tiny_factor(void)
{
    urrt_can_signal tiny = sig_make(0, 32, URRT_CAN_INTEL, URRT_CAN_SIGNED, 1e-300, 0);
    tiny.min = -DBL_MAX;
    tiny.max = DBL_MAX;
    CHECK_RAW(tiny, 1e300, 0x7FFFFFFF, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(tiny, -1e300, 0x80000000, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(tiny, 5e-300, 5, URRT_CAN_PACK_OK);
}

/* float32: IEEE bits, out of range clamped to FLT_MAX (never an
 * undefined double-to-float conversion), NaN stays NaN. */
static void values_float32(void)
{
    urrt_can_signal f = sig_make(0, 32, URRT_CAN_INTEL, URRT_CAN_FLOAT32, 1, 0);
    urrt_can_signal g = sig_make(0, 32, URRT_CAN_INTEL, URRT_CAN_FLOAT32, 2, 1);
    CHECK(f.max == (double)FLT_MAX && f.min == -(double)FLT_MAX, "float32 range %g", f.max);
    CHECK_RAW(f, 1.5, 0x3FC00000, URRT_CAN_PACK_OK);
    CHECK_RAW(f, -2.0, 0xC0000000, URRT_CAN_PACK_OK);
    CHECK_RAW(f, 1e39, 0x7F7FFFFF, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(f, -INFINITY, 0xFF7FFFFF, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(f, NAN, 0x7FC00000, URRT_CAN_PACK_NAN);
    CHECK_RAW(f, 1e-50, 0, URRT_CAN_PACK_OK); /* underflows to +0 */
    CHECK_RAW(g, 4.0, 0x3FC00000, URRT_CAN_PACK_OK);
    CHECK(urrt_can_from_raw(&g, 0x3FC00000) == 4.0, "float32 scaled read-back");
    f.max = 10;
    CHECK_RAW(f, 11, 0x41200000, URRT_CAN_PACK_SATURATED);
}

/* float64, Motorola: the big-endian double. */
static void values_float64(void)
{
    urrt_can_signal d = sig_make(0, 64, URRT_CAN_MOTOROLA, URRT_CAN_FLOAT64, 1, 0);
    uint8_t buf[8] = {0};
    const uint8_t want[8] = {0x3F, 0xF8, 0, 0, 0, 0, 0, 0};
    d.start = 7;
    CHECK_RAW(d, 1.5, UINT64_C(0x3FF8000000000000), URRT_CAN_PACK_OK);
    CHECK_RAW(d, INFINITY, UINT64_C(0x7FEFFFFFFFFFFFFF), URRT_CAN_PACK_SATURATED);
    CHECK_RAW(d, NAN, UINT64_C(0x7FF8000000000000), URRT_CAN_PACK_NAN);
    CHECK_EQ_INT(urrt_can_pack(&d, 1.5, buf, 8), URRT_CAN_PACK_OK);
    CHECK(bytes_are(buf, want, 8), "float64 motorola is the big-endian double");
}

/* Descriptors out of their domain. */
static void values_bad_descriptors(urrt_can_signal u8)
{
    int outcome;
    urrt_can_signal bad = u8;
    uint64_t r;
    bad.factor = 0;
    CHECK_EQ_INT(urrt_can_to_raw(&bad, 1, &r), URRT_CAN_E_SIGNAL);
    bad = u8;
    bad.factor = NAN;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = u8;
    bad.min = 5;
    bad.max = 4;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = u8;
    bad.length = 0;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad.length = 65;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 64), URRT_CAN_E_SIGNAL);
    bad = sig_make(0, 16, URRT_CAN_INTEL, URRT_CAN_FLOAT32, 1, 0);
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = u8;
    bad.type = 9;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = u8;
    bad.start = 600;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 64), URRT_CAN_E_PAST_END);
    CHECK_EQ_INT(urrt_can_pack(NULL, 1, (uint8_t[8]){0}, 8), URRT_E_ARG);
    CHECK_EQ_INT(urrt_can_pack(&u8, 1, NULL, 8), URRT_E_ARG);
    CHECK_EQ_STR(urrt_can_strerror(URRT_CAN_E_OVERLAP), "signals overlap");
    CHECK_EQ_STR(urrt_can_strerror(URRT_E_ARG), "invalid argument");
    CHECK(isnan(urrt_can_from_raw(NULL, 0)), "from_raw(NULL) is NaN");
    outcome = urrt_can_pack(&bad, 1, (uint8_t[64]){0}, 64);
    CHECK_EQ_INT(outcome, URRT_CAN_E_PAST_END);
}

static void test_values(void)
{
    urrt_can_signal u8 = sig_make(0, 8, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    urrt_can_signal s8 = sig_make(0, 8, URRT_CAN_INTEL, URRT_CAN_SIGNED, 1, 0);

    CHECK(u8.min == 0 && u8.max == 255, "u8 range %g %g", u8.min, u8.max);
    CHECK(s8.min == -128 && s8.max == 127, "s8 range %g %g", s8.min, s8.max);
    /* Round half away from zero, never through value + 0.5. */
    CHECK_RAW(u8, 2.5, 3, URRT_CAN_PACK_OK);
    CHECK_RAW(u8, 2.4999999999999996, 2, URRT_CAN_PACK_OK);
    CHECK_RAW(u8, 0.49999999999999994, 0, URRT_CAN_PACK_OK);
    CHECK_RAW(u8, -0.4, 0, URRT_CAN_PACK_SATURATED); /* below min: saturated though it rounds to 0 */
    CHECK_RAW(u8, 255.0, 255, URRT_CAN_PACK_OK);
    CHECK_RAW(s8, -2.5, 0xFD, URRT_CAN_PACK_OK);
    CHECK_RAW(s8, 127.0, 0x7F, URRT_CAN_PACK_OK);
    CHECK_RAW(s8, -128.0, 0x80, URRT_CAN_PACK_OK);
    /* Out of range: clamped to the limits, outcome saturated. */
    CHECK_RAW(u8, 255.5, 255, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(u8, -0.6, 0, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(u8, 1e300, 255, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(u8, INFINITY, 255, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(u8, -INFINITY, 0, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(s8, 128.0, 0x7F, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(s8, -128.6, 0x80, URRT_CAN_PACK_SATURATED);
    CHECK_RAW(s8, -1e308, 0x80, URRT_CAN_PACK_SATURATED);
    values_raw_type_range(u8);
    values_physical_limits();
    values_scaling();
    values_negative_factor();
    values_nan();
    values_64_bit_edges();
    values_tiny_factor();
    values_float32();
    values_float64();
    values_bad_descriptors(u8);
}

/* Random descriptors: pack, unpack, compare within half a raw step; every
 * bit outside the signal is kept; and the word-wide urrt_can_pack_checked
 * and urrt_can_put_raw_checked write the same bytes as the checked calls,
 * whose bytes the placement tests above pin down. */
static void test_round_trip(void)
{
    int n;
    int bad_value = 0;
    int bad_bits = 0;
    int bad_checked = 0;
    for (n = 0; n < 20000; n++) {
        urrt_can_signal s;
        uint8_t data[64];
        uint8_t before[64];
        uint8_t word[64];
        uint8_t raw_bytes[64];
        uint64_t raw = test_rng();
        uint8_t mask[64] = {0};
        unsigned len = (unsigned)(test_rng() % 64) + 1;
        unsigned type = (unsigned)(test_rng() % 4);
        unsigned frame_len = 64;
        double factor;
        double v;
        double back;
        int outcome;
        unsigned i;
        if (type == URRT_CAN_FLOAT32) {
            len = 32;
        } else if (type == URRT_CAN_FLOAT64) {
            len = 64;
        }
        factor = type >= URRT_CAN_FLOAT32 ? 1.0 : ldexp(1.0 + (double)(test_rng() % 1000) / 1000.0, (int)(test_rng() % 20) - 10);
        if (test_rng() % 4 == 0) {
            factor = -factor;
        }
        s = sig_make(0, len, test_rng() % 2 ? URRT_CAN_MOTOROLA : URRT_CAN_INTEL, (urrt_can_value_type)type, factor,
                     (double)((int)(test_rng() % 200) - 100));
        /* A start bit that fits. */
        do {
            s.start = (uint16_t)(test_rng() % (8 * frame_len));
        } while (urrt_can_signal_check(&s, frame_len) != 0);
        for (i = 0; i < 64; i++) {
            before[i] = data[i] = (uint8_t)test_rng();
        }
        urrt_can_put_raw(&s, ~UINT64_C(0), mask, frame_len);
        v = s.min + (s.max - s.min) * (double)(test_rng() % 1000001) / 1000000.0;
        if (type >= URRT_CAN_FLOAT32) {
            v = (double)((int64_t)(test_rng() % 2000001) - 1000000) / 64.0;
        }
        memcpy(word, before, sizeof word);
        outcome = urrt_can_pack(&s, v, data, frame_len);
        bad_checked += urrt_can_pack_checked(&s, v, word) != outcome || memcmp(word, data, sizeof word) != 0;
        memcpy(raw_bytes, data, sizeof raw_bytes);
        urrt_can_put_raw_checked(&s, raw, word);
        urrt_can_put_raw(&s, raw, raw_bytes, frame_len);
        bad_checked += memcmp(word, raw_bytes, sizeof word) != 0;
        urrt_can_unpack(&s, data, frame_len, &back);
        if (outcome != URRT_CAN_PACK_OK || !(fabs(back - v) <= fabs(factor) * 0.5000001 + fabs(v) * 1e-15)) {
            if (bad_value++ < 5) {
                fprintf(stderr, "round trip: len %u type %u start %u factor %g: %.17g -> %.17g (outcome %d)\n", len,
                        type, s.start, factor, v, back, outcome);
            }
        }
        for (i = 0; i < 64; i++) {
            if (((data[i] ^ before[i]) & ~mask[i]) != 0) {
                bad_bits++;
                break;
            }
        }
    }
    CHECK(bad_value == 0, "%d of 20000 random values did not round-trip", bad_value);
    CHECK(bad_bits == 0, "%d of 20000 packs changed bits outside the signal", bad_bits);
    CHECK(bad_checked == 0, "%d of 40000 word-wide writes differ from urrt_can_pack / urrt_can_put_raw", bad_checked);
}

/* ---- lib: bit masks ------------------------------------------------------------------ */

/* A bit mask signal of `length` bits carrying the mask's bits from `first`. */
static urrt_can_signal mask_make(unsigned start, unsigned length, unsigned first, urrt_can_byte_order order)
{
    urrt_can_signal s = sig_make(start, length, order, URRT_CAN_UNSIGNED, 1, 0);
    s.flags = (uint8_t)URRT_CAN_SIG_MASK(first);
    return s;
}

/* What a signal carrying bits first .. first + length - 1 of mask holds,
 * worked out here bit by bit (not as urrt_can shifts and masks). */
static uint64_t mask_bits(uint64_t mask, unsigned first, unsigned length)
{
    uint64_t out = 0;
    unsigned i;
    for (i = 0; i < length && first + i < 64; i++) {
        out |= ((mask >> (first + i)) & 1u) << i;
    }
    return out;
}

static double double_with_bits(uint64_t bits)
{
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* Every pattern of the 18 bits UR defines for the digital inputs and
 * outputs (8 standard, 8 configurable, 2 tool) through every width 1..64
 * from bit 0, and through the tool bits (16-17), the configurable ones
 * (8-15) and bits 4-20: the signal holds exactly its bits, whatever else is
 * set, never saturated. The widths' expected values come from mask_bits'
 * loop, once per pattern. */
static void masks_every_pattern(void)
{
    static const unsigned ranges[][2] = {{16, 2}, {8, 8}, {4, 17}, {17, 1}};
    urrt_can_signal widths[64 + 4];
    urrt_can_scale scales[64 + 4];
    unsigned k;
    uint64_t p;
    long bad = 0;
    for (k = 0; k < 64; k++) {
        widths[k] = mask_make(0, k + 1, 0, URRT_CAN_INTEL);
    }
    for (k = 0; k < 4; k++) {
        widths[64 + k] = mask_make(0, ranges[k][1], ranges[k][0], URRT_CAN_INTEL);
    }
    for (k = 0; k < 64 + 4; k++) {
        CHECK_EQ_INT(urrt_can_scale_prepare(&widths[k], &scales[k]), 0);
    }
    for (p = 0; p < (UINT64_C(1) << 18); p++) {
        for (k = 0; k < 64 + 4; k++) {
            unsigned first = k < 64 ? 0 : ranges[k - 64][0];
            uint64_t want = mask_bits(p, first, widths[k].length);
            uint64_t raw = ~UINT64_C(0);
            int outcome = urrt_can_to_raw_scaled(&widths[k], &scales[k], (double)p, &raw);
            if ((raw != want || outcome != URRT_CAN_PACK_OK) && bad++ < 5) {
                fprintf(stderr, "mask 0x%05llX, bits %u..%u: raw 0x%llX outcome %d, want 0x%llX\n",
                        (unsigned long long)p, first, first + widths[k].length - 1, (unsigned long long)raw, outcome,
                        (unsigned long long)want);
            }
        }
    }
    CHECK(bad == 0, "%ld of 2^18 x 68 masks packed wrong", bad);
}

/* Random masks over the 53 bits a double holds exactly, as UR's doubles
 * and as raw int64s read as doubles (below 2^52: subnormal), through
 * random widths and first bits, Intel and Motorola, read back from the
 * payload bit by bit here; bits outside the signal keep their value. */
static void masks_random(void)
{
    long bad = 0;
    int n;
    for (n = 0; n < 20000; n++) {
        unsigned length = (unsigned)(test_rng() % 64) + 1;
        unsigned first = (unsigned)(test_rng() % (65 - length));
        urrt_can_byte_order order = test_rng() % 2 ? URRT_CAN_MOTOROLA : URRT_CAN_INTEL;
        urrt_can_signal s = mask_make(0, length, first, order);
        uint64_t mask = test_rng() >> (11 + test_rng() % 53); /* 0 .. 2^53 - 1, all bit lengths */
        bool raw_int64 = n % 4 == 0 && mask < (UINT64_C(1) << 52);
        uint64_t want = mask_bits(mask, first, length);
        uint8_t data[64];
        uint8_t before[64];
        unsigned lsb;
        unsigned i;
        uint64_t got = 0;
        int outcome;
        bool outside_kept = true;
        do {
            s.start = (uint16_t)(test_rng() % 512);
        } while (urrt_can_signal_check(&s, 64) != 0);
        for (i = 0; i < 64; i++) {
            before[i] = data[i] = (uint8_t)test_rng();
        }
        outcome = urrt_can_pack_checked(&s, raw_int64 ? double_with_bits(mask) : (double)mask, data);
        urrt_can_signal_span(&s, &lsb, NULL, NULL);
        /* The signal's bits in payload order (docs: Intel up from lsb; Motorola
         * up from lsb within a byte, then on at bit 0 of the byte before). */
        for (i = 0; i < length; i++) {
            unsigned up = lsb % 8u + i; /* Motorola: bits up from lsb's, then the byte before */
            unsigned at = order == URRT_CAN_INTEL ? lsb + i : (lsb / 8u - up / 8u) * 8u + up % 8u;
            got |= (uint64_t)((data[at / 8u] >> (at % 8u)) & 1u) << i;
            before[at / 8u] = (uint8_t)(before[at / 8u] & ~(1u << (at % 8u)));
            data[at / 8u] = (uint8_t)(data[at / 8u] & ~(1u << (at % 8u)));
        }
        outside_kept = memcmp(before, data, sizeof data) == 0;
        if ((got != want || outcome != URRT_CAN_PACK_OK || !outside_kept) && bad++ < 5) {
            fprintf(stderr, "mask 0x%llX%s, bits %u..%u @%u %s: 0x%llX outcome %d, want 0x%llX%s\n",
                    (unsigned long long)mask, raw_int64 ? " (raw int64)" : "", first, first + length - 1, s.start,
                    order == URRT_CAN_INTEL ? "intel" : "motorola", (unsigned long long)got, outcome,
                    (unsigned long long)want, outside_kept ? "" : ", other bits changed");
        }
    }
    CHECK(bad == 0, "%ld of 20000 random masks packed wrong", bad);
}

/* A value that is no mask is NaN's case: 0, or invalid_raw, outcome NAN. */
static void masks_not_a_mask(void)
{
    urrt_can_signal m = mask_make(0, 16, 0, URRT_CAN_INTEL);
    CHECK_RAW(m, 65552.0, 0x0010, URRT_CAN_PACK_OK); /* the issue: input 4 and tool input 0 */
    CHECK_RAW(m, 65535.0, 0xFFFF, URRT_CAN_PACK_OK);
    CHECK_RAW(m, -0.0, 0, URRT_CAN_PACK_OK);
    CHECK_RAW(m, 9007199254740992.0, 0, URRT_CAN_PACK_OK);          /* 2^53: bit 53 only */
    CHECK_RAW(m, double_with_bits(0x10005), 5, URRT_CAN_PACK_OK); /* a raw int64 read as a double */
    CHECK_RAW(m, 9007199254740994.0, 0, URRT_CAN_PACK_NAN);         /* past 2^53 */
    CHECK_RAW(m, 18446744073709551616.0, 0, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, -1.0, 0, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, 0.5, 0, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, 65552.5, 0, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, NAN, 0, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, INFINITY, 0, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, -INFINITY, 0, URRT_CAN_PACK_NAN);
    m.flags |= URRT_CAN_SIG_INVALID_RAW;
    m.invalid_raw = 0xFFFF;
    CHECK_RAW(m, -1.0, 0xFFFF, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, NAN, 0xFFFF, URRT_CAN_PACK_NAN);
    CHECK_RAW(m, 3.0, 3, URRT_CAN_PACK_OK);
}

/* A mask is unsigned, factor 1, offset 0, inside 64 bits; no other flag
 * bits. Its range is the raw type's. */
static void masks_descriptors(void)
{
    urrt_can_signal m = mask_make(0, 8, 56, URRT_CAN_INTEL);
    urrt_can_signal bad;
    double lo;
    double hi;
    CHECK_EQ_INT(urrt_can_signal_check(&m, 8), 0);
    CHECK_EQ_INT(URRT_CAN_SIG_MASK_FIRST(m.flags), 56);
    CHECK_EQ_INT(urrt_can_signal_range(&m, &lo, &hi), 0);
    CHECK(lo == 0 && hi == 255, "mask range %g..%g", lo, hi);
    bad = mask_make(0, 8, 57, URRT_CAN_INTEL);
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = m;
    bad.factor = 2;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = m;
    bad.offset = 1;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = m;
    bad.offset = -0.0;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), 0);
    bad = m;
    bad.type = URRT_CAN_SIGNED;
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    bad = sig_make(0, 8, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    bad.flags = (uint8_t)(URRT_CAN_SIG_MASK(1) & ~URRT_CAN_SIG_BITMASK); /* a first bit without the flag */
    CHECK_EQ_INT(urrt_can_signal_check(&bad, 8), URRT_CAN_E_SIGNAL);
    /* min and max are not a mask's: narrow ones clamp nothing. */
    m = mask_make(0, 16, 0, URRT_CAN_INTEL);
    m.max = 1;
    CHECK_RAW(m, 65552.0, 0x0010, URRT_CAN_PACK_OK);
}

/* urrt_can reads a mask by urrt_bitmask's rule, written again on the bits:
 * the two agree on every exponent (both signs, fractions, the edges at 1,
 * 2^52, 2^53, 2^54, subnormals, infinities, NaNs) and random mantissas. */
static void masks_as_urrt_bitmask(void)
{
    urrt_can_signal m = mask_make(0, 64, 0, URRT_CAN_INTEL);
    long bad = 0;
    unsigned exponent;
    int n;
    for (exponent = 0; exponent < 4096; exponent++) {
        for (n = 0; n < 64; n++) {
            uint64_t fraction = n < 3 ? (uint64_t)n : (test_rng() >> 12) >> (test_rng() % 52) << (test_rng() % 52);
            uint64_t bits = (uint64_t)exponent << 52 | (fraction & UINT64_C(0xFFFFFFFFFFFFF));
            uint64_t want = 0;
            uint64_t raw = 0;
            int ok = urrt_bitmask(double_with_bits(bits), &want) == URRT_OK;
            int outcome = urrt_can_to_raw(&m, double_with_bits(bits), &raw);
            if ((ok ? outcome != URRT_CAN_PACK_OK || raw != want : outcome != URRT_CAN_PACK_NAN || raw != 0) &&
                bad++ < 5) {
                fprintf(stderr, "mask of %016llX: raw 0x%llX outcome %d; urrt_bitmask %s 0x%llX\n",
                        (unsigned long long)bits, (unsigned long long)raw, outcome, ok ? "gives" : "refuses",
                        (unsigned long long)want);
            }
        }
    }
    CHECK(bad == 0, "%ld of 4096 x 64 doubles read as masks unlike urrt_bitmask", bad);
}

static void test_masks(void)
{
    masks_descriptors();
    masks_as_urrt_bitmask();
    masks_not_a_mask();
    masks_every_pattern();
    masks_random();
}

/* ---- lib: layout, lengths, ids, bits on the wire --------------------------------- */

static void test_layout(void)
{
    urrt_can_signal sigs[4];
    size_t a = 99;
    size_t b = 99;
    sigs[0] = sig_make(0, 16, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    sigs[1] = sig_make(23, 16, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0); /* bytes 2-3 */
    sigs[2] = sig_make(32, 4, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    sigs[3] = sig_make(63, 1, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    CHECK_EQ_INT(urrt_can_layout_check(sigs, 4, 8, &a, &b), 0);
    /* A Motorola signal whose MSB is bit 16 (byte 2's low bit) runs into byte 3. */
    sigs[2] = sig_make(16, 2, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 1, 0);
    CHECK_EQ_INT(urrt_can_layout_check(sigs, 4, 8, &a, &b), URRT_CAN_E_OVERLAP);
    CHECK(a == 2 && b == 1, "overlap reported %zu with %zu", a, b);
    sigs[2] = sig_make(15, 1, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    CHECK_EQ_INT(urrt_can_layout_check(sigs, 4, 8, &a, &b), URRT_CAN_E_OVERLAP);
    CHECK(a == 2 && b == 0, "overlap reported %zu with %zu", a, b);
    sigs[2] = sig_make(32, 4, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1, 0);
    CHECK_EQ_INT(urrt_can_layout_check(sigs, 4, 7, &a, &b), URRT_CAN_E_PAST_END);
    CHECK_EQ_INT(a, 3);
    CHECK_EQ_INT(urrt_can_layout_check(sigs, 0, 8, NULL, NULL), 0);
    CHECK_EQ_INT(urrt_can_layout_check(sigs, 4, 65, NULL, NULL), URRT_CAN_E_FRAME_LENGTH);

    CHECK(urrt_can_length_valid(8, false) && !urrt_can_length_valid(9, false), "classic lengths");
    CHECK(urrt_can_length_valid(12, true) && urrt_can_length_valid(64, true) && !urrt_can_length_valid(10, true) &&
              !urrt_can_length_valid(65, true),
          "FD lengths");
    CHECK_EQ_INT(urrt_can_len_to_dlc(48), 14);
    CHECK_EQ_INT(urrt_can_len_to_dlc(13), 0xFF);
    CHECK_EQ_INT(urrt_can_dlc_to_len(9), 12);
    CHECK_EQ_INT(urrt_can_dlc_to_len(16), 0);
    CHECK_EQ_INT(urrt_can_fd_length_round_up(9), 12);
    CHECK_EQ_INT(urrt_can_fd_length_round_up(33), 48);
    CHECK(urrt_can_id_valid(0x7FF, false) && !urrt_can_id_valid(0x800, false), "11-bit ids");
    CHECK(urrt_can_id_valid(0x1FFFFFFF, true) && !urrt_can_id_valid(0x20000000, true), "29-bit ids");
}

static void test_frame_bits(void)
{
    unsigned nominal;
    unsigned data;
    /* Classic, worked by hand from Davis et al.: g + 8s + 13 + floor((g + 8s - 1) / 4). */
    urrt_can_frame_bits(8, false, false, &nominal, &data);
    CHECK(nominal == 135 && data == 0, "11-bit 8 bytes: %u", nominal); /* 34+64+13+24 */
    urrt_can_frame_bits(8, true, false, &nominal, &data);
    CHECK_EQ_INT(nominal, 160); /* 54+64+13+29 */
    urrt_can_frame_bits(0, false, false, &nominal, &data);
    CHECK_EQ_INT(nominal, 55); /* 34+0+13+8 */
    urrt_can_frame_bits(0, true, false, &nominal, &data);
    CHECK_EQ_INT(nominal, 80); /* 54+0+13+13 */
    urrt_can_frame_bits(1, false, false, &nominal, &data);
    CHECK_EQ_INT(nominal, 65); /* 34+8+13+10 */
    /* FD, 64 bytes, 11-bit id: arbitration 17 + 4 stuff + 13 tail = 34;
     * data phase 5 + 512 = 517, + ceil(517/4) = 130 stuff, + 4 + 21 + 7 = 679. */
    urrt_can_frame_bits(64, false, true, &nominal, &data);
    CHECK(nominal == 34 && data == 679, "FD 64: %u + %u", nominal, data);
    /* FD, 8 bytes, 29-bit id: 36 + 8 + 13 = 57; 69 + 18 + 27 = 114. */
    urrt_can_frame_bits(8, true, true, &nominal, &data);
    CHECK(nominal == 57 && data == 114, "FD 8 ext: %u + %u", nominal, data);
    /* FD, 20 bytes: CRC-21. 5 + 160 = 165 + 42 + 32 = 239. */
    urrt_can_frame_bits(20, false, true, &nominal, &data);
    CHECK(nominal == 34 && data == 239, "FD 20: %u + %u", nominal, data);
    /* An invalid FD length counts as the next valid one. */
    urrt_can_frame_bits(10, false, true, &nominal, &data);
    CHECK_EQ_INT(data, 5 + 96 + 26 + 27);
}

int main(void)
{
    test_placement();
    test_values();
    test_round_trip();
    test_masks();
    test_layout();
    test_frame_bits();
    return check_report();
}
