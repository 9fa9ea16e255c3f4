#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's verdict: urrt-gateway's CAN log (candump -l lines) and
# the firmware image's output ("ID#DATA" lines) must hold the same frames in
# the same order (id, FD flag, payload), and the capture must have made
# both show what it is there for: every frame of the configuration, frames
# sent invalid, a stopped frame, a heartbeat that said "data stale".
#   compare.sh GATEWAY_LOG FIRMWARE_OUTPUT
set -u
gw_log=$1; fw_out=$2
tmp=${TMPDIR:-/tmp}/urrt-fw-compare.$$
trap 'rm -f "$tmp".*' EXIT
awk '{ print $3 }' "$gw_log" > "$tmp.gw"
grep -E '^[0-9A-F]+##?[0-9A-F]*$' "$fw_out" > "$tmp.fw"
awk -v gwfile="$tmp.gw" '
function check(ok, what) { if (ok) passed++; else { failed++; print "FAIL: " what } }
BEGIN { while ((getline line < gwfile) > 0) gw[++ngw] = line }
{ fw[++nfw] = $0 }
END {
    check(ngw > 0, "urrt-gateway sent no frame")
    check(ngw == nfw, "urrt-gateway sent " ngw " frames, the firmware " nfw)
    n = ngw < nfw ? ngw : nfw; shown = 0
    for (i = 1; i <= n; i++) {
        same = gw[i] == fw[i]
        if (!same && shown++ < 5) print "frame " i ": urrt-gateway " gw[i] ", firmware " fw[i]
        if (same) passed++; else failed++
        split(gw[i], part, "#"); ids[part[1]]++
        if (part[1] == "185" && substr(part[2], 15, 1) ~ /[0-7]/) invalid++
        if (part[1] == "705") state[substr(part[2], 2, 1)]++
    }
    check(length(ids) == 5, "frames of " length(ids) " ids, not the 4 frames and the heartbeat of canopen.ini")
    check(invalid > 0, "no 0x185 frame went out invalid (stall, clamp, NaN)")
    check(ids["385"] < ids["185"] / 2 - 5, "0x385 (stop policy, 20 ms) did not stop during the stall")
    check(state["2"] > 0, "no heartbeat said data stale")
    check(state["1"] > 0, "no heartbeat said ok")
    printf "frames compared: %d; per id:", n
    for (id in ids) printf " %s %d", id, ids[id]
    printf "; 0x185 invalid %d; heartbeat ok %d, stale %d\n", invalid, state["1"], state["2"]
    printf "%d passed, %d failed\n", passed, failed
    exit failed > 0
}' "$tmp.fw"
