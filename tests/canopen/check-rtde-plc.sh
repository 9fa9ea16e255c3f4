#!/bin/bash
# SPDX-License-Identifier: MIT
# The RTDE part of make check-canopen: boots the VM (tests/vm/run.sh) with urrt-sim,
# urrt-gateway, docs/examples/rtde-plc.ini and the PLC's manager (rtde_plc.sh
# inside), Python staged by stage-python.sh. Prints "N passed, N failed" last.
#   tests/canopen/check-rtde-plc.sh BUILD
set -u
build=$1
here=$(dirname "$0")
. tests/lib.sh
. tests/vm/counts.sh
out=$build/vm/check-rtde-plc
rm -rf "$out"
if "$here/stage-python.sh" "$build/canopen/py"; then
  counted "the VM run (rtde_plc.sh)" tests/vm/run.sh --out "$out" --script "$here/rtde_plc.sh" --timeout 300 \
    --vcan 'vcan0:16' --files "tests/lib.sh tests/vm/counts.sh $build/canopen/py $build/bin/urrt-sim \
      $build/bin/urrt-gateway docs/examples/rtde-plc.ini $here/rtde_plc.py $here/eds.py $here/rtde_plc.sh"
else
  fail "could not stage Python for the VM (see above)"
fi
finish
