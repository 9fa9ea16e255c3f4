/* SPDX-License-Identifier: MIT */
/*
 * urrt_cantx: the CAN side of a gateway, as a contract with the PLC. Which
 * robot values go into which frame, when each frame goes out (with every
 * robot packet, or at a period), what happens when the data is stale (the
 * frame stops, or goes on with its validity bit cleared), alive counters,
 * and the gateway's heartbeat.
 *
 * The tables are the caller's: frame descriptors and signals, usually
 * const and generated from urrt-gateway's INI (`urrt-gateway
 * --print-c-tables`), and the run-time state, sized by the caller. They
 * are checked once, by urrt_cantx_init; the run-time calls trust them and
 * cost loads per packet and one packing per frame sent. Time is always an
 * argument (a monotonic clock in microseconds), and frames leave through
 * the caller's emit function: the module does no I/O, keeps no globals,
 * never allocates, and is C99 and freestanding like urrt.h and urrt_can.h.
 *
 * A firmware gateway (docs/firmware.md):
 *
 *     static urrt_cantx_frame_state states[TABLE_FRAMES];
 *     static urrt_cantx_robot robots[TABLE_ROBOTS];
 *     static double values[TABLE_VALUES];
 *     static urrt_cantx tx;
 *     static urrt_can_scale scales[TABLE_VALUES];
 *     urrt_cantx_init(&tx, &table, states, robots, values, TABLE_VALUES, &where);
 *     urrt_cantx_prepare(&tx, scales, TABLE_VALUES);
 *     urrt_cantx_start(&tx, now);
 *     on a decoded packet:  urrt_cantx_on_packet(&tx, 0, &state, now);
 *     on the link's state:  urrt_cantx_robot_link(&tx, 0, up);
 *     every loop:           urrt_cantx_run(&tx, now, send_frame, ctx);
 *                           sleep until urrt_cantx_deadline(&tx)
 *
 * The heartbeat is an ordinary frame whose values come from a fill
 * function; urrt_cantx_heartbeat_signals, _sources and _fill are
 * the one urrt-gateway sends (its layout is in docs/can.md and the DBC).
 */
#ifndef URRT_CANTX_H
#define URRT_CANTX_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt.h"
#include "urrt_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Errors of urrt_cantx_init, beside urrt_can.h's (a signal's descriptor,
 * layout, frame length and id errors come from there). */
enum urrt_cantx_result {
    URRT_CANTX_E_SOURCE = -40,   /* a signal's source: unknown kind, field or element out of
                                    range, a mask field without a bit mask descriptor (or a
                                    field with one), an alive counter or validity bit of the wrong type or
                                    length or twice in a frame, a filled value in a frame
                                    without a fill function */
    URRT_CANTX_E_ROBOT = -41,    /* robot index out of range */
    URRT_CANTX_E_POLICY = -42,   /* stale policy unknown, or "invalid" without a validity bit */
    URRT_CANTX_E_DUPLICATE = -43, /* two frames with the same id and format */
    URRT_CANTX_E_STORAGE = -44   /* values[] (or scales[]) shorter than the tables' signals */
};

/* A short English text for any urrt_cantx, urrt_can or urrt result. */
const char *urrt_cantx_strerror(int result);

/* Where a signal's value comes from. */
typedef enum urrt_cantx_kind {
    URRT_CANTX_FIELD = 0,     /* element elem of robot field `field` */
    URRT_CANTX_FIELD_MASK,    /* the same field read as a bit mask (digital I/O, urrt_bitmask):
                                 its signal is a URRT_CAN_SIG_BITMASK descriptor, which
                                 carries the mask's bits and is never clamped (a FIELD's
                                 signal is not one) */
    URRT_CANTX_ALIVE,         /* the frame's alive counter: 0, 1, ... with each frame sent,
                                 modulo 2^length (unsigned, length 1..8; one per frame) */
    URRT_CANTX_VALID,         /* the frame's validity bit (unsigned, length 1; one per frame):
                                 1 when the robot's data is fresh and every field and
                                 filled value was packed as it is (URRT_CAN_PACK_OK) */
    URRT_CANTX_FILLED,        /* the value the frame's fill function gives */
    URRT_CANTX_FILLED_MASK    /* a bit mask the fill function gives as its 64 bits, by
                                 urrt_cantx_mask_value (its signal a URRT_CAN_SIG_BITMASK
                                 descriptor): exact up to bit 63, where a double holding
                                 the integer loses bits past 2^53 */
} urrt_cantx_kind;

