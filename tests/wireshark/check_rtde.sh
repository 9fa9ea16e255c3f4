#!/bin/sh
# SPDX-License-Identifier: MIT
# check-wireshark-rtde: the generated dissector ($BUILD/urrt.lua) on RTDE
# sessions against the clients that took part in them. urrt-sim serves RTDE
# (port from the system) to urrt-dump --rtde in protocol 2 and, with the
# fault rtde-refuse-v2, in protocol 1, each with segments cut small
# (tiny-writes) and with packages coalesced, with text messages during the
# handshake and between data packages; a session is run by
# tests/gateway/tools/rtde_peer.py, which asks for a name the controller
# lacks (NOT_FOUND), sends setup inputs, pauses and sends a text message;
# two more (protocol 2 and 1, the simulator with --fieldbus) set up input
# recipes refused (IN_USE, NOT_FOUND) and accepted and write registers with
# data packages of their own (some of no recipe or the wrong size), which
# the output recipe reads back.
# tshark captures them all at once on loopback while the clients record
# what they decoded: urrt-dump records its session (--rtde -w) and
# afterwards prints it from that capture (--file, JSON, which must equal
# what it printed live); then tshark dissects the pcap (one pass, and two
# passes, where every frame is dissected again from the session state kept
# for it) and compare_rtde.py matches every data package by its controller
# timestamp with a client record, value by value. The capture's recipe holds
# more than the client's -k (a recording asks for the RealTime set and the
# status values too), so --file prints without -k: every value of every
# package.
# Every process runs under timeout; every wait is for an event, with a bound.
set -u
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-/usr/bin/python3}
SIM=$BUILD/bin/urrt-sim
DUMP=$BUILD/bin/urrt-dump
LUA=$BUILD/urrt.lua
N=24
. tests/lib.sh
T=$(mktemp -d "${TMPDIR:-/tmp}/urrt-wireshark-rtde.XXXXXX")
PIDS=""
cleanup() {
  for p in $PIDS; do kill "$p" 2>/dev/null; done
  [ -n "${KEEP:-}" ] || rm -rf "$T"   # KEEP=1: keep the capture and outputs
}
trap cleanup EXIT INT TERM

# Only the dissector under test, no settings of this user; root's tshark
# reads the capture as nobody (Wireshark ignores WIRESHARK_PLUGIN_DIR for root).
export WIRESHARK_PLUGIN_DIR="$T/plugins" HOME="$T/home"
mkdir -p "$WIRESHARK_PLUGIN_DIR" "$HOME"
chmod 755 "$T"
cp "$LUA" "$T/urrt.lua" && LUA=$T/urrt.lua
reader() {
  if [ "$(id -u)" = 0 ]; then setpriv --reuid=nobody --regid=nogroup --clear-groups "$@"; else "$@"; fi
}

if ! command -v tshark > /dev/null; then
  fail "tshark is not installed (make deps installs it)"; finish; exit 1
fi

# waitfor WHAT PID COMMAND...: until COMMAND holds (at most 20 s), or fails
# at once when process PID has ended. Polls: no sleep to be long enough.
waitfor() {
  what=$1; pid=$2; shift 2
  i=0
  while [ $i -lt 1000 ]; do
    "$@" && return 0
    kill -0 "$pid" 2>/dev/null || { "$@" && return 0; break; }
    sleep 0.02; i=$((i + 1))
  done
  echo "waited in vain for $what" >&2
  return 1
}

