/* SPDX-License-Identifier: MIT */
/*
 * sim_rtde.h: the server side of RTDE (UR's Real-Time Data Exchange, TCP
 * 30004) for urrt-sim, written from the protocol's description alone and
 * sharing no code with lib/'s client, so that the two cannot share a mistake.
 *
 * One sim_rtde_session per connection: feed it the bytes the client sent,
 * it answers through an emit callback (V, v, O, I, S, P, text messages);
 * once per control cycle the caller asks for the cycle's data package. The
 * values come from the same urrt_state the RealTime port encodes, so a value
 * at controller time t is the same on both ports; RTDE-only variables follow
 * the deterministic rules of docs/tools.md ("RTDE").
 *
 * What depends on the controller version: the variables it knows (a newer
 * one is NOT_FOUND), the rate (125 Hz before 5.0, 500 Hz from 5.0), and the
 * protocol (1 only before 3.4).
 *
 * Or the controller is an RTDE capture (urrt-sim --replay): a
 * sim_rtde_recording answers the handshake as the recorded controller did
 * and has only the recorded variables; each data package copies, for the
 * client's recipe, the bytes of the recorded package's values.
 */
#ifndef URRT_SIM_RTDE_H
#define URRT_SIM_RTDE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt.h"

#define SIM_RTDE_PORT 30004
/* The longest name list a controller takes in a setup (UR's guide). */
#define SIM_RTDE_NAMES_MAX 2048
/* Fields in one recipe: 2048 bytes of names hold fewer valid ones. */
#define SIM_RTDE_RECIPE_MAX 512
/* Input recipes a connection may set up (the simulator applies none). */
#define SIM_RTDE_INPUT_RECIPES 16
/* Backlog past the socket's buffer after which a reader is disconnected. */
#define SIM_RTDE_BACKLOG_DEFAULT (64u * 1024u)

typedef struct sim_rtde_recording sim_rtde_recording;

/* The controller behind the port. */
typedef struct sim_rtde_controller {
    uint32_t major, minor, bugfix, build;
    uint32_t rate_hz;     /* 125 before 5.0, 500 from 5.0: the highest frequency a client may ask */
    double cycle_hz;      /* the cycles k counted by sim_rtde_due: rate_hz, or a capture's own rate */
    const sim_rtde_recording *recording;   /* a capture's controller; NULL: the model's */
} sim_rtde_controller;

/* What a bad data package looks like (--fault rtde-bad-package). */
typedef enum sim_rtde_bad {
    SIM_RTDE_BAD_SIZE,    /* a data package one byte short of its recipe */
    SIM_RTDE_BAD_TYPE,    /* the data under a type letter no controller sends ('X') */
    SIM_RTDE_BAD_RECIPE,  /* v2: a recipe id the client was not given */
    SIM_RTDE_BAD_HEADER   /* a size field of 2, below the 3-byte header: unframable */
} sim_rtde_bad;

/* The RTDE-only faults; the per-connection faults of the RealTime port
 * (close, reset, truncate, stall, tiny writes, coalesce, freeze) are the
 * caller's and apply to data packages. */
typedef struct sim_rtde_faults {
    bool refuse_v2;           /* answer V(2) with 0 (V(1) still accepted) */
    bool text_handshake;      /* a text message before every handshake reply */
    uint64_t text_every;      /* a text message before data packages N+1, 2N+1, ... */
    uint8_t text_level;       /* 0 exception, 1 error, 2 warning, 3 info */
    uint64_t bad_every;       /* every Nth data package is bad ... */
    sim_rtde_bad bad_kind;    /* ... this way */
} sim_rtde_faults;

/* Sends bytes to the client; false when they cannot be queued. */
typedef bool (*sim_rtde_emit)(void *ctx, const uint8_t *bytes, size_t len);

typedef struct sim_rtde_field {
    uint16_t value;           /* index into the cycle's values */
    uint8_t type;             /* wire type */
} sim_rtde_field;

/* ---- a capture as the controller ---------------------------------------------- */

/* A variable of the recorded recipe. */
typedef struct sim_rtde_recorded_field {
    const char *name;         /* into the recording's names, not terminated */
    size_t len;
    uint8_t type;             /* wire type */
    size_t offset;            /* of its bytes among a package's values */
} sim_rtde_recorded_field;

