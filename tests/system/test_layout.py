"""The layout: a run (python -m petsc_rod) never imports the validation code
(petsc_rod.validation) nor scipy, which only the validation code uses.

The test spawns processes, so it is marked ``serial`` (skipped inside an MPI run).
"""

import json
import subprocess
import sys

import pytest

from helpers import REPO_ROOT, child_env

pytestmark = pytest.mark.serial


# What ``python -m petsc_rod ARGS`` does (petsc_rod/__main__.py), then the modules loaded.
CHILD = """
import json, sys
from petsc_rod.__main__ import main
sys.argv = ["petsc_rod"] + sys.argv[1:]
code = main()
print("MODULES " + json.dumps(sorted(m for m in sys.modules
                                     if m.startswith(("petsc_rod.validation", "scipy")))))
sys.exit(code)
"""

SCENES = {
    "cantilever": ["-options_file", "options/cantilever.opts", "-rod_elements", "8"],
    "catenary start": ["-options_file", "options/catenary.opts", "-rod_elements", "100"],
    "system": ["-rod_system", "tests/data/moordyn/small_spread.dat"],
}


@pytest.mark.parametrize("scene", SCENES)
def test_a_run_imports_neither_validation_nor_scipy(scene, tmp_path):
    args = SCENES[scene] + ["-rod_output", str(tmp_path / "out.h5")]
    process = subprocess.run([sys.executable, "-c", CHILD] + args, cwd=REPO_ROOT,
                             env=child_env(), capture_output=True, text=True, timeout=120,
                             check=False)
    report = f"exit {process.returncode}\nstdout:\n{process.stdout}\nstderr:\n{process.stderr}"
    lines = [line for line in process.stdout.splitlines() if line.startswith("MODULES ")]
    assert len(lines) == 1, report
    assert json.loads(lines[0].split(" ", 1)[1]) == [], report
    assert process.returncode == 0, report
