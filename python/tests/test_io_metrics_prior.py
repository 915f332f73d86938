"""Round trips (depth/RGB PNG, meshes, JSON), metrics, poses, priors, rendering."""

import math

import numpy as np
import pytest

import posefilter as pf


def test_depth_png_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    scale = 0.0001
    depth = (rng.integers(0, 30000, size=(30, 40)) * scale).astype(np.float32)
    depth[3, 4] = 0  # missing stays missing
    path = str(tmp_path / "depth.png")
    pf.save_depth_png(depth, path, scale)
    back = pf.load_depth_png(path, scale)
    assert back.dtype == np.float32 and back.shape == (30, 40)
    np.testing.assert_allclose(back, depth, atol=scale / 2 + 1e-7)
    assert back[3, 4] == 0
    # Another scale reads the same integers.
    np.testing.assert_allclose(pf.load_depth_png(path, 2 * scale), 2 * back, rtol=1e-6)
    with pytest.raises(ValueError, match="NaN"):
        pf.save_depth_png(np.full((2, 2), np.nan, np.float32), path, scale)


def test_rgb_png_round_trip(tmp_path):
    img = np.random.default_rng(1).integers(0, 256, size=(12, 17, 3), dtype=np.uint8)
    path = str(tmp_path / "rgb.png")
    pf.save_rgb_png(img, path)
    np.testing.assert_array_equal(pf.load_rgb_png(path), img)
    with pytest.raises(ValueError, match="uint8"):
        pf.save_rgb_png(img.astype(np.float32), path)
    with pytest.raises(ValueError, match=r"\(H, W, 3\)"):
        pf.save_rgb_png(img[..., :2].copy(), path)


def test_mesh_round_trip_and_units(tmp_path):
    box = pf.make_box(0.1, 0.2, 0.3, name="crate")
    assert box.vertices.shape == (8, 3) and box.faces.shape == (12, 3)
    assert box.diameter() == pytest.approx(math.sqrt(0.01 + 0.04 + 0.09), rel=1e-6)
    lo, hi = box.bounds()
    np.testing.assert_allclose(hi - lo, [0.1, 0.2, 0.3], rtol=1e-6)
    path = tmp_path / "crate.ply"
    box.save_ply(str(path))
    back = pf.load_mesh(path)
    assert back.name == "crate"
    np.testing.assert_allclose(back.vertices, box.vertices, atol=1e-7)
    mm = pf.load_mesh(str(path), units="mm", name="tiny")
    assert mm.name == "tiny"
    np.testing.assert_allclose(mm.vertices, box.vertices * 1e-3, atol=1e-9)
    np.testing.assert_allclose(pf.load_mesh(str(path), units=10.0).vertices, box.vertices * 10, rtol=1e-6)
    # A mesh from arrays equals the one it was copied from.
    copy = pf.Mesh(box.vertices, box.faces.astype(np.int64), name="copy")
    np.testing.assert_array_equal(copy.faces, box.faces)
    assert copy.diameter() == box.diameter()


def test_json_round_trips(tmp_path):
    cam = pf.Camera(fx=500, fy=510, cx=320.5, cy=240.5, width=640, height=480,
                    base_to_camera=pf.pose_to_transform([0.1, 0, 0.5, 0.2, 0, 0]))
    pf.write_camera_json(cam, str(tmp_path / "camera.json"), 0.001)
    back, scale = pf.read_camera_json(str(tmp_path / "camera.json"))
    assert scale == 0.001 and (back.fx, back.fy, back.cx, back.cy) == (500, 510, 320.5, 240.5)
    np.testing.assert_allclose(back.base_to_camera, cam.base_to_camera, atol=1e-12)
    T = pf.pose_to_transform([0.1, -0.2, 0.8, 0.3, -0.4, 1.0])
    pf.write_gt_json([("mug", T)], str(tmp_path / "gt.json"))
    [(obj, T_back)] = pf.read_gt_json(str(tmp_path / "gt.json"))
    assert obj == "mug"
    np.testing.assert_allclose(T_back, T, atol=1e-9)
    dets = [pf.Detection("mug", 0.75, (10, 20, 30, 40)), pf.Detection("box", 0.25, (1, 2, 3, 4))]
    pf.write_detections_json(dets, str(tmp_path / "d.json"))
    back_d = pf.read_detections_json(str(tmp_path / "d.json"))
    assert [(d.cls, d.score, d.bbox) for d in back_d] == [(d.cls, d.score, d.bbox) for d in dets]


