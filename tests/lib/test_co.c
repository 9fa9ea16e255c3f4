/* SPDX-License-Identifier: MIT */
/*
 * check-co: lib/urrt_co.h, the CANopen node, on a fake clock. Every expected
 * frame is written out byte by byte from CiA 301 (COB-IDs, command bytes,
 * abort codes, heartbeat states), never computed by the code under test.
 *
 * The node is tests/lib/co_fixture.h's. The same file runs on the host and,
 * without a C library, on the emulated Cortex-M4 and M0 (check-lib-m4:
 * tests/check.h prints through tests/target/target_check.h there); check-lib-be
 * runs it on big-endian Linux CPUs.
 */
#include "co_fixture.h"

#include <stdint.h>

#include "check.h"
#include "testutil.h"
#ifndef URRT_TARGET_CORTEX_M
#include <string.h> /* the images' memcmp and memcpy: tests/target/target_check.h */
#endif

static urrt_co_desc desc;

static urrt_cantx tx;
static urrt_cantx_frame_state frame_states[2];
static urrt_cantx_robot robots[1];
static double values[8];
static urrt_co co;
static urrt_co_tpdo_state tpdo_states[2];
static uint32_t vars[2];

/* Frames kept of the latest call (no call sends more than 2 + 1 + URRT_CO_CONDITIONS + 2);
 * out_count counts them all. Small: the Cortex-M0 has 16 KB of RAM. */
#define MAX_OUT 16
static urrt_can_frame out[MAX_OUT];
static size_t out_count;
static uint32_t rx_changes_at_emit; /* co.rx_changes as the latest frame went out */

static void capture(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)ctx;
    (void)now_us;
    rx_changes_at_emit = co.rx_changes;
    if (out_count < MAX_OUT) {
        out[out_count] = *f;
    }
    out_count++;
}

static void desc_defaults(void)
{
    co_fixture_desc(&desc);
}

/* CHECK_EQ_INT evaluates its arguments twice: these calls send frames. */
static void eq_at(int line, long long got, long long want)
{
    CHECK(got == want, "line %d: %lld != %lld", line, got, want);
}
#define EQ(got, want) eq_at(__LINE__, (long long)(got), (long long)(want))

/* A fresh node, started at time 0 (its boot-up captured). */
static void setup(void)
{
    size_t bad = 0;
    memset(frame_states, 0, sizeof frame_states);
    EQ(urrt_cantx_init(&tx, &tables, frame_states, robots, values, 8, NULL, NULL), 0);
    EQ(urrt_co_init(&co, &desc, &tx, tpdo_states, vars, 2, &bad), 0);
    EQ(urrt_co_state(&co), URRT_CO_INITIALISING);
    out_count = 0;
    EQ(urrt_co_start(&co, 0, capture, NULL), 1);
}

static size_t rx(uint32_t id, const uint8_t *data, size_t len, uint64_t now_us)
{
    out_count = 0;
    return urrt_co_on_frame(&co, id, 0, data, len, now_us, capture, NULL);
}

static size_t run(uint64_t now_us)
{
    out_count = 0;
    return urrt_co_run(&co, now_us, capture, NULL);
}

static void nmt(uint8_t cs, uint8_t node, uint64_t now_us)
{
    const uint8_t d[2] = {cs, node};
    rx(0x000, d, 2, now_us);
}

static void packet(uint64_t data_us, double q0, double mode)
{
    static urrt_state st; /* static: 1456 bytes, most of the Cortex-M0's 2 KB stack */
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    st.q_actual[0] = q0;
    st.robot_mode[0] = mode;
    st.present = (UINT64_C(1) << URRT_F_Q_ACTUAL) | (UINT64_C(1) << URRT_F_ROBOT_MODE);
    urrt_cantx_on_packet(&tx, 0, &st, data_us);
}

static size_t count_id(uint32_t id)
{
    size_t n = 0;
    size_t i;
    for (i = 0; i < out_count && i < MAX_OUT; i++) {
        n += out[i].id == id;
    }
    return n;
}

/* Up to 8 bytes as "0A 1B ", for messages (no snprintf without a C library). */
static void hex_bytes(char text[3 * 8 + 1], const uint8_t *bytes, unsigned len)
{
    static const char digits[] = "0123456789ABCDEF";
    unsigned k;
    for (k = 0; k < len && k < 8u; k++) {
        text[3 * k] = digits[bytes[k] >> 4];
        text[3 * k + 1] = digits[bytes[k] & 15u];
        text[3 * k + 2] = ' ';
    }
    text[3 * k] = '\0';
}

/* Frame i of the latest call: id, length and bytes. */
static void expect_at(int line, size_t i, uint32_t id, const uint8_t *bytes, unsigned len)
{
    char got[3 * 8 + 1];
    char want[3 * 8 + 1];
    if (i >= out_count || i >= MAX_OUT) {
        CHECK(i < out_count && i < MAX_OUT, "line %d: frame %zu missing (%zu sent, %d kept)", line, i, out_count,
              MAX_OUT);
        return;
    }
    hex_bytes(got, out[i].data, out[i].len);
    hex_bytes(want, bytes, len);
    CHECK(out[i].id == id && out[i].len == len && !out[i].extended && memcmp(out[i].data, bytes, len) == 0,
          "line %d: frame %zu: got 0x%03X [%s], want 0x%03X [%s]", line, i, (unsigned)out[i].id, got, (unsigned)id,
          want);
}
#define EXPECT(i, id, ...)                                                         \
    do {                                                                           \
        static const uint8_t want_[] = {__VA_ARGS__};                              \
        expect_at(__LINE__, (i), (id), want_, (unsigned)sizeof want_);             \
    } while (0)
#define EXPECT_NONE(what) CHECK(out_count == 0, "%s: %zu frames sent", (what), out_count)

/* An SDO request of 8 bytes: exactly one answer expected. */
#define SDO(t, ...)                                                             \
    do {                                                                        \
        static const uint8_t req_[8] = {__VA_ARGS__};                           \
        EQ(rx(0x600 + NODE, req_, 8, (t)), 1);                        \
    } while (0)
#define ANSWER(...) EXPECT(0, 0x580 + NODE, __VA_ARGS__)

/* ---- init ------------------------------------------------------------------------ */

static void expect_init(int want, size_t want_item, const char *what)
{
    size_t bad = 0;
    int rc = urrt_co_init(&co, &desc, &tx, tpdo_states, vars, 2, &bad);
    CHECK(rc == want && bad == want_item, "%s: got %d at %zu, want %d at %zu", what, rc, bad, want, want_item);
    CHECK(urrt_co_strerror(rc)[0] != '\0', "a text for %d", rc);
}

static void test_init(void)
{
    static urrt_co_tpdo bad_tpdos[2];
    static urrt_co_object bad_objects[4];
    static const uint32_t long_map[1] = {0x20000140}; /* 64 bits in 5 bytes */
    desc_defaults();
    memset(frame_states, 0, sizeof frame_states);
    EQ(urrt_cantx_init(&tx, &tables, frame_states, robots, values, 8, NULL, NULL), 0);
    expect_init(0, SIZE_MAX, "the test's description");
    desc.node_id = 0;
    expect_init(URRT_CO_E_NODE_ID, SIZE_MAX, "node id 0");
    desc.node_id = 128;
    expect_init(URRT_CO_E_NODE_ID, SIZE_MAX, "node id 128");
    desc_defaults();
    memcpy(bad_tpdos, tpdos, sizeof tpdos);
    desc.tpdos = bad_tpdos;
    bad_tpdos[1].frame = 0;
    expect_init(URRT_CO_E_TPDO, 1, "two TPDOs on one frame");
    bad_tpdos[1].frame = 1;
    bad_tpdos[1].transmission_type = 0;
    expect_init(URRT_CO_E_TPDO, 1, "transmission type 0");
    bad_tpdos[1].transmission_type = 241;
    expect_init(URRT_CO_E_TPDO, 1, "transmission type 241");
    bad_tpdos[1].transmission_type = 254;
    bad_tpdos[1].cob_id = 0x601;
    expect_init(URRT_CO_E_TPDO, 1, "a restricted COB-ID (SDO)");
    bad_tpdos[1].cob_id = URRT_CO_COB_DEFAULT;
    bad_tpdos[0].mapping = long_map;
    bad_tpdos[0].mapping_count = 1;
    expect_init(URRT_CO_E_TPDO, 0, "a mapping longer than the frame");
    desc_defaults();
    memcpy(bad_objects, objects, sizeof objects);
    desc.objects = bad_objects;
    bad_objects[1].sub = 1;
    expect_init(URRT_CO_E_OBJECT, 1, "(index, sub) twice");
    bad_objects[1].sub = 2;
    bad_objects[1].index = 0x1FFF;
    expect_init(URRT_CO_E_OBJECT, 1, "index below 0x2000");
    bad_objects[1].index = 0x2000;
    bad_objects[1].type = URRT_CO_INTEGER8;
    bad_objects[0].type = URRT_CO_INTEGER8;
    expect_init(URRT_CO_E_OBJECT, 0, "a 16-bit signal in an INTEGER8");
    bad_objects[0].type = URRT_CO_INTEGER16;
    bad_objects[2].def = 5;
    expect_init(URRT_CO_E_OBJECT, 2, "default below the range");
    bad_objects[2].def = 100;
    bad_objects[3].item = 2;
    expect_init(URRT_CO_E_OBJECT, 3, "var slot past vars[]");
    desc_defaults();
    EQ(urrt_co_init(&co, &desc, NULL, tpdo_states, vars, 2, NULL), URRT_CO_E_STORAGE);
    EQ(urrt_co_on_frame(&co, 0, 0, (const uint8_t *)"\x01\x00", 2, 0, capture, NULL), 0);
    EQ(urrt_co_deadline(&co), URRT_CANTX_NEVER);
}

/* ---- NMT ------------------------------------------------------------------------- */

static void test_nmt(void)
{
    desc_defaults();
    setup();
    EXPECT(0, 0x70A, 0x00);
    EQ(urrt_co_state(&co), URRT_CO_PRE_OPERATIONAL);
    nmt(0x01, NODE, 1000);
    EQ(out_count, 1);
    EXPECT(0, 0x70A, 0x05); /* a new state: its heartbeat at once */
    nmt(0x01, NODE, 1500);
    EXPECT_NONE("start while operational: no change, no heartbeat");
    EQ(urrt_co_state(&co), URRT_CO_OPERATIONAL);
    nmt(0x80, NODE, 2000);
    EQ(urrt_co_state(&co), URRT_CO_PRE_OPERATIONAL);
    nmt(0x01, 0x0B, 3000);
    EQ(urrt_co_state(&co), URRT_CO_PRE_OPERATIONAL); /* node 11's command */
    nmt(0x02, 0x00, 4000);
    EQ(urrt_co_state(&co), URRT_CO_STOPPED); /* broadcast */
    nmt(0x80, 0x00, 5000);
    EQ(urrt_co_state(&co), URRT_CO_PRE_OPERATIONAL);
    nmt(0x01, 0x00, 6000);
    EQ(urrt_co_state(&co), URRT_CO_OPERATIONAL);
    nmt(0x02, NODE, 7000);
    EQ(urrt_co_state(&co), URRT_CO_STOPPED);
    nmt(0x01, NODE, 8000);
    EQ(urrt_co_state(&co), URRT_CO_OPERATIONAL); /* stopped -> operational */
    nmt(0x03, NODE, 8500);
    EQ(urrt_co_state(&co), URRT_CO_OPERATIONAL); /* unknown command */
    {
        const uint8_t three[3] = {0x02, NODE, 0};
        rx(0x000, three, 3, 8600);
        EQ(urrt_co_state(&co), URRT_CO_OPERATIONAL); /* NMT is 2 bytes */
    }

    nmt(0x81, NODE, 9000);
    EQ(out_count, 1);
    EXPECT(0, 0x70A, 0x00); /* boot-up after reset node */
    EQ(urrt_co_state(&co), URRT_CO_PRE_OPERATIONAL);
    nmt(0x01, NODE, 9500);
    nmt(0x82, 0x00, 10000);
    EQ(out_count, 1);
    EXPECT(0, 0x70A, 0x00); /* boot-up after reset communication */
    EQ(urrt_co_state(&co), URRT_CO_PRE_OPERATIONAL);
    nmt(0x81, 0x0B, 11000);
    EXPECT_NONE("reset of node 11");

    /* Stopped: no SDO answer, only heartbeats. */
    nmt(0x02, NODE, 12000);
    {
        const uint8_t req[8] = {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0};
        EQ(rx(0x60A, req, 8, 12000), 0);
    }
    EQ(run(111999), 0); /* the cadence restarted at the change to STOPPED */
    EQ(run(112000), 1);
    EXPECT(0, 0x70A, 0x04);

    /* Self-starting: operational right after the boot-up. */
    desc.nmt_start = URRT_CO_START_OPERATIONAL;
    setup();
    EXPECT(0, 0x70A, 0x00);
    EQ(urrt_co_state(&co), URRT_CO_OPERATIONAL);
    CHECK_EQ_STR(urrt_co_state_name(urrt_co_state(&co)), "OPERATIONAL");
}

/* ---- heartbeat -------------------------------------------------------------------- */

