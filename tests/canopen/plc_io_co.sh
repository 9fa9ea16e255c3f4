# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh, for make check-canopen: docs/examples/plc-io-canopen.ini
# end to end. urrt-sim serves RTDE (a 3.10 controller: 125 Hz); urrt-gateway is CANopen
# node 5 on vcan0 and writes the example's input registers from RPDO1 (and SDO writes);
# plc_io_co.py is the manager and a recording proxy between the gateway and urrt-sim (the
# configuration's port is the proxy's). Only the robot's address, the CAN interface, the
# robot's backoff and silence timeout are changed from the example.
. ./lib.sh
. ./counts.sh
ln -sf /t/py/bin/python3 /usr/bin/python3
export PYTHONHOME=/t/py

urrt-sim --listen 127.0.0.1:0 --rtde 127.0.0.1:0 --rtde-port-file "$OUT/rtde.port" --controller 3.10 \
  --seed 1 >"$OUT/sim.log" 2>&1 & sim=$!
i=0
while [ ! -s "$OUT/rtde.port" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
sim_port=$(cat "$OUT/rtde.port" 2>/dev/null)
check "urrt-sim serves RTDE" [ -n "$sim_port" ]
candump -L vcan0 >"$OUT/can.log" 2>"$OUT/candump.err" & dump=$!
# The gateway starts once the manager listens (it sees the boot-up) and the proxy is up.
( i=0
  while [ ! -e "$OUT/ready" ] && [ $i -lt 1500 ]; do sleep 0.02; i=$((i + 1)); done
  port=$(cat "$OUT/proxy.port")
  sed -e "s/^host = .*/host = 127.0.0.1\nport = $port\nbackoff_max = 2 s\nsilence_timeout = 2 s/" \
      -e "s/^interface = .*/interface = vcan0/" plc-io-canopen.ini >"$OUT/plc-io-canopen.ini"
  exec urrt-gateway "$OUT/plc-io-canopen.ini" >"$OUT/gateway.log" 2>&1 ) & gw=$!
counted "plc_io_co.py" python3 plc_io_co.py --channel vcan0 --node 5 --sim-port "$sim_port" \
  --proxy-port-file "$OUT/proxy.port" --ready "$OUT/ready" --rate 125
kill $gw; wait $gw; gw_rc=$?
kill $sim $dump 2>/dev/null; wait 2>/dev/null
check "the gateway stops cleanly on SIGTERM (exit $gw_rc)" [ "$gw_rc" = 0 ]
check "the gateway says the manager's heartbeat is lost" grep -q "\[input plc_command\]: the PLC is silent (the manager's heartbeat is lost (0x1016))" "$OUT/gateway.log"
check "the gateway says the node is not OPERATIONAL" grep -q "\[input plc_command\]: the PLC is silent (the CANopen node is not OPERATIONAL)" "$OUT/gateway.log"
check "the gateway says no RPDO1 or SDO write came" grep -q "\[input plc_command\]: the PLC is silent (no RPDO1 or SDO write for 100 ms)" "$OUT/gateway.log"
if [ "$FAILED" != 0 ]; then
  echo "---- gateway.log"; tail -n 30 "$OUT/gateway.log"
fi
finish
