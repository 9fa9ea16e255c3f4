#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""How many of the controller's data packages TCP delivered in more than one
segment, from the segments alone (tshark without urrt's dissector).

check-wireshark-rtde asks the dissector to reassemble every data package
urrt-sim's tiny-writes fault cut across segments. Which ones those are is
the kernel's to decide, not the simulator's: a simulator that wakes late
writes its due pieces back to back, and Linux coalesces small writes queued
behind an unsent one (TCP autocorking), so a whole package may then travel
in one segment. This finds, for one direction of one connection, the data
packages whose bytes a segment boundary falls inside of.

Input on stdin: `tshark -T fields -e tcp.seq -e tcp.len -e tcp.payload` of
that direction's segments (relative sequence numbers, payload in hex), in
capture order. The stream is walked from its first byte: RTDE packages are
uint16 size (header included) and a type byte; 'U' (0x55) is a data package.

  split_packages.py < FIELDS      prints: SPLIT TOTAL (data packages), then
                                  each split data package in hex, a line each,
                                  in stream order
"""
import sys


def main():
    stream = bytearray()
    boundaries = set()   # stream offsets where a segment begins
    for line in sys.stdin:
        parts = line.rstrip('\n').split('\t')
        if len(parts) < 3 or not parts[1].isdigit() or int(parts[1]) == 0:
            continue
        seq, length, payload = int(parts[0]), int(parts[1]), bytes.fromhex(parts[2].replace(':', ''))
        start = seq - 1      # relative sequence numbers start at 1 after the SYN
        if start != len(stream) or len(payload) != length:
            if start + length <= len(stream):
                continue     # a retransmission of bytes already seen
            sys.exit('split_packages.py: a gap in the stream at %d (segment at %d)' % (len(stream), start))
        boundaries.add(start)
        stream += payload
    split, total, at = [], 0, 0
    while at + 3 <= len(stream):
        size = stream[at] << 8 | stream[at + 1]
        if size < 3:
            sys.exit('split_packages.py: a package of %d bytes at %d' % (size, at))
        if at + size > len(stream):
            break
        if stream[at + 2] == 0x55:
            total += 1
            if any(b in boundaries for b in range(at + 1, at + size)):
                split.append(stream[at:at + size].hex())
        at += size
    print(len(split), total)
    for package in split:
        print(package)


if __name__ == '__main__':
    main()
