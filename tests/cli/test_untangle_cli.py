#!/usr/bin/python3
"""`getme smooth` on tangled inputs (issue #12): untangling, the warning
line, --no-untangle, exit code 8 naming the elements, --allow-invalid.

usage: /usr/bin/python3 test_untangle_cli.py GETME_BINARY WORKDIR

The inputs are Abaqus decks written here: a 6^3 grid of C3D8 hexes (element
ids from 101, node ids from 1001, so that file ids differ from indices)
with interior nodes pushed through the opposite face of their cell.
Asserted: exit 0, a warning with the counts, every output element valid by
bench/quality.py's independent mean ratio, skin nodes bit-identical, 1 and
2 threads byte-identical; --no-untangle exits 6 without output; a hex whose
nodes are all fixed (--fix on an NSET) and pushed inside out exits 8, names
its file id, and writes nothing unless --allow-invalid.
"""
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench"))
from quality import element_quality  # noqa: E402

GETME, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)
for name in os.listdir(WORK):  # outputs of an earlier run
    os.remove(os.path.join(WORK, name))
N, E0, N0 = 6, 101, 1001
failures, passed = [], 0


def check(cond, what):
    global passed
    if cond:
        passed += 1
    else:
        failures.append(what)
        print("FAILED:", what, flush=True)


def run(*args, expect=0):
    p = subprocess.run([GETME, *args], capture_output=True, text=True)
    if p.returncode != expect:
        print(p.stdout[-3000:], p.stderr[-3000:])
    check(p.returncode == expect, f"getme {' '.join(args)} -> {p.returncode}, want {expect}")
    return p


def gid(i, j, k):
    return i + (N + 1) * (j + (N + 1) * k)


def grid():
    pts = np.array([(i, j, k) for k in range(N + 1) for j in range(N + 1)
                    for i in range(N + 1)], dtype=float)
    hexes = []
    for k in range(N):
        for j in range(N):
            for i in range(N):
                hexes.append([gid(i, j, k), gid(i + 1, j, k), gid(i + 1, j + 1, k),
                              gid(i, j + 1, k), gid(i, j, k + 1), gid(i + 1, j, k + 1),
                              gid(i + 1, j + 1, k + 1), gid(i, j + 1, k + 1)])
    return pts, np.array(hexes)


def write_inp(path, pts, hexes, nset=None):
    with open(path, "w") as f:
        f.write("*HEADING\ntangled hex grid\n*NODE\n")
        for n, p in enumerate(pts):
            f.write("%d, %.17g, %.17g, %.17g\n" % (N0 + n, *p))
        f.write("*ELEMENT, TYPE=C3D8, ELSET=SOLID\n")
        for e, h in enumerate(hexes):
            f.write("%d, %s\n" % (E0 + e, ", ".join(str(N0 + v) for v in h)))
        if nset is not None:
            f.write("*NSET, NSET=STUCK\n%s\n" % ", ".join(str(N0 + v) for v in nset))


def read_nodes(path):
    nodes, on = {}, False
    with open(path) as f:
        for line in f:
            if line.startswith("*"):
                on = line.upper().startswith("*NODE")
                continue
            if on and line.strip():
                v = line.split(",")
                nodes[int(v[0])] = np.array([float(x) for x in v[1:4]])
    return np.array([nodes[N0 + n] for n in range(len(nodes))])


def skin(hexes):
    ids = set()
    for i in range(N + 1):
        for j in range(N + 1):
            for k in range(N + 1):
                if min(i, j, k) == 0 or max(i, j, k) == N:
                    ids.add(gid(i, j, k))
    return sorted(ids)


pts, hexes = grid()
tangled = pts.copy()
tangled[gid(2, 2, 2)] += (1.6, 0.1, 0.05)
tangled[gid(4, 3, 4)] += (-0.1, -1.7, 0.1)
q0 = element_quality(tangled, hexes, "hex")
check((q0 <= 0).sum() > 0, "the input has invalid hexes")
src = os.path.join(WORK, "tangled.inp")
write_inp(src, tangled, hexes)

# untangled and smoothed, 1 and 2 threads
outs = []
for t in (1, 2):
    out = os.path.join(WORK, "smooth-%d.inp" % t)
    p = run("smooth", src, "-o", out, "--threads", str(t))
    warn = [ln for ln in p.stdout.splitlines() if ln.startswith("Warning :")]
    check(any("%d invalid" % (q0 <= 0).sum() in ln and "0 remain" in ln for ln in warn),
          "warning line with the counts: %s" % warn)
    x = read_nodes(out)
    q = element_quality(x, hexes, "hex")
    check(q.min() > 0.5, "output valid and smoothed (q_min %.4f)" % q.min())
    s = skin(hexes)
    check(np.array_equal(x[s], tangled[s]), "skin nodes bit-identical")
    outs.append(open(out, "rb").read())
check(outs[0] == outs[1], "1 and 2 threads byte-identical")

# --no-untangle: today's refusal
out = os.path.join(WORK, "refused.inp")
p = run("smooth", src, "-o", out, "--no-untangle", expect=6)
check(not os.path.exists(out), "no output with --no-untangle")
check("invalid" in p.stderr, "refusal names the problem")

# a hex with every node fixed, turned inside out: exit 8, named, no output
stuck_pts = pts.copy()
cell = 1 + N * (1 + N * 1)
stuck_pts[hexes[cell][6]] = (0.8, 0.8, 0.8)
stuck = os.path.join(WORK, "stuck.inp")
write_inp(stuck, stuck_pts, hexes, nset=hexes[cell])
out = os.path.join(WORK, "stuck-out.inp")
p = run("smooth", stuck, "-o", out, "--fix", "STUCK", expect=8)
check(not os.path.exists(out), "no output when elements stay invalid")
err = [ln for ln in p.stderr.splitlines() if "could not be untangled" in ln]
check(len(err) == 1 and str(E0 + cell) in err[0],
      "error names the element by its file id %d: %s" % (E0 + cell, err))
check(any(ln.startswith("Warning :") and "remain" in ln for ln in p.stdout.splitlines()),
      "warning line with the counts")
# --allow-invalid: the partly untangled mesh is written, exit code still 8
p = run("smooth", stuck, "-o", out, "--fix", "STUCK", "--allow-invalid", expect=8)
check(os.path.exists(out), "--allow-invalid writes the partly untangled mesh")
if os.path.exists(out):
    x = read_nodes(out)
    q = element_quality(x, hexes, "hex")
    qs = element_quality(stuck_pts, hexes, "hex")
    check(q[cell] <= 0 and (q <= 0).sum() < (qs <= 0).sum(),
          "only the stuck part stays invalid (%d -> %d)" % ((qs <= 0).sum(), (q <= 0).sum()))
    check(np.array_equal(x[hexes[cell]], stuck_pts[hexes[cell]]), "fixed nodes kept")

print("test_untangle_cli: %d passed, %d failed" % (passed, len(failures)))
sys.exit(1 if failures or not passed else 0)
