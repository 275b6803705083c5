#!/bin/sh
# `getme gmsh`: mesh a two-material OCC .geo with Gmsh, smooth, write MSH
# 2.2 and 4.1; Gmsh-style lines on the terminal; exit codes for bad use.
# usage: test_cli_gmsh.sh GETME_BINARY PYTHON
set -u
G=$1
PY=$2
fail=0
ok() { echo "ok: $*"; }
bad() { echo "FAILED: $*"; fail=1; }
here=$(cd "$(dirname "$0")" && pwd)
cp "$here/../../examples/part.geo" part.geo
rm -f part.msh part22.msh
"$G" gmsh part.geo -3 -clmax 0.15 --fix clamp -o part.msh -v > run.log 2>&1
rc=$?
[ $rc -eq 0 ] && ok "exit 0" || bad "exit $rc"
grep -q "^Info    : Optimizing mesh (GETMe adaptive, [0-9]* threads*)...$" run.log && ok "start line" || bad "no start line"
grep -q "^Info    : 0.90 < quality < 1.00 : " run.log && ok "histogram" || bad "no histogram"
grep -q "^Info    : Measures after  *(tet): dihedral .* deg, scaled Jacobian min .*, gamma min .*, SICN min " run.log \
  && ok "measures line" || bad "no measures line"
grep -q "^Info    : Done optimizing mesh (Wall " run.log && ok "done line" || bad "no done line"
grep -q "^Info    : Done meshing 3D" run.log && ok "Gmsh's own meshing lines" || bad "no Gmsh lines"
# the same log lines as getme smooth (one parser, one progress callback)
"$G" smooth part.msh -o part-again.msh --fix clamp -v > smooth.log 2>&1
for pat in "^Info    : Quality before: q\*min [0-9.]*, qmin" "^Info    : It    1 (qmean stage): q\*min" \
           "^Info    : It  *[0-9]* (q\*min stage, cycle 1, q_t" "^Info    : Quality after : q\*min" \
           "^Info    : Measures before (tet): dihedral" "^Info    : Measures after  (tet): dihedral"; do
  grep -q "$pat" run.log && grep -q "$pat" smooth.log && ok "both log '$pat'" || bad "log line '$pat'"
done
grep -q "getme-tmp" run.log && bad "the temporary file's name in the log" || ok "no temporary name in the log"
# smooth options: --param, --report, --method, --threads, --free-interfaces
rm -f opts.json part-opts.msh
"$G" gmsh part.msh -q -o part-opts.msh --param sigma=1.3 --param threshold_fraction=0.01 \
  --report opts.json --threads 1 --method getme --free-interfaces; rc=$?
