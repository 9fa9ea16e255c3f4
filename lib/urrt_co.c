/* SPDX-License-Identifier: MIT */
/* urrt_co: see urrt_co.h and docs/canopen.md. Freestanding C99, like urrt_cantx.c. */
#include "urrt_co.h"

#include <stdint.h>

#include "urrt_co_internal.h"

#define NONE URRT_CO_NONE
#define MAX_NODE_ID URRT_CO_MAX_NODE_ID
#define MAX_TPDOS 512u
#define ID_MASK URRT_CO_ID_MASK
#define COB_NO_RTR URRT_CO_COB_NO_RTR
#define SYNC_DEFAULT 0x080u
#define EMCY_BASE 0x080u
#define SDO_RX_BASE 0x600u
#define SDO_TX_BASE 0x580u
#define NMT_EC_BASE URRT_CO_NMT_EC_BASE
#define MFR_FIRST 0x2000u
#define MFR_LAST 0x5FFFu
#define SYNC_MAX_N URRT_CO_SYNC_MAX_N
#define TYPE_EVENT_MFR URRT_CO_TYPE_EVENT
#define SEG_BYTES 7u                   /* data bytes of an SDO segment */
#define SDO_LEN 8u

/* SDO command bytes (CiA 301 7.2.4.3): the command specifier in bits 7..5. */
#define CS_DOWNLOAD_SEGMENT 0u
#define CS_DOWNLOAD 1u
#define CS_UPLOAD 2u
#define CS_UPLOAD_SEGMENT 3u
#define CS_ABORT 4u
#define SDO_EXPEDITED 0x02u
#define SDO_SIZE_SET 0x01u
#define SDO_TOGGLE 0x10u
#define SDO_LAST 0x01u

/* Conditions: bit i of urrt_co.active, with its EMCY code and error register bits. */
enum { COND_LINK, COND_STALE, COND_OVERRUN, COND_PASSIVE, COND_BUS_OFF };
#define ERR_GENERIC 0x01u
#define ERR_COMMUNICATION 0x10u
#define ERR_MANUFACTURER 0x80u
static const uint16_t condition_codes[URRT_CO_CONDITIONS] = {
    URRT_CO_EMCY_ROBOT_LINK, URRT_CO_EMCY_ROBOT_STALE, URRT_CO_EMCY_CAN_OVERRUN, URRT_CO_EMCY_ERROR_PASSIVE,
    URRT_CO_EMCY_BUS_OFF,
};
#define ROBOT_CONDITIONS ((1u << COND_LINK) | (1u << COND_STALE))

const char *urrt_co_strerror(int result)
{
    switch (result) {
    case URRT_CO_E_NODE_ID: return "the node id is outside 1..127, or nmt_start is unknown";
    case URRT_CO_E_TPDO: return "a TPDO's frame, transmission type, period, mapping or COB-ID is not usable";
    case URRT_CO_E_OBJECT: return "a manufacturer object's index, type, access, source or range is not usable";
    case URRT_CO_E_STORAGE: return "the CANopen node lacks its urrt_cantx, TPDO states or variables";
    default: return urrt_cantx_strerror(result);
    }
}

/* ---- small helpers ------------------------------------------------------------ */

static void put_le(uint8_t *to, uint32_t value, uint32_t bytes)
{
    uint32_t i;
    for (i = 0; i < bytes; i++) {
        to[i] = (uint8_t)(value >> (8u * i));
    }
}

static uint32_t get_le32(const uint8_t *from)
{
    return (uint32_t)from[0] | (uint32_t)from[1] << 8 | (uint32_t)from[2] << 16 | (uint32_t)from[3] << 24;
}

static uint32_t text_len(const char *s)
{
    uint32_t n = 0;
    while (s != NULL && s[n] != '\0' && n < UINT16_MAX) {
        n++;
    }
    return n;
}

static uint32_t type_size(uint8_t type)
{
    switch (type) {
    case URRT_CO_INTEGER8:
    case URRT_CO_UNSIGNED8: return 1;
    case URRT_CO_INTEGER16:
    case URRT_CO_UNSIGNED16: return 2;
    case URRT_CO_INTEGER32:
    case URRT_CO_UNSIGNED32:
    case URRT_CO_REAL32: return 4;
    default: return 0;
    }
}

uint32_t urrt_co_type_size(uint8_t type)
{
    return type_size(type);
}

static bool type_signed(uint8_t type)
{
    return urrt_co_type_signed(type);
}

static uint32_t size_mask(uint32_t bytes)
{
    return bytes >= 4u ? UINT32_MAX : (UINT32_C(1) << (8u * bytes)) - 1u;
}

/* urrt_co_order_key for a value of the type (urrt_co_internal.h). */
static uint32_t order_key(uint32_t raw, uint8_t type)
{
    return urrt_co_order_key(raw, type_signed(type), type_size(type));
}

