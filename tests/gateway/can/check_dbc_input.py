#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-can-dbc, the [input] half: the frames the PLC sends and the gateway receives.

For docs/examples/plc-io.ini, a configuration of an extended-id CAN FD [input]
(a Motorola signed signal of factor 0.01 and offset 0.5 with min/max and a unit,
an input_bit_registers32_to_63 mask split in two by bits=, a 32-bit integer, a
float32 and a bit register) and plc-io.ini without a PLC node (receiver
Vector__XXX):

- the DBC read by python3-canmatrix: the [input]'s transmitter is [can]
  receiver, every signal's receiver [can] node, BU_ names both; every
  signal's start bit, length, byte order, sign, type, factor, offset, min, max
  and unit exactly as configured (written out here, not read back through the
  configuration); no GenMsgCycleTime, GenMsgSendType Cyclic, VFrameFormat,
  CANFD_BRS; the comments name each register, the timeout and on_silence;
- values, both ways: physical values encoded by canmatrix (phys2raw, encode)
  decode through the gateway's own unpacking (urrt_can_unpack with the map's
  signal table, can_tool unpack) to raw * factor + offset, equal to what
  canmatrix meant; values packed by lib/urrt_can with the same table
  (can_tool pack) decode in canmatrix to the raw values they came from; a mask
  register is the bits of its signals put together; an out-of-range raw value
  is decoded as it is (not clamped), so that the gateway can refuse it;
- the C tables (--print-c-tables, through can_tool ctables) compile under lib/'s
  warnings (and for the Cortex-M4), and tests/gateway/can/ctables_input.c, a
  firmware's receiving side over them, describes each [input] as configured
  and decodes canmatrix's payloads to the same register values.

usage: check_dbc_input.py --tool can_tool --work DIR --cc CC --cflags FLAGS --liburrt LIB [--target-cc CC]
"""
import argparse
import contextlib
import io
import math
import os
import random
import shlex
import struct
import subprocess
import sys
from decimal import Decimal
from fractions import Fraction

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
with contextlib.redirect_stdout(io.StringIO()):  # canmatrix prints "ldf is not supported"
    import test_dbc as ref  # the reader of the grammar, canmatrix's loader, check()

ROOT = ref.ROOT
HERE = ref.HERE
FLT_MAX = ref.FLT_MAX
check = ref.check
PLC_IO = os.path.join(ROOT, 'docs', 'examples', 'plc-io.ini')

# An extended-id FD [input] and a classic one, beside a [frame] that reads a register back.
FD_CONFIG = """\
[robot arm]
host = 127.0.0.1
source = rtde
version = 5.10

[can]
interface = log:-
fd = yes
data_bitrate = 2000000
heartbeat_id = 0x7F0
node = GW
receiver = CELL_PLC

[frame echo]
id = 0x181
period_ms = 100
signal = input_double_register_30 @0|32 intel signed factor=0.01 name=echo

[input cmd]
id = 0x18FF1234
extended = yes
fd = yes
length = 16
timeout_ms = 250
on_silence = value 0
comment = Cell PLC setpoints
signal = input_double_register_30 @7|16 motorola signed factor=0.01 offset=0.5 min=-100 max=200 unit=mm name=setpoint
signal = input_bit_registers32_to_63 @16|8 intel unsigned bits=8-15 name=mask_hi
signal = input_bit_registers32_to_63 @24|4 intel unsigned bits=0-3 name=mask_lo
signal = input_int_register_25 @32|32 intel signed name=count
signal = input_double_register_31 @64|32 intel float32 name=speed
signal = input_bit_register_100 @96|1 intel unsigned name=flag

