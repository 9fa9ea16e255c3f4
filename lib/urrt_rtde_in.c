/* SPDX-License-Identifier: MIT */
/* urrt_rtde_in: the writing side of the RTDE client, without I/O. See
 * urrt_rtde_in.h for the API and docs/rtde.md ("Writing registers") for the
 * session, the refusals and the errors. No floating-point arithmetic: values
 * are checked and packed as bits. */
#include "urrt_rtde_in.h"

#include "urrt_double_internal.h"

#define IN_STATIC_ASSERT(name, cond) typedef char urrt_rtde_in_assert_##name[(cond) ? 1 : -1]

IN_STATIC_ASSERT(double_is_binary64, sizeof(double) == 8);
IN_STATIC_ASSERT(given_bits, URRT_RTDE_IN_MAX_VARS % 8 == 0);
IN_STATIC_ASSERT(package_fits_uint16, URRT_RTDE_IN_PACKAGE_MAX <= 0xFFFF);
IN_STATIC_ASSERT(request_fits_uint16, URRT_RTDE_IN_REQUEST_MAX <= 0xFFFF);
/* The writable registers are one run of ids (lib/urrt_rtde.h's table). */
IN_STATIC_ASSERT(registers_contiguous,
                 URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63 == URRT_RTDE_V_INPUT_BIT_REGISTERS0_TO_31 + 1 &&
                     URRT_RTDE_V_INPUT_BIT_REGISTER == URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63 + 1 &&
                     URRT_RTDE_V_INPUT_INT_REGISTER == URRT_RTDE_V_INPUT_BIT_REGISTER_LAST_ + 1 &&
                     URRT_RTDE_V_INPUT_DOUBLE_REGISTER == URRT_RTDE_V_INPUT_INT_REGISTER_LAST_ + 1);

/* A recipe's progress in the session (urrt_rtde_in.state). */
enum in_state {
    IN_UNUSABLE = 0, /* zeroed, or an init refused */
    IN_IDLE,         /* init done, no session yet */
    IN_DUE,          /* its setup request is due once the output recipe is accepted */
    IN_SENT,         /* the request was written: its reply is awaited */
    IN_ACCEPTED,     /* the controller gave it an id */
    IN_REFUSED       /* its reply ended the session */
};

typedef union in_bits {
    uint64_t u;
    double d;
} in_bits;

/* ---- the writable variables ------------------------------------------------ */

bool urrt_rtde_in_writable(int var)
{
    return var >= (int)URRT_RTDE_V_INPUT_BIT_REGISTERS0_TO_31 && var <= (int)URRT_RTDE_V_INPUT_DOUBLE_REGISTER_LAST_;
}

static bool usable(const urrt_rtde_in *in)
{
    return in->state != IN_UNUSABLE && in->count > 0 && in->count <= URRT_RTDE_IN_MAX_VARS;
}

static void zero(void *p, size_t n)
{
    unsigned char *b = (unsigned char *)p;
    size_t i;
    for (i = 0; i < n; i++) {
        b[i] = 0;
    }
}

int urrt_rtde_in_init(urrt_rtde_in *in, const uint16_t *vars, size_t count)
{
    char name[URRT_RTDE_NAME_MAX];
    size_t i, j, names = 0;
    unsigned offset = 0;
    if (in == 0) {
        return URRT_E_ARG;
    }
    zero(in, sizeof *in);
    in->error_var = -1;
    if (vars == 0 || count == 0 || count > URRT_RTDE_IN_MAX_VARS) {
        return URRT_E_ARG;
    }
    for (i = 0; i < count; i++) {
        int n;
        if (vars[i] >= URRT_RTDE_VAR_COUNT) {
            return URRT_E_ARG;
        }
        if (!urrt_rtde_in_writable(vars[i])) {
            return URRT_RTDE_E_NOT_WRITABLE;
        }
        for (j = 0; j < i; j++) {
            if (vars[j] == vars[i]) {
                return URRT_RTDE_E_DUPLICATE;
            }
        }
        n = urrt_rtde_var_name(vars[i], name, sizeof name);
        if (n <= 0) {
            return URRT_E_ARG;
        }
        names += (size_t)n + (i > 0 ? 1u : 0u);
    }
    if (names > URRT_RTDE_NAMES_MAX) {
        return URRT_RTDE_E_NAMES_TOO_LONG;
    }
    for (i = 0; i < count; i++) {
        in->vars[i] = vars[i];
        in->types[i] = (uint8_t)urrt_rtde_var_type(vars[i]);
        in->offset[i] = (uint16_t)offset;
        offset += urrt_rtde_type_size((urrt_rtde_type)in->types[i]);
    }
    in->count = (uint16_t)count;
    in->data_size = (uint16_t)offset;
    in->state = IN_IDLE;
    return URRT_OK;
}

