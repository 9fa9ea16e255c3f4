#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""make_rx_inputs.py OUT.log: the CANopen manager of check-fw-gateway's
plc-inputs configuration (tests/fw/plc-inputs.ini, node 5), as candump -l
lines timed on the clock of tests/fw/make_rtde_capture.py's capture (its
first package at 1234.5 s, every 2 ms, a 350 ms stall from about 1235.5 s).
Written from CiA 301 (NMT, expedited SDO download, PDOs), not from lib/.

The script: NMT start; RPDO1 (job, start, door) and RPDO2 (speed, x 0.01)
every 20 ms, values changing and not; a speed past the signal's max (the
node refuses it); a job past 9999 (refused by the node's object range);
both RPDOs silent for longer than their timeouts (stop; value 0); RPDO1 again
with unchanged values (the minimum rate repeats them); an SDO write of the
job alone; NMT stop and start (across the capture's stall); RPDO1 switched
off (0x1400 sub 1, bit 31), sent while off, and on again.
"""
import struct
import sys

NODE = 5
RPDO1, RPDO2, SDO_RX, NMT = 0x200 + NODE, 0x300 + NODE, 0x600 + NODE, 0x000


def line(t, cob, data):
    sec, usec = divmod(round(t * 1e6), 1000000)
    return "(%d.%06d) can0 %03X#%s" % (sec, usec, cob, data.hex().upper())


def rpdo1(job, start, door):
    return struct.pack("<HBB", job, start, door) + bytes(4)


def rpdo2(raw):
    return struct.pack("<h", raw) + bytes(6)


def sdo_download(index, sub, fmt, value):
    size = struct.calcsize("<" + fmt)
    command = 0x23 | (4 - size) << 2  # expedited, size indicated
    return struct.pack("<BHB", command, index, sub) + struct.pack("<" + fmt, value).ljust(4, b"\0")


def script():
    frames = [(1234.510, NMT, bytes([0x01, NODE]))]
    for k in range(20):
        frames.append((1234.520 + 0.020 * k, RPDO1, rpdo1(100 + k // 2, (k // 4) % 2, 1)))
    for k in range(21):
        raw = 6000 if k == 10 else k * 250 - 2500
        frames.append((1234.530 + 0.020 * k, RPDO2, rpdo2(raw)))
    frames += [(1234.920, RPDO1, rpdo1(10000, 1, 1)), (1234.940, RPDO1, rpdo1(10000, 0, 1))]
    for k in range(11):
        frames.append((1235.200 + 0.020 * k, RPDO1, rpdo1(150, 1, 1)))
    frames.append((1235.450, SDO_RX, sdo_download(0x2200, 1, "H", 777)))
    frames.append((1235.500, NMT, bytes([0x02, NODE])))
    frames.append((1235.600, NMT, bytes([0x01, NODE])))
    for k in range(20):
        frames.append((1235.610 + 0.020 * k, RPDO1, rpdo1(200 + k, 1, k % 3 == 0)))
    frames.append((1236.000, SDO_RX, sdo_download(0x1400, 1, "I", 0x80000000 | RPDO1)))
    frames += [(1236.010, RPDO1, rpdo1(300, 1, 1)), (1236.030, RPDO1, rpdo1(301, 1, 1))]
    frames.append((1236.100, SDO_RX, sdo_download(0x1400, 1, "I", RPDO1)))
    for k in range(10):
        frames.append((1236.110 + 0.020 * k, RPDO1, rpdo1(400 + k, k % 2, 1)))
    for k in range(10):
        frames.append((1236.200 + 0.020 * k, RPDO2, rpdo2(-k * 300)))
    return sorted(frames, key=lambda f: f[0])


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_rx_inputs.py OUT.log")
    with open(sys.argv[1], "w") as f:
        f.write("# tests/fw/make_rx_inputs.py: the manager of tests/fw/plc-inputs.ini\n")
        for t, cob, data in script():
            f.write(line(t, cob, data) + "\n")


if __name__ == "__main__":
    main()
