"""Sweeps of a system (petsc_rod/sweep/system.py, docs/sweeps.md "Sweeps of a system"):
``python -m petsc_rod.sweep -rod_system FILE`` over offsets of a held body
(-sweep_offsets, -sweep_offset_of, headings in degrees) and over case files of the
bodies' loads and the lines' lengths, on 1 and 2 ranks with the same numbers; each case warm from the last is
the case run alone (``python -m petsc_rod -rod_system FILE`` with the case's option);
the summary's columns (the body's position, each line's fairlead tension, the largest
tension); bad sweep input in one line, exit 2. Small decks of tests/data/moordyn with
10 m elements. Spawns processes: marked ``serial``."""

import csv
import json
import os

import h5py
import numpy as np
import pytest

from helpers import REPO_ROOT, describe, run_petsc_rod
from test_sweep_cli import run_module

pytestmark = pytest.mark.serial

DECKS = os.path.join(REPO_ROOT, "tests", "data", "moordyn")
HELD = os.path.join(DECKS, "small_spread.dat")         # a body held (Coupled)
FREE = os.path.join(DECKS, "small_free_body.dat")      # a free body
COARSE = ["-rod_system_element_length", "10"]
OFFSETS = ["-sweep_offsets", "0,2", "-sweep_offset_of", "Body1", "-sweep_headings", "0,90"]


def summary_rows(folder):
    with open(os.path.join(folder, "summary.csv"), newline="") as f:
        return {row["case"]: row for row in csv.DictReader(f)}


def sweep(folder, deck, ranks, *args):
    process = run_module("petsc_rod.sweep", ["-rod_system", deck, *COARSE, *args,
                                             "-sweep_output", str(folder)], ranks)
    return process


@pytest.fixture(scope="module")
def offset_sweeps(tmp_path_factory):
    found = {}
    for ranks in (1, 2):
        folder = tmp_path_factory.mktemp(f"offsets{ranks}")
        found[ranks] = (folder, sweep(folder, HELD, ranks, *OFFSETS))
    return found


def test_offsets_of_a_held_body_on_one_and_two_ranks(offset_sweeps):
    for ranks, (folder, process) in offset_sweeps.items():
        assert process.returncode == 0, describe(process)
        assert "3 of 3 case(s) converged" in process.stdout
        assert sorted(os.listdir(folder)) == sorted(
            ["offset0.h5", "heading0_offset2.h5", "heading90_offset2.h5", "summary.csv",
             "summary.md", "sweep.json"])
    one, two = (summary_rows(offset_sweeps[r][0]) for r in (1, 2))
    columns = [c for c in one["offset0"] if c.endswith("(N)") or c.endswith("(m)")]
    assert "Line1 fairlead_tension (N)" in columns and "max_tension (N)" in columns
    for case in one:
        for column in columns:
            assert float(one[case][column]) == pytest.approx(float(two[case][column]),
                                                             rel=1e-9, abs=1e-9), column
    rows = {case: {c: float(v) for c, v in row.items() if c in columns}
            for case, row in one.items()}
    assert rows["heading0_offset2"]["Body1 x (m)"] == pytest.approx(2.0, abs=1e-12)
    assert rows["heading90_offset2"]["Body1 y (m)"] == pytest.approx(2.0, abs=1e-12)
    assert one["heading0_offset2"]["start"] == "from the last case"
    # the body moves towards +x, away from Line2's and Line3's anchors (at x = -32.5):
    # they tighten, Line1 (anchor at x = 65) slackens
    still, moved = rows["offset0"], rows["heading0_offset2"]
    assert moved["Line1 fairlead_tension (N)"] < 0.9 * still["Line1 fairlead_tension (N)"]
    assert moved["Line2 fairlead_tension (N)"] > 1.1 * still["Line2 fairlead_tension (N)"]
    # the largest effective tension, and the fairlead force (with the end's shear)
    assert moved["max_tension (N)"] == pytest.approx(moved["Line2 fairlead_tension (N)"],
                                                     rel=1e-4)
    assert one["heading0_offset2"]["max_tension_line"] in ("Line2", "Line3")


def test_a_warm_case_is_the_case_run_alone(offset_sweeps, tmp_path):
    folder, _ = offset_sweeps[1]
    alone = tmp_path / "alone.h5"
    process = run_petsc_rod(["-rod_system", HELD, *COARSE, "-rod_system_offset",
                             "Body1,0,2,0", "-rod_output", str(alone)], 1, 120)
    assert process.returncode == 0, describe(process)
    with h5py.File(folder / "heading90_offset2.h5", "r") as f, h5py.File(alone, "r") as g:
        swept, single = f["system/end_forces"][()], g["system/end_forces"][()]
        assert np.abs(swept - single).max() < 1e-6 * np.abs(single).max()
        assert np.array_equal(f["system/body_positions"][()], g["system/body_positions"][()])


