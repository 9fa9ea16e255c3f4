/* SPDX-License-Identifier: MIT */
/*
 * bench_gateway: urrt-gateway's latency and CPU cost beside a minimal relay
 * (bench_relay.c: the framer and one lcm_publish of the raw bytes per message,
 * nothing else), its scaling over many robots, and its highest packet rate.
 *
 * This program is the robots and the subscriber at once: it serves 1220-byte
 * packets (lib's urrt_encode, the controller time carrying the packet's index)
 * at 500 Hz on TCP ports taken from the system, and a thread of its own
 * receives the subject's messages on an LCM URL (ttl=0) whose UDP port the
 * system chose, reading LCM's datagrams itself (see subscribe_udp) so that
 * it costs less than what it measures. Latency is from the write of a
 * packet to the receipt of each of its messages; CPU is the subject's (all
 * threads, from /proc/PID/task/TID/schedstat) per packet read, beside how
 * many times the scheduler ran it and the subscriber's reads per packet
 * (counts, where the CPU is a time: they show what the bench did to it).
 * The subject runs on a core of its own, this program on the other
 * (choose_cores).
 *
 *   bench_gateway --gateway PATH --relay PATH [--focused-hz N] [--rounds R]
 *                 [--seconds S] [--max-rate]
 *       Relay and gateway in turn, R rounds (3) of S seconds (4) each, one
 *       robot; prints each subject's figures (median over rounds) and the
 *       ratios gateway/relay (median of the per-round ratios; *_of_best:
 *       the best round's against the best round's).
 *       --focused-hz N: no state message, the focused ones at N Hz (the relay
 *       sends every 500/N-th packet).
 *       --max-rate: then the gateway's highest packet rate.
 *   --no-pin (any mode): leave both cores to the scheduler (see choose_cores).
 *   bench_gateway --gateway PATH --robots N [--focused-hz N] [--seconds S]
 *       One gateway against N robots, every message at every packet, or
 *       the focused ones at N Hz and no state.
 *   bench_gateway --gateway PATH --robots N --versus M [--rounds R] ...
 *       The CPU per packet at M robots against N: R rounds (3) of one
 *       session with N robots and one with M, in turn; prints each round's
 *       ratio and their median. A loop whose cost per wake-up grows with the
 *       robots (a poll over every socket) shows here.
 *
 * Each subject's CPU per packet also gives how many 500 Hz robots one core
 * would serve at that cost: robots_per_core = 1 / (cpu_seconds_per_packet *
 * 500), the core the subject's alone (this program, the robots and the
 * subscriber, runs on another). Measured with 1 robot and with N, since a
 * wake-up serves more packets when more robots send.
 *
 * Prints "name: value" lines; asserts nothing about timings.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "urrt.h"

#define LENGTH 1220
#define LCM_GROUP "239.255.76.67" /* LCM's default group; ttl=0 keeps it on this host */
#define HZ 500
#define WARMUP 250 /* packets per robot not measured */
#define PERIOD_NS (1000000000u / HZ)
#define KINDS 4
#define MAX_ROBOTS 64
#define MAX_ROUNDS 9

static const char *kind_names[KINDS] = {"STATE", "JOINTS", "TOOL", "STATUS"};

/* One session: a subject process against n robots. */
typedef struct {
    int robots;
    long per_robot;        /* packets per robot this session, indexes 1..per_robot */
    bool raw;              /* messages are raw packets (the relay) */
    char prefix[32];       /* channels are PREFIX_R.KIND */
    uint64_t *sent_ns;     /* [robot * (per_robot + 1) + index] */
    double *lat_us[KINDS]; /* measured packets only */
    size_t lat_n[KINDS];
    uint64_t received;     /* every message of a known kind, warm-up included */
    uint64_t late;         /* of an unknown packet or beyond the arrays */
    uint64_t reads;        /* the subscriber's reads that brought datagrams: its wake-ups */
    volatile int stop;
} session;

