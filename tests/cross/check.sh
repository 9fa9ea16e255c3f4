#!/bin/sh
# SPDX-License-Identifier: MIT
# Proof that lib/ is freestanding: every lib/*.c compiled alone for a
# Cortex-M4 under the library's strict warnings, linked with -nostdlib into a
# small image (tests/cross/startup.c), and the footprint compared with the
# figures docs/footprint.md states; then for every core of that page's symbol
# table at -Os and -O2, what lib/ needs from outside (libgcc only).
#
# usage: check.sh OUTDIR FOOTPRINT_MD "LIB_WARN flags" lib/a.c lib/b.c ...
# Needs arm-none-eabi-gcc, -nm and -size, and riscv64-unknown-elf-gcc.
set -u
out=$1; doc=$2; warn=$3; shift 3
. "$(dirname "$0")/../lib.sh"

CROSS=arm-none-eabi-
ARCH="-mcpu=cortex-m4 -mthumb"
# -nostdinc with only the compiler's own include directory: lib/ may use the
# headers a freestanding compiler provides (stddef.h, stdint.h, stdbool.h,
# float.h, limits.h, ...) and no C library header.
CFLAGS="$ARCH -ffreestanding -Os $warn -ffunction-sections -fdata-sections -fstack-usage -Ilib"
CFLAGS="$CFLAGS -nostdinc -isystem $(${CROSS}gcc -print-file-name=include)"
LDFLAGS="$ARCH -nostdlib -Wl,--gc-sections -T tests/cross/link.ld"
# Percentage by which a measured text size may differ from the stated one.
TOLERANCE=10