static uint64_t min64(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

static bool cob_valid(uint32_t cob)
{
    return (cob & URRT_CO_COB_INVALID) == 0u;
}

/* CiA 301's restricted CAN-IDs: NMT, SYNC/EMCY of others, SDO, NMT error
 * control and the LSS range; no PDO, EMCY or SYNC may use them. */
static bool id_restricted(uint32_t id)
{
    return id <= 0x07Fu || (id >= 0x101u && id <= 0x180u) || (id >= 0x581u && id <= 0x5FFu) ||
           (id >= 0x601u && id <= 0x67Fu) || (id >= 0x6E0u && id <= 0x6FFu) || id >= 0x701u;
}

/* A COB-ID with a "not valid" bit 31 (EMCY, TPDO, RPDO): 11-bit ids only, and a
 * valid one not restricted. The id may change in a write that leaves or
 * makes the object invalid (CiA 301; python-canopen's PdoMap.save disables
 * and moves a PDO in one write): only a new id while staying valid is
 * refused, as CANopenNode does. */
uint32_t urrt_co_cob_check(uint32_t old, uint32_t value, uint32_t also_allowed)
{
    if ((value & ~(URRT_CO_COB_INVALID | also_allowed | ID_MASK)) != 0u) {
        return URRT_CO_ABORT_VALUE;
    }
    if (!cob_valid(value)) {
        return 0;
    }
    if (cob_valid(old) && ((old ^ value) & ID_MASK) != 0u) {
        return URRT_CO_ABORT_VALUE;
    }
    return id_restricted(value & ID_MASK) ? URRT_CO_ABORT_VALUE : 0u;
}

/* ---- checks, once --------------------------------------------------------------- */

static bool type_supported(uint8_t type)
{
    return type_size(type) != 0u;
}

static int check_tpdo(const urrt_co_desc *d, const urrt_cantx *tx, size_t n)
{
    const urrt_co_tpdo *p = &d->tpdos[n];
    const urrt_cantx_frame *f;
    uint32_t bits = 0;
    size_t i;
    if (p->frame >= tx->tables->frame_count || p->mapping_count > URRT_CO_MAX_MAPPED ||
        (p->mapping_count > 0u && p->mapping == NULL)) {
        return URRT_CO_E_TPDO;
    }
    for (i = 0; i < n; i++) {
        if (d->tpdos[i].frame == p->frame) {
            return URRT_CO_E_TPDO;
        }
    }
    f = &tx->tables->frames[p->frame];
    for (i = 0; i < p->mapping_count; i++) {
        bits += p->mapping[i] & 0xFFu;
    }
    if ((f->flags & (URRT_CANTX_EXTENDED | URRT_CANTX_FD)) != 0u || bits > 8u * f->len ||
        f->period_us % 1000u != 0u || f->period_us / 1000u > UINT16_MAX) {
        return URRT_CO_E_TPDO;
    }
    if (p->transmission_type == 0u || (p->transmission_type > SYNC_MAX_N && p->transmission_type < TYPE_EVENT_MFR)) {
        return URRT_CO_E_TPDO;
    }
    return p->cob_id != URRT_CO_COB_DEFAULT && urrt_co_cob_check(URRT_CO_COB_INVALID, p->cob_id, COB_NO_RTR) != 0u
               ? URRT_CO_E_TPDO
               : 0;
}

static bool signal_fits(const urrt_co_object *o, const urrt_cantx *tx)
{
    const urrt_cantx_frame *f;
    const urrt_can_signal *sig;
    if (o->frame >= tx->tables->frame_count || o->item >= tx->tables->frames[o->frame].signal_count ||
        o->access != URRT_CO_RO) {
        return false;
    }
    f = &tx->tables->frames[o->frame];
    sig = &f->signals[o->item];
    if ((o->type == URRT_CO_REAL32) != (sig->type == (uint8_t)URRT_CAN_FLOAT32)) {
        return false;
    }
    return sig->length <= 8u * type_size(o->type);
}

static bool var_fits(const urrt_co_object *o, const uint32_t *vars, size_t var_count)
{
    uint32_t def = order_key(o->def, o->type);
    return vars != NULL && o->item < var_count && (o->def & ~size_mask(type_size(o->type))) == 0u &&
           def >= order_key(o->min, o->type) && def <= order_key(o->max, o->type);
}

static int check_object(const urrt_co_desc *d, const urrt_cantx *tx, size_t i, const uint32_t *vars,
                        size_t var_count)
{
    const urrt_co_object *o = &d->objects[i];
    bool ok = o->index >= MFR_FIRST && o->index <= MFR_LAST && type_supported(o->type) && o->access >= URRT_CO_RO &&
              o->access <= URRT_CO_RW;
    size_t j;
    if (ok) {
        ok = o->kind == URRT_CO_SIGNAL ? signal_fits(o, tx) : o->kind == URRT_CO_VAR && var_fits(o, vars, var_count);
    }
    for (j = 0; ok && j < i; j++) {
        const urrt_co_object *e = &d->objects[j];
        ok = e->index != o->index || (e->sub != o->sub && e->sub != 0u && o->sub != 0u);
    }
    return ok ? 0 : URRT_CO_E_OBJECT;
}

static int check_desc(const urrt_co_desc *d, const urrt_cantx *tx, const uint32_t *vars, size_t var_count,
                      size_t *bad)
{
    int rc = 0;
    size_t i;
    if (d->node_id < 1u || d->node_id > MAX_NODE_ID || d->nmt_start > URRT_CO_START_OPERATIONAL) {
        return URRT_CO_E_NODE_ID;
    }
    if (d->tpdo_count > MAX_TPDOS) {
        return URRT_CO_E_TPDO;
    }
    for (i = 0; rc == 0 && i < d->tpdo_count; i++) {
        *bad = i;
        rc = check_tpdo(d, tx, i);
    }
    for (i = 0; rc == 0 && i < d->object_count; i++) {
        *bad = i;
        rc = check_object(d, tx, i, vars, var_count);
    }
    return rc;
}

/* urrt_co_init (ops NULL) and urrt_co_init_with: without ops, a
 * description with RPDOs or 0x1016 entries lacks their storage; with them
 * (urrt_co_init_rx, which saw that rx holds what the description needs),
 * the receiving side checks its part of the description after the node's,
 * and binds its storage. Inline in both, so that urrt_co_init holds none of
 * the receiving side's calls. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline int init_node(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                            uint32_t *vars, size_t var_count, const struct urrt_co_rx_ops *ops,
                            urrt_co_rx_storage *rx, size_t *bad_item)
{
    size_t bad = NONE;
    int rc = 0;
    if (co == NULL || desc == NULL) {
        rc = URRT_E_ARG;
    } else if (tx == NULL || tx->tables == NULL ||
               (desc->tpdo_count > 0u && (tpdo_states == NULL || desc->tpdos == NULL)) ||
               (desc->object_count > 0u && desc->objects == NULL) ||
               (ops == NULL && (desc->rpdo_count > 0u || desc->consumer_count > 0u))) {
        rc = URRT_CO_E_STORAGE;
    } else {
        rc = check_desc(desc, tx, vars, var_count, &bad);
        rc = rc == 0 && ops != NULL ? ops->check(desc, &bad) : rc;
    }
    if (bad_item != NULL) {
        *bad_item = rc == 0 ? NONE : bad;
    }
    if (rc < 0) {
        return rc;
    }
    co->desc = desc;
    co->tx = tx;
    co->tpdos = tpdo_states;
    co->vars = vars;
    co->state = (uint8_t)URRT_CO_INITIALISING;
    co->heartbeat_due_us = URRT_CANTX_NEVER;
    co->sdo_busy = false;
    co->error_passive = false;
    co->sync_cob_id = SYNC_DEFAULT; /* urrt_co_rx_ids holds before urrt_co_start */
    co->rx = ops;
    co->rx_storage = rx;
    co->var_writes = 0;
    co->values_refused = 0;
    if (ops != NULL) {
        ops->bind(co, var_count);
    }
    co->rx_changes = 0;
    return 0;
}

int urrt_co_init(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                 uint32_t *vars, size_t var_count, size_t *bad_item)
{
    return init_node(co, desc, tx, tpdo_states, vars, var_count, NULL, NULL, bad_item);
}

int urrt_co_init_with(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                      uint32_t *vars, size_t var_count, const struct urrt_co_rx_ops *ops, urrt_co_rx_storage *rx,
                      size_t *bad_item)
{
    return init_node(co, desc, tx, tpdo_states, vars, var_count, ops, rx, bad_item);
}

/* The SYNC id becomes id: a change of the received set when it is new. */
static void sync_id_set(urrt_co *co, uint32_t cob_id)
{
    if (((co->sync_cob_id ^ cob_id) & ID_MASK) != 0u) {
        co->rx_changes++;
    }
    co->sync_cob_id = cob_id;
}

size_t urrt_co_rx_ids(const urrt_co *co, uint32_t ids[URRT_CO_RX_IDS_MAX])
{
    if (co == NULL || co->desc == NULL) {
        return 0;
    }
    ids[0] = 0x000u; /* NMT */
    ids[1] = co->sync_cob_id & ID_MASK;
    ids[2] = SDO_RX_BASE + co->desc->node_id;
    return co->rx != NULL ? 3u + co->rx->ids(co, ids + 3) : 3u;
}

/* ---- frames out ------------------------------------------------------------------- */

static uint8_t *frame_begin(urrt_co *co, uint32_t id, uint8_t len)
{
    unsigned i;
    co->out.id = id;
    co->out.extended = false;
    co->out.fd = false;
    co->out.len = len;
    for (i = 0; i < URRT_CAN_CLASSIC_MAX_LEN; i++) {
        co->out.data[i] = 0;
    }
    return co->out.data;
}

static size_t frame_send(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    if (emit != NULL) {
        emit(ctx, &co->out, now_us);
    }
    return 1;
}

/* ---- TPDOs: the node's 0x18xx values onto urrt_cantx --------------------------------- */

static const urrt_co_tpdo *tpdo_desc(const urrt_co *co, size_t n)
{
    return &co->desc->tpdos[n];
}

static bool tpdo_event_driven(const urrt_co_tpdo_state *t)
{
    return t->type >= TYPE_EVENT_MFR;
}

/* Event timer 0 on a frame whose stale policy needs a period (invalid,
 * ignore): urrt_cantx cannot send it per packet, so the node does, on each
 * new robot data (tpdo_events); its own schedule stays closed. */
static bool tpdo_on_packets(const urrt_co *co, size_t n)
{
    const urrt_cantx_frame *f = &co->tx->tables->frames[tpdo_desc(co, n)->frame];
    return co->tpdos[n].event_ms == 0u && f->stale != (uint8_t)URRT_CANTX_STALE_STOP;
}

/* Whether the node may send TPDO n at all now. */
static bool tpdo_live(const urrt_co *co, size_t n)
{
    return co->state == (uint8_t)URRT_CO_OPERATIONAL && cob_valid(co->tpdos[n].cob_id);
}

static void gates_apply(urrt_co *co)
{
    bool operational = co->state == (uint8_t)URRT_CO_OPERATIONAL;
    size_t i;
    for (i = 0; i < co->tx->tables->frame_count; i++) {
        urrt_cantx_gate(co->tx, i, operational);
    }
    for (i = 0; i < co->desc->tpdo_count; i++) {
        const urrt_co_tpdo_state *t = &co->tpdos[i];
        urrt_cantx_gate(co->tx, tpdo_desc(co, i)->frame,
                        tpdo_live(co, i) && tpdo_event_driven(t) && !t->inhibited && !tpdo_on_packets(co, i));
    }
}

