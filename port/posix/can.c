/* SPDX-License-Identifier: MIT */
/*
 * can.c: the CAN link of port.h on Linux SocketCAN, and its candump-log
 * alternative.
 *
 * Why it is shaped this way:
 * - A raw socket bound to one interface, non-blocking, with the error mask
 *   fully open, so that bus-off and restarts wake the loop, and a data filter
 *   of exactly the configured rx ids (none: an empty list), so that a bus
 *   flooded with other ids is dropped by the kernel and never reaches the
 *   loop. What passes is read at most URRT_CANLINK_RX_BURST frames per
 *   service call, and the deadline says "now" while more may wait: the
 *   caller's other work (the robot link) gets its turn between bursts.
 * - Receive-queue overflows are the kernel's to count (SO_RXQ_OVFL gives
 *   the socket's running drop count with each frame); receive times are the
 *   kernel's (SO_TIMESTAMP, wall clock) moved onto the monotonic clock.
 * - A CAN driver that cannot take a frame makes the qdisc drop it and the
 *   socket return ENOBUFS, while poll() still reports POLLOUT (the socket
 *   buffer is not full). So a refused frame waits in a one-deep slot per ID
 *   and is retried at the next send (the cheapest probe that the queue has
 *   room again) or after retry_interval_ms; only EAGAIN (socket buffer full)
 *   is worth a POLLOUT wait.
 * - The interface going down reaches the socket as a pending error
 *   (ENETDOWN; ENODEV when it is removed) that makes poll() return POLLERR,
 *   so the loop notices even when it sends nothing.
 * - A log: link to stdout never waits for its reader (see open_stdout),
 *   and the reader sees whole candump lines only: a line it has no room
 *   for is dropped and counted like a frame the driver refused, and one it
 *   took in part (a terminal does that) is finished before any other.
 */
#include <errno.h>
#include <fcntl.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>

#include "port.h"

#ifndef CANFD_FDF
#define CANFD_FDF 0x04 /* kernels since 6.2 (and 6.1 stable) mark FD frames with it */
#endif

#define LOG_PREFIX "log:"
#define LOG_IFNAME_OPT ",ifname="
#define LOG_IFNAME_DEFAULT "can0"
/* A link serving more distinct IDs than this has a configuration problem;
 * the bound keeps a bug from turning into unbounded memory. */
#define MAX_HELD_IDS 4096
/* Frames read per service call (received and error frames together): a
 * babbling bus cannot starve the loop. Data frames handed on are bounded
 * further by URRT_CANLINK_RX_BURST. */
#define MAX_READS_PER_SERVICE 64
/* The longest candump line: "(" 10 "." 6 ") " IFNAMSIZ " " 8 "##" 1 128 "\n". */
#define LOG_LINE_MAX (32 + IFNAMSIZ + 16 + 2 * URRT_CAN_MAX_LEN)

/* Outage reasons: compared by address to log a change of reason once. */
static const char REASON_DOWN[] = "interface went down";
static const char REASON_IS_DOWN[] = "interface is down";
static const char REASON_REMOVED[] = "interface removed";
static const char REASON_MTU[] = "FD frames configured but the MTU is no longer 72";
static const char REASON_REOPEN[] = "reopen failed";
static const char REASON_NOT_CAN[] = "the name now belongs to an interface that is not CAN";
static const char REASON_FILTER[] = "the socket refused the new receive ids";

typedef struct held_frame {
    urrt_can_frame frame;
    uint64_t since_us;   /* when this value was handed in: its age decides its expiry */
} held_frame;

struct urrt_canlink {
    urrt_canlink_config cfg;
    char ifname[IFNAMSIZ];       /* SocketCAN interface, or the log's IFNAME column */
    char *log_path;              /* NULL for a socket link */
    int fd;                      /* socket or log file; -1 when closed */
    bool log_is_socket;          /* log:- to a socket: written with send(MSG_DONTWAIT) */
    char line[LOG_LINE_MAX];     /* the log line being written: line_done < line_len while */
    size_t line_len, line_done;  /* its tail waits for the reader (a partial write) */
    urrt_canlink_state state;
    bool reported_down;          /* the current outage has been logged */
    const char *down_reason;     /* last reason logged, to log a change once */
    uint64_t down_since_us;
    uint64_t dropped_at_down;
    uint64_t reopen_at_us;
    bool busy;                   /* the driver is refusing frames */
    bool wait_writable;          /* the last refusal was EAGAIN: POLLOUT helps */
    uint64_t dropped_at_busy;
    uint64_t retry_at_us;
    int last_send_errno;         /* logged once until it changes */
    held_frame *held;            /* insertion order = retry order */
    size_t n_held, cap_held;
    uint32_t *rx_ids;            /* the caller's rx ids, copied: the socket filter */
    size_t rx_count;
    urrt_canlink_rx_fn rx_fn;
    void *rx_ctx;
    bool rx_more;                /* the last service stopped at its bound: frames may wait */
    uint64_t rx_more_at_us;      /* that service's now: the deadline then */
    uint32_t ovfl_seen;          /* this socket's SO_RXQ_OVFL count already added */
    urrt_canlink_stats stats;
};

void urrt_canlink_config_defaults(urrt_canlink_config *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->interface = "can0";
    cfg->fd = false;
    cfg->fd_brs = false;
    cfg->reopen_interval_ms = 1000;
    cfg->retry_interval_ms = 5;
    cfg->hold_max_ms = 100;
}

/* ---- frames ---------------------------------------------------------------- */