mkdir -p "$out"
rm -f "$out"/*.o "$out"/*.elf "$out"/*.su

if ! command -v ${CROSS}gcc >/dev/null; then
  fail "arm-none-eabi-gcc not found: install gcc-arm-none-eabi (make deps)"
  finish; exit 1
fi
echo "cross: $(${CROSS}gcc --version | head -n 1)"

objs=""
for src in "$@"; do
  obj="$out/$(basename "$src" .c).o"
  if ${CROSS}gcc $CFLAGS -c "$src" -o "$obj"; then
    ok "$src compiles alone for Cortex-M4 (-ffreestanding -nostdinc -Os, strict warnings)"
    objs="$objs $obj"
  else
    fail "$src does not compile for Cortex-M4 under the library's warnings, or includes a C library header"
  fi
done
# The decoder's NEON path (ARMv7-A with NEON, as on an i.MX or Raspberry Pi
# class edge box) is lib/vector/urrt_vector.c, the host build's lib/urrt.c
# with the vector paths (lib/lib.mk); it and every lib/*.c under the same
# warnings for that core: compiled only, nothing here runs it.
vector_src=lib/vector/urrt_vector.c
for src in "$@" "$vector_src"; do
  check "$src compiles for Cortex-A7 with NEON" \
    ${CROSS}gcc -mcpu=cortex-a7 -mfpu=neon-vfpv4 -mfloat-abi=hard -ffreestanding -O2 $warn -Ilib \
      -c "$src" -o "$out/$(basename "$src" .c).neon.o"
done
# Big-endian NEON (armeb, aarch64_be): the wire's byte order is the host's,
# so the decoder must not take the byte-swapping vector path there.
# Regression: it did, and every double of the grid came out byte-reversed.
# Nothing here runs big-endian code, so the check is on the choice of path.
be_macros="$out/urrt.be.macros"
if ${CROSS}gcc -mbig-endian -mcpu=cortex-a7 -mfpu=neon-vfpv4 -mfloat-abi=hard -ffreestanding -O2 $warn -Ilib \
     -c "$vector_src" -o "$out/urrt.be.o" &&
   ${CROSS}gcc -mbig-endian -mcpu=cortex-a7 -mfpu=neon-vfpv4 -mfloat-abi=hard -ffreestanding -O2 -Ilib \
     -E -dM "$vector_src" > "$be_macros"; then
  if grep -q '^#define URRT_VECTOR ' "$be_macros"; then
    fail "$vector_src byte-swaps doubles with NEON on a big-endian target (regression_big_endian_neon)"
  else
    ok "$vector_src compiles for big-endian NEON without the byte-swapping vector path"
  fi
else
  fail "$vector_src does not compile for big-endian Cortex-A7 with NEON"
fi
# URRT_MAX_DOUBLES is a documented knob: the library must build at the
# smallest allowed value and a large one, and refuse values its structs cannot
# count (regression: a value past 65535 used to wrap urrt_state.doubles).
for max in 152 4096; do
  check "lib/urrt.c builds with -DURRT_MAX_DOUBLES=$max" \
    ${CROSS}gcc $CFLAGS -DURRT_MAX_DOUBLES=$max -c lib/urrt.c -o "$out/max$max.o"
done
for max in 151 65536; do
  if ${CROSS}gcc $CFLAGS -DURRT_MAX_DOUBLES=$max -c lib/urrt.c -o "$out/max$max.o" 2>/dev/null; then
    fail "lib/urrt.c accepts -DURRT_MAX_DOUBLES=$max; it must refuse it at compile time"
  else
    ok "lib/urrt.c refuses -DURRT_MAX_DOUBLES=$max at compile time"
  fi
done
check "startup compiles" ${CROSS}gcc $CFLAGS -c tests/cross/startup.c -o "$out/startup.o"
check "size probe compiles" ${CROSS}gcc $CFLAGS -c tests/cross/probe.c -o "$out/probe.o"

# What lib/ needs from outside, on every core a firmware may build it for, at
# -Os and -O2 (GCC may emit memcpy/memset calls for loops at -O2, or call
# memcpy for a __builtin_memcpy it cannot inline): every symbol an object
# leaves undefined that no lib/ object defines. Each must come from that
# core's libgcc (checked against libgcc.a itself) and the symbol table of
# docs/footprint.md must list exactly these symbols and cores.
#   name|compiler|flags
CORES="m0+|arm-none-eabi-gcc|-mcpu=cortex-m0plus -mthumb
m4|arm-none-eabi-gcc|-mcpu=cortex-m4 -mthumb
m4-na|arm-none-eabi-gcc|-mcpu=cortex-m4 -mthumb -mno-unaligned-access
m7-hf|arm-none-eabi-gcc|-mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard
rv32|riscv64-unknown-elf-gcc|-march=rv32imac -mabi=ilp32"
pairs="$out/needed-pairs"
: > "$pairs"
core_ok=yes
while IFS='|' read -r core cc flags; do
  if ! command -v "$cc" >/dev/null; then
    fail "$cc not found: make deps installs it"; core_ok=no; continue
  fi
  dir="$out/core-$core"
  mkdir -p "$dir"
  cflags="$flags -ffreestanding $warn -ffunction-sections -fdata-sections -Ilib -nostdinc -isystem $($cc $flags -print-file-name=include)"
  libgcc=$($cc $flags -print-libgcc-file-name)
  nm=${cc%gcc}nm
  $nm -g --defined-only "$libgcc" 2>/dev/null | awk 'NF == 3 { print $3 }' | sort -u > "$dir/libgcc.syms"
  $cc $cflags -Os -c tests/cross/startup.c -o "$dir/startup.o" || fail "startup.c does not compile for $core"
  for opt in -Os -O2; do
    cobjs=""
    for src in "$@"; do
      o="$dir/$(basename "$src" .c)$opt.o"
      if $cc $cflags $opt -c "$src" -o "$o"; then cobjs="$cobjs $o"; else
        fail "$src does not compile for $core at $opt"; core_ok=no; fi
    done
    [ -n "$cobjs" ] || continue
    $nm -g --defined-only $cobjs | awk 'NF == 3 { print $3 }' | sort -u > "$dir/defined$opt"
    $nm -u $cobjs | awk 'NF == 2 && $1 == "U" { print $2 }' | sort -u | comm -23 - "$dir/defined$opt" > "$dir/needed$opt"
    sed "s/\$/ $core/" "$dir/needed$opt" >> "$pairs"
    for sym in $(comm -23 "$dir/needed$opt" "$dir/libgcc.syms"); do
      fail "lib/ needs $sym on $core at $opt, which $libgcc does not define (a C library symbol?)"
    done
    # A real image: libgcc gives what is needed, nothing else links in.
    check "$core $opt: every lib/ function links with -nostdlib -lgcc" \
      $cc $flags -nostdlib -Wl,--gc-sections -T tests/cross/link.ld "$dir/startup.o" $cobjs \
        $(sed 's/^/-Wl,-u,/' "$dir/defined$opt") -lgcc -o "$dir/image$opt.elf"
  done
done <<EOF_CORES
$CORES
EOF_CORES
needed=$(sort -u "$pairs" | awk '{ c[$1] = c[$1] ? c[$1] " " $2 : $2 } END { for (s in c) print s ": " c[s] }' | sort)
listed=$(sed -n '/<!-- cross-symbols:begin/,/<!-- cross-symbols:end/p' "$doc" |
         sed -n 's/^| *`\([A-Za-z_][A-Za-z0-9_]*\)` *| *[^|]*| *\([^|]*[^ |]\) *|.*/\1: \2/p' | sort)
