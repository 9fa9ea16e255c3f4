/* SPDX-License-Identifier: MIT */
/*
 * cli.h: small helpers the urrt programs share: argument parsing with
 * useful errors, and the signal handling of a poll loop.
 *
 * Values on a command line are read by conf.h's parsers (included here),
 * as in the gateway's configuration file: the same integer, duration and
 * boolean grammar everywhere. The address parsers return NULL on success or
 * a short English reason for the caller to put in its message.
 */
#ifndef URRT_CLI_H
#define URRT_CLI_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "conf.h"

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

/* conf_uint, conf_u32 and conf_number with the reason as the result (NULL:
 * success), valid until the next call: for the address parsers and older
 * callers. */
const char *cli_parse_u64(const char *text, uint64_t min, uint64_t max, uint64_t *out);
const char *cli_parse_u32(const char *text, uint32_t min, uint32_t max, uint32_t *out);
const char *cli_parse_double(const char *text, double min, double max, double *out);

/*
 * SIGINT and SIGTERM clear *running (without SA_RESTART, so that a blocking
 * poll returns EINTR and the loop looks at the flag); SIGPIPE is ignored, so
 * that writing to a closed socket or pipe is an EPIPE error and not death.
 */
void cli_handle_signals(volatile sig_atomic_t *running);
/* The signal that cleared the flag, 0 if none. */
int cli_stop_signal(void);

#endif