static uint64_t mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The 500 Hz robots one core serves at this CPU cost per packet. */
static double robots_per_core(double cpu_per_packet_us)
{
    return 1.0 / (cpu_per_packet_us * 1e-6 * HZ);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

static double be_double(const uint8_t *d)
{
    uint64_t bits = 0;
    double t;
    for (int i = 0; i < 8; i++) {
        bits = bits << 8 | d[i];
    }
    memcpy(&t, &bits, sizeof t);
    return t;
}

/* The controller time of a message: the raw packet's first column, or in the
 * gateway's types after fingerprint(8) utime(8); in state after the length(4),
 * doubles(2), generation(1), versions (4-byte length, bytes), present(8) and
 * sequence(8). */
static bool message_time(const session *s, int kind, const uint8_t *d, size_t n, double *t)
{
    size_t off = s->raw ? 4 : 16;
    if (!s->raw && kind == 0) {
        if (n < 27) return false;
        uint32_t slen = (uint32_t)d[23] << 24 | (uint32_t)d[24] << 16 | (uint32_t)d[25] << 8 | d[26];
        off = 27 + (size_t)slen + 16;
    }
    if (off + 8 > n) return false;
    *t = be_double(d + off);
    return true;
}

static void on_message(session *s, const char *channel, const uint8_t *data, size_t size, uint64_t now)
{
    size_t pl = strlen(s->prefix);
    char *end;
    if (strncmp(channel, s->prefix, pl) != 0 || channel[pl] != '_') return;
    long r = strtol(channel + pl + 1, &end, 10);
    if (*end != '.' || r < 0 || r >= s->robots) return;
    int kind = -1;
    for (int k = 0; k < KINDS; k++) {
        if (strcmp(end + 1, kind_names[k]) == 0) kind = k;
    }
    double t;
    if (kind < 0 || !message_time(s, kind, data, size, &t)) return;
    __atomic_store_n(&s->received, s->received + 1, __ATOMIC_RELAXED);
    long index = lrint(t * HZ);
    uint64_t sent = 0;
    if (index >= 1 && index <= s->per_robot) {
        sent = __atomic_load_n(&s->sent_ns[(size_t)r * (size_t)(s->per_robot + 1) + (size_t)index], __ATOMIC_ACQUIRE);
    }
    if (sent == 0) {
        s->late++;
        return;
    }
    if (index > WARMUP) {
        s->lat_us[kind][s->lat_n[kind]++] = (double)(now - sent) / 1000.0;
    }
}

/*
 * The subscriber reads LCM's UDP multicast protocol itself: a datagram of one
 * message is "LC02", a sequence number and the channel's name ending in a
 * NUL, then the message; recvmmsg takes up to BATCH at a time. liblcm's
 * lcm_handle makes two system calls per message, which at 50 robots (over
 * 100 000 messages a second) took a core of this machine, more than the
 * subject it measured.
 */
#define LCM_SHORT_MAGIC 0x4C433032u
#define BATCH 64
#define DATAGRAM 65536

static int subscribe_udp(const char *group, uint16_t port)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0), one = 1, buf = 8 << 20;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(port), .sin_addr.s_addr = htonl(INADDR_ANY)};
    struct ip_mreq m = {.imr_interface.s_addr = htonl(INADDR_ANY)};
    inet_pton(AF_INET, group, &m.imr_multiaddr);
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    /* A second of messages at 50 robots, whatever net.core.rmem_max says
     * (the FORCE variant needs root; the plain one is capped). */
    if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &buf, sizeof buf) != 0) {
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buf, sizeof buf);
    }
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m) != 0) {
        perror("bench_gateway: subscribe");
        exit(1);
    }
    return fd;
}

typedef struct {
    int fd;
    session *s;
} sub_arg;

static void *subscriber(void *arg)
{
    sub_arg *a = arg;
    static uint8_t bufs[BATCH][DATAGRAM];
    struct iovec iov[BATCH];
    struct mmsghdr msgs[BATCH];
    for (int i = 0; i < BATCH; i++) {
        iov[i] = (struct iovec){.iov_base = bufs[i], .iov_len = DATAGRAM - 1};
        msgs[i] = (struct mmsghdr){.msg_hdr = {.msg_iov = &iov[i], .msg_iovlen = 1}};
    }
    while (!__atomic_load_n(&a->s->stop, __ATOMIC_ACQUIRE)) {
        struct pollfd p = {.fd = a->fd, .events = POLLIN};
        if (poll(&p, 1, 20) != 1) continue;
        int n = recvmmsg(a->fd, msgs, BATCH, MSG_DONTWAIT, NULL);
        uint64_t now = mono_ns();
        a->s->reads += n > 0;
        for (int i = 0; i < n; i++) {
            uint8_t *d = bufs[i];
            size_t len = msgs[i].msg_len;
            d[len] = 0; /* the channel ends before the end */
            size_t name = strnlen((char *)d + 8, len > 8 ? len - 8 : 0);
            uint32_t magic = (uint32_t)d[0] << 24 | (uint32_t)d[1] << 16 | (uint32_t)d[2] << 8 | d[3];
            if (len < 9 || magic != LCM_SHORT_MAGIC || 8 + name >= len) continue;
            on_message(a->s, (char *)d + 8, d + 9 + name, len - 9 - name, now);
        }
    }
    return NULL;
}

/* CPU time of every thread of pid, in ns, and how many times the scheduler
 * ran one of them (schedstat's third field: its wake-ups, near enough). */
typedef struct {
    uint64_t ns, runs;
} task_time;

static task_time task_times(pid_t pid)
{
    char path[64];
    task_time sum = {0, 0};
    snprintf(path, sizeof path, "/proc/%d/task", (int)pid);
    DIR *dir = opendir(path);
    if (dir == NULL) {
        return sum;
    }
    for (struct dirent *e; (e = readdir(dir)) != NULL;) {
        char p[320];
        unsigned long long run = 0, wait = 0, runs = 0;
        if (e->d_name[0] == '.') continue;
        snprintf(p, sizeof p, "/proc/%d/task/%s/schedstat", (int)pid, e->d_name);
        FILE *f = fopen(p, "r");
        if (f != NULL) {
            if (fscanf(f, "%llu %llu %llu", &run, &wait, &runs) == 3) {
                sum.ns += run;
                sum.runs += runs;
            }
            fclose(f);
        }
    }
    closedir(dir);
    return sum;
}

