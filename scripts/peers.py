#!/usr/bin/python3
"""posefilter against classical peers on the YCB table-top or room suite, in the same run.

Peers (`--peers`, default both; `scripts/setup.sh peers` installs their packages):
  open3d      the pipeline of Open3D's registration tutorial, as a robotics engineer would set
              it up for a detected object (Debian's python3-open3d):
                1. the scene's point cloud from the depth image, the dominant (table) plane
                   removed (RANSAC, 8 mm), cropped to the pixels of the detection box (or of the
                   instance mask; with --prior auto, no detector: the whole scene minus the
                   plane, against posefilter's `--prior auto`);
                2. the model: points sampled on the mesh; both clouds voxel-downsampled (voxel =
                   1/70 of the object's diameter, at least 2 mm), normals, FPFH features;
                3. RANSAC over FPFH correspondences (edge-length and distance checkers, 1M
                   iterations, confidence 0.999), then point-to-plane ICP;
  opencv-ppf  OpenCV's point-pair-feature detector (Drost et al. 2010; Debian's python3-opencv,
              cv2.ppf_match_3d), fed millimetres (in metres its pose clustering merges every
              vote): the model is 500 points (--opencv-model-points) sampled on the mesh with
              the mesh's normals (OpenCV's training time grows steeply: 1200 take a minute); the
              scene is the same cloud as open3d's, voxel-downsampled to 1/20 of the diameter
              with normals facing the camera; match (every 5th scene point a reference), the 5
              best poses refined by OpenCV's ICP, the lowest residual wins. OpenCV re-samples
              the scene on a grid relative to the scene's bounding box (relativeSceneDistance).
              --opencv-scene-sampling model (default) keeps the 1/20-diameter voxels, the
              model's own step, as Drost et al. sample model and scene (posefilter does too);
              `scene` passes OpenCV's usual 0.05, cells of 5 % of the whole scene's extent
              (a median 8 x 4 x 13 cm on the YCB table-top suite: fast, but coarser than every
              object's own step).
              Training is model preparation and is not counted in the time per object.
What the peers see (--world; the detection boxes or masks are cut from it):
  ycbv        the table world: the scene minus its dominant plane, the table (RANSAC, 8 mm).
  room        the room world: there is no one table plane; the dominant plane is often the floor
              or a wall, and the objects stand on a small tablet, stool or shelf board. The
              peers get what a user without a detector would give them: the points within 2 m
              of the camera (--max-depth; the world puts the objects' centre 0.5-1.5 m away,
              the sensor reads to 3.5 m), minus every plane larger than any object's face.
              Planes are found by repeated RANSAC (1 cm, on a 1 cm voxel grid of those points,
              at most 16 planes, until one holds under 100 voxels); a plane's points are those
              within its slab (8 mm at 1 m, growing as z^2 with the sensor's noise) whose normal
              is within 30 degrees of the plane's (an object's sides standing on it are not),
              the plane refit to them once by least squares. A plane is removed when one
              connected patch of it in the image covers at least 0.04 m^2 (--large-plane; the
              largest face of a YCB-Video object, the cracker box's, is 0.035 m^2), each point
              counted by its footprint on the plane, (z/fx)(z/fy)/cos of the viewing angle. So
              the floor, walls, desk tops, shelf boards and panels and the larger supports go;
              a support smaller than that (a stool's top of 20 cm, or one its objects hide)
              stays, as clutter beside the objects, and the furniture's legs and edges, the
              distractors and the other objects stay in any case. posefilter gets the whole
              image, as always.
Where a class has several boxes (a false box of the same class), every box is tried and the
registration with the highest fitness (open3d) or the lowest residual (opencv-ppf) wins.
All methods get the same scenes and the same boxes (or masks): this script runs
`posefilter suite --world ycbv|room --write-scenes`, then each peer on the scenes written,
and prints per-class recall (ADD-S < 10 % of the diameter), AUC of ADD-S and time per object
side by side. The peers' time per object includes its share of the scene's plane removal.

usage: scripts/peers.py [--world ycbv|room] [--count N] [--first-seed S]
                        [--prior boxes|masks|auto] [--peers open3d,opencv-ppf]
                        [--opencv-model-points N] [--opencv-scene-sampling model|scene]
                        [--max-depth M] [--large-plane A] [--models DIR]
                        [--posefilter PATH] [--out DIR] [--json FILE]
                        [--reuse-posefilter] [-- SUITE OPTIONS...]
Options after `--` go to `posefilter suite` (e.g. filter options). --reuse-posefilter skips the
suite and takes its scenes and results from an earlier run into the same --out: the peers of
one suite run can then run as separate processes, or on a subset of its seeds.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print("peers: error: " + msg, file=sys.stderr)
    sys.exit(1)


try:
    import numpy as np
    import open3d as o3d
    from scipy import ndimage
    from scipy.spatial import cKDTree
except ImportError as e:  # pragma: no cover - depends on the machine
    fail("%s (install the peers' packages with: scripts/setup.sh peers)" % e)


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


def load_mesh(models_dir, cls):
    """The class's mesh (metres) and its bounding-box diagonal as the diameter."""
    mesh = o3d.io.read_triangle_mesh(os.path.join(models_dir, cls + ".ply"))
    if len(mesh.triangles) == 0:
        fail("cannot read the mesh of " + cls)
    pts = np.asarray(mesh.vertices)
    return mesh, float(np.linalg.norm(pts.max(0) - pts.min(0)))


