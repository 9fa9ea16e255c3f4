/* SPDX-License-Identifier: MIT */
/* urrt_cantx: see urrt_cantx.h. Freestanding C99, like urrt.c. */
#include "urrt_cantx.h"

#include <stdint.h>

#define NAN_BITS UINT64_C(0x7FF8000000000000)

/* Field by field: a struct assignment may become a memcpy call, which a
 * firmware without a C library cannot link. */
static void link_copy(urrt_cantx_link *to, const urrt_cantx_link *from)
{
    to->bus_off = from->bus_off;
    to->error_frames = from->error_frames;
    to->down_events = from->down_events;
    to->send_errors = from->send_errors;
    to->dropped = from->dropped;
}

static void link_zero(urrt_cantx_link *link)
{
    link->bus_off = 0;
    link->error_frames = 0;
    link->down_events = 0;
    link->send_errors = 0;
    link->dropped = 0;
}

static double nan_value(void)
{
    union {
        uint64_t u;
        double d;
    } b;
    b.u = NAN_BITS;
    return b.d;
}

double urrt_cantx_mask_value(uint64_t mask)
{
    union {
        uint64_t u;
        double d;
    } b;
    b.u = mask;
    return b.d;
}

/* The bits a URRT_CANTX_FILLED_MASK signal carries of the mask in value
 * (urrt_cantx_mask_value's): integer work only, every bit exact. */
static uint64_t mask_raw(const urrt_can_signal *sig, double value)
{
    union {
        uint64_t u;
        double d;
    } b;
    unsigned first = URRT_CAN_SIG_MASK_FIRST(sig->flags);
    uint64_t keep = sig->length >= 64u ? UINT64_MAX : (UINT64_C(1) << sig->length) - 1u;
    b.d = value;
    return first < 64u ? (b.u >> first) & keep : 0u;
}

static bool takes_field(uint8_t kind)
{
    return kind == (uint8_t)URRT_CANTX_FIELD || kind == (uint8_t)URRT_CANTX_FIELD_MASK;
}

const char *urrt_cantx_strerror(int result)
{
    switch (result) {
    case URRT_CANTX_E_SOURCE: return "a signal's source is out of range or of the wrong shape";
    case URRT_CANTX_E_ROBOT: return "a frame's robot index is out of range";
    case URRT_CANTX_E_POLICY: return "a frame's stale policy is unknown or needs what the frame lacks";
    case URRT_CANTX_E_DUPLICATE: return "two frames have the same id";
    case URRT_CANTX_E_STORAGE: return "the values (or scales) array is shorter than the tables' signals";
    default: return urrt_can_strerror(result);
    }
}

/* ---- checks, once ------------------------------------------------------------- */

#define NONE SIZE_MAX

static int check_sources(const urrt_cantx_frame *f, size_t *bad_signal)
{
    unsigned alive = 0;
    unsigned valid = 0;
    size_t i;
    for (i = 0; i < f->signal_count; i++) {
        const urrt_cantx_source *src = &f->sources[i];
        const urrt_can_signal *sig = &f->signals[i];
        bool ok;
        switch ((urrt_cantx_kind)src->kind) {
        case URRT_CANTX_FIELD:
        case URRT_CANTX_FIELD_MASK: {
            /* The kind and the descriptor agree: a mask is never scaled. */
            const urrt_field_info *info = urrt_field((urrt_field_id)src->field);
            bool mask = (sig->flags & URRT_CAN_SIG_BITMASK) != 0u;
            ok = info != NULL && src->elem < info->count && mask == (src->kind == (uint8_t)URRT_CANTX_FIELD_MASK);
            break;
        }
        case URRT_CANTX_ALIVE:
            ok = ++alive == 1u && sig->type == (uint8_t)URRT_CAN_UNSIGNED && sig->length <= 8u;
            break;
        case URRT_CANTX_VALID:
            ok = ++valid == 1u && sig->type == (uint8_t)URRT_CAN_UNSIGNED && sig->length == 1u;
            break;
        case URRT_CANTX_FILLED: ok = f->fill != NULL; break;
        case URRT_CANTX_FILLED_MASK: ok = f->fill != NULL && (sig->flags & URRT_CAN_SIG_BITMASK) != 0u; break;
        default: ok = false; break;
        }
        if (!ok) {
            *bad_signal = i;
            return URRT_CANTX_E_SOURCE;
        }
    }
    return 0;
}

static bool has_kind(const urrt_cantx_frame *f, urrt_cantx_kind kind)
{
    size_t i;
    for (i = 0; i < f->signal_count; i++) {
        if (f->sources[i].kind == (uint8_t)kind) {
            return true;
        }
    }
    return false;
}

