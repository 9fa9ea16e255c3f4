#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""rtde_plc.py: the PLC's side of docs/examples/rtde-plc.ini, in the VM of make
check-canopen (tests/canopen/rtde_plc.sh): a CANopen manager written from CiA 301,
on python-can's SocketCAN bus, that imports the node's EDS and reads TPDO1 as a PLC
would. urrt-gateway reads urrt-sim over RTDE; urrt-sim's RTDE-only values follow its
documented model (docs/tools.md): output_int_register_24 = k + 24 in package k,
robot_status_bits 3 (power on, program running), safety_status_bits 1 (normal).

Every frame on the bus from the boot-up on is kept, in bus order, with its kernel
receive stamp (SO_TIMESTAMPNS: when the node wrote it to vcan0), so that each TPDO1
is judged against what the node said at the moment it sent it.

Checks: the EDS names the three values by their RTDE names, with the scaling stated;
TPDO1's mapping; every TPDO1 received in a window, decoded by that mapping, equals the
model at some package k exactly (valid or not: a frame with valid = 0 repeats the
newest package the gateway published), k never going back, advancing at the RTDE
rate. Validity is judged by what the node knew when it sent the frame, not demanded:
- the node's EMCYs (0x080 + node) from the boot-up on are followed as CiA 301 says
  (a code starts a condition, 0x0000 ends the one named in bytes 3-4); in the window
  only 0xFF02 (data older than stale_after_ms) and 0xFF01 (robot link down) may
  start, and every reset ends a condition that was on;
- valid = 0 only while 0xFF02 or 0xFF01 is on, valid = 1 only while neither is
  (lib/urrt_co.c sends a run's EMCY before its TPDO, with the same clock: the EMCY
  that starts a condition precedes the first valid = 0 frame, its reset the first
  valid = 1 one);
- the age of each valid = 1 frame's data from the frame itself: package k is due at
  k / rate on the controller's clock, so (kernel stamp - k / rate) above its
  smallest over the connection is how old the data was when the frame went out; at
  most stale_after_ms plus SEND_SLACK_MS (the node judges at its clock read, the
  stamp is its write, and the one emulated CPU can stall in between). Valid = 0
  frames' ages are printed, not bounded: the gateway may judge data older than the
  controller's clock says (freshness.h: the host's clock too);
- at least MIN_VALID of the window's TPDO1s are valid; the counts and episodes are
  printed.
