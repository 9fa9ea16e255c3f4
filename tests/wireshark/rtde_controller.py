#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-wireshark-rtde's edge-value controller: an RTDE server written from
the protocol's description (big-endian uint16 size with the 3 header bytes,
type letter, payload), sharing no code with lib/ or urrt-sim, for the values
urrt-sim never sends: negative INT32s and the extremes of every integer type,
BOOL bytes other than 0 and 1, -0.0, the smallest subnormal, infinities.

    rtde_controller.py PORT_FILE RECORD COUNT

Listens on 127.0.0.1 (port from the system, written to PORT_FILE), serves
one client in protocol 2: V, v (5.12.0.0), O (a type per name from TYPES,
recipe id 7), S; then COUNT data packages, all in one write (several per
segment), and closes. RECORD gets one JSON line per package: the values
sent, keyed by RTDE name.
"""
import json
import os
import socket
import struct
import sys

TYPES = {
    "timestamp": ("DOUBLE", "d", 1), "output_int_register_0": ("INT32", "i", 1),
    "joint_mode": ("VECTOR6INT32", "i", 6), "robot_status_bits": ("UINT32", "I", 1),
    "actual_digital_output_bits": ("UINT64", "Q", 1), "output_bit_register_64": ("BOOL", "B", 1),
    "tool_output_mode": ("UINT8", "B", 1), "actual_q": ("VECTOR6D", "d", 6),
}
RECIPE_ID = 7


def values(i):
    """Package i's values by name."""
    return {
        "timestamp": 2000.0 + i * 0.002, "output_int_register_0": -2 ** 31 + i,
        "joint_mode": [-1, -2 ** 31, 2 ** 31 - 1, 0, i, -i - 1], "robot_status_bits": 2 ** 32 - 1 - i,
        "actual_digital_output_bits": 2 ** 64 - 1 - i, "output_bit_register_64": [0, 1, 2, 255][i % 4],
        "tool_output_mode": 255 - i, "actual_q": [-0.0, 5e-324, float("inf"), float("-inf"), 1.7976931348623157e308,
                                                 i / 3.0],
    }


def package(letter, payload=b""):
    return struct.pack(">HB", 3 + len(payload), ord(letter)) + payload


def read_package(conn):
    head = b""
    while len(head) < 3:
        chunk = conn.recv(3 - len(head))
        if not chunk:
            raise EOFError("client closed")
        head += chunk
    size, letter = struct.unpack(">HB", head)
    body = b""
    while len(body) < size - 3:
        chunk = conn.recv(size - 3 - len(body))
        if not chunk:
            raise EOFError("client closed")
        body += chunk
    return chr(letter), body


def main():
    port_file, record, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(1)
    with open(port_file + ".tmp", "w") as f:
        f.write("%d\n" % srv.getsockname()[1])
    os.rename(port_file + ".tmp", port_file)
    conn, _ = srv.accept()
    names = []
    while True:
        letter, body = read_package(conn)
        if letter == "V":
            conn.sendall(package("V", b"\x01"))
        elif letter == "v":
            conn.sendall(package("v", struct.pack(">IIII", 5, 12, 0, 0)))
        elif letter == "O":
            names = body[8:].decode().split(",")  # after the v2 frequency
            types = ",".join(TYPES[n][0] for n in names).encode()
            conn.sendall(package("O", bytes([RECIPE_ID]) + types))
        elif letter == "S":
            conn.sendall(package("S", b"\x01"))
            break
    out, lines = b"", []
    for i in range(count):
        vals = values(i)
        payload = bytes([RECIPE_ID])
        for n in names:
            _, fmt, k = TYPES[n]
            payload += struct.pack(">%d%s" % (k, fmt), *(vals[n] if k > 1 else [vals[n]]))
        out += package("U", payload)
        lines.append(json.dumps({n: vals[n] for n in names}))
    with open(record, "w") as f:
        f.write("\n".join(lines) + "\n")
    conn.sendall(out)
    conn.close()


if __name__ == "__main__":
    main()
