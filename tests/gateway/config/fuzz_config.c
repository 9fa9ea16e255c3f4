/* SPDX-License-Identifier: MIT */
/*
 * fuzz_config.c: libFuzzer harness for the urrt-gateway configuration, an
 * untrusted input like the robot's bytes: the loader (gateway/urrt-gateway/config.c,
 * its reader included), the CAN mapping it feeds (gateway/can/can_map.c), the
 * tables built from it (gateway/can/can_run.c) and the DBC written from it
 * (gateway/can/dbc.c). Each input is one configuration file. It asserts:
 *
 *   - a rejected file gets exactly as many messages as errors counted, each
 *     one line "fuzz.ini:LINE: reason" with LINE within the file (or
 *     "fuzz.ini: reason" for a file-wide one), causes first: what is wrong
 *     on a line, then what the whole file lacks, each group in line order
 *     (file-wide ones first), without control characters;
 *   - an accepted file has no message, at least one robot with a host, and
 *     every text the gateway prints from it (the --check-config plan, the CAN
 *     description, the DBC) is free of control characters, and its CAN
 *     tables are built when it has CAN frames;
 *   - its DBC is written and reads back (dbc_check below): every BO_ has a
 *     valid and unique id, a C identifier as name and a CAN length, every
 *     signal is a unique C identifier that fits its frame without overlap,
 *     with finite scaling and min <= max; every reference names a frame and
 *     signal that exist; the frames the gateway sends come first, the
 *     heartbeat last of them, then exactly the [input]s, each sent by [can]
 *     receiver with its configured id, length and signals, each signal
 *     received by [can] node;
 *   - its C tables (--print-c-tables) are written, free of control
 *     characters, with one urrt_gateway_inputs entry per [input];
 *   - loading the same bytes again gives the same messages and the same DBC;
 *   - the scheduler runs on it (packets with ordinary, huge and NaN values, a
 *     stall, the link down): each frame sent is a configured one, with its
 *     id, length and FD flag, or the heartbeat;
 *   - the same for the file with the lines the loader names left out, and
 *     a robot added when it has none (check_can_only), so that many more
 *     mappings reach the DBC writer and the scheduler.
 *
 * Any violation aborts with a description, so libFuzzer keeps the input.
 * Replay inputs with: fuzz_config FILE...
 */
#define _GNU_SOURCE
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_ctables.h"
#include "can_map.h"
#include "can_run.h"
#include "config.h"
#include "dbc.h"

#define NAME "fuzz.ini"

static const char *current_input;
static size_t current_size;

static void violated(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));

static void violated(const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "fuzz_config: invariant violated: ");
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n--- input (%zu bytes) ---\n", current_size);
    fwrite(current_input, 1, current_size, stderr);
    fprintf(stderr, "\n--- end ---\n");
    abort();
}

/* ---- text helpers ---------------------------------------------------------------- */

/* Lines of the file as a text editor counts them. */
static long count_lines(const char *data, size_t size)
{
    long lines = 0;
    for (size_t i = 0; i < size; i++) {
        lines += data[i] == '\n';
    }
    return lines + (size > 0 && data[size - 1] != '\n');
}

/* No byte below 0x20 but '\n' (and '\t' where allowed), no DEL. */
static void no_control(const char *what, const char *text, size_t len, bool tabs)
{
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)text[i];
        if ((c < 0x20 && c != '\n' && !(tabs && c == '\t')) || c == 0x7f) {
            violated("%s holds control character 0x%02X at byte %zu: \"%.*s\"", what, c, i,
                     (int)(len - i < 80 ? len - i : 80), text + i);
        }
    }
}

static void no_control_str(const char *what, const char *text)
{
    if (text == NULL) {
        violated("%s is NULL", what);
    }
    no_control(what, text, strlen(text), false);
}

static bool c_identifier(const char *s, size_t len)
{
    if (len == 0 || len > CAN_MAP_NAME_MAX || !(isalpha((unsigned char)s[0]) || s[0] == '_')) {
        return false;
    }
    for (size_t i = 1; i < len; i++) {
        if (!(isalnum((unsigned char)s[i]) || s[i] == '_')) {
            return false;
        }
    }
    return true;
}

