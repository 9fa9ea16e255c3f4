#!/bin/bash
# SPDX-License-Identifier: MIT
# make check-canopen: stages Debian's Python with python3-can for the VM
# (stage-python.sh), boots the VM once (tests/vm/run.sh) with urrt-sim,
# urrt-gateway and the CANopen master (canopen.sh inside), then checks on the
# host what it left (canopen.post: the EDS, tshark on every frame, the TPDO
# values against urrt-dump); then the RTDE examples in VMs of their own
# (check-rtde-plc.sh, check-plc-io-co.sh). Prints the total "N passed, N failed" last.
#   tests/canopen/check-canopen.sh BUILD
set -u
build=$1
here=$(dirname "$0")
. tests/lib.sh
. tests/vm/counts.sh
out=$build/vm/check-canopen
rm -rf "$out"
start=$(date +%s.%N)
if "$here/stage-python.sh" "$build/canopen/py"; then
  # Classic CAN on vcan0, as a CANopen bus is. run.sh prints the script's output last.
  counted "the VM run (canopen.sh)" tests/vm/run.sh --out "$out" --script "$here/canopen.sh" --timeout 300 \
    --vcan 'vcan0:16' --files "tests/lib.sh tests/vm/counts.sh $build/canopen/py $build/bin/urrt-sim \
      $build/bin/urrt-gateway $here/canopen.ini $here/master.py $here/eds.py $here/canopen.sh"
  echo "==== $here/canopen.post (host)"
  counted "canopen.post" "$here/canopen.post" "$out/out" "$build/bin/urrt-dump" "$here/canopen.ini"
  echo "==== $here/check-rtde-plc.sh (docs/examples/rtde-plc.ini over urrt-sim's RTDE port, its own VM)"
  counted "check-rtde-plc.sh" "$here/check-rtde-plc.sh" "$build"
  echo "==== $here/check-plc-io-co.sh (docs/examples/plc-io-canopen.ini: RPDOs to urrt-sim's registers, its own VM)"
  counted "check-plc-io-co.sh" "$here/check-plc-io-co.sh" "$build"
else
  fail "could not stage Python for the VM (see above)"
fi
echo "check-canopen: $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s in all; results in $out"
finish
