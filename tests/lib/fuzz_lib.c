/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness for lib/: asserts the invariants of docs/security.md on
 * any input. Built with clang -fsanitize=fuzzer,address,undefined, so an
 * out-of-bounds access or undefined behaviour aborts as well.
 *
 * Input: byte 0 chooses how the rest is cut into chunks; bytes 1.. are the
 * TCP stream. The stream is framed twice (in one call and in the chosen
 * chunks), every yielded packet is decoded and read back by random access,
 * and the stream itself is handed to the whole-packet functions.
 */
#include "urrt.h"
#include "state_slot.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REQUIRE(cond)                                                               \
    do {                                                                            \
        if (!(cond)) {                                                              \
            fprintf(stderr, "%s:%d: invariant violated: %s\n", __FILE__, __LINE__, #cond); \
            abort();                                                                \
        }                                                                           \
    } while (0)

static uint64_t bits_of(double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
}


static int is_error(int r)
{
    return r <= URRT_E_ARG && r >= URRT_E_UNKNOWN_FIELD;
}

/* Invariant 11 for one value: the name is the listed entry whose value the
 * double equals exactly, or UNKNOWN when no entry does (fractions, NaN and
 * infinities equal none). */
static void check_enum_name(urrt_enum_kind kind, double value)
{
    size_t count = 0;
    const urrt_enum_entry *e = urrt_enum_entries(kind, &count);
    const char *name = urrt_enum_name(kind, value);
    const char *listed = URRT_UNKNOWN_NAME;
    REQUIRE(name != NULL);
    for (size_t i = 0; i < count; i++) {
        if ((double)e[i].value == value) {
            listed = e[i].name;
        }
    }
    REQUIRE(strcmp(name, listed) == 0);
}

/* Invariant 11 for a digital I/O value: a mask exactly when the bits are
 * a raw int64 (sign and exponent clear) or a double holding a non-negative
 * integer up to 2^53, and then the right mask. */
static void check_bitmask(double value)
{
    uint64_t mask = 0;
    uint64_t bits = bits_of(value);
    int r = urrt_bitmask(value, &mask);
    if (bits >> 52 == 0) {
        REQUIRE(r == URRT_OK && mask == bits);
    } else if (value >= 0.0 && value <= 9007199254740992.0 && (double)(uint64_t)value == value) {
        REQUIRE(r == URRT_OK && mask == (uint64_t)value);
    } else {
        REQUIRE(r == URRT_E_NOT_BITMASK);
    }
}

/* Invariant 9: a failed decode leaves no field behind. */
static void check_cleared(const urrt_state *st)
{
    REQUIRE(st->present == 0);
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        const double *v = state_slot((urrt_state *)st, id);
        for (unsigned i = 0; i < urrt_field((urrt_field_id)id)->count; i++) {
            REQUIRE(v[i] != v[i]);
        }
    }
}

/* Invariants 6-8, 10 and 11 of docs/security.md on one packet: decode
 * succeeds, presence follows the length, random access agrees with the full
 * decode, names are total, the encoder gives the same fields back.
 * (Invariant 1, memory safety, is the sanitizers' job throughout.) */
static void check_packet(const uint8_t *pkt, size_t len)
{
    static urrt_state st, back;
    static uint8_t out[URRT_PACKET_MAX];
    unsigned doubles;
    urrt_generation gen;

    REQUIRE(urrt_packet_length(pkt, len) == (int)len);
    REQUIRE(urrt_decode(pkt, len, &st) == (int)len);
    doubles = (unsigned)(len - URRT_HEADER_SIZE) / 8u;
    gen = urrt_generation_of((uint32_t)len);
    REQUIRE(st.length == len && st.doubles == doubles && st.generation == gen);
    REQUIRE(st.extra_columns == (gen == URRT_GEN_3X && doubles > URRT_WIRE_COLUMNS ? doubles - URRT_WIRE_COLUMNS : 0));
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        unsigned col = urrt_field_column((urrt_field_id)id, gen);
        int whole = col != 0 && col + f->count - 1u <= doubles &&
                    !(gen == URRT_GEN_1X && id == URRT_F_TOOL_ACCELEROMETER && doubles < 95);
        double *v = state_slot(&st, id);
        REQUIRE((int)urrt_has(&st, id) == whole);
        for (unsigned i = 0; i < f->count; i++) {
            double d;
            int r = urrt_read(pkt, len, (urrt_field_id)id, i, &d);
            if (whole) {
                uint64_t raw;
                REQUIRE(r == URRT_OK && bits_of(d) == bits_of(v[i]));
                REQUIRE(urrt_read_column_bits(pkt, len, col + i, &raw) == URRT_OK && raw == bits_of(v[i]));
            } else {
                REQUIRE(r == URRT_E_ABSENT);
                REQUIRE(v[i] != v[i]); /* absent fields hold NaN */
            }
            check_enum_name(urrt_field_enum((urrt_field_id)id, gen), v[i]);
        }
    }
    check_bitmask(st.digital_input_bits[0]);
    check_bitmask(st.digital_outputs[0]);
    for (int k = URRT_ENUM_ROBOT_MODE; k <= URRT_ENUM_PROGRAM_STATE; k++) {
        check_enum_name((urrt_enum_kind)k, st.time[0]);
    }
    REQUIRE(urrt_encode(&st, (uint32_t)len, out, sizeof out) == (int)len);
    REQUIRE(urrt_decode(out, len, &back) == (int)len && back.present == st.present);
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        if (urrt_has(&st, id)) {
            REQUIRE(memcmp(state_slot(&st, id), state_slot(&back, id), 8u * urrt_field((urrt_field_id)id)->count) == 0);
        }
    }
}

