/* SPDX-License-Identifier: MIT */
/* can_ctables.c: see can_ctables.h. */
#include "can_ctables.h"

#include <ctype.h>
#include <inttypes.h>

/* Doubles as C constants that read back to the same bits. */
static void put_double(FILE *out, double v)
{
    fprintf(out, "%.17g", v);
}

static const char *const kind_names[] = {
    [URRT_CANTX_FIELD] = "URRT_CANTX_FIELD",   [URRT_CANTX_FIELD_MASK] = "URRT_CANTX_FIELD_MASK",
    [URRT_CANTX_ALIVE] = "URRT_CANTX_ALIVE",   [URRT_CANTX_VALID] = "URRT_CANTX_VALID",
    [URRT_CANTX_FILLED] = "URRT_CANTX_FILLED", [URRT_CANTX_FILLED_MASK] = "URRT_CANTX_FILLED_MASK",
};

/* A firmware reads RealTime, which has no RTDE-only value: a table that
 * names one would not build (its frame has no fill function there), so the
 * source says why instead, where the compiler stops. */
static void put_rtde_refusal(FILE *out, const struct can_map *map)
{
    for (size_t i = 0; i < map->frame_count; i++) {
        for (size_t k = 0; k < map->frames[i].count; k++) {
            const struct can_map_signal *m = &map->frames[i].meta[k];
            if (m->role == CAN_MAP_ROLE_RTDE) {
                fprintf(out, "#error \"[frame %s] signal %s (line %d) is an RTDE-only value: a firmware reads "
                             "RealTime, which has none; leave this frame to urrt-gateway or map RealTime fields\"\n",
                        map->frames[i].name, m->name, m->loc.line);
            }
        }
    }
}

static const char *const stale_names[] = {
    [URRT_CANTX_STALE_STOP] = "URRT_CANTX_STALE_STOP",
    [URRT_CANTX_STALE_INVALID] = "URRT_CANTX_STALE_INVALID",
    [URRT_CANTX_STALE_IGNORE] = "URRT_CANTX_STALE_IGNORE",
};

/* URRT_F_Q_ACTUAL for q_actual: lib/urrt.h's ids are the names in capitals. */
static void put_field_id(FILE *out, unsigned field)
{
    const char *name = urrt_field((urrt_field_id)field)->name;
    fputs("URRT_F_", out);
    for (; *name != '\0'; name++) {
        fputc(toupper((unsigned char)*name), out);
    }
}

/* A descriptor's flags as urrt_can.h's macros: a bit mask's first bit by name. */
static void put_flags(FILE *out, uint8_t flags)
{
    bool invalid = (flags & URRT_CAN_SIG_INVALID_RAW) != 0u;
    if ((flags & URRT_CAN_SIG_BITMASK) != 0u) {
        fprintf(out, "URRT_CAN_SIG_MASK(%u)%s", URRT_CAN_SIG_MASK_FIRST(flags),
                invalid ? " | URRT_CAN_SIG_INVALID_RAW" : "");
    } else {
        fputs(invalid ? "URRT_CAN_SIG_INVALID_RAW" : "0", out);
    }
}

static void put_signal(FILE *out, const urrt_can_signal *s, const char *name)
{
    fputs("    {", out);
    put_double(out, s->factor);
    fputs(", ", out);
    put_double(out, s->offset);
    fputs(", ", out);
    put_double(out, s->min);
    fputs(", ", out);
    put_double(out, s->max);
    fprintf(out, ", UINT64_C(0x%" PRIX64 "), %u, %u, %s, %s, ", s->invalid_raw, s->start, s->length,
            s->byte_order == URRT_CAN_MOTOROLA ? "URRT_CAN_MOTOROLA" : "URRT_CAN_INTEL",
            s->type == URRT_CAN_SIGNED    ? "URRT_CAN_SIGNED"
            : s->type == URRT_CAN_FLOAT32 ? "URRT_CAN_FLOAT32"
            : s->type == URRT_CAN_FLOAT64 ? "URRT_CAN_FLOAT64"
                                          : "URRT_CAN_UNSIGNED");
    put_flags(out, s->flags);
    fprintf(out, "}, /* %s */\n", name);
}

