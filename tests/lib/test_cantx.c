/* SPDX-License-Identifier: MIT */
/*
 * check-cantx: lib/urrt_cantx.h, the CAN core, on its own: the checks of
 * urrt_cantx_init (one table per error), and the schedule on a fake clock
 * with payloads worked out by hand from the bit positions below (not by
 * urrt_can's packing). The same file runs on the host and, without a C
 * library, on the emulated Cortex-M cores (check-lib-m4).
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt.h"
#include "urrt_can.h"
#include "urrt_cantx.h"

#ifdef URRT_TARGET_CORTEX_M
#include "target.h"
#define say target_puts
#define say_uint target_put_uint
#else
#include <stdio.h>
static void say(const char *s)
{
    fputs(s, stdout);
}
static void say_uint(uint64_t v)
{
    printf("%llu", (unsigned long long)v);
}
#endif

static unsigned passed, failed;

/* Struct copies by hand: without a C library there is no memcpy to call. */
static void copy_bytes(void *dst, const void *src, size_t n)
{
    uint8_t *d = dst;
    const uint8_t *s = src;
    while (n-- > 0) {
        *d++ = *s++;
    }
}

static void check_at(bool ok, int line, const char *what, uint64_t got, uint64_t want)
{
    if (ok) {
        passed++;
        return;
    }
    failed++;
    say("FAIL: test_cantx.c:");
    say_uint((uint64_t)line);
    say(": ");
    say(what);
    say(": got ");
    say_uint(got);
    say(", want ");
    say_uint(want);
    say("\n");
}
static void check_eq(uint64_t got, uint64_t want, int line, const char *what)
{
    check_at(got == want, line, what, got, want);
}
#define CHECK_EQ(got, want, what) check_eq((uint64_t)(got), (uint64_t)(want), __LINE__, (what))

/* ---- the tables under test -------------------------------------------------------
 * 0x181, every packet, 8 bytes:  q_actual[0] in bits 0..15 (Intel, signed,
 *        0.001 rad), alive counter bits 56..59, validity bit 60.
 * 0x182, every 10 ms, 4 bytes, invalid policy: robot_mode bits 0..7 (signed),
 *        digital inputs as a mask bits 8..23, validity bit 31.
 * 0x701, heartbeat every 100 ms: urrt_cantx_heartbeat_signals (docs/can.md).
 * Data is stale after 50 ms everywhere. */

#define SIG(start, length, type, factor, min, max) {(factor), 0.0, (min), (max), 0, (start), (length), URRT_CAN_INTEL, (type), 0}

static urrt_can_signal sigs_a[3] = {
    SIG(0, 16, URRT_CAN_SIGNED, 0.001, -32.768, 32.767),
    SIG(56, 4, URRT_CAN_UNSIGNED, 1, 0, 15),
    SIG(60, 1, URRT_CAN_UNSIGNED, 1, 0, 1),
};
static urrt_cantx_source srcs_a[3] = {
    {URRT_CANTX_FIELD, URRT_F_Q_ACTUAL, 0},
    {URRT_CANTX_ALIVE, 0, 0},
    {URRT_CANTX_VALID, 0, 0},
};
/* A bit mask carrying the mask's bits from `first` (urrt_can.h). */
#define MASK_SIG(start, length, first) \
    {1.0, 0.0, 0.0, 0.0, 0, (start), (length), URRT_CAN_INTEL, URRT_CAN_UNSIGNED, URRT_CAN_SIG_MASK(first)}

static const urrt_can_signal sigs_b[3] = {
    SIG(0, 8, URRT_CAN_SIGNED, 1, -128, 127),
    MASK_SIG(8, 16, 0),
    SIG(31, 1, URRT_CAN_UNSIGNED, 1, 0, 1),
};
static const urrt_cantx_source srcs_b[3] = {
    {URRT_CANTX_FIELD, URRT_F_ROBOT_MODE, 0},
    {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_INPUT_BITS, 0},
    {URRT_CANTX_VALID, 0, 0},
};

#define STALE_US 50000u
static urrt_cantx_frame frames[3];
static urrt_cantx_tables tables;
static urrt_cantx_frame_state states[3];
static urrt_cantx_robot robots[1];
static double values[32];
static urrt_cantx tx;

