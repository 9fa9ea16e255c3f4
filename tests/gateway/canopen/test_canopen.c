/* SPDX-License-Identifier: MIT */
/*
 * The gateway's CANopen node (gateway/can/canopen_map.c, co_run.c, eds.c):
 * configurations loaded through the gateway's own loader
 * (gw_config_load_stream), each rejection of issue 18 section 4 with its
 * file, line and reason; the description built for docs/examples/canopen.ini;
 * its EDS read back against the node itself (every object the EDS names read
 * by SDO, of the declared size); the DBC and C tables carrying the same TPDOs.
 *
 * docs/canopen.md's table of the example's object dictionary, row for row.
 *
 * A node with [input]s (RPDOs): its EDS read back (NrOfRXPDO, 0x1400+n,
 * 0x1600+n, 0x1016, the 0x22xx variables), every value and limit of it
 * against the node by SDO, SDO downloads and RPDO frames through the node.
 * With EDS_CHECK.py (tests/canopen/eds_check.py), both EDSs pass CiA 306's rules.
 *
 * Usage: test_canopen EXAMPLE.ini GENERATED_TABLES.c CANOPEN.md [EDS_CHECK.py]
 *        test_canopen --table EXAMPLE.ini     (prints docs/canopen.md's table)
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "config.h"
#include "dbc.h"
#include "eds.h"
#include "urrt_rtde.h"

/* ---- loading ---------------------------------------------------------------------- */

/* Loads text as "t.ini"; returns the number of errors, their text in *messages (free it). */
static int load(gw_config *cfg, const char *text, char **messages)
{
    size_t size = 0;
    FILE *in = fmemopen((void *)text, strlen(text), "r");
    FILE *err = open_memstream(messages, &size);
    int errors = gw_config_load_stream(cfg, in, "t.ini", err);
    fclose(in);
    fclose(err);
    return errors;
}

static const char robot_can[] = "[robot a]\nhost = h\n[can]\ninterface = log:-\n";   /* lines 1-4 */

/* robot_can, then [canopen] with node_id (lines 5-6), then rest from line 7. */
static void expect(const char *node_id, const char *rest, const char *want, const char *what)
{
    char text[2048];
    char *messages = NULL;
    gw_config cfg;
    int errors;
    snprintf(text, sizeof text, "%s[canopen]\nnode_id = %s\n%s", robot_can, node_id, rest);
    errors = load(&cfg, text, &messages);
    CHECK(errors > 0 && strstr(messages, want) != NULL, "%s: want \"%s\" in:\n%s", what, want, messages);
    gw_config_free(&cfg);
    free(messages);
}

static const char frame1[] = "[frame a]\nperiod_ms = 10\nsignal = q_actual[0] @0|16 intel signed\n"; /* 7-9 */

static void test_rejections(void)
{
    char rest[1024];
    expect("128", frame1, "t.ini:6: node_id = '128': give the CANopen node id, 1..127", "node id above 127");
    expect("0", frame1, "t.ini:6: node_id = '0': give the CANopen node id, 1..127", "node id 0");
    /* Two TPDOs on one COB-ID: an own id that is TPDO1's. */
    snprintf(rest, sizeof rest, "%s[frame b]\nperiod_ms = 10\nid = 0x185\nown_id = yes\n"
             "signal = q_actual[1] @0|16 intel signed\n", frame1);
    expect("5", rest, "t.ini:12: [frame b] id 0x185 is already used by [frame a] (line 7)", "two TPDOs, one COB-ID");
    snprintf(rest, sizeof rest, "%s[frame b]\ntpdo = 1\nperiod_ms = 10\nsignal = q_actual[1] @0|16 intel signed\n",
             frame1);
    expect("5", rest, "t.ini:11: [frame b] is TPDO1, as [frame a] (line 7) already is", "one TPDO number twice");
    /* Signals a PDO cannot map. */
    expect("5", "[frame a]\nperiod_ms = 10\nsignal = q_actual[0] @4|16 intel signed name=q\n",
           "t.ini:9: [frame a] signal q starts at bit 4, inside a byte: a PDO maps whole bytes", "not byte-aligned");
    expect("5", "[frame a]\nperiod_ms = 10\nsignal = q_actual[0] @7|16 motorola signed name=q\n",
           "t.ini:9: [frame a] signal q is Motorola (big-endian): CANopen PDOs are little-endian", "Motorola");
    expect("5", "[frame a]\nperiod_ms = 10\nsignal = q_actual[0] @0|64 intel float64 name=q\n",
           "t.ini:9: [frame a] signal q has 64 bits: a PDO-mapped object holds at most 32 bits", "64 bits");
    expect("5", "[frame a]\nperiod_ms = 10\nsignal = q_actual[0] @0|12 intel signed name=q\n",
           "t.ini:9: [frame a] signal q is signed with 12 bits", "signed, not a whole object");
    expect("5", "[frame a]\nperiod_ms = 10\nsignal = digital_input_bits @0|12 intel unsigned name=d\n"
           "signal = robot_mode @16|8 intel signed\nalive_counter = 12\n",
           "t.ini:11: [frame a] signal alive_counter starts at bit 12", "alive counter inside a byte");
    expect("5", "[frame a]\nperiod_ms = 10\nsignal = digital_input_bits @0|18 intel unsigned name=d\n"
           "signal = robot_mode @24|8 intel signed\n",
           "t.ini:10: [frame a] signal robot_mode: its 1-byte object needs byte 3 that another signal uses",
           "a byte shared by two objects");
    expect("5", "[frame a]\nperiod_ms = 10\nextended = yes\nid = 0x185\nown_id = yes\n"
           "signal = q_actual[0] @0|16 intel signed\n", "t.ini:7: [frame a] (TPDO1) is extended (29-bit)", "29-bit");
    /* A frame id that does not follow from the node id, without saying so. */
    expect("5", "[frame a]\nperiod_ms = 10\nid = 0x181\nsignal = q_actual[0] @0|16 intel signed\n",
           "t.ini:9: [frame a] id = 0x181 is not TPDO1's COB-ID for node_id 5 (0x185): remove id (it follows from "
           "node_id), or keep it and say own_id = yes", "id not from the node id");
    expect("5", "[frame a]\nperiod_ms = 10\nid = 0x605\nown_id = yes\nsignal = q_actual[0] @0|16 intel signed\n",
           "t.ini:9: [frame a] id = 0x605 is one CiA 301 keeps", "an own id CiA 301 reserves");
    expect("5", "[frame a]\ntpdo = 5\nperiod_ms = 10\nsignal = q_actual[0] @0|16 intel signed\n",
           "t.ini:8: [frame a] tpdo = 5: the 1 frames are TPDO1..1, numbered without a gap", "a gap");
    expect("5", "[frame a]\nperiod_ms = 10\ntransmission = sync 241\nsignal = q_actual[0] @0|16 intel signed\n",
           "t.ini:9: transmission = 'sync 241': use event", "SYNC count out of range");
}

static void test_causes_first(void)
{
    char *messages = NULL;
    gw_config cfg;
    char text[512];
    /* The bad value (line 6) before what the file then lacks (the section, line 5). */
    snprintf(text, sizeof text, "%s[canopen]\nnode_id = 200\n%s", robot_can, frame1);
    CHECK(load(&cfg, text, &messages) == 2, "two errors: %s", messages);
    char *value = strstr(messages, "t.ini:6:"), *lack = strstr(messages, "t.ini:5:");
    CHECK(value != NULL && lack != NULL && value < lack, "cause first:\n%s", messages);
    CHECK(strstr(messages, "has no id") == NULL, "no consequence for the frames:\n%s", messages);
    gw_config_free(&cfg);
    free(messages);
    /* A CANopen key without [canopen]. */
    snprintf(text, sizeof text, "%sheartbeat_id = 0x701\n[frame a]\nid = 0x181\nperiod_ms = 10\ntpdo = 1\n"
             "signal = q_actual[0] @0|16 intel signed\n", robot_can);
    CHECK(load(&cfg, text, &messages) == 1 && strstr(messages, "t.ini:9: [frame a] tpdo is a CANopen key: it needs a "
                                                               "[canopen] section") != NULL, "%s", messages);
    gw_config_free(&cfg);
    free(messages);
}

/* ---- the worst-case bus load: the node's traffic beside its TPDOs ---------------------------- */

/* A classic 11-bit frame of `bytes` data bytes, worst-case stuffed (Davis, Burns, Bril and
 * Lukkien 2007: 34 + 8s + 13 + floor((34 + 8s - 1) / 4) bits), in microseconds. */
static double frame_us(unsigned bytes, double bitrate)
{
    unsigned g = 34u + 8u * bytes;
    return (double)(g + 13u + (g - 1u) / 4u) * 1e6 / bitrate;
}

