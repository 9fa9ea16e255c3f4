/* SPDX-License-Identifier: MIT */
/*
 * can_map: the CAN mapping, urrt-gateway's configuration language for CAN.
 * Which robot fields go into which CAN frames, at which periods, with which
 * staleness rules (the keys of [can] and [frame NAME], the signal grammar),
 * and the checks a whole configuration must pass (ids, layouts, robots, bus
 * load). It describes frames; it sends nothing: can_run.h turns a finished
 * map into the tables of lib/urrt_cantx.h, and dbc.h describes it for the
 * PLC side. The bit packing is lib/urrt_can.h. docs/can.md is the user's
 * reference.
 *
 * Life cycle (the configuration loader, gateway/urrt-gateway/config.c,
 * drives the parsing part):
 *   struct can_map map;  can_map_init(&map);    the keys' defaults set
 *   a [can] section:     can_map_can_begin, then can_map_set per key
 *   a [frame NAME]:      can_map_frame_begin, then can_map_set per key
 *                        (keys looked up in can_map_can_keys and
 *                        can_map_frame_keys by the loader)
 *   can_map_finish(&map, robots, robot_count, ...)   the whole-file checks
 *   ... can_run_build(&map, ...) ...
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
#include "urrt_plcin.h"
#include "urrt_rtde_in.h"

#define CAN_MAP_NAME_MAX 32           /* DBC names: C identifiers of at most 32 characters */
#define CAN_MAP_UNIT_MAX 24
#define CAN_MAP_HEARTBEAT_NAME "urrt_heartbeat"
#define CAN_MAP_ALIVE_NAME "alive_counter"
#define CAN_MAP_VALID_NAME "valid"
#define CAN_MAP_ALIVE_BITS 4u
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
    CAN_MAP_ROLE_VALID,      /* the frame's validity bit (1 = valid) */
    CAN_MAP_ROLE_RTDE        /* an element of an RTDE-only value (output_int_register_24, ...):
                                its robot has source = rtde, its value the package's (rtde_only.h) */
};

