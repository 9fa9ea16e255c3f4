#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""plc_io_co.py: the CANopen manager of docs/examples/plc-io-canopen.ini, in the VM of
make check-canopen (tests/canopen/plc_io_co.sh): master.py's CiA 301 client for SDO
and NMT, its own sender of RPDO1 and of the manager's heartbeat, and plc_io.py's proxy
between urrt-gateway and urrt-sim's RTDE port, which keeps every package the gateway
sends. Written from CiA 301 and the example's layout, apart from the gateway's code.

RPDO1 (0x205): job_number UNSIGNED16 in bytes 0-1, start and door_closed one byte each
(2, 3), dummy bytes 4-7. TPDO1 (0x185): program_state INTEGER32 (bytes 0-3), job_echo
UNSIGNED16 (4-5), robot_status (6), valid (7).

Steps, each with its checks:
  configure  boot-up; RPDO1's COB-ID, type, event timer and mapping read by SDO; the
             manager's heartbeat set in 0x1016 sub 1; NMT start
  nothing    the session is V v O I S and nothing is written before RPDO1 comes
  follow     RPDO1 every 20 ms, a new job every 100 ms: each job reaches an input
             package and comes back in TPDO1's job_echo (the round trip)
  sdo        RPDO1 stops and the manager writes 0x2200 sub 1..3 by SDO instead: the
             registers follow; the RPDO deadline's EMCY 0x8250 comes once
  deadline   neither: the packages stop within timeout_ms
  heartbeat  the manager's heartbeat stops while RPDO1 goes on: EMCY 0x8130, and the
             packages stop; back: they go again
  nmt        NMT stop: the packages stop; start: they go again
  short      an RPDO1 shorter than its mapping: EMCY 0x8210, not processed
  refused    start = 2 (a BOOLEAN takes 0 or 1): the node refuses it, and once that
             register's last value is older than timeout_ms, nothing is written
Prints "N passed, N failed" last.

  plc_io_co.py --channel vcan0 --node 5 --sim-port P --proxy-port-file F --ready F --rate 125
