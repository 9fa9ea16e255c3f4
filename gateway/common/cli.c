/* SPDX-License-Identifier: MIT */
/* cli.c: see cli.h. */
#define _GNU_SOURCE
#include "cli.h"
#include "urrt.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *parse_host_port(const char *arg, uint16_t default_port, uint32_t min_port, char *host,
                                   size_t host_size, uint16_t *port)
{
    const char *host_start = arg;
    size_t host_len;
    const char *port_text = NULL;

    if (arg == NULL || arg[0] == '\0') {
        return "empty address";
    }
    if (arg[0] == '[') {
        const char *close = strchr(arg, ']');
        if (close == NULL) {
            return "'[' without ']' (write an IPv6 address as [::1]:30003)";
        }
        host_start = arg + 1;
        host_len = (size_t)(close - host_start);
        if (close[1] == ':') {
            port_text = close + 2;
        } else if (close[1] != '\0') {
            return "text after ']' that is not \":PORT\"";
        }
    } else {
        const char *colon = strchr(arg, ':');
        host_len = strlen(arg);
        if (colon != NULL && strchr(colon + 1, ':') == NULL) {
            host_len = (size_t)(colon - arg);
            port_text = colon + 1;
        }
        /* Several colons: a bare IPv6 literal, no port. */
    }
    if (host_len == 0) {
        return "no host before the port";
    }
    if (host_len >= host_size) {
        return "host name too long";
    }
    memcpy(host, host_start, host_len);
    host[host_len] = '\0';
    *port = default_port;
    if (port_text != NULL) {
        uint32_t p;
        const char *err = cli_parse_u32(port_text, min_port, 65535, &p);
        if (err != NULL) {
            return port_text[0] == '\0' ? "no port after ':'"
                   : min_port == 0       ? "port must be a number from 0 to 65535"
                                         : "port must be a number from 1 to 65535";
        }
        *port = (uint16_t)p;
    }
    return NULL;
}

const char *cli_parse_host_port(const char *arg, uint16_t default_port, char *host, size_t host_size,
                                uint16_t *port)
{
    return parse_host_port(arg, default_port, 1, host, host_size, port);
}

const char *cli_parse_listen_address(const char *arg, uint16_t default_port, char *host, size_t host_size,
                                     uint16_t *port)
{
    return parse_host_port(arg, default_port, 0, host, host_size, port);
}

void cli_format_host_port(const char *host, uint16_t port, char *out, size_t out_size)
{
    snprintf(out, out_size, strchr(host, ':') != NULL ? "[%s]:%u" : "%s:%u", host, (unsigned)port);
}

/* The programs are single-threaded: one buffer for the reason. */
static char cli_why[CONF_WHY_MAX];

const char *cli_parse_u64(const char *text, uint64_t min, uint64_t max, uint64_t *out)
{
    return conf_uint(text, min, max, out, cli_why, sizeof cli_why) ? NULL : cli_why;
}

const char *cli_parse_u32(const char *text, uint32_t min, uint32_t max, uint32_t *out)
{
    return conf_u32(text, min, max, out, cli_why, sizeof cli_why) ? NULL : cli_why;
}

void cli_usage_error(const char *program, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", program);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry '%s --help'.\n", program);
    exit(CLI_EXIT_USAGE);
}

/* ---- options read by a table ------------------------------------------------------ */

/* getopt_long's value for a long name without a letter: past any char. */
#define CLI_LONG_ONLY 256
/* Options of one program at most: its getopt tables live on the stack. */
#define CLI_OPTIONS_MAX 40

void cli_bad_value(const char *program, const cli_option *row, const char *arg, const char *why)
{
    cli_usage_error(program, "--%s %s: %s%s", row->name, arg, why, row->hint != NULL ? row->hint : "");
}

void cli_print_version(const char *program)
{
    printf("%s %s\n", program, URRT_VERSION_STRING);
    exit(CLI_EXIT_OK);
}

/* "--clock sundial: use start, monotonic or realtime". */
static void bad_word(const char *program, const cli_option *row, const char *arg)
{
    char list[CONF_WHY_MAX] = "";
    size_t used = 0;
    for (size_t i = 0; row->words[i] != NULL && used < sizeof list; i++) {
        const char *sep = i == 0 ? "" : row->words[i + 1] == NULL ? " or " : ", ";
        used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", sep, row->words[i]);
    }
    cli_usage_error(program, "--%s %s: use %s", row->name, arg, list);
}

static int word_index(const char *const *words, const char *arg)
{
    for (int i = 0; words[i] != NULL; i++) {
        if (strcmp(words[i], arg) == 0) {
            return i;
        }
    }
    return -1;
}

