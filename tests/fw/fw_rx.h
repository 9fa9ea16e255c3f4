/* SPDX-License-Identifier: MIT */
/* The frames a CANopen manager sent the firmware's node in check-fw-gateway
 * (tests/fw/rx_table.py writes them from a candump -l log timed on the
 * capture's clock, recorded from check-canopen's master): what a board's CAN
 * receive interrupt would hand over. */
#ifndef URRT_TEST_FW_RX_H
#define URRT_TEST_FW_RX_H

#include <stdint.h>

struct fw_rx_frame {
    uint64_t t_us;
    uint32_t id;
    uint8_t len;
    uint8_t data[8];
};

extern const struct fw_rx_frame fw_rx_frames[];
extern const unsigned fw_rx_count;

#endif
