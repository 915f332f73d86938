"""Run ``posefilter run-dataset`` over a Dask cluster: one task per image (or per ``chunk``
images), the rows appended to one BOP results CSV on the client as they arrive.

    from dask.distributed import Client
    from posefilter.distributed import run_dataset

    client = Client("tcp://scheduler:8786")
    summary = run_dataset(client, "/shared/bop/ycbv", "results.csv", prior=("gt-boxes", 8),
                          options={"particles": 200, "restarts": 1, "threads": 1})

Each task runs the ``posefilter`` CLI on a worker (``run-dataset --images`` naming its images)
and returns the CSV rows; the workers need the CLI, the dataset at the same
path, and Dask, but not this Python package (the task functions travel by value). The CLI is
``cli=`` when given, else the worker's $POSEFILTER_CLI, else the CLI built with this module
(``build/release/posefilter`` beside ``build/release/python``) where that path exists on the
worker, else ``posefilter`` on the worker's PATH. The client asks the library for the dataset's
target list (the images run-dataset estimates, ``posefilter._posefilter.dataset_targets``),
skips the images already in ``out`` (resume), holds an exclusive lock on ``out`` (flock, as the
CLI does), and appends and fsyncs each image's rows when its task finishes, so an interrupted
client loses no finished image; an error before the first row leaves no new file behind. Tasks of a worker that dies are rerun elsewhere by Dask. Rows do not depend on which
images run together (each target's seed derives from --seed, scene, image, object), so the CSV
holds the rows of a single-process ``posefilter run-dataset`` run, in another order.

docs/DATASETS.md ("Many machines: Dask") has the cluster setup.
"""

from __future__ import annotations

import os
import stat
import uuid
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

__all__ = ["RunDatasetError", "RunSummary", "built_cli", "list_targets", "run_dataset", "BOP_CSV_HEADER"]

# The header `posefilter run-dataset` writes (kBopCsvHeader, include/posefilter/bop.h).
BOP_CSV_HEADER = "scene_id,im_id,obj_id,score,R,t,time"

# run-dataset flags that run_dataset sets itself (its own arguments), not through `options`.
_RESERVED = {
    "dataset": "the dataset argument",
    "split": "split=",
    "out": "the out argument",
    "targets": "targets=",
    "quiet": "(always set)",
    "no-time": "no_time=",
    "limit": "targets= (a subset of the targets)",
    "images": "targets= (the tasks' images)",
    "detections": "prior=('detections', PATH)",
    "gt-boxes": "prior=('gt-boxes', SIGMA_PX)",
    "uniform-prior": "prior='uniform'",
    "auto-prior": "prior='auto'",
    "help": "(not an option)",
}



class RunDatasetError(RuntimeError):
    """A run_dataset task failed (after its retries): the message names the image(s) and holds
    the CLI's stderr. The rows of the images finished before it are in the CSV; rerun to
    resume."""


@dataclass
class RunSummary:
    """What a run_dataset call did."""

    out: str                 # the results CSV
    images: int              # images with targets
    done: int                # images estimated by this call
    skipped: int             # images already in the CSV when it started
    rows: int                # rows appended by this call
    warnings: list[str] = field(default_factory=list)  # the CLI's warnings (targets without an estimate)


# ---- Worker side. These functions run on the workers and use the standard library only: the
# module is registered with cloudpickle to travel by value, so a worker needs no posefilter
# Python package, only the CLI.

def _resolve_cli(cli, built=None):
    """The CLI on this worker: `cli`, else $POSEFILTER_CLI, else `built` (the CLI built with the
    client's module) when it exists here, else `posefilter` on PATH."""
    import os
    import shutil
    import socket

    path = cli or os.environ.get("POSEFILTER_CLI")
    if not path and built and os.access(built, os.X_OK):
        path = built
    path = path or shutil.which("posefilter")
    if not path:
        raise FileNotFoundError(
            f"no posefilter CLI on worker host {socket.gethostname()}"
            + (f" (nor the client's build, {built})" if built else "")
            + ": pass cli=PATH to run_dataset, set POSEFILTER_CLI in the worker's environment, or put "
            "posefilter on the worker's PATH")
    if os.sep in path and not os.access(path, os.X_OK):
        raise FileNotFoundError(f"{path}: posefilter CLI not found or not executable on worker host "
                                f"{socket.gethostname()}")
    if os.sep not in path:
        found = shutil.which(path)
        if not found:
            raise FileNotFoundError(f"{path}: posefilter CLI not on the PATH of worker host {socket.gethostname()}")
        path = found
    return path