/* A text message the recorded controller sent while data flowed. */
typedef struct sim_rtde_recorded_text {
    uint8_t level;
    uint8_t mlen, slen;
    char message[255], source[255];
} sim_rtde_recorded_text;

struct sim_rtde_recording {
    int8_t protocol_answer[3];     /* the recorded answer to V(1), V(2): 1, 0, or -1 never asked */
    size_t nfields;
    sim_rtde_recorded_field *fields;
    char *names;                   /* the recipe's names, as the setup request gave them */
    size_t values_size;            /* bytes of values in a data package (no recipe id) */
    size_t timestamp_at;           /* the timestamp's offset among them */
    const uint8_t *file;           /* the capture, mapped */
    size_t file_size;
    size_t count;                  /* data packages */
    uint64_t *at;                  /* offset of package i's values in the file */
    double rate_hz;                /* the packages' rate by their timestamps (0: unknown) */
    sim_rtde_recorded_text *texts; /* texts[text_first[i] .. text_first[i + 1]) came just before package i */
    size_t ntexts;
    size_t *text_first;            /* count + 1 entries */
    size_t sessions;               /* connections whose packages are served */
};

/* Whether the file at path is an RTDE capture (1), by its first byte,
 * never its name (0: another file, a RealTime capture), or cannot be
 * opened (-1). */
int sim_rtde_sniff(const char *path);

/* Reads the RTDE capture at path as the controller to serve: ctl from its
 * version reply, r its recipe and packages. False with the reason in why
 * (file and byte offset where it is damaged); notes what it leaves out in
 * the log (a later session with another recipe, packages that do not
 * match the recipe, a record cut short at the end). */
bool sim_rtde_recording_load(const char *path, sim_rtde_recording *r, sim_rtde_controller *ctl, char *why,
                             size_t why_size);
/* The controller timestamp of data package i. */
double sim_rtde_recording_time(const sim_rtde_recording *r, size_t i);
void sim_rtde_recording_free(sim_rtde_recording *r);

typedef struct sim_rtde_session {
    const sim_rtde_controller *ctl;
    const sim_rtde_faults *faults;
    sim_rtde_emit emit;
    void *emit_ctx;
    char peer[80];
    unsigned protocol;        /* 1 until V(2) is accepted */
    bool recipe_valid;        /* an output recipe without NOT_FOUND, at an allowed rate */
    bool started;
    uint32_t divisor;         /* a data package every divisor-th control cycle */
    size_t nfields;
    sim_rtde_field fields[SIM_RTDE_RECIPE_MAX];
    size_t data_size;         /* the recipe's bytes in a data package */
    size_t input_size[SIM_RTDE_INPUT_RECIPES + 1];   /* by input recipe id; 0: none */
    unsigned ninputs;
    uint64_t data_sent;       /* data packages, for the faults that count them */
    uint64_t texts_sent;
    bool broken;              /* the client sent an unframable package: close */
    size_t in_len;
    uint8_t in[65536];        /* one package being reassembled */
} sim_rtde_session;

/* "5.12.3.1234" (bugfix and build optional, 0 when left out). NULL, or
 * why the version serves no RTDE. */
const char *sim_rtde_controller_parse(const char *text, sim_rtde_controller *c);

void sim_rtde_session_init(sim_rtde_session *s, const sim_rtde_controller *ctl, const sim_rtde_faults *faults,
                           sim_rtde_emit emit, void *emit_ctx, const char *peer);

/* Bytes the client sent, in any chunking; replies go out through emit.
 * False when the client must be disconnected (an unframable package). */
bool sim_rtde_feed(sim_rtde_session *s, const uint8_t *data, size_t len);

/* Whether control cycle k (of the controller's rate) carries a data package. */
bool sim_rtde_due(const sim_rtde_session *s, uint64_t k);

/* Cycle k's data package from its state (preceded by a text message, or
 * replaced by a bad package, when a fault says so). False when it cannot be
 * queued. Call only when sim_rtde_due() said so. */
bool sim_rtde_send_data(sim_rtde_session *s, uint64_t k, const urrt_state *st);

/* The same for a capture's controller: data package k mod count of the
 * recording, after the text messages it recorded since the client's
 * previous package. */
bool sim_rtde_send_recorded(sim_rtde_session *s, uint64_t k);

#endif
