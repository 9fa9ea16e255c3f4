/* SPDX-License-Identifier: MIT */
/*
 * lib/urrt.c with the decode's vector paths: the 3.x/5.x grid copied by x86
 * SSSE3, AVX2 or AVX-512BW shuffles (chosen by the CPU at each decode) or by
 * ARM NEON. Optional: a firmware compiles lib/urrt.c and leaves this file
 * out; a host build compiles this file in place of lib/urrt.c (lib/lib.mk).
 * It includes lib/urrt.c rather than linking beside it, so the vector paths
 * use its layout and its one-double-at-a-time fallback without a symbol of
 * their own, and urrt_decode still reaches them by a tail jump. Where the
 * target has no vector path (big-endian, no byte shuffle, no GNU C) it
 * decodes as lib/urrt.c alone does.
 */
#define URRT_VECTOR_PATHS 1 /* lib/urrt.c leaves decode_3x to this file */
#include "../urrt.c"

/* decode_by_table (lib/urrt.c's loop over the table) written out field by
 * field: each field's column, count and place are constants, the
 * generation a select, and each field's doubles are stored once, from the
 * packet or as NaN. The loop, which a firmware keeps for its size, took
 * three times as long. decode_by_table, at the end of this file, takes the
 * 1.x lengths of real controllers by vectors instead. */
