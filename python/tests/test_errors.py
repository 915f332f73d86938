"""Bad input raises clear exceptions: ValueError (posefilter.Error) for bad values, arrays
and files; TypeError for unknown keywords and values of the wrong type."""

import os
import stat

import numpy as np
import pytest

import posefilter as pf


@pytest.fixture(scope="module")
def tiny():
    est = pf.Estimator(particles=20, iterations=1, restarts=1, polish_steps=0, threads=1)
    return est


def test_error_is_a_value_error():
    assert issubclass(pf.Error, ValueError)


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda d: d.astype(np.int32), "dtype int32"),
        (lambda d: d.astype(np.uint8), "dtype uint8"),
        (lambda d: d.astype(bool), "dtype bool"),
        (lambda d: d[None], "2-D array"),
        (lambda d: d.ravel(), "2-D array"),
        (lambda d: d[:-1], r"differs from the camera's \(height, width\) = \(480, 640\)"),
        (lambda d: d.T.copy(), r"shape \(640, 480\)"),
        (lambda d: np.where(np.arange(d.size).reshape(d.shape) == 5, np.nan, d).astype(np.float32), "NaN at row 0, column 5"),
        (lambda d: np.where(np.arange(d.size).reshape(d.shape) == 641, np.inf, d), "inf at row 1, column 1"),
        (lambda d: -d, "negative"),
        (lambda d: np.zeros_like(d), "no valid pixel"),
        (lambda d: d.tolist(), "numpy array"),
    ],
)
def test_bad_depth_arrays(easy_scene, tiny, make, match):
    s = easy_scene
    with pytest.raises(ValueError, match=match):
        tiny.estimate(make(s.depth), s.camera, s.target, s.prior)


def test_uint16_depth_needs_a_valid_scale(easy_scene, tiny):
    s = easy_scene
    u16 = np.round(s.depth / s.depth_scale).astype(np.uint16)
    with pytest.raises(ValueError, match="depth_scale"):
        tiny.estimate(u16, s.camera, s.target, s.prior)
    with pytest.raises(ValueError, match="depth_scale must be finite and > 0"):
        tiny.estimate(u16, s.camera, s.target, s.prior, depth_scale=-1.0)
    with pytest.raises(ValueError, match="uint16 depth only"):
        tiny.estimate(s.depth, s.camera, s.target, s.prior, depth_scale=0.001)


@pytest.mark.parametrize(
    "options, match",
    [
        (dict(particles=1), "particles"),
        (dict(iterations=0), "iterations"),
        (dict(alpha=0.5, beta=0.5, gamma=0.5), "alpha"),
        (dict(elite=200, particles=100), "elite"),
        (dict(engine="vulkan"), "engine"),
        (dict(inlier_thr=0.0), "inlier_thr"),
        (dict(hard_inlier_thr=-1.0), "hard_inlier_thr"),
        (dict(heuristics_max_samples=0), "heuristics_max_samples"),
        (dict(heuristics_percentile_lo=0.9, heuristics_percentile_hi=0.1), "heuristics_percentile_lo"),
        (dict(move_probabilities=[0.0] * 17), "move_probabilities"),
        (dict(restarts=0), "restarts"),
        (dict(threads=-1), "threads"),
        (dict(threads=100000), r"threads must be in \[0, \d+\]"),
        (dict(iterations=10**9), r"^invalid filter option: iterations must be in \[1, 100000\] \(got 1000000000\)"),
        (dict(confidence=float("nan")), "confidence"),
        (dict(anneal_subsample=5), "anneal_subsample"),
        (dict(fine_fraction=0.0), "fine_fraction"),
    ],
)
def test_bad_option_values(options, match):
    with pytest.raises(ValueError, match=match):
        pf.Estimator(**options)


