"""getme.gmsh: GETMe adaptive smoothing of the current Gmsh model.

Mirrors gmsh.model.mesh.optimize(method, force, niter, dimTags):

    getme.gmsh.optimize(niter=0, dimTags=[], method="getme", fix=[],
                        log=2, **params)

niter      maximum iterations (0: max_iter, default 1000)
dimTags    [(dim, tag), ...] of one dimension (3, or 2 for planar surfaces);
           empty: every entity of the highest mesh dimension
method     "getme" (GETMe adaptive) or "laplace" (smart Laplace)
fix        physical group names (or "dim:tag") whose nodes stay fixed
log        0 silent, 1 summary + histograms, 2 also one line per iteration
params     any libgetme parameter: sigma, max_iter, tol, threshold_fraction,
           max_no_min_improve, min_tol, keep_best, finish (1: finishing
           step after the q*min stage; 0: the paper's method alone),
           finish_fraction, finish_max_passes, corner_guard, corner_floor,
           num_threads, renumber, untangle (1 by default: a mesh with
           inverted elements is untangled first, with a Gmsh warning giving
           the counts; 0 refuses it); and fix_skin, fix_interfaces,
           allow_invalid (0/1), topology (1: Gmsh's own optimize("") first
           when some of the worst elements have no free node; tet meshes),
           worst (0..10)

Returns a dict: iterations (total, mean stage, min stage, cycles,
finishing passes), q_min_star / q_min / q_mean before and after, the worst
corner scaled Jacobian before and after, nodes moved, seconds, "worst" and
"worst_free": the worst elements (all, and those with a free node) as
dicts {"tag", "type", "quality", "corner_sj", "num_free", "num_nodes",
"reason"} with reason one of "improvable", "all_nodes_fixed",
"fixed_interface", "local_optimum"; "topology": what Gmsh's optimizer did
(option topology=1) or None; and
measures_before / measures_after: {type: {measure: {"min", "max", "mean",
"num_elements", "num_negative", "histogram", ...}}} for the dihedral
angles, scaled Jacobian, Gmsh's gamma and SICN (docs/quality.md), and
"untangle": invalid_before / invalid_after / sweeps / nodes_moved /
seconds / ho_invalid / ho_repaired / ho_moved (second-order elements
invalid only at their mid-nodes, those of them repaired, and the mid-nodes
moved) of the untangling step; "second_order": None, or for a mesh with
second-order elements {"elements", "jacobian_ratio_before",
"jacobian_ratio_after", "element_before", "element_after"}: the worst
ratio of the smallest to the largest det J over an element's nodes, and
that element's Gmsh tag (docs/highorder.md).
Raises getme.GetmeError (with the Gmsh-logged message) on bad use, and with
status 3 when inverted elements could not be untangled (the message names
them by their Gmsh tags); the model is then unchanged, except with
allow_invalid=1, which writes the partly untangled coordinates.
"""
import ctypes
import os

from . import _lib
from ._lib import GetmeError
from .quality import stats_dict

_VALUES = ("dim", "num_entities", "num_nodes", "num_elements", "num_fixed",
           "num_moved", "wall", "cpu", "iterations", "iterations_mean",
           "iterations_min", "cycles_min", "threshold", "passes_finish",
           "moved_finish", "corner_sj_before", "corner_sj_after",
           "reverted_nodes")
_TYPES = ("tet", "hex", "prism", "pyramid", "tri", "quad")
_REASONS = ("improvable", "all_nodes_fixed", "fixed_interface",
            "local_optimum")


def _worst_list(val, which):
    out = []
    for i in range(int(val("num_" + which))):
        get = lambda k: val("%s%d_%s" % (which, i, k))  # noqa: E731
        out.append({"tag": int(get("tag")), "type": _TYPES[int(get("type"))],
                    "quality": get("quality"), "corner_sj": get("corner_sj"),
                    "num_free": int(get("num_free")),
                    "num_nodes": int(get("num_nodes")),
                    "reason": _REASONS[int(get("reason"))]})
    return out


def _options(method, fix, log, params):
    opt = _lib.plugin.getme_gmsh_options_new()
    if not opt:
        raise GetmeError("out of memory", 2)
    try:
        if _lib.plugin.getme_gmsh_options_set_method(opt, method.encode()):
            raise GetmeError(_lib.plugin.getme_gmsh_options_error(opt)
                             .decode())
        for name, value in dict(params, log=log).items():
            if _lib.plugin.getme_gmsh_options_set(opt, name.encode(),
                                                   float(value)):
                raise GetmeError(_lib.plugin.getme_gmsh_options_error(opt)
                                 .decode())
        for group in fix:
            _lib.plugin.getme_gmsh_options_add_fixed_group(
                opt, str(group).encode())
        return opt
    except Exception:
        _lib.plugin.getme_gmsh_options_free(opt)
        raise


def _dim_tags(dimTags):
    flat = [int(v) for pair in dimTags for v in pair]
    arr = (ctypes.c_int * max(len(flat), 1))(*flat)
    return arr, len(flat)