"""
import argparse
import os
import statistics
import struct
import sys
import threading
import time

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import master  # noqa: E402
import plc_io  # noqa: E402

MANAGER = 1                   # the manager's node id: its heartbeat is 0x701
MANAGER_HB_MS = 100           # how often it sends it
CONSUMER_MS = 300             # what 0x1016 sub 1 allows
TIMEOUT_MS = 100              # [input plc_command] timeout_ms: RPDO1's event timer
PERIOD = 0.020
SLACK = plc_io.SLACK
EMCY_DEADLINE, EMCY_LENGTH, EMCY_HEARTBEAT = 0x8250, 0x8210, 0x8130


class Bus:
    """RPDO1 and the manager's heartbeat on a timer, TPDO1 and the node's EMCYs kept."""

    def __init__(self, channel, node):
        import can
        self.can = can
        self.node = node
        self.tx = can.Bus(interface='socketcan', channel=channel, receive_own_messages=False)
        self.rx = can.Bus(interface='socketcan', channel=channel, receive_own_messages=False,
                          can_filters=[{'can_id': 0x180 + node, 'can_mask': 0x7FF, 'extended': False},
                                       {'can_id': 0x080 + node, 'can_mask': 0x7FF, 'extended': False}])
        self.values = None       # (job, start, door) RPDO1 carries; None: no RPDO1
        self.short = False       # send RPDO1 with 3 bytes
        self.heartbeat = False
        self.sent = []           # (t, job, start, door) of each RPDO1 sent
        self.tpdos = []          # (t, job_echo, program_state, valid)
        self.emcys = []          # (t, code)
        self.stop = threading.Event()
        threading.Thread(target=self.reader, daemon=True).start()
        threading.Thread(target=self.writer, daemon=True).start()

    def send(self, cob, data):
        self.tx.send(self.can.Message(arbitration_id=cob, data=bytes(data), is_extended_id=False))

    def writer(self):
        n, next_hb = 0, 0.0
        while not self.stop.is_set():
            now = time.monotonic()
            if self.heartbeat and now >= next_hb:
                self.send(0x700 + MANAGER, [0x05])   # operational
                next_hb = now + MANAGER_HB_MS / 1e3
            v = self.values
            if v is not None:
                data = struct.pack('<HBB', *v) + bytes(4)
                t = time.monotonic()  # before the send: the node may act first
                self.send(0x200 + self.node, data[:3] if self.short else data)
                if not self.short:
                    self.sent.append((t,) + tuple(v))
            n += 1
            time.sleep(PERIOD)

    def reader(self):
        while not self.stop.is_set():
            msg = self.rx.recv(0.1)
            if msg is None or msg.is_error_frame:
                continue
            d, t = bytes(msg.data), time.monotonic()
            if msg.arbitration_id == 0x180 + self.node and len(d) == 8:
                self.tpdos.append((t, struct.unpack_from('<H', d, 4)[0], struct.unpack_from('<i', d, 0)[0], d[7]))
            elif msg.arbitration_id == 0x080 + self.node and len(d) == 8:
                self.emcys.append((t, struct.unpack_from('<H', d, 0)[0]))

    def emcy_since(self, t, code):
        return [e for e in self.emcys if e[0] >= t and e[1] == code]


def run_for(seconds):
    time.sleep(seconds)


def step_configure(m, node):
    m.wait('boot-up', m.heartbeat(0x00), limit=60)
    m.check('RPDO1\'s COB-ID is the pre-defined 0x%03X' % (0x200 + node), m.read_u(0x1400, 1) == 0x200 + node)
    m.check('RPDO1 acts at once (type 254)', m.read_u(0x1400, 2) == 254)
    m.check('RPDO1\'s event timer is the [input]\'s timeout_ms (%d)' % TIMEOUT_MS, m.read_u(0x1400, 5) == TIMEOUT_MS)
    mapping = [m.read_u(0x1600, s) for s in range(1, m.read_u(0x1600, 0) + 1)]
    want = [0x22000110, 0x22000208, 0x22000308] + [0x00050008] * 4
    m.check('RPDO1\'s mapping: job_number, start, door_closed, four dummy bytes',
            mapping == want, ' '.join('%08X' % x for x in mapping))
    m.write_u(0x1016, 1, MANAGER << 16 | CONSUMER_MS, 4)
    m.check('0x1016 sub 1 holds the manager\'s heartbeat', m.read_u(0x1016, 1) == MANAGER << 16 | CONSUMER_MS)
    m.nmt(0x01)
    m.wait('operational heartbeat', m.heartbeat(0x05))


def step_nothing(m, proxy):
    sent = plc_io.wait_for(lambda: next((s for s, _, _ in proxy.snapshot() if 'S' in plc_io.session_types(s)),
                                        None))
    m.check('the session starts', sent is not None)
    types = plc_io.session_types(sent or [])
    m.check('it sends V v O I S (%s)' % types, types.startswith('VvOIS'))
    time.sleep(0.5)
    m.check('nothing is written before RPDO1 comes', not proxy.packages_u())


def step_follow(m, bus, proxy, rate):
    t0 = time.monotonic()
    for n in range(30):
        bus.values = (100 + n, n % 2, 1)
        run_for(0.1)
    jobs = list(range(100, 130))
    plc_io.wait_for(lambda: any(e == 129 for _, e, _, _ in bus.tpdos), limit=2.0)
    us = proxy.packages_u(t0)
    m.check('every job of RPDO1 reaches an input package (%d packages)' % len(us),
            {u[1] for u in us} >= set(jobs))
    sent = [s for s in bus.sent if s[0] >= t0]
    bad = [u for u in us if not any(s[1:] == u[1:] and s[0] <= u[0] for s in sent)]
    m.check('every package carries values RPDO1 carried before it', not bad, str(bad[:3]))
    trips = []
    for job in jobs:
        t_sent = min((s[0] for s in sent if s[1] == job), default=None)
        echo = [t for t, e, _, _ in bus.tpdos if e == job and t_sent is not None and t >= t_sent]
        if echo:
            trips.append(echo[0] - t_sent)
    m.check('every job comes back in TPDO1\'s job_echo (%d of %d)' % (len(trips), len(jobs)), len(trips) == len(jobs))
    if trips:
        print('round trip RPDO1 -> register -> TPDO1: median %.1f ms (%.1f cycles), p99 %.1f ms (%.1f cycles)' %
              (statistics.median(trips) * 1e3, statistics.median(trips) * rate, plc_io.pct(trips, 0.99) * 1e3,
               plc_io.pct(trips, 0.99) * rate))


def step_sdo(m, bus, proxy):
    bus.values = None
    t0 = time.monotonic()
    end = t0 + 0.6
    while time.monotonic() < end:
        m.write_u(0x2200, 1, 4242, 2)
        m.write_u(0x2200, 2, 1, 1)
        m.write_u(0x2200, 3, 0, 1)
        time.sleep(PERIOD)
    us = proxy.packages_u(t0)
    m.check('SDO writes of 0x2200 sub 1..3 alone reach the registers (%d packages of job 4242)' %
            sum(1 for u in us if u[1:] == (4242, 1, 0)), any(u[1:] == (4242, 1, 0) for u in us))
    m.check('RPDO1\'s deadline: EMCY 0x%04X, once' % EMCY_DEADLINE, len(bus.emcy_since(t0, EMCY_DEADLINE)) == 1)
    t_last = time.monotonic()
    time.sleep(1.0)
    late = proxy.packages_u(t_last + TIMEOUT_MS / 1e3 + SLACK)
    m.check('no RPDO1 and no SDO write: the packages stop within timeout_ms (%d after)' % len(late), not late)


def step_heartbeat(m, bus, proxy):
    bus.values = (900, 1, 1)
    t0 = time.monotonic()
    ok = plc_io.wait_for(lambda: any(u[1] == 900 for u in proxy.packages_u(t0)), limit=5.0)
    m.check('RPDO1 again: the registers follow', ok)
    bus.heartbeat = False
    t_off = time.monotonic()
    lost = plc_io.wait_for(lambda: bus.emcy_since(t_off, EMCY_HEARTBEAT), limit=5.0)
    m.check('the manager\'s heartbeat stops: EMCY 0x%04X' % EMCY_HEARTBEAT, lost)
    if lost:
        t_lost = lost[0][0]
        time.sleep(1.0)
        late = proxy.packages_u(t_lost + SLACK)
        m.check('while RPDO1 goes on, nothing is written (%d packages after the EMCY)' % len(late), not late)
    bus.heartbeat = True
    t_on = time.monotonic()
    bus.values = (901, 1, 1)
    back = plc_io.wait_for(lambda: any(u[1] == 901 for u in proxy.packages_u(t_on)), limit=5.0)
    m.check('the heartbeat back: the registers follow again', back)


def step_nmt(m, bus, proxy):
    m.nmt(0x02)
    m.wait('stopped heartbeat', m.heartbeat(0x04))
    t_stop = time.monotonic()
    bus.values = (902, 1, 1)
    time.sleep(1.0)
    late = proxy.packages_u(t_stop + SLACK)
    m.check('NMT stopped: nothing is written (%d packages)' % len(late), not late)
    m.nmt(0x01)
    m.wait('operational heartbeat', m.heartbeat(0x05))
    t_on = time.monotonic()
    back = plc_io.wait_for(lambda: any(u[1] == 902 for u in proxy.packages_u(t_on)), limit=5.0)
    m.check('NMT start: the registers follow again', back)


def step_short(m, bus, proxy):
    t0 = time.monotonic()
    bus.short = True
    bus.values = (903, 1, 1)
    time.sleep(0.5)
    m.check('RPDO1 shorter than its mapping: EMCY 0x%04X, once' % EMCY_LENGTH,
            len(bus.emcy_since(t0, EMCY_LENGTH)) == 1)
    m.check('and not processed (no job 903)', all(u[1] != 903 for u in proxy.packages_u(t0)))
    bus.short = False
    bus.values = (904, 1, 1)
    t1 = time.monotonic()
    m.check('the right length again: processed', plc_io.wait_for(
        lambda: any(u[1] == 904 for u in proxy.packages_u(t1)), limit=5.0))


def step_refused(m, bus, proxy):
    t0 = time.monotonic()
    for n in range(20):
        bus.values = (905 + n, 2, 1)
        run_for(0.05)
    us = proxy.packages_u(t0)
    m.check('start = 2 is never written', all(u[2] != 2 for u in us))
    late = [u for u in us if u[0] > t0 + TIMEOUT_MS / 1e3 + SLACK]
    m.check('once start\'s last good value is older than timeout_ms, nothing is written (%d after)' % len(late),
            not late)
    bus.values = None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--channel', required=True)
    ap.add_argument('--node', type=int, required=True)
    ap.add_argument('--sim-port', type=int, required=True)
    ap.add_argument('--proxy-port-file', required=True)
    ap.add_argument('--ready', required=True)
    ap.add_argument('--rate', type=int, required=True)
    a = ap.parse_args()
    proxy = plc_io.Proxy(a.sim_port)
    proxy.start()
    with open(a.proxy_port_file + '.tmp', 'w') as f:
        f.write('%d\n' % proxy.port)
    os.rename(a.proxy_port_file + '.tmp', a.proxy_port_file)
    m = master.Master(a.channel, a.node)
    # The manager's socket takes the node's SDO answers and heartbeats only: between
    # its SDO requests it does not read, and the TPDOs and RPDOs of seconds would fill
    # its receive queue (the kernel then drops what comes next: an SDO answer).
    m.bus.set_filters([{'can_id': 0x580 + a.node, 'can_mask': 0x7FF, 'extended': False},
                       {'can_id': 0x700 + a.node, 'can_mask': 0x7FF, 'extended': False}])
    bus = Bus(a.channel, a.node)
    open(a.ready, 'w').close()
    try:
        step_configure(m, a.node)
        bus.heartbeat = True
        step_nothing(m, proxy)
        step_follow(m, bus, proxy, a.rate)
        step_sdo(m, bus, proxy)
        step_heartbeat(m, bus, proxy)
        step_nmt(m, bus, proxy)
        step_short(m, bus, proxy)
        step_refused(m, bus, proxy)
        kinds = {k for s, _, _ in proxy.snapshot() for _, k, _ in s}
        m.check('the gateway sent nothing but V v O I S U (%s)' % ''.join(sorted(x.decode() for x in kinds)),
                kinds <= {b'V', b'v', b'O', b'I', b'S', b'U'})
    except (master.Missing, master.Abort, AssertionError) as e:
        m.check('the run goes to its end', False, str(e))
    finally:
        bus.stop.set()
    print('%d passed, %d failed' % (m.passed, m.failed))
    sys.stdout.flush()
    return 0 if m.failed == 0 else 1


if __name__ == '__main__':
    rc = main()
    sys.stdout.flush()
    os._exit(rc)  # the threads are daemons: see plc_io.py
