/* SPDX-License-Identifier: MIT */
/* can_map: the CAN mapping's keys, signal grammar and whole-file checks.
 * See can_map.h and docs/can.md. */
#include "can_map.h"

#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rtde_only.h"
#include "urrt_co.h"
#include "urrt_rtde.h"

/* ---- reporting ------------------------------------------------------------------- */

/* Reports a problem: to the map's reporter if one is set, and as
 * "FILE:LINE: reason" appended to err ('\n'-separated, as far as it fits). */
static void report(const struct can_map *map, char *err, size_t errlen, struct can_map_loc loc, const char *fmt,
                   va_list ap)
{
    char reason[512];
    size_t used = 0;
    vsnprintf(reason, sizeof reason, fmt, ap);
    if (map != NULL && map->reporter != NULL) {
        map->reporter(map->reporter_ctx, loc.file, loc.line, reason);
    }
    if (err == NULL || errlen == 0) {
        return;
    }
    used = strnlen(err, errlen);
    if (used + 1 >= errlen) {
        return;
    }
    if (used > 0) {
        err[used++] = '\n';
    }
    snprintf(err + used, errlen - used, "%s:%d: %s", loc.file ? loc.file : "?", loc.line, reason);
}

static void add_error(const struct can_map *map, char *err, size_t errlen, struct can_map_loc loc, const char *fmt,
                      ...) __attribute__((format(printf, 5, 6)));

static void add_error(const struct can_map *map, char *err, size_t errlen, struct can_map_loc loc, const char *fmt,
                      ...)
{
    va_list ap;
    va_start(ap, fmt);
    report(map, err, errlen, loc, fmt, ap);
    va_end(ap);
}

static const char *intern_file(struct can_map *map, const char *file)
{
    size_t i;
    char **grown;
    if (file == NULL) {
        file = "?";
    }
    for (i = 0; i < map->file_count; i++) {
        if (strcmp(map->files[i], file) == 0) {
            return map->files[i];
        }
    }
    grown = realloc(map->files, (map->file_count + 1) * sizeof *grown);
    if (grown == NULL) {
        return "?";
    }
    map->files = grown;
    map->files[map->file_count] = strdup(file);
    if (map->files[map->file_count] == NULL) {
        return "?";
    }
    return map->files[map->file_count++];
}

/* ---- life cycle ---------------------------------------------------------------------- */

void can_map_init(struct can_map *map)
{
    memset(map, 0, sizeof *map);
    map->frames_name = "frames";
    map->hb_name = "heartbeat";
    /* The table's defaults parse: test_config checks every table's. */
    (void)conf_key_defaults(can_map_can_keys, CAN_MAP_CK_COUNT, map, NULL, 0);
}

void can_map_free(struct can_map *map)
{
    size_t i;
    for (i = 0; i < map->frame_count; i++) {
        free(map->frames[i].sigs);
        free(map->frames[i].meta);
    }
    free(map->frames);
    for (i = 0; i < map->input_count; i++) {
        free(map->inputs[i].sigs);
        free(map->inputs[i].meta);
    }
    free(map->inputs);
    free(map->robots);
    free(map->interface);
    for (i = 0; i < map->file_count; i++) {
        free(map->files[i]);
    }
    free(map->files);
    for (i = 0; i < map->notice_count; i++) {
        free(map->notices[i]);
    }
    free(map->notices);
    memset(map, 0, sizeof *map);
}

void can_map_set_reporter(struct can_map *map, can_map_report_fn fn, void *ctx)
{
    map->reporter = fn;
    map->reporter_ctx = ctx;
}

bool can_map_enabled(const struct can_map *map)
{
    return map->configured && map->finished;
}

void can_map_link_config(const struct can_map *map, urrt_canlink_config *cfg)
{
    cfg->interface = map->interface;
    cfg->fd = map->fd;
    cfg->fd_brs = map->fd && map->data_bitrate > map->bitrate;
}

bool can_map_add_traffic(struct can_map *map, const char *name, unsigned len, double per_second)
{
    if (map->traffic_count == CAN_MAP_TRAFFIC_MAX) {
        return false;
    }
    map->traffic[map->traffic_count++] = (struct can_map_traffic){name, len, per_second, 0.0};
    return true;
}

/* "frames 7.43% + heartbeat 0.14% + ...": what the load counts, part by part. */
static void load_parts(const struct can_map *map, char *buf, size_t size)
{
    int n = snprintf(buf, size, "%s %.2f%% + %s %.2f%%", map->frames_name, map->frames_load * 100.0, map->hb_name,
                     map->hb_load * 100.0);
    for (size_t i = 0; i < map->traffic_count && n >= 0 && (size_t)n < size; i++) {
        n += snprintf(buf + n, size - (size_t)n, " + %s %.2f%%", map->traffic[i].name, map->traffic[i].load * 100.0);
    }
}

int can_map_describe(const struct can_map *map, char *buf, size_t size)
{
    char parts[256], received[48] = "";
    if (!can_map_enabled(map)) {
        return snprintf(buf, size, "no CAN output configured");
    }
    load_parts(map, parts, sizeof parts);
    if (map->input_count > 0) {
        /* The PLC's frames are its own bus load, not counted here. */
        snprintf(received, sizeof received, " (and %zu [input]%s received)", map->input_count,
                 map->input_count == 1 ? "" : "s");
    }
    return snprintf(buf, size, "%zu frame%s + %s 0x%X on %s%s, worst-case bus load %.1f%% of %u bit/s%s (max %u%%): "
                    "%s", map->frame_count, map->frame_count == 1 ? "" : "s", map->hb_name, (unsigned)map->hb_id,
                    map->interface ? map->interface : "?", received, map->load * 100.0, (unsigned)map->bitrate,
                    map->data_bitrate > map->bitrate ? " with an FD data phase" : "", map->max_load_percent, parts);
}

/* What the DBC says of each heartbeat signal (dbc.c). */
const struct can_map_hb_signal can_map_heartbeat_layout[URRT_CANTX_HB_COUNT] = {
    [URRT_CANTX_HB_STATE] = {"state", "", CAN_MAP_HB_VALUES_STATE,
                          "Gateway state: 0 starting, 1 ok, 2 data stale, 3 robot disconnected"},
    [URRT_CANTX_HB_ALIVE] = {"alive_counter", "", CAN_MAP_HB_VALUES_NONE,
                          "Incremented (modulo 16) with every heartbeat"},
    [URRT_CANTX_HB_ROBOT_MODE] = {"robot_mode", "",
                               CAN_MAP_HB_VALUES_ROBOT_MODE,
                               "Robot mode of the heartbeat robot as it sends it (numbering per generation); "
                               "-128: not available (no data, or older than stale_after_ms)"},
    [URRT_CANTX_HB_SAFETY_MODE] = {"safety_mode", "",
                                CAN_MAP_HB_VALUES_SAFETY_MODE,
                                "Safety mode of the heartbeat robot; 0: not available (1.x, no data, or older "
                                "than stale_after_ms)"},
    [URRT_CANTX_HB_GENERATION] = {"generation", "",
                               CAN_MAP_HB_VALUES_GENERATION,
                               "Controller generation of the heartbeat robot: 0 unknown, 1 CB1/CB2 (1.x), "
                               "3 CB3/e-series (3.x/5.x)"},
    [URRT_CANTX_HB_BUS_OFF] = {"bus_off", "", CAN_MAP_HB_VALUES_FLAG,
                            "The CAN controller went bus-off since the previous heartbeat"},
    [URRT_CANTX_HB_CAN_ERRORS] = {"can_errors", "", CAN_MAP_HB_VALUES_FLAG,
                               "CAN error frames since the previous heartbeat"},
    [URRT_CANTX_HB_CAN_DOWN] = {"can_down", "", CAN_MAP_HB_VALUES_FLAG,
                             "The CAN interface went down since the previous heartbeat"},
    [URRT_CANTX_HB_SEND_ERRORS] = {"send_errors", "",
                                CAN_MAP_HB_VALUES_FLAG, "Frames refused by the CAN link since the previous heartbeat"},
    [URRT_CANTX_HB_TX_DROPPED] = {"tx_dropped", "", CAN_MAP_HB_VALUES_FLAG,
                               "Frames dropped on a full transmit queue since the previous heartbeat"},
    [URRT_CANTX_HB_CLAMPED] = {"clamped", "", CAN_MAP_HB_VALUES_FLAG,
                            "A mapped value saturated or was NaN since the previous heartbeat"},
    [URRT_CANTX_HB_DATA_AGE] = {"data_age", "ms",
                             CAN_MAP_HB_VALUES_NONE,
                             "Age of the heartbeat robot's latest packet, saturated at 65534; 65535: no data yet"},
    [URRT_CANTX_HB_DROPS] = {"drops", "", CAN_MAP_HB_VALUES_NONE,
                          "Frames dropped by the CAN link since start, modulo 65536"},
};

/* ---- [can] ----------------------------------------------------------------------- */


static bool can_interface(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                          size_t n)
{
    struct can_map *map = obj;
    (void)key, (void)at;
    if (value[0] == '\0' || strlen(value) > 255 || (strncmp(value, "log:", 4) == 0 && value[4] == '\0')) {
        return conf_fail(why, n, "interface = '%s': give a CAN interface (can0) or log:PATH (log:- for stdout)", value);
    }
    if (!conf_printable(value, NULL, 0)) {
        return conf_fail(why, n, "interface = '%s': no control characters", value);
    }
    if (strncmp(value, "log:", 4) != 0 && (strlen(value) >= 16 || strpbrk(value, " /\t") != NULL)) {
        return conf_fail(why, n, "interface = '%s' is not an interface name (at most 15 characters, no '/')", value);
    }
    free(map->interface);
    map->interface = strdup(value);
    return map->interface != NULL || conf_fail(why, n, "out of memory");
}

/* heartbeat_robot, and a frame's robot: a name checked against the robots at the end. */
static bool robot_name(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                       size_t n)
{
    char *dst = (char *)obj + key->offset;
    (void)at;
    if (!conf_text(dst, key->size, value, NULL, 0) || dst[0] == '\0') {
        return conf_fail(why, n, "%s = '%s': give a robot name", key->name, value);
    }
    return true;
}

static bool can_generation(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                           size_t n)
{
    struct can_map *map = obj;
    (void)key, (void)at;
    if (strcmp(value, "3") == 0 || strcmp(value, "5") == 0 || strcasecmp(value, "3.x") == 0 ||
        strcasecmp(value, "5.x") == 0) {
        map->generation = URRT_GEN_3X;
    } else if (strcmp(value, "1") == 0 || strcasecmp(value, "1.x") == 0) {
        map->generation = URRT_GEN_1X;
    } else {
        return conf_fail(why, n, "robot_generation = '%s': use 3 (CB3 and e-series, 3.x/5.x) or 1 (CB1/CB2, 1.x)", value);
    }
    return true;
}

/* node, receiver: DBC names. */
static bool dbc_name(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why, size_t n)
{
    (void)at;
    if (!conf_name(value, CONF_NAME_C, CAN_MAP_NAME_MAX, NULL, 0)) {
        return conf_fail(why, n, "%s = '%s': a DBC node name is a C identifier of at most %d characters", key->name, value,
                   CAN_MAP_NAME_MAX);
    }
    snprintf((char *)obj + key->offset, key->size, "%s", value);
    return true;
}

