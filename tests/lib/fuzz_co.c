/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness for lib/urrt_co (the CANopen node): any sequence of
 * received frames (any id, any length 0..8, RTR and 29-bit flags; RPDOs,
 * heartbeats and SDO writes of 0x1400/0x1600/0x1016 and the variables
 * among them), robot packets, link changes and CAN counters, with time
 * advancing, on co_fixture.h's node without RPDOs (an input of odd length)
 * or with them (even length). Asserts:
 * a call sends a bounded number of frames; every SDO answer is on 0x580+id,
 * 8 bytes, with a command byte a server may send; heartbeats carry one of the
 * four states; the state is always one of the four; after a run nothing is
 * due (no busy loop); the ids received are at most URRT_CO_RX_IDS_MAX, 3 on
 * the node without RPDOs; an RPDO's status is a reason or fresh, and fresh
 * only in OPERATIONAL. Built with ASan and UBSan, so out-of-bounds accesses
 * and undefined behaviour abort too.
 *
 * Input: records of [time step, selector, length and flags, data...]; a
 * selector below 0xF0 picks a frame's id: bit 4 set, any id (from the
 * selector and the flags byte), else one of 16; with bit 5 set an SDO
 * request is aimed at an object of the receiving side.
 */
#include "co_fixture.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void require_at(int ok, int line, const char *what)
{
    if (!ok) {
        fprintf(stderr, "fuzz_co.c:%d: invariant violated: %s\n", line, what);
        abort();
    }
}
#define REQUIRE(cond) require_at((cond), __LINE__, #cond)

/* The most a call may send: a SYNC sends a TPDO each; a run a heartbeat, an
 * SDO timeout, one EMCY per condition and every cantx frame. */
#define MAX_ON_FRAME 2u
#define MAX_RUN (2u + URRT_CO_CONDITIONS + URRT_CO_RX_CONDITIONS + 2u)

static urrt_co_desc desc;
static size_t emitted;

static void check_frame(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)ctx;
    (void)now_us;
    emitted++;
    REQUIRE(!f->extended && !f->fd && f->len <= 8u);
    if (f->id == 0x580u + NODE) {
        uint8_t cmd = f->data[0];
        uint8_t cs = cmd >> 5;
        REQUIRE(f->len == 8u);
        REQUIRE(cmd == 0x80u || cmd == 0x60u || cmd == 0x41u || (cs == 2u && (cmd & 0x13u) == 0x03u) ||
                (cs == 0u && (cmd & 0xE0u) == 0u));
    } else if (f->id == 0x700u + NODE) {
        REQUIRE(f->len == 1u && (f->data[0] == 0u || f->data[0] == 4u || f->data[0] == 5u || f->data[0] == 0x7Fu));
    }
}

static const uint32_t ids[16] = {0x000, 0x080,        0x600 + NODE, 0x600 + NODE, 0x081, 0x180 + NODE,
                                 0x600, 0x7FF,        0x200 + NODE, 0x200 + NODE, 0x300 + NODE, 0x701,
                                 0x702, 0x400 + NODE, 0x600 + NODE, 0x080};
static const uint16_t rx_indices[8] = {0x1400, 0x1401, 0x1600, 0x1601, 0x1016, 0x2200, 0x2201, 0x1402};

static void robot_event(urrt_cantx *tx, urrt_co *co, uint8_t what, uint64_t now)
{
    static urrt_cantx_link link;
    urrt_state st;
    switch (what & 3u) {
    case 0:
        urrt_state_clear(&st);
        st.generation = URRT_GEN_3X;
        st.q_actual[0] = (double)(int8_t)what / 10.0;
        st.robot_mode[0] = 7;
        st.present = (UINT64_C(1) << URRT_F_Q_ACTUAL) | (UINT64_C(1) << URRT_F_ROBOT_MODE);
        urrt_cantx_on_packet(tx, 0, &st, now);
        break;
    case 1: urrt_cantx_robot_link(tx, 0, (what & 4u) != 0u); break;
    case 2:
        link.dropped += (what >> 2) & 1u;
        link.bus_off += (what >> 3) & 1u;
        urrt_cantx_set_link(tx, &link);
        break;
    default: urrt_co_set_error_passive(co, (what & 4u) != 0u); break;
    }
}

