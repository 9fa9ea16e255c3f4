/* SPDX-License-Identifier: MIT */
/*
 * The POSIX robot link against servers in this process, and the shared
 * command-line helpers. Real sockets on loopback, real time; every wait is
 * bounded. Every port comes from the system (bind to port 0), so that two
 * runs on one machine do not meet.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "cli.h"
#include "port.h"
#include "urrt_rtde.h"


/* ---- log capture ---------------------------------------------------------- */

#define MAX_LINES 256
static char log_lines[MAX_LINES][300];
static int log_count;

static void sink(void *ctx, urrt_log_level level, const char *message)
{
    (void)ctx;
    if (log_count < MAX_LINES) {
        snprintf(log_lines[log_count++], sizeof log_lines[0], "%s: %s", urrt_log_level_name(level), message);
    }
}

static int lines_with(const char *needle)
{
    int n = 0;
    for (int i = 0; i < log_count; i++) {
        n += strstr(log_lines[i], needle) != NULL;
    }
    return n;
}

static void dump_log(void)
{
    for (int i = 0; i < log_count; i++) {
        fprintf(stderr, "  log: %s\n", log_lines[i]);
    }
}

/* ---- driving a link ----------------------------------------------------------- */

typedef struct rx {
    uint64_t packets;
    uint64_t bytes_in_packets;
    uint64_t tapped;
    uint8_t first_byte_of_last;
} rx;

static void on_packet(void *ctx, const uint8_t *pkt, size_t len, uint64_t rx_us)
{
    rx *r = ctx;
    (void)rx_us;
    r->packets++;
    r->bytes_in_packets += len;
    r->first_byte_of_last = pkt[4];
}

static void on_tap(void *ctx, const uint8_t *data, size_t len)
{
    rx *r = ctx;
    (void)data;
    r->tapped += len;
}

typedef bool (*until_fn)(const urrt_link *link, const rx *r);

/* A server descriptor pump() waits on too (-1: none), so that a done()
 * that reads it runs as soon as bytes arrive. */
static int pump_also_fd = -1;
/* Set when urrt_link_poll_fd asked for POLLOUT: bytes waited for room. */
static bool pump_saw_pollout;

/* Polls and services the link until done() or ms pass. Returns done(). When
 * delays is given, each connect failure or loss records the backoff chosen
 * (deadline - now of that call) in milliseconds. */
static bool pump(urrt_link *link, rx *r, int ms, until_fn done, uint64_t *delays, int *ndelays, int max_delays)
{
    uint64_t end = urrt_port_monotonic_us() + (uint64_t)ms * 1000u;
    for (;;) {
        uint64_t now = urrt_port_monotonic_us();
        short ev = 0;
        int fd;
        uint64_t deadline;
        int timeout;
        const urrt_link_stats *st = urrt_link_get_stats(link);
        uint64_t events_before;

        if (done != NULL && done(link, r)) {
            return true;
        }
        if (now >= end) {
            return done == NULL;
        }
        fd = urrt_link_poll_fd(link, &ev);
        deadline = urrt_link_deadline(link);
        timeout = deadline <= now ? 0 : (int)((deadline - now + 999) / 1000);
        if (timeout > (int)((end - now) / 1000) + 1) {
            timeout = (int)((end - now) / 1000) + 1;
        }
        struct pollfd p[2] = {{.fd = fd, .events = ev}, {.fd = pump_also_fd, .events = POLLIN}};
        pump_saw_pollout |= (ev & POLLOUT) != 0 && urrt_link_get_state(link) != URRT_LINK_CONNECTING;
        poll(p, 2, timeout); /* a negative fd is ignored */
        now = urrt_port_monotonic_us();
        events_before = st->connect_failures + st->disconnects;
        urrt_link_service(link, now, on_packet, r);
        if (delays != NULL && st->connect_failures + st->disconnects != events_before && *ndelays < max_delays) {
            delays[(*ndelays)++] = (urrt_link_deadline(link) - now) / 1000u;
        }
    }
}

static bool is_up(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_state(l) == URRT_LINK_UP;
}

static bool is_waiting(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_state(l) == URRT_LINK_WAITING;
}

static bool one_disconnect(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_stats(l)->disconnects >= 1;
}

static bool two_disconnects(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_stats(l)->disconnects >= 2;
}

static bool twelve_failures(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_stats(l)->connect_failures >= 12;
}

static bool one_failure(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_stats(l)->connect_failures >= 1;
}

/* One more failure than when the pump began (pump_failures_base). */
static uint64_t pump_failures_base;
static bool one_failure_more(const urrt_link *l, const rx *r)
{
    (void)r;
    return urrt_link_get_stats(l)->connect_failures > pump_failures_base;
}

static uint64_t want_packets;
static bool enough_packets(const urrt_link *l, const rx *r)
{
    (void)l;
    return r->packets >= want_packets;
}

/* ---- a server ------------------------------------------------------------------ */

/* A loopback socket on a port the system picks (*port receives it), listening
 * with backlog, or only bound when backlog < 0. */
