#!/bin/sh
# SPDX-License-Identifier: MIT
# Adds up the "N passed, N failed" lines each suite left in DIR/NAME.result.
# A suite that left no result counts as one failure: it crashed or never ran.
dir=$1; shift
passed=0; failed=0
for suite in "$@"; do
  line=$(tail -n 1 "$dir/$suite.result" 2>/dev/null)
  p=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed.*/\1/p')
  f=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed.*/\2/p')
  if [ -z "$p" ]; then
    echo "summary: $suite left no result (crashed or did not run)"
    failed=$((failed + 1)); continue
  fi
  echo "summary: $suite: $line"
  passed=$((passed + p)); failed=$((failed + f))
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
