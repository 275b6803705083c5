#!/bin/sh
# The CGNS adapter as a module (formats/cgns/cgns_load.c):
#  1. libgetme_formats and the getme command do not need libcgns or HDF5;
#  2. the module exports exactly getme_cgns_module;
#  3. a CGNS file is read and written through it;
#  4. a libgetme_formats without the module beside it refuses a CGNS file
#     with one clear message and exit code 5 (unsupported content), and
#     still reads MSH.
# usage: cgns_module.sh GETME FORMATS_LIB MODULE CGNS_FILE MSH_FILE WORKDIR
set -u
getme=$1 formats=$2 module=$3 cgns=$4 msh=$5 work=$6
fail=0
bad() { echo "FAIL: $*"; fail=1; }
rm -rf "$work" && mkdir -p "$work/alone" || exit 1

for f in "$formats" "$getme"; do
    if readelf -d "$f" | grep NEEDED | grep -Eq 'libcgns|libhdf5'; then
        bad "$f needs libcgns or HDF5"
    fi
done
exports=$(nm -D --defined-only "$module" | awk '{print $3}' | tr '\n' ' ')
[ "$exports" = "getme_cgns_module " ] || bad "module exports '$exports'"

"$getme" smooth "$cgns" -o "$work/out.cgns" > "$work/ok.log" 2>&1 ||
    bad "smoothing $cgns failed: $(tail -1 "$work/ok.log")"
"$getme" quality "$work/out.cgns" > /dev/null 2>&1 || bad "output unreadable"

# the formats library alone in a folder, found first by the loader
cp "$formats" "$work/alone/" || exit 1
base=$(basename "$formats")
soname=$(readelf -d "$formats" | sed -n 's/.*SONAME.*\[\(.*\)\].*/\1/p')
[ "$soname" != "$base" ] && cp "$formats" "$work/alone/$soname"
LD_LIBRARY_PATH="$work/alone" "$getme" smooth "$cgns" -o "$work/no.cgns" \
    > "$work/no.log" 2>&1
rc=$?
[ $rc -eq 5 ] || bad "without the module: exit $rc, want 5"
grep -q "CGNS support is not installed" "$work/no.log" ||
    bad "without the module: $(cat "$work/no.log")"
[ -e "$work/no.cgns" ] && bad "without the module: an output was written"
LD_LIBRARY_PATH="$work/alone" "$getme" quality "$msh" > "$work/msh.log" 2>&1 ||
    bad "without the module: MSH no longer read: $(tail -1 "$work/msh.log")"
[ $fail -eq 0 ] && echo "cgns_module: ok"
exit $fail
