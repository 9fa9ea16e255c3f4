# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh, for make check-vm: runs every test script
# named in VM_TESTS (base names, in /t), each with its own OUT directory
# ($OUT/NAME), and adds up their closing "N passed, N failed" lines into
# $OUT/check.result. A test script is a sh script that sources lib.sh and
# ends with finish (or prints that line last in some other way).
. ./lib.sh
. ./counts.sh
top=$OUT
for t in $VM_TESTS; do
  echo "==== $t"
  OUT=$top/${t%.sh}
  export OUT
  mkdir -p "$OUT"
  counted "$t" sh "/t/$t"
done
OUT=$top
RESULT=$top/check.result
finish
