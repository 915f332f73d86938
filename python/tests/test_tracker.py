"""Tracking through the bindings: Tracker on synthetic sequences (make_synth_sequence) — it follows
a moving object, takes its options from the tracker's option table (the confirmation among them),
reports a jump beyond its search as lost, restarts from a stage 1, is deterministic, and rejects
bad arguments."""

import warnings

import numpy as np

import pytest

import posefilter as pf

SEQ = dict(target="lshape", clutter=2, false_positives=0)


def adds_ok(scene, pose):
    """ADD-S below 10 % of the diameter against the scene's ground truth."""
    e = pf.pose_errors(scene.target, pose, scene.gt_poses[0], 0.1)
    return e.adds_ok


@pytest.fixture(scope="module")
def sequence():
    return pf.make_synth_sequence(6, seed=21, speed=0.01, turn=0.05, **SEQ)


def test_sequence_moves_the_target_as_told(sequence):
    assert len(sequence) == 6
    first = pf.make_synth_scene(21, **SEQ)
    np.testing.assert_array_equal(sequence[0].gt_poses, first.gt_poses)  # frame 0: the seed's scene
    t = [s.gt_poses[0][:3, 3] for s in sequence]
    steps = [np.linalg.norm(t[i + 1] - t[i]) for i in range(5)]
    assert all(0.005 < d < 0.02 for d in steps), steps  # 1 cm slide plus the turn about the footprint


def test_tracks_a_moving_object_from_a_known_start(sequence):
    tracker = pf.Tracker(sequence[0].target, seed=5, threads=2)
    tracker.reset("lshape", sequence[0].gt_poses[0])
    for s in sequence:
        (r,) = tracker.track(s.depth, s.camera)
        assert r.obj == "lshape" and r.status == "tracked", r
        assert adds_ok(s, r.pose), (tracker.frames, r)
    assert tracker.frames == 6


def test_the_confirmation_is_a_keyword(sequence):
    names = pf.Tracker.option_names()
    assert names == ["lost_weight", "refresh_weight", "search_t", "search_r", "constant_velocity", "scene_pass",
                     "window_margin", "confirm", "confirm_margin"]
    defaults = pf.Tracker.defaults()
    assert set(defaults) == set(names) | set(pf.Estimator.option_names())
    assert defaults["confirm"] is True and defaults["confirm_margin"] == 0.02
    for name in names:
        assert name in pf.Tracker.__doc__
    # With the confirmation, frames after the first may end at the polished prediction; without
    # it, every frame runs the particle search.
    confirmed = {}
    for confirm in (True, False):
        tracker = pf.Tracker(sequence[0].target, seed=5, threads=2, confirm=confirm, confirm_margin=0.05)
        tracker.reset("lshape", sequence[0].gt_poses[0])
        results = [tracker.track(s.depth, s.camera)[0] for s in sequence[:4]]
        assert all(r.status == "tracked" for r in results), results
        confirmed[confirm] = [r.confirmed for r in results]
    assert not any(confirmed[False])
    assert not confirmed[True][0] and any(confirmed[True]), confirmed[True]


def test_same_seed_same_poses(sequence):
    poses = []
    for _ in range(2):
        tracker = pf.Tracker([sequence[0].target], seed=9, threads=2)
        tracker.reset("lshape", sequence[0].gt_poses[0])
        poses.append([tracker.track(s.depth, s.camera)[0].pose for s in sequence[:3]])
    np.testing.assert_array_equal(np.array(poses[0]), np.array(poses[1]))


def test_a_jump_beyond_the_search_is_lost_and_a_stage1_restarts_it():
    seq = pf.make_synth_sequence(4, seed=22, speed=0.005, turn=0.0, jump_frame=2, jump=0.15, **SEQ)
    tracker = pf.Tracker(seq[0].target, seed=5, threads=2)
    tracker.reset("lshape", seq[0].gt_poses[0])
    statuses = [tracker.track(s.depth, s.camera)[0].status for s in seq]
    assert statuses == ["tracked", "tracked", "lost", "lost"], statuses

    # With the scene's detections as the stage 1 the jumped object is found again.
    tracker = pf.Tracker(seq[0].target, seed=5, threads=2, init=dict(particles=200, iterations=10, restarts=2))
    tracker.reset("lshape", seq[0].gt_poses[0])
    calls = []

    def stage1(depth, camera):
        calls.append(camera.width)
        return seq[len(calls) + 1].detections  # called for frame 2 only

    results = [tracker.track(s.depth, s.camera, prior=stage1)[0] for s in seq]
    assert [r.status for r in results] == ["tracked", "tracked", "initialised", "tracked"], results
    assert len(calls) == 1
    assert adds_ok(seq[2], results[2].pose) and adds_ok(seq[3], results[3].pose)


def test_objects_without_a_start_wait_for_a_stage1(sequence):
    tracker = pf.Tracker(sequence[0].target, seed=5, threads=2)
    # With prior=None nothing can start the object: a warning naming it, once.
    with pytest.warns(RuntimeWarning, match="'lshape' has no pose and prior=None cannot start it"):
        (r,) = tracker.track(sequence[0].depth, sequence[0].camera)
    assert r.status == "not-started"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        (r,) = tracker.track(sequence[0].depth, sequence[0].camera)
    assert r.status == "not-started"
    (r,) = tracker.track(sequence[1].depth, sequence[1].camera, prior=sequence[1].detections)
    assert r.status == "initialised" and adds_ok(sequence[1], r.pose), r


def test_bad_arguments(sequence):
    mesh = sequence[0].target
    with pytest.raises(pf.Error, match="lost_weight"):
        pf.Tracker(mesh, lost_weight=2.0)
    with pytest.raises(pf.Error, match=r"confirm_margin must be in \[0, 1\] \(got 1.5\)"):
        pf.Tracker(mesh, confirm_margin=1.5)
    with pytest.raises(TypeError, match="option 'confirm' cannot take the value 'yes'"):
        pf.Tracker(mesh, confirm="yes")
    with pytest.raises(TypeError, match="option 'search_t' cannot take the value 'far'"):
        pf.Tracker(mesh, search_t="far")
    with pytest.raises(TypeError, match="unknown option 'particle'"):
        pf.Tracker(mesh, particle=10)
    with pytest.raises(pf.Error, match="particles"):
        pf.Tracker(mesh, particles=0)
    with pytest.raises(pf.Error, match="twice"):
        pf.Tracker([mesh, mesh])
    tracker = pf.Tracker(mesh)
    with pytest.raises(pf.Error, match="unknown object 'cup'"):
        tracker.reset("cup", np.eye(4))
    with pytest.raises(pf.Error, match="depth"):
        tracker.track(np.zeros((10, 10), np.float32), sequence[0].camera)
    bad = sequence[0].depth.copy()
    bad[5, 5] = np.nan
    with pytest.raises(pf.Error):
        tracker.track(bad, sequence[0].camera)
