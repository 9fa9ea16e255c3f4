#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's run: for each configuration, the capture through
# urrt-gateway --replay and through its firmware image on qemu's Cortex-M4,
# then the comparison; the results added up. An RTDE configuration (fw.mk
# wrote DIR/controller.bin for it) replays the RTDE capture, and its image
# reads what the scripted controller of that capture sends it; the requests
# the image sent are checked too.
#   run.sh BUILD_DIR FW_DIR CONFIG...
set -u
build=$1; fw=$2; shift 2
passed=0; failed=0
for name in "$@"; do
  dir=$fw/$name
  ini=$dir/gateway.ini
  rm -f "$dir/gateway.log"
  # A recorded configuration has its own capture; a CANopen node is fed the manager's frames
  # (fw.mk writes rx.log for it: empty when no manager talks to it).
  capture=$fw/capture.bin; [ -f "$dir/capture.bin" ] && capture=$dir/capture.bin
  stream=$capture; [ -f "$dir/controller.bin" ] && { capture=$fw/rtde-capture.bin; stream=$dir/controller.bin; }
  rx=; [ -s "$dir/rx.log" ] && rx="--replay-rx $dir/rx.log"
  # [input]s: the input packages the replay would write to the robot.
  inputs=; grep -q '^const urrt_plcin_desc urrt_gateway_inputs' "$dir/tables.c" && inputs="--replay-inputs $dir/inputs.log"
  # shellcheck disable=SC2086
  "$build/bin/urrt-gateway" --replay "$capture" $rx $inputs "$ini" 2> "$dir/replay.err" || {
    echo "FAIL: $name: urrt-gateway --replay: $(cat "$dir/replay.err")"; failed=$((failed + 1)); continue; }
  qemu-system-arm -nographic -monitor none -serial none \
    -semihosting-config "enable=on,target=native,arg=$stream" \
    -M mps2-an386 -kernel "$dir/fw_gateway.elf" > "$dir/firmware.out" 2>&1
  # What the configuration says: its frames and the heartbeat, as the log writes their ids.
  # A CANopen node: its heartbeat 0x700 + node id and its EMCY 0x080 + node id, no status
  # TPDO (off until enabled), and without a manager's frames no SYNC-driven TPDO either.
  node=$(sed -n 's/^node_id = //p' "$ini")
  want=
  if [ -f "$dir/controller.bin" ]; then
    # The image's side of the handshake: only V, v, O, S, the O naming the tables' recipe.
    /usr/bin/python3 tests/fw/rtde_controller.py check "$dir/firmware.out" "$dir/tables.c" "$dir/controller.bin" \
      > "$dir/requests.log"
    sed "s/^/$name: /" "$dir/requests.log" | grep -v ' failed$'
    passed=$((passed + $(grep -c '^ok: ' "$dir/requests.log"))); failed=$((failed + $(grep -c '^FAIL: ' "$dir/requests.log")))
  fi
  if [ -n "$node" ] && [ -n "$rx" ]; then
    # A recorded manager: which ids come depends on what it did when, so the ids are not
    # counted; what the frames it sent ask for is: a boot-up at power-on and after each
    # reset (node or communication, to this node or all), and one SDO answer to each
    # request but a client's abort (command specifier 4) while not stopped (CiA 301).
    ids=-
    hb=$(printf '%03X' $((0x700 + node)))
    want=$(awk -v node="$(printf '%02X' "$node")" -v sdo="$(printf '%03X' $((0x600 + node)))" '
      /^#/ { next }
      { split($3, f, "#"); cs = substr(f[2], 1, 2); to = substr(f[2], 3, 2) }
      f[1] == "000" && (to == node || to == "00") {
        if (cs == "02") stopped = 1; else stopped = 0
        if (cs == "81" || cs == "82") boots++ }
      f[1] == sdo && !stopped && substr(f[2], 1, 1) !~ /[89]/ { answers++ }
      END { print boots + 1, answers + 0 }' "$dir/rx.log")
  elif [ -n "$node" ]; then
    ids=$(( $(grep -c '^\[frame ' "$ini") - $(grep -c '^transmission = sync' "$ini") + 2 ))
    hb=$(printf '%03X' $((0x700 + node)))
  else
    ids=$(( $(grep -c '^\[frame ' "$ini") + 1 ))
    hb=$(sed -n 's/^heartbeat_id = 0x//p' "$ini" | tr a-f A-F)
    if grep -q '^heartbeat_extended = yes' "$ini"; then hb=$(printf '%08X' "0x$hb"); else hb=$(printf '%03X' "0x$hb"); fi
  fi
  echo "== $name: $ids ids, heartbeat $hb"
  # shellcheck disable=SC2086
  sh tests/fw/compare.sh "$dir/gateway.log" "$dir/firmware.out" "$ids" "$hb" "$name" "${node:--}" $want \
    > "$dir/compare.log"
  grep -v ' passed, ' "$dir/compare.log"
  line=$(tail -n 1 "$dir/compare.log")
  passed=$((passed + ${line%% *})); f=${line#* passed, }; failed=$((failed + ${f%% *}))
  # A recorded run: the replay answers the master's SDO requests as the live node did.
  if [ -f "$dir/node.log" ]; then
    sdo=$(printf '%03X' $((0x580 + node)))
    grep -v '^#' "$dir/node.log" | awk '{ print $3 }' > "$dir/answers.live"
    awk '{ print $3 }' "$dir/gateway.log" | grep "^$sdo#" > "$dir/answers.replay"
    if cmp -s "$dir/answers.live" "$dir/answers.replay"; then
      echo "ok: $name: the replay's $(wc -l < "$dir/answers.live") SDO answers are the live node's"; passed=$((passed + 1))
    else
      echo "FAIL: $name: the replay's SDO answers are not the live node's (diff $dir/answers.live $dir/answers.replay):"
      diff "$dir/answers.live" "$dir/answers.replay" | head -n 5; failed=$((failed + 1))
    fi
  fi
  # The PLC's answers: the input packages the image sent ("rtde> " lines of type 'U') are the
  # replay's, byte for byte and in order; and that comparison refuses one digit changed.
  if [ -n "$inputs" ]; then
    sed -n 's/^rtde> \(....55.*\)$/\1/p' "$dir/firmware.out" > "$dir/inputs.firmware"
    awk '{ print $2 }' "$dir/inputs.log" > "$dir/inputs.replay"
    n=$(wc -l < "$dir/inputs.replay")
    if [ "$n" -ge 50 ] && cmp -s "$dir/inputs.replay" "$dir/inputs.firmware"; then
      echo "ok: $name: the image's $n input packages are the replay's, byte for byte and in order"
      passed=$((passed + 1))
    else
      echo "FAIL: $name: the image's input packages are not the replay's $n (diff $dir/inputs.replay $dir/inputs.firmware):"
      diff "$dir/inputs.replay" "$dir/inputs.firmware" | head -n 5; failed=$((failed + 1))
    fi
    awk -v k=$(((n + 1) / 2)) 'NR == k { c = substr($0, 9, 1); $0 = substr($0, 1, 8) (c == "0" ? "1" : "0") substr($0, 10) } 1' \
      "$dir/inputs.firmware" > "$dir/inputs.changed"
    if cmp -s "$dir/inputs.replay" "$dir/inputs.changed"; then
      echo "FAIL: $name: the comparison accepts an input package with one digit changed"; failed=$((failed + 1))
    else
      echo "ok: $name: the comparison refuses an input package with one digit changed"; passed=$((passed + 1))
    fi
  fi
  # The comparison must be able to fail: one payload digit changed in the middle frame (in an
  # RTDE configuration the middle frame of the first id that carries an RTDE-only value, in
  # that value), and the refusal must name that frame.
  frame='^[0-9A-F]+##?[0-9A-F]*$'
  only=
  [ -f "$dir/controller.bin" ] &&
    only=$(sed -n 's/.*_sources, [0-9]*, [0-9]*, [^,]*, 0x\([0-9A-F]*\), .*_fill}, .*/\1/p' "$dir/tables.c" | head -n 1)
  k=$(grep -E "$frame" "$dir/firmware.out" | awk -v id="$only" '
    { split($0, f, "#"); if (id == "" || f[1] ~ ("^0*" id "$")) at[++m] = NR }
    END { print at[int((m + 1) / 2)] }')
  # The last payload digit; in an RTDE configuration the first, where its first signal (an
  # RTDE-only value in both) starts.
  awk -v frame="$frame" -v k="$k" -v first="$only" '
    $0 ~ frame && ++n == k {
      at = first == "" ? length($0) : index($0, "#") + 1
      c = substr($0, at, 1); $0 = substr($0, 1, at - 1) (c == "0" ? "1" : "0") substr($0, at + 1) }
    1' "$dir/firmware.out" > "$dir/firmware.changed"
  # shellcheck disable=SC2086
  if sh tests/fw/compare.sh "$dir/gateway.log" "$dir/firmware.changed" "$ids" "$hb" "$name" "${node:--}" $want \
       > "$dir/compare.changed"; then
    echo "FAIL: $name: compare.sh accepts a firmware output with one payload digit changed"; failed=$((failed + 1))
  elif ! grep -q "^frame $k: " "$dir/compare.changed"; then
    echo "FAIL: $name: compare.sh refuses a changed firmware output without naming frame $k:"
    head -n 3 "$dir/compare.changed"; failed=$((failed + 1))
  else
    echo "ok: $name: compare.sh refuses a firmware output with one payload digit changed: $(grep "^frame $k: " "$dir/compare.changed")"
    passed=$((passed + 1))
  fi
done
# The image given RealTime's port for its RTDE robot (fw.mk's rtde-port) refuses it and writes
# no request: not one "rtde> " line.
qemu-system-arm -nographic -monitor none -serial none \
  -semihosting-config "enable=on,target=native,arg=$fw/rtde-types/controller.bin" \
  -M mps2-an386 -kernel "$fw/rtde-port/fw_gateway.elf" > "$fw/rtde-port/firmware.out" 2>&1
if grep -q '^fw_gateway: refusing RTDE on port 30003: the RealTime interface, which runs the URScript it receives$' \
     "$fw/rtde-port/firmware.out" && ! grep -q 'rtde> ' "$fw/rtde-port/firmware.out"; then
  echo "ok: rtde-port: the image refuses RTDE on port 30003 and sends no request"; passed=$((passed + 1))
else
  echo "FAIL: rtde-port: the image given port 30003 did not refuse it before any request:"
  head -n 3 "$fw/rtde-port/firmware.out"; failed=$((failed + 1))
fi
echo "footprint of the canopen image on the Cortex-M4 at -Os (arm-none-eabi-size): the image; its tables; lib/"
arm-none-eabi-size "$fw/canopen/fw_gateway.elf" "$fw/canopen/tables.o" "$fw"/lib/*.o
echo "footprint of the rtde-plc image (RTDE, a CANopen node) on the Cortex-M4 at -Os: the image; its tables"
arm-none-eabi-size "$fw/rtde-plc/fw_gateway.elf" "$fw/rtde-plc/tables.o"
# docs/footprint.md's figures of that image, and the check shown to fail on a RAM figure one byte off.
sh tests/fw/footprint.sh docs/footprint.md "$fw/rtde-plc/fw_gateway.elf" "$fw/rtde-plc/tables.o" > "$fw/footprint.log"
cat "$fw/footprint.log"
passed=$((passed + $(grep -c '^ok: ' "$fw/footprint.log"))); failed=$((failed + $(grep -c '^FAIL: ' "$fw/footprint.log")))
awk '/<!-- fw-footprint:begin/ { on = 1 } on && !done && $NF == "|" && $(NF - 1) ~ /^[0-9]+$/ { $(NF - 1) += 1; done = 1 } 1' \
  docs/footprint.md > "$fw/footprint.wrong.md"
if sh tests/fw/footprint.sh "$fw/footprint.wrong.md" "$fw/rtde-plc/fw_gateway.elf" "$fw/rtde-plc/tables.o" > /dev/null; then
  echo "FAIL: footprint.sh accepts a RAM figure one byte off"; failed=$((failed + 1))
else
  echo "ok: footprint.sh refuses a RAM figure one byte off"; passed=$((passed + 1))
fi
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