static bool can_inputs_rate(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                            size_t n)
{
    struct can_map *map = obj;
    char reason[CONF_WHY_MAX];
    (void)at;
    return conf_rate_hz(value, key->min, key->max, &map->inputs_min_rate_hz, reason, sizeof reason) ||
           conf_fail(why, n, "%s = '%s': %s (a robot program's rtde_set_watchdog needs updates faster than its "
                     "min_frequency)", key->name, value, reason);
}

#define YES_NO "%1$s = '%2$s': use yes or no"

const struct conf_key can_map_can_keys[CAN_MAP_CK_COUNT] = {
    [CAN_MAP_CK_INTERFACE] = {"interface", CONF_FN, 0, 0, 0, 0, can_interface, NULL, false, "can0|log:PATH", NULL,
                              "required", "the SocketCAN interface, or log:PATH for candump's log format"},
    [CAN_MAP_CK_FD] = {"fd", CONF_BOOL, CONF_FIELD(struct can_map, fd), 0, 0, NULL, YES_NO, false, NULL, "no", NULL,
                       "CAN FD frames may be configured"},
    [CAN_MAP_CK_BITRATE] = {"bitrate", CONF_UINT, CONF_FIELD(struct can_map, bitrate), 10000, 12000000, NULL,
                            "%1$s = '%2$s': give bits per second between 10000 and 12000000 (500000)", false, NULL,
                            "500000", NULL, "arbitration bit rate, bit/s, for the bus load check and the DBC"},
    [CAN_MAP_CK_DATA_BITRATE] = {"data_bitrate", CONF_UINT, CONF_FIELD(struct can_map, data_bitrate), 10000,
                                 12000000, NULL,
                                 "%1$s = '%2$s': give bits per second between 10000 and 12000000 (2000000)", false,
                                 NULL, NULL, "= bitrate", "CAN FD data-phase bit rate"},
    [CAN_MAP_CK_MAX_LOAD] = {"max_bus_load", CONF_UINT, CONF_FIELD(struct can_map, max_load_percent), 1, 100, NULL,
                             "%1$s = '%2$s': give a percentage 1..100", false, NULL, "50", NULL,
                             "worst-case bus load allowed, percent"},
    [CAN_MAP_CK_HB_ID] = {"heartbeat_id", CONF_UINT, CONF_FIELD(struct can_map, hb_id), 0, UINT32_MAX, NULL,
                          "%1$s = '%2$s' is not a number (0x701 or 1793)", false, NULL, NULL, "required",
                          "id of the heartbeat frame (gateway state, modes, data age, drops)"},
    [CAN_MAP_CK_HB_EXTENDED] = {"heartbeat_extended", CONF_BOOL, CONF_FIELD(struct can_map, hb_extended), 0, 0, NULL,
                                YES_NO, false, NULL, "no", NULL, "the heartbeat id is 29-bit"},
    [CAN_MAP_CK_HB_PERIOD] = {"heartbeat_period_ms", CONF_MS, CONF_FIELD(struct can_map, hb_period_ms), 10, 1000,
                              NULL, "%1$s = '%2$s': give 10..1000 ms (the heartbeat goes at least once a second)",
                              false, NULL, "100", NULL, "the heartbeat's period"},
    [CAN_MAP_CK_HB_ROBOT] = {"heartbeat_robot", CONF_FN, CONF_FIELD(struct can_map, hb_robot), 0, 0, robot_name,
                             NULL, false, "NAME", NULL, "the only robot",
                             "robot whose mode, safety mode and data age the heartbeat carries"},
    [CAN_MAP_CK_STALE_AFTER] = {"stale_after_ms", CONF_MS, CONF_FIELD(struct can_map, stale_after_ms), 1, 60000,
                                NULL, "%1$s = '%2$s': give 1..60000 milliseconds", false, NULL, "100", NULL,
                                "data older than this is stale (the frames' default, the heartbeat's state)"},
    [CAN_MAP_CK_GENERATION] = {"robot_generation", CONF_FN, 0, 0, 0, 0, can_generation, NULL, false, "3|1", "3",
                               NULL, "robot-mode numbering of the DBC's value tables (3: CB3, e-series; 1: CB2)"},
    [CAN_MAP_CK_NODE] = {"node", CONF_FN, CONF_FIELD(struct can_map, node), 0, 0, dbc_name, NULL, false, "NAME",
                         "URRT_GATEWAY", NULL, "DBC node name of the gateway"},
    [CAN_MAP_CK_RECEIVER] = {"receiver", CONF_FN, CONF_FIELD(struct can_map, receiver), 0, 0, dbc_name, NULL, false,
                             "NAME", "Vector__XXX", NULL,
                             "DBC receiver of every signal, and the transmitter of the [input]s (Vector__XXX: none)"},
    [CAN_MAP_CK_INPUTS_MIN_RATE] = {"inputs_min_rate", CONF_FN, 0, 1, 1, 500, can_inputs_rate, NULL, false,
                                    "N Hz", "10 Hz", NULL,
                                    "fresh input registers are written at least this often, changed or not"},
};

void can_map_can_begin(struct can_map *map, struct conf_at at)
{
    map->configured = true;
    if (map->can_loc.line == 0) {
        map->can_loc.file = intern_file(map, at.file);
        map->can_loc.line = at.line;
    }
}

/* ---- [frame NAME] ------------------------------------------------------------------ */

/* A frame of either kind by name: DBC message names are unique. */
static struct can_map_frame *frame_named(const struct can_map *map, const char *name)
{
    for (size_t i = 0; i < map->frame_count; i++) {
        if (strcmp(map->frames[i].name, name) == 0) {
            return &map->frames[i];
        }
    }
    for (size_t i = 0; i < map->input_count; i++) {
        if (strcmp(map->inputs[i].name, name) == 0) {
            return &map->inputs[i];
        }
    }
    return NULL;
}

static const char *frame_kind(const struct can_map_frame *f)
{
    return f->input ? "input" : "frame";
}

/* A new [frame NAME] or [input NAME] at the end of its array. */
static struct can_map_frame *new_frame(struct can_map *map, bool input, const char *name, struct conf_at at,
                                       char *why, size_t n)
{
    const char *kind = input ? "input" : "frame";
    struct can_map_frame *f = frame_named(map, name);
    struct can_map_frame **frames = input ? &map->inputs : &map->frames;
    size_t *count = input ? &map->input_count : &map->frame_count;
    size_t *capacity = input ? &map->input_capacity : &map->frame_capacity;
    map->configured = true;
    if (!conf_name(name, CONF_NAME_C, CAN_MAP_NAME_MAX, NULL, 0)) {
        conf_fail(why, n, "[%s %s]: the frame name is its DBC name, a C identifier of at most %d characters", kind,
                  name, CAN_MAP_NAME_MAX);
        return NULL;
    }
    if (strcmp(name, CAN_MAP_HEARTBEAT_NAME) == 0) {
        conf_fail(why, n, "[%s %s]: that name is the heartbeat's", kind, CAN_MAP_HEARTBEAT_NAME);
        return NULL;
    }
    if (f != NULL && f->input == input) {
        conf_fail(why, n, "[%s %s] is already defined at line %d: frame names must be unique (the DBC names each "
                  "message)", kind, name, f->loc.line);
        return NULL;
    }
    if (f != NULL) {
        conf_fail(why, n, "[%s %s]: [%s %s] is already defined at line %d: frame names must be unique (the DBC "
                  "names each message)", kind, name, frame_kind(f), name, f->loc.line);
        return NULL;
    }
    if (*count == *capacity) {
        size_t cap = *capacity ? 2 * *capacity : 8;
        struct can_map_frame *grown = realloc(*frames, cap * sizeof *grown);
        if (grown == NULL) {
            conf_fail(why, n, "out of memory");
            return NULL;
        }
        *frames = grown;
        *capacity = cap;
    }
    f = &(*frames)[(*count)++];
    memset(f, 0, sizeof *f);
    snprintf(f->name, sizeof f->name, "%s", name);
    f->input = input;
    f->loc.file = intern_file(map, at.file);
    f->loc.line = at.line;
    if (input) {
        (void)conf_key_defaults(can_map_input_keys, CAN_MAP_IK_COUNT, f, NULL, 0);
    } else {
        (void)conf_key_defaults(can_map_frame_keys, CAN_MAP_FK_COUNT, f, NULL, 0);
    }
    f->alive_index = -1;
    f->valid_index = -1;
    return f;
}

struct can_map_frame *can_map_frame_begin(struct can_map *map, const char *name, struct conf_at at, char *why,
                                          size_t n)
{
    return new_frame(map, false, name, at, why, n);
}

struct can_map_frame *can_map_input_begin(struct can_map *map, const char *name, struct conf_at at, char *why,
                                          size_t n)
{
    return new_frame(map, true, name, at, why, n);
}

static int add_signal(struct can_map_frame *f, const urrt_can_signal *sig, const struct can_map_signal *meta)
{
    if (f->count == f->capacity) {
        size_t cap = f->capacity ? 2 * f->capacity : 8;
        urrt_can_signal *s = realloc(f->sigs, cap * sizeof *s);
        struct can_map_signal *m;
        if (s == NULL) {
            return -1;
        }
        f->sigs = s;
        m = realloc(f->meta, cap * sizeof *m);
        if (m == NULL) {
            return -1;
        }
        f->meta = m;
        f->capacity = cap;
    }
    f->sigs[f->count] = *sig;
    f->meta[f->count] = *meta;
    f->count++;
    return (int)(f->count - 1);
}

static int signal_named(const struct can_map_frame *f, const char *name)
{
    size_t i;
    for (i = 0; i < f->count; i++) {
        if (strcmp(f->meta[i].name, name) == 0) {
            return (int)i;
        }
    }
    return -1;
}

/* Splits a signal line into words; a word may hold a double-quoted part
 * with spaces (unit="N m"). Returns the number of words or -1. */
#define SIGNAL_MAX_WORDS 16
static int split_words(char *line, char **words)
{
    int n = 0;
    char *p = line;
    for (;;) {
        bool quoted = false;
        while (isspace((unsigned char)*p)) {
            p++;
        }
        if (*p == '\0') {
            return n;
        }
        if (n == SIGNAL_MAX_WORDS) {
            return -1;
        }
        words[n++] = p;
        while (*p != '\0' && (quoted || !isspace((unsigned char)*p))) {
            quoted ^= *p == '"';
            p++;
        }
        if (quoted) {
            return -1;
        }
        if (*p != '\0') {
            *p++ = '\0';
        }
    }
}

/* Unit of element elem of a field: the table writes "m, rad" for a pose,
 * i.e. the first three elements in m and the last three in rad. */
static void field_unit(const char *unit, unsigned count, unsigned elem, char *out, size_t size)
{
    const char *comma = strstr(unit, ", ");
    if (strcmp(unit, "enum") == 0 || strcmp(unit, "bits") == 0) {
        unit = "";
    }
    if (comma != NULL && count == 6) {
        if (elem < 3) {
            snprintf(out, size, "%.*s", (int)(comma - unit), unit);
        } else {
            snprintf(out, size, "%s", comma + 2);
        }
        return;
    }
    snprintf(out, size, "%s", unit);
}

