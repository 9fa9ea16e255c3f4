/* SPDX-License-Identifier: MIT */
/*
 * urrt-dump: see what a robot sends on its RealTime port, or over RTDE.
 *
 * Reads from a robot or simulator through the port's robot link (so it
 * reconnects like the gateway does), or from a raw capture, and prints each
 * packet as a table, CSV, JSON lines or gnuplot columns. A summary of the
 * stream goes to stderr at the end. With --rtde the link carries an RTDE
 * session (gateway/common/rtde_source): the recipe is what the format and
 * -k need, and each data package prints like a RealTime packet, RTDE-only
 * values under their RTDE names. --rtde -w records the session as an RTDE
 * capture (gateway/common/rtde_capture.h), which --file recognises by its
 * first byte and replays through the same client, so that it prints as the
 * session did live. See usage() and docs/tools.md.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <poll.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "port.h"
#include "rtde_capture.h"
#include "rtde_only.h"
#include "rtde_source.h"
#include "urrt.h"
#include "urrt_rtde.h"

#define PROGRAM "urrt-dump"
#define MAX_LENGTHS 16
/* Bytes held back from the recording until the packet they lead to is
 * complete (garbage, then the packet); past this they are written anyway. */
#define RECORD_PENDING_MAX (1u << 20)
/* No packet for this long: say so (then at twice the interval, up to a minute),
 * so that a wrong port does not look like a robot that is just slow to start. */
#define QUIET_NOTICE_FIRST_US 3000000u
#define QUIET_NOTICE_MAX_US 60000000u
/* What to check when RTDE does not answer. */
#define RTDE_HINT "30004; RTDE must be enabled on the controller: PolyScope 5.10 and later, Settings > " \
                  "Security > Services"

typedef enum format { FORMAT_TABLE, FORMAT_CSV, FORMAT_JSON, FORMAT_GNUPLOT } format;

/* What -k selects, as one number: a urrt_state field (RealTime's, which
 * RTDE's mapped variables fill) below KEY_RTDE, an RTDE-only variable
 * (KEY_RTDE + its urrt_rtde_var id) from there on. */
#define KEY_RTDE ((unsigned)URRT_FIELD_COUNT)
#define KEY_COUNT (KEY_RTDE + (unsigned)URRT_RTDE_VAR_COUNT)

static volatile sig_atomic_t running = 1;

typedef struct options {
    format fmt;
    bool fields_given;
    bool key_on[KEY_COUNT];
    unsigned key_order[KEY_COUNT]; /* the keys to print, in this order */
    unsigned nkeys;
    uint64_t count;
    uint64_t every;
    const char *record_path;
    const char *file_path;
    char host[256];
    uint16_t port;
    bool once;
    bool rtde; /* the address is read over RTDE */
    bool list; /* --rtde --list: the controller's variables, then exit */
    double timeout_s;
    uint32_t connect_timeout_ms;
    uint32_t silence_timeout_ms;
    uint32_t backoff_max_ms;
    bool summary;
    urrt_log_level log_level;
} options;

typedef struct dump {
    options opt;
    uint64_t packets;
    bool done;
    bool output_failed;
    int output_errno;
    /* lengths seen */
    uint32_t lengths[MAX_LENGTHS];
    uint64_t length_count[MAX_LENGTHS];
    size_t nlengths;
    uint64_t other_lengths;
    uint64_t gen_count[4];
    /* time */
    double first_time, last_time;
    double largest_gap;
    uint64_t largest_gap_before;
    uint64_t time_backwards;
    uint64_t first_rx_us, last_rx_us;
    /* stream counters, snapshot at the last packet */
    urrt_framer_stats fstats;
    urrt_link_stats lstats;
    size_t partial_at_end;
    /* csv */
    bool csv_header_done;
    /* rtde: a live session (src) or a capture read back (replay) */
    rtde_source *src;
    rtde_replay *replay;
    uint64_t sessions;    /* connections in the capture read back */
    size_t cut_short;     /* bytes of its last record, cut short */
    int rtde_status;      /* CLI_EXIT_RUNTIME once the session refused what was asked */
    bool hush_drop;       /* the reason is told: keep the link's drop line out of the log */
    urrt_link *link;      /* the robot's, for the peer a capture names */
    /* recording: RealTime bytes (record, pending) or an RTDE capture */
    FILE *record;
    uint8_t *pending;
    size_t pending_len;
    bool record_failed;
    rtde_capture_writer *capture;
} dump;

static void usage(FILE *out)
{
    fprintf(out,
"Usage: " PROGRAM " [options] HOST[:PORT]\n"
"       " PROGRAM " [options] --file PATH|-\n"
"       " PROGRAM " [options] --rtde HOST[:PORT]\n"
"       " PROGRAM " [options] --rtde -w CAPTURE HOST[:PORT]\n"
"       " PROGRAM " --rtde --list HOST[:PORT]\n"
"\n"
"Prints what a Universal Robots controller sends on its RealTime port\n"
"(30003, or the read-only 30013), from the robot or simulator at HOST (port\n"
"30003 unless given; IPv6 as [::1]:30003) or from a capture. It never\n"
"sends a byte to the RealTime port, and reconnects when the link drops.\n"
"\n"
"With --rtde it reads HOST over RTDE instead (port 30004 unless given): it\n"
"asks for the values the format and -k need (without -k every value of the\n"
"RealTime set this controller has), plus the timestamp, and sends nothing\n"
"but the handshake (protocol version, controller version, output setup,\n"
"start). Text messages of the controller go to stderr with their level.\n"
"With -w it records the session as an RTDE capture, which --file prints\n"
"again as it printed live and urrt-sim --replay and urrt-gateway --replay\n"
"play; the recipe then holds every RealTime value and every RTDE-only status\n"
"value the controller has, and the -k names (registers, for instance).\n"
"\n"
"Output (stdout):\n"
"  -F, --format FMT        table (default): names, units, enum names, bit masks\n"
"                          csv: a header row of field names, one row per packet\n"
"                          json: one object per packet per line\n"
"                          gnuplot: every double of the packet in wire order,\n"
"                          printed round-trip exact, so that column N is UR's\n"
"                          \"Gnuplot col.\" N (column 1 is the time)\n"
"  -k, --fields A,B,...    only these fields, in this order (table, csv, json);\n"
"                          names as in the field table, e.g. time,q_actual;\n"
"                          with --rtde (or an RTDE capture) also RTDE names:\n"
"                          actual_q is q_actual,\n"
"                          and RTDE-only values (output_int_register_24,\n"
"                          safety_status_bits, ...) print under their names\n"
"  -n, --count N           stop after N packets\n"
"  -e, --every N           print every Nth packet only (all are counted)\n"
"  -w, --record PATH       save the raw stream (every byte up to the last\n"
"                          complete packet); it replays through --file and\n"
"                          urrt-sim --replay. With --rtde an RTDE capture:\n"
"                          what urrt-dump sent and every package the\n"
"                          controller sent, from each connect on\n"
"      --no-summary        no summary on stderr at the end\n"
"\n"
"Source:\n"
"  -f, --file PATH         read a capture instead of a robot; - is stdin: a raw\n"
"                          RealTime stream or an RTDE capture (--rtde -w),\n"
"                          told apart by its first byte (--rtde optional)\n"
"      --rtde              read HOST over RTDE (port 30004 unless given)\n"
"      --list              with --rtde: the controller's version, then every\n"
"                          RTDE variable urrt knows, its type and whether this\n"
"                          controller has it (asked where no version is known)\n"
"      --once              end when the connection ends instead of reconnecting\n"
"  -t, --timeout SEC       fail when no packet arrives for SEC seconds (without\n"
"                          it, a notice every few seconds says none has come)\n"
"      --connect-timeout MS   (default 2000)\n"
"      --silence-timeout MS   treat this much silence as a lost link (default\n"
"                             1000; 0: never)\n"
"      --backoff-max MS       longest wait between connect attempts (default 5000)\n"
"  Numbers are decimal or 0x hexadecimal (a leading zero is refused); SEC and\n"
"  MS take a unit too: 250ms, 1.5s, 2min (us, ms, s, min), as in the gateway's\n"
"  configuration file.\n"
"\n"
"Other:\n"
"  -v, --verbose           more log lines (twice: debug)\n"
"  -q, --quiet             log errors only\n"
"  -h, --help              this text\n"
"  -V, --version           print the version (" URRT_VERSION_STRING ")\n"
"\n"
"The summary (stderr, lines starting \"summary:\") gives the packets, lengths\n"
"and controller versions seen, generations, resyncs and skipped bytes, partial\n"
"packets dropped, the mean rate and the largest gap in controller time, and\n"
"for a robot the link's connects, reconnects and silences. With --rtde (or an\n"
"RTDE capture) the session's counts instead of generations, resyncs and\n"
"partial packets: controller, protocol, recipe, packages, data packages, text\n"
"messages, ignored packages, errors, bytes, and the bytes of a package cut\n"
"short at close.\n"
"\n"
"Exit status: 0 done (--count reached, end of file, SIGINT/SIGTERM, end of\n"
"connection with --once), 1 runtime error (cannot open or write a file, a\n"
"file without a packet, no packet within --timeout, --once without a\n"
"packet, an RTDE controller or capture without a -k field, a damaged RTDE\n"
"capture), 2 usage error (--rtde with a RealTime capture too).\n"
"\n"
"Examples:\n"
"  " PROGRAM " 192.168.1.10:30013 -n 1                # one packet, as a table\n"
"  " PROGRAM " -F csv -k time,q_actual,i_actual robot -n 5000 > joints.csv\n"
"  " PROGRAM " -F gnuplot [::1]:30003 -w capture.bin -n 2500 > capture.dat\n"
"  " PROGRAM " -F json --file capture.bin | head\n"
"  nc robot 30013 | " PROGRAM " --file - -F gnuplot > live.dat\n"
"  " PROGRAM " --rtde robot -F csv -k timestamp,actual_q,output_int_register_24\n"
"  " PROGRAM " --rtde --list robot                    # what this controller has\n"
"  " PROGRAM " --rtde robot -w arm.rtde -k output_int_register_24 -n 5000\n"
"  " PROGRAM " --file arm.rtde -F csv -k timestamp,output_int_register_24\n");
}

