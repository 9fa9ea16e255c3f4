/* SPDX-License-Identifier: MIT */
/* urrt_can: signal packing for CAN payloads. See urrt_can.h for the API and
 * the bit numbering, docs/can.md for the gateway built on it. */
#include "urrt_can.h"

#include <float.h>

#include "urrt.h"

#define URRT_CAN_STATIC_ASSERT(name, cond) typedef char urrt_can_assert_##name[(cond) ? 1 : -1]

URRT_CAN_STATIC_ASSERT(double_is_binary64, sizeof(double) == 8 && DBL_MANT_DIG == 53);
URRT_CAN_STATIC_ASSERT(float_is_binary32, sizeof(float) == 4 && FLT_MANT_DIG == 24);
URRT_CAN_STATIC_ASSERT(errors_apart_from_urrt, (int)URRT_CAN_E_SIGNAL < (int)URRT_E_UNKNOWN_FIELD);

#define PAYLOAD_BITS (8u * URRT_CAN_MAX_LEN)
#define SIGN_BIT UINT64_C(0x8000000000000000)
#define ABS_BITS UINT64_C(0x7FFFFFFFFFFFFFFF)
#define INFINITY_BITS UINT64_C(0x7FF0000000000000)
#define FRACTION_BITS UINT64_C(0x000FFFFFFFFFFFFF)
#define HIDDEN_BIT UINT64_C(0x0010000000000000)
#define ONE_BITS UINT64_C(0x3FF0000000000000)
#define FLOAT32_QUIET_NAN UINT64_C(0x7FC00000)
#define FLOAT64_QUIET_NAN UINT64_C(0x7FF8000000000000)

const char *urrt_can_strerror(int result)
{
    switch (result) {
    case URRT_CAN_E_SIGNAL: return "invalid signal descriptor";
    case URRT_CAN_E_PAST_END: return "signal reaches past the frame's length";
    case URRT_CAN_E_OVERLAP: return "signals overlap";
    case URRT_CAN_E_FRAME_LENGTH: return "invalid frame length";
    case URRT_CAN_E_ID: return "CAN id out of range";
    default: return urrt_strerror(result);
    }
}

/* ---- frames ---------------------------------------------------------------- */

static const uint8_t dlc_lengths[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};

uint8_t urrt_can_len_to_dlc(unsigned len)
{
    uint8_t dlc;
    for (dlc = 0; dlc < 16u; dlc++) {
        if (dlc_lengths[dlc] == len) {
            return dlc;
        }
    }
    return 0xFF;
}

unsigned urrt_can_dlc_to_len(uint8_t dlc)
{
    return dlc < 16u ? dlc_lengths[dlc] : 0u;
}

bool urrt_can_length_valid(unsigned len, bool fd)
{
    if (!fd) {
        return len <= URRT_CAN_CLASSIC_MAX_LEN;
    }
    return urrt_can_len_to_dlc(len) != 0xFF;
}

unsigned urrt_can_fd_length_round_up(unsigned len)
{
    uint8_t dlc;
    for (dlc = 0; dlc < 16u; dlc++) {
        if (dlc_lengths[dlc] >= len) {
            return dlc_lengths[dlc];
        }
    }
    return URRT_CAN_MAX_LEN;
}

bool urrt_can_id_valid(uint32_t id, bool extended)
{
    return id <= (extended ? URRT_CAN_EFF_MAX : URRT_CAN_SFF_MAX);
}

void urrt_can_frame_bits(unsigned len, bool extended, bool fd, unsigned *nominal_bits, unsigned *data_bits)
{
    unsigned nominal;
    unsigned data;
    if (!fd) {
        unsigned g = extended ? 54u : 34u;
        unsigned s = len < URRT_CAN_CLASSIC_MAX_LEN ? len : URRT_CAN_CLASSIC_MAX_LEN;
        nominal = g + 8u * s + 13u + (g + 8u * s - 1u) / 4u;
        data = 0;
    } else {
        /* SOF, id, (SRR, IDE, id extension,) RRS, IDE/FDF, res, BRS. */
        unsigned arbitration = extended ? 36u : 17u;
        unsigned s = urrt_can_fd_length_round_up(len);
        unsigned stuffed = 5u + 8u * s; /* ESI, DLC, data */
        nominal = arbitration + (arbitration - 1u) / 4u + 13u;
        data = stuffed + (stuffed + 3u) / 4u + (s <= 16u ? 4u + 17u + 6u : 4u + 21u + 7u);
    }
    if (nominal_bits != NULL) {
        *nominal_bits = nominal;
    }
    if (data_bits != NULL) {
        *data_bits = data;
    }
}

/* ---- descriptors ------------------------------------------------------------- */

static uint64_t low_mask(unsigned length)
{
    return length >= 64u ? ~UINT64_C(0) : (UINT64_C(1) << length) - 1u;
}

typedef union {
    float f;
    uint32_t u;
} float_bits;

typedef union {
    double d;
    uint64_t u;
} double_bits;

static uint64_t bits_of(double x)
{
    double_bits b;
    b.d = x;
    return b.u;
}

/* Doubles are compared as integers, which a core without a double FPU does
 * in a few instructions instead of a call into libgcc. */
static bool is_finite(double x)
{
    return (bits_of(x) & ABS_BITS) < INFINITY_BITS;
}

