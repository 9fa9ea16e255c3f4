#!/bin/bash
# SPDX-License-Identifier: MIT
# make check-vm: boots the VM once (tests/vm/run.sh), runs every script of
# VM_TESTS inside with tests/vm/suite.sh, then, on the host, the checker
# that goes with a script, if there is one: for tests/x/NAME.sh an executable
# tests/x/NAME.post, called with the script's results directory (what it
# wrote to $OUT) and expected to print "N passed, N failed" last (for what
# the VM cannot do, e.g. Python). Prints the total last.
#   tests/vm/check-vm.sh BUILD 'TESTS' 'FILES' 'MODULES'
set -u
build=$1 tests=$2 files=$3 modules=$4
here=$(dirname "$0")
. tests/lib.sh
. "$here/counts.sh"
out=$build/vm/check-vm
rm -rf "$out"
names=''
for t in $tests; do names="$names $(basename "$t")"; done

start=$(date +%s.%N)
"$here/run.sh" --out "$out" --script "$here/suite.sh" --timeout 90 \
  --files "$here/counts.sh tests/lib.sh $files $tests" --modules "$modules" \
  --env "VM_TESTS=${names# }"
rc=$?
line=$(tail -n 1 "$out/out/check.result" 2>/dev/null)
p=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
f=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
if [ -n "$p" ]; then
  PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
  [ "$rc" = 0 ] || [ "$f" != 0 ] || fail "the VM run ended with exit status $rc"
else
  fail "the VM gave no result (exit status $rc; see above and $out/console.log)"
fi
for t in $tests; do
  post=${t%.sh}.post
  name=$(basename "${t%.sh}")
  if [ -x "$post" ]; then
    echo "==== $post (host)"
    counted "$post" "$post" "$out/out/$name"
  fi
done
echo "check-vm: $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s in all; results in $out"
finish
