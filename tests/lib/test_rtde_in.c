/* SPDX-License-Identifier: MIT */
/*
 * check-rtde-in: the writing side of the RTDE client (lib/urrt_rtde_in)
 * against the sessions of the independent reference (tests/ref/rtde_ref.py
 * --inputs plays the controller and says what the client must send, write
 * and refuse, byte for byte), fed whole, byte by byte and in 7-byte reads;
 * every split point of each session gives the same events and requests; the
 * read-only client alone, fed the same streams, writes nothing but V, v, O, S
 * and P; and the API without a controller.
 *   test_rtde_in VECTORS
 *
 * One source, three places: on the host and the big-endian CPUs
 * (check-lib-be) it reads VECTORS with stdio; in the bare-metal images of
 * tests/target (URRT_TARGET_CORTEX_M, no C library) it reads them through
 * semihosting (the file qemu's -semihosting-config arg= names), feeds whole,
 * byte by byte and in 7-byte reads, and prints the stack high-water mark of
 * every public urrt_rtde_in function ("stack: NAME BYTES", worst over the
 * first pass, as tests/target/rtde_target.c does for the reader) for
 * tests/target/stack.py. The split points run on the host only.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "check.h"
#include "urrt_rtde_in.h"

#ifndef URRT_TARGET_CORTEX_M
#include <stdio.h>
#include <string.h>
#endif

/* Buffers: the target's are sized for the Cortex-M0 board's 16 KiB (the
 * reference keeps its input sessions' lines and packages within them). */
#ifdef URRT_TARGET_CORTEX_M
#define LINE_CAP 800
#define QUEUE_CAP 192
#define OUT_CAP 400
#define VARS_CAP 16
#else
#define LINE_CAP 20000
#define QUEUE_CAP 8192
#define OUT_CAP URRT_RTDE_REQUEST_MAX
#define VARS_CAP URRT_RTDE_MAX_VARS
#endif
#define RECIPES 3
#define NAME_CAP 48

#define STACK_MARKS_MAX 20
#include "target/stack_marks.h"

/* ---- text, without a C library ----------------------------------------------------- */

static bool same(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return *a == *b;
}

static size_t text_len(const char *t)
{
    size_t n = 0;
    while (t[n] != '\0') {
        n++;
    }
    return n;
}

/* The next word of *p (split at c, which is overwritten), NULL at the end. */
static char *word(char **p, char c)
{
    char *w = *p, *e;
    if (w == NULL || *w == '\0') {
        return NULL;
    }
    for (e = w; *e != '\0' && *e != c; e++) {
    }
    *p = *e == c ? e + 1 : e;
    *e = '\0';
    return w;
}

