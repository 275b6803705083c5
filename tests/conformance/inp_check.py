"""The conformance sweep's checks of one smoothed Abaqus / CalculiX deck:
only *NODE data lines may differ from the input, and only in their
coordinates; meshio reads the same cells; ccx solves it as it solved the
input (docs/conformance.md)."""
import os
import shutil
import subprocess

import meshio


def node_data_lines(lines):
    """For each line: True when it is a data line of a *NODE block (not
    *NODE PRINT / FILE / OUTPUT, which are other keywords)."""
    inside = False
    for line in lines:
        s = line.lstrip()
        if s.startswith(b"**"):
            yield False
            continue
        if s.startswith(b"*"):
            inside = s[1:].split(b",")[0].strip().upper() == b"NODE"
            yield False
            continue
        yield inside


def compare(src, out, report):
    """('' or the first difference, number of node lines changed)."""
    a = open(src, "rb").read().split(b"\n")
    b = open(out, "rb").read().split(b"\n")
    if len(a) != len(b):
        return "line count %d -> %d" % (len(a), len(b)), 0
    moved = 0
    for i, (x, y, node) in enumerate(zip(a, b, node_data_lines(a))):
        if x == y:
            continue
        if not node:
            return "line %d changed outside *NODE data: %r -> %r" % (i + 1, x[:60], y[:60]), moved
        fx, fy = x.split(b","), y.split(b",")
        if fx[0] != fy[0] or len(fx) != len(fy):
            return "line %d: node id or field count changed" % (i + 1), moved
        moved += 1
    if moved and report and report["fixed_nodes"] == report["nodes"]:
        return "nodes moved although every node is fixed", moved
    return "", moved


def meshio_same(src, out):
    try:
        ma = meshio.read(src, file_format="abaqus")
    except BaseException:  # meshio exits (SystemExit) on decks it cannot read
        return ""                               # meshio cannot read this deck
    try:
        mb = meshio.read(out, file_format="abaqus")
    except BaseException as e:
        return "meshio reads the input but not the output: %s" % str(e)[:80]
    ca = sorted((c.type, len(c.data)) for c in ma.cells)
    cb = sorted((c.type, len(c.data)) for c in mb.cells)
    return "" if ca == cb and len(ma.points) == len(mb.points) else "meshio reads other cells"


def ccx_run(deck, work):
    os.makedirs(work, exist_ok=True)
    shutil.copyfile(deck, os.path.join(work, "job.inp"))
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    try:
        p = subprocess.run(["ccx", "-i", "job"], cwd=work, capture_output=True,
                           text=True, timeout=300, env=env)
    except subprocess.TimeoutExpired:
        return None
    return p.returncode == 0 and "*ERROR" not in p.stdout


def ccx_solve(src, out, work):
    """('pass' | 'refused' | 'fail', cause): ccx on the input, then on the
    output, when the input runs."""
    if shutil.which("ccx") is None:
        return "refused", "ccx not installed"
    name = os.path.splitext(os.path.basename(src))[0]
    ok = ccx_run(src, os.path.join(work, name))
    if not ok:
        return "refused", "the input deck does not run in ccx"
    if not ccx_run(out, os.path.join(work, name + "-out")):
        return "fail", "ccx fails on the smoothed deck"
    return "pass", ""
