#!/bin/sh
# `cmake --install BUILD --prefix P` for a P other than the configured one:
# the installed Python module finds libgetme / libgetme_gmsh (issue #10: its
# _paths.py used to name /usr/local), and the installed command runs.
# usage: test_install_prefix.sh BUILD_DIR PYTHON WORKDIR
set -eu
build=$1 py=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
prefix=$work/some/other/prefix
cmake --install "$build" --prefix "$prefix" > "$work/install.log"
site=$(find "$prefix" -path '*/getme/_paths.py' | head -n 1)
test -n "$site" || { echo "FAILED: no installed _paths.py"; exit 1; }
site=$(dirname "$(dirname "$site")")
if grep -q /usr/local "$site/getme/_paths.py"; then
    echo "FAILED: _paths.py still names /usr/local"; exit 1
fi
cd "$work"
PYTHONPATH=$site "$py" - "$prefix" <<'PY'
import os, sys
import gmsh, getme
from getme import _lib
prefix = os.path.realpath(sys.argv[1])
for lib in (_lib.core, _lib.plugin):
    assert os.path.realpath(lib._name).startswith(prefix), lib._name
    assert os.path.exists(lib._name), lib._name
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
gmsh.model.mesh.generate(3)
res = getme.gmsh.optimize(log=0)
gmsh.finalize()
assert 0 < res["q_min_star_after"] <= 1, res
print("installed module OK:", _lib.core._name, res["q_min_star_after"])
PY
"$prefix/bin/getme" --version | grep -q '^getme ' || { echo "FAILED: installed getme"; exit 1; }
# the command loads the Gmsh plugin only when needed (cli/gmsh_load.c):
# from the installed library folder, and runs the installed getme-gmsh
"$prefix/bin/getme" formats | grep -q 'through the Gmsh SDK' ||
    { echo "FAILED: installed getme does not load the Gmsh plugin"; exit 1; }
"$prefix/bin/getme" gmsh --help | grep -q '^usage: getme gmsh' ||
    { echo "FAILED: installed getme gmsh"; exit 1; }
echo "install prefix test passed"
