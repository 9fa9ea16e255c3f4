/* SPDX-License-Identifier: MIT */
/* urrt_co_rx: the CANopen node's receiving side, RPDOs 1..4 and the consumer
 * heartbeat 0x1016 (see urrt_co.h, "RPDOs", and docs/canopen.md). A unit of
 * its own, as urrt_rtde_in.c is for RTDE: urrt_co.c calls it only through
 * the table urrt_co_init_rx installs (urrt_co_internal.h), so a node set up
 * with urrt_co_init links none of this file. Freestanding C99. */
#include "urrt_co.h"

#include <stdint.h>

#include "urrt_co_internal.h"

#define NONE URRT_CO_NONE
#define MAX_NODE_ID URRT_CO_MAX_NODE_ID
#define ID_MASK URRT_CO_ID_MASK
#define COB_NO_RTR URRT_CO_COB_NO_RTR
#define NMT_EC_BASE URRT_CO_NMT_EC_BASE
#define SYNC_MAX_N URRT_CO_SYNC_MAX_N
#define TYPE_EVENT_MFR URRT_CO_TYPE_EVENT
#define RPDO_BASE 0x200u               /* RPDO1..4: 0x200, 0x300, 0x400, 0x500 + node id */
#define DUMMY_FIRST 0x0002u            /* dummy mapping entries: the data type indices INTEGER8.. */
#define DUMMY_LAST 0x0007u             /* .. UNSIGNED32 */
#define COND_HEARTBEAT URRT_CO_COND_HEARTBEAT
#define COND_LENGTH URRT_CO_COND_LENGTH
#define COND_TIMEOUT URRT_CO_COND_TIMEOUT
#define BASE_CONDITIONS URRT_CO_BASE_CONDITIONS

/* ---- checks, once --------------------------------------------------------------- */

/* The object a mapping entry names, or NONE. */
static size_t object_of(const urrt_co_desc *d, uint32_t entry)
{
    size_t i;
    for (i = 0; i < d->object_count; i++) {
        const urrt_co_object *o = &d->objects[i];
        if (o->index == entry >> 16 && o->sub == (uint8_t)(entry >> 8)) {
            return i;
        }
    }
    return NONE;
}

static bool dummy_entry(uint32_t entry)
{
    return entry >> 16 >= DUMMY_FIRST && entry >> 16 <= DUMMY_LAST;
}

/* An RPDO's mapping entry: a dummy of its type's size, or a writable
 * integer VAR of its size. */
static bool rpdo_entry_fits(const urrt_co_desc *d, uint32_t entry)
{
    size_t i = object_of(d, entry);
    uint32_t bits = entry & 0xFFu;
    if (dummy_entry(entry)) {
        return (entry >> 8 & 0xFFu) == 0u && bits == 8u * urrt_co_type_size((uint8_t)(entry >> 16));
    }
    return i != NONE && d->objects[i].kind == URRT_CO_VAR && (d->objects[i].access & URRT_CO_WO) != 0u &&
           d->objects[i].type != URRT_CO_REAL32 && bits == 8u * urrt_co_type_size(d->objects[i].type);
}

static uint32_t rpdo_bytes(const urrt_co_rpdo *p)
{
    uint32_t bits = 0;
    size_t i;
    for (i = 0; i < p->mapping_count; i++) {
        bits += p->mapping[i] & 0xFFu;
    }
    return bits / 8u;
}

/* RPDO n's COB-ID after a reset: the description's, or CiA 301's pre-defined one. */
static uint32_t rpdo_cob(const urrt_co_desc *d, size_t n)
{
    uint32_t cob = d->rpdos[n].cob_id;
    return cob != URRT_CO_COB_DEFAULT ? cob : RPDO_BASE + 0x100u * (uint32_t)n + d->node_id;
}

