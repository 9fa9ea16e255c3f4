/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness of the RTDE client's writing side (lib/urrt_rtde_in):
 * the input is what a controller sends on port 30004, after one byte that
 * says how it is cut into reads; the client has an output recipe and an
 * input recipe, and its requests are taken after every read, as a poll loop
 * does, so the seeds (tests/ref/rtde_ref.py --inputs) walk the handshake to
 * the setup-inputs reply, which the fuzzer mutates at every split point.
 * Invariants of docs/security.md's model, for the writing side:
 *   - urrt_rtde_in_feed consumes at most what it is given, all of it when
 *     it reports no event, at least a byte for an event; an ended session
 *     refuses input, requests nothing and writes no input package;
 *   - every request is a whole V, v, O, I, S or P; an 'I' only after the
 *     output recipe is accepted, one at a time, and no 'S' while its reply
 *     is awaited;
 *   - an accepted recipe has an id that is not 0, taken from an 'I' package
 *     whose words are exactly the recipe's types (never a value from other
 *     bytes); a refusal names one of the recipe's registers;
 *   - nothing is written before the recipe is accepted and the session
 *     streams; what is written is the values given, under the accepted id.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "urrt_rtde_in.h"

#define ASSERT(cond)   \
    do {               \
        if (!(cond)) { \
            abort();   \
        }              \
    } while (0)

static const char *const out_vars[] = {"timestamp", "input_int_register_24", "input_double_register_30",
                                       "robot_status_bits"};
static const char *const in_vars[] = {"input_int_register_24", "input_double_register_30", "input_bit_register_64",
                                      "input_bit_registers32_to_63", "input_int_register_47"};
static const char in_types[] = "INT32,DOUBLE,BOOL,UINT32,INT32";
/* The values given, as the package must carry them. */
static const uint8_t in_data[] = {0xFF, 0xFF, 0xFF, 0xE8,                         /* -24 */
                                  0x40, 0x38, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, /* 24.5 */
                                  0x01,                                           /* 1 */
                                  0xDE, 0xAD, 0xBE, 0xEF, 0x7F, 0xFF, 0xFF, 0xFF};
#define NOUT (sizeof out_vars / sizeof out_vars[0])
#define NIN (sizeof in_vars / sizeof in_vars[0])

static urrt_rtde s;
static urrt_rtde_in in;
static urrt_state st;
static urrt_rtde_values vals;
static uint16_t outs[NOUT], ins[NIN];

static struct {
    int recipe_accepted; /* EV_RECIPE seen */
    int awaiting;        /* an 'I' written, its reply not in */
    int accepted;        /* EV_INPUTS seen */
    int ended;
} seen;

static void take_output(void)
{
    static uint8_t out[URRT_RTDE_REQUEST_MAX];
    int n;
    while ((n = urrt_rtde_in_output(&s, &in, 1, out, sizeof out)) > 0) {
        ASSERT(n >= 3 && (out[0] << 8 | out[1]) == n && !seen.ended);
        ASSERT(strchr("VvOISP", out[2]) != NULL && out[2] != 0);
        if (out[2] == 'I') {
            ASSERT(seen.recipe_accepted && !seen.awaiting && !seen.accepted);
            seen.awaiting = 1;
        }
        if (out[2] == 'S') {
            ASSERT(!seen.awaiting && seen.accepted);
        }
    }
    ASSERT(n == 0);
}

/* Nothing before accepted and streaming; then exactly the values given. */
static void try_package(void)
{
    uint8_t pkg[URRT_RTDE_IN_PACKAGE_MAX];
    int n = urrt_rtde_in_package(&s, &in, pkg, sizeof pkg);
    if (!seen.accepted || seen.ended || !urrt_rtde_streaming(&s)) {
        ASSERT(n == URRT_RTDE_E_NOT_STARTED);
        return;
    }
    ASSERT(n == (int)(4 + sizeof in_data) && pkg[0] == 0 && pkg[1] == n && pkg[2] == 'U');
    ASSERT(pkg[3] == in.id && in.id != 0 && memcmp(pkg + 4, in_data, sizeof in_data) == 0);
}

static int in_recipe(int var)
{
    for (size_t i = 0; i < NIN; i++) {
        if (ins[i] == var) {
            return 1;
        }
    }
    return 0;
}