/* The key of a -k name: a urrt field name, or an RTDE name (a mapped one is
 * its urrt field: actual_q is q_actual); -1 for neither. */
static int key_of_name(const char *name, size_t len)
{
    int id = urrt_field_find(name, len);
    int var;
    if (id >= 0) {
        return id;
    }
    var = urrt_rtde_var_find(name, len);
    if (var < 0) {
        return -1;
    }
    id = urrt_rtde_var_field(var);
    return id >= 0 ? id : (int)KEY_RTDE + var;
}

/* --fields A,B,...: the fields to print, in this order. */
static void parse_fields(const cli_option *row, const char *list, void *obj)
{
    options *o = obj;
    const char *p = list;
    (void)row;
    while (*p != '\0') {
        const char *comma = strchr(p, ',');
        size_t n = comma != NULL ? (size_t)(comma - p) : strlen(p);
        int id = key_of_name(p, n);
        if (id < 0) {
            char near[2 * URRT_RTDE_NAME_MAX + 16];
            if (conf_suggest_value(p, n, near, sizeof near) != NULL) {
                cli_usage_error(PROGRAM, "-k: no field or RTDE value named \"%.*s\": did you mean %s?", (int)n, p,
                                near);
            }
            cli_usage_error(PROGRAM, "-k: no field or RTDE value named \"%.*s\" (docs/protocol.md lists the "
                            "fields, docs/rtde.md the RTDE names; --rtde --list HOST what a controller has)",
                            (int)n, p);
        }
        if (!o->key_on[id]) {
            o->key_on[id] = true;
            o->key_order[o->nkeys++] = (unsigned)id;
        }
        o->fields_given = true;
        p += n;
        if (*p == ',') {
            p++;
        }
    }
    if (!o->fields_given) {
        cli_usage_error(PROGRAM, "--fields: empty list");
    }
}

static void on_unknown_option(int letter)
{
    if (letter == 'o') {
        /* -o was --fields before it meant --output in urrt-gateway. */
        cli_usage_error(PROGRAM, "-o is gone: fields are -k A,B (--fields A,B)");
    }
}

static const char *const format_words[] = {"table", "csv", "json", "gnuplot", NULL}; /* format's order */
_Static_assert(sizeof(format) == sizeof(int), "CLI_WORD stores an int");

/* One row per option: names, argument, the parser that reads it (cli.h's
 * kinds), where it goes, its range, what the message adds. The order is
 * getopt_long's when it lists the options an abbreviation could mean. */
#define AT(member) offsetof(options, member)
static const cli_option option_table[] = {
    {"format", 'F', required_argument, CLI_WORD, AT(fmt), 0, 0, NULL, format_words, NULL},
    {"fields", 'k', required_argument, CLI_FN, 0, 0, 0, NULL, NULL, parse_fields},
    {"count", 'n', required_argument, CLI_UINT, AT(count), 1, UINT64_MAX, NULL, NULL, NULL},
    {"every", 'e', required_argument, CLI_UINT, AT(every), 1, UINT64_MAX, NULL, NULL, NULL},
    {"record", 'w', required_argument, CLI_TEXT, AT(record_path), 0, 0, NULL, NULL, NULL},
    {"file", 'f', required_argument, CLI_TEXT, AT(file_path), 0, 0, NULL, NULL, NULL},
    {"rtde", 0, no_argument, CLI_TRUE, AT(rtde), 0, 0, NULL, NULL, NULL},
    {"list", 0, no_argument, CLI_TRUE, AT(list), 0, 0, NULL, NULL, NULL},
    {"once", 0, no_argument, CLI_TRUE, AT(once), 0, 0, NULL, NULL, NULL},
    {"timeout", 't', required_argument, CLI_SECONDS, AT(timeout_s), 1000, UINT64_C(1000000000000),
     " (seconds, e.g. 2.5)", NULL, NULL},
    {"connect-timeout", 0, required_argument, CLI_MS, AT(connect_timeout_ms), 1, 600000, " (milliseconds)", NULL,
     NULL},
    {"silence-timeout", 0, required_argument, CLI_MS, AT(silence_timeout_ms), 0, 600000, " (milliseconds)", NULL,
     NULL},
    {"backoff-max", 0, required_argument, CLI_MS, AT(backoff_max_ms), 100, 600000, " (milliseconds, at least 100)",
     NULL, NULL},
    {"no-summary", 0, no_argument, CLI_FALSE, AT(summary), 0, 0, NULL, NULL, NULL},
    {"verbose", 'v', no_argument, CLI_VERBOSE, AT(log_level), 0, 0, NULL, NULL, NULL},
    {"quiet", 'q', no_argument, CLI_QUIET, AT(log_level), 0, 0, NULL, NULL, NULL},
    {"help", 'h', no_argument, CLI_HELP, 0, 0, 0, NULL, NULL, NULL},
    {"version", 'V', no_argument, CLI_VERSION, 0, 0, 0, NULL, NULL, NULL},
};
#undef AT

/* A key's name: the urrt field's, or the RTDE-only variable's. */
static const char *key_name(unsigned key, char *buf, size_t size)
{
    if (key < KEY_RTDE) {
        return urrt_field((urrt_field_id)key)->name;
    }
    return urrt_rtde_var_name((int)(key - KEY_RTDE), buf, size) >= 0 ? buf : "?";
}

/* The RTDE variable a key asks for, -1 for a field RTDE does not have. */
static int key_var(unsigned key)
{
    return key < KEY_RTDE ? urrt_rtde_var_of_field((urrt_field_id)key) : (int)(key - KEY_RTDE);
}

/* -k against the source: RTDE-only values need RTDE, and RTDE has no
 * value for some RealTime fields (test_value, the reserved ones). rtde:
 * the source is RTDE; file: the capture that says which (NULL: a robot,
 * the options say). */
static void check_keys(const options *o, bool rtde, const char *file)
{
    char buf[URRT_RTDE_NAME_MAX];
    for (unsigned k = 0; k < o->nkeys; k++) {
        unsigned key = o->key_order[k];
        if (!rtde && key >= KEY_RTDE && file != NULL) {
            cli_usage_error(PROGRAM, "-k %s: only RTDE has this value, and %s is a RealTime capture: leave it "
                            "out", key_name(key, buf, sizeof buf), file);
        }
        if (!rtde && key >= KEY_RTDE) {
            cli_usage_error(PROGRAM, "-k %s: only RTDE has this value: add --rtde (and the RTDE port, 30004, "
                            "is the default then)", key_name(key, buf, sizeof buf));
        }
        if (rtde && key_var(key) < 0) {
            cli_usage_error(PROGRAM, "-k %s: RTDE has no such value (RealTime only): leave it out, or read %s",
                            key_name(key, buf, sizeof buf),
                            file != NULL ? "a RealTime capture" : "the RealTime port without --rtde");
        }
    }
}

/* The source: a file, or one robot (over RTDE with --rtde). */
static void check_source(int argc, char **argv, int operand, options *o)
{
    const char *err;
    if (o->list && !o->rtde) {
        cli_usage_error(PROGRAM, "--list lists a controller's RTDE variables: give --rtde --list HOST[:PORT]");
    }
    if (o->list && (o->fields_given || o->count != 0 || o->record_path != NULL)) {
        cli_usage_error(PROGRAM, "--list prints the variables and ends: leave out -k, -n and -w");
    }
    if (o->file_path != NULL) {
        if (operand < argc) {
            cli_usage_error(PROGRAM, "give --file or HOST[:PORT], not both");
        }
        if (o->once || o->timeout_s > 0) {
            cli_usage_error(PROGRAM, "--once and --timeout are for a robot, not --file");
        }
        return;
    }
    if (operand >= argc) {
        cli_usage_error(PROGRAM, "no robot to read from: give HOST[:PORT] or --file PATH");
    }
    if (operand + 1 < argc) {
        cli_usage_error(PROGRAM, "unexpected argument \"%s\" (one robot at a time)", argv[operand + 1]);
    }
    if ((err = cli_parse_host_port(argv[operand], o->rtde ? URRT_RTDE_PORT : URRT_LINK_PORT_RW, o->host,
                                   sizeof o->host, &o->port)) != NULL) {
        cli_usage_error(PROGRAM, "%s: %s", argv[operand], err);
    }
    /* RTDE speaks first: never to a port that runs what it receives (the
     * link refuses it too). RealTime is never on RTDE's port, where a
     * controller sends nothing until it hears a handshake. */
    if (o->rtde && urrt_rtde_port_role(o->port) != NULL) {
        cli_usage_error(PROGRAM, "--rtde %s: port %u is %s: RTDE is port %u, or drop --rtde to read RealTime",
                        argv[operand], (unsigned)o->port, urrt_rtde_port_role(o->port), (unsigned)URRT_RTDE_PORT);
    }
    if (!o->rtde && o->port == URRT_RTDE_PORT) {
        cli_usage_error(PROGRAM, "%s: port %u is RTDE's on every controller, which sends nothing until a client's "
                        "handshake: add --rtde, or give RealTime's port (%u, or the read-only %u)",
                        argv[operand], (unsigned)o->port, (unsigned)URRT_LINK_PORT_RW, (unsigned)URRT_LINK_PORT_RO);
    }
}

