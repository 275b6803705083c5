#!/usr/bin/python3
"""CGNS adapter against files written and read by other tools.

usage: test_cgns_interop.py CGNS_TOOL WORKDIR

1. Node order.  A hybrid mesh (hex, tet, pyramid, prism) made by Gmsh is
   written by meshio as AFLR3 .ugrid and converted to CGNS by the CGNS
   project's own aflr3_to_cgns.  The CGNS connectivity (read with h5py) is
   Gmsh's, node for node (pyramids: the same base cycle, possibly started at
   another corner), and the adapter finds every element valid: CGNS
   TETRA_4/PYRA_5/PENTA_6/HEXA_8 order is getme's (= Gmsh's).
2. The smoothed output converts with cgns_to_vtk, and meshio reads that VTK
   file with our coordinates and the input's cells, all positively oriented.
3. meshio's own CGNS reader reads a smoothed Base/Zone1/GridElements file:
   its points are the ones we wrote, the input's fixed nodes unchanged.
4. meshio's CGNS writer omits the CGNS node attributes (libcgns cannot open
   its files): the adapter refuses with one clear line, status 4, leaving
   the input as it was and writing nothing.
"""
import os
import subprocess
import sys

import gmsh
import h5py
import meshio
import numpy as np

# the bundled CGNS example's model (examples/cgns/make_example.py), coarser
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "..", "examples", "cgns"))
from make_example import hybrid_geometry  # noqa: E402

TOOL, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def run(*args):
    return subprocess.run([TOOL, *args], capture_output=True, text=True)


def path(name):
    return os.path.join(WORK, name)


def hybrid_mesh(msh):
    """Hex block, tet blocks (with pyramids where they meet the hexes) and
    an extruded prism cylinder."""
    hybrid_geometry(size=0.34, edge_nodes=4, layers=3)
    gmsh.model.mesh.generate(3)
    tags, _, _ = gmsh.model.mesh.getNodes()
    index = {int(t): i for i, t in enumerate(tags)}
    elems = {}
    for gtype, nv in ((4, 4), (5, 8), (6, 6), (7, 5)):
        _, ntags = gmsh.model.mesh.getElementsByType(gtype)
        elems[nv] = [tuple(index[int(t)] for t in row)
                     for row in np.asarray(ntags).reshape(-1, nv)]
    gmsh.write(msh)
    gmsh.finalize()
    return elems


def cgns_sections(f, zone):
    out = {}
    for name, sec in zone.items():
        if isinstance(sec, h5py.Group) and "ElementConnectivity" in sec:
            etype = int(sec[" data"][0])
            out[etype] = np.asarray(sec["ElementConnectivity"][" data"]) - 1
    return out


def test_node_order():
    msh, ugrid, cg = path("hyb.msh"), path("hyb.ugrid"), path("hyb.cgns")
    gm = hybrid_mesh(msh)
    m = meshio.read(msh)
    blocks = {}
    for c in m.cells:
        if c.type in ("tetra", "pyramid", "wedge", "hexahedron"):
            blocks.setdefault(c.type, []).append(c.data)
    meshio.write(ugrid, meshio.Mesh(m.points, [(k, np.vstack(v))
                                               for k, v in blocks.items()]))
    r = subprocess.run(["aflr3_to_cgns", "-f", ugrid, cg], capture_output=True,
                       text=True)
    check(r.returncode == 0, "aflr3_to_cgns converts the meshio .ugrid")
    f = h5py.File(cg, "r")
    zone = f["Base"]["Zone"]
    secs = cgns_sections(f, zone)
    # CGNS ElementType_t: TETRA_4 10, PYRA_5 12, PENTA_6 14, HEXA_8 17
    for etype, nv, name in ((10, 4, "TETRA_4"), (17, 8, "HEXA_8"),
                            (14, 6, "PENTA_6")):
        rows = set(map(tuple, secs[etype].reshape(-1, nv).tolist()))
        check(len(rows) == len(gm[nv]) > 0 and rows == set(gm[nv]),
              f"{name}: {len(rows)} elements, node order identical to Gmsh's")
    pyr = secs[12].reshape(-1, 5).tolist()
    gmp = {frozenset(p): p for p in gm[5]}
    same = 0
    for p in pyr:
        g = gmp.get(frozenset(p))
        if g and g[4] == p[4]:
            base, gbase = p[:4], list(g[:4])
            same += any(base == gbase[s:] + gbase[:s] for s in range(4))
    check(same == len(pyr) == len(gm[5]) > 0,
          f"PYRA_5: {same} pyramids, same apex and base cycle as Gmsh's")
    r = run("dump", cg)
    check(r.returncode == 0, "adapter reads the aflr3_to_cgns file")
    q = [float(line.split()[2]) for line in r.stdout.splitlines()
         if line.startswith("q ")]
    total = sum(len(v) for v in gm.values())
    check(len(q) == total and min(q) > 0.0,
          f"all {len(q)} elements valid through the adapter "
          f"(min quality {min(q):.3f})")
    return cg, total


