#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's run: the capture through urrt-gateway --replay and
# through the firmware image on qemu's Cortex-M4, then the comparison.
#   run.sh BUILD_DIR FW_DIR
set -eu
build=$1; fw=$2
rm -f "$fw/gateway.log"
"$build/bin/urrt-gateway" --replay "$fw/capture.bin" "$fw/gateway.ini"
qemu-system-arm -nographic -monitor none -serial none \
  -semihosting-config "enable=on,target=native,arg=$fw/capture.bin" \
  -M mps2-an386 -kernel "$fw/fw_gateway.elf" > "$fw/firmware.out" 2>&1
echo "footprint on the Cortex-M4 at -Os (arm-none-eabi-size): the image; the generated tables; lib/"
arm-none-eabi-size "$fw/fw_gateway.elf" "$fw/tables.o" "$fw"/lib/*.o
# The comparison must be able to fail: one payload digit changed in frame 600.
awk 'NR == 600 { c = substr($0, length($0)); $0 = substr($0, 1, length($0) - 1) (c == "0" ? "1" : "0") } 1' \
  "$fw/firmware.out" > "$fw/firmware.flipped"
if sh tests/fw/compare.sh "$fw/gateway.log" "$fw/firmware.flipped" > "$fw/flipped.log"; then
  echo "FAIL: compare.sh accepts a firmware output with one payload digit changed"; exit 1
fi
echo "ok: compare.sh refuses a firmware output with one payload digit changed"
exec sh tests/fw/compare.sh "$fw/gateway.log" "$fw/firmware.out"
