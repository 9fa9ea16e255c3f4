#!/bin/sh
# SPDX-License-Identifier: MIT
# check-wireshark: the generated dissector ($BUILD/urrt.lua) against urrt-dump.
# Simulators serve every known length, lengths no controller sends, streams in
# tiny writes (a message over many segments, segments holding the end of one
# and the start of the next), coalesced writes (several messages per segment)
# and garbage between messages; tshark captures them all at once on loopback
# while urrt-dump reads each. tshark then dissects the capture twice, with the
# streams found by the dissector's heuristic and by port (as Decode As or
# 30003/30013 do), and compare.py holds every field of every message against
# urrt-dump's JSON and every column against its gnuplot output, bit for bit.
# Every process runs under timeout; every wait is for an event, with a bound.
set -u
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-/usr/bin/python3}
SIM=$BUILD/bin/urrt-sim
DUMP=$BUILD/bin/urrt-dump
LUA=$BUILD/urrt.lua
N=24
. tests/lib.sh
T=$(mktemp -d "${TMPDIR:-/tmp}/urrt-wireshark.XXXXXX")
PIDS=""
cleanup() {
  for p in $PIDS; do kill "$p" 2>/dev/null; done
  [ -n "${KEEP:-}" ] || rm -rf "$T"   # KEEP=1: keep the capture and outputs
}
trap cleanup EXIT INT TERM

# Only the dissector under test: not one installed in Wireshark's global or
# personal plugin folders (two would clash), and no settings of this user.
# Wireshark ignores WIRESHARK_PLUGIN_DIR when run by root, so root's tshark
# reads the capture as nobody.
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
tshark --version | head -n 1

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

# Cases: NAME, implausible headers expected in N messages, whether the
# heuristic takes the stream (only known controller lengths), simulator options.
cat > "$T/cases" <<'EOF'
early540 0 yes --length 540
early692 0 yes --length 692 --fault coalesce=3
v1.5 0 yes --version 1.5 --fault tiny-writes=500
v1.7 0 yes --version 1.7
v1.8 0 yes --version 1.8 --fault tiny-writes
v3.0 0 yes --version 3.0 --fault coalesce=4
v3.2 0 yes --version 3.2
v3.5 0 yes --version 3.5 --fault tiny-writes=1000
v3.10 0 yes --version 3.10 --fault tiny-writes
v3.14 0 yes --version 3.14
v5.10 0 yes --version 5.10 --fault coalesce=5
short36 0 no --length 36
unknown924 0 no --length 924 --fault coalesce=2
extra1236 0 no --length 1236 --fault tiny-writes=100
garbage 4 yes --version 3.10 --fault garbage-every=5 --fault coalesce=2
urscript 0 yes --version 3.10
EOF
# urscript's client sends a line of URScript as it connects, as a program on
# 30003 may, then records what it reads; urrt-dump decodes the recording.
CLIENT='import socket, sys
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])))
s.sendall(b"textmsg(\"urrt\")\n")
with open(sys.argv[2], "wb") as f:
    for b in iter(lambda: s.recv(65536), b""):
        f.write(b)'

# ---- simulators, one per case, each waiting for its one client ---------------------
PORTS=""
while read -r name skips heur opts; do
  # shellcheck disable=SC2086 # opts is a word list
  timeout -k 3 60 "$SIM" -l 127.0.0.1:0 --port-file "$T/$name.port" --start-on-connect \
    --clients 1 -n $N $opts 2> "$T/$name.sim" &
  pid=$!; PIDS="$PIDS $pid"
  if waitfor "$name's port file" $pid test -s "$T/$name.port"; then
    PORTS="$PORTS $(cat "$T/$name.port")"
  else
    sed 's/^/    sim: /' "$T/$name.sim" >&2
  fi
done < "$T/cases"
check "every simulator listens" [ "$(echo $PORTS | wc -w)" = "$(wc -l < "$T/cases")" ]

# ---- capture --------------------------------------------------------------------
# tshark writes the capture and prints each frame it has written (source port,
# FIN flag): a simulator's FIN printed means all its data is in the file.
filter=$(for p in $PORTS; do printf ' or tcp port %s' "$p"; done)
timeout -k 3 120 tshark -i lo -f "${filter# or }" -w "$T/cap.pcapng" -P -l \
  -T fields -e tcp.srcport -e tcp.flags.fin > "$T/live" 2> "$T/tshark.err" &