static int check_policy(const urrt_cantx_frame *f)
{
    switch ((urrt_cantx_stale)f->stale) {
    case URRT_CANTX_STALE_STOP: return 0;
    case URRT_CANTX_STALE_INVALID:
        /* A frame sent per packet stops with the packets: it has no
         * stale frames to mark. */
        return has_kind(f, URRT_CANTX_VALID) && f->period_us != URRT_CANTX_EVERY_PACKET ? 0 : URRT_CANTX_E_POLICY;
    case URRT_CANTX_STALE_IGNORE: return f->period_us != URRT_CANTX_EVERY_PACKET ? 0 : URRT_CANTX_E_POLICY;
    default: return URRT_CANTX_E_POLICY;
    }
}

static int check_frame(const urrt_cantx_tables *t, size_t index, size_t *bad_signal)
{
    const urrt_cantx_frame *f = &t->frames[index];
    bool extended = (f->flags & URRT_CANTX_EXTENDED) != 0u;
    size_t i;
    size_t second;
    int rc;
    if (!urrt_can_id_valid(f->id, extended)) {
        return URRT_CAN_E_ID;
    }
    if (!urrt_can_length_valid(f->len, (f->flags & URRT_CANTX_FD) != 0u)) {
        return URRT_CAN_E_FRAME_LENGTH;
    }
    if (f->signal_count > 0u && (f->signals == NULL || f->sources == NULL)) {
        return URRT_E_ARG;
    }
    rc = urrt_can_layout_check(f->signals, f->signal_count, f->len, bad_signal, &second);
    if (rc == 0) {
        *bad_signal = NONE;
        rc = check_sources(f, bad_signal);
    }
    if (rc < 0) {
        return rc;
    }
    if (f->robot >= t->robot_count) {
        return URRT_CANTX_E_ROBOT;
    }
    rc = check_policy(f);
    for (i = 0; rc == 0 && i < index; i++) {
        const urrt_cantx_frame *g = &t->frames[i];
        if (g->id == f->id && ((g->flags ^ f->flags) & URRT_CANTX_EXTENDED) == 0u) {
            rc = URRT_CANTX_E_DUPLICATE;
        }
    }
    return rc;
}

size_t urrt_cantx_value_count(const urrt_cantx_tables *tables)
{
    size_t n = 0;
    size_t i;
    for (i = 0; tables != NULL && tables->frames != NULL && i < tables->frame_count; i++) {
        n += tables->frames[i].signal_count;
    }
    return n;
}

/* The frame's fixed parts, and zeros where no signal is. */
static void frame_init(urrt_cantx_frame_state *fs, const urrt_cantx_frame *f, size_t first_value)
{
    size_t i;
    fs->first_value = (uint16_t)first_value;
    fs->fields_end = 0;
    for (i = 0; i < f->signal_count; i++) {
        fs->fields_end = takes_field(f->sources[i].kind) ? (uint16_t)(i + 1u) : fs->fields_end;
    }
    fs->frame.id = f->id;
    fs->period_us = f->period_us;
    fs->closed = false;
    fs->stopped = false; /* until urrt_cantx_start: what urrt_cantx_set_period reads */
    fs->frame.extended = (f->flags & URRT_CANTX_EXTENDED) != 0u;
    fs->frame.fd = (f->flags & URRT_CANTX_FD) != 0u;
    fs->frame.len = f->len;
    for (i = 0; i < URRT_CAN_MAX_LEN; i++) {
        fs->frame.data[i] = 0;
    }
}

int urrt_cantx_init(urrt_cantx *tx, const urrt_cantx_tables *tables, urrt_cantx_frame_state *frame_states,
                    urrt_cantx_robot *robots, double *values, size_t value_count, size_t *bad_frame,
                    size_t *bad_signal)
{
    size_t frame = NONE;
    size_t signal = NONE;
    size_t first = 0;
    int rc = 0;
    size_t i;
    if (tx == NULL || tables == NULL || (tables->frame_count > 0u && (tables->frames == NULL || frame_states == NULL)) ||
        robots == NULL || tables->robot_count == 0u || tables->robot_count > 255u) {
        rc = URRT_E_ARG;
    }
    for (i = 0; rc == 0 && i < tables->frame_count; i++) {
        signal = NONE;
        rc = check_frame(tables, i, &signal);
        frame = i;
    }
    if (rc == 0) {
        size_t needed = urrt_cantx_value_count(tables);
        frame = NONE;
        if (needed > value_count || needed > UINT16_MAX || (value_count > 0u && values == NULL)) {
            rc = URRT_CANTX_E_STORAGE;
        }
    }
    if (bad_frame != NULL) {
        *bad_frame = rc == 0 ? NONE : frame;
    }
    if (bad_signal != NULL) {
        *bad_signal = rc == 0 ? NONE : signal;
    }
    if (rc < 0) {
        return rc;
    }
    tx->tables = tables;
    tx->frames = frame_states;
    tx->robots = robots;
    tx->values = values;
    tx->scales = NULL;
    tx->user = NULL;
    link_zero(&tx->link);
    link_zero(&tx->link_seen);
    tx->clamped = 0;
    tx->clamped_seen = 0;
    for (i = 0; i < tables->frame_count; i++) {
        frame_init(&frame_states[i], &tables->frames[i], first);
        first += tables->frames[i].signal_count;
    }
    tx->wake_us = 0;
    /* Before the first start, no robot has data and no link is up. */
    for (i = 0; i < tables->robot_count; i++) {
        robots[i].has_data = false;
        robots[i].up = false;
    }
    tx->started = false;
    return 0;
}

