/* SPDX-License-Identifier: MIT */
/*
 * check-can-scale's C side: packs the values of the case file that
 * tests/lib/can_scale_ref.py writes, for that script to hold against exact
 * rational arithmetic.
 *
 * The case file is little-endian 64-bit words: for each signal kind
 * CASE_HEADER_WORDS words (type | length << 8 | flags << 16, then the bits
 * of factor, offset, min and max, invalid_raw, the number of values), then
 * the bits of its values. Each value goes through urrt_can_to_raw_scaled
 * (the scale prepared once per kind), urrt_can_to_raw (prepared at each
 * call) and urrt_can_pack_scaled into a frame read back with
 * urrt_can_get_raw; the three must agree.
 *
 * On the host (can_scale_driver CASES OUT) OUT receives two words per
 * value: the raw value and the outcome, the outcome with bit 8 set when the
 * three paths disagree. Without a C library (Cortex-M, the case file named
 * by semihosting) it prints, per kind, "kind K digest D": FNV-1a over the
 * same two words of every value, which the script computes from its
 * reference.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt_can.h"

#define CASE_HEADER_WORDS 7u
#define DISAGREE 0x100u
#define FNV_OFFSET UINT64_C(0xCBF29CE484222325)
#define FNV_PRIME UINT64_C(0x100000001B3)

#ifdef URRT_TARGET_CORTEX_M
#include "target.h"
typedef int source;
static size_t source_read(source src, uint8_t *buf, size_t n)
{
    return target_read(src, buf, n);
}
#else
#include <stdio.h>
typedef FILE *source;
static size_t source_read(source src, uint8_t *buf, size_t n)
{
    return fread(buf, 1, n, src);
}
#endif

/* The case file, a word at a time. */
static struct {
    source src;
    uint8_t buf[4096];
    size_t len;
    size_t pos;
} in;

static bool next_word(uint64_t *w)
{
    unsigned i;
    *w = 0;
    for (i = 0; i < 8u; i++) {
        if (in.pos == in.len) {
            in.len = source_read(in.src, in.buf, sizeof in.buf);
            in.pos = 0;
            if (in.len == 0) {
                return false;
            }
        }
        *w |= (uint64_t)in.buf[in.pos++] << (8u * i);
    }
    return true;
}

static double double_of(uint64_t bits)
{
    union {
        uint64_t u;
        double d;
    } b;
    b.u = bits;
    return b.d;
}

/* A kind's descriptor from its header (after the first word, `shape`):
 * the signal at bit 0 of the frame, Intel order. */
static bool read_signal(uint64_t shape, urrt_can_signal *sig, uint64_t *count)
{
    uint64_t w[CASE_HEADER_WORDS - 1u];
    unsigned i;
    for (i = 0; i < CASE_HEADER_WORDS - 1u; i++) {
        if (!next_word(&w[i])) {
            return false;
        }
    }
    sig->type = (uint8_t)shape;
    sig->length = (uint8_t)(shape >> 8);
    sig->flags = (uint8_t)(shape >> 16);
    sig->factor = double_of(w[0]);
    sig->offset = double_of(w[1]);
    sig->min = double_of(w[2]);
    sig->max = double_of(w[3]);
    sig->invalid_raw = w[4];
    sig->start = 0;
    sig->byte_order = URRT_CAN_INTEL;
    *count = w[5];
    return true;
}

/* The raw value and outcome of one value by the three paths. */
static uint64_t pack_one(const urrt_can_signal *sig, const urrt_can_scale *scale, double value, uint64_t *raw)
{
    uint8_t frame[URRT_CAN_MAX_LEN];
    uint64_t mask = sig->length >= 64u ? ~UINT64_C(0) : (UINT64_C(1) << sig->length) - 1u;
    uint64_t unprepared = 0;
    uint64_t in_frame = 0;
    unsigned i;
    int outcome = urrt_can_to_raw_scaled(sig, scale, value, raw);
    bool agree = urrt_can_to_raw(sig, value, &unprepared) == outcome && unprepared == *raw;
    for (i = 0; i < URRT_CAN_MAX_LEN; i++) {
        frame[i] = 0xA5;
    }
    agree = agree && urrt_can_pack_scaled(sig, scale, value, frame) == outcome;
    agree = agree && urrt_can_get_raw(sig, frame, URRT_CAN_MAX_LEN, &in_frame) == 0 && in_frame == (*raw & mask);
    return (uint64_t)outcome | (agree ? 0u : DISAGREE);
}

