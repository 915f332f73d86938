#!/usr/bin/env python3
"""ctest get_data: scripts/get_data.sh without a network. A small BOP YCB-V lookalike (the
three archives with the hosting's folder layout, and a file listing with each archive's size and
SHA-256) is served from file:// addresses; the script must lay out the first N test images with
the target list cut to them, and refuse an archive whose checksum differs, a listing without a
checksum and an archive member that leaves the target folder, unpacking nothing. Then the local
copy route: the development set in $POSEFILTER_DATA (or the shared folder) checks clean, and a
changed byte is an error naming the file (skipped, exit 77, when no copy is present).

    get_data_test.py SOURCE_DIR [SHARED_DATA_DIR]
"""

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile

SRC = os.path.abspath(sys.argv[1])
SCRIPT = os.path.join(SRC, "scripts", "get_data.sh")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def make_archives(folder, evil=False):
    targets = [{"scene_id": s, "im_id": i, "obj_id": 1, "inst_count": 1} for s, i in ((48, 1), (48, 2), (48, 3), (49, 1))]
    with zipfile.ZipFile(os.path.join(folder, "ycbv_base.zip"), "w") as z:
        z.writestr("ycbv/test_targets_bop19.json", json.dumps(targets))
        z.writestr("ycbv/dataset_info.md", "lookalike")
    with zipfile.ZipFile(os.path.join(folder, "ycbv_models.zip"), "w") as z:
        z.writestr("models/models_info.json", json.dumps({"1": {"diameter": 100.0}}))
        z.writestr("models/obj_000001.ply", "ply\n")
        z.writestr("models_eval/obj_000001.ply", "not kept")
    with zipfile.ZipFile(os.path.join(folder, "ycbv_test_bop19.zip"), "w") as z:
        for scene, images in ((48, (1, 2, 3)), (49, (1,))):
            for name in ("scene_camera.json", "scene_gt.json"):
                z.writestr(f"test/{scene:06d}/{name}", "{}")
            for i in images:
                for kind in ("depth", "rgb", "mask_visib"):
                    z.writestr(f"test/{scene:06d}/{kind}/{i:06d}.png", f"{kind} {scene} {i}")
        if evil:
            z.writestr("test/000048/../../../escaped.txt", "outside")


def listing(folder, corrupt=None, missing=None, out_name="listing.json"):
    entries = []
    for name in ("ycbv_base.zip", "ycbv_models.zip", "ycbv_test_bop19.zip"):
        if name == missing:
            continue
        data = open(os.path.join(folder, name), "rb").read()
        digest = hashlib.sha256(data + (b"x" if name == corrupt else b"")).hexdigest()
        entries.append({"type": "file", "path": name, "size": len(data), "lfs": {"oid": digest, "size": len(data)}})
    path = os.path.join(folder, out_name)
    with open(path, "w") as f:
        json.dump(entries, f)
    return path


def run(args, env_extra):
    env = {k: v for k, v in os.environ.items() if k != "POSEFILTER_DATA"}
    env.update(env_extra)
    return subprocess.run([SCRIPT] + args, capture_output=True, text=True, env=env)


with tempfile.TemporaryDirectory(prefix="get_data_test_") as tmp:
    host = os.path.join(tmp, "host")
    os.makedirs(host)
    make_archives(host)
    env = {"POSEFILTER_BOP_URL": "file://" + host, "POSEFILTER_BOP_LISTING": "file://" + listing(host)}
    out = os.path.join(tmp, "out")
    p = run(["ycbv", out, "--images", "2"], env)
    check(p.returncode == 0, f"download route exit {p.returncode}: {p.stderr}")
    root = os.path.join(out, "ycbv_bop")
    check(f"export POSEFILTER_DATA={out}" in p.stdout, f"no export line: {p.stdout}")
    check(os.path.isfile(os.path.join(root, "models", "obj_000001.ply")), "models/obj_000001.ply missing")
    check(not os.path.exists(os.path.join(root, "models_eval")), "models_eval unpacked")
    check(sorted(os.listdir(os.path.join(root, "test", "000048", "depth"))) == ["000001.png", "000002.png"],
          "depth images kept are not the first two targets")
    check(not os.path.exists(os.path.join(root, "test", "000048", "mask_visib")), "masks unpacked")
    check(not os.path.exists(os.path.join(root, "test", "000049")), "scene 49 unpacked although not kept")
    kept = json.load(open(os.path.join(root, "test_targets_bop19.json")))
    check([(t["scene_id"], t["im_id"]) for t in kept] == [(48, 1), (48, 2)], f"target list not cut: {kept}")
    check(os.listdir(out) == ["ycbv_bop"], f"temporary files left: {os.listdir(out)}")

    # A checksum that differs, or none published: an error naming the archive, nothing unpacked.
    for what, lst, name in (("corrupt", listing(host, corrupt="ycbv_models.zip", out_name="c.json"), "ycbv_models.zip"),
                            ("unlisted", listing(host, missing="ycbv_test_bop19.zip", out_name="u.json"),
                             "ycbv_test_bop19.zip")):
        bad_out = os.path.join(tmp, what)
        p = run(["ycbv", bad_out], {**env, "POSEFILTER_BOP_LISTING": "file://" + lst})
        check(p.returncode == 1 and name in p.stderr, f"{what}: exit {p.returncode}, stderr {p.stderr!r}")
        check(not os.path.exists(os.path.join(bad_out, "ycbv_bop")), f"{what}: something was unpacked")

    # An archive member that would leave the target folder.
    evil_host = os.path.join(tmp, "evil_host")
    os.makedirs(evil_host)
    make_archives(evil_host, evil=True)
    evil_out = os.path.join(tmp, "evil")
    p = run(["ycbv", evil_out], {"POSEFILTER_BOP_URL": "file://" + evil_host,
                                 "POSEFILTER_BOP_LISTING": "file://" + listing(evil_host)})
    check(p.returncode == 1 and "outside the target folder" in p.stderr, f"zip slip: exit {p.returncode} {p.stderr!r}")
    check(not os.path.exists(os.path.join(tmp, "escaped.txt")), "zip slip: a file escaped")

    # Usage errors.
    check(run(["ycbv", out, "--images", "0"], env).returncode == 2, "--images 0 accepted")
    check(run(["nosuchset"], env).returncode == 2, "unknown data set accepted")

    # The local copy route, on the development set when one is present.
    data = os.environ.get("POSEFILTER_DATA") or (sys.argv[2] if len(sys.argv) > 2 else "")
    if not data or not os.path.isdir(os.path.join(data, "ycbv")):
        print("get_data_test: no development set ($POSEFILTER_DATA/ycbv or SHARED_DATA_DIR/ycbv): local route skipped")
        if failures:
            sys.exit(1)
        sys.exit(77)
    copy = os.path.join(tmp, "copy")
    p = run(["ycbv", copy], {"POSEFILTER_DATA": data})
    check(p.returncode == 0 and "files of the YCB-Video development set checked" in p.stdout,
          f"local route: exit {p.returncode} {p.stderr}")
    camera = os.path.join(copy, "ycbv", "scenes", "ycbv_0000_000001", "camera.json")
    check(os.path.isfile(camera), "local route: copy not made")
    with open(camera, "a") as f:
        f.write(" ")
    p = run(["ycbv"], {"POSEFILTER_DATA": copy})
    check(p.returncode == 1 and "ycbv_0000_000001/camera.json: SHA-256 differs" in p.stderr,
          f"changed file: exit {p.returncode} {p.stderr!r}")

sys.exit(1 if failures else 0)