/* A signal line as it is read, word by word. */
struct signal_parse {
    urrt_can_signal sig;
    struct can_map_signal meta;
    const char *value;      /* the field's or the RTDE-only value's name */
    unsigned count;         /* its elements */
    const char *unit;       /* its unit as the tables write it ("m, rad", "bits") */
    char rtde_name[URRT_RTDE_NAME_MAX];
    int order;              /* URRT_CAN_INTEL/MOTOROLA, -1: not given */
    int type;               /* URRT_CAN_UNSIGNED..., -1: not given */
    bool have_min, have_max, have_name, have_unit, have_invalid, have_factor, have_offset, have_bits;
    int64_t invalid;
    uint32_t length;        /* as written, checked once the frame and signal can be named */
    uint32_t first_bit, last_bit; /* bits=FIRST-LAST of a bit mask */
};

#define SIGNAL_GRAMMAR \
    "signal = FIELD[ELEM] @START|LENGTH intel|motorola unsigned|signed|float32|float64 " \
    "[factor=F] [offset=O] [min=A] [max=B] [unit=U] [name=N] [invalid=RAW] [bits=FIRST-LAST]"

/* What FIELD names: a robot field (by its RealTime or RTDE name: actual_q
 * is q_actual), or an RTDE-only value, which its robot's RTDE session reads
 * (config.c refuses it on a realtime robot). */
static bool signal_value(struct signal_parse *s, const char *word, size_t name_len, char *why, size_t n)
{
    int fid = urrt_field_find(word, name_len);
    int var = fid < 0 ? urrt_rtde_var_find(word, name_len) : -1;
    if (fid < 0 && var >= 0 && urrt_rtde_var_field(var) >= 0) {
        fid = urrt_rtde_var_field(var);
    }
    if (fid >= 0) {
        const urrt_field_info *info = urrt_field((urrt_field_id)fid);
        s->meta.field = fid;
        s->value = info->name;
        s->count = info->count;
        s->unit = info->unit;
    } else if (rtde_only(var)) {
        s->meta.role = CAN_MAP_ROLE_RTDE;
        s->meta.field = -1;
        s->meta.var = var;
        (void)urrt_rtde_var_name(var, s->rtde_name, sizeof s->rtde_name);
        s->value = s->rtde_name;
        s->count = rtde_only_elements(var);
        s->unit = rtde_only_unit(var);
    } else {
        return conf_fail(why, n, "signal: no field '%.*s' (field names as in docs/protocol.md: q_actual, tcp_force, "
                   "robot_mode, ...; RTDE-only values by their RTDE names: output_int_register_24, ...)",
                   (int)name_len, word);
    }
    s->meta.bitmask = strcmp(s->unit, "bits") == 0;
    return true;
}

/* FIELD or FIELD[ELEM] */
static bool signal_field(struct signal_parse *s, const char *word, char *why, size_t n)
{
    const char *bracket = strchr(word, '[');
    size_t name_len = bracket ? (size_t)(bracket - word) : strlen(word);
    char reason[CONF_WHY_MAX];
    if (!signal_value(s, word, name_len, why, n)) {
        return false;
    }
    if (bracket != NULL) {
        size_t blen = strlen(bracket);
        char num[16];
        uint32_t e;
        if (blen < 3 || bracket[blen - 1] != ']' || blen - 2 >= sizeof num) {
            return conf_fail(why, n, "signal: '%s': write FIELD[ELEM], e.g. q_actual[0]", word);
        }
        snprintf(num, sizeof num, "%.*s", (int)(blen - 2), bracket + 1);
        if (!conf_u32(num, 0, UINT32_MAX, &e, reason, sizeof reason)) {
            return conf_fail(why, n, "signal: '%s': the element is a number: %s", word, reason);
        }
        if (e >= s->count) {
            return conf_fail(why, n, "signal: %s has %u element%s: %s[%u] is out of range (0..%u)", s->value,
                       s->count, s->count == 1 ? "" : "s", s->value, (unsigned)e, s->count - 1);
        }
        s->meta.elem = e;
    } else if (s->count > 1) {
        return conf_fail(why, n, "signal: %s has %u elements: write %s[0] .. %s[%u]", s->value, s->count, s->value,
                   s->value, s->count - 1);
    }
    return true;
}

/* @START|LENGTH */
static bool signal_place(struct signal_parse *s, const char *word, char *why, size_t n)
{
    char buf[32];
    char *bar;
    uint32_t start, length;
    if (word[0] != '@' || strlen(word) >= sizeof buf) {
        return conf_fail(why, n, "signal: '%s': expected @START|LENGTH, e.g. @0|16", word);
    }
    snprintf(buf, sizeof buf, "%s", word + 1);
    bar = strchr(buf, '|');
    if (bar == NULL) {
        return conf_fail(why, n, "signal: '%s': expected @START|LENGTH, e.g. @0|16", word);
    }
    *bar = '\0';
    if (!conf_u32(buf, 0, UINT32_MAX, &start, NULL, 0) || !conf_u32(bar + 1, 0, UINT32_MAX, &length, NULL, 0)) {
        return conf_fail(why, n, "signal: '%s': expected @START|LENGTH, e.g. @0|16 (decimal bit numbers)", word);
    }
    if (start >= 8 * URRT_CAN_MAX_LEN) {
        return conf_fail(why, n, "signal: start bit %u: give 0..511", (unsigned)start);
    }
    s->sig.start = (uint16_t)start;
    s->length = length;
    s->sig.length = length <= 64 ? (uint8_t)length : 0;
    return true;
}

/* intel|motorola, unsigned|signed|float32|float64 */
static bool signal_word(struct signal_parse *s, const char *w, char *why, size_t n)
{
    static const struct { const char *word; bool is_order; int value; } words[] = {
        {"intel", true, URRT_CAN_INTEL}, {"motorola", true, URRT_CAN_MOTOROLA},
        {"unsigned", false, URRT_CAN_UNSIGNED}, {"signed", false, URRT_CAN_SIGNED},
        {"float32", false, URRT_CAN_FLOAT32}, {"float64", false, URRT_CAN_FLOAT64},
    };
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++) {
        if (strcmp(w, words[i].word) == 0) {
            int *slot = words[i].is_order ? &s->order : &s->type;
            if (*slot >= 0) {
                return conf_fail(why, n, "signal: '%s': %s given twice", w, words[i].is_order ? "byte order" : "type");
            }
            *slot = words[i].value;
            return true;
        }
    }
    return conf_fail(why, n, "signal: unknown word '%s': expected intel|motorola, unsigned|signed|float32|float64 "
               "or factor=, offset=, min=, max=, unit=, name=, invalid=, bits=", w);
}

/* factor=, offset=, min=, max= */
static bool signal_number(struct signal_parse *s, const char *k, const char *v, char *why, size_t n)
{
    double d;
    if (!conf_number(v, -DBL_MAX, DBL_MAX, &d, NULL, 0)) {
        return conf_fail(why, n, "signal: %s = '%s' is not a finite number", k, v);
    }
    if (strcmp(k, "factor") == 0) {
        if (d == 0.0) {
            return conf_fail(why, n, "signal: factor must not be 0");
        }
        s->sig.factor = d;
        s->have_factor = true;
    } else if (strcmp(k, "offset") == 0) {
        s->sig.offset = d;
        s->have_offset = true;
    } else if (strcmp(k, "min") == 0) {
        s->sig.min = d;
        s->have_min = true;
    } else {
        s->sig.max = d;
        s->have_max = true;
    }
    return true;
}

/* bits=FIRST-LAST or bits=BIT: which bits of a bit mask the signal carries. */
static bool signal_bits(struct signal_parse *s, const char *v, char *why, size_t n)
{
    char first[16];
    const char *dash = strchr(v, '-');
    size_t len = dash != NULL ? (size_t)(dash - v) : strlen(v);
    if (len == 0 || len >= sizeof first) {
        return conf_fail(why, n, "signal: bits = '%s': give the mask's bits as FIRST-LAST (16-17) or one BIT", v);
    }
    snprintf(first, sizeof first, "%.*s", (int)len, v);
    if (!conf_u32(first, 0, 63, &s->first_bit, NULL, 0) ||
        !conf_u32(dash != NULL ? dash + 1 : first, s->first_bit, 63, &s->last_bit, NULL, 0)) {
        return conf_fail(why, n,
                         "signal: bits = '%s': give FIRST-LAST with 0 <= FIRST <= LAST <= 63 (16-17), or one BIT", v);
    }
    s->have_bits = true;
    return true;
}

/* KEY=VALUE */
static bool signal_option(struct signal_parse *s, char *w, char *eq, char *why, size_t n)
{
    const char *k = w, *v = eq + 1;
    char reason[CONF_WHY_MAX];
    *eq = '\0';
    if (strcmp(k, "factor") == 0 || strcmp(k, "offset") == 0 || strcmp(k, "min") == 0 || strcmp(k, "max") == 0) {
        return signal_number(s, k, v, why, n);
    }
    if (strcmp(k, "unit") == 0) {
        s->have_unit = true;
        return conf_text(s->meta.unit, sizeof s->meta.unit, v, NULL, 0) ||
               conf_fail(why, n, "signal: unit '%s': at most %d characters, no '\"', '\\' or control characters", v,
                   CAN_MAP_UNIT_MAX);
    }
    if (strcmp(k, "name") == 0) {
        if (!conf_name(v, CONF_NAME_C, CAN_MAP_NAME_MAX, NULL, 0)) {
            return conf_fail(why, n, "signal: name '%s': a DBC signal name is a C identifier of at most %d characters", v,
                       CAN_MAP_NAME_MAX);
        }
        snprintf(s->meta.name, sizeof s->meta.name, "%s", v);
        s->have_name = true;
        return true;
    }
    if (strcmp(k, "bits") == 0) {
        return signal_bits(s, v, why, n);
    }
    if (strcmp(k, "invalid") == 0) {
        s->have_invalid = true;
        if (!conf_int(v, INT64_MIN, INT64_MAX, &s->invalid, reason, sizeof reason)) {
            return conf_fail(why, n, "signal: invalid = '%s' is not an integer raw value: %s", v, reason);
        }
        return true;
    }
    return conf_fail(why, n, "signal: unknown option '%s=': expected factor=, offset=, min=, max=, unit=, name=, "
               "invalid=, bits=", k);
}

/* min=, max= against what the type and scaling can carry. */
static bool signal_limits(struct signal_parse *s, char *why, size_t n)
{
    urrt_can_signal bare = s->sig;
    bool is_float = s->type == URRT_CAN_FLOAT32 || s->type == URRT_CAN_FLOAT64;
    /* Half a raw step of slack, so that min=-3276.8 passes for a signed
     * 16-bit signal with factor 0.1 however the product rounds. */
    double slack = is_float ? 0 : fabs(s->sig.factor) / 2;
    double lo, hi;
    bare.min = bare.max = 0;
    if (urrt_can_signal_range(&bare, &lo, &hi) < 0) {
        return conf_fail(why, n, "signal: invalid scaling");
    }
    if (s->have_min && s->sig.min < lo - slack) {
        return conf_fail(why, n, "signal: min=%.17g is below what the signal can carry (%.17g)", s->sig.min, lo);
    }
    if (s->have_max && s->sig.max > hi + slack) {
        return conf_fail(why, n, "signal: max=%.17g is above what the signal can carry (%.17g)", s->sig.max, hi);
    }
    s->sig.min = s->have_min ? s->sig.min : lo;
    s->sig.max = s->have_max ? s->sig.max : hi;
    if (s->sig.min > s->sig.max) {
        return conf_fail(why, n, "signal: min=%.17g is above max=%.17g", s->sig.min, s->sig.max);
    }
    return true;
}