/* An integer in the numeric order of the (non-NaN) doubles, -0 equal to +0. */
static int64_t order_key(uint64_t bits)
{
    int64_t magnitude = (int64_t)(bits & ABS_BITS);
    return (bits & SIGN_BIT) != 0u ? -magnitude : magnitude;
}

/* A bit mask: unsigned, factor exactly 1, offset +-0, its bits inside the
 * 64 of a mask. */
static bool mask_valid(const urrt_can_signal *sig)
{
    return sig->type == (uint8_t)URRT_CAN_UNSIGNED && bits_of(sig->factor) == ONE_BITS &&
           (bits_of(sig->offset) & ABS_BITS) == 0u && URRT_CAN_SIG_MASK_FIRST(sig->flags) + sig->length <= 64u;
}

static bool descriptor_valid(const urrt_can_signal *sig)
{
    if (sig->length < 1u || sig->length > 64u || sig->byte_order > (uint8_t)URRT_CAN_MOTOROLA) {
        return false;
    }
    switch ((urrt_can_value_type)sig->type) {
    case URRT_CAN_UNSIGNED:
    case URRT_CAN_SIGNED: break;
    case URRT_CAN_FLOAT32:
        if (sig->length != 32u) {
            return false;
        }
        break;
    case URRT_CAN_FLOAT64:
        if (sig->length != 64u) {
            return false;
        }
        break;
    default: return false;
    }
    /* The flags before the numbers: a mask's factor and offset are done with
     * before the limits are loaded (fewer registers live on a 32-bit core). */
    if ((sig->flags & URRT_CAN_SIG_BITMASK) != 0u ? !mask_valid(sig)
                                                  : (sig->flags & ~URRT_CAN_SIG_INVALID_RAW) != 0u) {
        return false;
    }
    if (!is_finite(sig->factor) || (bits_of(sig->factor) & ABS_BITS) == 0u || !is_finite(sig->offset) ||
        !is_finite(sig->min) || !is_finite(sig->max) || order_key(bits_of(sig->min)) > order_key(bits_of(sig->max))) {
        return false;
    }
    if ((sig->flags & URRT_CAN_SIG_INVALID_RAW) != 0u && (sig->invalid_raw & ~low_mask(sig->length)) != 0u) {
        return false;
    }
    return true;
}

/* Motorola bits counted from the most significant bit of byte 0 downwards
 * ("big-endian linear"): a Motorola signal is a contiguous run there. */
static unsigned motorola_linear(unsigned dbc_bit)
{
    return (dbc_bit / 8u) * 8u + (7u - dbc_bit % 8u);
}

/* Where the signal's least significant bit sits: byte and bit in it, and
 * the direction towards the more significant bytes. */
static void lsb_position(const urrt_can_signal *sig, unsigned *byte, unsigned *bit, int *step)
{
    if (sig->byte_order == (uint8_t)URRT_CAN_INTEL) {
        *byte = sig->start / 8u;
        *bit = sig->start % 8u;
        *step = 1;
    } else {
        unsigned lsb_linear = motorola_linear(sig->start) + sig->length - 1u;
        *byte = lsb_linear / 8u;
        *bit = 7u - lsb_linear % 8u;
        *step = -1;
    }
}

int urrt_can_signal_span(const urrt_can_signal *sig, unsigned *lsb, unsigned *msb, unsigned *bytes_needed)
{
    unsigned lo;
    unsigned hi;
    unsigned bytes;
    if (sig == NULL) {
        return URRT_E_ARG;
    }
    if (sig->length < 1u || sig->length > 64u || sig->start >= PAYLOAD_BITS) {
        return URRT_CAN_E_SIGNAL;
    }
    if (sig->byte_order == (uint8_t)URRT_CAN_INTEL) {
        lo = sig->start;
        hi = sig->start + sig->length - 1u;
        bytes = (hi + 8u) / 8u;
    } else {
        unsigned last = motorola_linear(sig->start) + sig->length - 1u;
        hi = sig->start;
        lo = (last / 8u) * 8u + (7u - last % 8u);
        bytes = last / 8u + 1u;
    }
    if (lsb != NULL) {
        *lsb = lo;
    }
    if (msb != NULL) {
        *msb = hi;
    }
    if (bytes_needed != NULL) {
        *bytes_needed = bytes;
    }
    return 0;
}

int urrt_can_signal_check(const urrt_can_signal *sig, unsigned frame_len)
{
    unsigned bytes;
    int rc;
    if (sig == NULL) {
        return URRT_E_ARG;
    }
    if (!descriptor_valid(sig)) {
        return URRT_CAN_E_SIGNAL;
    }
    rc = urrt_can_signal_span(sig, NULL, NULL, &bytes);
    if (rc < 0) {
        return sig->start >= PAYLOAD_BITS ? URRT_CAN_E_PAST_END : rc;
    }
    return bytes > frame_len ? URRT_CAN_E_PAST_END : 0;
}

