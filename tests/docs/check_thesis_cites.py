#!/usr/bin/env python3
"""Checks that every thesis equation, listing and table the code cites is restated in the docs
(ctest: docs_thesis_cites).

The code cites the thesis (`../shared/seed/thesis.txt`) as "eq. 7.8", "eq. 6.12–6.20",
"Listing 5.1 and 7.6", "Listings 7.3–7.4", "Table 7.2/7.3", "Eq. (3.4)", "Alg. 2.1". A reader
without the thesis looks each one up in docs/ALGORITHM.md (the filter's equations) or
docs/HARDWARE.md (the hardware's equations, listings and tables), where it is restated under
a bold label: **(T-eq. 7.8)**, **(T-Listing 7.1)**, **(T-Table 7.2)**, **(T-Alg. 2.1)**. In a
comment the cite is followed by the name of the doc that restates it, in brackets:
"eq. 7.8 [HARDWARE.md]", "(eq. 6.12–6.20 [ALGORITHM.md])".

The check, over the source files (src include apps python tests fuzz bench scripts; C++,
Python, SystemVerilog, GLSL):
  1. every cited item has its bold label in one of the two docs (a range "eq. 6.12–6.20" cites
     every equation from 6.12 to 6.20);
  2. every cite in a comment has, on the same line, the name of each doc that restates the
     items it cites (cites in string literals — help text, docstrings — need no pointer).
The thesis numbers every item chapter.number, so "Table 1" (another paper's) is not a thesis
cite; "§7.4" (sections) and "Fig. 7.5" (figures) are not checked.
It prints what is missing and exits 1; with --list it prints every cited item and where.

    /usr/bin/python3 tests/docs/check_thesis_cites.py [--root DIR] [--list]

Standard library only.
"""

import argparse
import os
import re
import sys

SOURCE_DIRS = ("src", "include", "apps", "python", "tests", "fuzz", "bench", "scripts")
SOURCE_EXTS = (".cc", ".cpp", ".c", ".h", ".hpp", ".inc", ".sv", ".svh", ".v", ".py", ".pyi",
               ".glsl", ".comp", ".sh", ".tcl")
DOCS = ("docs/ALGORITHM.md", "docs/HARDWARE.md")

# kind words → canonical kind
KINDS = [
    (r"eqs?\.|equations?", "eq."),
    (r"listings?", "Listing"),
    (r"tables?", "Table"),
    (r"alg\.|algorithms?", "Alg."),
]
NUM = r"(?:\((\d+)\.(\d+)\)|(\d+)\.(\d+))"  # 7.8 or (7.8)
SEP = r"\s*(?:–|—|-|,|/|\band\b|&)\s*"
CITE_RE = re.compile(
    r"(?<![A-Za-z])(?P<kind>" + "|".join(k for k, _ in KINDS) + r")\s*(?P<nums>" + NUM +
    r"(?:" + SEP + NUM + r")*)", re.IGNORECASE)
ONE_NUM_RE = re.compile(NUM)


def canonical_kind(word):
    for pattern, kind in KINDS:
        if re.fullmatch(pattern, word, re.IGNORECASE):
            return kind
    raise ValueError(word)


def parse_numbers(text):
    """'6.12–6.20, 7.6' → [(6, 12), …, (6, 20), (7, 6)] (ranges expanded within a chapter)."""
    items = []
    pos = 0
    prev = None
    for m in ONE_NUM_RE.finditer(text):
        sep = text[pos:m.start()]
        cur = (int(m.group(1) or m.group(3)), int(m.group(2) or m.group(4)))
        if prev is not None and re.search(r"[–—-]", sep) and prev[0] == cur[0] and prev[1] < cur[1]:
            items.extend((cur[0], n) for n in range(prev[1] + 1, cur[1] + 1))
        else:
            items.append(cur)
        prev = cur
        pos = m.end()
    return items


def label(kind, num):
    return "(T-%s %d.%d)" % (kind, num[0], num[1])