/* --check-config's line for a node with one 2-byte TPDO every 10 ms, the status TPDO (8 bytes
 * every heartbeat_period_ms, 100 by default), the NMT heartbeat (1 byte every heartbeat_ms),
 * EMCY (8 bytes, 10 a second: five conditions starting and ending once a second) and SDO (8
 * bytes, a request and its answer every 10 ms): at 500 kbit/s 150 us / 10 ms = 1.50 %,
 * 270 us / 100 ms = 0.27 %, 130 us / 100 ms = 0.13 %, 2.7 ms/s = 0.27 %, 54 ms/s = 5.40 %. */
static void test_bus_load(void)
{
    struct { const char *bitrate, *heartbeat, *max; double rate; unsigned hb_ms; } cases[] = {
        {"500000", "100", "50", 500000.0, 100},
        {"125000", "0", "50", 125000.0, 0},  /* heartbeat off: no part of it */
        {"125000", "0", "25", 125000.0, 0},  /* over: the error names the parts */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[1024], want[512], parts[256], line[512];
        char *messages = NULL;
        gw_config cfg;
        double tpdo = frame_us(2, cases[i].rate) / 10000.0, status = frame_us(8, cases[i].rate) / 100000.0;
        double hb = cases[i].hb_ms ? frame_us(1, cases[i].rate) / (cases[i].hb_ms * 1000.0) : 0.0;
        double emcy = 10.0 * frame_us(8, cases[i].rate) / 1e6, sdo = 200.0 * frame_us(8, cases[i].rate) / 1e6;
        int n = snprintf(parts, sizeof parts, "TPDOs %.2f%% + status TPDO %.2f%%", tpdo * 100, status * 100);
        if (cases[i].hb_ms) {
            n += snprintf(parts + n, sizeof parts - (size_t)n, " + heartbeat %.2f%%", hb * 100);
        }
        snprintf(parts + n, sizeof parts - (size_t)n, " + EMCY %.2f%% + SDO %.2f%%", emcy * 100, sdo * 100);
        snprintf(text, sizeof text,
                 "[robot a]\nhost = h\n[can]\ninterface = log:-\nbitrate = %s\nmax_bus_load = %s\n[canopen]\n"
                 "node_id = 5\nheartbeat_ms = %s\n[frame a]\nperiod_ms = 10\nlength = 2\n"
                 "signal = q_actual[0] @0|16 intel signed\n", cases[i].bitrate, cases[i].max, cases[i].heartbeat);
        int errors = load(&cfg, text, &messages);
        double total = (tpdo + status + hb + emcy + sdo) * 100;
        if (i < 2) {
            snprintf(want, sizeof want, "1 frame + status TPDO 0x285 on log:-, worst-case bus load %.1f%% of %s bit/s "
                     "(max %s%%): %s", total, cases[i].bitrate, cases[i].max, parts);
            CHECK(errors == 0, "case %zu loads: %s", i, messages);
            if (errors == 0) {
                can_map_describe(&cfg.can, line, sizeof line);
                CHECK_EQ_STR(line, want);
            }
        } else {
            snprintf(want, sizeof want, "t.ini:6: worst-case bus load %.1f%% at %s bit/s is over max_bus_load = %s%% "
                     "(%s; heaviest: a %.1f%%): lengthen periods", total, cases[i].bitrate, cases[i].max, parts,
                     tpdo * 100);
            CHECK(errors == 1 && strstr(messages, want) == messages, "want \"%s\" in:\n%s", want, messages);
        }
        gw_config_free(&cfg);
        free(messages);
    }
}

/* ---- the example's description -------------------------------------------------------- */

static void test_description(const gw_config *cfg)
{
    const urrt_co_desc *d = co_run_desc(cfg->co_run);
    size_t rx_count;
    const uint32_t *rx = co_run_rx_ids(cfg->co_run, &rx_count);
    CHECK_EQ_INT(d->node_id, 5);
    CHECK_EQ_INT(d->nmt_start, URRT_CO_START_OPERATIONAL);
    CHECK_EQ_INT(d->heartbeat_ms, 1000);
    CHECK_EQ_INT(d->tpdo_count, 5); /* TPDO1..4 and the status TPDO */
    CHECK_EQ_INT(d->tpdos[0].cob_id, URRT_CO_COB_DEFAULT);
    CHECK_EQ_INT(d->tpdos[3].transmission_type, 1);
    CHECK_EQ_INT(d->tpdos[4].cob_id, 0x80000685u);
    {
        char line[512];
        co_run_describe(cfg->co_run, line, sizeof line);
        CHECK(strstr(line, "node 5: TPDO1..4 at 0x185 0x285 0x385 0x485, status TPDO5 at 0x685 (off until enabled)") ==
                  line, "--check-config's line names the COB-IDs: %s", line);
    }
    /* TPDO1: q0..q2 INTEGER16 at 0x2100 sub 1..3, the alive counter and validity bit a byte each. */
    CHECK_EQ_INT(d->tpdos[0].mapping_count, 5);
    CHECK_EQ_INT(d->tpdos[0].mapping[0], 0x21000110u);
    CHECK_EQ_INT(d->tpdos[0].mapping[3], 0x21000408u);
    CHECK_EQ_INT(d->tpdos[0].mapping[4], 0x21000508u);
    /* Status: whole-byte values mapped (robot mode, safety mode, data age, drops), a dummy byte
     * for each byte of bit fields. */
    CHECK_EQ_INT(d->tpdos[4].mapping_count, 6);
    CHECK_EQ_INT(d->tpdos[4].mapping[0], 0x00050008u);
    CHECK_EQ_INT(d->tpdos[4].mapping[1], 0x20000308u);
    CHECK_EQ_INT(d->tpdos[4].mapping[4], 0x20000C10u);
    CHECK_EQ_INT(rx_count, 3);
    CHECK(rx[0] == 0x000 && rx[1] == 0x080 && rx[2] == 0x605, "rx ids %X %X %X", rx[0], rx[1], rx[2]);
    for (size_t i = 0; i < d->object_count; i++) {
        if (d->objects[i].index == 0x2100 && d->objects[i].sub == 1) {
            CHECK_EQ_INT(d->objects[i].type, URRT_CO_INTEGER16);
        }
    }
}

/* ---- the EDS against the node ----------------------------------------------------------- */

/* The value of key in [section] of the EDS text, or NULL. */
static const char *eds_get(const char *eds, const char *section, const char *key, char *buf, size_t size)
{
    char head[64];
    const char *p;
    snprintf(head, sizeof head, "\n[%s]\n", section);
    if (strncmp(eds, head + 1, strlen(head + 1)) == 0) {
        p = eds + strlen(head + 1); /* the first section: no '\n' before it */
    } else if ((p = strstr(eds, head)) != NULL) {
        p += strlen(head);
    } else {
        return NULL;
    }
    for (; *p != '\0' && *p != '\n' && *p != '['; p = strchr(p, '\n') + 1) {
        size_t n = strlen(key);
        if (strncmp(p, key, n) == 0 && p[n] == '=') {
            size_t len = strcspn(p + n + 1, "\n");
            snprintf(buf, size, "%.*s", (int)len, p + n + 1);
            return buf;
        }
    }
    return NULL;
}

struct sink {
    urrt_can_frame last;
    unsigned count;
};

static void sink_emit(void *ctx, const urrt_can_frame *frame, uint64_t now_us)
{
    struct sink *s = ctx;
    (void)now_us;
    s->last = *frame;
    s->count++;
}

/* The size an SDO upload of index/sub reports, or -1 (abort: *abort); the
 * value of an expedited one in *value (0 for a segmented one). */
static long sdo_upload(urrt_co *node, unsigned index, unsigned sub, uint32_t *value, uint32_t *abort)
{
    struct sink s = {0};
    uint8_t req[8] = {0x40, (uint8_t)index, (uint8_t)(index >> 8), (uint8_t)sub, 0, 0, 0, 0};
    uint8_t cs;
    urrt_co_on_frame(node, 0x605, 0, req, 8, 1000, sink_emit, &s);
    cs = s.last.data[0];
    *abort = 0;
    *value = 0;
    if (s.count != 1 || s.last.id != 0x585) {
        return -2;
    }
    if (cs == 0x80) {
        *abort = (uint32_t)s.last.data[4] | (uint32_t)s.last.data[5] << 8 | (uint32_t)s.last.data[6] << 16 |
                 (uint32_t)s.last.data[7] << 24;
        return -1;
    }
    if (cs == 0x41) {
        uint8_t abort_req[8] = {0x80, 0, 0, 0, 0, 0, 0, 0};
        urrt_co_on_frame(node, 0x605, 0, abort_req, 8, 1000, sink_emit, &s); /* ends the segmented upload */
        return (long)s.last.data[4] | (long)s.last.data[5] << 8;
    }
    for (int i = 0; i < 4 - ((cs >> 2) & 3); i++) {
        *value |= (uint32_t)s.last.data[4 + i] << (8 * i);
    }
    return 4 - ((cs >> 2) & 3);
}

