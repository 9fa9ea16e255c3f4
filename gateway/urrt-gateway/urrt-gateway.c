/* SPDX-License-Identifier: MIT */
/*
 * urrt-gateway: reads one or more Universal Robots controllers, each over
 * RealTime (port 30003) or RTDE (port 30004, source = rtde: docs/rtde.md),
 * and publishes their state on LCM (docs/gateway.md) and as CAN frames or a
 * CANopen node (docs/can.md, docs/canopen.md).
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_ctables.h"
#include "can_out.h"
#include "can_replay.h"
#include "eds.h"
#include "cli.h"
#include "config.h"
#include "dbc.h"
#include "gateway.h"
#include "lcm_out.h"
#include "metrics.h"
#include "notify.h"
#include "plc_in.h"
#include "port.h"
#include "urrt.h"

static volatile sig_atomic_t running = 1;

static void usage(FILE *out)
{
    fputs(
        "Usage: urrt-gateway [options] CONFIG\n"
        "       urrt-gateway --check-config CONFIG\n"
        "\n"
        "Reads the robots in CONFIG, each over the RealTime interface (TCP 30003/30013)\n"
        "or RTDE (TCP 30004, [robot] source = rtde), and publishes each one's packets on\n"
        "LCM: NAME.STATE (urrt.state_t, every field), NAME.JOINTS, NAME.TOOL,\n"
        "NAME.STATUS, NAME.RTDE (RTDE-only values) and NAME.GATEWAY (urrt.gateway_t:\n"
        "link state and counters, once per second even while the robot is unreachable).\n"
        "With a [can] section it also sends the [frame NAME]s of CONFIG on a CAN bus,\n"
        "with a heartbeat frame, and --print-dbc describes them for the PLC side;\n"
        "with a [canopen] section it is a CANopen node, its frames TPDOs, and\n"
        "--print-eds writes its EDS.\n"
        "Never commands a robot: over RTDE it sends only the handshake that sets up\n"
        "its recipe. Stops on SIGINT or SIGTERM.\n"
        "\n"
        "Options:\n"
        "  -c, --check-config     validate CONFIG, print what would run, exit\n"
        "  -d, --print-dbc        write the DBC of CONFIG's CAN frames, exit\n"
        "      --print-c-tables   write CONFIG's CAN frames as C tables of lib/urrt_cantx.h\n"
        "                         (and its CANopen node, lib/urrt_co.h) for a firmware\n"
        "                         (docs/firmware.md), exit\n"
        "      --print-eds        write the EDS (CiA 306) of CONFIG's CANopen node, exit\n"
        "  -o, --output FILE      with --print-dbc, --print-c-tables or --print-eds:\n"
        "                         write to FILE\n"
        "      --print-keys       every configuration key, one per line: section, key,\n"
        "                         form, default, bounds, help (tab-separated), exit;\n"
        "                         no CONFIG (check-man holds the documents to it)\n"
        "      --replay CAPTURE   send a capture's packets through the CAN side,\n"
        "                         clocked by their controller time, and exit: the\n"
        "                         frames a PLC would have received (interface =\n"
        "                         log:PATH); the capture is the first robot's. A raw\n"
        "                         RealTime capture (urrt-dump -w) or an RTDE one\n"
        "                         (urrt-dump --rtde -w), told apart by its first\n"
        "                         byte; the capture decides, not the robot's source.\n"
        "                         An RTDE capture whose recipe lacks a value the\n"
        "                         CAN side needs is refused with the names\n"
        "      --replay-rx FILE   with --replay and [canopen]: the frames the node\n"
        "                         received (candump -l lines timed on the capture's\n"
        "                         clock), fed to it between the packets; without\n"
        "                         [canopen], to the [input]s (with --replay-inputs)\n"
        "      --replay-inputs FILE  with --replay of an RTDE capture: the input\n"
        "                         packages the gateway would write for the first\n"
        "                         robot's [input]s, one line each, (SEC.USEC) HEX\n"
        "  -s, --summary          one line per robot each second on stdout\n"
        "                         (state, data age, reconnects, messages/s per channel)\n"
        "  -u, --lcm-url URL      publish on URL instead of [lcm] url\n"
        "  -l, --log-level LEVEL  err, warning, notice, info or debug (overrides [gateway])\n"
        "  -h, --help             this text\n"
        "  -V, --version          program, library and wire format versions\n"
        "\n",
        out);
    gw_config_usage(out);
    fputs(
        "\n"
        "Example CONFIG:\n"
        "  [lcm]\n"
        "  url = udpm://239.255.76.67:7667?ttl=0   # ttl=1 to reach the LAN\n"
        "  state_rate = every\n"
        "  tool_rate = 50 Hz\n"
        "\n"
        "  [robot arm1]\n"
        "  host = 192.168.1.10\n"
        "  port = 30013\n"
        "  version = 5.10\n"
        "\n"
        "Examples:\n"
        "  urrt-gateway --check-config /etc/urrt/gateway.ini\n"
        "  urrt-gateway --summary /etc/urrt/gateway.ini\n"
        "  urrt-gateway -u 'udpm://239.255.76.67:7667?ttl=1' -l info gateway.ini\n"
        "  urrt-gateway --print-dbc -o robot.dbc gateway.ini\n"
        "  urrt-gateway --print-c-tables -o can_tables.c gateway.ini\n"
        "  urrt-gateway --print-eds -o urrt.eds canopen.ini\n"
        "  urrt-gateway --replay capture.bin gateway.ini\n"
        "  urrt-gateway --replay session.rtde rtde-plc.ini\n"
        "\n"
        "Exit status: 0 stopped by a signal (or the configuration is valid, the DBC,\n"
        "C tables or EDS were written, the capture was replayed),\n"
        "1 runtime failure, 2 bad command line or configuration.\n",
        out);
}

/* What an RTDE robot asks its controller for: optional names in brackets. */
static void print_recipe(const gw_robot_config *r)
{
    char rate[32];
    snprintf(rate, sizeof rate, r->rtde_frequency > 0 ? "%g Hz" : "the controller's rate", r->rtde_frequency);
    printf("  rtde: %zu values at %s ([optional]: where the controller has them):", r->recipe_count, rate);
    for (size_t i = 0; i < r->recipe_count; i++) {
        char name[URRT_RTDE_NAME_MAX];
        urrt_rtde_var_name(r->recipe[i], name, sizeof name);
        printf(r->recipe_optional[i] ? "%s[%s]" : "%s%s", i == 0 ? " " : ",", name);
    }
    printf("\n");
}

