#!/usr/bin/python3
"""GETMe adaptive next to Gmsh's own optimizers, through the Python API.

    PYTHONPATH=build/python /usr/bin/python3 examples/gmsh_api.py [--size H]
        [--distort] [-o out.msh]

Builds a flanged part with a bore and a pin (two materials) with
OpenCASCADE, meshes it with tetrahedra, and smooths the same mesh three
ways: getme.gmsh.optimize(), gmsh.model.mesh.optimize("") and
gmsh.model.mesh.optimize("Relocate3D"), reloading the saved mesh before
each.  --distort first applies random validity-preserving moves to the
interior (a hard case).  Prints q*min (worst element with a free node),
q_min, q_mean, element count and time for each.
"""
import argparse
import os
import tempfile
import time

import gmsh

import getme


def build(size):
    occ = gmsh.model.occ
    base = occ.addBox(0, 0, 0, 4, 2, 0.6)
    boss = occ.addCylinder(2, 1, 0, 0, 0, 1.6, 0.8)
    part = occ.fuse([(3, base)], [(3, boss)])[0]
    bore = occ.addCylinder(2, 1, -0.1, 0, 0, 1.8, 0.45)
    part = occ.cut(part, [(3, bore)])[0]
    pin = occ.addCylinder(2, 1, -0.1, 0, 0, 1.8, 0.45)
    occ.fragment(part, [(3, pin)])
    occ.synchronize()
    vols = [t for _, t in gmsh.model.getEntities(3)]
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, vols[:-1]),
                               "housing")
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, vols[-1:]),
                               "pin")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(3)


def row(name, before, q, n, seconds):
    print("%-26s %9s %8.4f %8.4f %8.4f %9d %8.2f"
          % (name, "%.4f" % before if before is not None else "-",
             q["q_min_star"], q["q_min"], q["q_mean"], n, seconds))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=0.12)
    ap.add_argument("--distort", action="store_true")
    ap.add_argument("-o", default="part-getme.msh")
    args = ap.parse_args()

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    build(args.size)
    if args.distort:
        getme.gmsh.distort(seed=1, amount=0.45, rounds=6)
    raw = os.path.join(tempfile.mkdtemp(), "part.msh")
    gmsh.write(raw)
    start = getme.quality()
    print("%-26s %9s %8s %8s %8s %9s %8s" % ("method", "q*min in", "q*min",
                                             "q_min", "q_mean", "elements",
                                             "seconds"))
    row("input", None, start, start["num_elements"], 0)

    res = getme.gmsh.optimize(log=0)
    q = getme.quality()
    row("getme.gmsh.optimize()", res["q_min_star_before"], q,
        q["num_elements"], res["seconds"])
    gmsh.write(args.o)

    for method in ("", "Relocate3D"):
        gmsh.model.remove()
        gmsh.open(raw)
        t = time.time()
        gmsh.model.mesh.optimize(method, force=True)
        seconds = time.time() - t
        q = getme.quality()
        row('optimize("%s")' % method, start["q_min_star"], q,
            q["num_elements"], seconds)
    print("GETMe result written to %s" % args.o)
    gmsh.finalize()


if __name__ == "__main__":
    main()
