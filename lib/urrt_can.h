/* SPDX-License-Identifier: MIT */
/*
 * urrt_can: table-driven packing of physical values into CAN and CAN FD
 * payloads, with the bit conventions of DBC files.
 *
 * This header is the API manual; docs/can.md is the user's reference for
 * the gateway's mapping configuration built on it.
 *
 * Like lib/urrt.c this module is C99 and freestanding: it includes only
 * <stddef.h>, <stdint.h>, <stdbool.h> and <float.h>, never allocates, keeps
 * no state and does no I/O, so a firmware gateway uses the same code as
 * urrt-gateway. Integer signals are scaled in integer arithmetic, exactly
 * (see "Values"); float32 and float64 signals, limits and unpacking use
 * double arithmetic, which on a core without a double-precision FPU the
 * compiler's runtime (libgcc's soft-float routines) provides: link with
 * -lgcc even under -nostdlib.
 *
 * ---- Bit numbering (the DBC convention) ------------------------------------
 *
 * Bit b of a payload is bit (b % 8) of byte (b / 8), bit 0 being the least
 * significant bit of a byte. So byte 0 holds bits 7..0, byte 1 bits 15..8,
 * and a 64-byte CAN FD payload has bits 0..511.
 *
 * Intel (little-endian, DBC "@1"): the start bit is the signal's LEAST
 * significant bit; the signal's bits occupy start, start+1, ... upwards,
 * so it continues into the next byte's bit 0. A 12-bit signal at start 12:
 *
 *     byte | bit 7   6   5   4   3   2   1   0
 *     -----+---------------------------------
 *       1  |    s3  s2  s1  s0   .   .   .   .     s0 = LSB at bit 12
 *       2  |   s11 s10  s9  s8  s7  s6  s5  s4     s11 = MSB at bit 23
 *
 * Motorola (big-endian, DBC "@0"): the start bit is the signal's MOST
 * significant bit; the signal's bits run downwards within a byte (bit 4,
 * 3, ... 0 of that byte) and continue at bit 7 of the NEXT byte (the DBC
 * "sawtooth"). A 12-bit signal at start 12:
 *
 *     byte | bit 7   6   5   4   3   2   1   0
 *     -----+---------------------------------
 *       1  |     .   .   . s11 s10  s9  s8  s7     s11 = MSB at bit 12
 *       2  |    s6  s5  s4  s3  s2  s1  s0   .     s0 = LSB at bit 17
 *
 * A Motorola signal that fills whole bytes starts at bit 7 of its first
 * byte: a 16-bit big-endian value in bytes 2-3 is start 23, length 16.
 *
 * ---- Values ---------------------------------------------------------------
 *
 * physical = raw * factor + offset. Integer signals hold raw in two's
 * complement (signed) or plain binary (unsigned) in `length` bits; float32
 * and float64 signals hold raw as an IEEE-754 binary32 / binary64 bit
 * pattern in 32 / 64 bits (factor and offset apply to them too).
 *
 * An integer signal's raw value is (value - offset) / factor rounded half
 * away from zero, computed exactly on the binary values of the three
 * doubles (not rounded once for the subtraction and again for the
 * division), in integer arithmetic: no division once the signal's scale is
 * prepared (urrt_can_scale_prepare), no floating-point operation at all.
 * Float signals are scaled in double precision, then rounded to the raw
 * type as the FPU rounds.
 *
 * Packing is total: every double, NaN and infinities included, gives a
 * defined payload, and no conversion is undefined behaviour (ranges are
 * checked before any double-to-float conversion; integer signals convert
 * nothing). The outcome says whether the value was sent as it is:
 *   URRT_CAN_PACK_OK         the value fit (after rounding half away from zero)
 *   URRT_CAN_PACK_SATURATED  it was out of [min, max] or of the raw type's
 *                            range (infinities included) and was clamped
 *   URRT_CAN_PACK_NAN        it was NaN (or, for a bit mask, no mask): the
 *                            signal carries invalid_raw if the descriptor
 *                            sets URRT_CAN_SIG_INVALID_RAW, else a quiet NaN
 *                            (float types), 0 (a bit mask) or the raw value
 *                            of physical 0 clamped into [min, max]
 * so that a caller can clear a validity bit on anything but OK.
 *
 * ---- Bit masks ----------------------------------------------------------------
 *
 * A signal with URRT_CAN_SIG_BITMASK carries a set of independent bits
 * (digital inputs and outputs, status bits), not a quantity: it is never
 * scaled and never saturated. Its value is a mask as UR sends one, by
 * urrt_bitmask's rule (urrt.h): a double holding the integer, or a raw int64
 * read as a double. The signal carries the mask's bits first .. first + length - 1
 * (URRT_CAN_SIG_MASK(first); first 0 by default): raw = (mask >> first)
 * in `length` bits. Bits it does not carry are left out, and the outcome
 * is URRT_CAN_PACK_OK for every mask, whatever bits are set.
 *
 * A value that is no mask (negative, fractional, NaN, infinite, or above
 * 2^53, where a double no longer holds every integer and the low bits may
 * have been rounded away) is URRT_CAN_PACK_NAN, never a guess: the signal
 * carries invalid_raw with URRT_CAN_SIG_INVALID_RAW, else 0 (no bit set),
 * and a caller clears the validity bit as for any NaN.
 *
 * A mask descriptor is unsigned, with factor 1 and offset 0; min and max
 * are not used (urrt_can_signal_range gives 0 .. 2^length - 1, what a DBC
 * states for it). Packing it is integer work on the double's bits only.
 */
