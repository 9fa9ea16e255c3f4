#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-replay-rtde: urrt-gateway --replay of an RTDE capture (gateway/can/can_replay.c).

Sessions of urrt-sim's RTDE port are recorded here in the capture format
(docs/rtde.md, "Captures": the header, then 'C' / '>' / '<' records of whole
packages) by tests/gateway/tools/rtde_peer.py, an RTDE client written from the
protocol, making the requests urrt's client makes (V, v, O, S); the RealTime
port of the same simulator is recorded raw at the same time. Then:

- the frames of --replay of the RTDE capture are the frames this script
  predicts from the capture's values (decoded by rtde_peer, packed by
  test_dbc.py's reference and python3-canmatrix through the DBC --print-dbc
  writes), each at its package's controller time, RTDE-only values included;
- for the fields both sources have, they are the frames of --replay of the
  RealTime capture, at the same controller times;
- docs/examples/rtde-plc.ini (CANopen) replays, its TPDO carrying the register
  and status bits of the latest package, and --replay-rx feeds the node a
  manager's NMT stop and start on the capture's clock;
- refusals, before any frame: a recipe without output_int_register_24 (the
  message names it, the signal that needs it and the urrt-dump -k that
  records it), a recipe without timestamp, a field RTDE has no variable for,
  RTDE-only signals from a RealTime capture; a file that starts like a
  capture but is none;
- a capture cut inside a record replays up to the cut with a warning, and a
  capture of two sessions (a reconnect) replays both.

Every server takes its port from the system; every wait is for an event
with a bound, never a sleep for something to have happened.

  check_replay_rtde.py BUILD
"""
import contextlib
import io
import os
import re
import socket
import struct
import subprocess
import sys
import tempfile
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, 'tests', 'gateway', 'tools'))
sys.path.insert(0, os.path.join(ROOT, 'tests'))
import rtde_peer  # noqa: E402
import suite  # noqa: E402  checks, their report, waits
from suite import check, wait_for  # noqa: E402
with contextlib.redirect_stderr(io.StringIO()):  # canmatrix's "ldf is not supported"
    import test_dbc  # noqa: E402  (the configuration reader, the reference packing, canmatrix)

BUILD = sys.argv[1] if len(sys.argv) > 1 else 'build'
SIM = os.path.join(BUILD, 'bin', 'urrt-sim')
DUMP = os.path.join(BUILD, 'bin', 'urrt-dump')
GW = os.path.join(BUILD, 'bin', 'urrt-gateway')
TMP = tempfile.mkdtemp(prefix='urrt-replay-rtde.')
MAGIC = b'URRT RTDE capture 1\n'
RATE = 500  # controller 5.12: 500 Hz


def tmp(name):
    return os.path.join(TMP, name)


# ---- the recorders ---------------------------------------------------

def package(kind, payload):
    return struct.pack('>HB', 3 + len(payload), kind) + payload


class Recorder(rtde_peer.Peer):
    """rtde_peer's client, every package it sends and receives kept as a
    capture's records."""

    def __init__(self, port, records):
        self.records = records
        super().__init__(port)
        records.append(b'C' + package(ord('C'), ('127.0.0.1:%d' % port).encode()))

    def send(self, letter, payload=b''):
        self.records.append(b'>' + package(letter[0], payload))
        super().send(letter, payload)

    def package(self, timeout=None):
        kind, payload = super().package(timeout)
        self.records.append(b'<' + package(kind[0], payload))
        return kind, payload


def record_session(port, names, count, records):
    """One session as urrt's client makes it: its count data packages, each
    as {name: value}."""
    peer = Recorder(port, records)
    try:
        check(peer.protocol_version(2) == 1, 'recorder: protocol 2 accepted')
        peer.controller_version()
        _, types = peer.setup_outputs(names, float(RATE))
        check('NOT_FOUND' not in types, 'recorder: the simulator has %s' % ','.join(names), types)
        check(peer.start() == 1, 'recorder: started')
        return [dict(zip(names, values)) for values in peer.data(count)]
    finally:
        peer.close()


