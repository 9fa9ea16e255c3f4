/* SPDX-License-Identifier: MIT */
/* config.c: the urrt-gateway configuration file (see config.h). Values are
 * read by conf.h's parsers, keys described by tables: one per section. */
#define _GNU_SOURCE
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "can_run.h"
#include "rtde_only.h"

#define CONFIG_MAX_KEYS 64

/* Messages are printed causes first: what is wrong on a line (syntax, an
 * unknown section or key, a bad value) before what the whole file then
 * lacks ("[robot a] has no host", "no robot"), each group in line order. */
enum { RANK_LINE = 0, RANK_FILE = 1 };

typedef struct config_message {
    int rank;
    int line;
    int order;
    char *text;
} config_message;

struct config_ctx {
    const char *path;
    FILE *err;
    int errors;
    config_message *messages;   /* printed by rank and line at the end */
    int rank;                 /* RANK_FILE once the whole-file checks run */
    int line;                 /* of the line being read */
    FILE *file;
    gw_config *cfg;
    bool in_section;          /* a section header was seen: keys are not outside of any */
    const config_section *section; /* NULL before the first header or after a bad one */
    bool section_ok;          /* keys of a bad section are skipped: one error is enough */
    char section_label[64 + 1 + 256]; /* "robot arm1": kind and name, blanks trimmed */
    struct can_map_frame *frame; /* of the current [frame NAME] */
    struct { char name[64]; int line; } keys[CONFIG_MAX_KEYS];
    unsigned key_count;
    int *seen_line;           /* per table entry: line of its first header, 0 if none */
};

static const char *const kind_names[GW_KIND_COUNT] = {"state", "joints", "tool", "status", "rtde", "gateway"};

const char *gw_kind_name(gw_kind kind)
{
    return (unsigned)kind < GW_KIND_COUNT ? kind_names[kind] : "?";
}

/* ---- the one error channel ------------------------------------------------------ */

void config_error(config_ctx *ctx, int line, const char *fmt, ...)
{
    va_list ap;
    char *text = NULL;
    config_message *grown;
    va_start(ap, fmt);
    if (vasprintf(&text, fmt, ap) < 0) {
        text = NULL;
    }
    va_end(ap);
    grown = realloc(ctx->messages, (size_t)(ctx->errors + 1) * sizeof *ctx->messages);
    if (grown == NULL || text == NULL) {
        fprintf(stderr, "urrt-gateway: out of memory reading the configuration\n");
        exit(1);
    }
    ctx->messages = grown;
    ctx->messages[ctx->errors] = (config_message){ctx->rank, line, ctx->errors, text};
    ctx->errors++;
}

static int by_rank_and_line(const void *a, const void *b)
{
    const config_message *x = a, *y = b;
    if (x->rank != y->rank) {
        return x->rank - y->rank;
    }
    return x->line != y->line ? (x->line > y->line) - (x->line < y->line) : x->order - y->order;
}

/* A message echoes the file's text: control characters (a tab, an escape
 * sequence, a carriage return that would overwrite the line on a terminal)
 * are written as \xNN, so each message is one plain line. */
static void put_message(FILE *out, const char *text)
{
    for (; *text != '\0'; text++) {
        unsigned char c = (unsigned char)*text;
        if (c < 0x20 || c == 0x7f) {
            fprintf(out, "\\x%02X", c);
        } else {
            fputc(c, out);
        }
    }
    fputc('\n', out);
}

static void print_errors(config_ctx *ctx)
{
    /* Within a rank, file-wide messages (line 0) first, then in line order.
     * No message: no array, and qsort must not be given NULL. */
    if (ctx->errors > 0) {
        qsort(ctx->messages, (size_t)ctx->errors, sizeof *ctx->messages, by_rank_and_line);
    }
    for (int i = 0; i < ctx->errors; i++) {
        if (ctx->messages[i].line > 0) {
            fprintf(ctx->err, "%s:%d: ", ctx->path, ctx->messages[i].line);
        } else {
            fprintf(ctx->err, "%s: ", ctx->path);
        }
        put_message(ctx->err, ctx->messages[i].text);
        free(ctx->messages[i].text);
    }
    free(ctx->messages);
    ctx->messages = NULL;
}


static char *xstrdup(const char *s)
{
    char *p = strdup(s);
    if (p == NULL) {
        fprintf(stderr, "urrt-gateway: out of memory reading the configuration\n");
        exit(1);
    }
    return p;
}

static void replace_string(char **slot, const char *value)
{
    free(*slot);
    *slot = xstrdup(value);
}

/* The table's defaults into obj, as if the file said them first. One that
 * does not parse is a bug of the table: said, not hidden. */
static void set_defaults(config_ctx *ctx, const struct conf_key *keys, size_t count, void *obj)
{
    char why[CONF_WHY_MAX];
    if (!conf_key_defaults(keys, count, obj, why, sizeof why)) {
        config_error(ctx, 0, "%s", why);
    }
}

/* ---- [gateway] ------------------------------------------------------------------ */

bool gw_parse_log_level(const char *text, urrt_log_level *level)
{
    static const struct { const char *name; urrt_log_level level; } levels[] = {
        {"err", URRT_LOG_ERR}, {"error", URRT_LOG_ERR}, {"warning", URRT_LOG_WARNING},
        {"notice", URRT_LOG_NOTICE}, {"info", URRT_LOG_INFO}, {"debug", URRT_LOG_DEBUG},
    };
    for (size_t i = 0; i < sizeof levels / sizeof levels[0]; i++) {
        if (strcmp(text, levels[i].name) == 0) {
            *level = levels[i].level;
            return true;
        }
    }
    return false;
}

static bool set_log_level(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                          size_t n)
{
    gw_config *cfg = obj;
    (void)key, (void)at;
    return gw_parse_log_level(value, &cfg->log_level) ||
           conf_fail(why, n, "log_level must be err, warning, notice, info or debug, not \"%s\"", value);
}

/* off, or an absolute file name the gateway can rename a PATH.tmp onto
 * (a service's working directory is /: a relative name would mislead). */
static bool set_metrics_file(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                             size_t n)
{
    gw_config *cfg = obj;
    size_t len = strlen(value);
    (void)key, (void)at;
    if (!conf_printable(value, why, n)) {
        return false;
    }
    free(cfg->metrics_file);
    cfg->metrics_file = NULL;
    if (strcmp(value, "off") == 0) {
        return true;
    }
    if (value[0] != '/' || value[len - 1] == '/') {
        return conf_fail(why, n, "metrics_file = \"%s\": give off or a file's absolute path, e.g. "
                         "/run/urrt-metrics/gateway.prom", value);
    }
    cfg->metrics_file = xstrdup(value);
    return true;
}

static const struct conf_key gateway_keys[] = {
    {"log_level", CONF_FN, 0, 0, 0, 0, set_log_level, NULL, false, "err|warning|notice|info|debug", "notice", NULL,
     "the least severe message logged"},
    {"summary", CONF_BOOL, CONF_FIELD(gw_config, summary), 0, 0, NULL,
     "%1$s must be yes or no (or true/false, on/off, 1/0), not \"%2$s\"", false, NULL, "no", NULL,
     "one status line per robot each second on stdout"},
    {"metrics_file", CONF_FN, 0, 0, 0, 0, set_metrics_file, NULL, false, "off|PATH", "off", NULL,
     "a Prometheus textfile (node_exporter) written every metrics_interval, via PATH.tmp and a rename"},
    {"metrics_interval", CONF_MS, CONF_FIELD(gw_config, metrics_interval_ms), 100, 3600000, NULL, NULL, false, NULL,
     "5 s", NULL, "how often metrics_file is written"},
};

/* ---- [lcm] ------------------------------------------------------------------------ */

