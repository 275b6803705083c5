#!/usr/bin/python3
"""Large deck: an INP with 126^3 = 2,000,376 hexes (2,048,383 nodes) is
generated in the build directory, then read and written by io_bench under
/usr/bin/time -v.  Prints read/write time and peak RSS (reported, never
asserted); asserts that the output has the same lines as the input except
the rewritten node lines, and that the node count is right.
usage: test_inp_large.py IO_BENCH WORKDIR [N]
"""
import os
import re
import subprocess
import sys

import numpy as np

BENCH, WORK = sys.argv[1], sys.argv[2]
N = int(sys.argv[3]) if len(sys.argv) > 3 else 126
os.makedirs(WORK, exist_ok=True)
deck = os.path.join(WORK, f"hex{N}.inp")
out = os.path.join(WORK, f"hex{N}-out.inp")

n1 = N + 1
if not os.path.exists(deck):
    k, j, i = np.meshgrid(np.arange(n1), np.arange(n1), np.arange(n1),
                          indexing="ij")
    ids = (i + n1 * j + n1 * n1 * k).ravel() + 1
    xyz = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1) * (1.0 / N)
    c = np.arange(N)
    k, j, i = np.meshgrid(c, c, c, indexing="ij")
    b = (i + n1 * j + n1 * n1 * k).ravel() + 1
    conn = np.stack([b, b + 1, b + 1 + n1, b + n1, b + n1 * n1,
                     b + 1 + n1 * n1, b + 1 + n1 + n1 * n1, b + n1 + n1 * n1],
                    axis=1)
    eid = np.arange(1, len(conn) + 1)
    with open(deck + ".tmp", "w") as f:
        f.write("*HEADING\nlarge hex block\n*NODE\n")
        np.savetxt(f, np.column_stack([ids, xyz]),
                   fmt=["%d", "%.10g", "%.10g", "%.10g"], delimiter=", ")
        f.write("*ELEMENT, TYPE=C3D8R, ELSET=Block\n")
        np.savetxt(f, np.column_stack([eid, conn]), fmt="%d", delimiter=", ")
        f.write("*SOLID SECTION, ELSET=Block, MATERIAL=Steel\n,\n")
    os.rename(deck + ".tmp", deck)

r = subprocess.run(["/usr/bin/time", "-v", BENCH, deck, out, "--move"],
                   capture_output=True, text=True)
print(r.stdout.strip())
rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr)
wall = re.search(r"Elapsed \(wall clock\) time.*: (\S+)", r.stderr)
size = os.path.getsize(deck) / 2**20
print(f"Info    : deck {size:.0f} MiB, peak RSS "
      f"{int(rss.group(1)) / 1024 if rss else -1:.0f} MiB, wall "
      f"{wall.group(1) if wall else '?'}")
ok = r.returncode == 0 and f"nodes {n1**3} " in r.stdout
# every non-node line identical, interior node lines rewritten
diff, interior = -1, (N - 1) ** 3
if os.path.exists(out):
    diff = 0
    with open(deck, "rb") as a, open(out, "rb") as b:
        for la, lb in zip(a, b):
            diff += la != lb
    os.remove(out)
ok = ok and diff == interior
print(f"Info    : {diff} lines differ, {interior} interior nodes")
print(f"test_inp_large: {int(ok)} passed, {int(not ok)} failed")
sys.exit(0 if ok else 1)
