#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-can-scale: lib/urrt_can's integer scaling against exact rational
arithmetic (fractions.Fraction).

For each signal kind below (signed and unsigned lengths; factors 0.001,
0.01, 1/3-ish, powers of two, 1, large and tiny, negative; offsets zero and
not; limits narrower than the raw type) it draws VALUES values: the limits,
+-0, NaN, infinities, subnormals, exact ties (values whose exact quotient
(value - offset) / factor is n + 1/2) and the values one ulp either side of
each tie and limit, then uniform, log-uniform and random-bit values. The
reference is the contract of lib/urrt_can.h: clamp to [min, max] (NaN:
invalid_raw, or physical 0 clamped), then (value - offset) / factor on the
doubles' exact values rounded half away from zero, clamped to the raw type.

Usage: can_scale_ref.py WORKDIR [--values N] [--host CMD]... [--target CMD]...
  --host CMD    runs `CMD CASES OUT` (tests/lib/can_scale_driver.c built for
                this machine): every value must match, and the driver's three
                paths (prepared, unprepared, packed into a frame) agree
  --target CMD  runs CMD with {cases} replaced by the case file (the driver on
                an emulated core): its per-kind digests must be the reference's
Each differing value is named with its class and exact quotient. Also says,
for information, how many values today's double arithmetic ((v - offset) /
factor rounded twice) would have got wrong. Last line: "N passed, N failed".
"""
import math
import os
import random
import re
import shlex
import struct
import subprocess
import sys
import time
from array import array
from fractions import Fraction

UNSIGNED, SIGNED = 0, 1
INVALID_RAW = 0x01
OK, SATURATED, NAN = 0, 1, 2
DISAGREE = 0x100
DBL_MAX = sys.float_info.max
HEADER_WORDS = 7
FNV_OFFSET, FNV_PRIME = 0xCBF29CE484222325, 0x100000001B3
MASK64 = (1 << 64) - 1

# name, type, length, factor, offset, (min, max) or None for the raw type's range, flags, invalid_raw
KINDS = [
    ("joint s16 x0.0002", SIGNED, 16, 0.0002, 0.0, None, 0, 0),
    ("s16 x0.001", SIGNED, 16, 0.001, 0.0, None, 0, 0),
    ("temperature u16 x0.01 -40", UNSIGNED, 16, 0.01, -40.0, None, 0, 0),
    ("s32 x1/3", SIGNED, 32, 1.0 / 3.0, 0.0, None, 0, 0),
    ("u8 x1/3 +0.5", UNSIGNED, 8, 1.0 / 3.0, 0.5, None, 0, 0),
    ("s12 x0.125", SIGNED, 12, 0.125, 0.0, None, 0, 0),
    ("s12 x0.125 +0.0625", SIGNED, 12, 0.125, 0.0625, None, 0, 0),
    ("u64 x1", UNSIGNED, 64, 1.0, 0.0, None, 0, 0),
    ("s64 x1", SIGNED, 64, 1.0, 0.0, None, 0, 0),
    ("u1 x1 (validity bit)", UNSIGNED, 1, 1.0, 0.0, None, 0, 0),
    ("u4 x1 (alive counter)", UNSIGNED, 4, 1.0, 0.0, None, 0, 0),
    ("s64 x2^-20 +1e6", SIGNED, 64, 2.0 ** -20, 1e6, None, 0, 0),
    ("u32 x1e10 (large)", UNSIGNED, 32, 1e10, 0.0, None, 0, 0),
    ("s24 x1e-300 (tiny)", SIGNED, 24, 1e-300, 0.0, None, 0, 0),
    ("s16 x5e-324 (subnormal factor)", SIGNED, 16, 5e-324, 0.0, None, 0, 0),
    ("s8 x-0.5 +3 (negative factor)", SIGNED, 8, -0.5, 3.0, None, 0, 0),
    ("s53 x0.1 +0.001", SIGNED, 53, 0.1, 0.001, None, 0, 0),
    ("u57 x3e-5 -123.456", UNSIGNED, 57, 3e-5, -123.456, None, 0, 0),
    ("s40 x1e300 -1e308", SIGNED, 40, 1e300, -1e308, None, 0, 0),
    ("s16 x0.01 +10, limits -100..200, invalid raw", SIGNED, 16, 0.01, 10.0, (-100.0, 200.0), INVALID_RAW, 0x8000),
    ("u16 x0.001 +1e20 (cancellation)", UNSIGNED, 16, 0.001, 1e20, None, 0, 0),
    ("s64 x1e-30 +1 (huge quotients)", SIGNED, 64, 1e-30, 1.0, None, 0, 0),
    ("s64 x1/3 +1e-300 (offset far below the value's last bit)", SIGNED, 64, 1.0 / 3.0, 1e-300, None, 0, 0),
    ("s32 x7", SIGNED, 32, 7.0, 0.0, None, 0, 0),
    ("u64 x3 +2^60", UNSIGNED, 64, 3.0, 2.0 ** 60, None, 0, 0),
    ("s16 x-0.0002 -1e-310, limits -0..1", SIGNED, 16, -0.0002, -1e-310, (-0.0, 1.0), 0, 0),
]


def bits(x):
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def from_bits(b):
    return struct.unpack("<d", struct.pack("<Q", b))[0]


def raw_range(typ, length):
    if typ == UNSIGNED:
        return 0, (1 << length) - 1
    return -(1 << (length - 1)), (1 << (length - 1)) - 1


def signal_range(typ, length, factor, offset):
    """urrt_can_signal_range: the raw type's limits scaled, in double."""
    lo, hi = raw_range(typ, length)
    a, b = float(lo) * factor + offset, float(hi) * factor + offset
    a, b = min(a, b), max(a, b)
    return max(a, -DBL_MAX), min(b, DBL_MAX)


