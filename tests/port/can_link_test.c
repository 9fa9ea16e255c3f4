/* SPDX-License-Identifier: MIT */
/*
 * can_link_test: black-box tests of the CAN link (port.h, port/posix/can.c).
 *
 *   can_link_test log DIR      the candump-log output (no CAN needed): writes
 *                              DIR/log-fd.log, DIR/log-classic.log,
 *                              DIR/log-stdout.log and DIR/log-expect.txt for
 *                              an independent reader (python-can, canplayer);
 *                              and log:- to a pipe, a socket and a terminal
 *                              whose reader stalls, and under a replay's
 *                              clock (it waits for a slow reader); receive
 *                              ids replaced and refused on a log link
 *   can_link_test frames DIR   sends a known set of frames through SocketCAN
 *                              links on vcan0 (FD MTU) and vcan1 (classic
 *                              MTU), checks them with its own receiving
 *                              sockets, and writes the same frames through
 *                              log links to DIR/frames-vcan0.log and
 *                              DIR/frames-vcan1.log, for a comparison with a
 *                              candump -L capture
 *   can_link_test socket       everything else on a real kernel: FD refused
 *                              on a classic MTU, data frames not received,
 *                              error frames, a full transmit queue (ENOBUFS
 *                              with the plug qdisc; EAGAIN with a tiny socket
 *                              buffer), interface down/up, removal and
 *                              re-creation, MTU change; receive ids
 *                              replaced on an open link and kept across a
 *                              reopen (urrt_canlink_set_rx_ids)
 *
 * The socket tests run in the VM of tests/vm/run.sh as root, with vcan0
 * (MTU 72) and vcan1 (MTU 16) up, sch_plug loaded and iproute2's ip and tc
 * in PATH. Each prints "N passed, N failed".
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <net/if.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>

#include "port.h"
#include "../check.h"

extern char **environ;

/* A call into the link must never block. Its duration cannot tell: a host
 * that preempts the VM makes a non-blocking call take 120 ms (seen under
 * TCG on a loaded 2-core host). The kernel can: a thread that sleeps in a
 * call gives up the CPU voluntarily (ru_nvcsw), one that is preempted does
 * not. So every call is bracketed by a sleep_mark, and the longest call is
 * printed for information only.
 *
 * A page fault may sleep too, whatever the call does: memory compaction
 * moving one of the thread's pages makes a fault on it wait for the move
 * (migration_entry_wait; traced here with compaction running beside the
 * test, and seen once in a fresh-clone make check after a VM suite freed
 * its guest's memory). A call that both slept and faulted is therefore
 * counted apart, as a fault's sleep. That cannot hide a link that waits for
 * its reader: a write that blocks on a stalled reader never returns at all
 * (the alarm and the longest call tell), and a link that waited a while for
 * room would sleep in every call it refused, with or without a fault. */
typedef struct {
    long switches; /* voluntary context switches */
    long faults;   /* page faults, minor and major */
} sleep_mark;

static unsigned fault_sleeps;

static sleep_mark sleep_mark_now(void)
{
    struct rusage ru;
    getrusage(RUSAGE_THREAD, &ru);
    return (sleep_mark){ ru.ru_nvcsw, ru.ru_minflt + ru.ru_majflt };
}

/* 1 if the thread slept since m other than in a page fault; a sleep in a
 * fault is counted in fault_sleeps. */
static int slept_since(sleep_mark m)
{
    sleep_mark now = sleep_mark_now();
    if (now.switches == m.switches)
        return 0;
    if (now.faults != m.faults) {
        fault_sleeps++;
        return 0;
    }
    return 1;
}

/* ---- captured log messages ----------------------------------------------------- */

static char messages[16384];
/* Set while calls are measured for sleeping: stderr may be a pipe to a
 * slow reader (make's tee), and a write to it must not count against the
 * link. The messages are printed afterwards from messages[]. */
static bool capture_quiet;

static void capture(void *ctx, urrt_log_level level, const char *message)
{
    (void)ctx;
    size_t used = strlen(messages);
    snprintf(messages + used, sizeof(messages) - used, "%s\n", message);
    if (!capture_quiet)
        fprintf(stderr, "  [link %s] %s\n", urrt_log_level_name(level), message);
}

static void messages_clear(void)
{
    messages[0] = '\0';
}

/* ---- helpers ---------------------------------------------------------------------- */

static uint64_t now_us(void)
{
    return urrt_port_monotonic_us();
}

/* Runs a program found in PATH (not through a shell: a busybox shell would
 * pick its own ip and tc). Returns the exit status. */
static int run(const char *first, ...)
{
    const char *argv[16];
    int argc = 0;
    va_list ap;
    va_start(ap, first);
    for (const char *a = first; a != NULL && argc < 15; a = va_arg(ap, const char *))
        argv[argc++] = a;
    va_end(ap);
    argv[argc] = NULL;
    pid_t pid;
    if (posix_spawnp(&pid, argv[0], NULL, NULL, (char *const *)argv, environ) != 0) {
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
        return -1;
    }
    int status;
    if (waitpid(pid, &status, 0) < 0)
        return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

#define RUN(...) CHECK(run(__VA_ARGS__, (const char *)NULL) == 0, "command failed")

static urrt_can_frame make_frame(uint32_t id, bool ext, bool fd, uint8_t len, uint8_t seed)
{
    urrt_can_frame f;
    memset(&f, 0, sizeof(f));
    f.id = id;
    f.extended = ext;
    f.fd = fd;
    f.len = len;
    for (unsigned i = 0; i < len; i++)
        f.data[i] = (uint8_t)(seed + i * 17u);
    return f;
}

static urrt_canlink *open_link_hold(const char *ifname, bool fd, bool brs, uint32_t hold_max_ms)
{
    urrt_canlink_config cfg;
    urrt_canlink_config_defaults(&cfg);
    cfg.interface = ifname;
    cfg.fd = fd;
    cfg.fd_brs = brs;
    cfg.reopen_interval_ms = 50;
    cfg.retry_interval_ms = 5;
    cfg.hold_max_ms = hold_max_ms;
    return urrt_canlink_new(&cfg);
}

/* Held values stay fresh for 2 s: longer than any wait here, even on a
 * loaded host under TCG, except where expiry is the point. */
static urrt_canlink *open_link(const char *ifname, bool fd, bool brs)
{
    return open_link_hold(ifname, fd, brs, 2000);
}

/* The longest single call into the link, and the calls into a socket link
 * that slept, over the whole run. A log: link writes a regular file, and
 * write(2) to a file may wait on the filesystem (its journal, the inode's
 * lock) whatever the caller does: check-stress saw one such wait of 121 us
 * on a loaded host. Those calls are counted apart, not held to "never
 * sleeps", which is the promise of the socket links. */
static uint64_t max_call_us;
static unsigned blocked_calls, file_waits;

static void call_ended(uint64_t t0, sleep_mark m, bool file)
{
    uint64_t dt = now_us() - t0;
    if (dt > max_call_us)
        max_call_us = dt;
    if (slept_since(m)) {
        if (file)
            file_waits++;
        else
            blocked_calls++;
    }
}

static int send_measured(urrt_canlink *can, const urrt_can_frame *f, bool file)
{
    sleep_mark m = sleep_mark_now();
    uint64_t t0 = now_us();
    int r = urrt_canlink_send(can, f, t0);
    call_ended(t0, m, file);
    return r;
}

static int timed_send(urrt_canlink *can, const urrt_can_frame *f)
{
    return send_measured(can, f, false);
}

/* A send to a log: link (a file). */
static int timed_log_send(urrt_canlink *can, const urrt_can_frame *f)
{
    return send_measured(can, f, true);
}

/* Runs the link's share of a poll loop for ms milliseconds. Returns the
 * poll events seen on its descriptor (ORed). */
static short pump(urrt_canlink *can, unsigned ms)
{
    uint64_t end = now_us() + ms * 1000u;
    short seen = 0;
    for (uint64_t t = now_us(); t < end; t = now_us()) {
        short events;
        int fd = urrt_canlink_poll_fd(can, &events);
        uint64_t deadline = urrt_canlink_deadline(can);
        uint64_t until = deadline < end ? deadline : end;
        int timeout_ms = until > t ? (int)((until - t + 999) / 1000) : 0;
        struct pollfd p = { .fd = fd, .events = events };
        int n = poll(&p, fd >= 0 ? 1 : 0, timeout_ms);
        if (n > 0)
            seen |= p.revents;
        sleep_mark m = sleep_mark_now();
        uint64_t t0 = now_us();
        urrt_canlink_service(can, t0);
        call_ended(t0, m, false);
    }
    return seen;
}

/* Pumps until the link is in state (or nothing is held, for want_idle) or
 * limit_ms pass: waits that depend on the host's speed end as soon as they
 * can and still have a bound. */
static short pump_until_state(urrt_canlink *can, urrt_canlink_state state, unsigned limit_ms)
{
    short seen = 0;
    for (unsigned waited = 0; urrt_canlink_get_state(can) != state && waited < limit_ms; waited += 10)
        seen |= pump(can, 10);
    return seen;
}

static short pump_until_idle(urrt_canlink *can, unsigned limit_ms)
{
    short seen = 0;
    for (unsigned waited = 0; urrt_canlink_get_stats(can)->pending != 0 && waited < limit_ms; waited += 10)
        seen |= pump(can, 10);
    return seen;
}

/* A receiving socket of our own: the kernel's view of what went out. */
static int rx_open(const char *ifname)
{
    int s = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK, CAN_RAW);
    int on = 1;
    setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof(on));
    struct sockaddr_can addr = { .can_family = AF_CAN, .can_ifindex = (int)if_nametoindex(ifname) };
    if (s < 0 || bind(s, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
        fprintf(stderr, "cannot open a receiver on %s: %s\n", ifname, strerror(errno));
        if (s >= 0)
            close(s);
        return -1;
    }
    return s;
}

