#!/bin/sh
# Build and run bench/setup.c (the smoother's set-up alone: workspace,
# faces, adjacency; timings and hashes of what they build) with libgetme's
# own compile flags (core/CMakeLists.txt):
#     bench/setup.sh MESH.msh|MESH.raw [threads] [repetitions]
# A .msh is converted once to MESH.raw in $RAW (default /tmp) with Gmsh's
# Python module (Debian's /usr/bin/python3).  SRC=other checkout measures
# another tree's set-up with the same driver; CPU=N pins it (taskset);
# WALL=1 reports wall seconds instead of CPU seconds.
set -e
here=$(cd "$(dirname "$0")/.." && pwd)
src=${SRC:-$here}
out=${OUT:-/tmp/getme-setup-$$}
[ -n "$KEEP" ] || trap 'rm -f "$out"' EXIT
mesh=$1
shift
case $mesh in
*.msh)
    raw=${RAW:-/tmp}/$(basename "$mesh" .msh).raw
    [ -f "$raw" ] || /usr/bin/python3 - "$mesh" "$raw" <<'PY'
import struct, sys
import gmsh
import numpy as np
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
tags, xyz, _ = gmsh.model.mesh.getNodes()
order = np.argsort(tags)
tags, xyz = tags[order], xyz.reshape(-1, 3)[order]
index = np.full(int(tags.max()) + 1, -1, np.int64)
index[tags] = np.arange(len(tags))
blocks = []  # Gmsh type -> getme type: tet, hex, prism, pyramid
for gtype, gt in ((4, 0), (5, 1), (6, 2), (7, 3)):
    et, en = gmsh.model.mesh.getElementsByType(gtype)
    if len(et):
        blocks.append((gt, len(et), index[en].astype(np.int32)))
with open(sys.argv[2], "wb") as f:
    f.write(struct.pack("iii", 3, len(tags), len(blocks)))
    f.write(xyz.astype(np.float64).tobytes())
    for gt, n, c in blocks:
        f.write(struct.pack("ii", gt, n))
        f.write(c.tobytes())
gmsh.finalize()
PY
    mesh=$raw ;;
esac
# the allocation helper (core/alloc since round 17; older trees had it
# among the core's sources)
alloc_inc= alloc_src=
if [ -d "$src/core/alloc" ]; then
    alloc_inc=-I"$src/core/alloc" alloc_src="$src/core/alloc/getme_alloc.c"
fi
gcc -std=c11 -O3 -fno-math-errno ${MARCH--march=native} -fopenmp -Wall -Wextra \
    -I"$src/core/include" -I"$src/core/src" $alloc_inc "$here/bench/setup.c" \
    $(ls "$src"/core/src/*.c | grep -v '/adjacency\.c$') $alloc_src -lm -o "$out"
if [ -n "$CPU" ]; then
    OMP_WAIT_POLICY=passive taskset -c "$CPU" "$out" "$mesh" "$@"
else
    OMP_WAIT_POLICY=passive "$out" "$mesh" "$@"
fi
