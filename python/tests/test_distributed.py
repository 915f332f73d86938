"""posefilter.distributed.run_dataset: `posefilter run-dataset` over a Dask cluster.

A tiny YCB-Video-style folder made with `posefilter synth` (6 images, two objects, one image
with two instances) is estimated once by the CLI in one process (the reference, --no-time) and
then over a LocalCluster; the CSVs must hold the same lines. Also: a worker killed mid-run,
resuming (with a torn last row), errors, a worker without the posefilter Python package, and
the target list against the CLI's on a BOP copy of the folder."""

import importlib.util
import json
import logging
import os
import shutil
import signal
import subprocess
import sys

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

import posefilter as pf  # noqa: E402
from posefilter.distributed import (  # noqa: E402
    BOP_CSV_HEADER, RunDatasetError, _probe_cli, built_cli, list_targets, run_dataset)

# The cheapest filter (tens of ms per target): the tests compare runs, not accuracy.
OPTIONS = dict(particles=60, restarts=1, iterations=6, polish_steps=0, threads=1, seed=3)
CLI_FLAGS = ["--particles", "60", "--restarts", "1", "--iterations", "6", "--polish-steps", "0", "--threads", "1",
             "--seed", "3"]
PRIOR = ("gt-boxes", 0)


def _cli():
    cli = os.environ.get("POSEFILTER_CLI_PATH")
    if not cli or not os.path.exists(cli):
        pytest.skip("POSEFILTER_CLI_PATH not set (ctest sets it)")
    return os.path.abspath(cli)


def _run(cmd):
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    assert p.returncode == 0, f"{cmd}: {p.stderr}"
    return p


def _cli_run_dataset(cli, dataset, out, *extra):
    return _run([cli, "run-dataset", "--dataset", dataset, "--gt-boxes", "0", "--out", out, "--quiet", "--no-time",
                 *CLI_FLAGS, *extra])


def _lines(path):
    with open(path, encoding="utf-8") as f:
        return sorted(f.read().splitlines())


def _rows_by_image(path):
    rows = {}
    for line in _lines(path):
        if line != BOP_CSV_HEADER:
            f = line.split(",")
            rows.setdefault((int(f[0]), int(f[1])), []).append(line)
    return rows


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """(cli, YCB-Video-style folder, reference CSV of one CLI process)."""
    cli = _cli()
    tmp = tmp_path_factory.mktemp("dask")
    _run([cli, "synth", "--out", tmp / "a", "--count", "3", "--seed", "11", "--clutter", "1", "--target", "lshape"])
    _run([cli, "synth", "--out", tmp / "b", "--count", "3", "--seed", "21", "--clutter", "1", "--target", "torus"])
    ds = tmp / "ds"
    (ds / "models").mkdir(parents=True)
    shutil.copy(tmp / "a" / "scene_000" / "lshape.ply", ds / "models" / "lshape.ply")  # obj_id 22
    shutil.copy(tmp / "b" / "scene_000" / "torus.ply", ds / "models" / "025_mug.ply")  # a YCB-Video name: obj_id 14
    for k in range(3):
        # Folder names: "scene_00k" has no two trailing numbers (scene 0, image = position k + 1);
        # "ycbv_0002_00000k" is scene 2, image k + 1.
        shutil.copytree(tmp / "a" / f"scene_{k:03d}", ds / "scenes" / f"scene_{k:03d}")
        dst = ds / "scenes" / f"ycbv_0002_{k + 1:06d}"
        shutil.copytree(tmp / "b" / f"scene_{k:03d}", dst)
        gt = json.loads((dst / "gt.json").read_text())
        for o in gt["objects"]:
            o["obj"] = "025_mug"
        (dst / "gt.json").write_text(json.dumps(gt))
    # A second instance of the L-shape in scene 0 image 2 (inst_count 2: two rows).
    gt_path = ds / "scenes" / "scene_001" / "gt.json"
    gt = json.loads(gt_path.read_text())
    twin = json.loads(json.dumps(gt["objects"][0]))
    twin["t"][0] += 0.06
    gt["objects"].append(twin)
    gt_path.write_text(json.dumps(gt))
    ref = tmp / "ref.csv"
    _cli_run_dataset(cli, ds, ref)
    return cli, ds, ref


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as c:
        yield c


def test_cli_no_time_runs_are_identical(data, tmp_path):
    cli, ds, ref = data
    again = tmp_path / "again.csv"
    _cli_run_dataset(cli, ds, again)
    assert again.read_bytes() == ref.read_bytes()
    assert all(line.endswith(",-1.000000") for line in _lines(ref) if line != BOP_CSV_HEADER)


