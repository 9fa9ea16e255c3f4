/* SPDX-License-Identifier: MIT */
/* eds.c: see eds.h. The object dictionary written here is lib/urrt_co.c's
 * (docs/canopen.md's table): communication objects as the node serves them,
 * the TPDOs and manufacturer objects from the node's description. */
#include "eds.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rtde_only.h"
#include "dbc.h"

#define ACCESS_RO "ro"
#define ACCESS_RW "rw"
#define OBJ_VAR 0x7u
#define OBJ_ARRAY 0x8u
#define OBJ_RECORD 0x9u
#define EMCY_INDEX 0x1014u
#define EMCY_BASE 0x080u
#define COUNT(a) (sizeof a / sizeof a[0])

static const unsigned mandatory_indices[] = {0x1000, 0x1001, 0x1018}; /* CiA 301 */

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

static void put_small(FILE *out, unsigned index, int sub, const char *name, unsigned type, const char *access,
                      unsigned value)
{
    char def[16];
    snprintf(def, sizeof def, "%u", value);
    put_var(out, &(struct eds_var){index, sub, name, type, access, def, false, NULL, NULL});
}

/* ---- the sections before the objects ------------------------------------------------- */

static const unsigned baud_kbits[] = {10, 20, 50, 125, 250, 500, 800, 1000};

/* When the EDS was made: SOURCE_DATE_EPOCH when set (reproducible builds),
 * else now. */
static struct tm made_at(void)
{
    const char *epoch = getenv("SOURCE_DATE_EPOCH");
    char *end = NULL;
    time_t t = time(NULL);
    struct tm tm = {0};
    if (epoch != NULL && *epoch != '\0') {
        long long v = strtoll(epoch, &end, 10);
        t = *end == '\0' && v >= 0 ? (time_t)v : t;
    }
    gmtime_r(&t, &tm);
    return tm;
}

/* FileName: the file written (its last path component), or the default
 * name when the EDS goes to standard output. CiA 306's dates: the time
 * "hh:mm" with AM or PM, the date "mm-dd-yyyy". */
static void put_file_info(FILE *out, const urrt_co_desc *d, const char *source, const char *file_name)
{
    struct tm tm = made_at();
    const char *slash = file_name != NULL ? strrchr(file_name, '/') : NULL;
    char when[48];
    if (file_name != NULL) {
        fprintf(out, "[FileInfo]\nFileName=%s\n", slash != NULL ? slash + 1 : file_name);
    } else {
        fprintf(out, "[FileInfo]\nFileName=urrt-node%u.eds\n", (unsigned)d->node_id);
    }
    fprintf(out, "FileVersion=1\nFileRevision=0\nEDSVersion=4.0\n");
    fprintf(out, "Description=urrt-gateway CANopen node%s%s: Universal Robots RealTime data as TPDOs\n",
            source ? " from " : "", source ? source : "");
    snprintf(when, sizeof when, "%02d:%02d%s", tm.tm_hour % 12 == 0 ? 12 : tm.tm_hour % 12, tm.tm_min,
             tm.tm_hour < 12 ? "AM" : "PM");
    fprintf(out, "CreationTime=%s\nModificationTime=%s\n", when, when);
    snprintf(when, sizeof when, "%02d-%02d-%04d", tm.tm_mon + 1, tm.tm_mday, tm.tm_year + 1900);
    fprintf(out, "CreationDate=%s\nModificationDate=%s\n", when, when);
    fprintf(out, "CreatedBy=urrt-gateway %s --print-eds\nModifiedBy=urrt-gateway %s --print-eds\n\n",
            URRT_VERSION_STRING, URRT_VERSION_STRING);
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

/* The robot value a signal carries, by name: q_actual[2], output_int_register_24. */
static void value_name(const struct can_map_signal *m, char *buf, size_t size)
{
    const urrt_field_info *info = m->role == CAN_MAP_ROLE_FIELD ? urrt_field((urrt_field_id)m->field) : NULL;
    char rtde[URRT_RTDE_NAME_MAX] = "?";
    const char *name = info != NULL ? info->name : rtde;
    unsigned count = info != NULL ? info->count : rtde_only_elements(m->var);
    if (m->role == CAN_MAP_ROLE_RTDE) {
        (void)urrt_rtde_var_name(m->var, rtde, sizeof rtde);
    }
    if (count > 1) {
        snprintf(buf, size, "%s[%u]", name, m->elem);
    } else {
        snprintf(buf, size, "%s", name);
    }
}

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
    if (m->role != CAN_MAP_ROLE_FIELD && m->role != CAN_MAP_ROLE_RTDE) {
        snprintf(buf, size, "%s %s", fr->name,
                 m->role == CAN_MAP_ROLE_ALIVE ? "alive counter (+1 per TPDO sent)" : "valid (1: fresh and exact)");
        return;
    }
    char field[48];
    value_name(m, field, sizeof field);
    if (m->bitmask) {
        snprintf(buf, size, "%s: %s, a bit mask as the robot sends it", m->name, field);
        return;
    }
    snprintf(buf, size, "%s: %s, %s = raw x %s + %s", m->name, field, m->unit[0] ? m->unit : "1",
             dbc_number(sig->factor, f, sizeof f), dbc_number(sig->offset, off, sizeof off));
}

