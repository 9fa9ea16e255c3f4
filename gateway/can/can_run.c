/* SPDX-License-Identifier: MIT */
/* can_run.c: see can_run.h. */
#include "can_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtde_only.h"

struct can_run {
    urrt_cantx tx;
    urrt_cantx_tables tables;
    urrt_cantx_frame *frames;        /* the map's, then the heartbeat */
    urrt_cantx_source **sources;     /* per map frame */
    size_t frame_count;              /* of the map: sources has as many */
    urrt_cantx_frame_state *states;
    urrt_cantx_robot *robots;
    double *values;
    urrt_can_scale *scales;          /* one per value: packing without a division (urrt_cantx_prepare) */
    const struct can_map *map;       /* what the RTDE-only signals carry (fill_rtde) */
    urrt_rtde_values *rtde;          /* per robot: its latest package's RTDE-only values */
};

void can_run_free(struct can_run *run)
{
    if (run == NULL) {
        return;
    }
    for (size_t i = 0; i < run->frame_count && run->sources != NULL; i++) {
        free(run->sources[i]);
    }
    free(run->sources);
    free(run->frames);
    free(run->states);
    free(run->robots);
    free(run->values);
    free(run->scales);
    free(run->rtde);
    free(run);
}

static urrt_cantx_source source_of(const struct can_map_signal *m)
{
    urrt_cantx_source src = {0, 0, 0};
    switch (m->role) {
    case CAN_MAP_ROLE_ALIVE: src.kind = URRT_CANTX_ALIVE; break;
    case CAN_MAP_ROLE_VALID: src.kind = URRT_CANTX_VALID; break;
    case CAN_MAP_ROLE_RTDE:
        /* A mask as its 64 bits: a double holding it would lose bits past 2^53. */
        src.kind = m->bitmask ? URRT_CANTX_FILLED_MASK : URRT_CANTX_FILLED;
        src.elem = (uint8_t)m->elem;
        break;
    default:
        src.kind = m->bitmask ? URRT_CANTX_FIELD_MASK : URRT_CANTX_FIELD;
        src.field = (uint8_t)m->field;
        src.elem = (uint8_t)m->elem;
        break;
    }
    return src;
}

/* The RTDE-only values of frame `frame`, from its robot's latest package: as
 * old as that package, whose time the frame's freshness already judges. */
static void fill_rtde(urrt_cantx *tx, size_t frame, uint64_t now_us, bool sending, double *values)
{
    const struct can_run *run = tx->user;
    const struct can_map_frame *f = &run->map->frames[frame];
    const urrt_rtde_values *v = &run->rtde[f->robot_index];
    (void)now_us;
    (void)sending;
    for (size_t k = 0; k < f->count; k++) {
        const struct can_map_signal *m = &f->meta[k];
        if (m->role == CAN_MAP_ROLE_RTDE) {
            values[k] = m->bitmask ? urrt_cantx_mask_value(rtde_only_mask(v, m->var))
                                   : rtde_only_element(v, m->var, m->elem);
        }
    }
}

