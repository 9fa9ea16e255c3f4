# SPDX-License-Identifier: MIT
"""eds_check.py EDS [NODE_ID]: checks an EDS against CiA 306's rules, independently of
the code that wrote it. Prints each problem and "N passed, N failed" last.

Rules: the sections [FileInfo], [DeviceInfo], [MandatoryObjects], [OptionalObjects],
[ManufacturerObjects]; each list's SupportedObjects equals its entries 1..n, each entry
has its object section, no object is listed twice or left unlisted, mandatory ones
(0x1000, 0x1001, 0x1018) are in MandatoryObjects and optional/manufacturer ones in the
right range; ObjectType, DataType, AccessType, PDOMapping take legal values; a RECORD
or ARRAY has SubNumber sections [XXXXsubN], sub 0 among them; every DefaultValue
parses for its type ($NODEID forms included); 0x1017 is there (no node guarding);
each TPDO mapping (0x1A00+n) names existing objects marked PDOMapping=1 whose size
matches the bit length, fits 64 bits, and has its communication object 0x1800+n;
NrOfTXPDO equals the number of TPDOs and NrOfRXPDO the RPDOs; [FileInfo] FileName is the
file's own name, CreationTime/ModificationTime "hh:mm" + AM/PM and CreationDate/
ModificationDate "mm-dd-yyyy"; a LowLimit/HighLimit pair parses, is ordered and holds the
DefaultValue; every TPDO COB-ID (0x18xx sub 1) has bit 30 set (no RTR: the node serves
none); an object mapped from a bit-mask field (unit "bits" in lib/urrt.h's field table)
carries no LowLimit/HighLimit and its [Comments] line no limits.

The receiving side (CiA 301, CiA 306): each RPDO mapping (0x1600+n) names existing
objects marked PDOMapping=1 and writable (rww, rw or wo) whose size matches the bit
length, or a dummy of a known type, fits 64 bits, and has its communication object
0x1400+n; a PDO mapping's sub 0 is the number of its entries; every RPDO COB-ID (0x14xx
sub 1) is an 11-bit one with bit 29 clear, and no two valid RPDOs share one; AccessType
rww or rwr only on a PDO-mappable object (PDOMapping=1); 0x1016 (consumer heartbeat) is
an ARRAY of UNSIGNED32 whose sub 0 is its number of entries; LowLimit and HighLimit are
values of the object's DataType.
"""
import os
import re
import struct
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import eds  # noqa: E402

MANDATORY = {0x1000, 0x1001, 0x1018}
URRT_H = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'lib', 'urrt.h')
TIME = re.compile(r'(0[1-9]|1[0-2]):[0-5][0-9](AM|PM)')
DATE = re.compile(r'(0[1-9]|1[0-2])-(0[1-9]|[12][0-9]|3[01])-[0-9]{4}')


def mask_fields():
    """The field names lib/urrt.h's X-macro table gives the unit "bits"."""
    with open(URRT_H) as f:
        return set(re.findall(r'X\(\w+, (\w+), [^"]*"bits"', f.read()))


class Checker:
    def __init__(self):
        self.passed = self.failed = 0

    def check(self, desc, ok, detail=''):
        if ok:
            self.passed += 1
        else:
            self.failed += 1
            print('FAIL: EDS: %s%s' % (desc, (': ' + detail) if detail else ''))
        return ok


def value_ok(dtype, text, node_id):
    """Whether a DefaultValue parses for its type and lies in its range."""
    name, size, fmt = eds.DATA_TYPES[dtype]
    if size == 0:
        return True
    try:
        if dtype in (0x0008, 0x0011):
            v = float(text)
            struct.pack(fmt, v)
            return True
        v = eds.resolve(text, node_id)
        struct.pack(fmt, v)
        return True
    except (ValueError, struct.error):
        return False


