#!/usr/bin/env python3
"""Compare two `posefilter suite --json` files row by row, times aside (docs/RELIABILITY.md §6).

usage: scripts/suite_compare.py OLD.json NEW.json [--max-rows N]

A change meant to move code without changing what it computes is checked by running the same
`posefilter suite ... --json F` with the binary before it and the one after, then comparing the
two files here. Every value is compared exactly (floats too: the same binary gives the same rows
run after run), except the times: keys that end in `_ms` or hold `_ms_` (`time_ms`,
`stage1_ms`, `scene_pass_ms`, `median_time_ms`, `stage1_median_ms_per_scene`, ...) at any depth.

Scene i uses the seeds --first-seed + i and --seed + i alone, so a run with a smaller --count
gives the first rows of a larger one: when the files hold different numbers of rows, the common
first rows are compared (and said so), and the summaries are not.

The rows are the file's `objects` (ycbv and room worlds: one per target) or `scenes` (shapes
world: one per scene). Prints "N rows; IDENTICAL (times aside)" and exits 0, or lists the
differing rows (seed, object, instance and the keys that differ, at most --max-rows of them) and
exits 1; files with no rows in common (or rows of different worlds) also exit 1. A missing or
unreadable file, or one that is not a suite's JSON, exits 2 with a message naming it. Only the
standard library is used.
"""

import argparse
import json
import sys

ROW_LISTS = ("objects", "scenes")  # the rows: one per target (ycbv, room) or per scene (shapes)


def is_time_key(key):
    """True for the keys that hold wall times (milliseconds), which differ run to run."""
    return key.endswith("_ms") or "_ms_" in key


def strip_times(value):
    """The value without its time keys, at every depth of dicts and lists."""
    if isinstance(value, dict):
        return {k: strip_times(v) for k, v in value.items() if not is_time_key(k)}
    if isinstance(value, list):
        return [strip_times(v) for v in value]
    return value


def load_suite(path):
    """The suite JSON at `path` (a dict with an `objects` or `scenes` list); raises ValueError naming it."""
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as e:
        raise ValueError(f"{path}: cannot read: {e.strerror or e}") from e
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON: {e}") from e
    if rows_of(data) is None:
        raise ValueError(f"{path}: not a `posefilter suite --json` file (no `objects` or `scenes` list)")
    return data


def rows_of(data):
    """(name, rows) of a suite JSON: `objects` (ycbv, room worlds) or `scenes` (shapes world);
    None when `data` holds neither."""
    if isinstance(data, dict):
        for key in ROW_LISTS:
            if isinstance(data.get(key), list):
                return key, data[key]
    return None


def row_name(row, index):
    """seed, object and instance of a row, for the report."""
    if not isinstance(row, dict):
        return f"row {index}"
    parts = [f"row {index}"]
    for key in ("seed", "obj", "target", "instance"):
        if key in row:
            parts.append(f"{key} {row[key]}")
    return ", ".join(parts)


def differing_keys(a, b):
    """The top-level keys whose values differ (times already stripped); [] when equal."""
    if not isinstance(a, dict) or not isinstance(b, dict):
        return [] if a == b else ["(whole row)"]
    return sorted(k for k in set(a) | set(b) if a.get(k, KeyError) != b.get(k, KeyError))


def compare(old, new):
    """For two loaded suite JSONs: (notes for the report, the differing rows' descriptions, the
    summary keys that differ, the number of rows compared)."""
    kind_old, raw_old = rows_of(old)
    kind_new, raw_new = rows_of(new)
    if kind_old != kind_new:
        return [f"the rows are {kind_old} in one file and {kind_new} in the other"], [], [], 0
    rows_old = [strip_times(r) for r in raw_old]
    rows_new = [strip_times(r) for r in raw_new]
    n = min(len(rows_old), len(rows_new))
    lines = []
    if len(rows_old) != len(rows_new):
        lines.append(f"the files hold {len(rows_old)} and {len(rows_new)} rows: comparing the first {n}")
    diffs = []
    for i in range(n):
        keys = differing_keys(rows_old[i], rows_new[i])
        if keys:
            diffs.append(f"{row_name(rows_old[i], i)}: {', '.join(keys)}")
    summary_diff = []
    if len(rows_old) == len(rows_new):
        sum_old = strip_times({k: v for k, v in old.items() if k != kind_old})
        sum_new = strip_times({k: v for k, v in new.items() if k != kind_new})
        summary_diff = differing_keys(sum_old, sum_new)
    return lines, diffs, summary_diff, n


def main(argv=None):
    parser = argparse.ArgumentParser(description="Compare two `posefilter suite --json` files, times aside.")
    parser.add_argument("old", help="the suite JSON of the binary before the change")
    parser.add_argument("new", help="the suite JSON of the binary after it")
    parser.add_argument("--max-rows", type=int, default=20, help="differing rows listed at most (default 20)")
    args = parser.parse_args(argv)
    if args.max_rows < 0:
        parser.error(f"--max-rows must be >= 0, got {args.max_rows}")
    try:
        old = load_suite(args.old)
        new = load_suite(args.new)
    except ValueError as e:
        print(f"suite_compare: error: {e}", file=sys.stderr)
        return 2
    lines, diffs, summary_diff, n = compare(old, new)
    for line in lines:
        print(line)
    if n == 0 and lines:
        print("no rows in common: nothing compared")
        return 1
    if not diffs and not summary_diff:
        print(f"{n} rows; IDENTICAL (times aside)")
        return 0
    print(f"{n} rows; {len(diffs)} differ" + (f"; the summary differs in {', '.join(summary_diff)}" if summary_diff else ""))
    for d in diffs[: args.max_rows]:
        print("  " + d)
    if len(diffs) > args.max_rows:
        print(f"  ... and {len(diffs) - args.max_rows} more")
    return 1


if __name__ == "__main__":
    sys.exit(main())
