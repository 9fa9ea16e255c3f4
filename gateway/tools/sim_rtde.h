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
 * Inputs are the controller's, shared by every connection
 * (sim_rtde_controller.inputs): an input recipe ('I') takes its variables
 * for its connection (IN_USE for any other, and for registers 0..23 and
 * bits 0..63 while a fieldbus adapter is enabled); input data packages
 * ('U' from the client) are applied at the next control cycle, so that
 * every client's output recipe reads the values back from that cycle on;
 * sim_rtde_session_end() gives the variables up (or holds them for a while,
 * fault rtde-hold-inputs) and keeps their values.
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
/* Input recipes a connection may set up, their ids from SIM_RTDE_INPUT_ID
 * on (the output recipe's is 1), and their variables on one connection. */
#define SIM_RTDE_INPUT_RECIPES 16
#define SIM_RTDE_INPUT_ID 2
#define SIM_RTDE_INPUT_FIELDS 1024
/* Every input's value, one double per element: the registers (48 int, 48
 * double, bits 64..127, the two words of bits 0..63) and the other inputs. */
#define SIM_RTDE_INPUT_SLOTS 180
/* Input packages received since the last control cycle, for its log lines. */
#define SIM_RTDE_PENDING_MAX 256
/* Connections whose inputs are held after they left (rtde-hold-inputs). */
#define SIM_RTDE_HELD_MAX 64
/* How long rtde-hold-inputs holds them by default. */
#define SIM_RTDE_HOLD_DEFAULT_MS 2000u
/* Backlog past the socket's buffer after which a reader is disconnected. */
#define SIM_RTDE_BACKLOG_DEFAULT (64u * 1024u)

typedef struct sim_rtde_recording sim_rtde_recording;

/* An input package received, applied at the next cycle (for its log line). */
typedef struct sim_rtde_pending {
    char peer[80];
    uint8_t recipe_id;
    uint16_t count;           /* variables */
} sim_rtde_pending;

/* A connection gone whose input variables stay IN_USE until a time. */
typedef struct sim_rtde_held {
    uint32_t owner;           /* its session id */
    uint64_t until_us;        /* monotonic */
    char peer[80];
} sim_rtde_held;

/* The controller's inputs, shared by its connections. A variable is owned
 * by the session that set it up in an input recipe (owner, at the slot of
 * its first element; 0: free); values are what the controller holds, read
 * back by output recipes, and stay when their owner leaves. */
typedef struct sim_rtde_inputs {
    double value[SIM_RTDE_INPUT_SLOTS];       /* in effect this cycle (doubles as bits) */
    double next[SIM_RTDE_INPUT_SLOTS];        /* written since: in effect from the next cycle */
    bool written[SIM_RTDE_INPUT_SLOTS];
    uint32_t owner[SIM_RTDE_INPUT_SLOTS];
    uint32_t sessions;        /* session ids given so far */
    bool cycle_known;
    uint64_t cycle;           /* the control cycle in effect (the last one sim_rtde_due saw) */
    sim_rtde_pending pending[SIM_RTDE_PENDING_MAX];
    size_t npending;
    uint64_t pending_over;    /* input packages past the log's records this cycle */
    sim_rtde_held held[SIM_RTDE_HELD_MAX];
    size_t nheld;
} sim_rtde_inputs;

/* The controller behind the port. */
typedef struct sim_rtde_controller {
    uint32_t major, minor, bugfix, build;
    uint32_t rate_hz;     /* 125 before 5.0, 500 from 5.0: the highest frequency a client may ask */
    double cycle_hz;      /* the cycles k counted by sim_rtde_due: rate_hz, or a capture's own rate */
    const sim_rtde_recording *recording;   /* a capture's controller; NULL: the model's */
    bool fieldbus;        /* an enabled fieldbus adapter (EtherNet/IP, PROFINET, Modbus) owns input
                             registers 0..23 and bits 0..63 (urrt-sim --fieldbus) */
    sim_rtde_inputs inputs;
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
    uint32_t hold_inputs_ms;  /* a connection's input variables stay IN_USE this long after it left (0: no) */
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

/* An input recipe of a connection: its variables in the session's in_fields. */
typedef struct sim_rtde_input_recipe {
    uint16_t first, count;
    size_t size;              /* bytes of values in its data package */
} sim_rtde_input_recipe;

typedef struct sim_rtde_session {
    sim_rtde_controller *ctl;
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
    uint32_t id;              /* as the owner of input variables */
    sim_rtde_input_recipe inputs[SIM_RTDE_INPUT_RECIPES];   /* id SIM_RTDE_INPUT_ID + index */
    unsigned ninputs;
    sim_rtde_field in_fields[SIM_RTDE_INPUT_FIELDS];
    size_t in_nfields;
    uint64_t inputs_applied;  /* input packages taken (applied at the next cycle) */
    uint64_t inputs_ignored;  /* input packages of no recipe, of the wrong size, before start */
    uint64_t data_sent;       /* data packages, for the faults that count them */
    uint64_t texts_sent;
    bool broken;              /* the client sent an unframable package: close */
    size_t in_len;
    uint8_t in[65536];        /* one package being reassembled */
} sim_rtde_session;

/* "5.12.3.1234" (bugfix and build optional, 0 when left out). NULL, or
 * why the version serves no RTDE. */
const char *sim_rtde_controller_parse(const char *text, sim_rtde_controller *c);

void sim_rtde_session_init(sim_rtde_session *s, sim_rtde_controller *ctl, const sim_rtde_faults *faults,
                           sim_rtde_emit emit, void *emit_ctx, const char *peer);

/* The client left (before the session is freed): its input variables are
 * free again, or IN_USE a while longer with rtde-hold-inputs; their values
 * stay. */
void sim_rtde_session_end(sim_rtde_session *s);

/* Bytes the client sent, in any chunking; replies go out through emit.
 * False when the client must be disconnected (an unframable package). */
bool sim_rtde_feed(sim_rtde_session *s, const uint8_t *data, size_t len);

/* Whether control cycle k (of the controller's rate) carries a data package.
 * Called for every session at every cycle: the first call of a cycle applies
 * the input packages received since the one before, and ends the holds
 * that are over. */
bool sim_rtde_due(sim_rtde_session *s, uint64_t k);

/* Cycle k's data package from its state (preceded by a text message, or
 * replaced by a bad package, when a fault says so). False when it cannot be
 * queued. Call only when sim_rtde_due() said so. */
bool sim_rtde_send_data(sim_rtde_session *s, uint64_t k, const urrt_state *st);

/* The same for a capture's controller: data package k mod count of the
 * recording, after the text messages it recorded since the client's
 * previous package. */
bool sim_rtde_send_recorded(sim_rtde_session *s, uint64_t k);

#endif
