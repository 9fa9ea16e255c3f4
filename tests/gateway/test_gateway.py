#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-gateway: urrt-gateway against urrt-sim, seen through LCM.

The subscriber (lcm_sub) decodes every message with the generated C types
and prints it as JSON; the expectations come from the simulator's --record
capture decoded here with the independent reference (tests/ref/urrt_ref.py),
matched by controller time.

No test waits for a sleep to be long enough: each waits for the messages it
needs (bounded, so a hang fails instead of blocking), and every process
started is stopped. Ports come from the system: the simulator listens on
port 0 and writes the port it got (--port-file), and each test publishes on
its own LCM UDP port. Robot names (channel prefixes) carry the PID too.

Ages are measured independently of the gateway: the simulator stamps each
packet with the wall clock (--clock realtime), LCM stamps each message with
the kernel's receive time (recv_utime), and the difference is how old the
data was when it reached the subscriber.

Usage: test_gateway.py --build DIR [--only NAME]
"""
import argparse
import json
import math
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "ref"))
import urrt_ref as ref  # noqa: E402
sys.path.insert(0, os.path.join(HERE, ".."))
import suite  # noqa: E402  checks and their report
from suite import check  # noqa: E402

KINDS = ("STATE", "JOINTS", "TOOL", "STATUS", "RTDE", "GATEWAY")
DATA_KINDS = ("STATE", "JOINTS", "TOOL", "STATUS")
# Upper bound of any wait: reached only when something is broken.
WAIT = 60
# What the subscriber's measured age may exceed the gateway's bound by: the
# part of the transport the gateway's floor takes as the baseline (loopback,
# well under a millisecond), the clocks' readings, and the gateway being
# preempted between its age check and the send it guards (the one window no
# check can close: a scheduling slice on a machine loaded several times
# over; 16.6 ms was seen with the load average at 8 on 2 cores).
AGE_MARGIN_US = 25000



def free_udp_port():
    """A UDP port the system hands out: this test's LCM traffic is its own."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("", 0))
        return s.getsockname()[1]


