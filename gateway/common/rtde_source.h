/* SPDX-License-Identifier: MIT */
/*
 * rtde_source.h: an RTDE session (lib/urrt_rtde.h) on a robot link
 * (port/port.h), shared by urrt-gateway and urrt-dump.
 *
 * The glue between port/'s link, which speaks first through its source
 * hooks (urrt_link_set_source), and lib/'s sans-I/O client: at every TCP
 * connect it begins the session afresh (the whole handshake again), writes
 * each request the session has due, feeds it every byte read, and reports
 * each decoded data package to the link (urrt_link_source_packet), so the
 * link comes up only after the handshake and the first data package, and
 * the program's packet function receives the package's bytes (header
 * included) while rtde_source_state()/rtde_source_values() hold its decoded
 * values. What the session says goes where the link's policy wants it:
 *
 *   a protocol error       urrt_link_drop(PROTOCOL): reconnect, usual backoff
 *   a configuration error  urrt_link_drop(CONFIG) with the names refused and
 *                          the controller's version: logged once, retried
 *                          every backoff_max_ms, never a tight loop
 *   protocol 2 refused     protocol 1 (the session asks again by itself)
 *   a text message         the log, at its level (exception and error: err,
 *                          warning: warning, info and others: info)
 *
 * The recipe has two parts. Required variables (what the configuration
 * names: focused messages, CAN signals, RTDE-only values) are always asked
 * for. Optional ones (STATE's fields shared with RealTime) are asked for
 * only where the controller has them: once its version is known, a
 * variable urrt_rtde_var_available() says it lacks is left out (its field is
 * then absent, NaN, as RealTime's older versions leave it). "Unknown" (no
 * source states the version) keeps the variable: the controller's
 * NOT_FOUND decides, a configuration error for a required one. A required
 * variable the tables say this controller lacks is a configuration error
 * before the setup is even sent.
 *
 * Allocates at rtde_source_new only; the per-package path does not.
 *
 * API stable from its first version; changes, if any, are listed here.
 */
#ifndef URRT_RTDE_SOURCE_H
#define URRT_RTDE_SOURCE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "port.h"
#include "urrt.h"
#include "urrt_rtde.h"
#include "urrt_rtde_in.h"

typedef struct rtde_source rtde_source;

/* An input recipe (lib/urrt_rtde_in.h): registers written together, in
 * the order their values are given. */
typedef struct rtde_source_input {
    const uint16_t *vars;    /* writable urrt_rtde_var ids (urrt_rtde_in_writable), distinct */
    size_t count;            /* 1..URRT_RTDE_IN_MAX_VARS */
} rtde_source_input;

/* An IN_USE right after a reconnect is often the controller still holding
 * this client's previous connection: the setup is tried again this many
 * times with the link's usual backoff, then only every backoff_max_ms. */
#define RTDE_SOURCE_IN_USE_RETRIES 3

typedef struct rtde_source_config {
    const char *name;        /* robot name for log lines */
    const uint16_t *vars;    /* urrt_rtde_var ids, distinct (copied) */
    const bool *optional;    /* per var: true = only where the controller has it;
                                NULL: every var required */
    size_t count;            /* 1..URRT_RTDE_MAX_VARS */
    double frequency;        /* Hz, 0 for the controller's rate (125 CB3, 500 e-Series) */
    /* Input recipes (none for a reader: the session sends exactly V v O S).
     * Each is set up after the output recipe and before start, at every
     * connect; nothing is written for one until its caller gives values and
     * sends it (rtde_source_send_input). Copied. */
    const rtde_source_input *inputs;
    size_t input_count;      /* 0..URRT_RTDE_IN_MAX_RECIPES */
} rtde_source_config;

/* Checks the recipe (urrt_rtde_begin's rules: distinct known ids, the
 * 2,048-byte name list, a frequency of 0..500) and returns a source, or
 * NULL with the reason written to why (one line, what failed and what to
 * do). */
rtde_source *rtde_source_new(const rtde_source_config *cfg, char *why, size_t why_size);
void rtde_source_free(rtde_source *src);

/* Makes src the link's source (urrt_link_set_source): call before the first
 * urrt_link_service. One source per link. False (logged by the link) when
 * the link's port runs what it receives (urrt_rtde_check_port): nothing is
 * ever written there. */
bool rtde_source_attach(rtde_source *src, urrt_link *link);

/* During the packet function of a package from this source (and until the
 * next byte is fed): the decoded values. The state is urrt_rtde_decode's:
 * present holds the recipe's fields, the others NaN (set once, when the
 * session's recipe was accepted: nothing else writes these structs), time
 * the controller's timestamp when the recipe has it. */
const urrt_state *rtde_source_state(const rtde_source *src);
const urrt_rtde_values *rtde_source_values(const rtde_source *src);

/* The session, for its statistics, protocol, controller version
 * (controller[]) and urrt_rtde_up(). */
const urrt_rtde *rtde_source_session(const rtde_source *src);

/* Input recipe g (0 <= g < input_count), for its values
 * (urrt_rtde_in_set_int, _set_double, _forget) and its counters. */
urrt_rtde_in *rtde_source_in(rtde_source *src, size_t g);

/* Input recipe g's package, with the values it holds, queued on the link:
 * 1; 0 when it cannot go now (the session does not stream or the
 * controller has not accepted the recipe in this session: urrt_rtde_in_ready;
 * a register without a value; the link's queue full: counted in
 * input_busy); never a drop. */
int rtde_source_send_input(rtde_source *src, size_t g);

/* Whether input recipe g can be sent now (urrt_rtde_in_ready). */
bool rtde_source_input_ready(const rtde_source *src, size_t g);

/* Sessions that started streaming with every input recipe accepted: a
 * caller that sees it change sends its current values at once (a robot
 * link that dropped and came back). */
uint64_t rtde_source_input_sessions(const rtde_source *src);

/* Input packages the link's queue had no room for. */
uint64_t rtde_source_input_busy(const rtde_source *src);

/* The refusal of an input recipe's setup that keeps the session from
 * starting (URRT_RTDE_E_IN_USE or URRT_RTDE_E_NOT_FOUND; 0: none, or a
 * session started since) and the register it named (-1: none). */
int rtde_source_input_refusal(const rtde_source *src, int *var);

/* The recipe of the current (or last) session as a comma-separated name
 * list into out (NUL-terminated, truncated to size); returns its length. */
size_t rtde_source_recipe_text(const rtde_source *src, char *out, size_t size);

/* Optional: every session event (handshake steps, text, data, errors) is
 * also handed to fn, after the source has acted on it (urrt-dump prints
 * them). ev is valid during the call only. NULL removes it. */
typedef void (*rtde_source_event_fn)(void *ctx, const urrt_rtde_event *ev, uint64_t rx_us);
void rtde_source_set_event_fn(rtde_source *src, rtde_source_event_fn fn, void *ctx);

/* Optional: the session's bytes as they go (urrt-dump -w records them,
 * rtde_capture.h): CONNECTED at each connect (data NULL), SENT with each
 * request as queued, whole, RECEIVED with the bytes read as the session
 * takes them (each piece before the events it leads to), in any split.
 * NULL removes it. */
typedef enum rtde_source_tap {
    RTDE_SOURCE_TAP_CONNECTED,
    RTDE_SOURCE_TAP_SENT,
    RTDE_SOURCE_TAP_RECEIVED
} rtde_source_tap;
typedef void (*rtde_source_tap_fn)(void *ctx, rtde_source_tap what, const uint8_t *data, size_t len);
void rtde_source_set_tap(rtde_source *src, rtde_source_tap_fn fn, void *ctx);

#endif
