"""The conformance sweep's CGNS inputs and checks, made and judged by the
CGNS project's own tools (Debian's cgns-convert), not by getme's writer:
a first-order volume mesh (from Gmsh) goes through meshio's AFLR3 writer
and aflr3_to_cgns (HDF5, one zone, the boundary faces as a BC section),
then hdf2adf (ADF).  The smoothed file must differ from its input in
GridCoordinates data only (cgnsdiff -d), get cgnscheck's messages of the
input, keep the boundary faces' nodes bit for bit (read with h5py), and
convert with cgns_to_vtk into a file meshio reads with the input's cells
(what ParaView opens)."""
import os
import shutil
import subprocess

import h5py
import meshio
import numpy as np

VOLUME = ("tetra", "hexahedron", "wedge", "pyramid")
FACES = ("triangle", "quad")
TOOLS = ("aflr3_to_cgns", "hdf2adf", "cgnsdiff", "cgnscheck", "cgns_to_vtk")


def missing_tools():
    return [t for t in TOOLS if shutil.which(t) is None]


def make(msh, stem):
    """(stem.cgns (HDF5), stem-adf.cgns, boundary node indices) from MSH,
    or None when the mesh has no linear volume elements (AFLR3 holds tets,
    pyramids, prisms, hexes and their boundary triangles and quads)."""
    m = meshio.read(msh)
    by = {}
    for c in m.cells:
        if c.type in VOLUME + FACES:
            by.setdefault(c.type, []).append(c.data)
    if not any(t in by for t in VOLUME):
        return None
    cells = [(t, np.vstack(v)) for t, v in by.items()]
    used = np.unique(np.concatenate([c.ravel() for _, c in cells]))
    # AFLR3 numbers the nodes 1..n: keep only the used ones, in order
    renum = -np.ones(len(m.points), dtype=np.int64)
    renum[used] = np.arange(len(used))
    cells = [(t, renum[c]) for t, c in cells]
    meshio.write(stem + ".ugrid", meshio.Mesh(m.points[used], cells))
    for cmd in (["aflr3_to_cgns", "-f", stem + ".ugrid", stem + ".cgns"],
                ["hdf2adf", stem + ".cgns", stem + "-adf.cgns"]):
        subprocess.run(cmd, capture_output=True, check=True, timeout=60)
    faces = [c for t, c in cells if t in FACES]
    skin = np.unique(np.concatenate([f.ravel() for f in faces])) if faces else np.zeros(0, int)
    return stem + ".cgns", stem + "-adf.cgns", skin


def coords(path):
    with h5py.File(path, "r") as f:
        g = f["Base"]["Zone"]["GridCoordinates"]
        return np.stack([g["Coordinate" + a][" data"][()] for a in "XYZ"], axis=1)


def messages(path):
    p = subprocess.run(["cgnscheck", path], capture_output=True, text=True, timeout=60)
    return [ln for ln in (p.stdout + p.stderr).splitlines() if not ln.startswith("reading")]


def vtk_cells(path, work):
    os.makedirs(work, exist_ok=True)
    for f in os.listdir(work):
        os.remove(os.path.join(work, f))
    subprocess.run(["cgns_to_vtk", "-a", path, work], capture_output=True, timeout=60)
    vtks = sorted(f for f in os.listdir(work) if f.endswith(".vtk"))
    if not vtks:
        return None
    m = meshio.read(os.path.join(work, vtks[0]))
    return sorted((c.type, len(c.data)) for c in m.cells)


def compare(src, out, skin, hdf5):
    """'' or the first difference between a CGNS input and getme's output."""
    p = subprocess.run(["cgnsdiff", "-d", src, out], capture_output=True,
                       text=True, timeout=60)
    other = [ln for ln in p.stdout.splitlines()
             if ln.strip() and "/GridCoordinates/Coordinate" not in ln]
    if other:
        return "cgnsdiff: %s" % other[0][:120]
    if messages(src) != messages(out):
        return "cgnscheck says something else about the output"
    if hdf5:
        a, b = coords(src), coords(out)
        moved = np.nonzero((a[skin] != b[skin]).any(axis=1))[0]
        if len(moved):
            return "%d boundary-face nodes moved" % len(moved)
    ca = vtk_cells(src, out + ".vtk-in")
    cb = vtk_cells(out, out + ".vtk-out")
    if ca is None or ca != cb:
        return "cgns_to_vtk + meshio: cells %s -> %s" % (ca, cb)
    return ""
