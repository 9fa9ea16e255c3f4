/* SPDX-License-Identifier: MIT */
/* urrt_co_rx: the CANopen node's receiving side, RPDOs 1..4 and the consumer
 * heartbeat 0x1016 (see urrt_co.h, "RPDOs", and docs/canopen.md). A unit of
 * its own, as urrt_rtde_in.c is for RTDE: urrt_co.c calls it only through
 * the table urrt_co_init_rx installs (urrt_co_internal.h), so a node set up
 * with urrt_co_init links none of this file: its error texts, its
 * conditions (their EMCYs, their entries in 0x1003) and its rows of the
 * communication objects are here. Freestanding C99. */
#include "urrt_co.h"

#include <stdint.h>

#include "urrt_co_internal.h"

#define type_size urrt_co_type_size
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
/* Its conditions: bit i of urrt_co_rx_storage.active, in the order of their EMCYs. */
#define COND_HEARTBEAT 0u                                      /* + 0x1016 entry */
#define COND_LENGTH (COND_HEARTBEAT + URRT_CO_MAX_CONSUMERS)   /* + RPDO */
#define COND_TIMEOUT (COND_LENGTH + URRT_CO_MAX_RPDOS)         /* + RPDO */

const char *urrt_co_rx_strerror(int result)
{
    switch (result) {
    case URRT_CO_E_STORAGE: return "the CANopen node lacks its urrt_cantx, TPDO states, variables or RPDO storage";
    case URRT_CO_E_RPDO: return "an RPDO's transmission type, mapping or COB-ID is not usable";
    case URRT_CO_E_CONSUMER: return "a consumer heartbeat (0x1016) entry is not usable, or RPDOs have none";
    default: return urrt_co_strerror(result);
    }
}

/* ---- small helpers ------------------------------------------------------------ */

