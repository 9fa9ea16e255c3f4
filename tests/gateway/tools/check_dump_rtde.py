#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-dump-rtde: urrt-dump --rtde against urrt-sim's RTDE port.

Every format, -k with urrt and RTDE names, CSV headers, the values against
urrt-dump's RealTime output of the same simulator at the same controller
time and the RTDE-only values against the simulator's documented model
(docs/tools.md, computed here from the timestamp), a -k field the controller
lacks (by the version table and by its NOT_FOUND), --list on 3.x and 5.x,
protocol 1 and 2, text messages, and a recording proxy that holds that
urrt-dump sends only V, v, O, S (and P) packages. RTDE captures (--rtde -w,
read back by --file): read by tests/ref/rtde_capture.py, a reader written
from the format; the recipe recorded, by UR's version table as typed here;
--file printing what the recording run printed live in every format; a
capture cut short, a damaged one, a wrong header, a RealTime capture beside
them, and sessions across reconnects.

Every server takes its port from the system (port 0, port files); every wait
is for an event (a port file, the end of a process, a connection) with a
bound, never a sleep for something to have happened.

  check_dump_rtde.py BUILD
"""
import csv
import io
import json
import os
import re
import socket
import struct
import subprocess
import sys
import tempfile
import threading

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'ref'))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
import rtde_capture  # noqa: E402  the independent reader of the format
import suite  # noqa: E402  checks, their report, waits
from suite import check, end_group, wait_for  # noqa: E402
from rtde_ref import MAPPED  # noqa: E402  the RTDE names RealTime has too, from the protocol

BUILD = sys.argv[1] if len(sys.argv) > 1 else 'build'
SIM = os.path.join(BUILD, 'bin', 'urrt-sim')
DUMP = os.path.join(BUILD, 'bin', 'urrt-dump')
TMP = tempfile.mkdtemp(prefix='urrt-dump-rtde.')
START_TIME = 1000.0  # controller time of cycle 0 with --clock start (docs/tools.md)


def Sim(*args):
    """The simulator of these checks (tests/suite.py's), with its arguments."""
    return suite.Sim(SIM, TMP, *args)


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
        (['--rtde', '--file', '/dev/null'], 'is no RTDE capture (it is empty'),
        (['--rtde', '--file', '/dev/null', '-k', 'test_value'], 'RTDE has no such value (RealTime only)'),
        (['--rtde', '-k', 'nosuch', '127.0.0.1'], '"nosuch"'),
        # Every port that runs what it receives, or is such a port's twin (the
        # controller's servers as UR documents them, not lib's table).
        (['--rtde', '127.0.0.1:29999'], 'port 29999 is the dashboard server, which runs the commands it receives: '
         'RTDE is port 30004'),
        (['--rtde', '127.0.0.1:30001'], 'port 30001 is the primary client interface, which runs the URScript'),
        (['--rtde', '127.0.0.1:30002'], 'port 30002 is the secondary client interface, which runs the URScript'),
        (['--rtde', '127.0.0.1:30003'], 'port 30003 is the RealTime interface, which runs the URScript it receives'),
        (['--rtde', '127.0.0.1:30011'], "port 30011 is the primary client interface's read-only twin"),
        (['--rtde', '127.0.0.1:30012'], "port 30012 is the secondary client interface's read-only twin"),
        (['--rtde', '--list', '[::1]:30013'], "port 30013 is the RealTime interface's read-only twin"),
        (['--rtde', '127.0.0.1:30020'], "port 30020 is the interpreter mode's socket, which runs the URScript"),
        (['127.0.0.1:30004'], "port 30004 is RTDE's on every controller, which sends nothing until a client's "
         "handshake: add --rtde"),
    ]
    for args, text in cases:
        rc, _, err = dump(*args, timeout=10)
        check(rc == 2 and text in err, 'usage error: %s' % ' '.join(args), err.strip())
    # A misspelled -k name: the nearest name of both of lib's tables (the RealTime
    # fields, the RTDE variables with each index of a family), or a family's
    # range, in one line and the usage hint: never a list of names.
    misspelled = [
        ('robot_status_bit', 'did you mean "robot_status_bits"?'),
        ('safety_status_bit', 'did you mean "safety_status_bits"?'),
        ('outptu_int_register_24', 'did you mean "output_int_register_24"?'),
        ('output_bit_register_3', 'did you mean one of output_bit_register_64 to output_bit_register_127?'),
        ('standard_analog_input2', 'did you mean one of standard_analog_input0 to standard_analog_input1?'),
        ('actual_TCP_Pose', 'did you mean "actual_TCP_pose"?'),
        ('q_actul', 'did you mean "q_actual"?'),
    ]
    for name, hint in misspelled:
        rc, out, err = dump('--rtde', '-k', 'time,' + name, '127.0.0.1', timeout=10)
        want = 'urrt-dump: -k: no field or RTDE value named "%s": %s\nTry \'urrt-dump --help\'.\n' % (name, hint)
        check(rc == 2 and out == '' and err == want, '-k %s: %s, and nothing else' % (name, hint), err)
    rc, _, err = dump('--rtde', '-k', 'nosuch', '127.0.0.1', timeout=10)
    check(rc == 2 and err == 'urrt-dump: -k: no field or RTDE value named "nosuch" (docs/protocol.md lists the '
          'fields, docs/rtde.md the RTDE names; --rtde --list HOST what a controller has)\n'
          "Try 'urrt-dump --help'.\n", 'an unknown -k name nothing is near: where the names are, not a list', err)
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
        # What the RTDE session counted, in its words: the four replies of the
        # handshake and at least the two data packages of -n 2, 1036 bytes
        # each; RealTime's framer words (resyncs, partial packets) are not
        # RTDE's.
        counts = re.search(r'^summary: rtde packages: (\d+), data packages: (\d+), text messages: (\d+), '
                           r'ignored: (\d+), errors: (\d+), bytes: (\d+)$', err, re.M)
        n = [int(x) for x in counts.groups()] if counts else []
        check(counts and n[1] >= 2 and n[0] >= n[1] + 4 and n[2] == n[3] == n[4] == 0 and n[5] >= 2 * 1036,
              'summary: the RTDE session\'s packages, data packages, text messages, ignored, errors, bytes', err)
        check(re.search(r'^summary: rtde partial package dropped at close: \d+ bytes$', err, re.M) and
              'resyncs' not in err and 'partial packets' not in err and 'generations' not in err,
              'summary: the bytes of a package cut short at close, no RealTime words (resyncs, partial packets)', err)
        rc, out, err = dump('--rtde', sim.addr, '-n', '1', '-k',
                            'q_actual,output_int_register_2,tcp_offset,actual_configurable_digital_input_bits')
        lines = {ln.split()[0]: ln.split()[1:] for ln in out.splitlines()[1:]}
        check(rc == 0 and lines['output_int_register_2'][0] == 'INT32' and lines['output_int_register_2'][1].isdigit()
              and lines['tcp_offset'] == ['VECTOR6D'] + ['0'] * 6,
              'table: RTDE-only values with their type', out)
        # Where each line's second column (unit or type) begins: one place for all, past the longest name.
        starts = {ln.index(' ' + ln.split()[1], 2 + len(ln.split()[0])) + 1 for ln in out.splitlines()[1:]}
        check(len(starts) == 1 and min(starts) > 2 + len('actual_configurable_digital_input_bits'),
              'table: the columns line up past the longest name (38 characters)', out)


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