static bool finite_number(const char *s, double *out)
{
    char *end;
    if (*s == '\0') {
        return false;
    }
    *out = strtod(s, &end);
    return *end == '\0' && isfinite(*out);
}

/* ---- loading ------------------------------------------------------------------------ */

struct loaded {
    gw_config cfg;
    int errors;
    char *messages;
    size_t messages_len;
};

static void load(struct loaded *l, const char *data, size_t size)
{
    /* fmemopen wants a writable buffer even for reading. */
    char *copy = malloc(size ? size : 1);
    FILE *in;
    FILE *err;
    if (copy == NULL) {
        abort();
    }
    memcpy(copy, data, size);
    in = fmemopen(copy, size, "r");
    err = open_memstream(&l->messages, &l->messages_len);
    if (in == NULL || err == NULL) {
        abort();
    }
    l->errors = gw_config_load_stream(&l->cfg, in, NAME, err);
    fclose(in);
    fclose(err);
    free(copy);
}

static void unload(struct loaded *l)
{
    gw_config_free(&l->cfg);
    free(l->messages);
}

/* ---- a rejected file ---------------------------------------------------------------- */

static void check_messages(const struct loaded *l, long lines)
{
    const char *p = l->messages;
    const char *end = l->messages + l->messages_len;
    int count = 0;
    long previous = 0;
    int groups = 1; /* causes (lines), then the whole file's checks: each group in line order */
    if (l->messages_len == 0 || end[-1] != '\n') {
        violated("%d errors but the messages are \"%s\" (not whole lines)", l->errors, l->messages);
    }
    no_control("the error messages", l->messages, l->messages_len, false);
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *q = p + strlen(NAME);
        count++;
        if (strncmp(p, NAME ":", strlen(NAME ":")) != 0) {
            violated("message %d does not begin with \"" NAME ":\": %.*s", count, (int)(nl - p), p);
        }
        q++;
        if (isdigit((unsigned char)*q)) {
            char *after;
            long line = strtol(q, &after, 10);
            if (*after != ':' || after[1] != ' ' || line < 1 || line > lines) {
                violated("message %d names line %ld of a %ld-line file: %.*s", count, line, lines, (int)(nl - p), p);
            }
            if (line < previous && ++groups > 2) {
                violated("message %d (line %ld) comes after one of line %ld in the second group", count, line,
                         previous);
            }
            previous = line;
        } else if (*q != ' ') {
            violated("message %d is neither \"" NAME ":LINE: \" nor \"" NAME ": \": %.*s", count, (int)(nl - p), p);
        } else if (previous != 0 && ++groups > 2) {
            violated("message %d is about the whole file but comes after line %ld in the second group", count,
                     previous);
        } else {
            previous = 0;
        }
        p = nl + 1;
    }
    if (count != l->errors) {
        violated("%d errors counted but %d messages printed:\n%s", l->errors, count, l->messages);
    }
}

/* ---- an accepted file: what --check-config prints --------------------------------- */

static void check_accepted(const gw_config *cfg)
{
    char line[512];
    if (cfg->robot_count < 1 || cfg->robot_count > GW_MAX_ROBOTS || cfg->robots == NULL) {
        violated("accepted with %u robots", cfg->robot_count);
    }
    no_control_str("lcm url", cfg->lcm.url);
    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        no_control_str("lcm channel", cfg->lcm.channel[k]);
        if (cfg->lcm.rate[k].mode == GW_RATE_HZ &&
            !(cfg->lcm.rate[k].hz >= 0.01 && cfg->lcm.rate[k].hz <= GW_ROBOT_MAX_RATE_HZ)) {
            violated("accepted rate %g Hz", cfg->lcm.rate[k].hz);
        }
    }
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        const gw_robot_config *r = &cfg->robots[i];
        no_control_str("robot name", r->name);
        no_control_str("robot host", r->host);
        no_control_str("robot version", r->expected);
        if (r->port == 0 || r->max_rate_hz == 0 || r->link.backoff_max_ms < r->link.backoff_initial_ms ||
            r->link.silence_timeout_ms == 0 || r->link.connect_timeout_ms == 0) {
            violated("robot %s accepted with port %u, rate %u Hz, backoff %u..%u ms", r->name, (unsigned)r->port,
                     r->max_rate_hz, (unsigned)r->link.backoff_initial_ms, (unsigned)r->link.backoff_max_ms);
        }
    }
    if (can_map_describe(&cfg->can, line, sizeof line) < 0) {
        violated("can_map_describe failed");
    }
    no_control_str("the CAN description", line);
    if (can_map_enabled(&cfg->can)) {
        no_control_str("the CAN interface", cfg->can.interface);
    }
    if (can_map_enabled(&cfg->can) != (cfg->can_run != NULL)) {
        violated("accepted with CAN %s but its tables %s", can_map_enabled(&cfg->can) ? "on" : "off",
                 cfg->can_run != NULL ? "built" : "not built");
    }
}