static int bind_any(int family, uint16_t *port, int backlog)
{
    int fd = socket(family, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_storage ss;
    socklen_t len;
    memset(&ss, 0, sizeof ss);
    if (family == AF_INET6) {
        struct sockaddr_in6 *a = (struct sockaddr_in6 *)&ss;
        a->sin6_family = AF_INET6;
        a->sin6_addr = in6addr_loopback;
        len = sizeof *a;
    } else {
        struct sockaddr_in *a = (struct sockaddr_in *)&ss;
        a->sin_family = AF_INET;
        a->sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        len = sizeof *a;
    }
    if (fd < 0 || bind(fd, (struct sockaddr *)&ss, len) != 0 || (backlog >= 0 && listen(fd, backlog) != 0) ||
        getsockname(fd, (struct sockaddr *)&ss, &len) != 0) {
        if (fd >= 0) {
            close(fd);
        }
        return -1;
    }
    *port = ntohs(family == AF_INET6 ? ((struct sockaddr_in6 *)&ss)->sin6_port : ((struct sockaddr_in *)&ss)->sin_port);
    return fd;
}

static int accept_within(int lfd, int ms)
{
    struct pollfd p = {.fd = lfd, .events = POLLIN};
    if (poll(&p, 1, ms) != 1) {
        return -1;
    }
    return accept4(lfd, NULL, NULL, SOCK_CLOEXEC);
}

/* Pumps the link until it has connected to lfd, then accepts every queued
 * connection and returns the newest (the link's, as long as it is still
 * waiting), or -1. */
static int accept_link(urrt_link *l, rx *r, int lfd)
{
    int s = -1, next;
    if (!pump(l, r, 2000, is_waiting, NULL, NULL, 0)) {
        return -1;
    }
    while ((next = accept_within(lfd, s < 0 ? 2000 : 0)) >= 0) {
        if (s >= 0) {
            close(s);
        }
        s = next;
    }
    return s;
}

/* What the link sent: must stay 0. -1 on error. */
static long bytes_from_client(int fd)
{
    uint8_t buf[256];
    long total = 0;
    for (;;) {
        ssize_t n = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
        if (n > 0) {
            total += n;
            continue;
        }
        if (n == 0 || errno == EAGAIN || errno == EWOULDBLOCK || errno == ECONNRESET) {
            return total;
        }
        return -1;
    }
}

static void make_packet(uint8_t *p, uint32_t len, uint8_t tag)
{
    memset(p, 0, len);
    p[0] = (uint8_t)(len >> 24);
    p[1] = (uint8_t)(len >> 16);
    p[2] = (uint8_t)(len >> 8);
    p[3] = (uint8_t)len;
    p[4] = tag;
}

static void send_all(int fd, const uint8_t *p, size_t n)
{
    while (n > 0) {
        ssize_t w = send(fd, p, n, MSG_NOSIGNAL);
        if (w <= 0) {
            return;
        }
        p += w;
        n -= (size_t)w;
    }
}

static void sleep_ms(int ms)
{
    struct timespec ts = {.tv_sec = ms / 1000, .tv_nsec = (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* ---- tests -------------------------------------------------------------------- */

static void test_config(void)
{
    urrt_link_config c;
    urrt_link_config_defaults(&c);
    CHECK_EQ_INT(c.port, 30003);
    CHECK_EQ_INT(c.connect_timeout_ms, 2000);
    CHECK_EQ_INT(c.silence_timeout_ms, 100);
    CHECK_EQ_INT(c.backoff_initial_ms, 100);
    CHECK_EQ_INT(c.backoff_max_ms, 5000);
    log_count = 0;
    CHECK(urrt_link_new(&c) == NULL, "a link without host");
    c.host = "127.0.0.1";
    c.port = 0;
    CHECK(urrt_link_new(&c) == NULL, "port 0");
    c.port = 30003;
    c.backoff_max_ms = 50;
    CHECK(urrt_link_new(&c) == NULL, "max backoff below initial");
    CHECK_EQ_INT(lines_with("error: robot"), 3);
    CHECK(lines_with("port 0") == 1, "the reason is logged");
    CHECK_EQ_STR(urrt_link_state_name(URRT_LINK_UP), "up");
}

static void test_refused_backoff(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint64_t delays[16];
    int nd = 0;
    static const uint64_t want[] = {10, 20, 40, 80, 80, 80, 80, 80, 80, 80, 80};
    char peer[64];
    /* Bound, not listening: a connect is refused, and nobody else can take
     * the port while we hold it (we set no SO_REUSEADDR). */
    uint16_t port = 0;
    int held = bind_any(AF_INET, &port, -1);

    CHECK(held >= 0, "a port that refuses");
    urrt_link_config_defaults(&c);
    c.name = "arm1";
    c.host = "127.0.0.1";
    c.port = port;
    c.backoff_initial_ms = 10;
    c.backoff_max_ms = 80;
    l = urrt_link_new(&c);
    CHECK(l != NULL, "link");
    snprintf(peer, sizeof peer, "127.0.0.1:%u", port);
    CHECK_EQ_STR(urrt_link_peer(l), peer);
    CHECK_EQ_INT(urrt_link_deadline(l), 0); /* the first attempt is due at once */
    log_count = 0;
    CHECK(pump(l, &r, 3000, twelve_failures, delays, &nd, 16), "12 refusals within 3 s");
    CHECK(nd >= 11, "%d delays", nd);
    for (int i = 0; i < 11 && i < nd; i++) {
        /* The recorded delay is the full backoff, give or take the ms rounding. */
        CHECK(delays[i] == want[i] || delays[i] + 1 == want[i], "backoff %d: %llu ms, want %llu", i,
              (unsigned long long)delays[i], (unsigned long long)want[i]);
    }
    CHECK_EQ_INT(urrt_link_get_stats(l)->connects, 0);
    /* One address: a socket per attempt, each a new one for a loop that
     * registers descriptors once (port.h). */
    CHECK_EQ_INT(urrt_link_get_stats(l)->sockets, urrt_link_get_stats(l)->connect_failures);
    CHECK_EQ_INT(lines_with("warning: robot arm1: cannot connect to"), 1);
    CHECK_EQ_INT(lines_with("still cannot connect"), 1);
    CHECK_EQ_INT(lines_with("after 10 attempts"), 1);
    CHECK_EQ_INT(lines_with("connection refused"), 2);
    CHECK_EQ_INT(lines_with("is the controller up, and the port right (RealTime 30003 or 30013, RTDE 30004)?"), 2);
    CHECK_EQ_INT(lines_with("connecting to"), 1);
    if (lines_with("cannot connect") != 2) {
        dump_log();
    }
    urrt_link_free(l);
    close(held);
}

static void test_session(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint8_t pkt[1116];
    uint64_t delays[8];
    int nd = 0;
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 4), s;
    long sent_by_link = 0;

    CHECK(lfd >= 0, "listen");
    urrt_link_config_defaults(&c);
    c.name = "arm1";
    c.host = "127.0.0.1";
    c.port = port;
    c.backoff_initial_ms = 20;
    c.backoff_max_ms = 1000;
    c.silence_timeout_ms = 100;
    l = urrt_link_new(&c);
    urrt_link_set_tap(l, on_tap, &r);
    log_count = 0;

    /* 1: three packets in awkward pieces, half a fourth, then close. Up
     * only once the first packet is in. */
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "accept");
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_WAITING);
    CHECK_EQ_INT(urrt_link_get_stats(l)->connects, 0);
    CHECK_EQ_STR(urrt_link_state_name(URRT_LINK_WAITING), "waiting");
    CHECK_EQ_INT(urrt_link_send(l, (const uint8_t *)"x", 1), URRT_E_ARG); /* the RealTime reader never writes */
    for (int i = 0; i < 3; i++) {
        make_packet(pkt, sizeof pkt, (uint8_t)(i + 1));
        send_all(s, pkt, 3);
        pump(l, &r, 10, NULL, NULL, NULL, 0);
        send_all(s, pkt + 3, 700);
        pump(l, &r, 10, NULL, NULL, NULL, 0);
        send_all(s, pkt + 703, sizeof pkt - 703);
    }
    make_packet(pkt, sizeof pkt, 4);
    send_all(s, pkt, 558);
    want_packets = 3;
    CHECK(pump(l, &r, 2000, enough_packets, NULL, NULL, 0), "three packets");
    sent_by_link += bytes_from_client(s);
    close(s);
    CHECK(pump(l, &r, 2000, one_disconnect, delays, &nd, 8), "sees the close");
    CHECK_EQ_INT(r.packets, 3);
    CHECK_EQ_INT(r.first_byte_of_last, 3);
    CHECK_EQ_INT(r.tapped, 3 * 1116 + 558);
    {
        const urrt_link_stats *st = urrt_link_get_stats(l);
        CHECK_EQ_INT(st->packets, 3);
        CHECK_EQ_INT(st->bytes, 3 * 1116 + 558);
        CHECK_EQ_INT(st->partial_drops, 1);
        CHECK_EQ_INT(st->partial_bytes, 558);
        CHECK_EQ_INT(st->connects, 1);
        CHECK_EQ_INT(st->disconnects, 1);
        CHECK_EQ_INT(st->sockets, 1);
        CHECK_EQ_INT(st->last_length, 1116);
        CHECK(st->last_packet_us != 0, "time of the last packet");
    }
    /* It delivered packets: the next attempt waits the initial backoff. */
    CHECK(nd == 1 && delays[0] >= 19 && delays[0] <= 20, "backoff after a good connection: %llu ms",
          (unsigned long long)(nd ? delays[0] : 0));
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_IDLE);
    CHECK_EQ_INT(urrt_link_poll_fd(l, NULL), -1);
    CHECK_EQ_INT(lines_with("connected to 127.0.0.1"), 1);
    CHECK_EQ_INT(lines_with("lost (closed by peer); reconnecting"), 1);

    /* 2: reconnect; a packet, garbage, a packet, then silence. */
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "accept again");
    CHECK_EQ_INT(urrt_link_get_stats(l)->reconnects, 0);
    make_packet(pkt, sizeof pkt, 5);
    send_all(s, pkt, sizeof pkt);
    send_all(s, (const uint8_t *)"\x01\x02\x03\x04\x05", 5);
    make_packet(pkt, sizeof pkt, 6);
    send_all(s, pkt, sizeof pkt);
    CHECK(pump(l, &r, 2000, two_disconnects, NULL, NULL, 0), "silence detected");
    sent_by_link += bytes_from_client(s);
    close(s);
    {
        const urrt_link_stats *st = urrt_link_get_stats(l);
        CHECK_EQ_INT(st->packets, 5);
        CHECK_EQ_INT(st->resyncs, 1);
        CHECK_EQ_INT(st->skipped, 5);
        CHECK_EQ_INT(st->silences, 1);
        CHECK_EQ_INT(st->reconnects, 1);
        CHECK_EQ_INT(st->sockets, 2); /* a reconnect is a new socket, whatever its number */
        CHECK_EQ_INT(st->partial_drops, 1);
    }
    CHECK_EQ_INT(lines_with("lost (no data for 100 ms); reconnecting"), 1);
    CHECK_EQ_INT(lines_with("connected to 127.0.0.1"), 2);

    /* 3: more than one service call's budget arrives at once. */
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "third connection");
    {
        static uint8_t burst[80 * 1116];
        uint64_t before = r.packets;
        for (int i = 0; i < 80; i++) {
            make_packet(burst + i * 1116, 1116, (uint8_t)i);
        }
        send_all(s, burst, sizeof burst);
        sleep_ms(50);
        urrt_link_service(l, urrt_port_monotonic_us(), on_packet, &r);
        CHECK(r.packets - before > 0 && r.packets - before <= 59, "one call read %llu packets (at most 64 KiB)",
              (unsigned long long)(r.packets - before));
        CHECK_EQ_INT(urrt_link_deadline(l), 0); /* more to read: service again at once */
        want_packets = before + 80;
        CHECK(pump(l, &r, 2000, enough_packets, NULL, NULL, 0), "the rest follows");
        CHECK_EQ_INT(r.first_byte_of_last, 79);
    }
    sent_by_link += bytes_from_client(s);
    close(s);
    CHECK_EQ_INT(sent_by_link, 0);
    urrt_link_free(l);
    close(lfd);
}

