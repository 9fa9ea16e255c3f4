/* SPDX-License-Identifier: MIT */
/*
 * urrt-sim: a robot controller's RealTime stream, and on request its RTDE
 * port (gateway/tools/sim_rtde.c) from the same arm, served here.
 *
 * One packet per period on an absolute monotonic schedule, to every
 * connected client, from a deterministic model of a moving UR5e-like arm
 * (gateway/tools/sim_model.c) or from a raw capture; or an RTDE capture's
 * data packages on the RTDE port alone. Fault modes reproduce what real
 * links do to the stream. See usage() and docs/tools.md.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "port.h"
#include "sim_model.h"
#include "sim_rtde.h"
#include "urrt.h"

#define PROGRAM "urrt-sim"
#define DEFAULT_LISTEN "127.0.0.1:30003"
#define DEFAULT_RTDE_LISTEN "127.0.0.1:30004"
#define DEFAULT_LENGTH 1116
#define MAX_CLIENTS_LIMIT 64
/* A client whose socket stays full this long, or whose queue grows past
 * this, is too slow: it is dropped so that it cannot stall the others. */
#define SLOW_CLIENT_NS (2000ull * 1000000ull)
#define CLIENT_QUEUE_MAX (1u << 20)
#define CLIENT_SNDBUF (128 * 1024)
/* Waking up later than this behind the schedule is a stop, not a hiccup:
 * the overdue packets are skipped rather than sent as a burst. */
#define CATCH_UP_MAX_NS (100ull * 1000000ull)
/* Lateness histogram: 10 us buckets up to 20 ms. */
#define LATE_BUCKET_NS 10000ull
#define LATE_BUCKETS 2000

static volatile sig_atomic_t running = 1;

/* ---- options ---------------------------------------------------------------- */

typedef struct fault_config {
    uint64_t close_after;     /* close normally after N packets */
    uint64_t reset_after;     /* close with RST after N packets */
    uint64_t truncate_after;  /* N packets, half of the next, then close */
    uint64_t garbage_every;   /* garbage bytes before packet N+1, 2N+1, ... */
    uint32_t garbage_bytes;
    uint32_t tiny_writes;     /* write at most this many bytes at a time, spread over the period */
    uint64_t coalesce;        /* hold packets and write N at once */
    uint64_t stall_after;     /* stop sending after N packets ... */
    uint64_t stall_ms;        /* ... for this long (0: until the client leaves) */
    uint64_t odd_every;       /* every Nth packet with a length no controller uses */
    uint32_t odd_length;
    /* Global, for every client: the schedule's packets counted from its start. */
    uint64_t freeze_after;    /* freeze the whole stream after N packets ... */
    uint64_t freeze_every;    /* ... or after every N packets ... */
    uint64_t freeze_ms;       /* ... for this long (0: for good) */
    /* RTDE only. */
    sim_rtde_faults rtde;
    uint32_t rtde_backlog;    /* disconnect a reader this many bytes behind */
    bool rtde_given;          /* an rtde-* fault was given */
} fault_config;

/* What the packets' time column counts. */
typedef enum sim_clock {
    SIM_CLOCK_START,      /* seconds since the (simulated) controller started */
    SIM_CLOCK_MONOTONIC,  /* this host's CLOCK_MONOTONIC at the packet's scheduled instant */
    SIM_CLOCK_REALTIME    /* CLOCK_REALTIME (Unix time) at that instant */
} sim_clock;

typedef struct options {
    char listen_host[256];
    uint16_t listen_port;
    const char *port_file;
    bool rtde;                /* serve RTDE too */
    bool rtde_replay;         /* --replay of an RTDE capture: RTDE alone, from it */
    char rtde_host[256];
    uint16_t rtde_port;
    const char *rtde_port_file;
    bool rtde_fieldbus;       /* --fieldbus: an adapter owns input registers 0..23 */
    sim_rtde_controller rtde_controller;
    sim_clock clock;
    uint32_t length;
    double rate_hz;
    bool rate_given;
    uint64_t seed;
    uint64_t count;
    const char *record_path;
    const char *replay_path;
    bool loop;
    bool start_on_connect;
    uint64_t clients_to_serve;
    uint32_t max_clients;
    uint32_t rt_priority;
    fault_config fault;
    urrt_log_level log_level;
} options;

/* What the command line says, as it is read: options, and what is resolved
 * once every option is in. */
typedef struct command_line {
    options opt;
    const char *listen_arg;    /* --listen HOST:PORT, NULL: not given */
    const char *rtde_arg;      /* --rtde HOST:PORT */
    const char *version_arg;   /* --controller V, or --version V */
    bool length_given;
    int argc;                  /* for --version, which may take the next word */
    char **argv;
} command_line;

/* ---- the packet source: the model or a capture ------------------------------ */

typedef struct replay {
    const uint8_t *data;  /* the mapped file */
    size_t size;
    size_t count;         /* packets */
    size_t *end;          /* end offset of packet i: unit i is [end[i-1], end[i]) */
    uint64_t *due_ns;     /* offset of packet i from the first, by the time column */
    uint64_t span_ns;     /* one pass, including the pause before the first again */
} replay;

typedef struct latency_stats {
    uint64_t samples;
    uint64_t late;        /* sent one period or more behind its deadline */
    uint64_t skipped;     /* not sent at all: the schedule was too far behind */
    uint64_t sum_ns;
    uint64_t max_ns;
    uint32_t hist[LATE_BUCKETS + 1];
} latency_stats;

typedef struct client {
    int fd;
    char peer[80];
    uint64_t id;
    uint8_t *queue;
    size_t head, len, cap;   /* queued bytes are queue[head .. head+len) */
    size_t releasable;       /* bytes at the front that may be written now */
    uint64_t packets;        /* packets queued for this client */
    uint64_t bytes_sent;
    uint64_t next_write_ns;  /* tiny writes: when the next piece may go */
    uint64_t stall_until_ns; /* UINT64_MAX: stalled for good */
    bool stalled;
    uint64_t full_since_ns;
    bool close_when_drained;
    bool reset_when_drained;
    bool recording;
    uint64_t received;       /* bytes the client sent us (ignored) */
    sim_rtde_session *rtde;  /* an RTDE client: its session (NULL: RealTime) */
} client;

typedef struct sim {
    options opt;
    int listen_fd;
    int rtde_fd;              /* the RTDE listener, -1 without --rtde */
    client clients[MAX_CLIENTS_LIMIT];
    size_t nclients;
    uint64_t next_client_id;
    uint64_t clients_done;
    bool started;
    uint64_t t0_ns;
    uint64_t period_ns;       /* model: nominal period */
    uint64_t next;            /* index of the next packet of the schedule */
    sim_model model;
    replay rp;
    bool replaying;
    urrt_state state;         /* the model's state at the current packet */
    sim_rtde_recording recording; /* --replay of an RTDE capture: the controller served */
    uint8_t packet[URRT_PACKET_MAX];
    uint8_t odd_packet[URRT_PACKET_MAX];
    FILE *record;
    bool record_taken;        /* the first client has been assigned the recording */
    uint64_t garbage_sent;
    uint64_t slow_drops;
    uint64_t rtde_behind;     /* RTDE readers disconnected for falling behind */
    uint64_t packets_out;     /* packets emitted by the schedule */
    uint64_t frozen_until_ns; /* freeze fault: nothing is emitted before this (0: not frozen) */
    uint64_t freezes;
    uint64_t frozen_packets;  /* packets of the schedule skipped by freezes */
    latency_stats lat;
    bool replay_done;
} sim;