class Peer:
    """Open3D FPFH + RANSAC + ICP, one model cache per class."""

    def __init__(self, models_dir):
        self.models_dir = models_dir
        self.cache = {}

    def model(self, cls):
        if cls not in self.cache:
            mesh, diameter = load_mesh(self.models_dir, cls)
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


class OpenCvPpfPeer:
    """OpenCV's PPF detector + ICP, one trained detector per class (millimetres)."""

    def __init__(self, models_dir, model_points=500, scene_sampling="model"):
        try:
            import cv2
        except ImportError as e:  # pragma: no cover - depends on the machine
            fail("%s (install the peers' packages with: scripts/setup.sh peers)" % e)
        self.cv2 = cv2
        self.models_dir = models_dir
        self.model_points = model_points
        self.scene_sampling = scene_sampling
        self.cache = {}
        self.train_s = {}

    def model(self, cls):
        if cls not in self.cache:
            mesh, diameter = load_mesh(self.models_dir, cls)
            mesh.compute_vertex_normals()
            o3d.utility.random.seed(1)
            pcd = mesh.sample_points_uniformly(self.model_points)
            model = np.hstack([np.asarray(pcd.points) * 1000, np.asarray(pcd.normals)]).astype(np.float32)
            detector = self.cv2.ppf_match_3d_PPF3DDetector(0.05, 0.05)
            t0 = time.perf_counter()
            detector.trainModel(model)
            self.train_s[cls] = time.perf_counter() - t0
            self.cache[cls] = (detector, model, diameter)
        return self.cache[cls]

    def register(self, scene_pts, cls):
        detector, model, diameter = self.model(cls)
        if len(scene_pts) < 30:
            return None, 0.0
        voxel = max(0.002, diameter / 20)  # metres: the model's step
        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(scene_pts)).voxel_down_sample(voxel)
        if len(pcd.points) < 10:
            return None, 0.0
        pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=diameter / 10, max_nn=30))
        pcd.orient_normals_towards_camera_location(np.zeros(3))
        scene = np.hstack([np.asarray(pcd.points) * 1000, np.asarray(pcd.normals)]).astype(np.float32)
        if self.scene_sampling == "model":
            # OpenCV's grid cell on each axis is relativeSceneDistance × that axis's extent: half
            # the voxel over the longest axis keeps (nearly) every voxel of side diameter / 20.
            extent = float(np.max(scene[:, :3].max(axis=0) - scene[:, :3].min(axis=0)))
            relative = min(1.0, 0.5 * 1000 * voxel / max(extent, 1e-9))
        else:
            relative = 0.05
        results = detector.match(scene, 1.0 / 5.0, relative)
        if not results:
            return None, 0.0
        icp = self.cv2.ppf_match_3d_ICP(100)
        _, results = icp.registerModelToScene(model, scene, results[:5])
        best = min(results, key=lambda r: r.residual)
        T = np.array(best.pose, dtype=np.float64)
        T[:3, 3] /= 1000.0
        return T, -float(best.residual)  # higher is better, as open3d's fitness