class Kind:
    def __init__(self, spec):
        self.name, self.type, self.length, self.factor, self.offset, limits, self.flags, self.invalid_raw = spec
        self.min, self.max = limits or signal_range(self.type, self.length, self.factor, self.offset)
        self.raw_lo, self.raw_hi = raw_range(self.type, self.length)
        self.f, self.o = Fraction(self.factor), Fraction(self.offset)

    def quotient(self, x):
        return (Fraction(x) - self.o) / self.f

    def reference(self, v):
        """(raw, outcome) by the contract, exactly."""
        outcome = OK
        if math.isnan(v):
            if self.flags & INVALID_RAW:
                return self.invalid_raw, NAN
            v, outcome = (self.min if 0.0 < self.min else self.max if 0.0 > self.max else 0.0), NAN
        elif v < self.min:
            v, outcome = self.min, SATURATED
        elif v > self.max:
            v, outcome = self.max, SATURATED
        q = self.quotient(v)
        n = math.floor(abs(q) + Fraction(1, 2))
        n = -n if q < 0 else n
        if not self.raw_lo <= n <= self.raw_hi:
            n, outcome = min(max(n, self.raw_lo), self.raw_hi), max(outcome, SATURATED)
        return n & ((1 << self.length) - 1), outcome

    def double_rounded(self, v):
        """The raw value of today's double arithmetic, (v - offset) / factor
        rounded to a double (twice) and then half away from zero; None where
        it does not apply (NaN, clamped values)."""
        if math.isnan(v) or not self.min <= v <= self.max:
            return None
        s = (v - self.offset) / self.factor
        if math.isinf(s):
            return None
        t = float(math.trunc(s))
        if abs(s) < 2.0 ** 52:
            t += 1.0 if s - t >= 0.5 else -1.0 if s - t <= -0.5 else 0.0
        n = min(max(int(t), self.raw_lo), self.raw_hi)
        return n & ((1 << self.length) - 1)


def around(x):
    """x and the doubles one ulp either side."""
    return [x, math.nextafter(x, -math.inf), math.nextafter(x, math.inf)]


