#!/bin/sh
# SPDX-License-Identifier: MIT
# check-deb: the Debian package as a user gets it.
#  - make deb builds it; lintian finds no error and no warning (debian/ overrides justify any)
#  - its contents: programs, unit and template unit (neither enabled), conffile, man pages, docs,
#    examples, .lcm, jar, library and pkg-config file
#  - the library whole: liburrt.a's members are lib/lib.mk's objects, and every header of lib/ they
#    are compiled from (cc -MM) is installed as in the tree; a program using a function of each
#    header compiles and links with the package's `pkg-config urrt` flags alone
#  - what a robot is read over (the choices of [robot] source in the package's own --print-keys):
#    urrt-gateway(8) and urrt-gateway.ini(5) as installed name every [robot] key and each
#    `source = NAME`, the package's Description and urrt.pc name each source
#    (tests/man/check_man.py --named, --sources: check-man's test of the pages in the tree)
#  - every relative link in the installed README and documents resolves in the unpacked package
#    (tests/deb/doc_links.py), and the README keeps all the links it has in the tree
#  - dpkg installs it into a scratch root (a bootstrap of busybox and a dpkg database holding its
#    dependencies as the host has them: no container, no root of the host touched), the programs
#    run from there, the shipped example passes --check-config, the unedited /etc/urrt/gateway.ini
#    fails it naming the file to edit; dpkg removes and purges it and nothing of it is left.
set -u
BUILD=${BUILD:-build}
MAKE=${MAKE:-make}
LIB_SRCS=${LIB_SRCS:-}   # liburrt.a's sources, from tests/deb/deb.mk (lib/lib.mk's LIB_HOST_SRCS)
passed=0; failed=0
check() {
  what=$1; shift
  if "$@" >/dev/null 2>&1; then passed=$((passed + 1)); echo "ok: $what"
  else failed=$((failed + 1)); echo "FAIL: $what"; return 1; fi
}
finish() {
  echo "$passed passed, $failed failed"
  [ "$failed" = 0 ]; exit $?
}
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
version=$(sed -n 's/^#define URRT_VERSION_STRING "\(.*\)"/\1/p' lib/urrt.h)

start=$(date +%s)
$MAKE --no-print-directory -s BUILD="$BUILD" deb > "$T/deb.log" 2>&1; rc=$?
deb=$(ls "$BUILD"/deb/urrt_*.deb 2>/dev/null | head -n 1)
check "make deb builds $BUILD/deb/urrt_${version}_*.deb in $(($(date +%s) - start)) s" \
  sh -c "[ $rc = 0 ] && [ -f '$deb' ] && [ '$(dpkg-deb -f "$deb" Version 2>/dev/null)' = '$version' ]"
if [ ! -f "$deb" ]; then tail -n 30 "$T/deb.log"; finish; fi

lintian "$deb" > "$T/lintian" 2>&1
sed 's/^/lintian: /' "$T/lintian"
check "lintian: no error, no warning" sh -c "! grep -q '^[EW]: ' '$T/lintian'"

dpkg-deb -c "$deb" | awk '{print $6}' | sed 's|^\./|/|' > "$T/contents"
for f in /usr/bin/urrt-gateway /usr/bin/urrt-dump /usr/bin/urrt-sim /usr/bin/urrt-spy \
         /lib/systemd/system/urrt-gateway.service /lib/systemd/system/urrt-gateway@.service /etc/urrt/gateway.ini \
         /usr/share/man/man8/urrt-gateway.8.gz /usr/share/man/man5/urrt-gateway.ini.5.gz \
         /usr/share/man/man1/urrt-dump.1.gz /usr/share/man/man1/urrt-sim.1.gz /usr/share/man/man1/urrt-spy.1.gz \
         /usr/share/doc/urrt/copyright /usr/share/doc/urrt/README.md /usr/share/doc/urrt/gateway.md \
         /usr/share/doc/urrt/examples/canopen.ini \
         /usr/share/urrt/urrt-gateway.example.ini /usr/share/urrt/lcmtypes/state_t.lcm \
         /usr/share/java/urrt-lcmtypes.jar; do
  check "contents: $f" grep -qx "$f" "$T/contents"
