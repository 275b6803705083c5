#!/usr/bin/python3
"""
test_highorder_cgns.py GETME CGNS_HO_WRITE WORKDIR -- second-order CGNS
(TETRA_10, HEXA_20, HEXA_27, PENTA_15, PENTA_18, PYRA_13, PYRA_14 with
TETRA_10 and HEXA_20/27 in one zone; docs/highorder.md).

Gmsh meshes a cube at order 2; the test writes it as CGNS with libcgns
(cgns_ho_write) in the SIDS node order (TYPES below, from the SIDS
element conventions: edges around the bottom, vertical, around the top;
faces F1..F6 of SIDS).  No tool on this machine writes or reads
second-order CGNS with its mid-nodes (Gmsh is built without CGNS, meshio
writes tetrahedra only, the CGNS project's cgns_to_vtk writes the corner
cells only), so the independent checks are: cgns_to_vtk opens every file
and its (linear) cells are our corners; and getme, whose table
(formats/cgns_highorder.c) was written separately, puts every interior
mid-node of the smoothed mesh at the midpoint of the corners the SIDS
table names (a disagreement between the two tables fails this).
Then, per type: det J > 0 at every node (Gmsh's getJacobians), skin nodes
bit-identical, 1 = 2 threads byte for byte.
"""
import os
import subprocess
import sys

import gmsh
import h5py
import meshio
import numpy as np

import ho_check
from checks import WorkChecks

GETME, WRITER, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
W = WorkChecks(GETME, WORK)
FAILED = W.failed
check, path, run = W.check, W.path, W.run

# Gmsh type -> (SIDS name, CGNS node i is Gmsh's node perm[i], meshio's
# name of the VTK cell)
TYPES = {
    11: ("TETRA_10", [0, 1, 2, 3, 4, 5, 6, 7, 9, 8], "tetra10"),
    17: ("HEXA_20", [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 10, 12, 14, 15,
                     16, 18, 19, 17], "hexahedron20"),
    12: ("HEXA_27", [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 10, 12, 14, 15,
                     16, 18, 19, 17, 20, 21, 23, 24, 22, 25, 26],
         "hexahedron27"),
    18: ("PENTA_15", [0, 1, 2, 3, 4, 5, 6, 9, 7, 8, 10, 11, 12, 14, 13],
         "wedge15"),
    13: ("PENTA_18", [0, 1, 2, 3, 4, 5, 6, 9, 7, 8, 10, 11, 12, 14, 13, 15,
                      17, 16], "wedge18"),
    # SIDS pyramid: base edges 1-2, 2-3, 3-4, 4-1, then 1-5, 2-5, 3-5, 4-5,
    # then (PYRA_14) the base centre
    19: ("PYRA_13", [0, 1, 2, 3, 4, 5, 8, 10, 6, 7, 9, 11, 12], "pyramid13"),
    14: ("PYRA_14", [0, 1, 2, 3, 4, 5, 8, 10, 6, 7, 9, 11, 12, 13],
         "pyramid14"),
}
NC = {11: 4, 17: 8, 12: 8, 18: 6, 13: 6, 19: 5, 14: 5}
def generate(gtype, n=3):
    """Nodes and {Gmsh type: 0-based connectivity} of every 3-D type in
    the mesh.  Pyramids: a hex block [0,1]^3 and a tet block [1,2]x[0,1]^2
    sharing its quad face, so Gmsh makes pyramids there (and tets, hexes)."""
    gmsh.clear()
    gmsh.model.add("m")
    if gtype in (19, 14):
        geo = gmsh.model.geo
        p = geo.addPoint(0, 0, 0)
        ln = geo.extrude([(0, p)], 1, 0, 0, [n], recombine=True)
        s = geo.extrude([ln[1]], 0, 1, 0, [n], recombine=True)
        v = geo.extrude([s[1]], 0, 0, 1, [n], recombine=True)
        geo.extrude([[e for e in v if e[0] == 2][2]], 1, 0, 0)
        geo.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0 / n)
    elif gtype == 11:
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0 / n)
    else:
        geo = gmsh.model.geo
        p = geo.addPoint(0, 0, 0)
        ln = geo.extrude([(0, p)], 1, 0, 0, [n], recombine=True)
        s = geo.extrude([ln[1]], 0, 1, 0, [n], recombine=gtype in (12, 17))
        geo.extrude([s[1]], 0, 0, 1, [n], recombine=True)
        geo.synchronize()
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete",
                          1 if gtype in (17, 18, 19) else 0)
    gmsh.model.mesh.setOrder(2)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = {t: i for i, t in enumerate(tags.tolist())}
    conns = {}
    for t in gmsh.model.mesh.getElementTypes(3):
        _, conn = gmsh.model.mesh.getElementsByType(t)
        nv = len(TYPES[t][1])
        conns[t] = np.array([index[k] for k in conn]).reshape(-1, nv)
    return np.array(xyz).reshape(-1, 3), conns


