#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Writes the RTDE capture check-fw-gateway replays, in the format
`urrt-dump --rtde -w` records (docs/rtde.md, "Captures": the 20-byte header,
then records of a kind byte and a whole package: 'C' a connection, '>' what
the client sent, '<' what the controller sent). The packages come from
tests/ref/rtde_ref.py, the protocol's encoder written apart from lib/: the
handshake urrt's client makes (protocol 2, the controller version, one
recipe at 500 Hz, start) against an e-Series 5.12.3, then 1000 data packages
at 500 Hz with what a PLC contract has to handle: a 350 ms stall (data goes
stale), registers at the ends of their range, a double register NaN and
infinite, bit masks with their high bits set (bit 31 of the status bits,
bits 48-63 of a UINT64), joints past a signal's limits and NaN, modes that
change, and a text message between data packages.

The recipe is larger than any configuration's and in another order, so that
a client of a smaller recipe (the firmware's) gets each of its values sliced
out of these packages (tests/fw/rtde_controller.py).

Usage: make_rtde_capture.py OUT
"""
import math
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "ref"))
import rtde_ref  # noqa: E402

MAGIC = b"URRT RTDE capture 1\n"
CONTROLLER = (5, 12, 3, 1234)
FREQUENCY = 500.0
PERIOD_S = 0.002
PACKAGES = 1000
STALL_AT = 500      # 350 ms without a package before this one
NAMES = [
    "actual_q", "timestamp", "actual_qd", "robot_status_bits", "output_int_register_25", "robot_mode",
    "safety_mode", "joint_mode", "actual_digital_input_bits", "speed_scaling", "runtime_state",
    "safety_status_bits", "output_int_register_24", "output_double_register_24", "output_bit_register_64",
    "tool_output_mode", "target_speed_fraction", "tcp_offset", "actual_TCP_pose",
    "actual_configurable_digital_input_bits", "actual_digital_output_bits",
]
INT32_MIN, INT32_MAX = -(1 << 31), (1 << 31) - 1


def record(kind, pkg):
    return kind + pkg


def values(i, t):
    q = [0.5 * math.sin(0.7 * t + j) + 0.3 * j - 0.6 for j in range(6)]
    if 300 <= i < 310:
        q[1] = 9.0                          # past what a 15-bit signal of factor 0.0005 holds: clamped
    if 320 <= i < 325:
        q[1] = float("nan")                 # sent as invalid=
    reg24 = {100: INT32_MIN, 101: INT32_MAX, 102: -1}.get(i, i * 7 - 3000)
    reg_double = 0.5 * (i % 400) - 50.0
    if 200 <= i < 205:
        reg_double = float("nan")
    elif i == 205:
        reg_double = math.inf
    status = (i // 25) & 0xF | (0x80000000 if i % 50 < 10 else 0)
    safety = 1 << ((i // 40) % 11) | (0xFFFF0000 if 600 <= i < 700 else 0)
    return {
        "timestamp": [t],
        "actual_q": q,
        "actual_qd": [0.35 * math.cos(0.7 * t + j) for j in range(6)],
        "robot_status_bits": [status],
        "output_int_register_25": [(i * 13) % 4001 - 2000],   # past min/max = +-1000: clamped
        "robot_mode": [7 if i < 200 else 5],
        "safety_mode": [1 if i < 350 else 3],
        "joint_mode": [253] * 6,
        "actual_digital_input_bits": [(i // 10) & 0x3FFFF],
        "speed_scaling": [min(1.0, 0.01 * (i % 150))],
        "runtime_state": [2 if i % 100 < 80 else 1],
        "safety_status_bits": [safety],
        "output_int_register_24": [reg24],
        "output_double_register_24": [reg_double],
        "output_bit_register_64": [(i // 7) & 1],
        "tool_output_mode": [i % 3],
        "target_speed_fraction": [(i % 101) / 100.0],
        "tcp_offset": [0.0, 0.0, 0.1, 0.0, 0.0, 0.01 * (i % 300) - 1.5],
        "actual_TCP_pose": [0.4 + 0.1 * math.cos(t), -0.2, 0.35, 0.0, 3.14, 0.0],
        "actual_configurable_digital_input_bits": [0xFFFF000000000000 | (i & 0xFF) << 40 | i],
        "actual_digital_output_bits": [i & 0xFF],
    }


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_rtde_capture.py OUT")
    r = rtde_ref
    types = [r.type_of(n) for n in NAMES]
    out = [MAGIC, record(b"C", r.package(b"C", b"robot:30004"))]
    out += [record(b">", r.req_protocol(2)), record(b"<", r.rep_flag(r.V, 1))]
    out += [record(b">", r.req_controller()), record(b"<", r.rep_controller(*CONTROLLER))]
    out += [record(b">", r.req_setup(2, FREQUENCY, NAMES)), record(b"<", r.rep_setup(2, 1, types))]
    out += [record(b">", r.req_start()), record(b"<", r.rep_flag(r.S, 1))]
    t = 1234.5
    for i in range(PACKAGES):
        if i == STALL_AT:
            t += 0.350
        if i == 150:
            out.append(record(b"<", r.text_v2(3, b"program started", b"URControl")))  # 3: info
        out.append(record(b"<", r.data_package(2, 1, NAMES, values(i, round(t, 6)))))
        t += PERIOD_S
    with open(sys.argv[1], "wb") as f:
        f.write(b"".join(out))


if __name__ == "__main__":
    main()
