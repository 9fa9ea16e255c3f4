/* SPDX-License-Identifier: MIT */
/* canopen_map.c: see canopen_map.h. */
#include "canopen_map.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NMT_EC_BASE 0x700u   /* boot-up and heartbeat: 0x700 + node id */
#define SYNC_MAX_N 240u

/* ---- keys ------------------------------------------------------------------------- */

static bool co_text(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why, size_t n)
{
    char *dst = (char *)obj + key->offset;
    char reason[CONF_WHY_MAX];
    (void)at;
    return conf_text(dst, key->size, value, reason, sizeof reason) ||
           conf_fail(why, n, "%s = '%s': %s", key->name, value, reason);
}

static bool co_nmt_start(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                         size_t n)
{
    struct canopen_map *co = obj;
    (void)key, (void)at;
    if (strcmp(value, "pre-operational") == 0) {
        co->nmt_start = URRT_CO_START_PRE_OPERATIONAL;
    } else if (strcmp(value, "operational") == 0) {
        co->nmt_start = URRT_CO_START_OPERATIONAL;
    } else {
        return conf_fail(why, n, "nmt_start = '%s': use pre-operational (wait for the manager's start) or operational "
                                 "(self-starting, for a bus without a manager or interface = log:)", value);
    }
    return true;
}

static bool co_transmission(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                            size_t n)
{
    struct canopen_frame *f = obj;
    uint32_t every;
    (void)key, (void)at;
    if (strcmp(value, "event") == 0) {
        f->sync_every = 0;
        return true;
    }
    if (strncmp(value, "sync", 4) == 0 && (value[4] == ' ' || value[4] == '\t') &&
        conf_u32(value + 5 + strspn(value + 5, " \t"), 1, SYNC_MAX_N, &every, NULL, 0)) {
        f->sync_every = every;
        return true;
    }
    return conf_fail(why, n, "transmission = '%s': use event (type 254: every period_ms) or sync N (every Nth SYNC, "
                             "N 1..240)", value);
}

#define TEXT_KEY(member) CONF_FN, offsetof(struct canopen_map, member), sizeof(((struct canopen_map *)0)->member)

const struct conf_key canopen_map_keys[CANOPEN_K_COUNT] = {
    [CANOPEN_K_NODE_ID] = {"node_id", CONF_UINT, CONF_FIELD(struct canopen_map, node_id), 1, 127, NULL,
                           "%1$s = '%2$s': give the CANopen node id, 1..127", false, NULL, NULL, "required",
                           "the node id: TPDO, EMCY, SDO and heartbeat ids follow from it"},
    [CANOPEN_K_DEVICE_TYPE] = {"device_type", CONF_UINT, CONF_FIELD(struct canopen_map, device_type), 0, UINT32_MAX,
                               NULL, NULL, false, NULL, "0", NULL, "0x1000 device type (0: no device profile)"},
    [CANOPEN_K_VENDOR_ID] = {"vendor_id", CONF_UINT, CONF_FIELD(struct canopen_map, vendor_id), 0, UINT32_MAX, NULL,
                             NULL, false, NULL, "0", NULL, "0x1018 sub 1, the vendor id CiA assigned"},
    [CANOPEN_K_PRODUCT_CODE] = {"product_code", CONF_UINT, CONF_FIELD(struct canopen_map, product_code), 0,
                                UINT32_MAX, NULL, NULL, false, NULL, "0", NULL, "0x1018 sub 2"},
    [CANOPEN_K_REVISION] = {"revision", CONF_UINT, CONF_FIELD(struct canopen_map, revision), 0, UINT32_MAX, NULL,
                            NULL, false, NULL, "0", NULL, "0x1018 sub 3, revision number"},
    [CANOPEN_K_SERIAL] = {"serial", CONF_UINT, CONF_FIELD(struct canopen_map, serial), 0, UINT32_MAX, NULL, NULL,
                          false, NULL, "0", NULL, "0x1018 sub 4, serial number"},
    [CANOPEN_K_VENDOR_NAME] = {"vendor_name", TEXT_KEY(vendor_name), 0, 0, co_text, NULL, false, "TEXT", "urrt",
                               NULL, "the EDS's VendorName"},
    [CANOPEN_K_DEVICE_NAME] = {"device_name", TEXT_KEY(device_name), 0, 0, co_text, NULL, false, "TEXT",
                               "urrt-gateway", NULL, "0x1008 and the EDS's ProductName"},
    [CANOPEN_K_HARDWARE_VERSION] = {"hardware_version", TEXT_KEY(hardware_version), 0, 0, co_text, NULL, false,
                                    "TEXT", "Linux", NULL, "0x1009 (0x100A, the software version, is urrt's)"},
    [CANOPEN_K_NMT_START] = {"nmt_start", CONF_FN, 0, 0, 0, 0, co_nmt_start, NULL, false,
                             "pre-operational|operational", "pre-operational", NULL,
                             "the state after boot-up: operational starts itself (no manager, interface = log:)"},
    [CANOPEN_K_HEARTBEAT] = {"heartbeat_ms", CONF_MS, CONF_FIELD(struct canopen_map, heartbeat_ms), 0, 65535, NULL,
                             "%1$s = '%2$s': give 0..65535 milliseconds (0: off)", false, NULL, "1000", NULL,
                             "0x1017 producer heartbeat time at 0x700 + node id (0: off)"},
    [CANOPEN_K_SDO_TIMEOUT] = {"sdo_timeout_ms", CONF_MS, CONF_FIELD(struct canopen_map, sdo_timeout_ms), 1, 65535,
                               NULL, "%1$s = '%2$s': give 1..65535 milliseconds", false, NULL, "1000", NULL,
                               "a segmented upload the client leaves this long is aborted"},
};

