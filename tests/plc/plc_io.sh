# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh, for make check-plc-io: docs/examples/plc-io.ini end to
# end. urrt-sim serves RTDE (a 3.10 controller: 125 Hz); urrt-gateway writes the
# example's input registers from the PLC's frames on vcan0 and sends robot_answer
# back; plc_io.py is the PLC and a recording proxy between the gateway and urrt-sim
# (the configuration's port is the proxy's). Only the robot's address, the CAN
# interface, the metrics file, the robot's backoff and silence timeout are changed
# from the example. With BENCH=N (make bench-plc-io): robot_answer goes with every
# package, and plc_io.py times N frames both ways instead of checking.
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
lcm_sub 'udpm://239.255.76.67:7667?ttl=0' 'arm1\.(RTDE|GATEWAY)' 120 "$OUT/lcm.ready" >"$OUT/lcm.jsonl" \
  2>"$OUT/lcm_sub.err" & sub=$!
i=0
while [ ! -e "$OUT/lcm.ready" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
# The gateway starts once the PLC's proxy listens and another client holds register 24.
( i=0
  while [ ! -e "$OUT/ready" ] && [ $i -lt 1500 ]; do sleep 0.02; i=$((i + 1)); done
  port=$(cat "$OUT/proxy.port")
  # backoff_max: the long backoff after IN_USE, short for the test; silence_timeout:
  # the emulated CPU may stall longer than the example's 100 ms.
  sed -e "s/^host = .*/host = 127.0.0.1\nport = $port\nbackoff_max = 2 s\nsilence_timeout = 2 s/" \
      -e "s/^interface = .*/interface = vcan0/" \
      -e "${BENCH:+s/^period_ms = 20/period_ms = every/}" \
      -e "1i [gateway]\nmetrics_file = $OUT/metrics.prom\nmetrics_interval = 100 ms\n" \
      plc-io.ini >"$OUT/plc-io.ini"
  exec urrt-gateway "$OUT/plc-io.ini" >"$OUT/gateway.log" 2>&1 ) & gw=$!
if [ -n "${BENCH:-}" ]; then
  python3 plc_io.py --channel vcan0 --sim-port "$sim_port" --proxy-port-file "$OUT/proxy.port" \
    --ready "$OUT/ready" --metrics "$OUT/metrics.prom" --rate 125 --bench "$BENCH"
  kill $gw $sim $dump $sub 2>/dev/null; wait 2>/dev/null
  exit 0
fi
counted "plc_io.py" python3 plc_io.py --channel vcan0 --sim-port "$sim_port" --proxy-port-file "$OUT/proxy.port" \
  --ready "$OUT/ready" --metrics "$OUT/metrics.prom" --rate 125
kill $gw; wait $gw; gw_rc=$?
kill $sim $dump $sub 2>/dev/null; wait 2>/dev/null
counted "LCM (plc_io.py --lcm)" python3 plc_io.py --lcm "$OUT/lcm.jsonl"
check "the gateway stops cleanly on SIGTERM (exit $gw_rc)" [ "$gw_rc" = 0 ]
check "--check-config on the test's configuration prints the [input]" \
  sh -c "urrt-gateway --check-config '$OUT/plc-io.ini' | grep -q '^input plc_command (0x200): robot arm1: input_int_register_24 <- job_number'"
in_use=$(grep -c 'IN_USE' "$OUT/gateway.log")
echo "gateway.log: $in_use lines name IN_USE; $(grep -c 'the PLC is silent' "$OUT/gateway.log") silences," \
  "$(grep -c 'the PLC writes again' "$OUT/gateway.log") resumptions"
check "IN_USE is logged, and not once per attempt ($in_use lines)" [ "$in_use" -ge 1 ] && [ "$in_use" -le 2 ]
check "the gateway says the PLC fell silent (timeout)" grep -q '\[input plc_command\]: the PLC is silent (no frame for 100 ms)' "$OUT/gateway.log"
check "the gateway says the CAN interface went down" grep -q '\[input plc_command\]: the PLC is silent (the CAN interface is down)' "$OUT/gateway.log"
if [ "$FAILED" != 0 ]; then
  echo "---- gateway.log"; tail -n 30 "$OUT/gateway.log"
fi
finish
