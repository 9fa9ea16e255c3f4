/* SPDX-License-Identifier: MIT */
/*
 * link.c: the robot link on POSIX sockets.
 *
 * One state machine per robot, driven by urrt_link_service from the
 * program's poll loop:
 *
 *   IDLE --(backoff over)--> CONNECTING --(connected)--> WAITING --(first packet)--> UP
 *     ^                          |                         |                         |
 *     +---(failed, timed out)----+--(closed, reset, silent, dropped: a failed attempt)
 *     +-------------------------------------------(closed, reset, silent, dropped: a loss)
 *
 * A connection is only "up" once data flows: a stopped controller's kernel
 * still accepts connections, and calling that up would raise and clear
 * every "link down" alarm downstream at each reconnect.
 *
 * Name resolution uses getaddrinfo, which blocks while a DNS server answers:
 * acceptable once per attempt (controllers are usually addressed by IP
 * literal, and a literal is parsed with AI_NUMERICHOST, so it never waits
 * for DNS). Everything after that is non-blocking.
 *
 * Without a source the link never sends: no write, no send, no shutdown;
 * closing the socket is the only thing it does to the peer. It writes only
 * bytes a source queued (urrt_link_send), and those only from its queue,
 * and never to a port that runs what it receives (urrt_rtde_check_port):
 * urrt_link_set_source refuses such a link, and the one send() below asks
 * again, whatever a caller did.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "port.h"
#include "urrt_rtde.h"

/* One recv per chunk, and at most this many bytes per service call, so that
 * one busy link cannot starve the others in the same loop (about 58
 * packets of 1116 bytes, several periods' worth even at 500 Hz). */
#define LINK_READ_CHUNK 16384
#define LINK_READ_BUDGET (4 * LINK_READ_CHUNK)
/* Connect failures are logged at the first one and then when their count
 * reaches 10, 100, 1000, ...: the log grows with the logarithm of an outage. */
#define LINK_FAILURE_REPORT_BASE 10
#define LINK_REASON_MAX 384

struct urrt_link {
    urrt_link_config cfg;
    char *name;
    char *host;
    char peer[300];
    urrt_link_state state;
    int fd;
    struct addrinfo *addrs;
    struct addrinfo *next_addr;
    uint64_t deadline_us;     /* IDLE: next attempt; CONNECTING: connect timeout */
    uint64_t last_rx_us;      /* WAITING, UP: last bytes received (or the connect) */
    /* The socket's queue was seen empty at empty_us (just before the last
     * read that emptied it, or at the connect): every byte read later
     * arrived after it. packet_empty_us is empty_us as it was when the first
     * byte of the packet being collected was read. */
    uint64_t empty_us;
    uint64_t packet_empty_us;
    bool read_drained;        /* the read being delivered emptied the queue */
    bool packet_newest;       /* nothing newer had arrived when this packet was read */
    uint64_t backoff_ms;      /* wait before the next attempt after a failure */
    bool more_to_read;        /* the read budget ran out with bytes left */
    bool announced;           /* "connecting" logged */
    bool lost_logged;         /* a loss was logged: the first failed retry needs no line */
    uint64_t failed_attempts; /* since packets last flowed */
    uint64_t next_report;     /* failure count at which to log again */
    int last_errno;
    uint64_t conn_packets;    /* on the current connection */
    uint64_t conn_bytes_start; /* stats.bytes when it was established */
    urrt_framer framer;
    urrt_link_stats stats;
    urrt_bytes_fn tap;
    void *tap_ctx;
    /* The service call in progress: where packets go. */
    urrt_packet_fn fn;
    void *fn_ctx;
    /* A source that speaks first (port.h), and what it asked for. */
    urrt_link_source source;
    bool has_source;
    uint64_t source_empty_us;  /* empty_us before the read of the next package's first byte */
    bool drop_pending;
    urrt_link_drop_kind drop_kind;
    char drop_reason[LINK_REASON_MAX];
    char config_logged[LINK_REASON_MAX]; /* the configuration error last reported, "" if none */
    int write_errno;          /* a write failed: the connection ends at the next service */
    size_t out_head, out_len; /* queued bytes: out[out_head .. out_head + out_len) */
    uint8_t out[URRT_LINK_SEND_MAX];
    /* urrt_link_service_waiting: the socket blocks unless a call says
     * MSG_DONTWAIT (every other call does), and its SO_RCVTIMEO, 0 if unset. */
    bool reads_can_wait;
    uint64_t wait_timeout_us;
};

