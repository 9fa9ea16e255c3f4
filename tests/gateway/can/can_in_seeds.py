#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""can_in_seeds.py DIR: seed scripts for tests/gateway/can/fuzz_can_in.c, written from its
record format (a kind byte, even: a frame for an [input] of the plain configuration,
odd: a frame to the CANopen twin's node) and CiA 301 (NMT, RPDOs, expedited SDO
downloads), so that the fuzzer starts from inputs that reach every path."""
import os
import struct
import sys

NMT, RPDO1, RPDO2, SDO = 0, 2, 3, 4       # fuzz_can_in.c's ids[] of the node's frames


def plain(which, data, fd=False, length=None):
    n = len(data) if length is None else length
    return bytes([0, which, (0x80 if fd else 0) | n]) + data


def node(which, data, step_ms=1, absent=False):
    return bytes([1, which | (0x10 if absent else 0), len(data), step_ms * 2 | (1 if absent else 0)]) + data


def sdo_write(index, sub, value, size):
    cs = 0x23 | (4 - size) << 2
    return bytes([cs, index & 0xFF, index >> 8, sub]) + value.to_bytes(size, 'little') + bytes(4 - size)


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    job = struct.pack('<HBBI', 1234, 1, 0, 77) + b'\x80'
    cmd = bytes(range(16))
    seeds = {
        'job': plain(1, job[:8].ljust(8, b'\0')),
        'job-max': plain(1, struct.pack('<HBBIB', 9999, 1, 0, 0xFFFFFFFF, 0xFF)[:8]),
        'job-past-max': plain(1, struct.pack('<HBBIB', 10000, 3, 0, 0, 0)[:8]),
        'job-short': plain(1, b'\1\2\3'),
        'cmd-fd': plain(0, cmd, fd=True),
        'cmd-classic': plain(0, cmd[:8]),
        'start': node(NMT, bytes([1, 5])) + node(RPDO1, struct.pack('<HBi', 42, 1, -3) + b'\0'),
        'rpdo2': node(NMT, bytes([1, 0])) + node(RPDO2, struct.pack('<Hb', 0xA5A5, -5) + bytes(5)),
        'rpdo-short': node(NMT, bytes([1, 5])) + node(RPDO1, b'\1\2'),
        'sdo-2200': node(SDO, sdo_write(0x2200, 1, 77, 2)) + node(SDO, sdo_write(0x2200, 2, 2, 1)),
        'sdo-1400': node(SDO, sdo_write(0x1400, 1, 0x80000205, 4)) + node(SDO, sdo_write(0x1400, 5, 10, 2)),
        'sdo-1016': node(SDO, sdo_write(0x1016, 1, 1 << 16 | 50, 4)) + node(5, bytes([5]), step_ms=100),
        'stopped': node(NMT, bytes([2, 5])) + node(RPDO1, bytes(8)) + node(NMT, bytes([1, 5])),
        'absent': node(NMT, bytes([1, 5])) + node(RPDO1, bytes(8), absent=True),
    }
    for name, data in seeds.items():
        with open(os.path.join(out, name), 'wb') as f:
            f.write(data)


if __name__ == '__main__':
    main()
