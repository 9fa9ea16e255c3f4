/* SPDX-License-Identifier: MIT */
/*
 * lib/ executed on the target: the reference's vectors decoded bit-exact
 * from every misalignment (decode and random access), the encoder round
 * trip, the framer on streams of every length with garbage fed in every
 * chunk size from 1 to 1460 bytes, and on Cortex-M the stack high-water
 * mark of every public lib/ function. No C library: text goes out through
 * target.h, the exit status is the result.
 */
#include "target.h"
#include "test_vectors.h"
#include "urrt.h"
#include "../lib/state_slot.h"
#include "../testutil.h"
#include "urrt_can.h"
#include "urrt_cantx.h"

/* ---- a harness without libc ----------------------------------------------- */

static unsigned passed, failed;

static void put_hex(uint64_t v)
{
    char text[19];
    int i;
    text[0] = '0';
    text[1] = 'x';
    for (i = 0; i < 16; i++) {
        text[2 + i] = "0123456789abcdef"[(v >> (60 - 4 * i)) & 15u];
    }
    text[18] = '\0';
    target_puts(text);
}

/* A failure names the check, the vector and up to two numbers. */
static void check(int ok, int line, const char *what, const char *name, uint64_t a, uint64_t b)
{
    if (ok) {
        passed++;
        return;
    }
    failed++;
    if (failed > 20) {
        return;
    }
    target_puts("FAIL: test_target.c:");
    target_put_uint((uint64_t)line);
    target_puts(": ");
    target_puts(what);
    target_puts(" [");
    target_puts(name);
    target_puts("] ");
    put_hex(a);
    target_puts(" ");
    put_hex(b);
    target_puts("\n");
}
#define CHECK(ok, what, name, a, b) check((ok) != 0, __LINE__, (what), (name), (uint64_t)(a), (uint64_t)(b))

static int same_text(const char *a, const char *b)
{
    if (a == NULL || b == NULL) {
        return a == b;
    }
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return *a == *b;
}

static int same_bytes(const uint8_t *a, const uint8_t *b, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        if (a[i] != b[i]) {
            return 0;
        }
    }
    return 1;
}

static void copy(uint8_t *dst, const uint8_t *src, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        dst[i] = src[i];
    }
}

static uint64_t bits_of(double d)
{
    union {
        double d;
        uint64_t u;
    } b;
    b.d = d;
    return b.u;
}


/* Large objects are static: the Cortex-M0 board has 16 KiB of RAM. */
static urrt_state st;
static uint64_t scratch_words[(URRT_PACKET_MAX + 16) / 8 + 1];
#define scratch ((uint8_t *)scratch_words)

/* ---- decoding, random access, encoding -------------------------------------- */

static void check_fields(const tv_vector *v, const uint8_t *pkt, const urrt_state *s)
{
    unsigned k, i;
    for (k = 0; k < v->expect_count; k++) {
        const tv_expect *e = &v->expect[k];
        const double *val = state_slot((urrt_state *)(uintptr_t)s, e->id);
        const urrt_field_info *f = urrt_field((urrt_field_id)e->id);
        double d = 0;
        uint64_t raw = 0;
        int r;
        switch (e->kind) {
        case TV_VALUE:
            CHECK(urrt_has(s, e->id), f->name, v->name, e->elem, 0);
            CHECK(bits_of(val[e->elem]) == e->bits, f->name, v->name, bits_of(val[e->elem]), e->bits);
            r = urrt_read(pkt, v->length, (urrt_field_id)e->id, e->elem, &d);
            CHECK(r == URRT_OK && bits_of(d) == e->bits, "urrt_read", v->name, (uint32_t)r, bits_of(d));
            r = urrt_read_column_bits(pkt, v->length,
                                      urrt_field_column((urrt_field_id)e->id, (urrt_generation)v->generation) +
                                          e->elem,
                                      &raw);
            CHECK(r == URRT_OK && raw == e->bits, "urrt_read_column_bits", v->name, (uint32_t)r, raw);
            break;
        case TV_ABSENT:
            CHECK(!urrt_has(s, e->id), f->name, v->name, 1, 0);
            for (i = 0; i < f->count; i++) {
                CHECK((bits_of(val[i]) & 0x7FF8000000000000ull) == 0x7FF8000000000000ull, "absent is NaN",
                      v->name, i, bits_of(val[i]));
            }
            CHECK(urrt_read(pkt, v->length, (urrt_field_id)e->id, 0, &d) == URRT_E_ABSENT, "read absent", v->name,
                  e->id, 0);
            break;
        case TV_ENUM:
            CHECK(same_text(urrt_enum_name(urrt_field_enum((urrt_field_id)e->id, (urrt_generation)v->generation),
                                           val[e->elem]),
                            e->name),
                  "enum name", v->name, e->id, e->elem);
            break;
        case TV_MASK:
            CHECK(urrt_bitmask(val[0], &raw) == URRT_OK && raw == e->bits, "bit mask", v->name, raw, e->bits);
            break;
        default:
            CHECK(urrt_bitmask(val[0], &raw) == URRT_E_NOT_BITMASK, "not a bit mask", v->name, e->id, 0);
            break;
        }
    }
}

