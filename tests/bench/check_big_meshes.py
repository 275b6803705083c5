#!/usr/bin/python3
"""bench/big_meshes.py's Kuhn box (the size tests' input, docs/bench.md
"Session 26"): a small box is written, read by meshio and by getme, and
checked against what the construction promises: 6 N^3 tets on (N + 1)^3
nodes, every tet positively oriented with the same mean ratio
12 (3 V)^(2/3) / sum of squared edges = 12 (1/2)^(2/3) / 10, the box's
surface nodes fixed, and a distorted copy smoothed back near that value."""
import argparse
import os
import re
import subprocess
import sys

import meshio
import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True)
    ap.add_argument("--getme", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    sys.path.insert(0, a.bench)
    from quality import element_quality
    os.makedirs(a.work, exist_ok=True)
    n = 5
    box = os.path.join(a.work, "kuhn5.msh")
    subprocess.run([sys.executable, os.path.join(a.bench, "big_meshes.py"),
                    "kuhn", str(n), box], check=True, capture_output=True)
    fails = []
    m = meshio.read(box)
    tets = m.cells_dict.get("tetra")
    if len(m.points) != (n + 1) ** 3 or tets is None or len(tets) != 6 * n ** 3:
        fails.append(f"meshio: {len(m.points)} points, cells {list(m.cells_dict)}")
    else:
        p = m.points[tets]
        vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                        p[:, 3] - p[:, 0]) / 6.0
        if not np.allclose(vol, 1.0 / 6.0, rtol=0, atol=1e-14):
            fails.append(f"volumes {vol.min()}..{vol.max()}, expected 1/6")
        q = element_quality(m.points, tets, "tet")
        exact = 12.0 * 0.5 ** (2.0 / 3.0) / 10.0
        if not np.allclose(q, exact, rtol=0, atol=1e-12):
            fails.append(f"mean ratio {q.min()}..{q.max()}, expected {exact}")
    r = subprocess.run([a.getme, "quality", box], capture_output=True, text=True)
    want = f"{6 * n ** 3} tets; {(n + 1) ** 3} nodes ({(n + 1) ** 3 - (n - 1) ** 3} fixed)"
    if r.returncode != 0 or want not in r.stdout + r.stderr:
        fails.append(f"getme quality: exit {r.returncode}, no '{want}' in\n{r.stdout}{r.stderr}")
    dist, out = os.path.join(a.work, "kuhn5-d.msh"), os.path.join(a.work, "kuhn5-s.msh")
    r = subprocess.run([a.getme, "distort", box, "-o", dist, "--seed", "1", "-q"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        fails.append(f"getme distort: exit {r.returncode}\n{r.stderr}")
    r = subprocess.run([a.getme, "smooth", dist, "-o", out], capture_output=True, text=True)
    after = re.search(r"Quality after : q\*min ([0-9.]+), qmin [0-9.]+, qmean ([0-9.]+)",
                      r.stdout + r.stderr)
    before = re.search(r"Quality before: q\*min ([0-9.]+)", r.stdout + r.stderr)
    if r.returncode != 0 or not after or not before:
        fails.append(f"getme smooth: exit {r.returncode}\n{r.stdout}{r.stderr}")
    elif not (float(before.group(1)) < 0.5 < float(after.group(1))
              and float(after.group(2)) > 0.74):
        fails.append(f"smoothing: q*min {before.group(1)} -> {after.group(1)}, "
                     f"qmean {after.group(2)}")
    for f in fails:
        print("FAIL:", f)
    print("big_meshes: ok" if not fails else f"big_meshes: {len(fails)} failures")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