static void test_connect_timeout(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 0);
    int fillers[4];
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(port), .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    uint64_t t0;

    /* A full accept queue drops further SYNs: a connect that hangs. */
    for (int i = 0; i < 4; i++) {
        fillers[i] = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        connect(fillers[i], (struct sockaddr *)&a, sizeof a);
    }
    sleep_ms(50);
    urrt_link_config_defaults(&c);
    c.host = "127.0.0.1";
    c.port = port;
    c.connect_timeout_ms = 150;
    c.backoff_initial_ms = 5000;
    c.backoff_max_ms = 5000;
    l = urrt_link_new(&c);
    log_count = 0;
    t0 = urrt_port_monotonic_us();
    CHECK(pump(l, &r, 2000, one_failure, NULL, NULL, 0), "the connect gives up");
    CHECK(urrt_port_monotonic_us() - t0 >= 150000, "not before the timeout");
    CHECK(urrt_port_monotonic_us() - t0 < 1000000, "soon after it");
    CHECK_EQ_INT(urrt_link_get_stats(l)->connects, 0);
    CHECK_EQ_INT(lines_with("timed out"), 1);
    CHECK_EQ_INT(lines_with("timed out: no answer; check the address"), 1);
    if (lines_with("timed out") != 1) {
        dump_log();
    }
    urrt_link_free(l);
    for (int i = 0; i < 4; i++) {
        close(fillers[i]);
    }
    close(lfd);
}

static void test_ipv6(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint16_t port = 0;
    int lfd = bind_any(AF_INET6, &port, 4), s;
    uint8_t pkt[1220];
    char peer[64];

    if (lfd < 0) {
        printf("skip: no IPv6 loopback\n");
        return;
    }
    urrt_link_config_defaults(&c);
    c.host = "::1";
    c.port = port;
    l = urrt_link_new(&c);
    snprintf(peer, sizeof peer, "[::1]:%u", port);
    CHECK_EQ_STR(urrt_link_peer(l), peer);
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "connects over IPv6");
    make_packet(pkt, sizeof pkt, 9);
    send_all(s, pkt, sizeof pkt);
    want_packets = 1;
    CHECK(pump(l, &r, 2000, enough_packets, NULL, NULL, 0), "a packet over IPv6");
    CHECK_EQ_INT(urrt_link_get_stats(l)->last_length, 1220);
    CHECK_EQ_INT(bytes_from_client(s), 0);
    close(s);
    urrt_link_free(l);
    close(lfd);
}

/* A name (from /etc/hosts, no DNS): every address is tried in turn, so a
 * server on 127.0.0.1 only is found even when ::1 comes first. */