def write_capture(path, records):
    with open(path, 'wb') as f:
        f.write(MAGIC + b''.join(records))


def read_capture(path):
    """The data packages of a capture, each as {name: value}, read here from
    the format: the setup request's names, the reply's types, rtde_peer's decode."""
    data = open(path, 'rb').read()
    check(data.startswith(MAGIC), '%s starts with the capture header' % os.path.basename(path))
    at, names, out = len(MAGIC), None, []
    peer = rtde_peer.Peer.__new__(rtde_peer.Peer)
    peer.protocol = 2
    while at + 3 <= len(data):
        kind = data[at:at + 1]
        size, letter = struct.unpack_from('>HB', data, at + 1)
        payload = data[at + 4:at + 1 + size]
        at += 1 + size
        if kind == b'>' and letter == ord('V'):
            peer.protocol = struct.unpack('>H', payload)[0]
        elif kind == b'>' and letter == ord('O'):
            names = payload[8 if peer.protocol >= 2 else 0:].decode().split(',')
        elif kind == b'<' and letter == ord('O'):
            peer.recipe_id = payload[0] if peer.protocol >= 2 else None
            peer.types = payload[1 if peer.protocol >= 2 else 0:].decode().split(',')
        elif kind == b'<' and letter == ord('U'):
            out.append(dict(zip(names, peer.decode(payload))))
    return out


class RealTimeReader:
    """The RealTime port's bytes, raw, from connect until stop()."""

    def __init__(self, port):
        self.sock = socket.create_connection(('127.0.0.1', port), timeout=5)
        self.data = bytearray()
        self.running = True
        self.thread = threading.Thread(target=self.read, daemon=True)
        self.thread.start()

    def read(self):
        while self.running:
            try:
                chunk = self.sock.recv(65536)
            except OSError:
                break
            if not chunk:
                break
            self.data += chunk

    def stop(self):
        self.running = False
        self.sock.shutdown(socket.SHUT_RDWR)
        self.thread.join(timeout=10)
        self.sock.close()
        return bytes(self.data)


# ---- the gateway ---------------------------------------------------------------------

def replay(ini, capture, rx=None):
    args = [GW, '--replay', capture] + (['--replay-rx', rx] if rx else []) + [ini]
    p = subprocess.run(['timeout', '-k', '3', '60'] + args, capture_output=True, text=True, errors='replace')
    return p.returncode, p.stderr


LOG_LINE = re.compile(r'\((\d+)\.(\d{6})\) \S+ ([0-9A-F]+)#([0-9A-F]*)$')


def read_log(path):
    """[(t_us, id, payload bytes)] of a candump -l file."""
    out = []
    for line in open(path):
        m = LOG_LINE.match(line.strip())
        if m:
            out.append((int(m.group(1)) * 1000000 + int(m.group(2)), int(m.group(3), 16), bytes.fromhex(m.group(4))))
    return out


def write_ini(name, body, log):
    path = tmp(name + '.ini')
    with open(path, 'w') as f:
        f.write(body.replace('LOG', log))
    return path


ROBOT = '[robot arm1]\nhost = 127.0.0.1\nsource = %s\n\n[can]\ninterface = log:LOG\nheartbeat_id = 0x700\n\n'
FIELDS = '''[frame joints]
id = 0x100
period_ms = every
signal = q_actual[0] @0|16 intel signed factor=0.0002
signal = actual_q[1] @16|16 intel signed factor=0.0002
signal = qd_actual[0] @32|16 intel signed factor=0.001
signal = robot_mode @48|8 intel signed
validity_bit = 63

[frame io]
id = 0x101
period_ms = every
signal = digital_input_bits @0|18 intel unsigned
signal = speed_scaling @32|16 intel unsigned factor=0.0001
signal = safety_mode @48|8 intel unsigned

'''
REGISTERS = '''[frame regs]
id = 0x102
period_ms = every
signal = output_int_register_24 @0|32 intel signed name=reg24
signal = safety_status_bits @32|16 intel unsigned bits=0-15 name=safety_bits
signal = robot_status_bits @48|8 intel unsigned bits=0-7 name=robot_bits

'''
# RTDE names of the fields the configurations above use (the RealTime ones are urrt's).
RECIPE = ['timestamp', 'actual_q', 'actual_qd', 'robot_mode', 'safety_mode', 'actual_digital_input_bits',
          'speed_scaling', 'output_int_register_24', 'safety_status_bits', 'robot_status_bits']
