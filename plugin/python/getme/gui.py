"""The Gmsh GUI with GETMe adaptive in its ONELAB panel.

    /usr/bin/python3 -m getme.gui model.geo|model.step|model.msh

opens Gmsh's own graphical interface (gmsh.fltk, Gmsh 4.8) in this process,
loads and (if needed) meshes the model, and adds a "GETMe adaptive" group to
the ONELAB panel: method, sigma, maximum iterations, threshold fraction,
fixed physical groups, the finishing step, Gmsh's swaps first, and a
"Smooth (GETMe)" button that smooths the mesh
shown, in place, and redraws it.  Results (q*min / q_mean before and after,
iterations, nodes moved) appear read-only under "GETMe adaptive/Result"; the
log lines go to Gmsh's message window.  File > Save Mesh saves the result.

Why in-process: Debian's Gmsh 4.8 runs ONELAB clients (Solver.Executable0)
as separate processes, and its Python API inside such a client talks to a
private ONELAB database instead of the GUI's (checked: parameters set by the
client never reach the panel), so a separate client could neither show its
parameters nor see the mesh on screen.  Here the GUI and the smoother share
one Gmsh instance and one model.
"""
import json
import sys

import gmsh

from . import gmsh as gg
from ._lib import GetmeError
from ._lib import parameters as getme_parameters

P = "GETMe adaptive/"


def _from_table(label, name, step, lo=None, hi=None):
    """A panel number whose default, range and help come from libgetme's
    parameter table (getme.parameters()), so the GUI cannot drift from the
    CLI and the library.  lo/hi narrow the slider's range only."""
    p = next(p for p in getme_parameters() if p["name"] == name)
    return {"type": "number", "name": P + label, "values": [p["default"]],
            "min": p["min"] if lo is None else lo,
            "max": p["max"] if hi is None else hi, "step": step,
            "help": p["help"]}


def parameters():
    groups = ["%s" % gmsh.model.getPhysicalName(d, t) or "%d:%d" % (d, t)
              for d, t in gmsh.model.getPhysicalGroups()]
    return [
        {"type": "string", "name": P + "0Method", "values": ["getme"],
         "choices": ["getme", "laplace"],
         "help": "GETMe adaptive or smart Laplace (baseline)"},
        _from_table("1Sigma", "sigma", 0.05, lo=0.05, hi=3),
        _from_table("2Max iterations", "max_iter", 1, lo=1, hi=100000),
        _from_table("3Threshold fraction", "threshold_fraction", 0.001,
                    lo=0.0001),
        {"type": "string", "name": P + "4Fixed groups", "values": [""],
         "help": "comma-separated physical group names or dim:tag; "
                 "available: " + (", ".join(groups) or "none")},
        dict(_from_table("6Finishing step", "finish", 1), choices=[0, 1]),
        {"type": "number", "name": P + "7Gmsh swaps first", "values": [0],
         "choices": [0, 1],
         "help": "when some worst tets have no free node, run Gmsh's own "
                 "optimizer (edge/face swaps) before GETMe"},
        {"type": "number", "name": P + "5Distort mesh now (demo)",
         "values": [0], "choices": [0, 1],
         "help": "random validity-preserving moves of the free nodes, to "
                 "try the smoother on a bad mesh"},
        {"type": "string", "name": "ONELAB/Button",
         "values": ["Smooth (GETMe)", "getme"], "visible": False},
    ]


def number(name, default=None):
    """A panel number; ONELAB drops a number whose only value is 0 from the
    JSON it was given, so such parameters read back empty: default."""
    v = gmsh.onelab.getNumber(P + name)
    return v[0] if v else default


RESULT_ROWS = ["q*min before", "q*min after", "q_mean before",
               "q_mean after", "Iterations", "Finishing passes", "Nodes moved",
               "Worst element tag", "Worst element quality",
               "Worst element free nodes"]


def clear_result():
    """Remove the rows of the last run (and its error), so that the panel
    never shows results of an earlier mesh after a failed run."""
    for i, label in enumerate(RESULT_ROWS):
        gmsh.onelab.clear(P + "Result/%d%s" % (i, label))
    gmsh.onelab.clear(P + "Result/Error")


