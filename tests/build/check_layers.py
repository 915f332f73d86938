#!/usr/bin/env python3
"""Checks that every #include of the library follows its layers (ctest: build_layers).

The library is built as one static library per layer (docs/ARCHITECTURE.md, "Layers"; CMake's
posefilter_add_layer, cmake/posefilter_layers.cmake), each linked only to the layers it uses.
The configure step writes the layer graph to <build>/posefilter_layers.json: per layer its
folders under the project root, its public headers (include/posefilter/*.h) and the layers it
depends on. This check reads that graph and every C++ file of src/ and include/ and fails when:
  1. a file includes a file of a layer its own layer does not depend on, directly or through
     other layers (an upward or sideways include);
  2. a file of src/ lies in no layer's folder, or a public header is in no layer's HEADERS
     (say where a new file belongs: src/<layer>/CMakeLists.txt);
  3. the graph itself is wrong: a dependency that is not a layer, or a cycle.
An include resolves as the compiler finds it: next to the including file, then under src/,
include/ and src/hw/hls_types (the library's include folders); an include found in none of
them (a generated or third-party header) is not checked.

It prints each violation as FILE:LINE and exits 1; otherwise it prints what it checked.

    /usr/bin/python3 tests/build/check_layers.py --layers BUILD/posefilter_layers.json [--root DIR]

Standard library only.
"""

import argparse
import json
import os
import re
import sys

CXX_EXTS = (".cc", ".cpp", ".h", ".hpp", ".inc")
# The library's include folders (CMake: posefilter_add_layer's include directories), searched
# after the including file's own folder.
SEARCH_DIRS = ("src", "include", "src/hw/hls_types")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*(?:"([^"]+)"|<(posefilter/[^>]+)>)')


def load_layers(path):
    """The layers of the JSON file: {name: {"dirs": [...], "headers": [...], "depends": [...]}}, in order."""
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    layers = {}
    for entry in data["layers"]:
        layers[entry["name"]] = {
            "dirs": [d.rstrip("/") for d in entry.get("dirs", [])],
            "headers": list(entry.get("headers", [])),
            "depends": list(entry.get("depends", [])),
        }
    return layers


def graph_errors(layers):
    """Dependencies that are not layers, and cycles."""
    errors = []
    for name, layer in layers.items():
        for dep in layer["depends"]:
            if dep not in layers:
                errors.append("layer %s depends on %s, which is not a layer" % (name, dep))
    state = {}

    def visit(name, path):
        if state.get(name) == "done":
            return
        if state.get(name) == "open":
            cycle = path[path.index(name):] + [name]
            errors.append("the layers form a cycle: %s" % " -> ".join(cycle))
            return
        state[name] = "open"
        for dep in layers[name]["depends"]:
            if dep in layers:
                visit(dep, path + [name])
        state[name] = "done"

    for name in layers:
        visit(name, [])
    return errors


def allowed_layers(layers):
    """{layer: the set of layers it may include from: itself and everything below it}."""
    allowed = {}

    def below(name, seen):
        for dep in layers[name]["depends"]:
            if dep in layers and dep not in seen:
                seen.add(dep)
                below(dep, seen)
        return seen

    for name in layers:
        allowed[name] = below(name, {name})
    return allowed


class LayerMap:
    """Which layer a file (a path relative to the root, with '/') belongs to."""

    def __init__(self, layers):
        self.headers = {}
        self.dirs = []
        for name, layer in layers.items():
            for h in layer["headers"]:
                self.headers[h] = name
            for d in layer["dirs"]:
                self.dirs.append((d, name))
        self.dirs.sort(key=lambda item: len(item[0]), reverse=True)  # the longest folder first

    def layer_of(self, rel):
        if rel in self.headers:
            return self.headers[rel]
        for d, name in self.dirs:
            if rel.startswith(d + "/"):
                return name
        return None


def source_files(root):
    for top in ("src", "include"):
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames.sort()
            for fn in sorted(filenames):
                if fn.endswith(CXX_EXTS):
                    yield os.path.relpath(os.path.join(dirpath, fn), root).replace(os.sep, "/")


def resolve(root, including, name):
    """The included file, relative to the root, or None when it is not one of the library's."""
    for base in (os.path.dirname(including),) + SEARCH_DIRS:
        candidate = os.path.normpath(os.path.join(base, name)).replace(os.sep, "/")
        if os.path.isfile(os.path.join(root, candidate)):
            return candidate
    return None


def check(root, layers):
    """(violations, number of files, number of includes checked)."""
    errors = graph_errors(layers)
    if errors:
        return errors, 0, 0
    allowed = allowed_layers(layers)
    where = LayerMap(layers)
    files = 0
    checked = 0
    for rel in source_files(root):
        files += 1
        own = where.layer_of(rel)
        if own is None:
            if rel.startswith("include/"):
                errors.append("%s: a public header in no layer: list it in HEADERS of its layer's "
                              "src/<layer>/CMakeLists.txt" % rel)
            else:
                errors.append("%s: in no layer's folder: put it under a layer's folder or add the folder to "
                              "DIRS of a layer (src/<layer>/CMakeLists.txt)" % rel)
            continue
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
            for lineno, line in enumerate(f, 1):
                m = INCLUDE_RE.match(line)
                if not m:
                    continue
                name = m.group(1) or m.group(2)
                target = resolve(root, rel, name)
                if target is None:
                    continue
                theirs = where.layer_of(target)
                if theirs is None:
                    continue  # reported as a file of its own
                checked += 1
                if theirs not in allowed[own]:
                    below = sorted(allowed[own] - {own})
                    errors.append("%s:%d: layer %s includes %s of layer %s; %s uses only %s "
                                  "(docs/ARCHITECTURE.md, \"Layers\": move the code to the layer it belongs to)" %
                                  (rel, lineno, own, name, theirs, own, ", ".join(below) if below else "no other layer"))
    return errors, files, checked


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--layers", required=True, help="the configured build's posefilter_layers.json")
    parser.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."),
                        help="the project root (default: this script's repository)")
    args = parser.parse_args(argv)
    root = os.path.abspath(args.root)
    try:
        layers = load_layers(args.layers)
    except (OSError, ValueError, KeyError) as e:
        print("check_layers: cannot read the layer graph %s: %s" % (args.layers, e), file=sys.stderr)
        return 2
    errors, files, checked = check(root, layers)
    if errors:
        for e in errors:
            print(e, file=sys.stderr)
        print("check_layers: %d violation(s) of the layers in %s" % (len(errors), root), file=sys.stderr)
        return 1
    print("check_layers: %d files, %d includes within the layers (%s)" %
          (files, checked, ", ".join(layers)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
