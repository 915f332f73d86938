"""Estimation through the bindings: accuracy on synthetic scenes, determinism, batches,
depth dtypes and layouts, priors in every accepted form."""

import math

import numpy as np

import pytest

import posefilter as pf
from conftest import EASY_SCENE, SMALL, TINY


def assert_rigid(T):
    """T is a 4x4 rigid transform: finite, rotation orthonormal with det +1, last row 0 0 0 1."""
    T = np.asarray(T)
    assert T.shape == (4, 4) and np.isfinite(T).all(), T
    R = T[:3, :3]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-9)
    assert abs(np.linalg.det(R) - 1.0) < 1e-9, np.linalg.det(R)
    np.testing.assert_array_equal(T[3], [0, 0, 0, 1])


def assert_valid_result(r, budget):
    """A result of an estimate with the `budget` options: a rigid pose, a weight in (0, 1], and
    at least one and at most `iterations` iterations per restart."""
    assert_rigid(r.pose)
    assert 0 < r.weight <= 1, r.weight
    assert budget["restarts"] <= r.iterations <= budget["iterations"] * budget["restarts"], r.iterations
    assert len(r.best_weight_history) == r.iterations
    assert np.all((np.asarray(r.best_weight_history) >= 0) & (np.asarray(r.best_weight_history) <= 1))


@pytest.mark.parametrize("seed", [1, 4, 6])
def test_pose_recovered_on_synthetic_scene(seed):
    scene = pf.make_synth_scene(seed, **EASY_SCENE)
    result = pf.Estimator(seed=1, **SMALL).estimate(scene.depth, scene.camera, scene.target, scene.prior)
    err = pf.pose_errors(scene.target, result.pose, scene.gt_poses[0])
    assert err.adds < 0.1 * scene.target.diameter(), err
    assert err.adds_ok
    assert result.obj == scene.target.name
    assert result.pose.shape == (4, 4) and result.pose6.shape == (6,)
    # pose6 (object -> base) and pose (object -> camera) agree: base_to_camera is the identity.
    np.testing.assert_allclose(pf.pose_to_transform(result.pose6), result.pose, atol=1e-9)
    assert_valid_result(result, SMALL)
    assert result.iterations == len(result.iteration_ms)
    assert np.all(result.iteration_ms >= 0) and result.time_ms > 0
    assert result.stats["weighings"] > 0


def test_easy_scene_small_budget_accurate_valid_and_reproducible(easy_scene):
    # The easy scene with the SMALL budget (about 0.6 s per estimate): ADD-S measured at
    # 0.5 % to 3.3 % of the torus's 0.17 m diameter over seeds 1, 2, 3, 5, 7, 11, 12, so the
    # 10 % bound (ADD-S's own threshold) fails only when the filter loses the object.
    s = easy_scene
    args = (s.depth, s.camera, s.target, s.prior)
    diameter = s.target.diameter()
    assert 0.1 < diameter < 0.3, diameter
    a = pf.Estimator(seed=2, **SMALL).estimate(*args)
    b = pf.Estimator(seed=2, **SMALL).estimate(*args)
    c = pf.Estimator(seed=5, **SMALL).estimate(*args)
    for r in (a, c):
        assert_valid_result(r, SMALL)
        err = pf.pose_errors(s.target, r.pose, s.gt_poses[0])
        assert err.adds < 0.1 * diameter, err
    # The same seed: the same pose, weight and trajectory, bit for bit.
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.pose6, b.pose6)
    assert a.weight == b.weight and a.iterations == b.iterations
    np.testing.assert_array_equal(a.best_weight_history, b.best_weight_history)
    # Another seed: another trajectory (and, above, another valid, accurate pose).
    assert not np.array_equal(a.best_weight_history, c.best_weight_history)


def test_same_seed_same_pose_other_seed_other_pose(easy_scene):
    args = (easy_scene.depth, easy_scene.camera, easy_scene.target, easy_scene.prior)
    a = pf.Estimator(seed=11, **TINY).estimate(*args)
    b = pf.Estimator(seed=11, **TINY).estimate(*args)
    c = pf.Estimator(seed=12, **TINY).estimate(*args)
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.best_weight_history, b.best_weight_history)
    assert a.weight == b.weight
    assert not np.array_equal(a.best_weight_history, c.best_weight_history)