/* The limits are lib's (urrt_can.h); the link adds only that FD frames need
 * an FD link. */
static bool frame_valid(const urrt_canlink *can, const urrt_can_frame *f)
{
    if (!urrt_can_id_valid(f->id, f->extended))
        return false;
    if (f->fd && !can->cfg.fd)
        return false;
    return urrt_can_length_valid(f->len, f->fd);
}

static bool same_id(const urrt_can_frame *a, const urrt_can_frame *b)
{
    return a->id == b->id && a->extended == b->extended;
}

static uint8_t fd_flags(bool brs)
{
    return (uint8_t)(CANFD_FDF | (brs ? CANFD_BRS : 0));
}

static canid_t kernel_id(const urrt_can_frame *f)
{
    return f->extended ? (f->id | CAN_EFF_FLAG) : f->id;
}

/* ---- the candump log --------------------------------------------------------- */

static const char hex_upper[] = "0123456789ABCDEF";

/* One line exactly as candump -l writes it (can-utils lib.c sprint_canframe
 * with no separator, after "(%010lu.%06lu) %s "). The FD flags nibble is what
 * candump shows for the frame received back from a current kernel, which
 * sets CANFD_FDF on every FD frame: 4, or 5 with the bit rate switch. */
static size_t format_log_line(char *out, size_t size, const char *ifname, uint64_t wall_us,
                              const urrt_can_frame *f, bool brs)
{
    int n = snprintf(out, size, "(%010llu.%06llu) %s ", (unsigned long long)(wall_us / 1000000u),
                     (unsigned long long)(wall_us % 1000000u), ifname);
    size_t pos = (size_t)n;
    pos += (size_t)snprintf(out + pos, size - pos, f->extended ? "%08X#" : "%03X#", (unsigned)f->id);
    if (f->fd) {
        out[pos++] = '#';
        out[pos++] = hex_upper[fd_flags(brs)];
    }
    for (unsigned i = 0; i < f->len; i++) {
        out[pos++] = hex_upper[f->data[i] >> 4];
        out[pos++] = hex_upper[f->data[i] & 0xF];
    }
    out[pos++] = '\n';
    return pos;
}

/* Writes what it can of the current line. 1: all of it is out; 0: the
 * reader has no room now (EAGAIN: only a non-blocking stdout says so);
 * -1: an error (errno). */
