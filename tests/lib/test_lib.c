/* SPDX-License-Identifier: MIT */
/*
 * Black-box tests of lib/: decode, random access, encoder, enums, bit masks,
 * field lookup and the stream framer.
 *
 * Expected values come from tests/ref/urrt_ref.py (an independent reference
 * written from UR's table), read from the vector file given as argv[1], and
 * from tables typed here from docs/sources.md. Packets for the framer tests
 * are the reference's packets, so nothing here is produced by the code under
 * test and then checked against itself.
 */
#include "urrt.h"
#include "state_slot.h"
#include "check.h"
#include "testutil.h"

#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- helpers ------------------------------------------------------------ */

static uint64_t bits_of(double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
}

static double double_of(uint64_t u)
{
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/* ---- reference vectors ---------------------------------------------------- */

typedef struct vector {
    char name[64];
    uint32_t length;
    int generation;
    unsigned doubles;
    unsigned extra;
    char versions[96];
    uint8_t *packet;
} vector;

typedef struct expected_field {
    int seen;
    int absent;
    int elements;
    uint64_t bits[URRT_FIELD_COUNT_MAX];
    char enum_name[URRT_FIELD_COUNT_MAX][64];
    int has_enum[URRT_FIELD_COUNT_MAX];
    int has_mask;
    int mask_ok;
    uint64_t mask;
} expected_field;

#define MAX_VECTORS 512
static vector vectors[MAX_VECTORS];
static size_t vector_count;

static const vector *find_vector(const char *name)
{
    for (size_t i = 0; i < vector_count; i++) {
        if (strcmp(vectors[i].name, name) == 0) {
            return &vectors[i];
        }
    }
    fprintf(stderr, "test_lib: no reference vector %s\n", name);
    exit(2);
}

/* What the decoded state says of the packet as a whole. */
static void check_vector_header(const vector *v, const urrt_state *st)
{
    CHECK(st->length == v->length, "%s: length %u", v->name, st->length);
    CHECK(st->doubles == v->doubles, "%s: doubles %u", v->name, st->doubles);
    CHECK((int)st->generation == v->generation, "%s: generation %d", v->name, (int)st->generation);
    CHECK((int)urrt_generation_of(v->length) == v->generation, "%s: generation_of", v->name);
    CHECK(st->extra_columns == v->extra, "%s: extra columns %u, expected %u", v->name, st->extra_columns, v->extra);
    {
        const char *vs = urrt_versions_of(v->length);
        if (strcmp(v->versions, "-") == 0) {
            CHECK(vs == NULL, "%s: versions \"%s\" for an unknown length", v->name, vs);
        } else {
            CHECK(vs != NULL && strcmp(vs, v->versions) == 0, "%s: versions \"%s\", expected \"%s\"", v->name,
                  vs ? vs : "(null)", v->versions);
        }
    }
}

/* A field the reference says is absent: NaN in the state, URRT_E_ABSENT to urrt_read. */
static void check_absent_field(const vector *v, urrt_state *st, int id)
{
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    double *val = state_slot(st, id);
    double d;
    CHECK(!urrt_has(st, id), "%s: %s present, reference says absent", v->name, f->name);
    for (unsigned i = 0; i < f->count; i++) {
        CHECK(isnan(val[i]), "%s: absent %s[%u] is not NaN", v->name, f->name, i);
    }
    CHECK_EQ_INT(urrt_read(v->packet, v->length, (urrt_field_id)id, 0, &d), URRT_E_ABSENT);
}

/* A present field's elements, bit for bit, by every way of reading them. */
static void check_field_elements(const vector *v, const expected_field *e, urrt_state *st, int id)
{
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    urrt_generation gen = (urrt_generation)v->generation;
    double *val = state_slot(st, id);
    int r;
    for (unsigned i = 0; i < f->count && (int)i < e[id].elements; i++) {
        double d = 0;
        uint64_t raw = 0;
        unsigned column = urrt_field_column((urrt_field_id)id, gen) + i;
        CHECK(bits_of(val[i]) == e[id].bits[i], "%s: decode %s[%u] = %016" PRIx64 ", expected %016" PRIx64,
              v->name, f->name, i, bits_of(val[i]), e[id].bits[i]);
        r = urrt_read(v->packet, v->length, (urrt_field_id)id, i, &d);
        CHECK(r == URRT_OK && bits_of(d) == e[id].bits[i], "%s: read %s[%u] = %d, %016" PRIx64, v->name,
              f->name, i, r, bits_of(d));
        r = urrt_read_column(v->packet, v->length, column, &d);
        CHECK(r == URRT_OK && bits_of(d) == e[id].bits[i], "%s: read_column %u (%s[%u]) = %d, %016" PRIx64,
              v->name, column, f->name, i, r, bits_of(d));
        r = urrt_read_column_bits(v->packet, v->length, column, &raw);
        CHECK(r == URRT_OK && raw == e[id].bits[i], "%s: read_column_bits %u", v->name, column);
        if (e[id].has_enum[i]) {
            const char *name = urrt_enum_name(urrt_field_enum((urrt_field_id)id, gen), val[i]);
            CHECK(strcmp(name, e[id].enum_name[i]) == 0, "%s: %s[%u] = %g is %s, expected %s", v->name,
                  f->name, i, val[i], name, e[id].enum_name[i]);
        }
    }
}

/* The bit mask of a field the reference reads as one (or says is none). */
static void check_field_mask(const vector *v, const expected_field *e, urrt_state *st, int id)
{
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    double *val = state_slot(st, id);
    uint64_t mask = 0;
    int r = urrt_bitmask(val[0], &mask);
    if (e[id].mask_ok) {
        CHECK(r == URRT_OK && mask == e[id].mask, "%s: %s mask %d %" PRIx64 ", expected %" PRIx64, v->name,
              f->name, r, mask, e[id].mask);
    } else {
        CHECK(r == URRT_E_NOT_BITMASK, "%s: %s (%016" PRIx64 ") gave %d, expected NOT_BITMASK", v->name,
              f->name, bits_of(val[0]), r);
    }
}

/* Every field against the reference, present or absent. */
static void check_vector_fields(const vector *v, const expected_field *e, urrt_state *st)
{
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        CHECK(e[id].seen, "%s: the reference does not know field %s", v->name, f->name);
        if (!e[id].seen) {
            continue;
        }
        if (e[id].absent) {
            check_absent_field(v, st, id);
            continue;
        }
        CHECK(urrt_has(st, id), "%s: %s absent, reference says present", v->name, f->name);
        CHECK(e[id].elements == f->count, "%s: %s has %d elements in the reference, %u in lib", v->name, f->name,
              e[id].elements, f->count);
        check_field_elements(v, e, st, id);
        if (e[id].has_mask) {
            check_field_mask(v, e, st, id);
        }
    }
}

/* Columns past the known layout are readable, one past the end is not. */
static void check_vector_extra_columns(const vector *v)
{
    for (unsigned c = URRT_WIRE_COLUMNS + 1; c <= v->doubles; c++) {
        uint64_t raw = 0;
        CHECK(urrt_read_column_bits(v->packet, v->length, c, &raw) == URRT_OK &&
                  raw == get_be64(v->packet + 4 + 8 * (c - 1)),
              "%s: extra column %u", v->name, c);
    }
    {
        double d;
        CHECK_EQ_INT(urrt_read_column(v->packet, v->length, v->doubles + 1, &d), URRT_E_RANGE);
        CHECK_EQ_INT(urrt_read_column(v->packet, v->length, 0, &d), URRT_E_RANGE);
    }
}

/* Bytes past the packet are left alone; one byte short is truncated. st2 is
 * the caller's, so that the round trip after decodes into the same state. */
static void check_vector_trailing_bytes(const vector *v, const urrt_state *st, urrt_state *st2)
{
    static uint8_t padded[URRT_PACKET_MAX + 16];
    memcpy(padded, v->packet, v->length);
    memset(padded + v->length, 0x5A, 16);
    CHECK_EQ_INT(urrt_decode(padded, v->length + 16, st2), v->length);
    CHECK(st2->present == st->present && st2->length == st->length && st2->extra_columns == st->extra_columns &&
              memcmp(st2->time, st->time, 8u * (URRT_WIRE_COLUMNS)) == 0,
          "%s: decode with trailing bytes differs", v->name);
    CHECK_EQ_INT(urrt_decode(v->packet, v->length - 1, st2), URRT_E_TRUNCATED);
    CHECK(st2->present == 0, "%s: a failed decode left fields present", v->name);
}

/* Where present fields cover every column, the bytes come back whole
 * (3.x up to column 152; 1.x from 1.7 on at the whole-field cuts). */
static void check_encode_coverage(const vector *v, const urrt_state *st, const uint8_t *out)
{
    urrt_generation gen = (urrt_generation)v->generation;
    unsigned char covered[URRT_MAX_DOUBLES + 1] = {0};
    unsigned all = 1;
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        unsigned column = urrt_field_column((urrt_field_id)id, gen);
        for (unsigned i = 0; urrt_has(st, id) && i < urrt_field((urrt_field_id)id)->count; i++) {
            covered[column + i] = 1;
        }
    }
    for (unsigned c = 1; c <= v->doubles && c <= URRT_WIRE_COLUMNS; c++) {
        all &= covered[c];
    }
    if (all && v->doubles <= URRT_WIRE_COLUMNS) {
        CHECK(memcmp(out, v->packet, v->length) == 0, "%s: encode(decode(p)) != p", v->name);
    }
    if (strcmp(v->name, "v3_10_1116") == 0 || strcmp(v->name, "v5_10_1220") == 0 ||
        strcmp(v->name, "v1_8_812") == 0 || strcmp(v->name, "v1_7_764") == 0) {
        CHECK(all, "%s: not every column is covered by a present field", v->name);
    }
}

