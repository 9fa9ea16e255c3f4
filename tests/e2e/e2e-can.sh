# SPDX-License-Identifier: MIT
# Runs inside the VM (tests/vm/run.sh): urrt-sim -> urrt-gateway -> vcan0,
# recorded by candump. Markers on vcan1 (ID 0x7FF) time the events for
# e2e-can.post, which decodes the recording through the DBC on the host.
# candump -D keeps recording vcan0 through its outage (a candump started
# after the interface came back up could miss the first heartbeat after it),
# and its error-frame filter (#FFFFFFFF) records the injected bus-off too. The first simulator takes its port from
# the system (--port-file), the gateway's configuration is written with it, and
# the second simulator (the robot coming back) listens on the same port.
. ./lib.sh

mark() { cansend vcan1 "7FF#0$1"; }
# sim SEED LISTEN: a simulator in the background, back once it listens, its port in $port.
sim() {
  rm -f "$OUT/sim.port"
  urrt-sim --listen "$2" --port-file "$OUT/sim.port" --version 5.10 --rate 125 --seed "$1" \
    --record "$OUT/sim$1.bin" >"$OUT/sim$1.log" 2>&1 & sim_pid=$!
  i=0
  while [ ! -s "$OUT/sim.port" ] && [ $i -lt 500 ] && kill -0 "$sim_pid" 2>/dev/null; do sleep 0.02; i=$((i + 1)); done
  port=$(cat "$OUT/sim.port" 2>/dev/null)
  [ -n "$port" ] || { echo "urrt-sim did not start:"; cat "$OUT/sim$1.log"; }
}

check "the DBC is written" urrt-gateway --print-dbc -o "$OUT/e2e.dbc" e2e-can.ini
candump -L vcan1 >"$OUT/marks.log" 2>>"$OUT/candump.err" & marks=$!
candump -D -L vcan0,0:0,#FFFFFFFF >"$OUT/can.log" 2>>"$OUT/candump.err" & dump=$!
sim 1 127.0.0.1:0
sed "s/^port = .*/port = $port/" e2e-can.ini > "$OUT/e2e-can.ini"
check "the gateway's configuration names the simulator's port ($port)" grep -q "^port = $port\$" "$OUT/e2e-can.ini"
lcm_sub 'udpm://239.255.76.67:7667?ttl=0' 'arm1\.GATEWAY' 30 >"$OUT/lcm.jsonl" 2>"$OUT/lcm_sub.err" & sub=$!
urrt-gateway "$OUT/e2e-can.ini" >"$OUT/gateway.log" 2>&1 & gw=$!
sleep 4
mark 1; kill "$sim_pid"; wait "$sim_pid"      # the robot goes away
sleep 2
mark 2; sim 2 "127.0.0.1:$port"                 # and comes back
sleep 3
ip link set vcan0 down; mark 3                  # the CAN interface goes down
sleep 1.5
mark 4; ip link set vcan0 up                    # and up (marked first: the gateway may send
                                                # before a slow VM has started cansend)
sleep 3
mark 5; can_error vcan0                         # the controller reports bus-off
sleep 1.5
mark 6
kill "$gw"; wait "$gw"; gw_rc=$?
kill "$sim_pid" "$dump" "$marks" "$sub"; wait "$sim_pid" "$dump" "$marks" "$sub" 2>/dev/null

check "the gateway stops cleanly on SIGTERM (exit $gw_rc)" [ "$gw_rc" = 0 ]
check "the gateway reported the interface down" grep -q "vcan0.*down" "$OUT/gateway.log"
check "the gateway reconnected to the robot" [ "$(grep -c 'connected to 127.0.0.1' "$OUT/gateway.log")" -ge 2 ]
check "candump recorded vcan0" [ -s "$OUT/can.log" ]
finish
