/* SPDX-License-Identifier: MIT */
/*
 * can_tool: drives gateway/can/can_map, gateway/can/can_run, gateway/can/dbc
 * and lib/urrt_can from the command line for the Python tests
 * (tests/gateway/can/test_dbc.py), which hold their output against python3-canmatrix
 * and an independent reference. CONFIG is loaded as the gateway loads it
 * (gw_config_load): its robots are its [robot NAME] sections, and their
 * rates follow from their version.
 *
 * usage: can_tool COMMAND CONFIG
 *   validate   load and check; prints "ok load=PERCENT" or the errors (exit 1)
 *   dbc        the DBC on stdout
 *   ctables    the C tables on stdout (--print-c-tables)
 *   pack       reads lines "FRAME NAME=VALUE ..." (FRAME a [frame] or an [input]) and prints
 *              "HEX OUTCOME..." per line: the payload (zeros elsewhere) packed
 *              with urrt_can_pack, and each signal's outcome (0 ok,
 *              1 saturated, 2 NaN); VALUE is a C double ("nan", "inf" too)
 *   unpack     reads lines "FRAME HEX" and prints "NAME=%.17g ..." per line (urrt_can_unpack
 *              with the map's signal table, as the gateway receives an [input])
 *   run        reads a script and prints every emitted frame as
 *              "T_US ID#HEX" (ids in candump's notation, "##" + flags for FD):
 *                packet T_US ROBOT FIELD[ELEM]=VALUE ...  a packet (only the
 *                       named fields present; generation 3.x), then due(T)
 *                tick T_US                             due(T)
 *                link ROBOT up|down
 *                stats DROPPED BUS_OFF ERROR_FRAMES DOWN_EVENTS SEND_ERRORS
 */
#include <ctype.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_ctables.h"
#include "can_map.h"
#include "can_run.h"
#include "config.h"
#include "dbc.h"

/* A [frame] or an [input] by name (DBC names are unique among both). */
static struct can_map_frame *frame_by_name(struct can_map *map, const char *name)
{
    size_t i;
    for (i = 0; i < map->frame_count; i++) {
        if (strcmp(map->frames[i].name, name) == 0) {
            return &map->frames[i];
        }
    }
    for (i = 0; i < map->input_count; i++) {
        if (strcmp(map->inputs[i].name, name) == 0) {
            return &map->inputs[i];
        }
    }
    return NULL;
}

/* The C tables as urrt-gateway --print-c-tables writes them. */
static int cmd_ctables(gw_config *cfg)
{
    struct can_ctables_robot robots[GW_MAX_ROBOTS];
    for (unsigned i = 0; i < cfg->robot_count && i < GW_MAX_ROBOTS; i++) {
        robots[i].rtde = cfg->robots[i].source == GW_SOURCE_RTDE;
        robots[i].frequency = cfg->robots[i].rtde_frequency;
        robots[i].port = cfg->robots[i].port;
    }
    return can_ctables_write(stdout, &cfg->can, cfg->can_run, cfg->co_run, robots, cfg->path) != 0;
}

static int signal_index(const struct can_map_frame *f, const char *name, size_t len)
{
    size_t i;
    for (i = 0; i < f->count; i++) {
        if (strlen(f->meta[i].name) == len && memcmp(f->meta[i].name, name, len) == 0) {
            return (int)i;
        }
    }
    return -1;
}

static void put_hex(const uint8_t *data, unsigned len)
{
    unsigned i;
    for (i = 0; i < len; i++) {
        printf("%02X", data[i]);
    }
}

static int cmd_pack(struct can_map *map)
{
    char line[4096];
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *save = NULL;
        char *tok = strtok_r(line, " \t\r\n", &save);
        struct can_map_frame *f;
        uint8_t data[URRT_CAN_MAX_LEN] = {0};
        char outcomes[2048] = "";
        if (tok == NULL) {
            continue;
        }
        f = frame_by_name(map, tok);
        if (f == NULL) {
            fprintf(stderr, "can_tool: no frame %s\n", tok);
            return 1;
        }
        while ((tok = strtok_r(NULL, " \t\r\n", &save)) != NULL) {
            char *eq = strchr(tok, '=');
            int k;
            int outcome;
            if (eq == NULL || (k = signal_index(f, tok, (size_t)(eq - tok))) < 0) {
                fprintf(stderr, "can_tool: bad item %s\n", tok);
                return 1;
            }
            outcome = urrt_can_pack(&f->sigs[k], strtod(eq + 1, NULL), data, f->len);
            snprintf(outcomes + strlen(outcomes), sizeof outcomes - strlen(outcomes), " %d", outcome);
        }
        put_hex(data, f->len);
        printf("%s\n", outcomes);
    }
    return 0;
}

static int cmd_unpack(struct can_map *map)
{
    char line[4096];
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *save = NULL;
        char *name = strtok_r(line, " \t\r\n", &save);
        char *hex = strtok_r(NULL, " \t\r\n", &save);
        struct can_map_frame *f;
        uint8_t data[URRT_CAN_MAX_LEN] = {0};
        size_t i;
        if (name == NULL) {
            continue;
        }
        f = frame_by_name(map, name);
        if (f == NULL || hex == NULL || strlen(hex) != 2u * f->len) {
            fprintf(stderr, "can_tool: bad unpack line\n");
            return 1;
        }
        for (i = 0; i < f->len; i++) {
            unsigned b;
            sscanf(hex + 2 * i, "%2x", &b);
            data[i] = (uint8_t)b;
        }
        for (i = 0; i < f->count; i++) {
            double v;
            if (urrt_can_unpack(&f->sigs[i], data, f->len, &v) < 0) {
                return 1;
            }
            printf("%s%s=%.17g", i ? " " : "", f->meta[i].name, v);
        }
        printf("\n");
    }
    return 0;
}