RTDE_OF = {field: name for name, field in test_dbc.RTDE_NAMES.items()}


def value_of(pkg, sig):
    """A signal's value in a data package ({RTDE name: value}), as a double."""
    field = sig['field']
    v = pkg[RTDE_OF.get(field, field)]
    v = v[sig['elem']] if isinstance(v, tuple) else v
    return float(v)


def predict(ini, packages):
    """[(t_us, id, payload)] of the frames sent per package (period_ms = every),
    by the test's own packing through the DBC --print-dbc writes of ini."""
    dbc = subprocess.run([GW, '--print-dbc', ini], capture_output=True, text=True, timeout=30).stdout
    db, _ = test_dbc.load_dbc(dbc)
    _, frames = test_dbc.parse_config(ini)
    out = []
    for pkg in packages:
        t_us = round(pkg['timestamp'] * 1e6)
        for f in frames:
            raws = {}
            for s in f['signals']:
                raws[s['name']] = 1 if s['role'] == 'valid' else test_dbc.ref_to_raw(s, value_of(pkg, s))[0]
            out.append((t_us, f['id'], bytes(db.frame_by_name(f['name']).encode(raws))))
    return out


def frames_of(log, ids):
    return [x for x in read_log(log) if x[1] in ids]


def same_frames(got, want):
    """The same ids and payloads in the same order, each within 1 us of its time."""
    if len(got) != len(want):
        return False, '%d frames, %d predicted' % (len(got), len(want))
    for i, (g, w) in enumerate(zip(got, want)):
        if g[1:] != w[1:] or abs(g[0] - w[0]) > 1:
            return False, 'frame %d: %s, predicted %s' % (i, g, w)
    return True, ''


# ---- the checks ----------------------------------------------------------------------

def test_frames(main_cap, packages, rt_cap):
    log = tmp('b.log')
    ini = write_ini('b', ROBOT % 'rtde' + FIELDS + REGISTERS, log)
    rc, err = replay(ini, main_cap)
    check(rc == 0, 'replay of the RTDE capture', err)
    check('replayed %s (RTDE): %d data packages in 1 session ' % (main_cap, len(packages)) in err,
          'the replay counts the capture\'s data packages and its session', err)
    ok, why = same_frames(frames_of(log, {0x100, 0x101, 0x102}), predict(ini, packages))
    check(ok, 'RTDE replay: every frame of every package as predicted from the capture\'s values (%d packages, '
          'RTDE-only values included)' % len(packages), why)
    check(any(i == 0x700 for _, i, _ in read_log(log)), 'RTDE replay: the heartbeat goes out')

    # The fields both sources have: the same frames at the same controller times.
    rtde_log, rt_log = tmp('a-rtde.log'), tmp('a-rt.log')
    rc1, err1 = replay(write_ini('a-rtde', ROBOT % 'rtde' + FIELDS, rtde_log), main_cap)
    rc2, err2 = replay(write_ini('a-rt', ROBOT % 'realtime' + FIELDS, rt_log), rt_cap)
    check(rc1 == 0 and rc2 == 0, 'replay of both captures with the fields configuration', err1 + err2)
    by_time_rtde = {(t, i): d for t, i, d in frames_of(rtde_log, {0x100, 0x101})}
    by_time_rt = {(t, i): d for t, i, d in frames_of(rt_log, {0x100, 0x101})}
    common = sorted(set(by_time_rtde) & set(by_time_rt))
    differ = [k for k in common if by_time_rtde[k] != by_time_rt[k]]
    check(len(common) >= len(packages), 'RealTime and RTDE captures overlap by controller time (%d frames)'
          % len(common), '%d RTDE, %d RealTime frames' % (len(by_time_rtde), len(by_time_rt)))
    check(not differ, 'the RTDE capture\'s frames are the RealTime capture\'s at the same controller time',
          [(k, by_time_rtde[k].hex(), by_time_rt[k].hex()) for k in differ[:3]])
    # The configuration's source does not matter: the capture decides.
    log_src = tmp('a-src.log')
    rc, err = replay(write_ini('a-src', ROBOT % 'realtime' + FIELDS, log_src), main_cap)
    check(rc == 0 and read_log(log_src) == read_log(rtde_log),
          'source = realtime replays an RTDE capture as source = rtde does', err)