echo "cross: symbols lib/ needs from the toolchain, and on which cores:"
echo "$needed" | sed 's/^/cross:   /'
if [ "$core_ok" = yes ]; then
  if [ "$needed" = "$listed" ]; then
    ok "$doc's cross-symbols table lists exactly these symbols and cores"
  else
    fail "$doc's cross-symbols table differs from what lib/ needs (symbol: cores, measured above): update it"
    echo "$listed" > "$out/listed-pairs"
    echo "$needed" > "$out/needed-sorted"
    diff "$out/listed-pairs" "$out/needed-sorted" | sed "s|^|cross:   $doc vs measured: |"
  fi
fi

# URRT_MAX_DOUBLES changes the framer's size, so urrt.h puts it into the
# framer's link names: a file built with another value than lib/urrt.c must
# fail to link, naming the macro (regression: it linked and corrupted memory).
printf '#include "urrt.h"\nint mix_feed(urrt_framer *f, const uint8_t *p, size_t n, size_t *u)\n{ return urrt_framer_feed(f, p, n, u); }\n' > "$out/mix.c"
mixed="$out/mix-link.txt"
if ${CROSS}gcc $CFLAGS -DURRT_MAX_DOUBLES=152 -c "$out/mix.c" -o "$out/mix152.o" &&
   ! ${CROSS}gcc $LDFLAGS "$out/startup.o" "$out/mix152.o" $objs -Wl,-u,mix_feed -o "$out/mix.elf" > "$mixed" 2>&1 &&
   grep -q "undefined reference to .urrt_framer_feed_URRT_MAX_DOUBLES_152" "$mixed"; then
  ok "two files with different URRT_MAX_DOUBLES fail to link: $(grep -o 'undefined reference to .urrt_framer_feed[^ ]*' "$mixed" | head -n 1)"
else
  fail "a file built with -DURRT_MAX_DOUBLES=152 linked against lib/ built with 256 (or failed for another reason): $(cat "$mixed")"
fi
check "a file with lib/'s URRT_MAX_DOUBLES links" sh -c "${CROSS}gcc $CFLAGS -c $out/mix.c -o $out/mix256.o &&
  ${CROSS}gcc $LDFLAGS $out/startup.o $out/mix256.o $objs -Wl,-u,mix_feed -o $out/mix.elf"