[input hold]
id = 0x210
timeout_ms = 50
on_silence = hold
signal = input_int_register_26 @0|8 intel unsigned
"""

# name: (start, length, little endian, signed, float, factor, offset, min, max, unit), as configured
PLC_IO_SIGNALS = {
    'job_number': (0, 16, True, False, False, 1.0, 0.0, 0.0, 9999.0, ''),
    'start': (16, 1, True, False, False, 1.0, 0.0, 0.0, 1.0, ''),
    'door_closed': (17, 1, True, False, False, 1.0, 0.0, 0.0, 1.0, ''),
}
CMD_SIGNALS = {
    'setpoint': (7, 16, False, True, False, 0.01, 0.5, -100.0, 200.0, 'mm'),
    'mask_hi': (16, 8, True, False, False, 1.0, 0.0, 0.0, 255.0, ''),
    'mask_lo': (24, 4, True, False, False, 1.0, 0.0, 0.0, 15.0, ''),
    'count': (32, 32, True, True, False, 1.0, 0.0, -2147483648.0, 2147483647.0, ''),
    'speed': (64, 32, True, True, True, 1.0, 0.0, -FLT_MAX, FLT_MAX, ''),
    'flag': (96, 1, True, False, False, 1.0, 0.0, 0.0, 1.0, ''),
}
# The register each signal writes, and a mask signal's first bit.
REGISTERS = {
    'job_number': ('input_int_register_24', None), 'start': ('input_bit_register_64', None),
    'door_closed': ('input_bit_register_65', None),
    'setpoint': ('input_double_register_30', None), 'mask_hi': ('input_bit_registers32_to_63', 8),
    'mask_lo': ('input_bit_registers32_to_63', 0), 'count': ('input_int_register_25', None),
    'speed': ('input_double_register_31', None), 'flag': ('input_bit_register_100', None),
    'input_int_register_26': ('input_int_register_26', None),
}


def run(args, stdin=''):
    p = subprocess.run(args, input=stdin, capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def layout(ds):
    return (ds.get_startbit(bit_numbering=1), int(ds.size), ds.is_little_endian, ds.is_signed, ds.is_float,
            float(ds.factor), float(ds.offset), float(ds.min), float(ds.max), ds.unit)


def dbc_of(tool, path, label):
    rc, out, err = run([tool, 'dbc', path])
    if not check(rc == 0, '%s: DBC written' % label, err):
        return None, ''
    db, noise = ref.load_dbc(out)
    check(noise == '', '%s: canmatrix reads the DBC without complaint' % label, noise)
    return db, out


# ---- the DBC ----------------------------------------------------------------------------------


def check_input_frame(label, db, name, fid, extended, fd, size, transmitters, receiver, signals):
    d = db.frame_by_name(name)
    if not check(d is not None, '%s: [input %s] in the DBC' % (label, name)):
        return None
    check((d.arbitration_id.id, d.arbitration_id.extended, d.is_fd, d.size) == (fid, extended, fd, size),
          '%s: %s id, extended, FD, length' % (label, name),
          (hex(d.arbitration_id.id), d.arbitration_id.extended, d.is_fd, d.size))
    check(d.transmitters == transmitters, '%s: %s is sent by %s' % (label, name, transmitters), d.transmitters)
    check(d.cycle_time == 0 and 'GenMsgCycleTime' not in d.attributes,
          '%s: %s has no GenMsgCycleTime (the PLC picks its period)' % (label, name), d.attributes)
    fmt = ('Extended' if extended else 'Standard') + 'CAN' + ('_FD' if fd else '')
    check(d.attributes.get('GenMsgSendType') == 'Cyclic' and d.attributes.get('VFrameFormat') == fmt,
          '%s: %s GenMsgSendType Cyclic, VFrameFormat %s' % (label, name, fmt), d.attributes)
    check(sorted(s.name for s in d.signals) == sorted(signals), '%s: %s signals' % (label, name),
          [s.name for s in d.signals])
    for sname, want in signals.items():
        ds = d.signal_by_name(sname)
        if not check(ds is not None, '%s: %s.%s in the DBC' % (label, name, sname)):
            continue
        check(layout(ds) == want, '%s: %s.%s start, length, byte order, sign, type, factor, offset, min, max, unit'
              % (label, name, sname), '%s vs %s' % (layout(ds), want))
        check(ds.receivers == [receiver], '%s: %s.%s is received by %s' % (label, name, sname, receiver),
              ds.receivers)
    return d


def test_plc_io_dbc(tool):
    label = 'plc-io.ini'
    db, text = dbc_of(tool, PLC_IO, label)
    if db is None:
        return
    check(sorted(e.name for e in db.ecus) == ['PLC', 'URRT_GATEWAY'], '%s: BU_ names the gateway and the PLC' % label,
          [e.name for e in db.ecus])
    check('\nBU_: URRT_GATEWAY PLC\n' in text, '%s: BU_ line' % label)
    d = check_input_frame(label, db, 'plc_command', 0x200, False, False, 8, ['PLC'], 'URRT_GATEWAY', PLC_IO_SIGNALS)
    if d is not None:
        check(d.comment.startswith("The PLC's command: the job to run, start, the door closed. Sent by PLC, received "
                                   "by URRT_GATEWAY, which writes robot arm1's input registers over RTDE from it; "
                                   "no frame for 100 ms is a silent PLC: on_silence = stop"),
              '%s: plc_command comment: its comment=, who sends it, timeout, on_silence' % label, d.comment)
        job = d.signal_by_name('job_number')
        check(job.comment == 'input_int_register_24: RTDE input INT32, written by urrt-gateway to robot arm1 as raw '
                             '* factor + offset; a value outside min..max is refused and counted, never clamped; '
                             '[input plc_command] timeout_ms = 100, on_silence = stop',
              '%s: job_number comment names its register, the timeout and on_silence' % label, job.comment)
        check(d.signal_by_name('start').comment.startswith('input_bit_register_64: RTDE input BOOL'),
              '%s: start writes input_bit_register_64' % label, d.signal_by_name('start').comment)
    answer = db.frame_by_name('robot_answer')
    check(answer is not None and answer.transmitters == ['URRT_GATEWAY'] and
          all(s.receivers == ['PLC'] for s in answer.signals),
          '%s: robot_answer still goes from the gateway to the PLC' % label)
    can, frames = ref.parse_config(PLC_IO)
    ref.compare_dbc(label, db, can, frames, 8000)


def test_no_plc_node(tool, work):
    """receiver = Vector__XXX (the default): the [input]'s transmitter is Vector__XXX, no node."""
    label = 'plc-io.ini without a PLC node'
    path = os.path.join(work, 'plc-io-no-node.ini')
    open(path, 'w').write(''.join(line for line in open(PLC_IO) if not line.startswith('receiver =')))
    db, text = dbc_of(tool, path, label)
    if db is None:
        return
    check('\nBU_: URRT_GATEWAY\n' in text and '\nBO_ 512 plc_command: 8 Vector__XXX\n' in text,
          '%s: BU_ has the gateway alone; plc_command is sent by Vector__XXX' % label)
    check_input_frame(label, db, 'plc_command', 0x200, False, False, 8, [], 'URRT_GATEWAY', PLC_IO_SIGNALS)
    d = db.frame_by_name('plc_command')
    check(d is not None and 'Sent by the PLC, received by URRT_GATEWAY' in d.comment,
          '%s: comment names the PLC without a node' % label, d.comment if d else None)


