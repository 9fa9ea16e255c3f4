/* SPDX-License-Identifier: MIT */
/* dbc: writes the DBC for a CAN mapping. See dbc.h. */
#include "dbc.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rtde_only.h"

#define DBC_EXTENDED_FLAG 0x80000000u
#define DBC_UNKNOWN_ROBOT_CYCLE_MS 8u /* 125 Hz: the slower rate, so a receiver's timeout is not too tight */

/* Vector's interaction-layer send types; index 0 is "Cyclic". */
static const char *const send_types =
    "\"Cyclic\",\"Spontaneous\",\"CyclicIfActive\",\"SpontaneousWithDelay\",\"CyclicAndSpontaneous\","
    "\"CyclicAndSpontaneousWithDelay\",\"SpontaneousWithRepetition\",\"CyclicIfActiveAndSpontanousWD\","
    "\"CyclicIfActiveFast\",\"CyclicWithRepeatOnDemand\",\"none\"";

/* Vector's frame formats: the FD ones sit at index 14 and 15. */
static const char *const frame_formats =
    "\"StandardCAN\",\"ExtendedCAN\",\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\","
    "\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\","
    "\"StandardCAN_FD\",\"ExtendedCAN_FD\"";

enum { FORMAT_STANDARD = 0, FORMAT_EXTENDED = 1, FORMAT_STANDARD_FD = 14, FORMAT_EXTENDED_FD = 15 };

const char *dbc_number(double value, char *buf, size_t size)
{
    int precision;
    if (value == 0) {
        snprintf(buf, size, "0");
        return buf;
    }
    for (precision = 1; precision <= 17; precision++) {
        snprintf(buf, size, "%.*g", precision, value);
        if (strtod(buf, NULL) == value) {
            break;
        }
    }
    /* Whole digits without an exponent where they fit: "1600", not "1.6e+03". */
    {
        double magnitude = fabs(value);
        int digits = magnitude >= 1 ? (int)floor(log10(magnitude)) + 1 : 0;
        if (digits > precision && digits <= 17) {
            snprintf(buf, size, "%.*g", digits, value);
        }
    }
    return buf;
}

static unsigned long dbc_id(uint32_t id, bool extended)
{
    return extended ? (unsigned long)(id | DBC_EXTENDED_FLAG) : (unsigned long)id;
}

/* A comment text with '"' and '\' escaped as canmatrix and CANdb++ expect. */
static void put_text(FILE *out, const char *text)
{
    for (; *text != '\0'; text++) {
        if (*text == '"' || *text == '\\') {
            fputc('\\', out);
        }
        fputc(*text, out);
    }
}

/*
 * A bit mask (URRT_CAN_SIG_BITMASK) has factor 1, offset 0 and its whole
 * unsigned range, [0|2^length-1], as its limits (can_map gives it no other):
 * read as written, that limits nothing, in every tool. [0|0] means "no
 * range" only by a convention some tools keep; canmatrix takes it as
 * written (it computes limits only where the file gives none), min 0 and
 * max 0, and so would any importer that checks values against it.
 */
static void put_signal(FILE *out, const char *name, const urrt_can_signal *sig, const char *unit,
                       const char *receiver)
{
    char factor[40];
    char offset[40];
    char min[40];
    char max[40];
    fprintf(out, " SG_ %s : %u|%u@%c%c (%s,%s) [%s|%s] \"", name, (unsigned)sig->start, (unsigned)sig->length,
            sig->byte_order == URRT_CAN_INTEL ? '1' : '0', sig->type == URRT_CAN_UNSIGNED ? '+' : '-',
            dbc_number(sig->factor, factor, sizeof factor), dbc_number(sig->offset, offset, sizeof offset),
            dbc_number(sig->min, min, sizeof min), dbc_number(sig->max, max, sizeof max));
    put_text(out, unit);
    fprintf(out, "\" %s\n", receiver);
}

