/* SPDX-License-Identifier: MIT */
/* co_run.c: see co_run.h. */
#include "co_run.h"

#include "urrt_rtde.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TYPE_EVENT 254u
#define SDO_RX_BASE 0x600u

struct co_run {
    urrt_co co;
    urrt_co_desc desc;
    urrt_co_tpdo *tpdos;            /* the [frame]s' in TPDO order, then the status TPDO */
    uint32_t *mappings;             /* URRT_CO_MAX_MAPPED per TPDO */
    urrt_co_object *objects;
    urrt_co_tpdo_state *states;
    /* The [input]s' RPDOs: their variables, one per signal, [input] i's from
     * first_var[i] on, in signal order. */
    urrt_co_rpdo rpdos[URRT_CO_MAX_RPDOS];
    uint32_t rpdo_maps[URRT_CO_MAX_RPDOS][URRT_CO_RPDO_MAX_MAPPED];
    urrt_co_rpdo_state rpdo_states[URRT_CO_MAX_RPDOS];
    urrt_co_consumer consumers[1];
    urrt_co_rx_storage rx;          /* the node's receiving side: kept as long as the node */
    uint32_t consumer_default;      /* 0x1016 sub 1: off until the manager writes it */
    size_t first_var[URRT_CO_MAX_RPDOS + 1];
    uint32_t *vars;                 /* at least one: urrt_co_init wants storage all the same */
    uint64_t *written_us;
    uint32_t rx_ids[URRT_CO_RX_IDS_MAX]; /* urrt_co_rx_ids after a reset */
    size_t rx_count;
};

void co_run_free(struct co_run *run)
{
    if (run == NULL) {
        return;
    }
    free(run->tpdos);
    free(run->mappings);
    free(run->objects);
    free(run->states);
    free(run->vars);
    free(run->written_us);
    free(run);
}

uint16_t co_run_values_index(unsigned tpdo)
{
    return (uint16_t)(CANOPEN_VALUES_INDEX + tpdo - 1u);
}

static uint32_t map_entry(uint16_t index, uint8_t sub, unsigned bits)
{
    return (uint32_t)index << 16 | (uint32_t)sub << 8 | bits;
}

/* A frame TPDO's mapping: its signals by byte, a dummy byte where none is. */
static uint8_t frame_mapping(const struct can_map_frame *f, unsigned tpdo, uint32_t *out)
{
    uint8_t count = 0;
    for (unsigned byte = 0; byte < f->len; byte++) {
        bool mapped = false;
        for (size_t k = 0; k < f->count && !mapped; k++) {
            uint8_t type;
            unsigned bytes;
            if (f->sigs[k].start / 8u == byte &&
                canopen_signal_object(&f->sigs[k], &f->meta[k], &type, &bytes, NULL, 0)) {
                out[count++] = map_entry(co_run_values_index(tpdo), (uint8_t)(k + 1u), 8u * bytes);
                byte += bytes - 1u;
                mapped = true;
            }
        }
        if (!mapped) {
            out[count++] = map_entry(CANOPEN_DUMMY_U8, 0, 8);
        }
    }
    return count;
}

static uint8_t status_type(const urrt_can_signal *sig)
{
    bool wide = sig->length > 8u;
    if (sig->type == URRT_CAN_SIGNED) {
        return wide ? URRT_CO_INTEGER16 : URRT_CO_INTEGER8;
    }
    return wide ? URRT_CO_UNSIGNED16 : URRT_CO_UNSIGNED8;
}

static urrt_co_object signal_object(uint16_t index, size_t sub, uint8_t type, size_t frame, size_t item)
{
    urrt_co_object o = {index, (uint8_t)sub, type, URRT_CO_RO, URRT_CO_SIGNAL, (uint16_t)frame, (uint16_t)item,
                        0, 0, 0};
    return o;
}

/* The status TPDO and its objects: [can]'s heartbeat frame. A signal that
 * fills whole bytes is mapped; a byte of bit fields (state and alive counter,
 * generation and flags) is an UNSIGNED8 dummy, as CiA 301 wants a mapped
 * length to be its object's size: those objects are read by SDO. */