# The M4 images the footprint table measures.
check "image (framer + decode + random access) links with -nostdlib" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs -o "$out/image-min.elf"
roots=$(${CROSS}nm -g --defined-only $objs | awk 'NF == 3 && $2 ~ /[TDRB]/ { printf " -Wl,-u,%s", $3 }')
check "image (every lib/ function) links with -nostdlib -lgcc" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs $roots -lgcc -o "$out/image-all.elf"
# The CANopen node as a firmware links it: every function of lib/urrt_co.h
# that urrt_co.o defines but the dictionary's readers (urrt_co_comm_*: the
# table of every row, its names, limits, instances and reads), which only an
# EDS writer calls; and with them. The SDO server reads rows of its own, so
# the table and the names are arrays that --gc-sections must drop without
# them. Functions lib/urrt_co_internal.h declares (the seam to urrt_co_rx.c)
# are no roots: a firmware links them only where something calls them.
sed -n 's/^[a-z].*[ *]\(urrt_co_[a-z0-9_]*\)(.*/\1/p' lib/urrt_co.h | sort -u > "$out/co-api"
${CROSS}nm -g --defined-only "$out/urrt_co.o" | awk 'NF == 3 && $2 ~ /[TDR]/ { print $3 }' | sort -u > "$out/co-defined"
co_roots=$(comm -12 "$out/co-api" "$out/co-defined" | awk '!/^urrt_co_comm_/ { printf " -Wl,-u,%s", $1 }')
eds_roots=$(awk '/^urrt_co_comm_/ { printf " -Wl,-u,%s", $1 }' "$out/co-defined")
if [ -z "$co_roots" ] || ! echo "$co_roots" | grep -q 'urrt_co_on_frame' || ! echo "$eds_roots" | grep -q 'urrt_co_comm_table'; then
  fail "the CANopen node's roots are not what lib/urrt_co.h declares (roots:$co_roots; readers:$eds_roots)"
fi
check "image (the CANopen node, no EDS writer) links with -nostdlib -lgcc" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs $co_roots -lgcc -o "$out/image-co.elf"
check "image (the CANopen node and the dictionary's readers) links with -nostdlib -lgcc" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs $co_roots $eds_roots -lgcc -o "$out/image-co-eds.elf"
# With the receiving side (RPDOs, 0x1016): every urrt_co_ function of both
# files (urrt_co_init_rx in place of urrt_co_init, which such a firmware does
# not call). urrt_co.c reaches lib/urrt_co_rx.c only through the table
# urrt_co_init_rx installs, so the node without it (image-co, a TPDO-only
# node) holds no symbol of urrt_co_rx.o: not one of its functions, nor the
# table, nor its rows of the communication objects (symbols urrt_co.o
# defines too, static inline copies, aside); nor its error texts.
rx_roots=$(${CROSS}nm -g --defined-only "$out/urrt_co_rx.o" | awk 'NF == 3 && $2 ~ /[TDR]/ { printf " -Wl,-u,%s", $3 }')
rx_co_roots=$(echo "$co_roots " | sed 's/ -Wl,-u,urrt_co_init / /')
check "image (the CANopen node with RPDOs and 0x1016, no EDS writer) links with -nostdlib -lgcc" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs $rx_co_roots $rx_roots -lgcc -o "$out/image-co-rx.elf"
if [ -f "$out/image-co.elf" ] && [ -f "$out/image-co-rx.elf" ]; then
  ${CROSS}nm --defined-only "$out/urrt_co.o" | awk 'NF == 3 { print $3 }' | sort -u > "$out/co-syms"
  ${CROSS}nm --defined-only "$out/urrt_co_rx.o" | awk 'NF == 3 && $2 ~ /[TtDdRrBb]/ { print $3 }' | sort -u |
    comm -23 - "$out/co-syms" > "$out/co-rx-syms"
  leaked=$(${CROSS}nm "$out/image-co.elf" | awk 'NF == 3 { print $3 }' | sort -u | comm -12 - "$out/co-rx-syms")
  if [ ! -s "$out/co-rx-syms" ]; then
    fail "lib/urrt_co_rx.o defines no symbol of its own: the check below would prove nothing"
  elif [ -n "$leaked" ]; then
    fail "the CANopen node without urrt_co_init_rx links the receiving side: $(echo $leaked)"
  else
    ok "the CANopen node without urrt_co_init_rx links none of lib/urrt_co_rx.c's $(wc -l < "$out/co-rx-syms") symbols"
  fi
  check "the image with the receiving side links urrt_co_init_rx and urrt_co_rpdo_status" \
    sh -c "${CROSS}nm '$out/image-co-rx.elf' | grep -q ' urrt_co_init_rx\$' &&
      ${CROSS}nm '$out/image-co-rx.elf' | grep -q ' urrt_co_rpdo_status\$'"
  rx_text="consumer heartbeat (0x1016) entry" # URRT_CO_E_CONSUMER's text (urrt_co_rx_strerror)
  if grep -q "$rx_text" "$out/image-co.elf"; then
    fail "the CANopen node without urrt_co_init_rx holds the receiving side's error texts (\"$rx_text\")"
  else
    ok "the CANopen node without urrt_co_init_rx holds none of the receiving side's error texts"
  fi
  check "the image with the receiving side holds its error texts (\"$rx_text\")" grep -q "$rx_text" "$out/image-co-rx.elf"