void urrt_link_config_defaults(urrt_link_config *cfg)
{
    if (cfg == NULL) {
        return;
    }
    cfg->name = NULL;
    cfg->host = NULL;
    cfg->port = URRT_LINK_PORT_RW;
    cfg->connect_timeout_ms = 2000;
    cfg->silence_timeout_ms = URRT_LINK_SILENCE_TIMEOUT_MS;
    cfg->backoff_initial_ms = 100;
    cfg->backoff_max_ms = 5000;
}

const char *urrt_link_state_name(urrt_link_state state)
{
    switch (state) {
    case URRT_LINK_IDLE: return "idle";
    case URRT_LINK_CONNECTING: return "connecting";
    case URRT_LINK_UP: return "up";
    case URRT_LINK_WAITING: return "waiting";
    default: return "unknown";
    }
}

urrt_link *urrt_link_new(const urrt_link_config *cfg)
{
    urrt_link *link;
    const char *why = NULL;

    if (cfg == NULL) {
        urrt_log(URRT_LOG_ERR, "robot link: no configuration");
        return NULL;
    }
    if (cfg->host == NULL || cfg->host[0] == '\0') {
        why = "no host given";
    } else if (strlen(cfg->host) > 255) {
        why = "host name longer than 255 characters";
    } else if (cfg->port == 0) {
        why = "port 0 (use 30003, or 30013 for the read-only port)";
    } else if (cfg->connect_timeout_ms == 0) {
        why = "connect timeout is 0";
    } else if (cfg->backoff_initial_ms == 0) {
        why = "initial backoff is 0 (would retry in a busy loop)";
    } else if (cfg->backoff_max_ms < cfg->backoff_initial_ms) {
        why = "maximum backoff is below the initial backoff";
    }
    if (why != NULL) {
        urrt_log(URRT_LOG_ERR, "robot %s: unusable link configuration: %s",
                 cfg->name != NULL ? cfg->name : "?", why);
        return NULL;
    }
    link = calloc(1, sizeof *link);
    if (link == NULL) {
        urrt_log(URRT_LOG_ERR, "robot %s: out of memory", cfg->name != NULL ? cfg->name : cfg->host);
        return NULL;
    }
    link->cfg = *cfg;
    link->name = strdup(cfg->name != NULL && cfg->name[0] != '\0' ? cfg->name : cfg->host);
    link->host = strdup(cfg->host);
    if (link->name == NULL || link->host == NULL) {
        urrt_log(URRT_LOG_ERR, "robot %s: out of memory", cfg->host);
        urrt_link_free(link);
        return NULL;
    }
    link->cfg.name = link->name;
    link->cfg.host = link->host;
    snprintf(link->peer, sizeof link->peer, strchr(link->host, ':') != NULL ? "[%s]:%u" : "%s:%u",
             link->host, (unsigned)cfg->port);
    link->fd = -1;
    link->state = URRT_LINK_IDLE;
    link->deadline_us = 0;
    link->backoff_ms = cfg->backoff_initial_ms;
    link->next_report = 1;
    urrt_framer_init(&link->framer);
    return link;
}

static void close_socket(urrt_link *link)
{
    if (link->fd >= 0) {
        close(link->fd);
        link->fd = -1;
    }
}

static void forget_addresses(urrt_link *link)
{
    if (link->addrs != NULL) {
        freeaddrinfo(link->addrs);
        link->addrs = NULL;
    }
    link->next_addr = NULL;
}

/* A TCP connection exists: waiting for data or up. */
static bool connected(const urrt_link *link)
{
    return link->state == URRT_LINK_WAITING || link->state == URRT_LINK_UP;
}

void urrt_link_free(urrt_link *link)
{
    if (link == NULL) {
        return;
    }
    close_socket(link);
    forget_addresses(link);
    free(link->name);
    free(link->host);
    free(link);
}

int urrt_link_poll_fd(const urrt_link *link, short *events)
{
    if (link == NULL || link->fd < 0 || link->state == URRT_LINK_IDLE) {
        if (events != NULL) {
            *events = 0;
        }
        return -1;
    }
    if (events != NULL) {
        *events = link->state == URRT_LINK_CONNECTING ? POLLOUT : (short)(POLLIN | (link->out_len > 0 ? POLLOUT : 0));
    }
    return link->fd;
}

uint64_t urrt_link_deadline(const urrt_link *link)
{
    if (link == NULL) {
        return UINT64_MAX;
    }
    switch (link->state) {
    case URRT_LINK_WAITING:
    case URRT_LINK_UP:
        if (link->more_to_read || link->drop_pending || link->write_errno != 0) {
            return 0;
        }
        if (link->cfg.silence_timeout_ms == 0) {
            return UINT64_MAX;
        }
        return link->last_rx_us + (uint64_t)link->cfg.silence_timeout_ms * 1000u;
    default:
        return link->deadline_us;
    }
}

