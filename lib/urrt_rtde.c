/* SPDX-License-Identifier: MIT */
/* urrt_rtde: a read-only RTDE client without I/O. See urrt_rtde.h for the
 * API and docs/rtde.md for the wire format, the errors and the bounds. */
#include "urrt_rtde.h"

#define RTDE_STATIC_ASSERT(name, cond) typedef char urrt_rtde_assert_##name[(cond) ? 1 : -1]

RTDE_STATIC_ASSERT(double_is_binary64, sizeof(double) == 8);
RTDE_STATIC_ASSERT(state_offsets_fit, sizeof(urrt_state) <= 0xFFFF);
RTDE_STATIC_ASSERT(values_offsets_fit, sizeof(urrt_rtde_values) <= 0xFFFF);
RTDE_STATIC_ASSERT(package_size_fits, URRT_RTDE_PACKAGE_MAX <= 0xFFFF);
/* A setup reply for the most variables (14 bytes per type and comma) and
 * a protocol-2 text message (1 + 255 + 1 + 255 + 1) fit the buffer. */
RTDE_STATIC_ASSERT(setup_reply_fits, 4 + 14 * URRT_RTDE_MAX_VARS <= URRT_RTDE_PACKAGE_MAX);
RTDE_STATIC_ASSERT(text_fits, 3 + 513 <= URRT_RTDE_PACKAGE_MAX);
RTDE_STATIC_ASSERT(not_found_bits, URRT_RTDE_MAX_VARS % 8 == 0);
RTDE_STATIC_ASSERT(vars_fit_ids, URRT_RTDE_VAR_COUNT <= 0xFFFF);

