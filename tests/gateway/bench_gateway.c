/*
 * bench_gateway: urrt-gateway's latency, CPU cost and highest packet rate.
 *
 * This program is the robot and the subscriber at once: it serves 1220-byte
 * packets (encoded with lib's urrt_encode, column 1 carrying the packet's
 * index) to a urrt-gateway it starts, with every message kind enabled at
 * every packet, and subscribes to the gateway's channels.
 *
 *   1. 500 Hz for SECONDS: latency from the write of a packet to the receipt
 *      of each of its messages (median, p99, max), and the gateway's CPU time
 *      (all its threads, from /proc/PID/task/TID/schedstat) per packet.
 *   2. As fast as the gateway reads: packets per second over the last two
 *      seconds of a three-second blast (TCP back-pressure paces the writes,
 *      so the rate written is the rate the gateway takes).
 *   Baseline, same run: the latency of a bare write-to-read over loopback TCP.
 *
 * Prints "name: value" lines; asserts nothing about timings.
 *
 *   bench_gateway --gateway PATH --port PORT [--seconds S] [--focused-hz N]
 *
 * --focused-hz N: no state message, the focused ones decimated to N Hz (the
 * latency phase then sees only the packets that are published).
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <math.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "urrt.h"

#define URL "udpm://239.255.76.67:7667?ttl=0"
#define LENGTH 1220
#define MAX_PACKETS 200000

static uint64_t mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static uint64_t *sent_ns;
static double *lat_us[4];
static unsigned lat_n[4];
static const char *kind_names[4] = {"STATE", "JOINTS", "TOOL", "STATUS"};
static char prefix[64];

/* The controller time is at offset 8 + 8 after the fingerprint in joints,
 * tool and status (utime first); in state it is the 'time' field further on.
 * Rather than parse, each message's index comes back through the time
 * column, which every kind carries: decode with the generated types' layout
 * is not needed, we look for the double the packet carried. */
static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    uint64_t now = mono_ns();
    const uint8_t *d = rbuf->data;
    size_t n = rbuf->data_size;
    int kind = -1;
    (void)user;
    for (int k = 0; k < 4; k++) {
        size_t pl = strlen(prefix);
        if (strncmp(channel, prefix, pl) == 0 && channel[pl] == '.' && strcmp(channel + pl + 1, kind_names[k]) == 0) {
            kind = k;
        }
    }
    if (kind < 0) {
        return;
    }
    /* Joints, tool, status: fingerprint(8) utime(8) controller_time(8). */
    size_t off = 16;
    if (kind == 0) {
        /* state: fingerprint, utime, length(4), doubles(2), generation(1),
         * versions (4-byte length incl. NUL, bytes), present(8), sequence(8), time. */
        if (n < 23) return;
        uint32_t slen = (uint32_t)d[23] << 24 | (uint32_t)d[24] << 16 | (uint32_t)d[25] << 8 | d[26];
        off = 27 + slen + 16;
    }
    if (off + 8 > n) {
        return;
    }
    uint64_t bits = 0;
    for (int i = 0; i < 8; i++) {
        bits = bits << 8 | d[off + (size_t)i];
    }
    double t;
    memcpy(&t, &bits, sizeof t);
    long index = lrint(t * 500.0);
    if (index < 0 || index >= MAX_PACKETS || sent_ns[index] == 0 || lat_n[kind] >= MAX_PACKETS) {
        return;
    }
    lat_us[kind][lat_n[kind]++] = (double)(now - sent_ns[index]) / 1000.0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void report_latency(const char *name, double *v, unsigned n)
{
    if (n == 0) {
        printf("%s_messages: 0\n", name);
        return;
    }
    qsort(v, n, sizeof *v, cmp_double);
    printf("%s_latency_median_us: %.1f\n", name, v[n / 2]);
    printf("%s_latency_p99_us: %.1f\n", name, v[(size_t)(n * 0.99)]);
    printf("%s_latency_max_us: %.1f\n", name, v[n - 1]);
    printf("%s_messages: %u\n", name, n);
}

