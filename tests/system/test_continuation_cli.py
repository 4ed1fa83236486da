"""Halving seen from the command line: the exit code without halvings, and one file group
per accepted step with them (spawns python -m petsc_rod: marked serial)."""

import h5py
import numpy as np
import pytest

from helpers import BENT, PULLED, describe, partial_files, run_petsc_rod
from helpers import HALVING_CTOL as CTOL, HALVING_ELEMENTS as N_ELEMENTS, HALVING_RTOL as RTOL


TIMEOUT = 120


# --- the command line (spawns processes) -------------------------------------------------
def cli_args(case):
    scene = case["scene"]
    return ["-rod_length", "1", "-rod_stiffness", "1,1,1", "-rod_end", "free",
            "-rod_end_force", ",".join(f"{v:g}" for v in scene["end_force"]),
            "-rod_elements", str(N_ELEMENTS), "-rod_al_penalty", f"{case['penalty']:g}",
            "-rod_al_rtol", f"{RTOL:g}", "-rod_al_ctol", f"{CTOL:g}",
            "-rod_al_max_it", str(case["max_it"]), "-rod_snes_type", case["snes_type"],
            "-rod_al_newton", "0"]        # the counts are the iteration's own


def run_cli(args):
    return run_petsc_rod(args, timeout=TIMEOUT)


@pytest.mark.serial
@pytest.mark.parametrize("case, exit_code", [(BENT, 3), (PULLED, 4)],
                         ids=["max_it", "diverged"])
def test_no_halvings_keeps_the_failure_exit_code(tmp_path, case, exit_code):
    path = tmp_path / "failed.h5"
    process = run_cli(cli_args(case) + ["-rod_max_halvings", "0", "-rod_output", str(path)])
    assert process.returncode == exit_code, describe(process)
    assert "halving" not in process.stdout, describe(process)
    assert not partial_files(path)
    if exit_code == 4:
        assert not path.exists()
        return
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 0
        assert list(f["steps"]) == ["1"]


@pytest.mark.serial
def test_halved_run_writes_one_group_per_accepted_step(tmp_path):
    path = tmp_path / "halved.h5"
    process = run_cli(cli_args(BENT) + ["-rod_output", str(path)])
    assert process.returncode == 0, describe(process)
    assert process.stdout.count("halving 1: retrying from load factor 0 with increment 0.5") == 1
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        assert sorted(f["steps"]) == ["1", "2"]
        assert [float(f[f"steps/{k}"].attrs["load_factor"]) for k in "12"] == [0.5, 1.0]
        assert all(0 < int(f[f"steps/{k}"].attrs["iterations"]) < BENT["max_it"]
                   for k in "12")
        assert float(f.attrs["load_factor"]) == 1.0
        assert np.array_equal(f["r"][:], f["steps/2/r"][:])