/* ---- the DBC, read back --------------------------------------------------------------- */

struct dbc_signal {
    char name[CAN_MAP_NAME_MAX + 1];
    char receiver[CAN_MAP_NAME_MAX + 1];
    unsigned len;
};

struct dbc_frame {
    unsigned long id;
    char name[CAN_MAP_NAME_MAX + 1];
    char transmitter[CAN_MAP_NAME_MAX + 1];
    unsigned len;
    struct dbc_signal *sig; /* nsig of dbc_read.sigs */
    unsigned nsig;
    uint8_t used[URRT_CAN_MAX_LEN];
};

/* Sized by counting the BO_ and SG_ lines first. */
struct dbc_read {
    struct dbc_frame *frames;
    unsigned count;
    struct dbc_signal *sigs;
    unsigned nsigs;
};

static const struct dbc_frame *dbc_find(const struct dbc_read *d, unsigned long id)
{
    for (unsigned i = 0; i < d->count; i++) {
        if (d->frames[i].id == id) {
            return &d->frames[i];
        }
    }
    return NULL;
}

static int dbc_signal(const struct dbc_frame *f, const char *name)
{
    for (unsigned i = 0; i < f->nsig; i++) {
        if (strcmp(f->sig[i].name, name) == 0) {
            return (int)i;
        }
    }
    return -1;
}

/* Bits of a signal in payload order, DBC numbering (Intel: start is the
 * LSB, counting up; Motorola: start is the MSB, counting down the byte and
 * on to the next byte's bit 7). Marks them in f->used. */
static void dbc_place(struct dbc_frame *f, const char *name, unsigned start, unsigned length, char order)
{
    unsigned bit = start;
    for (unsigned i = 0; i < length; i++) {
        if (bit >= 8 * f->len) {
            violated("DBC: signal %s (%u|%u@%c) reaches past the %u bytes of %s", name, start, length, order, f->len,
                     f->name);
        }
        if (f->used[bit / 8] & (1u << (bit % 8))) {
            violated("DBC: signal %s (%u|%u@%c) overlaps another signal of %s at bit %u", name, start, length, order,
                     f->name, bit);
        }
        f->used[bit / 8] |= (uint8_t)(1u << (bit % 8));
        if (order == '1') {
            bit++;
        } else if (bit % 8 == 0) {
            bit += 15;
        } else {
            bit--;
        }
    }
}

