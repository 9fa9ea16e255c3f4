/* SPDX-License-Identifier: MIT */
/*
 * urrt_lua: prints the Wireshark dissector for the RealTime stream.
 *
 *   urrt_lua gateway/wireshark/dissector.lua > urrt.lua
 *
 * Every fact about the wire format comes from lib/ (the X-macro field table
 * through urrt_field(), urrt_versions_of(), urrt_generation_of(),
 * urrt_enum_entries(), urrt_field_enum(), urrt_strerror()) and the ports
 * from port/port.h. Where lib/ knows a rule only as code (which fields a
 * packet of a given length holds, which sizes are plausible), the rule is
 * probed through lib/'s own functions, and the program fails rather than
 * print a table that would disagree with them. The tables come first; the
 * hand-written dissectors (the files named on the command line) follow.
 *
 * For RTDE (TCP 30004) it prints lib/urrt_rtde.h's variable table (every
 * name urrt_rtde_var_name() knows, its wire type, and for the variables that
 * fill a RealTime field that field's unit and description) and its type
 * table, so that the RTDE dissector names and decodes values as lib/ does.
 */
#include "urrt.h"
#include "urrt_rtde.h"
#include "port.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Generations in the order of their sizes, named as urrt-dump names them. */
static const struct {
    urrt_generation gen;
    const char *name;
    const char *suffix; /* for an enumeration that differs between generations */
} gens[] = {{URRT_GEN_1X, "1.x", "1x"}, {URRT_GEN_UNKNOWN, "unknown", "unknown"}, {URRT_GEN_3X, "3.x/5.x", "3x"}};
#define GENS (sizeof gens / sizeof gens[0])

static void die(const char *what)
{
    fprintf(stderr, "urrt_lua: %s\n", what);
    exit(1);
}

static void lua_string(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') {
            putchar('\\');
        }
        putchar(*s);
    }
    putchar('"');
}

static uint32_t length_of(unsigned doubles)
{
    return URRT_HEADER_SIZE + 8u * doubles;
}

/* A packet of `doubles` columns in which column c holds the number c. */
static size_t probe_packet(uint8_t *p, unsigned doubles)
{
    uint32_t len = length_of(doubles);
    for (unsigned i = 0; i < 4; i++) {
        p[i] = (uint8_t)(len >> (24 - 8 * i));
    }
    for (unsigned c = 1; c <= doubles; c++) {
        double v = (double)c;
        uint64_t u;
        memcpy(&u, &v, sizeof u);
        for (unsigned i = 0; i < 8; i++) {
            p[URRT_HEADER_SIZE + 8 * (c - 1) + i] = (uint8_t)(u >> (56 - 8 * i));
        }
    }
    return len;
}

/* The Lua size rule (below) must be urrt_packet_length()'s. */
static int lua_size_rule(long size)
{
    if (size < URRT_PACKET_MIN) {
        return URRT_E_SIZE_SMALL;
    }
    if ((size - URRT_HEADER_SIZE) % 8 != 0) {
        return URRT_E_SIZE_ALIGN;
    }
    return size > URRT_PACKET_MAX ? URRT_E_SIZE_LARGE : URRT_OK;
}

static void print_size_rules(void)
{
    uint8_t buf[URRT_PACKET_MAX + 64] = {0};
    for (long size = -64; size <= URRT_PACKET_MAX + 64; size++) {
        uint32_t u = (uint32_t)size;
        int lib;
        for (unsigned i = 0; i < 4; i++) {
            buf[i] = (uint8_t)(u >> (24 - 8 * i));
        }
        lib = urrt_packet_length(buf, sizeof buf);
        if ((lib < 0 ? lib : URRT_OK) != lua_size_rule(size)) {
            die("urrt_packet_length() no longer follows the size rule this program prints");
        }
    }
    printf("-- Message sizes (urrt_packet_length): a big-endian int32 header counting\n"
           "-- itself, then doubles; a plausible size is %d + 8n from %d to %d.\n",
           URRT_HEADER_SIZE, URRT_PACKET_MIN, URRT_PACKET_MAX);
    printf("local HEADER, PACKET_MIN, PACKET_MAX = %d, %d, %d\n", URRT_HEADER_SIZE, URRT_PACKET_MIN,
           URRT_PACKET_MAX);
    printf("local SIZE_SMALL = ");
    lua_string(urrt_strerror(URRT_E_SIZE_SMALL));
    printf("\nlocal SIZE_ALIGN = ");
    lua_string(urrt_strerror(URRT_E_SIZE_ALIGN));
    printf("\nlocal SIZE_LARGE = ");
    lua_string(urrt_strerror(URRT_E_SIZE_LARGE));
    printf("\nlocal PORTS = { %d, %d }\nlocal UNKNOWN_NAME = ", URRT_LINK_PORT_RW, URRT_LINK_PORT_RO);
    lua_string(URRT_UNKNOWN_NAME);
    printf("\n\n");
}