# Every RTDE type an output has (no output is VECTOR6UINT32), mapped and
# RTDE-only variables, enumerations, bit masks.
KEYS=timestamp,actual_q,target_TCP_pose,robot_mode,joint_mode,actual_digital_input_bits,runtime_state,\
output_int_register_24,output_bit_register_64,tool_output_mode,robot_status_bits,output_double_register_3,\
actual_tool_accelerometer,safety_status_bits,speed_scaling
# Cases: NAME, protocol, fewest text messages, client (all: urrt-dump's
# recording recipe, keys: that and -k KEYS, peer: rtde_peer.py), expert infos, sim
# options. edges: tests/wireshark/rtde_controller.py serves the extremes of
# every type instead of urrt-sim and records what it sent; rtde_peer.py asks.
# inputs: rtde_peer.py writes inputs and records what it sent (NAME.sent).
cat > "$T/cases" <<'EOF'
v2-coalesce 2 3 keys - -c 5.12 -n 24 --fault coalesce=4 --fault rtde-text-every=6
v2-tiny 2 4 all - -c 3.10 -n 24 --fault tiny-writes=50 --fault rtde-text-handshake
v1-tiny 1 3 keys - -c 5.12 -n 24 --fault rtde-refuse-v2 --fault tiny-writes=30 --fault rtde-text-every=6,level=1
v1-coalesce 1 5 all - -c 3.10 -n 24 --fault rtde-refuse-v2 --fault coalesce=5 --fault rtde-text-handshake
peer 2 0 peer not_found -c 5.12 -n 100000
edges 2 0 edges - rtde_controller.py
inputs 2 2 inputs not_found+in_use+input_recipe+data_size -c 5.12 -n 100000 --fieldbus
inputs-v1 1 1 inputs not_found+in_use+data_size -c 3.10 -n 100000 --fieldbus
EOF
# The peer: protocol 2, a recipe with a name no controller has (NOT_FOUND),
# setup inputs, then a good recipe, N data packages, pause (the packages that
# come before its reply recorded too), a text message of its own, close.
PEER='import json, sys
sys.path.insert(0, "tests/gateway/tools")
import rtde_peer
port, out, n = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
p = rtde_peer.Peer(port, timeout=20)
assert p.protocol_version(2) == 1
p.controller_version()
assert p.setup_outputs(["timestamp", "no_such_output"], 125.0)[1] == ["DOUBLE", "NOT_FOUND"]
p.setup_inputs(["input_int_register_24"])
names = ["timestamp", "actual_q", "output_bit_register_64", "tool_output_mode", "joint_mode",
         "robot_status_bits", "actual_digital_input_bits", "output_int_register_24"]
p.setup_outputs(names, 125.0)
assert p.start() == 1
got = p.data(n)
p.foreign = []
assert p.pause() == 1
got += [p.decode(b) for kind, b in p.foreign if kind == rtde_peer.U]
p.send(rtde_peer.M, bytes([4]) + b"done" + bytes([4]) + b"peer" + bytes([3]))
p.close()
with open(out, "w") as f:
    for vals in got:
        f.write(json.dumps({k: list(v) if isinstance(v, tuple) else v for k, v in zip(names, vals)}) + "\n")'