static void dbc_bo(struct dbc_read *d, const char *line)
{
    struct dbc_frame *f;
    unsigned long id;
    unsigned len;
    int name_at = 0, name_end = 0, used = 0;
    char node[64];
    if (sscanf(line, "BO_ %lu %n%*[A-Za-z0-9_]%n: %u %63s%n", &id, &name_at, &name_end, &len, node, &used) != 3 ||
        line[used] != '\0') {
        violated("DBC: malformed frame line: %s", line);
    }
    if (!c_identifier(line + name_at, (size_t)(name_end - name_at)) || !c_identifier(node, strlen(node))) {
        violated("DBC: frame or node name is not a C identifier of at most %d characters: %s", CAN_MAP_NAME_MAX, line);
    }
    if ((id & 0x80000000ul) ? (id & ~0x80000000ul) > URRT_CAN_EFF_MAX : id > URRT_CAN_SFF_MAX) {
        violated("DBC: frame id %lu is not a valid 11-bit or flagged 29-bit id: %s", id, line);
    }
    if (!urrt_can_length_valid(len, true)) {
        violated("DBC: frame length %u is not a CAN length: %s", len, line);
    }
    if (dbc_find(d, id) != NULL) {
        violated("DBC: frame id %lu appears twice", id);
    }
    for (unsigned i = 0; i < d->count; i++) {
        if (strlen(d->frames[i].name) == (size_t)(name_end - name_at) &&
            memcmp(d->frames[i].name, line + name_at, (size_t)(name_end - name_at)) == 0) {
            violated("DBC: frame name %s appears twice", d->frames[i].name);
        }
    }
    f = &d->frames[d->count++];
    memset(f, 0, sizeof *f);
    f->id = id;
    memcpy(f->name, line + name_at, (size_t)(name_end - name_at));
    snprintf(f->transmitter, sizeof f->transmitter, "%s", node);
    f->len = len;
    f->sig = d->sigs + d->nsigs;
}

static void dbc_sg(struct dbc_read *d, const char *line)
{
    struct dbc_frame *f;
    char name[64], factor[48], offset[48], min[48], max[48], receiver[64];
    unsigned start, length;
    char order, sign;
    int unit_at = 0, unit_end = 0, used = 0;
    double fa, of, lo, hi;
    if (d->count == 0) {
        violated("DBC: signal before any frame: %s", line);
    }
    f = &d->frames[d->count - 1];
    if (sscanf(line, " SG_ %63s : %u|%u@%c%c (%47[^,],%47[^)]) [%47[^|]|%47[^]]] \"%n%*[^\"]%n\" %63s%n", name, &start,
               &length, &order, &sign, factor, offset, min, max, &unit_at, &unit_end, receiver, &used) != 10 ||
        line[used] != '\0') {
        /* An empty unit: the %*[^"] above matches nothing and stops the scan. */
        if (sscanf(line, " SG_ %63s : %u|%u@%c%c (%47[^,],%47[^)]) [%47[^|]|%47[^]]] \"\" %63s%n", name, &start,
                   &length, &order, &sign, factor, offset, min, max, receiver, &used) != 10 ||
            line[used] != '\0') {
            violated("DBC: malformed signal line: %s", line);
        }
    }
    if (!c_identifier(name, strlen(name)) || !c_identifier(receiver, strlen(receiver))) {
        violated("DBC: signal or receiver name is not a C identifier: %s", line);
    }
    if (length < 1 || length > 64 || (order != '0' && order != '1') || (sign != '+' && sign != '-')) {
        violated("DBC: signal length, byte order or sign: %s", line);
    }
    if (!finite_number(factor, &fa) || fa == 0 || !finite_number(offset, &of) || !finite_number(min, &lo) ||
        !finite_number(max, &hi) || lo > hi) {
        violated("DBC: signal scaling (factor non-zero, everything finite, min <= max): %s", line);
    }
    if (dbc_signal(f, name) >= 0) {
        violated("DBC: signal %s appears twice in %s", name, f->name);
    }
    dbc_place(f, name, start, length, order);
    snprintf(f->sig[f->nsig].name, sizeof f->sig[0].name, "%s", name);
    snprintf(f->sig[f->nsig].receiver, sizeof f->sig[0].receiver, "%s", receiver);
    f->sig[f->nsig++].len = length;
    d->nsigs++;
}

/* A quoted string from *p (at the opening quote): backslash escapes only
 * '"' and '\'. Returns the position after the closing quote. */
static const char *dbc_string(const char *p, const char *line)
{
    if (*p != '"') {
        violated("DBC: expected a string: %s", line);
    }
    for (p++; *p != '"'; p++) {
        if (*p == '\0') {
            violated("DBC: unterminated string: %s", line);
        }
        if (*p == '\\') {
            p++;
            if (*p != '"' && *p != '\\') {
                violated("DBC: unknown escape in a string: %s", line);
            }
        }
    }
    return p + 1;
}

