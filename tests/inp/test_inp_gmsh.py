#!/usr/bin/python3
"""Decks written by other tools through `getme`: Gmsh's INP writer (tets in
two volumes, hexes) and meshio's.

Checks, with numpy and meshio only (independent of getme's code):
  - node order: every C3D4 / C3D8 element Gmsh and meshio write has positive
    node-simplex determinants in getme's convention (paper Fig. 1), and
    getme accepts them all as valid;
  - distort + smooth through the CLI: every line that differs between the
    distorted and the smoothed deck is a *NODE data line of the same node;
    skin and volume-interface nodes are byte-identical; no element inverted;
    q_mean and q_min improve;
  - --free-interfaces lets interface nodes move.
usage: test_inp_gmsh.py GETME_CLI WORKDIR
"""
import os
import subprocess
import sys

import gmsh
import meshio
import numpy as np

GETME, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)
failures = []
passed = 0


def check(cond, what):
    global passed
    if cond:
        passed += 1
    else:
        failures.append(what)
        print("FAILED:", what)


def run(*args, expect=0):
    r = subprocess.run([GETME, *args], capture_output=True, text=True)
    check(r.returncode == expect,
          f"getme {' '.join(args)} -> {r.returncode}: {r.stderr.strip()}")
    return r


W_TET = np.array([[1, 0.5, 0.5], [0, np.sqrt(3) / 2, np.sqrt(3) / 6],
                  [0, 0, np.sqrt(2.0 / 3.0)]])
HEX_SIMPLICES = [(0, 3, 4, 1), (1, 0, 5, 2), (2, 1, 6, 3), (3, 2, 7, 0),
                 (4, 7, 5, 0), (5, 4, 6, 1), (6, 5, 7, 2), (7, 6, 4, 3)]


def simplex_q(p, idx, winv):
    """Mean ratio of the node simplices idx (k, 4) of elements p (n, v, 3)."""
    d = np.stack([p[:, idx[1]] - p[:, idx[0]], p[:, idx[2]] - p[:, idx[0]],
                  p[:, idx[3]] - p[:, idx[0]]], axis=2)  # columns: edges
    s = d @ winv
    det = np.linalg.det(s)
    fro = np.einsum("nij,nij->n", s, s)
    q = np.where(det > 0, 3 * np.cbrt(np.maximum(det, 0)) ** 2 / fro, 0.0)
    return det, q


def tet_quality(pts, cells):
    det, q = simplex_q(pts[cells], (0, 1, 2, 3), np.linalg.inv(W_TET))
    return det, q


def hex_quality(pts, cells):
    p = pts[cells]
    dets, qs = [], []
    for s in HEX_SIMPLICES:
        det, q = simplex_q(p, s, np.eye(3))
        dets.append(det)
        qs.append(q)
    dets = np.array(dets)
    return dets.min(axis=0), np.where(dets.min(axis=0) > 0,
                                      np.mean(qs, axis=0), 0)


def gmsh_decks():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("boxes")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.addBox(1, 0, 0, 1, 1, 1)
    gmsh.model.occ.fragment([(3, 1)], [(3, 2)])
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
    gmsh.model.mesh.generate(3)
    # without physical groups Gmsh writes every element: T3D2 edges, CPS3
    # faces (also on the interface between the volumes) and the C3D4 tets
    gmsh.write(os.path.join(WORK, "tets-all.inp"))
    for v in (1, 2):
        gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [v]),
                                   f"Vol{v}")
    gmsh.write(os.path.join(WORK, "tets.inp"))
    gmsh.clear()
    gmsh.model.add("hexes")
    gmsh.model.occ.addBox(0, 0, 0, 2, 1, 1)
    gmsh.model.occ.synchronize()
    for c in gmsh.model.getEntities(1):
        gmsh.model.mesh.setTransfiniteCurve(c[1], 6)
    for s in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(s[1])
        gmsh.model.mesh.setRecombine(2, s[1])
    gmsh.model.mesh.setTransfiniteVolume(1)
    gmsh.model.mesh.generate(3)
    gmsh.write(os.path.join(WORK, "hexes.inp"))
    gmsh.finalize()


def node_lines(path):
    """{node id: raw line bytes} of the *NODE blocks, and all lines."""
    lines = open(path, "rb").read().splitlines(keepends=True)
    nodes, in_node = {}, False
    for ln in lines:
        s = ln.strip()
        if s.startswith(b"**") or not s:
            continue
        if s.startswith(b"*"):
            in_node = s.split(b",")[0].replace(b" ", b"").upper() == b"*NODE"
            continue
        if in_node:
            nodes[int(s.split(b",")[0])] = ln
    return nodes, lines


def read_elsets(path):
    """Tet id -> the ELSET named on its *ELEMENT line (Gmsh volumes)."""
    owner, cur = {}, None
    for ln in open(path):
        s = ln.strip()
        if s.startswith("*"):
            kw = [t.strip() for t in s.split(",")]
            cur = None
            if kw[0].upper() == "*ELEMENT" and any(
                    t.replace(" ", "").upper() == "TYPE=C3D4" for t in kw):
                for t in kw[1:]:
                    if t.upper().startswith("ELSET="):
                        cur = t.split("=", 1)[1]
            continue
        if cur and s:
            owner[int(s.split(",")[0])] = cur
    return owner


