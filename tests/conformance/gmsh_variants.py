#!/usr/bin/python3
"""gmsh_variants.py GEO OUTDIR [VARIANT...] -- mesh one of Gmsh's own .geo
demos in the variants the conformance sweep checks (conformance.py runs it
in a subprocess under a time limit, one per model, so that a model Gmsh
cannot mesh quickly costs seconds, not the sweep).

Variants (files OUTDIR/<variant>.<ext>):
  o1        first order, MSH 4.1 ASCII      o1-bin  MSH 4.1 binary
  o1-22     MSH 2.2 ASCII                   o1-inp  Abaqus INP (Gmsh's writer)
  o2        second order (tet10, tri6...)   o2-inp  second order, INP
  hex       all-hex/quad (recombination + subdivision), MSH 4.1
  hex20     hex20/quad8 (SecondOrderIncomplete), MSH 4.1
  hex27     hex27/quad9, MSH 4.1
(Debian's Gmsh writes no CGNS: conformance.py makes CGNS files with the
CGNS project's own converters, cgns_check.py.)
Volumes are meshed in 3D, otherwise surfaces in 2D. Prints one line:
'dim N nodes M elements' of the first-order mesh, or 'empty'."""
import os
import sys

import gmsh

GEO, OUT = sys.argv[1], sys.argv[2]
WANT = sys.argv[3:] or ["o1", "o1-bin", "o1-22", "o1-inp", "o2", "o2-inp",
                        "hex", "hex20", "hex27"]
os.makedirs(OUT, exist_ok=True)


def start(extra=()):
    gmsh.initialize(["gmsh_variants"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.open(GEO)
    # The demos' own sizes, bounded: a few thousand elements at most
    gmsh.option.setNumber("Mesh.MeshSizeFactor", 1.0)
    for k, v in extra:
        gmsh.option.setNumber(k, v)
    dim = 3 if gmsh.model.getEntities(3) else 2
    gmsh.model.mesh.generate(dim)
    return dim


def save(name, ext, opts=()):
    for k, v in opts:
        gmsh.option.setNumber(k, v)
    gmsh.write(os.path.join(OUT, name + "." + ext))


def count():
    _, tags, _ = gmsh.model.mesh.getElements()
    return sum(len(t) for t in tags)


dim = start()
nodes = len(gmsh.model.mesh.getNodes()[0])
if nodes == 0 or count() == 0:
    print("empty")
    sys.exit(0)
# Physical groups are kept as the .geo defines them; without any, Gmsh
# writes every element (Mesh.SaveAll) so that the file holds the whole mesh.
if not gmsh.model.getPhysicalGroups():
    gmsh.option.setNumber("Mesh.SaveAll", 1)
print("dim %d %d nodes %d elements" % (dim, nodes, count()), flush=True)
if "o1" in WANT:
    save("o1", "msh", [("Mesh.MshFileVersion", 4.1), ("Mesh.Binary", 0)])
if "o1-bin" in WANT:
    save("o1-bin", "msh", [("Mesh.MshFileVersion", 4.1), ("Mesh.Binary", 1)])
if "o1-22" in WANT:
    save("o1-22", "msh", [("Mesh.MshFileVersion", 2.2), ("Mesh.Binary", 0)])
if "o1-inp" in WANT:
    save("o1-inp", "inp")
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
if "o2" in WANT or "o2-inp" in WANT:
    gmsh.model.mesh.setOrder(2)
    if "o2" in WANT:
        save("o2", "msh")
    if "o2-inp" in WANT:
        save("o2-inp", "inp")
gmsh.finalize()
for name, incomplete in (("hex", None), ("hex20", 1), ("hex27", 0)):
    if name not in WANT:
        continue
    try:
        # Subdivision makes 4 hexes of a tet (with second-order nodes, many
        # more nodes): a coarser 3D mesh keeps it to seconds.
        start([("Mesh.MeshSizeFactor", 2.5 if dim == 3 else 1.0),
               ("Mesh.RecombineAll", 1),
               ("Mesh.SubdivisionAlgorithm", 2 if dim == 3 else 1)])
        if incomplete is not None:
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", incomplete)
            gmsh.model.mesh.setOrder(2)
        if not gmsh.model.getPhysicalGroups():
            gmsh.option.setNumber("Mesh.SaveAll", 1)
        save(name, "msh", [("Mesh.MshFileVersion", 4.1), ("Mesh.Binary", 0)])
    except Exception as e:      # e.g. extrusions that cannot be recombined
        print("variant failed: %s: %s" % (name, str(e).splitlines()[-1][:80]))
    gmsh.finalize()
