#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-wireshark-rtde's comparison: tshark's dissection (PDML) of RTDE
sessions against the values a client decoded from the same sessions.

    compare_rtde.py DOC PDML LABEL CASE...
        CASE is NAME:PORT:JSON:PROTOCOL:TEXTS:EXTRA[:SENT]

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
"+"-separated list of expert infos the session must carry (not_found, in_use,
input_recipe, data_size); no other expert info may appear. SENT, for a client
that writes inputs, is its record of every data package it sent (JSON lines:
id, names, types, values, whether the controller takes it): the client's
packages tshark shows must be those, in order, and each one the controller
takes must read, item by item, as its input recipe (names of the setup
request and types of its reply, read from their bytes, by the recipe id, or
in protocol 1 the last one) says, every value equal to the one sent.
Prints ok:/FAIL: lines and a last line with the totals.
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
DATA, SETUP, SETUP_INPUTS = 0x55, 0x4F, 0x49
# Inputs that are no output (UR's input list): lib's table, and so the
# dissector, has no field of their own; they show as urrt_rtde.other.KIND.
INPUT_ONLY = {"speed_slider_mask", "speed_slider_fraction", "standard_digital_output_mask", "standard_digital_output",
              "configurable_digital_output_mask", "configurable_digital_output", "tool_digital_output_mask",
              "tool_digital_output", "standard_analog_output_mask", "standard_analog_output_type",
              "standard_analog_output_0", "standard_analog_output_1", "external_force_torque"}
OTHER_KIND = {"BOOL": "bool", "UINT8": "uint8", "UINT32": "uint32", "VECTOR6UINT32": "uint32", "INT32": "int32",
              "VECTOR6INT32": "int32", "UINT64": "uint64", "DOUBLE": "double", "VECTOR3D": "double",
              "VECTOR6D": "double"}


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


class Package(list):
    """A package's items, (name, element) each; from_server: its direction."""
    from_server = True


def sessions(pdml, ports):
    """Server port (one of ports) -> its packages in frame order, both
    directions, each a Package."""
    per_port = {}
    for packet in ET.parse(pdml).getroot().iter("packet"):
        server = src = None
        for proto in packet.findall("proto"):
            if proto.get("name") == "tcp":
                for f in proto.iter("field"):
                    if f.get("name") == "tcp.srcport":
                        src = f.get("show")
                    if f.get("name") in ("tcp.srcport", "tcp.dstport") and f.get("show") in ports:
                        server = f.get("show")
            elif proto.get("name") == "urrt_rtde":
                pkg = Package(items(proto))
                pkg.from_server = src == server
                per_port.setdefault(server, []).append(pkg)
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
    shown_as = [("other." + OTHER_KIND[typ]) if name in INPUT_ONLY else name for name, typ, _ in want]
    if [n for n, _ in elems] != shown_as:
        return ["items %s, recipe %s" % ([n for n, _ in elems][:8], shown_as[:8])], 0
    elems = [(name, f) for (name, _, _), (_, f) in zip(want, elems)]
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
    data = [p for p in packages if int(first(p, "urrt_rtde.type").get("show"), 0) == DATA and p.from_server]
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


def input_recipes(packages):
    """The input recipes of a session from the bytes of its setups of
    inputs: id -> [(name, type)] for each accepted one (id not 0, a type
    per name), and the id of the last."""
    recipes, last, names = {}, None, None
    for pkg in packages:
        if int(first(pkg, "urrt_rtde.type").get("show"), 0) != SETUP_INPUTS:
            continue
        if not pkg.from_server:
            f = first(pkg, "urrt_rtde.names")
            names = raw(f).decode().split(",") if f is not None else []
            continue
        rid, types = first(pkg, "urrt_rtde.recipe_id"), first(pkg, "urrt_rtde.types")
        rid = raw(rid)[0] if rid is not None else 0
        types = raw(types).decode().split(",") if types is not None else []
        if rid != 0 and names is not None and len(types) == len(names) and all(t in TYPES for t in types):
            recipes[rid], last = list(zip(names, types)), rid
    return recipes, last


def check_inputs(packages, sent, protocol, rtde_to_field):
    """The client's data packages against what it sent."""
    errs, values = [], 0
    recipes, last = input_recipes(packages)
    mine = [p for p in packages if int(first(p, "urrt_rtde.type").get("show"), 0) == DATA and not p.from_server]
    if len(mine) != len(sent):
        return ["tshark shows %d data packages from the client, it sent %d" % (len(mine), len(sent))], 0
    for n, (pkg, rec) in enumerate(zip(mine, sent)):
        pid = first(pkg, "urrt_rtde.recipe_id")
        rid = raw(pid)[0] if pid is not None else last
        if (pid is not None) != (protocol >= 2) or (protocol >= 2 and int(pid.get("show")) != rec["id"]):
            errs.append("client package %d: recipe id %s, sent %s" % (n, pid.get("show") if pid is not None else None,
                                                                       rec["id"]))
            continue
        if not rec["taken"]:
            continue  # its expert info is the session's to show
        recipe = recipes.get(rid)
        if recipe is None or [nm for nm, _ in recipe] != rec["names"] or [t for _, t in recipe] != rec["types"]:
            errs.append("client package %d: input recipe %s is %s, sent as %s" % (n, rid, recipe, rec["names"]))
            continue
        vals = {nm: (tuple(v) if isinstance(v, list) else v) for nm, v in zip(rec["names"], rec["values"])}
        e, v = check_package(pkg, recipe, vals, rtde_to_field)
        errs += ["client package %d: %s" % (n, x) for x in e]
        values += v
    return errs, values


def main():
    doc, pdml, label = sys.argv[1:4]
    rtde_to_field = doc_rtde_names(doc)
    cases = [c.split(":") for c in sys.argv[4:]]
    per_port = sessions(pdml, {c[1] for c in cases})
    failed = packages = values = 0
    for name, port, jpath, protocol, texts, extra, *more in cases:
        with open(jpath) as f:
            recs = [json.loads(line) for line in f if line.strip()]
        errs, n, v = check_session(per_port.get(port, []), recs, int(protocol), int(texts),
                                   [e for e in extra.split("+") if e], rtde_to_field)
        if more:
            with open(more[0]) as f:
                sent = [json.loads(line) for line in f if line.strip()]
            e, w = check_inputs(per_port.get(port, []), sent, int(protocol), rtde_to_field)
            errs += e
            v += w
            if not e:
                print("ok: %s %s: the client's %d data packages as it sent them" % (label, name, len(sent)))
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
