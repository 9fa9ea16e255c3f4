#!/bin/sh
# SPDX-License-Identifier: MIT
# make check-can-log: the CAN link's candump-log output, on the host (no CAN
# needed): exact lines from can_link_test, then python-can's candump-log
# reader (an independent parser) on the same files; and log:- into a pipe,
# a socket and a terminal whose reader stalls (can_link_test log).
#   tests/port/check-can-log.sh DIR (where can_link_test and can_link_test_san are)
bin=$1
. tests/lib.sh
. tests/vm/counts.sh
dir=$bin/can-log
rm -rf "$dir"; mkdir -p "$dir"
counted "can_link_test log" "$bin/can_link_test" log "$dir"
counted "python-can CanutilsLogReader" /usr/bin/python3 tests/port/check_can_log.py "$dir"
rm -rf "$dir"; mkdir -p "$dir"
counted "can_link_test log (ASan+UBSan)" "$bin/can_link_test_san" log "$dir"
finish
