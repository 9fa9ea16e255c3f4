/* SPDX-License-Identifier: MIT */
/*
 * test_plcin: lib/urrt_plcin.h's rules on one input of four registers, every
 * expected value worked out by hand in the comments (the payload's fields,
 * the registers' big-endian bytes), not by lib's own arithmetic:
 *   - a payload of another length or kind is not used; the raws of one that is;
 *   - the values taken (scaling, min..max, masks gathered from two signals),
 *     a value refused or absent leaving its register without one;
 *   - when a package is due: nothing before the first write, at once on a
 *     change or a new session, then every period while fresh; the deadline;
 *   - the timeout, and each on_silence policy: stop, hold, value;
 *   - through a CANopen node (tests/lib/co_fixture.h's with RPDOs): an RPDO's
 *     values taken, an SDO write alone, each variable as old as its own write,
 *     and the node's reasons for silence (NMT stop, the RPDO switched off).
 * It runs on the host and, as NAME/plcin.elf, on the Cortex-M boards of
 * make check-lib-m4, where it paints the stack of each urrt_plcin function
 * (tests/target/stack_marks.h).
 */
#include <stdbool.h>
#include <stdint.h>

#include "check.h"
#include "co_fixture.h"
#include "urrt_plcin.h"
#define STACK_MARKS_MAX 12
#include "target/stack_marks.h"

enum { PERIOD_US = 100000, TIMEOUT_MS = 250 };

static const urrt_can_signal signals[] = {
    /* job: bytes 0-1, Intel, unsigned, 0..9999 */
    {.factor = 1, .offset = 0, .min = 0, .max = 9999, .start = 0, .length = 16, .type = URRT_CAN_UNSIGNED},
    /* start: bit 16 */
    {.factor = 1, .offset = 0, .min = 0, .max = 1, .start = 16, .length = 1, .type = URRT_CAN_UNSIGNED},
    /* mask_lo: byte 3's low nibble, the mask's bits 0-3 */
    {.factor = 1, .offset = 0, .min = 0, .max = 15, .start = 24, .length = 4, .type = URRT_CAN_UNSIGNED,
     .flags = URRT_CAN_SIG_MASK(0)},
    /* mask_hi: byte 4, the mask's bits 8-15 */
    {.factor = 1, .offset = 0, .min = 0, .max = 255, .start = 32, .length = 8, .type = URRT_CAN_UNSIGNED,
     .flags = URRT_CAN_SIG_MASK(8)},
    /* speed: bytes 5-6, signed, x 0.01 + 0.5, -100..200 */
    {.factor = 0.01, .offset = 0.5, .min = -100, .max = 200, .start = 40, .length = 16, .type = URRT_CAN_SIGNED},
};
static const uint16_t vars[] = {
    URRT_RTDE_V_INPUT_INT_REGISTER + 24, URRT_RTDE_V_INPUT_BIT_REGISTER + 0,
    URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63, URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63,
    URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 30,
};
/* INT32, BOOL, UINT32, DOUBLE: 4 + 1 + 4 + 8 = 17 bytes in a package. */
static const uint16_t regs[] = {
    URRT_RTDE_V_INPUT_INT_REGISTER + 24, URRT_RTDE_V_INPUT_BIT_REGISTER + 0,
    URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63, URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 30,
};