def _report_dict(rep):
    val = lambda name: _lib.plugin.getme_gmsh_report_value(rep,  # noqa: E731
                                                           name.encode())
    out = {k: val(k) for k in _VALUES}
    for k in ("dim", "num_entities", "num_nodes", "num_elements",
              "num_fixed", "num_moved", "iterations", "iterations_mean",
              "iterations_min", "cycles_min", "passes_finish",
              "moved_finish", "reverted_nodes"):
        out[k] = int(out[k])
    out["worst"] = _worst_list(val, "worst")
    out["worst_free"] = _worst_list(val, "worst_free")
    out["topology"] = None
    if val("topology_ran") == 1:
        out["topology"] = {k: int(val("topology_" + k)) for k in
                           ("changed", "elements_before", "elements_after")}
    out["seconds"] = out.pop("wall")
    for when in ("before", "after"):
        for k in ("q_min_star", "q_min", "q_mean", "q_max"):
            out["%s_%s" % (k, when)] = val("%s_%s" % (when, k))
        out["num_invalid_" + when] = int(val(when + "_num_invalid"))
        out["histogram_" + when] = [int(val("%s_hist%d" % (when, b)))
                                    for b in range(_lib.HIST_BINS)]
        after = when == "after"
        out["measures_" + when] = _lib.measure_dict(
            lambda t, m: _lib.plugin.getme_gmsh_report_measure(
                rep, after, t, m).contents)
    out["untangle"] = {k: val("untangle_" + k) for k in
                       ("invalid_before", "invalid_after", "sweeps", "moved",
                        "seconds", "ho_invalid", "ho_repaired", "ho_moved")}
    for k in ("invalid_before", "invalid_after", "sweeps", "moved",
              "ho_invalid", "ho_repaired", "ho_moved"):
        out["untangle"][k] = int(out["untangle"][k])
    out["untangle"]["nodes_moved"] = out["untangle"].pop("moved")
    out["second_order"] = None
    if val("num_second_order") > 0:
        out["second_order"] = {
            "elements": int(val("num_second_order")),
            "jacobian_ratio_before": val("jacobian_ratio_before"),
            "jacobian_ratio_after": val("jacobian_ratio_after"),
            "element_before": int(val("jacobian_ratio_tag_before")),
            "element_after": int(val("jacobian_ratio_tag_after"))}
    return out


def _run(fn, dimTags, method="getme", fix=(), log=0, niter=None, **params):
    opt = _options(method, fix, log, params)
    rep = ctypes.create_string_buffer(_lib.plugin.getme_gmsh_report_sizeof())
    arr, n = _dim_tags(dimTags)
    try:
        if niter is None:
            st = fn(arr, n, opt, rep)
        else:
            st = fn(int(niter), arr, n, opt, rep)
        if st not in (0, 6):
            raise GetmeError(_lib.plugin.getme_gmsh_report_message(rep)
                             .decode(), st)
        return rep
    finally:
        _lib.plugin.getme_gmsh_options_free(opt)


def optimize(niter=0, dimTags=(), method="getme", fix=(), log=2, **params):
    """Smooth the current Gmsh model in place (see the module help)."""
    rep = _run(_lib.plugin.getme_gmsh_optimize, dimTags, method, fix, log,
               niter, **params)
    return _report_dict(rep)


def model_quality(dimTags=(), fix=()):
    """Mean-ratio statistics of the current Gmsh model (nothing moves)."""
    rep = _run(_lib.plugin.getme_gmsh_quality, dimTags, "getme", fix, 0)
    d = _report_dict(rep)
    return {"num_elements": d["num_elements"], "num_nodes": d["num_nodes"],
            "num_fixed": d["num_fixed"], "q_min": d["q_min_before"],
            "q_min_star": d["q_min_star_before"],
            "q_mean": d["q_mean_before"], "q_max": d["q_max_before"],
            "num_invalid": d["num_invalid_before"],
            "histogram": d["histogram_before"],
            "measures": d["measures_before"]}


def distort(seed=1, amount=0.4, rounds=5, dimTags=(), fix=()):
    """Distort the current model for demos and benchmarks: libgetme's
    random validity-preserving moves of the nodes optimize() may move
    (getme_mesh_distort), written back like optimize() does.  Returns the
    number of nodes moved."""
    opt = _options("getme", fix, 0, {})
    model = ctypes.c_void_p()
    msg = ctypes.create_string_buffer(512)
    arr, n = _dim_tags(dimTags)
    try:
        st = _lib.plugin.getme_gmsh_model_read(ctypes.byref(model), arr, n,
                                               opt, msg, 512)
        if st:
            raise GetmeError(msg.value.decode(), st)
        mesh = _lib.plugin.getme_gmsh_model_mesh(model)
        st = _lib.core.getme_mesh_distort(mesh, seed, amount, 0.0, rounds)
        if st:
            raise GetmeError(_lib.core.getme_mesh_error(mesh).decode(), st)
        moved = ctypes.c_int32()
        st = _lib.plugin.getme_gmsh_model_apply(
            model, _lib.core.getme_mesh_coords(mesh), ctypes.byref(moved),
            msg, 512)
        if st:
            raise GetmeError(msg.value.decode(), st)
        return moved.value
    finally:
        _lib.plugin.getme_gmsh_model_free(model)
        _lib.plugin.getme_gmsh_options_free(opt)


def loaded_gmsh_libraries():
    """Paths of every libgmsh mapped in this process (expect exactly one)."""
    paths = set()
    with open("/proc/self/maps") as maps:
        for line in maps:
            path = line.split()[-1] if len(line.split()) >= 6 else ""
            if "libgmsh" in os.path.basename(path):
                paths.add(os.path.realpath(path))
    return sorted(paths)


__all__ = ["optimize", "model_quality", "distort", "loaded_gmsh_libraries",
           "stats_dict"]