/* An expedited SDO download of `bytes` bytes (1..4) of value to index/sub:
 * 0 for the node's confirmation [0x60, idx, sub], its abort code, or
 * UINT32_MAX for any other answer. */
static uint32_t sdo_download(urrt_co *node, unsigned index, unsigned sub, uint32_t value, unsigned bytes)
{
    struct sink s = {0};
    uint8_t req[8] = {(uint8_t)(0x23u | (4u - bytes) << 2), (uint8_t)index, (uint8_t)(index >> 8), (uint8_t)sub,
                      (uint8_t)value, (uint8_t)(value >> 8), (uint8_t)(value >> 16), (uint8_t)(value >> 24)};
    urrt_co_on_frame(node, 0x605, 0, req, 8, 1000, sink_emit, &s);
    if (s.count != 1 || s.last.id != 0x585 || s.last.len != 8 || s.last.data[1] != req[1] ||
        s.last.data[2] != req[2] || s.last.data[3] != req[3]) {
        return UINT32_MAX;
    }
    if (s.last.data[0] == 0x80) {
        return (uint32_t)s.last.data[4] | (uint32_t)s.last.data[5] << 8 | (uint32_t)s.last.data[6] << 16 |
               (uint32_t)s.last.data[7] << 24;
    }
    return s.last.data[0] == 0x60 && s.last.data[4] == 0 && s.last.data[7] == 0 ? 0u : UINT32_MAX;
}

/* An EDS number (CiA 306): decimal (signed too), 0x hex, "$NODEID+0x.." for node 5. */
static bool eds_number(const char *text, uint32_t *value)
{
    char *end = NULL;
    uint32_t base = 0;
    if (strncmp(text, "$NODEID+", 8) == 0) {
        base = 5;
        text += 8;
    }
    if (text[0] == '-') {
        long long v = strtoll(text, &end, 10);
        *value = (uint32_t)v;
    } else {
        *value = base + (uint32_t)strtoull(text, &end, 0);
    }
    return end != NULL && end != text && *end == '\0';
}

static long type_size(unsigned type)
{
    switch (type) {
    case URRT_CO_INTEGER8: case URRT_CO_UNSIGNED8: return 1;
    case URRT_CO_INTEGER16: case URRT_CO_UNSIGNED16: return 2;
    case URRT_CO_VISIBLE_STRING: return 0;
    default: return 4;
    }
}

/* One VAR section of the EDS: read by SDO, of the size its DataType says,
 * and (the node right after a reset) of its DefaultValue, where the value is
 * the node's own: not 0x1001, 0x1003 nor a robot value's (manufacturer, ro). */
static unsigned check_var(const char *eds, urrt_co *node, unsigned index, int sub)
{
    char name[32], buf[64], def[64], access[8];
    uint32_t abort, value, want_value;
    long size, want;
    if (sub < 0) {
        snprintf(name, sizeof name, "%04X", index);
    } else {
        snprintf(name, sizeof name, "%04Xsub%X", index, (unsigned)sub);
    }
    if (eds_get(eds, name, "DataType", buf, sizeof buf) == NULL) {
        CHECK(0, "[%s] has no DataType", name);
        return 0;
    }
    want = type_size((unsigned)strtoul(buf, NULL, 0));
    size = sdo_upload(node, index, sub < 0 ? 0u : (unsigned)sub, &value, &abort);
    if (index == 0x1003 && sub > 0) {
        CHECK(size == -1 && abort == URRT_CO_ABORT_NO_DATA, "[%s]: no error recorded yet: 0x08000024", name);
    } else {
        CHECK(size >= 0 && (want == 0 || size == want), "[%s]: SDO size %ld (abort 0x%08X), EDS DataType %s", name,
              size, abort, buf);
    }
    if (want == 0 || index == 0x1001 || index == 0x1003 || size != want ||
        eds_get(eds, name, "DefaultValue", def, sizeof def) == NULL ||
        eds_get(eds, name, "AccessType", access, sizeof access) == NULL ||
        (index >= 0x2000 && sub > 0 && strcmp(access, "ro") == 0)) {
        return 1;
    }
    CHECK(eds_number(def, &want_value), "[%s] DefaultValue %s is a number", name, def);
    if (want < 4) {
        want_value &= (UINT32_C(1) << (8 * want)) - 1u;
    }
    CHECK(value == want_value, "[%s]: SDO reads 0x%X, the EDS's DefaultValue %s", name, value, def);
    return 1;
}

/* Every object the three lists name, each sub-index of a record. */
static unsigned check_listed(const char *eds, urrt_co *node, const char *list)
{
    char buf[64], key[16];
    unsigned count = 0, vars = 0;
    if (eds_get(eds, list, "SupportedObjects", buf, sizeof buf) == NULL) {
        CHECK(0, "[%s] missing", list);
        return 0;
    }
    count = (unsigned)strtoul(buf, NULL, 0);
    for (unsigned i = 1; i <= count; i++) {
        char name[16];
        unsigned index;
        snprintf(key, sizeof key, "%u", i);
        index = (unsigned)strtoul(eds_get(eds, list, key, buf, sizeof buf) ? buf : "0", NULL, 0);
        snprintf(name, sizeof name, "%04X", index);
        if (eds_get(eds, name, "SubNumber", buf, sizeof buf) == NULL) {
            vars += check_var(eds, node, index, -1);
            continue;
        }
        for (unsigned sub = 0; sub < 256; sub++) {
            char sname[24];
            snprintf(sname, sizeof sname, "%04Xsub%X", index, sub);
            if (eds_get(eds, sname, "DataType", buf, sizeof buf) != NULL) {
                vars += check_var(eds, node, index, (int)sub);
            }
        }
    }
    return vars;
}

static void test_eds(gw_config *cfg)
{
    char *eds = NULL, buf[64];
    size_t size = 0;
    FILE *out = open_memstream(&eds, &size);
    urrt_co *node = co_run_node(cfg->co_run);
    struct sink s = {0};
    unsigned vars;
    CHECK_EQ_INT(eds_write(out, cfg->co_run, &cfg->co, &cfg->can, "canopen.ini", NULL), 0);
    fclose(out);
    CHECK(strncmp(eds, "[FileInfo]\n", 11) == 0, "EDS begins with [FileInfo]");
    CHECK(eds_get(eds, "FileInfo", "FileName", buf, sizeof buf) && strcmp(buf, "urrt-node5.eds") == 0,
          "FileName on standard output: %s", buf);
    CHECK(eds_get(eds, "DeviceInfo", "NrOfTXPDO", buf, sizeof buf) && strcmp(buf, "5") == 0, "NrOfTXPDO %s", buf);
    /* No [input]s: no RPDO, no 0x1016, no 0x22xx, as before RPDOs came. */
    CHECK(eds_get(eds, "DeviceInfo", "NrOfRXPDO", buf, sizeof buf) && strcmp(buf, "0") == 0, "NrOfRXPDO %s", buf);
    CHECK(strstr(eds, "\n[1400]\n") == NULL && strstr(eds, "\n[1600]\n") == NULL && strstr(eds, "\n[1016]\n") == NULL &&
              strstr(eds, "\n[2200]\n") == NULL && strstr(eds, "=0x1400\n") == NULL && strstr(eds, "=0x1016\n") == NULL,
          "without [input]s: no RPDO objects, no 0x1016");
    {
        char text[160];
        CHECK(eds_get(eds, "FileInfo", "Description", text, sizeof text) &&
                  strcmp(text, "urrt-gateway CANopen node from canopen.ini: Universal Robots RealTime data as TPDOs") ==
                      0,
              "Description %s", text);
    }
    CHECK(eds_get(eds, "DeviceInfo", "BaudRate_500", buf, sizeof buf) && strcmp(buf, "1") == 0, "BaudRate_500");
    CHECK(eds_get(eds, "1800sub1", "DefaultValue", buf, sizeof buf) && strcmp(buf, "$NODEID+0x40000180") == 0, "%s", buf);
    CHECK(eds_get(eds, "1014", "DefaultValue", buf, sizeof buf) && strcmp(buf, "$NODEID+0x80") == 0, "%s", buf);
    CHECK(eds_get(eds, "1A00sub1", "DefaultValue", buf, sizeof buf) && strcmp(buf, "0x21000110") == 0, "%s", buf);
    CHECK(eds_get(eds, "2100sub1", "ParameterName", buf, sizeof buf) &&
          strstr(buf, "q0: q_actual[0], rad = raw x 0.0002") == buf, "scaling in the name: %s", buf);
    for (unsigned n = 0; n < 5; n++) {
        char sec[16];
        snprintf(sec, sizeof sec, "%04Xsub1", 0x1800 + n);
        CHECK(eds_get(eds, sec, "DefaultValue", buf, sizeof buf) && strncmp(buf, "$NODEID+0x", 10) == 0 &&
                  (strtoul(buf + 8, NULL, 16) & 0x40000000u) != 0, "[%s] bit 30 (no RTR): %s", sec, buf);
    }
    CHECK(eds_get(eds, "1800sub2", "LowLimit", buf, sizeof buf) && strcmp(buf, "0x1") == 0, "1800sub2 LowLimit");
    CHECK(eds_get(eds, "1800sub2", "HighLimit", buf, sizeof buf) && strcmp(buf, "0xFF") == 0, "1800sub2 HighLimit");
    CHECK(strstr(eds, "241..253 are refused") != NULL, "[Comments] states sub 2's accepted set");
    /* din and dout (0x2103 sub 4, 5) are bit masks: no limits anywhere. */
    CHECK(eds_get(eds, "2103sub4", "LowLimit", buf, sizeof buf) == NULL, "no LowLimit on a mask");
    CHECK(eds_get(eds, "2103sub5", "HighLimit", buf, sizeof buf) == NULL, "no HighLimit on a mask");
    CHECK(strstr(eds, "=0x2103 sub 4 din: digital_input_bits, a bit mask as the robot sends it: no limits\n") != NULL,
          "[Comments]: din without limits");
    CHECK(strstr(eds, "=0x2100 sub 1 q0: q_actual[0], rad = raw x 0.0002 + 0, limits ") != NULL,
          "[Comments]: q0 with its limits");
    urrt_co_start(node, 0, sink_emit, &s);
    CHECK(s.count == 1 && s.last.id == 0x705 && s.last.len == 1 && s.last.data[0] == 0, "boot-up 0x705 [00]");
    vars = check_listed(eds, node, "MandatoryObjects") + check_listed(eds, node, "OptionalObjects") +
           check_listed(eds, node, "ManufacturerObjects");
    CHECK(vars > 100, "%u objects and sub-indices read by SDO", vars);
    free(eds);
}