static void parse_options(int argc, char **argv, options *o)
{
    static const cli_options set = {PROGRAM, option_table, sizeof option_table / sizeof option_table[0], usage,
                                    on_unknown_option};
    int operand;

    memset(o, 0, sizeof *o);
    o->fmt = FORMAT_TABLE;
    o->every = 1;
    o->connect_timeout_ms = 2000;
    o->silence_timeout_ms = 1000;
    o->backoff_max_ms = 5000;
    o->summary = true;
    o->log_level = URRT_LOG_NOTICE;
    operand = cli_parse_options(&set, argc, argv, o);
    check_source(argc, argv, operand, o);
    if (o->file_path == NULL || o->rtde) {
        check_keys(o, o->rtde, o->file_path); /* else the capture says which source it holds */
    }
    if (o->fmt == FORMAT_GNUPLOT && o->fields_given) {
        cli_usage_error(PROGRAM, "gnuplot output holds every column (column N is UR's col. N): use csv or json "
                                 "for --fields");
    }
}

/* ---- output ------------------------------------------------------------------- */

static void print_number(FILE *out, double v, bool json)
{
    if (json && !isfinite(v)) {
        fputs("null", out);
    } else {
        fprintf(out, "%.17g", v);
    }
}

/* What a packet holds to print: RealTime's (or RTDE's mapped) fields in st,
 * RTDE-only values in vals (NULL for a RealTime packet). */
typedef struct sample {
    const urrt_state *st;
    const urrt_rtde_values *vals;
} sample;

/* The RTDE session the packets come from: the live source's, or the one a
 * capture replays; NULL for RealTime. */
static const urrt_rtde *rtde_session_of(const dump *d)
{
    if (d->src != NULL) {
        return rtde_source_session(d->src);
    }
    return d->replay != NULL ? rtde_replay_session(d->replay) : NULL;
}

/* Element i of an RTDE-only value in its own type: integers exact. */
static void print_rtde_elem(FILE *out, const urrt_rtde_values *vals, int var, unsigned i, bool json)
{
    const void *p = urrt_rtde_value(vals, var);
    switch (urrt_rtde_var_type(var)) {
    case URRT_RTDE_T_BOOL:
    case URRT_RTDE_T_UINT8: fprintf(out, "%u", (unsigned)((const uint8_t *)p)[i]); break;
    case URRT_RTDE_T_UINT32:
    case URRT_RTDE_T_VECTOR6UINT32: fprintf(out, "%" PRIu32, ((const uint32_t *)p)[i]); break;
    case URRT_RTDE_T_UINT64: fprintf(out, "%" PRIu64, ((const uint64_t *)p)[i]); break;
    case URRT_RTDE_T_INT32:
    case URRT_RTDE_T_VECTOR6INT32: fprintf(out, "%" PRId32, ((const int32_t *)p)[i]); break;
    default: print_number(out, ((const double *)p)[i], json); break;
    }
}

static unsigned key_elems(unsigned key)
{
    return key < KEY_RTDE ? urrt_field((urrt_field_id)key)->count : rtde_only_elements((int)(key - KEY_RTDE));
}

static bool key_present(const sample *s, unsigned key)
{
    if (key < KEY_RTDE) {
        return urrt_has(s->st, key);
    }
    return s->vals != NULL && urrt_rtde_has(s->vals, key - KEY_RTDE);
}

static void print_key_elem(FILE *out, const sample *s, unsigned key, unsigned i, bool json)
{
    if (key < KEY_RTDE) {
        print_number(out, urrt_field_values(s->st, key)[i], json);
    } else {
        print_rtde_elem(out, s->vals, (int)(key - KEY_RTDE), i, json);
    }
}

/* The keys to print: those asked for, in the order asked, or else the
 * packet's fields, then its RTDE-only values (which an RTDE package has
 * without -k only when recorded: --rtde -w asks for them). */
static unsigned selected_keys(const dump *d, const sample *s, unsigned *keys)
{
    unsigned n = 0;
    if (d->opt.fields_given) {
        memcpy(keys, d->opt.key_order, d->opt.nkeys * sizeof *keys);
        return d->opt.nkeys;
    }
    for (unsigned key = 0; key < KEY_COUNT; key++) {
        if (key_present(s, key)) {
            keys[n++] = key;
        }
    }
    return n;
}

static void print_gnuplot(const dump *d, FILE *out, const uint8_t *pkt, size_t len)
{
    unsigned doubles = (unsigned)(len - URRT_HEADER_SIZE) / 8u;
    if (d->packets == 1) {
        fprintf(out, "# urrt-dump: one line per packet; column N is UR's \"Gnuplot col.\" N (1: time [s])\n");
    }
    for (unsigned col = 1; col <= doubles; col++) {
        double v = 0.0;
        urrt_read_column(pkt, len, col, &v);
        if (col > 1) {
            fputc(' ', out);
        }
        fprintf(out, "%.17g", v);
    }
    fputc('\n', out);
}

/* An RTDE package has no column layout of UR's: every value of the recipe's
 * fields in field order (RealTime's order, so column 1 is the time), then
 * its RTDE-only values, and a first comment line that names the columns. */
static void print_gnuplot_rtde(const dump *d, FILE *out, const sample *s)
{
    char buf[URRT_RTDE_NAME_MAX];
    unsigned keys[KEY_COUNT];
    unsigned n = selected_keys(d, s, keys);
    unsigned col = 1;
    if (d->packets == 1) {
        fputs("# urrt-dump --rtde: one line per data package; columns:", out);
        for (unsigned k = 0; k < n; k++) {
            unsigned count = key_elems(keys[k]);
            if (count > 1) {
                fprintf(out, " %u-%u %s", col, col + count - 1u, key_name(keys[k], buf, sizeof buf));
            } else {
                fprintf(out, " %u %s", col, key_name(keys[k], buf, sizeof buf));
            }
            col += count;
        }
        fputc('\n', out);
    }
    for (unsigned k = 0; k < n; k++) {
        for (unsigned i = 0; i < key_elems(keys[k]); i++) {
            if (k > 0 || i > 0) {
                fputc(' ', out);
            }
            print_key_elem(out, s, keys[k], i, false);
        }
    }
    fputc('\n', out);
}

static void print_csv_header(dump *d, FILE *out, const sample *s)
{
    char buf[URRT_RTDE_NAME_MAX];
    bool first = true;
    /* Without --fields the columns are those of the first packet. */
    if (!d->opt.fields_given) {
        d->opt.nkeys = selected_keys(d, s, d->opt.key_order);
        d->opt.fields_given = true;
    }
    for (unsigned k = 0; k < d->opt.nkeys; k++) {
        unsigned key = d->opt.key_order[k];
        unsigned count = key_elems(key);
        for (unsigned i = 0; i < count; i++) {
            fprintf(out, first ? "%s" : ",%s", key_name(key, buf, sizeof buf));
            if (count > 1) {
                fprintf(out, "[%u]", i);
            }
            first = false;
        }
    }
    fputc('\n', out);
    d->csv_header_done = true;
}

static void print_csv(dump *d, FILE *out, const sample *s)
{
    bool first = true;
    if (!d->csv_header_done) {
        print_csv_header(d, out, s);
    }
    for (unsigned k = 0; k < d->opt.nkeys; k++) {
        unsigned key = d->opt.key_order[k];
        unsigned count = key_elems(key);
        for (unsigned i = 0; i < count; i++) {
            if (!first) {
                fputc(',', out);
            }
            first = false;
            if (key_present(s, key)) {
                print_key_elem(out, s, key, i, false);
            }
        }
    }
    fputc('\n', out);
}

static bool is_bits(const urrt_field_info *f)
{
    return strcmp(f->unit, "bits") == 0;
}

/* The JSON head of a packet: what the packet is (RealTime: its generation
 * and the versions that send its length; RTDE: protocol and controller). */
static void print_json_head(const dump *d, FILE *out, const urrt_state *st)
{
    const urrt_rtde *ses = rtde_session_of(d);
    fprintf(out, "{\"packet\":%" PRIu64 ",\"length\":%u", d->packets, (unsigned)st->length);
    if (ses != NULL) {
        fprintf(out, ",\"source\":\"rtde\",\"protocol\":%u,\"controller\":\"%" PRIu32 ".%" PRIu32 ".%" PRIu32
                ".%" PRIu32 "\"", (unsigned)ses->protocol_accepted, ses->controller[0], ses->controller[1],
                ses->controller[2], ses->controller[3]);
        return;
    }
    const char *versions = urrt_versions_of(st->length);
    fprintf(out, ",\"generation\":\"%s\"",
            st->generation == URRT_GEN_1X ? "1.x" : st->generation == URRT_GEN_3X ? "3.x/5.x" : "unknown");
    if (versions != NULL) {
        fprintf(out, ",\"versions\":\"%s\"", versions);
    }
    if (st->extra_columns > 0) {
        fprintf(out, ",\"extra_columns\":%u", (unsigned)st->extra_columns);
    }
}

/* One field of urrt_state as JSON: its values, bit masks as integers, and
 * enumerations by name too. */
static void print_json_field(FILE *out, const urrt_state *st, unsigned id)
{
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    const double *v = urrt_field_values(st, id);
    urrt_enum_kind kind = urrt_field_enum((urrt_field_id)id, st->generation);
    fprintf(out, ",\"%s\":", f->name);
    if (f->count > 1) {
        fputc('[', out);
    }
    for (unsigned i = 0; i < f->count; i++) {
        uint64_t mask;
        if (i > 0) {
            fputc(',', out);
        }
        if (is_bits(f) && urrt_bitmask(v[i], &mask) == URRT_OK) {
            fprintf(out, "%" PRIu64, mask);
        } else {
            print_number(out, v[i], true);
        }
    }
    if (f->count > 1) {
        fputc(']', out);
    }
    if (kind != URRT_ENUM_NONE) {
        fprintf(out, ",\"%s_name\":", f->name);
        if (f->count > 1) {
            fputc('[', out);
        }
        for (unsigned i = 0; i < f->count; i++) {
            fprintf(out, i > 0 ? ",\"%s\"" : "\"%s\"", urrt_enum_name(kind, v[i]));
        }
        if (f->count > 1) {
            fputc(']', out);
        }
    }
}

