#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-metrics: urrt-gateway's Prometheus textfile ([gateway] metrics_file).

Each file the gateway renames into place is read (a new inode is the event
waited for, polled with a bound) and parsed here: promtool (Debian's
prometheus package) must accept it, every family has HELP and TYPE, and the
values agree with what is seen independently: the robot's link up while
urrt-sim sends and down while it is stopped, packets at the simulator's
rate, the CAN frames and EMCYs in the CAN log the gateway writes, the
CANopen node's NMT state. A directory that does not exist is a write error
logged and counted, never fatal; bad keys are refused with file and line.

Usage: test_metrics.py --build DIR
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_notify as tn  # noqa: E402  (the Gateway harness, and check)

WAIT = tn.WAIT
NODE = 5
SAMPLE = re.compile(r'^([a-zA-Z_:][a-zA-Z0-9_:]*)(\{([^}]*)\})? (\S+)$')
# The simulator's rate (e-series, 5.10).
RATE_HZ = 500
# A robot that is stopped goes silent within 100 ms.
ROBOT = "silence_timeout = 100 ms\nbackoff_initial = 100 ms\nbackoff_max = 200 ms\nconnect_timeout = 500 ms\n"
CAN = ("[can]\ninterface = log:%s\n[canopen]\nnode_id = %d\nnmt_start = operational\n[frame tpdo1]\nperiod_ms = 10\n"
       "signal = q_actual[0] @0|16 intel signed factor=0.0002 min=-6.3 max=6.3 name=q0\n")


def parse(text):
    """{(name, labels as a sorted tuple): value}, {family: type}, {family: help}; raises on a bad line."""
    samples, types, helps = {}, {}, {}
    for line in text.splitlines():
        if line.startswith("# HELP "):
            name, help_text = line[7:].split(" ", 1)
            helps[name] = help_text
        elif line.startswith("# TYPE "):
            name, kind = line[7:].split(" ")
            types[name] = kind
        else:
            m = SAMPLE.match(line)
            if m is None:
                raise ValueError("not a sample: %r" % line)
            labels = tuple(sorted(tuple(kv.split("=", 1)) for kv in m.group(3).split(","))) if m.group(3) else ()
            samples[(m.group(1), tuple((k, v.strip('"')) for k, v in labels))] = float(m.group(4))
    return samples, types, helps


def value(samples, name, **labels):
    return samples.get((name, tuple(sorted(labels.items()))))


