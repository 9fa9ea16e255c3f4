# SPDX-License-Identifier: MIT
"""master.py: a CANopen manager for the test, written from CiA 301 (not from the
node's code), on python-can's SocketCAN bus. It does what a PLC's manager does
with urrt-gateway's node, step by step, and checks every answer:

  1 boot-up            2 identity reads     3 heartbeat time and event timer
  4 bad SDO requests   5 operational: TPDOs decoded by the EDS's mapping
  6 SYNC counting, and the SYNC moved (0x1005)      7 stopped: only heartbeats
  8 reset node / communication: boot-up again
  9 the robot link cut (--cut) and back (--restore): EMCY, 0x1001, 0x1003

Every wait is for a frame, bounded by a limit; an absence is checked up to a
fence, an SDO answer that must come after what the node was asked before
(the node serves its frames in order). Writes OUT/tpdos.jsonl (the decoded
TPDOs, for the host's DBC comparison) and OUT/expect.json (what each frame
of the run should be, for the host's tshark check). Prints "N passed, N failed".

  master.py --channel vcan0 --node 5 --eds node.eds --out DIR --ready FILE \
            --cut 'CMD' --restore 'CMD'
"""
import argparse
import json
import os
import random
import shlex
import struct
import subprocess
import sys
import time

import can

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import eds  # noqa: E402

LIMIT = 10.0          # seconds any single awaited frame may take, at most
NMT, SYNC_ID = 0x000, 0x080
ABORTS = {
    0x05030000: 'toggle bit not alternated', 0x05040000: 'SDO protocol timed out',
    0x05040001: 'command specifier not valid or unknown', 0x06010001: 'read of a write-only object',
    0x06010002: 'write to a read-only object', 0x06020000: 'object does not exist',
    0x06070010: 'data type length does not match', 0x06070012: 'data type length too high',
    0x06070013: 'data type length too low', 0x06090011: 'sub-index does not exist',
    0x06090030: 'value range exceeded', 0x06090031: 'value too high', 0x06090032: 'value too low',
}


class Abort(Exception):
    def __init__(self, index, sub, code):
        super().__init__('SDO abort 0x%08X (%s) for 0x%04X sub %d' % (code, ABORTS.get(code, '?'), index, sub))
        self.index, self.sub, self.code = index, sub, code


class Missing(Exception):
    pass