TSHARK=$!; PIDS="$PIDS $TSHARK"
# Its "Capturing on" line comes before dumpcap has even started; "Capture
# started" once dumpcap has opened the interface and the file.
if ! waitfor "tshark's 'Capture started'" $TSHARK grep -q 'Capture started' "$T/tshark.err"; then
  sed 's/^/    tshark: /' "$T/tshark.err" >&2
  fail "tshark captures on lo (capturing needs root or the wireshark group)"; finish; exit 1
fi
ok "tshark captures on lo"

DUMPS=""
while read -r name skips heur opts; do
  port=$(cat "$T/$name.port" 2>/dev/null) || continue
  if [ "$name" = urscript ]; then
    timeout -k 3 60 $PYTHON -c "$CLIENT" "$port" "$T/$name.bin" 2> "$T/$name.dump" &
  else
    timeout -k 3 60 "$DUMP" "127.0.0.1:$port" --once -t 10 -F json -w "$T/$name.bin" --no-summary \
      > "$T/$name.json" 2> "$T/$name.dump" &
  fi
  DUMPS="$DUMPS $!"
done < "$T/cases"
for p in $DUMPS; do wait "$p"; done

all_fins() {
  for p in $PORTS; do grep -q "^$p	1" "$T/live" || return 1; done
}
check "tshark wrote every stream to its end" waitfor "every simulator's FIN in the capture" $TSHARK all_fins
kill "$TSHARK" 2>/dev/null; wait "$TSHARK" 2>/dev/null
chmod 644 "$T/cap.pcapng"

# ---- dissect and compare --------------------------------------------------------
specs=""; heur_specs=""
while read -r name skips heur opts; do
  port=$(cat "$T/$name.port" 2>/dev/null) || continue
  [ "$name" != urscript ] ||
    "$DUMP" --file "$T/$name.bin" -F json --no-summary > "$T/$name.json" 2>> "$T/$name.dump"
  "$DUMP" --file "$T/$name.bin" -F gnuplot --no-summary > "$T/$name.gp" 2>> "$T/$name.dump"
  check "$name: urrt-dump read $N packets" [ "$(wc -l < "$T/$name.json")" = $N ]
  specs="$specs $name:$port:$T/$name.json:$T/$name.gp:$skips"
  if [ "$heur" = yes ]; then hjson=$T/$name.json; else hjson=-; fi
  heur_specs="$heur_specs $name:$port:$hjson:$T/$name.gp:$skips"
done < "$T/cases"

# compare LABEL SPECS TSHARK_OPTIONS...: dissect, compare, count compare.py's lines.
compare() {
  label=$1; cases=$2; shift 2
  if ! reader timeout -k 3 120 tshark -r "$T/cap.pcapng" -X lua_script:"$LUA" "$@" -Y urrt -T pdml \
      > "$T/$label.pdml" 2> "$T/$label.err"; then
    cat "$T/$label.err" >&2; fail "$label: tshark failed"; return
  fi
  if grep -q 'Lua Error\|Lua: Error' "$T/$label.pdml" "$T/$label.err"; then
    grep -m 3 'Lua Error\|Lua: Error' "$T/$label.pdml" "$T/$label.err" >&2; fail "$label: Lua errors"
  fi
  # shellcheck disable=SC2086 # cases is a word list
  $PYTHON tests/wireshark/compare.py docs/protocol.md "$T/$label.pdml" "$label" $cases > "$T/$label.out"
  cat "$T/$label.out"
  PASSED=$((PASSED + $(grep -c '^ok: ' "$T/$label.out")))
  FAILED=$((FAILED + $(grep -c '^FAIL: ' "$T/$label.out")))
  grep -q ' compared: ' "$T/$label.out" || fail "$label: compare.py did not finish"
}
compare heuristic "$heur_specs"
compare port "$specs" --disable-heuristic urrt_tcp $(for p in $PORTS; do printf -- '-d tcp.port==%s,urrt ' "$p"; done)
# By port the client's bytes are always the dissector's (by heuristic only when
# the robot's first segment came before them).
check "urscript: the client's 16 bytes shown as sent to the controller, not decoded" \
  [ "$(grep -c '"Universal Robots RealTime, 16 bytes to the controller' "$T/port.pdml")" = 1 ]

finish