/* "writes robot arm: input_int_register_24 <- [input plc_cmd] job (0x201), ..."
 * : what an [input] writes, from where, its timeout, silence policy and rate. */
static void describe_input(const gw_config *cfg, size_t input, char *buf, size_t size)
{
    const struct can_map *map = &cfg->can;
    const struct can_map_frame *f = &map->inputs[input];
    static const char *const policy[] = {
        [URRT_PLCIN_STOP] = "stop (nothing written: the program's rtde_set_watchdog acts)",
        [URRT_PLCIN_HOLD] = "hold (the last values go on: the program's watchdog does not see the silence)",
        [URRT_PLCIN_VALUE] = "value",
    };
    size_t used = 0;
    int w = cfg->co_run != NULL ? snprintf(buf, size, "input %s (RPDO%zu, 0x%03X): robot %s:", f->name, input + 1u,
                                           (unsigned)f->id, map->robots[f->robot_index].name)
            : snprintf(buf, size, f->extended ? "input %s (0x%08X, 29-bit): robot %s:" : "input %s (0x%03X): robot %s:",
                       f->name, (unsigned)f->id, map->robots[f->robot_index].name);
    used += w > 0 ? (size_t)w : 0;
    for (size_t i = 0; i < f->count && used < size; i++) {
        char name[URRT_RTDE_NAME_MAX];
        (void)urrt_rtde_var_name(f->meta[i].var, name, sizeof name);
        w = snprintf(buf + used, size - used, "%s %s <- %s", i ? "," : "", name, f->meta[i].name);
        used += w > 0 ? (size_t)w : 0;
    }
    if (used < size) {
        w = snprintf(buf + used, size - used, "; every change and at least %g Hz while fresh; silent after %u ms: "
                     "on_silence = %s", map->inputs_min_rate_hz, (unsigned)f->timeout_ms, policy[f->silence]);
        used += w > 0 ? (size_t)w : 0;
    }
    if (used < size && f->silence == URRT_PLCIN_VALUE) {
        snprintf(buf + used, size - used, " %.17g", f->silence_value);
    }
}