/* "1 packet", "2 packets". */
static const char *plural(uint64_t n)
{
    return n == 1 ? "" : "s";
}

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static void usage(FILE *out)
{
    fprintf(out,
"Usage: " PROGRAM " [options]\n"
"\n"
"Serves the Universal Robots RealTime stream (the bytes of TCP port 30003)\n"
"from a simulated moving arm, or replays a raw capture, to every client that\n"
"connects. Each client gets the same packets from its connect on.\n"
"\n"
"Stream:\n"
"  -l, --listen HOST:PORT   address to listen on (default " DEFAULT_LISTEN ");\n"
"                           IPv6 as [::1]:30003; port 0: any free port\n"
"      --port-file FILE     once listening, write the port and a newline to\n"
"                           FILE (atomically: FILE.tmp, then renamed)\n"
"  -c, --controller V       controller software version whose length to send:\n"
"                           1.5 1.7 1.8 3.0 ... 3.15 5.0 ... 5.10 (and later);\n"
"                           1.6 sent 756 or 764 bytes: give -L instead\n"
"      --version V          the older spelling of --controller V (a word that\n"
"                           follows --version is always a controller version)\n"
"  -L, --length N           packet length in bytes, any 4+8n from 12 to %u,\n"
"                           lengths no controller uses included (default %u)\n"
"  -r, --rate HZ            packets per second (default 125; 500 with a 5.x controller)\n"
"  -s, --seed N             motion seed: same seed, same packets (default 1)\n"
"      --clock start|monotonic|realtime  what the time column counts: seconds\n"
"                           since the controller started (1000 s at packet 0;\n"
"                           default), or this host's CLOCK_MONOTONIC or\n"
"                           CLOCK_REALTIME at the packet's scheduled instant\n"
"                           (so that a receiver can tell a packet's age)\n"
"  -n, --count N            close each client after N packets\n"
"      --start-on-connect   start the schedule (packet 0) when the first client\n"
"                           connects, so that runs are byte-identical\n"
"      --clients N          exit after N clients have come and gone\n"
"      --max-clients N      refuse clients past N at once (default 16)\n"
"      --rt-priority N      run under SCHED_FIFO at priority N (1-99; needs\n"
"                           CAP_SYS_NICE): less jitter on a busy machine\n"
"  -w, --record PATH        write the exact bytes sent to the first RealTime\n"
"                           client (a raw capture for urrt-dump --file and\n"
"                           --replay)\n"
"      --replay PATH        send a raw capture (e.g. `nc robot 30003 > PATH`),\n"
"                           paced by its time column; bytes between packets\n"
"                           are sent as they are, a partial packet at the end\n"
"                           is not; it starts when the first client connects.\n"
"                           An RTDE capture (urrt-dump --rtde -w PATH, told by\n"
"                           its first byte) is served on the RTDE port alone:\n"
"                           see RTDE below\n"
"      --loop               replay again and again (default: exit at the end)\n"
"\n"
"RTDE (the Real-Time Data Exchange of TCP port 30004, from the same arm, or\n"
"from an RTDE capture):\n"
"      --rtde HOST:PORT     serve RTDE there too (port 0: any free port), as the\n"
"                           controller version of --controller (default 3.10)\n"
"                           does: its variables, 125 Hz before 5.0 and 500 Hz\n"
"                           from 5.0, protocol 1 only before 3.4; with\n"
"                           --replay of an RTDE capture, where to serve it\n"
"                           (default " DEFAULT_RTDE_LISTEN ")\n"
"      --rtde-port-file FILE  once listening, write the RTDE port to FILE\n"
"      --fieldbus           as with an enabled fieldbus adapter (EtherNet/IP,\n"
"                           PROFINET, Modbus): input registers 0..23 and bits\n"
"                           0..63 (the two words) are IN_USE to every client\n"
"  Inputs: a setup of inputs (I) gets the types of the input registers and\n"
"  the other inputs a controller has, NOT_FOUND for a name this version\n"
"  lacks, IN_USE for a variable another connected client set up (or the\n"
"  fieldbus has); any of them makes recipe id 0. Valid recipes get ids 2, 3,\n"
"  ... (1 is the output recipe's). A client's data package (U) takes effect\n"
"  at the next control cycle and is read back by every client's output\n"
"  recipe (input_int_register_24 as an output); one of an unknown recipe id,\n"
"  of the wrong size or while not started is ignored, counted and told the\n"
"  client in an error text. A client that leaves frees its variables; their\n"
"  values stay.\n"
"  An RTDE capture replayed is the controller it recorded: protocol versions\n"
"  and version answered as recorded; the recorded variables, with their\n"
"  recorded types, and no other (NOT_FOUND); a client's frequency f served as\n"
"  every floor(capture rate / f)th package; each package copied byte for byte\n"
"  for the client's recipe, paced by the capture's timestamp from the first\n"
"  client's start; the text messages recorded while data flowed sent again.\n"
"  The capture's sessions with its first recipe are served one after the\n"
"  other; one with another recipe ends the replay. The faults below apply.\n"
"  No RealTime port: -l, --port-file and -w are refused.\n"
"\n"
"Faults (repeat --fault to combine them; N counts packets per client):\n"
"  -f, --fault close-after=N          close the connection after N packets\n"
"      --fault reset-after=N          reset it (RST) after N packets\n"
"      --fault truncate-after=N       send N packets and half of the next, close\n"
"      --fault garbage-every=N[,bytes=B]  B bytes of garbage (default 37) before\n"
"                                     packets N+1, 2N+1, ...\n"
"      --fault tiny-writes[=B]        write B bytes at a time (default 7), spread\n"
"                                     over the period\n"
"      --fault coalesce=N             write N packets at once, every N periods\n"
"      --fault stall-after=N[,for=MS] stop sending after N packets for MS\n"
"                                     milliseconds (default: for good) while\n"
"                                     keeping the connection open\n"
"      --fault odd-length=N[,length=L]  send every Nth packet with length L\n"
"                                     (default: the stream's length + 8), a\n"
"                                     length no controller uses\n"
"      --fault freeze-after=N[,for=MS] freeze the whole stream once the schedule\n"
"                                     has produced N packets (counted from its\n"
"                                     start, for all clients): nothing goes to\n"
"                                     any client, new ones included, for MS\n"
"                                     milliseconds (default: for good); then\n"
"                                     every client gets the stream again, the\n"
"                                     packets of the frozen period skipped\n"
"      --fault freeze-every=N,for=MS  the same freeze after every N packets\n"
"  RTDE clients get the faults above but garbage-every and odd-length, N\n"
"  counting data packages, and these:\n"
"      --fault rtde-refuse-v2         refuse protocol 2 (V), accept 1\n"
"      --fault rtde-text-handshake    a text message before every reply\n"
"      --fault rtde-text-every=N[,level=L]  a text message (level 0-3, default\n"
"                                     2 warning) before data packages N+1,\n"
"                                     2N+1, ...\n"
"      --fault rtde-bad-package=N[,kind=size|type|recipe|header]  every Nth data\n"
"                                     package bad: a byte short (default), an\n"
"                                     unknown type, a wrong recipe id, a size\n"
"                                     field below the header\n"
"      --fault rtde-backlog=B         disconnect a reader more than B bytes\n"
"                                     behind (default 65536)\n"
"      --fault rtde-hold-inputs[,for=MS]  a client's input variables stay\n"
"                                     IN_USE for MS milliseconds (default\n"
"                                     2000) after it left, as a controller\n"
"                                     that still holds the old connection\n"
"\n"
"Other:\n"
"  -v, --verbose            log every client (twice: debug)\n"
"  -q, --quiet              log errors only\n"
"  -h, --help               this text\n"
"  -V, --version            print the program's version (" URRT_VERSION_STRING ")\n"
"\n"
"At exit it logs the schedule's figures: packets, late packets (sent a period\n"
"or more behind), skipped ones, and the lateness (mean, p99, max).\n"
"\n"
"Exit status: 0 done (signal, --clients, end of replay), 1 runtime error\n"
"(cannot listen, cannot read the capture, a damaged or unusable capture),\n"
"2 usage error.\n"
"\n"
"Examples:\n"
"  " PROGRAM "                                   # CB3 3.10 layout, 125 Hz, 127.0.0.1:30003\n"
"  " PROGRAM " -c 5.10 -l 0.0.0.0:30003          # e-series 5.10 at 500 Hz, on the LAN\n"
"  " PROGRAM " --length 1124 --rate 1000         # a length no controller sends\n"
"  " PROGRAM " -l [::1]:30013 --fault close-after=500 --fault garbage-every=100\n"
"  " PROGRAM " --start-on-connect -n 1000 -w capture.bin --clients 1\n"
"  " PROGRAM " -l 127.0.0.1:0 --port-file sim.port --fault freeze-every=2500,for=1500\n"
"  " PROGRAM " --replay capture.bin --loop\n"
"  " PROGRAM " --replay session.rtde --rtde 127.0.0.1:0 --rtde-port-file rtde.port\n"
"  " PROGRAM " -c 5.12.3.1234 -l 127.0.0.1:0 --port-file rt.port \\\n"
"           --rtde 127.0.0.1:0 --rtde-port-file rtde.port --fault rtde-text-every=500\n"
"  " PROGRAM " -c 5.12 --rtde 127.0.0.1:30004 --fieldbus --fault rtde-hold-inputs,for=3000\n",
            URRT_PACKET_MAX, DEFAULT_LENGTH);
}

/* Controller software version -> packet length and default rate, from
 * lib's controller table. NULL, or why the version is refused (why_buf
 * holds it). */
static const char *length_of_version(const char *text, uint32_t *length, double *rate, char *why_buf,
                                     size_t why_size)
{
    const urrt_controller *found[2];
    uint32_t period_us = 0;
    int n = urrt_controller_find(text, strlen(text), found, 2, &period_us);
    if (n == 1) {
        *length = found[0]->length;
        *rate = 1e6 / period_us;
        return NULL;
    }
    if (n == 2) {
        snprintf(why_buf, why_size, "%s controllers sent %u or %u bytes: give --length %u or --length %u", text,
                 (unsigned)found[0]->length, (unsigned)found[1]->length, (unsigned)found[0]->length,
                 (unsigned)found[1]->length);
        return why_buf;
    }
    return "not a RealTime controller version (1.5-1.8, 3.0-3.15, 5.0 and later); "
           "-V alone prints this program's version";
}

/* The number after "NAME=" in a --fault, between min and max; a usage
 * error otherwise. */
static uint64_t fault_value(const char *name, const char *value, uint64_t min, uint64_t max)
{
    uint64_t v;
    const char *err;
    if (value == NULL) {
        cli_usage_error(PROGRAM, "fault %s needs a value: %s=N", name, name);
    }
    if ((err = cli_parse_u64(value, min, max, &v)) != NULL) {
        cli_usage_error(PROGRAM, "fault %s=%s: %s (from %llu to %llu)", name, value, err,
                        (unsigned long long)min, (unsigned long long)max);
    }
    return v;
}

/* A kind that takes no value. */
static void no_value(const char *kind, const char *value)
{
    if (value != NULL) {
        cli_usage_error(PROGRAM, "fault %s takes no value (drop \"=%s\")", kind, value);
    }
}

/* The RTDE-only kinds; false for a kind that is not one of them. */
static bool parse_rtde_fault_kind(const char *kind, const char *value, fault_config *f)
{
    if (strcmp(kind, "rtde-refuse-v2") == 0) {
        no_value(kind, value);
        f->rtde.refuse_v2 = true;
    } else if (strcmp(kind, "rtde-text-handshake") == 0) {
        no_value(kind, value);
        f->rtde.text_handshake = true;
    } else if (strcmp(kind, "rtde-text-every") == 0) {
        f->rtde.text_every = fault_value(kind, value, 1, UINT64_MAX);
        f->rtde.text_level = 2;
    } else if (strcmp(kind, "rtde-bad-package") == 0) {
        f->rtde.bad_every = fault_value(kind, value, 1, UINT64_MAX);
        f->rtde.bad_kind = SIM_RTDE_BAD_SIZE;
    } else if (strcmp(kind, "rtde-backlog") == 0) {
        f->rtde_backlog = (uint32_t)fault_value(kind, value, 1, 1u << 30);
    } else if (strcmp(kind, "rtde-hold-inputs") == 0) {
        no_value(kind, value);
        f->rtde.hold_inputs_ms = SIM_RTDE_HOLD_DEFAULT_MS;
    } else {
        return false;
    }
    f->rtde_given = true;
    return true;
}