static uint64_t cpu_ns(pid_t pid)
{
    return task_times(pid).ns;
}

/* This process's CPU time (every thread), in ns. */
static uint64_t self_cpu_ns(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ((uint64_t)ru.ru_utime.tv_sec + (uint64_t)ru.ru_stime.tv_sec) * 1000000000u +
           ((uint64_t)ru.ru_utime.tv_usec + (uint64_t)ru.ru_stime.tv_usec) * 1000u;
}

static int listen_any(uint16_t *port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t al = sizeof a;
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 || listen(fd, 4) != 0 ||
        getsockname(fd, (struct sockaddr *)&a, &al) != 0) {
        perror("bench_gateway: listen");
        exit(1);
    }
    *port = ntohs(a.sin_port);
    return fd;
}

/* A UDP port the system is not using now, for the LCM multicast group. */
static uint16_t free_udp_port(void)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET};
    socklen_t al = sizeof a;
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 || getsockname(fd, (struct sockaddr *)&a, &al) != 0) {
        perror("bench_gateway: udp port");
        exit(1);
    }
    close(fd);
    return ntohs(a.sin_port);
}

static void make_packet(uint8_t *out, long index)
{
    static urrt_state st;
    static int ready;
    if (!ready) {
        urrt_state_clear(&st);
        double *p = (double *)(void *)&st;
        for (unsigned c = 0; c < URRT_WIRE_COLUMNS; c++) p[c] = 0.25 * c;
        st.robot_mode[0] = 7;
        st.safety_mode[0] = 1;
        st.program_state[0] = 2;
        for (int j = 0; j < 6; j++) st.joint_modes[j] = 253;
        st.digital_input_bits[0] = 5;
        st.digital_outputs[0] = 3;
        ready = 1;
    }
    /* A 500 Hz controller's clock: the gateway holds it against its own to
     * tell a backlog from fresh packets, and it gives back the index. */
    st.time[0] = (double)index / HZ;
    urrt_encode(&st, LENGTH, out, LENGTH);
}

/* Loopback TCP write-to-read with nothing in between. */
static double baseline_us(void)
{
    uint8_t buf[LENGTH];
    double v[2000];
    uint16_t port;
    int lfd = listen_any(&port), one = 1, sv[2];
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(port), .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    sv[0] = socket(AF_INET, SOCK_STREAM, 0);
    connect(sv[0], (struct sockaddr *)&a, sizeof a);
    sv[1] = accept(lfd, NULL, NULL);
    setsockopt(sv[0], IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    make_packet(buf, 0);
    for (int i = 0; i < 2000; i++) {
        uint64_t t0 = mono_ns();
        if (write(sv[0], buf, LENGTH) != LENGTH) break;
        size_t got = 0;
        while (got < LENGTH) {
            ssize_t r = read(sv[1], buf + got, LENGTH - got);
            if (r <= 0) break;
            got += (size_t)r;
        }
        v[i] = (double)(mono_ns() - t0) / 1000.0;
    }
    close(sv[0]);
    close(sv[1]);
    close(lfd);
    return median(v, 2000);
}

/* What a session measured. */
typedef struct {
    double cpu_per_packet_us, cpu_percent;
    double runs_per_packet; /* times the scheduler ran the subject: its wake-ups */
    double sub_reads_per_packet; /* the subscriber's wake-ups (all packets, warm-up included) */
    double self_cpu_percent; /* this program: the robots and the subscriber */
    double median_us[KINDS], p99_us[KINDS], max_us[KINDS];
    size_t messages[KINDS];
    uint64_t expected, received; /* messages of the measured packets (past the warm-up) */
    uint64_t warmup_lost, late;
    long packets; /* measured, all robots */
} result;

typedef struct {
    const char *path;  /* urrt-gateway or bench_relay */
    bool relay;
    int robots;
    double seconds;
    const char *focused_hz; /* NULL: every message at every packet */
} subject;

/* The cores: this program (robots, subscriber) on the first this process may
 * use, the subject on the last, each alone. Left to the scheduler, they
 * shared both cores as it chose, round by round: the subscriber, woken by
 * each message, preempted the subject where they met on a core, and the
 * subject ran 1.7-2.9 times a packet where once is its work, the same
 * binary's CPU 0.9 to 2.2 times the relay's from one run to the next.
 * Pinned, both run once a packet. -1: one core only, nothing pinned. */
static int bench_core = -1, subject_core = -1;

static void choose_cores(void)
{
    cpu_set_t allowed;
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0 || CPU_COUNT(&allowed) < 2) {
        return;
    }
    for (int c = 0; c < CPU_SETSIZE; c++) {
        if (CPU_ISSET(c, &allowed)) {
            if (bench_core < 0) bench_core = c;
            subject_core = c;
        }
    }
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(bench_core, &one);
    if (sched_setaffinity(0, sizeof one, &one) != 0) {
        perror("bench_gateway: sched_setaffinity");
        exit(1);
    }
}

