/* SPDX-License-Identifier: MIT */
/* eds.c: see eds.h. The object dictionary written here is lib/urrt_co.c's
 * (docs/canopen.md's table): communication objects as the node serves them
 * (the TPDOs', and with [input]s the RPDOs' and 0x1016), the manufacturer
 * objects from the node's description: the TPDOs' signals, read-only, and
 * the [input]s' variables (co_run.h: 0x2200 + i - 1 sub k + 1), rww. */
#include "eds.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rtde_only.h"
#include "dbc.h"

#define ACCESS_RO "ro"
#define ACCESS_RW "rw"
#define ACCESS_WO "wo"
#define ACCESS_RWW "rww" /* CiA 306: read/write, mappable to an RPDO (a process output of the manager) */
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
    fprintf(out, "Description=urrt-gateway CANopen node%s%s: Universal Robots RealTime data as TPDOs%s\n",
            source ? " from " : "", source ? source : "",
            d->rpdo_count > 0 ? ", robot input registers from RPDOs" : "");
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
                 "GroupMessaging=0\nNrOfRXPDO=%zu\nNrOfTXPDO=%zu\nLSS_Supported=0\n\n",
            d->rpdo_count, d->tpdo_count);
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
    for (size_t n = 0; n < d->rpdo_count; n++) {
        for (size_t i = 0; i < d->rpdos[n].mapping_count; i++) {
            if (d->rpdos[n].mapping[i] >> 16 == CANOPEN_DUMMY_U8) {
                return true;
            }
        }
    }
    return false;
}