def check_sections(c, cp):
    for name in ('FileInfo', 'DeviceInfo', 'MandatoryObjects', 'OptionalObjects', 'ManufacturerObjects'):
        c.check('[%s] present' % name, cp.has_section(name))
    info = cp['DeviceInfo'] if cp.has_section('DeviceInfo') else {}
    for key in ('VendorName', 'ProductName', 'NrOfRXPDO', 'NrOfTXPDO', 'SimpleBootUpSlave', 'Granularity'):
        c.check('[DeviceInfo] %s' % key, key in info)
    rates = [k for k in info if k.startswith('BaudRate_')]
    c.check('[DeviceInfo] BaudRate_* entries', bool(rates) and all(info[k].strip() in ('0', '1') for k in rates))


def check_lists(c, cp):
    lists = eds.listed(cp)
    seen = {}
    for name, indices in lists.items():
        sec = cp[name] if cp.has_section(name) else {}
        count = eds.parse_int(sec.get('SupportedObjects', '-1'))
        entries = [k for k in sec if k != 'SupportedObjects']
        c.check('[%s] SupportedObjects=%d matches its %d entries' % (name, count, len(entries)),
                count == len(entries) == len(indices) and sorted(entries, key=int) == [str(i) for i in
                                                                                     range(1, count + 1)])
        for i in indices:
            c.check('0x%04X listed once' % i, i not in seen, 'also in %s' % seen.get(i))
            seen[i] = name
            c.check('0x%04X (in %s) has its section [%04X]' % (i, name, i), cp.has_section('%04X' % i))
    for i in MANDATORY:
        c.check('mandatory 0x%04X in MandatoryObjects' % i, i in lists['MandatoryObjects'])
    c.check('0x1017 producer heartbeat time present (no node guarding)', 0x1017 in seen)
    for i in lists['ManufacturerObjects']:
        c.check('manufacturer object 0x%04X in 0x2000..0x5FFF' % i, 0x2000 <= i <= 0x5FFF)
    for i in lists['OptionalObjects']:
        c.check('optional object 0x%04X outside the manufacturer range' % i,
                not 0x2000 <= i <= 0x5FFF and i not in MANDATORY)
    objs = {i for (i, _sub) in eds.objects(cp)}
    c.check('every object section is listed', objs <= set(seen), ' '.join('%04X' % i for i in sorted(objs - set(seen))))


def check_variable(c, where, sec, node_id):
    dtype = eds.parse_int(sec.get('DataType', '0'))
    c.check('%s DataType 0x%04X known' % (where, dtype), dtype in eds.DATA_TYPES)
    access = sec.get('AccessType', '').strip().lower()
    c.check('%s AccessType "%s"' % (where, access), access in eds.ACCESS_TYPES)
    c.check('%s PDOMapping 0/1' % where, sec.get('PDOMapping', '0').strip() in ('0', '1'))
    c.check('%s ParameterName' % where, bool(sec.get('ParameterName', '').strip()))
    if 'DefaultValue' in sec and dtype in eds.DATA_TYPES:
        c.check('%s DefaultValue "%s" is a %s' % (where, sec['DefaultValue'], eds.DATA_TYPES[dtype][0]),
                value_ok(dtype, sec['DefaultValue'], node_id))


def check_objects(c, cp, node_id):
    for index in sorted({i for (i, _sub) in eds.objects(cp)}):
        name = '%04X' % index
        if not cp.has_section(name):
            continue
        sec = cp[name]
        otype = eds.parse_int(sec.get('ObjectType', '0x7'))
        c.check('[%s] ObjectType 0x%X legal' % (name, otype), otype in eds.OBJECT_TYPES)
        if otype == 0x7:
            check_variable(c, '[%s]' % name, sec, node_id)
            continue
        subs = sorted(int(s[len(name) + 3:], 16) for s in cp.sections()
                      if s.upper().startswith(name + 'SUB'))
        number = eds.parse_int(sec.get('SubNumber', '-1'))
        c.check('[%s] SubNumber %d = its %d sub-sections' % (name, number, len(subs)), number == len(subs))
        c.check('[%s] has sub 0' % name, 0 in subs)
        for s in subs:
            check_variable(c, '[%ssub%X]' % (name, s), cp['%ssub%X' % (name, s)], node_id)