def _probe_cli(cli, built=None):
    """(the CLI's path, run-dataset's option names) on the worker that runs this."""
    import re
    import subprocess

    path = _resolve_cli(cli, built)
    p = subprocess.run([path, "run-dataset", "--help"], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{path} run-dataset --help failed (exit {p.returncode}): {p.stderr.strip()[-2000:]}")
    names = sorted(set(re.findall(r"(?<![\w-])--([a-z0-9][a-z0-9-]*)", p.stdout)))
    return path, names


def _run_images(cli, built, dataset, split, flags, images, targets, where):
    """Runs `posefilter run-dataset --images` on some images ((scene_id, im_id) pairs); `targets`
    is None (the dataset's own targets), a targets JSON path, or a list of target entries
    (written to a file here). Returns {"rows": CSV rows without the header (text), "stderr": the
    CLI's warnings}."""
    import json
    import os
    import subprocess
    import tempfile

    path = _resolve_cli(cli, built)
    with tempfile.TemporaryDirectory(prefix="posefilter-dask-") as tmp:
        csv_path = os.path.join(tmp, "rows.csv")
        cmd = [path, "run-dataset", "--dataset", dataset, "--split", split,
               "--images", ",".join(f"{s}:{i}" for s, i in images), "--out", csv_path, "--quiet"]
        if isinstance(targets, str):
            cmd += ["--targets", targets]
        elif targets is not None:
            targets_path = os.path.join(tmp, "targets.json")
            with open(targets_path, "w", encoding="utf-8") as f:
                json.dump(targets, f)
            cmd += ["--targets", targets_path]
        p = subprocess.run(cmd + list(flags), capture_output=True, text=True, stdin=subprocess.DEVNULL)
        if p.returncode != 0:
            err = p.stderr.strip()
            if len(err) > 4000:
                err = "..." + err[-4000:]
            raise RuntimeError(f"posefilter run-dataset failed on {where} (exit {p.returncode}): {err}")
        text = ""
        if os.path.exists(csv_path):
            with open(csv_path, encoding="utf-8", newline="") as f:
                text = f.read()
    header, _, rows = text.partition("\n")
    if text and header.rstrip("\r") != "scene_id,im_id,obj_id,score,R,t,time":
        raise RuntimeError(f"posefilter run-dataset on {where} wrote an unexpected CSV header {header!r}")
    return {"rows": rows, "stderr": p.stderr}


def _register_by_value():
    try:
        import sys

        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[__name__])
    except (ImportError, AttributeError, ValueError):  # cloudpickle < 2.0: workers import posefilter
        pass


# ---- Client side.

def built_cli() -> str | None:
    """The `posefilter` CLI built together with this module: in a build tree the module is
    <build>/python/posefilter and the CLI <build>/posefilter. None when there is none (an
    installed module: then the CLI comes from PATH or $POSEFILTER_CLI)."""
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(os.path.dirname(os.path.dirname(here)), "posefilter")
    return path if os.path.isfile(path) and os.access(path, os.X_OK) else None


def _lock(path: str) -> int:
    """An exclusive advisory lock (flock) on the results CSV `path`, as run-dataset takes; a
    second writer, CLI or Python, is refused. Returns the descriptor that holds it."""
    import fcntl

    fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise RuntimeError(f"{path}: another process is writing this results CSV (it holds its lock); "
                           "wait for it to finish") from None
    return fd

def _image_key(row: str) -> str:
    """"scene_id,im_id" of a CSV row, or "" when it has fewer than two fields (as the CLI)."""
    a = row.find(",")
    if a < 0:
        return ""
    b = row.find(",", a + 1)
    return "" if b < 0 else row[:b]


def _int_field(entry: Mapping, key: str, where: str) -> int:
    if not isinstance(entry, Mapping) or key not in entry:
        raise ValueError(f"{where}: missing \"{key}\"")
    v = entry[key]
    if isinstance(v, bool) or not isinstance(v, int):
        raise ValueError(f"{where}: \"{key}\" must be an integer, got {v!r}")
    return v


def _targets_from_list(entries: Any, source: str) -> list[dict]:
    if not isinstance(entries, (list, tuple)):
        raise ValueError(f"{source}: targets must be a list of {{scene_id, im_id, obj_id, inst_count}}")
    out = []
    for i, e in enumerate(entries):
        where = f"{source}: entry {i}"
        t = {k: _int_field(e, k, where) for k in ("scene_id", "im_id", "obj_id", "inst_count")}
        if t["inst_count"] < 1:
            raise ValueError(f"{where}: inst_count must be >= 1")
        out.append(t)
    return out


