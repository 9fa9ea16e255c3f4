#!/bin/sh
# SPDX-License-Identifier: MIT
# check-deb: the Debian package as a user gets it.
#  - make deb builds it; lintian finds no error and no warning (debian/ overrides justify any)
#  - its contents: programs, unit and template unit (neither enabled), conffile, man pages, docs,
#    examples, .lcm, jar, C header, library and pkg-config file
#  - every relative link in the installed README and documents resolves in the unpacked package
#    (tests/deb/doc_links.py), and the README keeps all the links it has in the tree
#  - dpkg installs it into a scratch root (a bootstrap of busybox and a dpkg database holding its
#    dependencies as the host has them: no container, no root of the host touched), the programs
#    run from there, the shipped example passes --check-config, the unedited /etc/urrt/gateway.ini
#    fails it naming the file to edit; dpkg removes and purges it and nothing of it is left.
set -u
BUILD=${BUILD:-build}
MAKE=${MAKE:-make}
passed=0; failed=0
check() {
  what=$1; shift
  if "$@" >/dev/null 2>&1; then passed=$((passed + 1)); echo "ok: $what"
  else failed=$((failed + 1)); echo "FAIL: $what"; fi
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
         /usr/share/java/urrt-lcmtypes.jar /usr/include/urrt.h /usr/include/urrt_can.h /usr/include/urrt_cantx.h \
         /usr/include/urrt_co.h; do
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