/* The event timer (ms) as the frame's period; 0: no timer, the frame goes
 * with each robot packet (by urrt_cantx, or by the node: tpdo_on_packets). */
static void tpdo_event_timer(urrt_co *co, size_t n, uint16_t event_ms, uint64_t now_us)
{
    urrt_co_tpdo_state *t = &co->tpdos[n];
    size_t frame = tpdo_desc(co, n)->frame;
    const urrt_cantx_robot *r = &co->tx->robots[co->tx->tables->frames[frame].robot];
    t->event_ms = event_ms;
    t->packet_us = r->has_data ? r->data_us : URRT_CANTX_NEVER; /* only data that comes from now on counts */
    if (!tpdo_on_packets(co, n)) {
        (void)urrt_cantx_set_period(co->tx, frame, (uint32_t)event_ms * 1000u, now_us);
    }
}

uint32_t urrt_co_tpdo_cob_default(const urrt_co *co, size_t n)
{
    const urrt_co_tpdo *p = tpdo_desc(co, n);
    if (p->cob_id != URRT_CO_COB_DEFAULT) {
        return p->cob_id | COB_NO_RTR;
    }
    return COB_NO_RTR | (n < 4u ? 0x180u + 0x100u * (uint32_t)n + co->desc->node_id : URRT_CO_COB_INVALID);
}

static void tpdo_defaults(urrt_co *co, uint64_t now_us)
{
    size_t n;
    for (n = 0; n < co->desc->tpdo_count; n++) {
        const urrt_co_tpdo *p = tpdo_desc(co, n);
        urrt_co_tpdo_state *t = &co->tpdos[n];
        t->cob_id = urrt_co_tpdo_cob_default(co, n);
        t->type = p->transmission_type;
        t->syncs = 0;
        t->inhibit_100us = p->inhibit_100us;
        t->inhibited = false;
        t->held = false;
        t->sent_seen = (uint32_t)co->tx->frames[p->frame].sent;
        (void)urrt_cantx_set_id(co->tx, p->frame, t->cob_id & ID_MASK);
        /* A 32-bit division, at a reset only; urrt_co_init saw it fits. */
        tpdo_event_timer(co, n, (uint16_t)(co->tx->tables->frames[p->frame].period_us / 1000u), now_us);
    }
}

/* After frames went out: an event-driven TPDO just sent opens its inhibit gap. */
static void tpdo_sent(urrt_co *co, uint64_t now_us)
{
    bool changed = false;
    size_t n;
    for (n = 0; n < co->desc->tpdo_count; n++) {
        urrt_co_tpdo_state *t = &co->tpdos[n];
        uint32_t sent = (uint32_t)co->tx->frames[tpdo_desc(co, n)->frame].sent;
        if (sent != t->sent_seen && t->inhibit_100us != 0u && tpdo_event_driven(t)) {
            t->inhibited = true;
            t->inhibit_end_us = now_us + (uint64_t)t->inhibit_100us * 100u;
            changed = true;
        }
        t->sent_seen = sent;
    }
    if (changed) {
        gates_apply(co);
    }
}

/* Before urrt_cantx_run: what became due for each event-driven TPDO. A
 * send due inside its inhibit gap is held; at the gap's end a held send
 * goes out with the newest data (urrt_cantx_trigger). */
static size_t tpdo_events(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    size_t sent = 0;
    bool reopened = false;
    size_t n;
    for (n = 0; n < co->desc->tpdo_count; n++) {
        urrt_co_tpdo_state *t = &co->tpdos[n];
        size_t frame = tpdo_desc(co, n)->frame;
        const urrt_cantx_frame_state *fs = &co->tx->frames[frame];
        const urrt_cantx_robot *r = &co->tx->robots[co->tx->tables->frames[frame].robot];
        if (!tpdo_event_driven(t)) {
            continue;
        }
        if (tpdo_on_packets(co, n)) {
            t->held = t->held || (r->has_data && r->data_us != t->packet_us);
            t->packet_us = r->has_data ? r->data_us : t->packet_us;
        } else if (t->inhibited && now_us < t->inhibit_end_us) {
            /* urrt_cantx's send, due now: its closed gate lets it pass */
            t->held = t->held || fs->pending || fs->next_due_us <= now_us;
        }
        if (t->inhibited && now_us < t->inhibit_end_us) {
            continue;
        }
        reopened = reopened || t->inhibited;
        t->inhibited = false;
        if (t->held && tpdo_live(co, n)) {
            sent += urrt_cantx_trigger(co->tx, frame, now_us, emit, ctx);
        }
        t->held = false;
    }
    tpdo_sent(co, now_us); /* so that urrt_cantx_run does not send them again at once */
    if (reopened) {
        gates_apply(co);
    }
    return sent;
}

/* When a held send is due: the earliest gap's end. */
static uint64_t tpdo_deadline(const urrt_co *co)
{
    uint64_t next = URRT_CANTX_NEVER;
    size_t n;
    for (n = 0; n < co->desc->tpdo_count; n++) {
        const urrt_co_tpdo_state *t = &co->tpdos[n];
        next = t->held && t->inhibited ? min64(next, t->inhibit_end_us) : next;
    }
    return next;
}

/* No two valid TPDOs on one id. */
static bool tpdo_id_taken(const urrt_co *co, size_t n, uint32_t id)
{
    size_t i;
    for (i = 0; i < co->desc->tpdo_count; i++) {
        if (i != n && cob_valid(co->tpdos[i].cob_id) && (co->tpdos[i].cob_id & ID_MASK) == id) {
            return true;
        }
    }
    return false;
}

/* 0x1800+n sub 1, 2, 3, 5 (urrt_co_comm_table). */
static uint32_t tpdo_write(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    urrt_co_tpdo_state *t = &co->tpdos[n];
    switch (sub) {
    case 1:
        if (urrt_co_cob_check(t->cob_id, value, COB_NO_RTR) != 0u ||
            (cob_valid(value) && tpdo_id_taken(co, n, value & ID_MASK))) {
            return URRT_CO_ABORT_VALUE;
        }
        t->cob_id = value;
        (void)urrt_cantx_set_id(co->tx, tpdo_desc(co, n)->frame, value & ID_MASK);
        break;
    case 2:
        if (value > SYNC_MAX_N && value < TYPE_EVENT_MFR) {
            return URRT_CO_ABORT_TOO_HIGH; /* reserved, or RTR only: not supported */
        }
        t->type = (uint8_t)value;
        t->syncs = 0;
        t->held = false;
        t->inhibited = false;
        break;
    case 3:
        /* CiA 301: the inhibit time changes only while the PDO is not valid. */
        if (cob_valid(t->cob_id)) {
            return URRT_CO_ABORT_VALUE;
        }
        t->inhibit_100us = (uint16_t)value;
        t->inhibited = false;
        t->held = false;
        break;
    default: tpdo_event_timer(co, n, (uint16_t)value, now_us); break;
    }
    gates_apply(co);
    return 0;
}

/* ---- errors: 0x1001, 0x1003, EMCY ----------------------------------------------------- */

uint8_t urrt_co_error_register(const urrt_co *co)
{
    uint8_t reg = 0;
    if (co == NULL || co->active == 0u) {
        return 0;
    }
    reg = (co->active & ROBOT_CONDITIONS) != 0u ? ERR_MANUFACTURER : 0u;
    reg = (uint8_t)(reg | ((co->active & ~ROBOT_CONDITIONS) != 0u ? ERR_COMMUNICATION : 0u));
    return (uint8_t)(reg | ERR_GENERIC);
}

static void history_push(urrt_co *co, uint16_t code)
{
    unsigned i;
    for (i = URRT_CO_HISTORY - 1u; i > 0u; i--) {
        co->errors[i] = co->errors[i - 1u];
    }
    co->errors[0] = code;
    co->error_count = (uint8_t)(co->error_count < URRT_CO_HISTORY ? co->error_count + 1u : URRT_CO_HISTORY);
}