static void decode_fields(const uint8_t *body, unsigned doubles, urrt_generation gen, urrt_state *st)
{
    uint64_t present = 0;
#define URRT_X_DECODE_FIELD(ID, name, count, c1, c3, unit, since, desc)                   \
    {                                                                                     \
        unsigned column = gen == URRT_GEN_1X ? (c1) : (c1) == (c3) ? (c1) : 0u;           \
        if (field_fits((unsigned)URRT_F_##ID, column, doubles, gen)) {                     \
            load_doubles(st->name, body + 8u * (column - 1u), count);                     \
            present |= UINT64_C(1) << URRT_F_##ID;                                        \
        } else {                                                                          \
            fill_nan(st->name, count);                                                    \
        }                                                                                 \
    }
    URRT_FIELDS(URRT_X_DECODE_FIELD)
#undef URRT_X_DECODE_FIELD
    st->present = present;
}

/*
 * Vector byte swap for the grid copy, where the compiler offers portable
 * vector extensions (GCC, clang) and the target has a byte shuffle: x86
 * SSSE3 (-march=x86-64-v2), AVX2 (-march=x86-64-v3), AVX-512BW
 * (-march=x86-64-v4), ARM NEON; -march=native picks the widest. The decode
 * is bound by stores, so the widest vector wins. Elsewhere the copy is one
 * 8-byte load and swap per double. Little-endian hosts only: on a
 * big-endian one (armeb, aarch64_be also have NEON) the swap would reverse
 * bytes that are already in the host's order.
 *
 * x86-64 built without SSSE3 (a distribution's baseline -O2 build) carries
 * all three widths as functions compiled for their instruction sets and
 * picks the widest the CPU has at each decode (URRT_CPU_DISPATCH), from
 * libgcc's CPU model (__builtin_cpu_supports: a load and a bit test; libgcc
 * fills it in a constructor that runs before any other). Define
 * URRT_NO_CPU_DISPATCH to keep such a build to one double at a time, or
 * URRT_X86_MAX_VECTOR_BYTES (0, 16, 32, 64) to cap the choice (the tests
 * run every width that way).
 */
#if defined(URRT_LOAD_UNALIGNED) && (defined(__SSSE3__) || defined(__ARM_NEON))
#define URRT_VECTOR 1
#if defined(__AVX512BW__)
#define URRT_VECTOR_BYTES 64
#elif defined(__AVX2__)
#define URRT_VECTOR_BYTES 32
#else
#define URRT_VECTOR_BYTES 16
#endif
#elif defined(URRT_LOAD_UNALIGNED) && defined(__x86_64__) && !defined(URRT_NO_CPU_DISPATCH)
#define URRT_CPU_DISPATCH 1
#ifndef URRT_X86_MAX_VECTOR_BYTES
#define URRT_X86_MAX_VECTOR_BYTES 64
#endif
#endif

#if defined(URRT_VECTOR) || defined(URRT_CPU_DISPATCH)
/* The vector paths write the struct's last 48 bytes as {NaN, NaN, NaN,
 * present} and, where the counts are laid out so (not where enums are
 * short, as arm-none-eabi has them), {length | doubles << 32 |
 * extra_columns << 48, generation} (little-endian hosts only, as above). */
#define URRT_FILL_END (URRT_GRID_DOUBLES - 3u)
URRT_STATIC_ASSERT(present_follows_the_grid, offsetof(urrt_state, present) == URRT_GRID_DOUBLES * sizeof(double));
#define URRT_COUNTS_PACKED                                                                          \
    (offsetof(urrt_state, length) == offsetof(urrt_state, present) + 8 &&                           \
     offsetof(urrt_state, doubles) == offsetof(urrt_state, length) + 4 &&                           \
     offsetof(urrt_state, extra_columns) == offsetof(urrt_state, length) + 6 &&                     \
     offsetof(urrt_state, generation) == offsetof(urrt_state, length) + 8 &&                        \
     sizeof(urrt_generation) == 4 && sizeof(urrt_state) >= offsetof(urrt_state, generation) + 8)
/* The fill before the tail holds at least one 64-byte vector. */
URRT_STATIC_ASSERT(fill_holds_a_vector, URRT_FILL_END >= URRT_WIRE_COLUMNS + 8u);

/* The columns before the first absent field (grid_shape.copied), as the
 * vector paths take them: the last field end by column `known` (columns
 * are dense and one field ends at URRT_3X_MIN_DOUBLES, asserted in urrt.c),
 * a CLZ instead of grid_shape_of's table load, which waits for the bit
 * count (Cortex-M0, which urrt.c also serves, has no CLZ). */
#define URRT_COPIED_BY_CLZ(known) \
    (URRT_3X_MIN_DOUBLES + 31u - (unsigned)__builtin_clz(grid_tail_ends_by(known) | 1u))

#define URRT_SWAP_INDEX_16 7, 6, 5, 4, 3, 2, 1, 0, 15, 14, 13, 12, 11, 10, 9, 8
#define URRT_SWAP_INDEX_32 URRT_SWAP_INDEX_16, 23, 22, 21, 20, 19, 18, 17, 16, 31, 30, 29, 28, 27, 26, 25, 24
#define URRT_SWAP_INDEX_64 URRT_SWAP_INDEX_32, 39, 38, 37, 36, 35, 34, 33, 32, 47, 46, 45, 44, 43, 42, 41, 40, \
                           55, 54, 53, 52, 51, 50, 49, 48, 63, 62, 61, 60, 59, 58, 57, 56
#define URRT_NAN_16 URRT_NAN_BITS, URRT_NAN_BITS
#define URRT_NAN_32 URRT_NAN_16, URRT_NAN_16
#define URRT_NAN_64 URRT_NAN_32, URRT_NAN_32
#define URRT_LANES_16 0, 1
#define URRT_LANES_32 0, 1, 2, 3
#define URRT_LANES_64 0, 1, 2, 3, 4, 5, 6, 7
#if defined(__clang__)
#define URRT_SHUFFLE(v, type, ...) __builtin_shufflevector((v), (v), __VA_ARGS__)
#else
#define URRT_SHUFFLE(v, type, ...) __builtin_shuffle((v), (type){__VA_ARGS__})
#endif
#define URRT_PASTE2(a, b) a##b
#define URRT_PASTE(a, b) URRT_PASTE2(a, b)

/* The grid part of a decode: the packet's columns 1..n (n >= per) to the
 * struct's, then NaN to FILL_END, in vectors of BYTES bytes aligned but
 * for the first and the last (see below). Uses the caller's src, dst, n,
 * per, nan, bytes_v and i, the first aligned index; the arguments after
 * FILL_END store `a` where the copy meets the NaN (BOUNDARY below). */
#define URRT_GRID_FILL(BYTES, FILL_END, ...)                                                       \
    bytes_v a, b;                                                                                  \
    __builtin_memcpy(&a, src, sizeof a);                                                           \
    a = URRT_SHUFFLE(a, bytes_v, URRT_SWAP_INDEX_##BYTES);                                         \
    __builtin_memcpy(dst, &a, sizeof a);                                                           \
    for (; i + 2u * per <= n; i += 2u * per) {                                                     \
        __builtin_memcpy(&a, src + 8u * i, sizeof a);                                              \
        __builtin_memcpy(&b, src + 8u * i + BYTES, sizeof b);                                      \
        a = URRT_SHUFFLE(a, bytes_v, URRT_SWAP_INDEX_##BYTES);                                     \
        b = URRT_SHUFFLE(b, bytes_v, URRT_SWAP_INDEX_##BYTES);                                     \
        __builtin_memcpy(&dst[i], &a, sizeof a);                                                   \
        __builtin_memcpy(&dst[i + per], &b, sizeof b);                                             \
    }                                                                                              \
    if (i + per <= n) {                                                                            \
        __builtin_memcpy(&a, src + 8u * i, sizeof a);                                              \
        a = URRT_SHUFFLE(a, bytes_v, URRT_SWAP_INDEX_##BYTES);                                     \
        __builtin_memcpy(&dst[i], &a, sizeof a);                                                   \
        i += per;                                                                                  \
    }                                                                                              \
    if (i < n) {                                                                                   \
        /* the last `per` doubles, the first n - i of them wanted at dst[i] */                     \
        __builtin_memcpy(&a, src + 8u * (n - per), sizeof a);                                      \
        a = URRT_SHUFFLE(a, bytes_v, URRT_SWAP_INDEX_##BYTES);                                     \
        __VA_ARGS__                                                                                \
        i += per;                                                                                  \
    }                                                                                              \
    for (; i + per <= FILL_END; i += per) {                                                        \
        __builtin_memcpy(&dst[i], &nan, sizeof nan);                                               \
    }                                                                                              \
    if (i < FILL_END) {                                                                            \
        __builtin_memcpy(&dst[FILL_END - per], &nan, sizeof nan);                                  \
    }

/* Every length of a 3.x/5.x packet up to the newest layout, in doubles: the
 * decode is written out for each (URRT_DECODE_3X_CASE), the grid's shape
 * and the loops' ends then constants (working them out at each decode,
 * by a bit count and a CLZ, cost a tenth of it); longer packets, with
 * columns past the newest layout, take the general one. */
#define URRT_GRID_LENGTHS(X, A)                                                                    \
    X(A, 130) X(A, 131) X(A, 132) X(A, 133) X(A, 134) X(A, 135) X(A, 136) X(A, 137) X(A, 138)       \
    X(A, 139) X(A, 140) X(A, 141) X(A, 142) X(A, 143) X(A, 144) X(A, 145) X(A, 146) X(A, 147)       \
    X(A, 148) X(A, 149) X(A, 150) X(A, 151) X(A, 152)
#define URRT_X_LENGTH_COUNT(unused, d) +1
#define URRT_X_LENGTH_SUM(unused, d) +(d)
URRT_STATIC_ASSERT(grid_lengths_are_every_one,
                   0 URRT_GRID_LENGTHS(URRT_X_LENGTH_COUNT, ~) == URRT_WIRE_COLUMNS - URRT_3X_MIN_DOUBLES + 1 &&
                       0 URRT_GRID_LENGTHS(URRT_X_LENGTH_SUM, ~) ==
                           (URRT_WIRE_COLUMNS + URRT_3X_MIN_DOUBLES) * (URRT_WIRE_COLUMNS - URRT_3X_MIN_DOUBLES + 1) / 2);
#define URRT_DECODE_3X_CASE(NAME, d) \
    case URRT_HEADER_SIZE + 8u * (d): return NAME##_any(buf, URRT_HEADER_SIZE + 8u * (d), st);

/*
 * decode_3x at one width. The stores are aligned to the vector size except
 * the first and, where the caller's struct is not aligned, the last of the
 * fill: misaligned stores cost two (and where the struct crossed a 4 KiB
 * boundary, all-unaligned stores made the decode half again as slow). The
 * vector where the copy meets the NaN is one store (BOUNDARY, where the
 * compiler has a two-vector shuffle by a variable index) or two overlapping
 * ones. Loads come two vectors at a time ahead of their stores (one at a
 * time cost 1060 bytes a tenth more). NaN is a constant vector (built lane
 * by lane it went through the stack, and realigning the stack for it cost
 * a prologue). No stack, no call: a push is a store too.
 */
#define URRT_DECODE_3X_FUNC(NAME, BYTES, ATTR, BOUNDARY)                                           \
    static inline __attribute__((always_inline)) ATTR int NAME##_any(const uint8_t *buf, unsigned size, \
                                                                      urrt_state *st)             \
    {                                                                                              \
        typedef unsigned char bytes_v __attribute__((vector_size(BYTES)));                         \
        typedef uint64_t u64_v __attribute__((vector_size(BYTES)));                                \
        typedef uint64_t u64x4 __attribute__((vector_size(32)));                                   \
        typedef uint64_t u64x2 __attribute__((vector_size(16)));                                   \
        const unsigned per = BYTES / 8u;                                                           \
        const u64_v nan = {URRT_NAN_##BYTES};                                                      \
        const uint8_t *src = buf + URRT_HEADER_SIZE;                                               \
        double *dst = grid_slot(st, 1);                                                            \
        unsigned doubles = (size - URRT_HEADER_SIZE) / 8u;                                         \
        grid_shape g = grid_shape_of(doubles);                                                     \
        unsigned n = URRT_COPIED_BY_CLZ(g.known);                                                  \
        unsigned i = (unsigned)(BYTES - ((uintptr_t)(void *)dst & (BYTES - 1u))) / 8u;             \
        /* the struct's last 48 bytes, worked out first: fewer live registers */                   \
        const u64x4 last = {URRT_NAN_BITS, URRT_NAN_BITS, URRT_NAN_BITS, present_mask(g.fields)};  \
        const u64x2 counts = {size | (uint64_t)doubles << 32 | (uint64_t)(doubles - g.known) << 48, \
                              (uint64_t)URRT_GEN_3X};                                              \
        URRT_GRID_FILL(BYTES, URRT_FILL_END, BOUNDARY)                                             \
        __builtin_memcpy(&dst[URRT_FILL_END], &last, sizeof last);                                 \
        if (URRT_COUNTS_PACKED) {                                                                  \
            __builtin_memcpy(&dst[URRT_GRID_DOUBLES + 1u], &counts, sizeof counts);                \
        } else {                                                                                   \
            st->length = size;                                                                     \
            st->doubles = (uint16_t)doubles;                                                       \
            st->extra_columns = (uint16_t)(doubles - g.known);                                     \
            st->generation = URRT_GEN_3X;                                                          \
        }                                                                                          \
        return (int)size;                                                                          \
    }                                                                                              \
    static __attribute__((noinline)) ATTR int NAME(const uint8_t *buf, unsigned size, urrt_state *st) \
    {                                                                                              \
        switch (size) {                                                                            \
            URRT_GRID_LENGTHS(URRT_DECODE_3X_CASE, NAME)                                           \
        default: return NAME##_any(buf, size, st);                                                 \
        }                                                                                          \
    }

/* BOUNDARY as two overlapping stores, and as one: lane j of the store at
 * dst[i] takes lane j + per - (n - i) of `a`, which for j >= n - i is past
 * `a`'s last and so picks lane j - (n - i) of `nan` (GCC: VPERMT2Q). */
#define URRT_BOUNDARY_OVERLAP                                                                      \
    __builtin_memcpy(&dst[n - per], &a, sizeof a);                                                 \
    __builtin_memcpy(&dst[n], &nan, sizeof nan);
#define URRT_BOUNDARY_BLEND(BYTES)                                                                 \
    {                                                                                              \
        const u64_v lanes = {URRT_LANES_##BYTES};                                                  \
        u64_v q = __builtin_shuffle((u64_v)a, nan, lanes + (uint64_t)(per - (n - i)));             \
        __builtin_memcpy(&dst[i], &q, sizeof q);                                                   \
    }
#if defined(__clang__)
#define URRT_BOUNDARY_64 URRT_BOUNDARY_OVERLAP
#else
#define URRT_BOUNDARY_64 URRT_BOUNDARY_BLEND(64)
#endif
#define URRT_BOUNDARY_32 URRT_BOUNDARY_OVERLAP
#define URRT_BOUNDARY_16 URRT_BOUNDARY_OVERLAP

/*
 * The 1.x layout against the grid, for decode_1x below (each point asserted
 * from the field table): the packet's columns 1-101 are the grid's columns
 * 1-101 but for two gaps, grid columns 50-67 and 74-85, which hold 3.x
 * fields (NaN in a 1.x packet); the 1.x columns there move: 50-52 (the
 * accelerometer) to the grid's 109-111, 53-67 and 74-85 to the 1.x-only
 * fields after the grid, back to back. Indices count doubles from 0.
 */
enum {
#define URRT_X_COL_1X(ID, name, count, c1, c3, unit, since, desc) URRT_COL_1X_##ID = c1,
    URRT_FIELDS(URRT_X_COL_1X)
#undef URRT_X_COL_1X
    URRT_COL_1X_END
};
#define URRT_AT(name) (unsigned)(offsetof(urrt_state, name) / sizeof(double))
#define URRT_DOUBLES_OF(name) (unsigned)(sizeof(((urrt_state *)0)->name) / sizeof(double))
#define URRT_1X_GAP_A URRT_AT(i_control)          /* to tcp_force */
#define URRT_1X_GAP_B URRT_AT(tool_vector_target) /* to digital_input_bits */
#define URRT_1X_GAP_A_DOUBLES (URRT_AT(tcp_force) - URRT_1X_GAP_A)
#define URRT_1X_GAP_B_DOUBLES (URRT_AT(digital_input_bits) - URRT_1X_GAP_B)
#define URRT_1X_ACCEL_FROM (URRT_COL_1X_TOOL_ACCELEROMETER - 1u)
#define URRT_1X_UNUSED_FROM (URRT_COL_1X_UNUSED_53 - 1u) /* to unused_53 */
#define URRT_1X_TOOL_FROM (URRT_COL_1X_TOOL_VECTOR - 1u)  /* to tool_vector, then tcp_speed */
#define URRT_1X_TOOL_DOUBLES (URRT_DOUBLES_OF(tool_vector) + URRT_DOUBLES_OF(tcp_speed))
/* What decode_1x relies on, field by field: a field with the same column
 * in both layouts (copied with the grid) is in no gap; any other field
 * with a 1.x column is one of those that move and has it in a gap (its
 * bytes copied there are overwritten); a 3.x field within 1.x's columns is
 * in a gap. */
#define URRT_IN_GAP(c, count, gap, gap_doubles) ((c) - 1u >= (gap) && (c) - 1u + (count) <= (gap) + (gap_doubles))
#define URRT_IN_GAPS(c, count)                                                                     \
    ((c) != 0 && (URRT_IN_GAP(c, count, URRT_1X_GAP_A, URRT_1X_GAP_A_DOUBLES) ||                    \
                  URRT_IN_GAP(c, count, URRT_1X_GAP_B, URRT_1X_GAP_B_DOUBLES)))
#define URRT_MOVES_IN_1X(ID)                                                                       \
    (URRT_F_##ID == URRT_F_TOOL_ACCELEROMETER || URRT_F_##ID == URRT_F_UNUSED_53 ||                 \
     URRT_F_##ID == URRT_F_TOOL_VECTOR || URRT_F_##ID == URRT_F_TCP_SPEED)
#define URRT_X_1X_GAPS(ID, name, count, c1, c3, unit, since, desc)                                  \
    URRT_STATIC_ASSERT(one_x_##name, (c1) == (c3) ? (c3) != 0 && !URRT_IN_GAPS(c3, count)           \
                                                  : ((c1) == 0 || (URRT_IN_GAPS(c1, count) && URRT_MOVES_IN_1X(ID))) && \
                                                        ((c3) == 0 || (c3) > URRT_1X_MAX_DOUBLES || URRT_IN_GAPS(c3, count)));
URRT_FIELDS(URRT_X_1X_GAPS)
#undef URRT_X_1X_GAPS
/* The fields that move: the accelerometer past the copied columns, the
 * rest as two runs of the packet into the 1.x-only fields (back to back,
 * asserted in lib/urrt.c); tool_vector and tcp_speed are as long, so a
 * packet holds both, the first or neither. Each run and gap holds a
 * 64-byte vector (URRT_SPAN_*). */
URRT_STATIC_ASSERT(one_x_moves,
                   URRT_AT(tool_accelerometer) >= URRT_1X_MAX_DOUBLES &&
                       URRT_COL_1X_UNUSED_53 + URRT_DOUBLES_OF(unused_53) == URRT_COL_1X_TCP_FORCE &&
                       URRT_COL_1X_TOOL_VECTOR == URRT_COL_1X_TCP_FORCE + URRT_DOUBLES_OF(tcp_force) &&
                       URRT_COL_1X_TCP_SPEED == URRT_COL_1X_TOOL_VECTOR + URRT_DOUBLES_OF(tool_vector) &&
                       URRT_DOUBLES_OF(tool_vector) == URRT_DOUBLES_OF(tcp_speed));
URRT_STATIC_ASSERT(one_x_spans_hold_a_vector,
                   URRT_1X_GAP_A_DOUBLES >= 8 && URRT_1X_GAP_B_DOUBLES >= 8 && URRT_1X_TOOL_DOUBLES >= 8 &&
                       URRT_DOUBLES_OF(unused_53) >= 8 && URRT_DOUBLES_OF(tool_accelerometer) >= 2 &&
                       URRT_DOUBLES_OF(tool_vector) >= 2);

/* The doubles d..d+k-1 of the struct (k constant, at least VB / 8), as the
 * packet's from s on or as NaN, in vectors of VB bytes, the last one
 * ending at d + k (overlapping the one before it). */
#define URRT_SPAN_COPY(VB, d, s, k)                                                                \
    do {                                                                                           \
        typedef unsigned char span_v __attribute__((vector_size(VB)));                             \
        unsigned j_;                                                                               \
        span_v x_;                                                                                 \
        for (j_ = 0; j_ < (k); j_ += VB / 8u) {                                                    \
            unsigned at_ = j_ + VB / 8u <= (k) ? j_ : (k) - VB / 8u;                               \
            __builtin_memcpy(&x_, src + 8u * ((s) + at_), sizeof x_);                              \
            x_ = URRT_SHUFFLE(x_, span_v, URRT_SWAP_INDEX_##VB);                                   \
            __builtin_memcpy(&dst[(d) + at_], &x_, sizeof x_);                                     \
        }                                                                                          \
    } while (0)
#define URRT_SPAN_NAN(VB, d, k)                                                                    \
    do {                                                                                           \
        typedef uint64_t span_v __attribute__((vector_size(VB)));                                  \
        const span_v nan_ = {URRT_NAN_##VB};                                                       \
        unsigned j_;                                                                               \
        for (j_ = 0; j_ < (k); j_ += VB / 8u) {                                                    \
            __builtin_memcpy(&dst[(d) + (j_ + VB / 8u <= (k) ? j_ : (k) - VB / 8u)], &nan_, sizeof nan_); \
        }                                                                                          \
    } while (0)

/*
 * A 1.x packet whose last whole field ends at column n (n >= 67: the
 * shortest length real controllers sent, and unused_53 whole) at one
 * width: the grid's columns 1..n as decode_3x copies them and NaN to the
 * grid's end, then NaN over the gaps, the moved fields in their places and
 * the 1.x-only fields (their 12 doubles after unused_53, whole, half or
 * none). Leaves present and the counts to the caller. Each step stores
 * only where it must: the gaps and the accelerometer are the only doubles
 * stored twice.
 */
#define URRT_DECODE_1X_FUNC(NAME, BYTES, ATTR, BOUNDARY)                                           \
    static ATTR void NAME(const uint8_t *src, unsigned n, urrt_state *st)                          \
    {                                                                                              \
        typedef unsigned char bytes_v __attribute__((vector_size(BYTES)));                         \
        typedef uint64_t u64_v __attribute__((vector_size(BYTES)));                                \
        const unsigned per = BYTES / 8u;                                                           \
        const u64_v nan = {URRT_NAN_##BYTES};                                                      \
        double *dst = grid_slot(st, 1);                                                            \
        unsigned i = (unsigned)(BYTES - ((uintptr_t)(void *)dst & (BYTES - 1u))) / 8u;             \
        URRT_GRID_FILL(BYTES, URRT_WIRE_COLUMNS, BOUNDARY)                                         \
        URRT_SPAN_NAN(BYTES, URRT_1X_GAP_A, URRT_1X_GAP_A_DOUBLES);                                \
        if (n > URRT_1X_GAP_B) {                                                                   \
            URRT_SPAN_NAN(BYTES, URRT_1X_GAP_B, URRT_1X_GAP_B_DOUBLES);                            \
        }                                                                                          \
        if (n >= URRT_1X_ACCELEROMETER_MIN_DOUBLES) {                                              \
            URRT_SPAN_COPY(16, URRT_AT(tool_accelerometer), URRT_1X_ACCEL_FROM,                    \
                           URRT_DOUBLES_OF(tool_accelerometer));                                   \
        }                                                                                          \
        if (n >= URRT_1X_TOOL_FROM + URRT_1X_TOOL_DOUBLES) {                                       \
            URRT_SPAN_COPY(BYTES, URRT_AT(tool_vector), URRT_1X_TOOL_FROM, URRT_1X_TOOL_DOUBLES);  \
        } else if (n >= URRT_1X_TOOL_FROM + URRT_DOUBLES_OF(tool_vector)) {                        \
            URRT_SPAN_COPY(16, URRT_AT(tool_vector), URRT_1X_TOOL_FROM, URRT_DOUBLES_OF(tool_vector)); \
            URRT_SPAN_NAN(16, URRT_AT(tcp_speed), URRT_DOUBLES_OF(tcp_speed));                     \
        } else {                                                                                   \
            URRT_SPAN_NAN(BYTES, URRT_AT(tool_vector), URRT_1X_TOOL_DOUBLES);                      \
        }                                                                                          \
        URRT_SPAN_COPY(BYTES, URRT_AT(unused_53), URRT_1X_UNUSED_FROM, URRT_DOUBLES_OF(unused_53)); \
    }
#endif

#ifdef URRT_VECTOR
/* Not inlined either (URRT_DECODE_3X_FUNC): inside urrt_decode it cost four pushes. */
#define URRT_DECODE_3X_AT(BYTES) URRT_DECODE_3X_FUNC(decode_3x_vector, BYTES, , URRT_PASTE(URRT_BOUNDARY_, BYTES))
URRT_DECODE_3X_AT(URRT_VECTOR_BYTES)
#define URRT_DECODE_1X_AT(BYTES) URRT_DECODE_1X_FUNC(decode_1x_vector, BYTES, , URRT_PASTE(URRT_BOUNDARY_, BYTES))
URRT_DECODE_1X_AT(URRT_VECTOR_BYTES)
#endif

#ifdef URRT_CPU_DISPATCH
#if URRT_X86_MAX_VECTOR_BYTES >= 16
URRT_DECODE_3X_FUNC(decode_3x_16, 16, __attribute__((target("ssse3"))), URRT_BOUNDARY_16)
URRT_DECODE_1X_FUNC(decode_1x_16, 16, __attribute__((target("ssse3"))), URRT_BOUNDARY_16)
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 32
URRT_DECODE_3X_FUNC(decode_3x_32, 32, __attribute__((target("avx2"))), URRT_BOUNDARY_32)
URRT_DECODE_1X_FUNC(decode_1x_32, 32, __attribute__((target("avx2"))), URRT_BOUNDARY_32)
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 64
URRT_DECODE_3X_FUNC(decode_3x_64, 64, __attribute__((target("avx512bw"))), URRT_BOUNDARY_64)
URRT_DECODE_1X_FUNC(decode_1x_64, 64, __attribute__((target("avx512bw"))), URRT_BOUNDARY_64)
#endif

static unsigned cpu_vector_bytes(void)
{
#if URRT_X86_MAX_VECTOR_BYTES >= 64
    if (__builtin_cpu_supports("avx512bw")) {
        return 64;
    }
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 32
    if (__builtin_cpu_supports("avx2")) {
        return 32;
    }
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 16
    if (__builtin_cpu_supports("ssse3")) {
        return 16;
    }
#endif
    return 0;
}
#endif

#if defined(__x86_64__)
unsigned urrt_x86_vector_bytes(void)
{
#if defined(URRT_CPU_DISPATCH)
    return cpu_vector_bytes();
#elif defined(URRT_VECTOR)
    return URRT_VECTOR_BYTES;
#else
    return 0;
#endif
}
#endif

/* The hot path (e-series at 500 Hz): one pass over the grid, by the widest
 * vectors this build or CPU has, reached by a tail jump (the width tests
 * and the switch fold into one chain of branches). */
static int decode_3x(const uint8_t *buf, unsigned size, urrt_state *st)
{
#if defined(URRT_VECTOR)
    (void)decode_3x_scalar; /* the width is fixed at compile time: no fallback */
    return decode_3x_vector(buf, size, st);
#elif defined(URRT_CPU_DISPATCH)
    switch (cpu_vector_bytes()) {
#if URRT_X86_MAX_VECTOR_BYTES >= 64
    case 64: return decode_3x_64(buf, size, st);
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 32
    case 32: return decode_3x_32(buf, size, st);
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 16
    case 16: return decode_3x_16(buf, size, st);
#endif
    default: return decode_3x_scalar(buf, size, st);
    }
#else
    return decode_3x_scalar(buf, size, st);
#endif
}

#if defined(URRT_VECTOR) || (defined(URRT_CPU_DISPATCH) && URRT_X86_MAX_VECTOR_BYTES >= 16)
#define URRT_DECODE_1X_VECTOR 1
/* The end of the last whole field of a 1.x packet of `doubles` doubles (at
 * least 67): 1.x's columns are dense (each in one field), a field ends at
 * 67 and none past 101. */
static unsigned one_x_copied(unsigned doubles)
{
    static const uint64_t ends_past_64 = 0u
#define URRT_X_END_PAST_64(ID, name, count, c1, c3, unit, since, desc) \
    | ((c1) != 0 && (c1) + (count) - 1 > 64 ? UINT64_C(1) << (((c1) + (count) - 1 - 65) & 63) : 0u)
        URRT_FIELDS(URRT_X_END_PAST_64)
#undef URRT_X_END_PAST_64
        ;
    return 128u - (unsigned)__builtin_clzll(ends_past_64 & ((UINT64_C(2) << (doubles - 65u)) - 1u));
}

/* A 1.x packet of at least 67 doubles by the widest vectors this build or
 * CPU has; false, having stored nothing, where it has none. */
static bool decode_1x(const uint8_t *body, unsigned doubles, urrt_state *st)
{
    uint64_t present = 0;
#if defined(URRT_VECTOR)
    decode_1x_vector(body, one_x_copied(doubles), st);
#else
    switch (cpu_vector_bytes()) {
#if URRT_X86_MAX_VECTOR_BYTES >= 64
    case 64: decode_1x_64(body, one_x_copied(doubles), st); break;
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 32
    case 32: decode_1x_32(body, one_x_copied(doubles), st); break;
#endif
#if URRT_X86_MAX_VECTOR_BYTES >= 16
    case 16: decode_1x_16(body, one_x_copied(doubles), st); break;
#endif
    default: return false;
    }
#endif
#define URRT_X_PRESENT_1X(ID, name, count, c1, c3, unit, since, desc) \
    present |= field_fits((unsigned)URRT_F_##ID, c1, doubles, URRT_GEN_1X) ? UINT64_C(1) << URRT_F_##ID : 0u;
    URRT_FIELDS(URRT_X_PRESENT_1X)
#undef URRT_X_PRESENT_1X
    st->present = present;
    return true;
}
#endif

/* decode_by_table (lib/urrt.c): the 1.x lengths real controllers sent (the
 * shortest 540 bytes, 67 doubles) by vectors where there are, the rest
 * field by field. */
static void decode_by_table(const uint8_t *body, unsigned doubles, urrt_generation gen, urrt_state *st)
{
#ifdef URRT_DECODE_1X_VECTOR
    if (gen == URRT_GEN_1X && doubles >= URRT_1X_GAP_A + URRT_1X_GAP_A_DOUBLES && decode_1x(body, doubles, st)) {
        return;
    }
#endif
    decode_fields(body, doubles, gen, st);
}