static void reset_tables(void)
{
    const urrt_cantx_frame a = {sigs_a, srcs_a, 3, 8, 0, 0x181, URRT_CANTX_EVERY_PACKET, STALE_US,
                                URRT_CANTX_STALE_STOP, 0, NULL};
    const urrt_cantx_frame b = {sigs_b, srcs_b, 3, 4, 0, 0x182, 10000, STALE_US, URRT_CANTX_STALE_INVALID, 0, NULL};
    const urrt_cantx_frame hb = {urrt_cantx_heartbeat_signals, urrt_cantx_heartbeat_sources, URRT_CANTX_HB_COUNT,
                                 URRT_CANTX_HB_LEN, 0, 0x701, 100000, STALE_US, URRT_CANTX_STALE_IGNORE, 0,
                                 urrt_cantx_heartbeat_fill};
    copy_bytes(&frames[0], &a, sizeof a);
    copy_bytes(&frames[1], &b, sizeof b);
    copy_bytes(&frames[2], &hb, sizeof hb);
    sigs_a[0].start = 0;
    sigs_a[1].start = 56;
    sigs_a[1].length = 4;
    srcs_a[0].kind = URRT_CANTX_FIELD;
    srcs_a[0].elem = 0;
    srcs_a[2].kind = URRT_CANTX_VALID;
    tables.frames = frames;
    tables.frame_count = 3;
    tables.robot_count = 1;
    tables.startup_us = 5000000;
}

static int init(size_t *bad_frame, size_t *bad_signal)
{
    return urrt_cantx_init(&tx, &tables, states, robots, values, sizeof values / sizeof values[0], bad_frame,
                           bad_signal);
}

/* ---- init: each check once -------------------------------------------------------- */

static void expect_refused(int want, size_t want_frame, size_t want_signal, const char *what)
{
    size_t bad_frame = 0;
    size_t bad_signal = 0;
    int rc = init(&bad_frame, &bad_signal);
    CHECK_EQ(-rc, -want, what);
    CHECK_EQ(bad_frame, want_frame, what);
    CHECK_EQ(bad_signal, want_signal, what);
    reset_tables();
}

static void test_init(void)
{
    size_t bad_frame = 0;
    size_t bad_signal = 0;
    reset_tables();
    CHECK_EQ(urrt_cantx_value_count(&tables), 3 + 3 + URRT_CANTX_HB_COUNT, "value count");
    CHECK_EQ(init(&bad_frame, &bad_signal), 0, "valid tables");
    CHECK_EQ(bad_frame, SIZE_MAX, "no bad frame");
    CHECK_EQ(states[1].first_value, 3, "frame 1's values follow frame 0's");
    robots[0].has_data = true; /* what a reused or uninitialised array might hold */
    robots[0].up = true;
    CHECK_EQ(init(NULL, NULL), 0, "init again");
    CHECK_EQ(urrt_cantx_gateway_state(&tx, 2, 0), URRT_CANTX_DISCONNECTED, "before start: no data, no link");
    CHECK_EQ(urrt_cantx_fresh(&tx, 0, 0, STALE_US), 0, "before start: nothing is fresh");

    frames[1].id = 0x800;
    expect_refused(URRT_CAN_E_ID, 1, SIZE_MAX, "11-bit id above 0x7FF");
    frames[1].len = 9;
    expect_refused(URRT_CAN_E_FRAME_LENGTH, 1, SIZE_MAX, "9 bytes without FD");
    frames[1].flags = URRT_CANTX_FD;
    frames[1].len = 12;
    CHECK_EQ(init(NULL, NULL), 0, "12 bytes with FD");
    reset_tables();
    sigs_a[0].start = 48;
    expect_refused(URRT_CAN_E_OVERLAP, 0, 1, "q0 over the alive counter");
    srcs_a[0].elem = 6;
    expect_refused(URRT_CANTX_E_SOURCE, 0, 0, "q_actual has 6 elements");
    sigs_a[1].start = 40;
    sigs_a[1].length = 8;
    CHECK_EQ(init(NULL, NULL), 0, "an alive counter of 8 bits");
    sigs_a[1].length = 9;
    expect_refused(URRT_CANTX_E_SOURCE, 0, 1, "an alive counter of 9 bits");
    srcs_a[0].kind = URRT_CANTX_VALID;
    expect_refused(URRT_CANTX_E_SOURCE, 0, 0, "a validity bit of 16 bits");
    srcs_a[2].kind = 9;
    expect_refused(URRT_CANTX_E_SOURCE, 0, 2, "an unknown source kind");
    frames[2].fill = NULL;
    expect_refused(URRT_CANTX_E_SOURCE, 2, 0, "filled values without a fill function");
    frames[1].robot = 1;
    expect_refused(URRT_CANTX_E_ROBOT, 1, SIZE_MAX, "robot 1 of 1");
    frames[1].signal_count = 2;
    expect_refused(URRT_CANTX_E_POLICY, 1, SIZE_MAX, "invalid policy without a validity bit");
    frames[0].stale = URRT_CANTX_STALE_INVALID;
    expect_refused(URRT_CANTX_E_POLICY, 0, SIZE_MAX, "invalid policy on a frame sent per packet");
    frames[0].stale = 7;
    expect_refused(URRT_CANTX_E_POLICY, 0, SIZE_MAX, "unknown policy");
    frames[2].id = 0x181;
    expect_refused(URRT_CANTX_E_DUPLICATE, 2, SIZE_MAX, "two frames with id 0x181");
    frames[2].id = 0x181;
    frames[2].flags = URRT_CANTX_EXTENDED;
    CHECK_EQ(init(NULL, NULL), 0, "0x181 as a 29-bit id is another frame");
    reset_tables();
    CHECK_EQ(-urrt_cantx_init(&tx, &tables, states, robots, values, 18, NULL, NULL), -URRT_CANTX_E_STORAGE,
             "values[] one short");
    tables.robot_count = 0;
    expect_refused(URRT_E_ARG, SIZE_MAX, SIZE_MAX, "no robot");
}

