#!/bin/sh
# SPDX-License-Identifier: MIT
# make check-can-log: the CAN link's candump-log output, on the host (no CAN
# needed): exact lines from can_link_test, then python-can's candump-log
# reader (an independent parser) on the same files.
#   tests/vm/check-can-log.sh BUILD
build=$1
. tests/lib.sh
. tests/vm/counts.sh
RESULT=$build/results/check-can-log.result
mkdir -p "$build/results"
dir=$build/tests/can-log
rm -rf "$dir"; mkdir -p "$dir"
counted "can_link_test log" "$build/tests/can_link_test" log "$dir"
counted "python-can CanutilsLogReader" /usr/bin/python3 tests/vm/check_can_log.py "$dir"
rm -rf "$dir"; mkdir -p "$dir"
counted "can_link_test log (ASan+UBSan)" "$build/tests/can_link_test_san" log "$dir"
finish