static void put_source(FILE *out, const urrt_cantx_source *src)
{
    fprintf(out, "    {%s, ", kind_names[src->kind]);
    if (src->kind == URRT_CANTX_FIELD || src->kind == URRT_CANTX_FIELD_MASK) {
        put_field_id(out, src->field);
    } else {
        fputc('0', out);
    }
    fprintf(out, ", %u},\n", src->elem);
}

static void put_frame_tables(FILE *out, const struct can_map_frame *f, const urrt_cantx_frame *t)
{
    fprintf(out, "/* [frame %s] */\nstatic const urrt_can_signal frame_%s_signals[%u] = {\n", f->name, f->name,
            t->signal_count);
    for (size_t k = 0; k < t->signal_count; k++) {
        put_signal(out, &t->signals[k], f->meta[k].name);
    }
    fprintf(out, "};\nstatic const urrt_cantx_source frame_%s_sources[%u] = {\n", f->name, t->signal_count);
    for (size_t k = 0; k < t->signal_count; k++) {
        put_source(out, &t->sources[k]);
    }
    fprintf(out, "};\n\n");
}

static void put_frame(FILE *out, const char *name, const urrt_cantx_frame *t, bool heartbeat)
{
    fprintf(out, "    {");
    if (heartbeat) {
        fprintf(out, "urrt_cantx_heartbeat_signals, urrt_cantx_heartbeat_sources, URRT_CANTX_HB_COUNT");
    } else {
        fprintf(out, "frame_%s_signals, frame_%s_sources, %u", name, name, t->signal_count);
    }
    fprintf(out, ", %u, %s, 0x%" PRIX32 ", %" PRIu32 ", %" PRIu32 ", %s, %u, %s}, /* %s */\n", t->len,
            t->flags == (URRT_CANTX_EXTENDED | URRT_CANTX_FD) ? "URRT_CANTX_EXTENDED | URRT_CANTX_FD"
            : t->flags == URRT_CANTX_EXTENDED                 ? "URRT_CANTX_EXTENDED"
            : t->flags == URRT_CANTX_FD                       ? "URRT_CANTX_FD"
                                                              : "0",
            t->id, t->period_us, t->stale_after_us, stale_names[t->stale], t->robot,
            heartbeat ? "urrt_cantx_heartbeat_fill" : "NULL", name);
}

static void put_storage(FILE *out, const urrt_cantx_tables *t)
{
    size_t values = urrt_cantx_value_count(t);
    fprintf(out, "const urrt_cantx_tables urrt_gateway_tables = {urrt_gateway_frames, %zu, %zu, %" PRIu32 "};\n\n",
            t->frame_count, t->robot_count, t->startup_us);
    fprintf(out, "static urrt_cantx_frame_state urrt_gateway_states[%zu];\n", t->frame_count);
    fprintf(out, "static urrt_cantx_robot urrt_gateway_robots[%zu];\n", t->robot_count);
    fprintf(out, "static double urrt_gateway_values[%zu];\n", values);
    fprintf(out, "static urrt_can_scale urrt_gateway_scales[%zu];\n\n", values);
    fprintf(out, "/* The tables checked, then every signal's scale prepared once (urrt_cantx_prepare):\n"
                 " * packing without a division, a tenth of the instructions on a Cortex-M4. */\n"
                 "int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal)\n{\n"
                 "    int rc = urrt_cantx_init(tx, &urrt_gateway_tables, urrt_gateway_states, urrt_gateway_robots,\n"
                 "                             urrt_gateway_values, %zu, bad_frame, bad_signal);\n"
                 "    return rc != 0 ? rc : urrt_cantx_prepare(tx, urrt_gateway_scales, %zu);\n}\n",
            values, values);
}

/* ---- the CANopen node: its urrt_co_desc, from co_run's ---------------------------- */