typedef struct rx_frame {
    struct canfd_frame f;
    bool fd;
} rx_frame;

/* Reads what arrived until quiet_ms pass without a frame. Errors queued on
 * the socket (interface down) are read and skipped. */
static size_t rx_collect(int s, rx_frame *out, size_t max, unsigned quiet_ms)
{
    size_t n = 0;
    for (;;) {
        struct pollfd p = { .fd = s, .events = POLLIN };
        if (poll(&p, 1, (int)quiet_ms) <= 0)
            return n;
        struct canfd_frame f;
        ssize_t r = recv(s, &f, sizeof(f), 0);
        if (r < 0)
            continue;
        if (n < max) {
            out[n].f = f;
            out[n].fd = r == (ssize_t)CANFD_MTU;
            n++;
        }
    }
}

static bool rx_matches(const rx_frame *r, const urrt_can_frame *f, bool brs)
{
    canid_t id = f->extended ? (f->id | CAN_EFF_FLAG) : f->id;
    if (r->f.can_id != id || r->fd != f->fd || r->f.len != f->len)
        return false;
    if (f->fd && ((r->f.flags & CANFD_BRS) != 0) != brs)
        return false;
    return memcmp(r->f.data, f->data, f->len) == 0;
}

/* id as the kernel has it: CAN_EFF_FLAG set for a 29-bit ID. */
static int count_id(const rx_frame *rx, size_t n, canid_t id)
{
    int c = 0;
    for (size_t i = 0; i < n; i++)
        if (rx[i].f.can_id == id)
            c++;
    return c;
}

static const rx_frame *last_of_id(const rx_frame *rx, size_t n, canid_t id)
{
    const rx_frame *last = NULL;
    for (size_t i = 0; i < n; i++)
        if (rx[i].f.can_id == id)
            last = &rx[i];
    return last;
}

