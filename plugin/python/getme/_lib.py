"""Loading libgetme / libgetme_gmsh and their ctypes signatures.

The library paths come from _paths.py, written by the build (build tree) or
by `cmake --install` (installed tree).  libgetme_gmsh.so is linked against
libgmsh.so.4.8 by its soname, so the dynamic loader hands it the copy the
gmsh module already loaded: one Gmsh instance, one current model.
"""
import ctypes
import os
from ctypes import (POINTER, c_char_p, c_double, c_int, c_int32, c_int64,
                    c_size_t, c_void_p)

from ._paths import LIBGETME, LIBGETME_GMSH



def _load(path):
    """The recorded path; if the tree was installed under another prefix
    than configured, the soname through the loader's search path."""
    try:
        return ctypes.CDLL(path)
    except OSError:
        return ctypes.CDLL(os.path.basename(path))


core = _load(LIBGETME)
plugin = _load(LIBGETME_GMSH)

STATUS = {0: "ok", 1: "bad argument", 2: "out of memory", 3: "invalid mesh",
          4: "topology", 5: "state", 6: "cancelled"}


class GetmeError(Exception):
    """A libgetme / libgetme_gmsh failure; .status is the getme_status."""

    def __init__(self, message, status=1):
        super().__init__(message)
        self.status = status


HIST_BINS = 10
MAX_REPORTED_INVALID = 8


class QualityStats(ctypes.Structure):
    """getme_quality_stats from getme.h (public, stable layout)."""
    _fields_ = [("num_elements", c_int64), ("num_invalid", c_int64),
                ("num_free", c_int64), ("q_min", c_double),
                ("q_min_star", c_double), ("q_mean", c_double),
                ("q_max", c_double), ("num_below_04", c_int64),
                ("num_below_01", c_int64),
                ("histogram", c_int64 * HIST_BINS),
                ("num_reported_invalid", c_int32),
                ("first_invalid", c_int32 * MAX_REPORTED_INVALID)]


NUM_TYPES = 6
NUM_MEASURES = 6
TYPE_NAMES = ("tet", "hex", "prism", "pyramid", "tri", "quad")
MEASURE_NAMES = ("mean_ratio", "min_dihedral", "max_dihedral",
                 "scaled_jacobian", "gamma", "sicn")


class MeasureStats(ctypes.Structure):
    """getme_measure_stats from getme.h (public, stable layout)."""
    _fields_ = [("num_elements", c_int64), ("num_negative", c_int64),
                ("num_below", c_int64), ("min", c_double),
                ("max", c_double), ("mean", c_double),
                ("min_element", c_int32), ("max_element", c_int32),
                ("hist_lo", c_double), ("hist_hi", c_double),
                ("histogram", c_int64 * HIST_BINS)]


class ParamInfo(ctypes.Structure):
    """getme_param_info from getme.h: one entry of the parameter table."""
    _fields_ = [("name", c_char_p), ("type", c_int), ("default_value", c_double),
                ("min", c_double), ("max", c_double), ("open_min", c_int),
                ("offset", c_size_t), ("help", c_char_p)]


PARAM_TYPES = ("real", "int", "bool", "enum")


def _sig(lib, name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)


_sig(core, "getme_version", c_char_p)
_sig(core, "getme_param_count", c_int)
_sig(core, "getme_param_at", POINTER(ParamInfo), c_int)
_sig(core, "getme_status_string", c_char_p, c_int)
_sig(core, "getme_mesh_create", c_int, POINTER(c_void_p), c_int, c_int32,
     POINTER(c_double))
_sig(core, "getme_mesh_free", None, c_void_p)
_sig(core, "getme_mesh_error", c_char_p, c_void_p)
_sig(core, "getme_mesh_add_elements", c_int, c_void_p, c_int, c_int32,
     POINTER(c_int32), POINTER(c_int32))
_sig(core, "getme_mesh_num_elements", c_int32, c_void_p)
_sig(core, "getme_mesh_quality_stats", c_int, c_void_p, c_int,
     POINTER(QualityStats))