int urrt_can_signal_range(const urrt_can_signal *sig, double *lo, double *hi)
{
    double raw_lo;
    double raw_hi;
    double a;
    double b;
    if (sig == NULL || lo == NULL || hi == NULL) {
        return URRT_E_ARG;
    }
    if (!descriptor_valid(sig)) {
        return URRT_CAN_E_SIGNAL;
    }
    switch ((urrt_can_value_type)sig->type) {
    case URRT_CAN_UNSIGNED:
        raw_lo = 0.0;
        raw_hi = (double)low_mask(sig->length);
        break;
    case URRT_CAN_SIGNED:
        raw_hi = (double)(low_mask(sig->length) >> 1);
        raw_lo = -raw_hi - 1.0;
        break;
    case URRT_CAN_FLOAT32:
        raw_lo = -(double)FLT_MAX;
        raw_hi = (double)FLT_MAX;
        break;
    default:
        raw_lo = -DBL_MAX;
        raw_hi = DBL_MAX;
        break;
    }
    a = raw_lo * sig->factor + sig->offset;
    b = raw_hi * sig->factor + sig->offset;
    if (a > b) {
        double t = a;
        a = b;
        b = t;
    }
    /* Scaling a float64 range overflows to infinity (defined in IEEE-754);
     * limits stay finite. */
    *lo = a < -DBL_MAX ? -DBL_MAX : a;
    *hi = b > DBL_MAX ? DBL_MAX : b;
    return 0;
}

/* ---- bits ---------------------------------------------------------------------- */

/* Writes (or with `write` false, reads) the signal's bits chunk by chunk
 * from its least significant bit. The descriptor's span is checked. */
static uint64_t move_bits(const urrt_can_signal *sig, uint8_t *data, uint64_t raw, bool write)
{
    unsigned byte;
    unsigned bit;
    int step;
    unsigned done = 0;
    uint64_t out = 0;

    lsb_position(sig, &byte, &bit, &step);
    while (done < sig->length) {
        unsigned room = 8u - bit;
        unsigned n = sig->length - done < room ? sig->length - done : room;
        unsigned chunk_mask = ((1u << n) - 1u) << bit;
        if (write) {
            unsigned chunk = (unsigned)((raw >> done) & ((1u << n) - 1u)) << bit;
            data[byte] = (uint8_t)((data[byte] & ~chunk_mask) | chunk);
        } else {
            out |= (uint64_t)((data[byte] & chunk_mask) >> bit) << done;
        }
        done += n;
        bit = 0;
        byte = step > 0 ? byte + 1u : byte - 1u;
    }
    return out;
}

/*
 * Writing a signal a 64-bit word at a time is four times fewer instructions
 * than chunk by chunk on a 64-bit host (urrt-gateway packs every frame
 * with it); a build for size (-Os, firmware) keeps the chunk loop alone,
 * about 450 bytes smaller. Define URRT_CAN_WORD_WRITES to 0 or 1 to choose.
 */
#ifndef URRT_CAN_WORD_WRITES
#ifdef __OPTIMIZE_SIZE__
#define URRT_CAN_WORD_WRITES 0
#else
#define URRT_CAN_WORD_WRITES 1
#endif
#endif

#if URRT_CAN_WORD_WRITES
/* Eight bytes from p as one integer, p[0] least (le) or most (be)
 * significant; written out byte by byte, which compilers turn into one
 * load or store (and a byte swap) where the core allows. */
static uint64_t load_le64(const uint8_t *p)
{
    return (uint64_t)p[0] | (uint64_t)p[1] << 8 | (uint64_t)p[2] << 16 | (uint64_t)p[3] << 24 |
           (uint64_t)p[4] << 32 | (uint64_t)p[5] << 40 | (uint64_t)p[6] << 48 | (uint64_t)p[7] << 56;
}

static uint64_t load_be64(const uint8_t *p)
{
    return (uint64_t)p[7] | (uint64_t)p[6] << 8 | (uint64_t)p[5] << 16 | (uint64_t)p[4] << 24 |
           (uint64_t)p[3] << 32 | (uint64_t)p[2] << 40 | (uint64_t)p[1] << 48 | (uint64_t)p[0] << 56;
}

static void store_le64(uint8_t *p, uint64_t w)
{
    p[0] = (uint8_t)w;
    p[1] = (uint8_t)(w >> 8);
    p[2] = (uint8_t)(w >> 16);
    p[3] = (uint8_t)(w >> 24);
    p[4] = (uint8_t)(w >> 32);
    p[5] = (uint8_t)(w >> 40);
    p[6] = (uint8_t)(w >> 48);
    p[7] = (uint8_t)(w >> 56);
}

static void store_be64(uint8_t *p, uint64_t w)
{
    p[7] = (uint8_t)w;
    p[6] = (uint8_t)(w >> 8);
    p[5] = (uint8_t)(w >> 16);
    p[4] = (uint8_t)(w >> 24);
    p[3] = (uint8_t)(w >> 32);
    p[2] = (uint8_t)(w >> 40);
    p[1] = (uint8_t)(w >> 48);
    p[0] = (uint8_t)(w >> 56);
}

/* move_bits' write into a whole frame buffer: the signal in one 64-bit
 * word of it where it fits in one (any signal of up to 57 bits, and every
 * signal of a classic frame), else chunk by chunk. An Intel signal counts up from bit `shift` of a little-endian
 * word; a Motorola one from bit `shift` of a big-endian word, which holds
 * its contiguous run of big-endian linear bits. */
