#!/usr/bin/env python3
"""Fetches the real data sets posefilter's examples, tests and `suite --world ycbv` read, and lays
them out as the commands expect (README "Data"). Standard library only. Entry point:
scripts/get_data.sh.

    scripts/get_data.sh ycbv [DIR] [--images N]

Two sources, one layout under DIR (default: $POSEFILTER_DATA, else ./data):

* A local copy: POSEFILTER_DATA=SRC, where SRC/ycbv is the YCB-Video development set (21 meshes
  in metres, their model points, 10 frames of video 0000 with ground truth: the layout of
  docs/DATASETS.md "YCB-Video folder"). Every file is checked against the SHA-256 list
  scripts/data/ycbv_dev.sha256; a missing or changed file is an error naming it. With DIR, the
  checked files are copied to DIR/ycbv; without, SRC is used where it is.
* The BOP hosting (https://bop.felk.cvut.cz/datasets/, served from Hugging Face): the archives
  ycbv_base.zip, ycbv_models.zip and ycbv_test_bop19.zip. Each is checked against the size and
  SHA-256 that the hosting publishes for it (the Git LFS object id of its file listing) before
  anything is unpacked. Unpacked to DIR/ycbv_bop, a BOP dataset folder that run-dataset, eval
  --dataset, track and suite --world ycbv --models DIR/ycbv_bop/models read: the base files, the
  models, and the first N images (--images, default 20) of the BOP'19 test targets, with the
  target list cut to them.

POSEFILTER_BOP_URL and POSEFILTER_BOP_LISTING replace the hosting's file and listing addresses
(a mirror; the tests use file:// addresses).
"""

import argparse
import hashlib
import json
import os
import shutil
import sys
import tempfile
import urllib.error
import urllib.request
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
BOP_URL = "https://huggingface.co/datasets/bop-benchmark/ycbv/resolve/main"
BOP_LISTING = "https://huggingface.co/api/datasets/bop-benchmark/ycbv/tree/main"
ARCHIVES = ("ycbv_base.zip", "ycbv_models.zip", "ycbv_test_bop19.zip")
CHUNK = 1 << 20
MANIFEST = os.path.join(HERE, "ycbv_dev.sha256")  # the development set's files and their SHA-256


class DataError(Exception):
    """A one-line reason the data could not be fetched or checked."""


def sha256_of(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(CHUNK), b""):
            digest.update(block)
    return digest.hexdigest()


def read_manifest(path):
    """{relative path: sha256} from a `sha256sum`-style list."""
    out = {}
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            digest, _, rel = line.partition("  ")
            if len(digest) != 64 or not rel:
                raise DataError(f"{path}: line {n}: expected '<sha256>  <path>'")
            out[rel] = digest
    return out


def check_local_copy(src, manifest):
    """Checks every file of the manifest under src; returns how many were checked."""
    bad = []
    for rel, digest in sorted(manifest.items()):
        path = os.path.join(src, rel)
        if not os.path.isfile(path):
            bad.append(f"{path}: missing")
        elif sha256_of(path) != digest:
            bad.append(f"{path}: SHA-256 differs from {os.path.relpath(MANIFEST, os.getcwd())}")
    if bad:
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        raise DataError(bad[0] + more)
    return len(manifest)


def fetch(url, dest):
    try:
        with urllib.request.urlopen(url, timeout=60) as r, open(dest, "wb") as f:
            shutil.copyfileobj(r, f, CHUNK)
    except (urllib.error.URLError, OSError) as e:
        raise DataError(f"{url}: download failed ({getattr(e, 'reason', e)})") from None


def published_checksums(listing_url):
    """{file name: (size, sha256)} from the hosting's listing (JSON list of {path, size, lfs:
    {oid, size}})."""
    try:
        with urllib.request.urlopen(listing_url, timeout=60) as r:
            entries = json.loads(r.read().decode("utf-8"))
    except (urllib.error.URLError, OSError) as e:
        raise DataError(f"{listing_url}: cannot read the file listing ({getattr(e, 'reason', e)})") from None
    except (json.JSONDecodeError, UnicodeDecodeError):
        raise DataError(f"{listing_url}: the file listing is not JSON") from None
    out = {}
    for e in entries if isinstance(entries, list) else []:
        lfs = e.get("lfs") if isinstance(e, dict) else None
        if isinstance(lfs, dict) and isinstance(lfs.get("oid"), str) and isinstance(lfs.get("size"), int):
            out[os.path.basename(str(e.get("path", "")))] = (lfs["size"], lfs["oid"])
    return out


def check_members(archive):
    """Refuses the whole archive when any member's name is absolute or climbs out with '..'."""
    for n in archive.namelist():
        if n.startswith("/") or ".." in n.replace("\\", "/").split("/"):
            raise DataError(f"{os.path.basename(archive.filename)}: member {n!r} would be written outside the "
                            "target folder; nothing was unpacked")