static void test_name(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 4), s;
    uint8_t pkt[1116];

    urrt_link_config_defaults(&c);
    c.host = "localhost";
    c.port = port;
    l = urrt_link_new(&c);
    log_count = 0;
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "connects to localhost");
    make_packet(pkt, sizeof pkt, 1);
    send_all(s, pkt, sizeof pkt);
    want_packets = 1;
    CHECK(pump(l, &r, 2000, enough_packets, NULL, NULL, 0), "a packet from localhost");
    CHECK_EQ_INT(urrt_link_get_stats(l)->connect_failures, 0);
    CHECK_EQ_INT(lines_with("localhost: connected to localhost"), 1);
    close(s);
    urrt_link_free(l);
    close(lfd);
}

/* Something listens but sends no RealTime stream (a wrong port): the log
 * says it connected and what to check, not only how it ended. The socket has
 * TCP keepalive on, with the short probe times port.h promises. */
static void test_wrong_port(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 4), s, fd;
    int on = 0, idle = 0;
    socklen_t len = sizeof on;
    char want[96];
    static const char banner[] = "Connected: Universal Robots Dashboard Server\n";

    CHECK(lfd >= 0, "listen");
    urrt_link_config_defaults(&c);
    c.name = "arm2";
    c.host = "127.0.0.1";
    c.port = port;
    c.silence_timeout_ms = 100;
    c.backoff_initial_ms = 20;
    l = urrt_link_new(&c);
    log_count = 0;
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "connects");
    fd = urrt_link_poll_fd(l, NULL);
    CHECK(getsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &on, &len) == 0 && on == 1, "SO_KEEPALIVE on");
    len = sizeof idle;
    CHECK(getsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle, &len) == 0 && idle == 1, "keepalive after %d s idle", idle);
    send_all(s, (const uint8_t *)banner, sizeof banner - 1);
    CHECK(pump(l, &r, 2000, one_failure, NULL, NULL, 0), "no packet: a failed attempt");
    CHECK_EQ_INT(urrt_link_get_stats(l)->connects, 0);
    CHECK_EQ_INT(urrt_link_get_stats(l)->disconnects, 0); /* it never came up: not a loss */
    CHECK_EQ_INT(bytes_from_client(s), 0);
    close(s);
    snprintf(want, sizeof want, "sent %zu bytes but no RealTime packet, then no data for 100 ms: is %u the RealTime port",
             sizeof banner - 1, (unsigned)port);
    CHECK_EQ_INT(lines_with(want), 1);
    urrt_link_free(l);
    /* A peer that accepts and closes at once (a fresh link: only the first
     * failure is logged). */
    l = urrt_link_new(&c);
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "second connection");
    close(s);
    CHECK(pump(l, &r, 2000, one_failure, NULL, NULL, 0), "the close is a failed attempt");
    CHECK_EQ_INT(lines_with("it accepted, then closed by peer before sending anything"), 1);
    CHECK_EQ_INT(r.packets, 0);
    if (lines_with("RealTime port") != 1 || lines_with("before sending anything") != 1) {
        dump_log();
    }
    urrt_link_free(l);
    close(lfd);
}


/* Sends a packet on the link's newest connection until the link is up: a
 * connection the link dropped (silent too long) just before the packet went
 * out is replaced by the next, which gets the packet again. Returns the
 * socket the link came up on, or -1. */
static int send_until_up(urrt_link *l, rx *r, int lfd, const uint8_t *pkt, size_t len)
{
    const urrt_link_stats *st = urrt_link_get_stats(l);
    for (int i = 0; i < 10; i++) {
        int s = accept_link(l, r, lfd);
        uint64_t before = st->connect_failures;
        if (s < 0) {
            continue;
        }
        send_all(s, pkt, len);
        while (st->connect_failures == before) {
            if (pump(l, r, 20, is_up, NULL, NULL, 0)) {
                return s;
            }
        }
        close(s);
    }
    return -1;
}

/* A frozen controller (its process stopped, its kernel still accepting): the
 * link that was up goes down once at the silence and stays down through
 * every connection that sends nothing; it comes up once when data flows. */
static void test_frozen_peer(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    uint8_t pkt[1116];
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 16), s;
    const urrt_link_stats *st;
    uint64_t failures;
    bool up = false;

    CHECK(lfd >= 0, "listen");
    urrt_link_config_defaults(&c);
    c.name = "arm3";
    c.host = "127.0.0.1";
    c.port = port;
    c.silence_timeout_ms = 60;
    c.backoff_initial_ms = 10;
    c.backoff_max_ms = 40;
    l = urrt_link_new(&c);
    st = urrt_link_get_stats(l);
    log_count = 0;
    s = accept_link(l, &r, lfd);
    CHECK(s >= 0, "accept");
    make_packet(pkt, sizeof pkt, 1);
    send_all(s, pkt, sizeof pkt);
    CHECK(pump(l, &r, 2000, is_up, NULL, NULL, 0), "up at the first packet");
    CHECK_EQ_INT(st->connects, 1);
    /* Frozen: s stays open and silent; the kernel accepts the reconnects
     * (nobody calls accept). At least three more attempts must come and go
     * without the link coming up. */
    CHECK(pump(l, &r, 3000, one_disconnect, NULL, NULL, 0), "the silence drops the link");
    failures = st->connect_failures;
    for (int i = 0; i < 3 && !up; i++) {
        uint64_t before = st->connect_failures;
        CHECK(pump(l, &r, 2000, is_waiting, NULL, NULL, 0), "reconnect %d: TCP connects", i + 1);
        CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_WAITING);
        while (st->connect_failures == before && !up) {
            up = pump(l, &r, 20, is_up, NULL, NULL, 0);
        }
    }
    CHECK(!up, "never up while frozen");
    CHECK(st->connect_failures >= failures + 3, "each silent connection a failed attempt (%llu)",
          (unsigned long long)(st->connect_failures - failures));
    CHECK_EQ_INT(st->connects, 1);
    CHECK_EQ_INT(st->reconnects, 0);
    CHECK_EQ_INT(st->disconnects, 1);
    CHECK_EQ_INT(st->silences, 1);
    CHECK_EQ_INT(lines_with("lost (no data for 60 ms); reconnecting"), 1);
    CHECK_EQ_INT(lines_with("connected to 127.0.0.1"), 1);
    /* Thawed: data on the link's newest connection brings it up once. */
    close(s);
    s = send_until_up(l, &r, lfd, pkt, sizeof pkt);
    CHECK(s >= 0, "up again once data flows");
    CHECK_EQ_INT(st->connects, 2);
    CHECK_EQ_INT(st->reconnects, 1);
    CHECK_EQ_INT(lines_with("connected to 127.0.0.1"), 2);
    CHECK_EQ_INT(lines_with("failed attempts: 1116-byte packets"), 1);
    if (lines_with("connected to 127.0.0.1") != 2) {
        dump_log();
    }
    close(s);
    urrt_link_free(l);
    close(lfd);
}

