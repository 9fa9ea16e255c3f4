/* SPDX-License-Identifier: MIT */
/* config.c: the urrt-gateway configuration file (see config.h). */
#define _GNU_SOURCE
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include <ini.h>

#define CONFIG_MAX_KEYS 64

typedef struct config_message {
    int line;
    int order;
    char *text;
} config_message;

struct config_ctx {
    const char *path;
    FILE *err;
    int errors;
    config_message *messages;   /* printed in line order at the end */
    int line;                 /* line the reader handed to inih last */
    int last_error_line;
    FILE *file;
    gw_config *cfg;
    const config_section *section; /* NULL before the first header or after a bad one */
    bool section_ok;          /* keys of a bad section are skipped: one error is enough */
    char section_raw[256];    /* the text between the brackets, as inih sees it */
    struct { char name[64]; int line; } keys[CONFIG_MAX_KEYS];
    unsigned key_count;
    int *seen_line;           /* per table entry: line of its first header, 0 if none */
};

static const char *const kind_names[GW_KIND_COUNT] = {"state", "joints", "tool", "status", "gateway"};
static const char *const kind_channels[GW_KIND_COUNT] = {"STATE", "JOINTS", "TOOL", "STATUS", "GATEWAY"};

const char *gw_kind_name(gw_kind kind)
{
    return (unsigned)kind < GW_KIND_COUNT ? kind_names[kind] : "?";
}

/* ---- errors and value parsers ---------------------------------------------- */

int config_line(const config_ctx *ctx)
{
    return ctx->line;
}

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
    if (line > 0) {
        ctx->last_error_line = line;
    }
    grown = realloc(ctx->messages, (size_t)(ctx->errors + 1) * sizeof *ctx->messages);
    if (grown == NULL || text == NULL) {
        fprintf(stderr, "urrt-gateway: out of memory reading the configuration\n");
        exit(1);
    }
    ctx->messages = grown;
    ctx->messages[ctx->errors].line = line;
    ctx->messages[ctx->errors].text = text;
    ctx->messages[ctx->errors].order = ctx->errors;
    ctx->errors++;
}

