"""A system on the command line (petsc_rod/cli_system.py, docs/systems.md "Running a
system"): ``python -m petsc_rod -rod_system FILE`` on a small MoorDyn deck (a free buoyant
body on three 70 m chains in 30 m of water, tests/data/moordyn/small_free_body.dat),
under a body load from the command line, on 1 and 2 ranks with the same numbers; its
result file's groups and tables; the Python API's solve_system on the same file gives
the same numbers (issue 49 point 6, the MoorDyn-file path against the API path); bad
input in one line, exit 2, no file left. Spawns processes: marked ``serial``."""

import os

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, describe, partial_files, run_petsc_rod

pytestmark = pytest.mark.serial

DECK = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "small_free_body.dat")
LOAD = "Body1,10e3,2e3,0,0,0,5e3"
SYSTEM_DATASETS = ("point_positions", "body_positions", "body_rotations", "body_stiffness",
                   "body_stiffness_reference", "body_stiffness_moment",
                   "body_stiffness_asymmetry", "end_forces", "end_tensions",
                   "line_converged")


def system_run(folder, ranks, *extra):
    out = folder / "system.h5"
    process = run_petsc_rod(["-rod_system", DECK, "-rod_system_body_load", LOAD,
                             "-rod_output", str(out), "-rod_table",
                             str(folder / "system.csv"), *extra], ranks, 300)
    return out, process


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    found = {}
    for ranks in (1, 2):
        folder = tmp_path_factory.mktemp(f"ranks{ranks}")
        found[ranks] = (folder,) + system_run(folder, ranks)
    return found


def test_one_and_two_ranks_give_the_same_numbers(runs):
    for ranks, (_, _, process) in runs.items():
        assert process.returncode == 0, describe(process)
        assert "petsc_rod: converged" in process.stdout and "warning" not in process.stdout
    (_, one, _), (_, two, _) = runs[1], runs[2]
    with h5py.File(one, "r") as f, h5py.File(two, "r") as g:
        assert int(g["system"].attrs["ranks"]) == 2
        for name in SYSTEM_DATASETS:
            assert np.allclose(f["system"][name][()], g["system"][name][()], rtol=1e-12,
                               atol=1e-12 * np.abs(f["system"][name][()]).max()), name
        for line in ("Line1", "Line2", "Line3"):
            assert np.array_equal(f[f"lines/{line}/r"][()], g[f"lines/{line}/r"][()])


def test_the_result_file_and_the_tables(runs):
    folder, path, process = runs[1]
    with h5py.File(path, "r") as f:
        system = f["system"]
        assert set(SYSTEM_DATASETS) <= set(system)
        assert int(system.attrs["converged"]) == 1 and system.attrs["residual"] < 1e-7
        assert system.attrs["line_names"] == "Line1,Line2,Line3"
        with open(DECK, encoding="utf-8") as deck:
            assert system.attrs["input_text"] == deck.read()
        K = system["body_stiffness"][0]
        assert K.shape == (6, 6) and np.all(np.diag(K)[:3] > 1e3)
        # the rotational block's antisymmetric part is the lines' moment about the
        # reference point (docs/systems.md)
        M = system["body_stiffness_moment"][0]
        skew = np.array([[0, -M[2], M[1]], [M[2], 0, -M[0]], [-M[1], M[0], 0]])
        assert np.abs((K - K.T)[3:, 3:] - skew).max() < 1e-8 * np.abs(K).max()
        assert np.allclose(system["body_stiffness_reference"][0],
                           system["body_positions"][0, :3])
        # the body's load is balanced: the body moved downstream of the load
        assert system["body_positions"][0, 0] > 0.5
        for k, line in enumerate(("Line1", "Line2", "Line3")):
            group = f[f"lines/{line}"]
            assert group["r"].shape == (71, 3) and int(group.attrs["converged"]) == 1
            assert np.all(np.isfinite(group["n"][()]))
            # the end tensions are the end elements' n.t, the end forces -n(L)
            assert system["end_tensions"][k, 1] == pytest.approx(
                group["effective_tension"][-1], rel=1e-12)
            assert system["end_forces"][k, 1] == pytest.approx(-group["n"][-1], rel=1e-9)
    rows = (folder / "system_system.csv").read_text().splitlines()
    assert rows[0].startswith("line,end,to,force_x (N)") and len(rows) == 7
    assert rows[2].split(",")[:3] == ["Line1", "end", "Body1"]
    table = (folder / "system_Line2.csv").read_text().splitlines()
    assert table[0].startswith("S (m),x (m)") and len(table) == 72
    assert "petsc_rod: note: line type main: EI 0 in the file" in process.stdout
    assert "Body1" in process.stdout and "stiffness diagonal" in process.stdout
    rows = [line.split() for line in process.stdout.splitlines()
            if line.startswith("  Line")]
    assert len(rows) == 3 and all(row[-1] == "yes" for row in rows), process.stdout


