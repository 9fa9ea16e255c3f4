#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's verdict for one configuration: urrt-gateway's CAN log
# (candump -l lines) and the firmware image's output ("ID#DATA" lines) must
# hold the same frames in the same order: id (its width is the extended
# flag), FD or classic, payload. The FD flags nibble of the log is the link's
# bit rate switch setting, not the frame's: it is not compared. The capture
# must also have made both show what it is there for: every frame of the
# configuration and the heartbeat, a heartbeat that said "ok" and one that
# said "data stale" (canopen.ini, a CANopen node: the boot-up, an operational
# heartbeat, the stale EMCY and its reset); for canopen.ini also frames sent
# invalid (stall, clamp, NaN) and the stop-policy frame stopping during the stall.
# A node fed a recorded manager's frames (canopen-vm; IDS "-": not counted): the
# boot-up first, BOOTS boot-ups and SDO_ANSWERS answers, as run.sh worked them out
# from the frames the manager sent.
#   compare.sh GATEWAY_LOG FIRMWARE_OUTPUT IDS HEARTBEAT_ID NAME [BOOTS SDO_ANSWERS]
set -u
gw_log=$1; fw_out=$2; want_ids=$3; hb=$4; name=$5; want_boots=${6:-}; want_sdo=${7:-}
tmp=${TMPDIR:-/tmp}/urrt-fw-compare.$$
trap 'rm -f "$tmp".*' EXIT
awk '{ print $3 }' "$gw_log" | sed 's/##[0-9A-F]/##/' > "$tmp.gw"
grep -E '^[0-9A-F]+##?[0-9A-F]*$' "$fw_out" | sed 's/##[0-9A-F]/##/' > "$tmp.fw"
awk -v gwfile="$tmp.gw" -v want_ids="$want_ids" -v hb="$hb" -v name="$name" -v want_boots="$want_boots" \
  -v want_sdo="$want_sdo" -v sdo_id="$(printf '%03X' $((0x580 + 0x$hb - 0x700)))" '
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
        if (part[1] == "185" && substr(data, 15, 2) == "00") invalid++   # canopen.ini: byte 7, the validity bit of TPDO1
    }
    if (want_ids != "-")
        check(length(ids) == want_ids, "frames of " length(ids) " ids, not the " want_ids " of the configuration")
    if (name == "canopen") {
        # A CANopen node: boot-up [00], then heartbeats [05] (operational); the EMCY of stale data
        # (0xFF02) during the stall and its reset (0x0000) after it.
        check(gw[1] == hb "#00", "the first frame is not the boot-up " hb "#00")
        check(state["5"] > 0, "no heartbeat said operational")
        for (i = 1; i <= n; i++) {
            if (gw[i] ~ /^085#02FF/) stale_emcy++
            if (gw[i] ~ /^085#0000..02FF/) reset_emcy++
        }
        check(stale_emcy > 0, "no EMCY 0xFF02 (robot data stale) during the stall")
        check(reset_emcy > 0, "no EMCY reset of 0xFF02 after the stall")
    } else if (want_boots != "") {
        # Fed the frames a recorded manager sent: what they ask for, by CiA 301.
        for (i = 1; i <= n; i++) if (gw[i] == hb "#00") boots++
        check(gw[1] == hb "#00", "the first frame is not the boot-up " hb "#00")
        check(boots == want_boots, "boot-ups at power-on and after each NMT reset: " boots + 0 ", not " want_boots)
        check(ids[sdo_id] == want_sdo, "SDO answers (" sdo_id "): " ids[sdo_id] + 0 ", not one for each of the " \
              want_sdo " requests")
    } else {
        check(state["1"] > 0, "no heartbeat said ok")
        check(state["2"] > 0, "no heartbeat said data stale")
    }
    if (name == "canopen") {
        check(invalid > 0, "no 0x185 frame went out invalid (stall, clamp, NaN)")
        check(ids["385"] < ids["185"] / 2 - 5, "0x385 (stop policy, 20 ms) did not stop during the stall")
    }
    printf "%s: frames compared: %d; per id:", name, n
    for (id in ids) printf " %s %d", id, ids[id]
    if (name == "canopen")
        printf "; heartbeat operational %d, EMCY stale %d, reset %d; 0x185 invalid %d\n", state["5"], stale_emcy,
            reset_emcy, invalid
    else if (want_boots != "")
        printf "; boot-ups %d, SDO answers %d\n", boots, ids[sdo_id]
    else
        printf "; heartbeat ok %d, stale %d\n", state["1"], state["2"]
    printf "%d passed, %d failed\n", passed, failed
    exit failed > 0
}' "$tmp.fw"
