#!/bin/sh
# SPDX-License-Identifier: MIT
# bench-tools: how well urrt-sim keeps its schedule at 500 Hz, alone with
# one client and with four. Prints "name: value" lines; asserts nothing.
# The simulator takes its port from the system (--port-file).
set -u
BUILD=${BUILD:-build}
SIM=$BUILD/bin/urrt-sim
DUMP=$BUILD/bin/urrt-dump
SECONDS_EACH=${BENCH_SECONDS:-5}
T=$(mktemp -d "${TMPDIR:-/tmp}/urrt-bench.XXXXXX")
trap 'rm -rf "$T"' EXIT

# waitfile FILE PID: until FILE is there (at most 10 s, or until PID ends).
waitfile() {
  i=0
  while [ $i -lt 500 ] && kill -0 "$2" 2>/dev/null; do
    [ -s "$1" ] && return 0
    sleep 0.02; i=$((i + 1))
  done
  [ -s "$1" ]
}

# run NAME CLIENTS [SIM OPTIONS]
run() {
  name=$1; clients=$2; shift 2; n=$((SECONDS_EACH * 500))
  rm -f "$T/port"
  timeout $((SECONDS_EACH + 20)) "$SIM" -l 127.0.0.1:0 --port-file "$T/port" --version 5.10 "$@" 2> "$T/sim.log" &
  sp=$!
  waitfile "$T/port" $sp || { echo "the simulator did not start:" >&2; cat "$T/sim.log" >&2; exit 1; }
  port=$(cat "$T/port")
  k=0; pids=""
  while [ $k -lt "$clients" ]; do
    timeout $((SECONDS_EACH + 15)) "$DUMP" "127.0.0.1:$port" -n $n -F gnuplot > /dev/null 2> "$T/dump$k.sum" &
    pids="$pids $!"; k=$((k + 1))
  done
  for p in $pids; do wait "$p"; done
  kill -INT $sp; wait $sp
  # "N packets in S s; late (...) L, skipped K; lateness mean M us, p99 <= P us, max X us; ..."
  sed -n 's/.*notice: \([0-9]*\) packets in \([0-9.]*\) s; late ([^)]*) \([0-9]*\), skipped \([0-9]*\); lateness mean \([0-9.]*\) us, p99 <= \([0-9.]*\) us, max \([0-9.]*\) us.*/\1 \3 \4 \5 \6 \7/p' "$T/sim.log" > "$T/fig"
  read packets late skipped mean p99 max < "$T/fig"
  rate=$(sed -n 's/.*, \([0-9.]*\) Hz by arrival/\1/p' "$T/dump0.sum")
  gap=$(sed -n 's/summary: largest gap: \([0-9.]*\) s.*/\1/p' "$T/dump0.sum")
  echo "sim_500hz_${name}_packets: $packets"
  echo "sim_500hz_${name}_late_packets: $late"
  echo "sim_500hz_${name}_skipped_packets: $skipped"
  echo "sim_500hz_${name}_lateness_mean_us: $mean"
  echo "sim_500hz_${name}_lateness_p99_us: $p99"
  echo "sim_500hz_${name}_lateness_max_us: $max"
  echo "sim_500hz_${name}_client_arrival_rate_hz: $rate"
  echo "sim_500hz_${name}_client_largest_gap_s: $gap"
  eval "mean_$name=$mean"
}

run 1client 1
run 4clients 4
# SCHED_FIFO where allowed (root, CAP_SYS_NICE); a warning and normal priority otherwise.
run 1client_fifo 1 --rt-priority 10
echo "sim_500hz_lateness_mean_ratio_4clients_vs_1: $(awk "BEGIN { printf \"%.2f\", $mean_4clients / ($mean_1client > 0 ? $mean_1client : 1) }")"
