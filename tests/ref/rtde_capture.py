#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""An independent reader of RTDE captures (urrt-dump --rtde -w FILE).

Written from the format as docs/rtde.md ("Captures") states it and from the
RTDE protocol (docs/rtde.md, "Wire format"), NOT from gateway/common/
rtde_capture.c or lib/urrt_rtde.c: the tests that read a capture with it
check urrt's writer and readers against what the format says. Wire types
come from tests/ref/rtde_ref.py, itself written from the protocol's
description. Standard library only.

The format:
    header   the 20 bytes b"URRT RTDE capture 1\\n"
    record   a kind byte, then one RTDE package: uint16 size (big-endian,
             the 3 header bytes included), uint8 type, size - 3 bytes
        b"C"  a connection began; the package's type is "C", its payload
              the peer as text ("robot:30004")
        b">"  a request the client sent, whole
        b"<"  a package the controller sent, whole
A record cut short by the end of the file is not an error: the writer was
stopped while writing it (see Capture.truncated).

Functions and classes:
    read(data) -> Capture
        data: the file's bytes. Capture.records: the list of Record
        (kind "C" / ">" / "<", type: the package's letter as a one-character
        str, payload: bytes, offset: of the kind byte in the file);
        Capture.truncated: bytes of a record cut short at the end (0: none).
        Raises CaptureError (.offset, str) for a file that is no capture
        (the header, offset 0) or a damaged one (a kind byte that is none of
        C, >, <, or a size outside 3..4096).
    read_file(path) -> Capture
        the same from a file.
    sessions(capture) -> [Session]
        the records as the client's sessions, one per "C": Session.peer,
        .protocol (2 once a V reply accepted a V request for 2, else 1),
        .controller (major, minor, bugfix, build) or None, .names (the last
        setup request's names), .frequency (its frequency; None in
        protocol 1), .types (the setup reply's types), .recipe_id (None in
        protocol 1), .texts ([(level, text, source)]), .data ([dict name ->
        value] in order: a number, or a tuple for a vector), .requests
        ([(type, payload)] as sent), .replies ([(type, payload)] every
        package from the controller).
    decode_data(payload, names, types, protocol) -> (recipe_id, {name: value})
        one data package's payload (after the 3 header bytes) by the types
        of the setup reply. Raises ValueError if its size is not the
        recipe's.

Command line:
    rtde_capture.py FILE            every record: offset, kind, type, size
    rtde_capture.py --recipe FILE   each session's recipe, comma-separated
    rtde_capture.py --json FILE     each data package as a JSON line keyed by
                                    RTDE name (vectors as lists)