fi
${CROSS}nm -g --defined-only "$out/urrt_co_rx.o" | awk 'NF == 3 { print $3 }' | sort -u > "$out/co-rx-globals"
rx_used=$(${CROSS}nm -u "$out/urrt_co.o" | awk '{ print $NF }' | sort -u | comm -12 - "$out/co-rx-globals")
if [ -n "$rx_used" ]; then
  fail "lib/urrt_co.o references the receiving side: $(echo $rx_used)"
else
  ok "lib/urrt_co.o references no symbol of lib/urrt_co_rx.c"
fi
co_name="Producer heartbeat time" # 0x1017's name
if [ -f "$out/image-co.elf" ] && [ -f "$out/image-co-eds.elf" ]; then
  if grep -q "$co_name" "$out/image-co.elf"; then
    fail "the CANopen node's image without the dictionary's readers holds the object names (\"$co_name\"): keep them out of the SDO server's rows"
  else
    ok "the CANopen node's image without the dictionary's readers holds no object names"
  fi
  if ${CROSS}nm "$out/image-co.elf" | grep -q ' urrt_co_comm_table$'; then
    fail "the CANopen node's image without the dictionary's readers holds urrt_co_comm_table: the SDO server must read rows of its own"
  else
    ok "the CANopen node's image without the dictionary's readers holds no urrt_co_comm_table"
  fi
  check "the image with the dictionary's readers holds the object names (\"$co_name\")" grep -q "$co_name" "$out/image-co-eds.elf"
fi

# The RTDE client as a read-only firmware links it (a session: begin, the
# recipe, requests, feed, close), and with its writing side (every
# urrt_rtde_in_ function) as well. "This firmware cannot write" is a property
# of the link map: the read-only image holds no urrt_rtde_in_ symbol, nor the
# three functions urrt_rtde.c has for the writing side alone, and
# lib/urrt_rtde.o itself references no urrt_rtde_in_ symbol.
rtde_roots=""
for f in urrt_rtde_init urrt_rtde_begin urrt_rtde_set_recipe urrt_rtde_output urrt_rtde_feed urrt_rtde_finish \
         urrt_rtde_var_find urrt_rtde_up; do
  rtde_roots="$rtde_roots -Wl,-u,$f"
done
in_roots=$(${CROSS}nm -g --defined-only "$out/urrt_rtde_in.o" | awk 'NF == 3 && $2 ~ /[TDR]/ { printf " -Wl,-u,%s", $3 }')
check "image (the RTDE client, read-only) links with -nostdlib -lgcc" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs $rtde_roots -lgcc -o "$out/image-rtde.elf"
check "image (the RTDE client and its writing side) links with -nostdlib -lgcc" \
  ${CROSS}gcc $LDFLAGS "$out/startup.o" $objs $rtde_roots $in_roots -lgcc -o "$out/image-rtde-in.elf"