/* In a subject's child, before exec. */
static void pin_subject(void)
{
    if (subject_core >= 0) {
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(subject_core, &one);
        if (sched_setaffinity(0, sizeof one, &one) != 0) {
            dprintf(2, "bench_gateway: cannot pin the subject to core %d: %s (--no-pin runs without)\n",
                    subject_core, strerror(errno));
            _exit(126);
        }
    }
}

static pid_t start_gateway(const subject *sj, const char *url, const char *prefix, const uint16_t *ports, char *ini)
{
    int ifd = mkstemp(ini);
    if (sj->focused_hz == NULL) {
        dprintf(ifd, "[lcm]\nurl = %s\nstate_rate = every\njoints_rate = every\ntool_rate = every\n"
                     "status_rate = every\n", url);
    } else {
        dprintf(ifd, "[lcm]\nurl = %s\nstate_rate = off\njoints_rate = %s Hz\ntool_rate = %s Hz\n"
                     "status_rate = %s Hz\n", url, sj->focused_hz, sj->focused_hz, sj->focused_hz);
    }
    dprintf(ifd, "gateway_rate = 1 Hz\n");
    for (int r = 0; r < sj->robots; r++) {
        dprintf(ifd, "[robot %s_%d]\nhost = 127.0.0.1\nport = %u\nsilence_timeout = 2 s\n", prefix, r, ports[r]);
    }
    close(ifd);
    pid_t pid = fork();
    if (pid == 0) {
        pin_subject();
        execl(sj->path, sj->path, "--log-level", "warning", ini, (char *)NULL);
        _exit(127);
    }
    return pid;
}

static pid_t start_relay(const subject *sj, const char *url, const char *prefix, uint16_t port)
{
    char ports[8], every[16], chan[48];
    snprintf(ports, sizeof ports, "%u", port);
    snprintf(every, sizeof every, "%d", sj->focused_hz == NULL ? 1 : HZ / atoi(sj->focused_hz));
    snprintf(chan, sizeof chan, "%s_0", prefix);
    pid_t pid = fork();
    if (pid == 0) {
        pin_subject();
        if (sj->focused_hz == NULL) {
            execl(sj->path, sj->path, "127.0.0.1", ports, url, chan, every, "STATE", "JOINTS", "TOOL", "STATUS",
                  (char *)NULL);
        } else {
            execl(sj->path, sj->path, "127.0.0.1", ports, url, chan, every, "JOINTS", "TOOL", "STATUS", (char *)NULL);
        }
        _exit(127);
    }
    return pid;
}

static void summarize(session *s, result *res)
{
    for (int k = 0; k < KINDS; k++) {
        size_t n = s->lat_n[k];
        res->messages[k] = n;
        if (n == 0) continue;
        qsort(s->lat_us[k], n, sizeof(double), cmp_double);
        res->median_us[k] = s->lat_us[k][n / 2];
        res->p99_us[k] = s->lat_us[k][(size_t)((double)n * 0.99)];
        res->max_us[k] = s->lat_us[k][n - 1];
    }
    res->received = 0;
    for (int k = 0; k < KINDS; k++) res->received += res->messages[k];
    res->late = s->late;
}

#define INI_TEMPLATE "/tmp/bench-gateway-XXXXXX"

/* A run's subject process and its connections. */
typedef struct {
    pid_t pid;
    int sub_fd;                         /* the LCM subscriber's socket */
    int lfd[MAX_ROBOTS], cfd[MAX_ROBOTS]; /* each robot's listener and its connection */
    char ini[sizeof INI_TEMPLATE];      /* the gateway's configuration, mkstemp's template */
} subject_run;

/* Where the CPU and wall clocks stood when the measured packets began. */
typedef struct {
    task_time cpu;
    uint64_t self, wall;
} clocks;

/* The session's arrays and channel prefix, for sj against n robots. */
static void session_open(session *s, const subject *sj, int n)
{
    static unsigned serial;
    s->per_robot = WARMUP + (long)(sj->seconds * HZ);
    s->sent_ns = calloc((size_t)n * (size_t)(s->per_robot + 1), sizeof *s->sent_ns);
    for (int k = 0; k < KINDS; k++) s->lat_us[k] = calloc((size_t)n * (size_t)s->per_robot, sizeof(double));
    snprintf(s->prefix, sizeof s->prefix, "b%d_%u", (int)getpid(), serial++);
}

/* Subscribes, starts the subject and accepts its connection to each robot;
 * false (the subject stopped) if one does not come within 5 s. */
