#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Independent reference for UR's RTDE protocol (TCP 30004), controller side.

Written from docs/rtde.md's wire format (UR's RTDE guide and UR's client
libraries as that page records them), NOT from lib/urrt_rtde.[ch]: the
names, types and layouts below were typed from the documents, so a mistake
in the C tables shows up as a disagreement instead of being copied into the
expectations.

It plays the controller in scripted sessions and writes, for each, what a
read-only client must send (byte for byte), what the controller answers, and
what the client must make of it: events, and every decoded value as raw bits.

Output format (one directive per line):
    session NAME
    vars NAME,NAME,...          the recipe, in order
    freq HZ                     frequency asked for (0: the controller's maximum)
    begin_error ERR             begin must refuse the recipe with ERR (ends the session)
    send HEX                    the next request the client must write
    recv HEX                    bytes from the controller (fed by `event`/`idle`)
    event KIND [ARGS]           feed until the next event; it must be this one:
        protocol N | fallback N | controller MAJOR MINOR BUGFIX BUILD | recipe ID | started | paused
        text LEVEL TEXTHEX SOURCEHEX ("-" for empty) | data FIRST
        drop ERR | config ERR [NOT_FOUND_NAME...]
    idle                        feed the rest: no event, nothing left
    value NAME ELEM HEX         after `data`: the element's raw bits (mapped
                                variables: the double in urrt_state; RTDE-only:
                                the C value, 2/8/16 hex digits by width)
    absent NAME                 after `data`: the variable is not present
    pause | start               the caller asks for a pause / a restart
    set_recipe NAME,...         the caller replaces the recipe (urrt_rtde_set_recipe, once the
                                controller version is known, before the setup request is taken)
    set_recipe_error ERR NAME,...  the same must be refused with ERR (ARG: not in that phase),
                                the recipe unchanged ("-": an empty list)
    finish N                    the connection closes: N bytes of a package dropped
    ended                       the rest of the input, and any more, is refused (session over)
    end
A seed corpus for the fuzz harness (tests/lib/fuzz_rtde.c) is written with
--corpus: each controller stream of the sessions whose recipe is FUZZ_VARS.

With --inputs it writes instead the sessions of a client that also writes
input registers (lib/urrt_rtde_in, tests/lib/test_rtde_in.c): the order
V v O I.. S, each setup-inputs request byte for byte, every reply token, and
the input data packages the client must write for given values, byte for
byte. The directives above, and:
    inputs G NAME,...           input recipe G (0, 1, ... in order): init must take it
    inputs_error ERR NAME,...   init must refuse this recipe with ERR (it is no recipe G)
    event inputs G ID           recipe G accepted, its id ID
    event config ERR NAME COUNT an input setup refused (IN_USE, NOT_FOUND): the first
                                register refused and how many; TYPE_MISMATCH: NAME only
    set G I int N RESULT        the caller gives register I of recipe G the integer N
    set G I double HEX RESULT   ... the double of these 64 bits; RESULT OK or VALUE (refused)
    forget G                    recipe G's registers lose their values
    package G HEX               the client's input data package for recipe G, byte for byte
    package G ERR               ... refused with ERR (NOT_STARTED, INCOMPLETE)
    refused G N                 values refused for recipe G so far
    ignored N                   packages the session ignored so far (replies nobody awaited)
    reconnect                   the connection closes on a package boundary and a new one
                                begins (the recipes and their values are kept)
Their corpus (--corpus with --inputs) seeds tests/lib/fuzz_rtde_in.c: each controller
stream of the sessions whose recipes are FUZZ_OUT_VARS and FUZZ_IN_VARS.

