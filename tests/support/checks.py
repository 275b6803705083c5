"""The check / run helpers of the Python-hosted getme command tests
(test_cli.py, test_safety.py): count what passed, print what failed, run
the command and check its exit code."""
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
