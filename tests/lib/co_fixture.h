/* SPDX-License-Identifier: MIT */
/*
 * The CANopen node both tests/lib/test_co.c and tests/lib/fuzz_co.c run:
 * id 10 (0x0A), so boot-up and heartbeat 0x70A, EMCY 0x08A, SDO 0x60A in and
 * 0x58A out, TPDO1 0x18A, TPDO2 0x28A.
 *   TPDO1: cantx frame 0, every 10 ms, invalid policy, 5 bytes: q_actual[0]
 *          bits 0..15 (signed, 0.001 rad), robot_mode 16..23, alive counter
 *          24..31, validity bit 32. Type 254.
 *   TPDO2: cantx frame 1, every packet, stop policy, 2 bytes: q_actual[0]. Type 254.
 *   0x2000 sub 1, 2: TPDO1's q0 (INTEGER16) and mode (INTEGER8), read-only.
 *   0x2100: UNSIGNED16 variable, rw, default 100, range 10..1000.
 *   0x2101: UNSIGNED8 variable, write-only.
 * Robot data is stale after 50 ms; heartbeat 100 ms; the CAN core's startup 1 s.
 *
 * co_fixture_rx_node: the same node with two RPDOs and a consumer heartbeat
 * (urrt_co_init_rx, vars[CO_FIXTURE_RX_VARS]):
 *   0x2200 sub 1: INTEGER16 vars[2], rw, -1000..1000, default 0
 *   0x2200 sub 2: UNSIGNED8 vars[3], rw, a BOOLEAN: 0..1, default 0
 *   0x2200 sub 3: UNSIGNED32 vars[4], rw, whole range, default 7
 *   0x2200 sub 4: INTEGER8 vars[5], write-only, -100..100, default 0
 *   0x2201:       UNSIGNED16 vars[6], read-only, default 5
 *   RPDO1 (0x20A): type 255, event timer 100 ms, 7 bytes: 0x2200 sub 1 (bytes 0-1),
 *                  sub 2 (byte 2), sub 3 (bytes 3-6)
 *   RPDO2 (0x30A): type 0 (at the next SYNC), no event timer, 4 bytes: 0x2200 sub 4
 *                  (byte 0), an UNSIGNED8 dummy (byte 1), 0x2200 sub 1 (bytes 2-3)
 *   0x1016: 2 entries, sub 1 = node 1 every 150 ms (0x00010096), sub 2 = 0 (off)
 */
#ifndef URRT_TEST_CO_FIXTURE_H
#define URRT_TEST_CO_FIXTURE_H

#include "urrt_co.h"

#define NODE 0x0Au
#define SIG(start, length, type, factor, min, max) {(factor), 0.0, (min), (max), 0, (start), (length), URRT_CAN_INTEL, (type), 0}

static const urrt_can_signal sigs_1[4] = {
    SIG(0, 16, URRT_CAN_SIGNED, 0.001, -32.768, 32.767),
    SIG(16, 8, URRT_CAN_SIGNED, 1, -128, 127),
    SIG(24, 8, URRT_CAN_UNSIGNED, 1, 0, 255),
    SIG(32, 1, URRT_CAN_UNSIGNED, 1, 0, 1),
};
static const urrt_cantx_source srcs_1[4] = {
    {URRT_CANTX_FIELD, URRT_F_Q_ACTUAL, 0},
    {URRT_CANTX_FIELD, URRT_F_ROBOT_MODE, 0},
    {URRT_CANTX_ALIVE, 0, 0},
    {URRT_CANTX_VALID, 0, 0},
};
static const urrt_can_signal sigs_2[1] = {SIG(0, 16, URRT_CAN_SIGNED, 0.001, -32.768, 32.767)};
static const urrt_cantx_source srcs_2[1] = {{URRT_CANTX_FIELD, URRT_F_Q_ACTUAL, 0}};

static const urrt_cantx_frame frames[2] = {
    {sigs_1, srcs_1, 4, 5, 0, 0x7FF, 10000, 50000, URRT_CANTX_STALE_INVALID, 0, NULL},
    {sigs_2, srcs_2, 1, 2, 0, 0x7FE, URRT_CANTX_EVERY_PACKET, 50000, URRT_CANTX_STALE_STOP, 0, NULL},
};
static const urrt_cantx_tables tables = {frames, 2, 1, 1000000};

