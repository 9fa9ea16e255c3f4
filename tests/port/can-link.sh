# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh: the CAN link (port/posix/can.c) on a real
# kernel. Needs vcan0 (MTU 72), vcan1 (MTU 16), sch_plug, and the files
# can_link_test, lib.sh, counts.sh. Prints "N passed, N failed" as
# the last line (tests/vm/suite.sh adds it up).
. ./lib.sh
. ./counts.sh

cd "$OUT"

strip() { sed 's/^([0-9]*\.[0-9]*) //' "$@"; }

# Waits until N receivers are registered on IF (candump has bound).
wait_receivers() {
  i=0
  while [ "$(grep -c "^ *$1 " /proc/net/can/rcvlist_all 2>/dev/null)" -lt "$2" ] && [ $i -lt 50 ]; do
    sleep 0.1; i=$((i + 1))
  done
}

echo "== the candump-log output (at $(cut -d" " -f1 /proc/uptime) s)"
counted "can_link_test log" can_link_test log "$OUT"

echo "== frames on the wire, as candump sees them (at $(cut -d" " -f1 /proc/uptime) s)"
# can_link_test frames sends 8 frames on vcan0 and 6 on vcan1.
candump -L -n 8 -T 5000 vcan0 > candump-vcan0.log & d0=$!
candump -L -n 6 -T 5000 vcan1 > candump-vcan1.log & d1=$!
wait_receivers vcan0 1; wait_receivers vcan1 1
counted "can_link_test frames" can_link_test frames "$OUT"
wait $d0 $d1
strip frames-vcan0.log frames-vcan0-nobrs.log > want-vcan0.txt
strip candump-vcan0.log > got-vcan0.txt
strip frames-vcan1.log > want-vcan1.txt
strip candump-vcan1.log > got-vcan1.txt
check "vcan0: candump -L lines = log lines (8 frames, FD with and without BRS)" \
  sh -c '[ $(wc -l < got-vcan0.txt) = 8 ] && cmp want-vcan0.txt got-vcan0.txt'
check "vcan1: candump -L lines = log lines (6 classic frames)" \
  sh -c '[ $(wc -l < got-vcan1.txt) = 6 ] && cmp want-vcan1.txt got-vcan1.txt'
diff want-vcan0.txt got-vcan0.txt; diff want-vcan1.txt got-vcan1.txt

echo "== canplayer replays the log output (at $(cut -d" " -f1 /proc/uptime) s)"
n_fd=$(wc -l < log-fd.log); n_cc=$(wc -l < log-classic.log)
candump -L -n "$n_fd" -T 5000 vcan0 > replay-vcan0.log & d0=$!
candump -L -n "$n_cc" -T 5000 vcan1 > replay-vcan1.log & d1=$!
wait_receivers vcan0 1; wait_receivers vcan1 1
check "canplayer -I log-fd.log (interface column vcan0)" canplayer -I log-fd.log
check "canplayer -I log-classic.log vcan1=can0" canplayer -I log-classic.log vcan1=can0
wait $d0 $d1
strip log-fd.log > want-replay-vcan0.txt
strip replay-vcan0.log > got-replay-vcan0.txt
strip log-classic.log | sed 's/^can0 /vcan1 /' > want-replay-vcan1.txt
strip replay-vcan1.log > got-replay-vcan1.txt
check "the replay on vcan0 equals the file ($n_fd frames)" \
  sh -c "[ \$(wc -l < got-replay-vcan0.txt) = $n_fd ] && cmp want-replay-vcan0.txt got-replay-vcan0.txt"
check "the replay on vcan1 equals the file ($n_cc frames, can0 mapped to vcan1)" \
  sh -c "[ \$(wc -l < got-replay-vcan1.txt) = $n_cc ] && cmp want-replay-vcan1.txt got-replay-vcan1.txt"
diff want-replay-vcan0.txt got-replay-vcan0.txt; diff want-replay-vcan1.txt got-replay-vcan1.txt

echo "== the socket: refusals, error frames, full queue, down and up (at $(cut -d" " -f1 /proc/uptime) s)"
counted "can_link_test socket" can_link_test socket

echo "== the socket again, under ASan and UBSan (at $(cut -d" " -f1 /proc/uptime) s)"
if [ -x /t/can_link_test_san ]; then
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    counted "can_link_test_san socket" can_link_test_san socket
else
  fail "can_link_test_san is missing"
fi

finish