/* A value table entry for an enumeration value, if the signal carries it
 * exactly: VAL_ lists raw values. */
static bool enum_raw(const urrt_can_signal *sig, int value, long long *raw_out)
{
    uint64_t raw;
    if (sig->type == URRT_CAN_FLOAT32 || sig->type == URRT_CAN_FLOAT64) {
        return false;
    }
    if (urrt_can_to_raw(sig, value, &raw) != URRT_CAN_PACK_OK || urrt_can_from_raw(sig, raw) != (double)value) {
        return false;
    }
    if (sig->type == URRT_CAN_SIGNED && sig->length < 64 && ((raw >> (sig->length - 1)) & 1u)) {
        *raw_out = (long long)(raw | ~((UINT64_C(1) << sig->length) - 1));
    } else {
        *raw_out = (long long)raw;
    }
    return true;
}

static void put_enum_values(FILE *out, unsigned long id, const char *name, const urrt_can_signal *sig,
                            urrt_enum_kind kind, int extra_value, const char *extra_name)
{
    size_t count = 0;
    size_t i;
    const urrt_enum_entry *entries = urrt_enum_entries(kind, &count);
    bool any = false;
    long long raw;
    if (extra_name != NULL && enum_raw(sig, extra_value, &raw)) {
        fprintf(out, "VAL_ %lu %s %lld \"%s\"", id, name, raw, extra_name);
        any = true;
    }
    for (i = 0; i < count; i++) {
        if (!enum_raw(sig, entries[i].value, &raw)) {
            continue;
        }
        if (!any) {
            fprintf(out, "VAL_ %lu %s", id, name);
            any = true;
        }
        fprintf(out, " %lld \"%s\"", raw, entries[i].name);
    }
    if (any) {
        fprintf(out, " ;\n");
    }
}

static unsigned cycle_ms(const struct can_map *map, const struct can_map_frame *f)
{
    if (!f->every) {
        return f->period_ms;
    }
    if (f->robot_index < map->robot_count && map->robots[f->robot_index].period_us != 0) {
        uint32_t p = map->robots[f->robot_index].period_us;
        return (p + 999u) / 1000u;
    }
    return DBC_UNKNOWN_ROBOT_CYCLE_MS;
}

static void put_field_comment(FILE *out, unsigned long id, const struct can_map *map, const struct can_map_signal *m,
                              const urrt_can_signal *sig)
{
    const urrt_field_info *info = urrt_field((urrt_field_id)m->field);
    urrt_enum_kind kind = urrt_field_enum((urrt_field_id)m->field, map->generation);
    char column[96];
    if (info == NULL) {
        return;
    }
    if (info->col_3x && info->col_1x) {
        snprintf(column, sizeof column, "RealTime column %u on 3.x/5.x, %u on 1.x", info->col_3x + m->elem,
                 info->col_1x + m->elem);
    } else if (info->col_3x) {
        snprintf(column, sizeof column, "RealTime column %u, 3.x/5.x from %s", info->col_3x + m->elem, info->since);
    } else {
        snprintf(column, sizeof column, "RealTime column %u, 1.x only", info->col_1x + m->elem);
    }
    fprintf(out, "CM_ SG_ %lu %s \"", id, m->name);
    if (info->count > 1) {
        fprintf(out, "%s[%u]: ", info->name, m->elem);
    } else {
        fprintf(out, "%s: ", info->name);
    }
    put_text(out, info->description);
    if (info->count > 1) {
        fprintf(out, ", element %u of %u", m->elem, (unsigned)info->count);
    }
    fprintf(out, " (%s)", column);
    if (m->bitmask) {
        fprintf(out, "; a bit mask, sent bit for bit (never scaled or saturated): bit n of this signal is bit %u+n "
                     "of the field, whose bit 0 is input/output 0", URRT_CAN_SIG_MASK_FIRST(sig->flags));
    }
    if (kind != URRT_ENUM_NONE && m->field == URRT_F_ROBOT_MODE) {
        fprintf(out, "; value table for %s numbering ([can] robot_generation)",
                map->generation == URRT_GEN_1X ? "1.x (CB2)" : "3.x/5.x");
    }
    fprintf(out, "\";\n");
}