/* ---- the schedule ----------------------------------------------------------------- */

#define MAX_OUT 64
static urrt_can_frame out[MAX_OUT];
static uint64_t out_at[MAX_OUT];
static size_t out_count;

static void capture(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)ctx;
    if (out_count < MAX_OUT) {
        copy_bytes(&out[out_count], f, sizeof *f);
        out_at[out_count] = now_us;
    }
    out_count++;
}

static size_t run(uint64_t now_us)
{
    out_count = 0;
    return urrt_cantx_run(&tx, now_us, capture, NULL);
}

static void packet(uint64_t data_us, double q0, double mode, double din)
{
    urrt_state st;
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    st.q_actual[0] = q0;
    st.robot_mode[0] = mode;
    st.safety_mode[0] = 1;
    st.digital_input_bits[0] = din;
    st.present = (UINT64_C(1) << URRT_F_Q_ACTUAL) | (UINT64_C(1) << URRT_F_ROBOT_MODE) |
                 (UINT64_C(1) << URRT_F_SAFETY_MODE) | (UINT64_C(1) << URRT_F_DIGITAL_INPUT_BITS);
    urrt_cantx_on_packet(&tx, 0, &st, data_us);
}

/* The frame's id, length and payload against the expected bytes. */
static void expect_frame(const urrt_can_frame *f, uint32_t id, const uint8_t *bytes, unsigned len, const char *what)
{
    unsigned i;
    uint64_t got = 0;
    uint64_t want = 0;
    CHECK_EQ(f->id, id, what);
    CHECK_EQ(f->len, len, what);
    for (i = 0; i < len; i++) {
        got = got << 8 | f->data[i];
        want = want << 8 | bytes[i];
    }
    CHECK_EQ(got, want, what);
}