static int count_substr(const char *text, const char *needle)
{
    int n = 0;
    for (const char *p = strstr(text, needle); p != NULL; p = strstr(p + 1, needle))
        n++;
    return n;
}

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "r");
    if (f == NULL)
        return NULL;
    static char buf[65536];
    size_t n = fread(buf, 1, sizeof(buf) - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* ---- the frame sets ------------------------------------------------------------- */

/* Chosen for the formats' edge cases: 3- and 8-digit IDs, the largest IDs,
 * zero length, every FD length class, bytes that need two hex digits. */
static const struct { uint32_t id; bool ext, fd; uint8_t len; } classic_set[] = {
    { 0x123, false, false, 8 }, { 0x000, false, false, 0 }, { 0x7FF, false, false, 1 },
    { 0x1ABCDEF0, true, false, 3 }, { 0x00000001, true, false, 8 }, { 0x1FFFFFFF, true, false, 0 },
};
static const struct { uint32_t id; bool ext, fd; uint8_t len; } fd_set_[] = {
    { 0x100, false, true, 64 }, { 0x18FF1234, true, true, 12 }, { 0x101, false, true, 0 },
    { 0x321, false, false, 2 }, { 0x102, false, true, 8 }, { 0x103, false, true, 48 },
    { 0x0ABCDEF0, true, true, 20 },
};

/* ---- log: ------------------------------------------------------------------------ */

static void expect_line(FILE *expect, const char *file, const urrt_can_frame *f, bool brs)
{
    fprintf(expect, "%s %" PRIX32 " %d %d %d ", file, f->id, f->extended, f->fd, f->fd && brs);
    for (unsigned i = 0; i < f->len; i++)
        fprintf(expect, "%02X", f->data[i]);
    fputc('\n', expect);
}

/* "(SEC.USEC) " with a wall-clock time between lo and hi; returns what
 * follows, or NULL. */
static const char *strip_stamp(const char *line, uint64_t lo_us, uint64_t hi_us)
{
    unsigned long long sec, usec;
    int n = 0;
    if (strlen(line) < 20 || line[0] != '(' || line[11] != '.' || line[18] != ')' || line[19] != ' ')
        return NULL;
    if (sscanf(line, "(%10llu.%6llu) %n", &sec, &usec, &n) != 2 || n != 20)
        return NULL;
    uint64_t t = sec * 1000000u + usec;
    if (t + 1000000u < lo_us || t > hi_us + 1000000u)
        return NULL;
    return line + 20;
}

/* Compares the file, line by line, with "IFNAME ID#..." strings. */
static void check_log_file(const char *path, const char *const *want, size_t n_want, uint64_t lo_us, uint64_t hi_us)
{
    char *text = read_file(path);
    CHECK(text != NULL, "cannot read %s", path);
    if (text == NULL)
        return;
    size_t i = 0;
    for (char *save = NULL, *line = strtok_r(text, "\n", &save); line != NULL; line = strtok_r(NULL, "\n", &save), i++) {
        const char *rest = strip_stamp(line, lo_us, hi_us);
        CHECK(rest != NULL, "%s line %zu: no (SEC.USEC) stamp of now: %s", path, i + 1, line);
        if (rest != NULL && i < n_want)
            CHECK(strcmp(rest, want[i]) == 0, "%s line %zu: \"%s\", want \"%s\"", path, i + 1, rest, want[i]);
    }
    CHECK_EQ_INT(i, n_want);
}

/* Frames with the line candump -l writes for each (can-utils lib.c: 3 or 8
 * upper-case hex digits, '#', for FD a second '#' and the flags nibble, the
 * data in upper-case hex). Written by hand, not by a formatter. */
typedef struct log_case {
    uint32_t id;
    bool ext, fd;
    uint8_t len;
    const char *data;   /* hex; "ramp" is 00 01 02 ... */
    const char *line;
} log_case;

static const log_case log_fd_cases[] = {
    { 0x100, false, true, 64, "ramp",
      "vcan0 100##5000102030405060708090A0B0C0D0E0F101112131415161718191A1B1C1D1E1F"
      "202122232425262728292A2B2C2D2E2F303132333435363738393A3B3C3D3E3F" },
    { 0x18FF1234, true, true, 12, "a1b2c3d4e5f60718293a4b5c", "vcan0 18FF1234##5A1B2C3D4E5F60718293A4B5C" },
    { 0x101, false, true, 0, "", "vcan0 101##5" },
    { 0x321, false, false, 2, "dead", "vcan0 321#DEAD" },
    { 0x7FF, false, true, 8, "0001020304050607", "vcan0 7FF##50001020304050607" },
    { 0x0ABCDEF0, true, true, 20, "ramp", "vcan0 0ABCDEF0##5000102030405060708090A0B0C0D0E0F10111213" },
};
static const log_case log_classic_cases[] = {
    { 0x123, false, false, 8, "1122334455667788", "can0 123#1122334455667788" },
    { 0x000, false, false, 0, "", "can0 000#" },
    { 0x7FF, false, false, 1, "ff", "can0 7FF#FF" },
    { 0x1ABCDEF0, true, false, 3, "abcdef", "can0 1ABCDEF0#ABCDEF" },
    { 0x00000001, true, false, 1, "00", "can0 00000001#00" },
    { 0x1FFFFFFF, true, false, 0, "", "can0 1FFFFFFF#" },
};

static urrt_can_frame case_frame(const log_case *c)
{
    urrt_can_frame f = make_frame(c->id, c->ext, c->fd, c->len, 0);
    if (strcmp(c->data, "ramp") != 0)
        for (unsigned i = 0; i < c->len; i++)
            sscanf(c->data + 2 * i, "%2hhx", &f.data[i]);
    else
        for (unsigned i = 0; i < c->len; i++)
            f.data[i] = (uint8_t)i;
    return f;
}

/* ---- log:- with a reader that stalls --------------------------------------------- */

/* A call that blocked on the stalled reader would never return (nothing
 * reads then): the alarm turns that hang into a failure. */
static void stall_alarm(int sig)
{
    (void)sig;
    static const char msg[] = "FAIL: a log:- test did not end in 30 s: a call blocked on its stalled reader?\n";
    ssize_t ignored = write(STDERR_FILENO, msg, sizeof(msg) - 1);
    (void)ignored;
    _exit(1);
}

/* Reads what the reader's end (a pipe, a socket) holds: the writes before
 * were synchronous, so poll with no timeout sees all of it. Returns the
 * length read. */
static size_t drain_now(int rd, char *buf, size_t size)
{
    size_t n = 0;
    struct pollfd p = { .fd = rd, .events = POLLIN };
    while (n < size - 1 && poll(&p, 1, 0) == 1 && (p.revents & POLLIN)) {
        ssize_t r = read(rd, buf + n, size - 1 - n);
        if (r <= 0)
            break;
        n += (size_t)r;
    }
    buf[n] = '\0';
    return n;
}

/* The counters of the lines in text, which must all be whole candump lines
 * "(SEC.USEC) can1 123#CCCCCCCC"; false at the first that is not. */
static bool stall_lines(char *text, size_t len, uint32_t *seq, size_t max, size_t *n, uint64_t lo, uint64_t hi)
{
    *n = 0;
    if (len > 0 && text[len - 1] != '\n') {
        CHECK(false, "the stream ends inside a line: ...%s", len > 40 ? text + len - 40 : text);
        return false;
    }
    for (char *save = NULL, *line = strtok_r(text, "\n", &save); line != NULL; line = strtok_r(NULL, "\n", &save)) {
        const char *rest = strip_stamp(line, lo, hi);
        unsigned v;
        int end = 0;
        if (rest == NULL || strncmp(rest, "can1 123#", 9) != 0 || strlen(rest) != 17 ||
            sscanf(rest + 9, "%8X%n", &v, &end) != 1 || end != 8 || *n == max) {
            CHECK(false, "not a whole candump line of the test: \"%s\"", line);
            return false;
        }
        seq[(*n)++] = v;
    }
    return true;
}

static urrt_can_frame seq_frame(uint32_t i)
{
    urrt_can_frame f = make_frame(0x123, false, false, 4, 0);
    f.data[0] = (uint8_t)(i >> 24);
    f.data[1] = (uint8_t)(i >> 16);
    f.data[2] = (uint8_t)(i >> 8);
    f.data[3] = (uint8_t)i;
    return f;
}

/* log:- into a pipe whose reader stops reading (a pager, a hung script),
 * or a stream socket (systemd's StandardOutput=journal, socat): every call
 * returns at once, frames it has no room for are dropped and counted, the
 * reader then finds only whole lines, exactly those of the frames the link
 * took, and writing resumes when it drains. stdout's own open file
 * description stays blocking: the shell shares it. */
static void test_log_stall(bool socket_out)
{
    enum { TAKEN_MAX = 8192, STALLED_SENDS = 500, RESUMED = 20 };
    static uint32_t taken[TAKEN_MAX], got[TAKEN_MAX];
    static char text[TAKEN_MAX * 40];
    size_t n_taken = 0, n_got = 0;
    const char *kind = socket_out ? "socket" : "pipe";
    int p[2];
    CHECK((socket_out ? socketpair(AF_UNIX, SOCK_STREAM, 0, p) : pipe(p)) == 0, "%s: %s", kind, strerror(errno));
    fflush(stdout);
    int saved = dup(STDOUT_FILENO);
    dup2(p[1], STDOUT_FILENO);
    close(p[1]);
    signal(SIGALRM, stall_alarm);
    alarm(30);
    uint64_t lo = urrt_port_realtime_us();

    messages_clear();
    urrt_canlink *so = open_link("log:-,ifname=can1", false, false);
    int stdout_flags = fcntl(STDOUT_FILENO, F_GETFL);
    uint64_t longest = 0;
    long slept = 0;
    uint32_t i = 0, refused = 0, taken_before = 0;
    capture_quiet = true;
    for (; so != NULL && refused < STALLED_SENDS && i < 4 * TAKEN_MAX; i++) {
        urrt_can_frame f = seq_frame(i);
        sleep_mark m = sleep_mark_now();
        uint64_t t0 = now_us();
        int r = urrt_canlink_send(so, &f, t0);
        uint64_t dt = now_us() - t0;
        slept += slept_since(m);
        longest = dt > longest ? dt : longest;
        if (r == 1 && n_taken < TAKEN_MAX)
            taken[n_taken++] = i;
        refused += r == 0;
        if (r == 0 && taken_before == 0)
            taken_before = (uint32_t)n_taken;
    }
    capture_quiet = false;
    fprintf(stderr, "%s", messages);
    CHECK(so != NULL, "log:- link on a %s", kind);
    if (so == NULL)
        goto out;
    fprintf(stderr, "  stalled %s: %u sends, %zu taken before it was full, %u refused; longest call %" PRIu64
            " us\n", kind, i, n_taken, refused, longest);
    CHECK(stdout_flags >= 0 && !(stdout_flags & O_NONBLOCK), "stdout's shared description stays blocking");
    CHECK(slept == 0, "%ld calls slept on the stalled reader", slept);
    /* A blocked write would wait for ever (nothing reads): any bound tells,
     * and one second holds on a loaded host. */
    CHECK(longest < 1000000, "longest call %" PRIu64 " us", longest);
    CHECK_EQ_INT(refused, STALLED_SENDS);
    CHECK(n_taken > 100 && taken_before == n_taken, "the %s took %zu lines, all before the first refusal", kind,
          n_taken);
    const urrt_canlink_stats *st = urrt_canlink_get_stats(so);
    CHECK_EQ_INT(st->sent, n_taken);
    CHECK_EQ_INT(st->dropped, STALLED_SENDS);
    CHECK_EQ_INT(st->busy, STALLED_SENDS);
    CHECK_EQ_INT(st->send_errors, 0);
    CHECK_EQ_INT(st->pending, 0); /* both take a short line whole or not at all */
    CHECK_EQ_INT(count_substr(messages, "not keeping up"), 1);

    /* The reader comes back: whole lines, exactly the frames taken. */
    size_t len = drain_now(p[0], text, sizeof(text));
    uint64_t hi = urrt_port_realtime_us();
    if (stall_lines(text, len, got, TAKEN_MAX, &n_got, lo, hi)) {
        CHECK_EQ_INT(n_got, n_taken);
        CHECK(n_got == n_taken && memcmp(got, taken, n_got * sizeof(got[0])) == 0,
              "the lines read are the frames taken, in order");
    }

    /* Drained: every frame goes out again, and the recovery is said. */
    messages_clear();
    for (uint32_t k = 0; k < RESUMED; k++) {
        urrt_can_frame f = seq_frame(i + k);
        CHECK_EQ_INT(urrt_canlink_send(so, &f, now_us()), 1);
    }
    char said[64];
    snprintf(said, sizeof(said), "takes lines again; %d dropped meanwhile", STALLED_SENDS);
    CHECK(strstr(messages, said) != NULL, "logged: %s", messages);
    CHECK_EQ_INT(st->sent, n_taken + RESUMED);
    CHECK_EQ_INT(st->dropped, STALLED_SENDS);
    len = drain_now(p[0], text, sizeof(text));
    if (stall_lines(text, len, got, TAKEN_MAX, &n_got, lo, urrt_port_realtime_us())) {
        CHECK_EQ_INT(n_got, RESUMED);
        CHECK(n_got == RESUMED && got[0] == i && got[RESUMED - 1] == i + RESUMED - 1, "the resumed lines");
    }
    urrt_canlink_free(so);
out:
    alarm(0);
    CHECK(fcntl(STDOUT_FILENO, F_GETFD) >= 0, "stdout stays open after urrt_canlink_free");
    dup2(saved, STDOUT_FILENO);
    close(saved);
    close(p[0]);
}

/* A pty's master end, its slave in raw mode (bytes as written: no "\n" to
 * "\r\n") in *slave; -1 when there is none. */
static int open_raw_pty(int *slave)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY);
    *slave = -1;
    if (master >= 0 && grantpt(master) == 0 && unlockpt(master) == 0)
        *slave = open(ptsname(master), O_RDWR | O_NOCTTY);
    if (*slave < 0) {
        if (master >= 0)
            close(master);
        return -1;
    }
    struct termios raw;
    tcgetattr(*slave, &raw);
    cfmakeraw(&raw);
    tcsetattr(*slave, TCSANOW, &raw);
    return master;
}

/* What a test's reader has read so far. */
typedef struct stream_reader {
    int fd;
    size_t len, lines;
    char text[8192 * 40];
} stream_reader;

/* Reads at most max bytes of what arrives within timeout_ms. */
static void read_some(stream_reader *rd, size_t max, int timeout_ms)
{
    struct pollfd p = { .fd = rd->fd, .events = POLLIN };
    size_t room = sizeof(rd->text) - 1 - rd->len;
    if (room == 0 || poll(&p, 1, timeout_ms) != 1)
        return;
    ssize_t r = read(rd->fd, rd->text + rd->len, max < room ? max : room);
    for (ssize_t k = 0; k < r; k++)
        rd->lines += rd->text[rd->len + (size_t)k] == '\n';
    rd->len += r > 0 ? (size_t)r : 0;
    rd->text[rd->len] = '\0';
}