static uint64_t min64(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

static bool cob_valid(uint32_t cob)
{
    return (cob & URRT_CO_COB_INVALID) == 0u;
}

/* A number: its size is its row's type's (urrt_co.c's row_read). */
static uint32_t value_of(urrt_co_value *v, uint32_t value)
{
    v->value = value;
    v->text = NULL;
    return 0;
}

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
        return (entry >> 8 & 0xFFu) == 0u && bits == 8u * type_size((uint8_t)(entry >> 16));
    }
    return i != NONE && d->objects[i].kind == URRT_CO_VAR && (d->objects[i].access & URRT_CO_WO) != 0u &&
           d->objects[i].type != URRT_CO_REAL32 && bits == 8u * type_size(d->objects[i].type);
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
    for (i = 0; cob_valid(rpdo_cob(d, n)) && i < n; i++) {
        if (cob_valid(rpdo_cob(d, i)) && ((rpdo_cob(d, i) ^ rpdo_cob(d, n)) & ID_MASK) == 0u) {
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
    return cob_valid(cob_id) ? cob_id & ID_MASK : UINT32_MAX;
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

/* RPDO n's mapping to its objects and its length, once, so that no frame
 * scans the dictionary (urrt_co_init_rx saw every entry name one). Where a
 * mapping takes effect: init, a reset, the RPDO made valid. The mapping is
 * the description's (0x1600+n is read-only), but CiA 301 lets a manager
 * change one only while its RPDO is not valid, so that making the RPDO valid
 * is the one place a writable 0x1600+n would need its mapping resolved again. */
static void rpdo_resolve(const urrt_co_desc *d, size_t n, urrt_co_rpdo_state *t)
{
    const urrt_co_rpdo *p = &d->rpdos[n];
    size_t i;
    for (i = 0; i < URRT_CO_RPDO_MAX_MAPPED; i++) {
        size_t k = i < p->mapping_count && !dummy_entry(p->mapping[i]) ? object_of(d, p->mapping[i]) : NONE;
        t->mapped[i] = (uint16_t)(k < URRT_CO_UNRESOLVED ? k : URRT_CO_UNRESOLVED);
    }
    t->bytes = (uint8_t)rpdo_bytes(p);
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
    urrt_co_rx_storage *rx = co->rx_storage;
    bool changed = false;
    size_t i;
    for (i = 0; whole_node && rx->written_us != NULL && i < rx->var_count; i++) {
        rx->written_us[i] = URRT_CANTX_NEVER;
    }
    for (i = 0; i < d->rpdo_count; i++) {
        urrt_co_rpdo_state *t = &co->rx_storage->rpdos[i];
        uint32_t cob = rpdo_cob(d, i);
        changed = changed || (boot && rpdo_rx_id(t->cob_id) != rpdo_rx_id(cob));
        t->cob_id = cob;
        rpdo_resolve(d, i, t);
        t->type = d->rpdos[i].transmission_type;
        t->event_ms = d->rpdos[i].event_ms;
        rpdo_forget(t);
    }
    for (i = 0; i < d->consumer_count; i++) {
        urrt_co_consumer *c = &co->rx_storage->consumers[i];
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
    return co->state == (uint8_t)URRT_CO_OPERATIONAL && cob_valid(t->cob_id) && t->event_ms != 0u && t->armed &&
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
        urrt_co_rpdo_state *t = &co->rx_storage->rpdos[i];
        t->late = t->late || (rpdo_watched(co, t) && now_us > rpdo_due(t));
        found |= (uint32_t)t->short_seen << (COND_LENGTH + i) | (uint32_t)t->late << (COND_TIMEOUT + i);
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        urrt_co_consumer *c = &co->rx_storage->consumers[i];
        c->lost = c->lost || (consumer_watched(co, c) && now_us > consumer_due(c));
        found |= (uint32_t)c->lost << (COND_HEARTBEAT + i);
    }
    return found;
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

/* The conditions now (after a frame or a write changed them, or at
 * urrt_co_run, after the node's own): each that started goes into 0x1003
 * (newest first), as urrt_co.c's history_push, which stays static there so
 * that a node without RPDOs keeps it inline; urrt_co.active's bit for the
 * error register. Their EMCYs follow from urrt_co_run. */
static void rx_refresh(urrt_co *co, uint64_t now_us)
{
    uint32_t active = rx_conditions(co, now_us);
    uint32_t started = active & ~(uint32_t)co->rx_storage->active;
    unsigned i, k;
    /* Up to the highest condition that started only: most calls (each RPDO
     * received) start none. */
    for (i = 0; i < URRT_CO_RX_CONDITIONS && started >> i != 0u; i++) {
        if ((started >> i & 1u) == 0u) {
            continue;
        }
        for (k = URRT_CO_HISTORY - 1u; k > 0u; k--) {
            co->errors[k] = co->errors[k - 1u];
        }
        co->errors[0] = rx_emcy(i) & 0xFFFFu;
        co->error_count = (uint8_t)(co->error_count < URRT_CO_HISTORY ? co->error_count + 1u : URRT_CO_HISTORY);
    }
    co->rx_storage->active = (uint16_t)active;
    co->active = (uint8_t)((co->active & ~URRT_CO_RX_ACTIVE) | (active != 0u ? URRT_CO_RX_ACTIVE : 0u));
    co->reported = (uint8_t)((co->reported & ~URRT_CO_RX_ACTIVE) | (co->active & URRT_CO_RX_ACTIVE));
}

static bool rx_emcy_may_send(const urrt_co *co)
{
    return (co->state == (uint8_t)URRT_CO_PRE_OPERATIONAL || co->state == (uint8_t)URRT_CO_OPERATIONAL) &&
           co->rx_storage->active != co->rx_storage->reported;
}

/* After the node's own EMCYs (urrt_co_run): one per condition of the
 * receiving side that started or ended since the last, in order, as the
 * inhibit time (0x1015) allows, byte 5 its 0x1016 entry or RPDO. */
static size_t rx_emcy_send(urrt_co *co, urrt_cantx_emit_fn emit, void *ctx, uint64_t now_us)
{
    size_t sent = 0;
    unsigned i;
    if (!rx_emcy_may_send(co)) {
        return 0;
    }
    if (!cob_valid(co->emcy_cob_id)) {
        co->rx_storage->reported = co->rx_storage->active; /* no EMCY object: nothing to tell later */
        return 0;
    }
    for (i = 0; i < URRT_CO_RX_CONDITIONS && now_us >= urrt_co_emcy_due(co); i++) {
        uint32_t bit = UINT32_C(1) << i;
        if (((uint32_t)(co->rx_storage->active ^ co->rx_storage->reported) & bit) == 0u) {
            continue;
        }
        co->rx_storage->reported = (uint16_t)(co->rx_storage->reported ^ bit);
        sent += urrt_co_emcy_send(co, rx_emcy(i), (co->rx_storage->active & bit) != 0u, now_us, emit, ctx);
    }
    return sent;
}

/* When a deadline of the receiving side passes, or its EMCYs may go. */
static uint64_t rx_deadline(const urrt_co *co)
{
    uint64_t next = rx_emcy_may_send(co) ? urrt_co_emcy_due(co) : URRT_CANTX_NEVER;
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        next = rpdo_watched(co, &co->rx_storage->rpdos[i]) ? min64(next, rpdo_due(&co->rx_storage->rpdos[i]) + 1u) : next;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        next = consumer_watched(co, &co->rx_storage->consumers[i]) ? min64(next, consumer_due(&co->rx_storage->consumers[i]) + 1u) : next;
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
    t = &co->rx_storage->rpdos[n];
    if (co->state != (uint8_t)URRT_CO_OPERATIONAL) {
        return URRT_CO_RPDO_NOT_OPERATIONAL;
    }
    if (!cob_valid(t->cob_id)) {
        return URRT_CO_RPDO_NOT_VALID;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        const urrt_co_consumer *c = &co->rx_storage->consumers[i];
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
    const urrt_co_rpdo_state *t = &co->rx_storage->rpdos[n];
    uint64_t *written = co->rx_storage->written_us;
    uint32_t at = 0;
    bool wrote = false;
    size_t i;
    for (i = 0; i < p->mapping_count; i++) {
        uint32_t entry = p->mapping[i];
        uint32_t bytes = (entry & 0xFFu) / 8u; /* 1, 2 or 4, its object's size: urrt_co_init_rx saw it */
        size_t k = t->mapped[i]; /* resolved once (rpdo_resolve) */
        if (k != URRT_CO_UNRESOLVED || !dummy_entry(entry)) {
            /* Past the first 65535 objects: a scan (urrt_co_init_rx saw the object exists). */
            const urrt_co_object *o = &d->objects[k != URRT_CO_UNRESOLVED ? k : object_of(d, entry)];
            const uint8_t *b = data + at;
            uint32_t value = bytes == 1u   ? b[0]
                             : bytes == 2u ? (uint32_t)b[0] | (uint32_t)b[1] << 8
                                           : (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                                                 (uint32_t)b[3] << 24; /* little-endian (CiA 301) */
            bool sign = urrt_co_type_signed(o->type);
            uint32_t key = urrt_co_order_key(value, sign, bytes);
            if (key < urrt_co_order_key(o->min, sign, bytes) || key > urrt_co_order_key(o->max, sign, bytes)) {
                co->values_refused++; /* urrt_co_range_check's refusal, inline */
            } else {
                co->vars[o->item] = value;
                if (written != NULL) {
                    written[o->item] = now_us;
                }
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
    urrt_co_rpdo_state *t = &co->rx_storage->rpdos[n];
    size_t i;
    t->short_seen = len < t->bytes;
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
        urrt_co_consumer *c = &co->rx_storage->consumers[i];
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

/* At a SYNC in OPERATIONAL: the synchronous RPDOs kept since the last. */
static void rpdo_sync(urrt_co *co, uint64_t now_us)
{
    size_t n;
    for (n = 0; n < co->desc->rpdo_count; n++) {
        if (co->rx_storage->rpdos[n].pending) {
            co->rx_storage->rpdos[n].pending = false;
            rpdo_act(co, n, co->rx_storage->rpdos[n].data, now_us);
        }
    }
}

/* Every frame but NMT's, in PRE-OPERATIONAL and OPERATIONAL, before the
 * node's own: a SYNC (0 or 1 byte; only that: no RPDO on its id is acted
 * on) acts on the kept RPDOs in OPERATIONAL, before the node's TPDOs go;
 * then heartbeats (1 byte) and RPDOs (in OPERATIONAL). No SDO request
 * reaches here as anything else: no RPDO or heartbeat may use its id. */
static void rx_frame(urrt_co *co, uint32_t id, const uint8_t *data, size_t len, uint64_t now_us)
{
    size_t n;
    if (id == (co->sync_cob_id & ID_MASK)) {
        if (len <= 1u && co->state == (uint8_t)URRT_CO_OPERATIONAL) {
            rpdo_sync(co, now_us); /* the synchronous RPDOs' values first, as they stand at the SYNC */
        }
        return;
    }
    if (id > NMT_EC_BASE && len == 1u) {
        consumer_heard(co, id, data[0], now_us);
        return;
    }
    for (n = 0; co->state == (uint8_t)URRT_CO_OPERATIONAL && n < co->desc->rpdo_count; n++) {
        if (rpdo_rx_id(co->rx_storage->rpdos[n].cob_id) == id) {
            rpdo_received(co, n, data, len, now_us);
            return;
        }
    }
}

/* An NMT state entered: RPDOs are watched from their first in OPERATIONAL,
 * heartbeats from their first after STOPPED. */
static void rx_nmt(urrt_co *co, urrt_co_nmt state)
{
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        urrt_co_rpdo_state *t = &co->rx_storage->rpdos[i];
        bool again = state == URRT_CO_OPERATIONAL && co->state != (uint8_t)URRT_CO_OPERATIONAL;
        t->pending = t->pending && state == URRT_CO_OPERATIONAL;
        t->received = t->received && !again;
        t->armed = t->armed && !again;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        co->rx_storage->consumers[i].started = co->rx_storage->consumers[i].started && state != URRT_CO_STOPPED;
    }
}

/* No two valid RPDOs on one id. */
static bool rpdo_id_taken(const urrt_co *co, size_t n, uint32_t id)
{
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        if (i != n && rpdo_rx_id(co->rx_storage->rpdos[i].cob_id) == id) {
            return true;
        }
    }
    return false;
}

/* 0x1400+n sub 1, 2, 5 (urrt_co_comm_table): as a TPDO's, the COB-ID's id
 * changes only while or into invalid; a new id or validity starts the RPDO
 * over (its conditions end), a new event timer its monitoring. */
static uint32_t write_rpdo(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    urrt_co_rpdo_state *t = &co->rx_storage->rpdos[n];
    switch (sub) {
    case 1:
        if (urrt_co_cob_check(t->cob_id, value, COB_NO_RTR) != 0u || (cob_valid(value) && rpdo_id_taken(co, n, value & ID_MASK))) {
            return URRT_CO_ABORT_VALUE;
        }
        if (rpdo_rx_id(t->cob_id) != rpdo_rx_id(value)) {
            co->rx_changes++;
            rpdo_forget(t);
        }
        if (!cob_valid(t->cob_id) && cob_valid(value)) {
            rpdo_resolve(co->desc, n, t); /* switched on: where a mapping takes effect */
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
static uint32_t write_consumer(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    urrt_co_consumer *c = &co->rx_storage->consumers[sub - 1u];
    size_t i;
    (void)n;
    if (!consumer_value_ok(value)) {
        return URRT_CO_ABORT_VALUE;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        if (i != sub - 1u && consumer_twice(co->rx_storage->consumers[i].value, value)) {
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
        return value_of(v, p->mapping_count);
    }
    return sub > p->mapping_count ? URRT_CO_ABORT_NO_SUB : value_of(v, p->mapping[sub - 1u]);
}

/* 0x1016 sub 1..: the description's count of them. */
static uint32_t read_consumer(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    (void)n;
    return sub > co->desc->consumer_count ? URRT_CO_ABORT_NO_SUB : value_of(v, co->rx_storage->consumers[sub - 1u].value);
}

/* The ids after NMT, SYNC and SDO: the valid RPDOs', the watched producers'. */
static size_t rx_ids(const urrt_co *co, uint32_t *ids)
{
    size_t count = 0;
    size_t i;
    for (i = 0; i < co->desc->rpdo_count; i++) {
        ids[count] = rpdo_rx_id(co->rx_storage->rpdos[i].cob_id);
        count += ids[count] != UINT32_MAX;
    }
    for (i = 0; i < co->desc->consumer_count; i++) {
        ids[count] = consumer_rx_id(co->rx_storage->consumers[i].value);
        count += ids[count] != UINT32_MAX;
    }
    return count;
}

/* 0x1400+n sub 1, 2, 5. */
static uint32_t read_rpdo(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    const urrt_co_rpdo_state *t = &co->rx_storage->rpdos[n];
    return value_of(v, sub == 1u ? t->cob_id : sub == 2u ? t->type : t->event_ms);
}

/* The receiving side's rows of the communication objects, for the SDO
 * server (urrt_co_internal.h's list; the headers are urrt_co_comm_table's
 * alone: each row of an index knows it as well). */
#define U8 URRT_CO_UNSIGNED8
#define U16 URRT_CO_UNSIGNED16
#define U32 URRT_CO_UNSIGNED32
#define SUB URRT_CO_OBJ_SUB
#define PER_RPDO URRT_CO_PER_RPDO
#define IF_CONSUMERS URRT_CO_IF_CONSUMERS
#define NODE_ID URRT_CO_NODE_ID
#define READ_FN(f) (f)
#define READ_DESC(m) NULL
#define READ_CONST(value) NULL
#define IN_FN 0u
#define IN_DESC URRT_CO_IN_DESC
#define IN_CONST URRT_CO_IN_CONST
#define AT_FN(f, type_) 0u
#define TYPE_BYTES(type_) ((type_) == U32 ? 4u : (type_) == U16 ? 2u : 1u)
#define AT_DESC(m, type_) \
    (offsetof(urrt_co_desc, m) + 0u * sizeof(char[sizeof(((urrt_co_desc *)0)->m) == TYPE_BYTES(type_) ? 1 : -1]))
#define AT_CONST(value, type_) (value)
#define NO_HEAD(index_, object_, flags_, name_)
#define NO_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_)
#define NO_LIMITED(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_, low_, high_)
#define RX_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_)                        \
    {READ_##in_(what_), (write_), (index_), (sub_), (subs_), (object_), (type_), (flags_) | IN_##in_,     \
     AT_##in_(what_, type_)},
static const urrt_co_comm rx_rows[] = {URRT_CO_COMM_LIST(NO_HEAD, NO_ROW, NO_LIMITED, NO_HEAD, RX_ROW)};

/* One of rx_rows' objects on this node: the RPDOs', 0x1016 if it has entries. */
static size_t rx_instances(const urrt_co *co, const urrt_co_comm *row)
{
    return (row->flags & URRT_CO_PER_RPDO) != 0u ? co->desc->rpdo_count : co->desc->consumer_count > 0u ? 1u : 0u;
}

static uint32_t rx_find(const urrt_co *co, uint16_t index, uint8_t sub, const urrt_co_comm **found, size_t *n)
{
    uint32_t abort_code = URRT_CO_ABORT_NO_OBJECT;
    size_t i;
    for (i = 0; i < sizeof rx_rows / sizeof rx_rows[0]; i++) {
        const urrt_co_comm *row = &rx_rows[i];
        if (index < row->index || (size_t)(index - row->index) >= rx_instances(co, row)) {
            continue;
        }
        abort_code = URRT_CO_ABORT_NO_SUB;
        if (sub >= row->sub && sub - row->sub < row->subs) {
            *found = row;
            *n = (size_t)(index - row->index);
            return 0;
        }
    }
    return abort_code;
}

/* An SDO write stored vars[item]: when, for the caller. */
static void rx_written(urrt_co *co, uint16_t item, uint64_t now_us)
{
    if (co->rx_storage->written_us != NULL) {
        co->rx_storage->written_us[item] = now_us;
    }
}

/* Its storage, once every check passed: the defaults, nothing active. */
static void rx_bind(urrt_co *co, size_t var_count)
{
    co->rx_storage->var_count = var_count;
    co->rx_storage->active = 0;
    co->rx_storage->reported = 0;
    rx_defaults(co, false, false);
}

/* A reset: the parameters back, the ids received with them; nothing active. */
static void rx_reset(urrt_co *co, bool whole_node)
{
    co->rx_storage->active = 0;
    co->rx_storage->reported = 0;
    rx_defaults(co, true, whole_node);
}

static const struct urrt_co_rx_ops rx_ops = {
    .check = check_rx,
    .bind = rx_bind,
    .reset = rx_reset,
    .nmt = rx_nmt,
    .frame = rx_frame,
    .conditions = rx_refresh,
    .emcy = rx_emcy_send,
    .deadline = rx_deadline,
    .ids = rx_ids,
    .find = rx_find,
    .written = rx_written,
    .read_consumer = read_consumer,
    .write_consumer = write_consumer,
    .read_rpdo = read_rpdo,
    .write_rpdo = write_rpdo,
    .read_rpdo_map = read_rpdo_map,
};

int urrt_co_init_rx(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                    uint32_t *vars, size_t var_count, urrt_co_rx_storage *rx, size_t *bad_item)
{
    /* Storage the description needs and lacks: urrt_co_init's refusal (URRT_CO_E_STORAGE).
     * Without any (no RPDOs, no 0x1016), the node is urrt_co_init's. */
    bool missing = desc != NULL && rx_storage_missing(desc, rx);
    return urrt_co_init_with(co, desc, tx, tpdo_states, vars, var_count, missing || rx == NULL ? NULL : &rx_ops, rx,
                             bad_item);
}