def list_targets(dataset: str | os.PathLike, split: str = "test", targets: Any = None) -> list[dict]:
    """The targets `posefilter run-dataset` estimates, as [{scene_id, im_id, obj_id,
    inst_count}] sorted by (scene_id, im_id, obj_id), from the library's dataset reader (the
    run-dataset's own, posefilter/bop.h): `targets` (a test_targets_bop19-style JSON file or
    list) when given; else <dataset>/test_targets_bop19.json when present, else every
    ground-truth object. A list's entries are checked here; its image and object ids, by the
    CLI."""
    root = os.fspath(dataset)
    if not os.path.isdir(root):
        raise FileNotFoundError(f"{root}: dataset folder not found")
    if targets is not None and not isinstance(targets, (str, os.PathLike)):
        out = _targets_from_list(targets, "targets")
    else:
        from ._posefilter import dataset_targets

        out = list(dataset_targets(root, split, "" if targets is None else os.fspath(targets)))
    out.sort(key=lambda t: (t["scene_id"], t["im_id"], t["obj_id"]))
    return out


def _prior_flags(prior: Any) -> list[str]:
    if isinstance(prior, str):
        if prior in ("uniform", "uniform-prior"):
            return ["--uniform-prior"]
        if prior in ("auto", "auto-prior"):
            return ["--auto-prior"]
    elif isinstance(prior, (tuple, list)) and len(prior) == 2 and isinstance(prior[0], str):
        kind, value = prior
        if kind in ("gt-boxes", "gt_boxes") and isinstance(value, (int, float)) and not isinstance(value, bool):
            return ["--gt-boxes", repr(float(value))]
        if kind == "detections" and isinstance(value, (str, os.PathLike)):
            path = os.path.abspath(os.fspath(value))
            if not os.path.isfile(path):
                raise FileNotFoundError(f"{path}: detections file not found (prior=('detections', ...))")
            return ["--detections", path]
    raise ValueError(f"prior must be 'uniform', 'auto', ('gt-boxes', SIGMA_PX) or ('detections', PATH), got {prior!r}")


def _option_flags(options: Mapping[str, Any] | None, known: Sequence[str] | None) -> list[str]:
    flags: list[str] = []
    for key, value in (options or {}).items():
        name = str(key).lstrip("-").replace("_", "-")
        if name in _RESERVED:
            raise ValueError(f"options: --{name} is set by run_dataset itself: use {_RESERVED[name]}")
        if known is not None and name not in known:
            raise ValueError(f"options: unknown run-dataset option --{name} (posefilter run-dataset --help "
                             "lists them)")
        if value is None:
            continue
        if value is True:
            flags.append(f"--{name}")
        elif value is False:
            if known is None or f"no-{name}" in known:
                flags.append(f"--no-{name}")
        elif isinstance(value, (list, tuple)):
            flags += [f"--{name}", ",".join(str(v) for v in value)]
        else:
            flags += [f"--{name}", str(value)]
    return flags


def _repair_and_read(out: str) -> set[tuple[int, int]]:
    """Checks the header, then drops a torn last row with its image's rows (as run-dataset's
    DropTornImage), returns the images already in the CSV. Missing or empty file: empty set. A
    file that does not start with the header is refused before anything in it changes."""
    if not os.path.exists(out):
        return set()
    with open(out, "rb") as f:
        data = f.read()
    if data and data.split(b"\n", 1)[0].rstrip(b"\r") != BOP_CSV_HEADER.encode("utf-8"):
        raise ValueError(f"{out}: line 1: header must be exactly \"{BOP_CSV_HEADER}\" (not a run-dataset CSV?); "
                         "the file is left as it is")
    if data and not data.endswith(b"\n"):
        nl = data.rfind(b"\n")
        keep, torn = data[:nl + 1], data[nl + 1:].decode("utf-8", "replace")
        lines = keep.decode("utf-8").split("\n")[:-1]
        key = _image_key(torn)
        if not key and len(lines) > 1:
            key = _image_key(lines[-1])
        kept = [line for i, line in enumerate(lines) if i == 0 or not key or _image_key(line) != key]
        dropped = len(lines) - len(kept)
        _write_atomically(out, "".join(line + "\n" for line in kept).encode("utf-8"))
        warnings.warn(f"{out} ended in a torn row ({len(torn)} bytes, a crash while writing); removed it and "
                      f"{dropped} complete row(s) of its image, which is estimated again", RuntimeWarning,
                      stacklevel=3)
        data = "".join(line + "\n" for line in kept).encode("utf-8")
    done = set()
    lines = data.decode("utf-8").split("\n")
    if not data:
        return done
    if lines[0].rstrip("\r") != BOP_CSV_HEADER:
        raise ValueError(f"{out}: line 1: header must be exactly \"{BOP_CSV_HEADER}\" (not a run-dataset CSV?)")
    for n, line in enumerate(lines[1:], start=2):
        line = line.rstrip("\r")
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != 7 or not fields[0].isdigit() or not fields[1].isdigit():
            raise ValueError(f"{out}: line {n}: expected 7 fields scene_id,im_id,obj_id,score,R,t,time")
        done.add((int(fields[0]), int(fields[1])))
    return done