def test_an_estimator_prepares_each_mesh_once(easy_scene):
    """The Estimator keeps the meshes it prepared: a second estimate on an equal mesh reuses the
    model (same result as a fresh Estimator's), another mesh is prepared once more."""
    args = (easy_scene.depth, easy_scene.camera, easy_scene.target, easy_scene.prior)
    est = pf.Estimator(seed=11, **TINY)
    assert est.prepared_models == 0
    a = est.estimate(*args)
    b = est.estimate(*args)
    assert est.prepared_models == 1
    fresh = pf.Estimator(seed=11, **TINY).estimate(*args)
    for r in (b, fresh):
        np.testing.assert_array_equal(a.pose, r.pose)
        np.testing.assert_array_equal(a.best_weight_history, r.best_weight_history)
        assert a.weight == r.weight
    mesh = easy_scene.target
    est.estimate(easy_scene.depth, easy_scene.camera, pf.Mesh(mesh.vertices * 1.0001, mesh.faces, mesh.name),
                 easy_scene.prior)
    assert est.prepared_models == 2


def test_depth_dtypes_and_layouts_give_the_same_pose(easy_scene, tiny_estimator):
    s = easy_scene
    ref = tiny_estimator.estimate(s.depth, s.camera, s.target, s.prior)
    # float64 metres.
    r64 = tiny_estimator.estimate(s.depth.astype(np.float64), s.camera, s.target, s.prior)
    np.testing.assert_array_equal(ref.pose, r64.pose)
    # A non-contiguous view (every element of a 2x-wide array's even columns) is copied.
    wide = np.zeros((s.depth.shape[0], 2 * s.depth.shape[1]), np.float32)
    wide[:, ::2] = s.depth
    view = wide[:, ::2]
    assert not view.flags.c_contiguous
    np.testing.assert_array_equal(ref.pose, tiny_estimator.estimate(view, s.camera, s.target, s.prior).pose)
    # Fortran order.
    fortran = np.asfortranarray(s.depth)
    np.testing.assert_array_equal(ref.pose, tiny_estimator.estimate(fortran, s.camera, s.target, s.prior).pose)
    # uint16 with depth_scale: the synthetic depth is a multiple of depth_scale.
    u16 = np.round(s.depth / s.depth_scale).astype(np.uint16)
    r16 = tiny_estimator.estimate(u16, s.camera, s.target, s.prior, depth_scale=s.depth_scale)
    np.testing.assert_allclose(r16.pose, ref.pose, atol=1e-6)


def test_prior_forms(easy_scene, tiny_estimator, tmp_path):
    s = easy_scene
    from_prior = tiny_estimator.estimate(s.depth, s.camera, s.target, s.prior)
    # Detections as objects, as dicts, and as a JSON file all give a prior of the same cells.
    dicts = [{"class": d.cls, "score": d.score, "bbox": list(d.bbox)} for d in s.detections]
    path = tmp_path / "detections.json"
    pf.write_detections_json(s.detections, str(path))
    poses = [tiny_estimator.estimate(s.depth, s.camera, s.target, p).pose for p in (s.detections, dicts, path, str(path))]
    for p in poses[1:]:
        np.testing.assert_array_equal(p, poses[0])
    assert_valid_result(from_prior, TINY)
    # No prior: a uniform one over the object's class; the call still returns a valid pose.
    uniform = pf.Estimator(**TINY).estimate(s.depth, s.camera, s.target)
    assert_valid_result(uniform, TINY)
    # No detector: candidate regions of the depth image; the same as the CLI's --prior auto.
    auto = pf.Estimator(**TINY).estimate(s.depth, s.camera, s.target, "auto")
    assert_valid_result(auto, TINY)
    table_only = np.where(s.depth > 0, s.depth.max(), 0).astype(np.float32)  # a wall: no region stands out
    with pytest.raises(ValueError, match="no candidates"):
        pf.Estimator(**TINY).estimate(table_only, s.camera, s.target, "auto")


