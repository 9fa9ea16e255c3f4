/* SPDX-License-Identifier: MIT */
/*
 * The member of a decoded state that holds a field, by id: the tests' own map
 * from ids to members (lib/urrt.h's urrt_field_values is what they test), for
 * test_lib.c, fuzz_lib.c and tests/target/test_target.c.
 */
#ifndef URRT_TEST_STATE_SLOT_H
#define URRT_TEST_STATE_SLOT_H

#include "urrt.h"

static inline double *state_slot(urrt_state *st, int id)
{
    switch (id) {
#define URRT_TEST_X(ID, name, count, c1, c3, unit, since, desc) \
    case URRT_F_##ID: return st->name;
        URRT_FIELDS(URRT_TEST_X)
#undef URRT_TEST_X
    default: return (double *)0;
    }
}

#endif