static int log_put(urrt_canlink *can)
{
    while (can->line_done < can->line_len) {
        const char *p = can->line + can->line_done;
        size_t n = can->line_len - can->line_done;
        ssize_t w = can->log_is_socket ? send(can->fd, p, n, MSG_DONTWAIT) : write(can->fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
            return 0;
        if (w <= 0)
            return w == 0 ? 0 : -1;
        can->line_done += (size_t)w;
    }
    return 1;
}

/* The reader took no byte of a line: the frame is dropped, as one the
 * driver refused would be (the first of a spell is logged). */
static void log_refused(urrt_canlink *can)
{
    can->stats.busy++;
    can->stats.dropped++;
    if (can->busy)
        return;
    urrt_log(URRT_LOG_WARNING,
             "CAN log %s: the reader is not keeping up (stdout full); dropping whole lines, counting drops",
             can->log_path);
    can->busy = true;
    can->dropped_at_busy = can->stats.dropped - 1;
}

/* Writes the line in hand (line_len > 0). 1: it is out; 0: the reader
 * took none of it (the line is dropped) or only a part (its tail waits in
 * hand, and goes before any other line); -1: an error, logged, the line
 * lost. So a line in hand has always begun: the stream never holds half a
 * line followed by another. */
static int log_finish(urrt_canlink *can, uint64_t now_us)
{
    int r = log_put(can);
    if (r < 0) {
        can->stats.send_errors++;
        if (errno != can->last_send_errno)
            urrt_log(URRT_LOG_ERR, "CAN log %s: write failed: %s; frames are lost until it works again",
                     can->log_path, strerror(errno));
        can->last_send_errno = errno;
        can->line_len = can->line_done = 0;
        return -1;
    }
    if (r == 0) {
        if (can->line_done == 0) {
            log_refused(can);
            can->line_len = 0;
        }
        can->retry_at_us = now_us + (uint64_t)can->cfg.retry_interval_ms * 1000u;
        can->stats.pending = can->line_len > 0;
        return 0;
    }
    can->line_len = can->line_done = 0;
    can->stats.pending = 0;
    can->stats.sent++;
    if (can->last_send_errno != 0)
        urrt_log(URRT_LOG_NOTICE, "CAN log %s: writing again", can->log_path);
    can->last_send_errno = 0;
    if (can->busy)
        urrt_log(URRT_LOG_NOTICE, "CAN log %s: the reader takes lines again; %llu dropped meanwhile",
                 can->log_path, (unsigned long long)(can->stats.dropped - can->dropped_at_busy));
    can->busy = false;
    return 1;
}

/* 1: the frame's line is out; 0: dropped (no room for it, or the tail of
 * the line before still waits), lost to an error, or its own tail waits. */
static int log_write(urrt_canlink *can, const urrt_can_frame *f, uint64_t now_us)
{
    if (can->line_len > 0 && log_finish(can, now_us) == 0) {
        log_refused(can);
        return 0;
    }
    uint64_t line_us = can->cfg.log_caller_clock ? now_us : urrt_port_realtime_us();
    can->line_len = format_log_line(can->line, sizeof(can->line), can->ifname, line_us, f, can->cfg.fd_brs);
    can->line_done = 0;
    return log_finish(can, now_us) > 0 ? 1 : 0;
}

/* "log:PATH[,ifname=NAME]" */
static bool parse_log_interface(urrt_canlink *can, const char *spec)
{
    const char *path = spec + strlen(LOG_PREFIX);
    const char *opt = strstr(path, LOG_IFNAME_OPT);
    size_t path_len = opt ? (size_t)(opt - path) : strlen(path);
    const char *ifname = opt ? opt + strlen(LOG_IFNAME_OPT) : LOG_IFNAME_DEFAULT;

    if (path_len == 0) {
        urrt_log(URRT_LOG_ERR, "CAN interface \"%s\": no path after \"log:\" (use log:FILE or log:- for stdout)",
                 spec);
        return false;
    }
    size_t name_len = strlen(ifname);
    if (name_len == 0 || name_len >= IFNAMSIZ || strpbrk(ifname, " \t\n()#,") != NULL) {
        urrt_log(URRT_LOG_ERR,
                 "CAN interface \"%s\": ifname must be 1 to %d characters without blanks, '#', '(', ')' or ','",
                 spec, IFNAMSIZ - 1);
        return false;
    }
    memcpy(can->ifname, ifname, name_len + 1);
    can->log_path = strndup(path, path_len);
    return can->log_path != NULL;
}

/*
 * "log:-". Its reader may stop reading (a pager, a script that hangs, a
 * terminal held with Ctrl-S), and a blocking write would then stop the
 * whole loop. But O_NONBLOCK on descriptor 1 itself would be set on the
 * open file description it shares with the shell and the rest of the
 * pipeline, which expect blocking writes and reads (the next program on a
 * terminal left non-blocking may fail with EAGAIN), and it would outlive
 * us if we crashed. So, by what stdout is:
 * - a pipe, FIFO or character device (a terminal, /dev/null) is opened
 *   again through /proc/self/fd/1: a new open file description of the same
 *   pipe or terminal that is ours alone, made non-blocking (libuv does the
 *   same for terminals); O_NOCTTY: a terminal never becomes ours to control;
 * - a socket (systemd's StandardOutput=journal) is written with
 *   send(MSG_DONTWAIT), non-blocking per call, nothing shared changed;
 * - a regular file is written like log:FILE, and so is stdout when it
 *   cannot be opened again (no /proc): said once, since a stalled reader
 *   then stalls the loop;
 * - with log_caller_clock (urrt-gateway --replay: no live loop to keep
 *   going, and its point is every frame) stdout is written as it is too,
 *   waiting for the reader (`--replay ... | less` shows every line).
 */
static void open_stdout(urrt_canlink *can)
{
    struct stat st;
    can->fd = STDOUT_FILENO;
    if (can->cfg.log_caller_clock || fstat(STDOUT_FILENO, &st) != 0 || S_ISREG(st.st_mode) ||
        S_ISBLK(st.st_mode))
        return;
    if (S_ISSOCK(st.st_mode)) {
        can->log_is_socket = true;
        return;
    }
    int fd = open("/proc/self/fd/1", O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        urrt_log(URRT_LOG_WARNING,
                 "CAN log -: cannot open stdout again to write it without blocking (/proc/self/fd/1: %s); "
                 "writing it as it is: a reader that stops reading stops the gateway (mount /proc, or "
                 "use log:FILE)", strerror(errno));
        return;
    }
    can->fd = fd;
}

static bool open_log(urrt_canlink *can)
{
    if (strcmp(can->log_path, "-") == 0) {
        open_stdout(can);
    } else {
        can->fd = open(can->log_path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (can->fd < 0) {
            urrt_log(URRT_LOG_ERR, "CAN log %s: cannot create it: %s", can->log_path, strerror(errno));
            return false;
        }
    }
    can->state = URRT_CANLINK_UP;
    can->stats.opens++;
    return true;
}

/* ---- held frames --------------------------------------------------------------- */

static held_frame *find_held(urrt_canlink *can, const urrt_can_frame *f)
{
    for (size_t i = 0; i < can->n_held; i++)
        if (same_id(&can->held[i].frame, f))
            return &can->held[i];
    return NULL;
}

static void remove_held(urrt_canlink *can, size_t i)
{
    memmove(&can->held[i], &can->held[i + 1], (can->n_held - i - 1) * sizeof(can->held[0]));
    can->n_held--;
    can->stats.pending = (uint32_t)can->n_held;
}

static void hold(urrt_canlink *can, const urrt_can_frame *f, uint64_t now_us)
{
    held_frame *h = find_held(can, f);
    if (h != NULL) {
        h->frame = *f;
        h->since_us = now_us;
        can->stats.dropped++;
        return;
    }
    if (can->n_held == can->cap_held) {
        size_t cap = can->cap_held ? can->cap_held * 2 : 16;
        held_frame *grown = cap <= MAX_HELD_IDS ? realloc(can->held, cap * sizeof(*grown)) : NULL;
        if (grown == NULL) {
            can->stats.dropped++;
            return;
        }
        can->held = grown;
        can->cap_held = cap;
    }
    can->held[can->n_held].frame = *f;
    can->held[can->n_held].since_us = now_us;
    can->n_held++;
    can->stats.pending = (uint32_t)can->n_held;
}

static void discard_held(urrt_canlink *can)
{
    can->stats.dropped += can->n_held;
    can->n_held = 0;
    can->stats.pending = 0;
}

static void expire_held(urrt_canlink *can, uint64_t now_us)
{
    uint64_t max_us = (uint64_t)can->cfg.hold_max_ms * 1000u;
    size_t kept = 0;
    for (size_t i = 0; i < can->n_held; i++) {
        if (now_us > can->held[i].since_us && now_us - can->held[i].since_us > max_us)
            can->stats.dropped++;
        else
            can->held[kept++] = can->held[i];
    }
    can->n_held = kept;
    can->stats.pending = (uint32_t)kept;
}

/* ---- the socket ---------------------------------------------------------------- */

static void log_down(urrt_canlink *can, urrt_log_level level, const char *reason, const char *detail)
{
    if (can->reported_down && can->down_reason == reason)
        return;
    if (!can->reported_down)
        urrt_log(level, "CAN %s: down (%s%s%s); reopening every %u ms", can->ifname, reason,
                 detail ? ": " : "", detail ? detail : "", (unsigned)can->cfg.reopen_interval_ms);
    else
        urrt_log(level, "CAN %s: still down (%s%s%s)", can->ifname, reason, detail ? ": " : "",
                 detail ? detail : "");
    can->reported_down = true;
    can->down_reason = reason;
}

static void close_socket(urrt_canlink *can)
{
    if (can->fd >= 0)
        close(can->fd);
    can->fd = -1;
}

static void go_down(urrt_canlink *can, uint64_t now_us, const char *reason, int err)
{
    close_socket(can);
    if (can->state == URRT_CANLINK_UP) {
        can->stats.down_events++;
        can->down_since_us = now_us;
        can->dropped_at_down = can->stats.dropped;
    }
    can->state = URRT_CANLINK_DOWN;
    can->rx_more = false;
    discard_held(can);
    can->busy = false;
    can->wait_writable = false;
    can->reopen_at_us = now_us + (uint64_t)can->cfg.reopen_interval_ms * 1000u;
    log_down(can, URRT_LOG_WARNING, reason, err ? strerror(err) : NULL);
}

static bool is_down_errno(int err)
{
    return err == ENETDOWN || err == ENXIO || err == ENODEV || err == ENETUNREACH;
}

/* The interface facts that decide whether a socket can work. At creation a
 * missing or unsuitable interface is a configuration error (-1); later it is
 * part of an outage (0, logged once). Returns 1 when usable and up. */
static int check_interface(urrt_canlink *can, int sock, bool at_creation, unsigned *ifindex)
{
    struct ifreq ifr;
    memset(&ifr, 0, sizeof(ifr));
    memcpy(ifr.ifr_name, can->ifname, sizeof(ifr.ifr_name));

    *ifindex = if_nametoindex(can->ifname);
    if (*ifindex == 0) {
        if (at_creation)
            urrt_log(URRT_LOG_ERR,
                     "CAN interface %s: no such interface (check `ip link show type can`; "
                     "a test bus: `ip link add dev %s type vcan`)",
                     can->ifname, can->ifname);
        else
            log_down(can, URRT_LOG_WARNING, REASON_REMOVED, NULL);
        return at_creation ? -1 : 0;
    }
    if (ioctl(sock, SIOCGIFHWADDR, &ifr) == 0 && ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
        if (!at_creation) {
            log_down(can, URRT_LOG_ERR, REASON_NOT_CAN, NULL);
            return 0;
        }
        urrt_log(URRT_LOG_ERR, "CAN interface %s: not a CAN interface (link type %u)", can->ifname,
                 (unsigned)ifr.ifr_hwaddr.sa_family);
        return -1;
    }
    if (ioctl(sock, SIOCGIFMTU, &ifr) < 0) {
        if (!at_creation) {
            log_down(can, URRT_LOG_WARNING, REASON_REOPEN, strerror(errno));
            return 0;
        }
        urrt_log(URRT_LOG_ERR, "CAN interface %s: cannot read its MTU: %s", can->ifname, strerror(errno));
        return -1;
    }
    if (can->cfg.fd && ifr.ifr_mtu != (int)CANFD_MTU) {
        if (at_creation) {
            urrt_log(URRT_LOG_ERR,
                     "CAN interface %s: CAN FD frames are configured but its MTU is %d, not the FD MTU %d; "
                     "enable FD on it (`ip link set %s mtu %d`, or for a controller `ip link set %s type can "
                     "bitrate B dbitrate D fd on`) or configure classic frames only",
                     can->ifname, ifr.ifr_mtu, (int)CANFD_MTU, can->ifname, (int)CANFD_MTU, can->ifname);
            return -1;
        }
        char fix[64];
        snprintf(fix, sizeof(fix), "set it back with `ip link set %s mtu 72`", can->ifname);
        log_down(can, URRT_LOG_ERR, REASON_MTU, fix);
        return 0;
    }
    if (ioctl(sock, SIOCGIFFLAGS, &ifr) < 0)
        return at_creation ? -1 : 0;
    return (ifr.ifr_flags & IFF_UP) ? 1 : 0;
}

/* What the socket receives: exactly the rx ids as data frames of their
 * kind, 11-bit or 29-bit (the mask takes in the EFF and RTR flags, so a
 * frame of the other kind or a remote request with the same number does
 * not pass; no ids: an empty list, no data
 * frames at all), every error frame, the kernel's receive time and its
 * count of frames dropped on a full receive queue. NULL, or what failed. */
static bool set_filter(const urrt_canlink *can, int sock)
{
    struct can_filter filters[URRT_CANLINK_RX_IDS_MAX];
    for (size_t i = 0; i < can->rx_count; i++) {
        bool extended = (can->rx_ids[i] & URRT_CANLINK_RX_EXTENDED) != 0;
        filters[i].can_id = extended ? (can->rx_ids[i] & CAN_EFF_MASK) | CAN_EFF_FLAG : can->rx_ids[i];
        filters[i].can_mask = (extended ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    return setsockopt(sock, SOL_CAN_RAW, CAN_RAW_FILTER, can->rx_count ? filters : NULL,
                      (socklen_t)(can->rx_count * sizeof(filters[0]))) == 0;
}

static const char *configure_receive(const urrt_canlink *can, int sock)
{
    if (!set_filter(can, sock))
        return "set the receive filter";
    can_err_mask_t err_mask = CAN_ERR_MASK;
    if (setsockopt(sock, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) < 0)
        return "subscribe to error frames";
    int on = 1;
    if (setsockopt(sock, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof(on)) < 0)
        return "count receive overflows (SO_RXQ_OVFL)";
    if (setsockopt(sock, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof(on)) < 0)
        return "stamp received frames (SO_TIMESTAMP)";
    return NULL;
}

/* Opens and binds the socket when the interface is up. Returns as
 * check_interface does. */
static int open_socket(urrt_canlink *can, uint64_t now_us, bool at_creation)
{
    int sock = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (sock < 0) {
        int err = errno;
        if (!at_creation) {
            log_down(can, URRT_LOG_WARNING, REASON_REOPEN, strerror(err));
            return 0;
        }
        urrt_log(URRT_LOG_ERR, "CAN %s: cannot create a CAN socket: %s%s", can->ifname, strerror(err),
                 err == EAFNOSUPPORT || err == EPROTONOSUPPORT
                     ? " (this kernel has no CAN support: `modprobe can-raw`)" : "");
        return -1;
    }
    unsigned ifindex;
    int usable = check_interface(can, sock, at_creation, &ifindex);
    if (usable <= 0) {
        close(sock);
        if (usable == 0 && at_creation)
            log_down(can, URRT_LOG_WARNING, REASON_IS_DOWN, NULL);
        return usable;
    }

    const char *failed = configure_receive(can, sock);
    int on = 1;
    if (failed == NULL && can->cfg.fd &&
        setsockopt(sock, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof(on)) < 0)
        failed = "enable CAN FD frames";
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof(addr));
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)ifindex;
    if (failed == NULL && bind(sock, (struct sockaddr *)&addr, sizeof(addr)) < 0)
        failed = "bind";
    if (failed != NULL) {
        int err = errno;
        close(sock);
        if (at_creation) {
            urrt_log(URRT_LOG_ERR, "CAN %s: cannot %s: %s", can->ifname, failed, strerror(err));
            return -1;
        }
        log_down(can, URRT_LOG_WARNING, REASON_REOPEN, strerror(err));
        return 0;
    }

    can->fd = sock;
    can->state = URRT_CANLINK_UP;
    can->ovfl_seen = 0; /* a new socket counts its drops from 0 */
    can->stats.opens++;
    if (can->reported_down && !at_creation)
        urrt_log(URRT_LOG_NOTICE, "CAN %s: up again after %.1f s; %llu frames dropped meanwhile",
                 can->ifname, (double)(now_us - can->down_since_us) / 1e6,
                 (unsigned long long)(can->stats.dropped - can->dropped_at_down));
    else if (can->reported_down)
        urrt_log(URRT_LOG_NOTICE, "CAN %s: up", can->ifname);
    can->reported_down = false;
    can->down_reason = NULL;
    return 1;
}

static void reopen(urrt_canlink *can, uint64_t now_us)
{
    if (open_socket(can, now_us, false) <= 0)
        can->reopen_at_us = now_us + (uint64_t)can->cfg.reopen_interval_ms * 1000u;
}

/* 1 written; 0 refused for now (held by the caller); -1 the link went down or
 * the frame was lost to an unexpected error. */
static int write_frame(urrt_canlink *can, const urrt_can_frame *f, uint64_t now_us)
{
    union {
        struct can_frame cc;
        struct canfd_frame fd;
    } k;
    size_t size;
    memset(&k, 0, sizeof(k));
    if (f->fd) {
        k.fd.can_id = kernel_id(f);
        k.fd.len = f->len;
        k.fd.flags = fd_flags(can->cfg.fd_brs);
        memcpy(k.fd.data, f->data, f->len);
        size = sizeof(k.fd);
    } else {
        k.cc.can_id = kernel_id(f);
        k.cc.can_dlc = f->len;
        memcpy(k.cc.data, f->data, f->len);
        size = sizeof(k.cc);
    }
    for (;;) {
        ssize_t w = send(can->fd, &k, size, MSG_DONTWAIT);
        if (w == (ssize_t)size) {
            can->stats.sent++;
            can->last_send_errno = 0;
            return 1;
        }
        int err = w < 0 ? errno : EIO;
        if (err == EINTR)
            continue;
        if (err == ENOBUFS || err == EAGAIN) {
            can->stats.busy++;
            if (!can->busy) {
                urrt_log(URRT_LOG_WARNING,
                         "CAN %s: transmit queue full (%s); holding the newest frame per ID, counting drops",
                         can->ifname, strerror(err));
                can->busy = true;
                can->dropped_at_busy = can->stats.dropped;
            }
            can->wait_writable = err == EAGAIN;
            can->retry_at_us = now_us + (uint64_t)can->cfg.retry_interval_ms * 1000u;
            return 0;
        }
        if (is_down_errno(err)) {
            go_down(can, now_us, REASON_DOWN, err);
            return -1;
        }
        can->stats.send_errors++;
        if (err != can->last_send_errno)
            urrt_log(URRT_LOG_ERR, "CAN %s: send of ID %X failed: %s; frame lost", can->ifname,
                     (unsigned)f->id, strerror(err));
        can->last_send_errno = err;
        return -1;
    }
}

/* A write went through with nothing left held: the end of a busy spell. */
static void note_accepting(urrt_canlink *can)
{
    if (!can->busy)
        return;
    urrt_log(URRT_LOG_NOTICE, "CAN %s: transmit queue takes frames again; %llu dropped meanwhile",
             can->ifname, (unsigned long long)(can->stats.dropped - can->dropped_at_busy));
    can->busy = false;
    can->wait_writable = false;
}

/* Sends held frames in the order they were first held, until the driver
 * refuses one. */
static void flush_held(urrt_canlink *can, uint64_t now_us)
{
    while (can->n_held > 0 && can->state == URRT_CANLINK_UP) {
        urrt_can_frame f = can->held[0].frame;
        int r = write_frame(can, &f, now_us);
        if (r == 0)
            return;
        if (can->state != URRT_CANLINK_UP)
            return; /* went down: held frames already discarded */
        remove_held(can, 0);
        if (r > 0 && can->n_held == 0)
            note_accepting(can);
    }
}

static void note_error_frame(urrt_canlink *can, const struct can_frame *cf)
{
    uint32_t class = cf->can_id & CAN_ERR_MASK;
    can->stats.error_frames++;
    can->stats.last_error_class = class;
    if (class & CAN_ERR_BUSOFF) {
        can->stats.bus_off++;
        urrt_log(URRT_LOG_ERR, "CAN %s: bus-off (the controller stopped; it restarts if restart-ms is set: "
                 "`ip link set %s type can restart-ms 100`)", can->ifname, can->ifname);
    }
    if (class & CAN_ERR_CRTL) {
        /* A CANopen node reports error passive as EMCY 0x8120 until it ends. */
        if (cf->data[1] & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE))
            can->stats.error_passive = true;
        if (cf->data[1] & CAN_ERR_CRTL_ACTIVE)
            can->stats.error_passive = false;
    }
    if (class & CAN_ERR_RESTARTED) {
        can->stats.restarts++;
        can->stats.error_passive = false; /* a restarted controller is error active */
        urrt_log(URRT_LOG_NOTICE, "CAN %s: controller restarted after bus-off", can->ifname);
    }
    if (class & ~(uint32_t)(CAN_ERR_BUSOFF | CAN_ERR_RESTARTED))
        urrt_log(URRT_LOG_DEBUG, "CAN %s: error frame class 0x%X data %02X %02X %02X %02X", can->ifname,
                 (unsigned)class, cf->data[0], cf->data[1], cf->data[2], cf->data[3]);
}

/* The ancillary data of one recvmsg: the kernel's receive time and the
 * socket's running count of frames dropped on a full receive queue. */
typedef struct rx_meta {
    bool stamped;
    struct timeval stamp;
    bool has_drops;
    uint32_t drops;
} rx_meta;

static rx_meta read_meta(struct msghdr *msg)
{
    rx_meta m;
    memset(&m, 0, sizeof(m));
    for (struct cmsghdr *c = CMSG_FIRSTHDR(msg); c != NULL; c = CMSG_NXTHDR(msg, c)) {
        if (c->cmsg_level != SOL_SOCKET)
            continue;
        if (c->cmsg_type == SO_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof(m.stamp))) {
            memcpy(&m.stamp, CMSG_DATA(c), sizeof(m.stamp));
            m.stamped = true;
        } else if (c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(m.drops))) {
            memcpy(&m.drops, CMSG_DATA(c), sizeof(m.drops));
            m.has_drops = true;
        }
    }
    return m;
}