def test_canopen(main_cap, packages, label='rtde-plc'):
    """rtde-plc.ini: TPDO1 every 20 ms with the register and the status bits,
    and a manager's NMT stop and start through --replay-rx."""
    log = tmp(label + '.log')
    text = open(os.path.join(ROOT, 'docs', 'examples', 'rtde-plc.ini')).read()
    ini = write_ini(label, re.sub(r'(?m)^interface = .*$', 'interface = log:LOG', text), log)
    t0 = round(packages[0]['timestamp'] * 1e6)
    t_stop, t_start = t0 + 200000, t0 + 400000
    rx = tmp(label + '-rx.log')
    with open(rx, 'w') as f:
        f.write('(%d.%06d) can0 000#0205\n(%d.%06d) can0 000#0105\n' % (t_stop // 10 ** 6, t_stop % 10 ** 6,
                                                                       t_start // 10 ** 6, t_start % 10 ** 6))
    rc, err = replay(ini, main_cap, rx)
    check(rc == 0 and 'fed 2 received frames' in err, '%s: replay with --replay-rx' % label, err)
    dbc = subprocess.run([GW, '--print-dbc', ini], capture_output=True, text=True, timeout=30).stdout
    db, _ = test_dbc.load_dbc(dbc)
    _, frames = test_dbc.parse_config(ini)
    f = frames[0]
    d = db.frame_by_name(f['name'])
    frames_sent = read_log(log)
    tpdos = [(t, data) for t, i, data in frames_sent if i == 0x185]
    times = [(round(p['timestamp'] * 1e6), p) for p in packages]
    bad = []
    for t, data in tpdos:
        latest = [p for pt, p in times if pt <= t][-1]
        raws = {s['name']: 1 if s['role'] == 'valid' else test_dbc.ref_to_raw(s, value_of(latest, s))[0]
                for s in f['signals']}
        if bytes(d.encode(raws)) != data:
            bad.append((t, data.hex(), bytes(d.encode(raws)).hex()))
    check(len(tpdos) >= 10 and not bad, '%s: %d TPDOs carry the latest package\'s register and status '
          'bits' % (label, len(tpdos)), bad[:3])
    check(not [t for t, _ in tpdos if t_stop <= t < t_start], '%s: no TPDO while the manager has the '
          'node stopped' % label, [t for t, _ in tpdos])
    check(any(t < t_stop for t, _ in tpdos) and any(t >= t_start for t, _ in tpdos),
          '%s: TPDOs before the stop and after the start' % label)
    hb = [(t, data) for t, i, data in frames_sent if i == 0x705]
    check((t_stop, b'\x04') in hb and (t_start, b'\x05') in hb,
          '%s: the node\'s heartbeat says stopped and operational at the manager\'s commands' % label, hb)


def test_refusals(sim, main_cap, rt_cap):
    plc_text = open(os.path.join(ROOT, 'docs', 'examples', 'rtde-plc.ini')).read()
    plc_log = tmp('refused.log')
    plc = write_ini('plc-refused', re.sub(r'(?m)^interface = .*$', 'interface = log:LOG', plc_text), plc_log)

    records = []
    record_session(sim.port, ['timestamp', 'actual_q', 'robot_status_bits', 'safety_status_bits'], 20, records)
    no_register = tmp('no-register.rtde')
    write_capture(no_register, records)
    rc, err = replay(plc, no_register)
    check(rc == 1 and re.search(r'the recipe of session 1 \(127\.0\.0\.1:\d+\) lacks what the CAN side needs: '
                                r'output_int_register_24 \(frame tpdo1_program, signal parts, plc-refused\.ini:\d+\); '
                                r'record them: urrt-dump --rtde -w FILE -k output_int_register_24$', err, re.M),
          'a capture without output_int_register_24 with rtde-plc.ini: refused, naming it, its signal and '
          'the urrt-dump that records it', err)
    check(not os.path.exists(plc_log), 'a refused replay sends no frame (the log is not even opened)')
    check(len(err.strip().splitlines()) == 1, 'the refusal is one line', err)

    # Everything missing in one line: fields and RTDE-only values of config B.
    rc, err = replay(write_ini('b-refused', ROBOT % 'rtde' + FIELDS + REGISTERS, tmp('b-refused.log')), no_register)
    names = ['actual_qd', 'robot_mode', 'actual_digital_input_bits', 'speed_scaling', 'safety_mode',
             'output_int_register_24']
    line = [x for x in err.splitlines() if 'lacks' in x]
    check(rc == 1 and len(line) == 1 and all(n in line[0] for n in names) and
          line[0].endswith('-k ' + ','.join(['actual_qd', 'robot_mode', 'actual_digital_input_bits',
                                             'speed_scaling', 'safety_mode', 'output_int_register_24'])),
          'every missing value in one line, and one -k for all of them', err)

    records = []
    record_session(sim.port, ['actual_q', 'output_int_register_24', 'robot_status_bits', 'safety_status_bits'], 20,
                   records)
    no_time = tmp('no-timestamp.rtde')
    write_capture(no_time, records)
    rc, err = replay(plc, no_time)
    check(rc == 1 and 'lacks what the CAN side needs: timestamp (the replay\'s clock, which urrt-dump --rtde -w '
          'always records)' in err and ' -k ' not in err,
          'a capture without timestamp is refused: no clock', err)

    rc, err = replay(write_ini('rt-refused', ROBOT % 'rtde' + FIELDS + REGISTERS, tmp('rt-refused.log')), rt_cap)
    check(rc == 1 and 'is a RealTime capture, which has no RTDE-only values' in err and
          'output_int_register_24 (frame regs, signal reg24, rt-refused.ini:28)' in err and
          'safety_status_bits (frame regs, signal safety_bits, rt-refused.ini:29)' in err and
          '-k output_int_register_24,safety_status_bits,robot_status_bits' in err,
          'RTDE-only signals from a RealTime capture: refused, naming them', err)

    ini = write_ini('no-var', ROBOT % 'realtime' + '[frame t]\nid = 0x110\nperiod_ms = every\n'
                    'signal = test_value @0|32 intel float32\n', tmp('no-var.log'))
    rc, err = replay(ini, main_cap)
    check(rc == 1 and 'lacks what the CAN side needs: RTDE has no test_value (frame t, signal test_value, '
          'no-var.ini:12): replay a RealTime capture (urrt-dump -w FILE) for them' in err,
          'a field RTDE has no variable for: refused, saying so', err)

    fake = tmp('fake.rtde')
    with open(fake, 'wb') as f:
        f.write(b'URRT something else\n')
    rc, err = replay(plc, fake)
    check(rc == 1 and 'is not an RTDE capture' in err, 'a file starting with U that is no capture: refused', err)


def test_cut_and_sessions(sim, main_cap, packages):
    data = open(main_cap, 'rb').read()
    cut = tmp('cut.rtde')
    with open(cut, 'wb') as f:
        f.write(data[:-7])  # inside the last data package
    log = tmp('cut.log')
    ini = write_ini('cut', ROBOT % 'rtde' + FIELDS, log)
    rc, err = replay(ini, cut)
    got = frames_of(log, {0x100})
    check(rc == 0 and 'ends inside a record' in err and len(got) == len(packages) - 1,
          'a capture cut inside a record: replayed up to the cut, with a warning',
          '%d frames for %d packages: %s' % (len(got), len(packages), err))

    records = []
    first = record_session(sim.port, RECIPE, 50, records)
    second = record_session(sim.port, RECIPE, 50, records)
    two = tmp('two.rtde')
    write_capture(two, records)
    log = tmp('two.log')
    rc, err = replay(write_ini('two', ROBOT % 'rtde' + FIELDS, log), two)
    got = frames_of(log, {0x100})
    times = [t for t, _, _ in got]
    want = [round(p['timestamp'] * 1e6) for p in first + second]
    check(rc == 0 and 'in 2 sessions' in err and len(got) == 100 and
          all(abs(a - b) <= 1 for a, b in zip(times, want)),
          'a capture of two sessions (a reconnect): both replayed on the controller\'s clock', err)


def test_dump(sim):
    """Captures urrt-dump --rtde -w records: with the register, rtde-plc.ini
    replays from it; without, it is refused naming the register."""
    cap = tmp('dump.rtde')
    r = subprocess.run(['timeout', '-k', '3', '30', DUMP, '--rtde', '127.0.0.1:%d' % sim.port, '-w', cap, '-k',
                        'output_int_register_24', '-n', '300', '-q'], capture_output=True, text=True,
                       errors='replace')
    packages = read_capture(cap)
    check(r.returncode == 0 and len(packages) == 300, 'urrt-dump --rtde -w -k output_int_register_24 -n 300',
          r.stderr)
    test_canopen(cap, packages, 'dump-plc')
    bare = tmp('dump-bare.rtde')
    r = subprocess.run(['timeout', '-k', '3', '30', DUMP, '--rtde', '127.0.0.1:%d' % sim.port, '-w', bare, '-n',
                        '20', '-q'], capture_output=True, text=True, errors='replace')
    text = open(os.path.join(ROOT, 'docs', 'examples', 'rtde-plc.ini')).read()
    ini = write_ini('dump-bare', re.sub(r'(?m)^interface = .*$', 'interface = log:LOG', text), tmp('dump-bare.log'))
    rc, err = replay(ini, bare)
    check(r.returncode == 0 and rc == 1 and
          'lacks what the CAN side needs: output_int_register_24 (frame tpdo1_program, signal parts, '
          'dump-bare.ini:' in err and err.rstrip().endswith('record them: urrt-dump --rtde -w FILE -k '
                                                            'output_int_register_24'),
          'urrt-dump\'s default recipe replayed with rtde-plc.ini: refused, naming output_int_register_24', err)


def main():
    for path in (SIM, GW, DUMP):
        if not os.access(path, os.X_OK):
            print('FAIL: %s is not built' % path, file=sys.stderr)
            return 1
    sim = suite.Sim(SIM, TMP, '-c', '5.12', timeout=120)
    try:
        reader = RealTimeReader(sim.rt_port)
        records = []
        packages = record_session(sim.port, RECIPE, 300, records)
        # The RealTime stream until it has passed the RTDE session's last package.
        rt = reader.stop()
        main_cap, rt_cap = tmp('main.rtde'), tmp('main.rt')
        write_capture(main_cap, records)
        with open(rt_cap, 'wb') as f:
            f.write(rt)
        test_frames(main_cap, packages, rt_cap)
        test_canopen(main_cap, packages)
        test_refusals(sim, main_cap, rt_cap)
        test_cut_and_sessions(sim, main_cap, packages)
        check(read_capture(main_cap) == packages, 'the recorder\'s capture reads back as recorded')
        test_dump(sim)
    finally:
        sim.stop()
    return suite.report()


if __name__ == '__main__':
    sys.exit(main())
