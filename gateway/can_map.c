/* SPDX-License-Identifier: MIT */
/* can_map: mapping configuration, checks and frame scheduling for the CAN
 * side of urrt-gateway. See can_map.h and docs/can.md. */
#include "can_map.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- small helpers ---------------------------------------------------------------- */

static const char *const frame_key_names[CAN_MAP_FK_COUNT] = {
    [CAN_MAP_FK_ID] = "id",
    [CAN_MAP_FK_EXTENDED] = "extended",
    [CAN_MAP_FK_FD] = "fd",
    [CAN_MAP_FK_LENGTH] = "length",
    [CAN_MAP_FK_PERIOD] = "period_ms",
    [CAN_MAP_FK_ROBOT] = "robot",
    [CAN_MAP_FK_ALIVE] = "alive_counter",
    [CAN_MAP_FK_VALID] = "validity_bit",
    [CAN_MAP_FK_STALE_AFTER] = "stale_after_ms",
    [CAN_MAP_FK_STALE_POLICY] = "stale_policy",
    [CAN_MAP_FK_COMMENT] = "comment",
};

static const char *const can_key_names[CAN_MAP_CK_COUNT] = {
    [CAN_MAP_CK_INTERFACE] = "interface",
    [CAN_MAP_CK_FD] = "fd",
    [CAN_MAP_CK_BITRATE] = "bitrate",
    [CAN_MAP_CK_DATA_BITRATE] = "data_bitrate",
    [CAN_MAP_CK_MAX_LOAD] = "max_bus_load",
    [CAN_MAP_CK_HB_ID] = "heartbeat_id",
    [CAN_MAP_CK_HB_EXTENDED] = "heartbeat_extended",
    [CAN_MAP_CK_HB_PERIOD] = "heartbeat_period_ms",
    [CAN_MAP_CK_HB_ROBOT] = "heartbeat_robot",
    [CAN_MAP_CK_STALE_AFTER] = "stale_after_ms",
    [CAN_MAP_CK_GENERATION] = "robot_generation",
    [CAN_MAP_CK_NODE] = "node",
    [CAN_MAP_CK_RECEIVER] = "receiver",
};

/* Reports a problem: to the map's reporter if one is set, and as
 * "FILE:LINE: reason" into err. add_error appends ('\n'-separated, as far as
 * it fits); fail replaces and returns -1. */
static void report(const struct can_map *map, char *err, size_t errlen, bool append, struct can_map_loc loc,
                   const char *fmt, va_list ap)
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
    if (append) {
        used = strnlen(err, errlen);
        if (used + 1 >= errlen) {
            return;
        }
        if (used > 0) {
            err[used++] = '\n';
        }
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
    report(map, err, errlen, true, loc, fmt, ap);
    va_end(ap);
}