static void test_vector(const tv_vector *v)
{
    unsigned m, k;
    const char *versions = urrt_versions_of(v->length);
    CHECK(same_text(versions, same_text(v->versions, "-") ? NULL : v->versions), "versions", v->name, 0, 0);
    CHECK((int)urrt_generation_of(v->length) == v->generation, "generation_of", v->name, v->generation, 0);
    /* Every misalignment of the packet (an unaligned LDRD faults on
     * Cortex-M, so each must take a path that is right for it). */
    for (m = 0; m < 8; m++) {
        uint8_t *pkt = scratch + m;
        int r;
        copy(pkt, v->packet, v->length);
        r = urrt_decode(pkt, v->length, &st);
        CHECK(r == (int)v->length, "decode", v->name, (uint32_t)r, m);
        if (r != (int)v->length) {
            continue;
        }
        CHECK(st.length == v->length && st.doubles == v->doubles && (int)st.generation == v->generation &&
                  st.extra_columns == v->extra,
              "decoded length, doubles, generation, extra columns", v->name, st.doubles, st.extra_columns);
        check_fields(v, pkt, &st);
        CHECK(urrt_decode(pkt, v->length - 1u, &st) == URRT_E_TRUNCATED && st.present == 0, "truncated", v->name,
              m, 0);
    }
    /* Encoder round trip into every misalignment: the bytes of each present
     * field are the reference's, and decoding them gives the same values. */
    for (m = 0; m < 8; m++) {
        uint8_t *out = scratch + m;
        int r;
        urrt_decode(v->packet, v->length, &st);
        r = urrt_encode(&st, v->length, out, v->length);
        CHECK(r == (int)v->length && same_bytes(out, v->packet, 4), "encode", v->name, (uint32_t)r, m);
        for (k = 0; k < v->expect_count; k++) {
            const tv_expect *e = &v->expect[k];
            unsigned col = urrt_field_column((urrt_field_id)e->id, (urrt_generation)v->generation) + e->elem;
            if (e->kind == TV_VALUE) {
                CHECK(same_bytes(out + 4 + 8 * (col - 1), v->packet + 4 + 8 * (col - 1), 8), "encoded bytes",
                      v->name, e->id, e->elem);
            }
        }
        r = urrt_decode(out, v->length, &st);
        CHECK(r == (int)v->length, "decode(encode)", v->name, (uint32_t)r, m);
        check_fields(v, v->packet, &st);
    }
}

/* ---- the framer -------------------------------------------------------------------- */

static urrt_framer framer;
#define STREAM_PACKETS 3
static uint8_t stream[STREAM_PACKETS * URRT_PACKET_MAX + 2 * 64];