static int by_line(const void *a, const void *b)
{
    const config_message *x = a, *y = b;
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
    /* File-wide messages (line 0) first, then in line order. No message:
     * no array, and qsort must not be given NULL. */
    if (ctx->errors > 0) {
        qsort(ctx->messages, (size_t)ctx->errors, sizeof *ctx->messages, by_line);
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

bool config_uint(config_ctx *ctx, const char *what, const char *value, unsigned long min,
                 unsigned long max, unsigned long *out)
{
    char *end;
    unsigned long v;
    errno = 0;
    v = strtoul(value, &end, 10);
    if (!isdigit((unsigned char)value[0]) || *end != '\0' || errno != 0 || v < min || v > max) {
        config_error(ctx, ctx->line, "%s must be a whole number from %lu to %lu, not \"%s\"", what,
                     min, max, value);
        return false;
    }
    *out = v;
    return true;
}

static bool parse_number(const char *value, double *out, const char **rest)
{
    char *end;
    double v;
    if (!isdigit((unsigned char)value[0]) && value[0] != '.') {
        return false;
    }
    errno = 0;
    v = strtod(value, &end);
    if (end == value || errno != 0 || !isfinite(v)) {
        return false;
    }
    while (*end == ' ' || *end == '\t') {
        end++;
    }
    *out = v;
    *rest = end;
    return true;
}

bool config_duration_ms(config_ctx *ctx, const char *what, const char *value, uint32_t min_ms,
                        uint32_t max_ms, uint32_t *out)
{
    double v, ms;
    const char *unit;
    if (!parse_number(value, &v, &unit) || (strcmp(unit, "ms") != 0 && strcmp(unit, "s") != 0)) {
        config_error(ctx, ctx->line, "%s must be a duration with a unit, e.g. \"250 ms\" or \"2 s\", not \"%s\"",
                     what, value);
        return false;
    }
    ms = strcmp(unit, "s") == 0 ? v * 1000.0 : v;
    if (ms < min_ms || ms > max_ms || ms != floor(ms)) {
        config_error(ctx, ctx->line, "%s must be a whole number of milliseconds from %u ms to %u ms, not \"%s\"",
                     what, (unsigned)min_ms, (unsigned)max_ms, value);
        return false;
    }
    *out = (uint32_t)ms;
    return true;
}

bool config_rate(config_ctx *ctx, const char *what, const char *value, gw_rate *out)
{
    double hz;
    const char *unit;
    if (strcmp(value, "every") == 0) {
        out->mode = GW_RATE_EVERY;
        out->hz = 0;
        return true;
    }
    if (strcmp(value, "off") == 0) {
        out->mode = GW_RATE_OFF;
        out->hz = 0;
        return true;
    }
    if (!parse_number(value, &hz, &unit) || strcmp(unit, "Hz") != 0) {
        config_error(ctx, ctx->line, "%s must be \"every\", \"off\" or a rate such as \"50 Hz\", not \"%s\"",
                     what, value);
        return false;
    }
    if (hz < 0.01 || hz > GW_ROBOT_MAX_RATE_HZ) {
        config_error(ctx, ctx->line, "%s %s is out of range: from 0.01 Hz to %u Hz (the fastest robot)",
                     what, value, GW_ROBOT_MAX_RATE_HZ);
        return false;
    }
    out->mode = GW_RATE_HZ;
    out->hz = hz;
    return true;
}

bool config_bool(config_ctx *ctx, const char *what, const char *value, bool *out)
{
    static const char *const yes[] = {"yes", "true", "on", "1"};
    static const char *const no[] = {"no", "false", "off", "0"};
    for (unsigned i = 0; i < 4; i++) {
        if (strcmp(value, yes[i]) == 0) {
            *out = true;
            return true;
        }
        if (strcmp(value, no[i]) == 0) {
            *out = false;
            return true;
        }
    }
    config_error(ctx, ctx->line, "%s must be yes or no, not \"%s\"", what, value);
    return false;
}

bool config_identifier(config_ctx *ctx, const char *what, const char *value, bool dots)
{
    size_t n = strlen(value);
    bool ok = n >= 1 && n <= 64;
    for (size_t i = 0; ok && i < n; i++) {
        unsigned char c = (unsigned char)value[i];
        ok = isalnum(c) || c == '_' || c == '-' || (dots && c == '.' && i > 0 && i + 1 < n);
    }
    if (!ok) {
        config_error(ctx, ctx->line, "%s \"%s\" must be 1 to 64 letters, digits, '_' or '-'%s", what,
                     value, dots ? " (or '.' inside)" : "");
    }
    return ok;
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

static bool gateway_key(config_ctx *ctx, gw_config *cfg, const char *key, const char *value)
{
    if (strcmp(key, "log_level") == 0) {
        if (!gw_parse_log_level(value, &cfg->log_level)) {
            config_error(ctx, ctx->line, "log_level must be err, warning, notice, info or debug, not \"%s\"", value);
            return false;
        }
        return true;
    }
    if (strcmp(key, "summary") == 0) {
        return config_bool(ctx, "summary", value, &cfg->summary);
    }
    config_error(ctx, ctx->line, "unknown key \"%s\" in [gateway] (keys: log_level, summary)", key);
    return false;
}

/* ---- [lcm] ------------------------------------------------------------------------ */

/* udpm://GROUP:PORT?opt=v&...: the group must be IPv4 multicast, the options
 * those LCM's udpm provider knows. Other providers are checked for the
 * scheme only: LCM validates them when the gateway starts. */
static bool check_lcm_url(config_ctx *ctx, const char *url)
{
    static const char *const providers[] = {"udpm", "file", "memq", "tcpq", "mpudpm"};
    const char *sep = strstr(url, "://");
    bool known = false;
    for (const char *c = url; *c != '\0'; c++) {
        if ((unsigned char)*c < 0x20 || *c == 0x7f) {
            /* It is printed at start and by --check-config. */
            config_error(ctx, ctx->line, "url \"%s\": no control characters", url);
            return false;
        }
    }
    if (sep == NULL) {
        config_error(ctx, ctx->line, "url \"%s\" is not an LCM URL (provider://address?options), e.g. %s",
                     url, GW_DEFAULT_LCM_URL);
        return false;
    }
    for (size_t i = 0; i < sizeof providers / sizeof providers[0]; i++) {
        known |= strlen(providers[i]) == (size_t)(sep - url) && strncmp(url, providers[i], (size_t)(sep - url)) == 0;
    }
    if (!known) {
        config_error(ctx, ctx->line, "url \"%s\": unknown LCM provider \"%.*s\" (udpm, file, memq, tcpq, mpudpm)",
                     url, (int)(sep - url), url);
        return false;
    }
    if (strncmp(url, "udpm://", 7) == 0) {
        unsigned a, b, c, d, port;
        int used = 0;
        const char *p = url + 7;
        if (*p != '\0' && *p != '?') {
            if (sscanf(p, "%3u.%3u.%3u.%3u:%5u%n", &a, &b, &c, &d, &port, &used) != 5 ||
                (p[used] != '\0' && p[used] != '?') || a > 255 || b > 255 || c > 255 || d > 255 ||
                port == 0 || port > 65535) {
                config_error(ctx, ctx->line, "url \"%s\": udpm needs GROUP:PORT, e.g. 239.255.76.67:7667", url);
                return false;
            }
            if (a < 224 || a > 239) {
                config_error(ctx, ctx->line, "url \"%s\": %u.%u.%u.%u is not a multicast group (224.0.0.0 to 239.255.255.255)",
                             url, a, b, c, d);
                return false;
            }
            p += used;
        }
        if (*p == '?') {
            char opts[256];
            snprintf(opts, sizeof opts, "%s", p + 1);
            for (char *save = NULL, *opt = strtok_r(opts, "&", &save); opt != NULL; opt = strtok_r(NULL, "&", &save)) {
                char *eq = strchr(opt, '=');
                char *end;
                unsigned long v;
                if (eq == NULL) {
                    config_error(ctx, ctx->line, "url \"%s\": option \"%s\" has no value", url, opt);
                    return false;
                }
                *eq = '\0';
                errno = 0;
                v = strtoul(eq + 1, &end, 10);
                if (strcmp(opt, "ttl") == 0) {
                    if (*end != '\0' || eq[1] == '\0' || v > 255) {
                        config_error(ctx, ctx->line, "url \"%s\": ttl must be 0 to 255 (0: this host only, 1: the LAN)", url);
                        return false;
                    }
                } else if (strcmp(opt, "recv_buf_size") == 0) {
                    if (*end != '\0' || eq[1] == '\0' || errno != 0 || v == 0) {
                        config_error(ctx, ctx->line, "url \"%s\": recv_buf_size must be a number of bytes", url);
                        return false;
                    }
                } else if (strcmp(opt, "transmit_only") != 0) {
                    config_error(ctx, ctx->line, "url \"%s\": unknown udpm option \"%s\" (ttl, recv_buf_size, transmit_only)",
                                 url, opt);
                    return false;
                }
            }
        }
    }
    return true;
}

static bool lcm_key(config_ctx *ctx, gw_config *cfg, const char *key, const char *value)
{
    gw_lcm_config *lcm = &cfg->lcm;
    if (strcmp(key, "url") == 0) {
        if (!check_lcm_url(ctx, value)) {
            return false;
        }
        replace_string(&lcm->url, value);
        lcm->url_line = ctx->line;
        return true;
    }
    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        size_t n = strlen(kind_names[k]);
        if (strncmp(key, kind_names[k], n) != 0) {
            continue;
        }
        if (strcmp(key + n, "_channel") == 0) {
            if (!config_identifier(ctx, key, value, true)) {
                return false;
            }
            replace_string(&lcm->channel[k], value);
            lcm->channel_line[k] = ctx->line;
            return true;
        }
        if (strcmp(key + n, "_rate") == 0) {
            gw_rate rate;
            if (!config_rate(ctx, key, value, &rate)) {
                return false;
            }
            if (k == GW_KIND_GATEWAY && rate.mode == GW_RATE_EVERY) {
                config_error(ctx, ctx->line, "gateway_rate is a report rate: \"off\" or N Hz (default 1 Hz), not \"every\"");
                return false;
            }
            if (k == GW_KIND_GATEWAY && rate.mode == GW_RATE_HZ && rate.hz > 100) {
                config_error(ctx, ctx->line, "gateway_rate %s is out of range: at most 100 Hz", value);
                return false;
            }
            lcm->rate[k] = rate;
            lcm->rate_line[k] = ctx->line;
            return true;
        }
    }
    config_error(ctx, ctx->line,
                 "unknown key \"%s\" in [lcm] (keys: url, and KIND_channel, KIND_rate for KIND in "
                 "state, joints, tool, status, gateway)", key);
    return false;
}

static void lcm_finish(config_ctx *ctx, gw_config *cfg)
{
    gw_lcm_config *lcm = &cfg->lcm;
    if (lcm->url == NULL) {
        lcm->url = xstrdup(GW_DEFAULT_LCM_URL);
    }
    for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
        if (lcm->channel[k] == NULL) {
            lcm->channel[k] = xstrdup(kind_channels[k]);
        }
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
static bool version_length(config_ctx *ctx, const char *text, uint32_t *length, unsigned *rate_hz)
{
    const urrt_controller *found[2];
    uint32_t period_us = 0;
    int n = urrt_controller_find(text, strlen(text), found, 2, &period_us);
    if (n == 1) {
        *length = found[0]->length;
        *rate_hz = 1000000u / period_us;
        return true;
    }
    if (n == 2) {
        config_error(ctx, ctx->line, "version \"%s\": %s controllers sent %u or %u bytes: give the length instead "
                     "(version = %u or %u)", text, text, (unsigned)found[0]->length, (unsigned)found[1]->length,
                     (unsigned)found[0]->length, (unsigned)found[1]->length);
    } else if (n == 0) {
        config_error(ctx, ctx->line, "version \"%s\": no known controller version: give the message size in "
                     "bytes instead (e.g. version = 1220)", text);
    } else {
        config_error(ctx, ctx->line, "version \"%s\": expected auto, a controller version such as 5.10, or a "
                     "message size in bytes", text);
    }
    return false;
}

static bool robot_begin(config_ctx *ctx, gw_config *cfg, const char *name)
{
    gw_robot_config *robot, *grown;
    if (!config_identifier(ctx, "robot name", name, false)) {
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
    robot->port = URRT_LINK_PORT_RW;
    robot->expected = xstrdup("auto");
    robot->max_rate_hz = GW_ROBOT_MAX_RATE_HZ;
    urrt_link_config_defaults(&robot->link);
    return true;
}

static bool check_host(config_ctx *ctx, const char *host)
{
    size_t n = strlen(host);
    bool ipv6 = strchr(host, ':') != NULL;
    bool ok = n >= 1 && n <= 253;
    for (size_t i = 0; ok && i < n; i++) {
        unsigned char c = (unsigned char)host[i];
        ok = ipv6 ? (isxdigit(c) || c == ':' || c == '.' || c == '%' || isalnum(c))
                  : (isalnum(c) || c == '-' || c == '.');
    }
    if (!ok) {
        config_error(ctx, ctx->line, "host \"%s\" is not a host name, IPv4 or IPv6 address", host);
    }
    return ok;
}

static bool robot_key(config_ctx *ctx, gw_config *cfg, const char *key, const char *value)
{
    gw_robot_config *robot = &cfg->robots[cfg->robot_count - 1];
    unsigned long v;
    if (strcmp(key, "host") == 0) {
        if (!check_host(ctx, value)) {
            return false;
        }
        replace_string(&robot->host, value);
        robot->host_line = ctx->line;
        return true;
    }
    if (strcmp(key, "port") == 0) {
        if (!config_uint(ctx, "port", value, 1, 65535, &v)) {
            return false;
        }
        robot->port = (uint16_t)v;
        return true;
    }
    if (strcmp(key, "version") == 0) {
        uint32_t length = 0;
        unsigned rate = 1000000u / urrt_period_min_us(0);
        if (strcmp(value, "auto") == 0) {
            length = 0;
        } else if (strchr(value, '.') != NULL) {
            if (!version_length(ctx, value, &length, &rate)) {
                return false;
            }
        } else {
            char *end;
            errno = 0;
            v = strtoul(value, &end, 10);
            if (!isdigit((unsigned char)value[0]) || *end != '\0' || errno != 0 || v < URRT_PACKET_MIN ||
                v > URRT_PACKET_MAX || (v - URRT_HEADER_SIZE) % 8 != 0) {
                config_error(ctx, ctx->line,
                             "version \"%s\": expected auto, a controller version such as 5.10, or a message "
                             "size in bytes (4 + 8n, %d to %d)", value, URRT_PACKET_MIN, URRT_PACKET_MAX);
                return false;
            }
            length = (uint32_t)v;
            rate = 1000000u / urrt_period_min_us(length);
        }
        robot->expected_length = length;
        robot->max_rate_hz = rate;
        replace_string(&robot->expected, value);
        robot->version_line = ctx->line;
        return true;
    }
    if (strcmp(key, "connect_timeout") == 0) {
        return config_duration_ms(ctx, key, value, 10, 600000, &robot->link.connect_timeout_ms);
    }
    if (strcmp(key, "silence_timeout") == 0) {
        /* A 125 Hz controller sends every 8 ms: less than 20 ms would drop a
         * healthy link on ordinary jitter. */
        return config_duration_ms(ctx, key, value, 20, 600000, &robot->link.silence_timeout_ms);
    }
    if (strcmp(key, "backoff_initial") == 0) {
        return config_duration_ms(ctx, key, value, 10, 600000, &robot->link.backoff_initial_ms);
    }
    if (strcmp(key, "backoff_max") == 0) {
        return config_duration_ms(ctx, key, value, 10, 600000, &robot->link.backoff_max_ms);
    }
    config_error(ctx, ctx->line,
                 "unknown key \"%s\" in [robot %s] (keys: host, port, version, connect_timeout, "
                 "silence_timeout, backoff_initial, backoff_max)", key, robot->name);
    return false;
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
        robot->link.name = robot->name;
        robot->link.host = robot->host;
        robot->link.port = robot->port;
    }
}

/* ---- the section table ---------------------------------------------------------- */

/* One entry per section kind. CAN adds {"can", ...} and {"frame", true, ...}. */
/* ---- [can] and [frame NAME]: the CAN mapping (can_map.h checks them) ---- */

static void report_can_problem(void *user, const char *file, int line, const char *reason)
{
    (void)file; /* always this file: the map is fed one file */
    config_error(user, line, "%s", reason);
}

static bool can_section_key(config_ctx *ctx, gw_config *cfg, const char *key, const char *value)
{
    /* Problems reach config_error() through the reporter: no text buffer. */
    return can_map_ini(&cfg->can, ctx->section_raw, key, value, ctx->path, ctx->line, NULL, 0) == 1;
}

static void can_finish(config_ctx *ctx, gw_config *cfg)
{
    struct can_map_robot robots[GW_MAX_ROBOTS];
    (void)ctx;
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        robots[i].name = cfg->robots[i].name;
        robots[i].period_us = 1000000u / cfg->robots[i].max_rate_hz;
    }
    can_map_finish(&cfg->can, robots, cfg->robot_count, NULL, 0);
}

static const config_section config_sections[] = {
    {"gateway", false, false, NULL, gateway_key, NULL},
    {"robot", true, true, robot_begin, robot_key, robot_finish},
    {"lcm", false, false, NULL, lcm_key, lcm_finish},
    {"can", false, false, NULL, can_section_key, can_finish},
    {"frame", true, true, NULL, can_section_key, NULL},
};
#define CONFIG_SECTION_COUNT (sizeof config_sections / sizeof config_sections[0])

static void begin_section(config_ctx *ctx, const char *raw)
{
    char kind[64];
    const char *name;
    size_t kind_len;
    const config_section *sec = NULL;
    size_t index = 0;

    snprintf(ctx->section_raw, sizeof ctx->section_raw, "%s", raw);
    ctx->section = NULL;
    ctx->section_ok = false;
    ctx->key_count = 0;

    while (isspace((unsigned char)*raw)) {
        raw++;
    }
    kind_len = strcspn(raw, " \t");
    snprintf(kind, sizeof kind, "%.*s", (int)(kind_len < sizeof kind ? kind_len : sizeof kind - 1), raw);
    name = raw + kind_len;
    while (isspace((unsigned char)*name)) {
        name++;
    }
    char name_buf[256];
    snprintf(name_buf, sizeof name_buf, "%s", name);
    for (size_t n = strlen(name_buf); n > 0 && isspace((unsigned char)name_buf[n - 1]); n--) {
        name_buf[n - 1] = '\0';
    }
    for (index = 0; index < CONFIG_SECTION_COUNT; index++) {
        if (strcmp(config_sections[index].kind, kind) == 0) {
            sec = &config_sections[index];
            break;
        }
    }
    if (sec == NULL) {
        char known[256] = "";
        size_t used = 0;
        for (index = 0; index < CONFIG_SECTION_COUNT && used < sizeof known; index++) {
            used += (size_t)snprintf(known + used, sizeof known - used, "%s[%s%s]", index ? ", " : "",
                                     config_sections[index].kind, config_sections[index].named ? " NAME" : "");
        }
        config_error(ctx, ctx->line, "unknown section [%s] (sections: %s)", raw, known);
        return;
    }
    if (sec->named && name_buf[0] == '\0') {
        config_error(ctx, ctx->line, "section [%s] needs a name: [%s NAME]", kind, kind);
        return;
    }
    if (!sec->named && name_buf[0] != '\0') {
        config_error(ctx, ctx->line, "section [%s] takes no name, not \"%s\"", kind, name_buf);
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
    ctx->section_ok = sec->begin == NULL || sec->begin(ctx, ctx->cfg, sec->named ? name_buf : NULL);
}

/* Reads one line for inih and counts it, because Debian's libinih is built
 * without line numbers in the handler. It also sees each section header
 * first, so that empty and repeated sections are noticed too. */
static char *read_line(char *str, int num, void *stream)
{
    config_ctx *ctx = stream;
    const char *p;
    size_t n = 0;
    int c = 0;

    /* Byte by byte, not fgets: after a NUL byte strlen() would miss the
     * end of a long line, and its rest would count as a line of its own. */
    while (n + 1 < (size_t)num && c != '\n' && (c = getc(ctx->file)) != EOF) {
        str[n++] = (char)c;
    }
    if (n == 0) {
        return NULL;
    }
    str[n] = '\0';
    ctx->line++;
    if (n == (size_t)num - 1 && str[n - 1] != '\n' && (c = getc(ctx->file)) != EOF) {
        while (c != EOF && c != '\n') {
            c = getc(ctx->file);
        }
        config_error(ctx, ctx->line, "line longer than %d characters", num - 3);
        str[0] = '\n';
        str[1] = '\0';
        return str;
    }
    if (memchr(str, '\0', n) != NULL) {
        config_error(ctx, ctx->line, "a NUL byte: the configuration must be a text file");
        str[0] = '\n';
        str[1] = '\0';
        return str;
    }
    p = str;
    if (ctx->line == 1 && (unsigned char)p[0] == 0xEF && (unsigned char)p[1] == 0xBB && (unsigned char)p[2] == 0xBF) {
        p += 3;
    }
    /* Blanks as libinih skips them (isspace: a form feed too), so that a
     * line is a header for both or for neither. */
    while (isspace((unsigned char)*p)) {
        p++;
    }
    if (*p == '[') {
        const char *end = strchr(p, ']');
        if (end != NULL) {
            char raw[256];
            const char *rest = end + 1;
            while (isspace((unsigned char)*rest)) {
                rest++;
            }
            if (*rest != '\0' && *rest != ';' && *rest != '#') {
                /* libinih ignores it: "[lcm] url = ..." would be lost. */
                config_error(ctx, ctx->line, "text after the section header: \"%.*s\" (keys go on lines of their own)",
                             (int)strcspn(rest, "\r\n"), rest);
            }
            snprintf(raw, sizeof raw, "%.*s", (int)(end - p - 1), p + 1);
            begin_section(ctx, raw);
        } else {
            config_error(ctx, ctx->line, "section header without ']'");
            ctx->section = NULL;
            ctx->section_ok = false;
        }
    } else if (*p != '\0' && *p != '\n' && *p != '\r' && *p != ';' && *p != '#' &&
               strpbrk(p, "=:") == NULL) {
        config_error(ctx, ctx->line, "expected \"[section]\" or \"key = value\", not \"%.*s\"",
                     (int)strcspn(p, "\r\n"), p);
    }
    return str;
}

static int on_key(void *user, const char *section, const char *key, const char *value)
{
    config_ctx *ctx = user;
    if (section[0] == '\0') {
        config_error(ctx, ctx->line, "\"%s\" is outside of any section: put it under [gateway], [lcm] or [robot NAME]", key);
        return 0;
    }
    /* libinih keeps the first 49 characters of a section header only
     * ("[robot NAME]" takes up to 70): its name is a prefix of ours. */
    if (strncmp(section, ctx->section_raw, strlen(section)) != 0 || ctx->section == NULL || !ctx->section_ok) {
        return 1; /* the header's error was reported */
    }
    /* A frame's "signal" key adds one signal per line. */
    bool repeatable = strcmp(ctx->section->kind, "frame") == 0 && strcmp(key, "signal") == 0;
    for (unsigned i = 0; i < ctx->key_count && !repeatable; i++) {
        if (strcmp(ctx->keys[i].name, key) == 0) {
            config_error(ctx, ctx->line, "%s is set again (first at line %d)", key, ctx->keys[i].line);
            return 0;
        }
    }
    if (ctx->key_count < CONFIG_MAX_KEYS) {
        snprintf(ctx->keys[ctx->key_count].name, sizeof ctx->keys[0].name, "%s", key);
        ctx->keys[ctx->key_count++].line = ctx->line;
    }
    if (value[0] == '\0') {
        config_error(ctx, ctx->line, "%s has no value", key);
        return 0;
    }
    return ctx->section->key(ctx, ctx->cfg, key, value) ? 1 : 0;
}

static void config_defaults(gw_config *cfg, const char *path)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->path = path;
    cfg->log_level = URRT_LOG_NOTICE;
    cfg->lcm.rate[GW_KIND_STATE].mode = GW_RATE_EVERY;
    cfg->lcm.rate[GW_KIND_JOINTS].mode = GW_RATE_EVERY;
    cfg->lcm.rate[GW_KIND_TOOL].mode = GW_RATE_EVERY;
    cfg->lcm.rate[GW_KIND_STATUS] = (gw_rate){GW_RATE_HZ, 10};
    cfg->lcm.rate[GW_KIND_GATEWAY] = (gw_rate){GW_RATE_HZ, 1};

    can_map_init(&cfg->can);
}

static int config_parse(gw_config *cfg, FILE *in, FILE *err)
{
    config_ctx ctx;
    int seen[CONFIG_SECTION_COUNT] = {0};
    int r;

    memset(&ctx, 0, sizeof ctx);
    can_map_set_reporter(&cfg->can, report_can_problem, &ctx);
    ctx.path = cfg->path;
    ctx.err = err;
    ctx.cfg = cfg;
    ctx.seen_line = seen;
    ctx.file = in;
    /* A value is one line; ';' or '#' after a blank starts a comment. */
    ini_allow_multiline = false;
    ini_inline_comment_prefixes = ";#";
    r = ini_parse_stream(read_line, &ctx, on_key, &ctx);
    if (ferror(ctx.file)) {
        config_error(&ctx, 0, "read error: %s", strerror(errno));
    }
    if (r > 0 && ctx.errors == 0) {
        config_error(&ctx, r, "syntax error");
    } else if (r < 0 && ctx.errors == 0) {
        config_error(&ctx, 0, "cannot parse (inih error %d)", r);
    }
    for (size_t i = 0; i < CONFIG_SECTION_COUNT; i++) {
        if (config_sections[i].finish != NULL) {
            config_sections[i].finish(&ctx, cfg);
        }
    }
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
    can_map_free(&cfg->can);
    memset(cfg, 0, sizeof *cfg);
}

void gw_config_usage(FILE *out)
{
    fputs(
        "Configuration file (INI; '#' or ';' starts a comment; every key is optional\n"
        "unless marked required; an unknown section or key is an error):\n"
        "\n"
        "  [gateway]\n"
        "  log_level = err | warning | notice | info | debug    (notice)\n"
        "  summary = yes | no           one status line per second on stdout (no)\n"
        "\n"
        "  [lcm]\n"
        "  url = PROVIDER://...         (" GW_DEFAULT_LCM_URL ")\n"
        "  KIND_channel = SUFFIX        channel NAME.SUFFIX (STATE, JOINTS, TOOL, STATUS, GATEWAY)\n"
        "  KIND_rate = every | N Hz | off\n"
        "      KIND: state (every), joints (every), tool (every), status (10 Hz),\n"
        "            gateway (1 Hz; N Hz or off only). N Hz decimates on the\n"
        "            controller's clock and may not exceed the robot's rate.\n"
        "\n"
        "  [robot NAME]                 one per robot; NAME prefixes its channels\n"
        "  host = ADDRESS               required: host name, IPv4 or IPv6 address\n"
        "  port = N                     (30003; 30013 is the read-only port)\n"
        "  version = auto | X.Y | BYTES expected controller version or message size;\n"
        "                               other packets are counted as mismatches (auto)\n"
        "  connect_timeout = DURATION   (2 s)      DURATION: \"250 ms\", \"2 s\"\n"
        "  silence_timeout = DURATION   (100 ms)   no packet for this long: reconnect,\n"
        "                                          and no state is published meanwhile\n"
        "  backoff_initial = DURATION   (100 ms)   first wait before reconnecting\n"
        "  backoff_max = DURATION       (5 s)      doubling up to this\n"
        "\n"
        "  [can]                        CAN output (optional; docs/can.md has every key)\n"
        "  interface = can0 | log:PATH  SocketCAN interface, or candump log format\n"
        "  bitrate = 500000             for the bus load check and the DBC\n"
        "  heartbeat_id = 0x701         gateway state, modes, data age, drops (<= 1 s)\n"
        "\n"
        "  [frame NAME]                 one per CAN frame; NAME is its DBC name\n"
        "  id = 0x181                   (extended = yes for 29-bit)\n"
        "  period_ms = 10 | every       (fd = yes and length = 64 for CAN FD)\n"
        "  signal = FIELD[ELEM] ...     one line per signal: see docs/can.md\n",
        out);
}