static void print_json(const dump *d, FILE *out, const sample *s)
{
    char buf[URRT_RTDE_NAME_MAX];
    unsigned keys[KEY_COUNT];
    unsigned n = selected_keys(d, s, keys);
    print_json_head(d, out, s->st);
    for (unsigned k = 0; k < n; k++) {
        unsigned key = keys[k];
        unsigned count = key_elems(key);
        if (!key_present(s, key)) {
            continue;
        }
        if (key < KEY_RTDE) {
            print_json_field(out, s->st, key);
            continue;
        }
        fprintf(out, count > 1 ? ",\"%s\":[" : ",\"%s\":", key_name(key, buf, sizeof buf));
        for (unsigned i = 0; i < count; i++) {
            if (i > 0) {
                fputc(',', out);
            }
            print_key_elem(out, s, key, i, true);
        }
        if (count > 1) {
            fputc(']', out);
        }
    }
    fputs("}\n", out);
}

static void print_table_head(const dump *d, FILE *out, const urrt_state *st)
{
    const urrt_rtde *ses = rtde_session_of(d);
    if (ses != NULL) {
        fprintf(out, "package %" PRIu64 ": %u bytes, RTDE protocol %u, controller %" PRIu32 ".%" PRIu32 ".%" PRIu32
                ".%" PRIu32 "\n", d->packets, (unsigned)st->length, (unsigned)ses->protocol_accepted,
                ses->controller[0], ses->controller[1], ses->controller[2], ses->controller[3]);
        return;
    }
    const char *versions = urrt_versions_of(st->length);
    fprintf(out, "packet %" PRIu64 ": %u bytes, %s (%s)", d->packets, (unsigned)st->length,
            st->generation == URRT_GEN_1X ? "1.x" : st->generation == URRT_GEN_3X ? "3.x/5.x" : "generation unknown",
            versions != NULL ? versions : "no known controller sends this length");
    if (st->extra_columns > 0) {
        fprintf(out, ", %u extra columns", (unsigned)st->extra_columns);
    }
    fputc('\n', out);
}

/* The values of one urrt_state field on a table line. */
static void print_table_values(FILE *out, const urrt_state *st, unsigned id)
{
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    const double *v = urrt_field_values(st, id);
    urrt_enum_kind kind = urrt_field_enum((urrt_field_id)id, st->generation);
    for (unsigned i = 0; i < f->count; i++) {
        uint64_t mask;
        if (kind != URRT_ENUM_NONE) {
            fprintf(out, " %s(%g)", urrt_enum_name(kind, v[i]), v[i]);
        } else if (is_bits(f) && urrt_bitmask(v[i], &mask) == URRT_OK) {
            fprintf(out, " 0x%05" PRIx64 " [", mask);
            bool any = false;
            for (unsigned b = 0; b < 64; b++) {
                if (mask >> b & 1u) {
                    fprintf(out, any ? " %u" : "%u", b);
                    any = true;
                }
            }
            fputc(']', out);
        } else if (id == URRT_F_TIME) {
            fprintf(out, " %.3f", v[i]);
        } else {
            fprintf(out, " %10.6g", v[i]);
        }
    }
}

/* An RTDE-only value on a table line: integers exact, doubles as
 * RealTime's are. */
static void print_table_rtde(FILE *out, const urrt_rtde_values *vals, int var)
{
    urrt_rtde_type t = urrt_rtde_var_type(var);
    bool doubles = t == URRT_RTDE_T_DOUBLE || t == URRT_RTDE_T_VECTOR3D || t == URRT_RTDE_T_VECTOR6D;
    for (unsigned i = 0; i < rtde_only_elements(var); i++) {
        if (doubles) {
            fprintf(out, " %10.6g", ((const double *)urrt_rtde_value(vals, var))[i]);
        } else {
            fputc(' ', out);
            print_rtde_elem(out, vals, var, i, false);
        }
    }
}

/* A table line's second column: the unit of a RealTime field, the wire type
 * of an RTDE-only value. */
static const char *key_unit(unsigned key)
{
    return key < KEY_RTDE ? urrt_field((urrt_field_id)key)->unit
                          : urrt_rtde_type_name(urrt_rtde_var_type((int)(key - KEY_RTDE)));
}

static void print_table(const dump *d, FILE *out, const sample *s)
{
    char buf[URRT_RTDE_NAME_MAX];
    unsigned keys[KEY_COUNT];
    unsigned n = selected_keys(d, s, keys);
    /* The columns as wide as their longest entry (RTDE names run to 38
     * characters, types to 13), at least the widths RealTime's need. */
    int name_width = 22, unit_width = 10;
    for (unsigned k = 0; k < n; k++) {
        int name = (int)strlen(key_name(keys[k], buf, sizeof buf)), unit = (int)strlen(key_unit(keys[k]));
        name_width = name > name_width ? name : name_width;
        unit_width = unit > unit_width ? unit : unit_width;
    }
    print_table_head(d, out, s->st);
    for (unsigned k = 0; k < n; k++) {
        unsigned key = keys[k];
        fprintf(out, "  %-*s %-*s", name_width, key_name(key, buf, sizeof buf), unit_width, key_unit(key));
        if (!key_present(s, key)) {
            fputs(s->vals != NULL ? " (not in this package)\n" : " (not in this packet)\n", out);
            continue;
        }
        if (key < KEY_RTDE) {
            print_table_values(out, s->st, key);
        } else {
            print_table_rtde(out, s->vals, (int)(key - KEY_RTDE));
        }
        fputc('\n', out);
    }
}

/* ---- recording ---------------------------------------------------------------- */

/* -w of a RealTime stream: the file, and room for the bytes held back;
 * false (logged) if either cannot be had. */
static bool open_record(dump *d)
{
    if (d->opt.record_path == NULL) {
        return true;
    }
    d->record = fopen(d->opt.record_path, "wb");
    d->pending = malloc(RECORD_PENDING_MAX);
    if (d->record == NULL || d->pending == NULL) {
        urrt_log(URRT_LOG_ERR, "cannot create the recording %s: %s", d->opt.record_path, strerror(errno));
        return false;
    }
    return true;
}

static bool record_write(dump *d, const uint8_t *data, size_t len)
{
    if (d->record == NULL || d->record_failed) {
        return false;
    }
    if (fwrite(data, 1, len, d->record) != len) {
        urrt_log(URRT_LOG_ERR, "cannot write the recording %s: %s", d->opt.record_path, strerror(errno));
        d->record_failed = true;
    }
    return true;
}

/* Stream bytes in order; held until the packet they lead to completes. */
static void on_bytes(void *ctx, const uint8_t *data, size_t len)
{
    dump *d = ctx;
    if (d->record == NULL || d->done) {
        return;
    }
    if (d->pending_len + len > RECORD_PENDING_MAX) {
        record_write(d, d->pending, d->pending_len);
        d->pending_len = 0;
        if (len > RECORD_PENDING_MAX) {
            record_write(d, data, len);
            return;
        }
    }
    memcpy(d->pending + d->pending_len, data, len);
    d->pending_len += len;
}

/* ---- packets -------------------------------------------------------------------- */

static void note_length(dump *d, uint32_t len)
{
    for (size_t i = 0; i < d->nlengths; i++) {
        if (d->lengths[i] == len) {
            d->length_count[i]++;
            return;
        }
    }
    if (d->nlengths < MAX_LENGTHS) {
        d->lengths[d->nlengths] = len;
        d->length_count[d->nlengths++] = 1;
    } else {
        d->other_lengths++;
    }
}

/* Prints a packet in the chosen format: a RealTime packet decoded here, an
 * RTDE package as its source decoded it. */
static void print_packet(dump *d, FILE *out, const uint8_t *pkt, size_t len)
{
    static urrt_state decoded;
    sample s = {&decoded, NULL};
    if (d->src != NULL) {
        s.st = rtde_source_state(d->src);
        s.vals = rtde_source_values(d->src);
    } else if (d->replay != NULL) {
        s.st = rtde_replay_state(d->replay);
        s.vals = rtde_replay_values(d->replay);
    } else if (d->opt.fmt != FORMAT_GNUPLOT) {
        urrt_decode(pkt, len, &decoded);
    }
    switch (d->opt.fmt) {
    case FORMAT_GNUPLOT:
        if (s.vals != NULL) {
            print_gnuplot_rtde(d, out, &s);
        } else {
            print_gnuplot(d, out, pkt, len);
        }
        break;
    case FORMAT_CSV: print_csv(d, out, &s); break;
    case FORMAT_JSON: print_json(d, out, &s); break;
    default: print_table(d, out, &s); break;
    }
}