def port_mixups():
    """Each interface read at the other's port: the failure names the other interface."""
    with Sim('-c', '5.12.3.1234') as sim:
        rt = '127.0.0.1:%d' % sim.rt_port
        rc, out, err = dump('--rtde', rt, '--once', '--no-summary', timeout=20)
        check(rc == 1 and 'the peer streams without a handshake, as a RealTime port (30003) does: its first bytes '
              'announce a 1220-byte RealTime packet' in err and 'read it as RealTime (urrt-dump without --rtde' in err
              and 'package size below' not in err,
              '--rtde at a RealTime port: it streams without a handshake, drop --rtde', err)
        rc, out, err = dump(sim.addr, '--once', '--no-summary', '--silence-timeout', '200', timeout=20)
        check(rc == 1 and 'before sending anything: an RTDE port (30004) sends nothing until a client\'s handshake; '
              'if this is one, read it as RTDE (urrt-dump --rtde' in err,
              'RealTime at an RTDE port: it waits for a handshake, add --rtde', err)


# ---- captures: --rtde -w, --file ------------------------------------------------------
# What a recording asks for without -k, from UR's version table (typed here
# from UR's RTDE guide, not from lib/): (CB3 since, e-Series since), None
# for never. Every other RealTime value and these RTDE-only status values
# have no version (all versions of RTDE).
VERSIONED = {
    'elbow_position': ((3, 5), (5, 0)), 'elbow_velocity': ((3, 5), (5, 0)),
    'safety_status': ((3, 10), (5, 4)), 'payload': ((3, 11), (5, 5, 1)), 'payload_cog': ((3, 11), (5, 5, 1)),
    'payload_inertia': ((3, 15), (5, 11)),
    'input_bit_registers0_to_31': ((3, 4), (5, 0)), 'input_bit_registers32_to_63': ((3, 4), (5, 0)),
    'script_control_line': ((3, 14), (5, 9)), 'ft_raw_wrench': (None, (5, 9)),
    'collision_detection_ratio': (None, (5, 15)), 'time_scale_source': (None, (5, 17)),
    'actual_current_as_torque': (None, (5, 23)), 'actual_robot_energy_consumed': (None, (5, 23)),
    'target_gravity': (None, (5, 26)), 'target_base_acceleration': (None, (5, 26)),
    'control_step': (None, (5, 26)), 'target_base_wrench': (None, (5, 26)),
}
STATUS_ALWAYS = ['target_speed_fraction', 'robot_status_bits', 'safety_status_bits', 'output_bit_registers0_to_31',
                 'output_bit_registers32_to_63', 'analog_io_types', 'io_current', 'euromap67_input_bits',
                 'euromap67_output_bits', 'euromap67_24V_voltage', 'euromap67_24V_current', 'tool_mode',
                 'tool_analog_input_types', 'tool_output_voltage', 'tool_output_current', 'tool_temperature',
                 'tcp_force_scalar']
