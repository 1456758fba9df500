#!/usr/bin/env python3
"""The docs test: runs every fenced shell command of README.md and docs/*.md.

Rules the documents follow (this test enforces them):
  - a fenced block marked ```sh (or bash, shell) is run, command by command, in document order;
    lines ending in a backslash continue the command; `#` comments are the shell's;
  - a fenced block marked ```python is run as one script, with the module on PYTHONPATH;
  - ```sh no-test: REASON marks a block that is shown but not run, and says why (installing
    packages, a cluster that mpirun needs); the test prints each with its reason, so none hides,
    and a no-test without a reason fails;
  - mpirun runs on this machine (as root if need be, ranks oversubscribed on its cores), so
    the documents' one-machine mpirun examples are run like any other command;
  - a fenced block of another kind must not hold pathlab commands (mark it sh).

Each document runs in a fresh directory that looks like the repository (build/, scenes/,
tests/, examples/, scripts/, the Makefile, and ../shared linked in; docs/ empty), so a command
that refers to a file no earlier command of the same document made fails. Renders are kept
small by PATHLAB_SPP_CAP, PATHLAB_TIME_CAP and PATHLAB_RESOLUTION_CAP (every render: at most
2 samples per pixel, 0.1 s and 128 pixels on its longer side; see src/job/render_job.hpp), so
the whole test takes about a minute.

A command passes with exit code 0; `pathlab compare` and `pathlab check` may also exit with 1
(their verdict on tiny renders), never with 2 (bad usage: a missing file, an unknown name).
Also run: README's first command, `make render`, without its build step.
"""
import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

RUN_INFO = {"sh", "bash", "shell"}
# Every render at most 2 samples per pixel, 0.1 s and 128 pixels on its longer side.
CAPS = {"PATHLAB_SPP_CAP": "2", "PATHLAB_TIME_CAP": "0.1", "PATHLAB_RESOLUTION_CAP": "128"}
VERDICT_COMMANDS = re.compile(r"(^|\s)(build/)?pathlab\s+(compare|check)\s")
PATHLAB_LINE = re.compile(r"^\s*(build/pathlab\s|pathlab\s|PYTHONPATH=\S+\s+python3\s|make\s|mpirun\s)")
# mpirun on one machine: as root (CI and containers run as root), more ranks than cores.
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMPI_MCA_rmaps_base_oversubscribe": "1"}


def no_test_reason(info):
    """None for a block that runs; else the reason after `no-test` ("" when none is given)."""
    words = info.split(None, 1)
    rest = words[1].strip() if len(words) > 1 else ""
    if not rest.startswith("no-test"):
        return None
    return rest[len("no-test"):].lstrip(" :").strip()


def blocks(text):
    """(line number, info string, lines) of every fenced block."""
    out, inside, info, start, lines = [], False, "", 0, []
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if stripped.startswith("```"):
            if not inside:
                inside, info, start, lines = True, stripped[3:].strip(), number, []
            else:
                out.append((start, info, lines))
                inside = False
            continue
        if inside:
            lines.append(line)
    return out


def commands(lines):
    """Whole commands: continuation lines joined; blank and comment-only lines dropped."""
    out, current = [], ""
    for line in lines:
        if line.rstrip().endswith("\\"):
            current += line.rstrip()[:-1] + " "
            continue
        current += line
        if current.strip() and not current.strip().startswith("#"):
            out.append(current.strip())
        current = ""
    if current.strip():
        out.append(current.strip())
    return out


def make_root(tmp, source, build, shared, python):
    root = tmp / "repo"
    root.mkdir()
    (root / "build").symlink_to(build)
    for name in ("scenes", "tests", "examples", "scripts", "python", "src", "Makefile", "CMakeLists.txt"):
        if (source / name).exists():
            (root / name).symlink_to(source / name)
    (root / "docs").mkdir()
    if shared.exists():
        (tmp / "shared").symlink_to(shared)
    bindir = tmp / "bin"
    bindir.mkdir()
    (bindir / "python3").symlink_to(python)  # the interpreter with NumPy, as `python3` in the docs
    return root, bindir