static void on_packet(void *ctx, const uint8_t *pkt, size_t len, uint64_t rx_us)
{
    dump *d = ctx;
    double t = NAN;

    if (d->done) {
        return;
    }
    if (d->record != NULL && d->pending_len > 0) {
        record_write(d, d->pending, d->pending_len);
        d->pending_len = 0;
    }
    d->packets++;
    note_length(d, (uint32_t)len);
    if (d->src != NULL || d->replay != NULL) {
        /* NaN only if the recipe lacked it */
        t = (d->src != NULL ? rtde_source_state(d->src) : rtde_replay_state(d->replay))->time[0];
    } else {
        d->gen_count[urrt_generation_of((uint32_t)len)]++;
        urrt_read_column(pkt, len, 1, &t);
    }
    if (isfinite(t)) {
        if (d->packets > 1 && isfinite(d->last_time)) {
            double gap = t - d->last_time;
            if (gap < 0) {
                d->time_backwards++;
            } else if (gap > d->largest_gap) {
                d->largest_gap = gap;
                d->largest_gap_before = d->packets;
            }
        }
        if (!isfinite(d->first_time)) {
            d->first_time = t;
        }
        d->last_time = t;
    }
    if (d->first_rx_us == 0) {
        d->first_rx_us = rx_us;
    }
    d->last_rx_us = rx_us;

    if ((d->packets - 1) % d->opt.every == 0 && !d->output_failed) {
        print_packet(d, stdout, pkt, len);
        if (ferror(stdout)) {
            d->output_failed = true;
            d->output_errno = errno;
            d->done = true;
        }
    }
    if (d->opt.count != 0 && d->packets >= d->opt.count) {
        d->done = true;
    }
}

/* ---- RTDE ------------------------------------------------------------------------ */

/* Whether no source gives a version for var on any controller line: only
 * the controller's answer to a setup tells (--list asks it). */
static bool rtde_version_unstated(int var)
{
    return urrt_rtde_var_available(var, 3, 255, 255) == URRT_RTDE_UNKNOWN &&
           urrt_rtde_var_available(var, 5, 255, 255) == URRT_RTDE_UNKNOWN &&
           urrt_rtde_var_available(var, 10, 255, 255) == URRT_RTDE_UNKNOWN;
}

/* Whether var is a row of one name in lib's table of RTDE-only values
 * (a status value such as safety_status_bits, not a register of a family). */
static bool rtde_single(int var)
{
    switch (var) {
#define X_SINGLE(ID, member, name, TYPE, first, names, split, since, since_hi) \
    case URRT_RTDE_V_##ID: return (names) == 1;
        URRT_RTDE_ONLY(X_SINGLE)
#undef X_SINGLE
    default: return false;
    }
}

/* Whether a recording asks for var without -k: every value RealTime has
 * too, and every RTDE-only status value, wherever the version table says
 * which controllers have it (the source leaves out those this one lacks).
 * Where no source gives a version the controller's NOT_FOUND would refuse
 * the whole recipe: those only with -k. */
static bool rtde_recorded(int var)
{
    static const uint32_t lines[] = {3, 5, 10}; /* CB3, e-Series, PolyScope X */
    if (urrt_rtde_var_field(var) < 0 && !rtde_single(var)) {
        return false;
    }
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        if (urrt_rtde_var_available(var, lines[i], 255, 255) == URRT_RTDE_UNKNOWN) {
            return false;
        }
    }
    return true;
}

/* Bytes of the recipe's name list: the names and the commas between them. */
static size_t rtde_names_size(const uint16_t *vars, size_t n)
{
    size_t size = n > 0 ? n - 1 : 0;
    for (size_t i = 0; i < n; i++) {
        char name[URRT_RTDE_NAME_MAX];
        int len = urrt_rtde_var_name(vars[i], name, sizeof name);
        size += len > 0 ? (size_t)len : 0;
    }
    return size;
}

static bool rtde_recipe_fits(const uint16_t *vars, size_t n)
{
    return n <= URRT_RTDE_MAX_VARS && rtde_names_size(vars, n) <= URRT_RTDE_NAMES_MAX;
}

/* A recording's recipe past UR's bounds (2048 bytes of names, or more
 * variables than a recipe holds): the last RTDE-only values not named by
 * -k are left out, and a notice names them. Returns the new count; if
 * even that does not fit, the recipe as it was (rtde_source_new refuses
 * it, and the -k names are what to shorten). */
static size_t rtde_recipe_fit(uint16_t *vars, bool *optional, size_t n)
{
    char left_out[URRT_RTDE_NAMES_MAX + 1];
    uint16_t kept[URRT_RTDE_VAR_COUNT];
    size_t len = 0, nkept = 0;
    for (size_t i = 0; i < n; i++) {
        if (!optional[i] || urrt_rtde_var_field(vars[i]) >= 0) {
            kept[nkept++] = vars[i];
        }
    }
    if (rtde_recipe_fits(vars, n) || !rtde_recipe_fits(kept, nkept)) {
        return n;
    }
    left_out[0] = '\0';
    for (size_t i = n; i-- > 0 && !rtde_recipe_fits(vars, n);) {
        char name[URRT_RTDE_NAME_MAX];
        if (!optional[i] || urrt_rtde_var_field(vars[i]) >= 0) {
            continue;
        }
        urrt_rtde_var_name(vars[i], name, sizeof name);
        if (len + 2 + strlen(name) < sizeof left_out) { /* fits: at most 2048 bytes are left out */
            len += (size_t)snprintf(left_out + len, sizeof left_out - len, "%s%s", len > 0 ? ", " : "", name);
        }
        memmove(vars + i, vars + i + 1, (n - i - 1) * sizeof *vars);
        memmove(optional + i, optional + i + 1, (n - i - 1) * sizeof *optional);
        n--;
    }
    if (len > 0) {
        urrt_log(URRT_LOG_NOTICE, "the recording leaves out %s: the recipe holds %d names in %d bytes at most "
                 "(fewer -k names make room)", left_out, URRT_RTDE_MAX_VARS, URRT_RTDE_NAMES_MAX);
    }
    return n;
}

/* The recipe: the timestamp always, then what -k asks for (required: a
 * controller without one ends the run), or without -k every field RTDE
 * shares with RealTime, each only where the controller has it; a recording
 * (-w) asks for those and the RTDE-only status values too, so that its
 * capture serves any configuration that needs only those, and -k adds
 * what else it should hold (registers); for --list the variables only the
 * controller can say it has. Returns the count. */
static size_t rtde_recipe(const options *o, uint16_t *vars, bool *optional)
{
    size_t n = 0;
    vars[n] = URRT_RTDE_V_TIMESTAMP;
    optional[n++] = false;
    for (int var = URRT_RTDE_V_TIMESTAMP + 1; var < (int)URRT_RTDE_VAR_COUNT; var++) {
        int field = urrt_rtde_var_field(var);
        bool named = o->fields_given && o->key_on[field >= 0 ? (unsigned)field : KEY_RTDE + (unsigned)var];
        bool asked;
        if (o->list) {
            asked = rtde_version_unstated(var);
        } else if (o->record_path != NULL) {
            asked = named || rtde_recorded(var);
        } else if (o->fields_given) {
            asked = named;
        } else {
            asked = field >= 0;
        }
        if (asked) {
            vars[n] = (uint16_t)var;
            optional[n++] = !o->list && !named;
        }
    }
    return o->record_path != NULL ? rtde_recipe_fit(vars, optional, n) : n;
}

static void version_text(const urrt_rtde *ses, char *out, size_t size)
{
    snprintf(out, size, "%" PRIu32 ".%" PRIu32 ".%" PRIu32 ".%" PRIu32, ses->controller[0], ses->controller[1],
             ses->controller[2], ses->controller[3]);
}

/* The -k names (as RTDE names them) that the controller lacks: by the
 * version table, and by its NOT_FOUND answer. */
static void report_missing_fields(dump *d, const urrt_rtde_event *ev)
{
    const urrt_rtde *ses = rtde_source_session(d->src);
    char version[48], name[URRT_RTDE_NAME_MAX];
    for (unsigned k = 0; k < d->opt.nkeys; k++) {
        int var = key_var(d->opt.key_order[k]);
        bool lacking = urrt_rtde_var_available(var, ses->controller[0], ses->controller[1], ses->controller[2]) == 0;
        for (size_t i = 0; ev->kind == URRT_RTDE_EV_CONFIG && urrt_rtde_not_found(ses, i) >= 0; i++) {
            lacking = lacking || urrt_rtde_not_found(ses, i) == var;
        }
        if (lacking) {
            char buf[URRT_RTDE_NAME_MAX];
            urrt_rtde_var_name(var, name, sizeof name);
            version_text(ses, version, sizeof version);
            urrt_log(URRT_LOG_ERR, "-k %s: the controller (version %s) has no RTDE output %s: leave it out of -k "
                     "(--rtde --list %s shows what this controller has)",
                     key_name(d->opt.key_order[k], buf, sizeof buf), version, name, d->opt.host);
            d->rtde_status = CLI_EXIT_RUNTIME;
        }
    }
}

/* --list: the controller's version, then each variable of lib's table with
 * its type and whether this version has it; where the table cannot say,
 * the controller's answer to the setup (not_found: its NOT_FOUND bits). */
static void print_list(const dump *d, bool answered)
{
    const urrt_rtde *ses = rtde_source_session(d->src);
    char version[48];
    version_text(ses, version, sizeof version);
    printf("controller %s, RTDE protocol %u\n", version, (unsigned)ses->protocol_accepted);
    printf("%-40s %-14s %-22s %s\n", "variable", "type", "urrt field", "this controller");
    for (int var = 0; var < (int)URRT_RTDE_VAR_COUNT; var++) {
        char name[URRT_RTDE_NAME_MAX];
        int field = urrt_rtde_var_field(var);
        int has = urrt_rtde_var_available(var, ses->controller[0], ses->controller[1], ses->controller[2]);
        const char *says = has == 1 ? "yes" : has == 0 ? "no" : "yes (asked: no version known)";
        if (has == URRT_RTDE_UNKNOWN) {
            bool not_found = false;
            for (size_t i = 0; urrt_rtde_not_found(ses, i) >= 0; i++) {
                not_found = not_found || urrt_rtde_not_found(ses, i) == var;
            }
            says = !answered ? "unknown (not asked)" : not_found ? "no (asked: NOT_FOUND)" : says;
        }
        urrt_rtde_var_name(var, name, sizeof name);
        printf("%-40s %-14s %-22s %s\n", name, urrt_rtde_type_name(urrt_rtde_var_type(var)),
               field >= 0 ? urrt_field((urrt_field_id)field)->name : "-", says);
    }
}

