/* SPDX-License-Identifier: MIT */
/*
 * check-rtde: the RTDE client (lib/urrt_rtde) against the sessions of the
 * independent reference (tests/ref/rtde_ref.py plays the controller and says
 * what the client must send and decode), fed whole and in small chunks; every
 * split point of each session gives the same events; every byte the client
 * writes is a V, v, O, S or P request; and the tables against the version
 * facts of docs/rtde.md.
 *   test_rtde VECTORS
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "urrt_rtde.h"

#define LINE_MAX_CHARS 140000
#define IN_MAX 65536
#define TRANSCRIPT_MAX 65536

#include "rtde_names.h"

static size_t unhex(const char *h, uint8_t *out, size_t cap)
{
    size_t n = 0;
    if (strcmp(h, "-") == 0) {
        return 0;
    }
    while (h[0] != '\0' && h[1] != '\0' && n < cap) {
        unsigned b;
        sscanf(h, "%2x", &b);
        out[n++] = (uint8_t)b;
        h += 2;
    }
    return n;
}

/* Every request the client writes: a whole package of one of the five
 * types a read-only client has, its size field its length. */
static void check_request(const uint8_t *p, int n)
{
    CHECK(n >= 3 && (p[0] << 8 | p[1]) == n, "request of %d bytes declares %d", n, n >= 2 ? p[0] << 8 | p[1] : -1);
    CHECK(n >= 3 && strchr("VvOSP", p[2]) != NULL && p[2] != 0, "client wrote a package of type %c", n >= 3 ? p[2] : '?');
}

/* ---- the vector runner ----------------------------------------------------- */

static struct runner {
    urrt_rtde s;
    urrt_state st;
    urrt_rtde_values vals;
    urrt_rtde_event ev;
    uint8_t in[IN_MAX];
    size_t in_len, in_pos, chunk;
    uint16_t vars[URRT_RTDE_MAX_VARS];
    size_t var_count;
    double freq;
    int begun;
    int poison; /* the caller writes its structs before every read (see next_event) */
    char session[96];
} R;

#define POISON 0x3F /* every byte: a double 0.36, an integer 0x3F3F... */

/* Feeds pending input in chunks of R.chunk until an event. */
static int next_event(void)
{
    while (R.in_pos < R.in_len) {
        size_t n = R.in_len - R.in_pos < R.chunk ? R.in_len - R.in_pos : R.chunk;
        size_t used = 99999;
        /* The caller may write its structs between packages: with R.poison
         * every byte of both (present bits, length and generation too) is
         * poisoned before every read, so that a decode that writes what its
         * recipe lacks (or leaves a present bit it does not set) is caught:
         * it writes its values and the present bits, nothing else. */
        if (R.poison) {
            memset(&R.st, POISON, sizeof R.st);
            memset(&R.vals, POISON, sizeof R.vals);
        }
        int k = urrt_rtde_feed(&R.s, R.in + R.in_pos, n, &used, &R.ev, &R.st, &R.vals);
        CHECK(used <= n, "%s: used %zu of %zu", R.session, used, n);
        R.in_pos += used;
        if (k != URRT_RTDE_EV_NONE) {
            return k;
        }
        CHECK(used == n, "%s: no event but %zu of %zu used", R.session, used, n);
    }
    return URRT_RTDE_EV_NONE;
}

static void do_begin(const char *err)
{
    int r = urrt_rtde_begin(&R.s, R.vars, R.var_count, R.freq);
    if (err == NULL) {
        CHECK(r == URRT_OK, "%s: begin: %s", R.session, urrt_rtde_strerror(r));
    } else {
        CHECK_EQ_INT(r, LOOKUP(errors, err));
    }
    R.begun = 1;
}

static void parse_vars(char *list)
{
    R.var_count = 0;
    for (char *name = strtok(list, ","); name != NULL; name = strtok(NULL, ",")) {
        int var = urrt_rtde_var_find(name, strlen(name));
        CHECK(var >= 0, "%s: urrt_rtde_var_find(%s) = %d", R.session, name, var);
        if (R.var_count < URRT_RTDE_MAX_VARS) {
            R.vars[R.var_count++] = (uint16_t)(var < 0 ? 0 : var);
        }
    }
}

/* set_recipe [ERR] NAMES: the caller replaces the recipe; with ERR it must
 * be refused so, and R.vars (what the data must hold) stay as they were. */
static void do_set_recipe(char *arg, int must_fail)
{
    uint16_t old[URRT_RTDE_MAX_VARS];
    size_t old_count = R.var_count;
    const char *err = arg;
    int r;
    if (must_fail) {
        char *sp = strchr(arg, ' ');
        CHECK(sp != NULL, "%s: set_recipe_error without names", R.session);
        if (sp == NULL) {
            return;
        }
        *sp = '\0';
        arg = sp + 1;
    }
    memcpy(old, R.vars, sizeof old);
    if (strcmp(arg, "-") == 0) {
        R.var_count = 0;
    } else {
        parse_vars(arg);
    }
    r = urrt_rtde_set_recipe(&R.s, R.vars, R.var_count);
    if (must_fail) {
        CHECK(r == LOOKUP(errors, err), "%s: set_recipe gave %s, expected %s", R.session, urrt_rtde_strerror(r), err);
        memcpy(R.vars, old, sizeof old);
        R.var_count = old_count;
    } else {
        CHECK(r == URRT_OK, "%s: set_recipe: %s", R.session, urrt_rtde_strerror(r));
    }
}

