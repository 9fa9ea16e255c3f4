#!/bin/bash
# SPDX-License-Identifier: MIT
# run.sh: runs a shell script inside a throw-away qemu VM that has a real
# Linux kernel with SocketCAN (Debian's linux-image-amd64, cached by
# fetch-kernel.sh), virtual CAN interfaces up, and the given files.
# See docs/vm.md for the whole story.
set -eu

usage() {
  cat <<'EOF'
Usage: tests/vm/run.sh [OPTIONS] --script FILE

Boots Debian's kernel under qemu (TCG) with busybox, can-utils (candump,
cansend, canplayer, cangen, canbusload, cangw), iproute2 (ip, tc) and FILES in
an initramfs, loads the CAN modules, creates the vcan interfaces, runs FILE
with /bin/sh inside, and copies the results out.

Options:
  --script FILE      the script to run in the VM (required)
  --files 'F ...'    files or directories to put in the VM's /t (by base
                     name; repeatable). Executables bring their shared
                     libraries along.
  --env NAME=VALUE   exported to the script (repeatable)
  --vcan 'SPEC ...'  interfaces to create, SPEC = NAME:MTU (72: CAN FD,
                     16: classic). Default: 'vcan0:72 vcan1:16'
  --modules 'M ...'  more kernel modules to load (dependencies follow),
                     e.g. 'sch_plug sch_tbf can-gw'
  --timeout SEC      the script's time limit inside the VM (default 60)
  --out DIR          where the results go (default: a new directory under
                     ${TMPDIR:-/tmp}); it is emptied first
  --mem MB           guest memory (default 512)
  -v, --verbose      show the VM console while it runs
  -q, --quiet        do not print the script's output afterwards
  -h, --help

Inside the VM the script runs as root in /t with PATH=/t:/usr/local/bin:...,
OUT=/out (everything written there is copied to DIR/out), VM_VCAN (the
specs), and the --env variables. Results on the host:
  DIR/script.log   the script's stdout and stderr
  DIR/rc           its exit status
  DIR/out/         what it wrote to $OUT
  DIR/console.log  the whole serial console (kernel messages included)

Exit status: the script's, 124 when it (or the VM) timed out, 125 when the
VM could not be prepared or gave no result (the reason is printed).

Examples:
  tests/vm/run.sh --script tests/port/can-link.sh --modules sch_plug \
      --files 'build/tests/port/can_link_test tests/lib.sh tests/vm/counts.sh'
  tests/vm/run.sh -v --script my.sh --files 'build/bin/urrt-sim build/bin/urrt-gateway gw.ini' \
      --vcan 'vcan0:16' --out /tmp/e2e
EOF
}

die() { echo "vm: $*" >&2; exit 125; }

here=$(cd "$(dirname "$0")" && pwd)
script='' files=() envs=() vcan='vcan0:72 vcan1:16' extra_modules='' timeout_s=60 out='' mem=512
verbose=0 quiet=0
while [ $# -gt 0 ]; do
  case $1 in
    --script) script=$2; shift 2 ;;
    --files) read -r -a more <<<"$2"; files+=("${more[@]}"); shift 2 ;;
    --env) case $2 in [A-Za-z_]*=*) envs+=("$2") ;; *) die "--env wants NAME=VALUE, not '$2'" ;; esac; shift 2 ;;
    --vcan) vcan=$2; shift 2 ;;
    --modules) extra_modules="$extra_modules $2"; shift 2 ;;
    --timeout) timeout_s=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --mem) mem=$2; shift 2 ;;
    -v|--verbose) verbose=1; shift ;;
    -q|--quiet) quiet=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "vm: unknown argument '$1'" >&2; usage >&2; exit 125 ;;
  esac
done
[ -n "$script" ] || { usage >&2; exit 125; }
[ -f "$script" ] || die "no script $script"
case $timeout_s in ''|*[!0-9]*) die "--timeout wants seconds, not '$timeout_s'" ;; esac
for spec in $vcan; do
  case $spec in [a-z]*:16|[a-z]*:72) ;; *) die "--vcan wants NAME:16 or NAME:72, not '$spec'" ;; esac
