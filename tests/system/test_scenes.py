"""Every scene of options/ runs as a user runs it (``python -m petsc_rod -options_file
options/<scene>.opts``, from the repository's root, on one rank) and converges, with a
result file that says so and holds finite numbers. The scenes' own numbers are checked
where they are named (docs/riser.md, tests/system/test_riser_cli.py); this keeps every
scene runnable as the code changes."""

import glob
import os

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, run_petsc_rod

pytestmark = [pytest.mark.serial, pytest.mark.slow]

SCENES = sorted(os.path.basename(path)[:-5]
                for path in glob.glob(os.path.join(REPO_ROOT, "options", "*.opts")))


def test_there_are_scenes():
    assert len(SCENES) >= 13 and "paper" in SCENES


@pytest.mark.parametrize("scene", SCENES)
def test_every_scene_converges(scene, tmp_path):
    path = tmp_path / f"{scene}.h5"
    done = run_petsc_rod(["-options_file", f"options/{scene}.opts", "-rod_output", str(path)],
                         1, 600)
    text = done.stdout + done.stderr
    assert done.returncode == 0, text
    assert "petsc_rod: converged" in text and "warning" not in text, text
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        for name in ("r", "n", "m", "u"):
            assert np.all(np.isfinite(f[name][:])), name


def test_the_mooring_line_balances_its_weight_clumps_and_seabed(tmp_path):
    """options/mooring_chain.opts: the fairlead's and the anchor's forces balance the
    chain's submerged weight, the three clumps and the seabed's reaction (integrated
    by the trapezoidal rule on the 1 m elements: 1e-4)."""
    path = tmp_path / "mooring.h5"
    done = run_petsc_rod(["-options_file", "options/mooring_chain.opts", "-rod_output",
                          str(path)], 1, 600)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(path, "r") as f:
        n, S, reaction = f["n"][:], f["S"][:], f["seabed_reaction"][:]
        forces = f.attrs["point_load_force"][:]
    w = (286.6 - 1025 * np.pi * 0.2156**2 / 4) * 9.80665
    np.testing.assert_allclose(forces[:, 2], -(10000 - 1025 * 1.274) * 9.80665, rtol=1e-12)
    vertical = w * 850.0 - forces[:, 2].sum() - np.trapz(reaction, S)
    assert abs((n[-1, 2] - n[0, 2]) - vertical) < 1e-4 * abs(n[-1, 2])
    assert abs(n[-1, 0] - n[0, 0]) < 1e-9 * abs(n[0, 0])       # no horizontal load
