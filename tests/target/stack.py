#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Worst stack of every public lib/ function: the high-water marks a target
run painted (its "stack: NAME BYTES" lines) beside the worst path of
-fstack-usage frames through gcc's call graph (-fcallgraph-info=su .ci files
of the same build), and the table between <!-- stack:begin --> and
<!-- stack:end --> of docs/footprint.md, which must be these rows.

Agreement: for a function whose calls all stay in lib/, painted and static
must be equal (within TOLERANCE bytes: the frame of a path the run did not
take, or words a frame reserves but never writes); for one that calls
libgcc's soft-float routines, whose frames -fstack-usage cannot see, the
painted mark must cover the static lib/ part, and the difference is libgcc's.

Every function lib/*.h declares must have been measured.

Tail calls: where gcc ends a function in a jump to another (a sibling call,
`b`/`b.w` instead of `bl`), it pops the caller's frame before the jump, so
the callee runs at the depth the caller was entered at: that edge adds the
callee's worst path, not the caller's frame on top of it. The call graph
does not say which calls are jumps; the objects do. Each .ci file's object
(the .o beside it) is read with readelf -r: with -ffunction-sections every
call into another function is a relocation in the caller's section
(.rel.text.NAME), R_ARM_THM_CALL for a `bl`, R_ARM_THM_JUMP24, _JUMP19,
_JUMP11 or _JUMP8 for a branch. An edge is a tail call only if every
relocation from the caller to the callee is a branch; a caller that also
calls it with `bl` keeps its frame on that edge.

Usage: stack.py RUN_LOG FOOTPRINT_MD CI_FILE... (prints the table, then
"N passed, N failed")"""
import glob
import os
import re
import subprocess
import sys

TOLERANCE = 8
READELF = "arm-none-eabi-readelf"
# Relocations of a Thumb branch (b, b.w, b<cond>, b<cond>.w): a jump that does not return here.
BRANCHES = {"R_ARM_THM_JUMP24", "R_ARM_THM_JUMP19", "R_ARM_THM_JUMP11", "R_ARM_THM_JUMP8"}
# Declared in lib/*.h but not built for Cortex-M.
NOT_ON_CORTEX_M = {"urrt_x86_vector_bytes"}


def public_functions():
    """Every function lib/*.h declares (run from the repository's top)."""
    names = set()
    for header in sorted(glob.glob("lib/*.h")):
        if header.endswith("_internal.h"):
            continue  # a seam between two lib/ files, not for callers (lib/urrt_co_internal.h)
        names |= set(re.findall(r"^[a-z][^;(#]*?\b(urrt_\w+)\(", open(header).read(), re.M))
    return names - NOT_ON_CORTEX_M


def bare(title):
    """A call graph node's function name: a static one's title is FILE:NAME."""
    return title.rsplit(":", 1)[-1]


def relocations(obj):
    """{(caller, callee): relocation types} of an object's calls between functions."""
    out = subprocess.run([READELF, "-rW", obj], check=True, capture_output=True, text=True).stdout
    kinds, caller = {}, None
    for line in out.splitlines():
        # a function's cold part (.text.unlikely.NAME) calls as the function
        m = re.match(r"Relocation section '\.rela?\.text\.(?:unlikely\.|hot\.)?(\S+)'", line)
        if m:
            caller = m.group(1)
            continue
        if line.startswith("Relocation section"):
            caller = None  # data (.rel.rodata...): addresses, not calls
            continue
        fields = line.split()
        if caller is not None and len(fields) >= 5 and fields[2].startswith("R_ARM_"):
            callee = re.sub(r"^\.text\.", "", fields[4])
            if callee == caller + ".cold":
                continue  # a jump into its own cold part, no call
            kinds.setdefault((caller, callee), set()).add(fields[2])
    return kinds


def call_graph(paths):
    """Frames by node title, and each node's callees as (title, tail call)."""
    frames, edges = {}, {}
    for path in paths:
        kinds = relocations(os.path.splitext(path)[0] + ".o")
        for line in open(path):
            m = re.match(r'node: \{ title: "([^"]+)" label: "[^"]*\\n(\d+) bytes', line)
            if m:
                frames[m.group(1)] = int(m.group(2))
            m = re.match(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"', line)
            if m:
                k = kinds.get((bare(m.group(1)), bare(m.group(2))), set())
                edges.setdefault(m.group(1), set()).add((m.group(2), bool(k) and k <= BRANCHES))
    return frames, edges


def worst(name, frames, edges, seen=()):
    """(bytes, calls outside lib/) of the deepest path from name: a callee
    reached by a call below name's frame, one reached by a tail call at
    name's own depth."""
    if name not in frames:
        return 0, {name}
    if name in seen:
        sys.exit("stack.py: recursion through %s" % name)
    deepest, outside = frames[name], set()
    for callee, tail in edges.get(name, ()):
        b, o = worst(callee, frames, edges, seen + (name,))
        deepest = max(deepest, b if tail else frames[name] + b)
        outside |= o
    return deepest, outside


def main():
    log, doc, cis = sys.argv[1], sys.argv[2], sys.argv[3:]
    frames, edges = call_graph(cis)
    painted = [(m.group(1), int(m.group(2)))
               for m in re.finditer(r"^stack: (\w+) (\d+)$", open(log).read(), re.M)]
    passed = failed = 0

    def result(ok, text):
        nonlocal passed, failed
        if ok:
            passed += 1
        else:
            failed += 1
            print("FAIL: " + text)

    result(len(painted) > 0, "%s holds no stack lines" % log)
    unmeasured = public_functions() - {name for name, _ in painted}
    result(not unmeasured, "public lib/ functions without a stack measurement (tests/target/stack_target.h): "
           + ", ".join(sorted(unmeasured)))
    rows = ["| function | painted (bytes) | -fstack-usage call graph (bytes) |",
            "|---|---:|---:|"]
    for name, measured in painted:
        # urrt.h gives the framer's functions link names carrying URRT_MAX_DOUBLES.
        key = next((k for k in frames if re.sub(r"_URRT_MAX_DOUBLES_\d+$", "", k) == name), None)
        if key is None:
            result(False, "%s: not in the call graph" % name)
            continue
        static, outside = worst(key, frames, edges)
        if outside:
            note = "%d + libgcc" % static
            ok = measured >= static
            why = "painted %d below the static lib/ part %d" % (measured, static)
        else:
            note = "%d" % static
            ok = static - TOLERANCE <= measured <= static
            why = "painted %d, -fstack-usage %d" % (measured, static)
        result(ok, "%s: %s" % (name, why))
        rows.append("| `%s` | %d | %s |" % (name, measured, note))
    print("\n".join(rows))
    text = open(doc).read()
    m = re.search(r"<!-- stack:begin[^\n]*-->\n(.*?)<!-- stack:end -->", text, re.S)
    stated = [l for l in (m.group(1).splitlines() if m else []) if l.startswith("|")]
    result(stated == rows, "%s's stack table differs from the measured one above: replace it" % doc)
    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