static const uint32_t map_1[4] = {0x20000110, 0x20000208, 0x20000308, 0x20000401};
static const uint32_t map_2[1] = {0x20000110};
static const urrt_co_tpdo tpdos[2] = {
    {map_1, URRT_CO_COB_DEFAULT, 0, 0, 254, 4},
    {map_2, URRT_CO_COB_DEFAULT, 1, 0, 254, 1},
};
static const urrt_co_object objects[4] = {
    {0x2000, 1, URRT_CO_INTEGER16, URRT_CO_RO, URRT_CO_SIGNAL, 0, 0, 0, 0, 0},
    {0x2000, 2, URRT_CO_INTEGER8, URRT_CO_RO, URRT_CO_SIGNAL, 0, 1, 0, 0, 0},
    {0x2100, 0, URRT_CO_UNSIGNED16, URRT_CO_RW, URRT_CO_VAR, 0, 0, 100, 10, 1000},
    {0x2101, 0, URRT_CO_UNSIGNED8, URRT_CO_WO, URRT_CO_VAR, 0, 1, 0, 0, 1},
};
static const urrt_co_desc co_fixture_node = {
    NODE, URRT_CO_START_PRE_OPERATIONAL, 100, 0, 50000, 0x12345678, 0x01020304, 0x0000ABCD, 0x00010002,
    0x00000042, "urrt CANopen gateway", "1.0", "0.9.0", tpdos, 2, objects, 4, NULL, 0, NULL, 0,
};

#define CO_FIXTURE_RX_VARS 7u
static const urrt_co_object rx_objects[9] = {
    {0x2000, 1, URRT_CO_INTEGER16, URRT_CO_RO, URRT_CO_SIGNAL, 0, 0, 0, 0, 0},
    {0x2000, 2, URRT_CO_INTEGER8, URRT_CO_RO, URRT_CO_SIGNAL, 0, 1, 0, 0, 0},
    {0x2100, 0, URRT_CO_UNSIGNED16, URRT_CO_RW, URRT_CO_VAR, 0, 0, 100, 10, 1000},
    {0x2101, 0, URRT_CO_UNSIGNED8, URRT_CO_WO, URRT_CO_VAR, 0, 1, 0, 0, 1},
    {0x2200, 1, URRT_CO_INTEGER16, URRT_CO_RW, URRT_CO_VAR, 0, 2, 0, 0xFC18, 1000},
    {0x2200, 2, URRT_CO_UNSIGNED8, URRT_CO_RW, URRT_CO_VAR, 0, 3, 0, 0, 1},
    {0x2200, 3, URRT_CO_UNSIGNED32, URRT_CO_RW, URRT_CO_VAR, 0, 4, 7, 0, 0xFFFFFFFF},
    {0x2200, 4, URRT_CO_INTEGER8, URRT_CO_WO, URRT_CO_VAR, 0, 5, 0, 0x9C, 100},
    {0x2201, 0, URRT_CO_UNSIGNED16, URRT_CO_RO, URRT_CO_VAR, 0, 6, 5, 0, 0xFFFF},
};
static const uint32_t rmap_1[3] = {0x22000110, 0x22000208, 0x22000320};
static const uint32_t rmap_2[3] = {0x22000408, 0x00050008, 0x22000110};
static const urrt_co_rpdo rpdos[2] = {
    {rmap_1, URRT_CO_COB_DEFAULT, 100, 255, 3},
    {rmap_2, URRT_CO_COB_DEFAULT, 0, 0, 3},
};
static const uint32_t consumers[2] = {0x00010096, 0};
static const urrt_co_desc co_fixture_rx_node = {
    NODE, URRT_CO_START_PRE_OPERATIONAL, 100, 0, 50000, 0x12345678, 0x01020304, 0x0000ABCD, 0x00010002,
    0x00000042, "urrt CANopen gateway", "1.0", "0.9.0", tpdos, 2, rx_objects, 9, rpdos, 2, consumers, 2,
};
/* The description, its defaults restored (tests change fields of it). */
static inline void co_fixture_desc(urrt_co_desc *d)
{
    *d = co_fixture_node;
}
static inline void co_fixture_rx_desc(urrt_co_desc *d)
{
    *d = co_fixture_rx_node;
}

#endif
