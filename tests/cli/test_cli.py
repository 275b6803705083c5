#!/usr/bin/python3
"""Integration tests of the getme command on Gmsh-generated, distorted meshes.

usage: /usr/bin/python3 test_cli.py GETME_BINARY WORKDIR CASE
CASE: tet | hex | mixed | tri | quad | errors | untangle

For a mesh case: Gmsh (Python API) generates the mesh, `getme distort`
distorts it, then `getme smooth` runs with GETMe adaptive (1 and 2 threads)
and smart Laplace.  Asserted: every output element valid by a mean ratio
computed here with numpy (independently of libgetme), nodes on
lower-dimensional Gmsh entities bit-identical, q*min and qmean improved,
GETMe's q*min above smart Laplace's, 1- and 2-thread outputs byte-identical,
the input file untouched.
"""
import hashlib
import json
import os
import subprocess
import sys

import gmsh
import numpy as np

GETME, WORK, CASE = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(WORK, exist_ok=True)
from checks import Checks  # tests/support (PYTHONPATH set by ctest)

T = Checks(GETME)
check, run = T.check, T.run


# ---- independent mean ratio: bench/quality.py (numpy, docs/design.md §1, -----
# written apart from libgetme and checked against it by the bench_quality test)
from quality import element_quality  # bench/ (PYTHONPATH set by ctest)
from gmsh_helpers import structured_hex_volume, two_unit_boxes  # tests/support


GMSH_TYPES = {4: "tet", 5: "hex", 6: "prism", 7: "pyramid", 2: "tri", 3: "quad"}