def scene_points(depth, cam, pixels):
    """Camera-frame points of the given (v, u) pixel indices with valid depth."""
    v, u = pixels
    z = depth[v, u]
    keep = z > 0
    v, u, z = v[keep], u[keep], z[keep]
    return np.stack([(u - cam["cx"]) * z / cam["fx"], (v - cam["cy"]) * z / cam["fy"], z], axis=1)


def table_off_plane(depth, cam):
    """--world ycbv: the pixels off the dominant (table) plane (RANSAC, 8 mm)."""
    all_pix = np.nonzero(depth > 0)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(scene_points(depth, cam, all_pix)))
    _, inliers = cloud.segment_plane(distance_threshold=0.008, ransac_n=3, num_iterations=500)
    off_plane = np.ones(depth.shape, bool)
    off_plane[all_pix[0][inliers], all_pix[1][inliers]] = False
    return off_plane


def pixel_normals(depth, cam, window=15):
    """Unit normals of the depth image's points (camera frame), from the covariance of the
    valid points in a window x window neighbourhood (box filters); None where under 60 % of
    the window is valid (edges, holes)."""
    H, W = depth.shape
    v, u = np.mgrid[0:H, 0:W]
    valid = (depth > 0).astype(float)
    xyz = [(u - cam["cx"]) * depth / cam["fx"], (v - cam["cy"]) * depth / cam["fy"], depth]

    def mean(a):
        return ndimage.uniform_filter(a, window, mode="reflect")

    w = mean(valid)
    ok = (depth > 0) & (w > 0.6)
    m = [mean(a)[ok] / w[ok] for a in xyz]
    C = np.empty((int(ok.sum()), 3, 3))
    for i in range(3):
        for j in range(i, 3):
            C[:, i, j] = C[:, j, i] = mean(xyz[i] * xyz[j])[ok] / w[ok] - m[i] * m[j]
    normals = np.zeros((H, W, 3))
    normals[ok] = np.linalg.eigh(C)[1][:, :, 0]
    return normals, ok


def room_off_planes(depth, cam, max_depth, large_plane_m2):
    """--world room: the pixels within max_depth that lie on no plane of at least large_plane_m2.

    Repeated RANSAC (1 cm) on a 1 cm voxel grid of the points. A plane's points are those
    within its slab (8 mm at 1 m, growing as z^2 with the sensor's noise) whose normal (15 x 15
    pixel neighbourhood) is within 30 degrees of the plane's (so an object's sides standing on
    it are not), the plane refit to them by least squares once. Each plane's slab leaves the
    search; when its points hold a patch, 8-connected in the image, of at least large_plane_m2
    (each point counted by its footprint on the plane, (z/fx)(z/fy) over the cosine of its
    viewing angle), they are removed from the scene. At most 16 planes; it stops at a plane
    of under 100 voxels.
    """
    pix = np.nonzero((depth > 0) & (depth <= max_depth))
    pts = scene_points(depth, cam, pix)
    keep = np.ones(len(pts), bool)
    if len(pts) >= 100:
        normals, has_normal = pixel_normals(depth, cam)
        normals, has_normal = normals[pix], has_normal[pix]
        footprint = (pts[:, 2] / cam["fx"]) * (pts[:, 2] / cam["fy"])
        ray = np.linalg.norm(pts, axis=1)
        slab = 0.008 * np.maximum(1.0, pts[:, 2] ** 2)
        pool = np.asarray(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts)).voxel_down_sample(0.01).points)
        cos30 = np.cos(np.radians(30))
        for _ in range(16):
            if len(pool) < 100:
                break
            plane, inliers = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pool)).segment_plane(
                distance_threshold=0.01, ransac_n=3, num_iterations=1000)
            if len(inliers) < 100:
                break
            n = np.asarray(plane[:3], float)
            n, d = n / np.linalg.norm(n), plane[3] / np.linalg.norm(n)
            on = has_normal & (np.abs(pts @ n + d) < slab) & (np.abs(normals @ n) > cos30)
            if on.sum() >= 3:  # least-squares refit: the normal of the points' covariance
                c = pts[on].mean(axis=0)
                n_fit = np.linalg.eigh(np.cov((pts[on] - c).T))[1][:, 0]
                n, d = n_fit, -float(n_fit @ c)
                on = has_normal & (np.abs(pts @ n + d) < slab) & (np.abs(normals @ n) > cos30)
            pool_z = np.maximum(1.0, pool[:, 2] ** 2)
            rest = np.abs(pool @ n + d) >= 0.008 * pool_z
            rest[inliers] = False
            pool = pool[rest]
            if not on.any():
                continue
            cos = np.maximum(np.abs(pts[on] @ n) / ray[on], 0.1)
            image = np.zeros(depth.shape, bool)
            image[pix[0][on], pix[1][on]] = True
            patches, _ = ndimage.label(image, structure=np.ones((3, 3), int))
            area = np.bincount(patches[pix[0][on], pix[1][on]], weights=footprint[on] / cos)
            if area.max() >= large_plane_m2:
                keep &= ~on
    off_planes = np.zeros(depth.shape, bool)
    off_planes[pix[0][keep], pix[1][keep]] = True
    return off_planes