def test_targets_are_the_cli_images(data):
    """list_targets (the tasks) names the images and instances the CLI estimated."""
    cli, ds, ref = data
    targets = list_targets(ds)
    rows = _rows_by_image(ref)
    assert sorted({(t["scene_id"], t["im_id"]) for t in targets}) == sorted(rows) == \
        [(0, 1), (0, 2), (0, 3), (2, 1), (2, 2), (2, 3)]
    mug = pf.ycbv_class_names().index("025_mug") + 1
    assert {t["obj_id"] for t in targets} == {22, mug}
    for t in targets:
        objs = [int(r.split(",")[2]) for r in rows[(t["scene_id"], t["im_id"])]]
        assert objs.count(t["obj_id"]) == t["inst_count"]
    assert [t["inst_count"] for t in targets if (t["scene_id"], t["im_id"]) == (0, 2)] == [2]


def test_bop_targets_are_the_cli_images(data, tmp_path):
    """The same check on a BOP copy of the folder: targets from scene_gt.json, then from
    test_targets_bop19.json."""
    cli, ycbv, _ = data
    bop = tmp_path / "bop"
    (bop / "models").mkdir(parents=True)
    info = {}
    for obj_id, name in ((1, "lshape"), (5, "025_mug")):
        mesh = pf.load_mesh(str(ycbv / "models" / f"{name}.ply"))
        info[str(obj_id)] = {"diameter": mesh.diameter() * 1000}
        mm = pf.Mesh(np.asarray(mesh.vertices) * 1000, mesh.faces, name)
        mm.save_ply(str(bop / "models" / f"obj_{obj_id:06d}.ply"))
    (bop / "models" / "models_info.json").write_text(json.dumps(info))
    (bop / "test" / "notes").mkdir(parents=True)  # not a scene folder: ignored
    for scene_id, prefix, obj_id in ((1, "scene_", 1), (7, "ycbv_0002_", 5)):
        folders = sorted(p for p in (ycbv / "scenes").iterdir() if p.name.startswith(prefix))
        sdir = bop / "test" / f"{scene_id:06d}"
        (sdir / "depth").mkdir(parents=True)
        cams, gts = {}, {}
        for im_id, folder in enumerate(folders, start=3):
            cam = json.loads((folder / "camera.json").read_text())
            cams[str(im_id)] = {"cam_K": [cam["fx"], 0, cam["cx"], 0, cam["fy"], cam["cy"], 0, 0, 1],
                                "depth_scale": cam["depth_scale"] * 1000}
            gts[str(im_id)] = [{"obj_id": obj_id, "cam_R_m2c": np.ravel(o["R"]).tolist(),
                                "cam_t_m2c": (np.asarray(o["t"]) * 1000).tolist()}
                               for o in json.loads((folder / "gt.json").read_text())["objects"]]
            shutil.copy(folder / "depth.png", sdir / "depth" / f"{im_id:06d}.png")
        (sdir / "scene_camera.json").write_text(json.dumps(cams))
        (sdir / "scene_gt.json").write_text(json.dumps(gts))

    def check(out):
        _cli_run_dataset(cli, bop, out)
        rows = _rows_by_image(out)
        targets = list_targets(bop)
        assert sorted({(t["scene_id"], t["im_id"]) for t in targets}) == sorted(rows)
        for t in targets:
            objs = [int(r.split(",")[2]) for r in rows[(t["scene_id"], t["im_id"])]]
            assert objs.count(t["obj_id"]) == t["inst_count"]
        return targets

    targets = check(tmp_path / "gt.csv")
    assert [(t["scene_id"], t["im_id"], t["obj_id"], t["inst_count"]) for t in targets] == \
        [(1, 3, 1, 1), (1, 4, 1, 2), (1, 5, 1, 1), (7, 3, 5, 1), (7, 4, 5, 1), (7, 5, 5, 1)]
    subset = [{"scene_id": 7, "im_id": 4, "obj_id": 5, "inst_count": 1},
              {"scene_id": 1, "im_id": 4, "obj_id": 1, "inst_count": 1}]
    (bop / "test_targets_bop19.json").write_text(json.dumps(subset))
    assert check(tmp_path / "bop19.csv") == sorted(subset, key=lambda t: (t["scene_id"], t["im_id"]))