urrt_link_state urrt_link_get_state(const urrt_link *link)
{
    return link != NULL ? link->state : URRT_LINK_IDLE;
}

const urrt_link_stats *urrt_link_get_stats(const urrt_link *link)
{
    return link != NULL ? &link->stats : NULL;
}

const char *urrt_link_peer(const urrt_link *link)
{
    return link != NULL ? link->peer : "";
}

void urrt_link_set_tap(urrt_link *link, urrt_bytes_fn fn, void *ctx)
{
    if (link != NULL) {
        link->tap = fn;
        link->tap_ctx = ctx;
    }
}

/* The wait before the next attempt; doubles up to the cap. */
static void schedule_retry(urrt_link *link, uint64_t now_us)
{
    link->state = URRT_LINK_IDLE;
    link->deadline_us = now_us + link->backoff_ms * 1000u;
    link->backoff_ms *= 2;
    if (link->backoff_ms > link->cfg.backoff_max_ms) {
        link->backoff_ms = link->cfg.backoff_max_ms;
    }
}

static const char *errno_text(int err)
{
    switch (err) {
    /* Both interfaces' ports: a wrong port is the usual cause, and the
     * link does not know which interface its source speaks. */
    case ECONNREFUSED:
        return "connection refused: nothing listens on that port; is the controller up, and the port "
               "right (RealTime 30003 or 30013, RTDE 30004)?";
    case ETIMEDOUT: return "timed out: no answer; check the address, the cable and the subnet";
    case ECONNRESET: return "reset by peer";
    case EHOSTUNREACH: return "host unreachable: check the address and the subnet";
    case ENETUNREACH: return "network unreachable: no route to that address; check it and this machine's network settings";
    default: return strerror(err);
    }
}

/* A connect attempt failed (every address of the host tried). */
static void attempt_failed(urrt_link *link, uint64_t now_us, const char *reason)
{
    close_socket(link);
    forget_addresses(link);
    link->stats.connect_failures++;
    link->failed_attempts++;
    if (link->failed_attempts >= link->next_report) {
        /* The first failure after a logged loss was announced by "reconnecting". */
        if (link->failed_attempts == 1 && !link->lost_logged) {
            urrt_log(URRT_LOG_WARNING, "robot %s: cannot connect to %s (%s); retrying with backoff up to %" PRIu32 " ms",
                     link->name, link->peer, reason, link->cfg.backoff_max_ms);
        } else if (link->failed_attempts > 1) {
            urrt_log(URRT_LOG_WARNING, "robot %s: still cannot connect to %s after %" PRIu64 " attempts (%s)",
                     link->name, link->peer, link->failed_attempts, reason);
        }
        link->next_report = link->failed_attempts == 1 ? LINK_FAILURE_REPORT_BASE
                                                       : link->next_report * LINK_FAILURE_REPORT_BASE;
    }
    schedule_retry(link, now_us);
}

/* TCP connected: no data yet. The source (if any) starts its session. */
static void became_connected(urrt_link *link, uint64_t now_us)
{
    forget_addresses(link);
    link->state = URRT_LINK_WAITING;
    link->last_rx_us = now_us;
    link->empty_us = now_us;
    link->source_empty_us = now_us;
    link->more_to_read = false;
    link->conn_packets = 0;
    link->conn_bytes_start = link->stats.bytes;
    link->out_head = 0;
    link->out_len = 0;
    link->write_errno = 0;
    link->drop_pending = false;
    urrt_framer_reset(&link->framer);
    /* Opened non-blocking for the connect; from here every call but
     * urrt_link_service_waiting's read passes MSG_DONTWAIT. */
    {
        int flags = fcntl(link->fd, F_GETFL), on = 1;
        link->reads_can_wait = flags >= 0 && fcntl(link->fd, F_SETFL, flags & ~O_NONBLOCK) == 0;
        (void)setsockopt(link->fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on); /* without: before_us */
    }
    link->wait_timeout_us = 0;
    urrt_log(URRT_LOG_DEBUG, "robot %s: TCP connection to %s established; waiting for data", link->name, link->peer);
    if (link->has_source && link->source.connected != NULL) {
        link->source.connected(link->source.ctx, link, now_us);
    }
}

