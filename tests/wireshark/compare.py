#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-wireshark's comparison: tshark's dissection (PDML) of a capture against
urrt-dump's decoding of the same streams.

    compare.py DOC PDML LABEL CASE...      CASE is NAME:PORT:JSON:GNUPLOT:SKIPS

JSON "-" means the stream must not be dissected at all.
For the stream the simulator sent from PORT, every urrt message tshark shows is
held against the matching line of urrt-dump's JSON (length, generation,
versions, every element of every field, enumeration names) and of its gnuplot
output (every column, in order, bit for bit: the dissector must show each
double once, as a field or as a raw column). A field's double is read from the
bytes tshark shows for it (bit-exact), from its label (printed round-trip
exact) and from tshark's own value text (15 digits in Wireshark 4.0). Units
and element counts come from the field table in docs/protocol.md. SKIPS is the
number of implausible headers the stream holds (each must carry the expert
info). Prints ok:/FAIL: lines and a last line with the totals.
"""
import json
import math
import re
import struct
import sys
import xml.etree.ElementTree as ET

META = ("urrt.length", "urrt.generation", "urrt.versions")


def doc_fields(path):
    """name -> (count, unit) from the generated field table."""
    fields = {}
    row = re.compile(r"^\| `([a-z0-9_]+)` \| (\d+) \| ([^|]*) \|")
    with open(path) as f:
        for line in f:
            m = row.match(line)
            if m:
                unit = m.group(3).strip()
                fields[m.group(1)] = (int(m.group(2)), "" if unit == "-" else unit)
    return fields


def streams(pdml):
    """Server port -> the urrt items of tshark's tree, one list per message."""
    per_port = {}
    for packet in ET.parse(pdml).getroot().iter("packet"):
        port = None
        for proto in packet.findall("proto"):
            if proto.get("name") == "tcp":
                for f in proto.iter("field"):
                    if f.get("name") == "tcp.srcport":
                        port = f.get("show")
            elif proto.get("name") == "urrt":
                per_port.setdefault(port, []).append(list(walk(proto)))
    return per_port


def walk(node):
    """The urrt items below node in tree order; an expert info as its name."""
    for f in node.findall("field"):
        name = f.get("name", "")
        if name == "_ws.expert":
            for e in f.findall("field"):
                if e.get("name", "").startswith("urrt."):
                    yield ET.Element("expert", name=e.get("name"))
            continue
        if name.startswith("urrt."):
            yield f
        yield from walk(f)


def double(hexbytes):
    return struct.unpack(">d", bytes.fromhex(hexbytes))[0]


def same(a, b):
    """Bit-exact for numbers, any NaN for NaN (a JSON null is any non-finite)."""
    if b is None:
        return not math.isfinite(a)
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return struct.pack(">d", a) == struct.pack(">d", float(b))