/* Sends frames numbered from *next until one goes to the terminal in part
 * (pending 1), recording those taken whole. Where the terminal's room runs
 * out is the kernel's affair: when a line is refused whole, the reader
 * frees a little and the writer fills again. Returns the calls that slept. */
static long fill_until_part(urrt_canlink *so, stream_reader *rd, int slave, uint32_t *next, uint32_t *taken,
                            size_t max, size_t *n_taken)
{
    const urrt_canlink_stats *st = urrt_canlink_get_stats(so);
    long slept = 0;
    for (int round = 0; round < 40 && st->pending == 0; round++) {
        while (st->pending == 0 && *n_taken < max) {
            urrt_can_frame f = seq_frame(*next);
            sleep_mark m = sleep_mark_now();
            int r = urrt_canlink_send(so, &f, now_us());
            slept += slept_since(m);
            if (r == 1)
                taken[(*n_taken)++] = *next;
            (*next)++;
            if (r == 0 && st->pending == 0)
                break; /* refused whole */
        }
        if (st->pending != 0)
            break;
        read_some(rd, 100, 1000);
        struct pollfd p = { .fd = slave, .events = POLLOUT };
        poll(&p, 1, 200); /* room comes when the kernel moves on what the reader left */
    }
    return slept;
}

/* log:- to a terminal whose reader stalls. Unlike a pipe, a terminal takes
 * part of a line when it has room for only part: the link keeps the tail
 * (pending 1), drops what comes meanwhile, and finishes the tail before any
 * other line, so the reader still sees whole lines only. */
static void test_log_tty(void)
{
    enum { MAX_LINES = 8192 };
    static uint32_t taken[MAX_LINES], got[MAX_LINES];
    static stream_reader rd;
    size_t n_taken = 0, n_got = 0;
    int slave;
    rd.fd = open_raw_pty(&slave);
    CHECK(rd.fd >= 0, "a pty: %s", strerror(errno));
    if (rd.fd < 0)
        return;
    fflush(stdout);
    int saved = dup(STDOUT_FILENO);
    dup2(slave, STDOUT_FILENO);
    signal(SIGALRM, stall_alarm);
    alarm(30);
    uint64_t lo = urrt_port_realtime_us();
    messages_clear();
    urrt_canlink *so = open_link("log:-,ifname=can1", false, false);
    CHECK(so != NULL, "log:- link on a terminal");
    if (so == NULL)
        goto out;
    const urrt_canlink_stats *st = urrt_canlink_get_stats(so);
    uint32_t next = 0;
    capture_quiet = true;
    long slept = fill_until_part(so, &rd, slave, &next, taken, MAX_LINES - 1, &n_taken);
    uint32_t in_part = next - 1;
    fprintf(stderr, "  terminal: %zu lines taken whole, line %u went in part\n", n_taken, (unsigned)in_part);
    CHECK(st->pending == 1, "a line went to the terminal in part");
    /* While the tail waits, new frames are dropped, and no call sleeps. */
    uint64_t dropped0 = st->dropped;
    for (uint32_t k = 0; k < 3; k++) {
        urrt_can_frame f = seq_frame(next++);
        sleep_mark m = sleep_mark_now();
        CHECK_EQ_INT(urrt_canlink_send(so, &f, now_us()), 0);
        slept += slept_since(m);
    }
    capture_quiet = false;
    fprintf(stderr, "%s", messages);
    CHECK_EQ_INT(st->dropped, dropped0 + 3);
    CHECK_EQ_INT(slept, 0);
    CHECK(urrt_canlink_deadline(so) != UINT64_MAX, "a waiting tail is due for a retry");
    /* The reader drains; the link finishes the tail when its retry is due. */
    for (int waited = 0; st->pending != 0 && waited < 5000; waited += 10) {
        read_some(&rd, SIZE_MAX, 10);
        if (now_us() >= urrt_canlink_deadline(so))
            urrt_canlink_service(so, now_us());
    }
    CHECK_EQ_INT(st->pending, 0);
    taken[n_taken++] = in_part;
    CHECK_EQ_INT(st->sent, n_taken);
    /* The rest, as the kernel passes it on: a line for each frame taken. */
    for (int waited = 0; rd.lines < n_taken && waited < 5000; waited += 10)
        read_some(&rd, SIZE_MAX, 10);
    if (stall_lines(rd.text, rd.len, got, MAX_LINES, &n_got, lo, urrt_port_realtime_us())) {
        CHECK_EQ_INT(n_got, n_taken);
        CHECK(n_got == n_taken && memcmp(got, taken, n_got * sizeof(got[0])) == 0,
              "the lines read are the frames taken, the one written in part among them, in order");
    }
    urrt_canlink_free(so);
out:
    alarm(0);
    dup2(saved, STDOUT_FILENO);
    close(saved);
    close(slave);
    close(rd.fd);
}

/* A reader that takes one byte per read: far slower than the link writes. */
static void *slow_reader(void *arg)
{
    int rd = *(int *)arg;
    static char text[8192 * 40];
    size_t n = 0;
    ssize_t r;
    while (n < sizeof(text) - 1 && (r = read(rd, text + n, 1)) > 0)
        n += (size_t)r;
    text[n] = '\0';
    return text;
}

/* With log_caller_clock (urrt-gateway --replay) log:- waits for its reader:
 * a replay's point is every frame, and it has no live loop to keep going.
 * A reader far slower than the link still gets every line. */
static void test_log_replay_waits(void)
{
    enum { N = 4000 };
    static uint32_t got[N];
    size_t n_got = 0;
    int p[2];
    CHECK(pipe(p) == 0, "pipe: %s", strerror(errno));
    fflush(stdout);
    int saved = dup(STDOUT_FILENO);
    dup2(p[1], STDOUT_FILENO);
    close(p[1]);
    urrt_canlink_config cfg;
    urrt_canlink_config_defaults(&cfg);
    cfg.interface = "log:-,ifname=can1";
    cfg.log_caller_clock = true;
    urrt_canlink *so = urrt_canlink_new(&cfg);
    pthread_t reader;
    pthread_create(&reader, NULL, slow_reader, &p[0]);
    int taken = 0;
    for (uint32_t i = 0; so != NULL && i < N; i++) {
        urrt_can_frame f = seq_frame(i);
        taken += urrt_canlink_send(so, &f, 1000000u + i) == 1;
    }
    urrt_canlink_free(so);
    dup2(saved, STDOUT_FILENO); /* the pipe's last writer gone: the reader sees its end */
    close(saved);
    void *text;
    pthread_join(reader, &text);
    close(p[0]);
    CHECK(so != NULL, "log:- link with the caller's clock");
    CHECK_EQ_INT(taken, N);
    if (stall_lines(text, strlen(text), got, N, &n_got, 1000000u, 1000000u + N)) {
        CHECK_EQ_INT(n_got, N);
        CHECK(n_got == N && got[0] == 0 && got[N - 1] == N - 1, "every line, in order");
    }
}

/* urrt_canlink_set_rx_ids on a log link, which receives nothing: the
 * same rules as at creation (11-bit ids, at most the kernel's list), the
 * refusals naming the link and the id, and the link sending on. */
static void test_log_rx_ids(urrt_canlink *cc)
{
    static uint32_t many[URRT_CANLINK_RX_IDS_MAX + 1];
    static const uint32_t node[] = {0x000, 0x081, 0x605};
    static const uint32_t wide[] = {0x000, 0x800};
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(cc, node, 3), 0);
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(cc, NULL, 0), 0);
    messages_clear();
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(cc, wide, 2), URRT_E_ARG);
    CHECK(strstr(messages, "log-classic.log: receive id 0x800 is not an 11-bit standard id") != NULL,
          "the refusal names the link and the id: %s", messages);
    messages_clear();
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(cc, many, URRT_CANLINK_RX_IDS_MAX + 1), URRT_E_ARG);
    CHECK(strstr(messages, "513 receive ids, more than the kernel's filter takes (512)") != NULL, "reason: %s",
          messages);
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(cc, many, URRT_CANLINK_RX_IDS_MAX), 0);
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(cc, NULL, 1), URRT_E_ARG);
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(NULL, node, 3), URRT_E_ARG);
    CHECK_EQ_INT(urrt_canlink_get_state(cc), URRT_CANLINK_UP);
}