def write_cgns(conns, xyz, name):
    txt = path(name + ".txt")
    with open(txt, "w") as f:
        f.write("%d\n" % len(xyz))
        for p in xyz:
            f.write("%r %r %r\n" % tuple(p))
        for gtype, conn in conns.items():
            sids, perm, _ = TYPES[gtype]
            f.write("%s %d %d\n" % (sids, len(conn), len(perm)))
            for row in conn:
                f.write(" ".join(str(row[g] + 1) for g in perm) + "\n")
    out = path(name + ".cgns")
    r = subprocess.run([WRITER, txt, out], capture_output=True, text=True)
    check(r.returncode == 0, "%s: cgns_ho_write %s" % (name, r.stderr))
    return out


def vtk_of(cgns, name):
    """cgns_to_vtk (CGNS project), then meshio reads its VTK file."""
    d = path(name + "-vtk")
    os.makedirs(d, exist_ok=True)
    r = subprocess.run(["cgns_to_vtk", "-a", cgns, d], capture_output=True,
                       text=True)
    check(r.returncode == 0, "%s: cgns_to_vtk %s" % (name, r.stderr))
    files = [f for f in os.listdir(d) if f.endswith(".vtk")]
    check(len(files) == 1, "%s: one VTK file (%s)" % (name, files))
    m = meshio.read(os.path.join(d, files[0]))
    return m


def cgns_coords(f):
    with h5py.File(f, "r") as h:
        g = h["Base"]["Zone"]["GridCoordinates"]
        return np.stack([g["Coordinate" + a][" data"][()] for a in "XYZ"], 1)


def case(gtype):
    sids = TYPES[gtype][0]
    xyz, conns = generate(gtype)
    check(gtype in conns, "%s: Gmsh made the type (%s)" % (sids, list(conns)))
    src = write_cgns(conns, xyz, sids)
    m = vtk_of(src, sids)
    # cgns_to_vtk writes no cell for a PYRA_13 (it knows PYRA_14): its
    # limitation, so PYRA_13's corners are checked through PYRA_14's run
    ours = sorted(tuple(sorted(r[:NC[t]])) for t, c in conns.items()
                  if t != 19 for r in c.tolist())
    theirs = sorted(tuple(sorted(r)) for b in m.cells for r in b.data.tolist())
    check(ours == theirs,
          "%s: cgns_to_vtk reads the file, its cells are our corners" % sids)
    dis, o1, o2 = path(sids + "-d.cgns"), path(sids + "-s1.cgns"), path(sids + "-s2.cgns")
    r = run("distort", src, "-o", dis, "--seed", "2", "--target-qmean", "0.55")
    check(r.returncode == 0, "%s: distort %s" % (sids, r.stderr))
    r1 = run("smooth", dis, "-o", o1, threads=1)
    r2 = run("smooth", dis, "-o", o2, threads=2)
    check(r1.returncode == 0 and r2.returncode == 0,
          "%s: smooth %s" % (sids, r1.stderr[-300:]))
    x0, x1, x2 = cgns_coords(src), cgns_coords(dis), cgns_coords(o1)
    check(np.array_equal(x0, xyz), "%s: coordinates as written" % sids)
    check(np.array_equal(x2, cgns_coords(o2)), "%s: 1 = 2 threads" % sids)
    skin = np.where((x0 == x0.min(0)).any(1) | (x0 == x0.max(0)).any(1))[0]
    inner = set(range(len(x0))) - set(skin.tolist())
    check(not np.array_equal(x1, x0) and not np.array_equal(x2, x1),
          "%s: distort and smooth move nodes" % sids)
    check(np.array_equal(x2[skin], x1[skin]),
          "%s: skin nodes bit-identical" % sids)
    coords = dict(enumerate(x2))
    err = ho_check.midpoint_errors(
        coords, {t: (None, c) for t, c in conns.items()}, inner)
    check(err < 1e-12, "%s: smoothed interior mid-nodes at midpoints "
          "(worst %g)" % (sids, err))
    w = np.inf
    for t, c in conns.items():
        wt, bad = ho_check.min_node_jacobian_arrays(x2, t, c)
        check(bad == 0 and wt > 0, "%s: min node det J %g (type %d)"
              % (sids, wt, t))
        w = min(w, wt)
    print("%-8s ok: min node det J %.4g" % (sids, w), flush=True)


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
for t in (11, 17, 12, 18, 13, 19, 14):
    case(t)
gmsh.finalize()
print("%d failure(s)" % len(FAILED))
sys.exit(1 if FAILED else 0)