/* CPU time of every thread of pid, in ns. */
static uint64_t cpu_ns(pid_t pid)
{
    char path[64];
    uint64_t sum = 0;
    snprintf(path, sizeof path, "/proc/%d/task", (int)pid);
    DIR *dir = opendir(path);
    if (dir == NULL) {
        return 0;
    }
    for (struct dirent *e; (e = readdir(dir)) != NULL;) {
        char p[320];
        unsigned long long run = 0;
        if (e->d_name[0] == '.') continue;
        snprintf(p, sizeof p, "/proc/%d/task/%s/schedstat", (int)pid, e->d_name);
        FILE *f = fopen(p, "r");
        if (f != NULL) {
            if (fscanf(f, "%llu", &run) == 1) sum += run;
            fclose(f);
        }
    }
    closedir(dir);
    return sum;
}

static int listen_on(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0), one = 1;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port),
                            .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 || listen(fd, 4) != 0) {
        perror("bench_gateway: listen");
        exit(1);
    }
    return fd;
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
     * tell a backlog from fresh packets. */
    st.time[0] = (double)index * 0.002;
    urrt_encode(&st, LENGTH, out, LENGTH);
}

/* Loopback TCP write-to-read with nothing in between: the floor under
 * the gateway's figure. */
static double baseline_us(void)
{
    int sv[2];
    uint8_t buf[LENGTH];
    double v[2000];
    int lfd = socket(AF_INET, SOCK_STREAM, 0), one = 1;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t al = sizeof a;
    bind(lfd, (struct sockaddr *)&a, sizeof a);
    listen(lfd, 1);
    getsockname(lfd, (struct sockaddr *)&a, &al);
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
    qsort(v, 2000, sizeof v[0], cmp_double);
    return v[1000];
}