/* The first part of a --fault: the kind and its count. */
static void parse_fault_kind(const char *kind, const char *value, fault_config *f)
{
    if (strcmp(kind, "close-after") == 0) {
        f->close_after = fault_value(kind, value, 1, UINT64_MAX);
    } else if (strcmp(kind, "reset-after") == 0) {
        f->reset_after = fault_value(kind, value, 1, UINT64_MAX);
    } else if (strcmp(kind, "truncate-after") == 0) {
        /* stored as the packet that is cut */
        f->truncate_after = fault_value(kind, value, 0, UINT64_MAX - 1) + 1;
    } else if (strcmp(kind, "garbage-every") == 0) {
        f->garbage_every = fault_value(kind, value, 1, UINT64_MAX);
        f->garbage_bytes = 37;
    } else if (strcmp(kind, "tiny-writes") == 0) {
        f->tiny_writes = value != NULL ? (uint32_t)fault_value(kind, value, 1, 4096) : 7;
    } else if (strcmp(kind, "coalesce") == 0) {
        f->coalesce = fault_value(kind, value, 2, 1000);
    } else if (strcmp(kind, "stall-after") == 0) {
        f->stall_after = fault_value(kind, value, 1, UINT64_MAX);
    } else if (strcmp(kind, "odd-length") == 0) {
        f->odd_every = fault_value(kind, value, 1, UINT64_MAX);
    } else if (strcmp(kind, "freeze-after") == 0) {
        f->freeze_after = fault_value(kind, value, 1, UINT64_MAX);
    } else if (strcmp(kind, "freeze-every") == 0) {
        f->freeze_every = fault_value(kind, value, 1, UINT64_MAX);
    } else if (!parse_rtde_fault_kind(kind, value, f)) {
        cli_usage_error(PROGRAM, "unknown fault \"%s\": use close-after, reset-after, truncate-after, "
                        "garbage-every, tiny-writes, coalesce, stall-after, odd-length, freeze-after, freeze-every, "
                        "or for RTDE rtde-refuse-v2, rtde-text-handshake, rtde-text-every, rtde-bad-package, "
                        "rtde-backlog or rtde-hold-inputs",
                        kind);
    }
}

/* A ",KEY=VALUE" after the kind: the parameters some kinds take. */
static void parse_fault_param(const char *spec, const char *kind, const char *key, const char *value,
                              fault_config *f)
{
    if (strcmp(kind, "garbage-every") == 0 && strcmp(key, "bytes") == 0) {
        f->garbage_bytes = (uint32_t)fault_value(key, value, 1, 65536);
    } else if (strcmp(kind, "stall-after") == 0 && strcmp(key, "for") == 0) {
        f->stall_ms = fault_value(key, value, 1, 86400000);
    } else if ((strcmp(kind, "freeze-after") == 0 || strcmp(kind, "freeze-every") == 0) &&
               strcmp(key, "for") == 0) {
        f->freeze_ms = fault_value(key, value, 1, 86400000);
    } else if (strcmp(kind, "rtde-hold-inputs") == 0 && strcmp(key, "for") == 0) {
        f->rtde.hold_inputs_ms = (uint32_t)fault_value(key, value, 1, 86400000);
    } else if (strcmp(kind, "rtde-text-every") == 0 && strcmp(key, "level") == 0) {
        f->rtde.text_level = (uint8_t)fault_value(key, value, 0, 3);
    } else if (strcmp(kind, "rtde-bad-package") == 0 && strcmp(key, "kind") == 0) {
        static const char *const kinds[] = {"size", "type", "recipe", "header"}; /* sim_rtde_bad's order */
        size_t k = 0;
        while (k < 4 && (value == NULL || strcmp(value, kinds[k]) != 0)) {
            k++;
        }
        if (k == 4) {
            cli_usage_error(PROGRAM, "fault \"%s\": kind is size, type, recipe or header", spec);
        }
        f->rtde.bad_kind = (sim_rtde_bad)k;
    } else if (strcmp(kind, "odd-length") == 0 && strcmp(key, "length") == 0) {
        f->odd_length = (uint32_t)fault_value(key, value, URRT_PACKET_MIN, URRT_PACKET_MAX);
        if ((f->odd_length - URRT_HEADER_SIZE) % 8 != 0) {
            cli_usage_error(PROGRAM, "odd-length length=%s: must be 4 + 8n", value);
        }
    } else {
        cli_usage_error(PROGRAM, "fault \"%s\": unknown parameter \"%s\"", spec, key);
    }
}

/* "NAME[=VALUE]": splits off the value (NULL when there is none). */
static char *split_value(char *tok)
{
    char *value = strchr(tok, '=');
    if (value != NULL) {
        *value++ = '\0';
    }
    return value;
}

/* --fault KIND[=N][,KEY=VALUE]: into the options' fault_config. */
static void parse_fault(const cli_option *row, const char *spec, void *obj)
{
    fault_config *f = &((command_line *)obj)->opt.fault;
    char buf[128];
    char *save = NULL;
    char *kind, *tok;

    (void)row;
    if (strlen(spec) >= sizeof buf) {
        cli_usage_error(PROGRAM, "fault \"%s\" is too long", spec);
    }
    strcpy(buf, spec);
    kind = strtok_r(buf, ",", &save);
    if (kind == NULL) {
        cli_usage_error(PROGRAM, "empty --fault");
    }
    parse_fault_kind(kind, split_value(kind), f);
    /* A kind takes one parameter at most. */
    for (int params = 0; (tok = strtok_r(NULL, ",", &save)) != NULL; params++) {
        char *value = split_value(tok);
        parse_fault_param(spec, params == 0 ? kind : "", tok, value, f);
    }
    if (f->freeze_after != 0 && f->freeze_every != 0) {
        cli_usage_error(PROGRAM, "give freeze-after or freeze-every, not both");
    }
    if (f->freeze_every != 0 && f->freeze_ms == 0) {
        cli_usage_error(PROGRAM, "fault freeze-every needs its length: freeze-every=N,for=MS");
    }
}

/* --version [V]: a word after it is a controller version, not an option. */
static void version_or_controller(const cli_option *row, const char *arg, void *obj)
{
    command_line *cl = obj;
    (void)row;
    /* urrt-sim takes no operands, so a word after --version can only be
     * a controller version (the older spelling of --controller): it is
     * never taken for "print the version", whatever it says. */
    if (arg == NULL && optind < cl->argc && cl->argv[optind][0] != '-') {
        arg = cl->argv[optind++];
    }
    if (arg == NULL) {
        cli_print_version(PROGRAM);
    }
    cl->version_arg = arg;
}

static void check_length(const cli_option *row, const char *arg, void *obj)
{
    command_line *cl = obj;
    (void)row;
    if ((cl->opt.length - URRT_HEADER_SIZE) % 8 != 0) {
        cli_usage_error(PROGRAM, "--length %s: a packet is 4 bytes of size and 8 per double: 4 + 8n (e.g. 1116)",
                        arg);
    }
    cl->length_given = true;
}

static void parse_rate(const cli_option *row, const char *arg, void *obj)
{
    command_line *cl = obj;
    char why[CONF_WHY_MAX];
    if (!conf_rate_hz(arg, 0.1, 100000.0, &cl->opt.rate_hz, why, sizeof why)) {
        cli_bad_value(PROGRAM, row, arg, why);
    }
    cl->opt.rate_given = true;
}

static const char *const clock_words[] = {"start", "monotonic", "realtime", NULL}; /* sim_clock's order */
_Static_assert(sizeof(sim_clock) == sizeof(int), "CLI_WORD stores an int");

/* One row per option: names, argument, the parser that reads it (cli.h's
 * kinds), where it goes, its range, what the message adds. The order is
 * getopt_long's when it lists the options an abbreviation could mean. */