static void print_plan(const gw_config *cfg, const char *url)
{
    printf("%s: valid\n", cfg->path);
    printf("lcm %s\n", url);
    if (can_map_enabled(&cfg->can)) {
        char line[512];
        can_map_describe(&cfg->can, line, sizeof line);
        printf("can %s\n", line);
        for (size_t i = 0; i < can_map_notice_count(&cfg->can); i++) {
            printf("notice: %s\n", can_map_notice(&cfg->can, i));
        }
        for (size_t i = 0; i < cfg->can.input_count; i++) {
            char text[600];
            describe_input(cfg, i, text, sizeof text);
            printf("%s\n", text);
        }
    }
    if (cfg->co_run != NULL) {
        char line[512];
        co_run_describe(cfg->co_run, line, sizeof line);
        printf("canopen %s\n", line);
    }
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        const gw_robot_config *r = &cfg->robots[i];
        char peer[300];
        cli_format_host_port(r->host, r->port, peer, sizeof peer);
        printf("robot %s: %s, version %s, connect %u ms, silence %u ms, backoff %u..%u ms\n", r->name, peer,
               r->expected, (unsigned)r->link.connect_timeout_ms, (unsigned)r->link.silence_timeout_ms,
               (unsigned)r->link.backoff_initial_ms, (unsigned)r->link.backoff_max_ms);
        if (r->source == GW_SOURCE_RTDE) {
            print_recipe(r);
        }
        for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
            const gw_rate *rate = &cfg->lcm.rate[k];
            if (k == GW_KIND_RTDE && r->rtde_value_count == 0) {
                continue; /* nothing to publish there */
            }
            printf("  %s.%s: ", r->name, cfg->lcm.channel[k]);
            if (rate->mode == GW_RATE_OFF) {
                printf("off\n");
            } else if (rate->mode == GW_RATE_EVERY) {
                printf("every packet\n");
            } else {
                printf("%g Hz\n", rate->hz);
            }
        }
    }
}

/* What --print-dbc and --print-c-tables write. */
typedef int (*writer_fn)(FILE *out, gw_config *cfg, const char *path); /* path NULL: stdout */

static int dbc_writer(FILE *out, gw_config *cfg, const char *path)
{
    (void)path;
    return dbc_write(out, &cfg->can, cfg->path);
}

static int c_tables_writer(FILE *out, gw_config *cfg, const char *path)
{

    struct can_ctables_robot robots[GW_MAX_ROBOTS];
    (void)path;
    for (unsigned i = 0; i < cfg->robot_count && i < GW_MAX_ROBOTS; i++) {
        robots[i].rtde = cfg->robots[i].source == GW_SOURCE_RTDE;
        robots[i].frequency = cfg->robots[i].rtde_frequency;
        robots[i].port = cfg->robots[i].port;
    }
    return can_ctables_write(out, &cfg->can, cfg->can_run, cfg->co_run, robots, cfg->path);
}

static int eds_writer(FILE *out, gw_config *cfg, const char *path)
{
    return eds_write(out, cfg->co_run, &cfg->co, &cfg->can, cfg->path, path);
}

