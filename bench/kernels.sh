#!/bin/sh
# Build and run bench/kernels.c (the per-element kernels alone, one
# thread) with libgetme's own compile flags (core/CMakeLists.txt):
#     bench/kernels.sh [evaluations per kernel]
# SRC=other checkout measures another tree's kernels with the same driver.
# Exit code 1 if a lane kernel does not give the one-element kernel's bits
# (the ctest bench_kernels runs it with a few evaluations).
set -e
here=$(cd "$(dirname "$0")/.." && pwd)
src=${SRC:-$here}
out=${OUT:-/tmp/getme-kernels-$$}
trap 'rm -f "$out"' EXIT
gcc -std=c11 -O3 -fno-math-errno ${MARCH--march=native} -fopenmp -Wall -Wextra \
    -I"$src/core/include" -I"$src/core/src" -I"$src/core/alloc" \
    -fno-trapping-math "$here/bench/kernels.c" \
    "$src/core/src/quality.c" "$src/core/src/transform.c" \
    "$src/core/src/transform_tet.c" "$src/core/src/transform_dual.c" \
    "$src/core/src/transform_polygon.c" -lm -o "$out"
OMP_NUM_THREADS=1 taskset -c "${CPU:-0}" "$out" "$@"