struct run_ctx {
    uint64_t now;
};

static void print_frame(void *ctx, const urrt_can_frame *fr, uint64_t now_us)
{
    (void)now_us;
    struct run_ctx *run = ctx;
    printf("%" PRIu64 " ", run->now);
    if (fr->extended) {
        printf("%08" PRIX32, fr->id);
    } else {
        printf("%03" PRIX32, fr->id);
    }
    printf(fr->fd ? "##0" : "#");
    put_hex(fr->data, fr->len);
    printf("\n");
}

static size_t robot_by_name(const struct can_map *map, const char *name)
{
    size_t i;
    for (i = 0; i < map->robot_count; i++) {
        if (strcmp(map->robots[i].name, name) == 0) {
            return i;
        }
    }
    fprintf(stderr, "can_tool: no robot %s\n", name);
    exit(1);
}

static int cmd_run(const struct can_map *map, struct can_run *can)
{
    char line[8192];
    struct run_ctx run = {0};
    urrt_canlink_stats stats;
    urrt_state st;
    memset(&stats, 0, sizeof stats);
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *save = NULL;
        char *cmd = strtok_r(line, " \t\r\n", &save);
        if (cmd == NULL || cmd[0] == '#') {
            continue;
        }
        if (strcmp(cmd, "packet") == 0 || strcmp(cmd, "tick") == 0) {
            run.now = strtoull(strtok_r(NULL, " \t\r\n", &save), NULL, 10);
            if (strcmp(cmd, "packet") == 0) {
                size_t robot = robot_by_name(map, strtok_r(NULL, " \t\r\n", &save));
                char *tok;
                urrt_state_clear(&st);
                st.generation = URRT_GEN_3X;
                st.length = 1220;
                st.doubles = 152;
                while ((tok = strtok_r(NULL, " \t\r\n", &save)) != NULL) {
                    char *eq = strchr(tok, '=');
                    char *br = strchr(tok, '[');
                    size_t nlen = (size_t)((br && br < eq ? br : eq) - tok);
                    int id = urrt_field_find(tok, nlen);
                    unsigned elem = br && br < eq ? (unsigned)strtoul(br + 1, NULL, 10) : 0;
                    size_t off = 0;
                    if (eq == NULL || id < 0 || urrt_field((urrt_field_id)id)->col_3x == 0) {
                        fprintf(stderr, "can_tool: bad field %s\n", tok);
                        return 1;
                    }
                    /* The members are arrays of doubles in table order: find
                     * this one through the field table's column on 3.x. */
                    off = (size_t)(urrt_field((urrt_field_id)id)->col_3x - 1) * sizeof(double);
                    ((double *)(void *)((char *)&st + off))[elem] = strtod(eq + 1, NULL);
                    st.present |= UINT64_C(1) << id;
                }
                urrt_cantx_on_packet(can_run_tx(can), robot, &st, run.now);
            }
            can_run_due(can, run.now, &stats, print_frame, &run);
        } else if (strcmp(cmd, "link") == 0) {
            size_t robot = robot_by_name(map, strtok_r(NULL, " \t\r\n", &save));
            urrt_cantx_robot_link(can_run_tx(can), robot, strcmp(strtok_r(NULL, " \t\r\n", &save), "up") == 0);
        } else if (strcmp(cmd, "stats") == 0) {
            uint64_t *slots[] = {&stats.dropped, &stats.bus_off, &stats.error_frames, &stats.down_events,
                                 &stats.send_errors};
            size_t i;
            for (i = 0; i < sizeof slots / sizeof slots[0]; i++) {
                *slots[i] = strtoull(strtok_r(NULL, " \t\r\n", &save), NULL, 10);
            }
        } else {
            fprintf(stderr, "can_tool: unknown script command %s\n", cmd);
            return 1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    gw_config cfg;
    struct can_map *map = &cfg.can;
    const char *cmd;
    int rc;

    if (argc != 3) {
        fprintf(stderr, "usage: can_tool validate|dbc|ctables|pack|unpack|run CONFIG\n");
        return 2;
    }
    cmd = argv[1];
    if (gw_config_load(&cfg, argv[2], stdout) != 0) {
        gw_config_free(&cfg);
        return 1;
    }
    if (cfg.can_run == NULL) {
        printf("%s: no CAN output configured\n", argv[2]);
        gw_config_free(&cfg);
        return 1;
    }
    if (strcmp(cmd, "validate") == 0) {
        printf("ok load=%.4f\n", map->load * 100.0);
        for (size_t k = 0; k < map->frame_count; k++) {
            printf("frame %s load=%.4f\n", map->frames[k].name, map->frames[k].load * 100.0);
        }
        rc = 0;
    } else if (strcmp(cmd, "dbc") == 0) {
        rc = dbc_write(stdout, map, argv[2]) < 0;
    } else if (strcmp(cmd, "ctables") == 0) {
        rc = cmd_ctables(&cfg);
    } else if (strcmp(cmd, "pack") == 0) {
        rc = cmd_pack(map);
    } else if (strcmp(cmd, "unpack") == 0) {
        rc = cmd_unpack(map);
    } else if (strcmp(cmd, "run") == 0) {
        rc = cmd_run(map, cfg.can_run);
    } else {
        fprintf(stderr, "can_tool: unknown command %s\n", cmd);
        rc = 2;
    }
    gw_config_free(&cfg);
    return rc;
}
