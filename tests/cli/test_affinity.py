#!/usr/bin/python3
"""The getme command's restart for passive waiting keeps the CPUs it got.

usage: /usr/bin/python3 test_affinity.py GETME_BINARY

Without OMP_WAIT_POLICY, `getme` sets it to passive and re-executes itself
(cli/main.c).  With binding asked for (OMP_PROC_BIND, OMP_PLACES), libgomp
binds the initial thread to its first place before main() runs, and the
re-executed process used to inherit that one-CPU mask: every thread ran on
one CPU (twice as slow on 2 threads).  OMP_DISPLAY_ENV makes libgomp print
its settings at start-up, once per process, so the last OMP_PLACES line is
the re-executed process's view.  Asserted:
  - with OMP_PROC_BIND=true, and with OMP_PLACES=cores, the re-executed
    process has as many places as the first one had, and at least 2;
  - started on one CPU (a narrowed mask, as taskset gives), it keeps that
    one CPU: the restart does not widen the mask it was given;
  - without binding no places are listed, and with OMP_WAIT_POLICY set
    there is no restart (one settings block).
Needs 2 CPUs; skipped (exit 77) with fewer.
"""
import os
import re
import sys

# tests/support is on PYTHONPATH (set by ctest)
from checks import Checks

GETME = sys.argv[1]
CPUS = sorted(os.sched_getaffinity(0))
if len(CPUS) < 2:
    print("skipped: needs 2 CPUs, this process may use", len(CPUS))
    sys.exit(77)

T = Checks(GETME)
check = T.check


def places(env, cpus=None):
    """The OMP_PLACES lines (one per process start) of `getme version`."""
    e = {k: v for k, v in os.environ.items()
         if not k.startswith(("OMP_", "GOMP_"))}
    e.update(env, OMP_DISPLAY_ENV="true")
    pre = (lambda: os.sched_setaffinity(0, cpus)) if cpus else None
    r = T.run("version", env=e, preexec_fn=pre)
    return re.findall(r"OMP_PLACES = '([^']*)'", r.stderr + r.stdout)


def count(p):
    return p.count("{")


for env in ({"OMP_PROC_BIND": "true"}, {"OMP_PLACES": "cores"}):
    got = places(env)
    check(len(got) == 2, "%s: restarted once (%d settings blocks)"
          % (env, len(got)))
    if len(got) == 2:
        check(count(got[0]) >= 2 and count(got[1]) == count(got[0]),
              "%s: the restarted process has the first one's places "
              "(%s, then %s)" % (env, got[0], got[1]))

one = [CPUS[-1]]
got = places({"OMP_PROC_BIND": "true"}, cpus=one)
check(len(got) == 2 and got[-1] == "{%d}" % one[0],
      "started on CPU %d only: still only there after the restart (%s)"
      % (one[0], got))

got = places({})
check(len(got) == 2 and got == ["", ""], "no binding: no places (%s)" % got)
got = places({"OMP_WAIT_POLICY": "active", "OMP_PROC_BIND": "true"})
check(len(got) == 1, "OMP_WAIT_POLICY set: no restart (%d settings blocks)"
      % len(got))

sys.exit(T.summary())
