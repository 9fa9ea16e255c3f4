/* SPDX-License-Identifier: MIT */
/*
 * The RTDE client (lib/urrt_rtde) on the emulated Cortex-M cores, without a
 * C library: the reference's sessions (tests/ref/rtde_ref.py, as C data by
 * tests/target/rtde_vectors_c.py) fed whole, byte by byte and in 7-byte
 * reads, the client's output taken after every read as a poll loop does:
 * every request byte for byte, every event, every value bit for bit (what
 * tests/lib/test_rtde.c checks on the host from the same sessions). Built by
 * tests/target/target.mk as NAME/rtde.elf; RAM: one session, its values and
 * state (about 9 KiB: fits the Cortex-M0 board's 16 KiB).
 *
 * It also prints the stack high-water mark of every public urrt_rtde
 * function ("stack: NAME BYTES", as tests/target/stack_target.h does for the
 * rest of lib/), worst over the first pass, whose reads take every path
 * (and the calls the reads do not make, measured apart after it):
 * tests/target/stack.py holds them to -fstack-usage and docs/footprint.md.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../check.h"
#include "rtde_vectors.h"
#include "urrt_rtde.h"

static urrt_rtde s;
static urrt_state st;
static urrt_rtde_values vals;
static uint8_t out[URRT_RTDE_REQUEST_MAX];

#define STACK_MARKS_MAX 32
#include "stack_marks.h"

static size_t text_len(const char *t)
{
    size_t n = 0;
    while (t[n] != '\0') {
        n++;
    }
    return n;
}

static int var_of(const char *name)
{
    return urrt_rtde_var_find(name, text_len(name));
}

#include "../lib/rtde_names.h"

static uint64_t raw_of(const rtv_value *v)
{
    int var = var_of(v->name), field = urrt_rtde_var_field(var);
    uint64_t u = 0;
    if (field >= 0) {
        CHECK(urrt_has(&st, field), "%s not present", v->name);
        memcpy(&u, urrt_field_values(&st, (urrt_field_id)field) + v->elem, 8);
        return u;
    }
    CHECK(urrt_rtde_has(&vals, var), "%s not present", v->name);
    const void *p = urrt_rtde_value(&vals, var);
    switch (v->hex_digits) {
    case 2: return ((const uint8_t *)p)[v->elem];
    case 8: return ((const uint32_t *)p)[v->elem];
    default: memcpy(&u, (const uint64_t *)p + v->elem, 8); return u;
    }
}

static void check_event(const rtv_session *t, unsigned e, int k, const urrt_rtde_event *ev)
{
    const rtv_event *want = &t->events[e];
    CHECK(k == LOOKUP(kinds, want->kind), "%s: event %u is %d, not %s", t->name,
          e, k, want->kind);
    if (want->error != NULL) {
        CHECK(ev->error == LOOKUP(errors, want->error), "%s: error %d, not %s",
              t->name, ev->error, want->error);
    } else if (k == URRT_RTDE_EV_TEXT) {
        CHECK(ev->level == want->arg && ev->text_len == want->text_len && ev->source_len == want->source_len &&
                  memcmp(ev->text, want->text, want->text_len) == 0 &&
                  memcmp(ev->source, want->source, want->source_len) == 0,
              "%s: text event %u", t->name, e);
    } else if (k == URRT_RTDE_EV_DATA) {
        CHECK_EQ_INT(ev->first, want->arg);
        for (unsigned i = 0; i < t->value_count; i++) {
            const rtv_value *v = &t->values[i];
            if (v->event == e) {
                uint64_t got = raw_of(v);
                CHECK(got == v->raw, "%s: %s[%u] = %llx, expected %llx", t->name, v->name, v->elem,
                      (unsigned long long)got, (unsigned long long)v->raw);
            }
        }
    } else if (k == URRT_RTDE_EV_PROTOCOL || k == URRT_RTDE_EV_FALLBACK) {
        CHECK_EQ_INT(ev->protocol, want->arg);
    } else if (k == URRT_RTDE_EV_RECIPE) {
        CHECK_EQ_INT(ev->recipe_id, want->arg);
    }
}

/* Every request the client has due: the next bytes of t->sent. */
static void take_output(const rtv_session *t, size_t *sent)
{
    int n;
    for (;;) {
        MEASURED(n, urrt_rtde_output, (&s, out, sizeof out));
        if (n <= 0) {
            break;
        }
        CHECK(*sent + (size_t)n <= t->sent_len && memcmp(out, t->sent + *sent, (size_t)n) == 0,
              "%s: request %c of %d bytes at %u is not the reference's", t->name, out[2], n, (unsigned)*sent);
        *sent += (size_t)n;
    }
}

static void run(const rtv_session *t, size_t chunk)
{
    uint16_t vars[URRT_RTDE_MAX_VARS];
    size_t pos = 0, sent = 0;
    unsigned e = 0;
    int r;
    for (unsigned i = 0; i < t->var_count; i++) {
        MEASURED(r, urrt_rtde_var_find, (t->vars[i], text_len(t->vars[i])));
        vars[i] = (uint16_t)r;
    }
    MEASURED_VOID(urrt_rtde_init, (&s));
    MEASURED(r, urrt_rtde_begin, (&s, vars, t->var_count, t->freq));
    CHECK_EQ_INT(r, URRT_OK);
    take_output(t, &sent);
    while (pos < t->stream_len) {
        size_t n = t->stream_len - pos < chunk ? t->stream_len - pos : chunk, used;
        urrt_rtde_event ev;
        int k;
        MEASURED(k, urrt_rtde_feed, (&s, t->stream + pos, n, &used, &ev, &st, &vals));
        pos += used;
        if (k < 0) {
            break; /* ended by an earlier drop; the rest is refused */
        }
        if (k != URRT_RTDE_EV_NONE) {
            CHECK(e < t->event_count, "%s: more events than the reference's", t->name);
            if (e < t->event_count) {
                check_event(t, e, k, &ev);
            }
            if (k == URRT_RTDE_EV_DATA) { /* the package ends where the read was used up to */
                MEASURED(r, urrt_rtde_decode, (&s, t->stream + pos - s.data_size, s.data_size, &st, &vals));
                CHECK_EQ_INT(r, s.data_size);
            }
            e++;
        }
        take_output(t, &sent);
    }
    CHECK(e == t->event_count && sent == t->sent_len, "%s (reads of %u): %u of %u events, %u of %u request bytes",
          t->name, (unsigned)chunk, e, t->event_count, (unsigned)sent, (unsigned)t->sent_len);
}

