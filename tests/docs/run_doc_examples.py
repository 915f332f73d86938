#!/usr/bin/env python3
"""Runs every shell and Python example of README.md and docs/*.md (ctest: doc_examples).

Blocks: fenced blocks (```sh, ```bash, ```shell, ```console, ```python, ```py) and indented
(4-space) code blocks, which this project's docs use for shell commands. A ```console block's
commands are its `$ ` lines (with `\\` continuation lines); its other lines are shown output.
Blocks marked ```text, ```json, ```csv (formats, usage synopses, output) are not code and are
not run. Any other block (unlabelled ```, ```cpp, ...) must carry a marker saying what it is.

Markers: HTML comments (invisible when rendered) on the lines right before a block, one
directive each; blank lines may separate them from the block, nothing else may:

    <!-- doc-test: skip REASON -->       not run; the reason is required (a build, apt-get, ...)
    <!-- doc-test: text -->              not code (a diagram, a format); not run
    <!-- doc-test: env NAME=VALUE ... -->    extra environment variables for the block
    <!-- doc-test: sub OLD NEW -->       run the block with every OLD replaced by NEW (smaller
                                         settings, a scratch path); shell-quoted; OLD must occur
    <!-- doc-test: expect REGEX -->      the block's stdout+stderr must match REGEX (Python re,
                                         MULTILINE, search); several may be given
    <!-- doc-test: setup COMMANDS -->    bash run before the block (may span lines), e.g. to
                                         make the input files an example names
    <!-- doc-test: needs PATH ... -->    skip the block when PATH (relative to its folder, with
                                         $POSEFILTER_DATA expanded, e.g. $POSEFILTER_DATA/ycbv)
                                         does not exist
    <!-- doc-test: continue -->          put the code, env and needs of the file's previous block
                                         of the same kind (shell, Python; it must run too) in
                                         front: examples that use an earlier one's variables
    <!-- doc-test: timeout SECONDS -->   per-block limit (default 300)

Where blocks run: the blocks of one markdown file run in order in one fresh temporary folder
T/repo (so a block may use the files an earlier one wrote), which looks like the repository
root: a symlink to every top-level entry of $POSEFILTER_SOURCE_DIR except build/ and .git,
build/release/posefilter -> $POSEFILTER_CLI_PATH, build/release/python -> the PYTHONPATH entry
that holds the posefilter package, T/shared -> the shared folder ($POSEFILTER_SHARED_DIR,
default $POSEFILTER_SOURCE_DIR/../shared), and T/data -> the real data folder with POSEFILTER_DATA
set to it (the caller's $POSEFILTER_DATA, else T/shared/data: README "Data"), so `scripts/...`,
`build/release/...`, `../shared/...` and `$POSEFILTER_DATA/ycbv` resolve as in a checkout while
everything written stays in T (write under build/ or a new path: the linked folders are the
source tree's).
`posefilter` and `python3` (this interpreter) are first on PATH. Shell blocks run with
`bash -e`, Python blocks with this interpreter; PYTHONDONTWRITEBYTECODE=1, MPLBACKEND=Agg and
PYTEST_ADDOPTS=-p no:cacheprovider keep the source tree clean.

Environment: POSEFILTER_CLI_PATH (the posefilter binary, required), POSEFILTER_SOURCE_DIR
(default: this file's ../..), PYTHONPATH (the built module). Exit status 1 when a block fails,
a block is neither runnable nor marked, or a marker is malformed.

    POSEFILTER_CLI_PATH=build/release/posefilter PYTHONPATH=build/release/python \\
        /usr/bin/python3 tests/docs/run_doc_examples.py [--list] [--keep] [-v] [FILE.md ...]
"""

import argparse
import glob
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SHELL_LANGS = {"sh", "bash", "shell"}
CONSOLE_LANGS = {"console"}
PYTHON_LANGS = {"python", "py", "python3"}
DISPLAY_LANGS = {"text", "txt", "plain", "output", "json", "csv", "yaml", "toml", "ini", "diff"}
DIRECTIVES = {"skip", "text", "env", "sub", "expect", "setup", "needs", "continue", "timeout"}
DEFAULT_TIMEOUT_S = 300
OUTPUT_TAIL_LINES = 150