/* The encoded packet decoded again: the same fields, bit for bit. */
static void check_encode_round_trip(const vector *v, urrt_state *st, urrt_state *st2, const uint8_t *out)
{
    urrt_generation gen = (urrt_generation)v->generation;
    int r;
    for (unsigned c = URRT_WIRE_COLUMNS + 1; gen == URRT_GEN_3X && c <= v->doubles; c++) {
        CHECK(get_be64(out + 4 + 8 * (c - 1)) == 0, "%s: extra column %u not encoded as 0.0", v->name, c);
    }
    CHECK(out[v->length] == 0xEE, "%s: encode wrote past the length", v->name);
    r = urrt_decode(out, v->length, st2);
    CHECK(r == (int)v->length && st2->present == st->present && st2->generation == st->generation,
          "%s: decode(encode(st)) differs in presence", v->name);
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        if (urrt_has(st, id)) {
            CHECK(memcmp(state_slot(st, id), state_slot(st2, id), 8u * urrt_field((urrt_field_id)id)->count) == 0,
                  "%s: %s changed in a round trip", v->name, urrt_field((urrt_field_id)id)->name);
        }
    }
}

/* Encoder round trip: every present field comes back bit-exact, and the
 * bytes are the reference's wherever a present field covers them. */
static void check_vector_encode(const vector *v, urrt_state *st, urrt_state *st2)
{
    static uint8_t out[URRT_PACKET_MAX + 16];
    urrt_generation gen = (urrt_generation)v->generation;
    int r;
    memset(out, 0xEE, sizeof out);
    r = urrt_encode(st, v->length, out, sizeof out);
    CHECK(r == (int)v->length, "%s: encode returned %d", v->name, r);
    if (r != (int)v->length) {
        return;
    }
    CHECK(memcmp(out, v->packet, 4) == 0, "%s: encoded header", v->name);
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        unsigned column = urrt_field_column((urrt_field_id)id, gen);
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        if (!urrt_has(st, id)) {
            continue;
        }
        CHECK(memcmp(out + 4 + 8 * (column - 1), v->packet + 4 + 8 * (column - 1), 8u * f->count) == 0,
              "%s: encoded %s differs from the reference bytes", v->name, f->name);
    }
    check_encode_coverage(v, st, out);
    check_encode_round_trip(v, st, st2, out);
}

static void check_vector(const vector *v, expected_field *e)
{
    urrt_state st, st2;
    int r;

    if (v->length > URRT_PACKET_MAX) {
        /* Built with a smaller URRT_MAX_DOUBLES: past it is an error, and the
         * framer skips such packets. */
        double d;
        CHECK_EQ_INT(urrt_decode(v->packet, v->length, &st), URRT_E_SIZE_LARGE);
        CHECK_EQ_INT(urrt_read(v->packet, v->length, URRT_F_TIME, 0, &d), URRT_E_SIZE_LARGE);
        return;
    }
    memset(&st, 0xA5, sizeof st);
    r = urrt_decode(v->packet, v->length, &st);
    CHECK(r == (int)v->length, "%s: decode returned %d", v->name, r);
    if (r < 0) {
        return;
    }
    check_vector_header(v, &st);
    check_vector_fields(v, e, &st);
    check_vector_extra_columns(v);
    check_vector_trailing_bytes(v, &st, &st2);
    check_vector_encode(v, &st, &st2);
}