done

need() { command -v "$1" >/dev/null 2>&1 || die "$1 is missing: apt-get install $2"; }
export PATH=$PATH:/usr/sbin:/sbin
need qemu-system-x86_64 qemu-system-x86
need cpio cpio
need candump can-utils
need tc iproute2
[ -x /bin/busybox ] || die "/bin/busybox is missing: apt-get install busybox-static"
ldd /bin/busybox >/dev/null 2>&1 && die "/bin/busybox is not static: apt-get install busybox-static"

if [ -z "$out" ]; then
  out=$(mktemp -d "${TMPDIR:-/tmp}/urrt-vm.XXXXXX")
else
  rm -rf "$out"; mkdir -p "$out"
fi
out=$(cd "$out" && pwd)

kernel=$("$here/fetch-kernel.sh") || die "no kernel (see above)"
stage=$out/.initramfs
mkdir -p "$stage"/{bin,sbin,usr/bin,usr/sbin,usr/local/bin,lib/modules,t,proc,sys,dev,tmp,run,out,vmres,etc}

# ---- programs and their libraries ------------------------------------------------
is_elf() { [ "$(head -c 4 "$1" 2>/dev/null | od -An -c | tr -d ' ')" = '177ELF' ]; }

copy_libs() {  # the shared libraries (and loader) of an ELF file
  ldd "$1" 2>/dev/null | while read -r a b c _; do
    lib=''
    case $a in /*) lib=$a ;; esac
    [ "$b" = '=>' ] && case $c in /*) lib=$c ;; esac
    if [ -n "$lib" ] && [ ! -e "$stage$lib" ]; then
      mkdir -p "$stage$(dirname "$lib")"
      cp -L "$lib" "$stage$lib"
    fi
  done
}

add_file() {  # SRC DESTDIR
  local src=$1 dst=$2
  [ -e "$src" ] || die "no such file: $src"
  cp -rL "$src" "$dst/" || die "cannot copy $src"
  local f
  while IFS= read -r f; do
    if is_elf "$f"; then copy_libs "$f"; fi
  done < <(find "$dst/$(basename "$src")" -type f)
}

cp /bin/busybox "$stage/bin/busybox"
for tool in candump cansend canplayer cangen canbusload cangw ip tc; do
  add_file "$(command -v $tool)" "$stage/usr/local/bin"
done
for f in "${files[@]}"; do add_file "$f" "$stage/t"; done
# Debian's busybox shell runs its own applet for a name like ip or tc before
# searching PATH: functions make the real programs win.
{
  echo "# run.sh: the real programs rather than busybox applets of the same name"
  for f in "$stage"/usr/local/bin/* "$stage"/t/*; do
    name=$(basename "$f")
    [ -f "$f" ] && [ -x "$f" ] && /bin/busybox --list | grep -qx -- "$name" &&
      echo "$name() { ${f#"$stage"} \"\$@\"; }"
  done
  cat "$script"
} > "$stage/t/.vm-script"

# ---- modules, in load order ------------------------------------------------------
moddir=$kernel/modules
loaded=''
find_module() {  # NAME -> path of NAME.ko[.xz|.zst|.gz], '-' and '_' alike
  local n1=${1//_/-} n2=${1//-/_}
  find "$moddir/kernel" \( -name "$n1.ko*" -o -name "$n2.ko*" \) -print -quit
}
decompress() {
  case $1 in
    *.ko) cat "$1" ;;
    *.ko.xz) xz -dc "$1" ;;
    *.ko.zst) zstd -dcq "$1" ;;
    *.ko.gz) gzip -dc "$1" ;;
    *) return 1 ;;
  esac
}
add_module() {  # NAME: its dependencies first, then itself
  local name=${1//-/_} path dep
  case " $loaded " in *" $name "*) return ;; esac
  path=$(find_module "$1")
  if [ -z "$path" ]; then
    grep -Eq "/${1//[-_]/[-_]}\.ko" "$moddir/modules.builtin" 2>/dev/null && return
    die "kernel module $1 is not in $moddir (not extracted by fetch-kernel.sh?)"
  fi
  decompress "$path" > "$stage/lib/modules/$name.ko" || die "cannot decompress $path"
  for dep in $(tr '\0' '\n' < "$stage/lib/modules/$name.ko" | sed -n 's/^depends=//p' | head -n 1 | tr ',' ' '); do
    add_module "$dep"
  done
  loaded="$loaded $name"
}
for m in virtio_pci virtio_blk can can_raw can_dev vcan $extra_modules; do add_module "$m"; done

# ---- configuration and init --------------------------------------------------------
q() { printf "'%s'" "$(printf '%s' "$1" | sed "s/'/'\\\\''/g")"; }
{
  echo "VM_MODULES=$(q "${loaded# }")"
  echo "VM_VCAN=$(q "$vcan")"
  echo "VM_TIMEOUT=$timeout_s"
} > "$stage/etc/vm.conf"
{
  echo "export OUT=/out VM_VCAN=$(q "$vcan")"
  for e in "${envs[@]}"; do echo "export ${e%%=*}=$(q "${e#*=}")"; done
} > "$stage/etc/vm.env"
cp "$here/init" "$stage/init"
chmod 0755 "$stage/init" "$stage/bin/busybox"

(cd "$stage" && find . -print | cpio -o -H newc --quiet) > "$out/initramfs.cpio" || die "cpio failed"
rm -rf "$stage"

# ---- boot -------------------------------------------------------------------------
# The result disk: the VM writes a tar of its results onto it, raw.
disk=$out/result.img
rm -f "$disk"; truncate -s 256M "$disk"
accel=${URRT_VM_ACCEL:-tcg}
image=$kernel/vmlinuz
[ -f "$kernel/vmlinux" ] && image=$kernel/vmlinux
# Boot plus module loading take seconds under TCG; the margin absorbs a busy host.
outer=$((timeout_s + 60))
# The VM is the tests' machine, not the code under test: on a host kept busy
# (check-stress spins a core) an emulated CPU at the same priority stalls
# for hundreds of milliseconds, and the simulator inside with it. As root it
# gets a higher share of the host (nice -10), so the tests judge the code.
prio=()
[ "$(id -u)" = 0 ] && prio=(nice -n -10)
qemu=(timeout -k 5 "$outer" "${prio[@]}" qemu-system-x86_64 -accel "$accel" -m "$mem" -smp 1 -nodefaults
      -no-user-config -display none -serial stdio -no-reboot
      -kernel "$image" -initrd "$out/initramfs.cpio" -append 'console=ttyS0 panic=-1 quiet'
      -drive "file=$disk,format=raw,if=virtio")
start=$(date +%s.%N)
set +e
if [ "$verbose" = 1 ]; then
  "${qemu[@]}" </dev/null 2>&1 | tee "$out/console.log"
  qrc=${PIPESTATUS[0]}
else
  "${qemu[@]}" </dev/null >"$out/console.log" 2>&1
  qrc=$?
fi
set -e
end=$(date +%s.%N)
rm -f "$out/initramfs.cpio"
echo "vm: $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }') s in qemu ($accel), results in $out" >&2

no_result() {
  echo "vm: $1; the console's last lines ($out/console.log):" >&2
  tail -n 30 "$out/console.log" | sed 's/^/  | /' >&2
  rm -f "$disk"
  exit "$2"
}
[ "$qrc" = 124 ] || [ "$qrc" = 137 ] && no_result "the VM did not finish within $outer s" 124
tar -x -f "$disk" -C "$out" 2>/dev/null || no_result "the VM left no results (qemu exit status $qrc)" 125
rm -f "$disk"
[ -f "$out/rc" ] || no_result "the VM left no exit status (qemu exit status $qrc)" 125
rc=$(cat "$out/rc")
[ "$quiet" = 1 ] || [ "$verbose" = 1 ] || cat "$out/script.log"
if [ "$rc" = 124 ]; then
  echo "vm: the script did not finish within $timeout_s s (--timeout)" >&2
fi
exit "$rc"