static int fail(const struct can_map *map, char *err, size_t errlen, struct can_map_loc loc, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

static int fail(const struct can_map *map, char *err, size_t errlen, struct can_map_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    report(map, err, errlen, false, loc, fmt, ap);
    va_end(ap);
    return -1;
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

static bool is_identifier(const char *s, size_t len)
{
    size_t i;
    if (len == 0 || len > CAN_MAP_NAME_MAX || !(isalpha((unsigned char)s[0]) || s[0] == '_')) {
        return false;
    }
    for (i = 1; i < len; i++) {
        if (!(isalnum((unsigned char)s[i]) || s[i] == '_')) {
            return false;
        }
    }
    return true;
}

static bool parse_u64(const char *s, int base, uint64_t *out)
{
    char *end;
    unsigned long long v;
    while (isspace((unsigned char)*s)) {
        s++;
    }
    if (*s == '\0' || *s == '-' || *s == '+') {
        return false;
    }
    errno = 0;
    v = strtoull(s, &end, base);
    if (errno != 0 || end == s) {
        return false;
    }
    while (isspace((unsigned char)*end)) {
        end++;
    }
    if (*end != '\0') {
        return false;
    }
    *out = v;
    return true;
}

static bool parse_u32(const char *s, int base, uint32_t *out)
{
    uint64_t v;
    if (!parse_u64(s, base, &v) || v > UINT32_MAX) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

static bool parse_i64(const char *s, int64_t *out)
{
    char *end;
    long long v;
    while (isspace((unsigned char)*s)) {
        s++;
    }
    if (*s == '\0') {
        return false;
    }
    errno = 0;
    v = strtoll(s, &end, 0);
    if (errno != 0 || end == s || *end != '\0') {
        return false;
    }
    *out = v;
    return true;
}

static bool parse_double(const char *s, double *out)
{
    char *end;
    double v;
    while (isspace((unsigned char)*s)) {
        s++;
    }
    if (*s == '\0') {
        return false;
    }
    errno = 0;
    v = strtod(s, &end);
    if (end == s || !isfinite(v) || (errno == ERANGE && fabs(v) > 1.0)) {
        return false;
    }
    while (isspace((unsigned char)*end)) {
        end++;
    }
    if (*end != '\0') {
        return false;
    }
    *out = v;
    return true;
}

static bool parse_bool(const char *s, bool *out)
{
    static const char *const yes[] = {"yes", "true", "on", "1"};
    static const char *const no[] = {"no", "false", "off", "0"};
    size_t i;
    for (i = 0; i < sizeof yes / sizeof yes[0]; i++) {
        if (strcasecmp(s, yes[i]) == 0) {
            *out = true;
            return true;
        }
        if (strcasecmp(s, no[i]) == 0) {
            *out = false;
            return true;
        }
    }
    return false;
}

/* A byte below ' ' or DEL: it would go raw into the DBC and the log. */
static bool has_control(const char *s, size_t len)
{
    size_t i;
    for (i = 0; i < len; i++) {
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f) {
            return true;
        }
    }
    return false;
}

/* Copies a value, dropping one pair of surrounding double quotes. */
static bool copy_text(char *dst, size_t size, const char *value)
{
    size_t len = strlen(value);
    if (len >= 2 && value[0] == '"' && value[len - 1] == '"') {
        value++;
        len -= 2;
    }
    if (len >= size || memchr(value, '"', len) != NULL || memchr(value, '\\', len) != NULL ||
        has_control(value, len)) {
        return false;
    }
    memcpy(dst, value, len);
    dst[len] = '\0';
    return true;
}

/* ---- life cycle ---------------------------------------------------------------------- */

void can_map_init(struct can_map *map)
{
    memset(map, 0, sizeof *map);
    map->bitrate = CAN_MAP_DEFAULT_BITRATE;
    map->max_load_percent = CAN_MAP_DEFAULT_MAX_LOAD;
    map->hb_period_ms = CAN_MAP_DEFAULT_HEARTBEAT_MS;
    map->stale_after_ms = CAN_MAP_DEFAULT_STALE_MS;
    map->generation = URRT_GEN_3X;
    snprintf(map->node, sizeof map->node, "URRT_GATEWAY");
    snprintf(map->receiver, sizeof map->receiver, "Vector__XXX");
}

void can_map_free(struct can_map *map)
{
    size_t i;
    for (i = 0; i < map->frame_count; i++) {
        free(map->frames[i].sigs);
        free(map->frames[i].meta);
    }
    free(map->frames);
    free(map->robots);
    free(map->interface);
    for (i = 0; i < map->file_count; i++) {
        free(map->files[i]);
    }
    free(map->files);
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

int can_map_describe(const struct can_map *map, char *buf, size_t size)
{
    if (!can_map_enabled(map)) {
        return snprintf(buf, size, "no CAN output configured");
    }
    return snprintf(buf, size, "%zu frame%s + heartbeat 0x%X on %s, worst-case bus load %.1f%% of %u bit/s%s (max %u%%)",
                    map->frame_count, map->frame_count == 1 ? "" : "s", (unsigned)map->hb_id,
                    map->interface ? map->interface : "?", map->load * 100.0, (unsigned)map->bitrate,
                    map->data_bitrate > map->bitrate ? " with an FD data phase" : "", map->max_load_percent);
}

/* ---- [can] ----------------------------------------------------------------------- */

static int can_key(struct can_map *map, const char *key, const char *value, struct can_map_loc loc, char *err,
                   size_t errlen)
{
    int k;
    uint32_t u;
    for (k = 0; k < CAN_MAP_CK_COUNT; k++) {
        if (strcmp(key, can_key_names[k]) == 0) {
            break;
        }
    }
    if (k == CAN_MAP_CK_COUNT) {
        return fail(map, err, errlen, loc,
                    "unknown key '%s' in [can] (keys: interface, fd, bitrate, data_bitrate, max_bus_load, "
                    "heartbeat_id, heartbeat_extended, heartbeat_period_ms, heartbeat_robot, stale_after_ms, "
                    "robot_generation, node, receiver)",
                    key);
    }
    if (map->key_loc[k].line != 0) {
        return fail(map, err, errlen, loc, "[can] %s given twice (first at line %d)", key, map->key_loc[k].line);
    }
    switch ((enum can_map_can_key)k) {
    case CAN_MAP_CK_INTERFACE:
        if (value[0] == '\0' || strlen(value) > 255 || (strncmp(value, "log:", 4) == 0 && value[4] == '\0')) {
            return fail(map, err, errlen, loc, "interface = '%s': give a CAN interface (can0) or log:PATH (log:- for stdout)",
                        value);
        }
        if (has_control(value, strlen(value))) {
            return fail(map, err, errlen, loc, "interface = '%s': no control characters", value);
        }
        if (strncmp(value, "log:", 4) != 0 && (strlen(value) >= 16 || strpbrk(value, " /\t") != NULL)) {
            return fail(map, err, errlen, loc, "interface = '%s' is not an interface name (at most 15 characters, no '/')",
                        value);
        }
        free(map->interface);
        map->interface = strdup(value);
        if (map->interface == NULL) {
            return fail(map, err, errlen, loc, "out of memory");
        }
        break;
    case CAN_MAP_CK_FD:
        if (!parse_bool(value, &map->fd)) {
            return fail(map, err, errlen, loc, "fd = '%s': use yes or no", value);
        }
        break;
    case CAN_MAP_CK_BITRATE:
    case CAN_MAP_CK_DATA_BITRATE:
        if (!parse_u32(value, 10, &u) || u < 10000 || u > 12000000) {
            return fail(map, err, errlen, loc, "%s = '%s': give bits per second between 10000 and 12000000 (500000)", key,
                        value);
        }
        if (k == CAN_MAP_CK_BITRATE) {
            map->bitrate = u;
        } else {
            map->data_bitrate = u;
        }
        break;
    case CAN_MAP_CK_MAX_LOAD:
        if (!parse_u32(value, 10, &u) || u < 1 || u > 100) {
            return fail(map, err, errlen, loc, "max_bus_load = '%s': give a percentage 1..100", value);
        }
        map->max_load_percent = u;
        break;
    case CAN_MAP_CK_HB_ID:
        if (!parse_u32(value, 0, &map->hb_id)) {
            return fail(map, err, errlen, loc, "heartbeat_id = '%s' is not a number (0x701 or 1793)", value);
        }
        break;
    case CAN_MAP_CK_HB_EXTENDED:
        if (!parse_bool(value, &map->hb_extended)) {
            return fail(map, err, errlen, loc, "heartbeat_extended = '%s': use yes or no", value);
        }
        break;
    case CAN_MAP_CK_HB_PERIOD:
        if (!parse_u32(value, 10, &u) || u < 10 || u > 1000) {
            return fail(map, err, errlen, loc,
                        "heartbeat_period_ms = '%s': give 10..1000 (the heartbeat goes at least once a second)",
                        value);
        }
        map->hb_period_ms = u;
        break;
    case CAN_MAP_CK_HB_ROBOT:
        if (!copy_text(map->hb_robot, sizeof map->hb_robot, value) || map->hb_robot[0] == '\0') {
            return fail(map, err, errlen, loc, "heartbeat_robot = '%s': give a robot name", value);
        }
        break;
    case CAN_MAP_CK_STALE_AFTER:
        if (!parse_u32(value, 10, &u) || u < 1 || u > 60000) {
            return fail(map, err, errlen, loc, "stale_after_ms = '%s': give 1..60000 milliseconds", value);
        }
        map->stale_after_ms = u;
        break;
    case CAN_MAP_CK_GENERATION:
        if (strcmp(value, "3") == 0 || strcmp(value, "5") == 0 || strcasecmp(value, "3.x") == 0 ||
            strcasecmp(value, "5.x") == 0) {
            map->generation = URRT_GEN_3X;
        } else if (strcmp(value, "1") == 0 || strcasecmp(value, "1.x") == 0) {
            map->generation = URRT_GEN_1X;
        } else {
            return fail(map, err, errlen, loc,
                        "robot_generation = '%s': use 3 (CB3 and e-series, 3.x/5.x) or 1 (CB1/CB2, 1.x)", value);
        }
        break;
    case CAN_MAP_CK_NODE:
    case CAN_MAP_CK_RECEIVER: {
        char *dst = k == CAN_MAP_CK_NODE ? map->node : map->receiver;
        if (!is_identifier(value, strlen(value))) {
            return fail(map, err, errlen, loc, "%s = '%s': a DBC node name is a C identifier of at most %d characters",
                        key, value, CAN_MAP_NAME_MAX);
        }
        snprintf(dst, CAN_MAP_NAME_MAX + 1, "%s", value);
        break;
    }
    default: break;
    }
    map->key_loc[k] = loc;
    return 1;
}

/* ---- [frame NAME] ------------------------------------------------------------------ */

static struct can_map_frame *frame_get(struct can_map *map, const char *name, size_t len, struct can_map_loc loc)
{
    size_t i;
    struct can_map_frame *f;
    for (i = 0; i < map->frame_count; i++) {
        if (strlen(map->frames[i].name) == len && memcmp(map->frames[i].name, name, len) == 0) {
            return &map->frames[i];
        }
    }
    if (map->frame_count == map->frame_capacity) {
        size_t cap = map->frame_capacity ? 2 * map->frame_capacity : 8;
        struct can_map_frame *grown = realloc(map->frames, cap * sizeof *grown);
        if (grown == NULL) {
            return NULL;
        }
        map->frames = grown;
        map->frame_capacity = cap;
    }
    f = &map->frames[map->frame_count++];
    memset(f, 0, sizeof *f);
    memcpy(f->name, name, len);
    f->name[len] = '\0';
    f->loc = loc;
    f->len = 8;
    f->alive_index = -1;
    f->valid_index = -1;
    f->next_due_us = CAN_MAP_NOT_SCHEDULED;
    return f;
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
        {
            bool quoted = false;
            while (*p != '\0' && (quoted || !isspace((unsigned char)*p))) {
                if (*p == '"') {
                    quoted = !quoted;
                }
                p++;
            }
            if (quoted) {
                return -1;
            }
        }
        if (*p != '\0') {
            *p++ = '\0';
        }
    }
}

/* Unit of element elem of a field: the table writes "m, rad" for a pose,
 * i.e. the first three elements in m and the last three in rad. */
static void field_unit(const urrt_field_info *info, unsigned elem, char *out, size_t size)
{
    const char *unit = info->unit;
    const char *comma = strstr(unit, ", ");
    if (strcmp(unit, "enum") == 0 || strcmp(unit, "bits") == 0) {
        unit = "";
    }
    if (comma != NULL && info->count == 6) {
        if (elem < 3) {
            snprintf(out, size, "%.*s", (int)(comma - unit), unit);
        } else {
            snprintf(out, size, "%s", comma + 2);
        }
        return;
    }
    snprintf(out, size, "%s", unit);
}

static bool parse_place(const char *word, unsigned *start, unsigned *length)
{
    char buf[32];
    char *bar;
    uint32_t s;
    uint32_t l;
    if (word[0] != '@' || strlen(word) >= sizeof buf) {
        return false;
    }
    snprintf(buf, sizeof buf, "%s", word + 1);
    bar = strchr(buf, '|');
    if (bar == NULL) {
        return false;
    }
    *bar = '\0';
    if (!parse_u32(buf, 10, &s) || !parse_u32(bar + 1, 10, &l)) {
        return false;
    }
    *start = s;
    *length = l;
    return true;
}

#define SIGNAL_GRAMMAR \
    "signal = FIELD[ELEM] @START|LENGTH intel|motorola unsigned|signed|float32|float64 " \
    "[factor=F] [offset=O] [min=A] [max=B] [unit=U] [name=N] [invalid=RAW]"

static int frame_signal(const struct can_map *map, struct can_map_frame *f, const char *value, struct can_map_loc loc,
                        char *err, size_t errlen)
{
    char line[512];
    char *words[SIGNAL_MAX_WORDS];
    int nwords;
    int i;
    urrt_can_signal sig;
    struct can_map_signal meta;
    const urrt_field_info *info;
    char *bracket;
    unsigned start;
    unsigned length;
    int order = -1;
    int type = -1;
    bool have_min = false;
    bool have_max = false;
    bool have_name = false;
    bool have_unit = false;
    bool have_invalid = false;
    int64_t invalid = 0;
    double lo;
    double hi;
    int fid;

    if (strlen(value) >= sizeof line) {
        return fail(map, err, errlen, loc, "signal line too long");
    }
    snprintf(line, sizeof line, "%s", value);
    nwords = split_words(line, words);
    if (nwords < 0) {
        return fail(map, err, errlen, loc, "signal: unbalanced quotes or more than %d words", SIGNAL_MAX_WORDS);
    }
    if (nwords < 4) {
        return fail(map, err, errlen, loc, "signal = '%s': expected %s", value, SIGNAL_GRAMMAR);
    }
    memset(&sig, 0, sizeof sig);
    memset(&meta, 0, sizeof meta);
    meta.role = CAN_MAP_ROLE_FIELD;
    meta.loc = loc;
    sig.factor = 1.0;

    /* FIELD or FIELD[ELEM] */
    bracket = strchr(words[0], '[');
    fid = urrt_field_find(words[0], bracket ? (size_t)(bracket - words[0]) : strlen(words[0]));
    if (fid < 0) {
        return fail(map, err, errlen, loc, "signal: no field '%.*s' (field names as in docs/protocol.md: q_actual, "
                    "tcp_force, robot_mode, ...)",
                    bracket ? (int)(bracket - words[0]) : (int)strlen(words[0]), words[0]);
    }
    info = urrt_field((urrt_field_id)fid);
    meta.field = fid;
    if (bracket != NULL) {
        size_t blen = strlen(bracket);
        char num[16];
        uint32_t e;
        if (blen < 3 || bracket[blen - 1] != ']' || blen - 2 >= sizeof num) {
            return fail(map, err, errlen, loc, "signal: '%s': write FIELD[ELEM], e.g. q_actual[0]", words[0]);
        }
        memcpy(num, bracket + 1, blen - 2);
        num[blen - 2] = '\0';
        if (!parse_u32(num, 10, &e)) {
            return fail(map, err, errlen, loc, "signal: '%s': the element is a number", words[0]);
        }
        if (e >= info->count) {
            return fail(map, err, errlen, loc, "signal: %s has %u element%s: %s[%u] is out of range (0..%u)", info->name,
                        (unsigned)info->count, info->count == 1 ? "" : "s", info->name, (unsigned)e,
                        (unsigned)info->count - 1);
        }
        meta.elem = e;
    } else if (info->count > 1) {
        return fail(map, err, errlen, loc, "signal: %s has %u elements: write %s[0] .. %s[%u]", info->name,
                    (unsigned)info->count, info->name, info->name, (unsigned)info->count - 1);
    }
    meta.bitmask = strcmp(info->unit, "bits") == 0;

    if (!parse_place(words[1], &start, &length)) {
        return fail(map, err, errlen, loc, "signal: '%s': expected @START|LENGTH, e.g. @0|16", words[1]);
    }
    if (length < 1 || length > 64) {
        return fail(map, err, errlen, loc, "signal: length %u: give 1..64 bits", length);
    }
    if (start >= 8 * URRT_CAN_MAX_LEN) {
        return fail(map, err, errlen, loc, "signal: start bit %u: give 0..511", start);
    }
    sig.start = (uint16_t)start;
    sig.length = (uint8_t)length;

    for (i = 2; i < nwords; i++) {
        char *w = words[i];
        char *eq = strchr(w, '=');
        if (eq == NULL) {
            int *slot;
            int v;
            if (strcmp(w, "intel") == 0) {
                slot = &order, v = URRT_CAN_INTEL;
            } else if (strcmp(w, "motorola") == 0) {
                slot = &order, v = URRT_CAN_MOTOROLA;
            } else if (strcmp(w, "unsigned") == 0) {
                slot = &type, v = URRT_CAN_UNSIGNED;
            } else if (strcmp(w, "signed") == 0) {
                slot = &type, v = URRT_CAN_SIGNED;
            } else if (strcmp(w, "float32") == 0) {
                slot = &type, v = URRT_CAN_FLOAT32;
            } else if (strcmp(w, "float64") == 0) {
                slot = &type, v = URRT_CAN_FLOAT64;
            } else {
                return fail(map, err, errlen, loc,
                            "signal: unknown word '%s': expected intel|motorola, unsigned|signed|float32|float64 "
                            "or factor=, offset=, min=, max=, unit=, name=, invalid=",
                            w);
            }
            if (*slot >= 0) {
                return fail(map, err, errlen, loc, "signal: '%s': %s given twice", w,
                            slot == &order ? "byte order" : "type");
            }
            *slot = v;
            continue;
        }
        *eq = '\0';
        {
            const char *k = w;
            const char *v = eq + 1;
            double d;
            if (strcmp(k, "factor") == 0 || strcmp(k, "offset") == 0 || strcmp(k, "min") == 0 ||
                strcmp(k, "max") == 0) {
                if (!parse_double(v, &d)) {
                    return fail(map, err, errlen, loc, "signal: %s = '%s' is not a finite number", k, v);
                }
                if (k[0] == 'f') {
                    if (d == 0.0) {
                        return fail(map, err, errlen, loc, "signal: factor must not be 0");
                    }
                    sig.factor = d;
                } else if (k[0] == 'o') {
                    sig.offset = d;
                } else if (strcmp(k, "min") == 0) {
                    sig.min = d;
                    have_min = true;
                } else {
                    sig.max = d;
                    have_max = true;
                }
            } else if (strcmp(k, "unit") == 0) {
                if (!copy_text(meta.unit, sizeof meta.unit, v)) {
                    return fail(map, err, errlen, loc, "signal: unit '%s': at most %d characters, no '\"', '\\' or control characters", v,
                                CAN_MAP_UNIT_MAX);
                }
                have_unit = true;
            } else if (strcmp(k, "name") == 0) {
                if (!is_identifier(v, strlen(v))) {
                    return fail(map, err, errlen, loc,
                                "signal: name '%s': a DBC signal name is a C identifier of at most %d characters", v,
                                CAN_MAP_NAME_MAX);
                }
                snprintf(meta.name, sizeof meta.name, "%s", v);
                have_name = true;
            } else if (strcmp(k, "invalid") == 0) {
                if (!parse_i64(v, &invalid)) {
                    return fail(map, err, errlen, loc, "signal: invalid = '%s' is not an integer raw value", v);
                }
                have_invalid = true;
            } else {
                return fail(map, err, errlen, loc,
                            "signal: unknown option '%s=': expected factor=, offset=, min=, max=, unit=, name=, "
                            "invalid=",
                            k);
            }
        }
    }
    if (order < 0) {
        return fail(map, err, errlen, loc, "signal: byte order missing: add intel (little-endian) or motorola (big-endian)");
    }
    if (type < 0) {
        return fail(map, err, errlen, loc, "signal: type missing: add unsigned, signed, float32 or float64");
    }
    sig.byte_order = (uint8_t)order;
    sig.type = (uint8_t)type;
    if (type == URRT_CAN_FLOAT32 && length != 32) {
        return fail(map, err, errlen, loc, "signal: float32 needs length 32, not %u", length);
    }
    if (type == URRT_CAN_FLOAT64 && length != 64) {
        return fail(map, err, errlen, loc, "signal: float64 needs length 64, not %u", length);
    }
    {
        urrt_can_signal bare = sig;
        bare.min = bare.max = 0;
        if (urrt_can_signal_range(&bare, &lo, &hi) < 0) {
            return fail(map, err, errlen, loc, "signal: invalid scaling");
        }
    }
    {
        /* Half a raw step of slack, so that min=-3276.8 passes for a signed
         * 16-bit signal with factor 0.1 however the product rounds. */
        double slack = fabs(sig.factor) / 2;
        if (type == URRT_CAN_FLOAT32 || type == URRT_CAN_FLOAT64) {
            slack = 0;
        }
        if (have_min && sig.min < lo - slack) {
            return fail(map, err, errlen, loc, "signal: min=%.17g is below what the signal can carry (%.17g)", sig.min, lo);
        }
        if (have_max && sig.max > hi + slack) {
            return fail(map, err, errlen, loc, "signal: max=%.17g is above what the signal can carry (%.17g)", sig.max, hi);
        }
    }
    if (!have_min) {
        sig.min = lo;
    }
    if (!have_max) {
        sig.max = hi;
    }
    if (sig.min > sig.max) {
        return fail(map, err, errlen, loc, "signal: min=%.17g is above max=%.17g", sig.min, sig.max);
    }
    if (have_invalid) {
        uint64_t mask = length >= 64 ? UINT64_MAX : (UINT64_C(1) << length) - 1;
        if (type == URRT_CAN_FLOAT32 || type == URRT_CAN_FLOAT64) {
            return fail(map, err, errlen, loc, "signal: invalid= applies to integer signals (float signals send NaN)");
        }
        if (invalid < 0) {
            int64_t lowest = length >= 64 ? INT64_MIN : -((int64_t)1 << (length - 1));
            if (type != URRT_CAN_SIGNED || invalid < lowest) {
                return fail(map, err, errlen, loc, "signal: invalid=%lld does not fit %u %s bits", (long long)invalid,
                            length, type == URRT_CAN_SIGNED ? "signed" : "unsigned");
            }
            sig.invalid_raw = (uint64_t)invalid & mask;
        } else {
            /* A positive value is the raw bit pattern (0x8000 for a signed
             * 16-bit signal is its most negative value). */
            if (((uint64_t)invalid & ~mask) != 0) {
                return fail(map, err, errlen, loc, "signal: invalid=%lld does not fit %u bits", (long long)invalid, length);
            }
            sig.invalid_raw = (uint64_t)invalid;
        }
        sig.flags = URRT_CAN_SIG_INVALID_RAW;
    }
    if (!have_unit) {
        field_unit(info, meta.elem, meta.unit, sizeof meta.unit);
    }
    if (!have_name) {
        if (info->count > 1) {
            snprintf(meta.name, sizeof meta.name, "%s_%u", info->name, meta.elem);
        } else {
            snprintf(meta.name, sizeof meta.name, "%s", info->name);
        }
    }
    i = signal_named(f, meta.name);
    if (i >= 0) {
        return fail(map, err, errlen, loc, "signal name '%s' already used in [frame %s] (line %d): add name=OTHER",
                    meta.name, f->name, f->meta[i].loc.line);
    }
    if (urrt_can_signal_check(&sig, URRT_CAN_MAX_LEN) < 0) {
        return fail(map, err, errlen, loc, "signal: does not fit even a 64-byte frame");
    }
    if (add_signal(f, &sig, &meta) < 0) {
        return fail(map, err, errlen, loc, "out of memory");
    }
    return 1;
}

static int frame_marker(const struct can_map *map, struct can_map_frame *f, enum can_map_role role, const char *value, struct can_map_loc loc,
                        char *err, size_t errlen)
{
    char buf[64];
    char *words[SIGNAL_MAX_WORDS];
    int nwords;
    uint32_t start;
    urrt_can_signal sig;
    struct can_map_signal meta;
    int index;
    const char *name = role == CAN_MAP_ROLE_ALIVE ? CAN_MAP_ALIVE_NAME : CAN_MAP_VALID_NAME;
    const char *key = role == CAN_MAP_ROLE_ALIVE ? "alive_counter" : "validity_bit";

    snprintf(buf, sizeof buf, "%s", value);
    nwords = split_words(buf, words);
    memset(&sig, 0, sizeof sig);
    memset(&meta, 0, sizeof meta);
    sig.factor = 1.0;
    sig.type = URRT_CAN_UNSIGNED;
    sig.byte_order = URRT_CAN_INTEL;
    if (nwords < 1 || nwords > 2 || !parse_u32(words[0], 10, &start) ||
        (nwords == 2 && role == CAN_MAP_ROLE_VALID)) {
        return fail(map, err, errlen, loc, role == CAN_MAP_ROLE_ALIVE
                                          ? "alive_counter = '%s': give the start bit of the 4-bit counter "
                                            "and optionally its byte order (56, or 59 motorola)"
                                          : "validity_bit = '%s': give the bit number (0..511)",
                    value);
    }
    if (nwords == 2) {
        if (strcmp(words[1], "motorola") == 0) {
            sig.byte_order = URRT_CAN_MOTOROLA;
        } else if (strcmp(words[1], "intel") != 0) {
            return fail(map, err, errlen, loc, "alive_counter: byte order '%s': use intel or motorola", words[1]);
        }
    }
    if (start >= 8 * URRT_CAN_MAX_LEN) {
        return fail(map, err, errlen, loc, "%s = %u: give a bit number 0..511", key, (unsigned)start);
    }
    sig.start = (uint16_t)start;
    sig.length = role == CAN_MAP_ROLE_ALIVE ? CAN_MAP_ALIVE_BITS : 1;
    sig.min = 0;
    sig.max = (double)((1u << sig.length) - 1);
    meta.role = role;
    meta.loc = loc;
    meta.field = -1;
    snprintf(meta.name, sizeof meta.name, "%s", name);
    if (signal_named(f, name) >= 0) {
        return fail(map, err, errlen, loc, "[frame %s] already has a signal named '%s'", f->name, name);
    }
    if (urrt_can_signal_check(&sig, URRT_CAN_MAX_LEN) < 0) {
        return fail(map, err, errlen, loc, "%s does not fit even a 64-byte frame", key);
    }
    index = add_signal(f, &sig, &meta);
    if (index < 0) {
        return fail(map, err, errlen, loc, "out of memory");
    }
    if (role == CAN_MAP_ROLE_ALIVE) {
        f->alive_index = index;
    } else {
        f->valid_index = index;
    }
    return 1;
}

static int frame_key(struct can_map *map, struct can_map_frame *f, const char *key, const char *value,
                     struct can_map_loc loc, char *err, size_t errlen)
{
    int k;
    uint32_t u;
    if (strcmp(key, "signal") == 0) {
        return frame_signal(map, f, value, loc, err, errlen);
    }
    for (k = 0; k < CAN_MAP_FK_COUNT; k++) {
        if (strcmp(key, frame_key_names[k]) == 0) {
            break;
        }
    }
    if (k == CAN_MAP_FK_COUNT) {
        return fail(map, err, errlen, loc,
                    "unknown key '%s' in [frame %s] (keys: id, extended, fd, length, period_ms, robot, signal, "
                    "alive_counter, validity_bit, stale_after_ms, stale_policy, comment)",
                    key, f->name);
    }
    if (f->key_loc[k].line != 0) {
        return fail(map, err, errlen, loc, "[frame %s] %s given twice (first at line %d)", f->name, key,
                    f->key_loc[k].line);
    }
    switch ((enum can_map_frame_key)k) {
    case CAN_MAP_FK_ID:
        if (!parse_u32(value, 0, &f->id)) {
            return fail(map, err, errlen, loc, "id = '%s' is not a number (0x181 or 385)", value);
        }
        break;
    case CAN_MAP_FK_EXTENDED:
        if (!parse_bool(value, &f->extended)) {
            return fail(map, err, errlen, loc, "extended = '%s': use yes (29-bit id) or no (11-bit id)", value);
        }
        break;
    case CAN_MAP_FK_FD:
        if (!parse_bool(value, &f->fd)) {
            return fail(map, err, errlen, loc, "fd = '%s': use yes (CAN FD frame) or no (classic CAN)", value);
        }
        break;
    case CAN_MAP_FK_LENGTH:
        if (!parse_u32(value, 10, &u) || u > URRT_CAN_MAX_LEN) {
            return fail(map, err, errlen, loc, "length = '%s': give the payload length in bytes, 0..8 (FD: up to 64)",
                        value);
        }
        f->len = (uint8_t)u;
        break;
    case CAN_MAP_FK_PERIOD:
        if (strcmp(value, "every") == 0) {
            f->every = true;
        } else if (!parse_u32(value, 10, &u) || u < 1 || u > 60000) {
            return fail(map, err, errlen, loc, "period_ms = '%s': give 1..60000 milliseconds, or every (each packet)",
                        value);
        } else {
            f->period_ms = u;
        }
        break;
    case CAN_MAP_FK_ROBOT:
        if (!copy_text(f->robot, sizeof f->robot, value) || f->robot[0] == '\0') {
            return fail(map, err, errlen, loc, "robot = '%s': give a robot name", value);
        }
        break;
    case CAN_MAP_FK_ALIVE:
        if (frame_marker(map, f, CAN_MAP_ROLE_ALIVE, value, loc, err, errlen) < 0) {
            return -1;
        }
        break;
    case CAN_MAP_FK_VALID:
        if (frame_marker(map, f, CAN_MAP_ROLE_VALID, value, loc, err, errlen) < 0) {
            return -1;
        }
        break;
    case CAN_MAP_FK_STALE_AFTER:
        if (!parse_u32(value, 10, &u) || u < 1 || u > 60000) {
            return fail(map, err, errlen, loc, "stale_after_ms = '%s': give 1..60000 milliseconds", value);
        }
        f->stale_after_ms = u;
        break;
    case CAN_MAP_FK_STALE_POLICY:
        if (strcmp(value, "stop") == 0) {
            f->stale_policy = CAN_MAP_STALE_STOP;
        } else if (strcmp(value, "invalid") == 0) {
            f->stale_policy = CAN_MAP_STALE_INVALID;
        } else {
            return fail(map, err, errlen, loc, "stale_policy = '%s': use stop or invalid", value);
        }
        break;
    case CAN_MAP_FK_COMMENT:
        if (!copy_text(f->comment, sizeof f->comment, value)) {
            return fail(map, err, errlen, loc, "comment: at most %zu characters, no '\"', '\\' or control characters",
                        sizeof f->comment - 1);
        }
        break;
    default: break;
    }
    (void)map;
    f->key_loc[k] = loc;
    return 1;
}

int can_map_ini(struct can_map *map, const char *section, const char *key, const char *value, const char *file,
                int line, char *err, size_t errlen)
{
    struct can_map_loc loc;
    if (err != NULL && errlen > 0) {
        err[0] = '\0';
    }
    if (section == NULL || key == NULL || value == NULL) {
        return 0;
    }
    if (strcmp(section, "can") != 0 && strncmp(section, "frame", 5) != 0) {
        return 0;
    }
    if (strncmp(section, "frame", 5) == 0 && section[5] != '\0' && !isspace((unsigned char)section[5])) {
        return 0; /* [frames], [frame_x]: not ours */
    }
    loc.file = intern_file(map, file);
    loc.line = line;
    if (map->finished) {
        return fail(map, err, errlen, loc, "CAN configuration already finished");
    }
    map->configured = true;
    if (strcmp(section, "can") == 0) {
        if (map->can_loc.line == 0) {
            map->can_loc = loc;
        }
        return can_key(map, key, value, loc, err, errlen);
    }
    {
        const char *name = section + 5;
        size_t len;
        struct can_map_frame *f;
        while (isspace((unsigned char)*name)) {
            name++;
        }
        len = strlen(name);
        while (len > 0 && isspace((unsigned char)name[len - 1])) {
            len--;
        }
        if (!is_identifier(name, len)) {
            return fail(map, err, errlen, loc,
                        "[frame %.*s]: the frame name is its DBC name, a C identifier of at most %d characters",
                        (int)len, name, CAN_MAP_NAME_MAX);
        }
        if (len == strlen(CAN_MAP_HEARTBEAT_NAME) && memcmp(name, CAN_MAP_HEARTBEAT_NAME, len) == 0) {
            return fail(map, err, errlen, loc, "[frame %s]: that name is the heartbeat's", CAN_MAP_HEARTBEAT_NAME);
        }
        f = frame_get(map, name, len, loc);
        if (f == NULL) {
            return fail(map, err, errlen, loc, "out of memory");
        }
        return frame_key(map, f, key, value, loc, err, errlen);
    }
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

static void check_frame(struct can_map *map, struct can_map_frame *f, char *err, size_t errlen, int *errors)
{
    char what[64];
    size_t first = 0;
    size_t second = 0;
    size_t i;
    size_t fields = 0;
    int rc;
    struct can_map_loc id_loc = loc_or(f->key_loc[CAN_MAP_FK_ID], f->loc);
    struct can_map_loc len_loc = loc_or(f->key_loc[CAN_MAP_FK_LENGTH], f->loc);

    snprintf(what, sizeof what, "[frame %s]", f->name);
#define PROBLEM(loc, ...) (add_error(map, err, errlen, (loc), __VA_ARGS__), (*errors)++)
    if (f->key_loc[CAN_MAP_FK_ID].line == 0) {
        PROBLEM(f->loc, "%s has no id", what);
    } else if (!urrt_can_id_valid(f->id, f->extended)) {
        if (!f->extended && urrt_can_id_valid(f->id, true)) {
            PROBLEM(id_loc, "%s id 0x%X is past 0x7FF, the largest 11-bit id: set extended = yes for a 29-bit id",
                    what, (unsigned)f->id);
        } else {
            PROBLEM(id_loc, "%s id 0x%X is past 0x%X, the largest %s id", what, (unsigned)f->id,
                    f->extended ? URRT_CAN_EFF_MAX : URRT_CAN_SFF_MAX, f->extended ? "29-bit" : "11-bit");
        }
    }
    if (f->fd && !map->fd) {
        PROBLEM(loc_or(f->key_loc[CAN_MAP_FK_FD], f->loc), "%s is a CAN FD frame but [can] fd is not yes", what);
    }
    if (!urrt_can_length_valid(f->len, f->fd)) {
        if (f->fd) {
            PROBLEM(len_loc, "%s length %u is not a CAN FD length (0-8, 12, 16, 20, 24, 32, 48, 64): use %u", what,
                    (unsigned)f->len, urrt_can_fd_length_round_up(f->len));
        } else {
            PROBLEM(len_loc, "%s length %u: a classic CAN frame carries at most 8 bytes (fd = yes for up to 64)",
                    what, (unsigned)f->len);
        }
    }
    if (!f->every && f->key_loc[CAN_MAP_FK_PERIOD].line == 0) {
        PROBLEM(f->loc, "%s has no period_ms (milliseconds, or every)", what);
    }
    if (!resolve_robot(map, f->robot, &f->robot_index)) {
        robot_problem(map, err, errlen, loc_or(f->key_loc[CAN_MAP_FK_ROBOT], f->loc), what, f->robot);
        (*errors)++;
        f->robot_index = 0;
    } else if (!f->every && f->key_loc[CAN_MAP_FK_PERIOD].line != 0 && map->robots[f->robot_index].period_us != 0 &&
               (uint64_t)f->period_ms * 1000u < map->robots[f->robot_index].period_us) {
        uint32_t p = map->robots[f->robot_index].period_us;
        PROBLEM(f->key_loc[CAN_MAP_FK_PERIOD],
                "%s period_ms = %u is faster than robot %s sends (every %.3g ms, %.4g Hz): use period_ms >= %u or "
                "every",
                what, (unsigned)f->period_ms, map->robots[f->robot_index].name, p / 1000.0, 1e6 / p,
                (unsigned)((p + 999) / 1000));
    }
    if (f->stale_after_ms == 0) {
        f->stale_after_ms = map->stale_after_ms;
    }
    if (f->stale_policy == CAN_MAP_STALE_INVALID && f->valid_index < 0) {
        PROBLEM(f->key_loc[CAN_MAP_FK_STALE_POLICY],
                "%s stale_policy = invalid needs a validity_bit (the receiver could not tell stale values)", what);
    }
    if (f->stale_policy == CAN_MAP_STALE_INVALID && f->every) {
        PROBLEM(f->key_loc[CAN_MAP_FK_STALE_POLICY],
                "%s: a period_ms = every frame stops with the packets; stale_policy = invalid needs a period", what);
    }
    for (i = 0; i < f->count; i++) {
        fields += f->meta[i].role == CAN_MAP_ROLE_FIELD;
    }
    if (fields == 0) {
        PROBLEM(f->loc, "%s has no signal (signal = FIELD[ELEM] @START|LENGTH ...)", what);
    }
    if (urrt_can_length_valid(f->len, f->fd)) {
        /* Every problem, not only the first: check, and on an error take the
         * offending signal out of the way and look again. */
        urrt_can_signal *work = malloc((f->count ? f->count : 1) * sizeof *work);
        size_t *index = malloc((f->count ? f->count : 1) * sizeof *index);
        size_t n = f->count;
        if (work == NULL || index == NULL) {
            PROBLEM(f->loc, "out of memory");
            n = 0;
        }
        for (i = 0; i < n; i++) {
            work[i] = f->sigs[i];
            index[i] = i;
        }
        while (n > 0 && (rc = urrt_can_layout_check(work, n, f->len, &first, &second)) < 0) {
            const struct can_map_signal *a = &f->meta[index[first]];
            if (rc == URRT_CAN_E_OVERLAP) {
                const struct can_map_signal *b = &f->meta[index[second]];
                PROBLEM(a->loc, "%s signal '%s' overlaps signal '%s' (line %d)", what, a->name, b->name, b->loc.line);
            } else if (rc == URRT_CAN_E_PAST_END) {
                unsigned need = 0;
                urrt_can_signal_span(&work[first], NULL, NULL, &need);
                PROBLEM(a->loc, "%s signal '%s' (@%u|%u) reaches byte %u, past the frame's length %u", what, a->name,
                        (unsigned)work[first].start, (unsigned)work[first].length, need - 1, (unsigned)f->len);
            } else {
                PROBLEM(a->loc, "%s signal '%s': %s", what, a->name, urrt_can_strerror(rc));
            }
            memmove(&work[first], &work[first + 1], (n - first - 1) * sizeof *work);
            memmove(&index[first], &index[first + 1], (n - first - 1) * sizeof *index);
            n--;
        }
        free(work);
        free(index);
    }
#undef PROBLEM
}

static const char *id_owner(const struct can_map *map, size_t frame, char *buf, size_t size, int *line)
{
    if (frame == map->frame_count) {
        *line = map->key_loc[CAN_MAP_CK_HB_ID].line;
        return "the heartbeat";
    }
    *line = loc_or(map->frames[frame].key_loc[CAN_MAP_FK_ID], map->frames[frame].loc).line;
    snprintf(buf, size, "[frame %s]", map->frames[frame].name);
    return buf;
}

int can_map_finish(struct can_map *map, const struct can_map_robot *robots, size_t robot_count, char *err,
                   size_t errlen)
{
    int errors = 0;
    size_t i;
    size_t j;
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
    for (i = 0; i < robot_count; i++) {
        snprintf(map->robots[i].name, sizeof map->robots[i].name, "%s", robots[i].name ? robots[i].name : "");
        map->robots[i].period_us = robots[i].period_us;
    }
    map->finished = true;
    if (!map->configured) {
        return 0;
    }
    can_loc = map->can_loc.line ? map->can_loc : (map->frame_count ? map->frames[0].loc : map->can_loc);
#define PROBLEM(loc, ...) (add_error(map, err, errlen, (loc), __VA_ARGS__), errors++)
    if (map->can_loc.line == 0) {
        PROBLEM(can_loc, "CAN frames need a [can] section (interface, heartbeat_id, ...)");
    } else {
        if (map->interface == NULL) {
            PROBLEM(can_loc, "[can] has no interface (can0, or log:PATH for a candump log file)");
        }
        if (map->key_loc[CAN_MAP_CK_HB_ID].line == 0) {
            PROBLEM(can_loc, "[can] has no heartbeat_id: the heartbeat is how a receiver knows the gateway is alive "
                             "(e.g. heartbeat_id = 0x701)");
        } else if (!urrt_can_id_valid(map->hb_id, map->hb_extended)) {
            PROBLEM(map->key_loc[CAN_MAP_CK_HB_ID], "heartbeat_id 0x%X is past the largest %s id%s",
                    (unsigned)map->hb_id, map->hb_extended ? "29-bit" : "11-bit",
                    !map->hb_extended && urrt_can_id_valid(map->hb_id, true) ? ": set heartbeat_extended = yes" : "");
        }
    }
    if (map->key_loc[CAN_MAP_CK_DATA_BITRATE].line != 0) {
        if (!map->fd) {
            PROBLEM(map->key_loc[CAN_MAP_CK_DATA_BITRATE], "data_bitrate is for CAN FD: set fd = yes or remove it");
        } else if (map->data_bitrate < map->bitrate) {
            PROBLEM(map->key_loc[CAN_MAP_CK_DATA_BITRATE], "data_bitrate %u is below bitrate %u",
                    (unsigned)map->data_bitrate, (unsigned)map->bitrate);
        }
    }
    if (!resolve_robot(map, map->hb_robot, &map->hb_robot_index)) {
        robot_problem(map, err, errlen, loc_or(map->key_loc[CAN_MAP_CK_HB_ROBOT], can_loc), "heartbeat",
                      map->hb_robot);
        errors++;
        map->hb_robot_index = 0;
    }
    if (map->frame_count == 0) {
        PROBLEM(can_loc, "[can] without any [frame NAME] section: nothing to send");
    }
    for (i = 0; i < map->frame_count; i++) {
        check_frame(map, &map->frames[i], err, errlen, &errors);
    }
    /* Duplicate ids: the heartbeat counts as frame number frame_count. */
    for (i = 0; i <= map->frame_count; i++) {
        uint32_t id_i = i < map->frame_count ? map->frames[i].id : map->hb_id;
        bool ext_i = i < map->frame_count ? map->frames[i].extended : map->hb_extended;
        if (i == map->frame_count ? map->key_loc[CAN_MAP_CK_HB_ID].line == 0
                                  : map->frames[i].key_loc[CAN_MAP_FK_ID].line == 0) {
            continue; /* reported as missing */
        }
        for (j = 0; j < i; j++) {
            uint32_t id_j = map->frames[j].id;
            if (id_j == id_i && map->frames[j].extended == ext_i && map->frames[j].key_loc[CAN_MAP_FK_ID].line != 0) {
                char bi[64];
                char bj[64];
                int li;
                int lj;
                const char *who_i = id_owner(map, i, bi, sizeof bi, &li);
                const char *who_j = id_owner(map, j, bj, sizeof bj, &lj);
                struct can_map_loc at = i < map->frame_count ? loc_or(map->frames[i].key_loc[CAN_MAP_FK_ID], map->frames[i].loc)
                                                               : map->key_loc[CAN_MAP_CK_HB_ID];
                PROBLEM(at, "%s id 0x%X is already used by %s (line %d)", who_i, (unsigned)id_i, who_j, lj);
                (void)li;
                break;
            }
        }
    }
    /* Worst-case bus load. */
    map->load = 0;
    for (i = 0; i < map->frame_count; i++) {
        struct can_map_frame *f = &map->frames[i];
        double period_us = f->every ? robot_period_us(map, f->robot_index < robot_count ? f->robot_index : 0)
                                    : f->period_ms * 1000.0;
        unsigned len = urrt_can_length_valid(f->len, f->fd) ? f->len : URRT_CAN_MAX_LEN;
        if (robot_count == 0 && f->every) {
            period_us = CAN_MAP_FASTEST_ROBOT_US;
        }
        f->load = period_us > 0 ? can_map_frame_time_us(map, len, f->extended, f->fd) / period_us : 0;
        map->load += f->load;
    }
    map->hb_load = can_map_frame_time_us(map, CAN_MAP_HB_LEN, map->hb_extended, false) / (map->hb_period_ms * 1000.0);
    map->load += map->hb_load;
    if (map->load * 100.0 > map->max_load_percent + 1e-9) {
        char top[256] = "";
        size_t used = 0;
        int k;
        /* The three heaviest frames say where to act. */
        size_t order[3];
        size_t nshow = 0;
        for (k = 0; k < 3; k++) {
            double best = -1;
            size_t bi = SIZE_MAX;
            for (i = 0; i < map->frame_count; i++) {
                bool taken = false;
                for (j = 0; j < nshow; j++) {
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
        for (j = 0; j < nshow; j++) {
            int n = snprintf(top + used, sizeof top - used, "%s%s %.1f%%", j ? ", " : "",
                             map->frames[order[j]].name, map->frames[order[j]].load * 100.0);
            if (n < 0 || (size_t)n >= sizeof top - used) {
                break;
            }
            used += (size_t)n;
        }
        PROBLEM(loc_or(map->key_loc[CAN_MAP_CK_MAX_LOAD], loc_or(map->key_loc[CAN_MAP_CK_BITRATE], can_loc)),
                "worst-case bus load %.1f%% at %u bit/s is over max_bus_load = %u%% (heaviest: %s): lengthen "
                "periods, shorten frames or raise the bit rate",
                map->load * 100.0, (unsigned)map->bitrate, map->max_load_percent, top);
    }
#undef PROBLEM
    if (errors > 0) {
        map->finished = false;
        return -1;
    }
    return 0;
}