/* The kernel's receive time on the monotonic clock: now less the frame's
 * age on the wall clock (read once per burst), never after now; now itself
 * when there is no stamp or it lies ahead (the wall clock was stepped). */
static uint64_t monotonic_rx_us(const rx_meta *m, uint64_t now_us, uint64_t wall_us)
{
    if (!m->stamped)
        return now_us;
    uint64_t stamp_us = (uint64_t)m->stamp.tv_sec * 1000000u + (uint64_t)m->stamp.tv_usec;
    if (stamp_us > wall_us || wall_us - stamp_us > now_us)
        return now_us;
    return now_us - (wall_us - stamp_us);
}

/* A received data frame as urrt_can_frame: false for what the filter lets
 * through only by accident of the API (29-bit, remote requests). */
static bool to_frame(const struct canfd_frame *k, size_t size, urrt_can_frame *f)
{
    if (k->can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG))
        return false;
    memset(f, 0, sizeof(*f));
    f->id = k->can_id & CAN_SFF_MASK;
    f->fd = size == CANFD_MTU;
    f->len = k->len; /* can_dlc of a classic frame: 0..8 */
    if (f->len > (f->fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN))
        return false;
    memcpy(f->data, k->data, f->len);
    return true;
}

/* 1 a frame read into *k (its size in *size), 0 nothing more for now, -1
 * the link went down or the read failed (logged). */