#define AT(member) offsetof(command_line, member)
static const cli_option option_table[] = {
    {"listen", 'l', required_argument, CLI_TEXT, AT(listen_arg), 0, 0, NULL, NULL, NULL},
    {"port-file", 0, required_argument, CLI_TEXT, AT(opt.port_file), 0, 0, NULL, NULL, NULL},
    {"rtde", 0, required_argument, CLI_TEXT, AT(rtde_arg), 0, 0, NULL, NULL, NULL},
    {"rtde-port-file", 0, required_argument, CLI_TEXT, AT(opt.rtde_port_file), 0, 0, NULL, NULL, NULL},
    {"fieldbus", 0, no_argument, CLI_TRUE, AT(opt.rtde_fieldbus), 0, 0, NULL, NULL, NULL},
    {"clock", 0, required_argument, CLI_WORD, AT(opt.clock), 0, 0, NULL, clock_words, NULL},
    {"version", 'V', optional_argument, CLI_FN, 0, 0, 0, NULL, NULL, version_or_controller},
    {"controller", 'c', required_argument, CLI_TEXT, AT(version_arg), 0, 0, NULL, NULL, NULL},
    {"length", 'L', required_argument, CLI_U32, AT(opt.length), URRT_PACKET_MIN, URRT_PACKET_MAX, NULL, NULL,
     check_length},
    {"rate", 'r', required_argument, CLI_FN, 0, 0, 0, " (Hz)", NULL, parse_rate},
    {"seed", 's', required_argument, CLI_UINT, AT(opt.seed), 0, UINT64_MAX, NULL, NULL, NULL},
    {"count", 'n', required_argument, CLI_UINT, AT(opt.count), 1, UINT64_MAX, NULL, NULL, NULL},
    {"record", 'w', required_argument, CLI_TEXT, AT(opt.record_path), 0, 0, NULL, NULL, NULL},
    {"replay", 0, required_argument, CLI_TEXT, AT(opt.replay_path), 0, 0, NULL, NULL, NULL},
    {"loop", 0, no_argument, CLI_TRUE, AT(opt.loop), 0, 0, NULL, NULL, NULL},
    {"start-on-connect", 0, no_argument, CLI_TRUE, AT(opt.start_on_connect), 0, 0, NULL, NULL, NULL},
    {"clients", 0, required_argument, CLI_UINT, AT(opt.clients_to_serve), 1, UINT64_MAX, NULL, NULL, NULL},
    {"max-clients", 0, required_argument, CLI_U32, AT(opt.max_clients), 1, MAX_CLIENTS_LIMIT, NULL, NULL, NULL},
    {"rt-priority", 0, required_argument, CLI_U32, AT(opt.rt_priority), 1, 99, NULL, NULL, NULL},
    {"fault", 'f', required_argument, CLI_FN, 0, 0, 0, NULL, NULL, parse_fault},
    {"verbose", 'v', no_argument, CLI_VERBOSE, AT(opt.log_level), 0, 0, NULL, NULL, NULL},
    {"quiet", 'q', no_argument, CLI_QUIET, AT(opt.log_level), 0, 0, NULL, NULL, NULL},
    {"help", 'h', no_argument, CLI_HELP, 0, 0, 0, NULL, NULL, NULL},
};
#undef AT

/* --controller V: the length and, unless --rate says, the rate of V. */
static void resolve_controller(command_line *cl)
{
    options *o = &cl->opt;
    double rate;
    char why_buf[128];
    const char *why;
    if (cl->length_given) {
        cli_usage_error(PROGRAM, "give --controller or --length, not both");
    }
    if ((why = length_of_version(cl->version_arg, &o->length, &rate, why_buf, sizeof why_buf)) != NULL) {
        cli_usage_error(PROGRAM, "--controller %s: %s", cl->version_arg, why);
    }
    if (!o->rate_given) {
        o->rate_hz = rate;
    }
}

/* Options that go together, or do not, once every one is in. */
static void check_combinations(command_line *cl)
{
    options *o = &cl->opt;
    const char *err;
    if (o->replay_path != NULL && (cl->version_arg != NULL || cl->length_given || o->rate_given)) {
        cli_usage_error(PROGRAM, "--replay sends the capture's own packets at its own pace: drop --controller, "
                                 "--length, --rate");
    }
    if (o->replay_path != NULL && o->clock != SIM_CLOCK_START) {
        cli_usage_error(PROGRAM, "--replay sends the capture's own time column: drop --clock");
    }
    if (o->loop && o->replay_path == NULL) {
        cli_usage_error(PROGRAM, "--loop goes with --replay");
    }
    /* The kind of capture, by its first byte (a file that cannot be read
     * is the runtime error of loading it). */
    o->rtde_replay = o->replay_path != NULL && sim_rtde_sniff(o->replay_path) == 1;
    if (o->rtde_replay) {
        const char *rt = cl->listen_arg != NULL ? "--listen" : o->port_file != NULL ? "--port-file"
                         : o->record_path != NULL                            ? "--record"
                         : o->fault.garbage_every != 0                       ? "fault garbage-every"
                         : o->fault.odd_every != 0                           ? "fault odd-length"
                                                                             : NULL;
        if (rt != NULL) {
            cli_usage_error(PROGRAM, "%s is an RTDE capture, served on the RTDE port alone (no RealTime stream): "
                            "drop %s", o->replay_path, rt);
        }
        return;
    }
    if (o->fault.odd_every != 0 && o->fault.odd_length == 0) {
        o->fault.odd_length = o->length + 8;
    }
    if (cl->listen_arg == NULL) {
        cl->listen_arg = DEFAULT_LISTEN;
    }
    if ((err = cli_parse_listen_address(cl->listen_arg, URRT_LINK_PORT_RW, o->listen_host, sizeof o->listen_host,
                                        &o->listen_port)) != NULL) {
        cli_usage_error(PROGRAM, "--listen %s: %s", cl->listen_arg, err);
    }
}

/* --rtde with --replay of an RTDE capture: where; the capture is the
 * controller (read when the program starts). */
static void resolve_rtde_replay(command_line *cl)
{
    options *o = &cl->opt;
    const char *why, *where = cl->rtde_arg != NULL ? cl->rtde_arg : DEFAULT_RTDE_LISTEN;
    if ((why = cli_parse_listen_address(where, SIM_RTDE_PORT, o->rtde_host, sizeof o->rtde_host, &o->rtde_port)) !=
        NULL) {
        cli_usage_error(PROGRAM, "--rtde %s: %s", where, why);
    }
    if (o->fault.rtde_backlog == 0) {
        o->fault.rtde_backlog = SIM_RTDE_BACKLOG_DEFAULT;
    }
    o->rtde_controller.fieldbus = o->rtde_fieldbus; /* kept when the capture is loaded */
    o->rtde = true;
}

/* --rtde: where, and the controller version whose RTDE to serve. */
static void resolve_rtde(command_line *cl)
{
    options *o = &cl->opt;
    const char *why, *version = cl->version_arg != NULL ? cl->version_arg : "3.10";
    if (o->rtde_replay) {
        resolve_rtde_replay(cl);
        return;
    }
    if (cl->rtde_arg == NULL) {
        if (o->rtde_port_file != NULL || o->fault.rtde_given || o->rtde_fieldbus) {
            cli_usage_error(PROGRAM, "%s goes with --rtde HOST:PORT or --replay of an RTDE capture",
                            o->rtde_port_file != NULL ? "--rtde-port-file"
                            : o->rtde_fieldbus        ? "--fieldbus"
                                                      : "an rtde-* fault");
        }
        return;
    }
    if (o->replay_path != NULL) {
        cli_usage_error(PROGRAM, "--rtde serves the simulated arm or an RTDE capture; %s is no RTDE capture (a "
                        "RealTime capture has no RTDE to serve): drop --rtde", o->replay_path);
    }
    if (cl->length_given) {
        cli_usage_error(PROGRAM, "--rtde serves a controller version's variables: give --controller V, not --length");
    }
    if ((why = sim_rtde_controller_parse(version, &o->rtde_controller)) != NULL) {
        cli_usage_error(PROGRAM, "--rtde as controller %s: %s", version, why);
    }
    o->rtde_controller.fieldbus = o->rtde_fieldbus;
    if (o->rate_hz != (double)o->rtde_controller.rate_hz) {
        cli_usage_error(PROGRAM, "--rtde: controller %s runs at %u Hz on both ports: drop --rate", version,
                        (unsigned)o->rtde_controller.rate_hz);
    }
    if ((why = cli_parse_listen_address(cl->rtde_arg, SIM_RTDE_PORT, o->rtde_host, sizeof o->rtde_host,
                                        &o->rtde_port)) != NULL) {
        cli_usage_error(PROGRAM, "--rtde %s: %s", cl->rtde_arg, why);
    }
    if (o->fault.rtde_backlog == 0) {
        o->fault.rtde_backlog = SIM_RTDE_BACKLOG_DEFAULT;
    }
    o->rtde = true;
}

static void parse_options(int argc, char **argv, options *o)
{
    static const cli_options set = {PROGRAM, option_table, sizeof option_table / sizeof option_table[0], usage,
                                    NULL};
    command_line cl = {.argc = argc, .argv = argv};
    int operand;

    cl.opt.length = DEFAULT_LENGTH;
    cl.opt.rate_hz = 125.0;
    cl.opt.seed = 1;
    cl.opt.max_clients = 16;
    cl.opt.log_level = URRT_LOG_NOTICE;
    operand = cli_parse_options(&set, argc, argv, &cl);
    if (operand < argc) {
        cli_usage_error(PROGRAM, "unexpected argument \"%s\" (options only)", argv[operand]);
    }
    if (cl.version_arg != NULL) {
        resolve_controller(&cl);
    }
    check_combinations(&cl);
    resolve_rtde(&cl);
    *o = cl.opt;
}

/* ---- capture loading ---------------------------------------------------------- */

/* A capture's schedule by its own clock: each packet due one period after
 * the one before, the period read from the time column; a column that
 * stands still, runs back or jumps (a reconnect in the capture) keeps the
 * last sensible period. */
typedef struct pacer {
    double prev_time;
    double period;    /* seconds */
    uint64_t due;     /* ns after the first packet */
    bool any;
} pacer;

/* When the packet timed t is due. */
static uint64_t pace(pacer *p, double t)
{
    if (p->any) {
        double d = t - p->prev_time;
        if (isfinite(d) && d > 0.0 && d < 10.0) {
            p->period = d;
        }
        p->due += (uint64_t)llround(p->period * 1e9);
    }
    p->any = true;
    p->prev_time = t;
    return p->due;
}

/* The replay's arrays for count packets; false (logged) without memory. */
static bool replay_room(replay *rp, size_t count, const char *path)
{
    size_t *end = realloc(rp->end, count * sizeof *rp->end);
    uint64_t *due = end != NULL ? realloc(rp->due_ns, count * sizeof *rp->due_ns) : NULL;
    if (end != NULL) {
        rp->end = end;
    }
    if (due == NULL) {
        urrt_log(URRT_LOG_ERR, "capture %s: out of memory", path);
        return false;
    }
    rp->due_ns = due;
    return true;
}

/* An RTDE capture: the controller of the RTDE port, its packages' schedule
 * by their timestamps. */