static bool has_rtde(const struct can_map_frame *f)
{
    for (size_t k = 0; k < f->count; k++) {
        if (f->meta[k].role == CAN_MAP_ROLE_RTDE) {
            return true;
        }
    }
    return false;
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
        .fill = has_rtde(f) ? fill_rtde : NULL,
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

static bool alloc_run(struct can_run *run, size_t frames, size_t robots)
{
    run->frames = calloc(frames, sizeof *run->frames);
    run->sources = calloc(frames, sizeof *run->sources);
    run->states = calloc(frames, sizeof *run->states);
    run->robots = calloc(robots, sizeof *run->robots);
    run->rtde = calloc(robots, sizeof *run->rtde);
    for (size_t i = 0; run->rtde != NULL && i < robots; i++) {
        urrt_rtde_values_clear(&run->rtde[i]);
    }
    return run->frames != NULL && run->sources != NULL && run->states != NULL && run->robots != NULL &&
           run->rtde != NULL;
}

static int init_core(struct can_run *run, const struct can_map *map, char *err, size_t errlen)
{
    size_t count = urrt_cantx_value_count(&run->tables);
    size_t bad_frame;
    size_t bad_signal;
    int rc;
    run->values = calloc(count ? count : 1, sizeof *run->values);
    run->scales = calloc(count ? count : 1, sizeof *run->scales);
    if (run->values == NULL || run->scales == NULL) {
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
    /* Cannot fail: the tables were just accepted and scales[] holds count. */
    (void)urrt_cantx_prepare(&run->tx, run->scales, count);
    run->tx.user = run;
    return 0;
}

/* The frames' tables; false when out of memory. */
static bool fill_frames(struct can_run *run, const struct can_map *map)
{
    for (size_t i = 0; i < map->frame_count; i++) {
        const struct can_map_frame *f = &map->frames[i];
        run->sources[i] = calloc(f->count ? f->count : 1, sizeof *run->sources[i]);
        if (run->sources[i] == NULL) {
            return false;
        }
        for (size_t k = 0; k < f->count; k++) {
            run->sources[i][k] = source_of(&f->meta[k]);
        }
        run->frames[i] = frame_of(f, run->sources[i]);
    }
    run->frames[map->frame_count] = heartbeat_of(map);
    return true;
}

struct can_run *can_run_build(const struct can_map *map, char *err, size_t errlen)
{
    size_t robots = map->robot_count ? map->robot_count : 1;
    struct can_run *run = calloc(1, sizeof *run);
    if (run != NULL) {
        run->frame_count = map->frame_count;
        run->map = map;
    }
    if (run == NULL || !alloc_run(run, map->frame_count + 1, robots) || !fill_frames(run, map)) {
        can_run_free(run);
        snprintf(err, errlen, "CAN tables: out of memory");
        return NULL;
    }
    run->tables = (urrt_cantx_tables){run->frames, map->frame_count + 1, robots, CAN_RUN_STARTUP_MS * 1000u};
    if (init_core(run, map, err, errlen) < 0) {
        can_run_free(run);
        return NULL;
    }
    return run;
}

void can_run_rtde(struct can_run *run, size_t robot, const urrt_rtde_values *values)
{
    if (values != NULL && robot < run->tables.robot_count) {
        run->rtde[robot] = *values;
    }
}

urrt_cantx *can_run_tx(struct can_run *run)
{
    return &run->tx;
}

size_t can_run_heartbeat_index(const struct can_run *run)
{
    return run->frame_count;
}

void can_run_start(struct can_run *run, uint64_t now_us)
{
    urrt_cantx_start(&run->tx, now_us);
}

void can_run_set_link(struct can_run *run, const urrt_canlink_stats *stats)
{
    urrt_cantx_link link = {stats->bus_off, stats->error_frames, stats->down_events, stats->send_errors,
                            stats->dropped};
    urrt_cantx_set_link(&run->tx, &link);
}

uint64_t can_run_clamped(const struct can_run *run)
{
    return run->tx.clamped;
}

urrt_cantx_state can_run_state(const struct can_run *run, uint64_t now_us)
{
    return urrt_cantx_gateway_state(&run->tx, can_run_heartbeat_index(run), now_us);
}

void can_run_due(struct can_run *run, uint64_t now_us, const urrt_canlink_stats *stats, urrt_cantx_emit_fn emit,
                 void *ctx)
{
    if (stats != NULL) {
        can_run_set_link(run, stats);
    }
    urrt_cantx_run(&run->tx, now_us, emit, ctx);
}

void can_run_heartbeat_frame(struct can_run *run, uint64_t now_us, const urrt_canlink_stats *stats,
                             urrt_can_frame *frame)
{
    if (stats != NULL) {
        can_run_set_link(run, stats);
    }
    urrt_cantx_peek(&run->tx, can_run_heartbeat_index(run), now_us, frame);
}
