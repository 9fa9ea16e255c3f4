#!/bin/sh
# SPDX-License-Identifier: MIT
# check-fw-gateway's check of the RTDE image's figures in docs/footprint.md
# (the block between "fw-footprint:begin" and "fw-footprint:end": the whole
# image, then its generated tables) against arm-none-eabi-size of the image
# just built: flash (text) within 10 %, as check-cross holds lib/'s rows, RAM
# (data + bss) exactly. One line per row; exit status 1 on a difference.
#   footprint.sh DOC IMAGE.elf TABLES.o
set -u
doc=$1; elf=$2; tables=$3
measured=$(arm-none-eabi-size "$elf" "$tables" | awk 'NR > 1 { print $1, $2 + $3 }')
sed -n '/<!-- fw-footprint:begin/,/<!-- fw-footprint:end/p' "$doc" | awk -F'|' -v measured="$measured" -v doc="$doc" '
BEGIN { n = split(measured, m, "\n") }
$3 ~ /^ *[0-9,]+ *$/ {
    row++; text = $3; ram = $4; gsub(/[ ,]/, "", text); gsub(/[ ,]/, "", ram); what = $2; gsub(/^ +| +$/, "", what)
    split(m[row], got, " ")
    if (row > n) { print "FAIL: " doc ": row \"" what "\": nothing measured for it"; bad++; next }
    ok = got[1] <= text * 1.1 && got[1] >= text * 0.9 && got[2] == ram
    print (ok ? "ok: " : "FAIL: ") doc ": " what ": flash " got[1] " (written " text "), RAM " got[2] " (written " ram ")"
    bad += !ok
}
END {
    if (row != n) { print "FAIL: " doc ": " row + 0 " rows of the RTDE image, not " n; bad++ }
    exit bad > 0
}'
