/* SPDX-License-Identifier: MIT */
/* eds.c: see eds.h. The object dictionary written here is lib/urrt_co.c's
 * (docs/canopen.md's table): communication objects as the node serves them,
 * the TPDOs and manufacturer objects from the node's description. */
#include "eds.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "dbc.h"

#define ACCESS_RO "ro"
#define ACCESS_RW "rw"
#define OBJ_VAR 0x7u
#define OBJ_ARRAY 0x8u
#define OBJ_RECORD 0x9u
#define TPDO_COMM 0x1800u
#define TPDO_MAP 0x1A00u

/* One VAR (an object or a sub-index). sub < 0: the object itself. */
struct eds_var {
    unsigned index;
    int sub;
    const char *name;
    unsigned type;
    const char *access;
    const char *def;
    bool mappable;
    const char *low, *high;   /* NULL: none */
};

static void put_var(FILE *out, const struct eds_var *v)
{
    if (v->sub < 0) {
        fprintf(out, "[%04X]\n", v->index);
    } else {
        fprintf(out, "[%04Xsub%X]\n", v->index, (unsigned)v->sub);
    }
    fprintf(out, "ParameterName=%s\nObjectType=0x%X\nDataType=0x%04X\nAccessType=%s\n", v->name, OBJ_VAR, v->type,
            v->access);
    if (v->low != NULL) {
        fprintf(out, "LowLimit=%s\n", v->low);
    }
    if (v->high != NULL) {
        fprintf(out, "HighLimit=%s\n", v->high);
    }
    fprintf(out, "DefaultValue=%s\nPDOMapping=%d\n\n", v->def, v->mappable ? 1 : 0);
}

static void put_record(FILE *out, unsigned index, const char *name, unsigned type, unsigned subs)
{
    fprintf(out, "[%04X]\nParameterName=%s\nObjectType=0x%X\nSubNumber=0x%X\n\n", index, name, type, subs);
}

static void put_u32(FILE *out, unsigned index, int sub, const char *name, const char *access, uint32_t value)
{
    char def[16];
    snprintf(def, sizeof def, "0x%08X", (unsigned)value);
    put_var(out, &(struct eds_var){index, sub, name, URRT_CO_UNSIGNED32, access, def, false, NULL, NULL});
}

static void put_small(FILE *out, unsigned index, int sub, const char *name, unsigned type, const char *access,
                      unsigned value)
{
    char def[16];
    snprintf(def, sizeof def, "%u", value);
    put_var(out, &(struct eds_var){index, sub, name, type, access, def, false, NULL, NULL});
}

static void put_text(FILE *out, unsigned index, const char *name, const char *text)
{
    put_var(out, &(struct eds_var){index, -1, name, URRT_CO_VISIBLE_STRING, ACCESS_RO, text ? text : "", false,
                                   NULL, NULL});
}

/* ---- the sections before the objects ------------------------------------------------- */

static const unsigned baud_kbits[] = {10, 20, 50, 125, 250, 500, 800, 1000};

static void put_file_info(FILE *out, const urrt_co_desc *d, const char *source)
{
    fprintf(out, "[FileInfo]\nFileName=urrt-node%u.eds\nFileVersion=1\nFileRevision=0\nEDSVersion=4.0\n",
            (unsigned)d->node_id);
    fprintf(out, "Description=urrt-gateway CANopen node%s%s: Universal Robots RealTime data as TPDOs\n",
            source ? " from " : "", source ? source : "");
    fprintf(out, "CreatedBy=urrt-gateway %s --print-eds\n\n", URRT_VERSION_STRING);
}

static void put_device_info(FILE *out, const struct canopen_map *co, const struct can_map *can,
                            const urrt_co_desc *d)
{
    fprintf(out, "[DeviceInfo]\nVendorName=%s\nVendorNumber=0x%08X\nProductName=%s\nProductNumber=0x%08X\n"
                 "RevisionNumber=0x%08X\nOrderCode=\n",
            co->vendor_name, (unsigned)d->vendor_id, d->device_name, (unsigned)d->product_code,
            (unsigned)d->revision);
    for (size_t i = 0; i < sizeof baud_kbits / sizeof baud_kbits[0]; i++) {
        fprintf(out, "BaudRate_%u=%d\n", baud_kbits[i], can->bitrate == baud_kbits[i] * 1000u);
    }
    fprintf(out, "SimpleBootUpMaster=0\nSimpleBootUpSlave=1\nGranularity=0\nDynamicChannelsSupported=0\n"
                 "GroupMessaging=0\nNrOfRXPDO=0\nNrOfTXPDO=%zu\nLSS_Supported=0\n\n",
            d->tpdo_count);
}

