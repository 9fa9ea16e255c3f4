# SPDX-License-Identifier: MIT
"""eds.py: reads an EDS (CiA 306) as the test master and the EDS checker need it.

Written from CiA 306 and CiA 301, not from the node's code: an INI file with one
section per object ([1018]) and per sub-index ([1018sub1]); DataType numbers as CiA
301 gives them; DefaultValue may be "$NODEID+0x180" (or "0x180+$NODEID").
"""
import configparser
import re
import struct

# CiA 301 data types: number -> (name, size in bytes (0: variable), struct format or None)
DATA_TYPES = {
    0x0001: ('BOOLEAN', 1, '<B'),
    0x0002: ('INTEGER8', 1, '<b'),
    0x0003: ('INTEGER16', 2, '<h'),
    0x0004: ('INTEGER32', 4, '<i'),
    0x0005: ('UNSIGNED8', 1, '<B'),
    0x0006: ('UNSIGNED16', 2, '<H'),
    0x0007: ('UNSIGNED32', 4, '<I'),
    0x0008: ('REAL32', 4, '<f'),
    0x0009: ('VISIBLE_STRING', 0, None),
    0x000A: ('OCTET_STRING', 0, None),
    0x000B: ('UNICODE_STRING', 0, None),
    0x0011: ('REAL64', 8, '<d'),
    0x0015: ('INTEGER64', 8, '<q'),
    0x001B: ('UNSIGNED64', 8, '<Q'),
}
SIGNED = {0x0002, 0x0003, 0x0004, 0x0015}
OBJECT_TYPES = {0x7: 'VAR', 0x8: 'ARRAY', 0x9: 'RECORD'}
ACCESS_TYPES = {'ro', 'wo', 'rw', 'rwr', 'rww', 'const'}
OBJECT_SECTION = re.compile(r'^([0-9A-Fa-f]{4})(?:sub([0-9A-Fa-f]{1,2}))?$')
NODEID = re.compile(r'\$NODEID', re.IGNORECASE)


def parse_int(text):
    """An EDS integer: decimal, 0x hex or 0 octal, as CiA 306 allows."""
    text = text.strip()
    if text.lower().startswith('0x'):
        return int(text, 16)
    if len(text) > 1 and text.startswith('0') and text.isdigit():
        return int(text, 8)
    return int(text, 10)


def resolve(text, node_id):
    """A DefaultValue with $NODEID as a number for this node: "$NODEID+0x180",
    "0x180+$NODEID", "$NODEID"."""
    parts = [p.strip() for p in text.split('+')]
    total = 0
    for p in parts:
        total += node_id if NODEID.fullmatch(p) else parse_int(p)
    return total


def read(path):
    """The EDS as a ConfigParser with case-sensitive keys, strict about duplicates."""
    cp = configparser.ConfigParser(interpolation=None, strict=True, delimiters=('=',),
                                   comment_prefixes=(';',), inline_comment_prefixes=None)
    cp.optionxform = str
    with open(path, encoding='latin-1') as f:
        cp.read_file(f)
    return cp


def objects(cp):
    """{(index, sub): section} for every object section; a VAR without sub-indices is
    (index, 0) from its [XXXX] section; a RECORD/ARRAY's own section is (index, None)."""
    out = {}
    for name in cp.sections():
        m = OBJECT_SECTION.match(name)
        if not m:
            continue
        index = int(m.group(1), 16)
        sub = int(m.group(2), 16) if m.group(2) is not None else None
        sec = cp[name]
        if sub is None and parse_int(sec.get('ObjectType', '0x7')) == 0x7:
            sub = 0
        out[(index, sub)] = sec
    return out


def listed(cp):
    """Indices the three object lists name, in order, per list."""
    lists = {}
    for name in ('MandatoryObjects', 'OptionalObjects', 'ManufacturerObjects'):
        sec = cp[name] if cp.has_section(name) else {}
        count = parse_int(sec.get('SupportedObjects', '0'))
        lists[name] = [parse_int(sec[str(i)]) for i in range(1, count + 1) if str(i) in sec]
    return lists