int urrt_cantx_prepare(urrt_cantx *tx, urrt_can_scale *scales, size_t count)
{
    size_t slot = 0;
    size_t i;
    size_t k;
    if (tx == NULL || tx->tables == NULL || (scales == NULL && count > 0u)) {
        return URRT_E_ARG;
    }
    if (count < urrt_cantx_value_count(tx->tables)) {
        return URRT_CANTX_E_STORAGE;
    }
    for (i = 0; i < tx->tables->frame_count; i++) {
        const urrt_cantx_frame *f = &tx->tables->frames[i];
        for (k = 0; k < f->signal_count; k++) {
            (void)urrt_can_scale_prepare(&f->signals[k], &scales[slot++]); /* init checked them */
        }
    }
    tx->scales = scales;
    return 0;
}

/* ---- values in, payloads out -------------------------------------------------- */

/* Where each field's values start in urrt_state, in doubles: what
 * urrt_field_values gives, without a call for every value of every packet. */
static const uint16_t field_slots[URRT_FIELD_COUNT] = {
#define URRT_X_SLOT(ID, name, count, c1, c3, unit, since, desc) \
    (uint16_t)(offsetof(urrt_state, name) / sizeof(double)),
    URRT_FIELDS(URRT_X_SLOT)
#undef URRT_X_SLOT
};

/* A packet costs these loads only: the values are packed once, when the
 * frame next goes out (or a heartbeat reports clamping); a bit mask is
 * read as one then too (urrt_can's URRT_CAN_SIG_BITMASK). No state: every
 * field NaN. */
static void take_fields(urrt_cantx *tx, size_t index, const urrt_state *st)
{
    const urrt_cantx_source *sources = tx->tables->frames[index].sources;
    urrt_cantx_frame_state *fs = &tx->frames[index];
    double *values = tx->values + fs->first_value;
    const double *slots = (const double *)(const void *)st;
    uint64_t present = st != NULL ? st->present : 0u;
    size_t end = fs->fields_end;
    size_t i;
    for (i = 0; i < end; i++) {
        const urrt_cantx_source src = sources[i];
        if (takes_field(src.kind)) {
            values[i] = ((present >> src.field) & 1u) != 0u ? slots[field_slots[src.field] + src.elem] : nan_value();
        }
    }
    fs->unpacked = true;
}

/* One signal into the frame, with its prepared scale when the caller keeps
 * them (urrt_cantx_prepare): the same bits either way. */
static int pack_signal(const urrt_cantx *tx, size_t slot, const urrt_can_signal *sig, double value, uint8_t *data)
{
    return tx->scales != NULL ? urrt_can_pack_scaled(sig, &tx->scales[slot], value, data)
                              : urrt_can_pack_checked(sig, value, data);
}

/* The fields' bits of the frame; each write replaces the signal's own bits
 * (urrt_cantx_init saw that signals do not overlap). */
static void pack_fields(urrt_cantx *tx, size_t index)
{
    const urrt_cantx_frame *f = &tx->tables->frames[index];
    urrt_cantx_frame_state *fs = &tx->frames[index];
    const double *values = tx->values + fs->first_value;
    int worst = URRT_CAN_PACK_OK;
    size_t i;
    if (!fs->unpacked) {
        return;
    }
    fs->unpacked = false;
    for (i = 0; i < fs->fields_end; i++) {
        uint8_t kind = f->sources[i].kind;
        int outcome;
        if (!takes_field(kind)) {
            continue;
        }
        outcome = pack_signal(tx, fs->first_value + i, &f->signals[i], values[i], fs->frame.data);
        if (outcome != URRT_CAN_PACK_OK) {
            tx->clamped++;
            worst = outcome > worst ? outcome : worst;
        }
    }
    fs->outcome = (int8_t)worst;
}