MARKER_START = re.compile(r"^\s*<!--\s*doc-test:\s*")
FENCE_OPEN = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`]*)")
LIST_ITEM = re.compile(r"^(\s*)([-*+]|\d+[.)])(\s+)\S")


class Block:
    def __init__(self, path, line, lang, code, markers):
        self.path = path          # markdown file, relative to the source dir
        self.line = line          # 1-based line of the fence (or of the first indented line)
        self.lang = lang          # info string, "indented" or "" (unlabelled fence)
        self.code = code          # the block's text as written
        self.markers = markers    # [(line, directive, argument text)]
        self.kind = None          # "sh", "python", "text", "skip"; None = not runnable
        self.reason = ""
        self.errors = []          # marker errors
        self.env = {}
        self.subs = []
        self.expects = []
        self.setup = []
        self.needs = []
        self.cont = False
        self.timeout = DEFAULT_TIMEOUT_S
        self.script = None        # what runs (after sub, with a continued prefix)

    def where(self):
        return f"{self.path}:{self.line}"


def parse_markdown(path, rel):
    """Blocks of one markdown file, with the markers right above each; marker errors as
    blocks' errors (or as stray-marker entries)."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    blocks, stray = [], []
    pending = []          # markers waiting for their block
    prev_blank = True     # the previous line was blank (or the start of the file)
    list_indent = None    # content indent of the list we are in, None outside lists
    i, n = 0, len(lines)
    while i < n:
        line = lines[i]
        stripped = line.strip()
        if MARKER_START.match(line):
            start = i
            text = MARKER_START.sub("", line)
            while "-->" not in text and i + 1 < n:
                i += 1
                text += "\n" + lines[i]
            text = text.split("-->", 1)[0].strip()
            mk = re.match(r"(\S*)\s*(.*)", text, re.S)
            pending.append((start + 1, mk.group(1), mk.group(2).strip()))
            i += 1
            prev_blank = True   # an HTML block ends like a paragraph break
            continue
        if not stripped:
            prev_blank = True
            i += 1
            continue
        m = FENCE_OPEN.match(line)
        if m:
            indent, fence, lang = len(m.group(1)), m.group(2), m.group(3).lower()
            body, j = [], i + 1
            while j < n:
                s = lines[j].strip()
                if s.startswith(fence[0] * len(fence)) and set(s) == {fence[0]}:
                    break
                raw = lines[j]
                cut = min(indent, len(raw) - len(raw.lstrip(" ")))
                body.append(raw[cut:])
                j += 1
            blocks.append(Block(rel, i + 1, lang, "\n".join(body) + "\n", pending))
            pending = []
            i = j + 1
            prev_blank = False
            continue
        indent = len(line) - len(line.lstrip(" "))
        in_list_text = list_indent is not None and indent < list_indent + 4
        if indent >= 4 and prev_blank and not in_list_text:
            cut = 4 if list_indent is None else list_indent + 4
            body, j = [], i
            while j < n and (not lines[j].strip() or
                             len(lines[j]) - len(lines[j].lstrip(" ")) >= cut):
                body.append(lines[j][cut:])
                j += 1
            while body and not body[-1].strip():
                body.pop()
            blocks.append(Block(rel, i + 1, "indented", "\n".join(body) + "\n", pending))
            pending = []
            i = i + len(body)
            prev_blank = False
            continue
        # Ordinary text: it ends a list when it starts at column 0 after a blank line.
        item = LIST_ITEM.match(line)
        if item:
            list_indent = len(item.group(1)) + len(item.group(2)) + len(item.group(3))
        elif indent == 0 and (prev_blank or stripped.startswith("#")):
            list_indent = None
        for mk in pending:
            stray.append(f"{rel}:{mk[0]}: doc-test marker `{mk[1]}` is not right before a code block")
        pending = []
        prev_blank = False
        i += 1
    for mk in pending:
        stray.append(f"{rel}:{mk[0]}: doc-test marker `{mk[1]}` is not right before a code block")
    return blocks, stray


def console_commands(code):
    """The commands of a console block: `$ ` lines and their `\\` continuation lines."""
    out, cont = [], False
    for line in code.split("\n"):
        if cont:
            out.append(line)
            cont = line.rstrip().endswith("\\")
        elif line.startswith("$ ") or line.rstrip() == "$":
            out.append(line[2:])
            cont = line.rstrip().endswith("\\")
    return "\n".join(out) + "\n"


def classify(block):
    """Sets kind, options and errors of a block from its language and markers."""
    b = block
    for line, word, arg in b.markers:
        where = f"{b.path}:{line}"
        if word not in DIRECTIVES:
            b.errors.append(f"{where}: unknown doc-test directive `{word}` (known: {', '.join(sorted(DIRECTIVES))})")
        elif word == "skip":
            reason = arg.strip()
            if reason.startswith("(") and reason.endswith(")"):
                reason = reason[1:-1].strip()
            if not reason:
                b.errors.append(f"{where}: `skip` needs a reason")
            b.kind, b.reason = "skip", reason
        elif word == "text":
            if b.kind != "skip":
                b.kind = "text"
        elif word == "env":
            for item in shlex.split(arg):
                name, eq, value = item.partition("=")
                if not eq or not name:
                    b.errors.append(f"{where}: `env` takes NAME=VALUE, not `{item}`")
                else:
                    b.env[name] = value
        elif word == "sub":
            parts = shlex.split(arg)
            if len(parts) != 2 or not parts[0]:
                b.errors.append(f"{where}: `sub` takes OLD NEW (shell-quoted), got {parts}")
            else:
                b.subs.append((line, parts[0], parts[1]))
        elif word == "expect":
            try:
                b.expects.append(re.compile(arg, re.MULTILINE))
            except re.error as e:
                b.errors.append(f"{where}: `expect` regex {arg!r}: {e}")
        elif word == "setup":
            if not arg:
                b.errors.append(f"{where}: `setup` needs commands")
            b.setup.append(arg)
        elif word == "needs":
            b.needs.extend(shlex.split(arg))
        elif word == "continue":
            b.cont = True
        elif word == "timeout":
            try:
                b.timeout = float(arg)
            except ValueError:
                b.errors.append(f"{where}: `timeout` takes seconds, not `{arg}`")
    if b.kind in ("skip", "text"):
        return
    if b.lang in SHELL_LANGS or b.lang == "indented":
        b.kind, b.script = "sh", b.code
    elif b.lang in CONSOLE_LANGS:
        b.kind, b.script = "sh", console_commands(b.code)
    elif b.lang in PYTHON_LANGS:
        b.kind, b.script = "python", b.code
    elif b.lang in DISPLAY_LANGS:
        b.kind = "text"
        if b.env or b.subs or b.expects or b.setup or b.cont or b.needs:
            b.errors.append(f"{b.where()}: run-time markers on a ```{b.lang} block, which is not run")
        return
    else:
        b.kind = None
        what = f"```{b.lang}" if b.lang else "an unlabelled ``` block"
        b.errors.append(f"{b.where()}: {what} is not runnable and has no doc-test marker "
                        f"(not code: label it ```text or mark it `<!-- doc-test: text -->`; "
                        f"code that cannot run here: `<!-- doc-test: skip REASON -->`)")
        return
    for line, old, new in b.subs:
        if old not in b.script:
            b.errors.append(f"{b.path}:{line}: `sub` text {old!r} does not occur in the block")
        b.script = b.script.replace(old, new)