typedef struct run {
    uint8_t *out;      /* yielded packets, concatenated */
    size_t out_len;
    size_t packets;
    urrt_framer_stats stats;
    size_t pending;
} run;

static urrt_framer framer;

/* Feeds one chunk, checking invariants 2 (progress) and 4 (byte
 * accounting) on every call. */
static void feed(const uint8_t *p, size_t n, run *r, size_t *fed)
{
    do {
        size_t used = (size_t)-1;
        int res = urrt_framer_feed(&framer, p, n, &used);
        REQUIRE(res == 0 || res == 1);
        REQUIRE(used <= n);
        REQUIRE(used > 0 || n == 0);                     /* progress */
        REQUIRE(res == 1 || used == n);
        *fed += used;
        if (res == 1) {
            size_t len = 0;
            const uint8_t *pkt = urrt_framer_packet(&framer, &len);
            REQUIRE(pkt != NULL && len >= URRT_PACKET_MIN && len <= URRT_PACKET_MAX);
            REQUIRE((len - URRT_HEADER_SIZE) % 8 == 0);
            /* Invariant 6: the size is the packet's own header. */
            REQUIRE(((uint32_t)pkt[0] << 24 | (uint32_t)pkt[1] << 16 | (uint32_t)pkt[2] << 8 | pkt[3]) == len);
            memcpy(r->out + r->out_len, pkt, len);
            r->out_len += len;
            r->packets++;
        } else {
            REQUIRE(urrt_framer_packet(&framer, NULL) == NULL);
        }
        /* Bytes accounting. */
        REQUIRE(framer.stats.bytes == *fed);
        REQUIRE(r->out_len + framer.stats.skipped + framer.have == *fed);
        REQUIRE(framer.stats.packets == r->packets);
        REQUIRE(framer.have < URRT_PACKET_MAX);
        p += used;
        n -= used;
    } while (n > 0);
}

static void frame(const uint8_t *stream, size_t n, uint8_t selector, run *r)
{
    size_t at = 0, fed = 0;
    uint32_t rng = 0x9E3779B9u ^ selector;
    memset(r, 0, sizeof *r);
    r->out = malloc(n + 1);
    urrt_framer_init(&framer);
    if (selector == 0) {
        feed(stream, n, r, &fed);
    } else {
        /* Chunk sizes from the selector: small fixed sizes, a size near a
         * header or packet boundary, or pseudo-random, with zero-length
         * feeds mixed in. */
        while (at < n) {
            size_t chunk;
            rng = rng * 1664525u + 1013904223u;
            switch (selector & 3) {
            case 0: chunk = (size_t)(selector >> 2) + 1; break;
            case 1: chunk = (rng >> 16) % 9; break;
            case 2: chunk = (rng >> 16) % 1300; break;
            default: chunk = ((rng >> 16) & 1) ? 3 : 1117; break;
            }
            if (chunk > n - at) {
                chunk = n - at;
            }
            feed(stream + at, chunk, r, &fed);
            at += chunk;
        }
    }
    r->stats = framer.stats;
    r->pending = urrt_framer_finish(&framer);
    REQUIRE(r->out_len + r->stats.skipped + r->pending == n);
    REQUIRE(urrt_framer_packet(&framer, NULL) == NULL);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    run whole, chunked;
    const uint8_t *stream;
    size_t n;
    urrt_state st;

    if (size < 1) {
        return 0;
    }
    stream = data + 1;
    n = size - 1;

    /* Whole-packet functions on the raw bytes. */
    {
        int r = urrt_decode(stream, n, &st);
        if (r >= 0) {
            check_packet(stream, (size_t)r);
        } else {
            REQUIRE(is_error(r)); /* invariant 9 */
            check_cleared(&st);
        }
        for (unsigned c = 0; c < 4; c++) {
            double d;
            unsigned column = (unsigned)data[0] + c * 64u;
            r = urrt_read_column(stream, n, column, &d);
            REQUIRE(r == URRT_OK || is_error(r));
        }
        r = urrt_field_find((const char *)stream, n < 40 ? n : 40);
        REQUIRE(r == URRT_E_UNKNOWN_FIELD ||
                (r >= 0 && r < URRT_FIELD_COUNT && strlen(urrt_field((urrt_field_id)r)->name) == (n < 40 ? n : 40) &&
                 memcmp(urrt_field((urrt_field_id)r)->name, stream, n < 40 ? n : 40) == 0));
    }

    /* Invariant 5: framing once in one call, once in chunks; same packets,
     * same counts. */
    frame(stream, n, 0, &whole);
    frame(stream, n, data[0], &chunked);
    REQUIRE(whole.packets == chunked.packets && whole.out_len == chunked.out_len);
    REQUIRE(memcmp(whole.out, chunked.out, whole.out_len) == 0);
    REQUIRE(whole.stats.skipped == chunked.stats.skipped && whole.stats.resyncs == chunked.stats.resyncs);
    REQUIRE(whole.pending == chunked.pending);
    for (size_t at = 0; at < whole.out_len;) {
        int len = urrt_packet_length(whole.out + at, whole.out_len - at);
        REQUIRE(len >= (int)URRT_PACKET_MIN);
        check_packet(whole.out + at, (size_t)len);
        at += (size_t)len;
    }
    free(whole.out);
    free(chunked.out);
    return 0;
}