static int hexval(int c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

/* A "vector NAME LENGTH GENERATION DOUBLES EXTRA VERSIONS" line: the next vector. */
static vector *start_vector(const char *line)
{
    vector *v;
    int consumed = 0;
    if (vector_count == MAX_VECTORS) {
        fprintf(stderr, "test_lib: too many vectors\n");
        exit(2);
    }
    v = &vectors[vector_count++];
    if (sscanf(line, "vector %63s %" SCNu32 " %d %u %u %n", v->name, &v->length, &v->generation, &v->doubles,
               &v->extra, &consumed) != 5 || consumed == 0) {
        fprintf(stderr, "test_lib: bad line: %.80s\n", line);
        exit(2);
    }
    snprintf(v->versions, sizeof v->versions, "%s", line + consumed);
    return v;
}

/* A "hex" line: the vector's packet. */
static void read_packet(vector *v, const char *line)
{
    size_t n = strlen(line + 4) / 2;
    CHECK(n == v->length, "%s: hex holds %zu bytes", v->name, n);
    v->packet = malloc(n + 1);
    for (size_t i = 0; i < n; i++) {
        v->packet[i] = (uint8_t)(hexval(line[4 + 2 * i]) << 4 | hexval(line[5 + 2 * i]));
    }
}

/* A "field", "absent", "enum" or "bits" line into expected; 0 for any other line. */
static int read_expectation(const vector *v, const char *line, expected_field *expected)
{
    char name[64], word[64];
    unsigned elem;
    int id;
    if (sscanf(line, "field %63s %u %63s", name, &elem, word) == 3) {
        id = urrt_field_find(name, strlen(name));
        CHECK(id >= 0, "%s: lib has no field %s", v->name, name);
        if (id >= 0 && elem < URRT_FIELD_COUNT_MAX) {
            expected[id].seen = 1;
            expected[id].bits[elem] = strtoull(word, NULL, 16);
            if ((int)elem + 1 > expected[id].elements) {
                expected[id].elements = (int)elem + 1;
            }
        }
    } else if (sscanf(line, "absent %63s", name) == 1) {
        id = urrt_field_find(name, strlen(name));
        CHECK(id >= 0, "%s: lib has no field %s", v->name, name);
        if (id >= 0) {
            expected[id].seen = 1;
            expected[id].absent = 1;
        }
    } else if (sscanf(line, "enum %63s %u %63s", name, &elem, word) == 3) {
        id = urrt_field_find(name, strlen(name));
        if (id >= 0 && elem < URRT_FIELD_COUNT_MAX) {
            expected[id].has_enum[elem] = 1;
            snprintf(expected[id].enum_name[elem], sizeof expected[id].enum_name[elem], "%s", word);
        }
    } else if (sscanf(line, "bits %63s %63s", name, word) == 2) {
        id = urrt_field_find(name, strlen(name));
        if (id >= 0) {
            expected[id].has_mask = 1;
            expected[id].mask_ok = strcmp(word, "NOT_BITMASK") != 0;
            expected[id].mask = expected[id].mask_ok ? strtoull(word, NULL, 16) : 0;
        }
    } else {
        return 0;
    }
    return 1;
}

static void load_vectors(const char *path)
{
    FILE *f = fopen(path, "r");
    static char line[16384];
    static expected_field expected[URRT_FIELD_COUNT];
    vector *v = NULL;
    size_t checked = 0;

    if (f == NULL) {
        perror(path);
        exit(2);
    }
    while (fgets(line, sizeof line, f) != NULL) {
        line[strcspn(line, "\n")] = '\0';
        if (line[0] == '#' || line[0] == '\0') {
            continue;
        }
        if (strncmp(line, "vector ", 7) == 0) {
            v = start_vector(line);
            memset(expected, 0, sizeof expected);
            continue;
        }
        if (v == NULL) {
            fprintf(stderr, "test_lib: data before the first vector\n");
            exit(2);
        }
        if (strncmp(line, "hex ", 4) == 0) {
            read_packet(v, line);
        } else if (strcmp(line, "end") == 0) {
            if (v->packet != NULL) {
                check_vector(v, expected);
                checked++;
            }
        } else if (!read_expectation(v, line, expected)) {
            fprintf(stderr, "test_lib: bad line: %.80s\n", line);
            exit(2);
        }
    }
    fclose(f);
    /* 14 named lengths, 2 I/O, 2 capture, 256 lengths: a short file is a failure. */
    CHECK(checked >= 274 && checked == vector_count, "only %zu of %zu vectors checked", checked, vector_count);
}

/* ---- the framer ------------------------------------------------------------ */

typedef struct sink {
    uint8_t data[64 * 1024];
    size_t len;
    size_t packets;
    size_t lengths[64];
} sink;

/* Feeds a chunk completely, asserting progress on every call. */
static void feed_chunk(urrt_framer *fr, const uint8_t *p, size_t n, sink *s)
{
    int guard = 0;
    do {
        size_t used = (size_t)-1;
        int r = urrt_framer_feed(fr, p, n, &used);
        CHECK(r == 0 || r == 1, "feed returned %d", r);
        CHECK(used <= n, "used %zu of %zu", used, n);
        if (r < 0 || used > n) {
            return;
        }
        if (r == 1) {
            size_t len = 0;
            const uint8_t *pkt = urrt_framer_packet(fr, &len);
            CHECK(pkt != NULL && len >= URRT_PACKET_MIN, "a yielded packet is missing");
            if (pkt != NULL && s->len + len <= sizeof s->data && s->packets < 64) {
                memcpy(s->data + s->len, pkt, len);
                s->len += len;
                s->lengths[s->packets++] = len;
            }
        } else {
            CHECK(urrt_framer_packet(fr, NULL) == NULL, "a packet after a feed that yielded none");
            CHECK(used == n, "feed returned 0 with %zu of %zu bytes unused", n - used, n);
        }
        CHECK(used > 0 || r == 1 || n == 0, "no progress");
        if (used == 0 && r == 0) {
            return;
        }
        p += used;
        n -= used;
    } while (n > 0 && ++guard < 100000);
}

typedef struct run_result {
    sink out;
    urrt_framer_stats stats;
    size_t pending;
} run_result;

static urrt_framer framer; /* large: keep it off the stack */

/* Feeds stream in chunks ending at the given cut points, then finishes. */
static void run_framer(const uint8_t *stream, size_t n, const size_t *cuts, size_t ncuts, run_result *rr)
{
    size_t at = 0;
    memset(rr, 0, sizeof *rr);
    urrt_framer_init(&framer);
    for (size_t i = 0; i <= ncuts; i++) {
        size_t end = i < ncuts ? cuts[i] : n;
        feed_chunk(&framer, stream + at, end - at, &rr->out);
        at = end;
    }
    rr->stats = framer.stats;
    /* Bytes accounting: every byte fed is in a packet, skipped or pending. */
    CHECK(rr->stats.bytes == n, "fed %zu, counted %" PRIu64, n, rr->stats.bytes);
    CHECK(rr->out.len + rr->stats.skipped + framer.have == n,
          "accounting: %zu in packets + %" PRIu64 " skipped + %u pending != %zu", rr->out.len, rr->stats.skipped,
          framer.have, n);
    CHECK(rr->stats.packets == rr->out.packets, "packet count");
    rr->pending = urrt_framer_finish(&framer);
    CHECK(urrt_framer_packet(&framer, NULL) == NULL, "finish left a packet");
}

static int same_run(const run_result *a, const run_result *b)
{
    return a->out.len == b->out.len && a->out.packets == b->out.packets &&
           memcmp(a->out.data, b->out.data, a->out.len) == 0 &&
           memcmp(a->out.lengths, b->out.lengths, sizeof a->out.lengths) == 0 && a->pending == b->pending &&
           a->stats.skipped == b->stats.skipped && a->stats.resyncs == b->stats.resyncs &&
           a->stats.packets == b->stats.packets;
}

/* Every chunking must give what one call gives. */
static void check_every_split(const char *what, const uint8_t *stream, size_t n, size_t three_way_step)
{
    static run_result whole, part;
    size_t bad = 0;
    run_framer(stream, n, NULL, 0, &whole);
    for (size_t s = 0; s <= n; s++) {
        run_framer(stream, n, &s, 1, &part);
        if (!same_run(&whole, &part)) {
            bad++;
        }
    }
    CHECK(bad == 0, "%s: %zu of %zu two-way splits differ from one-shot feeding", what, bad, n + 1);
    bad = 0;
    for (size_t a = 0; three_way_step && a <= n; a += three_way_step) {
        for (size_t b = a; b <= n; b += three_way_step + 6) {
            size_t cuts[2] = {a, b};
            run_framer(stream, n, cuts, 2, &part);
            bad += !same_run(&whole, &part);
        }
    }
    CHECK(bad == 0, "%s: %zu three-way splits differ", what, bad);
    {
        /* One byte at a time, with zero-length feeds between. */
        static size_t cuts[8192];
        size_t k = 0;
        for (size_t i = 0; i <= n && k + 2 < 8192; i++) {
            cuts[k++] = i;
            cuts[k++] = i;
        }
        run_framer(stream, n, cuts, k, &part);
        CHECK(same_run(&whole, &part), "%s: byte-at-a-time feeding differs", what);
    }
}

static size_t concat(uint8_t *dst, size_t at, const uint8_t *src, size_t n)
{
    memcpy(dst + at, src, n);
    return at + n;
}

static void expect_packets(const char *what, const run_result *rr, const uint8_t *const *pkts, const size_t *lens,
                           size_t count)
{
    size_t at = 0;
    CHECK(rr->out.packets == count, "%s: %zu packets, expected %zu", what, rr->out.packets, count);
    for (size_t i = 0; i < count && i < rr->out.packets; i++) {
        CHECK(rr->out.lengths[i] == lens[i] && memcmp(rr->out.data + at, pkts[i], lens[i]) == 0,
              "%s: packet %zu differs", what, i);
        at += rr->out.lengths[i];
    }
}

static void test_framer_split_equivalence(void)
{
    static uint8_t stream[8192];
    static run_result rr;
    const char *pairs[][2] = {
        {"v3_10_1116", "len_1116"}, {"capture_1_8", "capture_1_8_next"}, {"v5_10_1220", "v5_10_1220"},
        {"early_540", "early_540"},
#if URRT_MAX_DOUBLES >= 154
        {"future_1236", "future_1236"},
#endif
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
        const vector *a = find_vector(pairs[i][0]), *b = find_vector(pairs[i][1]);
        const uint8_t *pk[2] = {a->packet, b->packet};
        size_t ln[2] = {a->length, b->length};
        size_t n = concat(stream, concat(stream, 0, a->packet, a->length), b->packet, b->length);
        run_framer(stream, n, NULL, 0, &rr);
        expect_packets(pairs[i][0], &rr, pk, ln, 2);
        CHECK(rr.stats.skipped == 0 && rr.stats.resyncs == 0 && rr.pending == 0, "%s: clean stream skipped bytes",
              pairs[i][0]);
        check_every_split(pairs[i][0], stream, n, i == 0 ? 29 : 0);
    }
}

static void test_framer_zero_length_feeds(void)
{
    size_t used = 99;
    uint8_t byte = 0;
    urrt_framer_init(&framer);
    CHECK_EQ_INT(urrt_framer_feed(&framer, NULL, 0, &used), 0);
    CHECK_EQ_INT(used, 0);
    used = 99;
    CHECK_EQ_INT(urrt_framer_feed(&framer, &byte, 0, &used), 0);
    CHECK_EQ_INT(used, 0);
    CHECK(urrt_framer_packet(&framer, NULL) == NULL, "a packet from nothing");
    CHECK_EQ_INT(framer.stats.bytes, 0);
    CHECK_EQ_INT(urrt_framer_finish(&framer), 0);
}

/* The 1460-byte read of docs/sources.md "The CB2 1.8 capture": one 812-byte
 * 1.8 packet and the first 648 bytes of the next. */
static void test_real_capture(void)
{
    static uint8_t stream[2048];
    static run_result rr;
    const vector *a = find_vector("capture_1_8"), *b = find_vector("capture_1_8_next");
    urrt_state st;
    const double accel[3] = {-0.138, -2.805, 8.385};
    size_t n = concat(stream, concat(stream, 0, a->packet, a->length), b->packet, 648);
    const uint8_t *pk[1] = {a->packet};
    size_t ln[1] = {a->length};

    CHECK_EQ_INT(n, 1460);
    run_framer(stream, n, NULL, 0, &rr);
    expect_packets("capture", &rr, pk, ln, 1);
    CHECK_EQ_INT(rr.pending, 648);
    CHECK_EQ_INT(urrt_decode(rr.out.data, rr.out.len, &st), 812);
    CHECK(st.generation == URRT_GEN_1X, "capture is not 1.x");
    CHECK(st.time[0] == 951.592, "time %.17g", st.time[0]);
    CHECK_EQ_STR(urrt_enum_name(urrt_field_enum(URRT_F_ROBOT_MODE, st.generation), st.robot_mode[0]), "RUNNING");
    CHECK(urrt_field_enum(URRT_F_ROBOT_MODE, st.generation) == URRT_ENUM_ROBOT_MODE_1X, "CB2 numbering");
    for (int j = 0; j < 6; j++) {
        CHECK(st.joint_modes[j] == 253.0, "joint mode %d", j);
        CHECK_EQ_STR(urrt_enum_name(URRT_ENUM_JOINT_MODE, st.joint_modes[j]), "RUNNING");
    }
    for (int j = 0; j < 3; j++) {
        CHECK(st.tool_accelerometer[j] == accel[j], "accelerometer %d: %g", j, st.tool_accelerometer[j]);
    }
    CHECK(st.motor_temperatures[0] == 24.2 && st.motor_temperatures[5] == 29.0, "motor temperatures");
    CHECK(urrt_has(&st, URRT_F_TOOL_VECTOR) && urrt_has(&st, URRT_F_TCP_SPEED) && urrt_has(&st, URRT_F_UNUSED_53),
          "1.x fields");
    CHECK(!urrt_has(&st, URRT_F_TOOL_VECTOR_ACTUAL) && !urrt_has(&st, URRT_F_SAFETY_MODE) &&
              !urrt_has(&st, URRT_F_I_CONTROL),
          "3.x fields in a 1.8 packet");
    /* The whole next packet, once the stream goes on. */
    n = concat(stream, n, b->packet + 648, b->length - 648);
    run_framer(stream, n, NULL, 0, &rr);
    CHECK_EQ_INT(rr.out.packets, 2);
    CHECK_EQ_INT(urrt_decode(rr.out.data + 812, rr.out.len - 812, &st), 812);
    CHECK(st.time[0] == 951.600, "next time %.17g", st.time[0]);
}

/* The garbage test_framer_garbage puts around packets: text that is not a
 * plausible header at any offset, and 0xFF bytes (filled there). */
static const uint8_t garbage_text[] = "GET / HTTP/1.0\r\n\r\n";
static uint8_t garbage_ff[37];

/* The stream of a, the garbage text, b, ff bytes of 0xFF and c; its length. */
static size_t garbage_between_packets(uint8_t *stream, const vector *a, const vector *b, size_t ff, const vector *c)
{
    size_t n = concat(stream, 0, a->packet, a->length);
    n = concat(stream, n, garbage_text, sizeof garbage_text - 1);
    n = concat(stream, n, b->packet, b->length);
    n = concat(stream, n, garbage_ff, ff);
    return concat(stream, n, c->packet, c->length);
}

/* Before the first packet. */
static void garbage_before(uint8_t *stream, run_result *rr)
{
    const vector *p1 = find_vector("v3_10_1116"), *p2 = find_vector("len_1116");
    size_t n = concat(stream, 0, garbage_ff, sizeof garbage_ff);
    n = concat(stream, n, p1->packet, p1->length);
    n = concat(stream, n, p2->packet, p2->length);
    run_framer(stream, n, NULL, 0, rr);
    {
        const uint8_t *pk[2] = {p1->packet, p2->packet};
        size_t ln[2] = {p1->length, p2->length};
        expect_packets("garbage before", rr, pk, ln, 2);
        CHECK(rr->stats.skipped == sizeof garbage_ff && rr->stats.resyncs == 1, "garbage before: skipped %" PRIu64
              ", %" PRIu64 " resyncs", rr->stats.skipped, rr->stats.resyncs);
    }
    check_every_split("garbage before", stream, n, 0);
}

/* Between packets, and between packets of different known lengths. */
static void garbage_between(uint8_t *stream, run_result *rr)
{
    const vector *p1 = find_vector("v3_10_1116"), *p2 = find_vector("len_1116"), *p3 = find_vector("v5_10_1220");
    size_t n = garbage_between_packets(stream, p1, p2, 5, p3);
    run_framer(stream, n, NULL, 0, rr);
    {
        const uint8_t *pk[3] = {p1->packet, p2->packet, p3->packet};
        size_t ln[3] = {p1->length, p2->length, p3->length};
        expect_packets("garbage between", rr, pk, ln, 3);
        CHECK(rr->stats.skipped == sizeof garbage_text - 1 + 5 && rr->stats.resyncs == 2,
              "garbage between: skipped %" PRIu64, rr->stats.skipped);
    }
    check_every_split("garbage between", stream, n, 0);
}

/* Regression: a fresh framer scanning leading garbage took any plausible
 * size it met (here 00 00 02 14, 532 bytes) as a packet, so noise came
 * out as values. Only known lengths lock once it has had to scan. */
static void regression_fresh_scan_unknown_size(uint8_t *stream, run_result *rr)
{
    const vector *v = find_vector("len_1116");
    static const uint8_t noise[] = {0xAB, 0x00, 0x00, 0x02, 0x14, 0x99, 0x42};
    const uint8_t *pk[1] = {v->packet};
    size_t ln[1] = {v->length};
    size_t n = concat(stream, 0, noise, sizeof noise);
    for (size_t pad = sizeof noise; pad < 600; pad++) {
        stream[n++] = 0x55; /* enough bytes for a 532-byte "packet" */
    }
    n = concat(stream, n, v->packet, v->length);
    run_framer(stream, n, NULL, 0, rr);
    expect_packets("regression_fresh_scan_unknown_size", rr, pk, ln, 1);
    CHECK(rr->stats.skipped == 600 && rr->stats.resyncs == 1,
          "regression_fresh_scan_unknown_size: skipped %" PRIu64, rr->stats.skipped);
}

/* A length no controller is known to send (a newer one, 1236 bytes):
 * after garbage the framer finds it again because it equals the last
 * accepted length. Likewise a 1.8 stream. */
static void garbage_around_unlisted_lengths(uint8_t *stream, run_result *rr)
{
    const char *names[2] = {"capture_1_8", "future_1236"};
    for (int k = 0; k < (URRT_MAX_DOUBLES >= 154 ? 2 : 1); k++) {
        const vector *f = find_vector(names[k]);
        const uint8_t *pk[3] = {f->packet, f->packet, f->packet};
        size_t ln[3] = {f->length, f->length, f->length};
        size_t n = garbage_between_packets(stream, f, f, 3, f);
        run_framer(stream, n, NULL, 0, rr);
        expect_packets(names[k], rr, pk, ln, 3);
        CHECK(rr->stats.skipped == sizeof garbage_text - 1 + 3 && rr->stats.resyncs == 2, "%s: skipped %" PRIu64,
              names[k], rr->stats.skipped);
    }
}

/* Inside a packet: the first 500 bytes of one, then whole packets. With
 * no checksum on the wire the cut packet swallows the start of the next
 * (a packet of the declared size is yielded), then the framer must find
 * its way back to the packet after. */
static void garbage_inside(uint8_t *stream, run_result *rr)
{
    const vector *p1 = find_vector("v3_10_1116"), *p2 = find_vector("len_1116");
    size_t n = concat(stream, 0, p1->packet, p1->length);
    n = concat(stream, n, p2->packet, 500);
    n = concat(stream, n, p1->packet, p1->length);
    n = concat(stream, n, p2->packet, p2->length);
    n = concat(stream, n, p1->packet, p1->length);
    run_framer(stream, n, NULL, 0, rr);
    CHECK_EQ_INT(rr->out.packets, 4);
    if (rr->out.packets == 4) {
        CHECK(memcmp(rr->out.data, p1->packet, 1116) == 0, "inside: first packet");
        CHECK(memcmp(rr->out.data + 1116, p2->packet, 500) == 0 && memcmp(rr->out.data + 1616, p1->packet, 616) == 0,
              "inside: the cut packet");
        CHECK(memcmp(rr->out.data + 2232, p2->packet, 1116) == 0, "inside: recovered packet");
        CHECK(memcmp(rr->out.data + 3348, p1->packet, 1116) == 0, "inside: last packet");
    }
    CHECK(rr->stats.skipped == 500 && rr->stats.resyncs == 1, "inside: skipped %" PRIu64, rr->stats.skipped);
    check_every_split("garbage inside", stream, n, 0);
}

static void test_framer_garbage(void)
{
    static uint8_t stream[16384];
    static run_result rr;
    memset(garbage_ff, 0xFF, sizeof garbage_ff);
    garbage_before(stream, &rr);
    garbage_between(stream, &rr);
    regression_fresh_scan_unknown_size(stream, &rr);
    garbage_around_unlisted_lengths(stream, &rr);
    garbage_inside(stream, &rr);
}

/* A stream that goes on mid-packet, at every double boundary: the framer
 * must skip to the next real header and never lock onto the bytes of a
 * double (0x3FEF0000, or a plausible size no controller sends). */
static void test_framer_resync_not_fooled(void)
{
    static uint8_t stream[8192], body[1116];
    static run_result rr;
    const vector *p1 = find_vector("v3_10_1116");
    size_t failures = 0;

    memcpy(body, p1->packet, sizeof body);
    for (unsigned c = 1; c <= 139; c++) {
        static const uint64_t traps[] = {
            UINT64_C(0x3FEF000000000000), UINT64_C(0x3FEF00003FEF0000), UINT64_C(0x0000021400000214),
            UINT64_C(0x000003F400000000), UINT64_C(0x7FF8000000000000), UINT64_C(0x000000000000000C),
        };
        put_be64(body + 4 + 8 * (c - 1), traps[c % 6]);
    }
    for (unsigned j = 0; j < 139; j++) {
        size_t n = concat(stream, 0, p1->packet, p1->length);
        size_t tail = sizeof body - 4 - 8 * j;
        n = concat(stream, n, body + 4 + 8 * j, tail);
        n = concat(stream, n, p1->packet, p1->length);
        n = concat(stream, n, p1->packet, p1->length);
        run_framer(stream, n, NULL, 0, &rr);
        if (rr.out.packets != 3 || rr.stats.skipped != tail || rr.stats.resyncs != 1) {
            failures++;
        }
    }
    CHECK(failures == 0, "resync locked onto the bytes of a double in %zu of 139 cases", failures);
}

static void test_framer_truncation(void)
{
    static uint8_t stream[4096];
    static run_result rr;
    const vector *p1 = find_vector("v3_10_1116"), *p2 = find_vector("len_1116");
    size_t bad = 0;
    for (size_t k = 0; k < p2->length; k++) {
        size_t n = concat(stream, concat(stream, 0, p1->packet, p1->length), p2->packet, k);
        run_framer(stream, n, NULL, 0, &rr);
        if (rr.out.packets != 1 || rr.pending != k || rr.stats.skipped != 0) {
            bad++;
        }
    }
    CHECK(bad == 0, "truncation: %zu of %u cut points misreported", bad, p2->length);
    /* After finish the framer starts a new stream. */
    urrt_framer_init(&framer);
    {
        size_t used;
        CHECK_EQ_INT(urrt_framer_feed(&framer, p2->packet, 100, &used), 0);
        CHECK_EQ_INT(urrt_framer_finish(&framer), 100);
        CHECK_EQ_INT(urrt_framer_finish(&framer), 0);
        CHECK_EQ_INT(urrt_framer_feed(&framer, p1->packet, p1->length, &used), 1);
        CHECK_EQ_INT(used, p1->length);
    }
}

static void test_bad_sizes(void)
{
    static const struct {
        uint32_t raw;
        int expected;
    } cases[] = {
        {0, URRT_E_SIZE_SMALL},
        {(uint32_t)-8, URRT_E_SIZE_SMALL},
        {(uint32_t)-1, URRT_E_SIZE_SMALL},
        {0x80000004u, URRT_E_SIZE_SMALL},
        {3, URRT_E_SIZE_SMALL},
        {4, URRT_E_SIZE_SMALL},
        {5, URRT_E_SIZE_SMALL},
        {13, URRT_E_SIZE_ALIGN},
        {4 + 8 * 139 + 1, URRT_E_SIZE_ALIGN},
        {4 + 8 * 10 + 1, URRT_E_SIZE_ALIGN},
        {1120, URRT_E_SIZE_ALIGN},
        {0x7FFFFFFFu, URRT_E_SIZE_ALIGN},
        {0x3FEF0000u, URRT_E_SIZE_ALIGN},
        {0x7FFFFFFCu, URRT_E_SIZE_LARGE},
        {URRT_PACKET_MAX + 8, URRT_E_SIZE_LARGE},
    };
    static uint8_t stream[8192];
    static run_result rr;
    const vector *p1 = find_vector("v3_10_1116");
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        uint8_t hdr[16] = {0};
        urrt_state st;
        size_t n;
        put_be32(hdr, cases[i].raw);
        CHECK(urrt_packet_length(hdr, sizeof hdr) == cases[i].expected, "size %#x: %d, expected %d", cases[i].raw,
              urrt_packet_length(hdr, sizeof hdr), cases[i].expected);
        CHECK(urrt_decode(hdr, sizeof hdr, &st) == cases[i].expected && st.present == 0, "decode size %#x",
              cases[i].raw);
        /* At the start of a stream and between packets. */
        n = concat(stream, 0, hdr, 4);
        n = concat(stream, n, p1->packet, p1->length);
        n = concat(stream, n, hdr, 4);
        n = concat(stream, n, p1->packet, p1->length);
        run_framer(stream, n, NULL, 0, &rr);
        CHECK(rr.out.packets == 2 && rr.stats.skipped == 8 && rr.stats.resyncs == 2 && rr.pending == 0,
              "framer, size %#x: %zu packets, %" PRIu64 " skipped", cases[i].raw, rr.out.packets, rr.stats.skipped);
    }
    {
        uint8_t hdr[4];
        put_be32(hdr, 12);
        CHECK_EQ_INT(urrt_packet_length(hdr, 3), URRT_E_TRUNCATED);
        CHECK_EQ_INT(urrt_packet_length(hdr, 4), URRT_E_TRUNCATED);
        CHECK_EQ_INT(urrt_packet_length(NULL, 4), URRT_E_ARG);
    }
    {
        /* The smallest and the largest packet the library accepts. */
        static uint8_t big[URRT_PACKET_MAX];
        urrt_state st;
        memset(big, 0, sizeof big);
        put_be32(big, URRT_PACKET_MAX);
        CHECK_EQ_INT(urrt_decode(big, sizeof big, &st), URRT_PACKET_MAX);
        CHECK_EQ_INT(st.extra_columns, URRT_MAX_DOUBLES - URRT_WIRE_COLUMNS);
        put_be32(big, URRT_PACKET_MIN);
        CHECK_EQ_INT(urrt_decode(big, URRT_PACKET_MIN, &st), URRT_PACKET_MIN);
        CHECK(st.present == 1u << URRT_F_TIME, "a 12-byte packet holds only time");
    }
}

