#!/usr/bin/env bash
# clang-tidy (the checks of .clang-tidy) on the C++ sources changed relative to a base commit:
# every .cc added or modified since BASE (default HEAD~1, i.e. the last commit), working-tree
# changes included, that the build compiles (its compile_commands.json; default the release
# preset's, build/release). Fails when clang-tidy reports a warning in one of them or in a
# header of src/, include/ or apps/ they include. scripts/test.sh runs it after the release build;
# that build compiles the CLI and the test binaries as unity batches (POSEFILTER_UNITY=ON), so
# there it checks the library's, the benchmarks' and the Python module's sources.
#
# usage: scripts/tidy.sh [BASE]
#   POSEFILTER_TIDY_BUILD=DIR  the build folder whose compile_commands.json is used
#   POSEFILTER_TIDY_JOBS=N     files checked at once (default: the number of cores)
set -euo pipefail
cd "$(dirname "$0")/.."

base=${1:-HEAD~1}
build=${POSEFILTER_TIDY_BUILD:-build/release}
db="$build/compile_commands.json"
tidy=$(command -v clang-tidy || true)
if [ -z "$tidy" ]; then
  echo "tidy: clang-tidy not found (scripts/setup.sh installs it)" >&2
  exit 1
fi
if [ ! -f "$db" ]; then
  echo "tidy: $db not found: configure the build first (cmake --preset release)" >&2
  exit 1
fi
if ! git rev-parse --verify --quiet "$base^{commit}" >/dev/null; then
  # A clone without history (git clone --depth 1) has no parent to compare with.
  echo "tidy: base '$base' is not a commit of this clone; nothing to compare with, no file checked"
  exit 0
fi

# The compile commands for clang: the build's, with each precompiled header of a GCC build
# (-include .../cmake_pch.hxx, beside GCC's .gch, which clang cannot read) replaced by a copy of
# its text, in a folder of their own. Prints the changed .cc files that the build compiles
# (headers are checked through them).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mapfile -t files < <(git diff --name-only --diff-filter=ACMR "$base" -- '*.cc' |
  /usr/bin/python3 -c '
import hashlib, json, os, re, shutil, sys
db_path, work = sys.argv[1], sys.argv[2]
entries = json.load(open(db_path))
def text_copy(pch):
    copy = os.path.join(work, hashlib.sha1(pch.encode()).hexdigest()[:12] + "_pch.hxx")
    if not os.path.exists(copy):
        shutil.copyfile(pch, copy)
    return copy
for e in entries:
    if "command" in e:
        e["command"] = re.sub(r"-include (\S+/cmake_pch\.hxx)", lambda m: "-include " + text_copy(m.group(1)),
                              e["command"])
    else:
        args = e["arguments"]
        for i in range(1, len(args)):
            if args[i - 1] == "-include" and args[i].endswith("/cmake_pch.hxx"):
                args[i] = text_copy(args[i])
json.dump(entries, open(os.path.join(work, "compile_commands.json"), "w"))
compiled = {os.path.realpath(e["file"]) for e in entries}
for line in sys.stdin:
    path = line.strip()
    if path and os.path.realpath(path) in compiled:
        print(path)
' "$db" "$work")
if [ ${#files[@]} -eq 0 ]; then
  echo "tidy: no compiled C++ source changed since $base"
  exit 0
fi
echo "tidy: clang-tidy on ${#files[@]} file(s) changed since $base (${build})"
jobs=${POSEFILTER_TIDY_JOBS:-$(nproc)}
# One clang-tidy per file, $jobs at a time; --quiet leaves only the findings.
log="$work/tidy.log"
status=0
printf '%s\0' "${files[@]}" |
  xargs -0 -n 1 -P "$jobs" "$tidy" -p "$work" --quiet \
    --extra-arg=-Wno-unknown-warning-option --extra-arg=-Wno-unused-command-line-argument >"$log" 2>&1 ||
  status=$?
# clang-tidy prints "N warnings generated." for warnings it suppressed (system headers).
grep -v -E '^[0-9]+ warnings? generated\.$|^Suppressed [0-9]+ warnings|^Use -header-filter' "$log" || true
if [ "$status" -ne 0 ] || grep -q -E ': (warning|error): ' "$log"; then
  echo "tidy: clang-tidy found problems in the files above (.clang-tidy lists the checks)" >&2
  exit 1
fi
echo "tidy: clean"