def test_fd_dbc(tool, path):
    label = 'FD [input]'
    db, _ = dbc_of(tool, path, label)
    if db is None:
        return
    check(sorted(e.name for e in db.ecus) == ['CELL_PLC', 'GW'], '%s: BU_ names GW and CELL_PLC' % label,
          [e.name for e in db.ecus])
    d = check_input_frame(label, db, 'cmd', 0x18FF1234, True, True, 16, ['CELL_PLC'], 'GW', CMD_SIGNALS)
    if d is not None:
        check(d.attributes.get('CANFD_BRS') == '1', '%s: cmd switches bit rate (data_bitrate > bitrate)' % label,
              d.attributes)
        check(d.comment.startswith('Cell PLC setpoints. Sent by CELL_PLC, received by GW') and
              d.comment.endswith('no frame for 250 ms is a silent PLC: on_silence = value 0 (written to every '
                                 'register of the frame).'),
              '%s: cmd comment' % label, d.comment)
        hi = d.signal_by_name('mask_hi').comment
        check(hi.startswith('input_bit_registers32_to_63: RTDE input UINT32') and
              'bit n of this signal is bit 8+n of the register' in hi and
              hi.endswith('[input cmd] timeout_ms = 250, on_silence = value 0'),
              '%s: mask_hi comment: its register, from bit 8' % label, hi)
    check_input_frame(label, db, 'hold', 0x210, False, False, 8, ['CELL_PLC'], 'GW',
                      {'input_int_register_26': (0, 8, True, False, False, 1.0, 0.0, 0.0, 255.0, '')})
    echo = db.frame_by_name('echo')
    check(echo is not None and echo.transmitters == ['GW'] and echo.signal_by_name('echo').receivers == ['CELL_PLC'],
          '%s: the [frame] goes from GW to CELL_PLC' % label)
    can, frames = ref.parse_config(path)
    ref.compare_dbc(label, db, can, frames, 2000)