def _write_atomically(path: str, data: bytes) -> None:
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _append_durably(path: str, data: bytes) -> None:
    """One append, fsynced; a failed one is cut back (as AppendFileDurably, file_io.h)."""
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_CLOEXEC, 0o666)
    size = os.fstat(fd).st_size
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        os.fsync(fd)
    except OSError:
        try:
            os.ftruncate(fd, size)
        except OSError:
            pass
        raise
    finally:
        os.close(fd)


def _where(images: Sequence[tuple[int, int]]) -> str:
    return ", ".join(f"scene {s} image {i}" for s, i in images)


def run_dataset(client: Any, dataset: str | os.PathLike, out: str | os.PathLike, *, split: str = "test",
                prior: Any, options: Mapping[str, Any] | None = None, targets: Any = None,
                cli: str | os.PathLike | None = None, chunk: int = 1, retries: int = 1, no_time: bool = False,
                progress: Callable[[int, int, tuple[int, int]], Any] | None = None) -> RunSummary:
    """Estimates every target of `dataset` on the workers of the Dask `client` and appends the
    rows to the BOP results CSV `out` (as `posefilter run-dataset --out`; images already in it
    are skipped). Returns a RunSummary.

    - prior: 'uniform', 'auto', ('gt-boxes', SIGMA_PX) or ('detections', PATH): run-dataset's
      --uniform-prior, --auto-prior, --gt-boxes, --detections.
    - options: filter options as {name: value} ('polish_steps' or 'polish-steps'): a value
      becomes `--name value`, True a bare `--name`, False `--no-name` (where the CLI has one),
      a list a comma-separated value; None is left out. Names are checked against the workers'
      `posefilter run-dataset --help`. Set 'threads' (the CLI's default, 0, is every core of the
      worker's machine, for each task the worker runs at once).
    - targets: a test_targets_bop19-style JSON file or list (default: list_targets's rule).
    - cli: the CLI's path on the workers (default: the worker's $POSEFILTER_CLI, else the CLI
      built with this module where it exists on the worker (built_cli()), else `posefilter` on
      the worker's PATH).
    - chunk: images per task (fewer CLI starts and mesh loads; a lost task reruns them all).
    - retries: reruns of a failed task before run_dataset gives up (a task of a worker that dies
      is rerun by Dask without counting).
    - no_time: write time -1 (run-dataset --no-time): runs of the same options write identical rows.
    - progress: called as progress(done, total, (scene_id, im_id)) after each image's rows are
      appended.

    The dataset, and the detections file, must be at the same path on the client and the
    workers (a shared file system); relative paths are made absolute on the client. A failed
    task raises RunDatasetError naming its image(s) with the CLI's stderr, after the remaining
    tasks are cancelled; the rows already appended stay, and a rerun resumes."""
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1:
        raise ValueError(f"chunk must be an integer >= 1, got {chunk!r}")
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise ValueError(f"retries must be an integer >= 0, got {retries!r}")
    root = os.path.abspath(os.fspath(dataset))
    out = os.path.abspath(os.fspath(out))
    if cli is not None:
        cli = os.fspath(cli)
        if os.sep in cli:
            cli = os.path.abspath(cli)
    prior_flags = _prior_flags(prior)
    _option_flags(options, None)  # reserved names, before any work
    out_dir = os.path.dirname(out)
    if os.path.isdir(out):
        raise IsADirectoryError(f"{out}: is a directory, not a results CSV")
    if os.path.islink(out) or (os.path.exists(out) and not stat.S_ISREG(os.stat(out).st_mode)):
        raise ValueError(f"{out}: not a regular file (a symlink, FIFO or device is never written); give a file path")
    if not os.path.isdir(out_dir):
        raise FileNotFoundError(f"{out}: the directory {out_dir} does not exist")

    if isinstance(targets, (str, os.PathLike)):
        targets = os.path.abspath(os.fspath(targets))
    all_targets = list_targets(root, split, targets)
    if not all_targets:
        raise ValueError(f"{root}: no targets (no test_targets_bop19.json and no ground truth)")
    by_image: dict[tuple[int, int], list[dict]] = {}
    for t in all_targets:
        by_image.setdefault((t["scene_id"], t["im_id"]), []).append(t)

    # Resume: a torn last row is dropped with its image, images in the CSV are skipped. The
    # lock is taken before the repair, so two clients never repair or append at once.
    lock_fd = _lock(out) if os.path.exists(out) else None
    try:
        return _run_locked(client, root, out, split, by_image, targets, prior_flags, options, cli, chunk, retries,
                           no_time, progress, lock_fd)
    finally:
        if lock_fd is not None:
            os.close(lock_fd)


