# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh, for make check-canopen: docs/examples/rtde-plc.ini
# end to end. urrt-sim serves RTDE (a 5.10 controller: 500 Hz), urrt-gateway reads it
# with the example's configuration (only the robot's address and the CAN interface
# changed) and sends output_int_register_24 and the status bits as TPDO1 of its
# CANopen node on vcan0; rtde_plc.py, the PLC's manager, imports the node's EDS and
# checks the TPDOs against urrt-sim's model, and each valid = 0 one against the node's
# EMCYs and its own data's age. candump records the bus for the host; rtde_plc.py
# keeps the frames it judged in plc-frames.txt (rtde_plc.py --judge reads them back).
. ./lib.sh
. ./counts.sh
node=5
ln -sf /t/py/bin/python3 /usr/bin/python3
export PYTHONHOME=/t/py

urrt-sim --listen 127.0.0.1:0 --rtde 127.0.0.1:0 --rtde-port-file "$OUT/rtde.port" --controller 5.10 \
  --seed 1 >"$OUT/sim.log" 2>&1 & sim=$!
i=0
while [ ! -s "$OUT/rtde.port" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
port=$(cat "$OUT/rtde.port" 2>/dev/null)
check "urrt-sim serves RTDE" [ -n "$port" ]
sed -e "s/^host = .*/host = 127.0.0.1\nport = $port/" -e "s/^interface = .*/interface = vcan0/" rtde-plc.ini \
  >"$OUT/rtde-plc.ini"
check "urrt-gateway --check-config on the example" urrt-gateway --check-config "$OUT/rtde-plc.ini"
check "urrt-gateway --print-eds" urrt-gateway --print-eds "$OUT/rtde-plc.ini" -o "$OUT/node.eds"
# The bound the node judges its data by, from the example: rtde_plc.py bounds the age
# of each valid = 1 TPDO1's data by it (each valid = 0 one it holds to the node's EMCYs).
stale_ms=$(sed -n '/^\[can\]/,/^\[/s/^stale_after_ms = *\([0-9]*\).*/\1/p' "$OUT/rtde-plc.ini")
check "rtde-plc.ini gives stale_after_ms ($stale_ms)" [ -n "$stale_ms" ]
candump -L vcan0 >"$OUT/can.log" 2>"$OUT/candump.err" & dump=$!
# The gateway starts once the manager listens, so that it sees the boot-up.
( i=0
  while [ ! -e "$OUT/ready" ] && [ $i -lt 1500 ]; do sleep 0.02; i=$((i + 1)); done
  exec urrt-gateway "$OUT/rtde-plc.ini" >"$OUT/gateway.log" 2>&1 ) & gw=$!
counted "rtde_plc.py" python3 rtde_plc.py --channel vcan0 --node $node --eds "$OUT/node.eds" \
  --ready "$OUT/ready" --rate 500 --stale-after-ms "${stale_ms:-100}" --frames "$OUT/plc-frames.txt"
kill $gw; wait $gw; gw_rc=$?
kill $sim $dump 2>/dev/null; wait 2>/dev/null
check "the gateway stops cleanly on SIGTERM (exit $gw_rc)" [ "$gw_rc" = 0 ]
# What the gateway said of old data over the whole run (the window is a part of it):
# packets read too late to publish, the robot's data fresh again, the link lost.
echo "gateway.log: $(grep -c 'older than silence_timeout' "$OUT/gateway.log") late-data warnings," \
  "$(grep -c 'data fresh again' "$OUT/gateway.log") fresh-again notices," \
  "$(grep -c 'connection to .* lost' "$OUT/gateway.log") connections lost"
if [ "$FAILED" != 0 ]; then
  echo "---- gateway.log"; tail -n 20 "$OUT/gateway.log"
fi
finish