static bool is_robot_value(const struct can_map *can, const urrt_co_object *o, size_t hb)
{
    if (o->frame == hb) {
        return false;
    }
    enum can_map_role role = can->frames[o->frame].meta[o->item].role;
    return role == CAN_MAP_ROLE_FIELD || role == CAN_MAP_ROLE_RTDE;
}

/* [Comments]: two notes, then the scaling of every mapped robot value with its limits. */
static void put_comments(FILE *out, const struct can_map *can, const urrt_co_desc *d, size_t hb)
{
    size_t lines = 4;
    for (size_t i = 0; i < d->object_count; i++) {
        lines += is_robot_value(can, &d->objects[i], hb);
    }
    fprintf(out, "[Comments]\nLines=%zu\n", lines);
    fprintf(out, "Line1=Robot values: physical = raw x factor + offset, as each ParameterName says "
                 "(docs/canopen.md)\n");
    fprintf(out, "Line2=EMCY 0xFF01 robot link down, 0xFF02 robot data stale; TPDO%zu (status) is off until enabled\n",
            d->tpdo_count);
    fprintf(out, "Line3=TPDO transmission type (0x18xx sub 2): 1..240 (every nth SYNC), 254, 255; "
                 "0 and 241..253 are refused\n");
    fprintf(out, "Line4=TPDO event timer (0x18xx sub 5) 0: no timer, the TPDO goes with each robot packet; "
                 "the inhibit time (sub 3) is a least gap between two\n");
    lines = 4;
    for (size_t i = 0; i < d->object_count; i++) {
        const urrt_co_object *o = &d->objects[i];
        char name[160], lo[32], hi[32];
        if (!is_robot_value(can, o, hb)) {
            continue;
        }
        const urrt_can_signal *sig = &can->frames[o->frame].sigs[o->item];
        object_name(can, o, hb, name, sizeof name);
        if (can->frames[o->frame].meta[o->item].bitmask) {
            fprintf(out, "Line%zu=0x%04X sub %u %s: no limits\n", ++lines, o->index, o->sub, name);
        } else {
            fprintf(out, "Line%zu=0x%04X sub %u %s, limits %s..%s\n", ++lines, o->index, o->sub, name,
                    dbc_number(sig->min, lo, sizeof lo), dbc_number(sig->max, hi, sizeof hi));
        }
    }
    fputc('\n', out);
}

/* ---- the communication objects: lib/urrt_co's table, read on the node -------------------- */

static bool is_header(const urrt_co_comm *row)
{
    return row->subs == 0u;
}

/* The pre-defined id a COB-ID counts from the node id (CiA 301), or 0. */
static uint32_t predefined_id(const urrt_co_desc *d, const urrt_co_comm *row, size_t n)
{
    uint32_t pre;
    if (row->index == EMCY_INDEX) {
        return EMCY_BASE + d->node_id;
    }
    pre = canopen_predefined_tpdo_id((unsigned)n + 1u, d->node_id);
    return pre != 0 || n + 1u != d->tpdo_count ? pre : CANOPEN_STATUS_ID_BASE + d->node_id;
}

/* A DefaultValue: the value right after a reset (urrt_co.h), with $NODEID
 * where it is the pre-defined id (CiA 306); 0 where no value is there yet
 * (0x1003's codes). */
static void default_text(const urrt_co *node, const urrt_co_comm *row, size_t n, uint8_t sub, char *buf,
                         size_t size)
{
    urrt_co_value v;
    uint32_t pre = (row->flags & URRT_CO_NODE_ID) != 0u ? predefined_id(node->desc, row, n) : 0u;
    if (urrt_co_comm_read(node, row, n, sub, &v) != 0u) {
        v.value = 0;
        v.text = NULL;
    }
    if (v.text != NULL) {
        snprintf(buf, size, "%.*s", (int)v.size, v.text);
    } else if (pre != 0 && (v.value & 0x7FFu) == pre) {
        snprintf(buf, size, "$NODEID+0x%X", (unsigned)((v.value & ~UINT32_C(0x7FF)) | (pre - node->desc->node_id)));
    } else if (row->type == URRT_CO_UNSIGNED32) {
        snprintf(buf, size, "0x%08X", (unsigned)v.value);
    } else {
        snprintf(buf, size, "%u", (unsigned)v.value);
    }
}

/* The sub-indices of a header row's object that instance n has. */
static unsigned subs_present(const urrt_co *node, const urrt_co_comm *rows, size_t count, size_t n)
{
    unsigned present = 0;
    urrt_co_value v;
    for (size_t i = 1; i < count; i++) {
        for (unsigned s = rows[i].sub; s < rows[i].sub + rows[i].subs; s++) {
            present += urrt_co_comm_read(node, &rows[i], n, (uint8_t)s, &v) != URRT_CO_ABORT_NO_SUB;
        }
    }
    return present;
}