/* "ID NAME" of a CM_ SG_, VAL_ or SIG_VALTYPE_ line: both must exist. */
static const char *dbc_ref(const struct dbc_read *d, const char *p, const char *line, unsigned *sig_len)
{
    unsigned long id;
    char name[64];
    int used = 0;
    const struct dbc_frame *f;
    int s;
    if (sscanf(p, "%lu %63[A-Za-z0-9_]%n", &id, name, &used) != 2) {
        violated("DBC: expected a frame id and a signal name: %s", line);
    }
    f = dbc_find(d, id);
    if (f == NULL || (s = dbc_signal(f, name)) < 0) {
        violated("DBC: reference to a frame or signal that does not exist: %s", line);
    }
    if (sig_len != NULL) {
        *sig_len = f->sig[s].len;
    }
    return p + used;
}

static void dbc_other(const struct dbc_read *d, const char *line)
{
    const char *p;
    unsigned long id;
    int used = 0;
    if (strncmp(line, "CM_ SG_ ", 8) == 0) {
        p = dbc_ref(d, line + 8, line, NULL);
        p = dbc_string(p + (*p == ' '), line);
    } else if (strncmp(line, "CM_ BO_ ", 8) == 0) {
        if (sscanf(line + 8, "%lu %n", &id, &used) != 1 || dbc_find(d, id) == NULL) {
            violated("DBC: comment on a frame that does not exist: %s", line);
        }
        p = dbc_string(line + 8 + used, line);
    } else if (strncmp(line, "CM_ BU_ ", 8) == 0) {
        p = strchr(line, '"');
        p = dbc_string(p ? p : line, line);
    } else if (strncmp(line, "CM_ ", 4) == 0) {
        p = dbc_string(line + 4, line);
    } else if (strncmp(line, "VAL_ ", 5) == 0) {
        p = dbc_ref(d, line + 5, line, NULL);
        while (*p == ' ' && p[1] != ';') {
            char *end;
            strtoll(p + 1, &end, 10);
            if (end == p + 1 || *end != ' ') {
                violated("DBC: value table entry: %s", line);
            }
            p = dbc_string(end + 1, line);
        }
        if (strcmp(p, " ;") != 0) {
            violated("DBC: value table end: %s", line);
        }
        return;
    } else if (strncmp(line, "SIG_VALTYPE_ ", 13) == 0) {
        unsigned len = 0;
        p = dbc_ref(d, line + 13, line, &len);
        if (!(strcmp(p, " : 1;") == 0 && len == 32) && !(strcmp(p, " : 2;") == 0 && len == 64)) {
            violated("DBC: float type does not match the signal length %u: %s", len, line);
        }
        return;
    } else if (strncmp(line, "BA_ \"", 5) == 0 && strstr(line, "\" BO_ ") != NULL) {
        if (sscanf(strstr(line, "\" BO_ ") + 6, "%lu", &id) != 1 || dbc_find(d, id) == NULL) {
            violated("DBC: attribute of a frame that does not exist: %s", line);
        }
        return;
    } else {
        return; /* headers and definitions: fixed text */
    }
    if (strcmp(p, ";") != 0) {
        violated("DBC: comment not closed by '\";': %s", line);
    }
}

/* The order of the frames and who sends them: the map's [frame]s and the
 * heartbeat, sent by the gateway's node, then its [input]s, sent by the PLC
 * ([can] receiver) to the gateway, each as configured. */