/* lib's calls, each through its stack mark on the target. */
static bool raws_of(const urrt_plcin_desc *d, const uint8_t *data, unsigned len, bool fd, uint64_t *raws)
{
    bool r;
    MEASURED(r, urrt_plcin_raws, (d, data, len, fd, raws));
    return r;
}
static size_t take(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in, const uint64_t *raws,
                   uint64_t absent, uint64_t at_us)
{
    size_t r;
    MEASURED(r, urrt_plcin_take, (d, p, in, raws, absent, at_us));
    return r;
}
static bool timed_out(const urrt_plcin_desc *d, const urrt_plcin *p, uint64_t now_us)
{
    bool r;
    MEASURED(r, urrt_plcin_timed_out, (d, p, now_us));
    return r;
}
static void silent(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in)
{
    MEASURED_VOID(urrt_plcin_silent, (d, p, in));
}
static bool writing(const urrt_plcin_desc *d, const urrt_plcin *p)
{
    bool r;
    MEASURED(r, urrt_plcin_writing, (d, p));
    return r;
}
static bool due(const urrt_plcin_desc *d, const urrt_plcin *p, bool ready, uint32_t session, uint64_t now_us,
                uint64_t period_us)
{
    bool r;
    MEASURED(r, urrt_plcin_due, (d, p, ready, session, now_us, period_us));
    return r;
}
static void sent(urrt_plcin *p, bool ok, uint32_t session, uint64_t now_us)
{
    MEASURED_VOID(urrt_plcin_sent, (p, ok, session, now_us));
}
static uint64_t deadline(const urrt_plcin_desc *d, const urrt_plcin *p, bool ready, uint64_t period_us)
{
    uint64_t r;
    MEASURED(r, urrt_plcin_deadline, (d, p, ready, period_us));
    return r;
}

static urrt_plcin_desc desc(urrt_plcin_silence silence, double value)
{
    urrt_plcin_desc d = {signals, vars, regs, 5, 4, 8, 0, 0x201, TIMEOUT_MS, (uint8_t)silence, 0, value};
    return d;
}

/* job 0x1234 = 4660, start 1, mask_lo 0xA, mask_hi 0xF5, speed raw 0x2710 = 10000 (100.5). */
static const uint8_t payload[8] = {0x34, 0x12, 0x01, 0x0A, 0xF5, 0x10, 0x27, 0x00};
/* 4660; 1; 0xF5 << 8 | 0xA = 0xF50A; 100.5 = 0x4059200000000000. */
static const uint8_t registers[17] = {0x00, 0x00, 0x12, 0x34, 0x01, 0x00, 0x00, 0xF5, 0x0A,
                                      0x40, 0x59, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00};

static bool given(const urrt_rtde_in *in, unsigned k)
{
    return ((unsigned)in->given[k / 8u] >> (k % 8u) & 1u) != 0;
}

static bool same(const uint8_t *a, const uint8_t *b, unsigned n)
{
    for (unsigned i = 0; i < n; i++) {
        if (a[i] != b[i]) {
            return false;
        }
    }
    return true;
}

static void setup(urrt_rtde_in *in, urrt_plcin *p)
{
    CHECK_EQ_INT(urrt_rtde_in_init(in, regs, 4), URRT_OK);
    MEASURED_VOID(urrt_plcin_init, (p));
}

static void test_raws(void)
{
    urrt_plcin_desc d = desc(URRT_PLCIN_STOP, 0);
    uint64_t raws[5] = {7, 7, 7, 7, 7};
    CHECK(!raws_of(&d, payload, 7, false, raws), "7 bytes for 8: not used");
    CHECK(!raws_of(&d, payload, 8, true, raws), "CAN FD for classic: not used");
    CHECK(raws[0] == 7 && raws[4] == 7, "raws untouched by a payload not used");
    CHECK(raws_of(&d, payload, 8, false, raws), "the configured length and kind");
    CHECK(raws[0] == 4660 && raws[1] == 1 && raws[2] == 0xA && raws[3] == 0xF5 && raws[4] == 10000,
          "raws %llu %llu %llu %llu %llu", (unsigned long long)raws[0], (unsigned long long)raws[1],
          (unsigned long long)raws[2], (unsigned long long)raws[3], (unsigned long long)raws[4]);
}