done
check "contents: liburrt.a and urrt.pc under /usr/lib/<multiarch>" \
  sh -c "grep -q '^/usr/lib/[^/]*/liburrt.a$' '$T/contents' && grep -q '^/usr/lib/[^/]*/pkgconfig/urrt.pc$' '$T/contents'"
# The documents as a reader of /usr/share/doc/urrt gets them: every link followed.
dpkg-deb -x "$deb" "$T/pkg"
doc=$T/pkg/usr/share/doc/urrt
/usr/bin/python3 tests/deb/doc_links.py "$T/pkg" "$doc"/*.md > "$T/links" 2>&1; rc=$?
sed 's/^/links: /' "$T/links"
check "every relative link in the installed README and docs resolves (files, directories, #anchors)" \
  sh -c "[ $rc = 0 ] && grep -q '^usr/share/doc/urrt/README.md: ' '$T/links'"
tree=$(/usr/bin/python3 tests/deb/doc_links.py . README.md | sed -n 's/^README.md: \([0-9]*\) links.*/\1/p')
installed=$(sed -n 's|^usr/share/doc/urrt/README.md: \([0-9]*\) links.*|\1|p' "$T/links")
check "the installed README keeps the tree's ${tree:-?} relative links (has ${installed:-?})" \
  sh -c "[ -n '$tree' ] && [ '$tree' = '$installed' ]"
check "no document compressed (links name .md files)" sh -c "! grep -q '^/usr/share/doc/urrt/.*\.md\.gz$' '$T/contents'"

# The library whole, its headers derived from it: liburrt.a's members are the objects of lib/lib.mk's
# sources (LIB_SRCS, from tests/deb/deb.mk), and each header of lib/ those are compiled from is installed.
lib=$(grep -m 1 '^/usr/lib/[^/]*/liburrt\.a$' "$T/contents")
members=$(ar t "$T/pkg$lib" 2>/dev/null | sort | tr '\n' ' ')
objects=$(for s in $LIB_SRCS; do echo "$(basename "$s" .c).o"; done | sort | tr '\n' ' ')
check "liburrt.a's members are lib/lib.mk's objects (${members:-none})" sh -c "[ -n '$objects' ] && [ '$members' = '$objects' ]" ||
  echo "  the package's library is not the one lib/lib.mk builds: see debian/rules and gateway/install/install.mk"
headers=$(${CC:-cc} -MM $LIB_SRCS | tr ' \\' '\n\n' | grep '\.h$' | xargs -r realpath --relative-to=. | grep '^lib/' | sort -u)
check "cc -MM names the headers liburrt.a's sources are compiled from: $(echo $headers)" [ -n "$headers" ]
for h in $headers; do
  check "contents: /usr/include/${h##*/}, as $h (liburrt.a is compiled from it)" cmp -s "$h" "$T/pkg/usr/include/${h##*/}" ||
    echo "  install it with the library: gateway/install/install.mk installs each LIB_SRCS module's header (LIB_INSTALL_HDRS)"
done
# A program that includes every header and uses a function of each module's (a header with a
# lib/ source of its name: a seam such as urrt_co_internal.h declares none), built with the
# package's pkg-config file alone.
nm -g --defined-only "$T/pkg$lib" 2>/dev/null | awk '$2 == "T" { print $3 }' | sort -u > "$T/defined"
{ for h in $headers; do echo "#include <${h##*/}>"; done
  echo 'typedef void (*fn)(void);'; echo 'static volatile fn used[] = {'
  for h in $headers; do
    [ -f "${h%.h}.c" ] || continue
    f=$(grep -oE "\\<$(basename "$h" .h)_[a-z0-9_]+\\(" "$h" | tr -d '(' | sort -u | comm -12 - "$T/defined" | head -n 1)
    echo "    (fn)&${f:-no_function_of_$(basename "$h" .h)_in_liburrt},"
  done
  echo '};'; echo 'int main(void) { return used[0] == 0; }'; } > "$T/use.c"