/* ?ttl=N&recv_buf_size=N&transmit_only=...: the options LCM's udpm knows. */
static bool check_udpm_options(const char *url, const char *options, char *why, size_t n)
{
    char opts[256];
    uint64_t v;
    snprintf(opts, sizeof opts, "%s", options);
    for (char *save = NULL, *opt = strtok_r(opts, "&", &save); opt != NULL; opt = strtok_r(NULL, "&", &save)) {
        char *eq = strchr(opt, '=');
        if (eq == NULL) {
            return conf_fail(why, n, "url \"%s\": option \"%s\" has no value", url, opt);
        }
        *eq = '\0';
        if (strcmp(opt, "ttl") == 0) {
            if (!conf_uint(eq + 1, 0, 255, &v, NULL, 0)) {
                return conf_fail(why, n, "url \"%s\": ttl must be 0 to 255 (0: this host only, 1: the LAN)", url);
            }
        } else if (strcmp(opt, "recv_buf_size") == 0) {
            if (!conf_uint(eq + 1, 1, UINT32_MAX, &v, NULL, 0)) {
                return conf_fail(why, n, "url \"%s\": recv_buf_size must be a number of bytes", url);
            }
        } else if (strcmp(opt, "transmit_only") != 0) {
            return conf_fail(why, n, "url \"%s\": unknown udpm option \"%s\" (ttl, recv_buf_size, transmit_only)", url, opt);
        }
    }
    return true;
}

/* udpm://GROUP:PORT?opt=v&...: the group must be IPv4 multicast. */
static bool check_udpm(const char *url, char *why, size_t n)
{
    unsigned a, b, c, d, port;
    int used = 0;
    const char *p = url + 7;
    if (*p != '\0' && *p != '?') {
        if (sscanf(p, "%3u.%3u.%3u.%3u:%5u%n", &a, &b, &c, &d, &port, &used) != 5 ||
            (p[used] != '\0' && p[used] != '?') || a > 255 || b > 255 || c > 255 || d > 255 || port == 0 ||
            port > 65535) {
            return conf_fail(why, n, "url \"%s\": udpm needs GROUP:PORT, e.g. 239.255.76.67:7667", url);
        }
        if (a < 224 || a > 239) {
            return conf_fail(why, n, "url \"%s\": %u.%u.%u.%u is not a multicast group (224.0.0.0 to 239.255.255.255)",
                       url, a, b, c, d);
        }
        p += used;
    }
    return *p != '?' || check_udpm_options(url, p + 1, why, n);
}

/* PROVIDER://...: udpm is checked here; other providers for the scheme
 * only: LCM validates them when the gateway starts. */
static bool set_lcm_url(void *obj, const struct conf_key *key, const char *url, struct conf_at at, char *why,
                        size_t n)
{
    static const char *const providers[] = {"udpm", "file", "memq", "tcpq", "mpudpm"};
    gw_lcm_config *lcm = obj;
    const char *sep = strstr(url, "://");
    bool known = false;
    (void)key;
    if (!conf_printable(url, NULL, 0)) {
        /* It is printed at start and by --check-config. */
        return conf_fail(why, n, "url \"%s\": no control characters", url);
    }
    if (sep == NULL) {
        return conf_fail(why, n, "url \"%s\" is not an LCM URL (provider://address?options), e.g. %s", url,
                   GW_DEFAULT_LCM_URL);
    }
    for (size_t i = 0; i < sizeof providers / sizeof providers[0]; i++) {
        known |= strlen(providers[i]) == (size_t)(sep - url) && strncmp(url, providers[i], (size_t)(sep - url)) == 0;
    }
    if (!known) {
        return conf_fail(why, n, "url \"%s\": unknown LCM provider \"%.*s\" (udpm, file, memq, tcpq, mpudpm)", url,
                   (int)(sep - url), url);
    }
    if (strncmp(url, "udpm://", 7) == 0 && !check_udpm(url, why, n)) {
        return false;
    }
    replace_string(&lcm->url, url);
    lcm->url_line = at.line;
    return true;
}

/* "every", "off" or a rate (conf_rate_hz: "50 Hz", or 50: a bare number is Hz). */
static bool parse_rate(const char *key, const char *value, gw_rate *out, char *why, size_t n)
{
    if (strcmp(value, "every") == 0 || strcmp(value, "off") == 0) {
        *out = (gw_rate){value[0] == 'e' ? GW_RATE_EVERY : GW_RATE_OFF, 0};
        return true;
    }
    if (!conf_rate_hz(value, 0.0, INFINITY, &out->hz, NULL, 0)) {
        return conf_fail(why, n, "%s must be \"every\", \"off\" or a rate such as \"50 Hz\" (a bare 50 is Hz "
                         "too), not \"%s\"", key, value);
    }
    if (out->hz < 0.01 || out->hz > GW_ROBOT_MAX_RATE_HZ) {
        return conf_fail(why, n, "%s %g Hz is out of range: from 0.01 Hz to %u Hz (the fastest robot)", key,
                         out->hz, GW_ROBOT_MAX_RATE_HZ);
    }
    out->mode = GW_RATE_HZ;
    return true;
}

/* KIND_channel, KIND_rate: the kind from the key's name. */
static unsigned kind_of(const char *key)
{
    unsigned k = 0;
    while (k < GW_KIND_COUNT - 1 && strncmp(key, kind_names[k], strlen(kind_names[k])) != 0) {
        k++;
    }
    return k;
}

static bool set_lcm_channel(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                            size_t n)
{
    gw_lcm_config *lcm = obj;
    unsigned k = kind_of(key->name);
    char reason[CONF_WHY_MAX];
    if (!conf_name(value, CONF_NAME_DASH | CONF_NAME_DOTS, 64, reason, sizeof reason)) {
        return conf_fail(why, n, "%s \"%s\" %s", key->name, value, reason);
    }
    replace_string(&lcm->channel[k], value);
    lcm->channel_line[k] = at.line;
    return true;
}

static bool set_lcm_rate(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                         size_t n)
{
    gw_lcm_config *lcm = obj;
    unsigned k = kind_of(key->name);
    gw_rate rate;
    if (!parse_rate(key->name, value, &rate, why, n)) {
        return false;
    }
    if (k == GW_KIND_GATEWAY && rate.mode == GW_RATE_EVERY) {
        return conf_fail(why, n, "gateway_rate is a report rate: \"off\" or N Hz (default 1 Hz), not \"every\"");
    }
    if (k == GW_KIND_GATEWAY && rate.mode == GW_RATE_HZ && rate.hz > 100) {
        return conf_fail(why, n, "gateway_rate %g Hz is out of range: at most 100 Hz", rate.hz);
    }
    lcm->rate[k] = rate;
    lcm->rate_line[k] = at.line;
    return true;
}

/* A kind of message: its channel suffix and its rate (kind_names' order). */
#define LCM_KIND_KEYS(kind, channel, rate, rate_form)                                                           \
    {kind "_channel", CONF_FN, 0, 0, 0, 0, set_lcm_channel, NULL, false, "SUFFIX", channel, NULL,                 \
     "the channel NAME.SUFFIX of " kind " messages"},                                                          \
    {kind "_rate", CONF_FN, 0, 0, 0, 0, set_lcm_rate, NULL, false, rate_form, rate, NULL,                         \
     "how often " kind " messages go out (N Hz on the controller's clock)"}

static const struct conf_key lcm_keys[] = {
    {"url", CONF_FN, 0, 0, 0, 0, set_lcm_url, NULL, false, "PROVIDER://...", GW_DEFAULT_LCM_URL, NULL,
     "the LCM URL to publish on"},
    LCM_KIND_KEYS("state", "STATE", "every", "every|N Hz|off"),
    LCM_KIND_KEYS("joints", "JOINTS", "every", "every|N Hz|off"),
    LCM_KIND_KEYS("tool", "TOOL", "every", "every|N Hz|off"),
    LCM_KIND_KEYS("status", "STATUS", "10 Hz", "every|N Hz|off"),
    LCM_KIND_KEYS("rtde", "RTDE", "every", "every|N Hz|off"),
    LCM_KIND_KEYS("gateway", "GATEWAY", "1 Hz", "N Hz|off"),
};

