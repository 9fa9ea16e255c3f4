/* SPDX-License-Identifier: MIT */
/*
 * The words of tests/ref/rtde_ref.py's vectors for lib/urrt_rtde's results
 * and events, said once for every suite that replays them (test_rtde.c,
 * test_rtde_in.c, tests/target/rtde_target.c). Included after check.h;
 * LOOKUP(errors, "NOT_FOUND") is the value of a word, a failed check for a
 * word the table lacks.
 */
#ifndef URRT_TESTS_RTDE_NAMES_H
#define URRT_TESTS_RTDE_NAMES_H

#include "urrt_rtde.h"

typedef struct named {
    const char *name;
    int value;
} named;

static const named errors[] = {
    {"SIZE_SMALL", URRT_RTDE_E_SIZE_SMALL}, {"SIZE_LARGE", URRT_RTDE_E_SIZE_LARGE},
    {"REPLY_LENGTH", URRT_RTDE_E_REPLY_LENGTH}, {"REPLY_VALUE", URRT_RTDE_E_REPLY_VALUE},
    {"VERSION_ZERO", URRT_RTDE_E_VERSION_ZERO}, {"DATA_EARLY", URRT_RTDE_E_DATA_EARLY},
    {"RECIPE_ID", URRT_RTDE_E_RECIPE_ID}, {"DATA_SIZE", URRT_RTDE_E_DATA_SIZE},
    {"TYPE_TOKEN", URRT_RTDE_E_TYPE_TOKEN}, {"TYPE_COUNT", URRT_RTDE_E_TYPE_COUNT},
    {"TEXT_LENGTH", URRT_RTDE_E_TEXT_LENGTH}, {"PAUSE_REFUSED", URRT_RTDE_E_PAUSE_REFUSED},
    {"NOT_FOUND", URRT_RTDE_E_NOT_FOUND}, {"TYPE_MISMATCH", URRT_RTDE_E_TYPE_MISMATCH},
    {"PROTOCOL_REFUSED", URRT_RTDE_E_PROTOCOL_REFUSED}, {"START_REFUSED", URRT_RTDE_E_START_REFUSED},
    {"FREQUENCY", URRT_RTDE_E_FREQUENCY}, {"IN_USE", URRT_RTDE_E_IN_USE},
    {"INPUTS_PROTOCOL", URRT_RTDE_E_INPUTS_PROTOCOL}, {"NAMES_TOO_LONG", URRT_RTDE_E_NAMES_TOO_LONG},
    {"NOT_WRITABLE", URRT_RTDE_E_NOT_WRITABLE}, {"DUPLICATE", URRT_RTDE_E_DUPLICATE},
    {"VALUE", URRT_RTDE_E_VALUE}, {"NOT_STARTED", URRT_RTDE_E_NOT_STARTED},
    {"INCOMPLETE", URRT_RTDE_E_INCOMPLETE}, {"ARG", URRT_E_ARG}, {"OK", URRT_OK},
};

static const named kinds[] = {
    {"protocol", URRT_RTDE_EV_PROTOCOL}, {"fallback", URRT_RTDE_EV_FALLBACK},
    {"controller", URRT_RTDE_EV_CONTROLLER}, {"recipe", URRT_RTDE_EV_RECIPE},
    {"started", URRT_RTDE_EV_STARTED}, {"paused", URRT_RTDE_EV_PAUSED}, {"text", URRT_RTDE_EV_TEXT},
    {"data", URRT_RTDE_EV_DATA}, {"drop", URRT_RTDE_EV_DROP}, {"config", URRT_RTDE_EV_CONFIG},
    {"inputs", URRT_RTDE_EV_INPUTS},
};

static int lookup(const named *t, size_t n, const char *name)
{
    for (size_t i = 0; i < n; i++) {
        if (CHECK_SAME_TEXT(t[i].name, name)) {
            return t[i].value;
        }
    }
    CHECK(0, "unknown word %s in the vectors", name);
    return 1; /* no result or event has it: a check that compares with it fails too */
}
#define LOOKUP(t, name) lookup(t, sizeof t / sizeof t[0], name)

#endif