static void test_schedule(void)
{
    static const uint8_t b_start[4] = {0, 0, 0, 0};
    static const uint8_t hb_start[8] = {0x00, 0x80, 0x00, 0x00, 0xFF, 0xFF, 0x00, 0x00};
    static const uint8_t a1[8] = {0xDC, 0x05, 0, 0, 0, 0, 0, 0x10};
    static const uint8_t a2[8] = {0xFF, 0xFF, 0, 0, 0, 0, 0, 0x11};
    static const uint8_t b_fresh[4] = {0x07, 0x05, 0x00, 0x80};
    static const uint8_t hb_ok[8] = {0x11, 0x07, 0x01, 0x03, 38, 0x00, 0x00, 0x00};
    static const uint8_t b_stale[4] = {0x07, 0x05, 0x00, 0x00};
    static const uint8_t hb_stale[8] = {0x12, 0x80, 0x00, 0x03, 98, 0x00, 0x00, 0x00};
    urrt_can_frame peeked;

    reset_tables();
    CHECK_EQ(init(NULL, NULL), 0, "init");
    CHECK_EQ(urrt_cantx_deadline(&tx), URRT_CANTX_NEVER, "no deadline before start");
    urrt_cantx_start(&tx, 0);
    CHECK_EQ(urrt_cantx_deadline(&tx), 0, "the invalid-policy frame and the heartbeat are due at start");
    CHECK_EQ(run(0), 2, "two frames at start");
    expect_frame(&out[0], 0x182, b_start, 4, "0x182 before data: values of physical 0, invalid");
    expect_frame(&out[1], 0x701, hb_start, 8, "heartbeat: starting, modes and age not available");
    CHECK_EQ(urrt_cantx_gateway_state(&tx, 2, 0), URRT_CANTX_STARTING, "starting");
    CHECK_EQ(urrt_cantx_deadline(&tx), 10000, "0x182 next, at its period");

    packet(1000, 1.5, 7, 5.0);
    CHECK_EQ(urrt_cantx_deadline(&tx), 0, "a packet makes 0x181 due now");
    CHECK_EQ(run(1000), 1, "one frame per packet");
    expect_frame(&out[0], 0x181, a1, 8, "0x181: q0 1500 mrad, alive 0, valid");
    CHECK_EQ(out_at[0], 1000, "emit gets the time");
    CHECK_EQ(run(1500), 0, "no packet, nothing due");
    packet(2000, -0.001, 7, 5.0);
    run(2000);
    expect_frame(&out[0], 0x181, a2, 8, "0x181: q0 -1 mrad, alive 1, valid");

    CHECK_EQ(run(10000), 1, "0x182 at its period");
    expect_frame(&out[0], 0x182, b_fresh, 4, "0x182: mode 7, inputs 5 as a mask, valid");
    urrt_cantx_peek(&tx, 2, 40000, &peeked);
    expect_frame(&peeked, 0x701, hb_ok, 8, "heartbeat peeked: ok, alive 1, mode 7, safety 1, 3.x, 38 ms");
    urrt_cantx_peek(&tx, 2, 40000, &peeked);
    expect_frame(&peeked, 0x701, hb_ok, 8, "peeking twice changes nothing");
    CHECK_EQ(tx.frames[2].sent, 1, "peek sends nothing");

    CHECK_EQ(run(100000), 2, "0x182 and the heartbeat at 100 ms");
    CHECK_EQ(out[0].id, 0x182, "0x182 first: table order");
    expect_frame(&out[0], 0x182, b_stale, 4, "0x182 on stale data: invalid, values kept");
    expect_frame(&out[1], 0x701, hb_stale, 8, "heartbeat: data stale, modes not available, 98 ms");
    CHECK_EQ(tx.frames[1].sent_invalid, 2, "0x182 sent invalid twice (at start, and stale)");

    packet(100000, 0, 7, 5.0);
    CHECK_EQ(run(200000), 2, "a packet 100 ms old when the CAN link could send: 0x181 dropped");
    CHECK_EQ(out[0].id, 0x182, "0x182 and the heartbeat went out, not 0x181");
    CHECK_EQ(tx.frames[0].stale_stops, 1, "the dropped packet is counted");
    CHECK_EQ(tx.frames[0].sent, 2, "0x181 sent twice in all");

    urrt_cantx_robot_link(&tx, 0, false);
    CHECK_EQ(urrt_cantx_gateway_state(&tx, 2, 200000), URRT_CANTX_DISCONNECTED, "link down: disconnected");
}

