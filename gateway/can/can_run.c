/* SPDX-License-Identifier: MIT */
/*
 * can_run.c: the run-time side of can_map.h. The map's frames become
 * lib/urrt_cantx.h tables (the same tables --print-c-tables writes for a
 * firmware), and the CAN core does the rest.
 */
#include "can_map.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const struct can_map_hb_signal can_map_heartbeat_layout[URRT_CANTX_HB_COUNT] = {
    [URRT_CANTX_HB_STATE] = {"state", "", CAN_MAP_HB_VALUES_STATE,
                          "Gateway state: 0 starting, 1 ok, 2 data stale, 3 robot disconnected"},
    [URRT_CANTX_HB_ALIVE] = {"alive_counter", "", CAN_MAP_HB_VALUES_NONE,
                          "Incremented (modulo 16) with every heartbeat"},
    [URRT_CANTX_HB_ROBOT_MODE] = {"robot_mode", "",
                               CAN_MAP_HB_VALUES_ROBOT_MODE,
                               "Robot mode of the heartbeat robot as it sends it (numbering per generation); "
                               "-128: not available (no data, or older than stale_after_ms)"},
    [URRT_CANTX_HB_SAFETY_MODE] = {"safety_mode", "",
                                CAN_MAP_HB_VALUES_SAFETY_MODE,
                                "Safety mode of the heartbeat robot; 0: not available (1.x, no data, or older "
                                "than stale_after_ms)"},
    [URRT_CANTX_HB_GENERATION] = {"generation", "",
                               CAN_MAP_HB_VALUES_GENERATION,
                               "Controller generation of the heartbeat robot: 0 unknown, 1 CB1/CB2 (1.x), "
                               "3 CB3/e-series (3.x/5.x)"},
    [URRT_CANTX_HB_BUS_OFF] = {"bus_off", "", CAN_MAP_HB_VALUES_FLAG,
                            "The CAN controller went bus-off since the previous heartbeat"},
    [URRT_CANTX_HB_CAN_ERRORS] = {"can_errors", "", CAN_MAP_HB_VALUES_FLAG,
                               "CAN error frames since the previous heartbeat"},
    [URRT_CANTX_HB_CAN_DOWN] = {"can_down", "", CAN_MAP_HB_VALUES_FLAG,
                             "The CAN interface went down since the previous heartbeat"},
    [URRT_CANTX_HB_SEND_ERRORS] = {"send_errors", "",
                                CAN_MAP_HB_VALUES_FLAG, "Frames refused by the CAN link since the previous heartbeat"},
    [URRT_CANTX_HB_TX_DROPPED] = {"tx_dropped", "", CAN_MAP_HB_VALUES_FLAG,
                               "Frames dropped on a full transmit queue since the previous heartbeat"},
    [URRT_CANTX_HB_CLAMPED] = {"clamped", "", CAN_MAP_HB_VALUES_FLAG,
                            "A mapped value saturated or was NaN since the previous heartbeat"},
    [URRT_CANTX_HB_DATA_AGE] = {"data_age", "ms",
                             CAN_MAP_HB_VALUES_NONE,
                             "Age of the heartbeat robot's latest packet, saturated at 65534; 65535: no data yet"},
    [URRT_CANTX_HB_DROPS] = {"drops", "", CAN_MAP_HB_VALUES_NONE,
                          "Frames dropped by the CAN link since start, modulo 65536"},
};

struct can_map_run {
    urrt_cantx tx;
    urrt_cantx_tables tables;
    urrt_cantx_frame *frames;        /* the map's, then the heartbeat */
    urrt_cantx_source **sources;     /* per map frame */
    urrt_cantx_frame_state *states;
    urrt_cantx_robot *robots;
    double *values;
};

void can_map_run_free(struct can_map *map)
{
    struct can_map_run *run = map->run;
    if (run == NULL) {
        return;
    }
    for (size_t i = 0; i < map->frame_count && run->sources != NULL; i++) {
        free(run->sources[i]);
    }
    free(run->sources);
    free(run->frames);
    free(run->states);
    free(run->robots);
    free(run->values);
    free(run);
    map->run = NULL;
}