static void status_tpdo(struct co_run *r, const struct can_map *can, size_t hb, size_t n, size_t *objects)
{
    uint32_t *mapping = &r->mappings[n * URRT_CO_MAX_MAPPED];
    uint8_t count = 0;
    for (size_t k = 0; k < URRT_CANTX_HB_COUNT; k++) {
        r->objects[(*objects)++] = signal_object(CANOPEN_STATUS_INDEX, k + 1u,
                                                 status_type(&urrt_cantx_heartbeat_signals[k]), hb, k);
    }
    for (unsigned byte = 0; byte < URRT_CANTX_HB_LEN; byte++) {
        uint32_t entry = map_entry(CANOPEN_DUMMY_U8, 0, 8);
        for (size_t k = 0; k < URRT_CANTX_HB_COUNT; k++) {
            const urrt_can_signal *sig = &urrt_cantx_heartbeat_signals[k];
            if (sig->start == 8u * byte && sig->length % 8u == 0u) {
                entry = map_entry(CANOPEN_STATUS_INDEX, (uint8_t)(k + 1u), sig->length);
                byte += sig->length / 8u - 1u;
            }
        }
        mapping[count++] = entry;
    }
    r->tpdos[n] = (urrt_co_tpdo){mapping, URRT_CO_COB_INVALID | can->hb_id, (uint16_t)hb, 0, TYPE_EVENT, count};
}

static void frame_tpdos(struct co_run *r, const struct canopen_map *co, const struct can_map *can, size_t *objects)
{
    for (size_t i = 0; i < can->frame_count; i++) {
        const struct can_map_frame *f = &can->frames[i];
        unsigned tpdo = co->tpdo_of[i];
        uint32_t *mapping = &r->mappings[(tpdo - 1u) * URRT_CO_MAX_MAPPED];
        for (size_t k = 0; k < f->count; k++) {
            uint8_t type = 0;
            unsigned bytes;
            (void)canopen_signal_object(&f->sigs[k], &f->meta[k], &type, &bytes, NULL, 0);
            r->objects[(*objects)++] = signal_object(co_run_values_index(tpdo), k + 1u, type, i, k);
        }
        r->tpdos[tpdo - 1u] = (urrt_co_tpdo){
            mapping, co->frames[i].own_id ? f->id : URRT_CO_COB_DEFAULT, (uint16_t)i, 0,
            (uint8_t)(co->frames[i].sync_every != 0 ? co->frames[i].sync_every : TYPE_EVENT),
            frame_mapping(f, tpdo, mapping)};
    }
}

/* A raw value (signed ones negative) as its object's bits. */
static uint32_t bits_of(const urrt_can_signal *sig, int64_t raw)
{
    return (uint32_t)((uint64_t)raw & (sig->length >= 32u ? UINT32_MAX : ((uint32_t)1u << sig->length) - 1u));
}

/* Whether raw, scaled, is a value the signal's min..max accepts (can_in's rule). */
static bool accepted(const urrt_can_signal *sig, int64_t raw)
{
    double v = urrt_can_from_raw(sig, bits_of(sig, raw));
    return v >= sig->min && v <= sig->max;
}

/* The raw range of an [input] signal's object: the raw values whose
 * physical value its min..max accepts (a BOOL register: 0 and 1), so that
 * the node refuses what the gateway would (an SDO write is aborted, an
 * RPDO value not stored and counted) and the EDS states the same limits. A
 * mask takes its whole width. */