static int test_log(const char *dir)
{
    char path_fd[512], path_cc[512], path_out[512], path_expect[512], spec[600];
    snprintf(path_fd, sizeof(path_fd), "%s/log-fd.log", dir);
    snprintf(path_cc, sizeof(path_cc), "%s/log-classic.log", dir);
    snprintf(path_out, sizeof(path_out), "%s/log-stdout.log", dir);
    snprintf(path_expect, sizeof(path_expect), "%s/log-expect.txt", dir);
    FILE *expect = fopen(path_expect, "w");
    CHECK(expect != NULL, "cannot create %s", path_expect);
    if (expect == NULL)
        return check_report();
    uint64_t lo = urrt_port_realtime_us();

    /* An FD link with the bit rate switch, interface column vcan0. */
    snprintf(spec, sizeof(spec), "log:%s,ifname=vcan0", path_fd);
    urrt_canlink *fd = open_link(spec, true, true);
    CHECK(fd != NULL, "log link %s", spec);
    /* A classic link with the default interface column. */
    snprintf(spec, sizeof(spec), "log:%s", path_cc);
    urrt_canlink *cc = open_link(spec, false, false);
    CHECK(cc != NULL, "log link %s", spec);
    if (fd == NULL || cc == NULL)
        return check_report();

    short events;
    CHECK_EQ_INT(urrt_canlink_poll_fd(fd, &events), -1);
    CHECK(urrt_canlink_deadline(fd) == UINT64_MAX, "a log link has nothing due");
    CHECK_EQ_INT(urrt_canlink_get_state(fd), URRT_CANLINK_UP);

    enum { N_FD = sizeof(log_fd_cases) / sizeof(log_fd_cases[0]),
           N_CC = sizeof(log_classic_cases) / sizeof(log_classic_cases[0]) };
    const char *want_fd[N_FD], *want_cc[N_CC];
    for (size_t i = 0; i < N_FD; i++) {
        urrt_can_frame f = case_frame(&log_fd_cases[i]);
        CHECK_EQ_INT(timed_log_send(fd, &f), 1);
        expect_line(expect, "log-fd.log", &f, true);
        want_fd[i] = log_fd_cases[i].line;
    }
    for (size_t i = 0; i < N_CC; i++) {
        urrt_can_frame f = case_frame(&log_classic_cases[i]);
        CHECK_EQ_INT(timed_log_send(cc, &f), 1);
        expect_line(expect, "log-classic.log", &f, false);
        want_cc[i] = log_classic_cases[i].line;
    }

    /* Frames no link can send. */
    urrt_can_frame bad = make_frame(0x100, false, true, 8, 0);
    CHECK_EQ_INT(urrt_canlink_send(cc, &bad, now_us()), URRT_E_ARG); /* FD on a classic link */
    bad = make_frame(0x100, false, false, 9, 0);
    CHECK_EQ_INT(urrt_canlink_send(cc, &bad, now_us()), URRT_E_ARG);
    bad = make_frame(0x100, false, true, 13, 0);
    CHECK_EQ_INT(urrt_canlink_send(fd, &bad, now_us()), URRT_E_ARG);
    bad = make_frame(0x100, false, true, 64, 0);
    bad.len = 65;
    CHECK_EQ_INT(urrt_canlink_send(fd, &bad, now_us()), URRT_E_ARG);
    bad = make_frame(0x800, false, false, 1, 0);
    CHECK_EQ_INT(urrt_canlink_send(cc, &bad, now_us()), URRT_E_ARG);
    bad = make_frame(0x20000000, true, false, 1, 0);
    CHECK_EQ_INT(urrt_canlink_send(cc, &bad, now_us()), URRT_E_ARG);
    CHECK_EQ_INT(urrt_canlink_send(cc, NULL, now_us()), URRT_E_ARG);
    test_log_rx_ids(cc);
    CHECK_EQ_INT(urrt_canlink_get_stats(fd)->sent, N_FD);
    CHECK_EQ_INT(urrt_canlink_get_stats(cc)->sent, N_CC);
    CHECK_EQ_INT(urrt_canlink_get_stats(cc)->dropped, 0);
    urrt_canlink_free(fd);
    urrt_canlink_free(cc);

    /* log:- writes to stdout: point stdout at a file for the moment. */
    fflush(stdout);
    int saved = dup(STDOUT_FILENO);
    int out = open(path_out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, STDOUT_FILENO);
    close(out);
    urrt_canlink *so = open_link("log:-,ifname=can1", false, false);
    urrt_can_frame f = case_frame(&(log_case){ 0x5A5, false, false, 4, "c3d4e5f6", NULL });
    int r = so ? urrt_canlink_send(so, &f, now_us()) : -99;
    urrt_canlink_free(so);
    int still_open = fcntl(STDOUT_FILENO, F_GETFD);
    dup2(saved, STDOUT_FILENO);
    close(saved);
    CHECK(so != NULL, "log:- link");
    CHECK_EQ_INT(r, 1);
    CHECK(still_open >= 0, "stdout stays open after urrt_canlink_free");
    expect_line(expect, "log-stdout.log", &f, false);
    fclose(expect);

    uint64_t hi = urrt_port_realtime_us();
    static const char *const want_out[] = { "can1 5A5#C3D4E5F6" };
    check_log_file(path_fd, want_fd, N_FD, lo, hi);
    check_log_file(path_cc, want_cc, N_CC, lo, hi);
    check_log_file(path_out, want_out, 1, lo, hi);

    /* Unusable log specifications fail at creation, with a reason. */
    messages_clear();
    CHECK(open_link("log:", false, false) == NULL, "empty path");
    CHECK(strstr(messages, "no path") != NULL, "reason: %s", messages);
    messages_clear();
    CHECK(open_link("log:/nonexistent-dir/x.log", false, false) == NULL, "uncreatable file");
    CHECK(strstr(messages, "/nonexistent-dir/x.log") != NULL, "reason names the file: %s", messages);
    messages_clear();
    snprintf(spec, sizeof(spec), "log:%s/x.log,ifname=averyveryverylongname", dir);
    CHECK(open_link(spec, false, false) == NULL, "long ifname");
    CHECK(strstr(messages, "ifname") != NULL, "reason: %s", messages);
    test_log_stall(false);
    test_log_stall(true);
    test_log_tty();
    test_log_replay_waits();
    /* Only files were written here: said, not held to "never sleeps" (see call_ended). */
    printf("log writes that waited on the filesystem: %u; calls that slept in a page fault: %u (longest call %" PRIu64
           " us)\n", file_waits, fault_sleeps, max_call_us);
    return check_report();
}

/* ---- frames: what goes on the wire ---------------------------------------------- */

static int test_frames(const char *dir)
{
    char spec0[600], spec1[600];
    snprintf(spec0, sizeof(spec0), "log:%s/frames-vcan0.log,ifname=vcan0", dir);
    snprintf(spec1, sizeof(spec1), "log:%s/frames-vcan1.log,ifname=vcan1", dir);
    int rx0 = rx_open("vcan0"), rx1 = rx_open("vcan1");
    urrt_canlink *fd = open_link("vcan0", true, true);
    urrt_canlink *fd_nobrs = open_link("vcan0", true, false);
    urrt_canlink *cc = open_link("vcan1", false, false);
    urrt_canlink *log_fd = open_link(spec0, true, true);
    urrt_canlink *log_cc = open_link(spec1, false, false);
    CHECK(rx0 >= 0 && rx1 >= 0, "receivers");
    CHECK(fd && fd_nobrs && cc && log_fd && log_cc, "links");
    if (!(rx0 >= 0 && rx1 >= 0 && fd && fd_nobrs && cc && log_fd && log_cc))
        return check_report();
    CHECK_EQ_INT(urrt_canlink_get_state(fd), URRT_CANLINK_UP);
    CHECK_EQ_INT(urrt_canlink_get_stats(fd)->opens, 1);

    enum { N_FD = sizeof(fd_set_) / sizeof(fd_set_[0]), N_CC = sizeof(classic_set) / sizeof(classic_set[0]) };
    urrt_can_frame sent0[N_FD + 1], sent1[N_CC];
    for (size_t i = 0; i < N_FD; i++) {
        sent0[i] = make_frame(fd_set_[i].id, fd_set_[i].ext, fd_set_[i].fd, fd_set_[i].len, (uint8_t)(0x31 * i));
        CHECK_EQ_INT(timed_send(fd, &sent0[i]), 1);
        CHECK_EQ_INT(timed_log_send(log_fd, &sent0[i]), 1);
    }
    /* Without the bit rate switch: flags nibble 4 in the capture. */
    sent0[N_FD] = make_frame(0x1F0, false, true, 16, 0x77);
    CHECK_EQ_INT(timed_send(fd_nobrs, &sent0[N_FD]), 1);
    for (size_t i = 0; i < N_CC; i++) {
        sent1[i] = make_frame(classic_set[i].id, classic_set[i].ext, false, classic_set[i].len, (uint8_t)(0x13 * i + 1));
        CHECK_EQ_INT(timed_send(cc, &sent1[i]), 1);
        CHECK_EQ_INT(timed_log_send(log_cc, &sent1[i]), 1);
    }
    urrt_can_frame fd_on_cc = make_frame(0x100, false, true, 8, 0);
    CHECK_EQ_INT(urrt_canlink_send(cc, &fd_on_cc, now_us()), URRT_E_ARG);

    rx_frame rx[32];
    size_t n = rx_collect(rx0, rx, 32, 100);
    CHECK_EQ_INT(n, N_FD + 1);
    for (size_t i = 0; i < n && i < N_FD + 1; i++)
        CHECK(rx_matches(&rx[i], &sent0[i], i < N_FD), "vcan0 frame %zu: id %X len %u fd %d", i,
              (unsigned)rx[i].f.can_id, rx[i].f.len, rx[i].fd);
    n = rx_collect(rx1, rx, 32, 100);
    CHECK_EQ_INT(n, N_CC);
    for (size_t i = 0; i < n && i < N_CC; i++)
        CHECK(rx_matches(&rx[i], &sent1[i], false), "vcan1 frame %zu: id %X len %u", i, (unsigned)rx[i].f.can_id,
              rx[i].f.len);
    CHECK_EQ_INT(urrt_canlink_get_stats(fd)->sent, N_FD);
    CHECK_EQ_INT(urrt_canlink_get_stats(cc)->sent, N_CC);
    CHECK_EQ_INT(urrt_canlink_get_stats(cc)->dropped, 0);

    /* The frame without BRS goes to the log too, from a log link without BRS. */
    urrt_canlink_free(log_fd);
    snprintf(spec0, sizeof(spec0), "log:%s/frames-vcan0-nobrs.log,ifname=vcan0", dir);
    log_fd = open_link(spec0, true, false);
    CHECK(log_fd != NULL && timed_log_send(log_fd, &sent0[N_FD]) == 1, "log without BRS");

    urrt_canlink_free(fd);
    urrt_canlink_free(fd_nobrs);
    urrt_canlink_free(cc);
    urrt_canlink_free(log_fd);
    urrt_canlink_free(log_cc);
    close(rx0);
    close(rx1);
    CHECK(blocked_calls == 0, "%u calls into socket links slept (longest call %" PRIu64 " us)", blocked_calls,
          max_call_us);
    printf("log writes that waited on the filesystem: %u; calls that slept in a page fault: %u\n", file_waits,
           fault_sleeps);
    return check_report();
}

