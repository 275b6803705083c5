"""getme -- GETMe adaptive mesh smoothing for Python (ctypes over libgetme
and libgetme_gmsh).

    import gmsh, getme
    gmsh.initialize()
    ... build / mesh / open a model with the gmsh module ...
    result = getme.gmsh.optimize(fix=["clamp"], sigma=1.5)
    print(result["q_min_star_before"], result["q_min_star_after"])

getme.gmsh acts on the current model of the Gmsh library loaded in this
process, the very same libgmsh.so the gmsh module uses.  getme.quality()
gives mean-ratio statistics of that model or of numpy arrays, plus the
dihedral angles, scaled Jacobian, Gmsh's gamma and SICN per element type;
getme.element_measure() one of them for one element.
"""
from ._lib import GetmeError, parameters, version
from .quality import element_measure, quality
from . import gmsh

__all__ = ["GetmeError", "element_measure", "gmsh", "parameters", "quality",
           "version"]
__version__ = version()