static void test_stop_policy_and_flags(void)
{
    static urrt_cantx_link link; /* static: zeroed without a memset call */
    unsigned i;
    reset_tables();
    frames[1].stale = URRT_CANTX_STALE_STOP;
    CHECK_EQ(init(NULL, NULL), 0, "init");
    urrt_cantx_start(&tx, 0);
    run(0);
    CHECK_EQ(out_count, 1, "the stop-policy frame waits for data: only the heartbeat");
    packet(5000, 0, 7, 5.0);
    CHECK_EQ(urrt_cantx_deadline(&tx), 0, "fresh data");
    CHECK_EQ(run(5000), 2, "0x181 and 0x182 at once");
    CHECK_EQ(run(15000), 1, "0x182 ten ms later");
    CHECK_EQ(run(60000), 0, "at 55 ms the data is 55 ms old: 0x182 stops");
    CHECK_EQ(tx.frames[1].stale_stops, 1, "counted");
    CHECK_EQ(urrt_cantx_deadline(&tx), 100000, "only the heartbeat is scheduled");
    packet(70000, 0, 7, 5.0);
    CHECK_EQ(run(70000), 2, "fresh data: 0x182 resumes at once");

    /* Alive counter: 4 bits wrap after 16 frames. */
    for (i = 0; i < 15; i++) {
        packet(71000 + i, 0, 7, 5.0);
        run(71000 + i);
    }
    CHECK_EQ(out[0].data[7] & 0x0Fu, 0, "alive counter wrapped to 0 on the 17th frame");

    /* Link flags and clamping reach the next heartbeat once. */
    link.bus_off = 1;
    urrt_cantx_set_link(&tx, &link);
    packet(90000, 100.0, 7, 5.0);
    run(90000);
    CHECK_EQ(out[0].data[7] >> 4 & 1u, 0, "a clamped value clears the validity bit");
    CHECK_EQ(out[0].data[0] | out[0].data[1] << 8, 0x7FFF, "q0 saturated at 32.767 rad");
    CHECK_EQ(tx.clamped, 1, "one clamped value");
    run(100000);
    CHECK_EQ(out[out_count - 1].id, 0x701, "heartbeat");
    CHECK_EQ(out[out_count - 1].data[3], 0x80 | 0x04 | 0x03, "clamped and bus-off flags, 3.x");
    run(200000);
    CHECK_EQ(out[out_count - 1].data[3] & 0xFCu, 0, "flags clear in the next heartbeat");
}

static void test_stall(void)
{
    reset_tables();
    CHECK_EQ(init(NULL, NULL), 0, "init");
    urrt_cantx_start(&tx, 0);
    run(0);
    packet(1000, 0, 7, 5.0);
    run(1000);
    /* The loop stalls 35 ms: one 0x182, not three, then the cadence. */
    CHECK_EQ(run(35000), 1, "one frame after a stall");
    CHECK_EQ(urrt_cantx_deadline(&tx), 45000, "then every 10 ms from the late one");
}

/* A replay's clock jumps from packet to packet: catch_up sends what a loop
 * waking at every deadline would have, each at its own time. */
static void test_catch_up(void)
{
    reset_tables();
    CHECK_EQ(init(NULL, NULL), 0, "init");
    CHECK_EQ(urrt_cantx_catch_up(&tx, 50000, capture, NULL), 0, "nothing before start");
    packet(1000, 0, 7, 5.0);
    run(1000);
    out_count = 0;
    CHECK_EQ(urrt_cantx_catch_up(&tx, 41000, capture, NULL), 3, "0x182 at 11, 21 and 31 ms: before 41");
    CHECK_EQ(out_at[0], 11000, "the first at its due time");
    CHECK_EQ(out_at[2], 31000, "the third at its due time");
    CHECK_EQ(out[0].id == 0x182 && out[1].id == 0x182 && out[2].id == 0x182, 1, "all of them 0x182");
    CHECK_EQ(urrt_cantx_deadline(&tx), 41000, "41 ms is left for the caller's run");
    out_count = 0;
    urrt_cantx_catch_up(&tx, 200000, capture, NULL);
    CHECK_EQ(out[out_count - 1].id, 0x182, "0x182 goes on (invalid) to 191 ms");
    CHECK_EQ(out_at[out_count - 1], 191000, "the last before 200 ms");
}