static void test_values(void)
{
    urrt_plcin_desc d = desc(URRT_PLCIN_STOP, 0);
    static urrt_rtde_in in; /* 896 bytes: not on the Cortex-M0's small stack */
    urrt_plcin p;
    uint64_t raws[5];
    setup(&in, &p);
    (void)raws_of(&d, payload, 8, false, raws);
    CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 1000), 0);
    CHECK_EQ_INT(in.data_size, 17);
    CHECK(same(in.data, registers, 17) && urrt_rtde_in_complete(&in), "the four registers as worked out");

    raws[0] = 10000; /* job past max=9999: refused, never clamped */
    raws[4] = (uint64_t)(uint16_t)-30000; /* -300 + 0.5: below min=-100 */
    CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 2000), 2);
    CHECK(!given(&in, 0) && given(&in, 1) && given(&in, 2) && !given(&in, 3), "the refused ones hold no value");
    CHECK(!urrt_rtde_in_complete(&in), "so no package can go");

    raws[0] = 9999;
    raws[4] = (uint64_t)(uint16_t)-10050; /* -100.5 + 0.5 = -100.0: the min itself */
    CHECK_EQ_INT(take(&d, &p, &in, raws, 1u << 1, 3000), 0); /* start absent: not counted */
    CHECK(given(&in, 0) && !given(&in, 1) && given(&in, 3), "an absent signal's register holds no value");
    CHECK(in.data[2] == 0x27 && in.data[3] == 0x0F, "job 9999 = 0x270F");
    CHECK(in.data[9] == 0xC0 && in.data[10] == 0x59 && in.data[11] == 0x00, "-100.0 = 0xC059000000000000");

    /* A mask bit past 31 (first 28, 8 bits): the UINT32 word refuses it. */
    {
        urrt_can_signal wide[5];
        for (unsigned i = 0; i < 5; i++) {
            wide[i] = signals[i];
        }
        wide[3].flags = (uint8_t)URRT_CAN_SIG_MASK(28);
        d.signals = wide;
        raws[3] = 0x10; /* bit 4 of the signal: the mask's bit 32 */
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 4000), 1);
        CHECK(!given(&in, 2), "a mask past bit 31 is refused");
        raws[3] = 0x08; /* the mask's bit 31: 0x8000000A */
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 5000), 0);
        CHECK(given(&in, 2) && in.data[5] == 0x80 && in.data[8] == 0x0A, "bit 31 and the low nibble");
    }
}

static void test_schedule(void)
{
    urrt_plcin_desc d = desc(URRT_PLCIN_STOP, 0);
    static urrt_rtde_in in; /* 896 bytes: not on the Cortex-M0's small stack */
    urrt_plcin p;
    uint64_t raws[5];
    const uint64_t t = 1000000;
    setup(&in, &p);
    (void)raws_of(&d, payload, 8, false, raws);
    CHECK(!writing(&d, &p) && !due(&d, &p, true, 1, t, PERIOD_US),
          "nothing before the PLC first wrote");
    CHECK(deadline(&d, &p, true, PERIOD_US) == URRT_CANTX_NEVER, "and no deadline");

    (void)take(&d, &p, &in, raws, 0, t);
    CHECK(due(&d, &p, true, 1, t, PERIOD_US), "the first write: due at once");
    CHECK(!due(&d, &p, false, 1, t, PERIOD_US), "but not to a session that is not ready");
    sent(&p, true, 1, t);
    CHECK(!due(&d, &p, true, 1, t + PERIOD_US - 1, PERIOD_US), "not again within the period");
    CHECK(due(&d, &p, true, 1, t + PERIOD_US, PERIOD_US), "again after the period");
    CHECK(due(&d, &p, true, 2, t + 1, PERIOD_US), "at once to a new session");
    CHECK(deadline(&d, &p, true, PERIOD_US) == t + PERIOD_US, "deadline: the period (before the timeout)");
    CHECK(deadline(&d, &p, false, PERIOD_US) == t + TIMEOUT_MS * 1000u + 1u,
          "deadline with no session ready: the first instant past the timeout");

    (void)take(&d, &p, &in, raws, 0, t + 10);
    CHECK(!due(&d, &p, true, 1, t + 10, PERIOD_US), "the same values: not due within the period");
    raws[4] = 10001;
    (void)take(&d, &p, &in, raws, 0, t + 20);
    CHECK(due(&d, &p, true, 1, t + 20, PERIOD_US), "a changed value: due at once");
    sent(&p, false, 1, t + 20);
    CHECK(due(&d, &p, true, 1, t + 21, PERIOD_US), "one that could not go: still due");
    CHECK(deadline(&d, &p, true, PERIOD_US) == t + 20 + PERIOD_US, "with its deadline a period later");
    sent(&p, true, 1, t + 30);
    CHECK(!due(&d, &p, true, 1, t + 31, PERIOD_US), "sent: no longer due");

    CHECK(!timed_out(&d, &p, t + 20 + TIMEOUT_MS * 1000u), "not timed out at exactly timeout_ms");
    CHECK(timed_out(&d, &p, t + 21 + TIMEOUT_MS * 1000u), "timed out past it");
    silent(&d, &p, &in);
    CHECK(!p.fresh && !given(&in, 0) && !given(&in, 3), "stop: not fresh, the values forgotten");
    CHECK(!writing(&d, &p) && !due(&d, &p, true, 3, t + 10000000, PERIOD_US),
          "stop: nothing is sent, even to a new session");
    CHECK(deadline(&d, &p, true, PERIOD_US) == URRT_CANTX_NEVER, "stop: no deadline");

    raws[4] = 10000;
    (void)take(&d, &p, &in, raws, 0, t + 20000000);
    CHECK(p.fresh && due(&d, &p, true, 1, t + 20000000, PERIOD_US), "the PLC writes again: due at once");
}

