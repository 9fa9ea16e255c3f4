# SPDX-License-Identifier: MIT
# Sourced by shell tests: ok/fail count, finish prints "N passed, N failed".
# RESULT (if set) receives the closing line for tests/summary.sh.
PASSED=0; FAILED=0
ok()   { PASSED=$((PASSED + 1)); echo "ok: $*"; }
fail() { FAILED=$((FAILED + 1)); echo "FAIL: $*" >&2; }
check() { desc=$1; shift; if "$@"; then ok "$desc"; else fail "$desc"; fi; }
finish() {
  line="$PASSED passed, $FAILED failed"
  echo "$line"
  [ -n "${RESULT:-}" ] && echo "$line" > "$RESULT"
  [ "$FAILED" = 0 ]
}