/* invalid=RAW: a negative value for a signed signal, else the raw bit
 * pattern (0x8000 for a signed 16-bit signal is its most negative value). */
static bool signal_invalid(struct signal_parse *s, char *why, size_t n)
{
    unsigned length = s->sig.length;
    uint64_t mask = length >= 64 ? UINT64_MAX : (UINT64_C(1) << length) - 1;
    if (!s->have_invalid) {
        return true;
    }
    if (s->type == URRT_CAN_FLOAT32 || s->type == URRT_CAN_FLOAT64) {
        return conf_fail(why, n, "signal: invalid= applies to integer signals (float signals send NaN)");
    }
    if (s->invalid < 0) {
        int64_t lowest = length >= 64 ? INT64_MIN : -((int64_t)1 << (length - 1));
        if (s->type != URRT_CAN_SIGNED || s->invalid < lowest) {
            return conf_fail(why, n, "signal: invalid=%lld does not fit %u %s bits", (long long)s->invalid, length,
                       s->type == URRT_CAN_SIGNED ? "signed" : "unsigned");
        }
    } else if (((uint64_t)s->invalid & ~mask) != 0) {
        return conf_fail(why, n, "signal: invalid=%lld does not fit %u bits", (long long)s->invalid, length);
    }
    s->sig.invalid_raw = (uint64_t)s->invalid & mask;
    s->sig.flags |= URRT_CAN_SIG_INVALID_RAW;
    return true;
}

/* A field whose unit is "bits" is a bit mask, whatever its name: its bits go
 * out as they are (lib/urrt_can.h, "Bit masks"), so nothing may scale or
 * limit them. bits= picks which of them the signal carries. */
static bool signal_mask(struct signal_parse *s, char *why, size_t n)
{
    static const char *const types[] = {"unsigned", "signed", "float32", "float64"};
    const char *field = s->value;
    unsigned first = s->have_bits ? s->first_bit : 0;
    if (!s->meta.bitmask) {
        return !s->have_bits ||
               conf_fail(why, n, "signal: bits= is for bit masks (fields of unit bits, such as digital_input_bits), "
                         "not %s", field);
    }
    if (s->have_factor || s->have_offset || s->have_min || s->have_max) {
        const char *key = s->have_factor ? "factor=" : s->have_offset ? "offset=" : s->have_min ? "min=" : "max=";
        return conf_fail(why, n, "signal: %s is a bit mask, sent bit for bit: remove %s (bits=FIRST-LAST picks "
                         "which bits)", field, key);
    }
    if (s->type != URRT_CAN_UNSIGNED) {
        return conf_fail(why, n, "signal: %s is a bit mask: its type is unsigned, not %s", field, types[s->type]);
    }
    if (s->have_bits && s->last_bit - s->first_bit + 1 != s->sig.length) {
        unsigned count = (unsigned)(s->last_bit - s->first_bit + 1);
        return conf_fail(why, n, "signal: bits=%u-%u %s %u bit%s, but the signal has %u: make them agree",
                         (unsigned)s->first_bit, (unsigned)s->last_bit, count == 1 ? "is" : "are", count,
                         count == 1 ? "" : "s", (unsigned)s->sig.length);
    }
    s->sig.flags |= (uint8_t)URRT_CAN_SIG_MASK(first);
    return true;
}

/* The words after FIELD and @START|LENGTH, then the checks between them. */
static bool signal_rest(struct signal_parse *s, char **words, int nwords, char *why, size_t n)
{
    for (int i = 2; i < nwords; i++) {
        char *eq = strchr(words[i], '=');
        if (!(eq == NULL ? signal_word(s, words[i], why, n) : signal_option(s, words[i], eq, why, n))) {
            return false;
        }
    }
    if (s->order < 0) {
        return conf_fail(why, n, "signal: byte order missing: add intel (little-endian) or motorola (big-endian)");
    }
    if (s->type < 0) {
        return conf_fail(why, n, "signal: type missing: add unsigned, signed, float32 or float64");
    }
    s->sig.byte_order = (uint8_t)s->order;
    s->sig.type = (uint8_t)s->type;
    if (!signal_mask(s, why, n)) {
        return false;
    }
    if ((s->type == URRT_CAN_FLOAT32 && s->sig.length != 32) || (s->type == URRT_CAN_FLOAT64 && s->sig.length != 64)) {
        return conf_fail(why, n, "signal: %s needs length %d, not %u", s->type == URRT_CAN_FLOAT32 ? "float32" : "float64",
                   s->type == URRT_CAN_FLOAT32 ? 32 : 64, (unsigned)s->sig.length);
    }
    return signal_limits(s, why, n) && signal_invalid(s, why, n);
}

/* RTDE inputs other than the general purpose registers: each acts on
 * hardware (speed, outputs, a force) with no robot program deciding, so no
 * [input] writes one. Named here for the reason; urrt_rtde_in_writable is
 * the rule. */
static const char *const hardware_inputs[] = {
    "speed_slider_mask", "speed_slider_fraction", "standard_digital_output_mask", "standard_digital_output",
    "configurable_digital_output_mask", "configurable_digital_output", "tool_digital_output_mask",
    "tool_digital_output", "standard_analog_output_mask", "standard_analog_output_type", "standard_analog_output_0",
    "standard_analog_output_1", "external_force_torque",
};

#define WRITABLE_REGISTERS \
    "input_int_register_N, input_double_register_N (N 0..47), input_bit_register_N (N 64..127), " \
    "input_bit_registers0_to_31, input_bit_registers32_to_63"

/* Before an [input]'s signal is parsed: a hardware input, refused with why. */
static bool input_hardware(const char *word, char *why, size_t n)
{
    size_t len = strcspn(word, "[");
    for (size_t i = 0; i < sizeof hardware_inputs / sizeof hardware_inputs[0]; i++) {
        if (strlen(hardware_inputs[i]) == len && strncmp(word, hardware_inputs[i], len) == 0) {
            return conf_fail(why, n, "signal: %s is an RTDE input that acts on the robot's hardware with no robot "
                             "program deciding: urrt never writes it; an [input] writes only general purpose "
                             "input registers (" WRITABLE_REGISTERS ")", hardware_inputs[i]);
        }
    }
    return true;
}

/* An [input]'s signal, parsed: a writable register, received as the PLC sends it. */
static bool input_signal(const struct signal_parse *s, char *why, size_t n)
{
    if (s->meta.role != CAN_MAP_ROLE_RTDE || !urrt_rtde_in_writable(s->meta.var)) {
        return conf_fail(why, n, "signal: %s is not an input register: an [input] writes only general purpose input "
                         "registers (" WRITABLE_REGISTERS "); a value the robot sends goes in a [frame]", s->value);
    }
    if (s->have_invalid) {
        return conf_fail(why, n, "signal: invalid= is for frames the gateway sends; an [input]'s value outside "
                         "min..max is refused and counted");
    }
    return true;
}

static bool frame_signal(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                         size_t n)
{
    struct can_map_frame *f = obj;
    char line[512];
    char *words[SIGNAL_MAX_WORDS];
    int nwords, other;
    struct signal_parse s;
    (void)key;
    if (strlen(value) >= sizeof line) {
        return conf_fail(why, n, "signal line too long");
    }
    snprintf(line, sizeof line, "%s", value);
    nwords = split_words(line, words);
    if (nwords < 0) {
        return conf_fail(why, n, "signal: unbalanced quotes or more than %d words", SIGNAL_MAX_WORDS);
    }
    if (nwords < 4) {
        return conf_fail(why, n, "signal = '%s': expected %s", value, SIGNAL_GRAMMAR);
    }
    memset(&s, 0, sizeof s);
    s.order = s.type = -1;
    s.sig.factor = 1.0;
    s.meta.role = CAN_MAP_ROLE_FIELD;
    s.meta.loc.file = at.file;
    s.meta.loc.line = at.line;
    if ((f->input && !input_hardware(words[0], why, n)) || !signal_field(&s, words[0], why, n) ||
        !signal_place(&s, words[1], why, n)) {
        return false;
    }
    if (s.length < 1 || s.length > 64) {
        return conf_fail(why, n, "[%s %s] signal '%s': length %u: give 1..64 bits", frame_kind(f), f->name, words[0],
                         (unsigned)s.length);
    }
    if (!signal_rest(&s, words, nwords, why, n) || (f->input && !input_signal(&s, why, n))) {
        return false;
    }
    if (!s.have_unit) {
        field_unit(s.unit, s.count, s.meta.elem, s.meta.unit, sizeof s.meta.unit);
    }
    if (!s.have_name) {
        char name[URRT_RTDE_NAME_MAX + 8];
        if (s.count > 1) {
            snprintf(name, sizeof name, "%s_%u", s.value, s.meta.elem);
        } else {
            snprintf(name, sizeof name, "%s", s.value);
        }
        if (strlen(name) > CAN_MAP_NAME_MAX) {
            return conf_fail(why, n, "signal: its name '%s' is longer than a DBC name's %d characters: add name=N",
                             name, CAN_MAP_NAME_MAX);
        }
        memcpy(s.meta.name, name, strlen(name) + 1); /* fits: checked just above */
    }
    other = signal_named(f, s.meta.name);
    if (other >= 0) {
        return conf_fail(why, n, "signal name '%s' already used in [%s %s] (line %d): add name=OTHER", s.meta.name,
                   frame_kind(f), f->name, f->meta[other].loc.line);
    }
    if (urrt_can_signal_check(&s.sig, URRT_CAN_MAX_LEN) < 0) {
        return conf_fail(why, n, "signal: does not fit even a 64-byte frame");
    }
    return add_signal(f, &s.sig, &s.meta) >= 0 || conf_fail(why, n, "out of memory");
}

