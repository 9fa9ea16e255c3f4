/* SPDX-License-Identifier: MIT */
/*
 * can_map: the CAN side of urrt-gateway. Which robot fields go into which
 * CAN frames (the mapping configuration, its checks), and when each frame is
 * sent (periods, every packet, staleness, alive counters, the heartbeat).
 *
 * It produces urrt_can_frame values and hands them to a callback; it never
 * touches a CAN link, a clock or a socket itself: the gateway loop passes
 * the time and the link's statistics in and sends what comes out. The bit
 * packing is lib/urrt_can.h. docs/can.md is the user's reference.
 *
 * Life cycle:
 *   struct can_map map;  can_map_init(&map);
 *   for each key of [can] and [frame NAME] sections:
 *       can_map_ini(&map, section, key, value, file, line, err, sizeof err)
 *   can_map_finish(&map, robots, robot_count, err, sizeof err)
 *   can_map_start(&map, now)
 *   loop:
 *       on a robot packet:    can_map_on_packet(&map, robot, &state, rx_us)
 *       on a robot link change: can_map_robot_link(&map, robot, up)
 *       can_map_due(&map, now, urrt_canlink_get_stats(can), send_fn, can)
 *       poll until min(can_map_deadline(&map), ...)
 *   can_map_free(&map)
 */
#ifndef URRT_GATEWAY_CAN_MAP_H
#define URRT_GATEWAY_CAN_MAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "port.h"
#include "urrt.h"
#include "urrt_can.h"

#define CAN_MAP_NAME_MAX 32           /* DBC names: C identifiers of at most 32 characters */
#define CAN_MAP_UNIT_MAX 24
#define CAN_MAP_HEARTBEAT_NAME "urrt_heartbeat"
#define CAN_MAP_ALIVE_NAME "alive_counter"
#define CAN_MAP_VALID_NAME "valid"
#define CAN_MAP_ALIVE_BITS 4u
#define CAN_MAP_STARTUP_MS 5000u      /* "starting" lasts at most this long without data */
#define CAN_MAP_DEFAULT_BITRATE 500000u
#define CAN_MAP_DEFAULT_STALE_MS 100u
#define CAN_MAP_DEFAULT_HEARTBEAT_MS 100u
#define CAN_MAP_DEFAULT_MAX_LOAD 50u  /* percent */
#define CAN_MAP_FASTEST_ROBOT_US 2000u /* e-series, 500 Hz: used where a robot's rate is unknown */
#define CAN_MAP_NOT_SCHEDULED UINT64_MAX

/* Where a key came from, for "FILE:LINE: reason". line 0: not given. */
struct can_map_loc {
    const char *file;
    int line;
};

enum can_map_role {
    CAN_MAP_ROLE_FIELD = 0,  /* a robot field element */
    CAN_MAP_ROLE_ALIVE,      /* the frame's alive counter */
    CAN_MAP_ROLE_VALID       /* the frame's validity bit (1 = valid) */
};

/* What a signal of the table carries; sigs[i] and meta[i] go together. */
struct can_map_signal {
    char name[CAN_MAP_NAME_MAX + 1];
    char unit[CAN_MAP_UNIT_MAX + 1];
    enum can_map_role role;
    int field;               /* urrt_field_id for CAN_MAP_ROLE_FIELD */
    unsigned elem;
    bool bitmask;            /* field coded as a bit mask (unit "bits"): sent as the integer mask */
    struct can_map_loc loc;
    double value;            /* run time: the latest packet's value, packed when the frame is sent */
};

enum can_map_stale_policy {
    CAN_MAP_STALE_STOP = 0,  /* the frame stops: the receiver's own timeout fires */
    CAN_MAP_STALE_INVALID    /* the frame goes on with the validity bit cleared */
};

/* Keys of a [frame NAME] section, for duplicate detection and messages. */
enum can_map_frame_key {
    CAN_MAP_FK_ID, CAN_MAP_FK_EXTENDED, CAN_MAP_FK_FD, CAN_MAP_FK_LENGTH, CAN_MAP_FK_PERIOD,
    CAN_MAP_FK_ROBOT, CAN_MAP_FK_ALIVE, CAN_MAP_FK_VALID, CAN_MAP_FK_STALE_AFTER,
    CAN_MAP_FK_STALE_POLICY, CAN_MAP_FK_COMMENT, CAN_MAP_FK_COUNT
};