# The inputs sessions (protocol $5): a setup of inputs refused (IN_USE: the
# fieldbus's register 0; NOT_FOUND: register 48), recipes B (other inputs
# than registers) and A (registers past the fieldbus's, the last: a
# protocol 1 package is its), an output recipe that reads A back, start;
# then N data packages, after every one an input package with the extremes
# of A's types (B's too in protocol 2), one of a recipe id the connection lacks (protocol 2) and
# one a byte too long, which the controller ignores; pause, close. The
# output packages go to OUT, every input package sent to SENT (JSON lines:
# id, names, types, values, whether the controller takes it).
INPUTS='import json, sys
sys.path.insert(0, "tests/gateway/tools")
import rtde_peer
port, out, sent, n, proto = int(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
p = rtde_peer.Peer(port, timeout=20)
if proto == 2:
    assert p.protocol_version(2) == 1
p.controller_version()
assert p.setup_inputs(["input_int_register_0", "input_int_register_48", "input_int_register_25"]) == \
    (0, ["IN_USE", "NOT_FOUND", "INT32"])
b_names = ["speed_slider_fraction", "speed_slider_mask", "external_force_torque", "standard_digital_output"]
a_names = ["input_int_register_24", "input_double_register_24", "input_bit_register_64", "input_bit_register_127"]
b, b_types = p.setup_inputs(b_names)
a, a_types = p.setup_inputs(a_names)
assert (b, a) == (2, 3), (b, a)
names = ["timestamp"] + a_names
p.setup_outputs(names, 125.0) if proto == 2 else p.setup_outputs(names)
assert p.start() == 1
ints, bits, words = [-2 ** 31, 2 ** 31 - 1, -1, 0], [1, 0, 2, 255], [2 ** 32 - 1, 2 ** 31 + 1, 0, 1]
doubles = [-0.0, 5e-324, float("inf"), float("-inf"), 1.7976931348623157e308, 0.1]
log = open(sent, "w")
def send(rid, names, types, values, taken, payload=None):
    p.send(rtde_peer.U, payload if payload is not None else p.input_package(rid, values, types))
    log.write(json.dumps({"id": rid, "names": names, "types": types, "values": values, "taken": taken}) + "\n")
got = []
for i in range(n):
    got += p.data(1)
    send(a, a_names, a_types, [ints[i % 4], doubles[i % 6], bits[i % 4], bits[(i + 1) % 4]], True)
    if proto == 2 and i % 3 == 0:
        send(b, b_names, b_types, [doubles[-i % 6], words[i % 4], doubles[i % 6:] + doubles[:i % 6], 255 - i], True)
    if i == 5 and proto == 2:
        send(9, ["input_int_register_24"], ["INT32"], [7], False)
    if i == 7:
        send(a, a_names + ["x"], a_types + ["UINT8"], [1, 1.0, 1, 1, 1], False)
p.foreign = []
assert p.pause() == 1
got += [p.decode(x) for kind, x in p.foreign if kind == rtde_peer.U]
p.close()
with open(out, "w") as f:
    for vals in got:
        f.write(json.dumps(dict(zip(names, vals))) + "\n")'

EDGES='import sys
sys.path.insert(0, "tests/gateway/tools")
import rtde_peer
p = rtde_peer.Peer(int(sys.argv[1]), timeout=20)
assert p.protocol_version(2) == 1
p.controller_version()
p.setup_outputs(["timestamp", "output_int_register_0", "joint_mode", "robot_status_bits",
                 "actual_digital_output_bits", "output_bit_register_64", "tool_output_mode", "actual_q"], 125.0)
assert p.start() == 1
p.data(int(sys.argv[2]))
p.close()'

# ---- simulators, one per case, each waiting for its one client ---------------------
PORTS=""
while read -r name proto texts client experts opts; do
  if [ "$client" = edges ]; then
    timeout -k 3 60 $PYTHON tests/wireshark/rtde_controller.py "$T/$name.port" "$T/$name.json" $N \
      2> "$T/$name.sim" &
  else
    # shellcheck disable=SC2086 # opts is a word list
    timeout -k 3 60 "$SIM" -l 127.0.0.1:0 --rtde 127.0.0.1:0 --rtde-port-file "$T/$name.port" \
      --start-on-connect --clients 1 $opts 2> "$T/$name.sim" &
  fi
  pid=$!; PIDS="$PIDS $pid"
  if waitfor "$name's port file" $pid test -s "$T/$name.port"; then
    PORTS="$PORTS $(cat "$T/$name.port")"
  else
    sed 's/^/    sim: /' "$T/$name.sim" >&2
  fi
done < "$T/cases"
check "every simulator listens" [ "$(echo $PORTS | wc -w)" = "$(wc -l < "$T/cases")" ]

# ---- capture --------------------------------------------------------------------
# tshark prints each frame it has written (source port, FIN flag): a
# simulator's FIN printed means all of its session is in the file.
filter=$(for p in $PORTS; do printf ' or tcp port %s' "$p"; done)
timeout -k 3 120 tshark -i lo -f "${filter# or }" -w "$T/cap.pcapng" -P -l \
  -T fields -e tcp.srcport -e tcp.flags.fin > "$T/live" 2> "$T/tshark.err" &
TSHARK=$!; PIDS="$PIDS $TSHARK"
if ! waitfor "tshark's 'Capture started'" $TSHARK grep -q 'Capture started' "$T/tshark.err"; then
  sed 's/^/    tshark: /' "$T/tshark.err" >&2
  fail "tshark captures on lo (capturing needs root or the wireshark group)"; finish; exit 1
fi
ok "tshark captures on lo"

CLIENTS=""
while read -r name proto texts client experts opts; do
  port=$(cat "$T/$name.port" 2>/dev/null) || continue
  case $client in
    peer) timeout -k 3 60 $PYTHON -c "$PEER" "$port" "$T/$name.json" $N 2> "$T/$name.client" & ;;
    edges) timeout -k 3 60 $PYTHON -c "$EDGES" "$port" $N 2> "$T/$name.client" & ;;
    inputs) timeout -k 3 60 $PYTHON -c "$INPUTS" "$port" "$T/$name.json" "$T/$name.sent" $N "$proto" \
              2> "$T/$name.client" & ;;
    keys) timeout -k 3 60 "$DUMP" --rtde "127.0.0.1:$port" -w "$T/$name.rtde" --once -t 10 -F json --no-summary \
            -k "$KEYS" > "$T/$name.live" 2> "$T/$name.client" & ;;
    *) timeout -k 3 60 "$DUMP" --rtde "127.0.0.1:$port" -w "$T/$name.rtde" --once -t 10 -F json --no-summary \
         > "$T/$name.live" 2> "$T/$name.client" & ;;
  esac
  CLIENTS="$CLIENTS $!"