def test_the_api_path_equals_the_file_path(runs, tmp_path):
    """solve_system on the System read from the same file, the load added in Python:
    the command line's numbers."""
    import subprocess
    import sys

    from helpers import child_env
    script = tmp_path / "api.py"
    out = tmp_path / "api.npz"
    script.write_text(f"""
import dataclasses, numpy as np
from petsc_rod.api import read_moordyn, solve_system
system, notes = read_moordyn({DECK!r})
body = system.bodies[0]
load = np.add(body.load, [10e3, 2e3, 0, 0, 0, 5e3])
system = dataclasses.replace(system, bodies=(dataclasses.replace(body, load=tuple(load)),))
r = solve_system(system)
np.savez({str(out)!r}, x=r.bodies["Body1"].position, K=r.bodies["Body1"].stiffness,
         F=np.array([r.end_forces[n] for n in ("Line1", "Line2", "Line3")]),
         T=np.array([r.end_tensions[n] for n in ("Line1", "Line2", "Line3")]),
         r=r.lines["Line2"].along_line(["r"])["r"])
""")
    process = subprocess.run([sys.executable, str(script)], cwd=REPO_ROOT, env=child_env(),
                             capture_output=True, text=True, timeout=300, check=False)
    assert process.returncode == 0, describe(process)
    api = np.load(out)
    with h5py.File(runs[1][1], "r") as f:
        system = f["system"]
        assert np.array_equal(api["x"], system["body_positions"][0])
        assert np.array_equal(api["K"], system["body_stiffness"][0])
        assert np.array_equal(api["F"], system["end_forces"][()])
        assert np.array_equal(api["T"], system["end_tensions"][()])
        assert np.array_equal(api["r"], f["lines/Line2/r"][()])


def refused(tmp_path, args, ranks=1):
    out = tmp_path / "bad.h5"
    process = run_petsc_rod(args + ["-rod_output", str(out)], ranks, 120)
    assert process.returncode == 2, describe(process)
    errors = [line for line in process.stdout.splitlines() if "error" in line]
    assert len(errors) == 1 and errors[0].startswith("petsc_rod: error: "), describe(process)
    assert "Traceback" not in process.stderr
    assert not out.exists() and not partial_files(out)
    return errors[0]


def test_bad_input_is_one_line_and_leaves_no_file(tmp_path):
    deck = tmp_path / "bad.dat"
    with open(DECK, encoding="utf-8") as source:
        deck.write_text(source.read().replace("1     main       1        4 ",
                                              "1     main       9        4 "))
    line = refused(tmp_path, ["-rod_system", str(deck)])
    assert "9" in line
    assert "-rod_length" in refused(tmp_path, ["-rod_system", DECK, "-rod_length", "3",
                                               "-rod_elements", "4"])
    assert "Body7" in refused(tmp_path, ["-rod_system", DECK, "-rod_system_body_load",
                                         "Body7,1,0,0,0,0,0"])
    assert "no such file" in refused(tmp_path, ["-rod_system", str(tmp_path / "none.dat")],
                                     ranks=2)
    copy = tmp_path / "deck.dat"
    with open(DECK, encoding="utf-8") as source:
        kept = source.read()
    copy.write_text(kept)
    process = run_petsc_rod(["-rod_system", str(copy), "-rod_output", str(copy)], 1, 120)
    assert process.returncode == 2 and "-rod_output" in process.stdout, describe(process)
    assert copy.read_text() == kept
    assert "-rod_system_steps" in refused(tmp_path, ["-options_file",
                                                     "options/cantilever.opts",
                                                     "-rod_system_steps", "2"])


def test_help_lists_the_system_options():
    process = run_petsc_rod(["-rod_system", DECK, "-help"], 1, 120)
    assert process.returncode == 0, describe(process)
    for name in ("-rod_system ", "-rod_system_element_length ", "-rod_system_body_load ",
                 "-rod_system_steps ", "-rod_al_rtol "):
        assert name in process.stdout, name


def test_no_equilibrium_writes_nothing_and_removes_old_tables(tmp_path):
    """Lines that cannot converge (two iterations allowed): exit 3 (not converged) in
    one line, no result file, and the tables of an earlier run at the same paths
    removed."""
    stale = [tmp_path / "t_Line1.csv", tmp_path / "t_system.csv"]
    for path in stale:
        path.write_text("an earlier run's\n")
    out = tmp_path / "none.h5"
    process = run_petsc_rod(["-rod_system", DECK, "-rod_al_max_it", "2", "-rod_output",
                             str(out), "-rod_table", str(tmp_path / "t.csv")], 1, 120)
    assert process.returncode == 3, describe(process)
    errors = [line for line in process.stdout.splitlines() if "error" in line]
    assert len(errors) == 1 and "did not converge" in errors[0], describe(process)
    assert not out.exists() and not partial_files(out)
    assert not any(path.exists() for path in stale)


def test_the_load_continuation_reaches_the_same_equilibrium(runs, tmp_path):
    """-rod_system_steps 3: the body load in three steps (more Newton iterations), the
    same pose and end forces as in one, to the lines' own accuracy (their end forces
    converged to about 1e-8 of themselves over a stiffness of 8e3 N/m: 6e-8 m apart)."""
    path, process = system_run(tmp_path, 1, "-rod_system_steps", "3")
    assert process.returncode == 0, describe(process)
    with h5py.File(runs[1][1], "r") as f, h5py.File(path, "r") as g:
        assert g["system"].attrs["iterations"] > f["system"].attrs["iterations"]
        assert np.abs(g["system/body_positions"][0, :3]
                      - f["system/body_positions"][0, :3]).max() < 1e-6
        assert np.abs(g["system/end_forces"][()] - f["system/end_forces"][()]).max() < (
            1e-7 * np.abs(f["system/end_forces"][()]).max())


def test_modes_of_each_line_on_the_command_line(tmp_path):
    """-rod_modes 3 on a system's run (2 ranks): a table per line in the run's lines and
    the group lines/<name>/modes of the result file, its frequencies those said."""
    path, process = system_run(tmp_path, 2, "-rod_modes", "3")
    assert process.returncode == 0, describe(process)
    assert "warning" not in process.stdout
    with h5py.File(path, "r") as f:
        for line in ("Line1", "Line2", "Line3"):
            assert f"line {line} (ends held): modes: 3 lowest" in process.stdout
            frequency = f[f"lines/{line}/modes/frequency"][()]
            assert frequency.shape == (3,) and frequency[-1] > 0.1
            assert f"{frequency[-1]:12.6g}" in process.stdout