def log_error(message):
    """Gmsh's Python API raises after logging at level "error" (it reports
    the last error of the call): log it and carry on, the GUI stays up."""
    try:
        gmsh.logger.write(message, "error")
    except Exception:  # noqa: BLE001 -- the message is logged already
        pass


def show_error(message):
    clear_result()
    gmsh.onelab.set(json.dumps([
        {"type": "string", "name": P + "Result/Error", "values": [message],
         "readOnly": True}]))


def show_result(res):
    clear_result()
    values = {"q*min before": res["q_min_star_before"],
              "q*min after": res["q_min_star_after"],
              "q_mean before": res["q_mean_before"],
              "q_mean after": res["q_mean_after"],
              "Iterations": res["iterations"],
              "Finishing passes": res["passes_finish"],
              "Nodes moved": res["num_moved"]}
    if res["worst"]:
        w = res["worst"][0]
        values.update({"Worst element tag": w["tag"],
                       "Worst element quality": w["quality"],
                       "Worst element free nodes": w["num_free"]})
    gmsh.onelab.set(json.dumps([
        {"type": "number", "name": P + "Result/%d%s" % (i, label),
         "values": [float(values[label])], "readOnly": True}
        for i, label in enumerate(RESULT_ROWS) if label in values]))


def redraw():
    """setNode does not flag the mesh as changed for the OpenGL vertex
    arrays; toggling a mesh display option does.  Then redraw the scene and
    rebuild the ONELAB panel (new results, unticked demo box)."""
    for opt in ("Mesh.SurfaceEdges", "Mesh.VolumeEdges"):
        v = gmsh.option.getNumber(opt)
        gmsh.option.setNumber(opt, 1 - v)
        gmsh.option.setNumber(opt, v)
    if gmsh.fltk.isAvailable():
        gmsh.graphics.draw()
        gmsh.fltk.update()


def smooth():
    method = gmsh.onelab.getString(P + "0Method")
    fixed = gmsh.onelab.getString(P + "4Fixed groups")
    fix = [g.strip() for g in (fixed[0] if fixed else "").split(",")
           if g.strip()]
    try:
        res = gg.optimize(method=method[0] if method else "getme", fix=fix,
                          sigma=number("1Sigma"),
                          max_iter=int(number("2Max iterations")),
                          threshold_fraction=number("3Threshold fraction"),
                          finish=int(number("6Finishing step", 1)),
                          topology=int(number("7Gmsh swaps first", 0)))
        show_result(res)
    except GetmeError as e:
        show_error(str(e))
        log_error("GETMe: %s" % e)
    redraw()


def distort_if_asked():
    """The demo checkbox acts at once (on the panel's "check" action) and
    unticks itself."""
    if not number("5Distort mesh now (demo)"):
        return
    gmsh.onelab.setNumber(P + "5Distort mesh now (demo)", [0])
    try:
        n = gg.distort(seed=1, amount=0.45, rounds=6)
        gmsh.logger.write("Distorted the mesh for the demo (%d nodes moved)"
                          % n, "info")
    except GetmeError as e:
        log_error("GETMe: %s" % e)
    redraw()


def handle_events():
    action = gmsh.onelab.getString("ONELAB/Action")
    if action and action[0]:
        gmsh.onelab.setString("ONELAB/Action", [""])
        if action[0] == "getme":
            smooth()
        elif action[0] == "check":
            distort_if_asked()
    return True


def main(argv):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 1)
    for i, path in enumerate(argv):
        (gmsh.open if i == 0 else gmsh.merge)(path)
    if argv and not any(len(gmsh.model.mesh.getElementTypes(d)) for d in (2, 3)):
        gmsh.model.mesh.generate(gmsh.model.getDimension())
    gmsh.onelab.set(json.dumps(parameters()))
    gmsh.option.setNumber("General.MenuWidth", 330)
    gmsh.option.setNumber("General.GraphicsWidth", 760)
    gmsh.option.setNumber("General.GraphicsHeight", 560)
    gmsh.fltk.initialize()
    while gmsh.fltk.isAvailable() and handle_events():
        gmsh.fltk.wait()
    gmsh.finalize()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