def _run_locked(client, root, out, split, by_image, targets, prior_flags, options, cli, chunk, retries, no_time,
                progress, lock_fd):
    """run_dataset after its argument checks; `lock_fd` holds the lock on an existing `out`."""
    from distributed import as_completed

    done_before = _repair_and_read(out)
    todo = [key for key in sorted(by_image) if key not in done_before]
    skipped = len(by_image) - len(todo)
    summary = RunSummary(out=out, images=len(by_image), done=0, skipped=skipped, rows=0)
    lock = [lock_fd]

    def start_file():
        # The header goes in with the first rows (or at the end of a run without rows), so an
        # error before then leaves no new file; a new file is locked as soon as it exists.
        if not os.path.exists(out) or os.path.getsize(out) == 0:
            _append_durably(out, (BOP_CSV_HEADER + "\n").encode("utf-8"))
        if lock[0] is None:
            lock[0] = _lock(out)

    if not todo:
        return summary

    _register_by_value()
    built = built_cli()
    # One worker checks the CLI and lists its options (each task resolves `cli` on its own worker).
    _, known = client.submit(_probe_cli, cli, built, pure=False).result()
    flags = prior_flags + _option_flags(options, known) + (["--no-time"] if no_time else [])

    run_id = uuid.uuid4().hex[:12]
    futures = {}
    for k in range(0, len(todo), chunk):
        images = todo[k:k + chunk]
        # The images by id; a targets list travels with them (its entries of these images).
        given = targets if targets is None or isinstance(targets, str) else \
            [t for key in images for t in by_image[key]]
        where = _where(images)
        key = f"posefilter-run-dataset-{run_id}-{images[0][0]}_{images[0][1]}" + \
            (f"+{len(images) - 1}" if len(images) > 1 else "")
        fut = client.submit(_run_images, cli, built, root, split, flags, images, given, where, key=key, pure=False,
                            retries=retries)
        futures[fut] = images
    appended: set[tuple[int, int]] = set()
    pending = set(futures)
    try:
        for fut in as_completed(list(futures)):
            pending.discard(fut)
            images = futures[fut]
            try:
                result = fut.result()
            except Exception as e:
                raise RunDatasetError(f"{out}: {_where(images)} failed: {e}") from e
            finally:
                fut.release()
            rows_of: dict[tuple[int, int], list[str]] = {key: [] for key in images}
            for line in result["rows"].splitlines():
                if not line.strip():
                    continue
                fields = line.split(",", 2)
                key = (int(fields[0]), int(fields[1])) if len(fields) == 3 and fields[0].isdigit() \
                    and fields[1].isdigit() else None
                if key not in rows_of:
                    raise RunDatasetError(f"{out}: the task of {_where(images)} returned a row of another image: "
                                          f"{line[:80]!r}")
                rows_of[key].append(line)
            summary.warnings += [w for w in result["stderr"].splitlines() if w.strip()]
            for key in images:
                if key in appended:
                    continue
                appended.add(key)
                if rows_of[key]:
                    start_file()
                    _append_durably(out, "".join(r + "\n" for r in rows_of[key]).encode("utf-8"))
                summary.rows += len(rows_of[key])
                summary.done += 1
                if progress is not None:
                    progress(summary.done, len(todo), key)
    finally:
        if pending:
            client.cancel(list(pending))
        if lock[0] is not None and lock[0] != lock_fd:
            os.close(lock[0])
    if not os.path.exists(out):  # every image ran and none gave a row: a resumable, empty results CSV
        _append_durably(out, (BOP_CSV_HEADER + "\n").encode("utf-8"))
    return summary