static void input_range(const urrt_can_signal *sig, const struct can_map_signal *meta, uint32_t *min, uint32_t *max,
                        uint32_t *def)
{
    unsigned len = sig->length;
    int64_t type_lo = sig->type == URRT_CAN_SIGNED ? -((int64_t)1 << (len - 1u)) : 0;
    int64_t type_hi = sig->type == URRT_CAN_SIGNED ? ((int64_t)1 << (len - 1u)) - 1 : ((int64_t)1 << len) - 1;
    int64_t lo = type_lo, hi = type_hi;
    if (!meta->bitmask) {
        /* The nearest raw values by the inverse scaling, then a step inward while
         * the value scaled back falls outside: exact whatever the rounding. */
        double a = (sig->min - sig->offset) / sig->factor, b = (sig->max - sig->offset) / sig->factor;
        double first = ceil(a < b ? a : b), last = floor(a < b ? b : a);
        lo = first > (double)type_hi ? type_hi : first < (double)type_lo ? type_lo : (int64_t)first;
        hi = last < (double)type_lo ? type_lo : last > (double)type_hi ? type_hi : (int64_t)last;
        while (lo < hi && !accepted(sig, lo)) {
            lo++;
        }
        while (hi > lo && !accepted(sig, hi)) {
            hi--;
        }
        lo = lo > type_lo && accepted(sig, lo - 1) ? lo - 1 : lo;
        hi = hi < type_hi && accepted(sig, hi + 1) ? hi + 1 : hi;
    }
    if (!meta->bitmask && meta->var >= URRT_RTDE_V_INPUT_BIT_REGISTER &&
        meta->var < URRT_RTDE_V_INPUT_BIT_REGISTER + 64) {
        lo = lo > 0 ? lo : 0;
        hi = hi < 1 ? hi : 1;
    }
    *min = bits_of(sig, lo);
    *max = bits_of(sig, hi);
    /* What the variable holds before the first write, which is never
     * forwarded (plc_in takes only written values): 0, or the limit nearest. */
    *def = bits_of(sig, lo > 0 ? lo : hi < 0 ? hi : 0);
}

/* [input] i as RPDO i + 1: a writable object per signal (0x2200 + i, sub
 * k + 1) in a variable of its own, mapped byte by byte, a dummy byte where
 * no signal is; its event timer the [input]'s timeout_ms, acted on at once
 * (type 254). */
static void input_rpdos(struct co_run *r, const struct can_map *can, size_t *objects)
{
    size_t var = 0;
    for (size_t i = 0; i < can->input_count && i < URRT_CO_MAX_RPDOS; i++) {
        const struct can_map_frame *f = &can->inputs[i];
        uint8_t count = 0;
        r->first_var[i] = var;
        for (size_t k = 0; k < f->count; k++) {
            uint8_t type = 0;
            unsigned bytes;
            urrt_co_object o = {(uint16_t)(CANOPEN_INPUTS_INDEX + i), (uint8_t)(k + 1u), 0, URRT_CO_RW, URRT_CO_VAR,
                                0, (uint16_t)var++, 0, 0, 0};
            (void)canopen_signal_object(&f->sigs[k], &f->meta[k], &type, &bytes, NULL, 0);
            o.type = type;
            input_range(&f->sigs[k], &f->meta[k], &o.min, &o.max, &o.def);
            r->objects[(*objects)++] = o;
        }
        for (unsigned byte = 0; byte < f->len; byte++) {
            uint32_t entry = map_entry(CANOPEN_DUMMY_U8, 0, 8);
            for (size_t k = 0; k < f->count; k++) {
                uint8_t type;
                unsigned bytes;
                if (f->sigs[k].start / 8u == byte &&
                    canopen_signal_object(&f->sigs[k], &f->meta[k], &type, &bytes, NULL, 0)) {
                    entry = map_entry((uint16_t)(CANOPEN_INPUTS_INDEX + i), (uint8_t)(k + 1u), 8u * bytes);
                    byte += bytes - 1u;
                    break;
                }
            }
            r->rpdo_maps[i][count++] = entry;
        }
        r->rpdos[i] = (urrt_co_rpdo){r->rpdo_maps[i], URRT_CO_COB_DEFAULT,
                                     (uint16_t)(f->timeout_ms < UINT16_MAX ? f->timeout_ms : UINT16_MAX), TYPE_EVENT,
                                     count};
    }
    r->first_var[can->input_count < URRT_CO_MAX_RPDOS ? can->input_count : URRT_CO_MAX_RPDOS] = var;
}