static void do_send(const char *hex)
{
    static uint8_t want[URRT_RTDE_REQUEST_MAX], got[URRT_RTDE_REQUEST_MAX];
    size_t n = unhex(hex, want, sizeof want);
    CHECK_EQ_INT(urrt_rtde_output(&R.s, got, n - 1), URRT_E_NO_SPACE); /* one byte short: stays due */
    int k = urrt_rtde_output(&R.s, got, sizeof got);
    CHECK(k == (int)n && memcmp(got, want, n) == 0, "%s: sent %d bytes, expected %zu (%s)", R.session, k, n, hex);
    if (k > 0) {
        check_request(got, k);
    }
    CHECK_EQ_INT(urrt_rtde_output(&R.s, got, sizeof got), 0);
}

static void check_text(const char *hex, const char *got, size_t len)
{
    static uint8_t want[600];
    size_t n = unhex(hex, want, sizeof want);
    CHECK(n == len && (n == 0 || memcmp(got, want, n) == 0), "%s: text of %zu bytes, expected %zu", R.session, len, n);
}

/* Whether the element bytes at p (n of them) are all the poison. */
static int poisoned(const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++) {
        if (b[i] != POISON) {
            return 0;
        }
    }
    return 1;
}

/* An absent field of urrt_state as the contract says: the caller's poison,
 * which no decode writes over; else NaN since the recipe's clear. */
static void check_absent_field(int f)
{
    const double *d = urrt_field_values(&R.st, (urrt_field_id)f);
    for (unsigned k = 0; k < urrt_field((urrt_field_id)f)->count; k++) {
        CHECK(R.poison ? poisoned(d + k, 8) : isnan(d[k]), "%s: absent %s[%u] is %s", R.session,
              urrt_field((urrt_field_id)f)->name, k, R.poison ? "written" : "not NaN");
    }
}

/* An absent RTDE-only variable likewise: poison, or NaN (doubles) and 0. */
static void check_absent_value(int var)
{
    const uint8_t *p = urrt_rtde_value(&R.vals, var);
    urrt_rtde_type t = urrt_rtde_var_type(var);
    unsigned n = urrt_rtde_type_size(t);
    int is_double = t == URRT_RTDE_T_DOUBLE || t == URRT_RTDE_T_VECTOR3D || t == URRT_RTDE_T_VECTOR6D;
    int ok = 1;
    if (R.poison) {
        ok = poisoned(p, n);
    } else {
        for (unsigned k = 0; k < n; k++) {
            ok &= is_double ? 1 : p[k] == 0;
        }
        for (unsigned k = 0; is_double && k < n / 8; k++) {
            double d;
            memcpy(&d, p + 8 * k, 8);
            ok &= isnan(d);
        }
    }
    CHECK(ok, "%s: absent variable %d is %s", R.session, var, R.poison ? "written" : "not NaN (or 0)");
}

/* After a data package: exactly the recipe's fields present in urrt_state,
 * exactly its RTDE-only variables present in urrt_rtde_values, whatever the
 * structs held (nothing of another recipe or session reads as present), and
 * every absent member as the contract says (check_absent_field). */
static void check_state_fields(void)
{
    for (int f = 0; f < URRT_FIELD_COUNT; f++) {
        int var = urrt_rtde_var_of_field((urrt_field_id)f), in_recipe = 0;
        for (size_t i = 0; i < R.var_count; i++) {
            in_recipe |= var >= 0 && R.vars[i] == var;
        }
        CHECK((int)urrt_has(&R.st, f) == in_recipe, "%s: field %d present %d", R.session, f, (int)urrt_has(&R.st, f));
        if (!in_recipe) {
            check_absent_field(f);
        }
    }
    CHECK(R.st.length == R.s.data_size && R.st.generation == URRT_GEN_3X && R.st.doubles == 0 &&
              R.st.extra_columns == 0, "%s: length %u", R.session, R.st.length);
    for (int var = URRT_RTDE_MAPPED_COUNT; var < URRT_RTDE_VAR_COUNT; var++) {
        int in_recipe = 0;
        for (size_t i = 0; i < R.var_count; i++) {
            in_recipe |= R.vars[i] == var;
        }
        CHECK((int)urrt_rtde_has(&R.vals, var) == in_recipe, "%s: var %d present", R.session, var);
        if (!in_recipe) {
            check_absent_value(var);
        }
    }
    for (size_t w = (URRT_RTDE_ONLY_COUNT + 31) / 32; w < URRT_RTDE_PRESENT_WORDS; w++) {
        CHECK(R.vals.present[w] == 0, "%s: present word %zu", R.session, w);
    }
    if (URRT_RTDE_ONLY_COUNT % 32 != 0) { /* the bits past the last variable */
        CHECK(R.vals.present[URRT_RTDE_ONLY_COUNT / 32] >> (URRT_RTDE_ONLY_COUNT % 32) == 0,
              "%s: present bits past the last variable", R.session);
    }
}

/* After the recipe is accepted: the structs the feed was given are cleared,
 * every member absent (NaN, 0), present none: what the recipe lacks stays
 * so for the session (no decode writes it). */
static void check_cleared(void)
{
    const double *d = (const double *)(const void *)&R.st;
    int bad = 0;
    for (size_t k = 0; k < offsetof(urrt_state, present) / 8; k++) {
        bad += !isnan(d[k]);
    }
    CHECK(bad == 0 && R.st.present == 0 && R.st.length == 0 && R.st.generation == URRT_GEN_UNKNOWN,
          "%s: after the recipe, %d doubles of the state are not NaN (present %llx)", R.session, bad,
          (unsigned long long)R.st.present);
    int saved = R.poison;
    R.poison = 0;
    for (int var = URRT_RTDE_MAPPED_COUNT; var < URRT_RTDE_VAR_COUNT; var++) {
        CHECK(!urrt_rtde_has(&R.vals, var), "%s: var %d present after the recipe", R.session, var);
        check_absent_value(var);
    }
    R.poison = saved;
    for (size_t w = 0; w < URRT_RTDE_PRESENT_WORDS; w++) {
        CHECK(R.vals.present[w] == 0, "%s: present word %zu after the recipe", R.session, w);
    }
}

