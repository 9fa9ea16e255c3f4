#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""soak_plc.py: the soak's RTDE robot and its PLC, in the qemu VM (SocketCAN on vcan0),
run by make soak beside the host's soak (tests/soak/soak_plc.sh starts it). Written
from the protocols, apart from the gateway's code: frames packed here, RTDE packages
parsed here, the CANopen manager is master.py.

Processes (all in the VM): urrt-sim serving RTDE (a 3.10 controller, --clock
realtime), restarted for each phase with the phase's fault or version; two
urrt-gateways with source = rtde, each behind a recording proxy to the simulator:
  frames    writes input_int_register_24 and input_bit_register_64 from the plain
            frame 0x200 (the PLC's, every 20 ms), sends the clock frame 0x181
            (time in ms since the soak's start, the register read back, validity)
  canopen   CANopen node 5: writes input_int_register_25 and input_bit_register_66
            from RPDO1 0x205 (the manager's, every 20 ms), consumes the manager's
            heartbeat (0x701, 0x1016), sends TPDO1 0x185 (time, the register read
            back, validity) and its EMCYs
The PLC writes a counter that steps every 100 ms (the same value to both), goes
silent, loses its heartbeat, stops the node, as each phase says; the simulator
restarts, freezes, stalls, sends bad packages and text, refuses protocol 2, holds
the registers IN_USE, or is a controller version without them.

Judged from the proxies' records (every package each gateway sent, every data package
the controller sent it), the PLC's own record of what it sent and the frames on the
bus, on the VM's wall clock:
  - every input package carries values the PLC sent before it, never going back within
    a connection; every register the controller reads back is 0 (a restarted
    controller's) or one the PLC sent, never going back within the controller's life
  - no input package while the PLC is silent (its frames or RPDOs stopped for longer
    than timeout_ms, the manager's heartbeat lost, the node stopped), and the first
    within one inputs period after it speaks again, when the session streams
  - no frame or TPDO with its validity bit set on data older than stale_after_ms
  - the node's EMCYs: 0x8250 and 0x8130 once per silence of that kind, each reset once;
    every EMCY raised while not set and reset while set
  - refused sessions write nothing (protocol 2 refused, IN_USE, the version without
    the registers), and the gateway's log says why
  - RSS and descriptors of both gateways flat, both alive to the end and exiting 0

Prints its tables and checks, "N passed, N failed" last.
  soak_plc.py --minutes M --phase-seconds S --out DIR
"""
import argparse
import os
import select
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import master  # noqa: E402  (tests/canopen/master.py, staged beside this file)

FRAME_IN, CLOCK_A = 0x200, 0x181           # the frames gateway's input and clock frame
NODE, MANAGER = 5, 1
RPDO1, TPDO1, EMCY, NODE_HB, MANAGER_HB = 0x200 + NODE, 0x180 + NODE, 0x80 + NODE, 0x700 + NODE, 0x700 + MANAGER
PERIOD = 0.020              # the PLC's frames and RPDOs
STEP = 0.100                # the counter's step
MANAGER_HB_S = 0.100
CONSUMER_MS = 1000          # 0x1016: the manager's heartbeat allowed (the VM's one CPU stalls)
TIMEOUT_MS = 300            # each [input]'s timeout_ms: RPDO1's event timer
MIN_RATE_HZ = 10            # [can] inputs_min_rate: one inputs period 100 ms
BOUND_MS = 500              # [can] stale_after_ms of the clock frame and TPDO1
SILENCE = "2 s"             # the robot's silence_timeout (the emulated CPU stalls)
RTDE_HZ = 25                # each gateway's rtde_frequency: the proxies parse every package
# What a measured time may exceed its bound by on the VM's one emulated CPU (a Python
# thread, a gateway and the simulator share it): the same slack as check-plc-io's VM.
SLACK = 0.35
RSS_ALLOWANCE_KIB = 256
FD_ALLOWANCE = 1
EMCY_DEADLINE, EMCY_HEARTBEAT = 0x8250, 0x8130
RESET_WITHIN_S = 1.0        # a fault's EMCY reset once the PLC speaks again (the VM's stalls included)
EMCY_LINK, EMCY_STALE = 0xFF01, 0xFF02
REG_A, REG_B = 'input_int_register_24', 'input_int_register_25'
TYPE_SIZES = {'BOOL': 1, 'UINT8': 1, 'UINT32': 4, 'UINT64': 8, 'INT32': 4, 'DOUBLE': 8, 'VECTOR3D': 24,
              'VECTOR6D': 48, 'VECTOR6INT32': 24, 'VECTOR6UINT32': 24}
WAIT = 30

# (name, urrt-sim options, the PLC's script: {event: (from, to) as fractions of the phase})
PHASES = [
    ("clean", [], {}),
    ("plc-silent", [], {"frames_off": (0.3, 0.55), "rpdo_off": (0.3, 0.55)}),
    ("hb-lost", [], {"hb_off": (0.3, 0.6)}),
    ("nmt-stop", [], {"nmt_stop": (0.3, 0.55)}),
    ("restart", [], {}),                                         # killed every 3 s, 0.5 s down
    ("freeze", ["--fault", "freeze-after=250,for=3000"], {}),    # 250 of 125 Hz: at 2 s
    ("stall", ["--fault", "stall-after=50,for=3000"], {}),       # 50 of 25 Hz: at 2 s
    ("bad-package", ["--fault", "rtde-bad-package=75"], {}),
    ("text", ["--fault", "rtde-text-every=25"], {}),
    ("refuse-v2", ["--fault", "rtde-refuse-v2"], {}),
    ("in-use", ["--fault", "close-after=75", "--fault", "rtde-hold-inputs,for=1500"], {}),
    ("version", ["--controller", "3.8"], {}),
]
RESTART_UP_S, RESTART_DOWN_S = 3.0, 0.5
# Phases whose sessions the controller refuses: nothing may be written in them.
REFUSED = {"refuse-v2": "protocol 1 only", "version": "does not have", "in-use": "IN_USE"}


def log(msg):
    print(msg)
    sys.stdout.flush()


class Counts:
    def __init__(self):
        self.passed = self.failed = 0

    def check(self, ok, desc):
        if ok:
            self.passed += 1
            log("ok: " + desc)
        else:
            self.failed += 1
            log("FAIL: " + desc)


def packages(buf):
    """Whole RTDE packages at the front of buf: ([(type, payload)], rest)."""
    out = []
    while len(buf) >= 3:
        size, kind = struct.unpack_from(">HB", buf)
        if size < 3:
            return out, b""          # a bad package (the fault): the rest is not parsed
        if len(buf) < size:
            break
        out.append((chr(kind), bytes(buf[3:size])))
        buf = buf[size:]
    return out, buf


class Conn:
    """One connection of a gateway through its proxy."""

    def __init__(self, register, t):
        self.register, self.opened = register, t
        self.sent = []             # (t, type, payload) from the gateway
        self.readback = []         # (t, value of the register) per data package from the controller
        self.in_ids = []           # input recipe ids the controller gave
        self.out_names = []
        self.at = None
        self.closed = None

    def from_gateway(self, kind, p, t):
        self.sent.append((t, kind, p))
        if kind == "O" and len(p) > 8:
            self.out_names = p[8:].decode("ascii", "replace").split(",")

    def from_controller(self, kind, p, t):
        if kind == "I" and p:
            self.in_ids.append(p[0])
        elif kind == "O" and p:
            types = p[1:].decode("ascii", "replace").split(",")
            if self.register in self.out_names and len(types) == len(self.out_names):
                i = self.out_names.index(self.register)
                self.at = 1 + sum(TYPE_SIZES.get(x, 0) for x in types[:i])
        elif kind == "U" and self.at is not None and len(p) >= self.at + 4:
            self.readback.append((t, struct.unpack_from(">i", p, self.at)[0]))

    def inputs(self):
        """(t, register value) of each input package: recipe id > 1, the register first."""
        return [(t, struct.unpack_from(">i", p, 1)[0]) for t, k, p in self.sent
                if k == "U" and len(p) >= 5 and p[0] > 1]


class Proxy(threading.Thread):
    """Forwards a gateway's connections to the simulator, recording both ways."""

    def __init__(self, register):
        super().__init__(daemon=True)
        self.register, self.sim_port = register, None
        self.lsock = socket.socket()
        self.lsock.bind(("127.0.0.1", 0))
        self.lsock.listen(4)
        self.port = self.lsock.getsockname()[1]
        self.conns, self.lock = [], threading.Lock()
        self.refused = 0           # connections the simulator was not there for

    def serve(self, client):
        conn = Conn(self.register, time.time())
        try:
            up = socket.create_connection(("127.0.0.1", self.sim_port), timeout=2)
        except OSError:
            self.refused += 1
            client.close()
            return
        with self.lock:
            self.conns.append(conn)
        # Each direction: (from, to, bytes of an unfinished package, what records a package).
        ways = [[client, up, b"", conn.from_gateway], [up, client, b"", conn.from_controller]]
        try:
            while True:
                r, _, _ = select.select([client, up], [], [], 1.0)
                t = time.time()
                for way in (w for w in ways if w[0] in r):
                    data = way[0].recv(65536)
                    if not data:
                        raise EOFError
                    way[1].sendall(data)
                    pk, way[2] = packages(way[2] + data)
                    with self.lock:
                        for k, p in pk:
                            way[3](k, p, t)
        except (OSError, EOFError):     # either side closed or reset
            pass
        conn.closed = time.time()
        client.close()
        up.close()

    def run(self):
        while True:
            client, _ = self.lsock.accept()
            threading.Thread(target=self.serve, args=(client,), daemon=True).start()


class Plc:
    """The PLC and the CANopen manager's periodic frames, and everything the gateways send."""

    def __init__(self, can, channel):
        self.can = can
        self.tx = can.Bus(interface="socketcan", channel=channel, receive_own_messages=False)
        self.rx = can.Bus(interface="socketcan", channel=channel, receive_own_messages=False,
                          can_filters=[{"can_id": i, "can_mask": 0x7FF, "extended": False}
                                       for i in (CLOCK_A, TPDO1, EMCY, NODE_HB)])
        self.frames_on = self.rpdo_on = self.hb_on = True
        self.value = 1
        self.sent = {"frames": [], "rpdo": []}   # (t, value) of each frame / RPDO1 sent
        self.hb_sent = []                        # t of each manager heartbeat
        self.got = []                            # (t, id, data) of the gateways' frames
        self.errors = 0
        self.stop = threading.Event()
        self.threads = [threading.Thread(target=f, daemon=True) for f in (self.writer, self.reader)]
        for th in self.threads:
            th.start()

    def send(self, cob, data):
        try:
            self.tx.send(self.can.Message(arbitration_id=cob, data=data, is_extended_id=False), timeout=0.05)
            return True
        except self.can.CanError:
            self.errors += 1
            return False

    def writer(self):
        t0 = time.time()
        n, next_hb = 0, 0.0
        while not self.stop.is_set():
            now = time.time()
            self.value = 1 + int((now - t0) / STEP)
            v = self.value
            # Stamped before the send: the gateway may act before send() returns.
            if self.frames_on and self.send(FRAME_IN, struct.pack("<IB", v, 1) + bytes(3)):
                self.sent["frames"].append((now, v))
            if self.rpdo_on and self.send(RPDO1, struct.pack("<IB", v, 1) + bytes(3)):
                self.sent["rpdo"].append((now, v))
            if self.hb_on and now >= next_hb and self.send(MANAGER_HB, b"\x05"):
                self.hb_sent.append(now)
                next_hb = now + MANAGER_HB_S
            n += 1
            time.sleep(max(0.0, t0 + n * PERIOD - time.time()))

    def reader(self):
        while not self.stop.is_set():
            try:
                msg = self.rx.recv(0.2)
            except self.can.CanError:
                continue
            if msg is not None and not msg.is_error_frame:
                self.got.append((msg.timestamp, msg.arbitration_id, bytes(msg.data)))


class Sim:
    """urrt-sim on one RTDE port for the whole soak, restarted per phase."""

    def __init__(self, out, t0):
        self.out, self.port, self.proc = out, 0, None
        self.starts, self.kills, self.bind_retries = 0, 0, 0
        self.lives = []            # the start time of each simulator process

    def start(self, extra):
        end = time.monotonic() + WAIT
        pf = os.path.join(self.out, "sim.port")
        while True:
            if os.path.exists(pf):
                os.unlink(pf)
            version = [] if "--controller" in extra else ["--controller", "3.10"]
            p = subprocess.Popen(["urrt-sim", "--listen", "127.0.0.1:0", "--rtde", "127.0.0.1:%d" % self.port,
                                  "--rtde-port-file", pf, "--clock", "realtime", "--seed", str(self.starts), "-q"] +
                                 version + extra, stdout=open(os.path.join(self.out, "sim.log"), "a"),
                                 stderr=subprocess.STDOUT)
            self.starts += 1
            while not os.path.exists(pf) and p.poll() is None and time.monotonic() < end:
                time.sleep(0.02)
            if os.path.exists(pf):
                self.port, self.proc = int(open(pf).read()), p
                self.lives.append(time.time())
                return
            p.wait()
            if time.monotonic() > end:
                raise RuntimeError("urrt-sim cannot serve RTDE on port %d" % self.port)
            self.bind_retries += 1
            time.sleep(0.1)

    def stop(self, sig=signal.SIGTERM):
        if self.proc is not None:
            self.proc.send_signal(sig)
            self.proc.wait(timeout=WAIT)
            self.proc = None


def robot_can(name, port, can_extra):
    """Both gateways' robot (RTDE through its proxy, the VM's wide bounds), no LCM
    messages, and [can] on vcan0."""
    return """[robot {name}]
host = 127.0.0.1
port = {port}
source = rtde
rtde_frequency = {hz} Hz
silence_timeout = {silence}
backoff_initial = 50 ms
backoff_max = 500 ms

[lcm]
url = udpm://239.255.76.67:7667?ttl=0
state_rate = off
joints_rate = off
tool_rate = off
status_rate = off
gateway_rate = off

[can]
interface = vcan0
{can_extra}
stale_after_ms = {bound}
inputs_min_rate = {rate} Hz
""".format(name=name, port=port, hz=RTDE_HZ, silence=SILENCE, can_extra=can_extra, bound=BOUND_MS, rate=MIN_RATE_HZ)


def config_frames(port, t0):
    return robot_can("armf", port, "heartbeat_id = 0x7F0") + """
[input plc_frames]
id = 0x{fin:X}
timeout_ms = {timeout}
on_silence = stop
signal = {reg} @0|32 intel unsigned name=counter
signal = input_bit_register_64 @32|1 intel unsigned name=run

[frame clock]
id = 0x{clock:X}
period_ms = 40
signal = time @0|32 intel unsigned factor=0.001 offset={t0} name=time_ms
signal = {reg} @32|24 intel unsigned name=echo
validity_bit = 63
""".format(fin=FRAME_IN, timeout=TIMEOUT_MS, reg=REG_A, clock=CLOCK_A, t0=t0)


def config_canopen(port, t0):
    return robot_can("armc", port, "") + """
[canopen]
node_id = {node}
heartbeat_ms = 100

[input plc_rpdo]
timeout_ms = {timeout}
on_silence = stop
signal = {reg} @0|32 intel unsigned name=counter
signal = input_bit_register_66 @32|8 intel unsigned name=run

[frame clock]
period_ms = 40
stale_policy = invalid
signal = time @0|32 intel unsigned factor=0.001 offset={t0} name=time_ms
signal = {reg} @32|16 intel unsigned name=echo
validity_bit = 56
""".format(node=NODE, timeout=TIMEOUT_MS, reg=REG_B, t0=t0)


def proc_sample(pid):
    rss = 0
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1])
    return rss, len(os.listdir("/proc/%d/fd" % pid))


def configure_node(m):
    """The manager's part: boot-up, the consumer heartbeat, NMT start (master.py's SDO client)."""
    m.wait("the node's boot-up", m.heartbeat(0x00), limit=60)
    m.write_u(0x1016, 1, MANAGER << 16 | CONSUMER_MS, 4)
    m.check("0x1016 sub 1 holds the manager's heartbeat", m.read_u(0x1016, 1) == MANAGER << 16 | CONSUMER_MS)
    m.nmt(0x01)
    m.wait("the node's OPERATIONAL heartbeat", m.heartbeat(0x05))


class Run:
    """What happened: phases, the PLC's silences, the simulator's lives."""

    def __init__(self, t0):
        self.t0 = t0               # the clock signals' offset: ms since then
        self.phases = []           # (name, start t, end t)
        self.silent = {"frames": [], "rpdo": []}   # (from t, to t): the input must not be written
        self.resumes = {"frames": [], "rpdo": []}  # (t, phase): it must be written again soon
        self.emcy_expected = []    # [code, fault's start t, its end t]: raised once, reset once

    def phase_at(self, t):
        for i, (name, a, b) in enumerate(self.phases):
            if a <= t < b:
                return i
        return len(self.phases) - 1


def run(args, c):
    import can
    out = args.out
    t0 = int(time.time())
    sim = Sim(out, t0)
    plc = Plc(can, "vcan0")
    m = master.Master("vcan0", NODE)
    proxies = {"frames": Proxy(REG_A), "rpdo": Proxy(REG_B)}
    R = Run(t0)
    gws = {}
    samples = {"frames": [], "rpdo": []}
    deadline = time.monotonic() + args.minutes * 60
    cycle_s = len(PHASES) * args.phase_seconds
    warm = len(PHASES) if args.minutes * 60 >= 2 * cycle_s else 1
    try:
        sim.start(PHASES[0][1])
        for p in proxies.values():
            p.sim_port = sim.port
            p.start()
        with open(os.path.join(out, "frames.ini"), "w") as f:
            f.write(config_frames(proxies["frames"].port, t0))
        with open(os.path.join(out, "canopen.ini"), "w") as f:
            f.write(config_canopen(proxies["rpdo"].port, t0))
        for key, ini in (("frames", "frames.ini"), ("rpdo", "canopen.ini")):
            gws[key] = subprocess.Popen(["urrt-gateway", os.path.join(out, ini)],
                                        stdout=open(os.path.join(out, key + "-gw.log"), "w"),
                                        stderr=subprocess.STDOUT)
        configure_node(m)
        log("soak-plc: %.1f min, %d phases of %d s, dir %s" % (args.minutes, len(PHASES), args.phase_seconds, out))
        n = 0
        while time.monotonic() < deadline:
            name, extra, script = PHASES[n % len(PHASES)]
            start = time.time()
            if n > 0:
                sim.stop()
                sim.start(extra)
            R.phases.append((name, start, float("inf")))
            end_m = min(time.monotonic() + args.phase_seconds, deadline)
            t_phase0 = time.monotonic()
            next_kill = t_phase0 + RESTART_UP_S
            done = set()
            while time.monotonic() < end_m:
                for key, g in gws.items():
                    if g.poll() is not None:
                        raise RuntimeError("the %s gateway exited (%s) in phase %s" % (key, g.returncode, name))
                el = (time.monotonic() - t_phase0) / args.phase_seconds
                for ev, (a, b) in script.items():
                    if el >= a and (ev, "on") not in done:
                        done.add((ev, "on"))
                        act(ev, True, plc, m, R, n)
                    if el >= b and (ev, "off") not in done:
                        done.add((ev, "off"))
                        act(ev, False, plc, m, R, n)
                if name == "restart" and time.monotonic() >= next_kill:
                    sim.stop(signal.SIGKILL)
                    sim.kills += 1
                    time.sleep(RESTART_DOWN_S)
                    sim.start([])
                    next_kill = time.monotonic() + RESTART_UP_S
                time.sleep(0.05)
            for ev in script:                      # a phase cut short by the deadline
                if (ev, "on") in done and (ev, "off") not in done:
                    act(ev, False, plc, m, R, n)
            R.phases[-1] = (name, start, time.time())
            n += 1
            for key, g in gws.items():
                rss, fds = proc_sample(g.pid)
                samples[key].append((n, name, rss, fds))
        sim.stop()
        time.sleep(0.5)
        exits = {}
        for key, g in gws.items():
            alive = g.poll() is None
            g.send_signal(signal.SIGTERM)
            exits[key] = (alive, g.wait(timeout=WAIT))
    finally:
        plc.stop.set()
        for g in gws.values():
            if g.poll() is None:
                g.kill()
        sim.stop(signal.SIGKILL)
    judge(c, R, plc, proxies, sim, samples, warm, exits, out)


def act(ev, on, plc, m, R, n):
    """A scripted event of the PLC: on = the fault begins."""
    t = time.time()
    if ev == "frames_off":
        plc.frames_on = not on
    elif ev == "rpdo_off":
        plc.rpdo_on = not on
        emcy_window(R, EMCY_DEADLINE, on, t)
    elif ev == "hb_off":
        plc.hb_on = not on
        emcy_window(R, EMCY_HEARTBEAT, on, t)
        if on:
            R.silent["rpdo"].append((t + CONSUMER_MS / 1e3 + SLACK, None))
        else:
            R.silent["rpdo"][-1] = (R.silent["rpdo"][-1][0], t)
            R.resumes["rpdo"].append((t, n))
    elif ev == "nmt_stop":
        m.nmt(0x02 if on else 0x01)
        if on:
            R.silent["rpdo"].append((t + SLACK, None))
        else:
            R.silent["rpdo"][-1] = (R.silent["rpdo"][-1][0], t)
            R.resumes["rpdo"].append((t, n))


def emcy_window(R, code, on, t):
    if on:
        R.emcy_expected.append([code, t, None])
    else:
        R.emcy_expected[-1][2] = t


def gaps(sent, timeout_s):
    """Silences in a PLC's record: (last write t, next write t) farther apart than the timeout."""
    return [(a[0], b[0]) for a, b in zip(sent, sent[1:]) if b[0] - a[0] > timeout_s]


def judge(c, R, plc, proxies, sim, samples, warm, exits, out):
    t_end = R.phases[-1][2]
    timeout_s = TIMEOUT_MS / 1e3
    log("")
    log("soak-plc per phase (summed over passes): input packages written; the PLC's silences; "
        "the node's EMCYs raised/reset")
    rows = {}
    for key in ("frames", "rpdo"):
        # The silences the record shows (the scripted ones and any the VM's stalls made).
        for a, b in gaps(plc.sent[key], timeout_s):
            R.silent[key].append((a + timeout_s + SLACK, b))
            R.resumes[key].append((b, R.phase_at(b)))
    # ---- values written and read back ----
    for key, reg in (("frames", REG_A), ("rpdo", REG_B)):
        sent = plc.sent[key]
        first_at = {}
        for t, v in sent:
            first_at.setdefault(v, t)
        conns = sorted(proxies[key].conns, key=lambda x: x.opened)
        bad_value = bad_order = n_u = 0
        examples = []
        us = []
        for conn in conns:
            last = None
            for t, v in conn.inputs():
                n_u += 1
                us.append((t, v, conn))
                if v not in first_at or first_at[v] > t:
                    bad_value += 1
                    examples.append("%s package at %.3f: %d never sent before it" % (key, t, v))
                if last is not None and v < last:
                    bad_order += 1
                    examples.append("%s package at %.3f: %d after %d" % (key, t, v, last))
                last = v
        for e in examples[:10]:
            log("  " + e)
        c.check(n_u > 0 and bad_value == 0 and bad_order == 0,
                "%s: each of %d input packages carries a value the PLC sent before it, none going back in its "
                "connection (%d invented, %d out of order)" % (key, n_u, bad_value, bad_order))
        # Read back: all data packages of all connections, per simulator life.
        rb = sorted((t, v) for conn in conns for t, v in conn.readback)
        bad_rb = back_rb = 0
        examples = []
        lives = sim.lives + [float("inf")]
        for i in range(len(lives) - 1):
            last = 0
            for t, v in (x for x in rb if lives[i] <= x[0] < lives[i + 1]):
                if v != 0 and (v not in first_at or first_at[v] > t):
                    bad_rb += 1
                    examples.append("%s read back at %.3f: %d never sent before it" % (reg, t, v))
                elif v < last:
                    back_rb += 1
                    examples.append("%s read back at %.3f: %d after %d" % (reg, t, v, last))
                last = max(last, v)
        for e in examples[:10]:
            log("  " + e)
        c.check(len(rb) > 0 and bad_rb == 0 and back_rb == 0,
                "%s: each of %d values the controller read back is 0 (a restarted controller's) or one the PLC "
                "wrote, never going back in the controller's life (%d invented, %d out of order)" %
                (reg, len(rb), bad_rb, back_rb))
        # ---- silence ----
        loud = [(t, v) for t, v, _ in us for a, b in R.silent[key] if a <= t < (b if b is not None else t_end)]
        for t, v in loud[:10]:
            log("  %s package at %.3f (%s) while the PLC was silent" % (key, t, R.phases[R.phase_at(t)][0]))
        c.check(not loud, "%s: no input package while the PLC is silent (%d silences; %d packages in them)" %
                (key, len(R.silent[key]), len(loud)))
        late, judged = [], 0
        u_times = sorted(t for t, _, _ in us)
        for t_r, ph in R.resumes[key]:
            # Judged when one connection streamed inputs from before until after the resumption.
            streaming = any(cn.opened < t_r - 1.0 and (cn.closed is None or cn.closed > t_r + 1.0) and
                            any(t < t_r for t, _ in cn.inputs()) for cn in conns)
            if not streaming:
                continue
            judged += 1
            nxt = next((t for t in u_times if t >= t_r), None)
            if nxt is None or nxt - t_r > 1.0 / MIN_RATE_HZ + SLACK:
                late.append((t_r, nxt))
        for t_r, nxt in late[:10]:
            log("  %s: the PLC spoke again at %.3f, the next package %s" %
                (key, t_r, "at %.3f" % nxt if nxt else "never"))
        c.check(not late, "%s: after a silence, the first input package within one inputs period (%d ms) + %.0f ms "
                "slack (%d resumptions judged, %d late)" % (key, 1000 // MIN_RATE_HZ, SLACK * 1e3, judged, len(late)))
        for i, (name, a, b) in enumerate(R.phases):
            row = rows.setdefault(name, {"n": 0, "frames": 0, "rpdo": 0, "sil_frames": 0, "sil_rpdo": 0,
                                         "conn_frames": 0, "conn_rpdo": 0})
            if key == "frames":
                row["n"] += 1
            row[key] += sum(1 for t in u_times if a <= t < b)
            row["sil_" + key] += sum(1 for s, _ in R.silent[key] if a <= s < b)
            row["conn_" + key] += sum(1 for cn in conns if a <= cn.opened < b)
    # ---- refused sessions ----
    for name, why in REFUSED.items():
        idx = [i for i, p in enumerate(R.phases) if p[0] == name]
        written = 0
        for key in ("frames", "rpdo"):
            for cn in proxies[key].conns:
                for i in idx:
                    a, b = R.phases[i][1], R.phases[i][2]
                    # A connection opened in the phase (after the simulator's restart at its start).
                    if a + 0.2 <= cn.opened < b and (name != "in-use" or 0 in cn.in_ids):
                        written += len(cn.inputs())
        logs = "".join(open(os.path.join(out, k + "-gw.log"), errors="replace").read() for k in ("frames", "rpdo"))
        c.check(idx and written == 0 and why in logs,
                "%s: nothing written in a session the controller refused (%d packages), and the gateways' logs "
                "say '%s'" % (name, written, why))
    # ---- frames and TPDOs on old data ----
    stale = {CLOCK_A: 0, TPDO1: 0}
    valid = {CLOCK_A: 0, TPDO1: 0}
    oldest = {CLOCK_A: 0.0, TPDO1: 0.0}
    for t, ident, d in plc.got:
        if ident == CLOCK_A and len(d) == 8 and d[7] & 0x80 or ident == TPDO1 and len(d) == 8 and d[7] & 1:
            valid[ident] += 1
            age = t - (R.t0 + struct.unpack_from("<I", d)[0] / 1e3)
            oldest[ident] = max(oldest[ident], age)
            if age > BOUND_MS / 1e3 + SLACK:
                stale[ident] += 1
    for ident, what in ((CLOCK_A, "frames: the clock frame 0x181"), (TPDO1, "canopen: TPDO1 0x185")):
        c.check(valid[ident] > 0 and stale[ident] == 0,
                "%s: none of %d with its validity bit set on data older than %d ms + %.0f ms (%d are; oldest %.1f ms)"
                % (what, valid[ident], BOUND_MS, SLACK * 1e3, stale[ident], oldest[ident] * 1e3))
    # ---- EMCYs ----
    set_codes, bad_pairs = {}, []
    per_phase = {}
    for t, ident, d in plc.got:
        if ident != EMCY or len(d) != 8:
            continue
        code = struct.unpack_from("<H", d)[0]
        i = R.phase_at(t)
        if code == 0:
            ended = struct.unpack_from("<H", d, 3)[0]
            if not set_codes.get(ended):
                bad_pairs.append("reset of 0x%04X at %.3f while not set" % (ended, t))
            set_codes[ended] = False
            per_phase.setdefault((i, ended), [0, 0])[1] += 1
        else:
            if set_codes.get(code):
                bad_pairs.append("0x%04X raised at %.3f while set" % (code, t))
            set_codes[code] = True
            per_phase.setdefault((i, code), [0, 0])[0] += 1
    for e in bad_pairs[:10]:
        log("  " + e)
    c.check(not bad_pairs, "canopen: every EMCY raised while not set and reset while set (%d not)" % len(bad_pairs))
    # Each scripted fault: its EMCY raised once while it lasts, reset once soon after it ends.
    emcys = [(t, struct.unpack_from("<H", d)[0], struct.unpack_from("<H", d, 3)[0]) for t, i, d in plc.got
             if i == EMCY and len(d) == 8]
    wrong = []
    for code, a, b in R.emcy_expected:
        raised = sum(1 for t, k, _ in emcys if k == code and a <= t <= b + SLACK)
        reset = sum(1 for t, k, ended in emcys if k == 0 and ended == code and b <= t <= b + RESET_WITHIN_S)
        if raised != 1 or reset != 1:
            wrong.append("%s 0x%04X from %.3f to %.3f: raised %d, reset %d" %
                         (R.phases[R.phase_at(a)][0], code, a, b, raised, reset))
    for e in wrong[:10]:
        log("  " + e)
    c.check(R.emcy_expected and not wrong,
            "canopen: each RPDO deadline and each lost manager heartbeat raises its EMCY (0x8250, 0x8130) once while "
            "it lasts and resets it once within %.1f s of its end (%d faults; %d not)" %
            (RESET_WITHIN_S, len(R.emcy_expected), len(wrong)))
    for row_name in rows:
        rows[row_name]["emcy"] = ["%04X %d/%d" % (code, v[0], v[1]) for (i, code), v in sorted(per_phase.items())
                                  if R.phases[i][0] == row_name]
    log("%-12s %3s %8s %8s %6s %6s %6s %6s  %s" % ("phase", "n", "U frames", "U rpdo", "sil-f", "sil-r", "conn-f",
                                                   "conn-r", "EMCY raised/reset"))
    for name, _, _ in PHASES:
        r = rows.get(name)
        if r:
            agg = {}
            for e in r["emcy"]:
                code, rr = e.split()
                a, b = rr.split("/")
                x = agg.setdefault(code, [0, 0])
                x[0] += int(a)
                x[1] += int(b)
            log("%-12s %3d %8d %8d %6d %6d %6d %6d  %s" %
                (name, r["n"], r["frames"], r["rpdo"], r["sil_frames"], r["sil_rpdo"], r["conn_frames"],
                 r["conn_rpdo"], " ".join("%s %d/%d" % (k, v[0], v[1]) for k, v in sorted(agg.items())) or "-"))
    log("simulator: %d starts, %d killed, %d binds retried; proxies: %d connections refused (no simulator); "
        "PLC: %d frames, %d RPDOs, %d send errors" %
        (sim.starts, sim.kills, sim.bind_retries, sum(p.refused for p in proxies.values()),
         len(plc.sent["frames"]), len(plc.sent["rpdo"]), plc.errors))
    # ---- the gateways ----
    for key, (alive, rc) in sorted(exits.items()):
        c.check(alive and rc == 0, "the %s gateway ran through every phase and exited 0 on SIGTERM (rc %s)" % (key, rc))
    for key, s in sorted(samples.items()):
        if len(s) <= warm:
            c.check(False, "%s gateway's RSS and fds: the soak was too short to sample after the warm-up" % key)
            continue
        _, wname, rss0, fd0 = s[warm - 1]
        _, _, rss1, fd1 = s[-1]
        c.check(rss1 <= rss0 + RSS_ALLOWANCE_KIB and fd1 <= fd0 + FD_ALLOWANCE,
                "%s gateway's RSS and descriptors flat: RSS %d -> %d KiB (peak %d), fds %d -> %d" %
                (key, rss0, rss1, max(x[2] for x in s[warm - 1:]), fd0, fd1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=10)
    ap.add_argument("--phase-seconds", type=int, default=10)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    c = Counts()
    try:
        run(args, c)
    except Exception as e:  # a broken soak is a failure, reported as one
        import traceback
        traceback.print_exc()
        c.check(False, "soak-plc: %r" % e)
    print("%d passed, %d failed" % (c.passed, c.failed))
    sys.stdout.flush()
    # Not sys.exit: the bus threads' exit would want libgcc_s, which the VM lacks,
    # and its complaint would follow the result line.
    os._exit(1 if c.failed else 0)


if __name__ == "__main__":
    main()
