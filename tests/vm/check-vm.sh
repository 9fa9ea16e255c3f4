#!/bin/bash
# make check-vm: boots the VM once (tests/vm/run.sh) and runs every script of
# VM_TESTS inside with tests/vm/suite.sh. Writes the closing line to RESULT.
#   tests/vm/check-vm.sh BUILD 'TESTS' 'FILES' 'MODULES'
set -u
build=$1 tests=$2 files=$3 modules=$4
here=$(dirname "$0")
RESULT=$build/results/check-vm.result
mkdir -p "$build/results"
out=$build/vm/check-vm
names=''
for t in $tests; do names="$names $(basename "$t")"; done

rm -rf "$out" "$RESULT"
start=$(date +%s.%N)
"$here/run.sh" --out "$out" --script "$here/suite.sh" --timeout 90 \
  --files "$here/counts.sh tests/lib.sh $files $tests" --modules "$modules" \
  --env "VM_TESTS=${names# }"
rc=$?
end=$(date +%s.%N)
echo "check-vm: $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s in all; results in $out"
line=$(tail -n 1 "$out/out/check.result" 2>/dev/null)
case $line in
  *' passed, '*' failed') echo "$line" > "$RESULT" ;;
  *) echo "check-vm: the VM gave no result (exit status $rc; see above and $out/console.log)" >&2
     echo "0 passed, 1 failed" > "$RESULT"; exit 1 ;;
esac
[ "$rc" = 0 ] && grep -q ' 0 failed$' "$RESULT"
