#!/bin/bash
# SPDX-License-Identifier: MIT
# make check-plc-io: stages Debian's Python with python3-can for the VM
# (tests/canopen/stage-python.sh), boots the VM once (tests/vm/run.sh) with urrt-sim,
# urrt-gateway, docs/examples/plc-io.ini and the PLC (plc_io.sh inside). Prints the
# total "N passed, N failed" last. With FRAMES, make bench-plc-io: the same VM times
# FRAMES frames both ways (plc_io.py --bench) and prints its figures instead.
#   tests/plc/check-plc-io.sh BUILD [FRAMES]
set -u
build=$1
frames=${2:-}
here=$(dirname "$0")
. tests/lib.sh
. tests/vm/counts.sh
out=$build/vm/check-plc-io
rm -rf "$out"
files="tests/lib.sh tests/vm/counts.sh $build/plc/py $build/bin/urrt-sim $build/bin/urrt-gateway \
  docs/examples/plc-io.ini $here/plc_io.py tests/gateway/tools/rtde_peer.py $here/plc_io.sh \
  $build/tests/gateway/lcm_sub"
if [ -n "$frames" ]; then
  tests/canopen/stage-python.sh "$build/plc/py" || exit 1
  exec tests/vm/run.sh --out "$out-bench" --script "$here/plc_io.sh" --timeout 300 --vcan 'vcan0:16' \
    --env "BENCH=$frames" --files "$files"
fi
if tests/canopen/stage-python.sh "$build/plc/py"; then
  counted "the VM run (plc_io.sh)" tests/vm/run.sh --out "$out" --script "$here/plc_io.sh" --timeout 300 \
    --vcan 'vcan0:16' --files "$files"
else
  fail "could not stage Python for the VM (see above)"
fi
finish