static void lcm_finish(config_ctx *ctx, gw_config *cfg)
{
    gw_lcm_config *lcm = &cfg->lcm;
    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        for (unsigned j = 0; j < k; j++) {
            if (strcmp(lcm->channel[j], lcm->channel[k]) == 0) {
                /* Blame the line that set it; of two, the later one. */
                unsigned culprit = lcm->channel_line[k] >= lcm->channel_line[j] ? k : j;
                unsigned other = culprit == k ? j : k;
                config_error(ctx, lcm->channel_line[culprit],
                             "%s_channel \"%s\" is also the channel of %s messages%s: each kind needs its own",
                             kind_names[culprit], lcm->channel[culprit], kind_names[other],
                             lcm->channel_line[other] ? "" : " (its default)");
            }
        }
        if (lcm->rate[k].mode != GW_RATE_HZ) {
            continue;
        }
        for (unsigned r = 0; r < cfg->robot_count; r++) {
            const gw_robot_config *robot = &cfg->robots[r];
            if (lcm->rate[k].hz > robot->max_rate_hz) {
                config_error(ctx, lcm->rate_line[k],
                             "%s_rate %g Hz is above the %u Hz robot \"%s\" sends (version %s, line %d); "
                             "use \"every\" or a lower rate",
                             kind_names[k], lcm->rate[k].hz, robot->max_rate_hz, robot->name,
                             robot->expected, robot->version_line);
            }
        }
    }
}

/* ---- [robot NAME] ------------------------------------------------------------------ */

/* What a version number implies, from lib's controller table: the message
 * size, and the packet rate. A version the sources give two sizes for (1.6)
 * is refused with both. */
static bool version_length(const char *text, uint32_t *length, unsigned *rate_hz, char *why, size_t n)
{
    const urrt_controller *found[2];
    uint32_t period_us = 0;
    int count = urrt_controller_find(text, strlen(text), found, 2, &period_us);
    if (count == 1) {
        *length = found[0]->length;
        *rate_hz = 1000000u / period_us;
        return true;
    }
    if (count == 2) {
        return conf_fail(why, n, "version \"%s\": %s controllers sent %u or %u bytes: give the length instead "
                   "(version = %u or %u)", text, text, (unsigned)found[0]->length, (unsigned)found[1]->length,
                   (unsigned)found[0]->length, (unsigned)found[1]->length);
    }
    if (count == 0) {
        return conf_fail(why, n, "version \"%s\": no known controller version: give the message size in bytes instead "
                   "(e.g. version = 1220)", text);
    }
    return conf_fail(why, n, "version \"%s\": expected auto, a controller version such as 5.10, or a message size in "
               "bytes", text);
}

static bool set_version(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                        size_t n)
{
    gw_robot_config *robot = obj;
    uint32_t length = 0;
    unsigned rate = 1000000u / urrt_period_min_us(0);
    char reason[CONF_WHY_MAX];
    (void)key;
    if (strchr(value, '.') != NULL) {
        if (!version_length(value, &length, &rate, why, n)) {
            return false;
        }
    } else if (strcmp(value, "auto") != 0) {
        if (!conf_u32(value, URRT_PACKET_MIN, URRT_PACKET_MAX, &length, reason, sizeof reason) ||
            (length - URRT_HEADER_SIZE) % 8 != 0) {
            return conf_fail(why, n, "version \"%s\": expected auto, a controller version such as 5.10, or a message "
                       "size in bytes (4 + 8n, %d to %d)%s%s", value, URRT_PACKET_MIN, URRT_PACKET_MAX,
                       CONF_IS_LEADING_ZERO(reason) ? ": " : "", CONF_IS_LEADING_ZERO(reason) ? reason : "");
        }
        rate = 1000000u / urrt_period_min_us(length);
    }
    robot->expected_length = length;
    robot->max_rate_hz = rate;
    replace_string(&robot->expected, value);
    robot->version_line = at.line;
    return true;
}

/* A host name, IPv4 or IPv6 address; HOST:PORT and [V6]:PORT are refused
 * here rather than by the resolver at run time, again and again. */
static bool set_host(void *obj, const struct conf_key *key, const char *host, struct conf_at at, char *why, size_t n)
{
    gw_robot_config *robot = obj;
    size_t len = strlen(host);
    const char *colon = strchr(host, ':');
    const char *close = strchr(host, ']');
    bool ok = len >= 1 && len <= 253;
    (void)key;
    if (host[0] == '[' && close != NULL) {
        return conf_fail(why, n, "host \"%s\": write the address without brackets (host = %.*s)%s%s%s", host,
                   (int)(close - host - 1), host + 1, close[1] == ':' ? " and the port apart (port = " : "",
                   close[1] == ':' ? close + 2 : "", close[1] == ':' ? ")" : "");
    }
    if (colon != NULL && strchr(colon + 1, ':') == NULL) {
        return conf_fail(why, n, "host \"%s\" is HOST:PORT: write host = %.*s and port = %s", host, (int)(colon - host),
                   host, colon + 1);
    }
    for (size_t i = 0; ok && i < len; i++) {
        unsigned char c = (unsigned char)host[i];
        ok = colon != NULL ? (isalnum(c) || c == ':' || c == '.' || c == '%') : (isalnum(c) || c == '-' || c == '.');
    }
    if (!ok) {
        return conf_fail(why, n, "host \"%s\" is not a host name, IPv4 or IPv6 address", host);
    }
    replace_string(&robot->host, host);
    robot->host_line = at.line;
    return true;
}

static bool set_port(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                     size_t n)
{
    gw_robot_config *robot = obj;
    uint32_t port;
    char reason[CONF_WHY_MAX];
    (void)key;
    if (!conf_u32(value, 1, 65535, &port, reason, sizeof reason)) {
        if (CONF_IS_LEADING_ZERO(reason)) {
            return conf_fail(why, n, "port = \"%s\": %s", value, reason);
        }
        return conf_fail(why, n, "port must be a whole number from 1 to 65535, not \"%s\"", value);
    }
    robot->port = (uint16_t)port;
    robot->port_line = at.line;
    return true;
}

static bool set_source(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                       size_t n)
{
    gw_robot_config *robot = obj;
    (void)key;
    if (strcmp(value, "realtime") == 0) {
        robot->source = GW_SOURCE_REALTIME;
    } else if (strcmp(value, "rtde") == 0) {
        robot->source = GW_SOURCE_RTDE;
    } else {
        return conf_fail(why, n, "source must be \"realtime\" (port 30003) or \"rtde\" (port 30004), not \"%s\"",
                         value);
    }
    robot->source_line = at.line;
    return true;
}

/* "auto" or a rate (conf_rate_hz: "125 Hz", or 125): RTDE streams at most at
 * the controller's own rate. */
