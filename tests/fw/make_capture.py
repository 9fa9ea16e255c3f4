#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Writes the capture check-fw-gateway replays: 1116-byte 3.x packets (the
column layout of tests/ref/urrt_ref.py, independent of lib/), 125 Hz, with
what a PLC contract has to handle: joints that move, a 350 ms stall (data
goes stale: frames with stale_policy = invalid go on invalid, stop frames
stop, the heartbeat says so), values past a signal's limits and NaN, robot
and safety modes that change, digital inputs in both codings (the integer
as a double, and int64 bits), and garbage between packets (the framer
resynchronises).

Usage: make_capture.py OUT
"""
import math
import os
import random
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "ref"))
import urrt_ref  # noqa: E402

DOUBLES = 139  # 1116 bytes: 3.10-3.13, 5.4-5.8
PERIOD_S = 0.008


def packet(t, i, rng):
    lay = urrt_ref.layout(DOUBLES)
    cols = [urrt_ref.bits_of(0.0)] * DOUBLES

    def put(name, values):
        count, first = lay[name]
        assert len(values) == count
        for k, v in enumerate(values):
            cols[first - 1 + k] = urrt_ref.bits_of(float(v))

    q = [0.5 * math.sin(0.7 * t + j) + 0.3 * j - 0.6 for j in range(6)]
    if 300 <= i < 310:
        q[0] = 7.0             # past max = 6.3: saturated, validity bit cleared
    if 320 <= i < 325:
        q[1] = float("nan")    # sent as invalid = -32768
    put("time", [t])
    put("q_actual", q)
    put("tool_vector_actual", [0.4 + 0.1 * math.cos(t), -0.2, 0.35 + 0.01 * (i % 7), 0.0, 3.14, 0.0])
    put("speed_scaling", [min(1.0, 0.01 * (i % 150))])
    put("robot_mode", [7.0 if i < 200 else 5.0])
    put("safety_mode", [1.0 if i < 350 else 3.0])
    put("program_state", [2.0 if i % 100 < 80 else 1.0])
    din = (i // 10) & 0x3FFFF
    # digital inputs: the documented coding (the integer as a double), and from
    # packet 400 on the int64 bits some controllers send.
    put("digital_input_bits", [din])
    if i >= 400:
        count, first = lay["digital_input_bits"]
        cols[first - 1] = din  # the int64 bits themselves: read as a double, a subnormal
    put("digital_outputs", [float(rng.randrange(0, 1 << 18))])
    return urrt_ref.packet_bytes(4 + 8 * DOUBLES, cols)


def main():
    out_path = sys.argv[1]
    rng = random.Random(20261122)
    t = 1234.5
    chunks = []
    for i in range(500):
        if i == 250:
            t += 0.350        # the stall: 350 ms without a packet
        if i in (150, 420):
            chunks.append(bytes(rng.randrange(256) for _ in range(37)))  # garbage
        chunks.append(packet(round(t, 6), i, rng))
        t += PERIOD_S
    with open(out_path, "wb") as f:
        f.write(b"".join(chunks))


if __name__ == "__main__":
    main()