/* ---- socket behaviour -------------------------------------------------------------- */

static void test_refusals(void)
{
    messages_clear();
    CHECK(open_link("vcan1", true, false) == NULL, "FD link on the classic-MTU vcan1");
    CHECK(strstr(messages, "vcan1") != NULL && strstr(messages, "ip link set vcan1 mtu 72") != NULL,
          "the reason names the interface and the fix: %s", messages);
    messages_clear();
    CHECK(open_link("vcan9", false, false) == NULL, "no such interface");
    CHECK(strstr(messages, "vcan9") != NULL && strstr(messages, "no such interface") != NULL, "reason: %s",
          messages);
    messages_clear();
    CHECK(open_link("lo", false, false) == NULL, "not a CAN interface");
    CHECK(strstr(messages, "not a CAN interface") != NULL, "reason: %s", messages);
    messages_clear();
    CHECK(open_link("averyveryverylongname", false, false) == NULL, "name too long");
    /* A classic link on an FD interface is fine. */
    urrt_canlink *cc = open_link("vcan0", false, false);
    CHECK(cc != NULL && urrt_canlink_get_state(cc) == URRT_CANLINK_UP, "classic link on vcan0");
    urrt_canlink_free(cc);
}

static void test_no_data_frames(void)
{
    urrt_canlink *can = open_link("vcan0", true, false);
    int tx = rx_open("vcan0");
    CHECK(can != NULL && tx >= 0, "link and sender");
    if (can == NULL || tx < 0)
        return;
    for (int i = 0; i < 20; i++) {
        struct can_frame f = { .can_id = 0x123, .can_dlc = 8 };
        CHECK(write(tx, &f, sizeof(f)) == (ssize_t)sizeof(f), "sender write: %s", strerror(errno));
    }
    short events;
    int fd = urrt_canlink_poll_fd(can, &events);
    CHECK(fd >= 0 && (events & POLLIN), "waits for POLLIN (error frames)");
    struct pollfd p = { .fd = fd, .events = events };
    CHECK_EQ_INT(poll(&p, 1, 200), 0); /* 20 data frames on the bus, none for the link */
    pump(can, 20);
    CHECK_EQ_INT(urrt_canlink_get_stats(can)->error_frames, 0);
    close(tx);
    urrt_canlink_free(can);
}

static void test_error_frames(void)
{
    urrt_canlink *can = open_link("vcan0", false, false);
    int tx = rx_open("vcan0");
    CHECK(can != NULL && tx >= 0, "link and injector");
    if (can == NULL || tx < 0)
        return;
    /* vcan has no controller to report errors, but an error frame written to
     * it reaches every socket subscribed to errors, as a driver's would. */
    struct can_frame e[3];
    memset(e, 0, sizeof(e));
    e[0].can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
    e[1].can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED;
    e[2].can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
    e[2].data[1] = CAN_ERR_CRTL_TX_WARNING;
    for (int i = 0; i < 3; i++) {
        e[i].can_dlc = CAN_ERR_DLC;
        CHECK(write(tx, &e[i], sizeof(e[i])) == (ssize_t)sizeof(e[i]), "inject error frame: %s", strerror(errno));
    }
    messages_clear();
    short seen = pump(can, 100);
    CHECK(seen & POLLIN, "error frames wake the loop");
    const urrt_canlink_stats *st = urrt_canlink_get_stats(can);
    CHECK_EQ_INT(st->error_frames, 3);
    CHECK_EQ_INT(st->bus_off, 1);
    CHECK_EQ_INT(st->restarts, 1);
    CHECK_EQ_INT(st->last_error_class, CAN_ERR_CRTL);
    CHECK(strstr(messages, "bus-off") != NULL, "bus-off logged: %s", messages);
    CHECK(strstr(messages, "restarted") != NULL, "restart logged: %s", messages);
    CHECK(!st->error_passive, "a warning is not error passive");
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    /* Error passive holds from the controller's word until it says error active. */
    static const uint8_t states[] = {CAN_ERR_CRTL_RX_PASSIVE, CAN_ERR_CRTL_TX_WARNING, CAN_ERR_CRTL_ACTIVE};
    static const bool passive_after[] = {true, true, false};
    for (int i = 0; i < 3; i++) {
        struct can_frame f = {.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL, .can_dlc = CAN_ERR_DLC};
        f.data[1] = states[i];
        CHECK(write(tx, &f, sizeof f) == (ssize_t)sizeof f, "inject error frame: %s", strerror(errno));
        /* vcan delivers on write: the frame is queued; a bound, not a sleep. */
        for (unsigned waited = 0; st->error_frames < (uint64_t)(4 + i) && waited < 1000; waited += 10)
            pump(can, 10);
        CHECK_EQ_INT(st->error_frames, 4 + i);
        CHECK(st->error_passive == passive_after[i], "controller state 0x%02X: error passive %d", states[i],
              (int)st->error_passive);
    }
    close(tx);
    urrt_canlink_free(can);
}

/* ENOBUFS, as a controller that cannot get frames onto the bus causes it: the
 * plug qdisc holds what it has taken and refuses the rest. */