class Run:
    """Processes and files of one test; stop() ends everything it started."""

    def __init__(self, args, name):
        self.args = args
        self.dir = tempfile.mkdtemp(prefix="gw-%s-" % name, dir=args.tmp)
        self.procs = []
        self.prefix = "t%d%s" % (os.getpid(), name.replace("_", ""))
        self.url = "udpm://239.255.76.67:%d?ttl=0" % free_udp_port()
        self.msgs = []
        self.ch = {}
        self._offset = 0

    def path(self, name):
        return os.path.join(self.dir, name)

    def start(self, argv, log, env=None):
        e = dict(os.environ)
        e.update(env or {})
        p = subprocess.Popen(argv, stdout=open(self.path(log), "w"), stderr=subprocess.STDOUT
                             if log.endswith(".log") else open(self.path(log + ".err"), "w"), env=e)
        self.procs.append(p)
        return p

    def sim(self, *extra, port=0, log="sim.log"):
        """urrt-sim on port (0: one from the system); returns (process, port) once it listens."""
        port_file = self.path(log + ".port")
        p = self.start([self.args.sim, "--listen", "127.0.0.1:%d" % port, "--port-file", port_file, "-q"] +
                       list(extra), log)
        wait_for(lambda: os.path.exists(port_file) or p.poll() is not None, WAIT)
        if not os.path.exists(port_file):
            raise RuntimeError("urrt-sim did not listen: %s" % self.log(log)[-300:])
        return p, int(open(port_file).read())

    def sim_rtde(self, *extra, port=0, rtde_port=0, log="sim.log"):
        """urrt-sim serving RealTime and RTDE from the same arm; returns (process, port, RTDE port)."""
        rtde_file = self.path(log + ".rtde")
        p, rt = self.sim("--rtde", "127.0.0.1:%d" % rtde_port, "--rtde-port-file", rtde_file, *extra, port=port,
                         log=log)
        wait_for(lambda: os.path.exists(rtde_file) or p.poll() is not None, WAIT)
        if not os.path.exists(rtde_file):
            raise RuntimeError("urrt-sim did not listen for RTDE: %s" % self.log(log)[-300:])
        return p, rt, int(open(rtde_file).read())

    def sub(self, regex=None):
        ready = self.path("sub.ready")
        p = self.start([self.args.sub, self.url, regex or (re.escape(self.prefix) + r".*\..*"), "600", ready],
                       "sub.jsonl")
        wait_for(lambda: os.path.exists(ready) or p.poll() is not None, WAIT)
        if not os.path.exists(ready):
            raise RuntimeError("lcm_sub did not start")
        return p

    def gateway(self, ini_text, env=None, log="gw.log"):
        ini = self.path("gw.ini")
        with open(ini, "w") as f:
            f.write(ini_text)
        return self.start([self.args.gateway, ini], log, env)

    def stop(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.send_signal(signal.SIGCONT)
                p.send_signal(signal.SIGTERM)
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.poll()

    def poll(self):
        """Reads the messages the subscriber wrote since the last call."""
        path = self.path("sub.jsonl")
        if not os.path.exists(path):
            return
        with open(path, "rb") as f:
            f.seek(self._offset)
            data = f.read()
        end = data.rfind(b"\n") + 1
        self._offset += end
        for line in data[:end].splitlines():
            if line.strip():
                m = json.loads(line)
                self.msgs.append(m)
                self.ch.setdefault(m["ch"], []).append(m)

    def channel(self, kind, prefix=None):
        return self.ch.get("%s.%s" % (prefix or self.prefix, kind), [])

    def wait(self, pred, what, seconds=WAIT):
        """Waits until pred() holds on the messages so far; a check that fails when it never does."""
        end = time.monotonic() + seconds
        while True:
            self.poll()
            if pred():
                return True
            if time.monotonic() >= end:
                return check(False, "%s (waited %d s)" % (what, seconds))
            time.sleep(0.02)

    def messages(self):
        self.poll()
        return self.msgs

    def log(self, name="gw.log"):
        with open(self.path(name)) as f:
            return f.read()


def wait_for(pred, seconds, step=0.02):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(step)
    return pred()


def source_sim(r, rtde, *extra, port=0, rtde_port=0, log="sim.log"):
    """urrt-sim and what a robot reads of it: (process, RealTime port, the
    robot's port, the robot's source line). With rtde the robot reads the
    simulator's RTDE port: the same arm, the same controller time."""
    if not rtde:
        p, rt = r.sim(*extra, port=port, log=log)
        return p, rt, rt, ""
    p, rt, rd = r.sim_rtde(*extra, port=port, rtde_port=rtde_port, log=log)
    return p, rt, rd, "source = rtde\n"


def robot_ini(name, port, extra=""):
    return "[robot %s]\nhost = 127.0.0.1\nport = %d\n%s\n" % (name, port, extra)


def lcm_ini(r, **rates):
    text = "[lcm]\nurl = %s\n" % r.url
    for k, v in rates.items():
        text += "%s = %s\n" % (k, v)
    return text


def counter(g, name):
    return g.get("counters", {}).get(name, 0) if g else 0


def gaps(msgs, min_gap_us):
    """(last utime before, first utime after) of every pause longer than min_gap_us."""
    t = [m["utime"] for m in msgs]
    return [(a, b) for a, b in zip(t, t[1:]) if b - a > min_gap_us]


def check_truthful(r, what, bound_us, prefix=None):
    """The promise, on every message of a run: no data message reached the
    subscriber older than the bound (measured by the simulator's clock), and
    no GATEWAY report said fresh later than the bound after the last packet
    read before it (the report's utime is the instant it was judged)."""
    prefix = prefix or r.prefix
    data = sorted((m for k in DATA_KINDS for m in r.channel(k, prefix)), key=lambda m: m["utime"])
    times = lambda m: m["time"] if "time" in m else m["controller_time"]  # noqa: E731
    old = [m for m in data if m["recv_utime"] - times(m) * 1e6 > bound_us + AGE_MARGIN_US]
    check(data and not old, "%s: none of %d data messages older than %d ms when received (%d are; oldest %.1f ms)" %
          (what, len(data), bound_us // 1000, len(old),
           max((m["recv_utime"] - times(m) * 1e6) / 1e3 for m in old) if old else 0))
    reads = [m["utime"] for m in data]
    lies, i = [], 0
    for g in r.channel("GATEWAY", prefix):
        while i < len(reads) and reads[i] <= g["utime"]:
            i += 1
        if g["data_fresh"] and (i == 0 or g["utime"] - reads[i - 1] > bound_us + 1000):
            lies.append("%.1f ms" % ((g["utime"] - reads[i - 1]) / 1e3) if i else "before any read")
    check(not lies, "%s: no GATEWAY report says fresh more than %d ms after the last packet read (%s)" %
          (what, bound_us // 1000, ", ".join(lies[:5]) or "none"))


def check_delivered(r, what, g):
    """The subscriber lost nothing: it received exactly what the gateway says it published."""
    for kind in DATA_KINDS:
        got, sent = len(r.channel(kind)), counter(g, "lcm.published." + kind.lower())
        check(got == sent, "%s: %s received %d of %d published" % (what, kind, got, sent))


def read_capture(path):
    """Packets of a raw capture, framed by their size header."""
    data = open(path, "rb").read()
    packets, i = [], 0
    while i + 4 <= len(data):
        (n,) = struct.unpack(">i", data[i:i + 4])
        if n < 12 or i + n > len(data):
            break
        cols = [struct.unpack(">Q", data[j:j + 8])[0] for j in range(i + 4, i + n, 8)]
        packets.append((n, cols))
        i += n
    return packets


def same(a, b):
    """Equal as doubles, NaN equal to NaN (JSON carries no NaN payload)."""
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return float(a) == float(b)


def field_values(cols, lay, name):
    count, first = lay[name]
    return [ref.double_of(cols[first - 1 + i]) for i in range(count)]


def by_channel(msgs, prefix):
    out = {k: [] for k in KINDS}
    for m in msgs:
        ch = m["ch"]
        if ch.startswith(prefix + "."):
            out.setdefault(ch[len(prefix) + 1:], []).append(m)
    return out


# ---- the tests ------------------------------------------------------------------------

def t_values(args, version, count):
    """Every message decodes and equals the packet the simulator sent."""
    r = Run(args, "v" + version.replace(".", ""))
    try:
        r.sub()
        _, port = r.sim("--version", version, "--start-on-connect", "-n", str(count), "-w", r.path("rec.bin"),
                        "--clients", "1", "--clock", "realtime")
        r.gateway(lcm_ini(r, status_rate="every") + robot_ini(r.prefix, port))
        # The simulator ends the connection after count packets and exits;
        # the gateway's report of that carries its final counters.
        r.wait(lambda: any(g["packets"] == count and not g["data_fresh"] for g in r.channel("GATEWAY")),
               "%s: GATEWAY reports the end of the stream after %d packets" % (version, count))
    finally:
        r.stop()
    msgs = r.messages()
    packets = read_capture(r.path("rec.bin"))
    check(len(packets) == count, "%s: simulator recorded %d packets (%d)" % (version, count, len(packets)))
    check(all(m["type"] is not None for m in msgs), "%s: every one of %d messages decodes" % (version, len(msgs)))
    final = [g for g in r.channel("GATEWAY") if g["packets"] == count and not g["data_fresh"]]
    if final:
        check_delivered(r, version, final[0])
        late, stale = counter(final[0], "late_packets"), counter(final[0], "lcm.stale_dropped")
        check(counter(final[0], "lcm.published.state") + late + stale >= count,
              "%s: every packet published or counted late (%d published, %d late, %d stale at send)" %
              (version, counter(final[0], "lcm.published.state"), late, stale))
    check_truthful(r, version, 100000)
    ch = by_channel(msgs, r.prefix)
    by_time = {p[1][0]: p for p in packets}
    length, doubles = packets[0][0], (packets[0][0] - 4) // 8
    lay = ref.layout(doubles)
    gen = ref.generation(doubles)
    for kind in ("STATE", "JOINTS", "TOOL", "STATUS"):
        n = len(ch[kind])
        check(n >= count // 2, "%s: %s messages for %d of %d packets" % (version, kind, n, count))
    # STATE: every field, bit by bit where JSON keeps bits.
    bad, first_bad = 0, None
    for m in ch["STATE"]:
        p = by_time.get(ref.bits_of(m["time"]))
        if p is None:
            bad += 1
            first_bad = first_bad or "no packet with time %r" % m["time"]
            continue
        cols = p[1]
        problems = []
        if m["length"] != length or m["doubles"] != doubles or m["generation"] != gen:
            problems.append("length/doubles/generation")
        if m["versions"] != ref.VERSIONS.get(length, ""):
            problems.append("versions %r" % m["versions"])
        for i, name in enumerate(ref.ALL_NAMES):
            present = bool(m["present"] >> i & 1)
            v = m[name] if isinstance(m[name], list) else [m[name]]
            if name in lay:
                want = field_values(cols, lay, name)
                if not present or len(v) != len(want) or not all(same(a, b) for a, b in zip(v, want)):
                    problems.append(name)
            elif present or not all(math.isnan(x) for x in v):
                problems.append(name + " (absent)")
        if problems:
            bad += 1
            first_bad = first_bad or "t=%r: %s" % (m["time"], ", ".join(problems))
    check(bad == 0, "%s: all %d STATE messages equal their packets%s" %
          (version, len(ch["STATE"]), "" if bad == 0 else " (%d differ; first: %s)" % (bad, first_bad)))
    # Focused messages: the same values under their names.
    for kind in ("JOINTS", "TOOL"):
        bad, first_bad = 0, None
        for m in ch[kind]:
            p = by_time.get(ref.bits_of(m["controller_time"]))
            if p is None:
                bad += 1
                continue
            for name, v in m.items():
                if name in ("ch", "recv_utime", "size", "type", "utime", "controller_time", "sequence"):
                    continue
                v = v if isinstance(v, list) else [v]
                want = field_values(p[1], lay, name) if name in lay else [float("nan")] * len(v)
                if not all(same(a, b) for a, b in zip(v, want)) or len(v) != len(want):
                    bad += 1
                    first_bad = first_bad or "%s t=%r" % (name, m["controller_time"])
                    break
        check(bad == 0, "%s: all %d %s messages equal their packets%s" %
              (version, len(ch[kind]), kind, "" if bad == 0 else " (%d differ; first %s)" % (bad, first_bad)))
    bad, first_bad = 0, None
    for m in ch["STATUS"]:
        p = by_time.get(ref.bits_of(m["controller_time"]))
        if p is None:
            bad += 1
            continue
        cols = p[1]
        problems = []
        for name in ("robot_mode", "safety_mode", "safety_status", "program_state"):
            if name in lay:
                bits = cols[lay[name][1] - 1]
                x = ref.double_of(bits)
                if m[name] != int(x) or m[name + "_name"] != ref.expected_enum(name, gen, bits):
                    problems.append(name)
            elif m[name] != -32768 or m[name + "_name"] != "":
                problems.append(name + " (absent)")
        if "joint_modes" in lay:
            for j in range(6):
                bits = cols[lay["joint_modes"][1] - 1 + j]
                if m["joint_modes"][j] != int(ref.double_of(bits)) or \
                        m["joint_mode_names"][j] != ref.expected_enum("joint_modes", gen, bits):
                    problems.append("joint_modes")
        for name, key in (("digital_input_bits", "digital_inputs"), ("digital_outputs", "digital_outputs")):
            want = ref.expected_mask(cols[lay[name][1] - 1]) if name in lay else None
            if m[key] != (-1 if want is None else want):
                problems.append(key)
        for name in ("speed_scaling", "v_main", "v_robot", "i_robot", "linear_momentum_norm", "controller_timer"):
            want = field_values(cols, lay, name)[0] if name in lay else float("nan")
            if not same(m[name], want):
                problems.append(name)
        if problems:
            bad += 1
            first_bad = first_bad or "t=%r: %s" % (m["controller_time"], problems)
    check(bad == 0, "%s: all %d STATUS messages (numbers, names, bits) equal their packets%s" %
          (version, len(ch["STATUS"]), "" if bad == 0 else " (%d differ; first %s)" % (bad, first_bad)))
    # One packet, one sequence number, one receive time across the kinds.
    seq = {}
    consistent = True
    for kind in ("STATE", "JOINTS", "TOOL", "STATUS"):
        for m in ch[kind]:
            t = m["time"] if kind == "STATE" else m["controller_time"]
            if seq.setdefault(t, (m["sequence"], m["utime"])) != (m["sequence"], m["utime"]):
                consistent = False
    check(consistent, "%s: sequence and utime agree across the messages of a packet" % version)
    ages = [m["recv_utime"] - m["utime"] for m in ch["STATE"]]
    check(ages and 0 <= min(ages) and max(ages) < 100000,
          "%s: utime is the time the gateway read the packet (publish - utime %s..%s us)" %
          (version, min(ages) if ages else "-", max(ages) if ages else "-"))
    waits = [m["utime"] - m["time"] * 1e6 for m in ch["STATE"]]
    check(waits and -1000 < min(waits) and max(waits) < 100000 + AGE_MARGIN_US,
          "%s: utime is after the simulator sent the packet and within the bound (%.0f..%.0f us)" %
          (version, min(waits) if waits else 0, max(waits) if waits else 0))
    g = ch["GATEWAY"]
    check(len(g) >= 1 and g[0]["robot"] == r.prefix and g[0]["port"] == port and g[0]["host"] == "127.0.0.1",
          "%s: GATEWAY names the robot, host and port" % version)
    up = [x for x in g if x["data_fresh"]]
    check(bool(up) and up[-1]["length"] == length and up[-1]["versions"] == ref.VERSIONS.get(length, "") and
          up[-1]["link_state_name"] == "up", "%s: GATEWAY reports the link up with %d-byte packets" % (version, length))


def t_decimation(args):
    r = Run(args, "dec")
    try:
        r.sub()
        _, port = r.sim("--version", "5.10", "--rate", "500")
        r.gateway(lcm_ini(r, state_rate="off", joints_rate="50 Hz", tool_rate="30 Hz", status_rate="10 Hz",
                          gateway_rate="2 Hz") + robot_ini(r.prefix, port))
        # Three seconds of the controller's clock on every decimated channel.
        r.wait(lambda: all(len(r.channel(k)) > 1 and
                           r.channel(k)[-1]["controller_time"] - r.channel(k)[0]["controller_time"] >= 3
                           for k in ("JOINTS", "TOOL", "STATUS")) and len(r.channel("GATEWAY")) >= 7,
               "decimation: 3 s of decimated messages")
    finally:
        r.stop()
    check(len(r.channel("STATE")) == 0, "decimation: state_rate = off publishes nothing (%d)" %
          len(r.channel("STATE")))
    for kind, hz in (("JOINTS", 50), ("TOOL", 30), ("STATUS", 10)):
        t = [m["controller_time"] for m in r.channel(kind)]
        if not check(len(t) > 5, "decimation: %s has messages (%d)" % (kind, len(t))):
            continue
        rate = (len(t) - 1) / (t[-1] - t[0])
        gaps_s = [b - a for a, b in zip(t, t[1:])]
        check(abs(rate - hz) <= 0.01 * hz, "decimation: %s at %.3f Hz on the controller clock (configured %d)" %
              (kind, rate, hz))
        # 500 Hz packets: each gap is the period rounded to a packet (2 ms).
        lo, hi = math.floor(500.0 / hz) * 0.002 - 1e-6, math.ceil(500.0 / hz) * 0.002 + 1e-6
        check(all(lo <= gp <= hi for gp in gaps_s), "decimation: every %s gap within %.3f..%.3f s (%.4f..%.4f)" %
              (kind, lo, hi, min(gaps_s), max(gaps_s)))
    # Reports come every 0.5 s on the host's clock, and at once when freshness changes.
    t = [m["utime"] / 1e6 for m in r.channel("GATEWAY") if m["data_fresh"]][1:]
    rate = (len(t) - 1) / (t[-1] - t[0]) if len(t) > 2 else 0
    check(abs(rate - 2) < 0.2, "decimation: GATEWAY at %.2f Hz (configured 2 Hz)" % rate)


def t_two_robots(args):
    r = Run(args, "two")
    a, b = r.prefix + "a", r.prefix + "b"
    try:
        r.sub(re.escape(r.prefix) + r"[ab]\..*")
        _, port_a = r.sim("--version", "5.10", "--seed", "7", log="sim_a.log")
        _, port_b = r.sim("--version", "3.10", "--seed", "8", log="sim_b.log")
        r.gateway(lcm_ini(r) + robot_ini(a, port_a, "version = 5.10") + robot_ini(b, port_b, "version = 3.10"))
        r.wait(lambda: len(r.channel("STATE", a)) > 800 and len(r.channel("STATE", b)) > 200 and
               len(r.channel("GATEWAY", a)) >= 3 and len(r.channel("GATEWAY", b)) >= 3,
               "two robots: both publish")
    finally:
        r.stop()
    msgs = r.messages()
    sa, sb = r.channel("STATE", a), r.channel("STATE", b)
    check(all(m["length"] == 1220 for m in sa) and all(m["length"] == 1116 for m in sb),
          "two robots: each channel carries its own robot's packets (1220 / 1116 bytes)")
    ga, gb = r.channel("GATEWAY", a), r.channel("GATEWAY", b)
    check(ga and gb and all(m["robot"] == a and m["port"] == port_a for m in ga) and
          all(m["robot"] == b and m["port"] == port_b for m in gb),
          "two robots: each GATEWAY channel reports its own robot")
    check(all(m["ch"].split(".")[0] in (a, b) for m in msgs), "two robots: no other channels, no mixing")
    rates = sorted(m["packet_rate"] for m in ga if m["packet_rate"] > 0) or [0]
    check(abs(rates[len(rates) // 2] - 500) < 25,
          "two robots: %s reports ~500 packets/s (%.1f)" % (a, rates[len(rates) // 2]))


def t_restart(args, rtde=False):
    """Kill the simulator, restart it: disconnected, no stale state, then
    recovery (with RTDE: the whole handshake again)."""
    r = Run(args, "rst" + ("rd" if rtde else ""))
    what = "rtde restart" if rtde else "restart"
    try:
        r.sub()
        sim, rt_port, port, source = source_sim(r, rtde, "--version", "5.10", "--clock", "realtime", log="sim1.log")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") +
                  robot_ini(r.prefix, port, source +
                            "silence_timeout = 100 ms\nbackoff_initial = 100 ms\nbackoff_max = 200 ms"))
        r.wait(lambda: len(r.channel("STATE")) >= 500, what + ": state flows before the kill")
        sim.kill()
        sim.wait()
        killed = time.time() * 1e6
        r.wait(lambda: len([g for g in r.channel("GATEWAY") if g["utime"] > killed + 300000]) >= 10,
               what + ": GATEWAY reports while the simulator is gone")
        restarted = time.time() * 1e6
        source_sim(r, rtde, "--version", "5.10", "--clock", "realtime", port=rt_port, rtde_port=port, log="sim2.log")
        r.wait(lambda: len([m for m in r.channel("STATE") if m["utime"] > restarted]) > 500 and
               any(g["data_fresh"] and g["utime"] > restarted for g in r.channel("GATEWAY")),
               what + ": state flows again after the restart")
        stopping = time.time() * 1e6
    finally:
        r.stop()
    state = [m for k in DATA_KINDS for m in r.channel(k)]
    gap = [m for m in state if killed < m["utime"] < restarted]
    check(len(gap) == 0, what + ": no packet read between the kill and the restart (%d)" % len(gap))
    down = [m for m in r.channel("GATEWAY") if killed + 100000 + 1000 < m["utime"] < restarted]
    check(len(down) >= 10 and all(not m["data_fresh"] and m["link_state_name"] != "up" for m in down),
          what + ": %d GATEWAY reports while down, all saying no data and link not up" % len(down))
    last = [g for g in r.channel("GATEWAY") if g["utime"] < stopping][-1]
    check(last.get("data_fresh") and last.get("reconnects", 0) >= 1 and last.get("disconnects", 0) >= 1,
          what + ": the last GATEWAY says fresh again, reconnects %s, disconnects %s" %
          (last.get("reconnects"), last.get("disconnects")))
    check_truthful(r, what, 100000)


def check_gap(r, what, gap, bound_us, silences_before, expect_silences):
    """One pause in the stream, (last read before, first read after)."""
    a, b = gap
    reports = r.channel("GATEWAY")
    stale = [g for g in reports if a < g["utime"] < b and not g["data_fresh"]]
    check(stale and stale[0]["utime"] <= a + bound_us + 50000,
          "%s: \"no data\" reported %.0f ms after the last packet (bound %d ms)" %
          (what, (stale[0]["utime"] - a) / 1e3 if stale else -1, bound_us // 1000))
    fresh_inside = [g for g in reports if a + bound_us + 1000 < g["utime"] < b and g["data_fresh"]]
    check(not fresh_inside, "%s: no report says fresh inside the gap (%d do)" % (what, len(fresh_inside)))
    after = [g for g in reports if g["utime"] >= b]
    check(after and after[0]["data_fresh"], "%s: the first report after the gap says fresh" % what)
    if after:
        counted = after[0]["silences"] - silences_before
        check(counted in expect_silences, "%s: %d silences counted (expected %s)" % (what, counted, expect_silences))
    return stale


# A stalled connection is dropped after silence_timeout (100 ms) and the next
# one comes after the backoff (100 ms): at least 200 ms without data. A pause
# of a loaded machine is far shorter.
STALL_GAP_US = 150000


def t_stall(args, rtde=False):
    """Half-open links: each connection goes quiet after 500 packets for 1.5 s;
    the gateway drops it after silence_timeout and the next one has data at once."""
    r = Run(args, "stall" + ("rd" if rtde else ""))
    what = "rtde stall" if rtde else "stall"
    bound = 100000
    try:
        r.sub()
        _, _, port, source = source_sim(r, rtde, "--version", "5.10", "--clock", "realtime", "--fault",
                                        "stall-after=500,for=1500")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") + robot_ini(r.prefix, port, source + "silence_timeout = 100 ms"))
        # Two gaps, and data again after the second.
        r.wait(lambda: len(gaps(r.channel("STATE"), STALL_GAP_US)) >= 2 and
               r.channel("STATE")[-1]["utime"] > gaps(r.channel("STATE"), STALL_GAP_US)[1][1] + 200000 and
               r.channel("GATEWAY")[-1]["utime"] > gaps(r.channel("STATE"), STALL_GAP_US)[1][1],
               what + ": two stalls and recovery")
    finally:
        r.stop()
    found = gaps(r.channel("STATE"), STALL_GAP_US)[:2]
    for n, gap in enumerate(found):
        before = [g for g in r.channel("GATEWAY") if g["utime"] <= gap[0]]
        check_gap(r, "%s %d" % (what, n + 1), gap, bound, before[-1]["silences"] if before else 0, (1,))
    check_truthful(r, what, bound)


def t_frozen(args):
    """A controller that stops sending for 1.5 s on every connection, new ones
    included: reconnecting does not help, and every report of the outage
    says so."""
    r = Run(args, "frozen")
    bound = 100000
    try:
        r.sub()
        _, port = r.sim("--version", "5.10", "--clock", "realtime", "--fault", "freeze-after=500,for=1500")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") + robot_ini(r.prefix, port, "silence_timeout = 100 ms"))
        r.wait(lambda: len(gaps(r.channel("STATE"), 1000000)) >= 1 and
               r.channel("GATEWAY")[-1]["utime"] > gaps(r.channel("STATE"), 1000000)[0][1] + 200000,
               "frozen: the outage and recovery")
    finally:
        r.stop()
    found = gaps(r.channel("STATE"), 1000000)
    if not check(len(found) == 1, "frozen: one outage (%d)" % len(found)):
        return
    a, b = found[0]
    check(1400000 <= b - a <= 1500000 + 1000000, "frozen: the outage lasted %.0f ms (freeze 1500 ms, then a "
          "reconnect within the backoff)" % ((b - a) / 1e3))
    before = [g for g in r.channel("GATEWAY") if g["utime"] <= a]
    # The link was up once, so it is lost once: the connections the frozen
    # controller accepts and never feeds are failed attempts, not losses.
    stale = check_gap(r, "frozen", found[0], bound, before[-1]["silences"] if before else 0, (1,))
    after = [g for g in r.channel("GATEWAY") if g["utime"] >= b]
    if before and after:
        check(after[0]["connect_failures"] - before[-1]["connect_failures"] >= 2 and
              after[0]["connects"] - before[-1]["connects"] == 1,
              "frozen: the silent connections are %d failed attempts, and the link came up once (connects +%d)" %
              (after[0]["connect_failures"] - before[-1]["connect_failures"],
               after[0]["connects"] - before[-1]["connects"]))
    # Reports come every 100 ms on the host's clock, whatever the link does.
    expected = int((b - a - bound - 50000) / 100000) - 1
    check(len(stale) >= expected, "frozen: %d \"no data\" reports over the %.0f ms outage (at least %d)" %
          (len(stale), (b - a) / 1e3, expected))
    check_truthful(r, "frozen", bound)


def read_can_log(path):
    """(wall time in us, id, data bytes) of each line of a candump -l file."""
    frames = []
    if not os.path.exists(path):
        return frames
    for line in open(path):
        m = re.match(r"\((\d+)\.(\d{6})\) \S+ ([0-9A-F]+)#([0-9A-F]*)$", line.strip())
        if m:
            frames.append((int(m.group(1)) * 1000000 + int(m.group(2)), int(m.group(3), 16),
                           bytes.fromhex(m.group(4))))
    return frames


def emcy_events(frames, cob_id, code):
    """Times an EMCY raised code, and times its reset (0x0000 naming code in bytes 3-4) came."""
    raised = [t for t, i, d in frames if i == cob_id and len(d) == 8 and d[0] | d[1] << 8 == code]
    reset = [t for t, i, d in frames if i == cob_id and len(d) == 8 and d[0] | d[1] << 8 == 0 and
             d[3] | d[4] << 8 == code]
    return raised, reset


# A robot whose process is stopped: its kernel still accepts connections.
SIGSTOP_ROBOT = ("silence_timeout = 100 ms\nbackoff_initial = 100 ms\nbackoff_max = 200 ms\n"
                 "connect_timeout = 500 ms")


def t_sigstop(args, rtde=False):
    """The simulator stopped (SIGSTOP) past the silence timeout and several
    reconnects: the link is down until data flows again, once, as GATEWAY,
    the CANopen node's EMCY 0xFF01 and the CAN heartbeat's state all say."""
    r = Run(args, "sigstop" + ("rd" if rtde else ""))
    what = "rtde sigstop" if rtde else "sigstop"
    node = 5
    emcy_log, hb_log = r.path("emcy.log"), r.path("hb.log")
    hb = r.prefix + "hb"
    try:
        r.sub()
        sim, _, port, source = source_sim(r, rtde, "--version", "5.10", "--clock", "realtime")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") + robot_ini(r.prefix, port, source + SIGSTOP_ROBOT) +
                  "[can]\ninterface = log:%s\nstale_after_ms = 100\n[canopen]\nnode_id = %d\n"
                  "nmt_start = operational\n[frame tpdo1]\nperiod_ms = 10\n"
                  "signal = q_actual[0] @0|16 intel signed factor=0.0002 min=-6.3 max=6.3 name=q0\n" % (emcy_log, node))
        # A second gateway with a plain CAN heartbeat (the node's status TPDO is off until a manager enables it).
        with open(r.path("gw_hb.ini"), "w") as f:
            f.write(lcm_ini(r, state_rate="off", joints_rate="off", tool_rate="off", status_rate="off",
                            gateway_rate="off") + robot_ini(hb, port, source + SIGSTOP_ROBOT) +
                    "[can]\ninterface = log:%s\nheartbeat_id = 0x701\nheartbeat_period_ms = 20\nstale_after_ms = 100\n"
                    "[frame f]\nid = 0x181\nperiod_ms = 100\nsignal = q_actual[0] @0|16 intel signed factor=0.001\n"
                    % hb_log)
        r.start([args.gateway, r.path("gw_hb.ini")], "gw_hb.log")
        hb_state = lambda f: f[2][0] & 0x0F  # noqa: E731
        r.wait(lambda: len(r.channel("STATE")) >= 200 and any(g["data_fresh"] for g in r.channel("GATEWAY")) and
               any(i == 0x701 and hb_state((t, i, d)) == 1 for t, i, d in read_can_log(hb_log)),
               what + ": data flows, GATEWAY fresh, the heartbeat says OK")
        before = r.channel("GATEWAY")[-1]
        stopped = time.time() * 1e6
        sim.send_signal(signal.SIGSTOP)
        # Several reconnects into the stopped simulator, each accepted by its kernel.
        r.wait(lambda: r.channel("GATEWAY")[-1]["connect_failures"] >= before["connect_failures"] + 3,
               what + ": three reconnects while stopped")
        thawed = time.time() * 1e6
        sim.send_signal(signal.SIGCONT)
        r.wait(lambda: len([g for g in r.channel("GATEWAY") if g["utime"] > thawed and g["data_fresh"]]) >= 3 and
               emcy_events(read_can_log(emcy_log), 0x80 + node, 0xFF01)[1] and
               any(t > thawed and i == 0x701 and hb_state((t, i, d)) == 1 for t, i, d in read_can_log(hb_log)),
               what + ": data, the EMCY reset and an OK heartbeat after SIGCONT")
        # Stopping the simulator first ends the gateways' links: what comes after this is the teardown.
        ending = time.time() * 1e6
    finally:
        r.stop()
    reports = sorted((g for g in r.channel("GATEWAY") if g["utime"] < ending), key=lambda g: g["utime"])
    frozen = [g for g in reports if stopped + 150000 < g["utime"] < thawed]
    check(len(frozen) >= 5 and all(g["link_state_name"] != "up" and g["link_state"] != 2 and not g["data_fresh"]
                                   for g in frozen),
          what + ": all %d GATEWAY reports while stopped say the link is not up (%s)" %
          (len(frozen), sorted(set(g["link_state_name"] for g in frozen))))
    ups = [b["utime"] for a, b in zip(reports, reports[1:])
           if b["utime"] > stopped and a["link_state_name"] != "up" and b["link_state_name"] == "up"]
    check(len(ups) == 1 and ups[0] > thawed, what + ": the link comes up once, after SIGCONT (%d times, %s)" %
          (len(ups), ["%+.0f ms" % ((u - thawed) / 1e3) for u in ups]))
    last = reports[-1]
    check(last["connects"] - before["connects"] == 1 and last["reconnects"] - before["reconnects"] == 1 and
          last["disconnects"] - before["disconnects"] == 1 and last["silences"] - before["silences"] == 1,
          what + ": one disconnect, one silence, one connect, one reconnect (%+d %+d %+d %+d)" %
          (last["disconnects"] - before["disconnects"], last["silences"] - before["silences"],
           last["connects"] - before["connects"], last["reconnects"] - before["reconnects"]))
    late = [m for k in DATA_KINDS for m in r.channel(k) if stopped + 100000 < m["utime"] < thawed]
    check(not late, what + ": no data message read while stopped (%d)" % len(late))
    frames = [f for f in read_can_log(emcy_log) if f[0] < ending]
    raised, reset = emcy_events(frames, 0x80 + node, 0xFF01)
    check(len(raised) == 1 and stopped < raised[0] < thawed,
          what + ": EMCY 0xFF01 raised once, while stopped (%d times, %s)" %
          (len(raised), ["%+.0f ms" % ((t - stopped) / 1e3) for t in raised]))
    check(len(reset) == 1 and reset[0] > thawed, what + ": its reset once, after data flows again (%d times, %s)" %
          (len(reset), ["%+.0f ms after SIGCONT" % ((t - thawed) / 1e3) for t in reset]))
    states = [(t, hb_state((t, i, d))) for t, i, d in read_can_log(hb_log) if i == 0x701 and t < ending]
    entered = [t for (_, a), (t, b) in zip(states, states[1:]) if b == 3 and a != 3]
    down = [s for t, s in states if entered and entered[0] <= t < thawed]
    check(len(entered) == 1 and stopped < entered[0] < thawed and down and all(s == 3 for s in down),
          what + ": the heartbeat says ROBOT_DISCONNECTED once, and in all %d heartbeats until SIGCONT (%s)" %
          (len(down), sorted(set(down))))
    check(any(s == 1 for t, s in states if t > thawed), what + ": the heartbeat says OK after SIGCONT")


def t_summary(args):
    """The --summary line's rates: a 1 Hz GATEWAY reads 1.0/s every second
    (not 0, 1 and 2 by where the second falls), 500 Hz STATE about 500/s."""
    r = Run(args, "summary")
    try:
        r.sub()
        _, port = r.sim("--version", "5.10")
        r.gateway("[gateway]\nsummary = yes\n" + lcm_ini(r, status_rate="10 Hz") + robot_ini(r.prefix, port))
        lines = lambda: [l for l in r.log().splitlines() if l.startswith(r.prefix + " ")]  # noqa: E731
        r.wait(lambda: len(lines()) >= 5, "summary: five summary lines")
    finally:
        r.stop()

    def rate(line, kind):
        m = re.search(r" %s\.%s (\S+)/s" % (re.escape(r.prefix), kind), line)
        return m.group(1) if m else None
    got = lines()
    check(len(got) >= 5 and all(rate(l, "GATEWAY") not in (None, "0.0") for l in got),
          "summary: no line says GATEWAY 0.0/s (%s; \"-\" before the first measurement)" %
          [rate(l, "GATEWAY") for l in got])
    steady = got[2:]

    def near(kind, hz, tolerance):
        """Within tolerance of hz on every steady line: a report the loaded machine delays by 50 ms
        moves one measurement by 5 %; a count per second would read 0 or 2."""
        return steady and all(rate(l, kind) not in (None, "-") and abs(float(rate(l, kind)) - hz) <= tolerance * hz
                              for l in steady)
    check(near("GATEWAY", 1, 0.15), "summary: GATEWAY at 1.0/s in every line from the third on (%s)" %
          [rate(l, "GATEWAY") for l in steady])
    check(steady and re.fullmatch(r"\d\.\d", rate(steady[0], "GATEWAY") or ""),
          "summary: a slow channel is printed with its tenth, as 1.0/s (%r)" % (rate(steady[0], "GATEWAY") if steady else None))
    check(near("STATUS", 10, 0.15), "summary: STATUS at 10/s (%s)" % [rate(l, "STATUS") for l in steady])
    check(near("STATE", 500, 0.05), "summary: STATE at 500/s (%s)" % [rate(l, "STATE") for l in steady])


def t_backlog(args, rtde=False):
    """A gateway stopped for a second finds a backlog in its socket: no message
    may carry data older than the silence timeout."""
    r = Run(args, "backlog" + ("rd" if rtde else ""))
    what = "rtde backlog" if rtde else "backlog"
    bound = 100000
    try:
        r.sub()
        _, _, port, source = source_sim(r, rtde, "--version", "5.10", "--clock", "realtime")
        gw = r.gateway(lcm_ini(r, gateway_rate="10 Hz") +
                       robot_ini(r.prefix, port, source + "silence_timeout = 100 ms"))
        r.wait(lambda: len(r.channel("STATE")) >= 500, what + ": state flows")
        stopped = time.time() * 1e6
        gw.send_signal(signal.SIGSTOP)
        time.sleep(1)  # the stimulus: how long the gateway is stopped
        # Taken before SIGCONT: the resumed gateway may read and publish
        # fresh packets before this process reads the clock again (on a
        # loaded machine it did, ten milliseconds' worth), so only a time
        # taken before the signal bounds what was read before the stop.
        resumed = time.time() * 1e6
        gw.send_signal(signal.SIGCONT)
        r.wait(lambda: len([m for m in r.channel("STATE") if m["utime"] > resumed]) >= 500 and
               any(g["utime"] > resumed and counter(g, "late_packets") > 0 for g in r.channel("GATEWAY")),
               what + ": state flows after the stop")
    finally:
        r.stop()
    data = [m for k in DATA_KINDS for m in r.channel(k)]
    # Messages read before the stop took effect may be sent after it: the
    # gateway can be stopped between its last age check and the send. At
    # most one packet's messages.
    in_flight = [m for m in data if m["utime"] < resumed and m["recv_utime"] > resumed]
    check(len(in_flight) <= 4 and all(m["utime"] < stopped + 50000 for m in in_flight),
          what + ": only messages read before the stop arrive after it (%d)" % len(in_flight))
    times = lambda m: m["time"] if "time" in m else m["controller_time"]  # noqa: E731
    old_at_read = [m for m in data if m["utime"] - times(m) * 1e6 > bound + AGE_MARGIN_US]
    check(not old_at_read, what + ": no message's data older than the bound when read (%d)" % len(old_at_read))
    after = [m for m in data if m["utime"] > resumed]
    old = [m for m in after if m["recv_utime"] - times(m) * 1e6 > bound + AGE_MARGIN_US]
    check(after and not old, what + ": no message read after the stop older than the bound when received (%d)" %
          len(old))
    g = r.channel("GATEWAY")
    counted = counter(g[-1], "late_packets") if g else 0
    check(counted > 0, what + ": GATEWAY counts the late packets (%d)" % counted)
    check("older than silence_timeout" in r.log(), what + ": logged")
    check_truthful(r, what, bound)


def t_overload(args, rtde=False):
    """A gateway slower than its robot: every STATE publish takes 2.5 ms, so
    it handles about 400 of 500 packets a second. The lag grows slowly; the
    gateway must notice it, drop what is too old, say so, and never publish
    data older than the bound."""
    r = Run(args, "overload" + ("rd" if rtde else ""))
    what = "rtde overload" if rtde else "overload"
    bound = 100000
    env = {"LD_PRELOAD": args.shim, "ALLOC_SHIM_DELAY_US": "2500", "ALLOC_SHIM_DELAY_SUFFIX": ".STATE"}
    try:
        r.sub()
        _, _, port, source = source_sim(r, rtde, "--version", "5.10", "--clock", "realtime")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") + robot_ini(r.prefix, port, source + "silence_timeout = 100 ms"),
                  env=env)
        r.wait(lambda: len(r.channel("STATE")) >= 1500 and
               sum(1 for g in r.channel("GATEWAY") if not g["data_fresh"]) >= 3,
               what + ": state published and the overload reported")
    finally:
        r.stop()
    g = r.channel("GATEWAY")
    late = counter(g[-1], "late_packets") if g else 0
    stale = counter(g[-1], "lcm.stale_dropped") if g else 0
    check(late + stale > 0, what + ": counted (%d late when read, %d stale at send)" % (late, stale))
    fresh = [m for m in g if m["data_fresh"]]
    check(len(fresh) >= 1 and len(g) > len(fresh),
          what + ": GATEWAY says fresh (%d) and not fresh (%d) as the lag comes and goes" %
          (len(fresh), len(g) - len(fresh)))
    check("older than silence_timeout" in r.log(), what + ": logged")
    check_truthful(r, what, bound)


# ---- RTDE as the source -----------------------------------------------------------------

RTDE_VALUES = "safety_status_bits, output_int_register_24, tcp_offset"
RTDE_NAMES = ["safety_status_bits", "output_int_register_24"] + ["tcp_offset[%d]" % i for i in range(6)]
# The same signals in a frame per robot, a frame per packet: payloads that change every packet.
RTDE_CAN_SIGNALS = ("signal = q_actual[0] @0|32 intel signed factor=0.0000001 name=q0\n"
                    "signal = qd_actual[1] @32|32 intel signed factor=0.0000001 name=qd1\n")
# Message members that are not values of the packet.
NOT_VALUES = ("ch", "recv_utime", "size", "type", "utime", "sequence", "length", "doubles", "versions", "present",
              "extra_columns", "extra")


def differing(a, b, absent=()):
    """Names of the values a and b (messages of one kind) hold differently;
    names in absent are NaN in a."""
    out = []
    for name, v in a.items():
        if name in NOT_VALUES:
            continue
        if name in absent:
            if not all(math.isnan(x) for x in (v if isinstance(v, list) else [v])):
                out.append(name + " (absent)")
            continue
        x, y = (v if isinstance(v, list) else [v]), (b[name] if isinstance(b[name], list) else [b[name]])
        if len(x) != len(y) or not all(same(p, q) if not isinstance(p, str) else p == q for p, q in zip(x, y)):
            out.append(name)
    return out


def t_rtde_values(args):
    """One gateway, a robot on each port of one simulator (the same arm, the
    same controller time): the RTDE robot publishes on LCM and CAN the same
    values as the RealTime one, and its RTDE-only values on NAME.RTDE."""
    r = Run(args, "rdval")
    rt, rd = r.prefix + "rt", r.prefix + "rd"
    can_log = r.path("can.log")
    try:
        r.sub()
        _, port, rport = r.sim_rtde("--version", "5.10", "--clock", "realtime")
        r.gateway(lcm_ini(r, status_rate="every", gateway_rate="10 Hz") + robot_ini(rt, port) +
                  robot_ini(rd, rport, "source = rtde\nrtde_values = %s\n" % RTDE_VALUES) +
                  "[can]\ninterface = log:%s\nheartbeat_id = 0x701\nheartbeat_robot = %s\n" % (can_log, rd) +
                  "[frame frt]\nid = 0x181\nperiod_ms = every\nrobot = %s\n%s" % (rt, RTDE_CAN_SIGNALS) +
                  "[frame frd]\nid = 0x182\nperiod_ms = every\nrobot = %s\n%s" %
                  (rd, RTDE_CAN_SIGNALS.replace("q_actual[0]", "actual_q[0]")))  # by its RTDE name
        r.wait(lambda: min(len(r.channel(k, p)) for k in DATA_KINDS for p in (rt, rd)) >= 1000 and
               len(r.channel("RTDE", rd)) >= 1000, "rtde values: both robots publish every message")
    finally:
        r.stop()
    # What RealTime 5.10 has and RTDE not: the test value and reserved
    # columns (no RTDE output), payload_inertia (RTDE from 5.11 on).
    lacks = {"test_value", "reserved_103", "reserved_112", "reserved_120", "reserved_121", "reserved_140",
             "payload_inertia"}
    st, ref_st = r.channel("STATE", rd), r.channel("STATE", rt)
    rd_absent = {n for i, n in enumerate(ref.ALL_NAMES) if st and not st[-1]["present"] >> i & 1}
    rt_present = {n for i, n in enumerate(ref.ALL_NAMES) if ref_st and ref_st[-1]["present"] >> i & 1}
    check(rt_present & rd_absent == lacks, "rtde values: the RTDE robot lacks exactly %s (%s)" %
          (sorted(lacks), sorted(rt_present & rd_absent)))
    for kind in DATA_KINDS:
        key = "time" if kind == "STATE" else "controller_time"
        ref_msgs = {m[key]: m for m in r.channel(kind, rt)}
        pairs = [(m, ref_msgs[m[key]]) for m in r.channel(kind, rd) if m[key] in ref_msgs]
        bad = [(m[key], differing(m, o, rd_absent)) for m, o in pairs if differing(m, o, rd_absent)]
        check(len(pairs) >= 500 and not bad, "rtde values: %d %s messages equal RealTime's at the same controller "
              "time%s" % (len(pairs), kind, " (%d differ; first t=%r: %s)" % (len(bad), bad[0][0], bad[0][1])
                          if bad else ""))
    check(st and all(m["type"] == "state_t" and m["versions"] == "" for m in st),
          "rtde values: NAME.STATE keeps its type (state_t), no RealTime version named")
    rtde = r.channel("RTDE", rd)
    check(rtde and all(m["type"] == "rtde_t" and m["names"] == RTDE_NAMES for m in rtde),
          "rtde values: NAME.RTDE is an rtde_t naming %s" % ", ".join(RTDE_NAMES))
    # The simulator's model: safety_status_bits has bit (safety_mode - 1) set.
    states = {m["time"]: m for m in st}
    bad = [m["controller_time"] for m in rtde if m["controller_time"] not in states or
           m["sequence"] != states[m["controller_time"]]["sequence"] or
           m["values"][0] != 2 ** (int(states[m["controller_time"]]["safety_mode"]) - 1) or
           m["values"][1] != int(m["values"][1]) or m["values"][2:] != [0.0] * 6]
    check(rtde and not bad, "rtde values: %d RTDE messages hold the package's values (safety_status_bits of its safety "
          "mode, an integer register, tcp_offset zero) under STATE's sequence (%d do not)" % (len(rtde), len(bad)))
    frames = read_can_log(can_log)
    a = [d for _, i, d in frames if i == 0x181]
    b = [d for _, i, d in frames if i == 0x182]
    common = set(a) & set(b)
    inner = b[5:-5]
    check(len(inner) >= 500 and all(d in common for d in inner),
          "rtde values: every CAN frame of the RTDE robot (%d) carries a payload the RealTime robot's sends too "
          "(%d do not)" % (len(inner), sum(1 for d in inner if d not in common)))
    check_truthful(r, "rtde values", 100000, prefix=rd)


def t_rtde_refused(args):
    """A controller without a value the configuration publishes: one error
    line naming it and the version, the long backoff, never a tight loop,
    nothing published."""
    r = Run(args, "rdref")
    try:
        r.sub()
        _, _, rport = r.sim_rtde("--version", "3.10", "--clock", "realtime")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") +
                  robot_ini(r.prefix, rport, "source = rtde\nrtde_values = ft_raw_wrench\n"
                            "backoff_initial = 100 ms\nbackoff_max = 500 ms\n"))
        r.wait(lambda: len(r.channel("GATEWAY")) >= 30, "rtde refused: three seconds of reports")
    finally:
        r.stop()
    lines = [l for l in r.log().splitlines() if "does not have ft_raw_wrench" in l]
    check(len(lines) == 1 and "3.10" in lines[0] and "error" in lines[0],
          "rtde refused: one error line names the value and the controller's version (%r)" % lines[:2])
    g = r.channel("GATEWAY")
    check(all(not m["data_fresh"] and m["link_state_name"] != "up" for m in g) and not r.channel("STATE"),
          "rtde refused: the link never comes up, nothing is published")
    tries = g[-1]["connect_failures"] if g else 0
    span = (g[-1]["utime"] - g[0]["utime"]) / 1e6 if g else 0
    check(2 <= tries <= span / 0.5 + 2, "rtde refused: %d attempts in %.1f s: every backoff_max (500 ms), "
          "not a tight loop" % (tries, span))


def t_rtde_at_realtime(args):
    """source = rtde at a port that streams RealTime (the simulator's, on a
    port the configuration check cannot know): the failure says the peer
    streams without a handshake, as RealTime does, and how to read it;
    nothing is published."""
    r = Run(args, "rdrt")
    try:
        r.sub()
        _, port, _ = r.sim_rtde("--version", "5.10", "--clock", "realtime")
        r.gateway(lcm_ini(r, gateway_rate="10 Hz") + robot_ini(r.prefix, port, "source = rtde\n"))
        r.wait(lambda: "streams without a handshake" in r.log(), "rtde at realtime: the failure is logged")
    finally:
        r.stop()
    lines = [l for l in r.log().splitlines() if "streams without a handshake" in l]
    check(lines and "as a RealTime port (30003) does: its first bytes announce a 1220-byte RealTime packet" in
          lines[0] and "source = realtime" in lines[0] and not r.channel("STATE"),
          "rtde at realtime: the failure names RealTime and source = realtime, nothing published (%r)" % lines[:1])


def t_rtde_frequency(args):
    """rtde_frequency past what the controller streams, the version not in
    the file: the controller's answer refuses it, and the one error line
    names both rates and the controller's version, and says what to do."""
    r = Run(args, "rdfreq")
    try:
        _, _, rport = r.sim_rtde("--version", "3.10", "--clock", "realtime")
        r.gateway(lcm_ini(r) + robot_ini(r.prefix, rport, "source = rtde\nrtde_frequency = 250\n"
                                         "backoff_initial = 100 ms\nbackoff_max = 500 ms\n"))
        said = "rtde_frequency 250 Hz is past this 3.10 controller's maximum of 125 Hz: lower it or use auto"
        wait_for(lambda: said in r.log(), WAIT)
    finally:
        r.stop()
    lines = [l for l in r.log().splitlines() if "controller's maximum" in l]
    check(len(lines) == 1 and said in lines[0] and "error" in lines[0],
          "rtde frequency: one error line names both rates and the controller (%r)" % lines[:2])


def t_rtde_fallback(args):
    """A controller that refuses protocol 2 gets protocol 1; its text
    messages go to the log at their level."""
    r = Run(args, "rdfb")
    try:
        r.sub()
        _, _, rport = r.sim_rtde("--version", "5.10", "--clock", "realtime", "--fault", "rtde-refuse-v2",
                                 "--fault", "rtde-text-every=100,level=2")
        r.gateway(lcm_ini(r) + robot_ini(r.prefix, rport, "source = rtde\n"))
        r.wait(lambda: len(r.channel("STATE")) >= 500, "rtde fallback: state flows over protocol 1")
    finally:
        r.stop()
    log = r.log()
    check("refuses RTDE protocol 2: asking for 1" in log, "rtde fallback: logged")
    said = [l for l in log.splitlines() if "controller says" in l]
    check(said and all("warning" in l for l in said), "rtde fallback: %d text messages logged as warnings" %
          len(said))
    check_truthful(r, "rtde fallback", 100000)


def t_mismatch(args):
    r = Run(args, "mis")
    try:
        r.sub()
        _, port = r.sim("--version", "3.10")
        r.gateway(lcm_ini(r) + robot_ini(r.prefix, port, "version = 5.10"))
        r.wait(lambda: any(g["version_mismatches"] > 100 for g in r.channel("GATEWAY")),
               "version mismatch: counted")
    finally:
        r.stop()
    check(sum(len(r.channel(k)) for k in DATA_KINDS) == 0, "version mismatch: no state published")
    g = r.channel("GATEWAY")
    check(g and g[-1]["version_mismatches"] > 100 and not g[-1]["data_fresh"] and "1116" in g[-1]["last_error"],
          "version mismatch: GATEWAY counts %s mismatches: %r" %
          (g[-1]["version_mismatches"] if g else "?", g[-1]["last_error"] if g else ""))
    check("1116-byte packets" in r.log() and "expected 1220" in r.log(), "version mismatch: logged with both lengths")


def t_allocations(args, rtde=False):
    """Zero allocations per packet in steady state, publish included (with
    RTDE: the session's feed and NAME.RTDE too)."""
    r = Run(args, "alloc" + ("rd" if rtde else ""))
    what = "rtde allocations" if rtde else "allocations"
    report = r.path("alloc.txt")
    warm, window = 4000, 20000
    env = {"LD_PRELOAD": args.shim, "ALLOC_SHIM_OUT": report, "ALLOC_SHIM_WARMUP": str(warm),
           "ALLOC_SHIM_WINDOW": str(window)}
    try:
        # RTDE streams at the controller's 500 Hz: the window takes 8 s there.
        _, _, port, source = source_sim(r, rtde, "--version", "5.10", *(() if rtde else ("--rate", "2500")))
        r.gateway(lcm_ini(r, status_rate="every") +
                  robot_ini(r.prefix, port, source + ("rtde_values = %s\n" % RTDE_VALUES if rtde else "")), env=env)
        wait_for(lambda: os.path.exists(report) and os.path.getsize(report) > 0, WAIT)
    finally:
        r.stop()
    text = open(report).read() if os.path.exists(report) else ""
    m = re.match(r"publishes (\d+) allocs (\d+) in_publish (\d+) outside (\d+)", text)
    if not check(m is not None, what + ": the shim reported (%r)" % text.strip()):
        return
    pubs, total, inside, outside = map(int, m.groups())
    print(what + ": %d publishes (%d packets): %d allocations, %d inside lcm_publish" %
          (pubs, pubs // (5 if rtde else 4), total, inside))
    check(outside == 0, what + ": the gateway's own per-packet path allocates nothing (%d)" % outside)
    check(inside == 0, what + ": lcm_publish allocates nothing either (%d)" % inside)


def t_publish_errors(args):
    r = Run(args, "perr")
    env = {"LD_PRELOAD": args.shim, "ALLOC_SHIM_FAIL_FROM": "2000", "ALLOC_SHIM_FAIL_COUNT": "1000"}
    try:
        r.sub()
        _, port = r.sim("--version", "5.10")
        gw = r.gateway(lcm_ini(r, status_rate="every") + robot_ini(r.prefix, port), env=env)
        r.wait(lambda: any(g["publish_errors"] >= 1000 for g in r.channel("GATEWAY")) and
               len(r.channel("STATE")) > 1000 and r.channel("STATE")[-1]["sequence"] > 1500,
               "publish errors: counted, and state flows after them")
        alive = gw.poll() is None
    finally:
        r.stop()
    check(alive, "publish errors: the gateway keeps running")
    g = r.channel("GATEWAY")
    check(g and g[-1]["publish_errors"] == 1000, "publish errors: GATEWAY counts exactly the 1000 lost (%s)" %
          (g[-1]["publish_errors"] if g else "?"))
    seq = [m["sequence"] for m in r.channel("STATE")]
    check(len(seq) > 1000 and seq[-1] - seq[0] + 1 > len(seq) and seq == sorted(seq),
          "publish errors: STATE has a hole where publishing failed and carries on after it")
    check("publishing" in r.log() and "failed" in r.log(), "publish errors: logged")


def t_publish_reopen(args):
    """Publishing that keeps failing reopens LCM, and recovers when it works again."""
    r = Run(args, "reopen")
    env = {"LD_PRELOAD": args.shim, "ALLOC_SHIM_FAIL_FROM": "1000", "ALLOC_SHIM_FAIL_COUNT": "6000"}
    try:
        r.sub()
        _, port = r.sim("--version", "5.10")
        gw = r.gateway(lcm_ini(r, status_rate="every") + robot_ini(r.prefix, port), env=env)
        r.wait(lambda: "works again" in r.log() and len(r.channel("STATE")) > 300 and
               r.channel("STATE")[-1]["sequence"] > 2000 and
               any(g["publish_errors"] >= 6000 for g in r.channel("GATEWAY")),
               "publish reopen: recovery")
        alive = gw.poll() is None
    finally:
        r.stop()
    check(alive, "publish reopen: the gateway keeps running through 3 s of failures")
    check("reopening" in r.log() and "works again" in r.log(), "publish reopen: LCM reopened, recovery logged")
    g = r.channel("GATEWAY")
    check(g and g[-1]["publish_errors"] >= 6000, "publish reopen: %s messages counted lost (>= 6000)" %
          (g[-1]["publish_errors"] if g else "?"))
    seq = [m["sequence"] for m in r.channel("STATE")]
    check(len(seq) > 300 and seq[-1] > 2000, "publish reopen: STATE flows after the recovery (last sequence %s)" %
          (seq[-1] if seq else "-"))


def t_jar(args):
    jar = args.jar
    names = sorted(os.path.basename(p)[:-4] for p in os.listdir(os.path.join(HERE, "..", "..", "gateway", "lcmtypes"))
                   if p.endswith(".lcm"))
    listing = subprocess.run(["jar", "tf", jar], capture_output=True, text=True, timeout=60).stdout.split()
    check(all("urrt/%s.class" % n in listing for n in names), "jar: holds urrt/%s.class" % ", urrt/".join(names))
    src = os.path.join(args.tmp, "Fingerprints.java")
    with open(src, "w") as f:
        f.write("public class Fingerprints { public static void main(String[] a) throws Exception {\n"
                "  for (String n : a) System.out.println(n + \" \" + Long.toHexString("
                "Class.forName(\"urrt.\" + n).getField(\"LCM_FINGERPRINT\").getLong(null))); } }\n")
    cp = "%s:%s:%s" % (args.lcm_jar, jar, args.tmp)
    subprocess.run(["javac", "-cp", cp, "-d", args.tmp, src], check=True, timeout=120)
    java = subprocess.run(["java", "-cp", cp, "Fingerprints"] + names, capture_output=True, text=True,
                          timeout=60).stdout.split()
    c = subprocess.run([args.sub, "--fingerprints"], capture_output=True, text=True, timeout=10).stdout.split()
    jfp = dict(zip(java[0::2], java[1::2]))
    cfp = dict(zip(c[0::2], c[1::2]))
    for n in names:
        check(n in jfp and jfp.get(n) == cfp.get(n),
              "jar: %s fingerprint Java %s == C %s" % (n, jfp.get(n), cfp.get(n)))


# 96 RTDE-only names, six to a line (a line holds 198 characters).
RTDE_LONG_NAMES = ["output_double_register_%d" % i for i in range(48)] + ["input_double_register_%d" % i for i in range(48)]
RTDE_LONG_RECIPE = "".join("rtde_values = %s\n" % ", ".join(RTDE_LONG_NAMES[k:k + 6]) for k in range(0, 96, 6))


BAD_CONFIGS = [
    # (name, text, line, reason pattern)
    ("unknown section", "[robots arm]\nhost = a\n", 1, r"unknown section \[robots arm\]"),
    ("unknown key", "[robot a]\nhost = h\nhots = x\n", 3, r'unknown key "hots" in \[robot a\]'),
    ("unknown lcm key", "[lcm]\nchannel = X\n[robot a]\nhost = h\n", 2, r'unknown key "channel" in \[lcm\]'),
    ("unknown gateway key", "[gateway]\nverbose = 1\n[robot a]\nhost = h\n", 2, r'unknown key "verbose"'),
    ("key outside a section", "host = h\n[robot a]\nhost = h\n", 1, r"outside of any section"),
    ("robot without name", "[robot]\nhost = h\n", 1, r"needs a name"),
    ("name with a dot", "[robot a.b]\nhost = h\n", 1, r'robot name "a.b"'),
    ("duplicate robot", "[robot a]\nhost = h\n\n[robot a]\nhost = i\n", 4, r'"a" is already defined at line 1'),
    ("duplicate section", "[lcm]\n[robot a]\nhost = h\n[lcm]\n", 4, r"\[lcm\] appears again \(first at line 1\)"),
    ("duplicate key", "[robot a]\nhost = h\nport = 1\nport = 2\n", 4, r"port is set again \(first at line 3\)"),
    ("no host", "[gateway]\n[robot a]\nport = 30013\n", 2, r"has no host"),
    ("bad host", "[robot a]\nhost = bad host!\n", 2, r"not a host name"),
    ("port 0", "[robot a]\nhost = h\nport = 0\n", 3, r"port must be a whole number from 1 to 65535"),
    ("port text", "[robot a]\nhost = h\nport = 30k\n", 3, r"port must be a whole number"),
    ("version 1.6", "[robot a]\nhost = h\nversion = 1.6\n", 3, r"756 or 764"),
    ("unknown version", "[robot a]\nhost = h\nversion = 4.2\n", 3, r"no known controller version"),
    ("bad length", "[robot a]\nhost = h\nversion = 1117\n", 3, r"4 \+ 8n"),
    ("duration without unit", "[robot a]\nhost = h\nsilence_timeout = 50\n", 3, r"with a unit"),
    ("duration too short", "[robot a]\nhost = h\nsilence_timeout = 5 ms\n", 3, r"from 20 ms"),
    ("backoff order", "[robot a]\nhost = h\nbackoff_initial = 2 s\nbackoff_max = 1 s\n", 1, r"backoff_max"),
    ("log level", "[gateway]\nlog_level = loud\n[robot a]\nhost = h\n", 2, r"log_level must be"),
    ("summary", "[gateway]\nsummary = maybe\n[robot a]\nhost = h\n", 2, r"summary must be yes or no"),
    ("url not a URL", "[lcm]\nurl = 239.255.76.67\n[robot a]\nhost = h\n", 2, r"not an LCM URL"),
    ("url provider", "[lcm]\nurl = udp://1.2.3.4:5\n[robot a]\nhost = h\n", 2, r'unknown LCM provider "udp"'),
    ("url not multicast", "[lcm]\nurl = udpm://10.1.2.3:7667\n[robot a]\nhost = h\n", 2, r"not a multicast group"),
    ("url ttl", "[lcm]\nurl = udpm://239.255.76.67:7667?ttl=300\n[robot a]\nhost = h\n", 2, r"ttl must be 0 to 255"),
    ("url option", "[lcm]\nurl = udpm://239.255.76.67:7667?tll=0\n[robot a]\nhost = h\n", 2, r'unknown udpm option "tll"'),
    ("rate syntax", "[lcm]\njoints_rate = 50 kHz\n[robot a]\nhost = h\n", 2,
     r'joints_rate must be "every", "off" or a rate such as "50 Hz" \(a bare 50 is Hz too\), not "50 kHz"'),
    ("rate range", "[lcm]\njoints_rate = 501 Hz\n[robot a]\nhost = h\n", 2, r"out of range"),
    # A bare number is Hz, in every key that takes a rate: the same message as with the unit.
    ("rate range, bare", "[lcm]\njoints_rate = 501\n[robot a]\nhost = h\n", 2,
     r"joints_rate 501 Hz is out of range: from 0.01 Hz to 500 Hz"),
    ("gateway rate, bare", "[lcm]\ngateway_rate = 200\n[robot a]\nhost = h\n", 2,
     r"gateway_rate 200 Hz is out of range: at most 100 Hz"),
    ("rate above robot", "[lcm]\ntool_rate = 200 Hz\n\n[robot a]\nhost = h\nversion = 3.10\n", 2,
     r'above the 125 Hz robot "a" sends \(version 3.10, line 6\)'),
    ("gateway every", "[lcm]\ngateway_rate = every\n[robot a]\nhost = h\n", 2, r"not \"every\""),
    ("channel syntax", "[lcm]\nstate_channel = ST ATE\n[robot a]\nhost = h\n", 2, r"state_channel \"ST ATE\""),
    ("channel twice", "[lcm]\ntool_channel = STATE\n[robot a]\nhost = h\n", 2,
     r'tool_channel "STATE" is also the channel of state'),
    ("empty value", "[robot a]\nhost =\n", 2, r"host has no value"),
    ("syntax", "[robot a]\nhost = h\njust words\n", 3, r'expected "\[section\]" or "key = value"'),
    ("header", "[robot a\nhost = h\n", 1, r"without '\]'"),
    ("long line", "[robot a]\nhost = h\n# " + "x" * 300 + "\n", 3, r"line longer than"),
    ("no robot", "[lcm]\n", 0, r"no robot"),
    ("rtde value on realtime", "[robot a]\nhost = h\nrtde_values = safety_status_bits\n", 3,
     r"rtde_values are RTDE-only values, and this robot's source is realtime"),
    ("rtde unknown value", "[robot a]\nhost = h\nsource = rtde\nrtde_values = output_int_register_48\n", 4,
     r'"output_int_register_48" is no RTDE output'),
    ("rtde shared value", "[robot a]\nhost = h\nsource = rtde\nrtde_values = actual_q\n", 4,
     r"on NAME.STATE already \(as q_actual\)"),
    ("rtde source", "[robot a]\nhost = h\nsource = RTDE\n", 3, r'source must be "realtime"'),
    # RTDE never to a port that runs what it receives, or its twin: at the port's line, naming the source's.
    ("rtde on realtime's port", "[robot a]\nhost = h\nsource = rtde\nport = 30003\n", 4,
     r"port 30003 is the RealTime interface, which runs the URScript it receives, and this robot's source is rtde "
     r"\(line 3\), which would send it RTDE's handshake: RTDE is port 30004 \(write port = 30004, or leave port out\)"),
    ("rtde on the dashboard", "[robot a]\nhost = h\nport = 29999\nsource = rtde\n", 3,
     r"port 29999 is the dashboard server, which runs the commands it receives, and this robot's source is rtde "
     r"\(line 4\)"),
    ("rtde on the primary", "[robot a]\nhost = h\nsource = rtde\nport = 30001\n", 4, r"port 30001 is the primary"),
    ("rtde on the secondary", "[robot a]\nhost = h\nsource = rtde\nport = 30002\n", 4, r"port 30002 is the second"),
    ("rtde on a twin", "[robot a]\nhost = h\nsource = rtde\nport = 30011\n", 4,
     r"port 30011 is the primary client interface's read-only twin"),
    ("rtde on a twin", "[robot a]\nhost = h\nsource = rtde\nport = 30012\n", 4, r"port 30012 is the secondary"),
    ("rtde on realtime's twin", "[robot a]\nhost = h\nsource = rtde\nport = 30013\n", 4,
     r"port 30013 is the RealTime interface's read-only twin"),
    ("rtde on the interpreter", "[robot a]\nhost = h\nsource = rtde\nport = 30020\n", 4,
     r"port 30020 is the interpreter mode's socket"),
    ("realtime on rtde's port", "[robot a]\nhost = h\nport = 30004\n", 3,
     r"port 30004 is RTDE's on every controller, where nothing is sent until a client's handshake, and this "
     r"robot's source is realtime: add \"source = rtde\", or give RealTime's port \(30003, or the read-only 30013\)"),
    ("rtde-only value on CAN, realtime robot", "[robot a]\nhost = h\n[can]\ninterface = log:-\nheartbeat_id = 0x701\n"
     "[frame f]\nid = 0x181\nperiod_ms = 10\nsignal = safety_status_bits @0|32 intel unsigned\n", 9,
     r'signal safety_status_bits: an RTDE-only value, and robot "a" reads RealTime, which has none'),
    ("field without RTDE on CAN", "[robot a]\nhost = h\nsource = rtde\n[can]\ninterface = log:-\n"
     "heartbeat_id = 0x701\n[frame f]\nid = 0x181\nperiod_ms = 10\nsignal = test_value @0|32 intel float32\n", 10,
     r"RTDE has no test_value"),
    ("rtde on 1.x", "[robot a]\nhost = h\nversion = 1.8\nsource = rtde\n", 3, r"version 1.8 has no RTDE"),
    ("rtde frequency", "[robot a]\nhost = h\nsource = rtde\nrtde_frequency = 501 Hz\n", 4,
     r"above 500 Hz, the fastest any controller streams RTDE"),
    # Bare, as "give at most 500 Hz" was read: the advice is written as the file takes it.
    ("rtde frequency, bare", "[robot a]\nhost = h\nsource = rtde\nrtde_frequency = 600\n", 4,
     r"rtde_frequency 600 Hz is above 500 Hz, the fastest any controller streams RTDE: write rtde_frequency = "
     r"500 Hz or less, or rtde_frequency = auto$"),
    ("rtde frequency syntax", "[robot a]\nhost = h\nsource = rtde\nrtde_frequency = fast\n", 4,
     r'rtde_frequency must be "auto" or a rate such as "125 Hz" \(a bare 125 is Hz too\), at most 500 Hz, '
     r'not "fast"'),
    ("rtde frequency of the version", "[robot a]\nhost = h\nversion = 3.10\nsource = rtde\n"
     "rtde_frequency = 200 Hz\n", 5, r"above the 125 Hz version 3.10"),
    ("rtde frequency on realtime", "[robot a]\nhost = h\nrtde_frequency = 125 Hz\n", 3,
     r"applies to source = rtde only"),
    # 96 registers of 24 and 25 letters: 2,437 bytes of names with the timestamp's.
    ("rtde recipe too long", "[lcm]\nstate_rate = off\njoints_rate = off\ntool_rate = off\nstatus_rate = off\n"
     "[robot a]\nhost = h\nsource = rtde\n" + RTDE_LONG_RECIPE, 9, r"names take 2\d\d\d bytes, over the controller's "
     "limit of 2048"),
]


def t_configs(args):
    d = tempfile.mkdtemp(prefix="gw-cfg-", dir=args.tmp)
    for i, (name, text, line, pattern) in enumerate(BAD_CONFIGS):
        path = os.path.join(d, "bad%02d.ini" % i)
        with open(path, "w") as f:
            f.write(text)
        p = subprocess.run([args.gateway, "--check-config", path], capture_output=True, text=True, timeout=10)
        where = "%s:%d: " % (path, line) if line else "%s: " % path
        hit = [l for l in p.stderr.splitlines() if l.startswith(where) and re.search(pattern, l)]
        check(p.returncode == 2 and hit, "config %s: exit 2 and \"%s.../%s\" (got %d: %s)" %
              (name, where.split("/")[-1], pattern, p.returncode, p.stderr.strip().splitlines()[:1]))
    p = subprocess.run([args.gateway, "--check-config", os.path.join(d, "missing.ini")], capture_output=True,
                       text=True, timeout=10)
    check(p.returncode == 2 and "missing.ini: cannot open" in p.stderr, "config: a missing file is named")
    example = os.path.join(HERE, "..", "..", "gateway", "install", "urrt-gateway.example.ini")
    p = subprocess.run([args.gateway, "--check-config", example], capture_output=True, text=True, timeout=10)
    check(p.returncode == 0 and "arm1.STATE: every packet" in p.stdout and "arm1.STATUS: 10 Hz" in p.stdout,
          "config: the example configuration is valid and its plan printed")
    example = os.path.join(HERE, "..", "..", "docs", "examples", "rtde.ini")
    p = subprocess.run([args.gateway, "--check-config", example], capture_output=True, text=True, timeout=10)
    check(p.returncode == 0 and "robot arm1: 192.168.1.10:30004," in p.stdout and
          re.search(r"rtde: 41 values .*: timestamp,\[target_q\],.*,\[payload_inertia\],output_int_register_24,"
                    r"output_double_register_24,robot_status_bits,safety_status_bits,target_speed_fraction\n",
                    p.stdout) and "arm1.RTDE: every packet" in p.stdout,
          "config: the RTDE example is valid: port 30004, its recipe (STATE's fields optional, the RTDE-only "
          "values required) and arm1.RTDE in the plan")
    good = os.path.join(d, "good.ini")
    with open(good, "w") as f:
        f.write("; comment\n[robot a]\nhost = ::1  # inline comment\nversion = 1.8\nconnect_timeout = 1.5 s\n"
                "[lcm]\njoints_rate = 125 Hz\n[robot b]\nhost = robot-b.local\nversion = 1220\n")
    p = subprocess.run([args.gateway, "--check-config", good], capture_output=True, text=True, timeout=10)
    check(p.returncode == 0 and "robot a: [::1]:30003, version 1.8, connect 1500 ms" in p.stdout and
          "b.JOINTS: 125 Hz" in p.stdout, "config: comments, IPv6, versions, lengths and durations accepted")
    # A bare number is Hz wherever a rate is given: rtde_frequency at the most the message above
    # allows, and an [lcm] rate.
    bare = os.path.join(d, "bare.ini")
    with open(bare, "w") as f:
        f.write("[lcm]\njoints_rate = 50\ngateway_rate = 2\n[robot a]\nhost = h\nsource = rtde\n"
                "rtde_frequency = 500\n[robot b]\nhost = h\nsource = rtde\nrtde_frequency = 125Hz\n")
    p = subprocess.run([args.gateway, "--check-config", bare], capture_output=True, text=True, timeout=10)
    check(p.returncode == 0 and re.search(r"robot a: .*\n  rtde: \d+ values at 500 Hz", p.stdout) and
          re.search(r"robot b: .*\n  rtde: \d+ values at 125 Hz", p.stdout) and "a.JOINTS: 50 Hz" in p.stdout and
          "a.GATEWAY: 2 Hz" in p.stdout,
          "config: a bare number is Hz (rtde_frequency = 500, joints_rate = 50, gateway_rate = 2), 125Hz too "
          "(got %d: %s)" % (p.returncode, (p.stderr or p.stdout).strip().splitlines()[:2]))
    many = os.path.join(d, "many.ini")
    with open(many, "w") as f:
        f.write("[robot a]\nhost = h\nport = 0\nversion = x\n[nope]\n")
    p = subprocess.run([args.gateway, "--check-config", many], capture_output=True, text=True, timeout=10)
    lines = [int(l.split(":")[1]) for l in p.stderr.splitlines() if l.startswith(many + ":")]
    check(lines == [3, 4, 5], "config: every error reported, in line order (%s)" % lines)
    # A CAN log on stdout next to the summary lines would no longer replay with canplayer.
    both = os.path.join(d, "both.ini")
    with open(both, "w") as f:
        f.write("[gateway]\nsummary = yes\n[robot a]\nhost = h\n[can]\ninterface = log:-\nheartbeat_id = 0x701\n"
                "[frame f]\nid = 0x181\nperiod_ms = 10\nsignal = q_actual[0] @0|16 intel signed factor=0.001\n")
    for extra in ([], ["--summary"]):
        text = open(both).read()
        with open(both, "w") as f:
            f.write(text.replace("summary = yes", "summary = no") if extra else text)
        p = subprocess.run([args.gateway, "--check-config"] + extra + [both], capture_output=True, text=True,
                           timeout=10)
        check(p.returncode == 2 and (both + ":6: interface = log:- and the summary both write to stdout") in p.stderr,
              "config: CAN log on stdout with the summary%s: exit 2 and %s:6 (%r)" %
              (" (--summary)" if extra else "", os.path.basename(both), p.stderr.strip()[:200]))


def t_install(args):
    """make install puts every file where PREFIX, DESTDIR and the directory variables say; the unit verifies;
    make uninstall removes exactly what install put there."""
    root = tempfile.mkdtemp(prefix="gw-inst-", dir=args.tmp)
    prefix, unitdir, etc = root + "/usr", root + "/unit", root + "/etc"
    repo = os.path.join(HERE, "..", "..")
    where = ["BUILD=" + os.path.abspath(args.build), "PREFIX=" + prefix, "UNITDIR=" + unitdir, "SYSCONFDIR=" + etc]

    def make(target, *settings):
        return subprocess.run(["make", "-s", "-C", repo, target] + list(settings or where), capture_output=True,
                              text=True, timeout=300)

    def tree():
        return sorted(os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs)

    p = make("install")
    files = ["usr/bin/urrt-gateway", "usr/bin/urrt-dump", "usr/bin/urrt-sim", "usr/bin/urrt-spy",
             "usr/share/java/urrt-lcmtypes.jar", "usr/share/urrt/urrt-gateway.example.ini",
             "unit/urrt-gateway.service", "unit/urrt-gateway@.service", "etc/urrt/gateway.ini",
             "usr/share/man/man8/urrt-gateway.8", "usr/share/man/man5/urrt-gateway.ini.5",
             "usr/share/man/man1/urrt-dump.1", "usr/share/man/man1/urrt-sim.1", "usr/share/man/man1/urrt-spy.1",
             "usr/share/doc/urrt/README.md", "usr/share/doc/urrt/gateway.md", "usr/share/doc/urrt/can.md",
             "usr/share/doc/urrt/LICENSE", "usr/share/doc/urrt/examples/canopen.ini",
             "usr/share/doc/urrt/examples/fd.ini", "usr/share/doc/urrt/examples/j1939.ini",
             "usr/share/urrt/lcmtypes/state_t.lcm", "usr/share/urrt/lcmtypes/gateway_t.lcm",
             "usr/include/urrt.h", "usr/include/urrt_can.h", "usr/include/urrt_cantx.h", "usr/include/urrt_co.h",
             "usr/lib/liburrt.a",
             "usr/lib/pkgconfig/urrt.pc", "usr/share/doc/urrt/firmware.md", "usr/share/doc/urrt/architecture.md"]
    missing = [f for f in files if not os.path.exists(os.path.join(root, f))]
    check(p.returncode == 0 and not missing, "install: %d files in place (missing: %s; %s)" %
          (len(files), missing, p.stderr.strip()[-200:]))
    installed = tree()
    unit = open(os.path.join(unitdir, "urrt-gateway.service")).read() if os.path.exists(unitdir) else ""
    check("ExecStart=%s/bin/urrt-gateway %s/urrt/gateway.ini" % (prefix, etc) in unit and "DynamicUser=yes" in unit
          and "Restart=on-failure" in unit and "Documentation=man:urrt-gateway(8)" in unit,
          "install: the unit names the installed paths and the man page, restarts, runs unprivileged")
    # RestartPreventExitStatus= looks at the main process only: a check that fails in ExecStartPre
    # would be retried every RestartSec for ever. The gateway checks its configuration itself.
    check("RestartPreventExitStatus=2" in unit and "ExecStartPre=" not in unit,
          "install: a bad configuration (exit 2 of the main process) is not restarted in a loop")
    check("ProtectSystem=strict" in unit and "LogsDirectory=urrt" in unit,
          "install: the read-only system leaves /var/log/urrt writable for a CAN log")
    template = os.path.join(unitdir, "urrt-gateway@.service")
    template_lines = open(template).read().splitlines() if os.path.exists(template) else []
    check("ExecStart=%s/bin/urrt-gateway %s/urrt/%%i.ini" % (prefix, etc) in template_lines and
          "LogsDirectory=urrt-%i" in template_lines,
          "install: the template unit urrt-gateway@NAME reads %s/urrt/NAME.ini and logs to its own directory" % etc)
    # Every setting but the per-instance ones is the plain unit's: the same hardening and restart policy.
    per_instance = ("Description=", "ExecStart=", "LogsDirectory=")

    def shared(lines):
        return [l for l in lines if l and not l.startswith("#") and not l.startswith(per_instance)]
    check(shared(template_lines) and shared(template_lines) == shared(unit.splitlines()),
          "install: the template unit has the plain unit's every other line (%s)" %
          sorted(set(shared(template_lines)) ^ set(shared(unit.splitlines())))[:3])
    spy = open(os.path.join(prefix, "bin", "urrt-spy")).read() if os.path.exists(prefix) else ""
    check("URRT_JAR_DEFAULT=%s/share/java/urrt-lcmtypes.jar" % prefix in spy, "install: urrt-spy knows the jar")
    conf = os.path.join(etc, "urrt", "gateway.ini")
    c = subprocess.run([args.gateway, "--check-config", conf], capture_output=True, text=True, timeout=10)
    check(c.returncode == 2 and ("no robot: edit %s" % conf) in c.stderr,
          "install: the unedited configuration fails its check and names the file to edit (%r)" % c.stderr[:200])
    ex = subprocess.run([args.gateway, "--check-config", os.path.join(prefix, "share/urrt/urrt-gateway.example.ini")],
                        capture_output=True, text=True, timeout=10)
    check(ex.returncode == 0, "install: the installed example is valid")
    # The C library as a user builds against it, through pkg-config.
    prog = os.path.join(root, "use.c")
    with open(prog, "w") as f:
        f.write('#include <urrt.h>\n#include <urrt_can.h>\n#include <stdio.h>\n'
                'int main(void) { printf("%d\\n", urrt_field_find("q_actual", 8) == URRT_F_Q_ACTUAL); return 0; }\n')
    env = dict(os.environ, PKG_CONFIG_PATH=os.path.join(prefix, "lib", "pkgconfig"))
    pc = subprocess.run(["sh", "-c", "cc -o %s.bin %s $(pkg-config --cflags --libs urrt) && %s.bin" % (prog, prog, prog)],
                        capture_output=True, text=True, timeout=60, env=env)
    check(pc.returncode == 0 and pc.stdout == "1\n", "install: urrt.pc, urrt.h and liburrt.a build a program (%s)" %
          pc.stderr.strip()[:200])
    os.remove(prog)
    os.remove(prog + ".bin")
    # The checked-in unit is the one for PREFIX=/usr, so that it can be copied as it is.
    usr = make("dist-files", where[0], "PREFIX=/usr")
    dist_unit = os.path.join(args.build, "dist", "urrt-gateway.service")
    check(usr.returncode == 0 and open(dist_unit).read() == open(os.path.join(repo, "gateway", "install",
          "urrt-gateway.service")).read(), "install: for PREFIX=/usr the unit is gateway/install/urrt-gateway.service as it is")
    make("dist-files")
    if subprocess.run(["which", "systemd-analyze"], capture_output=True).returncode == 0:
        # A template is verified as an instance of it (systemd-analyze names one itself).
        for name in ("urrt-gateway.service", "urrt-gateway@.service"):
            v = subprocess.run(["systemd-analyze", "verify", os.path.join(unitdir, name)],
                               capture_output=True, text=True, timeout=60,
                               env=dict(os.environ, MANPATH=os.path.join(prefix, "share", "man")))
            check(v.returncode == 0, "install: systemd-analyze verify accepts %s (%s)" % (name, v.stderr.strip()[:300]))
    with open(conf, "a") as f:
        f.write("# edited\n")
    make("install")
    check(open(conf).read().endswith("# edited\n"), "install: an edited configuration is kept")
    check(tree() == installed, "install: a second install adds nothing")
    u = make("uninstall")
    left = tree()
    check(u.returncode == 0 and left == ["etc/urrt/gateway.ini"] and "was edited: kept" in u.stdout,
          "uninstall: removes every file install put there but the edited configuration (left: %s)" % left[:5])
    os.remove(conf)
    make("install")
    make("uninstall")
    dirs = sorted(os.path.relpath(d, root) for d, _, _ in os.walk(root) if "urrt" in os.path.relpath(d, root))
    check(tree() == [] and dirs == [], "uninstall: an unedited configuration and urrt's own directories go too "
          "(left: %s %s)" % (tree()[:3], dirs[:3]))


def t_cli(args):
    h = subprocess.run([args.gateway, "--help"], capture_output=True, text=True, timeout=10)
    check(h.returncode == 0 and "--check-config" in h.stdout and "[robot NAME]" in h.stdout and
          "state_rate = every|N Hz|off" in h.stdout and "(default 100 ms; 20 ms..10 min)" in h.stdout and
          "Examples:" in h.stdout,
          "--help documents options, the file grammar and examples")
    v = subprocess.run([args.gateway, "--version"], capture_output=True, text=True, timeout=10)
    check(v.returncode == 0 and v.stdout.startswith("urrt-gateway "), "--version")
    u = subprocess.run([args.gateway], capture_output=True, text=True, timeout=10)
    check(u.returncode == 2 and "no CONFIG" in u.stderr, "no CONFIG: usage error")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--only")
    args = ap.parse_args()
    b = args.build
    args.gateway = os.path.join(b, "bin", "urrt-gateway")
    args.sim = os.path.join(b, "bin", "urrt-sim")
    args.sub = os.path.join(b, "tests", "gateway", "lcm_sub")
    args.shim = os.path.abspath(os.path.join(b, "tests", "gateway", "alloc_shim.so"))
    args.jar = os.path.join(b, "urrt_lcmtypes.jar")
    args.lcm_jar = "/usr/share/java/lcm.jar"
    args.tmp = tempfile.mkdtemp(prefix="check-gateway-")
    tests = [
        ("cli", lambda: t_cli(args)),
        ("configs", lambda: t_configs(args)),
        ("install", lambda: t_install(args)),
        ("jar", lambda: t_jar(args)),
        ("values510", lambda: t_values(args, "5.10", 1500)),
        ("values310", lambda: t_values(args, "3.10", 300)),
        ("values18", lambda: t_values(args, "1.8", 300)),
        ("decimation", lambda: t_decimation(args)),
        ("two", lambda: t_two_robots(args)),
        ("restart", lambda: t_restart(args)),
        ("stall", lambda: t_stall(args)),
        ("frozen", lambda: t_frozen(args)),
        ("sigstop", lambda: t_sigstop(args)),
        ("summary", lambda: t_summary(args)),
        ("mismatch", lambda: t_mismatch(args)),
        ("backlog", lambda: t_backlog(args)),
        ("overload", lambda: t_overload(args)),
        ("alloc", lambda: t_allocations(args)),
        ("publish_errors", lambda: t_publish_errors(args)),
        ("publish_reopen", lambda: t_publish_reopen(args)),
        ("rtde_values", lambda: t_rtde_values(args)),
        ("rtde_refused", lambda: t_rtde_refused(args)),
        ("rtde_at_realtime", lambda: t_rtde_at_realtime(args)),
        ("rtde_frequency", lambda: t_rtde_frequency(args)),
        ("rtde_fallback", lambda: t_rtde_fallback(args)),
        ("rtde_restart", lambda: t_restart(args, rtde=True)),
        ("rtde_stall", lambda: t_stall(args, rtde=True)),
        ("rtde_sigstop", lambda: t_sigstop(args, rtde=True)),
        ("rtde_backlog", lambda: t_backlog(args, rtde=True)),
        ("rtde_overload", lambda: t_overload(args, rtde=True)),
        ("rtde_alloc", lambda: t_allocations(args, rtde=True)),
    ]
    for name, fn in tests:
        if args.only and not re.search(args.only, name):
            continue
        t0 = time.monotonic()
        try:
            fn()
        except Exception as e:  # a crashed test is a failure, the others still run
            check(False, "%s: raised %r" % (name, e))
        print("-- %s: %.1f s" % (name, time.monotonic() - t0))
    status = suite.report()
    subprocess.run(["rm", "-rf", args.tmp])
    return status


if __name__ == "__main__":
    sys.exit(main())
