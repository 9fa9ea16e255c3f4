#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's run: for each configuration, the capture through
# urrt-gateway --replay and through its firmware image on qemu's Cortex-M4,
# then the comparison; the results added up.
#   run.sh BUILD_DIR FW_DIR CONFIG...
set -u
build=$1; fw=$2; shift 2
passed=0; failed=0
for name in "$@"; do
  dir=$fw/$name
  ini=$dir/gateway.ini
  rm -f "$dir/gateway.log"
  # A CANopen node is fed the manager's frames (fw.mk writes rx.log for it).
  rx=; [ -f "$dir/rx.log" ] && rx="--replay-rx $dir/rx.log"
  # shellcheck disable=SC2086
  "$build/bin/urrt-gateway" --replay "$fw/capture.bin" $rx "$ini" 2> "$dir/replay.err" || {
    echo "FAIL: $name: urrt-gateway --replay: $(cat "$dir/replay.err")"; failed=$((failed + 1)); continue; }
  qemu-system-arm -nographic -monitor none -serial none \
    -semihosting-config "enable=on,target=native,arg=$fw/capture.bin" \
    -M mps2-an386 -kernel "$dir/fw_gateway.elf" > "$dir/firmware.out" 2>&1
  # What the configuration says: its frames and the heartbeat, as the log writes their ids.
  # A CANopen node: its heartbeat 0x700 + node id and its EMCY 0x080 + node id, no status
  # TPDO (off until enabled), and without a manager's frames no SYNC-driven TPDO either.
  node=$(sed -n 's/^node_id = //p' "$ini")
  if [ -n "$node" ] && [ -f "$dir/rx.log" ]; then
    ids=$(( $(grep -c '^\[frame ' "$ini") + 3 ))   # and the SDO answers 0x580 + node id; SYNCs come
    hb=$(printf '%03X' $((0x700 + node)))
  elif [ -n "$node" ]; then
    ids=$(( $(grep -c '^\[frame ' "$ini") - $(grep -c '^transmission = sync' "$ini") + 2 ))
    hb=$(printf '%03X' $((0x700 + node)))
  else
    ids=$(( $(grep -c '^\[frame ' "$ini") + 1 ))
    hb=$(sed -n 's/^heartbeat_id = 0x//p' "$ini" | tr a-f A-F)
    if grep -q '^heartbeat_extended = yes' "$ini"; then hb=$(printf '%08X' "0x$hb"); else hb=$(printf '%03X' "0x$hb"); fi
  fi
  echo "== $name: $ids ids, heartbeat $hb"
  sh tests/fw/compare.sh "$dir/gateway.log" "$dir/firmware.out" "$ids" "$hb" "$name" > "$dir/compare.log"
  grep -v ' passed, ' "$dir/compare.log"
  line=$(tail -n 1 "$dir/compare.log")
  passed=$((passed + ${line%% *})); f=${line#* passed, }; failed=$((failed + ${f%% *}))
  # The comparison must be able to fail: one payload digit changed in frame 300.
  awk 'NR == 300 { c = substr($0, length($0)); $0 = substr($0, 1, length($0) - 1) (c == "0" ? "1" : "0") } 1' \
    "$dir/firmware.out" > "$dir/firmware.changed"
  if sh tests/fw/compare.sh "$dir/gateway.log" "$dir/firmware.changed" "$ids" "$hb" "$name" > /dev/null; then
    echo "FAIL: $name: compare.sh accepts a firmware output with one payload digit changed"; failed=$((failed + 1))
  else
    echo "ok: $name: compare.sh refuses a firmware output with one payload digit changed"; passed=$((passed + 1))
  fi
done
echo "footprint of the canopen image on the Cortex-M4 at -Os (arm-none-eabi-size): the image; its tables; lib/"
arm-none-eabi-size "$fw/canopen/fw_gateway.elf" "$fw/canopen/tables.o" "$fw"/lib/*.o
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