def test_batch_returns_stacked_arrays(easy_scene):
    s = easy_scene
    other = pf.make_shape("box")
    est = pf.Estimator(seed=5, **TINY)
    dets = list(s.detections) + [pf.Detection("box", 0.5, (20, 20, 80, 80))]
    batch = est.estimate(s.depth, s.camera, [s.target, other], dets)
    assert isinstance(batch, pf.BatchResult) and len(batch) == 2
    assert batch.poses.shape == (2, 4, 4) and batch.poses6.shape == (2, 6) and batch.weights.shape == (2,)
    assert batch.objs == ["torus", "box"]
    for i, r in enumerate(batch):
        np.testing.assert_array_equal(batch.poses[i], r.pose)
        assert batch.weights[i] == r.weight
    assert batch[-1].obj == "box"
    with pytest.raises(IndexError):
        batch[2]
    # The first object of the batch is estimated exactly as alone (same seed, same prior).
    alone = est.estimate(s.depth, s.camera, s.target, pf.prior_from_detections(dets, s.camera, ["torus", "box"]))
    np.testing.assert_array_equal(alone.pose, batch.poses[0])


def test_obj_names_a_prior_class(easy_scene):
    s = easy_scene
    mesh = pf.Mesh(s.target.vertices, s.target.faces, name="my_ring")
    est = pf.Estimator(**TINY)
    r = est.estimate(s.depth, s.camera, mesh, s.prior, obj="torus")
    assert r.obj == "torus"
    with pytest.raises(ValueError, match="my_ring"):
        est.estimate(s.depth, s.camera, mesh, s.prior)


def test_progress_callback_sees_every_iteration(easy_scene):
    s = easy_scene
    seen = []
    est = pf.Estimator(particles=40, iterations=3, restarts=2, polish_steps=0, threads=2, confidence=1.0)
    r = est.estimate(s.depth, s.camera, s.target, s.prior, progress=lambda obj, it, w: seen.append((obj, it, w)))
    assert [it for _, it, _ in seen] == list(range(r.iterations))
    assert all(obj == "torus" for obj, _, _ in seen)
    # The figure is the best weight at the final inlier threshold: NaN while the first run
    # anneals (round(0.5 * 3) = 2 iterations), then never falling, and with the polish off the
    # last one is the result's weight.
    weights = [w for _, _, w in seen]
    assert all(math.isnan(w) for w in weights[:2])
    final = weights[2:]
    assert final and all(0 <= w <= 1 for w in final)
    assert final == sorted(final)
    assert final[-1] == r.weight

    def boom(obj, it, w):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        est.estimate(s.depth, s.camera, s.target, s.prior, progress=boom)


def test_mask_prior_finds_the_target_and_bad_masks_are_errors(easy_scene):
    s = easy_scene
    mask = s.labels == 1  # the target's pixels
    est = pf.Estimator(seed=1, **SMALL)
    r = est.estimate(s.depth, s.camera, s.target, mask=mask)  # no prior: the mask's box
    err = pf.pose_errors(s.target, r.pose, s.gt_poses[0])
    assert err.adds_ok, err
    # int masks: non-zero is the object.
    r_int = est.estimate(s.depth, s.camera, s.target, mask=mask.astype(np.int32) * 7)
    np.testing.assert_array_equal(r.pose, r_int.pose)
    with pytest.raises(pf.Error, match="mask: expected shape"):
        est.estimate(s.depth, s.camera, s.target, mask=mask[:10])
    with pytest.raises(pf.Error, match="mask is empty"):
        est.estimate(s.depth, s.camera, s.target, mask=np.zeros_like(mask))
    with pytest.raises(pf.Error, match="one Mesh"):
        est.estimate(s.depth, s.camera, [s.target, s.target], mask=mask, obj=["a", "b"])


def test_gpu_engine_gives_the_cpu_engines_pose(easy_scene):
    """engine="gpu" (Vulkan; Mesa's lavapipe where there is no GPU) weighs exactly what the cpu
    engine weighs: the same pose, weight and history for the same seed."""
    args = (easy_scene.depth, easy_scene.camera, easy_scene.target, easy_scene.prior)
    cpu = pf.Estimator(seed=3, engine="cpu", **TINY).estimate(*args)
    try:
        gpu = pf.Estimator(seed=3, engine="gpu", **TINY).estimate(*args)
    except ValueError as e:
        # Only a build without the gpu engine may refuse it, and it must say so.
        assert "no Vulkan support" in str(e), e
        return
    np.testing.assert_array_equal(cpu.pose, gpu.pose)
    np.testing.assert_array_equal(cpu.best_weight_history, gpu.best_weight_history)
    assert cpu.weight == gpu.weight
