"""Estimator keywords stay in step with FilterOptions (include/posefilter/filter_options.h), the option table
(include/posefilter/option_table.h) and the type stub."""

import os
import re
from pathlib import Path

import pytest

import posefilter as pf

SOURCE = Path(os.environ.get("POSEFILTER_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def struct_fields(text, name):
    """Data members of `struct name { ... };` (one or more declarators per declaration)."""
    body = re.search(r"struct %s \{(.*?)\n\};" % name, text, re.S)
    assert body, name
    code = re.sub(r"//[^\n]*", "", body.group(1))
    code = re.sub(r"\{[^{}]*\}", "{}", code)  # brace initialisers
    fields = []
    for decl in code.split(";"):
        decl = " ".join(decl.split())
        m = re.match(r"^(?:const )?[\w:]+(?:<[^<>]*>)?\s*\*?\s+(.*)$", decl)
        if not m or "(" in decl.split("=")[0]:
            continue  # not a data member (a method, an empty piece)
        for part in m.group(1).split(","):
            name_m = re.match(r"^\s*([A-Za-z_]\w*)\s*(=|\{|$)", part)
            if name_m:
                fields.append(name_m.group(1))
    return fields


def filter_option_fields(text):
    """Every leaf field path of FilterOptions ("anneal.subsample", "score.inlier.thr1_m")."""
    def walk(struct, prefix):
        body = re.search(r"struct %s \{(.*?)\n\};" % struct, text, re.S).group(1)
        member_types = {m: t for t, m in re.findall(r"^\s+(\w+(?:Options|Params))\s+(\w+)\s*;", body, re.M)}
        out = []
        for f in struct_fields(text, struct):
            if f in member_types:
                out += walk(member_types[f], prefix + f + ".")
            else:
                out.append(prefix + f)
        return out

    return walk("FilterOptions", "")


def test_every_filter_option_is_a_keyword():
    inc = SOURCE / "include/posefilter"
    if not (inc / "filter_options.h").exists():
        pytest.skip("source tree not found")
    text = "".join((inc / h).read_text() for h in ("filter_options.h", "render.h", "heuristics.h"))
    fields = filter_option_fields(text)
    assert "anneal.subsample" in fields and "score.inlier.thr1_m" in fields and "heuristics.max_samples" in fields
    table = pf.Estimator.option_table()
    assert sorted(fields) == sorted(row["field"] for row in table)
    assert [row["keyword"] for row in table] == pf.Estimator.option_names()
    for row in table:
        assert row["keyword"] == row["cli"][2:].replace("-", "_")
        assert row["default"] == pf.Estimator.defaults()[row["keyword"]]
        assert row["keyword"] in pf.Estimator.__doc__


STUB_BEGIN = "    # BEGIN options: generated from Estimator.option_table() (python/tests/test_options.py --write-stub)\n"
STUB_END = "    # END options\n"


def estimator_init_stub():
    """The Estimator.__init__ block of __init__.pyi, from the option table."""
    lines = [STUB_BEGIN, "    def __init__(\n", "        self,\n", "        *,\n"]
    for row in pf.Estimator.option_table():
        note = ", ".join(x for x in (repr(row["default"]) if row["type"] != "Sequence[float]" else "", row["range"]) if x)
        lines.append(f"        {row['keyword']}: {row['type']} = ...,{'  # ' + note if note else ''}\n")
    lines += ["    ) -> None: ...\n", STUB_END]
    return "".join(lines)


def _stub_path():
    return Path(__file__).resolve().parents[1] / "posefilter" / "__init__.pyi"


def test_stub_estimator_signature_is_the_option_table():
    text = _stub_path().read_text()
    assert STUB_BEGIN in text and STUB_END in text
    block = text[text.index(STUB_BEGIN):text.index(STUB_END) + len(STUB_END)]
    assert block == estimator_init_stub(), "run: python3 python/tests/test_options.py --write-stub"


def test_every_synth_option_is_a_keyword():
    header = SOURCE / "include/posefilter/synth.h"
    if not header.exists():
        pytest.skip("source tree not found")
    assert sorted(struct_fields(header.read_text(), "SynthOptions")) == sorted(pf.synth_option_names())


def _stub():
    import ast

    path = Path(pf.__file__).with_name("__init__.pyi")
    if not path.exists():
        pytest.skip("no type stub next to the package")
    return ast.parse(path.read_text())


def test_type_stub_covers_the_module():
    import ast

    tree = _stub()
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    public = {n for n in dir(pf._posefilter) if not n.startswith("_")}
    assert public <= stubbed, public - stubbed
    assert set(pf.__all__) - {"plots"} <= stubbed | {"__version__"}

    def kwonly(fn):
        return [a.arg for a in fn.args.kwonlyargs]

    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    init = next(f for f in classes["Estimator"].body if isinstance(f, ast.FunctionDef) and f.name == "__init__")
    assert kwonly(init) == pf.Estimator.option_names()
    synth = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "make_synth_scene")
    assert sorted(kwonly(synth)) == sorted(pf.synth_option_names())
    # Tracker: init, then the tracker's own keywords (TrackOptionTable) with their types.
    init = next(f for f in classes["Tracker"].body if isinstance(f, ast.FunctionDef) and f.name == "__init__")
    assert kwonly(init) == ["init"] + pf.Tracker.option_names()
    defaults = pf.Tracker.defaults()
    for a in init.args.kwonlyargs[1:]:
        assert ast.unparse(a.annotation) == type(defaults[a.arg]).__name__, a.arg


if __name__ == "__main__":
    import sys

    if sys.argv[1:] != ["--write-stub"]:
        sys.exit("usage: test_options.py --write-stub   (rewrites Estimator.__init__ in posefilter/__init__.pyi)")
    path = _stub_path()
    text = path.read_text()
    start, end = text.index(STUB_BEGIN), text.index(STUB_END) + len(STUB_END)
    path.write_text(text[:start] + estimator_init_stub() + text[end:])


def test_version_is_the_clis():
    import subprocess

    assert pf.__version__.count(".") == 2
    cli = os.environ.get("POSEFILTER_CLI_PATH")
    if not cli:
        pytest.skip("POSEFILTER_CLI_PATH is not set (ctest sets it)")
    out = subprocess.run([cli, "--version"], capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[0] == f"posefilter {pf.__version__} (git {pf.__git_revision__})"
