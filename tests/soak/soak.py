#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""make soak: three urrt-gateways, many urrt-sim fault modes, an independent judge;
and in the qemu VM, a PLC writing an RTDE robot's registers (soak_plc.py).

One gateway runs for the whole soak with an LCM output and a CAN output to a
candump log, another as a CANopen node (self-starting) to a log of its own.
urrt-sim serves both on one port, restarted for each phase with
the next fault mode (and, in the restart phase, killed and restarted every
couple of seconds). A third gateway (source = rtde, LCM and a CAN log as the
first) reads a second urrt-sim serving RTDE, restarted for each phase with
the next RTDE fault (RTDE_PHASES), its gateway stopped for a while in the
backlog phase. Every packet carries the wall clock at its scheduled send
instant (--clock realtime), so each message's and frame's data age is known
without asking the gateway:

- LCM: soak_lcm (C) receives every message; age = LCM's recv_utime (kernel
  receive time) - the time column.
- CAN: this script reads the log as it grows (the gateway writes each line
  with write(2), unbuffered, stamped with the wall clock just before the
  write); age = the line's stamp - the simulator's time recovered from the
  payload (0x181: the time column as a float64, exact; 0x182 and 0x183: ms
  since the soak's start, 32 bits, +-0.5 ms).
- CANopen: the same for the node's TPDOs (validity bits), and its EMCYs
  (0xFF01 link down, 0xFF02 stale) and heartbeats judged against the data
  its TPDO1 carries and the fault schedule.

Usage: soak.py --build DIR --python-stage DIR [--minutes N] [--phase-seconds S]
               [--result FILE] [--phases A,B] [--no-plc-vm]
"""
import argparse
import os
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import suite  # noqa: E402  the check and report every Python suite shares
from suite import check  # noqa: E402

BOUND_MS = 100          # the robot's silence_timeout, and [can] stale_after_ms
FAST_BOUND_MS = 50      # stale_after_ms of frame 0x182
# What a measured age may exceed its bound by: the loopback transport and the
# clock readings the gateway's estimate takes as its baseline (as check-gateway).
MARGIN_MS = 5
RATE = 500
# Growth allowed between the sample after warm-up and the last one: the
# allocator may keep a few more pages; a leak per connection or per phase
# exceeds it within a few cycles.
RSS_ALLOWANCE_KIB = 256
FD_ALLOWANCE = 1        # the robot's socket may be open at one sample and not the other
RT_PRIORITY = 10
# The checker's socket buffer holds 4 MiB (as far as net.core.rmem_max allows):
# with the default 208 KiB, about 60 ms without a read overflows it, and the
# kernel drops datagrams the gateway did send (9 packets' messages in a
# 30-minute soak on a busy machine).
CHECKER_URL_OPTIONS = "&recv_buf_size=4194304"
WAIT = 30               # upper bound of any wait for an event
# The VM's time beyond the soak's minutes: boot, the gateways' start, the judge.
PLC_VM_SPARE_S = 240

# (name, urrt-sim fault options); "restart" kills and restarts the simulator.
PHASES = [
    ("clean", []),
    ("close", ["--fault", "close-after=1000"]),
    ("reset", ["--fault", "reset-after=1000"]),
    ("truncate", ["--fault", "truncate-after=1000"]),
    ("stall", ["--fault", "stall-after=1000,for=1500"]),
    ("freeze-after", ["--fault", "freeze-after=1000,for=1500"]),
    ("freeze-every", ["--fault", "freeze-every=1000,for=700"]),
    ("garbage", ["--fault", "garbage-every=50,bytes=37"]),
    # 7-byte pieces at the CB3 rate: at 500 Hz, 80,000 writes a second took the
    # simulator (under SCHED_FIFO) 0.6-0.9 of one of this machine's two cores, and
    # the gateways, its subject, waited for a CPU 40-440 ms of every second (the
    # per-phase "sched" lines): heartbeat gaps of up to 581 ms that were the soak's.
    ("tiny-writes", ["--fault", "tiny-writes=7", "--rate", "125"]),
    ("coalesce", ["--fault", "coalesce=4"]),
    ("odd-length", ["--fault", "odd-length=200"]),
    ("restart", []),
]
RESTART_UP_S, RESTART_DOWN_S = 2.0, 0.3

# The RTDE robot's phases, one beside each of the above, on its own urrt-sim
# (--rtde, a 5.10 controller at 500 Hz) and its own [can] gateway (source = rtde).
RTDE_PHASES = [
    ("clean", []),
    ("close", ["--fault", "close-after=1000"]),
    ("refuse-v2", ["--fault", "rtde-refuse-v2"]),           # protocol 1 serves a reader
    ("bad-size", ["--fault", "rtde-bad-package=500"]),     # a byte short: a protocol error
    ("bad-header", ["--fault", "rtde-bad-package=500,kind=header"]),
    ("text", ["--fault", "rtde-text-every=50"]),           # a warning ten times a second
    # The gateway stopped (SIGSTOP) for 3 s: the controller's buffer for it passes
    # 64 KiB and it is disconnected as behind; woken, it reads seconds-old packages.
    ("backlog", ["--fault", "rtde-backlog=65536"]),
    ("stall", ["--fault", "stall-after=1000,for=1500"]),
    ("freeze-every", ["--fault", "freeze-every=1000,for=700"]),
    ("version", ["--controller", "3.10"]),                 # a CB3 at 125 Hz, its own variables
    ("coalesce", ["--fault", "coalesce=4"]),
    ("restart", []),
]
BACKLOG_STOP = (3.0, 6.0)   # seconds into the phase: SIGSTOP, SIGCONT

CAN_EVERY, CAN_FAST, CAN_INVALID, CAN_HEARTBEAT = 0x181, 0x182, 0x183, 0x701
CAN_BOUND_MS = {CAN_EVERY: BOUND_MS, CAN_FAST: FAST_BOUND_MS, CAN_INVALID: BOUND_MS}

# The CANopen gateway: node 9, self-starting, to its own log. TPDO1 keeps its
# period while stale with valid = 0; TPDO2 stops. Both carry ms since the
# soak's start (bytes 0-3), as 0x182 does.
CO_NODE = 9
CO_TPDO_INVALID, CO_TPDO_STOP = 0x180 + CO_NODE, 0x280 + CO_NODE
CO_EMCY, CO_HEARTBEAT = 0x80 + CO_NODE, 0x700 + CO_NODE
CO_ALIVE_BYTE = 4                                           # TPDO1's alive counter
CO_VALID_BYTE = {CO_TPDO_INVALID: 5, CO_TPDO_STOP: 4}       # each TPDO's validity bit (bit 0)
CO_HB_MS = 100
# Between the freezes: freeze-every's 700 ms raises 0xFF02 (stale) and resets
# it on fresh data; the 1500 ms stalls and freeze raise 0xFF02, then 0xFF01 as
# the link drops (0xFF02's reset hands over to it), and a frozen simulator
# keeps 0xFF01 set through the reconnection until data flows.
CO_SILENCE_MS = 1000
EMCY_LINK, EMCY_STALE = 0xFF01, 0xFF02
# The EMCYs each phase must raise once data has flowed in it (the stop and
# start between phases drops the link in every phase: that one is not counted).
EXPECTED_EMCY = {"close": (EMCY_LINK,), "reset": (EMCY_LINK,), "truncate": (EMCY_LINK,), "restart": (EMCY_LINK,),
                 "stall": (EMCY_STALE, EMCY_LINK), "freeze-after": (EMCY_STALE, EMCY_LINK),
                 "freeze-every": (EMCY_STALE,)}


def now_us():
    return int(time.time() * 1e6)


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("", 0))
        return s.getsockname()[1]


def wait_for(pred, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.02)
    return pred()


def config(port, url, log, t0, name, robot_line):
    """The [can] gateway of one robot (RealTime: robot_line 'version = 5.10'; RTDE:
    'source = rtde')."""
    return """[lcm]
url = {url}
status_rate = 10 Hz
gateway_rate = 10 Hz

[robot {name}]
host = 127.0.0.1
port = {port}
{robot_line}
silence_timeout = {bound} ms
backoff_initial = 20 ms
backoff_max = 200 ms

[can]
interface = log:{log}
heartbeat_id = 0x{hb:X}
stale_after_ms = {bound}
bitrate = 1000000

# The time column, exact: a receiver recomputes each frame's data age.
[frame clock_every]
id = 0x{every:X}
period_ms = every
signal = time @0|64 intel float64

# Milliseconds since the soak's start, with a joint, counter and validity.
[frame clock_fast]
id = 0x{fast:X}
period_ms = 10
stale_after_ms = {fast_bound}
signal = time @0|32 intel unsigned factor=0.001 offset={t0} name=time_ms
signal = q_actual[0] @32|16 intel signed factor=0.0002
alive_counter = 48
validity_bit = 63

# Keeps its period while stale, with valid = 0.
[frame clock_invalid]
id = 0x{inv:X}
period_ms = 20
stale_policy = invalid
signal = time @0|32 intel unsigned factor=0.001 offset={t0} name=time_ms
validity_bit = 63
""".format(url=url, name=name, robot_line=robot_line, port=port, bound=BOUND_MS, log=log, hb=CAN_HEARTBEAT, every=CAN_EVERY,
           fast=CAN_FAST, fast_bound=FAST_BOUND_MS, t0=t0, inv=CAN_INVALID)


def co_config(port, url, log, t0):
    """The CANopen gateway: the same robot, its own log, no LCM messages."""
    return """[lcm]
url = {url}
state_rate = off
joints_rate = off
tool_rate = off
status_rate = off
gateway_rate = off

[robot {name}co]
host = 127.0.0.1
port = {port}
version = 5.10
silence_timeout = {silence} ms
backoff_initial = 20 ms
backoff_max = 200 ms

[can]
interface = log:{log}
stale_after_ms = {bound}
bitrate = 1000000

[canopen]
node_id = {node}
nmt_start = operational
heartbeat_ms = {hb}

# TPDO1: keeps its period while stale, with valid = 0.
[frame co_invalid]
period_ms = 10
stale_policy = invalid
signal = time @0|32 intel unsigned factor=0.001 offset={t0} name=time_ms
alive_counter = {alive_bit}
validity_bit = {valid1_bit}

# TPDO2: stops while stale.
[frame co_stop]
period_ms = 20
stale_policy = stop
signal = time @0|32 intel unsigned factor=0.001 offset={t0} name=time_ms
validity_bit = {valid2_bit}
""".format(url=url, name=NAME, port=port, silence=CO_SILENCE_MS, log=log, bound=BOUND_MS, node=CO_NODE, hb=CO_HB_MS,
           t0=t0, alive_bit=CO_ALIVE_BYTE * 8, valid1_bit=CO_VALID_BYTE[CO_TPDO_INVALID] * 8,
           valid2_bit=CO_VALID_BYTE[CO_TPDO_STOP] * 8)


NAME = "soak%d" % os.getpid()


class PhaseStats:
    def __init__(self, name, start_us):
        self.name, self.start_us = name, start_us
        self.frames = {}         # id -> count
        self.oldest_us = {}      # id -> oldest data age
        self.stale = {}          # id -> frames older than their bound
        self.invalid = 0         # 0x183 frames with valid = 0 (not judged)
        self.hb_lies = 0


class CandumpLog:
    """Reads a candump log as it grows and hands each frame to _frame()."""

    def __init__(self, path, t0, stats):
        self.path, self.t0, self.stats = path, t0, stats
        self.offset = 0
        self.bad_lines = 0
        self.reported = 0
        self.phases = []

    def phase(self, name, start_us):
        self.phases.append(self.stats(name, start_us))

    def _phase_at(self, t_us):
        for p in reversed(self.phases):
            if p.start_us <= t_us:
                return p
        return self.phases[0]

    def read(self):
        try:
            with open(self.path, "rb") as f:
                f.seek(self.offset)
                data = f.read()
        except FileNotFoundError:
            return
        end = data.rfind(b"\n") + 1
        self.offset += end
        for line in data[:end].decode("ascii", "replace").splitlines():
            self._line(line)

    def _report(self, text):
        if self.reported < 20:
            print(self.prefix + text)
        self.reported += 1

    def _line(self, line):
        try:
            stamp, _, frame = line.split(" ")
            t_us = int(stamp[1:-1].replace(".", ""))
            ident, payload = frame.split("#")
            ident = int(ident, 16)
            data = bytes.fromhex(payload)
        except ValueError:
            self.bad_lines += 1
            self._report("unparsable line %r" % line)
            return
        p = self._phase_at(t_us)
        p.frames[ident] = p.frames.get(ident, 0) + 1
        self._frame(p, t_us, ident, data)

    def ms_since_t0(self, data):
        """The simulator's time (us) from a 32-bit 'ms since the soak's start' signal at byte 0."""
        return self.t0 * 1000000 + struct.unpack("<I", data[:4])[0] * 1000


class CanLog(CandumpLog):
    """Judges a [can] gateway's frames as they are read."""

    def __init__(self, path, t0, prefix):
        CandumpLog.__init__(self, path, t0, PhaseStats)
        self.prefix = prefix
        self.newest_stamp_us = 0       # newest simulator time carried by a data frame so far
        self.last_hb_us = None
        self.hb_gaps = []              # (previous heartbeat, this one) us
        self.alive = None              # 0x182's last alive counter
        self.alive_breaks = 0

    def _frame(self, p, t_us, ident, data):
        if ident == CAN_HEARTBEAT:
            self._heartbeat(p, t_us, data)
            return
        if ident == CAN_EVERY:
            sim_us = round(struct.unpack("<d", data)[0] * 1e6)
        elif ident in (CAN_FAST, CAN_INVALID):
            sim_us = self.ms_since_t0(data)
            if ident == CAN_FAST:
                alive = data[6] & 0xF
                if self.alive is not None and alive != (self.alive + 1) % 16:
                    self.alive_breaks += 1
                self.alive = alive
            if not data[7] & 0x80:
                if ident == CAN_INVALID:
                    p.invalid += 1
                    return
                self._report("0x%X without its validity bit at %d" % (ident, t_us))
        else:
            self._report("unexpected id 0x%X" % ident)
            return
        self.newest_stamp_us = max(self.newest_stamp_us, sim_us)
        age = t_us - sim_us
        p.oldest_us[ident] = max(p.oldest_us.get(ident, age), age)
        if age > (CAN_BOUND_MS[ident] + MARGIN_MS) * 1000:
            p.stale[ident] = p.stale.get(ident, 0) + 1
            self._report("stale 0x%X at %d: %.1f ms old (%s)" % (ident, t_us, age / 1e3, p.name))

    def _heartbeat(self, p, t_us, data):
        if self.last_hb_us is not None:
            self.hb_gaps.append((self.last_hb_us, t_us))
        self.last_hb_us = t_us
        # state 1 (OK) says the data is fresh: the newest data sent must say so too.
        if data[0] & 0xF == 1 and t_us - self.newest_stamp_us > (BOUND_MS + MARGIN_MS) * 1000:
            p.hb_lies += 1
            self._report("heartbeat OK at %d while the newest data sent is %.1f ms old (%s)" %
                         (t_us, (t_us - self.newest_stamp_us) / 1e3, p.name))



class CoPhaseStats:
    def __init__(self, name, start_us):
        self.name, self.start_us = name, start_us
        self.frames = {}         # id -> count
        self.invalid = {}        # TPDO id -> frames with valid = 0
        self.oldest_us = {}      # TPDO id -> oldest data age of a frame with valid = 1
        self.first_data_us = None  # the first TPDO with valid = 1 of this phase
        self.end_us = None       # the simulator's stop at the phase's end
        self.raised = {}         # EMCY code -> raised after first_data_us, before end_us
        self.resets = {}         # EMCY code -> reset


class CoLog(CandumpLog):
    """Judges the CANopen node's frames as they are read. TPDO1 (invalid policy,
    10 ms) carries the newest data the node has at every period, whatever its
    age: it is the reference the EMCYs are judged against."""
    prefix = "canopen: "

    def __init__(self, path, t0):
        CandumpLog.__init__(self, path, t0, CoPhaseStats)
        self.violations = {}     # rule -> count
        self.data_seen = False   # a TPDO with valid = 1 was seen (before: the startup, no data)
        self.before_data = 0
        self.newest_us = 0       # newest simulator time sent in TPDO1
        self.active = {}         # EMCY code raised -> its time
        self.pending = []        # (code, reset time, raise time): judged by the next TPDO1
        self.alive = None
        self.hb_count = 0
        self.hb_boot = 0
        self.last_hb_us = None
        self.max_hb_gap_us = 0

    def _violate(self, rule, t_us, text):
        self.violations[rule] = self.violations.get(rule, 0) + 1
        self._report("%s at %d (%s)" % (text, t_us, self._phase_at(t_us).name))

    def _frame(self, p, t_us, ident, data):
        if ident == CO_HEARTBEAT:
            self._heartbeat(t_us, data)
        elif ident in CO_VALID_BYTE:
            self._tpdo(p, t_us, ident, data)
        elif ident == CO_EMCY:
            self._emcy(p, t_us, data)
        else:
            self._violate("unexpected", t_us, "unexpected frame 0x%X#%s" % (ident, data.hex().upper()))

    def _tpdo(self, p, t_us, ident, data):
        if len(data) <= max(CO_VALID_BYTE[ident], CO_ALIVE_BYTE):
            self._violate("unexpected", t_us, "TPDO 0x%X#%s too short" % (ident, data.hex().upper()))
            return
        valid = data[CO_VALID_BYTE[ident]] & 1
        if not valid and not self.data_seen:
            self.before_data += 1
            return
        self.data_seen = True
        sim_us = self.ms_since_t0(data)
        age = t_us - sim_us
        if valid:
            p.oldest_us[ident] = max(p.oldest_us.get(ident, age), age)
            if p.first_data_us is None:
                p.first_data_us = t_us
            if age > (BOUND_MS + MARGIN_MS) * 1000:
                self._violate("valid_stale_%X" % ident, t_us, "0x%X#%s has its validity bit set on data %.1f ms old" %
                              (ident, data.hex().upper(), age / 1e3))
        else:
            p.invalid[ident] = p.invalid.get(ident, 0) + 1
        if ident != CO_TPDO_INVALID:
            return
        alive = data[CO_ALIVE_BYTE] & 0xF
        if self.alive is not None and alive != (self.alive + 1) % 16:
            self._violate("alive", t_us, "0x%X's alive counter went from %d to %d" % (ident, self.alive, alive))
        self.alive = alive
        self._settle(t_us, sim_us)
        if age > (BOUND_MS + MARGIN_MS) * 1000 and not self.active:
            self._violate("stale_silent", t_us, "data %.1f ms old and neither EMCY 0xFF01 nor 0xFF02 set" %
                          (age / 1e3))
        self.newest_us = max(self.newest_us, sim_us)

    def _settle(self, t_us, sim_us):
        """Judges the resets since the last TPDO1 by the data this one carries."""
        for code, reset_us, raise_us in self.pending:
            if code == EMCY_LINK and sim_us < raise_us - MARGIN_MS * 1000:
                self._violate("reset_early", reset_us, "EMCY 0xFF01 reset before data flowed again (the next "
                              "TPDO1's data is %.1f ms older than the link's loss)" % ((raise_us - sim_us) / 1e3))
            elif code == EMCY_STALE and reset_us - sim_us > (BOUND_MS + MARGIN_MS) * 1000:
                self._violate("reset_early", reset_us, "EMCY 0xFF02 reset while the data is %.1f ms old" %
                              ((reset_us - sim_us) / 1e3))
        self.pending = []

    def _emcy(self, p, t_us, data):
        if len(data) != 8:
            self._violate("emcy", t_us, "EMCY of %d bytes %s" % (len(data), data.hex().upper()))
            return
        code, register = struct.unpack("<H", data[:2])[0], data[2]
        if code == 0:
            self._emcy_reset(p, t_us, struct.unpack("<H", data[3:5])[0])
            return
        if code not in (EMCY_LINK, EMCY_STALE) or register != 0x81:
            self._violate("emcy", t_us, "unexpected EMCY %s" % data.hex().upper())
            return
        if code in self.active:
            self._violate("emcy", t_us, "EMCY 0x%04X raised twice" % code)
        if code == EMCY_STALE and t_us - self.newest_us <= (BOUND_MS - MARGIN_MS) * 1000:
            self._violate("raise_early", t_us, "EMCY 0xFF02 raised while the newest data sent is %.1f ms old" %
                          ((t_us - self.newest_us) / 1e3))
        if code == EMCY_LINK:
            # The link's loss ends staleness: 0xFF02's reset in the same run is the handover.
            self.pending = [x for x in self.pending if not (x[0] == EMCY_STALE and x[1] >= t_us - MARGIN_MS * 1000)]
        self.active[code] = t_us
        if p.first_data_us is not None and (p.end_us is None or t_us < p.end_us):
            p.raised[code] = p.raised.get(code, 0) + 1

    def _emcy_reset(self, p, t_us, code):
        if code not in self.active:
            self._violate("emcy", t_us, "EMCY reset of 0x%04X, which is not set" % code)
            return
        raise_us = self.active.pop(code)
        p.resets[code] = p.resets.get(code, 0) + 1
        if code == EMCY_LINK or EMCY_LINK not in self.active:
            self.pending.append((code, t_us, raise_us))

    def _heartbeat(self, t_us, data):
        state = data[0] if len(data) == 1 else -1
        if self.hb_count == 0 and state == 0:
            self.hb_boot += 1
        elif state != 5:
            self._violate("hb_state", t_us, "heartbeat 0x%X#%s: not OPERATIONAL (05)%s" %
                          (CO_HEARTBEAT, data.hex().upper(), "" if self.hb_count else ", nor a first boot-up (00)"))
        if self.last_hb_us is not None:
            gap = t_us - self.last_hb_us
            self.max_hb_gap_us = max(self.max_hb_gap_us, gap)
            if gap > CO_HB_MS * 1500:
                self._violate("hb_gap", t_us, "heartbeat %.1f ms after the last" % (gap / 1e3))
        self.last_hb_us = t_us
        self.hb_count += 1

    def end_phase(self, t_us):
        """The simulator stops now: its stop drops the link, in every phase; the
        EMCYs that follow are not the phase's fault."""
        self.phases[-1].end_us = t_us

    def finish(self, end_us):
        """After the last read: what was raised before the simulator's final stop is reset."""
        for code, raise_us in self.active.items():
            if raise_us < end_us:
                self._violate("never_reset", raise_us, "EMCY 0x%04X raised and never reset" % code)
        for code, reset_us, _ in self.pending:
            if reset_us < end_us:
                self._violate("reset_early", reset_us, "EMCY 0x%04X reset and no TPDO1 after it" % code)


def sched_sample(pid):
    """(CPU time, time runnable but waiting for a CPU) of a process and its threads so
    far, in ms: /proc/PID/schedstat, the kernel's own accounting."""
    try:
        with open("/proc/%d/schedstat" % pid) as f:
            run_ns, wait_ns = (int(x) for x in f.read().split()[:2])
        return run_ns / 1e6, wait_ns / 1e6
    except (OSError, ValueError):
        return 0.0, 0.0


class Sched:
    """Per phase, how much CPU each process had and how long it waited for one: what
    tells a subject that cannot keep up from one the soak starves."""

    def __init__(self):
        self.start = {}
        self.lines = []

    def begin(self, procs):
        """procs: name -> a Popen, or a pid."""
        pids = {name: p if isinstance(p, int) else p.pid for name, p in procs.items() if p}
        self.start = {name: (pid, sched_sample(pid), time.monotonic()) for name, pid in pids.items()}

    def end(self, phase):
        parts = []
        for name, (pid, (run0, wait0), t0) in self.start.items():
            run1, wait1 = sched_sample(pid)
            seconds = max(time.monotonic() - t0, 1e-3)
            parts.append("%s cpu %.0f ms/s, waited %.0f ms/s" % (name, (run1 - run0) / seconds,
                                                                    (wait1 - wait0) / seconds))
        if parts:
            self.lines.append("soak: sched in %s: %s" % (phase, "; ".join(parts)))


def proc_sample(pid):
    """(RSS in KiB, open descriptors) of a process."""
    with open("/proc/%d/status" % pid) as f:
        rss = next(int(l.split()[1]) for l in f if l.startswith("VmRSS:"))
    return rss, len(os.listdir("/proc/%d/fd" % pid))


class Sim:
    """One urrt-sim, stopped and started again on the same port (taken from the
    system the first time). The port can be taken meanwhile (by an outgoing
    connection's local port, a gateway's own among them): started again until it
    binds, within WAIT."""

    def __init__(self, soak, name, rtde):
        self.soak, self.name, self.rtde = soak, name, rtde
        self.proc = None
        self.port = 0
        self.starts = self.kills = self.bind_retries = 0

    def argv(self, port_file, extra):
        if not self.rtde:
            return ["--listen", "127.0.0.1:%d" % self.port, "--port-file", port_file, "--version", "5.10"]
        version = [] if "--controller" in extra else ["--controller", "5.10"]
        return ["--listen", "127.0.0.1:0", "--rtde", "127.0.0.1:%d" % self.port, "--rtde-port-file", port_file] + version

    def start(self, extra):
        end = time.monotonic() + WAIT
        while True:
            port_file = self.soak.path(self.name + ".port")
            if os.path.exists(port_file):
                os.unlink(port_file)
            p = self.soak.start([self.soak.args.sim] + self.argv(port_file, extra) +
                                ["--clock", "realtime", "--seed", str(self.starts), "-q"] +
                                self.soak.args.sim_rt + extra, self.name + ".log")
            self.starts += 1
            wait_for(lambda: os.path.exists(port_file) or p.poll() is not None, WAIT)
            if os.path.exists(port_file):
                self.port = int(open(port_file).read())
                self.proc = p
                return
            p.wait()
            if time.monotonic() > end:
                raise RuntimeError("%s cannot listen on port %d" % (self.name, self.port))
            self.bind_retries += 1
            time.sleep(0.1)

    def stop(self, sig=signal.SIGTERM):
        if self.proc is not None:
            self.proc.send_signal(sig)
            self.proc.wait(timeout=WAIT)
            self.proc = None

    def summary(self):
        return "%s: %d starts, %d killed, %d binds retried" % (self.name, self.starts, self.kills, self.bind_retries)


class Soak:
    def __init__(self, args):
        self.args = args
        self.dir = tempfile.mkdtemp(prefix="soak-")
        self.procs = []

    def path(self, name):
        return os.path.join(self.dir, name)

    def start(self, argv, log, **kw):
        p = subprocess.Popen(argv, stdout=kw.pop("stdout", None) or open(self.path(log), "a"),
                             stderr=subprocess.STDOUT, **kw)
        self.procs.append(p)
        return p

    def stop_all(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def on_signal(sig, frame):
    raise KeyboardInterrupt("signal %d" % sig)


def start_checker(s, args, url, robot, key):
    """soak_lcm on the robot's channels; its facts go to KEY.out."""
    ready = s.path(key + ".ready")
    checker = subprocess.Popen(args.checker_rt + [args.checker, url + CHECKER_URL_OPTIONS, robot, str(BOUND_MS * 1000),
                                                  str(MARGIN_MS * 1000), ready],
                               stdin=subprocess.PIPE, stdout=open(s.path(key + ".out"), "w"),
                               stderr=open(s.path(key + ".err"), "w"), text=True)
    s.procs.append(checker)
    if not wait_for(lambda: os.path.exists(ready) or checker.poll() is not None, WAIT) or checker.poll() is not None:
        raise RuntimeError("soak_lcm did not start: %s" % open(s.path(key + ".err")).read())
    return checker


def run(args):
    s = Soak(args)
    t0 = int(time.time())
    can = CanLog(s.path("can.log"), t0, "can: ")
    rcan = CanLog(s.path("rtde-can.log"), t0, "rtde can: ")
    co = CoLog(s.path("co.log"), t0)
    sim, rsim = Sim(s, "sim", False), Sim(s, "rtde-sim", True)
    url = "udpm://239.255.76.67:%d?ttl=0" % free_udp_port()
    rurl = "udpm://239.255.76.67:%d?ttl=0" % free_udp_port()
    deadline = time.monotonic() + args.minutes * 60
    cycle_s = len(PHASES) * args.phase_seconds
    cycles = max(1, int(args.minutes * 60 // cycle_s))
    # Warm-up: the first pass of every fault when there is room for another,
    # else the first phase; RSS and descriptors are compared from there.
    warm_phases = len(PHASES) if args.minutes * 60 >= 2 * cycle_s else 1
    print("soak: %.1f min, %d phases of %d s (%d s per pass, %d passes), bound %d ms (+%d ms margin), dir %s" %
          (args.minutes, len(PHASES), args.phase_seconds, cycle_s, cycles, BOUND_MS, MARGIN_MS, s.dir))
    samples = {"can": [], "canopen": [], "rtde": []}
    sched = Sched()
    stops = []                  # (from, to) us: the RTDE gateway stopped (SIGSTOP) in the backlog phase
    gws = {}
    vm = start_plc_vm(args, s)
    try:
        sim.start(PHASES[0][1])
        rsim.start(RTDE_PHASES[0][1])
        checker = start_checker(s, args, url, NAME, "lcm")
        rchecker = start_checker(s, args, rurl, NAME + "rtde", "rtde-lcm")
        with open(s.path("gw.ini"), "w") as f:
            f.write(config(sim.port, url, can.path, t0, NAME, "version = 5.10"))
        with open(s.path("co.ini"), "w") as f:
            # Nobody listens to its LCM group; all its messages are off anyway.
            f.write(co_config(sim.port, "udpm://239.255.76.67:%d?ttl=0" % free_udp_port(), co.path, t0))
        with open(s.path("rtde-gw.ini"), "w") as f:
            f.write(config(rsim.port, rurl, rcan.path, t0, NAME + "rtde", "source = rtde"))

        def begin(name, rname):
            start = now_us()
            for log, n in ((can, name), (co, name), (rcan, rname)):
                log.phase(n, start)
            for c, n in ((checker, name), (rchecker, rname)):
                c.stdin.write("phase %s %d\n" % (n, start))
                c.stdin.flush()

        begin(PHASES[0][0], RTDE_PHASES[0][0])
        gws["can"] = s.start([args.gateway, s.path("gw.ini")], "gw.log")
        gws["canopen"] = s.start([args.gateway, s.path("co.ini")], "co-gw.log")
        gws["rtde"] = s.start([args.gateway, s.path("rtde-gw.ini")], "rtde-gw.log")
        n = 0
        while time.monotonic() < deadline:
            name, extra = PHASES[n % len(PHASES)]
            rname, rextra = RTDE_PHASES[n % len(RTDE_PHASES)]
            if n > 0:
                co.end_phase(now_us())
                sim.stop()
                rsim.stop()
                begin(name, rname)
                sim.start(extra)
                rsim.start(rextra)
            phase0 = time.monotonic()
            end = min(phase0 + args.phase_seconds, deadline)
            next_kill = phase0 + RESTART_UP_S
            stop_at, cont_at = phase0 + BACKLOG_STOP[0], phase0 + BACKLOG_STOP[1]
            sched.begin({"can gateway": gws["can"], "canopen gateway": gws["canopen"], "rtde gateway": gws["rtde"],
                         "simulator": sim.proc, "rtde simulator": rsim.proc, "checker": checker,
                         "soak.py": os.getpid()})
            while time.monotonic() < end:
                for key, g in gws.items():
                    if g.poll() is not None:
                        raise RuntimeError("the %s gateway exited (%s) in phase %s" % (key, g.returncode, name))
                now = time.monotonic()
                if rname == "backlog" and stop_at is not None and now >= stop_at:
                    gws["rtde"].send_signal(signal.SIGSTOP)   # a reader that stops reading
                    stops.append([now_us(), None])
                    stop_at = None
                elif rname == "backlog" and stop_at is None and stops[-1][1] is None and now >= cont_at:
                    gws["rtde"].send_signal(signal.SIGCONT)
                    stops[-1][1] = now_us()
                restarting = [x for x, nm in ((sim, name), (rsim, rname)) if nm == "restart"]
                # The last kill leaves a second for the gateway to be back before the phase ends.
                if restarting and now >= next_kill and now + RESTART_DOWN_S + 1.0 < end:
                    for x in restarting:
                        x.stop(signal.SIGKILL)
                        x.kills += 1
                    time.sleep(RESTART_DOWN_S)  # the stimulus: how long the controller is gone
                    for x in restarting:
                        x.start([])
                    next_kill = time.monotonic() + RESTART_UP_S
                can.read()
                rcan.read()
                co.read()
                time.sleep(0.05)
            if stops and stops[-1][1] is None:        # a phase cut short by the deadline
                gws["rtde"].send_signal(signal.SIGCONT)
                stops[-1][1] = now_us()
            sched.end(name if name == rname else "%s/%s" % (name, rname))
            n += 1
            for key, g in gws.items():
                rss, fds = proc_sample(g.pid)
                samples[key].append((n, name, rss, fds))
                if n % len(PHASES) == 0 or n == warm_phases:
                    print("soak: after phase %d (%s, pass %d): %s gateway RSS %d KiB, %d fds" %
                          (n, name, (n - 1) // len(PHASES) + 1, key, rss, fds))
            sys.stdout.flush()
        end_us = now_us()
        co.end_phase(end_us)
        sim.stop()
        rsim.stop()
        for c in (checker, rchecker):
            c.stdin.write("end %d\n" % now_us())
            c.stdin.flush()
        for c in (checker, rchecker):
            c.wait(timeout=WAIT)
        exits = {}
        for key, g in gws.items():
            alive = g.poll() is None
            g.send_signal(signal.SIGTERM)
            exits[key] = (alive, g.wait(timeout=WAIT))
        can.read()
        rcan.read()
        co.read()
        co.finish(end_us)
        if vm is not None:
            wait_plc_vm(vm)
    finally:
        for g in gws.values():
            if g.poll() is None:
                g.send_signal(signal.SIGCONT)
        s.stop_all()
        if vm is not None and vm.poll() is None:   # the soak broke off: so does the VM
            os.killpg(vm.pid, signal.SIGTERM)
            vm.wait()
    for line in sched.lines:
        print(line)
    plc_ok = report_plc_vm(args, s, vm)
    ok = report(s, can, rcan, co, (sim, rsim), samples, warm_phases, exits, stops)
    if ok and plc_ok:
        subprocess.run(["rm", "-rf", s.dir])
    else:
        print("soak: files kept in %s" % s.dir)


def start_plc_vm(args, s):
    """The RTDE robot and its PLC (tests/soak/soak_plc.py) in the qemu VM, for the
    soak's minutes, at the lowest CPU priority: the VM's emulated CPU takes one of
    the host's cores when it can, never a moment from the host's soak."""
    if not args.plc_vm:
        print("soak: the RTDE robot and its PLC (the VM) left out (--no-plc-vm)")
        return None
    here = os.path.dirname(os.path.abspath(__file__))
    files = [args.python_stage, os.path.join(args.build, "bin", "urrt-sim"), os.path.join(args.build, "bin", "urrt-gateway"),
             os.path.join(here, "soak_plc.py"), os.path.join(here, "..", "canopen", "master.py"),
             os.path.join(here, "..", "canopen", "eds.py")]
    argv = ["nice", "-n", "19", os.path.join(here, "..", "vm", "run.sh"), "--quiet", "--out", s.path("vm"),
            "--script", os.path.join(here, "soak_plc.sh"), "--vcan", "vcan0:16",
            "--timeout", str(int(args.minutes * 60 + PLC_VM_SPARE_S)),
            "--env", "SOAK_MINUTES=%g" % args.minutes, "--env", "SOAK_PHASE_SECONDS=%d" % args.phase_seconds,
            "--files", " ".join(files)]
    return subprocess.Popen(argv, stdout=open(s.path("vm.log"), "w"), stderr=subprocess.STDOUT,
                            start_new_session=True)


def wait_plc_vm(vm):
    """The VM ends by itself, its minutes being the host's, once its judge is done
    (run.sh bounds it too)."""
    try:
        vm.wait(timeout=PLC_VM_SPARE_S + 60)
    except subprocess.TimeoutExpired:
        pass


def report_plc_vm(args, s, vm):
    """Prints the VM's tables and checks and counts them; True when all passed."""
    if vm is None:
        return True
    print("\n---- the RTDE robot and its PLC, in the VM (tests/soak/soak_plc.py)")
    try:
        lines = open(s.path("vm/script.log"), errors="replace").read().splitlines()
    except OSError:
        lines = []
    for line in lines:
        print(line)
    last = lines[-1].split() if lines else []
    if len(last) == 4 and last[1] == "passed," and last[3] == "failed":
        suite.passed += int(last[0])
        suite.failed += int(last[2])
        print("---- (the VM's checks are counted with the host's)\n")
        return last[2] == "0"
    check(False, "the VM's soak gave no result line (exit %s; %s)" %
          (vm.returncode, open(s.path("vm.log"), errors="replace").read().strip()[-400:]))
    return False


def report(s, can, rcan, co, sims, samples, warm_phases, exits, stops):
    report_robot("the RealTime robot", "", s.path("lcm.out"), can, PHASES, [])
    report_robot("the RTDE robot", "RTDE robot: ", s.path("rtde-lcm.out"), rcan, RTDE_PHASES, stops)
    print("simulators: %s" % "; ".join(x.summary() for x in sims))
    print("RTDE robot: the gateway stopped (SIGSTOP) %d times for %.1f s each in the backlog phase" %
          (len(stops), (BACKLOG_STOP[1] - BACKLOG_STOP[0])))
    print()
    for key, (alive, rc) in sorted(exits.items()):
        check(alive and rc == 0, "the %s gateway ran through every phase and exited 0 on SIGTERM (rc %s)" % (key, rc))
    report_canopen(co)
    for key in ("can", "canopen", "rtde"):
        check_growth(key, samples[key], warm_phases)
    return suite.failed == 0


def report_robot(title, label, lcm_path, can, phases, stops):
    """One robot's table and judgements: its LCM checker's facts, its CAN log.
    Heartbeat gaps that span a stop of the gateway (stops, us) are not judged."""
    def rcheck(ok, what):
        check(ok, label + what)
    lcm_out = open(lcm_path).read().splitlines()
    for line in lcm_out:
        if line.startswith(("stale ", "lie ", "undecodable ")):
            print(label + "lcm: " + line)
    lcm_phases = [l.split() for l in lcm_out if l.startswith("phase ")]
    by_name = {}
    order = []
    for f in lcm_phases:
        name = f[2]
        kv = dict(zip(f[3::2], f[4::2]))
        if name == "start" and all(int(kv[k]) == 0 for k in ("state", "joints", "tool", "status", "gateway")):
            continue
        if name not in by_name:
            order.append(name)
            by_name[name] = {"n": 0, "state": 0, "joints": 0, "tool": 0, "status": 0, "gateway": 0,
                             "oldest_us": 0, "stale": 0, "lies": 0, "frames": {}, "can_oldest": {},
                             "can_stale": 0, "invalid": 0, "hb_lies": 0}
        a = by_name[name]
        a["n"] += 1
        for k in ("state", "joints", "tool", "status", "gateway", "stale", "lies"):
            a[k] += int(kv[k])
        a["oldest_us"] = max(a["oldest_us"], int(kv["oldest_us"]))
    for p in can.phases:
        a = by_name.get(p.name)
        if a is None:
            continue
        for i, c in p.frames.items():
            a["frames"][i] = a["frames"].get(i, 0) + c
        for i, o in p.oldest_us.items():
            a["can_oldest"][i] = max(a["can_oldest"].get(i, o), o)
        a["can_stale"] += sum(p.stale.values())
        a["invalid"] += p.invalid
        a["hb_lies"] += p.hb_lies
    print("\n%s, per fault phase (summed over passes): LCM messages, CAN frames, oldest data age (ms)" % title)
    print("%-13s %3s %8s %8s %8s %6s %6s %7s | %7s %6s %6s %5s %4s %7s %7s %7s" %
          ("phase", "n", "STATE", "JOINTS", "TOOL", "STATUS", "GW", "lcm_old", "0x181", "0x182", "0x183", "inv",
           "hb", "old181", "old182", "old183"))
    for name in order:
        a = by_name[name]
        fr, od = a["frames"], a["can_oldest"]
        print("%-13s %3d %8d %8d %8d %6d %6d %7.1f | %7d %6d %6d %5d %4d %7.1f %7.1f %7.1f" %
              (name, a["n"], a["state"], a["joints"], a["tool"], a["status"], a["gateway"], a["oldest_us"] / 1e3,
               fr.get(CAN_EVERY, 0), fr.get(CAN_FAST, 0), fr.get(CAN_INVALID, 0), a["invalid"],
               fr.get(CAN_HEARTBEAT, 0), od.get(CAN_EVERY, 0) / 1e3, od.get(CAN_FAST, 0) / 1e3,
               od.get(CAN_INVALID, 0) / 1e3))
    for line in lcm_out:
        if line.startswith("report "):
            print(label + "gateway's final report (for reference, not judged): " + line[7:])
    data_names = [n for n in order]
    rcheck(set(n for n, _ in phases) <= set(data_names) and
          all(by_name[n]["state"] > 0 and by_name[n]["frames"].get(CAN_EVERY, 0) > 0 for n in data_names),
          "every fault phase ran and delivered LCM messages and CAN frames (%d phases)" % len(data_names))
    stale = sum(a["stale"] for a in by_name.values())
    oldest = max((a["oldest_us"] for a in by_name.values()), default=0)
    total = sum(a[k] for a in by_name.values() for k in ("state", "joints", "tool", "status"))
    rcheck(total > 0 and stale == 0, "LCM: none of %d data messages older than %d ms + %d ms when received "
          "(%d are; oldest %.1f ms)" % (total, BOUND_MS, MARGIN_MS, stale, oldest / 1e3))
    lies = sum(a["lies"] for a in by_name.values())
    reports = sum(a["gateway"] for a in by_name.values())
    rcheck(reports > 0 and lies == 0, "LCM: no GATEWAY report of %d says fresh while the newest data is older than "
          "%d ms + %d ms (%d do)" % (reports, BOUND_MS, MARGIN_MS, lies))
    delivery = [l.split() for l in lcm_out if l.startswith("delivery ")]
    rcheck(len(delivery) == 4 and all(f[3] == f[5] for f in delivery),
          "LCM: the checker received exactly what the gateway published (%s)" %
          ", ".join("%s %s of %s" % (f[1], f[3], f[5]) for f in delivery))
    for ident in (CAN_EVERY, CAN_FAST, CAN_INVALID):
        n = sum(a["frames"].get(ident, 0) for a in by_name.values())
        judged = n - (sum(a["invalid"] for a in by_name.values()) if ident == CAN_INVALID else 0)
        old = max((a["can_oldest"].get(ident, 0) for a in by_name.values()), default=0)
        st = sum(p.stale.get(ident, 0) for p in can.phases)
        rcheck(judged > 0 and st == 0, "CAN 0x%X: none of %d frames%s older than %d ms + %d ms when written "
              "(%d are; oldest %.1f ms)" % (ident, judged, " with valid = 1" if ident == CAN_INVALID else "",
                                            CAN_BOUND_MS[ident], MARGIN_MS, st, old / 1e3))
    hb_lies = sum(p.hb_lies for p in can.phases)
    rcheck(hb_lies == 0, "CAN heartbeat: never OK while the newest data sent is older than %d ms + %d ms (%d are)" %
          (BOUND_MS, MARGIN_MS, hb_lies))
    judged = [b - a for a, b in can.hb_gaps if not any(a < t1 and b > t0 for t0, t1 in stops)]
    longest = max(judged, default=0)
    rcheck(0 < longest <= 1000000, "CAN heartbeat: at least once a second (longest gap %.1f ms%s)" %
           (longest / 1e3, "; %d gaps across the gateway's stops not judged" % (len(can.hb_gaps) - len(judged))
            if stops else ""))
    rcheck(can.alive_breaks == 0 and can.bad_lines == 0,
          "CAN log: every line parses, 0x182's alive counter steps by 1 (%d breaks, %d bad lines)" %
          (can.alive_breaks, can.bad_lines))


def report_canopen(co):
    """The CANopen node's table and judgements."""
    print("\nCANopen node %d, per fault phase (summed over passes): frames; EMCYs raised from the phase's "
          "first data to its end / reset; oldest data age with valid = 1 (ms)" % CO_NODE)
    print("%-13s %3s %7s %6s %6s %5s %4s %9s %9s %7s %7s" % ("phase", "n", "0x%X" % CO_TPDO_INVALID, "inv",
          "0x%X" % CO_TPDO_STOP, "emcy", "hb", "FF01", "FF02", "old%X" % CO_TPDO_INVALID, "old%X" % CO_TPDO_STOP))
    order = []
    for p in co.phases:
        if p.name not in order:
            order.append(p.name)
    for name in order:
        runs = [p for p in co.phases if p.name == name]

        def total(attr, key):
            return sum(getattr(p, attr).get(key, 0) for p in runs)

        def oldest(ident):
            return max((p.oldest_us.get(ident, 0) for p in runs), default=0) / 1e3
        print("%-13s %3d %7d %6d %6d %5d %4d %4d/%-4d %4d/%-4d %7.1f %7.1f" %
              (name, len(runs), total("frames", CO_TPDO_INVALID), total("invalid", CO_TPDO_INVALID),
               total("frames", CO_TPDO_STOP), total("frames", CO_EMCY), total("frames", CO_HEARTBEAT),
               total("raised", EMCY_LINK), total("resets", EMCY_LINK), total("raised", EMCY_STALE),
               total("resets", EMCY_STALE), oldest(CO_TPDO_INVALID), oldest(CO_TPDO_STOP)))
    print("(%d TPDOs before the first data, not judged)\n" % co.before_data)
    v = co.violations
    check(all(p.first_data_us is not None for p in co.phases),
          "CANopen: TPDOs with valid = 1 in every phase run (%d of %d)" %
          (sum(p.first_data_us is not None for p in co.phases), len(co.phases)))
    for ident in (CO_TPDO_INVALID, CO_TPDO_STOP):
        n = sum(p.frames.get(ident, 0) - p.invalid.get(ident, 0) for p in co.phases)
        old = max((p.oldest_us.get(ident, 0) for p in co.phases), default=0)
        check(n > 0 and v.get("valid_stale_%X" % ident, 0) == 0 and (ident != CO_TPDO_INVALID or v.get("alive", 0) == 0),
              "CANopen TPDO 0x%X: none of %d frames with valid = 1 older than %d ms + %d ms (%d frames with "
              "valid = 0; oldest valid %.1f ms%s)" %
              (ident, n, BOUND_MS, MARGIN_MS, sum(p.invalid.get(ident, 0) for p in co.phases), old / 1e3,
               "; alive counter breaks %d" % v.get("alive", 0) if ident == CO_TPDO_INVALID else ""))
    missing = ["%s (pass %d) 0x%04X" % (p.name, i // len(PHASES) + 1, code) for i, p in enumerate(co.phases)
               for code in EXPECTED_EMCY.get(p.name, ()) if p.raised.get(code, 0) == 0]
    check(not missing, "CANopen EMCY: each stall and freeze raises 0xFF02, each drop of the link 0xFF01, between the "
          "phase's first data and its end (%d raised; missing: %s)" %
          (sum(sum(p.raised.values()) for p in co.phases), ", ".join(missing) or "none"))
    raised = sum(p.frames.get(CO_EMCY, 0) for p in co.phases)
    check(raised > 0 and all(v.get(r, 0) == 0 for r in ("emcy", "raise_early", "never_reset", "unexpected")),
          "CANopen EMCY: only 0xFF01/0xFF02, each raised once and reset after, 0xFF02 only on data older than "
          "%d ms - %d ms (%d EMCY frames; %d malformed or doubled, %d early, %d never reset, %d other frames)" %
          (BOUND_MS, MARGIN_MS, raised, v.get("emcy", 0), v.get("raise_early", 0), v.get("never_reset", 0),
           v.get("unexpected", 0)))
    check(v.get("reset_early", 0) == 0,
          "CANopen EMCY: 0xFF01 reset only once new data flows (the next TPDO1 carries data newer than the link's "
          "loss), 0xFF02 only on fresh data or handed over to 0xFF01 (%d are not)" % v.get("reset_early", 0))
    check(v.get("stale_silent", 0) == 0, "CANopen EMCY: 0xFF01 or 0xFF02 set whenever TPDO1's data is older than "
          "%d ms + %d ms (%d TPDO1s without)" % (BOUND_MS, MARGIN_MS, v.get("stale_silent", 0)))
    check(co.hb_boot == 1 and co.hb_count > 1 and v.get("hb_state", 0) == 0 and v.get("hb_gap", 0) == 0 and
          co.bad_lines == 0,
          "CANopen heartbeat 0x%X: boot-up then OPERATIONAL (05) every %d ms, no gap over %d ms (%d beats, %d "
          "boot-up, %d in another state, longest gap %.1f ms; %d bad lines)" %
          (CO_HEARTBEAT, CO_HB_MS, CO_HB_MS * 3 // 2, co.hb_count, co.hb_boot, v.get("hb_state", 0),
           co.max_hb_gap_us / 1e3, co.bad_lines))


def check_growth(key, samples, warm_phases):
    """The gateway's RSS and descriptors from after the warm-up to the end."""
    if len(samples) <= warm_phases:
        check(False, "%s gateway's RSS and fds: the soak was too short to sample after the warm-up" % key)
        return
    _, wname, rss0, fd0 = samples[warm_phases - 1]
    _, _, rss1, fd1 = samples[-1]
    peak = max(x[2] for x in samples[warm_phases - 1:])
    print("%s gateway RSS: start %d KiB (after phase %d, %s), end %d KiB, peak %d KiB; fds: start %d, end %d" %
          (key, rss0, warm_phases, wname, rss1, peak, fd0, fd1))
    check(rss1 <= rss0 + RSS_ALLOWANCE_KIB, "%s gateway RSS does not grow: start %d KiB, end %d KiB "
          "(allowed +%d KiB)" % (key, rss0, rss1, RSS_ALLOWANCE_KIB))
    check(fd1 <= fd0 + FD_ALLOWANCE, "%s gateway fds do not grow: start %d, end %d (allowed +%d)" %
          (key, fd0, fd1, FD_ALLOWANCE))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--minutes", type=float, default=10)
    ap.add_argument("--phase-seconds", type=int, default=10)
    ap.add_argument("--result")
    ap.add_argument("--phases", help="only these phases, comma-separated (a quick look at one fault)")
    ap.add_argument("--python-stage", help="Python with python3-can for the VM (tests/canopen/stage-python.sh)")
    ap.add_argument("--no-plc-vm", dest="plc_vm", action="store_false",
                    help="leave out the RTDE robot and its PLC in the VM (tests/soak/soak_plc.py)")
    args = ap.parse_args()
    if args.plc_vm and not args.python_stage:
        ap.error("--python-stage DIR is needed for the VM's part (or --no-plc-vm)")
    if args.phases:
        wanted = args.phases.split(",")
        known = [name for name, _ in PHASES + RTDE_PHASES]
        unknown = [p for p in wanted if p not in known]
        if unknown:
            print("soak: no phase %s (phases: %s)" % (", ".join(unknown), ", ".join(dict.fromkeys(known))))
            return 2
        # Each robot runs the phases of its own list that are named, else its clean one.
        for lst in (PHASES, RTDE_PHASES):
            lst[:] = [ph for ph in lst if ph[0] in wanted] or [lst[0]]
    args.gateway = os.path.join(args.build, "bin", "urrt-gateway")
    args.sim = os.path.join(args.build, "bin", "urrt-sim")
    args.checker = os.path.join(args.build, "tests", "soak", "soak_lcm")
    # The stimulus and the judge run under SCHED_FIFO, the gateway as usual: a
    # simulator starved of CPU sends late (its time column is the scheduled
    # instant), and a starved checker receives late and loses datagrams; on a
    # busy machine both would be charged to the gateway.
    rt = subprocess.run(["chrt", "-f", "1", "true"], capture_output=True).returncode == 0
    args.sim_rt = ["--rt-priority", str(RT_PRIORITY)] if rt else []
    args.checker_rt = ["chrt", "-f", str(RT_PRIORITY)] if rt else []
    print("soak: simulators and checkers %s" % ("under SCHED_FIFO %d" % RT_PRIORITY if rt else
          "at normal priority (no CAP_SYS_NICE): their own delays count as the gateway's"))
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGHUP, on_signal)
    try:
        run(args)
    except Exception as e:  # a broken soak is a failure, reported as one
        check(False, "soak: %r" % e)
    except KeyboardInterrupt as e:
        check(False, "soak interrupted (%s)" % e)
    status = suite.report()
    if args.result:
        with open(args.result, "w") as f:
            f.write("%d passed, %d failed\n" % (suite.passed, suite.failed))
    return status


if __name__ == "__main__":
    sys.exit(main())