/* An RTDE-only value's comment: its RTDE name and type, and the mask rule. */
static void put_rtde_comment(FILE *out, unsigned long id, const struct can_map_signal *m, const urrt_can_signal *sig)
{
    char name[URRT_RTDE_NAME_MAX];
    urrt_rtde_type type = urrt_rtde_var_type(m->var);
    (void)urrt_rtde_var_name(m->var, name, sizeof name);
    fprintf(out, "CM_ SG_ %lu %s \"%s", id, m->name, name);
    if (rtde_only_elements(m->var) > 1) {
        fprintf(out, "[%u]", m->elem);
    }
    fprintf(out, ": RTDE output %s, RTDE only (the robot's source = rtde), as of the package the frame's data is",
            urrt_rtde_type_name(type));
    if (m->bitmask) {
        fprintf(out, "; a bit mask, sent bit for bit (never scaled or saturated): bit n of this signal is bit %u+n "
                     "of the value", URRT_CAN_SIG_MASK_FIRST(sig->flags));
    }
    fprintf(out, "\";\n");
}

/* Whether any frame is FD, and whether FD frames switch bit rate. */
static bool any_fd(const struct can_map *map)
{
    bool fd = map->fd;
    for (size_t i = 0; i < map->frame_count; i++) {
        fd |= map->frames[i].fd;
    }
    for (size_t i = 0; i < map->input_count; i++) {
        fd |= map->inputs[i].fd;
    }
    return fd;
}

static void put_header(FILE *out, const struct can_map *map)
{
    static const char *const ns[] = {
        "NS_DESC_", "CM_", "BA_DEF_", "BA_", "VAL_", "CAT_DEF_", "CAT_", "FILTER", "BA_DEF_DEF_", "EV_DATA_",
        "ENVVAR_DATA_", "SGTYPE_", "SGTYPE_VAL_", "BA_DEF_SGTYPE_", "BA_SGTYPE_", "SIG_TYPE_REF_",
        "VAL_TABLE_", "SIG_GROUP_", "SIG_VALTYPE_", "SIGTYPE_VALTYPE_", "BO_TX_BU_", "BA_DEF_REL_",
        "BA_REL_", "BA_DEF_DEF_REL_", "BU_SG_REL_", "BU_EV_REL_", "BU_BO_REL_", "SG_MUL_VAL_"};
    fprintf(out, "VERSION \"\"\n\n\n");
    fprintf(out, "NS_ :\n");
    for (size_t k = 0; k < sizeof ns / sizeof ns[0]; k++) {
        fprintf(out, "\t%s\n", ns[k]);
    }
    fprintf(out, "\nBS_:\n\n");
    if (strcmp(map->receiver, "Vector__XXX") != 0 && strcmp(map->receiver, map->node) != 0) {
        fprintf(out, "BU_: %s %s\n\n\n", map->node, map->receiver);
    } else {
        fprintf(out, "BU_: %s\n\n\n", map->node);
    }
}

/* A frame and its signals: sent by transmitter, each signal received by receiver. */
static void put_message(FILE *out, const struct can_map_frame *f, const char *transmitter, const char *receiver)
{
    fprintf(out, "BO_ %lu %s: %u %s\n", dbc_id(f->id, f->extended), f->name, (unsigned)f->len, transmitter);
    for (size_t k = 0; k < f->count; k++) {
        put_signal(out, f->meta[k].name, &f->sigs[k], f->meta[k].unit, receiver);
    }
    fprintf(out, "\n");
}

