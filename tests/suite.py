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
        print('ok: ' + what)
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