/* The receiving side's invariants after each step. */
static void check_rx(const urrt_co *co, uint64_t now, bool with_rx)
{
    uint32_t rx_ids[URRT_CO_RX_IDS_MAX];
    size_t n = urrt_co_rx_ids(co, rx_ids);
    size_t i;
    REQUIRE(n >= 3u && n <= URRT_CO_RX_IDS_MAX && (with_rx || n == 3u));
    for (i = 0; i < n; i++) {
        REQUIRE(rx_ids[i] <= 0x7FFu);
    }
    for (i = 0; i < 3u; i++) {
        urrt_co_rx_status s = urrt_co_rpdo_status(co, i, now);
        REQUIRE(with_rx && i < 2u ? s <= URRT_CO_RPDO_DEADLINE : s == URRT_CO_RPDO_NONE);
        REQUIRE(s != URRT_CO_RPDO_FRESH || co->state == URRT_CO_OPERATIONAL);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *in, size_t size)
{
    static urrt_cantx tx;
    static urrt_cantx_frame_state states[2];
    static urrt_cantx_robot robots[1];
    static double values[32];
    static urrt_co co;
    static urrt_co_tpdo_state tpdo_states[2];
    static uint32_t vars[CO_FIXTURE_RX_VARS];
    static urrt_co_rpdo_state rpdo_states[2];
    static urrt_co_consumer consumer_states[2];
    static uint64_t written[CO_FIXTURE_RX_VARS];
    static urrt_co_rx_storage rx = {.rpdos = rpdo_states, .consumers = consumer_states, .written_us = written};
    bool with_rx = size % 2u == 0u;
    uint64_t now = 0;
    size_t at = 0;
    if (with_rx) {
        co_fixture_rx_desc(&desc);
    } else {
        co_fixture_desc(&desc);
    }
    REQUIRE(urrt_cantx_init(&tx, &tables, states, robots, values, 32, NULL, NULL) == 0);
    REQUIRE(urrt_co_init_rx(&co, &desc, &tx, tpdo_states, vars, with_rx ? CO_FIXTURE_RX_VARS : 2u,
                            with_rx ? &rx : NULL, NULL) == 0);
    emitted = 0;
    REQUIRE(urrt_co_start(&co, 0, check_frame, NULL) == 1 && emitted == 1);
    while (at + 3u <= size) {
        uint8_t step = in[at];
        uint8_t sel = in[at + 1];
        uint8_t shape = in[at + 2];
        size_t len = shape % 9u;
        uint8_t data[8] = {0};
        size_t n;
        at += 3;
        len = len < size - at ? len : size - at;
        memcpy(data, in + at, len);
        at += len;
        now += (uint64_t)step * step * 50u;
        if (sel >= 0xF0u) {
            robot_event(&tx, &co, shape, now);
        } else {
            uint32_t id = (sel & 16u) != 0u ? ((uint32_t)sel << 3 | (shape >> 4 & 7u)) & 0x7FFu : ids[sel & 15u];
            unsigned flags = shape >= 0xF0u ? (shape & 1u ? URRT_CO_RX_RTR : URRT_CO_RX_EXTENDED) : 0u;
            if (id == 0x600u + NODE && (sel & 32u) != 0u && len == 8u) {
                uint16_t index = rx_indices[data[1] & 7u];
                data[1] = (uint8_t)index;
                data[2] = (uint8_t)(index >> 8);
            }
            emitted = 0;
            n = urrt_co_on_frame(&co, id, flags, len > 0u ? data : NULL, len, now, check_frame, NULL);
            REQUIRE(n == emitted && n <= MAX_ON_FRAME);
        }
        REQUIRE(co.state == URRT_CO_PRE_OPERATIONAL || co.state == URRT_CO_OPERATIONAL || co.state == URRT_CO_STOPPED);
        emitted = 0;
        n = urrt_co_run(&co, now, check_frame, NULL);
        REQUIRE(n == emitted && n <= MAX_RUN);
        REQUIRE(urrt_co_deadline(&co) > now);
        check_rx(&co, now, with_rx);
    }
    return 0;
}