Usage: rtde_ref.py [--inputs] --out vectors.txt [--corpus DIR] [--seed N]
Standard library only.
"""
import argparse
import math
import os
import random
import struct

# ---- the protocol, from docs/rtde.md -----------------------------------------

V, v, M, U, O, I, S, P = b"V", b"v", b"M", b"U", b"O", b"I", b"S", b"P"

# Wire types: struct format of one element and element count.
TYPES = {
    "BOOL": ("B", 1), "UINT8": ("B", 1), "UINT32": ("I", 1), "UINT64": ("Q", 1),
    "INT32": ("i", 1), "DOUBLE": ("d", 1), "VECTOR3D": ("d", 3), "VECTOR6D": ("d", 6),
    "VECTOR6INT32": ("i", 6), "VECTOR6UINT32": ("I", 6),
}

# The outputs RealTime also has, with the urrt_state member they fill
# (the RealTime field of the same meaning), from the RTDE->RealTime table.
MAPPED = {
    "timestamp": ("DOUBLE", "time"),
    "target_q": ("VECTOR6D", "q_target"), "target_qd": ("VECTOR6D", "qd_target"),
    "target_qdd": ("VECTOR6D", "qdd_target"), "target_current": ("VECTOR6D", "i_target"),
    "target_moment": ("VECTOR6D", "m_target"), "actual_q": ("VECTOR6D", "q_actual"),
    "actual_qd": ("VECTOR6D", "qd_actual"), "actual_current": ("VECTOR6D", "i_actual"),
    "joint_control_output": ("VECTOR6D", "i_control"),
    "actual_TCP_pose": ("VECTOR6D", "tool_vector_actual"),
    "actual_TCP_speed": ("VECTOR6D", "tcp_speed_actual"),
    "actual_TCP_force": ("VECTOR6D", "tcp_force"),
    "target_TCP_pose": ("VECTOR6D", "tool_vector_target"),
    "target_TCP_speed": ("VECTOR6D", "tcp_speed_target"),
    "actual_digital_input_bits": ("UINT64", "digital_input_bits"),
    "joint_temperatures": ("VECTOR6D", "motor_temperatures"),
    "actual_execution_time": ("DOUBLE", "controller_timer"),
    "robot_mode": ("INT32", "robot_mode"), "joint_mode": ("VECTOR6INT32", "joint_modes"),
    "safety_mode": ("INT32", "safety_mode"),
    "actual_tool_accelerometer": ("VECTOR3D", "tool_accelerometer"),
    "speed_scaling": ("DOUBLE", "speed_scaling"),
    "actual_momentum": ("DOUBLE", "linear_momentum_norm"),
    "actual_main_voltage": ("DOUBLE", "v_main"), "actual_robot_voltage": ("DOUBLE", "v_robot"),
    "actual_robot_current": ("DOUBLE", "i_robot"), "actual_joint_voltage": ("VECTOR6D", "v_actual"),
    "actual_digital_output_bits": ("UINT64", "digital_outputs"),
    "runtime_state": ("UINT32", "program_state"),
    "elbow_position": ("VECTOR3D", "elbow_position"), "elbow_velocity": ("VECTOR3D", "elbow_velocity"),
    "safety_status": ("INT32", "safety_status"), "payload": ("DOUBLE", "payload_mass"),
    "payload_cog": ("VECTOR3D", "payload_cog"), "payload_inertia": ("VECTOR6D", "payload_inertia"),
}

# RTDE-only outputs (a selection covering every type and every family).
ONLY = {
    "target_speed_fraction": "DOUBLE", "robot_status_bits": "UINT32",
    "safety_status_bits": "UINT32", "tcp_offset": "VECTOR6D",
    "output_bit_registers0_to_31": "UINT32", "output_bit_registers32_to_63": "UINT32",
    "tool_output_mode": "UINT8", "tool_digital_output1_mode": "UINT8",
    "control_step": "UINT64", "time_scale_source": "INT32", "target_gravity": "VECTOR3D",
    "standard_analog_input1": "DOUBLE", "ft_raw_wrench": "VECTOR6D", "encoder1_raw": "INT32",
    "actual_configurable_digital_input_bits": "UINT64",
}
for i in range(64, 128):
    ONLY["output_bit_register_%d" % i] = "BOOL"
    ONLY["input_bit_register_%d" % i] = "BOOL"
for i in range(48):
    ONLY["output_int_register_%d" % i] = "INT32"
    ONLY["output_double_register_%d" % i] = "DOUBLE"
    ONLY["input_int_register_%d" % i] = "INT32"
    ONLY["input_double_register_%d" % i] = "DOUBLE"


def type_of(name):
    return MAPPED[name][0] if name in MAPPED else ONLY[name]


def package(kind, payload=b""):
    """size (uint16 BE, header included), type letter, payload."""
    return struct.pack(">HB", 3 + len(payload), kind[0]) + payload


# What the client sends.
def req_protocol(version):
    return package(V, struct.pack(">H", version))


def req_controller():
    return package(v)


def req_setup(protocol, freq, names):
    body = ",".join(names).encode("ascii")
    assert len(body) <= 2048, "name list of %d bytes past UR's limit" % len(body)
    return package(O, (struct.pack(">d", freq) if protocol == 2 else b"") + body)


def req_start():
    return package(S)


def req_pause():
    return package(P)


# What the controller answers.
def rep_flag(kind, accepted):
    return package(kind, bytes([accepted]))


def rep_controller(major, minor, bugfix, build):
    return package(v, struct.pack(">IIII", major, minor, bugfix, build))


def rep_setup(protocol, recipe_id, types):
    body = ",".join(types).encode("ascii")
    return package(O, (bytes([recipe_id]) if protocol == 2 else b"") + body)


def text_v2(level, text, source):
    return package(M, bytes([len(text)]) + text + bytes([len(source)]) + source + bytes([level]))


def text_v1(level, text):
    return package(M, bytes([level]) + text)


def data_package(protocol, recipe_id, names, values):
    body = bytes([recipe_id]) if protocol == 2 else b""
    for n in names:
        fmt, count = TYPES[type_of(n)]
        body += struct.pack(">" + fmt * count, *values[n])
    return package(U, body)


# ---- values -------------------------------------------------------------------

SPECIAL_DOUBLES = [0.0, -0.0, math.inf, -math.inf, 5e-324, -1.5, 1e300,
                   struct.unpack(">d", bytes.fromhex("7ff8000000000123"))[0]]


def random_values(rng, names, round_no):
    vals = {}
    for k, n in enumerate(names):
        fmt, count = TYPES[type_of(n)]
        out = []
        for e in range(count):
            pick = (round_no + k + e) % 5 == 0
            if fmt == "d":
                out.append(SPECIAL_DOUBLES[(round_no + k + e) % len(SPECIAL_DOUBLES)] if pick
                           else rng.uniform(-1000, 1000))
            elif fmt == "B":
                out.append(rng.choice([0, 1, 2, 255]) if type_of(n) == "BOOL" else rng.randrange(256))
            elif fmt == "i":
                out.append(rng.choice([-2**31, 2**31 - 1, -1]) if pick else rng.randrange(-2**31, 2**31))
            elif fmt == "I":
                out.append(rng.choice([0, 2**32 - 1]) if pick else rng.randrange(2**32))
            else:
                out.append(rng.choice([2**64 - 1, 2**53 + 1]) if pick and n not in MAPPED
                           else rng.randrange(2**18 if n in MAPPED else 2**64))
        vals[n] = out
    return vals


def bits_of_double(x):
    return struct.pack(">d", x).hex()


def expect_values(lines, names, values, absent=()):
    """What the decode must hold: mapped values as doubles in urrt_state (a
    double on the wire is copied bit for bit, an integer converted),
    RTDE-only values in their own C type."""
    for n in names:
        fmt, count = TYPES[type_of(n)]
        for e, x in enumerate(values[n]):
            if n in MAPPED:
                if fmt == "d":
                    raw = struct.pack(">d", x).hex()
                else:
                    raw = bits_of_double(float(x))
            elif fmt == "d":
                raw = struct.pack(">d", x).hex()
            elif fmt == "B":
                raw = "%02x" % (1 if (type_of(n) == "BOOL" and x) else x)
            elif fmt in "iI":
                raw = "%08x" % (x & 0xFFFFFFFF)
            else:
                raw = "%016x" % x
            lines.append("value %s %d %s" % (n, e, raw))
    for n in absent:
        lines.append("absent %s" % n)


# ---- sessions -------------------------------------------------------------------

# The recipe mirroring the RealTime fields urrt publishes (docs/rtde.md).
STATE_VARS = ["timestamp", "target_q", "target_qd", "target_qdd", "target_current",
              "target_moment", "actual_q", "actual_qd", "actual_current", "joint_control_output",
              "actual_TCP_pose", "actual_TCP_speed", "actual_TCP_force", "target_TCP_pose",
              "target_TCP_speed", "actual_digital_input_bits", "joint_temperatures",
              "actual_execution_time", "robot_mode", "joint_mode", "safety_mode",
              "actual_tool_accelerometer", "speed_scaling", "actual_momentum",
              "actual_main_voltage", "actual_robot_voltage", "actual_robot_current",
              "actual_joint_voltage", "actual_digital_output_bits", "runtime_state"]

# Every wire type that an output has, mapped and RTDE-only; the fuzz harness's recipe.
FUZZ_VARS = ["timestamp", "actual_q", "robot_mode", "joint_mode", "runtime_state",
             "actual_digital_input_bits", "actual_tool_accelerometer", "output_bit_register_64",
             "tool_output_mode", "robot_status_bits", "control_step", "output_int_register_5",
             "output_double_register_47", "target_gravity", "tcp_offset"]


class Session:
    def __init__(self, name, names, freq=0.0):
        self.lines = ["session " + name, "vars " + ",".join(names), "freq %r" % freq]
        self.names = names
        self.freq = freq
        self.stream = b""  # everything the controller sent, for the corpus

    def send(self, b):
        self.lines.append("send " + b.hex())

    def recv(self, b):
        self.stream += b
        self.lines.append("recv " + b.hex())

    def event(self, *args):
        self.lines.append("event " + " ".join(str(a) for a in args))

    def add(self, line):
        self.lines.append(line)

    def handshake(self, protocol=2, controller=(5, 12, 3, 1234), recipe_id=1, refuse_v2=False):
        self.send(req_protocol(2))
        if refuse_v2:
            self.recv(rep_flag(V, 0))
            self.event("fallback", 1)
            self.send(req_protocol(1))
        self.recv(rep_flag(V, 1))
        self.event("protocol", protocol)
        self.send(req_controller())
        self.recv(rep_controller(*controller))
        self.event("controller", *controller)
        freq = self.freq if self.freq > 0 else (125.0 if controller[0] < 5 else 500.0)
        self.send(req_setup(protocol, freq, self.names))
        self.recv(rep_setup(protocol, recipe_id, [type_of(n) for n in self.names]))
        self.event("recipe", recipe_id if protocol == 2 else 0)
        self.send(req_start())

    def started(self):
        self.recv(rep_flag(S, 1))
        self.event("started")

    def data(self, protocol, recipe_id, values, first, absent=()):
        self.recv(data_package(protocol, recipe_id, self.names, values))
        self.event("data", 1 if first else 0)
        expect_values(self.lines, self.names, values, absent)

    def end(self):
        self.lines.append("end")
        return self


def streaming(rng, name, names, protocol=2, packages=3, controller=(5, 12, 3, 1234), freq=0.0,
              refuse_v2=False, absent=()):
    s = Session(name, names, freq)
    s.handshake(protocol, controller, 7 if protocol == 2 else 0, refuse_v2)
    s.started()
    for k in range(packages):
        s.data(protocol, 7 if protocol == 2 else 0, random_values(rng, names, k), k == 0, absent)
    s.add("idle")
    return s.end()


def good_sessions(rng):
    out = []
    out.append(streaming(rng, "state_v2", STATE_VARS, absent=["payload", "elbow_position", "tcp_offset"]))
    out.append(streaming(rng, "every_type_v2", FUZZ_VARS, freq=125.0))
    out.append(streaming(rng, "every_type_v1", FUZZ_VARS, protocol=1, refuse_v2=True,
                         controller=(3, 15, 8, 106330)))
    out.append(streaming(rng, "double_registers_v2", ["output_double_register_%d" % i for i in range(48)] +
                         ["input_double_register_%d" % i for i in range(0, 48, 12)], packages=2))
    regs = (["output_int_register_%d" % i for i in range(48)] +
            ["output_double_register_%d" % i for i in (0, 23, 24, 47)] +
            ["output_bit_register_%d" % i for i in (64, 100, 127)] +
            ["output_bit_registers0_to_31", "output_bit_registers32_to_63", "safety_status_bits",
             "target_speed_fraction", "input_bit_register_127", "input_int_register_0",
             "input_double_register_23", "standard_analog_input1", "tool_digital_output1_mode",
             "encoder1_raw", "actual_configurable_digital_input_bits", "ft_raw_wrench",
             "time_scale_source"])
    out.append(streaming(rng, "registers_v2", regs, packages=2, controller=(5, 17, 0, 1)))
    out.append(streaming(rng, "cb3_v2", ["timestamp", "actual_q", "safety_mode"], controller=(3, 4, 0, 1),
                         freq=25.0, packages=2))

    # Text messages: before the V reply (v1 layout), during the handshake and
    # between data packages (v2 layout); data before the S reply starts;
    # replies nobody waits for are ignored; pause and start again.
    s = Session("texts_pause_v2", ["timestamp", "robot_status_bits"])
    s.send(req_protocol(2))
    s.recv(text_v1(3, b"RTDE server ready"))
    s.event("text", 3, b"RTDE server ready".hex(), "-")
    s.recv(rep_flag(V, 1))
    s.event("protocol", 2)
    s.send(req_controller())
    s.recv(text_v2(2, b"SafetySetup has not been confirmed yet", b"Controller"))
    s.event("text", 2, b"SafetySetup has not been confirmed yet".hex(), b"Controller".hex())
    s.recv(rep_flag(S, 1))  # a start reply while the controller version is awaited
    s.recv(rep_controller(10, 11, 0, 77))
    s.event("controller", 10, 11, 0, 77)
    s.send(req_setup(2, 500.0, s.names))
    s.recv(rep_setup(2, 3, ["DOUBLE", "UINT32"]))
    s.event("recipe", 3)
    s.send(req_start())
    vals = random_values(rng, s.names, 1)
    s.data(2, 3, vals, True)  # before the S reply
    s.recv(rep_flag(S, 1))    # ignored: the data package started it
    s.recv(text_v2(0, b"", b""))
    s.event("text", 0, "-", "-")
    s.recv(text_v2(1, b"x" * 255, b"y" * 255))
    s.event("text", 1, (b"x" * 255).hex(), (b"y" * 255).hex())
    s.add("pause")
    s.send(req_pause())
    s.data(2, 3, random_values(rng, s.names, 2), False)  # queued before the P reply
    s.recv(rep_flag(P, 1))
    s.event("paused")
    s.add("start")
    s.send(req_start())
    s.started()
    s.data(2, 3, random_values(rng, s.names, 3), False)
    s.add("idle")
    out.append(s.end())

    # v1 text messages after v1 was accepted.
    s = Session("text_v1", ["timestamp"])
    s.handshake(1, (3, 9, 1, 1), 0, True)
    s.recv(text_v1(1, b"a,b level one"))
    s.event("text", 1, b"a,b level one".hex(), "-")
    s.recv(text_v1(9, b""))
    s.event("text", 9, "-", "-")
    s.started()
    s.add("idle")
    out.append(s.end())
    return out


def failing(name, names, setup, freq=0.0):
    """A session that goes through `setup(s)` and must end as it says."""
    s = Session(name, names, freq)
    setup(s)
    return s.end()


TWO = ["timestamp", "actual_q"]


def after_handshake(extra, protocol=2):
    """Streaming (v2, or v1 after a refusal), then `extra`, which ends it."""
    def run(s):
        s.handshake(protocol, (5, 12, 3, 1234), 7 if protocol == 2 else 0, protocol == 1)
        s.started()
        extra(s)
        s.add("ended")
    return run


def before(kind_bytes, err):
    """A package in place of the V reply, which ends the session."""
    def run(s):
        s.send(req_protocol(2))
        s.recv(kind_bytes)
        s.event("drop", err)
        s.add("ended")
    return run


def framing_errors(rng):
    out = []
    two = TWO
    # The framer: sizes 0, 1, 2, larger than any package, and the largest.
    for size in (0, 1, 2):
        out.append(failing("size_%d" % size, two, before(struct.pack(">HB", size, V[0]) + b"\x01", "SIZE_SMALL")))
    out.append(failing("size_4097", two, before(struct.pack(">HB", 4097, M[0]), "SIZE_LARGE")))
    out.append(failing("size_65535", two, before(struct.pack(">HB", 65535, U[0]), "SIZE_LARGE")))
    # A setup reply whose type string is longer than the buffer.
    long_types = ",".join(["VECTOR6D"] * 500).encode()
    out.append(failing("types_too_long", two, lambda s: (
        s.send(req_protocol(2)), s.recv(rep_flag(V, 1)), s.event("protocol", 2), s.send(req_controller()),
        s.recv(rep_controller(5, 12, 0, 0)), s.event("controller", 5, 12, 0, 0),
        s.send(req_setup(2, 500.0, two)), s.recv(package(O, b"\x01" + long_types)),
        s.event("drop", "SIZE_LARGE"), s.add("ended"))))
    # Data packages: before the recipe, another id, a byte short and long.
    out.append(failing("data_before_recipe", two, before(package(U, b"\x01" + bytes(56)), "DATA_EARLY")))
    vals = random_values(rng, two, 0)
    good = data_package(2, 7, two, vals)
    out.append(failing("data_other_recipe", two, after_handshake(
        lambda s: (s.recv(data_package(2, 8, two, vals)), s.event("drop", "RECIPE_ID")))))
    out.append(failing("data_byte_short", two, after_handshake(
        lambda s: (s.recv(package(U, good[3:-1])), s.event("drop", "DATA_SIZE")))))
    out.append(failing("data_byte_long", two, after_handshake(
        lambda s: (s.recv(package(U, good[3:] + b"\x00")), s.event("drop", "DATA_SIZE")))))
    out.append(failing("data_v1_with_id", two, after_handshake(
        lambda s: (s.recv(good), s.event("drop", "DATA_SIZE")), protocol=1)))
    return out


def setup_errors():
    out = []
    two = TWO

    # Setup replies.
    def setup_reply(reply, *expect, names=two, controller=(5, 12, 3, 1234)):
        def run(s):
            s.send(req_protocol(2))
            s.recv(rep_flag(V, 1))
            s.event("protocol", 2)
            s.send(req_controller())
            s.recv(rep_controller(*controller))
            s.event("controller", *controller)
            s.send(req_setup(2, 125.0 if controller[0] < 5 else 500.0, names))
            s.recv(reply)
            s.event(*expect)
            s.add("ended")
        return run
    out.append(failing("type_not_a_type", two, setup_reply(rep_setup(2, 1, ["DOUBLE", "VECTOR7D"]),
                                                           "drop", "TYPE_TOKEN")))
    out.append(failing("type_in_use", two, setup_reply(rep_setup(2, 1, ["IN_USE", "VECTOR6D"]),
                                                       "drop", "TYPE_TOKEN")))
    out.append(failing("type_empty_entry", two, setup_reply(package(O, b"\x01DOUBLE,"), "drop", "TYPE_TOKEN")))
    out.append(failing("types_more", two, setup_reply(rep_setup(2, 1, ["DOUBLE", "VECTOR6D", "DOUBLE"]),
                                                      "drop", "TYPE_COUNT")))
    out.append(failing("types_fewer", two, setup_reply(rep_setup(2, 1, ["DOUBLE"]), "drop", "TYPE_COUNT")))
    out.append(failing("types_none", two, setup_reply(package(O, b"\x01"), "drop", "TYPE_COUNT")))
    out.append(failing("setup_no_id", two, setup_reply(package(O), "drop", "REPLY_LENGTH")))
    out.append(failing("type_mismatch", two, setup_reply(rep_setup(2, 1, ["DOUBLE", "VECTOR6UINT32"]),
                                                         "config", "TYPE_MISMATCH")))
    three = ["timestamp", "tcp_offset", "target_gravity"]
    out.append(failing("not_found", three, setup_reply(
        rep_setup(2, 0, ["DOUBLE", "NOT_FOUND", "NOT_FOUND"]), "config", "NOT_FOUND", "tcp_offset",
        "target_gravity", names=three)))
    return out


def text_and_reply_errors():
    out = []
    two = TWO

    # Text messages whose lengths run past the package (or stop short of it).
    def text_after_v(payload, err):
        def run(s):
            s.send(req_protocol(2))
            s.recv(rep_flag(V, 1))
            s.event("protocol", 2)
            s.send(req_controller())
            s.recv(package(M, payload))
            s.event("drop", err)
            s.add("ended")
        return run
    out.append(failing("text_len_past", two, text_after_v(bytes([10]) + b"short" + b"\x00\x01", "TEXT_LENGTH")))
    out.append(failing("text_source_past", two, text_after_v(b"\x01a\x09src\x01", "TEXT_LENGTH")))
    out.append(failing("text_short_of_end", two, text_after_v(b"\x01a\x01b\x02extra", "TEXT_LENGTH")))
    out.append(failing("text_empty", two, text_after_v(b"", "TEXT_LENGTH")))
    out.append(failing("text_v1_empty", two, before(package(M), "TEXT_LENGTH")))
    return out + reply_errors(TWO)


def reply_errors(two):
    out = []

    # Replies.
    def controller_reply(reply, *expect, freq=0.0):
        def run(s):
            s.send(req_protocol(2))
            s.recv(rep_flag(V, 1))
            s.event("protocol", 2)
            s.send(req_controller())
            s.recv(reply)
            s.event(*expect)
            s.add("ended")
        return run
    out.append(failing("version_zero", two, controller_reply(rep_controller(0, 0, 0, 0), "drop", "VERSION_ZERO")))
    out.append(failing("version_short", two, controller_reply(package(v, bytes(15)), "drop", "REPLY_LENGTH")))
    out.append(failing("frequency_past_cb3", two, controller_reply(rep_controller(3, 15, 0, 1), "config", "FREQUENCY"),
                       freq=200.0))
    out.append(failing("protocol_reply_long", two, before(package(V, b"\x01\x00"), "REPLY_LENGTH")))
    out.append(failing("protocol_reply_2", two, before(rep_flag(V, 2), "REPLY_VALUE")))
    out.append(failing("protocol_refused", two, lambda s: (
        s.send(req_protocol(2)), s.recv(rep_flag(V, 0)), s.event("fallback", 1), s.send(req_protocol(1)), s.recv(rep_flag(V, 0)),
        s.event("config", "PROTOCOL_REFUSED"), s.add("ended"))))

    def start_reply(flag, *expect):
        def run(s):
            s.handshake(2, (5, 12, 3, 1234), 7)
            s.recv(rep_flag(S, flag))
            s.event(*expect)
            s.add("ended")
        return run
    out.append(failing("start_refused", two, start_reply(0, "config", "START_REFUSED")))
    out.append(failing("pause_refused", two, after_handshake(
        lambda s: (s.add("pause"), s.send(req_pause()), s.recv(rep_flag(P, 0)), s.event("drop", "PAUSE_REFUSED")))))
    return out


def close_and_begin_errors(rng):
    out = []
    two = TWO
    vals = random_values(rng, two, 0)
    good = data_package(2, 7, two, vals)

    # The connection closes in the middle of a package: nothing decoded.
    def closed(s):
        s.handshake(2, (5, 12, 3, 1234), 7)
        s.started()
        s.recv(good[:20])
        s.add("idle")
        s.add("finish 20")
        s.add("ended")
    out.append(failing("closed_mid_package", two, closed))

    # Recipes begin refuses.
    out.append(failing("duplicate", ["actual_q", "timestamp", "actual_q"],
                       lambda s: s.add("begin_error DUPLICATE")))
    out.append(failing("names_too_long", ["input_double_register_%d" % i for i in range(48)] +
                       ["output_double_register_%d" % i for i in range(48)] +
                       ["input_int_register_%d" % i for i in range(32)],
                       lambda s: s.add("begin_error NAMES_TOO_LONG")))
    return out


def up_to_controller(s, protocol, controller):
    """The handshake up to the controller version: the setup request is due."""
    s.send(req_protocol(2))
    if protocol == 1:
        s.recv(rep_flag(V, 0))
        s.event("fallback", 1)
        s.send(req_protocol(1))
    s.recv(rep_flag(V, 1))
    s.event("protocol", protocol)
    s.send(req_controller())
    s.recv(rep_controller(*controller))
    s.event("controller", *controller)


def setup_and_stream(rng, s, protocol, freq, absent, packages=2):
    """The setup request for s.names, its reply, start, data packages."""
    recipe_id = 7 if protocol == 2 else 0
    s.send(req_setup(protocol, freq, s.names))
    s.add("set_recipe_error ARG timestamp")  # the setup request is out: too late
    s.recv(rep_setup(protocol, recipe_id, [type_of(n) for n in s.names]))
    s.event("recipe", recipe_id)
    s.send(req_start())
    s.started()
    for k in range(packages):
        s.data(protocol, recipe_id, random_values(rng, s.names, k), k == 0, absent)
    s.add("set_recipe_error ARG timestamp")  # streaming: too late
    s.add("idle")


def recipe_changes(rng):
    """The caller replaces the recipe once the controller's version is known
    (to leave out what it lacks): the setup request, the decode and the
    present fields follow the new one; a refused change, or one outside that
    phase, leaves the old one in force."""
    out = []
    # CB3 3.10 has no payload (3.11): the caller drops it and adds a register.
    s = Session("set_recipe_cb3", ["timestamp", "actual_q", "payload", "robot_status_bits"])
    s.add("set_recipe_error ARG timestamp")  # the version is not known yet
    up_to_controller(s, 2, (3, 10, 0, 1))
    s.add("set_recipe_error DUPLICATE timestamp,elbow_position,timestamp")
    s.add("set_recipe_error NAMES_TOO_LONG " + ",".join(
        ["input_double_register_%d" % i for i in range(48)] + ["output_double_register_%d" % i for i in range(48)] +
        ["input_int_register_%d" % i for i in range(32)]))
    s.add("set_recipe_error ARG -")
    s.names = ["actual_q", "timestamp", "output_int_register_30", "safety_status"]
    s.add("set_recipe " + ",".join(s.names))
    setup_and_stream(rng, s, 2, 125.0, ["payload", "robot_status_bits", "elbow_position"])
    out.append(s.end())
    # A refused change keeps the recipe begin gave (its present fields too);
    # protocol 1, whose setup request has no frequency.
    s = Session("set_recipe_refused_v1", ["timestamp", "actual_q", "robot_mode"])
    up_to_controller(s, 1, (3, 9, 1, 1))
    s.add("set_recipe_error DUPLICATE payload,payload")
    s.add("set_recipe_error DUPLICATE output_int_register_3,output_int_register_3")
    setup_and_stream(rng, s, 1, 125.0, ["payload", "output_int_register_3"])
    out.append(s.end())
    # Changed twice: the last one counts; fewer fields than begin's.
    s = Session("set_recipe_twice", STATE_VARS)
    up_to_controller(s, 2, (5, 4, 0, 9))
    s.add("set_recipe payload_inertia,tcp_offset")
    s.names = ["target_q", "speed_scaling", "actual_digital_output_bits"]
    s.add("set_recipe " + ",".join(s.names))
    setup_and_stream(rng, s, 2, 500.0, ["payload_inertia", "tcp_offset", "actual_q", "timestamp"], packages=3)
    out.append(s.end())
    return out


def error_sessions(rng):
    return (framing_errors(rng) + setup_errors() + text_and_reply_errors() + close_and_begin_errors(rng) +
            recipe_changes(rng))


# ---- writing input registers (docs/rtde.md "Writing registers") ------------------

# The input registers a client may write, with their wire types (the facts'
# input list, typed again here: these are inputs, ONLY holds them as outputs).
INPUTS = {"input_bit_registers0_to_31": "UINT32", "input_bit_registers32_to_63": "UINT32"}
for i in range(64, 128):
    INPUTS["input_bit_register_%d" % i] = "BOOL"
for i in range(48):
    INPUTS["input_int_register_%d" % i] = "INT32"
    INPUTS["input_double_register_%d" % i] = "DOUBLE"

IN_FMT = {"BOOL": ">B", "UINT32": ">I", "INT32": ">i", "DOUBLE": ">d"}


def req_setup_inputs(names):
    """Setup inputs: the names, comma-separated; no frequency (either protocol)."""
    return package(I, ",".join(names).encode("ascii"))


def rep_setup_inputs(recipe_id, words):
    return package(I, bytes([recipe_id]) + ",".join(words).encode("ascii"))


def dbl(bits_hex):
    return struct.unpack(">d", bytes.fromhex(bits_hex))[0]


def accepts(typ, kind, x):
    """Whether a register of wire type typ takes x given as an integer
    (kind "int") or a double ("double"), and the value it then holds: the
    register holds exactly what it was given, or refuses it."""
    if kind == "double":
        if math.isnan(x) or math.isinf(x):
            return False, None
        if typ == "DOUBLE":
            return True, x
        if x != math.floor(x):
            return False, None
        x = int(x)  # -0.0 is the integer 0
    if typ == "DOUBLE":  # an integer: only if a double holds it exactly
        return (True, float(x)) if int(float(x)) == x else (False, None)
    lo, hi = {"BOOL": (0, 1), "INT32": (-2**31, 2**31 - 1), "UINT32": (0, 2**32 - 1)}[typ]
    return (True, x) if lo <= x <= hi else (False, None)


class InRecipe:
    def __init__(self, names):
        self.names = names
        self.values = {}  # name -> value held; a name absent holds none
        self.refused = 0

    def payload(self):
        return b"".join(struct.pack(IN_FMT[INPUTS[n]], self.values[n]) for n in self.names)


class InSession(Session):
    """A session with input recipes: the controller, and the client's model
    of what it may write (accepted ids, whether it streams)."""

    def __init__(self, name, names, recipes, freq=0.0):
        Session.__init__(self, name, names, freq)
        self.recipes = [InRecipe(r) for r in recipes]
        self.ids = [0] * len(recipes)
        self.streaming = False
        self.ignored = 0
        for g, r in enumerate(recipes):
            self.add("inputs %d %s" % (g, ",".join(r)))

    def up_to_recipe(self, protocol=2, controller=(5, 12, 3, 1234), recipe_id=1):
        self.send(req_protocol(2))
        if protocol == 1:
            self.recv(rep_flag(V, 0))
            self.event("fallback", 1)
            self.send(req_protocol(1))
        self.recv(rep_flag(V, 1))
        self.event("protocol", protocol)
        self.send(req_controller())
        self.recv(rep_controller(*controller))
        self.event("controller", *controller)
        self.send(req_setup(protocol, 125.0 if controller[0] < 5 else 500.0, self.names))
        self.recv(rep_setup(protocol, recipe_id, [type_of(n) for n in self.names]))

    def setup_inputs(self, ids):
        """Each recipe's request in turn, each answered with its types and id."""
        for g, r in enumerate(self.recipes):
            self.send(req_setup_inputs(r.names))
            self.package_check(g)  # not accepted yet
            self.recv(rep_setup_inputs(ids[g], [INPUTS[n] for n in r.names]))
            self.event("inputs", g, ids[g])
            self.ids[g] = ids[g]
        self.send(req_start())

    def start_streaming(self):
        self.recv(rep_flag(S, 1))
        self.event("started")
        self.streaming = True

    def set(self, g, i, kind, x):
        r = self.recipes[g]
        name = r.names[i]
        ok, held = accepts(INPUTS[name], kind, x)
        arg = str(x) if kind == "int" else struct.pack(">d", x).hex()
        self.add("set %d %d %s %s %s" % (g, i, kind, arg, "OK" if ok else "VALUE"))
        if ok:
            r.values[name] = held
        else:
            r.values.pop(name, None)
            r.refused += 1

    def forget(self, g):
        self.add("forget %d" % g)
        self.recipes[g].values = {}

    def package_check(self, g):
        """What the client must write for recipe g now: nothing before the
        recipe is accepted and the session streams, nothing while a register
        has no value, else the package byte for byte."""
        r = self.recipes[g]
        if not (self.streaming and self.ids[g] != 0):
            self.add("package %d NOT_STARTED" % g)
        elif any(n not in r.values for n in r.names):
            self.add("package %d INCOMPLETE" % g)
        else:
            self.add("package %d %s" % (g, package(U, bytes([self.ids[g]]) + r.payload()).hex()))

    def foreign(self, b):
        """A package the client must ignore (and count)."""
        self.recv(b)
        self.ignored += 1

    def counts(self):
        self.add("ignored %d" % self.ignored)
        for g, r in enumerate(self.recipes):
            self.add("refused %d %d" % (g, r.refused))