static void check_event(char *args)
{
    char *kind = strtok(args, " ");
    int want = LOOKUP(kinds, kind);
    int k = next_event();
    CHECK(k == want, "%s: event %d (error %s), expected %s", R.session, k, urrt_rtde_strerror(R.ev.error), kind);
    if (k != want) {
        return;
    }
    char *a1 = strtok(NULL, " "), *a2 = strtok(NULL, " "), *a3 = strtok(NULL, " "), *a4 = strtok(NULL, " ");
    switch (want) {
    case URRT_RTDE_EV_PROTOCOL:
    case URRT_RTDE_EV_FALLBACK: CHECK_EQ_INT(R.ev.protocol, atoi(a1)); break;
    case URRT_RTDE_EV_CONTROLLER:
        CHECK(R.ev.version[0] == strtoul(a1, NULL, 10) && R.ev.version[1] == strtoul(a2, NULL, 10) &&
                  R.ev.version[2] == strtoul(a3, NULL, 10) && R.ev.version[3] == strtoul(a4, NULL, 10),
              "%s: controller %u.%u.%u.%u", R.session, R.ev.version[0], R.ev.version[1], R.ev.version[2],
              R.ev.version[3]);
        break;
    case URRT_RTDE_EV_RECIPE:
        CHECK_EQ_INT(R.ev.recipe_id, atoi(a1));
        check_cleared();
        break;
    case URRT_RTDE_EV_TEXT:
        CHECK_EQ_INT(R.ev.level, atoi(a1));
        check_text(a2, R.ev.text, R.ev.text_len);
        check_text(a3, R.ev.source, R.ev.source_len);
        break;
    case URRT_RTDE_EV_DATA:
        CHECK_EQ_INT(R.ev.first, atoi(a1));
        CHECK(urrt_rtde_up(&R.s), "%s: not up after a data package", R.session);
        check_state_fields();
        break;
    case URRT_RTDE_EV_DROP:
    case URRT_RTDE_EV_CONFIG:
        CHECK(R.ev.error == LOOKUP(errors, a1), "%s: %s, expected %s", R.session, urrt_rtde_strerror(R.ev.error), a1);
        CHECK(urrt_rtde_is_config_error(R.ev.error) == (want == URRT_RTDE_EV_CONFIG), "%s: error kind", R.session);
        if (R.ev.error == URRT_RTDE_E_NOT_FOUND) {
            char *names[URRT_RTDE_MAX_VARS] = {a2, a3, a4};
            size_t n = 0;
            while (n < 3 && names[n] != NULL) {
                n++;
            }
            while (n >= 3 && n < URRT_RTDE_MAX_VARS && (names[n] = strtok(NULL, " ")) != NULL) {
                n++;
            }
            for (size_t i = 0; i < n; i++) {
                CHECK_EQ_INT(urrt_rtde_not_found(&R.s, i), urrt_rtde_var_find(names[i], strlen(names[i])));
            }
            CHECK_EQ_INT(R.ev.not_found, n);
            CHECK_EQ_INT(urrt_rtde_not_found(&R.s, n), -1);
        }
        break;
    default: break;
    }
}

static uint64_t raw_value(int var, unsigned elem, int *width)
{
    const void *p = urrt_rtde_value(&R.vals, var);
    switch (urrt_rtde_var_type(var)) {
    case URRT_RTDE_T_BOOL:
    case URRT_RTDE_T_UINT8: *width = 2; return ((const uint8_t *)p)[elem];
    case URRT_RTDE_T_INT32:
    case URRT_RTDE_T_VECTOR6INT32: *width = 8; return (uint32_t)((const int32_t *)p)[elem];
    case URRT_RTDE_T_UINT32:
    case URRT_RTDE_T_VECTOR6UINT32: *width = 8; return ((const uint32_t *)p)[elem];
    case URRT_RTDE_T_UINT64: *width = 16; return ((const uint64_t *)p)[elem];
    default: {
        uint64_t u;
        memcpy(&u, (const double *)p + elem, 8);
        *width = 16;
        return u;
    }
    }
}

static void check_value(char *args)
{
    char *name = strtok(args, " ");
    unsigned elem = (unsigned)atoi(strtok(NULL, " "));
    const char *hex = strtok(NULL, " ");
    uint64_t want = strtoull(hex, NULL, 16), got;
    int var = urrt_rtde_var_find(name, strlen(name)), field = urrt_rtde_var_field(var), width = 16;
    if (field >= 0) {
        const double *d = urrt_field_values(&R.st, (urrt_field_id)field);
        CHECK(urrt_has(&R.st, field), "%s: %s not present", R.session, name);
        memcpy(&got, d + elem, 8);
    } else {
        CHECK(urrt_rtde_has(&R.vals, var), "%s: %s not present", R.session, name);
        got = raw_value(var, elem, &width);
    }
    CHECK(got == want && (int)strlen(hex) == width, "%s: %s[%u] = %0*llx, expected %s", R.session, name, elem, width,
          (unsigned long long)got, hex);
}

static void check_absent(const char *name)
{
    int var = urrt_rtde_var_find(name, strlen(name)), field = urrt_rtde_var_field(var);
    if (field >= 0) {
        CHECK(!urrt_has(&R.st, field), "%s: %s present", R.session, name);
        check_absent_field(field);
    } else {
        CHECK(!urrt_rtde_has(&R.vals, var), "%s: %s present", R.session, name);
        check_absent_value(var);
    }
}