/* An input whose signals write its registers one each, in recipe order (the
 * usual input, and any RPDO's: register k taken from signal k alone), and the
 * same signals in another order (taken by a pass over all of them for each
 * register): the same bytes, refusals, absences and changes, worked out by
 * hand. A 40-bit identity signal (past 32 bits), a lone mask, a scaled value. */
static const urrt_can_signal in_order[4] = {
    /* big: 40 bits, signed, factor 1, -1000000..1000000 */
    {.factor = 1, .offset = 0, .min = -1000000, .max = 1000000, .start = 0, .length = 40, .type = URRT_CAN_SIGNED},
    /* start */
    {.factor = 1, .offset = 0, .min = 0, .max = 1, .start = 40, .length = 1, .type = URRT_CAN_UNSIGNED},
    /* mask: 8 bits, the word's bits 8-15 */
    {.factor = 1, .offset = 0, .min = 0, .max = 255, .start = 48, .length = 8, .type = URRT_CAN_UNSIGNED,
     .flags = URRT_CAN_SIG_MASK(8)},
    /* speed: as signals[4] */
    {.factor = 0.01, .offset = 0.5, .min = -100, .max = 200, .start = 0, .length = 16, .type = URRT_CAN_SIGNED},
};
static const urrt_can_signal out_of_order[4] = {in_order[3], in_order[2], in_order[1], in_order[0]};
static const uint16_t out_of_order_vars[4] = {
    URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 30, URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63,
    URRT_RTDE_V_INPUT_BIT_REGISTER + 0, URRT_RTDE_V_INPUT_INT_REGISTER + 24,
};

