/* SPDX-License-Identifier: MIT */
/*
 * co_run: a configuration's CANopen node. The urrt_co_desc of lib/urrt_co.h
 * (TPDOs, their mappings, the manufacturer objects) built from a finished
 * [canopen] (canopen_map.h) over the CAN tables of can_run.h, and the node
 * bound to can_run's CAN core. Built once when the configuration is loaded,
 * beside can_run, so that --check-config proves the node accepts it; the
 * gateway's loop, --replay, --print-eds and --print-c-tables all use this
 * one description, so the EDS and the node cannot disagree.
 *
 * The description, for a map with frames F1..Fn (TPDO numbers from
 * canopen_map) and [can]'s heartbeat frame H:
 *   TPDO k (k = 1..n): frame Fi with tpdo_of[i] = k, COB-ID pre-defined
 *     (or its own id), type 254 or sync N; its mapping one entry per signal
 *     (0x2100 + k - 1, sub s + 1, the object's bits), a CiA 301 UNSIGNED8
 *     dummy (0x0005) for each byte no signal owns;
 *   TPDO n + 1: the status frame H, its COB-ID invalid (bit 31) by default,
 *     its whole-byte values mapped, a dummy byte for each byte of bit fields;
 *   0x2000 sub 1..13: H's signals (the gateway's state, data age, counters);
 *   0x2100 + k - 1 sub 1..: TPDO k's signals (robot values, alive counter,
 *     validity bit), read-only, PDO-mappable;
 * and for [input]s I1..Im (m <= 4):
 *   RPDO j (j = 1..m): Ij, its pre-defined COB-ID, type 254, its event timer
 *     Ij's timeout_ms (the deadline), mapped one entry per signal
 *     (0x2200 + j - 1, sub s + 1), a dummy byte where no signal is;
 *   0x2200 + j - 1 sub 1..: Ij's signals, raw, writable (by RPDO or SDO),
 *     each in a variable of its own (co_run_input_raw);
 *   0x1016 sub 1: the manager's heartbeat, off until the manager sets it.
 */
#ifndef URRT_GATEWAY_CO_RUN_H
#define URRT_GATEWAY_CO_RUN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "can_map.h"
#include "can_run.h"
#include "canopen_map.h"
#include "urrt_co.h"

#define CO_RUN_RX_IDS 3u /* NMT 0x000, SYNC 0x080, SDO request 0x600 + node id: a node without [input]s */

struct co_run;

/* NULL with the reason in err (out of memory, or lib/urrt_co refusing the
 * description: a check missing in canopen_map). co, can and run must
 * outlive it. */
struct co_run *co_run_build(const struct canopen_map *co, const struct can_map *can, struct can_run *run, char *err,
                            size_t errlen);
void co_run_free(struct co_run *run);

urrt_co *co_run_node(struct co_run *run);
const urrt_co_desc *co_run_desc(const struct co_run *run);
/* The ids the node receives after a reset (urrt_co_rx_ids): what the CAN
 * link's filter starts with. A manager's write to 0x1005 changes them on the
 * running node (urrt_co.rx_changes), which can_out follows. */
const uint32_t *co_run_rx_ids(const struct co_run *run, size_t *count);

/* The node variable (urrt_co_init's vars) of [input] i's first signal; its
 * signal k's is that + k. i = the [input]s' count: how many variables the
 * [input]s have in all. */
size_t co_run_input_first_var(const struct co_run *run, size_t input);

/* [input] i's signal k as the node holds it: raw, as its object's type
 * (INTEGERn not sign-extended). */
uint32_t co_run_input_raw(const struct co_run *run, size_t input, size_t signal);
/* When an RPDO or SDO write last stored one of [input] i's variables, on the
 * node's clock; URRT_CANTX_NEVER before the first. */
uint64_t co_run_input_written_us(const struct co_run *run, size_t input);

/* Whether a TPDO's mapping names the object (the EDS's PDOMapping). */
bool co_run_mapped(const struct co_run *run, uint16_t index, uint8_t sub);

/* The index of TPDO n's (1..) values: 0x2100 + n - 1. */
uint16_t co_run_values_index(unsigned tpdo);

/* One line for --check-config and the log at start: "node 5: TPDO1..4 +
 * status TPDO5 (off until enabled), heartbeat 1000 ms at 0x705, ...".
 * Returns snprintf's. */
int co_run_describe(const struct co_run *run, char *buf, size_t size);

#endif
