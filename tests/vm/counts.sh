# SPDX-License-Identifier: MIT
# Sourced after tests/lib.sh: `counted DESC CMD...` runs a test program that
# ends with "N passed, N failed" and adds its counts to this suite's. A
# program that crashes or leaves no such line counts as one failure.
counted() {
  counted_desc=$1; shift
  counted_out=${TMPDIR:-/tmp}/counted.$$
  "$@" > "$counted_out" 2>&1
  counted_rc=$?
  cat "$counted_out"
  counted_line=$(tail -n 1 "$counted_out")
  rm -f "$counted_out"
  counted_p=$(echo "$counted_line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
  counted_f=$(echo "$counted_line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
  if [ -z "$counted_p" ]; then
    fail "$counted_desc: no result line (exit status $counted_rc)"
    return
  fi
  PASSED=$((PASSED + counted_p)); FAILED=$((FAILED + counted_f))
  if [ "$counted_rc" != 0 ] && [ "$counted_f" = 0 ]; then
    fail "$counted_desc: exit status $counted_rc with no failed check"
  fi
  echo "$counted_desc: $counted_line"
}