static bool set_rtde_frequency(void *obj, const struct conf_key *key, const char *value, struct conf_at at,
                               char *why, size_t n)
{
    gw_robot_config *robot = obj;
    double hz;
    (void)key;
    if (strcmp(value, "auto") == 0) {
        robot->rtde_frequency = 0.0;
        robot->rtde_frequency_line = at.line;
        return true;
    }
    if (!conf_rate_hz(value, 0.0, INFINITY, &hz, NULL, 0)) {
        return conf_fail(why, n, "rtde_frequency must be \"auto\" or a rate such as \"125 Hz\" (a bare 125 is Hz "
                         "too), at most %g Hz, not \"%s\"", URRT_RTDE_HZ_E_SERIES, value);
    }
    if (hz > URRT_RTDE_HZ_E_SERIES) {
        return conf_fail(why, n, "rtde_frequency %g Hz is above %g Hz, the fastest any controller streams RTDE: "
                         "write rtde_frequency = %g Hz or less, or rtde_frequency = auto", hz,
                         URRT_RTDE_HZ_E_SERIES, URRT_RTDE_HZ_E_SERIES);
    }
    if (hz < 0.01) {
        return conf_fail(why, n, "rtde_frequency %g Hz is out of range: from 0.01 Hz to %g Hz, or auto", hz,
                         URRT_RTDE_HZ_E_SERIES);
    }
    robot->rtde_frequency = hz;
    robot->rtde_frequency_line = at.line;
    return true;
}

/* A list of RTDE-only variable names (comma or blank separated); the key
 * may be repeated, each line adding to the list (a line holds 198
 * characters, a recipe up to 2048 bytes of names). */
static bool set_rtde_values(void *obj, const struct conf_key *key, const char *value, struct conf_at at,
                            char *why, size_t n)
{
    gw_robot_config *robot = obj;
    const char *p = value;
    size_t count = robot->rtde_value_count;
    (void)key;
    if (strcmp(value, "none") == 0) {
        return true; /* the default */
    }
    while (*(p += strspn(p, ", \t")) != '\0') {
        size_t len = strcspn(p, ", \t");
        int var = urrt_rtde_var_find(p, len);
        char near[2 * URRT_RTDE_NAME_MAX + 16];
        if (var < 0 && urrt_field_find(p, len) >= 0) {
            return conf_fail(why, n, "rtde_values: \"%.*s\" is a RealTime field: it is published on NAME.STATE "
                             "already; list only RTDE-only values here, by their RTDE names", (int)len, p);
        }
        if (var < 0 && conf_suggest_value(p, len, near, sizeof near) != NULL) {
            return conf_fail(why, n, "rtde_values: \"%.*s\" is no RTDE output: did you mean %s?", (int)len, p,
                             near);
        }
        if (var < 0) {
            return conf_fail(why, n, "rtde_values: \"%.*s\" is no RTDE output (names are case-sensitive, e.g. "
                             "output_int_register_24, safety_status_bits; docs/rtde.md lists them)", (int)len, p);
        }
        if (!rtde_only(var)) {
            return conf_fail(why, n, "rtde_values: \"%.*s\" is a value RealTime has too: it is published on "
                             "NAME.STATE already (as %s); list only RTDE-only values here", (int)len, p,
                             urrt_field((urrt_field_id)urrt_rtde_var_field(var))->name);
        }
        for (size_t i = 0; i < count; i++) {
            if (robot->rtde_values[i] == var) {
                return conf_fail(why, n, "rtde_values: \"%.*s\" is listed twice", (int)len, p);
            }
        }
        if (count == URRT_RTDE_MAX_VARS) {
            return conf_fail(why, n, "rtde_values: more than %d names", URRT_RTDE_MAX_VARS);
        }
        robot->rtde_values[count++] = (uint16_t)var;
        p += len;
    }
    robot->rtde_value_count = count;
    if (robot->rtde_values_line == 0) {
        robot->rtde_values_line = at.line;
    }
    return true;
}

#define LINK_FIELD(member) CONF_FIELD(gw_robot_config, link.member)
/* A number as the text of the file: the port's constants are literals. */
#define TEXT_OF(x) TEXT_OF_(x)
#define TEXT_OF_(x) #x

static const struct conf_key robot_keys[] = {
    {"host", CONF_FN, 0, 0, 0, 0, set_host, NULL, false, "ADDRESS", NULL, "required",
     "the robot's IPv4 or IPv6 address (no brackets, no :PORT), or host name"},
    {"port", CONF_FN, 0, 0, 1, 65535, set_port, NULL, false, "PORT", NULL,
     TEXT_OF(URRT_LINK_PORT_RW) ", or " TEXT_OF(URRT_RTDE_PORT) " with source = rtde",
     "the robot's port; " TEXT_OF(URRT_LINK_PORT_RO) " is RealTime's read-only one"},
    {"source", CONF_FN, 0, 0, 0, 0, set_source, NULL, false, "realtime|rtde", "realtime", NULL,
     "the interface read: RealTime (30003) or RTDE (30004, a recipe of exactly what is published)"},
    {"rtde_frequency", CONF_FN, 0, 0, 0, 0, set_rtde_frequency, NULL, false, "auto|N Hz", "auto", NULL,
     "source = rtde: the rate asked for; auto is the controller's (125 Hz CB3, 500 Hz e-Series)"},
    {"rtde_values", CONF_FN, 0, 0, 0, 0, set_rtde_values, NULL, true, "none|NAME, ...", "none", NULL,
     "source = rtde: RTDE-only values (output_int_register_24, safety_status_bits, ...) on NAME.RTDE; repeatable"},
    {"version", CONF_FN, 0, 0, 0, 0, set_version, NULL, false, "auto|X.Y|BYTES", "auto", NULL,
     "the expected controller version or message size: others are mismatches"},
    {"connect_timeout", CONF_MS, LINK_FIELD(connect_timeout_ms), 10, 600000, NULL, NULL, false, NULL, "2 s", NULL,
     "how long a connection attempt may take"},
    /* A 125 Hz controller sends every 8 ms: less than 20 ms would drop a
     * healthy link on ordinary jitter. The default is the port's. */
    {"silence_timeout", CONF_MS, LINK_FIELD(silence_timeout_ms), 20, 600000, NULL, NULL, false, NULL,
     TEXT_OF(URRT_LINK_SILENCE_TIMEOUT_MS) " ms", NULL,
     "no packet for this long: reconnect; nothing is published meanwhile"},
    {"backoff_initial", CONF_MS, LINK_FIELD(backoff_initial_ms), 10, 600000, NULL, NULL, false, NULL, "100 ms", NULL,
     "the first wait before reconnecting after a failure"},
    {"backoff_max", CONF_MS, LINK_FIELD(backoff_max_ms), 10, 600000, NULL, NULL, false, NULL, "5 s", NULL,
     "the wait doubles up to this"},
};

static bool robot_begin(config_ctx *ctx, gw_config *cfg, const char *name)
{
    gw_robot_config *robot, *grown;
    char why[CONF_WHY_MAX];
    if (!conf_name(name, CONF_NAME_DASH, 64, why, sizeof why)) {
        config_error(ctx, ctx->line, "robot name \"%s\" %s", name, why);
        return false;
    }
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        if (strcmp(cfg->robots[i].name, name) == 0) {
            config_error(ctx, ctx->line, "robot \"%s\" is already defined at line %d: names must be unique "
                         "(they prefix the channels)", name, cfg->robots[i].line);
            return false;
        }
    }
    if (cfg->robot_count == GW_MAX_ROBOTS) {
        config_error(ctx, ctx->line, "more than %d robots: run another gateway", GW_MAX_ROBOTS);
        return false;
    }
    grown = realloc(cfg->robots, (cfg->robot_count + 1) * sizeof *cfg->robots);
    if (grown == NULL) {
        fprintf(stderr, "urrt-gateway: out of memory reading the configuration\n");
        exit(1);
    }
    cfg->robots = grown;
    robot = &cfg->robots[cfg->robot_count++];
    memset(robot, 0, sizeof *robot);
    robot->name = xstrdup(name);
    robot->line = ctx->line;
    urrt_link_config_defaults(&robot->link);
    set_defaults(ctx, robot_keys, sizeof robot_keys / sizeof robot_keys[0], robot);
    return true;
}

