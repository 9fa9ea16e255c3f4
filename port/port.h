/*
 * port.h: what the urrt programs need from the operating system.
 *
 * This is the seam a firmware replaces: the programs in gateway/ call only
 * what is declared here (plus LCM on POSIX), and port/posix/ implements it
 * for Linux. A firmware gateway implements the same functions on its own TCP
 * stack, CAN controller and timer, or drops the parts it has no use for.
 *
 * Nothing here blocks unless it says so: the programs run one poll loop over
 * every link, and each link says which descriptor to wait on and by when it
 * must be serviced again.
 */
#ifndef URRT_PORT_H
#define URRT_PORT_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- clock --------------------------------------------------------------- */

/* Monotonic time in microseconds: for periods, timeouts and data age. */
uint64_t urrt_port_monotonic_us(void);
/* Wall-clock time in microseconds since the Unix epoch: for timestamps that
 * leave the box (LCM utime). */
uint64_t urrt_port_realtime_us(void);

/* ---- logging ------------------------------------------------------------- */

/* Levels are syslog priorities, so that journald shows them as such. */
typedef enum urrt_log_level {
    URRT_LOG_ERR = 3,
    URRT_LOG_WARNING = 4,
    URRT_LOG_NOTICE = 5,
    URRT_LOG_INFO = 6,
    URRT_LOG_DEBUG = 7
} urrt_log_level;

/* program: prefix of every line; lines above max_level are dropped. */
void urrt_log_init(const char *program, urrt_log_level max_level);
void urrt_log(urrt_log_level level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* ---- robot link ------------------------------------------------------------ */

/*
 * A read-only TCP link to a robot's RealTime port. It never writes a byte
 * (port 30003 executes URScript sent to it). It connects without blocking,
 * frames the stream with urrt_framer, and on a closed or reset connection, a
 * failed connect or silence longer than silence_timeout_ms (a half-open
 * link) it closes and reconnects with capped exponential backoff. Each state
 * change is logged once, not once per attempt.
 */
typedef struct urrt_link_config {
    const char *name;            /* robot name for log lines */
    const char *host;            /* host name, IPv4 or IPv6 literal */
    uint16_t port;               /* URRT_LINK_PORT_RW or URRT_LINK_PORT_RO */
    uint32_t connect_timeout_ms;
    uint32_t silence_timeout_ms;
    uint32_t backoff_initial_ms;
    uint32_t backoff_max_ms;
} urrt_link_config;

#define URRT_LINK_PORT_RW 30003
#define URRT_LINK_PORT_RO 30013

/* Defaults: port 30003, connect 2 s, silence 100 ms (12 periods at 125 Hz),
 * backoff 100 ms doubling to 5 s. */
void urrt_link_config_defaults(urrt_link_config *cfg);

typedef enum urrt_link_state {
    URRT_LINK_IDLE = 0,      /* waiting out the backoff before the next attempt */
    URRT_LINK_CONNECTING,
    URRT_LINK_UP             /* connected; packets may flow */
} urrt_link_state;

const char *urrt_link_state_name(urrt_link_state state);

typedef struct urrt_link_stats {
    uint64_t connects;       /* connections established */
    uint64_t reconnects;     /* connections established after a loss */
    uint64_t disconnects;    /* established connections lost (closed, reset, silent) */
    uint64_t connect_failures;
    uint64_t silences;       /* disconnects caused by silence */
    uint64_t bytes;
    uint64_t packets;
    uint64_t resyncs;
    uint64_t skipped;        /* bytes dropped while resynchronising */
    uint64_t partial_drops;  /* incomplete packets dropped when a connection ended */
    uint64_t last_packet_us; /* monotonic time of the last packet, 0 if none */
} urrt_link_stats;

typedef struct urrt_link urrt_link;

/* Called for each complete packet, in order. The bytes are valid during the
 * call only. rx_us is the monotonic time the bytes were read. */
typedef void (*urrt_packet_fn)(void *ctx, const uint8_t *packet, size_t len, uint64_t rx_us);

/* NULL with a logged reason when the configuration is unusable. The first
 * connection attempt starts at the first service call. */
urrt_link *urrt_link_new(const urrt_link_config *cfg);
void urrt_link_free(urrt_link *link);

/* The descriptor to wait on and the poll events to wait for (POLLIN or
 * POLLOUT), or -1 when there is none (waiting out the backoff). It changes
 * across reconnects: ask again before each wait. */
int urrt_link_poll_fd(const urrt_link *link, short *events);

/* Monotonic time by which urrt_link_service must run again at the latest. */
uint64_t urrt_link_deadline(const urrt_link *link);

/* Does what is due: connect progress, reads (bounded per call), framing,
 * timeouts, backoff. Calls fn for each complete packet. Never blocks. */
void urrt_link_service(urrt_link *link, uint64_t now_us, urrt_packet_fn fn, void *ctx);

urrt_link_state urrt_link_get_state(const urrt_link *link);
const urrt_link_stats *urrt_link_get_stats(const urrt_link *link);

#ifdef __cplusplus
}
#endif

#endif /* URRT_PORT_H */