static int receive_one(urrt_canlink *can, uint64_t now_us, struct canfd_frame *k, size_t *size, rx_meta *meta)
{
    struct iovec iov = {.iov_base = k, .iov_len = sizeof(*k)};
    union {
        char buf[CMSG_SPACE(sizeof(struct timeval)) + CMSG_SPACE(sizeof(uint32_t))];
        struct cmsghdr align;
    } control;
    struct msghdr msg;
    memset(&msg, 0, sizeof(msg));
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control.buf;
    msg.msg_controllen = sizeof(control.buf);
    ssize_t r = recvmsg(can->fd, &msg, MSG_DONTWAIT);
    if (r < 0) {
        int err = errno;
        if (err == EAGAIN || err == EINTR)
            return 0;
        if (is_down_errno(err))
            go_down(can, now_us, err == ENODEV ? REASON_REMOVED : REASON_DOWN, err);
        else
            urrt_log(URRT_LOG_WARNING, "CAN %s: receive failed: %s", can->ifname, strerror(err));
        return -1;
    }
    *size = (size_t)r;
    *meta = read_meta(&msg);
    if (meta->has_drops) {
        can->stats.rx_overflows += (uint32_t)(meta->drops - can->ovfl_seen);
        can->ovfl_seen = meta->drops;
    }
    return 1;
}

