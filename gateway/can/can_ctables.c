/* SPDX-License-Identifier: MIT */
/* can_ctables.c: see can_ctables.h. */
#include "can_ctables.h"

#include <ctype.h>
#include <inttypes.h>
#include <string.h>

#include "rtde_only.h"

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

/* Whether robot i is read over RTDE. */
static bool is_rtde(const struct can_ctables_robot *robots, const struct can_map *map, size_t i)
{
    return robots != NULL && i < map->robot_count && robots[i].rtde;
}

/* Whether frame f carries an RTDE-only value. */
static bool has_rtde(const struct can_map_frame *f)
{
    for (size_t k = 0; k < f->count; k++) {
        if (f->meta[k].role == CAN_MAP_ROLE_RTDE) {
            return true;
        }
    }
    return false;
}

/* A robot read over RealTime has no RTDE-only value: a table that names one
 * would not build (its frame has no fill function there), so the source
 * says why instead, where the compiler stops. (The configuration refuses
 * such a signal already; this keeps the generated file honest on its own.) */
static void put_rtde_refusal(FILE *out, const struct can_map *map, const struct can_ctables_robot *robots)
{
    for (size_t i = 0; i < map->frame_count; i++) {
        for (size_t k = 0; k < map->frames[i].count && !is_rtde(robots, map, map->frames[i].robot_index); k++) {
            const struct can_map_signal *m = &map->frames[i].meta[k];
            if (m->role == CAN_MAP_ROLE_RTDE) {
                fprintf(out, "#error \"[frame %s] signal %s (line %d) is an RTDE-only value: its robot is read over "
                             "RealTime, which has none; give the robot source = rtde or map RealTime fields\"\n",
                        map->frames[i].name, m->name, m->loc.line);
            }
        }
    }
    for (size_t i = 0; i < map->input_count; i++) {
        const struct can_map_frame *f = &map->inputs[i];
        if (!is_rtde(robots, map, f->robot_index)) {
            fprintf(out, "#error \"[input %s] (line %d) writes input registers over RTDE: its robot is read over "
                         "RealTime, which never writes; give the robot source = rtde\"\n",
                    f->name, f->loc.line);
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

/* A frame's flags (urrt_cantx_frame.flags) as urrt_cantx.h's macros. */
static const char *flag_names(uint8_t flags)
{
    return flags == (URRT_CANTX_EXTENDED | URRT_CANTX_FD) ? "URRT_CANTX_EXTENDED | URRT_CANTX_FD"
           : flags == URRT_CANTX_EXTENDED                 ? "URRT_CANTX_EXTENDED"
           : flags == URRT_CANTX_FD                       ? "URRT_CANTX_FD"
                                                          : "0";
}

/* fill: the frame has a fill function of put_rtde_fill's (frame_NAME_fill). */
static void put_frame(FILE *out, const char *name, const urrt_cantx_frame *t, bool heartbeat, bool fill)
{
    char fill_name[CAN_MAP_NAME_MAX + 16];
    snprintf(fill_name, sizeof fill_name, "frame_%s_fill", name);
    fprintf(out, "    {");
    if (heartbeat) {
        fprintf(out, "urrt_cantx_heartbeat_signals, urrt_cantx_heartbeat_sources, URRT_CANTX_HB_COUNT");
    } else {
        fprintf(out, "frame_%s_signals, frame_%s_sources, %u", name, name, t->signal_count);
    }
    fprintf(out, ", %u, %s, 0x%" PRIX32 ", %" PRIu32 ", %" PRIu32 ", %s, %u, %s}, /* %s */\n", t->len,
            flag_names(t->flags), t->id, t->period_us, t->stale_after_us, stale_names[t->stale], t->robot,
            heartbeat ? "urrt_cantx_heartbeat_fill" : fill ? fill_name : "NULL", name);
}

/* ---- RTDE robots: the recipe and the RTDE-only values ------------------------------ */

/* The trailing decimal index of an RTDE name ("output_int_register_24": 24
 * at 20), or the name's length when it has none. */
static size_t index_at(const char *name)
{
    size_t n = strlen(name);
    while (n > 0 && isdigit((unsigned char)name[n - 1])) {
        n--;
    }
    return n;
}

/* Whether vars a and b are names of one family (lib/urrt_rtde.h: a row of
 * several names, "output_int_register_" 0..47, "standard_analog_input" 0..1):
 * the same name but for the trailing index. */
static bool same_family(int a, int b)
{
    char na[URRT_RTDE_NAME_MAX];
    char nb[URRT_RTDE_NAME_MAX];
    size_t ia;
    if (!rtde_only(a) || !rtde_only(b) ||
        urrt_rtde_var_name(a, na, sizeof na) < 0 || urrt_rtde_var_name(b, nb, sizeof nb) < 0) {
        return false;
    }
    ia = index_at(na);
    return ia > 0 && ia < strlen(na) && ia == index_at(nb) && strncmp(na, nb, ia) == 0;
}

/* A variable as lib/urrt_rtde.h's enum names it: URRT_RTDE_V_ROBOT_STATUS_BITS,
 * URRT_RTDE_V_OUTPUT_INT_REGISTER + 24 (a family: its first name's id plus
 * the offset). Symbolic, so that the compiler checks it against lib/. */
static void put_var_id(FILE *out, int var)
{
    char name[URRT_RTDE_NAME_MAX];
    int first = var;
    size_t len;
    (void)urrt_rtde_var_name(var, name, sizeof name);
    while (same_family(first - 1, var)) {
        first--;
    }
    len = first != var || same_family(var + 1, var) ? index_at(name) : strlen(name);
    len -= len < strlen(name) && name[len - 1] == '_'; /* the family's enum name has no trailing '_' */
    fputs("URRT_RTDE_V_", out);
    for (size_t i = 0; i < len; i++) {
        fputc(toupper((unsigned char)name[i]), out);
    }
    if (len != strlen(name)) {
        fprintf(out, " + %d", var - first);
    }
}

/* The RTDE variable a signal needs: the one filling its field, its
 * RTDE-only value, or -1 (alive counter, validity bit). */
static int signal_var(const struct can_map_signal *m)
{
    return m->role == CAN_MAP_ROLE_FIELD  ? urrt_rtde_var_of_field((urrt_field_id)m->field)
           : m->role == CAN_MAP_ROLE_RTDE ? m->var
                                          : -1;
}

/* Robot r's recipe: the timestamp (the data's time) first, then what its
 * frames' signals need, each once, in the configuration's order. This is
 * what the gateway's CAN side asks for (its LCM messages and rtde_values
 * are not the firmware's). */
static size_t recipe_of(const struct can_map *map, size_t r, uint16_t *vars)
{
    size_t count = 0;
    vars[count++] = URRT_RTDE_V_TIMESTAMP;
    for (size_t i = 0; i < map->frame_count; i++) {
        for (size_t k = 0; map->frames[i].robot_index == r && k < map->frames[i].count; k++) {
            int var = signal_var(&map->frames[i].meta[k]);
            size_t j = 0;
            while (j < count && vars[j] != var) {
                j++;
            }
            if (var >= 0 && j == count && count < URRT_RTDE_MAX_VARS) {
                vars[count++] = (uint16_t)var;
            }
        }
    }
    return count;
}

static void put_rtde_recipes(FILE *out, const struct can_map *map, const struct can_ctables_robot *robots,
                             size_t robot_count)
{
    uint16_t vars[URRT_RTDE_MAX_VARS];
    fprintf(out, "\n/* The RTDE recipes: what urrt_rtde_begin asks each robot for. */\n");
    for (size_t r = 0; r < robot_count; r++) {
        size_t count;
        if (!is_rtde(robots, map, r)) {
            continue;
        }
        count = recipe_of(map, r, vars);
        fprintf(out, "static const uint16_t urrt_gateway_rtde_vars_%zu[%zu] = {\n", r, count);
        for (size_t i = 0; i < count; i++) {
            char name[URRT_RTDE_NAME_MAX];
            (void)urrt_rtde_var_name(vars[i], name, sizeof name);
            fputs("    ", out);
            put_var_id(out, vars[i]);
            fprintf(out, ", /* %s */\n", name);
        }
        fprintf(out, "};\n");
    }
    fprintf(out, "const uint16_t *const urrt_gateway_rtde_vars[%zu] = {", robot_count);
    for (size_t r = 0; r < robot_count; r++) {
        fprintf(out, r ? ", " : "");
        if (is_rtde(robots, map, r)) {
            fprintf(out, "urrt_gateway_rtde_vars_%zu", r);
        } else {
            fputs("NULL", out);
        }
    }
    fprintf(out, "};\nconst size_t urrt_gateway_rtde_var_count[%zu] = {", robot_count);
    for (size_t r = 0; r < robot_count; r++) {
        fprintf(out, "%s%zu", r ? ", " : "", is_rtde(robots, map, r) ? recipe_of(map, r, vars) : 0u);
    }
    fprintf(out, "};\nconst double urrt_gateway_rtde_frequency[%zu] = {", robot_count);
    for (size_t r = 0; r < robot_count; r++) {
        fputs(r ? ", " : "", out);
        put_double(out, is_rtde(robots, map, r) ? robots[r].frequency : 0.0);
    }
    fprintf(out, "};\nconst uint16_t urrt_gateway_rtde_port[%zu] = {", robot_count);
    for (size_t r = 0; r < robot_count; r++) {
        fprintf(out, "%s%u", r ? ", " : "", (unsigned)robots[r].port);
    }
    fprintf(out, "};\n\n"
                 "void urrt_gateway_rtde_values(size_t robot, const urrt_rtde_values *values)\n{\n"
                 "    if (robot < %zu) {\n        urrt_gateway_rtde[robot] = values;\n    }\n}\n",
            robot_count);
}

/* What the fill functions read: each robot's latest package, NULL before
 * the first; the helpers only where a fill function uses them (lib/'s
 * warnings refuse an unused static function). */
static void put_rtde_reading(FILE *out, const struct can_map *map, const struct can_ctables_robot *robots,
                             size_t robot_count)
{
    bool signals = false;
    bool quantities = false;
    for (size_t i = 0; i < map->frame_count; i++) {
        for (size_t k = 0; k < map->frames[i].count && is_rtde(robots, map, map->frames[i].robot_index); k++) {
            const struct can_map_signal *m = &map->frames[i].meta[k];
            signals = signals || m->role == CAN_MAP_ROLE_RTDE;
            quantities = quantities || (m->role == CAN_MAP_ROLE_RTDE && !m->bitmask);
        }
    }
    fprintf(out, "/* Each RTDE robot's latest package (urrt_gateway_rtde_values), NULL before its first. */\n"
                 "static const urrt_rtde_values *urrt_gateway_rtde[%zu];\n\n",
            robot_count);
    if (quantities) {
        fprintf(out, "static double urrt_gateway_nan(void)\n{\n"
                     "    union {\n        uint64_t bits;\n        double value;\n    } nan = {UINT64_C(0x7FF8000000000000)};\n"
                     "    return nan.value;\n}\n\n");
    }
    if (signals) {
        fprintf(out, "static int urrt_gateway_rtde_has(const urrt_rtde_values *v, int var)\n{\n"
                     "    return v != NULL && urrt_rtde_has(v, var);\n}\n\n");
    }
}

/* Frame f's fill function: each RTDE-only signal's value from its robot's
 * latest package, read as rtde_only.h reads it (the gateway's fill_rtde): a
 * quantity as a double, NaN when the package lacks it; a mask (can_map set
 * bitmask from rtde_only_is_mask) as its 64 bits, 0 when lacking. The C type
 * of each is lib/'s (URRT_RTDE_CTYPE_ of the variable's wire type). */
static void put_rtde_fill(FILE *out, const struct can_map_frame *f)
{
    fprintf(out, "/* [frame %s]: its RTDE-only values, from robot %zu's latest package. */\n"
                 "static void frame_%s_fill(urrt_cantx *tx, size_t frame, uint64_t now_us, bool sending, double *values)\n"
                 "{\n    const urrt_rtde_values *v = urrt_gateway_rtde[%zu];\n"
                 "    (void)tx;\n    (void)frame;\n    (void)now_us;\n    (void)sending;\n",
            f->name, f->robot_index, f->name, f->robot_index);
    for (size_t k = 0; k < f->count; k++) {
        const struct can_map_signal *m = &f->meta[k];
        const char *type = urrt_rtde_type_name(urrt_rtde_var_type(m->var));
        if (m->role != CAN_MAP_ROLE_RTDE) {
            continue;
        }
        fprintf(out, "    values[%zu] = %surrt_gateway_rtde_has(v, ", k, m->bitmask ? "urrt_cantx_mask_value(" : "");
        put_var_id(out, m->var);
        fprintf(out, ")\n        ? (%s)((const URRT_RTDE_CTYPE_%s *)urrt_rtde_value(v, ", m->bitmask ? "uint64_t" : "double",
                type);
        put_var_id(out, m->var);
        fprintf(out, "))[%u]\n        : %s; /* %s */\n", m->elem, m->bitmask ? "0u)" : "urrt_gateway_nan()", m->name);
    }
    fprintf(out, "}\n\n");
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

/* ---- [input]s: the frames the PLC sends, for a firmware that writes registers --------- */

static const char *const silence_names[] = {
    [URRT_PLCIN_STOP] = "URRT_PLCIN_STOP",
    [URRT_PLCIN_HOLD] = "URRT_PLCIN_HOLD",
    [URRT_PLCIN_VALUE] = "URRT_PLCIN_VALUE",
};

/* A register as lib/urrt_rtde.h's enum names it, and its RTDE name. */
static void put_register(FILE *out, int var, const char *what)
{
    char name[URRT_RTDE_NAME_MAX];
    (void)urrt_rtde_var_name(var, name, sizeof name);
    fputs("    ", out);
    put_var_id(out, var);
    fprintf(out, ", /* %s%s */\n", name, what);
}

/* [input NAME]'s signals (the very descriptors the gateway unpacks with),
 * the register of each, its recipe. */
static void put_input_tables(FILE *out, const struct can_map_frame *f)
{
    fprintf(out, "/* [input %s] */\nstatic const urrt_can_signal input_%s_signals[%zu] = {\n", f->name, f->name,
            f->count);
    for (size_t k = 0; k < f->count; k++) {
        put_signal(out, &f->sigs[k], f->meta[k].name);
    }
    fprintf(out, "};\nstatic const uint16_t input_%s_vars[%zu] = {\n", f->name, f->count);
    for (size_t k = 0; k < f->count; k++) {
        char what[CAN_MAP_NAME_MAX + 8];
        snprintf(what, sizeof what, " <- %s", f->meta[k].name);
        put_register(out, f->meta[k].var, what);
    }
    fprintf(out, "};\nstatic const uint16_t input_%s_regs[%zu] = {\n", f->name, f->reg_count);
    for (size_t k = 0; k < f->reg_count; k++) {
        put_register(out, f->regs[k], "");
    }
    fprintf(out, "};\n\n");
}

static void put_inputs(FILE *out, const struct can_map *map)
{
    fprintf(out, "\n/* The [input]s: what the PLC sends, and the registers it writes (lib/urrt_plcin.h). */\n");
    for (size_t i = 0; i < map->input_count; i++) {
        put_input_tables(out, &map->inputs[i]);
    }
    fprintf(out, "const urrt_plcin_desc urrt_gateway_inputs[%zu] = {\n", map->input_count);
    for (size_t i = 0; i < map->input_count; i++) {
        const struct can_map_frame *f = &map->inputs[i];
        uint8_t flags = (uint8_t)((f->extended ? URRT_CANTX_EXTENDED : 0u) | (f->fd ? URRT_CANTX_FD : 0u));
        fprintf(out, "    {input_%s_signals, input_%s_vars, input_%s_regs, %zu, %zu, %u, %s, 0x%" PRIX32 ", %" PRIu32
                     ", %s, %zu, ",
                f->name, f->name, f->name, f->count, f->reg_count, (unsigned)f->len, flag_names(flags), f->id,
                f->timeout_ms, silence_names[f->silence], f->robot_index);
        put_double(out, f->silence == URRT_PLCIN_VALUE ? f->silence_value : 0.0);
        fprintf(out, "}, /* %s */\n", f->name);
    }
    fprintf(out, "};\nconst size_t urrt_gateway_input_count = %zu;\n", map->input_count);
    fprintf(out, "/* [can] inputs_min_rate: a fresh input's package at least this often. */\n"
                 "const uint64_t urrt_gateway_inputs_period_us = %" PRIu64 "u;\n",
            (uint64_t)(1e6 / map->inputs_min_rate_hz));
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

/* A PDO's mapping entries: urrt_gateway_{tpdo,rpdo}N_mapping. */
static void put_mapping(FILE *out, const char *kind, size_t n, const uint32_t *mapping, unsigned count)
{
    fprintf(out, "static const uint32_t urrt_gateway_%s%zu_mapping[%u] = {", kind, n + 1u, count);
    for (unsigned k = 0; k < count; k++) {
        fprintf(out, "%sUINT32_C(0x%08" PRIX32 ")", k % 4u == 0u ? "\n    " : " ", mapping[k]);
        fputc(k + 1u < count ? ',' : '\n', out);
    }
    fprintf(out, "};\n");
}

static void put_tpdos(FILE *out, const urrt_co_desc *d)
{
    for (size_t n = 0; n < d->tpdo_count; n++) {
        put_mapping(out, "tpdo", n, d->tpdos[n].mapping, d->tpdos[n].mapping_count);
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

/* The node's RPDOs (the [input]s, RPDO n = [input] n) and 0x1016's entry. */
static void put_rpdos(FILE *out, const urrt_co_desc *d)
{
    for (size_t n = 0; n < d->rpdo_count; n++) {
        put_mapping(out, "rpdo", n, d->rpdos[n].mapping, d->rpdos[n].mapping_count);
    }
    fprintf(out, "static const urrt_co_rpdo urrt_gateway_rpdos[%zu] = {\n", d->rpdo_count);
    for (size_t n = 0; n < d->rpdo_count; n++) {
        const urrt_co_rpdo *p = &d->rpdos[n];
        fprintf(out, "    {urrt_gateway_rpdo%zu_mapping, UINT32_C(0x%08" PRIX32 "), %u, %u, %u}, /* RPDO%zu */\n",
                n + 1u, p->cob_id, p->event_ms, p->transmission_type, p->mapping_count, n + 1u);
    }
    fprintf(out, "};\nstatic const uint32_t urrt_gateway_consumers[%u] = {", d->consumer_count);
    for (unsigned k = 0; k < d->consumer_count; k++) {
        fprintf(out, "%sUINT32_C(0x%08" PRIX32 ")", k ? ", " : "", d->consumers != NULL ? d->consumers[k] : 0u);
    }
    fprintf(out, "};\n");
}

static void put_node(FILE *out, struct co_run *node, const struct can_map *map)
{
    const urrt_co_desc *d = co_run_desc(node);
    size_t rx_count;
    const uint32_t *rx = co_run_rx_ids(node, &rx_count);
    size_t vars = co_run_input_first_var(node, map->input_count);
    bool rpdos = d->rpdo_count > 0;
    fprintf(out, "\n/* The CANopen node over these tables (lib/urrt_co.h, docs/canopen.md). */\n");
    put_tpdos(out, d);
    put_objects(out, d);
    if (rpdos) {
        put_rpdos(out, d);
    }
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
    fprintf(out, ",\n    urrt_gateway_tpdos, %zu, urrt_gateway_objects, %zu, ", d->tpdo_count, d->object_count);
    if (rpdos) {
        fprintf(out, "urrt_gateway_rpdos, %zu, urrt_gateway_consumers, %u};\n", d->rpdo_count, d->consumer_count);
    } else {
        fprintf(out, "NULL, 0, NULL, 0};\n"); /* no [input]s: no RPDOs, no 0x1016 */
    }
    fprintf(out, "const uint32_t urrt_gateway_rx_ids[%zu] = {", rx_count);
    for (size_t i = 0; i < rx_count; i++) {
        fprintf(out, "%s0x%03" PRIX32, i ? ", " : "", rx[i]);
    }
    fprintf(out, "};\nstatic urrt_co_tpdo_state urrt_gateway_tpdo_states[%zu];\n", d->tpdo_count);
    if (!rpdos) {
        fprintf(out, "static uint32_t urrt_gateway_vars[1];\n\n"
                     "int urrt_gateway_co_init(urrt_co *co, urrt_cantx *tx, size_t *bad_item)\n{\n"
                     "    return urrt_co_init(co, &urrt_gateway_node, tx, urrt_gateway_tpdo_states, urrt_gateway_vars, 1,\n"
                     "                        bad_item);\n}\n");
        return;
    }
    /* With RPDOs: the variables they write, when each was written, and the
     * first of each [input]'s, for the firmware to take them from. */
    fprintf(out, "uint32_t urrt_gateway_vars[%zu];\nuint64_t urrt_gateway_written_us[%zu];\n"
                 "const uint16_t urrt_gateway_input_first_var[%zu] = {",
            vars, vars, map->input_count);
    for (size_t i = 0; i < map->input_count; i++) {
        fprintf(out, "%s%zu", i ? ", " : "", co_run_input_first_var(node, i));
    }
    fprintf(out, "};\nstatic urrt_co_rpdo_state urrt_gateway_rpdo_states[%zu];\n"
                 "static urrt_co_consumer urrt_gateway_consumer_states[%u];\n"
                 "static urrt_co_rx_storage urrt_gateway_rx;\n\n"
                 "int urrt_gateway_co_init(urrt_co *co, urrt_cantx *tx, size_t *bad_item)\n{\n"
                 "    urrt_gateway_rx.rpdos = urrt_gateway_rpdo_states;\n"
                 "    urrt_gateway_rx.consumers = urrt_gateway_consumer_states;\n"
                 "    urrt_gateway_rx.written_us = urrt_gateway_written_us;\n"
                 "    return urrt_co_init_rx(co, &urrt_gateway_node, tx, urrt_gateway_tpdo_states, urrt_gateway_vars, %zu,\n"
                 "                           &urrt_gateway_rx, bad_item);\n}\n",
            d->rpdo_count, d->consumer_count, vars);
}

/* Whether frame i gets a fill function of put_rtde_fill's. */
static bool rtde_filled(const struct can_map *map, const struct can_ctables_robot *robots, size_t i)
{
    return i < map->frame_count && has_rtde(&map->frames[i]) && is_rtde(robots, map, map->frames[i].robot_index);
}

int can_ctables_write(FILE *out, const struct can_map *map, struct can_run *run, struct co_run *node,
                      const struct can_ctables_robot *robots, const char *source)
{
    const urrt_cantx_tables *t = can_run_tx(run)->tables;
    bool rtde = false;
    char path[512];
    size_t used = 0;
    /* The path in a C comment: a "*" + "/" in it would end the comment. */
    for (const char *p = source != NULL ? source : "?"; *p != '\0' && used + 3 < sizeof path; p++) {
        path[used++] = *p;
        if (p[0] == '*' && p[1] == '/') {
            path[used++] = ' ';
        }
    }
    path[used] = '\0';
    for (size_t i = 0; i < map->robot_count; i++) {
        rtde = rtde || is_rtde(robots, map, i);
    }
    fprintf(out, "/* SPDX-License-Identifier: MIT */\n"
                 "/*\n * Generated by urrt-gateway %s --print-c-tables from %s: its CAN frames as\n"
                 " * lib/urrt_cantx.h tables, for a firmware that sends what urrt-gateway sends.\n"
                 " * Do not edit: change the configuration and generate again. Use:\n"
                 " *     extern const urrt_cantx_tables urrt_gateway_tables;\n"
                 " *     int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal);\n"
                 " * (urrt_cantx_init and urrt_cantx_prepare over the storage below). Robots by index:",
            URRT_VERSION_STRING, path);
    for (size_t i = 0; i < map->robot_count; i++) {
        fprintf(out, " %zu %s%s", i, map->robots[i].name, is_rtde(robots, map, i) ? " (RTDE)" : "");
    }
    if (rtde) {
        fprintf(out, ".\n * Robots read over RTDE (lib/urrt_rtde.h; NULL and 0 for the others):\n"
                     " *     extern const uint16_t *const urrt_gateway_rtde_vars[%zu];   the recipe of urrt_rtde_begin\n"
                     " *     extern const size_t urrt_gateway_rtde_var_count[%zu];\n"
                     " *     extern const double urrt_gateway_rtde_frequency[%zu];      Hz; 0: the controller's maximum\n"
                     " *     void urrt_gateway_rtde_values(size_t robot, const urrt_rtde_values *values);\n"
                     " * The last hands each data package's RTDE-only values to the frames, just before\n"
                     " * urrt_cantx_on_packet with its state; they are read when a frame is sent, so\n"
                     " * *values must stay as they are until the next package's",
                t->robot_count, t->robot_count, t->robot_count);
    }
    if (map->input_count > 0) {
        fprintf(out, ".\n * The [input]s, the frames the PLC sends, whose signals write robots' input\n"
                     " * registers over RTDE (lib/urrt_plcin.h and lib/urrt_rtde_in.h, which a firmware\n"
                     " * that writes links; one urrt_plcin and one urrt_rtde_in per [input]):\n"
                     " *     extern const urrt_plcin_desc urrt_gateway_inputs[%zu];\n"
                     " *     extern const size_t urrt_gateway_input_count;\n"
                     " *     extern const uint64_t urrt_gateway_inputs_period_us;   [can] inputs_min_rate's period\n"
                     " * (urrt_plcin_due's period_us)",
                map->input_count);
    }
    if (node != NULL) {
        fprintf(out, ".\n * The CANopen node ([canopen]), over urrt_cantx_init's tx:\n"
                     " *     extern const urrt_co_desc urrt_gateway_node;\n"
                     " *     extern const uint32_t urrt_gateway_rx_ids[%d];   the ids it receives\n"
                     " *     int urrt_gateway_co_init(urrt_co *co, urrt_cantx *tx, size_t *bad_item)%s",
                (int)CO_RUN_RX_IDS,
                map->input_count > 0
                    ? "\n * and its RPDOs ([input] i is RPDO i + 1), whose signal k the node stores in\n"
                      " * variable urrt_gateway_input_first_var[i] + k, raw as its object's type:\n"
                      " *     extern uint32_t urrt_gateway_vars[];          the variables\n"
                      " *     extern uint64_t urrt_gateway_written_us[];    when an RPDO or SDO write stored each\n"
                      " *     extern const uint16_t urrt_gateway_input_first_var[]\n"
                      " * (with written_us older than timeout_ms: absent, in urrt_plcin_take)"
                    : "");
    }
    fprintf(out, ".\n */\n#include <stdbool.h>\n#include <stddef.h>\n#include <stdint.h>\n\n#include \"%s\"\n%s\n",
            node != NULL ? "urrt_co.h" : "urrt_cantx.h",
            map->input_count > 0 ? "#include \"urrt_plcin.h\"\n" : rtde ? "#include \"urrt_rtde.h\"\n" : "");
    put_rtde_refusal(out, map, robots);
    if (rtde) {
        put_rtde_reading(out, map, robots, t->robot_count);
    }
    for (size_t i = 0; i < map->frame_count; i++) {
        put_frame_tables(out, &map->frames[i], &t->frames[i]);
        if (rtde_filled(map, robots, i)) {
            put_rtde_fill(out, &map->frames[i]);
        }
    }
    fprintf(out, "static const urrt_cantx_frame urrt_gateway_frames[%zu] = {\n", t->frame_count);
    for (size_t i = 0; i < t->frame_count; i++) {
        bool hb = i == can_run_heartbeat_index(run);
        put_frame(out, hb ? CAN_MAP_HEARTBEAT_NAME : map->frames[i].name, &t->frames[i], hb,
                  !hb && rtde_filled(map, robots, i));
    }
    fprintf(out, "};\n\n");
    put_storage(out, t);
    if (rtde) {
        put_rtde_recipes(out, map, robots, t->robot_count);
    }
    if (map->input_count > 0) {
        put_inputs(out, map);
    }
    if (node != NULL) {
        put_node(out, node, map);
    }
    return ferror(out) ? -1 : 0;
}
