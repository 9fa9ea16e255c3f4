#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-can-dbc: the CAN mapping against references that share no code with it.

- The DBC urrt-gateway writes is loaded with python3-canmatrix, and every
  frame, signal and attribute is compared with the configuration as this
  script reads it (its own reader of the grammar in docs/can.md).
- Payloads packed by lib/urrt_can (through tests/gateway/can/can_tool.c) are compared
  byte for byte with canmatrix encoding the raw values that this script's
  reference computes from the physical values (round half away from zero,
  saturation, NaN), for random layouts: both byte orders, odd start bits and
  lengths, signals across bytes, 1 to 64 bits, signed, unsigned, float32 and
  float64, classic and FD frames. Random payloads decode the same through
  urrt_can_unpack and canmatrix.
- [input NAME] frames (the PLC's, which the gateway receives) are in the DBC
  too, sent by [can] receiver, their signals received by [can] node
  (check_dbc_input.py has the rest of them: values through canmatrix and
  the gateway's own unpacking, both ways, and the C tables).
- docs/examples/*.ini validate and give DBCs that canmatrix loads, and the
  frames the scheduler emits for a scripted robot decode through the DBC to
  the robot's values within the scaling (canopen.ini, j1939.ini).

usage: test_dbc.py --tool build/tests/gateway/can/can_tool --work DIR
"""
import argparse
import contextlib
import io
import math
import os
import random
import re
import struct
import subprocess
import sys
from fractions import Fraction

with contextlib.redirect_stdout(io.StringIO()):  # canmatrix prints "ldf is not supported"
    import canmatrix
    import canmatrix.formats.dbc as canmatrix_dbc

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
FLT_MAX = struct.unpack('<f', b'\xff\xff\x7f\x7f')[0]
DBL_MAX = sys.float_info.max

passed = failed = 0


def check(cond, desc, detail=''):
    global passed, failed
    if cond:
        passed += 1
    else:
        failed += 1
        print('FAIL: %s%s' % (desc, (': ' + str(detail)) if detail != '' else ''))
    return cond


def run(tool, args, stdin=''):
    p = subprocess.run([tool] + args, input=stdin, capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


# ---- the field table (units and element counts), read from lib/urrt.h --------------

def read_fields():
    fields = {}
    text = open(os.path.join(ROOT, 'lib', 'urrt.h')).read()
    for m in re.finditer(r'X\((\w+), (\w+), (\d+), (\d+), (\d+), "([^"]*)", "[^"]*", "[^"]*"\)', text):
        fields[m.group(2)] = {'count': int(m.group(3)), 'unit': m.group(6), 'col_1x': int(m.group(4)),
                              'col_3x': int(m.group(5))}
    return fields


FIELDS = read_fields()


def read_rtde_names():
    """{RTDE name: field} from docs/protocol.md's "RTDE output" column: a
    signal may name a shared value by either name (docs/can.md)."""
    names = {}
    for line in open(os.path.join(ROOT, 'docs', 'protocol.md')):
        cells = [c.strip() for c in line.split('|')]
        if len(cells) > 8 and cells[1].startswith('`') and cells[7].startswith('`'):
            names[cells[7].split('`')[1]] = cells[1].strip('`')
    return names


RTDE_NAMES = read_rtde_names()

# Units of the RTDE-only values as UR's RTDE guide gives them ("bits": a bit mask,
# sent bit for bit), restated here so that the gateway's own table is checked.
RTDE_UNITS = {
    'robot_status_bits': 'bits', 'safety_status_bits': 'bits', 'tcp_offset': 'm, rad',
    'output_bit_registers0_to_31': 'bits', 'output_bit_registers32_to_63': 'bits',
    'input_bit_registers0_to_31': 'bits', 'input_bit_registers32_to_63': 'bits',
    'actual_current_window': 'A', 'actual_current_as_torque': 'Nm',
    'actual_TCP_acceleration': 'm/s^2, rad/s^2', 'target_TCP_acceleration': 'm/s^2, rad/s^2',
    'actual_configurable_digital_input_bits': 'bits', 'actual_configurable_digital_output_bits': 'bits',
    'target_execution_time': 's', 'analog_io_types': 'bits', 'io_current': 'mA',
    'actual_robot_energy_consumed': 'J', 'actual_robot_braking_energy_dissipated': 'J',
    'euromap67_input_bits': 'bits', 'euromap67_output_bits': 'bits', 'euromap67_24V_voltage': 'V',
    'euromap67_24V_current': 'mA', 'tool_analog_input_types': 'bits', 'tool_output_voltage': 'V',
    'tool_output_current': 'mA', 'tool_temperature': 'degC', 'tcp_force_scalar': 'N',
    'ft_raw_wrench': 'N, Nm', 'wrench_calc_from_currents': 'N, Nm', 'target_gravity': 'm/s^2',
    'target_base_acceleration': 'm/s^2, rad/s^2', 'target_base_wrench': 'N, Nm',
}
RTDE_COUNTS = {'VECTOR3D': 3, 'VECTOR6D': 6, 'VECTOR6INT32': 6, 'VECTOR6UINT32': 6}


def read_rtde_only():
    """{name: {'count', 'unit', 'type'}} of the RTDE-only values, by the names of
    lib/urrt_rtde.h's URRT_RTDE_ONLY rows (a family: name + index, first .. first +
    names - 1); units from RTDE_UNITS ('' where the guide gives none)."""
    out = {}
    text = open(os.path.join(ROOT, 'lib', 'urrt_rtde.h')).read()
    for m in re.finditer(r'X\((\w+), (\w+), "(\w+)", (\w+), (\d+), (\d+), (\d+),', text):
        name, wtype, first, names = m.group(3), m.group(4), int(m.group(5)), int(m.group(6))
        info = {'count': RTDE_COUNTS.get(wtype, 1), 'unit': RTDE_UNITS.get(name, ''), 'type': wtype,
                'col_1x': 0, 'col_3x': 0, 'rtde': True}
        for n in ([name] if names == 1 else ['%s%d' % (name, first + i) for i in range(names)]):
            out[n] = info
    return out


RTDE_ONLY = read_rtde_only()
assert 'output_int_register_24' in RTDE_ONLY and 'robot_status_bits' in RTDE_ONLY, 'lib/urrt_rtde.h rows not read'


def info_of(field):
    """A field's entry, or an RTDE-only value's."""
    return FIELDS[field] if field in FIELDS else RTDE_ONLY[field]

# ---- an independent reader of the configuration grammar (docs/can.md) ------------------


def read_ini(path):
    """(section, key, value) triples in file order; ';' or '#' start a comment
    line, ' ;' starts an inline comment, as the gateway reads them."""
    section = None
    out = []
    for raw in open(path):
        line = raw.strip()
        if not line or line[0] in ';#':
            continue
        if line.startswith('['):
            section = line[1:line.index(']')].strip()
            continue
        key, _, value = line.partition('=')
        value = re.split(r'\s;', value, maxsplit=1)[0]
        out.append((section, key.strip(), value.strip()))
    return out


def raw_range(sig):
    n = sig['length']
    if sig['type'] == 'unsigned':
        return 0, 2 ** n - 1
    if sig['type'] == 'signed':
        return -2 ** (n - 1), 2 ** (n - 1) - 1
    if sig['type'] == 'float32':
        return -FLT_MAX, FLT_MAX
    return -DBL_MAX, DBL_MAX


def default_limits(sig):
    lo, hi = raw_range(sig)
    a = float(lo) * sig['factor'] + sig['offset']
    b = float(hi) * sig['factor'] + sig['offset']
    if a > b:
        a, b = b, a
    return max(a, -DBL_MAX), min(b, DBL_MAX)


def field_unit(field, elem):
    unit = info_of(field)['unit']
    if unit in ('enum', 'bits'):
        return ''
    if ', ' in unit and info_of(field)['count'] == 6:
        return unit.split(', ')[0 if elem < 3 else 1]
    return unit


def parse_signal(value):
    words = re.findall(r'(?:[^\s"]|"[^"]*")+', value)
    m = re.match(r'(\w+)(?:\[(\d+)\])?$', words[0])
    field, elem = m.group(1), int(m.group(2) or 0)
    field = field if field in FIELDS else RTDE_NAMES.get(field, field)
    start, length = (int(x) for x in words[1][1:].split('|'))
    sig = {'field': field, 'elem': elem, 'start': start, 'length': length, 'factor': 1.0, 'offset': 0.0,
           'invalid': None, 'role': 'rtde' if field in RTDE_ONLY else 'field'}
    explicit = {}
    for w in words[2:]:
        if w in ('intel', 'motorola'):
            sig['order'] = w
        elif w in ('unsigned', 'signed', 'float32', 'float64'):
            sig['type'] = w
        else:
            k, v = w.split('=', 1)
            explicit[k] = v.strip('"')
    sig['factor'] = float(explicit.get('factor', 1))
    sig['offset'] = float(explicit.get('offset', 0))
    lo, hi = default_limits(sig)
    sig['min'] = float(explicit['min']) if 'min' in explicit else lo
    sig['max'] = float(explicit['max']) if 'max' in explicit else hi
    if 'invalid' in explicit:
        sig['invalid'] = int(explicit['invalid'], 0) & ((1 << length) - 1)
    # A field of unit "bits" is a bit mask: bits=FIRST-LAST (or one BIT) says
    # which of its bits the signal carries, from bit 0 by default.
    sig['mask'] = info_of(field)['unit'] == 'bits'
    sig['first'] = int(explicit.get('bits', '0').split('-')[0])
    if sig['mask']:  # a mask's range is its bits, whatever min/max the type has
        sig['min'], sig['max'] = 0.0, float(2 ** length - 1)
    if info_of(field)['count'] > 1:
        sig['name'] = explicit.get('name', '%s_%d' % (field, elem))
    else:
        sig['name'] = explicit.get('name', field)
    sig['unit'] = explicit.get('unit', field_unit(field, elem))
    return sig


def marker(role, value):
    words = value.split()
    sig = {'role': role, 'start': int(words[0]), 'length': 4 if role == 'alive' else 1, 'type': 'unsigned',
           'order': words[1] if len(words) > 1 else 'intel', 'factor': 1.0, 'offset': 0.0, 'min': 0.0,
           'max': 15.0 if role == 'alive' else 1.0, 'unit': '', 'invalid': None,
           'name': 'alive_counter' if role == 'alive' else 'valid'}
    return sig


def parse_config(path):
    can = {'fd': False, 'bitrate': 500000, 'data_bitrate': 0, 'hb_period': 100, 'hb_extended': False,
           'stale': 100, 'node': 'URRT_GATEWAY', 'receiver': 'Vector__XXX', 'generation': 3}
    frames = {}
    order = []
    for section, key, value in read_ini(path):
        if section == 'can':
            if key == 'fd':
                can['fd'] = value == 'yes'
            elif key in ('bitrate', 'data_bitrate', 'heartbeat_period_ms', 'stale_after_ms'):
                can[{'heartbeat_period_ms': 'hb_period', 'stale_after_ms': 'stale'}.get(key, key)] = int(value)
            elif key == 'heartbeat_id':
                can['hb_id'] = int(value, 0)
            elif key == 'heartbeat_extended':
                can['hb_extended'] = value == 'yes'
            elif key in ('node', 'receiver'):
                can[key] = value
            elif key == 'robot_generation':
                can['generation'] = int(value[0])
        elif section == 'canopen' and key == 'node_id':
            can['node_id'] = int(value, 0)
        elif section and (section.startswith('frame ') or section.startswith('input ')):
            kind, name = section.split(None, 1)
            if name not in frames:
                frames[name] = {'name': name, 'extended': False, 'fd': False, 'length': 8, 'signals': [],
                                'policy': 'stop', 'stale': None, 'every': False, 'input': kind == 'input',
                                'timeout': None, 'silence': 'stop', 'robot': None, 'comment': None}
                order.append(name)
            f = frames[name]
            if key == 'id':
                f['id'] = int(value, 0)
            elif key in ('extended', 'fd'):
                f[key] = value == 'yes'
            elif key == 'length':
                f['length'] = int(value)
            elif key == 'period_ms':
                f['every'] = value == 'every'
                f['period'] = None if f['every'] else int(value)
            elif key == 'signal':
                f['signals'].append(parse_signal(value))
            elif key == 'alive_counter':
                f['signals'].append(marker('alive', value))
            elif key == 'validity_bit':
                f['signals'].append(marker('valid', value))
            elif key == 'stale_policy':
                f['policy'] = value
            elif key == 'stale_after_ms':
                f['stale'] = int(value)
            elif key == 'comment':
                f['comment'] = value
            elif key == 'timeout_ms':
                f['timeout'] = int(value)
            elif key == 'on_silence':
                f['silence'] = ' '.join(value.split())
            elif key == 'robot':
                f['robot'] = value
    for f in frames.values():
        if f['stale'] is None:
            f['stale'] = can['stale']
    if 'node_id' in can:
        canopen_ids(can, [frames[n] for n in order if not frames[n]['input']],
                    [frames[n] for n in order if frames[n]['input']])
    return can, [frames[n] for n in order]


def canopen_ids(can, frames, inputs):
    """With [canopen] (docs/canopen.md): the nth frame is TPDO n, at CiA 301's pre-defined COB-ID
    0x180/0x280/0x380/0x480 + node id unless it gives its own; the status frame (the heartbeat's
    layout) is the next TPDO, at its pre-defined id, else 0x680 + node id; the nth [input] is
    RPDO n, at 0x200/0x300/0x400/0x500 + node id."""
    for n, f in enumerate(frames, 1):
        f.setdefault('id', 0x80 + 0x100 * n + can['node_id'])
    for n, f in enumerate(inputs, 1):
        f.setdefault('id', 0x100 + 0x100 * n + can['node_id'])
    status = len(frames) + 1
    can.setdefault('hb_id', 0x80 + 0x100 * status + can['node_id'] if status <= 4 else 0x680 + can['node_id'])


# ---- the reference packing (docs/can.md, "Values") -----------------------------------


def bits_of(sig):
    """Payload bit positions (DBC numbering) from LSB to MSB of the signal."""
    if sig['order'] == 'intel':
        return [sig['start'] + i for i in range(sig['length'])]
    pos = sig['start']
    msb_first = []
    for _ in range(sig['length']):
        msb_first.append(pos)
        pos = pos - 1 if pos % 8 != 0 else pos + 15
    return list(reversed(msb_first))


def round_half_away(x):
    f = Fraction(x)
    n = math.floor(abs(f) + Fraction(1, 2))
    return n if f >= 0 else -n


def mask_of(v):
    """The bit mask a double holds, as UR sends one (docs/protocol.md), or None:
    a non-negative integer up to 2^53, or a raw int64 read as a double (sign
    and exponent bits all zero: a subnormal, or zero)."""
    bits = struct.unpack('<Q', struct.pack('<d', v))[0]
    if bits >> 52 == 0:
        return bits
    if math.isfinite(v) and v >= 0 and v == int(v) and v <= 2 ** 53:
        return int(v)
    return None


def ref_to_raw(sig, v):
    """(raw value as canmatrix takes it: signed int or float, raw bits, outcome)."""
    n = sig['length']
    mask = (1 << n) - 1
    t = sig['type']
    if sig.get('mask'):
        m = mask_of(v)
        if m is None:  # no mask: as NaN, the invalid raw or no bit set
            bits = sig['invalid'] if sig['invalid'] is not None else 0
            return bits, bits, 2
        return (m >> sig['first']) & mask, (m >> sig['first']) & mask, 0
    if math.isnan(v):
        if sig['invalid'] is not None:
            bits = sig['invalid']
        elif t == 'float32':
            bits = 0x7FC00000
        elif t == 'float64':
            bits = 0x7FF8000000000000
        else:
            neutral = min(max(0.0, sig['min']), sig['max'])
            bits = ref_to_raw(sig, neutral)[1]
        return from_bits(sig, bits), bits, 2
    outcome = 0
    if v < sig['min']:
        v, outcome = sig['min'], 1
    elif v > sig['max']:
        v, outcome = sig['max'], 1
    try:
        scaled = (v - sig['offset']) / sig['factor']
    except OverflowError:
        scaled = math.inf
    if math.isinf(v - sig['offset']):
        scaled = math.copysign(math.inf, (v - sig['offset']) * sig['factor'])
    if t in ('float32', 'float64'):
        limit = FLT_MAX if t == 'float32' else DBL_MAX
        if scaled > limit:
            scaled, outcome = limit, 1
        elif scaled < -limit:
            scaled, outcome = -limit, 1
        if t == 'float32':
            bits = struct.unpack('<I', struct.pack('<f', scaled))[0]
        else:
            bits = struct.unpack('<Q', struct.pack('<d', scaled))[0]
        return from_bits(sig, bits), bits, outcome
    lo, hi = raw_range(sig)
    r = round_half_away(scaled) if math.isfinite(scaled) else (hi + 1 if scaled > 0 else lo - 1)
    if r > hi:
        r, outcome = hi, 1
    elif r < lo:
        r, outcome = lo, 1
    return r, r & mask, outcome


def from_bits(sig, bits):
    t = sig['type']
    if t == 'float32':
        return struct.unpack('<f', struct.pack('<I', bits))[0]
    if t == 'float64':
        return struct.unpack('<d', struct.pack('<Q', bits))[0]
    if t == 'signed' and bits >> (sig['length'] - 1):
        return bits - (1 << sig['length'])
    return bits


def phys_of(sig, raw):
    return float(raw) * sig['factor'] + sig['offset']


# ---- canmatrix helpers -------------------------------------------------------------------


def load_dbc(text):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        db = canmatrix_dbc.load(io.BytesIO(text.encode('iso-8859-1')))
    return db, out.getvalue()


def frame_in(db, fid, extended):
    return db.frame_by_id(canmatrix.ArbitrationId(id=fid, extended=extended))


HEARTBEAT = [  # name, start, length, signed, unit: docs/can.md "The heartbeat"
    ('state', 0, 4, False, ''), ('alive_counter', 4, 4, False, ''), ('robot_mode', 8, 8, True, ''),
    ('safety_mode', 16, 8, False, ''), ('generation', 24, 2, False, ''), ('bus_off', 26, 1, False, ''),
    ('can_errors', 27, 1, False, ''), ('can_down', 28, 1, False, ''), ('send_errors', 29, 1, False, ''),
    ('tx_dropped', 30, 1, False, ''), ('clamped', 31, 1, False, ''), ('data_age', 32, 16, False, 'ms'),
    ('drops', 48, 16, False, ''),
]

ENUM_SPOTS = {  # field: (value, name) pairs a value table must hold
    'robot_mode': [(-1, 'NO_CONTROLLER'), (7, 'RUNNING')],
    'joint_modes': [(253, 'RUNNING'), (235, 'RESET')],
    'safety_mode': [(1, 'NORMAL'), (7, 'ROBOT_EMERGENCY_STOP')],
    'safety_status': [(12, 'AUTOMATIC_MODE_SAFEGUARD_STOP')],
    'program_state': [(2, 'PLAYING')],
}


def compare_dbc(label, db, can, frames, robot_period_us):
    """Every configured frame, signal and attribute is in the DBC as configured."""
    names = sorted(f.name for f in db.frames)
    want_names = sorted([f['name'] for f in frames] + ['urrt_heartbeat'])
    check(names == want_names, '%s: DBC frames' % label, '%s vs %s' % (names, want_names))
    for f in frames:
        d = db.frame_by_name(f['name'])
        if not check(d is not None, '%s: frame %s in the DBC' % (label, f['name'])):
            continue
        ok = (d.arbitration_id.id == f['id'] and d.arbitration_id.extended == f['extended'] and
              d.size == f['length'] and d.is_fd == f['fd'])
        check(ok, '%s: %s id, format and length' % (label, f['name']),
              (hex(d.arbitration_id.id), d.arbitration_id.extended, d.size, d.is_fd))
        if f['input']:  # the PLC's period is its own: no GenMsgCycleTime (its default 0)
            check(d.cycle_time == 0 and 'GenMsgCycleTime' not in d.attributes,
                  '%s: %s has no GenMsgCycleTime' % (label, f['name']), d.attributes)
        else:
            cycle = -(-robot_period_us // 1000) if f['every'] else f['period']
            check(d.cycle_time == cycle, '%s: %s GenMsgCycleTime' % (label, f['name']), (d.cycle_time, cycle))
        fmt = ('Extended' if f['extended'] else 'Standard') + 'CAN' + ('_FD' if f['fd'] else '')
        check(d.attributes.get('VFrameFormat') == fmt and d.attributes.get('GenMsgSendType') == 'Cyclic',
              '%s: %s VFrameFormat and GenMsgSendType' % (label, f['name']), d.attributes)
        if f['fd']:
            brs = '1' if can['data_bitrate'] > can['bitrate'] else '0'
            check(d.attributes.get('CANFD_BRS') == brs, '%s: %s CANFD_BRS' % (label, f['name']), d.attributes)
        if f['input']:  # sent by the PLC ([can] receiver; Vector__XXX: no node, which canmatrix drops)
            want_tx = [] if can['receiver'] == 'Vector__XXX' else [can['receiver']]
            check(d.transmitters == want_tx, '%s: %s is sent by the PLC' % (label, f['name']), d.transmitters)
            check(d.comment is not None and d.comment.startswith(f['comment'] + '. ' if f['comment'] else 'Sent by ')
                  and ('no frame for %d ms is a silent PLC: on_silence = %s' % (f['timeout'], f['silence']))
                  in d.comment, '%s: %s comment: its comment=, timeout and on_silence' % (label, f['name']),
                  d.comment)
        else:
            check(d.transmitters == [can['node']], '%s: %s transmitter' % (label, f['name']), d.transmitters)
        check(len(d.signals) == len(f['signals']), '%s: %s signal count' % (label, f['name']))
        for s in f['signals']:
            ds = d.signal_by_name(s['name'])
            if not check(ds is not None, '%s: %s.%s in the DBC' % (label, f['name'], s['name'])):
                continue
            got = (ds.get_startbit(bit_numbering=1), int(ds.size), ds.is_little_endian, ds.is_signed,
                   ds.is_float, float(ds.factor), float(ds.offset), float(ds.min), float(ds.max), ds.unit)
            want = (s['start'], s['length'], s['order'] == 'intel', s['type'] != 'unsigned',
                    s['type'] in ('float32', 'float64'), s['factor'], s['offset'], s['min'], s['max'], s['unit'])
            check(got == want, '%s: %s.%s layout and scaling' % (label, f['name'], s['name']),
                  '%s vs %s' % (got, want))
            if f['input']:
                check(ds.receivers == [can['node']], '%s: %s.%s is received by the gateway' % (
                    label, f['name'], s['name']), ds.receivers)
            elif can['receiver'] != 'Vector__XXX':
                check(ds.receivers == [can['receiver']], '%s: %s.%s receiver' % (label, f['name'], s['name']),
                      ds.receivers)
            if s['role'] == 'field':
                info = FIELDS[s['field']]
                ref = '%s[%d]' % (s['field'], s['elem']) if info['count'] > 1 else s['field']
                col = info['col_3x'] or info['col_1x']
                check(ds.comment is not None and ds.comment.startswith(ref + ':') and
                      ('column %d' % (col + s['elem'])) in ds.comment,
                      '%s: %s.%s comment names the field and column' % (label, f['name'], s['name']), ds.comment)
            if s['role'] == 'rtde' and f['input']:
                info = RTDE_ONLY[s['field']]
                want = '%s: RTDE input %s, written by urrt-gateway to robot ' % (s['field'], info['type'])
                check(ds.comment is not None and ds.comment.startswith(want) and ds.comment.endswith(
                      '; [input %s] timeout_ms = %d, on_silence = %s' % (f['name'], f['timeout'], f['silence'])),
                      '%s: %s.%s comment names the register, the timeout and on_silence' % (
                          label, f['name'], s['name']), ds.comment)
                if s['mask']:
                    check('bit n of this signal is bit %d+n of the register' % s['first'] in ds.comment,
                          '%s: %s.%s comment: a mask from bit %d' % (label, f['name'], s['name'], s['first']),
                          ds.comment)
            elif s['role'] == 'rtde':
                info = RTDE_ONLY[s['field']]
                ref = '%s[%d]' % (s['field'], s['elem']) if info['count'] > 1 else s['field']
                check(ds.comment is not None and ds.comment.startswith('%s: RTDE output %s' % (ref, info['type'])),
                      '%s: %s.%s comment names the RTDE-only value and its type' % (label, f['name'], s['name']),
                      ds.comment)
                if s['mask']:
                    check('bit n of this signal is bit %d+n of the value' % s['first'] in ds.comment,
                          '%s: %s.%s comment: a mask from bit %d' % (label, f['name'], s['name'], s['first']),
                          ds.comment)
            if s['role'] == 'field':
                for value, name in ENUM_SPOTS.get(s['field'], []):
                    if s['field'] == 'robot_mode' and can['generation'] != 3:
                        continue
                    raw = (value - s['offset']) / s['factor']
                    lo, hi = raw_range(s)
                    if raw != int(raw) or not lo <= raw <= hi or not s['min'] <= value <= s['max']:
                        continue
                    check(ds.values.get(int(raw)) == name, '%s: %s.%s value table %d' % (
                        label, f['name'], s['name'], value), ds.values)
    hb = frame_in(db, can['hb_id'], can['hb_extended'])
    if check(hb is not None and hb.name == 'urrt_heartbeat', '%s: heartbeat frame' % label):
        check(hb.size == 8 and not hb.is_fd and hb.cycle_time == can['hb_period'],
              '%s: heartbeat length and cycle' % label, (hb.size, hb.cycle_time))
        got = [(s.name, s.get_startbit(bit_numbering=1), int(s.size), s.is_signed, s.unit) for s in hb.signals]
        check(got == HEARTBEAT, '%s: heartbeat layout as documented' % label, got)
        check(hb.signal_by_name('state').values == {0: 'STARTING', 1: 'OK', 2: 'DATA_STALE',
                                                   3: 'ROBOT_DISCONNECTED'},
              '%s: heartbeat state values' % label)
        check(hb.signal_by_name('robot_mode').values.get(-128) == 'NOT_AVAILABLE',
              '%s: heartbeat robot mode not available' % label)


# ---- random layouts ----------------------------------------------------------------------

FACTORS = [1.0, 0.5, 0.25, 0.1, 0.01, 0.001, 2.0, 10.0, 0.0002, -0.5, 1 / 3]
OFFSETS = [0.0, -40.0, 100.5, -6.4, 1000.0, 0.1]


def random_signal(rng, frame_bits, taken, index):
    for _ in range(200):
        t = rng.choice(['unsigned', 'signed', 'unsigned', 'signed', 'float32', 'float64'])
        if t == 'float32':
            n = 32
        elif t == 'float64':
            n = 64
        else:
            n = rng.choice([1, 2, 3, 5, 7, 8, 9, 12, 13, 16, 17, 23, 24, 31, 32, 33, 40, 47, 52, 63, 64])
        order = rng.choice(['intel', 'motorola'])
        start = rng.randrange(frame_bits)
        sig = {'type': t, 'length': n, 'order': order, 'start': start}
        pos = bits_of(sig)
        if any(p < 0 or p >= frame_bits for p in pos) or taken.intersection(pos):
            continue
        taken.update(pos)
        if t == 'unsigned' and rng.random() < 0.3:
            return random_mask_signal(rng, sig, index)
        if t in ('float32', 'float64') or n > 48:
            factor, offset = (1.0, 0.0) if n > 48 and t not in ('float32', 'float64') else \
                (rng.choice([1.0, 2.0, 0.5]), rng.choice([0.0, 1.0]))
        else:
            factor, offset = rng.choice(FACTORS), rng.choice(OFFSETS)
        words = ['q_actual[%d]' % (index % 6), '@%d|%d' % (start, n), order, t, 'name=s%d' % index]
        if factor != 1.0:
            words.append('factor=%r' % factor)
        if offset != 0.0:
            words.append('offset=%r' % offset)
        sig.update({'factor': factor, 'offset': offset, 'invalid': None})
        lo, hi = default_limits(sig)
        if t in ('unsigned', 'signed') and rng.random() < 0.3:
            a, b = sorted(rng.uniform(lo, hi) for _ in range(2))
            a, b = float('%.6g' % a), float('%.6g' % b)
            if lo <= a <= b <= hi:
                words += ['min=%r' % a, 'max=%r' % b]
        if t in ('unsigned', 'signed') and rng.random() < 0.3:
            words.append('invalid=%d' % rng.randrange(1 << n))
        return ' '.join(words)
    return None


def random_mask_signal(rng, sig, index):
    """A bit-mask field in the place chosen: its bits from a random first one."""
    n = sig['length']
    first = rng.randrange(65 - n)
    words = [rng.choice(['digital_input_bits', 'digital_outputs']), '@%d|%d' % (sig['start'], n), sig['order'],
             'unsigned', 'name=s%d' % index]
    if first > 0 or rng.random() < 0.3:
        words.append('bits=%d-%d' % (first, first + n - 1) if n > 1 or rng.random() < 0.5 else 'bits=%d' % first)
    if rng.random() < 0.3:
        words.append('invalid=%d' % rng.randrange(1 << n))
    return ' '.join(words)


def random_config(rng, path, nframes):
    fd = rng.random() < 0.5
    lines = ['[can]', 'interface = log:-', 'heartbeat_id = 0x7F0', 'heartbeat_period_ms = 200',
             'max_bus_load = 100']
    if fd:
        lines += ['fd = yes', 'data_bitrate = 2000000']
    for k in range(nframes):
        is_fd = fd and rng.random() < 0.7
        length = rng.choice([12, 16, 20, 24, 32, 48, 64, 8, 5]) if is_fd else rng.randint(1, 8)
        extended = rng.random() < 0.4
        lines += ['', '[frame f%d]' % k, 'id = 0x%X' % ((0x1000000 + k) if extended else (0x100 + k)),
                  'extended = %s' % ('yes' if extended else 'no'), 'fd = %s' % ('yes' if is_fd else 'no'),
                  'length = %d' % length, 'period_ms = %s' % rng.choice(['100', '250', 'every'])]
        taken = set()
        for i in range(rng.randint(1, 10)):
            line = random_signal(rng, 8 * length, taken, i)
            if line:
                lines.append('signal = ' + line)
    # The robot, as the gateway loads it: a 3.10 controller sends every 8 ms.
    lines += ['', '[robot arm]', 'host = 127.0.0.1', 'version = 3.10']
    open(path, 'w').write('\n'.join(lines) + '\n')


def at_period(path, work, period_us):
    """A copy of the configuration whose robots send every period_us: version
    3.10 (125 Hz) for 8000 us, 5.10 (500 Hz) for 2000 us."""
    text = re.sub(r'(?m)^version = .*$', 'version = %s' % ('3.10' if period_us == 8000 else '5.10'),
                  open(path).read())
    out = os.path.join(work, '%d-%s' % (period_us, os.path.basename(path)))
    open(out, 'w').write(text)
    return out


def mask_values(rng):
    """Masks of the digital I/O's 18 bits and of up to 53, as doubles and as raw
    int64s read as doubles; values that are no mask."""
    out = [float(rng.randrange(1 << 18)) for _ in range(4)]
    out += [float(rng.randrange(1 << rng.randrange(1, 54))) for _ in range(4)]
    out += [struct.unpack('<d', struct.pack('<Q', rng.randrange(1 << 52)))[0], 2.0 ** 53, 65552.0]
    out += [-1.0, 0.5, 2.0 ** 53 + 2, 2.0 ** 64, -0.0, math.nan, math.inf, -math.inf]
    return out


def values_for(rng, sig):
    """Physical values a packer must handle: raw-exact, random, out of range, specials."""
    lo, hi = raw_range(sig)
    t = sig['type']
    if sig.get('mask'):
        return mask_values(rng)
    out = []
    for _ in range(6):
        if t in ('float32', 'float64'):
            out.append(rng.uniform(-1e6, 1e6))
        else:
            out.append(phys_of(sig, rng.randint(lo, hi)))
    out.append(rng.uniform(sig['min'], sig['max']))
    out.append(sig['min'])
    out.append(sig['max'])
    span = (sig['max'] - sig['min']) or 1.0
    out.append(sig['max'] + rng.uniform(0.01, 10) * min(span, 1e300))
    out.append(sig['min'] - rng.uniform(0.01, 10) * min(span, 1e300))
    out += [math.nan, math.inf, -math.inf, 0.0]
    if t == 'float32':
        out += [1e39, -1e39, 3.4028235e38]
    return out


def test_random_layouts(tool, work, rng, configs):
    total = 0
    for c in range(configs):
        path = os.path.join(work, 'random%d.ini' % c)
        random_config(rng, path, rng.randint(1, 4))
        rc, out, err = run(tool, ['dbc', path])
        if not check(rc == 0, 'random config %d accepted' % c, out + err):
            continue
        db, noise = load_dbc(out)
        check(noise == '', 'random config %d: canmatrix reads the DBC without complaint' % c, noise)
        can, frames = parse_config(path)
        compare_dbc('random%d' % c, db, can, frames, 8000)
        # Pack: one line per value set, every signal of the frame set.
        lines = []
        expect = []
        for f in frames:
            d = db.frame_by_name(f['name'])
            sigs = [s for s in f['signals'] if s['role'] == 'field']
            columns = [values_for(rng, s) for s in sigs]
            for row in range(max(len(col) for col in columns)):
                vals = [col[row % len(col)] for col in columns]
                items = ' '.join('%s=%r' % (s['name'], v) for s, v in zip(sigs, vals))
                lines.append('%s %s' % (f['name'], items))
                raws = [ref_to_raw(s, v) for s, v in zip(sigs, vals)]
                data = d.encode({s['name']: r[0] for s, r in zip(sigs, raws)})
                expect.append((f['name'], bytes(data).hex().upper(), [r[2] for r in raws], items))
        rc, out, err = run(tool, ['pack', path], '\n'.join(lines) + '\n')
        got = out.splitlines()
        if not check(rc == 0 and len(got) == len(expect), 'random config %d: pack ran' % c, err):
            continue
        bad = 0
        for g, (name, hexdata, outcomes, items) in zip(got, expect):
            words = g.split()
            if words[0] != hexdata or [int(w) for w in words[1:]] != outcomes:
                bad += 1
                if bad <= 3:
                    print('  %s %s\n    packed    %s\n    reference %s %s' % (name, items, g, hexdata, outcomes))
        total += len(expect)
        check(bad == 0, 'random config %d: %d payloads match canmatrix and the reference' % (c, len(expect)),
              '%d differ' % bad)
        # Unpack random payloads.
        lines = []
        expect = []
        for f in frames:
            d = db.frame_by_name(f['name'])
            for _ in range(20):
                data = bytes(rng.randrange(256) for _ in range(f['length']))
                lines.append('%s %s' % (f['name'], data.hex().upper()))
                dec = d.decode(data)
                expect.append([(s['name'], phys_of(s, dec[s['name']].raw_value)) for s in f['signals']])
        rc, out, err = run(tool, ['unpack', path], '\n'.join(lines) + '\n')
        bad = 0
        for g, want in zip(out.splitlines(), expect):
            got_pairs = [(k, float(v)) for k, v in (w.split('=') for w in g.split())]
            same = len(got_pairs) == len(want) and all(
                a[0] == b[0] and (a[1] == b[1] or (math.isnan(a[1]) and math.isnan(b[1])))
                for a, b in zip(got_pairs, want))
            if not same:
                bad += 1
                if bad <= 3:
                    print('  unpack %s\n    got  %s\n    want %s' % (g, got_pairs, want))
        check(rc == 0 and bad == 0 and len(out.splitlines()) == len(expect),
              'random config %d: %d random payloads unpack as canmatrix decodes them' % (c, len(expect)),
              '%d differ' % bad)
    return total


# ---- the example configurations --------------------------------------------------------


def test_examples(tool, work):
    examples = sorted(p for p in os.listdir(os.path.join(ROOT, 'docs', 'examples')) if p.endswith('.ini'))
    check({'canopen.ini', 'j1939.ini'} <= set(examples), 'docs/examples has canopen.ini and j1939.ini', examples)
    for name in examples:
        path = os.path.join(ROOT, 'docs', 'examples', name)
        for period in (2000, 8000):
            rc, out, err = run(tool, ['validate', at_period(path, work, period)])
            check(rc == 0 and out.startswith('ok load='), '%s validates for a robot at %d us' % (name, period),
                  out + err)
        rc, out, err = run(tool, ['dbc', at_period(path, work, 2000)])
        if not check(rc == 0, '%s: DBC written' % name, err):
            continue
        open(os.path.join(work, name.replace('.ini', '.dbc')), 'w').write(out)
        db, noise = load_dbc(out)
        check(noise == '', '%s: canmatrix reads the DBC without complaint' % name, noise)
        can, frames = parse_config(path)
        compare_dbc(name, db, can, frames, 2000)


def test_canopen_run(tool, work):
    """canopen.ini driven by a scripted robot: frames decode through the DBC to
    the robot's values; alive counters, validity, staleness, heartbeat."""
    path = os.path.join(ROOT, 'docs', 'examples', 'canopen.ini')
    robot_8ms = at_period(path, work, 8000)
    rc, dbc, _ = run(tool, ['dbc', robot_8ms])
    db, _ = load_dbc(dbc)
    can, frames = parse_config(path)
    rng = random.Random(7)
    script = []
    packets = []  # (t, values)
    for t in range(0, 400000, 1000):
        if t % 8000 == 0 and 4000 <= t < 90000:
            v = {'q_actual[%d]' % j: rng.uniform(-6.2, 6.2) for j in range(6)}
            v.update({'tool_vector_actual[%d]' % j: rng.uniform(-1.3, 1.3) for j in range(3)})
            v.update({'speed_scaling': rng.uniform(0, 1), 'robot_mode': 7.0, 'safety_mode': 1.0,
                      'program_state': 2.0, 'digital_input_bits': float(rng.randrange(1 << 18)),
                      'digital_outputs': float(rng.randrange(1 << 18))})
            packets.append((t, v))
            script.append('packet %d arm1 %s' % (t, ' '.join('%s=%r' % kv for kv in v.items())))
        elif t == 300000:
            script.append('link arm1 down')
            script.append('tick %d' % t)
        else:
            script.append('tick %d' % t)
    rc, out, err = run(tool, ['run', robot_8ms], '\n'.join(script) + '\n')
    check(rc == 0, 'canopen run', err)
    by_id = {}
    for line in out.splitlines():
        t, frame = line.split()
        fid, data = frame.split('#')
        by_id.setdefault(int(fid, 16), []).append((int(t), bytes.fromhex(data)))
    # The CAN core alone (no node: the node's own frames are tests/gateway/canopen/'s): the four TPDOs
    # and the status frame, each on its id.
    check(set(by_id) == {0x185, 0x285, 0x385, 0x485, can['hb_id']}, 'canopen: the configured ids', sorted(by_id))

    def latest(t):
        best = None
        for pt, v in packets:
            if pt <= t:
                best = (pt, v)
        return best

    step = {s['name']: s for f in frames for s in f['signals']}
    for f in frames:
        d = db.frame_by_name(f['name'])
        sent = by_id.get(f['id'], [])
        times = [t for t, _ in sent]
        alive_ok = valid_ok = values_ok = stale_ok = True
        last_alive = None
        for t, data in sent:
            dec = d.decode(data)
            p = latest(t)
            age = t - p[0] if p else None
            fresh = p is not None and age <= f['stale'] * 1000
            if f['policy'] == 'stop':
                stale_ok &= fresh
            if 'valid' in dec:
                valid_ok &= dec['valid'].raw_value == (1 if fresh else 0)
            if 'alive_counter' in dec:
                a = dec['alive_counter'].raw_value
                alive_ok &= last_alive is None or a == (last_alive + 1) % 16
                last_alive = a
            if p is None:
                continue
            for s in f['signals']:
                if s['role'] != 'field':
                    continue
                key = '%s[%d]' % (s['field'], s['elem']) if FIELDS[s['field']]['count'] > 1 else s['field']
                want = p[1][key]
                got = float(dec[s['name']].phys_value)
                if s['mask']:  # the bits it carries, exactly, whatever else is set
                    values_ok &= got == (int(want) >> s['first']) & ((1 << s['length']) - 1)
                else:
                    values_ok &= abs(got - want) <= abs(step[s['name']]['factor']) / 2 + 1e-9
        label = 'canopen %s' % f['name']
        check(len(sent) >= 2, '%s: sent' % label, len(sent))
        check(all(b - a == f['period'] * 1000 for a, b in zip(times, times[1:])
                  if f['policy'] == 'invalid' or b - a < 100000),
              '%s: every %d ms' % (label, f['period']), times[:12])
        check(values_ok, '%s: values decode through the DBC to the robot values within the scaling' % label)
        check(alive_ok, '%s: alive counter +1 modulo 16' % label)
        check(valid_ok, '%s: validity bit 1 exactly while the data is fresh' % label)
        check(stale_ok, '%s: stale_policy = stop sends only fresh data' % label)
        if f['policy'] == 'invalid':
            check(times[-1] >= 390000, '%s: invalid policy keeps sending' % label, times[-1])
        else:
            check(times[-1] <= packets[-1][0] + f['stale'] * 1000, '%s: stop policy stops' % label, times[-1])
    hb = db.frame_by_name('urrt_heartbeat')
    states = [(t, hb.decode(data)) for t, data in by_id.get(can['hb_id'], [])]
    check([t for t, _ in states] == list(range(0, 400000, 100000)), 'canopen heartbeat every 100 ms',
          [t for t, _ in states])
    names = [d['state'].named_value for _, d in states]
    check(names == ['STARTING', 'OK', 'DATA_STALE', 'ROBOT_DISCONNECTED'], 'canopen heartbeat states', names)
    check(states[1][1]['robot_mode'].named_value == 'RUNNING' and
          states[1][1]['safety_mode'].named_value == 'NORMAL' and
          states[1][1]['generation'].named_value == 'CB3_ESERIES_3X_5X',
          'canopen heartbeat robot and safety mode names')
    ages = [int(d['data_age'].phys_value) for _, d in states]
    # Packets every 8 ms up to 88 ms: at 100 ms the data is 12 ms old, at 200 ms 112 ms.
    check(ages == [65535, 12, 112, 212], 'canopen heartbeat data age (65535: none yet)', ages)


def test_j1939_run(tool, work):
    """j1939.ini: "not available" raw values for NaN, offsets, 29-bit ids."""
    path = at_period(os.path.join(ROOT, 'docs', 'examples', 'j1939.ini'), work, 2000)
    rc, dbc, _ = run(tool, ['dbc', path])
    db, _ = load_dbc(dbc)
    script = ['packet 1000 arm1 q_actual[0]=1.5 q_actual[1]=-6.5 q_actual[2]=0 robot_mode=7 safety_mode=3 '
              'joint_modes[0]=253 joint_modes[1]=255 program_state=1 tool_vector_actual[0]=0.25',
              'tick 2000']
    rc, out, err = run(tool, ['run', path], '\n'.join(script) + '\n')
    frames = {}
    for line in out.splitlines():
        t, frame = line.split()
        fid, data = frame.split('#')
        frames.setdefault(int(fid, 16), bytes.fromhex(data))
    check(all(len('%X' % k) == 8 for k in frames) and 0x18FF1080 in frames,
          'j1939: 29-bit ids in candump notation', [hex(k) for k in frames])
    pos = frame_in(db, 0x18FF1080, True).decode(frames.get(0x18FF1080, bytes(8)))
    check(abs(float(pos['q0'].phys_value) - 1.5) <= 0.0001, 'j1939 q0', pos['q0'].phys_value)
    check(pos['q1'].raw_value == 0 and float(pos['q1'].phys_value) == -6.4, 'j1939 q1 below the range is clamped',
          pos['q1'].raw_value)
    check(pos['q3'].raw_value == 0xFFFF, 'j1939 q3 absent (NaN) is "not available" 0xFFFF', pos['q3'].raw_value)
    modes_frame = frame_in(db, 0x18FF1380, True)
    modes = modes_frame.decode(frames.get(0x18FF1380, bytes(8)))

    # VAL_ lists raw values (Vector's definition); canmatrix 0.9.5's named_value
    # looks the physical value up instead, which differs with an offset.
    def named(sig):
        return modes_frame.signal_by_name(sig).values.get(modes[sig].raw_value)
    check(modes['robot_mode'].raw_value == 8 and named('robot_mode') == 'RUNNING',
          'j1939 robot mode 7 is raw 8 (offset -1), named RUNNING', modes['robot_mode'].raw_value)
    check(float(modes['robot_mode'].phys_value) == 7, 'j1939 robot mode decodes to 7')
    check(modes['jm0'].raw_value == 53 and named('jm0') == 'RUNNING', 'j1939 joint mode 253 is raw 53')
    check(modes['jm1'].raw_value == 55 and named('jm1') == 'IDLE', 'j1939 joint mode 255 is raw 55')
    check(modes['jm2'].raw_value == 0xFF, 'j1939 absent joint mode is 0xFF', modes['jm2'].raw_value)
    check(modes['safety_mode'].named_value == 'PROTECTIVE_STOP', 'j1939 safety mode named')
    hb = frame_in(db, 0x18FF0080, True).decode(frames.get(0x18FF0080, bytes(8)))
    check(hb['state'].named_value == 'STARTING' or hb['state'].named_value == 'OK', 'j1939 heartbeat decodes',
          hb['state'].named_value)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--tool', required=True)
    ap.add_argument('--work', required=True)
    ap.add_argument('--configs', type=int, default=40)
    ap.add_argument('--seed', type=int, default=20261122)
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    rng = random.Random(args.seed)
    test_examples(args.tool, args.work)
    test_canopen_run(args.tool, args.work)
    test_j1939_run(args.tool, args.work)
    n = test_random_layouts(args.tool, args.work, rng, args.configs)
    print('random layouts: %d payloads packed, seed %d' % (n, args.seed))
    print('%d passed, %d failed' % (passed, failed))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