/* The port against the source: RTDE never where a controller runs what it
 * receives (lib's urrt_rtde_port_role: the link refuses it too), RealTime
 * never on RTDE's port, where a controller waits for a handshake and sends
 * nothing. A port given explicitly: the defaults are each source's own. */
static void robot_port_check(config_ctx *ctx, const gw_robot_config *robot)
{
    const char *role = urrt_rtde_port_role(robot->port);
    if (robot->port_line == 0) {
        return;
    }
    if (robot->source == GW_SOURCE_RTDE && role != NULL) {
        config_error(ctx, robot->port_line, "[robot %s]: port %u is %s, and this robot's source is rtde (line %d), "
                     "which would send it RTDE's handshake: RTDE is port %u (write port = %u, or leave port out)",
                     robot->name, (unsigned)robot->port, role, robot->source_line, (unsigned)URRT_RTDE_PORT,
                     (unsigned)URRT_RTDE_PORT);
    } else if (robot->source == GW_SOURCE_REALTIME && robot->port == URRT_RTDE_PORT) {
        config_error(ctx, robot->port_line, "[robot %s]: port %u is RTDE's on every controller, where nothing is "
                     "sent until a client's handshake, and this robot's source is realtime: add \"source = rtde\", "
                     "or give RealTime's port (%u, or the read-only %u)", robot->name, (unsigned)robot->port,
                     (unsigned)URRT_LINK_PORT_RW, (unsigned)URRT_LINK_PORT_RO);
    }
}

/* What only an RTDE robot may say, and the rate it then sends at. */
static void robot_source_check(config_ctx *ctx, gw_robot_config *robot)
{
    if (robot->source != GW_SOURCE_RTDE) {
        if (robot->rtde_value_count > 0) {
            config_error(ctx, robot->rtde_values_line, "[robot %s]: rtde_values are RTDE-only values, and this "
                         "robot's source is realtime: add \"source = rtde\" or remove them", robot->name);
        }
        if (robot->rtde_frequency > 0.0) {
            config_error(ctx, robot->rtde_frequency_line, "[robot %s]: rtde_frequency applies to source = rtde "
                         "only: add \"source = rtde\" or remove it", robot->name);
        }
        return;
    }
    if (strncmp(robot->expected, "1.", 2) == 0) {
        config_error(ctx, robot->version_line, "[robot %s]: version %s has no RTDE (it came with 3.3): use "
                     "source = realtime", robot->name, robot->expected);
    } else if (robot->rtde_frequency > robot->max_rate_hz) {
        config_error(ctx, robot->rtde_frequency_line, "[robot %s]: rtde_frequency %g Hz is above the %u Hz "
                     "version %s (line %d) streams: lower it, or set rtde_frequency = auto", robot->name,
                     robot->rtde_frequency, robot->max_rate_hz, robot->expected, robot->version_line);
    } else if (robot->rtde_frequency > 0.0) {
        robot->max_rate_hz = (unsigned)ceil(robot->rtde_frequency);
    }
    robot->expected_length = 0; /* RTDE packages are the recipe's size: version names the controller only */
}

static void robot_finish(config_ctx *ctx, gw_config *cfg)
{
    if (cfg->robot_count == 0) {
        /* An unedited install reads a file whose robot is commented out: say which file to edit. */
        config_error(ctx, 0, "no robot: edit %s and add a section \"[robot NAME]\" with \"host = ADDRESS\" "
                     "(the installed file has one commented out)", ctx->path);
    }
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        gw_robot_config *robot = &cfg->robots[i];
        if (robot->host == NULL) {
            config_error(ctx, robot->line, "[robot %s] has no host: add \"host = ADDRESS\"", robot->name);
        }
        if (robot->link.backoff_max_ms < robot->link.backoff_initial_ms) {
            config_error(ctx, robot->line, "[robot %s]: backoff_max (%u ms) is below backoff_initial (%u ms)",
                         robot->name, (unsigned)robot->link.backoff_max_ms,
                         (unsigned)robot->link.backoff_initial_ms);
        }
        if (robot->port == 0) {
            robot->port = robot->source == GW_SOURCE_RTDE ? URRT_RTDE_PORT : URRT_LINK_PORT_RW;
        }
        robot_port_check(ctx, robot);
        robot_source_check(ctx, robot);
        robot->link.name = robot->name;
        robot->link.host = robot->host;
        robot->link.port = robot->port;
    }
}

/* ---- [can] and [frame NAME]: the CAN mapping (can_map.h has their tables) ---- */

static void report_can_problem(void *user, const char *file, int line, const char *reason)
{
    (void)file; /* always this file: the map is fed one file */
    config_error(user, line, "%s", reason);
}

static bool can_begin(config_ctx *ctx, gw_config *cfg, const char *name)
{
    (void)name;
    ctx->frame = NULL;
    can_map_can_begin(&cfg->can, (struct conf_at){ctx->path, ctx->line});
    return true;
}

static bool frame_begin(config_ctx *ctx, gw_config *cfg, const char *name)
{
    char why[CONF_WHY_MAX];
    ctx->frame = can_map_frame_begin(&cfg->can, name, (struct conf_at){ctx->path, ctx->line}, why, sizeof why);
    if (ctx->frame == NULL) {
        config_error(ctx, ctx->line, "%s", why);
    }
    return ctx->frame != NULL;
}

static bool input_begin(config_ctx *ctx, gw_config *cfg, const char *name)
{
    char why[CONF_WHY_MAX];
    ctx->frame = can_map_input_begin(&cfg->can, name, (struct conf_at){ctx->path, ctx->line}, why, sizeof why);
    if (ctx->frame == NULL) {
        config_error(ctx, ctx->line, "%s", why);
    }
    return ctx->frame != NULL;
}

static bool can_set(config_ctx *ctx, gw_config *cfg, const struct conf_key *key, const char *value, char *why,
                    size_t n)
{
    struct conf_at at = {ctx->path, ctx->line};
    if (ctx->frame != NULL && key >= canopen_map_frame_keys && key < canopen_map_frame_keys + CANOPEN_FK_COUNT) {
        return canopen_map_frame_set(&cfg->co, (size_t)(ctx->frame - cfg->can.frames), key, value, at, why, n);
    }
    return can_map_set(&cfg->can, ctx->frame, key, value, at, why, n);
}

static bool canopen_begin(config_ctx *ctx, gw_config *cfg, const char *name)
{
    (void)name;
    ctx->frame = NULL;
    canopen_map_begin(&cfg->co, (struct conf_at){ctx->path, ctx->line});
    return true;
}

static bool canopen_set(config_ctx *ctx, gw_config *cfg, const struct conf_key *key, const char *value, char *why,
                        size_t n)
{
    return canopen_map_set(&cfg->co, key, value, (struct conf_at){ctx->path, ctx->line}, why, n);
}

/* The CANopen node over the CAN tables: built here, once, as they are. */
static void canopen_build(config_ctx *ctx, gw_config *cfg)
{
    char why[CONF_WHY_MAX];
    cfg->co_run = co_run_build(&cfg->co, &cfg->can, cfg->can_run, why, sizeof why);
    if (cfg->co_run == NULL) {
        config_error(ctx, 0, "%s", why);
    }
}

/* The whole-file checks, then the run-time tables: built here, once, so that
 * --check-config proves they build. */
static void can_finish(config_ctx *ctx, gw_config *cfg)
{
    struct can_map_robot robots[GW_MAX_ROBOTS];
    char why[CONF_WHY_MAX];
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        robots[i].name = cfg->robots[i].name;
        robots[i].period_us = 1000000u / cfg->robots[i].max_rate_hz;
    }
    bool node = canopen_map_enabled(&cfg->co);
    int node_errors = node ? canopen_map_prepare(&cfg->co, &cfg->can) : canopen_map_orphans(&cfg->co, &cfg->can);
    if (can_map_finish(&cfg->can, robots, cfg->robot_count, NULL, 0) != 0 || !can_map_enabled(&cfg->can) ||
        node_errors > 0 || (node && canopen_map_check(&cfg->co, &cfg->can) > 0) || ctx->errors > 0) {
        return;
    }
    cfg->can_run = can_run_build(&cfg->can, why, sizeof why);
    if (cfg->can_run == NULL) {
        config_error(ctx, 0, "%s", why);
    } else if (node) {
        canopen_build(ctx, cfg);
    }
}