/* A 64-bit mask as a fill function gives it to a URRT_CANTX_FILLED_MASK
 * signal: its bits in the double's place, not its value. */
double urrt_cantx_mask_value(uint64_t mask);

/* What signal i of a frame carries: sources[i] beside signals[i]. */
typedef struct urrt_cantx_source {
    uint8_t kind;          /* urrt_cantx_kind */
    uint8_t field;         /* urrt_field_id, for the field kinds */
    uint8_t elem;          /* element of the field */
} urrt_cantx_source;

/* What a frame does while its robot's data is older than stale_after_us. */
typedef enum urrt_cantx_stale {
    URRT_CANTX_STALE_STOP = 0,   /* it stops, so that the receiver's own timeout fires; a
                                    periodic frame resumes with the next fresh packet */
    URRT_CANTX_STALE_INVALID,    /* periodic frames only: it goes on at its period with the
                                    validity bit cleared */
    URRT_CANTX_STALE_IGNORE      /* periodic frames only: it always goes out (a heartbeat,
                                    which reports staleness itself) */
} urrt_cantx_stale;

#define URRT_CANTX_EVERY_PACKET 0u  /* period_us: one frame per packet of the robot */

/* Frame flags. */
#define URRT_CANTX_EXTENDED 0x01u   /* 29-bit id */
#define URRT_CANTX_FD 0x02u         /* CAN FD frame */

struct urrt_cantx;

/*
 * Gives values[i] for each URRT_CANTX_FILLED signal i of frame `frame` (other
 * entries are ignored) as it would go out at now_us. `sending` is false when
 * the frame is only looked at (urrt_cantx_peek): a fill function that keeps
 * "since the previous frame" state updates it only when sending.
 */
typedef void (*urrt_cantx_fill_fn)(struct urrt_cantx *tx, size_t frame, uint64_t now_us, bool sending,
                                   double *values);

typedef struct urrt_cantx_frame {
    const urrt_can_signal *signals;     /* place and scaling (urrt_can.h) */
    const urrt_cantx_source *sources;   /* what each carries */
    uint16_t signal_count;
    uint8_t len;               /* payload bytes: 0-8, or an FD length with URRT_CANTX_FD */
    uint8_t flags;             /* URRT_CANTX_EXTENDED, URRT_CANTX_FD */
    uint32_t id;
    uint32_t period_us;        /* URRT_CANTX_EVERY_PACKET or the period */
    uint32_t stale_after_us;   /* data older than this is stale */
    uint8_t stale;             /* urrt_cantx_stale */
    uint8_t robot;             /* the robot whose fields it carries and whose age counts */
    urrt_cantx_fill_fn fill;   /* NULL unless the frame has URRT_CANTX_FILLED signals */
} urrt_cantx_frame;

typedef struct urrt_cantx_tables {
    const urrt_cantx_frame *frames;  /* sent in this order when due at the same time */
    size_t frame_count;
    size_t robot_count;              /* 1..255 */
    uint32_t startup_us;             /* the heartbeat says "starting" this long without data */
} urrt_cantx_tables;