# ---- values, both ways ---------------------------------------------------------------------------


def raw_limits(ds):
    """The raw values whose physical value lies within min..max (integer signals)."""
    n = int(ds.size)
    lo, hi = (-(1 << (n - 1)), (1 << (n - 1)) - 1) if ds.is_signed else (0, (1 << n) - 1)
    f, o = Fraction(Decimal(ds.factor)), Fraction(Decimal(ds.offset))
    a, b = (Fraction(Decimal(ds.min)) - o) / f, (Fraction(Decimal(ds.max)) - o) / f
    a, b = min(a, b), max(a, b)
    return max(lo, math.ceil(a)), min(hi, math.floor(b))


def random_raw(rng, ds, row):
    if ds.is_float:
        if row < 2:
            return [0.0, -1.5][row]
        return struct.unpack('<f', struct.pack('<f', rng.uniform(-1e6, 1e6)))[0]
    lo, hi = raw_limits(ds)
    return [lo, hi][row] if row < 2 else rng.randint(lo, hi)


def gateway_value(ds, raw):
    """What lib computes: raw * factor + offset in doubles."""
    return float(raw) * float(ds.factor) + float(ds.offset)


def registers_of(d, raws):
    """{register: value} the frame writes for raw values {signal: raw}: a mask's bits put together."""
    out = {}
    for ds in d.signals:
        reg, first = REGISTERS[ds.name]
        if first is not None:
            out[reg] = out.get(reg, 0) | (int(raws[ds.name]) << first)
        else:
            out[reg] = gateway_value(ds, raws[ds.name])
    return out


def parse_pairs(line):
    return dict(w.split('=', 1) for w in line.split())


