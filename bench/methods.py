"""The smoothing methods the benchmark compares and how each is invoked.

Every method runs in its own process on the same distorted file and writes a
new file; the benchmark then reads that file back and measures it itself.
"""

import os
from dataclasses import dataclass, field

from runner import PYTHON

HERE = os.path.dirname(os.path.abspath(__file__))
VOLUME_CASES = ("tet", "hex", "mixed")
PLANAR_CASES = ("tri", "quad")


@dataclass(frozen=True)
class Method:
    key: str                 # short id: file names, CSV
    label: str               # table row name
    tool: str                # "getme", "gmsh" or "netgen"
    args: tuple = ()         # tool specific (see command())
    cases: tuple = VOLUME_CASES + PLANAR_CASES
    relocation_only: bool = True  # by design; the table checks it anyway
    params: tuple = field(default=())  # extra --param name=value for getme


def _getme(key, label, method, threads, params=()):
    return Method(key, label, "getme", ("--method", method, "--threads", str(threads)),
                  params=params)


# The paper's GETMe adaptive alone: no finishing step, no corner guard
# (README "Method notes"), for the before/after comparison of issue #9.
PAPER = (("finish", 0), ("corner_guard", 0))

METHODS = (
    _getme("getme-1", "GETMe adaptive", "getme", 1),
    _getme("getme-2", "GETMe adaptive (2 threads)", "getme", 2),
    _getme("paper-1", "GETMe adaptive, paper only", "getme", 1, PAPER),
    _getme("paper-2", "GETMe adaptive, paper only (2 threads)", "getme", 2, PAPER),
    _getme("laplace-1", "Smart Laplace", "laplace", 1),
    _getme("laplace-2", "Smart Laplace (2 threads)", "laplace", 2),
    # Gmsh 4.8's own optimizers.  "" is its tet optimizer (it also flips and
    # removes tets); on a pure hex mesh it has nothing to do.
    Method("gmsh-default", 'Gmsh optimize("")', "gmsh", ("",),
           cases=VOLUME_CASES, relocation_only=False),
    Method("gmsh-relocate3d", 'Gmsh optimize("Relocate3D")', "gmsh",
           ("Relocate3D",), cases=VOLUME_CASES),
    # the 2-D ones need the surface parametrized (see gmsh_baseline.py)
    Method("gmsh-laplace2d", 'Gmsh optimize("Laplace2D")', "gmsh",
           ("Laplace2D", "--create-geometry"), cases=PLANAR_CASES),
    Method("gmsh-relocate2d", 'Gmsh optimize("Relocate2D")', "gmsh",
           ("Relocate2D", "--create-geometry"), cases=PLANAR_CASES),
    # Netgen's OptimizeVolume: tets only, and it remeshes locally.
    Method("netgen", "Netgen OptimizeVolumeMesh", "netgen", cases=("tet",),
           relocation_only=False),
)


def command(method, getme, src, dst, report, params=()):
    """The command line that runs method on src and writes dst (getme: the
    command prefix, the CLI or the ctypes stand-in)."""
    if method.tool == "getme":
        cmd = [*getme, "smooth", src, "-o", dst, *method.args, "--report", report]
        for name, value in tuple(method.params) + tuple(params):
            cmd += ["--param", f"{name}={value}"]
        return cmd
    if method.tool == "gmsh":
        return [PYTHON, os.path.join(HERE, "gmsh_baseline.py"), src, dst,
                "--method", method.args[0], *method.args[1:]]
    if method.tool == "netgen":
        return [PYTHON, os.path.join(HERE, "netgen_baseline.py"), src, dst]
    raise ValueError(method.tool)


def baseline_command(method, getme, src, dst):
    """A run of the same tool that loads (and writes) the mesh but does not
    smooth it: its peak memory is subtracted to give the smoothing's own."""
    if method.tool == "getme":
        return [*getme, "quality", src]
    return command(method, getme, src, dst, None) + ["--load-only"]


def baseline_key(method):
    """Methods whose baseline runs are the same share one."""
    return method.tool if method.tool != "gmsh" else ("gmsh",) + tuple(method.args[1:])


def netgen_available():
    import importlib.util
    return importlib.util.find_spec("netgen") is not None
