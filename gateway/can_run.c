/* SPDX-License-Identifier: MIT */
/* can_run.c: the run-time half of can_map.h (being replaced by lib/urrt_cantx). */
#include "can_map.h"

#include <math.h>
#include <string.h>

/* ---- the heartbeat layout ----------------------------------------------------- */

#define HB_SIG(start_, length_, type_, min_, max_) \
    {1.0, 0.0, (min_), (max_), 0, (start_), (length_), URRT_CAN_INTEL, (type_), 0}

const struct can_map_hb_signal can_map_heartbeat_layout[CAN_MAP_HB_COUNT] = {
    [CAN_MAP_HB_STATE] = {"state", HB_SIG(0, 4, URRT_CAN_UNSIGNED, 0, 15), "", CAN_MAP_HB_VALUES_STATE,
                          "Gateway state: 0 starting, 1 ok, 2 data stale, 3 robot disconnected"},
    [CAN_MAP_HB_ALIVE] = {"alive_counter", HB_SIG(4, 4, URRT_CAN_UNSIGNED, 0, 15), "", CAN_MAP_HB_VALUES_NONE,
                          "Incremented (modulo 16) with every heartbeat"},
    [CAN_MAP_HB_ROBOT_MODE] = {"robot_mode", HB_SIG(8, 8, URRT_CAN_SIGNED, -128, 127), "",
                               CAN_MAP_HB_VALUES_ROBOT_MODE,
                               "Robot mode of the heartbeat robot as it sends it (numbering per generation); "
                               "-128: not available (no data, or older than stale_after_ms)"},
    [CAN_MAP_HB_SAFETY_MODE] = {"safety_mode", HB_SIG(16, 8, URRT_CAN_UNSIGNED, 0, 255), "",
                                CAN_MAP_HB_VALUES_SAFETY_MODE,
                                "Safety mode of the heartbeat robot; 0: not available (1.x, no data, or older "
                                "than stale_after_ms)"},
    [CAN_MAP_HB_GENERATION] = {"generation", HB_SIG(24, 2, URRT_CAN_UNSIGNED, 0, 3), "",
                               CAN_MAP_HB_VALUES_GENERATION,
                               "Controller generation of the heartbeat robot: 0 unknown, 1 CB1/CB2 (1.x), "
                               "3 CB3/e-series (3.x/5.x)"},
    [CAN_MAP_HB_BUS_OFF] = {"bus_off", HB_SIG(26, 1, URRT_CAN_UNSIGNED, 0, 1), "", CAN_MAP_HB_VALUES_FLAG,
                            "The CAN controller went bus-off since the previous heartbeat"},
    [CAN_MAP_HB_CAN_ERRORS] = {"can_errors", HB_SIG(27, 1, URRT_CAN_UNSIGNED, 0, 1), "", CAN_MAP_HB_VALUES_FLAG,
                               "CAN error frames since the previous heartbeat"},
    [CAN_MAP_HB_CAN_DOWN] = {"can_down", HB_SIG(28, 1, URRT_CAN_UNSIGNED, 0, 1), "", CAN_MAP_HB_VALUES_FLAG,
                             "The CAN interface went down since the previous heartbeat"},
    [CAN_MAP_HB_SEND_ERRORS] = {"send_errors", HB_SIG(29, 1, URRT_CAN_UNSIGNED, 0, 1), "",
                                CAN_MAP_HB_VALUES_FLAG, "Frames refused by the CAN link since the previous heartbeat"},
    [CAN_MAP_HB_TX_DROPPED] = {"tx_dropped", HB_SIG(30, 1, URRT_CAN_UNSIGNED, 0, 1), "", CAN_MAP_HB_VALUES_FLAG,
                               "Frames dropped on a full transmit queue since the previous heartbeat"},
    [CAN_MAP_HB_CLAMPED] = {"clamped", HB_SIG(31, 1, URRT_CAN_UNSIGNED, 0, 1), "", CAN_MAP_HB_VALUES_FLAG,
                            "A mapped value saturated or was NaN since the previous heartbeat"},
    [CAN_MAP_HB_DATA_AGE] = {"data_age", HB_SIG(32, 16, URRT_CAN_UNSIGNED, 0, 65535), "ms",
                             CAN_MAP_HB_VALUES_NONE,
                             "Age of the heartbeat robot's latest packet, saturated at 65534; 65535: no data yet"},
    [CAN_MAP_HB_DROPS] = {"drops", HB_SIG(48, 16, URRT_CAN_UNSIGNED, 0, 65535), "", CAN_MAP_HB_VALUES_NONE,
                          "Frames dropped by the CAN link since start, modulo 65536"},
};

