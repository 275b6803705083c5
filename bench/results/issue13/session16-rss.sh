#!/usr/bin/env bash
# Peak RSS (MiB, /usr/bin/time %M) and output identity of base vs new.
# usage: BASE=... NEW=... fullrss.sh MESH...
BASE=${BASE:-/work/base-7269/build/cli/getme}
NEW=${NEW:-/work/main/build/cli/getme}
T=$(mktemp -d)
for m in "$@"; do
  for th in 1 2; do
    line="$(basename $m) t$th:"
    for b in BASE NEW; do
      exe=${!b}
      /usr/bin/time -f %M -o $T/rss $exe smooth "$m" -o $T/$b.msh --threads $th >/dev/null 2>&1
      line="$line $b $(awk '{printf "%.1f", $1/1024}' $T/rss) MiB"
    done
    cmp -s $T/BASE.msh $T/NEW.msh && line="$line, outputs same" || line="$line, outputs DIFFER"
    echo "$line"
  done
done
rm -rf $T