static void test_queue_full(void)
{
    RUN("tc", "qdisc", "add", "dev", "vcan1", "root", "plug", "limit", "160"); /* 10 classic frames */
    urrt_canlink *can = open_link("vcan1", false, false);
    int rx = rx_open("vcan1");
    CHECK(can != NULL && rx >= 0, "link and receiver");
    if (can == NULL || rx < 0)
        return;
    const urrt_canlink_stats *st = urrt_canlink_get_stats(can);
    for (uint32_t i = 0; i < 10; i++) {
        urrt_can_frame f = make_frame(0x200 + i, false, false, 8, (uint8_t)i);
        CHECK_EQ_INT(timed_send(can, &f), 1);
    }
    messages_clear();
    /* The queue is full: 0x20A and 0x20B are held, each newer value
     * replacing the older one and counting a drop. */
    urrt_can_frame last_a, last_b;
    int not_held = 0;
    for (int i = 0; i < 500; i++) {
        last_a = make_frame(0x20A, false, false, 8, (uint8_t)(2 * i));
        last_b = make_frame(0x20B, false, false, 2, (uint8_t)(2 * i + 1));
        not_held += timed_send(can, &last_a) != 0;
        not_held += timed_send(can, &last_b) != 0;
        if (i % 50 == 0)
            pump(can, 1);
    }
    CHECK(not_held == 0, "%d of 1000 sends into a full queue did not return 0 (held)", not_held);
    CHECK_EQ_INT(st->sent, 10);
    CHECK_EQ_INT(st->pending, 2);
    CHECK_EQ_INT(st->dropped, 998);
    CHECK(st->busy >= 1000, "busy %" PRIu64, st->busy);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    CHECK_EQ_INT(count_substr(messages, "transmit queue full"), 1);
    /* 40 more IDs, one the 29-bit twin of 0x20A: each gets a slot of its own
     * (and the slot table grows past its first allocation). */
    urrt_can_frame twin = make_frame(0x20A, true, false, 1, 0x99);
    not_held = timed_send(can, &twin) != 0;
    for (uint32_t id = 0x210; id < 0x237; id++) {
        urrt_can_frame f = make_frame(id, false, false, 1, (uint8_t)id);
        not_held += timed_send(can, &f) != 0;
    }
    CHECK_EQ_INT(not_held, 0);
    CHECK_EQ_INT(st->pending, 42);
    CHECK_EQ_INT(st->dropped, 998);
    short events;
    urrt_canlink_poll_fd(can, &events);
    CHECK(!(events & POLLOUT), "no POLLOUT wait on ENOBUFS: the socket would report writable at once");
    CHECK(urrt_canlink_deadline(can) <= now_us() + 5000u + 1000u, "a retry is scheduled");

    /* The queue drains: the held frames go out, the newest value of each,
     * once. */
    RUN("tc", "qdisc", "change", "dev", "vcan1", "root", "plug", "release_indefinite");
    pump_until_idle(can, 2000);
    CHECK_EQ_INT(st->pending, 0);
    CHECK_EQ_INT(st->sent, 52);
    CHECK(strstr(messages, "takes frames again") != NULL, "recovery logged: %s", messages);
    rx_frame got[64];
    size_t n = rx_collect(rx, got, 64, 100);
    CHECK_EQ_INT(n, 52);
    CHECK_EQ_INT(count_id(got, n, 0x20A), 1);
    CHECK_EQ_INT(count_id(got, n, 0x20B), 1);
    CHECK_EQ_INT(count_id(got, n, 0x20A | CAN_EFF_FLAG), 1);
    /* Held frames leave in the order they were first held. */
    bool order_ok = n == 52 && got[10].f.can_id == 0x20A && got[11].f.can_id == 0x20B &&
                       got[12].f.can_id == (0x20A | CAN_EFF_FLAG);
    for (size_t i = 13; order_ok && i < n; i++)
        order_ok = got[i].f.can_id == 0x210 + (i - 13);
    CHECK(order_ok, "held frames in the order first held");
    const rx_frame *a = last_of_id(got, n, 0x20A), *b = last_of_id(got, n, 0x20B);
    CHECK(a != NULL && rx_matches(a, &last_a, false), "0x20A carries the newest value");
    CHECK(b != NULL && rx_matches(b, &last_b, false), "0x20B carries the newest value");

    /* A value held longer than hold_max_ms is stale: dropped, never sent. */
    urrt_canlink_free(can);
    can = open_link_hold("vcan1", false, false, 200);
    CHECK(can != NULL, "link with hold_max_ms 200");
    if (can == NULL)
        return;
    st = urrt_canlink_get_stats(can);
    RUN("tc", "qdisc", "del", "dev", "vcan1", "root");
    RUN("tc", "qdisc", "add", "dev", "vcan1", "root", "plug", "limit", "16");
    urrt_can_frame first = make_frame(0x300, false, false, 1, 1), stale = make_frame(0x301, false, false, 1, 2);
    CHECK_EQ_INT(timed_send(can, &first), 1);
    CHECK_EQ_INT(timed_send(can, &stale), 0);
    uint64_t dropped = st->dropped;
    CHECK(urrt_canlink_deadline(can) <= now_us() + 200000u + 1000u, "the held frame's expiry is a deadline");
    pump(can, 350); /* hold_max_ms 200 */
    CHECK_EQ_INT(st->pending, 0);
    CHECK_EQ_INT(st->dropped, dropped + 1);
    RUN("tc", "qdisc", "change", "dev", "vcan1", "root", "plug", "release_indefinite");
    pump(can, 20);
    n = rx_collect(rx, got, 64, 100);
    CHECK_EQ_INT(count_id(got, n, 0x300), 1);
    CHECK_EQ_INT(count_id(got, n, 0x301), 0);

    RUN("tc", "qdisc", "del", "dev", "vcan1", "root");
    close(rx);
    urrt_canlink_free(can);
}

/* EAGAIN: the socket's own buffer is full (the kernel keeps charging a
 * frame to it while a qdisc holds it). Here POLLOUT is the signal to retry. */
static void test_socket_buffer_full(void)
{
    RUN("tc", "qdisc", "add", "dev", "vcan1", "root", "plug", "limit", "1000000");
    urrt_canlink *can = open_link("vcan1", false, false);
    int rx = rx_open("vcan1");
    CHECK(can != NULL && rx >= 0, "link and receiver");
    if (can == NULL || rx < 0)
        return;
    short events;
    int fd = urrt_canlink_poll_fd(can, &events);
    int tiny = 1; /* the kernel's minimum: a few frames */
    CHECK(setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &tiny, sizeof(tiny)) == 0, "SO_SNDBUF");
    const urrt_canlink_stats *st = urrt_canlink_get_stats(can);
    uint64_t t0 = now_us();
    urrt_can_frame last[4];
    int refused = 0;
    for (int i = 0; i < 2000; i++) {
        last[i % 4] = make_frame(0x400 + (uint32_t)(i % 4), false, false, 8, (uint8_t)i);
        refused += timed_send(can, &last[i % 4]) < 0;
    }
    CHECK(refused == 0, "%d valid frames refused", refused);
    uint64_t flood_us = now_us() - t0;
    CHECK(st->sent > 0 && st->sent < 100, "the buffer took %" PRIu64 " frames", st->sent);
    CHECK_EQ_INT(st->pending, 4);
    CHECK_EQ_INT(st->sent + st->dropped + st->pending, 2000);
    CHECK(flood_us < 2000000u, "2000 sends took %" PRIu64 " us", flood_us);
    fd = urrt_canlink_poll_fd(can, &events);
    CHECK(events & POLLOUT, "waits for POLLOUT after EAGAIN");
    struct pollfd p = { .fd = fd, .events = POLLOUT };
    CHECK_EQ_INT(poll(&p, 1, 100), 0); /* still full: no spin */

    uint64_t sent_before = st->sent;
    RUN("tc", "qdisc", "change", "dev", "vcan1", "root", "plug", "release_indefinite");
    short seen = pump_until_idle(can, 2000);
    CHECK(seen & POLLOUT, "POLLOUT woke the loop");
    CHECK_EQ_INT(st->pending, 0);
    CHECK_EQ_INT(st->sent, sent_before + 4);
    rx_frame got[128];
    size_t n = rx_collect(rx, got, 128, 100);
    CHECK_EQ_INT(n, st->sent);
    for (uint32_t id = 0x400; id < 0x404; id++) {
        const rx_frame *r = last_of_id(got, n, id);
        CHECK(r != NULL && rx_matches(r, &last[id - 0x400], false), "0x%X ends with the newest value", id);
    }
    RUN("tc", "qdisc", "del", "dev", "vcan1", "root");
    close(rx);
    urrt_canlink_free(can);
}