/* The run-time changes a CANopen node makes (urrt_co.h): gate, id, period, trigger. */
static void test_run_time_changes(void)
{
    static const uint8_t b_fresh[4] = {0x07, 0x05, 0x00, 0x80};
    reset_tables();
    CHECK_EQ(init(NULL, NULL), 0, "init");
    urrt_cantx_start(&tx, 0);
    run(0);
    packet(1000, 1.5, 7, 5.0);
    urrt_cantx_gate(&tx, 0, false);
    urrt_cantx_gate(&tx, 1, false);
    CHECK_EQ(run(1000), 0, "closed: the packet's frame is not sent");
    CHECK_EQ(run(10000), 0, "closed: the periodic slot passes");
    CHECK_EQ(urrt_cantx_deadline(&tx), 20000, "the cadence holds while closed");
    urrt_cantx_gate(&tx, 1, true);
    CHECK_EQ(run(20000), 1, "open again: at its slot");
    expect_frame(&out[0], 0x182, b_fresh, 4, "0x182 as before: alive and values kept");
    CHECK_EQ(urrt_cantx_trigger(&tx, 0, 21000, capture, NULL), 1, "a trigger sends a closed frame");
    CHECK_EQ(urrt_cantx_trigger(&tx, 0, 60000, capture, NULL), 0, "not on stale data with the stop policy");
    CHECK_EQ(tx.frames[0].stale_stops, 1, "counted as a stale stop");
    out_count = 0;
    CHECK_EQ(urrt_cantx_trigger(&tx, 1, 60000, capture, NULL), 1, "invalid policy: sent on stale data");
    CHECK_EQ(out[0].data[3] >> 7, 0, "with the validity bit cleared");

    CHECK_EQ(urrt_cantx_set_id(&tx, 1, 0x1FF), 0, "a new id");
    CHECK_EQ(urrt_cantx_set_id(&tx, 1, 0x800), URRT_CAN_E_ID, "not an 11-bit id");
    CHECK_EQ(urrt_cantx_set_period(&tx, 1, 25000, 61000), 0, "a new period, due now");
    CHECK_EQ(urrt_cantx_set_period(&tx, 1, URRT_CANTX_EVERY_PACKET, 61000), URRT_CANTX_E_POLICY,
             "per packet needs the stop policy");
    CHECK_EQ(urrt_cantx_deadline(&tx), 61000, "due at the change");
    CHECK_EQ(run(61000), 1, "sent");
    CHECK_EQ(out[0].id, 0x1FF, "at the new id");
    CHECK_EQ(urrt_cantx_deadline(&tx), 86000, "then every 25 ms");

    /* The per-packet frame made periodic waits for data, then keeps its period. */
    urrt_cantx_gate(&tx, 0, true);
    CHECK_EQ(urrt_cantx_set_period(&tx, 0, 5000, 87000), 0, "0x181 every 5 ms");
    packet(87000, 0, 7, 5.0);
    CHECK_EQ(run(87000), 2, "0x181 with fresh data, and 0x182 at its slot of 86 ms");
    CHECK_EQ(out[0].id, 0x181, "0x181 first");
    CHECK_EQ(tx.frames[0].next_due_us, 92000, "next in 5 ms");
    CHECK_EQ(urrt_cantx_set_period(&tx, 0, URRT_CANTX_EVERY_PACKET, 88000), 0, "back to per packet");
    CHECK_EQ(run(92000), 0, "no slot, no packet");
    packet(93000, 0, 7, 5.0);
    CHECK_EQ(run(93000), 1, "one per packet again");
    urrt_cantx_start(&tx, 100000);
    CHECK_EQ(tx.frames[1].period_us, 25000, "start keeps the period set");
    CHECK_EQ(tx.frames[1].frame.id, 0x1FF, "and the id");
    CHECK_EQ(urrt_cantx_robot_state(&tx, 0, 100000, STALE_US), URRT_CANTX_STARTING, "robot state: starting");
}

/* ---- bit masks ----------------------------------------------------------------------
 * 0x190, every packet, 8 bytes: the digital inputs' bits 0-15 in bits 0..15
 * (a 16-bit signal, as docs/examples/canopen.ini maps them), their tool
 * bits 16-17 in bits 16..17, the digital outputs' 18 bits in bits 24..41,
 * input bit 17 alone in bit 42, the validity bit 63. */

static urrt_can_signal sigs_m[5] = {
    MASK_SIG(0, 16, 0), MASK_SIG(16, 2, 16), MASK_SIG(24, 18, 0), MASK_SIG(42, 1, 17),
    SIG(63, 1, URRT_CAN_UNSIGNED, 1, 0, 1),
};
static urrt_cantx_source srcs_m[5] = {
    {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_INPUT_BITS, 0}, {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_INPUT_BITS, 0},
    {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_OUTPUTS, 0},    {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_INPUT_BITS, 0},
    {URRT_CANTX_VALID, 0, 0},
};