def unpack(archive_path, target, keep=None, strip=""):
    """Unpacks the members of the archive whose names (after `strip`) `keep` accepts."""
    with zipfile.ZipFile(archive_path) as z:
        check_members(z)
        for info in z.infolist():
            name = info.filename
            if not name.startswith(strip) or info.is_dir():
                continue
            rel = name[len(strip):]
            if not rel or (keep is not None and not keep(rel)):
                continue
            out = os.path.join(target, rel)
            os.makedirs(os.path.dirname(out), exist_ok=True)
            with z.open(info) as src, open(out, "wb") as dst:
                shutil.copyfileobj(src, dst, CHUNK)


def bop_download(dest, images):
    base_url = os.environ.get("POSEFILTER_BOP_URL", BOP_URL).rstrip("/")
    listing = os.environ.get("POSEFILTER_BOP_LISTING", BOP_LISTING)
    sums = published_checksums(listing)
    target = os.path.join(dest, "ycbv_bop")
    with tempfile.TemporaryDirectory(prefix="posefilter-data-", dir=dest) as tmp:
        paths = {}
        for name in ARCHIVES:
            if name not in sums:
                raise DataError(f"{listing}: no size and SHA-256 for {name}; refusing to use it unchecked")
            size, digest = sums[name]
            path = os.path.join(tmp, name)
            print(f"get_data: {base_url}/{name} ({size / 1e6:.1f} MB)", flush=True)
            fetch(f"{base_url}/{name}", path)
            if os.path.getsize(path) != size or sha256_of(path) != digest:
                raise DataError(f"{name}: size or SHA-256 differs from the hosting's listing "
                                f"({os.path.getsize(path)} bytes); nothing was unpacked")
            paths[name] = path
        for path in paths.values():
            try:
                with zipfile.ZipFile(path) as z:
                    check_members(z)
            except zipfile.BadZipFile:
                raise DataError(f"{os.path.basename(path)}: not a zip archive") from None
        staging = os.path.join(tmp, "ycbv_bop")
        unpack(paths["ycbv_base.zip"], staging, strip="ycbv/")
        unpack(paths["ycbv_models.zip"], staging, keep=lambda rel: rel.startswith("models/"))
        targets_path = os.path.join(staging, "test_targets_bop19.json")
        if not os.path.isfile(targets_path):
            raise DataError("ycbv_base.zip: no ycbv/test_targets_bop19.json")
        with open(targets_path, encoding="utf-8") as f:
            targets = json.load(f)
        kept_images = sorted({(t["scene_id"], t["im_id"]) for t in targets})[:images]
        kept = set(kept_images)
        scenes = {s for s, _ in kept}

        def keep(rel):
            parts = rel.split("/")  # test/<scene>/<file> or test/<scene>/<kind>/<image>.png
            if len(parts) < 3 or parts[0] != "test" or not parts[1].isdigit() or int(parts[1]) not in scenes:
                return False
            if len(parts) == 3:
                return parts[2].endswith(".json")
            stem = os.path.splitext(parts[3])[0]
            return parts[2] in ("depth", "rgb") and stem.isdigit() and (int(parts[1]), int(stem)) in kept

        unpack(paths["ycbv_test_bop19.zip"], staging, keep=keep)
        with open(targets_path, "w", encoding="utf-8") as f:
            json.dump([t for t in targets if (t["scene_id"], t["im_id"]) in kept], f, indent=1)
        if os.path.exists(target):
            shutil.rmtree(target)
        os.replace(staging, target)
    return target, len(kept_images)


def main():
    ap = argparse.ArgumentParser(prog="scripts/get_data.sh", description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", choices=["ycbv"], help="the data set (ycbv: YCB-Video)")
    ap.add_argument("dir", nargs="?", help="where to lay it out (default: $POSEFILTER_DATA, else ./data)")
    ap.add_argument("--images", type=int, default=20, help="BOP download: test images kept (default 20)")
    args = ap.parse_args()
    if args.images < 1:
        ap.error("--images must be at least 1")
    try:
        local = os.environ.get("POSEFILTER_DATA")
        if local and os.path.isdir(os.path.join(local, "ycbv")):
            src = os.path.abspath(os.path.join(local, "ycbv"))
            manifest = read_manifest(MANIFEST)
            n = check_local_copy(src, manifest)
            where = os.path.abspath(local)
            if args.dir and os.path.abspath(args.dir) != where:
                where = os.path.abspath(args.dir)
                for rel in sorted(manifest):
                    out = os.path.join(where, "ycbv", rel)
                    os.makedirs(os.path.dirname(out), exist_ok=True)
                    shutil.copyfile(os.path.join(src, rel), out)
            print(f"get_data: {n} files of the YCB-Video development set checked in {src}")
            print(f"export POSEFILTER_DATA={where}")
            return 0
        dest = os.path.abspath(args.dir or local or "data")
        os.makedirs(dest, exist_ok=True)
        target, count = bop_download(dest, args.images)
        print(f"get_data: BOP YCB-V with {count} test image(s) in {target}")
        print(f"export POSEFILTER_DATA={dest}")
        return 0
    except DataError as e:
        print(f"get_data: error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