/* alive_counter = START [intel|motorola], validity_bit = BIT */
static bool frame_marker(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                         size_t n)
{
    struct can_map_frame *f = obj;
    enum can_map_role role = strcmp(key->name, "alive_counter") == 0 ? CAN_MAP_ROLE_ALIVE : CAN_MAP_ROLE_VALID;
    const char *name = role == CAN_MAP_ROLE_ALIVE ? CAN_MAP_ALIVE_NAME : CAN_MAP_VALID_NAME;
    char buf[64];
    char *words[SIGNAL_MAX_WORDS];
    int nwords, index;
    uint32_t start;
    urrt_can_signal sig = {.factor = 1.0, .type = URRT_CAN_UNSIGNED, .byte_order = URRT_CAN_INTEL};
    struct can_map_signal meta = {.role = role, .loc = {at.file, at.line}, .field = -1};

    snprintf(buf, sizeof buf, "%s", value);
    nwords = split_words(buf, words);
    if (nwords < 1 || nwords > 2 || !conf_u32(words[0], 0, UINT32_MAX, &start, NULL, 0) ||
        (nwords == 2 && role == CAN_MAP_ROLE_VALID)) {
        return conf_fail(why, n, role == CAN_MAP_ROLE_ALIVE ? "alive_counter = '%s': give the start bit of the 4-bit "
                   "counter and optionally its byte order (56, or 59 motorola)"
                   : "validity_bit = '%s': give the bit number (0..511)", value);
    }
    if (nwords == 2 && strcmp(words[1], "motorola") == 0) {
        sig.byte_order = URRT_CAN_MOTOROLA;
    } else if (nwords == 2 && strcmp(words[1], "intel") != 0) {
        return conf_fail(why, n, "alive_counter: byte order '%s': use intel or motorola", words[1]);
    }
    if (start >= 8 * URRT_CAN_MAX_LEN) {
        return conf_fail(why, n, "%s = %u: give a bit number 0..511", key->name, (unsigned)start);
    }
    sig.start = (uint16_t)start;
    sig.length = role == CAN_MAP_ROLE_ALIVE ? CAN_MAP_ALIVE_BITS : 1;
    sig.max = (double)((1u << sig.length) - 1);
    snprintf(meta.name, sizeof meta.name, "%s", name);
    if (signal_named(f, name) >= 0) {
        return conf_fail(why, n, "[frame %s] already has a signal named '%s'", f->name, name);
    }
    if (urrt_can_signal_check(&sig, URRT_CAN_MAX_LEN) < 0) {
        return conf_fail(why, n, "%s does not fit even a 64-byte frame", key->name);
    }
    index = add_signal(f, &sig, &meta);
    if (index < 0) {
        return conf_fail(why, n, "out of memory");
    }
    *(role == CAN_MAP_ROLE_ALIVE ? &f->alive_index : &f->valid_index) = index;
    return true;
}

static bool frame_period(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                         size_t n)
{
    struct can_map_frame *f = obj;
    char reason[CONF_WHY_MAX];
    (void)at;
    if (strcmp(value, "every") == 0) {
        f->every = true;
        return true;
    }
    if (!conf_duration_ms(value, conf_bare_unit(key->name), (uint32_t)key->min, (uint32_t)key->max, &f->period_ms,
                          reason, sizeof reason)) {
        return conf_fail(why, n, "period_ms = '%s': give %u..%u milliseconds, or every (each packet): %s", value,
                         (unsigned)key->min, (unsigned)key->max, reason);
    }
    return true;
}

static bool frame_policy(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                         size_t n)
{
    struct can_map_frame *f = obj;
    (void)key, (void)at;
    if (strcmp(value, "stop") == 0) {
        f->stale_policy = CAN_MAP_STALE_STOP;
    } else if (strcmp(value, "invalid") == 0) {
        f->stale_policy = CAN_MAP_STALE_INVALID;
    } else {
        return conf_fail(why, n, "stale_policy = '%s': use stop or invalid", value);
    }
    return true;
}

static bool frame_comment(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                          size_t n)
{
    struct can_map_frame *f = obj;
    (void)key, (void)at;
    return conf_text(f->comment, sizeof f->comment, value, NULL, 0) ||
           conf_fail(why, n, "comment: at most %zu characters, no '\"', '\\' or control characters", sizeof f->comment - 1);
}

const struct conf_key can_map_frame_keys[CAN_MAP_FK_COUNT] = {
    [CAN_MAP_FK_ID] = {"id", CONF_UINT, CONF_FIELD(struct can_map_frame, id), 0, UINT32_MAX, NULL,
                       "%1$s = '%2$s' is not a number (0x181 or 385)", false, NULL, NULL, "required",
                       "the frame's CAN id"},
    [CAN_MAP_FK_EXTENDED] = {"extended", CONF_BOOL, CONF_FIELD(struct can_map_frame, extended), 0, 0, NULL,
                             "%1$s = '%2$s': use yes (29-bit id) or no (11-bit id)", false, NULL, "no", NULL,
                             "a 29-bit id"},
    [CAN_MAP_FK_FD] = {"fd", CONF_BOOL, CONF_FIELD(struct can_map_frame, fd), 0, 0, NULL,
                       "%1$s = '%2$s': use yes (CAN FD frame) or no (classic CAN)", false, NULL, "no", NULL,
                       "a CAN FD frame"},
    [CAN_MAP_FK_LENGTH] = {"length", CONF_UINT, CONF_FIELD(struct can_map_frame, len), 0, URRT_CAN_MAX_LEN, NULL,
                           "%1$s = '%2$s': give the payload length in bytes, 0..8 (FD: up to 64)", false, NULL, "8",
                           NULL, "payload bytes (a CAN FD length above 8)"},
    [CAN_MAP_FK_PERIOD] = {"period_ms", CONF_FN, 0, 0, 1, 60000, frame_period, NULL, false, "N|every", NULL,
                           "required", "the frame's period, or every: one frame per robot packet"},
    [CAN_MAP_FK_ROBOT] = {"robot", CONF_FN, CONF_FIELD(struct can_map_frame, robot), 0, 0, robot_name, NULL, false,
                          "NAME", NULL, "the only robot", "robot the values come from"},
    [CAN_MAP_FK_ALIVE] = {"alive_counter", CONF_FN, 0, 0, 0, 0, frame_marker, NULL, false, "START [intel|motorola]",
                          NULL, "none", "a 4-bit counter at that start bit, +1 per frame sent"},
    [CAN_MAP_FK_VALID] = {"validity_bit", CONF_FN, 0, 0, 0, 0, frame_marker, NULL, false, "BIT", NULL, "none",
                          "1 while every value of the frame is fresh and sent as it is"},
    [CAN_MAP_FK_STALE_AFTER] = {"stale_after_ms", CONF_MS, CONF_FIELD(struct can_map_frame, stale_after_ms), 1, 60000,
                                NULL, "%1$s = '%2$s': give 1..60000 milliseconds", false, NULL, NULL,
                                "[can] stale_after_ms", "data older than this is stale"},
    [CAN_MAP_FK_STALE_POLICY] = {"stale_policy", CONF_FN, 0, 0, 0, 0, frame_policy, NULL, false, "stop|invalid",
                                 "stop", NULL, "what a frame does when its data is stale"},
    [CAN_MAP_FK_COMMENT] = {"comment", CONF_FN, 0, 0, 0, 0, frame_comment, NULL, false, "TEXT", NULL, "none",
                            "text for the DBC"},
    [CAN_MAP_FK_SIGNAL] = {"signal", CONF_FN, 0, 0, 0, 0, frame_signal, NULL, true, "FIELD[ELEM] @START|LENGTH ...",
                           NULL, "at least one", "one field element; the key again for each signal"},
};

/* on_silence = stop | hold | value V */
static bool input_silence(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                          size_t n)
{
    struct can_map_frame *f = obj;
    char reason[CONF_WHY_MAX];
    (void)key, (void)at;
    if (strcmp(value, "stop") == 0) {
        f->silence = URRT_PLCIN_STOP;
    } else if (strcmp(value, "hold") == 0) {
        f->silence = URRT_PLCIN_HOLD;
    } else if (strncmp(value, "value", 5) == 0 && isspace((unsigned char)value[5])) {
        const char *v = value + 5;
        while (isspace((unsigned char)*v)) {
            v++;
        }
        if (!conf_number(v, -DBL_MAX, DBL_MAX, &f->silence_value, reason, sizeof reason)) {
            return conf_fail(why, n, "on_silence = '%s': value takes a finite number (value 0): %s", value, reason);
        }
        f->silence = URRT_PLCIN_VALUE;
    } else {
        return conf_fail(why, n, "on_silence = '%s': use stop (the program's RTDE watchdog acts), hold (the last "
                         "values go on) or value V (V goes to every register of the frame)", value);
    }
    return true;
}

const struct conf_key can_map_input_keys[CAN_MAP_IK_COUNT] = {
    [CAN_MAP_IK_ID] = {"id", CONF_UINT, CONF_FIELD(struct can_map_frame, id), 0, UINT32_MAX, NULL,
                       "%1$s = '%2$s' is not a number (0x201 or 513)", false, NULL, NULL, "required",
                       "the CAN id the PLC sends the frame on"},
    [CAN_MAP_IK_EXTENDED] = {"extended", CONF_BOOL, CONF_FIELD(struct can_map_frame, extended), 0, 0, NULL,
                             "%1$s = '%2$s': use yes (29-bit id) or no (11-bit id)", false, NULL, "no", NULL,
                             "a 29-bit id"},
    [CAN_MAP_IK_FD] = {"fd", CONF_BOOL, CONF_FIELD(struct can_map_frame, fd), 0, 0, NULL,
                       "%1$s = '%2$s': use yes (CAN FD frame) or no (classic CAN)", false, NULL, "no", NULL,
                       "a CAN FD frame"},
    [CAN_MAP_IK_LENGTH] = {"length", CONF_UINT, CONF_FIELD(struct can_map_frame, len), 0, URRT_CAN_MAX_LEN, NULL,
                           "%1$s = '%2$s': give the payload length in bytes, 0..8 (FD: up to 64)", false, NULL, "8",
                           NULL, "payload bytes; a frame of another length is refused and counted"},
    [CAN_MAP_IK_ROBOT] = {"robot", CONF_FN, CONF_FIELD(struct can_map_frame, robot), 0, 0, robot_name, NULL, false,
                          "NAME", NULL, "the only robot", "robot whose input registers the frame writes"},
    [CAN_MAP_IK_TIMEOUT] = {"timeout_ms", CONF_MS, CONF_FIELD(struct can_map_frame, timeout_ms), 1, 60000, NULL,
                            "%1$s = '%2$s': give 1..60000 milliseconds", false, NULL, NULL, "required",
                            "no frame for longer than this: the PLC is silent (on_silence)"},
    [CAN_MAP_IK_ON_SILENCE] = {"on_silence", CONF_FN, 0, 0, 0, 0, input_silence, NULL, false,
                               "stop|hold|value V", "stop", NULL,
                               "what the registers get while the PLC is silent: nothing (stop), the last values, V"},
    [CAN_MAP_IK_COMMENT] = {"comment", CONF_FN, 0, 0, 0, 0, frame_comment, NULL, false, "TEXT", NULL, "none",
                            "text for the DBC"},
    [CAN_MAP_IK_SIGNAL] = {"signal", CONF_FN, 0, 0, 0, 0, frame_signal, NULL, true,
                           "REGISTER @START|LENGTH ...", NULL, "at least one",
                           "one input register (or bits of one); the key again for each signal"},
};

bool can_map_set(struct can_map *map, struct can_map_frame *frame, const struct conf_key *key, const char *value,
                 struct conf_at at, char *why, size_t n)
{
    const struct conf_key *table = frame == NULL ? can_map_can_keys
                                   : frame->input ? can_map_input_keys
                                                  : can_map_frame_keys;
    struct can_map_loc *loc = frame != NULL ? &frame->key_loc[key - table] : &map->key_loc[key - table];
    at.file = intern_file(map, at.file);
    if (!conf_key_set(key, frame != NULL ? (void *)frame : (void *)map, value, at, why, n)) {
        return false;
    }
    loc->file = at.file;
    loc->line = at.line;
    return true;
}

/* ---- whole-file checks ------------------------------------------------------------- */