static urrt_cantx_source source_of(const struct can_map_signal *m)
{
    urrt_cantx_source src = {0, 0, 0};
    switch (m->role) {
    case CAN_MAP_ROLE_ALIVE: src.kind = URRT_CANTX_ALIVE; break;
    case CAN_MAP_ROLE_VALID: src.kind = URRT_CANTX_VALID; break;
    default:
        src.kind = m->bitmask ? URRT_CANTX_FIELD_MASK : URRT_CANTX_FIELD;
        src.field = (uint8_t)m->field;
        src.elem = (uint8_t)m->elem;
        break;
    }
    return src;
}

static urrt_cantx_frame frame_of(const struct can_map_frame *f, const urrt_cantx_source *sources)
{
    urrt_cantx_frame out = {
        .signals = f->sigs,
        .sources = sources,
        .signal_count = (uint16_t)f->count,
        .len = f->len,
        .flags = (uint8_t)((f->extended ? URRT_CANTX_EXTENDED : 0u) | (f->fd ? URRT_CANTX_FD : 0u)),
        .id = f->id,
        .period_us = f->every ? URRT_CANTX_EVERY_PACKET : f->period_ms * 1000u,
        .stale_after_us = f->stale_after_ms * 1000u,
        .stale = f->stale_policy == CAN_MAP_STALE_INVALID ? URRT_CANTX_STALE_INVALID : URRT_CANTX_STALE_STOP,
        .robot = (uint8_t)f->robot_index,
        .fill = NULL,
    };
    return out;
}

static urrt_cantx_frame heartbeat_of(const struct can_map *map)
{
    urrt_cantx_frame hb = {
        .signals = urrt_cantx_heartbeat_signals,
        .sources = urrt_cantx_heartbeat_sources,
        .signal_count = URRT_CANTX_HB_COUNT,
        .len = URRT_CANTX_HB_LEN,
        .flags = map->hb_extended ? URRT_CANTX_EXTENDED : 0u,
        .id = map->hb_id,
        .period_us = map->hb_period_ms * 1000u,
        .stale_after_us = map->stale_after_ms * 1000u,
        .stale = URRT_CANTX_STALE_IGNORE,
        .robot = (uint8_t)map->hb_robot_index,
        .fill = urrt_cantx_heartbeat_fill,
    };
    return hb;
}

static bool alloc_run(struct can_map_run *run, size_t frames, size_t robots)
{
    run->frames = calloc(frames, sizeof *run->frames);
    run->sources = calloc(frames, sizeof *run->sources);
    run->states = calloc(frames, sizeof *run->states);
    run->robots = calloc(robots, sizeof *run->robots);
    return run->frames != NULL && run->sources != NULL && run->states != NULL && run->robots != NULL;
}

static int init_core(struct can_map *map, char *err, size_t errlen)
{
    struct can_map_run *run = map->run;
    size_t count = urrt_cantx_value_count(&run->tables);
    size_t bad_frame;
    size_t bad_signal;
    int rc;
    run->values = calloc(count ? count : 1, sizeof *run->values);
    if (run->values == NULL) {
        snprintf(err, errlen, "CAN tables: out of memory");
        return -1;
    }
    rc = urrt_cantx_init(&run->tx, &run->tables, run->states, run->robots, run->values, count, &bad_frame,
                         &bad_signal);
    if (rc < 0) {
        bool hb = bad_frame >= map->frame_count;
        const char *frame = hb ? CAN_MAP_HEARTBEAT_NAME : map->frames[bad_frame].name;
        const char *signal = bad_signal == SIZE_MAX ? NULL
                             : hb ? can_map_heartbeat_layout[bad_signal].name
                                  : map->frames[bad_frame].meta[bad_signal].name;
        snprintf(err, errlen, "frame %s%s%s: the CAN core (lib/urrt_cantx) refuses it: %s", frame,
                 signal ? ", signal " : "", signal ? signal : "", urrt_cantx_strerror(rc));
        return -1;
    }
    return 0;
}

