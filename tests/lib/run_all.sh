#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs each test binary on the vectors and adds up their
# "N passed, N failed" lines into one.
#   run_all.sh VECTORS BINARY...
set -u
vectors=$1; shift
passed=0; failed=0; rc=0
for bin in "$@"; do
  echo "== $bin"
  out=$("$bin" "$vectors" 2>&1) || rc=1
  echo "$out" | tail -n 40
  line=$(echo "$out" | tail -n 1)
  p=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
  f=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
  if [ -z "$p" ]; then echo "$bin left no result (crashed?)"; failed=$((failed + 1)); rc=1; continue; fi
  passed=$((passed + p)); failed=$((failed + f))
done
echo "$passed passed, $failed failed"
[ "$rc" = 0 ] && [ "$failed" = 0 ]