/* The filled values into the frame: the worst outcome of their packing (a
 * mask's is always OK: its bits go as they are), counted in tx->clamped
 * when the frame is sent. */
static int pack_filled(urrt_cantx *tx, size_t index, uint64_t now_us, bool sending)
{
    const urrt_cantx_frame *f = &tx->tables->frames[index];
    urrt_cantx_frame_state *fs = &tx->frames[index];
    double *values = tx->values + fs->first_value;
    int worst = URRT_CAN_PACK_OK;
    size_t i;
    if (f->fill == NULL) {
        return worst;
    }
    f->fill(tx, index, now_us, sending, values);
    for (i = 0; i < f->signal_count; i++) {
        const urrt_can_signal *sig = &f->signals[i];
        int outcome = URRT_CAN_PACK_OK;
        if (f->sources[i].kind == (uint8_t)URRT_CANTX_FILLED) {
            outcome = pack_signal(tx, fs->first_value + i, sig, values[i], fs->frame.data);
        } else if (f->sources[i].kind == (uint8_t)URRT_CANTX_FILLED_MASK) {
            urrt_can_put_raw_checked(sig, mask_raw(sig, values[i]), fs->frame.data);
        }
        if (outcome != URRT_CAN_PACK_OK) {
            tx->clamped += sending ? 1u : 0u;
            worst = outcome > worst ? outcome : worst;
        }
    }
    return worst;
}

/* The frame as it goes out at now_us, in fs->frame: the packed fields,
 * then the filled values, the alive counter and the validity bit (1: fresh,
 * and every field and filled value packed as it is), also in *valid. */
static const urrt_can_frame *build(urrt_cantx *tx, size_t index, uint64_t now_us, bool fresh, bool sending,
                                   bool *valid)
{
    const urrt_cantx_frame *f = &tx->tables->frames[index];
    urrt_cantx_frame_state *fs = &tx->frames[index];
    size_t i;
    pack_fields(tx, index);
    *valid = pack_filled(tx, index, now_us, sending) == URRT_CAN_PACK_OK && fresh && fs->outcome == URRT_CAN_PACK_OK;
    for (i = 0; i < f->signal_count; i++) {
        const urrt_can_signal *sig = &f->signals[i];
        switch ((urrt_cantx_kind)f->sources[i].kind) {
        case URRT_CANTX_ALIVE: urrt_can_put_raw_checked(sig, fs->alive, fs->frame.data); break;
        case URRT_CANTX_VALID: urrt_can_put_raw_checked(sig, *valid ? 1u : 0u, fs->frame.data); break;
        default: break;
        }
    }
    return &fs->frame;
}

static void send_frame(urrt_cantx *tx, size_t index, uint64_t now_us, bool fresh, urrt_cantx_emit_fn emit, void *ctx)
{
    urrt_cantx_frame_state *fs = &tx->frames[index];
    bool valid;
    const urrt_can_frame *out = build(tx, index, now_us, fresh, true, &valid);
    fs->alive++;
    fs->sent++;
    fs->sent_invalid += valid ? 0u : 1u;
    if (emit != NULL) {
        emit(ctx, out, now_us);
    }
}

/* Field by field, as link_copy. */
static void frame_copy(urrt_can_frame *to, const urrt_can_frame *from)
{
    size_t i;
    to->id = from->id;
    to->extended = from->extended;
    to->fd = from->fd;
    to->len = from->len;
    for (i = 0; i < URRT_CAN_MAX_LEN; i++) {
        to->data[i] = from->data[i];
    }
}

void urrt_cantx_peek(urrt_cantx *tx, size_t frame, uint64_t now_us, urrt_can_frame *out)
{
    const urrt_cantx_frame *f;
    bool valid;
    if (tx == NULL || out == NULL || frame >= tx->tables->frame_count) {
        return;
    }
    f = &tx->tables->frames[frame];
    /* What build writes beyond the packed fields, the next send writes again. */
    frame_copy(out, build(tx, frame, now_us, urrt_cantx_fresh(tx, f->robot, now_us, f->stale_after_us), false,
                          &valid));
}

/* ---- the schedule ------------------------------------------------------------- */

uint64_t urrt_cantx_deadline(const urrt_cantx *tx)
{
    return tx == NULL || !tx->started ? URRT_CANTX_NEVER : tx->wake_us;
}

/* The deadline from the frames: kept in wake_us by whatever moves it
 * (start, a packet, a run), so that a run or a deadline between frames
 * costs a comparison. */