double can_map_frame_time_us(const struct can_map *map, unsigned len, bool extended, bool fd)
{
    unsigned nominal;
    unsigned data;
    double data_rate = map->data_bitrate ? map->data_bitrate : map->bitrate;
    urrt_can_frame_bits(len, extended, fd, &nominal, &data);
    return nominal * 1e6 / map->bitrate + data * 1e6 / data_rate;
}

static struct can_map_loc loc_or(struct can_map_loc a, struct can_map_loc b)
{
    return a.line != 0 ? a : b;
}

static bool resolve_robot(const struct can_map *map, const char *name, size_t *index)
{
    size_t i;
    if (name[0] == '\0') {
        if (map->robot_count == 1) {
            *index = 0;
            return true;
        }
        return false;
    }
    for (i = 0; i < map->robot_count; i++) {
        if (strcmp(map->robots[i].name, name) == 0) {
            *index = i;
            return true;
        }
    }
    return false;
}

static void robot_list(const struct can_map *map, char *out, size_t size)
{
    size_t i;
    size_t used = 0;
    out[0] = '\0';
    for (i = 0; i < map->robot_count && used + 1 < size; i++) {
        int n = snprintf(out + used, size - used, "%s%s", i ? ", " : "", map->robots[i].name);
        if (n < 0) {
            break;
        }
        used += (size_t)n;
    }
    if (map->robot_count == 0) {
        snprintf(out, size, "none");
    }
}

static void robot_problem(const struct can_map *map, char *err, size_t errlen, struct can_map_loc loc,
                          const char *what, const char *name)
{
    char list[256];
    robot_list(map, list, sizeof list);
    if (name[0] == '\0') {
        add_error(map, err, errlen, loc, "%s: the gateway has %zu robots (%s): say which with %s", what,
                  map->robot_count, list, strcmp(what, "heartbeat") == 0 ? "heartbeat_robot = NAME" : "robot = NAME");
    } else {
        add_error(map, err, errlen, loc, "%s: unknown robot '%s' (robots: %s)", what, name, list);
    }
}

static uint32_t robot_period_us(const struct can_map *map, size_t index)
{
    uint32_t p = map->robots[index].period_us;
    return p ? p : CAN_MAP_FASTEST_ROBOT_US;
}

/* The problems can_map_finish finds: each reported, and counted. */
struct finish {
    struct can_map *map;
    char *err;
    size_t errlen;
    int errors;
};

