"""getme.quality(): mean-ratio statistics of the current Gmsh model or of
numpy arrays (nodes + elements)."""
import ctypes
from ctypes import POINTER, c_double, c_int32, c_void_p

import numpy as np

from . import _lib
from ._lib import GetmeError, QualityStats

TYPES = {"tet": 0, "hex": 1, "prism": 2, "pyramid": 3, "tri": 4, "quad": 5}
NODES = {"tet": 4, "hex": 8, "prism": 6, "pyramid": 5, "tri": 3, "quad": 4}


def stats_dict(s):
    """A getme_quality_stats as a plain dict."""
    return {"num_elements": s.num_elements, "num_invalid": s.num_invalid,
            "num_free": s.num_free, "q_min": s.q_min,
            "q_min_star": s.q_min_star, "q_mean": s.q_mean,
            "q_max": s.q_max, "num_below_04": s.num_below_04,
            "num_below_01": s.num_below_01,
            "histogram": list(s.histogram)}


def _mesh_measures(mesh):
    table = (_lib.MeasureStats * (_lib.NUM_TYPES * _lib.NUM_MEASURES))()
    st = _lib.core.getme_mesh_measure_all(mesh, table)
    if st:
        raise GetmeError(_lib.core.getme_mesh_error(mesh).decode(), st)
    return _lib.measure_dict(lambda t, m: table[t * _lib.NUM_MEASURES + m])


def element_measure(kind, measure, xyz):
    """One measure ("mean_ratio", "min_dihedral", "max_dihedral",
    "scaled_jacobian", "gamma", "sicn") of one element of kind "tet", ...
    with nodes xyz ((nv, 3) array, getme/Gmsh node order); NaN where the
    measure is not defined (gamma of hex and pyramid)."""
    x = np.ascontiguousarray(xyz, dtype=np.float64)
    if x.shape != (NODES[kind], 3):
        raise GetmeError("a %s needs a (%d, 3) array" % (kind, NODES[kind]))
    return _lib.core.getme_element_measure(
        TYPES[kind], _lib.MEASURE_NAMES.index(measure),
        x.ctypes.data_as(POINTER(c_double)))


def _array_quality(nodes, elements):
    xyz = np.ascontiguousarray(nodes, dtype=np.float64)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise GetmeError("nodes must be an (n, 3) array")
    dims = {3 if TYPES[t] < 4 else 2 for t in elements}
    if len(dims) != 1:
        raise GetmeError("elements mix volume and planar types")
    mesh = c_void_p()
    st = _lib.core.getme_mesh_create(ctypes.byref(mesh), dims.pop(),
                                     len(xyz),
                                     xyz.ctypes.data_as(POINTER(c_double)))
    if st:
        raise GetmeError(_lib.status_text(st), st)
    try:
        for name, conn in elements.items():
            c = np.ascontiguousarray(conn, dtype=np.int32)
            if c.ndim != 2 or c.shape[1] != NODES[name]:
                raise GetmeError("%s connectivity must be (m, %d)"
                                 % (name, NODES[name]))
            st = _lib.core.getme_mesh_add_elements(
                mesh, TYPES[name], len(c), c.ctypes.data_as(POINTER(c_int32)),
                None)
            if st:
                raise GetmeError(_lib.core.getme_mesh_error(mesh).decode(),
                                 st)
        s = QualityStats()
        _lib.core.getme_mesh_quality_stats(mesh, -1, ctypes.byref(s))
        q = np.empty(_lib.core.getme_mesh_num_elements(mesh))
        _lib.core.getme_mesh_element_qualities(
            mesh, q.ctypes.data_as(POINTER(c_double)))
        out = stats_dict(s)
        out["qualities"] = q
        out["measures"] = _mesh_measures(mesh)
        return out
    finally:
        _lib.core.getme_mesh_free(mesh)


def quality(nodes=None, elements=None, dimTags=()):
    """Mean-ratio statistics.

    quality(nodes, elements): nodes an (n, 3) array, elements a dict
    {"tet": (m, 4) zero-based int array, "hex": ..., ...}; the result also
    holds "qualities", one value per element in dict order.
    Both forms also give "measures": {type: {measure: {"min", "max",
    "mean", "num_elements", "num_negative", "histogram", ...}}} for the
    dihedral angles, scaled Jacobian, Gmsh's gamma and SICN
    (docs/quality.md).
    quality(dimTags=[...]): the current Gmsh model (same entity selection
    as getme.gmsh.optimize; q_min_star over elements with a free node).
    """
    if nodes is not None:
        return _array_quality(nodes, elements or {})
    from .gmsh import model_quality
    return model_quality(dimTags)