/* ---- a source that speaks first ------------------------------------------------ */

/* The test's protocol: after every connect the client sends HANDSHAKE_LEN
 * bytes (byte i is (i * 7 + connection) & 0xFF); the server answers with
 * 8-byte packages: 'D' data, 'X' a protocol error, 'N' a refusal of the
 * configuration. */
#define HANDSHAKE_LEN 8000
typedef struct test_source {
    unsigned connections;     /* connected() calls */
    int queued;               /* urrt_link_send's result for the handshake */
    int too_much;             /* its result for a byte more than fits */
    int small_sndbuf;         /* SO_SNDBUF to set before queueing, 0: leave */
    uint8_t pending[8];
    size_t have;
    uint64_t packages;
} test_source;

static void source_connected(void *ctx, urrt_link *link, uint64_t now_us)
{
    test_source *src = ctx;
    static uint8_t hs[URRT_LINK_SEND_MAX + 1];
    (void)now_us;
    src->connections++;
    src->have = 0; /* a reconnect starts the session afresh */
    if (src->small_sndbuf > 0) {
        (void)setsockopt(urrt_link_poll_fd(link, NULL), SOL_SOCKET, SO_SNDBUF, &src->small_sndbuf,
                         sizeof src->small_sndbuf);
    }
    for (size_t i = 0; i < sizeof hs; i++) {
        hs[i] = (uint8_t)(i * 7u + src->connections);
    }
    src->too_much = urrt_link_send(link, hs, URRT_LINK_SEND_MAX + 1); /* all or nothing: nothing */
    src->queued = urrt_link_send(link, hs, HANDSHAKE_LEN);
}

static void source_received(void *ctx, urrt_link *link, const uint8_t *data, size_t len, uint64_t rx_us)
{
    test_source *src = ctx;
    for (size_t i = 0; i < len; i++) {
        src->pending[src->have++] = data[i];
        if (src->have < sizeof src->pending) {
            continue;
        }
        src->have = 0;
        if (src->pending[0] == 'D') {
            src->packages++;
            urrt_link_source_packet(link, src->pending, sizeof src->pending, rx_us);
        } else if (src->pending[0] == 'N') {
            urrt_link_drop(link, URRT_LINK_DROP_CONFIG,
                           "output field \"no_such_field\" is NOT_FOUND on controller 5.10.0");
            return;
        } else {
            urrt_link_drop(link, URRT_LINK_DROP_PROTOCOL, "a package of unknown type");
            return;
        }
    }
}

/* Reads the server's socket into a buffer: pump's done() while a
 * handshake comes in. */
static int hs_fd = -1;
static uint8_t hs_buf[HANDSHAKE_LEN + 64];
static size_t hs_got;
static bool handshake_in(const urrt_link *l, const rx *r)
{
    (void)l;
    (void)r;
    for (;;) {
        ssize_t n = recv(hs_fd, hs_buf + hs_got, sizeof hs_buf - hs_got, MSG_DONTWAIT);
        if (n <= 0) {
            break;
        }
        hs_got += (size_t)n;
    }
    return hs_got >= HANDSHAKE_LEN;
}

/* The server's side of one session: accept, read the whole handshake while
 * the link writes it, check every byte. Returns the socket, or -1. */
static int serve_handshake(urrt_link *l, rx *r, int lfd, unsigned connection)
{
    int s = accept_link(l, r, lfd), bad = 0;
    if (s < 0) {
        return -1;
    }
    hs_fd = s;
    hs_got = 0;
    pump_also_fd = s;
    CHECK(pump(l, r, 3000, handshake_in, NULL, NULL, 0), "connection %u: the handshake arrives (%zu bytes)",
          connection, hs_got);
    pump_also_fd = -1;
    for (size_t i = 0; i < hs_got && i < HANDSHAKE_LEN; i++) {
        bad += hs_buf[i] != (uint8_t)(i * 7u + connection);
    }
    CHECK(hs_got == HANDSHAKE_LEN && bad == 0, "connection %u: exactly the handshake, byte for byte (%zu bytes, %d wrong)",
          connection, hs_got, bad);
    return s;
}

static void send_package(int s, char type)
{
    uint8_t p[8] = {(uint8_t)type, 1, 2, 3, 4, 5, 6, 7};
    send_all(s, p, sizeof p);
}

static void test_source_handshake(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    test_source src = {.small_sndbuf = 1024};
    urrt_link_source source = {.ctx = &src, .connected = source_connected, .received = source_received};
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 4), s;
    int small = 1024;
    const urrt_link_stats *st;

    CHECK(lfd >= 0, "listen");
    /* A small receive window too: the handshake cannot go in one write. */
    (void)setsockopt(lfd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    urrt_link_config_defaults(&c);
    c.name = "rtde";
    c.host = "127.0.0.1";
    c.port = port;
    c.silence_timeout_ms = 2000; /* the handshake takes a few round trips of a small window */
    c.backoff_initial_ms = 10;
    c.backoff_max_ms = 1000;
    l = urrt_link_new(&c);
    st = urrt_link_get_stats(l);
    urrt_link_set_source(l, &source);
    log_count = 0;
    pump_saw_pollout = false;

    /* 1: the handshake in partial writes, then data: up at the first package. */
    s = serve_handshake(l, &r, lfd, 1);
    CHECK_EQ_INT(src.connections, 1);
    CHECK_EQ_INT(src.queued, URRT_OK);
    CHECK_EQ_INT(src.too_much, URRT_E_NO_SPACE);
    CHECK(pump_saw_pollout, "the link waited for room and continued a partial write");
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_WAITING);
    CHECK_EQ_INT(st->connects, 0);
    send_package(s, 'D');
    want_packets = 1;
    CHECK(pump(l, &r, 2000, enough_packets, NULL, NULL, 0), "the first package reaches the packet function");
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_UP);
    CHECK_EQ_INT(st->connects, 1);
    CHECK_EQ_INT(st->packets, 1);
    CHECK_EQ_INT(st->last_length, 8);
    CHECK_EQ_INT(st->bytes, 8);
    CHECK_EQ_INT(r.first_byte_of_last, 4); /* pkt[4] of the package */
    CHECK_EQ_INT(lines_with("rtde: connected to 127.0.0.1"), 1);
    CHECK_EQ_INT(lines_with("data flows (8-byte packages)"), 1);
    CHECK_EQ_INT(bytes_from_client(s), 0); /* the handshake and nothing more */

    /* 2: the server ends the session; the reconnect redoes the handshake
     * from its first byte, with nothing left over from the first session. */
    close(s);
    s = serve_handshake(l, &r, lfd, 2);
    CHECK_EQ_INT(src.connections, 2);
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_WAITING);
    send_package(s, 'D');
    send_package(s, 'D');
    want_packets = 3;
    CHECK(pump(l, &r, 2000, enough_packets, NULL, NULL, 0), "packages again after the reconnect");
    CHECK_EQ_INT(st->connects, 2);
    CHECK_EQ_INT(st->reconnects, 1);

    /* 3: a protocol error: the source drops the connection; a loss, retried
     * after the initial backoff. */
    send_package(s, 'X');
    CHECK(pump(l, &r, 2000, two_disconnects, NULL, NULL, 0), "a protocol error drops the link");
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_IDLE);
    CHECK((int64_t)(urrt_link_deadline(l) - urrt_port_monotonic_us()) <= 10000, "retried after the initial backoff");
    CHECK_EQ_INT(lines_with("lost (a package of unknown type); reconnecting"), 1);
    CHECK_EQ_INT(bytes_from_client(s), 0); /* nothing after the handshake */
    close(s);
    urrt_link_free(l);
    close(lfd);
}

