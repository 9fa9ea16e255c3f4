/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness of the RTDE client (lib/urrt_rtde): the input is what a
 * controller sends on port 30004, after one byte that says how it is cut
 * into reads. The client's requests are taken after every read, as a poll
 * loop does, so a well-formed input walks the whole handshake (the seeds,
 * from tests/ref/rtde_ref.py, do) and the fuzzer mutates every reply and
 * data package from there. Invariants of docs/rtde.md's security model:
 *   - feed consumes at most what it is given, and all of it when it reports
 *     no event; an ended session refuses input and writes nothing more;
 *   - every byte the client writes is a whole V, v, O, S or P request;
 *   - a text event points into the text message's package;
 *   - a data event's present bits are exactly the recipe's variables,
 *     whatever the structs held (they are poisoned before every read), and
 *     nothing else of them is written (what the recipe lacks keeps the
 *     poison); the recipe's event clears them;
 *   - a NOT_FOUND error names as many variables as it counts.
 * The recipe is the reference's FUZZ_VARS: every wire type an output has.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "urrt_rtde.h"

#define ASSERT(cond)      \
    do {                  \
        if (!(cond)) {    \
            abort();      \
        }                 \
    } while (0)

static const char *const fuzz_vars[] = {
    "timestamp", "actual_q", "robot_mode", "joint_mode", "runtime_state", "actual_digital_input_bits",
    "actual_tool_accelerometer", "output_bit_register_64", "tool_output_mode", "robot_status_bits",
    "control_step", "output_int_register_5", "output_double_register_47", "target_gravity", "tcp_offset",
};
#define NVARS (sizeof fuzz_vars / sizeof fuzz_vars[0])

static urrt_rtde s;
static urrt_state st;
static urrt_rtde_values vals;
static uint16_t vars[NVARS];
static uint64_t mask;

static void take_output(void)
{
    static uint8_t out[URRT_RTDE_REQUEST_MAX];
    int n;
    while ((n = urrt_rtde_output(&s, out, sizeof out)) > 0) {
        ASSERT(n >= 3 && (out[0] << 8 | out[1]) == n);
        ASSERT(out[2] == 'V' || out[2] == 'v' || out[2] == 'O' || out[2] == 'S' || out[2] == 'P');
    }
    ASSERT(n == 0);
}

#define POISON 0x3F

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

static void check_data(void)
{
    ASSERT(st.present == mask && st.length == s.data_size && st.generation == URRT_GEN_3X);
    for (unsigned f = 0; f < URRT_FIELD_COUNT; f++) {
        if (((mask >> f) & 1u) == 0) {
            ASSERT(poisoned(urrt_field_values(&st, (urrt_field_id)f), 8u * urrt_field((urrt_field_id)f)->count));
        }
    }
    for (unsigned v = URRT_RTDE_MAPPED_COUNT; v < URRT_RTDE_VAR_COUNT; v++) {
        int want = 0;
        for (size_t i = 0; i < NVARS; i++) {
            want |= vars[i] == v;
        }
        ASSERT((int)urrt_rtde_has(&vals, v) == want);
        if (!want) {
            ASSERT(poisoned(urrt_rtde_value(&vals, (int)v), urrt_rtde_type_size(urrt_rtde_var_type((int)v))));
        }
    }
}

/* The recipe's event: both structs cleared, nothing present. */
static void check_cleared(void)
{
    ASSERT(st.present == 0 && st.generation == URRT_GEN_UNKNOWN);
    for (unsigned v = URRT_RTDE_MAPPED_COUNT; v < URRT_RTDE_VAR_COUNT; v++) {
        ASSERT(!urrt_rtde_has(&vals, v));
    }
}

static void check_event(int k, const urrt_rtde_event *ev)
{
    /* the package just parsed is still in the buffer, its size in front */
    const char *lo = (const char *)s.buf + URRT_RTDE_HEADER_SIZE, *hi = (const char *)s.buf + (s.buf[0] << 8 | s.buf[1]);
    switch (k) {
    case URRT_RTDE_EV_TEXT:
        ASSERT(ev->text >= lo && ev->text + ev->text_len <= hi);
        ASSERT(ev->source >= lo && ev->source + ev->source_len <= hi);
        break;
    case URRT_RTDE_EV_DATA: check_data(); break;
    case URRT_RTDE_EV_RECIPE: check_cleared(); break;
    case URRT_RTDE_EV_DROP:
    case URRT_RTDE_EV_CONFIG:
        ASSERT(ev->error < 0 && urrt_rtde_is_config_error(ev->error) == (k == URRT_RTDE_EV_CONFIG));
        if (ev->error == URRT_RTDE_E_NOT_FOUND) {
            ASSERT(ev->not_found > 0 && urrt_rtde_not_found(&s, ev->not_found - 1u) >= 0 &&
                   urrt_rtde_not_found(&s, ev->not_found) == -1);
        }
        break;
    default: ASSERT(k > 0 && k <= URRT_RTDE_EV_CONFIG); break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ready;
    if (!ready) {
        for (size_t i = 0; i < NVARS; i++) {
            int v = urrt_rtde_var_find(fuzz_vars[i], strlen(fuzz_vars[i]));
            ASSERT(v >= 0);
            vars[i] = (uint16_t)v;
            if (urrt_rtde_var_field(v) >= 0) {
                mask |= UINT64_C(1) << urrt_rtde_var_field(v);
            }
        }
        ready = 1;
    }
    if (size == 0) {
        return 0;
    }
    size_t chunk = data[0] % 4 == 0 ? SIZE_MAX : data[0] % 4 == 1 ? 1 : data[0] % 4 == 2 ? 7 : 1u + data[0] / 4u;
    uint64_t fed = 0;
    size_t pos = 1;
    int ended = 0;
    urrt_rtde_init(&s);
    ASSERT(urrt_rtde_begin(&s, vars, NVARS, 125.0) == URRT_OK);
    take_output();
    while (pos < size && !ended) {
        size_t n = size - pos < chunk ? size - pos : chunk, used = SIZE_MAX;
        urrt_rtde_event ev;
        memset(&st, POISON, sizeof st); /* the caller may write its structs between reads */
        memset(&vals, POISON, sizeof vals);
        int k = urrt_rtde_feed(&s, data + pos, n, &used, &ev, &st, &vals);
        ASSERT(used <= n && (k != URRT_RTDE_EV_NONE || used == n));
        pos += used;
        fed += used;
        if (k == URRT_RTDE_EV_DROP || k == URRT_RTDE_EV_CONFIG) {
            ended = 1;
        }
        if (k != URRT_RTDE_EV_NONE) {
            check_event(k, &ev);
        }
        take_output();
    }
    ASSERT(s.stats.bytes == fed);
    if (ended) {
        size_t used = 1;
        urrt_rtde_event ev;
        ASSERT(urrt_rtde_feed(&s, data, size, &used, &ev, &st, &vals) == URRT_RTDE_E_ENDED && used == 0);
        uint8_t out[8];
        ASSERT(urrt_rtde_output(&s, out, sizeof out) == 0);
    }
    ASSERT(urrt_rtde_finish(&s) < URRT_RTDE_PACKAGE_MAX);
    return 0;
}
