/* SPDX-License-Identifier: MIT */
/*
 * bench_gateway: urrt-gateway beside a minimal relay (bench_relay.c: the
 * framer, or lib's RTDE client, and one lcm_publish of the raw bytes per
 * message, nothing else): first what a packet costs in counts that do not
 * depend on the machine's load (--counts: user-space instructions from
 * valgrind's cachegrind, system calls from strace -c, RealTime and RTDE, at
 * 1, 10 and 50 robots); then its latency and CPU time, its scaling over many
 * robots, and its highest packet rate.
 *
 *   bench_gateway --counts --gateway PATH --relay PATH --sim URRT-SIM
 *                 --count-robots N[,N...] [--count-packets P] [--keep DIR]
 *                 [--top K]
 *       For RealTime and then RTDE (urrt-sim --rtde doing the handshake),
 *       at each robot count, relay and gateway: instructions and system
 *       calls per packet (each system call by name), P packets (1000) in
 *       all robots beyond a short session's (see "counts" below); the
 *       gateway's K (8) costliest functions per packet; the goals (system
 *       calls at most the relay's + 0.1; instructions at the most robots
 *       within 1.1x of those at the fewest). --keep DIR keeps the tools'
 *       files (cg_annotate, cg_diff read the cachegrind ones).
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
 * Prints "name: value" lines; asserts nothing about timings (nor about
 * counts: goals are printed met or NOT met).
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
#include <sys/stat.h>
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

/* A packet whose time column is t seconds (a 500 Hz controller's clock). */
static void make_packet_at(uint8_t *out, double t)
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
    st.time[0] = t;
    urrt_encode(&st, LENGTH, out, LENGTH);
}