/* Reads what is queued, at most MAX_READS_PER_SERVICE frames and
 * URRT_CANLINK_RX_BURST data frames handed on; rx_more tells the deadline
 * whether it stopped at a bound. The rx function may send (an SDO answer),
 * and a send may take the link down: the state is checked before each read. */
static void read_socket(urrt_canlink *can, uint64_t now_us)
{
    unsigned handed = 0;
    uint64_t wall_us = 0;
    can->rx_more = false;
    for (int i = 0; i < MAX_READS_PER_SERVICE; i++) {
        if (can->state != URRT_CANLINK_UP)
            return;
        if (handed == URRT_CANLINK_RX_BURST)
            break;
        struct canfd_frame k;
        size_t size = 0;
        rx_meta meta;
        if (receive_one(can, now_us, &k, &size, &meta) <= 0)
            return;
        if (size >= sizeof(struct can_frame) && (k.can_id & CAN_ERR_FLAG)) {
            note_error_frame(can, (const struct can_frame *)&k);
            continue;
        }
        urrt_can_frame f;
        if ((size != CAN_MTU && size != CANFD_MTU) || !to_frame(&k, size, &f))
            continue;
        if (wall_us == 0)
            wall_us = urrt_port_realtime_us();
        can->stats.received++;
        handed++;
        if (can->rx_fn != NULL)
            can->rx_fn(can->rx_ctx, &f, monotonic_rx_us(&meta, now_us, wall_us));
    }
    can->rx_more = can->state == URRT_CANLINK_UP;
    can->rx_more_at_us = now_us;
}

