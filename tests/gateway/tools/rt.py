#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Independent reference for the tools tests: a RealTime decoder written
from the wire format alone (big-endian int32 size, then big-endian doubles),
UR5e kinematics, and the small servers and clients the tests need.

Nothing here imports or calls the C library: it is the second opinion.

  rt.py gnuplot CAPTURE DUMP_OUT [COUNT]  dump's gnuplot lines equal the capture, bit for bit
  rt.py json CAPTURE DUMP_OUT             dump's JSON lines carry the capture's values
  rt.py csv CAPTURE DUMP_OUT              dump's CSV rows carry the capture's values
  rt.py model CAPTURE RATE                the simulated motion is consistent
  rt.py noread-server CAPTURE OUT         serve CAPTURE twice; fail on any byte received;
                                          the port (from the system) in OUT.port
  rt.py slow-client PORT SECONDS          connect, never read, hold on
  rt.py writer-client PORT                connect and send a byte (negative control)
  rt.py clock PORT CLOCK RATE COUNT       the time column on the simulator's --clock CLOCK
  rt.py freeze PORT SIMLOG MS RATE        a freeze (--clock monotonic) seen by a client that
                                          stays and one that reconnects during it
  rt.py freeze-every PORT N MS RATE       runs of N packets between freezes of MS
  rt.py pace PORT RATE COUNT LIMIT        packets at RATE by the time column keep that pace
                                          by arrival (no drift), to LIMIT (a fraction)
  rt.py same-packets A B MIN              two clients' gnuplot lines: where their time
                                          ranges overlap (at least MIN packets), identical
  rt.py refused-port OUT                  hold a bound port that does not listen; write it to OUT

