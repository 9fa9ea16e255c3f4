/* SPDX-License-Identifier: MIT */
/*
 * can_rx_test: black-box tests of the CAN link's receive side (port.h,
 * port/posix/can.c), and of the log link's caller clock.
 *
 *   can_rx_test clock DIR   log: links (no CAN needed): with log_caller_clock
 *                           each line carries the now_us given to the send,
 *                           without it the wall clock; a log link hands no
 *                           frame and names no descriptor
 *   can_rx_test rx          on vcan1 in the VM of tests/vm/run.sh: only the
 *                           configured 11-bit data frames arrive, in order
 *                           (not 29-bit, remote or other ids; error frames
 *                           still counted); at most URRT_CANLINK_RX_BURST per
 *                           service call with the deadline "now" meanwhile;
 *                           SO_RXQ_OVFL drops counted; the filter survives a
 *                           reopen; rx ids out of range refused
 *   can_rx_test flood       cangen floods vcan1 flat out with other ids and
 *                           with one of ours while a robot link (a local TCP
 *                           robot writing numbered packets) is served by the
 *                           same poll loop: none of the other ids is handed,
 *                           no service call hands more than the burst, and
 *                           every robot packet arrives, in order, without a
 *                           reconnect
 *
 * Events, never timings: every wait is a poll for the event with a bounded
 * limit. Each mode prints "N passed, N failed".
 */
#define _GNU_SOURCE
#include <errno.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>

#include "port.h"
#include "urrt.h"
#include "../check.h"

extern char **environ;

#define BUS "vcan1"
/* A CANopen node 1's receive ids: NMT, SYNC, SDO request. */
static const uint32_t node_ids[] = {0x000, 0x080, 0x601};
#define NODE_ID_COUNT (sizeof(node_ids) / sizeof(node_ids[0]))
/* Any wait for an event gives up after this: a limit, not a measurement. */
#define WAIT_LIMIT_US (20u * 1000000u)

static pid_t spawn(const char *const argv[])
{
    pid_t pid;
    if (posix_spawnp(&pid, argv[0], NULL, NULL, (char *const *)argv, environ) != 0) {
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
        return -1;
    }
    return pid;
}

/* Runs a program found in PATH (not through the busybox shell, whose ip
 * applet would win). Returns its exit status. */