static void print_versions(void)
{
    printf("-- Controller software per message size (urrt_versions_of).\nlocal VERSIONS = {\n");
    for (unsigned d = 1; d <= URRT_MAX_DOUBLES; d++) {
        const char *v = urrt_versions_of(length_of(d));
        if (v != NULL) {
            printf("    [%u] = ", (unsigned)length_of(d));
            lua_string(v);
            printf(",\n");
        }
    }
    printf("}\n\n");
}

static const char *gen_name(urrt_generation g)
{
    for (unsigned i = 0; i < GENS; i++) {
        if (gens[i].gen == g) {
            return gens[i].name;
        }
    }
    die("a generation this program does not know");
    return NULL;
}

static void print_generations(void)
{
    unsigned first = 1;
    printf("-- Generation per number of doubles (urrt_generation_of): first, last, name.\n"
           "local GENERATIONS = {\n");
    for (unsigned d = 1; d <= URRT_MAX_DOUBLES; d++) {
        urrt_generation g = urrt_generation_of(length_of(d));
        if (d == URRT_MAX_DOUBLES || urrt_generation_of(length_of(d + 1)) != g) {
            printf("    { %u, %u, \"%s\" },\n", first, d, gen_name(g));
            first = d + 1;
        }
    }
    printf("}\n\n");
}

/* Lua name of the enumeration a field is coded in for a generation: the
 * field's name, with the generation's suffix where generations differ. */
static void enum_name(char *buf, size_t size, unsigned id, unsigned gi)
{
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    urrt_enum_kind kind = urrt_field_enum((urrt_field_id)id, gens[gi].gen);
    bool differs = false;
    for (unsigned g = 0; g < GENS; g++) {
        urrt_enum_kind other = urrt_field_enum((urrt_field_id)id, gens[g].gen);
        differs |= other != URRT_ENUM_NONE && other != kind;
    }
    snprintf(buf, size, differs ? "%s_%s" : "%s", f->name, gens[gi].suffix);
}

static void print_enums(void)
{
    bool done[64] = {false};
    printf("-- Enumerations (urrt_enum_entries); any other value is %s.\n", URRT_UNKNOWN_NAME);
    for (unsigned gi = 0; gi < GENS; gi++) {
        for (unsigned id = 0; id < URRT_FIELD_COUNT; id++) {
            urrt_enum_kind kind = urrt_field_enum((urrt_field_id)id, gens[gi].gen);
            size_t count;
            const urrt_enum_entry *e = urrt_enum_entries(kind, &count);
            char name[64];
            if (kind == URRT_ENUM_NONE || done[kind]) {
                continue;
            }
            done[kind] = true;
            enum_name(name, sizeof name, id, gi);
            printf("local %s = {", name);
            for (size_t i = 0; i < count; i++) {
                printf("%s[%d] = ", i % 4 == 0 ? "\n    " : " ", e[i].value);
                lua_string(e[i].name);
                putchar(',');
            }
            printf("\n}\n");
        }
    }
    printf("\n");
}

static void print_fields(void)
{
    printf("-- The field table (URRT_FIELDS): name, elements, unit, description.\nlocal FIELDS = {\n");
    for (unsigned id = 0; id < URRT_FIELD_COUNT; id++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)id);
        printf("    { \"%s\", %u, ", f->name, f->count);
        lua_string(f->unit);
        printf(", ");
        lua_string(f->description);
        printf(" },\n");
    }
    printf("}\n\n");
}

typedef struct row {
    unsigned id, column, fewest;
} row;

/*
 * Where a field sits in packets of a generation, found by asking urrt_read()
 * of a packet of every length: its first column, and the fewest doubles a
 * packet needs to hold it (the 1.x accelerometer needs 95, more than its
 * columns). False if no packet of the generation holds it.
 */
