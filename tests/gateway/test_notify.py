#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-notify: urrt-gateway under systemd's notify protocol (Type=notify).

The test is the service manager: it binds its own datagram socket, abstract
("@name") or a path, hands it to the gateway as NOTIFY_SOCKET with a
WATCHDOG_USEC, and reads what comes: READY=1 after the start, STATUS= lines
that follow the robot, WATCHDOG=1 at half the period, none while the
gateway is stopped (SIGSTOP: its loop no longer runs), pings again after
SIGCONT, STOPPING=1 on SIGTERM. Every wait is for a datagram or a process,
bounded so that a hang fails; the one window that must stay silent is
itself the event (more than two ping periods without a datagram).

Usage: test_notify.py --build DIR
"""
import argparse
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import suite  # noqa: E402  checks and their report
from suite import check  # noqa: E402

# Upper bound of any wait: reached only when something is broken.
WAIT = 60
# WATCHDOG_USEC the tests give: pings every 200 ms.
WATCHDOG_US = 400000



def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("", 0))
        return s.getsockname()[1]


def wait_file(path, proc, seconds=WAIT):
    """Polls for a file a process writes (its port), bounded; False if the process ends first."""
    end = time.monotonic() + seconds
    while time.monotonic() < end and proc.poll() is None:
        if os.path.exists(path) and os.path.getsize(path) > 0:
            return True
        time.sleep(0.02)
    return os.path.exists(path) and os.path.getsize(path) > 0


class Gateway:
    """urrt-sim and urrt-gateway reading it, in a directory of their own; close() stops both."""

    def __init__(self, args, name, ini_extra="", env=None, robot_extra="", robot_port=None):
        """robot_port: where the robot is (nothing need listen there); None: a simulator's."""
        self.dir = tempfile.mkdtemp(prefix="%s-" % name, dir=args.tmp)
        self.procs = []
        if robot_port is None:
            port_file = os.path.join(self.dir, "sim.port")
            self.sim = self._start([args.sim, "--listen", "127.0.0.1:0", "--port-file", port_file, "-q",
                                    "--version", "5.10"], "sim.log")
            if not wait_file(port_file, self.sim):
                raise RuntimeError("urrt-sim did not listen: " + self.text("sim.log")[-300:])
            robot_port = int(open(port_file).read())
        self.ini = os.path.join(self.dir, "gw.ini")
        with open(self.ini, "w") as f:
            f.write("[lcm]\nurl = udpm://239.255.76.67:%d?ttl=0\n[robot r%d]\nhost = 127.0.0.1\nport = %d\n%s\n%s"
                    % (free_udp_port(), os.getpid(), robot_port, robot_extra, ini_extra))
        self.gw = self._start([args.gateway, self.ini], "gw.log", env)

    def _start(self, argv, log, env=None):
        e = {k: v for k, v in os.environ.items() if k not in ("NOTIFY_SOCKET", "WATCHDOG_USEC", "WATCHDOG_PID")}
        e.update(env or {})
        p = subprocess.Popen(argv, stdout=open(os.path.join(self.dir, log), "w"), stderr=subprocess.STDOUT, env=e)
        self.procs.append(p)
        return p

    def text(self, log):
        with open(os.path.join(self.dir, log)) as f:
            return f.read()

    def close(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.send_signal(signal.SIGCONT)
                p.terminate()
            try:
                p.wait(WAIT)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


class Notify:
    """The service manager's end: a datagram socket; each message is (monotonic time, {KEY: value})."""

    def __init__(self, name):
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(name if not name.startswith("@") else "\0" + name[1:])
        self.name = name
        self.messages = []

    def receive(self, seconds):
        """The next datagram within seconds, or None."""
        self.sock.settimeout(max(seconds, 0.001))
        try:
            data = self.sock.recv(4096)
        except socket.timeout:
            return None
        fields = dict(line.split("=", 1) for line in data.decode().splitlines() if "=" in line)
        self.messages.append((time.monotonic(), fields))
        return fields

    def wait(self, pred, seconds=WAIT):
        """Datagrams until one satisfies pred (returned), or None after seconds."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            m = self.receive(end - time.monotonic())
            if m is not None and pred(m):
                return m
        return None

    def close(self):
        self.sock.close()


def env_for(notify, watchdog_us=WATCHDOG_US, pid=None):
    e = {"NOTIFY_SOCKET": notify.name, "WATCHDOG_USEC": str(watchdog_us)}
    if pid is not None:
        e["WATCHDOG_PID"] = str(pid)
    return e


def t_protocol(args, name):
    """READY, STATUS, pings at half the period, none while stopped, again after SIGCONT, STOPPING."""
    what = "abstract" if name.startswith("@") else "path"
    n = Notify(name)
    g = Gateway(args, "notify-" + what, env=env_for(n))
    half = WATCHDOG_US / 2e6
    try:
        first = n.wait(lambda m: True)
        check(first is not None and first.get("READY") == "1",
              "%s: the first message is READY=1 (%s)" % (what, first))
        up = n.wait(lambda m: m.get("STATUS", "").startswith("robots up 1/1, oldest data "))
        check(up is not None and up["STATUS"].endswith(" ms"),
              "%s: STATUS says the robot is up, with its data's age (%s)" % (what, up and up["STATUS"]))
        start = len(n.messages)
        n.wait(lambda m: len([1 for _, f in n.messages[start:] if f.get("WATCHDOG") == "1"]) >= 11)
        pings = [t for t, f in n.messages[start:] if f.get("WATCHDOG") == "1"]
        gaps = sorted(b - a for a, b in zip(pings, pings[1:]))
        # Never early (the loop pings when the deadline has come); late only by a preemption.
        check(len(gaps) == 10 and gaps[0] >= half * 0.9 and gaps[len(gaps) // 2] <= half * 1.5,
              "%s: WATCHDOG=1 every %.0f ms (gaps %s ms)" % (what, half * 1e3, [round(x * 1e3) for x in gaps]))
        g.gw.send_signal(signal.SIGSTOP)
        # A datagram sent just before the stop may still be queued: drain what came
        # until one ping period after the signal, then listen for more than two periods.
        while n.receive(half) is not None:
            pass
        silent_from = time.monotonic()
        late = n.receive(half * 2.5)
        check(late is None, "%s: nothing while the gateway is stopped (%.0f ms window: %s)" %
              (what, (time.monotonic() - silent_from) * 1e3, late))
        g.gw.send_signal(signal.SIGCONT)
        again = n.wait(lambda m: m.get("WATCHDOG") == "1")
        check(again is not None, "%s: WATCHDOG=1 again after SIGCONT" % what)
        g.gw.terminate()
        stopping = n.wait(lambda m: "STOPPING" in m)
        check(stopping is not None and stopping["STOPPING"] == "1", "%s: STOPPING=1 on SIGTERM" % what)
        check(g.gw.wait(WAIT) == 0, "%s: the gateway then exits 0" % what)
    finally:
        g.close()
        n.close()


def t_idle(args):
    """A robot that never answers: the loop is idle between the link's attempts and still pings on
    time, every half period, because the ping is one of the deadlines it sleeps until."""
    n = Notify("@urrt-notify-idle-%d" % os.getpid())
    half = 0.05
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        closed = s.getsockname()[1]  # nothing listens there once closed
    g = Gateway(args, "notify-idle", env=env_for(n, watchdog_us=int(half * 2e6)),
                robot_extra="backoff_initial = 5 s\nbackoff_max = 5 s\n", robot_port=closed)
    try:
        check(n.wait(lambda m: m.get("READY") == "1") is not None, "idle: READY=1")
        start = len(n.messages)
        n.wait(lambda m: len([1 for _, f in n.messages[start:] if f.get("WATCHDOG") == "1"]) >= 21)
        pings = [t for t, f in n.messages[start:] if f.get("WATCHDOG") == "1"]
        gaps = sorted(b - a for a, b in zip(pings, pings[1:]))
        check(len(gaps) == 20 and gaps[0] >= half * 0.9 and gaps[len(gaps) // 2] <= half * 1.4,
              "idle: WATCHDOG=1 every %.0f ms with no data to wake the loop (gaps %s ms)" %
              (half * 1e3, [round(x * 1e3) for x in gaps]))
        status = [f["STATUS"] for _, f in n.messages if "STATUS" in f]
        check(status and status[-1] == "robots up 0/1, oldest data none",
              "idle: STATUS says no robot is up, no data (%s)" % status[-1:])
    finally:
        g.close()
        n.close()


def t_other_pid(args):
    """WATCHDOG_PID names another process: the watchdog is not ours, no pings; READY and STATUS still come."""
    n = Notify("@urrt-notify-pid-%d" % os.getpid())
    g = Gateway(args, "notify-pid", env=env_for(n, pid=os.getpid()))
    try:
        check(n.wait(lambda m: "STATUS" in m) is not None, "other pid: STATUS comes")
        end = time.monotonic() + 4 * WATCHDOG_US / 1e6
        while time.monotonic() < end:
            n.receive(end - time.monotonic())
        pings = [f for _, f in n.messages if "WATCHDOG" in f]
        check(n.messages[0][1].get("READY") == "1" and not pings,
              "other pid: READY=1, no WATCHDOG=1 in %.1f s (%d)" % (4 * WATCHDOG_US / 1e6, len(pings)))
    finally:
        g.close()
        n.close()


def t_outside(args):
    """No NOTIFY_SOCKET: no word of systemd; a bad one: a warning, and the gateway runs on."""
    g = Gateway(args, "notify-none")
    try:
        ok = wait_started(g)
        check(ok and "systemd" not in g.text("gw.log"), "no NOTIFY_SOCKET: the gateway runs, silent about systemd")
    finally:
        g.close()
    g = Gateway(args, "notify-bad", env={"NOTIFY_SOCKET": "relative/socket"})
    try:
        ok = wait_started(g)
        log = g.text("gw.log")
        check(ok and 'NOTIFY_SOCKET="relative/socket" is not an AF_UNIX socket' in log and g.gw.poll() is None,
              "a bad NOTIFY_SOCKET: a warning that says why, and the gateway runs (%s)" % log.strip()[-200:])
    finally:
        g.close()


def wait_started(g):
    end = time.monotonic() + WAIT
    while time.monotonic() < end and g.gw.poll() is None:
        if "started:" in g.text("gw.log"):
            return True
        time.sleep(0.02)
    return False


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    args = ap.parse_args()
    args.gateway = os.path.join(args.build, "bin", "urrt-gateway")
    args.sim = os.path.join(args.build, "bin", "urrt-sim")
    args.tmp = tempfile.mkdtemp(prefix="check-notify-")
    tests = [
        ("abstract", lambda: t_protocol(args, "@urrt-notify-%d" % os.getpid())),
        ("path", lambda: t_protocol(args, os.path.join(args.tmp, "notify.sock"))),
        ("idle", lambda: t_idle(args)),
        ("other_pid", lambda: t_other_pid(args)),
        ("outside", lambda: t_outside(args)),
    ]
    for name, fn in tests:
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