REG3 = ["input_int_register_24", "input_double_register_24", "input_bit_register_64"]
# Every writable type, the fuzz harness's recipes (outputs read some back).
FUZZ_OUT_VARS = ["timestamp", "input_int_register_24", "input_double_register_30", "robot_status_bits"]
FUZZ_IN_VARS = ["input_int_register_24", "input_double_register_30", "input_bit_register_64",
                "input_bit_registers32_to_63", "input_int_register_47"]


def in_registers(rng):
    """The main case: one recipe of every writable type, read back through the
    output recipe; values given, refused, forgotten; pause and start."""
    s = InSession("in_registers_v2", FUZZ_OUT_VARS, [FUZZ_IN_VARS])
    s.up_to_recipe(recipe_id=1)
    s.event("recipe", 1)
    s.setup_inputs([4])
    s.package_check(0)  # accepted, start not yet
    s.set(0, 0, "int", 24)
    s.start_streaming()
    s.package_check(0)  # four registers have no value
    s.set(0, 1, "double", -2.5)
    s.set(0, 2, "int", 1)
    s.set(0, 3, "int", 0x80000001)
    s.set(0, 4, "int", -7)
    s.package_check(0)
    back = random_values(rng, s.names, 0)
    back["input_int_register_24"] = [24]
    back["input_double_register_30"] = [-2.5]
    s.data(2, 1, back, True)  # the registers read back as the controller holds them
    s.set(0, 4, "int", 2**31)  # refused: the register has no value now
    s.package_check(0)
    s.set(0, 4, "double", 2147483647.0)
    s.package_check(0)
    s.forget(0)
    s.package_check(0)
    for i, (kind, x) in enumerate([("int", -1), ("double", 1e-3), ("double", 0.0), ("double", 4294967295.0),
                                   ("int", -2**31)]):
        s.set(0, i, kind, x)
    s.package_check(0)
    s.add("pause")
    s.send(req_pause())
    s.streaming = False
    s.package_check(0)  # a pause is asked: nothing more
    s.recv(rep_flag(P, 1))
    s.event("paused")
    s.package_check(0)
    s.add("start")
    s.send(req_start())
    s.start_streaming()
    s.package_check(0)
    s.data(2, 1, random_values(rng, s.names, 1), False)
    s.add("idle")
    s.counts()
    return s.end()