const struct conf_key canopen_map_frame_keys[CANOPEN_FK_COUNT] = {
    [CANOPEN_FK_TPDO] = {"tpdo", CONF_UINT, CONF_FIELD(struct canopen_frame, tpdo), 1, CANOPEN_MAX_TPDOS, NULL,
                         "%1$s = '%2$s': give the TPDO number, 1..512", false, NULL, NULL,
                         "its place among the [frame]s", "with [canopen]: the frame's TPDO number"},
    [CANOPEN_FK_TRANSMISSION] = {"transmission", CONF_FN, 0, 0, 1, SYNC_MAX_N, co_transmission, NULL, false,
                                 "event|sync N", "event", NULL,
                                 "with [canopen]: at its period (type 254) or on every Nth SYNC (type N)"},
    [CANOPEN_FK_OWN_ID] = {"own_id", CONF_BOOL, CONF_FIELD(struct canopen_frame, own_id), 0, 0, NULL,
                           "%1$s = '%2$s': use yes (id is this TPDO's own) or no (the node's pre-defined one)",
                           false, NULL, "no", NULL, "with [canopen]: id is not the pre-defined COB-ID of the TPDO"},
};

/* ---- the front end's calls ------------------------------------------------------------ */

void canopen_map_init(struct canopen_map *co)
{
    memset(co, 0, sizeof *co);
    (void)conf_key_defaults(canopen_map_keys, CANOPEN_K_COUNT, co, NULL, 0);
}

void canopen_map_free(struct canopen_map *co)
{
    free(co->frames);
    free(co->tpdo_of);
    memset(co, 0, sizeof *co);
}

bool canopen_map_enabled(const struct canopen_map *co)
{
    return co->configured;
}

void canopen_map_begin(struct canopen_map *co, struct conf_at at)
{
    co->configured = true;
    co->loc = (struct can_map_loc){at.file, at.line};
}

bool canopen_map_set(struct canopen_map *co, const struct conf_key *key, const char *value, struct conf_at at,
                     char *why, size_t n)
{
    if (!conf_key_set(key, co, value, at, why, n)) {
        return false;
    }
    co->key_loc[key - canopen_map_keys] = (struct can_map_loc){at.file, at.line};
    return true;
}

/* Frames' entries up to index frame, with their defaults. */
static struct canopen_frame *frame_entry(struct canopen_map *co, size_t frame)
{
    if (frame >= co->frame_count) {
        struct canopen_frame *grown = realloc(co->frames, (frame + 1) * sizeof *grown);
        if (grown == NULL) {
            return NULL;
        }
        co->frames = grown;
        for (; co->frame_count <= frame; co->frame_count++) {
            memset(&grown[co->frame_count], 0, sizeof *grown);
            (void)conf_key_defaults(canopen_map_frame_keys, CANOPEN_FK_COUNT, &grown[co->frame_count], NULL, 0);
        }
    }
    return &co->frames[frame];
}

bool canopen_map_frame_set(struct canopen_map *co, size_t frame, const struct conf_key *key, const char *value,
                           struct conf_at at, char *why, size_t n)
{
    struct canopen_frame *f = frame_entry(co, frame);
    if (f == NULL) {
        return conf_fail(why, n, "out of memory");
    }
    if (!conf_key_set(key, f, value, at, why, n)) {
        return false;
    }
    f->key_loc[key - canopen_map_frame_keys] = (struct can_map_loc){at.file, at.line};
    return true;
}

