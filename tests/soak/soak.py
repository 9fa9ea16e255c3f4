#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""make soak: one urrt-gateway, many urrt-sim fault modes, an independent judge.

One gateway runs for the whole soak with an LCM output and a CAN output to a
candump log. urrt-sim serves it on one port, restarted for each phase with
the next fault mode (and, in the restart phase, killed and restarted every
couple of seconds). Every packet carries the wall clock at its scheduled send
instant (--clock realtime), so each message's and frame's data age is known
without asking the gateway:

- LCM: soak_lcm (C) receives every message; age = LCM's recv_utime (kernel
  receive time) - the time column.
- CAN: this script reads the log as it grows (the gateway writes each line
  with write(2), unbuffered, stamped with the wall clock just before the
  write); age = the line's stamp - the simulator's time recovered from the
  payload (0x181: the time column as a float64, exact; 0x182 and 0x183: ms
  since the soak's start, 32 bits, +-0.5 ms).

Usage: soak.py --build DIR [--minutes N] [--phase-seconds S] [--result FILE]
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
    ("tiny-writes", ["--fault", "tiny-writes=7"]),
    ("coalesce", ["--fault", "coalesce=4"]),
    ("odd-length", ["--fault", "odd-length=200"]),
    ("restart", []),
]
RESTART_UP_S, RESTART_DOWN_S = 2.0, 0.3

CAN_EVERY, CAN_FAST, CAN_INVALID, CAN_HEARTBEAT = 0x181, 0x182, 0x183, 0x701
CAN_BOUND_MS = {CAN_EVERY: BOUND_MS, CAN_FAST: FAST_BOUND_MS, CAN_INVALID: BOUND_MS}

PASSED = 0
FAILED = 0


def check(cond, what):
    global PASSED, FAILED
    if cond:
        PASSED += 1
        print("ok: " + what)
    else:
        FAILED += 1
        print("FAIL: " + what)
    sys.stdout.flush()
    return cond


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


def config(port, url, log, t0):
    return """[lcm]
url = {url}
status_rate = 10 Hz
gateway_rate = 10 Hz

[robot {name}]
host = 127.0.0.1
port = {port}
version = 5.10
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
""".format(url=url, name=NAME, port=port, bound=BOUND_MS, log=log, hb=CAN_HEARTBEAT, every=CAN_EVERY,
           fast=CAN_FAST, fast_bound=FAST_BOUND_MS, t0=t0, inv=CAN_INVALID)


NAME = "soak%d" % os.getpid()


class PhaseStats:
    def __init__(self, name, start_us):
        self.name, self.start_us = name, start_us
        self.frames = {}         # id -> count
        self.oldest_us = {}      # id -> oldest data age
        self.stale = {}          # id -> frames older than their bound
        self.invalid = 0         # 0x183 frames with valid = 0 (not judged)
        self.hb_lies = 0


class CanLog:
    """Reads the candump log as it grows and judges each line."""

    def __init__(self, path, t0):
        self.path, self.t0 = path, t0
        self.offset = 0
        self.newest_stamp_us = 0       # newest simulator time carried by a data frame so far
        self.last_hb_us = None
        self.max_hb_gap_us = 0
        self.alive = None              # 0x182's last alive counter
        self.alive_breaks = 0
        self.bad_lines = 0
        self.reported = 0
        self.phases = []

    def phase(self, name, start_us):
        self.phases.append(PhaseStats(name, start_us))

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
            print("can: " + text)
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
        if ident == CAN_HEARTBEAT:
            self._heartbeat(p, t_us, data)
            return
        if ident == CAN_EVERY:
            sim_us = round(struct.unpack("<d", data)[0] * 1e6)
        elif ident in (CAN_FAST, CAN_INVALID):
            raw = struct.unpack("<I", data[:4])[0]
            sim_us = self.t0 * 1000000 + raw * 1000
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
            self.max_hb_gap_us = max(self.max_hb_gap_us, t_us - self.last_hb_us)
        self.last_hb_us = t_us
        # state 1 (OK) says the data is fresh: the newest data sent must say so too.
        if data[0] & 0xF == 1 and t_us - self.newest_stamp_us > (BOUND_MS + MARGIN_MS) * 1000:
            p.hb_lies += 1
            self._report("heartbeat OK at %d while the newest data sent is %.1f ms old (%s)" %
                         (t_us, (t_us - self.newest_stamp_us) / 1e3, p.name))


