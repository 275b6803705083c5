#!/bin/bash
# cmp of getme smooth outputs and log lines (times stripped), base vs finpar
export OMP_WAIT_POLICY=passive
B=/work/base-s7/build/cli/getme; F=/work/wt-finpar/build/cli/getme
D=/tmp/finpar/ident; mkdir -p $D
C=/work/cache
meshes="$C/tet-small-g1-h2.11-seed1-q0.45.msh $C/hex-small-g1-h1.83-seed1-q0.47.msh $C/mixed-small-g2-h0.075-seed1-q0.47.msh $C/quad-small-g1-h1-seed1-q0.47.msh $C/tri-small-g1-h1-seed1-q0.47.msh $C/tet-medium-g1-h1.08-seed1-q0.45.msh $C/hex-medium-g1-h0.98-seed1-q0.47.msh $EXTRA"
for m in $meshes; do
  n=$(basename $m .msh)
  for t in ${THREADS:-1 2 3}; do
    $B smooth $m -o $D/b-$n-$t.msh -v --threads $t --report $D/b-$n-$t.json 2>&1 | grep -vE "Writing|Reading|Done writing|Done reading" | sed -E 's/\(Wall [0-9.]+s\)//; s/\([0-9.]+ s\)//; s/[0-9.]+ s\b//g' > $D/b-$n-$t.log
    $F smooth $m -o $D/f-$n-$t.msh -v --threads $t --report $D/f-$n-$t.json 2>&1 | grep -vE "Writing|Reading|Done writing|Done reading" | sed -E 's/\(Wall [0-9.]+s\)//; s/\([0-9.]+ s\)//; s/[0-9.]+ s\b//g' > $D/f-$n-$t.log
    r1=same; cmp -s $D/b-$n-$t.msh $D/f-$n-$t.msh || r1=DIFF
    r2=same; diff -q $D/b-$n-$t.log $D/f-$n-$t.log >/dev/null || r2=DIFF
    for x in b f; do grep -v '"output"' $D/$x-$n-$t.json | sed -E 's/"(elapsed|seconds)": [0-9.e+-]+//g' > $D/$x-$n-$t.jsn; done
    r3=same; cmp -s $D/b-$n-$t.jsn $D/f-$n-$t.jsn || r3=DIFF
    echo "$n threads $t: output $r1, log $r2, report $r3, $(grep -c Finishing $D/f-$n-$t.log) passes"
    rm -f $D/b-$n-$t.msh $D/f-$n-$t.msh
  done
done
