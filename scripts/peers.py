#!/usr/bin/python3
"""posefilter against a classical peer on the YCB table-top suite, in the same run.

The peer is the pipeline of Open3D's registration tutorial, as a robotics engineer would set
it up for a detected object (Debian's python3-open3d; `scripts/setup.sh peers` installs it):
  1. the scene's point cloud from the depth image, the dominant (table) plane removed
     (RANSAC, 8 mm), cropped to the pixels of the detection box (or of the instance mask; with
     --prior auto, no detector: the whole scene minus the plane, against posefilter's
     `--prior auto`);
  2. the model: points sampled on the mesh; both clouds voxel-downsampled (voxel = 1/20 of the
     object's diameter, at least 4 mm), normals, FPFH features;
  3. RANSAC over FPFH correspondences (edge-length and distance checkers, 100k iterations,
     confidence 0.999), then point-to-plane ICP;
  4. where a class has several boxes (a false box of the same class), every box is tried and
     the registration with the highest fitness wins.
Both methods get the same scenes and the same boxes (or masks): this script runs
`posefilter suite --world ycbv --write-scenes`, then the peer on the scenes written, and
prints per-class recall (ADD-S < 10 % of the diameter), AUC of ADD-S and time per object
side by side.

usage: scripts/peer_open3d.py [--count N] [--first-seed S] [--prior boxes|masks|auto]
                              [--models DIR] [--out DIR] [--json FILE] [-- SUITE OPTIONS...]
Options after `--` go to `posefilter suite` (e.g. filter options).
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print("peer_open3d: error: " + msg, file=sys.stderr)
    sys.exit(1)


try:
    import numpy as np
    import open3d as o3d
    from scipy.spatial import cKDTree
except ImportError as e:  # pragma: no cover - depends on the machine
    fail("%s (install the peer's packages with: scripts/setup.sh peers)" % e)


def load_json(path):
    with open(path) as f:
        return json.load(f)


def adds_error(points, T_est, T_gt):
    """ADD-S, metres: mean distance of each gt-posed point to the nearest estimated point."""
    gt = points @ T_gt[:3, :3].T + T_gt[:3, 3]
    est = points @ T_est[:3, :3].T + T_est[:3, 3]
    d, _ = cKDTree(est).query(gt, k=1)
    return float(d.mean())


def auc(errors, cap=0.1):
    """YCB-Video AUC of ADD-S (PoseCNN's VOCap, as posefilter's YcbvAuc)."""
    n = len(errors)
    d = sorted(e for e in errors if e <= cap)
    if n == 0 or not d:
        return 0.0
    area, prev = 0.0, 0.0
    for k, e in enumerate(d):
        if e != prev:
            area += (e - prev) * (k + 1) / n
        prev = e
    if cap != prev:
        area += (cap - prev) * len(d) / n
    return area / cap


def sample_surface(mesh, n):
    """n points uniformly on the mesh's surface (area-weighted faces, fixed seed)."""
    v = np.asarray(mesh.vertices)
    f = np.asarray(mesh.triangles)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    rng = np.random.default_rng(1)
    face = rng.choice(len(f), size=n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    return (1 - s)[:, None] * a[face] + (s * (1 - r2))[:, None] * b[face] + (s * r2)[:, None] * c[face]


class Peer:
    """Open3D FPFH + RANSAC + ICP, one model cache per class."""

    def __init__(self, models_dir):
        self.models_dir = models_dir
        self.cache = {}

    def model(self, cls):
        if cls not in self.cache:
            mesh = o3d.io.read_triangle_mesh(os.path.join(self.models_dir, cls + ".ply"))
            if len(mesh.triangles) == 0:
                fail("cannot read the mesh of " + cls)
            pts = np.asarray(mesh.vertices)
            diameter = float(np.linalg.norm(pts.max(0) - pts.min(0)))
            voxel = max(0.002, diameter / 70)
            pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(sample_surface(mesh, 20000)))
            down, fpfh = self.features(pcd, voxel)
            self.cache[cls] = (down, fpfh, voxel)
        return self.cache[cls]

    @staticmethod
    def features(pcd, voxel):
        down = pcd.voxel_down_sample(voxel)
        down.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2 * voxel, max_nn=30))
        fpfh = o3d.pipelines.registration.compute_fpfh_feature(
            down, o3d.geometry.KDTreeSearchParamHybrid(radius=5 * voxel, max_nn=100))
        return down, fpfh

    def register(self, scene_pts, cls):
        model, model_fpfh, voxel = self.model(cls)
        if len(scene_pts) < 30:
            return None, 0.0
        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(scene_pts))
        scene, scene_fpfh = self.features(pcd, voxel)
        if len(scene.points) < 10:
            return None, 0.0
        reg = o3d.pipelines.registration
        dist = 1.5 * voxel
        result = reg.registration_ransac_based_on_feature_matching(
            model, scene, model_fpfh, scene_fpfh, True, dist,
            reg.TransformationEstimationPointToPoint(False), 3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(dist)],
            reg.RANSACConvergenceCriteria(1000000, 0.999))
        icp = reg.registration_icp(model, scene, 1.5 * voxel, result.transformation,
                                   reg.TransformationEstimationPointToPlane())
        icp = reg.registration_icp(model, scene, 0.5 * voxel, icp.transformation,
                                   reg.TransformationEstimationPointToPlane())
        return np.asarray(icp.transformation), icp.fitness


