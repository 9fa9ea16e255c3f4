/* SPDX-License-Identifier: MIT */
/*
 * cli.h: small helpers the urrt programs share: argument parsing with
 * useful errors, options read by a table, and the signal handling of a poll
 * loop.
 *
 * Values on a command line are read by conf.h's parsers (included here),
 * as in the gateway's configuration file: the same integer, duration and
 * boolean grammar everywhere. The address parsers return NULL on success or
 * a short English reason for the caller to put in its message.
 */
#ifndef URRT_CLI_H
#define URRT_CLI_H

#include <getopt.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "conf.h"
#include "port.h"

/* Exit codes every program documents in --help. */
enum {
    CLI_EXIT_OK = 0,
    CLI_EXIT_RUNTIME = 1, /* a file, socket or peer failed */
    CLI_EXIT_USAGE = 2    /* bad command line or configuration */
};

/*
 * "HOST", "HOST:PORT", "[V6]", "[V6]:PORT", or a bare IPv6 literal ("::1",
 * which has more than one colon and so no port). host receives the host
 * without brackets; *port the port, or default_port when none is given.
 */
const char *cli_parse_host_port(const char *arg, uint16_t default_port, char *host, size_t host_size,
                                uint16_t *port);

/* The same for an address to listen on: port 0 too (the system picks a free one). */
const char *cli_parse_listen_address(const char *arg, uint16_t default_port, char *host, size_t host_size,
                                     uint16_t *port);

/* "host:port", or "[host]:port" when host holds a colon. */
void cli_format_host_port(const char *host, uint16_t port, char *out, size_t out_size);

/* conf_uint and conf_u32 with the reason as the result (NULL: success),
 * valid until the next call: for the address parsers and older callers. */
const char *cli_parse_u64(const char *text, uint64_t min, uint64_t max, uint64_t *out);
const char *cli_parse_u32(const char *text, uint32_t min, uint32_t max, uint32_t *out);

/* "PROGRAM: <message>" and "Try 'PROGRAM --help'." on stderr, then exit
 * with CLI_EXIT_USAGE. */
void cli_usage_error(const char *program, const char *fmt, ...) __attribute__((format(printf, 2, 3), noreturn));

/* ---- options read by a table ------------------------------------------------------ */

/* Which conf.h parser reads an option's argument, and what it stores. */
typedef enum cli_kind {
    CLI_FN = 0,    /* the row's fn reads the argument and stores it */
    CLI_TRUE,      /* no argument: sets a bool */
    CLI_FALSE,     /* no argument: clears a bool (--no-...) */
    CLI_TEXT,      /* the argument as given, into a const char * */
    CLI_UINT,      /* conf_uint in [min, max], into a uint64_t */
    CLI_U32,       /* conf_u32 in [min, max], into a uint32_t */
    CLI_MS,        /* conf_duration_ms (a bare number is milliseconds) in [min, max], into a uint32_t */
    CLI_SECONDS,   /* conf_duration_us (a bare number is seconds) in [min, max] microseconds,
                      into a double of seconds */
    CLI_WORD,      /* one of words, into an enum of int's size: the word's index */
    CLI_VERBOSE,   /* no argument: an urrt_log_level from notice to info, then debug */
    CLI_QUIET,     /* no argument: an urrt_log_level of errors only */
    CLI_HELP,      /* no argument: the program's usage text on stdout, and exit */
    CLI_VERSION    /* no argument: cli_print_version */
} cli_kind;

typedef struct cli_option cli_option;
/* Reads arg (NULL for an option without one) into the options object obj,
 * or ends the program with cli_usage_error. */
typedef void (*cli_option_fn)(const cli_option *row, const char *arg, void *obj);

/* One option: its names, how its argument is read, and where it goes. */
struct cli_option {
    const char *name;        /* the long name, without "--" */
    char letter;             /* the short name, or 0 for none */
    int arg;                 /* getopt's no_argument, required_argument or optional_argument;
                                an optional argument only in the long form (--name=VALUE) */
    cli_kind kind;
    size_t offset;           /* of the destination in the options object (not CLI_FN) */
    uint64_t min, max;       /* CLI_UINT, CLI_U32, CLI_MS (milliseconds), CLI_SECONDS (microseconds) */
    const char *hint;        /* after the reason in the message: " (milliseconds)" */
    const char *const *words; /* CLI_WORD: the words, NULL at the end */
    /* CLI_FN: reads and stores the argument. Other kinds: NULL, or called once
     * the value is stored (a check of its own, noting that it was given). */
    cli_option_fn fn;
};

/* A program's options: its name for the messages, and its table. */
typedef struct cli_options {
    const char *program;
    const cli_option *rows;
    size_t count;
    void (*usage)(FILE *out); /* CLI_HELP */
    /* Called with getopt's optopt for an unknown option or a missing
     * argument, before "Try 'PROGRAM --help'." (may end the program with a
     * message of its own); NULL: none. */
    void (*on_unknown)(int optopt);
} cli_options;

/* Reads argv's options by the table into obj; a bad value, an unknown
 * option or a missing argument ends the program with CLI_EXIT_USAGE. The
 * result is the index of the first operand. */
int cli_parse_options(const cli_options *set, int argc, char **argv, void *obj);

/* "PROGRAM VERSION" on stdout, and exit with CLI_EXIT_OK. */
void cli_print_version(const char *program) __attribute__((noreturn));

/* "PROGRAM: --NAME ARG: WHY<hint>" and the usage exit: for a row's fn whose
 * value is refused. */
void cli_bad_value(const char *program, const cli_option *row, const char *arg, const char *why)
    __attribute__((noreturn));

/*
 * SIGINT and SIGTERM clear *running (without SA_RESTART, so that a blocking
 * poll returns EINTR and the loop looks at the flag); SIGPIPE is ignored, so
 * that writing to a closed socket or pipe is an EPIPE error and not death.
 */
void cli_handle_signals(volatile sig_atomic_t *running);
/* The signal that cleared the flag, 0 if none. */
int cli_stop_signal(void);

#endif