static bool subject_start(const subject *sj, const session *s, subject_run *sr)
{
    uint16_t ports[MAX_ROBOTS];
    char url[96];
    int n = sj->robots;
    uint16_t udp_port = free_udp_port();
    snprintf(url, sizeof url, "udpm://%s:%u?ttl=0", LCM_GROUP, udp_port);
    sr->sub_fd = subscribe_udp(LCM_GROUP, udp_port);
    for (int r = 0; r < n; r++) sr->lfd[r] = listen_any(&ports[r]);
    sr->pid = sj->relay ? start_relay(sj, url, s->prefix, ports[0]) : start_gateway(sj, url, s->prefix, ports, sr->ini);
    for (int r = 0; r < n; r++) {
        struct pollfd pl = {.fd = sr->lfd[r], .events = POLLIN};
        sr->cfd[r] = poll(&pl, 1, 5000) == 1 ? accept(sr->lfd[r], NULL, NULL) : -1;
        if (sr->cfd[r] < 0) {
            fprintf(stderr, "bench_gateway: %s did not connect\n", sj->path);
            kill(sr->pid, SIGTERM);
            waitpid(sr->pid, NULL, 0);
            return false;
        }
        int one = 1;
        setsockopt(sr->cfd[r], IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    return true;
}

/* Every robot's packets at 500 Hz; the clocks as the measured ones begin. */
static clocks send_packets(session *s, const subject_run *sr, int n)
{
    uint8_t pkt[LENGTH];
    clocks at = {{0, 0}, 0, 0};
    uint64_t start = mono_ns();
    size_t row = (size_t)(s->per_robot + 1);
    for (long index = 1; index <= s->per_robot; index++) {
        if (index == WARMUP + 1) {
            at.cpu = task_times(sr->pid);
            at.self = self_cpu_ns();
            at.wall = mono_ns();
        }
        make_packet(pkt, index);
        for (int r = 0; r < n; r++) {
            /* Robots are controllers with clocks of their own: their
             * packets come spread over the period, not all at once. */
            uint64_t due = start + (uint64_t)index * PERIOD_NS + (uint64_t)r * PERIOD_NS / (uint64_t)n;
            uint64_t now = mono_ns();
            if (now < due) {
                struct timespec ts = {.tv_sec = 0, .tv_nsec = (long)(due - now)};
                nanosleep(&ts, NULL);
            }
            __atomic_store_n(&s->sent_ns[(size_t)r * row + (size_t)index], mono_ns(), __ATOMIC_RELEASE);
            if (write(sr->cfd[r], pkt, LENGTH) != LENGTH) {
                fprintf(stderr, "bench_gateway: write: %s\n", strerror(errno));
                exit(1);
            }
        }
    }
    return at;
}

/* Waits until the subscriber has all messages (all 0: unknown) or a second has passed. */
static void await_messages(session *s, uint64_t all)
{
    for (uint64_t end = mono_ns() + 1000000000u; mono_ns() < end;) {
        if (all != 0 && __atomic_load_n(&s->received, __ATOMIC_RELAXED) >= all) break;
        struct timespec ts = {.tv_sec = 0, .tv_nsec = 1000000};
        nanosleep(&ts, NULL);
    }
}

/* Stops the subject and the subscriber thread, closes every socket. */
static void subject_stop(const subject *sj, session *s, subject_run *sr, pthread_t th)
{
    kill(sr->pid, SIGTERM);
    waitpid(sr->pid, NULL, 0);
    for (int r = 0; r < sj->robots; r++) {
        close(sr->cfd[r]);
        close(sr->lfd[r]);
    }
    __atomic_store_n(&s->stop, 1, __ATOMIC_RELEASE);
    pthread_join(th, NULL);
    close(sr->sub_fd);
    if (!sj->relay) unlink(sr->ini);
}

/* Serve sj->robots robots at 500 Hz for warm-up + seconds; false if the
 * subject did not connect. */
static bool run(const subject *sj, result *res)
{
    session s = {.robots = sj->robots, .raw = sj->relay};
    subject_run sr = {.ini = INI_TEMPLATE};
    int n = sj->robots;

    memset(res, 0, sizeof *res);
    session_open(&s, sj, n);
    if (!subject_start(sj, &s, &sr)) return false;
    pthread_t th;
    sub_arg sa = {sr.sub_fd, &s};
    pthread_create(&th, NULL, subscriber, &sa);

    clocks at = send_packets(&s, &sr, n);
    /* Every message is in once the subject's CPU stops moving and the
     * subscriber has them all, or after a second at most. */
    task_time cpu1 = task_times(sr.pid);
    uint64_t self1 = self_cpu_ns(), wall1 = mono_ns();
    res->packets = (long)(s.per_robot - WARMUP) * n;
    uint64_t all = sj->focused_hz == NULL ? (uint64_t)s.per_robot * (uint64_t)n * KINDS : 0;
    res->expected = sj->focused_hz == NULL ? (uint64_t)res->packets * KINDS : 0;
    await_messages(&s, all);
    subject_stop(sj, &s, &sr, th);
    res->cpu_per_packet_us = (double)(cpu1.ns - at.cpu.ns) / 1000.0 / (double)res->packets;
    res->runs_per_packet = (double)(cpu1.runs - at.cpu.runs) / (double)res->packets;
    res->sub_reads_per_packet = (double)s.reads / (double)(s.per_robot * n);
    res->cpu_percent = 100.0 * (double)(cpu1.ns - at.cpu.ns) / (double)(wall1 - at.wall);
    res->self_cpu_percent = 100.0 * (double)(self1 - at.self) / (double)(wall1 - at.wall);
    summarize(&s, res);
    /* A connection's first packets may come as a burst, which the gateway
     * does not publish (their age cannot be judged): counted apart. */
    uint64_t warmup_received = s.received - res->received;
    res->warmup_lost = all - res->expected > warmup_received ? all - res->expected - warmup_received : 0;
    free(s.sent_ns);
    for (int k = 0; k < KINDS; k++) free(s.lat_us[k]);
    return true;
}

static void lower(char *out, const char *in)
{
    for (; *in; in++) *out++ = (char)(*in >= 'A' && *in <= 'Z' ? *in - 'A' + 'a' : *in);
    *out = 0;
}

static void print_latency(const char *who, const result *res)
{
    for (int k = 0; k < KINDS; k++) {
        char name[16];
        lower(name, kind_names[k]);
        if (res->messages[k] == 0) continue;
        printf("%s%s_latency_median_us: %.1f\n", who, name, res->median_us[k]);
        printf("%s%s_latency_p99_us: %.1f\n", who, name, res->p99_us[k]);
        printf("%s%s_latency_max_us: %.1f\n", who, name, res->max_us[k]);
        printf("%s%s_messages: %zu\n", who, name, res->messages[k]);
    }
}

/* Figures across rounds: the median of each. */
static double med_of(const result *r, int rounds, size_t offset)
{
    double v[MAX_ROUNDS];
    for (int i = 0; i < rounds; i++) v[i] = *(const double *)(const void *)((const char *)&r[i] + offset);
    return median(v, rounds);
}

static double med_ratio(const result *g, const result *rl, int rounds, size_t offset)
{
    double v[MAX_ROUNDS];
    for (int i = 0; i < rounds; i++) {
        v[i] = *(const double *)(const void *)((const char *)&g[i] + offset) /
               *(const double *)(const void *)((const char *)&rl[i] + offset);
    }
    return median(v, rounds);
}

/* The best round's figure of the gateway against the relay's best: what
 * the rounds that other work on the machine disturbed least say (the
 * disturbance only adds), steadier than the median of the rounds' ratios. */
static double best_ratio(const result *g, const result *rl, int rounds, size_t offset)
{
    double best_g = INFINITY, best_rl = INFINITY;
    for (int i = 0; i < rounds; i++) {
        best_g = fmin(best_g, *(const double *)(const void *)((const char *)&g[i] + offset));
        best_rl = fmin(best_rl, *(const double *)(const void *)((const char *)&rl[i] + offset));
    }
    return best_g / best_rl;
}

static void print_subject(const char *who, const result *r, int rounds)
{
    result m = r[0];
    m.cpu_per_packet_us = med_of(r, rounds, offsetof(result, cpu_per_packet_us));
    m.cpu_percent = med_of(r, rounds, offsetof(result, cpu_percent));
    m.runs_per_packet = med_of(r, rounds, offsetof(result, runs_per_packet));
    m.sub_reads_per_packet = med_of(r, rounds, offsetof(result, sub_reads_per_packet));
    for (int k = 0; k < KINDS; k++) {
        m.median_us[k] = med_of(r, rounds, offsetof(result, median_us) + (size_t)k * sizeof(double));
        m.p99_us[k] = med_of(r, rounds, offsetof(result, p99_us) + (size_t)k * sizeof(double));
        m.max_us[k] = med_of(r, rounds, offsetof(result, max_us) + (size_t)k * sizeof(double));
    }
    printf("%scpu_per_packet_us: %.2f\n", who, m.cpu_per_packet_us);
    printf("%srobots_per_core: %.0f\n", who, robots_per_core(m.cpu_per_packet_us));
    printf("%scpu_percent_of_core_at_500hz: %.3f\n", who, m.cpu_percent);
    printf("%sruns_per_packet: %.3f\n", who, m.runs_per_packet);
    printf("%ssubscriber_reads_per_packet: %.3f\n", who, m.sub_reads_per_packet);
    for (int i = 0; i < rounds; i++) {
        printf("%sround_%d_cpu_per_packet_us: %.2f\n", who, i + 1, r[i].cpu_per_packet_us);
    }
    print_latency(who, &m);
    uint64_t lost = 0;
    for (int i = 0; i < rounds; i++) {
        lost += r[i].expected > r[i].received ? r[i].expected - r[i].received : 0;
    }
    if (r[0].expected != 0) printf("%smessages_lost: %llu\n", who, (unsigned long long)lost);
}

static void compare(subject *gw, subject *relay, int rounds)
{
    result g[MAX_ROUNDS], rl[MAX_ROUNDS];
    for (int i = 0; i < rounds; i++) {
        if (!run(relay, &rl[i]) || !run(gw, &g[i])) exit(1);
    }
    printf("rounds: %d\n", rounds);
    printf("packets_at_500hz_per_round: %ld\n", g[0].packets);
    print_subject("relay_", rl, rounds);
    print_subject("gateway_", g, rounds);
    printf("gateway_cpu_vs_relay: %.2f\n", med_ratio(g, rl, rounds, offsetof(result, cpu_per_packet_us)));
    printf("gateway_cpu_vs_relay_of_best: %.2f\n", best_ratio(g, rl, rounds, offsetof(result, cpu_per_packet_us)));
    printf("gateway_runs_vs_relay: %.2f\n", med_ratio(g, rl, rounds, offsetof(result, runs_per_packet)));
    for (int k = 0; k < KINDS; k++) {
        char name[16];
        lower(name, kind_names[k]);
        if (g[0].messages[k] == 0 || rl[0].messages[k] == 0) continue;
        printf("%s_latency_median_vs_relay: %.2f\n", name,
               med_ratio(g, rl, rounds, offsetof(result, median_us) + (size_t)k * sizeof(double)));
        printf("%s_latency_median_vs_relay_of_best: %.2f\n", name,
               best_ratio(g, rl, rounds, offsetof(result, median_us) + (size_t)k * sizeof(double)));
        printf("%s_latency_p99_vs_relay: %.2f\n", name,
               med_ratio(g, rl, rounds, offsetof(result, p99_us) + (size_t)k * sizeof(double)));
    }
}

static void scaling(subject *gw)
{
    result r;
    if (!run(gw, &r)) exit(1);
    char who[32];
    /* "decimated_" as the rule's sed names the focused comparison. */
    snprintf(who, sizeof who, "%srobots_%d_", gw->focused_hz != NULL ? "decimated_" : "", gw->robots);
    printf("%spackets: %ld\n", who, r.packets);
    printf("%scpu_per_packet_us: %.2f\n", who, r.cpu_per_packet_us);
    printf("%srobots_per_core: %.0f\n", who, robots_per_core(r.cpu_per_packet_us));
    printf("%scpu_percent_of_core: %.1f\n", who, r.cpu_percent);
    printf("%sruns_per_packet: %.3f\n", who, r.runs_per_packet);
    printf("%sbench_cpu_percent_of_core: %.1f\n", who, r.self_cpu_percent);
    print_latency(who, &r);
    /* All kinds together: the robots' worst message. */
    double worst = 0;
    for (int k = 0; k < KINDS; k++) worst = r.p99_us[k] > worst ? r.p99_us[k] : worst;
    printf("%sworst_kind_latency_p99_us: %.1f\n", who, worst);
    if (gw->focused_hz != NULL) { /* decimated: no count to hold them to */
        printf("%smessages_received: %llu\n", who, (unsigned long long)r.received);
        return;
    }
    printf("%smessages_expected: %llu\n", who, (unsigned long long)r.expected);
    printf("%smessages_received: %llu\n", who, (unsigned long long)r.received);
    printf("%smessages_lost: %llu\n", who, (unsigned long long)(r.expected > r.received ? r.expected - r.received : 0));
    printf("%swarmup_messages_lost: %llu\n", who, (unsigned long long)r.warmup_lost);
}

/* The CPU per packet at vs->robots against gw->robots, round by round. */
static void versus(subject *gw, subject *vs, int rounds)
{
    double ratio[MAX_ROUNDS], base[MAX_ROUNDS], other[MAX_ROUNDS];
    char who[48];
    snprintf(who, sizeof who, "%srobots_%d_vs_%d_", gw->focused_hz != NULL ? "decimated_" : "", vs->robots,
             gw->robots);
    for (int i = 0; i < rounds; i++) {
        result a, b;
        if (!run(gw, &a) || !run(vs, &b)) exit(1);
        base[i] = a.cpu_per_packet_us;
        other[i] = b.cpu_per_packet_us;
        ratio[i] = b.cpu_per_packet_us / a.cpu_per_packet_us;
        printf("%sround_%d_cpu_per_packet_us: %.2f vs %.2f (%.2fx)\n", who, i + 1, other[i], base[i], ratio[i]);
        printf("%sround_%d_runs_per_packet: %.3f vs %.3f\n", who, i + 1, b.runs_per_packet, a.runs_per_packet);
    }
    printf("%scpu_per_packet_us_median: %.2f vs %.2f\n", who, median(other, rounds), median(base, rounds));
    double m = median(ratio, rounds);
    printf("%scpu_per_packet_ratio: %.2f\n", who, m);
    printf("bench-gateway: %s%d robots vs %d: per-packet cost %.2fx (median of %d rounds)\n",
           gw->focused_hz != NULL ? "focused messages, " : "", vs->robots, gw->robots, m, rounds);
}

/* As fast as the gateway takes packets: TCP back-pressure paces the writes,
 * so the rate written is the rate the gateway reads. Nobody subscribes. */
static void max_rate(const subject *sj)
{
    uint16_t port;
    int lfd = listen_any(&port);
    char url[96], ini[] = "/tmp/bench-gateway-XXXXXX", prefix[32];
    snprintf(url, sizeof url, "udpm://%s:%u?ttl=0", LCM_GROUP, free_udp_port());
    snprintf(prefix, sizeof prefix, "b%d_max", (int)getpid());
    pid_t pid = start_gateway(sj, url, prefix, &port, ini);
    struct pollfd pl = {.fd = lfd, .events = POLLIN};
    int cfd = poll(&pl, 1, 5000) == 1 ? accept(lfd, NULL, NULL) : -1;
    if (cfd < 0) {
        fprintf(stderr, "bench_gateway: the gateway did not connect\n");
        exit(1);
    }
    fcntl(cfd, F_SETFL, fcntl(cfd, F_GETFL) | O_NONBLOCK);
    /* Packets whose times keep increasing, so that decimation and the age
     * estimator see a live stream. */
    enum { BURST = 4096 };
    static uint8_t burst[BURST * LENGTH];
    long next_index = 1;
    for (int i = 0; i < BURST; i++) make_packet(burst + (size_t)i * LENGTH, next_index++);
    uint64_t t0 = mono_ns(), mark_t = 0, written = 0, mark_w = 0, cpu_mark = 0;
    size_t off = 0;
    while (mono_ns() - t0 < 3000000000u) {
        struct pollfd p = {.fd = cfd, .events = POLLOUT};
        if (poll(&p, 1, 100) != 1) continue;
        ssize_t w = write(cfd, burst + off, sizeof burst - off);
        if (w > 0) {
            written += (uint64_t)w;
            off += (size_t)w;
            if (off == sizeof burst) {
                off = 0;
                for (int i = 0; i < BURST; i++) make_packet(burst + (size_t)i * LENGTH, next_index++);
            }
        } else if (w < 0 && errno != EAGAIN) {
            fprintf(stderr, "bench_gateway: blast write: %s\n", strerror(errno));
            break;
        }
        if (mark_t == 0 && mono_ns() - t0 >= 1000000000u) {
            mark_t = mono_ns();
            mark_w = written;
            cpu_mark = cpu_ns(pid);
        }
    }
    uint64_t t1 = mono_ns(), cpu_end = cpu_ns(pid);
    double rate = (double)(written - mark_w) / LENGTH / ((double)(t1 - mark_t) / 1e9);
    printf("max_rate_packets_per_s: %.0f\n", rate);
    printf("gateway_cpu_percent_of_core_at_max_rate: %.1f\n", 100.0 * (double)(cpu_end - cpu_mark) / (double)(t1 - mark_t));
    printf("max_rate_vs_500hz: %.0f\n", rate / HZ);
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    printf("gateway_exit_status: %d\n", WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
    close(cfd);
    close(lfd);
    unlink(ini);
}

int main(int argc, char **argv)
{
    /* Sleeps of tens of microseconds between robots' packets: no 50 us slack. */
    prctl(PR_SET_TIMERSLACK, 1000UL);
    subject gw = {.robots = 0, .seconds = 4}, relay = {.relay = true, .robots = 1};
    int rounds = 3, versus_robots = 0;
    bool max = false, pin = true;
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : "";
        if (strcmp(argv[i], "--gateway") == 0) gw.path = argv[++i];
        else if (strcmp(argv[i], "--relay") == 0) relay.path = argv[++i];
        else if (strcmp(argv[i], "--seconds") == 0) gw.seconds = atof(v), i++;
        else if (strcmp(argv[i], "--focused-hz") == 0) gw.focused_hz = argv[++i];
        else if (strcmp(argv[i], "--rounds") == 0) rounds = atoi(v), i++;
        else if (strcmp(argv[i], "--robots") == 0) gw.robots = atoi(v), i++;
        else if (strcmp(argv[i], "--versus") == 0) versus_robots = atoi(v), i++;
        else if (strcmp(argv[i], "--max-rate") == 0) max = true;
        else if (strcmp(argv[i], "--no-pin") == 0) pin = false;
    }
    bool scale = gw.robots > 0;
    if (gw.path == NULL || (!scale && relay.path == NULL) || gw.robots > MAX_ROBOTS || rounds < 1 ||
        versus_robots < 0 || versus_robots > MAX_ROBOTS || (versus_robots > 0 && !scale) ||
        rounds > MAX_ROUNDS || (gw.focused_hz != NULL && (atoi(gw.focused_hz) < 1 || HZ % atoi(gw.focused_hz)))) {
        fprintf(stderr, "usage: bench_gateway --gateway PATH (--relay PATH [--rounds R] [--max-rate] | --robots N "
                        "[--versus M [--rounds R]]) [--focused-hz N] [--seconds S]\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    if (pin) choose_cores();
    printf("bench_core: %d\nsubject_core: %d\n", bench_core, subject_core);
    relay.seconds = gw.seconds;
    relay.focused_hz = gw.focused_hz;
    if (scale && versus_robots > 0) {
        subject vs = gw;
        vs.robots = versus_robots;
        versus(&gw, &vs, rounds);
        return 0;
    }
    if (scale) {
        scaling(&gw);
        return 0;
    }
    gw.robots = 1;
    printf("baseline_tcp_loopback_median_us: %.1f\n", baseline_us());
    compare(&gw, &relay, rounds);
    if (max) max_rate(&gw);
    return 0;
}
