"""The system's verdict at each case of a sweep on the command line (docs/systems.md
"Excursions and the watch circle", docs/errors.md): the small free body's watch circle
says "all stable" and exits 0; the body with Line1 crossed under it
(tests/data/moordyn/crossed_line.dat), stable at rest, is a saddle of the system in yaw
under 60 kN towards -x: its load-excursion curve (0 and 60 kN at heading 180 deg) keeps
the saddle's row, marked ``saddle`` in the table and 0 in the file's ``verdict``, says
it in the run's lines and exits 3 as a saddle at rest does, the sweep's group with
converged = 0 (the rest's ``system`` group converged = 1), on 1 and 2 ranks; a case of
a system's sweep (python -m petsc_rod.sweep -rod_system) whose equilibrium is that
saddle exits 3 as its run alone does, its file written. Spawns processes: marked
``serial``."""

import json
import os

import h5py
import pytest

from helpers import REPO_ROOT, describe, run_petsc_rod
from test_sweep_cli import run_module

pytestmark = pytest.mark.serial

DATA = os.path.join(REPO_ROOT, "tests", "data", "moordyn")


def test_the_small_free_bodys_watch_circle_is_all_stable(tmp_path):
    process = run_petsc_rod(["-rod_system", os.path.join(DATA, "small_free_body.dat"),
                             "-rod_system_watch_circle", "Body1,2e4,2", "-rod_output",
                             str(tmp_path / "s.h5")])
    assert process.returncode == 0, describe(process)
    assert ("petsc_rod: watch circle: 2 heading(s), the system's verdict: all stable"
            in process.stdout.splitlines()), process.stdout
    with h5py.File(tmp_path / "s.h5", "r") as f:
        group = f["system/watch_circle"]
        assert group["verdict"][()].tolist() == [1.0, 1.0]
        assert min(group["lowest_eigenvalue"][()]) > 1e3
        assert int(group.attrs["converged"]) == 1 and group.attrs["system_verdict"] == \
            "all stable"


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_saddle_in_the_curves_exits_3_with_its_row_marked(tmp_path, ranks):
    output = tmp_path / "crossed.h5"
    process = run_petsc_rod(["-rod_system", os.path.join(DATA, "crossed_line.dat"),
                             "-rod_system_element_length", "2",
                             "-rod_system_excursion", "Body1,6e4,1,180",
                             "-rod_output", str(output), "-rod_table",
                             str(tmp_path / "crossed.csv")], ranks)
    assert process.returncode == 3, describe(process)
    said = process.stdout.strip().splitlines()
    assert "  the system's equilibrium: stable (" in process.stdout      # at rest
    assert ("petsc_rod: load-excursion curves: 2 case(s), the system's verdict: 1 "
            "saddle(s) of the system: heading 180 deg under 60000 N; 1 stable") in said
    assert said[-1].startswith("petsc_rod: error: the load-excursion curves of Body1 have "
                               "1 saddle(s) of the system: heading 180 deg under 60000 N: "
                               ), said[-1]
    assert said[-1].endswith("whose system/excursion says converged = 0"), said[-1]
    assert "Traceback" not in process.stderr
    rows = [row.split(",") for row in
            (tmp_path / "crossed_excursion.csv").read_text().splitlines()]
    column = rows[0].index("verdict")
    assert rows[0][column + 1] == "lowest_eigenvalue (N/m)"
    assert [row[1] for row in rows[1:]] == ["0", "60000"]
    assert [row[column] for row in rows[1:]] == ["stable", "saddle"]
    assert float(rows[1][column + 1]) > 0 > float(rows[2][column + 1])
    with h5py.File(output, "r") as f:
        assert int(f["system"].attrs["converged"]) == 1
        assert int(f["system"].attrs["system_stable"]) == 1
        group = f["system/excursion"]
        assert group["verdict"][()].tolist() == [1.0, 0.0]
        assert int(group.attrs["converged"]) == 0 and int(group.attrs["saddles"]) == 1


def test_a_system_sweeps_case_at_a_saddle_exits_3(tmp_path):
    cases = tmp_path / "cases.txt"
    cases.write_text("name rod_system_body_load\npushed Body1,-6e4,0,0,0,0,0\n")
    folder = tmp_path / "sweep"
    process = run_module("petsc_rod.sweep", [
        "-rod_system", os.path.join(DATA, "crossed_line.dat"),
        "-rod_system_element_length", "2", "-sweep_cases", str(cases),
        "-sweep_output", str(folder)], 1)
    assert process.returncode == 3, describe(process)
    assert ("petsc_rod: error: the system's equilibrium is a saddle of the system: its "
            "stiffness has 1 negative eigenvalue(s)") in process.stdout
    assert "0 of 1 case(s) converged; not: pushed" in process.stdout
    # the summary says why it did not converge and the record names the saddle's file
    assert "not converged (saddle)" in (folder / "summary.csv").read_text()
    (record,) = json.loads((folder / "sweep.json").read_text())["cases"]
    assert record["file"] == str(folder / "pushed.h5")
    with h5py.File(folder / "pushed.h5", "r") as f:
        assert int(f["system"].attrs["system_stable"]) == 0
        assert int(f["system"].attrs["converged"]) == 0