#ifndef URRT_CAN_H
#define URRT_CAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Errors, negative and apart from urrt.h's URRT_E_* (-1..-10), which are
 * used where they fit (URRT_E_ARG for a null pointer). */
enum urrt_can_result {
    URRT_CAN_E_SIGNAL = -32,       /* descriptor out of its domain (length, type, factor, limits) */
    URRT_CAN_E_PAST_END = -33,     /* signal reaches past the frame's length */
    URRT_CAN_E_OVERLAP = -34,      /* two signals share a bit */
    URRT_CAN_E_FRAME_LENGTH = -35, /* length no classic (0-8) or FD frame has */
    URRT_CAN_E_ID = -36            /* 11-bit id above 0x7FF or 29-bit id above 0x1FFFFFFF */
};

/* Outcomes of packing (non-negative). */
#define URRT_CAN_PACK_OK 0
#define URRT_CAN_PACK_SATURATED 1
#define URRT_CAN_PACK_NAN 2

/* A short English text for an urrt_can_result or an urrt_result. */
const char *urrt_can_strerror(int result);

/* ---- frames ---------------------------------------------------------------- */

#define URRT_CAN_MAX_LEN 64u   /* CAN FD payload */
#define URRT_CAN_CLASSIC_MAX_LEN 8u
#define URRT_CAN_SFF_MAX 0x7FFu
#define URRT_CAN_EFF_MAX 0x1FFFFFFFu

/* Classic frames carry 0-8 bytes; FD frames 0-8, 12, 16, 20, 24, 32, 48 or 64. */
bool urrt_can_length_valid(unsigned len, bool fd);
/* DLC code of a valid length (0-15), and back; 0xFF / 0 for invalid input. */
uint8_t urrt_can_len_to_dlc(unsigned len);
unsigned urrt_can_dlc_to_len(uint8_t dlc);
/* Smallest valid FD length holding len bytes (64 for more than 64). */
unsigned urrt_can_fd_length_round_up(unsigned len);

bool urrt_can_id_valid(uint32_t id, bool extended);

/* A frame as the CAN core (urrt_cantx.h) produces it and a CAN link sends
 * it; port.h's SocketCAN link takes this type. */
typedef struct urrt_can_frame {
    uint32_t id;    /* 11-bit, or 29-bit when extended */
    bool extended;
    bool fd;        /* CAN FD: len 0-8, 12, 16, 20, 24, 32, 48 or 64 */
    uint8_t len;
    uint8_t data[URRT_CAN_MAX_LEN];
} urrt_can_frame;

/*
 * Worst-case length of a frame on the wire in bits, worst-case bit stuffing
 * included, with the 3-bit interframe space.
 *
 * Classic CAN (Davis, Burns, Bril, Lukkien, "Controller Area Network (CAN)
 * schedulability analysis: refuted, revisited and revised", 2007):
 *     bits = g + 8s + 13 + floor((g + 8s - 1) / 4),  g = 34 (11-bit id) or 54 (29-bit)
 * so 8 bytes take 135 (11-bit) or 160 (29-bit) bits and all of them are
 * *nominal_bits; *data_bits is 0.
 *
 * CAN FD (ISO 11898-1:2015): *nominal_bits counts SOF to BRS (17 bits for an
 * 11-bit id, 36 for a 29-bit id, plus floor((n - 1) / 4) stuff bits) and the
 * tail from the CRC delimiter (CRC delimiter, ACK slot and delimiter, EOF, IFS:
 * 13 bits), sent at the arbitration bit rate. *data_bits counts ESI, DLC and
 * data (5 + 8s, plus ceil((5 + 8s) / 4) stuff bits: rounded up, so that
 * the two phases together never count fewer stuff bits than the dynamically
 * stuffed run from SOF to the last data bit has at worst) and the stuff
 * count and CRC with their fixed stuff bits (4 + 17 + 6 up to
 * 16 bytes, 4 + 21 + 7 above), sent at the data bit rate (the arbitration
 * rate without bit rate switching). len is rounded up to a valid length.
 */
