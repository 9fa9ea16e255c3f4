#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's verdict for one configuration: urrt-gateway's CAN log
# (candump -l lines) and the firmware image's output ("ID#DATA" lines) must
# hold the same frames in the same order: id (its width is the extended
# flag), FD or classic, payload. The FD flags nibble of the log is the link's
# bit rate switch setting, not the frame's: it is not compared. The capture
# must also have made both show what it is there for: every frame of the
# configuration and the heartbeat, a heartbeat that said "ok" and one that
# said "data stale"; for canopen.ini also frames sent invalid (stall, clamp,
# NaN) and the stop-policy frame stopping during the stall.
#   compare.sh GATEWAY_LOG FIRMWARE_OUTPUT IDS HEARTBEAT_ID NAME
set -u
gw_log=$1; fw_out=$2; want_ids=$3; hb=$4; name=$5
tmp=${TMPDIR:-/tmp}/urrt-fw-compare.$$
trap 'rm -f "$tmp".*' EXIT
awk '{ print $3 }' "$gw_log" | sed 's/##[0-9A-F]/##/' > "$tmp.gw"
grep -E '^[0-9A-F]+##?[0-9A-F]*$' "$fw_out" | sed 's/##[0-9A-F]/##/' > "$tmp.fw"
awk -v gwfile="$tmp.gw" -v want_ids="$want_ids" -v hb="$hb" -v name="$name" '
function check(ok, what) { if (ok) passed++; else { failed++; print "FAIL: " name ": " what } }
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
        split(gw[i], part, "#"); ids[part[1]]++; data = gw[i]; sub(/^[0-9A-F]+##?/, "", data)
        if (part[1] == hb) state[substr(data, 2, 1)]++
        if (part[1] == "185" && substr(data, 15, 1) ~ /[0-7]/) invalid++
    }
    check(length(ids) == want_ids, "frames of " length(ids) " ids, not the " want_ids " of the configuration")
    check(state["1"] > 0, "no heartbeat said ok")
    check(state["2"] > 0, "no heartbeat said data stale")
    if (name == "canopen") {
        check(invalid > 0, "no 0x185 frame went out invalid (stall, clamp, NaN)")
        check(ids["385"] < ids["185"] / 2 - 5, "0x385 (stop policy, 20 ms) did not stop during the stall")
    }
    printf "%s: frames compared: %d; per id:", name, n
    for (id in ids) printf " %s %d", id, ids[id]
    printf "; heartbeat ok %d, stale %d%s\n", state["1"], state["2"], name == "canopen" ? "; 0x185 invalid " invalid : ""
    printf "%d passed, %d failed\n", passed, failed
    exit failed > 0
}' "$tmp.fw"