static void directive(char *line)
{
    char *sp = strchr(line, ' ');
    char *arg = sp != NULL ? sp + 1 : line + strlen(line);
    if (sp != NULL) {
        *sp = '\0';
    }
    if (strcmp(line, "session") == 0) {
        snprintf(R.session, sizeof R.session, "%.40s/%s%u%s", arg, R.chunk == SIZE_MAX ? "whole" : "chunk ",
                 R.chunk == SIZE_MAX ? 0u : (unsigned)R.chunk, R.poison ? " poisoned" : "");
        urrt_rtde_init(&R.s);
        R.in_len = R.in_pos = 0;
        R.begun = 0;
        return;
    }
    if (strcmp(line, "vars") == 0) {
        parse_vars(arg);
        return;
    }
    if (strcmp(line, "freq") == 0) {
        R.freq = strtod(arg, NULL);
        return;
    }
    if (!R.begun) {
        do_begin(strcmp(line, "begin_error") == 0 ? arg : NULL);
    }
    if (strcmp(line, "send") == 0) {
        do_send(arg);
    } else if (strcmp(line, "recv") == 0) {
        R.in_len += unhex(arg, R.in + R.in_len, IN_MAX - R.in_len);
    } else if (strcmp(line, "event") == 0) {
        check_event(arg);
    } else if (strcmp(line, "idle") == 0) {
        CHECK_EQ_INT(next_event(), URRT_RTDE_EV_NONE);
    } else if (strcmp(line, "value") == 0) {
        check_value(arg);
    } else if (strcmp(line, "absent") == 0) {
        check_absent(arg);
    } else if (strcmp(line, "set_recipe") == 0 || strcmp(line, "set_recipe_error") == 0) {
        do_set_recipe(arg, strcmp(line, "set_recipe_error") == 0);
    } else if (strcmp(line, "pause") == 0) {
        CHECK_EQ_INT(urrt_rtde_pause(&R.s), URRT_OK);
    } else if (strcmp(line, "start") == 0) {
        CHECK_EQ_INT(urrt_rtde_start(&R.s), URRT_OK);
    } else if (strcmp(line, "finish") == 0) {
        CHECK_EQ_INT(urrt_rtde_finish(&R.s), atoi(arg));
    } else if (strcmp(line, "ended") == 0) {
        uint8_t out[URRT_RTDE_REQUEST_MAX];
        size_t used = 1;
        if (R.in_pos == R.in_len) { /* the error was at the last byte: feed one more package */
            R.in_len += unhex("000356", R.in + R.in_len, 3);
        }
        CHECK_EQ_INT(urrt_rtde_feed(&R.s, R.in + R.in_pos, R.in_len - R.in_pos, &used, &R.ev, &R.st, &R.vals),
                     URRT_RTDE_E_ENDED);
        CHECK_EQ_INT(used, 0);
        R.in_pos = R.in_len;
        CHECK_EQ_INT(urrt_rtde_output(&R.s, out, sizeof out), 0);
    } else if (strcmp(line, "end") == 0) {
        CHECK(R.in_pos == R.in_len, "%s: %zu bytes never fed", R.session, R.in_len - R.in_pos);
    } else if (strcmp(line, "begin_error") != 0) {
        CHECK(0, "unknown directive %s", line);
    }
}

static int run_vectors(const char *path, size_t chunk, int poison)
{
    static char line[LINE_MAX_CHARS];
    FILE *f = fopen(path, "r");
    int sessions = 0;
    if (f == NULL) {
        CHECK(0, "cannot open %s (run tests/ref/rtde_ref.py)", path);
        return 0;
    }
    R.chunk = chunk;
    R.poison = poison;
    while (fgets(line, sizeof line, f) != NULL) {
        line[strcspn(line, "\n")] = '\0';
        sessions += strncmp(line, "session ", 8) == 0;
        directive(line);
    }
    fclose(f);
    return sessions;
}

/* ---- every split point ---------------------------------------------------------- */

/* A session's controller stream and recipe, for replays. */
typedef struct replay {
    uint16_t vars[URRT_RTDE_MAX_VARS];
    size_t var_count;
    double freq;
    uint8_t stream[IN_MAX];
    size_t len;
} replay;

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++) {
        h = (h ^ b[i]) * UINT64_C(0x100000001b3);
    }
    return h;
}

/* Appends what an event says to a transcript (data as a hash of what was
 * decoded; nothing for no event), and the client's output after it. */
static void note_event(char *t, size_t *at, int k, const urrt_rtde_event *ev, const urrt_state *st,
                       const urrt_rtde_values *vals, urrt_rtde *s)
{
    uint64_t h = 0xcbf29ce484222325u;
    if (k == URRT_RTDE_EV_DATA) {
        h = fnv(fnv(h, st, sizeof *st), vals, sizeof *vals);
    } else if (k == URRT_RTDE_EV_TEXT) {
        h = fnv(fnv(h, ev->text, ev->text_len), ev->source, ev->source_len);
    }
    if (k != URRT_RTDE_EV_NONE) {
        *at += (size_t)snprintf(t + *at, TRANSCRIPT_MAX - *at, "%d %d %u %u %u %u %d %d %llx\n", k, ev->error,
                                ev->protocol, ev->recipe_id, ev->level, ev->version[0], ev->first, ev->not_found,
                                (unsigned long long)h);
    }
    uint8_t out[URRT_RTDE_REQUEST_MAX];
    int n;
    while ((n = urrt_rtde_output(s, out, sizeof out)) > 0) {
        check_request(out, n);
        *at += (size_t)snprintf(t + *at, TRANSCRIPT_MAX - *at, "out %d %c\n", n, out[2]);
    }
}

/* Feeds the stream cut at each point of cuts[] (ascending), the output taken
 * after every call; returns the transcript's length. */