static bool load_rtde_replay(sim *s, const char *path)
{
    sim_rtde_recording *r = &s->recording;
    replay *rp = &s->rp;
    char why[512];
    pacer pc = {.any = false};

    if (!sim_rtde_recording_load(path, r, &s->opt.rtde_controller, why, sizeof why)) {
        urrt_log(URRT_LOG_ERR, "%s", why);
        return false;
    }
    if (!replay_room(rp, r->count, path)) {
        return false;
    }
    pc.period = 1.0 / s->opt.rtde_controller.cycle_hz;
    for (size_t i = 0; i < r->count; i++) {
        rp->due_ns[i] = pace(&pc, sim_rtde_recording_time(r, i));
        rp->end[i] = 0; /* no RealTime bytes */
    }
    rp->count = r->count;
    rp->span_ns = pc.due + (uint64_t)llround(pc.period * 1e9);
    s->opt.rate_hz = s->opt.rtde_controller.cycle_hz;
    return true;
}

static bool load_replay(sim *s, const char *path)
{
    replay *rp = &s->rp;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    urrt_framer fr;
    size_t off = 0, cap = 0;
    pacer pc = {.period = 0.008};

    if (fd < 0) {
        urrt_log(URRT_LOG_ERR, "cannot open capture %s: %s", path, strerror(errno));
        return false;
    }
    if (fstat(fd, &st) != 0 || st.st_size == 0) {
        urrt_log(URRT_LOG_ERR, "capture %s is empty or unreadable", path);
        close(fd);
        return false;
    }
    rp->size = (size_t)st.st_size;
    rp->data = mmap(NULL, rp->size, PROT_READ, MAP_PRIVATE, fd, 0);
    close(fd);
    if (rp->data == MAP_FAILED) {
        urrt_log(URRT_LOG_ERR, "cannot map capture %s: %s", path, strerror(errno));
        return false;
    }
    urrt_framer_init(&fr);
    while (off < rp->size) {
        size_t used = 0, len = 0;
        int got = urrt_framer_feed(&fr, rp->data + off, rp->size - off, &used);
        off += used;
        if (got == 1) {
            const uint8_t *pkt = urrt_framer_packet(&fr, &len);
            double t = NAN;
            if (rp->count == cap) {
                cap = cap ? cap * 2 : 4096;
                if (!replay_room(rp, cap, path)) {
                    return false;
                }
            }
            (void)urrt_read(pkt, len, URRT_F_TIME, 0, &t);
            rp->end[rp->count] = off;
            rp->due_ns[rp->count] = pace(&pc, t);
            rp->count++;
        }
    }
    if (rp->count == 0) {
        urrt_log(URRT_LOG_ERR, "capture %s holds no RealTime packet (is it a raw port-30003 capture?)", path);
        return false;
    }
    rp->span_ns = pc.due + (uint64_t)llround(pc.period * 1e9);
    urrt_log(URRT_LOG_INFO, "capture %s: %zu packet%s over %.3f s; %" PRIu64 " bytes skipped, %zu trailing bytes dropped",
             path, rp->count, plural(rp->count), (double)pc.due / 1e9, fr.stats.skipped,
             rp->size - rp->end[rp->count - 1]);
    return true;
}

/* When packet k of the schedule is due, relative to t0. */
static uint64_t due_offset(const sim *s, uint64_t k)
{
    if (s->replaying) {
        return (k / s->rp.count) * s->rp.span_ns + s->rp.due_ns[k % s->rp.count];
    }
    /* k / rate in nanoseconds, exact for any k in 128-bit arithmetic. */
    return (uint64_t)((unsigned __int128)k * 1000000000000ull / (uint64_t)llround(s->opt.rate_hz * 1000.0));
}

/* Nanoseconds to seconds, exact to the double's resolution (a plain
 * division would round the whole count first). */
static double ns_to_s(uint64_t ns)
{
    return (double)(ns / 1000000000ull) + (double)(ns % 1000000000ull) / 1e9;
}

/* CLOCK_REALTIME less CLOCK_MONOTONIC, in ns. The realtime reading is taken
 * between two monotonic ones and the narrowest of a few tries is kept: a
 * preemption between two readings would shift the result by its length. */
static int64_t realtime_offset_ns(void)
{
    int64_t best = 0;
    uint64_t best_width = UINT64_MAX;
    for (int i = 0; i < 10 && best_width > 500; i++) {
        struct timespec rt;
        uint64_t m1 = now_ns(), m2;
        clock_gettime(CLOCK_REALTIME, &rt);
        m2 = now_ns();
        if (m2 - m1 < best_width) {
            best_width = m2 - m1;
            best = (int64_t)((uint64_t)rt.tv_sec * 1000000000ull + (uint64_t)rt.tv_nsec) - (int64_t)(m1 + (m2 - m1) / 2);
        }
    }
    return best;
}

/* The time column of a packet due at monotonic instant due. */
static double clock_column(const sim *s, uint64_t k, uint64_t due)
{
    switch (s->opt.clock) {
    case SIM_CLOCK_MONOTONIC: return ns_to_s(due);
    case SIM_CLOCK_REALTIME: return ns_to_s((uint64_t)((int64_t)due + realtime_offset_ns()));
    case SIM_CLOCK_START: break;
    }
    return sim_model_time(&s->model, k);
}

/* The bytes of packet k of the schedule, due at monotonic instant due. */
static const uint8_t *packet_bytes(sim *s, uint64_t k, uint64_t due, size_t *len)
{
    if (s->opt.rtde_replay) {
        *len = 0;
        return NULL;
    }
    if (s->replaying) {
        size_t i = (size_t)(k % s->rp.count);
        size_t start = i == 0 ? 0 : s->rp.end[i - 1];
        *len = s->rp.end[i] - start;
        return s->rp.data + start;
    }
    /* Kept for the RTDE clients: one state, the same values on both ports. */
    urrt_state *st = &s->state;
    sim_model_state(&s->model, k, urrt_generation_of(s->opt.length) == URRT_GEN_1X ? URRT_GEN_1X : URRT_GEN_3X, st);
    st->time[0] = clock_column(s, k, due);
    int n = urrt_encode(st, s->opt.length, s->packet, sizeof s->packet);
    *len = n > 0 ? (size_t)n : 0;
    return s->packet;
}

/* ---- clients ------------------------------------------------------------------ */

static bool queue_bytes(client *c, const uint8_t *data, size_t len)
{
    if (c->head > 0 && c->head + c->len + len > c->cap) {
        memmove(c->queue, c->queue + c->head, c->len);
        c->head = 0;
    }
    if (c->len + len > c->cap) {
        size_t cap = c->cap ? c->cap : 16384;
        uint8_t *q;
        while (cap < c->len + len) {
            cap *= 2;
        }
        q = realloc(c->queue, cap);
        if (q == NULL) {
            return false;
        }
        c->queue = q;
        c->cap = cap;
    }
    memcpy(c->queue + c->head + c->len, data, len);
    c->len += len;
    return true;
}

static void drop_client(sim *s, size_t i, urrt_log_level level, const char *why)
{
    client *c = &s->clients[i];
    urrt_log(level, "client %s %s after %" PRIu64 " packet%s (%" PRIu64 " bytes)", c->peer, why, c->packets,
             plural(c->packets), c->bytes_sent);
    if (c->reset_when_drained) {
        struct linger lg = {.l_onoff = 1, .l_linger = 0};
        setsockopt(c->fd, SOL_SOCKET, SO_LINGER, &lg, sizeof lg);
    }
    close(c->fd);
    if (c->recording && s->record != NULL) {
        fclose(s->record);
        s->record = NULL;
    }
    free(c->queue);
    if (c->rtde != NULL) {
        sim_rtde_session_end(c->rtde); /* its input variables free (or held), their values kept */
    }
    free(c->rtde);
    s->clients[i] = s->clients[--s->nclients];
    if (i < s->nclients && s->clients[i].rtde != NULL) {
        s->clients[i].rtde->emit_ctx = &s->clients[i]; /* it moved */
    }
    s->clients_done++;
}

/* An RTDE session's replies and packages go into its client's queue, to be
 * written at once. */
static bool rtde_emit(void *ctx, const uint8_t *bytes, size_t len)
{
    client *c = ctx;
    return queue_bytes(c, bytes, len);
}

/* A new client of the RTDE port: its session. */
static bool rtde_attach(sim *s, client *c)
{
    c->rtde = malloc(sizeof *c->rtde);
    if (c->rtde == NULL) {
        urrt_log(URRT_LOG_WARNING, "refusing RTDE client %s: out of memory", c->peer);
        return false;
    }
    sim_rtde_session_init(c->rtde, &s->opt.rtde_controller, &s->opt.fault.rtde, rtde_emit, c, c->peer);
    return true;
}

/* Packet 0 of the schedule is due now. */
static void start_schedule(sim *s, uint64_t now)
{
    s->started = true;
    s->t0_ns = now;
    s->next = 0;
}