Clocks: Python's time.monotonic() and time.time() read CLOCK_MONOTONIC and
CLOCK_REALTIME, the clocks urrt-sim's --clock monotonic and realtime use.
"""
import json
import math
import os
import select
import socket
import statistics
import struct
import sys
import time


def packets(path):
    """Strict framing of a clean capture: every packet is size + doubles."""
    data = open(path, 'rb').read()
    out = []
    off = 0
    while off + 4 <= len(data):
        size = struct.unpack_from('>i', data, off)[0]
        if size < 12 or (size - 4) % 8 or off + size > len(data):
            break
        raw = data[off + 4:off + size]
        out.append((size, raw))
        off += size
    return out


def doubles(raw):
    return struct.unpack('>%dd' % (len(raw) // 8), raw)


def fail(msg):
    print('rt.py: FAIL: ' + msg, file=sys.stderr)
    sys.exit(1)


def cmd_gnuplot(capture, dump_out, count=None):
    pk = packets(capture)
    lines = [l for l in open(dump_out) if not l.startswith('#')]
    if count is not None and len(pk) != int(count):
        fail('capture holds %d packets, expected %s' % (len(pk), count))
    if len(lines) != len(pk):
        fail('%d gnuplot lines for %d packets' % (len(lines), len(pk)))
    for n, ((size, raw), line) in enumerate(zip(pk, lines), 1):
        cols = line.split()
        if len(cols) != (size - 4) // 8:
            fail('packet %d: %d columns, the packet holds %d doubles' % (n, len(cols), (size - 4) // 8))
        for c, text in enumerate(cols):
            want = raw[8 * c:8 * c + 8]
            got = struct.pack('>d', float(text))
            if got != want:
                fail('packet %d column %d: printed %s (%s), sent %s' % (n, c + 1, text, got.hex(), want.hex()))
    print('rt.py: %d packets, %d columns each, bit-exact' % (len(pk), (pk[0][0] - 4) // 8 if pk else 0))


# Column (1-based) of a few fields in the 3.x/5.x grid, from UR's table.
COL3 = {'time': 1, 'q_target': 2, 'qd_target': 8, 'qdd_target': 14, 'i_target': 20, 'm_target': 26,
        'q_actual': 32, 'qd_actual': 38, 'i_actual': 44, 'tool_vector_actual': 56, 'tcp_speed_actual': 62,
        'tcp_force': 68, 'tool_vector_target': 74, 'digital_input_bits': 86, 'motor_temperatures': 87,
        'robot_mode': 95, 'joint_modes': 96, 'safety_mode': 102, 'tool_accelerometer': 109,
        'speed_scaling': 118, 'digital_outputs': 131, 'program_state': 132, 'elbow_position': 133,
        'safety_status': 139}
COL1 = {'time': 1, 'q_target': 2, 'q_actual': 32, 'qd_actual': 38, 'tool_accelerometer': 50,
        'tool_vector': 74, 'digital_input_bits': 86, 'robot_mode': 95, 'joint_modes': 96}
COUNTS = {'time': 1, 'digital_input_bits': 1, 'robot_mode': 1, 'safety_mode': 1, 'speed_scaling': 1,
          'digital_outputs': 1, 'program_state': 1, 'safety_status': 1, 'tool_accelerometer': 3,
          'elbow_position': 3}


def field(vals, name):
    cols = COL1 if len(vals) <= 101 else COL3
    c = cols[name] - 1
    return list(vals[c:c + COUNTS.get(name, 6)])


def cmd_json(capture, dump_out):
    pk = packets(capture)
    objs = [json.loads(l) for l in open(dump_out)]
    if len(objs) != len(pk):
        fail('%d JSON objects for %d packets' % (len(objs), len(pk)))
    for n, ((size, raw), o) in enumerate(zip(pk, objs), 1):
        v = doubles(raw)
        if o['packet'] != n or o['length'] != size:
            fail('packet %d: packet/length %s/%s' % (n, o['packet'], o['length']))
        names = COL1 if len(v) <= 101 else COL3
        for name in names:
            if name not in o:
                continue
            want = field(v, name)
            got = o[name] if isinstance(o[name], list) else [o[name]]
            if name in ('digital_input_bits', 'digital_outputs'):
                want = [int(x) for x in want]
            if got != want:
                fail('packet %d %s: %s != %s' % (n, name, got, want))
        if len(v) > 101:
            if o.get('robot_mode_name') != 'RUNNING' or o.get('joint_modes_name') != ['RUNNING'] * 6:
                fail('packet %d: mode names %s %s' % (n, o.get('robot_mode_name'), o.get('joint_modes_name')))
            if o.get('safety_mode_name') != 'NORMAL' or o.get('program_state_name', 'PLAYING') != 'PLAYING':
                fail('packet %d: safety/program names' % n)
    print('rt.py: %d JSON objects match' % len(objs))


def cmd_csv(capture, dump_out):
    pk = packets(capture)
    rows = [l.rstrip('\n').split(',') for l in open(dump_out)]
    header, rows = rows[0], rows[1:]
    if len(rows) != len(pk):
        fail('%d CSV rows for %d packets' % (len(rows), len(pk)))
    for n, ((size, raw), row) in enumerate(zip(pk, rows), 1):
        v = doubles(raw)
        for h, text in zip(header, row):
            name, _, idx = h.partition('[')
            i = int(idx[:-1]) if idx else 0
            if name not in COL3:
                continue
            want = field(v, name)[i]
            if struct.pack('>d', float(text)) != struct.pack('>d', want):
                fail('packet %d %s: %s != %r' % (n, h, text, want))
    print('rt.py: %d CSV rows match (%d columns)' % (len(rows), len(header)))


# UR5e standard DH parameters, as Universal Robots publishes them.
DH_D = [0.1625, 0, 0, 0.1333, 0.0997, 0.0996]
DH_A = [0, -0.425, -0.3922, 0, 0, 0]
DH_ALPHA = [math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def fk(q):
    t = [[1 if i == j else 0 for j in range(4)] for i in range(4)]
    for i in range(6):
        ct, st = math.cos(q[i]), math.sin(q[i])
        ca, sa = math.cos(DH_ALPHA[i]), math.sin(DH_ALPHA[i])
        t = matmul(t, [[ct, -st * ca, st * sa, DH_A[i] * ct], [st, ct * ca, -ct * sa, DH_A[i] * st],
                       [0, sa, ca, DH_D[i]], [0, 0, 0, 1]])
    return t


def rodrigues(rv):
    th = math.sqrt(sum(x * x for x in rv))
    if th < 1e-12:
        return [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    kx, ky, kz = (x / th for x in rv)
    c, s, v = math.cos(th), math.sin(th), 1 - math.cos(th)
    return [[kx * kx * v + c, kx * ky * v - kz * s, kx * kz * v + ky * s],
            [ky * kx * v + kz * s, ky * ky * v + c, ky * kz * v - kx * s],
            [kz * kx * v - ky * s, kz * ky * v + kx * s, kz * kz * v + c]]


def cmd_model(capture, rate):
    rate = float(rate)
    dt = 1.0 / rate
    pk = [doubles(raw) for _, raw in packets(capture)]
    if len(pk) < 10:
        fail('too few packets')
    lag = int(round(0.004 * rate))
    worst = {}

    def note(what, err):
        worst[what] = max(worst.get(what, 0.0), err)

    for k in range(1, len(pk) - 1):
        p, a, b = pk[k], pk[k - 1], pk[k + 1]
        note('time step', abs((b[0] - p[0]) - dt))
        for j in range(6):
            # Central differences: errors of order dt^2 times the third derivative.
            note('qd = dq/dt', abs((b[1 + j] - a[1 + j]) / (2 * dt) - p[7 + j]))
            note('qdd = dqd/dt', abs((b[7 + j] - a[7 + j]) / (2 * dt) - p[13 + j]))
        if k >= lag:
            for j in range(6):
                note('q_actual = q_target a lag earlier', abs(p[31 + j] - pk[k - lag][1 + j]))
        t = fk(p[31:37])
        for i in range(3):
            note('tcp position = fk(q_actual)', abs(t[i][3] - p[55 + i]))
        r = rodrigues(p[58:61])
        for i in range(3):
            for j in range(3):
                note('tcp rotation = fk(q_actual)', abs(t[i][j] - r[i][j]))
        # TCP speed against the difference of neighbouring poses.
        ta, tb = fk(a[31:37]), fk(b[31:37])
        for i in range(3):
            note('tcp speed = d(pose)/dt', abs((tb[i][3] - ta[i][3]) / (2 * dt) - p[61 + i]))
        if p[94] != 7 or any(m != 253 for m in p[95:101]) or p[101] != 1 or p[131] != 2 or p[138] != 1:
            fail('packet %d: modes %s %s %s %s %s' % (k, p[94], p[95:101], p[101], p[131], p[138]))
        for j in range(6):
            # Torque over current: one positive torque constant per joint.
            if abs(p[43 + j]) > 0.2:
                note('current follows torque (sign)', 0.0 if (p[43 + j] > 0) == (p[25 + j] > 0) else 1.0)
        if not 20 < min(p[86:92]) <= max(p[86:92]) < 60:
            fail('packet %d: temperatures %s' % (k, p[86:92]))
        acc = math.sqrt(sum(x * x for x in p[108:111]))
        note('accelerometer ~ g', 0.0 if 7 < acc < 13 else abs(acc - 9.8))
    limits = {'time step': 1e-9, 'qd = dq/dt': 5e-4, 'qdd = dqd/dt': 5e-3,
              'q_actual = q_target a lag earlier': 1e-9, 'tcp position = fk(q_actual)': 1e-9,
              'tcp rotation = fk(q_actual)': 1e-6, 'tcp speed = d(pose)/dt': 5e-4,
              'current follows torque (sign)': 0.5, 'accelerometer ~ g': 0.5}
    for what, err in sorted(worst.items()):
        print('rt.py: model: %-36s worst %.3g (limit %g)' % (what, err, limits[what]))
        if err > limits[what]:
            fail('model: %s off by %g' % (what, err))
    bits = set(p[85] for p in pk)
    moving = max(abs(pk[-1][31 + j] - pk[0][31 + j]) for j in range(6))
    print('rt.py: model: %d distinct input masks, joints moved up to %.3f rad' % (len(bits), moving))
    if moving < 1e-3:
        fail('model: the joints do not move')


def write_port(path, port):
    """As urrt-sim --port-file: the whole line or no file."""
    with open(path + '.tmp', 'w') as f:
        f.write('%d\n' % port)
    os.rename(path + '.tmp', path)


def cmd_noread_server(capture, out):
    """Serves the capture in two connections (half, stall until the client
    gives up, then the rest) and records every byte a client sends."""
    data = open(capture, 'rb').read()
    pk = packets(capture)
    half = sum(size for size, _ in pk[:len(pk) // 2])
    srv = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    srv.bind(('127.0.0.1', 0))
    srv.listen(4)
    write_port(out + '.port', srv.getsockname()[1])
    srv.settimeout(10)
    received = 0
    result = {'connections': 0, 'received': 0}
    for part in (data[:half], data[half:]):
        conn, _ = srv.accept()
        result['connections'] += 1
        conn.sendall(part)
        # Keep the connection open and silent until the client closes it
        # (the first time: its silence timeout) or 5 s pass; count any byte.
        end = time.time() + (5 if part is data[:half] else 0.5)
        while time.time() < end:
            r, _, _ = select.select([conn], [], [], 0.05)
            if r:
                try:
                    chunk = conn.recv(4096)
                except ConnectionResetError:
                    break
                if not chunk:
                    break
                received += len(chunk)
        conn.close()
        if received:
            break
    result['received'] = received
    json.dump(result, open(out, 'w'))
    sys.exit(1 if received else 0)


def cmd_slow_client(port, seconds):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    s.connect(('127.0.0.1', int(port)))
    time.sleep(float(seconds))
    s.close()


def cmd_writer_client(port):
    s = socket.create_connection(('127.0.0.1', int(port)), timeout=5)
    s.recv(100)
    s.sendall(b'x')
    time.sleep(0.2)
    s.close()


class Stream:
    """One connection to the simulator: (arrival, time column) per packet,
    and when its first byte came."""

    def __init__(self, port, clock=time.monotonic):
        self.clock = clock
        self.sock = socket.create_connection(('127.0.0.1', int(port)), timeout=5)
        self.connected = clock()
        self.sock.setblocking(False)
        self.buf = b''
        self.first_byte = None
        self.packets = []

    def read(self):
        try:
            data = self.sock.recv(65536)
        except BlockingIOError:
            return
        now = self.clock()
        if not data:
            fail('the simulator closed a connection')
        if self.first_byte is None:
            self.first_byte = now
        self.buf += data
        while len(self.buf) >= 12:
            size = struct.unpack_from('>i', self.buf)[0]
            if len(self.buf) < size:
                break
            self.packets.append((now, struct.unpack_from('>d', self.buf, 4)[0]))
            self.buf = self.buf[size:]


def serve(streams, until, seconds):
    """Reads every stream until until() holds; fails after seconds."""
    end = time.monotonic() + seconds
    while not until():
        if time.monotonic() > end:
            fail('timed out')
        r, _, _ = select.select([s.sock for s in streams], [], [], 0.01)
        for s in streams:
            if s.sock in r:
                s.read()


def gaps(packets, at_least):
    """(index after the gap, gap in the time column) where the column jumps
    by at_least or more. (A simulator held past its 100 ms catch-up limit by
    a loaded machine skips packets: shorter gaps, not freezes.)"""
    return [(i, packets[i][1] - packets[i - 1][1]) for i in range(1, len(packets))
            if packets[i][1] - packets[i - 1][1] >= at_least - 1e-6]


def off_period(packets, period):
    """The largest distance of a step of the time column from a whole number
    of periods (more than one where the simulator skipped), and the number of
    such skips."""
    steps = [b[1] - a[1] for a, b in zip(packets, packets[1:])]
    worst = max(abs(d - max(1, round(d / period)) * period) for d in steps)
    return worst, sum(1 for d in steps if round(d / period) > 1)


def cmd_clock(port, clock, rate, count):
    period, count = 1.0 / float(rate), int(count)
    c = Stream(port, time.time if clock == 'realtime' else time.monotonic)
    serve([c], lambda: len(c.packets) >= count, 10)
    ages = [arrival - t for arrival, t in c.packets]
    worst_step, skips = off_period(c.packets, period)
    print('rt.py: clock %s: time column %.6f, %d packets, age min %.6f s, max %.6f s, step error %.3g s, %d skips'
          % (clock, c.packets[0][1], len(ages), min(ages), max(ages), worst_step, skips))
    # The column is the scheduled instant: a packet cannot arrive before it
    # (1 us for the double's rounding), and the steps are exact periods to
    # the microsecond, Unix time (1.8e9 s) included.
    if worst_step > 1e-6:
        fail('clock %s: a step of the time column is off the period by %g s' % (clock, worst_step))
    if clock == 'start':
        if abs(c.packets[0][1] - (1000.0 + round((c.packets[0][1] - 1000.0) / period) * period)) > 1e-6:
            fail('clock start: %.9f is not 1000 s + k periods' % c.packets[0][1])
        return
    if min(ages) < -1e-6 or max(ages) > 0.5:
        fail('clock %s: ages from %.6f to %.6f s (0 to 0.5 s expected)' % (clock, min(ages), max(ages)))
    if clock == 'realtime' and not 1.6e9 < c.packets[0][1] < 4.1e9:
        fail('clock realtime: %.6f is not Unix time' % c.packets[0][1])


def wait_for_line(path, text, streams, seconds):
    def seen():
        with open(path) as f:
            return text in f.read()
    serve(streams, seen, seconds)


def cmd_freeze(port, simlog, ms, rate):
    """Client a stays connected; client b connects before the freeze and
    again while it lasts. Times on CLOCK_MONOTONIC, the time column's clock."""
    freeze, period = float(ms) / 1000.0, 1.0 / float(rate)
    a, b = Stream(port), Stream(port)
    serve([a, b], lambda: len(a.packets) >= 10 and len(b.packets) >= 10, 10)
    wait_for_line(simlog, 'freeze 1: nothing to any client', [a, b], 20)
    b.sock.close()
    b2 = Stream(port)
    wait_for_line(simlog, 'freeze 1 over', [a, b2], 10 + freeze)
    serve([a, b2], lambda: len(b2.packets) >= 10 and len(a.packets) > 0 and a.packets[-1][1] > b2.packets[9][1], 10)
    g = gaps(a.packets, freeze)
    if len(g) != 1:
        fail('freeze: %d gaps in the stream of the client that stayed: %s (none: it connected during the freeze)'
             % (len(g), g))
    i, gap = g[0]
    last, first = a.packets[i - 1], a.packets[i]
    end = last[1] + freeze  # the freeze ends MS after the last packet's instant
    print('rt.py: freeze: gap %.6f s in the time column, %.6f s by arrival; reconnected %.3f s before its end, '
          'first byte %.6f s after it' % (gap, first[0] - last[0], end - b2.connected, b2.first_byte - end))
    if not freeze - 1e-6 <= gap < freeze + period + 1e-6:
        fail('freeze: the time column jumps %.6f s, not %.3f s (to one period more)' % (gap, freeze))
    if first[0] < end - 1e-6:
        fail('freeze: a packet arrived %.6f s before the freeze ended' % (end - first[0]))
    if b2.connected >= end:
        fail('freeze: the reconnect came %.3f s after the freeze (the test could not reconnect during it)'
             % (b2.connected - end))
    if b2.first_byte < end - 1e-6:
        fail('freeze: the client that reconnected got a byte %.6f s before the freeze ended' % (end - b2.first_byte))
    if b2.first_byte > end + 1.0:
        fail('freeze: the client that reconnected waited %.3f s past the freeze' % (b2.first_byte - end))
    if b2.packets[0][1] != first[1]:
        fail('freeze: after it the clients got different packets first (%.6f and %.6f)' % (b2.packets[0][1], first[1]))