static void put_bits_in_frame(const urrt_can_signal *sig, uint8_t *data, uint64_t raw)
{
    uint64_t mask = low_mask(sig->length);
    unsigned at;
    unsigned shift;
    if (sig->byte_order == (uint8_t)URRT_CAN_INTEL) {
        at = sig->start / 8u < URRT_CAN_MAX_LEN - 8u ? sig->start / 8u : URRT_CAN_MAX_LEN - 8u;
        shift = sig->start - 8u * at;
    } else {
        unsigned lsb = motorola_linear(sig->start) + sig->length - 1u;
        at = lsb / 8u >= 7u ? lsb / 8u - 7u : 0u;
        shift = 8u * at + 63u - lsb;
    }
    if (shift + sig->length > 64u) {
        (void)move_bits(sig, data, raw, true);
    } else if (sig->byte_order == (uint8_t)URRT_CAN_INTEL) {
        store_le64(data + at, (load_le64(data + at) & ~(mask << shift)) | (raw & mask) << shift);
    } else {
        store_be64(data + at, (load_be64(data + at) & ~(mask << shift)) | (raw & mask) << shift);
    }
}
#else
static void put_bits_in_frame(const urrt_can_signal *sig, uint8_t *data, uint64_t raw)
{
    (void)move_bits(sig, data, raw, true);
}
#endif

static int check_placement(const urrt_can_signal *sig, const void *data, unsigned frame_len)
{
    if (sig == NULL || data == NULL) {
        return URRT_E_ARG;
    }
    return urrt_can_signal_check(sig, frame_len);
}

int urrt_can_put_raw(const urrt_can_signal *sig, uint64_t raw, uint8_t *data, unsigned frame_len)
{
    int rc = check_placement(sig, data, frame_len);
    if (rc < 0) {
        return rc;
    }
    (void)move_bits(sig, data, raw, true);
    return 0;
}

int urrt_can_get_raw(const urrt_can_signal *sig, const uint8_t *data, unsigned frame_len, uint64_t *raw)
{
    int rc = check_placement(sig, data, frame_len);
    if (rc < 0) {
        return rc;
    }
    if (raw == NULL) {
        return URRT_E_ARG;
    }
    /* move_bits only reads when write is false. */
    *raw = move_bits(sig, (uint8_t *)(uintptr_t)data, 0, false);
    return 0;
}

static void mark_bits(const urrt_can_signal *sig, uint8_t *mask)
{
    (void)move_bits(sig, mask, ~UINT64_C(0), true);
}

static bool masks_overlap(const uint8_t *a, const uint8_t *b, unsigned len)
{
    unsigned i;
    for (i = 0; i < len; i++) {
        if ((a[i] & b[i]) != 0u) {
            return true;
        }
    }
    return false;
}

int urrt_can_layout_check(const urrt_can_signal *sigs, size_t count, unsigned frame_len, size_t *first,
                          size_t *second)
{
    uint8_t occupied[URRT_CAN_MAX_LEN];
    uint8_t mine[URRT_CAN_MAX_LEN];
    size_t i;
    size_t j;
    unsigned k;

    if (sigs == NULL && count > 0) {
        return URRT_E_ARG;
    }
    if (frame_len > URRT_CAN_MAX_LEN) {
        return URRT_CAN_E_FRAME_LENGTH;
    }
    for (k = 0; k < URRT_CAN_MAX_LEN; k++) {
        occupied[k] = 0;
    }
    for (i = 0; i < count; i++) {
        int rc = urrt_can_signal_check(&sigs[i], frame_len);
        if (rc < 0) {
            if (first != NULL) {
                *first = i;
            }
            return rc;
        }
        for (k = 0; k < URRT_CAN_MAX_LEN; k++) {
            mine[k] = 0;
        }
        mark_bits(&sigs[i], mine);
        if (masks_overlap(occupied, mine, frame_len)) {
            /* Which earlier signal: rebuild their masks one at a time. */
            for (j = 0; j < i; j++) {
                uint8_t theirs[URRT_CAN_MAX_LEN];
                for (k = 0; k < URRT_CAN_MAX_LEN; k++) {
                    theirs[k] = 0;
                }
                mark_bits(&sigs[j], theirs);
                if (masks_overlap(theirs, mine, frame_len)) {
                    break;
                }
            }
            if (first != NULL) {
                *first = i;
            }
            if (second != NULL) {
                *second = j;
            }
            return URRT_CAN_E_OVERLAP;
        }
        for (k = 0; k < frame_len; k++) {
            occupied[k] = (uint8_t)(occupied[k] | mine[k]);
        }
    }
    return 0;
}

/* ---- values ------------------------------------------------------------------------ */

/*
 * Integer signals are scaled exactly, in integers: raw = (value - offset) /
 * factor rounded half away from zero, on the exact binary values of the
 * three doubles. With |factor| = divisor * 2^(half_exponent + 1), divisor
 * odd, and X = floor(2 |value - offset| / 2^(half_exponent + 1)) (the
 * difference exact, in units of half the factor's last bit), the rounded
 * magnitude is floor((X + divisor) / (2 divisor)): the bits of the
 * difference below that unit cannot move it, since the divisor is an
 * integer. The division by the divisor is a multiplication by its
 * reciprocal, prepared once (urrt_can_scale_prepare) and corrected exactly
 * by the remainder, so that packing needs no division and no
 * floating-point arithmetic at all (soft-float cores spend thousands of
 * instructions on one double division).
 */

