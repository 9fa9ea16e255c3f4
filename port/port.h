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

/* ---- CAN link ---------------------------------------------------------------- */

/*
 * A transmit-mostly CAN link: a SocketCAN raw socket on POSIX, or a file in
 * candump's log format (replayable with canplayer) for boxes without a CAN
 * interface. Sending never blocks the loop: a frame the driver cannot take
 * (ENOBUFS) waits in a one-deep slot per CAN ID, and a newer frame for that
 * ID replaces it and counts a drop, so an outage never replays a backlog. An
 * interface that goes down is reported and reopened. Error frames (bus-off,
 * restarted, ...) are received and counted.
 */
#define URRT_CAN_MAX_DATA 64

typedef struct urrt_can_frame {
    uint32_t id;    /* 11-bit, or 29-bit when extended */
    bool extended;
    bool fd;        /* CAN FD: len 0-8, 12, 16, 20, 24, 32, 48 or 64 */
    uint8_t len;
    uint8_t data[URRT_CAN_MAX_DATA];
} urrt_can_frame;

typedef struct urrt_can_config {
    const char *interface;     /* "can0", or "log:PATH" ("log:-" is stdout) */
    bool fd;                   /* FD frames allowed: needs an interface with the FD MTU */
    uint32_t reopen_interval_ms;
} urrt_can_config;

void urrt_can_config_defaults(urrt_can_config *cfg);

typedef enum urrt_can_state {
    URRT_CAN_DOWN = 0,         /* not open, or the interface is down; reopening */
    URRT_CAN_UP
} urrt_can_state;

typedef struct urrt_can_stats {
    uint64_t sent;
    uint64_t dropped;          /* values replaced before they could be sent, or discarded by an outage */
    uint64_t send_errors;
    uint64_t opens;
    uint64_t down_events;
    uint64_t error_frames;
    uint64_t bus_off;
    uint64_t restarts;
    uint32_t last_error_class; /* CAN_ERR_* bits of the last error frame */
} urrt_can_stats;

typedef struct urrt_can urrt_can;

/* NULL with a logged reason when the configuration cannot work (an FD link
 * on an interface without the FD MTU, say). */
urrt_can *urrt_can_new(const urrt_can_config *cfg);
void urrt_can_free(urrt_can *can);

/* Queue a frame for sending now; never blocks. Negative on a frame the link
 * can never send (FD frame on a classic link, bad length). */
int urrt_can_send(urrt_can *can, const urrt_can_frame *frame, uint64_t now_us);

int urrt_can_poll_fd(const urrt_can *can, short *events);
uint64_t urrt_can_deadline(const urrt_can *can);
void urrt_can_service(urrt_can *can, uint64_t now_us);
urrt_can_state urrt_can_get_state(const urrt_can *can);
const urrt_can_stats *urrt_can_get_stats(const urrt_can *can);

#ifdef __cplusplus
}
#endif

#endif /* URRT_PORT_H */
