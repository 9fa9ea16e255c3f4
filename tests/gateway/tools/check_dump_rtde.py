#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-dump-rtde: urrt-dump --rtde against urrt-sim's RTDE port.

Every format, -k with urrt and RTDE names, CSV headers, the values against
urrt-dump's RealTime output of the same simulator at the same controller
time and the RTDE-only values against the simulator's documented model
(docs/tools.md, computed here from the timestamp), a -k field the controller
lacks (by the version table and by its NOT_FOUND), --list on 3.x and 5.x,
protocol 1 and 2, text messages, and a recording proxy that holds that
urrt-dump sends only V, v, O, S (and P) packages.

Every server takes its port from the system (port 0, port files); every wait
is for an event (a port file, the end of a process, a connection) with a
bound, never a sleep for something to have happened.

  check_dump_rtde.py BUILD
"""
import csv
import io
import json
import os
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

BUILD = sys.argv[1] if len(sys.argv) > 1 else 'build'
SIM = os.path.join(BUILD, 'bin', 'urrt-sim')
DUMP = os.path.join(BUILD, 'bin', 'urrt-dump')
TMP = tempfile.mkdtemp(prefix='urrt-dump-rtde.')
PASSED = FAILED = 0
START_TIME = 1000.0  # controller time of cycle 0 with --clock start (docs/tools.md)


def check(ok, what, detail=''):
    global PASSED, FAILED
    if ok:
        PASSED += 1
        print('ok: ' + what)
    else:
        FAILED += 1
        print('FAIL: %s%s' % (what, (': ' + str(detail)[:2000]) if detail else ''), file=sys.stderr)
    return ok


def wait_for(what, cond, proc=None, timeout=10.0):
    """Until cond() holds (polled), or fails at once when proc has ended."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return True
        if proc is not None and proc.poll() is not None:
            return cond()
        time.sleep(0.02)
    print('waited in vain for ' + what, file=sys.stderr)
    return False


class Sim:
    count = 0

    def __init__(self, *args):
        Sim.count += 1
        base = os.path.join(TMP, 'sim%d' % Sim.count)
        self.log_path, rt_pf, rtde_pf = base + '.log', base + '.rt', base + '.rtde'
        with open(self.log_path, 'w') as log:
            self.proc = subprocess.Popen(['timeout', '-k', '3', '90', SIM, '-l', '127.0.0.1:0', '--port-file', rt_pf,
                                          '--rtde', '127.0.0.1:0', '--rtde-port-file', rtde_pf, '-v'] + list(args),
                                         stderr=log)
        if not wait_for('the simulator\'s port files', lambda: os.path.exists(rtde_pf), self.proc):
            raise RuntimeError('simulator did not start: ' + open(self.log_path).read())
        self.rt_port = int(open(rt_pf).read())
        self.port = int(open(rtde_pf).read())
        self.addr = '127.0.0.1:%d' % self.port

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.proc.terminate()
        self.proc.wait(timeout=10)


