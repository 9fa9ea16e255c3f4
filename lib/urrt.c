/* SPDX-License-Identifier: MIT */
/* urrt: RealTime interface decoder. See urrt.h for the API, docs/ for the
 * wire format and the security model. */
#include "urrt.h"

/* C99 has no _Static_assert; a negative array size stops the build. */
#define URRT_STATIC_ASSERT(name, cond) typedef char urrt_assert_##name[(cond) ? 1 : -1]

URRT_STATIC_ASSERT(double_is_ieee754_binary64, sizeof(double) == 8);
URRT_STATIC_ASSERT(max_doubles_holds_newest_layout, URRT_MAX_DOUBLES >= URRT_WIRE_COLUMNS);
URRT_STATIC_ASSERT(max_doubles_fits_int, URRT_MAX_DOUBLES <= 0x0FFFFFFF);
/* urrt_state counts doubles and extra columns in uint16_t. */
URRT_STATIC_ASSERT(max_doubles_fits_state, URRT_MAX_DOUBLES <= 0xFFFF);
URRT_STATIC_ASSERT(fields_fit_presence_mask, URRT_FIELD_COUNT <= 64);

/* The decoder fills the 3.x/5.x grid in one pass, so each grid field must
 * sit at its column's offset from the start of the struct. */
#define URRT_X_GRID_CHECK(ID, name, count, c1, c3, unit, since, desc) \
    URRT_STATIC_ASSERT(grid_##name, (c3) == 0 || offsetof(urrt_state, name) == ((c3) - 1) * sizeof(double));
URRT_FIELDS(URRT_X_GRID_CHECK)
#undef URRT_X_GRID_CHECK
URRT_STATIC_ASSERT(grid_is_152_columns,
                   offsetof(urrt_state, unused_53) == URRT_WIRE_COLUMNS * sizeof(double));
/* The fields only 1.x has follow the grid, back to back, so the 3.x decoder
 * clears them with one fill. */
#define URRT_1X_ONLY_DOUBLES 27u
URRT_STATIC_ASSERT(one_x_only_fields_contiguous,
                   offsetof(urrt_state, tool_vector) == offsetof(urrt_state, unused_53) + 15 * sizeof(double) &&
                       offsetof(urrt_state, tcp_speed) == offsetof(urrt_state, tool_vector) + 6 * sizeof(double) &&
                       offsetof(urrt_state, tcp_speed) + 6 * sizeof(double) ==
                           offsetof(urrt_state, unused_53) + URRT_1X_ONLY_DOUBLES * sizeof(double) &&
                       URRT_F_TCP_SPEED == URRT_FIELD_COUNT - 1);

#define URRT_X_COUNT_CHECK(ID, name, count, c1, c3, unit, since, desc) \
    URRT_STATIC_ASSERT(count_##name, (count) <= URRT_FIELD_COUNT_MAX);
URRT_FIELDS(URRT_X_COUNT_CHECK)
#undef URRT_X_COUNT_CHECK

#define URRT_NAN_BITS UINT64_C(0x7FF8000000000000)
#define URRT_1X_MAX_DOUBLES 101u
#define URRT_3X_MIN_DOUBLES 130u
/* 1.5 sent columns 50-52 without the accelerometer (docs/sources.md, "1.x differences"). */
#define URRT_1X_ACCELEROMETER_MIN_DOUBLES 95u

/* The shortest 3.x grid ends with a whole field: a 3.x decode copies at
 * least URRT_3X_MIN_DOUBLES columns (two vectors, as the vector paths
 * need), up to the last field end by the packet's last column. */
#define URRT_X_ENDS_SHORTEST(ID, name, count, c1, c3, unit, since, desc) \
    +((c3) != 0 && (c3) + (count) - 1 == URRT_3X_MIN_DOUBLES)
URRT_STATIC_ASSERT(a_field_ends_the_shortest_grid, 0 URRT_FIELDS(URRT_X_ENDS_SHORTEST) == 1);
#undef URRT_X_ENDS_SHORTEST

static const urrt_field_info field_table[URRT_FIELD_COUNT] = {
#define URRT_X_INFO(ID, name, count, c1, c3, unit, since, desc) \
    {#name, unit, since, desc, count, c1, c3},
    URRT_FIELDS(URRT_X_INFO)
#undef URRT_X_INFO
};

/* What decoding needs of the table, without the strings: a firmware that
 * only decodes links 135 bytes of layout instead of the ~3 KiB of names
 * and descriptions (they come in with urrt_field() and urrt_field_find()). */
typedef struct field_layout {
    uint8_t count;
    uint8_t col_1x;
    uint8_t col_3x;
} field_layout;

static const field_layout layout_table[URRT_FIELD_COUNT] = {
#define URRT_X_LAYOUT(ID, name, count, c1, c3, unit, since, desc) {count, c1, c3},
    URRT_FIELDS(URRT_X_LAYOUT)
#undef URRT_X_LAYOUT
};

/* ---- bytes and bits ---------------------------------------------------- */

static uint32_t load_be32(const uint8_t *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | (uint32_t)p[3];
}

/*
 * How a big-endian double is loaded, chosen by what the compiler and the
 * target guarantee (one place, so that a runtime choice can be added here):
 *
 * URRT_LOAD_UNALIGNED: GCC or clang on a little-endian target whose every
 *   load may be unaligned (x86, AArch64, ARM with __ARM_FEATURE_UNALIGNED:
 *   ARMv7-M/A without -mno-unaligned-access). A fixed-size __builtin_memcpy
 *   is then one load, never a call, and the byte swap is one instruction.
 * URRT_LOAD_WORDS: GCC or clang on little-endian ARM without unaligned
 *   access but with REV (ARMv6-M such as Cortex-M0/M0+, or ARMv7-M built
 *   with -mno-unaligned-access): word loads where the source is 4-byte
 *   aligned (packets in the framer's buffer are), bytes where it is not.
 * Otherwise (RISC-V, whose misaligned loads may trap or be emulated, any
 *   big-endian target, compilers without GNU extensions): byte loads,
 *   which GCC merges into wider loads where that is allowed. A
 *   __builtin_memcpy of unaligned bytes is a call to the C library's memcpy
 *   on those targets, which lib/ must not need.
 */
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__)
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#if defined(__x86_64__) || defined(__i386__) || defined(__aarch64__) || defined(__ARM_FEATURE_UNALIGNED)
#define URRT_LOAD_UNALIGNED 1
#elif defined(__arm__) && defined(__ARM_ARCH) && __ARM_ARCH >= 6
#define URRT_LOAD_WORDS 1
#endif
#endif
#endif

#ifdef URRT_LOAD_UNALIGNED
static uint64_t load_be64(const uint8_t *p)
{
    uint64_t v;
    __builtin_memcpy(&v, p, sizeof v);
    return __builtin_bswap64(v);
}
#else
static uint64_t load_be64(const uint8_t *p)
{
    return ((uint64_t)load_be32(p) << 32) | (uint64_t)load_be32(p + 4);
}
#endif

#ifdef URRT_LOAD_WORDS
/* p must be 4-byte aligned: two word loads and two REV. */
static uint64_t load_be64_aligned4(const uint8_t *p)
{
    const uint8_t *a = (const uint8_t *)__builtin_assume_aligned(p, 4);
    uint32_t hi, lo;
    __builtin_memcpy(&hi, a, 4);
    __builtin_memcpy(&lo, a + 4, 4);
    return ((uint64_t)__builtin_bswap32(hi) << 32) | __builtin_bswap32(lo);
}
#endif

static void store_be64(uint8_t *p, uint64_t v)
{
    unsigned i;
    for (i = 0; i < 8; i++) {
        p[i] = (uint8_t)(v >> (56 - 8 * i));
    }
}

/* Reading a union member other than the one last written reinterprets the
 * bytes (C99 TC3 6.5.2.3): the portable way to move bits without memcpy. */
typedef union {
    uint64_t u;
    double d;
} urrt_bits;

static double double_from_bits(uint64_t u)
{
    urrt_bits b;
    b.u = u;
    return b.d;
}

static uint64_t bits_from_double(double d)
{
    urrt_bits b;
    b.d = d;
    return b.u;
}

/*
 * An integral double's value, worked out on the bits so that the library
 * needs no floating-point arithmetic (a Cortex-M without an FPU would pull in
 * soft-float routines for a single comparison). False for NaN, infinities,
 * fractions and magnitudes past 2^53.
 */
static bool integral_from_bits(uint64_t u, bool *negative, uint64_t *magnitude)
{
    const uint64_t mantissa_mask = (UINT64_C(1) << 52) - 1;
    unsigned exponent = (unsigned)((u >> 52) & 0x7FFu);
    uint64_t mantissa = u & mantissa_mask;

    *negative = (u >> 63) != 0;
    if (exponent == 0) {
        *magnitude = 0;
        return mantissa == 0; /* zero, or a subnormal fraction */
    }
    if (exponent == 0x7FFu || exponent < 1023u || exponent > 1023u + 53u) {
        return false;
    }
    mantissa |= UINT64_C(1) << 52;
    if (exponent >= 1075u) {
        *magnitude = mantissa << (exponent - 1075u);
        return true;
    }
    {
        unsigned shift = 1075u - exponent;
        if ((mantissa & ((UINT64_C(1) << shift) - 1)) != 0) {
            return false;
        }
        *magnitude = mantissa >> shift;
    }
    return true;
}

/* ---- results and metadata ----------------------------------------------- */

const char *urrt_strerror(int result)
{
    switch (result) {
    case URRT_E_ARG: return "invalid argument";
    case URRT_E_TRUNCATED: return "fewer bytes than the packet declares";
    case URRT_E_SIZE_SMALL: return "declared size below the minimum packet";
    case URRT_E_SIZE_ALIGN: return "declared size is not 4 + 8n";
    case URRT_E_SIZE_LARGE: return "declared size past the largest packet accepted";
    case URRT_E_ABSENT: return "field not present in a packet of this length";
    case URRT_E_RANGE: return "index out of range";
    case URRT_E_NOT_BITMASK: return "value is not a bit mask";
    case URRT_E_NO_SPACE: return "output buffer too small";
    case URRT_E_UNKNOWN_FIELD: return "no field of that name";
    default: return result >= 0 ? "ok" : "unknown error";
    }
}

const urrt_field_info *urrt_field(urrt_field_id id)
{
    if ((unsigned)id >= (unsigned)URRT_FIELD_COUNT) {
        return NULL;
    }
    return &field_table[id];
}

int urrt_field_find(const char *name, size_t name_len)
{
    unsigned id;
    if (name == NULL) {
        return URRT_E_ARG;
    }
    for (id = 0; id < (unsigned)URRT_FIELD_COUNT; id++) {
        const char *candidate = field_table[id].name;
        size_t i = 0;
        while (i < name_len && candidate[i] != '\0' && candidate[i] == name[i]) {
            i++;
        }
        if (i == name_len && candidate[i] == '\0') {
            return (int)id;
        }
    }
    return URRT_E_UNKNOWN_FIELD;
}

static unsigned layout_column(const field_layout *f, urrt_generation gen)
{
    switch (gen) {
    case URRT_GEN_1X: return f->col_1x;
    case URRT_GEN_3X: return f->col_3x;
    case URRT_GEN_UNKNOWN: return f->col_1x == f->col_3x ? f->col_1x : 0u;
    default: return 0;
    }
}

unsigned urrt_field_column(urrt_field_id id, urrt_generation gen)
{
    if ((unsigned)id >= (unsigned)URRT_FIELD_COUNT) {
        return 0;
    }
    return layout_column(&layout_table[id], gen);
}

/* ---- lengths ------------------------------------------------------------ */

static bool plausible_length(uint32_t size)
{
    return size >= URRT_PACKET_MIN && size <= URRT_PACKET_MAX && (size - URRT_HEADER_SIZE) % 8u == 0;
}

/* The rates of docs/protocol.md: 125 Hz on CB2/CB3, 500 Hz on e-series. No
 * source gives CB1's (1.5): taken as 125 Hz, like the CB2 that followed it. */
#define CB_US 8000u
#define E_US 2000u

static const urrt_controller controller_table[] = {
    {540, {{0, 0, 0, 0}, {0, 0, 0, 0}}, "early 1.x (before 1.5)"},
    {692, {{0, 0, 0, 0}, {0, 0, 0, 0}}, "early 1.x (before 1.5)"},
    {756, {{1, 5, 6, CB_US}, {0, 0, 0, 0}}, "1.5-1.6"},
    {764, {{1, 6, 7, CB_US}, {0, 0, 0, 0}}, "1.6-1.7"},
    {812, {{1, 8, 8, CB_US}, {0, 0, 0, 0}}, "1.8"},
    {1044, {{3, 0, 1, CB_US}, {0, 0, 0, 0}}, "3.0-3.1"},
    {1060, {{3, 2, 4, CB_US}, {0, 0, 0, 0}}, "3.2-3.4"},
    {1108, {{3, 5, 9, CB_US}, {5, 0, 3, E_US}}, "3.5-3.9, 5.0-5.3"},
    {1116, {{3, 10, 13, CB_US}, {5, 4, 8, E_US}}, "3.10-3.13, 5.4-5.8"},
    {1140, {{3, 14, 15, CB_US}, {5, 9, 9, E_US}}, "3.14-3.15, 5.9"},
    {1220, {{5, 10, URRT_MINOR_LATER, E_US}, {0, 0, 0, 0}}, "5.10 or later"},
};
#define CONTROLLER_ROWS (sizeof controller_table / sizeof controller_table[0])
#define RANGES_PER_ROW (sizeof controller_table[0].ranges / sizeof controller_table[0].ranges[0])

const urrt_controller *urrt_controllers(size_t *count)
{
    if (count != NULL) {
        *count = CONTROLLER_ROWS;
    }
    return controller_table;
}

const urrt_controller *urrt_controller_of_length(uint32_t length)
{
    size_t i;
    for (i = 0; i < CONTROLLER_ROWS; i++) {
        if (controller_table[i].length == length) {
            return &controller_table[i];
        }
    }
    return NULL;
}

const char *urrt_versions_of(uint32_t length)
{
    const urrt_controller *c = urrt_controller_of_length(length);
    return c != NULL ? c->versions : NULL;
}

/* One group of decimal digits at *pos, its value capped at 255 (no version
 * number comes near it). False for an empty group. */
static bool version_number(const char *text, size_t len, size_t *pos, unsigned *value)
{
    size_t start = *pos;
    *value = 0;
    while (*pos < len && text[*pos] >= '0' && text[*pos] <= '9') {
        unsigned v = *value * 10u + (unsigned)(text[*pos] - '0');
        *value = v > 255u ? 255u : v;
        (*pos)++;
    }
    return *pos > start;
}

/* MAJOR.MINOR[.PATCH[.BUILD]]: the first two numbers decide. */
static bool parse_version(const char *text, size_t len, unsigned *major, unsigned *minor)
{
    size_t pos = 0;
    unsigned groups = 0, ignored;
    if (!version_number(text, len, &pos, major)) {
        return false;
    }
    while (pos < len && groups < 3u && text[pos] == '.') {
        pos++;
        if (!version_number(text, len, &pos, groups == 0 ? minor : &ignored)) {
            return false;
        }
        groups++;
    }
    return pos == len && groups >= 1u;
}

static bool range_holds(const urrt_version_range *r, unsigned major, unsigned minor)
{
    return r->major != 0 && r->major == major && minor >= r->minor_first &&
           (r->minor_last == URRT_MINOR_LATER || minor <= r->minor_last);
}

int urrt_controller_find(const char *text, size_t len, const urrt_controller **found, size_t max,
                         uint32_t *period_us)
{
    unsigned major, minor;
    size_t i, j;
    int rows = 0;
    if (text == NULL || !parse_version(text, len, &major, &minor)) {
        return URRT_E_ARG;
    }
    for (i = 0; i < CONTROLLER_ROWS; i++) {
        for (j = 0; j < RANGES_PER_ROW; j++) {
            const urrt_version_range *r = &controller_table[i].ranges[j];
            if (!range_holds(r, major, minor)) {
                continue;
            }
            if (found != NULL && (size_t)rows < max) {
                found[rows] = &controller_table[i];
            }
            if (period_us != NULL) {
                *period_us = r->period_us;
            }
            rows++;
        }
    }
    return rows;
}

uint32_t urrt_period_min_us(uint32_t length)
{
    const urrt_controller *own = urrt_controller_of_length(length);
    urrt_generation gen = urrt_generation_of(length);
    uint32_t best = 0;
    size_t i, j;
    if (own != NULL && own->ranges[0].major == 0) {
        own = NULL; /* early 1.x: no versions to ask, ask the generation */
    }
    for (i = 0; i < CONTROLLER_ROWS; i++) {
        const urrt_controller *c = &controller_table[i];
        if (own != NULL ? c != own : gen != URRT_GEN_UNKNOWN && urrt_generation_of(c->length) != gen) {
            continue;
        }
        for (j = 0; j < RANGES_PER_ROW; j++) {
            uint32_t p = c->ranges[j].period_us;
            if (c->ranges[j].major != 0 && (best == 0 || p < best)) {
                best = p;
            }
        }
    }
    return best;
}

urrt_generation urrt_generation_of(uint32_t length)
{
    uint32_t doubles;
    if (!plausible_length(length)) {
        return URRT_GEN_UNKNOWN;
    }
    doubles = (length - URRT_HEADER_SIZE) / 8u;
    if (doubles <= URRT_1X_MAX_DOUBLES) {
        return URRT_GEN_1X;
    }
    if (doubles >= URRT_3X_MIN_DOUBLES) {
        return URRT_GEN_3X;
    }
    return URRT_GEN_UNKNOWN;
}

/* urrt_packet_length(), kept static so that the decoders can inline it. */
static inline int packet_length(const uint8_t *buf, size_t len)
{
    int32_t declared;
    uint32_t raw;
    if (buf == NULL) {
        return URRT_E_ARG;
    }
    if (len < URRT_HEADER_SIZE) {
        return URRT_E_TRUNCATED;
    }
    raw = load_be32(buf);
    declared = raw > 0x7FFFFFFFu ? -1 : (int32_t)raw;
    if (declared < (int32_t)URRT_PACKET_MIN) {
        return URRT_E_SIZE_SMALL;
    }
    if ((raw - URRT_HEADER_SIZE) % 8u != 0) {
        return URRT_E_SIZE_ALIGN;
    }
    if (raw > URRT_PACKET_MAX) {
        return URRT_E_SIZE_LARGE;
    }
    if (raw > len) {
        return URRT_E_TRUNCATED;
    }
    return (int)raw;
}

int urrt_packet_length(const uint8_t *buf, size_t len)
{
    return packet_length(buf, len);
}

/* ---- decoding ----------------------------------------------------------- */

static bool field_fits(unsigned id, unsigned column, unsigned doubles, urrt_generation gen)
{
    if (column == 0 || column + layout_table[id].count - 1u > doubles) {
        return false;
    }
    if (gen == URRT_GEN_1X && id == (unsigned)URRT_F_TOOL_ACCELEROMETER) {
        return doubles >= URRT_1X_ACCELEROMETER_MIN_DOUBLES;
    }
    return true;
}

/* Column c of the 3.x/5.x grid, as a place in the struct (see the static
 * assertions above: the grid members are laid out in column order). */
static double *grid_slot(urrt_state *st, unsigned column)
{
    return (double *)(void *)((unsigned char *)st + (column - 1u) * sizeof(double));
}

static const double *grid_slot_const(const urrt_state *st, unsigned column)
{
    return (const double *)(const void *)((const unsigned char *)st + (column - 1u) * sizeof(double));
}

static const uint16_t field_offsets[URRT_FIELD_COUNT] = {
#define URRT_X_OFFSET(ID, name, count, c1, c3, unit, since, desc) (uint16_t)offsetof(urrt_state, name),
    URRT_FIELDS(URRT_X_OFFSET)
#undef URRT_X_OFFSET
};

static double *field_slot(urrt_state *st, unsigned id)
{
    return (double *)(void *)((unsigned char *)st + field_offsets[id]);
}

static const double *field_slot_const(const urrt_state *st, unsigned id)
{
    return (const double *)(const void *)((const unsigned char *)st + field_offsets[id]);
}

const double *urrt_field_values(const urrt_state *st, urrt_field_id id)
{
    if (st == NULL || (unsigned)id >= (unsigned)URRT_FIELD_COUNT) {
        return NULL;
    }
    return field_slot_const(st, (unsigned)id);
}

static void fill_nan(double *p, unsigned count)
{
    double nan = double_from_bits(URRT_NAN_BITS);
    unsigned i;
    for (i = 0; i < count; i++) {
        p[i] = nan;
    }
}

void urrt_state_clear(urrt_state *st)
{
    unsigned id;
    if (st == NULL) {
        return;
    }
    for (id = 0; id < (unsigned)URRT_FIELD_COUNT; id++) {
        fill_nan(field_slot(st, id), layout_table[id].count);
    }
    st->present = 0;
    st->length = 0;
    st->doubles = 0;
    st->extra_columns = 0;
    st->generation = URRT_GEN_UNKNOWN;
}

/* Number of grid fields (the rows with a 3.x/5.x column, which come first). */
static const unsigned grid_fields = 0u
#define URRT_X_GRID_COUNT(ID, name, count, c1, c3, unit, since, desc) + ((c3) != 0 ? 1u : 0u)
    URRT_FIELDS(URRT_X_GRID_COUNT)
#undef URRT_X_GRID_COUNT
    ;

/* Of those, the last ones, which end past the shortest 3.x grid's last
 * column (the only ones a 3.x packet can lack), as a mask: bit e - 130 for
 * a field ending in column e (ends differ: fields do not overlap). */
static const unsigned grid_tail_fields = 0u
#define URRT_X_GRID_TAIL(ID, name, count, c1, c3, unit, since, desc) \
    + ((c3) != 0 && (c3) + (count) - 1 > URRT_3X_MIN_DOUBLES ? 1u : 0u)
    URRT_FIELDS(URRT_X_GRID_TAIL)
#undef URRT_X_GRID_TAIL
    ;
static const uint32_t grid_tail_ends = 0u
#define URRT_X_GRID_TAIL_END(ID, name, count, c1, c3, unit, since, desc) \
    | ((c3) != 0 && (c3) + (count) - 1 > URRT_3X_MIN_DOUBLES ? UINT32_C(1) << (((c3) + (count) - 1 - URRT_3X_MIN_DOUBLES) & 31u) : 0u)
    URRT_FIELDS(URRT_X_GRID_TAIL_END)
#undef URRT_X_GRID_TAIL_END
    ;

static unsigned bit_count(uint32_t x)
{
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    x = (x + (x >> 4)) & 0x0F0F0F0Fu;
    return (unsigned)((x * 0x01010101u) >> 24);
}

/*
 * The 3.x/5.x decode writes the struct from the grid to `generation` in
 * one pass: the grid's columns, NaN for the absent ones and the 1.x-only
 * fields after them (URRT_GRID_DOUBLES doubles, asserted contiguous
 * above), then present, length, doubles, extra_columns and generation. It
 * is bound by stores (about one per cycle, whatever its width up to a
 * cache line; lib/vector/urrt_vector.c has the vector paths).
 */
#define URRT_GRID_DOUBLES (URRT_WIRE_COLUMNS + URRT_1X_ONLY_DOUBLES)

static inline uint64_t present_mask(unsigned fields)
{
    return fields >= 64u ? ~UINT64_C(0) : (UINT64_C(1) << fields) - 1u;
}

/* What a 3.x/5.x packet of `doubles` doubles fills in. */
typedef struct grid_shape {
    unsigned copied;  /* columns 1..copied are copied; NaN from there on */
    unsigned fields;  /* the grid fields present (a prefix of the table) */
    unsigned known;   /* the packet's columns that the grid has */
} grid_shape;

/* The grid_tail_ends of the tail fields that end by column `known`. */
static inline uint32_t grid_tail_ends_by(unsigned known)
{
    return grid_tail_ends & ((UINT32_C(2) << (known - URRT_3X_MIN_DOUBLES)) - 1u);
}

static inline grid_shape grid_shape_of(unsigned doubles)
{
    grid_shape g;
    g.known = doubles < URRT_WIRE_COLUMNS ? doubles : URRT_WIRE_COLUMNS;
    /* Grid fields are in column order and end in ascending columns, so the
     * whole ones are a prefix: those before the tail, and the tail fields
     * ending by column `known` (a bit count, no branches: walking back
     * from the last field until one fitted cost the 1060-byte packet,
     * seven steps, a sixth of its decode). */
    g.fields = grid_fields - grid_tail_fields + bit_count(grid_tail_ends_by(g.known));
    /* The columns before the first absent field, the one after the prefix
     * (lib/vector/urrt_vector.c counts them by a CLZ instead). */
    g.copied = g.fields < grid_fields ? layout_table[g.fields].col_3x - 1u : URRT_WIRE_COLUMNS;
    return g;
}

/* n big-endian doubles from src into dst. Counted by the destination
 * pointer: an index beside it cost GCC for Cortex-M4 (-O2) one more
 * instruction per double. */
static void load_doubles(double *dst, const uint8_t *src, unsigned n)
{
    double *end = dst + n;
#ifdef URRT_LOAD_WORDS
    if (((uintptr_t)(const void *)src & 3u) == 0) {
        for (; dst < end; dst++, src += 8) {
            *dst = double_from_bits(load_be64_aligned4(src));
        }
    }
#endif
    for (; dst < end; dst++, src += 8) {
        *dst = double_from_bits(load_be64(src));
    }
}

/* decode_3x one double at a time. */
static int decode_3x_scalar(const uint8_t *buf, unsigned size, urrt_state *st)
{
    unsigned doubles = (size - URRT_HEADER_SIZE) / 8u;
    grid_shape g = grid_shape_of(doubles);

    load_doubles(grid_slot(st, 1), buf + URRT_HEADER_SIZE, g.copied);
    fill_nan(grid_slot(st, g.copied + 1u), URRT_GRID_DOUBLES - g.copied);
    st->present = present_mask(g.fields);
    st->length = size;
    st->doubles = (uint16_t)doubles;
    st->extra_columns = (uint16_t)(doubles - g.known);
    st->generation = URRT_GEN_3X;
    return (int)size;
}

/* The hot path (e-series at 500 Hz): one pass over the grid. Where
 * lib/vector/urrt_vector.c includes this file, it defines decode_3x after
 * it: by the widest vectors the build or the CPU has, else as here. */
#ifdef URRT_VECTOR_PATHS
static int decode_3x(const uint8_t *buf, unsigned size, urrt_state *st);
#else
static int decode_3x(const uint8_t *buf, unsigned size, urrt_state *st)
{
    return decode_3x_scalar(buf, size, st);
}

#if defined(__x86_64__)
/* Declared by urrt.h on x86-64: this file alone copies one double at a time. */
unsigned urrt_x86_vector_bytes(void)
{
    return 0;
}
#endif
#endif

/* 1.x and the ambiguous lengths: field by field from the table, each
 * field's doubles stored once, from the packet or as NaN (clearing the
 * struct first and then copying stored the present fields twice). Where
 * lib/vector/urrt_vector.c includes this file, it defines decode_by_table
 * after it: the 1.x lengths of real controllers by vectors, the rest
 * written out field by field (three times as fast as this loop, and a
 * kilobyte more code than a firmware wants for them). */
#ifdef URRT_VECTOR_PATHS
static void decode_by_table(const uint8_t *body, unsigned doubles, urrt_generation gen, urrt_state *st);
#else
static void decode_by_table(const uint8_t *body, unsigned doubles, urrt_generation gen, urrt_state *st)
{
    uint64_t present = 0;
    unsigned id;
    for (id = 0; id < (unsigned)URRT_FIELD_COUNT; id++) {
        const field_layout *f = &layout_table[id];
        unsigned column = layout_column(f, gen);
        double *slot = field_slot(st, id);
        if (field_fits(id, column, doubles, gen)) {
            load_doubles(slot, body + 8u * (column - 1u), f->count);
            present |= UINT64_C(1) << id;
        } else {
            fill_nan(slot, f->count);
        }
    }
    st->present = present;
}
#endif

/* Everything but a 3.x/5.x packet: errors, 1.x, the ambiguous lengths. Not
 * inlined beside the vector paths, so that urrt_decode saves no registers
 * before it jumps to them (a push is a store). A firmware keeps one frame
 * (the stack checker adds the frames of a tail call). */
#if defined(URRT_VECTOR_PATHS) && defined(__GNUC__)
__attribute__((noinline))
#endif
static int decode_other(const uint8_t *buf, int size, urrt_state *st)
{
    unsigned doubles;
    urrt_generation gen;

    if (size < 0) {
        urrt_state_clear(st);
        return size;
    }
    doubles = ((unsigned)size - URRT_HEADER_SIZE) / 8u;
    gen = urrt_generation_of((uint32_t)size);
    decode_by_table(buf + URRT_HEADER_SIZE, doubles, gen, st);
    st->length = (uint32_t)size;
    st->doubles = (uint16_t)doubles;
    st->extra_columns = 0;
    st->generation = gen;
    return size;
}

int urrt_decode(const uint8_t *buf, size_t len, urrt_state *st)
{
    int size;

    if (st == NULL) {
        return URRT_E_ARG;
    }
    size = packet_length(buf, len);
    /* A valid size of 130 doubles or more is 3.x/5.x (urrt_generation_of). */
    if (size >= (int)(URRT_HEADER_SIZE + 8u * URRT_3X_MIN_DOUBLES)) {
        return decode_3x(buf, (unsigned)size, st);
    }
    return decode_other(buf, size, st);
}

int urrt_read_column_bits(const uint8_t *buf, size_t len, unsigned column, uint64_t *out)
{
    int size = packet_length(buf, len);
    if (size < 0) {
        return size;
    }
    if (out == NULL) {
        return URRT_E_ARG;
    }
    if (column == 0 || column > ((unsigned)size - URRT_HEADER_SIZE) / 8u) {
        return URRT_E_RANGE;
    }
    *out = load_be64(buf + URRT_HEADER_SIZE + 8u * (column - 1u));
    return URRT_OK;
}

int urrt_read_column(const uint8_t *buf, size_t len, unsigned column, double *out)
{
    uint64_t bits;
    int r;
    if (out == NULL) {
        return URRT_E_ARG;
    }
    r = urrt_read_column_bits(buf, len, column, &bits);
    if (r == URRT_OK) {
        *out = double_from_bits(bits);
    }
    return r;
}

int urrt_read(const uint8_t *buf, size_t len, urrt_field_id id, unsigned elem, double *out)
{
    int size = packet_length(buf, len);
    unsigned doubles;
    urrt_generation gen;
    unsigned column;

    if (size < 0) {
        return size;
    }
    if ((unsigned)id >= (unsigned)URRT_FIELD_COUNT || out == NULL) {
        return URRT_E_ARG;
    }
    if (elem >= layout_table[id].count) {
        return URRT_E_RANGE;
    }
    doubles = ((unsigned)size - URRT_HEADER_SIZE) / 8u;
    gen = urrt_generation_of((uint32_t)size);
    column = layout_column(&layout_table[id], gen);
    if (!field_fits((unsigned)id, column, doubles, gen)) {
        return URRT_E_ABSENT;
    }
    /* The packet was validated above and the element lies inside it. */
    *out = double_from_bits(load_be64(buf + URRT_HEADER_SIZE + 8u * (column - 1u + elem)));
    return URRT_OK;
}

/* ---- encoding ----------------------------------------------------------- */

int urrt_encode(const urrt_state *st, uint32_t length, uint8_t *out, size_t out_size)
{
    unsigned doubles;
    unsigned col;
    unsigned id;
    urrt_generation gen;

    if (st == NULL || out == NULL) {
        return URRT_E_ARG;
    }
    if (length < URRT_PACKET_MIN) {
        return URRT_E_SIZE_SMALL;
    }
    if ((length - URRT_HEADER_SIZE) % 8u != 0) {
        return URRT_E_SIZE_ALIGN;
    }
    if (length > URRT_PACKET_MAX) {
        return URRT_E_SIZE_LARGE; /* 0x80000004 and up included: a size, not a sign */
    }
    if (out_size < length) {
        return URRT_E_NO_SPACE;
    }
    doubles = (length - URRT_HEADER_SIZE) / 8u;
    gen = doubles <= URRT_1X_MAX_DOUBLES ? URRT_GEN_1X : URRT_GEN_3X;

    out[0] = (uint8_t)(length >> 24);
    out[1] = (uint8_t)(length >> 16);
    out[2] = (uint8_t)(length >> 8);
    out[3] = (uint8_t)length;
    if (gen == URRT_GEN_3X) {
        unsigned known = doubles < URRT_WIRE_COLUMNS ? doubles : URRT_WIRE_COLUMNS;
        for (col = 1; col <= known; col++) {
            store_be64(out + URRT_HEADER_SIZE + 8u * (col - 1u), bits_from_double(*grid_slot_const(st, col)));
        }
        for (; col <= doubles; col++) {
            store_be64(out + URRT_HEADER_SIZE + 8u * (col - 1u), 0);
        }
        return (int)length;
    }
    for (col = 1; col <= doubles; col++) {
        store_be64(out + URRT_HEADER_SIZE + 8u * (col - 1u), 0);
    }
    for (id = 0; id < (unsigned)URRT_FIELD_COUNT; id++) {
        const field_layout *f = &layout_table[id];
        const double *slot = field_slot_const(st, id);
        unsigned i;
        if (f->col_1x == 0) {
            continue;
        }
        for (i = 0; i < f->count && f->col_1x + i <= doubles; i++) {
            store_be64(out + URRT_HEADER_SIZE + 8u * (f->col_1x - 1u + i), bits_from_double(slot[i]));
        }
    }
    return (int)length;
}

/* ---- controller time ------------------------------------------------------ */

/* A 128-bit unsigned number as two words: enough for a 53-bit mantissa
 * times 15625 (2^67). */
typedef struct {
    uint64_t hi, lo;
} wide_u128;

static void wide_add(wide_u128 *w, uint64_t hi, uint64_t lo)
{
    w->lo += lo;
    w->hi += hi + (w->lo < lo ? 1u : 0u);
}

/* x * 15625 (10^6 = 15625 * 2^6), x < 2^53, by shifts and adds: a 64-bit
 * multiply is a libgcc call on Cortex-M0+ (Thumb-1 has no long multiply). */
static wide_u128 times_15625(uint64_t x)
{
    static const unsigned char shifts[] = {13, 12, 11, 10, 8, 3}; /* 15625 = 0b11110100001001 */
    wide_u128 w = {0, x};
    unsigned i;
    for (i = 0; i < sizeof shifts; i++) {
        wide_add(&w, x >> (64u - shifts[i]), x << shifts[i]);
    }
    return w;
}

int urrt_time_us(double seconds, int64_t *us)
{
    const uint64_t max = (uint64_t)URRT_TIME_US_MAX;
    uint64_t u = bits_from_double(seconds);
    unsigned exponent = (unsigned)((u >> 52) & 0x7FFu);
    uint64_t mantissa = u & ((UINT64_C(1) << 52) - 1u);
    int shift; /* microseconds = mantissa * 15625 * 2^shift */
    wide_u128 w;
    uint64_t result;

    if (us == NULL) {
        return URRT_E_ARG;
    }
    if ((exponent == 0x7FFu && mantissa != 0) || ((u >> 63) != 0 && (u << 1) != 0)) {
        *us = 0; /* NaN, or below zero (-0.0 is zero) */
        return URRT_E_RANGE;
    }
    if (exponent >= 1023u + 34u) {
        *us = URRT_TIME_US_MAX; /* 2^34 s and up, infinity included: past the maximum */
        return URRT_E_RANGE;
    }
    if (exponent != 0) {
        mantissa |= UINT64_C(1) << 52;
    }
    /* Below 2^34 s the shift is negative: 1075 - 6 - 34 = 1035 of it at most. */
    shift = (exponent != 0 ? (int)exponent : 1) - 1075 + 6;
    if (shift < -68) {
        result = 0; /* below half a microsecond: mantissa * 15625 < 2^67 */
    } else {
        unsigned s = (unsigned)-shift; /* 13..68: add a half, then shift */
        w = times_15625(mantissa);
        if (s - 1u < 64u) {
            wide_add(&w, 0, UINT64_C(1) << (s - 1u));
        } else {
            wide_add(&w, UINT64_C(1) << (s - 65u), 0);
        }
        result = s >= 64u ? w.hi >> (s - 64u) : (w.lo >> s) | (w.hi << (64u - s));
    }
    if (result > max) {
        *us = URRT_TIME_US_MAX;
        return URRT_E_RANGE;
    }
    *us = (int64_t)result;
    return URRT_OK;
}

/* ---- bit masks and enumerations ------------------------------------------ */

int urrt_bitmask(double value, uint64_t *mask)
{
    uint64_t u = bits_from_double(value);
    uint64_t magnitude;
    bool negative;

    if (mask == NULL) {
        return URRT_E_ARG;
    }
    if ((u >> 52) == 0) {
        /* Sign and exponent clear: zero, or a raw int64 read as a double. */
        *mask = u;
        return URRT_OK;
    }
    if (!integral_from_bits(u, &negative, &magnitude) || (negative && magnitude != 0) ||
        magnitude > (UINT64_C(1) << 53)) {
        return URRT_E_NOT_BITMASK;
    }
    *mask = magnitude;
    return URRT_OK;
}

static const urrt_enum_entry robot_modes[] = {
    {-1, "NO_CONTROLLER"}, {0, "DISCONNECTED"}, {1, "CONFIRM_SAFETY"}, {2, "BOOTING"},
    {3, "POWER_OFF"}, {4, "POWER_ON"}, {5, "IDLE"}, {6, "BACKDRIVE"},
    {7, "RUNNING"}, {8, "UPDATING_FIRMWARE"},
};

static const urrt_enum_entry robot_modes_1x[] = {
    {0, "RUNNING"}, {1, "FREEDRIVE"}, {2, "READY"}, {3, "INITIALIZING"},
    {4, "SECURITY_STOPPED"}, {5, "EMERGENCY_STOPPED"}, {6, "FATAL_ERROR"}, {7, "NO_POWER"},
    {8, "NOT_CONNECTED"}, {9, "SHUTDOWN"}, {10, "SAFEGUARD_STOP"},
};

static const urrt_enum_entry joint_modes[] = {
    {235, "RESET"}, {236, "SHUTTING_DOWN"}, {237, "PART_D_CALIBRATION"}, {238, "BACKDRIVE"},
    {239, "POWER_OFF"}, {240, "READY_FOR_POWER_OFF"}, {241, "CALVAL_INITIALIZATION"}, {242, "ERROR"},
    {243, "FREEDRIVE"}, {244, "SIMULATED"}, {245, "NOT_RESPONDING"}, {246, "MOTOR_INITIALISATION"},
    {247, "BOOTING"}, {248, "PART_D_CALIBRATION_ERROR"}, {249, "BOOTLOADER"}, {250, "CALIBRATION"},
    {251, "VIOLATION"}, {252, "FAULT"}, {253, "RUNNING"}, {254, "INITIALISATION"},
    {255, "IDLE"},
};

static const urrt_enum_entry safety_modes[] = {
    {1, "NORMAL"}, {2, "REDUCED"}, {3, "PROTECTIVE_STOP"}, {4, "RECOVERY"},
    {5, "SAFEGUARD_STOP"}, {6, "SYSTEM_EMERGENCY_STOP"}, {7, "ROBOT_EMERGENCY_STOP"}, {8, "VIOLATION"},
    {9, "FAULT"}, {10, "VALIDATE_JOINT_ID"}, {11, "UNDEFINED_SAFETY_MODE"},
};

static const urrt_enum_entry safety_statuses[] = {
    {1, "NORMAL"}, {2, "REDUCED"}, {3, "PROTECTIVE_STOP"}, {4, "RECOVERY"},
    {5, "SAFEGUARD_STOP"}, {6, "SYSTEM_EMERGENCY_STOP"}, {7, "ROBOT_EMERGENCY_STOP"}, {8, "VIOLATION"},
    {9, "FAULT"}, {10, "VALIDATE_JOINT_ID"}, {11, "UNDEFINED_SAFETY_MODE"},
    {12, "AUTOMATIC_MODE_SAFEGUARD_STOP"}, {13, "SYSTEM_THREE_POSITION_ENABLING_STOP"},
};

static const urrt_enum_entry program_states[] = {
    {0, "STOPPING"}, {1, "STOPPED"}, {2, "PLAYING"}, {3, "PAUSING"}, {4, "PAUSED"}, {5, "RESUMING"},
};

#define URRT_ENTRIES(table) (*count = sizeof(table) / sizeof(table[0]), table)

const urrt_enum_entry *urrt_enum_entries(urrt_enum_kind kind, size_t *count)
{
    size_t ignored;
    if (count == NULL) {
        count = &ignored;
    }
    switch (kind) {
    case URRT_ENUM_ROBOT_MODE: return URRT_ENTRIES(robot_modes);
    case URRT_ENUM_ROBOT_MODE_1X: return URRT_ENTRIES(robot_modes_1x);
    case URRT_ENUM_JOINT_MODE: return URRT_ENTRIES(joint_modes);
    case URRT_ENUM_SAFETY_MODE: return URRT_ENTRIES(safety_modes);
    case URRT_ENUM_SAFETY_STATUS: return URRT_ENTRIES(safety_statuses);
    case URRT_ENUM_PROGRAM_STATE: return URRT_ENTRIES(program_states);
    case URRT_ENUM_NONE:
    default: *count = 0; return NULL;
    }
}

const char *urrt_enum_name(urrt_enum_kind kind, double value)
{
    size_t count;
    size_t i;
    const urrt_enum_entry *entries = urrt_enum_entries(kind, &count);
    uint64_t magnitude;
    bool negative;

    if (entries == NULL || !integral_from_bits(bits_from_double(value), &negative, &magnitude) ||
        magnitude > 0x7FFFu) {
        return URRT_UNKNOWN_NAME;
    }
    for (i = 0; i < count; i++) {
        int v = negative ? -(int)magnitude : (int)magnitude;
        if (entries[i].value == v) {
            return entries[i].name;
        }
    }
    return URRT_UNKNOWN_NAME;
}

urrt_enum_kind urrt_field_enum(urrt_field_id id, urrt_generation gen)
{
    switch (id) {
    case URRT_F_ROBOT_MODE:
        return gen == URRT_GEN_1X ? URRT_ENUM_ROBOT_MODE_1X
             : gen == URRT_GEN_3X ? URRT_ENUM_ROBOT_MODE : URRT_ENUM_NONE;
    case URRT_F_JOINT_MODES: return URRT_ENUM_JOINT_MODE;
    case URRT_F_SAFETY_MODE: return URRT_ENUM_SAFETY_MODE;
    case URRT_F_SAFETY_STATUS: return URRT_ENUM_SAFETY_STATUS;
    case URRT_F_PROGRAM_STATE: return URRT_ENUM_PROGRAM_STATE;
    default: return URRT_ENUM_NONE;
    }
}

/* ---- framing ------------------------------------------------------------ */

void urrt_framer_init(urrt_framer *fr)
{
    if (fr == NULL) {
        return;
    }
    fr->stats.bytes = 0;
    fr->stats.packets = 0;
    fr->stats.resyncs = 0;
    fr->stats.skipped = 0;
    urrt_framer_reset(fr);
}

void urrt_framer_reset(urrt_framer *fr)
{
    if (fr == NULL) {
        return;
    }
    fr->have = 0;
    fr->need = 0;
    fr->last_length = 0;
    fr->out_of_sync = false;
    fr->packet = NULL;
    fr->packet_length = 0;
}

/* A byte copy without libc: 16-byte blocks where unaligned loads and stores
 * make a fixed-size copy a few instructions (see URRT_LOAD_UNALIGNED; on
 * other targets the same builtin is a call to memcpy), then single bytes. */
static void copy_bytes(uint8_t *dst, const uint8_t *src, size_t n)
{
    size_t i = 0;
#ifdef URRT_LOAD_UNALIGNED
    for (; i + 16u <= n; i += 16u) {
        __builtin_memcpy(dst + i, src + i, 16u);
    }
#endif
    for (; i < n; i++) {
        dst[i] = src[i];
    }
}

static bool header_acceptable(const urrt_framer *fr, uint32_t size)
{
    if (size == fr->last_length && size != 0) {
        return true; /* the usual case: only plausible sizes are remembered */
    }
    if (!plausible_length(size)) {
        return false;
    }
    /* An unknown size is trusted only as the very first header of a stream:
     * found while scanning garbage, it is more likely noise than a newer
     * controller, and a bogus packet would present noise as values. */
    if (fr->last_length == 0 && !fr->out_of_sync) {
        return true;
    }
    return urrt_controller_of_length(size) != NULL;
}

static void reject_byte(urrt_framer *fr)
{
    if (!fr->out_of_sync) {
        fr->out_of_sync = true;
        fr->stats.resyncs++;
    }
    fr->stats.skipped++;
}

static void accept_header(urrt_framer *fr, uint32_t size)
{
    fr->need = size;
    fr->last_length = size;
    fr->out_of_sync = false;
}

int urrt_framer_feed(urrt_framer *fr, const uint8_t *data, size_t len, size_t *used_out)
{
    size_t used = 0;

    if (fr == NULL || used_out == NULL || (data == NULL && len != 0)) {
        return URRT_E_ARG;
    }
    if (len >= URRT_HEADER_SIZE && (fr->need | fr->have) == 0) {
        /* The usual read first: it starts with a whole packet of the last
         * accepted size, taken where it lies (what the loop below does for
         * it, without the loop). */
        uint32_t size = load_be32(data);
        if (size == fr->last_length && size != 0 && len >= size) {
            fr->packet = data;
            fr->packet_length = size;
            fr->stats.bytes += size;
            fr->stats.packets++;
            *used_out = size;
            return 1;
        }
    }
    fr->packet = NULL;
    fr->packet_length = 0;
    while (used < len) {
        if (fr->need == 0 && fr->have == 0 && len - used >= URRT_HEADER_SIZE) {
            /* Header straight from the caller's bytes: no copy for whole packets. */
            uint32_t size = load_be32(data + used);
            if (!header_acceptable(fr, size)) {
                reject_byte(fr);
                used++;
                continue;
            }
            accept_header(fr, size);
            if (len - used >= size) {
                fr->packet = data + used;
                fr->packet_length = size;
                fr->need = 0;
                used += size;
                break;
            }
        } else if (fr->need == 0) {
            uint32_t size;
            fr->buf[fr->have++] = data[used++];
            if (fr->have < URRT_HEADER_SIZE) {
                continue;
            }
            size = load_be32(fr->buf);
            if (!header_acceptable(fr, size)) {
                reject_byte(fr);
                fr->buf[0] = fr->buf[1];
                fr->buf[1] = fr->buf[2];
                fr->buf[2] = fr->buf[3];
                fr->have = URRT_HEADER_SIZE - 1u;
                continue;
            }
            accept_header(fr, size);
        }
        {
            size_t take = fr->need - fr->have;
            if (take > len - used) {
                take = len - used;
            }
            copy_bytes(fr->buf + fr->have, data + used, take);
            fr->have += (uint32_t)take;
            used += take;
        }
        if (fr->have == fr->need) {
            fr->packet = fr->buf;
            fr->packet_length = fr->need;
            fr->have = 0;
            fr->need = 0;
            break;
        }
    }
    fr->stats.bytes += used;
    *used_out = used;
    if (fr->packet != NULL) {
        fr->stats.packets++;
        return 1;
    }
    return 0;
}

const uint8_t *urrt_framer_packet(const urrt_framer *fr, size_t *len)
{
    if (fr == NULL || fr->packet == NULL) {
        if (len != NULL) {
            *len = 0;
        }
        return NULL;
    }
    if (len != NULL) {
        *len = fr->packet_length;
    }
    return fr->packet;
}

size_t urrt_framer_finish(urrt_framer *fr)
{
    size_t pending;
    if (fr == NULL) {
        return 0;
    }
    pending = fr->have;
    urrt_framer_reset(fr);
    return pending;
}