static bool probe_field(unsigned id, urrt_generation gen, row *r)
{
    uint8_t pkt[URRT_PACKET_MAX];
    const urrt_field_info *f = urrt_field((urrt_field_id)id);
    unsigned first_doubles = 0;
    bool found = false;
    for (unsigned d = 1; d <= URRT_MAX_DOUBLES; d++) {
        size_t len;
        double v;
        bool present;
        if (urrt_generation_of(length_of(d)) != gen) {
            continue;
        }
        if (first_doubles == 0) {
            first_doubles = d;
        }
        len = probe_packet(pkt, d);
        present = urrt_read(pkt, len, (urrt_field_id)id, 0, &v) == URRT_OK;
        if (found && !present) {
            die("a field present in a shorter packet is absent in a longer one");
        }
        if (present && !found) {
            found = true;
            r->id = id;
            r->column = (unsigned)v;
            /* Present from the generation's first length on: its columns say it. */
            r->fewest = d == first_doubles ? r->column + f->count - 1u : d;
        }
        if (present) {
            for (unsigned i = 0; i < f->count; i++) {
                if (urrt_read(pkt, len, (urrt_field_id)id, i, &v) != URRT_OK || v != (double)(r->column + i)) {
                    die("a field's elements are not consecutive columns");
                }
            }
        }
    }
    return found;
}

static void print_layout(unsigned gi)
{
    row rows[URRT_FIELD_COUNT];
    unsigned n = 0, end = 0;
    for (unsigned id = 0; id < URRT_FIELD_COUNT; id++) {
        row r;
        unsigned j;
        if (!probe_field(id, gens[gi].gen, &r)) {
            continue;
        }
        for (j = n; j > 0 && rows[j - 1].column > r.column; j--) {
            rows[j] = rows[j - 1];
        }
        rows[j] = r;
        n++;
    }
    printf("    [\"%s\"] = {\n", gens[gi].name);
    for (unsigned i = 0; i < n; i++) {
        const urrt_field_info *f = urrt_field((urrt_field_id)rows[i].id);
        char name[64];
        if (rows[i].column <= end) {
            die("two fields share a column");
        }
        end = rows[i].column + f->count - 1u;
        printf("        { \"%s\", %u, %u", f->name, rows[i].column, rows[i].fewest);
        if (urrt_field_enum((urrt_field_id)rows[i].id, gens[gi].gen) != URRT_ENUM_NONE) {
            enum_name(name, sizeof name, rows[i].id, gi);
            printf(", %s", name);
        }
        printf(" },\n");
    }
    printf("    },\n");
}

/* How the dissector reads one element of an RTDE type; lib/ knows each
 * type's name and size, this adds the element coding (checked against them). */
static const struct {
    urrt_rtde_type type;
    const char *element; /* "double", "int32", "uint32", "uint64", "uint8", "bool" */
    unsigned element_size, count;
} rtde_codings[] = {
    {URRT_RTDE_T_BOOL, "bool", 1, 1},        {URRT_RTDE_T_UINT8, "uint8", 1, 1},
    {URRT_RTDE_T_UINT32, "uint32", 4, 1},    {URRT_RTDE_T_UINT64, "uint64", 8, 1},
    {URRT_RTDE_T_INT32, "int32", 4, 1},      {URRT_RTDE_T_DOUBLE, "double", 8, 1},
    {URRT_RTDE_T_VECTOR3D, "double", 8, 3},  {URRT_RTDE_T_VECTOR6D, "double", 8, 6},
    {URRT_RTDE_T_VECTOR6INT32, "int32", 4, 6}, {URRT_RTDE_T_VECTOR6UINT32, "uint32", 4, 6},
};
#define RTDE_CODINGS (sizeof rtde_codings / sizeof rtde_codings[0])