Exit status 1 for a damaged capture (after what was read).
"""
import json
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rtde_ref import TYPES  # noqa: E402  the wire types: struct format and element count

MAGIC = b"URRT RTDE capture 1\n"
KINDS = (b"C", b">", b"<")
PACKAGE_MAX = 4096  # the format's bound on a package (RTDE's largest is far smaller)


class CaptureError(Exception):
    def __init__(self, offset, message):
        super().__init__("byte %d: %s" % (offset, message))
        self.offset = offset


class Record:
    def __init__(self, kind, type_, payload, offset):
        self.kind, self.type, self.payload, self.offset = kind, type_, payload, offset

    def __repr__(self):
        return "Record(%r, %r, %d bytes, @%d)" % (self.kind, self.type, len(self.payload), self.offset)


class Capture:
    def __init__(self):
        self.records = []
        self.truncated = 0


def read(data):
    cap = Capture()
    if data[:len(MAGIC)] != MAGIC:
        raise CaptureError(0, "no capture header %r" % MAGIC)
    at = len(MAGIC)
    while at < len(data):
        kind = data[at:at + 1]
        if kind not in KINDS:
            raise CaptureError(at, "record kind 0x%02X" % kind[0])
        if len(data) - at < 4:
            cap.truncated = len(data) - at
            break
        size = struct.unpack(">H", data[at + 1:at + 3])[0]
        if size < 3 or size > PACKAGE_MAX:
            raise CaptureError(at + 1, "package size %d" % size)
        if len(data) - at - 1 < size:
            cap.truncated = len(data) - at
            break
        pkg = data[at + 1:at + 1 + size]
        cap.records.append(Record(kind.decode(), chr(pkg[2]), pkg[3:], at))
        at += 1 + size
    return cap


def read_file(path):
    with open(path, "rb") as f:
        return read(f.read())


def decode_data(payload, names, types, protocol):
    at, recipe_id = 0, None
    if protocol >= 2:
        recipe_id, at = payload[0], 1
    values = {}
    for name, typ in zip(names, types):
        fmt, count = TYPES[typ]
        n = struct.calcsize(">" + fmt) * count
        if at + n > len(payload):
            raise ValueError("a data package of %d bytes, short of the recipe" % (len(payload) + 3))
        v = struct.unpack(">" + fmt * count, payload[at:at + n])
        values[name] = v if count > 1 else v[0]
        at += n
    if at != len(payload):
        raise ValueError("a data package of %d bytes, %d past the recipe" % (len(payload) + 3, len(payload) - at))
    return recipe_id, values


class Session:
    def __init__(self, peer):
        self.peer = peer
        self.protocol = 1
        self.asked = None            # the protocol the last V request asked for
        self.controller = None
        self.names, self.frequency, self.types, self.recipe_id = [], None, [], None
        self.texts, self.data, self.requests, self.replies = [], [], [], []

    def sent(self, t, p):
        self.requests.append((t, p))
        if t == "V":
            self.asked = struct.unpack(">H", p)[0]
        elif t == "O":
            if self.protocol >= 2:
                self.frequency, p = struct.unpack(">d", p[:8])[0], p[8:]
            self.names = p.decode().split(",")

    def received(self, t, p):
        self.replies.append((t, p))
        if t == "V" and p == b"\x01":
            self.protocol = self.asked
        elif t == "v":
            self.controller = struct.unpack(">IIII", p)
        elif t == "O":
            if self.protocol >= 2:
                self.recipe_id, p = p[0], p[1:]
            self.types = p.decode().split(",")
        elif t == "M":
            if self.protocol >= 2:
                n = p[0]
                m = p[1 + n]
                self.texts.append((p[2 + n + m], p[1:1 + n].decode(errors="replace"),
                                   p[2 + n:2 + n + m].decode(errors="replace")))
            else:
                self.texts.append((p[0], p[1:].decode(errors="replace"), ""))
        elif t == "U":
            self.data.append(decode_data(p, self.names, self.types, self.protocol)[1])


def sessions(capture):
    out = []
    for r in capture.records:
        if r.kind == "C":
            out.append(Session(r.payload.decode(errors="replace")))
        elif not out:
            raise CaptureError(r.offset, "a package before any connection")
        elif r.kind == ">":
            out[-1].sent(r.type, r.payload)
        else:
            out[-1].received(r.type, r.payload)
    return out


def main(argv):
    mode = argv[1] if len(argv) == 3 and argv[1] in ("--recipe", "--json") else None
    if len(argv) != (3 if mode else 2):
        print(__doc__.split("Command line:")[1], file=sys.stderr)
        return 2
    with open(argv[-1], "rb") as f:
        data = f.read()
    damaged = None
    try:
        cap = read(data)
    except CaptureError as e:
        damaged = e
        cap = Capture()
        if e.offset > 0:  # the records before the damage
            cap = read(data[:e.offset])
    if mode is None:
        for r in cap.records:
            print("%d %s %s %d" % (r.offset, r.kind, r.type, len(r.payload) + 3))
        if cap.truncated:
            print("truncated %d" % cap.truncated)
    else:
        for s in sessions(cap):
            if mode == "--recipe":
                print(",".join(s.names))
            else:
                for values in s.data:
                    print(json.dumps({k: list(v) if isinstance(v, tuple) else v for k, v in values.items()}))
    if damaged is not None:
        print("rtde_capture.py: %s: %s" % (argv[-1], damaged), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
