/* SPDX-License-Identifier: MIT */
/*
 * Prints the tables of docs/protocol.md from the library's own metadata
 * (urrt_field(), urrt_enum_entries(), and urrt_rtde.h's map from each field
 * to the RTDE output that fills it), so the document cannot drift from the
 * code. `make docs` splices the output between the markers; `make
 * check-docs` fails when the document differs from it.
 */
#include "urrt.h"
#include "urrt_rtde.h"

#include <stdio.h>

static void columns(char *buf, size_t size, unsigned first, unsigned count)
{
    if (first == 0) {
        snprintf(buf, size, "-");
    } else if (count == 1) {
        snprintf(buf, size, "%u", first);
    } else {
        snprintf(buf, size, "%u-%u", first, first + count - 1);
    }
}

/* The RTDE output that fills a field, with its wire type, or "-". */
static void rtde_name(char *buf, size_t size, urrt_field_id id)
{
    int var = urrt_rtde_var_of_field(id);
    char name[URRT_RTDE_NAME_MAX];
    if (var < 0 || urrt_rtde_var_name(var, name, sizeof name) < 0) {
        snprintf(buf, size, "-");
    } else {
        snprintf(buf, size, "`%s` %s", name, urrt_rtde_type_name(urrt_rtde_var_type(var)));
    }
}

static void enum_table(const char *title, urrt_enum_kind kind)
{
    size_t count, i;
    const urrt_enum_entry *e = urrt_enum_entries(kind, &count);
    printf("\n**%s**\n\n| value | name |\n|---:|---|\n", title);
    for (i = 0; i < count; i++) {
        printf("| %d | `%s` |\n", e[i].value, e[i].name);
    }
}

int main(void)
{
    int id;
    printf("| field | count | unit | columns 3.x/5.x | columns 1.x | since | RTDE output (type) | description |\n");
    printf("|---|---:|---|---|---|---|---|---|\n");
    for (id = 0; id < URRT_FIELD_COUNT; id++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        char c3[16], c1[16], rtde[64];
        columns(c3, sizeof c3, f->col_3x, f->count);
        columns(c1, sizeof c1, f->col_1x, f->count);
        rtde_name(rtde, sizeof rtde, (urrt_field_id)id);
        printf("| `%s` | %u | %s | %s | %s | %s | %s | %s |\n", f->name, f->count, f->unit[0] ? f->unit : "-", c3,
               c1, f->since, rtde, f->description);
    }
    printf("\n%d fields; the 3.x/5.x grid has %d columns (%d bytes); "
           "a packet may hold up to %d doubles (URRT_MAX_DOUBLES, %d bytes).\n",
           (int)URRT_FIELD_COUNT, URRT_WIRE_COLUMNS, URRT_PACKET_KNOWN_MAX, URRT_MAX_DOUBLES, URRT_PACKET_MAX);
    enum_table("Robot mode, 3.x/5.x (`robot_mode` in packets of 130 doubles or more)", URRT_ENUM_ROBOT_MODE);
    enum_table("Robot mode, 1.x / CB2 (`robot_mode` in packets of at most 101 doubles)", URRT_ENUM_ROBOT_MODE_1X);
    enum_table("Joint mode (`joint_modes`)", URRT_ENUM_JOINT_MODE);
    enum_table("Safety mode (`safety_mode`)", URRT_ENUM_SAFETY_MODE);
    enum_table("Safety status (`safety_status`)", URRT_ENUM_SAFETY_STATUS);
    enum_table("Program state (`program_state`)", URRT_ENUM_PROGRAM_STATE);
    printf("\nAny other value, a fraction, NaN or an infinity is named `%s`.\n", URRT_UNKNOWN_NAME);
    return 0;
}
