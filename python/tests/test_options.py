"""Estimator keywords stay in step with FilterOptions (include/posefilter/filter.h)."""

import os
import re
from pathlib import Path

import pytest

import posefilter as pf

SOURCE = Path(os.environ.get("POSEFILTER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
NESTED = {"inlier": "InlierParams", "heuristics": "HeuristicOptions"}


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


def test_every_filter_option_is_a_keyword():
    header = SOURCE / "include/posefilter/filter.h"
    if not header.exists():
        pytest.skip("source tree not found")
    text = header.read_text() + (SOURCE / "include/posefilter/render.h").read_text() + (
        SOURCE / "include/posefilter/heuristics.h").read_text()
    expected = []
    for f in struct_fields(text, "FilterOptions"):
        if f in NESTED:
            expected += [f"{f}_{g}" for g in struct_fields(text, NESTED[f])]
        else:
            expected.append(f)
    assert "num_particles" in expected and "inlier_thr1_m" in expected
    assert sorted(expected) == sorted(pf.Estimator.option_names())


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