def test_cluster_csv_is_the_single_process_csv(data, client, tmp_path):
    cli, ds, ref = data
    out = tmp_path / "dask.csv"
    seen = []
    s = run_dataset(client, ds, out, prior=PRIOR, options=OPTIONS, cli=cli, no_time=True,
                    progress=lambda done, total, image: seen.append((done, total, image)))
    assert _lines(out) == _lines(ref)
    assert out.read_text().startswith(BOP_CSV_HEADER + "\n")
    assert (s.images, s.done, s.skipped, s.rows) == (6, 6, 0, 7)
    assert [d for d, _, _ in seen] == [1, 2, 3, 4, 5, 6] and {t for _, t, _ in seen} == {6}
    assert sorted(im for _, _, im in seen) == sorted(_rows_by_image(ref))
    # Several images per task; a second call on the finished CSV does nothing.
    out4 = tmp_path / "chunk.csv"
    run_dataset(client, ds, out4, prior=PRIOR, options=OPTIONS, cli=cli, no_time=True, chunk=4)
    assert _lines(out4) == _lines(ref)
    s = run_dataset(client, ds, out4, prior=PRIOR, options=OPTIONS, cli=cli, no_time=True)
    assert (s.done, s.skipped, s.rows) == (0, 6, 0)
    assert _lines(out4) == _lines(ref)


def test_resume_skips_done_images_and_repairs_a_torn_row(data, client, tmp_path):
    cli, ds, ref = data
    rows = _rows_by_image(ref)
    first = (0, 1)
    out = tmp_path / "resume.csv"
    out.write_text(BOP_CSV_HEADER + "\n" + "".join(r + "\n" for r in rows[first]))
    seen = []
    s = run_dataset(client, ds, out, prior=PRIOR, options=OPTIONS, cli=cli, no_time=True,
                    progress=lambda done, total, image: seen.append(image))
    assert _lines(out) == _lines(ref)
    assert (s.done, s.skipped, s.rows) == (5, 1, 6)
    assert first not in seen and len(seen) == 5

    # A crash mid-append: image (0, 2)'s first row whole, its second cut. The torn row and the
    # image's whole rows go, the image is estimated again, as `posefilter run-dataset` does.
    two = rows[(0, 2)]
    assert len(two) == 2
    torn_text = BOP_CSV_HEADER + "\n" + "".join(r + "\n" for r in rows[first]) + two[0] + "\n" + two[1][:30]
    out = tmp_path / "torn.csv"
    out.write_text(torn_text)
    with pytest.warns(RuntimeWarning, match="torn row .* removed it and 1 complete row"):
        s = run_dataset(client, ds, out, prior=PRIOR, options=OPTIONS, cli=cli, no_time=True)
    assert _lines(out) == _lines(ref)
    assert (s.done, s.skipped) == (5, 1)
    by_cli = tmp_path / "torn_cli.csv"
    by_cli.write_text(torn_text)
    _cli_run_dataset(cli, ds, by_cli)
    assert _lines(by_cli) == _lines(ref)


def test_killed_worker_loses_no_rows(data, tmp_path, monkeypatch):
    from distributed import Client, LocalCluster

    cli, ds, ref = data
    # A CLI that takes at least 0.5 s per task, so that the other worker is mid-task when the
    # first image's rows arrive.
    slow = tmp_path / "slow-posefilter"
    slow.write_text(f"#!/bin/sh\nsleep 0.5\nexec '{cli}' \"$@\"\n")
    slow.chmod(0o755)
    monkeypatch.setenv("TMPDIR", str(tmp_path))  # the workers' scratch folders (a killed one keeps its)
    out = tmp_path / "killed.csv"
    killed = {}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.CRITICAL) as cluster, Client(cluster) as c:
        pids = c.run(os.getpid)

        def kill_one(done, total, image):
            if killed:
                return
            processing = c.processing()
            victim = max(processing, key=lambda a: len(processing[a]))
            killed["tasks"] = list(processing[victim])
            os.kill(pids[victim], signal.SIGKILL)
            killed["worker"] = victim

        s = run_dataset(c, ds, out, prior=PRIOR, options=OPTIONS, cli=slow, no_time=True, progress=kill_one)
    assert killed["tasks"], "the killed worker had no task"
    assert _lines(out) == _lines(ref)
    assert (s.done, s.rows) == (6, 7)