done < "$T/cases"
for p in $CLIENTS; do wait "$p"; done

all_fins() {
  for p in $PORTS; do grep -q "^$p	1" "$T/live" || return 1; done
}
check "tshark wrote every session to its end" waitfor "every simulator's FIN in the capture" $TSHARK all_fins
kill "$TSHARK" 2>/dev/null; wait "$TSHARK" 2>/dev/null
chmod 644 "$T/cap.pcapng"

# ---- the clients' records ---------------------------------------------------------
# urrt-dump's: its capture printed by urrt-dump --file, every value; with the
# client's own -k it prints what the session printed live.
while read -r name proto texts client experts opts; do
  case $client in keys|all) ;; *) continue ;; esac
  [ "$client" = keys ] && k="-k $KEYS" || k=
  timeout -k 3 60 "$DUMP" --file "$T/$name.rtde" -F json --no-summary > "$T/$name.json" 2> "$T/$name.file"
  check "$name: urrt-dump --file reads its capture" [ $? = 0 ]
  # shellcheck disable=SC2086 # k is "-k LIST" or nothing
  timeout -k 3 60 "$DUMP" --file "$T/$name.rtde" -F json --no-summary $k > "$T/$name.again" 2>> "$T/$name.file"
  check "$name: urrt-dump --file of the capture prints what it printed live" cmp -s "$T/$name.again" "$T/$name.live"
  [ -s "$T/$name.json" ] || sed 's/^/    file: /' "$T/$name.file" >&2
done < "$T/cases"
specs=""
while read -r name proto texts client experts opts; do
  port=$(cat "$T/$name.port" 2>/dev/null) || continue
  lines=$(wc -l < "$T/$name.json")
  if [ "$client" = edges ]; then
    check "$name: rtde_controller.py sent $N data packages" [ "$lines" = $N ]
  elif [ "$client" = peer ] || [ "$client" = inputs ]; then
    check "$name: rtde_peer.py decoded $N data packages or more" [ "$lines" -ge $N ]
  else
    check "$name: urrt-dump decoded $N data packages in protocol $proto" \
      [ "$lines:$(grep -c "\"protocol\":$proto," "$T/$name.json")" = "$N:$N" ]
  fi
  [ "$lines" -gt 0 ] || sed 's/^/    client: /' "$T/$name.client" >&2
  [ "$experts" != - ] || experts=
  [ "$client" = inputs ] && sent=":$T/$name.sent" || sent=
  specs="$specs $name:$port:$T/$name.json:$proto:$texts:$experts$sent"
done < "$T/cases"

# ---- dissect and compare --------------------------------------------------------
# compare LABEL TSHARK_OPTIONS...: dissect by port (Decode As), compare.
compare() {
  label=$1; shift
  # shellcheck disable=SC2046 # one -d per port
  if ! reader timeout -k 3 120 tshark -r "$T/cap.pcapng" -X lua_script:"$LUA" "$@" \
      $(for p in $PORTS; do printf -- '-d tcp.port==%s,urrt_rtde ' "$p"; done) -Y urrt_rtde -T pdml \
      > "$T/$label.pdml" 2> "$T/$label.err"; then
    cat "$T/$label.err" >&2; fail "$label: tshark failed"; return
  fi
  if grep -q 'Lua Error\|Lua: Error' "$T/$label.pdml" "$T/$label.err"; then
    grep -m 3 'Lua Error\|Lua: Error' "$T/$label.pdml" "$T/$label.err" >&2; fail "$label: Lua errors"
  fi
  # A field read past its bytes is an exception, shown as a malformed packet.
  if grep -q '_ws.malformed' "$T/$label.pdml"; then
    grep -m 3 -B 3 '_ws.malformed' "$T/$label.pdml" >&2; fail "$label: malformed packets (an exception in the dissector)"
  fi
  # shellcheck disable=SC2086 # specs is a word list
  $PYTHON tests/wireshark/compare_rtde.py docs/protocol.md "$T/$label.pdml" "$label" $specs > "$T/$label.out"
  cat "$T/$label.out"
  PASSED=$((PASSED + $(grep -c '^ok: ' "$T/$label.out")))
  FAILED=$((FAILED + $(grep -c '^FAIL: ' "$T/$label.out")))
  grep -q ' compared: ' "$T/$label.out" || fail "$label: compare_rtde.py did not finish"
}
compare one-pass
compare two-pass -2

