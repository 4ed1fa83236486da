"""A sweep marks a case whose run failed and goes on, whatever the failure
(sweep/runner.py, docs/sweeps.md): exit codes of petsc_rod's own errors, and exceptions
that petsc_rod's run does not turn into one (numpy's LinAlgError, a Python error), raised
on every rank. In-process on PETSc.COMM_WORLD (serially, and under ``mpiexec -n 2`` on
two ranks), petsc_rod's run replaced by one that raises for the chosen cases: no solve."""

import csv
import json
import os

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.sweep import runner

CASES = {"first": None, "linalg": np.linalg.LinAlgError("SVD did not converge"),
         "python": KeyError("point_load_drag_areas"), "last": None}


@pytest.fixture
def folder(tmp_path_factory):
    """One folder for every rank (rank 0's, broadcast)."""
    comm = PETSc.COMM_WORLD.tompi4py()
    path = str(tmp_path_factory.mktemp("sweep")) if comm.rank == 0 else None
    return comm.bcast(path, root=0)


def sweep_in_process(folder, names, outcome, monkeypatch):
    """(exit code, the cases run, the output folder) of a sweep of the cases ``names``
    (-rod_length 1, 2, ...) whose runs are ``outcome(name)`` (an exit code; it may
    raise). Collective."""
    comm = PETSc.COMM_WORLD
    cases = os.path.join(folder, "cases.txt")
    if comm.getRank() == 0:
        with open(cases, "w") as f:
            f.write("name rod_length\n" + "".join(f"{name} {i + 1}\n"
                                                   for i, name in enumerate(names)))
    comm.tompi4py().Barrier()
    ran = []

    def run(comm, texts):
        name = os.path.basename(texts["rod_output"])[:-3]
        ran.append(name)
        return outcome(name)

    monkeypatch.setattr(runner, "run", run)
    output = os.path.join(folder, "out")
    database = PETSc.Options()
    options = {"sweep_cases": cases, "sweep_output": output, "sweep_start": "scene"}
    for name, value in options.items():
        database.setValue(name, value)
    try:
        return runner.run_sweep(comm), ran, output
    finally:
        for name in options:
            database.delValue(name)


def test_a_case_that_raises_is_marked_and_the_sweep_goes_on(folder, monkeypatch):
    comm = PETSc.COMM_WORLD

    def outcome(name):
        if CASES[name] is not None:
            raise CASES[name]
        return 0

    code, ran, output = sweep_in_process(folder, list(CASES), outcome, monkeypatch)
    assert code == 3
    assert ran == list(CASES)
    if comm.getRank() == 0:
        with open(os.path.join(output, "summary.csv"), newline="") as f:
            rows = {row["case"]: row for row in csv.DictReader(f)}
        assert list(rows) == list(CASES)
        assert rows["first"]["status"] == rows["last"]["status"] == "converged"
        assert rows["linalg"]["exit"] == rows["python"]["exit"] == str(runner.FAILED)
        assert rows["linalg"]["status"] == "failed (LinAlgError: SVD did not converge)"
        assert rows["python"]["status"] == "failed (KeyError: 'point_load_drag_areas')"
        with open(os.path.join(output, "sweep.json")) as f:
            record = json.load(f)
        assert [case["code"] for case in record["cases"]] == [0, 1, 1, 0]


def test_a_case_stopped_by_a_signal_ends_the_sweep_and_its_summary_says_so(folder,
                                                                           monkeypatch):
    """A case's run that a SIGTERM stopped (exit 143): the sweep ends there with 143,
    the next cases not run, the summary's title and the record's ``stopped`` saying
    where and how many were not run (a table that is not the whole sweep's)."""
    code, ran, output = sweep_in_process(
        folder, ["first", "stopped", "third", "fourth"],
        lambda name: 143 if name == "stopped" else 0, monkeypatch)
    assert code == 143 and ran == ["first", "stopped"]
    if PETSc.COMM_WORLD.getRank() == 0:
        stopped = "stopped by SIGTERM during case stopped; 2 case(s) not run"
        with open(os.path.join(output, "summary.md")) as f:
            assert f.readline() == f"# Sweep of 4 case(s); {stopped}\n"
        with open(os.path.join(output, "sweep.json")) as f:
            record = json.load(f)
        assert record["stopped"] == stopped
        assert [case["code"] for case in record["cases"]] == [0, 143]