static int check_rpdo(const urrt_co_desc *d, size_t n)
{
    const urrt_co_rpdo *p = &d->rpdos[n];
    uint32_t bits = 0;
    size_t i;
    if (p->mapping_count > URRT_CO_RPDO_MAX_MAPPED || (p->mapping_count > 0u && p->mapping == NULL) ||
        (p->transmission_type > SYNC_MAX_N && p->transmission_type < TYPE_EVENT_MFR)) {
        return URRT_CO_E_RPDO;
    }
    for (i = 0; i < p->mapping_count; i++) {
        bits += p->mapping[i] & 0xFFu;
        if (!rpdo_entry_fits(d, p->mapping[i])) {
            return URRT_CO_E_RPDO;
        }
    }
    if (bits > 8u * URRT_CAN_CLASSIC_MAX_LEN) {
        return URRT_CO_E_RPDO;
    }
    for (i = 0; urrt_co_cob_valid(rpdo_cob(d, n)) && i < n; i++) {
        if (urrt_co_cob_valid(rpdo_cob(d, i)) && ((rpdo_cob(d, i) ^ rpdo_cob(d, n)) & ID_MASK) == 0u) {
            return URRT_CO_E_RPDO; /* two valid RPDOs on one id */
        }
    }
    return p->cob_id != URRT_CO_COB_DEFAULT && urrt_co_cob_check(URRT_CO_COB_INVALID, p->cob_id, COB_NO_RTR) != 0u
               ? URRT_CO_E_RPDO
               : 0;
}

/* 0x1016 sub n's value, n from 1: bits 24..31 reserved, node ids 0..127,
 * no node id twice with a time (0 in either: the entry is off). */
static bool consumer_on(uint32_t value)
{
    return (value >> 16 & 0xFFu) != 0u && (value & 0xFFFFu) != 0u;
}

static bool consumer_value_ok(uint32_t value)
{
    return (value >> 24) == 0u && (value >> 16 & 0xFFu) <= MAX_NODE_ID;
}

/* Two entries that watch one node (CiA 301 refuses it: 0x06040043). */
static bool consumer_twice(uint32_t a, uint32_t b)
{
    return consumer_on(a) && consumer_on(b) && (a ^ b) >> 16 == 0u;
}

static int check_rx(const urrt_co_desc *d, size_t *bad)
{
    int rc = 0;
    size_t i;
    *bad = NONE;
    if (d->rpdo_count > URRT_CO_MAX_RPDOS) {
        return URRT_CO_E_RPDO;
    }
    for (i = 0; rc == 0 && i < d->rpdo_count; i++) {
        *bad = i;
        rc = check_rpdo(d, i);
    }
    if (rc != 0) {
        return rc;
    }
    *bad = NONE;
    if (d->consumer_count > URRT_CO_MAX_CONSUMERS || (d->rpdo_count > 0u && d->consumer_count == 0u)) {
        return URRT_CO_E_CONSUMER;
    }
    for (i = 0; d->consumers != NULL && i < d->consumer_count; i++) {
        size_t j;
        *bad = i;
        if (!consumer_value_ok(d->consumers[i])) {
            return URRT_CO_E_CONSUMER;
        }
        for (j = 0; j < i; j++) {
            if (consumer_twice(d->consumers[i], d->consumers[j])) {
                return URRT_CO_E_CONSUMER;
            }
        }
    }
    return 0;
}

static bool rx_storage_missing(const urrt_co_desc *d, const urrt_co_rx_storage *rx)
{
    return (d->rpdo_count > 0u && (d->rpdos == NULL || rx == NULL || rx->rpdos == NULL)) ||
           (d->consumer_count > 0u && (rx == NULL || rx->consumers == NULL));
}

/* The id an RPDO's COB-ID or a 0x1016 entry makes the node receive, or NONE. */
static uint32_t rpdo_rx_id(uint32_t cob_id)
{
    return urrt_co_cob_valid(cob_id) ? cob_id & ID_MASK : UINT32_MAX;
}

static uint32_t consumer_rx_id(uint32_t value)
{
    return consumer_on(value) ? NMT_EC_BASE + (value >> 16 & 0xFFu) : UINT32_MAX;
}

/* ---- RPDOs and the consumer heartbeat ---------------------------------------------------- */