/* ---- the API ------------------------------------------------------------------- */

/* The rx ids, checked and copied: the socket filter of every (re)open.
 * false (logged, naming the link) leaves the ids the link had. */
static bool copy_rx_ids(urrt_canlink *can, const char *name, const uint32_t *ids, size_t count)
{
    size_t n = ids != NULL ? count : 0;
    if (n > URRT_CANLINK_RX_IDS_MAX) {
        urrt_log(URRT_LOG_ERR, "CAN link %s: %zu receive ids, more than the kernel's filter takes (%d); "
                 "receive fewer ids", name, n, URRT_CANLINK_RX_IDS_MAX);
        return false;
    }
    for (size_t i = 0; i < n; i++) {
        bool extended = (ids[i] & URRT_CANLINK_RX_EXTENDED) != 0;
        if ((ids[i] & ~URRT_CANLINK_RX_EXTENDED) > (extended ? CAN_EFF_MASK : CAN_SFF_MASK)) {
            urrt_log(URRT_LOG_ERR, "CAN link %s: receive id 0x%X is not an %s id (0 to 0x%X)", name,
                     (unsigned)(ids[i] & ~URRT_CANLINK_RX_EXTENDED), extended ? "29-bit extended" : "11-bit standard",
                     extended ? (unsigned)CAN_EFF_MASK : (unsigned)CAN_SFF_MASK);
            return false;
        }
    }
    uint32_t *copy = NULL;
    if (n > 0) {
        copy = malloc(n * sizeof(copy[0]));
        if (copy == NULL) {
            urrt_log(URRT_LOG_ERR, "CAN link %s: out of memory for the receive ids", name);
            return false;
        }
        memcpy(copy, ids, n * sizeof(copy[0]));
    }
    free(can->rx_ids);
    can->rx_ids = copy;
    can->rx_count = n;
    return true;
}

urrt_canlink *urrt_canlink_new(const urrt_canlink_config *cfg)
{
    if (cfg == NULL || cfg->interface == NULL || cfg->interface[0] == '\0') {
        urrt_log(URRT_LOG_ERR, "CAN link: no interface configured");
        return NULL;
    }
    urrt_canlink *can = calloc(1, sizeof(*can));
    if (can == NULL)
        return NULL;
    can->cfg = *cfg;
    can->cfg.interface = NULL; /* not owned; ifname/log_path hold what we need */
    can->cfg.rx_ids = NULL;    /* not owned; copied into rx_ids */
    can->fd = -1;
    can->state = URRT_CANLINK_DOWN;
    if (!copy_rx_ids(can, cfg->interface, cfg->rx_ids, cfg->rx_id_count)) {
        free(can);
        return NULL;
    }

    if (strncmp(cfg->interface, LOG_PREFIX, strlen(LOG_PREFIX)) == 0) {
        if (!parse_log_interface(can, cfg->interface) || !open_log(can)) {
            urrt_canlink_free(can);
            return NULL;
        }
        return can;
    }

    if (strlen(cfg->interface) >= IFNAMSIZ) {
        urrt_log(URRT_LOG_ERR, "CAN interface \"%s\": name longer than %d characters", cfg->interface,
                 IFNAMSIZ - 1);
        urrt_canlink_free(can);
        return NULL;
    }
    memcpy(can->ifname, cfg->interface, strlen(cfg->interface) + 1);
    uint64_t now_us = urrt_port_monotonic_us();
    int r = open_socket(can, now_us, true);
    if (r < 0) {
        urrt_canlink_free(can);
        return NULL;
    }
    if (r == 0) {
        can->down_since_us = now_us;
        can->reopen_at_us = now_us + (uint64_t)can->cfg.reopen_interval_ms * 1000u;
    }
    return can;
}