static int run(const char *const argv[])
{
    pid_t pid = spawn(argv);
    int status;
    if (pid < 0 || waitpid(pid, &status, 0) < 0)
        return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* ---- what the link hands over ------------------------------------------------ */

#define SEEN_MAX 4096

typedef struct seen {
    urrt_can_frame frames[SEEN_MAX];
    size_t count;       /* handed in all */
    size_t in_call;     /* handed during the current service call */
    size_t max_in_call;
    size_t calls_at_burst; /* service calls that handed exactly the burst */
    size_t foreign;     /* frames with an id not configured */
    uint64_t last_rx_us;
    bool rx_after_now;  /* an rx_us later than the service's now */
    uint64_t now_us;
} seen;

static bool is_node_id(const urrt_can_frame *f)
{
    for (size_t i = 0; i < NODE_ID_COUNT; i++)
        if (!f->extended && f->id == node_ids[i])
            return true;
    return false;
}

static void on_rx(void *ctx, const urrt_can_frame *frame, uint64_t rx_us)
{
    seen *s = ctx;
    if (s->count < SEEN_MAX)
        s->frames[s->count] = *frame;
    s->count++;
    s->in_call++;
    if (!is_node_id(frame))
        s->foreign++;
    if (rx_us > s->now_us)
        s->rx_after_now = true;
    s->last_rx_us = rx_us;
}

/* One service call, with the count of frames it handed. */
static size_t service(urrt_canlink *can, seen *s)
{
    s->now_us = urrt_port_monotonic_us();
    s->in_call = 0;
    urrt_canlink_service(can, s->now_us);
    if (s->in_call > s->max_in_call)
        s->max_in_call = s->in_call;
    if (s->in_call == URRT_CANLINK_RX_BURST)
        s->calls_at_burst++;
    return s->in_call;
}

/* Services the link whenever its socket is readable until it has handed
 * want frames in all, or the limit. */
static void service_until(urrt_canlink *can, seen *s, size_t want)
{
    uint64_t end = urrt_port_monotonic_us() + WAIT_LIMIT_US;
    while (s->count < want && urrt_port_monotonic_us() < end) {
        short events;
        int fd = urrt_canlink_poll_fd(can, &events);
        struct pollfd p = {.fd = fd, .events = events};
        if (fd >= 0)
            poll(&p, 1, 100);
        service(can, s);
    }
}

static urrt_canlink *open_rx_link(const uint32_t *ids, size_t count, seen *s)
{
    urrt_canlink_config cfg;
    urrt_canlink_config_defaults(&cfg);
    cfg.interface = BUS;
    cfg.reopen_interval_ms = 20;
    cfg.rx_ids = ids;
    cfg.rx_id_count = count;
    urrt_canlink *can = urrt_canlink_new(&cfg);
    if (can != NULL && s != NULL)
        urrt_canlink_set_rx(can, on_rx, s);
    return can;
}

/* ---- a raw socket on the bus: the other nodes ------------------------------------ */

static int open_raw(bool receive_node_ids)
{
    int sock = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (sock < 0)
        return -1;
    struct can_filter f[NODE_ID_COUNT];
    for (size_t i = 0; i < NODE_ID_COUNT; i++) {
        f[i].can_id = node_ids[i];
        f[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    setsockopt(sock, SOL_CAN_RAW, CAN_RAW_FILTER, receive_node_ids ? f : NULL,
               receive_node_ids ? (socklen_t)sizeof(f) : 0);
    int big = 4 << 20; /* the observer must never drop what it counts */
    setsockopt(sock, SOL_SOCKET, SO_RCVBUFFORCE, &big, sizeof(big));
    struct sockaddr_can addr = {.can_family = AF_CAN, .can_ifindex = (int)if_nametoindex(BUS)};
    if (bind(sock, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
        close(sock);
        return -1;
    }
    return sock;
}

static bool raw_send(int sock, canid_t id, uint8_t len, uint8_t seed)
{
    struct can_frame cf;
    memset(&cf, 0, sizeof(cf));
    cf.can_id = id;
    cf.can_dlc = len;
    for (unsigned i = 0; i < len && i < CAN_MAX_DLEN; i++)
        cf.data[i] = (uint8_t)(seed + i);
    return write(sock, &cf, sizeof(cf)) == (ssize_t)sizeof(cf);
}

/* Reads n frames from an observer socket (bounded wait): once it has them,
 * the kernel has delivered them to every socket on the bus. */
static size_t observe(int sock, size_t n)
{
    size_t got = 0;
    uint64_t end = urrt_port_monotonic_us() + WAIT_LIMIT_US;
    while (got < n && urrt_port_monotonic_us() < end) {
        struct pollfd p = {.fd = sock, .events = POLLIN};
        if (poll(&p, 1, 100) <= 0)
            continue;
        struct can_frame cf;
        if (read(sock, &cf, sizeof(cf)) == (ssize_t)sizeof(cf))
            got++;
    }
    return got;
}

/* ---- clock: the log link ---------------------------------------------------------- */

static char *read_file(const char *path)
{
    static char buf[4096];
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, sizeof(buf) - 1, f) : 0;
    if (f)
        fclose(f);
    buf[n] = '\0';
    return buf;
}

static void test_clock(const char *dir)
{
    char spec[600], path[512];
    snprintf(path, sizeof(path), "%s/log-caller-clock.log", dir);
    snprintf(spec, sizeof(spec), "log:%s,ifname=vcan1", path);
    urrt_canlink_config cfg;
    urrt_canlink_config_defaults(&cfg);
    cfg.interface = spec;
    cfg.log_caller_clock = true;
    cfg.rx_ids = node_ids;
    cfg.rx_id_count = NODE_ID_COUNT;
    urrt_canlink *can = urrt_canlink_new(&cfg);
    CHECK(can != NULL, "a log link with rx ids and the caller's clock");
    if (can == NULL)
        return;
    seen *s = calloc(1, sizeof(*s));
    urrt_canlink_set_rx(can, on_rx, s);
    urrt_can_frame f = {.id = 0x181, .len = 2, .data = {0xAB, 0x01}};
    CHECK_EQ_INT(urrt_canlink_send(can, &f, UINT64_C(1234567890123)), 1);
    f.id = 0x701;
    f.len = 1;
    f.data[0] = 0x7F;
    CHECK_EQ_INT(urrt_canlink_send(can, &f, UINT64_C(7000001)), 1);
    short events;
    CHECK_EQ_INT(urrt_canlink_poll_fd(can, &events), -1);
    service(can, s);
    CHECK_EQ_INT(s->count, 0);
    CHECK(urrt_canlink_deadline(can) == UINT64_MAX, "a log link has nothing due");
    urrt_canlink_free(can);
    CHECK_EQ_STR(read_file(path), "(0001234567.890123) vcan1 181#AB01\n(0000000007.000001) vcan1 701#7F\n");

    snprintf(path, sizeof(path), "%s/log-wall-clock.log", dir);
    snprintf(spec, sizeof(spec), "log:%s", path);
    cfg.log_caller_clock = false;
    can = urrt_canlink_new(&cfg);
    uint64_t before = urrt_port_realtime_us() / 1000000u;
    CHECK_EQ_INT(urrt_canlink_send(can, &f, UINT64_C(7000001)), 1);
    uint64_t after = urrt_port_realtime_us() / 1000000u;
    urrt_canlink_free(can);
    unsigned long long sec = 0;
    CHECK(sscanf(read_file(path), "(%llu.", &sec) == 1 && sec >= before && sec <= after,
          "without log_caller_clock the line carries the wall clock (%llu, not 7)", sec);
    free(s);
}

/* ---- rx: filter, order, burst, overflow, reopen ------------------------------------ */

static void test_refusals(void)
{
    const uint32_t bad[] = {0x601, 0x800};
    CHECK(open_rx_link(bad, 2, NULL) == NULL, "an rx id above 0x7FF is refused");
    static uint32_t many[URRT_CANLINK_RX_IDS_MAX + 1];
    CHECK(open_rx_link(many, URRT_CANLINK_RX_IDS_MAX + 1, NULL) == NULL, "more ids than the kernel filter takes");
    urrt_canlink *none = open_rx_link(NULL, 5, NULL);
    CHECK(none != NULL, "NULL rx ids: a link that receives nothing");
    urrt_canlink_free(none);
}

/* Sends the mix: ours, theirs, ours as 29-bit and as remote requests, an
 * error frame. Returns how many frames of ours were sent. */
static size_t send_mix(int raw, unsigned round)
{
    static const canid_t mix[] = {
        0x000, 0x123, 0x080, 0x601 | CAN_EFF_FLAG, 0x601, 0x601 | CAN_RTR_FLAG, 0x602, 0x7FF, 0x081,
        0x000 | CAN_EFF_FLAG, 0x080 | CAN_RTR_FLAG, 0x700, 0x581,
    };
    size_t ours = 0;
    for (size_t i = 0; i < sizeof(mix) / sizeof(mix[0]); i++) {
        uint8_t len = (mix[i] & ~CAN_EFF_FLAG) == 0x080 ? 0 : (uint8_t)(mix[i] == 0x000 ? 2 : 8);
        raw_send(raw, mix[i], len, (uint8_t)(round * 16u + i));
        if (!(mix[i] & (CAN_EFF_FLAG | CAN_RTR_FLAG)) && (mix[i] == 0x000 || mix[i] == 0x080 || mix[i] == 0x601))
            ours++;
    }
    return ours;
}

static void check_mix(const seen *s, size_t rounds)
{
    static const uint32_t want_ids[] = {0x000, 0x080, 0x601};
    static const uint8_t want_len[] = {2, 0, 8};
    static const unsigned want_pos[] = {0, 2, 4};
    bool ok = s->count == rounds * 3;
    for (size_t i = 0; ok && i < s->count; i++) {
        const urrt_can_frame *f = &s->frames[i];
        size_t k = i % 3;
        uint8_t seed = (uint8_t)((i / 3) * 16u + want_pos[k]);
        ok = f->id == want_ids[k] && !f->extended && !f->fd && f->len == want_len[k] &&
             (f->len == 0 || f->data[0] == seed);
        if (!ok)
            fprintf(stderr, "  frame %zu: id %X len %u data[0] %02X\n", i, (unsigned)f->id, f->len, f->data[0]);
    }
    CHECK(ok, "only the node's ids, in order, with their data (%zu frames of %zu)", s->count, rounds * 3);
    CHECK_EQ_INT(s->foreign, 0);
}

/* Services the link at its deadlines (the reopen timer) until it is up. */
static void wait_up(urrt_canlink *can, seen *s)
{
    uint64_t end = urrt_port_monotonic_us() + WAIT_LIMIT_US;
    while (urrt_canlink_get_state(can) != URRT_CANLINK_UP && urrt_port_monotonic_us() < end) {
        uint64_t now = urrt_port_monotonic_us(), due = urrt_canlink_deadline(can);
        poll(NULL, 0, due > now ? (int)((due - now) / 1000u) + 1 : 0);
        service(can, s);
    }
}

static void test_filter(void)
{
    seen *s = calloc(1, sizeof(*s));
    urrt_canlink *can = open_rx_link(node_ids, NODE_ID_COUNT, s);
    int raw = open_raw(false);
    int obs = open_raw(true);
    CHECK(can != NULL && raw >= 0 && obs >= 0, "link, sender and observer on " BUS);
    if (can == NULL || raw < 0 || obs < 0)
        return;
    size_t ours = 0;
    for (unsigned round = 0; round < 4; round++)
        ours += send_mix(raw, round);
    /* An error frame, as a driver's would be: still counted beside the filter. */
    raw_send(raw, CAN_ERR_FLAG | CAN_ERR_CRTL, CAN_ERR_DLC, 0);
    CHECK_EQ_INT(observe(obs, ours), ours);
    service_until(can, s, ours);
    check_mix(s, 4);
    const urrt_canlink_stats *st = urrt_canlink_get_stats(can);
    CHECK_EQ_INT(st->received, ours);
    CHECK_EQ_INT(st->error_frames, 1);
    CHECK(!s->rx_after_now, "rx_us never after the service's now");
    CHECK(s->last_rx_us > 0, "rx_us given");

    /* The filter survives the interface going down and up. */
    const char *down[] = {"ip", "link", "set", BUS, "down", NULL};
    const char *up[] = {"ip", "link", "set", BUS, "up", NULL};
    CHECK_EQ_INT(run(down), 0);
    service(can, s);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    CHECK_EQ_INT(run(up), 0);
    wait_up(can, s);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    CHECK_EQ_INT(urrt_canlink_get_stats(can)->opens, 2);
    s->count = 0;
    close(raw);
    raw = open_raw(false); /* the old sockets lost their binding with the interface */
    close(obs);
    obs = open_raw(true);
    ours = send_mix(raw, 0);
    CHECK_EQ_INT(observe(obs, ours), ours);
    service_until(can, s, ours);
    check_mix(s, 1);
    urrt_canlink_free(can);
    close(raw);
    close(obs);
    free(s);
}

static void test_burst(void)
{
    seen *s = calloc(1, sizeof(*s));
    urrt_canlink *can = open_rx_link(node_ids, NODE_ID_COUNT, s);
    int raw = open_raw(false), obs = open_raw(true);
    const size_t n = 100;
    for (size_t i = 0; i < n; i++)
        raw_send(raw, 0x601, 8, (uint8_t)i);
    CHECK_EQ_INT(observe(obs, n), n);
    /* All 100 are queued on the link's socket now: one call hands the burst. */
    CHECK_EQ_INT(service(can, s), URRT_CANLINK_RX_BURST);
    CHECK(urrt_canlink_deadline(can) <= s->now_us, "deadline now while frames remain after a burst");
    service_until(can, s, n);
    CHECK_EQ_INT(s->count, n);
    CHECK_EQ_INT(s->max_in_call, URRT_CANLINK_RX_BURST);
    bool in_order = true;
    for (size_t i = 0; i < n && i < s->count; i++)
        in_order = in_order && s->frames[i].id == 0x601 && s->frames[i].data[0] == (uint8_t)i;
    CHECK(in_order, "100 frames in the order sent");
    service(can, s);
    CHECK(urrt_canlink_deadline(can) == UINT64_MAX, "nothing due once the queue is empty");

    /* Overflow: far more than the socket's receive queue holds, unread. */
    const size_t flood = 3000;
    for (size_t i = 0; i < flood; i++)
        raw_send(raw, 0x080, 0, 0);
    CHECK_EQ_INT(observe(obs, flood), flood);
    size_t before = s->count;
    while (service(can, s) > 0)
        ;
    /* Drops are reported with the next frame queued after them. */
    raw_send(raw, 0x000, 2, 0);
    CHECK_EQ_INT(observe(obs, 1), 1);
    service_until(can, s, s->count + 1);
    const urrt_canlink_stats *st = urrt_canlink_get_stats(can);
    CHECK(st->rx_overflows > 0, "a full receive queue counts drops (%llu)", (unsigned long long)st->rx_overflows);
    CHECK_EQ_INT(s->count - before + st->rx_overflows, flood + 1);
    urrt_canlink_free(can);
    close(raw);
    close(obs);
    free(s);
}

/* ---- flood: the robot link beside a flooded bus ------------------------------------- */

#define ROBOT_PACKETS 400u
#define FULL_BURSTS 10u /* service calls that must hand a whole burst during the flood */
#define PACKET_LEN 1116u

typedef struct robot_server {
    int lsock;
    int done[2]; /* a pipe: the connection stays open until the test is done */
} robot_server;

/* The robot: accepts one client, writes packets numbered 1..N (the time
 * column) as fast as the client takes them, and keeps the connection open
 * until the test says it is done (a close would count as a lost link). */
static void *robot(void *arg)
{
    robot_server *rs = arg;
    int c = accept(rs->lsock, NULL, NULL);
    if (c < 0)
        return NULL;
    static urrt_state st;
    urrt_state_clear(&st);
    uint8_t pkt[PACKET_LEN];
    for (unsigned k = 1; k <= ROBOT_PACKETS; k++) {
        st.time[0] = (double)k;
        urrt_encode(&st, PACKET_LEN, pkt, sizeof(pkt));
        size_t done = 0;
        while (done < sizeof(pkt)) {
            ssize_t w = write(c, pkt + done, sizeof(pkt) - done);
            if (w <= 0)
                break;
            done += (size_t)w;
        }
    }
    char b;
    while (read(rs->done[0], &b, 1) < 0 && errno == EINTR)
        ;
    close(c);
    return NULL;
}

typedef struct robot_seen {
    unsigned packets;
    bool in_order;
} robot_seen;

static void on_packet(void *ctx, const uint8_t *packet, size_t len, uint64_t rx_us)
{
    (void)rx_us;
    robot_seen *r = ctx;
    double t = 0;
    urrt_read(packet, len, URRT_F_TIME, 0, &t);
    r->packets++;
    if (t != (double)r->packets)
        r->in_order = false;
}

static int listen_local(uint16_t *port)
{
    int s = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t alen = sizeof(a);
    if (s < 0 || bind(s, (struct sockaddr *)&a, sizeof(a)) < 0 || listen(s, 1) < 0 ||
        getsockname(s, (struct sockaddr *)&a, &alen) < 0)
        return -1;
    *port = ntohs(a.sin_port);
    return s;
}

static urrt_link *robot_link(uint16_t port)
{
    urrt_link_config cfg;
    urrt_link_config_defaults(&cfg);
    cfg.host = "127.0.0.1";
    cfg.port = port;
    cfg.silence_timeout_ms = 0; /* a preempted VM is not a lost link: reconnects count losses */
    return urrt_link_new(&cfg);
}

/* One turn of the gateway's loop: wait on both, then serve the robot link
 * and the CAN link, each once. */
static void loop_turn(urrt_link *link, robot_seen *r, urrt_canlink *can, seen *s)
{
    struct pollfd p[2];
    p[0].fd = urrt_link_poll_fd(link, &p[0].events);
    p[1].fd = urrt_canlink_poll_fd(can, &p[1].events);
    poll(p, 2, 50);
    urrt_link_service(link, urrt_port_monotonic_us(), on_packet, r);
    service(can, s);
}

static pid_t flood(const char *id, const char *extra)
{
    const char *argv[] = {"cangen", BUS, "-g", "0", "-I", id, "-L", "8", "-D", "i", extra, NULL};
    return spawn(argv);
}

static void test_flood(void)
{
    seen *s = calloc(1, sizeof(*s));
    urrt_canlink *can = open_rx_link(node_ids, NODE_ID_COUNT, s);
    pid_t theirs = flood("123", NULL), theirs_ext = flood("601", "-e"), ours = flood("601", NULL);
    CHECK(can != NULL && theirs > 0 && theirs_ext > 0 && ours > 0, "link and three cangen floods");
    service_until(can, s, 1); /* the flood is on the bus */
    uint16_t port = 0;
    robot_server rs = {.lsock = listen_local(&port)};
    pthread_t th;
    CHECK(pipe(rs.done) == 0 && pthread_create(&th, NULL, robot, &rs) == 0, "the robot thread");
    urrt_link *link = robot_link(port);
    robot_seen r = {0, true};
    /* Every packet, and the flood filling bursts meanwhile: the bound was tested. */
    uint64_t end = urrt_port_monotonic_us() + 4 * WAIT_LIMIT_US;
    while ((r.packets < ROBOT_PACKETS || s->calls_at_burst < FULL_BURSTS) && urrt_port_monotonic_us() < end)
        loop_turn(link, &r, can, s);
    size_t flood_frames = s->count;
    kill(theirs, SIGTERM), kill(theirs_ext, SIGTERM), kill(ours, SIGTERM);
    waitpid(theirs, NULL, 0), waitpid(theirs_ext, NULL, 0), waitpid(ours, NULL, 0);
    CHECK(write(rs.done[1], "", 1) == 1, "the robot is told to finish");
    pthread_join(th, NULL);
    CHECK_EQ_INT(r.packets, ROBOT_PACKETS);
    CHECK(r.in_order, "robot packets 1..%u in order", ROBOT_PACKETS);
    CHECK_EQ_INT(urrt_link_get_stats(link)->disconnects, 0);
    CHECK_EQ_INT(urrt_link_get_stats(link)->connects, 1);
    CHECK_EQ_INT(s->foreign, 0);
    CHECK(s->max_in_call <= URRT_CANLINK_RX_BURST, "at most the burst per service call (%zu)", s->max_in_call);
    CHECK(s->calls_at_burst >= FULL_BURSTS, "the flood of our id filled bursts (%zu frames, %zu full calls)",
          flood_frames, s->calls_at_burst);
    printf("flood: %zu of our frames handed during %u robot packets, %zu calls at the burst, %llu overflows\n",
           flood_frames, r.packets, s->calls_at_burst,
           (unsigned long long)urrt_canlink_get_stats(can)->rx_overflows);
    urrt_link_free(link);
    urrt_canlink_free(can);
    close(rs.lsock), close(rs.done[0]), close(rs.done[1]);
    free(s);
}

int main(int argc, char **argv)
{
    signal(SIGPIPE, SIG_IGN);
    urrt_log_init("can_rx_test", URRT_LOG_INFO);
    if (argc == 3 && strcmp(argv[1], "clock") == 0) {
        test_clock(argv[2]);
    } else if (argc == 2 && strcmp(argv[1], "rx") == 0) {
        test_refusals();
        test_filter();
        test_burst();
    } else if (argc == 2 && strcmp(argv[1], "flood") == 0) {
        test_flood();
    } else {
        fprintf(stderr, "usage: can_rx_test clock DIR | rx | flood\n");
        return 2;
    }
    return check_report();
}