static void dbc_directions(const struct dbc_read *d, const struct can_map *map)
{
    size_t sent = d->count;
    for (unsigned i = 0; i < d->count; i++) {
        if (strcmp(d->frames[i].name, CAN_MAP_HEARTBEAT_NAME) == 0) {
            sent = i + 1;
        }
    }
    if (sent != map->frame_count + 1 || d->count != sent + map->input_count) {
        violated("DBC: %u frames, the heartbeat at %zu; the map has %zu frames and %zu inputs", d->count, sent,
                 map->frame_count, map->input_count);
    }
    for (size_t i = 0; i < sent; i++) {
        if (strcmp(d->frames[i].transmitter, map->node) != 0) {
            violated("DBC: frame %s is sent by %s, not the gateway's node %s", d->frames[i].name,
                     d->frames[i].transmitter, map->node);
        }
    }
    for (size_t i = 0; i < map->input_count; i++) {
        const struct can_map_frame *in = &map->inputs[i];
        const struct dbc_frame *f = &d->frames[sent + i];
        unsigned long id = in->extended ? (unsigned long)in->id | 0x80000000ul : (unsigned long)in->id;
        if (f->id != id || strcmp(f->name, in->name) != 0 || f->len != in->len || f->nsig != in->count ||
            strcmp(f->transmitter, map->receiver) != 0) {
            violated("DBC: [input %s] is BO_ %lu %s: %u %s with %u signals; configured %lu, %u bytes, %zu signals, "
                     "sent by %s", in->name, f->id, f->name, f->len, f->transmitter, f->nsig, id, (unsigned)in->len,
                     in->count, map->receiver);
        }
        for (unsigned k = 0; k < f->nsig; k++) {
            if (strcmp(f->sig[k].receiver, map->node) != 0 || strcmp(f->sig[k].name, in->meta[k].name) != 0) {
                violated("DBC: [input %s] signal %s is received by %s, not the gateway's node %s", in->name,
                         f->sig[k].name, f->sig[k].receiver, map->node);
            }
        }
    }
}

static void dbc_check(const char *text, size_t len, const struct can_map *map)
{
    struct dbc_read d;
    char *copy = strndup(text, len);
    char *save = NULL;
    if (copy == NULL || strlen(copy) != len) {
        violated("DBC text holds a NUL byte");
    }
    no_control("the DBC", text, len, true);
    memset(&d, 0, sizeof d);
    {
        unsigned frames = 0, signals = 0;
        for (const char *p = text; p != NULL && p < text + len;) {
            frames += strncmp(p, "BO_ ", 4) == 0;
            signals += strncmp(p, " SG_ ", 5) == 0;
            p = memchr(p, '\n', (size_t)(text + len - p));
            p = p != NULL ? p + 1 : NULL;
        }
        d.frames = calloc(frames + 1, sizeof *d.frames);
        d.sigs = calloc(signals + 1, sizeof *d.sigs);
        if (d.frames == NULL || d.sigs == NULL) {
            abort();
        }
    }
    for (char *line = strtok_r(copy, "\n", &save); line != NULL; line = strtok_r(NULL, "\n", &save)) {
        if (strchr(line, '\t') != NULL && line[0] != '\t') {
            violated("DBC: a tab outside the NS_ list: %s", line);
        }
        if (strncmp(line, "BO_ ", 4) == 0) {
            dbc_bo(&d, line);
        } else if (strncmp(line, " SG_ ", 5) == 0) {
            dbc_sg(&d, line);
        } else {
            dbc_other(&d, line);
        }
    }
    dbc_directions(&d, map);
    for (unsigned i = 0; i < d.count; i++) {
        if (d.frames[i].nsig == 0) {
            violated("DBC: frame %s has no signal", d.frames[i].name);
        }
    }
    free(d.frames);
    free(d.sigs);
    free(copy);
}

static char *write_dbc(const gw_config *cfg, size_t *len)
{
    char *text = NULL;
    FILE *out = open_memstream(&text, len);
    if (out == NULL) {
        abort();
    }
    if (dbc_write(out, &cfg->can, cfg->path) != 0) {
        violated("dbc_write failed on an accepted configuration");
    }
    fclose(out);
    return text;
}

/* ---- the C tables ------------------------------------------------------------------- */

/* --print-c-tables, as urrt-gateway writes it: written, without control
 * characters, with one urrt_gateway_inputs entry per [input]. */