if [ -f "$out/image-rtde.elf" ] && [ -f "$out/image-rtde-in.elf" ]; then
  writer=$(${CROSS}nm "$out/image-rtde.elf" | awk '$3 ~ /^urrt_rtde_in_|^urrt_rtde_(due|streaming|end)$/ { print $3 }')
  if [ -n "$writer" ]; then
    fail "the read-only RTDE image links the writing side: $(echo $writer)"
  else
    ok "the read-only RTDE image links no urrt_rtde_in_ function, nor urrt_rtde_due, _streaming, _end"
  fi
  check "the RTDE image with its writing side links urrt_rtde_in_package and urrt_rtde_in_feed" \
    sh -c "${CROSS}nm '$out/image-rtde-in.elf' | grep -q ' urrt_rtde_in_package\$' &&
      ${CROSS}nm '$out/image-rtde-in.elf' | grep -q ' urrt_rtde_in_feed\$'"
fi
if ${CROSS}nm "$out/urrt_rtde.o" | grep -q 'urrt_rtde_in_'; then
  fail "lib/urrt_rtde.o references the writing side: $(${CROSS}nm "$out/urrt_rtde.o" | grep 'urrt_rtde_in_' | head -n 3)"
else
  ok "lib/urrt_rtde.o references no urrt_rtde_in_ symbol"
fi

# Footprint.
row() { # name text data bss
  printf '| %s | %s | %s | %s |\n' "$1" "$2" "$3" "$4"
}
measured="$out/footprint.md"
: > "$measured"
for obj in $objs; do
  set -- $(${CROSS}size "$obj" | awk 'NR == 2 { print $1, $2, $3 }')
  row "lib/$(basename "$obj" .o).c (every function)" "$1" "$2" "$3" >> "$measured"
  [ "$2" = 0 ] && [ "$3" = 0 ] && ok "$(basename "$obj" .o).c has no globals (data and bss are 0)" ||
    fail "$(basename "$obj" .o).c has data $2 / bss $3: lib/ must keep no state of its own"
