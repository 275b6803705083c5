#!/bin/sh
# Build and run bench/report_calls.c against a build tree's libraries:
#     bench/report_calls.sh BUILD MESH [repetitions] [values-file]
# BUILD: a cmake build directory of this or another checkout (its core/ and
# formats/ libraries; headers from this tree, whose additions are only
# used with SHARED=1, i.e. -DGETME_SHARED_Q).
set -e
here=$(cd "$(dirname "$0")/.." && pwd)
build=$1
shift
out=${OUT:-/tmp/getme-report-calls-$$}
flags=
[ -n "$SHARED" ] && flags=-DGETME_SHARED_Q
gcc -std=c11 -O2 -fopenmp $flags -I"$here/core/include" -I"$here/formats/include" \
    "$here/bench/report_calls.c" -L"$build/core" -L"$build/formats" \
    -Wl,-rpath,"$build/core" -Wl,-rpath,"$build/formats" \
    -lgetme_formats -lgetme -o "$out"
OMP_WAIT_POLICY=passive "$out" "$@"
[ -n "$KEEP" ] || rm -f "$out"
