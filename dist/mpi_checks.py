"""The start every getme-mpi test (test_mpi*.py) shares: its command line,
the environment its MPI runs need and the Checks that counts its results.
Imported by name (dist/CMakeLists.txt puts dist/ and tests/support on
PYTHONPATH).

usage: test_mpi*.py GETME_MPI GETME MPIEXEC SOURCE_DIR [--sanitized]
"""
import atexit
import os
import shutil
import sys
import tempfile

from checks import Checks

GETME_MPI, GETME, MPIEXEC, SRC = sys.argv[1:5]
SANITIZED = "--sanitized" in sys.argv[5:]
# Passive OpenMP waits keep oversubscribed ranks from spinning; the
# OMPI_* settings let the tests run as root (CI containers) and start more
# ranks than cores.
ENV = dict(os.environ, OMP_WAIT_POLICY="passive", OMPI_ALLOW_RUN_AS_ROOT="1",
           OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_rmaps_base_oversubscribe="1")
# Each test's mpiexec keeps its session directory under a tree of its own:
# in the shared /tmp/ompi.HOST.UID, one test's mpiexec removing the tree
# as it ends could fail another's start ("orte_session_dir failed",
# seen once with ctest -j2 in a clean-clone .ci/run).
SESSION_DIR = tempfile.mkdtemp(prefix="getme-ompi-")
atexit.register(shutil.rmtree, SESSION_DIR, ignore_errors=True)
ENV["OMPI_MCA_orte_tmpdir_base"] = SESSION_DIR
if SANITIZED:
    # Open MPI's own start-up allocations are never freed.
    ENV["ASAN_OPTIONS"] = "detect_leaks=0"
c = Checks(GETME)


def why(p, tail=400):
    """What a failed run said: its "Error" lines (Open MPI's abort notice
    after them would push them out of a plain tail), then the tail."""
    errs = [ln for ln in p.stderr.splitlines() if ln.startswith("Error")]
    return "\n".join(errs[:5]) + ("\n" if errs else "") + p.stderr[-tail:]