const char *can_map_state_name(enum can_map_gateway_state state)
{
    switch (state) {
    case CAN_MAP_STATE_STARTING: return "STARTING";
    case CAN_MAP_STATE_OK: return "OK";
    case CAN_MAP_STATE_DATA_STALE: return "DATA_STALE";
    case CAN_MAP_STATE_DISCONNECTED: return "ROBOT_DISCONNECTED";
    default: return "UNKNOWN";
    }
}

/* ---- run time ------------------------------------------------------------------------ */

static const size_t field_offsets[URRT_FIELD_COUNT] = {
#define X_OFFSET(ID, name, count, c1, c3, unit, since, desc) offsetof(urrt_state, name),
    URRT_FIELDS(X_OFFSET)
#undef X_OFFSET
};

static double field_value(const urrt_state *st, const struct can_map_signal *m)
{
    double v;
    if (m->field < 0 || m->field >= URRT_FIELD_COUNT || !urrt_has(st, m->field)) {
        return NAN;
    }
    v = ((const double *)(const void *)((const char *)st + field_offsets[m->field]))[m->elem];
    if (m->bitmask) {
        uint64_t mask;
        if (urrt_bitmask(v, &mask) < 0) {
            return NAN;
        }
        v = (double)mask;
    }
    return v;
}

/* Takes the values of f's field signals from st (NULL: every value NaN).
 * A packet costs these loads only: the values are packed when the frame
 * goes out (or before a heartbeat reports clamping), at the frame's rate. */
static void take_fields(struct can_map_frame *f, const urrt_state *st)
{
    size_t i;
    for (i = 0; i < f->count; i++) {
        if (f->meta[i].role == CAN_MAP_ROLE_FIELD) {
            f->meta[i].value = st ? field_value(st, &f->meta[i]) : NAN;
        }
    }
    f->unpacked = true;
}

/* Packs the values taken last, once. */
static void pack_fields(struct can_map *map, struct can_map_frame *f)
{
    size_t i;
    int worst = URRT_CAN_PACK_OK;
    if (!f->unpacked) {
        return;
    }
    f->unpacked = false;
    memset(f->payload, 0, sizeof f->payload);
    for (i = 0; i < f->count; i++) {
        int outcome;
        if (f->meta[i].role != CAN_MAP_ROLE_FIELD) {
            continue;
        }
        outcome = urrt_can_pack(&f->sigs[i], f->meta[i].value, f->payload, f->len);
        if (outcome > worst) {
            worst = outcome;
        }
        if (outcome != URRT_CAN_PACK_OK) {
            map->clamped++;
        }
    }
    f->outcome = worst;
}

void can_map_start(struct can_map *map, uint64_t now_us)
{
    size_t i;
    map->started = true;
    map->start_us = now_us;
    map->hb_next_us = now_us;
    map->hb_alive = 0;
    map->hb_clamped_seen = 0;
    memset(&map->hb_seen, 0, sizeof map->hb_seen);
    for (i = 0; i < map->robot_count; i++) {
        struct can_map_robot_rt *r = &map->robots[i];
        r->has_data = false;
        r->up = false;
        r->robot_mode = NAN;
        r->safety_mode = NAN;
        r->generation = URRT_GEN_UNKNOWN;
    }
    for (i = 0; i < map->frame_count; i++) {
        struct can_map_frame *f = &map->frames[i];
        take_fields(f, NULL);
        pack_fields(map, f);
        f->pending = false;
        f->alive = 0;
        f->stopped = f->stale_policy == CAN_MAP_STALE_STOP;
        f->next_due_us = f->every || f->stopped ? CAN_MAP_NOT_SCHEDULED : now_us;
    }
    map->clamped = 0; /* the NaNs above are no packet's values */
}

void can_map_robot_link(struct can_map *map, size_t robot, bool up)
{
    if (robot < map->robot_count) {
        map->robots[robot].up = up;
    }
}

void can_map_on_packet(struct can_map *map, size_t robot, const urrt_state *st, uint64_t rx_us)
{
    size_t i;
    struct can_map_robot_rt *r;
    if (!map->finished || robot >= map->robot_count || st == NULL) {
        return;
    }
    if (!map->started) {
        can_map_start(map, rx_us);
    }
    r = &map->robots[robot];
    r->has_data = true;
    r->up = true;
    r->last_rx_us = rx_us;
    r->robot_mode = urrt_has(st, URRT_F_ROBOT_MODE) ? st->robot_mode[0] : NAN;
    r->safety_mode = urrt_has(st, URRT_F_SAFETY_MODE) ? st->safety_mode[0] : NAN;
    r->generation = st->generation;
    for (i = 0; i < map->frame_count; i++) {
        struct can_map_frame *f = &map->frames[i];
        if (f->robot_index != robot) {
            continue;
        }
        take_fields(f, st);
        if (f->every) {
            f->pending = true;
        } else if (f->stopped) {
            /* Fresh data again: resume now, then keep the period. */
            f->stopped = false;
            f->next_due_us = rx_us;
        }
    }
}