/* FileName is the file -o names; the dates are SOURCE_DATE_EPOCH's (CiA 306's formats). */
static void test_eds_file_info(gw_config *cfg)
{
    char *eds = NULL, buf[64];
    size_t size = 0;
    FILE *out = open_memstream(&eds, &size);
    setenv("SOURCE_DATE_EPOCH", "1700000000", 1); /* date -u -d @1700000000: Tue Nov 14 22:13:20 UTC 2023 */
    CHECK_EQ_INT(eds_write(out, cfg->co_run, &cfg->co, &cfg->can, "canopen.ini", "out/plc/node5-line2.eds"), 0);
    fclose(out);
    unsetenv("SOURCE_DATE_EPOCH");
    CHECK(eds_get(eds, "FileInfo", "FileName", buf, sizeof buf) && strcmp(buf, "node5-line2.eds") == 0, "%s", buf);
    CHECK(eds_get(eds, "FileInfo", "CreationTime", buf, sizeof buf) && strcmp(buf, "10:13PM") == 0, "%s", buf);
    CHECK(eds_get(eds, "FileInfo", "CreationDate", buf, sizeof buf) && strcmp(buf, "11-14-2023") == 0, "%s", buf);
    CHECK(eds_get(eds, "FileInfo", "ModificationDate", buf, sizeof buf) && strcmp(buf, "11-14-2023") == 0, "%s", buf);
    free(eds);
}

static void count_status(void *ctx, const urrt_can_frame *frame, uint64_t now_us)
{
    (void)now_us;
    *(unsigned *)ctx += frame->id == 0x685;
}

/* The status TPDO (TPDO5, the [can] heartbeat frame: a policy that needs a
 * period) takes event timer 0: it then goes with each robot packet, and
 * not at all without one. */
static void test_status_event_timer_zero(gw_config *cfg)
{
    static const uint8_t start[2] = {0x01, 0x05};
    static const uint8_t enable[8] = {0x23, 0x04, 0x18, 0x01, 0x85, 0x06, 0x00, 0x40};
    static const uint8_t no_timer[8] = {0x2B, 0x04, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00};
    static const uint8_t done[8] = {0x60, 0x04, 0x18, 0x00, 0x00, 0x00, 0x00, 0x00};
    static urrt_state st;
    urrt_co *node = co_run_node(cfg->co_run);
    struct sink s = {0};
    unsigned status = 0;
    urrt_co_start(node, 0, sink_emit, &s);
    urrt_co_on_frame(node, 0x000, 0, start, 2, 0, sink_emit, &s);
    for (unsigned k = 0; k < 2; k++) {
        const uint8_t *req = k == 0 ? enable : no_timer;
        s.count = 0;
        urrt_co_on_frame(node, 0x605, 0, req, 8, 0, sink_emit, &s);
        CHECK(s.count == 1 && s.last.id == 0x585 && s.last.data[0] == done[0] && s.last.data[3] == req[3],
              "0x1804 sub %u written: [%02X ... sub %u]", req[3], s.last.data[0], s.last.data[3]);
    }
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    for (uint64_t t = 1000; t < 2000000; t += 1000) {
        if (t % 8000 == 0 && t <= 400000) { /* 50 packets, then none for 1.6 s */
            urrt_cantx_on_packet(node->tx, 0, &st, t);
        }
        urrt_co_run(node, t, count_status, &status);
    }
    CHECK(status == 50, "status TPDO with event timer 0: one frame per packet, none without (%u)", status);
}

/* ---- docs/canopen.md's table of the example's object dictionary --------------------------- */

static const char *type_name(unsigned type)
{
    static const char *const names[] = {[URRT_CO_INTEGER8] = "INTEGER8", [URRT_CO_INTEGER16] = "INTEGER16",
                                        [URRT_CO_INTEGER32] = "INTEGER32", [URRT_CO_UNSIGNED8] = "UNSIGNED8",
                                        [URRT_CO_UNSIGNED16] = "UNSIGNED16", [URRT_CO_UNSIGNED32] = "UNSIGNED32",
                                        [URRT_CO_REAL32] = "REAL32", [URRT_CO_VISIBLE_STRING] = "VISIBLE_STRING"};
    return type < sizeof names / sizeof names[0] && names[type] ? names[type] : "?";
}

/* Calls row() with each VAR of the EDS as a markdown table row, in the EDS's order. */
static unsigned table_rows(const char *eds, void (*row)(void *ctx, const char *line), void *ctx)
{
    unsigned rows = 0;
    for (const char *p = strstr(eds, "\n["); p != NULL; p = strstr(p + 1, "\n[")) {
        char section[32], name[200], type[16], access[8], def[64], pdo[4], line[400];
        unsigned index = 0, sub = 0;
        int sublen = 0;
        if (sscanf(p + 1, "[%31[^]]]", section) != 1 || sscanf(section, "%4X%n", &index, &sublen) != 1 ||
            sublen != 4 || eds_get(eds, section, "DataType", type, sizeof type) == NULL) {
            continue;
        }
        if (strncmp(section + 4, "sub", 3) == 0) {
            sub = (unsigned)strtoul(section + 7, NULL, 16);
        }
        eds_get(eds, section, "ParameterName", name, sizeof name);
        eds_get(eds, section, "AccessType", access, sizeof access);
        eds_get(eds, section, "DefaultValue", def, sizeof def);
        eds_get(eds, section, "PDOMapping", pdo, sizeof pdo);
        snprintf(line, sizeof line, "| 0x%04X | %u | %s | %s | %s | %s | %s |", index, sub, name,
                 type_name((unsigned)strtoul(type, NULL, 0)), access, def[0] ? def : "\"\"",
                 strcmp(pdo, "1") == 0 ? "yes" : "no");
        row(ctx, line);
        rows++;
    }
    return rows;
}

static void print_row(void *ctx, const char *line)
{
    (void)ctx;
    puts(line);
}

static void find_row(void *ctx, const char *line)
{
    const char *doc = ctx;
    char want[420];
    snprintf(want, sizeof want, "\n%s\n", line);
    CHECK(strstr(doc, want) != NULL, "docs/canopen.md lacks the row: %s", line);
}

static char *eds_text(gw_config *cfg)
{
    char *eds = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&eds, &size);
    eds_write(out, cfg->co_run, &cfg->co, &cfg->can, "canopen.ini", NULL);
    fclose(out);
    return eds;
}