def run(command, root, env, timeout=120):
    start = time.monotonic()
    r = subprocess.run(["bash", "-c", command], cwd=root, env=env, capture_output=True, text=True, timeout=timeout)
    return r, time.monotonic() - start


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True, type=pathlib.Path)
    ap.add_argument("--build", required=True, type=pathlib.Path)
    ap.add_argument("--shared", required=True, type=pathlib.Path)
    ap.add_argument("--python", required=True)
    ap.add_argument("--only", help="run only this document (relative path)")
    args = ap.parse_args()
    source, build, shared = args.source.resolve(), args.build.resolve(), args.shared.resolve()
    documents = [source / "README.md"] + sorted((source / "docs").glob("*.md"))
    if args.only:
        documents = [source / args.only]

    failures, skipped, ran = [], [], 0
    total_start = time.monotonic()
    for doc in documents:
        rel = doc.relative_to(source)
        with tempfile.TemporaryDirectory(prefix="pathlab-docs-") as t:
            tmp = pathlib.Path(t)
            root, bindir = make_root(tmp, source, build, shared, args.python)
            env = dict(os.environ, PATH=f"{bindir}:{os.environ.get('PATH', '')}", **CAPS, **MPI_ENV)
            env.pop("PYTHONPATH", None)
            for start, info, lines in blocks(doc.read_text()):
                words = info.split()
                kind = words[0] if words else ""
                reason = no_test_reason(info)
                if reason == "":
                    failures.append(f"{rel}:{start}: a no-test block must say why it is not run (```{kind} no-test: REASON)")
                    continue
                if reason is not None and kind in RUN_INFO | {"python"}:
                    skipped.append(f"{rel}:{start} ({reason})")
                    continue
                if kind == "python":
                    script = tmp / f"block-{start}.py"
                    script.write_text("\n".join(lines) + "\n")
                    try:
                        r, seconds = run(f"python3 {script}", root, dict(env, PYTHONPATH=str(root / "build" / "python")))
                    except subprocess.TimeoutExpired:
                        failures.append(f"{rel}:{start}: the python block timed out")
                        continue
                    ran += 1
                    print(f"{'ok  ' if r.returncode == 0 else 'FAIL'} {seconds:5.1f}s {rel}:{start}: python block", flush=True)
                    if r.returncode != 0:
                        failures.append(f"{rel}:{start}: the python block exited with {r.returncode}\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
                    continue
                if kind not in RUN_INFO:
                    for line in lines:
                        if PATHLAB_LINE.match(line):
                            failures.append(f"{rel}:{start}: a ```{info} block holds the command '{line.strip()}': mark the block sh "
                                            "(run by this test) or sh no-test")
                            break
                    continue
                for command in commands(lines):
                    if "../shared" in command and not shared.exists():
                        skipped.append(f"{rel}:{start}: {command} (no {shared})")
                        continue
                    try:
                        r, seconds = run(command, root, env)
                    except subprocess.TimeoutExpired:
                        failures.append(f"{rel}:{start}: timed out: {command}")
                        continue
                    ran += 1
                    ok = r.returncode == 0 or (r.returncode == 1 and VERDICT_COMMANDS.search(" " + command + " "))
                    print(f"{'ok  ' if ok else 'FAIL'} {seconds:5.1f}s {rel}:{start}: {command}", flush=True)
                    if not ok:
                        failures.append(f"{rel}:{start}: exit code {r.returncode}: {command}\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    # README's first command, `make render`, without its build step (-o build: taken as made).
    with tempfile.TemporaryDirectory(prefix="pathlab-docs-") as t:
        tmp = pathlib.Path(t)
        root, bindir = make_root(tmp, source, build, shared, args.python)
        env = dict(os.environ, PATH=f"{bindir}:{os.environ.get('PATH', '')}", **CAPS)
        r, seconds = run("make -o build render BUILD=build", root, env, timeout=300)
        ran += 1
        made = sorted(p.relative_to(root).as_posix() for p in (root / "out").rglob("*.png")) if (root / "out").exists() else []
        print(f"{'ok  ' if r.returncode == 0 else 'FAIL'} {seconds:5.1f}s make render ({len(made)} pictures)", flush=True)
        if r.returncode != 0 or len(made) != 16:
            failures.append(f"make render: exit code {r.returncode}, {len(made)} of 16 pictures\n{r.stdout[-2000:]}{r.stderr[-2000:]}")

    print(f"\n{ran} commands in {time.monotonic() - total_start:.1f} s; not run (marked no-test):")
    for s in skipped:
        print(f"  {s}")
    if failures:
        print(f"\n{len(failures)} failed:\n" + "\n\n".join(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