void urrt_can_frame_bits(unsigned len, bool extended, bool fd, unsigned *nominal_bits, unsigned *data_bits);

/* ---- signals --------------------------------------------------------------- */

typedef enum urrt_can_byte_order {
    URRT_CAN_INTEL = 0,    /* little-endian, DBC @1 */
    URRT_CAN_MOTOROLA = 1  /* big-endian, DBC @0 */
} urrt_can_byte_order;

typedef enum urrt_can_value_type {
    URRT_CAN_UNSIGNED = 0,
    URRT_CAN_SIGNED = 1,
    URRT_CAN_FLOAT32 = 2,  /* length must be 32 */
    URRT_CAN_FLOAT64 = 3   /* length must be 64 */
} urrt_can_value_type;

/* Flags of a signal descriptor. */
#define URRT_CAN_SIG_INVALID_RAW 0x01u /* send invalid_raw for NaN (and, for a bit mask, for no mask) */
#define URRT_CAN_SIG_BITMASK 0x02u     /* the value is a bit mask (see "Bit masks" above) */
/*
 * The flags of a bit mask signal that carries the mask's bits from `first`
 * (0..63) up: URRT_CAN_SIG_BITMASK, and `first` in the flags' upper six
 * bits. Kept in the flags so that the descriptor's layout stays as it was:
 * tables written for it, positional initializers included, still compile.
 * Without URRT_CAN_SIG_BITMASK those six bits are 0.
 */
#define URRT_CAN_SIG_MASK(first) (URRT_CAN_SIG_BITMASK | (unsigned)(first) << 2)
#define URRT_CAN_SIG_MASK_FIRST(flags) ((unsigned)(flags) >> 2)

/*
 * One signal: where it sits and how it is scaled. A frame is an array of
 * these (the "table"); the functions below take one descriptor, or the
 * array for layout checks and whole-frame packing.
 *
 * min and max are physical limits; packing clamps to them before scaling,
 * and again to the raw type's range after. Use urrt_can_signal_range() for
 * the widest limits a raw type can carry. A bit mask (URRT_CAN_SIG_BITMASK)
 * is never clamped: unsigned, factor 1, offset 0, first + length <= 64.
 */
typedef struct urrt_can_signal {
    double factor;        /* finite and non-zero (negative allowed) */
    double offset;        /* finite */
    double min;           /* finite, min <= max */
    double max;           /* finite */
    uint64_t invalid_raw; /* raw bits sent for NaN with URRT_CAN_SIG_INVALID_RAW; must fit length */
    uint16_t start;       /* DBC start bit: LSB (Intel) or MSB (Motorola), see above */
    uint8_t length;       /* bits, 1..64 */
    uint8_t byte_order;   /* urrt_can_byte_order */
    uint8_t type;         /* urrt_can_value_type */
    uint8_t flags;        /* URRT_CAN_SIG_*, URRT_CAN_SIG_MASK(first) for a bit mask */
} urrt_can_signal;

/*
 * The descriptor alone (length and type, factor, offset, limits, invalid
 * raw), then whether it fits a frame of frame_len bytes. Returns 0,
 * URRT_CAN_E_SIGNAL or URRT_CAN_E_PAST_END (or URRT_E_ARG).
 */
int urrt_can_signal_check(const urrt_can_signal *sig, unsigned frame_len);

/* Bits of the signal in DBC numbering: its least and most significant bit
 * (for Intel lsb = start, for Motorola msb = start), and the first bit past
 * it in payload order: the payload needs at least (end + 7) / 8 bytes.
 * URRT_CAN_E_SIGNAL for a length outside 1..64. */
int urrt_can_signal_span(const urrt_can_signal *sig, unsigned *lsb, unsigned *msb, unsigned *bytes_needed);

/* The physical range the raw type can carry: raw minimum and maximum scaled
 * (ordered for a negative factor; +-DBL_MAX where float64 scaling
 * overflows). Ignores sig->min and sig->max. */
int urrt_can_signal_range(const urrt_can_signal *sig, double *lo, double *hi);

/*
 * Overlap and fit of a frame's signals: 0 when every signal is valid, fits
 * frame_len bytes and no two share a bit. Otherwise the error of the first
 * problem found, with *first (and for URRT_CAN_E_OVERLAP *second, the
 * earlier signal it overlaps) set to the index of the offending signal.
 * Work is O(count^2 * length / 8), stack use one 64-byte mask.
 */