An SDO upload of 0x2100 sub 1 (the register's object) gives the model's value
between the TPDO1s around it (the last before the request, the first after the
answer). Prints "N passed, N failed" last.

  rtde_plc.py --channel vcan0 --node 5 --eds node.eds --ready FILE --rate 500 \
      --stale-after-ms 100 [--frames FILE]
--frames writes every frame kept (stamp, id, data) and the window's marks, which
judge() reads back on the host: `rtde_plc.py --judge FILE --node 5 --eds node.eds
--rate 500 --stale-after-ms 100` repeats the checks of a run without a bus.
"""
import argparse
import os
import struct
import sys
import time

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import eds  # noqa: E402

LIMIT = 30.0     # seconds the boot-up may take (the gateway's RTDE handshake included)
WINDOW = 2.0     # seconds of TPDOs read
REGISTER = 24    # output_int_register_24
ROBOT_STATUS, SAFETY_STATUS = 3, 1
EMCY_LINK, EMCY_STALE, EMCY_RESET = 0xFF01, 0xFF02, 0x0000
DATA_CONDITIONS = {EMCY_LINK, EMCY_STALE}  # link down, data stale: a robot's values not fresh
MIN_VALID = 0.8      # of the window's TPDO1s at least this share valid
SEND_SLACK_MS = 50.0  # a node preempted between judging a frame and writing it (one vCPU, TCG)


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


class Recorder:
    """Every data frame the bus hands, in bus order: (kernel stamp, id, data)."""

    def __init__(self, bus):
        self.bus = bus
        self.frames = []

    def recv_until(self, pred, limit):
        """The index of the first frame pred accepts within limit seconds, or None;
        every frame read on the way is kept."""
        end = time.monotonic() + limit
        while True:
            left = end - time.monotonic()
            msg = self.bus.recv(left) if left > 0 else None
            if msg is None:
                return None
            if msg.is_error_frame or msg.is_extended_id or msg.is_remote_frame:
                continue
            self.frames.append((msg.timestamp, msg.arbitration_id, bytes(msg.data)))
            if pred(msg.arbitration_id, bytes(msg.data)):
                return len(self.frames) - 1


def sdo_upload(rec, can, node, index, sub):
    """An expedited SDO upload (CiA 301 7.2.4.3.3): (frames index before the request,
    index of the answer, the data bytes or None)."""
    before = len(rec.frames)
    rec.bus.send(can.Message(arbitration_id=0x600 + node, is_extended_id=False,
                             data=bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])))
    at = rec.recv_until(lambda i, d: i == 0x580 + node and len(d) == 8 and d[1:4] == bytes(
        [index & 0xFF, index >> 8, sub]), 5.0)
    if at is None:
        return before, None, None
    d = rec.frames[at][2]
    if d[0] & 0xE3 not in (0x43, 0x47, 0x4B, 0x4F):
        return before, at, None
    size = 4 - ((d[0] >> 2) & 3) if d[0] & 1 else 4
    return before, at, d[4:4 + size]


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


def judge(c, frames, start, node, mapping, objs, rate, stale_ms):
    """The window's TPDO1s (frames[start:], the EMCYs followed from frames[0], the
    boot-up) against the model and against what the node said when it sent each.
    Returns [(frames index, k)] of the window's TPDO1s."""
    tpdo, emcy_id = 0x180 + node, 0x080 + node
    active, emcy_bad, started = set(), [], []
    rows = []   # (index, stamp, k, valid byte, values ok, conditions on when sent)
    for n, (t, i, d) in enumerate(frames):
        if i == emcy_id:
            code = d[0] | d[1] << 8 if len(d) == 8 else None
            if code is None:
                emcy_bad.append('%d: %s (not 8 bytes)' % (n, d.hex()))
            elif code == EMCY_RESET:
                cleared = d[3] | d[4] << 8
                if cleared not in active:
                    emcy_bad.append('%d: reset of 0x%04X, which was not on' % (n, cleared))
                active.discard(cleared)
            else:
                if n >= start and code not in DATA_CONDITIONS:
                    emcy_bad.append('%d: EMCY 0x%04X (only 0xFF01 and 0xFF02 may start here)' % (n, code))
                if n >= start and code not in active:
                    started.append(code)
                active.add(code)
        elif i == tpdo and n >= start:
            values = [v[4] for v in eds.decode(d, mapping, objs)] if len(d) == 8 else [None] * 4
            k = values[0] - REGISTER if values[0] is not None else -1
            ok = len(d) == 8 and values[1:3] == [ROBOT_STATUS, SAFETY_STATUS] and values[3] in (0, 1) and k >= 0
            rows.append((n, t, k, values[3], ok, frozenset(active), d))
    valid = [r for r in rows if r[3] == 1]
    stale = [r for r in rows if r[3] == 0]
    bad = ['%d: %s' % (r[0], r[6].hex()) for r in rows if not r[4]]
    # The age of each frame's data by its own k: the stamp less k's due time, above the
    # window's smallest (the freshest frame, a few ms after its package was due).
    # A new connection anchors the gateway's floor again (gateway/urrt-gateway/freshness.h),
    # so ours is taken per connection: the first frame after a link-down EMCY's reset
    # starts the next (the frames while it is on repeat the old connection's data).
    age, part = {}, []
    for r in [r for r in rows if r[4]] + [None]:
        if r is None or (part and EMCY_LINK not in r[5] and EMCY_LINK in part[-1][5]):
            floor = min(p[1] - p[2] / rate for p in part) if part else 0.0
            age.update({p[0]: (p[1] - p[2] / rate - floor) * 1000.0 for p in part})
            part = []
        if r is not None:
            part.append(r)
    episodes = '%d data stale (EMCY 0xFF02), %d link down (0xFF01)' % (started.count(EMCY_STALE),
                                                                      started.count(EMCY_LINK))
    print('TPDO1s in the window: %d, valid = 1: %d, valid = 0: %d; episodes: %s; '
          'age of the data by k: valid = 1 at most %.1f ms, valid = 0 at least %s ms (stale_after %d ms)'
          % (len(rows), len(valid), len(stale), episodes,
             max((age[r[0]] for r in valid if r[0] in age), default=0.0),
             '%.1f' % min(age[r[0]] for r in stale if r[0] in age) if any(r[0] in age for r in stale) else '-',
             stale_ms))
    c.check('%d TPDO1s in %.0f s' % (len(rows), WINDOW), len(rows) >= WINDOW / 0.020 / 2, str(len(rows)))
    c.check('every TPDO1: register 24 = k + 24 (k >= 0), robot_status_bits 3, safety_status_bits 1, '
            'valid 0 or 1', not bad, '; '.join(bad[:3]))
    c.check('the node\'s EMCYs: each reset ends a condition that was on; in the window only 0xFF01 and 0xFF02 start',
            not emcy_bad, '; '.join(emcy_bad[:3]))
    lying = ['%d: %s with %s on' % (r[0], r[6].hex(), ', '.join('0x%04X' % x for x in sorted(r[5])))
             for r in valid if r[5] & DATA_CONDITIONS]
    c.check('every valid = 1 TPDO1 sent while the node reported its data fresh (neither EMCY 0xFF01 nor 0xFF02 on)',
            not lying, '; '.join(lying[:3]))
    unexplained = ['%d: %s with %s' % (r[0], r[6].hex(), ', '.join('0x%04X' % x for x in sorted(r[5])) or
                                       'no EMCY on') for r in stale if not r[5] & DATA_CONDITIONS]
    c.check('every valid = 0 TPDO1 (%d) sent while the node reported its data stale or its link down '
            '(EMCY 0xFF02 or 0xFF01 on)' % len(stale), not unexplained, '; '.join(unexplained[:3]))
    old = ['%d: k %d, %.1f ms' % (r[0], r[2], age[r[0]]) for r in valid
           if r[0] in age and age[r[0]] > stale_ms + SEND_SLACK_MS]
    c.check('every valid = 1 TPDO1 carries data at most %d ms old plus %.0f, by its own k'
            % (stale_ms, SEND_SLACK_MS), not old, '; '.join(old[:3]))
    c.check('at least %.0f%% of the TPDO1s valid (%d of %d; %d valid = 0; %s)'
            % (MIN_VALID * 100, len(valid), len(rows), len(stale), episodes),
            bool(rows) and len(valid) >= MIN_VALID * len(rows))
    ks = [(r[0], r[1], r[2]) for r in rows]
    back = [(a, b) for (_, _, a), (_, _, b) in zip(ks, ks[1:]) if b < a]
    c.check('k never goes back', not back, repr(back[:3]))
    if len(ks) >= 2 and ks[-1][1] > ks[0][1]:
        seen = (ks[-1][2] - ks[0][2]) / (ks[-1][1] - ks[0][1])
        c.check('k advances at the RTDE rate (%.0f packages/s, %d expected)' % (seen, rate),
                0.5 * rate <= seen <= 1.5 * rate)
    return [(n, k) for n, _, k in ks]