static void make_packet(uint8_t *out, long index)
{
    /* A 500 Hz controller's clock: the gateway holds it against its own to
     * tell a backlog from fresh packets, and it gives back the index. */
    make_packet_at(out, (double)index / HZ);
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
    bool rtde;              /* source = rtde (the relay: --rtde) */
    const char *gateway_rate; /* the gateway's GATEWAY reports; NULL: 1 Hz */
    const char *const *tool; /* run under this tool's argv (counts); NULL: none */
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

/* Starts argv under tool (the tool's own argv, NULL-terminated, before the
 * subject's; NULL: none), pinned to the subject's core. */
static pid_t spawn(const char *const *tool, char *const *argv)
{
    char *all[MAX_ROBOTS + 40];
    int n = 0;
    for (; tool != NULL && tool[n] != NULL; n++) all[n] = (char *)(uintptr_t)tool[n];
    for (int i = 0; argv[i] != NULL; i++) all[n++] = argv[i];
    all[n] = NULL;
    pid_t pid = fork();
    if (pid == 0) {
        pin_subject();
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        execvp(all[0], all);
        dprintf(2, "bench_gateway: %s: %s\n", all[0], strerror(errno));
        _exit(127);
    }
    return pid;
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
    dprintf(ifd, "gateway_rate = %s\n", sj->gateway_rate != NULL ? sj->gateway_rate : "1 Hz");
    for (int r = 0; r < sj->robots; r++) {
        dprintf(ifd, "[robot %s_%d]\nhost = 127.0.0.1\nport = %u\nsilence_timeout = 2 s\n%s", prefix, r, ports[r],
                sj->rtde ? "source = rtde\n" : "");
    }
    close(ifd);
    char *argv[] = {(char *)(uintptr_t)sj->path, "--log-level", "warning", ini, NULL};
    return spawn(sj->tool, argv);
}

static pid_t start_relay(const subject *sj, const char *url, const char *prefix, const uint16_t *ports)
{
    char every[16], port_s[MAX_ROBOTS][8];
    char *argv[MAX_ROBOTS + 10];
    int a = 0;
    snprintf(every, sizeof every, "%d", sj->focused_hz == NULL ? 1 : HZ / atoi(sj->focused_hz));
    argv[a++] = (char *)(uintptr_t)sj->path;
    if (sj->rtde) argv[a++] = "--rtde";
    argv[a++] = "127.0.0.1";
    argv[a++] = (char *)(uintptr_t)url;
    argv[a++] = (char *)(uintptr_t)prefix;
    argv[a++] = every;
    argv[a++] = sj->focused_hz == NULL ? "STATE,JOINTS,TOOL,STATUS" : "JOINTS,TOOL,STATUS";
    for (int r = 0; r < sj->robots; r++) {
        snprintf(port_s[r], sizeof port_s[r], "%u", ports[r]);
        argv[a++] = port_s[r];
    }
    argv[a] = NULL;
    return spawn(sj->tool, argv);
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
    sr->pid = sj->relay ? start_relay(sj, url, s->prefix, ports) : start_gateway(sj, url, s->prefix, ports, sr->ini);
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

/* ---- counts: user-space instructions and system calls per packet ------------- */

/*
 * Figures that do not move with the machine's load: each subject runs under
 * a tool that counts what it does, not how long it takes. valgrind's
 * cachegrind (--cache-sim=no) counts the instructions the subject executes
 * in user space (its own code, liblcm, the C library; not the kernel's);
 * strace -f -c counts its system calls, by name. Two sessions per subject and
 * tool, a short one (COUNT_WARMUP packets in all, at least two a robot) and
 * one env->packets longer: the difference divided by those packets is what
 * a packet costs, start-up, connections, the RTDE handshake and the exit
 * taken out. Before the first packet the subject has settled (settle).
 *
 * Each packet is written only once every message of the one before has
 * come in (lock-step), and not before its time at 500 Hz a robot (the
 * robots spread over the period): however slow the tool makes the subject,
 * every packet finds it waiting and is read on its own, so a packet costs
 * one wake-up, as it does when the gateway keeps up. The time column (the
 * RTDE timestamp) is this host's monotonic clock when the packet is written,
 * so that a subject slowed by its tool still judges the data fresh.
 * GATEWAY reports are off: they come with time, not packets (0.002 of a
 * message a packet at 1 Hz and 500 Hz), and a run the tool slows has more
 * time per packet.
 *
 * RTDE: urrt-sim --rtde (-c 5.12, every variable the gateway asks for) does
 * the handshake with the subject, through this program, which passes every
 * byte both ways until the simulator's first data package; that package is
 * then the template of every package this program writes, its timestamp set
 * at the write.
 */
typedef enum { TOOL_VALGRIND, TOOL_STRACE } tool_kind;

#define COUNT_WARMUP 100              /* packets (all robots) of the shorter session */
#define COUNT_TIMEOUT_NS 30000000000u /* a subject under valgrind starts slowly */
#define COUNT_WAIT_NS 10000000000u    /* for one packet's messages */
#define PKG_MAX 4096

typedef struct {
    char key[128];
    double v;
} tally_entry;

/* What a tool counted: per name (a function, a system call) and in all. */
typedef struct {
    tally_entry *e;
    size_t n, cap;
    double total;
} tally;

static size_t tally_find(tally *t, const char *key)
{
    for (size_t i = 0; i < t->n; i++) {
        if (strcmp(t->e[i].key, key) == 0) return i;
    }
    if (t->n == t->cap) {
        t->cap = t->cap ? 2 * t->cap : 256;
        t->e = realloc(t->e, t->cap * sizeof *t->e);
    }
    snprintf(t->e[t->n].key, sizeof t->e[t->n].key, "%s", key);
    t->e[t->n].v = 0;
    return t->n++;
}

static void tally_free(tally *t)
{
    free(t->e);
    memset(t, 0, sizeof *t);
}

/* (b - a) / packets, by name and in all. */
static tally tally_per_packet(const tally *a, tally *b, double packets)
{
    tally d = {0};
    for (size_t i = 0; i < b->n; i++) {
        size_t k = tally_find(&d, b->e[i].key);
        d.e[k].v += b->e[i].v / packets;
    }
    for (size_t i = 0; i < a->n; i++) {
        size_t k = tally_find(&d, a->e[i].key);
        d.e[k].v -= a->e[i].v / packets;
    }
    d.total = (b->total - a->total) / packets;
    return d;
}

static int cmp_entry_desc(const void *x, const void *y)
{
    const tally_entry *p = x, *q = y;
    double a = round(p->v * 1000.0), b = round(q->v * 1000.0); /* as printed: equal figures by name */
    return a != b ? (a < b) - (a > b) : strcmp(p->key, q->key);
}

/* cachegrind's file (--cache-sim=no: one event, Ir): "fn=NAME" starts a
 * function's lines, "LINE COUNT" follow, "summary: TOTAL" ends it. */
static bool read_cachegrind(const char *path, tally *t)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    size_t cur = SIZE_MAX;
    bool summary = false;
    if (f == NULL) return false;
    while (fgets(line, sizeof line, f) != NULL) {
        if (strncmp(line, "fn=", 3) == 0) {
            line[strcspn(line, "\n")] = 0;
            cur = tally_find(t, line + 3);
        } else if (strncmp(line, "summary:", 8) == 0) {
            t->total = strtod(line + 8, NULL);
            summary = true;
        } else if (line[0] >= '0' && line[0] <= '9' && cur != SIZE_MAX) {
            char *end;
            strtoull(line, &end, 10);
            t->e[cur].v += strtod(end, NULL);
        }
    }
    fclose(f);
    return summary;
}

/* strace -c -U name,calls: "NAME CALLS" lines, "total CALLS" last. */
static bool read_strace(const char *path, tally *t)
{
    FILE *f = fopen(path, "r");
    char line[512], name[128];
    unsigned long long calls;
    bool total = false;
    if (f == NULL) return false;
    while (fgets(line, sizeof line, f) != NULL) {
        if (sscanf(line, "%127s %llu", name, &calls) != 2) continue;
        if (strcmp(name, "total") == 0) {
            t->total = (double)calls;
            total = true;
        } else {
            size_t k = tally_find(t, name); /* may move t->e */
            t->e[k].v += (double)calls;
        }
    }
    fclose(f);
    return total;
}

static void put_be_double(uint8_t *d, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    for (int i = 7; i >= 0; i--, bits >>= 8) d[i] = (uint8_t)bits;
}

static bool write_all_fd(int fd, const uint8_t *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        p += w;
        n -= (size_t)w;
    }
    return true;
}