/* ---- values, enums, lookup, arguments ---------------------------------------- */

static void test_nan_inf_bit_exact(void)
{
    static const uint64_t values[] = {
        UINT64_C(0x7FF8000000000000), UINT64_C(0x7FF8DEADBEEF0001), UINT64_C(0x7FF0000000000001),
        UINT64_C(0xFFF400000000BEEF), UINT64_C(0x7FF0000000000000), UINT64_C(0xFFF0000000000000),
        UINT64_C(0x8000000000000000), UINT64_C(0x0000000000000001), UINT64_C(0x800FFFFFFFFFFFFF),
    };
    uint8_t pkt[1220];
    urrt_state st;
    put_be32(pkt, 1220);
    for (unsigned c = 1; c <= 152; c++) {
        put_be64(pkt + 4 + 8 * (c - 1), values[c % 9]);
    }
    CHECK_EQ_INT(urrt_decode(pkt, sizeof pkt, &st), 1220);
    for (unsigned c = 1; c <= 152; c++) {
        uint64_t got;
        memcpy(&got, (const uint8_t *)&st + 8 * (c - 1), 8); /* the grid is laid out in column order */
        CHECK(got == values[c % 9], "column %u: %016" PRIx64, c, got);
    }
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        double d;
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        if (f->col_3x) {
            CHECK(urrt_read(pkt, sizeof pkt, (urrt_field_id)id, 0, &d) == URRT_OK &&
                      bits_of(d) == values[f->col_3x % 9],
                  "read %s", f->name);
        }
    }
}