def run_peer(peer, scene_dirs, prior, world="ycbv", max_depth=2.0, large_plane_m2=0.04):
    o3d.utility.random.seed(1)
    rows = []
    for d in scene_dirs:
        cam = load_json(os.path.join(d, "camera.json"))
        depth = np.asarray(o3d.io.read_image(os.path.join(d, "depth.png"))).astype(np.float64) * cam["depth_scale"]
        gt = load_json(os.path.join(d, "gt.json"))["objects"]
        info = load_json(os.path.join(d, "scene.json"))
        dets = load_json(os.path.join(d, "detections.json"))["detections"]
        masks = np.asarray(o3d.io.read_image(os.path.join(d, "mask.png"))) if prior == "masks" else None
        t0 = time.perf_counter()
        # The usual table-plane removal (in a room: the working range minus every large
        # plane), once per scene.
        H, W = depth.shape
        off_plane = (table_off_plane(depth, cam) if world == "ycbv"
                     else room_off_planes(depth, cam, max_depth, large_plane_m2))
        plane_ms = 1000 * (time.perf_counter() - t0)
        n_targets = sum(1 for o in info["objects"] if o["target"])
        for obj, g in zip(info["objects"], gt):
            if not obj["target"]:
                continue
            cls = obj["obj"]
            t1 = time.perf_counter()
            regions = []
            if prior == "auto":  # no detector: the whole scene minus the table plane (room: planes)
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
            best, best_fit = None, -float("inf")
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