def round_trip(tool, path, label, rng, rows=120):
    """canmatrix -> the gateway, and the gateway -> canmatrix, for every [input] of path; returns
    (frame name, hex payload, {register: value}) of canmatrix's payloads for the C tables."""
    db, _ = dbc_of(tool, path, label + ' (values)')
    if db is None:
        return []
    can, frames = ref.parse_config(path)
    payloads = []
    for f in [f for f in frames if f['input']]:
        d = db.frame_by_name(f['name'])
        rows_raw = [{ds.name: random_raw(rng, ds, row) for ds in d.signals} for row in range(rows)]
        # canmatrix encodes physical values (phys2raw, then the raw values into bytes) ...
        lines, encoded_ok = [], True
        for raws in rows_raw:
            data = {}
            for ds in d.signals:
                phys = ds.raw2phys(Decimal(repr(raws[ds.name])) if ds.is_float else raws[ds.name])
                back = ds.phys2raw(phys)
                encoded_ok &= (float(back) == float(raws[ds.name]))
                data[ds.name] = float(back) if ds.is_float else back
            hexdata = bytes(d.encode(data)).hex().upper()
            lines.append('%s %s' % (f['name'], hexdata))
            payloads.append((f['name'], hexdata, registers_of(d, raws)))
        check(encoded_ok, '%s: %s: canmatrix phys2raw gives the raw values back' % (label, f['name']))
        # ... which the gateway's unpacking (the map's signal table) decodes to raw * factor + offset.
        rc, out, err = run([tool, 'unpack', path], '\n'.join(lines) + '\n')
        got = out.splitlines()
        bad = []
        for raws, g in zip(rows_raw, got):
            values = parse_pairs(g)
            for ds in d.signals:
                want = gateway_value(ds, raws[ds.name])
                meant = float(ds.raw2phys(Decimal(repr(raws[ds.name])) if ds.is_float else raws[ds.name]))
                v = float(values.get(ds.name, 'nan'))
                if v != want or abs(v - meant) > 1e-9 * max(1.0, abs(meant)) or not ds.min <= Decimal(v) <= ds.max:
                    bad.append((ds.name, raws[ds.name], v, want, meant))
        check(rc == 0 and len(got) == rows and not bad,
              '%s: %s: %d payloads canmatrix encoded decode through urrt_can_unpack to the values canmatrix meant'
              % (label, f['name'], rows), (err, bad[:3]))
        # The other way: lib/urrt_can packs the same physical values, canmatrix decodes the raw values.
        lines = []
        for raws in rows_raw:
            items = []
            for ds in d.signals:
                reg, first = REGISTERS[ds.name]
                value = float(int(raws[ds.name]) << first) if first is not None else gateway_value(ds, raws[ds.name])
                items.append('%s=%r' % (ds.name, value))
            lines.append('%s %s' % (f['name'], ' '.join(items)))
        rc, out, err = run([tool, 'pack', path], '\n'.join(lines) + '\n')
        got = out.splitlines()
        bad = []
        for raws, g in zip(rows_raw, got):
            dec = d.decode(bytes.fromhex(g.split()[0]))
            for ds in d.signals:
                if float(dec[ds.name].raw_value) != float(raws[ds.name]):
                    bad.append((ds.name, raws[ds.name], dec[ds.name].raw_value))
        check(rc == 0 and len(got) == rows and not bad,
              '%s: %s: %d payloads lib/urrt_can packed decode in canmatrix to their raw values'
              % (label, f['name'], rows), (err, bad[:3]))
    return payloads


def test_not_clamped(tool):
    """job_number max=9999: a raw 65535 decodes to 65535, which the gateway then refuses (never clamps)."""
    data = bytes([0xFF, 0xFF, 0x01] + [0] * 5).hex().upper()
    rc, out, err = run([tool, 'unpack', PLC_IO], 'plc_command %s\n' % data)
    check(rc == 0 and parse_pairs(out.strip()) == {'job_number': '65535', 'start': '1', 'door_closed': '0'},
          'plc-io.ini: a job_number past max decodes as sent, not clamped', out + err)


# ---- the C tables ----------------------------------------------------------------------------------