static void test_heartbeat(void)
{
    desc_defaults();
    setup();
    EQ(urrt_co_deadline(&co), 0); /* urrt_cantx: TPDO1 due (closed) at start */
    run(0);
    EQ(urrt_co_deadline(&co), 10000);
    EQ(run(99999), 0);
    EQ(run(100000), 1);
    EXPECT(0, 0x70A, 0x7F);
    nmt(0x01, NODE, 150000);
    EQ(out_count, 1);
    EXPECT(0, 0x70A, 0x05); /* at once, then every 100 ms from here */
    EQ(run(200000), 1);     /* TPDO1 (no data: invalid) */
    EQ(out[0].id, 0x18A);
    EQ(run(249999), 1); /* TPDO1 again (its missed slots skipped), next due at 259999 */
    EQ(run(250000), 1);
    EXPECT(0, 0x70A, 0x05);
    /* Off by SDO: 0x1017 = 0. */
    SDO(250000, 0x2B, 0x17, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x17, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    nmt(0x80, NODE, 250000);
    EXPECT_NONE("heartbeat off: no heartbeat on a state change");
    EQ(run(300000), 0);
    EQ(run(400000), 0);
    /* On again: 250 ms from the write. */
    SDO(500000, 0x2B, 0x17, 0x10, 0x00, 0xFA, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x17, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(500000, 0x40, 0x17, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    ANSWER(0x4B, 0x17, 0x10, 0x00, 0xFA, 0x00, 0x00, 0x00);
    EQ(run(749999), 0);
    EQ(run(750000), 1);
    EXPECT(0, 0x70A, 0x7F);
    EQ(run(990000), 0);
    EQ(run(1000000), 2); /* the heartbeat, and EMCY: no robot after the startup time */
    EXPECT(0, 0x70A, 0x7F);
}

/* ---- SDO --------------------------------------------------------------------------- */

static void test_sdo_upload(void)
{
    desc_defaults();
    setup();
    SDO(1000, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x10, 0x00, 0x78, 0x56, 0x34, 0x12);
    SDO(1000, 0x40, 0x01, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x01, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x03, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x03, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x43, 0x05, 0x10, 0x00, 0x80, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x14, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x43, 0x14, 0x10, 0x00, 0x8A, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x15, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x15, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x17, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x17, 0x10, 0x00, 0x64, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x09, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x47, 0x09, 0x10, 0x00, '1', '.', '0', 0x00); /* 3 bytes: expedited */
    SDO(1000, 0x40, 0x18, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x18, 0x10, 0x00, 0x04, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x18, 0x10, 0x01, 0x04, 0x03, 0x02, 0x01);
    SDO(1000, 0x40, 0x18, 0x10, 0x02, 0, 0, 0, 0);
    ANSWER(0x43, 0x18, 0x10, 0x02, 0xCD, 0xAB, 0x00, 0x00);
    SDO(1000, 0x40, 0x18, 0x10, 0x03, 0, 0, 0, 0);
    ANSWER(0x43, 0x18, 0x10, 0x03, 0x02, 0x00, 0x01, 0x00);
    SDO(1000, 0x40, 0x18, 0x10, 0x04, 0, 0, 0, 0);
    ANSWER(0x43, 0x18, 0x10, 0x04, 0x42, 0x00, 0x00, 0x00);
    /* TPDO parameters and mapping. */
    SDO(1000, 0x40, 0x00, 0x18, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x18, 0x00, 0x05, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x18, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x18, 0x01, 0x8A, 0x01, 0x00, 0x40); /* bit 30: no RTR */
    SDO(1000, 0x40, 0x01, 0x18, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x01, 0x18, 0x01, 0x8A, 0x02, 0x00, 0x40);
    SDO(1000, 0x40, 0x00, 0x18, 0x02, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x18, 0x02, 0xFE, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x18, 0x03, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x18, 0x03, 0x00, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x18, 0x05, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x18, 0x05, 0x0A, 0x00, 0x00, 0x00); /* the frame's 10 ms */
    SDO(1000, 0x40, 0x00, 0x1A, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x1A, 0x00, 0x04, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x1A, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x1A, 0x01, 0x10, 0x01, 0x00, 0x20);
    /* Manufacturer objects: a record's count, a robot value as it goes out. */
    packet(2000, -1.5, 7);
    SDO(2000, 0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x20, 0x00, 0x02, 0x00, 0x00, 0x00);
    SDO(2000, 0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x20, 0x01, 0x24, 0xFA, 0x00, 0x00); /* -1500 */
    SDO(2000, 0x40, 0x00, 0x20, 0x02, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x20, 0x02, 0x07, 0x00, 0x00, 0x00);
    SDO(2000, 0x40, 0x00, 0x21, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x21, 0x00, 0x64, 0x00, 0x00, 0x00);
}

static void test_sdo_segmented(void)
{
    desc_defaults();
    setup();
    SDO(1000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x41, 0x08, 0x10, 0x00, 0x14, 0x00, 0x00, 0x00); /* 20 bytes */
    SDO(2000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x00, 'u', 'r', 'r', 't', ' ', 'C', 'A');
    SDO(3000, 0x70, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x10, 'N', 'o', 'p', 'e', 'n', ' ', 'g');
    SDO(4000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x03, 'a', 't', 'e', 'w', 'a', 'y', 0x00); /* 6 bytes (n = 1), last */
    SDO(5000, 0x70, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x80, 0x00, 0x00, 0x00, 0x01, 0x00, 0x04, 0x05); /* no transfer: command unknown */
    /* 0x100A, 5 bytes: one segment. */
    SDO(6000, 0x40, 0x0A, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x41, 0x0A, 0x10, 0x00, 0x05, 0x00, 0x00, 0x00);
    SDO(7000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x05, '0', '.', '9', '.', '0', 0x00, 0x00);
    /* An empty string is segmented too: size 0, one empty last segment. */
    desc.device_name = NULL;
    SDO(8000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x41, 0x08, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(9000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x0F, 0, 0, 0, 0, 0, 0, 0);
}

#define ABORT(t, code, ...)                                                                     \
    do {                                                                                         \
        static const uint8_t areq_[8] = {__VA_ARGS__};                                           \
        EQ(rx(0x600 + NODE, areq_, 8, (t)), 1);                                        \
        EXPECT(0, 0x580 + NODE, 0x80, areq_[1], areq_[2], areq_[3], (code) & 0xFF, (code) >> 8 & 0xFF, \
               (code) >> 16 & 0xFF, (code) >> 24 & 0xFF);                                        \
    } while (0)

/* Requests the node refuses, each answered with its abort code. */
static void sdo_refused_requests(void)
{
    ABORT(0, 0x06090030, 0x23, 0x14, 0x10, 0x00, 0x8B, 0, 0, 0); /* EMCY id while valid */
    SDO(0, 0x23, 0x14, 0x10, 0x00, 0x8A, 0x00, 0x00, 0x80);        /* no EMCY: SDO answers only */
    ABORT(1000, 0x06020000, 0x40, 0x34, 0x12, 0x00, 0, 0, 0, 0);  /* no object 0x1234 */
    ABORT(1000, 0x06020000, 0x40, 0x02, 0x18, 0x00, 0, 0, 0, 0);  /* no TPDO3 */
    ABORT(1000, 0x06020000, 0x40, 0x00, 0x22, 0x00, 0, 0, 0, 0);  /* no 0x2200 */
    ABORT(1000, 0x06090011, 0x40, 0x18, 0x10, 0x05, 0, 0, 0, 0);  /* 0x1018 sub 5 */
    ABORT(1000, 0x06090011, 0x40, 0x00, 0x18, 0x04, 0, 0, 0, 0);  /* 0x1800 sub 4 is reserved */
    ABORT(1000, 0x06090011, 0x40, 0x00, 0x1A, 0x05, 0, 0, 0, 0);  /* past the mapping */
    ABORT(1000, 0x06090011, 0x40, 0x00, 0x10, 0x01, 0, 0, 0, 0);  /* a VAR has sub 0 only */
    ABORT(1000, 0x06090011, 0x40, 0x03, 0x10, 0x09, 0, 0, 0, 0);  /* 0x1003 holds 8 */
    ABORT(1000, 0x08000024, 0x40, 0x03, 0x10, 0x01, 0, 0, 0, 0);  /* 0x1003: no error recorded */
    ABORT(1000, 0x06010002, 0x23, 0x00, 0x10, 0x00, 1, 2, 3, 4);  /* 0x1000 read-only */
    ABORT(1000, 0x06010002, 0x23, 0x00, 0x1A, 0x01, 1, 2, 3, 4);  /* mapping static */
    ABORT(1000, 0x06010002, 0x2B, 0x00, 0x20, 0x01, 1, 2, 0, 0);  /* a robot value */
    ABORT(1000, 0x06010001, 0x40, 0x01, 0x21, 0x00, 0, 0, 0, 0);  /* write-only */
    ABORT(1000, 0x06070012, 0x23, 0x17, 0x10, 0x00, 1, 0, 0, 0);  /* 4 bytes into UNSIGNED16 */
    ABORT(1000, 0x06070013, 0x2B, 0x14, 0x10, 0x00, 0x8A, 0, 0, 0); /* 2 bytes into UNSIGNED32 */
    ABORT(1000, 0x06070013, 0x2F, 0x00, 0x21, 0x00, 0x64, 0, 0, 0); /* 1 byte into UNSIGNED16 */
    ABORT(1000, 0x06090030, 0x23, 0x00, 0x18, 0x01, 0x8B, 0x01, 0, 0); /* new id while valid */
    ABORT(1000, 0x06090030, 0x2B, 0x00, 0x18, 0x03, 0x0A, 0x00, 0, 0); /* inhibit while valid */
    ABORT(1000, 0x06090030, 0x2F, 0x03, 0x10, 0x00, 0x01, 0, 0, 0);    /* 0x1003 takes only 0 */
    ABORT(1000, 0x06090030, 0x23, 0x05, 0x10, 0x00, 0x80, 0, 0, 0x40); /* SYNC producer */
    ABORT(1000, 0x06090031, 0x2B, 0x00, 0x21, 0x00, 0xE9, 0x03, 0, 0); /* 1001 > 1000 */
    ABORT(1000, 0x06090032, 0x2B, 0x00, 0x21, 0x00, 0x09, 0x00, 0, 0); /* 9 < 10 */
    ABORT(1000, 0x06090031, 0x2F, 0x00, 0x18, 0x02, 0xFC, 0, 0, 0);    /* type 252: RTR only */
    ABORT(1000, 0x06090032, 0x2F, 0x00, 0x18, 0x02, 0x00, 0, 0, 0);    /* type 0 */
    ABORT(1000, 0x05040001, 0xA0, 0x00, 0x10, 0x00, 0, 0, 0, 0);       /* block upload */
    ABORT(1000, 0x05040001, 0xC0, 0x00, 0x10, 0x00, 0, 0, 0, 0);       /* block download */
    ABORT(1000, 0x05040001, 0x21, 0x00, 0x21, 0x00, 2, 0, 0, 0);       /* segmented download */
    ABORT(1000, 0x05040001, 0xE0, 0x00, 0x10, 0x00, 0, 0, 0, 0);       /* cs 7 */
    /* The values behind the refused writes did not change. */
    SDO(1000, 0x40, 0x00, 0x21, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x21, 0x00, 0x64, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x18, 0x02, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x18, 0x02, 0xFE, 0x00, 0x00, 0x00);
}

/* Short frames: 0x06070010, with what index they carry. */
static void sdo_short_frames(void)
{
    const uint8_t seven[7] = {0x40, 0x00, 0x10, 0x00, 0, 0, 0};
    EQ(rx(0x60A, seven, 7, 1000), 1);
    EXPECT(0, 0x58A, 0x80, 0x00, 0x10, 0x00, 0x10, 0x00, 0x07, 0x06);
    EQ(rx(0x60A, NULL, 0, 1000), 1);
    EXPECT(0, 0x58A, 0x80, 0x00, 0x00, 0x00, 0x10, 0x00, 0x07, 0x06);
}

/* Toggle error: the first segment request must have toggle 0. */
static void sdo_toggle_errors(void)
{
    SDO(2000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    ABORT(2000, 0x05030000, 0x70, 0x08, 0x10, 0x00, 0, 0, 0, 0); /* bytes 1-3: the transfer's, as written */
    /* ... and twice the same toggle. */
    SDO(2000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    SDO(2000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    SDO(2000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x03, 0x05);
}

/* Timeout: the client leaves; 1 s after the last exchange the node aborts. */
static void sdo_timeout(void)
{
    SDO(10000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    SDO(20000, 0x60, 0, 0, 0, 0, 0, 0, 0);
    EQ(urrt_co_deadline(&co) <= 1020000, 1);
    EQ(run(1019999), 0);
    EQ(run(1020000), 1);
    ANSWER(0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05);
    SDO(1030000, 0x70, 0, 0, 0, 0, 0, 0, 0);
    ANSWER(0x80, 0x00, 0x00, 0x00, 0x01, 0x00, 0x04, 0x05); /* the transfer is over */
}

/* A new request in the middle: the old transfer is aborted, the request
 * not served; the client's retry is. */
static void sdo_interrupted_transfers(void)
{
    SDO(2000000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    SDO(2000000, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x80, 0x08, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05);
    SDO(2000000, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x10, 0x00, 0x78, 0x56, 0x34, 0x12);
    /* The client's abort ends the transfer, unanswered. */
    SDO(3000000, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    {
        const uint8_t client_abort[8] = {0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05};
        EQ(rx(0x60A, client_abort, 8, 3000000), 0);
    }
    run(5000000);
    EQ(count_id(0x58A), 0); /* no timeout abort */
}

/* Every abort of the server, on one node: each step continues from the state the one
 * before left. */
static void test_sdo_aborts(void)
{
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    sdo_refused_requests();
    sdo_short_frames();
    sdo_toggle_errors();
    sdo_timeout();
    sdo_interrupted_transfers();
}

static void test_sdo_download(void)
{
    desc_defaults();
    setup();
    SDO(1000, 0x2B, 0x00, 0x21, 0x00, 0xF4, 0x01, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x21, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x21, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x21, 0x00, 0xF4, 0x01, 0x00, 0x00);
    SDO(1000, 0x22, 0x00, 0x21, 0x00, 0x0A, 0x00, 0xFF, 0xFF); /* size not indicated: the object's */
    ANSWER(0x60, 0x00, 0x21, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(1000, 0x40, 0x00, 0x21, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x21, 0x00, 0x0A, 0x00, 0x00, 0x00);
    SDO(1000, 0x2F, 0x01, 0x21, 0x00, 0x01, 0, 0, 0);
    ANSWER(0x60, 0x01, 0x21, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(vars[1], 1);
    /* Reset node: variables back to their defaults; reset communication keeps them. */
    nmt(0x82, NODE, 2000);
    EQ(vars[0], 10);
    nmt(0x81, NODE, 3000);
    EQ(vars[0], 100);
    EQ(vars[1], 0);
}

/* ---- TPDOs -------------------------------------------------------------------------- */

static void test_tpdo_gating(void)
{
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    packet(1000, 1.5, 7);
    EQ(run(1000), 0); /* pre-operational: no PDO */
    EQ(run(10000), 0);
    nmt(0x01, NODE, 15000);
    packet(15000, 1.5, 7);
    EQ(run(15000), 1);
    EXPECT(0, 0x28A, 0xDC, 0x05); /* TPDO2 with the packet */
    EQ(run(20000), 1);
    EXPECT(0, 0x18A, 0xDC, 0x05, 0x07, 0x00, 0x01); /* TPDO1 on its 10 ms cadence: alive 0, valid */
    EQ(run(30000), 1);
    EXPECT(0, 0x18A, 0xDC, 0x05, 0x07, 0x01, 0x01);
    /* COB-ID: invalid, then a new id, then valid again. */
    SDO(31000, 0x23, 0x00, 0x18, 0x01, 0x8A, 0x01, 0x00, 0x80);
    ANSWER(0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0);
    EQ(run(40000), 0);
    SDO(41000, 0x23, 0x00, 0x18, 0x01, 0x9A, 0x01, 0x00, 0x80);
    ANSWER(0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0);
    SDO(41000, 0x2B, 0x00, 0x18, 0x03, 0x64, 0x00, 0, 0); /* inhibit 10 ms while invalid */
    ANSWER(0x60, 0x00, 0x18, 0x03, 0, 0, 0, 0);
    SDO(41000, 0x2B, 0x00, 0x18, 0x05, 0x14, 0x00, 0, 0); /* event timer 20 ms */
    ANSWER(0x60, 0x00, 0x18, 0x05, 0, 0, 0, 0);
    SDO(41000, 0x23, 0x00, 0x18, 0x01, 0x9A, 0x01, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0);
    packet(41000, 1.5, 7);
    EQ(run(41000), 2);
    EQ(count_id(0x19A), 1); /* at the new id, due at once after the change */
    EQ(count_id(0x18A), 0);
    EQ(run(51000), 0);
    packet(60000, 1.5, 7);
    EQ(run(61000), 2); /* 20 ms later, with TPDO2's packet */
    EQ(count_id(0x19A), 1);
    /* A valid id may not be taken twice. */
    SDO(62000, 0x23, 0x01, 0x18, 0x01, 0x8A, 0x02, 0x00, 0x80);
    SDO(62000, 0x23, 0x01, 0x18, 0x01, 0x9A, 0x01, 0x00, 0x80);
    ABORT(62000, 0x06090030, 0x23, 0x01, 0x18, 0x01, 0x9A, 0x01, 0x00, 0x00);
    /* Stopped and pre-operational: nothing. */
    nmt(0x02, NODE, 70000);
    packet(70000, 1.5, 7);
    EQ(run(70000), 0);
    EQ(run(81000), 0);
    nmt(0x80, NODE, 90000);
    EQ(run(101000), 0);
}

static void test_sync(void)
{
    const uint8_t counter[1] = {1};
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    SDO(1000, 0x2F, 0x01, 0x18, 0x02, 0x02, 0, 0, 0); /* TPDO2 on every 2nd SYNC */
    ANSWER(0x60, 0x01, 0x18, 0x02, 0, 0, 0, 0);
    packet(2000, 0.25, 7);
    EQ(rx(0x080, NULL, 0, 2000), 0); /* pre-operational */
    EQ(rx(0x080, NULL, 0, 2000), 0);
    nmt(0x01, NODE, 3000);
    run(3000);
    EQ(count_id(0x28A), 0); /* TPDO2 no longer follows the packets */
    EQ(rx(0x080, NULL, 0, 4000), 0);
    EQ(rx(0x080, counter, 1, 5000), 1); /* with the optional counter byte */
    EXPECT(0, 0x28A, 0xFA, 0x00);
    EQ(rx(0x080, NULL, 0, 6000), 0);
    EQ(rx(0x080, NULL, 0, 7000), 1);
    EQ(rx(0x080, NULL, 0, 100000), 0);
    EQ(rx(0x080, NULL, 0, 100000), 0); /* stale data: the stop policy holds */
    {
        const uint8_t two[2] = {1, 2};
        packet(200000, 0.25, 7);
        EQ(rx(0x080, two, 2, 200000), 0); /* not a SYNC: 2 bytes */
    }
    /* The SYNC id moves with 0x1005. */
    SDO(200000, 0x23, 0x05, 0x10, 0x00, 0x81, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    EQ(rx(0x080, NULL, 0, 200000), 0);
    EQ(rx(0x081, NULL, 0, 200000), 0);
    EQ(rx(0x081, NULL, 0, 200000), 1);
    /* Invalid PDO: counted, not sent. */
    SDO(200000, 0x23, 0x01, 0x18, 0x01, 0x8A, 0x02, 0x00, 0x80);
    EQ(rx(0x081, NULL, 0, 200000), 0);
    EQ(rx(0x081, NULL, 0, 200000), 0);
}

/* ---- the ids the node receives: 0x1005 moves the SYNC one ------------------------------ */

/* urrt_co_rx_ids: NMT 0x000, SYNC, the SDO request 0x60A; and the change count. */
static void expect_rx_ids(int line, uint32_t sync_id, uint32_t changes)
{
    uint32_t ids[URRT_CO_RX_IDS_MAX] = {0xFFFF, 0xFFFF, 0xFFFF};
    size_t n = urrt_co_rx_ids(&co, ids);
    CHECK(n == 3u && ids[0] == 0x000u && ids[1] == sync_id && ids[2] == 0x60Au && co.rx_changes == changes,
          "line %d: %zu ids 0x%03X 0x%03X 0x%03X after %u changes, want 0x000 0x%03X 0x60A after %u", line, n,
          (unsigned)ids[0], (unsigned)ids[1], (unsigned)ids[2], (unsigned)co.rx_changes, (unsigned)sync_id,
          (unsigned)changes);
}
#define RX_IDS(sync_id, changes) expect_rx_ids(__LINE__, (sync_id), (changes))

/* A manager moves the SYNC to 0x081 (0x1005 = 0x81, CiA 301's expedited
 * 4-byte download 0x23): the set the caller filters on changes once, before
 * the answer goes out; a SYNC on 0x081 runs the synchronous TPDO, one on
 * 0x080 no longer does.
 * Refused writes (producer bit 30, bit 29, a restricted id, a wrong size:
 * checked in the order exists, access, size, value) leave the set; bit 31
 * ("do not care") neither moves it nor stops the SYNCs; a reset brings
 * 0x080 back, a second change. */
static void test_rx_ids(void)
{
    size_t bad = 0;
    desc_defaults();
    desc.heartbeat_ms = 0;
    memset(frame_states, 0, sizeof frame_states);
    EQ(urrt_cantx_init(&tx, &tables, frame_states, robots, values, 8, NULL, NULL), 0);
    EQ(urrt_co_init(&co, &desc, &tx, tpdo_states, vars, 2, &bad), 0);
    RX_IDS(0x080, 0); /* before the boot-up: a filter is set before the node speaks */
    EQ(urrt_co_start(&co, 0, capture, NULL), 1);
    RX_IDS(0x080, 0);
    EQ(urrt_co_rx_ids(NULL, NULL), 0);
    SDO(1000, 0x2F, 0x01, 0x18, 0x02, 0x01, 0, 0, 0); /* TPDO2 on every SYNC */
    ANSWER(0x60, 0x01, 0x18, 0x02, 0, 0, 0, 0);
    nmt(0x01, NODE, 1000);
    packet(2000, 0.25, 7);
    EQ(rx(0x080, NULL, 0, 2000), 1);
    EXPECT(0, 0x28A, 0xFA, 0x00);

    SDO(2000, 0x23, 0x05, 0x10, 0x00, 0x81, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    RX_IDS(0x081, 1);
    EQ(rx_changes_at_emit, 1); /* changed before the answer went out: a filter set in emit is in time */
    EQ(rx(0x081, NULL, 0, 3000), 1);
    EXPECT(0, 0x28A, 0xFA, 0x00);
    EQ(rx(0x080, NULL, 0, 3000), 0);
    SDO(3000, 0x40, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x43, 0x05, 0x10, 0x00, 0x81, 0x00, 0x00, 0x00);

    SDO(3000, 0x23, 0x05, 0x10, 0x00, 0x81, 0x00, 0x00, 0x80); /* bit 31: do not care */
    ANSWER(0x60, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    RX_IDS(0x081, 1);
    EQ(rx(0x081, NULL, 0, 4000), 1);
    SDO(4000, 0x23, 0x05, 0x10, 0x00, 0x81, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    RX_IDS(0x081, 1); /* the same id again: no change */

    ABORT(4000, 0x06090030, 0x23, 0x05, 0x10, 0x00, 0x82, 0x00, 0x00, 0x40); /* producer: not this node */
    ABORT(4000, 0x06090030, 0x23, 0x05, 0x10, 0x00, 0x82, 0x00, 0x00, 0x20); /* bit 29: 29-bit id */
    ABORT(4000, 0x06090030, 0x23, 0x05, 0x10, 0x00, 0x05, 0x06, 0x00, 0x00); /* 0x605: an SDO id */
    ABORT(4000, 0x06070013, 0x2B, 0x05, 0x10, 0x00, 0x82, 0x00, 0x00, 0x00); /* 2 bytes: size first */
    RX_IDS(0x081, 1);
    EQ(rx(0x081, NULL, 0, 5000), 1);

    nmt(0x82, NODE, 6000); /* reset communication: 0x1005 back to 0x080 */
    RX_IDS(0x080, 2);
    EQ(rx_changes_at_emit, 2); /* before the boot-up */
    SDO(6000, 0x40, 0x05, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x43, 0x05, 0x10, 0x00, 0x80, 0x00, 0x00, 0x00);
    nmt(0x81, NODE, 7000); /* reset node with the default id: no change */
    RX_IDS(0x080, 2);
}

/* ---- TPDO timing: inhibit time and event timer, in frames per interval ------------------- */

/* The node from t0 for span_us as a loop would run it: woken at every
 * deadline, and a robot packet (q0 rising by 0.001 rad each) every
 * packet_us (0: none). Returns the frames sent on `id`; *last_q0 (if not
 * NULL) the raw q0 of the latest such frame. */
static size_t frames_in(uint32_t id, uint64_t t0, uint64_t span_us, uint64_t packet_us, int *last_q0)
{
    uint64_t next_packet = t0;
    uint64_t t = t0;
    size_t sent = 0;
    unsigned wakes;
    double q0 = 0.0;
    for (wakes = 0; wakes < 10000u; wakes++) {
        uint64_t due = urrt_co_deadline(&co);
        due = due < t ? t : due;
        if (packet_us != 0u && next_packet <= due) {
            t = next_packet;
            q0 += 0.001;
            next_packet += packet_us;
            if (t < t0 + span_us) {
                packet(t, q0, 7);
            }
        } else {
            t = due;
        }
        if (t >= t0 + span_us) {
            break;
        }
        run(t);
        sent += count_id(id);
        if (last_q0 != NULL && count_id(id) > 0u) {
            size_t i;
            for (i = 0; i < out_count && i < MAX_OUT; i++) {
                *last_q0 = out[i].id == id ? (int16_t)(out[i].data[0] | out[i].data[1] << 8) : *last_q0;
            }
        }
    }
    CHECK(wakes < 10000u, "the node woke without end at %llu", (unsigned long long)t);
    return sent;
}

/* A node with TPDO n alone (the other's COB-ID invalid), operational, its
 * inhibit time and event timer set by SDO as a manager does it (invalid,
 * inhibit, event timer, valid again): the requests and answers of CiA 301. */
static void timing_node(unsigned n, uint8_t inhibit_100us, uint8_t event_ms)
{
    const uint8_t off = (uint8_t)(1u - n);
    const uint8_t id_high = (uint8_t)(0x01u + n);
    const uint8_t invalid[8] = {0x23, off, 0x18, 0x01, 0x8A, (uint8_t)(0x01u + off), 0x00, 0xC0};
    const uint8_t disable[8] = {0x23, (uint8_t)n, 0x18, 0x01, 0x8A, id_high, 0x00, 0xC0};
    const uint8_t inhibit[8] = {0x2B, (uint8_t)n, 0x18, 0x03, inhibit_100us, 0x00, 0x00, 0x00};
    const uint8_t event[8] = {0x2B, (uint8_t)n, 0x18, 0x05, event_ms, 0x00, 0x00, 0x00};
    const uint8_t enable[8] = {0x23, (uint8_t)n, 0x18, 0x01, 0x8A, id_high, 0x00, 0x40};
    const uint8_t *reqs[5] = {invalid, disable, inhibit, event, enable};
    unsigned k;
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    for (k = 0; k < 5u; k++) {
        const uint8_t answer[8] = {0x60, reqs[k][1], 0x18, reqs[k][3], 0, 0, 0, 0};
        EQ(rx(0x60A, reqs[k], 8, 0), 1);
        expect_at(__LINE__, 0, 0x58A, answer, 8);
    }
    nmt(0x01, NODE, 0);
}

/* The inhibit time is a least gap between two sends: it lowers a rate,
 * never raises it, and a send that falls in the gap goes at its end with
 * the newest data. TPDO2: per packet (event timer 0); TPDO1: event timer. */
static void test_inhibit_time(void)
{
    int q0 = 0;
    timing_node(1, 0, 0);
    EQ(frames_in(0x28A, 0, 80000, 8000, NULL), 10); /* a packet every 8 ms: 10 frames in 80 ms */
    timing_node(1, 20, 0);
    EQ(frames_in(0x28A, 0, 80000, 8000, NULL), 10); /* 2 ms inhibit: still 10, not 40 */
    timing_node(1, 200, 0);
    EQ(frames_in(0x28A, 0, 80000, 8000, &q0), 4); /* 20 ms inhibit: at 0, 20, 40, 60 ms */
    EQ(q0, 8);                                      /* at 60 ms: the newest packet, 56 ms's (the 8th) */
    timing_node(0, 0, 10);
    EQ(frames_in(0x18A, 0, 80000, 8000, NULL), 8); /* event timer 10 ms: 8 in 80 ms */
    timing_node(0, 20, 10);
    EQ(frames_in(0x18A, 0, 80000, 8000, NULL), 8); /* 2 ms inhibit under a 10 ms timer: no change */
    timing_node(0, 250, 10);
    EQ(frames_in(0x18A, 0, 80000, 8000, NULL), 4); /* 25 ms inhibit: at 0, 25, 50, 75 ms */
    timing_node(0, 0, 10);
    EQ(frames_in(0x18A, 0, 80000, 0, NULL), 8); /* no data: the invalid policy goes on, validity 0 */
    EQ(out[0].data[4], 0x00);
}

/* Event timer 0 means "no event timer" (CiA 301), for every TPDO and
 * every transmission type. On a frame whose stale policy needs a period
 * (TPDO1: invalid) the node then sends it with each robot packet, and
 * nothing while no packet comes: the validity bit has no slot to go out in. */
static void test_event_timer_zero(void)
{
    timing_node(0, 0, 0);
    SDO(0, 0x40, 0x00, 0x18, 0x05, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    EQ(frames_in(0x18A, 0, 80000, 8000, NULL), 10); /* with the packets, every 8 ms */
    EQ(frames_in(0x18A, 80000, 80000, 0, NULL), 0); /* none without them */
    EQ(frames_in(0x18A, 160000, 80000, 20000, NULL), 4);
    EQ(out[0].data[4], 0x01); /* fresh: valid */
    timing_node(0, 200, 0);
    EQ(frames_in(0x18A, 0, 80000, 8000, NULL), 4); /* with a 20 ms inhibit time */
    /* The requests of the report, for both TPDOs and under SYNC type 1. */
    desc_defaults();
    setup();
    SDO(0, 0x2B, 0x00, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    SDO(0, 0x2B, 0x01, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x01, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    SDO(0, 0x2F, 0x00, 0x18, 0x02, 0x01, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x18, 0x02, 0x00, 0x00, 0x00, 0x00);
    SDO(0, 0x2B, 0x00, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x18, 0x05, 0x00, 0x00, 0x00, 0x00);
    nmt(0x01, NODE, 1000);
    packet(1000, 0.5, 7);
    run(1000);
    EQ(count_id(0x18A), 0); /* type 1: not on packets */
    EQ(rx(0x080, NULL, 0, 2000), 1);
    EXPECT(0, 0x18A, 0xF4, 0x01, 0x07, 0x00, 0x01); /* on the SYNC */
}

/* A manager disables a TPDO and gives it a new COB-ID in one write
 * (python-canopen's PdoMap.save); only a new id while valid is refused. */
static void test_cob_move(void)
{
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    SDO(0, 0x23, 0x00, 0x18, 0x01, 0x90, 0x01, 0x00, 0x80);
    ANSWER(0x60, 0x00, 0x18, 0x01, 0x00, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x00, 0x18, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x18, 0x01, 0x90, 0x01, 0x00, 0x80);
    ABORT(0, 0x06090030, 0x23, 0x01, 0x18, 0x01, 0x8B, 0x02, 0x00, 0x40); /* TPDO2: new id, valid */
    SDO(0, 0x23, 0x00, 0x18, 0x01, 0x90, 0x01, 0x00, 0x40);            /* valid at the new id */
    ANSWER(0x60, 0x00, 0x18, 0x01, 0x00, 0x00, 0x00, 0x00);
    SDO(0, 0x23, 0x14, 0x10, 0x00, 0x8B, 0x00, 0x00, 0x80); /* EMCY: the same rule */
    ANSWER(0x60, 0x14, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00);
    nmt(0x01, NODE, 1000);
    EQ(run(10000), 1);
    EXPECT(0, 0x190, 0x00, 0x00, 0x00, 0x00, 0x00); /* no data yet: validity 0 */
}

/* One order of checks for every object: exists, access, size, value. */
static void test_abort_order(void)
{
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    ABORT(0, 0x06010002, 0x23, 0x03, 0x10, 0x01, 0, 0, 0, 0); /* 0x1003 sub 1, history empty */
    ABORT(0, 0x06090011, 0x23, 0x03, 0x10, 0x09, 0, 0, 0, 0); /* sub 9 does not exist */
    ABORT(0, 0x06010002, 0x2F, 0x00, 0x10, 0x00, 1, 0, 0, 0); /* read-only before size */
    ABORT(0, 0x06070012, 0x23, 0x00, 0x18, 0x02, 0, 0, 0, 0); /* size before value (type 0) */
    ABORT(0, 0x06090032, 0x2F, 0x00, 0x18, 0x02, 0, 0, 0, 0); /* then the value */
    nmt(0x01, NODE, 0);
    EQ(run(1000000), 2); /* EMCY: no robot by the end of the startup time; TPDO1 */
    SDO(1000000, 0x40, 0x03, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x03, 0x10, 0x01, 0x01, 0xFF, 0x00, 0x00);
    ABORT(1000000, 0x06010002, 0x23, 0x03, 0x10, 0x01, 0, 0, 0, 0); /* the same with one error */
    ABORT(1000000, 0x06010002, 0x23, 0x03, 0x10, 0x02, 0, 0, 0, 0);
}

/* ---- the communication objects' table: names and limits ---------------------------- */

/* The row of (index, sub): a header row when header, else the row holding sub. */
static const urrt_co_comm *comm_row(uint16_t index, uint8_t sub, bool header)
{
    size_t i;
    for (i = 0; i < urrt_co_comm_count; i++) {
        const urrt_co_comm *r = &urrt_co_comm_table[i];
        if (r->index == index && (header ? r->subs == 0u : sub >= r->sub && sub - r->sub < r->subs)) {
            return r;
        }
    }
    return NULL;
}

static void expect_name(int line, uint16_t index, uint8_t sub, bool header, const char *want)
{
    const urrt_co_comm *r = comm_row(index, sub, header);
    CHECK(r != NULL, "line %d: no row for 0x%04X sub %u", line, (unsigned)index, (unsigned)sub);
    if (r != NULL) {
        CHECK(CHECK_SAME_TEXT(urrt_co_comm_name(r), want), "line %d: 0x%04X sub %u is \"%s\", want \"%s\"", line,
              (unsigned)index, (unsigned)sub, urrt_co_comm_name(r), want);
    }
}
#define NAME(index, sub, header, want) expect_name(__LINE__, (index), (sub), (header), (want))

/* Names as CiA 301 gives its objects (an EDS's ParameterName), read for
 * rows at the start, middle and end of the table; and the one row with
 * limits, the transmission type (CiA 301: 0 and 241..253 are not values
 * this node takes; 1..255 is the range a write is held to first). */
static void test_comm_table(void)
{
    uint32_t low = 0, high = 0;
    size_t i;
    NAME(0x1000, 0, false, "Device type");
    NAME(0x1003, 0, true, "Pre-defined error field");
    NAME(0x1003, 0, false, "Number of errors");
    NAME(0x1003, 8, false, "Standard error field");
    NAME(0x1016, 0, true, "Consumer heartbeat time");
    NAME(0x1016, 4, false, "Consumer heartbeat time");
    NAME(0x1017, 0, false, "Producer heartbeat time");
    NAME(0x1018, 0, true, "Identity object");
    NAME(0x1018, 1, false, "Vendor-ID");
    NAME(0x1018, 4, false, "Serial number");
    NAME(0x1400, 1, false, "COB-ID used by RPDO");
    NAME(0x1600, 0, true, "RPDO mapping parameter");
    NAME(0x1600, 8, false, "Mapped object");
    NAME(0x1800, 2, false, "Transmission type");
    NAME(0x1A00, 0, true, "TPDO mapping parameter");
    NAME(0x1A00, 64, false, "Mapped object");
    for (i = 0; i < urrt_co_comm_count; i++) {
        CHECK(urrt_co_comm_name(&urrt_co_comm_table[i])[0] != '\0', "row %zu has a name", i);
    }
    CHECK(urrt_co_comm_limits(comm_row(0x1800, 2, false), &low, &high) && low == 1u && high == 0xFFu,
          "0x1800 sub 2's limits: %u..%u, want 1..255", (unsigned)low, (unsigned)high);
    CHECK(!urrt_co_comm_limits(comm_row(0x1800, 1, false), &low, &high), "0x1800 sub 1 has no limits");
    CHECK(!urrt_co_comm_limits(comm_row(0x1800, 0, true), &low, &high), "0x1800's header has no limits");
    CHECK(!urrt_co_comm_limits(comm_row(0x1017, 0, false), &low, &high), "0x1017 has no limits");
}

/* ---- EMCY ------------------------------------------------------------------------- */

static void read_errors(uint64_t t, uint8_t reg, uint8_t count)
{
    SDO(t, 0x40, 0x01, 0x10, 0x00, 0, 0, 0, 0);
    CHECK(out[0].data[0] == 0x4F && out[0].data[4] == reg, "0x1001 = 0x%02X, want 0x%02X", out[0].data[4], reg);
    SDO(t, 0x40, 0x03, 0x10, 0x00, 0, 0, 0, 0);
    CHECK(out[0].data[0] == 0x4F && out[0].data[4] == count, "0x1003 sub 0 = %u, want %u", out[0].data[4], count);
}

static void test_emcy(void)
{
    static urrt_cantx_link link;
    desc_defaults();
    desc.heartbeat_ms = 0;
    setup();
    packet(1000, 0, 7);
    EQ(run(1000), 0);
    urrt_cantx_robot_link(&tx, 0, false);
    EQ(run(2000), 1);
    EXPECT(0, 0x08A, 0x01, 0xFF, 0x81, 0x00, 0x00, 0x00, 0x00, 0x00);
    read_errors(2000, 0x81, 1);
    SDO(2000, 0x40, 0x03, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x03, 0x10, 0x01, 0x01, 0xFF, 0x00, 0x00);
    EQ(run(3000), 0); /* told once */
    packet(4000, 0, 7);
    EQ(run(4000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x01, 0xFF, 0x00, 0x00, 0x00); /* reset, naming 0xFF01 */
    read_errors(4000, 0x00, 1);
    /* Stale: 50 ms after the data, plus one microsecond. */
    EQ(run(50000), 0);
    EQ(urrt_co_deadline(&co), 54001); /* before urrt_cantx's next slot at 60 ms */
    EQ(run(54000), 0);
    EQ(run(54001), 1);
    EXPECT(0, 0x08A, 0x02, 0xFF, 0x81, 0x00, 0x00, 0x00, 0x00, 0x00);
    /* CAN overrun while stale: the register has both bits. */
    link.dropped = 3;
    urrt_cantx_set_link(&tx, &link);
    EQ(run(60000), 1);
    EXPECT(0, 0x08A, 0x10, 0x81, 0x91, 0x00, 0x00, 0x00, 0x00, 0x00);
    read_errors(60000, 0x91, 3);
    SDO(60000, 0x40, 0x03, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x03, 0x10, 0x01, 0x10, 0x81, 0x00, 0x00); /* newest first */
    SDO(60000, 0x40, 0x03, 0x10, 0x03, 0, 0, 0, 0);
    ANSWER(0x43, 0x03, 0x10, 0x03, 0x01, 0xFF, 0x00, 0x00);
    packet(70000, 0, 7);
    EQ(run(70000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x11, 0x02, 0xFF, 0x00, 0x00, 0x00);
    {
        uint64_t t;
        size_t sent = 0;
        for (t = 100000; t < 1060000; t += 40000) {
            packet(t, 0, 7);
            sent += run(t);
        }
        EQ(sent, 0);
    }
    packet(1060000, 0, 7);
    EQ(run(1060000), 1); /* the overrun held 1 s */
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x10, 0x81, 0x00, 0x00, 0x00);
    /* Error passive and bus off, with an inhibit time of 5 ms (50 x 100 us). */
    SDO(1060000, 0x2B, 0x15, 0x10, 0x00, 0x32, 0x00, 0, 0);
    urrt_co_set_error_passive(&co, true);
    link.bus_off = 1;
    urrt_cantx_set_link(&tx, &link);
    packet(1070000, 0, 7);
    EQ(run(1070000), 1);
    EXPECT(0, 0x08A, 0x20, 0x81, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(urrt_co_deadline(&co), 1075000);
    EQ(run(1074999), 0);
    EQ(run(1075000), 1);
    EXPECT(0, 0x08A, 0x40, 0x81, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00);
    /* 0x1003 sub 0 = 0 clears the history, not the register. */
    SDO(1075000, 0x2F, 0x03, 0x10, 0x00, 0x00, 0, 0, 0);
    ANSWER(0x60, 0x03, 0x10, 0x00, 0, 0, 0, 0);
    read_errors(1075000, 0x11, 0);
    /* EMCY switched off (bit 31): nothing sent, the register still kept. */
    SDO(1075000, 0x23, 0x14, 0x10, 0x00, 0x8A, 0x00, 0x00, 0x80);
    ANSWER(0x60, 0x14, 0x10, 0x00, 0, 0, 0, 0);
    urrt_co_set_error_passive(&co, false);
    packet(1080000, 0, 7);
    EQ(run(1080000), 0);
    read_errors(1080000, 0x11, 0);
}

/* ---- the receiving side: RPDOs and the consumer heartbeat -------------------------------- */

/* co_fixture_rx_node's storage (urrt_co_init_rx). */
static urrt_co_rpdo_state rpdo_states[2];
static urrt_co_consumer consumer_states[2];
static uint32_t rx_vars[CO_FIXTURE_RX_VARS];
static uint64_t written[CO_FIXTURE_RX_VARS];
/* Kept as long as the node: the receiving side's state is in it. */
static urrt_co_rx_storage storage;

static int init_rx(size_t *bad)
{
    memset(&storage, 0xA5, sizeof storage); /* what the node keeps there, it sets */
    storage.rpdos = rpdo_states;
    storage.consumers = consumer_states;
    storage.written_us = written;
    memset(frame_states, 0, sizeof frame_states);
    EQ(urrt_cantx_init(&tx, &tables, frame_states, robots, values, 8, NULL, NULL), 0);
    return urrt_co_init_rx(&co, &desc, &tx, tpdo_states, rx_vars, CO_FIXTURE_RX_VARS, &storage, bad);
}

/* desc (co_fixture_rx_node's, as a test changed it) started at time 0. */
static void setup_rx(void)
{
    size_t bad = 0;
    EQ(init_rx(&bad), 0);
    out_count = 0;
    EQ(urrt_co_start(&co, 0, capture, NULL), 1);
}

/* The node of the RPDO tests: no heartbeat of its own, both TPDOs switched off
 * (their COB-IDs invalid), so that only EMCYs come out of a run. No robot
 * packet comes: the tests end before the CAN core's startup second. */
static void rx_node(void)
{
    co_fixture_rx_desc(&desc);
    desc.heartbeat_ms = 0;
    setup_rx();
    SDO(0, 0x23, 0x00, 0x18, 0x01, 0x8A, 0x01, 0x00, 0xC0);
    ANSWER(0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0);
    SDO(0, 0x23, 0x01, 0x18, 0x01, 0x8A, 0x02, 0x00, 0xC0);
    ANSWER(0x60, 0x01, 0x18, 0x01, 0, 0, 0, 0);
}

/* A frame the node answers nothing to (an RPDO, a heartbeat). */
#define RX0(t, id, ...)                                                   \
    do {                                                                  \
        static const uint8_t d_[] = {__VA_ARGS__};                        \
        EQ(rx((id), d_, sizeof d_, (t)), 0);                              \
    } while (0)

/* The node as a loop runs it, woken at each of its deadlines from t on, until
 * a frame on id goes out (that run's time; out[] its frames) or limit. */
static uint64_t wake_until(uint32_t id, uint64_t t, uint64_t limit)
{
    unsigned wakes;
    for (wakes = 0; wakes < 100000u; wakes++) {
        uint64_t due = urrt_co_deadline(&co);
        t = due > t ? due : t;
        if (t >= limit) {
            return limit;
        }
        run(t);
        if (count_id(id) > 0u) {
            return t;
        }
    }
    CHECK(0, "the node woke without end at %llu", (unsigned long long)t);
    return limit;
}

static void expect_rx_init(int want, size_t want_item, const char *what)
{
    size_t bad = 0;
    int rc = init_rx(&bad);
    CHECK(rc == want && bad == want_item, "%s: got %d at %zu, want %d at %zu", what, rc, bad, want, want_item);
    CHECK(urrt_co_rx_strerror(rc)[0] != '\0' && !CHECK_SAME_TEXT(urrt_co_rx_strerror(rc), urrt_strerror(-1000)),
          "a text of its own for %d", rc);
}

/* urrt_co_init_rx's own results have their texts in the receiving side's
 * urrt_co_rx_strerror, which a node without RPDOs does not link (check-cross
 * looks for them in its image); every other result it gives as
 * urrt_co_strerror does. */
static void test_rx_strerror(void)
{
    int rc;
    CHECK(CHECK_SAME_TEXT(urrt_co_rx_strerror(URRT_CO_E_RPDO),
                          "an RPDO's transmission type, mapping or COB-ID is not usable"),
          "URRT_CO_E_RPDO: \"%s\"", urrt_co_rx_strerror(URRT_CO_E_RPDO));
    CHECK(CHECK_SAME_TEXT(urrt_co_rx_strerror(URRT_CO_E_CONSUMER),
                          "a consumer heartbeat (0x1016) entry is not usable, or RPDOs have none"),
          "URRT_CO_E_CONSUMER: \"%s\"", urrt_co_rx_strerror(URRT_CO_E_CONSUMER));
    CHECK(CHECK_SAME_TEXT(urrt_co_rx_strerror(URRT_CO_E_STORAGE),
                          "the CANopen node lacks its urrt_cantx, TPDO states, variables or RPDO storage"),
          "URRT_CO_E_STORAGE: \"%s\"", urrt_co_rx_strerror(URRT_CO_E_STORAGE));
    CHECK(CHECK_SAME_TEXT(urrt_co_strerror(URRT_CO_E_RPDO), urrt_strerror(-1000)),
          "urrt_co_strerror knows URRT_CO_E_RPDO: \"%s\"", urrt_co_strerror(URRT_CO_E_RPDO));
    for (rc = -80; rc <= 1; rc++) {
        if (rc != URRT_CO_E_RPDO && rc != URRT_CO_E_CONSUMER && rc != URRT_CO_E_STORAGE) {
            CHECK(urrt_co_rx_strerror(rc) == urrt_co_strerror(rc), "%d: urrt_co_rx_strerror differs", rc);
        }
    }
}

/* Descriptions urrt_co_init_rx refuses, each naming the RPDO or 0x1016 entry. */
static void test_rx_init(void)
{
    static urrt_co_rpdo bad_rpdos[5];
    static uint32_t bad_map[3];
    static uint32_t bad_consumers[5];
    size_t bad = 0;
    co_fixture_rx_desc(&desc);
    expect_rx_init(0, SIZE_MAX, "the test's description with RPDOs");
    memset(frame_states, 0, sizeof frame_states);
    EQ(urrt_cantx_init(&tx, &tables, frame_states, robots, values, 8, NULL, NULL), 0);
    EQ(urrt_co_init(&co, &desc, &tx, tpdo_states, rx_vars, CO_FIXTURE_RX_VARS, &bad), URRT_CO_E_STORAGE);
    memcpy(bad_rpdos, rpdos, sizeof rpdos);
    bad_rpdos[2] = bad_rpdos[3] = bad_rpdos[4] = bad_rpdos[1];
    desc.rpdos = bad_rpdos;
    desc.rpdo_count = 5;
    expect_rx_init(URRT_CO_E_RPDO, SIZE_MAX, "five RPDOs");
    desc.rpdo_count = 2;
    memcpy(bad_map, rmap_1, sizeof rmap_1);
    bad_rpdos[0].mapping = bad_map;
    bad_map[0] = 0x22010010;
    expect_rx_init(URRT_CO_E_RPDO, 0, "a read-only variable mapped");
    bad_map[0] = 0x20000110;
    expect_rx_init(URRT_CO_E_RPDO, 0, "a robot value mapped");
    bad_map[0] = 0x22000108;
    expect_rx_init(URRT_CO_E_RPDO, 0, "8 bits of an INTEGER16");
    bad_map[0] = 0x22050008;
    expect_rx_init(URRT_CO_E_RPDO, 0, "an object that does not exist");
    bad_map[0] = 0x00050010;
    expect_rx_init(URRT_CO_E_RPDO, 0, "an UNSIGNED8 dummy of 16 bits");
    bad_map[0] = 0x00060010; /* an UNSIGNED16 dummy is fine ... */
    bad_map[1] = 0x22000320;
    bad_map[2] = 0x22000320; /* ... but 16 + 32 + 32 bits is over 8 bytes */
    expect_rx_init(URRT_CO_E_RPDO, 0, "a mapping of 80 bits");
    bad_rpdos[0].mapping = rmap_1;
    bad_rpdos[1].transmission_type = 241;
    expect_rx_init(URRT_CO_E_RPDO, 1, "transmission type 241");
    bad_rpdos[1].transmission_type = 240;
    bad_rpdos[1].cob_id = 0x601;
    expect_rx_init(URRT_CO_E_RPDO, 1, "a restricted COB-ID (SDO)");
    bad_rpdos[1].cob_id = 0x20A;
    expect_rx_init(URRT_CO_E_RPDO, 1, "RPDO1's id");
    bad_rpdos[1].cob_id = 0x8000020A;
    expect_rx_init(0, SIZE_MAX, "RPDO1's id, invalid");
    co_fixture_rx_desc(&desc);
    desc.consumer_count = 0;
    expect_rx_init(URRT_CO_E_CONSUMER, SIZE_MAX, "RPDOs without 0x1016");
    desc.consumer_count = 5;
    expect_rx_init(URRT_CO_E_CONSUMER, SIZE_MAX, "five 0x1016 entries");
    desc.consumer_count = 2;
    desc.consumers = bad_consumers;
    bad_consumers[0] = 0x00800064;
    expect_rx_init(URRT_CO_E_CONSUMER, 0, "node id 128");
    bad_consumers[0] = 0x01010064;
    expect_rx_init(URRT_CO_E_CONSUMER, 0, "bit 24");
    bad_consumers[0] = 0x00010064;
    bad_consumers[1] = 0x000100C8;
    expect_rx_init(URRT_CO_E_CONSUMER, 1, "node 1 twice");
    bad_consumers[1] = 0x00010000;
    expect_rx_init(0, SIZE_MAX, "node 1 twice, once off (time 0)");
    desc.consumers = NULL;
    expect_rx_init(0, SIZE_MAX, "0x1016 all 0");
    /* Heartbeat consumers without RPDOs. */
    desc.rpdos = NULL;
    desc.rpdo_count = 0;
    expect_rx_init(0, SIZE_MAX, "0x1016 alone");
    EQ(urrt_co_init(&co, &desc, &tx, tpdo_states, rx_vars, CO_FIXTURE_RX_VARS, &bad), URRT_CO_E_STORAGE);
}

/* 0x1400, 0x1600, 0x1016 as CiA 301 lays them out; none on a node without. */
static void test_rx_sdo_reads(void)
{
    co_fixture_rx_desc(&desc);
    setup_rx();
    SDO(0, 0x40, 0x00, 0x14, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x14, 0x00, 0x05, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x00); /* 0x200 + 10 */
    SDO(0, 0x40, 0x01, 0x14, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x01, 0x14, 0x01, 0x0A, 0x03, 0x00, 0x00); /* 0x300 + 10 */
    SDO(0, 0x40, 0x00, 0x14, 0x02, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x14, 0x02, 0xFF, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x01, 0x14, 0x02, 0, 0, 0, 0);
    ANSWER(0x4F, 0x01, 0x14, 0x02, 0x00, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x00, 0x14, 0x05, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x14, 0x05, 0x64, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x01, 0x14, 0x05, 0, 0, 0, 0);
    ANSWER(0x4B, 0x01, 0x14, 0x05, 0x00, 0x00, 0x00, 0x00);
    ABORT(0, 0x06090011, 0x40, 0x00, 0x14, 0x03, 0, 0, 0, 0); /* no inhibit time on an RPDO */
    ABORT(0, 0x06090011, 0x40, 0x00, 0x14, 0x04, 0, 0, 0, 0);
    ABORT(0, 0x06090011, 0x40, 0x00, 0x14, 0x06, 0, 0, 0, 0);
    ABORT(0, 0x06020000, 0x40, 0x02, 0x14, 0x00, 0, 0, 0, 0); /* no RPDO3 */
    SDO(0, 0x40, 0x00, 0x16, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x16, 0x00, 0x03, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x00, 0x16, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x16, 0x01, 0x10, 0x01, 0x00, 0x22);
    SDO(0, 0x40, 0x00, 0x16, 0x03, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x16, 0x03, 0x20, 0x03, 0x00, 0x22);
    SDO(0, 0x40, 0x01, 0x16, 0x02, 0, 0, 0, 0);
    ANSWER(0x43, 0x01, 0x16, 0x02, 0x08, 0x00, 0x05, 0x00); /* the UNSIGNED8 dummy */
    ABORT(0, 0x06090011, 0x40, 0x00, 0x16, 0x04, 0, 0, 0, 0);
    ABORT(0, 0x06020000, 0x40, 0x02, 0x16, 0x00, 0, 0, 0, 0);
    SDO(0, 0x40, 0x16, 0x10, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x16, 0x10, 0x00, 0x02, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x16, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x16, 0x10, 0x01, 0x96, 0x00, 0x01, 0x00); /* node 1, 150 ms */
    SDO(0, 0x40, 0x16, 0x10, 0x02, 0, 0, 0, 0);
    ANSWER(0x43, 0x16, 0x10, 0x02, 0x00, 0x00, 0x00, 0x00);
    ABORT(0, 0x06090011, 0x40, 0x16, 0x10, 0x03, 0, 0, 0, 0);
    SDO(0, 0x40, 0x00, 0x22, 0x00, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x22, 0x00, 0x04, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x00, 0x22, 0x03, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x22, 0x03, 0x07, 0x00, 0x00, 0x00);
    SDO(0, 0x40, 0x01, 0x22, 0x00, 0, 0, 0, 0);
    ANSWER(0x4B, 0x01, 0x22, 0x00, 0x05, 0x00, 0x00, 0x00);
    ABORT(0, 0x06010001, 0x40, 0x00, 0x22, 0x04, 0, 0, 0, 0); /* write-only */
    /* The node without RPDOs has none of these objects. */
    desc_defaults();
    setup();
    ABORT(0, 0x06020000, 0x40, 0x00, 0x14, 0x00, 0, 0, 0, 0);
    ABORT(0, 0x06020000, 0x40, 0x00, 0x16, 0x00, 0, 0, 0, 0);
    ABORT(0, 0x06020000, 0x40, 0x16, 0x10, 0x00, 0, 0, 0, 0);
    ABORT(0, 0x06020000, 0x23, 0x16, 0x10, 0x01, 0x64, 0x00, 0x01, 0x00);
}

/* An upload's answer (expedited, or the initiation of a segmented one,
 * which the client's abort then ends): 0 with the value and its size, or
 * the abort code. */
static uint32_t sdo_read(uint16_t index, uint8_t sub, uint32_t *value, uint32_t *size)
{
    const uint8_t req[8] = {0x40, (uint8_t)index, (uint8_t)(index >> 8), sub, 0, 0, 0, 0};
    const uint8_t client_abort[8] = {0x80, (uint8_t)index, (uint8_t)(index >> 8), sub, 0, 0, 0x04, 0x05};
    uint32_t word;
    EQ(rx(0x600 + NODE, req, 8, 0), 1);
    word = (uint32_t)out[0].data[4] | (uint32_t)out[0].data[5] << 8 | (uint32_t)out[0].data[6] << 16 |
           (uint32_t)out[0].data[7] << 24;
    if (out[0].data[0] == 0x80) {
        return word;
    }
    if ((out[0].data[0] & 0x02) == 0u) {
        *size = word;
        *value = 0;
        EQ(rx(0x600 + NODE, client_abort, 8, 0), 0);
        return 0;
    }
    *size = 4u - (uint32_t)(out[0].data[0] >> 2 & 3u);
    *value = *size == 4u ? word : word & ((UINT32_C(1) << (8u * *size)) - 1u);
    return 0;
}

/* The dictionary as its readers (an EDS writer) see it, urrt_co_comm_table:
 * every row, in index order, the receiving side's among them, with its
 * instances on this node; each of their sub-indices reads what the SDO
 * server answers an upload of it (the value and its size, or the abort), and
 * a row without a write function is the SDO server's read-only. The SDO
 * server looks up rows of its own (urrt_co.c's and urrt_co_rx.c's), so this
 * holds the two expansions of one list to each other. On the node with
 * RPDOs, then the one without (where the receiving side's rows have none). */
static void check_comm_readers(const char *node)
{
    size_t i;
    for (i = 0; i < urrt_co_comm_count; i++) {
        const urrt_co_comm *r = &urrt_co_comm_table[i];
        size_t n;
        unsigned s;
        CHECK(i == 0 || r->index >= urrt_co_comm_table[i - 1u].index, "%s: row %zu (0x%04X) out of index order",
              node, i, (unsigned)r->index);
        for (n = 0; n < urrt_co_comm_instances(&co, r); n++) {
            for (s = r->sub; s < (unsigned)r->sub + r->subs; s++) {
                uint16_t index = (uint16_t)(r->index + n);
                urrt_co_value v;
                uint32_t value = 0, size = 0;
                uint32_t abort_code = urrt_co_comm_read(&co, r, n, (uint8_t)s, &v);
                uint32_t sdo = sdo_read(index, (uint8_t)s, &value, &size);
                CHECK(abort_code == sdo, "%s: 0x%04X sub %u: read 0x%08X, the SDO server 0x%08X", node,
                      (unsigned)index, s, (unsigned)abort_code, (unsigned)sdo);
                if (abort_code == 0u && sdo == 0u) {
                    CHECK(v.size == size && (v.text != NULL || v.value == value),
                          "%s: 0x%04X sub %u: read 0x%X (%u bytes), the SDO server 0x%X (%u bytes)", node,
                          (unsigned)index, s, (unsigned)v.value, (unsigned)v.size, (unsigned)value, (unsigned)size);
                }
                if (r->write == NULL && abort_code != URRT_CO_ABORT_NO_SUB) {
                    const uint8_t req[8] = {0x23, (uint8_t)index, (uint8_t)(index >> 8), (uint8_t)s, 0, 0, 0, 0};
                    EQ(rx(0x600 + NODE, req, 8, 0), 1);
                    CHECK(out[0].data[0] == 0x80 && out[0].data[4] == 0x02 && out[0].data[5] == 0x00 &&
                              out[0].data[6] == 0x01 && out[0].data[7] == 0x06,
                          "%s: 0x%04X sub %u has no write, and the SDO server does not answer 0x06010002", node,
                          (unsigned)index, s);
                }
            }
        }
        if (r->subs != 0u) {
            urrt_co_value v;
            EQ(urrt_co_comm_read(&co, r, urrt_co_comm_instances(&co, r), r->sub, &v), URRT_CO_ABORT_NO_SUB);
        }
    }
}

static void test_comm_readers(void)
{
    co_fixture_rx_desc(&desc);
    setup_rx();
    nmt(0x01, NODE, 0);
    check_comm_readers("the node with RPDOs");
    desc_defaults();
    setup();
    check_comm_readers("the node without");
}

/* urrt_co_rx_ids on the node with RPDOs: NMT, SYNC, SDO, RPDO1, RPDO2, node 1's heartbeat. */
static void expect_rx_ids6(int line, const uint32_t *want, size_t want_count, uint32_t changes)
{
    uint32_t ids[URRT_CO_RX_IDS_MAX];
    size_t n = urrt_co_rx_ids(&co, ids);
    size_t i;
    bool same = n == want_count && co.rx_changes == changes;
    for (i = 0; same && i < n; i++) {
        same = ids[i] == want[i];
    }
    CHECK(same, "line %d: %zu ids (0x%03X ...) after %u changes, want %zu after %u", line, n, (unsigned)ids[3],
          (unsigned)co.rx_changes, want_count, (unsigned)changes);
}
#define RX_IDS_ARE(changes, ...)                                                            \
    do {                                                                                    \
        static const uint32_t w_[] = {__VA_ARGS__};                                         \
        expect_rx_ids6(__LINE__, w_, sizeof w_ / sizeof w_[0], (changes));                  \
    } while (0)

/* Writes of 0x1400, 0x1600, 0x1016 and the variables: what CiA 301 allows,
 * the abort of each refusal, and the ids received following them. */
static void test_rx_sdo_writes(void)
{
    co_fixture_rx_desc(&desc);
    desc.heartbeat_ms = 0;
    setup_rx();
    RX_IDS_ARE(0, 0x000, 0x080, 0x60A, 0x20A, 0x30A, 0x701);
    /* The mapping is the description's: read-only, even the remap sequence's sub 0 = 0. */
    ABORT(0, 0x06010002, 0x2F, 0x00, 0x16, 0x00, 0x00, 0, 0, 0);
    ABORT(0, 0x06010002, 0x23, 0x00, 0x16, 0x01, 0x08, 0x00, 0x01, 0x21);
    ABORT(0, 0x06090011, 0x23, 0x00, 0x16, 0x04, 0x08, 0x00, 0x01, 0x21); /* past the entries: exists first */
    ABORT(0, 0x06010002, 0x2F, 0x00, 0x14, 0x00, 0x02, 0, 0, 0);
    ABORT(0, 0x06010002, 0x2B, 0x01, 0x22, 0x00, 0x06, 0x00, 0, 0); /* a read-only register */
    ABORT(0, 0x06010002, 0x2F, 0x16, 0x10, 0x00, 0x01, 0, 0, 0);
    /* COB-ID: a new id only while or into invalid (CiA 301), as for TPDOs. */
    ABORT(0, 0x06090030, 0x23, 0x00, 0x14, 0x01, 0x0B, 0x02, 0x00, 0x00);
    ABORT(0, 0x06090030, 0x23, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x20); /* bit 29 */
    ABORT(0, 0x06070013, 0x2B, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x00); /* 2 bytes into UNSIGNED32 */
    RX_IDS_ARE(0, 0x000, 0x080, 0x60A, 0x20A, 0x30A, 0x701);
    SDO(0, 0x23, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x80); /* RPDO1 off */
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    RX_IDS_ARE(1, 0x000, 0x080, 0x60A, 0x30A, 0x701);
    EQ(rx_changes_at_emit, 1); /* before the answer */
    SDO(0, 0x23, 0x00, 0x14, 0x01, 0x1A, 0x02, 0x00, 0x80); /* a new id while off */
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    RX_IDS_ARE(1, 0x000, 0x080, 0x60A, 0x30A, 0x701);
    ABORT(0, 0x06090030, 0x23, 0x00, 0x14, 0x01, 0x01, 0x06, 0x00, 0x00); /* valid on 0x601: restricted */
    ABORT(0, 0x06090030, 0x23, 0x00, 0x14, 0x01, 0x0A, 0x03, 0x00, 0x00); /* valid on RPDO2's 0x30A */
    SDO(0, 0x23, 0x00, 0x14, 0x01, 0x1A, 0x02, 0x00, 0x00); /* valid on 0x21A */
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    RX_IDS_ARE(2, 0x000, 0x080, 0x60A, 0x21A, 0x30A, 0x701);
    SDO(0, 0x40, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x00, 0x14, 0x01, 0x1A, 0x02, 0x00, 0x00);
    SDO(0, 0x23, 0x00, 0x14, 0x01, 0x1A, 0x02, 0x00, 0x40); /* bit 30 kept as written, the id the same */
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    RX_IDS_ARE(2, 0x000, 0x080, 0x60A, 0x21A, 0x30A, 0x701);
    /* Transmission type: 0..240, 254, 255; 241..253 refused. */
    ABORT(0, 0x06090031, 0x2F, 0x00, 0x14, 0x02, 0xF1, 0, 0, 0);
    ABORT(0, 0x06090031, 0x2F, 0x00, 0x14, 0x02, 0xFD, 0, 0, 0);
    ABORT(0, 0x06070012, 0x23, 0x00, 0x14, 0x02, 0x00, 0, 0, 0); /* 4 bytes into UNSIGNED8 */
    SDO(0, 0x2F, 0x00, 0x14, 0x02, 0x00, 0, 0, 0);
    ANSWER(0x60, 0x00, 0x14, 0x02, 0, 0, 0, 0);
    SDO(0, 0x2F, 0x00, 0x14, 0x02, 0xF0, 0, 0, 0);
    ANSWER(0x60, 0x00, 0x14, 0x02, 0, 0, 0, 0);
    SDO(0, 0x2F, 0x00, 0x14, 0x02, 0xFE, 0, 0, 0);
    ANSWER(0x60, 0x00, 0x14, 0x02, 0, 0, 0, 0);
    SDO(0, 0x40, 0x00, 0x14, 0x02, 0, 0, 0, 0);
    ANSWER(0x4F, 0x00, 0x14, 0x02, 0xFE, 0x00, 0x00, 0x00);
    /* Event timer: any value, 2 bytes. */
    ABORT(0, 0x06070013, 0x2F, 0x00, 0x14, 0x05, 0x32, 0, 0, 0);
    SDO(0, 0x2B, 0x00, 0x14, 0x05, 0xF4, 0x01, 0, 0);
    ANSWER(0x60, 0x00, 0x14, 0x05, 0, 0, 0, 0);
    SDO(0, 0x40, 0x00, 0x14, 0x05, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x14, 0x05, 0xF4, 0x01, 0x00, 0x00);
    /* A request frame shorter than 8 bytes: 0x06070010 with its index. */
    {
        static const uint8_t seven[7] = {0x23, 0x00, 0x14, 0x05, 0x32, 0x00, 0x00};
        EQ(rx(0x60A, seven, 7, 0), 1);
        EXPECT(0, 0x58A, 0x80, 0x00, 0x14, 0x05, 0x10, 0x00, 0x07, 0x06);
    }
    /* 0x1016: node id << 16 | ms; one node once; bits 24..31 0; node ids to 127. */
    ABORT(0, 0x06070013, 0x2B, 0x16, 0x10, 0x01, 0x64, 0x00, 0, 0);
    SDO(0, 0x23, 0x16, 0x10, 0x02, 0x64, 0x00, 0x02, 0x00); /* node 2, 100 ms */
    ANSWER(0x60, 0x16, 0x10, 0x02, 0, 0, 0, 0);
    RX_IDS_ARE(3, 0x000, 0x080, 0x60A, 0x21A, 0x30A, 0x701, 0x702);
    ABORT(0, 0x06040043, 0x23, 0x16, 0x10, 0x01, 0xC8, 0x00, 0x02, 0x00); /* node 2 twice */
    ABORT(0, 0x06090030, 0x23, 0x16, 0x10, 0x01, 0x64, 0x00, 0x80, 0x00); /* node 128 */
    ABORT(0, 0x06090030, 0x23, 0x16, 0x10, 0x01, 0x64, 0x00, 0x03, 0x01); /* bit 24 */
    SDO(0, 0x23, 0x16, 0x10, 0x01, 0x00, 0x00, 0x02, 0x00); /* node 2, time 0: off, so not twice */
    ANSWER(0x60, 0x16, 0x10, 0x01, 0, 0, 0, 0);
    RX_IDS_ARE(4, 0x000, 0x080, 0x60A, 0x21A, 0x30A, 0x702);
    SDO(0, 0x40, 0x16, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x16, 0x10, 0x01, 0x00, 0x00, 0x02, 0x00);
    /* The variables: in range stored and recorded, out of range refused. */
    ABORT(0, 0x06090032, 0x2B, 0x00, 0x22, 0x01, 0x17, 0xFC, 0, 0); /* -1001 */
    ABORT(0, 0x06090031, 0x2B, 0x00, 0x22, 0x01, 0xE9, 0x03, 0, 0); /* 1001 */
    ABORT(0, 0x06090031, 0x2F, 0x00, 0x22, 0x02, 0x02, 0, 0, 0);    /* a BOOLEAN: 2 */
    ABORT(0, 0x06070012, 0x23, 0x00, 0x22, 0x02, 0x01, 0, 0, 0);    /* 4 bytes into UNSIGNED8 */
    EQ(co.var_writes, 0);
    EQ(written[2], URRT_CANTX_NEVER);
    SDO(5000, 0x2B, 0x00, 0x22, 0x01, 0x18, 0xFC, 0, 0); /* -1000 */
    ANSWER(0x60, 0x00, 0x22, 0x01, 0, 0, 0, 0);
    EQ(rx_vars[2], 0xFC18);
    EQ(written[2], 5000);
    EQ(co.var_writes, 1);
    /* Reset communication: the parameters back, the ids with them. */
    nmt(0x82, NODE, 6000);
    RX_IDS_ARE(5, 0x000, 0x080, 0x60A, 0x20A, 0x30A, 0x701);
    EQ(rx_changes_at_emit, 5); /* before the boot-up */
    SDO(6000, 0x40, 0x00, 0x14, 0x05, 0, 0, 0, 0);
    ANSWER(0x4B, 0x00, 0x14, 0x05, 0x64, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 0xFC18); /* the application's values stay */
    EQ(written[2], 5000);
    nmt(0x81, NODE, 7000); /* reset node: they go back too */
    EQ(rx_vars[2], 0);
    EQ(rx_vars[4], 7);
    EQ(written[2], URRT_CANTX_NEVER);
    RX_IDS_ARE(5, 0x000, 0x080, 0x60A, 0x20A, 0x30A, 0x701);
}

/* RPDO1 (type 255) at once, RPDO2 (type 0) at the next SYNC, only in
 * OPERATIONAL; too short: EMCY 0x8210 once, not processed; too long:
 * processed; values outside their range refused and counted. */
static void test_rpdo_processing(void)
{
    rx_node();
    RX0(1000, 0x20A, 0xF4, 0x01, 0x01, 0x78, 0x56, 0x34, 0x12);
    EQ(rx_vars[2], 0); /* pre-operational: not processed */
    EQ(co.var_writes, 0);
    nmt(0x02, NODE, 1000);
    RX0(1000, 0x20A, 0xF4, 0x01, 0x01, 0x78, 0x56, 0x34, 0x12);
    EQ(rx_vars[2], 0); /* stopped */
    nmt(0x01, NODE, 2000);
    RX0(10000, 0x20A, 0xF4, 0x01, 0x01, 0x78, 0x56, 0x34, 0x12);
    EQ(rx_vars[2], 500);
    EQ(rx_vars[3], 1);
    EQ(rx_vars[4], 0x12345678);
    EQ(written[2], 10000);
    EQ(written[3], 10000);
    EQ(written[4], 10000);
    EQ(written[5], URRT_CANTX_NEVER);
    EQ(co.var_writes, 1);
    EQ(run(10000), 0);
    /* Longer: the extra byte ignored. */
    RX0(20000, 0x20A, 0x18, 0xFC, 0x00, 0x01, 0x00, 0x00, 0x00, 0xEE);
    EQ(rx_vars[2], 0xFC18); /* -1000, as the INTEGER16's bits */
    EQ(rx_vars[3], 0);
    EQ(rx_vars[4], 1);
    EQ(co.var_writes, 2);
    /* Shorter: not processed, EMCY 0x8210 once, reset by one of the right length. */
    RX0(30000, 0x20A, 0x01, 0x00, 0x01, 0x02, 0x00, 0x00);
    EQ(rx_vars[2], 0xFC18);
    EQ(co.var_writes, 2);
    EQ(urrt_co_deadline(&co) <= 30000, 1); /* the EMCY is due at once */
    EQ(run(30000), 1);
    EXPECT(0, 0x08A, 0x10, 0x82, 0x11, 0x00, 0x00, 0x01, 0x00, 0x00);
    read_errors(30000, 0x11, 1);
    RX0(31000, 0x20A, 0x01);
    EQ(run(31000), 0); /* told once */
    RX0(40000, 0x20A, 0x02, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 2);
    EQ(run(40000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x10, 0x82, 0x01, 0x00, 0x00);
    read_errors(40000, 0x00, 1);
    /* Out of range: 1001 and a BOOLEAN 2 refused, the UNSIGNED32 stored. */
    RX0(50000, 0x20A, 0xE9, 0x03, 0x02, 0x05, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 2);
    EQ(rx_vars[3], 0);
    EQ(rx_vars[4], 5);
    EQ(written[2], 40000);
    EQ(written[4], 50000);
    EQ(co.values_refused, 2);
    EQ(co.var_writes, 4);
    /* RPDO2, type 0: kept; the latest before the SYNC acted on at it. */
    RX0(60000, 0x30A, 0x9C, 0xAA, 0x10, 0x00); /* -100, dummy, 16 */
    RX0(61000, 0x30A, 0x05, 0xAA, 0x20, 0x00); /* 5, dummy, 32 */
    EQ(rx_vars[5], 0);
    EQ(rx_vars[2], 2);
    EQ(rx(0x080, NULL, 0, 62000), 0);
    EQ(rx_vars[5], 5);
    EQ(rx_vars[2], 0x20);
    EQ(written[5], 62000);
    EQ(written[2], 62000);
    EQ(co.var_writes, 5);
    EQ(rx(0x080, NULL, 0, 63000), 0);
    EQ(co.var_writes, 5); /* nothing new at the next SYNC */
    RX0(64000, 0x30A, 0x9B, 0xAA, 0x20, 0x00); /* -101: below -100 */
    EQ(rx(0x080, NULL, 0, 65000), 0);
    EQ(rx_vars[5], 5);
    EQ(co.values_refused, 3);
    EQ(written[2], 65000); /* its other value was stored */
    /* A kept RPDO does not outlive OPERATIONAL. */
    RX0(66000, 0x30A, 0x01, 0xAA, 0x30, 0x00);
    nmt(0x80, NODE, 67000);
    nmt(0x01, NODE, 68000);
    EQ(rx(0x080, NULL, 0, 69000), 0);
    EQ(rx_vars[5], 5);
    /* RPDO2 made event-driven (255): at once. */
    SDO(70000, 0x2F, 0x01, 0x14, 0x02, 0xFF, 0, 0, 0);
    ANSWER(0x60, 0x01, 0x14, 0x02, 0, 0, 0, 0);
    RX0(71000, 0x30A, 0x9C, 0xAA, 0x30, 0x00);
    EQ(rx_vars[5], 0x9C);
    EQ(rx_vars[2], 0x30);
    /* An RPDO whose COB-ID is invalid is not received. */
    SDO(72000, 0x23, 0x01, 0x14, 0x01, 0x0A, 0x03, 0x00, 0x80);
    ANSWER(0x60, 0x01, 0x14, 0x01, 0, 0, 0, 0);
    RX0(73000, 0x30A, 0x01, 0xAA, 0x40, 0x00);
    EQ(rx_vars[2], 0x30);
    EQ(run(80000), 0);
}

/* The event timer is RPDO1's deadline: watched from its first RPDO in
 * OPERATIONAL; late: EMCY 0x8250 once (at the deadline a loop wakes for),
 * reset when it comes again. */
static void test_rpdo_deadline(void)
{
    rx_node();
    nmt(0x01, NODE, 0);
    EQ(wake_until(0x08A, 0, 500000), 500000); /* none before the first */
    RX0(500000, 0x20A, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(wake_until(0x08A, 500000, 900000), 600001); /* 100 ms after it, plus 1 us */
    EXPECT(0, 0x08A, 0x50, 0x82, 0x11, 0x00, 0x00, 0x01, 0x00, 0x00);
    EQ(wake_until(0x08A, 600001, 650000), 650000); /* once */
    RX0(650000, 0x20A, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(run(650000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x50, 0x82, 0x01, 0x00, 0x00);
    /* On time: no EMCY. */
    RX0(740000, 0x20A, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    RX0(840000, 0x20A, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(wake_until(0x08A, 840000, 940000), 940000);
    /* Not watched outside OPERATIONAL. */
    nmt(0x80, NODE, 940000);
    EQ(wake_until(0x08A, 940000, 999000), 999000);
}

/* The same deadline written by SDO: watched again from the next RPDO; 0 is off. */
static void test_rpdo_deadline_write(void)
{
    rx_node();
    nmt(0x01, NODE, 0);
    RX0(10000, 0x20A, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    SDO(20000, 0x2B, 0x00, 0x14, 0x05, 0x00, 0x00, 0, 0); /* off */
    ANSWER(0x60, 0x00, 0x14, 0x05, 0, 0, 0, 0);
    EQ(wake_until(0x08A, 20000, 500000), 500000);
    SDO(500000, 0x2B, 0x00, 0x14, 0x05, 0x0A, 0x00, 0, 0); /* 10 ms */
    ANSWER(0x60, 0x00, 0x14, 0x05, 0, 0, 0, 0);
    EQ(wake_until(0x08A, 500000, 600000), 600000); /* from the next RPDO */
    RX0(600000, 0x20A, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(wake_until(0x08A, 600000, 700000), 610001);
    EXPECT(0, 0x08A, 0x50, 0x82, 0x11, 0x00, 0x00, 0x01, 0x00, 0x00);
    /* RPDO2 has no event timer: never late. */
    RX0(620000, 0x30A, 0x01, 0x00, 0x00, 0x00);
    /* RPDO1 switched off: its condition ends. */
    SDO(630000, 0x23, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x80);
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    EQ(run(630000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x50, 0x82, 0x01, 0x00, 0x00);
    EQ(wake_until(0x08A, 630000, 990000), 990000);
}

/* 0x1016 sub 1: node 1, 150 ms. Watched from its first heartbeat; a lost
 * one raises EMCY 0x8130 once, reset when heartbeats come back. */
static void test_consumer_heartbeat(void)
{
    rx_node();
    EQ(wake_until(0x08A, 0, 300000), 300000); /* none before the first */
    RX0(300000, 0x701, 0x05);
    RX0(400000, 0x701, 0x05);
    EQ(wake_until(0x08A, 400000, 900000), 550001); /* 150 ms after the last, plus 1 us */
    EXPECT(0, 0x08A, 0x30, 0x81, 0x11, 0x00, 0x00, 0x01, 0x00, 0x00);
    read_errors(550001, 0x11, 1);
    SDO(550001, 0x40, 0x03, 0x10, 0x01, 0, 0, 0, 0);
    ANSWER(0x43, 0x03, 0x10, 0x01, 0x30, 0x81, 0x00, 0x00);
    EQ(wake_until(0x08A, 550001, 700000), 700000); /* once */
    {
        const uint8_t two[2] = {0x05, 0x00};
        EQ(rx(0x701, two, 2, 700000), 0); /* a heartbeat is one byte */
        EQ(run(700000), 0);
        EQ(rx(0x702, two, 1, 700000), 0); /* another node's */
        EQ(run(700000), 0);
    }
    RX0(710000, 0x701, 0x7F);
    EQ(run(710000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x30, 0x81, 0x01, 0x00, 0x00);
    EQ(consumer_states[0].producer_state, 0x7F);
    /* A boot-up starts it over: nothing until the next heartbeat. */
    RX0(720000, 0x701, 0x00);
    EQ(wake_until(0x08A, 720000, 900000), 900000);
    /* STOPPED stops it; back in PRE-OPERATIONAL it starts with the next heartbeat. */
    RX0(900000, 0x701, 0x05);
    nmt(0x02, NODE, 910000);
    EQ(wake_until(0x08A, 910000, 960000), 960000);
    nmt(0x80, NODE, 960000);
    EQ(wake_until(0x08A, 960000, 999000), 999000);
}

/* The same in OPERATIONAL, with a moved producer: 0x1016 sub 1 = node 2, 20 ms. */
static void test_consumer_write(void)
{
    rx_node();
    nmt(0x01, NODE, 0);
    RX0(10000, 0x701, 0x05);
    SDO(20000, 0x23, 0x16, 0x10, 0x01, 0x14, 0x00, 0x02, 0x00);
    ANSWER(0x60, 0x16, 0x10, 0x01, 0, 0, 0, 0);
    RX0(30000, 0x701, 0x05); /* node 1 no longer watched */
    EQ(wake_until(0x08A, 30000, 200000), 200000);
    RX0(200000, 0x702, 0x05);
    EQ(wake_until(0x08A, 200000, 300000), 220001);
    EXPECT(0, 0x08A, 0x30, 0x81, 0x11, 0x00, 0x00, 0x01, 0x00, 0x00);
    SDO(230000, 0x23, 0x16, 0x10, 0x01, 0x00, 0x00, 0x00, 0x00); /* off: the condition ends */
    ANSWER(0x60, 0x16, 0x10, 0x01, 0, 0, 0, 0);
    EQ(run(230000), 1);
    EXPECT(0, 0x08A, 0x00, 0x00, 0x00, 0x30, 0x81, 0x01, 0x00, 0x00);
}

/* urrt_co_rpdo_status: what a gateway's silence policy reads, through
 * every reason. */
static void test_rpdo_status(void)
{
    size_t bad = 0;
    co_fixture_rx_desc(&desc);
    desc.heartbeat_ms = 0;
    EQ(init_rx(&bad), 0);
    EQ(urrt_co_rpdo_status(&co, 0, 0), URRT_CO_RPDO_NOT_OPERATIONAL); /* not started */
    rx_node();
    EQ(urrt_co_rpdo_status(&co, 2, 0), URRT_CO_RPDO_NONE);
    EQ(urrt_co_rpdo_status(NULL, 0, 0), URRT_CO_RPDO_NONE);
    EQ(urrt_co_rpdo_status(&co, 0, 0), URRT_CO_RPDO_NOT_OPERATIONAL);
    nmt(0x01, NODE, 0);
    EQ(urrt_co_rpdo_status(&co, 0, 0), URRT_CO_RPDO_NO_DATA);
    RX0(10000, 0x20A, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    RX0(10000, 0x30A, 0x01, 0x00, 0x00, 0x00);
    EQ(urrt_co_rpdo_status(&co, 0, 10000), URRT_CO_RPDO_FRESH);
    EQ(urrt_co_rpdo_status(&co, 0, 110000), URRT_CO_RPDO_FRESH);  /* 100 ms: still within */
    EQ(urrt_co_rpdo_status(&co, 0, 110001), URRT_CO_RPDO_DEADLINE);
    EQ(urrt_co_rpdo_status(&co, 1, 900000), URRT_CO_RPDO_FRESH);  /* no event timer */
    /* The manager's heartbeat: lost at 150 ms after its last, for every RPDO. */
    RX0(20000, 0x701, 0x05);
    EQ(urrt_co_rpdo_status(&co, 1, 170000), URRT_CO_RPDO_FRESH);
    EQ(urrt_co_rpdo_status(&co, 1, 170001), URRT_CO_RPDO_HEARTBEAT_LOST);
    EQ(wake_until(0x08A, 20000, 999000), 110001); /* RPDO1's deadline first */
    EQ(wake_until(0x08A, 110001, 999000), 170001);
    EQ(urrt_co_rpdo_status(&co, 1, 170001), URRT_CO_RPDO_HEARTBEAT_LOST);
    RX0(180000, 0x701, 0x05);
    EQ(urrt_co_rpdo_status(&co, 1, 180000), URRT_CO_RPDO_FRESH);
    /* The manager switches RPDO2 off, then on: no data until the next. */
    SDO(190000, 0x23, 0x01, 0x14, 0x01, 0x0A, 0x03, 0x00, 0x80);
    EQ(urrt_co_rpdo_status(&co, 1, 190000), URRT_CO_RPDO_NOT_VALID);
    SDO(190000, 0x23, 0x01, 0x14, 0x01, 0x0A, 0x03, 0x00, 0x00);
    EQ(urrt_co_rpdo_status(&co, 1, 190000), URRT_CO_RPDO_NO_DATA);
    RX0(200000, 0x30A, 0x01, 0x00, 0x00, 0x00);
    EQ(urrt_co_rpdo_status(&co, 1, 200000), URRT_CO_RPDO_FRESH);
    /* NMT: pre-operational and stopped are silence; back in OPERATIONAL, no data until the next. */
    nmt(0x80, NODE, 210000);
    EQ(urrt_co_rpdo_status(&co, 1, 210000), URRT_CO_RPDO_NOT_OPERATIONAL);
    nmt(0x02, NODE, 220000);
    EQ(urrt_co_rpdo_status(&co, 1, 220000), URRT_CO_RPDO_NOT_OPERATIONAL);
    nmt(0x01, NODE, 230000);
    EQ(urrt_co_rpdo_status(&co, 1, 230000), URRT_CO_RPDO_NO_DATA);
    RX0(240000, 0x30A, 0x01, 0x00, 0x00, 0x00);
    EQ(urrt_co_rpdo_status(&co, 1, 240000), URRT_CO_RPDO_FRESH);
}

/* Each RPDO's mapping is resolved to its objects where a mapping takes
 * effect (urrt_co_init_rx, a reset, the RPDO made valid), not per frame: the
 * resolution in urrt_co_rpdo_state, a stale one scribbled over while the
 * RPDO is off, made again when the manager switches it on (0x1400+n sub 1,
 * bit 31), and at a reset; the RPDOs then write, check and skip as their
 * mappings say. */
static void expect_resolved(int line)
{
    /* RPDO1: 0x2200 sub 1, 2, 3 (rx_objects[4..6]), 7 bytes; RPDO2: sub 4, a dummy, sub 1, 4 bytes. */
    const urrt_co_rpdo_state *r1 = &rpdo_states[0], *r2 = &rpdo_states[1];
    CHECK(r1->mapped[0] == 4 && r1->mapped[1] == 5 && r1->mapped[2] == 6 && r1->mapped[3] == URRT_CO_UNRESOLVED &&
              r1->bytes == 7,
          "line %d: RPDO1's mapping not resolved", line);
    CHECK(r2->mapped[0] == 7 && r2->mapped[1] == URRT_CO_UNRESOLVED && r2->mapped[2] == 4 && r2->bytes == 4,
          "line %d: RPDO2's mapping not resolved", line);
}

/* What a stale resolution would hold: the wrong objects (a read-only one,
 * the wrong slot), no length. */
static void scribble(urrt_co_rpdo_state *t)
{
    size_t i;
    for (i = 0; i < URRT_CO_RPDO_MAX_MAPPED; i++) {
        t->mapped[i] = 8;
    }
    t->bytes = 0;
}

static void test_rpdo_mapping_resolved(void)
{
    rx_node();
    expect_resolved(__LINE__); /* at urrt_co_init_rx */
    nmt(0x01, NODE, 1000);
    RX0(2000, 0x20A, 0xF4, 0x01, 0x01, 0x78, 0x56, 0x34, 0x12);
    EQ(rx_vars[2], 500);
    EQ(rx_vars[3], 1);
    EQ(rx_vars[4], 0x12345678);
    /* RPDO1 switched off: not received, its resolution scribbled over. */
    SDO(3000, 0x23, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x80);
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    scribble(&rpdo_states[0]);
    RX0(4000, 0x20A, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 500);
    EQ(rx_vars[6], 5); /* 0x2201, read-only, untouched */
    /* Switched on again: resolved again, before any frame. */
    SDO(5000, 0x23, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    expect_resolved(__LINE__);
    RX0(6000, 0x20A, 0x18, 0xFC, 0x00, 0x01, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 0xFC18); /* -1000 */
    EQ(rx_vars[3], 0);
    EQ(rx_vars[4], 1);
    EQ(rx_vars[6], 5);
    EQ(written[2], 6000);
    EQ(written[6], URRT_CANTX_NEVER);
    /* Its objects' ranges, not another's: 1001 and a BOOLEAN 2 refused. */
    EQ(co.values_refused, 0);
    RX0(7000, 0x20A, 0xE9, 0x03, 0x02, 0x07, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 0xFC18);
    EQ(rx_vars[3], 0);
    EQ(rx_vars[4], 7);
    EQ(co.values_refused, 2);
    /* Its length: one byte short is not processed (an EMCY follows from the run). */
    RX0(8000, 0x20A, 0x05, 0x00, 0x01, 0x09, 0x00, 0x00);
    EQ(rx_vars[4], 7);
    EQ(run(8000), 1);
    EXPECT(0, 0x08A, 0x10, 0x82, 0x11, 0x00, 0x00, 0x01, 0x00, 0x00);
    /* Switched off and on with a new id in the off write (python-canopen's
     * way): resolved, received on the new id only. */
    SDO(9000, 0x23, 0x00, 0x14, 0x01, 0x0B, 0x02, 0x00, 0x80);
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    scribble(&rpdo_states[0]);
    SDO(9000, 0x23, 0x00, 0x14, 0x01, 0x0B, 0x02, 0x00, 0x00);
    ANSWER(0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    expect_resolved(__LINE__);
    RX0(10000, 0x20A, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 0xFC18);
    RX0(10000, 0x20B, 0x03, 0x00, 0x01, 0x0A, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 3);
    EQ(rx_vars[3], 1);
    EQ(rx_vars[4], 10);
    /* A write that leaves it valid (its type) resolves nothing again, and needs not. */
    SDO(11000, 0x2F, 0x00, 0x14, 0x02, 0xFE, 0, 0, 0);
    ANSWER(0x60, 0x00, 0x14, 0x02, 0, 0, 0, 0);
    expect_resolved(__LINE__);
    /* Reset communication: both resolved again with the defaults. */
    scribble(&rpdo_states[0]);
    scribble(&rpdo_states[1]);
    nmt(0x82, NODE, 12000);
    expect_resolved(__LINE__);
    nmt(0x01, NODE, 13000);
    RX0(14000, 0x30A, 0x9C, 0xAA, 0x10, 0x00); /* RPDO2, type 0: at the next SYNC; the dummy byte skipped */
    EQ(rx(0x080, NULL, 0, 15000), 0);
    EQ(rx_vars[5], 0x9C);
    EQ(rx_vars[2], 0x10);
    RX0(16000, 0x20A, 0x04, 0x00, 0x00, 0x0B, 0x00, 0x00, 0x00); /* RPDO1 back on 0x20A */
    EQ(rx_vars[2], 4);
    EQ(rx_vars[4], 11);
    /* An object it could not resolve (one past the description's first 65535,
     * as none here is): found by a scan at each frame, the same values. */
    rpdo_states[0].mapped[0] = rpdo_states[0].mapped[2] = URRT_CO_UNRESOLVED;
    RX0(17000, 0x20A, 0x18, 0xFC, 0x01, 0x0C, 0x00, 0x00, 0x00);
    EQ(rx_vars[2], 0xFC18);
    EQ(rx_vars[3], 1);
    EQ(rx_vars[4], 12);
    RX0(18000, 0x20A, 0x17, 0xFC, 0x00, 0x0D, 0x00, 0x00, 0x00); /* -1001: its own range still */
    EQ(rx_vars[2], 0xFC18);
    EQ(rx_vars[4], 13);
    EQ(co.values_refused, 3);
}

/* ---- robustness ----------------------------------------------------------------------- */

static bool state_known(void)
{
    urrt_co_nmt s = urrt_co_state(&co);
    return s == URRT_CO_PRE_OPERATIONAL || s == URRT_CO_OPERATIONAL || s == URRT_CO_STOPPED;
}

static bool sdo_command_valid(uint8_t cmd)
{
    uint8_t cs = cmd >> 5;
    return cmd == 0x80 || cmd == 0x60 || cmd == 0x41 || (cs == 2 && (cmd & 0x13) == 0x03) ||
           (cs == 0 && (cmd & 0xE0) == 0);
}

/* Every frame out is one the node may send, at its ids. */
static void check_outputs(const char *what)
{
    size_t i;
    for (i = 0; i < out_count && i < MAX_OUT; i++) {
        const urrt_can_frame *f = &out[i];
        bool ok = f->len <= 8 && !f->extended && !f->fd;
        if (f->id == 0x58A) {
            ok = ok && f->len == 8 && sdo_command_valid(f->data[0]);
        } else if (f->id == 0x70A) {
            ok = ok && f->len == 1 && (f->data[0] == 0 || f->data[0] == 4 || f->data[0] == 5 || f->data[0] == 0x7F);
        }
        CHECK(ok, "%s: frame 0x%03X len %u byte0 0x%02X", what, (unsigned)f->id, f->len, f->data[0]);
    }
}

static void test_lengths(void)
{
    static const uint32_t ids[] = {0x000, 0x080, 0x08A, 0x18A, 0x58A, 0x60A, 0x70A, 0x7FF};
    uint8_t data[8];
    size_t i;
    unsigned len;
    unsigned fill;
    desc_defaults();
    setup();
    for (fill = 0; fill < 256; fill += 17) {
        memset(data, (int)fill, sizeof data);
        for (i = 0; i < sizeof ids / sizeof ids[0]; i++) {
            for (len = 0; len <= 8; len++) {
                size_t n = rx(ids[i], data, len, 1000 + fill);
                CHECK(n <= 2 && n == out_count, "id 0x%03X len %u: %zu frames", (unsigned)ids[i], len, n);
                check_outputs("lengths");
                CHECK(state_known(), "state after id 0x%03X len %u", (unsigned)ids[i], len);
                EQ(urrt_co_on_frame(&co, ids[i], URRT_CO_RX_RTR, data, len, 1000, capture, NULL), 0);
            }
            EQ(urrt_co_on_frame(&co, ids[i], 0, data, 9, 1000, capture, NULL), 0);
        }
        if (urrt_co_state(&co) == URRT_CO_STOPPED) {
            nmt(0x80, 0, 1000);
        }
    }
}

/* 0..n-1 from tests/testutil.h's sequence, the one every test shares. */
static unsigned pick(unsigned n)
{
    return (unsigned)(test_rng() % n);
}

/* Every core takes them all: the emulated Cortex-M0 (soft-float, no divide) in well under a second. */
#define RANDOM_FRAMES 100000u

static void test_random(void)
{
    static const uint32_t ids[] = {0x000, 0x080, 0x081, 0x60A, 0x60B, 0x18A};
    uint64_t now = 0;
    unsigned i;
    unsigned bad = 0;
    desc_defaults();
    setup();
    test_rng_seed(20261122);
    for (i = 0; i < RANDOM_FRAMES; i++) {
        uint8_t data[8];
        unsigned k;
        unsigned len = pick(9);
        uint32_t id = ids[pick(6)];
        size_t n;
        for (k = 0; k < 8; k++) {
            data[k] = (uint8_t)test_rng();
        }
        if (id == 0x60A && pick(2) == 0) {
            /* Keep the SDO server on its interesting paths: objects that exist. */
            static const uint8_t cmds[] = {0x40, 0x60, 0x70, 0x2B, 0x2F, 0x23, 0x80, 0x22};
            static const uint16_t idx[] = {0x1008, 0x1800, 0x1801, 0x1017, 0x1003, 0x2100, 0x2000, 0x1A00};
            uint16_t index = idx[pick(8)];
            data[0] = cmds[pick(8)];
            data[1] = (uint8_t)(index & 0xFF);
            data[2] = (uint8_t)(index >> 8);
            data[3] = (uint8_t)pick(7);
            len = 8;
        }
        if (id == 0 && len == 2 && data[0] >= 0x81 && pick(4) != 0) {
            data[0] = 0x01; /* resets less often: the node spends time in every state */
        }
        now += pick(20000);
        if (pick(8) == 0) {
            packet(now, (double)pick(3000) / 1000.0, 7);
        }
        n = rx(id, data, len, now);
        bad += n > 2u;
        check_outputs("random frame");
        n = run(now);
        bad += n > 2u + 1u + URRT_CO_CONDITIONS + 2u;
        check_outputs("random run");
        bad += !state_known();
        bad += urrt_co_deadline(&co) <= now; /* a run leaves nothing due: no busy loop */
    }
    EQ(bad, 0);
}

/* Every frame of 0..8 bytes on the receiving side's ids, and random ones, on
 * the node with RPDOs: the invariants of test_lengths and test_random. */
static void test_rx_robustness(void)
{
    static const uint32_t ids[] = {0x20A, 0x30A, 0x701, 0x702, 0x080, 0x000};
    uint64_t now = 0;
    unsigned bad = 0;
    unsigned i;
    co_fixture_rx_desc(&desc);
    setup_rx();
    nmt(0x01, NODE, 0);
    test_rng_seed(20260107);
    for (i = 0; i < RANDOM_FRAMES / 2u; i++) {
        uint8_t data[8];
        unsigned k;
        unsigned len = pick(9);
        uint32_t id = pick(4) == 0 ? 0x60A : ids[pick(6)];
        size_t n;
        for (k = 0; k < 8; k++) {
            data[k] = (uint8_t)test_rng();
        }
        if (id == 0x60A) {
            /* SDO requests to the receiving side's objects. */
            static const uint8_t cmds[] = {0x40, 0x2B, 0x2F, 0x23, 0x22};
            static const uint16_t idx[] = {0x1400, 0x1401, 0x1402, 0x1600, 0x1601, 0x1016, 0x2200, 0x2201};
            uint16_t index = idx[pick(8)];
            data[0] = cmds[pick(5)];
            data[1] = (uint8_t)(index & 0xFF);
            data[2] = (uint8_t)(index >> 8);
            data[3] = (uint8_t)pick(7);
            data[7] = (uint8_t)(data[7] & (pick(2) != 0 ? 0x00 : 0x80)); /* COB-IDs valid or not */
            len = 8;
        }
        if (id == 0 && len == 2 && data[0] >= 0x81 && pick(4) != 0) {
            data[0] = 0x01;
        }
        now += pick(20000);
        n = rx(id, data, len, now);
        bad += n > 2u;
        check_outputs("random receiving-side frame");
        n = run(now);
        bad += n > 2u + 1u + URRT_CO_CONDITIONS + URRT_CO_RX_CONDITIONS + 2u;
        check_outputs("random receiving-side run");
        bad += !state_known();
        bad += urrt_co_deadline(&co) <= now;
        bad += urrt_co_rpdo_status(&co, 0, now) > URRT_CO_RPDO_DEADLINE;
    }
    EQ(bad, 0);
}

int main(void)
{
    test_init();
    test_nmt();
    test_heartbeat();
    test_sdo_upload();
    test_sdo_segmented();
    test_sdo_aborts();
    test_sdo_download();
    test_tpdo_gating();
    test_sync();
    test_rx_ids();
    test_inhibit_time();
    test_event_timer_zero();
    test_cob_move();
    test_abort_order();
    test_comm_table();
    test_emcy();
    test_lengths();
    test_random();
    test_rx_init();
    test_rx_sdo_reads();
    test_comm_readers();
    test_rx_strerror();
    test_rx_sdo_writes();
    test_rpdo_processing();
    test_rpdo_deadline();
    test_rpdo_deadline_write();
    test_consumer_heartbeat();
    test_consumer_write();
    test_rpdo_status();
    test_rpdo_mapping_resolved();
    test_rx_robustness();
    return check_report();
}
