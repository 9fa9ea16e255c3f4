#!/bin/sh
# SPDX-License-Identifier: MIT
# make check-stress: the suites that involve processes, sockets or time, run
# RUNS times each, every second run with the other core kept busy by a spin
# loop, and a table of how often each suite and each of its checks failed.
# A check that fails once without a cause is a defect to find, so the table
# names the checks, not just the suites.
#
#   tests/stress/stress.sh BUILD RUNS SUITE...
# Each run is `make BUILD=BUILD SUITE`; its output is kept in
# BUILD/stress/SUITE.N.log. Exit status 0 only if every run of every suite passed.
set -u
build=$1 runs=$2; shift 2
dir=$build/stress
rm -rf "$dir"; mkdir -p "$dir"
spin=
stop_spin() { [ -n "$spin" ] && kill "$spin" 2>/dev/null; wait 2>/dev/null; spin=; }
trap 'stop_spin' EXIT INT TERM

# Built once, outside the runs: a run measures the suite, not the compiler.
make --no-print-directory BUILD="$build" -k "$@" >"$dir/build.log" 2>&1

i=1
while [ "$i" -le "$runs" ]; do
  load=idle
  if [ $((i % 2)) = 0 ]; then
    # Bounded: a stress run never outlives its hour even if the trap is lost.
    timeout 3600 sh -c 'while :; do :; done' & spin=$!
    load=busy
  fi
  for suite in "$@"; do
    start=$(date +%s)
    make --no-print-directory BUILD="$build" "$suite" >"$dir/$suite.$i.log" 2>&1
    rc=$?
    echo "$suite $i $load $rc $(( $(date +%s) - start ))" >>"$dir/runs.txt"
    printf 'stress: run %d/%d (%s) %s: %s in %d s\n' "$i" "$runs" "$load" "$suite" \
      "$([ $rc = 0 ] && echo pass || echo FAIL)" "$(( $(date +%s) - start ))"
  done
  stop_spin
  i=$((i + 1))
done

echo
printf '%-18s %5s %6s %8s %8s  %s\n' suite runs failed busy-fail max-s "failing checks (times)"
for suite in "$@"; do
  awk -v s="$suite" '$1 == s { n++; if ($4 != 0) { f++; if ($3 == "busy") b++ } if ($5 > m) m = $5 }
    END { printf "%-18s %5d %6d %8d %8d  ", s, n, f, b, m }' "$dir/runs.txt"
  # A failing check's line with its numbers blanked, so that the same check
  # failing with other figures counts as one.
  checks=$(cat "$dir/$suite".*.log 2>/dev/null | grep -E 'FAIL' | grep -v '^make' |
           sed -E 's/[0-9]+(\.[0-9]+)?/N/g' | sort | uniq -c | sort -rn |
           awk '{ c = $1; $1 = ""; printf "%s[%d x]%s", (NR > 1 ? "; " : ""), c, $0 }')
  echo "${checks:--}"
done
! awk '$4 != 0 { bad = 1 } END { exit !bad }' "$dir/runs.txt"
