"""The system's verdict on the command line (docs/systems.md "The system's verdict"):
``python -m petsc_rod -rod_system FILE`` on the small free body's deck says "stable"
and exits 0; the same deck with the body's cog 5 m above its reference point (each line
stable with its ends held, the system a saddle in roll and pitch) exits 3 as a single
line's saddle does, the file written with converged = 0 and system_stable = 0, the same
on 1 and 2 ranks. Spawns processes: marked ``serial``."""

import os

import h5py
import pytest

from helpers import REPO_ROOT, describe, run_petsc_rod

pytestmark = pytest.mark.serial

DECK = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "small_free_body.dat")


def top_heavy_deck(folder):
    with open(DECK, encoding="utf-8") as f:
        text = f.read()
    row = "1    Free        0.0    0.0   0     0       0      0      20000 -2"
    assert row in text
    path = folder / "top_heavy.dat"
    path.write_text(text.replace(row, row[:-2] + " 5"), encoding="utf-8")
    return str(path)


def test_a_stable_system_says_so(tmp_path):
    process = run_petsc_rod(["-rod_system", DECK, "-rod_output", str(tmp_path / "s.h5")])
    assert process.returncode == 0, describe(process)
    assert ("  the system's equilibrium: stable (the lowest eigenvalue of its stiffness "
            "7270.88 N/m, mostly in Body1 z)") in process.stdout
    with h5py.File(tmp_path / "s.h5", "r") as f:
        assert int(f["system"].attrs["system_stable"]) == 1
        assert int(f["system"].attrs["converged"]) == 1


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_saddle_of_the_system_exits_3_with_its_file(tmp_path, ranks):
    output = tmp_path / "saddle.h5"
    process = run_petsc_rod(["-rod_system", top_heavy_deck(tmp_path), "-rod_output",
                             str(output)], ranks)
    assert process.returncode == 3, describe(process)
    last = process.stdout.strip().splitlines()[-1]
    assert last.startswith("petsc_rod: error: the system's equilibrium is a saddle of the "
                           "system: its stiffness has 2 negative eigenvalue(s), the lowest "
                           "-8424.5"), last
    assert last.endswith("which says converged = 0"), last
    assert "Traceback" not in process.stderr
    with h5py.File(output, "r") as f:
        assert int(f["system"].attrs["system_stable"]) == 0
        assert int(f["system"].attrs["converged"]) == 0
        assert f["system"].attrs["system_verdict"].startswith("a saddle of the system")


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_line_that_is_a_saddle_makes_the_system_one(tmp_path, ranks):
    """200 kN on the body along +x: the leeward chain, slack, is a saddle of its energy
    with its ends held (the lines' table says SADDLE), so the whole system is one
    (system/verdict.py: the lines' Hessians beside K, Sylvester), whatever its stiffness
    K says (positive definite here): exit 3, converged = 0, system_stable = 0. Before,
    the run said "stable" and exited 0, and a watch circle reached other equilibria
    there from other neighbours."""
    output = tmp_path / "pushed.h5"
    process = run_petsc_rod(["-rod_system", DECK, "-rod_system_element_length", "5",
                             "-rod_system_body_load", "Body1,200e3,0,0,0,0,0",
                             "-rod_output", str(output)], ranks)
    assert process.returncode == 3, describe(process)
    assert ("  the system's equilibrium: a saddle of the system: line Line1 is a saddle "
            "of its energy with the ends held") in process.stdout, describe(process)
    with h5py.File(output, "r") as f:
        assert int(f["system"].attrs["system_stable"]) == 0
        assert int(f["system"].attrs["converged"]) == 0