/* What the gateway sends (the frames, then the heartbeat), then what it
 * receives: each [input], sent by the PLC ([can] receiver: its node, or
 * Vector__XXX, "no node"), its signals received by the gateway's node. */
static void put_frames(FILE *out, const struct can_map *map, unsigned long hb)
{
    for (size_t i = 0; i < map->frame_count; i++) {
        put_message(out, &map->frames[i], map->node, map->receiver);
    }
    fprintf(out, "BO_ %lu %s: %u %s\n", hb, CAN_MAP_HEARTBEAT_NAME, URRT_CANTX_HB_LEN, map->node);
    for (size_t k = 0; k < URRT_CANTX_HB_COUNT; k++) {
        const struct can_map_hb_signal *h = &can_map_heartbeat_layout[k];
        put_signal(out, h->name, &urrt_cantx_heartbeat_signals[k], h->unit, map->receiver);
    }
    fprintf(out, "\n");
    for (size_t i = 0; i < map->input_count; i++) {
        put_message(out, &map->inputs[i], map->receiver, map->node);
    }
    fprintf(out, "\n");
}

static void put_frame_comment(FILE *out, const struct can_map *map, const struct can_map_frame *f)
{
    unsigned long id = dbc_id(f->id, f->extended);
    const char *robot = f->robot_index < map->robot_count ? map->robots[f->robot_index].name : f->robot;
    fprintf(out, "CM_ BO_ %lu \"", id);
    if (f->comment[0] != '\0') {
        put_text(out, f->comment);
        fprintf(out, ". ");
    }
    fprintf(out, "Robot ");
    put_text(out, robot);
    if (f->every) {
        fprintf(out, ", one frame per robot packet; stops when the packets stop.");
    } else if (f->stale_policy == CAN_MAP_STALE_STOP) {
        fprintf(out, ", every %u ms; stops when the data is older than %u ms.", (unsigned)f->period_ms,
                (unsigned)f->stale_after_ms);
    } else {
        fprintf(out, ", every %u ms; sent with valid = 0 when the data is older than %u ms.",
                (unsigned)f->period_ms, (unsigned)f->stale_after_ms);
    }
    fprintf(out, "\";\n");
    for (size_t k = 0; k < f->count; k++) {
        const struct can_map_signal *m = &f->meta[k];
        switch (m->role) {
        case CAN_MAP_ROLE_FIELD: put_field_comment(out, id, map, m, &f->sigs[k]); break;
        case CAN_MAP_ROLE_RTDE: put_rtde_comment(out, id, m, &f->sigs[k]); break;
        case CAN_MAP_ROLE_ALIVE:
            fprintf(out, "CM_ SG_ %lu %s \"Alive counter: +1 modulo 16 with every frame sent\";\n", id, m->name);
            break;
        case CAN_MAP_ROLE_VALID:
            fprintf(out,
                    "CM_ SG_ %lu %s \"1: every value in this frame is fresh and was sent as it is; 0: data "
                    "older than %u ms, a value saturated or NaN, or no data yet\";\n",
                    id, m->name, (unsigned)f->stale_after_ms);
            break;
        }
    }
}

/* An [input]'s on_silence, as the configuration writes it. */
static void put_silence(FILE *out, const struct can_map_frame *f, bool why)
{
    char value[40];
    switch (f->silence) {
    case URRT_PLCIN_HOLD:
        fprintf(out, "on_silence = hold%s", why ? " (the last values go on being written)" : "");
        break;
    case URRT_PLCIN_VALUE:
        fprintf(out, "on_silence = value %s%s", dbc_number(f->silence_value, value, sizeof value),
                why ? " (written to every register of the frame)" : "");
        break;
    default:
        fprintf(out, "on_silence = stop%s",
                why ? " (nothing more is written: the robot program's rtde_set_watchdog acts)" : "");
        break;
    }
}

/* An [input]'s comments: the frame (its comment=, who sends it, the robot
 * it writes, its timeout and silence policy), and each signal's register. */