static uint64_t next_wake(const urrt_cantx *tx)
{
    uint64_t next = URRT_CANTX_NEVER;
    size_t i;
    for (i = 0; i < tx->tables->frame_count; i++) {
        const urrt_cantx_frame_state *fs = &tx->frames[i];
        if (fs->pending) {
            return 0; /* now */
        }
        next = fs->next_due_us < next ? fs->next_due_us : next;
    }
    return next;
}

void urrt_cantx_start(urrt_cantx *tx, uint64_t now_us)
{
    const urrt_cantx_tables *t = tx->tables;
    size_t i;
    tx->started = true;
    tx->start_us = now_us;
    tx->run_us = now_us;
    for (i = 0; i < t->robot_count; i++) {
        urrt_cantx_robot *r = &tx->robots[i];
        r->has_data = false;
        r->up = false;
        r->data_us = 0;
        r->robot_mode = nan_value();
        r->safety_mode = nan_value();
        r->generation = (uint8_t)URRT_GEN_UNKNOWN;
    }
    for (i = 0; i < t->frame_count; i++) {
        const urrt_cantx_frame *f = &t->frames[i];
        urrt_cantx_frame_state *fs = &tx->frames[i];
        take_fields(tx, i, NULL);
        pack_fields(tx, i);
        fs->pending = false;
        fs->alive = 0;
        fs->sent = 0;
        fs->sent_invalid = 0;
        fs->stale_stops = 0;
        fs->stopped = f->stale == (uint8_t)URRT_CANTX_STALE_STOP;
        fs->next_due_us = fs->period_us == URRT_CANTX_EVERY_PACKET || fs->stopped ? URRT_CANTX_NEVER : now_us;
    }
    tx->wake_us = next_wake(tx);
    tx->clamped = 0; /* the NaNs above are no packet's values */
    tx->clamped_seen = 0;
    link_zero(&tx->link_seen); /* the first heartbeat reports what came before */
}

void urrt_cantx_robot_link(urrt_cantx *tx, size_t robot, bool up)
{
    if (tx != NULL && robot < tx->tables->robot_count) {
        tx->robots[robot].up = up;
    }
}

void urrt_cantx_set_link(urrt_cantx *tx, const urrt_cantx_link *link)
{
    if (tx != NULL && link != NULL) {
        link_copy(&tx->link, link);
    }
}

void urrt_cantx_on_packet(urrt_cantx *tx, size_t robot, const urrt_state *st, uint64_t data_us)
{
    const urrt_cantx_tables *t;
    urrt_cantx_robot *r;
    size_t i;
    if (tx == NULL || st == NULL || robot >= tx->tables->robot_count) {
        return;
    }
    t = tx->tables;
    if (!tx->started) {
        urrt_cantx_start(tx, data_us);
    }
    r = &tx->robots[robot];
    r->has_data = true;
    r->up = true;
    r->data_us = data_us;
    r->robot_mode = urrt_has(st, URRT_F_ROBOT_MODE) ? st->robot_mode[0] : nan_value();
    r->safety_mode = urrt_has(st, URRT_F_SAFETY_MODE) ? st->safety_mode[0] : nan_value();
    r->generation = (uint8_t)st->generation;
    for (i = 0; i < t->frame_count; i++) {
        urrt_cantx_frame_state *fs = &tx->frames[i];
        if (t->frames[i].robot != robot) {
            continue;
        }
        take_fields(tx, i, st);
        if (fs->period_us == URRT_CANTX_EVERY_PACKET) {
            fs->pending = true;
            tx->wake_us = 0;
        } else if (fs->stopped) {
            /* Fresh data again: resume now, then keep the period. */
            fs->stopped = false;
            fs->next_due_us = data_us;
            tx->wake_us = data_us < tx->wake_us ? data_us : tx->wake_us;
        }
    }
}

bool urrt_cantx_fresh(const urrt_cantx *tx, size_t robot, uint64_t now_us, uint32_t max_age_us)
{
    const urrt_cantx_robot *r;
    if (tx == NULL || robot >= tx->tables->robot_count) {
        return false;
    }
    r = &tx->robots[robot];
    return r->has_data && (now_us < r->data_us || now_us - r->data_us <= max_age_us);
}

/* A frame sent per packet goes out once per packet, while that packet is
 * fresh: one that waited past its bound (the CAN link was down) is dropped. */
static size_t run_every(urrt_cantx *tx, size_t i, uint64_t now_us, bool fresh, urrt_cantx_emit_fn emit, void *ctx)
{
    urrt_cantx_frame_state *fs = &tx->frames[i];
    if (!fs->pending) {
        return 0;
    }
    fs->pending = false;
    if (fs->closed) {
        return 0;
    }
    if (!fresh) {
        fs->stale_stops++;
        return 0;
    }
    send_frame(tx, i, now_us, true, emit, ctx);
    return 1;
}

