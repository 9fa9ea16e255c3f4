#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs the libFuzzer harness of lib/ (tests/lib/fuzz_lib.c).
#   fuzz.sh FUZZER SEEDS WORKDIR SECONDS [--check]
# First every seed (inputs made by the reference, tests/ref/urrt_ref.py) is
# replayed, then the fuzzer runs for SECONDS, mutating from the seeds and from
# WORKDIR (kept between runs, so `make fuzz` builds on earlier runs). With
# --check the run uses a fixed seed, so make check is repeatable. A crash
# leaves its input in WORKDIR/artifacts/; replay it with: FUZZER FILE
set -u
fuzzer=$1; seeds=$2; work=$3; seconds=$4; mode=${5:-}
. "$(dirname "$0")/../lib.sh"
mkdir -p "$work/corpus" "$work/artifacts"
opts="-max_len=6000 -timeout=10 -rss_limit_mb=1024 -artifact_prefix=$work/artifacts/ -print_final_stats=1"
[ "$mode" = --check ] && opts="$opts -seed=20261122"
n=$(ls "$seeds" | wc -l)
if [ "$n" -lt 10 ]; then
  fail "seed corpus $seeds holds $n inputs; the reference should have made more"
elif "$fuzzer" $opts -runs=0 "$seeds" > "$work/replay.log" 2>&1; then
  ok "harness holds on all $n reference seeds"
else
  tail -n 30 "$work/replay.log"; fail "harness failed on a reference seed (see $work/replay.log)"
fi
if "$fuzzer" $opts -max_total_time="$seconds" "$work/corpus" "$seeds" > "$work/fuzz.log" 2>&1; then
  ok "fuzzed for ${seconds}s: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/fuzz.log" | grep -o '[0-9]*$') inputs, no invariant violated"
else
  tail -n 40 "$work/fuzz.log"
  fail "fuzzer found a failing input: $(ls "$work/artifacts" | head -n 3)"
fi
finish