static void test_bitmask(void)
{
    static const struct {
        uint64_t bits;
        int ok;
        uint64_t mask;
    } cases[] = {
        {0x4014000000000000u, 1, 5},          /* 5.0: UR's encoding */
        {0x0000000000000005u, 1, 5},          /* raw int64 5 */
        {0x0000000000000000u, 1, 0},          /* 0.0 and raw 0 */
        {0x8000000000000000u, 1, 0},          /* -0.0 */
        {0x000000000003FFFFu, 1, 0x3FFFF},    /* raw, 18 outputs */
        {0x410FFFF800000000u, 1, 0x3FFFF},    /* 262143.0 */
        {0x000FFFFFFFFFFFFFu, 1, 0x000FFFFFFFFFFFFFu},
        {0x4340000000000000u, 1, UINT64_C(1) << 53}, /* 2^53 */
        {0x4340000000000001u, 0, 0},          /* 2^53 + 2 */
        {0xBFF0000000000000u, 0, 0},          /* -1.0 */
        {0x3FE0000000000000u, 0, 0},          /* 0.5 */
        {0x4014000000000001u, 0, 0},          /* just above 5.0 */
        {0x7FF8000000000000u, 0, 0},          /* NaN */
        {0x7FF0000000000000u, 0, 0},          /* inf */
        {0xFFF0000000000000u, 0, 0},          /* -inf */
        {0x8000000000000005u, 0, 0},          /* negative int64 seen as -subnormal */
        {0x0010000000000000u, 0, 0},          /* DBL_MIN: neither encoding */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        uint64_t mask = 0xDEAD;
        int r = urrt_bitmask(double_of(cases[i].bits), &mask);
        if (cases[i].ok) {
            CHECK(r == URRT_OK && mask == cases[i].mask, "bitmask %016" PRIx64 ": %d %" PRIx64, cases[i].bits, r,
                  mask);
        } else {
            CHECK(r == URRT_E_NOT_BITMASK, "bitmask %016" PRIx64 ": %d", cases[i].bits, r);
        }
    }
    CHECK_EQ_INT(urrt_bitmask(5.0, NULL), URRT_E_ARG);
}

/* The enumerations, typed from docs/sources.md "Enumerations". */
static const struct {
    urrt_enum_kind kind;
    int first;
    const char *names[22];
} enum_facts[] = {
    {URRT_ENUM_ROBOT_MODE, -1, {"NO_CONTROLLER", "DISCONNECTED", "CONFIRM_SAFETY", "BOOTING", "POWER_OFF",
                                "POWER_ON", "IDLE", "BACKDRIVE", "RUNNING", "UPDATING_FIRMWARE"}},
    {URRT_ENUM_ROBOT_MODE_1X, 0, {"RUNNING", "FREEDRIVE", "READY", "INITIALIZING", "SECURITY_STOPPED",
                                  "EMERGENCY_STOPPED", "FATAL_ERROR", "NO_POWER", "NOT_CONNECTED", "SHUTDOWN",
                                  "SAFEGUARD_STOP"}},
    {URRT_ENUM_JOINT_MODE, 235, {"RESET", "SHUTTING_DOWN", "PART_D_CALIBRATION", "BACKDRIVE", "POWER_OFF",
                                 "READY_FOR_POWER_OFF", "CALVAL_INITIALIZATION", "ERROR", "FREEDRIVE",
                                 "SIMULATED", "NOT_RESPONDING", "MOTOR_INITIALISATION", "BOOTING",
                                 "PART_D_CALIBRATION_ERROR", "BOOTLOADER", "CALIBRATION", "VIOLATION", "FAULT",
                                 "RUNNING", "INITIALISATION", "IDLE"}},
    {URRT_ENUM_SAFETY_MODE, 1, {"NORMAL", "REDUCED", "PROTECTIVE_STOP", "RECOVERY", "SAFEGUARD_STOP",
                                "SYSTEM_EMERGENCY_STOP", "ROBOT_EMERGENCY_STOP", "VIOLATION", "FAULT",
                                "VALIDATE_JOINT_ID", "UNDEFINED_SAFETY_MODE"}},
    {URRT_ENUM_SAFETY_STATUS, 1, {"NORMAL", "REDUCED", "PROTECTIVE_STOP", "RECOVERY", "SAFEGUARD_STOP",
                                  "SYSTEM_EMERGENCY_STOP", "ROBOT_EMERGENCY_STOP", "VIOLATION", "FAULT",
                                  "VALIDATE_JOINT_ID", "UNDEFINED_SAFETY_MODE", "AUTOMATIC_MODE_SAFEGUARD_STOP",
                                  "SYSTEM_THREE_POSITION_ENABLING_STOP"}},
    {URRT_ENUM_PROGRAM_STATE, 0, {"STOPPING", "STOPPED", "PLAYING", "PAUSING", "PAUSED", "RESUMING"}},
};