#ifdef URRT_TARGET_CORTEX_M
/* FNV-1a a word at a time (not byte by byte): cheap, and enough to tell. */
static uint64_t fnv_word(uint64_t hash, uint64_t w)
{
    return (hash ^ w) * FNV_PRIME;
}

static void put_hex(uint64_t v)
{
    char text[17];
    int i;
    for (i = 15; i >= 0; i--, v >>= 4) {
        text[i] = "0123456789abcdef"[v & 0xFu];
    }
    text[16] = '\0';
    target_puts(text);
}

int main(void)
{
    uint64_t shape;
    uint64_t kind = 0;
    in.src = target_open_cmdline_file();
    if (in.src < 0) {
        target_puts("can_scale_driver: cannot open the case file named on the semihosting command line\n");
        return 1;
    }
    while (next_word(&shape)) {
        urrt_can_signal sig;
        urrt_can_scale scale;
        uint64_t count;
        uint64_t hash = FNV_OFFSET;
        uint64_t bits;
        if (!read_signal(shape, &sig, &count) || urrt_can_scale_prepare(&sig, &scale) != 0) {
            target_puts("can_scale_driver: a truncated case file or an invalid signal: write it again\n");
            return 1;
        }
        while (count-- > 0 && next_word(&bits)) {
            uint64_t raw;
            uint64_t outcome = pack_one(&sig, &scale, double_of(bits), &raw);
            hash = fnv_word(fnv_word(hash, raw), outcome);
        }
        target_puts("kind ");
        target_put_uint(kind++);
        target_puts(" digest ");
        put_hex(hash);
        target_puts("\n");
    }
    return 0;
}
#else
static bool put_word(FILE *out, uint64_t w)
{
    uint8_t b[8];
    unsigned i;
    for (i = 0; i < 8u; i++) {
        b[i] = (uint8_t)(w >> (8u * i));
    }
    return fwrite(b, 1, 8, out) == 8;
}

static int pack_cases(FILE *out)
{
    uint64_t shape;
    while (next_word(&shape)) {
        urrt_can_signal sig;
        urrt_can_scale scale;
        uint64_t count;
        uint64_t bits;
        if (!read_signal(shape, &sig, &count) || urrt_can_scale_prepare(&sig, &scale) != 0) {
            fprintf(stderr, "can_scale_driver: a truncated case file or an invalid signal: write it again\n");
            return 1;
        }
        while (count-- > 0 && next_word(&bits)) {
            uint64_t raw;
            uint64_t outcome = pack_one(&sig, &scale, double_of(bits), &raw);
            if (!put_word(out, raw) || !put_word(out, outcome)) {
                fprintf(stderr, "can_scale_driver: cannot write the results: is the disk full?\n");
                return 1;
            }
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    FILE *out;
    int rc;
    if (argc != 3) {
        fprintf(stderr, "usage: can_scale_driver CASES OUT (tests/lib/can_scale_ref.py runs it)\n");
        return 2;
    }
    in.src = fopen(argv[1], "rb");
    out = fopen(argv[2], "wb");
    if (in.src == NULL || out == NULL) {
        fprintf(stderr, "can_scale_driver: cannot open %s or %s: check the paths\n", argv[1], argv[2]);
        return 1;
    }
    rc = pack_cases(out);
    if (fclose(out) != 0) {
        fprintf(stderr, "can_scale_driver: cannot write %s: is the disk full?\n", argv[2]);
        rc = 1;
    }
    fclose(in.src);
    return rc;
}
#endif
