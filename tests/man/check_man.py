#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""check-man: each man page documents exactly its program's options.

The options come from the option table in the program's source (cli.h's
cli_option rows, or getopt_long's table and option string), and again from its --help; the page's are the `### ` headings of its
OPTIONS section (gateway/man/*.md). Both directions: every option documented,
nothing documented that does not exist. Each rendered page is also read by
man(1) with warnings on, and must produce none. urrt-gateway(8) and urrt-gateway.ini(5) name every
key of [robot] and each source (`source = rtde`); check-deb runs the same test on the installed
pages and the package's descriptions (--named, --sources)."""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import suite  # noqa: E402  the check and report every Python suite shares
from suite import check  # noqa: E402


def table_options(source):
    """{(short or None, long)} from the program's option table: a cli_option table (cli.h: one row per
    option, its long name and letter first), or getopt_long's struct option table and option string,
    plus shorts without a long."""
    text = open(source).read()
    rows = re.search(r"cli_option \w+\[\]\s*=\s*\{(.*?)\};", text, re.S)
    if rows:
        return {(None if short == "0" else short[1], long_name)
                for long_name, short in re.findall(r'\{"([\w-]+)",\s*(\'.\'|0),', rows.group(1))}
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


# ---- the configuration keys ------------------------------------------------------------


def table_keys(program):
    """{section: {key: {'form', 'default', 'absent', 'bounds'}}} in table order."""
    out = subprocess.run([program, "--print-keys"], capture_output=True, text=True, timeout=10).stdout
    keys = {}
    for line in out.splitlines():
        section, key, form, default, bounds, _help = line.split("\t")
        absent = default[1:-1] if default.startswith("(") else None
        keys.setdefault(section, {})[key] = {"form": form, "default": None if absent else default,
                                             "absent": absent, "bounds": None if bounds == "-" else bounds}
    return keys


def kinds(keys):
    """state, joints, ...: the KIND of [lcm]'s KIND_channel and KIND_rate, in table order."""
    return [k[:-len("_channel")] for k in keys["lcm"] if k.endswith("_channel")]


def expand(keys, section, name, default):
    """A documented key and its default: KIND_x is one key per kind, its default
    a list in kind order ("`STATE`, `JOINTS`, ...") or by kind ("`every` for state,
    joints and tool; `10 Hz` for status")."""
    if not name.startswith("KIND_"):
        return [(name, default)]
    per_kind = {}
    if " for " in default:
        for part in default.split(";"):
            m = re.match(r"\s*`([^`]*)` for (.*)", part)
            for kind in re.split(r",\s*|\s+and\s+", m.group(2).strip().rstrip(".")) if m else []:
                per_kind[kind.strip()] = "`%s`" % m.group(1)
    else:
        per_kind = dict(zip(kinds(keys), ("`%s`" % v for v in re.findall(r"`([^`]*)`", default))))
    return [(k + name[len("KIND"):], per_kind.get(k, "")) for k in kinds(keys)]


def check_key(keys, where, section, name, default, text):
    """One documented key: it exists, its default (a cell or the text after
    "default") is the table's, and its bounds appear in text as `BOUNDS`."""
    key = keys.get(section, {}).get(name)
    if not check(key is not None, "%s: [%s] %s is a key of the table" % (where, section, name)):
        return
    said = default.replace("`", "").strip()
    want = key["default"] if key["default"] is not None else key["absent"]
    check(said == want, "%s: [%s] %s: default %r, the table's %r" % (where, section, name, said, want))
    if key["bounds"]:
        check("`%s`" % key["bounds"] in text, "%s: [%s] %s: bounds `%s` written" % (where, section, name,
                                                                                    key["bounds"]))


def check_all_listed(keys, where, section, listed):
    missing = [k for k in keys[section] if k not in listed]
    check(not missing, "%s: every key of [%s] listed (missing: %s)" % (where, section, ", ".join(missing) or "none"))


def check_doc_tables(keys, path, heading, sections):
    """Markdown tables `| `key` | values | default |` under headings such as
    "### `[robot NAME]`": each row against the table."""
    section, listed = None, {}
    for line in open(path):
        if line.startswith("#"):
            m = re.match(heading, line)
            section = m.group(1) if m and m.group(1) in sections else None
            continue
        row = re.match(r"\| `(\w+)` \|(.*)\|(.*)\|\s*$", line)
        if section and row:
            for name, default in expand(keys, section, row.group(1), row.group(3)):
                listed.setdefault(section, set()).add(name)
                check_key(keys, path, section, name, default, row.group(2))
    for section in sections:
        check_all_listed(keys, path, section, listed.get(section, set()))


def check_man_keys(keys, path, sections):
    """urrt-gateway.ini(5): a `### key = FORM` heading per key, its default in
    "(default `X`" (or "Required"), its bounds as `BOUNDS` in its paragraph."""
    section, key, body, listed = None, None, [], {s: set() for s in sections}

    def flush():
        if section in sections and key:
            text = " ".join(body)
            listed_defaults = re.search(r"Defaults: (.*?)\.(?:\s|$)", text)
            one = re.search(r"[Dd]efault `([^`]*)`", text)
            default = listed_defaults.group(1) if listed_defaults else "`%s`" % one.group(1) if one else ""
            default = "required" if text.startswith("Required") else default
            for name, value in expand(keys, section, key, default):
                listed[section].add(name)
                check_key(keys, path, section, name, value, text)

    for line in open(path):
        if line.startswith("# "):
            flush()
            section, key, body = line[2:].strip().strip("[]").split(" ")[0].lower(), None, []
        elif line.startswith("### "):
            flush()
            key, body = line[4:].split("=")[0].strip(), []
        elif key:
            body.append(line.strip())
    flush()
    for s in sections:
        check_all_listed(keys, path, s, listed[s])


def check_example(keys, path, sections):
    """The example configuration sets every key of its sections to its default."""
    section, listed = None, {s: set() for s in sections}
    for line in open(path):
        line = line.strip()
        if line.startswith("["):
            section = line[1:line.index("]")].split()[0]
        elif line and line[0] not in "#;" and section in sections:
            name, value = (x.strip() for x in line.split("=", 1))
            listed[section].add(name)
            key = keys[section].get(name)
            if check(key is not None, "%s: [%s] %s is a key of the table" % (path, section, name)) and \
                    key["default"] is not None:
                check(value == key["default"], "%s: [%s] %s = %r, the table's default %r" %
                      (path, section, name, value, key["default"]))
    for s in sections:
        check_all_listed(keys, path, s, listed[s])


# ---- what a robot is read over, named where a reader looks first -------------------------
# check-man holds the pages in the tree to it, check-deb the pages and texts of the package
# (`check_man.py --named PROGRAM PAGE...`, `--sources PROGRAM FILE...`): the same table, the same test.


def choices(form):
    """A form of lowercase words (`realtime|rtde`) is the list of its choices; others
    (`auto|N Hz`, `DURATION`) have none."""
    return form.split("|") if re.fullmatch(r"[a-z]+(\|[a-z]+)+", form) else []


def readable(path):
    """A man page (roff, gzipped or not) as man(1) shows it, without hyphenation or justification;
    any other file as it is. Whitespace runs are one blank, so that no line break splits a phrase."""
    if re.search(r"\.\d(\.gz)?$", path):
        r = subprocess.run(["man", "--nh", "--nj", "-E", "UTF-8", "-l", path], capture_output=True, text=True,
                           timeout=30, env=dict(os.environ, MANWIDTH="80"))
        text = r.stdout
    else:
        text = open(path).read()
    return " ".join(text.split())


def unnamed_keys(keys, section, text):
    """What of SECTION's keys TEXT leaves out: each key as a word, and each choice of a key whose form
    lists its choices as `key = choice`, alone or in the list (`source = rtde`, `source = realtime|rtde`)."""
    missing = [k for k in keys[section] if not re.search(r"(?<![\w-])%s(?![\w-])" % re.escape(k), text)]
    for k, key in keys[section].items():
        missing += ["%s = %s" % (k, c) for c in choices(key["form"])
                    if not re.search(r"(?<![\w-])%s = (?:[a-z]+\|)*%s(?![\w-])" % (re.escape(k), c), text)]
    return missing


def unnamed_sources(keys, text):
    """The sources a robot is read over (the choices of [robot] source) TEXT does not name, in any case
    (`RealTime`, `RTDE`)."""
    return [c for c in choices(keys["robot"]["source"]["form"]) if not re.search(r"\b%s\b" % c, text, re.I)]


def check_named(keys, pages):
    """Each page (rendered, in the tree or installed) names every [robot] key and each source as
    `source = NAME`; a failure names the page's source to edit."""
    for page in pages:
        missing = unnamed_keys(keys, "robot", readable(page))
        fix = "; add them to gateway/man/%s.md" % re.sub(r"\.gz$", "", os.path.basename(page))
        check(not missing, "%s names every [robot] key of --print-keys and each source as `source = NAME`"
              " (missing: %s)%s" % (page, ", ".join(missing) or "none", fix if missing else ""))


def check_sources(keys, files):
    """Each text names every source, the choices of `[robot] source` (a package's description)."""
    for path in files:
        missing = unnamed_sources(keys, readable(path))
        check(not missing, "%s names every source of [robot] source = %s (missing: %s%s)" %
              (path, keys["robot"]["source"]["form"], ", ".join(missing) or "none",
               ": name them in debian/control's Description and gateway/install/install.mk's urrt.pc" if missing else ""))


def check_keys(build):
    keys = table_keys(os.path.join(build, "bin", "urrt-gateway"))
    check(len(keys) == 7 and len(keys.get("robot", {})) >= 7, "--print-keys lists the sections' keys (%s)" %
          ", ".join("%s: %d" % (s, len(k)) for s, k in keys.items()))
    check_man_keys(keys, "gateway/man/urrt-gateway.ini.5.md", ["gateway", "lcm", "robot", "input", "canopen"])
    check_doc_tables(keys, "docs/gateway.md", r"### `\[(\w+)[ \w]*\]`", ["gateway", "lcm", "robot"])
    check_doc_tables(keys, "docs/can.md", r"##+ `\[(\w+)[ \w]*\]`", ["can", "frame", "input"])
    check_doc_tables(keys, "docs/canopen.md", r"## `\[(\w+)[ \w]*\]`", ["canopen"])
    check_example(keys, "gateway/install/urrt-gateway.example.ini", ["gateway", "lcm", "robot"])
    check_named(keys, [os.path.join(build, "man", p) for p in ("urrt-gateway.8", "urrt-gateway.ini.5")])


def named_main(mode, program, files):
    """check-deb's entry: the installed pages (--named) or texts (--sources) against PROGRAM's keys."""
    keys = table_keys(program)
    if mode == "--named":
        check_named(keys, files)
    else:
        check_sources(keys, files)
    return suite.report() if suite.passed > 0 else 1


def main():
    if sys.argv[1] in ("--named", "--sources"):
        return named_main(sys.argv[1], sys.argv[2], sys.argv[3:])
    build = sys.argv[1]
    check_keys(build)
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
    for path in ("gateway/install/urrt-gateway.service", os.path.join(build, "dist", "urrt-gateway@.service")):
        unit = open(path).read() if os.path.exists(path) else ""
        check("Documentation=man:urrt-gateway(8)" in unit, "%s: Documentation= is the man page" % path)
    page = open("gateway/man/urrt-gateway.8.md").read()
    check("urrt-gateway@NAME" in page and "/etc/urrt/NAME.ini" in page,
          "urrt-gateway(8) names the template unit urrt-gateway@NAME and the file it reads")
    return suite.report()


if __name__ == "__main__":
    sys.exit(main())
