/* SPDX-License-Identifier: MIT */
/*
 * urrt-dump: see what a robot sends on its RealTime port.
 *
 * Reads from a robot or simulator through the port's robot link (so it
 * reconnects like the gateway does), or from a raw capture, and prints each
 * packet as a table, CSV, JSON lines or gnuplot columns. A summary of the
 * stream goes to stderr at the end. See usage() and docs/tools.md.
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
#include "urrt.h"

#define PROGRAM "urrt-dump"
#define MAX_LENGTHS 16
/* Bytes held back from the recording until the packet they lead to is
 * complete (garbage, then the packet); past this they are written anyway. */
#define RECORD_PENDING_MAX (1u << 20)
/* No packet for this long: say so (then at twice the interval, up to a minute),
 * so that a wrong port does not look like a robot that is just slow to start. */
#define QUIET_NOTICE_FIRST_US 3000000u
#define QUIET_NOTICE_MAX_US 60000000u

typedef enum format { FORMAT_TABLE, FORMAT_CSV, FORMAT_JSON, FORMAT_GNUPLOT } format;

static volatile sig_atomic_t running = 1;

typedef struct options {
    format fmt;
    bool fields_given;
    bool field_on[URRT_FIELD_COUNT];
    unsigned field_order[URRT_FIELD_COUNT]; /* the fields to print, in this order */
    unsigned nfields;
    uint64_t count;
    uint64_t every;
    const char *record_path;
    const char *file_path;
    char host[256];
    uint16_t port;
    bool once;
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
    /* recording */
    FILE *record;
    uint8_t *pending;
    size_t pending_len;
    bool record_failed;
} dump;