static bool uses_dummy(const urrt_co_desc *d)
{
    for (size_t n = 0; n < d->tpdo_count; n++) {
        for (size_t i = 0; i < d->tpdos[n].mapping_count; i++) {
            if (d->tpdos[n].mapping[i] >> 16 == CANOPEN_DUMMY_U8) {
                return true;
            }
        }
    }
    return false;
}

static void put_dummy_usage(FILE *out, const urrt_co_desc *d)
{
    fprintf(out, "[DummyUsage]\n");
    for (unsigned i = 1; i <= 7; i++) {
        fprintf(out, "Dummy%04X=%d\n", i, i == CANOPEN_DUMMY_U8 && uses_dummy(d));
    }
    fputc('\n', out);
}

/* ---- names and scaling ------------------------------------------------------------------ */

/* What an object of the description carries, in words: its ParameterName. */
static void object_name(const struct can_map *can, const urrt_co_object *o, size_t hb, char *buf, size_t size)
{
    char f[32], off[32];
    if (o->frame == hb) {
        const struct can_map_hb_signal *h = &can_map_heartbeat_layout[o->item];
        snprintf(buf, size, "status %s%s%s", h->name, h->unit[0] ? ", " : "", h->unit);
        return;
    }
    const struct can_map_frame *fr = &can->frames[o->frame];
    const struct can_map_signal *m = &fr->meta[o->item];
    const urrt_can_signal *sig = &fr->sigs[o->item];
    if (m->role != CAN_MAP_ROLE_FIELD) {
        snprintf(buf, size, "%s %s", fr->name,
                 m->role == CAN_MAP_ROLE_ALIVE ? "alive counter (+1 per TPDO sent)" : "valid (1: fresh and exact)");
        return;
    }
    const urrt_field_info *info = urrt_field((urrt_field_id)m->field);
    char field[48];
    if (info != NULL && info->count > 1) {
        snprintf(field, sizeof field, "%s[%u]", info->name, m->elem);
    } else {
        snprintf(field, sizeof field, "%s", info ? info->name : "?");
    }
    snprintf(buf, size, "%s: %s, %s = raw x %s + %s", m->name, field, m->unit[0] ? m->unit : "1",
             dbc_number(sig->factor, f, sizeof f), dbc_number(sig->offset, off, sizeof off));
}

static bool is_robot_value(const struct can_map *can, const urrt_co_object *o, size_t hb)
{
    return o->frame != hb && can->frames[o->frame].meta[o->item].role == CAN_MAP_ROLE_FIELD;
}

/* [Comments]: two notes, then the scaling of every mapped robot value with its limits. */
static void put_comments(FILE *out, const struct can_map *can, const urrt_co_desc *d, size_t hb)
{
    size_t lines = 2;
    for (size_t i = 0; i < d->object_count; i++) {
        lines += is_robot_value(can, &d->objects[i], hb);
    }
    fprintf(out, "[Comments]\nLines=%zu\n", lines);
    fprintf(out, "Line1=Robot values: physical = raw x factor + offset, as each ParameterName says "
                 "(docs/canopen.md)\n");
    fprintf(out, "Line2=EMCY 0xFF01 robot link down, 0xFF02 robot data stale; TPDO%zu (status) is off until enabled\n",
            d->tpdo_count);
    lines = 2;
    for (size_t i = 0; i < d->object_count; i++) {
        const urrt_co_object *o = &d->objects[i];
        char name[160], lo[32], hi[32];
        if (is_robot_value(can, o, hb)) {
            const urrt_can_signal *sig = &can->frames[o->frame].sigs[o->item];
            object_name(can, o, hb, name, sizeof name);
            fprintf(out, "Line%zu=0x%04X sub %u %s, limits %s..%s\n", ++lines, o->index, o->sub, name,
                    dbc_number(sig->min, lo, sizeof lo), dbc_number(sig->max, hi, sizeof hi));
        }
    }
    fputc('\n', out);
}

/* ---- object lists ------------------------------------------------------------------------ */

static int by_value(const void *a, const void *b)
{
    unsigned x = *(const unsigned *)a, y = *(const unsigned *)b;
    return (x > y) - (x < y);
}

static void put_list(FILE *out, const char *section, const unsigned *indices, size_t count)
{
    fprintf(out, "[%s]\nSupportedObjects=%zu\n", section, count);
    for (size_t i = 0; i < count; i++) {
        fprintf(out, "%zu=0x%04X\n", i + 1, indices[i]);
    }
    fputc('\n', out);
}

