/* SPDX-License-Identifier: MIT */
/* The RTDE reference's sessions as C data (tests/target/rtde_vectors_c.py). */
#ifndef URRT_TEST_RTDE_VECTORS_H
#define URRT_TEST_RTDE_VECTORS_H

#include <stddef.h>
#include <stdint.h>

typedef struct rtv_event {
    const char *kind;  /* as in the vector file: protocol, controller, ..., drop, config */
    const char *error; /* drop, config: the error's name; else NULL */
    int arg;           /* protocol, recipe id, text level, data "first" */
    const char *text; /* text: the text and the source, as sent */
    unsigned text_len;
    const char *source;
    unsigned source_len;
} rtv_event;

typedef struct rtv_value {
    unsigned event; /* index of the data event it belongs to */
    const char *name;
    unsigned elem;
    unsigned hex_digits; /* 16: a double's bits (or a uint64), 8: 32 bits, 2: 8 bits */
    uint64_t raw;
} rtv_value;

typedef struct rtv_session {
    const char *name;
    const char *const *vars;
    unsigned var_count;
    double freq;
    const uint8_t *stream;
    size_t stream_len;
    const uint8_t *sent; /* every request, in order */
    size_t sent_len;
    const rtv_event *events;
    unsigned event_count;
    const rtv_value *values;
    unsigned value_count;
} rtv_session;

extern const rtv_session rtv_sessions[];
extern const unsigned rtv_session_count;

#endif