/* Every row of the EDS in docs/canopen.md's table, and no other (the rows of that table counted). */
static void test_doc_table(gw_config *cfg, const char *doc_path)
{
    static char doc[1 << 18];
    FILE *in = fopen(doc_path, "r");
    size_t n = in ? fread(doc, 1, sizeof doc - 1, in) : 0;
    char *eds = eds_text(cfg);
    const char *table = strstr(doc, "\n| 0x1000 | 0 |");
    unsigned doc_rows = 0, rows;
    doc[n] = '\0';
    if (in) {
        fclose(in);
    }
    rows = table_rows(eds, find_row, doc);
    for (const char *p = table; p != NULL && strncmp(p, "\n| 0x", 5) == 0; p = strchr(p + 1, '\n')) {
        doc_rows++;
    }
    CHECK(rows == doc_rows && rows > 100, "%s: %u rows, the EDS %u (regenerate with test_canopen --table)",
          doc_path, doc_rows, rows);
    free(eds);
}

/* ---- the DBC and the C tables ---------------------------------------------------------------- */

static void test_dbc(gw_config *cfg)
{
    char *dbc = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&dbc, &size);
    CHECK_EQ_INT(dbc_write(out, &cfg->can, "canopen.ini"), 0);
    fclose(out);
    CHECK(strstr(dbc, "BO_ 389 tpdo1_joints_a: 8 URRT_GW") != NULL, "TPDO1 at 0x185");
    CHECK(strstr(dbc, "BO_ 1157 tpdo4_status: 8 URRT_GW") != NULL, "TPDO4 at 0x485");
    CHECK(strstr(dbc, " SG_ q0 : 0|16@1- (0.0002,0) [-6.3|6.3] \"rad\"") != NULL, "q0's scaling as the EDS says");
    CHECK(strstr(dbc, "BO_ 1797 ") == NULL, "nothing at 0x705: the NMT heartbeat is not a DBC frame");
    free(dbc);
}

static void test_c_tables(const char *path)
{
    FILE *in = fopen(path, "r");
    static char text[1 << 18];
    size_t n = in ? fread(text, 1, sizeof text - 1, in) : 0;
    text[n] = '\0';
    if (in) {
        fclose(in);
    }
    CHECK(strstr(text, "const urrt_co_desc urrt_gateway_node = {\n    5, URRT_CO_START_OPERATIONAL, 1000,") != NULL,
          "%s carries the node", path);
    CHECK(strstr(text, "{urrt_gateway_tpdo5_mapping, UINT32_C(0x80000685), 4, 0, 254, 6}") != NULL, "status TPDO");
    CHECK(strstr(text, "const uint32_t urrt_gateway_rx_ids[3] = {0x000, 0x080, 0x605};") != NULL, "rx ids");
}

/* ---- RTDE-only values in a TPDO ------------------------------------------------------------ */

static const char rtde_node[] =
    "[robot a]\nhost = h\nversion = 5.10\nsource = rtde\n[can]\ninterface = log:-\n[canopen]\nnode_id = 5\n"
    "[frame a]\nperiod_ms = 10\nsignal = output_int_register_24 @0|32 intel signed name=parts\n"
    "signal = safety_status_bits @32|16 intel unsigned bits=0-15 name=safety\n";

/* The 4 data bytes of an expedited SDO upload of index/sub, as a little-endian number. */
static uint32_t sdo_u32(urrt_co *node, unsigned index, unsigned sub)
{
    struct sink s = {0};
    uint8_t req[8] = {0x40, (uint8_t)index, (uint8_t)(index >> 8), (uint8_t)sub, 0, 0, 0, 0};
    urrt_co_on_frame(node, 0x605, 0, req, 8, 2000, sink_emit, &s);
    CHECK(s.count == 1 && (s.last.data[0] & 0xF3u) == 0x43u, "SDO upload 0x%04X sub %u: expedited (%02x %02x%02x%02x%02x)",
          index, sub, s.last.data[0], s.last.data[4], s.last.data[5], s.last.data[6], s.last.data[7]);
    return (uint32_t)s.last.data[4] | (uint32_t)s.last.data[5] << 8 | (uint32_t)s.last.data[6] << 16 |
           (uint32_t)s.last.data[7] << 24;
}

/* The EDS names the values by their RTDE names, with the scaling; the node's
 * objects hold the package's values, the register exactly. */
static void test_rtde_node(void)
{
    gw_config cfg;
    char *messages = NULL, buf[128];
    int errors = load(&cfg, rtde_node, &messages);
    CHECK(errors == 0 && cfg.co_run != NULL, "an RTDE-only TPDO loads: %s", messages);
    free(messages);
    if (errors == 0 && cfg.co_run != NULL) {
        char *eds = eds_text(&cfg);
        urrt_rtde_values v;
        urrt_state st;
        CHECK_EQ_STR(eds_get(eds, "2100sub1", "ParameterName", buf, sizeof buf),
                     "parts: output_int_register_24, 1 = raw x 1 + 0");
        CHECK_EQ_STR(eds_get(eds, "2100sub1", "DataType", buf, sizeof buf), "0x0004");
        CHECK_EQ_STR(eds_get(eds, "2100sub2", "ParameterName", buf, sizeof buf),
                     "safety: safety_status_bits, a bit mask as the robot sends it");
        CHECK_EQ_STR(eds_get(eds, "2100sub2", "DataType", buf, sizeof buf), "0x0006");
        CHECK(eds_get(eds, "2100sub2", "HighLimit", buf, sizeof buf) == NULL, "a mask has no limits");
        free(eds);
        urrt_rtde_values_clear(&v);
        v.output_int_register[24] = INT32_MIN + 5;
        v.safety_status_bits[0] = 0x0404u;
        for (int k = 0; k < 2; k++) {
            unsigned bit = (unsigned)((k ? URRT_RTDE_V_SAFETY_STATUS_BITS : URRT_RTDE_V_OUTPUT_INT_REGISTER + 24) -
                                      URRT_RTDE_MAPPED_COUNT);
            v.present[bit / 32u] |= 1u << (bit % 32u);
        }
        urrt_state_clear(&st);
        st.time[0] = 1.0;
        st.present = UINT64_C(1) << URRT_F_TIME;
        can_run_rtde(cfg.can_run, 0, &v);
        urrt_cantx_on_packet(can_run_tx(cfg.can_run), 0, &st, 1000);
        CHECK(sdo_u32(co_run_node(cfg.co_run), 0x2100, 1) == (uint32_t)(INT32_MIN + 5), "0x2100 sub 1: INT32_MIN + 5");
        CHECK((sdo_u32(co_run_node(cfg.co_run), 0x2100, 2) & 0xFFFFu) == 0x0404u, "0x2100 sub 2: the mask");
    }
    gw_config_free(&cfg);
}

/* ---- [input]s: RPDOs that write robot input registers ------------------------------------- */

/* Two [input]s, RPDO1 at 0x205 (an UNSIGNED16 with max=9999, two BOOL registers, four dummy
 * bytes) and RPDO2 at 0x305 (INTEGER32, a scaled INTEGER16, INTEGER8: 7 bytes). */
static const char inputs_node[] =
    "[robot arm1]\nhost = h\nsource = rtde\n[can]\ninterface = log:-\nbitrate = 500000\n[canopen]\nnode_id = 5\n"
    "[frame robot_answer]\nperiod_ms = 20\n"
    "signal = output_int_register_24 @0|32 intel signed name=program_state\n"
    "signal = input_int_register_24 @32|16 intel unsigned name=job_echo\n"
    "[input plc_command]\ntimeout_ms = 100\n"
    "signal = input_int_register_24 @0|16 intel unsigned max=9999 name=job_number\n"
    "signal = input_bit_register_64 @16|8 intel unsigned name=start\n"
    "signal = input_bit_register_65 @24|8 intel unsigned name=door_closed\n"
    "[input plc_setpoint]\ntimeout_ms = 250\nlength = 7\n"
    "signal = input_int_register_25 @0|32 intel signed name=offset\n"
    "signal = input_double_register_24 @32|16 intel signed factor=0.001 unit=m/s name=speed\n"
    "signal = input_int_register_26 @48|8 intel signed name=trim\n";

/* Key of [section] is want. */
static void eds_is(const char *eds, const char *section, const char *key, const char *want)
{
    char buf[256];
    const char *got = eds_get(eds, section, key, buf, sizeof buf);
    CHECK(got != NULL && strcmp(got, want) == 0, "[%s] %s=%s, want %s", section, key, got ? got : "(none)", want);
}

/* Whether the list section names index. */
static bool eds_lists(const char *eds, const char *list, unsigned index)
{
    char buf[64], key[16], want[16];
    unsigned count = (unsigned)strtoul(eds_get(eds, list, "SupportedObjects", buf, sizeof buf) ? buf : "0", NULL, 0);
    snprintf(want, sizeof want, "0x%04X", index);
    for (unsigned i = 1; i <= count; i++) {
        snprintf(key, sizeof key, "%u", i);
        if (eds_get(eds, list, key, buf, sizeof buf) != NULL && strcmp(buf, want) == 0) {
            return true;
        }
    }
    return false;
}