def proc_sample(pid):
    """(RSS in KiB, open descriptors) of a process."""
    with open("/proc/%d/status" % pid) as f:
        rss = next(int(l.split()[1]) for l in f if l.startswith("VmRSS:"))
    return rss, len(os.listdir("/proc/%d/fd" % pid))


class Soak:
    def __init__(self, args):
        self.args = args
        self.dir = tempfile.mkdtemp(prefix="soak-")
        self.procs = []
        self.sim = None
        self.port = 0
        self.sim_starts = 0
        self.sim_kills = 0
        self.bind_retries = 0

    def path(self, name):
        return os.path.join(self.dir, name)

    def start(self, argv, log, **kw):
        p = subprocess.Popen(argv, stdout=kw.pop("stdout", None) or open(self.path(log), "a"),
                             stderr=subprocess.STDOUT, **kw)
        self.procs.append(p)
        return p

    def start_sim(self, extra):
        """urrt-sim on self.port (0 the first time: one from the system). The port
        can be taken meanwhile (by an outgoing connection's local port, the
        gateway's own among them): retried until it binds, within WAIT."""
        end = time.monotonic() + WAIT
        while True:
            port_file = self.path("sim.port")
            if os.path.exists(port_file):
                os.unlink(port_file)
            p = self.start([self.args.sim, "--listen", "127.0.0.1:%d" % self.port, "--port-file", port_file,
                            "--version", "5.10", "--clock", "realtime", "--seed", str(self.sim_starts), "-q"] +
                           self.args.sim_rt + extra, "sim.log")
            self.sim_starts += 1
            wait_for(lambda: os.path.exists(port_file) or p.poll() is not None, WAIT)
            if os.path.exists(port_file):
                self.port = int(open(port_file).read())
                self.sim = p
                return
            p.wait()
            if time.monotonic() > end:
                raise RuntimeError("urrt-sim cannot listen on port %d" % self.port)
            self.bind_retries += 1
            time.sleep(0.1)

    def stop_sim(self, sig=signal.SIGTERM):
        if self.sim is not None:
            self.sim.send_signal(sig)
            self.sim.wait(timeout=WAIT)
            self.sim = None

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