static const char *const co_type_names[] = {
    [URRT_CO_INTEGER8] = "URRT_CO_INTEGER8",   [URRT_CO_INTEGER16] = "URRT_CO_INTEGER16",
    [URRT_CO_INTEGER32] = "URRT_CO_INTEGER32", [URRT_CO_UNSIGNED8] = "URRT_CO_UNSIGNED8",
    [URRT_CO_UNSIGNED16] = "URRT_CO_UNSIGNED16", [URRT_CO_UNSIGNED32] = "URRT_CO_UNSIGNED32",
    [URRT_CO_REAL32] = "URRT_CO_REAL32",
};

/* A C string literal of a configuration text (conf_text keeps '"', '\\'
 * and control characters out of it). */
static void put_string(FILE *out, const char *s)
{
    fprintf(out, "\"%s\"", s != NULL ? s : "");
}

static void put_tpdos(FILE *out, const urrt_co_desc *d)
{
    for (size_t n = 0; n < d->tpdo_count; n++) {
        const urrt_co_tpdo *p = &d->tpdos[n];
        fprintf(out, "static const uint32_t urrt_gateway_tpdo%zu_mapping[%u] = {", n + 1u, p->mapping_count);
        for (unsigned k = 0; k < p->mapping_count; k++) {
            fprintf(out, "%sUINT32_C(0x%08" PRIX32 ")", k % 4u == 0u ? "\n    " : " ", p->mapping[k]);
            fputc(k + 1u < p->mapping_count ? ',' : '\n', out);
        }
        fprintf(out, "};\n");
    }
    fprintf(out, "static const urrt_co_tpdo urrt_gateway_tpdos[%zu] = {\n", d->tpdo_count);
    for (size_t n = 0; n < d->tpdo_count; n++) {
        const urrt_co_tpdo *p = &d->tpdos[n];
        fprintf(out, "    {urrt_gateway_tpdo%zu_mapping, UINT32_C(0x%08" PRIX32 "), %u, %u, %u, %u}, /* TPDO%zu */\n",
                n + 1u, p->cob_id, p->frame, p->inhibit_100us, p->transmission_type, p->mapping_count,
                n + 1u);
    }
    fprintf(out, "};\n");
}

static void put_objects(FILE *out, const urrt_co_desc *d)
{
    fprintf(out, "static const urrt_co_object urrt_gateway_objects[%zu] = {\n", d->object_count);
    for (size_t i = 0; i < d->object_count; i++) {
        const urrt_co_object *o = &d->objects[i];
        fprintf(out, "    {0x%04X, %u, %s, %s, %s, %u, %u, %" PRIu32 ", %" PRIu32 ", %" PRIu32 "},\n", o->index,
                o->sub, co_type_names[o->type], o->access == URRT_CO_RO ? "URRT_CO_RO" : o->access == URRT_CO_WO
                ? "URRT_CO_WO" : "URRT_CO_RW", o->kind == URRT_CO_SIGNAL ? "URRT_CO_SIGNAL" : "URRT_CO_VAR",
                o->frame, o->item, o->def, o->min, o->max);
    }
    fprintf(out, "};\n");
}