/* The first packet of a connection: data flows, the link is up. */
static void became_up(urrt_link *link, size_t plen)
{
    char after[64] = "";
    link->state = URRT_LINK_UP;
    link->stats.connects++;
    if (link->stats.disconnects > 0) {
        link->stats.reconnects++;
    }
    if (link->failed_attempts > 0) {
        snprintf(after, sizeof after, " after %" PRIu64 " failed attempts", link->failed_attempts);
    }
    if (link->has_source) {
        urrt_log(URRT_LOG_NOTICE, "robot %s: connected to %s%s: data flows (%zu-byte packages)", link->name,
                 link->peer, after, plen);
    } else {
        const char *versions = urrt_versions_of((uint32_t)plen);
        urrt_log(URRT_LOG_NOTICE, "robot %s: connected to %s%s: %zu-byte packets (%s)", link->name, link->peer,
                 after, plen, versions != NULL ? versions : "a length no known controller sends");
    }
    link->failed_attempts = 0;
    link->next_report = 1;
    link->backoff_ms = link->cfg.backoff_initial_ms;
    link->lost_logged = false;
    link->config_logged[0] = '\0';
}

/* Ends the current connection: what it left half-read is dropped. */
static void end_connection(urrt_link *link)
{
    size_t partial = urrt_framer_finish(&link->framer);
    if (partial > 0) {
        link->stats.partial_drops++;
        link->stats.partial_bytes += partial;
    }
    link->more_to_read = false;
    link->drop_pending = false;
    link->write_errno = 0;
    link->out_len = 0;
    close_socket(link);
}

/* A connection that never delivered a packet is a failed attempt, logged
 * like a refusal (once, not once per attempt), and says what came: a wrong
 * port (the dashboard's 29999, the primary 30001), a peer that turns
 * clients away, or a stopped controller whose kernel still accepts. */
static void waiting_failed(urrt_link *link, uint64_t now_us, const char *reason)
{
    char why[LINK_REASON_MAX + 160];
    uint64_t got = link->stats.bytes - link->conn_bytes_start;
    if (got == 0 && !link->has_source) {
        snprintf(why, sizeof why, "it accepted, then %s before sending anything: an RTDE port (%u) sends "
                 "nothing until a client's handshake; if this is one, read it as RTDE (urrt-dump --rtde, "
                 "source = rtde)", reason, (unsigned)URRT_RTDE_PORT);
    } else if (got == 0) {
        snprintf(why, sizeof why, "it accepted, then %s before sending anything", reason);
    } else if (link->has_source) {
        snprintf(why, sizeof why, "it accepted and sent %" PRIu64 " bytes but no data, then %s", got, reason);
    } else {
        snprintf(why, sizeof why,
                 "it accepted and sent %" PRIu64 " bytes but no RealTime packet, then %s: "
                 "is %u the RealTime port (30003, or 30013)?",
                 got, reason, (unsigned)link->cfg.port);
    }
    attempt_failed(link, now_us, why);
}

/* A connection ended (closed, reset, silent, or dropped by the source). */
static void connection_lost(urrt_link *link, uint64_t now_us, const char *reason, bool silent)
{
    bool was_up = link->state == URRT_LINK_UP;
    end_connection(link);
    if (!was_up) {
        waiting_failed(link, now_us, reason);
        return;
    }
    link->stats.disconnects++;
    if (silent) {
        link->stats.silences++;
    }
    urrt_log(URRT_LOG_WARNING, "robot %s: connection to %s lost (%s); reconnecting", link->name, link->peer, reason);
    link->lost_logged = true;
    /* It worked until now: start again from the short wait. */
    link->backoff_ms = link->cfg.backoff_initial_ms;
    link->failed_attempts = 0;
    link->next_report = LINK_FAILURE_REPORT_BASE;
    schedule_retry(link, now_us);
}

/* The peer refuses what the configuration asks: retrying soon cannot help,
 * and the log says it once, not once per attempt. */
static void configuration_refused(urrt_link *link, uint64_t now_us, const char *reason)
{
    if (link->state == URRT_LINK_UP) {
        link->stats.disconnects++;
    } else {
        link->stats.connect_failures++;
    }
    end_connection(link);
    if (strcmp(link->config_logged, reason) != 0) {
        urrt_log(URRT_LOG_ERR, "robot %s: %s refuses the configuration: %s; fix the configuration (retrying every %" PRIu32
                 " ms meanwhile)", link->name, link->peer, reason, link->cfg.backoff_max_ms);
        snprintf(link->config_logged, sizeof link->config_logged, "%s", reason);
    }
    link->backoff_ms = link->cfg.backoff_max_ms;
    schedule_retry(link, now_us);
}