def run(args):
    s = Soak(args)
    t0 = int(time.time())
    log = s.path("can.log")
    can = CanLog(log, t0)
    url = "udpm://239.255.76.67:%d?ttl=0" % free_udp_port()
    deadline = time.monotonic() + args.minutes * 60
    cycle_s = len(PHASES) * args.phase_seconds
    cycles = max(1, int(args.minutes * 60 // cycle_s))
    # Warm-up: the first pass of every fault when there is room for another,
    # else the first phase; RSS and descriptors are compared from there.
    warm_phases = len(PHASES) if args.minutes * 60 >= 2 * cycle_s else 1
    print("soak: %.1f min, %d phases of %d s (%d s per pass, %d passes), bound %d ms (+%d ms margin), dir %s" %
          (args.minutes, len(PHASES), args.phase_seconds, cycle_s, cycles, BOUND_MS, MARGIN_MS, s.dir))
    samples = []
    gw = checker = None
    try:
        s.start_sim(PHASES[0][1])
        ready = s.path("lcm.ready")
        checker = subprocess.Popen(args.checker_rt + [args.checker, url + CHECKER_URL_OPTIONS, NAME, str(BOUND_MS * 1000), str(MARGIN_MS * 1000), ready],
                                   stdin=subprocess.PIPE, stdout=open(s.path("lcm.out"), "w"),
                                   stderr=open(s.path("lcm.err"), "w"), text=True)
        s.procs.append(checker)
        if not wait_for(lambda: os.path.exists(ready) or checker.poll() is not None, WAIT) or checker.poll() is not None:
            raise RuntimeError("soak_lcm did not start: %s" % open(s.path("lcm.err")).read())
        with open(s.path("gw.ini"), "w") as f:
            f.write(config(s.port, url, log, t0))

        def begin(name):
            start = now_us()
            can.phase(name, start)
            checker.stdin.write("phase %s %d\n" % (name, start))
            checker.stdin.flush()

        begin(PHASES[0][0])
        gw = s.start([args.gateway, s.path("gw.ini")], "gw.log")
        n = 0
        while time.monotonic() < deadline:
            name, extra = PHASES[n % len(PHASES)]
            if n > 0:
                s.stop_sim()
                begin(name)
                s.start_sim(extra)
            end = min(time.monotonic() + args.phase_seconds, deadline)
            next_kill = time.monotonic() + RESTART_UP_S
            while time.monotonic() < end:
                if gw.poll() is not None:
                    raise RuntimeError("urrt-gateway exited (%s) in phase %s" % (gw.returncode, name))
                if name == "restart" and time.monotonic() >= next_kill:
                    s.stop_sim(signal.SIGKILL)
                    s.sim_kills += 1
                    time.sleep(RESTART_DOWN_S)  # the stimulus: how long the controller is gone
                    s.start_sim([])
                    next_kill = time.monotonic() + RESTART_UP_S
                can.read()
                time.sleep(0.05)
            n += 1
            rss, fds = proc_sample(gw.pid)
            samples.append((n, name, rss, fds))
            if n % len(PHASES) == 0 or n == warm_phases:
                print("soak: after phase %d (%s, pass %d): gateway RSS %d KiB, %d fds" %
                      (n, name, (n - 1) // len(PHASES) + 1, rss, fds))
                sys.stdout.flush()
        s.stop_sim()
        checker.stdin.write("end %d\n" % now_us())
        checker.stdin.flush()
        checker.wait(timeout=WAIT)
        alive = gw.poll() is None
        gw.send_signal(signal.SIGTERM)
        gw_rc = gw.wait(timeout=WAIT)
        can.read()
    finally:
        s.stop_all()
    if report(s, can, samples, warm_phases, alive, gw_rc):
        subprocess.run(["rm", "-rf", s.dir])
    else:
        print("soak: files kept in %s" % s.dir)


def report(s, can, samples, warm_phases, alive, gw_rc):
    lcm_out = open(s.path("lcm.out")).read().splitlines()
    for line in lcm_out:
        if line.startswith(("stale ", "lie ", "undecodable ")):
            print("lcm: " + line)
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
    print("\nper fault phase (summed over passes): LCM messages, CAN frames, oldest data age (ms)")
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
            print("gateway's final report (for reference, not judged): " + line[7:])
    print("simulator: %d starts, %d killed, %d binds retried" % (s.sim_starts, s.sim_kills, s.bind_retries))
    print()
    check(alive and gw_rc == 0, "the gateway ran through every phase and exited 0 on SIGTERM (rc %s)" % gw_rc)
    data_names = [n for n in order]
    check(set(n for n, _ in PHASES) <= set(data_names) and
          all(by_name[n]["state"] > 0 and by_name[n]["frames"].get(CAN_EVERY, 0) > 0 for n in data_names),
          "every fault phase ran and delivered LCM messages and CAN frames (%d phases)" % len(data_names))
    stale = sum(a["stale"] for a in by_name.values())
    oldest = max((a["oldest_us"] for a in by_name.values()), default=0)
    total = sum(a[k] for a in by_name.values() for k in ("state", "joints", "tool", "status"))
    check(total > 0 and stale == 0, "LCM: none of %d data messages older than %d ms + %d ms when received "
          "(%d are; oldest %.1f ms)" % (total, BOUND_MS, MARGIN_MS, stale, oldest / 1e3))
    lies = sum(a["lies"] for a in by_name.values())
    reports = sum(a["gateway"] for a in by_name.values())
    check(reports > 0 and lies == 0, "LCM: no GATEWAY report of %d says fresh while the newest data is older than "
          "%d ms + %d ms (%d do)" % (reports, BOUND_MS, MARGIN_MS, lies))
    delivery = [l.split() for l in lcm_out if l.startswith("delivery ")]
    check(len(delivery) == 4 and all(f[3] == f[5] for f in delivery),
          "LCM: the checker received exactly what the gateway published (%s)" %
          ", ".join("%s %s of %s" % (f[1], f[3], f[5]) for f in delivery))
    for ident in (CAN_EVERY, CAN_FAST, CAN_INVALID):
        n = sum(a["frames"].get(ident, 0) for a in by_name.values())
        judged = n - (sum(a["invalid"] for a in by_name.values()) if ident == CAN_INVALID else 0)
        old = max((a["can_oldest"].get(ident, 0) for a in by_name.values()), default=0)
        st = sum(p.stale.get(ident, 0) for p in can.phases)
        check(judged > 0 and st == 0, "CAN 0x%X: none of %d frames%s older than %d ms + %d ms when written "
              "(%d are; oldest %.1f ms)" % (ident, judged, " with valid = 1" if ident == CAN_INVALID else "",
                                            CAN_BOUND_MS[ident], MARGIN_MS, st, old / 1e3))
    hb_lies = sum(p.hb_lies for p in can.phases)
    check(hb_lies == 0, "CAN heartbeat: never OK while the newest data sent is older than %d ms + %d ms (%d are)" %
          (BOUND_MS, MARGIN_MS, hb_lies))
    check(0 < can.max_hb_gap_us <= 1000000, "CAN heartbeat: at least once a second (longest gap %.1f ms)" %
          (can.max_hb_gap_us / 1e3))
    check(can.alive_breaks == 0 and can.bad_lines == 0,
          "CAN log: every line parses, 0x182's alive counter steps by 1 (%d breaks, %d bad lines)" %
          (can.alive_breaks, can.bad_lines))
    if len(samples) > warm_phases:
        _, wname, rss0, fd0 = samples[warm_phases - 1]
        _, _, rss1, fd1 = samples[-1]
        peak = max(x[2] for x in samples[warm_phases - 1:])
        print("gateway RSS: start %d KiB (after phase %d, %s), end %d KiB, peak %d KiB; fds: start %d, end %d" %
              (rss0, warm_phases, wname, rss1, peak, fd0, fd1))
        check(rss1 <= rss0 + RSS_ALLOWANCE_KIB, "gateway RSS does not grow: start %d KiB, end %d KiB "
              "(allowed +%d KiB)" % (rss0, rss1, RSS_ALLOWANCE_KIB))
        check(fd1 <= fd0 + FD_ALLOWANCE, "gateway fds do not grow: start %d, end %d (allowed +%d)" %
              (fd0, fd1, FD_ALLOWANCE))
    else:
        check(False, "RSS and fds: the soak was too short to sample after the warm-up")
    return FAILED == 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--minutes", type=float, default=10)
    ap.add_argument("--phase-seconds", type=int, default=10)
    ap.add_argument("--result")
    args = ap.parse_args()
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
    print("soak: simulator and checker %s" % ("under SCHED_FIFO %d" % RT_PRIORITY if rt else
          "at normal priority (no CAP_SYS_NICE): their own delays count as the gateway's"))
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGHUP, on_signal)
    try:
        run(args)
    except Exception as e:  # a broken soak is a failure, reported as one
        check(False, "soak: %r" % e)
    except KeyboardInterrupt as e:
        check(False, "soak interrupted (%s)" % e)
    line = "%d passed, %d failed" % (PASSED, FAILED)
    print(line)
    if args.result:
        with open(args.result, "w") as f:
            f.write(line + "\n")
    return 0 if FAILED == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