static void errors_reset(urrt_co *co)
{
    co->active = 0;
    co->reported = 0;
    co->error_count = 0;
    co->emcy_sent = false;
    co->seen_dropped = co->tx->link.dropped;
    co->seen_bus_off = co->tx->link.bus_off;
    co->overrun_until_us = 0;
    co->bus_off_until_us = 0;
}

static uint8_t robot_conditions(const urrt_co *co, uint64_t now_us)
{
    uint8_t found = 0;
    size_t i;
    for (i = 0; i < co->tx->tables->robot_count; i++) {
        urrt_cantx_state s = urrt_cantx_robot_state(co->tx, i, now_us, co->desc->stale_after_us);
        found = (uint8_t)(found | (s == URRT_CANTX_DISCONNECTED ? 1u << COND_LINK : 0u) |
                          (s == URRT_CANTX_DATA_STALE ? 1u << COND_STALE : 0u));
    }
    return found;
}

static void conditions_update(urrt_co *co, uint64_t now_us)
{
    const urrt_cantx_link *link = &co->tx->link;
    uint8_t active = robot_conditions(co, now_us);
    uint8_t started;
    unsigned i;
    if (link->dropped != co->seen_dropped) {
        co->seen_dropped = link->dropped;
        co->overrun_until_us = now_us + URRT_CO_EVENT_HOLD_US;
    }
    if (link->bus_off != co->seen_bus_off) {
        co->seen_bus_off = link->bus_off;
        co->bus_off_until_us = now_us + URRT_CO_EVENT_HOLD_US;
    }
    active = (uint8_t)(active | (now_us < co->overrun_until_us ? 1u << COND_OVERRUN : 0u) |
                       (co->error_passive ? 1u << COND_PASSIVE : 0u) |
                       (now_us < co->bus_off_until_us ? 1u << COND_BUS_OFF : 0u));
    started = (uint8_t)(active & ~co->active);
    for (i = 0; i < URRT_CO_CONDITIONS; i++) {
        if (((unsigned)started >> i & 1u) != 0u) {
            history_push(co, condition_codes[i]);
        }
    }
    co->active = active;
    if (co->rx != NULL) {
        co->rx->conditions(co, now_us); /* its own after the node's, and bit URRT_CO_CONDITIONS */
    }
}

static bool emcy_may_send(const urrt_co *co)
{
    return (co->state == (uint8_t)URRT_CO_PRE_OPERATIONAL || co->state == (uint8_t)URRT_CO_OPERATIONAL) &&
           co->active != co->reported;
}

static uint64_t emcy_due(const urrt_co *co)
{
    return co->emcy_sent ? co->emcy_last_us + (uint64_t)co->emcy_inhibit_100us * 100u : 0u;
}

uint64_t urrt_co_emcy_due(const urrt_co *co)
{
    return emcy_due(co);
}

/* One EMCY per condition that started or ended since the last, in order,
 * as the inhibit time (0x1015) allows. A reset EMCY names the code it
 * clears in its manufacturer bytes 3-4. */
static size_t emcy_send(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    size_t sent = 0;
    unsigned i;
    if (!emcy_may_send(co)) {
        return 0;
    }
    if (!cob_valid(co->emcy_cob_id)) {
        co->reported = co->active; /* no EMCY object: nothing to tell later */
        return 0;
    }
    for (i = 0; i < URRT_CO_CONDITIONS && now_us >= emcy_due(co); i++) {
        uint8_t bit = (uint8_t)(1u << i);
        uint8_t *data;
        if (((co->active ^ co->reported) & bit) == 0u) {
            continue;
        }
        data = frame_begin(co, co->emcy_cob_id & ID_MASK, 8);
        if ((co->active & bit) != 0u) {
            put_le(data, condition_codes[i], 2);
        } else {
            put_le(data + 3, condition_codes[i], 2);
        }
        data[2] = urrt_co_error_register(co);
        co->reported ^= bit;
        co->emcy_last_us = now_us;
        co->emcy_sent = true;
        sent += frame_send(co, now_us, emit, ctx);
    }
    return sent;
}

size_t urrt_co_emcy_send(urrt_co *co, uint32_t emcy, bool started, uint64_t now_us, urrt_cantx_emit_fn emit,
                         void *ctx)
{
    uint8_t *data = frame_begin(co, co->emcy_cob_id & ID_MASK, 8);
    put_le(data + (started ? 0u : 3u), emcy, 2);
    data[2] = urrt_co_error_register(co);
    data[5] = (uint8_t)(emcy >> 16);
    co->emcy_last_us = now_us;
    co->emcy_sent = true;
    return frame_send(co, now_us, emit, ctx);
}

void urrt_co_set_error_passive(urrt_co *co, bool passive)
{
    if (co != NULL) {
        co->error_passive = passive;
    }
}

/* ---- NMT ------------------------------------------------------------------------------ */

urrt_co_nmt urrt_co_state(const urrt_co *co)
{
    return co == NULL ? URRT_CO_INITIALISING : (urrt_co_nmt)co->state;
}

const char *urrt_co_state_name(urrt_co_nmt state)
{
    switch (state) {
    case URRT_CO_INITIALISING: return "INITIALISING";
    case URRT_CO_STOPPED: return "STOPPED";
    case URRT_CO_OPERATIONAL: return "OPERATIONAL";
    case URRT_CO_PRE_OPERATIONAL: return "PRE-OPERATIONAL";
    default: return "UNKNOWN";
    }
}

static size_t heartbeat(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    uint64_t period_us = (uint64_t)co->heartbeat_ms * 1000u;
    if (co->heartbeat_due_us == URRT_CANTX_NEVER || now_us < co->heartbeat_due_us) {
        return 0;
    }
    frame_begin(co, NMT_EC_BASE + co->desc->node_id, 1)[0] = co->state;
    /* The cadence holds; after a stall the missed beats are skipped. */
    co->heartbeat_due_us += period_us;
    if (co->heartbeat_due_us <= now_us) {
        co->heartbeat_due_us = now_us + period_us;
    }
    return frame_send(co, now_us, emit, ctx);
}

static void nmt_enter(urrt_co *co, urrt_co_nmt state)
{
    size_t n;
    if (co->rx != NULL) {
        co->rx->nmt(co, state);
    }
    if (state == URRT_CO_OPERATIONAL && co->state != (uint8_t)URRT_CO_OPERATIONAL) {
        for (n = 0; n < co->desc->tpdo_count; n++) {
            co->tpdos[n].syncs = 0;
        }
    }
    if (state == URRT_CO_STOPPED) {
        co->sdo_busy = false; /* no SDO while stopped: the client times out */
    }
    co->state = (uint8_t)state;
    gates_apply(co);
}

/* An NMT command's new state: a heartbeat tells it at once and the cadence
 * restarts from it (as CANopenNode and the common stacks do). */
static size_t nmt_change(urrt_co *co, urrt_co_nmt state, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    if (co->state == (uint8_t)state) {
        return 0;
    }
    nmt_enter(co, state);
    if (co->heartbeat_ms == 0u) {
        return 0;
    }
    co->heartbeat_due_us = now_us;
    return heartbeat(co, now_us, emit, ctx);
}

static void heartbeat_restart(urrt_co *co, uint64_t now_us)
{
    co->heartbeat_due_us = co->heartbeat_ms == 0u ? URRT_CANTX_NEVER : now_us + (uint64_t)co->heartbeat_ms * 1000u;
}

/* Reset communication: 0x1000-0x1FFF to their defaults, then the boot-up.
 * Reset node also resets the application: the variables and urrt_cantx. */