def cmd_freeze_every(port, n, ms, rate):
    """Runs of exactly N packets, gaps of MS (to a period) in the time column
    (--clock start: it counts the frozen packets too)."""
    n, freeze, period = int(n), float(ms) / 1000.0, 1.0 / float(rate)
    c = Stream(port)
    serve([c], lambda: len(gaps(c.packets, freeze)) >= 4, 10 + 6 * freeze)
    g = gaps(c.packets, freeze)
    runs = [j - i for (i, _), (j, _) in zip(g, g[1:])]
    print('rt.py: freeze-every: runs %s, gaps %s' % (runs, ['%.6f' % d for _, d in g]))
    if runs != [n] * len(runs):
        fail('freeze-every: runs of %s packets, not %d' % (runs, n))
    for _, d in g:
        if not freeze - 1e-6 <= d < freeze + period + 1e-6:
            fail('freeze-every: a gap of %.6f s in the time column, not %.3f s' % (d, freeze))


def cmd_pace(port, rate, count, limit):
    """Arrival less time column, compared between the first and the last
    fifth of the packets by their medians: a sender that drifts (sleeps a
    period after each send) grows it by 3% of the span, while one late
    packet, or a catch-up burst after a preemption, moves no median."""
    period, count = 1.0 / float(rate), int(count)
    c = Stream(port)
    serve([c], lambda: len(c.packets) >= count, 10 + count * period)
    if off_period(c.packets, period)[0] > 1e-6:
        fail('pace: the time column does not step by %g s' % period)
    k = count // 5
    lag = [arrival - t for arrival, t in c.packets]
    drift = statistics.median(lag[-k:]) - statistics.median(lag[:k])
    span = c.packets[-1][1] - c.packets[0][1]
    print('rt.py: pace: %d packets over %.3f s by the time column; arrival drifted %.6f s (%.3f%%)'
          % (len(c.packets), span, drift, 100 * drift / span))
    if abs(drift) > float(limit) * span:
        fail('pace: arrival drifted %.6f s over %.3f s (%g allowed)' % (drift, span, float(limit) * span))