STATUS_VERSIONED = [n for n in VERSIONED if n not in MAPPED]


def recorded_names(version, keys):
    """The recipe urrt-dump --rtde -w -k KEYS asks a controller of version
    (a tuple) for: as a set, the timestamp apart."""
    line = 0 if version[0] == 3 else 1

    def has(name):
        since = VERSIONED.get(name, ((0,), (0,)))[line]
        return since is not None and version >= since
    return {n for n in list(MAPPED) + STATUS_ALWAYS + STATUS_VERSIONED if has(n)} | set(keys)


KEYS = ['timestamp', 'actual_q', 'robot_mode', 'output_int_register_24', 'output_double_register_3',
        'safety_status_bits']


def cut(path, name, data):
    out = os.path.join(TMP, name)
    with open(out, 'wb') as f:
        f.write(data)
    return out


def recording(sim, name, *args, n=100):
    """urrt-dump --rtde -w: (status, live stdout, stderr, capture path)."""
    path = os.path.join(TMP, name)
    rc, out, err = dump('--rtde', sim.addr, '-w', path, '-n', str(n), *args)
    return rc, out, err, path


def capture_read_back():
    """A recording read by the independent reader: the recipe of the version,
    the client's requests, every data package as urrt-dump printed it live;
    --file gives the live output again, with either name of a value, from a
    pipe and with --rtde."""
    keys = ','.join(KEYS)
    with Sim('-c', '5.12.3.1234') as sim:
        rc, live, err, path = recording(sim, 'c1.rtde', '-F', 'json', '-k', keys, n=200)
    check(rc == 0 and len(live.splitlines()) == 200, 'a recording run prints its 200 packages live', err)
    cap = rtde_capture.read_file(path)
    ses = rtde_capture.sessions(cap)
    check(cap.truncated == 0 and len(ses) == 1 and ses[0].peer == sim.addr,
          'the capture: one session, whole, its "C" record naming the peer', (cap.truncated, [s.peer for s in ses]))
    s = ses[0]
    check([t for t, _ in s.requests] == ['V', 'v', 'O', 'S'] and s.protocol == 2 and
          s.controller == (5, 12, 3, 1234), 'the capture holds the client\'s requests and the controller\'s replies',
          ([t for t, _ in s.requests], s.protocol, s.controller))
    want = recorded_names((5, 12, 3), KEYS)
    check(s.names[0] == 'timestamp' and len(set(s.names)) == len(s.names) and set(s.names) == want,
          'the recipe recorded on 5.12: the RealTime set, the status values 5.12 has, the -k names',
          (sorted(set(s.names) - want), sorted(want - set(s.names))))
    check(len(s.types) == len(s.names) and 'NOT_FOUND' not in s.types, 'the controller has every name recorded',
          s.types)
    objs = [json.loads(ln) for ln in live.splitlines()]
    same = len(s.data) == len(objs) and all(
        d['timestamp'] == o['time'] and list(d['actual_q']) == o['q_actual'] and d['robot_mode'] == o['robot_mode']
        and d['output_int_register_24'] == o['output_int_register_24'] and
        d['output_double_register_3'] == o['output_double_register_3'] and
        d['safety_status_bits'] == o['safety_status_bits'] for d, o in zip(s.data, objs))
    check(same, 'the capture holds exactly the 200 packages printed live, value for value', (len(s.data), len(objs)))

    rc, out, err = dump('--file', path, '-F', 'json', '-k', keys)
    check(rc == 0 and out == live, '--file prints what the recording run printed live (json, -k)', err)
    rc, out2, _ = dump('--file', path, '-F', 'json', '-k', 'time,q_actual,robot_mode,output_int_register_24,'
                       'output_double_register_3,safety_status_bits')
    check(rc == 0 and out2 == live, '-k takes urrt names and RTDE names alike', out2[:300])
    rc, out3, _ = dump('--rtde', '--file', path, '-F', 'json', '-k', keys)
    check(rc == 0 and out3 == live, '--rtde --file: the same', out3[:300])
    with open(path, 'rb') as f:
        r = subprocess.run(['timeout', '-k', '3', '30', DUMP, '--file', '-', '-F', 'json', '-k', keys], stdin=f,
                           capture_output=True, text=True)
    check(r.returncode == 0 and r.stdout == live, '--file - reads a capture from a pipe', r.stderr)
    check('summary: packets: 200' in err and 'summary: rtde: controller 5.12.3.1234, protocol 2' in err and
          'summary: rtde recipe: timestamp,' in err and 'output_int_register_24' in err and
          'summary: rtde capture: sessions 1, last record cut short: 0 bytes' in err,
          '--file\'s summary: packages, controller, protocol, recipe, sessions', err)
    # The replay's session counted exactly what the capture received, by the independent reader.
    got = [r for r in cap.records if r.kind == '<']
    want = 'summary: rtde packages: %d, data packages: %d, text messages: %d, ignored: 0, errors: 0, bytes: %d' % (
        len(got), sum(r.type == 'U' for r in got), sum(r.type == 'M' for r in got), sum(3 + len(r.payload) for r in got))
    check(want in err and 'partial package dropped at close' not in err and 'resyncs' not in err,
          '--file\'s summary: the session\'s counts are the capture\'s received packages (%s)' % want, err)
    rc, _, err = dump('--file', path, '-k', 'time,output_int_register_5')
    check(rc == 1 and '-k output_int_register_5: the capture' in err and
          'record it with urrt-dump --rtde -w FILE -k output_int_register_5' in err,
          '-k of a value the capture lacks: exit 1, saying how to record it', err)

    # Cut short inside its last record (a data package), and damaged.
    with open(path, 'rb') as f:
        data = f.read()
    last = cap.records[-1]
    check(last.kind == '<' and last.type == 'U', 'the capture ends with the last data package printed', last)
    short = cut(path, 'short.rtde', data[:last.offset + 10])
    rc, out, err = dump('--file', short, '-F', 'json', '-k', keys)
    check(rc == 0 and out.splitlines() == live.splitlines()[:-1] and 'cut short (10 bytes' in err and
          'last record cut short: 10 bytes' in err,
          'a record cut short: a notice with its bytes, every package before it, exit 0', err)
    data_records = [r for r in cap.records if r.type == 'U']
    bad_at = data_records[99].offset
    bad = cut(path, 'bad.rtde', data[:bad_at] + b'X' + data[bad_at + 1:])
    rc, out, err = dump('--file', bad, '-F', 'json', '-k', keys)
    check(rc == 1 and out.splitlines() == live.splitlines()[:99] and
          ('byte %d: record kind 0x58' % bad_at) in err, 'a damaged record: its byte offset, exit 1, the packages '
          'before it', (rc, len(out.splitlines()), err))
    try:
        rtde_capture.read(data[:bad_at] + b'X' + data[bad_at + 1:])
        check(False, 'the reference reader refuses the damaged copy')
    except rtde_capture.CaptureError as e:
        check(e.offset == bad_at, 'the reference reader finds the damage at the same byte', e)
    header = cut(path, 'header.rtde', b'URRT RTDE capture 2\n' + data[20:])
    rc, out, err = dump('--file', header)
    check(rc == 1 and out == '' and 'not an RTDE capture' in err and 'URRT RTDE capture 1' in err,
          'a file starting with "U" but another header: refused, naming the header', err)


