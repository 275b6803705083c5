"""Run one benchmark command in its own process under /usr/bin/time -v.

Peak memory is what the OS reports for the process (maximum resident set
size), never an estimate from inside; wall time is measured around the
process.  Tools report the time of the smoothing call itself separately
(getme's --report, the baselines' JSON line).
"""

import json
import os
import re
import subprocess
import tempfile
import time
from dataclasses import dataclass

TIME = "/usr/bin/time"
PYTHON = "/usr/bin/python3"  # Debian's: it has gmsh, netgen, numpy, meshio


@dataclass
class Run:
    cmd: list
    returncode: int
    stdout: str
    stderr: str
    max_rss_kib: int  # peak resident set size reported by the OS
    wall: float       # seconds, whole process

    @property
    def peak_gib(self):
        return self.max_rss_kib / 2**20

    def last_json(self):
        """The last stdout line that parses as a JSON object, or {}."""
        for line in reversed(self.stdout.splitlines()):
            line = line.strip()
            if line.startswith("{"):
                try:
                    return json.loads(line)
                except ValueError:
                    continue
        return {}

    def error_line(self):
        """The most telling line of a failed run, for the log."""
        lines = [ln for ln in self.stderr.splitlines() if ln.strip()
                 and not ln.startswith("\t") and "Command exited" not in ln]
        errors = [ln for ln in lines if ln.startswith("Error")]
        return (errors or lines or [f"exit code {self.returncode}"])[-1]


_RSS = re.compile(r"Maximum resident set size \(kbytes\):\s*(\d+)")


def run(cmd, timeout=None, env=None):
    """Run cmd (a list) under /usr/bin/time -v; never raises on failure."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        full = [TIME, "-v", "-o", tf.name] + [str(c) for c in cmd]
        start = time.perf_counter()
        try:
            proc = subprocess.run(full, capture_output=True, text=True,
                                  timeout=timeout, env=env)
            code, out, err = proc.returncode, proc.stdout, proc.stderr
        except subprocess.TimeoutExpired as exc:
            code = -1
            out = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
            err = f"Error   : timed out after {timeout} s"
        wall = time.perf_counter() - start
        match = _RSS.search(tf.read())
    return Run(cmd=[str(c) for c in cmd], returncode=code, stdout=out,
               stderr=err, max_rss_kib=int(match.group(1)) if match else 0,
               wall=wall)


def cpu_name():
    """'model name' of /proc/cpuinfo and the number of online CPUs."""
    name = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    name = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{name}, {os.cpu_count()} logical CPUs"


def load_average():
    try:
        return os.getloadavg()
    except OSError:
        return (0.0, 0.0, 0.0)
