#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-man: each man page documents exactly its program's options.

The options come from the getopt_long table and option string in the program's
source, and again from its --help; the page's are the `### ` headings of its
OPTIONS section (gateway/man/*.md). Both directions: every option documented,
nothing documented that does not exist. Each rendered page is also read by
man(1) with warnings on, and must produce none."""
import os
import re
import subprocess
import sys

PASSED = FAILED = 0


def check(ok, what):
    global PASSED, FAILED
    if ok:
        PASSED += 1
        print("ok: " + what)
    else:
        FAILED += 1
        print("FAIL: " + what)


def table_options(source):
    """{(short or None, long)} from the struct option table, plus shorts without a long."""
    text = open(source).read()
    table = re.search(r"struct option \w+\[\]\s*=\s*\{(.*?)\};", text, re.S).group(1)
    optstring = re.search(r'getopt_long\(argc, argv, "([^"]*)"', text).group(1)
    shorts = set(optstring.replace(":", ""))
    pairs, mapped = set(), set()
    for long_name, val in re.findall(r'\{"([\w-]+)",\s*\w+,\s*NULL,\s*([^}]+?)\s*\}', table):
        m = re.fullmatch(r"'(.)'", val)
        short = m.group(1) if m and m.group(1) in shorts else None
        pairs.add((short, long_name))
        mapped.add(short)
    return pairs | {(s, None) for s in shorts - mapped}


def normalise(pairs):
    """(None, L) adds nothing when (x, L) is there: `--fault SPEC` beside `-f, --fault SPEC`."""
    return {p for p in pairs if p[0] is not None or not any(q[1] == p[1] and q[0] for q in pairs)}


def heading_pairs(lines):
    pairs = set()
    for line in lines:
        short = re.findall(r"(?<![\w-])-(\w)\b", line)
        longs = re.findall(r"(?<![\w-])--([\w][\w-]*)", line)
        pairs.add((short[0] if short else None, longs[0] if longs else None))
    return normalise(pairs)


def page_options(page):
    heads, section = [], None
    for line in open(page):
        if line.startswith("# "):
            section = line[2:].strip().upper()
        elif section == "OPTIONS" and line.startswith("### "):
            heads.append(line[4:])
    return heading_pairs(heads)


def help_options(program):
    out = subprocess.run([program, "--help"], capture_output=True, text=True, timeout=10).stdout
    # Option lines: two spaces, then -x or --long (continuation lines are indented further).
    return heading_pairs(l for l in out.splitlines() if re.match(r"  {1,5}-", l))


def show(pairs):
    return ", ".join(sorted(("-%s " % s if s else "") + ("--" + l if l else "") for s, l in pairs)) or "none"


def main():
    build = sys.argv[1]
    # program: (man section, the source with its option table)
    programs = {"urrt-gateway": ("8", "gateway/urrt-gateway/urrt-gateway.c"),
                "urrt-dump": ("1", "gateway/tools/urrt-dump.c"), "urrt-sim": ("1", "gateway/tools/urrt-sim.c")}
    for prog, (sec, source) in programs.items():
        table = normalise(table_options(source))
        page = page_options("gateway/man/%s.%s.md" % (prog, sec))
        helped = help_options(os.path.join(build, "bin", prog))
        check(len(table) >= 8, "%s: the option table parses (%d options)" % (prog, len(table)))
        check(not table - page, "%s(%s) documents every option (missing: %s)" % (prog, sec, show(table - page)))
        check(not page - table, "%s(%s) documents no option that does not exist (extra: %s)" %
              (prog, sec, show(page - table)))
        check(table == helped, "%s --help lists exactly the options of the table (missing: %s; extra: %s)" %
              (prog, show(table - helped), show(helped - table)))
    pages = sorted(os.listdir("gateway/man"))
    pages = [p[:-3] for p in pages if p.endswith(".md")]
    check(sorted(pages) == sorted(["urrt-gateway.8", "urrt-gateway.ini.5", "urrt-dump.1", "urrt-sim.1", "urrt-spy.1"]),
          "a page for each program and the configuration: %s" % pages)
    # urrt-spy is a script: its options are the ones it tests for itself.
    spy = open("gateway/install/urrt-spy").read()
    spy_opts = {(None, o) for o in re.findall(r'(?:"\$\{1:-\}" = |case \$a in )--([\w-]+)', spy)}
    spy_page = page_options("gateway/man/urrt-spy.1.md")
    check(spy_opts == spy_page and len(spy_opts) == 2, "urrt-spy(1) documents exactly the script's options (%s; page %s)"
          % (show(spy_opts), show(spy_page)))
    for p in pages:
        rendered = os.path.join(build, "man", p)
        r = subprocess.run(["man", "--warnings", "-E", "UTF-8", "-l", "-Tutf8", "-Z", rendered],
                           capture_output=True, text=True, timeout=30, env=dict(os.environ, MANWIDTH="80"))
        check(r.returncode == 0 and not r.stderr.strip(), "%s renders without warnings (%s)" %
              (p, r.stderr.strip()[:200]))
        text = subprocess.run(["man", "-l", rendered], capture_output=True, text=True, timeout=30,
                              env=dict(os.environ, MANWIDTH="80", MAN_KEEP_FORMATTING="")).stdout
        check("NAME" in text and "SEE ALSO" in text and "\\" not in text,
              "%s has NAME and SEE ALSO and no stray backslash" % p)
    unit = open("gateway/install/urrt-gateway.service").read()
    check("Documentation=man:urrt-gateway(8)" in unit, "the unit's Documentation= is the man page")
    line = "%d passed, %d failed" % (PASSED, FAILED)
    print(line)
    with open(os.path.join(build, "results", "check-man.result"), "w") as f:
        f.write(line + "\n")
    return 0 if FAILED == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
