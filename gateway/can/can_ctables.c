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
    [URRT_CANTX_FILLED] = "URRT_CANTX_FILLED",
};

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
    fprintf(out, ", UINT64_C(0x%" PRIX64 "), %u, %u, %s, %s, %s}, /* %s */\n", s->invalid_raw, s->start, s->length,
            s->byte_order == URRT_CAN_MOTOROLA ? "URRT_CAN_MOTOROLA" : "URRT_CAN_INTEL",
            s->type == URRT_CAN_SIGNED    ? "URRT_CAN_SIGNED"
            : s->type == URRT_CAN_FLOAT32 ? "URRT_CAN_FLOAT32"
            : s->type == URRT_CAN_FLOAT64 ? "URRT_CAN_FLOAT64"
                                          : "URRT_CAN_UNSIGNED",
            s->flags & URRT_CAN_SIG_INVALID_RAW ? "URRT_CAN_SIG_INVALID_RAW" : "0", name);
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
    fprintf(out, "static double urrt_gateway_values[%zu];\n\n", values);
    fprintf(out, "int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal)\n{\n"
                 "    return urrt_cantx_init(tx, &urrt_gateway_tables, urrt_gateway_states, urrt_gateway_robots,\n"
                 "                           urrt_gateway_values, %zu, bad_frame, bad_signal);\n}\n",
            values);
}

int can_ctables_write(FILE *out, struct can_map *map, const char *source)
{
    urrt_cantx *tx = can_map_tx(map);
    const urrt_cantx_tables *t;
    if (tx == NULL) {
        return -1;
    }
    t = tx->tables;
    fprintf(out, "/* SPDX-License-Identifier: MIT */\n"
                 "/*\n * Generated by urrt-gateway %s --print-c-tables from %s: its CAN frames as\n"
                 " * lib/urrt_cantx.h tables, for a firmware that sends what urrt-gateway sends.\n"
                 " * Do not edit: change the configuration and generate again. Use:\n"
                 " *     extern const urrt_cantx_tables urrt_gateway_tables;\n"
                 " *     int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal);\n"
                 " * Robots by index:",
            URRT_VERSION_STRING, source);
    for (size_t i = 0; i < map->robot_count; i++) {
        fprintf(out, " %zu %s", i, map->robots[i].name);
    }
    fprintf(out, ".\n */\n#include <stddef.h>\n#include <stdint.h>\n\n#include \"urrt_cantx.h\"\n\n");
    for (size_t i = 0; i < map->frame_count; i++) {
        put_frame_tables(out, &map->frames[i], &t->frames[i]);
    }
    fprintf(out, "static const urrt_cantx_frame urrt_gateway_frames[%zu] = {\n", t->frame_count);
    for (size_t i = 0; i < t->frame_count; i++) {
        bool hb = i == can_map_heartbeat_index(map);
        put_frame(out, hb ? CAN_MAP_HEARTBEAT_NAME : map->frames[i].name, &t->frames[i], hb);
    }
    fprintf(out, "};\n\n");
    put_storage(out, t);
    return ferror(out) ? -1 : 0;
}