/* Whether an RPDO's mapping names the object (a variable's PDOMapping). */
static bool rpdo_mapped(const urrt_co_desc *d, uint16_t index, uint8_t sub)
{
    for (size_t n = 0; n < d->rpdo_count; n++) {
        for (size_t i = 0; i < d->rpdos[n].mapping_count; i++) {
            if (d->rpdos[n].mapping[i] >> 8 == ((uint32_t)index << 8 | sub)) {
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

/* The [input] signal a variable of the description is (co_run.h: [input] i's
 * signal k at 0x2200 + i sub k + 1), or NULL. */
static const struct can_map_frame *input_of(const struct can_map *can, const urrt_co_object *o, size_t *signal)
{
    size_t i = (size_t)o->index - CANOPEN_INPUTS_INDEX;
    if (o->kind != URRT_CO_VAR || o->index < CANOPEN_INPUTS_INDEX || i >= can->input_count || o->sub < 1u ||
        o->sub > can->inputs[i].count) {
        return NULL;
    }
    *signal = o->sub - 1u;
    return &can->inputs[i];
}

/* What a variable of an [input] writes, in words, as object_name says what a
 * TPDO's object carries: the signal, the register, the scaling. */
static void input_name(const struct can_map_frame *f, size_t k, char *buf, size_t size)
{
    const struct can_map_signal *m = &f->meta[k];
    char reg[48], fac[32], off[32];
    value_name(m, reg, sizeof reg);
    if (m->bitmask) {
        snprintf(buf, size, "%s: %s, a bit mask as the robot takes it", m->name, reg);
        return;
    }
    snprintf(buf, size, "%s: %s, %s = raw x %s + %s", m->name, reg, m->unit[0] ? m->unit : "1",
             dbc_number(f->sigs[k].factor, fac, sizeof fac), dbc_number(f->sigs[k].offset, off, sizeof off));
}

static bool is_robot_value(const struct can_map *can, const urrt_co_object *o, size_t hb)
{
    if (o->kind != URRT_CO_SIGNAL || o->frame == hb) {
        return false;
    }
    enum can_map_role role = can->frames[o->frame].meta[o->item].role;
    return role == CAN_MAP_ROLE_FIELD || role == CAN_MAP_ROLE_RTDE;
}

/* [Comments]' notes on the receiving side, with [input]s. */
static const char *const rx_notes[] = {
    "RPDO transmission type (0x14xx sub 2): 0..240 (acted on at the next SYNC), 254, 255 (at once); 241..253 are "
    "refused",
    "RPDO event timer (0x14xx sub 5): the deadline in ms, EMCY 0x8250 when late; an RPDO shorter than its mapping "
    "is not processed, EMCY 0x8210 (byte 5: the RPDO)",
    "0x1016 sub 1: the manager's heartbeat (node id << 16 | ms), off until written; EMCY 0x8130 when it is late",
    "Robot input registers (0x22xx): physical = raw x factor + offset, as each ParameterName says; the node stores "
    "a raw value within LowLimit..HighLimit, the gateway writes the register only with a value within the limits "
    "below (never clamped)",
};

/* The physical limits an [input] signal's register is written within: its
 * min..max, narrowed to what its object stores (LowLimit..HighLimit). */
static void input_limits(const struct can_map_frame *f, size_t k, const urrt_co_object *o, double *lo, double *hi)
{
    const urrt_can_signal *sig = &f->sigs[k];
    double a = urrt_can_from_raw(sig, o->min), b = urrt_can_from_raw(sig, o->max);
    double low = a < b ? a : b, high = a < b ? b : a;
    *lo = sig->min > low ? sig->min : low;
    *hi = sig->max < high ? sig->max : high;
}

/* [Comments]: the notes, then the scaling of every mapped robot value with
 * its limits, then with [input]s their notes and each register's scaling
 * with the limits the gateway writes it within. */
static void put_comments(FILE *out, const struct can_map *can, const urrt_co_desc *d, size_t hb)
{
    size_t lines = 4, signal;
    for (size_t i = 0; i < d->object_count; i++) {
        lines += is_robot_value(can, &d->objects[i], hb) || input_of(can, &d->objects[i], &signal) != NULL;
    }
    lines += d->rpdo_count > 0 ? COUNT(rx_notes) : 0u;
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
    for (size_t i = 0; d->rpdo_count > 0 && i < COUNT(rx_notes); i++) {
        fprintf(out, "Line%zu=%s\n", ++lines, rx_notes[i]);
    }
    for (size_t i = 0; i < d->object_count; i++) {
        const urrt_co_object *o = &d->objects[i];
        const struct can_map_frame *f = input_of(can, o, &signal);
        char name[160], lo[32], hi[32];
        double low, high;
        if (f == NULL) {
            continue;
        }
        input_name(f, signal, name, sizeof name);
        if (f->meta[signal].bitmask) {
            fprintf(out, "Line%zu=0x%04X sub %u %s: no limits\n", ++lines, o->index, o->sub, name);
        } else {
            input_limits(f, signal, o, &low, &high);
            fprintf(out, "Line%zu=0x%04X sub %u %s, limits %s..%s\n", ++lines, o->index, o->sub, name,
                    dbc_number(low, lo, sizeof lo), dbc_number(high, hi, sizeof hi));
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
    if ((row->flags & URRT_CO_PER_RPDO) != 0u) {
        return canopen_predefined_rpdo_id((unsigned)n + 1u, d->node_id);
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

/* A variable's raw value as a decimal of its type (INTEGERn sign-extended). */
static void var_number(uint8_t type, uint32_t raw, char *buf, size_t size)
{
    unsigned bits = type == URRT_CO_INTEGER8 || type == URRT_CO_UNSIGNED8    ? 8u
                    : type == URRT_CO_INTEGER16 || type == URRT_CO_UNSIGNED16 ? 16u
                                                                              : 32u;
    uint32_t mask = bits == 32u ? UINT32_MAX : ((uint32_t)1u << bits) - 1u;
    bool is_signed = type == URRT_CO_INTEGER8 || type == URRT_CO_INTEGER16 || type == URRT_CO_INTEGER32;
    raw &= mask;
    if (is_signed && (raw >> (bits - 1u) & 1u) != 0u) {
        snprintf(buf, size, "-%lu", (unsigned long)(mask - raw) + 1ul);
    } else {
        snprintf(buf, size, "%lu", (unsigned long)raw);
    }
}

/* A variable of the description (an [input]'s register): its name, its
 * range as LowLimit/HighLimit, rww where an RPDO maps it. */
static void put_variable(FILE *out, const struct can_map *can, const urrt_co_desc *d, const urrt_co_object *o)
{
    char what[200], low[16], high[16], def[16];
    size_t signal;
    const struct can_map_frame *f = input_of(can, o, &signal);
    bool mapped = rpdo_mapped(d, o->index, o->sub);
    const char *access = o->access == URRT_CO_RO ? ACCESS_RO : o->access == URRT_CO_WO ? ACCESS_WO
                         : mapped                ? ACCESS_RWW
                                                 : ACCESS_RW;
    if (f != NULL) {
        input_name(f, signal, what, sizeof what);
    } else {
        snprintf(what, sizeof what, "Variable 0x%04X sub %u", o->index, o->sub);
    }
    var_number(o->type, o->min, low, sizeof low);
    var_number(o->type, o->max, high, sizeof high);
    var_number(o->type, o->def, def, sizeof def);
    put_var(out, &(struct eds_var){o->index, o->sub, what, o->type, access, def, mapped, low, high});
}

static void put_manufacturer(FILE *out, const struct co_run *run, const struct can_map *can, size_t hb,
                             const unsigned *indices, size_t count)
{
    const urrt_co_desc *d = co_run_desc(run);
    for (size_t x = 0; x < count; x++) {
        unsigned highest = 0;
        char name[160];
        size_t input = (size_t)indices[x] - CANOPEN_INPUTS_INDEX;
        for (size_t i = 0; i < d->object_count; i++) {
            highest = d->objects[i].index == indices[x] && d->objects[i].sub > highest ? d->objects[i].sub : highest;
        }
        if (indices[x] == CANOPEN_STATUS_INDEX) {
            snprintf(name, sizeof name, "Gateway status (TPDO%zu, docs/can.md's heartbeat layout)", d->tpdo_count);
        } else if (indices[x] >= CANOPEN_INPUTS_INDEX && input < can->input_count) {
            const struct can_map_frame *f = &can->inputs[input];
            snprintf(name, sizeof name, "RPDO%zu values ([input %s]: robot %s's input registers)", input + 1u, f->name,
                     f->robot_index < can->robot_count ? can->robots[f->robot_index].name : f->robot);
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
            if (o->kind == URRT_CO_VAR) {
                put_variable(out, can, d, o);
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