/* A text message of the controller on stderr with its level. The source
 * logs it already (exception and error as errors, warning as a warning,
 * the rest as info); what that hides at this log level is shown here. */
static void show_text(const dump *d, const char *robot, const urrt_rtde_event *ev)
{
    static const char *const level_names[] = {"exception", "error", "warning", "info"};
    if (ev->level < URRT_RTDE_LEVEL_INFO || d->opt.log_level >= URRT_LOG_INFO) {
        return;
    }
    urrt_log(URRT_LOG_NOTICE, "robot %s: controller says (%s)%s%.*s: %.*s", robot,
             ev->level <= URRT_RTDE_LEVEL_INFO ? level_names[ev->level] : "level past info",
             ev->source_len > 0 ? " from " : "", (int)ev->source_len, ev->source_len > 0 ? ev->source : "",
             (int)ev->text_len, ev->text);
}

/* The session's events beside its data: what ends the run. */
static void on_rtde_event(void *ctx, const urrt_rtde_event *ev, uint64_t rx_us)
{
    dump *d = ctx;
    (void)rx_us;
    if (ev->kind == URRT_RTDE_EV_TEXT) {
        show_text(d, d->opt.host, ev);
        return;
    }
    if (d->done) {
        return;
    }
    if (d->opt.list && (ev->kind == URRT_RTDE_EV_RECIPE ||
                        (ev->kind == URRT_RTDE_EV_CONFIG && ev->error == URRT_RTDE_E_NOT_FOUND))) {
        /* The controller answered: a NOT_FOUND is the answer here, not
         * the error the link would log as it drops the connection. */
        print_list(d, true);
        d->done = true;
        d->hush_drop = ev->kind == URRT_RTDE_EV_CONFIG;
    } else if (!d->opt.list && d->opt.fields_given &&
               (ev->kind == URRT_RTDE_EV_CONTROLLER || ev->kind == URRT_RTDE_EV_CONFIG)) {
        report_missing_fields(d, ev);
        d->done = d->hush_drop = d->rtde_status != CLI_EXIT_OK;
    }
    if (d->hush_drop) {
        /* Said above in urrt-dump's words: the link's line as it drops the
         * connection (for a gateway's configuration) would only confuse.
         * run_link restores the level. */
        urrt_log_set_level((urrt_log_level)(URRT_LOG_ERR - 1));
    }
    if (!d->done && ev->kind == URRT_RTDE_EV_CONFIG) {
        /* The source logs why (names, version); a retry gets the same. */
        d->rtde_status = CLI_EXIT_RUNTIME;
        d->done = true;
    }
}

/* The session's bytes into the capture (-w), up to the package that ends
 * the run; a failed write is told once and ends the recording, not the run. */
static void on_rtde_tap(void *ctx, rtde_source_tap what, const uint8_t *data, size_t len)
{
    dump *d = ctx;
    bool ok = true;
    if (d->capture == NULL || d->record_failed || d->done) {
        return;
    }
    switch (what) {
    case RTDE_SOURCE_TAP_CONNECTED: ok = rtde_capture_connected(d->capture, urrt_link_peer(d->link)); break;
    case RTDE_SOURCE_TAP_SENT: ok = rtde_capture_sent(d->capture, data, len); break;
    default: ok = rtde_capture_received(d->capture, data, len); break;
    }
    if (!ok) {
        urrt_log(URRT_LOG_ERR, "cannot write the capture %s: %s; it ends at the last record written, the run goes "
                 "on", d->opt.record_path, strerror(errno));
        d->record_failed = true;
    }
}

/* The RTDE source of the run, set on the link; false (logged) when the
 * recipe cannot be. */
static bool open_rtde(dump *d, urrt_link *link)
{
    static uint16_t vars[URRT_RTDE_VAR_COUNT];
    static bool optional[URRT_RTDE_VAR_COUNT];
    char why[300];
    rtde_source_config cfg = {.name = d->opt.host, .vars = vars, .optional = optional};
    cfg.count = rtde_recipe(&d->opt, vars, optional);
    d->src = rtde_source_new(&cfg, why, sizeof why);
    if (d->src == NULL) {
        urrt_log(URRT_LOG_ERR, "%s%s", why, !d->opt.fields_given ? ""
                 : d->opt.record_path != NULL ? " (-k asks for too many values beside the RealTime set a recording "
                                                "asks for)"
                                              : " (-k asks for too many values)");
        return false;
    }
    rtde_source_set_event_fn(d->src, on_rtde_event, d);
    if (d->capture != NULL) {
        rtde_source_set_tap(d->src, on_rtde_tap, d);
    }
    return rtde_source_attach(d->src, link);
}

/* ---- sources ------------------------------------------------------------------ */

/* The name of the file read, for messages. */
static const char *file_name(const dump *d)
{
    return strcmp(d->opt.file_path, "-") == 0 ? "the input" : d->opt.file_path;
}

/* A RealTime capture: the framer over the file's bytes, first the byte
 * read to tell the kind (if any). */
static int run_realtime_file(dump *d, int fd, const uint8_t *first, size_t first_len)
{
    static uint8_t buf[65536];
    urrt_framer fr;
    int status = CLI_EXIT_OK;
    bool at_first = true;

    urrt_framer_init(&fr);
    while (running && !d->done) {
        ssize_t n;
        const uint8_t *p = buf;
        if (at_first) {
            memcpy(buf, first, first_len);
            n = (ssize_t)first_len;
            at_first = false;
        } else {
            n = read(fd, buf, sizeof buf);
        }
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            urrt_log(URRT_LOG_ERR, "cannot read %s: %s", d->opt.file_path, strerror(errno));
            status = CLI_EXIT_RUNTIME;
            break;
        }
        if (n == 0) {
            d->partial_at_end = urrt_framer_finish(&fr);
            break;
        }
        while (n > 0 && !d->done) {
            size_t used = 0;
            int got = urrt_framer_feed(&fr, p, (size_t)n, &used);
            d->fstats = fr.stats;
            on_bytes(d, p, used);
            if (got == 1) {
                size_t len;
                const uint8_t *pkt = urrt_framer_packet(&fr, &len);
                on_packet(d, pkt, len, 0);
            }
            p += used;
            n -= (ssize_t)used;
        }
    }
    d->fstats = fr.stats;
    if (status == CLI_EXIT_OK && running && d->packets == 0) {
        urrt_log(URRT_LOG_ERR, "%s holds no RealTime packet (%" PRIu64 " bytes): give a raw capture of port 30003 "
                 "or 30013 (nc robot 30003 > FILE, urrt-dump -w FILE) or an RTDE capture (urrt-dump --rtde -w FILE)",
                 file_name(d), fr.stats.bytes);
        status = CLI_EXIT_RUNTIME;
    }
    return status;
}

/* A text message of the recorded controller, at the level rtde_source
 * gives it live. */
static void replay_text(const dump *d, const char *robot, const urrt_rtde_event *ev)
{
    urrt_log_level level = ev->level <= URRT_RTDE_LEVEL_ERROR     ? URRT_LOG_ERR
                           : ev->level == URRT_RTDE_LEVEL_WARNING ? URRT_LOG_WARNING
                                                                  : URRT_LOG_INFO;
    urrt_log(level, "robot %s: controller says%s%.*s: %.*s", robot, ev->source_len > 0 ? " from " : "",
             (int)ev->source_len, ev->source_len > 0 ? ev->source : "", (int)ev->text_len, ev->text);
    show_text(d, robot, ev);
}

/* -k against the recipe of a session of the capture: a name it lacks was
 * not recorded; false (logged) if any. */
static bool capture_has_keys(const dump *d)
{
    char buf[URRT_RTDE_NAME_MAX], name[URRT_RTDE_NAME_MAX];
    bool ok = true;
    for (unsigned k = 0; k < d->opt.nkeys; k++) {
        int var = key_var(d->opt.key_order[k]);
        if (!rtde_replay_has(d->replay, var)) {
            urrt_rtde_var_name(var, name, sizeof name);
            urrt_log(URRT_LOG_ERR, "-k %s: the capture %s holds no %s (its session with %s did not ask for it): "
                     "leave it out of -k, or record it with urrt-dump --rtde -w FILE -k %s", key_name(d->opt.key_order[k], buf, sizeof buf),
                     file_name(d), name, rtde_replay_peer(d->replay), name);
            ok = false;
        }
    }
    return ok;
}

/* An RTDE capture, f positioned at its first byte: replayed through
 * lib/urrt_rtde's client (rtde_replay), each data package printed as the
 * live session printed it, each connection's events logged as they were. */
