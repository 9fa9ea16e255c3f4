/* SPDX-License-Identifier: MIT */
/*
 * port.h: the robot link (urrt_link_*), the CAN link (urrt_canlink_*), the
 * clock and logging.
 *
 * These are the parts of a gateway that sit on an operating system's
 * network, CAN and timer services, the seam a firmware replaces: port/posix/
 * implements them for Linux (non-blocking TCP sockets, SocketCAN or a
 * candump log file, clock_gettime, stderr), and a firmware gateway
 * implements the same functions on its own TCP stack, CAN controller and
 * timer, or drops the parts it has no use for (docs/porting.md).
 *
 * It is not everything the programs take from the system. urrt-gateway,
 * urrt-dump and urrt-sim are POSIX programs: they run their own wait loop,
 * handle signals, read and write files, urrt-gateway publishes on LCM, and
 * urrt-sim opens its listening sockets and reads the clocks itself. A
 * firmware does not port those programs; it keeps lib/, writes its own main
 * loop, and uses this header's contracts for its link, CAN and clock.
 *
 * Nothing here blocks. The wait interface is POSIX's: each link names a
 * descriptor and poll() events to wait for (-1: none) and a deadline by
 * which it must be serviced again; a port without descriptors returns -1
 * and is driven by the deadlines (and its stack's receive events) alone.
 */
#ifndef URRT_PORT_H
#define URRT_PORT_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt.h"
#include "urrt_can.h"

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

/* Change the threshold after init (a --verbose option, say). */
void urrt_log_set_level(urrt_log_level max_level);
/* "error", "warning", "notice", "info", "debug". */
const char *urrt_log_level_name(urrt_log_level level);

/* Route messages (without prefix or newline) to fn instead of stderr, or
 * back to stderr with NULL: for tests, and for firmware that keeps a log
 * ring. Messages above the threshold are still dropped first. */
typedef void (*urrt_log_sink_fn)(void *ctx, urrt_log_level level, const char *message);
void urrt_log_set_sink(urrt_log_sink_fn fn, void *ctx);

/* ---- robot link ------------------------------------------------------------ */

/*
 * A TCP link to a robot. By default it reads the RealTime port and never
 * writes a byte (port 30003 executes URScript sent to it): it frames the
 * stream with urrt_framer. A source that speaks first (RTDE, port 30004)
 * plugs in with urrt_link_set_source, below: it queues its handshake at
 * every connect, takes the bytes read and says when its data flows. Either
 * way the link connects without blocking, and on a closed or reset
 * connection, a failed connect or silence longer than silence_timeout_ms (a
 * half-open link) it closes and reconnects with capped exponential backoff.
 * Each state change is logged once, not once per attempt.
 *
 * The link is up when data flows, not when TCP connects: a controller whose
 * process is stopped still has its kernel accept connections. A connection
 * is URRT_LINK_WAITING until its first packet (for a source: until the
 * source reports its first data package), and one that ends before it is a
 * failed attempt, not a connect and a disconnect.
 */
typedef struct urrt_link_config {
    const char *name;            /* robot name for log lines */
    const char *host;            /* host name, IPv4 or IPv6 literal */
    uint16_t port;               /* URRT_LINK_PORT_RW or URRT_LINK_PORT_RO */
    uint32_t connect_timeout_ms;
    uint32_t silence_timeout_ms; /* 0: never treat silence as a lost link */
    uint32_t backoff_initial_ms;
    uint32_t backoff_max_ms;
} urrt_link_config;

#define URRT_LINK_PORT_RW 30003
#define URRT_LINK_PORT_RO 30013

/* The silence that drops a link by default: 12 periods at 125 Hz. A
 * literal: urrt-gateway's key table shows it as text. */
#define URRT_LINK_SILENCE_TIMEOUT_MS 100

/* Defaults: port 30003, connect 2 s, silence URRT_LINK_SILENCE_TIMEOUT_MS,
 * backoff 100 ms doubling to 5 s. */
