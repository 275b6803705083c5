"""The check / run helpers of the Python-hosted getme command tests
(test_cli.py, test_safety.py, the getme-mpi tests): count what passed,
print what failed, run the command and check its exit code."""
import os
import subprocess


class Checks:
    def __init__(self, getme):
        self.getme = getme
        self.passed = 0
        self.failures = []

    def check(self, cond, what):
        if cond:
            self.passed += 1
        else:
            self.failures.append(what)
            print("FAILED:", what, flush=True)

    def run(self, *args, expect=0, **kwargs):
        """getme ARGS..., checking the exit code (output kept on failure)."""
        p = subprocess.run([self.getme, *args], capture_output=True, text=True,
                           **kwargs)
        if p.returncode != expect:
            print(p.stdout[-3000:], p.stderr[-3000:])
        self.check(p.returncode == expect,
                   f"getme {' '.join(args)} -> {p.returncode}, want {expect}")
        return p

    def summary(self):
        """Print the counts; the exit status for sys.exit."""
        print(f"{self.passed} passed, {len(self.failures)} failed")
        return 1 if self.failures else 0


class WorkChecks:
    """The check / path / run helpers of the tests that write into one work
    folder (the second-order tests, test_msh_native.py): failures are
    printed as they happen and collected in .failed, which each test turns
    into its exit code."""

    def __init__(self, getme, work):
        self.getme = getme
        self.work = work
        self.failed = []
        os.makedirs(work, exist_ok=True)

    def check(self, cond, what):
        if not cond:
            self.failed.append(what)
            print("FAIL:", what, flush=True)

    def path(self, name):
        return os.path.join(self.work, name)

    def run(self, *args, threads=2):
        """getme ARGS... with THREADS OpenMP threads (passive waits: the
        tests share the machine with other jobs)."""
        env = dict(os.environ, OMP_NUM_THREADS=str(threads),
                   OMP_WAIT_POLICY="passive")
        return subprocess.run([self.getme] + list(args), capture_output=True,
                              text=True, env=env)