static size_t boot(urrt_co *co, uint64_t now_us, bool whole_node, urrt_cantx_emit_fn emit, void *ctx)
{
    const urrt_co_desc *d = co->desc;
    size_t i;
    if (whole_node) {
        for (i = 0; i < d->object_count; i++) {
            if (d->objects[i].kind == URRT_CO_VAR) {
                co->vars[d->objects[i].item] = d->objects[i].def;
            }
        }
        urrt_cantx_start(co->tx, now_us);
    }
    co->state = (uint8_t)URRT_CO_INITIALISING;
    co->sdo_busy = false;
    co->heartbeat_ms = d->heartbeat_ms;
    sync_id_set(co, SYNC_DEFAULT);
    if (co->rx != NULL) {
        co->rx->reset(co, whole_node);
    }
    co->emcy_cob_id = EMCY_BASE + d->node_id;
    co->emcy_inhibit_100us = 0;
    errors_reset(co);
    tpdo_defaults(co, now_us);
    frame_begin(co, NMT_EC_BASE + d->node_id, 1);
    (void)frame_send(co, now_us, emit, ctx);
    nmt_enter(co, d->nmt_start == URRT_CO_START_OPERATIONAL ? URRT_CO_OPERATIONAL : URRT_CO_PRE_OPERATIONAL);
    heartbeat_restart(co, now_us);
    return 1;
}

size_t urrt_co_start(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    return co == NULL || co->desc == NULL ? 0 : boot(co, now_us, true, emit, ctx);
}

/* [cs, node]: node 0 is every node; unknown commands are ignored. */
static size_t nmt_command(urrt_co *co, const uint8_t *data, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    if (data[1] != 0u && data[1] != co->desc->node_id) {
        return 0;
    }
    switch (data[0]) {
    case URRT_CO_NMT_START: return nmt_change(co, URRT_CO_OPERATIONAL, now_us, emit, ctx);
    case URRT_CO_NMT_STOP: return nmt_change(co, URRT_CO_STOPPED, now_us, emit, ctx);
    case URRT_CO_NMT_PRE_OPERATIONAL: return nmt_change(co, URRT_CO_PRE_OPERATIONAL, now_us, emit, ctx);
    case URRT_CO_NMT_RESET_NODE: return boot(co, now_us, true, emit, ctx);
    case URRT_CO_NMT_RESET_COMM: return boot(co, now_us, false, emit, ctx);
    default: return 0;
    }
}

/* Every nth SYNC, in OPERATIONAL, a valid TPDO of type n goes out. */
static size_t sync_received(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    size_t sent = 0;
    size_t n;
    if (co->state != (uint8_t)URRT_CO_OPERATIONAL) {
        return 0;
    }
    for (n = 0; n < co->desc->tpdo_count; n++) {
        urrt_co_tpdo_state *t = &co->tpdos[n];
        if (t->type > SYNC_MAX_N || ++t->syncs < t->type) {
            continue;
        }
        t->syncs = 0;
        if (cob_valid(t->cob_id)) {
            sent += urrt_cantx_trigger(co->tx, tpdo_desc(co, n)->frame, now_us, emit, ctx);
        }
    }
    return sent;
}

/* ---- the object dictionary: the communication objects ---------------------------------- */

/* A number: its size is its row's type's (urrt_co_comm_read). */
static uint32_t value_of(urrt_co_value *v, uint32_t value)
{
    v->value = value;
    v->text = NULL;
    return 0;
}

static uint32_t text_of(urrt_co_value *v, const char *text)
{
    v->value = 0;
    v->text = text != NULL ? text : "";
    v->size = text_len(text);
    return 0;
}

static uint32_t read_error_register(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    (void)n;
    (void)sub;
    return value_of(v, urrt_co_error_register(co));
}

/* 0x1003 sub 1..: the codes, newest first. */
static uint32_t read_errors(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    (void)n;
    return sub > co->error_count ? URRT_CO_ABORT_NO_DATA : value_of(v, co->errors[sub - 1u]);
}

/* 0x1003 sub 0: only 0 clears the history (CiA 301). */
static uint32_t write_errors(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    (void)n;
    (void)sub;
    (void)now_us;
    if (value != 0u) {
        return URRT_CO_ABORT_VALUE;
    }
    co->error_count = 0;
    return 0;
}

/* SYNC consumer only: bit 30 (generate) and 29-bit ids are refused; bit
 * 31 is CiA 301's "do not care", kept as written. A new id changes the set
 * urrt_co_rx_ids gives. */
static uint32_t write_sync(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    (void)n;
    (void)sub;
    (void)now_us;
    if ((value & ~(URRT_CO_COB_INVALID | ID_MASK)) != 0u || id_restricted(value & ID_MASK)) {
        return URRT_CO_ABORT_VALUE;
    }
    sync_id_set(co, value);
    return 0;
}

static uint32_t write_emcy(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    uint32_t abort_code = urrt_co_cob_check(co->emcy_cob_id, value, 0);
    (void)n;
    (void)sub;
    (void)now_us;
    co->emcy_cob_id = abort_code != 0u ? co->emcy_cob_id : value;
    return abort_code;
}

static uint32_t write_emcy_inhibit(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    (void)n;
    (void)sub;
    (void)now_us;
    co->emcy_inhibit_100us = (uint16_t)value;
    return 0;
}

static uint32_t write_heartbeat(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    (void)n;
    (void)sub;
    co->heartbeat_ms = (uint16_t)value;
    heartbeat_restart(co, now_us);
    return 0;
}

/* 0x1A00+n: the description's mapping, read-only. */
static uint32_t read_tpdo_map(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    const urrt_co_tpdo *p = tpdo_desc(co, n);
    if (sub == 0u) {
        return value_of(v, p->mapping_count);
    }
    return sub > p->mapping_count ? URRT_CO_ABORT_NO_SUB : value_of(v, p->mapping[sub - 1u]);
}

/* The receiving side's rows as urrt_co_comm_table has them: through its
 * functions (urrt_co_internal.h). Instances only with it (the counts are the
 * description's, which urrt_co_init holds at 0 without it), so these are
 * called only with urrt_co.rx set. */
static uint32_t via_read_consumer(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    return co->rx->read_consumer(co, n, sub, v);
}

static uint32_t via_write_consumer(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    return co->rx->write_consumer(co, n, sub, value, now_us);
}

static uint32_t via_read_rpdo(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    return co->rx->read_rpdo(co, n, sub, v);
}

static uint32_t via_write_rpdo(urrt_co *co, size_t n, uint8_t sub, uint32_t value, uint64_t now_us)
{
    return co->rx->write_rpdo(co, n, sub, value, now_us);
}

static uint32_t via_read_rpdo_map(const urrt_co *co, size_t n, uint8_t sub, urrt_co_value *v)
{
    return co->rx->read_rpdo_map(co, n, sub, v);
}

/*
 * The communication objects: URRT_CO_COMM_LIST (urrt_co_internal.h),
 * expanded here four times: into comm_rows, the node's rows, which the SDO
 * server looks requests up in (the receiving side's are urrt_co_rx.c's);
 * into urrt_co_comm_table, every row in index order, for readers of the
 * dictionary (an EDS writer), the receiving side's rows through the via_
 * functions above; into comm_names, which only urrt_co_comm_name reads; and
 * into comm_limits, for the rows with limits. The last three are arrays of
 * their own, so that a firmware that reads no dictionary links none of them
 * (--gc-sections drops them).
 */
#define U8 URRT_CO_UNSIGNED8
#define U16 URRT_CO_UNSIGNED16
#define U32 URRT_CO_UNSIGNED32
#define TEXT URRT_CO_VISIBLE_STRING
#define VAR URRT_CO_OBJ_VAR
#define SUB URRT_CO_OBJ_SUB
#define ARRAY URRT_CO_OBJ_ARRAY
#define RECORD URRT_CO_OBJ_RECORD
#define PER_TPDO URRT_CO_PER_TPDO
#define PER_RPDO URRT_CO_PER_RPDO
#define IF_CONSUMERS URRT_CO_IF_CONSUMERS
#define NODE_ID URRT_CO_NODE_ID

/* A ROW's `in`, `what` as the table's read, flags and at. A member's offset
 * must fit `at` (a uint8_t: -Woverflow) and its size be the type's (a
 * negative array size otherwise), so that read_plain reads it whole. */