void urrt_link_config_defaults(urrt_link_config *cfg);

/* The values are on the wire (urrt-gateway's GATEWAY message): WAITING was
 * added after UP, and none of them changes. */
typedef enum urrt_link_state {
    URRT_LINK_IDLE = 0,       /* waiting out the backoff before the next attempt */
    URRT_LINK_CONNECTING = 1, /* the TCP connect is in progress */
    URRT_LINK_UP = 2,         /* data flows: a packet arrived on this connection */
    URRT_LINK_WAITING = 3     /* TCP connected, no packet yet (a source's handshake, or
                                 a peer that accepts and sends nothing) */
} urrt_link_state;

const char *urrt_link_state_name(urrt_link_state state);

typedef struct urrt_link_stats {
    uint64_t connects;       /* times the link came up (a connection delivered a packet) */
    uint64_t reconnects;     /* of those, the ones after a loss */
    uint64_t disconnects;    /* times an up link went down (closed, reset, silent, dropped) */
    uint64_t connect_failures; /* attempts that never came up: refused, timed out, or a
                                  connection that ended before its first packet */
    uint64_t silences;       /* disconnects caused by silence */
    uint64_t bytes;
    uint64_t packets;
    uint64_t resyncs;
    uint64_t skipped;        /* bytes dropped while resynchronising */
    uint64_t partial_drops;  /* incomplete packets dropped when a connection ended */
    uint64_t last_packet_us; /* monotonic time of the last packet, 0 if none */
    uint64_t partial_bytes;  /* bytes of those incomplete packets */
    uint32_t last_length;    /* size of the last packet, 0 if none */
    uint64_t sockets;        /* sockets opened (one per address tried): a new socket may
                                get a closed one's descriptor number, this tells them apart */
    uint64_t read_waits;     /* urrt_link_service_waiting calls that waited in the read */
} urrt_link_stats;

typedef struct urrt_link urrt_link;

/* Called for each complete packet, in order. The bytes are valid during the
 * call only. rx_us is the monotonic time the read that completed the packet
 * returned (taken per read, not per service call). */
typedef void (*urrt_packet_fn)(void *ctx, const uint8_t *packet, size_t len, uint64_t rx_us);

/* NULL with a logged reason when the configuration is unusable. The first
 * connection attempt starts at the first service call. */
urrt_link *urrt_link_new(const urrt_link_config *cfg);
void urrt_link_free(urrt_link *link);

/* The descriptor to wait on and the poll events to wait for (POLLOUT while
 * connecting; POLLIN once connected, with POLLOUT while a source's bytes
 * wait to be written), or -1 when there is none (waiting out the backoff:
 * the socket is closed). It and its events change only in
 * urrt_link_service and urrt_link_send: a loop that registers it once
 * (epoll) asks again after those, and registers anew when the descriptor,
 * the events or stats.sockets changed. */
int urrt_link_poll_fd(const urrt_link *link, short *events);

/* Monotonic time by which urrt_link_service must run again at the latest. */
uint64_t urrt_link_deadline(const urrt_link *link);

/* Does what is due: connect progress, writes of a source's queue, reads
 * (bounded per call), framing, timeouts, backoff. Calls fn for each
 * complete packet (with a source: each package it reports). Never blocks. */
void urrt_link_service(urrt_link *link, uint64_t now_us, urrt_packet_fn fn, void *ctx);

/*
 * urrt_link_service for a loop whose only descriptor is this link's: the
 * read is the wait, one system call a packet where a wait and a read are
 * two. It waits in the socket's first read, ending by until_us (monotonic)
 * at the latest, and then does what urrt_link_service does; the stamps
 * (rx_us, the empty queue) mean what they mean there, the empty queue
 * taken from the kernel's receive time of the bytes the wait returned
 * (SO_TIMESTAMPNS). It waits only while the link is connected with nothing
 * to write and nothing left to read, and until_us leaves room for the
 * read's timeout (a kernel tick and twice URRT_LINK_WAIT_MIN_US, about
 * 6 ms at 250 Hz); otherwise it does nothing and returns false, and the
 * loop waits its own way (poll, epoll). A signal ends the wait (EINTR).
 */
