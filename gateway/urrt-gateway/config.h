/* SPDX-License-Identifier: MIT */
/*
 * config.h: the urrt-gateway configuration file.
 *
 * An INI file, each line read once by config.c's own reader (a byte order
 * mark, blank lines, ';' and '#' comments, "[KIND NAME]" headers, "key =
 * value"). Sections are dispatched through a table of sections, each with a
 * table of keys (config.c: config_sections), so an output such as CAN adds
 * its sections ("[can]", "[frame NAME]") with one entry and a member of
 * gw_config for its values. A key's default, bounds and help are its table
 * entry's (conf.h). Values are read by the parsers of conf.h, the same for
 * every section and command line. Every error is reported as "FILE:LINE:
 * reason"; an unknown section or key is an error, because a typo must not
 * be silently ignored. Parsing allocates; nothing after startup does.
 */
#ifndef URRT_GATEWAY_CONFIG_H
#define URRT_GATEWAY_CONFIG_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "can_map.h"
#include "can_run.h"
#include "canopen_map.h"
#include "co_run.h"
#include "conf.h"
#include "port.h"
#include "urrt_rtde.h"

/* The LCM messages, one channel each per robot: "NAME.SUFFIX". */
typedef enum gw_kind {
    GW_KIND_STATE = 0, /* urrt.state_t: every field of the packet */
    GW_KIND_JOINTS,    /* urrt.joints_t */
    GW_KIND_TOOL,      /* urrt.tool_t */
    GW_KIND_STATUS,    /* urrt.status_t */
    GW_KIND_RTDE,      /* urrt.rtde_t: the RTDE-only values (source = rtde) */
    GW_KIND_GATEWAY,   /* urrt.gateway_t: the gateway's view of the robot */
    GW_KIND_COUNT
} gw_kind;

/* "state", "joints", ...: the key prefix in [lcm]. */
const char *gw_kind_name(gw_kind kind);

typedef enum gw_rate_mode {
    GW_RATE_OFF = 0,
    GW_RATE_EVERY, /* every packet */
    GW_RATE_HZ     /* decimated to hz, on the controller's clock */
} gw_rate_mode;

typedef struct gw_rate {
    gw_rate_mode mode;
    double hz;
} gw_rate;

typedef struct gw_lcm_config {
    char *url;
    int url_line;
    char *channel[GW_KIND_COUNT]; /* suffix after "NAME." */
    int channel_line[GW_KIND_COUNT];
    gw_rate rate[GW_KIND_COUNT];
    int rate_line[GW_KIND_COUNT];
} gw_lcm_config;

/* Where a robot's data comes from. */
typedef enum gw_source {
    GW_SOURCE_REALTIME = 0, /* the RealTime stream, port 30003 */
    GW_SOURCE_RTDE          /* an RTDE recipe, port 30004 (gateway/common/rtde_source.h) */
} gw_source;

typedef struct gw_robot_config {
    char *name;            /* channel prefix */
    int line;              /* of the section header */
    char *host;
    int host_line;
    uint16_t port;         /* 0 until robot_finish: by source when not given */
    int port_line;
    gw_source source;
    int source_line;
    double rtde_frequency; /* Hz; 0: auto, the controller's rate */
    int rtde_frequency_line;
    /* rtde_values: RTDE-only variables published on NAME.RTDE */
    uint16_t rtde_values[URRT_RTDE_MAX_VARS];
    size_t rtde_value_count;
    int rtde_values_line;
    /* The RTDE recipe, built from the whole file (config.c: build_recipes):
     * timestamp, STATE's shared fields (optional: only where the controller
     * has them), the CAN signals' fields and the RTDE-only values. */
    uint16_t recipe[URRT_RTDE_MAX_VARS];
    bool recipe_optional[URRT_RTDE_MAX_VARS];
    size_t recipe_count;
    uint32_t expected_length; /* 0: auto, any length is accepted */
    char *expected;        /* "auto", or the version/length as written */
    unsigned max_rate_hz;  /* 125 for a 1.x/3.x version, else 500 */
    int version_line;
    urrt_link_config link; /* timeouts and backoff; name/host/port filled in */
} gw_robot_config;