def test_errors_name_the_cause(data, client, tmp_path):
    cli, ds, _ = data
    out = tmp_path / "err.csv"
    with pytest.raises(FileNotFoundError, match="no_such_dataset: dataset folder not found"):
        run_dataset(client, tmp_path / "no_such_dataset", out, prior=PRIOR, cli=cli)
    with pytest.raises(ValueError, match="unknown run-dataset option --partikles"):
        run_dataset(client, ds, out, prior=PRIOR, options=dict(partikles=60), cli=cli)
    with pytest.raises(ValueError, match="--out is set by run_dataset"):
        run_dataset(client, ds, out, prior=PRIOR, options={"out": "x.csv"}, cli=cli)
    with pytest.raises(ValueError, match="prior must be"):
        run_dataset(client, ds, out, prior="gt", cli=cli)
    with pytest.raises(FileNotFoundError, match="/nonexistent/posefilter"):
        run_dataset(client, ds, out, prior=PRIOR, cli="/nonexistent/posefilter")
    # The CLI rejects a value: the error names an image and carries the CLI's message.
    with pytest.raises(RunDatasetError, match=r"scene \d image \d failed: .*--particles"):
        run_dataset(client, ds, out, prior=PRIOR, options=dict(particles=-5), cli=cli, retries=0)
    assert not out.exists()  # an error before the first row leaves no file behind
    # An existing file that is not a results CSV (no final newline, what the torn-row repair
    # would cut): refused before anything in it changes.
    other = tmp_path / "gt.json"
    other.write_text('{"objects": []}')
    with pytest.raises(ValueError, match="header must be exactly .* left as it is"):
        run_dataset(client, ds, other, prior=PRIOR, cli=cli)
    assert other.read_text() == '{"objects": []}'


def test_the_cli_built_with_the_module_is_found_without_cli(data, client, tmp_path):
    """As docs/DATASETS.md runs it after the README's build: no cli=, no posefilter on PATH."""
    cli, ds, ref = data
    built = built_cli()
    if built is None:
        pytest.skip("the module is not in a build tree (installed): no CLI beside it")
    assert os.path.samefile(built, cli)
    # The workers (started without $POSEFILTER_CLI) resolve to the client's build.
    assert not any(client.run(os.environ.get, "POSEFILTER_CLI").values())
    assert client.submit(_probe_cli, None, built, pure=False).result()[0] == built
    out = tmp_path / "nocli.csv"
    s = run_dataset(client, ds, out, prior=PRIOR, options=OPTIONS, no_time=True)
    assert s.done == 6 and _lines(out) == _lines(ref)


def test_a_second_writer_is_refused_and_the_file_kept(data, client, tmp_path):
    import fcntl

    cli, ds, _ = data
    out = tmp_path / "locked.csv"
    out.write_text(BOP_CSV_HEADER + "\n")
    with open(out, "rb") as held:
        fcntl.flock(held.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(RuntimeError, match="another process is writing this results CSV"):
            run_dataset(client, ds, out, prior=PRIOR, options=OPTIONS, cli=cli)
    assert out.read_text() == BOP_CSV_HEADER + "\n"
    fifo = tmp_path / "fifo.csv"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        run_dataset(client, ds, fifo, prior=PRIOR, options=OPTIONS, cli=cli)


def test_worker_needs_no_posefilter_package(data, tmp_path):
    """The tasks travel by value: a `dask worker` that cannot import posefilter runs them."""
    from distributed import Client, LocalCluster

    cli, ds, ref = data
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONNOUSERSITE"] = "1"
    env["TMPDIR"] = str(tmp_path)

    out = tmp_path / "bare.csv"
    with LocalCluster(n_workers=0, processes=True, dashboard_address=":0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as c:
        worker = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", cluster.scheduler_address,
                                   "--nthreads", "1", "--no-nanny", "--no-dashboard"], env=env, cwd=str(tmp_path),
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            c.wait_for_workers(1, timeout=60)
            if any(spec is not None for spec in c.run(importlib.util.find_spec, "posefilter").values()):
                pytest.skip("posefilter is importable without PYTHONPATH here (installed)")
            s = run_dataset(c, ds, out, prior=PRIOR, options=OPTIONS, cli=cli, no_time=True)
        finally:
            # A worker still closing its comms after 30 s on a loaded machine is killed: what is
            # tested is that it ran the tasks, not how fast it shuts down.
            worker.terminate()
            try:
                worker.wait(timeout=30)
            except subprocess.TimeoutExpired:
                worker.kill()
                worker.wait()
    assert s.done == 6 and _lines(out) == _lines(ref)