/* A source on a port that runs what it receives: refused, logged with the
 * port's role, and the link stays the RealTime reader that writes nothing.
 * The ports are the controller's servers as UR documents them (dashboard
 * 29999; primary, secondary, RealTime 30001-30003 and their read-only twins
 * 30011-30013; interpreter mode 30020), not lib's table. Where 30003 is
 * free on loopback a listener there sees the link connect and receives not
 * one byte. */
static void test_source_script_port(void)
{
    static const uint16_t ports[] = {29999, 30001, 30002, 30003, 30011, 30012, 30013, 30020};
    test_source src = {0};
    urrt_link_source source = {.ctx = &src, .connected = source_connected, .received = source_received};
    urrt_link_config c;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(30003)};
    int lfd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0), one = 1;

    urrt_link_config_defaults(&c);
    c.name = "script";
    c.host = "127.0.0.1";
    c.backoff_initial_ms = 10;
    for (size_t i = 0; i < sizeof ports / sizeof ports[0]; i++) {
        urrt_link *l;
        char want[64];
        c.port = ports[i];
        l = urrt_link_new(&c);
        log_count = 0;
        CHECK_EQ_INT(urrt_link_set_source(l, &source), URRT_RTDE_E_SCRIPT_PORT);
        snprintf(want, sizeof want, "will not write to 127.0.0.1:%u: port %u is the", (unsigned)ports[i],
                 (unsigned)ports[i]);
        CHECK(lines_with(want) == 1 && lines_with("RTDE is port 30004") == 1, "port %u: the refusal is logged",
              (unsigned)ports[i]);
        urrt_link_free(l);
    }
    c.port = 30004;
    {
        urrt_link *l = urrt_link_new(&c);
        CHECK_EQ_INT(urrt_link_set_source(l, &source), URRT_OK);
        urrt_link_free(l);
    }

    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    (void)setsockopt(lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (lfd >= 0 && bind(lfd, (struct sockaddr *)&a, sizeof a) == 0 && listen(lfd, 4) == 0) {
        rx r = {0};
        urrt_link *l;
        int s;
        c.port = 30003;
        l = urrt_link_new(&c);
        (void)urrt_link_set_source(l, &source);
        CHECK(pump(l, &r, 3000, is_waiting, NULL, NULL, 0), "the link connects to 30003 as the RealTime reader");
        s = accept_within(lfd, 2000);
        CHECK(s >= 0, "the listener on 30003 accepts");
        CHECK_EQ_INT(src.connections, 0);
        CHECK_EQ_INT(urrt_link_send(l, (const uint8_t *)"V", 1), URRT_E_ARG);
        CHECK_EQ_INT(bytes_from_client(s), 0);
        if (s >= 0) {
            close(s);
        }
        urrt_link_free(l);
    } else {
        printf("note: 127.0.0.1:30003 is taken here: the refusals above are checked without a listener\n");
    }
    if (lfd >= 0) {
        close(lfd);
    }
}

/* A controller that refuses the configuration: reported once, however
 * often it refuses, and retried with the long backoff, never in a loop. */
static void test_source_refused(void)
{
    urrt_link_config c;
    urrt_link *l;
    rx r = {0};
    test_source src = {0};
    urrt_link_source source = {.ctx = &src, .connected = source_connected, .received = source_received};
    uint16_t port = 0;
    int lfd = bind_any(AF_INET, &port, 4), s;
    const urrt_link_stats *st;
    uint64_t delays[4];
    int nd = 0;

    CHECK(lfd >= 0, "listen");
    urrt_link_config_defaults(&c);
    c.name = "rtde";
    c.host = "127.0.0.1";
    c.port = port;
    c.silence_timeout_ms = 2000;
    c.backoff_initial_ms = 10;
    c.backoff_max_ms = 300;
    l = urrt_link_new(&c);
    st = urrt_link_get_stats(l);
    urrt_link_set_source(l, &source);
    log_count = 0;
    for (unsigned i = 1; i <= 3; i++) {
        uint64_t before = st->connect_failures;
        s = serve_handshake(l, &r, lfd, i);
        if (s < 0) {
            break;
        }
        send_package(s, 'N');
        pump_failures_base = before;
        CHECK(pump(l, &r, 2000, one_failure_more, delays, &nd, 4), "refusal %u ends the attempt", i);
        CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_IDLE);
        close(s);
    }
    CHECK_EQ_INT(st->connect_failures, 3);
    CHECK_EQ_INT(st->connects, 0);
    CHECK_EQ_INT(st->disconnects, 0);
    CHECK(nd == 3, "%d waits recorded", nd);
    for (int i = 0; i < nd; i++) {
        CHECK(delays[i] >= 299 && delays[i] <= 300, "refusal %d: the long backoff (%llu ms)", i + 1,
              (unsigned long long)delays[i]);
    }
    CHECK_EQ_INT(lines_with("refuses the configuration: output field \"no_such_field\" is NOT_FOUND on controller "
                            "5.10.0; fix the configuration (retrying every 300 ms meanwhile)"), 1);
    CHECK_EQ_INT(lines_with("error: robot rtde:"), 1);
    if (lines_with("refuses the configuration") != 1) {
        dump_log();
    }
    urrt_link_free(l);
    close(lfd);
}