def in_edge_values():
    """Edge values packed byte for byte, refused ones never packed."""
    regs = (["input_int_register_24", "input_int_register_25"] +
            ["input_double_register_%d" % i for i in range(24, 32)] +
            ["input_bit_register_64", "input_bit_register_127", "input_bit_registers0_to_31",
             "input_bit_registers32_to_63"])
    s = InSession("in_edge_values_v2", ["timestamp"], [regs])
    s.up_to_recipe(recipe_id=2)
    s.event("recipe", 2)
    s.setup_inputs([255])
    s.start_streaming()
    doubles = ["8000000000000000",  # -0.0
               "0000000000000001",  # the least denormal
               "8000000000000001",
               "7fefffffffffffff",  # the largest double
               "ffefffffffffffff",
               "0010000000000000",  # the least normal
               "000fffffffffffff",  # the largest denormal
               "3ff0000000000000"]
    first = [("int", -2**31), ("int", 2**31 - 1)] + [("double", dbl(h)) for h in doubles] +             [("int", 0), ("int", 1), ("int", 0xFFFFFFFF), ("int", 0)]
    for i, (kind, x) in enumerate(first):
        s.set(0, i, kind, x)
    s.package_check(0)
    refused = [(0, "int", 2**31), (1, "int", -2**31 - 1), (0, "double", 1.5), (0, "double", dbl("7ff8000000000000")),
               (0, "double", math.inf), (0, "double", 2147483648.0), (0, "double", dbl("0000000000000001")),
               (1, "double", -2147483649.0),
               (2, "double", dbl("7ff8000000000000")), (3, "double", dbl("7ff0000000000001")),
               (4, "double", dbl("fff8000000000000")), (5, "double", math.inf), (6, "double", -math.inf),
               (2, "int", 2**53 + 1), (3, "int", 2**63 - 1), (4, "int", -2**53 - 1),
               (10, "int", 2), (10, "int", -1), (11, "double", 0.5), (11, "double", dbl("0000000000000001")),
               (12, "int", -1), (12, "int", 2**32), (13, "double", 4294967296.0), (13, "double", -1.0)]
    for i, kind, x in refused:
        s.set(0, i, kind, x)
        s.package_check(0)
    accepted = [(0, "double", -2147483648.0), (1, "double", dbl("8000000000000000")),  # -0.0: the integer 0
                (2, "int", 2**53), (3, "int", -2**63), (4, "int", -(2**53)), (5, "double", 1e-300),
                (6, "double", -1.7976931348623157e308), (7, "int", 0),
                (10, "double", 1.0), (11, "double", dbl("8000000000000000")),
                (12, "double", 4294967295.0), (13, "int", 0x80000000)]
    for i, kind, x in accepted:
        s.set(0, i, kind, x)
    s.package_check(0)
    s.add("idle")
    s.counts()
    return s.end()


