#!/bin/sh
# SPDX-License-Identifier: MIT
# check-ship: see tests/ship/ship.mk.
set -u
BUILD=${BUILD:-build}
MAKE=${MAKE:-make}
PYTHON=${PYTHON:-/usr/bin/python3}
passed=0; failed=0
check() {
  what=$1; shift
  if "$@" >/dev/null 2>&1; then passed=$((passed + 1)); echo "ok: $what"
  else failed=$((failed + 1)); echo "FAIL: $what"; fi
}
T=$(mktemp -d); PIDS=""
trap 'for p in $PIDS; do kill $p 2>/dev/null; done; rm -rf "$T"' EXIT
m() { $MAKE --no-print-directory -s BUILD="$BUILD" "$@"; }

# ---- dependency tiers --------------------------------------------------------------
m deps-list > "$T/deps"
dups=$(awk '{print $2}' "$T/deps" | sort | uniq -d | tr '\n' ' ')
check "deps: $(wc -l < "$T/deps") packages in three tiers, none named twice (twice: ${dups:-none})" [ -z "$dups" ]
check "deps: the build tier holds no test tool (cross compilers, emulators, clang, valgrind, lintian)" \
  sh -c "! grep '^build ' '$T/deps' | grep -Eq 'arm-none-eabi|qemu|clang|valgrind|lintian|python3'"
check "deps: the spy tier holds a GUI Java runtime and jchart2d" \
  sh -c "grep -qx 'spy default-jre' '$T/deps' && grep -qx 'spy libjchart2d-java' '$T/deps'"
m -p -q demo 2>/dev/null | grep '^demo:' > "$T/demo.rule"
check "make demo needs deps-build only ($(cat "$T/demo.rule"))" \
  sh -c "grep -qw deps-build '$T/demo.rule' && ! grep -Eq ' deps( |\$)' '$T/demo.rule'"
m -p -q spy 2>/dev/null | grep '^spy:' > "$T/spy.rule"
check "make spy needs deps-spy" grep -qw deps-spy "$T/spy.rule"
# Not root: the one line to run, and stop.
setpriv --reuid=65534 --regid=65534 --clear-groups $MAKE --no-print-directory -s BUILD="$T/nobody" deps-build \
  DEPS_BUILD="make urrt-no-such-package" > "$T/nonroot" 2>&1; rc=$?
check "deps-build as a user: exit 1 and the one sudo apt-get line" \
  sh -c "[ $rc != 0 ] && grep -qx '  sudo apt-get install -y urrt-no-such-package' '$T/nonroot'"

# ---- make demo -----------------------------------------------------------------------
# In a session of its own, so that "left behind" means this demo's processes
# and not another make check's on the same machine.
setsid -w sh -c 'echo $$ > "$1"; shift; exec "$@"' sh "$T/demo.sid" \
  $MAKE --no-print-directory -s BUILD="$BUILD" demo DEMO_SECONDS=3 > "$T/demo.out" 2> "$T/demo.err"; rc=$?
sed 's/^/demo: /' "$T/demo.out"
check "make demo DEMO_SECONDS=3: exit 0" [ $rc = 0 ]
check "demo: its own robot and LCM URL, not production's default" \
  sh -c "grep -q 'robot demo on udpm://239.255.76.68:7668?ttl=0' '$T/demo.out' && ! grep -q '239.255.76.67:7667' '$T/demo.out'"
check "demo: the gateway connected at once (the simulator listened first)" \
  sh -c "grep -q 'robot demo: connected to 127.0.0.1' '$T/demo.err' && ! grep -qi 'refused' '$T/demo.err'"
check "demo: summary lines with demo.STATE at 500/s" grep -q 'demo.STATE 5[0-9][0-9]/s' "$T/demo.out"
check "demo: says it runs until Ctrl-C, or for DEMO_SECONDS" grep -qx 'demo: runs until Ctrl-C (or 3 s)' "$T/demo.out"
check "demo: the closing lines say how to watch it" sh -c "tail -n 1 '$T/demo.out' | grep -q 'make spy'"
check "demo: no process left behind" sh -c "! pgrep -s $(cat "$T/demo.sid")"
# Ctrl-C as a terminal sends it: SIGINT to the demo's process group, once it publishes.
setsid -w sh -c 'echo $$ > "$1"; shift; exec "$@"' sh "$T/int.sid" \
  $MAKE --no-print-directory -s BUILD="$BUILD" demo > "$T/int.out" 2> "$T/int.err" &
INT=$!; PIDS="$PIDS $INT"
i=0; while ! grep -q 'demo.STATE' "$T/int.out" 2>/dev/null && kill -0 $INT 2>/dev/null && [ $i -lt 1500 ]; do
  sleep 0.02; i=$((i + 1)); done
