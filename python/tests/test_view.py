"""Result.view / BatchResult.view (docs/VIEWER.md) and the particle record: the page holds the
recorded sets, recording changes no pose, and bad arguments raise posefilter.Error."""
import json
import re

import numpy as np
import pytest

import posefilter as pf


def page_data(path):
    html = open(path, encoding="utf-8").read()
    m = re.search(r'<script type="application/json" id="posefilter-data">(.*?)</script>', html, re.S)
    return json.loads(m.group(1))


@pytest.fixture(scope="module")
def scene():
    return pf.make_synth_scene(7, target="lshape", clutter=1)


def small(**kw):
    return pf.Estimator(seed=1, restarts=1, particles=64, iterations=4, polish_steps=0, **kw)


def test_view_writes_the_recorded_sets(scene, tmp_path):
    r = small(record_particles=True).estimate(scene.depth, scene.camera, scene.target, scene.prior)
    plain = small().estimate(scene.depth, scene.camera, scene.target, scene.prior)
    assert np.array_equal(r.pose, plain.pose), "recording moved the pose"
    assert plain.particle_history == []
    h = r.particle_history
    assert [s["iteration"] for s in h] == list(range(len(h))) and len(h) >= 2
    assert h[0]["poses6"].shape == (64, 6)
    assert np.all(np.diff(h[0]["weights"]) <= 0), "sets are stored best first"
    path = tmp_path / "v.html"
    r.view(str(path), scene.depth, scene.camera, scene.target, gt=scene.gt_poses[0], title="py")
    d = page_data(path)
    assert d["title"] == "py"
    (o,) = d["objects"]
    assert len(o["sets"]) == len(h) and o["sets"][0]["total"] == 64
    assert o["gt"] is not None
    assert np.allclose(np.array(o["estimate"]).reshape(4, 4), r.pose)


def test_view_errors(scene, tmp_path):
    r = small().estimate(scene.depth, scene.camera, scene.target, scene.prior)
    with pytest.raises(pf.Error, match="2 meshes for 1 results"):
        r.view(str(tmp_path / "a.html"), scene.depth, scene.camera, [scene.target, scene.target])
    with pytest.raises(pf.Error, match="RGB image is 4x4"):
        r.view(str(tmp_path / "a.html"), scene.depth, scene.camera, scene.target, rgb=np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(pf.Error, match="no_such_dir"):
        r.view(str(tmp_path / "no_such_dir" / "a.html"), scene.depth, scene.camera, scene.target)
    assert not (tmp_path / "a.html").exists()