static size_t transcript(const replay *r, const size_t *cuts, size_t ncuts, char *t)
{
    static urrt_rtde s;
    static urrt_state st;
    static urrt_rtde_values vals;
    urrt_rtde_event ev;
    size_t at = 0, pos = 0;
    urrt_rtde_init(&s);
    CHECK_EQ_INT(urrt_rtde_begin(&s, r->vars, r->var_count, r->freq), URRT_OK);
    note_event(t, &at, URRT_RTDE_EV_NONE, &(urrt_rtde_event){0}, &st, &vals, &s);
    for (size_t c = 0; c <= ncuts; c++) {
        size_t end = c < ncuts ? cuts[c] : r->len;
        while (pos < end) {
            size_t used;
            memset(&st, 0, sizeof st); /* padding too: the hash covers every byte */
            memset(&vals, 0, sizeof vals);
            int k = urrt_rtde_feed(&s, r->stream + pos, end - pos, &used, &ev, &st, &vals);
            pos += used;
            if (k < 0) {
                at += (size_t)snprintf(t + at, TRANSCRIPT_MAX - at, "ended %d\n", k);
                return at;
            }
            /* the output after every read, event or not, as a poll loop takes it */
            note_event(t, &at, k, &ev, &st, &vals, &s);
        }
    }
    return at;
}

static void check_splits(const replay *r, const char *name)
{
    static char whole[TRANSCRIPT_MAX], cut[TRANSCRIPT_MAX];
    size_t n = transcript(r, NULL, 0, whole), bad = 0;
    for (size_t k = 0; k <= r->len; k++) {
        size_t m = transcript(r, &k, 1, cut);
        bad += m != n || memcmp(whole, cut, n) != 0;
    }
    CHECK(bad == 0, "%s: %zu of %zu split points give other events", name, bad, r->len + 1);
    /* and one byte at a time */
    static size_t every[IN_MAX];
    for (size_t k = 0; k < r->len; k++) {
        every[k] = k;
    }
    size_t m = transcript(r, every, r->len, cut);
    CHECK(m == n && memcmp(whole, cut, n) == 0, "%s: byte by byte gives other events", name);
}

/* Every session of the vectors without caller actions in its middle. */
static void run_splits(const char *path)
{
    static char line[LINE_MAX_CHARS], name[64];
    static replay r;
    FILE *f = fopen(path, "r");
    int usable = 0, checked = 0;
    if (f == NULL) {
        return;
    }
    while (fgets(line, sizeof line, f) != NULL) {
        line[strcspn(line, "\n")] = '\0';
        char *arg = strchr(line, ' ');
        arg = arg != NULL ? arg + 1 : line;
        if (strncmp(line, "session ", 8) == 0) {
            snprintf(name, sizeof name, "split %.40s", arg);
            r.len = 0;
            usable = 1;
        } else if (strncmp(line, "vars ", 5) == 0) {
            r.var_count = 0;
            for (char *v = strtok(arg, ","); v != NULL && r.var_count < URRT_RTDE_MAX_VARS; v = strtok(NULL, ",")) {
                r.vars[r.var_count++] = (uint16_t)urrt_rtde_var_find(v, strlen(v));
            }
        } else if (strncmp(line, "freq ", 5) == 0) {
            r.freq = strtod(arg, NULL);
        } else if (strncmp(line, "recv ", 5) == 0) {
            r.len += unhex(arg, r.stream + r.len, IN_MAX - r.len);
        } else if (!strncmp(line, "pause", 5) || !strncmp(line, "start", 5) || !strncmp(line, "finish", 6) ||
                   !strncmp(line, "begin_error", 11) || !strncmp(line, "set_recipe", 10)) {
            usable = 0;
        } else if (strcmp(line, "end") == 0 && usable && r.len > 0) {
            check_splits(&r, name);
            checked++;
        }
    }
    fclose(f);
    CHECK(checked >= 30, "only %d sessions replayed at every split point", checked);
}

/* ---- the tables and the API without a controller ---------------------------------- */

static void test_names(void)
{
    char name[URRT_RTDE_NAME_MAX];
    for (int var = 0; var < URRT_RTDE_VAR_COUNT; var++) {
        int n = urrt_rtde_var_name(var, name, sizeof name);
        CHECK(n > 0 && urrt_rtde_var_find(name, (size_t)n) == var, "var %d: name %s does not find it", var, name);
        CHECK(urrt_rtde_var_type(var) != URRT_RTDE_T_NONE, "var %d has no type", var);
    }
    CHECK_EQ_INT(urrt_rtde_var_name(URRT_RTDE_VAR_COUNT, name, sizeof name), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_var_name(-1, name, sizeof name), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_var_name(URRT_RTDE_V_ACTUAL_Q, name, 8), URRT_E_NO_SPACE);
    CHECK_EQ_INT(urrt_rtde_var_name(URRT_RTDE_V_ACTUAL_Q, name, 9), 8);
    const char *bad[] = {"actual_Q", "output_int_register_48", "output_int_register_05", "output_bit_register_63",
                         "output_bit_register_128", "output_int_register_", "output_bit_register_0", "actual_q ",
                         "standard_analog_input2", "", "output_int_register_1x"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK(urrt_rtde_var_find(bad[i], strlen(bad[i])) == URRT_RTDE_E_UNKNOWN_NAME, "found \"%s\"", bad[i]);
    }
    CHECK_EQ_INT(urrt_rtde_var_find("output_bit_register_64", 22), URRT_RTDE_V_OUTPUT_BIT_REGISTER);
    CHECK_EQ_INT(urrt_rtde_var_find("output_int_register_47", 22), URRT_RTDE_V_OUTPUT_INT_REGISTER + 47);
    CHECK_EQ_INT(urrt_rtde_var_find("actual_q", 6), URRT_RTDE_E_UNKNOWN_NAME); /* "actual" */
    /* The RealTime field each name fills, as docs/rtde.md's table says. */
    CHECK_EQ_INT(urrt_rtde_var_field(urrt_rtde_var_find("actual_TCP_pose", 15)), URRT_F_TOOL_VECTOR_ACTUAL);
    CHECK_EQ_INT(urrt_rtde_var_field(urrt_rtde_var_find("payload", 7)), URRT_F_PAYLOAD_MASS);
    CHECK_EQ_INT(urrt_rtde_var_of_field(URRT_F_Q_ACTUAL), URRT_RTDE_V_ACTUAL_Q);
    CHECK_EQ_INT(urrt_rtde_var_of_field(URRT_F_TEST_VALUE), -1);
    CHECK_EQ_INT(urrt_rtde_var_field(URRT_RTDE_V_ROBOT_STATUS_BITS), -1);
    CHECK_EQ_STR(urrt_rtde_type_name(URRT_RTDE_T_VECTOR6UINT32), "VECTOR6UINT32");
    CHECK_EQ_INT(urrt_rtde_type_size(URRT_RTDE_T_VECTOR6INT32), 24);
}