def dump(*args, timeout=30):
    """urrt-dump to its end: (exit status, stdout, stderr)."""
    r = subprocess.run(['timeout', '-k', '3', str(timeout), DUMP] + list(args), capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def cycle(ts, rate):
    return round((ts - START_TIME) * rate)


def model(name, k):
    """The simulator's RTDE-only values at cycle k (docs/tools.md's table)."""
    if name.startswith('output_int_register_'):
        v = (k + int(name.rsplit('_', 1)[1])) & 0xFFFFFFFF
        return v - (1 << 32) if v >= 1 << 31 else v
    if name.startswith('output_double_register_'):
        return int(name.rsplit('_', 1)[1]) + k / 1000.0
    return {'output_bit_registers0_to_31': k & 0xFFFFFFFF, 'output_bit_registers32_to_63': ~k & 0xFFFFFFFF,
            'robot_status_bits': 3, 'safety_status_bits': 1, 'target_speed_fraction': 1.0}[name]


def rows(text):
    return list(csv.reader(io.StringIO(text)))


# ---- usage -------------------------------------------------------------------------
def usage_errors():
    cases = [
        (['-k', 'output_int_register_24', '127.0.0.1'], 'only RTDE has this value: add --rtde'),
        (['--rtde', '-k', 'test_value', '127.0.0.1'], 'RTDE has no such value (RealTime only)'),
        (['--list', '127.0.0.1'], 'give --rtde --list HOST[:PORT]'),
        (['--rtde', '--list', '-k', 'actual_q', '127.0.0.1'], '--list prints the variables and ends'),
        (['--rtde', '--file', '/dev/null'], 'with --rtde read HOST[:PORT] live'),
        (['--rtde', '-w', os.path.join(TMP, 'x'), '127.0.0.1'], 'with --rtde read HOST[:PORT] live'),
        (['--rtde', '-k', 'nosuch', '127.0.0.1'], '"nosuch"'),
        (['--rtde', '127.0.0.1:30003'], 'port 30003 is not RTDE'),
        (['--rtde', '--list', '[::1]:30013'], 'port 30013 is not RTDE'),
    ]
    for args, text in cases:
        rc, _, err = dump(*args, timeout=10)
        check(rc == 2 and text in err, 'usage error: %s' % ' '.join(args), err.strip())
    rc, _, err = dump('--rtde', '-k', 'nosuch', '127.0.0.1', timeout=10)
    check('q_actual' in err and 'actual_q' in err, 'an unknown -k name lists urrt names with their RTDE names', err)
    rc, out, _ = dump('--help', timeout=10)
    check('--rtde' in out and '--list' in out and '30004' in out, '--help shows --rtde and --list', out)


# ---- the recording proxy -------------------------------------------------------------
class Proxy:
    """Relays one client to the simulator and records the packages the client
    sends (type letter, payload), framed by RTDE's size field."""

    def __init__(self, port):
        self.upstream = port
        self.sent = []
        self.framing_error = None
        self.ls = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.ls.bind(('127.0.0.1', 0))
        self.ls.listen(4)
        self.port = self.ls.getsockname()[1]
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        try:
            c, _ = self.ls.accept()
        except OSError:
            return
        u = socket.create_connection(('127.0.0.1', self.upstream))
        back = threading.Thread(target=self.pipe, args=(u, c), daemon=True)
        back.start()
        try:
            self.record(c, u)
        except OSError:
            pass  # urrt-dump closed its end first: what it sent is recorded
        for s in (u, c):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    def record(self, c, u):
        buf = b''
        while True:
            data = c.recv(65536)
            if not data:
                break
            buf += data
            u.sendall(data)
            while len(buf) >= 3:
                size = struct.unpack('>H', buf[:2])[0]
                if size < 3:
                    self.framing_error = size
                    buf = b''
                    break
                if len(buf) < size:
                    break
                self.sent.append((chr(buf[2]), buf[3:size]))
                buf = buf[size:]

    @staticmethod
    def pipe(src, dst):
        try:
            while True:
                data = src.recv(65536)
                if not data:
                    break
                dst.sendall(data)
        except OSError:
            pass
        try:
            dst.shutdown(socket.SHUT_WR)
        except OSError:
            pass

    def close(self):
        self.ls.close()
        self.thread.join(timeout=10)


def bytes_sent():
    """urrt-dump sends only V, v, O, S (P) packages: the handshake of a read-only
    client, in protocol 2 and (after a refusal) protocol 1."""
    for args, protocols in (((), [2]), (('--fault', 'rtde-refuse-v2'), [2, 1])):
        with Sim('-c', '5.12.3.1234', *args) as sim:
            px = Proxy(sim.port)
            rc, out, err = dump('--rtde', '127.0.0.1:%d' % px.port, '-n', '20', '-F', 'csv', '--once',
                                '-k', 'time,actual_q,output_int_register_7')
            px.close()
            what = 'protocol %d' % protocols[-1]
            types = [t for t, _ in px.sent]
            check(rc == 0 and len(rows(out)) == 21, '%s through the proxy: 20 rows' % what, err)
            check(px.framing_error is None and set(types) <= set('VvOSP'),
                  '%s: only V, v, O, S, P packages sent' % what, types)
            versions = [struct.unpack('>H', p)[0] for t, p in px.sent if t == 'V']
            check(versions == protocols, '%s: V asks for %s' % (what, protocols), versions)
            check(types.count('v') == 1 and types.count('O') == 1 and types.count('S') == 1,
                  '%s: one v, one O, one S' % what, types)
            setup = [p for t, p in px.sent if t == 'O'][0]
            names = setup[8:] if protocols[-1] == 2 else setup
            check(names == b'timestamp,actual_q,output_int_register_7',
                  '%s: the recipe is the timestamp and -k, by RTDE names' % what, names)
            if protocols[-1] == 2:
                check(struct.unpack('>d', setup[:8])[0] == 500.0, 'protocol 2: the controller\'s rate, 500 Hz on 5.x',
                      setup[:8])
    with Sim('-c', '3.10') as sim:
        px = Proxy(sim.port)
        rc, out, err = dump('--rtde', '--list', '127.0.0.1:%d' % px.port)
        px.close()
        types = [t for t, _ in px.sent]
        check(rc == 0 and types == ['V', 'v', 'O'] and b'tcp_offset' in px.sent[2][1],
              '--list sends V, v and one O of the variables without a known version', (types, err))


# ---- formats, against RealTime -------------------------------------------------------
def rt_and_rtde(sim, rt_args, rtde_args):
    """urrt-dump of the RealTime port and urrt-dump --rtde of the same
    simulator at once: their outputs."""
    rt = subprocess.Popen(['timeout', '-k', '3', '30', DUMP, '127.0.0.1:%d' % sim.rt_port, '--no-summary'] + rt_args,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rc, out, err = dump('--rtde', sim.addr, *rtde_args)
    rt_out, rt_err = rt.communicate(timeout=40)
    return rc, out, err, rt_out


def same_values(version, rate, protocol_args):
    """CSV with urrt and RTDE names: the RealTime set equal, as printed, to
    urrt-dump's RealTime CSV at the same controller time; RTDE-only values as
    the simulator's model says."""
    with Sim('-c', version, *protocol_args) as sim:
        keys = 'time,actual_q,q_target,actual_TCP_pose,robot_mode,runtime_state,digital_input_bits,' \
               'output_int_register_3,output_double_register_5,safety_status_bits,robot_status_bits,' \
               'output_bit_registers32_to_63'
        rc, out, err, rt_out = rt_and_rtde(sim, ['-F', 'csv', '-n', str(rate * 2), '-k',
                                                 'time,q_actual,q_target,tool_vector_actual,robot_mode,program_state,'
                                                 'digital_input_bits'],
                                           ['-F', 'csv', '-n', str(rate), '-k', keys])
    what = '%s protocol %s' % (version, '1' if protocol_args else '2')
    r = rows(out)
    check(rc == 0 and len(r) == rate + 1, '%s: csv, %d rows' % (what, rate), err)
    header = r[0]
    want = (['time'] + ['q_actual[%d]' % i for i in range(6)] + ['q_target[%d]' % i for i in range(6)] +
            ['tool_vector_actual[%d]' % i for i in range(6)] +
            ['robot_mode', 'program_state', 'digital_input_bits', 'output_int_register_3', 'output_double_register_5',
             'safety_status_bits', 'robot_status_bits', 'output_bit_registers32_to_63'])
    check(header == want, '%s: csv header: urrt names (RTDE ones mapped) and RTDE-only names' % what, header)
    rt_rows = {row[0]: row for row in rows(rt_out)[1:]}
    common = [row for row in r[1:] if row[0] in rt_rows]
    check(len(common) >= rate // 2, '%s: %d of %d rows at a controller time RealTime printed too'
          % (what, len(common), rate), (r[1][0] if len(r) > 1 else '', list(rt_rows)[:3]))
    bad = [(row[0], row[:22], rt_rows[row[0]]) for row in common if row[:22] != rt_rows[row[0]]]
    check(common and not bad, '%s: the RealTime set equals RealTime\'s, digit for digit' % what, bad[:2])
    wrong = []
    for row in r[1:]:
        k = cycle(float(row[0]), rate)
        for name, text in zip(header[22:], row[22:]):
            v = float(text) if 'double' in name else int(text)
            if v != model(name, k):
                wrong.append((row[0], name, text, model(name, k)))
    check(len(r) > 1 and not wrong, '%s: RTDE-only values as the model says' % what, wrong[:4])
    steps = [cycle(float(b[0]), rate) - cycle(float(a[0]), rate) for a, b in zip(r[1:], r[2:])]
    check(steps and all(s >= 1 for s in steps) and steps.count(1) >= 0.9 * len(steps),
          '%s: every cycle (the controller\'s rate)' % what, steps[:20])


def formats():
    with Sim('-c', '5.12.3.1234') as sim:
        rc, out, err, rt_out = rt_and_rtde(sim, ['-F', 'gnuplot', '-n', '1000'], ['-F', 'gnuplot', '-n', '200'])
        lines = out.splitlines()
        check(rc == 0 and len(lines) == 201 and lines[0].startswith('# urrt-dump --rtde:'),
              'gnuplot: a comment line, then one line per package', err)
        check(' 1 time 2-7 q_target ' in lines[0] and '129-134 payload_inertia' in lines[0],
              'gnuplot: the comment names the columns (5.12: every RealTime field RTDE has)', lines[0])
        rt_lines = {ln.split()[0]: ln.split() for ln in rt_out.splitlines()[1:]}
        common = [ln.split() for ln in lines[1:] if ln.split()[0] in rt_lines]
        # Up to column 102 (safety mode) the layouts agree: RTDE lacks only
        # RealTime's test value (column 94) before the reserved columns.
        bad = [c[0] for c in common if c[:93] != rt_lines[c[0]][:93] or c[93:101] != rt_lines[c[0]][94:102]]
        check(len(common) >= 100 and not bad, 'gnuplot: %d lines equal to RealTime\'s columns at the same time'
              % len(common), bad[:3])

        rc, out, err = dump('--rtde', sim.addr, '-n', '3', '-F', 'json', '-k',
                            'actual_q,robot_mode,digital_outputs,output_int_register_40,tcp_offset,safety_status_bits')
        objs = [json.loads(ln) for ln in out.splitlines()]
        check(rc == 0 and len(objs) == 3, 'json: one object per package', err)
        o = objs[0]
        check(o.get('source') == 'rtde' and o.get('protocol') == 2 and o.get('controller') == '5.12.3.1234',
              'json: source, protocol, controller', o)
        check(list(o)[5:] == ['q_actual', 'robot_mode', 'robot_mode_name', 'digital_outputs', 'output_int_register_40',
                              'tcp_offset', 'safety_status_bits'], 'json: the -k keys in order, urrt and RTDE names',
              list(o))
        check(o['robot_mode_name'] == 'RUNNING' and o['tcp_offset'] == [0, 0, 0, 0, 0, 0] and o['safety_status_bits'] == 1,
              'json: enumeration names, vectors as arrays, integers', o)
        check(isinstance(o['digital_outputs'], int), 'json: an I/O mask as an integer', o)
        rc2, out2, _ = dump('--rtde', sim.addr, '-n', '1', '-F', 'json', '-k', 'time,output_int_register_40')
        o2 = json.loads(out2)
        check(o2['output_int_register_40'] == model('output_int_register_40', cycle(o2['time'], 500)),
              'json: an RTDE-only value as the model says', o2)

        rc, out, err = dump('--rtde', sim.addr, '-n', '2')
        check(rc == 0 and out.startswith('package 1: 1036 bytes, RTDE protocol 2, controller 5.12.3.1234\n'),
              'table: the head names the package, protocol and controller', out[:200])
        check('  robot_mode             enum       RUNNING(7)' in out and 'payload_inertia' in out and
              'package 2: ' in out, 'table: every field of 5.12 by urrt name, enumerations by name', out[:3000])
        check('summary: lengths: 1036 x 2 (RTDE data packages)' in err and
              'summary: rtde: controller 5.12.3.1234, protocol 2' in err and 'summary: rtde recipe: timestamp,' in err,
              'table: the summary says what the session was', err)
        rc, out, err = dump('--rtde', sim.addr, '-n', '1', '-k', 'q_actual,output_int_register_2,tcp_offset')
        lines = {ln.split()[0]: ln.split()[1:] for ln in out.splitlines()[1:]}
        check(rc == 0 and lines['output_int_register_2'][0] == 'INT32' and lines['output_int_register_2'][1].isdigit()
              and lines['tcp_offset'] == ['VECTOR6D'] + ['0'] * 6,
              'table: RTDE-only values with their type', out)


def three_x():
    """3.10 (125 Hz): the RealTime set it has; payload_inertia it lacks."""
    with Sim('-c', '3.10') as sim:
        rc, out, err = dump('--rtde', sim.addr, '-n', '1', '-F', 'json')
        o = json.loads(out) if rc == 0 else {}
        check('safety_status' in o and 'payload_mass' not in o and 'payload_inertia' not in o,
              '3.10 without -k: its fields (safety_status), not those it lacks (payload)', list(o))
        for key, name in (('payload_inertia', 'payload_inertia'), ('ft_raw_wrench', 'ft_raw_wrench'),
                          ('payload_mass', 'payload')):
            rc, out, err = dump('--rtde', sim.addr, '-n', '1', '-k', 'time,' + key, '--no-summary')
            check(rc == 1 and out == '' and ('-k %s: the controller (version 3.10.0.0) has no RTDE output %s' % (key, name))
                  in err, '-k %s on 3.10 (version table): an error naming the field and the version' % key, err)
            check(err.count('error:') == 1, '-k %s on 3.10: one error line' % key, err)
        # No version known for it: the controller's NOT_FOUND says (the simulator
        # serves the energy values from 5.23).
        rc, out, err = dump('--rtde', sim.addr, '-n', '1', '-k', 'actual_robot_braking_energy_dissipated', '--no-summary')
        check(rc == 1 and '-k actual_robot_braking_energy_dissipated: the controller (version 3.10.0.0) has no RTDE '
              'output actual_robot_braking_energy_dissipated' in err and err.count('error:') == 1,
              '-k of a variable the controller answers NOT_FOUND for: the same error', err)


def lists():
    for version, yes, no in (('3.10', ['safety_status', 'output_int_register_24', 'elbow_position'],
                              ['payload_inertia', 'ft_raw_wrench', 'control_step']),
                             ('5.12.3.1234', ['payload_inertia', 'ft_raw_wrench', 'output_bit_register_64'],
                              ['control_step', 'time_scale_source', 'actual_current_as_torque'])):
        with Sim('-c', version) as sim:
            rc, out, err = dump('--rtde', '--list', sim.addr)
        lines = out.splitlines()
        table = {ln.split()[0]: ln for ln in lines[2:]}
        check(rc == 0 and lines[0].startswith('controller %s' % (version if version.count('.') == 3 else version + '.0.0')),
              '--list %s: the controller version first' % version, out[:200] + err)
        check(len(table) == len(lines) - 2 and 'output_double_register_47' in table and 'timestamp' in table,
              '--list %s: every variable, families by name' % version, len(table))
        check(all(table[n].endswith(' yes') for n in yes) and all(table[n].endswith(' no') for n in no),
              '--list %s: the version table\'s yes and no' % version, [table.get(n) for n in yes + no])
        check(table['actual_q'].split()[1:3] == ['VECTOR6D', 'q_actual'] and table['output_int_register_24'].split()[1] == 'INT32',
              '--list %s: types and urrt names' % version, table['actual_q'])
        check(table['tcp_offset'].endswith('yes (asked: no version known)') and
              table['actual_robot_braking_energy_dissipated'].endswith('no (asked: NOT_FOUND)'),
              '--list %s: where no version is known, the controller\'s answer' % version,
              (table['tcp_offset'], table['actual_robot_braking_energy_dissipated']))
        check('error' not in err, '--list %s: the expected NOT_FOUND is no error line' % version, err)


def texts():
    with Sim('-c', '5.12.3.1234', '--fault', 'rtde-text-every=5,level=3') as sim:
        rc, out, err = dump('--rtde', sim.addr, '-n', '12', '-F', 'csv', '-k', 'time')
    check(rc == 0 and err.count('controller says (info) from urrt-sim: ') == 2,
          'text messages at level info shown on stderr with their level', err)
    with Sim('-c', '5.12.3.1234', '--fault', 'rtde-text-every=5,level=2') as sim:
        rc, out, err = dump('--rtde', sim.addr, '-n', '12', '-F', 'csv', '-k', 'time')
    check(rc == 0 and err.count('warning: robot 127.0.0.1: controller says from urrt-sim: ') == 2,
          'text messages at level warning shown as warnings', err)
    with Sim('-c', '3.10', '--fault', 'rtde-refuse-v2', '--fault', 'rtde-text-every=5,level=1') as sim:
        rc, out, err = dump('--rtde', sim.addr, '-n', '12', '-F', 'csv', '-k', 'time')
    check(rc == 0 and err.count('error: robot 127.0.0.1: controller says') == 2 and 'RTDE protocol 2: asking for 1' in err,
          'protocol 1: text messages (their layout) shown as errors', err)


def no_rtde():
    """A port that refuses: --once ends with what to check."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind(('127.0.0.1', 0))  # held, not listening: connections are refused
    port = s.getsockname()[1]
    rc, out, err = dump('--rtde', '127.0.0.1:%d' % port, '--once', '--no-summary', timeout=20)
    s.close()
    check(rc == 1 and 'no RTDE data package' in err and 'Security > Services' in err and '30004' in err,
          'a refused RTDE port: exit 1, saying to check the port and that RTDE is enabled', err)
    rc, out, err = dump('--rtde', '--list', '127.0.0.1:%d' % port, timeout=20)
    check(rc == 1 and out == '', '--list of a refused port: exit 1, nothing listed', err)


def run(group, *args):
    try:
        group(*args)
    except Exception as e:  # noqa: BLE001  any of them is a failure to report
        check(False, '%s%s raised %s' % (group.__name__, args, type(e).__name__), e)


def main():
    run(usage_errors)
    run(bytes_sent)
    run(same_values, '5.12.3.1234', 500, ())
    run(same_values, '3.10', 125, ('--fault', 'rtde-refuse-v2'))
    run(formats)
    run(three_x)
    run(lists)
    run(texts)
    run(no_rtde)
    print('%d passed, %d failed' % (PASSED, FAILED))
    return 1 if FAILED else 0


if __name__ == '__main__':
    try:
        sys.exit(main())
    finally:
        subprocess.run(['rm', '-rf', TMP])