static bool robot_fresh(const struct can_map *map, size_t robot, uint64_t now_us, uint32_t stale_after_ms)
{
    const struct can_map_robot_rt *r = &map->robots[robot];
    return r->has_data && (now_us < r->last_rx_us || now_us - r->last_rx_us <= (uint64_t)stale_after_ms * 1000u);
}

enum can_map_gateway_state can_map_state(const struct can_map *map, uint64_t now_us)
{
    size_t i;
    enum can_map_gateway_state worst = CAN_MAP_STATE_OK;
    bool starting = map->started && now_us - map->start_us < (uint64_t)CAN_MAP_STARTUP_MS * 1000u;
    for (i = 0; i < map->robot_count; i++) {
        const struct can_map_robot_rt *r = &map->robots[i];
        enum can_map_gateway_state s;
        if (!r->has_data) {
            s = starting ? CAN_MAP_STATE_STARTING : r->up ? CAN_MAP_STATE_DATA_STALE : CAN_MAP_STATE_DISCONNECTED;
        } else if (!r->up) {
            s = CAN_MAP_STATE_DISCONNECTED;
        } else if (!robot_fresh(map, i, now_us, map->stale_after_ms)) {
            s = CAN_MAP_STATE_DATA_STALE;
        } else {
            s = CAN_MAP_STATE_OK;
        }
        /* Severity: disconnected, stale, starting, ok. */
        if (s == CAN_MAP_STATE_DISCONNECTED || (s == CAN_MAP_STATE_DATA_STALE && worst != CAN_MAP_STATE_DISCONNECTED) ||
            (s == CAN_MAP_STATE_STARTING && worst == CAN_MAP_STATE_OK)) {
            worst = s;
        }
    }
    return worst;
}

static double enum_or(double v, double lo, double hi, double na)
{
    if (!(v >= lo && v <= hi) || v != (double)(long long)v) {
        return na;
    }
    return v;
}

static void heartbeat_pack(const struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats,
                           uint8_t alive, urrt_can_frame *frame)
{
    double values[CAN_MAP_HB_COUNT];
    const struct can_map_robot_rt *r = map->robot_count ? &map->robots[map->hb_robot_index] : NULL;
    /* Modes as old as stale data are not the robot's modes now. */
    bool current = r != NULL && robot_fresh(map, map->hb_robot_index, now_us, map->stale_after_ms);
    urrt_canlink_stats zero;
    const urrt_canlink_stats *seen = &map->hb_seen;
    unsigned k;

    memset(&zero, 0, sizeof zero);
    if (stats == NULL) {
        stats = &zero;
    }
    memset(frame, 0, sizeof *frame);
    frame->id = map->hb_id;
    frame->extended = map->hb_extended;
    frame->fd = false;
    frame->len = CAN_MAP_HB_LEN;

    values[CAN_MAP_HB_STATE] = can_map_state(map, now_us);
    values[CAN_MAP_HB_ALIVE] = alive;
    values[CAN_MAP_HB_ROBOT_MODE] = current ? enum_or(r->robot_mode, -127, 127, CAN_MAP_HB_ROBOT_MODE_NA)
                                            : CAN_MAP_HB_ROBOT_MODE_NA;
    values[CAN_MAP_HB_SAFETY_MODE] = current ? enum_or(r->safety_mode, 1, 255, CAN_MAP_HB_SAFETY_MODE_NA)
                                             : CAN_MAP_HB_SAFETY_MODE_NA;
    values[CAN_MAP_HB_GENERATION] = r ? (double)r->generation : 0;
    values[CAN_MAP_HB_BUS_OFF] = stats->bus_off != seen->bus_off;
    values[CAN_MAP_HB_CAN_ERRORS] = stats->error_frames != seen->error_frames;
    values[CAN_MAP_HB_CAN_DOWN] = stats->down_events != seen->down_events;
    values[CAN_MAP_HB_SEND_ERRORS] = stats->send_errors != seen->send_errors;
    values[CAN_MAP_HB_TX_DROPPED] = stats->dropped != seen->dropped;
    values[CAN_MAP_HB_CLAMPED] = map->clamped != map->hb_clamped_seen;
    if (r == NULL || !r->has_data) {
        values[CAN_MAP_HB_DATA_AGE] = CAN_MAP_HB_AGE_NA;
    } else {
        uint64_t age_ms = now_us > r->last_rx_us ? (now_us - r->last_rx_us) / 1000u : 0;
        values[CAN_MAP_HB_DATA_AGE] = age_ms > CAN_MAP_HB_AGE_NA - 1 ? CAN_MAP_HB_AGE_NA - 1 : (double)age_ms;
    }
    values[CAN_MAP_HB_DROPS] = (double)(stats->dropped & 0xFFFFu);
    for (k = 0; k < CAN_MAP_HB_COUNT; k++) {
        urrt_can_pack(&can_map_heartbeat_layout[k].sig, values[k], frame->data, frame->len);
    }
}