uint32_t urrt_co_rpdo_cob_default(const urrt_co *co, size_t n)
{
    return rpdo_cob(co->desc, n);
}

/* RPDO n starts over: nothing received, kept or wrong (a new COB-ID, a reset). */
static void rpdo_forget(urrt_co_rpdo_state *t)
{
    t->pending = false;
    t->received = false;
    t->armed = false;
    t->late = false;
    t->short_seen = false;
}

/* 0x1400+n and 0x1016 to their defaults; at a reset (boot), a change of the
 * ids received is one of rx_changes (urrt_co_init_rx sets them first); reset
 * node (whole_node) also forgets when the variables were written. */
static void rx_defaults(urrt_co *co, bool boot, bool whole_node)
{
    const urrt_co_desc *d = co->desc;
    bool changed = false;
    size_t i;
    for (i = 0; whole_node && co->written_us != NULL && i < co->var_count; i++) {
        co->written_us[i] = URRT_CANTX_NEVER;
    }
    for (i = 0; i < d->rpdo_count; i++) {
        urrt_co_rpdo_state *t = &co->rpdos[i];
        uint32_t cob = rpdo_cob(d, i);
        changed = changed || (boot && rpdo_rx_id(t->cob_id) != rpdo_rx_id(cob));
        t->cob_id = cob;
        t->type = d->rpdos[i].transmission_type;
        t->event_ms = d->rpdos[i].event_ms;
        rpdo_forget(t);
    }
    for (i = 0; i < d->consumer_count; i++) {
        urrt_co_consumer *c = &co->consumers[i];
        uint32_t value = d->consumers != NULL ? d->consumers[i] : 0u;
        changed = changed || (boot && consumer_rx_id(c->value) != consumer_rx_id(value));
        c->value = value;
        c->producer_state = 0;
        c->started = false;
        c->lost = false;
    }
    co->rx_changes += changed ? 1u : 0u;
}

static uint64_t rpdo_due(const urrt_co_rpdo_state *t)
{
    return t->received_us + (uint64_t)t->event_ms * 1000u;
}

/* Whether RPDO n's deadline is watched now: a late one raises its EMCY. */
static bool rpdo_watched(const urrt_co *co, const urrt_co_rpdo_state *t)
{
    return co->state == (uint8_t)URRT_CO_OPERATIONAL && urrt_co_cob_valid(t->cob_id) && t->event_ms != 0u && t->armed &&
           !t->late;
}

static uint64_t consumer_due(const urrt_co_consumer *c)
{
    return c->seen_us + (uint64_t)(c->value & 0xFFFFu) * 1000u;
}

static bool consumer_watched(const urrt_co *co, const urrt_co_consumer *c)
{
    return (co->state == (uint8_t)URRT_CO_PRE_OPERATIONAL || co->state == (uint8_t)URRT_CO_OPERATIONAL) &&
           consumer_on(c->value) && c->started && !c->lost;
}

/* The receiving side's conditions at now_us (a deadline passed latches). */
static uint32_t rx_conditions(urrt_co *co, uint64_t now_us)
{
    uint32_t found = 0;
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        urrt_co_rpdo_state *t = &co->rpdos[i];
        t->late = t->late || (rpdo_watched(co, t) && now_us > rpdo_due(t));
        found |= (uint32_t)t->short_seen << (COND_LENGTH + i) | (uint32_t)t->late << (COND_TIMEOUT + i);
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        urrt_co_consumer *c = &co->consumers[i];
        c->lost = c->lost || (consumer_watched(co, c) && now_us > consumer_due(c));
        found |= (uint32_t)c->lost << (COND_HEARTBEAT + i);
    }
    return found;
}

/* After a frame or a write changed them: the EMCY follows from urrt_co_run. */
static uint32_t rx_emcy(unsigned i);

/* urrt_co.c's conditions_commit for the receiving side's bits: each that
 * started goes into 0x1003 (newest first), as urrt_co.c's history_push,
 * which stays static there so that a node without RPDOs keeps it inline. */