int main(int argc, char **argv)
{
    const char *gateway = NULL;
    int port = 41500;
    double seconds = 6;
    const char *focused_hz = NULL; /* NULL: every message at every packet */
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--gateway") == 0) gateway = argv[i + 1];
        else if (strcmp(argv[i], "--port") == 0) port = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--seconds") == 0) seconds = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--focused-hz") == 0) focused_hz = argv[i + 1];
    }
    if (gateway == NULL) {
        fprintf(stderr, "usage: bench_gateway --gateway PATH --port PORT [--seconds S] [--focused-hz N]\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    sent_ns = calloc(MAX_PACKETS, sizeof *sent_ns);
    for (int k = 0; k < 4; k++) lat_us[k] = calloc(MAX_PACKETS, sizeof(double));

    double base = baseline_us();

    snprintf(prefix, sizeof prefix, "bench%d", (int)getpid());
    char ini[] = "/tmp/bench-gateway-XXXXXX";
    int ifd = mkstemp(ini);
    if (focused_hz == NULL) {
        dprintf(ifd, "[lcm]\nurl = %s\nstate_rate = every\njoints_rate = every\ntool_rate = every\n"
                     "status_rate = every\n", URL);
    } else {
        dprintf(ifd, "[lcm]\nurl = %s\nstate_rate = off\njoints_rate = %s Hz\ntool_rate = %s Hz\n"
                     "status_rate = %s Hz\n", URL, focused_hz, focused_hz, focused_hz);
    }
    dprintf(ifd, "gateway_rate = 1 Hz\n[robot %s]\nhost = 127.0.0.1\nport = %d\nsilence_timeout = 2 s\n",
            prefix, port);
    close(ifd);

    lcm_t *lcm = lcm_create(URL);
    if (lcm == NULL) {
        fprintf(stderr, "bench_gateway: cannot open %s\n", URL);
        return 1;
    }
    char regex[96];
    snprintf(regex, sizeof regex, "%s\\..*", prefix);
    lcm_subscribe(lcm, regex, on_message, NULL);
    int lfd = listen_on(port);

    pid_t pid = fork();
    if (pid == 0) {
        execl(gateway, gateway, "--log-level", "warning", ini, (char *)NULL);
        _exit(127);
    }
    int cfd = -1;
    struct pollfd pl = {.fd = lfd, .events = POLLIN};
    if (poll(&pl, 1, 5000) == 1) cfd = accept(lfd, NULL, NULL);
    if (cfd < 0) {
        fprintf(stderr, "bench_gateway: the gateway did not connect\n");
        kill(pid, SIGTERM);
        waitpid(pid, NULL, 0);
        unlink(ini);
        return 1;
    }
    int one = 1;
    setsockopt(cfd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    int lcm_fd = lcm_get_fileno(lcm);

    /* Phase 1: 500 Hz. The first second warms up and is not measured. */
    uint8_t pkt[LENGTH];
    long index = 1;
    long total = (long)(seconds * 500.0) + 500;
    uint64_t start = mono_ns(), cpu0 = 0, wall0 = 0;
    long measured_from = 500;
    while (index < total) {
        uint64_t due = start + (uint64_t)index * 2000000u;
        uint64_t now = mono_ns();
        if (now >= due) {
            if (index == measured_from) {
                for (int k = 0; k < 4; k++) lat_n[k] = 0;
                cpu0 = cpu_ns(pid);
                wall0 = now;
            }
            make_packet(pkt, index);
            sent_ns[index] = mono_ns();
            if (write(cfd, pkt, LENGTH) != LENGTH) {
                fprintf(stderr, "bench_gateway: write: %s\n", strerror(errno));
                break;
            }
            index++;
            continue;
        }
        struct pollfd p = {.fd = lcm_fd, .events = POLLIN};
        struct timespec ts = {.tv_sec = 0, .tv_nsec = (long)(due - now)};
        if (ppoll(&p, 1, &ts, NULL) == 1) lcm_handle(lcm);
    }
    uint64_t cpu1 = cpu_ns(pid), wall1 = mono_ns();
    /* Collect the last messages. */
    for (uint64_t end = mono_ns() + 200000000u; mono_ns() < end;) {
        struct pollfd p = {.fd = lcm_fd, .events = POLLIN};
        if (poll(&p, 1, 20) == 1) lcm_handle(lcm);
    }
    long packets = index - measured_from;
    printf("baseline_tcp_loopback_median_us: %.1f\n", base);
    for (int k = 0; k < 4; k++) {
        char name[32];
        snprintf(name, sizeof name, "%s", kind_names[k]);
        for (char *c = name; *c; c++) *c = (char)(*c - 'A' + 'a');
        report_latency(name, lat_us[k], lat_n[k]);
    }
    printf("packets_at_500hz: %ld\n", packets);
    printf("gateway_cpu_per_packet_us: %.2f\n", (double)(cpu1 - cpu0) / 1000.0 / (double)packets);
    printf("gateway_cpu_percent_of_core_at_500hz: %.3f\n", 100.0 * (double)(cpu1 - cpu0) / (double)(wall1 - wall0));

    /* Phase 2: as fast as the gateway takes them. Stop reading LCM: the
     * kernel drops what this process does not read. */
    lcm_unsubscribe(lcm, NULL);
    lcm_destroy(lcm);
    fcntl(cfd, F_SETFL, fcntl(cfd, F_GETFL) | O_NONBLOCK);
    /* 4096 packets whose times keep increasing: refreshed each round, so
     * that decimation on the controller's clock works as it would live. */
    enum { BURST = 4096 };
    static uint8_t burst[BURST * LENGTH];
    long next_index = 100000;
    for (int i = 0; i < BURST; i++) make_packet(burst + (size_t)i * LENGTH, next_index++);
    uint64_t t0 = mono_ns(), mark_t = 0;
    uint64_t written = 0, mark_w = 0;
    uint64_t cpu_mark = 0;
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
    uint64_t t1 = mono_ns();
    uint64_t cpu_end = cpu_ns(pid);
    double rate = (double)(written - mark_w) / LENGTH / ((double)(t1 - mark_t) / 1e9);
    printf("max_rate_packets_per_s: %.0f\n", rate);
    printf("gateway_cpu_percent_of_core_at_max_rate: %.1f\n",
           100.0 * (double)(cpu_end - cpu_mark) / (double)(t1 - mark_t));
    printf("max_rate_vs_500hz: %.0f\n", rate / 500.0);

    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    printf("gateway_exit_status: %d\n", WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
    close(cfd);
    close(lfd);
    unlink(ini);
    return 0;
}