/* ---- the RTDE recipes: exactly what the whole file publishes ---------------------- */

/* Adds var to the robot's recipe (once; a required entry stays required). */
static void recipe_add(gw_robot_config *robot, int var, bool optional)
{
    for (size_t i = 0; i < robot->recipe_count; i++) {
        if (robot->recipe[i] == var) {
            robot->recipe_optional[i] = robot->recipe_optional[i] && optional;
            return;
        }
    }
    if (robot->recipe_count < URRT_RTDE_MAX_VARS) {
        robot->recipe[robot->recipe_count] = (uint16_t)var;
        robot->recipe_optional[robot->recipe_count++] = optional;
    }
}

/* The fields and RTDE-only values of robot index's CAN signals: required. */
static void recipe_add_can(config_ctx *ctx, gw_config *cfg, gw_robot_config *robot, unsigned index)
{
    for (size_t f = 0; cfg->can.finished && f < cfg->can.frame_count; f++) {
        const struct can_map_frame *frame = &cfg->can.frames[f];
        if (frame->robot_index != index) {
            continue;
        }
        for (size_t i = 0; i < frame->count; i++) {
            const struct can_map_signal *m = &frame->meta[i];
            int var = m->role == CAN_MAP_ROLE_FIELD  ? urrt_rtde_var_of_field((urrt_field_id)m->field)
                      : m->role == CAN_MAP_ROLE_RTDE ? m->var
                                                     : -2;
            if (var == -1) {
                config_error(ctx, m->loc.line, "signal %s: RTDE has no %s: robot \"%s\" has source = rtde; "
                             "use another value or source = realtime", m->name,
                             urrt_field((urrt_field_id)m->field)->name, robot->name);
            } else if (var >= 0) {
                recipe_add(robot, var, false);
            }
        }
    }
}

/* The registers robot index's [input]s write are read back: in its output
 * recipe and on NAME.RTDE, so that what the controller holds is seen (an
 * input register is an RTDE output too). */
static void add_read_back(gw_config *cfg, gw_robot_config *robot, unsigned index)
{
    for (size_t f = 0; cfg->can.finished && f < cfg->can.input_count; f++) {
        const struct can_map_frame *in = &cfg->can.inputs[f];
        for (size_t k = 0; in->robot_index == index && k < in->reg_count; k++) {
            bool listed = false;
            for (size_t i = 0; i < robot->rtde_value_count && !listed; i++) {
                listed = robot->rtde_values[i] == in->regs[k];
            }
            if (!listed && robot->rtde_value_count < URRT_RTDE_MAX_VARS) {
                robot->rtde_values[robot->rtde_value_count++] = in->regs[k];
            }
        }
    }
}

/* The bytes of the recipe's name list on the wire (names and commas). */
static size_t recipe_names_length(const gw_robot_config *robot)
{
    size_t total = 0;
    for (size_t i = 0; i < robot->recipe_count; i++) {
        char name[URRT_RTDE_NAME_MAX];
        int len = urrt_rtde_var_name(robot->recipe[i], name, sizeof name);
        total += (size_t)(len > 0 ? len : 0) + (i > 0 ? 1u : 0u);
    }
    return total;
}

/* timestamp (the data's time, for freshness) first, required; STATE's
 * shared fields when any robot message is published, optional (only where
 * the controller has them: rtde_source.h); the CAN signals' fields and the
 * RTDE-only values, required. */
static void build_recipe(config_ctx *ctx, gw_config *cfg, gw_robot_config *robot, unsigned index)
{
    bool messages = false;
    size_t wanted = 1 + robot->rtde_value_count;
    for (unsigned k = GW_KIND_STATE; k <= GW_KIND_STATUS; k++) {
        messages = messages || cfg->lcm.rate[k].mode != GW_RATE_OFF;
    }
    robot->recipe_count = 0;
    recipe_add(robot, URRT_RTDE_V_TIMESTAMP, false);
    for (int v = 0; messages && v < URRT_RTDE_MAPPED_COUNT; v++) {
        recipe_add(robot, v, true);
    }
    recipe_add_can(ctx, cfg, robot, index);
    add_read_back(cfg, robot, index);
    for (size_t i = 0; i < robot->rtde_value_count; i++) {
        recipe_add(robot, robot->rtde_values[i], false);
    }
    wanted += messages ? URRT_RTDE_MAPPED_COUNT : 0;
    if (robot->recipe_count == URRT_RTDE_MAX_VARS && wanted > URRT_RTDE_MAX_VARS) {
        config_error(ctx, robot->line, "[robot %s]: the RTDE recipe would hold more than %d values: publish "
                     "fewer (rtde_values, CAN signals)", robot->name, URRT_RTDE_MAX_VARS);
    } else if (recipe_names_length(robot) > URRT_RTDE_NAMES_MAX) {
        config_error(ctx, robot->rtde_values_line != 0 ? robot->rtde_values_line : robot->line,
                     "[robot %s]: the RTDE recipe's names take %zu bytes, over the controller's limit of %d: "
                     "publish fewer values (rtde_values, CAN signals), or turn off messages in [lcm]",
                     robot->name, recipe_names_length(robot), URRT_RTDE_NAMES_MAX);
    }
}

/* A realtime robot's CAN signals naming an RTDE-only value: RealTime has none. */
static void refuse_rtde_signals(config_ctx *ctx, gw_config *cfg, const gw_robot_config *robot, unsigned index)
{
    for (size_t f = 0; cfg->can.finished && f < cfg->can.frame_count; f++) {
        const struct can_map_frame *frame = &cfg->can.frames[f];
        for (size_t i = 0; frame->robot_index == index && i < frame->count; i++) {
            if (frame->meta[i].role == CAN_MAP_ROLE_RTDE) {
                config_error(ctx, frame->meta[i].loc.line, "signal %s: an RTDE-only value, and robot \"%s\" reads "
                             "RealTime, which has none: add \"source = rtde\" to [robot %s] or remove the signal",
                             frame->meta[i].name, robot->name, robot->name);
            }
        }
    }
}

/* A realtime robot's [input]s: RealTime cannot write. */
static void refuse_inputs(config_ctx *ctx, gw_config *cfg, const gw_robot_config *robot, unsigned index)
{
    for (size_t f = 0; cfg->can.finished && f < cfg->can.input_count; f++) {
        const struct can_map_frame *in = &cfg->can.inputs[f];
        if (in->robot_index == index) {
            config_error(ctx, in->loc.line, "[input %s] writes robot \"%s\"'s input registers, and that robot reads "
                         "RealTime, which never writes: add \"source = rtde\" to [robot %s] (RTDE, port 30004) or "
                         "remove the [input]", in->name, robot->name, robot->name);
        }
    }
}

static void build_recipes(config_ctx *ctx, gw_config *cfg)
{
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        if (cfg->robots[i].source == GW_SOURCE_RTDE) {
            build_recipe(ctx, cfg, &cfg->robots[i], i);
        } else {
            refuse_rtde_signals(ctx, cfg, &cfg->robots[i], i);
            refuse_inputs(ctx, cfg, &cfg->robots[i], i);
        }
    }
}

/* ---- the section table ---------------------------------------------------------- */

static void *gateway_object(config_ctx *ctx, gw_config *cfg)
{
    (void)ctx;
    return cfg;
}