static void rx_refresh(urrt_co *co, uint64_t now_us)
{
    uint32_t active = rx_conditions(co, now_us);
    uint32_t started = active & ~co->active;
    unsigned i, k;
    for (i = URRT_CO_CONDITIONS; i < URRT_CO_COND_ALL; i++) {
        if ((started >> i & 1u) == 0u) {
            continue;
        }
        for (k = URRT_CO_HISTORY - 1u; k > 0u; k--) {
            co->errors[k] = co->errors[k - 1u];
        }
        co->errors[0] = rx_emcy(i) & 0xFFFFu;
        co->error_count = (uint8_t)(co->error_count < URRT_CO_HISTORY ? co->error_count + 1u : URRT_CO_HISTORY);
    }
    co->active = (co->active & BASE_CONDITIONS) | active;
}

/* When a deadline of the receiving side passes. */
static uint64_t rx_deadline(const urrt_co *co)
{
    uint64_t next = URRT_CANTX_NEVER;
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        next = rpdo_watched(co, &co->rpdos[i]) ? urrt_co_min64(next, rpdo_due(&co->rpdos[i]) + 1u) : next;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        next = consumer_watched(co, &co->consumers[i]) ? urrt_co_min64(next, consumer_due(&co->consumers[i]) + 1u) : next;
    }
    return next;
}

urrt_co_rx_status urrt_co_rpdo_status(const urrt_co *co, size_t n, uint64_t now_us)
{
    const urrt_co_rpdo_state *t;
    size_t i;
    if (co == NULL || co->desc == NULL || n >= co->desc->rpdo_count) {
        return URRT_CO_RPDO_NONE;
    }
    t = &co->rpdos[n];
    if (co->state != (uint8_t)URRT_CO_OPERATIONAL) {
        return URRT_CO_RPDO_NOT_OPERATIONAL;
    }
    if (!urrt_co_cob_valid(t->cob_id)) {
        return URRT_CO_RPDO_NOT_VALID;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        const urrt_co_consumer *c = &co->consumers[i];
        if (c->lost || (consumer_watched(co, c) && now_us > consumer_due(c))) {
            return URRT_CO_RPDO_HEARTBEAT_LOST;
        }
    }
    if (!t->received) {
        return URRT_CO_RPDO_NO_DATA;
    }
    return t->event_ms != 0u && now_us > rpdo_due(t) ? URRT_CO_RPDO_DEADLINE : URRT_CO_RPDO_FRESH;
}

/* RPDO n's data into the variables it maps: each value in its object's
 * range stored, each outside refused (not stored, counted). */
static void rpdo_act(urrt_co *co, size_t n, const uint8_t *data, uint64_t now_us)
{
    const urrt_co_desc *d = co->desc;
    const urrt_co_rpdo *p = &d->rpdos[n];
    uint32_t at = 0;
    bool wrote = false;
    size_t i;
    for (i = 0; i < p->mapping_count; i++) {
        uint32_t bytes = (p->mapping[i] & 0xFFu) / 8u;
        if (!dummy_entry(p->mapping[i])) {
            const urrt_co_object *o = &d->objects[object_of(d, p->mapping[i])]; /* urrt_co_init saw it */
            uint32_t value = 0;
            uint32_t k;
            for (k = 0; k < bytes; k++) {
                value |= (uint32_t)data[at + k] << (8u * k);
            }
            if (urrt_co_range_check(value, o->type, o->min, o->max) != 0u) {
                co->values_refused++;
            } else {
                urrt_co_var_store(co, o->item, value, now_us);
                wrote = true;
            }
        }
        at += bytes;
    }
    co->var_writes += wrote ? 1u : 0u;
}

/* RPDO n in OPERATIONAL: too short, not processed; else acted on now
 * (254, 255) or kept for the next SYNC (0..240). */