static void put_input_comment(FILE *out, const struct can_map *map, const struct can_map_frame *f)
{
    unsigned long id = dbc_id(f->id, f->extended);
    const char *robot = f->robot_index < map->robot_count ? map->robots[f->robot_index].name : f->robot;
    fprintf(out, "CM_ BO_ %lu \"", id);
    if (f->comment[0] != '\0') {
        put_text(out, f->comment);
        fprintf(out, ". ");
    }
    fprintf(out, "Sent by %s, received by %s, which writes robot ",
            strcmp(map->receiver, "Vector__XXX") != 0 ? map->receiver : "the PLC", map->node);
    put_text(out, robot);
    fprintf(out, "'s input registers over RTDE from it; no frame for %u ms is a silent PLC: ", (unsigned)f->timeout_ms);
    put_silence(out, f, true);
    fprintf(out, ".\";\n");
    for (size_t k = 0; k < f->count; k++) {
        const struct can_map_signal *m = &f->meta[k];
        char name[URRT_RTDE_NAME_MAX];
        (void)urrt_rtde_var_name(m->var, name, sizeof name);
        fprintf(out, "CM_ SG_ %lu %s \"%s: RTDE input %s, written by urrt-gateway to robot ", id, m->name, name,
                urrt_rtde_type_name(urrt_rtde_var_type(m->var)));
        put_text(out, robot);
        if (m->bitmask) {
            fprintf(out, "; a bit mask, taken bit for bit (never scaled): bit n of this signal is bit %u+n of the "
                         "register",
                    URRT_CAN_SIG_MASK_FIRST(f->sigs[k].flags));
        } else {
            fprintf(out, " as raw * factor + offset; a value outside min..max is refused and counted, never clamped");
        }
        fprintf(out, "; [input %s] timeout_ms = %u, ", f->name, (unsigned)f->timeout_ms);
        put_silence(out, f, false);
        fprintf(out, "\";\n");
    }
}

static void put_comments(FILE *out, const struct can_map *map, const char *source, unsigned long hb)
{
    fprintf(out, "CM_ \"Generated by urrt-gateway %s: Universal Robots RealTime data on CAN. "
                 "Bit numbering and value scaling as in docs/can.md.\";\n",
            URRT_VERSION_STRING);
    if (source != NULL) {
        /* Kept apart so that a path with quotes cannot break the file. */
        fprintf(out, "CM_ BU_ %s \"urrt-gateway, configuration ", map->node);
        put_text(out, source);
        fprintf(out, "\";\n");
    } else {
        fprintf(out, "CM_ BU_ %s \"urrt-gateway\";\n", map->node);
    }
    for (size_t i = 0; i < map->frame_count; i++) {
        put_frame_comment(out, map, &map->frames[i]);
    }
    fprintf(out, "CM_ BO_ %lu \"Gateway heartbeat, every %u ms. Robot ", hb, (unsigned)map->hb_period_ms);
    put_text(out, map->hb_robot_index < map->robot_count ? map->robots[map->hb_robot_index].name : map->hb_robot);
    fprintf(out, "; data stale after %u ms.\";\n", (unsigned)map->stale_after_ms);
    for (size_t k = 0; k < URRT_CANTX_HB_COUNT; k++) {
        fprintf(out, "CM_ SG_ %lu %s \"", hb, can_map_heartbeat_layout[k].name);
        put_text(out, can_map_heartbeat_layout[k].comment);
        fprintf(out, "\";\n");
    }
    for (size_t i = 0; i < map->input_count; i++) {
        put_input_comment(out, map, &map->inputs[i]);
    }
}