void urrt_rtde_in_begin(urrt_rtde_in *in, size_t n)
{
    size_t g;
    for (g = 0; in != 0 && g < n; g++) {
        if (usable(&in[g])) {
            in[g].state = IN_DUE;
            in[g].id = 0;
            in[g].error = 0;
            in[g].error_var = -1;
        }
    }
}

/* ---- the setup request -------------------------------------------------------- */

int urrt_rtde_in_write_setup(uint8_t *out, size_t cap, const urrt_rtde_in *in)
{
    char name[URRT_RTDE_NAME_MAX];
    size_t i, at = URRT_RTDE_HEADER_SIZE, size = URRT_RTDE_HEADER_SIZE;
    if (out == 0 || in == 0 || !usable(in)) {
        return URRT_E_ARG;
    }
    for (i = 0; i < in->count; i++) {
        int n = urrt_rtde_var_name(in->vars[i], name, sizeof name);
        if (n <= 0) {
            return URRT_E_ARG;
        }
        size += (size_t)n + (i > 0 ? 1u : 0u);
    }
    if (size > URRT_RTDE_IN_REQUEST_MAX) {
        return URRT_RTDE_E_NAMES_TOO_LONG;
    }
    if (cap < size) {
        return URRT_E_NO_SPACE;
    }
    out[0] = (uint8_t)(size >> 8);
    out[1] = (uint8_t)size;
    out[2] = URRT_RTDE_TYPE_SETUP_INPUTS;
    for (i = 0; i < in->count; i++) {
        int n = urrt_rtde_var_name(in->vars[i], name, sizeof name), k;
        if (i > 0) {
            out[at++] = ',';
        }
        for (k = 0; k < n; k++) {
            out[at++] = (uint8_t)name[k];
        }
    }
    return (int)size;
}

/* The first recipe whose setup is not through (due or awaiting its reply),
 * n if none. */
static size_t pending_setup(const urrt_rtde_in *in, size_t n)
{
    size_t g;
    for (g = 0; g < n; g++) {
        if (in[g].state == IN_DUE || in[g].state == IN_SENT) {
            return g;
        }
    }
    return n;
}

static bool all_usable(const urrt_rtde_in *in, size_t n)
{
    size_t g;
    for (g = 0; g < n; g++) {
        if (!usable(&in[g])) {
            return false;
        }
    }
    return true;
}

int urrt_rtde_in_output(urrt_rtde *s, urrt_rtde_in *in, size_t n, uint8_t *out, size_t cap)
{
    size_t g;
    int k;
    if (s == 0 || out == 0 || (n > 0 && in == 0) || !all_usable(in, n)) {
        return URRT_E_ARG;
    }
    g = pending_setup(in, n);
    if (urrt_rtde_due(s) != URRT_RTDE_TYPE_START || g == n) {
        k = urrt_rtde_output(s, out, cap);
    } else if (in[g].state == IN_SENT) {
        k = 0; /* start waits for every reply; one request at a time */
    } else {
        k = urrt_rtde_in_write_setup(out, cap, &in[g]);
    }
    if (k > 0 && out[2] == URRT_RTDE_TYPE_SETUP_INPUTS) {
        in[g].state = IN_SENT;
    }
    return k;
}

/* ---- the setup reply ----------------------------------------------------------- */

