/* SPDX-License-Identifier: MIT */
/*
 * urrt_rtde_in: the writing side of the RTDE client (lib/urrt_rtde.h), a
 * unit of its own: input recipes (setup-inputs, 'I') in the session's
 * handshake, after the output recipe and before start, and input data
 * packages ('U' from the client) packed from values the caller gives, only
 * while the session streams. Freestanding C99 like urrt_rtde.h: no heap, no
 * globals, no clock. A firmware that only reads does not link this file, and
 * nothing in urrt_rtde.c can write 'I' or 'U': "this firmware cannot write"
 * is a property of its link map.
 *
 * Only general purpose input registers can be written (urrt_rtde_in_writable):
 * input_int_register_N and input_double_register_N (N 0..47),
 * input_bit_register_N (N 64..127), input_bit_registers0_to_31 and
 * input_bit_registers32_to_63. Every other RTDE input (speed slider, digital,
 * analog and tool outputs, external force-torque) acts on hardware with no
 * robot program deciding, and no function here takes one. Registers 0..23
 * (and bits 0..63) belong to an enabled fieldbus adapter (EtherNet/IP,
 * PROFINET, Modbus): the controller answers IN_USE for them; 24..47 and bits
 * 64..127 are the external clients' range.
 *
 * The session with inputs, in place of urrt_rtde_output and urrt_rtde_feed
 * (one urrt_rtde_in per group of registers written together, each its own
 * input recipe):
 *
 *   static urrt_rtde s;
 *   static urrt_rtde_in in[GROUPS];           each about URRT_RTDE_IN_RAM bytes
 *   once: urrt_rtde_init(&s); urrt_rtde_in_init(&in[g], vars_g, count_g)
 *   on every TCP (re)connect:
 *       urrt_rtde_begin(&s, outputs, count, 0.0);  urrt_rtde_in_begin(in, GROUPS);
 *   whenever the socket may be written:
 *       n = urrt_rtde_in_output(&s, in, GROUPS, out, sizeof out);   V v O I.. S
 *   for every chunk read (any split), as with urrt_rtde_feed:
 *       k = urrt_rtde_in_feed(&s, in, GROUPS, p, len, &used, &ev, &st, &vals);
 *       k == URRT_RTDE_EV_INPUTS: input recipe ev.var accepted, id ev.recipe_id
 *       k == URRT_RTDE_EV_CONFIG, ev.error URRT_RTDE_E_IN_USE or _NOT_FOUND:
 *           ev.var names the first register refused, ev.not_found how many
 *   a value from the PLC: urrt_rtde_in_set_int(&in[g], i, v), _set_double
 *   to send a group: n = urrt_rtde_in_package(&s, &in[g], out, sizeof out)
 *
 * The controller sends no reply to an input package; what a program reads is
 * the register's value, which an output recipe can read back (the register
 * is an RTDE output too). When the caller's data goes stale it stops
 * sending (or forgets the values: urrt_rtde_in_forget), so that the robot
 * program's own rtde_set_watchdog() acts; this unit never sends on its own.
 */
#ifndef URRT_RTDE_IN_H
#define URRT_RTDE_IN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt_rtde.h"