int can_map_build(struct can_map *map, char *err, size_t errlen)
{
    size_t robots = map->robot_count ? map->robot_count : 1;
    size_t i;
    if (map->run != NULL) {
        return 0;
    }
    map->run = calloc(1, sizeof *map->run);
    if (map->run == NULL || !alloc_run(map->run, map->frame_count + 1, robots)) {
        can_map_run_free(map);
        snprintf(err, errlen, "CAN tables: out of memory");
        return -1;
    }
    for (i = 0; i < map->frame_count; i++) {
        const struct can_map_frame *f = &map->frames[i];
        map->run->sources[i] = calloc(f->count ? f->count : 1, sizeof *map->run->sources[i]);
        if (map->run->sources[i] == NULL) {
            can_map_run_free(map);
            snprintf(err, errlen, "CAN tables: out of memory");
            return -1;
        }
        for (size_t k = 0; k < f->count; k++) {
            map->run->sources[i][k] = source_of(&f->meta[k]);
        }
        map->run->frames[i] = frame_of(f, map->run->sources[i]);
    }
    map->run->frames[map->frame_count] = heartbeat_of(map);
    map->run->tables = (urrt_cantx_tables){map->run->frames, map->frame_count + 1, robots,
                                           CAN_MAP_STARTUP_MS * 1000u};
    if (init_core(map, err, errlen) < 0) {
        can_map_run_free(map);
        return -1;
    }
    return 0;
}

urrt_cantx *can_map_tx(struct can_map *map)
{
    char err[256];
    if (map->run == NULL && (!can_map_enabled(map) || can_map_build(map, err, sizeof err) < 0)) {
        return NULL;
    }
    return &map->run->tx;
}

size_t can_map_heartbeat_index(const struct can_map *map)
{
    return map->frame_count;
}

void can_map_start(struct can_map *map, uint64_t now_us)
{
    char err[256];
    if (map->run == NULL && can_map_build(map, err, sizeof err) < 0) {
        return;
    }
    urrt_cantx_start(&map->run->tx, now_us);
}

void can_map_link_stats(struct can_map *map, const urrt_canlink_stats *stats)
{
    urrt_cantx_link link = {stats->bus_off, stats->error_frames, stats->down_events, stats->send_errors,
                            stats->dropped};
    if (map->run != NULL) {
        urrt_cantx_set_link(&map->run->tx, &link);
    }
}

uint64_t can_map_clamped(const struct can_map *map)
{
    return map->run != NULL ? map->run->tx.clamped : 0;
}

urrt_cantx_state can_map_state(const struct can_map *map, uint64_t now_us)
{
    if (map->run == NULL) {
        return URRT_CANTX_STARTING;
    }
    return urrt_cantx_gateway_state(&map->run->tx, can_map_heartbeat_index(map), now_us);
}

/* The core, started at now_us if it was not, with the link's counters
 * (stats NULL: unchanged); NULL when the tables cannot be built. */
static urrt_cantx *core_at(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats)
{
    if (map->run == NULL) {
        can_map_start(map, now_us);
    }
    if (map->run != NULL && stats != NULL) {
        can_map_link_stats(map, stats);
    }
    return map->run != NULL ? &map->run->tx : NULL;
}

void can_map_due(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats, urrt_cantx_emit_fn emit,
                 void *ctx)
{
    urrt_cantx *tx = core_at(map, now_us, stats);
    if (tx != NULL) {
        urrt_cantx_run(tx, now_us, emit, ctx);
    }
}

void can_map_heartbeat_frame(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats,
                             urrt_can_frame *frame)
{
    urrt_cantx *tx = core_at(map, now_us, stats);
    if (tx != NULL) {
        urrt_cantx_peek(tx, can_map_heartbeat_index(map), now_us, frame);
    }
}