static int run_rtde_file(dump *d, FILE *f)
{
    char why[600];
    int status = CLI_EXIT_OK;
    urrt_rtde_event ev;

    if (d->opt.record_path != NULL) {
        cli_usage_error(PROGRAM, "%s is an RTDE capture: -w records a robot (urrt-dump --rtde -w FILE HOST); "
                        "to keep the capture, copy it", file_name(d));
    }
    if (!d->opt.rtde) {
        check_keys(&d->opt, true, file_name(d));
    }
    d->replay = rtde_replay_open(f, file_name(d), why, sizeof why);
    if (d->replay == NULL) {
        urrt_log(URRT_LOG_ERR, "%s", why);
        return CLI_EXIT_RUNTIME;
    }
    while (running && !d->done) {
        int k = rtde_replay_next(d->replay, &ev, why, sizeof why);
        const char *robot = rtde_replay_peer(d->replay);
        if (k == 0) {
            d->cut_short = rtde_replay_truncated(d->replay);
            if (d->cut_short > 0) {
                urrt_log(URRT_LOG_NOTICE, "%s: the last record is cut short (%zu bytes, the recording ended while "
                         "writing it): left out", file_name(d), d->cut_short);
            }
            break;
        }
        if (k < 0) {
            urrt_log(URRT_LOG_ERR, "%s", why);
            status = CLI_EXIT_RUNTIME;
            break;
        }
        switch (k) {
        case RTDE_REPLAY_SESSION:
            d->sessions++;
            urrt_log(d->sessions > 1 ? URRT_LOG_NOTICE : URRT_LOG_INFO, "%s: session %" PRIu64 ": connected to %s",
                     file_name(d), d->sessions, robot);
            break;
        case URRT_RTDE_EV_FALLBACK:
            urrt_log(URRT_LOG_NOTICE, "robot %s: the controller refuses RTDE protocol %d: asking for %u", robot,
                     URRT_RTDE_PROTOCOL, (unsigned)ev.protocol);
            break;
        case URRT_RTDE_EV_RECIPE:
            if (!capture_has_keys(d)) {
                status = CLI_EXIT_RUNTIME;
                d->done = true;
            }
            break;
        case URRT_RTDE_EV_TEXT: replay_text(d, robot, &ev); break;
        case URRT_RTDE_EV_DATA: {
            size_t size;
            const uint8_t *pkg = rtde_replay_package(d->replay, &size);
            on_packet(d, pkg, size, 0);
            break;
        }
        case URRT_RTDE_EV_DROP:
            urrt_log(URRT_LOG_WARNING, "robot %s: the recorded session broke the RTDE protocol (%s): the client "
                     "dropped the connection", robot, urrt_rtde_strerror(ev.error));
            break;
        case URRT_RTDE_EV_CONFIG:
            urrt_log(URRT_LOG_ERR, "robot %s: the recorded session was refused: %s; the client ended it there",
                     robot, urrt_rtde_strerror(ev.error));
            status = CLI_EXIT_RUNTIME;
            break;
        default: break;
        }
    }
    if (status == CLI_EXIT_OK && running && !d->done && d->packets == 0) {
        urrt_log(URRT_LOG_ERR, "%s holds no RTDE data package (%" PRIu64 " sessions): record one with urrt-dump "
                 "--rtde -w FILE HOST", file_name(d), d->sessions);
        status = CLI_EXIT_RUNTIME;
    }
    return status;
}

/* A capture: its first byte says which kind (rtde_capture.h: 'U' starts an
 * RTDE capture, a RealTime stream starts with a size's high byte, 0). */