static int avail(const char *name, unsigned a, unsigned b, unsigned c)
{
    return urrt_rtde_var_available(urrt_rtde_var_find(name, strlen(name)), a, b, c);
}

/* Versions as docs/rtde.md lists them. */
static void test_versions(void)
{
    CHECK_EQ_INT(avail("actual_q", 3, 4, 0), 1);
    CHECK_EQ_INT(avail("actual_q", 2, 0, 0), 0);
    CHECK_EQ_INT(avail("payload", 5, 5, 0), 0);
    CHECK_EQ_INT(avail("payload", 5, 5, 1), 1);
    CHECK_EQ_INT(avail("payload", 3, 10, 9), 0);
    CHECK_EQ_INT(avail("payload", 3, 11, 0), 1);
    CHECK_EQ_INT(avail("payload_inertia", 5, 10, 99), 0);
    CHECK_EQ_INT(avail("output_int_register_23", 3, 4, 0), 1);
    CHECK_EQ_INT(avail("output_int_register_23", 3, 3, 9), 0);
    CHECK_EQ_INT(avail("output_int_register_24", 3, 8, 0), 0);
    CHECK_EQ_INT(avail("output_int_register_24", 3, 9, 0), 1);
    CHECK_EQ_INT(avail("output_double_register_47", 5, 2, 0), 0);
    CHECK_EQ_INT(avail("output_double_register_47", 5, 3, 0), 1);
    CHECK_EQ_INT(avail("output_double_register_0", 5, 0, 0), 1);
    CHECK_EQ_INT(avail("output_bit_register_64", 5, 2, 9), 0);
    CHECK_EQ_INT(avail("ft_raw_wrench", 3, 15, 0), 0);
    CHECK_EQ_INT(avail("ft_raw_wrench", 5, 9, 0), 1);
    CHECK_EQ_INT(avail("ft_raw_wrench", 10, 0, 0), 1);
    CHECK_EQ_INT(avail("target_gravity", 10, 11, 0), 0);
    CHECK_EQ_INT(avail("target_gravity", 10, 12, 0), 1);
    CHECK_EQ_INT(avail("target_gravity", 5, 26, 0), 1);
    CHECK_EQ_INT(avail("safety_status", 3, 10, 0), 1);
    CHECK_EQ_INT(avail("safety_status", 5, 3, 0), 0);
    CHECK_EQ_INT(avail("tcp_offset", 5, 20, 0), URRT_RTDE_UNKNOWN);
    CHECK_EQ_INT(avail("time_scale_source", 3, 15, 0), 0);
    CHECK_EQ_INT(urrt_rtde_var_available(URRT_RTDE_VAR_COUNT, 5, 0, 0), URRT_E_ARG);
}

/* No recipe can overflow the buffer: the URRT_RTDE_MAX_VARS largest
 * variables' data package fits URRT_RTDE_PACKAGE_MAX. */
static void test_largest_recipe(void)
{
    unsigned sizes[URRT_RTDE_VAR_COUNT], total = 4;
    for (int var = 0; var < URRT_RTDE_VAR_COUNT; var++) {
        sizes[var] = urrt_rtde_type_size(urrt_rtde_var_type(var));
    }
    for (int k = 0; k < URRT_RTDE_MAX_VARS; k++) {
        int best = 0;
        for (int var = 1; var < URRT_RTDE_VAR_COUNT; var++) {
            best = sizes[var] > sizes[best] ? var : best;
        }
        total += sizes[best];
        sizes[best] = 0;
    }
    CHECK(total <= URRT_RTDE_PACKAGE_MAX, "largest recipe %u bytes", total);
}

static void test_api_errors(void)
{
    static urrt_rtde s;
    static urrt_state st;
    urrt_rtde_event ev;
    uint8_t out[8];
    size_t used;
    uint16_t vars[] = {URRT_RTDE_V_ACTUAL_Q, URRT_RTDE_V_OUTPUT_INT_REGISTER};
    urrt_rtde_init(&s);
    CHECK_EQ_INT(urrt_rtde_feed(&s, out, 1, &used, &ev, &st, NULL), URRT_RTDE_E_ENDED); /* before begin */
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, 0, 0.0), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, URRT_RTDE_MAX_VARS + 1, 0.0), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, 2, -1.0), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, 2, NAN), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_output(&s, out, sizeof out), 0); /* a refused begin queues nothing */
    uint16_t unknown[] = {URRT_RTDE_VAR_COUNT};
    CHECK_EQ_INT(urrt_rtde_begin(&s, unknown, 1, 0.0), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, 2, 0.0), URRT_OK);
    /* the recipe has an RTDE-only variable: values are required */
    CHECK_EQ_INT(urrt_rtde_feed(&s, out, 1, &used, &ev, &st, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_pause(&s), URRT_E_ARG); /* not streaming */
    CHECK_EQ_INT(urrt_rtde_start(&s), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_output(&s, out, 4), URRT_E_NO_SPACE);
    CHECK_EQ_INT(urrt_rtde_output(&s, out, 5), 5);
    CHECK_EQ_INT(urrt_rtde_write_start(out, 2), URRT_E_NO_SPACE);
    CHECK_EQ_INT(urrt_rtde_write_pause(out, 3), 3);
    CHECK(out[0] == 0 && out[1] == 3 && out[2] == 'P', "pause request");
    CHECK_EQ_INT(urrt_rtde_write_setup_outputs(out, sizeof out, 3, 0.0, vars, 1), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_write_setup_outputs(out, sizeof out, 1, 0.0, vars, 1), URRT_E_NO_SPACE);
    CHECK_EQ_INT(urrt_rtde_decode(&s, out, 3, &st, NULL), URRT_E_ARG);
    CHECK(strcmp(urrt_rtde_strerror(URRT_RTDE_E_NOT_FOUND), "ok") != 0, "strerror");
    CHECK_EQ_STR(urrt_rtde_strerror(URRT_E_NO_SPACE), urrt_strerror(URRT_E_NO_SPACE));
}