/* Each mapped variable fills a whole urrt_state member. */
#define X_SIZE_CHECK(ID, name, TYPE, FIELD, member, since) \
    RTDE_STATIC_ASSERT(size_##member, sizeof(((urrt_state *)0)->member) == 8 * URRT_RTDE_COUNT_##TYPE);
URRT_RTDE_MAPPED(X_SIZE_CHECK)
#undef X_SIZE_CHECK

/* A value in urrt_rtde_values takes as many bytes as on the wire, so the
 * names of a family sit type_size apart. */
#define X_CSIZE_CHECK(ID, member, name, TYPE, first, names, split, since, since_hi) \
    RTDE_STATIC_ASSERT(csize_##member, sizeof(((urrt_rtde_values *)0)->member) == \
                                           (names) * sizeof(URRT_RTDE_CTYPE_##TYPE) * URRT_RTDE_COUNT_##TYPE);
URRT_RTDE_ONLY(X_CSIZE_CHECK)
#undef X_CSIZE_CHECK

#define RTDE_NAN_BITS UINT64_C(0x7FF8000000000000)

/* ---- tables ------------------------------------------------------------- */

typedef struct type_info {
    const char *name;
    uint8_t size;  /* bytes on the wire */
    uint8_t count; /* elements */
} type_info;

static const type_info type_table[URRT_RTDE_T_COUNT] = {
    {0, 0, 0},
    {"BOOL", 1, 1},
    {"UINT8", 1, 1},
    {"UINT32", 4, 1},
    {"UINT64", 8, 1},
    {"INT32", 4, 1},
    {"DOUBLE", 8, 1},
    {"VECTOR3D", 24, 3},
    {"VECTOR6D", 48, 6},
    {"VECTOR6INT32", 24, 6},
    {"VECTOR6UINT32", 24, 6},
};

#define SINCE_INIT_(cb3, e, x) {cb3, e, x}
#define SINCE_INIT(triple) SINCE_INIT_ triple

typedef struct mapped_row {
    const char *name;
    uint32_t since[3];
    uint16_t offset; /* in urrt_state */
    uint8_t type;
    uint8_t field;
} mapped_row;

static const mapped_row mapped_table[URRT_RTDE_MAPPED_COUNT] = {
#define X_MAPPED(ID, name, TYPE, FIELD, member, since) \
    {name, SINCE_INIT(since), (uint16_t)offsetof(urrt_state, member), URRT_RTDE_T_##TYPE, URRT_F_##FIELD},
    URRT_RTDE_MAPPED(X_MAPPED)
#undef X_MAPPED
};

typedef struct only_row {
    const char *name;
    uint32_t since[3];
    uint32_t since_hi[3]; /* of indexes first + split and later */
    uint16_t offset;      /* in urrt_rtde_values */
    uint16_t var;         /* id of the first name */
    uint8_t type;
    uint8_t first;
    uint8_t names;
    uint8_t split;
} only_row;

#define ONLY_ROWS (sizeof(only_table) / sizeof(only_table[0]))

static const only_row only_table[] = {
#define X_ONLY(ID, member, name, TYPE, first, names, split, since, since_hi)                           \
    {name, SINCE_INIT(since), SINCE_INIT(since_hi), (uint16_t)offsetof(urrt_rtde_values, member), \
     URRT_RTDE_V_##ID, URRT_RTDE_T_##TYPE, first, names, split},
    URRT_RTDE_ONLY(X_ONLY)
#undef X_ONLY
};

/* urrt_state's fields are doubles back to back from its start up to
 * present: the clear at URRT_RTDE_EV_RECIPE writes NaN over all of them. */
#define X_STATE_DOUBLES(ID, name, count, c1, c3, unit, since, desc) +(count)
enum { STATE_DOUBLES = 0 URRT_FIELDS(X_STATE_DOUBLES) };
#undef X_STATE_DOUBLES
RTDE_STATIC_ASSERT(state_doubles_first, offsetof(urrt_state, present) == 8u * STATE_DOUBLES);
RTDE_STATIC_ASSERT(present_words, URRT_RTDE_PRESENT_WORDS * 32 >= URRT_RTDE_ONLY_COUNT &&
                                       URRT_RTDE_PRESENT_WORDS % 4 == 0);

/* A function kept out of its caller, where GCC or clang would inline it
 * (or GCC clone it with fewer arguments): the caller's usual path then
 * does not pay for its registers. */
#if defined(__GNUC__) && !defined(__clang__)
#define RTDE_NOINLINE __attribute__((noinline, noclone))
#elif defined(__GNUC__)
#define RTDE_NOINLINE __attribute__((noinline))
#else
#define RTDE_NOINLINE
#endif

/* A function GCC and clang must inline, where their estimate would keep one
 * copy called from two places and its caller would save registers for it;
 * not when optimizing for size (-Os), which the copies would undo. */
#if defined(__GNUC__) && !defined(__OPTIMIZE_SIZE__)
#define RTDE_INLINE inline __attribute__((always_inline))
#else
#define RTDE_INLINE inline
#endif

/* ---- bytes ----------------------------------------------------------------- */

typedef union rtde_bits {
    uint64_t u;
    double d;
} rtde_bits;

static uint16_t load_be16(const uint8_t *p)
{
    return (uint16_t)((unsigned)p[0] << 8 | (unsigned)p[1]);
}

/* As urrt.c loads: one load and a byte swap where GCC or clang may load
 * unaligned (little-endian x86, AArch64, ARM with unaligned access), bytes
 * elsewhere (a __builtin_memcpy of unaligned bytes may be a memcpy call
 * there, which lib/ must not need). Inline: the decode walks these. */
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__)
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#if defined(__x86_64__) || defined(__i386__) || defined(__aarch64__) || defined(__ARM_FEATURE_UNALIGNED)
#define RTDE_LOAD_UNALIGNED 1
#endif
#endif
#endif

#ifdef RTDE_LOAD_UNALIGNED
static inline uint32_t load_be32(const uint8_t *p)
{
    uint32_t v;
    __builtin_memcpy(&v, p, sizeof v);
    return __builtin_bswap32(v);
}

static inline uint64_t load_be64(const uint8_t *p)
{
    uint64_t v;
    __builtin_memcpy(&v, p, sizeof v);
    return __builtin_bswap64(v);
}
#else
static inline uint32_t load_be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

static inline uint64_t load_be64(const uint8_t *p)
{
    return (uint64_t)load_be32(p) << 32 | (uint64_t)load_be32(p + 4);
}
#endif

static inline double load_double(const uint8_t *p)
{
    rtde_bits b;
    b.u = load_be64(p);
    return b.d;
}

/* n bytes from src to dst (distinct buffers): 8 at a time where loads may
 * be unaligned (a fixed-size __builtin_memcpy is then one load and one
 * store, never a call), then single bytes. Its own pointers and count: no
 * store through a byte pointer makes it reload a session's counters. */
static void copy_bytes(uint8_t *dst, const uint8_t *src, size_t n)
{
    size_t i = 0;
#ifdef RTDE_LOAD_UNALIGNED
    for (; i + 8u <= n; i += 8u) {
        __builtin_memcpy(dst + i, src + i, 8u);
    }
#endif
    for (; i < n; i++) {
        dst[i] = src[i];
    }
}

/* A data package's first four bytes as one word, in the host's order where
 * loads may be unaligned, else assembled (either way as compile_recipe
 * computes the expected one). */
static uint32_t load_head(const uint8_t *p)
{
#ifdef RTDE_LOAD_UNALIGNED
    uint32_t v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
#else
    return load_be32(p);
#endif
}

static void store_be16(uint8_t *p, unsigned v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

/* ---- results --------------------------------------------------------------- */

const char *urrt_rtde_strerror(int result)
{
    switch (result) {
    case URRT_RTDE_E_SIZE_SMALL: return "package size below its 3-byte header";
    case URRT_RTDE_E_SIZE_LARGE: return "package size past the largest accepted";
    case URRT_RTDE_E_REPLY_LENGTH: return "reply length does not match its layout";
    case URRT_RTDE_E_REPLY_VALUE: return "accepted flag neither 0 nor 1";
    case URRT_RTDE_E_VERSION_ZERO: return "controller version 0.0.0.0";
    case URRT_RTDE_E_DATA_EARLY: return "data package before a recipe was accepted";
    case URRT_RTDE_E_RECIPE_ID: return "data package of another recipe";
    case URRT_RTDE_E_DATA_SIZE: return "data package size differs from the recipe's";
    case URRT_RTDE_E_TYPE_TOKEN: return "setup reply holds a word that is no type";
    case URRT_RTDE_E_TYPE_COUNT: return "setup reply has more or fewer types than names";
    case URRT_RTDE_E_TEXT_LENGTH: return "text message lengths do not fill the package";
    case URRT_RTDE_E_PAUSE_REFUSED: return "controller refused to pause";
    case URRT_RTDE_E_ENDED: return "session ended: begin a new one";
    case URRT_RTDE_E_NOT_FOUND: return "controller does not have some of the variables";
    case URRT_RTDE_E_TYPE_MISMATCH: return "controller's type for a variable is not urrt's";
    case URRT_RTDE_E_PROTOCOL_REFUSED: return "controller refused protocol versions 2 and 1";
    case URRT_RTDE_E_START_REFUSED: return "controller refused to start the recipe";
    case URRT_RTDE_E_FREQUENCY: return "frequency past the controller's maximum";
    case URRT_RTDE_E_IN_USE: return "input registers another client or a fieldbus owns";
    case URRT_RTDE_E_INPUTS_PROTOCOL: return "inputs need protocol 2; the controller speaks 1 only";
    case URRT_RTDE_E_NAMES_TOO_LONG: return "name list past 2048 bytes";
    case URRT_RTDE_E_NOT_WRITABLE: return "not a general purpose input register";
    case URRT_RTDE_E_DUPLICATE: return "variable asked for twice";
    case URRT_RTDE_E_UNKNOWN_NAME: return "no RTDE output of that name";
    case URRT_RTDE_E_SCRIPT_PORT: return "port runs what it receives (URScript, dashboard) or is its read-only "
                                         "twin: RTDE is port 30004";
    case URRT_RTDE_E_VALUE: return "value its register cannot hold (refused, not clamped)";
    case URRT_RTDE_E_NOT_STARTED: return "input package before its recipe is accepted and streaming";
    case URRT_RTDE_E_INCOMPLETE: return "input package while a register has no value";
    default: return urrt_strerror(result);
    }
}

bool urrt_rtde_is_config_error(int result)
{
    return result <= URRT_RTDE_E_NOT_FOUND && result >= URRT_RTDE_E_INPUTS_PROTOCOL;
}

/* ---- ports ------------------------------------------------------------------ */

/* The controller's servers an RTDE client never writes to (the header says
 * why each). Named arrays, not literals: literals share one section with
 * the variable names, which a read-only firmware keeps, while these are
 * dropped (--gc-sections) unless the table is used. */
static const char role_dashboard[] = "the dashboard server, which runs the commands it receives";
static const char role_primary[] = "the primary client interface, which runs the URScript it receives";
static const char role_secondary[] = "the secondary client interface, which runs the URScript it receives";
static const char role_realtime[] = "the RealTime interface, which runs the URScript it receives";
static const char role_primary_ro[] = "the primary client interface's read-only twin";
static const char role_secondary_ro[] = "the secondary client interface's read-only twin";
static const char role_realtime_ro[] = "the RealTime interface's read-only twin";
static const char role_interpreter[] = "the interpreter mode's socket, which runs the URScript it receives";
static const struct {
    uint16_t port;
    const char *role;
} script_ports[] = {
    {29999u, role_dashboard},   {30001u, role_primary},      {30002u, role_secondary},
    {30003u, role_realtime},    {30011u, role_primary_ro},   {30012u, role_secondary_ro},
    {30013u, role_realtime_ro}, {30020u, role_interpreter},
};

const char *urrt_rtde_port_role(uint32_t port)
{
    size_t i;
    for (i = 0; i < sizeof script_ports / sizeof script_ports[0]; i++) {
        if (script_ports[i].port == port) {
            return script_ports[i].role;
        }
    }
    return 0;
}

int urrt_rtde_check_port(uint32_t port)
{
    return urrt_rtde_port_role(port) == 0 ? URRT_OK : URRT_RTDE_E_SCRIPT_PORT;
}

/* ---- types and variables -------------------------------------------------- */

const char *urrt_rtde_type_name(urrt_rtde_type type)
{
    return (unsigned)type < (unsigned)URRT_RTDE_T_COUNT ? type_table[type].name : 0;
}

unsigned urrt_rtde_type_size(urrt_rtde_type type)
{
    return (unsigned)type < (unsigned)URRT_RTDE_T_COUNT ? type_table[type].size : 0u;
}

/* The RTDE-only row of a variable, NULL for mapped ones and ids out of range. */
static const only_row *only_row_of(int var)
{
    size_t i;
    if (var < (int)URRT_RTDE_MAPPED_COUNT || var >= (int)URRT_RTDE_VAR_COUNT) {
        return 0;
    }
    for (i = ONLY_ROWS; i-- > 0;) {
        if (var >= (int)only_table[i].var) {
            return &only_table[i];
        }
    }
    return 0;
}

static size_t text_length(const char *s)
{
    size_t n = 0;
    while (s[n] != '\0') {
        n++;
    }
    return n;
}

/* n bytes of a equal b's first n, and b ends there if whole is set. */
static bool same_prefix(const char *a, size_t n, const char *b, bool whole)
{
    size_t i;
    for (i = 0; i < n; i++) {
        if (b[i] == '\0' || a[i] != b[i]) {
            return false;
        }
    }
    return !whole || b[n] == '\0';
}

/* Decimal digits without a leading zero (except "0"), at most 3; -1 else. */
static int parse_index(const char *p, size_t n)
{
    int v = 0;
    size_t i;
    if (n == 0 || n > 3 || (n > 1 && p[0] == '0')) {
        return -1;
    }
    for (i = 0; i < n; i++) {
        if (p[i] < '0' || p[i] > '9') {
            return -1;
        }
        v = v * 10 + (p[i] - '0');
    }
    return v;
}

int urrt_rtde_var_find(const char *name, size_t len)
{
    size_t i;
    if (name == 0) {
        return URRT_E_ARG;
    }
    for (i = 0; i < (size_t)URRT_RTDE_MAPPED_COUNT; i++) {
        if (same_prefix(name, len, mapped_table[i].name, true)) {
            return (int)i;
        }
    }
    for (i = 0; i < ONLY_ROWS; i++) {
        const only_row *r = &only_table[i];
        size_t plen = text_length(r->name);
        int index;
        if (r->names == 1) {
            if (same_prefix(name, len, r->name, true)) {
                return r->var;
            }
            continue;
        }
        if (len <= plen || !same_prefix(name, plen, r->name, true)) {
            continue;
        }
        index = parse_index(name + plen, len - plen);
        if (index >= r->first && index < r->first + r->names) {
            return r->var + index - r->first;
        }
    }
    return URRT_RTDE_E_UNKNOWN_NAME;
}

/* Writes the name of var (no NUL) into out when out is not NULL; returns
 * its length, or 0 for an id out of range. */
static size_t put_name(int var, char *out)
{
    const only_row *r = only_row_of(var);
    const char *base;
    size_t n;
    char digits[3];
    unsigned index, d = 0;
    if (var >= 0 && var < (int)URRT_RTDE_MAPPED_COUNT) {
        base = mapped_table[var].name;
    } else if (r != 0) {
        base = r->name;
    } else {
        return 0;
    }
    for (n = 0; base[n] != '\0'; n++) {
        if (out != 0) {
            out[n] = base[n];
        }
    }
    if (r == 0 || r->names == 1) {
        return n;
    }
    index = (unsigned)r->first + (unsigned)(var - r->var);
    do {
        digits[d++] = (char)('0' + index % 10u);
        index /= 10u;
    } while (index != 0);
    while (d > 0) {
        char c = digits[--d];
        if (out != 0) {
            out[n] = c;
        }
        n++;
    }
    return n;
}

int urrt_rtde_var_name(int var, char *out, size_t cap)
{
    size_t n = put_name(var, 0);
    if (out == 0 || n == 0) {
        return URRT_E_ARG;
    }
    if (n + 1 > cap) {
        return URRT_E_NO_SPACE;
    }
    put_name(var, out);
    out[n] = '\0';
    return (int)n;
}

urrt_rtde_type urrt_rtde_var_type(int var)
{
    const only_row *r = only_row_of(var);
    if (var >= 0 && var < (int)URRT_RTDE_MAPPED_COUNT) {
        return (urrt_rtde_type)mapped_table[var].type;
    }
    return r != 0 ? (urrt_rtde_type)r->type : URRT_RTDE_T_NONE;
}

int urrt_rtde_var_field(int var)
{
    return var >= 0 && var < (int)URRT_RTDE_MAPPED_COUNT ? (int)mapped_table[var].field : -1;
}

int urrt_rtde_var_of_field(urrt_field_id field)
{
    int i;
    for (i = 0; i < (int)URRT_RTDE_MAPPED_COUNT; i++) {
        if (mapped_table[i].field == (unsigned)field) {
            return i;
        }
    }
    return -1;
}

int urrt_rtde_var_available(int var, uint32_t major, uint32_t minor, uint32_t bugfix)
{
    const only_row *r = only_row_of(var);
    const uint32_t *since;
    uint32_t line, have, need;
    if (var >= 0 && var < (int)URRT_RTDE_MAPPED_COUNT) {
        since = mapped_table[var].since;
    } else if (r != 0) {
        since = var - r->var >= r->split ? r->since_hi : r->since;
    } else {
        return URRT_E_ARG;
    }
    if (major < 3) {
        return 0;
    }
    line = major == 3 ? 0u : major < 10 ? 1u : 2u;
    need = since[line];
    if (need == URRT_RTDE_UNSTATED) {
        return URRT_RTDE_UNKNOWN;
    }
    if (need == URRT_RTDE_NEVER) {
        return 0;
    }
    have = URRT_RTDE_VER(major > 255 ? 255 : major, minor > 255 ? 255 : minor, bugfix > 255 ? 255 : bugfix);
    return have >= need ? 1 : 0;
}

/* count doubles at d set to NaN, four at a time (GCC and clang join the
 * stores into the widest the build has). */
static void fill_nan(double *d, size_t count)
{
    rtde_bits nan;
    size_t k;
    nan.u = RTDE_NAN_BITS;
    for (k = 0; k + 4 <= count; k += 4) {
        d[k] = nan.d;
        d[k + 1] = nan.d;
        d[k + 2] = nan.d;
        d[k + 3] = nan.d;
    }
    for (; k < count; k++) {
        d[k] = nan.d;
    }
}

/* Every member of *v by its row: the doubles NaN, the integers 0, in their
 * own types (a byte loop of unknown length would be a call to memset). */
void urrt_rtde_values_clear(urrt_rtde_values *v)
{
    size_t i, k;
    if (v == 0) {
        return;
    }
    for (i = 0; i < ONLY_ROWS; i++) {
        const only_row *r = &only_table[i];
        unsigned char *d = (unsigned char *)v + r->offset;
        size_t n = (size_t)r->names * type_table[r->type].count;
        switch (type_table[r->type].size / type_table[r->type].count) {
        case 8:
            if (r->type == URRT_RTDE_T_UINT64) {
                for (k = 0; k < n; k++) {
                    ((uint64_t *)(void *)d)[k] = 0;
                }
            } else {
                fill_nan((double *)(void *)d, n);
            }
            break;
        case 4:
            for (k = 0; k < n; k++) {
                ((uint32_t *)(void *)d)[k] = 0;
            }
            break;
        default:
            for (k = 0; k < n; k++) {
                d[k] = 0;
            }
            break;
        }
    }
    for (i = 0; i < URRT_RTDE_PRESENT_WORDS; i++) {
        v->present[i] = 0;
    }
}

/* *st as urrt_state_clear leaves it (without linking urrt.c's table). */
static void state_clear(urrt_state *st)
{
    fill_nan((double *)(void *)st, STATE_DOUBLES);
    st->present = 0;
    st->length = 0;
    st->doubles = 0;
    st->extra_columns = 0;
    st->generation = URRT_GEN_UNKNOWN;
}

/* Where an RTDE-only variable sits in urrt_rtde_values: a family's values
 * are back to back, each as big as on the wire (checked above). */
static unsigned value_offset(const only_row *r, int var)
{
    return r->offset + (unsigned)(var - r->var) * type_table[r->type].size;
}

const void *urrt_rtde_value(const urrt_rtde_values *v, int var)
{
    const only_row *r = only_row_of(var);
    if (v == 0 || r == 0) {
        return 0;
    }
    return (const unsigned char *)v + value_offset(r, var);
}

/* ---- requests ---------------------------------------------------------- */

static int write_header_only(uint8_t *out, size_t cap, uint8_t type)
{
    if (out == 0) {
        return URRT_E_ARG;
    }
    if (cap < URRT_RTDE_HEADER_SIZE) {
        return URRT_E_NO_SPACE;
    }
    store_be16(out, URRT_RTDE_HEADER_SIZE);
    out[2] = type;
    return URRT_RTDE_HEADER_SIZE;
}

int urrt_rtde_write_protocol_version(uint8_t *out, size_t cap, uint16_t version)
{
    if (out == 0) {
        return URRT_E_ARG;
    }
    if (cap < 5) {
        return URRT_E_NO_SPACE;
    }
    store_be16(out, 5);
    out[2] = URRT_RTDE_TYPE_PROTOCOL_VERSION;
    store_be16(out + 3, version);
    return 5;
}

int urrt_rtde_write_controller_version(uint8_t *out, size_t cap)
{
    return write_header_only(out, cap, URRT_RTDE_TYPE_CONTROLLER_VERSION);
}

int urrt_rtde_write_start(uint8_t *out, size_t cap)
{
    return write_header_only(out, cap, URRT_RTDE_TYPE_START);
}

int urrt_rtde_write_pause(uint8_t *out, size_t cap)
{
    return write_header_only(out, cap, URRT_RTDE_TYPE_PAUSE);
}

/* Bytes of the comma-separated name list; 0 for an id out of range. */
static size_t names_length(const uint16_t *vars, size_t count)
{
    size_t i, total = count - 1;
    for (i = 0; i < count; i++) {
        size_t n = put_name(vars[i], 0);
        if (n == 0) {
            return 0;
        }
        total += n;
    }
    return total;
}

int urrt_rtde_write_setup_outputs(uint8_t *out, size_t cap, unsigned protocol, double frequency,
                                  const uint16_t *vars, size_t count)
{
    size_t names, size, at, i;
    if (out == 0 || vars == 0 || count == 0 || count > URRT_RTDE_MAX_VARS ||
        (protocol != 1 && protocol != 2) || !(frequency >= 0.0)) {
        return URRT_E_ARG;
    }
    names = names_length(vars, count);
    if (names == 0) {
        return URRT_E_ARG;
    }
    if (names > URRT_RTDE_NAMES_MAX) {
        return URRT_RTDE_E_NAMES_TOO_LONG;
    }
    size = URRT_RTDE_HEADER_SIZE + (protocol == 2 ? 8u : 0u) + names;
    if (cap < size) {
        return URRT_E_NO_SPACE;
    }
    store_be16(out, (unsigned)size);
    out[2] = URRT_RTDE_TYPE_SETUP_OUTPUTS;
    at = URRT_RTDE_HEADER_SIZE;
    if (protocol == 2) {
        rtde_bits f;
        unsigned k;
        f.d = frequency;
        for (k = 0; k < 8; k++) {
            out[at++] = (uint8_t)(f.u >> (56u - 8u * k));
        }
    }
    for (i = 0; i < count; i++) {
        if (i > 0) {
            out[at++] = ',';
        }
        at += put_name(vars[i], (char *)(out + at));
    }
    return (int)size;
}

/* ---- the session ---------------------------------------------------------- */

enum rtde_phase {
    PH_IDLE = 0,    /* before begin, after finish */
    PH_PROTOCOL,    /* waiting for the V reply */
    PH_CONTROLLER,  /* waiting for the v reply */
    PH_SETUP,       /* waiting for the O reply */
    PH_START,       /* waiting for the S reply (a data package also starts) */
    PH_STREAMING,
    PH_PAUSE,       /* waiting for the P reply */
    PH_PAUSED,
    PH_ENDED        /* an error ended the session */
};

enum rtde_request { REQ_NONE = 0, REQ_PROTOCOL, REQ_CONTROLLER, REQ_SETUP, REQ_START, REQ_PAUSE };

void urrt_rtde_init(urrt_rtde *s)
{
    unsigned char *p = (unsigned char *)s;
    size_t i;
    if (s == 0) {
        return;
    }
    for (i = 0; i < sizeof *s; i++) {
        p[i] = 0;
    }
}

/* Checks the variables of a recipe and notes what they fill. */
static int check_vars(urrt_rtde *s, const uint16_t *vars, size_t count)
{
    size_t i, j;
    if (names_length(vars, count) > URRT_RTDE_NAMES_MAX) {
        return URRT_RTDE_E_NAMES_TOO_LONG;
    }
    s->state_present = 0;
    s->has_values = 0;
    s->has_state = 0;
    for (i = 0; i < count; i++) {
        for (j = 0; j < i; j++) {
            if (vars[j] == vars[i]) {
                return URRT_RTDE_E_DUPLICATE;
            }
        }
        if (vars[i] < URRT_RTDE_MAPPED_COUNT) {
            s->state_present |= UINT64_C(1) << mapped_table[vars[i]].field;
            s->has_state = 1;
        } else {
            s->has_values = 1;
        }
    }
    return URRT_OK; /* its data package fits URRT_RTDE_PACKAGE_MAX: any recipe's does */
}

int urrt_rtde_begin(urrt_rtde *s, const uint16_t *vars, size_t count, double frequency)
{
    size_t i;
    int r;
    if (s == 0) {
        return URRT_E_ARG;
    }
    s->phase = PH_IDLE;
    s->pending = REQ_NONE;
    if (vars == 0 || count == 0 || count > URRT_RTDE_MAX_VARS || !(frequency >= 0.0 && frequency <= 1e6)) {
        return URRT_E_ARG;
    }
    for (i = 0; i < count; i++) {
        if (vars[i] >= URRT_RTDE_VAR_COUNT) {
            return URRT_E_ARG;
        }
    }
    r = check_vars(s, vars, count);
    if (r < 0) {
        return r;
    }
    for (i = 0; i < count; i++) {
        s->vars[i] = vars[i];
    }
    for (i = 0; i < sizeof s->not_found; i++) {
        s->not_found[i] = 0;
    }
    s->var_count = (uint16_t)count;
    s->frequency = frequency;
    s->data_size = 0;
    s->head = 1; /* no data package matches before a recipe is compiled */
    s->head_mask = 0;
    s->have = 0;
    s->need = 0;
    s->error = 0;
    s->up = 0;
    s->recipe_id = 0;
    s->protocol = URRT_RTDE_PROTOCOL;
    s->protocol_accepted = 0;
    for (i = 0; i < 4; i++) {
        s->controller[i] = 0;
    }
    s->phase = PH_PROTOCOL;
    s->pending = REQ_PROTOCOL;
    return URRT_OK;
}

int urrt_rtde_set_recipe(urrt_rtde *s, const uint16_t *vars, size_t count)
{
    uint64_t state_present;
    uint8_t has_values, has_state;
    size_t i;
    int r;
    if (s == 0 || s->phase != PH_SETUP || s->pending != REQ_SETUP || vars == 0 || count == 0 ||
        count > URRT_RTDE_MAX_VARS) {
        return URRT_E_ARG;
    }
    for (i = 0; i < count; i++) {
        if (vars[i] >= URRT_RTDE_VAR_COUNT) {
            return URRT_E_ARG;
        }
    }
    state_present = s->state_present;
    has_values = s->has_values;
    has_state = s->has_state;
    r = check_vars(s, vars, count);
    if (r < 0) {
        s->state_present = state_present;
        s->has_values = has_values;
        s->has_state = has_state;
        return r;
    }
    for (i = 0; i < count; i++) {
        s->vars[i] = vars[i];
    }
    s->var_count = (uint16_t)count;
    return URRT_OK;
}

static double max_frequency(const urrt_rtde *s)
{
    return s->controller[0] < 5 ? URRT_RTDE_HZ_CB3 : URRT_RTDE_HZ_E_SERIES;
}

double urrt_rtde_max_frequency(const urrt_rtde *s)
{
    return s != 0 ? max_frequency(s) : 0.0;
}

int urrt_rtde_output(urrt_rtde *s, uint8_t *out, size_t cap)
{
    int n;
    if (s == 0 || out == 0) {
        return URRT_E_ARG;
    }
    switch (s->pending) {
    case REQ_PROTOCOL: n = urrt_rtde_write_protocol_version(out, cap, s->protocol); break;
    case REQ_CONTROLLER: n = urrt_rtde_write_controller_version(out, cap); break;
    case REQ_SETUP:
        n = urrt_rtde_write_setup_outputs(out, cap, s->protocol_accepted,
                                          s->frequency > 0.0 ? s->frequency : max_frequency(s), s->vars,
                                          s->var_count);
        break;
    case REQ_START: n = urrt_rtde_write_start(out, cap); break;
    case REQ_PAUSE: n = urrt_rtde_write_pause(out, cap); break;
    default: return 0;
    }
    if (n > 0) {
        s->pending = REQ_NONE;
    }
    return n;
}

int urrt_rtde_pause(urrt_rtde *s)
{
    if (s == 0 || s->phase != PH_STREAMING || s->pending != REQ_NONE) {
        return URRT_E_ARG;
    }
    s->phase = PH_PAUSE;
    s->pending = REQ_PAUSE;
    return URRT_OK;
}

int urrt_rtde_start(urrt_rtde *s)
{
    if (s == 0 || s->phase != PH_PAUSED || s->pending != REQ_NONE) {
        return URRT_E_ARG;
    }
    s->phase = PH_START;
    s->pending = REQ_START;
    return URRT_OK;
}

bool urrt_rtde_up(const urrt_rtde *s)
{
    return s != 0 && s->up != 0;
}

/* The writing side's view of the handshake (urrt_rtde_in.c): nothing in
 * this file calls these three, so a read-only image links none of them. */
int urrt_rtde_due(const urrt_rtde *s)
{
    if (s == 0) {
        return 0;
    }
    switch (s->pending) {
    case REQ_PROTOCOL: return URRT_RTDE_TYPE_PROTOCOL_VERSION;
    case REQ_CONTROLLER: return URRT_RTDE_TYPE_CONTROLLER_VERSION;
    case REQ_SETUP: return URRT_RTDE_TYPE_SETUP_OUTPUTS;
    case REQ_START: return URRT_RTDE_TYPE_START;
    case REQ_PAUSE: return URRT_RTDE_TYPE_PAUSE;
    default: return 0;
    }
}

bool urrt_rtde_streaming(const urrt_rtde *s)
{
    return s != 0 && s->phase == PH_STREAMING;
}

static int end_session(urrt_rtde *s, urrt_rtde_event *ev, int error);

int urrt_rtde_end(urrt_rtde *s, urrt_rtde_event *ev, int error)
{
    if (s == 0 || ev == 0 || error >= 0) {
        return URRT_E_ARG;
    }
    return end_session(s, ev, error);
}

int urrt_rtde_not_found(const urrt_rtde *s, size_t i)
{
    size_t k;
    if (s == 0) {
        return -1;
    }
    for (k = 0; k < s->var_count; k++) {
        if (((unsigned)s->not_found[k / 8] >> (k % 8)) & 1u) {
            if (i == 0) {
                return s->vars[k];
            }
            i--;
        }
    }
    return -1;
}

size_t urrt_rtde_finish(urrt_rtde *s)
{
    size_t dropped;
    if (s == 0) {
        return 0;
    }
    dropped = s->have;
    s->have = 0;
    s->need = 0;
    s->phase = PH_IDLE;
    s->pending = REQ_NONE;
    return dropped;
}

/* ---- data packages ---------------------------------------------------------- */

/* How an entry's elements are converted (urrt_rtde_entry.op). The two usual
 * conversions, doubles and 32-bit values, carry their entry's count in the
 * op where it is at most RUN_MAX (OP_F64_1 + count - 1, OP_X32_1 + count - 1:
 * a variable, or a short run): the decode reaches the code for exactly that
 * many values by one switch over the op's low bits, which covers every value
 * they can have (so no range test either). A longer run keeps OP_F64 or
 * OP_X32 and is converted by a loop. compile_recipe sets them when the recipe
 * is accepted. */
#define RUN_MAX 8
enum rtde_op {
    OP_F64_1 = 0,          /* 1..RUN_MAX doubles into doubles */
    OP_X32_1 = RUN_MAX,    /* 1..RUN_MAX 32-bit values into int32_t or uint32_t */
    OP_F64 = 2 * RUN_MAX,  /* doubles into doubles (urrt_state or urrt_rtde_values) */
    OP_X32,                /* 32 bits into int32_t or uint32_t of urrt_rtde_values */
    OP_I32_F64,            /* an int32 into a double of urrt_state */
    OP_U32_F64,            /* a uint32 into a double of urrt_state */
    OP_U64_F64,            /* a uint64 into a double of urrt_state */
    OP_U64,                /* 64 bits into a uint64_t of urrt_rtde_values */
    OP_U8,                 /* a byte into urrt_rtde_values */
    OP_BOOL                /* a byte into urrt_rtde_values as 0 or 1 */
};
#define SHORT_OPS (2 * RUN_MAX) /* the ops below it carry a count; a power of two */
RTDE_STATIC_ASSERT(short_ops, (SHORT_OPS & (SHORT_OPS - 1)) == 0);
RTDE_STATIC_ASSERT(ops_fit, OP_BOOL <= 0xFF);

static int32_t to_int32(uint32_t u)
{
    return u >= UINT32_C(0x80000000) ? -(int32_t)(~u) - 1 : (int32_t)u;
}

/* n doubles from the wire at p into d, a run longer than RUN_MAX: eight at
 * a time, then the last ones by four, two and one. */
static RTDE_NOINLINE void swap_doubles(double *d, const uint8_t *p, size_t n)
{
    for (; n >= 8; n -= 8, d += 8, p += 64) {
        d[0] = load_double(p);
        d[1] = load_double(p + 8);
        d[2] = load_double(p + 16);
        d[3] = load_double(p + 24);
        d[4] = load_double(p + 32);
        d[5] = load_double(p + 40);
        d[6] = load_double(p + 48);
        d[7] = load_double(p + 56);
    }
    if ((n & 4u) != 0) {
        d[0] = load_double(p);
        d[1] = load_double(p + 8);
        d[2] = load_double(p + 16);
        d[3] = load_double(p + 24);
        d += 4;
        p += 32;
    }
    if ((n & 2u) != 0) {
        d[0] = load_double(p);
        d[1] = load_double(p + 8);
        d += 2;
        p += 16;
    }
    if ((n & 1u) != 0) {
        d[0] = load_double(p);
    }
}

/* The same for 32-bit values (an int32_t written through its unsigned type,
 * C99 6.5p7). */
static RTDE_NOINLINE void swap_words(uint32_t *d, const uint8_t *p, size_t n)
{
    for (; n >= 4; n -= 4, d += 4, p += 16) {
        d[0] = load_be32(p);
        d[1] = load_be32(p + 4);
        d[2] = load_be32(p + 8);
        d[3] = load_be32(p + 12);
    }
    if ((n & 2u) != 0) {
        d[0] = load_be32(p);
        d[1] = load_be32(p + 4);
        d += 2;
        p += 8;
    }
    if ((n & 1u) != 0) {
        d[0] = load_be32(p);
    }
}

/* One entry's values of the ops other than OP_F64 and OP_X32, once (p: its
 * first byte on the wire, d: its destination, n its elements). */
static RTDE_NOINLINE void decode_other(unsigned op, const uint8_t *p, unsigned char *d, size_t n)
{
    size_t k;
    switch (op) {
    case OP_I32_F64:
        for (k = 0; k < n; k++) {
            ((double *)(void *)d)[k] = (double)to_int32(load_be32(p + 4u * k));
        }
        break;
    case OP_U32_F64:
        for (k = 0; k < n; k++) {
            ((double *)(void *)d)[k] = (double)load_be32(p + 4u * k);
        }
        break;
    case OP_U64_F64:
        for (k = 0; k < n; k++) {
            ((double *)(void *)d)[k] = (double)load_be64(p + 8u * k);
        }
        break;
    case OP_U64:
        for (k = 0; k < n; k++) {
            ((uint64_t *)(void *)d)[k] = load_be64(p + 8u * k);
        }
        break;
    case OP_U8:
        for (k = 0; k < n; k++) {
            d[k] = p[k];
        }
        break;
    default: /* OP_BOOL */
        for (k = 0; k < n; k++) {
            d[k] = (unsigned char)(p[k] != 0);
        }
        break;
    }
}

/* The present bits of the recipe's RTDE-only variables into *vals, whole,
 * sixteen bytes at a time (URRT_RTDE_PRESENT_WORDS is whole groups of four
 * words): as structs of four words where GCC copies those inline (LDM/STM
 * on ARM, vector moves on x86-64 and AArch64; an uint32_t is accessed
 * through an aggregate that holds it, C99 6.5p7), else word by word. */
typedef struct rtde_quad {
    uint32_t w[4];
} rtde_quad;

RTDE_STATIC_ASSERT(present_three_quads, URRT_RTDE_PRESENT_WORDS == 12); /* else one more line below */

static void copy_present(uint32_t *d, const uint32_t *p)
{
#if defined(__GNUC__) && (defined(__arm__) || defined(__x86_64__) || defined(__aarch64__))
    rtde_quad *dq = (rtde_quad *)(void *)d;
    const rtde_quad *pq = (const rtde_quad *)(const void *)p;
    dq[0] = pq[0];
    dq[1] = pq[1];
    dq[2] = pq[2];
#else
    size_t i;
    for (i = 0; i < URRT_RTDE_PRESENT_WORDS; i += 4) {
        d[i] = p[i];
        d[i + 1] = p[i + 1];
        d[i + 2] = p[i + 2];
        d[i + 3] = p[i + 3];
    }
#endif
}

/* The entries after the short ones (compile_recipe puts those first): long
 * runs and the rarer conversions, each by a loop. Returns
 * URRT_RTDE_EV_DATA, as decode_package, which ends in it. */
static RTDE_NOINLINE int decode_long(const urrt_rtde *s, const uint8_t *pkg, urrt_state *st,
                                     urrt_rtde_values *vals)
{
    const urrt_rtde_entry *e = s->recipe + s->short_entries, *end = s->recipe + s->entry_count;
    for (; e != end; e++) {
        const uint8_t *p = pkg + e->wire_offset;
        unsigned char *d = (e->to_state ? (unsigned char *)st : (unsigned char *)vals) + e->dest_offset;
        if (e->op == OP_F64) {
            swap_doubles((double *)(void *)d, p, e->count);
        } else if (e->op == OP_X32) {
            swap_words((uint32_t *)(void *)d, p, e->count); /* an int32_t through its unsigned type */
        } else {
            decode_other(e->op, p, d, e->count);
        }
    }
    return URRT_RTDE_EV_DATA;
}

/* The short entries from e to end, all into one struct (base), by one switch
 * each, which enters the straight line below at their count (the cases fall
 * through to the first value). It calls nothing, so that on x86-64 the loop
 * fits in the registers a call may clobber and none is saved for it. */
static RTDE_INLINE void decode_short(const urrt_rtde_entry *e, const urrt_rtde_entry *end, const uint8_t *pkg,
                                unsigned char *base)
{
    for (; e != end; e++) {
        const uint8_t *p = pkg + e->wire_offset;
        double *dd = (double *)(void *)(base + e->dest_offset);
        uint32_t *dw = (uint32_t *)(void *)(base + e->dest_offset); /* an int32_t as unsigned (C99 6.5p7) */
        switch (e->op & (SHORT_OPS - 1u)) {
        case OP_F64_1 + 7: dd[7] = load_double(p + 56); /* fall through */
        case OP_F64_1 + 6: dd[6] = load_double(p + 48); /* fall through */
        case OP_F64_1 + 5: dd[5] = load_double(p + 40); /* fall through */
        case OP_F64_1 + 4: dd[4] = load_double(p + 32); /* fall through */
        case OP_F64_1 + 3: dd[3] = load_double(p + 24); /* fall through */
        case OP_F64_1 + 2: dd[2] = load_double(p + 16); /* fall through */
        case OP_F64_1 + 1: dd[1] = load_double(p + 8); /* fall through */
        case OP_F64_1: dd[0] = load_double(p); break;
        case OP_X32_1 + 7: dw[7] = load_be32(p + 28); /* fall through */
        case OP_X32_1 + 6: dw[6] = load_be32(p + 24); /* fall through */
        case OP_X32_1 + 5: dw[5] = load_be32(p + 20); /* fall through */
        case OP_X32_1 + 4: dw[4] = load_be32(p + 16); /* fall through */
        case OP_X32_1 + 3: dw[3] = load_be32(p + 12); /* fall through */
        case OP_X32_1 + 2: dw[2] = load_be32(p + 8); /* fall through */
        case OP_X32_1 + 1: dw[1] = load_be32(p + 4); /* fall through */
        default: dw[0] = load_be32(p); break; /* OP_X32_1: the cases cover every value */
        }
    }
}

/* The decode proper, of a package whose size (the recipe's), type and
 * recipe id are checked: the present bits whole, every time (nothing of
 * another recipe reads as present), then each value of the recipe, once;
 * nothing else. compile_recipe orders the entries: the short ones into
 * urrt_state, the short ones into urrt_rtde_values (a loop each, with its
 * struct's address: no choice per entry), then the rest, by decode_long.
 * Returns URRT_RTDE_EV_DATA, the event it completes: the feed's usual read
 * ends in it, and it in decode_long, by jumps where the compiler makes them. */
static RTDE_INLINE int decode_in(const urrt_rtde *s, const uint8_t *pkg, urrt_state *st, urrt_rtde_values *vals)
{
    const urrt_rtde_entry *e = s->recipe;
    if (st != 0) {
        st->present = s->state_present;
        st->length = s->data_size;
        st->doubles = 0;
        st->extra_columns = 0;
        st->generation = URRT_GEN_3X;
    }
    if (vals != 0) {
        copy_present(vals->present, s->values_present);
    }
    decode_short(e, e + s->state_entries, pkg, (unsigned char *)st);
    decode_short(e + s->state_entries, e + s->short_entries, pkg, (unsigned char *)vals);
    if (s->short_entries != s->entry_count) {
        return decode_long(s, pkg, st, vals);
    }
    return URRT_RTDE_EV_DATA;
}

/* decode_in once, out of line, for urrt_rtde_decode and feed_bytes; the
 * feed's usual read has a copy of its own. */
static int decode_package(const urrt_rtde *s, const uint8_t *pkg, urrt_state *st, urrt_rtde_values *vals)
{
    return decode_in(s, pkg, st, vals);
}

/* Whether a data package of the recipe's size and type has its recipe id
 * (protocol 2; protocol 1 has none). */
static bool recipe_id_ok(const urrt_rtde *s, const uint8_t *pkg)
{
    return s->protocol_accepted != 2 || pkg[3] == s->recipe_id;
}

int urrt_rtde_decode(const urrt_rtde *s, const uint8_t *pkg, size_t size, urrt_state *st,
                     urrt_rtde_values *vals)
{
    if (s == 0 || pkg == 0 || (s->has_state && st == 0) || (s->has_values && vals == 0)) {
        return URRT_E_ARG;
    }
    if (s->data_size == 0) {
        return URRT_RTDE_E_DATA_EARLY;
    }
    if (size != s->data_size || load_be16(pkg) != size || pkg[2] != URRT_RTDE_TYPE_DATA) {
        return URRT_RTDE_E_DATA_SIZE;
    }
    if (!recipe_id_ok(s, pkg)) {
        return URRT_RTDE_E_RECIPE_ID;
    }
    decode_package(s, pkg, st, vals);
    return (int)size;
}

/* ---- replies ------------------------------------------------------------- */

/* Ends the session with an error: the event says which kind of drop. */
static int end_session(urrt_rtde *s, urrt_rtde_event *ev, int error)
{
    s->phase = PH_ENDED;
    s->pending = REQ_NONE;
    s->error = error;
    s->stats.errors++;
    ev->kind = urrt_rtde_is_config_error(error) ? URRT_RTDE_EV_CONFIG : URRT_RTDE_EV_DROP;
    ev->error = error;
    return (int)ev->kind;
}

/* The accepted flag of a V, S or P reply (size 4): 0, 1, or an error. */
static int accepted_flag(const urrt_rtde *s)
{
    if (s->need != 4) {
        return URRT_RTDE_E_REPLY_LENGTH;
    }
    return s->buf[3] <= 1 ? s->buf[3] : URRT_RTDE_E_REPLY_VALUE;
}

static int on_protocol(urrt_rtde *s, urrt_rtde_event *ev)
{
    int ok = accepted_flag(s);
    if (ok < 0) {
        return end_session(s, ev, ok);
    }
    if (ok == 0) {
        if (s->protocol == URRT_RTDE_PROTOCOL_FALLBACK) {
            return end_session(s, ev, URRT_RTDE_E_PROTOCOL_REFUSED);
        }
        /* An event, so that the caller takes the request out before the
         * next reply is read. */
        s->protocol = URRT_RTDE_PROTOCOL_FALLBACK;
        s->pending = REQ_PROTOCOL;
        ev->kind = URRT_RTDE_EV_FALLBACK;
        ev->protocol = s->protocol;
        return (int)ev->kind;
    }
    s->protocol_accepted = s->protocol;
    s->phase = PH_CONTROLLER;
    s->pending = REQ_CONTROLLER;
    ev->kind = URRT_RTDE_EV_PROTOCOL;
    ev->protocol = s->protocol;
    return (int)ev->kind;
}

static int on_controller(urrt_rtde *s, urrt_rtde_event *ev)
{
    unsigned i;
    if (s->need != URRT_RTDE_HEADER_SIZE + 16) {
        return end_session(s, ev, URRT_RTDE_E_REPLY_LENGTH);
    }
    for (i = 0; i < 4; i++) {
        s->controller[i] = load_be32(s->buf + URRT_RTDE_HEADER_SIZE + 4u * i);
        ev->version[i] = s->controller[i];
    }
    if ((s->controller[0] | s->controller[1] | s->controller[2] | s->controller[3]) == 0) {
        return end_session(s, ev, URRT_RTDE_E_VERSION_ZERO);
    }
    if (s->protocol_accepted == 2 && s->frequency > max_frequency(s)) {
        return end_session(s, ev, URRT_RTDE_E_FREQUENCY);
    }
    s->phase = PH_SETUP;
    s->pending = REQ_SETUP;
    ev->kind = URRT_RTDE_EV_CONTROLLER;
    return (int)ev->kind;
}

/* The type a setup reply word names: a urrt_rtde_type, 0 for NOT_FOUND,
 * -1 for a word that is no type. */
static int type_of_word(const uint8_t *w, size_t n)
{
    unsigned t;
    if (same_prefix((const char *)w, n, "NOT_FOUND", true)) {
        return 0;
    }
    for (t = 1; t < (unsigned)URRT_RTDE_T_COUNT; t++) {
        if (same_prefix((const char *)w, n, type_table[t].name, true)) {
            return (int)t;
        }
    }
    return -1;
}

/* How a variable of a wire type is converted: into urrt_state every element
 * becomes a double, into urrt_rtde_values it keeps its C type. */
static unsigned op_of(unsigned type, bool to_state)
{
    switch (type) {
    case URRT_RTDE_T_DOUBLE:
    case URRT_RTDE_T_VECTOR3D:
    case URRT_RTDE_T_VECTOR6D: return OP_F64;
    case URRT_RTDE_T_UINT64: return to_state ? OP_U64_F64 : OP_U64;
    case URRT_RTDE_T_INT32:
    case URRT_RTDE_T_VECTOR6INT32: return to_state ? OP_I32_F64 : OP_X32;
    case URRT_RTDE_T_UINT32:
    case URRT_RTDE_T_VECTOR6UINT32: return to_state ? OP_U32_F64 : OP_X32;
    case URRT_RTDE_T_BOOL: return OP_BOOL;
    default: return OP_U8; /* no mapped variable is a BOOL or a UINT8 */
    }
}

/* Bytes of one element of an op's entries on the wire and in the struct. */
static unsigned op_wire_size(unsigned op)
{
    switch (op) {
    case OP_X32:
    case OP_I32_F64:
    case OP_U32_F64: return 4u;
    case OP_U8:
    case OP_BOOL: return 1u;
    default: return 8u;
    }
}

static unsigned op_dest_size(unsigned op)
{
    return op == OP_X32 ? 4u : op == OP_U8 || op == OP_BOOL ? 1u : 8u;
}

/* One pass of compile_recipe over the recipe: the entries of the variables
 * into urrt_state (to_state set) or into urrt_rtde_values, appended from
 * entry n in wire order, each joined to the one before it where both follow
 * each other on the wire and in the struct and convert alike (a run, which
 * the decode converts in one go); returns the entries then in use. */
static unsigned compile_pass(urrt_rtde *s, unsigned n, bool to_state)
{
    unsigned offset = URRT_RTDE_HEADER_SIZE + (s->protocol_accepted == 2 ? 1u : 0u), first = n;
    size_t i;
    for (i = 0; i < s->var_count; i++) {
        urrt_rtde_entry *e = &s->recipe[n], *prev = n > first ? &s->recipe[n - 1] : 0;
        int var = s->vars[i];
        const only_row *r = only_row_of(var);
        unsigned type = (unsigned)urrt_rtde_var_type(var), op = op_of(type, r == 0), at = offset;
        offset += type_table[type].size;
        if ((r == 0) != to_state) {
            continue;
        }
        e->wire_offset = (uint16_t)at;
        e->count = type_table[type].count;
        e->op = (uint8_t)op;
        e->to_state = (uint8_t)to_state;
        if (r == 0) {
            e->dest_offset = mapped_table[var].offset;
        } else {
            unsigned bit = (unsigned)(var - URRT_RTDE_MAPPED_COUNT);
            e->dest_offset = (uint16_t)value_offset(r, var);
            s->values_present[bit / 32u] |= UINT32_C(1) << (bit % 32u);
        }
        if (prev != 0 && prev->op == e->op && prev->wire_offset + op_wire_size(op) * prev->count == e->wire_offset &&
            prev->dest_offset + op_dest_size(op) * prev->count == e->dest_offset) {
            prev->count = (uint16_t)(prev->count + e->count);
        } else {
            n++;
        }
    }
    s->data_size = (uint16_t)offset;
    return n;
}

/* *d = *e, field by field: a struct copy may be a call of memcpy (which
 * lib/ must not need) where a target has no unaligned access (Cortex-M0). */
static void copy_entry(urrt_rtde_entry *d, const urrt_rtde_entry *e)
{
    d->wire_offset = e->wire_offset;
    d->dest_offset = e->dest_offset;
    d->count = e->count;
    d->op = e->op;
    d->to_state = e->to_state;
}

/* Compiles the accepted recipe into the entry table (to_state says which
 * struct each fills; the short entries first, see below) and the present
 * bits of its RTDE-only variables, which every decode writes whole. */
static void compile_recipe(urrt_rtde *s)
{
    size_t i;
    uint8_t head[4];
    for (i = 0; i < URRT_RTDE_PRESENT_WORDS; i++) {
        s->values_present[i] = 0;
    }
    s->state_entries = (uint16_t)compile_pass(s, 0, true);
    s->entry_count = (uint16_t)compile_pass(s, s->state_entries, false);
    /* The short entries (up to RUN_MAX doubles or 32-bit values) carry
     * their count in the op and come first, those into urrt_state first
     * (compile_pass put them first, and this keeps the short ones in
     * order), then the rest: the decode converts the short ones without a
     * loop, a struct at a time. Their order is free: each writes values of
     * its own. */
    s->short_entries = 0;
    s->state_entries = 0;
    for (i = 0; i < s->entry_count; i++) {
        urrt_rtde_entry e;
        copy_entry(&e, &s->recipe[i]);
        if ((e.op == OP_F64 || e.op == OP_X32) && e.count <= RUN_MAX) {
            e.op = (uint8_t)((e.op == OP_F64 ? OP_F64_1 : OP_X32_1) + e.count - 1);
            copy_entry(&s->recipe[i], &s->recipe[s->short_entries]);
            copy_entry(&s->recipe[s->short_entries], &e);
            s->short_entries++;
            s->state_entries = (uint16_t)(s->state_entries + e.to_state);
        }
    }
    /* A data package begins size, 'U', recipe id (protocol 2): the feed
     * compares those four bytes (three in protocol 1) at once. */
    store_be16(head, s->data_size);
    head[2] = URRT_RTDE_TYPE_DATA;
    head[3] = s->recipe_id;
    s->head = load_head(head);
    store_be16(head, 0xFFFFu);
    head[2] = 0xFFu;
    head[3] = s->protocol_accepted == 2 ? 0xFFu : 0u;
    s->head_mask = load_head(head);
    s->head &= s->head_mask;
}

/* Checks each word of a setup reply against its name: a word that is no
 * type is a protocol error, NOT_FOUND and a type urrt does not expect are
 * configuration errors (NOT_FOUND reported per name). */
static int check_types(urrt_rtde *s, urrt_rtde_event *ev, size_t at)
{
    size_t i, start, words = 1, not_found = 0;
    int mismatch = -1;
    for (i = at; i < s->need; i++) {
        words += s->buf[i] == ',';
    }
    if (at == s->need || words != s->var_count) {
        return end_session(s, ev, URRT_RTDE_E_TYPE_COUNT);
    }
    for (i = 0; i < s->var_count; i++, at++) {
        int t;
        start = at;
        while (at < s->need && s->buf[at] != ',') {
            at++;
        }
        t = type_of_word(s->buf + start, at - start);
        if (t < 0) {
            return end_session(s, ev, URRT_RTDE_E_TYPE_TOKEN);
        }
        if (t == 0) {
            s->not_found[i / 8] = (uint8_t)(s->not_found[i / 8] | 1u << (i % 8));
            not_found++;
        } else if (t != (int)urrt_rtde_var_type(s->vars[i]) && mismatch < 0) {
            mismatch = s->vars[i];
        }
    }
    if (not_found > 0) {
        ev->not_found = (uint16_t)not_found;
        return end_session(s, ev, URRT_RTDE_E_NOT_FOUND);
    }
    if (mismatch >= 0) {
        ev->var = mismatch;
        return end_session(s, ev, URRT_RTDE_E_TYPE_MISMATCH);
    }
    return URRT_OK;
}

/* The recipe is fixed for the session: what it lacks is set absent here,
 * once, in the structs the caller decodes into (a decode writes only the
 * recipe's members). */
static int on_setup(urrt_rtde *s, urrt_rtde_event *ev, urrt_state *st, urrt_rtde_values *vals)
{
    size_t at = URRT_RTDE_HEADER_SIZE + (s->protocol_accepted == 2 ? 1u : 0u);
    int r;
    if (s->need < at) {
        return end_session(s, ev, URRT_RTDE_E_REPLY_LENGTH);
    }
    r = check_types(s, ev, at);
    if (r != URRT_OK) {
        return r;
    }
    s->recipe_id = s->protocol_accepted == 2 ? s->buf[URRT_RTDE_HEADER_SIZE] : 0;
    compile_recipe(s);
    if (st != 0) {
        state_clear(st);
    }
    urrt_rtde_values_clear(vals);
    s->phase = PH_START;
    s->pending = REQ_START;
    ev->kind = URRT_RTDE_EV_RECIPE;
    ev->recipe_id = s->recipe_id;
    return (int)ev->kind;
}

static int on_start(urrt_rtde *s, urrt_rtde_event *ev)
{
    int ok = accepted_flag(s);
    if (ok < 0) {
        return end_session(s, ev, ok);
    }
    if (ok == 0) {
        return end_session(s, ev, URRT_RTDE_E_START_REFUSED);
    }
    s->phase = PH_STREAMING;
    ev->kind = URRT_RTDE_EV_STARTED;
    return (int)ev->kind;
}

static int on_pause(urrt_rtde *s, urrt_rtde_event *ev)
{
    int ok = accepted_flag(s);
    if (ok < 0) {
        return end_session(s, ev, ok);
    }
    if (ok == 0) {
        return end_session(s, ev, URRT_RTDE_E_PAUSE_REFUSED);
    }
    s->phase = PH_PAUSED;
    ev->kind = URRT_RTDE_EV_PAUSED;
    return (int)ev->kind;
}

/* Protocol 2: uint8 length, text, uint8 length, source, uint8 level, filling
 * the package exactly. Before protocol 2 is accepted, and in protocol 1:
 * uint8 level, then text to the end. */
static int on_text(urrt_rtde *s, urrt_rtde_event *ev)
{
    size_t at = URRT_RTDE_HEADER_SIZE, end = s->need;
    const char *b = (const char *)s->buf;
    if (s->protocol_accepted != 2) {
        if (end < at + 1) {
            return end_session(s, ev, URRT_RTDE_E_TEXT_LENGTH);
        }
        ev->level = s->buf[at];
        ev->text = b + at + 1;
        ev->text_len = (uint16_t)(end - at - 1);
        ev->source = b + end;
        ev->source_len = 0;
    } else {
        size_t text_len, source_len;
        if (end < at + 3) {
            return end_session(s, ev, URRT_RTDE_E_TEXT_LENGTH);
        }
        text_len = s->buf[at];
        if (at + 3 + text_len > end) {
            return end_session(s, ev, URRT_RTDE_E_TEXT_LENGTH);
        }
        source_len = s->buf[at + 1 + text_len];
        if (at + 3 + text_len + source_len != end) {
            return end_session(s, ev, URRT_RTDE_E_TEXT_LENGTH);
        }
        ev->text = b + at + 1;
        ev->text_len = (uint16_t)text_len;
        ev->source = b + at + 2 + text_len;
        ev->source_len = (uint16_t)source_len;
        ev->level = s->buf[end - 1];
    }
    s->stats.texts++;
    ev->kind = URRT_RTDE_EV_TEXT;
    return (int)ev->kind;
}

/* A data package's event (at pkg: in s->buf, or in the caller's read), its
 * size, type and recipe id checked. */
static int data_event(urrt_rtde *s, const uint8_t *pkg, urrt_rtde_event *ev, urrt_state *st, urrt_rtde_values *vals)
{
    decode_package(s, pkg, st, vals);
    if (s->phase == PH_START) {
        s->phase = PH_STREAMING; /* data before the S reply: start succeeded */
    }
    s->stats.data++;
    ev->kind = URRT_RTDE_EV_DATA;
    ev->first = !s->up;
    s->up = 1;
    return (int)ev->kind;
}

/* A data package check_header has let through (its size and type). */
static int on_data(urrt_rtde *s, const uint8_t *pkg, urrt_rtde_event *ev, urrt_state *st, urrt_rtde_values *vals)
{
    if (!recipe_id_ok(s, pkg)) {
        return end_session(s, ev, URRT_RTDE_E_RECIPE_ID);
    }
    return data_event(s, pkg, ev, st, vals);
}

/* Whether a reply of this type answers the request of the phase. (Not
 * whether the request was taken out yet: a stream replayed at once holds the
 * reply before the caller could take it.) */
static int awaited(const urrt_rtde *s, uint8_t type)
{
    switch (type) {
    case URRT_RTDE_TYPE_PROTOCOL_VERSION: return s->phase == PH_PROTOCOL;
    case URRT_RTDE_TYPE_CONTROLLER_VERSION: return s->phase == PH_CONTROLLER;
    case URRT_RTDE_TYPE_SETUP_OUTPUTS: return s->phase == PH_SETUP;
    case URRT_RTDE_TYPE_START: return s->phase == PH_START;
    case URRT_RTDE_TYPE_PAUSE: return s->phase == PH_PAUSE;
    default: return 0;
    }
}

/* A whole package of size bytes at pkg (in s->buf, or in the caller's
 * read). A data package is decoded where it lies; any other is read from
 * s->buf, its size in s->need (where the replies and urrt_rtde_in_feed look),
 * copied there first if it lies in the read. */
static int on_package(urrt_rtde *s, const uint8_t *pkg, size_t size, urrt_rtde_event *ev, urrt_state *st,
                      urrt_rtde_values *vals)
{
    uint8_t type = pkg[2];
    s->stats.packages++;
    if (type == URRT_RTDE_TYPE_DATA) {
        return on_data(s, pkg, ev, st, vals);
    }
    if (pkg != s->buf) {
        copy_bytes(s->buf, pkg, size);
    }
    s->need = (uint16_t)size;
    if (type == URRT_RTDE_TYPE_TEXT_MESSAGE) {
        return on_text(s, ev);
    }
    if (!awaited(s, type)) {
        s->stats.ignored++;
        return URRT_RTDE_EV_NONE;
    }
    switch (type) {
    case URRT_RTDE_TYPE_PROTOCOL_VERSION: return on_protocol(s, ev);
    case URRT_RTDE_TYPE_CONTROLLER_VERSION: return on_controller(s, ev);
    case URRT_RTDE_TYPE_SETUP_OUTPUTS: return on_setup(s, ev, st, vals);
    case URRT_RTDE_TYPE_START: return on_start(s, ev);
    default: return on_pause(s, ev);
    }
}

/* A complete header at p: the size bounds, and a data package's size
 * against the recipe, before any of its body is taken. */
static int check_header(const urrt_rtde *s, const uint8_t *p)
{
    unsigned size = load_be16(p);
    if (size < URRT_RTDE_HEADER_SIZE) {
        return URRT_RTDE_E_SIZE_SMALL;
    }
    if (size > URRT_RTDE_PACKAGE_MAX) {
        return URRT_RTDE_E_SIZE_LARGE;
    }
    if (p[2] == URRT_RTDE_TYPE_DATA) {
        if (s->data_size == 0) {
            return URRT_RTDE_E_DATA_EARLY;
        }
        if (size != s->data_size) {
            return URRT_RTDE_E_DATA_SIZE;
        }
    }
    return URRT_OK;
}

static void clear_event(urrt_rtde_event *ev)
{
    ev->kind = URRT_RTDE_EV_NONE;
    ev->error = 0;
    ev->protocol = 0;
    ev->recipe_id = 0;
    ev->level = 0;
    ev->first = false;
    ev->version[0] = ev->version[1] = ev->version[2] = ev->version[3] = 0;
    ev->text = 0;
    ev->source = 0;
    ev->text_len = 0;
    ev->source_len = 0;
    ev->not_found = 0;
    ev->var = -1;
}

/* A data event: clear_event's fields, kind URRT_RTDE_EV_DATA. Where GCC
 * copies a struct of this size inline (x86-64, AArch64: a few vector moves,
 * never a memcpy call), as one copy of a constant event (fewer stores than
 * its 13 fields); elsewhere field by field. */
static void data_event_start(urrt_rtde_event *ev)
{
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__aarch64__))
    static const urrt_rtde_event data = {URRT_RTDE_EV_DATA, 0, 0, 0, 0, false, {0, 0, 0, 0}, 0, 0, 0, 0, 0, -1};
    *ev = data;
#else
    clear_event(ev);
    ev->kind = URRT_RTDE_EV_DATA;
#endif
}

/* urrt_rtde_feed in general: every argument, phase and split. */
static RTDE_NOINLINE int feed_bytes(urrt_rtde *s, const uint8_t *data, size_t len, size_t *used,
                                    urrt_rtde_event *ev, urrt_state *st, urrt_rtde_values *vals)
{
    size_t i = 0;
    if (used != 0) {
        *used = 0;
    }
    if (s == 0 || used == 0 || ev == 0 || (data == 0 && len > 0) || (s->has_values && vals == 0) ||
        (s->has_state && st == 0)) {
        return URRT_E_ARG;
    }
    clear_event(ev);
    if (s->phase == PH_IDLE || s->phase == PH_ENDED) {
        return URRT_RTDE_E_ENDED;
    }
    if (s->have == 0 && len >= s->data_size && len >= 4 && (load_head(data) & s->head_mask) == s->head) {
        /* The same read in the other phases (data before the S reply,
         * around a pause): a whole data package of the recipe first,
         * decoded where it lies, what the loop below does, without it. */
        int k;
        s->stats.packages++;
        k = data_event(s, data, ev, st, vals);
        *used = s->data_size;
        s->stats.bytes += s->data_size;
        return k;
    }
    while (i < len) {
        const uint8_t *pkg;
        size_t size, left = len - i, take;
        int k;
        if (s->have == 0 && left >= URRT_RTDE_HEADER_SIZE) {
            /* A header in the read: a package it holds whole is taken
             * where it lies; the start of a longer one is kept. */
            pkg = data + i;
            k = check_header(s, pkg);
            if (k < 0) {
                i += URRT_RTDE_HEADER_SIZE;
                *used = i;
                s->stats.bytes += i;
                return end_session(s, ev, k);
            }
            size = load_be16(pkg);
            if (left < size) {
                copy_bytes(s->buf, pkg, left);
                s->have = (uint16_t)left;
                s->need = (uint16_t)size;
                break;
            }
            i += size;
        } else {
            /* A package split across reads, gathered in s->buf: the rest of
             * its header, then of its body. */
            if (s->need == 0) {
                take = (size_t)(URRT_RTDE_HEADER_SIZE - s->have);
                take = take < left ? take : left;
                copy_bytes(s->buf + s->have, data + i, take);
                s->have = (uint16_t)(s->have + take);
                i += take;
                left -= take;
                if (s->have < URRT_RTDE_HEADER_SIZE) {
                    break;
                }
                k = check_header(s, s->buf);
                if (k < 0) {
                    *used = i;
                    s->stats.bytes += i;
                    return end_session(s, ev, k);
                }
                s->need = load_be16(s->buf);
            }
            take = (size_t)(s->need - s->have);
            take = take < left ? take : left;
            copy_bytes(s->buf + s->have, data + i, take);
            s->have = (uint16_t)(s->have + take);
            i += take;
            if (s->have < s->need) {
                break;
            }
            pkg = s->buf;
            size = s->need;
        }
        k = on_package(s, pkg, size, ev, st, vals);
        s->have = 0;
        s->need = 0;
        if (k != URRT_RTDE_EV_NONE) {
            *used = i;
            s->stats.bytes += i;
            return k;
        }
    }
    *used = len;
    s->stats.bytes += len;
    return URRT_RTDE_EV_NONE;
}

int urrt_rtde_feed(urrt_rtde *s, const uint8_t *data, size_t len, size_t *used, urrt_rtde_event *ev,
                   urrt_state *st, urrt_rtde_values *vals)
{
    /* The usual read, while the session streams: one that starts with a
     * whole data package of the recipe (its size, type and recipe id are
     * its first four bytes, compared at once; a recipe's package has at
     * least four), with the structs its recipe needs: what feed_bytes does
     * for it, its event and counts, then the decode where the package lies,
     * which this ends in. Any other read goes to feed_bytes. Both are jumps
     * where the compiler makes them (the call is the last thing done), so
     * the usual read pays for none of feed_bytes's registers. */
    if (s != 0 && used != 0 && ev != 0 && data != 0 && s->phase == PH_STREAMING && s->have == 0 &&
        len >= s->data_size && (load_head(data) & s->head_mask) == s->head && (st != 0 || !s->has_state) &&
        (vals != 0 || !s->has_values)) {
        data_event_start(ev);
        ev->first = !s->up;
        s->up = 1;
        s->stats.bytes += s->data_size;
        *used = s->data_size;
        s->stats.packages++;
        s->stats.data++;
        return decode_in(s, data, st, vals);
    }
    return feed_bytes(s, data, len, used, ev, st, vals);
}
