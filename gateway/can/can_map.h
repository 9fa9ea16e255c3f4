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
 *   the configuration front end (config.c) reads [can] with can_map_can_keys
 *   and [frame NAME] with can_map_frame_keys, through can_map_can_begin,
 *   can_map_frame_begin and can_map_set; a caller without it (tests,
 *   tools) feeds keys to can_map_ini
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

#include "conf.h"
#include "port.h"
#include "urrt.h"
#include "urrt_can.h"
#include "urrt_cantx.h"

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
/* Where a robot's rate is unknown: the fastest any controller sends (lib's table). */
#define CAN_MAP_FASTEST_ROBOT_US urrt_period_min_us(0)

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
};

enum can_map_stale_policy {
    CAN_MAP_STALE_STOP = 0,  /* the frame stops: the receiver's own timeout fires */
    CAN_MAP_STALE_INVALID    /* the frame goes on with the validity bit cleared */
};

/* Keys of a [frame NAME] section, for duplicate detection and messages. */
enum can_map_frame_key {
    CAN_MAP_FK_ID, CAN_MAP_FK_EXTENDED, CAN_MAP_FK_FD, CAN_MAP_FK_LENGTH, CAN_MAP_FK_PERIOD,
    CAN_MAP_FK_ROBOT, CAN_MAP_FK_ALIVE, CAN_MAP_FK_VALID, CAN_MAP_FK_STALE_AFTER,
    CAN_MAP_FK_STALE_POLICY, CAN_MAP_FK_COMMENT, CAN_MAP_FK_SIGNAL, CAN_MAP_FK_COUNT
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

/* What a heartbeat signal's value table is. */
enum can_map_hb_values {
    CAN_MAP_HB_VALUES_NONE = 0,
    CAN_MAP_HB_VALUES_STATE,       /* urrt_cantx_state */
    CAN_MAP_HB_VALUES_ROBOT_MODE,  /* robot mode of [can] robot_generation, plus not-available */
    CAN_MAP_HB_VALUES_SAFETY_MODE, /* safety mode, plus not-available */
    CAN_MAP_HB_VALUES_GENERATION,
    CAN_MAP_HB_VALUES_FLAG
};

/* What the DBC says of heartbeat signal k; its place and scaling are
 * urrt_cantx_heartbeat_signals[k] (lib/urrt_cantx.h). */
struct can_map_hb_signal {
    const char *name;
    const char *unit;
    enum can_map_hb_values values;
    const char *comment;
};
extern const struct can_map_hb_signal can_map_heartbeat_layout[URRT_CANTX_HB_COUNT];

struct can_map_robot_rt {
    char name[64];
    uint32_t period_us;
};

/* The keys of [can] and of [frame NAME], in the order of their enums. */
extern const struct conf_key can_map_can_keys[CAN_MAP_CK_COUNT];
extern const struct conf_key can_map_frame_keys[CAN_MAP_FK_COUNT];

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
    /* Run time: lib/urrt_cantx.h over tables built from the above (can_run.c). */
    struct can_map_run *run;
};

void can_map_init(struct can_map *map);
void can_map_free(struct can_map *map);

/* Every problem also goes to fn (NULL: none) as it is found. err buffers
 * still receive the text. */
void can_map_set_reporter(struct can_map *map, can_map_report_fn fn, void *ctx);

/* The front end's calls: a [can] section begins; a [frame NAME] section
 * begins (NULL, with the reason in why, for a name that is not a C
 * identifier of at most 32 characters, the heartbeat's, or taken); a key of
 * either (frame NULL: [can]), looked up in its table by the caller, parsed
 * by the table and its place kept for later messages. */
void can_map_can_begin(struct can_map *map, struct conf_at at);
struct can_map_frame *can_map_frame_begin(struct can_map *map, const char *name, struct conf_at at, char *why,
                                          size_t n);
bool can_map_set(struct can_map *map, struct can_map_frame *frame, const struct conf_key *key, const char *value,
                 struct conf_at at, char *why, size_t n);

/*
 * One key of the configuration file, for a caller without the front end
 * (tests, tools): the same tables. Handles the sections "can" and "frame
 * NAME" (a second [frame NAME] continues the first). Returns 1 when the key
 * was handled, 0 when the section is not the CAN map's (the caller's own),
 * -1 on an error, with "FILE:LINE: reason" in err. Repeated keys are errors
 * except "signal", which adds one signal per line.
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

/*
 * The map as lib/urrt_cantx.h tables: its frames in configuration order, then
 * the heartbeat. Built once, after can_map_finish; 0, or -1 with the reason
 * in err (a table lib/ refuses: a check missing above). can_map_start builds
 * them if the caller did not. can_map_free frees them.
 */
int can_map_build(struct can_map *map, char *err, size_t errlen);
void can_map_run_free(struct can_map *map);

/* The CAN core over the built tables (NULL before can_map_build), and the
 * heartbeat's index in them. */
urrt_cantx *can_map_tx(struct can_map *map);
size_t can_map_heartbeat_index(const struct can_map *map);

/* Restarts the schedule at now_us (urrt_cantx_start). */
void can_map_start(struct can_map *map, uint64_t now_us);

/* The CAN link's counters, as the heartbeat's flags need them. */
void can_map_link_stats(struct can_map *map, const urrt_canlink_stats *stats);

/* Values packed with an outcome other than OK, since start. */
uint64_t can_map_clamped(const struct can_map *map);

/* The CAN link's counters (NULL: unchanged), then every frame due at now_us
 * through emit (urrt_cantx_run). Starts the schedule on its first call. */
void can_map_due(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats, urrt_cantx_emit_fn emit,
                 void *ctx);

/* The heartbeat as it would go out at now_us with these link counters,
 * without sending it (urrt_cantx_peek): for status displays and tests. */
void can_map_heartbeat_frame(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats,
                             urrt_can_frame *frame);

/* The heartbeat's gateway state at now_us. */
urrt_cantx_state can_map_state(const struct can_map *map, uint64_t now_us);

/* Worst-case bus time of one frame in microseconds at the map's bit rates. */
double can_map_frame_time_us(const struct can_map *map, unsigned len, bool extended, bool fd);

#endif /* URRT_GATEWAY_CAN_MAP_H */