#ifdef __cplusplus
extern "C" {
#endif

#define URRT_RTDE_TYPE_SETUP_INPUTS 'I'

/* ---- bounds ----------------------------------------------------------------- */

/* The most registers in one input recipe: a CAN FD frame of single bits, or
 * a CANopen RPDO's 64 bits, is one recipe. */
#define URRT_RTDE_IN_MAX_VARS 64
/* The most input recipes one session sets up: a recipe id is a byte, 0 is
 * "refused", and the output recipe holds one. */
#define URRT_RTDE_IN_MAX_RECIPES 254
/* The values of the largest recipe (doubles): 8 bytes each. */
#define URRT_RTDE_IN_DATA_MAX (URRT_RTDE_IN_MAX_VARS * 8)
/* An input data package: header, recipe id, values. */
#define URRT_RTDE_IN_PACKAGE_MAX (URRT_RTDE_HEADER_SIZE + 1 + URRT_RTDE_IN_DATA_MAX)
/* A setup-inputs request: header and names (no frequency). */
#define URRT_RTDE_IN_REQUEST_MAX (URRT_RTDE_HEADER_SIZE + URRT_RTDE_NAMES_MAX)

/* ---- the writable variables ----------------------------------------------------- */

/* True for the general purpose input registers (the variable ids of
 * lib/urrt_rtde.h's input register families), false for any other id. */
bool urrt_rtde_in_writable(int var);

/* ---- one input recipe ----------------------------------------------------------- */

typedef struct urrt_rtde_in_stats {
    uint64_t packages;  /* input data packages written by urrt_rtde_in_package */
    uint64_t refused;   /* values urrt_rtde_in_set_* refused (out of range, not finite, ...) */
    uint64_t accepted;  /* setups the controller accepted */
    uint64_t in_use;    /* setups answered with IN_USE */
    uint64_t not_found; /* setups answered with NOT_FOUND */
} urrt_rtde_in_stats;

typedef struct urrt_rtde_in {
    uint16_t vars[URRT_RTDE_IN_MAX_VARS];    /* the registers, in recipe order */
    uint16_t offset[URRT_RTDE_IN_MAX_VARS];  /* each value's place in data */
    uint8_t types[URRT_RTDE_IN_MAX_VARS];    /* each register's urrt_rtde_type, looked up once at init */
    uint8_t data[URRT_RTDE_IN_DATA_MAX];     /* the values, big-endian, packed in recipe order */
    uint8_t given[URRT_RTDE_IN_MAX_VARS / 8]; /* bit i: vars[i] holds a value */
    uint16_t count;
    uint16_t data_size;  /* bytes of data a package carries */
    uint8_t id;          /* the controller's id of this recipe; 0 until accepted */
    uint8_t state;       /* internal: the setup's progress in this session */
    int error;           /* the last setup's refusal (URRT_RTDE_E_IN_USE, ...), 0 */
    int error_var;       /* the first register it names, -1 */
    urrt_rtde_in_stats stats;
} urrt_rtde_in;

#define URRT_RTDE_IN_RAM (sizeof(urrt_rtde_in))

/*
 * Checks and keeps a recipe: count (1..URRT_RTDE_IN_MAX_VARS) distinct
 * writable variable ids in the order the packages carry them, their names
 * within URRT_RTDE_NAMES_MAX bytes. No value is given yet. URRT_OK,
 * URRT_E_ARG, URRT_RTDE_E_NOT_WRITABLE, URRT_RTDE_E_DUPLICATE or
 * URRT_RTDE_E_NAMES_TOO_LONG (then in is unusable until a good init).
 */
int urrt_rtde_in_init(urrt_rtde_in *in, const uint16_t *vars, size_t count);

/* On every connect, after urrt_rtde_begin: each recipe's setup is due again
 * (a reconnect sets the inputs up again) and nothing is written until the
 * new session accepts it; the values are kept. (urrt_rtde_in_feed does the
 * same when a session's protocol is accepted.) */
void urrt_rtde_in_begin(urrt_rtde_in *in, size_t n);

/*
 * The session's next request, with the input recipes' setups in their
 * place: urrt_rtde_output's requests, but when start is due, first each
 * input recipe's setup in the order of in[], one at a time (the next once
 * the reply to the last is in), and start only once every reply is in.
 * Returns the bytes written, 0 when nothing is due (a reply is awaited),
 * URRT_E_NO_SPACE (the request stays due; cap >= URRT_RTDE_REQUEST_MAX is
 * always enough) or URRT_E_ARG (null pointers, a recipe whose init failed).
 */
int urrt_rtde_in_output(urrt_rtde *s, urrt_rtde_in *in, size_t n, uint8_t *out, size_t cap);

/*
 * urrt_rtde_feed with the input recipes' replies taken out: the same events
 * and contract (it consumes until an event or all of len; any chunking of
 * the same bytes, the output taken after every call, gives the same events),
 * plus URRT_RTDE_EV_INPUTS when a recipe is accepted (ev.var: its index in
 * in[], ev.recipe_id: the controller's id) and these ends of the session:
 * EV_CONFIG with URRT_RTDE_E_NOT_FOUND or URRT_RTDE_E_IN_USE (ev.var: the
 * first register refused, ev.not_found: how many; NOT_FOUND is reported
 * first when a reply has both), URRT_RTDE_E_TYPE_MISMATCH (ev.var), and
 * URRT_RTDE_E_INPUTS_PROTOCOL in place of EV_RECIPE when the controller
 * accepted protocol 1 only; EV_DROP with URRT_RTDE_E_TYPE_TOKEN (a word
 * that is no type, NOT_FOUND or IN_USE), _TYPE_COUNT, _REPLY_LENGTH or
 * _RECIPE_ID (a valid recipe given id 0). A reply answers the first recipe
 * whose request was written and not answered; an 'I' package when none is
 * awaited is a reply nobody waits for (s->stats.ignored), as the reader
 * counts them; the awaited ones are not counted there. A reply is read
 * from s->buf, where the reader frames it, so the reader's own feed is
 * unchanged. n 0: urrt_rtde_feed itself.
 */
int urrt_rtde_in_feed(urrt_rtde *s, urrt_rtde_in *in, size_t n, const uint8_t *data, size_t len, size_t *used,
                      urrt_rtde_event *ev, urrt_state *st, urrt_rtde_values *vals);

/*
 * A value for vars[i], checked before it is packed, never clamped: a BOOL
 * register takes 0 or 1, an INT32 register an integer in its range, a
 * UINT32 one (the bit-register words) 0..4294967295, a DOUBLE register any
 * finite double, bit for bit (-0.0 and denormals as given). _set_double
 * takes an integer register's value as a double that is exactly such an
 * integer (-0.0 is 0); _set_int takes a DOUBLE register's value as an
 * integer that a double holds exactly (any up to 2^53 in magnitude).
 * URRT_OK; URRT_RTDE_E_VALUE for any other value (NaN, infinities,
 * fractions, out of range), which is counted (stats.refused) and leaves
 * vars[i] without a value, so that nothing is sent for it until a good one
 * comes; URRT_E_ARG for i out of range or a recipe whose init failed. No
 * floating-point arithmetic: values are checked and packed as bits.
 */
int urrt_rtde_in_set_int(urrt_rtde_in *in, size_t i, int64_t value);
int urrt_rtde_in_set_double(urrt_rtde_in *in, size_t i, double value);

/* Every register without a value: nothing is sent until each is given
 * again (the caller's data went stale). */
void urrt_rtde_in_forget(urrt_rtde_in *in);

/* vars[i] without a value, not counted as refused: the caller has none
 * for it now (its source went stale, or refused it before it came here). */
void urrt_rtde_in_unset(urrt_rtde_in *in, size_t i);

/* Every register of the recipe holds a value. */
bool urrt_rtde_in_complete(const urrt_rtde_in *in);

/* The controller accepted the recipe in this session (its id is not 0)
 * and the session streams (urrt_rtde_streaming: start accepted, no pause
 * asked for, not ended). */
bool urrt_rtde_in_ready(const urrt_rtde *s, const urrt_rtde_in *in);

/*
 * The recipe's input data package, written whole into out: its size;
 * URRT_RTDE_E_NOT_STARTED unless urrt_rtde_in_ready; URRT_RTDE_E_INCOMPLETE
 * unless every register holds a value; URRT_E_NO_SPACE (cap >=
 * URRT_RTDE_IN_PACKAGE_MAX is always enough) or URRT_E_ARG. Counted in
 * stats.packages.
 */
int urrt_rtde_in_package(const urrt_rtde *s, urrt_rtde_in *in, uint8_t *out, size_t cap);

/* The setup-inputs request of a recipe (header and names): its size,
 * URRT_E_NO_SPACE or URRT_E_ARG. */
int urrt_rtde_in_write_setup(uint8_t *out, size_t cap, const urrt_rtde_in *in);

#ifdef __cplusplus
}
#endif

#endif /* URRT_RTDE_IN_H */