static void rpdo_received(urrt_co *co, size_t n, const uint8_t *data, size_t len, uint64_t now_us)
{
    urrt_co_rpdo_state *t = &co->rpdos[n];
    size_t i;
    t->short_seen = len < rpdo_bytes(&co->desc->rpdos[n]);
    if (!t->short_seen) {
        t->received_us = now_us;
        t->received = true;
        t->armed = true;
        t->late = false;
        if (t->type <= SYNC_MAX_N) {
            for (i = 0; i < len; i++) {
                t->data[i] = data[i];
            }
            t->pending = true;
        } else {
            rpdo_act(co, n, data, now_us);
        }
    }
    rx_refresh(co, now_us);
}

/* A heartbeat of a 0x1016 producer: monitoring starts (a boot-up, state 0, starts it over). */
static void consumer_heard(urrt_co *co, uint32_t id, uint8_t state, uint64_t now_us)
{
    bool heard = false;
    size_t i;
    for (i = 0; i < co->desc->consumer_count; i++) {
        urrt_co_consumer *c = &co->consumers[i];
        if (consumer_rx_id(c->value) != id) {
            continue;
        }
        heard = true;
        c->producer_state = state;
        c->seen_us = now_us;
        c->started = state != (uint8_t)URRT_CO_INITIALISING;
        c->lost = c->lost && !c->started;
    }
    if (heard) {
        rx_refresh(co, now_us);
    }
}

/* Frames of the receiving side: RPDOs (in OPERATIONAL), heartbeats (1 byte). */
static void rx_frame(urrt_co *co, uint32_t id, const uint8_t *data, size_t len, uint64_t now_us)
{
    size_t n;
    if (id > NMT_EC_BASE && len == 1u) {
        consumer_heard(co, id, data[0], now_us);
        return;
    }
    for (n = 0; co->state == (uint8_t)URRT_CO_OPERATIONAL && n < co->desc->rpdo_count; n++) {
        if (rpdo_rx_id(co->rpdos[n].cob_id) == id) {
            rpdo_received(co, n, data, len, now_us);
            return;
        }
    }
}

/* At a SYNC in OPERATIONAL: the synchronous RPDOs kept since the last. */
static void rpdo_sync(urrt_co *co, uint64_t now_us)
{
    size_t n;
    for (n = 0; n < co->desc->rpdo_count; n++) {
        if (co->rpdos[n].pending) {
            co->rpdos[n].pending = false;
            rpdo_act(co, n, co->rpdos[n].data, now_us);
        }
    }
}

/* An NMT state entered: RPDOs are watched from their first in OPERATIONAL,
 * heartbeats from their first after STOPPED. */
static void rx_nmt(urrt_co *co, urrt_co_nmt state)
{
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        urrt_co_rpdo_state *t = &co->rpdos[i];
        bool again = state == URRT_CO_OPERATIONAL && co->state != (uint8_t)URRT_CO_OPERATIONAL;
        t->pending = t->pending && state == URRT_CO_OPERATIONAL;
        t->received = t->received && !again;
        t->armed = t->armed && !again;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        co->consumers[i].started = co->consumers[i].started && state != URRT_CO_STOPPED;
    }
}

/* No two valid RPDOs on one id. */
static bool rpdo_id_taken(const urrt_co *co, size_t n, uint32_t id)
{
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        if (i != n && rpdo_rx_id(co->rpdos[i].cob_id) == id) {
            return true;
        }
    }
    return false;
}

/* 0x1400+n sub 1, 2, 5 (urrt_co_comm_table): as a TPDO's, the COB-ID's id
 * changes only while or into invalid; a new id or validity starts the RPDO
 * over (its conditions end), a new event timer its monitoring. */
static uint32_t rpdo_write(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    urrt_co_rpdo_state *t = &co->rpdos[n];
    switch (sub) {
    case 1:
        if (urrt_co_cob_check(t->cob_id, value, COB_NO_RTR) != 0u || (urrt_co_cob_valid(value) && rpdo_id_taken(co, n, value & ID_MASK))) {
            return URRT_CO_ABORT_VALUE;
        }
        if (rpdo_rx_id(t->cob_id) != rpdo_rx_id(value)) {
            co->rx_changes++;
            rpdo_forget(t);
        }
        t->cob_id = value;
        break;
    case 2:
        if (value > SYNC_MAX_N && value < TYPE_EVENT_MFR) {
            return URRT_CO_ABORT_TOO_HIGH; /* reserved */
        }
        t->type = (uint8_t)value;
        t->pending = false;
        break;
    default:
        t->event_ms = (uint16_t)value;
        t->armed = false;
        t->late = false;
        break;
    }
    rx_refresh(co, now_us);
    return 0;
}

