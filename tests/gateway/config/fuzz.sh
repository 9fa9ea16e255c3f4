#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs the libFuzzer harness of the gateway configuration (tests/gateway/config/fuzz_config.c).
#   fuzz.sh FUZZER SEEDS WORKDIR SECONDS [--check]
# First every seed (the example and test configurations) and every input of
# tests/gateway/config/regressions/ (what the fuzzer once found) is replayed, then the
# fuzzer runs for SECONDS on one core, mutating from the seeds and from
# WORKDIR/corpus (kept between runs, so `make fuzz` builds on earlier runs),
# with the grammar's words as a dictionary. With --check the run uses a fixed
# seed, so make check is repeatable. A failing input is left in
# WORKDIR/artifacts/; replay it with: FUZZER FILE
# REGRESSION (if set) is a test program run first (tests/gateway/config/test_config.c).
set -u
fuzzer=$1; seeds=$2; work=$3; seconds=$4; mode=${5:-}
here=$(dirname "$0")
. "$here/../../lib.sh"
mkdir -p "$work/corpus" "$work/artifacts"
opts="-max_len=8192 -timeout=10 -rss_limit_mb=2048 -dict=$here/config.dict -artifact_prefix=$work/artifacts/"
opts="$opts -print_final_stats=1"
[ "$mode" = --check ] && opts="$opts -seed=20261122"

if [ -n "${REGRESSION:-}" ]; then
  if out=$(ASAN_OPTIONS=detect_leaks=1 "$REGRESSION" 2>&1); then
    ok "regression tests: $(echo "$out" | tail -n 1)"
  else
    echo "$out"; fail "regression tests: $(echo "$out" | tail -n 1)"
  fi
fi
for dir in "$seeds" "$here/regressions"; do
  n=$(ls "$dir" | wc -l)
  if [ "$n" -lt 1 ]; then
    fail "no inputs in $dir"
  elif "$fuzzer" $opts -runs=0 "$dir" > "$work/replay.log" 2>&1; then
    ok "harness holds on all $n inputs of $dir"
  else
    tail -n 30 "$work/replay.log"; fail "harness failed on an input of $dir (see $work/replay.log)"
  fi
done
if "$fuzzer" $opts -max_total_time="$seconds" "$work/corpus" "$seeds" > "$work/fuzz.log" 2>&1; then
  stat() { grep -o "stat::$1: *[0-9]*" "$work/fuzz.log" | grep -o '[0-9]*$'; }
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$work/fuzz.log" | tail -n 1)
  ok "fuzzed for ${seconds}s: $(stat number_of_executed_units) inputs ($cov, corpus $(ls "$work/corpus" | wc -l)), no invariant violated"
else
  tail -n 40 "$work/fuzz.log"
  fail "fuzzer found a failing input: $(ls "$work/artifacts" | head -n 3)"
fi
finish