static void test_register_order(void)
{
    static urrt_rtde_in in; /* 896 bytes: not on the Cortex-M0's small stack */
    /* -10 (40 bits: 0xFFFFFFFFF6); 1; 0xA5 << 8; 100.5 */
    static const uint8_t want[17] = {0xFF, 0xFF, 0xFF, 0xF6, 0x01, 0x00, 0x00, 0xA5, 0x00,
                                     0x40, 0x59, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00};
    urrt_plcin_desc d = desc(URRT_PLCIN_STOP, 0);
    urrt_plcin p;
    unsigned pass;
    d.signal_count = 4;
    for (pass = 0; pass < 2; pass++) {
        /* raws in signal order: big, start, mask, speed; or reversed */
        uint64_t r[4] = {UINT64_C(0xFFFFFFFFF6), 1, 0xA5, 10000};
        uint64_t raws[4];
        unsigned big = pass == 0 ? 0 : 3, start = pass == 0 ? 1 : 2, mask = pass == 0 ? 2 : 1,
                 speed = pass == 0 ? 3 : 0;
        d.signals = pass == 0 ? in_order : out_of_order;
        d.vars = pass == 0 ? regs : out_of_order_vars;
        for (unsigned i = 0; i < 4; i++) {
            raws[pass == 0 ? i : 3 - i] = r[i];
        }
        setup(&in, &p);
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 1000), 0);
        CHECK(same(in.data, want, 17) && urrt_rtde_in_complete(&in), "pass %u: the four registers", pass);
        CHECK(p.changed, "pass %u: the first values are news", pass);
        sent(&p, true, 1, 1000);
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 2000), 0);
        CHECK(!p.changed, "pass %u: the same values again: no change", pass);
        raws[mask] = 0xA4; /* one bit of the mask */
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 3000), 0);
        CHECK(p.changed && in.data[7] == 0xA4, "pass %u: one bit changed: news", pass);
        sent(&p, true, 1, 3000);
        raws[big] = 1000001;                    /* past max */
        raws[speed] = (uint64_t)(uint16_t)-30000; /* below min */
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 4000), 2);
        CHECK(!given(&in, 0) && given(&in, 1) && given(&in, 2) && !given(&in, 3) && p.changed,
              "pass %u: the refused ones hold no value, and that is news", pass);
        sent(&p, true, 1, 4000);
        raws[big] = UINT64_C(0x8000000000); /* -2^39: below min */
        CHECK_EQ_INT(take(&d, &p, &in, raws, 0, 5000), 2);
        CHECK(!p.changed, "pass %u: refused again: no change", pass);
        raws[big] = 1000000;
        raws[speed] = 10000;
        CHECK_EQ_INT(take(&d, &p, &in, raws, UINT64_C(1) << start, 6000), 0); /* start absent: not counted */
        CHECK(given(&in, 0) && !given(&in, 1) && given(&in, 3), "pass %u: an absent signal's register: none", pass);
        CHECK(in.data[0] == 0x00 && in.data[1] == 0x0F && in.data[2] == 0x42 && in.data[3] == 0x40,
              "pass %u: 1000000 = 0x000F4240", pass);
    }
}

static void test_hold_and_value(void)
{
    urrt_plcin_desc hold = desc(URRT_PLCIN_HOLD, 0), value = desc(URRT_PLCIN_VALUE, 0);
    static urrt_rtde_in in; /* 896 bytes: not on the Cortex-M0's small stack */
    urrt_plcin p;
    uint64_t raws[5];
    const uint64_t t = 5000000;
    setup(&in, &p);
    (void)raws_of(&hold, payload, 8, false, raws);
    (void)take(&hold, &p, &in, raws, 0, t);
    sent(&p, true, 1, t);
    silent(&hold, &p, &in);
    CHECK(!p.fresh && same(in.data, registers, 17) && urrt_rtde_in_complete(&in), "hold: the last values kept");
    CHECK(!due(&hold, &p, true, 1, t + 1, PERIOD_US) &&
              due(&hold, &p, true, 1, t + PERIOD_US, PERIOD_US),
          "hold: sent on at the period");
    CHECK(deadline(&hold, &p, true, PERIOD_US) == t + PERIOD_US, "hold: the period is the deadline");

    setup(&in, &p);
    (void)take(&value, &p, &in, raws, 0, t);
    sent(&p, true, 1, t);
    silent(&value, &p, &in);
    {
        static const uint8_t zeros[17] = {0};
        CHECK(same(in.data, zeros, 17) && urrt_rtde_in_complete(&in), "value 0: every register 0");
    }
    CHECK(due(&value, &p, true, 1, t + 1, PERIOD_US), "value: the new values due at once");
    silent(&value, &p, &in);
    CHECK(!p.fresh, "silent twice: nothing more");
}

/* ---- through the node: co_fixture_rx_node, its RPDO1 (0x20A) mapping 0x2200 sub 1-3,
 * the node's variables 2 (INTEGER16, -1000..1000), 3 (a BOOLEAN) and 4 (UNSIGNED32). */