/* A connection to urrt-sim's RTDE port for each of n robots, in sfd[],
 * before the subject starts: eight at a time, so that the simulator's
 * listen backlog (16) never overflows (a SYN dropped is sent again a second
 * later, which the subject's silence timeout would see). */
static bool sim_connect(int n, uint16_t sim_port, int *sfd)
{
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(sim_port),
                            .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    for (int r = 0; r < n; r++) sfd[r] = -1;
    for (int r = 0; r < n; r++) {
        sfd[r] = socket(AF_INET, SOCK_STREAM, 0);
        if (connect(sfd[r], (struct sockaddr *)&a, sizeof a) != 0) {
            perror("bench_gateway: connect to urrt-sim's RTDE port");
            return false;
        }
        if (r % 8 == 7) nanosleep(&(struct timespec){0, 20000000}, NULL);
    }
    return true;
}

/* Accepts each robot's connection from the subject (lfd[r] -> cfd[r],
 * *accepted of them) and, with RTDE (sfd[r] urrt-sim's connection for
 * robot r; NULL: RealTime), passes every byte both ways until the
 * simulator's first data package, which becomes the robot's template (not
 * passed on): each robot's handshake goes on while the subject connects
 * the next. Closes sfd[]. */
static bool accept_robots(int n, const int *lfd, int *cfd, int *accepted, int *sfd, uint8_t (*tmpl)[PKG_MAX],
                          size_t *tmpl_len)
{
    static struct {
        uint8_t b[2 * PKG_MAX];
        size_t have;
    } in[MAX_ROBOTS];
    int left = n;
    bool done[MAX_ROBOTS] = {false}, ok = true, rtde = sfd != NULL;
    for (int r = 0; r < n; r++) cfd[r] = -1;
    *accepted = 0;
    uint64_t end = mono_ns() + COUNT_TIMEOUT_NS;
    while (ok && left > 0 && mono_ns() < end) {
        struct pollfd p[2 * MAX_ROBOTS];
        for (int r = 0; r < n; r++) {
            p[2 * r] = (struct pollfd){.fd = cfd[r] < 0 ? lfd[r] : cfd[r], .events = POLLIN};
            p[2 * r + 1] = (struct pollfd){.fd = done[r] || cfd[r] < 0 ? -1 : sfd[r], .events = POLLIN};
        }
        if (poll(p, (nfds_t)(2 * n), 100) <= 0) continue;
        for (int r = 0; ok && r < n; r++) {
            uint8_t buf[PKG_MAX];
            if (p[2 * r].revents != 0 && cfd[r] < 0) { /* the subject connects */
                cfd[r] = accept(lfd[r], NULL, NULL);
                ok = cfd[r] >= 0;
                if (!ok) break;
                (*accepted)++;
                setsockopt(cfd[r], IPPROTO_TCP, TCP_NODELAY, &(int){1}, sizeof(int));
                in[r].have = 0;
                if (!rtde) {
                    done[r] = true;
                    left--;
                    continue;
                }
            } else if (p[2 * r].revents != 0) { /* the subject's requests */
                ssize_t k = read(cfd[r], buf, sizeof buf);
                ok = k > 0 && (done[r] || write_all_fd(sfd[r], buf, (size_t)k));
                if (!ok) fprintf(stderr, "bench_gateway: RTDE: robot %d: the subject closed its connection\n", r);
            }
            if (ok && p[2 * r + 1].revents != 0) { /* the simulator's replies */
                ssize_t k = read(sfd[r], in[r].b + in[r].have, sizeof in[r].b - in[r].have);
                ok = k > 0;
                if (!ok) fprintf(stderr, "bench_gateway: RTDE: robot %d: urrt-sim closed its connection\n", r);
                in[r].have += k > 0 ? (size_t)k : 0;
                while (ok && !done[r] && in[r].have >= 3) {
                    size_t size = (size_t)in[r].b[0] << 8 | in[r].b[1];
                    ok = size >= 3 && size <= PKG_MAX;
                    if (!ok || in[r].have < size) break;
                    if (in[r].b[2] == 'U') {
                        memcpy(tmpl[r], in[r].b, size);
                        tmpl_len[r] = size;
                        done[r] = true;
                        left--;
                    } else {
                        ok = write_all_fd(cfd[r], in[r].b, size);
                    }
                    memmove(in[r].b, in[r].b + size, in[r].have - size);
                    in[r].have -= size;
                }
            }
        }
    }
    for (int r = 0; rtde && r < n; r++) close(sfd[r]);
    /* The timestamp is the recipe's first variable, after the recipe id
     * (protocol 2): urrt-sim's clock is this host's monotonic one. */
    for (int r = 0; ok && left == 0 && rtde && r < n; r++) {
        double t = be_double(tmpl[r] + 4), now = (double)mono_ns() / 1e9;
        ok = tmpl_len[r] >= 12 && fabs(t - now) < 10.0;
    }
    if (!ok || left > 0) {
        fprintf(stderr, "bench_gateway: %d of %d robots connected%s\n", rtde ? n - left : *accepted, n,
                rtde ? " and streaming RTDE (through urrt-sim)" : "");
    }
    return ok && left == 0;
}

