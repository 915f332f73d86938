#!/usr/bin/python3
"""Tracking against per-frame estimation on synthetic moving-object sequences, in one run.

For each sequence (`posefilter synth --sequence`: a target sliding and turning on a table
among clutter, sensor noise and holes; the YCB-Video meshes of --models and the procedural
shapes, one per sequence in turn), this script runs
  track-auto     `posefilter track --prior auto`: frame 0 (and any lost frame) from the
                 no-detector stage 1, the others tracked;
  track-gt       `posefilter track --init-gt`: frame 0 from its ground truth, no stage 1;
  per-frame      `posefilter run-dataset --auto-prior`: every frame estimated from scratch with
                 the same stage 1;
and prints, per method, the frames found (ADD-S < 10 % of the diameter) and the median time
per object and frame (tracking: the tracker's own time per object; per-frame: run-dataset's
time per image, one object per image, stage 1 included).

usage: scripts/track_bench.py [--sequences N] [--frames F] [--first-seed S] [--speed M]
                              [--turn R] [--models DIR] [--out DIR] [--json FILE]
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SHAPES = ["lshape", "torus", "box", "cylinder"]
YCB = ["025_mug", "006_mustard_bottle", "035_power_drill", "010_potted_meat_can", "021_bleach_cleanser", "011_banana"]


def cli_path():
    for p in (os.environ.get("POSEFILTER_CLI"), os.path.join(HERE, "..", "build", "release", "posefilter")):
        if p and os.path.exists(p):
            return p
    sys.exit("track_bench: no posefilter CLI (build it with scripts/build.sh, or set POSEFILTER_CLI)")


def run(args, **kw):
    r = subprocess.run(args, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit("track_bench: failed: " + " ".join(args) + "\n" + r.stderr)
    return r.stdout


def track(cli, seq, extra):
    out = os.path.join(seq, "track_%s.csv" % extra[0].strip("-").replace("-", "_"))
    run([cli, "track", "--dataset", seq, "--csv", out, "--quiet"] + extra)
    rows = list(csv.DictReader(open(out)))
    return sum(r["found"] == "yes" for r in rows), len(rows), [float(r["time_ms"]) for r in rows]


def per_frame(cli, seq):
    out = os.path.join(seq, "per_frame.csv")
    if os.path.exists(out):
        os.remove(out)
    run([cli, "run-dataset", "--dataset", seq, "--auto-prior", "--out", out, "--quiet"])
    text = run([cli, "eval", "--dataset", seq, "--results", out, "--no-vsd", "--quiet", "--json", out + ".json"])
    j = json.load(open(out + ".json"))
    rows = list(csv.DictReader(open(out)))
    return j, [1000 * float(r["time"]) for r in rows], text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sequences", type=int, default=10)
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=501)
    ap.add_argument("--speed", type=float, default=0.01, help="slide per frame, m")
    ap.add_argument("--turn", type=float, default=0.05, help="turn per frame, rad")
    ap.add_argument("--models", default=os.path.join(os.environ.get("POSEFILTER_DATA") or os.path.join(HERE, "..", "..", "shared", "data"),
                                                     "ycbv", "models"),
                    help="the YCB-Video meshes (default: $POSEFILTER_DATA/ycbv/models, else ../shared/data/ycbv/models)")
    ap.add_argument("--out", default="/tmp/posefilter_track_bench")
    ap.add_argument("--json", help="also write the table as JSON")
    a = ap.parse_args()
    cli = cli_path()
    os.makedirs(a.out, exist_ok=True)
    targets = SHAPES + ([m for m in YCB if os.path.exists(os.path.join(a.models, m + ".ply"))])
    rows = []
    print("%-4s %-22s %12s %12s %12s %10s %10s %10s" % ("seq", "target", "track-auto", "track-gt", "per-frame",
                                                         "ms auto", "ms gt", "ms frame"))
    for i in range(a.sequences):
        seed = a.first_seed + i
        target = targets[i % len(targets)]
        seq = os.path.join(a.out, "seq_%d" % seed)
        kind = ["--target", target] if target in SHAPES else ["--mesh", os.path.join(a.models, target + ".ply")]
        run([cli, "synth", "--sequence", str(a.frames), "--out", seq, "--seed", str(seed), "--speed", str(a.speed),
             "--turn", str(a.turn), "--false-positives", "0"] + kind)
        fa, n, ta = track(cli, seq, ["--prior", "auto"])
        fg, _, tg = track(cli, seq, ["--init-gt"])
        j, tf, _ = per_frame(cli, seq)
        ff = round(j["overall"]["adds_recall"] * j["overall"]["n_instances"])
        row = dict(seed=seed, target=target, frames=n, track_auto=fa, track_gt=fg, per_frame=ff,
                   ms_auto=statistics.median(ta), ms_gt=statistics.median(tg), ms_per_frame=statistics.median(tf))
        rows.append(row)
        print("%-4d %-22s %12s %12s %12s %10.1f %10.1f %10.1f" % (seed, target, "%d/%d" % (fa, n), "%d/%d" % (fg, n),
                                                                 "%s/%d" % (ff, n), row["ms_auto"], row["ms_gt"],
                                                                 row["ms_per_frame"]))
        sys.stdout.flush()
    tot = sum(r["frames"] for r in rows)
    print("all: track-auto %d/%d, track-gt %d/%d, per-frame %d/%d; median ms per object and frame: %.1f, %.1f, %.1f" % (
        sum(r["track_auto"] for r in rows), tot, sum(r["track_gt"] for r in rows), tot,
        sum(r["per_frame"] for r in rows), tot, statistics.median(r["ms_auto"] for r in rows),
        statistics.median(r["ms_gt"] for r in rows), statistics.median(r["ms_per_frame"] for r in rows)))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