static urrt_co co;
static urrt_cantx tx;
static urrt_cantx_frame_state frame_states[2];
static urrt_cantx_robot robots[1];
static double values[8];
static urrt_co_tpdo_state tpdo_states[2];
static urrt_co_rpdo_state rpdo_states[2];
static urrt_co_consumer consumer_states[2];
static uint32_t node_vars[CO_FIXTURE_RX_VARS];
static uint64_t written[CO_FIXTURE_RX_VARS];
static urrt_co_rx_storage storage;

static const urrt_can_signal node_signals[] = {
    {.factor = 1, .offset = 0, .min = -1000, .max = 1000, .start = 0, .length = 16, .type = URRT_CAN_SIGNED},
    {.factor = 1, .offset = 0, .min = 0, .max = 1, .start = 16, .length = 8, .type = URRT_CAN_UNSIGNED},
    {.factor = 1, .offset = 0, .min = 0, .max = 4294967295.0, .start = 24, .length = 32, .type = URRT_CAN_UNSIGNED,
     .flags = URRT_CAN_SIG_MASK(0)},
};
static const uint16_t node_vars_of[] = {URRT_RTDE_V_INPUT_INT_REGISTER + 24, URRT_RTDE_V_INPUT_BIT_REGISTER + 0,
                                        URRT_RTDE_V_INPUT_BIT_REGISTERS0_TO_31};

static void emit(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)ctx, (void)f, (void)now_us;
}

static void frame(uint32_t id, const uint8_t *data, unsigned len, uint64_t t)
{
    urrt_co_on_frame(&co, id, 0, data, len, t, emit, NULL);
}

static urrt_plcin_look look_at(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in, uint64_t t)
{
    const urrt_plcin_rpdo rpdo = {&co, 2, 0};
    urrt_plcin_look look;
    MEASURED_VOID(urrt_plcin_node, (d, &rpdo, p, in, t, &look));
    return look;
}