def family(block):
    if block.lang in PYTHON_LANGS:
        return "python"
    if block.lang in SHELL_LANGS or block.lang in CONSOLE_LANGS or block.lang == "indented":
        return "sh"
    return None


def link_chains(blocks):
    """`continue`: prefix each such block with the previous block of its kind (its code, env
    and needs; that block must itself run)."""
    last = {}
    for b in blocks:
        fam = family(b)
        if b.cont:
            prev = last.get(fam) if b.kind in ("sh", "python") else None
            if b.kind not in ("sh", "python"):
                b.errors.append(f"{b.where()}: `continue` on a block that is not run")
            elif prev is None:
                b.errors.append(f"{b.where()}: `continue` but no earlier {fam} block in the file")
            elif prev.kind != b.kind or prev.errors:
                b.errors.append(f"{b.where()}: `continue` after {prev.where()}, which is not run")
            else:
                b.script = prev.script.rstrip("\n") + "\n\n" + b.script
                b.env = {**prev.env, **b.env}
                b.needs = prev.needs + [p for p in b.needs if p not in prev.needs]
        if fam:
            last[fam] = b


def python_package_dir():
    for entry in os.environ.get("PYTHONPATH", "").split(os.pathsep):
        if entry and os.path.isfile(os.path.join(entry, "posefilter", "__init__.py")):
            return os.path.abspath(entry)
    return None