/* ---- shared rules ------------------------------------------------------------------- */

uint32_t canopen_predefined_tpdo_id(unsigned n, uint32_t node_id)
{
    return n >= 1u && n <= 4u ? 0x180u + 0x100u * (n - 1u) + node_id : 0u;
}

uint32_t canopen_predefined_rpdo_id(unsigned n, uint32_t node_id)
{
    return n >= 1u && n <= URRT_CO_MAX_RPDOS ? 0x200u + 0x100u * (n - 1u) + node_id : 0u;
}

/* CiA 301 (as lib/urrt_co.c keeps them): NMT, SYNC and EMCY, SDO, NMT error control, LSS. */
bool canopen_id_restricted(uint32_t id)
{
    return id <= 0x07Fu || (id >= 0x101u && id <= 0x180u) || (id >= 0x581u && id <= 0x5FFu) ||
           (id >= 0x601u && id <= 0x67Fu) || (id >= 0x6E0u && id <= 0x6FFu) || id >= 0x701u;
}

const char *canopen_nmt_start_name(uint8_t start)
{
    return start == URRT_CO_START_OPERATIONAL ? "operational" : "pre-operational";
}

static void problem(const struct can_map *can, struct can_map_loc loc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void problem(const struct can_map *can, struct can_map_loc loc, const char *fmt, ...)
{
    char reason[CONF_WHY_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, sizeof reason, fmt, ap);
    va_end(ap);
    if (can->reporter != NULL) {
        can->reporter(can->reporter_ctx, loc.file, loc.line, reason);
    }
}

static struct can_map_loc loc_or(struct can_map_loc a, struct can_map_loc b)
{
    return a.line != 0 ? a : b;
}

/* By size in bytes (1, 2, 4). */
static const uint8_t uns[] = {0, URRT_CO_UNSIGNED8, URRT_CO_UNSIGNED16, 0, URRT_CO_UNSIGNED32};
static const uint8_t sig_types[] = {0, URRT_CO_INTEGER8, URRT_CO_INTEGER16, 0, URRT_CO_INTEGER32};

bool canopen_signal_object(const urrt_can_signal *sig, const struct can_map_signal *meta, uint8_t *type,
                           unsigned *bytes, char *why, size_t n)
{
    unsigned len = sig->length;
    if (sig->byte_order != URRT_CAN_INTEL) {
        return conf_fail(why, n, "is Motorola (big-endian): CANopen PDOs are little-endian, use intel");
    }
    if (sig->start % 8u != 0u) {
        return conf_fail(why, n, "starts at bit %u, inside a byte: a PDO maps whole bytes, start it at a multiple of 8",
                         (unsigned)sig->start);
    }
    if (len > 32u) {
        return conf_fail(why, n,
                         "has %u bits: a PDO-mapped object holds at most 32 bits here (use float32, or 32 bits)", len);
    }
    *bytes = len <= 8u ? 1u : len <= 16u ? 2u : 4u;
    if (sig->type == URRT_CAN_FLOAT32) {
        *type = URRT_CO_REAL32;
        return true;
    }
    if (sig->type == URRT_CAN_SIGNED && len != 8u * *bytes) {
        return conf_fail(why, n, "is signed with %u bits: an INTEGER%u object would not read as negative on the PLC: "
                                 "make it %u bits", len, 8u * *bytes, 8u * *bytes);
    }
    (void)meta;
    *type = sig->type == URRT_CAN_SIGNED ? sig_types[*bytes] : uns[*bytes];
    return true;
}

/* ---- before can_map_finish: numbers and ids --------------------------------------------- */

/* TPDO numbers: given, or the frame's place; unique, 1..n without a gap. */
static int number_tpdos(struct canopen_map *co, const struct can_map *can)
{
    int errors = 0;
    free(co->tpdo_of);
    co->tpdo_of = calloc(can->frame_count ? can->frame_count : 1, sizeof *co->tpdo_of);
    co->tpdo_count = can->frame_count;
    if (co->tpdo_of == NULL || frame_entry(co, can->frame_count) == NULL) {
        problem(can, co->loc, "out of memory");
        return 1;
    }
    for (size_t i = 0; i < can->frame_count; i++) {
        co->tpdo_of[i] = (uint16_t)(co->frames[i].tpdo != 0 ? co->frames[i].tpdo : i + 1);
        for (size_t j = 0; j < i; j++) {
            if (co->tpdo_of[j] == co->tpdo_of[i]) {
                problem(can, loc_or(co->frames[i].key_loc[CANOPEN_FK_TPDO], can->frames[i].loc),
                        "[frame %s] is TPDO%u, as [frame %s] (line %d) already is: give each frame its own tpdo = N",
                        can->frames[i].name, co->tpdo_of[i], can->frames[j].name, can->frames[j].loc.line);
                errors++;
            }
        }
        if (co->tpdo_of[i] > can->frame_count) {
            problem(can, co->frames[i].key_loc[CANOPEN_FK_TPDO],
                    "[frame %s] tpdo = %u: the %zu frames are TPDO1..%zu, numbered without a gap", can->frames[i].name,
                    co->tpdo_of[i], can->frame_count, can->frame_count);
            errors++;
        }
    }
    return errors;
}

/* A frame's id: the node's pre-defined COB-ID, or its own with own_id = yes. */
static int frame_id(struct canopen_map *co, struct can_map *can, size_t i, bool has_node)
{
    struct can_map_frame *f = &can->frames[i];
    const struct canopen_frame *c = &co->frames[i];
    unsigned n = co->tpdo_of[i];
    uint32_t pre = canopen_predefined_tpdo_id(n, co->node_id);
    bool has_id = f->key_loc[CAN_MAP_FK_ID].line != 0;
    if (c->own_id && !has_id) {
        problem(can, c->key_loc[CANOPEN_FK_OWN_ID], "[frame %s] own_id = yes needs its id = ...", f->name);
        return 1;
    }
    if (!c->own_id && !has_id && pre != 0) {
        f->id = pre; /* as if the file said it, on the header's line */
        f->key_loc[CAN_MAP_FK_ID] = f->loc;
        return 0;
    }
    if (!c->own_id && pre == 0) {
        problem(can, loc_or(f->key_loc[CAN_MAP_FK_ID], f->loc),
                "[frame %s] is TPDO%u: CiA 301 pre-defines COB-IDs for TPDO1..4 only: give its id = ... and own_id = "
                "yes", f->name, n);
        return 1;
    }
    if (!c->own_id && f->id != pre && has_node) {
        problem(can, f->key_loc[CAN_MAP_FK_ID],
                "[frame %s] id = 0x%X is not TPDO%u's COB-ID for node_id %u (0x%X): remove id (it follows from "
                "node_id), or keep it and say own_id = yes", f->name, (unsigned)f->id, n, (unsigned)co->node_id, (unsigned)pre);
        return 1;
    }
    if (c->own_id && !f->extended && canopen_id_restricted(f->id)) {
        problem(can, f->key_loc[CAN_MAP_FK_ID],
                "[frame %s] id = 0x%X is one CiA 301 keeps for NMT, SYNC, EMCY, SDO or heartbeat: no PDO may use it",
                f->name, (unsigned)f->id);
        return 1;
    }
    return 0;
}

/* [input] i is RPDO i + 1, on its pre-defined COB-ID: CiA 301's set has
 * four, and the manager moves one by 0x1400 + n sub 1 if it wants. */
static int input_id(struct canopen_map *co, struct can_map *can, size_t i)
{
    struct can_map_frame *f = &can->inputs[i];
    unsigned n = (unsigned)i + 1u;
    uint32_t pre = canopen_predefined_rpdo_id(n, co->node_id);
    if (pre == 0) {
        problem(can, f->loc, "[input %s] would be RPDO%u: the node receives RPDO1..%u (CiA 301's pre-defined "
                "set): join it with another [input], at most %u with [canopen]", f->name, n,
                (unsigned)URRT_CO_MAX_RPDOS, (unsigned)URRT_CO_MAX_RPDOS);
        f->key_loc[CAN_MAP_IK_ID] = f->loc; /* no "has no id" from the same cause */
        return 1;
    }
    if (f->key_loc[CAN_MAP_IK_ID].line != 0 && (f->id != pre || f->extended)) {
        problem(can, f->key_loc[CAN_MAP_IK_ID], "[input %s] id = 0x%X is not RPDO%u's COB-ID for node_id %u (0x%03X): "
                "remove id (it follows from node_id; the manager may move it through 0x%04X sub 1)", f->name,
                (unsigned)f->id, n, (unsigned)co->node_id, (unsigned)pre, 0x1400u + n - 1u);
        return 1;
    }
    f->id = pre; /* as if the file said it, on the header's line */
    if (f->key_loc[CAN_MAP_IK_ID].line == 0) {
        f->key_loc[CAN_MAP_IK_ID] = f->loc;
    }
    return 0;
}

/* [can]'s heartbeat frame is the node's status TPDO (off by default); the
 * NMT heartbeat at 0x700 + node id replaces it on the bus. */
static int status_id(struct canopen_map *co, struct can_map *can)
{
    unsigned n = (unsigned)co->tpdo_count + 1u;
    uint32_t pre = canopen_predefined_tpdo_id(n, co->node_id);
    if (can->key_loc[CAN_MAP_CK_HB_ID].line == 0) {
        /* Past TPDO4: 0x680 + node id, which no CiA 301 function uses (below node 96). */
        can->hb_id = pre != 0 ? pre : CANOPEN_STATUS_ID_BASE + co->node_id;
        can->hb_extended = false;
        can->key_loc[CAN_MAP_CK_HB_ID] = co->loc;
        if (!canopen_id_restricted(can->hb_id)) {
            return 0;
        }
        problem(can, co->loc, "the status TPDO%u of node_id %u has no free default id (0x%X is kept by CiA 301): "
                "give [can] heartbeat_id, an 11-bit id no CiA 301 function uses", n, (unsigned)co->node_id,
                (unsigned)can->hb_id);
        return 1;
    }
    if (can->hb_extended || canopen_id_restricted(can->hb_id)) {
        problem(can, can->key_loc[CAN_MAP_CK_HB_ID],
                "heartbeat_id 0x%X: with [canopen] the heartbeat is CANopen's, 0x700 + node_id every heartbeat_ms; "
                "heartbeat_id names the status TPDO%u (off until the manager enables it): remove it, or give an "
                "11-bit id no CiA 301 function uses", (unsigned)can->hb_id, n);
        return 1;
    }
    return 0;
}

/* What the bus load counts for the node beside its TPDOs (canopen_map.h). */
static void node_traffic(const struct canopen_map *co, struct can_map *can)
{
    can->frames_name = "TPDOs";
    can->hb_name = "status TPDO";
    can->traffic_count = 0;
    if (co->heartbeat_ms != 0) {
        (void)can_map_add_traffic(can, "heartbeat", 1, 1000.0 / co->heartbeat_ms);
    }
    (void)can_map_add_traffic(can, "EMCY", URRT_CAN_CLASSIC_MAX_LEN, CANOPEN_EMCY_PER_S);
    (void)can_map_add_traffic(can, "SDO", URRT_CAN_CLASSIC_MAX_LEN, 2.0 * 1000.0 / CANOPEN_SDO_POLL_MS);
}

int canopen_map_prepare(struct canopen_map *co, struct can_map *can)
{
    int errors = 0;
    bool has_node = co->key_loc[CANOPEN_K_NODE_ID].line != 0;
    if (can->can_loc.line == 0) {
        problem(can, co->loc, "[canopen] needs a [can] section (interface, bitrate) and [frame NAME]s, its TPDOs");
        return 1;
    }
    if (!has_node) {
        /* Ids are still filled in, so that no "has no id" follows from this one cause. */
        problem(can, co->loc, "[canopen] has no valid node_id (1..127): every CANopen id follows from it");
        co->node_id = 1;
        errors++;
    }
    errors += number_tpdos(co, can);
    for (size_t i = 0; i < can->frame_count && co->tpdo_of != NULL; i++) {
        errors += frame_id(co, can, i, has_node);
    }
    for (size_t i = 0; i < can->input_count; i++) {
        errors += input_id(co, can, i);
    }
    node_traffic(co, can);
    return errors + status_id(co, can);
}

/* ---- after can_map_finish: the PDO layout ---------------------------------------------- */

/* A PDO's layout: classic, 11-bit, at most 8 bytes, each signal an object
 * of whole bytes of its own. what: "[frame x]", pdo: "TPDO3". */
static int pdo_layout(const struct can_map *can, const struct can_map_frame *f, const char *what, const char *pdo)
{
    uint8_t owner[URRT_CAN_CLASSIC_MAX_LEN];
    int errors = 0;
    if (f->extended || f->fd || f->len > URRT_CAN_CLASSIC_MAX_LEN) {
        problem(can, f->loc, "%s (%s) is %s: a PDO is a classic CAN frame with an 11-bit id, 0..8 bytes", what, pdo,
                f->extended ? "extended (29-bit)" : "CAN FD or longer than 8 bytes");
        return 1;
    }
    memset(owner, 0xFF, sizeof owner);
    for (size_t k = 0; k < f->count; k++) {
        char why[CONF_WHY_MAX];
        uint8_t type;
        unsigned bytes;
        unsigned first = f->sigs[k].start / 8u;
        if (!canopen_signal_object(&f->sigs[k], &f->meta[k], &type, &bytes, why, sizeof why)) {
            problem(can, f->meta[k].loc, "%s signal %s %s", what, f->meta[k].name, why);
            errors++;
            continue;
        }
        if (f->input && type == URRT_CO_REAL32) {
            problem(can, f->meta[k].loc, "%s signal %s is float32: an RPDO writes INTEGERn and UNSIGNEDn objects: "
                    "send an integer and scale it (factor=0.001)", what, f->meta[k].name);
            errors++;
            continue;
        }
        for (unsigned b = first; b < first + bytes; b++) {
            if (b >= f->len || owner[b] != 0xFF) {
                problem(can, f->meta[k].loc,
                        "%s signal %s: its %u-byte object needs byte %u %s: a PDO maps whole bytes, one "
                        "signal each", what, f->meta[k].name, bytes, b,
                        b >= f->len ? "past the frame's length" : "that another signal uses");
                errors++;
                break;
            }
            owner[b] = (uint8_t)k;
        }
    }
    return errors;
}

static int check_frame(const struct canopen_map *co, const struct can_map *can, size_t i)
{
    char what[48], pdo[16];
    snprintf(what, sizeof what, "[frame %s]", can->frames[i].name);
    snprintf(pdo, sizeof pdo, "TPDO%u", co->tpdo_of[i]);
    return pdo_layout(can, &can->frames[i], what, pdo);
}

int canopen_map_orphans(const struct canopen_map *co, const struct can_map *can)
{
    int errors = 0;
    for (size_t i = 0; i < co->frame_count && i < can->frame_count; i++) {
        for (size_t k = 0; k < CANOPEN_FK_COUNT; k++) {
            if (co->frames[i].key_loc[k].line != 0) {
                problem(can, co->frames[i].key_loc[k], "[frame %s] %s is a CANopen key: it needs a [canopen] section "
                        "(node_id, ...)", can->frames[i].name, canopen_map_frame_keys[k].name);
                errors++;
            }
        }
    }
    return errors;
}

int canopen_map_check(const struct canopen_map *co, const struct can_map *can)
{
    int errors = 0;
    /* TPDO n's values are at 0x2100 + n - 1: past TPDO256, RPDO1's registers' 0x2200. */
    if (can->input_count > 0 && co->tpdo_count > CANOPEN_INPUTS_INDEX - CANOPEN_VALUES_INDEX) {
        problem(can, can->inputs[0].loc, "[input %s]: with %zu [frame]s, TPDO%u's values would take 0x%04X, the "
                "index of RPDO1's registers: at most %u [frame]s beside [input]s", can->inputs[0].name,
                co->tpdo_count, CANOPEN_INPUTS_INDEX - CANOPEN_VALUES_INDEX + 1u, CANOPEN_INPUTS_INDEX,
                CANOPEN_INPUTS_INDEX - CANOPEN_VALUES_INDEX);
        errors++;
    }
    for (size_t i = 0; i < can->input_count; i++) {
        char what[48], pdo[16];
        snprintf(what, sizeof what, "[input %s]", can->inputs[i].name);
        snprintf(pdo, sizeof pdo, "RPDO%u", (unsigned)i + 1u);
        errors += pdo_layout(can, &can->inputs[i], what, pdo);
    }
    for (size_t i = 0; i < can->frame_count; i++) {
        errors += check_frame(co, can, i);
        if (co->frames[i].sync_every != 0 && can->frames[i].every) {
            problem(can, co->frames[i].key_loc[CANOPEN_FK_TRANSMISSION],
                    "[frame %s] transmission = sync needs a period_ms (its event timer), not every",
                    can->frames[i].name);
            errors++;
        }
    }
    switch (can->bitrate) {
    case 10000: case 20000: case 50000: case 125000: case 250000: case 500000: case 800000: case 1000000: break;
    default:
        problem(can, loc_or(can->key_loc[CAN_MAP_CK_BITRATE], can->can_loc),
                "bitrate %u is not a CANopen bit rate (CiA 301: 10, 20, 50, 125, 250, 500, 800 or 1000 kbit/s)",
                (unsigned)can->bitrate);
        errors++;
    }
    return errors;
}