/* Three packets of one length with garbage between them; garbage bytes are
 * never 0, so no header can start in it (every such size is past
 * URRT_PACKET_MAX), and a packet after garbage is accepted because its size
 * equals the last one. */
static size_t make_stream(uint32_t length, size_t *at, size_t *garbage)
{
    size_t n = 0;
    unsigned p;
    *garbage = 0;
    for (p = 0; p < STREAM_PACKETS; p++) {
        size_t i;
        if (p > 0) {
            size_t g = 1u + (uint32_t)test_rng() % 64u;
            for (i = 0; i < g; i++) {
                stream[n++] = (uint8_t)(1u + (uint32_t)test_rng() % 255u);
            }
            *garbage += g;
        }
        at[p] = n;
        stream[n++] = (uint8_t)(length >> 24);
        stream[n++] = (uint8_t)(length >> 16);
        stream[n++] = (uint8_t)(length >> 8);
        stream[n++] = (uint8_t)length;
        for (i = 4; i < length; i++) {
            stream[n++] = (uint8_t)test_rng();
        }
    }
    return n;
}

static void test_framer(void)
{
    static const char name[] = "framer";
    size_t chunk;
    for (chunk = 1; chunk <= 1460; chunk++) {
        uint32_t length = URRT_HEADER_SIZE + 8u * (uint32_t)(1u + (chunk - 1u) % URRT_MAX_DOUBLES);
        size_t at[STREAM_PACKETS], garbage, n, pos = 0, yielded = 0;
        n = make_stream(length, at, &garbage);
        urrt_framer_init(&framer);
        for (pos = 0; pos < n; pos += chunk) {
            const uint8_t *p = stream + pos;
            size_t len = n - pos < chunk ? n - pos : chunk;
            do {
                size_t used = 0, plen = 0;
                int r = urrt_framer_feed(&framer, p, len, &used);
                const uint8_t *pkt = urrt_framer_packet(&framer, &plen);
                CHECK((r == 0 || r == 1) && used <= len && (used > 0 || r == 1), "feed", name, (uint32_t)r, chunk);
                if (r < 0 || used > len) {
                    return;
                }
                if (r == 1) {
                    CHECK(yielded < STREAM_PACKETS && plen == length &&
                              same_bytes(pkt, stream + at[yielded < STREAM_PACKETS ? yielded : 0], length),
                          "yielded packet", name, chunk, yielded);
                    yielded++;
                } else {
                    CHECK(pkt == NULL && used == len, "feed returned 0", name, chunk, used);
                }
                p += used;
                len -= used;
            } while (len > 0);
        }
        CHECK(yielded == STREAM_PACKETS, "packets yielded", name, chunk, yielded);
        CHECK(framer.stats.skipped == garbage && framer.stats.resyncs == STREAM_PACKETS - 1u &&
                  framer.stats.packets == STREAM_PACKETS && framer.stats.bytes == n,
              "framer statistics", name, chunk, framer.stats.skipped);
        CHECK(urrt_framer_finish(&framer) == 0, "stream ends on a packet boundary", name, chunk, 0);
    }
}

/* ---- stack ------------------------------------------------------------------------- */

#ifdef URRT_TARGET_CORTEX_M
#include "stack_target.h"
#endif

int main(void)
{
    unsigned i;
    for (i = 0; i < tv_vector_count; i++) {
        test_vector(&tv_vectors[i]);
    }
    target_puts("target: ");
    target_put_uint(tv_vector_count);
    target_puts(" reference vectors, decode, random access and encode at 8 misalignments\n");
    test_framer();
    target_puts("target: framer, streams of lengths 12.." );
    target_put_uint(URRT_PACKET_MAX);
    target_puts(" with garbage, chunk sizes 1..1460\n");
#ifdef URRT_TARGET_CORTEX_M
    test_stack();
#endif
    target_put_uint(passed);
    target_puts(" passed, ");
    target_put_uint(failed);
    target_puts(" failed\n");
    return failed == 0 && passed > 0 ? 0 : 1;
}