static void usage(FILE *out)
{
    fprintf(out,
"Usage: " PROGRAM " [options] HOST[:PORT]\n"
"       " PROGRAM " [options] --file PATH|-\n"
"\n"
"Prints what a Universal Robots controller sends on its RealTime port\n"
"(30003, or the read-only 30013), from the robot or simulator at HOST (port\n"
"30003 unless given; IPv6 as [::1]:30003) or from a raw capture. It never\n"
"sends a byte to the robot, and reconnects when the link drops.\n"
"\n"
"Output (stdout):\n"
"  -F, --format FMT        table (default): names, units, enum names, bit masks\n"
"                          csv: a header row of field names, one row per packet\n"
"                          json: one object per packet per line\n"
"                          gnuplot: every double of the packet in wire order,\n"
"                          printed round-trip exact, so that column N is UR's\n"
"                          \"Gnuplot col.\" N (column 1 is the time)\n"
"  -k, --fields A,B,...    only these fields, in this order (table, csv, json);\n"
"                          names as in the field table, e.g. time,q_actual\n"
"  -n, --count N           stop after N packets\n"
"  -e, --every N           print every Nth packet only (all are counted)\n"
"  -w, --record PATH       save the raw stream (every byte up to the last\n"
"                          complete packet); it replays through --file and\n"
"                          urrt-sim --replay\n"
"      --no-summary        no summary on stderr at the end\n"
"\n"
"Source:\n"
"  -f, --file PATH         read a raw capture instead of a robot; - is stdin\n"
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
"for a robot the link's connects, reconnects and silences.\n"
"\n"
"Exit status: 0 done (--count reached, end of file, SIGINT/SIGTERM, end of\n"
"connection with --once), 1 runtime error (cannot open or write a file, a\n"
"file without a packet, no packet within --timeout, --once without a\n"
"packet), 2 usage error.\n"
"\n"
"Examples:\n"
"  " PROGRAM " 192.168.1.10:30013 -n 1                # one packet, as a table\n"
"  " PROGRAM " -F csv -k time,q_actual,i_actual robot -n 5000 > joints.csv\n"
"  " PROGRAM " -F gnuplot [::1]:30003 -w capture.bin -n 2500 > capture.dat\n"
"  " PROGRAM " -F json --file capture.bin | head\n"
"  nc robot 30013 | " PROGRAM " --file - -F gnuplot > live.dat\n");
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
        int id = urrt_field_find(p, n);
        if (id < 0) {
            fprintf(stderr, PROGRAM ": --fields: no field named \"%.*s\". Fields:\n", (int)n, p);
            for (unsigned i = 0; i < URRT_FIELD_COUNT; i++) {
                const urrt_field_info *f = urrt_field((urrt_field_id)i);
                fprintf(stderr, "  %-22s %-11s %s\n", f->name, f->unit[0] ? f->unit : "-", f->description);
            }
            exit(CLI_EXIT_USAGE);
        }
        if (!o->field_on[id]) {
            o->field_on[id] = true;
            o->field_order[o->nfields++] = (unsigned)id;
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

/* The source: a file, or one robot. */
static void check_source(int argc, char **argv, int operand, options *o)
{
    const char *err;
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
    if ((err = cli_parse_host_port(argv[operand], URRT_LINK_PORT_RW, o->host, sizeof o->host, &o->port)) != NULL) {
        cli_usage_error(PROGRAM, "%s: %s", argv[operand], err);
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

/* The ids to print: those asked for, in the order asked, or else the packet's. */
static unsigned selected_fields(const dump *d, const urrt_state *st, unsigned *ids)
{
    unsigned n = 0;
    if (d->opt.fields_given) {
        memcpy(ids, d->opt.field_order, d->opt.nfields * sizeof *ids);
        return d->opt.nfields;
    }
    for (unsigned id = 0; id < URRT_FIELD_COUNT; id++) {
        if (urrt_has(st, id)) {
            ids[n++] = id;
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

static void print_csv(dump *d, FILE *out, const urrt_state *st)
{
    bool first = true;
    if (!d->csv_header_done) {
        /* Without --fields the columns are those of the first packet. */
        if (!d->opt.fields_given) {
            d->opt.nfields = selected_fields(d, st, d->opt.field_order);
            d->opt.fields_given = true;
        }
        for (unsigned k = 0; k < d->opt.nfields; k++) {
            const urrt_field_info *f = urrt_field((urrt_field_id)d->opt.field_order[k]);
            for (unsigned i = 0; i < f->count; i++) {
                fprintf(out, first ? "%s" : ",%s", f->name);
                if (f->count > 1) {
                    fprintf(out, "[%u]", i);
                }
                first = false;
            }
        }
        fputc('\n', out);
        d->csv_header_done = true;
        first = true;
    }
    for (unsigned k = 0; k < d->opt.nfields; k++) {
        unsigned id = d->opt.field_order[k];
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        const double *v = urrt_field_values(st, id);
        for (unsigned i = 0; i < f->count; i++) {
            if (!first) {
                fputc(',', out);
            }
            first = false;
            if (urrt_has(st, id)) {
                print_number(out, v[i], false);
            }
        }
    }
    fputc('\n', out);
}

static bool is_bits(const urrt_field_info *f)
{
    return strcmp(f->unit, "bits") == 0;
}

static void print_json(const dump *d, FILE *out, const urrt_state *st)
{
    const char *versions = urrt_versions_of(st->length);
    fprintf(out, "{\"packet\":%" PRIu64 ",\"length\":%u,\"generation\":\"%s\"", d->packets, (unsigned)st->length,
            st->generation == URRT_GEN_1X ? "1.x" : st->generation == URRT_GEN_3X ? "3.x/5.x" : "unknown");
    if (versions != NULL) {
        fprintf(out, ",\"versions\":\"%s\"", versions);
    }
    if (st->extra_columns > 0) {
        fprintf(out, ",\"extra_columns\":%u", (unsigned)st->extra_columns);
    }
    unsigned ids[URRT_FIELD_COUNT];
    unsigned n = selected_fields(d, st, ids);
    for (unsigned k = 0; k < n; k++) {
        unsigned id = ids[k];
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        const double *v = urrt_field_values(st, id);
        urrt_enum_kind kind = urrt_field_enum((urrt_field_id)id, st->generation);
        if (!urrt_has(st, id)) {
            continue;
        }
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
    fputs("}\n", out);
}

static void print_table(const dump *d, FILE *out, const urrt_state *st)
{
    const char *versions = urrt_versions_of(st->length);
    fprintf(out, "packet %" PRIu64 ": %u bytes, %s (%s)", d->packets, (unsigned)st->length,
            st->generation == URRT_GEN_1X ? "1.x" : st->generation == URRT_GEN_3X ? "3.x/5.x" : "generation unknown",
            versions != NULL ? versions : "no known controller sends this length");
    if (st->extra_columns > 0) {
        fprintf(out, ", %u extra columns", (unsigned)st->extra_columns);
    }
    fputc('\n', out);
    unsigned ids[URRT_FIELD_COUNT];
    unsigned n = selected_fields(d, st, ids);
    for (unsigned k = 0; k < n; k++) {
        unsigned id = ids[k];
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        const double *v = urrt_field_values(st, id);
        urrt_enum_kind kind = urrt_field_enum((urrt_field_id)id, st->generation);
        fprintf(out, "  %-22s %-10s", f->name, f->unit);
        if (!urrt_has(st, id)) {
            fputs(" (not in this packet)\n", out);
            continue;
        }
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
        fputc('\n', out);
    }
}

/* ---- recording ---------------------------------------------------------------- */

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

static void on_packet(void *ctx, const uint8_t *pkt, size_t len, uint64_t rx_us)
{
    dump *d = ctx;
    urrt_state st;
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
    d->gen_count[urrt_generation_of((uint32_t)len)]++;
    if (urrt_read_column(pkt, len, 1, &t) == URRT_OK && isfinite(t)) {
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
        if (d->opt.fmt == FORMAT_GNUPLOT) {
            print_gnuplot(d, stdout, pkt, len);
        } else {
            urrt_decode(pkt, len, &st);
            switch (d->opt.fmt) {
            case FORMAT_CSV: print_csv(d, stdout, &st); break;
            case FORMAT_JSON: print_json(d, stdout, &st); break;
            default: print_table(d, stdout, &st); break;
            }
        }
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

/* ---- sources ------------------------------------------------------------------ */

static int run_file(dump *d)
{
    int fd = strcmp(d->opt.file_path, "-") == 0 ? STDIN_FILENO : open(d->opt.file_path, O_RDONLY | O_CLOEXEC);
    static uint8_t buf[65536];
    urrt_framer fr;
    int status = CLI_EXIT_OK;

    if (fd < 0) {
        urrt_log(URRT_LOG_ERR, "cannot open %s: %s", d->opt.file_path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    urrt_framer_init(&fr);
    while (running && !d->done) {
        ssize_t n = read(fd, buf, sizeof buf);
        const uint8_t *p = buf;
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
    if (fd != STDIN_FILENO) {
        close(fd);
    }
    if (status == CLI_EXIT_OK && running && d->packets == 0) {
        urrt_log(URRT_LOG_ERR, "%s holds no RealTime packet (%" PRIu64 " bytes): give a raw capture of port 30003 "
                 "or 30013 (nc robot 30003 > FILE, urrt-dump -w FILE)",
                 strcmp(d->opt.file_path, "-") == 0 ? "the input" : d->opt.file_path, fr.stats.bytes);
        status = CLI_EXIT_RUNTIME;
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
    if (link != NULL) {
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
                 "address and the port (30003, or the read-only 30013)%s", urrt_link_peer(link),
                 (double)(now - p->last_us) / 1e6, urrt_link_state_name(urrt_link_get_state(link)),
                 ls->connect_failures, d->opt.timeout_s > 0 ? "" : "; -t SEC gives up after SEC seconds");
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
            urrt_log(URRT_LOG_ERR, "%s: no RealTime packet (%s, see above); check the address and port, "
                     "or drop --once to keep trying",
                     urrt_link_peer(link), ls->connects == 0 ? "no connection" : "the connection ended first");
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
    urrt_link_free(lc.link);
    return status;
}

/* ---- summary ------------------------------------------------------------------ */

static void print_summary(const dump *d, bool from_link)
{
    FILE *out = stderr;
    fprintf(out, "summary: packets: %" PRIu64 "\n", d->packets);
    fprintf(out, "summary: lengths:");
    for (size_t i = 0; i < d->nlengths; i++) {
        const char *v = urrt_versions_of(d->lengths[i]);
        fprintf(out, "%s %" PRIu32 " x %" PRIu64 " (%s)", i > 0 ? ";" : "", d->lengths[i], d->length_count[i],
                v != NULL ? v : "no known controller");
    }
    if (d->other_lengths > 0) {
        fprintf(out, "; %" PRIu64 " of other lengths", d->other_lengths);
    }
    fprintf(out, "%s\n", d->nlengths == 0 ? " none" : "");
    fprintf(out, "summary: generations: 1.x %" PRIu64 ", 3.x/5.x %" PRIu64 ", unknown %" PRIu64 "\n",
            d->gen_count[URRT_GEN_1X], d->gen_count[URRT_GEN_3X], d->gen_count[URRT_GEN_UNKNOWN]);
    if (from_link) {
        fprintf(out, "summary: resyncs: %" PRIu64 ", skipped bytes: %" PRIu64 "\n", d->lstats.resyncs,
                d->lstats.skipped);
        fprintf(out, "summary: partial packets dropped: %" PRIu64 " (%" PRIu64 " bytes)\n", d->lstats.partial_drops,
                d->lstats.partial_bytes);
        fprintf(out,
                "summary: link: connects %" PRIu64 ", reconnects %" PRIu64 ", disconnects %" PRIu64
                ", silences %" PRIu64 ", connect failures %" PRIu64 "\n",
                d->lstats.connects, d->lstats.reconnects, d->lstats.disconnects, d->lstats.silences,
                d->lstats.connect_failures);
    } else {
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
    if (d.opt.record_path != NULL) {
        d.record = fopen(d.opt.record_path, "wb");
        d.pending = malloc(RECORD_PENDING_MAX);
        if (d.record == NULL || d.pending == NULL) {
            urrt_log(URRT_LOG_ERR, "cannot create the recording %s: %s", d.opt.record_path, strerror(errno));
            return CLI_EXIT_RUNTIME;
        }
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
    if (d.opt.summary) {
        print_summary(&d, d.opt.file_path == NULL);
    }
    free(d.pending);
    return status;
}
