# SPDX-License-Identifier: MIT
"""What the Python suites share, said once: counting checks and the line
that reports them, waiting for an event with a bound, ending what is left
of a process group.

    sys.path.insert(0, TESTS)   # this directory
    from suite import check, wait_for, end_group
    import suite
    ...
    return suite.report()       # "N passed, M failed", the exit status

The report line is what tests/summary.sh and the CI read.
"""
import os
import signal
import subprocess
import sys
import time

passed = 0
failed = 0


def check(ok, what, detail=''):
    """Counts one check: "ok: WHAT" on stdout, or "FAIL: WHAT[: DETAIL]" on
    stderr (DETAIL cut to 3000 characters). Returns ok."""
    global passed, failed
    if ok:
        passed += 1
        print('ok: ' + what, flush=True)
    else:
        failed += 1
        print('FAIL: %s%s' % (what, (': ' + str(detail)[:3000]) if detail != '' else ''), file=sys.stderr)
    return ok


def report():
    """Prints the count of checks; 0 if none failed, else 1."""
    print('%d passed, %d failed' % (passed, failed))
    return 1 if failed else 0


def wait_for(what, cond, proc=None, timeout=10.0):
    """Until cond() holds (polled every 20 ms), at most timeout seconds; at
    once when proc has ended. Says what it waited for in vain."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return True
        if proc is not None and proc.poll() is not None:
            return cond()
        time.sleep(0.02)
    print('waited in vain for ' + what, file=sys.stderr)
    return False


def end_group(proc):
    """Kills what is left of proc's process group (a `timeout` leads one): a
    program that outlived its timeout must not keep running, nor hold a pipe
    of the suite's open (check-stress once hung on one that did)."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


class Sim:
    """urrt-sim serving RealTime and RTDE on ports the system picks, at -v,
    its output kept in a log file under tmp; ended with its process group
    (a context manager, or stop()). args: the simulator's own (-c 5.10,
    --fault ...); timeout bounds its life. rt_port, port (RTDE's) and addr
    (127.0.0.1:port) say where it listens."""
    count = 0

    def __init__(self, sim, tmp, *args, timeout=90):
        Sim.count += 1
        base = os.path.join(tmp, 'sim%d' % Sim.count)
        self.log_path, rt_pf, rtde_pf = base + '.log', base + '.rt', base + '.rtde'
        with open(self.log_path, 'w') as log:
            self.proc = subprocess.Popen(['timeout', '-k', '3', str(timeout), sim, '-l', '127.0.0.1:0', '--port-file',
                                          rt_pf, '--rtde', '127.0.0.1:0', '--rtde-port-file', rtde_pf, '-v'] + list(args),
                                         stdout=log, stderr=log)
        # Each port file is written whole and renamed: it exists only with its line.
        if not wait_for('the simulator\'s port files', lambda: os.path.exists(rtde_pf) and os.path.exists(rt_pf),
                        self.proc):
            raise RuntimeError('the simulator did not start: ' + self.log())
        self.rt_port = int(open(rt_pf).read())
        self.port = int(open(rtde_pf).read())
        self.addr = '127.0.0.1:%d' % self.port

    def log(self):
        with open(self.log_path) as f:
            return f.read()

    def stop(self):
        self.proc.terminate()
        self.proc.wait(timeout=10)
        end_group(self.proc)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()