static int run_file(dump *d)
{
    bool from_stdin = strcmp(d->opt.file_path, "-") == 0;
    int fd = from_stdin ? STDIN_FILENO : open(d->opt.file_path, O_RDONLY | O_CLOEXEC);
    uint8_t first = 0;
    ssize_t n;
    FILE *f;
    int status;

    if (fd < 0) {
        urrt_log(URRT_LOG_ERR, "cannot open %s: %s", d->opt.file_path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    while ((n = read(fd, &first, 1)) < 0 && errno == EINTR && running) {
    }
    if (n < 0) {
        urrt_log(URRT_LOG_ERR, "cannot read %s: %s", d->opt.file_path, strerror(errno));
        status = CLI_EXIT_RUNTIME;
    } else if (n == 1 && first == RTDE_CAPTURE_FIRST_BYTE) {
        /* The capture reader takes the file from its first byte. */
        f = from_stdin ? stdin : fdopen(fd, "rb");
        if (f == NULL || ungetc(first, f) == EOF) {
            urrt_log(URRT_LOG_ERR, "cannot read %s: %s", d->opt.file_path, strerror(errno));
            status = CLI_EXIT_RUNTIME;
        } else {
            status = run_rtde_file(d, f);
            if (!from_stdin) {
                fclose(f);
                fd = -1;
            }
        }
    } else if (d->opt.rtde) {
        cli_usage_error(PROGRAM, "--rtde --file %s: %s is no RTDE capture (%s; an RTDE capture starts with "
                        "\"%.*s\"): drop --rtde to read a RealTime capture", d->opt.file_path, file_name(d),
                        n == 0 ? "it is empty" : first == 0 ? "it starts as a RealTime capture does, with 0x00"
                                                            : "its first byte is no capture's",
                        RTDE_CAPTURE_MAGIC_LEN - 1, RTDE_CAPTURE_MAGIC);
    } else {
        check_keys(&d->opt, false, file_name(d));
        status = open_record(d) ? run_realtime_file(d, fd, &first, (size_t)n) : CLI_EXIT_RUNTIME;
    }
    if (fd >= 0 && !from_stdin) {
        close(fd);
    }
    return status;
}

typedef struct link_ctx {
    dump *d;
    urrt_link *link;
} link_ctx;

static void snapshot_link(void *ctx, const uint8_t *pkt, size_t len, uint64_t rx_us)
{
    link_ctx *lc = ctx;
    if (lc->d->done) {
        return;
    }
    on_packet(lc->d, pkt, len, rx_us);
    /* The counters as they stood at this packet: what the summary reports
     * when this is the last one. */
    lc->d->lstats = *urrt_link_get_stats(lc->link);
}

static urrt_link *open_link(dump *d)
{
    urrt_link_config cfg;
    urrt_link *link;
    urrt_link_config_defaults(&cfg);
    cfg.host = d->opt.host;
    cfg.port = d->opt.port;
    cfg.name = d->opt.host;
    cfg.connect_timeout_ms = d->opt.connect_timeout_ms;
    cfg.silence_timeout_ms = d->opt.silence_timeout_ms;
    cfg.backoff_max_ms = d->opt.backoff_max_ms;
    link = urrt_link_new(&cfg);
    d->link = link;
    if (link != NULL && d->opt.rtde && !open_rtde(d, link)) {
        urrt_link_free(link);
        return NULL;
    }
    if (link != NULL && !d->opt.rtde) {
        urrt_link_set_tap(link, on_bytes, d);
    }
    return link;
}

/* Waits for the link's descriptor until its deadline, a second at most.
 * False (logged) on a poll error other than EINTR. */
static bool wait_link(const urrt_link *link)
{
    short events = 0;
    int fd = urrt_link_poll_fd(link, &events);
    uint64_t now = urrt_port_monotonic_us();
    uint64_t deadline = urrt_link_deadline(link);
    int timeout_ms = 1000;
    struct pollfd pfd = {.fd = fd, .events = events};

    if (deadline <= now) {
        timeout_ms = 0;
    } else if (deadline - now < 1000000u) {
        timeout_ms = (int)((deadline - now + 999u) / 1000u);
    }
    if (poll(&pfd, fd >= 0 ? 1 : 0, timeout_ms) < 0 && errno != EINTR) {
        urrt_log(URRT_LOG_ERR, "poll: %s", strerror(errno));
        return false;
    }
    return true;
}

/* Progress as the loop watches it: when the last packet came, and when to
 * say that none has come for a while (at growing intervals). */
typedef struct progress {
    uint64_t last_us;
    uint64_t quiet_interval_us;
    uint64_t quiet_notice_at;
    uint64_t seen_packets;
    uint64_t seen_disconnects;
} progress;

static void watch_progress(dump *d, const urrt_link *link, progress *p, uint64_t now)
{
    const urrt_link_stats *ls = urrt_link_get_stats(link);
    if (ls->disconnects != p->seen_disconnects) {
        /* Bytes of a packet the connection ended inside: the next
         * connection starts a new packet, so they never complete one
         * and stay out of the recording. */
        p->seen_disconnects = ls->disconnects;
        d->pending_len = 0;
    }
    if (ls->packets != p->seen_packets) {
        p->seen_packets = ls->packets;
        p->last_us = now;
        p->quiet_interval_us = QUIET_NOTICE_FIRST_US;
        p->quiet_notice_at = now + p->quiet_interval_us;
    }
    if (!d->done && now >= p->quiet_notice_at) {
        urrt_log(URRT_LOG_NOTICE, "%s: no packet for %.0f s (link %s, %" PRIu64 " connect failures): check the "
                 "address and the port (%s)%s", urrt_link_peer(link),
                 (double)(now - p->last_us) / 1e6, urrt_link_state_name(urrt_link_get_state(link)),
                 ls->connect_failures, d->opt.rtde ? RTDE_HINT : "30003, or the read-only 30013",
                 d->opt.timeout_s > 0 ? "" : "; -t SEC gives up after SEC seconds");
        p->quiet_interval_us = p->quiet_interval_us * 2 < QUIET_NOTICE_MAX_US ? p->quiet_interval_us * 2
                                                                              : QUIET_NOTICE_MAX_US;
        p->quiet_notice_at = now + p->quiet_interval_us;
    }
}

/* Whether to stop waiting for packets (--once after the connection ended
 * or failed, -t after a silence that long); *status says if that failed. */
static bool give_up(const dump *d, const urrt_link *link, const progress *p, uint64_t now, int *status)
{
    const urrt_link_stats *ls = urrt_link_get_stats(link);
    if (d->opt.once && !d->done && (ls->disconnects > 0 || (ls->connect_failures > 0 && ls->connects == 0))) {
        if (d->packets == 0) {
            urrt_log(URRT_LOG_ERR, "%s: no %s (%s, see above); check the address and port%s, "
                     "or drop --once to keep trying", urrt_link_peer(link),
                     d->opt.rtde ? "RTDE data package" : "RealTime packet",
                     ls->connects > 0 ? "the connection ended first"
                     : d->opt.rtde    ? "no connection, or no handshake"
                                      : "no connection",
                     d->opt.rtde ? " (" RTDE_HINT ")" : "");
            *status = CLI_EXIT_RUNTIME;
        }
        return true;
    }
    if (d->opt.timeout_s > 0 && !d->done && (double)(now - p->last_us) / 1e6 >= d->opt.timeout_s) {
        urrt_log(URRT_LOG_ERR, "%s: no packet for %g s (link %s); giving up", urrt_link_peer(link),
                 d->opt.timeout_s, urrt_link_state_name(urrt_link_get_state(link)));
        *status = CLI_EXIT_RUNTIME;
        return true;
    }
    return false;
}

static int run_link(dump *d)
{
    link_ctx lc = {.d = d};
    progress p = {.quiet_interval_us = QUIET_NOTICE_FIRST_US};
    int status = CLI_EXIT_OK;

    lc.link = open_link(d);
    if (lc.link == NULL) {
        return CLI_EXIT_RUNTIME;
    }
    if (d->opt.list) {
        d->opt.once = true; /* a list, not a vigil: one attempt */
    }
    p.last_us = urrt_port_monotonic_us();
    p.quiet_notice_at = p.last_us + p.quiet_interval_us;
    while (running && !d->done) {
        uint64_t now;
        if (!wait_link(lc.link)) {
            status = CLI_EXIT_RUNTIME;
            break;
        }
        now = urrt_port_monotonic_us();
        urrt_link_service(lc.link, now, snapshot_link, &lc);
        if (!d->done) {
            d->lstats = *urrt_link_get_stats(lc.link);
        }
        watch_progress(d, lc.link, &p, now);
        if (give_up(d, lc.link, &p, now, &status)) {
            break;
        }
    }
    urrt_log_set_level(d->opt.log_level); /* after a hushed drop */
    urrt_link_free(lc.link);
    d->link = NULL;
    return status != CLI_EXIT_OK ? status : d->rtde_status;
}

/* ---- summary ------------------------------------------------------------------ */

/* The RTDE session: controller, protocol, the recipe asked for, and what
 * lib's session counted (urrt_rtde_stats) in RTDE's words, not RealTime's
 * resyncs: RTDE packages carry their size, a framer never hunts for one. */
static void print_summary_rtde(const dump *d, FILE *out)
{
    const urrt_rtde *ses = rtde_session_of(d);
    static char recipe[URRT_RTDE_NAMES_MAX + 1];
    char version[48];
    version_text(ses, version, sizeof version);
    if (ses->controller[0] == 0) {
        snprintf(version, sizeof version, "unknown (no handshake)");
    }
    if (d->src != NULL) {
        rtde_source_recipe_text(d->src, recipe, sizeof recipe);
    } else {
        /* The capture's last session: its setup request's names. */
        size_t len = 0;
        recipe[0] = '\0';
        for (size_t i = 0; i < ses->var_count && len < sizeof recipe - 1; i++) {
            char name[URRT_RTDE_NAME_MAX];
            urrt_rtde_var_name(ses->vars[i], name, sizeof name);
            len += (size_t)snprintf(recipe + len, sizeof recipe - len, "%s%s", i > 0 ? "," : "", name);
        }
    }
    fprintf(out, "summary: rtde: controller %s, protocol %u\n", version, (unsigned)ses->protocol_accepted);
    fprintf(out, "summary: rtde recipe: %s\n", recipe);
    fprintf(out, "summary: rtde packages: %" PRIu64 ", data packages: %" PRIu64 ", text messages: %" PRIu64
            ", ignored: %" PRIu64 ", errors: %" PRIu64 ", bytes: %" PRIu64 "\n", ses->stats.packages,
            ses->stats.data, ses->stats.texts, ses->stats.ignored, ses->stats.errors, ses->stats.bytes);
    if (d->src != NULL) {
        /* What urrt_rtde_finish would drop as the run closes the connection:
         * the bytes of a package begun and not complete. */
        fprintf(out, "summary: rtde partial package dropped at close: %u bytes\n", (unsigned)ses->have);
    }
    if (d->replay != NULL) {
        fprintf(out, "summary: rtde capture: sessions %" PRIu64 ", last record cut short: %zu bytes\n", d->sessions,
                d->cut_short);
    }
}

static void print_summary(const dump *d, bool from_link)
{
    FILE *out = stderr;
    fprintf(out, "summary: packets: %" PRIu64 "\n", d->packets);
    fprintf(out, "summary: lengths:");
    for (size_t i = 0; i < d->nlengths; i++) {
        const char *v = rtde_session_of(d) != NULL ? "RTDE data packages" : urrt_versions_of(d->lengths[i]);
        fprintf(out, "%s %" PRIu32 " x %" PRIu64 " (%s)", i > 0 ? ";" : "", d->lengths[i], d->length_count[i],
                v != NULL ? v : "no known controller");
    }
    if (d->other_lengths > 0) {
        fprintf(out, "; %" PRIu64 " of other lengths", d->other_lengths);
    }
    fprintf(out, "%s\n", d->nlengths == 0 ? " none" : "");
    if (rtde_session_of(d) != NULL) {
        print_summary_rtde(d, out);
    } else {
        fprintf(out, "summary: generations: 1.x %" PRIu64 ", 3.x/5.x %" PRIu64 ", unknown %" PRIu64 "\n",
                d->gen_count[URRT_GEN_1X], d->gen_count[URRT_GEN_3X], d->gen_count[URRT_GEN_UNKNOWN]);
    }
    if (from_link) {
        if (d->src == NULL) { /* RealTime's framer; RTDE's session said its own above */
            fprintf(out, "summary: resyncs: %" PRIu64 ", skipped bytes: %" PRIu64 "\n", d->lstats.resyncs,
                    d->lstats.skipped);
            fprintf(out, "summary: partial packets dropped: %" PRIu64 " (%" PRIu64 " bytes)\n",
                    d->lstats.partial_drops, d->lstats.partial_bytes);
        }
        fprintf(out,
                "summary: link: connects %" PRIu64 ", reconnects %" PRIu64 ", disconnects %" PRIu64
                ", silences %" PRIu64 ", connect failures %" PRIu64 "\n",
                d->lstats.connects, d->lstats.reconnects, d->lstats.disconnects, d->lstats.silences,
                d->lstats.connect_failures);
    } else if (d->replay == NULL) { /* an RTDE capture's own line said where it ends */
        fprintf(out, "summary: resyncs: %" PRIu64 ", skipped bytes: %" PRIu64 "\n", d->fstats.resyncs,
                d->fstats.skipped);
        fprintf(out, "summary: partial packet dropped at end: %zu bytes\n", d->partial_at_end);
    }
    if (d->packets > 1 && d->last_time > d->first_time) {
        fprintf(out, "summary: mean rate: %.3f Hz by controller time", (double)(d->packets - 1) / (d->last_time - d->first_time));
        if (from_link && d->last_rx_us > d->first_rx_us) {
            fprintf(out, ", %.3f Hz by arrival", (double)(d->packets - 1) * 1e6 / (double)(d->last_rx_us - d->first_rx_us));
        }
        fputc('\n', out);
        fprintf(out, "summary: largest gap: %.6f s (controller time) before packet %" PRIu64 "\n", d->largest_gap,
                d->largest_gap_before);
    }
    if (d->time_backwards > 0) {
        fprintf(out, "summary: time went backwards: %" PRIu64 " times (controller restarted, or a spliced capture)\n",
                d->time_backwards);
    }
}

int main(int argc, char **argv)
{
    static dump d;
    int status;

    parse_options(argc, argv, &d.opt);
    urrt_log_init(PROGRAM, d.opt.log_level);
    cli_handle_signals(&running);
    d.first_time = NAN;
    d.last_time = NAN;
    if (d.opt.record_path != NULL && d.opt.rtde && d.opt.file_path == NULL) {
        char why[400];
        d.capture = rtde_capture_create(d.opt.record_path, why, sizeof why);
        if (d.capture == NULL) {
            urrt_log(URRT_LOG_ERR, "%s", why);
            return CLI_EXIT_RUNTIME;
        }
    } else if (d.opt.file_path == NULL && !open_record(&d)) {
        return CLI_EXIT_RUNTIME; /* a file's kind is known once it is open: run_file opens it */
    }
    if (d.opt.file_path == NULL) {
        setvbuf(stdout, NULL, _IOLBF, 0); /* live: each packet as it comes */
    }
    status = d.opt.file_path != NULL ? run_file(&d) : run_link(&d);
    if (!d.output_failed && fflush(stdout) != 0) {
        d.output_failed = true;
        d.output_errno = errno;
    }
    /* A reader that went away (| head) is a normal end. */
    if (d.output_failed && d.output_errno != EPIPE) {
        urrt_log(URRT_LOG_ERR, "cannot write the output: %s", strerror(d.output_errno));
        status = CLI_EXIT_RUNTIME;
    }
    if (d.record != NULL) {
        /* A partial packet at the end is left out: the file ends on a packet. */
        if (fclose(d.record) != 0 || d.record_failed) {
            urrt_log(URRT_LOG_ERR, "cannot write the recording %s: %s", d.opt.record_path, strerror(errno));
            status = CLI_EXIT_RUNTIME;
        }
    }
    if (d.capture != NULL) {
        char why[400];
        size_t held = 0;
        /* It ends on a record: a package the run did not see whole is left out. */
        if (!rtde_capture_close(d.capture, &held, why, sizeof why)) {
            urrt_log(URRT_LOG_ERR, "%s", why);
            status = CLI_EXIT_RUNTIME;
        } else if (held > 0) {
            urrt_log(URRT_LOG_INFO, "the capture %s ends at the last whole package (%zu bytes of the next left out)",
                     d.opt.record_path, held);
        }
    }
    if (d.opt.summary && !d.opt.list) {
        print_summary(&d, d.opt.file_path == NULL);
    }
    rtde_source_free(d.src);
    rtde_replay_free(d.replay);
    free(d.pending);
    return status;
}