_sig(core, "getme_mesh_element_qualities", c_int, c_void_p,
     POINTER(c_double))
_sig(core, "getme_mesh_measure_all", c_int, c_void_p, POINTER(MeasureStats))
_sig(core, "getme_mesh_element_measures", c_int, c_void_p, c_int,
     POINTER(c_double))
_sig(core, "getme_element_measure", c_double, c_int, c_int,
     POINTER(c_double))

_sig(plugin, "getme_gmsh_options_new", c_void_p)
_sig(plugin, "getme_gmsh_options_free", None, c_void_p)
_sig(plugin, "getme_gmsh_options_set", c_int, c_void_p, c_char_p, c_double)
_sig(plugin, "getme_gmsh_options_set_method", c_int, c_void_p, c_char_p)
_sig(plugin, "getme_gmsh_options_add_fixed_group", c_int, c_void_p, c_char_p)
_sig(plugin, "getme_gmsh_options_error", c_char_p, c_void_p)
_sig(plugin, "getme_gmsh_optimize", c_int, c_int, POINTER(c_int), c_size_t,
     c_void_p, c_void_p)
_sig(plugin, "getme_gmsh_quality", c_int, POINTER(c_int), c_size_t,
     c_void_p, c_void_p)
_sig(plugin, "getme_gmsh_report_sizeof", c_size_t)
_sig(plugin, "getme_gmsh_report_value", c_double, c_void_p, c_char_p)
_sig(plugin, "getme_gmsh_report_message", c_char_p, c_void_p)
_sig(plugin, "getme_gmsh_report_measure", POINTER(MeasureStats), c_void_p,
     c_int, c_int, c_int)
_sig(plugin, "getme_gmsh_model_read", c_int, POINTER(c_void_p), POINTER(c_int),
     c_size_t, c_void_p, c_char_p, c_size_t)
_sig(plugin, "getme_gmsh_model_free", None, c_void_p)
_sig(plugin, "getme_gmsh_model_mesh", c_void_p, c_void_p)
_sig(plugin, "getme_gmsh_model_apply", c_int, c_void_p, POINTER(c_double),
     POINTER(c_int32), c_char_p, c_size_t)
_sig(core, "getme_mesh_coords", POINTER(c_double), c_void_p)
_sig(core, "getme_mesh_distort", c_int, c_void_p, ctypes.c_uint64, c_double,
     c_double, c_int)


def measure_dict(get):
    """{type: {measure: stats}} from get(type, measure) -> MeasureStats,
    for the types present and the measures defined for them (docs/quality.md:
    angles in degrees; min, max, mean, num_negative, and a histogram of
    HIST_BINS equal bins over histogram_range, values below it in
    num_below)."""
    out = {}
    for t, tname in enumerate(TYPE_NAMES):
        per = {}
        for m, mname in enumerate(MEASURE_NAMES):
            s = get(t, m)
            if s.num_elements:
                per[mname] = {"num_elements": s.num_elements,
                              "num_negative": s.num_negative,
                              "num_below": s.num_below, "min": s.min,
                              "max": s.max, "mean": s.mean,
                              "histogram_range": (s.hist_lo, s.hist_hi),
                              "histogram": list(s.histogram)}
        if per:
            out[tname] = per
    return out


def version():
    return core.getme_version().decode()


def status_text(status):
    return core.getme_status_string(status).decode()


def parameters():
    """libgetme's parameter table (getme_param_at): one dict per numeric
    parameter with name, type ("real", "int", "bool", "enum"), default, min,
    max, open_min and help.  The one definition the CLI, the Gmsh options
    and the GUI also use."""
    out = []
    for i in range(core.getme_param_count()):
        p = core.getme_param_at(i).contents
        out.append({"name": p.name.decode(), "type": PARAM_TYPES[p.type],
                    "default": p.default_value, "min": p.min, "max": p.max,
                    "open_min": bool(p.open_min), "help": p.help.decode()})
    return out


def defaults():
    """{name: default} of libgetme's parameter table (getme_params_init's
    values): what every entry point (CLI, Python, GUI) starts from."""
    return {p["name"]: p["default"] for p in parameters()}