static int write_output(gw_config *cfg, const char *path, writer_fn write, const char *what)
{
    FILE *out = stdout;
    bool ok;
    if (!can_map_enabled(&cfg->can)) {
        fprintf(stderr, "urrt-gateway: %s has no [can] section or [frame NAME]: no %s to write\n", cfg->path, what);
        return CLI_EXIT_USAGE;
    }
    if (write == eds_writer && cfg->co_run == NULL) {
        fprintf(stderr, "urrt-gateway: %s has no [canopen] section: no EDS to write (docs/canopen.md shows one)\n",
                cfg->path);
        return CLI_EXIT_USAGE;
    }
    if (path != NULL && (out = fopen(path, "w")) == NULL) {
        fprintf(stderr, "urrt-gateway: cannot write %s: %s\n", path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    ok = write(out, cfg, path) == 0;
    ok = fflush(out) == 0 && ok;
    if (out != stdout) {
        ok = fclose(out) == 0 && ok;
    }
    if (!ok) {
        fprintf(stderr, "urrt-gateway: writing the %s to %s failed: %s\n", what, path ? path : "stdout",
                strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    return CLI_EXIT_OK;
}

typedef struct options {
    bool check_only;
    bool summary;
    bool print_dbc;
    bool print_c_tables;
    bool print_eds;
    const char *output_path;
    const char *url_override;
    const char *replay_path;
    const char *replay_rx_path;
    const char *replay_inputs_path;
    const char *config_path;
    urrt_log_level level;
    bool level_given;
} options;

/* CLI_EXIT_* to stop with, or -1 to go on. */
static int parse_options(int argc, char **argv, options *o)
{
    enum { OPT_C_TABLES = 256, OPT_REPLAY, OPT_PRINT_KEYS, OPT_EDS, OPT_REPLAY_RX, OPT_REPLAY_INPUTS };
    static const struct option longopts[] = {
        {"check-config", no_argument, NULL, 'c'},
        {"print-dbc", no_argument, NULL, 'd'},
        {"print-c-tables", no_argument, NULL, OPT_C_TABLES},
        {"print-keys", no_argument, NULL, OPT_PRINT_KEYS},
        {"print-eds", no_argument, NULL, OPT_EDS},
        {"replay", required_argument, NULL, OPT_REPLAY},
        {"replay-rx", required_argument, NULL, OPT_REPLAY_RX},
        {"replay-inputs", required_argument, NULL, OPT_REPLAY_INPUTS},
        {"output", required_argument, NULL, 'o'},
        {"summary", no_argument, NULL, 's'},
        {"lcm-url", required_argument, NULL, 'u'},
        {"log-level", required_argument, NULL, 'l'},
        {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'},
        {NULL, 0, NULL, 0},
    };
    int opt;
    memset(o, 0, sizeof *o);
    o->level = URRT_LOG_NOTICE;
    while ((opt = getopt_long(argc, argv, "cdo:su:l:hV", longopts, NULL)) != -1) {
        switch (opt) {
        case 'c': o->check_only = true; break;
        case 'd': o->print_dbc = true; break;
        case OPT_C_TABLES: o->print_c_tables = true; break;
        case OPT_EDS: o->print_eds = true; break;
        case OPT_REPLAY: o->replay_path = optarg; break;
        case OPT_REPLAY_RX: o->replay_rx_path = optarg; break;
        case OPT_REPLAY_INPUTS: o->replay_inputs_path = optarg; break;
        case OPT_PRINT_KEYS: gw_config_print_keys(stdout); return CLI_EXIT_OK;
        case 'o': o->output_path = optarg; break;
        case 's': o->summary = true; break;
        case 'u': o->url_override = optarg; break;
        case 'l':
            if (!gw_parse_log_level(optarg, &o->level)) {
                fprintf(stderr, "urrt-gateway: --log-level %s: use err, warning, notice, info or debug\n", optarg);
                return CLI_EXIT_USAGE;
            }
            o->level_given = true;
            break;
        case 'h': usage(stdout); return CLI_EXIT_OK;
        case 'V':
            printf("urrt-gateway %s (wire format up to %d, %d columns)\n", URRT_VERSION_STRING,
                   URRT_WIRE_VERSION, URRT_WIRE_COLUMNS);
            return CLI_EXIT_OK;
        default:
            fprintf(stderr, "Try 'urrt-gateway --help'.\n");
            return CLI_EXIT_USAGE;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "urrt-gateway: %s\nTry 'urrt-gateway --help'.\n",
                optind == argc ? "no CONFIG file given" : "only one CONFIG file is read");
        return CLI_EXIT_USAGE;
    }
    if ((int)o->print_dbc + (int)o->print_c_tables + (int)o->print_eds + (int)o->check_only +
            (o->replay_path != NULL) > 1) {
        fprintf(stderr, "urrt-gateway: --check-config, --print-dbc, --print-c-tables, --print-eds and --replay are "
                        "separate jobs: give one\nTry 'urrt-gateway --help'.\n");
        return CLI_EXIT_USAGE;
    }
    if ((o->replay_rx_path != NULL || o->replay_inputs_path != NULL) && o->replay_path == NULL) {
        fprintf(stderr, "urrt-gateway: --replay-rx and --replay-inputs go with --replay\nTry 'urrt-gateway --help'.\n");
        return CLI_EXIT_USAGE;
    }
    if (o->output_path != NULL && !o->print_dbc && !o->print_c_tables && !o->print_eds) {
        fprintf(stderr, "urrt-gateway: --output goes with --print-dbc, --print-c-tables or --print-eds\n"
                        "Try 'urrt-gateway --help'.\n");
        return CLI_EXIT_USAGE;
    }
    o->config_path = argv[optind];
    return -1;
}

/* Summary lines in a CAN log on stdout would stop canplayer replaying it. */
static bool summary_clashes(const gw_config *cfg, const options *o)
{
    const char *iface = cfg->can.interface;
    return (o->summary || cfg->summary) && o->replay_path == NULL && !o->print_dbc && !o->print_c_tables &&
           !o->print_eds &&
           can_map_enabled(&cfg->can) && strncmp(iface, "log:-", 5) == 0 && (iface[5] == '\0' || iface[5] == ',');
}

/* CLI_EXIT_* to stop with (cfg freed), or -1 with cfg loaded. */
static int load_config(gw_config *cfg, const options *o)
{
    if (gw_config_load(cfg, o->config_path, stderr) != 0) {
        fprintf(stderr, "urrt-gateway: %s is not valid; see `urrt-gateway --help` for the grammar\n", o->config_path);
        gw_config_free(cfg);
        return CLI_EXIT_USAGE;
    }
    if (summary_clashes(cfg, o)) {
        fprintf(stderr, "%s:%d: interface = %s and the summary both write to stdout: log the frames to a file "
                "(log:PATH) or turn the summary off\n", cfg->path, cfg->can.key_loc[CAN_MAP_CK_INTERFACE].line,
                cfg->can.interface);
        gw_config_free(cfg);
        return CLI_EXIT_USAGE;
    }
    if (o->url_override != NULL) {
        free(cfg->lcm.url);
        cfg->lcm.url = strdup(o->url_override);
    }
    return -1;
}

/* The PLC's [input] frames: received by the CAN output's link, written to
 * the robots' input registers. NULL (logged) when it cannot start. */
static plc_in *add_inputs(gateway *gw, const gw_config *cfg, can_out *can)
{
    uint32_t ids[URRT_CANLINK_RX_IDS_MAX];
    plc_in *in = plc_in_new(gw, &cfg->can, cfg->co_run);
    gw_output output;
    /* With [canopen] the [input]s are the node's RPDOs: their ids are its own. */
    can_out_receiver receiver = {.frame = cfg->co_run == NULL ? plc_in_on_frame : NULL, .link = plc_in_link,
                                 .node = cfg->co_run != NULL ? plc_in_node : NULL, .ctx = in, .ids = ids};
    if (in == NULL) {
        return NULL;
    }
    output = plc_in_output(in);
    if (!gw_add_output(gw, &output)) { /* then closed, and freed, with the gateway */
        output.close(in);
        return NULL;
    }
    receiver.id_count = cfg->co_run == NULL ? can_map_input_ids(&cfg->can, ids, URRT_CANLINK_RX_IDS_MAX) : 0;
    if (!can_out_set_receiver(can, &receiver)) {
        urrt_log(URRT_LOG_ERR, "the CAN link cannot receive the [input] frames' ids (see above); fix them in %s",
                 cfg->path);
        return NULL;
    }
    for (size_t i = 0; i < cfg->can.input_count; i++) {
        char line[600];
        describe_input(cfg, i, line, sizeof line);
        urrt_log(URRT_LOG_NOTICE, "%s", line);
    }
    return in;
}

/* The metrics file's writer ([gateway] metrics_file) and systemd's watchdog
 * and status (when started by it), after the outputs they report on. False
 * (logged) when out of memory. */
static bool add_supervision(gateway *gw, const gw_config *cfg, lcm_out *lcm, can_out *can, plc_in *inputs,
                            gw_notify **notify)
{
    gw_output output;
    if (cfg->metrics_file != NULL) {
        gw_metrics *m = gw_metrics_new(gw, cfg, lcm, can, inputs);
        if (m == NULL) {
            return false;
        }
        output = gw_metrics_output(m);
        gw_add_output(gw, &output);
        urrt_log(URRT_LOG_NOTICE, "metrics: %s every %.1f s", cfg->metrics_file, cfg->metrics_interval_ms / 1000.0);
    }
    if ((*notify = gw_notify_new(gw, can)) != NULL) {
        output = gw_notify_output(*notify);
        gw_add_output(gw, &output);
    }
    return true;
}

/* The gateway itself: until SIGINT or SIGTERM. */
static int run(gw_config *cfg, const options *o)
{
    gateway gw;
    lcm_out *lcm;
    can_out *can = NULL;
    plc_in *inputs = NULL;
    gw_notify *notify;
    gw_output output;
    cli_handle_signals(&running);
    if (!gw_init(&gw, cfg)) {
        return CLI_EXIT_RUNTIME;
    }
    gw.summary = gw.summary || o->summary;
    if ((lcm = lcm_out_new(&gw, &cfg->lcm)) == NULL) {
        urrt_log(URRT_LOG_ERR, "out of memory");
        gw_close(&gw);
        return CLI_EXIT_RUNTIME;
    }
    output = lcm_out_output(lcm);
    gw_add_output(&gw, &output);
    if (can_map_enabled(&cfg->can)) {
        char line[512];
        can = can_out_new(&gw, &cfg->can, cfg->can_run, cfg->co_run);
        if (can == NULL) {
            urrt_log(URRT_LOG_ERR, "the CAN output cannot start (see above); fix [can] in %s", cfg->path);
            gw_close(&gw);
            return CLI_EXIT_RUNTIME;
        }
        output = can_out_output(can);
        gw_add_output(&gw, &output);
        can_map_describe(&cfg->can, line, sizeof line);
        urrt_log(URRT_LOG_NOTICE, "CAN: %s", line);
        for (size_t i = 0; i < can_map_notice_count(&cfg->can); i++) {
            urrt_log(URRT_LOG_NOTICE, "CAN: %s", can_map_notice(&cfg->can, i));
        }
        if (cfg->co_run != NULL) {
            co_run_describe(cfg->co_run, line, sizeof line);
            urrt_log(URRT_LOG_NOTICE, "CANopen %s", line);
        }
        if (cfg->can.input_count > 0 && (inputs = add_inputs(&gw, cfg, can)) == NULL) {
            gw_close(&gw);
            return CLI_EXIT_RUNTIME;
        }
    }
    if (!add_supervision(&gw, cfg, lcm, can, inputs, &notify)) {
        gw_close(&gw);
        return CLI_EXIT_RUNTIME;
    }
    urrt_log(URRT_LOG_NOTICE, "started: %u robot%s, LCM %s", cfg->robot_count, cfg->robot_count == 1 ? "" : "s",
             cfg->lcm.url);
    gw_notify_ready(notify);
    gw_run(&gw, &running);
    urrt_log(URRT_LOG_NOTICE, "stopping (signal %d)", cli_stop_signal());
    gw_notify_stopping(notify);
    gw_close(&gw);
    gw_notify_free(notify);
    return CLI_EXIT_OK;
}

int main(int argc, char **argv)
{
    options o;
    gw_config cfg;
    int rc;
    urrt_log_init(argv[0], URRT_LOG_NOTICE);
    if ((rc = parse_options(argc, argv, &o)) >= 0 || (rc = load_config(&cfg, &o)) >= 0) {
        return rc;
    }
    urrt_log_set_level(o.level_given ? o.level : cfg.log_level);
    if (o.print_dbc) {
        rc = write_output(&cfg, o.output_path, dbc_writer, "DBC");
    } else if (o.print_c_tables) {
        rc = write_output(&cfg, o.output_path, c_tables_writer, "C tables");
    } else if (o.print_eds) {
        rc = write_output(&cfg, o.output_path, eds_writer, "EDS");
    } else if (o.replay_path != NULL) {
        rc = can_replay(&cfg.can, cfg.can_run, cfg.co_run, o.replay_path, o.replay_rx_path, o.replay_inputs_path);
    } else if (o.check_only) {
        print_plan(&cfg, cfg.lcm.url);
        rc = CLI_EXIT_OK;
    } else {
        rc = run(&cfg, &o);
    }
    gw_config_free(&cfg);
    return rc;
}
