"""`pip install .` works offline on Debian: a venv made with --system-site-packages (Debian's
numpy), `pip install --no-build-isolation --no-index .`, and the module imports from the venv,
not from the build tree. setup.py reuses the build folder these tests run from (only the
module target is built, already up to date), so the test takes seconds."""

import os
import pathlib
import subprocess
import sys
import venv

import pytest

import posefilter as pf

ROOT = pathlib.Path(__file__).resolve().parents[2]


def build_dir():
    """The CMake build folder the imported module comes from (<build>/python/posefilter)."""
    build = pathlib.Path(pf.__file__).resolve().parents[2]
    assert (build / "CMakeCache.txt").exists(), "posefilter imported from outside a CMake build: %s" % pf.__file__
    return build


def test_pip_install_into_a_venv(tmp_path):
    pytest.importorskip("pip")
    env_dir = tmp_path / "venv"
    venv.create(env_dir, system_site_packages=True, with_pip=False)
    py = env_dir / "bin" / "python"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["POSEFILTER_CMAKE_BUILD_DIR"] = str(build_dir())
    env["PIP_NO_CACHE_DIR"] = "1"
    # The system pip (python3-pip), running as the venv's interpreter, installs into the venv.
    r = subprocess.run([str(py), "-m", "pip", "install", "--no-build-isolation", "--no-index", "--no-deps",
                        "--quiet", str(ROOT)], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    r = subprocess.run([str(py), "-c", "import posefilter, numpy; print(posefilter.__file__); "
                        "print(len(posefilter.Estimator.option_table()))"],
                       cwd=tmp_path, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    where, rows = r.stdout.split()
    assert pathlib.Path(where).resolve().is_relative_to(env_dir.resolve()), where
    assert int(rows) > 50