#define READ_FN(f) (f)
#define READ_NODE(m) NULL
#define READ_DESC(m) NULL
#define READ_TPDO(m) NULL
#define READ_CONST(value) NULL
#define IN_FN 0u
#define IN_NODE URRT_CO_IN_NODE
#define IN_DESC URRT_CO_IN_DESC
#define IN_TPDO URRT_CO_IN_TPDO
#define IN_CONST URRT_CO_IN_CONST
#define TYPE_BYTES(type_) ((type_) == TEXT ? sizeof(const char *) : (type_) == U32 ? 4u : (type_) == U16 ? 2u : 1u)
#define MEMBER_AT(struct_, m, type_) \
    (offsetof(struct_, m) + 0u * sizeof(char[sizeof(((struct_ *)0)->m) == TYPE_BYTES(type_) ? 1 : -1]))
#define AT_FN(f, type_) 0u
#define AT_NODE(m, type_) MEMBER_AT(urrt_co, m, type_)
#define AT_DESC(m, type_) MEMBER_AT(urrt_co_desc, m, type_)
#define AT_TPDO(m, type_) MEMBER_AT(urrt_co_tpdo_state, m, type_)
#define AT_CONST(value, type_) (value)
/* The receiving side's functions, as urrt_co_comm_table reaches them. */
#define VIA_FN(f) via_##f
#define VIA_DESC(m) NULL
#define VIA_CONST(value) NULL
#define via_NULL NULL

#define NO_HEAD(index_, object_, flags_, name_)
#define NO_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_)
#define NO_LIMITED(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_, low_, high_)
#define TABLE_HEAD(index_, object_, flags_, name_) {NULL, NULL, (index_), 0, 0, (object_), 0, (flags_), 0},
#define TABLE_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_)                     \
    {READ_##in_(what_), (write_), (index_), (sub_), (subs_), (object_), (type_), (flags_) | IN_##in_,     \
     AT_##in_(what_, type_)},
#define TABLE_LIMITED(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_, low_, high_) \
    TABLE_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_)