/* One row's variables of instance n: each of its sub-indices the node has. */
static void put_comm_row(FILE *out, const urrt_co *node, const urrt_co_comm *row, size_t n)
{
    unsigned index = row->index + (unsigned)n;
    urrt_co_value v;
    uint32_t lowest = 0, highest = 0;
    bool limits = urrt_co_comm_limits(row, &lowest, &highest);
    for (unsigned s = row->sub; s < row->sub + row->subs; s++) {
        char name[64], def[64], low[16], high[16];
        if (urrt_co_comm_read(node, row, n, (uint8_t)s, &v) == URRT_CO_ABORT_NO_SUB) {
            continue;
        }
        snprintf(name, sizeof name, row->subs > 1u ? "%s %u" : "%s", urrt_co_comm_name(row), s);
        default_text(node, row, n, (uint8_t)s, def, sizeof def);
        snprintf(low, sizeof low, "0x%X", (unsigned)lowest);
        snprintf(high, sizeof high, "0x%X", (unsigned)highest);
        put_var(out, &(struct eds_var){index, row->object == URRT_CO_OBJ_VAR ? -1 : (int)s, name, row->type,
                                       row->write != NULL ? ACCESS_RW : ACCESS_RO, def, false,
                                       limits ? low : NULL, limits ? high : NULL});
    }
}

/* Every object of the table, instance by instance: a header and the rows
 * of its index after it. */
static void put_communication(FILE *out, const urrt_co *node)
{
    size_t i = 0;
    while (i < urrt_co_comm_count) {
        const urrt_co_comm *first = &urrt_co_comm_table[i];
        size_t count = 1;
        while (i + count < urrt_co_comm_count && urrt_co_comm_table[i + count].index == first->index) {
            count++;
        }
        for (size_t n = 0; n < urrt_co_comm_instances(node, first); n++) {
            if (is_header(first)) {
                put_record(out, first->index + (unsigned)n, urrt_co_comm_name(first), first->object,
                           subs_present(node, first, count, n));
            }
            for (size_t k = is_header(first) ? 1u : 0u; k < count; k++) {
                put_comm_row(out, node, &first[k], n);
            }
        }
        i += count;
    }
}

/* The table's objects other than the mandatory ones, ascending: their number. */
static size_t optional_indices(const urrt_co *node, unsigned *out)
{
    size_t count = 0;
    for (size_t i = 0; i < urrt_co_comm_count; i++) {
        const urrt_co_comm *row = &urrt_co_comm_table[i];
        bool mandatory = false;
        if (i > 0 && urrt_co_comm_table[i - 1].index == row->index) {
            continue;
        }
        for (size_t k = 0; k < COUNT(mandatory_indices); k++) {
            mandatory = mandatory || mandatory_indices[k] == row->index;
        }
        for (size_t n = 0; !mandatory && n < urrt_co_comm_instances(node, row); n++) {
            out[count++] = row->index + (unsigned)n;
        }
    }
    return count;
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

static int put_lists(FILE *out, const urrt_co *node, unsigned *work)
{
    put_list(out, "MandatoryObjects", mandatory_indices, COUNT(mandatory_indices));
    put_list(out, "OptionalObjects", work, optional_indices(node, work));
    put_list(out, "ManufacturerObjects", work, manufacturer_indices(node->desc, work));
    return 0;
}

/* ---- the objects -------------------------------------------------------------------------- */

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

/* The most indices a list holds: the table's per node, and every manufacturer object. */
static size_t list_capacity(const urrt_co *node)
{
    size_t count = node->desc->object_count;
    for (size_t i = 0; i < urrt_co_comm_count; i++) {
        count += urrt_co_comm_instances(node, &urrt_co_comm_table[i]);
    }
    return count;
}

int eds_write(FILE *out, struct co_run *run, const struct canopen_map *co, const struct can_map *can,
              const char *source, const char *file_name)
{
    urrt_co *node = co_run_node(run);
    const urrt_co_desc *d = co_run_desc(run);
    size_t hb = can->frame_count; /* can_run's heartbeat index: the status TPDO's frame */
    unsigned *work = calloc(list_capacity(node), sizeof *work);
    size_t manufacturers;
    if (work == NULL) {
        return -1;
    }
    /* The defaults are the values right after a reset (urrt_co.h): reset it, silently. */
    urrt_co_start(node, 0, NULL, NULL);
    put_file_info(out, d, source, file_name);
    put_device_info(out, co, can, d);
    put_dummy_usage(out, d);
    put_comments(out, can, d, hb);
    put_lists(out, node, work);
    put_communication(out, node);
    manufacturers = manufacturer_indices(d, work);
    put_manufacturer(out, run, can, hb, work, manufacturers);
    free(work);
    return fflush(out) == 0 && !ferror(out) ? 0 : -1;
}