/* The next slot after one due at or before now_us: keep the cadence; after
 * a stall, skip the missed slots rather than send a burst. */
static void next_slot(urrt_cantx_frame_state *fs, uint64_t now_us)
{
    fs->next_due_us += fs->period_us;
    if (fs->next_due_us <= now_us) {
        fs->next_due_us = now_us + fs->period_us;
    }
}

static size_t run_periodic(urrt_cantx *tx, size_t i, uint64_t now_us, bool fresh, urrt_cantx_emit_fn emit,
                           void *ctx)
{
    const urrt_cantx_frame *f = &tx->tables->frames[i];
    urrt_cantx_frame_state *fs = &tx->frames[i];
    if (fs->next_due_us == URRT_CANTX_NEVER || now_us < fs->next_due_us) {
        return 0;
    }
    if (fs->closed) {
        /* The slot passes unsent, so that the cadence holds when the gate opens. */
        next_slot(fs, now_us);
        return 0;
    }
    if (!fresh && f->stale == (uint8_t)URRT_CANTX_STALE_STOP) {
        fs->stopped = true;
        fs->stale_stops++;
        fs->next_due_us = URRT_CANTX_NEVER;
        return 0;
    }
    send_frame(tx, i, now_us, fresh, emit, ctx);
    next_slot(fs, now_us);
    return 1;
}

size_t urrt_cantx_run(urrt_cantx *tx, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    size_t sent = 0;
    size_t i;
    if (tx == NULL) {
        return 0;
    }
    if (!tx->started) {
        urrt_cantx_start(tx, now_us);
    }
    tx->run_us = now_us;
    if (now_us < tx->wake_us) {
        return 0; /* most packets: no frame is due */
    }
    for (i = 0; i < tx->tables->frame_count; i++) {
        const urrt_cantx_frame *f = &tx->tables->frames[i];
        bool fresh = urrt_cantx_fresh(tx, f->robot, now_us, f->stale_after_us);
        sent += tx->frames[i].period_us == URRT_CANTX_EVERY_PACKET ? run_every(tx, i, now_us, fresh, emit, ctx)
                                                                    : run_periodic(tx, i, now_us, fresh, emit, ctx);
    }
    tx->wake_us = next_wake(tx);
    return sent;
}

size_t urrt_cantx_catch_up(urrt_cantx *tx, uint64_t until_us, urrt_cantx_emit_fn emit, void *ctx)
{
    size_t sent = 0;
    uint64_t due;
    if (tx == NULL || !tx->started) {
        return 0;
    }
    /* Each run moves every frame it sends past `due`, and clears what is
     * pending, so the loop ends. */
    while ((due = urrt_cantx_deadline(tx)) < until_us) {
        sent += urrt_cantx_run(tx, due > tx->run_us ? due : tx->run_us, emit, ctx);
    }
    return sent;
}

/* ---- run-time changes: a CANopen node's PDO parameters ------------------------- */

void urrt_cantx_gate(urrt_cantx *tx, size_t frame, bool open)
{
    if (tx != NULL && frame < tx->tables->frame_count) {
        tx->frames[frame].closed = !open;
    }
}

int urrt_cantx_set_id(urrt_cantx *tx, size_t frame, uint32_t id)
{
    if (tx == NULL || frame >= tx->tables->frame_count) {
        return URRT_E_ARG;
    }
    if (!urrt_can_id_valid(id, tx->frames[frame].frame.extended)) {
        return URRT_CAN_E_ID;
    }
    tx->frames[frame].frame.id = id;
    return 0;
}

int urrt_cantx_set_period(urrt_cantx *tx, size_t frame, uint32_t period_us, uint64_t now_us)
{
    const urrt_cantx_frame *f;
    urrt_cantx_frame_state *fs;
    if (tx == NULL || frame >= tx->tables->frame_count) {
        return URRT_E_ARG;
    }
    f = &tx->tables->frames[frame];
    fs = &tx->frames[frame];
    if (period_us == URRT_CANTX_EVERY_PACKET && f->stale != (uint8_t)URRT_CANTX_STALE_STOP) {
        return URRT_CANTX_E_POLICY; /* as urrt_cantx_init's check_policy */
    }
    fs->period_us = period_us;
    fs->pending = false;
    if (period_us == URRT_CANTX_EVERY_PACKET || fs->stopped) {
        /* A frame sent per packet with the stop policy starts stopped (as
         * urrt_cantx_start leaves it): made periodic, it waits for data. */
        fs->stopped = f->stale == (uint8_t)URRT_CANTX_STALE_STOP;
        fs->next_due_us = URRT_CANTX_NEVER;
    } else {
        fs->next_due_us = now_us;
    }
    if (tx->started) {
        tx->wake_us = next_wake(tx);
    }
    return 0;
}