def test_a_case_file_of_body_loads(tmp_path):
    """A free body under two loads from a case file: the second case warm from the
    first is that load's run alone; the body moves with the load."""
    cases = tmp_path / "cases.txt"
    cases.write_text("name rod_system_body_load\n"
                     "calm Body1,0,0,0,0,0,0\n"
                     "push Body1,20e3,0,0,0,0,0\n")
    folder = tmp_path / "loads"
    process = sweep(folder, FREE, 1, "-sweep_cases", str(cases))
    assert process.returncode == 0, describe(process)
    rows = summary_rows(folder)
    assert float(rows["push"]["Body1 x (m)"]) > float(rows["calm"]["Body1 x (m)"]) + 0.5
    alone = tmp_path / "alone.h5"
    single = run_petsc_rod(["-rod_system", FREE, *COARSE, "-rod_system_body_load",
                            "Body1,20e3,0,0,0,0,0", "-rod_output", str(alone)], 1, 120)
    assert single.returncode == 0, describe(single)
    with h5py.File(folder / "push.h5", "r") as f, h5py.File(alone, "r") as g:
        assert np.abs(f["system/body_positions"][()] - g["system/body_positions"][()]
                      ).max() < 1e-6
    # a case's bad value (an offset of the free body) is that case's exit 2
    bad = tmp_path / "bad.txt"
    bad.write_text("name rod_system_offset\nmoved Body1,1,0,0\n")
    process = sweep(tmp_path / "bad", FREE, 1, "-sweep_cases", str(bad))
    assert process.returncode == 3, describe(process)
    assert "body Body1 is free in x" in process.stdout
    assert summary_rows(tmp_path / "bad")["moved"]["exit"] == "2"


def test_a_case_file_of_line_lengths(tmp_path):
    """A line's length per case: the case whose lines differ from the last case's gets a
    solver of its own; a longer Line1 (its anchor at +x) lets the pushed body sit
    nearer its rest."""
    cases = tmp_path / "lengths.txt"
    cases.write_text("name rod_system_line_length\n"
                     "short Line1,69\n"
                     "long Line1,71\n")
    folder = tmp_path / "lengths"
    process = sweep(folder, FREE, 1, "-sweep_cases", str(cases), "-rod_system_body_load",
                    "Body1,20e3,0,0,0,0,0")
    assert process.returncode == 0, describe(process)
    rows = summary_rows(folder)
    assert rows["long"]["start"] == "own start (its lines differ)"
    assert float(rows["long"]["Body1 x (m)"]) < float(rows["short"]["Body1 x (m)"]) - 0.5
    with h5py.File(folder / "long.h5", "r") as f:
        assert f["lines/Line1/S"][-1] == pytest.approx(71.0, rel=1e-12)
        assert f["lines/Line2/S"][-1] == pytest.approx(70.0, rel=1e-12)
    # the report of a system's sweep is not made yet: one line, exit 2, no page
    page = tmp_path / "page.html"
    report = run_module("petsc_rod.report", [str(folder), "-o", str(page)])
    assert report.returncode == 2 and not page.exists(), describe(report)
    assert report.stderr.strip().splitlines() == [
        f"petsc_rod.report: error: {folder}: a system's sweep, whose page is not made "
        f"yet: report one of its cases' files ({folder / '<case>.h5'}), or read its "
        "summary.md"]


def test_a_case_s_options_act_on_the_base_s(tmp_path):
    """The base's -rod_system_offset, -rod_system_line_length and -rod_system_body_load
    kept under a case's (the base's Point2 offset under the sweep's offsets of Point1):
    a case's offsets and loads add to the base's per name, its lengths replace the
    base's for the lines it names; the warm case is the plain run with the sums."""
    cases = tmp_path / "cases.txt"
    cases.write_text("name rod_system_line_length rod_system_body_load\n"
                     "more Line1,70.5 Body1,5e3,0,0,0,0,0\n")
    folder = tmp_path / "over"
    process = sweep(folder, FREE, 1, "-rod_system_offset", "Point2,10,0,0:Point1,1,0,0",
                    "-rod_system_line_length", "Line3,70.5:Line1,69",
                    "-rod_system_body_load", "Body1,5e3,0,0,0,0,0", "-sweep_cases",
                    str(cases), "-sweep_offsets", "0,2", "-sweep_offset_of", "Point1")
    assert process.returncode == 0, describe(process)
    assert set(summary_rows(folder)) == {"more_offset0", "more_heading0_offset2"}
    alone = tmp_path / "alone.h5"
    single = run_petsc_rod(["-rod_system", FREE, *COARSE, "-rod_system_offset",
                            "Point2,10,0,0:Point1,3,0,0", "-rod_system_line_length",
                            "Line3,70.5:Line1,70.5", "-rod_system_body_load",
                            "Body1,10e3,0,0,0,0,0", "-rod_output", str(alone)], 1, 120)
    assert single.returncode == 0, describe(single)
    with h5py.File(folder / "more_heading0_offset2.h5", "r") as f, h5py.File(alone, "r") as g:
        for line, length in (("Line1", 70.5), ("Line2", 70.0), ("Line3", 70.5)):
            assert f[f"lines/{line}/S"][-1] == pytest.approx(length, rel=1e-12)
        assert np.array_equal(f["system/point_positions"][()], g["system/point_positions"][()])
        assert np.abs(f["system/body_positions"][()] - g["system/body_positions"][()]
                      ).max() < 1e-6
    with h5py.File(folder / "more_offset0.h5", "r") as f:
        assert f["system/point_positions"][0, 0] == pytest.approx(65.0 + 1.0, abs=1e-12)
        assert f["system/point_positions"][1, 0] == pytest.approx(-32.5 + 10.0, abs=1e-12)