[ $rc -eq 0 ] && "$PY" -c "
import json; r = json.load(open('opts.json'))
assert r['params']['sigma'] == 1.3 and r['params']['threshold_fraction'] == 0.01, r['params']
assert r['params']['num_threads'] == 1 and r['elements']['tet'] > 100, r
assert len(r['history']) == r['iterations']['total'] + r['iterations']['finish_passes'] > 0
" && ok "gmsh --param/--report" || bad "gmsh --param/--report ($rc)"
"$G" gmsh part.msh -q -o x.msh --param nonsense=1; rc=$?
[ $rc -eq 2 ] && ok "gmsh bad --param: 2" || bad "gmsh bad --param: $rc"
"$G" gmsh part.msh -q -o x.msh --free nope 2> err.log; rc=$?
[ $rc -eq 2 ] && grep -q "Unknown physical group 'nope' to free" err.log && ok "gmsh unknown --free: 2" || bad "gmsh --free: $rc"
"$G" gmsh part.msh -q -o x.msh --report part.msh; rc=$?
[ $rc -eq 2 ] && ok "gmsh --report = input refused" || bad "gmsh --report input: $rc"
# -o .inp: *Heading names the output, not the temporary file
rm -f part.inp
"$G" gmsh part.msh -q -o part.inp; rc=$?
[ $rc -eq 0 ] && [ "$(sed -n 2p part.inp)" = " part.inp" ] && ok "*Heading names part.inp" || bad "*Heading: $(sed -n 2p part.inp) ($rc)"
ls -a | grep -q getme-tmp && bad "temporary files left" || ok "no temporary files left"
head -2 part.msh | grep -q "^4.1 0 8" && ok "MSH 4.1" || bad "not MSH 4.1"
"$G" gmsh part.msh -q -format msh22 -bin -o part22.msh; rc=$?
[ $rc -eq 0 ] && head -2 part22.msh | grep -q "^2.2 1 8" && ok "msh input -> MSH 2.2 binary" || bad "msh22 ($rc)"
# The result is a valid mesh for Gmsh and by an independent mean ratio.
"$PY" - <<'PYEOF' || bad "python check of part.msh"
import gmsh, numpy as np
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.open("part.msh")
t, x, _ = gmsh.model.mesh.getNodes(); o = np.argsort(t); t = t[o]; x = x.reshape(-1, 3)[o]
_, en = gmsh.model.mesh.getElementsByType(4)
p = x[np.searchsorted(t, en).reshape(-1, 4)]
det = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
assert (det > 0).all(), "inverted tets"
names = sorted(gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups())
assert names == ["clamp", "insert", "matrix"], names
print("ok: part.msh valid, %d tets, groups %s" % (len(p), names))
PYEOF
# A tangled input (an interior node pushed through its tets): untangled
# with a warning line, then smoothed; --no-untangle refuses it (exit 6).
"$PY" - <<'PYEOF' || bad "writing tangled.msh"
import gmsh, numpy as np
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.open("part.msh")
t, x, _ = gmsh.model.mesh.getNodes(3, -1)
gmsh.model.mesh.setNode(int(t[len(t) // 2]), (x.reshape(-1, 3)[len(t) // 2] + [0.3, 0, 0]).tolist(), [])
gmsh.write("tangled.msh")
PYEOF
"$G" gmsh tangled.msh -o untangled.msh > tangled.log 2>&1; rc=$?
[ $rc -eq 0 ] && grep -q "^Warning : [0-9]* invalid (inverted or degenerate) elements* in the input, 0 remain after untangling" tangled.log \
  && ok "tangled input untangled: 0" || bad "tangled input: $rc"
"$G" gmsh tangled.msh -q --no-untangle -o refused.msh 2> err.log; rc=$?
[ $rc -eq 6 ] && [ ! -e refused.msh ] && ok "--no-untangle: 6" || bad "--no-untangle: $rc"
"$G" gmsh missing.geo -q; rc=$?; [ $rc -eq 3 ] && ok "missing input: 3" || bad "missing input: $rc"
"$G" gmsh part.geo -q -3 -clmax 0.3 --fix nope -o x.msh 2> err.log; rc=$?
[ $rc -eq 2 ] && grep -q "Unknown physical group 'nope'" err.log && ok "unknown group: 2" || bad "unknown group: $rc"
"$G" gmsh part.msh -o part.msh -q; rc=$?; [ $rc -eq 2 ] && ok "refuses to overwrite input" || bad "overwrite: $rc"
"$G" gmsh part.geo --bogus 2> err.log; rc=$?; [ $rc -eq 2 ] && grep -q "unknown option" err.log && ok "bad option: 2" || bad "bad option: $rc"
# getme.geo: the stock gmsh runs `getme gmsh` from the .geo and loads the
# smoothed mesh (what the GUI does when "Smooth the mesh" is ticked).
rm -f getme_raw.msh getme_smoothed.msh
cp "$here/../../examples/gmsh_gui/plate.geo" plate.geo
printf 'getme_dim = 2;\ngetme_dir = CurrentDirectory;\nInclude "%s";\n' \
  "$here/../../examples/gmsh_gui/getme.geo" >> plate.geo
gmsh plate.geo -setnumber getme_run 1 -setstring getme_exe "$G" -parse_and_exit > geo.log 2>&1
grep -q "Calling '.*gmsh .*getme_raw.msh' -o '.*getme_smoothed.msh'" geo.log \
  && [ -s getme_smoothed.msh ] && grep -q "^Info    : Reading '.*getme_smoothed.msh'" geo.log \
  && ok "getme.geo: gmsh ran getme and loaded the result" || bad "getme.geo path"
exit $fail