/* Every new object's section and keys, as the node serves them. */
static void test_inputs_eds_text(const char *eds)
{
    static const struct { const char *section, *name, *type, *low, *high; } vars[] = {
        {"2200sub1", "job_number: input_int_register_24, 1 = raw x 1 + 0", "0x0006", "0", "9999"},
        {"2200sub2", "start: input_bit_register_64, 1 = raw x 1 + 0", "0x0005", "0", "1"},
        {"2200sub3", "door_closed: input_bit_register_65, 1 = raw x 1 + 0", "0x0005", "0", "1"},
        {"2201sub1", "offset: input_int_register_25, 1 = raw x 1 + 0", "0x0004", "-2147483648", "2147483647"},
        {"2201sub2", "speed: input_double_register_24, m/s = raw x 0.001 + 0", "0x0003", "-32768", "32767"},
        {"2201sub3", "trim: input_int_register_26, 1 = raw x 1 + 0", "0x0002", "-128", "127"},
    };
    static const char *const map1[] = {"0x22000110", "0x22000208", "0x22000308", "0x00050008",
                                       "0x00050008", "0x00050008", "0x00050008"};
    static const char *const map2[] = {"0x22010120", "0x22010210", "0x22010308"};
    char sec[16];
    eds_is(eds, "DeviceInfo", "NrOfRXPDO", "2");
    eds_is(eds, "DeviceInfo", "NrOfTXPDO", "2");
    eds_is(eds, "DummyUsage", "Dummy0005", "1");
    eds_is(eds, "FileInfo", "Description", "urrt-gateway CANopen node from inputs.ini: Universal Robots RealTime "
                                           "data as TPDOs, robot input registers from RPDOs");
    for (unsigned n = 0; n < 2; n++) {
        static const char *const cob[] = {"$NODEID+0x200", "$NODEID+0x300"}, *const timer[] = {"100", "250"};
        unsigned comm = 0x1400 + n, map = 0x1600 + n;
        CHECK(eds_lists(eds, "OptionalObjects", comm) && eds_lists(eds, "OptionalObjects", map),
              "[OptionalObjects] lists 0x%04X and 0x%04X", comm, map);
        snprintf(sec, sizeof sec, "%04X", comm);
        eds_is(eds, sec, "ParameterName", "RPDO communication parameter");
        eds_is(eds, sec, "ObjectType", "0x9");
        eds_is(eds, sec, "SubNumber", "0x4"); /* subs 0, 1, 2, 5 */
        snprintf(sec, sizeof sec, "%04Xsub0", comm);
        eds_is(eds, sec, "AccessType", "ro");
        eds_is(eds, sec, "DefaultValue", "5");
        snprintf(sec, sizeof sec, "%04Xsub1", comm);
        eds_is(eds, sec, "ParameterName", "COB-ID used by RPDO");
        eds_is(eds, sec, "DataType", "0x0007");
        eds_is(eds, sec, "AccessType", "rw");
        eds_is(eds, sec, "DefaultValue", cob[n]);
        snprintf(sec, sizeof sec, "%04Xsub2", comm);
        eds_is(eds, sec, "DataType", "0x0005");
        eds_is(eds, sec, "AccessType", "rw");
        eds_is(eds, sec, "DefaultValue", "254");
        snprintf(sec, sizeof sec, "%04Xsub3", comm);
        CHECK(eds_get(eds, sec, "DataType", sec, sizeof sec) == NULL, "0x%04X has no sub 3", comm);
        snprintf(sec, sizeof sec, "%04Xsub5", comm);
        eds_is(eds, sec, "DataType", "0x0006");
        eds_is(eds, sec, "AccessType", "rw");
        eds_is(eds, sec, "DefaultValue", timer[n]);
        snprintf(sec, sizeof sec, "%04X", map);
        eds_is(eds, sec, "ParameterName", "RPDO mapping parameter");
        eds_is(eds, sec, "SubNumber", n == 0 ? "0x8" : "0x4");
        snprintf(sec, sizeof sec, "%04Xsub0", map);
        eds_is(eds, sec, "AccessType", "ro");
        eds_is(eds, sec, "DefaultValue", n == 0 ? "7" : "3");
        for (unsigned k = 1; k <= (n == 0 ? 7u : 3u); k++) {
            snprintf(sec, sizeof sec, "%04Xsub%X", map, k);
            eds_is(eds, sec, "DataType", "0x0007");
            eds_is(eds, sec, "AccessType", "ro"); /* static: the node refuses a write (0x06010002) */
            eds_is(eds, sec, "PDOMapping", "0");
            eds_is(eds, sec, "DefaultValue", n == 0 ? map1[k - 1] : map2[k - 1]);
        }
    }
    CHECK(eds_get(eds, "1402", "ObjectType", sec, sizeof sec) == NULL, "no RPDO3");
    CHECK(eds_lists(eds, "OptionalObjects", 0x1016), "[OptionalObjects] lists 0x1016");
    eds_is(eds, "1016", "ObjectType", "0x8");
    eds_is(eds, "1016", "SubNumber", "0x2");
    eds_is(eds, "1016sub0", "DefaultValue", "1");
    eds_is(eds, "1016sub0", "AccessType", "ro");
    eds_is(eds, "1016sub1", "DataType", "0x0007");
    eds_is(eds, "1016sub1", "AccessType", "rw");
    eds_is(eds, "1016sub1", "DefaultValue", "0x00000000");
    for (unsigned n = 0; n < 2; n++) {
        snprintf(sec, sizeof sec, "%04X", 0x2200 + n);
        CHECK(eds_lists(eds, "ManufacturerObjects", 0x2200 + n) && !eds_lists(eds, "OptionalObjects", 0x2200 + n),
              "[ManufacturerObjects] lists 0x%04X", 0x2200 + n);
        eds_is(eds, sec, "ObjectType", "0x9");
        eds_is(eds, sec, "SubNumber", "0x4");
        eds_is(eds, sec, "ParameterName", n == 0 ? "RPDO1 values ([input plc_command]: robot arm1's input registers)"
                                                 : "RPDO2 values ([input plc_setpoint]: robot arm1's input registers)");
        snprintf(sec, sizeof sec, "%04Xsub0", 0x2200 + n);
        eds_is(eds, sec, "DataType", "0x0005");
        eds_is(eds, sec, "AccessType", "ro");
        eds_is(eds, sec, "DefaultValue", "3");
    }
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++) {
        eds_is(eds, vars[i].section, "ParameterName", vars[i].name);
        eds_is(eds, vars[i].section, "ObjectType", "0x7");
        eds_is(eds, vars[i].section, "DataType", vars[i].type);
        eds_is(eds, vars[i].section, "AccessType", "rww");
        eds_is(eds, vars[i].section, "PDOMapping", "1");
        eds_is(eds, vars[i].section, "LowLimit", vars[i].low);
        eds_is(eds, vars[i].section, "HighLimit", vars[i].high);
        eds_is(eds, vars[i].section, "DefaultValue", "0");
    }
    /* [Comments]: the limits the gateway writes each register within (max=9999, a BOOL's 0..1). */
    CHECK(strstr(eds, "=0x2200 sub 1 job_number: input_int_register_24, 1 = raw x 1 + 0, limits 0..9999\n") != NULL,
          "[Comments]: job_number within 0..9999");
    CHECK(strstr(eds, "=0x2200 sub 2 start: input_bit_register_64, 1 = raw x 1 + 0, limits 0..1\n") != NULL,
          "[Comments]: a BOOL register within 0..1");
    CHECK(strstr(eds, "=0x2201 sub 2 speed: input_double_register_24, m/s = raw x 0.001 + 0, limits -32.768..32.767\n")
              != NULL, "[Comments]: speed's scaled limits");
    CHECK(strstr(eds, "241..253 are refused") != NULL && strstr(eds, "EMCY 0x8210") != NULL,
          "[Comments]: the RPDO notes");
}

/* The limits of every writable variable the EDS gives agree with the node: the
 * limit itself written and read back, one past it refused (0x06090031 above,
 * 0x06090032 below) where the type holds it. Leaves the node's values changed. */
