#!/usr/bin/python3
"""bench/phase_timers.py on a copy of the library's sources: every anchor
must still match (a change of the instrumented lines would silently drop
timers), the instrumented files must compile with the project's warnings
as errors, a second run must leave them alone, a missing anchor must be
reported with exit code 1, and a main checkout (a .git directory) must
be refused untouched."""
import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile


def tool_patches(tool):
    """The tool's own table of files and anchors (not a copy of it)."""
    spec = importlib.util.spec_from_file_location("phase_timers", tool)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.PATCHES


def run(tool, root):
    return subprocess.run([sys.executable, tool, root], capture_output=True,
                          text=True)


def copy_core(src, dst):
    shutil.copytree(os.path.join(src, "core"), os.path.join(dst, "core"),
                    ignore=shutil.ignore_patterns("build*"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--cc", required=True)
    a = ap.parse_args()
    tool = os.path.join(a.source, "bench", "phase_timers.py")
    patches = tool_patches(tool)
    files = tuple(patches)
    fails = []
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.join(tmp, "tree")
        copy_core(a.source, root)
        r = run(tool, root)
        if r.returncode != 0:
            fails.append(f"exit {r.returncode} on the current sources:\n{r.stdout}{r.stderr}")
        for rel in files:
            text = open(os.path.join(root, rel)).read()
            marks = text.count("TT(\"") + text.count("TT0();")
            # every anchor's replacement inserts at least one mark
            if "static double TT_t0;" not in text or marks < len(patches[rel]):
                fails.append(f"{rel}: {marks} marks inserted for "
                             f"{len(patches[rel])} anchors")
            c = subprocess.run([a.cc, "-std=c11", "-fopenmp", "-fsyntax-only",
                                "-Wall", "-Wextra", "-Wpedantic", "-Werror",
                                "-I", os.path.join(root, "core/include"),
                                "-I", os.path.join(root, "core/src"),
                                "-I", os.path.join(root, "core/alloc"),
                                os.path.join(root, rel)],
                               capture_output=True, text=True)
            if c.returncode != 0:
                fails.append(f"{rel} does not compile instrumented:\n{c.stderr[:2000]}")
        before = {rel: open(os.path.join(root, rel)).read() for rel in files}
        r = run(tool, root)
        if r.returncode != 0 or r.stdout.count("already instrumented") != len(files):
            fails.append(f"second run: exit {r.returncode}, {r.stdout!r}")
        for rel in files:
            if open(os.path.join(root, rel)).read() != before[rel]:
                fails.append(f"second run changed {rel}")

        # a drifted anchor: reported, skipped, exit code 1
        drift = os.path.join(tmp, "drift")
        copy_core(a.source, drift)
        p = os.path.join(drift, "core/src/adjacency.c")
        s = open(p).read()
        anchor = "    if (!(scratch = getme__malloc(sbytes)))"
        if anchor not in s:
            fails.append("the drift case's anchor is gone from adjacency.c")
        open(p, "w").write(s.replace(anchor, "    if ((scratch = getme__malloc(sbytes)) == NULL)"))
        r = run(tool, drift)
        if r.returncode != 1 or "anchor not found" not in r.stdout:
            fails.append(f"a drifted anchor: exit {r.returncode}, {r.stdout!r}")

        # a main checkout (.git is a directory): refused, nothing written
        main_co = os.path.join(tmp, "main")
        copy_core(a.source, main_co)
        os.makedirs(os.path.join(main_co, ".git"))
        orig = {rel: open(os.path.join(main_co, rel)).read() for rel in files}
        r = run(tool, main_co)
        if r.returncode != 2 or "refusing" not in r.stderr:
            fails.append(f"main checkout: exit {r.returncode}, {r.stderr!r}")
        for rel in files:
            if open(os.path.join(main_co, rel)).read() != orig[rel]:
                fails.append(f"main checkout: {rel} was changed")
    for f in fails:
        print("FAIL:", f)
    if not fails:
        print(f"ok: {len(files)} files instrumented and compiled; drift, "
              "repeat and main checkout handled")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