/* Run-time state of a frame (caller-owned, one per frame). */
typedef struct urrt_cantx_frame_state {
    uint64_t next_due_us;      /* periodic: URRT_CANTX_NEVER while stopped */
    uint64_t sent;
    uint64_t sent_invalid;     /* sent with the validity bit cleared */
    uint64_t stale_stops;      /* times it stopped (or dropped a packet's frame) for stale data */
    uint16_t first_value;      /* its signals' slots in values[] */
    uint16_t fields_end;       /* no signal from this index on carries a robot field */
    uint32_t period_us;        /* the table's, until urrt_cantx_set_period */
    urrt_can_frame frame;      /* as last built: the field values last taken (packed when
                                  first needed), then the alive counter, validity bit and
                                  filled values of its latest send; emit receives it */
    int8_t outcome;            /* worst URRT_CAN_PACK_* of the fields' packing */
    uint8_t alive;
    bool unpacked;             /* values taken since the payload was packed */
    bool pending;              /* every packet: a packet came since the last send */
    bool stopped;              /* periodic, stop policy: waiting for fresh data */
    bool closed;               /* urrt_cantx_gate: its schedule sends nothing */
} urrt_cantx_frame_state;

/* Run-time state of a robot (caller-owned, one per robot). */
typedef struct urrt_cantx_robot {
    uint64_t data_us;          /* when its newest data was current (the caller's clock) */
    double robot_mode;         /* of the newest packet, NaN if none */
    double safety_mode;
    uint8_t generation;        /* urrt_generation */
    bool has_data;
    bool up;                   /* its link is connected */
} urrt_cantx_robot;

/* The CAN link's counters, kept up to date by the caller (urrt_cantx_set_link)
 * for the heartbeat's flags. */
typedef struct urrt_cantx_link {
    uint64_t bus_off;
    uint64_t error_frames;
    uint64_t down_events;
    uint64_t send_errors;
    uint64_t dropped;
} urrt_cantx_link;

typedef struct urrt_cantx {
    const urrt_cantx_tables *tables;
    urrt_cantx_frame_state *frames;
    urrt_cantx_robot *robots;
    double *values;
    const urrt_can_scale *scales; /* urrt_cantx_prepare's, or NULL */
    void *user;                /* for the caller's fill functions: set it after urrt_cantx_init */
    urrt_cantx_link link;      /* as last set */
    urrt_cantx_link link_seen; /* at the previous heartbeat */
    uint64_t clamped;          /* values packed with an outcome other than OK */
    uint64_t clamped_seen;     /* at the previous heartbeat */
    uint64_t start_us;
    uint64_t run_us;           /* the time of the latest urrt_cantx_run */
    uint64_t wake_us;          /* urrt_cantx_deadline: nothing is due before it */
    bool started;
} urrt_cantx;

#define URRT_CANTX_NEVER UINT64_MAX

/*
 * Checks the tables once and binds the caller's storage: frame_states and
 * robots hold tables->frame_count and ->robot_count entries, values at
 * least the tables' signal count in all. Every frame: id and length valid
 * for its format, signals valid, inside the frame and apart
 * (urrt_can_layout_check), sources valid, robot in range, policy known
 * (invalid needs a validity bit; a frame sent with every packet cannot
 * keep going on stale data), ids unique. Returns 0, or the first error with
 * *bad_frame and *bad_signal (SIZE_MAX when it is the frame as a whole)
 * naming it; either pointer may be NULL.
 */
int urrt_cantx_init(urrt_cantx *tx, const urrt_cantx_tables *tables, urrt_cantx_frame_state *frame_states,
                    urrt_cantx_robot *robots, double *values, size_t value_count, size_t *bad_frame,
                    size_t *bad_signal);

/* Total signals of the tables: the values[] urrt_cantx_init needs. */
size_t urrt_cantx_value_count(const urrt_cantx_tables *tables);

/*
 * After urrt_cantx_init: prepares every signal's scale once
 * (urrt_can_scale_prepare) into the caller's scales[], at least
 * urrt_cantx_value_count entries (indexed as values[]), which the core then
 * packs with: no division per signal packed, a tenth of the instructions on
 * a core without a double-precision FPU. Without it each packing prepares
 * its signal's scale again, to the same bits. Returns 0,
 * URRT_CANTX_E_STORAGE (scales[] too short) or URRT_E_ARG; urrt_cantx_init
 * forgets the scales.
 */