#define GW_DEFAULT_LCM_URL "udpm://239.255.76.67:7667?ttl=0"
#define GW_MAX_ROBOTS 64
/* The fastest any controller sends (e-series, 500 Hz): lib's controller table. */
#define GW_ROBOT_MAX_RATE_HZ (1000000u / urrt_period_min_us(0))

typedef struct gw_config {
    const char *path;
    urrt_log_level log_level;
    bool summary;          /* one line per second on stdout */
    char *metrics_file;    /* Prometheus textfile (metrics.h); NULL: none */
    uint32_t metrics_interval_ms;
    gw_lcm_config lcm;
    gw_robot_config *robots;
    unsigned robot_count;
    struct can_map can;    /* [can] and [frame NAME]; disabled when absent */
    struct can_run *can_run; /* can's tables, built with the file; NULL when disabled */
    struct canopen_map co; /* [canopen] and the [frame]s' CANopen keys; disabled when absent */
    struct co_run *co_run; /* the CANopen node over can_run, built with the file; NULL without [canopen] */
} gw_config;

/* Parse a file. Returns the number of errors (0: *cfg is complete and
 * valid, its CAN tables built), each written to err as "FILE:LINE: reason". */
int gw_config_load(gw_config *cfg, const char *path, FILE *err);
/* The same from an open stream (left open), named path in the messages:
 * for a configuration that is not a file, and for the tests, their tools and
 * the fuzz harness, which load configurations as the gateway does. */
int gw_config_load_stream(gw_config *cfg, FILE *in, const char *path, FILE *err);
void gw_config_free(gw_config *cfg);

/* Writes the file grammar and every key, for --help. */
void gw_config_usage(FILE *out);
/* Every key of every section, one per line (conf_key_print), for
 * --print-keys: what check-man holds the documents against. */
void gw_config_print_keys(FILE *out);

/* Parses a log level name ("err", "warning", "notice", "info", "debug"). */
bool gw_parse_log_level(const char *text, urrt_log_level *level);

/*
 * The section table (config.c: config_sections). A section's keys are a
 * table of conf.h keys: the front end sets the keys' defaults, finds the key
 * (an unknown one is an error with a "did you mean" hint), refuses it twice
 * (the one place that rule is written), and parses the value
 * into the section's object, or hands it to set. A handler reports a
 * problem with config_error() and returns false; the parser goes on, so
 * that one run shows every error.
 */
typedef struct config_ctx config_ctx;

typedef struct config_section {
    const char *kind;   /* "robot" matches "[robot NAME]" */
    bool named;         /* the header carries a NAME */
    bool repeatable;    /* may appear more than once (with different names) */
    /* A section header; name is NULL for unnamed sections. May be NULL. */
    bool (*begin)(config_ctx *ctx, gw_config *cfg, const char *name);
    const struct conf_key *keys;
    size_t key_count;
    /* Where the keys write (the current robot, say); NULL when set is given. */
    void *(*object)(config_ctx *ctx, gw_config *cfg);
    /* Parses a key instead of conf_key_set: false with the reason in why. */
    bool (*set)(config_ctx *ctx, gw_config *cfg, const struct conf_key *key, const char *value, char *why, size_t n);
    /* After the whole file: checks across sections. May be NULL. */
    void (*finish)(config_ctx *ctx, gw_config *cfg);
    const char *usage;  /* one line for --help */
    /* Keys another part adds to the section ([frame]'s CANopen keys), handed
     * to set as well; NULL: none. */
    const struct conf_key *more_keys;
    size_t more_key_count;
} config_section;

/* The one error channel: "FILE:LINE: reason", printed at the end, causes
 * (what is wrong on a line) before consequences (what the file then lacks). */
void config_error(config_ctx *ctx, int line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#endif