@pytest.mark.parametrize("name", ["Body1", "Point2"])
def test_offsets_of_a_free_body_or_point_are_refused_before_any_case(tmp_path, name):
    """The free body of small_free_body.dat (x only: heading 0), or a point made free:
    one line, exit 2, no folder."""
    deck = tmp_path / "deck.dat"
    with open(FREE, encoding="utf-8") as source:
        deck.write_text(source.read().replace("2     Fixed       -32.5",
                                              "2     Free        -32.5"))
    process = sweep(tmp_path / "out", str(deck), 1, "-sweep_offsets", "0,5",
                    "-sweep_offset_of", name)
    assert process.returncode == 2, describe(process)
    lines = process.stdout.strip().splitlines()
    assert lines == [f"petsc_rod.sweep: error: -sweep_offset_of {name}: " + (
        "body Body1 is free in x, where its equilibrium decides where it is; hold it there "
        "(Fixed or Coupled in the file) or move it by a load (-sweep_cases of "
        "rod_system_body_load)" if name == "Body1" else
        "a free point, whose equilibrium decides where it is; offset a fixed or "
        "prescribed point or a held body")], describe(process)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("args, message", [
    (["-sweep_offsets", "1"], "-sweep_offsets and -sweep_offset_of NAME go together"),
    (["-sweep_offsets", "1", "-sweep_offset_of", "Body9"], "no point or body of that name"),
    (["-sweep_offsets", "1", "-sweep_offset_of", "Body1", "-sweep_headings", "far"],
     "-sweep_headings"),
    (["-sweep_current_headings", "0"], "a system's current is the base options'"),
    (["-sweep_cases", "lengths.txt"], "column rod_length is not an option a system's case"),
    (["-rod_system_line_length", "Line1,-3", "-sweep_offsets", "1", "-sweep_offset_of", "Body1"],
     "a positive length"),
])
def test_bad_system_sweep_input_is_one_line_and_exit_2(tmp_path, args, message):
    (tmp_path / "lengths.txt").write_text("name rod_length\nlong 80\n")
    args = [str(tmp_path / arg) if arg == "lengths.txt" else arg for arg in args]
    process = sweep(tmp_path / "out", HELD, 1, *args)
    assert process.returncode == 2, describe(process)
    lines = process.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("petsc_rod.sweep: error: ")
    assert message in lines[0] and "Traceback" not in process.stderr


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_lines_modes_failing_stop_the_sweep_at_that_case(tmp_path, ranks):
    """-rod_modes with -rod_modes_st_type cayley (SLEPc refuses a Cayley transform of
    shift 0: analysis/modes.ModesFailed) on every case of a 3-case offset sweep: the
    first case's one line, the sweep stopped there (the same modes' options would fail
    every case alike, each after PETSc's failed solve), exit 4, no case file, the
    summary titled stopped with its one row and the record's ``stopped``. Before: every
    case ran and failed alike (exit 4 each, status diverged) and the sweep exited 3."""
    folder = tmp_path / "out"
    process = sweep(folder, HELD, ranks, "-sweep_offsets", "0,1,2", "-sweep_offset_of",
                    "Body1", "-rod_modes", "2", "-rod_modes_st_type", "cayley")
    assert process.returncode == 4, describe(process)
    said = [line for line in process.stdout.splitlines() if line.startswith("petsc_rod")]
    why = ("the lines' modes failed in their eigensolver, and every case asks for the "
           "same modes with the same options (-rod_modes*): each would fail alike")
    assert said[2:4] == [
        "petsc_rod: error: line Line1: the modes' eigensolver (SLEPc) failed: Values of "
        "shift and antishift cannot be zero simultaneously; check the -rod_modes_eps_* and "
        "-rod_modes_st_* options",
        f"petsc_rod.sweep: stopped after case offset0: {why}"], describe(process)
    assert said[-1] == ("petsc_rod.sweep: 0 of 3 case(s) converged; not: offset0; 2 not "
                        f"run; summary in {folder / 'summary.md'}"), describe(process)
    assert "sweep: case 2/3" not in process.stdout and "Traceback" not in process.stderr
    assert sorted(os.listdir(folder)) == ["summary.csv", "summary.md", "sweep.json"]
    rows = summary_rows(folder)
    assert list(rows) == ["offset0"]
    assert (rows["offset0"]["exit"], rows["offset0"]["status"]) == (
        "4", "failed (the modes' eigensolver failed)")
    stopped = f"stopped after case offset0: {why}; 2 case(s) not run"
    assert (folder / "summary.md").read_text().splitlines()[0] == (
        f"# Sweep of 3 case(s) of a system; {stopped}")
    with open(folder / "sweep.json", encoding="utf-8") as f:
        assert json.load(f)["stopped"] == stopped