#define URRT_LINK_WAIT_MIN_US 1000u /* the shortest timeout the read is given */
bool urrt_link_service_waiting(urrt_link *link, uint64_t until_us, urrt_packet_fn fn, void *ctx);

urrt_link_state urrt_link_get_state(const urrt_link *link);
const urrt_link_stats *urrt_link_get_stats(const urrt_link *link);

/* During a packet callback: a monotonic time at which the socket's queue
 * was seen empty before the packet's first byte was read, so every byte of
 * the packet arrived on this host after it. rx_us minus it bounds how long
 * the packet waited here (in the socket or half-read), however the process
 * was delayed: a reader that keeps up sees about one period, one that falls
 * behind sees its backlog grow. */
uint64_t urrt_link_packet_empty_us(const urrt_link *link);
/* During a packet callback: whether nothing newer had arrived when the
 * packet was read (the read emptied the socket's queue and no further
 * packet follows in it). The first packets of a connection that come in a
 * burst are not: their age cannot be judged until the newest has come. */
bool urrt_link_packet_newest(const urrt_link *link);
/* "host:port" as log lines name the robot ("[::1]:30003" for IPv6). */
const char *urrt_link_peer(const urrt_link *link);

/* A tap on the raw stream, for recording it: fn receives every byte read,
 * in order, in pieces that end where a packet ends, each piece before the
 * packet callback for the packet it completes (so a recorder can keep the
 * bytes up to the last complete packet). Bytes of a packet that a lost
 * connection ended inside are never completed: the next connection starts
 * afresh. With a source (below) the pieces are the reads, each before the
 * source receives it. NULL removes the tap. */
typedef void (*urrt_bytes_fn)(void *ctx, const uint8_t *data, size_t len);
void urrt_link_set_tap(urrt_link *link, urrt_bytes_fn fn, void *ctx);

/*
 * A source that speaks first. Without one the link is the RealTime reader
 * above and never writes. With one (set before the first service call):
 *
 * - connected() runs at every TCP connect, before any byte is read: the
 *   source starts its session afresh (a reconnect redoes all of it) and
 *   queues its opening bytes with urrt_link_send.
 * - received() gets every byte read, in order, as read (the link's framer
 *   is not used); rx_us as for urrt_packet_fn. The link reads whenever
 *   bytes arrive, so the source is never a slow reader.
 * - The source calls urrt_link_source_packet for each data package its
 *   session decodes: the link counts it, comes up at the first one of the
 *   connection (so "up" means the handshake is done and data arrived), and
 *   hands it to the urrt_packet_fn of the service call in progress.
 * - urrt_link_drop(URRT_LINK_DROP_PROTOCOL, why) ends the connection (the
 *   peer broke the protocol): logged like a lost connection or a failed
 *   attempt, retried with the usual backoff.
 *   urrt_link_drop(URRT_LINK_DROP_CONFIG, why) ends it because the peer
 *   refuses what the configuration asks (an RTDE recipe names a field the
 *   controller does not have: why should name them and the controller's
 *   version): logged once as an error, not again until the link has come
 *   up or the reason changes, and retried every backoff_max_ms.
 *
 * Bytes queued with urrt_link_send are written when the socket is writable
 * (urrt_link_poll_fd asks for POLLOUT while some wait), never blocking,
 * partial writes continued; the queue holds URRT_LINK_SEND_MAX bytes and is
 * emptied at every new connection. Silence detection, keepalive, the
 * connect timeout and the backoff are the same as without a source.
 * urrt_link_send, urrt_link_source_packet and urrt_link_drop may be called
 * from inside the source's functions; the link acts on a drop when the
 * function returns. In the packet callback of a source's package,
 * urrt_link_packet_empty_us is a time the queue was seen empty before the
 * read that brought the first byte after the previous package (never later
 * than the package's first byte), and urrt_link_packet_newest whether the
 * current read emptied the queue.
 */