static void check_ctables(const gw_config *cfg)
{
    struct can_ctables_robot robots[GW_MAX_ROBOTS];
    char *text = NULL;
    size_t len = 0;
    size_t entries = 0;
    char want[64];
    FILE *out = open_memstream(&text, &len);
    if (out == NULL) {
        abort();
    }
    for (unsigned i = 0; i < cfg->robot_count && i < GW_MAX_ROBOTS; i++) {
        robots[i].rtde = cfg->robots[i].source == GW_SOURCE_RTDE;
        robots[i].frequency = cfg->robots[i].rtde_frequency;
        robots[i].port = cfg->robots[i].port;
    }
    if (can_ctables_write(out, &cfg->can, cfg->can_run, cfg->co_run, robots, cfg->path) != 0) {
        violated("can_ctables_write failed on an accepted configuration");
    }
    fclose(out);
    no_control("the C tables", text, len, false);
    for (const char *p = strstr(text, "\n    {input_"); p != NULL; p = strstr(p + 1, "\n    {input_")) {
        entries++;
    }
    snprintf(want, sizeof want, "urrt_gateway_inputs[%zu] = {", cfg->can.input_count);
    if (entries != cfg->can.input_count || (cfg->can.input_count > 0) != (strstr(text, want) != NULL)) {
        violated("C tables: %zu urrt_gateway_inputs entries for %zu [input]s", entries, cfg->can.input_count);
    }
    free(text);
}

/* ---- the scheduler ------------------------------------------------------------------- */

struct emitted {
    const struct can_map *map;
    unsigned long frames;
};

static void on_frame(void *ctx, const urrt_can_frame *fr, uint64_t now_us)
{
    (void)now_us;
    struct emitted *e = ctx;
    const struct can_map *map = e->map;
    e->frames++;
    if (fr->id == map->hb_id && fr->extended == map->hb_extended) {
        if (fr->len != URRT_CANTX_HB_LEN || fr->fd) {
            violated("heartbeat sent with length %u, fd %d", fr->len, fr->fd);
        }
        return;
    }
    for (size_t i = 0; i < map->frame_count; i++) {
        const struct can_map_frame *f = &map->frames[i];
        if (f->id == fr->id && f->extended == fr->extended) {
            if (f->len != fr->len || f->fd != fr->fd) {
                violated("frame %s sent with length %u fd %d, configured %u fd %d", f->name, fr->len, fr->fd, f->len,
                         f->fd);
            }
            return;
        }
    }
    violated("a frame with id 0x%X that is not configured was sent", (unsigned)fr->id);
}

/* Every field present and set to v (a bit mask field that is not a whole
 * number goes out as NaN). */
static void fill_state(urrt_state *st, double v)
{
    urrt_state_clear(st);
#define FILL(ID, name, count, c1, c3, unit, since, desc)  \
    for (unsigned i = 0; i < (count); i++) {              \
        st->name[i] = v;                                  \
    }
    URRT_FIELDS(FILL)
#undef FILL
    st->present = (UINT64_C(1) << URRT_FIELD_COUNT) - 1;
    st->generation = URRT_GEN_3X;
    st->length = 1220;
}

static void run_schedule(const struct can_map *map, struct can_run *run)
{
    static const double values[] = {0.0, 1.5, -7.0, 1e300, -1e300, 4294967296.0, NAN, INFINITY};
    struct emitted e = {map, 0};
    urrt_canlink_stats stats;
    uint64_t now = 1000000;
    memset(&stats, 0, sizeof stats);
    can_run_start(run, now);
    for (size_t k = 0; k < sizeof values / sizeof values[0]; k++) {
        urrt_state st;
        fill_state(&st, values[k]);
        for (size_t r = 0; r < map->robot_count; r++) {
            urrt_cantx_on_packet(can_run_tx(run), r, &st, now);
        }
        can_run_due(run, now, &stats, on_frame, &e);
        now += 4000;
        can_run_due(run, now, &stats, on_frame, &e);
        stats.sent = e.frames;
    }
    /* A stall past every stale_after_ms, then a robot that went away. */
    now += 61000000;
    can_run_due(run, now, &stats, on_frame, &e);
    urrt_cantx_robot_link(can_run_tx(run), 0, false);
    now += 1000000;
    can_run_due(run, now, &stats, on_frame, &e);
    if (urrt_cantx_deadline(can_run_tx(run)) == URRT_CANTX_NEVER) {
        violated("nothing scheduled after start: the heartbeat is always due again");
    }
    if (e.frames == 0) {
        violated("no frame sent in 62 s, not even a heartbeat");
    }
}