/* 0x1016 sub 1..: node ids up to 127, bits 24..31 0, no node twice;
 * monitoring starts again with the producer's next heartbeat. */
static uint32_t consumer_write(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    urrt_co_consumer *c = &co->consumers[sub - 1u];
    size_t i;
    (void)n;
    if (!consumer_value_ok(value)) {
        return URRT_CO_ABORT_VALUE;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        if (i != sub - 1u && consumer_twice(co->consumers[i].value, value)) {
            return URRT_CO_ABORT_INCOMPATIBLE;
        }
    }
    co->rx_changes += consumer_rx_id(c->value) != consumer_rx_id(value) ? 1u : 0u;
    c->value = value;
    c->started = false;
    c->lost = false;
    rx_refresh(co, now_us);
    return 0;
}

/* 0x1600+n: the description's mapping, read-only. */
static uint32_t read_rpdo_map(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    const urrt_co_rpdo *p = &co->desc->rpdos[n];
    if (sub == 0u) {
        return urrt_co_value_of(v, p->mapping_count);
    }
    return sub > p->mapping_count ? URRT_CO_ABORT_NO_SUB : urrt_co_value_of(v, p->mapping[sub - 1u]);
}

/* 0x1016 sub 1..: the description's count of them. */
static uint32_t read_consumer(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    (void)n;
    return sub > co->desc->consumer_count ? URRT_CO_ABORT_NO_SUB : urrt_co_value_of(v, co->consumers[sub - 1u].value);
}

/* The ids after NMT, SYNC and SDO: the valid RPDOs', the watched producers'. */
static size_t rx_ids(const urrt_co *co, uint32_t *ids)
{
    size_t count = 0;
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        ids[count] = rpdo_rx_id(co->rpdos[i].cob_id);
        count += ids[count] != UINT32_MAX;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        ids[count] = consumer_rx_id(co->consumers[i].value);
        count += ids[count] != UINT32_MAX;
    }
    return count;
}

/* Condition i of the receiving side: its EMCY code, and byte 5 (the 0x1016
 * sub-index or the RPDO number) in bits 16..23. */
static uint32_t rx_emcy(unsigned i)
{
    if (i < COND_LENGTH) {
        return URRT_CO_EMCY_HEARTBEAT | (uint32_t)(i - COND_HEARTBEAT + 1u) << 16;
    }
    return i < COND_TIMEOUT ? URRT_CO_EMCY_PDO_LENGTH | (uint32_t)(i - COND_LENGTH + 1u) << 16
                            : URRT_CO_EMCY_RPDO_TIMEOUT | (uint32_t)(i - COND_TIMEOUT + 1u) << 16;
}

static void rx_bind(urrt_co *co, const urrt_co_rx_storage *rx, size_t var_count)
{
    co->rpdos = co->desc->rpdo_count > 0u ? rx->rpdos : NULL;
    co->consumers = co->desc->consumer_count > 0u ? rx->consumers : NULL;
    co->written_us = rx != NULL ? rx->written_us : NULL;
    co->var_count = var_count;
    rx_defaults(co, false, false);
}

static const struct urrt_co_rx_ops rx_ops = {
    rx_storage_missing, check_rx, rx_bind, rx_defaults, rx_nmt, rx_frame, rpdo_sync, rx_conditions, rx_emcy, rx_deadline,
    rx_ids, read_rpdo_map, read_consumer, rpdo_write, consumer_write,
};

int urrt_co_init_rx(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                    uint32_t *vars, size_t var_count, const urrt_co_rx_storage *rx, size_t *bad_item)
{
    return urrt_co_init_with(co, desc, tx, tpdo_states, vars, var_count, &rx_ops, rx, bad_item);
}