def make_workdir(source_dir, shared_dir, data_dir, cli, pydir, name):
    """T/repo that looks like a checkout (see the module docstring); returns (T, T/repo, env)."""
    root = tempfile.mkdtemp(prefix=f"doc_examples_{name}_")
    repo = os.path.join(root, "repo")
    os.makedirs(os.path.join(repo, "build", "release"))
    for entry in sorted(os.listdir(source_dir)):
        if entry in ("build", ".git"):
            continue
        os.symlink(os.path.join(source_dir, entry), os.path.join(repo, entry))
    os.symlink(cli, os.path.join(repo, "build", "release", "posefilter"))
    if pydir:
        os.symlink(pydir, os.path.join(repo, "build", "release", "python"))
    if shared_dir and os.path.isdir(shared_dir):
        os.symlink(shared_dir, os.path.join(root, "shared"))
    if data_dir and os.path.isdir(data_dir):
        os.symlink(data_dir, os.path.join(root, "data"))
    bindir = os.path.join(root, "bin")
    os.makedirs(bindir)
    os.symlink(cli, os.path.join(bindir, "posefilter"))
    os.symlink(sys.executable, os.path.join(bindir, "python3"))
    os.makedirs(os.path.join(root, "blocks"))
    env = dict(os.environ)
    env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env.setdefault("MPLBACKEND", "Agg")
    env["PYTEST_ADDOPTS"] = (env.get("PYTEST_ADDOPTS", "") + " -p no:cacheprovider").strip()
    env["POSEFILTER_SOURCE_DIR"] = source_dir
    env["POSEFILTER_DATA"] = os.path.join(root, "data")
    return root, repo, env