void can_map_heartbeat_frame(const struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats,
                             urrt_can_frame *frame)
{
    heartbeat_pack(map, now_us, stats, map->hb_alive, frame);
}

static void send_frame(struct can_map *map, struct can_map_frame *f, bool fresh, can_map_emit_fn emit, void *ctx)
{
    urrt_can_frame out;
    bool valid;
    pack_fields(map, f);
    valid = fresh && f->outcome == URRT_CAN_PACK_OK;
    memset(&out, 0, sizeof out);
    out.id = f->id;
    out.extended = f->extended;
    out.fd = f->fd;
    out.len = f->len;
    memcpy(out.data, f->payload, f->len);
    if (f->alive_index >= 0) {
        urrt_can_put_raw(&f->sigs[f->alive_index], f->alive, out.data, out.len);
        f->alive = (uint8_t)((f->alive + 1u) & ((1u << CAN_MAP_ALIVE_BITS) - 1u));
    }
    if (f->valid_index >= 0) {
        urrt_can_put_raw(&f->sigs[f->valid_index], valid ? 1u : 0u, out.data, out.len);
    }
    f->sent++;
    f->sent_invalid += !valid;
    if (emit != NULL) {
        emit(ctx, &out);
    }
}

void can_map_due(struct can_map *map, uint64_t now_us, const urrt_canlink_stats *stats, can_map_emit_fn emit, void *ctx)
{
    size_t i;
    if (!map->finished || !map->configured) {
        return;
    }
    if (!map->started) {
        can_map_start(map, now_us);
    }
    for (i = 0; i < map->frame_count; i++) {
        struct can_map_frame *f = &map->frames[i];
        bool fresh = robot_fresh(map, f->robot_index, now_us, f->stale_after_ms);
        if (f->every) {
            /* Pending since a packet that came while the CAN link was
             * down: stale by now, it stops with the packets. */
            if (f->pending && !fresh) {
                f->pending = false;
                f->stale_stops++;
            }
            if (f->pending) {
                f->pending = false;
                send_frame(map, f, true, emit, ctx);
            }
            continue;
        }
        if (f->next_due_us == CAN_MAP_NOT_SCHEDULED || now_us < f->next_due_us) {
            continue;
        }
        if (!fresh && f->stale_policy == CAN_MAP_STALE_STOP) {
            f->stopped = true;
            f->stale_stops++;
            f->next_due_us = CAN_MAP_NOT_SCHEDULED;
            continue;
        }
        send_frame(map, f, fresh, emit, ctx);
        /* Keep the cadence; after a stall, skip the missed slots rather
         * than send a burst. */
        f->next_due_us += (uint64_t)f->period_ms * 1000u;
        if (f->next_due_us <= now_us) {
            f->next_due_us = now_us + (uint64_t)f->period_ms * 1000u;
        }
    }
    if (now_us >= map->hb_next_us) {
        urrt_can_frame hb;
        /* The clamped flag covers every value taken so far. */
        for (i = 0; i < map->frame_count; i++) {
            pack_fields(map, &map->frames[i]);
        }
        heartbeat_pack(map, now_us, stats, map->hb_alive, &hb);
        map->state = can_map_state(map, now_us);
        map->hb_alive = (uint8_t)((map->hb_alive + 1u) & 0x0Fu);
        if (stats != NULL) {
            map->hb_seen = *stats;
        }
        map->hb_clamped_seen = map->clamped;
        map->hb_sent++;
        map->hb_next_us += (uint64_t)map->hb_period_ms * 1000u;
        if (map->hb_next_us <= now_us) {
            map->hb_next_us = now_us + (uint64_t)map->hb_period_ms * 1000u;
        }
        if (emit != NULL) {
            emit(ctx, &hb);
        }
    }
}

uint64_t can_map_deadline(const struct can_map *map)
{
    uint64_t next = CAN_MAP_NOT_SCHEDULED;
    size_t i;
    if (!map->finished || !map->configured || !map->started) {
        return CAN_MAP_NOT_SCHEDULED;
    }
    next = map->hb_next_us;
    for (i = 0; i < map->frame_count; i++) {
        const struct can_map_frame *f = &map->frames[i];
        if (f->every && f->pending) {
            return 0; /* now */
        }
        if (f->next_due_us < next) {
            next = f->next_due_us;
        }
    }
    return next;
}