static void describe(struct co_run *r, const struct canopen_map *co, const struct can_map *can, size_t tpdos,
                     size_t objects)
{
    urrt_co_desc *d = &r->desc;
    d->node_id = (uint8_t)co->node_id;
    d->nmt_start = co->nmt_start;
    d->heartbeat_ms = (uint16_t)co->heartbeat_ms;
    d->sdo_timeout_ms = (uint16_t)co->sdo_timeout_ms;
    d->stale_after_us = can->stale_after_ms * 1000u;
    d->device_type = co->device_type;
    d->vendor_id = co->vendor_id;
    d->product_code = co->product_code;
    d->revision = co->revision;
    d->serial = co->serial;
    d->device_name = co->device_name;
    d->hardware_version = co->hardware_version;
    d->software_version = URRT_VERSION_STRING;
    d->tpdos = r->tpdos;
    d->tpdo_count = tpdos;
    d->objects = r->objects;
    d->object_count = objects;
    d->rpdos = can->input_count > 0 ? r->rpdos : NULL;
    d->rpdo_count = can->input_count;
    /* 0x1016 sub 1, off: the manager says whose heartbeat to watch, and how closely. */
    d->consumers = can->input_count > 0 ? &r->consumer_default : NULL;
    d->consumer_count = can->input_count > 0 ? 1u : 0u;
}

static int node_init(struct co_run *r, struct can_run *run, size_t vars, char *err, size_t errlen)
{
    size_t bad;
    int rc;
    r->rx.rpdos = r->rpdo_states;
    r->rx.consumers = r->consumers;
    r->rx.written_us = r->written_us;
    rc = r->desc.rpdo_count > 0
             ? urrt_co_init_rx(&r->co, &r->desc, can_run_tx(run), r->states, r->vars, vars, &r->rx, &bad)
             : urrt_co_init(&r->co, &r->desc, can_run_tx(run), r->states, r->vars, 1, &bad);
    if (rc < 0) {
        snprintf(err, errlen, "the CANopen node (lib/urrt_co) refuses the configuration (%s %zu): %s",
                 rc == URRT_CO_E_OBJECT ? "object" : r->desc.rpdo_count > 0 ? "PDO" : "TPDO",
                 bad == SIZE_MAX ? 0 : bad + 1,
                 r->desc.rpdo_count > 0 ? urrt_co_rx_strerror(rc) : urrt_co_strerror(rc));
    }
    return rc;
}

struct co_run *co_run_build(const struct canopen_map *co, const struct can_map *can, struct can_run *run, char *err,
                            size_t errlen)
{
    size_t tpdos = can->frame_count + 1u;
    size_t objects = URRT_CANTX_HB_COUNT;
    size_t vars = 0;
    size_t made = 0;
    struct co_run *r = calloc(1, sizeof *r);
    for (size_t i = 0; i < can->frame_count; i++) {
        objects += can->frames[i].count;
    }
    for (size_t i = 0; i < can->input_count; i++) {
        vars += can->inputs[i].count;
    }
    objects += vars;
    if (r != NULL) {
        r->tpdos = calloc(tpdos, sizeof *r->tpdos);
        r->mappings = calloc(tpdos * URRT_CO_MAX_MAPPED, sizeof *r->mappings);
        r->objects = calloc(objects, sizeof *r->objects);
        r->states = calloc(tpdos, sizeof *r->states);
        r->vars = calloc(vars ? vars : 1, sizeof *r->vars);
        r->written_us = calloc(vars ? vars : 1, sizeof *r->written_us);
    }
    if (r == NULL || r->tpdos == NULL || r->mappings == NULL || r->objects == NULL || r->states == NULL ||
        r->vars == NULL || r->written_us == NULL) {
        co_run_free(r);
        snprintf(err, errlen, "CANopen node: out of memory");
        return NULL;
    }
    frame_tpdos(r, co, can, &made);
    status_tpdo(r, can, can_run_heartbeat_index(run), tpdos - 1u, &made);
    input_rpdos(r, can, &made);
    describe(r, co, can, tpdos, made);
    if (node_init(r, run, vars, err, errlen) < 0) {
        co_run_free(r);
        return NULL;
    }
    r->rx_count = urrt_co_rx_ids(&r->co, r->rx_ids);
    return r;
}