/* New clients of a listener: the RealTime one, or the RTDE one (rtde). */
static void accept_clients(sim *s, int listen_fd, bool rtde, uint64_t now)
{
    for (;;) {
        struct sockaddr_storage ss;
        socklen_t sl = sizeof ss;
        char host[64], serv[8];
        int fd = accept4(listen_fd, (struct sockaddr *)&ss, &sl, SOCK_NONBLOCK | SOCK_CLOEXEC);
        client *c;
        int on = 1, sndbuf = CLIENT_SNDBUF;

        if (fd < 0) {
            if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR && errno != ECONNABORTED) {
                urrt_log(URRT_LOG_WARNING, "accept: %s", strerror(errno));
            }
            return;
        }
        if (getnameinfo((struct sockaddr *)&ss, sl, host, sizeof host, serv, sizeof serv,
                        NI_NUMERICHOST | NI_NUMERICSERV) != 0) {
            strcpy(host, "?");
            strcpy(serv, "?");
        }
        if (s->nclients >= s->opt.max_clients) {
            urrt_log(URRT_LOG_WARNING, "refusing client %s:%s: %zu clients already (--max-clients)", host, serv,
                     s->nclients);
            close(fd);
            continue;
        }
        if (s->replay_done) {
            /* Nothing more will come: the program ends once the last clients have their data. */
            urrt_log(URRT_LOG_INFO, "refusing client %s:%s: the replay has ended", host, serv);
            close(fd);
            continue;
        }
        /* A controller sends each packet as it is made, and keeps little
         * buffered: a reader that falls behind is seen as one. */
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
        setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
        c = &s->clients[s->nclients++];
        memset(c, 0, sizeof *c);
        c->fd = fd;
        c->id = ++s->next_client_id;
        snprintf(c->peer, sizeof c->peer, strchr(host, ':') ? "[%s]:%s" : "%s:%s", host, serv);
        if (rtde && !rtde_attach(s, c)) {
            close(fd);
            s->nclients--;
            continue;
        }
        if (s->opt.record_path != NULL && !s->record_taken && !rtde) {
            s->record_taken = true;
            c->recording = true;
        }
        if (!s->started && !s->opt.rtde_replay) {
            start_schedule(s, now);
        }
        urrt_log(URRT_LOG_INFO, "%sclient %s connected%s", rtde ? "RTDE " : "", c->peer,
                 c->recording ? " (recorded)" : "");
    }
}

/* Whether a client takes a packet now: not closing, not in a stall. */
static bool client_takes(client *c, uint64_t now)
{
    if (c->close_when_drained) {
        return false;
    }
    if (c->stalled) {
        if (now < c->stall_until_ns) {
            return false;
        }
        c->stalled = false;
        urrt_log(URRT_LOG_INFO, "client %s: stall over, sending again", c->peer);
    }
    return true;
}

/* The faults that act once packet n went into the queue (from byte before):
 * the ends of the connection, the stall, what may be written. */
static void after_packet(sim *s, client *c, uint64_t n, size_t before, uint64_t now)
{
    const fault_config *f = &s->opt.fault;
    if (f->truncate_after != 0 && n == f->truncate_after) {
        c->len = before + (c->len - before) / 2;
        c->close_when_drained = true;
    }
    if ((f->close_after != 0 && n == f->close_after) || (s->opt.count != 0 && n == s->opt.count)) {
        c->close_when_drained = true;
    }
    if (f->reset_after != 0 && n == f->reset_after) {
        c->close_when_drained = true;
        c->reset_when_drained = true;
    }
    if (f->stall_after != 0 && n == f->stall_after) {
        c->stalled = true;
        c->stall_until_ns = f->stall_ms ? now + f->stall_ms * 1000000ull : UINT64_MAX;
        urrt_log(URRT_LOG_INFO, "client %s: stalling after %" PRIu64 " packet%s", c->peer, n, plural(n));
    }
    if (f->coalesce == 0 || n % f->coalesce == 0 || c->close_when_drained) {
        c->releasable = c->len;
    }
}

/* An RTDE client's data package of control cycle k, when its recipe's
 * rate has one in this cycle; the same faults as on the RealTime port. */
static void rtde_to_client(sim *s, client *c, uint64_t k, uint64_t now)
{
    size_t before = c->len;
    uint64_t n;
    if (!sim_rtde_due(c->rtde, k) || !client_takes(c, now)) {
        return;
    }
    n = ++c->packets;
    if (!(s->opt.rtde_replay ? sim_rtde_send_recorded(c->rtde, k) : sim_rtde_send_data(c->rtde, k, &s->state))) {
        c->close_when_drained = true;
        c->len = 0;
        return;
    }
    after_packet(s, c, n, before, now);
}

/* Packet n (1-based, per client) goes into the client's queue, shaped by
 * the faults. */
static void emit_to_client(sim *s, client *c, const uint8_t *pkt, size_t len, uint64_t now)
{
    const fault_config *f = &s->opt.fault;
    uint64_t n;
    size_t before;
    bool ok = true;

    if (!client_takes(c, now)) {
        return;
    }
    n = ++c->packets;
    if (f->garbage_every != 0 && n > 1 && (n - 1) % f->garbage_every == 0) {
        /* Bytes 0x01-0xFF only: no window of them, nor of them and the next
         * header, reads as a plausible header, so the reader skips exactly
         * these bytes. */
        uint8_t junk[256];
        uint32_t left = f->garbage_bytes;
        uint64_t h = s->opt.seed ^ (n * 0x9E3779B97F4A7C15ull);
        while (left > 0 && ok) {
            uint32_t k = left < sizeof junk ? left : (uint32_t)sizeof junk;
            for (uint32_t i = 0; i < k; i++) {
                h = h * 6364136223846793005ull + 1442695040888963407ull;
                junk[i] = (uint8_t)(1 + (h >> 33) % 255);
            }
            ok = queue_bytes(c, junk, k);
            left -= k;
        }
        s->garbage_sent += f->garbage_bytes;
    }
    if (f->odd_every != 0 && n % f->odd_every == 0) {
        /* The same columns at another length: cut, or padded with zeros. */
        size_t odd = f->odd_length;
        memset(s->odd_packet, 0, odd);
        memcpy(s->odd_packet, pkt, len < odd ? len : odd);
        s->odd_packet[0] = (uint8_t)(odd >> 24);
        s->odd_packet[1] = (uint8_t)(odd >> 16);
        s->odd_packet[2] = (uint8_t)(odd >> 8);
        s->odd_packet[3] = (uint8_t)odd;
        pkt = s->odd_packet;
        len = odd;
    }
    before = c->len;
    ok = ok && queue_bytes(c, pkt, len);
    if (!ok) {
        c->close_when_drained = true;
        c->len = 0;
        return;
    }
    after_packet(s, c, n, before, now);
}

/* Writes what may be written now. Returns false when the client is gone. */
static bool flush_client(sim *s, size_t i, uint64_t now)
{
    client *c = &s->clients[i];
    const uint32_t tiny = s->opt.fault.tiny_writes;

    while (c->releasable > 0) {
        size_t n = c->releasable;
        ssize_t w;
        if (tiny != 0) {
            if (now < c->next_write_ns) {
                break;
            }
            n = n < tiny ? n : tiny;
        }
        w = send(c->fd, c->queue + c->head, n, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (w < 0) {
            if (errno == EINTR) {
                continue;
            }
            if (errno == EAGAIN || errno == EWOULDBLOCK) {
                if (c->full_since_ns == 0) {
                    c->full_since_ns = now;
                }
                break;
            }
            drop_client(s, i, URRT_LOG_INFO, errno == EPIPE || errno == ECONNRESET ? "left" : strerror(errno));
            return false;
        }
        if (c->recording && s->record != NULL && fwrite(c->queue + c->head, 1, (size_t)w, s->record) != (size_t)w) {
            urrt_log(URRT_LOG_ERR, "cannot write the recording: %s; recording stopped", strerror(errno));
            fclose(s->record);
            s->record = NULL;
        }
        c->head += (size_t)w;
        c->len -= (size_t)w;
        c->releasable -= (size_t)w;
        c->bytes_sent += (uint64_t)w;
        c->full_since_ns = 0;
        if (tiny != 0) {
            /* Pieces on their own schedule, twice as fast as the stream
             * needs so that a backlog drains; a pass that wakes late sends
             * the pieces that are due, each in its own write. */
            uint64_t per_packet = s->replaying ? s->rp.span_ns / s->rp.count : s->period_ns;
            size_t plen = s->replaying ? s->rp.end[s->rp.count - 1] / s->rp.count : s->opt.length;
            if (c->rtde != NULL) {
                per_packet = s->period_ns * c->rtde->divisor;
                plen = c->rtde->data_size + 4;
            }
            uint64_t interval = per_packet * tiny / (2 * plen);
            uint64_t from = c->next_write_ns + per_packet > now ? c->next_write_ns : now;
            c->next_write_ns = from + interval;
        }
    }
    if (c->len == 0) {
        c->head = 0;
    }
    if (c->close_when_drained && c->releasable == 0) {
        drop_client(s, i, URRT_LOG_INFO,
                    c->reset_when_drained ? "reset (fault)"
                    : s->opt.count != 0 && c->packets == s->opt.count ? "closed (--count reached)"
                    : "closed");
        return false;
    }
    if (c->rtde != NULL && c->len > s->opt.fault.rtde_backlog) {
        /* A controller closes an RTDE reader whose unread data overflows its
         * buffer: no throttling, no dropping of packages. */
        s->rtde_behind++;
        drop_client(s, i, URRT_LOG_WARNING, "disconnected: fell behind (its backlog passed the RTDE limit)");
        return false;
    }
    if (c->rtde == NULL &&
        ((c->full_since_ns != 0 && now - c->full_since_ns > SLOW_CLIENT_NS) || c->len > CLIENT_QUEUE_MAX)) {
        s->slow_drops++;
        drop_client(s, i, URRT_LOG_WARNING, "dropped: too slow (its socket stayed full)");
        return false;
    }
    return true;
}

/* Reads what a client sends: an RTDE client's requests go to its session;
 * a RealTime client's bytes are discarded (a controller would run them as
 * URScript, a simulator only says so). Returns false when the client left. */
static bool read_client(sim *s, size_t i)
{
    client *c = &s->clients[i];
    uint8_t buf[4096];
    for (;;) {
        ssize_t n = recv(c->fd, buf, sizeof buf, MSG_DONTWAIT);
        if (n > 0 && c->rtde != NULL) {
            c->received += (uint64_t)n;
            if (!sim_rtde_feed(c->rtde, buf, (size_t)n)) {
                drop_client(s, i, URRT_LOG_INFO, "disconnected (unframable package)");
                return false;
            }
            c->releasable = c->len; /* replies go at once */
            if (s->opt.rtde_replay && !s->started && c->rtde->started) {
                /* A capture starts from its first package for the first
                 * client whose data starts. */
                start_schedule(s, now_ns());
            }
            continue;
        }
        if (n > 0) {
            if (c->received == 0) {
                urrt_log(URRT_LOG_WARNING, "client %s sends data: ignored (a controller on port 30003 would run it as URScript)",
                         c->peer);
            }
            c->received += (uint64_t)n;
            continue;
        }
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            return true;
        }
        drop_client(s, i, URRT_LOG_INFO, n == 0 ? "left" : "left (error)");
        return false;
    }
}

