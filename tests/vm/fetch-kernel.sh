#!/bin/bash
# SPDX-License-Identifier: MIT
# fetch-kernel.sh: makes sure Debian's current amd64 kernel (vmlinuz plus the
# module trees the VM tests load from) is in the cache, and prints its
# directory. Downloads once with apt-get (the package is extracted, never
# installed); later runs are cache hits that need no network.
#
#   tests/vm/fetch-kernel.sh            -> prints e.g. ~/.cache/urrt-vm/linux-image-6.1.0-56-amd64_6.1.192-2
#
# Environment: URRT_VM_CACHE (default ${XDG_CACHE_HOME:-$HOME/.cache}/urrt-vm),
# URRT_VM_KERNEL_PKG to pin a package (default: what linux-image-amd64 depends on).
set -eu

die() { echo "fetch-kernel: $*" >&2; exit 1; }

cache=${URRT_VM_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/urrt-vm}

# The metapackage names the current ABI package; apt-cache works offline.
# Lists that are missing or older than the mirror (a version it no longer
# has) are refreshed once, when root, before giving up.
resolve() {
  pkg=${URRT_VM_KERNEL_PKG:-}
  if [ -z "$pkg" ]; then
    pkg=$(apt-cache depends linux-image-amd64 2>/dev/null |
          sed -n 's/^ *Depends: \(linux-image-[0-9][^ ]*-amd64\)$/\1/p' | head -n 1)
  fi
  version=
  [ -n "$pkg" ] && version=$(apt-cache show --no-all-versions "$pkg" 2>/dev/null | sed -n 's/^Version: //p' | head -n 1)
  [ -n "$version" ]
}
refreshed=
refresh() {
  [ "$(id -u)" = 0 ] && [ -z "$refreshed" ] || return 1
  refreshed=yes
  echo "fetch-kernel: refreshing the Debian package lists (apt-get update)" >&2
  apt-get update -qq >/dev/null 2>&1
}
resolve || { refresh && resolve; } ||
  die "apt-cache does not know linux-image-amd64 or its version (no Debian package lists?): run 'apt-get update'"

dir=$cache/${pkg}_$version
if [ -f "$dir/.complete" ]; then
  echo "$dir"
  exit 0
fi

mkdir -p "$cache" || die "cannot create the cache directory $cache"
tmp=$(mktemp -d "$cache/.fetch.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
download() {
  echo "fetch-kernel: downloading $pkg $version into $cache (once)" >&2
  (cd "$tmp" && apt-get download "$pkg=$version" >"$tmp/apt.log" 2>&1)
}
if ! download && ! { refresh && resolve && download; }; then
  cat "$tmp/apt.log" >&2
  die "could not download $pkg $version (no network or no Debian mirror?); the VM tests need it once, then it is cached in $cache"
fi
dir=$cache/${pkg}_$version
deb=$(ls "$tmp"/*.deb 2>/dev/null | head -n 1)
[ -n "$deb" ] || die "apt-get download left no .deb in $tmp"

# Only what a CAN test VM can want: the kernel, the network stack (CAN,
# qdiscs), CAN drivers, virtio (the result disk), 9p and library modules.
# Debian 12 ships /lib/modules, later releases /usr/lib/modules: match both.
mkdir -p "$tmp/x"
dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$tmp/x" --wildcards \
  '*/boot/vmlinuz-*' '*/boot/config-*' \
  '*/modules/*/modules.builtin' '*/modules/*/modules.order' \
  '*/modules/*/kernel/net/*' '*/modules/*/kernel/drivers/net/can/*' \
  '*/modules/*/kernel/drivers/virtio/*' '*/modules/*/kernel/drivers/block/virtio_blk.ko*' \
  '*/modules/*/kernel/drivers/char/*' '*/modules/*/kernel/fs/9p/*' '*/modules/*/kernel/fs/netfs/*' \
  '*/modules/*/kernel/fs/fscache/*' '*/modules/*/kernel/lib/*' '*/modules/*/kernel/crypto/*' \
  || die "extracting $deb failed"

mkdir -p "$tmp/kernel"
vmlinuz=$(ls "$tmp"/x/boot/vmlinuz-* 2>/dev/null | head -n 1)
[ -n "$vmlinuz" ] || die "$deb has no /boot/vmlinuz-*"
mv "$vmlinuz" "$tmp/kernel/vmlinuz"
mv "$tmp"/x/boot/config-* "$tmp/kernel/config" 2>/dev/null || true
moddir=$(ls -d "$tmp"/x/lib/modules/* "$tmp"/x/usr/lib/modules/* 2>/dev/null | head -n 1)
[ -n "$moddir" ] || die "$deb has no modules directory"
mv "$moddir" "$tmp/kernel/modules"
# A PVH kernel boots from its uncompressed ELF image and skips the in-guest
# decompression, which takes seconds under TCG. Optional: vmlinuz works too.
if grep -q '^CONFIG_PVH=y' "$tmp/kernel/config" 2>/dev/null; then
  for magic in '\xfd7zXZ\x00:xz -dc' '\x28\xb5\x2f\xfd:zstd -dcq'; do
    off=$(LC_ALL=C grep -obUaP "${magic%%:*}" "$tmp/kernel/vmlinuz" 2>/dev/null | head -n 1 | cut -d: -f1)
    [ -n "$off" ] || continue
    # Trailing bytes after the payload make the decompressor complain; the ELF check decides.
    tail -c +$((off + 1)) "$tmp/kernel/vmlinuz" | ${magic#*:} > "$tmp/kernel/vmlinux" 2>/dev/null || true
    if [ "$(head -c 4 "$tmp/kernel/vmlinux" | od -An -c | tr -d ' ')" = '177ELF' ]; then break; fi
    rm -f "$tmp/kernel/vmlinux"
  done
fi
echo "$pkg $version" > "$tmp/kernel/release"
basename "$moddir" > "$tmp/kernel/uname"
touch "$tmp/kernel/.complete"

# Another run may have finished first: its copy is as good as ours.
[ -f "$dir/.complete" ] || rm -rf "$dir"
mv -T "$tmp/kernel" "$dir" 2>/dev/null || [ -f "$dir/.complete" ] || die "cannot move the kernel into $dir"
echo "$dir"
