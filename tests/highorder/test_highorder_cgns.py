#!/usr/bin/python3
"""
test_highorder_cgns.py GETME CGNS_HO_WRITE WORKDIR -- second-order CGNS
(TETRA_10, HEXA_20, HEXA_27, PENTA_15, PENTA_18; docs/highorder.md).

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

GETME, WRITER, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(WORK, exist_ok=True)
FAILED = []

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
}
def check(cond, what):
    if not cond:
        FAILED.append(what)
        print("FAIL:", what, flush=True)


def path(name):
    return os.path.join(WORK, name)


def run(*args, threads=2):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads),
               OMP_WAIT_POLICY="passive")
    return subprocess.run([GETME] + list(args), capture_output=True,
                          text=True, env=env)


def generate(gtype, n=3):
    gmsh.clear()
    gmsh.model.add("m")
    if gtype == 11:
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
                          1 if gtype in (17, 18) else 0)
    gmsh.model.mesh.setOrder(2)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = {t: i for i, t in enumerate(tags.tolist())}
    _, conn = gmsh.model.mesh.getElementsByType(gtype)
    nv = len(TYPES[gtype][1])
    conn = np.array([index[t] for t in conn]).reshape(-1, nv)
    return np.array(xyz).reshape(-1, 3), conn


def write_cgns(gtype, xyz, conn, name):
    sids, perm, _ = TYPES[gtype]
    txt = path(name + ".txt")
    with open(txt, "w") as f:
        f.write("%d\n" % len(xyz))
        for p in xyz:
            f.write("%r %r %r\n" % tuple(p))
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
    sids, perm, _ = TYPES[gtype]
    xyz, conn = generate(gtype)
    src = write_cgns(gtype, xyz, conn, sids)
    m = vtk_of(src, sids)
    cells = np.concatenate([b.data for b in m.cells])
    nc = {11: 4, 17: 8, 12: 8, 18: 6, 13: 6}[gtype]
    check(np.array_equal(np.sort(cells, axis=1), np.sort(conn[:, :nc], axis=1)),
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
    skin = np.where((x0 == 0).any(1) | (x0 == 1).any(1))[0]
    inner = set(range(len(x0))) - set(skin.tolist())
    check(not np.array_equal(x1, x0) and not np.array_equal(x2, x1),
          "%s: distort and smooth move nodes" % sids)
    check(np.array_equal(x2[skin], x1[skin]),
          "%s: skin nodes bit-identical" % sids)
    coords = dict(enumerate(x2))
    err = ho_check.midpoint_errors(coords, {gtype: (None, conn)}, inner)
    check(err < 1e-12, "%s: smoothed interior mid-nodes at midpoints "
          "(worst %g)" % (sids, err))
    w, bad = ho_check.min_node_jacobian_arrays(x2, gtype, conn)
    check(bad == 0 and w > 0, "%s: min node det J %g" % (sids, w))
    print("%-8s ok: min node det J %.4g" % (sids, w), flush=True)


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
for t in (11, 17, 12, 18, 13):
    case(t)
gmsh.finalize()
print("%d failure(s)" % len(FAILED))
sys.exit(1 if FAILED else 0)