def read(path):
    """Nodes (tag -> xyz), fixed node tags (on entities below the mesh
    dimension), per-type element qualities, element tags."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(path)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = xyz.reshape(-1, 3)
    node = {int(t): xyz[i] for i, t in enumerate(tags)}
    dim = max(d for d, _ in gmsh.model.getEntities() if len(gmsh.model.mesh.getElements(d)[0]))
    fixed = set()
    for d in range(dim):
        t, _, _ = gmsh.model.mesh.getNodes(d, -1, includeBoundary=True)
        fixed.update(int(v) for v in t)
    qual, etags = {}, []
    index = {int(t): i for i, t in enumerate(tags)}
    types, etag_lists, conns = gmsh.model.mesh.getElements(dim)
    for ty, et, conn in zip(types, etag_lists, conns):
        kind = GMSH_TYPES[ty]
        nv = len(conn) // len(et)
        idx = np.vectorize(index.get)(conn.reshape(-1, nv))
        qual[kind] = element_quality(xyz, idx, kind)
        etags.extend(int(e) for e in et)
    gmsh.finalize()
    return node, fixed, qual, sorted(etags), dim


def summary(qual, fixed=None):
    allq = np.concatenate(list(qual.values()))
    return float(allq.min()), float(allq.mean()), int((allq <= 0).sum())


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


# ---- mesh generation -----------------------------------------------------

def make(case, path):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    occ, gm = gmsh.model.occ, gmsh.model
    if case == "tet":
        b = occ.addBox(0, 0, 0, 2, 1, 1)
        c = occ.addCylinder(1, 0.5, -0.1, 0, 0, 1.2, 0.25)
        occ.cut([(3, b)], [(3, c)])
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.09)
        gm.mesh.generate(3)
    elif case == "hex":
        r = occ.addRectangle(0, 0, 0, 2, 1)
        d = occ.addDisk(1, 0.5, 0, 0.25, 0.25)
        occ.cut([(2, r)], [(2, d)])
        occ.extrude([(2, r)], 0, 0, 0.5, numElements=[5], recombine=True)
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.08)
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
        gm.mesh.generate(3)
    elif case == "mixed":
        two_unit_boxes()
        top = [s for s in gm.getBoundary([(3, 2)], oriented=False)
               if abs(occ.getCenterOfMass(2, s[1])[2] - 1) < 1e-9][0]
        occ.extrude([top], 0, 0, 0.5, numElements=[3], recombine=True)
        occ.synchronize()
        structured_hex_volume(1, 7)
        gm.mesh.generate(3)
    elif case in ("tri", "quad"):
        r = occ.addRectangle(0, 0, 0, 2, 1)
        d = occ.addDisk(0.7, 0.5, 0, 0.2, 0.2)
        occ.cut([(2, r)], [(2, d)])
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.04)
        if case == "quad":
            gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gm.mesh.generate(2)
    gmsh.write(path)
    gmsh.finalize()


def mesh_case(case):
    base = os.path.join(WORK, case)
    orig, dist = base + ".msh", base + "-distorted.msh"
    make(case, orig)
    run("distort", orig, "-o", dist, "--seed", "11", "--target-qmean", "0.55", "-q")
    digest = sha(dist)
    out1, out2, lap = base + "-t1.msh", base + "-t2.msh", base + "-laplace.msh"
    run("smooth", dist, "-o", out1, "--threads", "1", "-q", "--report", base + ".json")
    run("smooth", dist, "-o", out2, "--threads", "2", "-q")
    run("smooth", dist, "-o", lap, "--method", "laplace", "-q")
    check(sha(dist) == digest, "input file untouched")
    check(sha(out1) == sha(out2), "1 and 2 threads give byte-identical output")

    n0, fixed, q0, e0, dim = read(dist)
    n1, _, q1, e1, _ = read(out1)
    _, _, ql, _, _ = read(lap)
    kinds = sorted(q0)
    check(e0 == e1, "element tags kept")
    check(set(n0) == set(n1), "node tags kept")
    moved_fixed = [t for t in fixed if not np.array_equal(n0[t], n1[t])]
    check(not moved_fixed, f"fixed nodes bit-identical ({len(moved_fixed)} moved)")
    moved = sum(not np.array_equal(n0[t], n1[t]) for t in n0)
    check(moved > 0, "free nodes moved")
    mn0, mean0, bad0 = summary(q0)
    mn1, mean1, bad1 = summary(q1)
    mnl, meanl, badl = summary(ql)
    check(bad0 == 0 and bad1 == 0 and badl == 0, "every element valid")
    check(mn1 > mn0 + 0.1, f"q*min improved ({mn0:.4f} -> {mn1:.4f})")
    check(mean1 > mean0 + 0.05, f"qmean improved ({mean0:.4f} -> {mean1:.4f})")
    check(mn1 > mnl, f"GETMe q*min {mn1:.4f} above smart Laplace {mnl:.4f}")
    rep = json.load(open(base + ".json"))
    check(abs(rep["after"]["q_mean"] - mean1) < 1e-9,
          "report's qmean equals the independent one")
    check(rep["iterations"]["mean_stage"] > 0 and rep["iterations"]["min_stage"] > 0,
          "both stages ran")
    its = [h for h in rep["history"] if h["stage"] != 4]
    passes = [h for h in rep["history"] if h["stage"] == 4]
    check(len(its) == rep["iterations"]["total"], "one history record per iteration")
    check(len(passes) == rep["iterations"]["finish_passes"], "one history record per finishing pass")
    # The finishing step never lowers q*min: its passes climb from where the
    # q*min stage (with keep_best) ended, and the result is the last pass.
    qs = [h["q_min_star"] for h in passes]
    check(all(b >= a for a, b in zip(qs, qs[1:])), "q*min never decreases over the finishing passes")
    check(not qs or abs(qs[-1] - rep["after"]["q_min_star"]) < 1e-12, "the result is the last pass's q*min")
    # The worst elements of the report, checked against the output's own
    # qualities: the worst overall is the minimum over all elements.
    worst = rep["worst_elements"]
    check(len(worst) == min(10, rep["after"]["elements"]) and
          abs(worst[0]["quality"] - rep["after"]["q_min"]) < 1e-12, "worst element = qmin")
    check(all(a["quality"] <= b["quality"] for a, b in zip(worst, worst[1:])), "worst first")
    wf = rep["worst_free_elements"]
    check(wf and abs(wf[0]["quality"] - rep["after"]["q_min_star"]) < 1e-12 and
          all(w["free_nodes"] > 0 for w in wf), "worst element with a free node = q*min")
    # the analysts' measures (docs/quality.md): per type, before and after
    meas = rep["measures"]
    for k in kinds:
        b, a = meas["before"][k], meas["after"][k]
        check(a["sicn"]["elements"] == len(q1[k]) and sum(a["sicn"]["histogram"]) == len(q1[k]),
              f"{k}: SICN counted for every element")
        check(a["sicn"]["min"] > b["sicn"]["min"] and a["scaled_jacobian"]["min"] > 0,
              f"{k}: SICN min improved, scaled Jacobian positive after smoothing")
        check(abs(a["mean_ratio"]["min"] - min(q1[k])) < 1e-9,
              f"{k}: report's per-type mean ratio min equals the independent one")
        check(("gamma" in a) == (k not in ("hex", "pyramid")), f"{k}: gamma only where Gmsh has one")
    p = run("quality", out1)
    for k in kinds:
        check(f"{k} SICN: min" in p.stdout and f"{k} scaled Jacobian: min" in p.stdout,
              f"getme quality prints the {k} measures")
    # --threads as smooth's: the report is the same for any number
    r1 = run("quality", dist, "--threads", "1", "--worst", "5")
    r2 = run("quality", dist, "--threads", "2", "--worst", "5")
    check(r1.stdout == r2.stdout and r1.stderr == r2.stderr and "Worst 5" in r1.stdout,
          "getme quality --threads 1 and 2 print the same report")
    run("quality", dist, "--threads", "0", expect=2)
    print(f"{case}: {', '.join(f'{k} {len(q0[k])}' for k in kinds)}; q*min {mn0:.4f} -> "
          f"getme {mn1:.4f} (laplace {mnl:.4f}); qmean {mean0:.4f} -> {mean1:.4f} "
          f"(laplace {meanl:.4f}); iterations {rep['iterations']['mean_stage']}/"
          f"{rep['iterations']['min_stage']}")


def errors_case():
    missing = os.path.join(WORK, "nope.msh")
    p = run("smooth", missing, "-o", os.path.join(WORK, "x.msh"), expect=3)
    check("nope.msh" in p.stderr, "missing file named in the error")
    run("smooth", expect=2)
    run("smooth", missing, expect=2)
    run("smooth", "a.msh", "-o", "b.msh", "--threads", "zero", expect=2)
    p = run("smooth", "a.msh", "-o", "b.msh", "--param", "sigma=-1", expect=2)
    check("sigma takes a number > 0" in p.stderr, "range named: " + p.stderr.strip())
    p = run("smooth", "a.msh", "-o", "b.msh", "--param", "finish=0.5", expect=2)
    check("finish takes an integer [0, 1]" in p.stderr, "integer range named: " + p.stderr.strip())
    p = run("smooth", "a.msh", "-o", "b.msh", "--param", "sigm=1", expect=2)
    check("unknown parameter 'sigm'" in p.stderr, "unknown parameter named")
    run("frobnicate", expect=2)
    p = run("--help")
    check("smooth" in p.stdout and "exit codes" in p.stdout, "--help answers")
    p = run("smooth", "--help")
    check("--fix" in p.stdout, "smooth --help lists options")
    # the parameter list comes from the library's table: every name, with
    # its default
    table = [ln.split()[0] for ln in p.stdout.split("parameters (--param")[1].splitlines()[1:] if ln.strip()]
    check(table[:3] == ["method", "max_iter", "tol"] and "finish" in table and
          "corner_guard" in table and "untangle" in table, f"--help parameter table: {table}")
    garbage = os.path.join(WORK, "garbage.msh")
    open(garbage, "w").write("$MeshFormat\nthis is not a mesh\n")
    p = subprocess.run([GETME, "smooth", garbage, "-o", garbage + "-out.msh"], capture_output=True, text=True)
    check(p.returncode in (4, 5), f"garbage input -> {p.returncode}, want 4 (malformed)")
    check(not os.path.exists(garbage + "-out.msh"), "no output for bad input")
    # An inverted element: swap the last two nodes of one tet (MSH 2.2 text:
    # "tag type ntags tags... nodes").
    good = os.path.join(WORK, "inv-src.msh")
    make("tet", good)
    lines = open(good).read().split("\n")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(good)
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    gmsh.write(good + ".v2.msh")
    gmsh.finalize()
    lines = open(good + ".v2.msh").read().split("\n")
    start = lines.index("$Elements") + 2
    tets = [i for i in range(start, len(lines)) if lines[i].split()[1:2] == ["4"]]
    victim = lines[tets[5]].split()
    victim[-1], victim[-2] = victim[-2], victim[-1]
    lines[tets[5]] = " ".join(victim)
    inv = os.path.join(WORK, "inverted.msh")
    open(inv, "w").write("\n".join(lines))
    tags = [[int(victim[0])] * 6]
    digest = sha(inv)
    if os.path.exists(inv + "-out.msh"):  # written by an earlier run
        os.remove(inv + "-out.msh")
    p = run("smooth", inv, "-o", inv + "-out.msh", "--no-untangle", expect=6)
    check("invalid" in p.stderr and str(tags[0][5]) in p.stderr,
          "inverted element reported by its Gmsh tag")
    check(sha(inv) == digest and not os.path.exists(inv + "-out.msh"), "input untouched, no output")
    # by default it is untangled first (issue #12), then smoothed
    p = run("smooth", inv, "-o", inv + "-out.msh")
    check("Warning : 1 invalid (inverted or degenerate) element in the input, 0 remain"
          in p.stdout, "untangling warning line")
    check(sha(inv) == digest and os.path.exists(inv + "-out.msh"), "input untouched, output written")
    run("quality", inv, expect=6)
    p = run("smooth", good, "-o", good, expect=2)
    check("overwrite" in p.stderr, "refuses to overwrite the input")


# ---- tangled inputs (issue #12): Abaqus decks written here, a 6^3 grid of
# C3D8 hexes (element ids from 101, node ids from 1001, so that file ids
# differ from indices) with interior nodes pushed through the opposite face
# of their cell: exit 0 with a warning giving the counts, every element
# valid by the independent mean ratio, skin bit-identical, 1 = 2 threads;
# --no-untangle exits 6; a hex whose nodes are all fixed (--fix on an NSET)
# turned inside out exits 8, named by its file id, no output unless
# --allow-invalid.
N, E0, N0 = 6, 101, 1001


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


def untangle_case():
    for name in os.listdir(WORK):  # outputs of an earlier run
        os.remove(os.path.join(WORK, name))
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


if CASE == "errors":
    errors_case()
elif CASE == "untangle":
    untangle_case()
else:
    mesh_case(CASE)
sys.exit(T.summary())
