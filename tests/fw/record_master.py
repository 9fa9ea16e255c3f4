#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""record_master.py RUN_DIR DEST_DIR: check-fw-gateway's recorded pair, from what
make check-canopen's VM run left in RUN_DIR (tests/canopen/canopen.sh): the robot's
stream as the simulators recorded it (sim1.bin, then sim2.bin after the cut) and the
frames tests/canopen/master.py sent (candump's can.log), put on the stream's clock.
Writes (make record-fw-master):

  DEST_DIR/vm-capture.bin.xz  the stream's packets in the window, a raw capture (xz)
  DEST_DIR/vm-master.log      the master's frames in the window, candump -l lines on
                              the capture's clock, for --replay-rx; '#' lines say how
                              the pair was made
  DEST_DIR/vm-node.log        the live node's SDO answers to those frames, the same way:
                              what the replay must answer too

The clock: the simulators ran with --clock monotonic, so a packet's time column is the
VM's CLOCK_MONOTONIC at its scheduled send instant; candump stamps a frame with the
kernel's CLOCK_REALTIME when vcan delivers it. canopen.sh read REALTIME, MONOTONIC,
REALTIME at the start and at the end of the run (clocks.txt): the offset is the middle
of each realtime pair less the monotonic reading, known to half the pair's spread, and
the VM has no NTP to slew one clock against the other (the two offsets must agree to
1 ms). A frame's time on the capture's clock is its stamp less the offset: right to
that bound. The replay then orders it against the packets by their scheduled instants,
where the live gateway saw each packet later by the simulator's lateness and the link's
delay (the simulator logs its lateness): a frame that came within that lateness after a
packet's instant may be fed before that packet in the replay (the header of vm-master.log
quotes the simulator's figures). The frame-for-frame comparison does not depend on that
order (--replay and the image are fed the same frames at the same times), nor do the SDO
answers compared with the live node's: in the window the master reads no robot value,
only communication objects.

The window: the whole run is about 1.4 MB of 1220-byte packets that do not compress
(the simulated currents carry noise), so the pair keeps the part of the run from
WINDOW_BEFORE before the master's first NMT start (step 5: operational) to WINDOW_AFTER
after its first NMT stop (step 7): TPDOs, the PDO configuration and event timer writes,
SYNC counting with two transmission types, the SYNC moved to another id (0x1005) and back,
stop and an SDO request while stopped. The script refuses a pair over MAX_BYTES (a run on
a loaded host is slower: record again on a quieter one).
"""
import json
import lzma
import os
import re
import struct
import sys

NODE = 5
WINDOW_BEFORE = 0.05
WINDOW_AFTER = 0.1
MAX_BYTES = 240000
CLOCK_AGREE_NS = 1000000


def fail(msg):
    sys.exit('record_master.py: %s' % msg)


def clock_offset(path):
    """REALTIME - MONOTONIC in ns, and its error bound, from canopen.sh's two samples."""
    samples = []
    for line in open(path):
        r1, mono, r2 = (int(x) for x in line.split())
        samples.append(((r1 + r2) // 2 - mono, (r2 - r1 + 1) // 2))
    if len(samples) != 2:
        fail('%s: %d clock samples, not 2 (start and end of the run)' % (path, len(samples)))
    (off0, err0), (off1, err1) = samples
    if abs(off1 - off0) > CLOCK_AGREE_NS:
        fail('%s: REALTIME - MONOTONIC moved by %d ns during the run: a clock was stepped' % (path, off1 - off0))
    return off0, max(err0, err1) + abs(off1 - off0)


def can_log(path, offset_ns, wanted):
    """The frames of candump's log whose id is wanted, as (monotonic ns, id, data)."""
    out = []
    for line in open(path):
        m = re.match(r'^\((\d+)\.(\d{6})\) \S+ ([0-9A-F]{3})#([0-9A-F]*)$', line.strip())
        if not m:
            continue
        fid = int(m.group(3), 16)
        if wanted(fid):
            t = int(m.group(1)) * 1000000000 + int(m.group(2)) * 1000 - offset_ns
            out.append((t, fid, bytes.fromhex(m.group(4))))
    return out


def packets(path):
    """(time column in ns, bytes) of each whole packet of a simulator's recording."""
    data = open(path, 'rb').read()
    out, pos = [], 0
    while pos + 12 <= len(data):
        size = struct.unpack_from('>I', data, pos)[0]
        if size < 12 or pos + size > len(data):
            break  # the simulator was stopped inside a packet
        out.append((round(struct.unpack_from('>d', data, pos + 4)[0] * 1e9), data[pos:pos + size]))
        pos += size
    return out


def lateness(path):
    """The simulator's own account of how late it sent (its exit notice), or '?'."""
    m = re.search(r'lateness (mean [^;]*);', open(path).read())
    return m.group(1) if m else '?'


def nmt_time(frames, cs):
    t = [f[0] for f in frames if f[1] == 0x000 and f[2][0] == cs and f[2][1] in (0, NODE)]
    if not t:
        fail('the master sent no NMT command 0x%02X: not a whole run of master.py' % cs)
    return t[0]


def write_log(path, header, frames):
    with open(path, 'w') as f:
        f.write(header)
        for t, fid, data in frames:
            sec, usec = divmod(round(t / 1000), 1000000)
            f.write('(%010d.%06d) vcan0 %03X#%s\n' % (sec, usec, fid, data.hex().upper()))


def main():
    if len(sys.argv) != 3:
        sys.exit('usage: record_master.py RUN_DIR DEST_DIR')
    run, dest = sys.argv[1:]
    offset, err = clock_offset(os.path.join(run, 'clocks.txt'))
    # The master's frames: NMT, SYNC (on 0x080 and on every id it moved the SYNC to, which
    # the master lists in expect.json), SDO requests; ids the node never sends.
    with open(os.path.join(run, 'expect.json')) as f:
        sync_ids = {0x080} | set(json.load(f)['sync_ids'])
    frames = can_log(os.path.join(run, 'can.log'), offset,
                     lambda i: i == 0 or i in sync_ids or 0x600 <= i <= 0x67F)
    answers = can_log(os.path.join(run, 'can.log'), offset, lambda i: i == 0x580 + NODE)
    pk = packets(os.path.join(run, 'sim1.bin')) + packets(os.path.join(run, 'sim2.bin'))
    t0 = nmt_time(frames, 0x01) - round(WINDOW_BEFORE * 1e9)
    t1 = nmt_time(frames, 0x02) + round(WINDOW_AFTER * 1e9)
    pk = [p for p in pk if t0 <= p[0] <= t1]
    if len(pk) < 2:
        fail('no packets of the simulators in the window: were they run with --clock monotonic?')
    # The replay feeds frames from the first packet (the node's power-on) to the last.
    frames = [f for f in frames if pk[0][0] < f[0] <= pk[-1][0]]
    # The node's answers to those frames: from the first on (the node answers in order).
    answers = [a for a in answers if frames[0][0] < a[0] <= pk[-1][0]]
    capture = lzma.compress(b''.join(p[1] for p in pk), preset=9 | lzma.PRESET_EXTREME)
    if len(capture) > MAX_BYTES:
        fail('the window holds %d packets, %d bytes compressed, over %d: the run was slow; record again' %
             (len(pk), len(capture), MAX_BYTES))
    with open(os.path.join(dest, 'vm-capture.bin.xz'), 'wb') as f:
        f.write(capture)
    header = ('# Recorded by make record-fw-master (tests/fw/record_master.py) from make check-canopen\'s VM run:\n'
              '# tests/canopen/master.py managing urrt-gateway (node %d on vcan0, tests/canopen/canopen.ini),\n'
              '# robot data from urrt-sim --seed 1 --clock monotonic, from %g s before the master\'s NMT start to\n'
              '# %g s after its NMT stop; vm-capture.bin.xz holds the packets the gateway got in that window\n'
              '# (%d, %.6f s to %.6f s). Times are the VM\'s CLOCK_MONOTONIC, the packets\' time column:\n'
              '# candump\'s stamp less REALTIME - MONOTONIC (%d ns), right to %d ns.\n'
              '# The live gateway got each packet after its time column by the simulator\'s lateness\n'
              '# (%s) and the link\'s delay.\n' %
              (NODE, WINDOW_BEFORE, WINDOW_AFTER, len(pk), pk[0][0] / 1e9, pk[-1][0] / 1e9, offset, err,
               lateness(os.path.join(run, 'sim1.log'))))
    write_log(os.path.join(dest, 'vm-master.log'), header + '# These are the frames the master sent.\n', frames)
    write_log(os.path.join(dest, 'vm-node.log'), header + '# These are the node\'s SDO answers to them.\n', answers)
    print('record_master.py: %d packets (%d bytes compressed), %d master frames, %d SDO answers; offset known '
          'to %d ns' % (len(pk), len(capture), len(frames), len(answers), err))


if __name__ == '__main__':
    try:
        main()
    except (OSError, ValueError) as e:
        fail('%s: not a whole check-canopen run? (make record-fw-master runs one first)' % e)