def test_ctables(tool, work, path, label, payloads, args):
    """The tables compile under lib/'s flags, describe each [input] as configured, and decode
    canmatrix's payloads (payloads: from round_trip) to the same registers."""
    rc, tables, err = run([tool, 'ctables', path])
    if not check(rc == 0 and 'urrt_gateway_inputs[' in tables, '%s: C tables written' % label, err):
        return
    # Absolute: the tables are #included from tests/gateway/can/ctables_input.c, whose
    # directory a relative path would be taken from.
    base = os.path.abspath(os.path.join(work, label.replace(' ', '_').replace('[', '').replace(']', '')
                                        .replace('.ini', '')))
    open(base + '-tables.c', 'w').write(tables)
    cflags = shlex.split(args.cflags)
    rc, out, err = run(shlex.split(args.cc) + cflags + ['-Ilib', '-c', base + '-tables.c', '-o', base + '-tables.o'])
    check(rc == 0 and out + err == '', '%s: the C tables compile without a warning under lib/\'s flags' % label,
          out + err)
    if args.target_cc:
        rc, out, err = run(shlex.split(args.target_cc) + ['-Os', '-ffreestanding'] + cflags +
                           ['-Ilib', '-c', base + '-tables.c', '-o', base + '-tables-m4.o'])
        check(rc == 0 and out + err == '', '%s: the C tables compile for the Cortex-M4 under lib/\'s flags' % label,
              out + err)
    exe = base + '-ctables_input'
    rc, out, err = run(shlex.split(args.cc) + cflags + ['-Ilib', '-DTABLES="%s"' % (base + '-tables.c'),
                                                        os.path.join(HERE, 'ctables_input.c'), args.liburrt, '-lm',
                                                        '-o', exe])
    if not check(rc == 0 and out + err == '', '%s: a firmware\'s receiving side builds on them' % label, out + err):
        return
    can, frames = ref.parse_config(path)
    inputs = [f for f in frames if f['input']]
    rc, out, err = run([exe, 'describe'])
    described = [line for line in out.splitlines() if line.startswith('INPUT ')]
    signals = [line for line in out.splitlines() if line.startswith('SIGNAL ')]
    check(rc == 0 and len(described) == len(inputs), '%s: urrt_gateway_inputs has each [input]' % label, out + err)
    k = 0
    for f, line in zip(inputs, described):
        silence = {'stop': 0, 'hold': 1}.get(f['silence'], 2)
        value = float(f['silence'].split()[1]) if silence == 2 else 0.0
        regs = []
        for s in f['signals']:
            reg = REGISTERS[s['name']][0]
            if reg not in regs:
                regs.append(reg)
        want = 'INPUT id=0x%X flags=%d len=%d timeout_ms=%d silence=%d value=%s robot=0 regs=%s' % (
            f['id'], (1 if f['extended'] else 0) | (2 if f['fd'] else 0), f['length'], f['timeout'], silence,
            '%.17g' % value, ','.join(regs))
        check(line == want, '%s: %s as configured: id, kind, length, timeout, on_silence, its recipe' % (
            label, f['name']), '%s vs %s' % (line, want))
        got = signals[k:k + len(f['signals'])]
        k += len(f['signals'])
        check(got == ['SIGNAL reg=%s' % REGISTERS[s['name']][0] for s in f['signals']],
              '%s: %s: the register of each signal' % (label, f['name']), got)
    index = {f['name']: i for i, f in enumerate(inputs)}
    lines = ['%d %s' % (index[name], hexdata) for name, hexdata, _ in payloads]
    rc, out, err = run([exe], '\n'.join(lines) + '\n')
    got = out.splitlines()
    bad = []
    for (name, hexdata, regs), g in zip(payloads, got):
        values = parse_pairs(g)
        want = {r: (str(v) if isinstance(v, int) else '%.17g' % v) for r, v in regs.items()}
        if values != want:
            bad.append((name, hexdata, values, want))
    check(rc == 0 and len(got) == len(payloads) and not bad,
          '%s: %d payloads canmatrix encoded decode through the C tables to the registers' % (label, len(payloads)),
          (err, bad[:2]))
    # Out of range is refused, a length not configured is not used.
    for name, hexdata, _ in payloads[:1]:
        rc, out, err = run([exe], '%d %s\n' % (index[name], hexdata + '00'))
        check(out == 'bad\n', '%s: a payload of another length is not used' % label, out + err)
    if 'plc_command' in index:
        rc, out, err = run([exe], '%d FFFF000000000000\n' % index['plc_command'])
        check(out.startswith('input_int_register_24=refused '), '%s: job_number 65535 past max=9999 is refused'
              % label, out + err)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--tool', required=True)
    ap.add_argument('--work', required=True)
    ap.add_argument('--cc', required=True)
    ap.add_argument('--cflags', required=True)
    ap.add_argument('--liburrt', required=True)
    ap.add_argument('--target-cc', default='')
    ap.add_argument('--seed', type=int, default=20261122)
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    os.chdir(ROOT)
    rng = random.Random(args.seed)
    fd_path = os.path.join(args.work, 'input-fd.ini')
    open(fd_path, 'w').write(FD_CONFIG)
    test_plc_io_dbc(args.tool)
    test_no_plc_node(args.tool, args.work)
    test_fd_dbc(args.tool, fd_path)
    test_not_clamped(args.tool)
    for path, label in ((PLC_IO, 'plc-io.ini'), (fd_path, 'FD [input]')):
        payloads = round_trip(args.tool, path, label, rng)
        test_ctables(args.tool, args.work, path, label, payloads, args)
    print('%d passed, %d failed' % (ref.passed, ref.failed))
    return 1 if ref.failed else 0


if __name__ == '__main__':
    sys.exit(main())
