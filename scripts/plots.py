#!/usr/bin/env python3
"""Figures of posefilter runs (PNG files), a command-line wrapper of posefilter.plots.

    scripts/plots.py demo --out build/plots [--scenes 4] [--particles 200 --iterations 10 ...]
        synthetic scenes → estimate → overlay grid, weight history, iteration times,
        prior heatmap/CDF/draws, recall curve
    scripts/plots.py recall --out recall.png EVAL.json [EVAL.json ...]
        recall vs threshold of `posefilter eval --json` outputs

Needs the built module: PYTHONPATH=build/release/python (set here automatically when that
folder exists) and an interpreter with numpy and matplotlib (Debian: /usr/bin/python3).
"""

import argparse
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def import_posefilter():
    try:
        import posefilter  # noqa: F401
    except ImportError:
        build = os.environ.get("POSEFILTER_BUILD_DIR", os.path.join(ROOT, "build", "release"))
        sys.path.insert(0, os.path.join(build, "python"))
        try:
            import posefilter  # noqa: F401
        except ImportError as e:
            sys.exit(f"plots.py: cannot import posefilter ({e}); build it (scripts/build.sh) and set "
                     f"PYTHONPATH=<build>/python, using an interpreter with numpy (e.g. /usr/bin/python3)")
    import posefilter
    import posefilter.plots
    return posefilter


def run_demo(args, pf):
    plots = pf.plots
    kinds = pf.synth_class_names()
    est = pf.Estimator(particles=args.particles, iterations=args.iterations, restarts=args.restarts,
                       seed=args.seed, threads=args.threads)
    panels, results, errors = [], [], []
    first = None
    for i in range(args.scenes):
        scene = pf.make_synth_scene(args.scene_seed + i, target=kinds[i % len(kinds)], occlusion=args.occlusion)
        first = first or scene
        r = est.estimate(scene.depth, scene.camera, scene.target, scene.prior)
        e = pf.pose_errors(scene.target, r.pose, scene.gt_poses[0])
        results.append(r)
        errors.append(e)
        print(f"scene {i}: {scene.target.name:9s} weight {r.weight:.3f}  ADD-S {1e3 * e.adds:6.1f} mm "
              f"({100 * e.adds / e.diameter:5.1f}% of diameter)  {r.time_ms:6.0f} ms")
        panels.append(dict(depth=scene.depth, camera=scene.camera, mesh=scene.target, estimate=r.pose,
                           gt=scene.gt_poses[0],
                           title=f"{scene.target.name}: ADD-S {1e3 * e.adds:.1f} mm, w {r.weight:.2f}"))
    out = args.out
    written = [
        plots.overlay_grid(panels, os.path.join(out, "overlays.png")),
        plots.weight_history(results, os.path.join(out, "weight_history.png")),
        plots.iteration_times(results, os.path.join(out, "iteration_times.png")),
        plots.prior_heatmap(first.prior, first.target.name, os.path.join(out, "prior.png"), n_samples=args.particles,
                            seed=args.seed, depth=first.depth, camera=first.camera, image=pf.shade_depth(first.depth)),
        plots.recall_curve(errors, os.path.join(out, "recall.png"), labels=["synthetic"]),
    ]
    for w in written:
        print("wrote", w)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("demo", help="synthetic scenes → every plot")
    d.add_argument("--out", required=True, help="folder for the PNGs")
    d.add_argument("--scenes", type=int, default=4)
    d.add_argument("--scene-seed", type=int, default=1)
    d.add_argument("--occlusion", type=float, default=0.2)
    d.add_argument("--particles", type=int, default=200)
    d.add_argument("--iterations", type=int, default=10)
    d.add_argument("--restarts", type=int, default=2)
    d.add_argument("--seed", type=int, default=1)
    d.add_argument("--threads", type=int, default=0)
    r = sub.add_parser("recall", help="recall vs threshold of `posefilter eval --json` files")
    r.add_argument("--out", required=True, help="PNG to write")
    r.add_argument("evals", nargs="+", help="eval JSON files")
    args = ap.parse_args()
    pf = import_posefilter()
    try:
        if args.cmd == "demo":
            if args.scenes < 1:
                ap.error("--scenes must be >= 1")
            run_demo(args, pf)
        else:
            print("wrote", pf.plots.recall_curve(args.evals, args.out))
    except (ValueError, OSError, KeyError) as e:
        sys.exit(f"plots.py: error: {e}")


if __name__ == "__main__":
    main()