def scene_points(depth, cam, pixels):
    """Camera-frame points of the given (v, u) pixel indices with valid depth."""
    v, u = pixels
    z = depth[v, u]
    keep = z > 0
    v, u, z = v[keep], u[keep], z[keep]
    return np.stack([(u - cam["cx"]) * z / cam["fx"], (v - cam["cy"]) * z / cam["fy"], z], axis=1)


def run_peer(scene_dirs, models_dir, prior):
    o3d.utility.random.seed(1)
    peer = Peer(models_dir)
    rows = []
    for d in scene_dirs:
        cam = load_json(os.path.join(d, "camera.json"))
        depth = np.asarray(o3d.io.read_image(os.path.join(d, "depth.png"))).astype(np.float64) * cam["depth_scale"]
        gt = load_json(os.path.join(d, "gt.json"))["objects"]
        info = load_json(os.path.join(d, "scene.json"))
        dets = load_json(os.path.join(d, "detections.json"))["detections"]
        masks = np.asarray(o3d.io.read_image(os.path.join(d, "mask.png"))) if prior == "masks" else None
        t0 = time.perf_counter()
        # The usual table-plane removal, once per scene.
        H, W = depth.shape
        all_pix = np.nonzero(depth > 0)
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(scene_points(depth, cam, all_pix)))
        _, inliers = cloud.segment_plane(distance_threshold=0.008, ransac_n=3, num_iterations=500)
        off_plane = np.ones(depth.shape, bool)
        off_plane[all_pix[0][inliers], all_pix[1][inliers]] = False
        plane_ms = 1000 * (time.perf_counter() - t0)
        n_targets = sum(1 for o in info["objects"] if o["target"])
        for obj, g in zip(info["objects"], gt):
            if not obj["target"]:
                continue
            cls = obj["obj"]
            t1 = time.perf_counter()
            regions = []
            if prior == "auto":  # no detector: the whole scene minus the table plane
                regions.append(off_plane)
            elif prior == "masks":
                regions.append((masks == obj["instance"]) & off_plane)
            else:
                for det in dets:
                    if det["class"] != cls:
                        continue
                    x, y, w, h = det["bbox"]
                    region = np.zeros(depth.shape, bool)
                    region[max(0, int(y)):min(H, int(np.ceil(y + h))), max(0, int(x)):min(W, int(np.ceil(x + w)))] = True
                    regions.append(region & off_plane)
            best, best_fit = None, -1.0
            for region in regions:
                T, fit = peer.register(scene_points(depth, cam, np.nonzero(region)), cls)
                if T is not None and fit > best_fit:
                    best, best_fit = T, fit
            ms = 1000 * (time.perf_counter() - t1) + plane_ms / max(1, n_targets)
            T_gt = np.eye(4)
            T_gt[:3, :3] = np.asarray(g["R"], float).reshape(3, 3)
            T_gt[:3, 3] = g["t"]
            rows.append({"scene": os.path.basename(d), "obj": cls, "T": best, "T_gt": T_gt, "time_ms": ms})
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count", type=int, default=20, help="scenes (default 20)")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--prior", choices=["boxes", "masks", "auto"], default="boxes")
    ap.add_argument("--models", default=os.path.join(ROOT, "..", "shared", "data", "ycbv", "models"))
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "peer_open3d"), help="scenes and results folder")
    ap.add_argument("--posefilter", default=os.path.join(ROOT, "build", "release", "posefilter"))
    ap.add_argument("--json", help="also write the comparison as JSON")
    args, suite_extra = ap.parse_known_args()
    if suite_extra and suite_extra[0] == "--":
        suite_extra = suite_extra[1:]
    if args.count < 1:
        fail("--count must be >= 1")
    if not os.path.isdir(args.models):
        fail(args.models + ": no such folder (the YCB-Video meshes)")
    if not os.access(args.posefilter, os.X_OK):
        fail("no posefilter binary at %s (run scripts/build.sh)" % args.posefilter)
    scenes = os.path.join(args.out, "scenes")
    os.makedirs(scenes, exist_ok=True)
    ours_json = os.path.join(args.out, "posefilter.json")
    cmd = [args.posefilter, "suite", "--world", "ycbv", "--count", str(args.count), "--first-seed",
           str(args.first_seed), "--prior", args.prior, "--models", args.models, "--write-scenes", scenes,
           "--json", ours_json] + suite_extra
    print("== posefilter: " + " ".join(cmd), flush=True)
    if subprocess.call(cmd) != 0:
        fail("posefilter suite failed")
    ours = load_json(ours_json)
    dirs = [os.path.join(scenes, "scene_%06d" % (args.first_seed + i)) for i in range(args.count)]
    print("== peer: Open3D %s FPFH + RANSAC + ICP on the same %d scenes" % (o3d.__version__, len(dirs)), flush=True)
    peer_rows = run_peer(dirs, args.models, args.prior)

    points, diameters = {}, {}
    for o in ours["objects"]:
        diameters[o["obj"]] = o["diameter_m"]
    per = {}
    for r in peer_rows:
        cls = r["obj"]
        if cls not in points:
            points[cls] = np.loadtxt(os.path.join(args.models, "points", cls + ".xyz"))
        err = float("inf") if r["T"] is None else adds_error(points[cls], r["T"], r["T_gt"])
        per.setdefault(cls, {"peer": [], "peer_ms": [], "ours": [], "ours_ms": []})
        per[cls]["peer"].append(err)
        per[cls]["peer_ms"].append(r["time_ms"])
    for o in ours["objects"]:
        e = o["adds_m"] if o["adds_m"] is not None else float("inf")
        per.setdefault(o["obj"], {"peer": [], "peer_ms": [], "ours": [], "ours_ms": []})
        per[o["obj"]]["ours"].append(e)
        per[o["obj"]]["ours_ms"].append(o["time_ms"])

    def found(errs, cls):
        return sum(1 for e in errs if e < 0.1 * diameters[cls])

    print("\n%-22s %4s | %-23s | %-23s" % ("", "", "posefilter", "Open3D FPFH+RANSAC+ICP"))
    print("%-22s %4s | %6s %6s %9s | %6s %6s %9s" % ("class", "n", "recall", "AUC", "med[ms]",
                                                    "recall", "AUC", "med[ms]"))
    tot = {"n": 0, "ours": 0, "peer": 0}
    all_o, all_p, all_om, all_pm = [], [], [], []
    summary = {}
    for cls in sorted(per):
        p = per[cls]
        n = len(p["ours"])
        fo, fp = found(p["ours"], cls), found(p["peer"], cls)
        tot["n"] += n
        tot["ours"] += fo
        tot["peer"] += fp
        all_o += p["ours"]
        all_p += p["peer"]
        all_om += p["ours_ms"]
        all_pm += p["peer_ms"]
        print("%-22s %4d | %5.0f%% %6.1f %9.0f | %5.0f%% %6.1f %9.0f" % (
            cls, n, 100.0 * fo / n, 100 * auc(p["ours"]), np.median(p["ours_ms"]),
            100.0 * fp / max(1, len(p["peer"])), 100 * auc(p["peer"]), np.median(p["peer_ms"])))
        summary[cls] = {"n": n, "posefilter_found": fo, "peer_found": fp}
    n = tot["n"]
    print("%-22s %4d | %5.1f%% %6.1f %9.0f | %5.1f%% %6.1f %9.0f" % (
        "all", n, 100.0 * tot["ours"] / n, 100 * auc(all_o), np.median(all_om),
        100.0 * tot["peer"] / n, 100 * auc(all_p), np.median(all_pm)))
    print("median time per object: posefilter %.0f ms, peer %.0f ms (%.1fx)" % (
        np.median(all_om), np.median(all_pm), np.median(all_pm) / max(1e-9, np.median(all_om))))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"prior": args.prior, "count": args.count, "first_seed": args.first_seed,
                       "targets": n, "posefilter": {"found": tot["ours"], "auc_adds": auc(all_o),
                                                    "median_time_ms": float(np.median(all_om))},
                       "open3d": {"found": tot["peer"], "auc_adds": auc(all_p),
                                  "median_time_ms": float(np.median(all_pm))},
                       "classes": summary}, f, indent=1)


if __name__ == "__main__":
    main()