typedef struct urrt_link_source {
    void *ctx;
    void (*connected)(void *ctx, urrt_link *link, uint64_t now_us);
    void (*received)(void *ctx, urrt_link *link, const uint8_t *data, size_t len, uint64_t rx_us);
} urrt_link_source;

#define URRT_LINK_SEND_MAX 8192

typedef enum urrt_link_drop_kind {
    URRT_LINK_DROP_PROTOCOL = 0, /* the peer broke the protocol: reconnect with the usual backoff */
    URRT_LINK_DROP_CONFIG        /* the peer refuses the configuration: report once, long backoff */
} urrt_link_drop_kind;

/* Copies *source; NULL goes back to the RealTime reader. URRT_OK, or
 * URRT_RTDE_E_SCRIPT_PORT (logged, the link stays the RealTime reader) when
 * the link's port runs what it receives or is such a port's read-only twin
 * (urrt_rtde_check_port: 29999, 30001-30003, 30011-30013, 30020): no source
 * writes there, and the link's one write asks again before every send. */
int urrt_link_set_source(urrt_link *link, const urrt_link_source *source);
/* Queues len bytes to write, all or none. URRT_OK; URRT_E_NO_SPACE when the
 * queue has no room for them; URRT_E_ARG without a source (the RealTime
 * reader never writes) or without a connection (the bytes belong to a
 * session: the next one starts with connected()). */
int urrt_link_send(urrt_link *link, const uint8_t *data, size_t len);
/* From received(): one data package, complete and decoded; packet and len
 * are what the packet function receives (the source's bytes or record). */
void urrt_link_source_packet(urrt_link *link, const uint8_t *packet, size_t len, uint64_t rx_us);
/* Ends the connection for the reason given (copied; one line, what failed
 * and what to do). */
void urrt_link_drop(urrt_link *link, urrt_link_drop_kind kind, const char *reason);

/* ---- CAN link ---------------------------------------------------------------- */

/*
 * A transmit-mostly CAN link: a SocketCAN raw socket on POSIX, or a file in
 * candump's log format (replayable with canplayer) for boxes without a CAN
 * interface. It receives only the 11-bit data frames it is configured for
 * (a CANopen node's NMT, SYNC and SDO requests), filtered in the kernel, so
 * that a flooded bus costs the loop nothing; a log link receives nothing.
 *
 * Sending never blocks the loop. A frame the driver cannot take (ENOBUFS
 * from a full transmit queue, EAGAIN from a full socket buffer) waits in a
 * one-deep slot per CAN ID; a newer frame for that ID replaces it and counts
 * a drop, and a held frame older than hold_max_ms is discarded and counted,
 * so an outage never replays a backlog of stale values. Held frames are
 * retried at the next send, when the socket is writable again (EAGAIN) and
 * every retry_interval_ms (ENOBUFS: the socket reports writable while the
 * queue is full, so waiting for POLLOUT alone would spin).
 *
 * An interface that goes down (or is removed) is reported once, its held
 * frames are discarded and counted as dropped, frames sent meanwhile are
 * dropped and counted, and it is reopened every reopen_interval_ms until it
 * is up again, which is reported once too. Error frames (bus-off,
 * restarted, controller problems, ...) are received and counted; data frames
 * are received only for the configured rx_ids (CAN_RAW_FILTER, kept across
 * reopens, replaced by urrt_canlink_set_rx_ids; remote requests and 29-bit
 * frames never), handed to the rx function from urrt_canlink_service, at
 * most URRT_CANLINK_RX_BURST per call. Frames the kernel dropped because the
 * socket's queue was full are counted (SO_RXQ_OVFL).
 *
 * The interface string:
 *   "can0"                      a SocketCAN interface: it must exist when the
 *                               link is created (it may be down); with fd set
 *                               its MTU must be the FD MTU (72):
 *                               `ip link set can0 mtu 72`
 *   "log:PATH"                  candump -l format into PATH (created or
 *                               truncated); "log:-" is stdout
 *   "log:PATH,ifname=NAME"      the same, with NAME as the interface column
 *                               (default "can0"), so that `canplayer -I PATH`
 *                               replays onto NAME without a mapping
 * Log lines are "(SEC.USEC) IFNAME ID#DATA" for classic frames and
 * "(SEC.USEC) IFNAME ID##FDATA" for FD frames (F: the flags nibble, 4, or 5
 * with the bit rate switch, as candump shows FD frames on current kernels),
 * ID in 3 hex digits (11-bit) or 8 (29-bit), DATA in upper-case hex,
 * wall-clock time (or, with log_caller_clock, the caller's now_us).
 * "log:-" never waits for its reader either: a stdout that is a pipe, FIFO,
 * terminal or socket is written without blocking, through an open file
 * description of the link's own (stdout's, shared with the shell, is left
 * blocking). The reader sees whole lines only: a line it has no room for
 * is dropped and counted (dropped, busy), and one it took in part is
 * finished before any other (at the next send, and every retry_interval_ms:
 * pending is 1 meanwhile). A log file, a stdout that is a regular file,
 * and stdout with log_caller_clock (a replay wants every line) are written
 * with write(2), which may wait (on the filesystem, on the reader).
 */