void urrt_canlink_free(urrt_canlink *can)
{
    if (can == NULL)
        return;
    if (can->log_path != NULL) {
        if (can->line_len > 0 && log_finish(can, urrt_port_monotonic_us()) == 0)
            urrt_log(URRT_LOG_WARNING, "CAN log %s: closed with its last line incomplete: the reader did not "
                     "take it", can->log_path);
        if (can->fd >= 0 && can->fd != STDOUT_FILENO)
            close(can->fd);
    } else {
        close_socket(can);
    }
    free(can->log_path);
    free(can->held);
    free(can->rx_ids);
    free(can);
}

void urrt_canlink_set_rx(urrt_canlink *can, urrt_canlink_rx_fn fn, void *ctx)
{
    if (can == NULL)
        return;
    can->rx_fn = fn;
    can->rx_ctx = ctx;
}

int urrt_canlink_set_rx_ids(urrt_canlink *can, const uint32_t *ids, size_t count)
{
    if (can == NULL || (count > 0 && ids == NULL))
        return URRT_E_ARG;
    if (!copy_rx_ids(can, can->log_path != NULL ? can->log_path : can->ifname, ids, count))
        return URRT_E_ARG;
    /* A socket that will not take them is an outage: the reopen sets them. */
    if (can->log_path == NULL && can->state == URRT_CANLINK_UP && !set_filter(can, can->fd)) {
        int err = errno;
        go_down(can, urrt_port_monotonic_us(), REASON_FILTER, err);
    }
    return 0;
}

int urrt_canlink_send(urrt_canlink *can, const urrt_can_frame *frame, uint64_t now_us)
{
    if (can == NULL || frame == NULL || !frame_valid(can, frame))
        return URRT_E_ARG;
    if (can->log_path != NULL)
        return log_write(can, frame, now_us);
    if (can->state != URRT_CANLINK_UP) {
        can->stats.dropped++;
        return 0;
    }
    held_frame *h = find_held(can, frame);
    if (h != NULL) {
        /* The older value of this ID is still waiting: the new one takes its
         * place (and its turn), then everything waiting gets a chance. */
        hold(can, frame, now_us);
        flush_held(can, now_us);
        return find_held(can, frame) == NULL && can->state == URRT_CANLINK_UP ? 1 : 0;
    }
    int r = write_frame(can, frame, now_us);
    if (r == 0) {
        hold(can, frame, now_us);
        return 0;
    }
    if (r < 0) {
        if (can->state != URRT_CANLINK_UP)
            can->stats.dropped++;
        return 0;
    }
    if (can->n_held > 0)
        flush_held(can, now_us); /* the queue took a frame: it has room again */
    else
        note_accepting(can);
    return 1;
}

int urrt_canlink_poll_fd(const urrt_canlink *can, short *events)
{
    if (events != NULL)
        *events = 0;
    if (can == NULL || can->log_path != NULL || can->state != URRT_CANLINK_UP)
        return -1;
    if (events != NULL)
        *events = (short)(POLLIN | (can->n_held > 0 && can->wait_writable ? POLLOUT : 0));
    return can->fd;
}

uint64_t urrt_canlink_deadline(const urrt_canlink *can)
{
    if (can == NULL)
        return UINT64_MAX;
    if (can->log_path != NULL)
        return can->line_len > 0 ? can->retry_at_us : UINT64_MAX; /* a tail waits for the reader */
    if (can->state != URRT_CANLINK_UP)
        return can->reopen_at_us;
    if (can->rx_more)
        return can->rx_more_at_us;
    if (can->n_held == 0)
        return UINT64_MAX;
    uint64_t deadline = can->retry_at_us;
    uint64_t max_us = (uint64_t)can->cfg.hold_max_ms * 1000u;
    for (size_t i = 0; i < can->n_held; i++) {
        uint64_t expiry = can->held[i].since_us + max_us + 1;
        if (expiry < deadline)
            deadline = expiry;
    }
    return deadline;
}

void urrt_canlink_service(urrt_canlink *can, uint64_t now_us)
{
    if (can == NULL)
        return;
    if (can->log_path != NULL) {
        if (can->line_len > 0 && now_us >= can->retry_at_us)
            log_finish(can, now_us);
        return;
    }
    if (can->state != URRT_CANLINK_UP) {
        if (now_us >= can->reopen_at_us)
            reopen(can, now_us);
        return;
    }
    read_socket(can, now_us);
    if (can->state != URRT_CANLINK_UP || can->n_held == 0)
        return;
    expire_held(can, now_us);
    if (can->n_held > 0 && (now_us >= can->retry_at_us || can->wait_writable))
        flush_held(can, now_us);
}

urrt_canlink_state urrt_canlink_get_state(const urrt_canlink *can)
{
    return can->state;
}

const urrt_canlink_stats *urrt_canlink_get_stats(const urrt_canlink *can)
{
    return &can->stats;
}
