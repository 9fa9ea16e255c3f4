# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh: the CAN link's receive side on vcan1 and the
# log link's caller clock (tests/port/can_rx_test.c), then the same under
# ASan and UBSan. Needs can_rx_test, can_rx_test_san, lib.sh, counts.sh and
# cangen. Prints "N passed, N failed" last (tests/vm/suite.sh adds it up).
. ./lib.sh
. ./counts.sh

for t in can_rx_test can_rx_test_san; do
  if [ ! -x "/t/$t" ]; then fail "$t is missing"; continue; fi
  echo "== $t (at $(cut -d" " -f1 /proc/uptime) s)"
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
  counted "$t clock" "$t" clock "$OUT"
  counted "$t rx" "$t" rx
  counted "$t flood" "$t" flood
done
finish