/* |x| = mantissa * 2^exponent. */
typedef struct {
    uint64_t mantissa;
    int exponent;
} dyadic;

static dyadic magnitude_of(uint64_t bits)
{
    dyadic d;
    unsigned biased = (unsigned)(bits >> 52) & 0x7FFu;
    d.mantissa = bits & FRACTION_BITS;
    d.exponent = -1074; /* subnormal */
    if (biased != 0u) {
        d.mantissa |= HIDDEN_BIT;
        d.exponent = (int)biased - 1075;
    }
    return d;
}

/* An unsigned 128-bit integer. */
typedef struct {
    uint64_t hi;
    uint64_t lo;
} wide;

static wide wide_of(uint64_t x)
{
    wide w;
    w.hi = 0;
    w.lo = x;
    return w;
}

static wide wide_left(wide x, unsigned k) /* k < 128 */
{
    if (k >= 64u) {
        x.hi = x.lo << (k - 64u);
        x.lo = 0;
    } else if (k > 0u) {
        x.hi = x.hi << k | x.lo >> (64u - k);
        x.lo <<= k;
    }
    return x;
}

static wide wide_right(wide x, unsigned k)
{
    if (k >= 128u) {
        return wide_of(0);
    }
    if (k >= 64u) {
        x.lo = x.hi >> (k - 64u);
        x.hi = 0;
    } else if (k > 0u) {
        x.lo = x.lo >> k | x.hi << (64u - k);
        x.hi >>= k;
    }
    return x;
}

static wide wide_add(wide x, uint64_t y)
{
    x.lo += y;
    x.hi += x.lo < y;
    return x;
}

static wide wide_sub(wide x, uint64_t y)
{
    x.hi -= x.lo < y;
    x.lo -= y;
    return x;
}

/* x < 2^bits, for bits <= 128. */
static bool wide_below(wide x, unsigned bits)
{
    if (bits >= 64u) {
        return bits >= 128u || x.hi >> (bits - 64u) == 0u;
    }
    return x.hi == 0u && x.lo >> bits == 0u;
}

/* The high half of a * b. */
static uint64_t mul_high(uint64_t a, uint64_t b)
{
#if defined(__GNUC__) && defined(__SIZEOF_INT128__)
    __extension__ typedef unsigned __int128 u128;
    return (uint64_t)(((u128)a * b) >> 64);
#else
    uint64_t a_lo = (uint32_t)a;
    uint64_t a_hi = a >> 32;
    uint64_t b_lo = (uint32_t)b;
    uint64_t b_hi = b >> 32;
    uint64_t lo_lo = a_lo * b_lo;
    uint64_t hi_lo = a_hi * b_lo;
    uint64_t lo_hi = a_lo * b_hi;
    uint64_t middle = (lo_lo >> 32) + (uint32_t)hi_lo + lo_hi; /* below 3 * 2^32 */
    return a_hi * b_hi + (hi_lo >> 32) + (middle >> 32);
#endif
}

/* floor((2^128 - 1) / d) - 2^64 for d >= 2^63: Moller and Granlund,
 * "Improved division by invariant integers" (IEEE Trans. Computers, 2011),
 * algorithm 3, with its 256-entry table computed by one 32-bit division. */
static uint64_t reciprocal_of(uint64_t d)
{
    uint32_t v0 = UINT32_C(0x7FD00) / (uint32_t)(d >> 55);
    uint64_t d40 = (d >> 24) + 1u;
    uint64_t v1 = ((uint64_t)v0 << 11) - (uint32_t)(((uint64_t)v0 * v0 * d40) >> 40) - 1u;
    uint64_t v2 = (v1 << 13) + ((v1 * ((UINT64_C(1) << 60) - v1 * d40)) >> 47);
    uint64_t d0 = d & 1u;
    uint64_t e = ((v2 >> 1) & (0u - d0)) - v2 * ((d >> 1) + d0);
    uint64_t v3 = (mul_high(v2, e) >> 1) + (v2 << 31);
    uint64_t low = v3 * d;
    uint64_t high = mul_high(v3, d) + (low + d < low);
    return v3 - high - d;
}

/* Trailing zero bits and bit length of a non-zero x, by halving: no libgcc
 * call on cores without a count-leading-zeros instruction. */
static unsigned trailing_zeros(uint64_t x)
{
    unsigned n = 0;
    unsigned half;
    for (half = 32u; half > 0u; half /= 2u) {
        if ((x & ((UINT64_C(1) << half) - 1u)) == 0u) {
            x >>= half;
            n += half;
        }
    }
    return n;
}

static unsigned bit_length(uint64_t x)
{
    unsigned n = 0;
    unsigned half;
    for (half = 32u; half > 0u; half /= 2u) {
        if (x >> half != 0u) {
            x >>= half;
            n += half;
        }
    }
    return n + (unsigned)x;
}

/* The factor of a valid descriptor (finite, non-zero). */
static void scale_of(double factor, urrt_can_scale *scale)
{
    uint64_t bits = bits_of(factor);
    dyadic f = magnitude_of(bits);
    unsigned zeros = trailing_zeros(f.mantissa);
    unsigned length;
    f.mantissa >>= zeros;
    length = bit_length(f.mantissa);
    scale->divisor = f.mantissa;
    scale->reciprocal = f.mantissa > 1u ? reciprocal_of(f.mantissa << (64u - length)) : 0u;
    scale->half_exponent = (int16_t)(f.exponent + (int)zeros - 1);
    scale->divisor_bits = (uint8_t)length;
    scale->negative = (bits & SIGN_BIT) != 0u;
}

