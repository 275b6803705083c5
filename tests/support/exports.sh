#!/bin/sh
# exports.sh CC LIB INCLUDE_DIR... -- HEADER...: the functions LIB exports
# (nm -D) are exactly those the HEADERs declare with their export macro
# (visibility "default": their documented API): nothing private leaks out,
# nothing documented is missing.
cc=$1 lib=$2
shift 2
incs=""
while [ "$1" != "--" ]; do incs="$incs -I$1"; shift; done
shift
# The preprocessed headers (comments gone): the identifier before the first
# "(" of every declaration that carries the visibility attribute.
# Only the text of the HEADERs themselves (the line markers say whose it
# is), not of the headers they include.
names=" $* "
want=$(for h in "$@"; do echo "#include \"$h\""; done |
       $cc -E $incs -x c - |
       awk -v names="$names" '/^# [0-9]+ "/ { f = $3; gsub(/"/, "", f);
                                             n = split(f, p, "/");
                                             mine = index(names, " " p[n] " ") > 0;
                                             next }
                              mine' | tr '\n' ' ' | tr ';' '\n' |
       grep 'visibility *( *"default" *)' |
       sed 's/__attribute__ *(( *visibility *( *"default" *) *))//; s/(.*//' |
       awk '{print $NF}' | tr -d '*' | sort -u)
# Functions are T, and i for an ifunc (gcc's target_clones): both count.
have=$(nm -D --defined-only "$lib" | awk '$2 == "T" || $2 == "i" {print $3}' | sort -u)
if [ -n "$want" ] && [ "$want" = "$have" ]; then
    echo "ok   $(echo "$have" | wc -l) exported functions, all declared in the headers"
    exit 0
fi
echo "FAIL exports of $lib differ from the headers (-: declared only, +: exported only):"
echo "$want" > "${TMPDIR:-/tmp}/exports-want.$$"
echo "$have" | diff "${TMPDIR:-/tmp}/exports-want.$$" - | grep '^[<>]' | sed 's/^</-/; s/^>/+/'
rm -f "${TMPDIR:-/tmp}/exports-want.$$"
exit 1
