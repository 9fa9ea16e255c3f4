#!/bin/sh
# SPDX-License-Identifier: MIT
# stage-python.sh DIR: Debian's own Python (/usr/bin/python3) with python3-can,
# laid out in DIR for the check-vm VM, whose initramfs has no Python:
#   DIR/bin/python3                       the interpreter (run.sh brings its libraries)
#   DIR/lib/python3X.zip                  the standard library and python3-can with what
#                                         it imports, compiled (no compiling under TCG)
#   DIR/lib/python3.X/lib-dynload/*.so    the extension modules (their libraries follow)
# Inside, PYTHONHOME=DIR (tests/canopen/canopen.sh links /usr/bin/python3 to it).
set -eu
dir=$1
py=/usr/bin/python3
[ -x "$py" ] || { echo "stage-python: $py is missing: apt-get install python3" >&2; exit 1; }
"$py" -c 'import can' 2>/dev/null || { echo "stage-python: python3-can is missing: apt-get install python3-can" >&2; exit 1; }
ver=$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
stdlib=/usr/lib/python$ver
rm -rf "$dir"
mkdir -p "$dir/bin" "$dir/lib/python$ver/lib-dynload"
cp -L "$py" "$dir/bin/python3"
for so in "$stdlib"/lib-dynload/*.so; do
  case $(basename "$so") in _test*|xx*|_tkinter*|_curses*|readline*|_ctypes_test*) ;; *) cp "$so" "$dir/lib/python$ver/lib-dynload/" ;; esac
done
"$py" - "$dir/lib/python$(echo "$ver" | tr -d .).zip" "$stdlib" <<'PY'
import os, sys, zipfile
out, stdlib = sys.argv[1], sys.argv[2]
# What a test master never imports: tests, GUIs, the packaging tools.
skip = {'test', 'idlelib', 'tkinter', 'turtledemo', 'lib2to3', 'ensurepip', 'site-packages', 'dist-packages',
        'pydoc_data', 'venv'}
def wanted(path):
    parts = set(os.path.relpath(path, stdlib).split(os.sep))
    return not (parts & skip) and not os.path.basename(path).startswith('config-')
import can, wrapt, packaging, typing_extensions, msgpack, serial, pkg_resources
with zipfile.PyZipFile(out, 'w', optimize=0) as z:
    z.writepy(stdlib, filterfunc=wanted)  # the top-level modules; packages one by one
    for name in sorted(os.listdir(stdlib)):
        path = os.path.join(stdlib, name)
        if os.path.isfile(os.path.join(path, '__init__.py')) and wanted(path):
            z.writepy(path, filterfunc=wanted)
    for mod in (can, wrapt, packaging, typing_extensions, msgpack, serial, pkg_resources):
        path = mod.__file__
        z.writepy(os.path.dirname(path) if path.endswith('__init__.py') else path)
PY