static unsigned check_limits_by_sdo(const char *eds, urrt_co *node)
{
    unsigned checked = 0;
    for (const char *p = strstr(eds, "\n["); p != NULL; p = strstr(p + 1, "\n[")) {
        char section[32], buf[64], access[8];
        unsigned index = 0, sub = 0;
        int sublen = 0;
        uint32_t low, high, value, abort;
        long bytes;
        if (sscanf(p + 1, "[%31[^]]]", section) != 1 || sscanf(section, "%4Xsub%X%n", &index, &sub, &sublen) != 2 ||
            eds_get(eds, section, "AccessType", access, sizeof access) == NULL || strcmp(access, "ro") == 0 ||
            eds_get(eds, section, "DataType", buf, sizeof buf) == NULL ||
            eds_get(eds, section, "LowLimit", buf, sizeof buf) == NULL || !eds_number(buf, &low) ||
            eds_get(eds, section, "HighLimit", buf, sizeof buf) == NULL || !eds_number(buf, &high)) {
            continue;
        }
        eds_get(eds, section, "DataType", buf, sizeof buf);
        unsigned type = (unsigned)strtoul(buf, NULL, 0);
        bytes = type_size(type);
        bool is_signed = type == URRT_CO_INTEGER8 || type == URRT_CO_INTEGER16 || type == URRT_CO_INTEGER32;
        uint32_t mask = bytes == 4 ? UINT32_MAX : (UINT32_C(1) << (8 * bytes)) - 1u;
        uint32_t type_max = is_signed ? mask >> 1 : mask, type_min = is_signed ? (mask >> 1) + 1u : 0u;
        checked++;
        for (int k = 0; k < 2; k++) {
            uint32_t limit = (k == 0 ? low : high) & mask;
            CHECK(sdo_download(node, index, sub, limit, (unsigned)bytes) == 0, "[%s]: %s 0x%X written", section,
                  k == 0 ? "LowLimit" : "HighLimit", limit);
            CHECK(sdo_upload(node, index, sub, &value, &abort) == bytes && value == limit, "[%s]: read back 0x%X",
                  section, value);
        }
        if ((high & mask) != type_max) {
            CHECK(sdo_download(node, index, sub, (high + 1u) & mask, (unsigned)bytes) == URRT_CO_ABORT_TOO_HIGH,
                  "[%s]: HighLimit + 1 refused with 0x06090031", section);
        }
        if ((low & mask) != type_min) {
            CHECK(sdo_download(node, index, sub, (low - 1u) & mask, (unsigned)bytes) == URRT_CO_ABORT_TOO_LOW,
                  "[%s]: LowLimit - 1 refused with 0x06090032", section);
        }
    }
    return checked;
}

/* tests/canopen/eds_check.py (CiA 306's rules) on the EDS written to a file of its own name. */
static void run_eds_checker(gw_config *cfg, const char *checker, const char *what)
{
    char dir[] = "/tmp/urrt-eds-XXXXXX", path[64], cmd[512], line[512];
    unsigned passed = 0, failed = 1;
    bool summary = false;
    FILE *out, *pipe;
    if (mkdtemp(dir) == NULL) {
        CHECK(0, "mkdtemp");
        return;
    }
    snprintf(path, sizeof path, "%s/urrt-node5.eds", dir);
    out = fopen(path, "w");
    CHECK(out != NULL && eds_write(out, cfg->co_run, &cfg->co, &cfg->can, what, path) == 0, "EDS to %s", path);
    if (out != NULL) {
        fclose(out);
    }
    snprintf(cmd, sizeof cmd, "python3 %s %s 5 2>&1", checker, path);
    pipe = popen(cmd, "r");
    while (pipe != NULL && fgets(line, sizeof line, pipe) != NULL) {
        if (strncmp(line, "FAIL", 4) == 0) {
            fprintf(stderr, "%s: %s", what, line);
        }
        summary = sscanf(line, "%u passed, %u failed", &passed, &failed) == 2 || summary;
    }
    CHECK(pipe != NULL && pclose(pipe) == 0 && summary && failed == 0 && passed > 1000,
          "%s: eds_check.py %u passed, %u failed", what, passed, failed);
    remove(path);
    rmdir(dir);
}

struct frames {
    urrt_can_frame f[64];
    unsigned count;
};

static void frames_emit(void *ctx, const urrt_can_frame *frame, uint64_t now_us)
{
    struct frames *s = ctx;
    (void)now_us;
    if (s->count < sizeof s->f / sizeof s->f[0]) {
        s->f[s->count] = *frame;
    }
    s->count++;
}

/* EMCYs (0x085) among the frames with this code (bytes 0-1), or the error reset of it (bytes 3-4). */
static unsigned emcys(const struct frames *s, unsigned code, bool reset, uint8_t rpdo)
{
    unsigned n = 0;
    for (unsigned i = 0; i < s->count && i < sizeof s->f / sizeof s->f[0]; i++) {
        const uint8_t *d = s->f[i].data;
        unsigned at = reset ? 3u : 0u;
        n += s->f[i].id == 0x085 && s->f[i].len == 8 && (unsigned)(d[at] | d[at + 1] << 8) == code && d[5] == rpdo &&
             (!reset || (d[0] == 0 && d[1] == 0)) && (reset || (d[2] & 0x11u) == 0x11u);
    }
    return n;
}

static uint32_t read_u(urrt_co *node, unsigned index, unsigned sub)
{
    uint32_t value, abort;
    long size = sdo_upload(node, index, sub, &value, &abort);
    CHECK(size > 0, "0x%04X sub %u readable (abort 0x%08X)", index, sub, abort);
    return value;
}

/* The node's SDO server on the [input]s' objects, frame by frame. */
static void test_inputs_sdo(gw_config *cfg)
{
    urrt_co *node = co_run_node(cfg->co_run);
    struct sink s = {0};
    uint32_t before;
    urrt_co_start(node, 0, sink_emit, &s);
    /* An expedited download stores the value: read back by upload, and as the gateway takes it. */
    CHECK(sdo_download(node, 0x2200, 1, 1234, 2) == 0, "0x2200 sub 1 = 1234: [60 00 22 01]");
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 1234);
    CHECK_EQ_INT(co_run_input_raw(cfg->co_run, 0, 0), 1234);
    CHECK(co_run_input_written_us(cfg->co_run, 0) != URRT_CANTX_NEVER, "the SDO write is recorded");
    CHECK(sdo_download(node, 0x2201, 3, 0xFE, 1) == 0 && read_u(node, 0x2201, 3) == 0xFE, "INTEGER8 -2 stored");
    CHECK_EQ_INT(co_run_input_raw(cfg->co_run, 1, 2), 0xFE);
    /* A read-only robot value (TPDO1's 0x2100 sub 1). */
    CHECK_EQ_INT(sdo_download(node, 0x2100, 1, 7, 4), URRT_CO_ABORT_READ_ONLY);
    /* Lengths: 4 bytes into an UNSIGNED16, 1 byte into it, a request frame of 5 bytes. */
    CHECK_EQ_INT(sdo_download(node, 0x2200, 1, 5, 4), URRT_CO_ABORT_TOO_LONG);
    CHECK_EQ_INT(sdo_download(node, 0x2200, 1, 5, 1), URRT_CO_ABORT_TOO_SHORT);
    {
        static const uint8_t five[5] = {0x2B, 0x00, 0x22, 0x01, 0x05};
        s.count = 0;
        urrt_co_on_frame(node, 0x605, 0, five, sizeof five, 1000, sink_emit, &s);
        CHECK(s.count == 1 && s.last.data[0] == 0x80 && s.last.data[1] == 0x00 && s.last.data[2] == 0x22 &&
                  s.last.data[3] == 1 && s.last.data[4] == 0x10 && s.last.data[5] == 0x00 && s.last.data[6] == 0x07 &&
                  s.last.data[7] == 0x06, "a 5-byte request: abort 0x06070010 for 0x2200 sub 1");
    }
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 1234); /* none of them stored anything */
    /* Past the object's range: 2 into a BOOL register's. */
    before = read_u(node, 0x2200, 2);
    CHECK_EQ_INT(sdo_download(node, 0x2200, 2, 2, 1), URRT_CO_ABORT_TOO_HIGH);
    CHECK_EQ_INT(read_u(node, 0x2200, 2), before);
    CHECK(sdo_download(node, 0x2200, 2, 1, 1) == 0 && read_u(node, 0x2200, 2) == 1, "1 into the BOOL's object");
    /* The mapping is static (lib/urrt_co_rx.c: 0x1600+n has no write): read-only, sub 0 too. */
    CHECK_EQ_INT(sdo_download(node, 0x1600, 1, 0x22000110u, 4), URRT_CO_ABORT_READ_ONLY);
    CHECK_EQ_INT(sdo_download(node, 0x1600, 0, 0, 1), URRT_CO_ABORT_READ_ONLY);
    CHECK_EQ_INT(read_u(node, 0x1600, 0), 7);
    /* The RPDOs past the configured ones do not exist; RPDO transmission types 241..253 are refused. */
    CHECK_EQ_INT(sdo_download(node, 0x1402, 2, 254, 1), URRT_CO_ABORT_NO_OBJECT);
    CHECK_EQ_INT(sdo_download(node, 0x1400, 2, 241, 1), URRT_CO_ABORT_TOO_HIGH);
    /* A reset node takes the defaults back. */
    urrt_co_start(node, 0, sink_emit, &s);
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 0);
    CHECK(co_run_input_written_us(cfg->co_run, 0) == URRT_CANTX_NEVER, "reset: no write recorded");
}