env kill -s INT -- -"$(cat "$T/int.sid")"; wait $INT  # procps kill: dash's takes no --
check "demo after Ctrl-C: the closing tip, once, and no process left behind" \
  sh -c "[ \$(grep -c 'To watch the next one' '$T/int.out') = 1 ] && ! pgrep -s $(cat "$T/int.sid")"
# A port that is taken: the simulator cannot listen, the demo stops and names the variable.
$PYTHON -c '
import socket, sys, os
s = socket.socket(); s.bind(("127.0.0.1", 0)); s.listen(1)
open(sys.argv[1] + ".tmp", "w").write("%d\n" % s.getsockname()[1]); os.rename(sys.argv[1] + ".tmp", sys.argv[1])
sys.stdin.read()' "$T/busy.port" < /dev/zero > /dev/null &
BUSY=$!; PIDS="$PIDS $BUSY"
i=0; while [ ! -s "$T/busy.port" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
m demo DEMO_SECONDS=3 DEMO_PORT="$(cat "$T/busy.port")" > "$T/busy.out" 2> "$T/busy.err"; rc=$?
kill $BUSY 2>/dev/null
check "demo on a taken port: exit non-zero, names DEMO_PORT, no gateway started" \
  sh -c "[ $rc != 0 ] && grep -q 'make demo DEMO_PORT=N' '$T/busy.err' && ! grep -q 'urrt-gateway' '$T/busy.out'"

# ---- the README's urrt-sim + urrt-dump lines --------------------------------------------
# The text as the README shows it (the one shell block that passes --port-file), run twice
# in a row as a reader would, each run in a session of its own: three packets of 3.10's
# 1116 bytes each time, no "Address already in use", no simulator and no file left behind.
awk '/^```/ { if (inside && block ~ /--port-file/) { printf "%s", block; exit }
              inside = !inside; block = ""; next }
     inside { block = block $0 "\n" }' README.md > "$T/readme.sh"
check "README: one shell block starts urrt-sim and urrt-dump from build/bin/ ($(wc -l < "$T/readme.sh") lines)" \
  sh -c "grep -q 'build/bin/urrt-sim ' '$T/readme.sh' && grep -q 'build/bin/urrt-dump ' '$T/readme.sh'"