# The text views: the Info column carries the controller timestamp of each
# data package; the peer's packages read as what they are.
reader timeout -k 3 60 tshark -r "$T/cap.pcapng" -X lua_script:"$LUA" \
  $(for p in $PORTS; do printf -- '-d tcp.port==%s,urrt_rtde ' "$p"; done) -Y urrt_rtde \
  -T fields -e tcp.srcport -e tcp.dstport -e _ws.col.Info > "$T/info" 2> "$T/info.err"
# The packages tshark reassembled from several segments, each whole. A frame
# that ends one may also hold whole packages of other types, so the frames a
# filter on the type selects are not the count: the bytes tell.
reader timeout -k 3 60 tshark -r "$T/cap.pcapng" -X lua_script:"$LUA" \
  $(for p in $PORTS; do printf -- '-d tcp.port==%s,urrt_rtde ' "$p"; done) -Y 'tcp.reassembled.length' \
  -T fields -e tcp.srcport -e tcp.reassembled.data > "$T/reassembled" 2>> "$T/info.err"
peer=$(cat "$T/peer.port" 2>/dev/null)
check "Info: every data package's controller timestamp" \
  [ "$(grep -o 'U from controller: t=[0-9.]*' "$T/info" | wc -l)" -ge $((4 * N)) ]
# has PORT TEXT...: the Info column of frames of that session holds each TEXT.
has() {
  port=$1; shift
  for text in "$@"; do
    grep -q -e "^$port	.*$text" -e "^[0-9]*	$port	.*$text" "$T/info" || { echo "no Info \"$text\"" >&2; return 1; }
  done
}
check "Info: the peer's setup inputs, its NOT_FOUND recipe, text message and pause" \
  has "$peer" "I request: 1 names" "O reply: recipe INVALID 0, 2 types" "M from client: info: done (peer)" \
  "P request" "P reply: accepted"
# reassembled_as_split PORT SPLIT TOTAL SPLITFILE: the session's N data
# packages, some cut over segments, and the data packages tshark reassembled
# on PORT are exactly those, byte for byte and in order (SPLITFILE's lines
# after the first: each split package in hex).
reassembled_as_split() {
  [ "$3" = $N ] && [ "$2" -ge 1 ] || return 1
  awk -F '\t' -v port="$1" '$1 == port { gsub(":", "", $2); if (substr($2, 5, 2) == "55") print $2 }' \
    "$T/reassembled" > "$T/reassembled.$1"
  tail -n +2 "$4" | cmp -s - "$T/reassembled.$1"
}
# The faults did what they are for: packages cut over segments, several per
# segment. Which data packages travel in more than one segment is the
# kernel's to decide (a late simulator's pieces may be coalesced), so the
# segments themselves, read without the dissector, say which ones must be
# reassembled (split_packages.py).
for name in v2-tiny v1-tiny; do
  port=$(cat "$T/$name.port")
  reader timeout -k 3 60 tshark -r "$T/cap.pcapng" -o tcp.relative_sequence_numbers:TRUE \
    -Y "tcp.srcport == $port && tcp.len > 0" -T fields -e tcp.seq -e tcp.len -e tcp.payload \
    2>> "$T/info.err" | $PYTHON tests/wireshark/split_packages.py > "$T/$name.split"
  read -r split total < "$T/$name.split" || split=0 total=0
  check "$name: the data packages cut over segments ($split of $total) are the ones reassembled" \
    reassembled_as_split "$port" "$split" "$total" "$T/$name.split"
done
for name in v2-coalesce v1-coalesce; do
  check "$name: segments holding several data packages" has "$(cat "$T/$name.port")" "U from controller.*U from controller"
done
check "Info: protocol 2 refused and 1 accepted" has "$(cat "$T/v1-tiny.port")" "V reply: 2 refused" "V reply: 1 accepted"
check "Info: the inputs session's setups of inputs and its data packages" \
  has "$(cat "$T/inputs.port")" "I request: 3 names" "I reply: input recipe INVALID 0, 3 types" \
  "I reply: input recipe 2, 4 types" "I reply: input recipe 3, 4 types" "U from client: input recipe 3, 4 values" \
  "U from client: input recipe 2, 4 values" "U from client: no input recipe 9" \
  "U from client: input recipe 3: size not the recipe's"
check "Info: protocol 1: a client's data package is of the last input recipe" \
  has "$(cat "$T/inputs-v1.port")" "I reply: input recipe 3, 4 types" "U from client: input recipe 3, 4 values"
finish