urrt_co *co_run_node(struct co_run *run)
{
    return &run->co;
}

const urrt_co_desc *co_run_desc(const struct co_run *run)
{
    return &run->desc;
}

bool co_run_mapped(const struct co_run *run, uint16_t index, uint8_t sub)
{
    const urrt_co_desc *d = &run->desc;
    for (size_t n = 0; n < d->tpdo_count; n++) {
        for (size_t i = 0; i < d->tpdos[n].mapping_count; i++) {
            if (d->tpdos[n].mapping[i] >> 8 == ((uint32_t)index << 8 | sub)) {
                return true;
            }
        }
    }
    return false;
}

const uint32_t *co_run_rx_ids(const struct co_run *run, size_t *count)
{
    *count = run->rx_count;
    return run->rx_ids;
}

size_t co_run_input_first_var(const struct co_run *run, size_t input)
{
    return run->first_var[input < URRT_CO_MAX_RPDOS ? input : URRT_CO_MAX_RPDOS];
}

uint32_t co_run_input_raw(const struct co_run *run, size_t input, size_t signal)
{
    return run->vars[run->first_var[input] + signal];
}

uint64_t co_run_input_written_us(const struct co_run *run, size_t input)
{
    uint64_t newest = URRT_CANTX_NEVER;
    for (size_t v = run->first_var[input]; v < run->first_var[input + 1u]; v++) {
        uint64_t w = run->written_us[v];
        newest = w == URRT_CANTX_NEVER ? newest : newest == URRT_CANTX_NEVER || w > newest ? w : newest;
    }
    return newest;
}

/* snprintf at the end of what buf holds so far (*len: snprintf's total). */
static void append(char *buf, size_t size, int *len, const char *fmt, ...)
{
    size_t at = *len >= 0 && (size_t)*len < size ? (size_t)*len : size;
    va_list ap;
    int n;
    if (*len < 0) {
        return;
    }
    va_start(ap, fmt);
    n = vsnprintf(buf + at, size - at, fmt, ap);
    va_end(ap);
    *len = n < 0 ? n : *len + n;
}

int co_run_describe(const struct co_run *run, char *buf, size_t size)
{
    const urrt_co_desc *d = &run->desc;
    size_t status = d->tpdo_count - 1u;
    int len = 0;
    append(buf, size, &len, "node %u: ", (unsigned)d->node_id);
    if (status > 0) {
        append(buf, size, &len, "TPDO1..%zu at", status);
    }
    for (size_t n = 0; n < status; n++) {
        append(buf, size, &len, " 0x%X", (unsigned)(urrt_co_tpdo_cob_default(&run->co, n) & 0x7FFu));
    }
    append(buf, size, &len,
           "%sstatus TPDO%zu at 0x%X (off until enabled), heartbeat %u ms at 0x%X, EMCY 0x%X, SDO 0x%X/0x%X, starts %s",
           status > 0 ? ", " : "", d->tpdo_count, (unsigned)(urrt_co_tpdo_cob_default(&run->co, status) & 0x7FFu),
           (unsigned)d->heartbeat_ms, 0x700u + d->node_id, 0x080u + d->node_id, SDO_RX_BASE + d->node_id,
           0x580u + d->node_id, canopen_nmt_start_name(d->nmt_start));
    for (size_t n = 0; n < d->rpdo_count; n++) {
        append(buf, size, &len, "%s RPDO%zu at 0x%X", n == 0 ? "; receives" : ",", n + 1u,
               (unsigned)(urrt_co_rpdo_cob_default(&run->co, n) & 0x7FFu));
    }
    if (d->consumer_count > 0) {
        append(buf, size, &len, ", the manager's heartbeat watched once 0x1016 sub 1 names it");
    }
    return len;
}