def test_pose_conversions():
    p = np.array([0.1, -0.2, 0.8, 0.3, -0.4, 1.0])
    T = pf.pose_to_transform(p)
    np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(T[:3, 3], p[:3])
    np.testing.assert_allclose(pf.transform_to_pose(T), p, atol=1e-12)
    # Rz(yaw) alone: x axis turns towards y.
    Tz = pf.pose_to_transform([0, 0, 0, 0, 0, math.pi / 2])
    np.testing.assert_allclose(Tz[:3, 0], [0, 1, 0], atol=1e-12)
    assert pf.wrap_angle(3 * math.pi) == pytest.approx(math.pi)


def test_metrics():
    box = pf.make_box(0.1, 0.1, 0.1)
    T = pf.pose_to_transform([0, 0, 1, 0, 0, 0])
    shifted = T.copy()
    shifted[0, 3] += 0.01
    assert pf.add_error(box, T, T) == 0
    assert pf.add_error(box, shifted, T) == pytest.approx(0.01, rel=1e-6)
    # A cube turned a quarter about z has the same vertex set: ADD-S 0, ADD large.
    turned = T @ pf.pose_to_transform([0, 0, 0, 0, 0, math.pi / 2])
    assert pf.adds_error(box, turned, T) < 1e-6 < pf.add_error(box, turned, T)
    assert pf.rotation_error_deg(turned[:3, :3], T[:3, :3]) == pytest.approx(90)
    assert pf.translation_error([0, 0, 1], [0, 0.03, 1.04]) == pytest.approx(0.05)
    e = pf.pose_errors(box, shifted, T)
    assert e.diameter == pytest.approx(box.diameter()) and e.add_ok and e.adds_ok
    e = pf.pose_errors(box, shifted, T, threshold=0.01)
    assert not e.add_ok
    pts = pf.sample_points(box, max_points=4)
    assert pts.shape == (4, 3)
    assert pf.add_error(pts, shifted, T) == pytest.approx(0.01, rel=1e-6)


def test_xyz_points(tmp_path):
    path = tmp_path / "p.xyz"
    path.write_text("0 0 0\n1 2 3\n\n")
    np.testing.assert_array_equal(pf.read_xyz_points(str(path)), [[0, 0, 0], [1, 2, 3]])
    path.write_text("0 0\n")
    with pytest.raises(ValueError, match="p.xyz"):
        pf.read_xyz_points(str(path))


def test_prior_from_detections_and_cdf_sampling():
    cam = pf.Camera()
    dets = [pf.Detection("mug", 0.9, (300, 200, 64, 64))]
    prior = pf.prior_from_detections(dets, cam, ["bowl", "mug"])
    assert prior.classes == ["bowl", "mug"]
    n_cells = prior.layout.cell_count()
    assert n_cells == 15 * 20 + 30 * 40 + 60 * 80
    assert prior.prob.shape == (n_cells, 2) and prior.boxes.shape == (n_cells, 4)
    mug = prior.class_index("mug")
    assert prior.class_mass("mug") == pytest.approx(prior.prob[:, mug].sum(), rel=1e-5)
    assert prior.class_mass("mug") > 100 * prior.class_mass("bowl")
    grid = prior.level_grid("mug", 2)
    assert grid.shape == (60, 80)
    # The most probable cell of the finest level lies inside the detection box.
    r, c = np.unravel_index(np.argmax(grid), grid.shape)
    assert 300 <= (c + 0.5) * 8 <= 364 and 200 <= (r + 0.5) * 8 <= 264
    s = pf.sample_cells(prior, "mug", 500, seed=3)
    cdf, cells = s["cdf"], s["cells"]
    assert cdf.shape == (n_cells,) and cdf[-1] == 1.0 and np.all(np.diff(cdf) >= 0)
    w = prior.prob[:, mug].astype(np.float64)
    np.testing.assert_allclose(cdf, np.cumsum(w) / w.sum(), atol=1e-9)
    # Most samples land in cells whose box overlaps the detection (they hold most of the mass).
    cx, cy = prior.boxes[cells, 0], prior.boxes[cells, 1]
    inside = (cx >= 300) & (cx <= 364) & (cy >= 200) & (cy <= 264)
    assert inside.mean() > 0.5
    assert s["reads"] <= s["reads_linear"]
    np.testing.assert_array_equal(pf.sample_cells(prior, "mug", 500, seed=3)["cells"], cells)
    with pytest.raises(ValueError, match="'cup' is not a class"):
        prior.level_grid("cup", 0)
    with pytest.raises(ValueError, match="level 3 out of range"):
        prior.level_grid(1, 3)
    with pytest.raises(ValueError, match="unknown class|cup"):
        pf.prior_from_detections([pf.Detection("cup", 0.5, (0, 0, 10, 10))], cam, ["mug"])


