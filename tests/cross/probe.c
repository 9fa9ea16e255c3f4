/* SPDX-License-Identifier: MIT */
/* Sizes of the caller-owned structs on the target: each array's size is
 * read back from the symbol table (arm-none-eabi-nm -S). */
#include "urrt.h"
#include "urrt_co.h"
#include "urrt_rtde.h"
#include "urrt_rtde_in.h"

char urrt_probe_state[sizeof(urrt_state)];
char urrt_probe_framer[sizeof(urrt_framer)];
char urrt_probe_rtde[sizeof(urrt_rtde)];
char urrt_probe_rtde_values[sizeof(urrt_rtde_values)];
char urrt_probe_rtde_in[sizeof(urrt_rtde_in)];
/* The CANopen node, its per-PDO and per-0x1016-entry storage and its receiving side's (lib/urrt_co.h). */
char urrt_probe_co[sizeof(urrt_co)];
char urrt_probe_co_tpdo[sizeof(urrt_co_tpdo_state)];
char urrt_probe_co_rpdo[sizeof(urrt_co_rpdo_state)];
char urrt_probe_co_consumer[sizeof(urrt_co_consumer)];
char urrt_probe_co_rx_storage[sizeof(urrt_co_rx_storage)];
