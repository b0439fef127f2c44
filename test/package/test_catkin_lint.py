"""The package passes catkin_lint (Debian's catkin-lint) with no error and no warning."""
import os
import shutil
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def test_catkin_lint_reports_no_error_or_warning():
    exe = shutil.which("catkin_lint")
    assert exe, "catkin_lint is missing (scripts/common.sh installs Debian's catkin-lint)"
    # -W1: errors and warnings (notices are style hints); --strict: any of them fails.
    run = subprocess.run([exe, "-W1", "--strict", "--pkg", "map_aided_fusion", ROOT],
                         capture_output=True, text=True, timeout=300)
    problems = [ln for ln in (run.stdout + run.stderr).splitlines() if ": error:" in ln or ": warning:" in ln]
    assert run.returncode == 0 and not problems, "\n".join(problems) or run.stdout + run.stderr