def test_unknown_or_mistyped_options():
    with pytest.raises(TypeError, match="unknown option 'num_particles'"):
        pf.Estimator(num_particles=10)
    with pytest.raises(TypeError, match="'particles'"):
        pf.Estimator(particles="many")
    with pytest.raises(TypeError, match="'particles'"):
        pf.Estimator(particles=10.5)
    with pytest.raises(TypeError, match="'move_probabilities'"):
        pf.Estimator(move_probabilities=[0.5, 0.5])
    with pytest.raises(TypeError, match="'seed'"):
        pf.Estimator(seed=-1)
    with pytest.raises(TypeError):
        pf.Estimator(5)


def test_options_round_trip_and_defaults():
    defaults = pf.Estimator.defaults()
    assert pf.Estimator().options == defaults
    est = pf.Estimator(particles=77, hard_inlier=True, seed=2**63)
    assert est.options["particles"] == 77 and est.options["hard_inlier"] is True
    assert est.options["seed"] == 2**63
    assert pf.Estimator(**est.options).options == est.options


def test_bad_estimate_arguments(easy_scene, tiny):
    s = easy_scene
    with pytest.raises(ValueError, match="not a class of the prior"):
        tiny.estimate(s.depth, s.camera, s.target, s.prior, obj="teapot")
    # A name no detection carries: the prior would say nothing about it.
    with pytest.raises(ValueError, match=r"prior: no detection on the image is of an object's class \(objects: giraffe"):
        tiny.estimate(s.depth, s.camera, s.target, s.detections, obj="giraffe")
    # One object with detections, one without: a warning for the second.
    with pytest.warns(UserWarning, match="no detection of 'giraffe' on the image"):
        tiny.estimate(s.depth, s.camera, [s.target, s.target], s.detections, obj=["torus", "giraffe"])
    # A detection wholly off the image is named.
    off = list(s.detections) + [{"class": "torus", "score": 0.5, "bbox": [-900.0, -900.0, 50.0, 50.0]}]
    with pytest.warns(UserWarning, match="wholly outside the 640x480 image"):
        tiny.estimate(s.depth, s.camera, s.target, off)
    with pytest.raises(ValueError, match="2 names for 1 meshes"):
        tiny.estimate(s.depth, s.camera, [s.target], s.prior, obj=["a", "b"])
    # prior="none" is the CLI's --prior none: the uniform prior, the same result as None.
    a = tiny.estimate(s.depth, s.camera, s.target, None)
    b = tiny.estimate(s.depth, s.camera, s.target, "none")
    assert np.array_equal(a.pose, b.pose) and a.weight == b.weight
    # Two meshes under one name (as the CLI's --mesh given twice): refused, naming it.
    with pytest.raises(ValueError, match="name 'torus' given twice \\(meshes 0 and 1\\)"):
        tiny.estimate(s.depth, s.camera, [s.target, s.target], s.detections)
    with pytest.raises(ValueError, match="empty list"):
        tiny.estimate(s.depth, s.camera, [], s.prior)
    with pytest.raises(TypeError, match="Mesh"):
        tiny.estimate(s.depth, s.camera, [s.target, "box"], s.prior)
    with pytest.raises(TypeError, match="prior"):
        tiny.estimate(s.depth, s.camera, s.target, 3.5)
    with pytest.raises(ValueError, match="detection 0: missing key 'bbox'"):
        tiny.estimate(s.depth, s.camera, s.target, [{"class": "torus", "score": 0.5}])
    with pytest.raises(ValueError, match="detection 0"):
        tiny.estimate(s.depth, s.camera, s.target, [{"class": "torus", "score": 0.5, "bbox": [1, 2, 3]}])
    with pytest.raises(ValueError, match="/nonexistent/detections.json"):
        tiny.estimate(s.depth, s.camera, s.target, "/nonexistent/detections.json")
    small_cam = pf.Camera(width=320, height=240, fx=270, fy=270, cx=160, cy=120)
    with pytest.raises(ValueError, match="prior: made for a 640x480 image"):
        tiny.estimate(s.depth[::2, ::2].copy(), small_cam, s.target, s.prior)
    with pytest.raises(TypeError, match="progress"):
        tiny.estimate(s.depth, s.camera, s.target, s.prior, progress=3)