static const unsigned mandatory[] = {0x1000, 0x1001, 0x1018};
static const unsigned optional_comm[] = {0x1003, 0x1005, 0x1008, 0x1009, 0x100A, 0x1014, 0x1015, 0x1017};
#define COUNT(a) (sizeof a / sizeof a[0])

/* The manufacturer indices, ascending, each once: their number. */
static size_t manufacturer_indices(const urrt_co_desc *d, unsigned *out)
{
    size_t n = 0;
    for (size_t i = 0; i < d->object_count; i++) {
        bool seen = false;
        for (size_t j = 0; j < n && !seen; j++) {
            seen = out[j] == d->objects[i].index;
        }
        if (!seen) {
            out[n++] = d->objects[i].index;
        }
    }
    qsort(out, n, sizeof *out, by_value);
    return n;
}

static int put_lists(FILE *out, const urrt_co_desc *d, unsigned *work)
{
    size_t n = 0;
    put_list(out, "MandatoryObjects", mandatory, COUNT(mandatory));
    for (size_t i = 0; i < COUNT(optional_comm); i++) {
        work[n++] = optional_comm[i];
    }
    for (size_t i = 0; i < d->tpdo_count; i++) {
        work[n++] = TPDO_COMM + (unsigned)i;
    }
    for (size_t i = 0; i < d->tpdo_count; i++) {
        work[n++] = TPDO_MAP + (unsigned)i;
    }
    put_list(out, "OptionalObjects", work, n);
    put_list(out, "ManufacturerObjects", work, manufacturer_indices(d, work));
    return 0;
}

/* ---- the objects -------------------------------------------------------------------------- */

static void put_communication(FILE *out, const urrt_co_desc *d)
{
    static const char *const identity[] = {"Vendor-ID", "Product code", "Revision number", "Serial number"};
    const uint32_t ids[] = {d->vendor_id, d->product_code, d->revision, d->serial};
    put_u32(out, 0x1000, -1, "Device type", ACCESS_RO, d->device_type);
    put_small(out, 0x1001, -1, "Error register", URRT_CO_UNSIGNED8, ACCESS_RO, 0);
    put_record(out, 0x1003, "Pre-defined error field", OBJ_ARRAY, URRT_CO_HISTORY + 1u);
    put_small(out, 0x1003, 0, "Number of errors", URRT_CO_UNSIGNED8, ACCESS_RW, 0);
    for (unsigned k = 1; k <= URRT_CO_HISTORY; k++) {
        put_u32(out, 0x1003, (int)k, "Standard error field", ACCESS_RO, 0);
    }
    put_u32(out, 0x1005, -1, "COB-ID SYNC", ACCESS_RW, 0x80);
    put_text(out, 0x1008, "Manufacturer device name", d->device_name);
    put_text(out, 0x1009, "Manufacturer hardware version", d->hardware_version);
    put_text(out, 0x100A, "Manufacturer software version", d->software_version);
    put_var(out, &(struct eds_var){0x1014, -1, "COB-ID EMCY", URRT_CO_UNSIGNED32, ACCESS_RW, "$NODEID+0x80", false,
                                   NULL, NULL});
    put_small(out, 0x1015, -1, "Inhibit time EMCY", URRT_CO_UNSIGNED16, ACCESS_RW, 0);
    put_small(out, 0x1017, -1, "Producer heartbeat time", URRT_CO_UNSIGNED16, ACCESS_RW, d->heartbeat_ms);
    put_record(out, 0x1018, "Identity object", OBJ_RECORD, 5);
    put_small(out, 0x1018, 0, "Highest sub-index supported", URRT_CO_UNSIGNED8, ACCESS_RO, 4);
    for (unsigned k = 0; k < 4; k++) {
        put_u32(out, 0x1018, (int)k + 1, identity[k], ACCESS_RO, ids[k]);
    }
}

/* TPDO n's COB-ID default: with $NODEID where it is the pre-defined one (CiA 306). */
static void cob_text(const urrt_co_desc *d, size_t n, char *buf, size_t size)
{
    uint32_t pre = canopen_predefined_tpdo_id((unsigned)n + 1u, d->node_id);
    uint32_t cob = d->tpdos[n].cob_id;
    if (cob == URRT_CO_COB_DEFAULT) {
        cob = pre != 0 ? pre : URRT_CO_COB_INVALID;
    }
    if (pre == 0 && n + 1u == d->tpdo_count) {
        pre = CANOPEN_STATUS_ID_BASE + d->node_id; /* the status TPDO's default past TPDO4 */
    }
    if (pre != 0 && (cob & 0x7FFu) == pre) {
        snprintf(buf, size, "$NODEID+0x%X", (unsigned)((cob & ~UINT32_C(0x7FF)) | (pre - d->node_id)));
    } else {
        snprintf(buf, size, "0x%08X", (unsigned)cob);
    }
}

