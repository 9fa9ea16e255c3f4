#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Checks that every relative link in Markdown files resolves inside a tree.

  doc_links.py ROOT FILE...

ROOT is an unpacked package (or any directory standing for /); each FILE is a
Markdown file under ROOT. Every inline link and image ([text](target),
![alt](target)) and every reference definition ([label]: target) outside code
is followed: a target with a scheme (https:, mailto:) is left alone; any other
must name a file or directory under ROOT, relative to the linking file, and its
#fragment, when the target is Markdown, a heading of that file (GitHub's
anchors: lower case, punctuation dropped, blanks to '-', "-1" for a repeat).
Symbolic links are followed within ROOT (an absolute one is taken from ROOT).

Prints each broken link as FILE:LINE: TARGET: why, then "FILE: N links, N broken"
per file; exits 1 when a link is broken or the files hold no relative link at
all (a parser that found nothing has checked nothing).
"""
import os
import re
import sys
from urllib.parse import unquote

FENCE = re.compile(r"^\s{0,3}(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1")
# [text](target "title") and ![alt](target); text may hold one level of brackets.
INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")
HEADING = re.compile(r"^\s{0,3}#{1,6}\s+(.*?)\s*#*\s*$")
HTML_ANCHOR = re.compile(r"<a\s+(?:name|id)=\"([^\"]+)\"")


def prose_lines(text):
    """(line number, line) outside fenced code."""
    fenced = None
    for number, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if m:
            if fenced is None:
                fenced = m.group(1)
            elif fenced == m.group(1):
                fenced = None
            continue
        if fenced is None:
            yield number, line


def links(text):
    for number, line in prose_lines(text):
        line = CODE_SPAN.sub("``", line)  # `[a](b)` in code is no link
        for m in INLINE.finditer(line):
            yield number, m.group(1)
        m = REFERENCE.match(line)
        if m:
            yield number, m.group(1)


def slug(heading):
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text only
    text = text.replace("`", "").lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(text):
    seen = {}
    found = set()
    for _, line in prose_lines(text):
        found.update(HTML_ANCHOR.findall(line))
        m = HEADING.match(line)
        if not m:
            continue
        base = slug(m.group(1))
        n = seen.get(base, 0)
        seen[base] = n + 1
        found.add(base if n == 0 else "%s-%d" % (base, n))
    return found


def resolve(root, path):
    """path (absolute, under root) with a final symbolic link followed within root."""
    for _ in range(10):
        if not os.path.islink(path):
            return path
        target = os.readlink(path)
        if os.path.isabs(target):
            path = os.path.join(root, target.lstrip("/"))
        else:
            path = os.path.normpath(os.path.join(os.path.dirname(path), target))
    return path


def check_file(root, md):
    try:
        with open(md, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        print("%s: cannot read it: %s" % (md, e.strerror))
        return 0, 1
    count = broken = 0
    for number, target in links(text):
        if not target or SCHEME.match(target):
            continue
        count += 1
        path, _, fragment = target.partition("#")
        dest = md if not path else resolve(root, os.path.normpath(os.path.join(os.path.dirname(md), unquote(path))))
        why = None
        if os.path.relpath(dest, root).startswith(".."):
            why = "leaves the tree"
        elif not os.path.exists(dest):
            why = "no such file or directory"
        elif fragment and dest.endswith(".md") and os.path.isfile(dest):
            with open(dest, encoding="utf-8") as f:
                if fragment not in anchors(f.read()):
                    why = "no heading with anchor #%s in %s" % (fragment, os.path.relpath(dest, root))
        if why:
            broken += 1
            print("%s:%d: %s: %s" % (os.path.relpath(md, root), number, target, why))
    print("%s: %d links, %d broken" % (os.path.relpath(md, root), count, broken))
    return count, broken


def main(argv):
    if len(argv) < 3:
        sys.exit("usage: doc_links.py ROOT FILE...")
    root = os.path.abspath(argv[1])
    count = broken = 0
    for md in argv[2:]:
        c, b = check_file(root, os.path.abspath(md))
        count += c
        broken += b
    return 0 if count > 0 and broken == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
