#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""A small RTDE client (UR's Real-Time Data Exchange, TCP 30004) written from
the protocol's description alone, for testing urrt-sim's RTDE port. It shares
no code with lib/ and imports nothing from the C side.

Wire format: every package is a big-endian uint16 size (the 3-byte header
included), a type letter, then the payload; every number is big-endian.
It writes inputs too: setup_inputs() ('I': names; the reply an input recipe
id and a type per name) and send_inputs() (a data package 'U' from the
client: the recipe id in protocol 2, then the values packed by its types).
"""
import select
import socket
import struct
import time

V, v_, M, U, O, I, S, P = b'V', b'v', b'M', b'U', b'O', b'I', b'S', b'P'

# Type token -> (struct format of one value, element count).
TYPES = {
    'BOOL': ('B', 1), 'UINT8': ('B', 1), 'UINT32': ('I', 1), 'UINT64': ('Q', 1), 'INT32': ('i', 1),
    'DOUBLE': ('d', 1), 'VECTOR3D': ('d', 3), 'VECTOR6D': ('d', 6), 'VECTOR6INT32': ('i', 6),
    'VECTOR6UINT32': ('I', 6),
}


CAPTURE_MAGIC = b'URRT RTDE capture 1\n'


class CaptureWriter:
    """Writes urrt's RTDE capture format (docs/rtde.md, "Captures"), from
    its description: the 20-byte header, then records, each a kind byte
    ('C' a connection began, '>' a request the client sent, '<' a package
    the controller sent) and a whole package (uint16 size incl. the 3-byte
    header, type, payload); a 'C' record's package is of type 'C' and holds
    the peer as text."""

    def __init__(self, path, append=False):
        """append: one more session at the end of a capture."""
        self.f = open(path, 'ab' if append else 'wb')
        if not append:
            self.f.write(CAPTURE_MAGIC)

    def record(self, kind, package):
        self.f.write(kind + package)

    def connected(self, peer):
        self.record(b'C', struct.pack('>HB', 3 + len(peer), ord('C')) + peer)

    def close(self):
        self.f.close()


class Closed(Exception):
    """The controller ended the connection (orderly: EOF)."""


class Unframable(Exception):
    """A package whose size field is below its own header."""


class Peer:
    def __init__(self, port, host='127.0.0.1', rcvbuf=None, timeout=5.0, capture=None):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if rcvbuf is not None:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock.settimeout(timeout)
        self.sock.connect((host, port))
        self.capture = capture  # a CaptureWriter: the session is recorded into it
        if capture is not None:
            capture.connected(b'%s:%d' % (host.encode(), port))
        self.buf = b''
        self.received = 0     # bytes read from the socket
        self.protocol = 1
        self.texts = []       # (level, message, source) of every text message read
        self.foreign = []     # (type, payload) of packages skipped while waiting for a reply
        self.types = None
        self.recipe_id = None
        self.inputs = {}      # input recipe id -> its types (valid recipes only)
        self.last_input = None  # the id of the last valid input recipe (protocol 1 packages go to it)
        self.timeout = timeout

    def close(self):
        self.sock.close()

    # ---- framing ----
    def send(self, letter, payload=b''):
        package = struct.pack('>HB', 3 + len(payload), letter[0]) + payload
        if self.capture is not None:
            self.capture.record(b'>', package)
        self.sock.sendall(package)

    def send_raw(self, data):
        self.sock.sendall(data)

    def _fill(self, n, deadline):
        while len(self.buf) < n:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError('no package within %.1f s' % self.timeout)
            r, _, _ = select.select([self.sock], [], [], left)
            if not r:
                continue
            chunk = self.sock.recv(65536)
            if not chunk:
                raise Closed('closed by the controller')
            self.received += len(chunk)
            self.buf += chunk

    def package(self, timeout=None):
        """The next package as (type letter, payload); text messages are
        decoded into self.texts as they pass but returned too."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        self._fill(3, deadline)
        size, kind = struct.unpack_from('>HB', self.buf)
        if size < 3:
            raise Unframable('size field %d' % size)
        self._fill(size, deadline)
        payload = self.buf[3:size]
        if self.capture is not None:
            self.capture.record(b'<', self.buf[:size])
        self.buf = self.buf[size:]
        letter = bytes([kind])
        if letter == M:
            self.texts.append(self.parse_text(payload))
        return letter, payload

    def parse_text(self, p):
        """v2: uint8 length, message, uint8 length, source, uint8 level.
        v1 (controller to client): uint8 level, then the message."""
        if self.protocol >= 2:
            n = p[0]
            msg = p[1:1 + n]
            m = p[1 + n]
            src = p[2 + n:2 + n + m]
            level = p[2 + n + m]
            if len(p) != 3 + n + m:
                raise ValueError('v2 text message of %d bytes holds %d' % (len(p), 3 + n + m))
            return level, msg.decode(), src.decode()
        return p[0], p[1:].decode(), None

    def request(self, letter, payload=b''):
        """Sends a request and returns the payload of the reply of the same
        type, skipping (and keeping) anything else that comes first."""
        self.send(letter, payload)
        for _ in range(1000):
            kind, p = self.package()
            if kind == letter:
                return p
            self.foreign.append((kind, p))
        raise RuntimeError('no reply to %r' % letter)

    # ---- the handshake ----
    def protocol_version(self, version):
        p = self.request(V, struct.pack('>H', version))
        if len(p) != 1:
            raise ValueError('V reply of %d bytes' % len(p))
        if p[0] == 1:
            self.protocol = version
        return p[0]

    def controller_version(self):
        p = self.request(v_)
        if len(p) != 16:
            raise ValueError('v reply of %d bytes' % len(p))
        return struct.unpack('>IIII', p)

    def setup_outputs(self, names, frequency=None):
        """Returns (recipe id or None in v1, [type tokens])."""
        body = ','.join(names).encode()
        if self.protocol >= 2:
            body = struct.pack('>d', frequency) + body
        p = self.request(O, body)
        if self.protocol >= 2:
            self.recipe_id, p = p[0], p[1:]
        self.types = p.decode().split(',')
        return self.recipe_id, self.types

    def setup_inputs(self, names):
        """Returns (input recipe id, [type tokens]); the reply carries the id
        in both protocol versions. Id 0 (a NOT_FOUND or IN_USE): invalid."""
        p = self.request(I, ','.join(names).encode())
        rid, types = p[0], p[1:].decode().split(',')
        if rid != 0:
            self.inputs[rid] = types
            self.last_input = rid
        return rid, types

    @staticmethod
    def pack(types, values):
        """Values (a tuple per vector) packed by their types, big-endian."""
        out = b''
        for t, v in zip(types, values):
            fmt, n = TYPES[t]
            out += struct.pack('>%d%s' % (n, fmt), *(v if n > 1 else (v,)))
        return out

    def input_package(self, rid, values, types=None):
        """The payload of an input data package: in protocol 2 the recipe id
        first, then the values by the recipe's (or the given) types."""
        body = self.pack(types or self.inputs[rid], values)
        return (bytes([rid]) if self.protocol >= 2 else b'') + body

    def send_inputs(self, rid, values, types=None):
        """Sends an input data package; the controller answers none."""
        self.send(U, self.input_package(rid, values, types))

    def start(self):
        return self.request(S)[0]

    def pause(self):
        return self.request(P)[0]

    # ---- data ----
    def size_of(self, types=None):
        types = types or self.types
        return (1 if self.protocol >= 2 else 0) + sum(struct.calcsize('>' + TYPES[t][0]) * TYPES[t][1]
                                                     for t in types)

    def decode(self, payload, types=None):
        """The values of a data package, a tuple per vector, by the recipe's
        types; raises ValueError when it does not match the recipe."""
        types = types or self.types
        if len(payload) != self.size_of(types):
            raise ValueError('data package of %d bytes, the recipe makes %d' % (len(payload), self.size_of(types)))
        off = 0
        if self.protocol >= 2:
            if payload[0] != self.recipe_id:
                raise ValueError('recipe id %d, not %d' % (payload[0], self.recipe_id))
            off = 1
        out = []
        for t in types:
            fmt, n = TYPES[t]
            vals = struct.unpack_from('>%d%s' % (n, fmt), payload, off)
            off += struct.calcsize('>%d%s' % (n, fmt))
            out.append(vals if n > 1 else vals[0])
        return out

    def data(self, count, timeout=None):
        """The next count data packages, decoded; other packages are kept in
        self.foreign (text messages in self.texts too)."""
        out = []
        while len(out) < count:
            kind, p = self.package(timeout)
            if kind == U:
                out.append(self.decode(p))
            else:
                self.foreign.append((kind, p))
        return out
