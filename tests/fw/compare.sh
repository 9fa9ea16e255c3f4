#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's verdict for one configuration: urrt-gateway's CAN log
# (candump -l lines) and the firmware image's output ("ID#DATA" lines) must
# hold the same frames in the same order: id (its width is the extended
# flag), FD or classic, payload. The FD flags nibble of the log is the link's
# bit rate switch setting, not the frame's: it is not compared. The capture
# must also have made both show what it is there for: every frame of the
# configuration and the heartbeat, a heartbeat that said "ok" and one that
# said "data stale" (a CANopen node, NODE its id, "-" for none: the boot-up,
# an operational heartbeat, the stale EMCY and its reset); for canopen.ini and
# rtde-plc.ini also TPDO1 frames sent invalid (stall, clamp, NaN), for
# canopen.ini the stop-policy frame stopping during the stall; for rtde-types
# the RTDE values the capture is there for (bit 31 of a UINT32 mask, high bits
# of a UINT64 mask, a frame sent invalid).
# A node fed a recorded manager's frames (canopen-vm; IDS "-": not counted): the
# boot-up first, BOOTS boot-ups and SDO_ANSWERS answers, as run.sh worked them out
# from the frames the manager sent.
#   compare.sh GATEWAY_LOG FIRMWARE_OUTPUT IDS HEARTBEAT_ID NAME NODE [BOOTS SDO_ANSWERS]
set -u
gw_log=$1; fw_out=$2; want_ids=$3; hb=$4; name=$5; node=$6; want_boots=${7:-}; want_sdo=${8:-}
emcy=-; [ "$node" != - ] && emcy=$(printf '%03X' $((0x80 + node)))
tmp=${TMPDIR:-/tmp}/urrt-fw-compare.$$
trap 'rm -f "$tmp".*' EXIT
awk '{ print $3 }' "$gw_log" | sed 's/##[0-9A-F]/##/' > "$tmp.gw"
grep -E '^[0-9A-F]+##?[0-9A-F]*$' "$fw_out" | sed 's/##[0-9A-F]/##/' > "$tmp.fw"
awk -v gwfile="$tmp.gw" -v want_ids="$want_ids" -v hb="$hb" -v name="$name" -v want_boots="$want_boots" \
  -v want_sdo="$want_sdo" -v sdo_id="$(printf '%03X' $((0x580 + 0x$hb - 0x700)))" -v emcy="$emcy" '
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
        if (part[1] == "185" && substr(data, 15, 2) == "00") invalid++   # byte 7, the validity bit of TPDO1
        if (part[1] == "200" && substr(data, 15, 1) ~ /[0-7]/) invalid++  # rtde-types: bit 63, rtde_registers valid
        if (part[1] == "201" && substr(data, 7, 1) ~ /[89A-F]/) bit31++    # robot_status_bits bit 31
        if (part[1] == "201" && substr(data, 9, 4) == "FFFF") safety_hi++  # safety_status_bits 16-31
        if (part[1] == "201" && substr(data, 13, 4) == "FFFF") uint64_hi++ # bits 48-63 of a UINT64
    }
    if (want_ids != "-")
        check(length(ids) == want_ids, "frames of " length(ids) " ids, not the " want_ids " of the configuration")
    if (emcy != "-" && want_boots == "") {
        # A CANopen node: boot-up [00], then heartbeats [05] (operational); the EMCY of stale data
        # (0xFF02) during the stall and its reset (0x0000) after it.
        check(gw[1] == hb "#00", "the first frame is not the boot-up " hb "#00")
        check(state["5"] > 0, "no heartbeat said operational")
        for (i = 1; i <= n; i++) {
            if (gw[i] ~ ("^" emcy "#02FF")) stale_emcy++
            if (gw[i] ~ ("^" emcy "#0000..02FF")) reset_emcy++
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
    if (name == "canopen" || name == "rtde-plc")
        check(invalid > 0, "no 0x185 frame went out invalid (stall, clamp, NaN)")
    if (name == "canopen")
        check(ids["385"] < ids["185"] / 2 - 5, "0x385 (stop policy, 20 ms) did not stop during the stall")
    if (name == "rtde-types") {
        check(invalid > 0, "no 0x200 frame went out invalid (stall, NaN register)")
        check(bit31 > 0, "no 0x201 frame carried bit 31 of robot_status_bits")
        check(safety_hi > 0, "no 0x201 frame carried bits 16-31 of safety_status_bits set")
        check(uint64_hi > 0, "no 0x201 frame carried bits 48-63 of a UINT64 mask set")
    }
    printf "%s: frames compared: %d; per id:", name, n
    for (id in ids) printf " %s %d", id, ids[id]
    if (emcy != "-" && want_boots == "")
        printf "; heartbeat operational %d, EMCY stale %d, reset %d; 0x185 invalid %d\n", state["5"], stale_emcy,
            reset_emcy, invalid
    else if (name == "rtde-types")
        printf "; heartbeat ok %d, stale %d; 0x200 invalid %d; 0x201 with bit 31 %d, safety bits 16-31 %d, " \
            "UINT64 bits 48-63 %d\n", state["1"], state["2"], invalid, bit31, safety_hi, uint64_hi
    else if (want_boots != "")
        printf "; boot-ups %d, SDO answers %d\n", boots, ids[sdo_id]
    else
        printf "; heartbeat ok %d, stale %d\n", state["1"], state["2"]
    printf "%d passed, %d failed\n", passed, failed
    exit failed > 0
}' "$tmp.fw"