static void put_attribute_definitions(FILE *out, bool fd, bool brs)
{
    fprintf(out, "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 65535;\n");
    fprintf(out, "BA_DEF_ BO_ \"GenMsgSendType\" ENUM %s;\n", send_types);
    fprintf(out, "BA_DEF_ BO_ \"VFrameFormat\" ENUM %s;\n", frame_formats);
    if (fd) {
        fprintf(out, "BA_DEF_ BO_ \"CANFD_BRS\" ENUM \"0\",\"1\";\n");
    }
    fprintf(out, "BA_DEF_ \"BusType\" STRING ;\n");
    fprintf(out, "BA_DEF_ \"Baudrate\" INT 10000 1000000;\n");
    fprintf(out, "BA_DEF_ \"DBName\" STRING ;\n");
    fprintf(out, "BA_DEF_DEF_ \"GenMsgCycleTime\" 0;\n");
    fprintf(out, "BA_DEF_DEF_ \"GenMsgSendType\" \"Cyclic\";\n");
    fprintf(out, "BA_DEF_DEF_ \"VFrameFormat\" \"StandardCAN\";\n");
    if (fd) {
        fprintf(out, "BA_DEF_DEF_ \"CANFD_BRS\" \"%d\";\n", brs ? 1 : 0);
    }
    fprintf(out, "BA_DEF_DEF_ \"BusType\" \"CAN\";\n");
    fprintf(out, "BA_DEF_DEF_ \"Baudrate\" 500000;\n");
    fprintf(out, "BA_DEF_DEF_ \"DBName\" \"\";\n");
}

/*
 * The frames in order (put_frames'): the [frame]s, the heartbeat, the
 * [input]s. An [input]'s cycle is the PLC's own choice (any period well
 * below its timeout_ms), which the configuration does not know: it gets no
 * GenMsgCycleTime, whose BA_DEF_DEF_ 0 then stands, "none given" (canmatrix
 * reads cycle_time 0, as for a frame without the attribute; CANdb++ shows
 * 0), rather than a made-up period a PLC's interaction layer would send at.
 * Its GenMsgSendType is Cyclic, written out like every frame's: the gateway
 * needs the frame again and again (timeout_ms without it is a silent PLC),
 * which Spontaneous ("on change") would not say; the timeout is in its CM_.
 */
static void put_attributes(FILE *out, const struct can_map *map, unsigned long hb)
{
    bool fd_any = any_fd(map);
    bool brs = map->fd && map->data_bitrate > map->bitrate;
    put_attribute_definitions(out, fd_any, brs);
    fprintf(out, "BA_ \"BusType\" \"%s\";\n", fd_any ? "CAN FD" : "CAN");
    fprintf(out, "BA_ \"Baudrate\" %u;\n", (unsigned)(map->bitrate > 1000000 ? 1000000 : map->bitrate));
    fprintf(out, "BA_ \"DBName\" \"urrt_gateway\";\n");
    for (size_t i = 0; i <= map->frame_count + map->input_count; i++) {
        bool input = i > map->frame_count;
        const struct can_map_frame *f = i < map->frame_count ? &map->frames[i]
                                        : input              ? &map->inputs[i - map->frame_count - 1]
                                                             : NULL;
        bool ext = f ? f->extended : map->hb_extended;
        bool fd = f ? f->fd : false;
        unsigned long id = f ? dbc_id(f->id, f->extended) : hb;
        if (!input) {
            fprintf(out, "BA_ \"GenMsgCycleTime\" BO_ %lu %u;\n", id,
                    f ? cycle_ms(map, f) : (unsigned)map->hb_period_ms);
        }
        fprintf(out, "BA_ \"GenMsgSendType\" BO_ %lu 0;\n", id);
        fprintf(out, "BA_ \"VFrameFormat\" BO_ %lu %d;\n", id,
                fd ? (ext ? FORMAT_EXTENDED_FD : FORMAT_STANDARD_FD) : (ext ? FORMAT_EXTENDED : FORMAT_STANDARD));
        if (fd_any && fd) {
            fprintf(out, "BA_ \"CANFD_BRS\" BO_ %lu %d;\n", id, brs ? 1 : 0);
        }
    }
}

