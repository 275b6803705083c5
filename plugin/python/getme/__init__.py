"""getme -- GETMe adaptive mesh smoothing for Python (ctypes over libgetme
and libgetme_gmsh).

    import gmsh, getme
    gmsh.initialize()
    ... build / mesh / open a model with the gmsh module ...
    result = getme.gmsh.optimize(fix=["clamp"], sigma=1.5)
    print(result["q_min_star_before"], result["q_min_star_after"])

getme.gmsh acts on the current model of the Gmsh library loaded in this
process, the very same libgmsh.so the gmsh module uses.  getme.quality()
gives mean-ratio statistics of that model or of numpy arrays.
"""
from ._lib import GetmeError, version
from .quality import quality
from . import gmsh

__all__ = ["GetmeError", "gmsh", "quality", "version"]
__version__ = version()