struct can_map_frame {
    char name[CAN_MAP_NAME_MAX + 1];
    char comment[128];
    struct can_map_loc loc;                 /* first key of the section */
    struct can_map_loc key_loc[CAN_MAP_FK_COUNT];
    uint32_t id;
    bool extended;
    bool fd;
    uint8_t len;
    bool every;                             /* one frame per robot packet */
    uint32_t period_ms;                     /* when !every */
    char robot[64];                         /* as configured; "" = the only robot */
    size_t robot_index;                     /* resolved by can_map_finish */
    uint32_t stale_after_ms;
    enum can_map_stale_policy stale_policy;
    int alive_index;                        /* index in sigs of the alive counter, -1: none */
    int valid_index;                        /* index in sigs of the validity bit, -1: none */
    /* The signal table: what lib/urrt_can.h packs, and what each carries. */
    urrt_can_signal *sigs;
    struct can_map_signal *meta;
    size_t count;
    size_t capacity;
    double load;                            /* worst-case share of the bus (0.027 = 2.7 %) */
    /* Run time. */
    uint8_t payload[URRT_CAN_MAX_LEN];     /* signals packed from the latest packet */
    int outcome;                            /* worst URRT_CAN_PACK_* of the latest packing */
    bool unpacked;                          /* values taken since the payload was packed */
    bool pending;                           /* every: a packet arrived since the last send */
    bool stopped;                           /* periodic, stop policy: waiting for fresh data */
    uint64_t next_due_us;                   /* periodic: CAN_MAP_NOT_SCHEDULED while stopped */
    uint8_t alive;
    uint64_t sent;
    uint64_t sent_invalid;                  /* sent with the validity bit cleared */
    uint64_t stale_stops;                   /* times the frame stopped for stale data */
};

/* Keys of the [can] section. */
enum can_map_can_key {
    CAN_MAP_CK_INTERFACE, CAN_MAP_CK_FD, CAN_MAP_CK_BITRATE, CAN_MAP_CK_DATA_BITRATE,
    CAN_MAP_CK_MAX_LOAD, CAN_MAP_CK_HB_ID, CAN_MAP_CK_HB_EXTENDED, CAN_MAP_CK_HB_PERIOD,
    CAN_MAP_CK_HB_ROBOT, CAN_MAP_CK_STALE_AFTER, CAN_MAP_CK_GENERATION, CAN_MAP_CK_NODE,
    CAN_MAP_CK_RECEIVER, CAN_MAP_CK_COUNT
};

/* A robot as the gateway knows it: name, and the period it sends packets at
 * (8000 us at 125 Hz, 2000 at 500 Hz; 0 if unknown). */
struct can_map_robot {
    const char *name;
    uint32_t period_us;
};

/* Gateway state in the heartbeat, ordered by value as on the bus. */
enum can_map_gateway_state {
    CAN_MAP_STATE_STARTING = 0,      /* no data yet from a robot, within CAN_MAP_STARTUP_MS */
    CAN_MAP_STATE_OK = 1,
    CAN_MAP_STATE_DATA_STALE = 2,    /* a robot's data older than [can] stale_after_ms */
    CAN_MAP_STATE_DISCONNECTED = 3   /* a robot's link is down */
};

/* Error flags in the heartbeat: each says "happened since the previous
 * heartbeat", so a receiver can latch them. */
#define CAN_MAP_FLAG_BUS_OFF 0x01u      /* the controller went bus-off */
#define CAN_MAP_FLAG_CAN_ERRORS 0x02u   /* CAN error frames (error passive, warnings, ...) */
#define CAN_MAP_FLAG_CAN_DOWN 0x04u     /* the interface went down (and is being reopened) */
#define CAN_MAP_FLAG_SEND_ERRORS 0x08u  /* frames the link refused */
#define CAN_MAP_FLAG_TX_DROPPED 0x10u   /* frames dropped on a full queue (see drop counter) */
#define CAN_MAP_FLAG_CLAMPED 0x20u      /* a value saturated or was NaN */

