#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The scripted controller of check-fw-gateway's RTDE configurations, written
from the protocol (docs/rtde.md) and the capture format, apart from lib/.

  rtde_controller.py stream CAPTURE TABLES.c OUT
      The bytes a controller sends a client that asks for the recipe of
      TABLES.c (what `urrt-gateway --print-c-tables` wrote: the names in the
      comments of urrt_gateway_rtde_vars_0), made of the capture's first
      session: its replies to the protocol and controller version requests,
      its start reply and its text messages as they are; the setup reply with
      the recipe id and, for each of the client's names, the type the
      capture's reply gave it; each data package re-encoded for the client's
      recipe, every value's bytes sliced, byte for byte, from the capture's
      package by the capture's types. A name the capture lacks is refused.
      With [input]s in TABLES.c (urrt_gateway_inputs), after the setup reply
      one setup-inputs reply per input recipe, in order, accepting it with
      the id after the output recipe's (+1, +2, ...; urrt-gateway --replay
      --replay-inputs takes a capture's controller as doing the same), each
      register's type as the protocol gives it.

  rtde_controller.py check FIRMWARE_OUT TABLES.c STREAM
      What the firmware sent ("rtde> HEX" lines, one whole request each) is
      exactly the handshake of a read-only client: V (protocol 2), v, O
      (TABLES.c's frequency, or for 0 the maximum of the controller version
      STREAM's v reply names: 125 Hz on CB3, 500 later; and, in order, its
      recipe's names), S, and nothing else ever. With [input]s: V, v, O, one I
      per input recipe naming its registers in order, S, then input data
      packages only, each of an accepted recipe's id and size. Prints one
      line per check; exit status 1 on a failure.

Captures are read with tests/ref/rtde_capture.py, packages written with
tests/ref/rtde_ref.py: both from the format and the protocol, not from lib/.
"""
import os
import re
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "ref"))
import rtde_capture  # noqa: E402
import rtde_ref  # noqa: E402


def type_size(name):
    fmt, count = rtde_ref.TYPES[name]
    return struct.calcsize(">" + fmt) * count


def read_records(path):
    """[(kind, package bytes)] of an RTDE capture, kind one of b'C', b'>', b'<'."""
    try:
        cap = rtde_capture.read_file(path)
    except rtde_capture.CaptureError as e:
        sys.exit("%s: %s" % (path, e))
    return [(r.kind.encode(), rtde_ref.package(r.type.encode("latin-1"), r.payload)) for r in cap.records]


def recipe_of_tables(path):
    """The names and frequency of robot 0's recipe in generated tables."""
    text = open(path).read()
    m = re.search(r"urrt_gateway_rtde_vars_0\[\d+\] = \{\n(.*?)\n\};", text, re.S)
    f = re.search(r"urrt_gateway_rtde_frequency\[\d+\] = \{([^,}]+)", text)
    if not m or not f:
        sys.exit("%s: no RTDE recipe for robot 0 (urrt_gateway_rtde_vars_0, urrt_gateway_rtde_frequency)" % path)
    return re.findall(r"/\* (\S+) \*/", m.group(1)), float(f.group(1))


def inputs_of_tables(path):
    """Each input recipe of generated tables, in urrt_gateway_inputs' order: its register names."""
    text = open(path).read()
    table = re.search(r"urrt_gateway_inputs\[\d+\] = \{\n(.*?)\n\};", text, re.S)
    if not table:
        return []
    recipes = []
    for regs in re.findall(r"\{input_\w+_signals, input_\w+_vars, (input_\w+_regs),", table.group(1)):
        m = re.search(regs + r"\[\d+\] = \{\n(.*?)\n\};", text, re.S)
        if not m:
            sys.exit("%s: no %s" % (path, regs))
        recipes.append(re.findall(r"/\* (\S+) \*/", m.group(1)))
    return recipes


def first_session(records, path):
    start = [i for i, (k, _) in enumerate(records) if k == b"C"]
    if not start:
        sys.exit("%s: no connection record" % path)
    end = start[1] if len(start) > 1 else len(records)
    if len(start) > 1:
        print("%s: %d sessions; the controller replays the first" % (path, len(start)), file=sys.stderr)
    return records[start[0] + 1:end]


def stream(capture, tables, out_path):
    names, _ = recipe_of_tables(tables)
    inputs = inputs_of_tables(tables)
    session = first_session(read_records(capture), capture)
    protocol = 1
    sent = None  # the capture's setup request's names
    types = {}
    out = []
    for kind, pkg in session:
        ptype = pkg[2:3]
        body = pkg[3:]
        if kind == b">":
            if ptype == b"V":
                asked = struct.unpack(">H", body)[0]
            elif ptype == b"O":
                sent = body[8 if protocol == 2 else 0:].decode("ascii").split(",")
            continue
        if ptype == b"V":
            protocol = asked if body[0] == 1 else protocol
            out.append(pkg)
        elif ptype == b"O":
            rid = body[:1] if protocol == 2 else b""
            got = body[len(rid):].decode("ascii").split(",")
            types = dict(zip(sent, got))
            lacking = [n for n in names if n not in types or types[n] == "NOT_FOUND"]
            if lacking:
                sys.exit("%s: the recipe lacks %s: record it with urrt-dump --rtde -w FILE -k %s"
                         % (capture, ", ".join(lacking), ",".join(lacking)))
            out.append(rtde_ref.package(b"O", rid + ",".join(types[n] for n in names).encode("ascii")))
            first = body[0] + 1 if protocol == 2 else 1
            for k, regs in enumerate(inputs):
                out.append(rtde_ref.rep_setup_inputs(first + k, [rtde_ref.type_of(n) for n in regs]))
        elif ptype == b"U":
            at = 3 + (1 if protocol == 2 else 0)
            where = {}
            for n in sent:
                where[n] = (at, at + type_size(types[n]))
                at += type_size(types[n])
            if at != len(pkg):
                sys.exit("%s: a data package of %d bytes, not the recipe's %d" % (capture, len(pkg), at))
            rid = pkg[3:4] if protocol == 2 else b""
            out.append(rtde_ref.package(b"U", rid + b"".join(pkg[where[n][0]:where[n][1]] for n in names)))
        else:
            out.append(pkg)  # V, v, S replies and text messages as they came
    with open(out_path, "wb") as f:
        f.write(b"".join(out))


def first_body(stream_path, kind):
    """The payload of a stream's first package of type kind (bytes)."""
    data = open(stream_path, "rb").read()
    at = 0
    while at + 3 <= len(data):
        size = struct.unpack(">H", data[at:at + 2])[0]
        if data[at + 2:at + 3] == kind:
            return data[at + 3:at + size]
        at += max(size, 3)
    sys.exit("%s: no %s reply" % (stream_path, kind.decode()))


def controller_major(stream_path):
    return struct.unpack(">I", first_body(stream_path, b"v")[:4])[0]


def recipe_id_of(stream_path):
    """The output recipe's id in a stream's setup reply (protocol 2)."""
    return first_body(stream_path, b"O")[0]


def check(fw_out, tables, stream_path):
    names, freq = recipe_of_tables(tables)
    if freq == 0:
        freq = 125.0 if controller_major(stream_path) == 3 else 500.0
    sent = [bytes.fromhex(line[6:].strip()) for line in open(fw_out, errors="replace")
            if line.startswith("rtde> ")]
    failed = 0

    def verdict(ok, what):
        nonlocal failed
        print(("ok: " if ok else "FAIL: ") + what)
        failed += not ok

    whole = all(len(p) >= 3 and struct.unpack(">H", p[:2])[0] == len(p) for p in sent)
    verdict(whole, "each of the firmware's %d requests is one whole package" % len(sent))
    inputs = inputs_of_tables(tables)
    kinds = "".join(chr(p[2]) for p in sent if len(p) >= 3)
    handshake = "VvO" + "I" * len(inputs) + "S"
    if inputs:
        ok = re.fullmatch(handshake + "U*", kinds) is not None
        verdict(ok, "the firmware sent V, v, O, I (one per input recipe), S, then input data packages and nothing "
                "else (sent: %s%s)" % (" ".join(kinds[:len(handshake) + 3]) or "none",
                                      " ..." if len(kinds) > len(handshake) + 3 else ""))
        for k, regs in enumerate(inputs):
            i = sent[3 + k][3:].decode("ascii", "replace").split(",") if len(sent) > 3 + k else []
            verdict(i == regs, "its setup-inputs request %d names the generated input recipe, in order: %s%s"
                    % (k + 1, ",".join(regs), "" if i == regs else " (sent: %s)" % ",".join(i)))
        first = recipe_id_of(stream_path) + 1
        sizes = {first + k: 4 + sum(type_size(rtde_ref.type_of(n)) for n in regs) for k, regs in enumerate(inputs)}
        packages = sent[len(handshake):]
        verdict(bool(packages) and all(len(p) >= 4 and sizes.get(p[3]) == len(p) for p in packages),
                "its %d input data packages are each of an accepted recipe's id and size (%s)"
                % (len(packages), ", ".join("id %d: %d bytes" % kv for kv in sorted(sizes.items()))))
        if ok:  # the read-only client's checks on V, v, O, S
            sent = sent[:3] + [sent[len(handshake) - 1]]
            kinds = "VvOS"
    else:
        verdict(kinds == "VvOS", "the firmware sent V, v, O, S and nothing else (sent: %s)" % (" ".join(kinds) or "none"))
    if whole and kinds == "VvOS":
        verdict(struct.unpack(">H", sent[0][3:])[0] == 2, "it asked for protocol 2")
        o = sent[2][3:]
        verdict(struct.unpack(">d", o[:8])[0] == freq, "its setup request asks for %g Hz (the tables' frequency, 0: "
                "the controller's maximum)" % freq)
        got = o[8:].decode("ascii", "replace").split(",")
        verdict(got == names, "its setup request names the generated recipe, in order: %s%s"
                % (",".join(names), "" if got == names else " (sent: %s)" % ",".join(got)))
    print("%d failed" % failed)
    return 1 if failed else 0


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "stream":
        stream(sys.argv[2], sys.argv[3], sys.argv[4])
    elif len(sys.argv) == 5 and sys.argv[1] == "check":
        sys.exit(check(sys.argv[2], sys.argv[3], sys.argv[4]))
    else:
        sys.exit("usage: rtde_controller.py stream CAPTURE TABLES.c OUT | check FIRMWARE_OUT TABLES.c STREAM")


if __name__ == "__main__":
    main()
