#!/bin/bash
# SPDX-License-Identifier: MIT
# The RPDO part of make check-canopen: boots the VM (tests/vm/run.sh) with urrt-sim,
# urrt-gateway, docs/examples/plc-io-canopen.ini and the manager (plc_io_co.sh inside),
# Python staged by stage-python.sh. Prints "N passed, N failed" last.
#   tests/canopen/check-plc-io-co.sh BUILD
set -u
build=$1
here=$(dirname "$0")
. tests/lib.sh
. tests/vm/counts.sh
out=$build/vm/check-plc-io-co
rm -rf "$out"
if "$here/stage-python.sh" "$build/canopen/py"; then
  counted "the VM run (plc_io_co.sh)" tests/vm/run.sh --out "$out" --script "$here/plc_io_co.sh" --timeout 300 \
    --vcan 'vcan0:16' --files "tests/lib.sh tests/vm/counts.sh $build/canopen/py $build/bin/urrt-sim \
      $build/bin/urrt-gateway docs/examples/plc-io-canopen.ini $here/plc_io_co.py $here/master.py $here/eds.py \
      tests/plc/plc_io.py tests/gateway/tools/rtde_peer.py $here/plc_io_co.sh"
else
  fail "could not stage Python for the VM (see above)"
fi
finish