def variables(cp, node_id):
    """Every readable or writable variable: [(index, sub, name, type, access, default)],
    default resolved (None for strings and missing values)."""
    out = []
    for (index, sub), sec in sorted(objects(cp).items(), key=lambda kv: (kv[0][0], kv[0][1] or -1)):
        if sub is None:
            continue
        dtype = parse_int(sec.get('DataType', '0'))
        default = sec.get('DefaultValue', '').strip()
        value = None
        if default and DATA_TYPES.get(dtype, ('', 0))[1] and dtype not in (0x0008, 0x0011):
            value = resolve(default, node_id)
        out.append((index, sub, sec.get('ParameterName', ''), dtype, sec.get('AccessType', '').strip().lower(),
                    value if value is not None else default))
    return out


def _pdos(cp, node_id, comm_base, map_base):
    """The PDOs whose communication (comm_base + n) and mapping (map_base + n) objects
    the EDS has: [{'n': 1.., 'cob_id', 'type', 'event_ms', 'mapping': [(index, sub, bits)]}]."""
    objs = objects(cp)
    out = []
    for n in range(512):
        comm, mapping = comm_base + n, map_base + n
        if (comm, 1) not in objs or (mapping, 0) not in objs:
            continue

        def value(index, sub, default=0):
            sec = objs.get((index, sub))
            return resolve(sec['DefaultValue'], node_id) if sec is not None and 'DefaultValue' in sec else default
        entries = []
        for k in range(1, value(mapping, 0) + 1):
            raw = value(mapping, k)
            entries.append((raw >> 16, (raw >> 8) & 0xFF, raw & 0xFF))
        out.append({'n': n + 1, 'cob_id': value(comm, 1), 'type': value(comm, 2),
                    'event_ms': value(comm, 5), 'mapping': entries})
    return out


def tpdos(cp, node_id):
    """The TPDOs: [{'n': 1.., 'cob_id', 'type', 'event_ms', 'mapping': [(index, sub, bits)]}]."""
    return _pdos(cp, node_id, 0x1800, 0x1A00)


def rpdos(cp, node_id):
    """The RPDOs (0x1400+n, 0x1600+n), as tpdos gives the TPDOs: what a manager sends
    the node, its COB-ID (cob_id & 0x7FF while bit 31 is clear) and its mapping."""
    return _pdos(cp, node_id, 0x1400, 0x1600)


def decode(data, mapping, objs):
    """A TPDO's bytes by its mapping: [(index, sub, start_bit, bits, raw value)], Intel
    order from bit 0; dummy entries (index < 0x1000: a data type) are skipped."""
    bits_all = int.from_bytes(bytes(data), 'little')
    out, pos = [], 0
    for index, sub, bits in mapping:
        raw = (bits_all >> pos) & ((1 << bits) - 1)
        if index >= 0x1000:
            sec = objs.get((index, sub))
            dtype = parse_int(sec.get('DataType', '0')) if sec is not None else 0
            if dtype == 0x0008 and bits == 32:
                raw = struct.unpack('<f', raw.to_bytes(4, 'little'))[0]
            elif dtype in SIGNED and raw >> (bits - 1):
                raw -= 1 << bits
            out.append((index, sub, pos, bits, raw))
        pos += bits
    return out


def encode(values, mapping):
    """An RPDO's bytes from its mapping: values {(index, sub): raw} (a negative raw as
    two's complement of the entry's bits, a missing one 0), dummy entries 0; Intel order
    from bit 0, as decode reads a TPDO."""
    total, pos = 0, 0
    for index, sub, bits in mapping:
        raw = values.get((index, sub), 0) if index >= 0x1000 else 0
        total |= (raw & ((1 << bits) - 1)) << pos
        pos += bits
    return total.to_bytes((pos + 7) // 8, 'little')