def check_pdos(c, cp, node_id):
    objs = eds.objects(cp)
    tps = eds.tpdos(cp, node_id)
    for t in tps:
        total = 0
        for index, sub, bits in t['mapping']:
            total += bits
            if index < 0x1000:  # a dummy: the data type's own size
                c.check('TPDO%d dummy 0x%04X of a known type' % (t['n'], index), index in eds.DATA_TYPES)
                continue
            sec = objs.get((index, sub))
            where = 'TPDO%d maps 0x%04X sub %d' % (t['n'], index, sub)
            if not c.check('%s: it exists' % where, sec is not None):
                continue
            c.check('%s: PDOMapping=1' % where, sec.get('PDOMapping', '0').strip() == '1')
            size = eds.DATA_TYPES.get(eds.parse_int(sec.get('DataType', '0')), ('', -1))[1]
            c.check('%s: %d bits = its type\'s size' % (where, bits), size * 8 == bits, '%d bytes' % size)
        c.check('TPDO%d mapping fits 64 bits (%d)' % (t['n'], total), total <= 64)
    rps = eds.rpdos(cp, node_id)
    for r in rps:
        total = 0
        for index, sub, bits in r['mapping']:
            total += bits
            if index < 0x1000:  # a dummy: the data type's own size
                c.check('RPDO%d dummy 0x%04X of a known type, %d bits' % (r['n'], index, bits),
                        index in eds.DATA_TYPES and eds.DATA_TYPES[index][1] * 8 == bits and sub == 0)
                continue
            sec = objs.get((index, sub))
            where = 'RPDO%d maps 0x%04X sub %d' % (r['n'], index, sub)
            if not c.check('%s: it exists' % where, sec is not None):
                continue
            c.check('%s: PDOMapping=1' % where, sec.get('PDOMapping', '0').strip() == '1')
            access = sec.get('AccessType', '').strip().lower()
            c.check('%s: writable (%s)' % (where, access), access in ('rww', 'rw', 'wo'))
            size = eds.DATA_TYPES.get(eds.parse_int(sec.get('DataType', '0')), ('', -1))[1]
            c.check('%s: %d bits = its type\'s size' % (where, bits), size * 8 == bits, '%d bytes' % size)
        c.check('RPDO%d mapping fits 64 bits (%d)' % (r['n'], total), total <= 64)
        cob = r['cob_id']
        c.check('RPDO%d COB-ID 0x%08X: an 11-bit id, bit 29 clear' % (r['n'], cob), cob & 0x3FFFF800 == 0)
    valid = [r['cob_id'] & 0x7FF for r in rps if not r['cob_id'] & 0x80000000]
    c.check('no two valid RPDOs on one COB-ID', len(valid) == len(set(valid)), ' '.join('0x%X' % v for v in valid))
    for base in (0x1600, 0x1A00):
        for n in range(512):
            name = '%04X' % (base + n)
            if (base + n, 0) not in objs:
                continue
            entries = sum(1 for (i, s) in objs if i == base + n and s is not None and s > 0)
            count = eds.resolve(objs[(base + n, 0)].get('DefaultValue', '-1'), node_id)
            c.check('[%ssub0] %d = its %d entries' % (name, count, entries), count == entries)
    info = cp['DeviceInfo'] if cp.has_section('DeviceInfo') else {}
    c.check('NrOfTXPDO = %d TPDOs' % len(tps), eds.parse_int(info.get('NrOfTXPDO', '-1')) == len(tps))
    rx = sum(1 for n in range(512) if (0x1400 + n, 1) in objs)
    c.check('NrOfRXPDO = %d RPDOs' % rx, eds.parse_int(info.get('NrOfRXPDO', '-1')) == rx)
    for n in range(512):
        c.check('0x%04X has its communication object 0x%04X' % (0x1A00 + n, 0x1800 + n),
                not cp.has_section('%04X' % (0x1A00 + n)) or cp.has_section('%04X' % (0x1800 + n)))
        c.check('0x%04X has its communication object 0x%04X' % (0x1600 + n, 0x1400 + n),
                not cp.has_section('%04X' % (0x1600 + n)) or cp.has_section('%04X' % (0x1400 + n)))


