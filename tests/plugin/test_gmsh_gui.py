"""The GUI's ONELAB panel (getme.gui) without a display (issue #10):
its defaults are the library's getme_params_init values (the CLI's too, and
examples/gmsh_gui/getme.geo's), and a failed Smooth removes the previous
run's results instead of leaving them on show."""
import json
import os
import re
import subprocess
import sys

import gmsh

import getme
from getme import _lib, gui

FAILS = []
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")


def check(cond, what):
    print(("ok     " if cond else "FAILED ") + what)
    if not cond:
        FAILS.append(what)


d = _lib.defaults()
check(d["threshold_fraction"] == 0.005 and d["sigma"] == 1.5 and d["max_iter"] == 1000,
      f"library defaults as documented ({d})")

# the CLI prints the same defaults in its help
getme_cli = sys.argv[1] if len(sys.argv) > 1 else None
if getme_cli:
    h = subprocess.run([getme_cli, "smooth", "--help"], capture_output=True, text=True).stdout
    check(re.search(r"threshold_fraction +real +default %g " % d["threshold_fraction"], h)
          is not None, "getme smooth --help names the library's threshold_fraction")

# getme.geo (the stock-gmsh path) carries the same numbers
geo = open(os.path.join(ROOT, "examples", "gmsh_gui", "getme.geo")).read()
for var, key in (("getme_fraction", "threshold_fraction"), ("getme_sigma", "sigma"),
                 ("getme_maxiter", "max_iter")):
    m = re.search(var + r"\s*=\s*\{\s*([0-9.eE+-]+)", geo)
    check(m is not None and float(m.group(1)) == d[key],
          f"getme.geo {var} = library {key} ({m.group(1) if m else None})")

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.model.addPhysicalGroup(3, [1])
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
gmsh.model.mesh.generate(3)
params = gui.parameters()
gmsh.onelab.set(json.dumps(params))
shown = {p["name"]: p["values"][0] for p in params if "values" in p}
check(shown[gui.P + "3Threshold fraction"] == d["threshold_fraction"],
      f"GUI threshold default {shown[gui.P + '3Threshold fraction']} = library's")
check(shown[gui.P + "1Sigma"] == d["sigma"], "GUI sigma default = library's")


def result_rows():
    """The result parameters present in the ONELAB database."""
    rows = {gui.P + "Result/%d%s" % (i, label)
            for i, label in enumerate(gui.RESULT_ROWS)
            if gmsh.onelab.getNumber(gui.P + "Result/%d%s" % (i, label))}
    if gmsh.onelab.getString(gui.P + "Result/Error"):
        rows.add(gui.P + "Result/Error")
    return rows


getme.gmsh.distort(seed=1, amount=0.4, rounds=2)
gui.smooth()
rows = result_rows()
check(len(rows) >= 7 and not any("Error" in r for r in rows), f"results shown after Smooth ({rows})")
# a failing run: a fixed group that does not exist
gmsh.onelab.setString(gui.P + "4Fixed groups", ["no such group"])
gui.smooth()
rows = result_rows()
check(rows == {gui.P + "Result/Error"}, f"after a failed Smooth only the error is shown ({rows})")
err = gmsh.onelab.getString(gui.P + "Result/Error")
check(bool(err) and "no such group" in err[0], f"the error names the cause ({err})")
gmsh.onelab.setString(gui.P + "4Fixed groups", [""])
gui.smooth()
rows = result_rows()
check(len(rows) >= 7 and not any("Error" in r for r in rows), "a good run replaces the error")
gmsh.finalize()
print(f"{len(FAILS)} failed")
sys.exit(1 if FAILS else 0)