def test_an_earlier_sweep_s_file_that_cannot_be_removed_is_one_line_on_every_rank(
        folder):
    """An earlier sweep's folder whose listed case file is a folder: removing it raised
    IsADirectoryError on rank 0 alone (a traceback there, the other ranks waiting in
    the agreement for ever); now bad input on every rank, nothing removed."""
    from types import SimpleNamespace

    from petsc_rod.errors import RodInputError

    comm = PETSc.COMM_WORLD
    if comm.getRank() == 0:
        with open(os.path.join(folder, "sweep.json"), "w") as f:
            json.dump({"cases": [{"name": "a"}]}, f)
        os.mkdir(os.path.join(folder, "a.h5"))
    comm.tompi4py().Barrier()
    with pytest.raises(RodInputError, match="the earlier sweep's a.h5 cannot be removed"):
        runner.claim_folder(comm, folder, [SimpleNamespace(name="b", options={})], [])
    assert os.path.isdir(os.path.join(folder, "a.h5"))


def test_a_case_s_options_reach_its_run_as_values_not_the_database(folder, monkeypatch):
    """Issue 48: each case's options were written into PETSc's global options database
    and restored after it; now its -rod_* options reach the run as values (cli.main.run's
    texts) over the base ones, and only a solver option it varies (-rod_snes_type, which
    PETSc's SNES reads from the database alone) is set there, for that case."""
    comm = PETSc.COMM_WORLD
    cases = os.path.join(folder, "cases.txt")
    if comm.getRank() == 0:
        with open(cases, "w") as f:
            f.write("name rod_length rod_snes_type\na 2 nrichardson\nb 3 anderson\n")
    comm.tompi4py().Barrier()
    seen = []

    def run(comm, texts):
        database = PETSc.Options()
        seen.append((texts["rod_length"], texts["rod_al_rtol"],
                     database.hasName("rod_length"), database.getString("rod_snes_type")))
        return 0

    monkeypatch.setattr(runner, "run", run)
    database = PETSc.Options()
    options = {"sweep_cases": cases, "sweep_output": os.path.join(folder, "out"),
               "sweep_start": "scene", "rod_al_rtol": "1e-9"}
    for name, value in options.items():
        database.setValue(name, value)
    try:
        assert runner.run_sweep(comm) == 0
        assert not database.hasName("rod_snes_type")
    finally:
        for name in options:
            database.delValue(name)
    assert seen == [("2", "1e-9", False, "nrichardson"), ("3", "1e-9", False, "anderson")]


def test_a_system_case_whose_retry_fails_its_modes_stops_the_sweep(folder, monkeypatch):
    """A system's sweep (sweep/system.py) whose warm case ends with exit 3 and whose
    retry from the case's own start fails in the modes' eigensolver: the sweep stops
    there (exit 4, the third case not run, the record's ``stopped``), as when the first
    run of a case fails so. The system's run replaced by a stub (SystemSweep._run): no
    solve."""
    from petsc_rod.sweep import system as system_sweep

    runs = []

    class Kept:                              # a solver kept for the next case's warm start
        def __init__(self, system):
            self.system = system

        def destroy(self):
            pass

    def run(self, case, made):
        runs.append(case.name)
        self._error = self._stops = None
        if len(runs) == 1:                   # the first case converges, its solver kept
            self.solver = Kept(made[0])
            return 0, None
        if len(runs) == 2:                   # the second, warm: not converged
            return 3, None
        self._error = "the modes' eigensolver failed"      # its retry: the modes fail
        self._stops = "the lines' modes failed in their eigensolver (a stub)"
        return 4, None

    monkeypatch.setattr(system_sweep.SystemSweep, "_run", run)
    monkeypatch.setattr(system_sweep, "case_numbers", lambda system, results: {})
    output = os.path.join(folder, "out")
    database = PETSc.Options()
    deck = os.path.join(os.path.dirname(__file__), "..", "data", "moordyn",
                        "small_free_body.dat")
    options = {"rod_system": deck, "sweep_offsets": "0,1,2", "sweep_offset_of": "Point1",
               "sweep_output": output}
    for name, value in options.items():
        database.setValue(name, value)
    try:
        code = system_sweep.run_system_sweep(PETSc.COMM_WORLD)
    finally:
        for name in options:
            database.delValue(name)
    assert code == 4 and runs == ["offset0", "heading0_offset1", "heading0_offset1"]
    if PETSc.COMM_WORLD.getRank() == 0:
        with open(os.path.join(output, "sweep.json")) as f:
            record = json.load(f)
        assert record["stopped"].startswith(
            "stopped after case heading0_offset1: the lines' modes failed")
        assert record["stopped"].endswith("; 1 case(s) not run")
        assert [case["code"] for case in record["cases"]] == [0, 4]