PEERS = {"open3d": ("Open3D FPFH+RANSAC+ICP", Peer), "opencv-ppf": ("OpenCV PPF+ICP", OpenCvPpfPeer)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--world", choices=["ycbv", "room"], default="ycbv",
                    help="the suite: ycbv, the YCB table-top world (default), or room (docs/SYNTHETIC.md)")
    ap.add_argument("--count", type=int, default=20, help="scenes (default 20)")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--prior", choices=["boxes", "masks", "auto"], default="boxes")
    ap.add_argument("--peers", default="open3d,opencv-ppf", help="comma-separated: open3d, opencv-ppf")
    ap.add_argument("--opencv-model-points", type=int, default=500,
                    help="opencv-ppf: model points (default 500; its training time grows steeply: 1200 take a minute)")
    ap.add_argument("--opencv-scene-sampling", choices=["model", "scene"], default="model",
                    help="opencv-ppf: the scene's grid: the model's step, diameter/20 (default), or "
                         "0.05 of the scene's extent (OpenCV's usual relativeSceneDistance)")
    ap.add_argument("--max-depth", type=float,
                    help="room: the peers' working range, metres from the camera (default 2)")
    ap.add_argument("--large-plane", type=float,
                    help="room: planes covering at least this many m^2 are removed for the peers (default 0.04)")
    ap.add_argument("--models", default=os.path.join(os.environ.get("POSEFILTER_DATA") or os.path.join(ROOT, "..", "shared", "data"),
                                                     "ycbv", "models"),
                    help="the YCB-Video meshes (default: $POSEFILTER_DATA/ycbv/models, else ../shared/data/ycbv/models)")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "peers"), help="scenes and results folder")
    ap.add_argument("--posefilter", default=os.path.join(ROOT, "build", "release", "posefilter"))
    ap.add_argument("--json", help="also write the comparison as JSON")
    ap.add_argument("--reuse-posefilter", action="store_true",
                    help="do not run the suite: reuse the scenes and posefilter.json that an earlier run wrote to "
                         "--out (same --world and --prior, covering the seeds asked for)")
    args, suite_extra = ap.parse_known_args()
    if suite_extra and suite_extra[0] == "--":
        suite_extra = suite_extra[1:]
    if args.count < 1:
        fail("--count must be >= 1")
    if args.opencv_model_points < 10:
        fail("--opencv-model-points must be >= 10")
    if args.world == "ycbv" and (args.max_depth is not None or args.large_plane is not None):
        fail("--max-depth and --large-plane apply to --world room (the table world removes the table plane)")
    max_depth = 2.0 if args.max_depth is None else args.max_depth
    large_plane = 0.04 if args.large_plane is None else args.large_plane
    if not max_depth > 0.35:
        fail("--max-depth must be above 0.35 (metres; the sensor reads from 0.35 m)")
    if not large_plane > 0:
        fail("--large-plane must be > 0 (m^2)")
    peers = [p for p in args.peers.split(",") if p]
    for p in peers:
        if p not in PEERS:
            fail("--peers: unknown peer '%s' (known: %s)" % (p, ", ".join(PEERS)))
    if not peers:
        fail("--peers: name at least one peer")
    if not os.path.isdir(args.models):
        fail(args.models + ": no such folder (the YCB-Video meshes)")
    scenes = os.path.join(args.out, "scenes")
    ours_json = os.path.join(args.out, "posefilter.json")
    seeds = set(range(args.first_seed, args.first_seed + args.count))
    dirs = [os.path.join(scenes, "scene_%06d" % s) for s in sorted(seeds)]
    if args.reuse_posefilter:
        # The suite's results and scenes of an earlier run into --out (e.g. the peers of that run
        # in processes of their own): the same world and prior, every seed asked for.
        if suite_extra:
            fail("--reuse-posefilter: the suite does not run, so it takes no options after --")
        if not os.path.isfile(ours_json):
            fail("--reuse-posefilter: no posefilter.json in %s (run without it first)" % args.out)
        ours = load_json(ours_json)
        if ours.get("world") != args.world or ours.get("prior") != args.prior:
            fail("--reuse-posefilter: %s is of --world %s --prior %s" % (ours_json, ours.get("world"), ours.get("prior")))
        missing = sorted(seeds - {o["seed"] for o in ours["objects"]}) + [d for d in dirs if not os.path.isdir(d)]
        if missing:
            fail("--reuse-posefilter: %s lacks %s" % (args.out, ", ".join(str(m) for m in missing[:5])))
        ours["objects"] = [o for o in ours["objects"] if o["seed"] in seeds]
        print("== posefilter: its results in %s, reused (the suite does not run)" % ours_json, flush=True)
    else:
        if not os.access(args.posefilter, os.X_OK):
            fail("no posefilter binary at %s (run scripts/build.sh)" % args.posefilter)
        os.makedirs(scenes, exist_ok=True)
        cmd = [args.posefilter, "suite", "--world", args.world, "--count", str(args.count), "--first-seed",
               str(args.first_seed), "--prior", args.prior, "--models", args.models, "--write-scenes", scenes,
               "--json", ours_json] + suite_extra
        print("== posefilter: " + " ".join(cmd), flush=True)
        if subprocess.call(cmd) != 0:
            fail("posefilter suite failed")
        ours = load_json(ours_json)
    peer_rows, train_s = {}, {}
    for name in peers:
        title, cls = PEERS[name]
        print("== peer: %s on the same %d scenes" % (title, len(dirs)), flush=True)
        peer = (cls(args.models, args.opencv_model_points, args.opencv_scene_sampling) if name == "opencv-ppf"
                else cls(args.models))
        peer_rows[name] = run_peer(peer, dirs, args.prior, args.world, max_depth, large_plane)
        train_s[name] = getattr(peer, "train_s", {})

    points, diameters = {}, {}
    for o in ours["objects"]:
        diameters[o["obj"]] = o["diameter_m"]
    methods = ["posefilter"] + peers
    per = {}

    def add(cls, method, err, ms):
        per.setdefault(cls, {m: ([], []) for m in methods})
        per[cls][method][0].append(err)
        per[cls][method][1].append(ms)

    for name in peers:
        for r in peer_rows[name]:
            cls = r["obj"]
            if cls not in points:
                points[cls] = np.loadtxt(os.path.join(args.models, "points", cls + ".xyz"))
            err = float("inf") if r["T"] is None else adds_error(points[cls], r["T"], r["T_gt"])
            add(cls, name, err, r["time_ms"])
    for o in ours["objects"]:  # posefilter's time: its estimate and its share of the scene's stage 1
        add(o["obj"], "posefilter", o["adds_m"] if o["adds_m"] is not None else float("inf"),
            o["time_ms"] + o.get("stage1_ms", 0.0))

    def found(errs, cls):
        return sum(1 for e in errs if e < 0.1 * diameters[cls])

    head = "%-22s %4s" % ("", "")
    sub = "%-22s %4s" % ("class", "n")
    for m in methods:
        head += " | %-23s" % (m if m == "posefilter" else PEERS[m][0])[:23]
        sub += " | %6s %6s %9s" % ("recall", "AUC", "med[ms]")
    print("\n" + head + "\n" + sub)
    totals = {m: {"found": 0, "errs": [], "ms": []} for m in methods}
    n_all = 0
    summary = {}
    for cls in sorted(per):
        n = len(per[cls]["posefilter"][0])
        n_all += n
        line = "%-22s %4d" % (cls, n)
        summary[cls] = {"n": n}
        for m in methods:
            errs, ms = per[cls][m]
            f = found(errs, cls)
            totals[m]["found"] += f
            totals[m]["errs"] += errs
            totals[m]["ms"] += ms
            summary[cls][m + "_found"] = f
            line += " | %5.0f%% %6.1f %9.0f" % (100.0 * f / max(1, len(errs)), 100 * auc(errs),
                                                np.median(ms) if ms else 0)
        print(line)
    line = "%-22s %4d" % ("all", n_all)
    for m in methods:
        t = totals[m]
        line += " | %5.1f%% %6.1f %9.0f" % (100.0 * t["found"] / n_all, 100 * auc(t["errs"]), np.median(t["ms"]))
    print(line)
    ours_ms = np.median(totals["posefilter"]["ms"])
    # --prior auto: the share of the depth-only stage 1 in posefilter's time.
    stage1 = [o["stage1_ms"] for o in ours["objects"] if "stage1_ms" in o] if args.prior == "auto" else []
    if stage1:
        print("posefilter's stage 1 (regions + point-pair features): mean %.0f ms per object" % np.mean(stage1))
    for m in peers:
        print("median time per object: posefilter %.0f ms, %s %.0f ms (%.1fx)" % (
            ours_ms, PEERS[m][0], np.median(totals[m]["ms"]), np.median(totals[m]["ms"]) / max(1e-9, ours_ms)))
        if train_s[m]:
            print("  %s model preparation (not in the time per object): %.1f s per model on average" % (
                PEERS[m][0], sum(train_s[m].values()) / len(train_s[m])))
    if args.json:
        out = {"world": args.world, "prior": args.prior, "count": args.count, "first_seed": args.first_seed, "targets": n_all,
               "opencv_scene_sampling": args.opencv_scene_sampling, "classes": summary}
        for m in methods:
            t = totals[m]
            out[m] = {"found": t["found"], "auc_adds": auc(t["errs"]), "median_time_ms": float(np.median(t["ms"]))}
            if m in train_s and train_s[m]:
                out[m]["model_preparation_s"] = train_s[m]
        if stage1:
            out["posefilter"]["stage1_mean_ms"] = float(np.mean(stage1))
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