static void put_tpdo(FILE *out, const urrt_co *node, size_t n)
{
    const urrt_co_desc *d = node->desc;
    const urrt_co_tpdo *p = &d->tpdos[n];
    unsigned comm = TPDO_COMM + (unsigned)n, map = TPDO_MAP + (unsigned)n;
    char cob[32], type[8];
    put_record(out, comm, "TPDO communication parameter", OBJ_RECORD, 5);
    put_small(out, comm, 0, "Highest sub-index supported", URRT_CO_UNSIGNED8, ACCESS_RO, 5);
    cob_text(d, n, cob, sizeof cob);
    put_var(out, &(struct eds_var){comm, 1, "COB-ID used by TPDO", URRT_CO_UNSIGNED32, ACCESS_RW, cob, false, NULL,
                                   NULL});
    snprintf(type, sizeof type, "%u", p->transmission_type);
    put_var(out, &(struct eds_var){comm, 2, "Transmission type", URRT_CO_UNSIGNED8, ACCESS_RW, type, false, "0x01",
                                   "0xFF"});
    put_small(out, comm, 3, "Inhibit time", URRT_CO_UNSIGNED16, ACCESS_RW, p->inhibit_100us);
    put_small(out, comm, 5, "Event timer", URRT_CO_UNSIGNED16, ACCESS_RW,
              (unsigned)(node->tx->tables->frames[p->frame].period_us / 1000u));
    put_record(out, map, "TPDO mapping parameter", OBJ_RECORD, p->mapping_count + 1u);
    put_small(out, map, 0, "Number of mapped objects", URRT_CO_UNSIGNED8, ACCESS_RO, p->mapping_count);
    for (unsigned k = 0; k < p->mapping_count; k++) {
        char name[32];
        snprintf(name, sizeof name, "Mapped object %u", k + 1u);
        put_u32(out, map, (int)k + 1, name, ACCESS_RO, p->mapping[k]);
    }
}

static void put_manufacturer(FILE *out, const struct co_run *run, const struct can_map *can, size_t hb,
                             const unsigned *indices, size_t count)
{
    const urrt_co_desc *d = co_run_desc(run);
    for (size_t x = 0; x < count; x++) {
        unsigned highest = 0;
        char name[96];
        for (size_t i = 0; i < d->object_count; i++) {
            highest = d->objects[i].index == indices[x] && d->objects[i].sub > highest ? d->objects[i].sub : highest;
        }
        if (indices[x] == CANOPEN_STATUS_INDEX) {
            snprintf(name, sizeof name, "Gateway status (TPDO%zu, docs/can.md's heartbeat layout)", d->tpdo_count);
        } else {
            unsigned tpdo = indices[x] - CANOPEN_VALUES_INDEX + 1u;
            snprintf(name, sizeof name, "TPDO%u values", tpdo);
        }
        put_record(out, indices[x], name, OBJ_RECORD, highest + 1u);
        put_small(out, indices[x], 0, "Highest sub-index supported", URRT_CO_UNSIGNED8, ACCESS_RO, highest);
        for (size_t i = 0; i < d->object_count; i++) {
            const urrt_co_object *o = &d->objects[i];
            char what[200];
            if (o->index != indices[x]) {
                continue;
            }
            object_name(can, o, hb, what, sizeof what);
            put_var(out, &(struct eds_var){o->index, o->sub, what, o->type, ACCESS_RO, "0",
                                           co_run_mapped(run, o->index, o->sub), NULL, NULL});
        }
    }
}

int eds_write(FILE *out, struct co_run *run, const struct canopen_map *co, const struct can_map *can,
              const char *source)
{
    const urrt_co *node = co_run_node(run);
    const urrt_co_desc *d = co_run_desc(run);
    size_t hb = can->frame_count; /* can_run's heartbeat index: the status TPDO's frame */
    unsigned *work = calloc(COUNT(optional_comm) + 2u * d->tpdo_count + d->object_count + 1u, sizeof *work);
    size_t manufacturers;
    if (work == NULL) {
        return -1;
    }
    put_file_info(out, d, source);
    put_device_info(out, co, can, d);
    put_dummy_usage(out, d);
    put_comments(out, can, d, hb);
    put_lists(out, d, work);
    put_communication(out, d);
    for (size_t n = 0; n < d->tpdo_count; n++) {
        put_tpdo(out, node, n);
    }
    manufacturers = manufacturer_indices(d, work);
    put_manufacturer(out, run, can, hb, work, manufacturers);
    free(work);
    return fflush(out) == 0 && !ferror(out) ? 0 : -1;
}