class Master:
    def __init__(self, channel, node_id):
        self.bus = can.Bus(interface='socketcan', channel=channel, receive_own_messages=False)
        self.node = node_id
        self.frames = []      # (time, id, data) of everything seen from the node
        self.passed = self.failed = 0
        # What the run must show on the bus, for the host's tshark check (expect.json).
        self.expect = {'aborts': [], 'emcy': [], 'bootups': 0, 'pdo_ids': [], 'sync_ids': []}

    # ---- counting ----
    def check(self, desc, ok, detail=''):
        if ok:
            self.passed += 1
            print('ok: %s' % desc)
        else:
            self.failed += 1
            print('FAIL: %s%s' % (desc, (': ' + detail) if detail else ''))
        sys.stdout.flush()
        return ok

    # ---- frames ----
    def send(self, cob_id, data):
        self.bus.send(can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False))

    def recv(self, limit):
        """The next frame from the bus (kept in self.frames), or None at the limit."""
        msg = self.bus.recv(limit)
        if msg is None:
            return None
        if msg.is_error_frame or msg.is_remote_frame or msg.is_extended_id:
            return self.recv(limit)
        f = (msg.timestamp, msg.arbitration_id, bytes(msg.data))
        self.frames.append(f)
        return f

    def wait(self, what, pred, limit=LIMIT):
        """The first frame pred accepts (the frames before it stay in self.frames only).
        Raises Missing at the limit."""
        end = time.monotonic() + limit
        while True:
            left = end - time.monotonic()
            f = self.recv(left) if left > 0 else None
            if f is None:
                raise Missing('no %s within %.0f s' % (what, limit))
            if pred(f):
                return f

    def collect_until(self, pred, limit=LIMIT):
        """Every frame up to and including the first one pred accepts."""
        got = []
        end = time.monotonic() + limit
        while time.monotonic() < end:
            f = self.recv(end - time.monotonic())
            if f is None:
                break
            got.append(f)
            if pred(f):
                return got
        raise Missing('the awaited frame did not come within %.0f s' % limit)

    def heartbeat(self, state=None):
        n = self.node

        def pred(f):
            return f[1] == 0x700 + n and len(f[2]) == 1 and (state is None or f[2][0] == state)
        return pred

    def nmt(self, cs, node=None):
        self.send(NMT, [cs, self.node if node is None else node])

    # ---- SDO client ----
    def sdo(self, request, limit=LIMIT):
        """One request, its one answer."""
        self.send(0x600 + self.node, request)
        return self.wait('SDO answer to %s' % bytes(request).hex(), lambda f: f[1] == 0x580 + self.node, limit)[2]

    def upload(self, index, sub):
        """A read, expedited or segmented: (bytes, segmented)."""
        ans = self.sdo([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])
        if ans[0] == 0x80:
            raise Abort(index, sub, struct.unpack_from('<I', ans, 4)[0])
        if (ans[0] & 0xE0) != 0x40 or ans[1] != (index & 0xFF) or ans[2] != index >> 8 or ans[3] != sub:
            raise AssertionError('bad upload answer %s' % ans.hex())
        if ans[0] & 0x02:  # expedited
            size = 4 - ((ans[0] >> 2) & 3) if ans[0] & 0x01 else 4
            return ans[4:4 + size], False
        size = struct.unpack_from('<I', ans, 4)[0] if ans[0] & 0x01 else None
        data, toggle = b'', 0
        while True:
            seg = self.sdo([0x60 | toggle << 4, 0, 0, 0, 0, 0, 0, 0])
            if seg[0] == 0x80:
                raise Abort(index, sub, struct.unpack_from('<I', seg, 4)[0])
            if (seg[0] & 0xE0) != 0x00 or (seg[0] >> 4) & 1 != toggle:
                raise AssertionError('bad segment %s' % seg.hex())
            data += seg[1:8 - ((seg[0] >> 1) & 7)]
            if seg[0] & 0x01:
                break
            toggle ^= 1
        if size is not None and size != len(data):
            raise AssertionError('segmented upload: %d bytes announced, %d came' % (size, len(data)))
        return data, True

    def download(self, index, sub, data):
        """An expedited write of 1..4 bytes."""
        cs = 0x23 | (4 - len(data)) << 2
        ans = self.sdo([cs, index & 0xFF, index >> 8, sub] + list(data) + [0] * (4 - len(data)))
        if ans[0] == 0x80:
            raise Abort(index, sub, struct.unpack_from('<I', ans, 4)[0])
        if bytes(ans[:4]) != bytes([0x60, index & 0xFF, index >> 8, sub]):
            raise AssertionError('bad download answer %s' % ans.hex())

    def read_u(self, index, sub):
        return int.from_bytes(self.upload(index, sub)[0], 'little')

    def write_u(self, index, sub, value, size):
        self.download(index, sub, list(value.to_bytes(size, 'little')))

    def fence(self):
        """An SDO round trip: everything the node sent for earlier frames came before it."""
        return self.read_u(0x1000, 0)

    def expect_abort(self, desc, request, code, index=None, sub=None):
        ans = self.sdo(request)
        got = struct.unpack_from('<I', ans, 4)[0] if ans[0] == 0x80 else None
        idx = index if index is not None else request[1] | request[2] << 8
        sb = sub if sub is not None else request[3]
        ok = got == code and ans[1] | ans[2] << 8 == idx and ans[3] == sb
        self.expect['aborts'].append(code)
        self.check('%s: abort 0x%08X' % (desc, code), ok, 'answer %s' % ans.hex())