def capture_formats():
    """Every format, live while recording and from the capture: the same."""
    with Sim('-c', '5.12.3.1234') as sim:
        for fmt, args in (('table', ()), ('table', ('-k', 'time,actual_q,output_int_register_2,tcp_force_scalar')),
                          ('csv', ('-k', ','.join(KEYS))), ('csv', ()), ('json', ()), ('gnuplot', ())):
            name = 'f-%s-%d.rtde' % (fmt, len(args))
            rc, live, err, path = recording(sim, name, '-F', fmt, *args, n=30)
            rc2, out, err2 = dump('--file', path, '-F', fmt, *args)
            check(rc == 0 and rc2 == 0 and live and out == live, '%s%s: --file prints what the recording printed'
                  % (fmt, ' -k' if args else ''), (err2, out[:300], live[:300]))
        check('output_bit_registers32_to_63' in live.splitlines()[0] and 'ft_raw_wrench' in live.splitlines()[0],
              'gnuplot of a recording names its RTDE-only columns too', live.splitlines()[0])


def capture_3x():
    """3.10 in protocol 1: the recipe without what 3.10 lacks, printed again."""
    with Sim('-c', '3.10', '--fault', 'rtde-refuse-v2') as sim:
        rc, live, err, path = recording(sim, 'c310.rtde', '-F', 'csv', n=50)
    ses = rtde_capture.sessions(rtde_capture.read_file(path))
    s = ses[0] if ses else None
    want = recorded_names((3, 10, 0), ['timestamp'])
    check(rc == 0 and s is not None and s.protocol == 1 and [t for t, _ in s.requests] == ['V', 'V', 'v', 'O', 'S'],
          '3.10: the capture holds the refused protocol 2 and protocol 1', s and [t for t, _ in s.requests])
    check(s is not None and set(s.names) == want, 'the recipe recorded on 3.10: no payload*, no script_control_line',
          s and (sorted(set(s.names) - want), sorted(want - set(s.names))))
    check(s is not None and len(s.data) == 50 and s.data[0]['safety_status_bits'] == 1,
          '3.10: the reference decodes protocol 1\'s packages', s and len(s.data))
    rc, out, err = dump('--file', path, '-F', 'csv')
    check(rc == 0 and out == live and 'refuses RTDE protocol 2: asking for 1' in err,
          '3.10: --file prints the live csv again, and says protocol 2 was refused', err)