/* n bytes at w spell the NUL-terminated word t exactly. */
static bool same_word(const uint8_t *w, size_t n, const char *t)
{
    size_t i;
    for (i = 0; i < n; i++) {
        if (t[i] == '\0' || (char)w[i] != t[i]) {
            return false;
        }
    }
    return t[n] == '\0';
}

#define WORD_NOT_FOUND (-2)
#define WORD_IN_USE (-3)

/* A reply word: a urrt_rtde_type, WORD_NOT_FOUND, WORD_IN_USE, or -1. */
static int word_of(const uint8_t *w, size_t n)
{
    int t;
    if (same_word(w, n, "NOT_FOUND")) {
        return WORD_NOT_FOUND;
    }
    if (same_word(w, n, "IN_USE")) {
        return WORD_IN_USE;
    }
    for (t = 1; t < (int)URRT_RTDE_T_COUNT; t++) {
        if (same_word(w, n, urrt_rtde_type_name((urrt_rtde_type)t))) {
            return t;
        }
    }
    return -1;
}

/* Ends the session over recipe g's reply (a refusal names a register and
 * says how many were refused). */
static int refuse(urrt_rtde *s, urrt_rtde_in *in, urrt_rtde_event *ev, int error, int var, size_t count)
{
    int k;
    in->state = IN_REFUSED;
    in->error = error;
    in->error_var = var;
    k = urrt_rtde_end(s, ev, error);
    ev->var = var;
    ev->not_found = (uint16_t)count;
    return k;
}

/* The setup-inputs reply in s->buf (the package the reader just framed and
 * counted as ignored): uint8 id, then one word per register. */
static int on_reply(urrt_rtde *s, urrt_rtde_in *in, size_t g, urrt_rtde_event *ev)
{
    urrt_rtde_in *r = &in[g];
    size_t size = (size_t)s->buf[0] << 8 | (size_t)s->buf[1], at = URRT_RTDE_HEADER_SIZE + 1, i, words = 1;
    size_t not_found = 0, in_use = 0;
    int first_not_found = -1, first_in_use = -1, mismatch = -1;
    s->stats.ignored--; /* the reader's count of replies nobody waits for: this one was awaited */
    if (size < at) {
        return refuse(s, r, ev, URRT_RTDE_E_REPLY_LENGTH, -1, 0);
    }
    for (i = at; i < size; i++) {
        words += s->buf[i] == ',';
    }
    if (at == size || words != r->count) {
        return refuse(s, r, ev, URRT_RTDE_E_TYPE_COUNT, -1, 0);
    }
    for (i = 0; i < r->count; i++, at++) {
        size_t start = at;
        int w;
        while (at < size && s->buf[at] != ',') {
            at++;
        }
        w = word_of(s->buf + start, at - start);
        if (w == -1) {
            return refuse(s, r, ev, URRT_RTDE_E_TYPE_TOKEN, -1, 0);
        }
        if (w == WORD_NOT_FOUND) {
            first_not_found = not_found++ == 0 ? r->vars[i] : first_not_found;
        } else if (w == WORD_IN_USE) {
            first_in_use = in_use++ == 0 ? r->vars[i] : first_in_use;
        } else if (w != (int)urrt_rtde_var_type(r->vars[i]) && mismatch < 0) {
            mismatch = r->vars[i];
        }
    }
    if (not_found > 0) {
        r->stats.not_found++;
        return refuse(s, r, ev, URRT_RTDE_E_NOT_FOUND, first_not_found, not_found);
    }
    if (in_use > 0) {
        r->stats.in_use++;
        return refuse(s, r, ev, URRT_RTDE_E_IN_USE, first_in_use, in_use);
    }
    if (mismatch >= 0) {
        return refuse(s, r, ev, URRT_RTDE_E_TYPE_MISMATCH, mismatch, 0);
    }
    if (s->buf[URRT_RTDE_HEADER_SIZE] == 0) { /* a valid recipe has an id; 0 marks a refused one */
        return refuse(s, r, ev, URRT_RTDE_E_RECIPE_ID, -1, 0);
    }
    r->id = s->buf[URRT_RTDE_HEADER_SIZE];
    r->state = IN_ACCEPTED;
    r->stats.accepted++;
    ev->kind = URRT_RTDE_EV_INPUTS;
    ev->var = (int)g;
    ev->recipe_id = r->id;
    return (int)ev->kind;
}