static void test_node(void)
{
    static const uint8_t start[2] = {0x01, NODE}, stop[2] = {0x02, NODE};
    /* 1000 (0x2200 sub 1's HighLimit), 1, 0x0000000F; then 1001, which the node refuses, and 0x000000F0. */
    static const uint8_t rpdo1[7] = {0xE8, 0x03, 0x01, 0x0F, 0x00, 0x00, 0x00};
    static const uint8_t rpdo_1001[7] = {0xE9, 0x03, 0x01, 0xF0, 0x00, 0x00, 0x00};
    static const uint8_t sdo_500[8] = {0x2B, 0x00, 0x22, 0x01, 0xF4, 0x01, 0, 0}; /* 0x2200 sub 1 = 500 */
    static const uint8_t rpdo_off[8] = {0x23, 0x00, 0x14, 0x01, 0x0A, 0x02, 0x00, 0x80}; /* 0x1400 sub 1 |= bit 31 */
    const uint16_t recipe[] = {URRT_RTDE_V_INPUT_INT_REGISTER + 24, URRT_RTDE_V_INPUT_BIT_REGISTER + 0,
                               URRT_RTDE_V_INPUT_BIT_REGISTERS0_TO_31};
    const urrt_plcin_desc d = {node_signals, node_vars_of, recipe, 3, 3, 7, 0, 0x20A, TIMEOUT_MS, URRT_PLCIN_STOP,
                               0, 0};
    urrt_co_desc desc;
    static urrt_rtde_in in; /* 896 bytes: not on the Cortex-M0's small stack */
    urrt_plcin p;
    urrt_plcin_look look;
    size_t bad = 0;
    co_fixture_rx_desc(&desc);
    desc.heartbeat_ms = 0;
    storage.rpdos = rpdo_states;
    storage.consumers = consumer_states;
    storage.written_us = written;
    CHECK_EQ_INT(urrt_cantx_init(&tx, &tables, frame_states, robots, values, 8, NULL, NULL), 0);
    CHECK_EQ_INT(urrt_co_init_rx(&co, &desc, &tx, tpdo_states, node_vars, CO_FIXTURE_RX_VARS, &storage, &bad), 0);
    (void)urrt_co_start(&co, 0, emit, NULL);
    CHECK_EQ_INT(urrt_rtde_in_init(&in, recipe, 3), URRT_OK);
    urrt_plcin_init(&p);

    look = look_at(&d, &p, &in, 1000);
    CHECK(!look.took && look.why == URRT_PLCIN_STILL && !p.fresh, "nothing written: nothing taken, nothing said");
    frame(0x20A, rpdo1, 7, 2000);
    look = look_at(&d, &p, &in, 2000);
    CHECK(!look.took, "an RPDO in PRE-OPERATIONAL is not acted on");
    frame(0x000, start, 2, 3000);
    frame(0x20A, rpdo1, 7, 10000);
    look = look_at(&d, &p, &in, 10000);
    CHECK(look.took && look.refused == 0 && look.why == URRT_PLCIN_STILL && p.fresh, "RPDO1 in OPERATIONAL: taken");
    CHECK(in.data[2] == 0x03 && in.data[3] == 0xE8 && in.data[4] == 1 && in.data[8] == 0x0F &&
              urrt_rtde_in_complete(&in), "1000, 1, 0x0000000F");
    look = look_at(&d, &p, &in, 20000);
    CHECK(!look.took && p.fresh, "nothing new: nothing taken");
    frame(0x20A, rpdo_1001, 7, 30000);
    look = look_at(&d, &p, &in, 30000);
    CHECK(look.took && in.data[3] == 0xE8 && in.data[8] == 0xF0 && urrt_rtde_in_complete(&in),
          "1001 refused by the node: the register keeps 1000 (written 20 ms before), the mask is new");
    look = look_at(&d, &p, &in, 30000 + TIMEOUT_MS * 1000u + 1u);
    CHECK(look.why == URRT_PLCIN_NO_WRITE && !p.fresh && !urrt_rtde_in_complete(&in),
          "no write for timeout_ms: silent, and stop forgets the values");

    /* An SDO write alone, long after the RPDO: its variable taken, the others too old to be. */
    frame(0x60A, sdo_500, 8, 700000);
    look = look_at(&d, &p, &in, 700000);
    CHECK(look.took && p.fresh, "an SDO write makes the input fresh");
    CHECK(given(&in, 0) && in.data[2] == 0x01 && in.data[3] == 0xF4 && !given(&in, 1) && !given(&in, 2),
          "500 taken; the variables the RPDO wrote 690 ms before are absent");

    frame(0x20A, rpdo1, 7, 710000);
    look = look_at(&d, &p, &in, 710000);
    CHECK(look.took && urrt_rtde_in_complete(&in), "the RPDO again: every register");
    frame(0x000, stop, 2, 720000);
    look = look_at(&d, &p, &in, 720000);
    CHECK(look.why == URRT_PLCIN_NOT_OPERATIONAL && !p.fresh, "NMT stop: silent, the node not OPERATIONAL");
    frame(0x000, start, 2, 730000);
    frame(0x20A, rpdo1, 7, 740000);
    look = look_at(&d, &p, &in, 740000);
    CHECK(look.took && p.fresh, "started again: taken");
    frame(0x60A, rpdo_off, 8, 750000);
    look = look_at(&d, &p, &in, 750000);
    CHECK(look.why == URRT_PLCIN_RPDO_OFF && !p.fresh, "the RPDO switched off: silent");
}

int main(void)
{
#ifdef URRT_TARGET_CORTEX_M
    measuring = true;
#endif
    test_raws();
    test_values();
    test_schedule();
    test_register_order();
    test_hold_and_value();
    test_node();
    {
        static urrt_rtde_in in;
        CHECK_EQ_INT(urrt_rtde_in_init(&in, regs, 4), URRT_OK);
        in.given[0] = 0x0F;
        MEASURED_VOID(urrt_rtde_in_unset, (&in, 2));
        MEASURED_VOID(urrt_rtde_in_unset, (&in, 4)); /* past the recipe: nothing */
        CHECK(in.given[0] == 0x0B, "urrt_rtde_in_unset: register 2 alone");
    }
#ifdef URRT_TARGET_CORTEX_M
    stack_marks_print();
#endif
    return check_report();
}