done
# Every core: each file's text at -Os (a core without unaligned access or
# with Thumb-1 only needs more instructions per double; RV32 has no 64-bit
# registers).
while IFS='|' read -r core cc flags; do
  [ "$core" = m4 ] && continue # the rows above
  for o in "$out/core-$core"/*-Os.o; do
    [ -f "$o" ] || continue
    set -- $(${cc%gcc}size "$o" | awk 'NR == 2 { print $1, $2, $3 }')
    row "lib/$(basename "$o" -Os.o).c on $core (-Os)" "$1" "$2" "$3" >> "$measured"
  done
done <<EOF_CORES
$CORES
EOF_CORES
for img in min co co-rx co-eds rtde rtde-in all; do
  [ -f "$out/image-$img.elf" ] || continue
  set -- $(${CROSS}size "$out/image-$img.elf" | awk 'NR == 2 { print $1, $2, $3 }')
  case $img in
    min) name="image: framer + decode + random access (tests/cross)" ;;
    co) name="image: the CANopen node, no EDS writer (tests/cross)" ;;
    co-rx) name="image: the CANopen node with RPDOs and 0x1016, no EDS writer (tests/cross)" ;;
    co-eds) name="image: the CANopen node and the dictionary's readers, urrt_co_comm_* (tests/cross)" ;;
    rtde) name="image: the RTDE client, read-only (tests/cross)" ;;
    rtde-in) name="image: the RTDE client and its writing side (tests/cross)" ;;
    all) name="image: every lib/ function (tests/cross)" ;;
  esac
  row "$name" "$1" "$2" "$3" >> "$measured"
done
symbol_size() {
  hex=$(${CROSS}nm -S "$out/probe.o" | awk -v s="$1" '$4 == s { print $2 }')
  [ -n "$hex" ] && echo $((0x$hex))
}
state=$(symbol_size urrt_probe_state)
framer=$(symbol_size urrt_probe_framer)
printf '| sizeof(urrt_state) | %s |\n| sizeof(urrt_framer) | %s |\n' "$state" "$framer" >> "$measured"
# The RTDE client's session and its RTDE-only values (lib/urrt_rtde.h).
printf '| sizeof(urrt_rtde) | %s |\n| sizeof(urrt_rtde_values) | %s |\n' \
  "$(symbol_size urrt_probe_rtde)" "$(symbol_size urrt_probe_rtde_values)" >> "$measured"
# One input recipe of the writing side (lib/urrt_rtde_in.h).
printf '| sizeof(urrt_rtde_in) | %s |\n' "$(symbol_size urrt_probe_rtde_in)" >> "$measured"
# The CANopen node, and what it needs per TPDO, RPDO and 0x1016 entry (lib/urrt_co.h).
printf '| sizeof(urrt_co) | %s |\n| sizeof(urrt_co_tpdo_state) | %s |\n' \
  "$(symbol_size urrt_probe_co)" "$(symbol_size urrt_probe_co_tpdo)" >> "$measured"
printf '| sizeof(urrt_co_rpdo_state) | %s |\n| sizeof(urrt_co_consumer) | %s |\n' \
  "$(symbol_size urrt_probe_co_rpdo)" "$(symbol_size urrt_probe_co_consumer)" >> "$measured"
# The receiving side's storage, kept beside the node (its run-time state is there).
printf '| sizeof(urrt_co_rx_storage) | %s |\n' "$(symbol_size urrt_probe_co_rx_storage)" >> "$measured"
rm -f "$out"/*.O2.su
echo "cross: largest stack frames of lib/ functions (-fstack-usage, bytes; lib/ has no recursion):"
for obj in $objs; do cat "${obj%.o}.su"; done | sort -t "$(printf '\t')" -k2 -n -r | head -n 5 | sed 's/^/cross:   /'
echo "cross: footprint (arm-none-eabi-size; bytes):"
sed 's/^/cross:   /' "$measured"

# docs/footprint.md must state the same figures: text within TOLERANCE %, the rest exact.
stated=$(sed -n '/<!-- footprint:begin/,/<!-- footprint:end/p' "$doc")
while IFS= read -r line; do
  name=$(echo "$line" | awk -F'|' '{ gsub(/^ +| +$/, "", $2); print $2 }')
  want=$(echo "$stated" | awk -F'|' -v n="$name" '{ k = $2; gsub(/^ +| +$/, "", k) } k == n { print; exit }')
  if [ -z "$want" ]; then
    fail "$doc footprint table has no row \"$name\": add it with the measured figures"
    continue
  fi
  m=$(echo "$line" | awk -F'|' '{ for (i = 3; i < NF; i++) { v = $i; gsub(/[ ,]/, "", v); printf "%s ", v } }')
  s=$(echo "$want" | awk -F'|' '{ for (i = 3; i < NF; i++) { v = $i; gsub(/[ ,]/, "", v); printf "%s ", v } }')
  if echo "$m|$s" | awk -F'|' -v tol="$TOLERANCE" '{
        n = split($1, m, " "); k = split($2, s, " ");
        if (n != k) exit 1;
        if (n == 1) exit (m[1] == s[1]) ? 0 : 1;      # sizeof rows: exact
        d = m[1] - s[1]; if (d < 0) d = -d;
        if (s[1] == 0 || d * 100 > tol * s[1]) exit 1; # text: within tolerance
        for (i = 2; i <= n; i++) if (m[i] != s[i]) exit 1;
        exit 0 }'; then
    ok "$doc states \"$name\" ($s; measured $m)"
  else
    fail "$doc says \"$name\" is $s, measured $m: update the footprint table"
  fi
done < "$measured"
finish
