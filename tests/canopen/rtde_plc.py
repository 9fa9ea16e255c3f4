#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""rtde_plc.py: the PLC's side of docs/examples/rtde-plc.ini, in the VM of make
check-canopen (tests/canopen/rtde_plc.sh): a CANopen manager written from CiA 301,
on python-can's SocketCAN bus, that imports the node's EDS and reads TPDO1 as a PLC
would. urrt-gateway reads urrt-sim over RTDE; urrt-sim's RTDE-only values follow its
documented model (docs/tools.md): output_int_register_24 = k + 24 in package k,
robot_status_bits 3 (power on, program running), safety_status_bits 1 (normal).

Checks: the EDS names the three values by their RTDE names, with the scaling stated;
TPDO1's mapping; every TPDO1 received in a window, decoded by that mapping, equals the
model at some package k, k never going back, advancing at the RTDE rate; valid = 1;
an SDO upload of 0x2100 sub 1 (the register's object) gives the model's value between
the TPDOs around it. Prints "N passed, N failed".

  rtde_plc.py --channel vcan0 --node 5 --eds node.eds --ready FILE --rate 500
"""
import argparse
import os
import struct
import sys
import time

import can

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import eds  # noqa: E402

LIMIT = 30.0     # seconds the boot-up may take (the gateway's RTDE handshake included)
WINDOW = 2.0     # seconds of TPDOs read
REGISTER = 24    # output_int_register_24
ROBOT_STATUS, SAFETY_STATUS = 3, 1


class Counts:
    def __init__(self):
        self.passed = self.failed = 0

    def check(self, desc, ok, detail=''):
        if ok:
            self.passed += 1
            print('ok: %s' % desc)
        else:
            self.failed += 1
            print('FAIL: %s%s' % (desc, (': ' + detail) if detail else ''))
        return ok


def recv_until(bus, pred, limit):
    """The first frame pred accepts within limit seconds, as (time, id, data), or None."""
    end = time.monotonic() + limit
    while True:
        left = end - time.monotonic()
        msg = bus.recv(left) if left > 0 else None
        if msg is None:
            return None
        if not msg.is_error_frame and pred(msg.arbitration_id, bytes(msg.data)):
            return (time.monotonic(), msg.arbitration_id, bytes(msg.data))


def sdo_upload(bus, node, index, sub):
    """An expedited SDO upload (CiA 301 7.2.4.3.3): the data bytes, or None."""
    bus.send(can.Message(arbitration_id=0x600 + node, is_extended_id=False,
                         data=bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])))
    f = recv_until(bus, lambda i, d: i == 0x580 + node and len(d) == 8 and d[1:4] == bytes(
        [index & 0xFF, index >> 8, sub]), 5.0)
    if f is None or f[2][0] & 0xE3 not in (0x43, 0x47, 0x4B, 0x4F):
        return None
    size = 4 - ((f[2][0] >> 2) & 3) if f[2][0] & 1 else 4
    return f[2][4:4 + size]


def check_eds(c, cp, node):
    """The EDS names the values and states their scaling; TPDO1's mapping."""
    names = {(i, s): n for i, s, n, _, _, _ in eds.variables(cp, node)}
    want = {1: 'parts: output_int_register_24, 1 = raw x 1 + 0',
            2: 'robot_status: robot_status_bits, a bit mask as the robot sends it',
            3: 'safety_status: safety_status_bits, a bit mask as the robot sends it'}
    for sub, text in want.items():
        c.check('EDS 0x2100 sub %d: %s' % (sub, text), names.get((0x2100, sub)) == text,
                repr(names.get((0x2100, sub))))
    tp = [t for t in eds.tpdos(cp, node) if t['n'] == 1]
    ok = c.check('EDS: TPDO1 at 0x%03X' % (0x180 + node), len(tp) == 1 and tp[0]['cob_id'] & 0x7FF == 0x180 + node)
    mapping = tp[0]['mapping'] if ok else []
    c.check('TPDO1 maps the register (32 bits), robot (8) and safety (16) status bits, then valid (8)',
            [(i, s, b) for i, s, b in mapping][:3] == [(0x2100, 1, 32), (0x2100, 2, 8), (0x2100, 3, 16)]
            and len(mapping) == 4 and mapping[3][2] == 8, repr(mapping))
    return mapping


def check_tpdos(c, frames, mapping, objs, rate):
    """Each TPDO1 is the model at some package k, k never going back, at the RTDE rate."""
    ks, bad = [], []
    for t, _, data in frames:
        values = [v[4] for v in eds.decode(data, mapping, objs)]
        k = values[0] - REGISTER
        if len(data) != 8 or values[1:] != [ROBOT_STATUS, SAFETY_STATUS, 1] or k < 0:
            bad.append('%s -> %r' % (data.hex(), values))
        ks.append((t, k))
    c.check('%d TPDO1s in %.0f s' % (len(frames), WINDOW), len(frames) >= WINDOW / 0.020 / 2, str(len(frames)))
    c.check('every TPDO1: register 24 = k + 24 (k >= 0), robot_status_bits 3, safety_status_bits 1, valid 1',
            not bad, '; '.join(bad[:3]))
    back = [(a, b) for (_, a), (_, b) in zip(ks, ks[1:]) if b < a]
    c.check('k never goes back', not back, repr(back[:3]))
    if len(ks) >= 2 and ks[-1][0] > ks[0][0]:
        seen = (ks[-1][1] - ks[0][1]) / (ks[-1][0] - ks[0][0])
        c.check('k advances at the RTDE rate (%.0f packages/s, %d expected)' % (seen, rate),
                0.5 * rate <= seen <= 1.5 * rate)
    return ks


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--channel', required=True)
    ap.add_argument('--node', type=int, required=True)
    ap.add_argument('--eds', required=True)
    ap.add_argument('--ready', required=True)
    ap.add_argument('--rate', type=int, required=True)
    a = ap.parse_args()
    c = Counts()
    bus = can.Bus(interface='socketcan', channel=a.channel, receive_own_messages=False)
    open(a.ready, 'w').close()
    cp = eds.read(a.eds)
    mapping = check_eds(c, cp, a.node)
    boot = recv_until(bus, lambda i, d: i == 0x700 + a.node and d == b'\x00', LIMIT)
    c.check('boot-up 0x%03X [00]' % (0x700 + a.node), boot is not None)
    first = recv_until(bus, lambda i, d: i == 0x180 + a.node and d[7:8] == b'\x01', LIMIT)
    c.check('TPDO1 with valid = 1 (the RTDE session is up)', first is not None)
    frames, end = [], time.monotonic() + WINDOW
    sdo_at, sdo = None, None
    while time.monotonic() < end and mapping:
        f = recv_until(bus, lambda i, d: i == 0x180 + a.node, end - time.monotonic())
        if f is not None:
            frames.append(f)
        if sdo_at is None and len(frames) >= 10:
            sdo_at = len(frames)
            sdo = sdo_upload(bus, a.node, 0x2100, 1)
    if not mapping:
        print('%d passed, %d failed' % (c.passed, c.failed))
        return 1
    ks = check_tpdos(c, frames, mapping, eds.objects(cp), a.rate)
    ok = c.check('SDO upload 0x2100 sub 1: 4 bytes', sdo is not None and len(sdo) == 4, repr(sdo))
    if ok and sdo_at is not None and sdo_at < len(ks):
        k = struct.unpack('<i', sdo)[0] - REGISTER
        lo, hi = ks[sdo_at - 1][1], ks[sdo_at][1]
        c.check('SDO 0x2100 sub 1 = k + 24 with k between the TPDOs around it (%d <= %d <= %d)' % (lo, k, hi),
                lo <= k <= hi)
    print('%d passed, %d failed' % (c.passed, c.failed))
    return 0 if c.failed == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