int urrt_cantx_prepare(urrt_cantx *tx, urrt_can_scale *scales, size_t count);

/* Starts (or restarts) the schedule at now_us: periodic frames with the
 * invalid or ignore policy are due now (invalid until data comes), frames
 * with the stop policy wait for data, robots have none. urrt_cantx_run
 * starts it on its first call if the caller did not. */
void urrt_cantx_start(urrt_cantx *tx, uint64_t now_us);

/* A decoded packet of robot `robot` whose data was current at data_us (its
 * read time, less any lag the caller knows of): takes the values of that
 * robot's frames. A packet means the robot's link is up. */
void urrt_cantx_on_packet(urrt_cantx *tx, size_t robot, const urrt_state *st, uint64_t data_us);

/* The robot's link went up or down (down: the heartbeat says disconnected). */
void urrt_cantx_robot_link(urrt_cantx *tx, size_t robot, bool up);

/* The CAN link's counters now, for the heartbeat. */
void urrt_cantx_set_link(urrt_cantx *tx, const urrt_cantx_link *link);

/* Sends a frame; *frame is the core's own and changes with the next
 * frame built: copy it to keep it past the call (a transmit queue). */
typedef void (*urrt_cantx_emit_fn)(void *ctx, const urrt_can_frame *frame, uint64_t now_us);

/* Sends every frame due at now_us through emit, in table order. Returns the
 * number sent. */
size_t urrt_cantx_run(urrt_cantx *tx, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx);

/* Runs the schedule at each deadline before until_us, at that deadline's
 * time: what a loop that woke at every deadline would have sent. For a
 * replay clocked by its packets' time (urrt-gateway --replay) and for
 * simulations; a loop on a real clock calls urrt_cantx_run. Returns the
 * number sent. */
size_t urrt_cantx_catch_up(urrt_cantx *tx, uint64_t until_us, urrt_cantx_emit_fn emit, void *ctx);

/* When urrt_cantx_run must run next (URRT_CANTX_NEVER: not before the next
 * packet; a time at or before now means now). */
uint64_t urrt_cantx_deadline(const urrt_cantx *tx);

/* Frame `frame` as it would go out now, without sending it: no counter,
 * alive value or heartbeat flag advances. For status displays and tests. */
void urrt_cantx_peek(urrt_cantx *tx, size_t frame, uint64_t now_us, urrt_can_frame *out);

/* Whether robot `robot`'s data is no older than max_age_us at now_us. */
bool urrt_cantx_fresh(const urrt_cantx *tx, size_t robot, uint64_t now_us, uint32_t max_age_us);

/* ---- run-time changes ---------------------------------------------------------
 * For a CANopen node (urrt_co.h), whose PDOs are frames of these tables: the
 * manager switches them on and off, moves their ids and periods, or has them
 * sent on its SYNC. urrt_cantx_init leaves every frame open, with the
 * table's id and period; urrt_cantx_start keeps what these calls set. */

/* Opens or closes the frame's schedule. A closed frame's slots pass unsent
 * (a periodic frame keeps its cadence, a per-packet frame forgets the
 * packet); urrt_cantx_trigger still sends it. */
void urrt_cantx_gate(urrt_cantx *tx, size_t frame, bool open);

/* The frame's id from now on (its format stays): URRT_CAN_E_ID if the id is
 * not valid for it. Unlike urrt_cantx_init it does not compare the id with
 * the other frames': the caller keeps the ids it sends apart. */
int urrt_cantx_set_id(urrt_cantx *tx, size_t frame, uint32_t id);

/* The frame's period from now on, due first at now_us (a stop-policy frame
 * waiting for data still waits); URRT_CANTX_EVERY_PACKET only for a frame
 * with the stop policy (else URRT_CANTX_E_POLICY, as urrt_cantx_init). */
int urrt_cantx_set_period(urrt_cantx *tx, size_t frame, uint32_t period_us, uint64_t now_us);