static void put_heartbeat_values(FILE *out, const struct can_map *map, unsigned long hb)
{
    for (size_t k = 0; k < URRT_CANTX_HB_COUNT; k++) {
        const struct can_map_hb_signal *h = &can_map_heartbeat_layout[k];
        const urrt_can_signal *sig = &urrt_cantx_heartbeat_signals[k];
        switch (h->values) {
        case CAN_MAP_HB_VALUES_STATE:
            fprintf(out, "VAL_ %lu %s", hb, h->name);
            for (int s = URRT_CANTX_STARTING; s <= URRT_CANTX_DISCONNECTED; s++) {
                fprintf(out, " %d \"%s\"", s, urrt_cantx_state_name((urrt_cantx_state)s));
            }
            fprintf(out, " ;\n");
            break;
        case CAN_MAP_HB_VALUES_ROBOT_MODE:
            put_enum_values(out, hb, h->name, sig,
                            map->generation == URRT_GEN_1X ? URRT_ENUM_ROBOT_MODE_1X : URRT_ENUM_ROBOT_MODE,
                            URRT_CANTX_HB_ROBOT_MODE_NA, "NOT_AVAILABLE");
            break;
        case CAN_MAP_HB_VALUES_SAFETY_MODE:
            put_enum_values(out, hb, h->name, sig, URRT_ENUM_SAFETY_MODE, URRT_CANTX_HB_SAFETY_MODE_NA,
                            "NOT_AVAILABLE");
            break;
        case CAN_MAP_HB_VALUES_GENERATION:
            fprintf(out, "VAL_ %lu %s 0 \"UNKNOWN\" 1 \"CB2_1X\" 3 \"CB3_ESERIES_3X_5X\" ;\n", hb, h->name);
            break;
        default: break;
        }
    }
}

/* Value tables of coded fields, then the float signals' types. */
static void put_values(FILE *out, const struct can_map *map, unsigned long hb)
{
    for (size_t i = 0; i < map->frame_count; i++) {
        const struct can_map_frame *f = &map->frames[i];
        for (size_t k = 0; k < f->count; k++) {
            const struct can_map_signal *m = &f->meta[k];
            urrt_enum_kind kind = m->role == CAN_MAP_ROLE_FIELD
                                      ? urrt_field_enum((urrt_field_id)m->field, map->generation)
                                      : URRT_ENUM_NONE;
            if (kind != URRT_ENUM_NONE) {
                put_enum_values(out, dbc_id(f->id, f->extended), m->name, &f->sigs[k], kind, 0, NULL);
            }
        }
    }
    put_heartbeat_values(out, map, hb);
    for (size_t i = 0; i < map->frame_count + map->input_count; i++) {
        const struct can_map_frame *f = i < map->frame_count ? &map->frames[i] : &map->inputs[i - map->frame_count];
        for (size_t k = 0; k < f->count; k++) {
            if (f->sigs[k].type == URRT_CAN_FLOAT32 || f->sigs[k].type == URRT_CAN_FLOAT64) {
                fprintf(out, "SIG_VALTYPE_ %lu %s : %d;\n", dbc_id(f->id, f->extended), f->meta[k].name,
                        f->sigs[k].type == URRT_CAN_FLOAT32 ? 1 : 2);
            }
        }
    }
}

int dbc_write(FILE *out, const struct can_map *map, const char *source)
{
    unsigned long hb;
    if (out == NULL || map == NULL || !map->finished || !map->configured) {
        errno = EINVAL;
        return -1;
    }
    hb = dbc_id(map->hb_id, map->hb_extended);
    put_header(out, map);
    put_frames(out, map, hb);
    put_comments(out, map, source, hb);
    put_attributes(out, map, hb);
    put_values(out, map, hb);
    fflush(out);
    return ferror(out) ? -1 : 0;
}