static void test_down_up(void)
{
    urrt_canlink *can = open_link("vcan0", true, false);
    int rx = rx_open("vcan0");
    CHECK(can != NULL && rx >= 0, "link and receiver");
    if (can == NULL || rx < 0)
        return;
    const urrt_canlink_stats *st = urrt_canlink_get_stats(can);
    rx_frame got[64];

    /* A frame held in the slot when the interface goes down is discarded. */
    RUN("tc", "qdisc", "add", "dev", "vcan0", "root", "plug", "limit", "72");
    urrt_can_frame f1 = make_frame(0x500, false, true, 64, 1), f2 = make_frame(0x501, false, true, 64, 2);
    CHECK_EQ_INT(timed_send(can, &f1), 1);
    CHECK_EQ_INT(timed_send(can, &f2), 0);
    CHECK_EQ_INT(st->pending, 1);
    messages_clear();
    RUN("ip", "link", "set", "vcan0", "down");
    short seen = pump_until_state(can, URRT_CANLINK_DOWN, 2000);
    CHECK(seen & (POLLERR | POLLIN), "the down event wakes the loop");
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    CHECK_EQ_INT(st->down_events, 1);
    CHECK_EQ_INT(st->pending, 0);
    CHECK_EQ_INT(st->dropped, 1);
    short events;
    CHECK_EQ_INT(urrt_canlink_poll_fd(can, &events), -1);
    CHECK(strstr(messages, "vcan0: down") != NULL, "down logged: %s", messages);
    /* Sent while down: dropped and counted, never replayed. */
    for (int i = 0; i < 5; i++) {
        urrt_can_frame f = make_frame(0x502, false, true, 8, (uint8_t)i);
        CHECK_EQ_INT(timed_send(can, &f), 0);
    }
    CHECK_EQ_INT(st->dropped, 6);
    pump(can, 200); /* a few reopen attempts: logged once */
    CHECK_EQ_INT(count_substr(messages, "vcan0: down"), 1); /* not once per reopen attempt */
    CHECK_EQ_INT(count_substr(messages, "still down"), 0);
    RUN("tc", "qdisc", "del", "dev", "vcan0", "root");
    RUN("ip", "link", "set", "vcan0", "up");
    rx_collect(rx, got, 64, 50); /* the receiver's own error and the plugged frame */
    pump_until_state(can, URRT_CANLINK_UP, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    CHECK_EQ_INT(st->opens, 2);
    CHECK(strstr(messages, "up again") != NULL, "recovery logged: %s", messages);
    urrt_can_frame f3 = make_frame(0x503, false, true, 12, 3);
    CHECK_EQ_INT(timed_send(can, &f3), 1);
    size_t n = rx_collect(rx, got, 64, 100);
    CHECK_EQ_INT(n, 1);
    CHECK(n >= 1 && rx_matches(&got[0], &f3, false), "the first frame after the outage is the new one");

    /* Removed and created again: a new ifindex, found by name. */
    messages_clear();
    RUN("ip", "link", "del", "vcan0");
    pump_until_state(can, URRT_CANLINK_DOWN, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    CHECK_EQ_INT(st->down_events, 2);
    CHECK(strstr(messages, "removed") != NULL, "removal logged: %s", messages);
    RUN("ip", "link", "add", "dev", "vcan0", "type", "vcan");
    RUN("ip", "link", "set", "vcan0", "mtu", "72");
    RUN("ip", "link", "set", "vcan0", "up");
    pump_until_state(can, URRT_CANLINK_UP, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    CHECK_EQ_INT(st->opens, 3);
    close(rx);
    rx = rx_open("vcan0");
    CHECK_EQ_INT(timed_send(can, &f3), 1);
    n = rx_collect(rx, got, 64, 100);
    CHECK(n == 1 && rx_matches(&got[0], &f3, false), "frames flow on the new vcan0");

    /* The MTU shrinks while down: an FD link stays down and says why. */
    messages_clear();
    RUN("ip", "link", "set", "vcan0", "down");
    RUN("ip", "link", "set", "vcan0", "mtu", "16");
    RUN("ip", "link", "set", "vcan0", "up");
    for (int waited = 0; strstr(messages, "mtu 72") == NULL && waited < 2000; waited += 10)
        pump(can, 10); /* until a reopen attempt has seen the interface up */
    pump(can, 100);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    CHECK(strstr(messages, "mtu 72") != NULL, "MTU reason logged: %s", messages);
    RUN("ip", "link", "set", "vcan0", "down");
    RUN("ip", "link", "set", "vcan0", "mtu", "72");
    RUN("ip", "link", "set", "vcan0", "up");
    pump_until_state(can, URRT_CANLINK_UP, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    close(rx);
    urrt_canlink_free(can);

    /* Created while the interface is down: a link that opens later. */
    RUN("ip", "link", "set", "vcan1", "down");
    messages_clear();
    can = open_link("vcan1", false, false);
    CHECK(can != NULL, "a link on a down interface");
    if (can == NULL)
        return;
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    CHECK(strstr(messages, "vcan1: down (interface is down)") != NULL, "logged: %s", messages);
    pump(can, 120);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    RUN("ip", "link", "set", "vcan1", "up");
    pump_until_state(can, URRT_CANLINK_UP, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    CHECK_EQ_INT(urrt_canlink_get_stats(can)->opens, 1);
    CHECK_EQ_INT(urrt_canlink_get_stats(can)->down_events, 0);
    urrt_canlink_free(can);
}

/* What a link's rx function was handed. */
typedef struct rx_seen {
    uint32_t ids[64];
    size_t count;
} rx_seen;

static void on_rx(void *ctx, const urrt_can_frame *frame, uint64_t rx_us)
{
    rx_seen *s = ctx;
    (void)rx_us;
    if (s->count < sizeof s->ids / sizeof s->ids[0])
        s->ids[s->count] = frame->id;
    s->count++;
}

/* Sends 0x080, 0x081 and 0x7E0 (a third id, handed in every round) in that
 * order and pumps until 0x7E0 arrives (bounded): frames on one bus reach a
 * socket in order, so whatever of the first two the filter lets in came
 * before it. Returns what was handed, 0x7E0 the last. */
static size_t sync_round(urrt_canlink *can, int tx, rx_seen *s)
{
    static const canid_t ids[] = {0x080, 0x081, 0x7E0};
    s->count = 0;
    for (size_t i = 0; i < 3; i++) {
        struct can_frame f = {.can_id = ids[i], .can_dlc = 0};
        CHECK(write(tx, &f, sizeof(f)) == (ssize_t)sizeof(f), "sender write: %s", strerror(errno));
    }
    for (unsigned waited = 0; (s->count == 0 || s->ids[s->count - 1] != 0x7E0) && waited < 5000; waited += 10)
        pump(can, 10);
    CHECK(s->count > 0 && s->ids[s->count - 1] == 0x7E0, "the round's last frame 0x7E0 arrived (%zu handed)",
          s->count);
    return s->count;
}

/* urrt_canlink_set_rx_ids on vcan1: the kernel's filter replaced at once
 * (a CANopen node's SYNC moved from 0x080 to 0x081), kept across the
 * interface going down and up, set while down for the reopen; ids the link
 * cannot take refused, the filter kept. */
static void test_set_rx_ids(void)
{
    static const uint32_t at_080[] = {0x000, 0x080, 0x7E0}, at_081[] = {0x000, 0x081, 0x7E0};
    static const uint32_t wide[] = {0x081, 0x800};
    urrt_canlink_config cfg;
    rx_seen s = {{0}, 0};
    urrt_canlink_config_defaults(&cfg);
    cfg.interface = "vcan1";
    cfg.reopen_interval_ms = 50;
    cfg.rx_ids = at_080;
    cfg.rx_id_count = 3;
    urrt_canlink *can = urrt_canlink_new(&cfg);
    int tx = rx_open("vcan1");
    CHECK(can != NULL && tx >= 0, "link and sender");
    if (can == NULL || tx < 0)
        return;
    urrt_canlink_set_rx(can, on_rx, &s);
    CHECK(sync_round(can, tx, &s) == 2 && s.ids[0] == 0x080, "ids 0x080: 0x080 handed, 0x081 not (%zu)", s.count);
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(can, at_081, 3), 0);
    CHECK(sync_round(can, tx, &s) == 2 && s.ids[0] == 0x081, "ids 0x081: 0x081 handed, 0x080 not (%zu)", s.count);
    messages_clear();
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(can, wide, 2), URRT_E_ARG);
    CHECK(strstr(messages, "receive id 0x800") != NULL, "the refusal names the id: %s", messages);
    CHECK(sync_round(can, tx, &s) == 2 && s.ids[0] == 0x081, "a refused set keeps 0x081 (%zu)", s.count);

    RUN("ip", "link", "set", "vcan1", "down");
    pump_until_state(can, URRT_CANLINK_DOWN, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_DOWN);
    RUN("ip", "link", "set", "vcan1", "up");
    pump_until_state(can, URRT_CANLINK_UP, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    close(tx);
    tx = rx_open("vcan1"); /* the old sender lost its binding with the interface */
    CHECK(tx >= 0 && sync_round(can, tx, &s) == 2 && s.ids[0] == 0x081, "0x081 after the reopen (%zu)", s.count);

    RUN("ip", "link", "set", "vcan1", "down");
    pump_until_state(can, URRT_CANLINK_DOWN, 2000);
    CHECK_EQ_INT(urrt_canlink_set_rx_ids(can, at_080, 3), 0); /* while down: for the reopen */
    RUN("ip", "link", "set", "vcan1", "up");
    pump_until_state(can, URRT_CANLINK_UP, 2000);
    CHECK_EQ_INT(urrt_canlink_get_state(can), URRT_CANLINK_UP);
    close(tx);
    tx = rx_open("vcan1");
    CHECK(tx >= 0 && sync_round(can, tx, &s) == 2 && s.ids[0] == 0x080, "ids set while down: 0x080 (%zu)", s.count);
    CHECK_EQ_INT(urrt_canlink_get_stats(can)->opens, 3);
    if (tx >= 0)
        close(tx);
    urrt_canlink_free(can);
}

static int test_socket(void)
{
    test_refusals();
    test_no_data_frames();
    test_set_rx_ids();
    test_error_frames();
    test_queue_full();
    test_socket_buffer_full();
    test_down_up();
    CHECK(blocked_calls == 0, "no call into the link slept (%u did)", blocked_calls);
    printf("longest call into the link: %" PRIu64 " us; calls that slept in a page fault: %u\n", max_call_us,
           fault_sleeps);
    return check_report();
}

int main(int argc, char **argv)
{
    urrt_log_init("can_link_test", URRT_LOG_DEBUG);
    urrt_log_set_sink(capture, NULL);
    if (argc == 3 && strcmp(argv[1], "log") == 0)
        return test_log(argv[2]);
    if (argc == 3 && strcmp(argv[1], "frames") == 0)
        return test_frames(argv[2]);
    if (argc == 2 && strcmp(argv[1], "socket") == 0)
        return test_socket();
    fprintf(stderr, "usage: %s log DIR | frames DIR | socket\n", argv[0]);
    return 2;
}
