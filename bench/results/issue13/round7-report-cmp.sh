#!/bin/bash
# cmp.sh MESH THREADS : base-s6 vs build, logs/json/outputs
export OMP_WAIT_POLICY=passive
m=$1; t=$2; n=$(basename $m .msh); ext=${m##*.}
B=/work/base-s6/build/cli/getme; N=/work/wt-report/build/cli/getme
d=/tmp/rep/cmp
strip() { sed -E 's/[0-9]+\.[0-9]+ ?s\b/T/g; s/Wall [0-9.]+s/Wall T/; s/[0-9]+\.[0-9]+s\)/T)/g; s#/tmp/rep/cmp/[a-z]+-#OUT-#g' "$1"; }
sj() { /usr/bin/python3 -c '
import json,sys
d=json.load(open(sys.argv[1]))
for k in ("seconds","output"): d.pop(k,None)
d["untangle"].pop("seconds",None)
for h in d.get("history",[]): h.pop("elapsed",None)
print(json.dumps(d,indent=1,sort_keys=True))' "$1"; }
$B smooth $m -o $d/base-$n.$ext -v --threads $t --report $d/base-$n.json > $d/base-$n.log 2>&1; rb=$?
$N smooth $m -o $d/new-$n.$ext -v --threads $t --report $d/new-$n.json > $d/new-$n.log 2>&1; rn=$?
r="exit $rb/$rn"
cmp -s $d/base-$n.$ext $d/new-$n.$ext && r="$r mesh=" || r="$r MESH-DIFF"
diff <(strip $d/base-$n.log) <(strip $d/new-$n.log) > $d/$n.logdiff && r="$r log=" || r="$r LOG-DIFF"
diff <(sj $d/base-$n.json) <(sj $d/new-$n.json) > $d/$n.jsondiff && r="$r json=" || r="$r JSON-DIFF"
$B quality $m --worst 10 > $d/base-$n.q 2>&1; $N quality $m --worst 10 > $d/new-$n.q 2>&1
cmp -s $d/base-$n.q $d/new-$n.q && r="$r quality=" || r="$r QUALITY-DIFF"
echo "$n t$t: $r"
