"""Every plot function writes a non-trivial PNG; the recall arithmetic; scripts/plots.py."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import posefilter as pf

plots = pytest.importorskip("posefilter.plots")  # needs matplotlib

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def tiny_run(easy_scene):
    s = easy_scene
    est = pf.Estimator(particles=40, iterations=3, restarts=2, polish_steps=0, threads=2, confidence=1.0)
    r = est.estimate(s.depth, s.camera, s.target, s.prior)
    return s, r


def assert_png(path, min_colours=8):
    assert os.path.isfile(path)
    assert os.path.getsize(path) > 5000
    img = pf.load_rgb_png(path)
    assert img.shape[0] > 100 and img.shape[1] > 100
    assert len(np.unique(img.reshape(-1, 3), axis=0)) >= min_colours  # not a blank canvas


def test_overlay_grid(tiny_run, tmp_path):
    s, r = tiny_run
    panel = dict(depth=s.depth, camera=s.camera, mesh=s.target, estimate=r.pose, gt=s.gt_poses[0], title="t")
    path = plots.overlay_grid([panel, dict(panel, estimate=None)], tmp_path / "sub" / "grid.png", cols=2)
    assert_png(path)
    with pytest.raises(ValueError):
        plots.overlay_grid([], tmp_path / "none.png")


def test_weight_history_and_iteration_times(tiny_run, tmp_path):
    _, r = tiny_run
    assert_png(plots.weight_history(r, tmp_path / "w.png"))
    assert_png(plots.iteration_times([r, r], tmp_path / "t.png", labels=["a", "b"]))


def test_prior_heatmap(tiny_run, tmp_path):
    s, _ = tiny_run
    assert_png(plots.prior_heatmap(s.prior, "torus", tmp_path / "p.png", n_samples=100, image=pf.shade_depth(s.depth)))
    assert_png(plots.prior_heatmap(s.prior, 0, tmp_path / "p2.png", depth=s.depth, camera=s.camera))


def test_recall_arithmetic():
    errs = np.array([0.5, 1.5, np.nan])
    diam = np.array([10.0, 10.0, 10.0])
    np.testing.assert_allclose(plots.recall_at(errs, diam, np.array([0.0, 0.1, 0.2])), [0, 1 / 3, 2 / 3])


def test_recall_curve_from_errors_and_eval_json(tiny_run, tmp_path):
    s, r = tiny_run
    e = pf.pose_errors(s.target, r.pose, s.gt_poses[0])
    assert_png(plots.recall_curve([e, None], tmp_path / "r.png"))
    ev = {"objects": [
        {"obj": "a", "add_mm": 5.0, "adds_mm": 2.0, "diameter_mm": 100.0},
        {"obj": "b", "add_mm": None, "adds_mm": None, "diameter_mm": 100.0},
    ]}
    path = tmp_path / "eval.json"
    path.write_text(json.dumps(ev))
    table = plots.load_eval_json(path)
    np.testing.assert_allclose(plots.recall_at(table["adds"], table["diameter"], np.array([0.01, 0.03])), [0, 0.5])
    assert_png(plots.recall_curve([path, str(path)], tmp_path / "r2.png", labels=["x", "y"]))


def test_plots_script_recall_on_cli_eval(tiny_run, tmp_path):
    """scripts/plots.py recall on the JSON of the real `posefilter eval --json`."""
    cli = os.environ.get("POSEFILTER_CLI_PATH")
    if not cli or not os.path.exists(cli):
        pytest.skip("POSEFILTER_CLI_PATH not set (ctest sets it)")
    s, r = tiny_run
    d = tmp_path / "scene"
    s.write(str(d))
    pf.write_gt_json([("torus", s.gt_poses[0])], str(d / "gt_copy.json"))
    results = {"objects": [{"obj": "torus", "x": 0, "y": 0, "z": 0, "roll": 0, "pitch": 0, "yaw": 0,
                            "R": r.pose[:3, :3].tolist(), "t": r.pose[:3, 3].tolist(), "weight": r.weight,
                            "iterations": r.iterations, "time_ms": r.time_ms}]}
    (d / "results.json").write_text(json.dumps(results))
    res_back = pf.read_results_json(str(d / "results.json"))
    np.testing.assert_allclose(res_back[0]["T_cam_obj"], r.pose, atol=1e-9)
    subprocess.run([cli, "eval", "--results", str(d / "results.json"), "--gt", str(d / "gt.json"),
                    "--mesh", f"torus={d / 'torus.ply'}", "--json", str(d / "eval.json")],
                   check=True, capture_output=True)
    table = plots.load_eval_json(d / "eval.json")
    ours = pf.pose_errors(s.target, r.pose, s.gt_poses[0])
    assert table["adds"][0] == pytest.approx(ours.adds, rel=1e-3, abs=1e-6)
    out = tmp_path / "recall.png"
    env = dict(os.environ)
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "plots.py"), "recall", "--out", str(out),
                           str(d / "eval.json")], env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert_png(str(out))
    bad = subprocess.run([sys.executable, str(ROOT / "scripts" / "plots.py"), "recall", "--out", str(out),
                          str(d / "missing.json")], env=env, capture_output=True, text=True)
    assert bad.returncode != 0 and "missing.json" in bad.stderr


def test_plots_script_recall_on_dataset_eval(tmp_path):
    """scripts/plots.py recall on an `eval --dataset --json` file: one entry per ground-truth
    instance (a missing estimate counts as a failure), diameters from the per-object table."""
    ev = {"dataset": "ds", "format": "bop", "split": "test",
          "overall": {"obj_id": 0, "name": "all", "diameter_mm": 0.0},
          "objects": [{"obj_id": 1, "name": "obj_000001", "diameter_mm": 100.0},
                      {"obj_id": 2, "name": "obj_000002", "diameter_mm": 200.0}],
          "instances": [{"scene_id": 1, "im_id": 1, "obj_id": 1, "gt_index": 0, "estimated": True,
                         "add_mm": 5.0, "adds_mm": 4.0, "mssd_mm": 5.0, "mspd_px": 1.0, "vsd": []},
                        {"scene_id": 1, "im_id": 1, "obj_id": 2, "gt_index": 1, "estimated": True,
                         "add_mm": 50.0, "adds_mm": 30.0, "mssd_mm": 50.0, "mspd_px": 9.0, "vsd": []},
                        {"scene_id": 1, "im_id": 2, "obj_id": 2, "gt_index": 0, "estimated": False,
                         "add_mm": None, "adds_mm": None, "mssd_mm": None, "mspd_px": None, "vsd": []}]}
    path = tmp_path / "eval_dataset.json"
    path.write_text(json.dumps(ev))
    table = plots.load_eval_json(path)
    np.testing.assert_allclose(table["diameter"], [0.1, 0.2, 0.2])
    # ADD-S below 0.1 diameter: 4 mm of 100 (yes), 30 mm of 200 (no), missing (no).
    np.testing.assert_allclose(plots.recall_at(table["adds"], table["diameter"], np.array([0.1, 0.2])), [1 / 3, 2 / 3])
    out = tmp_path / "recall.png"
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "plots.py"), "recall", "--out", str(out), str(path)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert_png(str(out))
    # A JSON that is no eval output: a one-line error naming the file, no traceback.
    other = tmp_path / "other.json"
    other.write_text('{"detections": []}')
    bad = subprocess.run([sys.executable, str(ROOT / "scripts" / "plots.py"), "recall", "--out", str(out), str(other)],
                         capture_output=True, text=True)
    assert bad.returncode != 0 and "other.json" in bad.stderr and "Traceback" not in bad.stderr