/* Parses arg by row->kind into field; false with the reason in why. */
static bool read_value(const cli_option *row, const char *arg, void *field, char *why, size_t n)
{
    uint64_t us;
    switch (row->kind) {
    case CLI_TEXT: *(const char **)field = arg; return true;
    case CLI_UINT: return conf_uint(arg, row->min, row->max, field, why, n);
    case CLI_U32: return conf_u32(arg, (uint32_t)row->min, (uint32_t)row->max, field, why, n);
    case CLI_MS: return conf_duration_ms(arg, "ms", (uint32_t)row->min, (uint32_t)row->max, field, why, n);
    case CLI_SECONDS:
        if (!conf_duration_us(arg, "s", row->min, row->max, &us, why, n)) {
            return false;
        }
        *(double *)field = (double)us / 1e6;
        return true;
    default: return conf_fail(why, n, "option kind %d takes no value (a bug in the table)", (int)row->kind);
    }
}

static void apply(const cli_options *set, const cli_option *row, const char *arg, void *obj)
{
    char why[CONF_WHY_MAX];
    void *field = (char *)obj + row->offset;
    urrt_log_level *level = field;
    int word;

    switch (row->kind) {
    case CLI_FN: row->fn(row, arg, obj); return;
    case CLI_TRUE: *(bool *)field = true; break;
    case CLI_FALSE: *(bool *)field = false; break;
    case CLI_VERBOSE: *level = *level == URRT_LOG_NOTICE ? URRT_LOG_INFO : URRT_LOG_DEBUG; break;
    case CLI_QUIET: *level = URRT_LOG_ERR; break;
    case CLI_HELP: set->usage(stdout); exit(CLI_EXIT_OK);
    case CLI_VERSION: cli_print_version(set->program);
    case CLI_WORD:
        if ((word = word_index(row->words, arg)) < 0) {
            bad_word(set->program, row, arg);
        }
        memcpy(field, &word, sizeof word); /* an enum: int's size (the tables' users assert it) */
        break;
    default:
        if (!read_value(row, arg, field, why, sizeof why)) {
            cli_bad_value(set->program, row, arg, why);
        }
    }
    if (row->fn != NULL) {
        row->fn(row, arg, obj);
    }
}

/* getopt_long's option string and table from the rows. */
static void getopt_tables(const cli_options *set, char *letters, struct option *longs)
{
    size_t k = 0;
    for (size_t i = 0; i < set->count; i++) {
        const cli_option *row = &set->rows[i];
        int val = row->letter != 0 ? row->letter : CLI_LONG_ONLY + (int)i;
        longs[i] = (struct option){row->name, row->arg, NULL, val};
        if (row->letter != 0) {
            letters[k++] = row->letter;
            if (row->arg == required_argument) {
                letters[k++] = ':';
            }
        }
    }
    letters[k] = '\0';
    longs[set->count] = (struct option){NULL, 0, NULL, 0};
}

static const cli_option *row_of(const cli_options *set, int c)
{
    if (c >= CLI_LONG_ONLY) {
        return &set->rows[c - CLI_LONG_ONLY];
    }
    for (size_t i = 0; i < set->count; i++) {
        if (set->rows[i].letter == c) {
            return &set->rows[i];
        }
    }
    return NULL;
}

int cli_parse_options(const cli_options *set, int argc, char **argv, void *obj)
{
    char letters[2 * CLI_OPTIONS_MAX + 1];
    struct option longs[CLI_OPTIONS_MAX + 1];
    int c;

    if (set->count > CLI_OPTIONS_MAX) {
        cli_usage_error(set->program, "%zu options: more than cli.c's CLI_OPTIONS_MAX (a bug)", set->count);
    }
    getopt_tables(set, letters, longs);
    while ((c = getopt_long(argc, argv, letters, longs, NULL)) != -1) {
        const cli_option *row = row_of(set, c);
        if (row == NULL) {
            /* getopt said what was wrong. */
            if (set->on_unknown != NULL) {
                set->on_unknown(optopt);
            }
            fprintf(stderr, "Try '%s --help'.\n", set->program);
            exit(CLI_EXIT_USAGE);
        }
        apply(set, row, optarg, obj);
    }
    return optind;
}

static volatile sig_atomic_t *running_flag;
static volatile sig_atomic_t stop_signal;

static void on_stop_signal(int sig)
{
    stop_signal = sig;
    if (running_flag != NULL) {
        *running_flag = 0;
    }
}

void cli_handle_signals(volatile sig_atomic_t *running)
{
    struct sigaction sa;
    running_flag = running;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: poll must return EINTR */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL);
}

int cli_stop_signal(void)
{
    return (int)stop_signal;
}
