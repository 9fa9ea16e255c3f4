# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh, for make check-canopen: urrt-sim -> urrt-gateway,
# a CANopen node on vcan0, managed by tests/canopen/master.py (Debian's Python
# and python3-can, staged by stage-python.sh as /t/py), recorded by candump for
# the host's checks (canopen.post). Step 9 of the master cuts the robot link
# (cut.sh: the simulator ends) and brings it back (restore.sh: a new one on the
# same port). The simulators' time column is this VM's CLOCK_MONOTONIC, and
# clocks.txt pairs it with CLOCK_REALTIME (candump's stamps) at the start and
# the end, so that tests/fw/record_master.py can put the master's frames on
# the recorded stream's clock (make record-fw-master).
. ./lib.sh
. ./counts.sh
node=5
ln -sf /t/py/bin/python3 /usr/bin/python3
export PYTHONHOME=/t/py

# sim SEED LISTEN: a simulator in the background, back once it listens; its port in $port.
sim() {
  rm -f "$OUT/sim.port"
  urrt-sim --listen "$2" --port-file "$OUT/sim.port" --version 5.10 --rate 125 --seed "$1" --clock monotonic \
    --record "$OUT/sim$1.bin" >"$OUT/sim$1.log" 2>&1 &
  echo $! > "$OUT/sim.pid"
  i=0
  while [ ! -s "$OUT/sim.port" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
  port=$(cat "$OUT/sim.port" 2>/dev/null)
  [ -n "$port" ] || { echo "urrt-sim did not start:"; cat "$OUT/sim$1.log"; }
}
if [ "${1:-}" = cut ]; then
  pid=$(cat "$OUT/sim.pid"); kill "$pid"; while kill -0 "$pid" 2>/dev/null; do sleep 0.02; done
  exit 0
elif [ "${1:-}" = restore ]; then
  sim 2 "127.0.0.1:$(cat "$OUT/port")" </dev/null
  exit 0
fi

check "urrt-gateway --print-eds" urrt-gateway --print-eds canopen.ini -o "$OUT/node.eds"
check "urrt-gateway --print-dbc" urrt-gateway --print-dbc canopen.ini -o "$OUT/node.dbc"
# "REALTIME MONOTONIC REALTIME" in ns: the monotonic reading between two realtime ones.
clocks() {
  python3 -c 'import time; c = time.clock_gettime_ns
print(c(time.CLOCK_REALTIME), c(time.CLOCK_MONOTONIC), c(time.CLOCK_REALTIME))' >>"$OUT/clocks.txt"
}
clocks
candump -L vcan0 >"$OUT/can.log" 2>"$OUT/candump.err" & dump=$!
sim 1 127.0.0.1:0
echo "$port" > "$OUT/port"
sed "s/^port = .*/port = $port/" canopen.ini > "$OUT/canopen.ini"
# The gateway starts once the master listens, so that the master sees its boot-up.
( i=0
  while [ ! -e "$OUT/ready" ] && [ $i -lt 1500 ]; do sleep 0.02; i=$((i + 1)); done
  exec urrt-gateway "$OUT/canopen.ini" >"$OUT/gateway.log" 2>&1 ) & gw=$!
counted "master.py" python3 master.py --channel vcan0 --node $node --eds "$OUT/node.eds" --out "$OUT" \
  --ready "$OUT/ready" --cut "sh /t/canopen.sh cut" --restore "sh /t/canopen.sh restore"
kill $gw; wait $gw; gw_rc=$?
clocks
kill "$(cat "$OUT/sim.pid")" $dump 2>/dev/null; wait 2>/dev/null
check "the gateway stops cleanly on SIGTERM (exit $gw_rc)" [ "$gw_rc" = 0 ]
check "candump recorded vcan0" [ -s "$OUT/can.log" ]
finish