static void problem(struct finish *fin, struct can_map_loc loc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void problem(struct finish *fin, struct can_map_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    report(fin->map, fin->err, fin->errlen, loc, fmt, ap);
    va_end(ap);
    fin->errors++;
}

static void check_frame_id(struct finish *fin, const struct can_map_frame *f, const char *what)
{
    struct can_map_loc id_loc = loc_or(f->key_loc[CAN_MAP_FK_ID], f->loc);
    if (f->key_loc[CAN_MAP_FK_ID].line == 0) {
        problem(fin, f->loc, "%s has no id", what);
    } else if (!urrt_can_id_valid(f->id, f->extended)) {
        if (!f->extended && urrt_can_id_valid(f->id, true)) {
            problem(fin, id_loc, "%s id 0x%X is past 0x7FF, the largest 11-bit id: set extended = yes for a 29-bit id",
                    what, (unsigned)f->id);
        } else {
            problem(fin, id_loc, "%s id 0x%X is past 0x%X, the largest %s id", what, (unsigned)f->id,
                    f->extended ? URRT_CAN_EFF_MAX : URRT_CAN_SFF_MAX, f->extended ? "29-bit" : "11-bit");
        }
    }
}

static void check_frame_length(struct finish *fin, const struct can_map_frame *f, const char *what)
{
    struct can_map_loc len_loc = loc_or(f->key_loc[CAN_MAP_FK_LENGTH], f->loc);
    if (f->fd && !fin->map->fd) {
        problem(fin, loc_or(f->key_loc[CAN_MAP_FK_FD], f->loc), "%s is a CAN FD frame but [can] fd is not yes", what);
    }
    if (urrt_can_length_valid(f->len, f->fd)) {
        return;
    }
    if (f->fd) {
        problem(fin, len_loc, "%s length %u is not a CAN FD length (0-8, 12, 16, 20, 24, 32, 48, 64): use %u", what,
                (unsigned)f->len, urrt_can_fd_length_round_up(f->len));
    } else {
        problem(fin, len_loc, "%s length %u: a classic CAN frame carries at most 8 bytes (fd = yes for up to 64)", what,
                (unsigned)f->len);
    }
}

/* The frame's robot, and its period against the robot's. */
static void check_frame_timing(struct finish *fin, struct can_map_frame *f, const char *what)
{
    struct can_map *map = fin->map;
    bool has_period = f->key_loc[CAN_MAP_FK_PERIOD].line != 0;
    if (!f->every && !has_period) {
        problem(fin, f->loc, "%s has no period_ms (milliseconds, or every)", what);
    }
    if (!resolve_robot(map, f->robot, &f->robot_index)) {
        robot_problem(map, fin->err, fin->errlen, loc_or(f->key_loc[CAN_MAP_FK_ROBOT], f->loc), what, f->robot);
        fin->errors++;
        f->robot_index = 0;
    } else if (!f->every && has_period && map->robots[f->robot_index].period_us != 0 &&
               (uint64_t)f->period_ms * 1000u < map->robots[f->robot_index].period_us) {
        uint32_t p = map->robots[f->robot_index].period_us;
        problem(fin, f->key_loc[CAN_MAP_FK_PERIOD],
                "%s period_ms = %u is faster than robot %s sends (every %.3g ms, %.4g Hz): use period_ms >= %u or "
                "every",
                what, (unsigned)f->period_ms, map->robots[f->robot_index].name, p / 1000.0, 1e6 / p,
                (unsigned)((p + 999) / 1000));
    }
    if (f->stale_after_ms == 0) {
        f->stale_after_ms = map->stale_after_ms;
    }
    if (f->stale_policy == CAN_MAP_STALE_INVALID && f->valid_index < 0) {
        problem(fin, f->key_loc[CAN_MAP_FK_STALE_POLICY],
                "%s stale_policy = invalid needs a validity_bit (the receiver could not tell stale values)", what);
    }
    if (f->stale_policy == CAN_MAP_STALE_INVALID && f->every) {
        problem(fin, f->key_loc[CAN_MAP_FK_STALE_POLICY],
                "%s: a period_ms = every frame stops with the packets; stale_policy = invalid needs a period", what);
    }
}

static void layout_problem(struct finish *fin, const struct can_map_frame *f, const char *what, int rc,
                           const urrt_can_signal *sig, size_t a, size_t b)
{
    const struct can_map_signal *ma = &f->meta[a];
    if (rc == URRT_CAN_E_OVERLAP) {
        problem(fin, ma->loc, "%s signal '%s' overlaps signal '%s' (line %d)", what, ma->name, f->meta[b].name,
                f->meta[b].loc.line);
    } else if (rc == URRT_CAN_E_PAST_END) {
        unsigned need = 0;
        urrt_can_signal_span(sig, NULL, NULL, &need);
        problem(fin, ma->loc, "%s signal '%s' (@%u|%u) reaches byte %u, past the frame's length %u", what, ma->name,
                (unsigned)sig->start, (unsigned)sig->length, need - 1, (unsigned)f->len);
    } else {
        problem(fin, ma->loc, "%s signal '%s': %s", what, ma->name, urrt_can_strerror(rc));
    }
}

/* Every layout problem, not only the first: check, and on an error take
 * the offending signal out of the way and look again. */
static void check_frame_layout(struct finish *fin, const struct can_map_frame *f, const char *what)
{
    urrt_can_signal *work = malloc((f->count ? f->count : 1) * sizeof *work);
    size_t *index = malloc((f->count ? f->count : 1) * sizeof *index);
    size_t n = f->count, first = 0, second = 0;
    int rc;
    if (work == NULL || index == NULL) {
        problem(fin, f->loc, "out of memory");
        n = 0;
    }
    for (size_t i = 0; i < n; i++) {
        work[i] = f->sigs[i];
        index[i] = i;
    }
    while (n > 0 && (rc = urrt_can_layout_check(work, n, f->len, &first, &second)) < 0) {
        layout_problem(fin, f, what, rc, &work[first], index[first], index[second]);
        memmove(&work[first], &work[first + 1], (n - first - 1) * sizeof *work);
        memmove(&index[first], &index[first + 1], (n - first - 1) * sizeof *index);
        n--;
    }
    free(work);
    free(index);
}

static void check_frame(struct finish *fin, struct can_map_frame *f)
{
    char what[64];
    size_t fields = 0;
    snprintf(what, sizeof what, "[frame %s]", f->name);
    check_frame_id(fin, f, what);
    check_frame_length(fin, f, what);
    check_frame_timing(fin, f, what);
    for (size_t i = 0; i < f->count; i++) {
        fields += f->meta[i].role == CAN_MAP_ROLE_FIELD || f->meta[i].role == CAN_MAP_ROLE_RTDE;
    }
    if (fields == 0) {
        problem(fin, f->loc, "%s has no signal (signal = FIELD[ELEM] @START|LENGTH ...)", what);
    }
    if (urrt_can_length_valid(f->len, f->fd)) {
        check_frame_layout(fin, f, what);
    }
}

/* ---- [input NAME]: frames the gateway receives ------------------------------------------ */

static void add_notice(struct can_map *map, struct can_map_loc loc, const char *text);

/* The bits of its register a signal writes: a mask's bits= run, else all. */
static uint64_t signal_reg_bits(const urrt_can_signal *sig, const struct can_map_signal *meta)
{
    unsigned first = URRT_CAN_SIG_MASK_FIRST(sig->flags);
    if (!meta->bitmask) {
        return ~UINT64_C(0);
    }
    return (sig->length >= 64 ? ~UINT64_C(0) : (UINT64_C(1) << sig->length) - 1) << first;
}

/* The frame's recipe: each register once, in the order of its first
 * signal; a register that two signals write is refused unless both carry
 * disjoint bits of one mask. */
static void input_registers(struct finish *fin, struct can_map_frame *f, const char *what)
{
    f->reg_count = 0;
    for (size_t i = 0; i < f->count; i++) {
        const struct can_map_signal *m = &f->meta[i];
        uint64_t bits = signal_reg_bits(&f->sigs[i], m);
        bool seen = false;
        if (m->bitmask && (bits >> 32) != 0) {
            char name[URRT_RTDE_NAME_MAX];
            (void)urrt_rtde_var_name(m->var, name, sizeof name);
            problem(fin, m->loc, "%s signal '%s' carries bits %u-%u of %s, which has 32 (0..31): shorten it, or "
                    "pick them with bits=", what, m->name, URRT_CAN_SIG_MASK_FIRST(f->sigs[i].flags),
                    URRT_CAN_SIG_MASK_FIRST(f->sigs[i].flags) + f->sigs[i].length - 1u, name);
        }
        for (size_t k = 0; k < i && !seen; k++) {
            if (f->meta[k].var != m->var) {
                continue;
            }
            seen = true;
            if (!m->bitmask || (signal_reg_bits(&f->sigs[k], &f->meta[k]) & bits) != 0) {
                problem(fin, m->loc, "%s signal '%s' writes the register signal '%s' (line %d) writes: one register, "
                        "one signal (bits of a mask: disjoint bits=)", what, m->name, f->meta[k].name,
                        f->meta[k].loc.line);
            }
        }
        if (!seen && f->reg_count == URRT_RTDE_IN_MAX_VARS) {
            problem(fin, m->loc, "%s writes more than %d registers: one input recipe takes at most %d; split the "
                    "frame", what, URRT_RTDE_IN_MAX_VARS, URRT_RTDE_IN_MAX_VARS);
            return; /* once a frame */
        } else if (!seen) {
            f->regs[f->reg_count++] = (uint16_t)m->var;
        }
    }
}

/* on_silence = value V: a value every register of the frame takes (lib's
 * own check, on a recipe of the frame's registers). */
static void check_silence_value(struct finish *fin, const struct can_map_frame *f, const char *what)
{
    urrt_rtde_in in;
    if (f->silence != URRT_PLCIN_VALUE || f->reg_count == 0 ||
        urrt_rtde_in_init(&in, f->regs, f->reg_count) != URRT_OK) {
        return;
    }
    for (size_t i = 0; i < f->reg_count; i++) {
        if (urrt_rtde_in_set_double(&in, i, f->silence_value) != URRT_OK) {
            char name[URRT_RTDE_NAME_MAX];
            (void)urrt_rtde_var_name(f->regs[i], name, sizeof name);
            problem(fin, loc_or(f->key_loc[CAN_MAP_IK_ON_SILENCE], f->loc),
                    "%s on_silence = value %.17g: %s does not take it (an integer register an integer in its "
                    "range, a bit 0 or 1, a mask word 0..4294967295)", what, f->silence_value, name);
            return;
        }
    }
    for (size_t k = 0; k < f->count; k++) {
        const urrt_can_signal *sig = &f->sigs[k];
        if (!f->meta[k].bitmask && !(f->silence_value >= sig->min && f->silence_value <= sig->max)) {
            problem(fin, loc_or(f->key_loc[CAN_MAP_IK_ON_SILENCE], f->loc),
                    "%s on_silence = value %.17g is outside signal '%s''s min..max (%.17g..%.17g): a value the PLC "
                    "could never send", what, f->silence_value, f->meta[k].name, sig->min, sig->max);
            return;
        }
    }
}

static void check_input(struct finish *fin, struct can_map_frame *f)
{
    char what[64];
    snprintf(what, sizeof what, "[input %s]", f->name);
    check_frame_id(fin, f, what);
    check_frame_length(fin, f, what);
    if (!resolve_robot(fin->map, f->robot, &f->robot_index)) {
        robot_problem(fin->map, fin->err, fin->errlen, loc_or(f->key_loc[CAN_MAP_IK_ROBOT], f->loc), what, f->robot);
        fin->errors++;
        f->robot_index = 0;
    }
    if (f->key_loc[CAN_MAP_IK_TIMEOUT].line == 0) {
        problem(fin, f->loc, "%s has no timeout_ms: after how long without the frame is the PLC silent? (the PLC's "
                "period and some margin, e.g. timeout_ms = 100 for a 20 ms frame)", what);
    }
    if (f->count == 0) {
        problem(fin, f->loc, "%s has no signal (signal = input_int_register_24 @0|32 intel signed, ...)", what);
    }
    if (urrt_can_length_valid(f->len, f->fd)) {
        check_frame_layout(fin, f, what);
    }
    input_registers(fin, f, what);
    check_silence_value(fin, f, what);
}

/* One register, one source: no two [input]s of a robot write it. And the
 * kernel's receive filter holds every [input]'s id beside a CANopen node's. */
static void check_input_sources(struct finish *fin)
{
    const struct can_map *map = fin->map;
    size_t per_robot[64] = {0};
    if (map->input_count > URRT_CANLINK_RX_IDS_MAX - URRT_CO_RX_IDS_MAX) {
        problem(fin, map->inputs[URRT_CANLINK_RX_IDS_MAX - URRT_CO_RX_IDS_MAX].loc, "[input %s]: more than %d "
                "[input]s: the CAN socket's receive filter takes %d ids, %d of them kept for a CANopen node's",
                map->inputs[URRT_CANLINK_RX_IDS_MAX - URRT_CO_RX_IDS_MAX].name,
                URRT_CANLINK_RX_IDS_MAX - URRT_CO_RX_IDS_MAX, URRT_CANLINK_RX_IDS_MAX, URRT_CO_RX_IDS_MAX);
    }
    for (size_t i = 0; i < map->input_count; i++) {
        const struct can_map_frame *f = &map->inputs[i];
        if (f->robot_index < sizeof per_robot / sizeof per_robot[0] &&
            ++per_robot[f->robot_index] == URRT_RTDE_IN_MAX_RECIPES + 1) {
            problem(fin, f->loc, "[input %s]: more than %d [input]s write robot %s's registers: a session takes "
                    "%d input recipes; join frames", f->name, URRT_RTDE_IN_MAX_RECIPES,
                    map->robots[f->robot_index].name, URRT_RTDE_IN_MAX_RECIPES);
        }
        for (size_t k = 0; k < f->count; k++) {
            for (size_t j = 0; j < i; j++) {
                const struct can_map_frame *g = &map->inputs[j];
                for (size_t l = 0; g->robot_index == f->robot_index && l < g->count; l++) {
                    if (g->meta[l].var == f->meta[k].var) {
                        problem(fin, f->meta[k].loc, "[input %s] signal '%s': its register is written by [input %s] "
                                "signal '%s' (line %d) already: one register, one source", f->name, f->meta[k].name,
                                g->name, g->meta[l].name, g->meta[l].loc.line);
                        j = i; /* once per signal */
                        break;
                    }
                }
            }
        }
    }
}

/* Registers 0..23 (and bits 0..63) are an enabled fieldbus adapter's: say
 * so where a user picked one. */
static void notice_fieldbus_registers(struct can_map *map)
{
    for (size_t i = 0; i < map->input_count; i++) {
        const struct can_map_frame *f = &map->inputs[i];
        for (size_t k = 0; k < f->count; k++) {
            int var = f->meta[k].var;
            bool low = (var >= URRT_RTDE_V_INPUT_INT_REGISTER && var < URRT_RTDE_V_INPUT_INT_REGISTER + 24) ||
                       (var >= URRT_RTDE_V_INPUT_DOUBLE_REGISTER && var < URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 24) ||
                       var == URRT_RTDE_V_INPUT_BIT_REGISTERS0_TO_31 || var == URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63;
            char text[400], name[URRT_RTDE_NAME_MAX];
            bool again = false;
            for (size_t j = 0; j < k; j++) {
                again = again || f->meta[j].var == var;
            }
            if (!low || again) {
                continue;
            }
            (void)urrt_rtde_var_name(var, name, sizeof name);
            snprintf(text, sizeof text, "%s: registers 0..23 (bits 0..63) belong to a fieldbus adapter "
                     "(EtherNet/IP, PROFINET, Modbus) while one is enabled, and the controller then answers IN_USE; "
                     "24..47 (bits 64..127) are the RTDE clients'", name);
            add_notice(map, f->meta[k].loc, text);
        }
    }
}

/* The frames with an id, for the duplicate check: the [frame]s, the
 * heartbeat (number frame_count), then the [input]s. */
static size_t id_count(const struct can_map *map)
{
    return map->frame_count + 1 + map->input_count;
}

static const struct can_map_frame *id_frame(const struct can_map *map, size_t k)
{
    return k < map->frame_count ? &map->frames[k] : k > map->frame_count ? &map->inputs[k - map->frame_count - 1] : NULL;
}

/* Frame k's id, the kind of it and where it was given (line 0: not given,
 * reported as missing); its name for a message into buf. */
static struct can_map_loc id_of(const struct can_map *map, size_t k, uint32_t *id, bool *extended, char *buf,
                                size_t size)
{
    const struct can_map_frame *f = id_frame(map, k);
    if (f == NULL) {
        *id = map->hb_id;
        *extended = map->hb_extended;
        snprintf(buf, size, "the heartbeat");
        return map->key_loc[CAN_MAP_CK_HB_ID];
    }
    *id = f->id;
    *extended = f->extended;
    snprintf(buf, size, "[%s %s]", frame_kind(f), f->name);
    return f->key_loc[CAN_MAP_FK_ID];
}

/* [can]'s own keys, and the heartbeat's robot. */
static void check_can(struct finish *fin, struct can_map_loc can_loc)
{
    struct can_map *map = fin->map;
    if (map->can_loc.line == 0) {
        problem(fin, can_loc, "CAN frames need a [can] section (interface, heartbeat_id, ...)");
    } else {
        if (map->interface == NULL) {
            problem(fin, can_loc, "[can] has no interface (can0, or log:PATH for a candump log file)");
        }
        if (map->key_loc[CAN_MAP_CK_HB_ID].line == 0) {
            problem(fin, can_loc, "[can] has no heartbeat_id: the heartbeat is how a receiver knows the gateway is "
                                  "alive (e.g. heartbeat_id = 0x701)");
        } else if (!urrt_can_id_valid(map->hb_id, map->hb_extended)) {
            problem(fin, map->key_loc[CAN_MAP_CK_HB_ID], "heartbeat_id 0x%X is past the largest %s id%s",
                    (unsigned)map->hb_id, map->hb_extended ? "29-bit" : "11-bit",
                    !map->hb_extended && urrt_can_id_valid(map->hb_id, true) ? ": set heartbeat_extended = yes" : "");
        }
    }
    if (map->key_loc[CAN_MAP_CK_DATA_BITRATE].line != 0) {
        if (!map->fd) {
            problem(fin, map->key_loc[CAN_MAP_CK_DATA_BITRATE], "data_bitrate is for CAN FD: set fd = yes or remove it");
        } else if (map->data_bitrate < map->bitrate) {
            problem(fin, map->key_loc[CAN_MAP_CK_DATA_BITRATE], "data_bitrate %u is below bitrate %u",
                    (unsigned)map->data_bitrate, (unsigned)map->bitrate);
        }
    }
    if (!resolve_robot(map, map->hb_robot, &map->hb_robot_index)) {
        robot_problem(map, fin->err, fin->errlen, loc_or(map->key_loc[CAN_MAP_CK_HB_ROBOT], can_loc), "heartbeat",
                      map->hb_robot);
        fin->errors++;
        map->hb_robot_index = 0;
    }
    if (map->frame_count == 0 && map->input_count == 0) {
        problem(fin, can_loc, "[can] without any [frame NAME] or [input NAME] section: nothing to send or receive");
    }
}

/* Duplicate ids, the [input]s' among them: one id has one transmitter. */
static void check_ids(struct finish *fin)
{
    const struct can_map *map = fin->map;
    for (size_t i = 0; i < id_count(map); i++) {
        char who_i[64], who_j[64];
        uint32_t id_i, id_j;
        bool ext_i, ext_j;
        struct can_map_loc at = id_of(map, i, &id_i, &ext_i, who_i, sizeof who_i);
        if (at.line == 0) {
            continue; /* reported as missing */
        }
        for (size_t j = 0; j < i; j++) {
            struct can_map_loc other = id_of(map, j, &id_j, &ext_j, who_j, sizeof who_j);
            if (other.line != 0 && id_j == id_i && ext_j == ext_i) {
                bool received = id_frame(map, i) != NULL && id_frame(map, i)->input;
                problem(fin, at, "%s id 0x%X is already used by %s (line %d)%s", who_i, (unsigned)id_i, who_j,
                        other.line, received ? ": the PLC's frames need ids of their own" : "");
                break;
            }
        }
    }
}

/* Worst-case bus load of each frame and of the whole. */
static void compute_load(struct can_map *map)
{
    map->load = 0;
    for (size_t i = 0; i < map->frame_count; i++) {
        struct can_map_frame *f = &map->frames[i];
        double period_us = f->every ? robot_period_us(map, f->robot_index < map->robot_count ? f->robot_index : 0)
                                    : f->period_ms * 1000.0;
        unsigned len = urrt_can_length_valid(f->len, f->fd) ? f->len : URRT_CAN_MAX_LEN;
        if (map->robot_count == 0 && f->every) {
            period_us = CAN_MAP_FASTEST_ROBOT_US;
        }
        f->load = period_us > 0 ? can_map_frame_time_us(map, len, f->extended, f->fd) / period_us : 0;
        map->load += f->load;
    }
    map->frames_load = map->load;
    map->hb_load = can_map_frame_time_us(map, URRT_CANTX_HB_LEN, map->hb_extended, false) / (map->hb_period_ms * 1000.0);
    map->load += map->hb_load;
    for (size_t i = 0; i < map->traffic_count; i++) {
        struct can_map_traffic *t = &map->traffic[i];
        t->load = can_map_frame_time_us(map, t->len, false, false) * t->per_second / 1e6;
        map->load += t->load;
    }
}

/* "a 2.7%, b 1.2%, c 0.3%": the three heaviest frames say where to act. */
static void heaviest(const struct can_map *map, char *top, size_t size)
{
    size_t order[3];
    size_t nshow = 0, used = 0;
    top[0] = '\0';
    for (size_t k = 0; k < 3; k++) {
        double best = -1;
        size_t bi = SIZE_MAX;
        for (size_t i = 0; i < map->frame_count; i++) {
            bool taken = false;
            for (size_t j = 0; j < nshow; j++) {
                taken |= order[j] == i;
            }
            if (!taken && map->frames[i].load > best) {
                best = map->frames[i].load;
                bi = i;
            }
        }
        if (bi == SIZE_MAX) {
            break;
        }
        order[nshow++] = bi;
    }
    for (size_t j = 0; j < nshow; j++) {
        int n = snprintf(top + used, size - used, "%s%s %.1f%%", j ? ", " : "", map->frames[order[j]].name,
                         map->frames[order[j]].load * 100.0);
        if (n < 0 || (size_t)n >= size - used) {
            break;
        }
        used += (size_t)n;
    }
}

static void check_load(struct finish *fin, struct can_map_loc can_loc)
{
    struct can_map *map = fin->map;
    char top[256];
    char parts[256];
    compute_load(map);
    if (map->load * 100.0 <= map->max_load_percent + 1e-9) {
        return;
    }
    heaviest(map, top, sizeof top);
    load_parts(map, parts, sizeof parts);
    problem(fin, loc_or(map->key_loc[CAN_MAP_CK_MAX_LOAD], loc_or(map->key_loc[CAN_MAP_CK_BITRATE], can_loc)),
            "worst-case bus load %.1f%% at %u bit/s is over max_bus_load = %u%% (%s; heaviest: %s): lengthen "
            "periods, shorten frames or raise the bit rate",
            map->load * 100.0, (unsigned)map->bitrate, map->max_load_percent, parts, top);
}

/* ---- notices: bits of a mask that no signal carries ---------------------------------- */

/*
 * What the bits of each bit-mask field mean: the one place the gateway keeps
 * them (docs/protocol.md; the RealTime interface and RTDE give digital inputs
 * and outputs the same layout). A mask field without rows here has no defined
 * bits to miss. RTDE-only masks (robot_status_bits, safety_status_bits, the bit
 * registers: CAN_MAP_ROLE_RTDE signals) have no rows yet, so no notice names
 * their bits a signal leaves out.
 */
static const struct mask_group {
    urrt_field_id field;
    unsigned first, last;
    const char *meaning;
} mask_groups[] = {
    {URRT_F_DIGITAL_INPUT_BITS, 0, 7, "standard inputs"},
    {URRT_F_DIGITAL_INPUT_BITS, 8, 15, "configurable inputs"},
    {URRT_F_DIGITAL_INPUT_BITS, 16, 17, "tool inputs"},
    {URRT_F_DIGITAL_OUTPUTS, 0, 7, "standard outputs"},
    {URRT_F_DIGITAL_OUTPUTS, 8, 15, "configurable outputs"},
    {URRT_F_DIGITAL_OUTPUTS, 16, 17, "tool outputs"},
};

size_t can_map_notice_count(const struct can_map *map)
{
    return map->notice_count;
}

const char *can_map_notice(const struct can_map *map, size_t i)
{
    return i < map->notice_count ? map->notices[i] : NULL;
}

static void add_notice(struct can_map *map, struct can_map_loc loc, const char *text)
{
    char **grown = realloc(map->notices, (map->notice_count + 1) * sizeof *grown);
    char line[512];
    if (grown == NULL) {
        return; /* a notice is advice: without memory, none */
    }
    map->notices = grown;
    snprintf(line, sizeof line, "%s:%d: %s", loc.file ? loc.file : "?", loc.line, text);
    map->notices[map->notice_count] = strdup(line);
    map->notice_count += map->notices[map->notice_count] != NULL;
}

/* The bits of `field` that robot `robot`'s signals carry, and the place of
 * the first such signal (line 0: none). */
static uint64_t carried_bits(const struct can_map *map, size_t robot, int field, struct can_map_loc *first)
{
    uint64_t carried = 0;
    first->line = 0;
    for (size_t i = 0; i < map->frame_count; i++) {
        const struct can_map_frame *f = &map->frames[i];
        for (size_t k = 0; k < f->count && f->robot_index == robot; k++) {
            unsigned from = URRT_CAN_SIG_MASK_FIRST(f->sigs[k].flags);
            unsigned len = f->sigs[k].length;
            if (f->meta[k].role != CAN_MAP_ROLE_FIELD || f->meta[k].field != field || !f->meta[k].bitmask) {
                continue;
            }
            carried |= (len >= 64 ? ~UINT64_C(0) : (UINT64_C(1) << len) - 1) << from;
            *first = first->line == 0 ? f->meta[k].loc : *first;
        }
    }
    return carried;
}

/* "bits 16-17 (tool inputs)" for each run of group bits not carried; the
 * number of runs. */
static int missing_runs(int field, uint64_t carried, char *out, size_t size, unsigned *run_first, unsigned *run_last)
{
    size_t used = 0;
    int runs = 0;
    out[0] = '\0';
    for (size_t g = 0; g < sizeof mask_groups / sizeof mask_groups[0]; g++) {
        const struct mask_group *m = &mask_groups[g];
        for (unsigned b = m->first; m->field == (urrt_field_id)field && b <= m->last; b++) {
            unsigned e = b;
            int w;
            if ((carried >> b & 1u) != 0) {
                continue;
            }
            while (e < m->last && (carried >> (e + 1) & 1u) == 0) {
                e++;
            }
            w = e > b ? snprintf(out + used, size - used, "%sbits %u-%u (%s)", runs ? ", " : "", b, e, m->meaning)
                      : snprintf(out + used, size - used, "%sbit %u (%s)", runs ? ", " : "", b, m->meaning);
            used += w > 0 && (size_t)w < size - used ? (size_t)w : 0;
            *run_first = runs == 0 ? b : *run_first;
            *run_last = e;
            runs++;
            b = e;
        }
    }
    return runs;
}

/* For each robot and mask field it sends: the defined bits no signal carries. */
static void notice_dropped_bits(struct can_map *map)
{
    for (size_t i = 0; i < map->notice_count; i++) {
        free(map->notices[i]);
    }
    map->notice_count = 0;
    for (size_t r = 0; r < map->robot_count; r++) {
        for (int field = 0; field < URRT_FIELD_COUNT; field++) {
            struct can_map_loc at;
            uint64_t carried = carried_bits(map, r, field, &at);
            char runs[256], text[400];
            unsigned first = 0, last = 0;
            int n;
            if (at.line == 0 || (n = missing_runs(field, carried, runs, sizeof runs, &first, &last)) == 0) {
                continue;
            }
            int used = snprintf(text, sizeof text, "%s%s%s: %s %s not carried", urrt_field((urrt_field_id)field)->name,
                                map->robot_count > 1 ? " of robot " : "",
                                map->robot_count > 1 ? map->robots[r].name : "", runs,
                                n > 1 || last > first ? "are" : "is");
            if (n == 1 && used > 0 && (size_t)used < sizeof text) {
                /* One run: the bits= that would carry it. */
                char bits[24];
                snprintf(bits, sizeof bits, last > first ? "%u-%u" : "%u", first, last);
                snprintf(text + used, sizeof text - (size_t)used, " (bits=%s in a signal would carry %s)", bits,
                         last > first ? "them" : "it");
            }
            add_notice(map, at, text);
        }
    }
}

int can_map_finish(struct can_map *map, const struct can_map_robot *robots, size_t robot_count, char *err,
                   size_t errlen)
{
    struct finish fin = {map, err, errlen, 0};
    struct can_map_loc can_loc;

    if (err != NULL && errlen > 0) {
        err[0] = '\0';
    }
    free(map->robots);
    map->robots = calloc(robot_count ? robot_count : 1, sizeof *map->robots);
    if (map->robots == NULL) {
        return -1;
    }
    map->robot_count = robot_count;
    for (size_t i = 0; i < robot_count; i++) {
        snprintf(map->robots[i].name, sizeof map->robots[i].name, "%s", robots[i].name ? robots[i].name : "");
        map->robots[i].period_us = robots[i].period_us;
    }
    map->finished = true;
    if (!map->configured) {
        return 0;
    }
    can_loc = map->can_loc.line ? map->can_loc
              : map->frame_count ? map->frames[0].loc
              : map->input_count ? map->inputs[0].loc
                                 : map->can_loc;
    check_can(&fin, can_loc);
    for (size_t i = 0; i < map->frame_count; i++) {
        check_frame(&fin, &map->frames[i]);
    }
    for (size_t i = 0; i < map->input_count; i++) {
        check_input(&fin, &map->inputs[i]);
    }
    check_input_sources(&fin);
    check_ids(&fin);
    check_load(&fin, can_loc);
    if (fin.errors > 0) {
        map->finished = false;
        return -1;
    }
    notice_dropped_bits(map);
    notice_fieldbus_registers(map);
    return 0;
}

size_t can_map_input_ids(const struct can_map *map, uint32_t *ids, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < map->input_count && n < max; i++) {
        ids[n++] = map->inputs[i].id | (map->inputs[i].extended ? URRT_CANLINK_RX_EXTENDED : 0u);
    }
    return n;
}

const struct can_map_frame *can_map_input_of(const struct can_map *map, uint32_t id, bool extended)
{
    for (size_t i = 0; i < map->input_count; i++) {
        if (map->inputs[i].id == id && map->inputs[i].extended == extended) {
            return &map->inputs[i];
        }
    }
    return NULL;
}