/* The ports an RTDE client never writes to, as UR documents the controller's
 * servers (dashboard 29999; primary, secondary, RealTime 30001-30003 and
 * their read-only twins 30011-30013; interpreter mode 30020), and their
 * neighbours, which a forwarded or simulated RTDE port may be. */
static void test_ports(void)
{
    static const uint32_t script[] = {29999, 30001, 30002, 30003, 30011, 30012, 30013, 30020};
    static const uint32_t other[] = {0, 1, 502, 29998, 30000, 30004, 30010, 30014, 30019, 30021, 40000, 65535, 95535};
    for (size_t i = 0; i < sizeof script / sizeof script[0]; i++) {
        CHECK(urrt_rtde_check_port(script[i]) == URRT_RTDE_E_SCRIPT_PORT && urrt_rtde_port_role(script[i]) != NULL,
              "port %u is refused", (unsigned)script[i]);
    }
    for (size_t i = 0; i < sizeof other / sizeof other[0]; i++) {
        CHECK(urrt_rtde_check_port(other[i]) == URRT_OK && urrt_rtde_port_role(other[i]) == NULL,
              "port %u is allowed", (unsigned)other[i]);
    }
    CHECK_EQ_STR(urrt_rtde_port_role(30003), "the RealTime interface, which runs the URScript it receives");
    CHECK_EQ_STR(urrt_rtde_port_role(30013), "the RealTime interface's read-only twin");
    CHECK(strstr(urrt_rtde_strerror(URRT_RTDE_E_SCRIPT_PORT), "30004") != NULL, "the error names RTDE's port");
}

/* What the vectors cannot say: ids out of range, null pointers, and that a
 * refused change keeps the recipe's need for values (a recipe of urrt_state
 * fields only still takes vals NULL). The controller's two replies are
 * docs/rtde.md's layouts: V accepted, v 5.12.0.1. */
static void test_set_recipe_api(void)
{
    static urrt_rtde s;
    static urrt_state st;
    static const uint8_t replies[] = {0, 4, 'V', 1, 0, 19, 'v', 0, 0, 0, 5, 0, 0, 0, 12, 0, 0, 0, 0, 0, 0, 0, 1};
    uint16_t mapped[] = {URRT_RTDE_V_ACTUAL_Q}, regs[] = {URRT_RTDE_V_OUTPUT_INT_REGISTER, URRT_RTDE_V_OUTPUT_INT_REGISTER};
    uint16_t unknown[] = {URRT_RTDE_V_TIMESTAMP, URRT_RTDE_VAR_COUNT};
    uint8_t out[URRT_RTDE_REQUEST_MAX];
    urrt_rtde_event ev;
    size_t used;
    urrt_rtde_init(&s);
    CHECK_EQ_INT(urrt_rtde_set_recipe(&s, mapped, 1), URRT_E_ARG); /* before begin */
    CHECK_EQ_INT(urrt_rtde_set_recipe(NULL, mapped, 1), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_begin(&s, mapped, 1, 0.0), URRT_OK);
    CHECK_EQ_INT(urrt_rtde_output(&s, out, sizeof out), 5);
    CHECK_EQ_INT(urrt_rtde_feed(&s, replies, sizeof replies, &used, &ev, &st, NULL), URRT_RTDE_EV_PROTOCOL);
    CHECK_EQ_INT(urrt_rtde_output(&s, out, sizeof out), 3);
    CHECK_EQ_INT(urrt_rtde_feed(&s, replies + 4, sizeof replies - 4, &used, &ev, &st, NULL), URRT_RTDE_EV_CONTROLLER);
    CHECK_EQ_INT(urrt_rtde_set_recipe(&s, NULL, 1), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_set_recipe(&s, mapped, URRT_RTDE_MAX_VARS + 1), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_set_recipe(&s, unknown, 2), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_set_recipe(&s, regs, 2), URRT_RTDE_E_DUPLICATE);
    CHECK_EQ_INT(urrt_rtde_feed(&s, replies, 0, &used, &ev, &st, NULL), URRT_RTDE_EV_NONE); /* vals not needed */
    CHECK(s.state_present == UINT64_C(1) << URRT_F_Q_ACTUAL, "a refused set_recipe changed the present mask");
    CHECK_EQ_INT(urrt_rtde_set_recipe(&s, regs, 1), URRT_OK);
    CHECK_EQ_INT(urrt_rtde_feed(&s, replies, 0, &used, &ev, &st, NULL), URRT_E_ARG); /* now they are */
}

/* The receive path: a data package a read holds whole is decoded where it
 * lies (s.buf untouched), one split across reads is gathered in s.buf, and
 * both decode alike; replies always land in s.buf (urrt_rtde_in_feed reads
 * an input setup reply there). The decode writes the recipe's values and
 * the present bits only: a struct written between packages keeps what the
 * recipe lacks, and a present bit of another recipe is cleared. */