int urrt_can_layout_check(const urrt_can_signal *sigs, size_t count, unsigned frame_len, size_t *first,
                          size_t *second);

/*
 * Physical value to raw bits (the low `length` bits of *raw; signed raw in
 * two's complement). Returns URRT_CAN_PACK_OK, _SATURATED or _NAN, or a
 * negative error for an invalid descriptor.
 */
int urrt_can_to_raw(const urrt_can_signal *sig, double value, uint64_t *raw);

/*
 * A signal's scaling prepared once, for packing without a division: the
 * factor as an odd integer and a power of two, and that integer's
 * reciprocal. urrt_can_to_raw, urrt_can_pack and urrt_can_pack_checked
 * prepare it on every call; a caller that packs the same signals again and
 * again keeps one per signal (urrt_cantx_prepare does so for the CAN core).
 * Float signals do not use it.
 */
typedef struct urrt_can_scale {
    uint64_t divisor;      /* |factor| = divisor * 2^(half_exponent + 1), divisor odd */
    uint64_t reciprocal;   /* floor(2^(64 + divisor_bits) / divisor) - 2^64 (0 for divisor 1) */
    int16_t half_exponent;
    uint8_t divisor_bits;  /* the divisor's bit length, 1..53 */
    uint8_t negative;      /* the factor is negative */
} urrt_can_scale;

/* The scale of a valid descriptor: 0, URRT_CAN_E_SIGNAL or URRT_E_ARG. */
int urrt_can_scale_prepare(const urrt_can_signal *sig, urrt_can_scale *scale);

/* urrt_can_to_raw with the scale urrt_can_scale_prepare made of sig (it
 * checks nothing: passing a scale not made of this descriptor, or of an
 * invalid one, is undefined behaviour). */
int urrt_can_to_raw_scaled(const urrt_can_signal *sig, const urrt_can_scale *scale, double value, uint64_t *raw);

/* Raw bits (the low `length` bits are used) to the physical value. */
double urrt_can_from_raw(const urrt_can_signal *sig, uint64_t raw);

/* Put raw bits into / take them from a payload of frame_len bytes. Bits of
 * the payload outside the signal are left alone. */
int urrt_can_put_raw(const urrt_can_signal *sig, uint64_t raw, uint8_t *data, unsigned frame_len);
int urrt_can_get_raw(const urrt_can_signal *sig, const uint8_t *data, unsigned frame_len, uint64_t *raw);

/* urrt_can_to_raw then urrt_can_put_raw: the outcome or a negative error
 * (the payload is untouched on an error). */
int urrt_can_pack(const urrt_can_signal *sig, double value, uint8_t *data, unsigned frame_len);

/*
 * For a descriptor already checked against this payload's length
 * (urrt_can_signal_check, urrt_can_layout_check or urrt_cantx_init returned
 * 0): what urrt_can_pack and urrt_can_put_raw do, without checking it again,
 * into a whole frame buffer (URRT_CAN_MAX_LEN bytes, a urrt_can_frame's
 * data, whatever the frame's length), so that a signal can be written a
 * 64-bit word at a time; bits outside the signal keep their value.
 * Passing a descriptor that was not checked is undefined behaviour.
 */
int urrt_can_pack_checked(const urrt_can_signal *sig, double value, uint8_t data[URRT_CAN_MAX_LEN]);
void urrt_can_put_raw_checked(const urrt_can_signal *sig, uint64_t raw, uint8_t data[URRT_CAN_MAX_LEN]);
/* urrt_can_pack_checked with the signal's prepared scale: for an integer
 * signal, integer operations only. */
int urrt_can_pack_scaled(const urrt_can_signal *sig, const urrt_can_scale *scale, double value,
                         uint8_t data[URRT_CAN_MAX_LEN]);

/* urrt_can_get_raw then urrt_can_from_raw. */
int urrt_can_unpack(const urrt_can_signal *sig, const uint8_t *data, unsigned frame_len, double *value);

/*
 * A whole frame: values[i] packed by sigs[i]; outcomes[i] (if outcomes is
 * not NULL) receives each outcome. Returns the worst outcome (NAN above
 * SATURATED above OK), or a negative error at the first invalid signal.
 * The payload is not cleared first: bytes no signal covers keep their
 * contents.
 */
int urrt_can_pack_frame(const urrt_can_signal *sigs, const double *values, size_t count, uint8_t *data,
                        unsigned frame_len, uint8_t *outcomes);

#ifdef __cplusplus
}
#endif

#endif /* URRT_CAN_H */