def step_boot(m, cp):
    f = m.wait('boot-up 0x%03X [00]' % (0x700 + m.node), m.heartbeat(0x00), limit=60)
    m.expect['bootups'] += 1
    m.check('boot-up 0x%03X [00]' % (0x700 + m.node), f is not None)
    hb = m.wait('heartbeat', m.heartbeat())
    m.check('first heartbeat: pre-operational (0x7F)', hb[2][0] == 0x7F, hb[2].hex())


def step_identity(m, cp):
    objs = eds.objects(cp)

    def default(index, sub):
        return eds.resolve(objs[(index, sub)]['DefaultValue'], m.node)
    got = m.read_u(0x1000, 0)
    m.check('0x1000 device type = the EDS (0x%08X)' % default(0x1000, 0), got == default(0x1000, 0), hex(got))
    count = m.read_u(0x1018, 0)
    m.check('0x1018 sub 0 = 4', count == 4, str(count))
    for sub, name in ((1, 'vendor id'), (2, 'product code'), (3, 'revision'), (4, 'serial number')):
        got = m.read_u(0x1018, sub)
        m.check('0x1018 sub %d %s = the EDS (0x%08X)' % (sub, name, default(0x1018, sub)),
                got == default(0x1018, sub), hex(got))
    name, segmented = m.upload(0x1008, 0)
    want = objs[(0x1008, 0)]['DefaultValue']
    m.check('0x1008 device name "%s" by segmented upload' % want, segmented and name.decode('latin-1') == want,
            repr(name))


def step_every_object(m, cp):
    """Every object the EDS names, read: the declared type's size (strings: the
    default's length); write-only ones refused with 0x06010001."""
    for index, sub, pname, dtype, access, default in eds.variables(cp, m.node):
        what = '0x%04X sub %d (%s)' % (index, sub, pname)
        try:
            data, _ = m.upload(index, sub)
        except Abort as a:
            if access == 'wo':
                m.check('%s write-only: read refused' % what, a.code == 0x06010001, hex(a.code))
            elif index == 0x1003 and a.code == 0x08000024:
                m.check('%s: past the errors recorded (0x08000024)' % what, True)
            else:
                m.check('%s readable' % what, False, str(a))
            continue
        size = eds.DATA_TYPES.get(dtype, ('?', None))[1]
        if size == 0:
            m.check('%s: a string of its default\'s length' % what, len(data) == len(str(default)), repr(data))
        else:
            m.check('%s: %s, %s bytes' % (what, eds.DATA_TYPES.get(dtype, ('?',))[0], size), len(data) == size,
                    data.hex())
        if access in ('ro', 'const', 'rw') and isinstance(default, int) and not (0x2000 <= index < 0x6000) \
                and index not in (0x1001, 0x1003):
            got = int.from_bytes(data, 'little', signed=dtype in eds.SIGNED)
            m.check('%s = its EDS default %d' % (what, default), got == default, str(got))


def heartbeats_in_timeout_window(m):
    """Heartbeats the node sends while its own SDO timeout runs (a segmented upload
    left open until the node aborts it with 0x05040000): a window on the node's clock."""
    ans = m.sdo([0x40, 0x08, 0x10, 0, 0, 0, 0, 0])
    m.check('0x1008: a segmented upload starts', ans[0] == 0x41, ans.hex())
    got = m.collect_until(lambda f: f[1] == 0x580 + m.node, limit=30)
    end = got[-1][2]
    code = struct.unpack_from('<I', end, 4)[0] if end[0] == 0x80 else None
    m.check('a segmented upload left open: abort 0x05040000 (SDO timeout) for 0x1008',
            code == 0x05040000 and end[1:4] == bytes([0x08, 0x10, 0]), end.hex())
    return sum(1 for f in got if m.heartbeat()(f))