/* Acts on the source's urrt_link_drop, once its function has returned. */
static void handle_drop(urrt_link *link, uint64_t now_us)
{
    char reason[LINK_REASON_MAX];
    snprintf(reason, sizeof reason, "%s", link->drop_reason);
    if (link->drop_kind == URRT_LINK_DROP_CONFIG) {
        configuration_refused(link, now_us, reason);
    } else {
        connection_lost(link, now_us, reason, false);
    }
}

static void set_keepalive(int fd)
{
    int on = 1;
    /* Failure only loses the kernel's own dead-peer detection; the silence
     * timeout still covers a half-open link. */
    (void)setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on);
#ifdef TCP_KEEPIDLE
    {
        int idle = 1, interval = 1, count = 3;
        (void)setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
        (void)setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval);
        (void)setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &count, sizeof count);
    }
#endif
}

/* Starts a non-blocking connect to the next address; returns when one is in
 * progress or established, or every address failed. */
static void try_next_address(urrt_link *link, uint64_t now_us)
{
    while (link->next_addr != NULL) {
        struct addrinfo *ai = link->next_addr;
        link->next_addr = ai->ai_next;
        link->fd = socket(ai->ai_family, ai->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, ai->ai_protocol);
        if (link->fd < 0) {
            link->last_errno = errno;
            continue;
        }
        link->stats.sockets++;
        set_keepalive(link->fd);
        if (connect(link->fd, ai->ai_addr, ai->ai_addrlen) == 0) {
            became_connected(link, now_us);
            return;
        }
        if (errno == EINPROGRESS) {
            link->state = URRT_LINK_CONNECTING;
            link->deadline_us = now_us + (uint64_t)link->cfg.connect_timeout_ms * 1000u;
            return;
        }
        link->last_errno = errno;
        close_socket(link);
    }
    attempt_failed(link, now_us, errno_text(link->last_errno));
}

static void start_attempt(urrt_link *link, uint64_t now_us)
{
    struct addrinfo hints;
    char service[8];
    int rc;

    if (!link->announced) {
        urrt_log(URRT_LOG_INFO, "robot %s: connecting to %s", link->name, link->peer);
        link->announced = true;
    }
    forget_addresses(link);
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_NUMERICHOST | AI_NUMERICSERV;
    snprintf(service, sizeof service, "%u", (unsigned)link->cfg.port);
    rc = getaddrinfo(link->host, service, &hints, &link->addrs);
    if (rc == EAI_NONAME) {
        /* Not a literal: a name, and this may wait for DNS. */
        hints.ai_flags = AI_NUMERICSERV;
        rc = getaddrinfo(link->host, service, &hints, &link->addrs);
    }
    if (rc != 0) {
        char reason[400];
        link->addrs = NULL;
        snprintf(reason, sizeof reason, "cannot resolve \"%s\": %s; check the name, or give the IP address", link->host,
                 rc == EAI_SYSTEM ? strerror(errno) : gai_strerror(rc));
        attempt_failed(link, now_us, reason);
        return;
    }
    link->next_addr = link->addrs;
    link->last_errno = EHOSTUNREACH;
    try_next_address(link, now_us);
}

static void check_connect(urrt_link *link, uint64_t now_us)
{
    struct pollfd pfd = {.fd = link->fd, .events = POLLOUT};
    int rc = poll(&pfd, 1, 0);
    if (rc > 0) {
        int err = 0;
        socklen_t len = sizeof err;
        if (getsockopt(link->fd, SOL_SOCKET, SO_ERROR, &err, &len) != 0) {
            err = errno;
        }
        if (err == 0) {
            became_connected(link, now_us);
            return;
        }
        link->last_errno = err;
    } else if (now_us >= link->deadline_us) {
        link->last_errno = ETIMEDOUT;
    } else {
        return;
    }
    close_socket(link);
    try_next_address(link, now_us);
}

/* A packet (framed here, or a source's package): counted, the link up at
 * the first of the connection, then handed to the service's function. */
static void packet_arrived(urrt_link *link, const uint8_t *packet, size_t plen, uint64_t now_us)
{
    link->stats.packets++;
    link->stats.last_packet_us = now_us;
    link->stats.last_length = (uint32_t)plen;
    if (link->conn_packets++ == 0) {
        became_up(link, plen);
    }
    if (link->fn != NULL) {
        link->fn(link->fn_ctx, packet, plen, now_us);
    }
}