sed -i "s|build/bin/|$BUILD/bin/|g" "$T/readme.sh"
mkdir "$T/readme.tmp"; sids=""
for shell in sh bash; do
  TMPDIR="$T/readme.tmp" setsid -w sh -c 'echo $$ > "$1"; shift; exec "$@"' sh "$T/readme.sid" \
    timeout -k 2 30 $shell "$T/readme.sh" > "$T/readme.out" 2> "$T/readme.err"; rc=$?
  sid=$(cat "$T/readme.sid"); sids="$sids $sid"
  check "README's urrt-sim + urrt-dump under $shell: exit 0, packets 1-3 of 1116 bytes with time and q_actual" \
    sh -c "[ $rc = 0 ] && [ \"\$(grep -c '^packet [123]: 1116 bytes' '$T/readme.out')\" = 3 ] &&
           ! grep -q '^packet 4' '$T/readme.out' && [ \"\$(grep -c '^  q_actual ' '$T/readme.out')\" = 3 ] &&
           [ \"\$(grep -c '^  time ' '$T/readme.out')\" = 3 ] && grep -q '^summary: packets: 3\$' '$T/readme.err'"
  check "README's urrt-sim + urrt-dump under $shell: no 'Address already in use'" \
    sh -c "! grep -qi 'address already in use' '$T/readme.err'"
  check "README's urrt-sim + urrt-dump under $shell: no urrt-sim left running" sh -c "! pgrep -s $sid"
  check "README's urrt-sim + urrt-dump under $shell: its temporary directory removed" \
    sh -c "[ -z \"\$(ls -A '$T/readme.tmp')\" ]"
done
# What a failed run left (after both, so that a second run meets the first's simulator).
for sid in $sids; do pkill -s "$sid" 2>/dev/null; done

# ---- urrt-spy -------------------------------------------------------------------------
spy() { URRT_LCMTYPES_JAR="$BUILD/urrt_lcmtypes.jar" DISPLAY=:99 gateway/install/urrt-spy --check "$@"; }
mkdir -p "$T/jre/bin"; printf '#!/bin/sh\nexit 0\n' > "$T/jre/bin/java"; chmod +x "$T/jre/bin/java"
URRT_JAVA="$T/jre/bin/java" spy > "$T/spy1" 2>&1; rc=$?
check "urrt-spy on a headless Java: exit 1, names default-jre, no stack trace" \
  sh -c "[ $rc = 1 ] && grep -q 'headless Java runtime' '$T/spy1' && grep -q 'apt-get install default-jre' '$T/spy1' && ! grep -q Exception '$T/spy1'"
JCHART2D_JAR=$T/none.jar spy > "$T/spy2" 2>&1; rc=$?
check "urrt-spy without jchart2d: names libjchart2d-java" sh -c "[ $rc = 1 ] && grep -q 'apt-get install libjchart2d-java' '$T/spy2'"
URRT_LCMTYPES_JAR="$BUILD/urrt_lcmtypes.jar" DISPLAY= WAYLAND_DISPLAY= gateway/install/urrt-spy --check > "$T/spy3" 2>&1; rc=$?
check "urrt-spy without a display: says so" sh -c "[ $rc = 1 ] && grep -q 'no display' '$T/spy3'"
# From the source tree with no URRT_LCMTYPES_JAR: the jar is where `make` put it, $BUILD
# (build/ when BUILD is not set). A stand-in GUI runtime and jars, so that the jar is the
# one thing looked for.
mkdir -p "$T/gui/bin" "$T/gui/lib"; cp "$T/jre/bin/java" "$T/gui/bin/java"
touch "$T/gui/lib/libawt_xawt.so" "$T/lcm.jar" "$T/jchart2d.jar"
tree_spy() { env -u URRT_LCMTYPES_JAR "$@" URRT_JAVA="$T/gui/bin/java" LCM_JAR="$T/lcm.jar" \
  JCHART2D_JAR="$T/jchart2d.jar" DISPLAY=:99 gateway/install/urrt-spy --check; }
tree_spy BUILD="$BUILD" > "$T/spy5" 2>&1; rc=$?
check "urrt-spy --check from the source tree after make BUILD=$BUILD: ready, with $BUILD/urrt_lcmtypes.jar" \
  sh -c "[ $rc = 0 ] && grep -qx 'urrt-spy: ready: $T/gui/bin/java, $(cd "$BUILD" && pwd)/urrt_lcmtypes.jar' '$T/spy5'"
tree_spy -u BUILD > "$T/spy6" 2>&1; rc=$?
check "urrt-spy --check from the source tree without BUILD: looks in build/" \
  sh -c "grep -Eq '(ready: .*|not found \()$(pwd)/build/urrt_lcmtypes.jar' '$T/spy6'"
if [ -f "$(dirname "$(dirname "$(readlink -f "$(command -v java)")")")/lib/libawt_xawt.so" ]; then
  spy > "$T/spy4" 2>&1; rc=$?
  check "urrt-spy with the spy tier installed: ready" sh -c "[ $rc = 0 ] && grep -q 'ready' '$T/spy4'"
fi

# ---- the examples' sentinels before the first packet ------------------------------------
# The gateway with a robot that never answers (a port bound, not listening) and the CAN
# frames to a log: what a PLC sees before the first packet.
$PYTHON -c '
import socket, sys, os
s = socket.socket(); s.bind(("127.0.0.1", 0))
open(sys.argv[1] + ".tmp", "w").write("%d\n" % s.getsockname()[1]); os.rename(sys.argv[1] + ".tmp", sys.argv[1])
sys.stdin.read()' "$T/dead.port" < /dev/zero > /dev/null &
DEAD=$!; PIDS="$PIDS $DEAD"
i=0; while [ ! -s "$T/dead.port" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
for ex in canopen fd; do
  sed -e "s|^interface = .*|interface = log:$T/$ex.log|; s|^host = .*|host = 127.0.0.1|; s|^port = .*|port = $(cat "$T/dead.port")|" \
    "docs/examples/$ex.ini" > "$T/$ex.ini"
  grep -q '^port = ' "$T/$ex.ini" || sed -i "s|^host = 127.0.0.1|host = 127.0.0.1\nport = $(cat "$T/dead.port")|" "$T/$ex.ini"
  "$BUILD/bin/urrt-gateway" -u 'udpm://239.255.76.69:7669?ttl=0' -l err "$T/$ex.ini" 2> "$T/$ex.err" &
  G=$!; PIDS="$PIDS $G"
  want=$([ $ex = canopen ] && echo '185#' || echo '##')
  i=0; while [ "$(cat "$T/$ex.log" 2>/dev/null | grep -c "$want")" -lt 3 ] && [ $i -lt 500 ] && kill -0 $G 2>/dev/null; do
    sleep 0.02; i=$((i + 1)); done
  kill $G 2>/dev/null; wait $G 2>/dev/null
done
# TPDO1 (0x185): q0..q2 = -32768 (00 80, Intel) each, not 0.0 rad; valid (bit 63) = 0.
check "canopen.ini before the first packet: joints -32768, not 0.0 rad; valid = 0" \
  sh -c "grep -q '185#0080008000800' '$T/canopen.log' && ! grep '185#' '$T/canopen.log' | grep -q '#000000'"
# The FD frame: robot mode -128 (0x80) and safety mode 255 at bytes 60 and 61.
check "fd.ini before the first packet: modes -128 and 255, not raw 0" \
  sh -c "grep -o '##[0-9A-F]*' '$T/fd.log' | head -n 1 | cut -c4- | cut -c121-124 | grep -qx 80FF"

echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