/* ---- the schedule ------------------------------------------------------------- */

static void note_lateness(latency_stats *lat, uint64_t late_ns, uint64_t period_ns)
{
    size_t b = (size_t)(late_ns / LATE_BUCKET_NS);
    lat->samples++;
    lat->sum_ns += late_ns;
    if (late_ns > lat->max_ns) {
        lat->max_ns = late_ns;
    }
    if (late_ns >= period_ns) {
        lat->late++;
    }
    lat->hist[b < LATE_BUCKETS ? b : LATE_BUCKETS]++;
}

static uint64_t percentile_ns(const latency_stats *lat, double p)
{
    uint64_t want = (uint64_t)ceil(p * (double)lat->samples), seen = 0;
    for (size_t b = 0; b <= LATE_BUCKETS; b++) {
        seen += lat->hist[b];
        if (seen >= want && want > 0) {
            return (b + 1) * LATE_BUCKET_NS;
        }
    }
    return lat->max_ns;
}

/* The freeze fault: whether packet k, due at due, falls in a freeze, which
 * then swallows it (a controller that stops sending does not buffer). */
static bool frozen(sim *s, uint64_t due)
{
    if (s->frozen_until_ns == 0) {
        return false;
    }
    if (due < s->frozen_until_ns) {
        s->frozen_packets++;
        return true;
    }
    urrt_log(URRT_LOG_NOTICE, "freeze %" PRIu64 " over: sending to every client again", s->freezes);
    s->frozen_until_ns = 0;
    return false;
}

/* After the packet due at due went out: starts a freeze when one is due. */
static void maybe_freeze(sim *s, uint64_t due)
{
    const fault_config *f = &s->opt.fault;
    if (!(f->freeze_after != 0 && s->packets_out == f->freeze_after) &&
        !(f->freeze_every != 0 && s->packets_out % f->freeze_every == 0)) {
        return;
    }
    /* Measured from the last packet sent: the next one goes MS later. */
    s->frozen_until_ns = f->freeze_ms != 0 ? due + f->freeze_ms * 1000000ull : UINT64_MAX;
    s->freezes++;
    if (f->freeze_ms != 0) {
        urrt_log(URRT_LOG_NOTICE, "freeze %" PRIu64 ": nothing to any client for %" PRIu64 " ms after %" PRIu64
                 " packet%s", s->freezes, f->freeze_ms, s->packets_out, plural(s->packets_out));
    } else {
        urrt_log(URRT_LOG_NOTICE, "freeze %" PRIu64 ": nothing to any client from now on, after %" PRIu64 " packet%s",
                 s->freezes, s->packets_out, plural(s->packets_out));
    }
}

/* Emits every packet that is due. */
static void run_schedule(sim *s, uint64_t now)
{
    if (!s->started || s->replay_done) {
        return;
    }
    while (s->t0_ns + due_offset(s, s->next) <= now) {
        uint64_t due = s->t0_ns + due_offset(s, s->next);
        uint64_t period = s->next > 0 ? due - (s->t0_ns + due_offset(s, s->next - 1)) : s->period_ns;
        const uint8_t *pkt;
        size_t len;

        if (!s->replaying || s->opt.loop || s->next < s->rp.count) {
            /* Frozen first, so that a freeze swallows the same packets however late we are. */
            if (frozen(s, due)) {
                s->next++;
                continue;
            }
            if (now - due > CATCH_UP_MAX_NS) {
                /* Too far behind (stopped, swapped out): skip, do not burst. */
                s->lat.skipped++;
                s->next++;
                continue;
            }
            note_lateness(&s->lat, now - due, period ? period : 1);
            pkt = packet_bytes(s, s->next, due, &len);
            for (size_t i = 0; i < s->nclients; i++) {
                if (s->clients[i].rtde != NULL) {
                    rtde_to_client(s, &s->clients[i], s->next, now);
                } else {
                    emit_to_client(s, &s->clients[i], pkt, len, now);
                }
            }
            s->packets_out++;
            maybe_freeze(s, due);
            s->next++;
        }
        if (s->replaying && !s->opt.loop && s->next >= s->rp.count) {
            s->replay_done = true;
            for (size_t i = 0; i < s->nclients; i++) {
                s->clients[i].close_when_drained = true;
                s->clients[i].releasable = s->clients[i].len;
            }
            urrt_log(URRT_LOG_INFO, "end of capture");
            return;
        }
    }
}

/* A listener on host:port, which option gave (named in the errors). */
static int open_listener(const char *host, uint16_t port, const char *option)
{
    struct addrinfo hints, *res = NULL, *ai;
    char service[8];
    int fd = -1, rc, on = 1;
    char where[300];

    cli_format_host_port(host, port, where, sizeof where);
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
    snprintf(service, sizeof service, "%u", (unsigned)port);
    rc = getaddrinfo(host, service, &hints, &res);
    if (rc != 0) {
        urrt_log(URRT_LOG_ERR, "cannot listen on %s: %s (give an address of this machine, e.g. 127.0.0.1 or 0.0.0.0)",
                 where, gai_strerror(rc));
        return -1;
    }
    for (ai = res; ai != NULL; ai = ai->ai_next) {
        fd = socket(ai->ai_family, ai->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, ai->ai_protocol);
        if (fd < 0) {
            continue;
        }
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
        if (bind(fd, ai->ai_addr, ai->ai_addrlen) == 0 && listen(fd, 16) == 0) {
            break;
        }
        rc = errno;
        close(fd);
        fd = -1;
        errno = rc;
    }
    if (fd < 0) {
        urrt_log(URRT_LOG_ERR, "cannot listen on %s: %s%s%s%s", where, strerror(errno),
                 errno == EADDRINUSE      ? " (another simulator or program has the port: pick another with "
                 : errno == EADDRNOTAVAIL ? " (not an address of this machine: use 127.0.0.1, 0.0.0.0 or one that "
                                            "`ip addr` lists in "
                 : errno == EACCES        ? " (ports below 1024 need root: pick another with "
                                          : "",
                 errno == EADDRINUSE || errno == EADDRNOTAVAIL || errno == EACCES ? option : "",
                 errno == EADDRINUSE || errno == EADDRNOTAVAIL || errno == EACCES ? ")" : "");
    }
    freeaddrinfo(res);
    return fd;
}

/* The port the listener got (the system picks one for port 0). */
static uint16_t bound_port(int fd)
{
    struct sockaddr_storage ss;
    socklen_t sl = sizeof ss;
    if (getsockname(fd, (struct sockaddr *)&ss, &sl) != 0) {
        return 0;
    }
    return ntohs(ss.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&ss)->sin6_port
                                          : ((struct sockaddr_in *)&ss)->sin_port);
}

/* Written to PATH.tmp and renamed, so that a reader sees the whole line or no file. */
static bool write_port_file(const char *path, uint16_t port)
{
    char tmp[4096];
    FILE *f;
    bool ok;

    if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", path) >= sizeof tmp) {
        urrt_log(URRT_LOG_ERR, "--port-file %s: name too long", path);
        return false;
    }
    f = fopen(tmp, "w");
    ok = f != NULL;
    if (ok) {
        ok = fprintf(f, "%u\n", (unsigned)port) > 0;
        ok = fclose(f) == 0 && ok;
    }
    ok = ok && rename(tmp, path) == 0;
    if (!ok) {
        urrt_log(URRT_LOG_ERR, "cannot write the port file %s: %s", path, strerror(errno));
        unlink(tmp);
    }
    return ok;
}

static void log_summary(const sim *s, uint64_t now)
{
    const latency_stats *lat = &s->lat;
    double secs = s->started ? (double)(now - s->t0_ns) / 1e9 : 0.0;
    urrt_log(URRT_LOG_NOTICE,
             "%" PRIu64 " packet%s in %.3f s; late (a period or more behind) %" PRIu64 ", skipped %" PRIu64
             "; lateness mean %.1f us, p99 <= %.0f us, max %.1f us; clients %" PRIu64 ", dropped as slow %" PRIu64
             "; garbage bytes %" PRIu64 "; freezes %" PRIu64 " (%" PRIu64 " packet%s not sent)"
             "; RTDE readers disconnected as behind %" PRIu64,
             s->packets_out, plural(s->packets_out), secs, lat->late, lat->skipped,
             lat->samples ? (double)lat->sum_ns / (double)lat->samples / 1e3 : 0.0,
             (double)percentile_ns(lat, 0.99) / 1e3, (double)lat->max_ns / 1e3, s->next_client_id, s->slow_drops,
             s->garbage_sent, s->freezes, s->frozen_packets, plural(s->frozen_packets), s->rtde_behind);
}

/* Real-time priority on request; a normal one with a warning if refused. */
static void set_priority(const options *o)
{
    /* The default 50 us timer slack would be a quarter of a 500 Hz period. */
    prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);
    if (o->rt_priority != 0) {
        struct sched_param sp = {.sched_priority = (int)o->rt_priority};
        if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) {
            urrt_log(URRT_LOG_WARNING, "cannot run under SCHED_FIFO (%s): running with normal priority; "
                     "give the program CAP_SYS_NICE or run it as root", strerror(errno));
        }
    }
}