/* Reads the subscriber's socket until want messages of prefix's robots
 * have come in all (*got counts them) or the time is up. */
static bool await_count(int fd, const char *prefix, uint64_t *got, uint64_t want, uint64_t timeout_ns)
{
    enum { N = 16, SIZE = 2048 };
    static uint8_t bufs[N][SIZE];
    struct iovec iov[N];
    struct mmsghdr msgs[N];
    size_t pl = strlen(prefix);
    uint64_t end = mono_ns() + timeout_ns;
    while (*got < want) {
        uint64_t now = mono_ns();
        if (now >= end) return false;
        struct pollfd p = {.fd = fd, .events = POLLIN};
        if (poll(&p, 1, (int)((end - now) / 1000000u) + 1) != 1) continue;
        for (int i = 0; i < N; i++) {
            iov[i] = (struct iovec){.iov_base = bufs[i], .iov_len = SIZE};
            msgs[i] = (struct mmsghdr){.msg_hdr = {.msg_iov = &iov[i], .msg_iovlen = 1}};
        }
        int n = recvmmsg(fd, msgs, N, MSG_DONTWAIT, NULL);
        for (int i = 0; i < n; i++) {
            const uint8_t *d = bufs[i];
            if (msgs[i].msg_len > 8 + pl && memcmp(d, "LC02", 4) == 0 && memcmp(d + 8, prefix, pl) == 0 &&
                d[8 + pl] == '_') {
                (*got)++;
            }
        }
    }
    return true;
}

