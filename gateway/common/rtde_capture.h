/* SPDX-License-Identifier: MIT */
/*
 * rtde_capture.h: RTDE captures, `urrt-dump --rtde -w FILE`, read back by
 * `urrt-dump --file`, `urrt-sim --replay` and `urrt-gateway --replay`.
 *
 * RTDE is a dialogue: a data package means nothing without the recipe the
 * client asked for, so a capture keeps both directions, each as whole
 * packages, in the order the client sent and received them (docs/rtde.md,
 * "Captures", is the format's reference):
 *
 *   header   the 20 bytes "URRT RTDE capture 1\n"
 *   record   a kind byte, then a package: uint16 size (big-endian, these
 *            two bytes and the type byte included, 3..URRT_RTDE_PACKAGE_MAX),
 *            uint8 type, size - 3 bytes of payload
 *     'C'    a TCP connection began (a session): the package's type is 'C'
 *            and its payload the peer as text ("robot:30004")
 *     '>'    a request the client sent (V, v, O, S, P), whole, as sent
 *     '<'    a package the controller sent, whole, as received
 *
 * A RealTime capture starts with a message size, whose first byte is 0; a
 * capture starts with 'U'. Readers tell the two apart by that byte, never
 * by the file's name. A capture ends on a record boundary: the writer keeps
 * an incomplete package back, and a reader reports a record cut short (a
 * writer killed mid-write) and stops there.
 *
 * Three layers, each usable alone:
 *   rtde_capture_writer   writes records; frames the controller's bytes itself
 *   rtde_capture          reads records (urrt-sim, which is written apart
 *                         from lib/urrt_rtde, stops here)
 *   rtde_replay           the records through lib/urrt_rtde's client: the
 *                         session's events and each data package decoded
 *                         by the recipe the capture's client asked for
 */
#ifndef URRT_RTDE_CAPTURE_H
#define URRT_RTDE_CAPTURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "urrt.h"
#include "urrt_rtde.h"

#define RTDE_CAPTURE_MAGIC "URRT RTDE capture 1\n"
#define RTDE_CAPTURE_MAGIC_LEN 20
/* The first byte of every capture; never the first byte of a RealTime one. */
#define RTDE_CAPTURE_FIRST_BYTE 'U'

/* Record kinds. */
#define RTDE_CAPTURE_CONNECT 'C'
#define RTDE_CAPTURE_SENT '>'
#define RTDE_CAPTURE_RECEIVED '<'

/* ---- writing ------------------------------------------------------------ */

typedef struct rtde_capture_writer rtde_capture_writer;

/* Creates path (truncating it) and writes the header. NULL with the reason
 * in why (what failed, what to do). */
rtde_capture_writer *rtde_capture_create(const char *path, char *why, size_t why_size);

/* A connection to peer began: a 'C' record; any bytes of an incomplete
 * package of the previous connection are dropped (they are not its end). */
bool rtde_capture_connected(rtde_capture_writer *w, const char *peer);
/* A whole request, as sent. */
bool rtde_capture_sent(rtde_capture_writer *w, const uint8_t *pkg, size_t size);
/* Bytes read from the controller, any split: each package completed is
 * written as a record; the rest is kept for the next call. A size outside
 * 3..URRT_RTDE_PACKAGE_MAX cannot be framed: the connection's later bytes
 * are not recorded (the client ends that session too). */
bool rtde_capture_received(rtde_capture_writer *w, const uint8_t *data, size_t len);

/* Flushes, closes, frees. Returns false (reason in why) if any write
 * failed. *held: bytes of an incomplete package left out (may be NULL). */
bool rtde_capture_close(rtde_capture_writer *w, size_t *held, char *why, size_t why_size);

/* ---- reading records ---------------------------------------------------- */

typedef struct rtde_capture rtde_capture;

typedef struct rtde_capture_record {
    char kind;            /* RTDE_CAPTURE_CONNECT, _SENT or _RECEIVED */
    const uint8_t *pkg;   /* the package, header included; valid until the next read */
    size_t size;
    uint8_t type;         /* pkg[2] */
    uint64_t offset;      /* of the kind byte in the file */
} rtde_capture_record;

/* Reads the header from f (positioned at the capture's first byte; name is
 * for messages). NULL with the reason in why if f holds no RTDE capture.
 * The capture does not own f. */
rtde_capture *rtde_capture_open(FILE *f, const char *name, char *why, size_t why_size);

/* The next record: 1, 0 at the end, -1 for a damaged capture (why says
 * where and what). A record cut short at the end is the end: 0, with
 * rtde_capture_truncated() > 0. */
int rtde_capture_next(rtde_capture *c, rtde_capture_record *rec, char *why, size_t why_size);

/* Bytes of a record cut short at the end of the file (0: none). */
size_t rtde_capture_truncated(const rtde_capture *c);

void rtde_capture_free(rtde_capture *c);

/* ---- replaying through lib/urrt_rtde ------------------------------------ */

typedef struct rtde_replay rtde_replay;

/* A new connection in the capture: returned by rtde_replay_next beside
 * lib's URRT_RTDE_EV_* kinds. */
#define RTDE_REPLAY_SESSION 100

/* Reads the capture from f (as rtde_capture_open). */
rtde_replay *rtde_replay_open(FILE *f, const char *name, char *why, size_t why_size);

/*
 * The next event: RTDE_REPLAY_SESSION at each connection (the peer in
 * rtde_replay_peer), then the client's events as lib's feed gives them
 * (URRT_RTDE_EV_PROTOCOL, _CONTROLLER, _RECIPE, _STARTED, _TEXT, _DATA,
 * _DROP, _CONFIG, ...; on _DATA the package is in rtde_replay_state and
 * rtde_replay_values); 0 at the end; -1 for a damaged capture or one whose
 * requests are not the handshake urrt's client makes (why says which).
 * The recipe is the capture's own: the setup request's names.
 */
int rtde_replay_next(rtde_replay *r, urrt_rtde_event *ev, char *why, size_t why_size);

const urrt_rtde *rtde_replay_session(const rtde_replay *r);
const urrt_state *rtde_replay_state(const rtde_replay *r);
const urrt_rtde_values *rtde_replay_values(const rtde_replay *r);
/* The last data package's bytes (header included), valid until the next
 * call of rtde_replay_next. */
const uint8_t *rtde_replay_package(const rtde_replay *r, size_t *size);
const char *rtde_replay_peer(const rtde_replay *r);
/* Whether the current session's recipe has var, accepted (asked for and
 * not NOT_FOUND). */
bool rtde_replay_has(const rtde_replay *r, int var);
/* Bytes of a record cut short at the end, once rtde_replay_next returned 0. */
size_t rtde_replay_truncated(const rtde_replay *r);

void rtde_replay_free(rtde_replay *r);

#endif
