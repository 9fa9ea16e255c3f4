#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-sim-rtde: urrt-sim's RTDE port against an RTDE client written from
the protocol's description (rtde_peer.py), and against its own RealTime port;
and urrt-sim --replay of RTDE captures (urrt-dump --rtde -w recordings, read
back by the independent reader tests/ref/rtde_capture.py).

Every simulator takes its ports from the system (port 0, port files); every
wait is for an event (a port file, a package, a log line, the end of a
connection) with a bound, never a sleep for something to have happened.

  check_sim_rtde.py BUILD
"""
import os
import socket
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'ref'))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
import rt  # noqa: E402  the RealTime reference: column table
import suite  # noqa: E402  checks, their report, waits
from suite import check, end_group, wait_for  # noqa: E402
import rtde_capture as ref_capture  # noqa: E402  the independent reader of RTDE captures
from rtde_peer import Peer, CaptureWriter, Closed, Unframable, M, U, TYPES  # noqa: E402

BUILD = sys.argv[1] if len(sys.argv) > 1 else 'build'
SIM = os.path.join(BUILD, 'bin', 'urrt-sim')
TMP = tempfile.mkdtemp(prefix='urrt-sim-rtde.')
START_TIME = 1000.0  # controller time of cycle 0 (docs/tools.md)


def Sim(*args):
    """The simulator of these checks (tests/suite.py's), with its arguments."""
    return suite.Sim(SIM, TMP, *args, timeout=60)


def cycle(ts, rate):
    """The control cycle of a timestamp (--clock start)."""
    return round((ts - START_TIME) * rate)


def steps_of(pk, rate):
    """Cycles between consecutive data packages, by their timestamps."""
    return [cycle(b[0], rate) - cycle(a[0], rate) for a, b in zip(pk, pk[1:])]


def regular(steps, d):
    """Every d-th cycle: each step d, or a multiple of it where a loaded
    machine held the simulator past its catch-up limit (it then skips whole
    cycles, never sends them late), at most one step in ten."""
    return bool(steps) and all(x > 0 and x % d == 0 for x in steps) and steps.count(d) >= 0.9 * len(steps)


# ---- usage -------------------------------------------------------------------------
def usage_errors():
    cases = [
        (['--rtde', '127.0.0.1:0', '--replay', '/dev/null'], 'no RTDE capture (a RealTime capture has no RTDE to '
                                                              'serve): drop --rtde'),
        (['--rtde', '127.0.0.1:0', '--length', '1116'], 'give --controller V, not --length'),
        (['--rtde', '127.0.0.1:0', '-c', '3.2'], 'no RTDE on this version'),
        (['--rtde', '127.0.0.1:0', '-c', '5.10', '--rate', '125'], 'runs at 500 Hz on both ports: drop --rate'),
        (['--fault', 'rtde-refuse-v2'], 'an rtde-* fault goes with --rtde'),
        (['--rtde-port-file', 'x'], '--rtde-port-file goes with --rtde'),
        (['--fieldbus'], '--fieldbus goes with --rtde'),
        (['--rtde', '127.0.0.1:0', '--fault', 'rtde-hold-inputs=5'], 'takes no value'),
        (['--rtde', '127.0.0.1:0', '--fault', 'rtde-hold-inputs,for=0'], 'from 1 to 86400000'),
        (['--fault', 'rtde-hold-inputs'], 'an rtde-* fault goes with --rtde'),
        (['--rtde', '127.0.0.1:0', '--fault', 'rtde-bad-package=3,kind=odd'], 'kind is size, type, recipe or header'),
        (['--rtde', '127.0.0.1:0', '--fault', 'rtde-text-every=3,level=4'], 'from 0 to 3'),
        (['--rtde', '127.0.0.1:0', '--fault', 'rtde-refuse-v2=1'], 'takes no value'),
        (['--rtde', '127.0.0.1:99999'], '--rtde 127.0.0.1:99999'),
    ]
    for args, text in cases:
        r = subprocess.run([SIM] + args, capture_output=True, text=True, timeout=10)
        check(r.returncode == 2 and text in r.stderr, 'usage error: %s' % ' '.join(args), r.stderr.strip())


# ---- handshakes, versions, variables -------------------------------------------------
RECIPE = ['timestamp', 'actual_q', 'robot_mode', 'joint_mode', 'actual_digital_input_bits', 'runtime_state',
          'speed_scaling', 'robot_status_bits', 'output_bit_registers0_to_31']
RECIPE_TYPES = ['DOUBLE', 'VECTOR6D', 'INT32', 'VECTOR6INT32', 'UINT64', 'UINT32', 'DOUBLE', 'UINT32', 'UINT32']
# Variables newer than some versions, with their first CB3 / e-Series versions (UR's guide).
NEWER = {'elbow_position': ((3, 5), (5, 0)), 'safety_status': ((3, 10), (5, 4)), 'payload': ((3, 11), (5, 5, 1)),
         'output_int_register_24': ((3, 9), (5, 3)), 'output_bit_register_64': ((3, 9), (5, 3)),
         'payload_inertia': ((3, 15), (5, 11)), 'ft_raw_wrench': (None, (5, 9)),
         'time_scale_source': (None, (5, 17)), 'control_step': (None, (5, 26))}
NEWER_TYPES = {'elbow_position': 'VECTOR3D', 'safety_status': 'INT32', 'payload': 'DOUBLE',
               'output_int_register_24': 'INT32', 'output_bit_register_64': 'BOOL', 'payload_inertia': 'VECTOR6D',
               'ft_raw_wrench': 'VECTOR6D', 'time_scale_source': 'INT32', 'control_step': 'UINT64'}


def has(version, name):
    since = NEWER[name][0 if version[0] == 3 else 1]
    return since is not None and tuple(version) >= since


def handshake_v2(version_text, version, rate):
    with Sim('-c', version_text) as sim:
        p = Peer(sim.port)
        check(p.protocol_version(2) == 1, '%s: protocol 2 accepted' % version_text)
        got = p.controller_version()
        want = tuple(version) + (0,) * (4 - len(version))
        check(got == want, '%s: v gives all four numbers %s' % (version_text, want), got)
        rid, types = p.setup_outputs(RECIPE, rate)
        check(rid == 1 and types == RECIPE_TYPES, '%s: recipe id 1 and the types UR gives' % version_text, (rid, types))
        names = sorted(NEWER)
        rid2, types2 = p.setup_outputs(names, rate)
        want2 = [NEWER_TYPES[n] if has(version, n) else 'NOT_FOUND' for n in names]
        check(types2 == want2, '%s: NOT_FOUND exactly for the variables newer than it' % version_text,
              list(zip(names, types2)))
        check(rid2 == (1 if 'NOT_FOUND' not in want2 else 0), '%s: recipe id 0 when a name is NOT_FOUND' % version_text)
        if 'NOT_FOUND' in want2:
            check(p.start() == 0, '%s: start refused without a valid recipe' % version_text)
        p.setup_outputs(RECIPE, rate)
        check(p.start() == 1, '%s: start accepted' % version_text)
        pk = p.data(int(rate) // 2)
        steps = steps_of(pk, rate)
        check(regular(steps, 1), '%s: %d Hz, every cycle (by the timestamps)' % (version_text, rate), set(steps))
        ok = all(x[2] == 7 and x[3] == (253,) * 6 and x[5] == 2 and x[7] == 3 and x[8] == cycle(x[0], rate) % 2**32
                 for x in pk)
        check(ok, '%s: modes RUNNING, PLAYING, status bits power on + program running, bit registers count cycles'
              % version_text, pk[0])
        p.close()


def handshake_v1(version_text, rate):
    with Sim('-c', version_text) as sim:
        p = Peer(sim.port)
        check(p.protocol_version(1) == 1, '%s: protocol 1 accepted' % version_text)
        rid, types = p.setup_outputs(['timestamp', 'actual_q', 'robot_mode'])
        check(rid is None and types == ['DOUBLE', 'VECTOR6D', 'INT32'], '%s v1: types without a recipe id' % version_text,
              types)
        check(p.start() == 1, '%s v1: start accepted' % version_text)
        kind, payload = p.package()
        while kind != U:
            kind, payload = p.package()
        check(len(payload) == 8 + 48 + 4, '%s v1: data packages carry no recipe id (60 bytes)' % version_text,
              len(payload))
        pk = [p.decode(payload)] + p.data(50)
        steps = steps_of(pk, rate)
        check(regular(steps, 1), '%s v1: always the controller\'s %d Hz' % (version_text, rate), set(steps))
        p.close()


def old_protocol():
    with Sim('-c', '3.3') as sim:
        p = Peer(sim.port)
        check(p.protocol_version(2) == 0, '3.3: protocol 2 refused')
        check(p.protocol_version(1) == 1, '3.3: then protocol 1 accepted on the same connection')
        rid, types = p.setup_outputs(['timestamp', 'output_int_register_0', 'elbow_position'])
        check(types == ['DOUBLE', 'NOT_FOUND', 'NOT_FOUND'], '3.3: registers (3.4) and elbow (3.5) NOT_FOUND', types)
        p.close()


def inputs_and_misc():
    with Sim('-c', '5.4') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        rid, types = p.setup_inputs(['input_int_register_24', 'input_double_register_0', 'speed_slider_fraction'])
        check(rid == 2 and types == ['INT32', 'DOUBLE', 'DOUBLE'], 'inputs: recipe id 2 (1 is the output recipe\'s) '
              'and types', (rid, types))
        rid, types = p.setup_inputs(['input_int_register_48'])
        check(rid == 0 and types == ['NOT_FOUND'], 'inputs: register 48 NOT_FOUND, id 0', (rid, types))
        p.send(b'Z')
        kind, payload = p.package()
        check(kind == M and p.texts[-1][0] == 1 and 'unknown package type 90' in p.texts[-1][1],
              'an unknown package type: an error text message', p.texts[-1:])
        p.setup_outputs(['timestamp'], 500.0)
        p.start()
        p.data(5)
        check(p.pause() == 1, 'pause accepted')
        try:
            p.package(0.3)
            quiet = False
        except TimeoutError:
            quiet = True
        check(quiet, 'after the pause reply no data package')
        check(p.start() == 1, 'start again after a pause')
        check(len(p.data(5)) == 5, 'data again after the second start')
        long_names = ['actual_q'] * 230  # 2069 bytes of names
        rid, _ = p.setup_outputs(long_names, 500.0)
        check(rid == 0 and 'longer than 2048 bytes' in p.texts[-1][1], 'a name list past 2048 bytes refused, said why',
              p.texts[-1:])
        p.close()
        # A package below its own header ends the connection.
        q = Peer(sim.port)
        q.send_raw(b'\x00\x02V')
        try:
            q.package(5)
            ended = False
        except Closed:
            ended = True
        except ConnectionResetError:
            ended = True
        check(ended, 'a package of size 2 from the client: disconnected')
        check(wait_for('the log line', lambda: 'below its 3-byte header' in sim.log()), 'and the log says why')
        q.close()


def frequencies():
    cases = [('5.10', 500, 125.0, 4), ('5.10', 500, 200.0, 2), ('5.10', 500, 499.0, 1), ('3.10', 125, 25.0, 5),
             ('3.10', 125, 1.0, 125)]
    for version, rate, asked, divisor in cases:
        with Sim('-c', version) as sim:
            p = Peer(sim.port)
            p.protocol_version(2)
            p.setup_outputs(['timestamp', 'output_int_register_24'], asked)
            p.start()
            n = 3 if asked < 5 else 40
            pk = p.data(n, timeout=5)
            steps = steps_of(pk, rate)
            check(regular(steps, divisor) and all(cycle(x[0], rate) % divisor == 0 for x in pk),
                  '%s at %g Hz: every %d%s cycle by the timestamp (%g Hz)' %
                  (version, asked, divisor, {1: 'st', 2: 'nd'}.get(divisor, 'th'), rate / divisor), steps)
            check(all(x[1] == cycle(x[0], rate) + 24 for x in pk),
                  '%s at %g Hz: output_int_register_24 = cycle + 24' % (version, asked), pk[:2])
            p.close()
    for version, asked in (('5.10', 501.0), ('3.10', 126.0), ('5.10', 0.5)):
        with Sim('-c', version) as sim:
            p = Peer(sim.port)
            p.protocol_version(2)
            rid, types = p.setup_outputs(['timestamp'], asked)
            check(rid == 0 and types == ['DOUBLE'] and p.texts and p.texts[-1][0] == 1,
                  '%s: %g Hz refused (recipe id 0, an error text)' % (version, asked), (rid, types, p.texts))
            check(p.start() == 0, '%s: %g Hz: start refused' % (version, asked))
            p.close()


# ---- inputs: setup inputs (I) and the client's data packages (U) ----------------------------
# The types a controller gives each input (UR's input list), and the other
# inputs than the registers, which urrt never asks for.
INPUT_TYPES = {'input_int_register_0': 'INT32', 'input_int_register_23': 'INT32', 'input_int_register_24': 'INT32',
               'input_int_register_47': 'INT32', 'input_double_register_0': 'DOUBLE',
               'input_double_register_24': 'DOUBLE', 'input_double_register_47': 'DOUBLE',
               'input_bit_register_64': 'BOOL', 'input_bit_register_127': 'BOOL',
               'input_bit_registers0_to_31': 'UINT32', 'input_bit_registers32_to_63': 'UINT32',
               'speed_slider_mask': 'UINT32', 'speed_slider_fraction': 'DOUBLE',
               'standard_digital_output_mask': 'UINT8', 'standard_digital_output': 'UINT8',
               'configurable_digital_output_mask': 'UINT8', 'configurable_digital_output': 'UINT8',
               'tool_digital_output_mask': 'UINT8', 'tool_digital_output': 'UINT8',
               'standard_analog_output_mask': 'UINT8', 'standard_analog_output_type': 'UINT8',
               'standard_analog_output_0': 'DOUBLE', 'standard_analog_output_1': 'DOUBLE',
               'external_force_torque': 'VECTOR6D'}
# Registers 24..47 and bits 64..127 came with 3.9 / 5.3 (as outputs in UR's
# table, and lib/urrt_rtde.h's); 0..23 and the bit words with 3.4.
UPPER = ['input_int_register_24', 'input_int_register_47', 'input_double_register_24', 'input_double_register_47',
         'input_bit_register_64', 'input_bit_register_127']
LOWER = ['input_int_register_0', 'input_int_register_23', 'input_double_register_0', 'input_bit_registers0_to_31',
         'input_bit_registers32_to_63']
FIELDBUS = ['input_int_register_0', 'input_int_register_23', 'input_double_register_0', 'input_double_register_23',
            'input_bit_registers0_to_31', 'input_bit_registers32_to_63']


def log_lines(sim, text):
    return [l for l in sim.log().splitlines() if text in l]


def inputs_types():
    with Sim('-c', '5.12') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        names = sorted(INPUT_TYPES)
        rid, types = p.setup_inputs(names)
        check(rid == 2 and types == [INPUT_TYPES[n] for n in names],
              'inputs 5.12: every input a controller has, its type, in order (recipe id 2)', list(zip(names, types)))
        orid, _ = p.setup_outputs(['timestamp'], 500.0)
        rid3, types3 = p.setup_inputs(['input_int_register_30', 'input_double_register_31'])
        rid4, _ = p.setup_inputs(['input_bit_register_100'])
        check(orid == 1 and (rid3, rid4) == (3, 4) and types3 == ['INT32', 'DOUBLE'],
              'inputs: several recipes per connection, each its own id (3, 4), none the output recipe\'s 1',
              (orid, rid3, rid4))
        bad = ['input_int_register_48', 'input_bit_register_63', 'input_bit_register_0', 'no_such_input',
               'output_int_register_24', 'timestamp', 'input_double_register_-1']
        rid, types = p.setup_inputs(['input_int_register_25'] + bad)
        check(rid == 0 and types == ['INT32'] + ['NOT_FOUND'] * len(bad),
              'inputs: NOT_FOUND for unknown names (register 48, single bits 0-63, outputs), the whole recipe id 0',
              (rid, types))
        rid, _ = p.setup_inputs(['input_int_register_25'])
        check(rid == 5, 'inputs: a refused recipe takes no id (the next valid one is 5)', rid)
        p.close()


def inputs_versions():
    for version, proto, upper, lower in (('3.3', 1, False, False), ('3.4', 2, False, True), ('3.8', 2, False, True),
                                         ('3.9', 2, True, True), ('5.2', 2, False, True), ('5.3', 2, True, True)):
        with Sim('-c', version) as sim:
            p = Peer(sim.port)
            if proto == 2:
                p.protocol_version(2)
            names = UPPER + LOWER
            rid, types = p.setup_inputs(names)
            want = [INPUT_TYPES[n] if (upper if n in UPPER else lower) else 'NOT_FOUND' for n in names]
            check(types == want and (rid == 0) == ('NOT_FOUND' in want),
                  '%s: registers 24-47 and bits 64-127 %s, 0-23 and the bit words %s (recipe id %d)' %
                  (version, 'there' if upper else 'NOT_FOUND', 'there' if lower else 'NOT_FOUND', rid),
                  list(zip(names, types)))
            p.close()


def inputs_in_use():
    with Sim('-c', '5.12', '--fieldbus') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        for name in FIELDBUS:
            rid, types = p.setup_inputs([name])
            check(rid == 0 and types == ['IN_USE'], '--fieldbus: %s IN_USE, id 0' % name, (rid, types))
        rid, types = p.setup_inputs(['input_int_register_24', 'input_int_register_0', 'input_bit_register_64'])
        check(rid == 0 and types == ['INT32', 'IN_USE', 'BOOL'], '--fieldbus: one IN_USE makes the recipe invalid',
              (rid, types))
        rid, types = p.setup_inputs(['input_int_register_24', 'input_double_register_47', 'input_bit_register_64',
                                     'speed_slider_fraction'])
        check(rid == 2 and 'IN_USE' not in types, '--fieldbus: registers 24-47, bits 64-127 and the rest are free',
              (rid, types))
        p.close()
    with Sim('-c', '5.12') as sim:
        a = Peer(sim.port)
        a.protocol_version(2)
        rid, _ = a.setup_inputs(['input_int_register_0', 'input_bit_registers0_to_31'])
        check(rid == 2, 'without --fieldbus registers 0-23 and the bit words are free', rid)
        a.setup_inputs(['input_int_register_24', 'input_double_register_24'])
        rid, _ = a.setup_inputs(['input_int_register_24'])
        check(rid == 4, 'a client may name its own input variable again in another recipe', rid)
        a.setup_outputs(['timestamp'], 500.0)
        a.start()
        a.send_inputs(3, [4242, 0.25])
        b = Peer(sim.port)
        b.protocol_version(2)
        rid, types = b.setup_inputs(['input_int_register_25', 'input_int_register_24'])
        check(rid == 0 and types == ['INT32', 'IN_USE'], 'a second client: a variable the first holds is IN_USE',
              (rid, types))
        rid, types = b.setup_inputs(['input_bit_registers0_to_31'])
        check(rid == 0 and types == ['IN_USE'], 'a second client: the first\'s bit word IN_USE too', (rid, types))
        rid, _ = b.setup_inputs(['input_int_register_25'])
        check(rid == 2, 'a second client: a free register is its own (id 2 on its connection)', rid)
        check(wait_for('the first client\'s input data applied', lambda: log_lines(sim, 'applied at cycle')),
              'the first client\'s input data applied')
        a.close()
        check(wait_for('the first client\'s release',
                       lambda: log_lines(sim, 'left: its 4 input variables are free again')),
              'the first client leaves: its 4 input variables free again, said at -v', sim.log()[-500:])
        rid, types = b.setup_inputs(['input_int_register_24', 'input_bit_registers0_to_31'])
        check(rid == 3 and types == ['INT32', 'UINT32'], 'then the second client gets them', (rid, types))
        b.setup_outputs(['timestamp', 'input_int_register_24', 'input_double_register_24'], 500.0)
        b.start()
        x = b.data(1)[0]
        check(x[1:] == [4242, 0.25], 'their values stay when their client leaves (no source says they reset)', x)
        b.close()


NAN = struct.unpack('>d', bytes.fromhex('7ff8000000000123'))[0]
ROUNDS = [  # input_int_register_24, input_double_register_24, input_bit_register_64, input_bit_registers32_to_63
    (-2 ** 31, -0.0, 1, 0xffffffff),
    (2 ** 31 - 1, 5e-324, 0, 0x80000001),
    (-1, float('inf'), 1, 0),
    (0, NAN, 0, 1),
    (123456, 1.7976931348623157e308, 1, 0x12345678),
]
BACK = ['timestamp', 'input_int_register_24', 'input_double_register_24', 'input_bit_register_64',
        'input_bit_registers32_to_63']


def exact(a, b):
    if isinstance(a, float) or isinstance(b, float):
        return struct.pack('>d', a) == struct.pack('>d', b)
    return a == b


def inputs_next_cycle():
    """A client writes registers after the package of cycle c; the
    simulator says at which cycle k it applied them; the values are in the
    packages of cycle k on, of both clients, and in none before."""
    with Sim('-c', '5.12') as sim:
        w = Peer(sim.port)
        w.protocol_version(2)
        rid, types = w.setup_inputs(BACK[1:])
        w.setup_outputs(BACK, 500.0)
        w.start()
        r = Peer(sim.port)  # another client, reading back only
        r.protocol_version(2)
        r.setup_outputs(BACK, 500.0)
        r.start()
        check(rid == 2 and types == ['INT32', 'DOUBLE', 'BOOL', 'UINT32'], 'inputs: the writer\'s recipe', types)
        old = (0, 0.0, 0, 0)
        prev = {}
        for n, vals in enumerate(ROUNDS):
            prev['reader'] = r.data(1)[0]
            prev['writer'] = w.data(1)[0]
            c = cycle(prev['writer'][0], 500)
            w.send_inputs(rid, list(vals))
            ok = wait_for('the log line of input data %d' % (n + 1),
                          lambda: len(log_lines(sim, 'input data of recipe 2 (4 variables) applied at cycle')) > n)
            if not check(ok, 'round %d: the simulator applies the input data at a cycle (log at -v)' % (n + 1)):
                return
            k = int(log_lines(sim, 'applied at cycle')[n].rsplit(' ', 1)[1])
            for who, p in (('writer', w), ('reader', r)):
                seen = [prev[who]]
                while cycle(seen[-1][0], 500) < k:
                    seen += p.data(1)
                first = seen[-1]
                before = seen[:-1]
                check(k > c and cycle(first[0], 500) == k and all(exact(a, b) for a, b in zip(first[1:], vals)),
                      'round %d, %s: the package of cycle %d (the next after the write, at %d) holds the values, '
                      'bit for bit' % (n + 1, who, k, c), (c, k, first, vals))
                check(before and cycle(before[-1][0], 500) == k - 1 and
                      all(all(exact(a, b) for a, b in zip(x[1:], old)) for x in before),
                      'round %d, %s: the packages before it (cycle %d the last) still hold the old ones' %
                      (n + 1, who, k - 1), (before[-1:], old))
            old = vals
        w.close()
        r.close()


def inputs_several_and_v1():
    with Sim('-c', '5.12') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        a, _ = p.setup_inputs(['input_int_register_30', 'input_int_register_31'])
        b, _ = p.setup_inputs(['input_double_register_30', 'input_bit_register_70'])
        c, _ = p.setup_inputs(['speed_slider_fraction', 'speed_slider_mask', 'external_force_torque',
                               'standard_digital_output'])
        p.setup_outputs(['timestamp', 'input_int_register_30', 'input_int_register_31', 'input_double_register_30',
                         'input_bit_register_70'], 500.0)
        p.start()
        p.send_inputs(b, [2.5, 1])
        p.send_inputs(c, [0.5, 1, (1.0, 2.0, 3.0, 4.0, 5.0, 6.0), 255])
        check(wait_for('2 input data applied', lambda: len(log_lines(sim, 'applied at cycle')) == 2),
              'several recipes: data of recipes %d and %d applied' % (b, c))
        k = int(log_lines(sim, 'applied at cycle')[-1].rsplit(' ', 1)[1])
        x = p.data(1)[0]
        while cycle(x[0], 500) < k:
            x = p.data(1)[0]
        check(x[1:] == [0, 0, 2.5, 1], 'several recipes: a package of recipe %d sets its variables, no other' % b, x)
        p.send_inputs(a, [7, -7])
        check(wait_for('the third applied', lambda: len(log_lines(sim, 'applied at cycle')) == 3), 'recipe %d too' % a)
        k = int(log_lines(sim, 'applied at cycle')[-1].rsplit(' ', 1)[1])
        while cycle(x[0], 500) < k:
            x = p.data(1)[0]
        check(x[1:] == [7, -7, 2.5, 1], 'several recipes: then recipe %d\'s, the others\' values kept' % a, x)
        p.close()
    with Sim('-c', '3.10') as sim:
        p = Peer(sim.port)
        check(p.protocol_version(1) == 1, 'protocol 1')
        rid, types = p.setup_inputs(['input_int_register_24'])
        rid2, types2 = p.setup_inputs(['input_int_register_25', 'input_double_register_2'])
        check((rid, rid2) == (2, 3) and types == ['INT32'] and types2 == ['INT32', 'DOUBLE'],
              'I in protocol 1: the reply carries the recipe id too (no v1 layout without it is described)',
              (rid, rid2, types2))
        p.setup_outputs(['timestamp', 'input_int_register_24', 'input_int_register_25', 'input_double_register_2'])
        p.start()
        p.send_inputs(rid2, [-99, 0.125])  # protocol 1: no recipe id, the connection's last input recipe
        check(wait_for('the v1 input data applied', lambda: log_lines(sim, 'input data of recipe 3 (2 variables)')),
              'U in protocol 1 (values only): applied to the connection\'s last input recipe (3)', sim.log()[-300:])
        k = int(log_lines(sim, 'applied at cycle')[-1].rsplit(' ', 1)[1])
        x = p.data(1)[0]
        while cycle(x[0], 125) < k:
            x = p.data(1)[0]
        check(x[1:] == [0, -99, 0.125], 'protocol 1: the values read back', x)
        p.close()


def inputs_ignored():
    """Input data the controller cannot take: of a recipe id the connection
    does not have, of the wrong size, before start. Each is ignored, told
    the client in an error text, logged and counted."""
    with Sim('-c', '5.12') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        rid, _ = p.setup_inputs(['input_int_register_24'])
        p.setup_outputs(['timestamp', 'input_int_register_24'], 500.0)

        def refused(payload, text, what):
            p.texts = []
            p.send(U, payload)
            while not p.texts:
                p.package()
            level, msg, _ = p.texts[-1]
            check(level == 1 and text in msg and msg.endswith(': ignored'), '%s: an error text, "%s"' % (what, msg),
                  p.texts)
        refused(p.input_package(rid, [5]), 'while not started', 'U before start')
        p.start()
        refused(p.input_package(9, [6], ['INT32']), 'of recipe id 9, no input recipe of this connection',
                'U of an unknown recipe id')
        refused(p.input_package(1, [6], ['INT32']), 'of recipe id 1', 'U of the output recipe\'s id')
        refused(p.input_package(rid, [7, 0], ['INT32', 'UINT8']), 'of 5 bytes of values for input recipe 2, which '
                'has 4', 'U one byte too long')
        refused(p.input_package(rid, [0], ['UINT8']), 'of 1 byte of', 'U too short')
        refused(b'', 'without a recipe id', 'U without a recipe id')
        x = p.data(3)
        check(all(v[1] == 0 for v in x), 'none of them applied', x)
        p.send_inputs(rid, [8])
        check(wait_for('the good one applied', lambda: log_lines(sim, 'applied at cycle')), 'a good one then is')
        p.close()
        check(wait_for('the count at the end', lambda: log_lines(sim, '1 input data package taken, 6 ignored')),
              'counted: "1 input data package taken, 6 ignored" when the client leaves', sim.log()[-600:])
        check(len(log_lines(sim, ': ignored (')) == 6, 'each logged at -v with its count')


def inputs_hold():
    """--fault rtde-hold-inputs: a client's variables stay IN_USE for 2 s
    (the default) after it left, as a controller that still holds the
    old connection; a client retrying gets them after that."""
    with Sim('-c', '5.12', '--fault', 'rtde-hold-inputs') as sim:
        a = Peer(sim.port)
        a.protocol_version(2)
        a.setup_inputs(['input_int_register_24', 'input_bit_register_64'])
        a.close()
        left = time.monotonic()
        b = Peer(sim.port)
        b.protocol_version(2)
        check(wait_for('the hold', lambda: log_lines(sim, 'stay IN_USE for 2000 ms (fault rtde-hold-inputs)')),
              'rtde-hold-inputs: the client leaves, its 2 variables held 2000 ms (log)', sim.log()[-400:])
        rid, types = b.setup_inputs(['input_int_register_24'])
        early = time.monotonic() - left
        check(rid == 0 and types == ['IN_USE'] and early < 2.0,
              'rtde-hold-inputs: the same register asked for again %.3f s later: IN_USE' % early, (rid, types))
        rid, types = b.setup_inputs(['input_int_register_25'])
        check(rid == 2, 'rtde-hold-inputs: other registers are free', (rid, types))
        b.setup_outputs(['timestamp'], 10.0)
        b.start()  # cycles run: the hold ends on time
        ok = wait_for('the end of the hold', lambda: log_lines(sim, 'held after it left are free again'), timeout=10)
        rid, types = b.setup_inputs(['input_int_register_24', 'input_bit_register_64'])
        late = time.monotonic() - left
        check(ok and rid == 3 and types == ['INT32', 'BOOL'] and late >= 2.0,
              'rtde-hold-inputs: free again after the hold (asked %.3f s after the client left)' % late, (rid, types))
        b.close()


# ---- the same arm on both ports ------------------------------------------------------------
PAIRS = [('actual_q', 'q_actual', 6), ('target_q', 'q_target', 6), ('target_qd', 'qd_target', 6),
         ('actual_qd', 'qd_actual', 6), ('actual_current', 'i_actual', 6), ('actual_TCP_pose', 'tool_vector_actual', 6),
         ('actual_TCP_speed', 'tcp_speed_actual', 6), ('actual_TCP_force', 'tcp_force', 6),
         ('target_TCP_pose', 'tool_vector_target', 6), ('joint_temperatures', 'motor_temperatures', 6),
         ('actual_tool_accelerometer', 'tool_accelerometer', 3), ('speed_scaling', 'speed_scaling', 1),
         ('elbow_position', 'elbow_position', 3), ('actual_digital_input_bits', 'digital_input_bits', 1),
         ('actual_digital_output_bits', 'digital_outputs', 1), ('robot_mode', 'robot_mode', 1),
         ('joint_mode', 'joint_modes', 6), ('safety_mode', 'safety_mode', 1), ('safety_status', 'safety_status', 1),
         ('runtime_state', 'program_state', 1)]
EXTRA_COLS = {'safety_mode': 102}


def rt_packets(sock, until, deadline):
    """RealTime packets (size, then doubles) up to the one timed until."""
    data, out = b'', []
    while (not out or out[-1][0] < until) and time.monotonic() < deadline:
        chunk = sock.recv(65536)
        if not chunk:
            break
        data += chunk
        while len(data) >= 4:
            size = struct.unpack_from('>i', data)[0]
            if len(data) < size:
                break
            out.append(struct.unpack('>%dd' % ((size - 4) // 8), data[4:size]))
            data = data[size:]
    return out


def rt_value(vals, name, n):
    col = rt.COL3.get(name) or EXTRA_COLS[name]
    got = vals[col - 1:col - 1 + n]
    return got if n > 1 else got[0]


def same_arm(version, rate, clock):
    """RealTime first (its packets queue while RTDE is read), then RTDE; then
    RealTime is read up to the last RTDE timestamp: they overlap wholly."""
    with Sim('-c', version, '--clock', clock) as sim:
        s = socket.create_connection(('127.0.0.1', sim.rt_port), timeout=5)
        p = Peer(sim.port)
        p.protocol_version(2)
        p.setup_outputs(['timestamp'] + [a for a, _, _ in PAIRS], float(rate))
        p.start()
        rtde = p.data(rate // 5)
        p.close()
        rtp = rt_packets(s, rtde[-1][0], time.monotonic() + 10)
        s.close()
    by_time = {x[0]: x for x in rtde}
    common = [r for r in rtp if r[0] in by_time]
    check(len(common) >= len(rtde) * 0.9, '%s --clock %s: RealTime and RTDE overlap in controller time (%d of %d)'
          % (version, clock, len(common), len(rtde)), (len(rtp), len(rtde)))
    bad = []
    for r in common:
        x = by_time[r[0]]
        for i, (a, b, n) in enumerate(PAIRS):
            want = rt_value(r, b, n)
            got = x[i + 1]
            if isinstance(got, tuple):
                same = len(got) == len(want) and all(struct.pack('>d', float(g)) == struct.pack('>d', w)
                                                     for g, w in zip(got, want))
            else:
                same = struct.pack('>d', float(got)) == struct.pack('>d', want)
            if not same:
                bad.append((r[0], a, got, want))
    check(common and not bad, '%s --clock %s: every value the same on both ports at the same timestamp, bit for bit'
          % (version, clock), bad[:3])


def rtde_only_model():
    with Sim('-c', '5.26') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        names = ['timestamp', 'control_step', 'output_int_register_47', 'output_double_register_30',
                 'output_bit_registers0_to_31', 'output_bit_registers32_to_63', 'output_bit_register_65',
                 'output_bit_register_100', 'robot_status_bits', 'safety_status_bits', 'target_speed_fraction',
                 'tcp_offset', 'payload', 'payload_cog', 'time_scale_source', 'tool_output_voltage',
                 'input_int_register_30', 'actual_configurable_digital_input_bits']
        p.setup_outputs(names, 500.0)
        p.start()
        pk = p.data(300)
        p.close()
    bad = []
    for x in pk:
        k = cycle(x[0], 500)
        want = [x[0], k, k + 47, 30 + k / 1000.0, k % 2**32, ~k % 2**32, (k >> 1) & 1, (k >> 4) & 1, 3, 1, 1.0,
                (0.0,) * 6, 1.0, (0.0, 0.0, 0.05), 1, 24, 0, 0]
        for name, g, w in zip(names, x, want):
            if w is not None and g != w:
                bad.append((k, name, g, w))
    # The model's inputs use bits 0-4 and 16: no configurable one (8-15) is on.
    check(not bad, '5.26: the RTDE-only values follow docs/tools.md (registers count cycles, status bits, ...)', bad[:3])


# ---- faults --------------------------------------------------------------------------------
def session(sim, names=('timestamp', 'actual_q'), rate=500.0, protocol=2, rcvbuf=None):
    p = Peer(sim.port, rcvbuf=rcvbuf)
    if protocol == 2:
        p.protocol_version(2)
        p.setup_outputs(list(names), rate)
    else:
        p.setup_outputs(list(names))
    p.start()
    return p


def read_until_end(p, limit=100000):
    """Data packages until the connection ends: (packages, how it ended)."""
    pk = []
    try:
        while len(pk) < limit:
            kind, payload = p.package()
            if kind == U:
                pk.append(p.decode(payload))
    except Closed:
        return pk, 'closed'
    except ConnectionResetError:
        return pk, 'reset'
    except TimeoutError:
        return pk, 'timeout'
    return pk, 'limit'


def faults_refuse_and_text():
    with Sim('-c', '5.10', '--fault', 'rtde-refuse-v2') as sim:
        p = Peer(sim.port)
        check(p.protocol_version(2) == 0, 'rtde-refuse-v2: V(2) answered 0')
        check(p.protocol_version(1) == 1, 'rtde-refuse-v2: V(1) accepted on the same connection')
        p.setup_outputs(['timestamp'])
        p.start()
        check(len(p.data(20)) == 20, 'rtde-refuse-v2: data in protocol 1')
        p.close()
    with Sim('-c', '5.10', '--fault', 'rtde-text-handshake') as sim:
        p = Peer(sim.port)
        p.protocol_version(2)
        p.controller_version()
        p.setup_outputs(['timestamp'], 500.0)
        p.start()
        layouts = [t[2] for t in p.texts]
        check(len(p.texts) == 4 and layouts[0] is None and all(s == 'urrt-sim' for s in layouts[1:]),
              'rtde-text-handshake: a text before each of 4 replies, before V in the v1 layout, then v2', p.texts)
        check(all(k == M for k, _ in p.foreign), 'rtde-text-handshake: the client skipped them to find its replies')
        p.close()
    with Sim('-c', '5.10', '--fault', 'rtde-text-every=10,level=1') as sim:
        p = session(sim)
        pk = p.data(45)
        steps = steps_of(pk, 500)
        check([t[0] for t in p.texts] == [1, 1, 1, 1] and regular(steps, 1),
              'rtde-text-every=10,level=1: 4 error texts among 45 data packages, none missing', (p.texts, steps))
        p.close()
    with Sim('-c', '3.10', '--fault', 'rtde-text-every=5') as sim:
        p = session(sim, rate=125.0, protocol=1)
        p.data(11)
        check(len(p.texts) == 2 and p.texts[0][0] == 2 and p.texts[0][2] is None and 'text message 1' in p.texts[0][1],
              'rtde-text-every in protocol 1: level then message, warning by default', p.texts)
        p.close()


def faults_bad_package():
    for kind in ('size', 'type', 'recipe'):
        with Sim('-c', '5.10', '--fault', 'rtde-bad-package=5,kind=' + kind) as sim:
            p = session(sim)
            good, bad = [], []
            while len(good) + len(bad) < 15:
                k, payload = p.package()
                if k == M:
                    continue
                try:
                    if k != U:
                        raise ValueError('type %r' % k)
                    good.append(p.decode(payload))
                except ValueError as e:
                    bad.append(str(e))
            steps = [cycle(b[0], 500) - cycle(a[0], 500) for a, b in zip(good, good[1:])]
            check(len(bad) == 3 and sorted(set(steps)) == [1, 2],
                  'rtde-bad-package=5,kind=%s: every 5th package bad, framing intact' % kind, (bad, steps))
            p.close()
    with Sim('-c', '5.10', '--fault', 'rtde-bad-package=5,kind=header') as sim:
        p = session(sim)
        try:
            p.data(10)
            got = 'no error'
        except Unframable as e:
            got = str(e)
        check(got == 'size field 2', 'rtde-bad-package kind=header: an unframable size field after 4 packages', got)
        p.close()


def faults_connection():
    with Sim('-c', '5.10', '--fault', 'close-after=30') as sim:
        pk, how = read_until_end(session(sim))
        check(len(pk) == 30 and how == 'closed', 'close-after=30: 30 data packages, then an orderly close', (len(pk), how))
    with Sim('-c', '5.10', '--fault', 'reset-after=30') as sim:
        pk, how = read_until_end(session(sim))
        check(len(pk) == 30 and how == 'reset', 'reset-after=30: 30 data packages, then a reset', (len(pk), how))
    with Sim('-c', '5.10', '--fault', 'truncate-after=10') as sim:
        p = session(sim)
        pk, how = read_until_end(p)
        check(len(pk) == 10 and how == 'closed' and len(p.buf) == (3 + 1 + 56) // 2,
              'truncate-after=10: 10 packages, half of the next, a close', (len(pk), how, len(p.buf)))
    with Sim('-c', '5.10', '-n', '25') as sim:
        pk, how = read_until_end(session(sim))
        check(len(pk) == 25 and how == 'closed', '--count 25: 25 data packages', (len(pk), how))
    with Sim('-c', '5.10', '--fault', 'stall-after=20,for=300') as sim:
        p = session(sim)
        pk = p.data(60)
        steps = [cycle(b[0], 500) - cycle(a[0], 500) for a, b in zip(pk, pk[1:])]
        gaps = [s for s in steps if s != 1]
        check(len(gaps) == 1 and 140 <= gaps[0] <= 400 and steps.index(gaps[0]) == 19,
              'stall-after=20,for=300: 20 packages, a gap of about 150 cycles in controller time, then one per cycle '
              '(no burst)', gaps)
        p.close()
    with Sim('-c', '5.10', '--start-on-connect', '--fault', 'freeze-after=250,for=300') as sim:
        p = session(sim)
        pk = p.data(400)
        steps = [cycle(b[0], 500) - cycle(a[0], 500) for a, b in zip(pk, pk[1:])]
        gaps = [s for s in steps if s != 1]
        # From cycle 250 on (later only if the schedule skipped cycles), 300 ms of them.
        check(len(gaps) == 1 and 140 <= gaps[0] <= 170 and cycle(pk[0][0], 500) + steps.index(gaps[0]) >= 249,
              'freeze-after=250,for=300: the controller\'s cycles 250 to ~400 skipped for RTDE too', gaps)
        p.close()
    with Sim('-c', '5.10', '--fault', 'tiny-writes=5') as sim:
        p = session(sim, names=['timestamp'], rate=50.0)
        pk = p.data(40)
        steps = steps_of(pk, 500)
        check(regular(steps, 10), 'tiny-writes=5: packages in 5-byte writes arrive whole, at the rate', set(steps))
        p.close()
    with Sim('-c', '5.10', '--fault', 'coalesce=8') as sim:
        p = session(sim)
        pk = p.data(64)
        steps = steps_of(pk, 500)
        check(regular(steps, 1), 'coalesce=8: every package, 8 to a write', set(steps))
        p.close()


def slow_reader(extra, bound, what):
    """A reader that stops reading is disconnected once the backlog the
    simulator holds for it passes the bound; one that reads is not."""
    names = ['timestamp', 'target_q', 'actual_q', 'actual_qd', 'actual_current', 'actual_TCP_pose']
    with Sim('-c', '5.10', *extra) as sim:
        slow = session(sim, names=names, rcvbuf=4096)
        fast = session(sim, names=['timestamp'])
        before = len(fast.data(10))
        ok = wait_for('the slow reader\'s disconnection', lambda: 'fell behind' in sim.log(), sim.proc, timeout=20)
        check(ok, '%s: a reader that does not read is disconnected' % what, sim.log()[-400:])
        pk, how = read_until_end(slow, limit=10**6)
        size = 3 + slow.size_of()
        check(how == 'closed', '%s: with an orderly close (EOF after what was sent)' % what, how)
        # The log: "... fell behind (...) after N packets (B bytes)": N packages
        # queued, B bytes written; the reader got those bytes, and what the
        # simulator dropped is the backlog: just past the bound.
        line = [l for l in sim.log().splitlines() if 'fell behind' in l][0]
        queued, written = [int(w.strip('(')) for w in line.split(' after ')[1].split()[0:3:2]]
        backlog = (queued - len(pk)) * size
        check(written == slow.received and bound < backlog <= bound + size,
              '%s: the reader got all that was written (%d bytes), the backlog dropped was just past %d bytes (%d)'
              % (what, written, bound, backlog), (written, slow.received, line))
        more = fast.data(50)
        steps = steps_of(more, 500)
        check(before == 10 and regular(steps, 1), '%s: the reader that reads is not disturbed' % what, set(steps))
        slow.close()
        fast.close()
        sim.stop()
        check('RTDE readers disconnected as behind 1' in sim.log(), '%s: the summary counts it' % what,
              sim.log()[-300:])


# ---- --replay of an RTDE capture ------------------------------------------------------------
# The captures are urrt-dump --rtde -w recordings of the simulator's model,
# and, for what urrt-dump never writes (a recipe without timestamp, a later
# session with another recipe), sessions that rtde_peer's CaptureWriter
# records. What the replay must serve is read from the files by the
# independent reader tests/ref/rtde_capture.py: each recorded package's
# values, sliced by the recorded types.
DUMP = os.path.join(BUILD, 'bin', 'urrt-dump')


class Capture:
    """A capture as the replay serves it: its first session's recipe, then
    the data packages of the sessions with that recipe, up to the first
    with another (values past the recipe id), and the text messages
    between them: [(packages before it, (level, message))]."""

    def __init__(self, path):
        self.path = path
        self.sessions = ref_capture.sessions(ref_capture.read_file(path))
        first = self.sessions[0]
        self.names, self.types = first.names, first.types
        self.packages, self.texts = [], []
        for sess in self.sessions:
            if (sess.names, sess.types) != (self.names, self.types):
                break
            texts = iter(sess.texts)
            for kind, payload in sess.replies:
                if kind == 'U':
                    self.packages.append(payload[1:] if sess.protocol >= 2 else payload)
                elif kind == 'M':
                    self.texts.append((len(self.packages), next(texts)[:2]))

    def slices(self, i):
        """{name: the bytes of its value} of package i."""
        out, off = {}, 0
        for name, t in zip(self.names, self.types):
            fmt, n = TYPES[t]
            size = struct.calcsize('>' + fmt) * n
            out[name] = self.packages[i][off:off + size]
            off += size
        return out

    def timestamp(self, i):
        return struct.unpack('>d', self.slices(i)['timestamp'])[0]


def dump_capture(name, version, count, faults=(), keys=()):
    """urrt-dump --rtde -w TMP/name of count packages from the model of version."""
    path = os.path.join(TMP, name)
    with Sim('-c', version, *faults) as sim:
        args = [DUMP, '--rtde', '127.0.0.1:%d' % sim.port, '-w', path, '-n', str(count)]
        if keys:
            args += ['-k', ','.join(('timestamp',) + tuple(keys))]
        r = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=30)
    if r.returncode != 0:
        raise RuntimeError('urrt-dump -w failed: ' + r.stderr[-300:])
    return Capture(path)


def record(path, version, count, names, rate=500.0, append=False):
    """A session of count data packages with the model of version, recorded
    by rtde_peer into path (appended: one more session)."""
    w = CaptureWriter(path, append=append)
    with Sim('-c', version) as sim:
        p = Peer(sim.port, capture=w)
        p.protocol_version(2)
        p.controller_version()
        p.setup_outputs(list(names), rate)
        if p.start() != 1:
            raise RuntimeError('the recorded session did not start: %s' % p.types)
        p.data(count)
        p.close()
    w.close()


class Replay:
    """urrt-sim --replay CAPTURE on an RTDE port of the system's choosing."""
    count = 0

    def __init__(self, path, *args):
        Replay.count += 1
        base = os.path.join(TMP, 'replay%d' % Replay.count)
        self.log_path, self.rtde_pf = base + '.log', base + '.rtde'
        with open(self.log_path, 'w') as log:
            self.proc = subprocess.Popen(['timeout', '-k', '3', '60', SIM, '--replay', path, '--rtde', '127.0.0.1:0',
                                          '--rtde-port-file', self.rtde_pf, '-v'] + list(args), stdout=log, stderr=log)
        if not wait_for('the replay\'s port file', lambda: os.path.exists(self.rtde_pf), self.proc):
            raise RuntimeError('replay did not start: ' + self.log())
        self.port = int(open(self.rtde_pf).read())

    def log(self):
        return open(self.log_path).read()

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
        self.proc.wait(timeout=10)
        end_group(self.proc)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def client(port, names, rate=500.0, protocol=2):
    p = Peer(port)
    if protocol == 2:
        p.protocol_version(2)
        p.setup_outputs(list(names), rate)
    else:
        p.setup_outputs(list(names))
    if p.start() != 1:
        raise RuntimeError('start refused')
    return p


def replayed(p, limit=100000):
    """Data packages until the connection ends: (payloads past the recipe
    id, [(packages before it, text)], how it ended)."""
    pk, texts = [], []
    try:
        while len(pk) < limit:
            kind, payload = p.package()
            if kind == U:
                p.decode(payload)  # the size and recipe id the recipe makes
                pk.append(payload[1:] if p.protocol >= 2 else payload)
            elif kind == M:
                texts.append((len(pk), p.texts[-1]))
    except Closed:
        return pk, texts, 'closed'
    except TimeoutError:
        return pk, texts, 'timeout'
    return pk, texts, 'limit'


def matches(cap, names, pk):
    """The indices of the capture's packages that pk's are, by timestamp
    (names[0] is timestamp), and the packages whose bytes are not the
    capture's values for names, in order."""
    by_ts = {cap.timestamp(i): i for i in range(len(cap.packages))}
    idx, bad = [], []
    for got in pk:
        i = by_ts.get(struct.unpack_from('>d', got)[0])
        want = None if i is None else b''.join(cap.slices(i)[n] for n in names)
        if want != got:
            bad.append((i, got[:16], (want or b'')[:16]))
        idx.append(i)
    return idx, bad


def replay_usage():
    cap = dump_capture('usage.rtde', '5.10', 5)
    rt = os.path.join(TMP, 'rt.bin')
    with open(rt, 'wb') as f:
        f.write(struct.pack('>i', 1116) + b'\0' * 1112)
    cases = [
        (['--replay', cap.path, '-l', '127.0.0.1:0'], 'is an RTDE capture, served on the RTDE port alone (no RealTime '
                                                      'stream): drop --listen'),
        (['--replay', cap.path, '--port-file', 'x'], 'drop --port-file'),
        (['--replay', cap.path, '-w', 'x'], 'drop --record'),
        (['--replay', cap.path, '--fault', 'garbage-every=3'], 'drop fault garbage-every'),
        (['--replay', cap.path, '-c', '5.10'], 'drop --controller'),
        (['--replay', rt, '--rtde', '127.0.0.1:0'], 'a RealTime capture has no RTDE to serve): drop --rtde'),
        (['--replay', rt, '--fault', 'rtde-refuse-v2'], 'an rtde-* fault goes with --rtde HOST:PORT or --replay of an '
                                                        'RTDE capture'),
    ]
    for args, text in cases:
        r = subprocess.run([SIM] + args, capture_output=True, text=True, timeout=10)
        check(r.returncode == 2 and text in r.stderr, 'replay usage error: %s' % ' '.join(args), r.stderr.strip())


def replay_handshake_and_values():
    cap = dump_capture('full.rtde', '5.10.2.77', 300, faults=('--fault', 'rtde-text-every=100,level=3'),
                       keys=('output_int_register_24', 'output_bit_register_64'))
    check(len(cap.packages) == 300 and [t[0] for t in cap.texts] == [100, 200],
          'urrt-dump -w: 300 packages and 2 text messages among them', cap.texts)
    with Replay(cap.path) as sim:
        check('no RealTime stream' in sim.log() and '300 data packages at 500 Hz' in sim.log() and
              'a recipe of %d variables' % len(cap.names) in sim.log(),
              'replay: says what it serves, and that there is no RealTime stream', sim.log()[-500:])
        p = Peer(sim.port)
        check(p.protocol_version(1) == 1, 'replay: protocol 1 accepted, as a controller does')
        p.close()
        p = Peer(sim.port)
        check(p.protocol_version(2) == 1, 'replay: protocol 2 accepted, as recorded')
        check(p.controller_version() == (5, 10, 2, 77), 'replay: the recorded controller version')
        rid, types = p.setup_outputs(['actual_q', 'timestamp', 'tcp_offset', 'output_int_register_25', 'payload'],
                                     500.0)
        check(rid == 0 and types == ['VECTOR6D', 'DOUBLE', 'NOT_FOUND', 'NOT_FOUND', 'DOUBLE'],
              'replay: recorded names get their recorded types, unrecorded ones (that 5.10 has) NOT_FOUND',
              (rid, types))
        check(p.start() == 0, 'replay: start refused without a valid recipe')
        names = ['timestamp', 'output_int_register_24', 'joint_mode', 'output_bit_register_64', 'actual_q']
        rid, types = p.setup_outputs(names, 500.0)
        want = [cap.types[cap.names.index(n)] for n in names]
        check(rid == 1 and types == want, 'replay: a subset in another order: recipe id 1, the recorded types',
              (rid, types))
        check(p.start() == 1, 'replay: start accepted')
        pk, texts, how = replayed(p)
        p.close()
        idx, bad = matches(cap, names, pk)
        check(how == 'closed' and idx[:1] == [0] and regular([b - a for a, b in zip(idx, idx[1:])], 1),
              'replay: every package from the capture\'s first, in its order (by the timestamps), then the end '
              '(%d of 300)' % len(pk), (how, idx[:3], idx[-3:]))
        check(not bad, 'replay: each variable\'s bytes exactly the recorded ones', bad[:3])
        check([t[1][:2] for t in texts] == [t[1] for t in cap.texts] and
              [t[0] for t in texts] == [idx.index(t[0]) if t[0] in idx else None for t in cap.texts],
              'replay: the recorded text messages, before the package they preceded', (texts, cap.texts))
        check(wait_for('the end of the replay', lambda: sim.proc.poll() is not None, timeout=10) and
              sim.proc.returncode == 0 and 'end of capture' in sim.log(),
              'replay: at the end of the capture the program exits with 0', (sim.proc.returncode, sim.log()[-300:]))


def replay_clients_and_rates():
    cap = dump_capture('rates.rtde', '5.10', 400, keys=('actual_q', 'robot_mode', 'output_bit_registers0_to_31',
                                                       'output_int_register_24', 'runtime_state'))
    with Replay(cap.path) as sim:
        a_names = ['timestamp', 'actual_q']
        b_names = ['timestamp', 'robot_mode', 'output_bit_registers0_to_31']
        c_names = ['timestamp', 'output_int_register_24']
        d_names = ['timestamp', 'runtime_state']
        a = client(sim.port, a_names)
        b = client(sim.port, b_names, protocol=1)
        c = client(sim.port, c_names, rate=125.0)
        d = client(sim.port, d_names, rate=200.0)
        e = Peer(sim.port)
        e.protocol_version(2)
        rid, _ = e.setup_outputs(['timestamp'], 501.0)
        check(rid == 0 and e.texts and e.texts[-1][0] == 1, 'replay of 5.10: 501 Hz refused as its controller does',
              (rid, e.texts))
        e.close()
        got = {}
        for name, p, names, d_ in (('a', a, a_names, 1), ('b', b, b_names, 1), ('c', c, c_names, 4),
                                   ('d', d, d_names, 2)):
            pk, _, how = replayed(p)
            p.close()
            idx, bad = matches(cap, names, pk)
            steps = [y - x for x, y in zip(idx, idx[1:])]
            got[name] = len(pk)
            check(how == 'closed' and not bad and None not in idx and regular(steps, d_) and
                  all(i % d_ == 0 for i in idx),
                  'replay, several clients: %s (%s, protocol %d) every %d package%s, the recorded bytes' %
                  (name, ','.join(names), p.protocol, d_, '' if d_ == 1 else 's'), (how, bad[:2], steps[:5]))
        check(got['a'] >= 390, 'replay: the first client got the capture from its start', got)


def replay_loop():
    cap = dump_capture('loop.rtde', '3.10', 40)
    with Replay(cap.path, '--loop') as sim:
        p = client(sim.port, ['timestamp', 'actual_q'], rate=125.0)
        pk, _, _ = replayed(p, limit=100)
        p.close()
    idx, bad = matches(cap, ['timestamp', 'actual_q'], pk)
    check(not bad and (idx == [i % 40 for i in range(100)] or
                       regular([(y - x) % 40 for x, y in zip(idx, idx[1:])], 1)),
          '--loop: the capture again and again, its own timestamps each time (as a RealTime replay)', idx[35:45])


def replay_protocol1_capture():
    """A 3.3 controller: protocol 2 refused, 1 accepted; its packages carry
    no recipe id."""
    cap = dump_capture('v1.rtde', '3.3', 30)
    check(cap.sessions[0].protocol == 1, 'urrt-dump -w of a 3.3 controller: a protocol 1 session')
    with Replay(cap.path) as sim:
        p = Peer(sim.port)
        check(p.protocol_version(2) == 0, 'replay of a protocol 1 capture: protocol 2 refused, as recorded')
        check(p.protocol_version(1) == 1, 'then protocol 1 accepted')
        check(p.controller_version() == (3, 3, 0, 0), 'the recorded version 3.3')
        p.setup_outputs(['robot_mode', 'timestamp'])
        p.start()
        pk, _, how = replayed(p)
        p.close()
    idx, bad = matches(cap, ['timestamp'], [x[4:] for x in pk])
    check(how == 'closed' and not bad and idx[:1] == [0] and regular([y - x for x, y in zip(idx, idx[1:])], 1) and
          all(x[:4] == cap.slices(i)['robot_mode'] for x, i in zip(pk, idx)),
          'replay of a protocol 1 capture: protocol 1 packages, the recorded bytes', (how, bad[:2]))


def replay_sessions():
    """urrt-dump reconnects after the simulator closes every 20 packages:
    3 sessions of one recipe, served one after the other; a fourth with
    another recipe (appended) ends the replay before it."""
    cap = dump_capture('sessions.rtde', '5.10', 50, faults=('--fault', 'close-after=20'))
    record(cap.path, '5.10', 10, ['timestamp', 'actual_qd'], append=True)
    cap = Capture(cap.path)
    check(len(cap.sessions) == 4 and len(cap.packages) == 50, 'a capture of 4 sessions, 50 packages in the first 3',
          (len(cap.sessions), len(cap.packages)))
    with Replay(cap.path) as sim:
        check('50 data packages' in sim.log() and 'from 3 sessions' in sim.log() and
              'asks for another recipe: the replay ends before it' in sim.log(),
              'replay: the 3 sessions with its first recipe served, the log says why not the fourth',
              sim.log()[-600:])
        p = client(sim.port, ['timestamp', 'actual_q'])
        pk, _, how = replayed(p)
        p.close()
    want = [b''.join(cap.slices(i)[n] for n in ('timestamp', 'actual_q')) for i in range(50)]
    check(how == 'closed' and pk == want, 'replay: the 3 sessions\' packages one after the other',
          (len(pk), len(want)))


def replay_refusals():
    path = os.path.join(TMP, 'nots.rtde')
    record(path, '5.10', 5, ['actual_q', 'robot_mode'])
    r = subprocess.run([SIM, '--replay', path, '--rtde', '127.0.0.1:0'], capture_output=True, text=True, timeout=10)
    check(r.returncode == 1 and 'has no timestamp, the clock a replay is paced by' in r.stderr and
          'urrt-dump --rtde -w' in r.stderr, 'a capture without timestamp: refused at start (exit 1), says why',
          r.stderr.strip())
    good = dump_capture('damage.rtde', '5.10', 20)
    data = open(good.path, 'rb').read()
    records = ref_capture.read(data).records
    off = records[10].offset
    for what, damaged, text in (
            ('kind', data[:off] + b'?' + data[off + 1:], 'byte %d: record kind 0x3F' % off),
            ('size', data[:off + 1] + b'\x00\x02' + data[off + 3:], 'byte %d: a package of 2 bytes' % (off + 1))):
        bad_path = os.path.join(TMP, 'damaged-%s.rtde' % what)
        open(bad_path, 'wb').write(damaged)
        r = subprocess.run([SIM, '--replay', bad_path, '--rtde', '127.0.0.1:0'], capture_output=True, text=True,
                           timeout=10)
        check(r.returncode == 1 and text in r.stderr, 'a damaged capture (%s): refused, the message names the offset'
              % what, r.stderr.strip())
    cut = os.path.join(TMP, 'cut.rtde')
    open(cut, 'wb').write(data[:-7])
    with Replay(cut) as sim:
        check('last record is cut short' in sim.log() and '19 data packages' in sim.log(),
              'a capture cut short mid-record: served up to its last whole record, said so', sim.log()[-400:])
    # The RTDE faults apply to a replay too.
    with Replay(good.path, '--fault', 'rtde-refuse-v2', '--fault', 'close-after=5') as sim:
        p = Peer(sim.port)
        check(p.protocol_version(2) == 0, 'replay with rtde-refuse-v2: protocol 2 refused')
        p.setup_outputs(['timestamp'])
        p.start()
        pk, _, how = replayed(p)
        check(len(pk) == 5 and how == 'closed', 'replay with close-after=5: 5 packages, then closed', (len(pk), how))
        p.close()


def run(group, *args):
    """One group of checks; an exception (a reply that never came, a package
    that does not parse) fails the group instead of ending the suite."""
    try:
        group(*args)
    except Exception as e:  # noqa: BLE001  any of them is a failure to report
        check(False, '%s%s raised %s' % (group.__name__, args, type(e).__name__), e)


def main():
    run(usage_errors)
    run(handshake_v2, '3.4', (3, 4), 125)
    run(handshake_v2, '3.10', (3, 10), 125)
    run(handshake_v2, '5.12.3.1234', (5, 12, 3, 1234), 500)
    run(handshake_v2, '5.5.1', (5, 5, 1), 500)
    run(handshake_v1, '3.10', 125)
    run(handshake_v1, '5.10', 500)
    run(old_protocol)
    run(inputs_and_misc)
    run(inputs_types)
    run(inputs_versions)
    run(inputs_in_use)
    run(inputs_next_cycle)
    run(inputs_several_and_v1)
    run(inputs_ignored)
    run(inputs_hold)
    run(frequencies)
    run(same_arm, '5.10', 500, 'start')
    run(same_arm, '3.15', 125, 'monotonic')
    run(rtde_only_model)
    run(faults_refuse_and_text)
    run(faults_bad_package)
    run(faults_connection)
    run(slow_reader, [], 65536, 'default backlog')
    run(slow_reader, ['--fault', 'rtde-backlog=2048'], 2048, 'rtde-backlog=2048')
    run(replay_usage)
    run(replay_handshake_and_values)
    run(replay_clients_and_rates)
    run(replay_loop)
    run(replay_protocol1_capture)
    run(replay_sessions)
    run(replay_refusals)
    return suite.report()


if __name__ == '__main__':
    try:
        sys.exit(main())
    finally:
        subprocess.run(['rm', '-rf', TMP])