/* The pid of pid's child (the subject strace started). */
static pid_t child_of(pid_t pid)
{
    char path[64];
    long child = 0;
    snprintf(path, sizeof path, "/proc/%d/task/%d/children", (int)pid, (int)pid);
    for (int i = 0; i < 100 && child == 0; i++) {
        FILE *f = fopen(path, "r");
        if (f != NULL) {
            if (fscanf(f, "%ld", &child) != 1) child = 0;
            fclose(f);
        }
        if (child == 0) nanosleep(&(struct timespec){0, 10000000}, NULL);
    }
    return (pid_t)child;
}

/* Waits for pid to exit, SIGKILL after timeout; its exit status, or -1. */
static int reap(pid_t pid, uint64_t timeout_ns)
{
    int status = 0;
    uint64_t end = mono_ns() + timeout_ns;
    while (waitpid(pid, &status, WNOHANG) == 0) {
        if (mono_ns() > end) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            return -1;
        }
        nanosleep(&(struct timespec){0, 5000000}, NULL);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* urrt-sim serving RTDE as a 5.12 controller on a port the system chose. */
static pid_t start_sim(const char *path, const char *dir, uint16_t *port)
{
    char port_file[128];
    snprintf(port_file, sizeof port_file, "%s/sim.port", dir);
    unlink(port_file);
    pid_t pid = fork();
    if (pid == 0) {
        int null = open("/dev/null", O_WRONLY);
        dup2(null, 1);
        prctl(PR_SET_PDEATHSIG, SIGTERM); /* not left behind if this program dies */
        execl(path, path, "-q", "-l", "127.0.0.1:0", "--rtde", "127.0.0.1:0", "--rtde-port-file", port_file, "-c",
              "5.12", "--clock", "monotonic", "--max-clients", "64", (char *)NULL);
        _exit(127);
    }
    for (int i = 0; i < 500; i++) {
        FILE *f = fopen(port_file, "r");
        unsigned p = 0;
        if (f != NULL) {
            int got = fscanf(f, "%u", &p);
            fclose(f);
            if (got == 1 && p > 0 && p < 65536) {
                *port = (uint16_t)p;
                return pid;
            }
        }
        nanosleep(&(struct timespec){0, 10000000}, NULL);
    }
    fprintf(stderr, "bench_gateway: urrt-sim did not start\n");
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
    return -1;
}

/* Waits until pid (every thread) has used no CPU for 30 ms, 1.5 s at most:
 * it has done what its connections started and waits (the gateway's ticks,
 * every 100 ms, leave such gaps even under valgrind; its robots' silence
 * timeout, 2 s, is not reached). */
static void settle(pid_t pid)
{
    uint64_t last = task_times(pid).ns;
    int quiet = 0;
    for (int i = 0; i < 150 && quiet < 3; i++) {
        nanosleep(&(struct timespec){0, 10000000}, NULL);
        uint64_t now = task_times(pid).ns;
        quiet = now == last ? quiet + 1 : 0;
        last = now;
    }
}

typedef struct {
    const char *gateway, *relay, *sim;
    char dir[64];   /* the tools' files */
    long packets;   /* the longer session's packets beyond the shorter's (all robots) */
} count_env;

/* One session of a subject under a tool: per_robot packets to each of n
 * robots in lock-step; t gets the tool's figures. Messages that never came
 * (each waited for COUNT_WAIT_NS) are added to *missing. */
static bool count_session(const count_env *env, bool relay, bool rtde, int n, long per_robot, tool_kind tool,
                          const char *out, tally *t, uint64_t *missing)
{
    static unsigned serial;
    static uint8_t tmpl[MAX_ROBOTS][PKG_MAX];
    size_t tmpl_len[MAX_ROBOTS];
    char prefix[32], url[96], file_opt[320], log_opt[320], ini[] = INI_TEMPLATE;
    uint16_t ports[MAX_ROBOTS], udp_port = free_udp_port();
    int lfd[MAX_ROBOTS], cfd[MAX_ROBOTS], sfd[MAX_ROBOTS], accepted = 0;
    snprintf(prefix, sizeof prefix, "c%d_%u", (int)getpid(), serial++);
    snprintf(url, sizeof url, "udpm://%s:%u?ttl=0", LCM_GROUP, udp_port);
    snprintf(file_opt, sizeof file_opt, "--cachegrind-out-file=%s", out);
    snprintf(log_opt, sizeof log_opt, "--log-file=%s.log", out); /* valgrind's own messages */
    const char *valgrind[] = {"valgrind", "-q", "--tool=cachegrind", "--cache-sim=no", file_opt, log_opt, NULL};
    const char *strace[] = {"strace", "-f", "-c", "-U", "name,calls", "-o", out, NULL};
    subject sj = {.path = relay ? env->relay : env->gateway, .relay = relay, .robots = n, .rtde = rtde,
                  .gateway_rate = "off", .tool = tool == TOOL_VALGRIND ? valgrind : strace};
    int sub_fd = subscribe_udp(LCM_GROUP, udp_port);
    for (int r = 0; r < n; r++) {
        lfd[r] = listen_any(&ports[r]);
        cfd[r] = sfd[r] = -1;
    }
    /* A simulator of its own for each session: one that still counts the
     * last session's connections might refuse this one's. */
    uint16_t sim_port = 0;
    pid_t sim_pid = rtde ? start_sim(env->sim, env->dir, &sim_port) : -1;
    pid_t pid = rtde && (sim_pid < 0 || !sim_connect(n, sim_port, sfd)) ? -1
                : relay ? start_relay(&sj, url, prefix, ports)
                        : start_gateway(&sj, url, prefix, ports, ini);
    bool ok = pid > 0 && accept_robots(n, lfd, cfd, &accepted, rtde ? sfd : NULL, tmpl, tmpl_len);
    for (int r = 0; pid <= 0 && rtde && r < n; r++) {
        if (sfd[r] >= 0) close(sfd[r]);
    }
    if (sim_pid > 0) {
        kill(sim_pid, SIGTERM);
        waitpid(sim_pid, NULL, 0);
    }
    /* strace's subject is its child; valgrind's is the process it runs in. */
    pid_t target = pid <= 0 ? -1 : tool == TOOL_STRACE ? child_of(pid) : pid;
    /* Nothing of the start-up left to do when the first packet comes. */
    if (ok && target > 0) settle(target);
    uint64_t start = mono_ns(), got = 0, want = 0;
    for (long i = 0; ok && i < per_robot; i++) {
        for (int r = 0; ok && r < n; r++) {
            uint8_t pkt[PKG_MAX];
            size_t len = LENGTH;
            uint64_t due = start + (uint64_t)i * PERIOD_NS + (uint64_t)r * PERIOD_NS / (uint64_t)n, now = mono_ns();
            if (now < due) nanosleep(&(struct timespec){0, (long)(due - now)}, NULL);
            double stamp = (double)mono_ns() / 1e9;
            if (rtde) {
                len = tmpl_len[r];
                memcpy(pkt, tmpl[r], len);
                put_be_double(pkt + 4, stamp);
            } else {
                make_packet_at(pkt, stamp);
            }
            ok = write_all_fd(cfd[r], pkt, len);
            want += KINDS;
            if (ok && !await_count(sub_fd, prefix, &got, want, COUNT_WAIT_NS)) {
                fprintf(stderr, "bench_gateway: %s under %s: packet %ld of robot %d: %llu of %d messages came\n",
                        sj.path, sj.tool[0], i + 1, r, (unsigned long long)(got + KINDS - want), KINDS);
                *missing += want - got;
                ok = false;
            }
        }
    }
    if (!ok) fprintf(stderr, "bench_gateway: a count session of %s failed\n", sj.path);
    if (target > 0) kill(target, SIGTERM);
    int status = pid > 0 ? reap(pid, COUNT_TIMEOUT_NS) : -1;
    for (int r = 0; r < n; r++) {
        if (cfd[r] >= 0) close(cfd[r]);
    }
    for (int r = 0; r < n; r++) close(lfd[r]);
    close(sub_fd);
    if (!relay) unlink(ini);
    if (status != 0) {
        fprintf(stderr, "bench_gateway: %s under %s exited with status %d\n", sj.path, sj.tool[0], status);
        ok = false;
    }
    return ok && (tool == TOOL_VALGRIND ? read_cachegrind(out, t) : read_strace(out, t));
}

/* A subject's figures per packet under a tool: two sessions, the second
 * env->packets longer. */
static bool count_per_packet(const count_env *env, bool relay, bool rtde, int n, tool_kind tool, tally *per_packet,
                             uint64_t *missing)
{
    long warm = (COUNT_WARMUP + n - 1) / n, more = (env->packets + n - 1) / n;
    tally a = {0}, b = {0};
    char out_a[160], out_b[160];
    const char *what = tool == TOOL_VALGRIND ? "cachegrind" : "strace";
    snprintf(out_a, sizeof out_a, "%s/%s-%s-%d-%s-short.out", env->dir, rtde ? "rtde" : "realtime",
             relay ? "relay" : "gateway", n, what);
    snprintf(out_b, sizeof out_b, "%s/%s-%s-%d-%s-long.out", env->dir, rtde ? "rtde" : "realtime",
             relay ? "relay" : "gateway", n, what);
    bool ok = count_session(env, relay, rtde, n, warm, tool, out_a, &a, missing) &&
              count_session(env, relay, rtde, n, warm + more, tool, out_b, &b, missing);
    if (ok) *per_packet = tally_per_packet(&a, &b, (double)(more * n));
    tally_free(&a);
    tally_free(&b);
    return ok;
}

static void print_goal(const char *name, double value, const char *fmt_goal, bool met)
{
    printf("%s: %.3f (goal %s: %s)\n", name, value, fmt_goal, met ? "met" : "NOT met");
}

/* Prints the counts for both sources at each robot count of list. */
static bool counts(const count_env *env, const int *list, int nlist, int top)
{
    bool all_ok = true;
    char name[160];
    if (system("valgrind --version >/dev/null 2>&1") != 0 || system("strace -V >/dev/null 2>&1") != 0) {
        fprintf(stderr, "bench_gateway: the counts need valgrind and strace (Debian: apt-get install valgrind "
                        "strace)\n");
        return false;
    }
    printf("counts_packets_per_figure: %ld\n", env->packets);
    for (int src = 0; src < 2; src++) {
        const char *sname = src ? "rtde" : "realtime";
        double gw_instr[MAX_ROBOTS + 1] = {0};
        for (int li = 0; li < nlist; li++) {
            int n = list[li];
            tally instr[2] = {{0}}, sys[2] = {{0}};
            uint64_t missing[2] = {0, 0};
            bool ok[2];
            for (int who = 0; who < 2; who++) { /* relay, gateway */
                ok[who] = count_per_packet(env, who == 0, src, n, TOOL_VALGRIND, &instr[who], &missing[who]) &&
                          count_per_packet(env, who == 0, src, n, TOOL_STRACE, &sys[who], &missing[who]);
                all_ok = all_ok && ok[who];
                const char *wname = who ? "gateway" : "relay";
                if (!ok[who]) {
                    printf("counts_%s_robots_%d_%s: failed\n", sname, n, wname);
                    continue;
                }
                snprintf(name, sizeof name, "counts_%s_robots_%d_%s_", sname, n, wname);
                printf("%sinstructions_per_packet: %.0f\n", name, instr[who].total);
                printf("%ssyscalls_per_packet: %.3f\n", name, sys[who].total);
                qsort(sys[who].e, sys[who].n, sizeof *sys[who].e, cmp_entry_desc);
                for (size_t i = 0; i < sys[who].n; i++) {
                    if (fabs(sys[who].e[i].v) >= 0.0005) {
                        printf("%ssyscall_%s_per_packet: %.3f\n", name, sys[who].e[i].key, sys[who].e[i].v);
                    }
                }
                qsort(instr[who].e, instr[who].n, sizeof *instr[who].e, cmp_entry_desc);
                for (size_t i = 0; who == 1 && i < instr[who].n && (int)i < top; i++) {
                    printf("%sinstructions_in_%s: %.0f\n", name, instr[who].e[i].key, instr[who].e[i].v);
                }
                if (missing[who] != 0) {
                    printf("%smessages_missing: %llu\n", name, (unsigned long long)missing[who]);
                }
            }
            if (ok[0] && ok[1]) {
                snprintf(name, sizeof name, "counts_%s_robots_%d_gateway_syscalls_vs_relay", sname, n);
                double d = sys[1].total - sys[0].total;
                printf("%s: %+.3f (goal at most +0.100: %s)\n", name, d, d <= 0.1 ? "met" : "NOT met");
                snprintf(name, sizeof name, "counts_%s_robots_%d_gateway_instructions_vs_relay", sname, n);
                printf("%s: %.2f\n", name, instr[1].total / instr[0].total);
            }
            if (ok[1]) gw_instr[li] = instr[1].total;
            for (int who = 0; who < 2; who++) {
                tally_free(&instr[who]);
                tally_free(&sys[who]);
            }
        }
        /* The most robots against the fewest (50 against 1). */
        int lo = 0, hi = 0;
        for (int li = 0; li < nlist; li++) {
            if (list[li] < list[lo]) lo = li;
            if (list[li] > list[hi]) hi = li;
        }
        if (lo != hi && gw_instr[lo] > 0 && gw_instr[hi] > 0) {
            snprintf(name, sizeof name, "counts_%s_gateway_instructions_%d_vs_%d_robots", sname, list[hi], list[lo]);
            print_goal(name, gw_instr[hi] / gw_instr[lo], "at most 1.100", gw_instr[hi] / gw_instr[lo] <= 1.1);
        }
    }
    return all_ok;
}

int main(int argc, char **argv)
{
    /* Sleeps of tens of microseconds between robots' packets: no 50 us slack. */
    prctl(PR_SET_TIMERSLACK, 1000UL);
    subject gw = {.robots = 0, .seconds = 4}, relay = {.relay = true, .robots = 1};
    int rounds = 3, versus_robots = 0, count_list[MAX_ROBOTS], count_n = 0, top = 8;
    bool max = false, pin = true, count_mode = false;
    const char *sim = NULL, *keep = NULL;
    long count_packets = 1000;
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
        else if (strcmp(argv[i], "--counts") == 0) count_mode = true;
        else if (strcmp(argv[i], "--sim") == 0) sim = argv[++i];
        else if (strcmp(argv[i], "--keep") == 0) keep = argv[++i];
        else if (strcmp(argv[i], "--count-packets") == 0) count_packets = atol(v), i++;
        else if (strcmp(argv[i], "--top") == 0) top = atoi(v), i++;
        else if (strcmp(argv[i], "--count-robots") == 0) {
            char list[256], *save = NULL;
            snprintf(list, sizeof list, "%s", v);
            for (char *t = strtok_r(list, ", ", &save); t != NULL && count_n < MAX_ROBOTS;
                 t = strtok_r(NULL, ", ", &save)) {
                count_list[count_n++] = atoi(t);
            }
            i++;
        }
    }
    if (count_mode) {
        bool bad = gw.path == NULL || relay.path == NULL || sim == NULL || count_packets < 10 || count_n == 0;
        for (int k = 0; k < count_n; k++) bad = bad || count_list[k] < 1 || count_list[k] > MAX_ROBOTS;
        if (bad) {
            fprintf(stderr, "usage: bench_gateway --counts --gateway PATH --relay PATH --sim PATH --count-robots "
                            "N[,N...] [--count-packets P] [--keep DIR] [--top K] [--no-pin]\n");
            return 2;
        }
        signal(SIGPIPE, SIG_IGN);
        if (pin) choose_cores();
        count_env env = {.gateway = gw.path, .relay = relay.path, .sim = sim, .packets = count_packets};
        if (keep != NULL) {
            snprintf(env.dir, sizeof env.dir, "%s", keep);
            mkdir(keep, 0777);
        } else if (mkdtemp(strcpy(env.dir, "/tmp/bench-gateway-counts-XXXXXX")) == NULL) {
            perror("bench_gateway: mkdtemp");
            return 1;
        }
        printf("bench_core: %d\nsubject_core: %d\n", bench_core, subject_core);
        fflush(stdout);
        bool ok = counts(&env, count_list, count_n, top);
        if (keep == NULL) {
            DIR *d = opendir(env.dir);
            for (struct dirent *e; d != NULL && (e = readdir(d)) != NULL;) {
                char p[400];
                snprintf(p, sizeof p, "%s/%s", env.dir, e->d_name);
                if (e->d_name[0] != '.') unlink(p);
            }
            if (d != NULL) closedir(d);
            rmdir(env.dir);
        }
        return ok ? 0 : 1;
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