/* Heartbeat signals, in the order of can_map_heartbeat_layout. */
enum can_map_hb_signal_id {
    CAN_MAP_HB_STATE, CAN_MAP_HB_ALIVE, CAN_MAP_HB_ROBOT_MODE, CAN_MAP_HB_SAFETY_MODE,
    CAN_MAP_HB_GENERATION, CAN_MAP_HB_BUS_OFF, CAN_MAP_HB_CAN_ERRORS, CAN_MAP_HB_CAN_DOWN,
    CAN_MAP_HB_SEND_ERRORS, CAN_MAP_HB_TX_DROPPED, CAN_MAP_HB_CLAMPED, CAN_MAP_HB_DATA_AGE,
    CAN_MAP_HB_DROPS, CAN_MAP_HB_COUNT
};

/* What a heartbeat signal's value table is. */
enum can_map_hb_values {
    CAN_MAP_HB_VALUES_NONE = 0,
    CAN_MAP_HB_VALUES_STATE,       /* enum can_map_gateway_state */
    CAN_MAP_HB_VALUES_ROBOT_MODE,  /* robot mode of [can] robot_generation, plus not-available */
    CAN_MAP_HB_VALUES_SAFETY_MODE, /* safety mode, plus not-available */
    CAN_MAP_HB_VALUES_GENERATION,
    CAN_MAP_HB_VALUES_FLAG
};

struct can_map_hb_signal {
    const char *name;
    urrt_can_signal sig;
    const char *unit;
    enum can_map_hb_values values;
    const char *comment;
};

/* The heartbeat frame's layout, written once: the gateway packs it, the DBC
 * writer describes it, the tests decode it. 8 bytes, classic CAN. */
#define CAN_MAP_HB_LEN 8u
#define CAN_MAP_HB_ROBOT_MODE_NA (-128) /* robot mode not available */
#define CAN_MAP_HB_SAFETY_MODE_NA 0     /* safety mode not available (1.x, or no data) */
#define CAN_MAP_HB_AGE_NA 65535u        /* no data yet (ages saturate at 65534) */
extern const struct can_map_hb_signal can_map_heartbeat_layout[CAN_MAP_HB_COUNT];
const char *can_map_state_name(enum can_map_gateway_state state);

struct can_map_robot_rt {
    char name[64];
    uint32_t period_us;
    bool has_data;
    bool up;
    uint64_t last_rx_us;
    double robot_mode;
    double safety_mode;
    urrt_generation generation;
};

/* Receives each problem can_map_ini and can_map_finish find, as file, line
 * and reason (without "FILE:LINE: "), for a caller with its own error list. */
typedef void (*can_map_report_fn)(void *ctx, const char *file, int line, const char *reason);

struct can_map {
    can_map_report_fn reporter;             /* optional, see can_map_set_reporter */
    void *reporter_ctx;
    bool configured;                        /* a [can] key or a [frame] section was seen */
    bool finished;
    /* [can] */
    struct can_map_loc can_loc;             /* first key of [can] */
    struct can_map_loc key_loc[CAN_MAP_CK_COUNT];
    char *interface;                        /* "can0" or "log:PATH": for urrt_canlink_config */
    bool fd;                                /* FD frames allowed: urrt_canlink_config.fd */
    uint32_t bitrate;
    uint32_t data_bitrate;                  /* 0: same as bitrate (no bit rate switch) */
    unsigned max_load_percent;
    uint32_t hb_id;
    bool hb_extended;
    uint32_t hb_period_ms;
    char hb_robot[64];
    size_t hb_robot_index;
    uint32_t stale_after_ms;                /* default for frames, and the heartbeat's "data stale" */
    urrt_generation generation;             /* numbering of robot mode value tables in the DBC */
    char node[CAN_MAP_NAME_MAX + 1];        /* DBC node of the gateway */
    char receiver[CAN_MAP_NAME_MAX + 1];    /* DBC receiver of every signal */
    /* [frame NAME] */
    struct can_map_frame *frames;
    size_t frame_count;
    size_t frame_capacity;
    /* Robots (copied by can_map_finish). */
    struct can_map_robot_rt *robots;
    size_t robot_count;
    double load;                            /* worst-case bus load, 0.5 = 50 % (heartbeat included) */
    double hb_load;
    /* File names seen, each stored once (struct can_map_loc points here). */
    char **files;
    size_t file_count;
    /* Run time. */
    bool started;
    uint64_t start_us;
    uint64_t hb_next_us;
    uint8_t hb_alive;
    uint64_t clamped;                       /* values packed with a non-OK outcome */
    urrt_canlink_stats hb_seen;                 /* link statistics at the previous heartbeat */
    uint64_t hb_clamped_seen;
    uint64_t hb_sent;
    enum can_map_gateway_state state;       /* as in the last heartbeat */
};