static void test_cli(void)
{
    char host[64];
    uint16_t port = 0;
    uint64_t v = 0;
    uint32_t v32 = 0;

    CHECK(cli_parse_host_port("robot", 30003, host, sizeof host, &port) == NULL, "host");
    CHECK_EQ_STR(host, "robot");
    CHECK_EQ_INT(port, 30003);
    CHECK(cli_parse_host_port("10.0.0.5:30013", 30003, host, sizeof host, &port) == NULL, "host:port");
    CHECK_EQ_STR(host, "10.0.0.5");
    CHECK_EQ_INT(port, 30013);
    CHECK(cli_parse_host_port("[::1]:40001", 30003, host, sizeof host, &port) == NULL, "[v6]:port");
    CHECK_EQ_STR(host, "::1");
    CHECK_EQ_INT(port, 40001);
    CHECK(cli_parse_host_port("[fe80::1%eth0]", 30003, host, sizeof host, &port) == NULL, "[v6]");
    CHECK_EQ_STR(host, "fe80::1%eth0");
    CHECK_EQ_INT(port, 30003);
    CHECK(cli_parse_host_port("::1", 30013, host, sizeof host, &port) == NULL, "bare v6");
    CHECK_EQ_STR(host, "::1");
    CHECK_EQ_INT(port, 30013);
    CHECK(cli_parse_host_port("robot:", 30003, host, sizeof host, &port) != NULL, "no port after colon");
    CHECK(cli_parse_host_port(":30003", 30003, host, sizeof host, &port) != NULL, "no host");
    CHECK(cli_parse_host_port("robot:70000", 30003, host, sizeof host, &port) != NULL, "port range");
    CHECK(cli_parse_host_port("robot:0", 30003, host, sizeof host, &port) != NULL, "port 0");
    CHECK(cli_parse_listen_address("127.0.0.1:0", 30003, host, sizeof host, &port) == NULL, "listen on port 0");
    CHECK_EQ_INT(port, 0);
    CHECK(cli_parse_listen_address("[::1]:30013", 30003, host, sizeof host, &port) == NULL, "listen [v6]:port");
    CHECK_EQ_INT(port, 30013);
    CHECK(cli_parse_listen_address("robot:65536", 30003, host, sizeof host, &port) != NULL, "listen port range");
    CHECK(cli_parse_host_port("robot:30x", 30003, host, sizeof host, &port) != NULL, "port text");
    CHECK(cli_parse_host_port("[::1", 30003, host, sizeof host, &port) != NULL, "unclosed bracket");
    CHECK(cli_parse_host_port("[::1]x", 30003, host, sizeof host, &port) != NULL, "text after bracket");
    CHECK(cli_parse_host_port("", 30003, host, sizeof host, &port) != NULL, "empty");
    CHECK(cli_parse_host_port("a-very-long-host-name-that-does-not-fit-into-the-buffer-given-here", 1, host,
                              sizeof host, &port) != NULL,
          "too long");

    CHECK(cli_parse_u64("125", 1, 1000, &v) == NULL && v == 125, "u64");
    CHECK(cli_parse_u64("0x10", 1, 1000, &v) == NULL && v == 16, "hex");
    CHECK(cli_parse_u64("0", 1, 1000, &v) != NULL, "below min");
    CHECK(cli_parse_u64("1001", 1, 1000, &v) != NULL, "above max");
    CHECK(cli_parse_u64("-1", 0, UINT64_MAX, &v) != NULL, "sign");
    CHECK(cli_parse_u64("12abc", 0, UINT64_MAX, &v) != NULL, "trailing text");
    CHECK(cli_parse_u64("99999999999999999999999", 0, UINT64_MAX, &v) != NULL, "overflow");
    CHECK(cli_parse_u32("4294967296", 0, UINT32_MAX, &v32) != NULL, "u32 overflow");

    cli_format_host_port("::1", 30003, host, sizeof host);
    CHECK_EQ_STR(host, "[::1]:30003");
    cli_format_host_port("robot", 30013, host, sizeof host);
    CHECK_EQ_STR(host, "robot:30013");
}

/* ---- waiting in the read --------------------------------------------------------- */

typedef struct late_send {
    int fd;
    int after_ms;
    const uint8_t *bytes;
    size_t len;
    uint64_t sent_us; /* monotonic, just before the send */
} late_send;

/* The stimulus: a packet that comes while the link waits in its read. */
static void *send_later(void *arg)
{
    late_send *ls = arg;
    sleep_ms(ls->after_ms);
    ls->sent_us = urrt_port_monotonic_us();
    send_all(ls->fd, ls->bytes, ls->len);
    return NULL;
}

static volatile sig_atomic_t alarms;
static void on_alarm(int sig)
{
    (void)sig;
    alarms++;
}

static uint64_t rcvtimeo_us(int fd)
{
    struct timeval tv = {0, 0};
    socklen_t len = sizeof tv;
    if (getsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, &len) != 0) {
        return UINT64_MAX;
    }
    return (uint64_t)tv.tv_sec * 1000000u + (uint64_t)tv.tv_usec;
}

/* A link named `name` to a server of this test's on loopback, up at the
 * server's first packet (tag 1): the listening socket in *lfd, the accepted
 * one in *s. NULL (checks failed) if it did not come up. */
static urrt_link *link_up(const char *name, uint32_t silence_timeout_ms, rx *r, int *lfd, int *s)
{
    urrt_link_config c;
    urrt_link *l;
    uint8_t pkt[1116];
    uint16_t port = 0;

    *lfd = bind_any(AF_INET, &port, 16);
    CHECK(*lfd >= 0, "%s: listen", name);
    urrt_link_config_defaults(&c);
    c.name = name;
    c.host = "127.0.0.1";
    c.port = port;
    c.silence_timeout_ms = silence_timeout_ms;
    l = urrt_link_new(&c);
    *s = accept_link(l, r, *lfd);
    CHECK(*s >= 0, "%s: accept", name);
    make_packet(pkt, sizeof pkt, 1);
    send_all(*s, pkt, sizeof pkt);
    if (!pump(l, r, 2000, is_up, NULL, NULL, 0)) {
        CHECK(false, "%s: up at the first packet", name);
        urrt_link_free(l);
        return NULL;
    }
    return l;
}

/* urrt_link_service_waiting: waits only where it can end in time, delivers
 * what arrives with the stamps urrt_link_service gives (the empty queue from
 * the kernel's receive time, not the start of the wait), and a signal ends
 * the wait. */