def physical(kind, q):
    """The double nearest offset + q * factor (q a Fraction), and whether it
    is exactly that value."""
    t = kind.o + q * kind.f
    try:
        x = float(t)
    except OverflowError:
        return None, False
    return x, not math.isinf(x) and Fraction(x) == t


def draw(kind, rng, count):
    """count values, each with its class, edge cases first."""
    values = []

    def add(cls, xs):
        values.extend((cls, x) for x in xs if x is not None)

    add("special", [0.0, -0.0, math.nan, from_bits(0xFFF8000000000001), math.inf, -math.inf, 5e-324, -5e-324,
                    2.2250738585072014e-308, -2.2250738585072014e-308, DBL_MAX, -DBL_MAX])
    add("limit or offset +-1 ulp", around(kind.min) + around(kind.max) + around(kind.offset))
    edges = [kind.raw_lo, kind.raw_hi, 0, 1, -1, kind.raw_lo + 1, kind.raw_hi - 1]
    for n in edges:
        for q in (Fraction(n), Fraction(2 * n + 1, 2), Fraction(2 * n - 1, 2)):
            x, exact = physical(kind, q)
            if x is not None and not math.isinf(x):
                add("tie" if exact and q.denominator == 2 else "raw limit +-1 ulp", around(x))
    while len(values) < count:
        r = rng.random()
        if r < 0.35:  # ties: exact where the double exists, else the nearest and its neighbours
            span = min(kind.raw_hi - kind.raw_lo, 1 << rng.choice((4, 12, 24, 52, 64)))
            n = kind.raw_lo + rng.randrange(span + 1) if rng.random() < 0.5 else rng.randrange(-span, span + 1)
            x, exact = physical(kind, Fraction(2 * n + 1, 2))
            if x is not None and not math.isinf(x):
                add("tie" if exact else "near tie", around(x))
        elif r < 0.65:
            add("uniform in [min, max]", [rng.uniform(kind.min, kind.max)])
        elif r < 0.85:
            scale = abs(kind.factor) * 2.0 ** rng.uniform(-8, min(kind.length + 8, 1000))
            if not math.isinf(scale):
                add("log-uniform", [math.copysign(scale * rng.random(), rng.random() - 0.5) + kind.offset])
        else:
            add("random bits", [from_bits(rng.getrandbits(64))])
    return values[:count]


def write_cases(path, kinds, draws):
    words = array("Q")
    for kind, values in zip(kinds, draws):
        words.extend([kind.type | kind.length << 8 | kind.flags << 16, bits(kind.factor), bits(kind.offset),
                      bits(kind.min), bits(kind.max), kind.invalid_raw, len(values)])
        words.extend(bits(v) for _, v in values)
    if sys.byteorder != "little":
        words.byteswap()
    with open(path, "wb") as f:
        words.tofile(f)


def read_results(path):
    words = array("Q")
    with open(path, "rb") as f:
        words.frombytes(f.read())
    if sys.byteorder != "little":
        words.byteswap()
    return words


def digest(ref):
    """FNV-1a over the words (raw, outcome) of every value, a word at a time."""
    h = FNV_OFFSET
    for raw, outcome in ref:
        h = ((((h ^ raw) * FNV_PRIME) & MASK64 ^ outcome) * FNV_PRIME) & MASK64
    return h