class Files:
    """The metrics file as each rename leaves it: next() waits for a new inode."""

    def __init__(self, path, proc):
        self.path = path
        self.proc = proc
        self.inode = None

    def next(self, seconds=WAIT):
        """(monotonic time seen, mtime in ns, text) of the next file; None after seconds."""
        end = time.monotonic() + seconds
        while time.monotonic() < end and self.proc.poll() is None:
            try:
                with open(self.path) as f:
                    st = os.fstat(f.fileno())
                    if st.st_ino != self.inode:
                        self.inode = st.st_ino
                        return time.monotonic(), st.st_mtime_ns, f.read()
            except FileNotFoundError:
                pass
            time.sleep(0.01)
        return None

    def until(self, pred, seconds=WAIT):
        """Files until one's samples satisfy pred: (samples, text, mtime in ns), or None."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            f = self.next(end - time.monotonic())
            if f is None:
                return None
            samples = parse(f[2])[0]
            if pred(samples):
                return samples, f[2], f[1]
        return None


def emcys_in(log):
    count = 0
    for line in open(log) if os.path.exists(log) else []:
        m = re.match(r"\(\d+\.\d+\) \S+ ([0-9A-F]+)#", line)
        count += m is not None and int(m.group(1), 16) == 0x80 + NODE
    return count


def frames_in(log):
    return sum(1 for line in open(log) if re.match(r"\(\d+\.\d+\) \S+ [0-9A-F]+#", line))


def t_format(args):
    """promtool accepts the file, every family has HELP and TYPE, counters end in _total, renames are whole."""
    d = tempfile.mkdtemp(dir=args.tmp)
    path, canlog = os.path.join(d, "urrt.prom"), os.path.join(d, "can.log")
    g = tn.Gateway(args, "metrics-format", robot_extra=ROBOT,
                   ini_extra="[gateway]\nmetrics_file = %s\nmetrics_interval = 100 ms\n" % path +
                   CAN % (canlog, NODE))
    files = Files(path, g.gw)
    try:
        got = files.until(lambda s: value(s, "urrt_robot_up", robot="r%d" % os.getpid()) == 1)
        tn.check(got is not None, "format: a file says the robot is up")
        samples, text, _ = got
        pc = subprocess.run(["promtool", "check", "metrics"], input=text, capture_output=True, text=True)
        tn.check(pc.returncode == 0 and pc.stdout.strip() == "" and pc.stderr.strip() == "",
                 "format: promtool check metrics accepts it (%s%s)" % (pc.stdout.strip()[:300], pc.stderr.strip()[:300]))
        _, types, helps = parse(text)
        names = set(n for n, _ in samples)
        tn.check(names == set(types) == set(helps), "format: every family has HELP and TYPE (without: %s)" %
                 sorted((names - set(types)) | (names - set(helps))))
        wrong = [n for n, t in types.items() if (t == "counter") != n.endswith("_total") or not n.startswith("urrt_")]
        tn.check(not wrong and len(types) >= 18, "format: %d families, urrt_ names, counters and only they end in "
                 "_total (%s)" % (len(types), wrong))
        whole = 0
        for _ in range(20):
            f = files.next()
            whole += f is not None and f[2].endswith("urrt_metrics_write_errors_total 0\n") and bool(parse(f[2])[0])
        tn.check(whole == 20, "format: 20 renamed files in a row, each whole (%d)" % whole)
    finally:
        g.close()
    tn.check(os.path.exists(path) and not os.path.exists(path + ".tmp"),
             "format: after SIGTERM the file is there, no PATH.tmp left behind")


def t_values(args):
    """The values against the simulator and the CAN log: up, rates, down while stopped, reconnects, EMCYs."""
    d = tempfile.mkdtemp(dir=args.tmp)
    path, canlog = os.path.join(d, "urrt.prom"), os.path.join(d, "can.log")
    robot = "r%d" % os.getpid()
    g = tn.Gateway(args, "metrics-values", robot_extra=ROBOT,
                   ini_extra="[gateway]\nmetrics_file = %s\nmetrics_interval = 200 ms\n" % path +
                   CAN % (canlog, NODE))
    files = Files(path, g.gw)
    try:
        got = files.until(lambda s: value(s, "urrt_robot_up", robot=robot) == 1 and
                          value(s, "urrt_canopen_nmt_state", state="operational") == 1)
        tn.check(got is not None, "values: the robot up and the node operational")
        # Two files a second apart, timed by their modification times.
        # (A file that does not come is None here: the test raises, and fails.)
        a = b = files.until(lambda s: True)
        while b[2] - a[2] < 1e9:
            b = files.until(lambda s: True)
        sa, sb = a[0], b[0]
        rate = (value(sb, "urrt_robot_packets_total", robot=robot) -
                value(sa, "urrt_robot_packets_total", robot=robot)) / ((b[2] - a[2]) / 1e9)
        tn.check(RATE_HZ * 0.5 < rate < RATE_HZ * 1.5, "values: packets at the simulator's %d Hz (%.0f/s)" %
                 (RATE_HZ, rate))
        state = value(sb, "urrt_lcm_messages_total", robot=robot, channel="STATE")
        packets = value(sb, "urrt_robot_packets_total", robot=robot)
        tn.check(0 < state <= packets, "values: STATE messages %d, at most the %d packets" % (state, packets))
        age = value(sb, "urrt_robot_data_age_seconds", robot=robot)
        tn.check(age is not None and 0 <= age < 0.1, "values: data age %s s while it flows" % age)
        sent = value(sb, "urrt_can_frames_sent_total")
        logged = frames_in(canlog)
        tn.check(value(sb, "urrt_can_up") == 1 and 0 < sent <= logged,
                 "values: CAN up, %d frames sent, all in the log (%d lines)" % (sent, logged))
        link = {s: value(sb, "urrt_robot_link_state", robot=robot, state=s) for s in
                ("idle", "connecting", "waiting", "up")}
        tn.check(link == {"idle": 0, "connecting": 0, "waiting": 0, "up": 1}, "values: link_state up only (%s)" % link)
        g.sim.send_signal(signal.SIGSTOP)
        down = files.until(lambda s: value(s, "urrt_robot_up", robot=robot) == 0 and
                           value(s, "urrt_robot_stale_total", robot=robot) >= 1 and
                           value(s, "urrt_canopen_emcy_total") >= 1)
        tn.check(down is not None, "values: the robot down, a stale event and an EMCY while the simulator is stopped")
        if down is not None:
            emcys = value(down[0], "urrt_canopen_emcy_total")
            tn.check(emcys <= emcys_in(canlog), "values: %d EMCYs counted, as many in the CAN log (%d)" %
                     (emcys, emcys_in(canlog)))
            tn.check(value(down[0], "urrt_robot_link_state", robot=robot, state="up") == 0,
                     "values: link_state up is 0 while stopped")
        g.sim.send_signal(signal.SIGCONT)
        back = files.until(lambda s: value(s, "urrt_robot_up", robot=robot) == 1)
        tn.check(back is not None and value(back[0], "urrt_robot_reconnects_total", robot=robot) >= 1 and
                 value(back[0], "urrt_robot_connects_total", robot=robot) >= 2,
                 "values: up again after SIGCONT, a reconnect counted")
    finally:
        g.close()


def t_write_errors(args):
    """A directory that does not exist: a warning that says what to do, counted; the file once it exists."""
    d = os.path.join(tempfile.mkdtemp(dir=args.tmp), "later")
    path = os.path.join(d, "urrt.prom")
    g = tn.Gateway(args, "metrics-errors", ini_extra="[gateway]\nmetrics_file = %s\nmetrics_interval = 100 ms\n" % path)
    try:
        end = time.monotonic() + WAIT
        while time.monotonic() < end and "metrics: cannot write" not in g.text("gw.log") and g.gw.poll() is None:
            time.sleep(0.02)
        log = g.text("gw.log")
        tn.check("metrics: cannot write %s (through %s.tmp): No such file or directory" % (path, path) in log,
                 "errors: the failed write is logged with the path and the reason")
        os.mkdir(d)
        got = Files(path, g.gw).until(lambda s: value(s, "urrt_metrics_write_errors_total") >= 1)
        tn.check(got is not None and g.gw.poll() is None and g.text("gw.log").count("metrics: cannot write") == 1,
                 "errors: counted in the file once the directory exists, logged once, the gateway ran on")
    finally:
        g.close()


def t_config(args):
    """Bad keys: refused with the file, the line and the reason."""
    d = tempfile.mkdtemp(dir=args.tmp)
    for key, text, why in (("metrics_file", d + "/", "give off or a file's absolute path"),
                           ("metrics_file", "gw.prom", "give off or a file's absolute path"),
                           ("metrics_interval", "50 ms", "metrics_interval")):
        ini = os.path.join(d, "bad.ini")
        with open(ini, "w") as f:
            f.write("[gateway]\n%s = %s\n[robot a]\nhost = 127.0.0.1\n" % (key, text))
        r = subprocess.run([args.gateway, "--check-config", ini], capture_output=True, text=True)
        tn.check(r.returncode == 2 and ("%s:2:" % ini) in r.stderr and why in r.stderr,
                 "config: %s = %s refused at %s:2 (%s)" % (key, text, ini, r.stderr.strip()[:200]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    args = ap.parse_args()
    args.gateway = os.path.join(args.build, "bin", "urrt-gateway")
    args.sim = os.path.join(args.build, "bin", "urrt-sim")
    args.tmp = tempfile.mkdtemp(prefix="check-metrics-")
    for name, fn in (("format", t_format), ("values", t_values), ("errors", t_write_errors), ("config", t_config)):
        t0 = time.monotonic()
        try:
            fn(args)
        except Exception as e:  # a crashed test is a failure, the others still run
            tn.check(False, "%s: raised %r" % (name, e))
        print("-- %s: %.1f s" % (name, time.monotonic() - t0))
    status = tn.suite.report()
    subprocess.run(["rm", "-rf", args.tmp])
    return status


if __name__ == "__main__":
    sys.exit(main())