int urrt_can_scale_prepare(const urrt_can_signal *sig, urrt_can_scale *scale)
{
    if (sig == NULL || scale == NULL) {
        return URRT_E_ARG;
    }
    if (!descriptor_valid(sig)) {
        return URRT_CAN_E_SIGNAL;
    }
    scale_of(sig->factor, scale);
    return 0;
}

/* Exact sums need the larger term's bits shifted this far at most. */
#define ALIGN_BITS 70u

/* The difference is kept below this many bits; anything larger gives a
 * raw value of at least 2^121 / 2^54, past every integer type. */
#define DIFFERENCE_BITS 121u

/* n * 2^shift as a whole number: floor for a negative shift. */
static bool to_units(wide n, int shift, wide *x)
{
    if (shift <= 0) {
        *x = wide_right(n, (unsigned)-shift);
        return wide_below(*x, DIFFERENCE_BITS);
    }
    if ((unsigned)shift >= DIFFERENCE_BITS || !wide_below(n, DIFFERENCE_BITS - (unsigned)shift)) {
        return false;
    }
    *x = wide_left(n, (unsigned)shift);
    return true;
}

/*
 * floor(|v - o| / 2^unit) for finite v and o (bits), on their exact values:
 * *x, and *negative for v < o; false when it is 2^121 or more. The smaller
 * term, when it lies wholly below the larger one's last bit by more than
 * ALIGN_BITS, is kept to that many bits and a borrow: enough for the floor,
 * as the result then either has no bits below 2^unit or is too large.
 */
static bool exact_difference(uint64_t v, uint64_t o, int unit, wide *x, bool *negative)
{
    uint64_t big = v;
    uint64_t small = o ^ SIGN_BIT; /* v - o = v + (-o) */
    bool subtract;
    dyadic b;
    dyadic s;
    wide n;
    int at;
    if ((big & ABS_BITS) < (small & ABS_BITS)) {
        big = small;
        small = v;
    }
    b = magnitude_of(big);
    s = magnitude_of(small);
    *negative = (big & SIGN_BIT) != 0u;
    subtract = ((big ^ small) & SIGN_BIT) != 0u;
    n = wide_of(b.mantissa);
    at = b.exponent;
    if (s.mantissa != 0u) {
        unsigned apart = (unsigned)(b.exponent - s.exponent); /* b >= s */
        uint64_t term = s.mantissa;
        if (apart <= ALIGN_BITS) {
            n = wide_left(n, apart);
            at = s.exponent;
        } else {
            unsigned drop = apart - ALIGN_BITS;
            bool borrow = subtract && (drop >= 64u || s.mantissa << (64u - drop) != 0u);
            term = (drop < 64u ? s.mantissa >> drop : 0u) + borrow;
            n = wide_left(n, ALIGN_BITS);
            at = b.exponent - (int)ALIGN_BITS;
            if (at > unit) {
                return false; /* |v - o| >= 2^(52 + ALIGN_BITS - 1) units */
            }
        }
        n = subtract ? wide_sub(n, term) : wide_add(n, term);
    }
    return to_units(n, at - unit, x);
}

/* floor((x + divisor) / (2 divisor)), x below 2^121: false when it is 2^64
 * or more. The estimate through the reciprocal is at most 3 below the
 * quotient; the remainder corrects it. */
static bool rounded_quotient(const urrt_can_scale *scale, wide x, uint64_t *q)
{
    uint64_t divisor = scale->divisor;
    unsigned bits = scale->divisor_bits;
    wide z = wide_right(wide_add(x, divisor), 1);
    uint64_t top;
    uint64_t rest;
    if (divisor == 1u) {
        *q = z.lo;
        return z.hi == 0u;
    }
    if (z.hi >= divisor) {
        return false;
    }
    top = z.hi << (64u - bits) | z.lo >> bits;
    *q = top + mul_high(top, scale->reciprocal);
    rest = z.lo - *q * divisor;
    while (rest >= divisor) {
        rest -= divisor;
        ++*q;
    }
    return true;
}

/* The raw value of an integer signal for a finite value (bits), clamped to
 * the raw type's range. */
static int integer_raw(const urrt_can_signal *sig, const urrt_can_scale *scale, uint64_t value, uint64_t *raw)
{
    uint64_t mask = low_mask(sig->length);
    uint64_t top = sig->type == (uint8_t)URRT_CAN_SIGNED ? mask >> 1 : mask;
    uint64_t n = 0;
    wide x;
    bool negative;
    bool fits = exact_difference(value, bits_of(sig->offset), scale->half_exponent, &x, &negative) &&
                rounded_quotient(scale, x, &n);
    negative = negative != (scale->negative != 0u);
    if (negative && fits && n == 0u) {
        negative = false; /* -0 */
    }
    if (!negative) {
        *raw = fits && n <= top ? n : top;
        return fits && n <= top ? URRT_CAN_PACK_OK : URRT_CAN_PACK_SATURATED;
    }
    if (sig->type == (uint8_t)URRT_CAN_UNSIGNED) {
        *raw = 0;
        return URRT_CAN_PACK_SATURATED;
    }
    if (!fits || n > top + 1u) {
        *raw = (top + 1u) & mask; /* the most negative value */
        return URRT_CAN_PACK_SATURATED;
    }
    *raw = (~n + 1u) & mask; /* two's complement, in length bits */
    return URRT_CAN_PACK_OK;
}

