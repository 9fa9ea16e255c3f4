#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Independent reference for the Universal Robots RealTime packet layout.

Written from docs/sources.md (UR's RealTime table at 1116 bytes, as that
page records it, and what public sources add), NOT from lib/urrt.h: the
column tables below were typed from that page, so a mistake in the C field
table shows up as a disagreement instead of being copied into the
expectations.

It writes test vectors: packets with seeded values, and for each the decode
the library must produce (every field and element as raw IEEE-754 bits or
"absent", the generation, the extra-column count, the versions text, enum
names and digital I/O bit masks).

Output format (one record per vector, text, one item per line):
    vector NAME LENGTH GENERATION DOUBLES EXTRA VERSIONS...   (VERSIONS "-" = none)
    hex HEX-OF-THE-PACKET
    field NAME ELEMENT BITS16          (present field, per element)
    absent NAME                        (field not in a packet of this length)
    enum NAME ELEMENT ENUM_NAME        (coded fields only, when present)
    bits NAME MASK16 | bits NAME NOT_BITMASK
    end

Usage: urrt_ref.py --out vectors.txt [--corpus DIR] [--seed N]
Standard library only.
"""
import argparse
import math
import os
import random
import struct
import sys

# ---- the layouts --------------------------------------------------------

# 3.x/5.x grid: (name, element count, first column). Columns are UR's
# "Gnuplot col." (column 1 = time, the first double after the size). Rows
# 1-139 from UR's table at 1116 bytes and 140-152 from UR's 2021 document,
# both as docs/sources.md records them. UR's unnamed "used by Universal Robots software only" rows
# are kept as reserved_<first column>.
GRID_3X = [
    ("time", 1, 1),
    ("q_target", 6, 2),
    ("qd_target", 6, 8),
    ("qdd_target", 6, 14),
    ("i_target", 6, 20),
    ("m_target", 6, 26),
    ("q_actual", 6, 32),
    ("qd_actual", 6, 38),
    ("i_actual", 6, 44),
    ("i_control", 6, 50),
    ("tool_vector_actual", 6, 56),
    ("tcp_speed_actual", 6, 62),
    ("tcp_force", 6, 68),
    ("tool_vector_target", 6, 74),
    ("tcp_speed_target", 6, 80),
    ("digital_input_bits", 1, 86),
    ("motor_temperatures", 6, 87),
    ("controller_timer", 1, 93),
    ("test_value", 1, 94),
    ("robot_mode", 1, 95),
    ("joint_modes", 6, 96),
    ("safety_mode", 1, 102),
    ("reserved_103", 6, 103),
    ("tool_accelerometer", 3, 109),
    ("reserved_112", 6, 112),
    ("speed_scaling", 1, 118),
    ("linear_momentum_norm", 1, 119),
    ("reserved_120", 1, 120),
    ("reserved_121", 1, 121),
    ("v_main", 1, 122),
    ("v_robot", 1, 123),
    ("i_robot", 1, 124),
    ("v_actual", 6, 125),
    ("digital_outputs", 1, 131),
    ("program_state", 1, 132),
    ("elbow_position", 3, 133),
    ("elbow_velocity", 3, 136),
    ("safety_status", 1, 139),
    ("reserved_140", 3, 140),
    ("payload_mass", 1, 143),
    ("payload_cog", 3, 144),
    ("payload_inertia", 6, 147),
]
LAST_KNOWN_COLUMN = 152

# 1.x (CB1/CB2): docs/sources.md "1.x differences". Columns 1-49, 68-73 and
# 86-101 as in 3.x; 50-52 the tool accelerometer (1.7 and later), 53-67
# unused, 74-79 / 80-85 tool vector and TCP speed with UR's 1.x names
# (neither "actual" nor "target").
GRID_1X = [row for row in GRID_3X if row[2] + row[1] - 1 <= 49] + [
    ("tool_accelerometer", 3, 50),
    ("unused_53", 15, 53),
    ("tcp_force", 6, 68),
    ("tool_vector", 6, 74),
    ("tcp_speed", 6, 80),
    ("digital_input_bits", 1, 86),
    ("motor_temperatures", 6, 87),
    ("controller_timer", 1, 93),
    ("test_value", 1, 94),
    ("robot_mode", 1, 95),
    ("joint_modes", 6, 96),
]
# 1.5 (756 bytes, 94 doubles) decoders skip the accelerometer; it exists
# from 1.7 (764 bytes, 95 doubles).
ACCELEROMETER_1X_MIN_DOUBLES = 95
MAX_1X_DOUBLES = 101   # 812 bytes, 1.8
MIN_3X_DOUBLES = 130   # 1044 bytes, 3.0
# Columns that mean the same in both generations: what a packet of an
# ambiguous length (102..129 doubles) can be trusted to hold.
SHARED_COLUMNS = [(1, 49), (68, 73), (86, 101)]

GEN_UNKNOWN, GEN_1X, GEN_3X = 0, 1, 3

VERSIONS = {
    540: "early 1.x (before 1.5)",
    692: "early 1.x (before 1.5)",
    756: "1.5-1.6",
    764: "1.6-1.7",
    812: "1.8",
    1044: "3.0-3.1",
    1060: "3.2-3.4",
    1108: "3.5-3.9, 5.0-5.3",
    1116: "3.10-3.13, 5.4-5.8",
    1140: "3.14-3.15, 5.9",
    1220: "5.10 or later",
}

# Enumerations from docs/sources.md ("Enumerations").
ROBOT_MODE_3X = {-1: "NO_CONTROLLER", 0: "DISCONNECTED", 1: "CONFIRM_SAFETY", 2: "BOOTING",
                 3: "POWER_OFF", 4: "POWER_ON", 5: "IDLE", 6: "BACKDRIVE", 7: "RUNNING",
                 8: "UPDATING_FIRMWARE"}
ROBOT_MODE_1X = {0: "RUNNING", 1: "FREEDRIVE", 2: "READY", 3: "INITIALIZING",
                 4: "SECURITY_STOPPED", 5: "EMERGENCY_STOPPED", 6: "FATAL_ERROR", 7: "NO_POWER",
                 8: "NOT_CONNECTED", 9: "SHUTDOWN", 10: "SAFEGUARD_STOP"}
JOINT_MODE = dict(zip(range(235, 256), [
    "RESET", "SHUTTING_DOWN", "PART_D_CALIBRATION", "BACKDRIVE", "POWER_OFF",
    "READY_FOR_POWER_OFF", "CALVAL_INITIALIZATION", "ERROR", "FREEDRIVE", "SIMULATED",
    "NOT_RESPONDING", "MOTOR_INITIALISATION", "BOOTING", "PART_D_CALIBRATION_ERROR",
    "BOOTLOADER", "CALIBRATION", "VIOLATION", "FAULT", "RUNNING", "INITIALISATION", "IDLE"]))
SAFETY_MODE = dict(zip(range(1, 12), [
    "NORMAL", "REDUCED", "PROTECTIVE_STOP", "RECOVERY", "SAFEGUARD_STOP",
    "SYSTEM_EMERGENCY_STOP", "ROBOT_EMERGENCY_STOP", "VIOLATION", "FAULT",
    "VALIDATE_JOINT_ID", "UNDEFINED_SAFETY_MODE"]))
SAFETY_STATUS = dict(SAFETY_MODE)
SAFETY_STATUS.update({12: "AUTOMATIC_MODE_SAFEGUARD_STOP",
                      13: "SYSTEM_THREE_POSITION_ENABLING_STOP"})
PROGRAM_STATE = {0: "STOPPING", 1: "STOPPED", 2: "PLAYING", 3: "PAUSING", 4: "PAUSED",
                 5: "RESUMING"}
UNKNOWN_NAME = "UNKNOWN"


def enum_table(name, gen):
    """The numbering a coded field uses in a generation, or None."""
    if name == "robot_mode":
        # The two numberings are incompatible; an ambiguous length cannot
        # tell which one it carries, so it gets no name.
        return {GEN_1X: ROBOT_MODE_1X, GEN_3X: ROBOT_MODE_3X}.get(gen, {})
    return {"joint_modes": JOINT_MODE, "safety_mode": SAFETY_MODE,
            "safety_status": SAFETY_STATUS, "program_state": PROGRAM_STATE}.get(name)


BIT_FIELDS = ("digital_input_bits", "digital_outputs")


def self_check():
    """The typed tables must tile their grids exactly: a typo in a column or
    a count would leave a gap or an overlap."""
    for grid, last in ((GRID_3X, LAST_KNOWN_COLUMN), (GRID_1X, MAX_1X_DOUBLES)):
        col = 1
        for name, count, first in sorted(grid, key=lambda r: r[2]):
            assert first == col, (name, first, col)
            col += count
        assert col == last + 1, (col, last)
    # The seed's total: 139 doubles after the size in a 1116-byte packet,
    # ending with safety status at column 139.
    assert dict((n, c) for n, _, c in GRID_3X)["safety_status"] == (1116 - 4) // 8
    for length in VERSIONS:
        assert (length - 4) % 8 == 0


ALL_NAMES = []
for _n, _c, _f in GRID_3X + GRID_1X:
    if _n not in ALL_NAMES:
        ALL_NAMES.append(_n)


def generation(doubles):
    if doubles <= MAX_1X_DOUBLES:
        return GEN_1X
    if doubles >= MIN_3X_DOUBLES:
        return GEN_3X
    return GEN_UNKNOWN


def layout(doubles):
    """(name -> (count, first column)) of the fields a packet of this many
    doubles holds whole. A field cut by the end of the packet is absent."""
    gen = generation(doubles)
    if gen == GEN_1X:
        rows = GRID_1X
    elif gen == GEN_3X:
        rows = GRID_3X
    else:
        rows = [r for r in GRID_3X
                if any(lo <= r[2] and r[2] + r[1] - 1 <= hi for lo, hi in SHARED_COLUMNS)]
    out = {}
    for name, count, first in rows:
        if first + count - 1 > doubles:
            continue
        if gen == GEN_1X and name == "tool_accelerometer" and doubles < ACCELEROMETER_1X_MIN_DOUBLES:
            continue
        out[name] = (count, first)
    return out


# ---- values -------------------------------------------------------------

def bits_of(x):
    return struct.unpack(">Q", struct.pack(">d", x))[0]


def double_of(bits):
    return struct.unpack(">d", struct.pack(">Q", bits))[0]


SPECIAL_BITS = [
    0x7FF8000000000000,  # the default quiet NaN
    0x7FF8DEADBEEF0001,  # quiet NaN with a payload
    0x7FF0000000000001,  # signalling NaN
    0xFFF400000000BEEF,  # negative signalling NaN with a payload
    0x7FF0000000000000,  # +inf
    0xFFF0000000000000,  # -inf
    0x8000000000000000,  # -0.0
    0x0000000000000001,  # smallest subnormal
    0x000FFFFFFFFFFFFF,  # largest subnormal
    0x8000000000000001,  # negative subnormal
    0x7FEFFFFFFFFFFFFF,  # DBL_MAX
    0x0010000000000000,  # DBL_MIN
    0x3FEF000000000000,  # 0.96875: the classic 0x3FEF0000 "length" of a desynced reader
]


def enum_candidates(table):
    known = sorted(table) if table else [0]
    return known + [min(known) - 1, max(known) + 1, 1000, -7]


def coded_value_bits(rng, name, gen):
    """A value for an enum column: mostly listed numbers, sometimes numbers
    no table lists, fractions, NaN or infinities."""
    table = enum_table(name, gen) or enum_table(name, GEN_3X)
    r = rng.random()
    if r < 0.6:
        return bits_of(float(rng.choice(sorted(table))))
    if r < 0.75:
        return bits_of(float(rng.choice(enum_candidates(table))))
    if r < 0.85:
        return bits_of(rng.choice(sorted(table)) + 0.5)
    if r < 0.9:
        return bits_of(-0.0)
    return rng.choice(SPECIAL_BITS[:6])


def mask_value_bits(rng, raw_int64):
    """Digital I/O: UR sends a double holding the integer mask; some
    controllers/decoders use the raw big-endian int64. Sometimes a value that
    is neither."""
    r = rng.random()
    mask = rng.getrandbits(rng.choice((4, 8, 18, 32)))
    if r < 0.85:
        return mask if raw_int64 else bits_of(float(mask))
    return rng.choice([bits_of(-1.0), bits_of(0.5), bits_of(-0.0), 0x7FF8000000000000,
                       0x7FF0000000000000, bits_of(float(2 ** 53)), bits_of(float(2 ** 53 + 2)),
                       0x8000000000000005])


def plain_value_bits(rng, special_rate):
    if rng.random() < special_rate:
        return rng.choice(SPECIAL_BITS)
    scale = 10.0 ** rng.randint(-6, 4)
    return bits_of(rng.uniform(-1.0, 1.0) * scale)


def make_columns(rng, doubles, raw_int64, special_rate):
    gen = generation(doubles)
    # Coded columns get coded values where this generation has them; the
    # ambiguous lengths use the 3.x places so that both kinds get exercised.
    coded = {}
    for name, (count, first) in layout(max(doubles, MIN_3X_DOUBLES) if gen != GEN_1X else doubles).items():
        if enum_table(name, GEN_3X) is not None or name in BIT_FIELDS:
            coded.update({first + i: name for i in range(count)})
    cols = []
    for c in range(1, doubles + 1):
        name = coded.get(c)
        if name in BIT_FIELDS:
            cols.append(mask_value_bits(rng, raw_int64))
        elif name is not None:
            cols.append(coded_value_bits(rng, name, gen))
        else:
            cols.append(plain_value_bits(rng, special_rate))
    return cols


def expected_mask(bits):
    """The integer bit mask of a digital I/O value, or None."""
    if bits >> 52 == 0:
        return bits  # sign and exponent clear: a raw int64 seen as a subnormal (or +0)
    x = double_of(bits)
    if math.isnan(x) or math.isinf(x) or x != math.floor(x):
        return None
    if x == 0:
        return 0  # -0.0
    if x < 0 or x > 2.0 ** 53:
        return None
    return int(x)


def expected_enum(name, gen, bits):
    table = enum_table(name, gen)
    x = double_of(bits)
    if not table or math.isnan(x) or math.isinf(x) or x != math.floor(x):
        return UNKNOWN_NAME
    return table.get(int(x), UNKNOWN_NAME)


# ---- output -------------------------------------------------------------

def packet_bytes(length, cols):
    return struct.pack(">i", length) + b"".join(struct.pack(">Q", b) for b in cols)


def write_vector(out, name, cols):
    doubles = len(cols)
    length = 4 + 8 * doubles
    gen = generation(doubles)
    extra = doubles - LAST_KNOWN_COLUMN if gen == GEN_3X and doubles > LAST_KNOWN_COLUMN else 0
    out.write("vector %s %d %d %d %d %s\n" % (name, length, gen, doubles, extra,
                                            VERSIONS.get(length, "-")))
    out.write("hex %s\n" % packet_bytes(length, cols).hex())
    lay = layout(doubles)
    for fname in ALL_NAMES:
        if fname not in lay:
            out.write("absent %s\n" % fname)
            continue
        count, first = lay[fname]
        for i in range(count):
            bits = cols[first - 1 + i]
            out.write("field %s %d %016x\n" % (fname, i, bits))
            if enum_table(fname, GEN_3X) is not None:
                out.write("enum %s %d %s\n" % (fname, i, expected_enum(fname, gen, bits)))
        if fname in BIT_FIELDS:
            mask = expected_mask(cols[first - 1])
            out.write("bits %s %s\n" % (fname, "NOT_BITMASK" if mask is None else "%016x" % mask))
    out.write("end\n")


def capture_columns(rng, time):
    """The 1.8 packet of docs/sources.md "The CB2 1.8 capture" (values the
    page does not give are seeded)."""
    cols = make_columns(rng, MAX_1X_DOUBLES, False, 0.0)
    lay = layout(MAX_1X_DOUBLES)

    def put(name, values):
        count, first = lay[name]
        assert len(values) == count
        for i, v in enumerate(values):
            cols[first - 1 + i] = bits_of(v)
    put("time", [time])
    put("robot_mode", [0.0])
    put("joint_modes", [253.0] * 6)
    put("tool_accelerometer", [-0.138, -2.805, 8.385])
    put("motor_temperatures", [24.2, 25.1, 26.4, 27.0, 28.3, 29.0])
    put("digital_input_bits", [5.0])
    return cols


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="vector file to write")
    ap.add_argument("--corpus", help="directory for a libFuzzer seed corpus")
    ap.add_argument("--seed", type=int, default=0x5EED)
    ap.add_argument("--max-doubles", type=int, default=256,
                    help="largest packet to generate (the library's default URRT_MAX_DOUBLES)")
    args = ap.parse_args()
    self_check()

    vectors = []  # (name, columns)
    # Every known length, with the special values forced in round robin so
    # that each kind of NaN/inf/subnormal lands in every vector.
    named = [(540, "early"), (692, "early"), (756, "v1_5"), (764, "v1_7"),
             (812, "v1_8"), (1044, "v3_0"), (1060, "v3_2"), (1108, "v3_5"), (1116, "v3_10"),
             (1140, "v3_14"), (1220, "v5_10"), (868, "ambiguous"), (1236, "future"),
             (1628, "future")]
    for index, (length, label) in enumerate(named):
        rng = random.Random(args.seed * 1000003 + length)
        doubles = (length - 4) // 8
        cols = make_columns(rng, doubles, raw_int64=index % 2 == 1, special_rate=0.15)
        lay = layout(doubles)
        plain = [c for c in range(1, doubles + 1)
                 if not any(f <= c < f + n for name, (n, f) in lay.items()
                            if name in BIT_FIELDS or enum_table(name, GEN_3X) is not None)]
        for i, bits in enumerate(SPECIAL_BITS):
            cols[plain[(7 * i + index) % len(plain)] - 1] = bits
        vectors.append(("%s_%d" % (label, length), cols))
    # Both I/O encodings of the same mask at the same length.
    for raw in (False, True):
        rng = random.Random(args.seed + 77)
        cols = make_columns(rng, (1220 - 4) // 8, raw_int64=raw, special_rate=0.0)
        lay = layout(152)
        cols[lay["digital_input_bits"][1] - 1] = 0x25 if raw else bits_of(37.0)
        cols[lay["digital_outputs"][1] - 1] = 0x3FFFF if raw else bits_of(float(0x3FFFF))
        vectors.append(("io_%s_1220" % ("int64" if raw else "double"), cols))
    # The real 1.8 capture and the packet after it.
    vectors.append(("capture_1_8", capture_columns(random.Random(args.seed + 18), 951.592)))
    vectors.append(("capture_1_8_next", capture_columns(random.Random(args.seed + 19), 951.600)))
    # Every length the library accepts, so that presence is checked at each
    # cut of every field.
    for doubles in range(1, args.max_doubles + 1):
        rng = random.Random(args.seed * 7919 + doubles)
        vectors.append(("len_%d" % (4 + 8 * doubles),
                        make_columns(rng, doubles, raw_int64=doubles % 2 == 1, special_rate=0.05)))

    tmp = args.out + ".tmp"
    with open(tmp, "w") as out:
        out.write("# urrt reference vectors: generated by tests/ref/urrt_ref.py --seed %d\n" % args.seed)
        for name, cols in vectors:
            write_vector(out, name, cols)
    os.replace(tmp, args.out)

    if args.corpus:
        # libFuzzer seeds in the harness's input format: one byte choosing the
        # chunking, then the stream (two packets back to back, and variants).
        os.makedirs(args.corpus, exist_ok=True)
        by_name = dict(vectors)
        for i, (name, _) in enumerate(vectors[:len(named) + 4]):
            doubles = len(by_name[name])
            pkt = packet_bytes(4 + 8 * doubles, by_name[name])
            seeds = [pkt + pkt, b"\xff\x00\x13" + pkt + pkt[:100] + pkt,
                     pkt[: len(pkt) // 2] + pkt + pkt]
            for j, stream in enumerate(seeds):
                with open(os.path.join(args.corpus, "%s_%d" % (name, j)), "wb") as f:
                    f.write(bytes([(i * 37 + j * 11) & 0xFF]) + stream)
    return 0


if __name__ == "__main__":
    sys.exit(main())