static void check_event(int k, const urrt_rtde_event *ev)
{
    switch (k) {
    case URRT_RTDE_EV_RECIPE: seen.recipe_accepted = 1; break;
    case URRT_RTDE_EV_INPUTS: {
        size_t size = (size_t)(s.buf[0] << 8 | s.buf[1]);
        ASSERT(seen.awaiting && ev->var == 0 && ev->recipe_id != 0 && ev->recipe_id == in.id);
        /* the reply in the buffer: 'I', the id, exactly the recipe's types */
        ASSERT(s.buf[2] == 'I' && s.buf[3] == ev->recipe_id && size == 4 + sizeof in_types - 1 &&
               memcmp(s.buf + 4, in_types, sizeof in_types - 1) == 0);
        seen.awaiting = 0;
        seen.accepted = 1;
        break;
    }
    case URRT_RTDE_EV_DROP:
    case URRT_RTDE_EV_CONFIG:
        ASSERT(ev->error < 0 && urrt_rtde_is_config_error(ev->error) == (k == URRT_RTDE_EV_CONFIG));
        if (ev->error == URRT_RTDE_E_IN_USE || (ev->error == URRT_RTDE_E_NOT_FOUND && seen.awaiting)) {
            ASSERT(in_recipe(ev->var) && ev->not_found >= 1 && ev->not_found <= NIN);
        }
        if (ev->error == URRT_RTDE_E_TYPE_MISMATCH && seen.awaiting) {
            ASSERT(in_recipe(ev->var));
        }
        seen.ended = 1;
        break;
    default: ASSERT(k > 0 && k <= URRT_RTDE_EV_INPUTS); break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ready;
    if (!ready) {
        for (size_t i = 0; i < NOUT; i++) {
            int v = urrt_rtde_var_find(out_vars[i], strlen(out_vars[i]));
            ASSERT(v >= 0);
            outs[i] = (uint16_t)v;
        }
        for (size_t i = 0; i < NIN; i++) {
            int v = urrt_rtde_var_find(in_vars[i], strlen(in_vars[i]));
            ASSERT(v >= 0);
            ins[i] = (uint16_t)v;
        }
        ready = 1;
    }
    if (size == 0) {
        return 0;
    }
    size_t chunk = data[0] % 4 == 0 ? SIZE_MAX : data[0] % 4 == 1 ? 1 : data[0] % 4 == 2 ? 7 : 1u + data[0] / 4u;
    uint64_t fed = 0;
    size_t pos = 1;
    memset(&seen, 0, sizeof seen);
    urrt_rtde_init(&s);
    ASSERT(urrt_rtde_in_init(&in, ins, NIN) == URRT_OK);
    ASSERT(urrt_rtde_in_set_int(&in, 0, -24) == URRT_OK && urrt_rtde_in_set_double(&in, 1, 24.5) == URRT_OK &&
           urrt_rtde_in_set_int(&in, 2, 1) == URRT_OK && urrt_rtde_in_set_int(&in, 3, 0xDEADBEEF) == URRT_OK &&
           urrt_rtde_in_set_double(&in, 4, 2147483647.0) == URRT_OK);
    ASSERT(urrt_rtde_begin(&s, outs, NOUT, 0.0) == URRT_OK);
    urrt_rtde_in_begin(&in, 1);
    take_output();
    while (pos < size && !seen.ended) {
        size_t n = size - pos < chunk ? size - pos : chunk, used = SIZE_MAX;
        urrt_rtde_event ev;
        int k = urrt_rtde_in_feed(&s, &in, 1, data + pos, n, &used, &ev, &st, &vals);
        ASSERT(used <= n && (k != URRT_RTDE_EV_NONE || used == n) && (k <= 0 || used > 0));
        ASSERT(k >= 0);
        pos += used;
        fed += used;
        if (k != URRT_RTDE_EV_NONE) {
            check_event(k, &ev);
        }
        ASSERT(s.stats.ignored <= s.stats.packages);
        take_output();
        try_package();
    }
    ASSERT(s.stats.bytes == fed);
    if (seen.ended) {
        size_t used = 1;
        urrt_rtde_event ev;
        uint8_t out[8];
        ASSERT(urrt_rtde_in_feed(&s, &in, 1, data, size, &used, &ev, &st, &vals) == URRT_RTDE_E_ENDED && used == 0);
        ASSERT(urrt_rtde_in_output(&s, &in, 1, out, sizeof out) == 0);
        try_package();
    }
    ASSERT(urrt_rtde_finish(&s) < URRT_RTDE_PACKAGE_MAX);
    return 0;
}