void can_map_init(struct can_map *map);
void can_map_free(struct can_map *map);

/* Every problem also goes to fn (NULL: none) as it is found. err buffers
 * still receive the text. */
void can_map_set_reporter(struct can_map *map, can_map_report_fn fn, void *ctx);

/*
 * One key of the configuration file, as the INI parser reads it. Handles
 * the sections "can" and "frame NAME" (NAME a C identifier of at most 32
 * characters). Returns 1 when the key was handled, 0 when the section is
 * not the CAN map's (the caller's own), -1 on an error, with
 * "FILE:LINE: reason" in err. Repeated keys are errors except "signal",
 * which adds one signal per line.
 */
int can_map_ini(struct can_map *map, const char *section, const char *key, const char *value, const char *file,
                int line, char *err, size_t errlen);

/*
 * Checks that need the whole file and the gateway's robots: overlaps and
 * lengths, duplicate and out-of-range ids (heartbeat included), robot
 * names, periods faster than a robot sends, worst-case bus load. Resolves
 * robot names and computes loads. Returns 0, or -1 with every problem found
 * in err as "FILE:LINE: reason" lines separated by '\n' (as many as fit).
 * A map with no CAN configuration at all finishes with 0 and stays
 * disabled (can_map_enabled() false).
 */
int can_map_finish(struct can_map *map, const struct can_map_robot *robots, size_t robot_count, char *err,
                   size_t errlen);

bool can_map_enabled(const struct can_map *map);

/* The CAN link's configuration from [can]: interface, fd, and fd_brs (FD
 * frames switch to data_bitrate when it is above bitrate). cfg must hold
 * urrt_canlink_config_defaults() first; the other fields are left alone. The
 * interface string stays owned by the map. Bit rates are not set on the
 * interface (ip link does that): the map uses them for the bus load check
 * and the DBC. */
void can_map_link_config(const struct can_map *map, urrt_canlink_config *cfg);

/* One line for the log at start: "4 frames + heartbeat 0x705 on can0,
 * worst-case bus load 7.6% of 500000 bit/s (max 40%)". Returns snprintf's. */
int can_map_describe(const struct can_map *map, char *buf, size_t size);

/* ---- run time ------------------------------------------------------------------ */

typedef void (*can_map_emit_fn)(void *ctx, const urrt_can_frame *frame);

/* Resets the run-time state: the heartbeat is due at now_us, frames with
 * the invalid policy are due at now_us (flagged invalid until data comes).
 * can_map_due calls it on its first call if the gateway did not. */
void can_map_start(struct can_map *map, uint64_t now_us);

/* A decoded packet of robot `robot` (index into the robots given to
 * can_map_finish) whose data is no older than now - data_us (its read time,
 * less any lag the gateway measured: gateway/freshness.h): packs every
 * frame of that robot. Staleness is judged from data_us. A packet means
 * the robot's link is up. */
void can_map_on_packet(struct can_map *map, size_t robot, const urrt_state *st, uint64_t data_us);

/* The robot's link went up or down (down: the heartbeat says disconnected). */
void can_map_robot_link(struct can_map *map, size_t robot, bool up);

/* Emits every frame due at now_us, in configuration order, then the
 * heartbeat if due. stats: the CAN link's statistics (NULL if none), for
 * the heartbeat's drop counter and error flags. */
void can_map_due(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats, can_map_emit_fn emit,
                 void *ctx);

/* Monotonic time by which can_map_due must run next (CAN_MAP_NOT_SCHEDULED
 * if never, e.g. before can_map_start). A time at or before now means now. */
uint64_t can_map_deadline(const struct can_map *map);

/* The heartbeat's gateway state at now_us. */
enum can_map_gateway_state can_map_state(const struct can_map *map, uint64_t now_us);

/* Pack the heartbeat as it would be sent now (without advancing its alive
 * counter or flag snapshots): for status displays and tests. */
void can_map_heartbeat_frame(const struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats,
                             urrt_can_frame *frame);

/* Worst-case bus time of one frame in microseconds at the map's bit rates. */
double can_map_frame_time_us(const struct can_map *map, unsigned len, bool extended, bool fd);

#endif /* URRT_GATEWAY_CAN_MAP_H */