/* What the reader's event means with inputs: a new session sets every
 * recipe up again; an output recipe accepted in protocol 1 ends it. */
static int after_event(urrt_rtde *s, urrt_rtde_in *in, size_t n, urrt_rtde_event *ev, int k)
{
    if (k == URRT_RTDE_EV_PROTOCOL) {
        urrt_rtde_in_begin(in, n);
    } else if (k == URRT_RTDE_EV_RECIPE && s->protocol_accepted != 2) {
        return urrt_rtde_end(s, ev, URRT_RTDE_E_INPUTS_PROTOCOL);
    }
    return k;
}

int urrt_rtde_in_feed(urrt_rtde *s, urrt_rtde_in *in, size_t n, const uint8_t *data, size_t len, size_t *used,
                      urrt_rtde_event *ev, urrt_state *st, urrt_rtde_values *vals)
{
    size_t g, total = 0;
    if (used != 0) {
        *used = 0;
    }
    if (s == 0 || used == 0 || ev == 0 || (n > 0 && in == 0) || !all_usable(in, n)) {
        return URRT_E_ARG;
    }
    if (n == 0) {
        return urrt_rtde_feed(s, data, len, used, ev, st, vals);
    }
    g = pending_setup(in, n);
    if (g == n || in[g].state != IN_SENT) {
        /* No reply awaited: an 'I' package is one nobody waits for. */
        int k = urrt_rtde_feed(s, data, len, used, ev, st, vals);
        return k > 0 ? after_event(s, in, n, ev, k) : k;
    }
    /* A reply awaited: the reader frames, one package at a time, and the
     * package it just completed (s->buf) is looked at when it is an 'I'. */
    for (;;) {
        size_t room = s->need == 0 ? (size_t)(URRT_RTDE_HEADER_SIZE - s->have) : (size_t)(s->need - s->have);
        size_t step = len - total < room ? len - total : room, u = 0;
        int k = urrt_rtde_feed(s, data == 0 ? data : data + total, step, &u, ev, st, vals);
        total += u;
        *used = total;
        if (k != URRT_RTDE_EV_NONE) {
            return k > 0 ? after_event(s, in, n, ev, k) : k;
        }
        if (u > 0 && s->have == 0 && s->need == 0 && s->buf[2] == URRT_RTDE_TYPE_SETUP_INPUTS) {
            return on_reply(s, in, g, ev);
        }
        if (total == len) {
            return URRT_RTDE_EV_NONE;
        }
    }
}

/* ---- values ---------------------------------------------------------------------- */

static void store_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static void store_be64(uint8_t *p, uint64_t v)
{
    store_be32(p, (uint32_t)(v >> 32));
    store_be32(p + 4, (uint32_t)v);
}

static void set_given(urrt_rtde_in *in, size_t i, bool given)
{
    unsigned bit = 1u << (i % 8u);
    in->given[i / 8u] = (uint8_t)(given ? in->given[i / 8u] | bit : in->given[i / 8u] & ~bit);
}

/* The end of a set: register i holds the value it was given, or (refused)
 * none, and the refusal is counted. */
static int given(urrt_rtde_in *in, size_t i, bool ok)
{
    set_given(in, i, ok);
    if (!ok) {
        in->stats.refused++;
        return URRT_RTDE_E_VALUE;
    }
    return URRT_OK;
}

/* An integer into an integer register if its type holds it; false if not. */
static bool put_int(urrt_rtde_in *in, size_t i, int64_t v)
{
    uint8_t *p = in->data + in->offset[i];
    switch ((urrt_rtde_type)in->types[i]) {
    case URRT_RTDE_T_BOOL:
        if (v != 0 && v != 1) {
            return false;
        }
        p[0] = (uint8_t)v;
        return true;
    case URRT_RTDE_T_INT32:
        if (v < INT32_MIN || v > INT32_MAX) {
            return false;
        }
        store_be32(p, (uint32_t)v); /* two's complement, as on the wire */
        return true;
    case URRT_RTDE_T_UINT32:
        if (v < 0 || v > (int64_t)UINT32_MAX) {
            return false;
        }
        store_be32(p, (uint32_t)v);
        return true;
    default: return false; /* no other type is writable */
    }
}