def check_consumer_heartbeat(c, cp, node_id):
    if not cp.has_section('1016'):
        return
    objs = eds.objects(cp)
    c.check('[1016] is an ARRAY', eds.parse_int(cp['1016'].get('ObjectType', '0')) == 0x8)
    subs = sorted(s for (i, s) in objs if i == 0x1016 and s is not None and s > 0)
    count = eds.resolve(objs[(0x1016, 0)].get('DefaultValue', '-1'), node_id) if (0x1016, 0) in objs else -1
    c.check('[1016sub0] %d = its %d entries' % (count, len(subs)), count == len(subs) == (subs[-1] if subs else 0))
    for s in subs:
        c.check('[1016sub%X] UNSIGNED32' % s, eds.parse_int(objs[(0x1016, s)].get('DataType', '0')) == 0x0007)


def check_file_info(c, cp, path):
    info = cp['FileInfo'] if cp.has_section('FileInfo') else {}
    name = info.get('FileName', '').strip()
    c.check('[FileInfo] FileName "%s" is the file\'s name' % name, name == os.path.basename(path))
    for key, form in (('CreationTime', TIME), ('ModificationTime', TIME), ('CreationDate', DATE),
                      ('ModificationDate', DATE)):
        c.check('[FileInfo] %s "%s" as CiA 306 writes it' % (key, info.get(key, '')),
                form.fullmatch(info.get(key, '').strip()) is not None)


def check_limits(c, cp, node_id):
    masks = mask_fields()
    c.check('lib/urrt.h names bit-mask fields', bool(masks))
    comments = cp['Comments'] if cp.has_section('Comments') else {}
    for (index, sub), sec in eds.objects(cp).items():
        where = '[%04X%s]' % (index, '' if sub is None else 'sub%X' % sub)
        field = re.match(r'\w+: (\w+)', sec.get('ParameterName', ''))
        if index >= 0x2000 and field and field.group(1) in masks:
            c.check('%s bit mask %s: no LowLimit/HighLimit' % (where, field.group(1)),
                    'LowLimit' not in sec and 'HighLimit' not in sec)
            lines = [v for v in comments.values() if v.startswith('0x%04X sub %d ' % (index, sub))]
            c.check('%s bit mask: its [Comments] line gives no limits' % where,
                    bool(lines) and all('limits' not in v or 'no limits' in v for v in lines), ' / '.join(lines))
        access = sec.get('AccessType', '').strip().lower()
        if access in ('rww', 'rwr'):
            c.check('%s AccessType %s: PDO-mappable (PDOMapping=1)' % (where, access),
                    sec.get('PDOMapping', '0').strip() == '1')
        if 'LowLimit' in sec or 'HighLimit' in sec:
            dtype = eds.parse_int(sec.get('DataType', '0'))
            if dtype in eds.DATA_TYPES:
                for k in ('LowLimit', 'HighLimit'):
                    c.check('%s %s "%s" is a %s' % (where, k, sec.get(k), eds.DATA_TYPES[dtype][0]),
                            k not in sec or value_ok(dtype, sec[k], node_id))
            low, high = (eds.resolve(sec.get(k, '0'), node_id) for k in ('LowLimit', 'HighLimit'))
            default = eds.resolve(sec.get('DefaultValue', str(low)), node_id)
            c.check('%s limits %d..%d hold the default %d' % (where, low, high, default), low <= default <= high)
        if 0x1800 <= index < 0x1A00 and sub == 1:
            value = eds.resolve(sec.get('DefaultValue', '0'), node_id)
            c.check('%s COB-ID 0x%08X: bit 30 (no RTR)' % (where, value), value & 0x40000000 != 0)


def check(path, node_id=1):
    c = Checker()
    cp = eds.read(path)
    check_sections(c, cp)
    check_file_info(c, cp, path)
    check_lists(c, cp)
    check_objects(c, cp, node_id)
    check_pdos(c, cp, node_id)
    check_consumer_heartbeat(c, cp, node_id)
    check_limits(c, cp, node_id)
    return c


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit('usage: eds_check.py EDS [NODE_ID]')
    c = check(sys.argv[1], int(sys.argv[2]) if len(sys.argv) == 3 else 1)
    print('%d passed, %d failed' % (c.passed, c.failed))
    return 0 if c.failed == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