static void deliver(urrt_link *link, const uint8_t *data, size_t len, uint64_t now_us)
{
    while (len > 0) {
        size_t used = 0;
        int got;
        if (link->framer.have == 0 && link->framer.need == 0) {
            link->packet_empty_us = link->empty_us; /* the next packet starts in this read */
        }
        got = urrt_framer_feed(&link->framer, data, len, &used);
        /* Counters are current at each callback: a program that stops at a
         * packet reports exactly the stream up to it. */
        link->stats.bytes = link->framer.stats.bytes;
        link->stats.resyncs = link->framer.stats.resyncs;
        link->stats.skipped = link->framer.stats.skipped;
        if (link->tap != NULL && used > 0) {
            link->tap(link->tap_ctx, data, used);
        }
        if (got == 1) {
            size_t plen = 0;
            const uint8_t *packet = urrt_framer_packet(&link->framer, &plen);
            link->packet_newest = link->read_drained && len - used < plen;
            packet_arrived(link, packet, plen, now_us);
        }
        data += used;
        len -= used;
    }
}

/* A source takes every byte as read; empty_us is still the time before
 * this read, when the queue was last seen empty. */
static void deliver_to_source(urrt_link *link, const uint8_t *data, size_t len, uint64_t now_us)
{
    link->stats.bytes += len;
    if (link->tap != NULL) {
        link->tap(link->tap_ctx, data, len);
    }
    link->packet_newest = link->read_drained;
    if (link->source.received != NULL) {
        link->source.received(link->source.ctx, link, data, len, now_us);
    }
    /* Whatever follows in the stream arrived after the empty queue seen
     * before this read (or a later one). */
    link->source_empty_us = link->empty_us;
}

void urrt_link_source_packet(urrt_link *link, const uint8_t *packet, size_t len, uint64_t rx_us)
{
    if (link == NULL || !link->has_source || !connected(link) || link->drop_pending) {
        return;
    }
    link->packet_empty_us = link->source_empty_us;
    link->source_empty_us = link->empty_us;
    packet_arrived(link, packet, len, rx_us);
}

/* The read urrt_link_service_waiting waits in. *arrived_us: the kernel's
 * receive time of the last bytes it returns (SO_TIMESTAMPNS, on the
 * realtime clock, in microseconds), 0 if it gave none. */
static ssize_t read_waiting(urrt_link *link, uint8_t *buf, size_t size, uint64_t *arrived_us)
{
    union {
        struct cmsghdr align;
        uint8_t bytes[CMSG_SPACE(sizeof(struct timespec))];
    } control;
    struct iovec iov = {.iov_base = buf, .iov_len = size};
    struct msghdr msg = {.msg_iov = &iov, .msg_iovlen = 1, .msg_control = &control, .msg_controllen = sizeof control};
    ssize_t n = recvmsg(link->fd, &msg, 0);
    *arrived_us = 0;
    for (struct cmsghdr *c = n > 0 ? CMSG_FIRSTHDR(&msg) : NULL; c != NULL; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
            struct timespec ts;
            memcpy(&ts, CMSG_DATA(c), sizeof ts);
            *arrived_us = ts.tv_sec > 0 ? (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u : 0;
        }
    }
    return n;
}

/* The later of before_us and the kernel's receive stamp (realtime) moved
 * onto the monotonic clock by the clocks' offset just after read_us (the
 * realtime clock is read a little later, so the stamp comes out a little
 * early: the safe side for a time the queue was empty). A stamp after
 * read_us, or none, leaves before_us: the realtime clock was set since. */
static uint64_t arrival_or(uint64_t arrived_real_us, uint64_t before_us, uint64_t read_us)
{
    uint64_t real_us = urrt_port_realtime_us();
    uint64_t ago_us = real_us - arrived_real_us;
    if (arrived_real_us == 0 || arrived_real_us > real_us || ago_us > read_us - before_us) {
        return before_us;
    }
    return read_us - ago_us;
}

/* Each read is stamped with the clock taken just after it returns, so a
 * packet's rx_us is when its last bytes left the socket, whatever the loop
 * did since it woke up. A read shorter than asked emptied the queue: the
 * clock taken just before it is then a time the queue was empty (every
 * byte after what it took came later). A first read that waited (`wait`)
 * took what was there when it returned, after the last of its bytes
 * arrived: that arrival, as the kernel stamped it, is the later such time;
 * its timeout (EAGAIN) means nothing came since the clock was read. */
