#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs target programs and adds up their "N passed, N failed" lines.
#   run.sh LOGDIR NAME=COMMAND ...
# Each COMMAND runs under sh -c with its output in LOGDIR/NAME.log; it passes
# when it exits 0 and its last line says 0 failed. A NAME starting with "!"
# must FAIL instead (exit status not 0 and failures counted): a regression
# test showing that an old bug is caught at run time; it counts as one check.
set -u
logs=$1; shift
mkdir -p "$logs"
passed=0; failed=0
for spec in "$@"; do
  name=${spec%%=*}; cmd=${spec#*=}
  expect_fail=no
  case $name in !*) expect_fail=yes; name=${name#!} ;; esac
  start=$(date +%s.%N)
  sh -c "$cmd" > "$logs/$name.log" 2>&1; rc=$?
  secs=$(echo "$start $(date +%s.%N)" | awk '{ printf "%.2f", $2 - $1 }')
  line=$(tail -n 1 "$logs/$name.log")
  p=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
  f=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
  if [ $expect_fail = yes ]; then
    grep -m 2 '^FAIL: ' "$logs/$name.log" | sed "s|^FAIL: |$name: as expected: |"
    if [ "$rc" != 0 ] && [ -n "$f" ] && [ "$f" -gt 0 ]; then
      echo "ok: $name fails as it must (exit status $rc, $f failed checks; ${secs} s)"; passed=$((passed + 1))
    else
      echo "FAIL: $name should fail (a regression test of an old bug) but exited $rc: $line"; failed=$((failed + 1))
    fi
    continue
  fi
  grep -v '^stack: ' "$logs/$name.log" | grep -v '^ok:' | tail -n 8 | sed "s|^|$name: |"
  if [ -z "$p" ]; then
    echo "FAIL: $name left no result (exit status $rc; crashed or faulted?)"; failed=$((failed + 1))
  elif [ "$rc" != 0 ] || [ "$f" != 0 ]; then
    passed=$((passed + p)); failed=$((failed + f))
    echo "FAIL: $name exited $rc: $line"; [ "$f" = 0 ] && failed=$((failed + 1))
  else
    passed=$((passed + p))
    echo "ok: $name ($line; ${secs} s)"
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