size_t urrt_cantx_trigger(urrt_cantx *tx, size_t frame, uint64_t now_us, urrt_cantx_emit_fn emit, void *ctx)
{
    const urrt_cantx_frame *f;
    bool fresh;
    if (tx == NULL || frame >= tx->tables->frame_count) {
        return 0;
    }
    if (!tx->started) {
        urrt_cantx_start(tx, now_us);
    }
    f = &tx->tables->frames[frame];
    fresh = urrt_cantx_fresh(tx, f->robot, now_us, f->stale_after_us);
    if (!fresh && f->stale == (uint8_t)URRT_CANTX_STALE_STOP) {
        tx->frames[frame].stale_stops++;
        return 0;
    }
    send_frame(tx, frame, now_us, fresh, emit, ctx);
    return 1;
}

/* ---- the heartbeat ------------------------------------------------------------ */

#define HB_SIG(start_, length_, type_, min_, max_) \
    {1.0, 0.0, (min_), (max_), 0, (start_), (length_), URRT_CAN_INTEL, (type_), 0}

const urrt_can_signal urrt_cantx_heartbeat_signals[URRT_CANTX_HB_COUNT] = {
    [URRT_CANTX_HB_STATE] = HB_SIG(0, 4, URRT_CAN_UNSIGNED, 0, 15),
    [URRT_CANTX_HB_ALIVE] = HB_SIG(4, 4, URRT_CAN_UNSIGNED, 0, 15),
    [URRT_CANTX_HB_ROBOT_MODE] = HB_SIG(8, 8, URRT_CAN_SIGNED, -128, 127),
    [URRT_CANTX_HB_SAFETY_MODE] = HB_SIG(16, 8, URRT_CAN_UNSIGNED, 0, 255),
    [URRT_CANTX_HB_GENERATION] = HB_SIG(24, 2, URRT_CAN_UNSIGNED, 0, 3),
    [URRT_CANTX_HB_BUS_OFF] = HB_SIG(26, 1, URRT_CAN_UNSIGNED, 0, 1),
    [URRT_CANTX_HB_CAN_ERRORS] = HB_SIG(27, 1, URRT_CAN_UNSIGNED, 0, 1),
    [URRT_CANTX_HB_CAN_DOWN] = HB_SIG(28, 1, URRT_CAN_UNSIGNED, 0, 1),
    [URRT_CANTX_HB_SEND_ERRORS] = HB_SIG(29, 1, URRT_CAN_UNSIGNED, 0, 1),
    [URRT_CANTX_HB_TX_DROPPED] = HB_SIG(30, 1, URRT_CAN_UNSIGNED, 0, 1),
    [URRT_CANTX_HB_CLAMPED] = HB_SIG(31, 1, URRT_CAN_UNSIGNED, 0, 1),
    [URRT_CANTX_HB_DATA_AGE] = HB_SIG(32, 16, URRT_CAN_UNSIGNED, 0, 65535),
    [URRT_CANTX_HB_DROPS] = HB_SIG(48, 16, URRT_CAN_UNSIGNED, 0, 65535),
};

#define FILLED {(uint8_t)URRT_CANTX_FILLED, 0, 0}
const urrt_cantx_source urrt_cantx_heartbeat_sources[URRT_CANTX_HB_COUNT] = {
    FILLED, {(uint8_t)URRT_CANTX_ALIVE, 0, 0}, FILLED, FILLED, FILLED, FILLED, FILLED,
    FILLED, FILLED, FILLED, FILLED, FILLED, FILLED,
};

const char *urrt_cantx_state_name(urrt_cantx_state state)
{
    switch (state) {
    case URRT_CANTX_STARTING: return "STARTING";
    case URRT_CANTX_OK: return "OK";
    case URRT_CANTX_DATA_STALE: return "DATA_STALE";
    case URRT_CANTX_DISCONNECTED: return "ROBOT_DISCONNECTED";
    default: return "UNKNOWN";
    }
}

urrt_cantx_state urrt_cantx_robot_state(const urrt_cantx *tx, size_t i, uint64_t now_us, uint32_t stale_after_us)
{
    const urrt_cantx_robot *r;
    if (tx == NULL || i >= tx->tables->robot_count) {
        return URRT_CANTX_STARTING;
    }
    r = &tx->robots[i];
    bool starting = tx->started && now_us - tx->start_us < tx->tables->startup_us;
    if (!r->has_data) {
        return starting ? URRT_CANTX_STARTING : r->up ? URRT_CANTX_DATA_STALE : URRT_CANTX_DISCONNECTED;
    }
    if (!r->up) {
        return URRT_CANTX_DISCONNECTED;
    }
    return urrt_cantx_fresh(tx, i, now_us, stale_after_us) ? URRT_CANTX_OK : URRT_CANTX_DATA_STALE;
}

