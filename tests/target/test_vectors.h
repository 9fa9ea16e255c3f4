/* SPDX-License-Identifier: MIT */
/* The reference vectors as C data (written by vectors_c.py). */
#ifndef URRT_TEST_VECTORS_H
#define URRT_TEST_VECTORS_H

#include "urrt.h"

enum tv_kind { TV_VALUE, TV_ABSENT, TV_ENUM, TV_MASK, TV_NOT_BITMASK };

typedef struct tv_expect {
    uint8_t id;
    uint8_t elem;
    uint8_t kind;     /* enum tv_kind */
    uint64_t bits;    /* TV_VALUE: the element's bits; TV_MASK: the mask */
    const char *name; /* TV_ENUM: the element's enum name */
} tv_expect;

typedef struct tv_vector {
    const char *name;
    const char *versions; /* "-" for none */
    uint32_t length;
    int generation;
    unsigned doubles;
    unsigned extra;
    const uint8_t *packet;
    const tv_expect *expect;
    unsigned expect_count;
} tv_vector;

extern const tv_vector tv_vectors[];
extern const unsigned tv_vector_count;

#endif
