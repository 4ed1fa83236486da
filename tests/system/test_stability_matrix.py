"""The CI subset of the stability matrix (scripts/stability_matrix.py, docs/stability.md):
each case run as a user runs it, on 1 rank and under mpiexec -n 2, must give the same
outcome; a converged case must be within its bound of the closed form, with the same
iteration count and the same centreline on both rank counts.

Serial: the cases are child processes (mpiexec cannot nest).
"""

import importlib.util
import os

import numpy as np
import pytest

from helpers import REPO_ROOT, child_env

pytestmark = pytest.mark.serial

SCRIPT = os.path.join(REPO_ROOT,
                      "scripts", "stability_matrix.py")


def load_script():
    spec = importlib.util.spec_from_file_location("stability_matrix", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


MATRIX = load_script()
CI_CASES = [case for case in MATRIX.cases() if case.ci]


def test_the_ci_subset_covers_every_outcome_kind():
    groups = {case.group for case in CI_CASES}
    assert {"stiffness", "penalty", "mesh", "catenary", "tolerance"} <= groups


@pytest.mark.parametrize("case", CI_CASES, ids=[case.name for case in CI_CASES])
def test_same_result_on_one_and_two_ranks(case, tmp_path):
    runs = {}
    for ranks in (1, 2):
        folder = tmp_path / f"ranks{ranks}"
        folder.mkdir()
        runs[ranks] = MATRIX.run_case(case, str(folder), ranks=ranks, env=child_env())
    (one, result_one), (two, result_two) = runs[1], runs[2]
    assert one["outcome"] == two["outcome"], (one, two)
    assert one["outcome"] in ("converged", "stopped"), one
    if case.notes.startswith("expected: stopped"):
        assert one["outcome"] == "stopped" and "stalled" in one["reason"], one
        return
    assert one["outcome"] == "converged", one
    assert one["iterations"] == two["iterations"]
    scale = np.abs(result_one["r"]).max()
    assert np.abs(result_one["r"] - result_two["r"]).max() <= 1e-9 * scale
    assert float(one["error"]) <= float(one["bound"])
    assert float(one["error"]) == pytest.approx(float(two["error"]), rel=1e-3, abs=1e-12)