def capture_sessions():
    """A recording across reconnects (the simulator closes every 40 packages):
    one session per connection, printed as they were live."""
    with Sim('-c', '5.12.3.1234', '--fault', 'close-after=40') as sim:
        rc, live, err, path = recording(sim, 'c2.rtde', '-F', 'csv', '-k', ','.join(KEYS), n=100)
    ses = rtde_capture.sessions(rtde_capture.read_file(path))
    check(rc == 0 and len(rows(live)) == 101 and 'reconnecting' in err, 'a recording across reconnects: 100 rows live',
          err)
    check(len(ses) == 3 and [len(s.data) for s in ses] == [40, 40, 20] and
          all([t for t, _ in s.requests] == ['V', 'v', 'O', 'S'] for s in ses),
          'three sessions, each with its whole handshake and its packages', [(len(s.data), s.requests) for s in ses])
    rc, out, err = dump('--file', path, '-F', 'csv', '-k', ','.join(KEYS))
    check(rc == 0 and out == live, 'its sessions print as they did live (one header, every row)', err)
    check('session 2: connected to %s' % sim.addr in err and 'session 3: connected to' in err and
          'sessions 3' in err, 'each new session is told on stderr, the summary counts them', err)


def capture_budget():
    """-k names that leave no room: the recording drops the last status values
    not named, says which, and keeps within UR's 2048 bytes and 128 names."""
    keys = ['output_int_register_%d' % i for i in range(48)] + ['output_double_register_%d' % i for i in range(3)]
    with Sim('-c', '5.12.3.1234') as sim:
        rc, live, err, path = recording(sim, 'budget.rtde', '-F', 'csv', '-k', ','.join(keys), n=5)
    ses = rtde_capture.sessions(rtde_capture.read_file(path))
    names = ses[0].names if ses else []
    dropped = err.split('the recording leaves out ')[1].split(':')[0].split(', ') if 'leaves out' in err else []
    check(rc == 0 and len(rows(live)) == 6, 'a recording with 51 registers in -k runs', err)
    check(len(names) <= 128 and len(','.join(names)) <= 2048 and set(keys) <= set(names) and
          set(MAPPED) & recorded_names((5, 12, 3), []) <= set(names),
          'its recipe: within 128 names and 2048 bytes, every -k name and the RealTime set',
          (len(names), len(','.join(names))))
    check(dropped and 'safety_status_bits' not in dropped and not set(dropped) & set(names) and
          set(names) | set(dropped) >= recorded_names((5, 12, 3), keys),
          'the notice names the status values left out (the last ones first)', dropped)


