#!/usr/bin/python3
"""Cantilever beam: Gmsh -> INP -> getme distort -> getme smooth -> CalculiX.

A steel beam L x b x h, clamped at x = 0, with a transverse tip load P,
meshed with structured hexahedra (C3D8I, incompatible modes: exact in pure
bending on a regular mesh, sensitive to distorted elements).  The mesh goes
into mesh.inp, included from the analysis deck; the deck is distorted with
`getme distort`, smoothed with `getme smooth`, and all three decks are run
through `ccx`.  The tip deflection of each is compared with Timoshenko beam
theory (Euler-Bernoulli plus shear).

usage: cantilever.py [--getme PATH] [--ccx PATH] [--workdir DIR] [--small]
                     [--check]
  --small   a coarse mesh (for the test suite)
  --check   exit 1 unless the smoothed deck's error is below the distorted one
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

import gmsh

L, B, H = 100.0, 10.0, 10.0         # mm
E, NU, P = 210000.0, 0.3, -1000.0   # MPa, -, N (in z)


def analytic_tip():
    inertia = B * H ** 3 / 12.0
    shear = E / (2 * (1 + NU))
    return P * L ** 3 / (3 * E * inertia) + P * L / (5.0 / 6.0 * shear * B * H)


def mesh(path, nx, nyz):
    """Structured hex mesh of the beam; returns (fixed end, tip) node ids."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("beam")
    gmsh.model.occ.addBox(0, 0, 0, L, B, H)
    gmsh.model.occ.synchronize()
    for _, c in gmsh.model.getEntities(1):
        xmin, _, _, xmax, _, _ = gmsh.model.getBoundingBox(1, c)
        gmsh.model.mesh.setTransfiniteCurve(c, (nx if xmax - xmin > 1.0
                                                else nyz) + 1)
    for _, s in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
    gmsh.model.mesh.setTransfiniteVolume(1)
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [1]), "Beam")
    gmsh.model.mesh.generate(3)
    gmsh.write(path)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    gmsh.finalize()
    x, y, z = xyz[0::3], xyz[1::3], xyz[2::3]
    end = [i for i in range(len(tags)) if abs(x[i]) < 1e-9]
    # A clamp that lets the end section contract (Poisson) as beam theory
    # assumes: all end nodes held in x, the mid-height line in z, the
    # centre node in y.  nyz is even, so these nodes exist.
    fixed = {"FixedX": [int(tags[i]) for i in end],
             "FixedZ": [int(tags[i]) for i in end if abs(z[i] - H / 2) < 1e-6],
             "FixedY": [int(tags[i]) for i in end
                        if abs(z[i] - H / 2) < 1e-6 and abs(y[i] - B / 2) < 1e-6]}
    tip = [int(t) for t, v in zip(tags, x) if abs(v - L) < 1e-9]
    # linear hexes with incompatible modes: same nodes, better bending
    text = open(path).read()
    text = re.sub(r"type=C3D8\b", "type=C3D8I", text)
    # ccx allows one *HEADING per deck: the analysis deck has it
    text = re.sub(r"^\*Heading\n[^\n]*\n", "", text)
    open(path, "w").write(text)
    return fixed, tip


def node_list(ids):
    return "\n".join(", ".join(str(i) for i in ids[k:k + 10])
                     for k in range(0, len(ids), 10))


def analysis_deck(path, fixed, tip):
    with open(path, "w") as f:
        f.write("*HEADING\nCantilever: getme + CalculiX example\n"
                "*INCLUDE, INPUT=mesh.inp\n")
        for name, ids in fixed.items():
            f.write(f"*NSET, NSET={name}\n{node_list(ids)}\n")
        f.write(f"*NSET, NSET=Tip\n{node_list(tip)}\n"
                f"*MATERIAL, NAME=Steel\n*ELASTIC\n{E}, {NU}\n"
                "*SOLID SECTION, ELSET=Beam, MATERIAL=Steel\n"
                "*STEP\n*STATIC\n*BOUNDARY\nFixedX, 1\nFixedY, 2\n"
                "FixedZ, 3\n*CLOAD\n")
        for n in tip:
            f.write(f"{n}, 3, {P / len(tip)!r}\n")
        f.write("*NODE PRINT, NSET=Tip\nU\n*END STEP\n")


def run(cmd, cwd):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"Error   : {' '.join(cmd)} failed ({r.returncode}):\n"
                 f"{r.stdout[-2000:]}{r.stderr[-2000:]}")
    return r


def tip_deflection(ccx, workdir, job):
    """Mean z displacement of the tip nodes from ccx's .dat file."""
    run([ccx, "-i", job], workdir)
    uz = []
    in_block = False
    for line in open(os.path.join(workdir, job + ".dat")):
        if "displacements" in line:
            in_block = True
            continue
        parts = line.split()
        if in_block and len(parts) == 4:
            uz.append(float(parts[3]))
    return sum(uz) / len(uz)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--getme", default=shutil.which("getme") or "getme")
    ap.add_argument("--ccx", default=shutil.which("ccx") or "ccx")
    ap.add_argument("--workdir", default="cantilever-run")
    ap.add_argument("--small", action="store_true")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    wd = os.path.abspath(a.workdir)
    nx, nyz = (20, 4) if a.small else (50, 6)
    fixed, tip = mesh(os.path.join(wd, "mesh.inp"), nx, nyz)
    analysis_deck(os.path.join(wd, "beam.inp"), fixed, tip)
    print(f"Info    : {nx} x {nyz} x {nyz} C3D8I hexes, "
          f"{len(fixed['FixedX'])} clamped and {len(tip)} loaded nodes")
    # getme writes beam-*.inp next to beam-*.mesh.inp (the include's copy)
    run([a.getme, "distort", "beam.inp", "-o", "beam-distorted.inp",
         "--seed", "11", "--amount", "0.45", "--rounds", "6", "-q"], wd)
    run([a.getme, "smooth", "beam-distorted.inp", "-o", "beam-smoothed.inp",
         "-q"], wd)
    ref = analytic_tip()
    print(f"Info    : Timoshenko tip deflection {ref:.5f} mm")
    err = {}
    for job in ("beam", "beam-distorted", "beam-smoothed"):
        u = tip_deflection(a.ccx, wd, job)
        err[job] = abs(u - ref) / abs(ref)
        q = run([a.getme, "quality", job + ".inp"], wd)
        m = re.search(r"qmin (\S+), qmean (\S+),", q.stdout + q.stderr)
        print(f"Info    : {job:15s} qmin {m.group(1) if m else '?'}, qmean "
              f"{m.group(2) if m else '?'}: tip deflection {u:.5f} mm, "
              f"error {100 * err[job]:6.3f} %")
    if a.check and not err["beam-smoothed"] < err["beam-distorted"]:
        print("Error   : smoothing did not reduce the deflection error")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
