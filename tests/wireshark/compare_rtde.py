#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-wireshark-rtde's comparison: tshark's dissection (PDML) of RTDE
sessions against the values a client decoded from the same sessions.

    compare_rtde.py DOC PDML LABEL CASE...
        CASE is NAME:PORT:JSON:PROTOCOL:TEXTS:EXTRA

For the session the simulator served on PORT, every data package tshark shows
is matched by its controller timestamp with one line of JSON (urrt-dump
--rtde -F json, whose keys are urrt field names for the variables RealTime
also has, which DOC's field table maps to RTDE names; or rtde_peer.py's,
keyed by RTDE name), and every line must be matched. The recipe (names and
types) is read here from the raw bytes of the setup request and reply as
tshark shows them, and each value from the bytes of its item with that type:
they must equal the client's value (bit for bit for doubles), tshark's own
value and the number in the item's label, and the items of a package must be
exactly the recipe's, in order, element by element. PROTOCOL is the protocol
the session must run (every package's "protocol in use" once the V reply
accepted it), TEXTS the least number of text messages it must show, EXTRA a
"+"-separated list of expert infos the session must carry (not_found,
setup_inputs); no other expert info may appear. Prints ok:/FAIL: lines and a
last line with the totals.
"""
import json
import math
import re
import struct
import sys
import xml.etree.ElementTree as ET

# RTDE type -> struct format of one element, elements.
TYPES = {
    "BOOL": ("B", 1), "UINT8": ("B", 1), "UINT32": ("I", 1), "UINT64": ("Q", 1), "INT32": ("i", 1),
    "DOUBLE": ("d", 1), "VECTOR3D": ("d", 3), "VECTOR6D": ("d", 6), "VECTOR6INT32": ("i", 6),
    "VECTOR6UINT32": ("I", 6),
}
DATA, SETUP = 0x55, 0x4F


def doc_rtde_names(path):
    """RTDE name -> urrt field name, from the "RTDE output" column."""
    names = {}
    row = re.compile(r"^\| `([a-z0-9_]+)` \|.*\| `([A-Za-z0-9_]+)` [A-Z0-9]+ \|")
    with open(path) as f:
        for line in f:
            m = row.match(line)
            if m:
                names[m.group(2)] = m.group(1)
    return names


def items(node):
    """The urrt_rtde items below node in tree order; expert infos as ("expert", name)."""
    for f in node.findall("field"):
        name = f.get("name", "")
        if name == "_ws.expert":
            for e in f.findall("field"):
                if e.get("name", "").startswith("urrt_rtde."):
                    yield ("expert", e.get("name"))
            continue
        if name.startswith("urrt_rtde."):
            yield (name, f)
        yield from items(f)


def sessions(pdml, ports):
    """Server port (one of ports) -> its packages in frame order, both
    directions, each a list of (name, element)."""
    per_port = {}
    for packet in ET.parse(pdml).getroot().iter("packet"):
        server = None
        for proto in packet.findall("proto"):
            if proto.get("name") == "tcp":
                for f in proto.iter("field"):
                    if f.get("name") in ("tcp.srcport", "tcp.dstport") and f.get("show") in ports:
                        server = f.get("show")
            elif proto.get("name") == "urrt_rtde":
                per_port.setdefault(server, []).append(list(items(proto)))
    return per_port


def first(pkg, name):
    for n, f in pkg:
        if n == name:
            return f
    return None


def raw(f):
    return bytes.fromhex(f.get("value"))


def same(a, b):
    """Bit-exact for doubles, equal for integers."""
    if isinstance(a, float) or isinstance(b, float):
        return struct.pack(">d", float(a)) == struct.pack(">d", float(b))
    return a == b


def check_package(pkg, recipe, rec, rtde_to_field):
    """Errors of one data package against one client record; values compared."""
    errs = []
    elems = [(n[len("urrt_rtde."):], f) for n, f in pkg
             if n not in ("expert", "urrt_rtde.size", "urrt_rtde.type", "urrt_rtde.protocol", "urrt_rtde.recipe_id")]
    want = [(name, typ, i) for name, typ in recipe for i in range(TYPES[typ][1])]
    if [n for n, _ in elems] != [name for name, _, _ in want]:
        return ["items %s, recipe %s" % ([n for n, _ in elems][:8], [w[0] for w in want][:8])], 0
    for (name, f), (_, typ, i) in zip(elems, want):
        fmt, count = TYPES[typ]
        b = raw(f)
        if len(b) != struct.calcsize(">" + fmt):
            errs.append("%s[%d]: %d bytes for %s" % (name, i, len(b), typ))
            continue
        value = struct.unpack(">" + fmt, b)[0]
        key = name if name in rec else rtde_to_field.get(name)
        if key not in rec:
            errs.append("%s: not in the client's record" % name)
            continue
        client = rec[key][i] if count > 1 else rec[key]
        shown = f.get("show")
        label = "%s[%d]" % (name, i) if count > 1 else name
        # "name: 1.5 rad", "name: 16 (0x10)", "name: RUNNING (7)", "name: true (1)"
        m = re.match(re.escape(label) + r": (\S+)(?: \((\S+)\))?", f.get("showname", ""))
        if fmt == "d":
            ok = same(value, float(client)) and m is not None and same(value, float(m.group(1))) and \
                (shown == "%.15g" % value or math.isclose(float(shown), value, rel_tol=1e-14, abs_tol=0))
        else:
            in_label = m is not None and str(value) in (m.group(1), m.group(2))
            ok = value == client and int(shown, 0) == value and in_label
        if not ok:
            errs.append("%s: bytes %s read %r, tshark %r / %r, client %r" % (label, b.hex(), value, shown,
                                                                            f.get("showname"), client))
    return errs, len(want)


def recipe_of(packages):
    """(names, types, recipe id) from the last setup request and reply, read from their bytes."""
    names = types = rid = None
    for pkg in packages:
        if int(first(pkg, "urrt_rtde.type").get("show"), 0) != SETUP:
            continue
        if first(pkg, "urrt_rtde.names") is not None:
            names = raw(first(pkg, "urrt_rtde.names")).decode().split(",")
        if first(pkg, "urrt_rtde.types") is not None:
            types = raw(first(pkg, "urrt_rtde.types")).decode().split(",")
            rid = first(pkg, "urrt_rtde.recipe_id")
            rid = int(rid.get("show")) if rid is not None else None
    return names, types, rid


def check_session(packages, recs, protocol, texts, extra, rtde_to_field):
    errs = []
    names, types, rid = recipe_of(packages)
    if not names or not types or len(names) != len(types) or any(t not in TYPES for t in types):
        return ["no valid recipe: names %s, types %s" % (names, types)], 0, 0
    recipe = list(zip(names, types))
    experts = sorted({f for pkg in packages for n, f in pkg if n == "expert"})
    want = sorted("urrt_rtde." + e for e in extra)
    if experts != want:
        errs.append("expert infos %s, expected %s" % (experts, want))
    by_time = {}
    for rec in recs:
        t = rec.get("time", rec.get("timestamp"))
        if t in by_time:
            errs.append("the client has two records at t=%r" % t)
        by_time[t] = rec
    data = [p for p in packages if int(first(p, "urrt_rtde.type").get("show"), 0) == DATA]
    n_texts = sum(1 for p in packages if first(p, "urrt_rtde.level") is not None)
    if n_texts < texts:
        errs.append("%d text messages shown, at least %d sent" % (n_texts, texts))
    matched, values = set(), 0
    for pkg in data:
        ts = first(pkg, "urrt_rtde.timestamp")
        t = struct.unpack(">d", raw(ts))[0] if ts is not None else None
        if t not in by_time or t in matched:
            errs.append("data package at t=%r: %s" % (t, "matched twice" if t in matched else "not in the client's"))
            continue
        matched.add(t)
        if first(pkg, "urrt_rtde.protocol").get("show") != str(protocol):
            errs.append("t=%r: protocol %s, the session's is %d" % (t, first(pkg, "urrt_rtde.protocol").get("show"),
                                                                   protocol))
        pid = first(pkg, "urrt_rtde.recipe_id")
        if (pid is not None) != (protocol >= 2) or (pid is not None and int(pid.get("show")) != rid):
            errs.append("t=%r: recipe id %s, setup's %s" % (t, pid.get("show") if pid is not None else None, rid))
        e, v = check_package(pkg, recipe, by_time[t], rtde_to_field)
        errs += ["t=%r: %s" % (t, x) for x in e]
        values += v
    if len(matched) != len(recs) or not recs:
        errs.append("tshark shows %d data packages, the client decoded %d" % (len(matched), len(recs)))
    return errs, len(matched), values


def main():
    doc, pdml, label = sys.argv[1:4]
    rtde_to_field = doc_rtde_names(doc)
    cases = [c.split(":") for c in sys.argv[4:]]
    per_port = sessions(pdml, {c[1] for c in cases})
    failed = packages = values = 0
    for name, port, jpath, protocol, texts, extra in cases:
        with open(jpath) as f:
            recs = [json.loads(line) for line in f if line.strip()]
        errs, n, v = check_session(per_port.get(port, []), recs, int(protocol), int(texts),
                                   [e for e in extra.split("+") if e], rtde_to_field)
        packages += n
        values += v
        if errs:
            failed += 1
            print("FAIL: %s %s: %s" % (label, name, "; ".join(errs[:5])))
        else:
            print("ok: %s %s: %d data packages, %d values as the client decoded them" % (label, name, n, v))
    print("%s compared: %d data packages, %d values" % (label, packages, values))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