def test_bad_cameras_meshes_and_poses():
    with pytest.raises(ValueError, match="fx must be finite and > 0"):
        pf.Camera(fx=0)
    with pytest.raises(ValueError, match="width"):
        pf.Camera(width=-3)
    with pytest.raises(ValueError, match="base_to_camera: the 3x3 block"):
        pf.Camera(base_to_camera=np.diag([2.0, 1, 1, 1]))
    with pytest.raises(ValueError, match=r"vertices: expected an N x 3 array"):
        pf.Mesh(np.zeros((4, 2)), [[0, 1, 2]])
    with pytest.raises(ValueError, match="face 0 indexes vertex 7 of 3"):
        pf.Mesh(np.eye(3), [[0, 1, 7]])
    with pytest.raises(ValueError, match="faces: expected an M x 3 integer array"):
        pf.Mesh(np.eye(3), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="vertices: holds NaN"):
        pf.Mesh(np.full((3, 3), np.nan), [[0, 1, 2]])
    with pytest.raises(ValueError, match=r"T_est: expected shape \(4, 4\)"):
        pf.add_error(pf.make_box(0.1, 0.1, 0.1), np.eye(3), np.eye(4))
    with pytest.raises(ValueError, match="last row"):
        pf.add_error(pf.make_box(0.1, 0.1, 0.1), np.ones((4, 4)), np.eye(4))
    with pytest.raises(ValueError, match="give diameter"):
        pf.pose_errors(np.zeros((5, 3)), np.eye(4), np.eye(4))
    with pytest.raises(ValueError, match="units"):
        pf.load_mesh("x.ply", units="inch")
    with pytest.raises(ValueError, match="units must be a finite number > 0"):
        pf.load_mesh("x.ply", units=0.0)
    with pytest.raises(TypeError, match="units"):
        pf.load_mesh("x.ply", units=None)
    with pytest.raises(ValueError, match="pairs"):
        pf.write_gt_json([("mug",)], "/tmp/never_written.json")
    with pytest.raises(ValueError, match="T_cam_obj"):
        pf.write_gt_json([("mug", np.eye(3))], "/tmp/never_written.json")
    with pytest.raises(ValueError, match="sx|size|> 0"):
        pf.make_box(-1, 1, 1)


def test_missing_and_corrupt_files(tmp_path):
    missing = str(tmp_path / "missing.png")
    with pytest.raises(pf.Error, match="missing.png"):
        pf.load_depth_png(missing, 0.001)
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not a png at all")
    with pytest.raises(pf.Error, match="bad.png"):
        pf.load_depth_png(str(bad), 0.001)
    with pytest.raises(pf.Error, match="nothing.ply"):
        pf.load_mesh(tmp_path / "nothing.ply")
    with pytest.raises(pf.Error, match="camera.json"):
        pf.read_camera_json(str(tmp_path / "camera.json"))


def test_writers_refuse_what_the_cli_refuses(tmp_path):
    """Python's writers make the CLI's pre-work check of an output path (one library call)."""
    cam = pf.Camera(width=640, height=480, fx=500, fy=500, cx=320, cy=240)
    with pytest.raises(pf.Error, match="empty value"):
        pf.write_camera_json(cam, "", 0.001)
    long_name = str(tmp_path / ("c" * 240 + ".json"))
    with pytest.raises(pf.Error, match="the file name is 245 bytes"):
        pf.write_gt_json([("mug", np.eye(4))], long_name)
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    with pytest.raises(pf.Error, match="a FIFO"):
        pf.write_detections_json([], str(fifo))
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo.json"]


def test_bad_synth_options():
    with pytest.raises(ValueError, match="occlusion"):
        pf.make_synth_scene(1, occlusion=2.0)
    with pytest.raises(ValueError, match="target must be one of box, cylinder, lshape, torus \\(got 'teapot'\\)"):
        pf.make_synth_scene(1, target="teapot")
    with pytest.raises(TypeError, match="unknown option 'occluder'"):
        pf.make_synth_scene(1, occluder=0.2)
    with pytest.raises(TypeError, match="target_mesh"):
        pf.make_synth_scene(1, target_mesh="box")