/* Sends the frame now, whatever its schedule or gate, under its stale
 * policy (stop: nothing while the data is stale; invalid: the validity bit
 * cleared). Returns the number sent, 0 or 1. */
size_t urrt_cantx_trigger(urrt_cantx *tx, size_t frame, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx);

/* ---- the heartbeat ---------------------------------------------------------- */

/* The gateway's state, ordered by value as on the bus. */
typedef enum urrt_cantx_state {
    URRT_CANTX_STARTING = 0,       /* no data yet from a robot, within startup_us */
    URRT_CANTX_OK = 1,
    URRT_CANTX_DATA_STALE = 2,     /* a robot's data older than the heartbeat's stale_after_us */
    URRT_CANTX_DISCONNECTED = 3    /* a robot's link is down */
} urrt_cantx_state;

/* Robot `robot`'s state at now_us, its data judged stale past stale_after_us. */
urrt_cantx_state urrt_cantx_robot_state(const urrt_cantx *tx, size_t robot, uint64_t now_us,
                                        uint32_t stale_after_us);

/* The worst state over every robot at now_us, judged by frame hb's
 * stale_after_us (the heartbeat's). */
urrt_cantx_state urrt_cantx_gateway_state(const urrt_cantx *tx, size_t hb, uint64_t now_us);
const char *urrt_cantx_state_name(urrt_cantx_state state);

/* Heartbeat signals: 8 bytes, classic CAN, Intel byte order. Its robot
 * (modes, generation, data age) is the frame's robot. Flags say "happened
 * since the previous heartbeat", so a receiver can latch them. */
enum urrt_cantx_hb_signal {
    URRT_CANTX_HB_STATE,           /* urrt_cantx_state, 4 bits */
    URRT_CANTX_HB_ALIVE,           /* 4 bits */
    URRT_CANTX_HB_ROBOT_MODE,      /* signed 8 bits, URRT_CANTX_HB_ROBOT_MODE_NA: not available */
    URRT_CANTX_HB_SAFETY_MODE,     /* 8 bits, URRT_CANTX_HB_SAFETY_MODE_NA: not available */
    URRT_CANTX_HB_GENERATION,      /* urrt_generation, 2 bits */
    URRT_CANTX_HB_BUS_OFF,         /* flags, 1 bit each */
    URRT_CANTX_HB_CAN_ERRORS,
    URRT_CANTX_HB_CAN_DOWN,
    URRT_CANTX_HB_SEND_ERRORS,
    URRT_CANTX_HB_TX_DROPPED,
    URRT_CANTX_HB_CLAMPED,         /* a value saturated or was NaN (or, for a bit mask, no mask) */
    URRT_CANTX_HB_DATA_AGE,        /* ms, 16 bits, saturated at 65534; URRT_CANTX_HB_AGE_NA: no data */
    URRT_CANTX_HB_DROPS,           /* link's dropped frames modulo 65536 */
    URRT_CANTX_HB_COUNT
};
#define URRT_CANTX_HB_LEN 8u
#define URRT_CANTX_HB_ROBOT_MODE_NA (-128)
#define URRT_CANTX_HB_SAFETY_MODE_NA 0
#define URRT_CANTX_HB_AGE_NA 65535u

extern const urrt_can_signal urrt_cantx_heartbeat_signals[URRT_CANTX_HB_COUNT];
extern const urrt_cantx_source urrt_cantx_heartbeat_sources[URRT_CANTX_HB_COUNT];

/* The heartbeat's fill function: a frame with signals
 * urrt_cantx_heartbeat_signals and _sources, length URRT_CANTX_HB_LEN, a period, the
 * ignore policy, and stale_after_us the age at which data counts as stale. */
void urrt_cantx_heartbeat_fill(urrt_cantx *tx, size_t frame, uint64_t now_us, bool sending, double *values);

#ifdef __cplusplus
}
#endif

#endif /* URRT_CANTX_H */