def vtk_cells_positive(mesh):
    """Signed volume of tets/hexes of a VTK-ordered meshio mesh (VTK tet and
    hex orders are Gmsh's)."""
    p = mesh.points
    ok = True
    for c in mesh.cells:
        if c.type == "tetra":
            a, b, cc, d = (p[c.data[:, k]] for k in range(4))
            ok &= bool(np.all(np.einsum("ij,ij->i", np.cross(b - a, cc - a),
                                        d - a) > 0))
        if c.type == "hexahedron":
            a, b, d, e = (p[c.data[:, k]] for k in (0, 1, 3, 4))
            ok &= bool(np.all(np.einsum("ij,ij->i", np.cross(b - a, d - a),
                                        e - a) > 0))
    return ok


def test_vtk_chain(cg, total):
    out = path("hyb-smooth.cgns")
    r = run("smooth", cg, out)
    check(r.returncode == 0, "smooth the aflr3_to_cgns file: " + r.stdout.strip())
    vdir = path("vtk")
    os.makedirs(vdir, exist_ok=True)
    r = subprocess.run(["cgns_to_vtk", "-a", out, vdir], capture_output=True,
                       text=True)
    check(r.returncode == 0, "cgns_to_vtk converts the output")
    vm = meshio.read(os.path.join(vdir, "Zone.vtk"))
    z = h5py.File(out, "r")["Base"]["Zone"]["GridCoordinates"]
    pts = np.column_stack([z[c][" data"][()] for c in
                           ("CoordinateX", "CoordinateY", "CoordinateZ")])
    zin = h5py.File(cg, "r")["Base"]["Zone"]["GridCoordinates"]
    pin = np.column_stack([zin[c][" data"][()] for c in
                           ("CoordinateX", "CoordinateY", "CoordinateZ")])
    # cgns_to_vtk -a prints 6 significant digits; smoothing moved nodes by
    # far more than that
    check(np.abs(vm.points - pts).max() < 1e-5 and
          np.abs(vm.points - pin).max() > 1e-3,
          "meshio reads the VTK conversion with our (moved) coordinates")
    check(vtk_cells_positive(vm), "tets and hexes positively oriented there")
    ncells = sum(len(c.data) for c in vm.cells)
    check(ncells == total, f"{ncells} cells in the VTK conversion")


def test_meshio_reader():
    src, out = path("zone1.cgns"), path("zone1-smooth.cgns")
    r = run("fixture", src)
    check(r.returncode == 0, "write Base/Zone1/GridElements fixture")
    before = meshio.read(src)
    r = run("smooth", src, out)
    check(r.returncode == 0, "smooth it: " + r.stdout.strip())
    after = meshio.read(out)
    z = h5py.File(out, "r")["Base"]["Zone1"]["GridCoordinates"]
    pts = np.column_stack([z[c][" data"][()] for c in
                           ("CoordinateX", "CoordinateY", "CoordinateZ")])
    check(np.array_equal(after.points, pts), "meshio reads our coordinates")
    check(np.array_equal(after.cells[0].data, before.cells[0].data),
          "meshio reads the input's cells")
    moved = np.any(after.points != before.points, axis=1)
    skin = np.any((before.points == before.points.min(axis=0)) |
                  (before.points == before.points.max(axis=0)), axis=1)
    check(not np.any(moved & skin) and np.count_nonzero(moved) == 8,
          f"{np.count_nonzero(moved)} interior nodes moved, skin unchanged")
    check(vtk_cells_positive(after), "all tets positive after smoothing")


def test_meshio_writer():
    bad, out = path("meshio.cgns"), path("meshio-smooth.cgns")
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    meshio.write(bad, meshio.Mesh(pts, [("tetra", np.array([[0, 1, 2, 3]]))]))
    data = open(bad, "rb").read()
    r = run("smooth", bad, out)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 4, f"meshio-written file refused with status 4 "
                             f"(got {r.returncode})")
    check(len(lines) == 1 and lines[0].startswith("Error   : ") and
          bad in lines[0] and "meshio" in lines[0],
          "one error line naming the file: " + (lines[0] if lines else ""))
    check(open(bad, "rb").read() == data and not os.path.exists(out),
          "input untouched, no output")


def test_damaged(cg):
    """libcgns prints nothing of its own: one line from us, status 4."""
    data = open(cg, "rb").read()
    bad, out = path("cut.cgns"), path("cut-smooth.cgns")
    open(bad, "wb").write(data[: len(data) // 2])
    r = run("smooth", bad, out)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 4 and len(lines) == 1 and r.stdout == "" and
          lines[0].startswith("Error   : " + bad + ": libcgns cannot read"),
          "truncated HDF5 file: one error line, status 4: " +
          (lines[0] if lines else ""))
    check(not os.path.exists(out), "no output for the truncated file")


cg, total = test_node_order()
test_damaged(cg)
test_vtk_chain(cg, total)
test_meshio_reader()
test_meshio_writer()
print(f"test_cgns_interop: {len(failures)} failed")
sys.exit(1 if failures else 0)