/* An integer signal: clamped to [min, max] (compared as integers), NaN
 * as physical 0 clamped into them, then scaled. */
static int scaled_to_raw(const urrt_can_signal *sig, const urrt_can_scale *scale, double value, uint64_t *raw)
{
    uint64_t bits = bits_of(value);
    uint64_t min = bits_of(sig->min);
    uint64_t max = bits_of(sig->max);
    int outcome = URRT_CAN_PACK_OK;
    int raw_outcome;
    if ((bits & ABS_BITS) > INFINITY_BITS) {
        if ((sig->flags & URRT_CAN_SIG_INVALID_RAW) != 0u) {
            *raw = sig->invalid_raw;
            return URRT_CAN_PACK_NAN;
        }
        bits = order_key(min) > 0 ? min : order_key(max) < 0 ? max : 0u;
        outcome = URRT_CAN_PACK_NAN;
    } else if (order_key(bits) < order_key(min)) {
        bits = min; /* -inf too */
        outcome = URRT_CAN_PACK_SATURATED;
    } else if (order_key(bits) > order_key(max)) {
        bits = max;
        outcome = URRT_CAN_PACK_SATURATED;
    }
    raw_outcome = integer_raw(sig, scale, bits, raw);
    return outcome > raw_outcome ? outcome : raw_outcome;
}

static int clamp_to_limits(const urrt_can_signal *sig, double *value)
{
    if (*value < sig->min) {
        *value = sig->min;
        return URRT_CAN_PACK_SATURATED;
    }
    if (*value > sig->max) {
        *value = sig->max;
        return URRT_CAN_PACK_SATURATED;
    }
    return URRT_CAN_PACK_OK;
}

/* A float32 or float64 signal: its raw is a float, so it is scaled in
 * double precision and rounded to the raw type as the FPU rounds. */
static int float_to_raw(const urrt_can_signal *sig, double value, uint64_t *raw)
{
    bool single = sig->type == (uint8_t)URRT_CAN_FLOAT32;
    double limit = single ? (double)FLT_MAX : DBL_MAX;
    double scaled;
    int outcome;
    int raw_outcome = URRT_CAN_PACK_OK;
    if (value != value) {
        *raw = (sig->flags & URRT_CAN_SIG_INVALID_RAW) != 0u ? sig->invalid_raw
               : single                                    ? FLOAT32_QUIET_NAN
                                                           : FLOAT64_QUIET_NAN;
        return URRT_CAN_PACK_NAN;
    }
    outcome = clamp_to_limits(sig, &value); /* infinities end here too */
    scaled = (value - sig->offset) / sig->factor; /* may overflow to +-inf: defined */
    if (scaled > limit || scaled < -limit) {
        scaled = scaled > 0.0 ? limit : -limit;
        raw_outcome = URRT_CAN_PACK_SATURATED;
    }
    if (single) {
        float_bits b;
        b.f = (float)scaled;
        *raw = b.u;
    } else {
        *raw = bits_of(scaled);
    }
    return outcome > raw_outcome ? outcome : raw_outcome;
}

/*
 * The mask a double holds, by urrt_bitmask's rule (urrt.h): sign and
 * exponent bits all zero is a raw int64 read as a double, whose bits are
 * the mask; anything else must be a non-negative integer up to 2^53.
 * Written again here, on the bits in hand, because calling urrt_bitmask
 * made packing a mask 40 bytes deeper on a Cortex-M4 than scaling a number
 * (docs/footprint.md, "Stack"); tests/lib/test_can.c holds the two to the
 * same answers.
 */
static bool mask_of(uint64_t bits, uint64_t *mask)
{
    unsigned biased = (unsigned)(bits >> 52); /* with the sign: 0x800 and up is negative */
    uint64_t mantissa = (bits & FRACTION_BITS) | HIDDEN_BIT;
    if (biased == 0u || bits == SIGN_BIT) {
        *mask = biased == 0u ? bits : 0u; /* a raw int64, or -0 */
        return true;
    }
    if (biased < 1023u || biased > 1076u) {
        return false; /* a fraction below 1, negative, 2^54 or more, infinite or NaN */
    }
    if (biased == 1076u) {
        *mask = mantissa << 1; /* [2^53, 2^54): 2^53 alone is a mask */
        return mantissa == HIDDEN_BIT;
    }
    *mask = mantissa >> (1075u - biased);
    return (mantissa & low_mask(1075u - biased)) == 0u; /* no fraction */
}

/* A bit mask: the bits the signal carries, never clamped; a value that is
 * no mask goes as NaN does. */
static int mask_to_raw(const urrt_can_signal *sig, double value, uint64_t *raw)
{
    uint64_t mask;
    if (!mask_of(bits_of(value), &mask)) {
        *raw = (sig->flags & URRT_CAN_SIG_INVALID_RAW) != 0u ? sig->invalid_raw : 0u;
        return URRT_CAN_PACK_NAN;
    }
    *raw = (mask >> URRT_CAN_SIG_MASK_FIRST(sig->flags)) & low_mask(sig->length);
    return URRT_CAN_PACK_OK;
}