/* The functions a session's reads do not call, on the state the last
 * session left (streaming, or ended), and the tables, each on its deepest
 * path (a family's name has digits to write, a version its column). */
static void measure_rest(void)
{
    static const uint16_t family[] = {URRT_RTDE_V_OUTPUT_DOUBLE_REGISTER + 47, URRT_RTDE_V_INPUT_BIT_REGISTER + 63};
    char name[URRT_RTDE_NAME_MAX];
    const void *p;
    const char *text;
    unsigned u;
    int r;
    bool b;
    double d;
    MEASURED(r, urrt_rtde_pause, (&s));
    MEASURED(r, urrt_rtde_start, (&s));
    MEASURED(b, urrt_rtde_up, (&s));
    MEASURED(r, urrt_rtde_not_found, (&s, 3));
    MEASURED(u, urrt_rtde_finish, (&s));
    MEASURED(text, urrt_rtde_strerror, (URRT_E_NO_SPACE));
    MEASURED(b, urrt_rtde_is_config_error, (URRT_RTDE_E_NOT_FOUND));
    MEASURED(text, urrt_rtde_type_name, (URRT_RTDE_T_VECTOR6D));
    MEASURED(u, urrt_rtde_type_size, (URRT_RTDE_T_VECTOR6D));
    MEASURED_VOID(urrt_rtde_values_clear, (&vals));
    MEASURED(p, urrt_rtde_value, (&vals, family[1]));
    MEASURED(r, urrt_rtde_var_name, (family[0], name, sizeof name));
    CHECK(r == 25 && CHECK_SAME_TEXT(name, "output_double_register_47"), "urrt_rtde_var_name: %s", name);
    MEASURED(r, urrt_rtde_var_type, (family[1]));
    MEASURED(r, urrt_rtde_var_field, (URRT_RTDE_V_ACTUAL_Q));
    MEASURED(r, urrt_rtde_var_of_field, (URRT_F_PAYLOAD_INERTIA));
    MEASURED(r, urrt_rtde_var_available, (family[0], 3, 8, 0));
    MEASURED(r, urrt_rtde_write_protocol_version, (out, sizeof out, 2));
    MEASURED(r, urrt_rtde_write_controller_version, (out, sizeof out));
    MEASURED(r, urrt_rtde_write_setup_outputs, (out, sizeof out, 2, 500.0, family, 2));
    MEASURED(r, urrt_rtde_write_start, (out, sizeof out));
    MEASURED(r, urrt_rtde_write_pause, (out, sizeof out));
    MEASURED(r, urrt_rtde_check_port, (30003u));
    MEASURED(d, urrt_rtde_max_frequency, (&s));
    MEASURED(text, urrt_rtde_port_role, (30013u));
    (void)p;
    (void)d;
    (void)u;
    (void)text;
    (void)b;
}

/* urrt_rtde_set_recipe, which the sessions' reads never call: the first
 * session's stream up to the controller's version (the setup request is
 * then due), and its recipe set again, every name checked and the absent
 * fields found (the one path it has past its argument checks). */
static void measure_set_recipe(void)
{
    const rtv_session *t = &rtv_sessions[0];
    uint16_t vars[URRT_RTDE_MAX_VARS];
    size_t pos = 0, used;
    urrt_rtde_event ev;
    int k = URRT_RTDE_EV_NONE, r;
    for (unsigned i = 0; i < t->var_count; i++) {
        vars[i] = (uint16_t)var_of(t->vars[i]);
    }
    urrt_rtde_init(&s);
    CHECK_EQ_INT(urrt_rtde_begin(&s, vars, t->var_count, t->freq), URRT_OK);
    while (k != URRT_RTDE_EV_CONTROLLER && k >= 0 && pos < t->stream_len) {
        while (urrt_rtde_output(&s, out, sizeof out) > 0) {
        }
        k = urrt_rtde_feed(&s, t->stream + pos, t->stream_len - pos, &used, &ev, &st, &vals);
        pos += used;
    }
    CHECK(k == URRT_RTDE_EV_CONTROLLER, "%s: no controller version to set a recipe after", t->name);
    MEASURED(r, urrt_rtde_set_recipe, (&s, vars, t->var_count));
    CHECK_EQ_INT(r, URRT_OK);
}

int main(void)
{
    static const size_t chunks[] = {SIZE_MAX, 1, 7};
    CHECK(rtv_session_count >= 10, "only %u sessions", rtv_session_count);
    for (unsigned c = 0; c < sizeof chunks / sizeof chunks[0]; c++) {
        measuring = c == 0;
        for (unsigned i = 0; i < rtv_session_count; i++) {
            run(&rtv_sessions[i], chunks[c]);
        }
    }
    measuring = true;
    measure_rest();
    measure_set_recipe();
    stack_marks_print();
    return check_report();
}
