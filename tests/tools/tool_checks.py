"""Shared helpers of the tools/ tests: run a command and check its exit code, assert a fact."""
import subprocess
import sys


def run(cmd, expect_rc=0, env=None):
    """Runs `cmd`; exits the test when the exit code is not `expect_rc` (None: any non-zero)."""
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    ok = r.returncode != 0 if expect_rc is None else r.returncode == expect_rc
    if not ok:
        want = "non-zero" if expect_rc is None else str(expect_rc)
        sys.exit(f"FAIL: {' '.join(cmd)} returned {r.returncode}, expected {want}\n{r.stdout}\n{r.stderr}")
    return r


def check(cond, what):
    if not cond:
        sys.exit(f"FAIL: {what}")
    print(f"ok: {what}")
