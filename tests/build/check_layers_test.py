#!/usr/bin/env python3
"""Tests of the layer check, tests/build/check_layers.py (ctest: build_layers_control).

Each test copies src/ and include/ of the tree into a temporary folder, changes the copy and
runs the check on it with the configured build's layer graph: the unchanged copy passes, and a
deliberate upward include (the negative control), a file outside every layer and a cycle in the
graph each make it fail, naming the file and line.

    /usr/bin/python3 tests/build/check_layers_test.py --layers BUILD/posefilter_layers.json [--root DIR]

Standard library only.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKER = os.path.join(HERE, "check_layers.py")
ARGS = None  # the command line's --layers and --root


class CheckLayersTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="check_layers_")
        for top in ("src", "include"):
            shutil.copytree(os.path.join(ARGS.root, top), os.path.join(self.tmp, top),
                            ignore=shutil.ignore_patterns("*.sv", "*.json", "*.md", "*.js", "*.comp", "*.glsl"))
        self.layers = os.path.join(self.tmp, "posefilter_layers.json")
        shutil.copyfile(ARGS.layers, self.layers)

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def run_check(self):
        p = subprocess.run([sys.executable, CHECKER, "--layers", self.layers, "--root", self.tmp],
                           capture_output=True, text=True, check=False)
        return p.returncode, p.stdout + p.stderr

    def add_line(self, rel, line):
        """Inserts `line` before the first #include of `rel` (in the copy); returns its line number."""
        path = os.path.join(self.tmp, rel)
        with open(path, encoding="utf-8") as f:
            lines = f.readlines()
        at = next(i for i, l in enumerate(lines) if l.startswith("#include"))
        lines.insert(at, line + "\n")
        with open(path, "w", encoding="utf-8") as f:
            f.writelines(lines)
        return at + 1

    def test_the_tree_as_it_is_passes(self):
        rc, out = self.run_check()
        self.assertEqual(rc, 0, out)
        self.assertIn("check_layers:", out)

    def test_an_upward_public_include_fails_naming_the_file_and_line(self):
        # The negative control: core may use no other layer, so a core source that includes the
        # filter's public header breaks the layers.
        line = self.add_line("src/core/pose.cc", '#include "posefilter/filter.h"')
        rc, out = self.run_check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/core/pose.cc:%d: layer core includes posefilter/filter.h of layer filter" % line, out)

    def test_an_upward_internal_include_fails(self):
        line = self.add_line("src/render/overlay.cc", '#include "filter/driver.h"')
        rc, out = self.run_check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/render/overlay.cc:%d: layer render includes filter/driver.h of layer filter" % line, out)

    def test_a_public_header_including_a_higher_layer_fails(self):
        line = self.add_line("include/posefilter/mesh.h", '#include "posefilter/tracker.h"')
        rc, out = self.run_check()
        self.assertEqual(rc, 1, out)
        self.assertIn("include/posefilter/mesh.h:%d: layer core includes posefilter/tracker.h" % line, out)

    def test_a_sideways_include_fails(self):
        # eval and synth are beside each other: neither uses the other.
        self.add_line("src/synth/shapes.cc", '#include "posefilter/metrics.h"')
        rc, out = self.run_check()
        self.assertEqual(rc, 1, out)
        self.assertIn("layer synth includes posefilter/metrics.h of layer eval", out)

    def test_a_downward_include_passes(self):
        self.add_line("src/view/view_html.cc", '#include "posefilter/mesh.h"')
        self.add_line("src/filter/polish.cc", '#include "render/cpu_kernel.h"')
        rc, out = self.run_check()
        self.assertEqual(rc, 0, out)

    def test_files_outside_every_layer_fail(self):
        os.makedirs(os.path.join(self.tmp, "src", "newlayer"))
        with open(os.path.join(self.tmp, "src", "newlayer", "thing.cc"), "w", encoding="utf-8") as f:
            f.write('#include "posefilter/pose.h"\n')
        with open(os.path.join(self.tmp, "include", "posefilter", "thing.h"), "w", encoding="utf-8") as f:
            f.write("#pragma once\n")
        rc, out = self.run_check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/newlayer/thing.cc: in no layer's folder", out)
        self.assertIn("include/posefilter/thing.h: a public header in no layer", out)

    def test_a_cycle_in_the_graph_fails(self):
        with open(self.layers, encoding="utf-8") as f:
            graph = json.load(f)
        core = next(layer for layer in graph["layers"] if layer["name"] == "core")
        core["depends"] = core.get("depends", []) + ["filter"]
        with open(self.layers, "w", encoding="utf-8") as f:
            json.dump(graph, f)
        rc, out = self.run_check()
        self.assertEqual(rc, 1, out)
        self.assertIn("the layers form a cycle: core -> filter", out)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--layers", required=True)
    parser.add_argument("--root", default=os.path.join(HERE, "..", ".."))
    ARGS, rest = parser.parse_known_args()
    ARGS.root = os.path.abspath(ARGS.root)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