static int init_masks(void)
{
    const urrt_cantx_frame m = {sigs_m, srcs_m, 5, 8, 0, 0x190, URRT_CANTX_EVERY_PACKET, STALE_US,
                                URRT_CANTX_STALE_STOP, 0, NULL};
    copy_bytes(&frames[0], &m, sizeof m);
    tables.frames = frames;
    tables.frame_count = 1;
    tables.robot_count = 1;
    tables.startup_us = 0;
    return init(NULL, NULL);
}

static void mask_packet(uint64_t at_us, double din, double dout)
{
    urrt_state st;
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    st.digital_input_bits[0] = din;
    st.digital_outputs[0] = dout;
    st.present = (UINT64_C(1) << URRT_F_DIGITAL_INPUT_BITS) | (UINT64_C(1) << URRT_F_DIGITAL_OUTPUTS);
    urrt_cantx_on_packet(&tx, 0, &st, at_us);
}

static uint64_t payload_le(const urrt_can_frame *f)
{
    uint64_t w = 0;
    unsigned i;
    for (i = 0; i < 8; i++) {
        w |= (uint64_t)f->data[i] << (8 * i);
    }
    return w;
}

/* The kind and the descriptor agree, or init refuses the table. */
static void masks_refused(void)
{
    CHECK_EQ(init_masks(), 0, "mask tables");
    srcs_m[2].kind = URRT_CANTX_FIELD;
    CHECK_EQ(-init_masks(), -URRT_CANTX_E_SOURCE, "a field with a bit mask descriptor");
    srcs_m[2].kind = URRT_CANTX_FIELD_MASK;
    sigs_m[2].flags = 0;
    CHECK_EQ(-init_masks(), -URRT_CANTX_E_SOURCE, "a mask field whose signal would be scaled");
    sigs_m[2].flags = URRT_CAN_SIG_MASK(0);
    sigs_m[1].flags = URRT_CAN_SIG_MASK(63);
    CHECK_EQ(-init_masks(), -URRT_CAN_E_SIGNAL, "bits 63..64 are past a mask's 64");
    sigs_m[1].flags = URRT_CAN_SIG_MASK(16);
}

/* Every pattern of the inputs' and outputs' 18 bits (every 251st on the
 * emulated cores, which run slower by a thousand): each signal holds its
 * bits, worked out here; nothing is clamped, the frame stays valid. */
static void masks_every_pattern(void)
{
#ifdef URRT_TARGET_CORTEX_M
    const uint32_t step = 251;
#else
    const uint32_t step = 1;
#endif
    uint32_t p;
    uint32_t bad = 0;
    uint64_t t = 1000;
    CHECK_EQ(init_masks(), 0, "mask tables");
    urrt_cantx_start(&tx, 0);
    for (p = 0; p < (UINT32_C(1) << 18); p += step, t += 1000) {
        uint32_t dout = p ^ UINT32_C(0x2A5A5);
        uint64_t want = (p & UINT64_C(0xFFFF)) | (uint64_t)(p >> 16 & 3u) << 16 | (uint64_t)dout << 24 |
                        (uint64_t)(p >> 17 & 1u) << 42 | UINT64_C(1) << 63;
        mask_packet(t, (double)p, (double)dout);
        if ((run(t) != 1 || payload_le(&out[0]) != want) && bad++ < 3) {
            CHECK_EQ(payload_le(&out[0]), want, "the masks' bits");
        }
    }
    CHECK_EQ(bad, 0, "every pattern packed as its bits");
    CHECK_EQ(tx.clamped, 0, "no mask counted as clamped");
    CHECK_EQ(tx.frames[0].sent_invalid, 0, "no frame sent invalid");
}

