"""Estimator.estimate from many Python threads at once (it runs without the GIL): on one shared
Estimator and on one Estimator per call, for the cpu and reference engines, with and without a
progress callback. Every result equals the serial result of the same seed, bit for bit."""

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import posefilter as pf
from conftest import EASY_SCENE, TINY

# One worker per estimate (the threads here are Python's); a tiny budget: this runs in the
# normal suite.
BUDGET = dict(TINY, threads=1)
THREADS = 8
ENGINES = ("cpu", "reference")
SEEDS = (5, 6)


@pytest.fixture(scope="module")
def scenes():
    # Two scenes with their inputs made once and shared by every call: depth array, camera,
    # mesh and prior objects (the torus with a Prior, the box with its detection list).
    torus = pf.make_synth_scene(4, **EASY_SCENE)
    box = pf.make_synth_scene(6, **dict(EASY_SCENE, target="box"))
    return [
        (torus.depth, torus.camera, torus.target, torus.prior),
        (box.depth, box.camera, box.target, list(box.detections)),
    ]


def jobs():
    return [(s, e, seed) for s in range(2) for e in ENGINES for seed in SEEDS]


def same(a, b):
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.pose6, b.pose6)
    np.testing.assert_array_equal(a.best_weight_history, b.best_weight_history)
    assert a.weight == b.weight and a.iterations == b.iterations and a.cell == b.cell
    assert a.stats["fragments"] == b.stats["fragments"]


@pytest.fixture(scope="module")
def serial(scenes):
    return {(s, e, seed): pf.Estimator(engine=e, seed=seed, **BUDGET).estimate(*scenes[s]) for s, e, seed in jobs()}


def run_at_once(calls):
    """Runs every call (a function of no arguments) on THREADS threads, started together."""
    start = threading.Barrier(min(THREADS, len(calls)))

    def wrapped(call):
        try:
            start.wait(timeout=30)
        except threading.BrokenBarrierError:
            pass
        return call()

    with ThreadPoolExecutor(max_workers=THREADS) as pool:
        return list(pool.map(wrapped, calls))


def test_serial_results_depend_on_the_seed(serial):
    for s in range(2):
        for e in ENGINES:
            assert not np.array_equal(serial[(s, e, SEEDS[0])].best_weight_history,
                                      serial[(s, e, SEEDS[1])].best_weight_history)


def test_one_estimator_per_engine_and_seed_shared_by_all_threads(scenes, serial):
    estimators = {(e, seed): pf.Estimator(engine=e, seed=seed, **BUDGET) for e in ENGINES for seed in SEEDS}
    todo = jobs() * 2
    results = run_at_once([lambda j=j: estimators[j[1:]].estimate(*scenes[j[0]]) for j in todo])
    for j, r in zip(todo, results):
        same(r, serial[j])


def test_one_estimator_estimating_every_scene_at_once(scenes, serial):
    est = pf.Estimator(engine="cpu", seed=SEEDS[0], **BUDGET)
    todo = [0, 1] * 4
    results = run_at_once([lambda s=s: est.estimate(*scenes[s]) for s in todo])
    for s, r in zip(todo, results):
        same(r, serial[(s, "cpu", SEEDS[0])])


def test_a_new_estimator_per_call(scenes, serial):
    todo = jobs()
    results = run_at_once([lambda j=j: pf.Estimator(engine=j[1], seed=j[2], **BUDGET).estimate(*scenes[j[0]])
                           for j in todo])
    for j, r in zip(todo, results):
        same(r, serial[j])


def test_progress_callbacks_from_many_threads(scenes, serial):
    # The callback runs with the GIL, on the thread that called estimate.
    seen = {}
    lock = threading.Lock()

    def call(k, j):
        def progress(obj, iteration, weight):
            with lock:
                seen.setdefault(k, []).append((threading.get_ident(), iteration))
        return threading.get_ident(), pf.Estimator(engine=j[1], seed=j[2], **BUDGET).estimate(
            *scenes[j[0]], progress=progress)

    todo = jobs()
    results = run_at_once([lambda k=k, j=j: call(k, j) for k, j in enumerate(todo)])
    for k, (j, (ident, r)) in enumerate(zip(todo, results)):
        same(r, serial[j])
        assert len(seen[k]) == r.iterations
        assert all(t == ident for t, _ in seen[k])


def test_an_error_in_one_thread_leaves_the_others_alone(scenes, serial):
    est = pf.Estimator(engine="cpu", seed=SEEDS[0], **BUDGET)
    depth, camera, mesh, prior = scenes[0]
    bad = np.full_like(depth, np.nan)

    def call(k):
        if k % 2:
            with pytest.raises(pf.Error):
                est.estimate(bad, camera, mesh, prior)
            return None
        return est.estimate(depth, camera, mesh, prior)

    for r in run_at_once([lambda k=k: call(k) for k in range(THREADS)]):
        if r is not None:
            same(r, serial[(0, "cpu", SEEDS[0])])
