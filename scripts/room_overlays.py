#!/usr/bin/python3
"""The room world's pictures in docs/SYNTHETIC.md: posefilter's estimates drawn over a few rooms.

For each seed (from the tuning range 1-100, never the held-out 301 and up):
  1. `posefilter synth --world room --seed S` writes the scene (docs/SYNTHETIC.md);
  2. `posefilter estimate --prior auto` (no detector) with the mesh of each target class, the
     scene's rgb.png (its depth shaded, nearer brighter) as the background, `--overlay`: the
     estimates in green with a legend of their weights;
  3. `posefilter eval` against the targets' ground truth prints each estimate's ADD-S;
  4. the overlay, shrunk to --width pixels (area averaging, OpenCV), is written as
     OUT/room_<seed>.png (default OUT: docs/img).
The estimate runs with the CLI's defaults and --threads 2; the scenes and results stay in
--work (default build/room_overlays).

usage: scripts/room_overlays.py [--seeds 3,14,...] [--width 320] [--posefilter PATH]
                                [--models DIR] [--out DIR] [--work DIR]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_SEEDS = "1,3,10,15"


def fail(msg):
    print("room_overlays: error: " + msg, file=sys.stderr)
    sys.exit(1)


def run(cmd):
    print("== " + " ".join(cmd), flush=True)
    if subprocess.call(cmd) != 0:
        fail("failed: " + " ".join(cmd))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", default=DEFAULT_SEEDS, help="comma-separated room seeds (default %s)" % DEFAULT_SEEDS)
    ap.add_argument("--width", type=int, default=320, help="width of the pictures, pixels (default 320)")
    ap.add_argument("--posefilter", default=os.path.join(ROOT, "build", "release", "posefilter"))
    ap.add_argument("--models", default=os.path.join(os.environ.get("POSEFILTER_DATA") or os.path.join(ROOT, "..", "shared", "data"),
                                                     "ycbv", "models"),
                    help="the YCB-Video meshes (default: $POSEFILTER_DATA/ycbv/models, else ../shared/data/ycbv/models)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "img"), help="folder of the pictures (default docs/img)")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "room_overlays"), help="scenes and results")
    args = ap.parse_args()
    try:
        seeds = [int(s) for s in args.seeds.split(",") if s]
    except ValueError:
        fail("--seeds: comma-separated integers, e.g. %s" % DEFAULT_SEEDS)
    if not seeds or any(s < 1 for s in seeds):
        fail("--seeds: name at least one seed, each >= 1")
    if not 16 <= args.width <= 640:
        fail("--width must be in [16, 640] (the scenes are 640 px wide)")
    if not os.path.isdir(args.models):
        fail(args.models + ": no such folder (the YCB-Video meshes)")
    if not os.access(args.posefilter, os.X_OK):
        fail("no posefilter binary at %s (run scripts/build.sh)" % args.posefilter)
    try:
        import cv2
    except ImportError as e:  # pragma: no cover - depends on the machine
        fail("%s (install python3-opencv: scripts/setup.sh peers)" % e)
    os.makedirs(args.out, exist_ok=True)
    pf = args.posefilter
    for seed in seeds:
        scenes = os.path.join(args.work, "seed_%d" % seed)
        shutil.rmtree(scenes, ignore_errors=True)  # this script's own folder of the seed
        os.makedirs(scenes, exist_ok=True)
        run([pf, "synth", "--world", "room", "--models", args.models, "--seed", str(seed), "--count", "1",
             "--out", scenes])
        d = os.path.join(scenes, "scene_000")
        with open(os.path.join(d, "scene.json")) as f:
            info = json.load(f)
        with open(os.path.join(d, "gt.json")) as f:
            gt = json.load(f)
        targets = [(o, g) for o, g in zip(info["objects"], gt["objects"]) if o["target"]]
        classes = sorted({o["obj"] for o, _ in targets})
        meshes = []
        for c in classes:
            meshes += ["--mesh", "%s=%s" % (c, os.path.join(args.models, c + ".ply"))]
        gt_targets = os.path.join(d, "gt_targets.json")
        with open(gt_targets, "w") as f:
            json.dump(dict(gt, objects=[g for _, g in targets]), f, indent=1)
        overlay = os.path.join(d, "overlay.png")
        results = os.path.join(d, "results.json")
        run([pf, "estimate", "--depth", os.path.join(d, "depth.png"), "--camera", os.path.join(d, "camera.json"),
             "--prior", "auto", "--threads", "2", "--quiet", "--rgb", os.path.join(d, "rgb.png"),
             "--overlay", overlay, "--out", results] + meshes)
        run([pf, "eval", "--results", results, "--gt", gt_targets] + meshes)
        img = cv2.imread(overlay, cv2.IMREAD_COLOR)
        if img is None:
            fail("cannot read " + overlay)
        h = round(img.shape[0] * args.width / img.shape[1])
        small = cv2.resize(img, (args.width, h), interpolation=cv2.INTER_AREA)
        out = os.path.join(args.out, "room_%d.png" % seed)
        if not cv2.imwrite(out, small, [cv2.IMWRITE_PNG_COMPRESSION, 9]):
            fail("cannot write " + out)
        print("room_overlays: %s (%d x %d, %.0f KB; seed %d: %s)" % (
            out, args.width, h, os.path.getsize(out) / 1024, seed,
            ", ".join("%s %.0f%% visible" % (o["obj"], 100 * o["visible_fraction"]) for o, _ in targets)), flush=True)


if __name__ == "__main__":
    main()