def in_three_recipes():
    """Several input recipes: one request at a time, start after the last reply."""
    recipes = [["input_int_register_30"], ["input_double_register_40", "input_bit_register_100"],
               ["input_bit_registers0_to_31", "input_int_register_31", "input_double_register_47"]]
    s = InSession("in_three_recipes_v2", ["timestamp", "actual_q"], recipes)
    s.up_to_recipe(recipe_id=1)
    s.event("recipe", 1)
    s.setup_inputs([2, 3, 9])
    s.start_streaming()
    s.set(0, 0, "int", 30)
    s.set(1, 0, "double", 40.5)
    s.set(1, 1, "int", 1)
    s.set(2, 0, "int", 0x00FF00FF)
    s.set(2, 1, "int", -31)
    s.set(2, 2, "double", -47.25)
    for g in range(3):
        s.package_check(g)
    s.forget(1)
    for g in range(3):
        s.package_check(g)
    s.add("idle")
    s.counts()
    return s.end()


def in_foreign():
    """Packages before the reply: a text message (an event), replies nobody
    waits for and unknown letters (ignored), an 'I' before the request and
    after every reply (ignored)."""
    s = InSession("in_foreign_v2", ["timestamp"], [REG3])
    s.send(req_protocol(2))
    s.recv(rep_flag(V, 1))
    s.event("protocol", 2)
    s.send(req_controller())
    s.recv(rep_controller(5, 12, 3, 1234))
    s.event("controller", 5, 12, 3, 1234)
    s.send(req_setup(2, 500.0, s.names))
    s.foreign(rep_setup_inputs(3, ["INT32", "DOUBLE", "BOOL"]))  # before its request: nobody waits for it
    s.recv(rep_setup(2, 1, ["DOUBLE"]))
    s.event("recipe", 1)
    s.send(req_setup_inputs(REG3))
    s.recv(text_v2(2, b"input registers 0-23 are the fieldbus's", b"RTDE"))
    s.event("text", 2, b"input registers 0-23 are the fieldbus's".hex(), b"RTDE".hex())
    s.foreign(rep_flag(V, 1))
    s.foreign(rep_setup(2, 1, ["DOUBLE"]))
    s.foreign(package(b"X", b"\x01\x02"))
    s.foreign(rep_flag(P, 1))
    s.foreign(package(b"Q"))
    s.recv(text_v2(3, b"", b""))
    s.event("text", 3, "-", "-")
    s.recv(rep_setup_inputs(3, ["INT32", "DOUBLE", "BOOL"]))
    s.event("inputs", 0, 3)
    s.ids[0] = 3
    s.foreign(rep_setup_inputs(4, ["INT32", "DOUBLE", "BOOL"]))  # every reply is in: ignored
    s.send(req_start())
    s.start_streaming()
    s.foreign(rep_setup_inputs(5, ["INT32", "DOUBLE", "BOOL"]))
    for i, x in enumerate([-24, 24.0, 1]):
        s.set(0, i, "int" if i != 1 else "double", x)
    s.package_check(0)
    s.add("idle")
    s.counts()
    return s.end()