#define VIA_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_)                       \
    {VIA_##in_(what_), via_##write_, (index_), (sub_), (subs_), (object_), (type_), (flags_) | IN_##in_,  \
     AT_##in_(what_, type_)},

static const urrt_co_comm comm_rows[] = {
    URRT_CO_COMM_LIST(TABLE_HEAD, TABLE_ROW, TABLE_LIMITED, NO_HEAD, NO_ROW)};
#define COMM_ROWS (sizeof comm_rows / sizeof comm_rows[0])

const urrt_co_comm urrt_co_comm_table[] = {
    URRT_CO_COMM_LIST(TABLE_HEAD, TABLE_ROW, TABLE_LIMITED, TABLE_HEAD, VIA_ROW)};
const size_t urrt_co_comm_count = sizeof urrt_co_comm_table / sizeof urrt_co_comm_table[0];

/* The names, each ended by its NUL, in urrt_co_comm_table's order. */
#define NAME_HEAD(index_, object_, flags_, name_) name_ "\0"
#define NAME_ROW(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_) name_ "\0"
#define NAME_LIMITED(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_, low_, high_) name_ "\0"
static const char comm_names[] = URRT_CO_COMM_LIST(NAME_HEAD, NAME_ROW, NAME_LIMITED, NAME_HEAD, NAME_ROW);

const char *urrt_co_comm_name(const urrt_co_comm *row)
{
    const char *name = comm_names;
    size_t i;
    for (i = 0; i < (size_t)(row - urrt_co_comm_table); i++) {
        name += text_len(name) + 1u;
    }
    return name;
}

typedef struct comm_limit {
    uint32_t low, high;
    uint16_t index;
    uint8_t sub;
} comm_limit;
#define LIMITS_OF(index_, sub_, subs_, object_, type_, in_, what_, write_, flags_, name_, low_, high_) \
    {(low_), (high_), (index_), (sub_)},
static const comm_limit comm_limits[] = {URRT_CO_COMM_LIST(NO_HEAD, NO_ROW, LIMITS_OF, NO_HEAD, NO_ROW)};

/* Where in comm_limits a row that holds sub-indices has its limits, or NONE. */
static size_t limits_at(const urrt_co_comm *row)
{
    size_t i;
    for (i = 0; i < sizeof comm_limits / sizeof comm_limits[0]; i++) {
        if (comm_limits[i].index == row->index && comm_limits[i].sub == row->sub && row->subs != 0u) {
            return i;
        }
    }
    return NONE;
}

bool urrt_co_comm_limits(const urrt_co_comm *row, uint32_t *low, uint32_t *high)
{
    size_t i = limits_at(row);
    if (i != NONE) {
        *low = comm_limits[i].low;
        *high = comm_limits[i].high;
    }
    return i != NONE;
}

/* The instances of one of the node's rows (comm_rows). */
static size_t row_instances(const urrt_co *co, const urrt_co_comm *row)
{
    return (row->flags & URRT_CO_PER_TPDO) != 0u ? co->desc->tpdo_count : 1u;
}

size_t urrt_co_comm_instances(const urrt_co *co, const urrt_co_comm *row)
{
    if ((row->flags & URRT_CO_PER_RPDO) != 0u) {
        return co->desc->rpdo_count;
    }
    if ((row->flags & URRT_CO_IF_CONSUMERS) != 0u) {
        return co->desc->consumer_count > 0u ? 1u : 0u;
    }
    return row_instances(co, row);
}

/* A row without a read function: the member `at` bytes into the node, its
 * description or TPDO n's state, read as the row's type; or `at` itself. */
static uint32_t read_plain(const urrt_co *co, const urrt_co_comm *row, size_t n, urrt_co_value *v)
{
    const unsigned char *base;
    switch (row->flags & URRT_CO_IN_MASK) {
    case URRT_CO_IN_NODE: base = (const unsigned char *)co; break;
    case URRT_CO_IN_DESC: base = (const unsigned char *)co->desc; break;
    case URRT_CO_IN_TPDO: base = (const unsigned char *)&co->tpdos[n]; break;
    default: return value_of(v, row->at);
    }
    base += row->at;
    switch (row->type) {
    case TEXT: return text_of(v, *(const char *const *)(const void *)base);
    case U8: return value_of(v, *base);
    case U16: return value_of(v, *(const uint16_t *)(const void *)base);
    default: return value_of(v, *(const uint32_t *)(const void *)base);
    }
}

/* Sub-index `sub` of instance n of a row that has both (the caller saw to it). */
static uint32_t row_read(const urrt_co *co, const urrt_co_comm *row, size_t n, uint8_t sub, urrt_co_value *v)
{
    uint32_t abort_code;
    v->text = NULL;
    abort_code = row->read != NULL ? row->read(co, n, sub, v) : read_plain(co, row, n, v);
    v->size = v->text != NULL ? v->size : type_size(row->type);
    return abort_code;
}

uint32_t urrt_co_comm_read(const urrt_co *co, const urrt_co_comm *row, size_t n, uint8_t sub, urrt_co_value *v)
{
    uint32_t abort_code = URRT_CO_ABORT_NO_SUB; /* a header row holds no sub-index */
    v->text = NULL;
    if (sub >= row->sub && sub - row->sub < row->subs && n < urrt_co_comm_instances(co, row)) {
        abort_code = row_read(co, row, n, sub, v);
    }
    v->text = abort_code == 0u ? v->text : NULL; /* a read that failed leaves no text behind */
    return abort_code;
}

/* What a request names: a row of the table or a manufacturer object. */
typedef struct od_entry {
    urrt_co_value v;
    const urrt_co_comm *row;
    size_t n;                       /* the row's instance */
    const urrt_co_object *object;   /* a manufacturer object */
    uint8_t access;
} od_entry;

/* The row holding (index, sub), the node's or the receiving side's, or
 * NULL with the abort code. */
static uint32_t comm_find(const urrt_co *co, uint16_t index, uint8_t sub, od_entry *e)
{
    bool known = false;
    size_t i;
    for (i = 0; i < COMM_ROWS; i++) {
        const urrt_co_comm *row = &comm_rows[i];
        size_t n = (size_t)(index - row->index);
        if (index < row->index || n >= row_instances(co, row)) {
            continue;
        }
        known = true;
        if (row->subs != 0u && sub >= row->sub && sub - row->sub < row->subs) {
            e->row = row;
            e->n = n;
            break;
        }
    }
    if (e->row == NULL) {
        uint32_t abort_code = known ? URRT_CO_ABORT_NO_SUB : URRT_CO_ABORT_NO_OBJECT;
        if (known || co->rx == NULL || (abort_code = co->rx->find(co, index, sub, &e->row, &e->n)) != 0u) {
            return abort_code;
        }
    }
    e->access = e->row->write != NULL ? URRT_CO_RW : URRT_CO_RO;
    return row_read(co, e->row, e->n, sub, &e->v);
}

/* A signal's raw bits as its frame would go out now, sign-extended for INTEGERn. */
static uint32_t signal_value(urrt_co *co, const urrt_co_object *o, uint64_t now_us)
{
    const urrt_can_signal *sig = &co->tx->tables->frames[o->frame].signals[o->item];
    uint64_t raw = 0;
    uint32_t value;
    urrt_cantx_peek(co->tx, o->frame, now_us, &co->out);
    (void)urrt_can_get_raw(sig, co->out.data, co->out.len, &raw);
    value = (uint32_t)raw; /* urrt_co_init saw the signal fits the type's 32 bits at most */
    if (type_signed(o->type) && sig->length < 32u && (value >> (sig->length - 1u) & 1u) != 0u) {
        value |= UINT32_MAX << sig->length;
    }
    return value & size_mask(type_size(o->type));
}

/* 0x2000-0x5FFF: the description's objects; a record's sub 0 is its highest sub. */
static uint32_t od_mfr(urrt_co *co, uint16_t index, uint8_t sub, uint64_t now_us, od_entry *e)
{
    const urrt_co_desc *d = co->desc;
    bool known = false;
    uint8_t highest = 0;
    size_t i;
    for (i = 0; i < d->object_count; i++) {
        const urrt_co_object *o = &d->objects[i];
        if (o->index != index) {
            continue;
        }
        known = true;
        highest = o->sub > highest ? o->sub : highest;
        if (o->sub == sub) {
            e->object = o;
            e->access = o->access;
            e->v.size = type_size(o->type);
            return value_of(&e->v, o->kind == URRT_CO_VAR ? co->vars[o->item] : signal_value(co, o, now_us));
        }
    }
    if (known && sub == 0u) {
        e->access = URRT_CO_RO;
        e->v.size = 1;
        return value_of(&e->v, highest);
    }
    return known ? URRT_CO_ABORT_NO_SUB : URRT_CO_ABORT_NO_OBJECT;
}

/* The entry and its value: 0, or why it cannot be read (e->access is set
 * whenever the object exists: a NO_DATA read still has an access). */
static uint32_t od_find(urrt_co *co, uint16_t index, uint8_t sub, uint64_t now_us, od_entry *e)
{
    e->row = NULL;
    e->object = NULL;
    e->access = 0;
    if (index >= MFR_FIRST && index <= MFR_LAST) {
        return od_mfr(co, index, sub, now_us, e);
    }
    return comm_find(co, index, sub, e);
}

static bool od_missing(uint32_t abort_code)
{
    return abort_code == URRT_CO_ABORT_NO_OBJECT || abort_code == URRT_CO_ABORT_NO_SUB;
}

/* A value in range of a manufacturer variable, or of a row with limits. */
uint32_t urrt_co_range_check(uint32_t value, uint8_t type, uint32_t low, uint32_t high)
{
    uint32_t key = order_key(value, type);
    if (key < order_key(low, type)) {
        return URRT_CO_ABORT_TOO_LOW;
    }
    return key > order_key(high, type) ? URRT_CO_ABORT_TOO_HIGH : 0u;
}

/* A value outside a row's limits: why; else 0. */
static uint32_t limits_check(const urrt_co_comm *row, uint32_t value)
{
    size_t i = limits_at(row);
    return i != NONE ? urrt_co_range_check(value, row->type, comm_limits[i].low, comm_limits[i].high) : 0u;
}

/* A write the entry's access and size allow: its value's rules. */
static uint32_t od_write(urrt_co *co, uint8_t sub, const od_entry *e, uint32_t value, uint64_t now_us)
{
    const urrt_co_comm *row = e->row;
    uint32_t abort_code;
    if (e->object != NULL) {
        abort_code = urrt_co_range_check(value, e->object->type, e->object->min, e->object->max);
        if (abort_code == 0u) {
            co->vars[e->object->item] = value;
            co->var_writes++;
            if (co->rx != NULL) {
                co->rx->written(co, e->object->item, now_us); /* when, for the caller (written_us) */
            }
        }
        return abort_code;
    }
    abort_code = limits_check(row, value);
    return abort_code != 0u ? abort_code : row->write(co, e->n, sub, value, now_us);
}

/* ---- the SDO server ------------------------------------------------------------------ */

static uint8_t *sdo_begin(urrt_co *co, uint8_t command, uint16_t index, uint8_t sub)
{
    uint8_t *data = frame_begin(co, SDO_TX_BASE + co->desc->node_id, SDO_LEN);
    data[0] = command;
    put_le(data + 1, index, 2);
    data[3] = sub;
    return data;
}

static size_t sdo_abort(urrt_co *co, uint16_t index, uint8_t sub, uint32_t code, uint64_t now_us,
                        urrt_cantx_emit_fn emit, void *ctx)
{
    put_le(sdo_begin(co, CS_ABORT << 5, index, sub) + 4, code, 4);
    co->sdo_busy = false;
    return frame_send(co, now_us, emit, ctx);
}

static uint64_t sdo_timeout_us(const urrt_co *co)
{
    uint16_t ms = co->desc->sdo_timeout_ms;
    return (uint64_t)(ms != 0u ? ms : URRT_CO_SDO_TIMEOUT_MS) * 1000u;
}

/* Up to 4 bytes in the answer itself; a longer (or empty) string segmented.
 * Checked in order: exists, access, then what the value's read says. */
static size_t upload(urrt_co *co, uint16_t index, uint8_t sub, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    od_entry e;
    uint32_t abort_code = od_find(co, index, sub, now_us, &e);
    uint8_t *data;
    uint32_t i;
    if (!od_missing(abort_code) && e.access == URRT_CO_WO) {
        abort_code = URRT_CO_ABORT_WRITE_ONLY;
    }
    if (abort_code != 0u) {
        return sdo_abort(co, index, sub, abort_code, now_us, emit, ctx);
    }
    if (e.v.text != NULL && (e.v.size == 0u || e.v.size > 4u)) {
        data = sdo_begin(co, CS_UPLOAD << 5 | SDO_SIZE_SET, index, sub);
        put_le(data + 4, e.v.size, 4);
        co->sdo_busy = true;
        co->sdo_text = e.v.text;
        co->sdo_size = e.v.size;
        co->sdo_offset = 0;
        co->sdo_toggle = 0;
        co->sdo_index = index;
        co->sdo_sub = sub;
        co->sdo_deadline_us = now_us + sdo_timeout_us(co);
        return frame_send(co, now_us, emit, ctx);
    }
    data = sdo_begin(co, (uint8_t)(CS_UPLOAD << 5 | (4u - e.v.size) << 2 | SDO_EXPEDITED | SDO_SIZE_SET), index,
                     sub);
    for (i = 0; i < e.v.size; i++) {
        data[4 + i] = (uint8_t)(e.v.text != NULL ? (unsigned char)e.v.text[i] : e.v.value >> (8u * i));
    }
    return frame_send(co, now_us, emit, ctx);
}

static size_t upload_segment(urrt_co *co, uint8_t command, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    uint8_t toggle = command & SDO_TOGGLE;
    uint32_t n = co->sdo_size - co->sdo_offset;
    uint8_t *data;
    uint32_t i;
    if (toggle != co->sdo_toggle) {
        return sdo_abort(co, co->sdo_index, co->sdo_sub, URRT_CO_ABORT_TOGGLE, now_us, emit, ctx);
    }
    n = n > SEG_BYTES ? SEG_BYTES : n;
    data = frame_begin(co, SDO_TX_BASE + co->desc->node_id, SDO_LEN);
    for (i = 0; i < n; i++) {
        data[1 + i] = (uint8_t)co->sdo_text[co->sdo_offset + i];
    }
    co->sdo_offset += n;
    co->sdo_busy = co->sdo_offset < co->sdo_size;
    data[0] = (uint8_t)(toggle | (SEG_BYTES - n) << 1 | (co->sdo_busy ? 0u : SDO_LAST));
    co->sdo_toggle ^= SDO_TOGGLE;
    co->sdo_deadline_us = now_us + sdo_timeout_us(co);
    return frame_send(co, now_us, emit, ctx);
}

/* Why a download is refused, checked in one order for every object (CiA
 * 301): exists, access, size, value. A value the object cannot be read at
 * now (0x1003 past the errors recorded) is no reason: it exists. */
static uint32_t download_check(urrt_co *co, const uint8_t *req, uint64_t now_us, od_entry *e)
{
    uint16_t index = (uint16_t)(req[1] | req[2] << 8);
    uint8_t sub = req[3];
    uint32_t bytes = (req[0] & SDO_SIZE_SET) != 0u ? 4u - (uint32_t)(req[0] >> 2 & 3u) : 0u;
    uint32_t abort_code;
    if ((req[0] & SDO_EXPEDITED) == 0u) {
        return URRT_CO_ABORT_COMMAND;
    }
    abort_code = od_find(co, index, sub, now_us, e);
    if (od_missing(abort_code)) {
        return abort_code;
    }
    if ((e->access & URRT_CO_WO) == 0u) {
        return URRT_CO_ABORT_READ_ONLY;
    }
    if (bytes != 0u && bytes != e->v.size) {
        return bytes > e->v.size ? URRT_CO_ABORT_TOO_LONG : URRT_CO_ABORT_TOO_SHORT;
    }
    return od_write(co, sub, e, get_le32(req + 4) & size_mask(e->v.size), now_us);
}

/* Expedited only: a segmented download is an unknown command here. */
static size_t download(urrt_co *co, const uint8_t *req, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    uint16_t index = (uint16_t)(req[1] | req[2] << 8);
    od_entry e;
    uint32_t abort_code = download_check(co, req, now_us, &e);
    if (abort_code != 0u) {
        return sdo_abort(co, index, req[3], abort_code, now_us, emit, ctx);
    }
    (void)sdo_begin(co, 0x60u, index, req[3]);
    return frame_send(co, now_us, emit, ctx);
}

/* One answer per request at most. A request that is not the next segment
 * while an upload is in progress aborts that upload (0x05040001, with its
 * index) and is not served: the client's retry is (as CANopenNode). */
static size_t sdo_request(urrt_co *co, const uint8_t *req, size_t len, uint64_t now_us, urrt_cantx_emit_fn emit,
                          void *ctx)
{
    uint8_t cs = len > 0u ? (uint8_t)(req[0] >> 5) : 0u;
    if (len > 0u && cs == CS_ABORT) {
        co->sdo_busy = false; /* the client's abort is never answered */
        return 0;
    }
    if (co->sdo_busy) {
        if (len == SDO_LEN && cs == CS_UPLOAD_SEGMENT) {
            return upload_segment(co, req[0], now_us, emit, ctx);
        }
        return sdo_abort(co, co->sdo_index, co->sdo_sub, len < SDO_LEN ? URRT_CO_ABORT_LENGTH : URRT_CO_ABORT_COMMAND,
                         now_us, emit, ctx);
    }
    if (len < SDO_LEN) {
        return sdo_abort(co, (uint16_t)(len >= 3u ? (unsigned)req[1] | (unsigned)req[2] << 8 : 0u), len >= 4u ? req[3] : 0u,
                         URRT_CO_ABORT_LENGTH, now_us, emit, ctx);
    }
    switch (cs) {
    case CS_UPLOAD: return upload(co, (uint16_t)(req[1] | req[2] << 8), req[3], now_us, emit, ctx);
    case CS_DOWNLOAD: return download(co, req, now_us, emit, ctx);
    default:
        return sdo_abort(co, (uint16_t)(req[1] | req[2] << 8), req[3], URRT_CO_ABORT_COMMAND, now_us, emit, ctx);
    }
}

/* ---- frames in, time passing ------------------------------------------------------------ */

size_t urrt_co_on_frame(urrt_co *co, uint32_t id, unsigned flags, const uint8_t *data, size_t len, uint64_t now_us,
                        urrt_cantx_emit_fn emit, void *ctx)
{
    uint8_t state;
    if (co == NULL || co->state == (uint8_t)URRT_CO_INITIALISING ||
        (flags & (URRT_CO_RX_EXTENDED | URRT_CO_RX_RTR)) != 0u ||
        len > URRT_CAN_CLASSIC_MAX_LEN || (len > 0u && data == NULL)) {
        return 0;
    }
    state = co->state;
    if (id == 0u) {
        return len == 2u ? nmt_command(co, data, now_us, emit, ctx) : 0u;
    }
    if (state == (uint8_t)URRT_CO_STOPPED) {
        return 0; /* only NMT */
    }
    if (co->rx != NULL) {
        co->rx->frame(co, id, data, len, now_us); /* RPDOs, heartbeats, a SYNC's kept RPDOs: no answer */
    }
    if (id == (co->sync_cob_id & ID_MASK)) {
        return len <= 1u ? sync_received(co, now_us, emit, ctx) : 0u;
    }
    if (id == SDO_RX_BASE + co->desc->node_id) {
        return sdo_request(co, data, len, now_us, emit, ctx);
    }
    return 0;
}

size_t urrt_co_run(urrt_co *co, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    size_t sent;
    if (co == NULL || co->state == (uint8_t)URRT_CO_INITIALISING) {
        return 0;
    }
    sent = heartbeat(co, now_us, emit, ctx);
    if (co->sdo_busy && now_us >= co->sdo_deadline_us) {
        sent += sdo_abort(co, co->sdo_index, co->sdo_sub, URRT_CO_ABORT_TIMEOUT, now_us, emit, ctx);
    }
    conditions_update(co, now_us);
    sent += emcy_send(co, now_us, emit, ctx);
    if (co->rx != NULL) {
        sent += co->rx->emcy(co, emit, ctx, now_us); /* the receiving side's, after the node's */
    }
    sent += tpdo_events(co, now_us, emit, ctx);
    sent += urrt_cantx_run(co->tx, now_us, emit, ctx);
    tpdo_sent(co, now_us);
    return sent;
}

/* When a condition may change without a call: a robot's data turning
 * stale, a counter's hold ending. Only instants after the latest run. */
static uint64_t conditions_deadline(const urrt_co *co)
{
    const urrt_cantx *tx = co->tx;
    uint64_t after = tx->run_us;
    uint64_t next = URRT_CANTX_NEVER;
    size_t i;
    for (i = 0; i < tx->tables->robot_count; i++) {
        const urrt_cantx_robot *r = &tx->robots[i];
        uint64_t stale_us = r->data_us + co->desc->stale_after_us + 1u;
        next = r->has_data && r->up && stale_us > after ? min64(next, stale_us) : next;
    }
    next = tx->start_us + tx->tables->startup_us > after ? min64(next, tx->start_us + tx->tables->startup_us) : next;
    next = co->overrun_until_us > after ? min64(next, co->overrun_until_us) : next;
    return co->bus_off_until_us > after ? min64(next, co->bus_off_until_us) : next;
}

uint64_t urrt_co_deadline(const urrt_co *co)
{
    uint64_t next;
    if (co == NULL || co->state == (uint8_t)URRT_CO_INITIALISING) {
        return URRT_CANTX_NEVER;
    }
    next = min64(urrt_cantx_deadline(co->tx), co->heartbeat_due_us);
    next = co->sdo_busy ? min64(next, co->sdo_deadline_us) : next;
    next = emcy_may_send(co) ? min64(next, emcy_due(co)) : next;
    next = min64(next, tpdo_deadline(co));
    next = co->rx != NULL ? min64(next, co->rx->deadline(co)) : next;
    return min64(next, conditions_deadline(co));
}
