/* SPDX-License-Identifier: MIT */
/* cli.c: see cli.h. */
#define _GNU_SOURCE
#include "cli.h"

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

const char *cli_parse_double(const char *text, double min, double max, double *out)
{
    return conf_number(text, min, max, out, cli_why, sizeof cli_why) ? NULL : cli_why;
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