def check_sdo(c, ks, before, answer, sdo):
    """The SDO's register between the last TPDO1 before the request and the first
    after the answer."""
    ok = c.check('SDO upload 0x2100 sub 1: 4 bytes', sdo is not None and len(sdo) == 4, repr(sdo))
    lo = [k for n, k in ks if n < before]
    hi = [k for n, k in ks if answer is not None and n > answer]
    if ok and lo and hi:
        k = struct.unpack('<i', sdo)[0] - REGISTER
        c.check('SDO 0x2100 sub 1 = k + 24 with k between the TPDOs around it (%d <= %d <= %d)'
                % (lo[-1], k, hi[0]), lo[-1] <= k <= hi[0])
    elif ok:
        c.check('TPDO1s before the SDO request and after its answer', False,
                '%d before, %d after' % (len(lo), len(hi)))


def write_frames(path, frames, start, before, answer, sdo):
    with open(path, 'w') as f:
        f.write('# start %d sdo %d %s %s\n' % (start, before, -1 if answer is None else answer,
                                              sdo.hex() if sdo is not None else '-'))
        for t, i, d in frames:
            f.write('%.6f %03X %s\n' % (t, i, d.hex()))


def read_frames(path):
    with open(path) as f:
        head = f.readline().split()
        frames = []
        for line in f:
            parts = line.split() + ['']
            frames.append((float(parts[0]), int(parts[1], 16), bytes.fromhex(parts[2])))
    answer = int(head[5])
    return frames, int(head[2]), int(head[4]), None if answer < 0 else answer, \
        None if head[6] == '-' else bytes.fromhex(head[6])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--channel')
    ap.add_argument('--node', type=int, required=True)
    ap.add_argument('--eds', required=True)
    ap.add_argument('--ready')
    ap.add_argument('--rate', type=int, required=True)
    ap.add_argument('--stale-after-ms', type=int, required=True)
    ap.add_argument('--frames', help='write every frame kept here')
    ap.add_argument('--judge', help='judge the frames a run wrote, without a bus')
    a = ap.parse_args()
    c = Counts()
    cp = eds.read(a.eds)
    mapping = check_eds(c, cp, a.node)
    if a.judge:
        frames, start, before, answer, sdo = read_frames(a.judge)
    else:
        import can
        bus = can.Bus(interface='socketcan', channel=a.channel, receive_own_messages=False)
        rec = Recorder(bus)
        open(a.ready, 'w').close()
        boot = rec.recv_until(lambda i, d: i == 0x700 + a.node and d == b'\x00', LIMIT)
        c.check('boot-up 0x%03X [00]' % (0x700 + a.node), boot is not None)
        # The EMCYs are followed from the boot-up, which clears the node's conditions.
        del rec.frames[:boot if boot is not None else 0]
        first = rec.recv_until(lambda i, d: i == 0x180 + a.node and d[7:8] == b'\x01', LIMIT)
        c.check('TPDO1 with valid = 1 (the RTDE session is up)', first is not None)
        start, tpdos, end = len(rec.frames), 0, time.monotonic() + WINDOW
        before, answer, sdo = None, None, None
        while time.monotonic() < end and mapping:
            if rec.recv_until(lambda i, d: i == 0x180 + a.node, end - time.monotonic()) is not None:
                tpdos += 1
            if before is None and tpdos >= 10:
                before, answer, sdo = sdo_upload(rec, can, a.node, 0x2100, 1)
        frames = rec.frames
        if a.frames:
            write_frames(a.frames, frames, start, -1 if before is None else before, answer, sdo)
    if not mapping:
        print('%d passed, %d failed' % (c.passed, c.failed))
        return 1
    ks = judge(c, frames, start, a.node, mapping, eds.objects(cp), a.rate, a.stale_after_ms)
    check_sdo(c, ks, -1 if before is None else before, answer, sdo)
    print('%d passed, %d failed' % (c.passed, c.failed))
    return 0 if c.failed == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