static void log_serving(const sim *s)
{
    char where[300];
    if (s->opt.rtde_replay) {
        const sim_rtde_controller *c = &s->opt.rtde_controller;
        const sim_rtde_recording *r = &s->recording;
        cli_format_host_port(s->opt.rtde_host, s->opt.rtde_port, where, sizeof where);
        urrt_log(URRT_LOG_NOTICE, "replaying the RTDE capture %s on %s%s: controller %" PRIu32 ".%" PRIu32 ".%" PRIu32
                 ".%" PRIu32 ", %zu data package%s at %.6g Hz over %.3f s from %zu session%s, a recipe of %zu "
                 "variable%s (a client gets these, any other name is NOT_FOUND); no RealTime stream (the capture "
                 "holds RTDE alone)", s->opt.replay_path, where, s->opt.loop ? " in a loop" : "", c->major, c->minor,
                 c->bugfix, c->build, r->count, plural(r->count), c->cycle_hz, (double)s->rp.span_ns / 1e9,
                 r->sessions, plural(r->sessions), r->nfields, plural(r->nfields));
        return;
    }
    cli_format_host_port(s->opt.listen_host, s->opt.listen_port, where, sizeof where);
    if (s->replaying) {
        urrt_log(URRT_LOG_NOTICE, "replaying %s on %s%s", s->opt.replay_path, where, s->opt.loop ? " in a loop" : "");
    } else {
        const char *v = urrt_versions_of(s->opt.length);
        urrt_log(URRT_LOG_NOTICE, "serving %" PRIu32 "-byte packets (%s) at %g Hz on %s, seed %" PRIu64,
                 s->opt.length, v ? v : "no controller sends this length", s->opt.rate_hz, where, s->opt.seed);
    }
    if (s->opt.rtde) {
        const sim_rtde_controller *c = &s->opt.rtde_controller;
        cli_format_host_port(s->opt.rtde_host, s->opt.rtde_port, where, sizeof where);
        urrt_log(URRT_LOG_NOTICE, "serving RTDE as controller %" PRIu32 ".%" PRIu32 ".%" PRIu32 ".%" PRIu32
                 " (%" PRIu32 " Hz, protocol %s) on %s", c->major, c->minor, c->bugfix, c->build, c->rate_hz,
                 c->major == 3 && c->minor < 4 ? "1" : "1 and 2", where);
    }
}

/* The source of packets, the recording, the listener; false (logged) if
 * one of them cannot be had. */
static bool sim_start(sim *s)
{
    s->listen_fd = s->rtde_fd = -1;
    if (s->opt.rtde_replay) {
        if (!load_rtde_replay(s, s->opt.replay_path)) {
            return false;
        }
        s->replaying = true;
    } else if (s->opt.replay_path != NULL) {
        if (!load_replay(s, s->opt.replay_path)) {
            return false;
        }
        s->replaying = true;
        s->opt.length = 0;
    } else {
        sim_model_init(&s->model, s->opt.seed, s->opt.rate_hz);
    }
    s->period_ns = (uint64_t)llround(1e9 / s->opt.rate_hz);
    if (s->opt.record_path != NULL) {
        s->record = fopen(s->opt.record_path, "wb");
        if (s->record == NULL) {
            urrt_log(URRT_LOG_ERR, "cannot create the recording %s: %s", s->opt.record_path, strerror(errno));
            return false;
        }
    }
    if (!s->opt.rtde_replay) {
        s->listen_fd = open_listener(s->opt.listen_host, s->opt.listen_port, "--listen");
        if (s->listen_fd < 0) {
            return false;
        }
        s->opt.listen_port = bound_port(s->listen_fd);
    }
    if (s->opt.rtde) {
        s->rtde_fd = open_listener(s->opt.rtde_host, s->opt.rtde_port, "--rtde");
        if (s->rtde_fd < 0) {
            return false;
        }
        s->opt.rtde_port = bound_port(s->rtde_fd);
    }
    log_serving(s);
    /* After the log line, so that a reader woken by the file finds it too. */
    if (s->opt.port_file != NULL && !write_port_file(s->opt.port_file, s->opt.listen_port)) {
        return false;
    }
    if (s->opt.rtde_port_file != NULL && !write_port_file(s->opt.rtde_port_file, s->opt.rtde_port)) {
        return false;
    }
    /* A capture starts from its first packet for the first client. */
    if (!s->opt.start_on_connect && !s->replaying) {
        s->started = true;
        s->t0_ns = now_ns();
    }
    return true;
}

static bool sim_finished(const sim *s)
{
    return (s->opt.clients_to_serve != 0 && s->clients_done >= s->opt.clients_to_serve && s->nclients == 0) ||
           (s->replay_done && s->nclients == 0);
}

/* The descriptors to wait on (the listeners first, then each client) and,
 * in *wake, the time of the next packet, paced write or slow-client verdict. */
static size_t poll_set(const sim *s, uint64_t now, struct pollfd *pfds, uint64_t *wake)
{
    size_t nfds = 0;
    *wake = s->started && !s->replay_done ? s->t0_ns + due_offset(s, s->next) : UINT64_MAX;
    pfds[nfds++] = (struct pollfd){.fd = s->listen_fd, .events = POLLIN};
    pfds[nfds++] = (struct pollfd){.fd = s->rtde_fd, .events = POLLIN}; /* -1: ignored */
    for (size_t i = 0; i < s->nclients; i++) {
        const client *c = &s->clients[i];
        short ev = POLLIN;
        if (c->releasable > 0) {
            if (s->opt.fault.tiny_writes != 0 && c->next_write_ns > now) {
                *wake = c->next_write_ns < *wake ? c->next_write_ns : *wake;
            } else {
                ev |= POLLOUT;
            }
        }
        if (c->full_since_ns != 0 && c->rtde == NULL) {
            uint64_t give_up = c->full_since_ns + SLOW_CLIENT_NS + 1;
            *wake = give_up < *wake ? give_up : *wake;
        }
        pfds[nfds++] = (struct pollfd){.fd = c->fd, .events = ev};
    }
    return nfds;
}

static int wait_until(struct pollfd *pfds, size_t nfds, uint64_t wake, uint64_t now)
{
    struct timespec ts, *tsp = NULL;
    if (wake != UINT64_MAX) {
        uint64_t d = wake > now ? wake - now : 0;
        ts.tv_sec = (time_t)(d / 1000000000ull);
        ts.tv_nsec = (long)(d % 1000000000ull);
        tsp = &ts;
    }
    return ppoll(pfds, nfds, tsp, NULL);
}

/* Reads and writes what poll reported, then accepts new clients. */
static void serve_ready(sim *s, const struct pollfd *pfds, size_t nfds, uint64_t now)
{
    /* Clients by descriptor: dropping one reorders the array. */
    for (size_t k = nfds; k-- > 2;) {
        if (pfds[k].revents == 0) {
            continue;
        }
        for (size_t i = 0; i < s->nclients; i++) {
            if (s->clients[i].fd != pfds[k].fd) {
                continue;
            }
            if ((pfds[k].revents & (POLLIN | POLLERR | POLLHUP)) && !read_client(s, i)) {
                break;
            }
            if (pfds[k].revents & POLLOUT) {
                (void)flush_client(s, i, now);
            }
            break;
        }
    }
    if (pfds[0].revents & POLLIN) {
        accept_clients(s, s->listen_fd, false, now);
    }
    if (pfds[1].revents & POLLIN) {
        accept_clients(s, s->rtde_fd, true, now);
    }
}

/* The loop: send what is due, wait, serve. Returns the exit status. */
static int serve(sim *s)
{
    static struct pollfd pfds[MAX_CLIENTS_LIMIT + 2];
    while (running) {
        uint64_t now = now_ns();
        uint64_t wake;
        size_t nfds;

        run_schedule(s, now);
        for (size_t i = 0; i < s->nclients;) {
            if (flush_client(s, i, now)) {
                i++;
            }
        }
        if (sim_finished(s)) {
            break;
        }
        nfds = poll_set(s, now, pfds, &wake);
        if (wait_until(pfds, nfds, wake, now) < 0) {
            if (errno == EINTR) {
                continue;
            }
            urrt_log(URRT_LOG_ERR, "poll: %s", strerror(errno));
            return CLI_EXIT_RUNTIME;
        }
        serve_ready(s, pfds, nfds, now_ns());
    }
    return CLI_EXIT_OK;
}

static int sim_stop(sim *s, int status)
{
    if (cli_stop_signal() != 0) {
        urrt_log(URRT_LOG_INFO, "stopping on %s", strsignal(cli_stop_signal()));
    }
    log_summary(s, now_ns());
    while (s->nclients > 0) {
        drop_client(s, s->nclients - 1, URRT_LOG_DEBUG, "closed at exit");
    }
    if (s->record != NULL && fclose(s->record) != 0) {
        urrt_log(URRT_LOG_ERR, "cannot write the recording %s: %s", s->opt.record_path, strerror(errno));
        status = CLI_EXIT_RUNTIME;
    }
    if (s->listen_fd >= 0) {
        close(s->listen_fd);
    }
    if (s->rtde_fd >= 0) {
        close(s->rtde_fd);
    }
    if (s->opt.rtde_replay) {
        sim_rtde_recording_free(&s->recording);
    }
    return status;
}

int main(int argc, char **argv)
{
    static sim s; /* large (packet buffers, histogram): not on the stack */

    parse_options(argc, argv, &s.opt);
    urrt_log_init(PROGRAM, s.opt.log_level);
    cli_handle_signals(&running);
    set_priority(&s.opt);
    if (!sim_start(&s)) {
        return CLI_EXIT_RUNTIME;
    }
    return sim_stop(&s, serve(&s));
}