def step_heartbeat_time(m, cp):
    default = m.read_u(0x1017, 0)
    m.write_u(0x1017, 0, 0, 2)
    m.check('0x1017 written 0, read back 0', m.read_u(0x1017, 0) == 0)
    n = heartbeats_in_timeout_window(m)
    m.check('0x1017 = 0: no heartbeat through the SDO timeout', n == 0, '%d heartbeats' % n)
    m.write_u(0x1017, 0, 50, 2)
    n = heartbeats_in_timeout_window(m)
    m.check('0x1017 = 50 ms: heartbeats through the SDO timeout (%d)' % n, n >= 4, '%d heartbeats' % n)
    m.write_u(0x1017, 0, 5000, 2)
    n = heartbeats_in_timeout_window(m)
    m.check('0x1017 = 5000 ms: no heartbeat within the SDO timeout', n == 0, '%d heartbeats' % n)
    m.write_u(0x1017, 0, 50, 2)
    m.wait('heartbeat after 0x1017 = 50', m.heartbeat())
    m.check('0x1017 back to a 50 ms heartbeat (default %d)' % default, True)


def step_bad_requests(m, cp):
    objs = eds.objects(cp)
    r = lambda *b: list(b) + [0] * (8 - len(b))  # noqa: E731
    m.expect_abort('read of 0x1234 (no such object)', r(0x40, 0x34, 0x12, 0), 0x06020000)
    m.expect_abort('read of 0x1018 sub 9', r(0x40, 0x18, 0x10, 9), 0x06090011)
    m.expect_abort('write of 0x1000 (read-only)', r(0x23, 0x00, 0x10, 0, 1, 2, 3, 4), 0x06010002)
    m.expect_abort('write of 0x1018 sub 1 (read-only)', r(0x23, 0x18, 0x10, 1, 1, 2, 3, 4), 0x06010002)
    wo = [k for k, s in objs.items() if k[1] is not None and s.get('AccessType', '').lower() == 'wo']
    if wo:
        m.expect_abort('read of write-only 0x%04X sub %d' % wo[0], r(0x40, wo[0][0] & 0xFF, wo[0][0] >> 8, wo[0][1]),
                       0x06010001)
    else:
        print('note: the EDS has no write-only object: 0x06010001 is not reachable here')
    m.expect_abort('request of 5 bytes', [0x40, 0x00, 0x10, 0, 0], 0x06070010)
    m.expect_abort('4 bytes to 0x1017 (UNSIGNED16)', r(0x23, 0x17, 0x10, 0, 50, 0, 0, 0), 0x06070012)
    m.expect_abort('1 byte to 0x1017 (UNSIGNED16)', r(0x2F, 0x17, 0x10, 0, 50), 0x06070013)
    tp = eds.tpdos(cp, m.node)[0]
    comm = 0x1800 + tp['n'] - 1
    lo, hi = comm & 0xFF, comm >> 8
    m.expect_abort('TPDO%d COB-ID changed while valid' % tp['n'], r(0x23, lo, hi, 1, 0x7E, 0x01, 0, 0), 0x06090030)
    m.expect_abort('TPDO%d transmission type 241' % tp['n'], r(0x2F, lo, hi, 2, 241), 0x06090031)
    m.expect_abort('TPDO%d transmission type 0' % tp['n'], r(0x2F, lo, hi, 2, 0), 0x06090032)
    m.expect_abort('segmented download (0x21)', r(0x21, 0x17, 0x10, 0, 2, 0, 0, 0), 0x05040001)
    m.expect_abort('block upload (0xA0)', r(0xA0, 0x08, 0x10, 0, 0x7F), 0x05040001)
    m.expect_abort('command specifier 7 (0xE0)', r(0xE0, 0x00, 0x10, 0), 0x05040001)
    m.expect_abort('upload segment without an upload', r(0x60), 0x05040001, 0, 0)
    ans = m.sdo(r(0x40, 0x08, 0x10, 0))
    m.check('0x1008 segmented upload starts', ans[0] == 0x41, ans.hex())
    m.expect_abort('first segment with toggle 1', r(0x70), 0x05030000, 0x1008, 0)
    m.sdo(r(0x40, 0x08, 0x10, 0))
    m.expect_abort('a new request in a segmented upload', r(0x40, 0x00, 0x10, 0), 0x05040001, 0x1008, 0)
    m.check('the retried request is served', m.read_u(0x1000, 0) >= 0)
    step_random_requests(m)


