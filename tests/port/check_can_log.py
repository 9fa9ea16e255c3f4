#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Reads the candump-format files that `can_link_test log DIR` wrote with
python-can's CanutilsLogReader (an independent parser of `candump -L`) and
compares every frame with DIR/log-expect.txt. Prints "N passed, N failed"."""
import os
import sys

from can.io import CanutilsLogReader

passed = failed = 0


def check(cond, what):
    global passed, failed
    if cond:
        passed += 1
    else:
        failed += 1
        print("FAIL: " + what, file=sys.stderr)


def main(directory):
    expected = {}
    with open(os.path.join(directory, "log-expect.txt")) as f:
        for line in f:
            parts = line.split()
            name, can_id, ext, fd, brs = parts[:5]
            data = bytes.fromhex(parts[5]) if len(parts) > 5 else b""
            expected.setdefault(name, []).append(
                (int(can_id, 16), ext == "1", fd == "1", brs == "1", data))
    channels = {"log-fd.log": "vcan0", "log-classic.log": "can0", "log-stdout.log": "can1"}
    check(set(expected) == set(channels), "expectations for %s" % sorted(expected))
    for name, want in sorted(expected.items()):
        msgs = list(CanutilsLogReader(os.path.join(directory, name)))
        check(len(msgs) == len(want), "%s: %d frames, want %d" % (name, len(msgs), len(want)))
        for i, (msg, (can_id, ext, fd, brs, data)) in enumerate(zip(msgs, want)):
            where = "%s frame %d" % (name, i + 1)
            check(msg.arbitration_id == can_id, "%s: id %X, want %X" % (where, msg.arbitration_id, can_id))
            check(msg.is_extended_id == ext, "%s: extended %s" % (where, msg.is_extended_id))
            check(msg.is_fd == fd, "%s: fd %s" % (where, msg.is_fd))
            check(msg.bitrate_switch == brs, "%s: brs %s" % (where, msg.bitrate_switch))
            check(bytes(msg.data) == data, "%s: data %s, want %s" % (where, bytes(msg.data).hex(), data.hex()))
            check(msg.channel == channels.get(name), "%s: channel %s" % (where, msg.channel))
            check(not msg.is_error_frame and not msg.is_remote_frame, "%s: a data frame" % where)
        stamps = [m.timestamp for m in msgs]
        check(stamps == sorted(stamps), "%s: timestamps ascend" % name)
    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: check_can_log.py DIR")
    sys.exit(main(sys.argv[1]))