static void read_available(urrt_link *link, bool wait)
{
    uint8_t buf[LINK_READ_CHUNK];
    size_t budget = LINK_READ_BUDGET;

    link->more_to_read = false;
    while (connected(link) && !link->drop_pending) {
        uint64_t before_us = urrt_port_monotonic_us();
        uint64_t arrived_real_us = 0;
        ssize_t n = wait ? read_waiting(link, buf, sizeof buf, &arrived_real_us)
                         : recv(link->fd, buf, sizeof buf, MSG_DONTWAIT);
        uint64_t read_us = urrt_port_monotonic_us();
        bool waited = wait;
        wait = false;
        if (waited && n > 0) {
            before_us = arrival_or(arrived_real_us, before_us, read_us);
        }
        if (n > 0) {
            link->last_rx_us = read_us;
            link->read_drained = (size_t)n < sizeof buf;
            if (link->has_source) {
                deliver_to_source(link, buf, (size_t)n, read_us);
            } else {
                deliver(link, buf, (size_t)n, read_us);
            }
            if ((size_t)n < sizeof buf) {
                link->empty_us = before_us;
                return; /* drained: poll says when there is more */
            }
            if ((size_t)n >= budget) {
                link->more_to_read = true;
                return;
            }
            budget -= (size_t)n;
        } else if (n == 0) {
            connection_lost(link, read_us, "closed by peer", false);
        } else if (errno == EINTR) {
            /* Once more without waiting: what a signal (a stop and
             * SIGCONT too) left in the queue is read before the silence
             * is judged, and a stop request reaches the loop at once. */
            continue;
        } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
            link->empty_us = before_us;
            return;
        } else {
            connection_lost(link, read_us, errno_text(errno), false);
        }
    }
}

/* Writes what the source queued, as much as the socket takes now. A failed
 * write is kept for the service to act on: this may run inside a source's
 * function, where the connection must not end under it. */
static void flush_queue(urrt_link *link)
{
    if (link->out_len == 0) {
        return; /* a RealTime reader's every service: nothing to write, nothing to check */
    }
    if (urrt_rtde_check_port(link->cfg.port) != URRT_OK) {
        link->out_head = link->out_len = 0; /* never reached through set_source: the last guard */
        return;
    }
    while (link->out_len > 0 && link->write_errno == 0 && link->fd >= 0) {
        ssize_t n = send(link->fd, link->out + link->out_head, link->out_len, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (n > 0) {
            link->out_head += (size_t)n;
            link->out_len -= (size_t)n;
        } else if (n < 0 && errno == EINTR) {
            continue;
        } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            break; /* POLLOUT says when there is room */
        } else {
            link->write_errno = n < 0 ? errno : EPIPE;
        }
    }
    if (link->out_len == 0) {
        link->out_head = 0;
    }
}

int urrt_link_set_source(urrt_link *link, const urrt_link_source *source)
{
    const char *role;
    if (link == NULL) {
        return URRT_E_ARG;
    }
    role = source != NULL ? urrt_rtde_port_role(link->cfg.port) : NULL;
    if (role != NULL) {
        urrt_log(URRT_LOG_ERR, "robot %s: will not write to %s: port %u is %s; RTDE is port %u",
                 link->name, link->peer, (unsigned)link->cfg.port, role, (unsigned)URRT_RTDE_PORT);
        link->has_source = false;
        return URRT_RTDE_E_SCRIPT_PORT;
    }
    link->has_source = source != NULL;
    if (source != NULL) {
        link->source = *source;
    }
    return URRT_OK;
}

int urrt_link_send(urrt_link *link, const uint8_t *data, size_t len)
{
    if (link == NULL || (data == NULL && len > 0) || !link->has_source || !connected(link)) {
        return URRT_E_ARG; /* the RealTime reader never writes */
    }
    if (len > URRT_LINK_SEND_MAX - link->out_len) {
        return URRT_E_NO_SPACE;
    }
    if (link->out_head + link->out_len + len > URRT_LINK_SEND_MAX) {
        memmove(link->out, link->out + link->out_head, link->out_len);
        link->out_head = 0;
    }
    if (len > 0) {
        memcpy(link->out + link->out_head + link->out_len, data, len);
        link->out_len += len;
    }
    flush_queue(link);
    return URRT_OK;
}

void urrt_link_drop(urrt_link *link, urrt_link_drop_kind kind, const char *reason)
{
    if (link == NULL || !connected(link) || link->drop_pending) {
        return;
    }
    link->drop_pending = true;
    link->drop_kind = kind;
    snprintf(link->drop_reason, sizeof link->drop_reason, "%s",
             reason != NULL && reason[0] != '\0' ? reason : "the source ended the session");
}

uint64_t urrt_link_packet_empty_us(const urrt_link *link)
{
    return link->packet_empty_us;
}

bool urrt_link_packet_newest(const urrt_link *link)
{
    return link->packet_newest;
}

/* What a connection does in one service call: the queue written, bytes
 * read, the source's requests acted on, silence judged. The silence is
 * judged at now_us, taken before the reads, also after a read that waited:
 * a clock read after a read that found nothing may come after a stop (a
 * SIGSTOP, a starved CPU) that left the queue full, and would call a link
 * silent that only this process was not reading. A silence that a wait's
 * timeout ends is judged at the next call, its deadline passed. */