def step_random_requests(m):
    """Whatever 8 bytes arrive: one answer each (none for a client's abort), and the
    node still serves."""
    rng = random.Random(18)
    wrong = 0
    for _ in range(300):
        req = [rng.randrange(256) for _ in range(8)]
        if req[0] >> 5 == 1 and 0x10 <= req[2] <= 0x1F:
            req[2] = 0x30  # no writes to the communication objects: the later steps rely on them
        if req[0] >> 5 == 4:
            continue  # a client's abort: no answer
        m.send(0x600 + m.node, req)
        try:
            m.wait('answer', lambda f: f[1] == 0x580 + m.node)
        except Missing:
            wrong += 1
    m.send(0x600 + m.node, [0x80] + [0] * 7)  # ends a transfer a random request began
    m.check('300 random SDO requests: one answer each', wrong == 0, '%d unanswered' % wrong)
    m.check('the node serves after them', m.read_u(0x1000, 0) >= 0)


def tpdo_pred(tps):
    ids = {t['cob_id'] & 0x7FF: t for t in tps if not t['cob_id'] & 0x80000000}
    return ids, (lambda f: f[1] in ids)


def step_operational(m, cp, out):
    tps = eds.tpdos(cp, m.node)
    objs = eds.objects(cp)
    ids, is_tpdo = tpdo_pred(tps)
    m.nmt(0x01)
    m.wait('heartbeat 0x05', m.heartbeat(0x05))
    m.check('started: heartbeat operational (0x05)', True)
    event = [t for t in tps if t['type'] >= 254 and not t['cob_id'] & 0x80000000]
    seen = {}
    with open(os.path.join(out, 'tpdos.jsonl'), 'w') as f:
        def record(fr):
            t = ids[fr[1]]
            seen[t['n']] = seen.get(t['n'], 0) + 1
            values = eds.decode(fr[2], t['mapping'], objs)
            f.write(json.dumps({'n': t['n'], 'id': fr[1], 'time': fr[0], 'data': fr[2].hex(),
                                'values': values}) + '\n')
        need = {t['n'] for t in event}
        end = time.monotonic() + 30
        while (need - {n for n, c in seen.items() if c >= 20}) and time.monotonic() < end:
            fr = m.wait('TPDO', is_tpdo)
            record(fr)
        m.check('every event-driven TPDO came 20 times or more (%s)' % seen,
                not need - {n for n, c in seen.items() if c >= 20})
        lengths = {t['n']: (sum(b for _, _, b in t['mapping']) + 7) // 8 for t in tps}
        m.check('each TPDO as long as its mapping', all(
            len(fr[2]) == lengths[ids[fr[1]]['n']] for fr in m.frames if fr[1] in ids), str(lengths))
        step_pdo_configuration(m, tps)
        step_event_timer(m, event[0])
        step_sync(m, tps, record)


def step_pdo_configuration(m, tps):
    """What a manager writes at boot: a TPDO the EDS declares off (COB-ID bit 31)
    enabled; a TPDO moved to another COB-ID by CiA 301's sequence (bit 31 set, the
    new id, bit 31 clear), its frames seen there, then moved back; the same with
    the new id in the disabling write (python-canopen's PdoMap.save)."""
    for t in [t for t in tps if t['cob_id'] & 0x80000000]:
        index, cob = 0x1800 + t['n'] - 1, t['cob_id'] & 0x7FF
        m.write_u(index, 1, cob, 4)
        m.wait('TPDO%d at 0x%03X once enabled' % (t['n'], cob), lambda f: f[1] == cob)
        m.check('TPDO%d enabled by its COB-ID (0x%03X): it comes' % (t['n'], cob), True)
        m.write_u(index, 1, t['cob_id'], 4)
    t = [t for t in tps if t['type'] >= 254 and not t['cob_id'] & 0x80000000][0]
    index, old, new = 0x1800 + t['n'] - 1, t['cob_id'], 0x1A0 + m.node
    m.expect['pdo_ids'].append(new)
    m.expect_abort('TPDO%d: a new COB-ID while valid' % t['n'], [0x23, index & 0xFF, index >> 8, 1] +
                   list(new.to_bytes(4, 'little')), 0x06090030)
    for value in (old | 0x80000000, new | 0x80000000, new):
        m.write_u(index, 1, value, 4)
    m.wait('TPDO%d at its new COB-ID 0x%03X' % (t['n'], new), lambda f: f[1] == new)
    for value in (new | 0x80000000, old | 0x80000000, old):
        m.write_u(index, 1, value, 4)
    m.fence()
    m.wait('TPDO%d back at 0x%03X' % (t['n'], old & 0x7FF), lambda f: f[1] == old & 0x7FF)
    m.check('TPDO%d moved to 0x%03X and back by the bit 31 sequence' % (t['n'], new), True)
    # python-canopen's PdoMap.save: disabled and given the new id in one write, then enabled.
    m.check('TPDO%d COB-ID 0x%08X reads bit 30 set (no RTR)' % (t['n'], old), (m.read_u(index, 1) & 0x40000000) != 0)
    for value in (new | 0xC0000000, new | 0x40000000):
        m.write_u(index, 1, value, 4)
    m.wait('TPDO%d at 0x%03X after one disabling write' % (t['n'], new), lambda f: f[1] == new)
    for value in (old | 0x80000000, old):
        m.write_u(index, 1, value, 4)
    m.fence()
    m.wait('TPDO%d back at 0x%03X' % (t['n'], old & 0x7FF), lambda f: f[1] == old & 0x7FF)
    m.check('TPDO%d moved to 0x%03X and back, each in one write with bit 31' % (t['n'], new), True)


def tpdos_per_heartbeats(m, cob_id, beats):
    """TPDO n's frames between one heartbeat and the beats-th after it: the node's clock."""
    m.wait('heartbeat', m.heartbeat(0x05))
    count = 0
    for _ in range(beats):
        for fr in m.collect_until(m.heartbeat(0x05)):
            if fr[1] == cob_id:
                count += 1
    return count


def step_event_timer(m, t):
    index = 0x1800 + t['n'] - 1
    cob = t['cob_id'] & 0x7FF
    was = m.read_u(index, 5)
    m.write_u(index, 5, 10, 2)
    fast = tpdos_per_heartbeats(m, cob, 8)
    m.write_u(index, 5, 200, 2)
    m.check('TPDO%d event timer read back 200' % t['n'], m.read_u(index, 5) == 200)
    m.wait('heartbeat', m.heartbeat(0x05))
    slow = tpdos_per_heartbeats(m, cob, 8)
    m.check('TPDO%d event timer 10 ms: 20 or more per 8 heartbeats of 50 ms (%d)' % (t['n'], fast), fast >= 20)
    m.check('TPDO%d event timer 200 ms: 4 or fewer per 8 heartbeats of 50 ms (%d)' % (t['n'], slow), slow <= 4)
    # 0: no timer, the TPDO goes with each packet (urrt-sim at 125 Hz: 50 in 400 ms); the
    # inhibit time (written while the PDO is invalid) then caps it at one per 20 ms.
    m.write_u(index, 5, 0, 2)
    m.wait('heartbeat', m.heartbeat(0x05))
    packets = tpdos_per_heartbeats(m, cob, 8)
    m.check('TPDO%d event timer 0: one per packet, 30 or more per 8 heartbeats (%d)' % (t['n'], packets),
            packets >= 30)
    for sub, value, size in ((1, t['cob_id'] | 0x80000000, 4), (3, 200, 2), (1, t['cob_id'], 4)):
        m.write_u(index, sub, value, size)
    m.wait('heartbeat', m.heartbeat(0x05))
    gapped = tpdos_per_heartbeats(m, cob, 8)
    m.check('TPDO%d inhibit time 20 ms: 10..21 per 8 heartbeats of 50 ms (%d)' % (t['n'], gapped),
            10 <= gapped <= 21)
    for sub, value, size in ((1, t['cob_id'] | 0x80000000, 4), (3, 0, 2), (1, t['cob_id'], 4)):
        m.write_u(index, sub, value, size)
    m.write_u(index, 5, was, 2)


def step_sync(m, tps, record):
    synced = [t for t in tps if 1 <= t['type'] <= 240 and not t['cob_id'] & 0x80000000]
    if not m.check('the EDS has a SYNC-driven TPDO', bool(synced)):
        return
    t = synced[0]
    index, cob = 0x1800 + t['n'] - 1, t['cob_id'] & 0x7FF
    for every, syncs in ((1, 10), (3, 9)):
        m.write_u(index, 2, every, 1)
        m.fence()
        count = 0
        for i in range(syncs):
            m.send(SYNC_ID, [])
            m.send(0x600 + m.node, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])  # the fence after it
            got = m.collect_until(lambda f: f[1] == 0x580 + m.node)
            for fr in got:
                if fr[1] == cob:
                    count += 1
                    record(fr)
        m.check('TPDO%d, transmission type %d: %d frames for %d SYNCs' % (t['n'], every, syncs // every, syncs),
                count == syncs // every, '%d frames' % count)
    m.write_u(index, 2, 1, 1)
    step_sync_moved(m, cob, record)
    m.write_u(index, 2, t['type'], 1)


def step_sync_moved(m, cob, record):
    """0x1005 moved to 0x081 (CiA 301: the SYNC's COB-ID is the manager's to set): a
    SYNC there gets the synchronous TPDO (type 1), one on 0x080 none; then back."""
    def tpdos_after_sync(sync_id, rounds):
        count = 0
        for _ in range(rounds):
            m.send(sync_id, [])
            m.send(0x600 + m.node, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])  # the fence after it
            for fr in m.collect_until(lambda f: f[1] == 0x580 + m.node):
                if fr[1] == cob:
                    count += 1
                    record(fr)
        return count
    moved = 0x081
    m.write_u(0x1005, 0, moved, 4)  # the SYNC id leaves 0x080 at once: the node's filter follows
    m.expect['sync_ids'].append(moved)
    got = m.read_u(0x1005, 0)
    m.check('0x1005 read back 0x%08X' % moved, got == moved, '0x%08X' % got)
    n = tpdos_after_sync(moved, 5)
    m.check('SYNC on the new id 0x%03X: the TPDO each time (%d of 5)' % (moved, n), n == 5)
    n = tpdos_after_sync(SYNC_ID, 5)
    m.check('SYNC on the old id 0x%03X: no TPDO (%d)' % (SYNC_ID, n), n == 0)
    m.write_u(0x1005, 0, SYNC_ID, 4)
    n = tpdos_after_sync(SYNC_ID, 3)
    m.check('0x1005 back to 0x%03X: the TPDO each time (%d of 3)' % (SYNC_ID, n), n == 3)


def step_stopped(m, cp):
    m.nmt(0x02)
    m.wait('heartbeat 0x04', m.heartbeat(0x04))
    m.send(0x600 + m.node, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
    got = []
    for _ in range(6):
        got += m.collect_until(m.heartbeat())
    other = [f for f in got if not m.heartbeat(0x04)(f)]
    m.check('stopped: only heartbeats 0x04 over 6 heartbeats (SDO ignored)', not other,
            ' '.join('%03X#%s' % (f[1], f[2].hex()) for f in other[:5]))


def step_reset(m, cp):
    for cs, name in ((0x82, 'reset communication'), (0x81, 'reset node')):
        m.nmt(cs)
        m.wait('boot-up after %s' % name, m.heartbeat(0x00))
        m.expect['bootups'] += 1
        hb = m.wait('heartbeat after the boot-up', m.heartbeat())
        m.check('%s: boot-up, then pre-operational (0x%02X)' % (name, hb[2][0]), hb[2][0] == 0x7F)
    objs = eds.objects(cp)
    want = eds.resolve(objs[(0x1017, 0)]['DefaultValue'], m.node)
    m.check('reset node: 0x1017 back to its EDS default %d' % want, m.read_u(0x1017, 0) == want)
    m.nmt(0x01, node=0)
    m.wait('heartbeat 0x05 after start to all (node 0)', m.heartbeat(0x05))
    m.check('NMT start to node 0 (all) starts it', True)


def run_cmd(cmd):
    subprocess.run(shlex.split(cmd), check=True, timeout=60)


def emcy_pred(m, code=None):
    return lambda f: f[1] == 0x80 + m.node and len(f[2]) == 8 and (code is None or f[2][0] | f[2][1] << 8 == code)


def step_robot_cut(m, cp, cut, restore):
    m.write_u(0x1003, 0, 0, 1)
    run_cmd(cut)
    f = m.wait('EMCY 0xFF01 (robot link lost)', emcy_pred(m, 0xFF01), limit=30)
    m.check('EMCY 0xFF01: robot link lost, error register 0x81', f[2][2] & 0x81 == 0x81, f[2].hex())
    reg = m.read_u(0x1001, 0)
    m.check('0x1001 error register: generic and manufacturer bits (0x%02X)' % reg, reg & 0x81 == 0x81)
    n = m.read_u(0x1003, 0)
    codes = [m.read_u(0x1003, s) & 0xFFFF for s in range(1, n + 1)]
    m.check('0x1003 holds 0xFF01 (%s)' % [hex(c) for c in codes], 0xFF01 in codes)
    run_cmd(restore)
    reset = m.wait('EMCY reset of 0xFF01', lambda fr: emcy_pred(m, 0x0000)(fr) and fr[2][3:5] == b'\x01\xff',
                   limit=60)
    m.check('EMCY 0x0000 clears 0xFF01', True, reset[2].hex())
    m.expect['emcy'] += [0xFF01, 0x0000]
    end = time.monotonic() + 30
    while m.read_u(0x1001, 0) != 0 and time.monotonic() < end:
        m.wait('EMCY reset', emcy_pred(m, 0x0000), limit=30)
    m.check('0x1001 error register back to 0 once the robot is back', m.read_u(0x1001, 0) == 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--channel', default='vcan0')
    ap.add_argument('--node', type=int, required=True)
    ap.add_argument('--eds', required=True)
    ap.add_argument('--out', required=True)
    ap.add_argument('--ready', help='file created once the bus is open')
    ap.add_argument('--cut', required=True, help='command that cuts the robot link')
    ap.add_argument('--restore', required=True, help='command that brings it back')
    a = ap.parse_args()
    cp = eds.read(a.eds)
    m = Master(a.channel, a.node)
    if a.ready:
        open(a.ready, 'w').close()
    steps = [('1 boot-up', lambda: step_boot(m, cp)), ('2 identity', lambda: step_identity(m, cp)),
             ('2b every object of the EDS', lambda: step_every_object(m, cp)),
             ('3 heartbeat time', lambda: step_heartbeat_time(m, cp)),
             ('4 bad requests', lambda: step_bad_requests(m, cp)),
             ('5-6 operational, event timer, SYNC', lambda: step_operational(m, cp, a.out)),
             ('7 stopped', lambda: step_stopped(m, cp)), ('8 reset', lambda: step_reset(m, cp)),
             ('9 robot link cut', lambda: step_robot_cut(m, cp, a.cut, a.restore))]
    for name, fn in steps:
        print('== step %s' % name)
        sys.stdout.flush()
        try:
            fn()
        except (Missing, Abort, AssertionError, subprocess.SubprocessError) as e:
            m.check('step %s' % name, False, str(e))
            if name.startswith('1 '):
                break
    with open(os.path.join(a.out, 'expect.json'), 'w') as f:
        json.dump(m.expect, f)
    m.bus.shutdown()
    print('%d passed, %d failed' % (m.passed, m.failed))
    return 0 if m.failed == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