def in_reconnect():
    """A reconnect sets the inputs up again: nothing is written until the new
    session accepts them (under its new id); the values are kept."""
    s = InSession("in_reconnect_v2", ["timestamp"], [REG3])
    s.up_to_recipe(recipe_id=1)
    s.event("recipe", 1)
    s.setup_inputs([7])
    s.start_streaming()
    for i, x in enumerate([1, 2.0, 0]):
        s.set(0, i, "int" if i != 1 else "double", x)
    s.package_check(0)
    s.add("reconnect")
    s.streaming = False
    s.ids = [0]
    s.package_check(0)
    s.up_to_recipe(recipe_id=1)
    s.event("recipe", 1)
    s.setup_inputs([8])
    s.package_check(0)
    s.start_streaming()
    s.package_check(0)
    s.add("idle")
    s.counts()
    return s.end()


def in_reply_errors():
    """Every reply token and shape: refusals (configuration), broken replies
    (protocol); the session ends and nothing is ever written."""
    out = []

    def refused(name, reply, *expect):
        s = InSession(name, ["timestamp"], [REG3])
        s.up_to_recipe(recipe_id=1)
        s.event("recipe", 1)
        s.send(req_setup_inputs(REG3))
        s.recv(reply)
        s.event(*expect)
        s.package_check(0)
        s.add("ended")
        s.package_check(0)
        out.append(s.end())
    words = lambda *w: rep_setup_inputs(0, list(w))
    refused("in_reply_in_use", words("IN_USE", "DOUBLE", "BOOL"), "config", "IN_USE", REG3[0], 1)
    refused("in_reply_in_use_two", words("INT32", "IN_USE", "IN_USE"), "config", "IN_USE", REG3[1], 2)
    refused("in_reply_in_use_id", rep_setup_inputs(7, ["IN_USE", "IN_USE", "IN_USE"]), "config", "IN_USE", REG3[0], 3)
    refused("in_reply_not_found", words("INT32", "DOUBLE", "NOT_FOUND"), "config", "NOT_FOUND", REG3[2], 1)
    refused("in_reply_mixed", words("IN_USE", "NOT_FOUND", "NOT_FOUND"), "config", "NOT_FOUND", REG3[1], 2)
    refused("in_reply_mixed_order", words("NOT_FOUND", "IN_USE", "BOOL"), "config", "NOT_FOUND", REG3[0], 1)
    refused("in_reply_mismatch", rep_setup_inputs(5, ["INT32", "INT32", "BOOL"]), "config", "TYPE_MISMATCH", REG3[1])
    refused("in_reply_more", rep_setup_inputs(5, ["INT32", "DOUBLE", "BOOL", "BOOL"]), "drop", "TYPE_COUNT")
    refused("in_reply_fewer", rep_setup_inputs(5, ["INT32", "DOUBLE"]), "drop", "TYPE_COUNT")
    refused("in_reply_trailing_comma", package(I, b"\x05INT32,DOUBLE,BOOL,"), "drop", "TYPE_COUNT")
    refused("in_reply_no_types", package(I, b"\x05"), "drop", "TYPE_COUNT")
    refused("in_reply_no_id", package(I), "drop", "REPLY_LENGTH")
    refused("in_reply_unknown_word", rep_setup_inputs(5, ["INT32", "FLOAT", "BOOL"]), "drop", "TYPE_TOKEN")
    refused("in_reply_lower_case", rep_setup_inputs(5, ["int32", "DOUBLE", "BOOL"]), "drop", "TYPE_TOKEN")
    refused("in_reply_empty_word", package(I, b"\x05INT32,,BOOL"), "drop", "TYPE_TOKEN")
    refused("in_reply_space", package(I, b"\x00NOT_FOUND ,DOUBLE,BOOL"), "drop", "TYPE_TOKEN")
    refused("in_reply_refusal_then_word", words("NOT_FOUND", "VECTOR7D", "BOOL"), "drop", "TYPE_TOKEN")
    refused("in_reply_id_zero", words("INT32", "DOUBLE", "BOOL"), "drop", "RECIPE_ID")
    return out