static void test_wait_in_read(void)
{
    urrt_link *l;
    rx r = {0};
    uint8_t pkt[1116];
    int lfd, s, fd;
    const urrt_link_stats *st;
    struct timespec res;
    uint64_t tick_us, t0, until, waits;
    late_send ls;
    pthread_t th;
    struct sigaction sa, old;
    struct itimerval it = {{0, 0}, {0, 100000}};

    CHECK(clock_getres(CLOCK_MONOTONIC_COARSE, &res) == 0, "the kernel's tick");
    tick_us = (uint64_t)res.tv_nsec / 1000u;
    /* A silence timeout of a minute: no deadline of the link's own while the test waits. */
    l = link_up("arm-wait", 60000, &r, &lfd, &s);
    if (l == NULL) {
        return;
    }
    st = urrt_link_get_stats(l);
    fd = urrt_link_poll_fd(l, NULL);

    /* Too little room for a timeout that ends in time: nothing done. */
    CHECK(!urrt_link_service_waiting(l, urrt_port_monotonic_us(), on_packet, &r), "no wait for a deadline now");
    CHECK(!urrt_link_service_waiting(l, urrt_port_monotonic_us() + tick_us, on_packet, &r),
          "no wait for a deadline a tick away");
    CHECK_EQ_INT(st->read_waits, 0);

    /* A packet that comes during the wait: delivered, and the queue's empty
     * time is its arrival, not the start of the wait. */
    ls = (late_send){.fd = s, .after_ms = 200, .bytes = pkt, .len = sizeof pkt};
    make_packet(pkt, sizeof pkt, 2);
    t0 = urrt_port_monotonic_us();
    until = t0 + 20000000u;
    CHECK(pthread_create(&th, NULL, send_later, &ls) == 0, "sender thread");
    while (r.packets < 2 && urrt_port_monotonic_us() < until) {
        CHECK(urrt_link_service_waiting(l, until, on_packet, &r), "waits for the packet");
    }
    pthread_join(th, NULL);
    CHECK_EQ_INT(r.packets, 2);
    CHECK_EQ_INT(r.first_byte_of_last, 2);
    CHECK(st->read_waits >= 1, "counted (%llu)", (unsigned long long)st->read_waits);
    CHECK(rcvtimeo_us(fd) <= (until - t0) / 2u + tick_us, "the read's timeout is at most half the room and a tick "
          "(%llu us of %llu)", (unsigned long long)rcvtimeo_us(fd), (unsigned long long)(until - t0));
    /* The next packet, already queued: its first byte came after the queue
     * was seen empty, which the wait put at the last one's arrival (the
     * start of the wait was 200 ms before it). */
    make_packet(pkt, sizeof pkt, 3);
    send_all(s, pkt, sizeof pkt);
    waits = st->read_waits;
    CHECK(urrt_link_service_waiting(l, urrt_port_monotonic_us() + 20000000u, on_packet, &r), "a queued packet");
    CHECK_EQ_INT(r.packets, 3);
    CHECK_EQ_INT(st->read_waits, waits + 1);
    CHECK(urrt_link_packet_empty_us(l) >= t0 + 100000u && urrt_link_packet_empty_us(l) <= st->last_packet_us,
          "empty queue at the kernel's arrival of the packet before (%lld us after the wait began, sent at %lld)",
          (long long)(urrt_link_packet_empty_us(l) - t0), (long long)(ls.sent_us - t0));

    /* A signal ends the wait (its timeout here is about 10 s). */
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART, as urrt-gateway's handlers */
    sigaction(SIGALRM, &sa, &old);
    alarms = 0;
    t0 = urrt_port_monotonic_us();
    setitimer(ITIMER_REAL, &it, NULL);
    CHECK(urrt_link_service_waiting(l, t0 + 20000000u, on_packet, &r), "waits until the signal");
    CHECK(alarms == 1, "the signal came (%d)", (int)alarms);
    CHECK(urrt_port_monotonic_us() - t0 < 5000000u, "the signal ended the wait (after %llu ms)",
          (unsigned long long)((urrt_port_monotonic_us() - t0) / 1000u));
    CHECK_EQ_INT(r.packets, 3);
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_UP);
    sigaction(SIGALRM, &old, NULL);

    /* Nothing comes: the timeout ends the wait before the deadline the
     * caller gave, the link still up (its own silence is a minute). */
    t0 = urrt_port_monotonic_us();
    until = t0 + 300000u;
    while (urrt_port_monotonic_us() < until && urrt_link_service_waiting(l, until, on_packet, &r)) {
    }
    CHECK_EQ_INT(r.packets, 3);
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_UP);
    CHECK(rcvtimeo_us(fd) <= 150000u + tick_us, "each timeout at most half the room and a tick (%llu us)",
          (unsigned long long)rcvtimeo_us(fd));

    /* The peer closes: the wait reads the end of the stream. */
    close(s);
    while (urrt_link_get_state(l) == URRT_LINK_UP &&
           urrt_link_service_waiting(l, urrt_port_monotonic_us() + 2000000u, on_packet, &r)) {
    }
    CHECK_EQ_INT(st->disconnects, 1);
    CHECK(!urrt_link_service_waiting(l, urrt_port_monotonic_us() + 2000000u, on_packet, &r),
          "no wait without a connection (closed by the peer)");
    urrt_link_free(l);
    close(lfd);
}

/* A wait that its timeout ends, past the link's silence timeout: the
 * silence is judged by the clock before the read, as urrt_link_service
 * judges it, so the wait itself drops nothing (a clock read after a read
 * that found nothing may come after a stop that left the queue full); the
 * next call, its deadline passed, does. */
static void test_wait_silence(void)
{
    urrt_link *l;
    rx r = {0};
    int lfd, s;
    const urrt_link_stats *st;
    uint64_t t0;

    l = link_up("arm-wait-silence", 50, &r, &lfd, &s);
    if (l == NULL) {
        return;
    }
    st = urrt_link_get_stats(l);
    t0 = urrt_port_monotonic_us();
    CHECK(urrt_link_service_waiting(l, t0 + 400000u, on_packet, &r), "waits");
    CHECK(urrt_port_monotonic_us() - st->last_packet_us >= 50000u, "the wait outlasted the silence timeout");
    CHECK_EQ_INT(urrt_link_get_state(l), URRT_LINK_UP);
    CHECK_EQ_INT(st->silences, 0);
    urrt_link_service(l, urrt_port_monotonic_us(), on_packet, &r);
    CHECK_EQ_INT(st->silences, 1);
    CHECK(urrt_link_get_state(l) != URRT_LINK_UP, "the next call drops the silent link");
    close(s);
    urrt_link_free(l);
    close(lfd);
}

int main(void)
{
    urrt_log_init("test_link", URRT_LOG_DEBUG);
    urrt_log_set_sink(sink, NULL);
    test_cli();
    test_config();
    test_refused_backoff();
    test_session();
    test_connect_timeout();
    test_ipv6();
    test_name();
    test_wrong_port();
    test_frozen_peer();
    test_wait_in_read();
    test_wait_silence();
    test_source_handshake();
    test_source_refused();
    test_source_script_port();
    return check_report();
}