static void test_in_place(void)
{
    static urrt_rtde s;
    static urrt_state st;
    static urrt_rtde_values vals;
    static const uint8_t replies[] = {0, 4, 'V', 1, 0, 19, 'v', 0, 0, 0, 5, 0, 0, 0, 12, 0, 0, 0, 0, 0, 0, 0, 1,
                                      0, 16, 'O', 9, 'D', 'O', 'U', 'B', 'L', 'E', ',', 'I', 'N', 'T', '3', '2',
                                      0, 4, 'S', 1};
    /* timestamp 1.5, output_int_register_24 -2 */
    static const uint8_t data[] = {0, 16, 'U', 9, 0x3F, 0xF8, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFE};
    uint16_t vars[] = {URRT_RTDE_V_TIMESTAMP, URRT_RTDE_V_OUTPUT_INT_REGISTER + 24};
    uint8_t out[URRT_RTDE_REQUEST_MAX], marker[sizeof data];
    urrt_rtde_event ev;
    size_t used, pos = 0;
    int k;
    urrt_rtde_init(&s);
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, 2, 0.0), URRT_OK);
    memset(&st, 0x11, sizeof st);
    memset(&vals, 0x11, sizeof vals);
    while (pos < sizeof replies) {
        while (urrt_rtde_output(&s, out, sizeof out) > 0) {
        }
        k = urrt_rtde_feed(&s, replies + pos, sizeof replies - pos, &used, &ev, &st, &vals);
        CHECK(k > 0, "handshake event %d", k);
        pos += used;
        if (k == URRT_RTDE_EV_RECIPE) { /* the recipe's clear */
            CHECK(st.present == 0 && isnan(st.q_actual[0]) && isnan(st.time[0]), "state not cleared");
            CHECK(vals.present[0] == 0 && vals.output_int_register[3] == 0 && isnan(vals.output_double_register[0]),
                  "values not cleared");
            CHECK(s.buf[2] == 'O', "the setup reply is not in s.buf");
        }
        if (k <= 0) {
            break;
        }
    }
    CHECK(urrt_rtde_streaming(&s), "not streaming after the handshake");
    /* whole in one read: decoded in place */
    memset(s.buf, 0xA5, sizeof data);
    memcpy(marker, s.buf, sizeof data);
    st.q_actual[0] = 7.0;                   /* the caller's own writes to what the recipe lacks */
    vals.output_int_register[3] = 33;
    st.present |= UINT64_C(1) << URRT_F_Q_ACTUAL; /* and a present bit of another recipe */
    vals.present[URRT_RTDE_PRESENT_WORDS - 1] = 0xFFFFFFFFu;
    CHECK_EQ_INT(urrt_rtde_feed(&s, data, sizeof data, &used, &ev, &st, &vals), URRT_RTDE_EV_DATA);
    CHECK(used == sizeof data && ev.first, "used %zu", used);
    CHECK(memcmp(s.buf, marker, sizeof data) == 0, "a whole data package was copied into s.buf");
    CHECK(st.time[0] == 1.5 && vals.output_int_register[24] == -2, "values %g %d", st.time[0],
          (int)vals.output_int_register[24]);
    CHECK(st.q_actual[0] == 7.0 && vals.output_int_register[3] == 33, "the decode wrote what the recipe lacks");
    CHECK(st.present == UINT64_C(1) << URRT_F_TIME && st.length == 16 && st.generation == URRT_GEN_3X,
          "present %llx", (unsigned long long)st.present);
    for (int var = URRT_RTDE_MAPPED_COUNT; var < URRT_RTDE_VAR_COUNT; var++) {
        CHECK((int)urrt_rtde_has(&vals, var) == (var == URRT_RTDE_V_OUTPUT_INT_REGISTER + 24), "var %d present", var);
    }
    /* behind another package in the same read, and split across reads: the same values */
    for (size_t cut = 1; cut < sizeof data; cut++) {
        st.time[0] = 0.0;
        vals.output_int_register[24] = 0;
        CHECK_EQ_INT(urrt_rtde_feed(&s, data, cut, &used, &ev, &st, &vals), URRT_RTDE_EV_NONE);
        CHECK_EQ_INT(urrt_rtde_feed(&s, data + cut, sizeof data - cut, &used, &ev, &st, &vals), URRT_RTDE_EV_DATA);
        CHECK(used == sizeof data - cut && !ev.first && st.time[0] == 1.5 && vals.output_int_register[24] == -2,
              "split at %zu", cut);
        CHECK(memcmp(s.buf, data, sizeof data) == 0, "split at %zu: not gathered in s.buf", cut);
    }
    /* a wrong recipe id in a whole package ends the session, as split */
    {
        uint8_t bad[sizeof data];
        memcpy(bad, data, sizeof data);
        bad[3] = 8;
        CHECK_EQ_INT(urrt_rtde_feed(&s, bad, sizeof bad, &used, &ev, &st, &vals), URRT_RTDE_EV_DROP);
        CHECK(ev.error == URRT_RTDE_E_RECIPE_ID && used == sizeof bad, "error %d, used %zu", ev.error, used);
    }
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s VECTORS (from tests/ref/rtde_ref.py)\n", argv[0]);
        return 2;
    }
    test_names();
    test_versions();
    test_largest_recipe();
    test_api_errors();
    test_set_recipe_api();
    test_in_place();
    test_ports();
    /* whole and in small reads; the caller's structs left alone (absent
     * members NaN and 0 from the recipe's clear on) and poisoned before
     * every read (the decode writes its values and present bits only) */
    int sessions = run_vectors(argv[1], SIZE_MAX, 0);
    CHECK(sessions >= 40, "only %d sessions in %s", sessions, argv[1]);
    run_vectors(argv[1], SIZE_MAX, 1);
    run_vectors(argv[1], 1, 1);
    run_vectors(argv[1], 7, 0);
    run_splits(argv[1]);
    return check_report();
}