static void put_node(FILE *out, struct co_run *node)
{
    const urrt_co_desc *d = co_run_desc(node);
    size_t rx_count;
    const uint32_t *rx = co_run_rx_ids(node, &rx_count);
    fprintf(out, "\n/* The CANopen node over these tables (lib/urrt_co.h, docs/canopen.md). */\n");
    put_tpdos(out, d);
    put_objects(out, d);
    fprintf(out, "const urrt_co_desc urrt_gateway_node = {\n    %u, %s, %u, %u, %" PRIu32 ",\n"
                 "    UINT32_C(0x%08" PRIX32 "), UINT32_C(0x%08" PRIX32 "), UINT32_C(0x%08" PRIX32 "), "
                 "UINT32_C(0x%08" PRIX32 "), UINT32_C(0x%08" PRIX32 "),\n    ",
            d->node_id, d->nmt_start == URRT_CO_START_OPERATIONAL ? "URRT_CO_START_OPERATIONAL"
                                                                  : "URRT_CO_START_PRE_OPERATIONAL",
            d->heartbeat_ms, d->sdo_timeout_ms, d->stale_after_us, d->device_type, d->vendor_id, d->product_code,
            d->revision, d->serial);
    put_string(out, d->device_name);
    fputs(", ", out);
    put_string(out, d->hardware_version);
    fputs(", ", out);
    put_string(out, d->software_version);
    fprintf(out, ",\n    urrt_gateway_tpdos, %zu, urrt_gateway_objects, %zu};\n", d->tpdo_count, d->object_count);
    fprintf(out, "const uint32_t urrt_gateway_rx_ids[%zu] = {", rx_count);
    for (size_t i = 0; i < rx_count; i++) {
        fprintf(out, "%s0x%03" PRIX32, i ? ", " : "", rx[i]);
    }
    fprintf(out, "};\nstatic urrt_co_tpdo_state urrt_gateway_tpdo_states[%zu];\n"
                 "static uint32_t urrt_gateway_vars[1];\n\n"
                 "int urrt_gateway_co_init(urrt_co *co, urrt_cantx *tx, size_t *bad_item)\n{\n"
                 "    return urrt_co_init(co, &urrt_gateway_node, tx, urrt_gateway_tpdo_states, urrt_gateway_vars, 1,\n"
                 "                        bad_item);\n}\n",
            d->tpdo_count);
}

int can_ctables_write(FILE *out, const struct can_map *map, struct can_run *run, struct co_run *node,
                      const char *source)
{
    const urrt_cantx_tables *t = can_run_tx(run)->tables;
    fprintf(out, "/* SPDX-License-Identifier: MIT */\n"
                 "/*\n * Generated by urrt-gateway %s --print-c-tables from %s: its CAN frames as\n"
                 " * lib/urrt_cantx.h tables, for a firmware that sends what urrt-gateway sends.\n"
                 " * Do not edit: change the configuration and generate again. Use:\n"
                 " *     extern const urrt_cantx_tables urrt_gateway_tables;\n"
                 " *     int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal);\n"
                 " * (urrt_cantx_init and urrt_cantx_prepare over the storage below). Robots by index:",
            URRT_VERSION_STRING, source);
    for (size_t i = 0; i < map->robot_count; i++) {
        fprintf(out, " %zu %s", i, map->robots[i].name);
    }
    if (node != NULL) {
        fprintf(out, ".\n * The CANopen node ([canopen]), over urrt_cantx_init's tx:\n"
                     " *     extern const urrt_co_desc urrt_gateway_node;\n"
                     " *     extern const uint32_t urrt_gateway_rx_ids[%d];   the ids it receives\n"
                     " *     int urrt_gateway_co_init(urrt_co *co, urrt_cantx *tx, size_t *bad_item)",
                (int)CO_RUN_RX_IDS);
    }
    fprintf(out, ".\n */\n#include <stddef.h>\n#include <stdint.h>\n\n#include \"%s\"\n\n",
            node != NULL ? "urrt_co.h" : "urrt_cantx.h");
    put_rtde_refusal(out, map);
    for (size_t i = 0; i < map->frame_count; i++) {
        put_frame_tables(out, &map->frames[i], &t->frames[i]);
    }
    fprintf(out, "static const urrt_cantx_frame urrt_gateway_frames[%zu] = {\n", t->frame_count);
    for (size_t i = 0; i < t->frame_count; i++) {
        bool hb = i == can_run_heartbeat_index(run);
        put_frame(out, hb ? CAN_MAP_HEARTBEAT_NAME : map->frames[i].name, &t->frames[i], hb);
    }
    fprintf(out, "};\n\n");
    put_storage(out, t);
    if (node != NULL) {
        put_node(out, node);
    }
    return ferror(out) ? -1 : 0;
}