typedef struct urrt_canlink_config {
    const char *interface;     /* "can0", or "log:PATH[,ifname=NAME]" ("log:-" is stdout) */
    bool fd;                   /* FD frames allowed: needs an interface with the FD MTU */
    bool fd_brs;               /* FD frames use the bit rate switch (data phase bitrate) */
    uint32_t reopen_interval_ms;
    uint32_t retry_interval_ms; /* held frames retried at least this often */
    uint32_t hold_max_ms;       /* a held frame older than this is stale: dropped */
    const uint32_t *rx_ids;     /* ids to receive, filtered in the kernel (CAN_RAW_FILTER):
                                   11-bit standard ids, or a 29-bit id with
                                   URRT_CANLINK_RX_EXTENDED; NULL or rx_id_count 0: receive
                                   nothing. Copied by urrt_canlink_new. */
    size_t rx_id_count;         /* at most URRT_CANLINK_RX_IDS_MAX */
    bool log_caller_clock;      /* log: links: each line carries the now_us given to
                                   urrt_canlink_send (seconds.microseconds of that clock)
                                   instead of the wall clock (urrt-gateway --replay) */
} urrt_canlink_config;

/* An rx id with this bit is a 29-bit (extended) id: 0x18FF0010 | this. */
#define URRT_CANLINK_RX_EXTENDED 0x80000000u

/* The kernel's limit on one socket's filter list (CAN_RAW_FILTER_MAX). */
#define URRT_CANLINK_RX_IDS_MAX 512

/* Defaults: no FD, reopen every 1000 ms, retry every 5 ms, hold 100 ms,
 * nothing received, wall-clock log times. */
void urrt_canlink_config_defaults(urrt_canlink_config *cfg);

typedef enum urrt_canlink_state {
    URRT_CANLINK_DOWN = 0,         /* not open, or the interface is down; reopening */
    URRT_CANLINK_UP
} urrt_canlink_state;

typedef struct urrt_canlink_stats {
    uint64_t sent;             /* frames the driver (or the log file) took */
    uint64_t dropped;          /* values replaced before they could be sent, too old, or discarded by an outage */
    uint64_t send_errors;      /* frames lost to an unexpected error (logged) */
    uint64_t busy;             /* times the driver refused a frame (ENOBUFS, EAGAIN) */
    uint64_t opens;            /* sockets opened: 1 + reopens */
    uint64_t down_events;
    uint64_t error_frames;
    uint64_t bus_off;
    uint64_t restarts;
    uint32_t last_error_class; /* CAN_ERR_* class bits of the last error frame */
    uint32_t pending;          /* frames held for a retry right now */
    bool error_passive;        /* the controller said error passive (receive or transmit) and has not
                                  said error active again nor restarted since */
    uint64_t received;         /* data frames received (handed to the rx function, if one is set) */
    uint64_t rx_overflows;     /* frames the kernel dropped: the socket's receive queue was full (SO_RXQ_OVFL) */
} urrt_canlink_stats;