static void test_enums(void)
{
    for (size_t k = 0; k < sizeof enum_facts / sizeof enum_facts[0]; k++) {
        size_t count = 99, n = 0;
        const urrt_enum_entry *e = urrt_enum_entries(enum_facts[k].kind, &count);
        while (n < 22 && enum_facts[k].names[n] != NULL) {
            n++;
        }
        CHECK(e != NULL && count == n, "kind %d: %zu entries, expected %zu", (int)enum_facts[k].kind, count, n);
        for (size_t i = 0; i < n; i++) {
            int value = enum_facts[k].first + (int)i;
            CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, value), enum_facts[k].names[i]);
            CHECK(e == NULL || i >= count || (e[i].value == value && strcmp(e[i].name, enum_facts[k].names[i]) == 0),
                  "kind %d entry %zu", (int)enum_facts[k].kind, i);
            CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, value + 0.5), URRT_UNKNOWN_NAME);
            CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, value - 1e-9), URRT_UNKNOWN_NAME);
        }
        /* Unknown numbers on both sides, and values that are no number. */
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, enum_facts[k].first - 1), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, enum_facts[k].first + (double)n), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, NAN), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, double_of(UINT64_C(0x7FF0000000000001))), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, INFINITY), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, -INFINITY), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, 1e300), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, 65536.0 + enum_facts[k].first), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, 4294967296.0 + enum_facts[k].first), URRT_UNKNOWN_NAME);
        CHECK_EQ_STR(urrt_enum_name(enum_facts[k].kind, double_of(1)), URRT_UNKNOWN_NAME);
    }
    CHECK_EQ_STR(urrt_enum_name(URRT_ENUM_ROBOT_MODE, -0.0), "DISCONNECTED");
    CHECK_EQ_STR(urrt_enum_name(URRT_ENUM_ROBOT_MODE, -2.0), URRT_UNKNOWN_NAME);
    CHECK_EQ_STR(urrt_enum_name(URRT_ENUM_ROBOT_MODE_1X, -1.0), URRT_UNKNOWN_NAME);
    CHECK_EQ_STR(urrt_enum_name(URRT_ENUM_NONE, 0.0), URRT_UNKNOWN_NAME);
    CHECK_EQ_STR(urrt_enum_name((urrt_enum_kind)99, 0.0), URRT_UNKNOWN_NAME);
    {
        size_t count = 5;
        CHECK(urrt_enum_entries(URRT_ENUM_NONE, &count) == NULL && count == 0, "no entries for NONE");
        count = 5;
        CHECK(urrt_enum_entries((urrt_enum_kind)99, &count) == NULL && count == 0, "no entries for kind 99");
        CHECK(urrt_enum_entries(URRT_ENUM_SAFETY_MODE, NULL) != NULL, "count may be NULL");
    }
    /* Robot mode: the numbering follows the generation. */
    CHECK(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_1X) == URRT_ENUM_ROBOT_MODE_1X, "1.x robot mode");
    CHECK(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_3X) == URRT_ENUM_ROBOT_MODE, "3.x robot mode");
    CHECK(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_UNKNOWN) == URRT_ENUM_NONE, "ambiguous robot mode");
    CHECK_EQ_STR(urrt_enum_name(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_1X), 7), "NO_POWER");
    CHECK_EQ_STR(urrt_enum_name(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_3X), 7), "RUNNING");
    CHECK_EQ_STR(urrt_enum_name(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_1X), 0), "RUNNING");
    CHECK_EQ_STR(urrt_enum_name(urrt_field_enum(URRT_F_ROBOT_MODE, URRT_GEN_3X), 0), "DISCONNECTED");
    CHECK(urrt_field_enum(URRT_F_JOINT_MODES, URRT_GEN_1X) == URRT_ENUM_JOINT_MODE, "joint modes");
    CHECK(urrt_field_enum(URRT_F_SAFETY_MODE, URRT_GEN_3X) == URRT_ENUM_SAFETY_MODE, "safety mode");
    CHECK(urrt_field_enum(URRT_F_SAFETY_STATUS, URRT_GEN_3X) == URRT_ENUM_SAFETY_STATUS, "safety status");
    CHECK(urrt_field_enum(URRT_F_PROGRAM_STATE, URRT_GEN_3X) == URRT_ENUM_PROGRAM_STATE, "program state");
    CHECK(urrt_field_enum(URRT_F_TIME, URRT_GEN_3X) == URRT_ENUM_NONE, "time is no enum");
}

static void test_field_lookup(void)
{
    static const char *const names[] = {"time", "q_target", "q_actual", "tcp_force", "digital_input_bits",
                                        "robot_mode", "joint_modes", "safety_mode", "tool_accelerometer",
                                        "digital_outputs", "program_state", "safety_status", "payload_mass",
                                        "payload_cog", "payload_inertia", "tool_vector", "tcp_speed", "unused_53",
                                        "reserved_140"};
    char *exact;
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        int id = urrt_field_find(names[i], strlen(names[i]));
        CHECK(id >= 0 && strcmp(urrt_field((urrt_field_id)id)->name, names[i]) == 0, "find %s", names[i]);
    }
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        const char *n = urrt_field((urrt_field_id)id)->name;
        size_t len = strlen(n);
        CHECK_EQ_INT(urrt_field_find(n, len), id);
        /* Not NUL-terminated: exactly len bytes on the heap, so that ASan sees
         * any read past them. */
        exact = malloc(len);
        memcpy(exact, n, len);
        CHECK_EQ_INT(urrt_field_find(exact, len), id);
        CHECK_EQ_INT(urrt_field_find(exact, len - 1), len - 1 == 0 ? URRT_E_UNKNOWN_FIELD
                                                      : urrt_field_find(n, len - 1));
        free(exact);
    }
    CHECK_EQ_INT(urrt_field_find("q_targetXYZ", 8), URRT_F_Q_TARGET);
    CHECK_EQ_INT(urrt_field_find("q_targe", 7), URRT_E_UNKNOWN_FIELD);
    CHECK_EQ_INT(urrt_field_find("q", 1), URRT_E_UNKNOWN_FIELD);
    CHECK_EQ_INT(urrt_field_find("time", 0), URRT_E_UNKNOWN_FIELD);
    CHECK_EQ_INT(urrt_field_find("time\0", 5), URRT_E_UNKNOWN_FIELD);
    CHECK_EQ_INT(urrt_field_find("TIME", 4), URRT_E_UNKNOWN_FIELD);
    CHECK_EQ_INT(urrt_field_find("time ", 5), URRT_E_UNKNOWN_FIELD);
    CHECK_EQ_INT(urrt_field_find("tcp_speed_actualX", 9), URRT_F_TCP_SPEED);
    CHECK_EQ_INT(urrt_field_find(NULL, 4), URRT_E_ARG);
}

static void test_field_metadata(void)
{
    unsigned covered_3x[URRT_WIRE_COLUMNS + 1] = {0}, covered_1x[102] = {0};
    CHECK(urrt_field((urrt_field_id)URRT_FIELD_COUNT) == NULL, "id past the table");
    CHECK(urrt_field((urrt_field_id)-1) == NULL, "negative id");
    CHECK_EQ_INT(urrt_field_column((urrt_field_id)URRT_FIELD_COUNT, URRT_GEN_3X), 0);
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        CHECK(f != NULL && f->name && f->unit && f->since && f->description && f->description[0], "metadata %d", id);
        CHECK(f->count >= 1 && f->count <= URRT_FIELD_COUNT_MAX, "%s count", f->name);
        CHECK(f->col_1x != 0 || f->col_3x != 0, "%s has no column", f->name);
        CHECK_EQ_INT(urrt_field_column((urrt_field_id)id, URRT_GEN_1X), f->col_1x);
        CHECK_EQ_INT(urrt_field_column((urrt_field_id)id, URRT_GEN_3X), f->col_3x);
        CHECK_EQ_INT(urrt_field_column((urrt_field_id)id, URRT_GEN_UNKNOWN), f->col_1x == f->col_3x ? f->col_1x : 0);
        for (unsigned i = 0; i < f->count; i++) {
            if (f->col_3x) covered_3x[f->col_3x + i]++;
            if (f->col_1x) covered_1x[f->col_1x + i]++;
        }
        for (int other = 0; other < id; other++) {
            CHECK(strcmp(f->name, urrt_field((urrt_field_id)other)->name) != 0, "duplicate name %s", f->name);
        }
    }
    for (unsigned c = 1; c <= URRT_WIRE_COLUMNS; c++) {
        CHECK(covered_3x[c] == 1, "3.x column %u covered %u times", c, covered_3x[c]);
    }
    for (unsigned c = 1; c <= 101; c++) {
        CHECK(covered_1x[c] == 1, "1.x column %u covered %u times", c, covered_1x[c]);
    }
    CHECK(URRT_FRAMER_RAM >= URRT_PACKET_MAX, "framer RAM macro");
    CHECK_EQ_STR(URRT_VERSION_STRING, "0.1.0");
}

/* "since" of every field agrees with the lengths table of docs/sources.md:
 * it is the first version of the first documented length whose packets
 * hold the field (presence itself is checked against the reference). */
static void test_field_since_follows_lengths(void)
{
    static const struct {
        uint32_t length;
        const char *first_version;
    } lengths[] = {
        {756, "1.5"}, {764, "1.7"}, {812, "1.8"}, {1044, "3.0"}, {1060, "3.2"},
        {1108, "3.5"}, {1116, "3.10/5.4"}, {1140, "3.14/5.9"}, {1220, "5.10"},
    };
    const char *since[URRT_FIELD_COUNT] = {0};
    static uint8_t pkt[1220];
    urrt_state st;
    for (size_t k = 0; k < sizeof lengths / sizeof lengths[0]; k++) {
        memset(pkt, 0, sizeof pkt);
        put_be32(pkt, lengths[k].length);
        CHECK_EQ_INT(urrt_decode(pkt, lengths[k].length, &st), lengths[k].length);
        for (int id = 0; id < URRT_FIELD_COUNT; id++) {
            if (since[id] == NULL && urrt_has(&st, id)) {
                since[id] = lengths[k].first_version;
            }
        }
    }
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        CHECK(since[id] != NULL && strcmp(f->since, since[id]) == 0, "%s: since \"%s\", the lengths say \"%s\"",
              f->name, f->since, since[id] ? since[id] : "(never)");
    }
}