static void masks_values(void)
{
    union {
        uint64_t u;
        double d;
    } raw_int64 = {UINT64_C(0x10010)};
    CHECK_EQ(init_masks(), 0, "mask tables");
    urrt_cantx_start(&tx, 0);
    mask_packet(1000, 65552.0, 0.0);
    run(1000);
    CHECK_EQ(payload_le(&out[0]), UINT64_C(0x8000000000000000) | UINT64_C(1) << 16 | 0x10,
             "65552: input 4 in the 16-bit signal, tool input 0 in bits 16-17, valid");
    mask_packet(2000, raw_int64.d, 0.0);
    run(2000);
    CHECK_EQ(payload_le(&out[0]), UINT64_C(0x8000000000000000) | UINT64_C(1) << 16 | 0x10,
             "the same mask as a raw int64 read as a double");
    CHECK_EQ(tx.clamped, 0, "nothing clamped");
    mask_packet(3000, -1.0, 3.0);
    run(3000);
    CHECK_EQ(payload_le(&out[0]), UINT64_C(3) << 24, "inputs -1: no mask, no bits, invalid; outputs 3 as they are");
    CHECK_EQ(tx.clamped, 3, "the inputs' three signals counted");
    mask_packet(4000, 65536.5, 9007199254740994.0);
    run(4000);
    CHECK_EQ(payload_le(&out[0]), 0, "a fraction and a value past 2^53 are no masks either");
    CHECK_EQ(tx.clamped, 3 + 4, "all four counted");
}

static void test_masks(void)
{
    masks_refused();
    masks_values();
    masks_every_pattern();
}

/* ---- prepared scales ----------------------------------------------------------------
 * q0 at 0.001 rad: 0.0005 is exactly half of 0.001 (a tie: away from zero);
 * the double nearest 0.0045 is just below 4.5 mrad, though dividing it by
 * 0.001 in double precision rounds to 4.5 (and then to 5). */

static void expect_q0(double q0, uint64_t at_us, uint16_t raw, const char *what)
{
    packet(at_us, q0, 7, 5.0);
    CHECK_EQ(run(at_us), 1, what);
    CHECK_EQ(out[0].id, 0x181, what);
    CHECK_EQ(out[0].data[0] | out[0].data[1] << 8, raw, what);
}

static void expect_q0_exact(void)
{
    expect_q0(0.0005, 1000, 1, "0.5 mrad: a tie, away from zero");
    expect_q0(-0.0005, 2000, 0xFFFF, "-0.5 mrad: a tie, away from zero");
    expect_q0(0.0045, 3000, 4, "the double nearest 4.5 mrad is below it");
    expect_q0(-0.0045, 4000, 0xFFFC, "and its negative");
    expect_q0(32.7675, 5000, 0x7FFF, "above max: clamped to 32.767");
    expect_q0(-1e300, 6000, 0x8000, "clamped below");
}

static void test_prepared_scales(void)
{
    static urrt_can_scale scales[3 + 3 + URRT_CANTX_HB_COUNT];
    reset_tables();
    CHECK_EQ(init(NULL, NULL), 0, "init");
    urrt_cantx_start(&tx, 0);
    run(0); /* the frames due at start */
    expect_q0_exact(); /* each packing prepares its scale */
    CHECK_EQ(-urrt_cantx_prepare(&tx, scales, 3 + 3 + URRT_CANTX_HB_COUNT - 1), -URRT_CANTX_E_STORAGE,
             "scales[] one short");
    CHECK_EQ(tx.scales == NULL, 1, "no scales kept");
    CHECK_EQ(urrt_cantx_prepare(&tx, scales, 3 + 3 + URRT_CANTX_HB_COUNT), 0, "prepared");
    CHECK_EQ(scales[0].divisor, UINT64_C(0x4189374BC6A7F), "0.001 = 0x4189374BC6A7F * 2^-60, odd");
    CHECK_EQ(scales[0].half_exponent, -61, "half of 2^-60");
    CHECK_EQ(scales[1].divisor, 1, "the alive counter's factor 1");
    urrt_cantx_start(&tx, 0);
    run(0);
    expect_q0_exact(); /* the prepared scales: the same bits */
    CHECK_EQ(init(NULL, NULL), 0, "init again");
    CHECK_EQ(tx.scales == NULL, 1, "forgets the scales");
}

int main(void)
{
    test_init();
    test_schedule();
    test_stop_policy_and_flags();
    test_stall();
    test_catch_up();
    test_run_time_changes();
    test_masks();
    test_prepared_scales();
    say_uint(passed);
    say(" passed, ");
    say_uint(failed);
    say(" failed\n");
    return failed == 0 && passed > 0 ? 0 : 1;
}
