#!/usr/bin/python3
"""The finishing step on a mesh that locks GETMe adaptive's q*min stage.

usage: /usr/bin/python3 test_finish.py GETME_BINARY WORKDIR

tests/data/locked-ring.msh is a piece of the benchmark's full-size piston
mesh (4.03M tets) after the paper's method: the 3-ring neighbourhood of the
tet it left at q = 0.0070, cut out with its outer skin as the new boundary.
Every averaged move of that tet's nodes inverts a neighbour, so Eq. 10
resets them in every iteration and the paper's method (--param finish=0)
cannot raise it.  Asserted:
  - the paper's method stays locked there (q*min <= 0.01): the mesh really
    locks, so the next check can fail;
  - the default (finishing step) raises q*min above 0.3;
  - q*min never decreases over the finishing passes, and starts from the
    paper's result;
  - output valid by an independent mean ratio (bench/quality.py), skin
    nodes bit-identical, 1 and 2 threads byte-identical, input untouched;
  - the reported worst element with a free node is the independent q*min.
"""
import hashlib
import json
import os
import sys

import numpy as np

GETME, WORK = sys.argv[1], sys.argv[2]
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data", "locked-ring.msh")
# tests/support and bench/ are on PYTHONPATH (set by ctest)
from checks import Checks
from quality import element_quality

os.makedirs(WORK, exist_ok=True)
T = Checks(GETME)
check = T.check


def read_msh22(path):
    """Nodes (n x 3, by tag 1..n) and tets (m x 4, zero-based) of the
    fixture's MSH 2.2 ASCII layout: dense tags, one tet type."""
    lines = open(path).read().split("\n")
    i = lines.index("$Nodes")
    n = int(lines[i + 1])
    xyz = np.array([[float(v) for v in lines[i + 2 + k].split()[1:4]] for k in range(n)])
    j = lines.index("$Elements")
    m = int(lines[j + 1])
    tets = np.array([[int(v) - 1 for v in lines[j + 2 + k].split()[5:9]] for k in range(m)])
    return xyz, tets


def skin_nodes(tets):
    """Nodes of faces with one tet (computed here, not by getme)."""
    faces = np.sort(tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    uniq, count = np.unique(faces, axis=0, return_counts=True)
    return np.unique(uniq[count == 1])


def smooth(name, *args):
    out, rep = os.path.join(WORK, name + ".msh"), os.path.join(WORK, name + ".json")
    T.run("smooth", DATA, "-o", out, "--report", rep, *args)
    return out, json.load(open(rep))


sha = hashlib.sha256(open(DATA, "rb").read()).hexdigest()
x0, tets = read_msh22(DATA)
skin = skin_nodes(tets)
free_el = ~np.isin(tets, skin).all(axis=1)
q_in = element_quality(x0, tets, "tet")

paper_out, paper = smooth("paper", "--threads", "1", "--param", "finish=0",
                          "--param", "corner_guard=0")
out1, rep1 = smooth("finish1", "--threads", "1")
out2, rep2 = smooth("finish2", "--threads", "2")

check(paper["after"]["q_min_star"] <= 0.01,
      f"the paper's method stays locked ({paper['after']['q_min_star']:.4f})")
check(rep1["after"]["q_min_star"] > 0.3,
      f"the finishing step unlocks it ({rep1['after']['q_min_star']:.4f})")
passes = [h["q_min_star"] for h in rep1["history"] if h["stage"] == 4]
check(len(passes) >= 2 and passes[0] >= paper["after"]["q_min_star"],
      "finishing passes start from the paper's result")
check(all(b >= a for a, b in zip(passes, passes[1:])),
      "q*min never decreases over the finishing passes")

x1, t1 = read_msh22(out1)
q1 = element_quality(x1, tets, "tet")
check((t1 == tets).all(), "topology unchanged")
check((q1 > 0).all(), "every element valid (independent mean ratio)")
check(np.array_equal(x1[skin], x0[skin]), "skin nodes bit-identical")
check(abs(q1[free_el].min() - rep1["after"]["q_min_star"]) < 1e-9,
      "report's q*min equals the independent one")
check(q1.mean() >= paper["after"]["q_mean"], "q_mean not below the paper's method's")
wf = rep1["worst_free_elements"]
check(wf and wf[0]["index"] == int(np.argmin(np.where(free_el, q1, np.inf))),
      "the worst element with a free node is the independent argmin")
check(open(out1, "rb").read() == open(out2, "rb").read(), "1 and 2 threads byte-identical")
check(hashlib.sha256(open(DATA, "rb").read()).hexdigest() == sha, "input untouched")

# `getme quality --worst`: on the paper's locked result the worst tet (all 4
# nodes free) is named with its tag and reported as still improvable; the
# finishing step is what improves it.
q = T.run("quality", paper_out, "--worst", "2")
lines = [ln for ln in q.stdout.splitlines() if " tet q " in ln]
tag = paper["worst_free_elements"][0]["tag"]
check(q.returncode == 0 and len(lines) == 4, "quality --worst 2 lists 2 + 2 elements")
check(lines and lines[0].split()[2] == str(tag) and "4/4 free: a node move can still raise it" in lines[0],
      f"quality --worst names the locked tet {tag}: {lines[:1]}")
# a tet's corner scaled Jacobian is 1 by definition: not printed as if
# it were the element's (it read "tet q 0.22 sj 1.0000")
check(lines and all(" sj " not in ln for ln in lines), f"no corner sj on tet lines: {lines[:1]}")

print(f"locked ring: q*min {q_in[free_el].min():.4f} -> paper {paper['after']['q_min_star']:.4f}, "
      f"finishing step {rep1['after']['q_min_star']:.4f} in {len(passes)} passes; "
      f"qmean paper {paper['after']['q_mean']:.4f}, finishing {rep1['after']['q_mean']:.4f}")
sys.exit(T.summary())