typedef struct urrt_canlink urrt_canlink;

/* NULL with a logged reason when the configuration cannot work: no such
 * interface, not a CAN interface, an FD link on an interface without the FD
 * MTU, a log file that cannot be created, an rx id that is not 11-bit or
 * more than URRT_CANLINK_RX_IDS_MAX of them. An interface that exists but is
 * down gives a link in URRT_CANLINK_DOWN that opens when the interface comes up. */
urrt_canlink *urrt_canlink_new(const urrt_canlink_config *cfg);
void urrt_canlink_free(urrt_canlink *can);

/* Sends a frame now, never waiting for the bus or a log:- reader (a log
 * file is written with write(2), which the kernel may make wait briefly on
 * the filesystem). 1: the driver (or the log) took it;
 * 0: held for a retry, or dropped and counted because the link is down (or
 * the log:- reader has no room);
 * URRT_E_ARG for a frame the link can never send (FD frame on a classic
 * link, a length FD does not have, an ID out of range). */
int urrt_canlink_send(urrt_canlink *can, const urrt_can_frame *frame, uint64_t now_us);

/* Replaces the ids the link receives (as urrt_canlink_config's rx_ids:
 * 11-bit, at most URRT_CANLINK_RX_IDS_MAX, copied; none: receive nothing):
 * an open socket's filter at once, and every reopen's after, so that a
 * CANopen node whose manager moves an id (0x1005, the SYNC) keeps hearing it.
 * Frames the socket queued under the old ids may still be handed. It may be
 * called from the rx function. 0; URRT_E_ARG for ids the link cannot take
 * (logged; the link keeps its ids). A socket that refuses the new filter
 * goes down (logged as an outage) and its reopen sets it. */
int urrt_canlink_set_rx_ids(urrt_canlink *can, const uint32_t *ids, size_t count);

/* Received frames are handed to fn from urrt_canlink_service, at most
 * URRT_CANLINK_RX_BURST per call, so that a flooded bus never starves the
 * robot link; rx_us is the kernel's receive time on the monotonic clock
 * where available, else the time read. The frame is valid during the call
 * only. NULL fn: frames that pass the filter are read and discarded. */
#define URRT_CANLINK_RX_BURST 32
typedef void (*urrt_canlink_rx_fn)(void *ctx, const urrt_can_frame *frame, uint64_t rx_us);
void urrt_canlink_set_rx(urrt_canlink *can, urrt_canlink_rx_fn fn, void *ctx);

/* The descriptor to wait on and the events (POLLIN, plus POLLOUT while
 * frames wait for socket buffer space), or -1 when there is none (down, or
 * a log file). It changes across reopens: ask again before each wait. */
int urrt_canlink_poll_fd(const urrt_canlink *can, short *events);

/* Monotonic time by which urrt_canlink_service must run again at the latest
 * (UINT64_MAX when nothing is due; the last service's now, i.e. already due,
 * while received frames may remain after a burst). */
uint64_t urrt_canlink_deadline(const urrt_canlink *can);

/* Does what is due: reads received and error frames (bounded per call),
 * notices the interface going down, retries and expires held frames,
 * reopens. Never blocks. */
void urrt_canlink_service(urrt_canlink *can, uint64_t now_us);

urrt_canlink_state urrt_canlink_get_state(const urrt_canlink *can);
const urrt_canlink_stats *urrt_canlink_get_stats(const urrt_canlink *can);

#ifdef __cplusplus
}
#endif

#endif /* URRT_PORT_H */