int urrt_rtde_in_set_int(urrt_rtde_in *in, size_t i, int64_t value)
{
    uint64_t bits;
    bool ok;
    if (in == 0 || !usable(in) || i >= in->count) {
        return URRT_E_ARG;
    }
    if (in->types[i] != (uint8_t)URRT_RTDE_T_DOUBLE) {
        ok = put_int(in, i, value);
    } else {
        ok = urrt_double_bits_of_int(value, &bits); /* no double holds it exactly: refused */
        if (ok) {
            store_be64(in->data + in->offset[i], bits);
        }
    }
    return given(in, i, ok);
}

int urrt_rtde_in_set_double(urrt_rtde_in *in, size_t i, double value)
{
    in_bits b;
    int64_t v;
    bool ok;
    if (in == 0 || !usable(in) || i >= in->count) {
        return URRT_E_ARG;
    }
    b.d = value;
    if (in->types[i] != (uint8_t)URRT_RTDE_T_DOUBLE) {
        ok = urrt_int_of_double_bits(b.u, &v) && put_int(in, i, v);
    } else {
        ok = ((unsigned)(b.u >> 52) & 0x7FFu) != 0x7FFu; /* infinite or NaN: refused */
        if (ok) {
            store_be64(in->data + in->offset[i], b.u); /* bit for bit: -0.0 and denormals too */
        }
    }
    return given(in, i, ok);
}

void urrt_rtde_in_forget(urrt_rtde_in *in)
{
    if (in != 0) {
        zero(in->given, sizeof in->given);
    }
}

void urrt_rtde_in_unset(urrt_rtde_in *in, size_t i)
{
    if (in != 0 && i < in->count) {
        set_given(in, i, false);
    }
}

bool urrt_rtde_in_complete(const urrt_rtde_in *in)
{
    unsigned rest;
    size_t i;
    if (in == 0 || !usable(in)) {
        return false;
    }
    /* A byte of given bits at a time (each package asks), then the last one's
     * bits below count. */
    for (i = 0; i < in->count / 8u; i++) {
        if (in->given[i] != 0xFFu) {
            return false;
        }
    }
    rest = (1u << (in->count % 8u)) - 1u;
    return rest == 0u || ((unsigned)in->given[i] & rest) == rest;
}

bool urrt_rtde_in_ready(const urrt_rtde *s, const urrt_rtde_in *in)
{
    return s != 0 && in != 0 && usable(in) && in->state == IN_ACCEPTED && in->id != 0 && urrt_rtde_streaming(s);
}

/* ---- the input data package ---------------------------------------------------- */

int urrt_rtde_in_package(const urrt_rtde *s, urrt_rtde_in *in, uint8_t *out, size_t cap)
{
    const uint8_t *from;
    size_t size, i, n;
    if (s == 0 || in == 0 || out == 0 || !usable(in)) {
        return URRT_E_ARG;
    }
    if (!urrt_rtde_in_ready(s, in)) {
        return URRT_RTDE_E_NOT_STARTED;
    }
    if (!urrt_rtde_in_complete(in)) {
        return URRT_RTDE_E_INCOMPLETE;
    }
    size = URRT_RTDE_HEADER_SIZE + 1u + in->data_size;
    if (cap < size) {
        return URRT_E_NO_SPACE;
    }
    out[0] = (uint8_t)(size >> 8);
    out[1] = (uint8_t)size;
    out[2] = URRT_RTDE_TYPE_DATA;
    out[3] = in->id;
    /* The count and the source held in locals: out may alias in for all the
     * compiler knows, which would reload both at every byte. */
    from = in->data;
    n = in->data_size;
    for (i = 0; i < n; i++) {
        out[4 + i] = from[i];
    }
    in->stats.packages++;
    return (int)size;
}