/* ---- the CAN mapping, with the bad lines left out ------------------------------------- */

/* The loader rejects a file for any mistake, so few mutated files reach the
 * DBC writer that way. Here the lines the loader names are left out (each
 * becomes a blank line, so that the others keep their numbers) and the file
 * is loaded again, through the same entry point, a few times over; a file
 * without a robot gets one at its end. Whatever is then accepted is written
 * and run: the DBC writer and the scheduler see far more mappings. */
#define CAN_ONLY_ROUNDS 4

/* Blanks every line a message of l names; false when none is named. */
static bool blank_named_lines(char *text, size_t size, const struct loaded *l)
{
    bool any = false;
    for (const char *m = l->messages; m != NULL && *m != '\0';) {
        const char *nl = strchr(m, '\n');
        long line = 0;
        if (sscanf(m, NAME ":%ld:", &line) == 1 && line > 0) {
            long at = 1;
            for (size_t i = 0; i < size; i++) {
                if (at == line && text[i] != '\n') {
                    text[i] = ' ';
                    any = true;
                }
                at += text[i] == '\n';
            }
        }
        m = nl != NULL ? nl + 1 : NULL;
    }
    return any;
}

static void check_can_only(const char *data, size_t size)
{
    static const char robot[] = "\n[robot arm]\nhost = h\nversion = 3.10\n";
    char *text = malloc(size + sizeof robot);
    size_t len = size;
    struct loaded l;
    if (text == NULL) {
        abort();
    }
    memcpy(text, data, size);
    load(&l, text, len);
    for (int round = 0; round < CAN_ONLY_ROUNDS && l.errors > 0; round++) {
        bool changed = blank_named_lines(text, len, &l);
        if (l.cfg.robot_count == 0 && len == size) {
            memcpy(text + len, robot, sizeof robot - 1);
            len += sizeof robot - 1;
            changed = true;
        }
        unload(&l);
        if (!changed) {
            free(text);
            return;
        }
        load(&l, text, len);
    }
    if (l.errors == 0 && l.cfg.can_run != NULL) {
        size_t dbc_len;
        char *dbc = write_dbc(&l.cfg, &dbc_len);
        dbc_check(dbc, dbc_len, &l.cfg.can);
        free(dbc);
        check_ctables(&l.cfg);
        run_schedule(&l.cfg.can, l.cfg.can_run);
    }
    unload(&l);
    free(text);
}

/* ---- the entry point ------------------------------------------------------------------ */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct loaded a, b;
    long lines = count_lines((const char *)data, size);
    current_input = (const char *)data;
    current_size = size;

    load(&a, (const char *)data, size);
    load(&b, (const char *)data, size);
    if (a.errors != b.errors || a.messages_len != b.messages_len || memcmp(a.messages, b.messages, a.messages_len) != 0) {
        violated("two loads of the same bytes differ:\n%s---\n%s", a.messages, b.messages);
    }
    if (a.errors < 0) {
        violated("negative error count %d", a.errors);
    } else if (a.errors > 0) {
        check_messages(&a, lines);
    } else {
        if (a.messages_len != 0) {
            violated("accepted, but with messages: %s", a.messages);
        }
        check_accepted(&a.cfg);
        if (can_map_enabled(&a.cfg.can)) {
            size_t len_a, len_b;
            char *dbc_a = write_dbc(&a.cfg, &len_a);
            char *dbc_b = write_dbc(&b.cfg, &len_b);
            if (len_a != len_b || memcmp(dbc_a, dbc_b, len_a) != 0) {
                violated("two loads of the same bytes give different DBCs");
            }
            dbc_check(dbc_a, len_a, &a.cfg.can);
            free(dbc_a);
            free(dbc_b);
            check_ctables(&a.cfg);
            run_schedule(&a.cfg.can, a.cfg.can_run);
        }
    }
    check_can_only((const char *)data, size);
    unload(&a);
    unload(&b);
    return 0;
}