def in_protocol_1():
    """Inputs need protocol 2: a controller that speaks 1 only is a
    configuration error once the output recipe is accepted."""
    s = InSession("in_protocol_1", ["timestamp"], [REG3])
    s.up_to_recipe(protocol=1, controller=(3, 9, 1, 1), recipe_id=0)
    s.event("config", "INPUTS_PROTOCOL")
    s.package_check(0)
    s.add("ended")
    return s.end()


def in_init_errors():
    """Recipes init refuses: no session runs."""
    s = Session("in_init_errors", ["timestamp"])
    s.add("inputs_error NOT_WRITABLE output_int_register_24")
    s.add("inputs_error NOT_WRITABLE input_int_register_24,timestamp")
    s.add("inputs_error NOT_WRITABLE robot_status_bits")
    s.add("inputs_error DUPLICATE input_bit_register_64,input_int_register_1,input_bit_register_64")
    return s.end()  # (more than 64 registers: tests/lib/test_rtde_in.c's API test, a line too long here)


def input_sessions(rng):
    return ([in_registers(rng), in_edge_values(), in_three_recipes(), in_foreign(), in_reconnect(),
             in_protocol_1(), in_init_errors()] + in_reply_errors())


def check_sizes():
    """Own arithmetic of docs/rtde.md: the state recipe's data package."""
    size = 3 + 1 + sum(struct.calcsize(">" + TYPES[type_of(n)][0] * TYPES[type_of(n)][1])
                       for n in STATE_VARS)
    assert size == 904, size
    assert req_protocol(2) == bytes.fromhex("0005560002")
    assert req_setup(2, 125.0, ["timestamp", "actual_q"])[:11] == bytes.fromhex("001d4f405f400000000000")
    assert struct.pack(">d", 500.0) == bytes.fromhex("407f400000000000")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--corpus")
    ap.add_argument("--seed", type=int, default=0x27DE)
    ap.add_argument("--inputs", action="store_true", help="the sessions of a client writing input registers")
    args = ap.parse_args()
    check_sizes()
    rng = random.Random(args.seed)
    if args.inputs:
        write_inputs(args, rng)
        return
    sessions = good_sessions(rng) + error_sessions(rng)
    with open(args.out, "w") as f:
        for s in sessions:
            f.write("\n".join(s.lines) + "\n")
    if args.corpus:
        os.makedirs(args.corpus, exist_ok=True)
        n = 0
        for s in sessions:
            if s.names == FUZZ_VARS and s.stream:
                for mode in range(4):  # the harness's first byte: chunking
                    n += 1
                    with open(os.path.join(args.corpus, "seed%02d" % n), "wb") as f:
                        f.write(bytes([mode * 37]) + s.stream)
        # and short streams of every error, for the framer
        for s in sessions:
            if s.stream and s.names != FUZZ_VARS:
                n += 1
                with open(os.path.join(args.corpus, "seed%02d" % n), "wb") as f:
                    f.write(b"\x00" + s.stream)


def write_inputs(args, rng):
    sessions = input_sessions(rng)
    with open(args.out, "w") as f:
        for s in sessions:
            f.write("\n".join(s.lines) + "\n")
    if args.corpus:
        os.makedirs(args.corpus, exist_ok=True)
        n = 0
        for s in sessions:
            if not s.stream:
                continue
            fuzz = s.names == FUZZ_OUT_VARS and getattr(s, "recipes", None) and \
                s.recipes[0].names == FUZZ_IN_VARS
            for mode in range(4) if fuzz else range(1):  # the harness's first byte: chunking
                n += 1
                with open(os.path.join(args.corpus, "seed%02d" % n), "wb") as f:
                    f.write(bytes([mode * 37]) + s.stream)


if __name__ == "__main__":
    main()