/* RPDOs as a manager sends them: acted on in OPERATIONAL only; a short one raises EMCY 0x8210 once. */
static void test_inputs_rpdo(gw_config *cfg)
{
    static const uint8_t start[2] = {0x01, 0x05};
    static const uint8_t rpdo1[8] = {0x0F, 0x27, 0x01, 0x00, 0, 0, 0, 0}; /* job 9999, start 1, door 0 */
    static const uint8_t rpdo1_bad[8] = {0x2A, 0x00, 0x02, 0x01, 0, 0, 0, 0}; /* job 42, start 2 (refused), door 1 */
    static const uint8_t rpdo2[7] = {0xFB, 0xFF, 0xFF, 0xFF, 0x18, 0xFC, 0x9C}; /* -5, -1000 (-1 m/s), -100 */
    urrt_co *node = co_run_node(cfg->co_run);
    struct frames f = {0};
    size_t rx_count;
    const uint32_t *rx = co_run_rx_ids(cfg->co_run, &rx_count);
    uint32_t refused;
    CHECK(rx_count == 5 && rx[0] == 0x000 && rx[1] == 0x080 && rx[2] == 0x605 && rx[3] == 0x205 && rx[4] == 0x305,
          "rx ids: NMT, SYNC, SDO, RPDO1 0x205, RPDO2 0x305 (%zu)", rx_count);
    urrt_co_start(node, 0, frames_emit, &f);
    /* PRE-OPERATIONAL: not processed. */
    urrt_co_on_frame(node, 0x205, 0, rpdo1, 8, 1000, frames_emit, &f);
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 0);
    urrt_co_on_frame(node, 0x000, 0, start, 2, 2000, frames_emit, &f);
    CHECK_EQ_INT(urrt_co_state(node), URRT_CO_OPERATIONAL);
    f.count = 0;
    CHECK_EQ_INT(urrt_co_on_frame(node, 0x205, 0, rpdo1, 8, 3000, frames_emit, &f), 0);
    CHECK_EQ_INT(f.count, 0); /* an RPDO is never answered */
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 9999);
    CHECK_EQ_INT(read_u(node, 0x2200, 2), 1);
    CHECK_EQ_INT(read_u(node, 0x2200, 3), 0);
    CHECK_EQ_INT(co_run_input_raw(cfg->co_run, 0, 0), 9999);
    CHECK_EQ_INT(co_run_input_written_us(cfg->co_run, 0), 3000);
    urrt_co_on_frame(node, 0x305, 0, rpdo2, 7, 3500, frames_emit, &f);
    CHECK_EQ_INT(read_u(node, 0x2201, 1), 0xFFFFFFFBu);
    CHECK_EQ_INT(read_u(node, 0x2201, 2), 0xFC18u);
    CHECK_EQ_INT(read_u(node, 0x2201, 3), 0x9Cu);
    /* A value past its object's range is not stored (never clamped), the others are. */
    refused = node->values_refused;
    urrt_co_on_frame(node, 0x205, 0, rpdo1_bad, 8, 4000, frames_emit, &f);
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 42);
    CHECK_EQ_INT(read_u(node, 0x2200, 2), 1);
    CHECK_EQ_INT(read_u(node, 0x2200, 3), 1);
    CHECK_EQ_INT(node->values_refused, refused + 1u);
    /* Shorter than its mapping (4 of 8 bytes): not processed, EMCY 0x8210 (byte 5: RPDO 1) once. */
    urrt_co_run(node, 5000, frames_emit, &f);
    f.count = 0;
    urrt_co_on_frame(node, 0x205, 0, rpdo1, 4, 6000, frames_emit, &f);
    CHECK(urrt_co_deadline(node) <= 6000, "a short RPDO makes the node due at once");
    urrt_co_run(node, 6000, frames_emit, &f);
    urrt_co_on_frame(node, 0x205, 0, rpdo1, 4, 7000, frames_emit, &f);
    urrt_co_run(node, 7000, frames_emit, &f);
    urrt_co_run(node, 8000, frames_emit, &f);
    CHECK(emcys(&f, 0x8210, false, 1) == 1, "EMCY 0x8210 for RPDO1, once (%u frames)", f.count);
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 42);
    CHECK(urrt_co_error_register(node) & 0x10u, "error register: communication");
    /* The right length again: processed, the error reset names 0x8210 and RPDO 1. */
    f.count = 0;
    urrt_co_on_frame(node, 0x205, 0, rpdo1, 8, 9000, frames_emit, &f);
    urrt_co_run(node, 9000, frames_emit, &f);
    CHECK(emcys(&f, 0x8210, true, 1) == 1, "EMCY reset of 0x8210 for RPDO1");
    CHECK_EQ_INT(read_u(node, 0x2200, 1), 9999);
    /* Longer than its mapping (RPDO2, 8 bytes for 7): processed, the extra byte ignored. */
    {
        uint8_t longer[8] = {0x01, 0, 0, 0, 0x02, 0, 0x03, 0xAA};
        urrt_co_on_frame(node, 0x305, 0, longer, 8, 9500, frames_emit, &f);
        CHECK(read_u(node, 0x2201, 1) == 1 && read_u(node, 0x2201, 2) == 2 && read_u(node, 0x2201, 3) == 3,
              "a longer RPDO2: processed");
    }
}

static void test_inputs_node(const char *checker)
{
    gw_config cfg;
    char *messages = NULL;
    int errors = load(&cfg, inputs_node, &messages);
    CHECK(errors == 0 && cfg.co_run != NULL, "a node with [input]s loads: %s", messages);
    free(messages);
    if (errors == 0 && cfg.co_run != NULL) {
        char *eds = NULL;
        size_t size = 0;
        FILE *out = open_memstream(&eds, &size);
        urrt_co *node = co_run_node(cfg.co_run);
        struct sink s = {0};
        unsigned vars;
        const urrt_co_desc *d = co_run_desc(cfg.co_run);
        CHECK_EQ_INT(d->rpdo_count, 2);
        CHECK_EQ_INT(d->consumer_count, 1);
        CHECK_EQ_INT(eds_write(out, cfg.co_run, &cfg.co, &cfg.can, "inputs.ini", NULL), 0);
        fclose(out);
        test_inputs_eds_text(eds);
        /* Every object the lists name read back by SDO: sizes, and the defaults right after a reset. */
        urrt_co_start(node, 0, sink_emit, &s);
        vars = check_listed(eds, node, "MandatoryObjects") + check_listed(eds, node, "OptionalObjects") +
               check_listed(eds, node, "ManufacturerObjects");
        CHECK(vars > 60, "%u objects and sub-indices read by SDO", vars);
        CHECK_EQ_INT(check_limits_by_sdo(eds, node), 6u + 2u); /* 0x22xx's six, TPDO1 and status sub 2 */
        free(eds);
        test_inputs_sdo(&cfg);
        test_inputs_rpdo(&cfg);
        if (checker != NULL) {
            run_eds_checker(&cfg, checker, "inputs.ini");
        }
    }
    gw_config_free(&cfg);
}

int main(int argc, char **argv)
{
    gw_config cfg;
    if (argc == 3 && strcmp(argv[1], "--table") == 0) {
        /* docs/canopen.md's table, from the EDS of the configuration. */
        if (gw_config_load(&cfg, argv[2], stderr) != 0 || cfg.co_run == NULL) {
            return 2;
        }
        char *eds = eds_text(&cfg);
        table_rows(eds, print_row, NULL);
        free(eds);
        gw_config_free(&cfg);
        return 0;
    }
    if (argc != 4 && argc != 5) {
        fprintf(stderr, "usage: test_canopen EXAMPLE.ini TABLES.c CANOPEN.md [EDS_CHECK.py] | "
                        "test_canopen --table EXAMPLE.ini\n");
        return 2;
    }
    test_rejections();
    test_causes_first();
    test_bus_load();
    test_rtde_node();
    test_inputs_node(argc == 5 ? argv[4] : NULL);
    CHECK(gw_config_load(&cfg, argv[1], stderr) == 0 && cfg.co_run != NULL, "%s loads, with its node", argv[1]);
    if (cfg.co_run != NULL) {
        test_description(&cfg);
        test_eds(&cfg);
        test_eds_file_info(&cfg);
        test_status_event_timer_zero(&cfg);
        test_dbc(&cfg);
        test_doc_table(&cfg, argv[3]);
        if (argc == 5) {
            run_eds_checker(&cfg, argv[4], "canopen.ini");
        }
    }
    gw_config_free(&cfg);
    test_c_tables(argv[2]);
    return check_report();
}