static void service_connection(urrt_link *link, uint64_t now_us, bool wait)
{
    if (!link->drop_pending) {
        flush_queue(link);
        read_available(link, wait);
    }
    if (connected(link) && link->drop_pending) {
        handle_drop(link, now_us);
        return;
    }
    if (!connected(link)) {
        return;
    }
    flush_queue(link); /* replies the source queued while reading */
    if (link->write_errno != 0) {
        connection_lost(link, now_us, errno_text(link->write_errno), false);
        return;
    }
    if (!link->more_to_read && link->cfg.silence_timeout_ms != 0 && now_us > link->last_rx_us &&
        now_us - link->last_rx_us >= (uint64_t)link->cfg.silence_timeout_ms * 1000u) {
        char reason[64];
        snprintf(reason, sizeof reason, "no data for %" PRIu32 " ms", link->cfg.silence_timeout_ms);
        connection_lost(link, now_us, reason, true);
    }
}

void urrt_link_service(urrt_link *link, uint64_t now_us, urrt_packet_fn fn, void *ctx)
{
    if (link == NULL) {
        return;
    }
    switch (link->state) {
    case URRT_LINK_IDLE:
        if (now_us >= link->deadline_us) {
            start_attempt(link, now_us);
        }
        break;
    case URRT_LINK_CONNECTING:
        check_connect(link, now_us);
        break;
    case URRT_LINK_WAITING:
    case URRT_LINK_UP:
        break;
    }
    if (!connected(link)) {
        return;
    }
    link->fn = fn;
    link->fn_ctx = ctx;
    service_connection(link, now_us, false);
    link->fn = NULL;
    link->fn_ctx = NULL;
}

/* The kernel's tick, the unit SO_RCVTIMEO counts in (CLOCK_MONOTONIC_COARSE
 * advances by one): 10 ms, the coarsest a Linux kernel has, if unknown. */
static uint64_t kernel_tick_us(void)
{
    struct timespec res;
    if (clock_getres(CLOCK_MONOTONIC_COARSE, &res) != 0 || res.tv_sec != 0 || res.tv_nsec <= 0) {
        return 10000u;
    }
    return ((uint64_t)res.tv_nsec + 999u) / 1000u;
}

/* SO_RCVTIMEO for a wait that must end within room_us: half of what is
 * left of it after a tick. The kernel rounds a timeout up to whole ticks
 * and, past 64 ticks, lets its timer wheel fire up to an eighth late: a
 * timeout t ends by t + t/8 + one tick. Setting it is a system call, so the
 * one set is kept while it ends in time and is not under half of that:
 * a deadline that moves on with every packet (the silence timeout, the
 * data's freshness) never needs another, a fixed one (the outputs' ticks)
 * is approached in a few steps of about half the room each, until the room
 * is too short to wait in the read. */
static bool wait_timeout_fits(urrt_link *link, uint64_t room_us)
{
    static uint64_t tick_us;
    struct timeval tv;
    uint64_t timeout_us = link->wait_timeout_us, half_us;
    if (tick_us == 0) {
        tick_us = kernel_tick_us();
    }
    if (room_us < tick_us + 2u * URRT_LINK_WAIT_MIN_US) {
        return false;
    }
    half_us = (room_us - tick_us) / 2u;
    if (timeout_us >= half_us / 2u && timeout_us + timeout_us / 8u + tick_us <= room_us) {
        return true;
    }
    timeout_us = half_us;
    tv.tv_sec = (time_t)(timeout_us / 1000000u);
    tv.tv_usec = (suseconds_t)(timeout_us % 1000000u);
    if (setsockopt(link->fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv) != 0) {
        return false;
    }
    link->wait_timeout_us = timeout_us;
    return true;
}

bool urrt_link_service_waiting(urrt_link *link, uint64_t until_us, urrt_packet_fn fn, void *ctx)
{
    uint64_t now_us = urrt_port_monotonic_us();
    if (link == NULL || !connected(link) || !link->reads_can_wait || link->drop_pending || link->more_to_read ||
        link->out_len > 0 || link->write_errno != 0 || until_us <= now_us ||
        !wait_timeout_fits(link, until_us - now_us)) {
        return false;
    }
    link->stats.read_waits++;
    link->fn = fn;
    link->fn_ctx = ctx;
    service_connection(link, now_us, true);
    link->fn = NULL;
    link->fn_ctx = NULL;
    return true;
}