def comment_start(line, path):
    """Column where a comment starts on this line (None: no comment). Approximate: a comment
    marker outside a string literal on the same line; a line inside a /* */ block starting
    with '*' counts as comment from column 0."""
    marker = "#" if path.endswith((".py", ".pyi", ".sh", ".tcl")) else "//"
    stripped = line.lstrip()
    if marker == "//" and (stripped.startswith("*") or stripped.startswith("/*")):
        return len(line) - len(stripped)
    in_str = None
    i = 0
    while i < len(line):
        ch = line[i]
        if in_str:
            if ch == "\\":
                i += 2
                continue
            if ch == in_str:
                in_str = None
        elif ch in "\"'":
            # C++ digit separators and apostrophes in comments only matter after the marker
            in_str = ch
        elif line.startswith(marker, i):
            return i
        i += 1
    return None


def collect_cites(root):
    """[(path, line_no, line, kind, [nums], in_comment)]"""
    out = []
    for top in SOURCE_DIRS:
        base = os.path.join(root, top)
        if not os.path.isdir(base):
            continue
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "__pycache__")
            for name in sorted(filenames):
                if not name.endswith(SOURCE_EXTS):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root)
                if rel == os.path.join("tests", "docs", "check_thesis_cites.py"):
                    continue  # this file's own examples
                try:
                    with open(path, encoding="utf-8") as f:
                        lines = f.read().splitlines()
                except (UnicodeDecodeError, OSError):
                    continue
                for no, line in enumerate(lines, 1):
                    cstart = None
                    for m in CITE_RE.finditer(line):
                        if cstart is None:
                            cstart = comment_start(line, rel)
                            if cstart is None:
                                cstart = len(line) + 1
                        nums = parse_numbers(m.group("nums"))
                        if nums:
                            out.append((rel, no, line, canonical_kind(m.group("kind")), nums,
                                        m.start() >= cstart))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                   "..", ".."),
                    help="repository root (default: this file's ../..)")
    ap.add_argument("--list", action="store_true", help="print every cited item and where")
    args = ap.parse_args()
    root = os.path.abspath(args.root)

    docs = {}
    for doc in DOCS:
        with open(os.path.join(root, doc), encoding="utf-8") as f:
            docs[os.path.basename(doc)] = f.read()

    cites = collect_cites(root)
    items = {}
    for rel, no, line, kind, nums, in_comment in cites:
        for num in nums:
            items.setdefault(label(kind, num), []).append("%s:%d" % (rel, no))

    def holders(lab):
        return [name for name, text in docs.items() if "**%s**" % lab in text]

    def sort_key(lab):
        m = re.match(r"\(T-(\S+) (\d+)\.(\d+)\)", lab)
        return (m.group(1), int(m.group(2)), int(m.group(3)))

    if args.list:
        for lab in sorted(items, key=sort_key):
            where = items[lab]
            print("%-20s %-24s %d cites, e.g. %s" % (lab, ",".join(holders(lab)) or "-", len(where),
                                                      where[0]))

    missing = [lab for lab in sorted(items, key=sort_key) if not holders(lab)]
    unpointed = []
    for rel, no, line, kind, nums, in_comment in cites:
        if not in_comment:
            continue
        need = set()
        for num in nums:
            need.update(holders(label(kind, num)))
        lacking = sorted(d for d in need if d not in line)
        if lacking:
            unpointed.append("%s:%d: %s %s cited without %s: %s" % (
                rel, no, kind, ", ".join("%d.%d" % n for n in nums), " and ".join(lacking),
                line.strip()))

    for lab in missing:
        where = items[lab]
        print("not restated in %s: %s, cited at %s%s" % (
            " or ".join(os.path.basename(d) for d in DOCS), lab, ", ".join(where[:3]),
            " and %d more" % (len(where) - 3) if len(where) > 3 else ""))
    for msg in unpointed:
        print("no pointer: " + msg)
    print("thesis cites: %d distinct items in %d cites; %d not restated, %d comments without the doc's name"
          % (len(items), len(cites), len(missing), len(unpointed)))
    return 1 if missing or unpointed else 0


if __name__ == "__main__":
    sys.exit(main())