def run_process(argv, cwd, env, timeout):
    """(exit status or None on timeout, combined stdout+stderr)."""
    proc = subprocess.Popen(argv, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        return proc.returncode, out.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        return None, out.decode("utf-8", "replace")


def numbered(code):
    return "\n".join(f"  {k + 1:3d} | {l}" for k, l in enumerate(code.rstrip("\n").split("\n")))


def tail(text):
    lines = text.rstrip("\n").split("\n")
    if len(lines) > OUTPUT_TAIL_LINES:
        return f"  ... ({len(lines) - OUTPUT_TAIL_LINES} lines left out)\n" + "\n".join(lines[-OUTPUT_TAIL_LINES:])
    return "\n".join(lines)


def run_block(b, index, root, repo, env):
    """Runs one block; returns (ok, seconds, the output or, on a failure, the report)."""
    block_env = {**env, **b.env}
    t0 = time.monotonic()
    output = ""
    for k, setup in enumerate(b.setup):
        path = os.path.join(root, "blocks", f"{index:03d}_setup{k}.sh")
        with open(path, "w") as f:
            f.write(setup + "\n")
        rc, out = run_process(["bash", "-e", path], repo, block_env, b.timeout)
        output += out
        if rc != 0:
            status = "timed out" if rc is None else f"exit status {rc}"
            return False, time.monotonic() - t0, f"setup {status}:\n{numbered(setup)}\n{tail(output)}"
    ext = "py" if b.kind == "python" else "sh"
    path = os.path.join(root, "blocks", f"{index:03d}_{os.path.basename(b.path)}_{b.line}.{ext}")
    with open(path, "w") as f:
        f.write(b.script)
    argv = [sys.executable, path] if b.kind == "python" else ["bash", "-e", path]
    rc, out = run_process(argv, repo, block_env, b.timeout)
    output += out
    secs = time.monotonic() - t0
    problems = []
    if rc is None:
        problems.append(f"timed out after {b.timeout:.0f} s")
    elif rc != 0:
        problems.append(f"exit status {rc}")
    for rx in b.expects:
        if not rx.search(output):
            problems.append(f"output does not match expect /{rx.pattern}/")
    if problems:
        env_note = "".join(f"\n  env {k}={v}" for k, v in b.env.items())
        return False, secs, (f"{'; '.join(problems)}{env_note}\n--- {b.kind} block as run:\n"
                             f"{numbered(b.script)}\n--- output:\n{tail(output)}")
    return True, secs, output


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="*", help="markdown files (relative to the source dir); default "
                    "README.md and docs/*.md")
    ap.add_argument("--list", action="store_true", help="list the blocks and what would happen; run nothing")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folders")
    ap.add_argument("-v", "--verbose", action="store_true", help="print the output of every block run")
    args = ap.parse_args()

    here = os.path.dirname(os.path.abspath(__file__))
    source_dir = os.path.abspath(os.environ.get("POSEFILTER_SOURCE_DIR") or os.path.join(here, "..", ".."))
    shared_dir = os.path.abspath(os.environ.get("POSEFILTER_SHARED_DIR") or
                                 os.path.join(source_dir, "..", "shared"))
    data_dir = os.path.abspath(os.environ.get("POSEFILTER_DATA") or os.path.join(shared_dir, "data"))
    files = args.files or (["README.md"] + sorted(
        os.path.relpath(p, source_dir) for p in glob.glob(os.path.join(source_dir, "docs", "*.md"))))

    problems, all_blocks = [], []
    for rel in files:
        path = os.path.join(source_dir, rel)
        if not os.path.isfile(path):
            problems.append(f"{rel}: no such file")
            continue
        blocks, stray = parse_markdown(path, rel)
        problems.extend(stray)
        for b in blocks:
            classify(b)
        link_chains(blocks)
        for b in blocks:
            problems.extend(b.errors)
        all_blocks.append((rel, blocks))

    if args.list:
        for rel, blocks in all_blocks:
            for b in blocks:
                extra = f" ({b.reason})" if b.kind == "skip" else ""
                print(f"{(b.kind or '??'):6s} {b.where():28s} {b.lang or '```'}{extra}")
        for p in problems:
            print("ERROR", p)
        return 1 if problems else 0

    cli = os.environ.get("POSEFILTER_CLI_PATH")
    if not cli or not os.access(cli, os.X_OK):
        print(f"run_doc_examples: POSEFILTER_CLI_PATH={cli!r} is not an executable posefilter", file=sys.stderr)
        return 1
    cli = os.path.abspath(cli)
    pydir = python_package_dir()

    t_start = time.monotonic()
    counts = {"ran": 0, "failed": 0, "skipped": 0, "text": 0}
    failures = []
    for rel, blocks in all_blocks:
        runnable = [b for b in blocks if b.kind in ("sh", "python") and not b.errors]
        root = repo = env = None
        if runnable:
            root, repo, env = make_workdir(source_dir, shared_dir, data_dir, cli, pydir,
                                           re.sub(r"\W", "_", os.path.splitext(os.path.basename(rel))[0]))
        for index, b in enumerate(blocks):
            head = f"{b.where():28s} {b.kind or '??':6s}"
            if b.errors:
                print(f"[ERR ] {head} marker error (below)")
                counts["failed"] += 1
                continue
            if b.kind == "text":
                counts["text"] += 1
                continue
            if b.kind == "skip":
                print(f"[skip] {head} {b.reason}")
                counts["skipped"] += 1
                continue
            missing = [p for p in b.needs
                       if not os.path.exists(os.path.join(repo, p.replace("$POSEFILTER_DATA", env["POSEFILTER_DATA"])))]
            if missing:
                print(f"[skip] {head} needs {', '.join(missing)}: absent")
                counts["skipped"] += 1
                continue
            ok, secs, message = run_block(b, index, root, repo, env)
            if ok:
                print(f"[ ok ] {head} {secs:6.1f} s", flush=True)
                if args.verbose:
                    print(tail(message))
                counts["ran"] += 1
            else:
                print(f"[FAIL] {head} {secs:6.1f} s", flush=True)
                counts["failed"] += 1
                failures.append(f"{b.where()} ({b.lang or '```'} block): {message}")
        if root and not args.keep:
            shutil.rmtree(root, ignore_errors=True)
        elif root:
            print(f"       kept {root}")

    for f in failures:
        print(f"\n==== FAILED {f}")
    if problems:
        print()
        for p in problems:
            print("ERROR", p)
    total = time.monotonic() - t_start
    print(f"\ndoc examples: {counts['ran']} ran, {counts['failed']} failed, {counts['skipped']} skipped, "
          f"{counts['text']} not code; marker/classification errors: {len(problems)}; total {total:.1f} s")
    return 1 if failures or problems or counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