def capture_realtime():
    """A RealTime capture beside them: still read as RealTime; --rtde refuses it."""
    with Sim('-c', '5.12.3.1234') as sim:
        path = os.path.join(TMP, 'rt.bin')
        rc, live, err = dump('127.0.0.1:%d' % sim.rt_port, '-w', path, '-n', '20', '-F', 'json')
    rc2, out, err2 = dump('--file', path, '-F', 'json')
    check(rc == 0 and rc2 == 0 and out == live and '"generation":"3.x/5.x"' in out,
          'a RealTime capture reads as RealTime', err2)
    rc, out, err = dump('--rtde', '--file', path)
    check(rc == 2 and out == '' and 'is no RTDE capture (it starts as a RealTime capture does' in err and
          'drop --rtde' in err, '--rtde --file of a RealTime capture: refused, saying what to do', err)
    rc, out, err = dump('--file', path, '-k', 'output_int_register_24')
    check(rc == 2 and 'only RTDE has this value, and %s is a RealTime capture' % path in err,
          '-k of an RTDE-only value on a RealTime capture: refused', err)


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
    run(port_mixups)
    run(capture_read_back)
    run(capture_formats)
    run(capture_3x)
    run(capture_sessions)
    run(capture_budget)
    run(capture_realtime)
    return suite.report()


if __name__ == '__main__':
    try:
        sys.exit(main())
    finally:
        subprocess.run(['rm', '-rf', TMP])