/* What a signal of the table carries; sigs[i] and meta[i] go together. */
struct can_map_signal {
    char name[CAN_MAP_NAME_MAX + 1];
    char unit[CAN_MAP_UNIT_MAX + 1];
    enum can_map_role role;
    int field;               /* urrt_field_id for CAN_MAP_ROLE_FIELD */
    int var;                 /* urrt_rtde_var for CAN_MAP_ROLE_RTDE */
    unsigned elem;
    bool bitmask;            /* field coded as a bit mask (unit "bits"): its bits sent as they are,
                                never scaled or clamped (sigs[i] has URRT_CAN_SIG_MASK(first)) */
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

/* Keys of an [input NAME] section: a frame the gateway receives, whose
 * signals write a robot's input registers over RTDE. Its places in key_loc
 * are its own; the first four are the [frame] keys' (id, extended, fd,
 * length), so that the checks of both read them alike. */
enum can_map_input_key {
    CAN_MAP_IK_ID = CAN_MAP_FK_ID, CAN_MAP_IK_EXTENDED = CAN_MAP_FK_EXTENDED, CAN_MAP_IK_FD = CAN_MAP_FK_FD,
    CAN_MAP_IK_LENGTH = CAN_MAP_FK_LENGTH, CAN_MAP_IK_ROBOT, CAN_MAP_IK_TIMEOUT, CAN_MAP_IK_ON_SILENCE,
    CAN_MAP_IK_COMMENT, CAN_MAP_IK_SIGNAL, CAN_MAP_IK_COUNT
};

struct can_map_frame {
    char name[CAN_MAP_NAME_MAX + 1];
    bool input;                             /* an [input NAME]: received, its signals input registers */
    char comment[128];
    struct can_map_loc loc;                 /* the section's header */
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
    /* An [input]'s: */
    uint32_t timeout_ms;                    /* silent longer than this: on_silence */
    urrt_plcin_silence silence;             /* when the PLC falls silent (lib/urrt_plcin.h) */
    double silence_value;                   /* URRT_PLCIN_VALUE's */
    /* Its input recipe, set by can_map_finish: the registers its signals
     * write, each once, in the order of their first signal. */
    uint16_t regs[URRT_RTDE_IN_MAX_VARS];
    size_t reg_count;
};

/* Keys of the [can] section. */
enum can_map_can_key {
    CAN_MAP_CK_INTERFACE, CAN_MAP_CK_FD, CAN_MAP_CK_BITRATE, CAN_MAP_CK_DATA_BITRATE,
    CAN_MAP_CK_MAX_LOAD, CAN_MAP_CK_HB_ID, CAN_MAP_CK_HB_EXTENDED, CAN_MAP_CK_HB_PERIOD,
    CAN_MAP_CK_HB_ROBOT, CAN_MAP_CK_STALE_AFTER, CAN_MAP_CK_GENERATION, CAN_MAP_CK_NODE,
    CAN_MAP_CK_RECEIVER, CAN_MAP_CK_INPUTS_MIN_RATE, CAN_MAP_CK_COUNT
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

/* The keys of [can], [frame NAME] and [input NAME], in the order of their enums. */
extern const struct conf_key can_map_can_keys[CAN_MAP_CK_COUNT];
extern const struct conf_key can_map_frame_keys[CAN_MAP_FK_COUNT];
extern const struct conf_key can_map_input_keys[CAN_MAP_IK_COUNT];

/* Traffic the bus carries beside the map's frames and its heartbeat, which
 * another front end adds before can_map_finish (canopen_map: the CANopen
 * node's heartbeat, EMCY and SDO): counted in the worst-case bus load and
 * named, part by part, where the load is printed. */
#define CAN_MAP_TRAFFIC_MAX 4
struct can_map_traffic {
    const char *name;                       /* "heartbeat", "EMCY", ...: a string that outlives the map */
    unsigned len;                           /* data bytes of each frame: classic, 11-bit id */
    double per_second;                      /* frames a second, at most */
    double load;                            /* its share of the bus, set by can_map_finish */
};

/* Receives each problem can_map_finish finds, as file, line and reason
 * (without "FILE:LINE: "), for a caller with its own error list. */
typedef void (*can_map_report_fn)(void *ctx, const char *file, int line, const char *reason);

struct can_map {
    can_map_report_fn reporter;             /* optional, see can_map_set_reporter */
    void *reporter_ctx;
    bool configured;                        /* a [can] key or a [frame] section was seen */
    bool finished;
    /* [can] */
    struct can_map_loc can_loc;             /* the [can] header */
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
    char receiver[CAN_MAP_NAME_MAX + 1];    /* DBC receiver of every signal; the [input]s' transmitter */
    double inputs_min_rate_hz;              /* fresh input registers are sent at least this often */
    /* [frame NAME] */
    struct can_map_frame *frames;
    size_t frame_count;
    size_t frame_capacity;
    /* [input NAME] */
    struct can_map_frame *inputs;
    size_t input_count;
    size_t input_capacity;
    /* Robots (copied by can_map_finish). */
    struct can_map_robot_rt *robots;
    size_t robot_count;
    double load;                            /* worst-case bus load, 0.5 = 50 % (heartbeat, traffic included) */
    double hb_load;
    double frames_load;                     /* the frames' share of load */
    /* The load's parts as printed: the frames, the heartbeat frame, then the traffic. */
    const char *frames_name;                /* "frames" (canopen_map: "TPDOs") */
    const char *hb_name;                    /* "heartbeat" (canopen_map: "status TPDO") */
    struct can_map_traffic traffic[CAN_MAP_TRAFFIC_MAX];
    size_t traffic_count;
    /* File names seen, each stored once (struct can_map_loc points here). */
    char **files;
    size_t file_count;
    /* What can_map_finish noticed in a valid map, as "FILE:LINE: text". */
    char **notices;
    size_t notice_count;
};

/* An empty map with the keys' defaults (can_map_can_keys' def). */
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
struct can_map_frame *can_map_input_begin(struct can_map *map, const char *name, struct conf_at at, char *why,
                                          size_t n);
bool can_map_set(struct can_map *map, struct can_map_frame *frame, const struct conf_key *key, const char *value,
                 struct conf_at at, char *why, size_t n);

/*
 * Checks that need the whole file and the gateway's robots: overlaps and
 * lengths, duplicate and out-of-range ids (heartbeat and [input]s
 * included), robot names, periods faster than a robot sends, worst-case bus
 * load; an [input]'s timeout, its registers (each written by one signal of
 * one frame, bit masks by disjoint bits=, at most URRT_RTDE_IN_MAX_VARS of
 * them, on_silence's value one each register takes). Resolves robot names,
 * computes loads and the [input]s' recipes (regs). Returns 0, or -1 with every problem found
 * in err as "FILE:LINE: reason" lines separated by '\n' (as many as fit).
 * A map with no CAN configuration at all finishes with 0 and stays
 * disabled (can_map_enabled() false).
 */
int can_map_finish(struct can_map *map, const struct can_map_robot *robots, size_t robot_count, char *err,
                   size_t errlen);

bool can_map_enabled(const struct can_map *map);

/*
 * Notices of a finished map: what a valid configuration does that its
 * author may not mean, for --check-config and the log at start (level
 * notice). Today: the bits of a bit-mask field that UR defines and no
 * signal of a robot carries, with their meaning, e.g. "t.ini:9:
 * digital_input_bits: bits 16-17 (tool inputs) are not carried (bits=16-17
 * in a signal would carry them)". Each is "FILE:LINE: text"; i below
 * can_map_notice_count().
 */
size_t can_map_notice_count(const struct can_map *map);
const char *can_map_notice(const struct can_map *map, size_t i);

/* The ids the [input]s are received on, for the link's filter: a 29-bit
 * one with URRT_CANLINK_RX_EXTENDED. At most max; returns how many. */
size_t can_map_input_ids(const struct can_map *map, uint32_t *ids, size_t max);

/* The [input] a received frame is (same id, same kind of id), or NULL. */
const struct can_map_frame *can_map_input_of(const struct can_map *map, uint32_t id, bool extended);

/* The CAN link's configuration from [can]: interface, fd, and fd_brs (FD
 * frames switch to data_bitrate when it is above bitrate). cfg must hold
 * urrt_canlink_config_defaults() first; the other fields are left alone. The
 * interface string stays owned by the map. Bit rates are not set on the
 * interface (ip link does that): the map uses them for the bus load check
 * and the DBC. */
void can_map_link_config(const struct can_map *map, urrt_canlink_config *cfg);

/* Adds traffic beside the map's frames (see struct can_map_traffic), before
 * can_map_finish. false when CAN_MAP_TRAFFIC_MAX parts are there already. */
bool can_map_add_traffic(struct can_map *map, const char *name, unsigned len, double per_second);

/* One line for --check-config and the log at start: "4 frames + heartbeat
 * 0x705 on can0, worst-case bus load 7.6% of 500000 bit/s (max 40%): frames
 * 7.43% + heartbeat 0.14%", the traffic's parts after the heartbeat's.
 * Returns snprintf's. */
int can_map_describe(const struct can_map *map, char *buf, size_t size);

/* Worst-case bus time of one frame in microseconds at the map's bit rates. */
double can_map_frame_time_us(const struct can_map *map, unsigned len, bool extended, bool fd);

#endif /* URRT_GATEWAY_CAN_MAP_H */
