"""Shared fixtures of the Python tests (run by ctest as `python_tests`, or by hand with
PYTHONPATH=<build>/python python3 -m pytest python/tests)."""

import pytest

import posefilter as pf

# A small filter budget (a fraction of a second per estimate on one core): enough for the easy
# synthetic scenes below, far below the defaults (510 particles x 17 iterations x 4 restarts).
SMALL = dict(particles=150, iterations=8, restarts=2, polish_steps=4, threads=2)
# Tests that compare calls with each other need no accuracy: the smallest budget.
TINY = dict(particles=40, iterations=3, restarts=1, polish_steps=0, threads=2)

# An easy scene: a torus alone on the table, no occluder, a tight true detection and no false
# positives (the filter's own accuracy is tested by the C++ suite; here we test the bindings).
EASY_SCENE = dict(target="torus", occlusion=0.0, clutter=0, false_positives=0, box_jitter_px=2)


@pytest.fixture(scope="session")
def easy_scene():
    return pf.make_synth_scene(4, **EASY_SCENE)


@pytest.fixture(scope="session")
def tiny_estimator():
    return pf.Estimator(seed=3, **TINY)