def show(q):
    try:
        return "%.6f" % float(q)
    except OverflowError:
        return "about 10^%d" % (len(str(abs(q.numerator // q.denominator))) - 1)


def describe(kind, cls, v):
    if math.isnan(v):
        return "NaN (%s)" % cls
    q = kind.quotient(v) if math.isfinite(v) else None
    return "%r (bits %016x, %s; exact quotient %s)" % (
        v, bits(v), cls, "n/a" if q is None else show(q) + (" = n + 1/2 exactly" if q.denominator == 2 else ""))


def check_host(cmd, cases, out, kinds, draws, refs, result):
    run = subprocess.run(shlex.split(cmd) + [cases, out], capture_output=True, text=True)
    if run.returncode != 0:
        result(False, "%s exited %d: %s" % (cmd, run.returncode, run.stderr.strip()))
        return
    got = read_results(out)
    at = 0
    for kind, values, ref in zip(kinds, draws, refs):
        bad = 0
        for (cls, v), (raw, outcome) in zip(values, ref):
            g_raw, g_outcome = got[at], got[at + 1]
            at += 2
            ok = g_raw == raw and g_outcome == outcome
            if not ok and bad < 5:
                why = "the prepared, unprepared and packed paths disagree" if g_outcome & DISAGREE else \
                      "raw %d (outcome %d), exact %d (outcome %d)" % (g_raw, g_outcome & 0xFF, raw, outcome)
                print("FAIL: %s: %s: value %s: %s" % (os.path.basename(cmd.split()[0]), kind.name,
                                                      describe(kind, cls, v), why))
            bad += not ok
        result.add(len(values) - bad, bad)


def check_target(cmd, cases, kinds, wanted, result):
    run = subprocess.run(cmd.replace("{cases}", cases), shell=True, capture_output=True, text=True, timeout=900)
    digests = dict((int(k), int(d, 16))
                   for k, d in re.findall(r"^kind (\d+) digest ([0-9a-f]+)$", run.stdout + run.stderr, re.M))
    for i, (kind, h) in enumerate(zip(kinds, wanted)):
        result(digests.get(i) == h, "%s: %s: the emulated core's results differ from the exact ones (digest %s, "
               "want %016x; exit %d %s)" % (cmd.split()[0], kind.name, "%016x" % digests[i] if i in digests
                                           else "missing", h, run.returncode, run.stderr.strip()[-200:]))


class Result:
    def __init__(self):
        self.passed = self.failed = 0

    def add(self, passed, failed):
        self.passed += passed
        self.failed += failed

    def __call__(self, ok, text):
        self.add(int(ok), int(not ok))
        if not ok:
            print("FAIL: " + text)


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        return 2
    work, hosts, targets, count = args[0], [], [], 100000
    rest = args[1:]
    while rest:
        opt, value, rest = rest[0], rest[1], rest[2:]
        if opt == "--host":
            hosts.append(value)
        elif opt == "--target":
            targets.append(value)
        elif opt == "--values":
            count = int(value)
        else:
            print("can_scale_ref.py: unknown option %s (see --help in the script's docstring)" % opt)
            return 2
    os.makedirs(work, exist_ok=True)
    rng = random.Random(20240519)
    kinds = [Kind(k) for k in KINDS]
    draws = [draw(k, rng, count) for k in kinds]
    refs = [[k.reference(v) for _, v in values] for k, values in zip(kinds, draws)]
    cases = os.path.join(work, "cases.bin")
    write_cases(cases, kinds, draws)
    for kind, values, ref in zip(kinds, draws, refs):
        ties = sum(1 for cls, _ in values if cls == "tie")
        wrong = [(cls, v) for (cls, v), (raw, _) in zip(values, ref)
                 if kind.double_rounded(v) not in (None, raw)]
        print("%s: %d values, %d exact ties; double arithmetic would get %d wrong%s" % (
            kind.name, len(values), ties, len(wrong),
            " (e.g. %s)" % describe(kind, *wrong[0]) if wrong else ""))
    result = Result()
    for i, cmd in enumerate(hosts):
        start = time.time()
        check_host(cmd, cases, os.path.join(work, "results%d.bin" % i), kinds, draws, refs, result)
        print("%s: %.1f s" % (cmd, time.time() - start))
    wanted = [digest(ref) for ref in refs] if targets else []
    for cmd in targets:
        start = time.time()
        check_target(cmd, cases, kinds, wanted, result)
        print("%s: %.1f s" % (cmd.split(" -kernel ")[-1], time.time() - start))
    print("%d passed, %d failed" % (result.passed, result.failed))
    return 0 if result.failed == 0 and result.passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
