#!/bin/bash
# byte-identity of qmin10 against base-s9 (5a19eed): outputs and --report JSON without timing fields
B=/work/base-s9/build/cli/getme; N=/work/h-qmin10/build/cli/getme; D=/tmp/qmin10/ident; mkdir -p $D
for m in /work/cache/tet-medium-g1-h1.08-seed1-q0.45.msh /work/cache/hex-medium-g1-h0.98-seed1-q0.47.msh /work/main/examples/bracket-distorted.msh; do
  for t in 1 2 3; do
    n=$(basename $m .msh)
    $B smooth $m -o $D/b.msh --threads $t -q --report $D/b.json
    $N smooth $m -o $D/n.msh --threads $t -q --report $D/n.json
    o=$(cmp $D/b.msh $D/n.msh && echo same || echo DIFFER)
    j=$(diff <(python3 -c "import json,sys
def strip(x):
    if isinstance(x,dict): return {k:strip(v) for k,v in x.items() if 'second' not in k and 'time' not in k and k not in ('wall','seconds','elapsed','output')}
    if isinstance(x,list): return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open('$D/b.json'))),sort_keys=True,indent=0))") <(python3 -c "import json,sys
def strip(x):
    if isinstance(x,dict): return {k:strip(v) for k,v in x.items() if 'second' not in k and 'time' not in k and k not in ('wall','seconds','elapsed','output')}
    if isinstance(x,list): return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open('$D/n.json'))),sort_keys=True,indent=0))") >/dev/null && echo same || echo DIFFER)
    echo "$n threads $t: output $o, report-without-times $j"
  done
done
rm -f $D/*.msh