/* Severity: disconnected, stale, starting, ok. */
static unsigned severity(urrt_cantx_state s)
{
    switch (s) {
    case URRT_CANTX_DISCONNECTED: return 3;
    case URRT_CANTX_DATA_STALE: return 2;
    case URRT_CANTX_STARTING: return 1;
    default: return 0;
    }
}

urrt_cantx_state urrt_cantx_gateway_state(const urrt_cantx *tx, size_t hb, uint64_t now_us)
{
    urrt_cantx_state worst = URRT_CANTX_OK;
    uint32_t stale_after_us;
    size_t i;
    if (tx == NULL || hb >= tx->tables->frame_count) {
        return URRT_CANTX_STARTING;
    }
    stale_after_us = tx->tables->frames[hb].stale_after_us;
    for (i = 0; i < tx->tables->robot_count; i++) {
        urrt_cantx_state s = urrt_cantx_robot_state(tx, i, now_us, stale_after_us);
        worst = severity(s) > severity(worst) ? s : worst;
    }
    return worst;
}

/* v if it is an integer in [lo, hi], else na. */
static double enum_or(double v, double lo, double hi, double na)
{
    if (!(v >= lo && v <= hi) || v != (double)(int64_t)v) {
        return na;
    }
    return v;
}

static double age_ms(const urrt_cantx_robot *r, uint64_t now_us)
{
    uint64_t age_us = now_us > r->data_us ? now_us - r->data_us : 0u;
    uint32_t saturated_us = (URRT_CANTX_HB_AGE_NA - 1u) * 1000u;
    if (!r->has_data) {
        return URRT_CANTX_HB_AGE_NA;
    }
    /* A 32-bit division: a Cortex-M0 has no 64-bit one in hardware. */
    return age_us >= saturated_us ? URRT_CANTX_HB_AGE_NA - 1u : (double)((uint32_t)age_us / 1000u);
}

void urrt_cantx_heartbeat_fill(urrt_cantx *tx, size_t frame, uint64_t now_us, bool sending, double *values)
{
    const urrt_cantx_frame *f = &tx->tables->frames[frame];
    const urrt_cantx_robot *r = &tx->robots[f->robot];
    const urrt_cantx_link *now = &tx->link;
    const urrt_cantx_link *seen = &tx->link_seen;
    /* Modes as old as stale data are not the robot's modes now. */
    bool current = urrt_cantx_fresh(tx, f->robot, now_us, f->stale_after_us);
    size_t i;
    /* The clamped flag covers every value taken so far. */
    for (i = 0; i < tx->tables->frame_count; i++) {
        pack_fields(tx, i);
    }
    values[URRT_CANTX_HB_STATE] = urrt_cantx_gateway_state(tx, frame, now_us);
    values[URRT_CANTX_HB_ROBOT_MODE] =
        current ? enum_or(r->robot_mode, -127, 127, URRT_CANTX_HB_ROBOT_MODE_NA) : URRT_CANTX_HB_ROBOT_MODE_NA;
    values[URRT_CANTX_HB_SAFETY_MODE] =
        current ? enum_or(r->safety_mode, 1, 255, URRT_CANTX_HB_SAFETY_MODE_NA) : URRT_CANTX_HB_SAFETY_MODE_NA;
    values[URRT_CANTX_HB_GENERATION] = r->generation;
    values[URRT_CANTX_HB_BUS_OFF] = now->bus_off != seen->bus_off;
    values[URRT_CANTX_HB_CAN_ERRORS] = now->error_frames != seen->error_frames;
    values[URRT_CANTX_HB_CAN_DOWN] = now->down_events != seen->down_events;
    values[URRT_CANTX_HB_SEND_ERRORS] = now->send_errors != seen->send_errors;
    values[URRT_CANTX_HB_TX_DROPPED] = now->dropped != seen->dropped;
    values[URRT_CANTX_HB_CLAMPED] = tx->clamped != tx->clamped_seen;
    values[URRT_CANTX_HB_DATA_AGE] = age_ms(r, now_us);
    values[URRT_CANTX_HB_DROPS] = (double)(uint16_t)now->dropped;
    if (sending) {
        link_copy(&tx->link_seen, &tx->link);
        tx->clamped_seen = tx->clamped;
    }
}