static void *lcm_object(config_ctx *ctx, gw_config *cfg)
{
    (void)ctx;
    return &cfg->lcm;
}

static void *robot_object(config_ctx *ctx, gw_config *cfg)
{
    (void)ctx;
    return &cfg->robots[cfg->robot_count - 1];
}

#define KEYS(table) table, sizeof table / sizeof table[0]

static const config_section config_sections[] = {
    {"gateway", false, false, NULL, KEYS(gateway_keys), gateway_object, NULL, NULL, "optional, once", NULL, 0},
    {"robot", true, true, robot_begin, KEYS(robot_keys), robot_object, NULL, robot_finish,
     "one per robot; NAME prefixes its channels", NULL, 0},
    {"lcm", false, false, NULL, KEYS(lcm_keys), lcm_object, NULL, lcm_finish, "optional, once", NULL, 0},
    {"can", false, false, can_begin, can_map_can_keys, CAN_MAP_CK_COUNT, NULL, can_set, can_finish,
     "the CAN output (optional; docs/can.md)", NULL, 0},
    {"frame", true, true, frame_begin, can_map_frame_keys, CAN_MAP_FK_COUNT, NULL, can_set, NULL,
     "one per CAN frame; NAME is its DBC name", canopen_map_frame_keys, CANOPEN_FK_COUNT},
    {"input", true, true, input_begin, can_map_input_keys, CAN_MAP_IK_COUNT, NULL, can_set, NULL,
     "one per CAN frame the PLC sends; its signals write input registers (docs/can.md)", NULL, 0},
    {"canopen", false, false, canopen_begin, canopen_map_keys, CANOPEN_K_COUNT, NULL, canopen_set, NULL,
     "the CAN output as a CANopen node, its [frame]s TPDOs (optional; docs/canopen.md)", NULL, 0},
};
#define CONFIG_SECTION_COUNT (sizeof config_sections / sizeof config_sections[0])

static void unknown_section(config_ctx *ctx, const char *raw, const char *kind)
{
    const char *near = conf_suggest(kind, config_sections, CONFIG_SECTION_COUNT, sizeof config_sections[0]);
    const config_section *like = NULL;
    char known[256] = "";
    size_t used = 0;
    for (size_t i = 0; i < CONFIG_SECTION_COUNT && used < sizeof known; i++) {
        used += (size_t)snprintf(known + used, sizeof known - used, "%s[%s%s]", i ? ", " : "",
                                 config_sections[i].kind, config_sections[i].named ? " NAME" : "");
        like = config_sections[i].kind == near ? &config_sections[i] : like;
    }
    if (like != NULL) {
        config_error(ctx, ctx->line, "unknown section [%s]: did you mean [%s%s]? (sections: %s)", raw, like->kind,
                     like->named ? " NAME" : "", known);
    } else {
        config_error(ctx, ctx->line, "unknown section [%s] (sections: %s)", raw, known);
    }
}

/* "robot  arm1 " -> kind "robot", name "arm1" (trimmed). */
static void split_header(const char *raw, char *kind, size_t kind_size, char *name, size_t name_size)
{
    size_t kind_len;
    raw += strspn(raw, " \t\f\v");
    kind_len = strcspn(raw, " \t");
    snprintf(kind, kind_size, "%.*s", (int)(kind_len < kind_size ? kind_len : kind_size - 1), raw);
    raw += kind_len;
    while (isspace((unsigned char)*raw)) {
        raw++;
    }
    snprintf(name, name_size, "%s", raw);
    for (size_t n = strlen(name); n > 0 && isspace((unsigned char)name[n - 1]); n--) {
        name[n - 1] = '\0';
    }
}

static void begin_section(config_ctx *ctx, const char *raw)
{
    char kind[64], name[256];
    const config_section *sec = NULL;
    size_t index;

    ctx->in_section = true;
    ctx->section = NULL;
    ctx->section_ok = false;
    ctx->key_count = 0;
    split_header(raw, kind, sizeof kind, name, sizeof name);
    snprintf(ctx->section_label, sizeof ctx->section_label, "%s%s%s", kind, name[0] ? " " : "", name);
    for (index = 0; index < CONFIG_SECTION_COUNT && sec == NULL; index++) {
        sec = strcmp(config_sections[index].kind, kind) == 0 ? &config_sections[index] : NULL;
    }
    if (sec == NULL) {
        unknown_section(ctx, ctx->section_label, kind);
        return;
    }
    index--;
    if (sec->named && name[0] == '\0') {
        config_error(ctx, ctx->line, "section [%s] needs a name: [%s NAME]", kind, kind);
        return;
    }
    if (!sec->named && name[0] != '\0') {
        config_error(ctx, ctx->line, "section [%s] takes no name, not \"%s\"", kind, name);
        return;
    }
    if (!sec->repeatable && ctx->seen_line[index] != 0) {
        config_error(ctx, ctx->line, "section [%s] appears again (first at line %d): merge them", kind,
                     ctx->seen_line[index]);
        return;
    }
    if (ctx->seen_line[index] == 0) {
        ctx->seen_line[index] = ctx->line;
    }
    ctx->section = sec;
    ctx->section_ok = sec->begin == NULL || sec->begin(ctx, ctx->cfg, sec->named ? name : NULL);
}

/* ---- the reader: each line read once, here ------------------------------------- */

/* Characters of a line before its end ("\n" or "\r\n"): room for any
 * configuration a person writes, and a bound for a file that is not one. */
#define CONFIG_LINE_MAX 198

/* The next line into buf (CONFIG_LINE_MAX + 2 bytes), without its "\n":
 * false at the end of the file. A line too long or holding a NUL byte is
 * reported and comes back empty. Byte by byte, not fgets: after a NUL byte
 * strlen() would miss the end of the line, and its rest would count as a
 * line of its own. */
static bool next_line(config_ctx *ctx, char *buf)
{
    size_t n = 0, len = 0;
    int c, last = 0;
    bool nul = false;
    while ((c = getc(ctx->file)) != EOF && c != '\n') {
        if (n < CONFIG_LINE_MAX + 1) {
            buf[n++] = (char)c;
        }
        nul |= c == '\0';
        last = c;
        len++;
    }
    buf[n] = '\0';
    if (c == EOF && len == 0) {
        return false;
    }
    ctx->line++;
    if (len - (last == '\r') > CONFIG_LINE_MAX) {
        config_error(ctx, ctx->line, "line longer than %d characters", CONFIG_LINE_MAX);
        buf[0] = '\0';
    } else if (nul) {
        config_error(ctx, ctx->line, "a NUL byte: the configuration must be a text file");
        buf[0] = '\0';
    }
    return true;
}

/* Blanks (isspace: a form feed too) off both ends. */
static char *trim(char *s)
{
    size_t n;
    while (isspace((unsigned char)*s)) {
        s++;
    }
    for (n = strlen(s); n > 0 && isspace((unsigned char)s[n - 1]); n--) {
        s[n - 1] = '\0';
    }
    return s;
}

/* The first of chars in s, or where a comment starts: ';' or '#' after a
 * blank. Returns the end of s when there is neither. */
static char *find_or_comment(char *s, const char *chars)
{
    bool after_blank = false;
    for (; *s != '\0'; s++) {
        if ((chars != NULL && strchr(chars, *s) != NULL) || (after_blank && (*s == ';' || *s == '#'))) {
            break;
        }
        after_blank = isspace((unsigned char)*s) != 0;
    }
    return s;
}

