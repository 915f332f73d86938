"""scripts/suite_compare.py: two suite JSONs compared row by row, times aside (RELIABILITY.md §6)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "suite_compare.py"


def run_compare(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=60)


@pytest.fixture(scope="module")
def suite_json(tmp_path_factory):
    """A real `posefilter suite --json` of two small shapes scenes (a short budget): rows in `scenes`."""
    cli = os.environ.get("POSEFILTER_CLI_PATH")
    assert cli, "POSEFILTER_CLI_PATH (set by ctest) names the posefilter binary"
    out = tmp_path_factory.mktemp("suite") / "a.json"
    subprocess.run([cli, "suite", "--count", "2", "--restarts", "1", "--iterations", "3", "--polish-steps", "0",
                    "--threads", "2", "--json", str(out)], check=True, capture_output=True, timeout=300)
    data = json.loads(out.read_text())
    assert len(data["scenes"]) == 2 and "time_ms" in data["scenes"][0]
    return data


def write(path, data):
    path.write_text(json.dumps(data))
    return path


def test_same_rows_with_other_times_are_identical(suite_json, tmp_path):
    other = json.loads(json.dumps(suite_json))
    for row in other["scenes"]:
        row["time_ms"] += 17.0
    other["median_time_ms"] = other.get("median_time_ms", 0) + 3.0
    r = run_compare(write(tmp_path / "a.json", suite_json), write(tmp_path / "b.json", other))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "2 rows; IDENTICAL (times aside)" in r.stdout


def test_a_changed_weight_is_a_difference_naming_the_row_and_key(suite_json, tmp_path):
    other = json.loads(json.dumps(suite_json))
    other["scenes"][1]["weight"] += 1e-12  # exact comparison: the last bits count
    r = run_compare(write(tmp_path / "a.json", suite_json), write(tmp_path / "b.json", other))
    assert r.returncode == 1, r.stdout + r.stderr
    assert "1 differ" in r.stdout
    assert "row 1" in r.stdout and f"seed {other['scenes'][1]['seed']}" in r.stdout and "weight" in r.stdout


def test_a_shorter_run_is_compared_on_its_rows(suite_json, tmp_path):
    first = json.loads(json.dumps(suite_json))
    first["scenes"] = first["scenes"][:1]
    first["recall_adds"] = -1  # a summary of other rows: not compared
    r = run_compare(write(tmp_path / "a.json", first), write(tmp_path / "b.json", suite_json))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "comparing the first 1" in r.stdout and "1 rows; IDENTICAL" in r.stdout


def test_bad_input_names_the_file(tmp_path):
    good = write(tmp_path / "good.json", {"objects": []})
    missing = tmp_path / "missing.json"
    r = run_compare(missing, good)
    assert r.returncode == 2 and str(missing) in r.stderr and "cannot read" in r.stderr
    broken = tmp_path / "broken.json"
    broken.write_text("{not json")
    r = run_compare(good, broken)
    assert r.returncode == 2 and str(broken) in r.stderr and "not JSON" in r.stderr
    other = write(tmp_path / "other.json", {"rows": []})
    r = run_compare(good, other)
    assert r.returncode == 2 and str(other) in r.stderr and "objects" in r.stderr
    rooms = write(tmp_path / "rooms.json", {"objects": [{"seed": 1, "obj": "025_mug", "weight": 0.5}]})
    r = run_compare(rooms, good)  # one row against none: nothing to compare is not identity
    assert r.returncode == 1 and "nothing compared" in r.stdout
    shapes = write(tmp_path / "shapes.json", {"scenes": [{"seed": 1, "target": "box", "weight": 0.5}]})
    r = run_compare(rooms, shapes)
    assert r.returncode == 1 and "objects in one file and scenes in the other" in r.stdout
    r = run_compare(good, good, "--max-rows", "-1")
    assert r.returncode == 2 and "--max-rows" in r.stderr