def test_sample_cells_with_depth_masks_cells_without_depth(easy_scene):
    s = easy_scene
    prior = pf.uniform_prior(s.camera, ["torus"])
    depth = s.depth.copy()
    depth[:, :320] = 0  # left half missing: cells there have no heuristic volume
    out = pf.sample_cells(prior, "torus", 300, depth=depth, camera=s.camera)
    boxes = prior.boxes[out["cells"]]
    assert np.all(boxes[:, 0] + boxes[:, 2] / 2 > 319.5)  # every drawn cell's box reaches the valid half
    assert np.count_nonzero(out["weights"]) < prior.layout.cell_count()
    with pytest.raises(ValueError, match="camera"):
        pf.sample_cells(prior, "torus", 5, depth=depth)


def test_raw_pyramid_path(easy_scene, tmp_path):
    s = easy_scene
    prior = pf.post_process_pyramid(s.raw_pyramid, s.layout, s.classes)
    np.testing.assert_array_equal(prior.prob, s.prior.prob)
    raw = pf.detections_to_raw_pyramid(s.detections, s.layout, s.classes)
    np.testing.assert_array_equal(raw, s.raw_pyramid)
    s.write(str(tmp_path / "scene"))
    back = pf.read_raw_pyramid(str(tmp_path / "scene" / "prior.pyr"), s.layout, s.classes)
    np.testing.assert_array_equal(back, s.raw_pyramid)
    depth = pf.load_depth_png(str(tmp_path / "scene" / "depth.png"), s.depth_scale)
    np.testing.assert_allclose(depth, s.depth, atol=s.depth_scale / 2)
    with pytest.raises(ValueError, match="prior.pyr|size|bytes"):
        pf.read_raw_pyramid(str(tmp_path / "scene" / "prior.pyr"), s.camera, s.classes + ["extra"])


def test_synth_scene_contents(easy_scene):
    s = easy_scene
    assert s.depth.shape == s.labels.shape == (s.camera.height, s.camera.width)
    assert s.gt_objs == ["torus"] and s.gt_poses.shape == (1, 4, 4)
    assert s.target.name == "torus" and "torus" in s.classes
    assert (s.labels == 1).any()
    # The target's pixels are at the rendered depth of its ground-truth pose.
    rendered, mask = pf.render_depth(s.target, s.gt_poses[0], s.camera)
    assert mask.any()
    both = mask & (s.labels == 1) & (s.depth > 0)
    assert both.sum() > 100
    assert np.median(np.abs(rendered[both] - s.depth[both])) < 0.005
    cx, cy, w, h = pf.projected_box(s.target, s.gt_poses[0], s.camera)
    np.testing.assert_allclose((cx, cy, w, h), s.gt_box, atol=1e-9)
    again = pf.make_synth_scene(4, target="torus", occlusion=0.0, clutter=0, false_positives=0, box_jitter_px=2)
    np.testing.assert_array_equal(again.depth, s.depth)


def test_overlay_and_shading(easy_scene):
    s = easy_scene
    shaded = pf.shade_depth(s.depth)
    assert shaded.shape == (480, 640, 3) and shaded.dtype == np.uint8
    over = pf.draw_pose_overlay(shaded, s.target, s.gt_poses[0], s.camera, (255, 0, 0))
    changed = np.any(over != shaded, axis=2)
    assert changed.any()
    _, mask = pf.render_depth(s.target, s.gt_poses[0], s.camera)
    assert changed[mask].mean() > 0.9  # the tint covers the silhouette
    assert not np.array_equal(over, shaded) and shaded is not over