/* "[KIND NAME]", with nothing after it but a comment. */
static void header_line(config_ctx *ctx, char *line)
{
    char *end = strchr(line, ']');
    char *rest;
    if (end == NULL) {
        config_error(ctx, ctx->line, "section header without ']'");
        ctx->section = NULL;
        ctx->section_ok = false;
        return;
    }
    rest = end + 1 + strspn(end + 1, " \t\f\v\r\n");
    if (*rest != '\0' && *rest != ';' && *rest != '#') {
        /* "[lcm] url = ..." would lose the key. */
        config_error(ctx, ctx->line, "text after the section header: \"%.*s\" (keys go on lines of their own)",
                     (int)strcspn(rest, "\r\n"), rest);
    }
    *end = '\0';
    begin_section(ctx, line + 1);
}

static void on_key(config_ctx *ctx, const char *key, const char *value);

/* "KEY = VALUE" (or "KEY: VALUE"); a comment after a blank is not part of
 * the value. */
static void key_line(config_ctx *ctx, char *line)
{
    char *sep = find_or_comment(line, "=:");
    char *value;
    if (*sep != '=' && *sep != ':') {
        config_error(ctx, ctx->line, "expected \"[section]\" or \"key = value\", not \"%s\"", line);
        return;
    }
    *sep = '\0';
    value = sep + 1;
    *find_or_comment(value, NULL) = '\0';
    on_key(ctx, trim(line), trim(value));
}

static void read_file(config_ctx *ctx)
{
    char buf[CONFIG_LINE_MAX + 2];
    while (next_line(ctx, buf)) {
        char *line = buf;
        if (ctx->line == 1 && strncmp(line, "\xEF\xBB\xBF", 3) == 0) {
            line += 3; /* a byte order mark */
        }
        line = trim(line);
        if (*line == '[') {
            header_line(ctx, line);
        } else if (*line != '\0' && *line != ';' && *line != '#') {
            key_line(ctx, line);
        }
    }
    if (ferror(ctx->file)) {
        config_error(ctx, 0, "read error: %s", strerror(errno));
    }
}

/* A key given twice in a section: reported once, at its second line. */
static bool seen_again(config_ctx *ctx, const char *key)
{
    for (unsigned i = 0; i < ctx->key_count; i++) {
        if (strcmp(ctx->keys[i].name, key) == 0) {
            config_error(ctx, ctx->line, "%s is set again (first at line %d)", key, ctx->keys[i].line);
            return true;
        }
    }
    if (ctx->key_count < CONFIG_MAX_KEYS) {
        snprintf(ctx->keys[ctx->key_count].name, sizeof ctx->keys[0].name, "%s", key);
        ctx->keys[ctx->key_count++].line = ctx->line;
    }
    return false;
}

static void on_key(config_ctx *ctx, const char *key, const char *value)
{
    const config_section *sec = ctx->section;
    const struct conf_key *k;
    char why[CONF_WHY_MAX];
    if (!ctx->in_section) {
        config_error(ctx, ctx->line, "\"%s\" is outside of any section: put it under [gateway], [lcm] or [robot NAME]",
                     key);
        return;
    }
    if (sec == NULL || !ctx->section_ok) {
        return; /* the header's error was reported */
    }
    k = conf_key_find(sec->keys, sec->key_count, key);
    if (k == NULL && sec->more_keys != NULL) {
        k = conf_key_find(sec->more_keys, sec->more_key_count, key);
    }
    if (k == NULL) {
        conf_unknown_key(sec->keys, sec->key_count, key, ctx->section_label, why, sizeof why);
        config_error(ctx, ctx->line, "%s", why);
        return;
    }
    if (!k->many && seen_again(ctx, key)) {
        return;
    }
    if (value[0] == '\0') {
        config_error(ctx, ctx->line, "%s has no value", key);
        return;
    }
    if (!(sec->set != NULL ? sec->set(ctx, ctx->cfg, k, value, why, sizeof why)
                           : conf_key_set(k, sec->object(ctx, ctx->cfg), value, (struct conf_at){ctx->path, ctx->line},
                                          why, sizeof why))) {
        config_error(ctx, ctx->line, "%s", why);
    }
}

static void config_defaults(gw_config *cfg, const char *path)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->path = path;
    can_map_init(&cfg->can);
    canopen_map_init(&cfg->co);
}

static int config_parse(gw_config *cfg, FILE *in, FILE *err)
{
    config_ctx ctx;
    int seen[CONFIG_SECTION_COUNT] = {0};

    memset(&ctx, 0, sizeof ctx);
    can_map_set_reporter(&cfg->can, report_can_problem, &ctx);
    ctx.path = cfg->path;
    ctx.err = err;
    ctx.cfg = cfg;
    ctx.seen_line = seen;
    ctx.file = in;
    set_defaults(&ctx, KEYS(gateway_keys), cfg);
    set_defaults(&ctx, KEYS(lcm_keys), &cfg->lcm);
    read_file(&ctx);
    ctx.rank = RANK_FILE;
    for (size_t i = 0; i < CONFIG_SECTION_COUNT; i++) {
        if (config_sections[i].finish != NULL) {
            config_sections[i].finish(&ctx, cfg);
        }
    }
    build_recipes(&ctx, cfg);
    can_map_set_reporter(&cfg->can, NULL, NULL);
    print_errors(&ctx);
    return ctx.errors;
}

int gw_config_load(gw_config *cfg, const char *path, FILE *err)
{
    FILE *in;
    int errors;

    config_defaults(cfg, path);
    in = strcmp(path, "-") == 0 ? stdin : fopen(path, "r");
    if (in == NULL) {
        fprintf(err, "%s: cannot open: %s\n", path, strerror(errno));
        return 1;
    }
    errors = config_parse(cfg, in, err);
    if (in != stdin) {
        fclose(in);
    }
    return errors;
}

int gw_config_load_stream(gw_config *cfg, FILE *in, const char *path, FILE *err)
{
    config_defaults(cfg, path);
    return config_parse(cfg, in, err);
}

void gw_config_free(gw_config *cfg)
{
    free(cfg->metrics_file);
    free(cfg->lcm.url);
    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        free(cfg->lcm.channel[k]);
    }
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        free(cfg->robots[i].name);
        free(cfg->robots[i].host);
        free(cfg->robots[i].expected);
    }
    free(cfg->robots);
    co_run_free(cfg->co_run); /* before the CAN tables it runs on */
    can_run_free(cfg->can_run); /* before the map: its tables are the map's */
    can_map_free(&cfg->can);
    canopen_map_free(&cfg->co);
    memset(cfg, 0, sizeof *cfg);
}

void gw_config_usage(FILE *out)
{
    fputs("Configuration file (INI; '#' or ';' starts a comment; every key is optional\n"
          "unless marked required; an unknown section or key is an error). Values:\n"
          "integers decimal or 0x hex (no leading zero); yes/no (true/false, on/off,\n"
          "1/0); DURATION a number and a unit: 250ms, 1.5 s, 2 min (us, ms, s, min),\n"
          "a bare number only for keys named _ms (milliseconds); N Hz a rate, a bare\n"
          "number being Hz too (50 Hz or 50). docs/can.md has the signal grammar.\n",
          out);
    for (size_t i = 0; i < CONFIG_SECTION_COUNT; i++) {
        const config_section *sec = &config_sections[i];
        fprintf(out, "\n  [%s%s]  %s\n", sec->kind, sec->named ? " NAME" : "", sec->usage);
        conf_key_usage(out, sec->keys, sec->key_count);
        if (sec->more_keys != NULL) {
            conf_key_usage(out, sec->more_keys, sec->more_key_count);
        }
    }
}

void gw_config_print_keys(FILE *out)
{
    for (size_t i = 0; i < CONFIG_SECTION_COUNT; i++) {
        conf_key_print(out, config_sections[i].kind, config_sections[i].keys, config_sections[i].key_count);
        if (config_sections[i].more_keys != NULL) {
            conf_key_print(out, config_sections[i].kind, config_sections[i].more_keys,
                           config_sections[i].more_key_count);
        }
    }
}
