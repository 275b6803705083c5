#!/usr/bin/env bash
# Byte-compare getme smooth outputs of two builds.  BASE, NEW: getme binaries.
# usage: BASE=... NEW=... cmp.sh MESH...   (threads 1 and 2)
BASE=${BASE:-/work/base-7269/build/cli/getme}
NEW=${NEW:-/work/main/build/cli/getme}
T=$(mktemp -d); same=0; diff=0
for m in "$@"; do
  ext=${m##*.}
  for th in 1 2; do
    $BASE smooth "$m" -o $T/a.$ext --threads $th >/dev/null 2>&1; ra=$?
    $NEW smooth "$m" -o $T/b.$ext --threads $th >/dev/null 2>&1; rb=$?
    if [ $ra = $rb ] && cmp -s $T/a.$ext $T/b.$ext; then same=$((same+1)); r=same; else diff=$((diff+1)); r="DIFFERENT (rc $ra/$rb)"; fi
    echo "$(basename $m) t$th: $r"
    rm -f $T/a.$ext $T/b.$ext
  done
done
echo "$same of $((same+diff)) the same"
rm -rf $T