static void test_bad_arguments(void)
{
    const vector *p = find_vector("v3_10_1116");
    urrt_state st;
    double d;
    uint64_t u;
    size_t used;
    uint8_t out[URRT_PACKET_MAX];

    CHECK_EQ_INT(urrt_decode(p->packet, p->length, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_decode(NULL, p->length, &st), URRT_E_ARG);
    CHECK(st.present == 0 && isnan(st.time[0]), "failed decode clears the state");
    CHECK_EQ_INT(urrt_decode(p->packet, 0, &st), URRT_E_TRUNCATED);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, URRT_F_TIME, 0, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, (urrt_field_id)URRT_FIELD_COUNT, 0, &d), URRT_E_ARG);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, (urrt_field_id)-1, 0, &d), URRT_E_ARG);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, URRT_F_TIME, 1, &d), URRT_E_RANGE);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, URRT_F_Q_ACTUAL, 6, &d), URRT_E_RANGE);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, URRT_F_Q_ACTUAL, 5, &d), URRT_OK);
    CHECK_EQ_INT(urrt_read(NULL, 0, URRT_F_TIME, 0, &d), URRT_E_ARG);
    CHECK_EQ_INT(urrt_read(p->packet, 3, URRT_F_TIME, 0, &d), URRT_E_TRUNCATED);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, URRT_F_PAYLOAD_MASS, 0, &d), URRT_E_ABSENT);
    CHECK_EQ_INT(urrt_read(p->packet, p->length, URRT_F_TOOL_VECTOR, 0, &d), URRT_E_ABSENT);
    CHECK_EQ_INT(urrt_read_column(p->packet, p->length, 1, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_read_column_bits(p->packet, p->length, 1, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_read_column_bits(p->packet, p->length, 140, &u), URRT_E_RANGE);
    CHECK_EQ_INT(urrt_read_column_bits(NULL, 0, 1, &u), URRT_E_ARG);

    urrt_state_clear(&st);
    CHECK_EQ_INT(urrt_encode(NULL, 1116, out, sizeof out), URRT_E_ARG);
    CHECK_EQ_INT(urrt_encode(&st, 1116, NULL, sizeof out), URRT_E_ARG);
    CHECK_EQ_INT(urrt_encode(&st, 1116, out, 1115), URRT_E_NO_SPACE);
    CHECK_EQ_INT(urrt_encode(&st, 0, out, sizeof out), URRT_E_SIZE_SMALL);
    CHECK_EQ_INT(urrt_encode(&st, 4, out, sizeof out), URRT_E_SIZE_SMALL);
    CHECK_EQ_INT(urrt_encode(&st, 1117, out, sizeof out), URRT_E_SIZE_ALIGN);
    CHECK_EQ_INT(urrt_encode(&st, URRT_PACKET_MAX + 8, out, sizeof out), URRT_E_SIZE_LARGE);
    CHECK_EQ_INT(urrt_encode(&st, URRT_PACKET_MAX, out, sizeof out), URRT_PACKET_MAX);
    CHECK_EQ_INT(urrt_encode(&st, 12, out, 12), 12);
    urrt_state_clear(NULL); /* must not crash */

    CHECK_EQ_INT(urrt_framer_feed(NULL, out, 1, &used), URRT_E_ARG);
    urrt_framer_init(&framer);
    CHECK_EQ_INT(urrt_framer_feed(&framer, out, 1, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_framer_feed(&framer, NULL, 1, &used), URRT_E_ARG);
    CHECK(urrt_framer_packet(NULL, NULL) == NULL, "packet of NULL");
    CHECK_EQ_INT(urrt_framer_finish(NULL), 0);
    urrt_framer_init(NULL);
    urrt_framer_reset(NULL);

    {
        static const int codes[] = {URRT_E_ARG, URRT_E_TRUNCATED, URRT_E_SIZE_SMALL, URRT_E_SIZE_ALIGN,
                                    URRT_E_SIZE_LARGE, URRT_E_ABSENT, URRT_E_RANGE, URRT_E_NOT_BITMASK,
                                    URRT_E_NO_SPACE, URRT_E_UNKNOWN_FIELD};
        for (size_t i = 0; i < sizeof codes / sizeof codes[0]; i++) {
            CHECK(codes[i] < 0, "error codes are negative");
            CHECK(strcmp(urrt_strerror(codes[i]), "ok") != 0 && strcmp(urrt_strerror(codes[i]), "unknown error") != 0,
                  "strerror(%d)", codes[i]);
            for (size_t j = 0; j < i; j++) {
                CHECK(codes[i] != codes[j] && strcmp(urrt_strerror(codes[i]), urrt_strerror(codes[j])) != 0,
                      "codes %d and %d alike", codes[i], codes[j]);
            }
        }
        CHECK_EQ_STR(urrt_strerror(0), "ok");
        CHECK_EQ_STR(urrt_strerror(1116), "ok");
        CHECK_EQ_STR(urrt_strerror(-99), "unknown error");
    }
}

static void test_state_clear_and_encoder(void)
{
    urrt_state st, back;
    static uint8_t out[URRT_PACKET_MAX];
    size_t bad = 0;
    urrt_state_clear(&st);
    CHECK(st.present == 0 && st.length == 0 && st.generation == URRT_GEN_UNKNOWN, "cleared state");
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        for (unsigned i = 0; i < urrt_field((urrt_field_id)id)->count; i++) {
            CHECK(isnan(state_slot(&st, id)[i]), "cleared %s[%u]", urrt_field((urrt_field_id)id)->name, i);
        }
    }
    /* A state set by hand, encoded at every length the library accepts. */
    for (int id = 0; id < URRT_FIELD_COUNT; id++) {
        for (unsigned i = 0; i < urrt_field((urrt_field_id)id)->count; i++) {
            state_slot(&st, id)[i] = double_of(test_rng());
        }
    }
    for (uint32_t len = URRT_PACKET_MIN; len <= URRT_PACKET_MAX; len += 8) {
        urrt_generation gen = urrt_generation_of(len);
        if (urrt_encode(&st, len, out, len) != (int)len || urrt_decode(out, len, &back) != (int)len) {
            bad++;
            continue;
        }
        for (int id = 0; id < URRT_FIELD_COUNT; id++) {
            const urrt_field_info *f = urrt_field((urrt_field_id)id);
            if (urrt_has(&back, id) && memcmp(state_slot(&st, id), state_slot(&back, id), 8u * f->count) != 0) {
                bad++;
            }
            /* A field this generation has and the packet holds whole is present. */
            unsigned col = urrt_field_column((urrt_field_id)id, gen);
            if (col && col + f->count - 1 <= (len - 4) / 8 && !(gen == URRT_GEN_1X && id == URRT_F_TOOL_ACCELEROMETER &&
                                                             (len - 4) / 8 < 95)) {
                bad += !urrt_has(&back, id);
            }
        }
    }
    CHECK(bad == 0, "encoder round trip failed %zu times", bad);
}

/* ---- regression tests: one per fixed bug ---------------------------------------- */

/* urrt_encode() called a length of 0x80000004 or more "below the minimum"
 * (URRT_E_SIZE_SMALL): it is past the largest packet. */
static void regression_encode_huge_length_is_large(void)
{
    static uint8_t out[16];
    urrt_state st;
    urrt_state_clear(&st);
    CHECK_EQ_INT(urrt_encode(&st, 0x80000004u, out, sizeof out), URRT_E_SIZE_LARGE);
    CHECK_EQ_INT(urrt_encode(&st, 0xFFFFFFFCu, out, sizeof out), URRT_E_SIZE_LARGE);
    CHECK_EQ_INT(urrt_encode(&st, 0xFFFFFFFFu, out, sizeof out), URRT_E_SIZE_ALIGN);
}

/* x86-64: the decode runs the vector width this build and CPU select (a
 * baseline build picks it at run time; URRT_TEST_VECTOR_BYTES is the width
 * a check-lib variant forced), and never one the CPU lacks. */
static void test_vector_width(void)
{
#if defined(__GNUC__) && defined(__x86_64__)
    unsigned w = urrt_x86_vector_bytes();
    printf("decode vector width: %u bytes\n", w);
    CHECK(w == 0 || w == 16 || w == 32 || w == 64, "vector width %u", w);
    CHECK(w < 16 || __builtin_cpu_supports("ssse3"), "16-byte path without SSSE3");
    CHECK(w < 32 || __builtin_cpu_supports("avx2"), "32-byte path without AVX2");
    CHECK(w < 64 || __builtin_cpu_supports("avx512bw"), "64-byte path without AVX-512BW");
#ifdef URRT_TEST_VECTOR_BYTES
    CHECK(w == URRT_TEST_VECTOR_BYTES, "vector width %u, forced %u", w, (unsigned)URRT_TEST_VECTOR_BYTES);
#endif
#endif
}

/* ---- controller versions and time ---------------------------------------- */

/* Every version of docs/sources.md's length table, with its size and rate
 * (125 Hz on CB2/CB3, 500 Hz on e-series), typed here from that page. */
static const struct {
    const char *version;
    uint32_t length;
    uint32_t period_us;
} version_facts[] = {
    {"1.5", 756, 8000},   {"1.7", 764, 8000},   {"1.8", 812, 8000},    {"3.0", 1044, 8000},
    {"3.1", 1044, 8000},  {"3.2", 1060, 8000},  {"3.4", 1060, 8000},   {"3.5", 1108, 8000},
    {"3.9", 1108, 8000},  {"5.0", 1108, 2000},  {"5.3", 1108, 2000},   {"3.10", 1116, 8000},
    {"3.13", 1116, 8000}, {"5.4", 1116, 2000},  {"5.8", 1116, 2000},   {"3.14", 1140, 8000},
    {"3.15", 1140, 8000}, {"5.9", 1140, 2000},  {"5.10", 1220, 2000},  {"5.25", 1220, 2000},
    {"3.15.4", 1140, 8000}, {"5.10.1.2", 1220, 2000}, {"5.300", 1220, 2000},
};

static void test_controller_versions(void)
{
    for (size_t i = 0; i < sizeof version_facts / sizeof version_facts[0]; i++) {
        const urrt_controller *found[2] = {NULL, NULL};
        uint32_t period = 0;
        const char *v = version_facts[i].version;
        int n = urrt_controller_find(v, strlen(v), found, 2, &period);
        CHECK(n == 1 && found[0] != NULL && found[0]->length == version_facts[i].length,
              "version %s: %d rows, length %u, expected %u", v, n, found[0] ? found[0]->length : 0,
              version_facts[i].length);
        CHECK(period == version_facts[i].period_us, "version %s: period %u us, expected %u", v, period,
              version_facts[i].period_us);
    }
    /* 1.6: the sources say 756 or 764; both are reported, in length order. */
    {
        const urrt_controller *found[2] = {NULL, NULL};
        uint32_t period = 0;
        CHECK_EQ_INT(urrt_controller_find("1.6", 3, found, 2, &period), 2);
        CHECK(found[0] && found[1] && found[0]->length == 756 && found[1]->length == 764, "1.6: 756 and 764");
        CHECK(period == 8000, "1.6: period %u", period);
        CHECK_EQ_INT(urrt_controller_find("1.6", 3, found, 1, NULL), 2); /* max 1: counts all, writes one */
    }
    /* Versions no row lists, and text that is no version. */
    static const char *unknown[] = {"1.4", "1.9", "2.0", "3.16", "4.0", "6.0", "10.0", "0.0"};
    for (size_t i = 0; i < sizeof unknown / sizeof unknown[0]; i++) {
        CHECK(urrt_controller_find(unknown[i], strlen(unknown[i]), NULL, 0, NULL) == 0, "%s: no row", unknown[i]);
    }
    static const char *malformed[] = {"", "5", "5.", ".5", "5.x", "5.10x", "x5.10", "5..10", "5.10.", "-5.1",
                                      " 5.10", "5.10 ", "5,10", "1.2.3.4.5", "1e3.1"};
    for (size_t i = 0; i < sizeof malformed / sizeof malformed[0]; i++) {
        CHECK(urrt_controller_find(malformed[i], strlen(malformed[i]), NULL, 0, NULL) == URRT_E_ARG,
              "\"%s\": not a version", malformed[i]);
    }
    CHECK_EQ_INT(urrt_controller_find(NULL, 0, NULL, 0, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_controller_find("5.10 and more", 4, NULL, 0, NULL), 1); /* len bounds the text */

    /* Periods by length: of the versions that send it, else of its generation. */
    static const struct { uint32_t length, period_us; } periods[] = {
        {756, 8000}, {812, 8000}, {1044, 8000}, {1060, 8000}, {1108, 2000}, {1220, 2000},
        {540, 8000}, {692, 8000}, {716, 8000} /* an unknown 1.x size */, {1228, 2000}, {900, 2000}, {0, 2000},
    };
    for (size_t i = 0; i < sizeof periods / sizeof periods[0]; i++) {
        CHECK(urrt_period_min_us(periods[i].length) == periods[i].period_us, "period of %u: %u, expected %u",
              periods[i].length, urrt_period_min_us(periods[i].length), periods[i].period_us);
    }

    /* The table: increasing lengths, each row's text naming its ranges, each
     * row the one its length finds. */
    size_t count = 0;
    const urrt_controller *rows = urrt_controllers(&count);
    CHECK(rows != NULL && count == 11, "%zu rows", count);
    for (size_t i = 0; rows != NULL && i < count; i++) {
        char text[64] = "";
        CHECK(i == 0 || rows[i].length > rows[i - 1].length, "row %zu: lengths increase", i);
        CHECK(urrt_controller_of_length(rows[i].length) == &rows[i], "row %zu: found by its length", i);
        for (size_t j = 0; j < 2 && rows[i].ranges[j].major != 0; j++) {
            const urrt_version_range *r = &rows[i].ranges[j];
            size_t n = strlen(text);
            if (r->minor_last == URRT_MINOR_LATER) {
                snprintf(text + n, sizeof text - n, "%s%u.%u or later", j ? ", " : "", r->major, r->minor_first);
            } else if (r->minor_first == r->minor_last) {
                snprintf(text + n, sizeof text - n, "%s%u.%u", j ? ", " : "", r->major, r->minor_first);
            } else {
                snprintf(text + n, sizeof text - n, "%s%u.%u-%u.%u", j ? ", " : "", r->major, r->minor_first,
                         r->major, r->minor_last);
            }
        }
        if (rows[i].ranges[0].major == 0) {
            CHECK_EQ_STR(rows[i].versions, "early 1.x (before 1.5)");
        } else {
            CHECK(strcmp(rows[i].versions, text) == 0, "row %u: text \"%s\", ranges say \"%s\"", rows[i].length,
                  rows[i].versions, text);
        }
    }
    CHECK(urrt_controller_of_length(1116) != NULL && urrt_controller_of_length(1117) == NULL, "of_length");
    CHECK(urrt_controllers(NULL) == rows, "count may be NULL");
}

static void test_time_us(void)
{
    static const struct { double seconds; int64_t us; } cases[] = {
        {0.0, 0}, {-0.0, 0}, {1.0, 1000000}, {951.592, 951592000}, {951.6, 951600000},
        {0.0078125, 7813} /* 1/128 s: 7812.5 us exactly, a half rounds away from zero */,
        {0.0000005, 0} /* the double is 4.99999999999999977e-07 */, {0.00000051, 1}, {0.0000015, 2},
        {1e-300, 0}, {4.9e-324, 0} /* the smallest subnormal */, {0.001, 1000}, {0.008, 8000},
        {123456.789012, 123456789012}, {4.0 - 1e-15, 4000000}, {1.0e9, 1000000000000000},
        {9007199254.740992, INT64_C(9007199254740992)} /* 2^53 us: the maximum */,
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int64_t us = -1;
        CHECK(urrt_time_us(cases[i].seconds, &us) == URRT_OK && us == cases[i].us,
              "time %.17g s: %" PRId64 " us, expected %" PRId64, cases[i].seconds, us, cases[i].us);
    }
    /* Every 997th packet of a day at 125 Hz, against rounding in long double. */
    for (int64_t k = 0; k < 86400 * 125; k += 997) {
        double t = (double)k * 0.008 + 0.0000004;
        int64_t us = -1;
        int64_t expect = (int64_t)llroundl((long double)t * 1000000.0L);
        CHECK(urrt_time_us(t, &us) == URRT_OK && us == expect, "time %.17g: %" PRId64 ", expected %" PRId64, t,
              us, expect);
    }
    /* Out of range: saturated, and said so. */
    static const struct { double seconds; int64_t us; } saturated[] = {
        {9007199254.7409935, URRT_TIME_US_MAX} /* the next double: just past 2^53 us */, {1e10, URRT_TIME_US_MAX},
        {17179869184.0, URRT_TIME_US_MAX} /* 2^34 s */, {1e300, URRT_TIME_US_MAX}, {INFINITY, URRT_TIME_US_MAX},
        {-1e-300, 0}, {-0.5, 0}, {-1.0, 0}, {-INFINITY, 0}, {NAN, 0}, {-NAN, 0},
    };
    for (size_t i = 0; i < sizeof saturated / sizeof saturated[0]; i++) {
        int64_t us = 42;
        CHECK(urrt_time_us(saturated[i].seconds, &us) == URRT_E_RANGE && us == saturated[i].us,
              "time %g: %" PRId64 ", expected URRT_E_RANGE and %" PRId64, saturated[i].seconds, us,
              saturated[i].us);
    }
    CHECK(URRT_TIME_US_MAX == INT64_C(9007199254740992), "URRT_TIME_US_MAX is 2^53");
    CHECK_EQ_INT(urrt_time_us(double_of(UINT64_C(0x7FF0000000000001)), &(int64_t){0}), URRT_E_RANGE);
    CHECK_EQ_INT(urrt_time_us(1.0, NULL), URRT_E_ARG);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s VECTORS (written by tests/ref/urrt_ref.py)\n", argv[0]);
        return 2;
    }
    load_vectors(argv[1]);
    test_vector_width();
    test_field_metadata();
    test_field_lookup();
    test_field_since_follows_lengths();
    test_nan_inf_bit_exact();
    test_bitmask();
    test_enums();
    test_bad_arguments();
    test_controller_versions();
    test_time_us();
    test_state_clear_and_encoder();
    test_bad_sizes();
    test_real_capture();
    test_framer_zero_length_feeds();
    test_framer_split_equivalence();
    test_framer_garbage();
    test_framer_resync_not_fooled();
    test_framer_truncation();
    regression_encode_huge_length_is_large();
    for (size_t i = 0; i < vector_count; i++) {
        free(vectors[i].packet);
    }
    return check_report();
}
