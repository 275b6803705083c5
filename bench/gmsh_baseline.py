#!/usr/bin/python3
"""Run one of Gmsh's own mesh optimizers on a mesh file, in its own process.

  gmsh_baseline.py IN OUT --method NAME [--load-only]

NAME is a gmsh.model.mesh.optimize() method: "" (the default tet optimizer,
run with force=True so it also works on a mesh read from a file),
"Relocate3D", "Relocate2D", "Laplace2D", ...  Only the optimize() call is
timed.  --load-only opens and writes the mesh without optimizing: run under
/usr/bin/time it gives the memory baseline that the benchmark subtracts.
--create-geometry parametrizes the mesh's discrete entities first (needed
by the 2-D methods; not timed).  Prints one JSON line {"method", "seconds", "same_connectivity"} (the
connectivity compared in-process, nodes renumbered first because some
optimizers renumber them).
"""

import argparse
import json
import sys
import time


def connectivity():
    """Sorted node lists per element type: equal before and after iff the
    optimizer only moved nodes (element order and tags may change)."""
    import gmsh
    import numpy as np
    out = {}
    types, _, nodes = gmsh.model.mesh.getElements()
    for t, n in zip(types, nodes):
        nn = gmsh.model.mesh.getElementProperties(t)[3]
        c = np.asarray(n).reshape(-1, nn)
        out[int(t)] = c[np.lexsort(c.T[::-1])].tobytes()
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--method", default="")
    ap.add_argument("--niter", type=int, default=1)
    ap.add_argument("--load-only", action="store_true")
    ap.add_argument("--create-geometry", action="store_true",
                    help="parametrize the discrete entities first (2-D methods)")
    args = ap.parse_args()

    import gmsh
    gmsh.initialize(["gmsh_baseline"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.open(args.input)
        if args.create_geometry:
            # Relocate2D/Laplace2D work in the surface's (u, v) parameters; a
            # surface read from a mesh file has none, and without this they
            # either do nothing (Laplace2D) or scatter the nodes (Relocate2D).
            gmsh.model.mesh.createGeometry()
        # Some optimizers (Relocate3D) renumber the nodes: number them the
        # same way first, so that the connectivity before and after compares.
        gmsh.model.mesh.renumberNodes()
        before = connectivity()
        seconds = 0.0
        if not args.load_only:
            start = time.perf_counter()
            # force: the mesh comes from a file (discrete entities), which the
            # default optimizer otherwise skips
            gmsh.model.mesh.optimize(args.method, force=True, niter=args.niter)
            seconds = time.perf_counter() - start
        same = before == connectivity()
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(args.output)
    finally:
        gmsh.finalize()
    print(json.dumps({"method": args.method, "seconds": seconds,
                      "same_connectivity": same}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