def unit_of(unit, count, i):
    """Unit of element i: "m, rad" splits a pose's elements evenly."""
    units = [u.strip() for u in unit.split(",")] if unit else [""]
    return units[i * len(units) // count]


def check_message(items, rec, row, fields):
    """Errors (strings) and the number of field values compared."""
    errs = []
    by_name = {}
    for f in items:
        if f.tag == "field":
            by_name.setdefault(f.get("name"), []).append(f)
    show = lambda n: by_name[n][0].get("show") if n in by_name else None
    if show("urrt.length") != str(rec["length"]):
        errs.append("length %s, urrt-dump %s" % (show("urrt.length"), rec["length"]))
    if show("urrt.generation") != rec["generation"]:
        errs.append("generation %s, urrt-dump %s" % (show("urrt.generation"), rec["generation"]))
    if show("urrt.versions") != rec.get("versions"):
        errs.append("versions %s, urrt-dump %s" % (show("urrt.versions"), rec.get("versions")))

    doubles = [double(f.get("value")) for f in items if f.tag == "field" and f.get("name") not in META]
    columns = [float(x) for x in row]
    if len(doubles) != len(columns) or not all(same(a, b) for a, b in zip(doubles, columns)):
        errs.append("columns in tree order differ from urrt-dump's gnuplot line")

    names = {n[len("urrt."):] for n in by_name if n not in META and n != "urrt.column"}
    if rec.get("versions") is None and not any(f.tag == "expert" and f.get("name") == "urrt.length.unknown"
                                               for f in items):
        errs.append("no expert info on a length no known controller sends")
    dumped = {k for k in rec if k in fields}
    if names != dumped:
        errs.append("fields only in tshark %s, only in urrt-dump %s" % (sorted(names - dumped), sorted(dumped - names)))
    values = 0
    for name in sorted(names & dumped):
        count, unit = fields[name]
        elems = by_name["urrt." + name]
        want = rec[name] if count > 1 else [rec[name]]
        enum = rec.get(name + "_name")
        if enum is not None and count == 1:
            enum = [enum]
        if len(elems) != count or len(want) != count:
            errs.append("%s: %d elements, urrt-dump %d, table %d" % (name, len(elems), len(want), count))
            continue
        for i, (f, v) in enumerate(zip(elems, want)):
            values += 1
            d = double(f.get("value"))
            label = "%s[%d]" % (name, i) if count > 1 else name
            m = re.match(re.escape(label) + r": (.*)$", f.get("showname"))
            text = m.group(1) if m else ""
            if enum is not None:
                m = re.match(r"^(\w+) \((\S+)\)$", text)
                ok = m and m.group(1) == enum[i] and same(float(m.group(2)), v)
            elif unit == "bits":
                m = re.match(r"^(\S+) \((0x[0-9A-F]+)\)$", text)
                ok = m and same(float(m.group(1)), d) and v is not None and int(m.group(2), 16) == v and d == v
            else:
                u = unit_of(unit, count, i) if unit != "enum" else ""
                num = text[: -len(u) - 1] if u and text.endswith(" " + u) else (None if u else text)
                ok = num is not None and same(float(num), v)
            if unit != "bits":
                ok = ok and same(d, v)
            s = float(f.get("show"))
            ok = ok and (same(s, d) or math.isclose(s, d, rel_tol=1e-14))
            if not ok:
                errs.append("%s: tshark %r (%s, bytes %s), urrt-dump %r%s" % (
                    label, f.get("showname"), f.get("show"), f.get("value"), v,
                    " " + enum[i] if enum is not None else ""))
    return errs, values


def main():
    doc, pdml, label = sys.argv[1:4]
    fields = doc_fields(doc)
    per_port = streams(pdml)
    failed = messages = values = columns = 0
    for case in sys.argv[4:]:
        name, port, jpath, gpath, skips = case.split(":")
        msgs = per_port.get(port, [])
        if jpath == "-":
            if msgs:
                failed += 1
                print("FAIL: %s %s: %d messages dissected, expected none" % (label, name, len(msgs)))
            else:
                print("ok: %s %s: not taken for a robot's stream" % (label, name))
            continue
        with open(jpath) as f:
            recs = [json.loads(line) for line in f]
        with open(gpath) as f:
            rows = [line.split() for line in f if not line.startswith("#")]
        skipped = [m for m in msgs if any(f.get("name") == "urrt.skipped" for f in m)]
        real = [m for m in msgs if m not in skipped]
        errs = []
        noted = sum(1 for m in skipped if any(f.tag == "expert" and f.get("name") == "urrt.size.implausible"
                                              for f in m))
        if len(skipped) != int(skips) or noted != len(skipped):
            errs.append("%d skipped regions (%d with the expert info), expected %s" % (len(skipped), noted, skips))
        if not (len(real) == len(recs) == len(rows)) or not recs:
            errs.append("tshark shows %d messages, urrt-dump %d (gnuplot %d)" % (len(real), len(recs), len(rows)))
        n = 0
        for items, rec, row in zip(real, recs, rows):
            e, v = check_message(items, rec, row, fields)
            errs += ["message %d: %s" % (rec["packet"], x) for x in e]
            n += 1
            values += v
            columns += len(row)
        messages += n
        if errs:
            failed += 1
            print("FAIL: %s %s: %s" % (label, name, "; ".join(errs[:5])))
        else:
            print("ok: %s %s: %d messages as urrt-dump decodes them" % (label, name, n))
    print("%s compared: %d messages, %d field values, %d columns" % (label, messages, values, columns))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