pcdir=$T/pkg${lib%/*}/pkgconfig
flags=$(PKG_CONFIG_SYSROOT_DIR="$T/pkg" PKG_CONFIG_LIBDIR="$pcdir" pkg-config --cflags --libs urrt 2>&1)
${CC:-cc} -std=c99 -Wall -Wextra -Wpedantic -Werror -o "$T/use" "$T/use.c" $flags > "$T/use.log" 2>&1; rc=$?
sed 's/^/cc: /' "$T/use.log"
check "a program including every header and using a function of each module's ($(echo $(grep -o '&[a-z0-9_]*' "$T/use.c" | tr -d '&'))) builds with \`pkg-config urrt\` alone ($(echo $flags | sed "s|$T/pkg|PKG|g"))" \
  sh -c "[ $rc = 0 ] && '$T/use'"

# What a robot is read over, as the package's own --print-keys says: named in the installed pages,
# the package's Description and urrt.pc (check_man.py: the test check-man runs on the tree's pages).
/usr/bin/python3 tests/man/check_man.py --named "$T/pkg/usr/bin/urrt-gateway" \
  "$T/pkg/usr/share/man/man8/urrt-gateway.8.gz" "$T/pkg/usr/share/man/man5/urrt-gateway.ini.5.gz" > "$T/named" 2>&1; rc=$?
sed "s|^|pages: |; s|$T/pkg||g" "$T/named"
check "urrt-gateway(8) and urrt-gateway.ini(5) as installed name every [robot] key and each source (source = NAME)" \
  [ "$rc" = 0 ]
dpkg-deb -f "$deb" Description > "$T/Description"
grep '^Description:' "$pcdir/urrt.pc" > "$T/urrt.pc-Description" 2>/dev/null
/usr/bin/python3 tests/man/check_man.py --sources "$T/pkg/usr/bin/urrt-gateway" "$T/Description" "$T/urrt.pc-Description" \
  > "$T/sources" 2>&1; rc=$?
sed "s|^|sources: |; s|$T/||g" "$T/sources"
check "the package's Description and urrt.pc name each source a robot is read over" [ "$rc" = 0 ]

dpkg-deb --ctrl-tarfile "$deb" | tar -x -C "$T" ./conffiles ./postinst 2>/dev/null
check "conffiles: /etc/urrt/gateway.ini alone" sh -c "[ \"\$(cat '$T/conffiles')\" = /etc/urrt/gateway.ini ]"
check "the unit is not enabled on install (only if it was enabled before)" \
  sh -c "grep -q 'was-enabled' '$T/postinst' && ! grep -q 'systemctl.*start' '$T/postinst' && ! grep -q 'wants/' '$T/contents'"
check "the template unit is never enabled by the package (the administrator enables urrt-gateway@NAME)" \
  sh -c "! grep -q 'urrt-gateway@' '$T/postinst'"
dpkg-deb --fsys-tarfile "$deb" | tar -xO ./lib/systemd/system/urrt-gateway@.service > "$T/template" 2>/dev/null
check "the template unit runs /usr/bin/urrt-gateway on /etc/urrt/NAME.ini" \
  grep -qx 'ExecStart=/usr/bin/urrt-gateway /etc/urrt/%i.ini' "$T/template"

# The scratch root: busybox for the maintainer scripts, a dpkg database that
# knows the dependencies (copied from the host's), and a regular file for /dev/null.
R=$T/root
mkdir -p "$R/var/lib/dpkg/info" "$R/var/lib/dpkg/updates" "$R/var/lib/dpkg/triggers" "$R/bin" "$R/sbin" "$R/dev"
: > "$R/var/lib/dpkg/available"; : > "$R/dev/null"
cp /bin/busybox "$R/bin/busybox"
for a in $("$R/bin/busybox" --list); do [ -e "$R/bin/$a" ] || ln -s busybox "$R/bin/$a"; done
ln -s ../bin/true "$R/sbin/ldconfig"
deps=$(dpkg-deb -f "$deb" Depends | tr ',' '\n' | sed 's/(.*)//; s/|.*//; s/ //g')
for p in $deps; do dpkg-query -s "$p"; echo; done > "$R/var/lib/dpkg/status" 2>/dev/null
seed=$(find "$R" | wc -l)
dpkg --root="$R" -i "$deb" > "$T/install.log" 2>&1; rc=$?
sed 's/^/dpkg: /' "$T/install.log" | grep -v "^dpkg: (Reading database"
check "dpkg -i into the scratch root: installed, dependencies satisfied" \
  sh -c "[ $rc = 0 ] && dpkg --root='$R' -s urrt | grep -q '^Status: install ok installed'"
"$R/usr/bin/urrt-gateway" --version > "$T/v" 2>&1
check "urrt-gateway --version from the package: $(cat "$T/v")" grep -q "^urrt-gateway $version " "$T/v"
check "urrt-dump and urrt-sim --version from the package" \
  sh -c "'$R/usr/bin/urrt-dump' --version | grep -qx 'urrt-dump $version' && '$R/usr/bin/urrt-sim' -V | grep -qx 'urrt-sim $version'"
"$R/usr/bin/urrt-gateway" --check-config "$R/usr/share/urrt/urrt-gateway.example.ini" > "$T/ex" 2>&1; rc=$?
check "--check-config on the shipped example: valid" sh -c "[ $rc = 0 ] && grep -q ': valid$' '$T/ex'"
"$R/usr/bin/urrt-gateway" --print-dbc "$R/usr/share/doc/urrt/examples/canopen.ini" > "$T/dbc" 2>&1; rc=$?
check "--print-dbc on the shipped CAN example" sh -c "[ $rc = 0 ] && grep -q '^BO_ ' '$T/dbc'"
"$R/usr/bin/urrt-gateway" --check-config "$R/etc/urrt/gateway.ini" > "$T/conf" 2>&1; rc=$?
sed 's/^/conf: /' "$T/conf"
check "--check-config on the unedited /etc/urrt/gateway.ini: exit 2, names the file to edit" \
  sh -c "[ $rc = 2 ] && grep -q 'no robot: edit $R/etc/urrt/gateway.ini' '$T/conf'"
check "man urrt-gateway from the package" sh -c "man -l '$R/usr/share/man/man8/urrt-gateway.8.gz' | grep -q 'check-config'"

dpkg --root="$R" -r urrt > "$T/remove.log" 2>&1; rc=$?
check "dpkg -r: removed, the conffile kept" sh -c "[ $rc = 0 ] && [ -f '$R/etc/urrt/gateway.ini' ] && [ ! -e '$R/usr/bin/urrt-gateway' ]"
dpkg --root="$R" -P urrt > "$T/purge.log" 2>&1; rc=$?
left=$(find "$R" | grep -v "^$R/var/lib/dpkg" | grep -v "^$R/bin" | grep -v "^$R/sbin" | grep -v "^$R/dev")
check "dpkg -P: purged, nothing of the package left (left: $(echo $left | cut -c1-200))" \
  sh -c "[ $rc = 0 ] && [ -z \"\$(find '$R' -path '$R/var' -prune -o -path '$R/bin' -prune -o -path '$R/sbin' -prune -o -path '$R/dev' -prune -o -type f -print)\" ] && ! dpkg --root='$R' -s urrt 2>/dev/null | grep -q installed"
finish