static void print_rtde_types(void)
{
    if (RTDE_CODINGS != URRT_RTDE_T_COUNT - 1u) {
        die("lib/urrt_rtde.h has an RTDE type this program does not know");
    }
    printf("-- RTDE (urrt_rtde.h): port, header size, the package letters, and the wire\n"
           "-- types (urrt_rtde_type_name, urrt_rtde_type_size): element coding, element\n"
           "-- size, elements.\n");
    printf("local RTDE_PORT, RTDE_HEADER, RTDE_PROTOCOL = %d, %d, %d\n", URRT_RTDE_PORT, URRT_RTDE_HEADER_SIZE,
           URRT_RTDE_PROTOCOL);
    printf("local RTDE_LETTER = { V = %d, v = %d, M = %d, U = %d, O = %d, S = %d, P = %d }\n",
           URRT_RTDE_TYPE_PROTOCOL_VERSION, URRT_RTDE_TYPE_CONTROLLER_VERSION, URRT_RTDE_TYPE_TEXT_MESSAGE,
           URRT_RTDE_TYPE_DATA, URRT_RTDE_TYPE_SETUP_OUTPUTS, URRT_RTDE_TYPE_START, URRT_RTDE_TYPE_PAUSE);
    printf("local RTDE_TYPES = {\n");
    for (unsigned i = 0; i < RTDE_CODINGS; i++) {
        urrt_rtde_type t = rtde_codings[i].type;
        const char *name = urrt_rtde_type_name(t);
        if (name == NULL || rtde_codings[i].element_size * rtde_codings[i].count != urrt_rtde_type_size(t)) {
            die("an RTDE type's size in lib/ is not its elements' here");
        }
        printf("    %s = { \"%s\", %u, %u },\n", name, rtde_codings[i].element, rtde_codings[i].element_size,
               rtde_codings[i].count);
    }
    printf("}\n\n");
}

/* Every RTDE variable: name, wire type, and for a mapped one the urrt field's
 * name, unit, description and (in 3.x/5.x numbering, RTDE's) enumeration. */
static void print_rtde_vars(void)
{
    unsigned gi3 = 0;
    while (gens[gi3].gen != URRT_GEN_3X) {
        gi3++;
    }
    printf("-- RTDE variables (urrt_rtde_var_name, urrt_rtde_var_type, urrt_rtde_var_field):\n"
           "-- name, type, and for those RealTime also has its field, unit, description,\n"
           "-- enumeration.\nlocal RTDE_VARS = {\n");
    for (int var = 0; var < (int)URRT_RTDE_VAR_COUNT; var++) {
        char name[URRT_RTDE_NAME_MAX];
        const char *type = urrt_rtde_type_name(urrt_rtde_var_type(var));
        int field = urrt_rtde_var_field(var);
        if (urrt_rtde_var_name(var, name, sizeof name) < 0 || type == NULL) {
            die("an RTDE variable without a name or a type");
        }
        printf("    { \"%s\", \"%s\"", name, type);
        if (field >= 0) {
            const urrt_field_info *f = urrt_field((urrt_field_id)field);
            printf(", \"%s\", ", f->name);
            lua_string(f->unit);
            printf(", ");
            lua_string(f->description);
            if (urrt_field_enum((urrt_field_id)field, URRT_GEN_3X) != URRT_ENUM_NONE) {
                char e[64];
                enum_name(e, sizeof e, (unsigned)field, gi3);
                printf(", %s", e);
            }
        }
        printf(" },\n");
    }
    printf("}\n\n");
}

static void copy_body(const char *path)
{
    char line[1024];
    FILE *in = fopen(path, "r");
    if (in == NULL) {
        perror(path);
        exit(1);
    }
    while (fgets(line, sizeof line, in) != NULL) {
        if (strncmp(line, "-- SPDX-License-Identifier:", 27) != 0) {
            fputs(line, stdout);
        }
    }
    fclose(in);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: urrt_lua DISSECTOR.lua... > urrt.lua\n");
        return 2;
    }
    printf("-- SPDX-License-Identifier: MIT\n"
           "-- urrt.lua: Wireshark dissector for the Universal Robots RealTime interface\n"
           "-- (TCP 30003 and 30013) and its RTDE interface (TCP 30004), urrt %s.\n"
           "-- Generated from lib/urrt.h and lib/urrt_rtde.h by\n"
           "-- gateway/wireshark/urrt_lua.c: do not edit; the tables come from lib/, the\n"
           "-- code after them from gateway/wireshark/dissector.lua and rtde.lua.\n\n",
           URRT_VERSION_STRING);
    print_size_rules();
    print_versions();
    print_generations();
    print_enums();
    print_fields();
    printf("-- Layout per generation, in column order: field, first column, fewest\n"
           "-- doubles a message needs to hold it, enumeration.\nlocal LAYOUT = {\n");
    for (unsigned gi = 0; gi < GENS; gi++) {
        print_layout(gi);
    }
    printf("}\n\n");
    print_rtde_types();
    print_rtde_vars();
    for (int i = 1; i < argc; i++) {
        copy_body(argv[i]);
    }
    return ferror(stdout) ? 1 : 0;
}