static int hex_digit(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

static size_t unhex(const char *h, uint8_t *out, size_t cap)
{
    size_t n = 0;
    if (same(h, "-")) {
        return 0;
    }
    for (; h[0] != '\0' && h[1] != '\0'; h += 2) {
        CHECK(n < cap, "hex of more than %u bytes", (unsigned)cap);
        if (n == cap) {
            break;
        }
        out[n++] = (uint8_t)(hex_digit(h[0]) << 4 | hex_digit(h[1]));
    }
    return n;
}

static uint64_t hex64(const char *h)
{
    uint64_t v = 0;
    for (; *h != '\0'; h++) {
        v = v << 4 | (uint64_t)hex_digit(*h);
    }
    return v;
}

static int64_t dec64(const char *t)
{
    bool negative = *t == '-';
    uint64_t v = 0;
    for (t += negative; *t >= '0' && *t <= '9'; t++) {
        v = v * 10u + (uint64_t)(*t - '0');
    }
    return negative ? (int64_t)(0u - v) : (int64_t)v;
}

/* A frequency as the reference writes it ("0.0", "125.0", "25.5"). */
static double decimal(const char *t)
{
    double v = 0.0, scale = 1.0;
    for (; *t >= '0' && *t <= '9'; t++) {
        v = v * 10.0 + (double)(*t - '0');
    }
    if (*t == '.') {
        for (t++; *t >= '0' && *t <= '9'; t++) {
            scale /= 10.0;
            v += scale * (double)(*t - '0');
        }
    }
    return v;
}

static int var_of(const char *name)
{
    return urrt_rtde_var_find(name, text_len(name));
}

#include "rtde_names.h"

/* ---- the vectors, a line at a time -------------------------------------------------- */

static const char *vectors_path;
#ifdef URRT_TARGET_CORTEX_M
static int vectors_handle;
static uint8_t chunk_buf[128];
static size_t chunk_len, chunk_pos;

static bool vectors_open(void)
{
    vectors_handle = target_open_cmdline_file();
    chunk_len = chunk_pos = 0;
    return vectors_handle >= 0;
}

/* The next line without its newline; false at the end. */
static bool vectors_line(char *line, size_t cap)
{
    size_t n = 0;
    for (;;) {
        if (chunk_pos == chunk_len) {
            chunk_len = target_read(vectors_handle, chunk_buf, sizeof chunk_buf);
            chunk_pos = 0;
            if (chunk_len == 0) {
                line[n] = '\0';
                return n > 0;
            }
        }
        char c = (char)chunk_buf[chunk_pos++];
        if (c == '\n') {
            line[n < cap ? n : 0] = '\0';
            return true;
        }
        CHECK(n + 1 != cap, "a vector line longer than %u bytes", (unsigned)cap - 1u);
        if (n + 1 < cap) {
            line[n++] = c;
        } else {
            n = cap; /* reported once */
        }
    }
}
#else
static FILE *vectors_file;

static bool vectors_open(void)
{
    if (vectors_file != NULL) {
        fclose(vectors_file);
    }
    vectors_file = fopen(vectors_path, "r");
    return vectors_file != NULL;
}

static bool vectors_line(char *line, size_t cap)
{
    if (fgets(line, (int)cap, vectors_file) == NULL) {
        return false;
    }
    size_t n = text_len(line);
    CHECK(n + 1 < cap || line[n - 1] == '\n', "a vector line longer than %u bytes", (unsigned)cap);
    if (n > 0 && line[n - 1] == '\n') {
        line[n - 1] = '\0';
    }
    return true;
}
#endif

/* ---- the session runner ----------------------------------------------------------- */

static struct runner {
    urrt_rtde s;
    urrt_state st;
    urrt_rtde_values vals;
    urrt_rtde_event ev;
    urrt_rtde_in in[RECIPES];
    unsigned recipes;
    uint8_t queue[QUEUE_CAP]; /* received, not fed yet */
    size_t queued, fed;
    size_t chunk;
    uint16_t vars[VARS_CAP];
    size_t var_count;
    double freq;
    bool begun, ended;
    char session[NAME_CAP];
} R;
/* The client's output, what the reference says it must be, a vector line. */
static uint8_t out[OUT_CAP], want[OUT_CAP];
static char line[LINE_CAP];

static void copy_name(char *dst, const char *src)
{
    size_t i;
    for (i = 0; i + 1 < NAME_CAP && src[i] != '\0'; i++) {
        dst[i] = src[i];
    }
    dst[i] = '\0';
}

static size_t parse_vars(char *list, uint16_t *vars, size_t cap)
{
    size_t n = 0;
    for (char *name; (name = word(&list, ',')) != NULL;) {
        int var = var_of(name);
        CHECK(var >= 0, "%s: urrt_rtde_var_find(%s) = %d", R.session, name, var);
        if (n < cap) {
            vars[n++] = (uint16_t)(var < 0 ? 0 : var);
        }
    }
    return n;
}

/* Feeds the queue in reads of R.chunk until an event, as a poll loop does. */
static int next_event(void)
{
    size_t pos = 0;
    int k = URRT_RTDE_EV_NONE;
    while (pos < R.queued) {
        size_t n = R.queued - pos < R.chunk ? R.queued - pos : R.chunk, used = 99999;
        MEASURED(k, urrt_rtde_in_feed, (&R.s, R.in, R.recipes, R.queue + pos, n, &used, &R.ev, &R.st, &R.vals));
        CHECK(used <= n, "%s: used %u of %u", R.session, (unsigned)used, (unsigned)n);
        pos += used;
        R.fed += used;
        if (k != URRT_RTDE_EV_NONE) {
            break;
        }
        CHECK(used == n, "%s: no event but %u of %u used", R.session, (unsigned)used, (unsigned)n);
    }
    for (size_t i = pos; i < R.queued; i++) {
        R.queue[i - pos] = R.queue[i];
    }
    R.queued -= pos;
    return k;
}

static void do_begin(void)
{
    int r = urrt_rtde_begin(&R.s, R.vars, R.var_count, R.freq); /* measured by tests/target/rtde_target.c */
    CHECK(r == URRT_OK, "%s: begin: %s", R.session, urrt_rtde_strerror(r));
    MEASURED_VOID(urrt_rtde_in_begin, (R.in, R.recipes));
    R.begun = true;
}

/* Every request: whole, of a type the writing client has (never 'U': input
 * data packages come from urrt_rtde_in_package alone). */
static void check_request(const uint8_t *p, int n)
{
    CHECK(n >= 3 && (p[0] << 8 | p[1]) == n, "%s: request of %d bytes", R.session, n);
    CHECK(n >= 3 && (p[2] == 'V' || p[2] == 'v' || p[2] == 'O' || p[2] == 'I' || p[2] == 'S' || p[2] == 'P'),
          "%s: the client wrote a package of type %c", R.session, n >= 3 ? p[2] : '?');
}

static void do_send(const char *hex)
{
    size_t n = unhex(hex, want, sizeof want);
    int k;
    MEASURED(k, urrt_rtde_in_output, (&R.s, R.in, R.recipes, out, n - 1));
    CHECK_EQ_INT(k, URRT_E_NO_SPACE); /* one byte short: it stays due */
    MEASURED(k, urrt_rtde_in_output, (&R.s, R.in, R.recipes, out, sizeof out));
    CHECK(k == (int)n && memcmp(out, want, n) == 0, "%s: sent %d bytes (%c), expected %u (%c)", R.session, k,
          k >= 3 ? out[2] : '?', (unsigned)n, n >= 3 ? want[2] : '?');
    if (k > 0) {
        check_request(out, k);
    }
    MEASURED(k, urrt_rtde_in_output, (&R.s, R.in, R.recipes, out, sizeof out));
    CHECK(k == 0, "%s: %d more bytes (%c) after the request", R.session, k, k >= 3 ? out[2] : '?');
}

static uint64_t raw_value(int var, unsigned elem, unsigned *digits)
{
    const void *p = urrt_rtde_value(&R.vals, var);
    uint64_t u = 0;
    switch (urrt_rtde_var_type(var)) {
    case URRT_RTDE_T_BOOL:
    case URRT_RTDE_T_UINT8: *digits = 2; return ((const uint8_t *)p)[elem];
    case URRT_RTDE_T_INT32:
    case URRT_RTDE_T_VECTOR6INT32: *digits = 8; return (uint32_t)((const int32_t *)p)[elem];
    case URRT_RTDE_T_UINT32:
    case URRT_RTDE_T_VECTOR6UINT32: *digits = 8; return ((const uint32_t *)p)[elem];
    default: memcpy(&u, (const uint8_t *)p + 8u * elem, 8); *digits = 16; return u;
    }
}

static void check_value(char *args)
{
    const char *name = word(&args, ' ');
    unsigned elem = (unsigned)dec64(word(&args, ' '));
    const char *hex = word(&args, ' ');
    int var = var_of(name), field = urrt_rtde_var_field(var);
    unsigned digits = 16;
    uint64_t got = 0;
    if (field >= 0) {
        CHECK(urrt_has(&R.st, field), "%s: %s not present", R.session, name);
        memcpy(&got, urrt_field_values(&R.st, (urrt_field_id)field) + elem, 8);
    } else {
        CHECK(urrt_rtde_has(&R.vals, var), "%s: %s not present", R.session, name);
        got = raw_value(var, elem, &digits);
    }
    CHECK(got == hex64(hex) && digits == text_len(hex), "%s: %s[%u] = %llx, expected %s", R.session, name, elem,
          (unsigned long long)got, hex);
}

static void check_event(char *args)
{
    const char *kind = word(&args, ' ');
    char *a1 = word(&args, ' '), *a2 = word(&args, ' '), *a3 = word(&args, ' ');
    int expect = LOOKUP(kinds, kind), k = next_event();
    CHECK(k == expect, "%s: event %d (error %s), expected %s", R.session, k, urrt_rtde_strerror(R.ev.error), kind);
    if (k != expect) {
        return;
    }
    switch (expect) {
    case URRT_RTDE_EV_PROTOCOL:
    case URRT_RTDE_EV_FALLBACK: CHECK_EQ_INT(R.ev.protocol, dec64(a1)); break;
    case URRT_RTDE_EV_CONTROLLER: CHECK_EQ_INT(R.ev.version[0], dec64(a1)); break;
    case URRT_RTDE_EV_RECIPE: CHECK_EQ_INT(R.ev.recipe_id, dec64(a1)); break;
    case URRT_RTDE_EV_TEXT: {
        size_t n = unhex(a2, want, sizeof want);
        CHECK_EQ_INT(R.ev.level, dec64(a1));
        CHECK(n == R.ev.text_len && memcmp(R.ev.text, want, n) == 0, "%s: text", R.session);
        n = unhex(a3, want, sizeof want);
        CHECK(n == R.ev.source_len && memcmp(R.ev.source, want, n) == 0, "%s: source", R.session);
        break;
    }
    case URRT_RTDE_EV_DATA: CHECK_EQ_INT(R.ev.first, dec64(a1)); break;
    case URRT_RTDE_EV_INPUTS: {
        unsigned g = (unsigned)dec64(a1);
        bool ready;
        CHECK(R.ev.var == (int)g && R.ev.recipe_id == dec64(a2), "%s: inputs %d id %u, expected %s %s", R.session,
              R.ev.var, R.ev.recipe_id, a1, a2);
        CHECK(g < R.recipes && R.in[g].id == R.ev.recipe_id, "%s: recipe %u keeps its id", R.session, g);
        MEASURED(ready, urrt_rtde_in_ready, (&R.s, &R.in[g]));
        CHECK(!ready || urrt_rtde_streaming(&R.s), "%s: ready before streaming", R.session);
        break;
    }
    case URRT_RTDE_EV_DROP:
    case URRT_RTDE_EV_CONFIG:
        CHECK(R.ev.error == LOOKUP(errors, a1), "%s: %s, expected %s", R.session, urrt_rtde_strerror(R.ev.error), a1);
        CHECK(urrt_rtde_is_config_error(R.ev.error) == (expect == URRT_RTDE_EV_CONFIG), "%s: error kind", R.session);
        if (a2 != NULL) {
            CHECK(R.ev.var == var_of(a2), "%s: the refusal names var %d, expected %s", R.session, R.ev.var, a2);
        }
        if (a3 != NULL) {
            CHECK(R.ev.not_found == dec64(a3), "%s: %u refused, expected %s", R.session, R.ev.not_found, a3);
        }
        break;
    default: break;
    }
}

static urrt_rtde_in *recipe_arg(char **args)
{
    unsigned g = (unsigned)dec64(word(args, ' '));
    CHECK(g < R.recipes, "%s: no input recipe %u", R.session, g);
    return &R.in[g < R.recipes ? g : 0];
}

/* set G I int N RESULT | set G I double HEX RESULT */
static void do_set(char *args)
{
    urrt_rtde_in *in = recipe_arg(&args);
    size_t i = (size_t)dec64(word(&args, ' '));
    const char *kind = word(&args, ' '), *value = word(&args, ' '), *result = word(&args, ' ');
    uint64_t refused = in->stats.refused;
    int r;
    bool complete;
    if (same(kind, "int")) {
        MEASURED(r, urrt_rtde_in_set_int, (in, i, dec64(value)));
    } else {
        union {
            uint64_t u;
            double d;
        } b;
        b.u = hex64(value);
        MEASURED(r, urrt_rtde_in_set_double, (in, i, b.d));
    }
    CHECK(r == LOOKUP(errors, result), "%s: set %u %s %s gave %s, expected %s", R.session, (unsigned)i, kind, value,
          urrt_rtde_strerror(r), result);
    CHECK(in->stats.refused == refused + (r == URRT_RTDE_E_VALUE), "%s: refusals counted", R.session);
    MEASURED(complete, urrt_rtde_in_complete, (in));
    CHECK(r == URRT_OK || !complete, "%s: complete after a refused value", R.session);
}

/* package G HEX | package G ERR */
static void do_package(char *args)
{
    urrt_rtde_in *in = recipe_arg(&args);
    const char *what = word(&args, ' ');
    uint64_t packages = in->stats.packages;
    int k;
    bool ready;
    if (what[0] >= 'A' && what[0] <= 'Z') {
        int err = LOOKUP(errors, what);
        MEASURED(k, urrt_rtde_in_package, (&R.s, in, out, sizeof out));
        CHECK(k == err, "%s: package gave %d (%s), expected %s", R.session, k, urrt_rtde_strerror(k), what);
        MEASURED(ready, urrt_rtde_in_ready, (&R.s, in));
        CHECK(ready == (err != URRT_RTDE_E_NOT_STARTED), "%s: ready %d with %s", R.session, (int)ready, what);
        CHECK(in->stats.packages == packages, "%s: a refused package counted", R.session);
        return;
    }
    size_t n = unhex(what, want, sizeof want);
    MEASURED(k, urrt_rtde_in_package, (&R.s, in, out, n - 1));
    CHECK_EQ_INT(k, URRT_E_NO_SPACE);
    MEASURED(k, urrt_rtde_in_package, (&R.s, in, out, sizeof out));
    CHECK(k == (int)n && memcmp(out, want, n) == 0, "%s: package of %d bytes, expected %u (%s)", R.session, k,
          (unsigned)n, what);
    CHECK(in->stats.packages == packages + 1, "%s: packages counted", R.session);
}

static void do_inputs(char *args, bool must_fail)
{
    uint16_t vars[URRT_RTDE_IN_MAX_VARS + 8];
    const char *err = must_fail ? word(&args, ' ') : NULL;
    unsigned g = must_fail ? 0 : (unsigned)dec64(word(&args, ' '));
    size_t n = parse_vars(args, vars, sizeof vars / sizeof vars[0]);
    /* a refused one in the first unused slot: its init wipes it */
    urrt_rtde_in *in = &R.in[must_fail ? (R.recipes < RECIPES ? R.recipes : RECIPES - 1) : g < RECIPES ? g : 0];
    int r;
    CHECK(must_fail ? R.recipes < RECIPES : g == R.recipes && g < RECIPES, "%s: input recipe %u out of order",
          R.session, g);
    MEASURED(r, urrt_rtde_in_init, (in, vars, n));
    if (!must_fail) {
        CHECK(r == URRT_OK, "%s: init of recipe %u: %s", R.session, g, urrt_rtde_strerror(r));
        R.recipes = g + 1 < RECIPES ? g + 1 : RECIPES;
        return;
    }
    CHECK(r == LOOKUP(errors, err), "%s: init gave %s, expected %s", R.session, urrt_rtde_strerror(r), err);
    /* a refused recipe is unusable until a good init */
    CHECK_EQ_INT(urrt_rtde_in_output(&R.s, in, 1, out, sizeof out), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_set_int(in, 0, 0), URRT_E_ARG);
    CHECK(!urrt_rtde_in_complete(in) && !urrt_rtde_in_ready(&R.s, in), "%s: a refused recipe is usable", R.session);
}

static void directive(char *text)
{
    char *args = text;
    const char *what = word(&args, ' ');
    if (what == NULL) {
        return;
    }
    if (same(what, "session")) {
        copy_name(R.session, args);
        urrt_rtde_init(&R.s);
        R.recipes = 0;
        R.queued = R.fed = 0;
        R.begun = R.ended = false;
        return;
    }
    if (same(what, "vars")) {
        R.var_count = parse_vars(args, R.vars, VARS_CAP);
        return;
    }
    if (same(what, "freq")) {
        R.freq = decimal(args);
        return;
    }
    if (same(what, "inputs") || same(what, "inputs_error")) {
        do_inputs(args, same(what, "inputs_error"));
        return;
    }
    if (same(what, "end")) {
        CHECK(R.queued == 0, "%s: %u bytes never fed", R.session, (unsigned)R.queued);
        CHECK(R.ended || R.s.stats.bytes == R.fed, "%s: %llu bytes counted, %u fed", R.session,
              (unsigned long long)R.s.stats.bytes, (unsigned)R.fed);
        return;
    }
    if (!R.begun) {
        do_begin();
    }
    if (same(what, "send")) {
        do_send(args);
    } else if (same(what, "recv")) {
        R.queued += unhex(args, R.queue + R.queued, sizeof R.queue - R.queued);
    } else if (same(what, "event")) {
        check_event(args);
    } else if (same(what, "idle")) {
        CHECK_EQ_INT(next_event(), URRT_RTDE_EV_NONE);
    } else if (same(what, "value")) {
        check_value(args);
    } else if (same(what, "set")) {
        do_set(args);
    } else if (same(what, "forget")) {
        urrt_rtde_in *in = recipe_arg(&args);
        bool complete;
        MEASURED_VOID(urrt_rtde_in_forget, (in));
        MEASURED(complete, urrt_rtde_in_complete, (in));
        CHECK(!complete, "%s: complete after forget", R.session);
    } else if (same(what, "package")) {
        do_package(args);
    } else if (same(what, "refused")) {
        urrt_rtde_in *in = recipe_arg(&args);
        CHECK_EQ_INT(in->stats.refused, dec64(args));
    } else if (same(what, "ignored")) {
        CHECK_EQ_INT(R.s.stats.ignored, dec64(args));
    } else if (same(what, "pause")) {
        CHECK_EQ_INT(urrt_rtde_pause(&R.s), URRT_OK);
    } else if (same(what, "start")) {
        CHECK_EQ_INT(urrt_rtde_start(&R.s), URRT_OK);
    } else if (same(what, "reconnect")) {
        CHECK_EQ_INT(R.queued, 0);
        CHECK_EQ_INT(urrt_rtde_finish(&R.s), 0);
        do_begin();
    } else if (same(what, "ended")) {
        size_t used = 1;
        int k;
        static const uint8_t more[] = {0, 4, 'I', 1};
        MEASURED(k, urrt_rtde_in_feed, (&R.s, R.in, R.recipes, more, sizeof more, &used, &R.ev, &R.st, &R.vals));
        CHECK(k == URRT_RTDE_E_ENDED && used == 0, "%s: fed after the end: %d, %u used", R.session, k,
              (unsigned)used);
        MEASURED(k, urrt_rtde_in_output, (&R.s, R.in, R.recipes, out, sizeof out));
        CHECK_EQ_INT(k, 0);
        R.queued = 0;
        R.ended = true;
    } else {
        CHECK(0, "%s: unknown directive %s", R.session, what);
    }
}

static int run_vectors(size_t chunk)
{
    int sessions = 0;
    if (!vectors_open()) {
        CHECK(0, "cannot open the vectors %s (tests/ref/rtde_ref.py --inputs)", vectors_path);
        return 0;
    }
    R.chunk = chunk;
    while (vectors_line(line, sizeof line)) {
        sessions += line[0] == 's' && line[1] == 'e' && line[2] == 's';
        directive(line);
    }
    return sessions;
}

/* ---- the API without a controller ------------------------------------------------- */

/* The functions no session reaches, each on its deepest path. */
static void test_api(void)
{
    urrt_rtde *sp = &R.s;
    urrt_rtde_in *ip = &R.in[0];
    uint8_t *big = (uint8_t *)line; /* the largest request fits on the host; the M0's line is smaller */
    uint16_t all[URRT_RTDE_IN_MAX_VARS + 1];
    size_t names = 0;
    uint16_t regs[] = {URRT_RTDE_V_INPUT_INT_REGISTER + 24, URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 47};
#define s (*sp)
#define in (*ip)
    urrt_rtde_event ev;
    size_t used;
    bool b;
    int r, writable = 0;
    /* exactly the general purpose input registers are writable */
    for (int var = -1; var <= URRT_RTDE_VAR_COUNT; var++) {
        MEASURED(b, urrt_rtde_in_writable, (var));
        char name[URRT_RTDE_NAME_MAX];
        bool input = urrt_rtde_var_name(var, name, sizeof name) > 0 && name[0] == 'i' && name[1] == 'n' &&
                     name[2] == 'p' && name[5] == '_' && (name[6] == 'b' || name[6] == 'i' || name[6] == 'd');
        CHECK(b == input, "var %d (%s) writable %d", var, input ? name : "-", (int)b);
        writable += b;
    }
    CHECK_EQ_INT(writable, 2 + 64 + 48 + 48);
    /* init: arguments, and the largest recipe: 64 registers */
    CHECK_EQ_INT(urrt_rtde_in_init(NULL, regs, 2), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_init(&in, NULL, 2), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_init(&in, regs, 0), URRT_E_ARG);
    all[0] = URRT_RTDE_VAR_COUNT;
    CHECK_EQ_INT(urrt_rtde_in_init(&in, all, 1), URRT_E_ARG);
    for (unsigned i = 0; i <= URRT_RTDE_IN_MAX_VARS; i++) {
        all[i] = (uint16_t)(URRT_RTDE_V_INPUT_BIT_REGISTER + i % 64u + (i == 64 ? URRT_RTDE_V_INPUT_DOUBLE_REGISTER -
                                                                              URRT_RTDE_V_INPUT_BIT_REGISTER : 0));
    }
    CHECK_EQ_INT(urrt_rtde_in_init(&in, all, URRT_RTDE_IN_MAX_VARS + 1), URRT_E_ARG);
    MEASURED(r, urrt_rtde_in_init, (&in, all, URRT_RTDE_IN_MAX_VARS));
    CHECK_EQ_INT(r, URRT_OK);
    CHECK_EQ_INT(in.data_size, URRT_RTDE_IN_MAX_VARS);
    for (unsigned i = 0; i < URRT_RTDE_IN_MAX_VARS; i++) {
        char name[URRT_RTDE_NAME_MAX];
        names += (size_t)urrt_rtde_var_name(all[i], name, sizeof name) + 1u;
    }
    MEASURED(r, urrt_rtde_in_write_setup, (big, sizeof line, &in));
    if (3 + names - 1 <= sizeof line) {
        CHECK(r == (int)(3 + names - 1) && r <= URRT_RTDE_IN_REQUEST_MAX && big[2] == 'I' &&
                  (big[0] << 8 | big[1]) == r,
              "the largest recipe's request: %d bytes", r);
        CHECK_EQ_INT(urrt_rtde_in_write_setup(big, (size_t)r - 1, &in), URRT_E_NO_SPACE);
    } else {
        CHECK_EQ_INT(r, URRT_E_NO_SPACE);
    }
    CHECK_EQ_INT(urrt_rtde_in_write_setup(NULL, sizeof line, &in), URRT_E_ARG);
    for (unsigned i = 0; i < URRT_RTDE_IN_MAX_VARS; i++) {
        all[i] = (uint16_t)(URRT_RTDE_V_INPUT_DOUBLE_REGISTER + i % 48u);
        all[i] = (uint16_t)(i < 48 ? all[i] : URRT_RTDE_V_INPUT_INT_REGISTER + i - 48u);
    }
    CHECK_EQ_INT(urrt_rtde_in_init(&in, all, URRT_RTDE_IN_MAX_VARS), URRT_OK);
    CHECK_EQ_INT(in.data_size, 48 * 8 + 16 * 4);
    /* values: index out of range, every register kind */
    CHECK_EQ_INT(urrt_rtde_in_set_int(&in, URRT_RTDE_IN_MAX_VARS, 0), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_set_double(NULL, 0, 0.0), URRT_E_ARG);
    for (unsigned i = 0; i < URRT_RTDE_IN_MAX_VARS; i++) {
        CHECK_EQ_INT(urrt_rtde_in_set_double(&in, i, (double)i), URRT_OK);
    }
    MEASURED(b, urrt_rtde_in_complete, (&in));
    CHECK(b, "every register given");
    /* a session that never began: nothing is written */
    urrt_rtde_init(&s);
    MEASURED(r, urrt_rtde_in_package, (&s, &in, big, sizeof line));
    CHECK_EQ_INT(r, URRT_RTDE_E_NOT_STARTED);
    CHECK_EQ_INT(urrt_rtde_in_package(NULL, &in, big, sizeof line), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_output(&s, &in, 1, NULL, 8), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_output(&s, NULL, 1, big, 8), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_feed(&s, &in, 1, big, 1, NULL, &ev, NULL, NULL), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_in_feed(&s, &in, 1, big, 1, &used, &ev, NULL, NULL), URRT_RTDE_E_ENDED);
    /* the reader's three functions for the writer */
    MEASURED(r, urrt_rtde_due, (&s));
    CHECK_EQ_INT(r, 0);
    CHECK_EQ_INT(urrt_rtde_begin(&s, regs, 2, 0.0), URRT_OK);
    MEASURED(r, urrt_rtde_due, (&s));
    CHECK_EQ_INT(r, 'V');
    MEASURED(b, urrt_rtde_streaming, (&s));
    CHECK(!b, "streaming before start");
    MEASURED(r, urrt_rtde_end, (&s, &ev, URRT_RTDE_E_IN_USE));
    CHECK(r == URRT_RTDE_EV_CONFIG && ev.error == URRT_RTDE_E_IN_USE && urrt_rtde_due(&s) == 0, "end: config");
    CHECK_EQ_INT(urrt_rtde_feed(&s, big, 1, &used, &ev, NULL, NULL), URRT_E_ARG); /* the recipe needs values */
    CHECK_EQ_INT(urrt_rtde_feed(&s, big, 1, &used, &ev, NULL, &R.vals), URRT_RTDE_E_ENDED);
    CHECK_EQ_INT(urrt_rtde_begin(&s, regs, 2, 0.0), URRT_OK);
    CHECK_EQ_INT(urrt_rtde_end(&s, &ev, URRT_RTDE_E_TYPE_TOKEN), URRT_RTDE_EV_DROP);
    CHECK_EQ_INT(urrt_rtde_end(&s, NULL, URRT_RTDE_E_TYPE_TOKEN), URRT_E_ARG);
    CHECK_EQ_INT(urrt_rtde_end(&s, &ev, URRT_OK), URRT_E_ARG);
    CHECK(!urrt_rtde_streaming(NULL) && urrt_rtde_due(NULL) == 0, "null sessions");
    /* the new results: configuration errors -48..-54, texts of their own */
    for (int e = -64; e <= -44; e++) {
        CHECK(urrt_rtde_is_config_error(e) == (e <= -48 && e >= -54), "is_config_error(%d)", e);
    }
    static const int news[] = {URRT_RTDE_E_IN_USE, URRT_RTDE_E_INPUTS_PROTOCOL, URRT_RTDE_E_NOT_WRITABLE,
                               URRT_RTDE_E_VALUE, URRT_RTDE_E_NOT_STARTED, URRT_RTDE_E_INCOMPLETE};
    for (size_t i = 0; i < sizeof news / sizeof news[0]; i++) {
        CHECK(!same(urrt_rtde_strerror(news[i]), urrt_strerror(news[i])), "strerror(%d) has a text", news[i]);
    }
    MEASURED_VOID(urrt_rtde_in_begin, (NULL, 1));
    MEASURED_VOID(urrt_rtde_in_forget, (NULL));
#undef s
#undef in
}

/* ---- every split point (host) ------------------------------------------------------- */

#ifndef URRT_TARGET_CORTEX_M
typedef struct replay {
    uint16_t vars[URRT_RTDE_MAX_VARS];
    size_t var_count;
    uint16_t in_vars[RECIPES][URRT_RTDE_IN_MAX_VARS];
    size_t in_count[RECIPES];
    unsigned recipes;
    double freq;
    uint8_t stream[QUEUE_CAP * 4];
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

#define TRANSCRIPT_MAX 65536

/* The events of the stream cut at the points cuts[] (ascending), the output
 * taken after every call; with reader set, the read-only client alone (no
 * inputs), whose every request must be V, v, O, S or P. */
static size_t transcript(const replay *r, const size_t *cuts, size_t ncuts, char *t, bool reader)
{
    static urrt_rtde s;
    static urrt_rtde_in in[RECIPES];
    static urrt_state st;
    static urrt_rtde_values vals;
    urrt_rtde_event ev;
    size_t at = 0, pos = 0;
    unsigned n = reader ? 0 : r->recipes;
    urrt_rtde_init(&s);
    for (unsigned g = 0; g < n; g++) {
        CHECK_EQ_INT(urrt_rtde_in_init(&in[g], r->in_vars[g], r->in_count[g]), URRT_OK);
    }
    CHECK_EQ_INT(urrt_rtde_begin(&s, r->vars, r->var_count, r->freq), URRT_OK);
    urrt_rtde_in_begin(in, n);
    for (size_t c = 0; c <= ncuts; c++) {
        size_t end = c < ncuts ? cuts[c] : r->len;
        int k = URRT_RTDE_EV_NONE;
        for (;;) {
            int w;
            while ((w = reader ? urrt_rtde_output(&s, out, sizeof out) : urrt_rtde_in_output(&s, in, n, out, sizeof out)) > 0) {
                CHECK(!reader || out[2] == 'V' || out[2] == 'v' || out[2] == 'O' || out[2] == 'S' || out[2] == 'P',
                      "the read-only client wrote a package of type %c", out[2]);
                at += (size_t)snprintf(t + at, TRANSCRIPT_MAX - at, "out %d %c\n", w, out[2]);
            }
            if (pos == end || k < 0) {
                break;
            }
            size_t used;
            memset(&st, 0, sizeof st);
            memset(&vals, 0, sizeof vals);
            k = reader ? urrt_rtde_feed(&s, r->stream + pos, end - pos, &used, &ev, &st, &vals)
                       : urrt_rtde_in_feed(&s, in, n, r->stream + pos, end - pos, &used, &ev, &st, &vals);
            pos += used;
            if (k < 0) {
                at += (size_t)snprintf(t + at, TRANSCRIPT_MAX - at, "ended %d\n", k);
                return at;
            }
            if (k != URRT_RTDE_EV_NONE) {
                uint64_t h = k == URRT_RTDE_EV_DATA ? fnv(fnv(0, &st, sizeof st), &vals, sizeof vals)
                             : k == URRT_RTDE_EV_TEXT ? fnv(fnv(0, ev.text, ev.text_len), ev.source, ev.source_len)
                                                      : 0;
                at += (size_t)snprintf(t + at, TRANSCRIPT_MAX - at, "%d %d %u %d %u %llx\n", k, ev.error,
                                       ev.recipe_id, ev.var, ev.not_found, (unsigned long long)h);
            }
        }
    }
    at += (size_t)snprintf(t + at, TRANSCRIPT_MAX - at, "ignored %llu bytes %llu\n",
                           (unsigned long long)s.stats.ignored, (unsigned long long)s.stats.bytes);
    return at;
}

static void check_splits(const replay *r, const char *name)
{
    static char whole[TRANSCRIPT_MAX], cut[TRANSCRIPT_MAX];
    static size_t every[QUEUE_CAP * 4];
    size_t n = transcript(r, NULL, 0, whole, false), bad = 0;
    for (size_t k = 0; k <= r->len; k++) {
        size_t m = transcript(r, &k, 1, cut, false);
        bad += m != n || memcmp(whole, cut, n) != 0;
    }
    CHECK(bad == 0, "%s: %u of %u split points give other events", name, (unsigned)bad, (unsigned)r->len + 1);
    for (size_t k = 0; k < r->len; k++) {
        every[k] = k;
    }
    size_t m = transcript(r, every, r->len, cut, false);
    CHECK(m == n && memcmp(whole, cut, n) == 0, "%s: byte by byte gives other events", name);
    transcript(r, NULL, 0, cut, true);
    transcript(r, every, r->len, cut, true);
}

/* Every session without caller actions between its packages. */
static void run_splits(void)
{
    static char name[NAME_CAP];
    static replay r;
    bool usable = false;
    int checked = 0;
    if (!vectors_open()) {
        return;
    }
    while (vectors_line(line, sizeof line)) {
        char *args = line;
        const char *what = word(&args, ' ');
        if (what == NULL) {
            continue;
        }
        if (same(what, "session")) {
            copy_name(name, args);
            r.len = 0;
            r.recipes = 0;
            usable = true;
        } else if (same(what, "vars")) {
            r.var_count = parse_vars(args, r.vars, URRT_RTDE_MAX_VARS);
        } else if (same(what, "freq")) {
            r.freq = decimal(args);
        } else if (same(what, "inputs")) {
            unsigned g = (unsigned)dec64(word(&args, ' '));
            if (g < RECIPES) {
                r.in_count[g] = parse_vars(args, r.in_vars[g], URRT_RTDE_IN_MAX_VARS);
                r.recipes = g + 1;
            }
        } else if (same(what, "recv")) {
            r.len += unhex(args, r.stream + r.len, sizeof r.stream - r.len);
        } else if (same(what, "pause") || same(what, "start") || same(what, "finish") || same(what, "reconnect") ||
                   same(what, "inputs_error")) {
            usable = false;
        } else if (same(what, "end") && usable && r.len > 0) {
            check_splits(&r, name);
            checked++;
        }
    }
    CHECK(checked >= 20, "only %d sessions replayed at every split point", checked);
}
#endif

int main(int argc, char **argv)
{
    static const size_t chunks[] = {SIZE_MAX, 1, 7};
#ifdef URRT_TARGET_CORTEX_M
    (void)argc;
    (void)argv;
    vectors_path = "(semihosting)";
#else
    if (argc != 2) {
        fprintf(stderr, "usage: %s VECTORS (from tests/ref/rtde_ref.py --inputs)\n", argv[0]);
        return 2;
    }
    vectors_path = argv[1];
#endif
    for (unsigned c = 0; c < sizeof chunks / sizeof chunks[0]; c++) {
#ifdef URRT_TARGET_CORTEX_M
        measuring = c == 0;
#endif
        int sessions = run_vectors(chunks[c]);
        CHECK(sessions >= 20, "only %d sessions in %s", sessions, vectors_path);
    }
#ifdef URRT_TARGET_CORTEX_M
    measuring = true;
#endif
    test_api();
#ifdef URRT_TARGET_CORTEX_M
    stack_marks_print();
#else
    run_splits();
#endif
    return check_report();
}