static bool is_float(const urrt_can_signal *sig)
{
    return sig->type == (uint8_t)URRT_CAN_FLOAT32 || sig->type == (uint8_t)URRT_CAN_FLOAT64;
}

static int prepared_to_raw(const urrt_can_signal *sig, const urrt_can_scale *scale, double value, uint64_t *raw)
{
    if ((sig->flags & URRT_CAN_SIG_BITMASK) != 0u) {
        return mask_to_raw(sig, value, raw);
    }
    return is_float(sig) ? float_to_raw(sig, value, raw) : scaled_to_raw(sig, scale, value, raw);
}

/* urrt_can_to_raw for a descriptor known to be valid: its scale prepared
 * here, for callers that kept none. */
static int to_raw(const urrt_can_signal *sig, double value, uint64_t *raw)
{
    urrt_can_scale scale;
    scale_of(sig->factor, &scale);
    return prepared_to_raw(sig, &scale, value, raw);
}

int urrt_can_to_raw(const urrt_can_signal *sig, double value, uint64_t *raw)
{
    urrt_can_scale scale;
    int rc;
    if (raw == NULL) {
        return URRT_E_ARG;
    }
    rc = urrt_can_scale_prepare(sig, &scale); /* checks the descriptor */
    return rc < 0 ? rc : prepared_to_raw(sig, &scale, value, raw);
}

int urrt_can_to_raw_scaled(const urrt_can_signal *sig, const urrt_can_scale *scale, double value, uint64_t *raw)
{
    return prepared_to_raw(sig, scale, value, raw);
}

double urrt_can_from_raw(const urrt_can_signal *sig, uint64_t raw)
{
    uint64_t mask;
    double r;
    if (sig == NULL || sig->length < 1u || sig->length > 64u) {
        double_bits nan;
        nan.u = FLOAT64_QUIET_NAN;
        return nan.d;
    }
    mask = low_mask(sig->length);
    raw &= mask;
    switch ((urrt_can_value_type)sig->type) {
    case URRT_CAN_FLOAT32: {
        float_bits b;
        b.u = (uint32_t)raw;
        r = (double)b.f;
        break;
    }
    case URRT_CAN_FLOAT64: {
        double_bits b;
        b.u = raw;
        r = b.d;
        break;
    }
    case URRT_CAN_SIGNED: {
        if (((raw >> (sig->length - 1u)) & 1u) != 0u) {
            /* -(magnitude): magnitude = two's complement of raw in length bits. */
            uint64_t magnitude = (~raw + 1u) & mask;
            r = -(double)magnitude;
        } else {
            r = (double)raw;
        }
        break;
    }
    default: r = (double)raw; break;
    }
    return r * sig->factor + sig->offset;
}

int urrt_can_pack(const urrt_can_signal *sig, double value, uint8_t *data, unsigned frame_len)
{
    uint64_t raw;
    int outcome;
    int rc = check_placement(sig, data, frame_len);
    if (rc < 0) {
        return rc;
    }
    outcome = to_raw(sig, value, &raw); /* the descriptor was checked above */
    (void)move_bits(sig, data, raw, true);
    return outcome;
}

int urrt_can_pack_checked(const urrt_can_signal *sig, double value, uint8_t data[URRT_CAN_MAX_LEN])
{
    uint64_t raw;
    int outcome = to_raw(sig, value, &raw);
    put_bits_in_frame(sig, data, raw);
    return outcome;
}

int urrt_can_pack_scaled(const urrt_can_signal *sig, const urrt_can_scale *scale, double value,
                         uint8_t data[URRT_CAN_MAX_LEN])
{
    uint64_t raw;
    int outcome = prepared_to_raw(sig, scale, value, &raw);
    put_bits_in_frame(sig, data, raw);
    return outcome;
}

void urrt_can_put_raw_checked(const urrt_can_signal *sig, uint64_t raw, uint8_t data[URRT_CAN_MAX_LEN])
{
    put_bits_in_frame(sig, data, raw);
}

int urrt_can_unpack(const urrt_can_signal *sig, const uint8_t *data, unsigned frame_len, double *value)
{
    uint64_t raw;
    int rc;
    if (value == NULL) {
        return URRT_E_ARG;
    }
    rc = urrt_can_get_raw(sig, data, frame_len, &raw);
    if (rc < 0) {
        return rc;
    }
    *value = urrt_can_from_raw(sig, raw);
    return 0;
}

int urrt_can_pack_frame(const urrt_can_signal *sigs, const double *values, size_t count, uint8_t *data,
                        unsigned frame_len, uint8_t *outcomes)
{
    size_t i;
    int worst = URRT_CAN_PACK_OK;
    if ((sigs == NULL || values == NULL) && count > 0) {
        return URRT_E_ARG;
    }
    for (i = 0; i < count; i++) {
        int outcome = urrt_can_pack(&sigs[i], values[i], data, frame_len);
        if (outcome < 0) {
            return outcome;
        }
        if (outcomes != NULL) {
            outcomes[i] = (uint8_t)outcome;
        }
        if (outcome > worst) {
            worst = outcome;
        }
    }
    return worst;
}