def fixed_nodes(cells, region):
    """Skin and interface nodes (row indices), from the faces' counts."""
    faces = np.sort(np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 1, 3]],
                                    cells[:, [0, 2, 3]], cells[:, [1, 2, 3]]]),
                    axis=1)
    reg = np.tile(region, 4)
    uniq, inv, cnt = np.unique(faces, axis=0, return_inverse=True,
                               return_counts=True)
    inv = inv.ravel()
    skin = uniq[cnt == 1]
    rmin = np.full(len(uniq), 1 << 30)
    rmax = np.full(len(uniq), -1)
    np.minimum.at(rmin, inv, reg)
    np.maximum.at(rmax, inv, reg)
    iface = uniq[(cnt == 2) & (rmin != rmax)]
    return set(skin.ravel().tolist()), set(iface.ravel().tolist())


def test_orientation():
    for name in ("tets.inp", "hexes.inp"):
        m = meshio.read(os.path.join(WORK, name))
        pts = m.points
        if name == "tets.inp":
            det, q = tet_quality(pts, m.cells_dict["tetra"])
        else:
            det, q = hex_quality(pts, m.cells_dict["hexahedron"])
        check(det.min() > 0, f"{name}: all Gmsh elements positive in getme's "
                             f"node order (min det {det.min():.3g})")
        r = run("quality", os.path.join(WORK, name))
        check(", 0 invalid" in r.stdout + r.stderr,
              f"getme finds no invalid element in Gmsh's {name}")
        # meshio's own INP writer: same order, getme accepts it
        out = os.path.join(WORK, "meshio-" + name)
        meshio.write(out, m)
        r = run("quality", out)
        check(", 0 invalid" in r.stdout + r.stderr,
              f"getme finds no invalid element in meshio's {name}")


def test_smooth(name):
    src = os.path.join(WORK, name + ".inp")
    dist = os.path.join(WORK, name + "-d.inp")
    smooth = os.path.join(WORK, name + "-s.inp")
    run("distort", src, "-o", dist, "--seed", "5", "--amount", "0.4", "-q")
    run("smooth", dist, "-o", smooth, "-q")
    nd, ld = node_lines(dist)
    ns, ls = node_lines(smooth)
    check(len(ld) == len(ls), "same number of lines")
    node_set = set(nd.values())
    other_diff = sum(1 for a, b in zip(ld, ls) if a != b and a not in node_set)
    check(other_diff == 0, f"{other_diff} non-node lines differ")
    moved = [i for i in nd if nd[i] != ns[i]]
    check(len(moved) > 50, f"{len(moved)} nodes moved")

    md, ms = meshio.read(dist), meshio.read(smooth)
    cells = md.cells_dict["tetra"]
    # meshio keeps file order: map rows back to node ids for the text check
    ids = sorted(nd)
    owner = read_elsets(dist)
    elem_ids = sorted(owner)
    names = sorted(set(owner.values()))
    region = np.array([names.index(owner[e]) for e in elem_ids])
    skin, iface = fixed_nodes(cells, region)
    check(len(iface) > 20, f"{len(iface)} interface nodes between volumes")
    bad = [r for r in skin | iface if nd[ids[r]] != ns[ids[r]]]
    check(not bad, f"{len(bad)} skin/interface node lines changed")
    _, qd = tet_quality(md.points, cells)
    _, qs = tet_quality(ms.points, cells)
    check(qs.min() > 0, f"no inverted element (min q {qs.min():.4f})")
    check(qs.mean() > qd.mean(), f"q_mean {qd.mean():.4f} -> {qs.mean():.4f}")
    check(qs.min() > qd.min(), f"q_min {qd.min():.4f} -> {qs.min():.4f}")
    print(f"{name}: {len(cells)} elements, {len(moved)} node lines rewritten, "
          f"q_min {qd.min():.4f} -> {qs.min():.4f}, "
          f"q_mean {qd.mean():.4f} -> {qs.mean():.4f}")

    if name != "tets":
        return
    free = os.path.join(WORK, "tets-f.inp")
    run("smooth", dist, "-o", free, "-q", "--free-interfaces")
    nf, _ = node_lines(free)
    moved_iface = [r for r in iface - skin if nd[ids[r]] != nf[ids[r]]]
    check(len(moved_iface) > 0, "--free-interfaces moves interface nodes")
    check(all(nd[ids[r]] == nf[ids[r]] for r in skin), "skin still fixed")


def test_errors():
    # C3D10/C3D15/C3D20 are smoothed (tests/highorder); C3D13 is not
    bad = os.path.join(WORK, "c3d13.inp")
    with open(bad, "w") as f:
        f.write("*NODE\n1,0,0,0\n*ELEMENT, TYPE=C3D13\n"
                "1,1,1,1,1,1,1,1,1,1,1,1,1,1\n")
    r = run("smooth", bad, "-o", os.path.join(WORK, "x.inp"), expect=5)
    check("c3d13.inp:3: element type C3D13 is second order" in r.stderr,
          "second-order message names file, line and type: " + r.stderr)
    check(not os.path.exists(os.path.join(WORK, "x.inp")), "no output")
    r = run("smooth", os.path.join(WORK, "tets.inp"), "-o",
            os.path.join(WORK, "y.inp"), "--fix", "nosuch", expect=2)
    check("nosuch" in r.stderr, "unknown set named")


gmsh_decks()
test_orientation()
test_smooth("tets-all")
test_smooth("tets")
test_errors()
print(f"test_inp_gmsh: {passed} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
