/* SPDX-License-Identifier: MIT */
/*
 * urrt-gateway: reads the RealTime stream of one or more Universal Robots
 * controllers and publishes it on LCM (docs/gateway.md) and as CAN frames
 * (docs/can.md).
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_out.h"
#include "cli.h"
#include "config.h"
#include "dbc.h"
#include "gateway.h"
#include "lcm_out.h"
#include "port.h"
#include "urrt.h"

static volatile sig_atomic_t running = 1;

static void usage(FILE *out)
{
    fputs(
        "Usage: urrt-gateway [options] CONFIG\n"
        "       urrt-gateway --check-config CONFIG\n"
        "\n"
        "Reads the RealTime interface (TCP 30003/30013) of the robots in CONFIG and\n"
        "publishes each one's packets on LCM: NAME.STATE (urrt.state_t, every field),\n"
        "NAME.JOINTS, NAME.TOOL, NAME.STATUS, and NAME.GATEWAY (urrt.gateway_t: link\n"
        "state and counters, once per second even while the robot is unreachable).\n"
        "With a [can] section it also sends the [frame NAME]s of CONFIG on a CAN bus,\n"
        "with a heartbeat frame, and --print-dbc describes them for the PLC side.\n"
        "Never writes to a robot. Stops on SIGINT or SIGTERM.\n"
        "\n"
        "Options:\n"
        "  -c, --check-config     validate CONFIG, print what would run, exit\n"
        "  -d, --print-dbc        write the DBC of CONFIG's CAN frames, exit\n"
        "  -o, --output FILE      with --print-dbc: write to FILE, not stdout\n"
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
        "\n"
        "Exit status: 0 stopped by a signal (or the configuration is valid, or the\n"
        "DBC was written),\n"
        "1 runtime failure, 2 bad command line or configuration.\n",
        out);
}

static void print_plan(const gw_config *cfg, const char *url)
{
    printf("%s: valid\n", cfg->path);
    printf("lcm %s\n", url);
    if (can_map_enabled(&cfg->can)) {
        char line[256];
        can_map_describe(&cfg->can, line, sizeof line);
        printf("can %s\n", line);
    }
    for (unsigned i = 0; i < cfg->robot_count; i++) {
        const gw_robot_config *r = &cfg->robots[i];
        char peer[300];
        cli_format_host_port(r->host, r->port, peer, sizeof peer);
        printf("robot %s: %s, version %s, connect %u ms, silence %u ms, backoff %u..%u ms\n", r->name, peer,
               r->expected, (unsigned)r->link.connect_timeout_ms, (unsigned)r->link.silence_timeout_ms,
               (unsigned)r->link.backoff_initial_ms, (unsigned)r->link.backoff_max_ms);
        for (unsigned k = 0; k < GW_KIND_COUNT; k++) {
            const gw_rate *rate = &cfg->lcm.rate[k];
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

static int write_dbc(const gw_config *cfg, const char *path)
{
    FILE *out = stdout;
    bool ok;
    if (!can_map_enabled(&cfg->can)) {
        fprintf(stderr, "urrt-gateway: %s has no [can] section or [frame NAME]: nothing to describe\n", cfg->path);
        return CLI_EXIT_USAGE;
    }
    if (path != NULL && (out = fopen(path, "w")) == NULL) {
        fprintf(stderr, "urrt-gateway: cannot write %s: %s\n", path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    ok = dbc_write(out, &cfg->can, cfg->path) == 0;
    ok = fflush(out) == 0 && ok;
    if (out != stdout) {
        ok = fclose(out) == 0 && ok;
    }
    if (!ok) {
        fprintf(stderr, "urrt-gateway: writing the DBC to %s failed: %s\n", path ? path : "stdout", strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    return CLI_EXIT_OK;
}

int main(int argc, char **argv)
{
    static const struct option options[] = {
        {"check-config", no_argument, NULL, 'c'},
        {"print-dbc", no_argument, NULL, 'd'},
        {"output", required_argument, NULL, 'o'},
        {"summary", no_argument, NULL, 's'},
        {"lcm-url", required_argument, NULL, 'u'},
        {"log-level", required_argument, NULL, 'l'},
        {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'},
        {NULL, 0, NULL, 0},
    };
    bool check_only = false, summary = false, print_dbc = false;
    const char *output_path = NULL;
    const char *url_override = NULL;
    urrt_log_level level = URRT_LOG_NOTICE;
    bool level_given = false;
    gw_config cfg;
    gateway gw;
    lcm_out *lcm;
    gw_output output;
    int opt;

    urrt_log_init(argv[0], URRT_LOG_NOTICE);
    while ((opt = getopt_long(argc, argv, "cdo:su:l:hV", options, NULL)) != -1) {
        switch (opt) {
        case 'c': check_only = true; break;
        case 'd': print_dbc = true; break;
        case 'o': output_path = optarg; break;
        case 's': summary = true; break;
        case 'u': url_override = optarg; break;
        case 'l':
            if (!gw_parse_log_level(optarg, &level)) {
                fprintf(stderr, "urrt-gateway: --log-level %s: use err, warning, notice, info or debug\n", optarg);
                return CLI_EXIT_USAGE;
            }
            level_given = true;
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
    if (gw_config_load(&cfg, argv[optind], stderr) != 0) {
        fprintf(stderr, "urrt-gateway: %s is not valid; see `urrt-gateway --help` for the grammar\n", argv[optind]);
        gw_config_free(&cfg);
        return CLI_EXIT_USAGE;
    }
    if ((summary || cfg.summary) && !print_dbc && can_map_enabled(&cfg.can) &&
        strncmp(cfg.can.interface, "log:-", 5) == 0 &&
        (cfg.can.interface[5] == '\0' || cfg.can.interface[5] == ',')) {
        /* Summary lines in the CAN log would stop canplayer replaying it. */
        fprintf(stderr, "%s:%d: interface = %s and the summary both write to stdout: log the frames to a file "
                "(log:PATH) or turn the summary off\n", cfg.path, cfg.can.key_loc[CAN_MAP_CK_INTERFACE].line,
                cfg.can.interface);
        gw_config_free(&cfg);
        return CLI_EXIT_USAGE;
    }
    if (url_override != NULL) {
        free(cfg.lcm.url);
        cfg.lcm.url = strdup(url_override);
    }
    if (output_path != NULL && !print_dbc) {
        fprintf(stderr, "urrt-gateway: --output goes with --print-dbc\nTry 'urrt-gateway --help'.\n");
        gw_config_free(&cfg);
        return CLI_EXIT_USAGE;
    }
    if (print_dbc) {
        int rc = write_dbc(&cfg, output_path);
        gw_config_free(&cfg);
        return rc;
    }
    if (check_only) {
        print_plan(&cfg, cfg.lcm.url);
        gw_config_free(&cfg);
        return CLI_EXIT_OK;
    }
    urrt_log_set_level(level_given ? level : cfg.log_level);
    cli_handle_signals(&running);

    if (!gw_init(&gw, &cfg)) {
        gw_config_free(&cfg);
        return CLI_EXIT_RUNTIME;
    }
    gw.summary = gw.summary || summary;
    lcm = lcm_out_new(&gw, &cfg.lcm);
    if (lcm == NULL) {
        urrt_log(URRT_LOG_ERR, "out of memory");
        gw_close(&gw);
        gw_config_free(&cfg);
        return CLI_EXIT_RUNTIME;
    }
    output = lcm_out_output(lcm);
    gw_add_output(&gw, &output);
    if (can_map_enabled(&cfg.can)) {
        char line[256];
        can_out *can = can_out_new(&gw, &cfg.can);
        if (can == NULL) {
            urrt_log(URRT_LOG_ERR, "the CAN output cannot start (see above); fix [can] in %s", cfg.path);
            gw_close(&gw);
            gw_config_free(&cfg);
            return CLI_EXIT_RUNTIME;
        }
        output = can_out_output(can);
        gw_add_output(&gw, &output);
        can_map_describe(&cfg.can, line, sizeof line);
        urrt_log(URRT_LOG_NOTICE, "CAN: %s", line);
    }
    urrt_log(URRT_LOG_NOTICE, "started: %u robot%s, LCM %s", cfg.robot_count, cfg.robot_count == 1 ? "" : "s",
             cfg.lcm.url);

    gw_run(&gw, &running);

    urrt_log(URRT_LOG_NOTICE, "stopping (signal %d)", cli_stop_signal());
    gw_close(&gw);
    gw_config_free(&cfg);
    return CLI_EXIT_OK;
}