def cmd_same_packets(a, b, least):
    """Clients that connected at different times share the packets of the
    time both were connected, byte for byte, and no other."""
    def rows(path):
        return [l for l in open(path) if not l.startswith('#')]
    ra, rb = rows(a), rows(b)
    lo = max(float(ra[0].split()[0]), float(rb[0].split()[0]))
    hi = min(float(ra[-1].split()[0]), float(rb[-1].split()[0]))
    ia = [l for l in ra if lo <= float(l.split()[0]) <= hi]
    ib = [l for l in rb if lo <= float(l.split()[0]) <= hi]
    print('rt.py: same-packets: %d and %d packets, %d while both were connected' % (len(ra), len(rb), len(ia)))
    if ia != ib:
        fail('same-packets: the clients got different packets while both were connected')
    if len(ia) < int(least):
        fail('same-packets: only %d packets while both were connected (%s wanted)' % (len(ia), least))


def cmd_refused_port(out):
    """A port nobody listens on and nobody else can take while this runs:
    bound (without SO_REUSEADDR) but not listening, so a connect is refused."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind(('127.0.0.1', 0))
    write_port(out, s.getsockname()[1])
    time.sleep(60)


if __name__ == '__main__':
    cmds = {'gnuplot': cmd_gnuplot, 'json': cmd_json, 'csv': cmd_csv, 'model': cmd_model,
            'noread-server': cmd_noread_server, 'slow-client': cmd_slow_client,
            'writer-client': cmd_writer_client, 'clock': cmd_clock, 'freeze': cmd_freeze,
            'freeze-every': cmd_freeze_every, 'pace': cmd_pace, 'same-packets': cmd_same_packets,
            'refused-port': cmd_refused_port}
    if len(sys.argv) < 2 or sys.argv[1] not in cmds:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    cmds[sys.argv[1]](*sys.argv[2:])
