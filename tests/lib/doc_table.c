/* SPDX-License-Identifier: MIT */
/*
 * Prints the generated tables of a document from the library's own metadata,
 * so the document cannot drift from the code:
 *   doc_table protocol   docs/protocol.md's field and enum tables (urrt_field(),
 *                        urrt_enum_entries(), and urrt_rtde.h's map from each
 *                        field to the RTDE output that fills it)
 *   doc_table rtde       docs/rtde.md's RTDE variable table: every row of
 *                        urrt_rtde.h's URRT_RTDE_MAPPED and URRT_RTDE_ONLY
 *                        (name or family, wire type, the member it fills, the
 *                        controller versions)
 * `make docs` splices the output between the markers; `make check-docs`
 * fails when the document differs from it.
 */
#include "urrt.h"
#include "urrt_rtde.h"

#include <stdio.h>
#include <string.h>

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

/* ---- docs/rtde.md: the variable table ------------------------------------------- */

/* A row's "since" triple: (CB3 3.x, e-Series 5.x, PolyScope X 10.x). */
typedef struct since3 {
    uint32_t v[3];
} since3;
#define SINCE3(a, b, c) {{(a), (b), (c)}}

/* One line's "since" as a cell: all, never, not stated, or the version from
 * which on it has the variable ("3.4", "5.5.1"). */
static const char *since_cell(uint32_t v, char *buf, size_t size)
{
    if (v == URRT_RTDE_ANY) {
        return "all";
    }
    if (v == URRT_RTDE_NEVER) {
        return "never";
    }
    if (v == URRT_RTDE_UNSTATED) {
        return "not stated";
    }
    if ((v & 0xFFu) != 0) {
        snprintf(buf, size, "%u.%u.%u", (unsigned)(v >> 16), (unsigned)(v >> 8 & 0xFFu), (unsigned)(v & 0xFFu));
    } else {
        snprintf(buf, size, "%u.%u", (unsigned)(v >> 16), (unsigned)(v >> 8 & 0xFFu));
    }
    return buf;
}

static void rtde_row(const char *name, int var, const char *fills, since3 since)
{
    char b[3][16];
    printf("| %s | %s | %s | %s | %s | %s |\n", name, urrt_rtde_type_name(urrt_rtde_var_type(var)), fills,
           since_cell(since.v[0], b[0], sizeof b[0]), since_cell(since.v[1], b[1], sizeof b[1]),
           since_cell(since.v[2], b[2], sizeof b[2]));
}

/* A family's indexes lo..hi as one row: its name with N, the member's
 * element of index N (count elements per index). */
static void rtde_family(const char *stem, int var, const char *member, unsigned count, int first, int lo, int hi,
                        since3 since)
{
    char name[96], fills[128], at[32];
    snprintf(name, sizeof name, "`%sN`, N %d-%d", stem, lo, hi);
    if (first == 0) {
        snprintf(at, sizeof at, "N");
    } else {
        snprintf(at, sizeof at, "N - %d", first);
    }
    if (count > 1) {
        snprintf(fills, sizeof fills, "`urrt_rtde_values.%s[(%s) * %u]`", member, at, count);
    } else {
        snprintf(fills, sizeof fills, "`urrt_rtde_values.%s[%s]`", member, at);
    }
    rtde_row(name, var, fills, since);
}

static void rtde_table(void)
{
    char name[96], fills[128];
    int rows = 0;
    printf("| RTDE name | type | fills | CB3 (3.x) | e-Series (5.x) | PolyScope X (10.x) |\n");
    printf("|---|---|---|---|---|---|\n");
#define DOC_X_MAPPED(ID, rname, TYPE, FIELD, member, since)                           \
    snprintf(name, sizeof name, "`%s`", rname);                                      \
    snprintf(fills, sizeof fills, "`urrt_state.%s`", #member);                       \
    rtde_row(name, URRT_RTDE_V_##ID, fills, (since3)SINCE3 since);                    \
    rows++;
    URRT_RTDE_MAPPED(DOC_X_MAPPED)
#undef DOC_X_MAPPED
#define DOC_X_ONLY(ID, member, rname, TYPE, first, names, split, since, since_hi)                               \
    if ((names) == 1) {                                                                                         \
        snprintf(name, sizeof name, "`%s`", rname);                                                            \
        snprintf(fills, sizeof fills, "`urrt_rtde_values.%s`", #member);                                       \
        rtde_row(name, URRT_RTDE_V_##ID, fills, (since3)SINCE3 since);                                          \
        rows++;                                                                                                 \
    } else {                                                                                                    \
        rtde_family(rname, URRT_RTDE_V_##ID, #member, URRT_RTDE_COUNT_##TYPE, (first), (first), (first) + (split) - 1,                  \
                    (since3)SINCE3 since);                                                                      \
        rows++;                                                                                                 \
        if ((split) < (names)) {                                                                                \
            rtde_family(rname, URRT_RTDE_V_##ID, #member, URRT_RTDE_COUNT_##TYPE, (first), (first) + (split), (first) + (names) - 1,    \
                        (since3)SINCE3 since_hi);                                                               \
            rows++;                                                                                             \
        }                                                                                                       \
    }
    URRT_RTDE_ONLY(DOC_X_ONLY)
#undef DOC_X_ONLY
    printf("\n%d names in %d rows: %d that RealTime has too (`URRT_RTDE_MAPPED`, into `urrt_state`), %d that only "
           "RTDE has (`URRT_RTDE_ONLY`, into `urrt_rtde_values`). A version is the first of its line to have the "
           "variable; all: every version of the line that has RTDE; never: the line does not have it; not stated: "
           "no source gives the version, and only the controller's `NOT_FOUND` tells.\n",
           (int)URRT_RTDE_VAR_COUNT, rows, (int)URRT_RTDE_MAPPED_COUNT, (int)URRT_RTDE_ONLY_COUNT);
}

/* ---- docs/protocol.md: the field and enum tables --------------------------------- */

static void protocol_tables(void)
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
}

int main(int argc, char **argv)
{
    const char *table = argc > 1 ? argv[1] : "protocol";
    if (strcmp(table, "protocol") == 0) {
        protocol_tables();
    } else if (strcmp(table, "rtde") == 0) {
        rtde_table();
    } else {
        fprintf(stderr, "doc_table: no table for \"%s\" (protocol, rtde)\n", table);
        return 1;
    }
    return 0;
}
