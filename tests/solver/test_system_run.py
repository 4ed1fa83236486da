"""The system's run with real lines (api.solve_system: system/equilibrium.SystemSolver
with every line a system/held_line.HeldLine, api/system_run.py), on one rank and on all
(under ``mpiexec -n 2`` each line on its own rank, or one line over both), issue 49
point 6:

(a) a system of one line between fixed points is the single-line solver's line
    (api.solve of the same Model): its end forces, end tensions and centreline;
(b) a line split at a massless free point is the unsplit line: the point where the
    unsplit line's vertex of that arc length is, and the same end forces.
"""

import os

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import (Connection, End, Environment, Model, Point, System, SystemLine,
                           UniformLine, read_moordyn, solve, solve_system)

pytestmark = pytest.mark.solver

TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
# an elastic catenary: 100 m of 10 N/m, EA 1e5 N, pins 80 m across and 20 m up
ANCHOR, FAIRLEAD = (0.0, 0.0, 0.0), (80.0, 0.0, 20.0)


def uniform(length, elements):
    return UniformLine(length=length, stiffness=(1e-2, 1e-2, 1e-2), load=(0, 0, -10.0),
                       axial_stiffness=1e5, elements=elements)


def whole_line():
    return solve(Model(line=uniform(100.0, 40), start=End.anchor(ANCHOR),
                       end=End.anchor(FAIRLEAD), options=TIGHT))


def test_one_line_between_fixed_points_is_the_single_line(tmp_path):
    """Also its result file (on 2 ranks: the one line's group is both ranks): the line's
    group holds the single line's centreline."""
    import h5py
    system = System(lines=(SystemLine("one", uniform(100.0, 40), Connection("A"),
                                      Connection("B")),),
                    points=(Point("A", "fixed", ANCHOR), Point("B", "prescribed", FAIRLEAD)),
                    environment=Environment())
    folder = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path))
    found = solve_system(system, options=TIGHT, output=f"{folder}/one.h5")
    single = whole_line()
    with h5py.File(f"{folder}/one.h5", "r") as f:
        assert np.abs(f["lines/one/r"][()] - single.along_line(["r"])["r"]).max() < 1e-7
        assert f["lines/one"].attrs["ranks"] == PETSc.COMM_WORLD.getSize()
        assert f["lines/one/effective_tension"].attrs["units"] == "N"
    forces = found.end_forces["one"]
    assert forces[0] == pytest.approx(single.scalars["start_force"], rel=1e-9)
    assert forces[1] == pytest.approx(single.scalars["end_force"], rel=1e-9)
    line = found.lines["one"]
    along, reference = line.along_line(["r", "effective_tension"]), single.along_line()
    assert np.abs(along["r"] - reference["r"]).max() < 1e-9 * 100.0
    t = reference["d3"] / np.linalg.norm(reference["d3"], axis=1)[:, None]
    tension = np.einsum("ij,ij->i", reference["n"], t)[[0, -1]]    # n.t at the ends
    assert found.end_tensions["one"] == pytest.approx(tension, rel=1e-9)
    assert along["effective_tension"][[0, -1]] == pytest.approx(tension, rel=1e-9)
    assert found.converged and found.iterations == 0 and found.lines_converged["one"]


def test_a_line_split_at_a_massless_free_point_is_the_unsplit_line():
    """40 m + 60 m joined at a free point J (no mass, no volume), started 3 m off the
    unsplit line: J where the unsplit line's vertex at S = 40 m is, the fairlead's force
    the unsplit line's."""
    system = System(lines=(SystemLine("lower", uniform(40.0, 16), Connection("A"),
                                      Connection("J")),
                           SystemLine("upper", uniform(60.0, 24), Connection("J"),
                                      Connection("B"))),
                    points=(Point("A", "fixed", ANCHOR), Point("J", "free", (30.0, 0.0, -12.0)),
                            Point("B", "fixed", FAIRLEAD)),
                    environment=Environment())
    found = solve_system(system, options=TIGHT)
    single = whole_line()
    r = single.along_line(["r"])["r"]
    assert found.converged and found.iterations >= 2
    assert np.abs(found.points["J"] - r[16]).max() < 1e-6
    assert found.end_forces["upper"][1] == pytest.approx(single.scalars["end_force"],
                                                         rel=1e-7)
    assert found.end_forces["lower"][0] == pytest.approx(single.scalars["start_force"],
                                                         rel=1e-7)
    # J's balance: the two lines' forces on it cancel
    J = found.end_forces["lower"][1] + found.end_forces["upper"][0]
    assert np.abs(J).max() < 1e-6 * np.abs(found.end_forces["upper"]).max()


class Signalled:
    """An Interrupts (cli/signals.py) whose ranks received SIGTERM."""

    def received(self, comm=None):
        return 15

    @staticmethod
    def name(number):
        return "SIGTERM"


def test_a_stop_signal_ends_the_run_before_anything_is_written(tmp_path):
    import os

    from petsc_rod.api.system_run import run_system
    from petsc_rod.errors import RodInterrupted
    from petsc_rod.system.equilibrium import Settings
    system = System(lines=(SystemLine("one", uniform(100.0, 40), Connection("A"),
                                      Connection("B")),),
                    points=(Point("A", "fixed", ANCHOR), Point("B", "fixed", FAIRLEAD)))
    out = str(tmp_path / "system.h5") if PETSc.COMM_WORLD.getSize() == 1 else None
    with pytest.raises(RodInterrupted) as stopped:
        run_system(PETSc.COMM_WORLD, system, Settings(), TIGHT, lambda line: None,
                   output=out, interrupts=Signalled())
    assert stopped.value.exit_code == 143 and "SIGTERM" in str(stopped.value)
    assert out is None or not os.listdir(tmp_path)


class SignalledLater(Signalled):
    """An Interrupts whose ranks received SIGTERM from the system's ``calls``-th
    question on (the lines' questions, on their communicators, not counted)."""

    def __init__(self, calls):
        self.calls, self.asked = calls, 0

    def received(self, comm=None):
        if comm is None:
            self.asked += 1
        return 15 if self.asked >= self.calls else 0


class SignalledInAWalk(Signalled):
    """An Interrupts whose ranks received SIGTERM at a line's ``calls``-th question
    (a line asks on its communicator after every iteration of its walks)."""

    def __init__(self, calls):
        self.calls, self.line_asked = calls, 0

    def received(self, comm=None):
        if comm is not None:
            self.line_asked += 1
        return 15 if self.line_asked >= self.calls else 0


def interrupted_joined_lines(tmp_path, interrupts):
    """The message of the RodInterrupted that run_system raises on two lines joined at
    a free point (a Newton of several iterations) given ``interrupts``, its exit code
    143 and no file written."""
    from petsc_rod.api.system_run import run_system
    from petsc_rod.errors import RodInterrupted
    from petsc_rod.system.equilibrium import Settings
    system = System(lines=(SystemLine("lower", uniform(40.0, 16), Connection("A"),
                                      Connection("J")),
                           SystemLine("upper", uniform(60.0, 24), Connection("J"),
                                      Connection("B"))),
                    points=(Point("A", "fixed", ANCHOR), Point("J", "free", (30.0, 0.0, 5.0)),
                            Point("B", "fixed", FAIRLEAD)))
    out = str(tmp_path / "system.h5") if PETSc.COMM_WORLD.getSize() == 1 else None
    with pytest.raises(RodInterrupted) as stopped:
        run_system(PETSc.COMM_WORLD, system, Settings(), TIGHT, lambda line: None,
                   output=out, interrupts=interrupts)
    assert stopped.value.exit_code == 143
    assert out is None or not os.listdir(tmp_path)
    return str(stopped.value)


def test_a_stop_signal_is_acted_on_between_the_newton_s_iterations(tmp_path):
    """A signal received during the system's Newton (a free point to find: several
    iterations) ends the run at the next iteration, not once the equilibrium is found;
    nothing written."""
    interrupts = SignalledLater(3)
    stopped = interrupted_joined_lines(tmp_path, interrupts)
    assert "during the system's Newton (load factor 1, iteration 2)" in stopped
    assert interrupts.asked == 3


def test_a_stop_signal_after_the_equilibrium_ends_the_run_before_the_file(tmp_path,
                                                                         monkeypatch):
    """A signal received after the equilibrium, while its records, the modes or the
    sweeps are made (here: once the equilibrium's lines are said), ends the run before
    the file is written, where it went on to write it and exit 0."""
    from petsc_rod.api import system_run
    interrupts = SignalledLater(10**9)
    reported = system_run.report_lines

    def signalled_once_reported(*args):
        interrupts.calls = 0                  # from now on every rank has SIGTERM
        return reported(*args)

    monkeypatch.setattr(system_run, "report_lines", signalled_once_reported)
    stopped = interrupted_joined_lines(tmp_path, interrupts)
    assert stopped == ("stopped by SIGTERM before the system's results were written; "
                       "nothing written")


def test_a_stop_signal_during_a_line_s_walk_ends_the_walk_and_the_run(tmp_path):
    """A signal received while a line walks (a watch circle's case under a load no
    line can hold spends minutes in its lines' iterations and halvings) stops the walk
    at the iteration it arrived in and the run there, nothing written: the lines ask
    after every iteration (HeldLine.interrupts). Before, the lines never asked and the
    run went on to the end."""
    interrupts = SignalledInAWalk(5)
    assert "SIGTERM" in interrupted_joined_lines(tmp_path, interrupts)
    # the walk that received it stopped at once, the other line's (on this rank) at
    # its first iteration
    assert 5 <= interrupts.line_asked <= 6


def test_a_sweep_of_a_held_body_is_refused_before_anything_is_solved(tmp_path):
    """solve_system's watch circle of the coupled body of small_spread.dat (its offsets
    would all be 0 m) refused on every rank, naming Sweeps.watch_circle, the output that
    existed kept; the same through system/excursions.watch_circle on a solver, before
    its rest is solved. Serially and under mpiexec -n 2."""
    from petsc_rod.api import Sweeps, read_moordyn
    from petsc_rod.errors import RodInputError
    from petsc_rod.system.equilibrium import SystemSolver
    from petsc_rod.system.excursions import watch_circle
    from petsc_rod.system.held_line import held_lines
    system, _ = read_moordyn(os.path.join(os.path.dirname(__file__), "..", "data",
                                          "moordyn", "small_spread.dat"), 10.0)
    folder = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path))
    out = os.path.join(folder, "kept.h5")
    PETSc.COMM_WORLD.tompi4py().Barrier()
    if PETSc.COMM_WORLD.getRank() == 0:
        with open(out, "wb") as f:
            f.write(b"an earlier result")
    PETSc.COMM_WORLD.tompi4py().Barrier()
    with pytest.raises(RodInputError, match=r"^Sweeps.watch_circle: body Body1 is held in "
                                            "x and y .*its position there is imposed"):
        solve_system(system, output=out, sweeps=Sweeps(watch_circle=("Body1", 1e5,
                                                                     [0.0, 90.0])))
    with open(out, "rb") as f:
        assert f.read() == b"an earlier result"
    solver = SystemSolver(system, held_lines(system, TIGHT), PETSc.COMM_WORLD)
    try:
        with pytest.raises(RodInputError, match="^excursions: body Body1 is held in x "):
            watch_circle(solver, "Body1", 1e5, [0.0, 180.0])
    finally:
        solver.destroy()


def test_options_a_system_does_not_take_are_refused():
    from petsc_rod.errors import RodInputError
    system = System(lines=(SystemLine("one", uniform(100.0, 40), Connection("A"),
                                      Connection("B")),),
                    points=(Point("A", "fixed", ANCHOR), Point("B", "fixed", FAIRLEAD)))
    with pytest.raises(RodInputError, match="'length': not an option of a system"):
        solve_system(system, options={"length": 3.0})
    with pytest.raises(RodInputError, match="system_steps 0"):
        solve_system(system, options={"system_steps": 0})
    with pytest.raises(RodInputError, match="-rod_al_rtol"):
        solve_system(system, options={"al_rtol": "tight"})


def test_a_single_line_run_refuses_a_system():
    """cli.main.run (the single line's command line, a sweep's case) given -rod_system
    or a system's option: exit 2 in one line, no default line run in its place."""
    from petsc_rod.cli import main
    try:
        for texts in ({"rod_system": "spread.dat"}, {"rod_system_steps": "2"}):
            assert main.run(PETSc.COMM_WORLD, texts) == 2
    finally:
        PETSc.Options().delValue("options_left")      # set by the refusal


def test_each_line_is_tested_for_stability_once_at_the_equilibrium(monkeypatch):
    """The lines solve with their own stability test off during the system's iterations
    (held_lines) and are asked once each at its equilibrium (SystemSolver.line_verdicts),
    the record reading that verdict: the verdict's calls over the ranks are one per line
    on each rank of its group; the test runs for each line not settled by a Newton run
    whose last H passed the inertia test (HeldLine.verified, which is the verdict), and
    each line's verdict is in its results."""
    import dataclasses
    import os

    from helpers import REPO_ROOT
    from petsc_rod.iteration.driver import UzawaSolver
    from petsc_rod.model.moordyn import read_moordyn
    from petsc_rod.system.held_line import HeldLine

    calls, asked = [], []
    check, stable = UzawaSolver.check_stability, HeldLine.stable
    monkeypatch.setattr(UzawaSolver, "check_stability",
                        lambda self, *a, **k: calls.append(1) or check(self, *a, **k))
    monkeypatch.setattr(HeldLine, "stable", lambda self: asked.append(
        int(self.settled and self.verified)) or stable(self))
    system, _ = read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                          "small_free_body.dat"))
    body = dataclasses.replace(system.bodies[0], load=(3e4, 1e4, 0, 0, 0, 0))
    results = solve_system(dataclasses.replace(system, bodies=(body,)))
    mpi = PETSc.COMM_WORLD.tompi4py()
    ranks = sum(int(line.scalars["ranks"]) for line in results.lines.values())
    assert mpi.allreduce(len(asked)) == ranks and len(results.lines) == 3
    assert mpi.allreduce(len(calls)) == ranks - mpi.allreduce(sum(asked))
    assert all(int(line.scalars["stable"]) == 1 for line in results.lines.values())


def free_body_system():
    import dataclasses
    import os

    from helpers import REPO_ROOT
    from petsc_rod.model.moordyn import read_moordyn

    system, _ = read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                          "small_free_body.dat"))
    body = dataclasses.replace(system.bodies[0], load=(3e4, 1e4, 0, 0, 0, 0))
    return dataclasses.replace(system, bodies=(body,))


def test_a_line_whose_last_solve_failed_is_not_converged(monkeypatch, tmp_path):
    """Line2's last solve left unconverged (as the system's last evaluation may): its
    converged is 0 in the results, its group and the file's line_converged, and the
    system's converged is 0."""
    import h5py

    from petsc_rod.system.equilibrium import SystemSolver

    solve = SystemSolver.solve

    def failed_last(self):
        found = solve(self)
        for k, line in self.lines.items():
            if self.system.lines[k].name == "Line2":
                line.converged = False
        return found
    monkeypatch.setattr(SystemSolver, "solve", failed_last)
    path = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path / "sys.h5"))
    results = solve_system(free_body_system(), output=path)
    assert results.lines_converged == {"Line1": True, "Line2": False, "Line3": True}
    assert not results.converged
    assert int(results.lines["Line2"].scalars["converged"]) == 0
    with h5py.File(path, "r") as f:
        assert list(f["system/line_converged"][()]) == [1.0, 0.0, 1.0]
        assert int(f["system"].attrs["converged"]) == 0
        assert int(f["lines/Line2"].attrs["converged"]) == 0
        assert int(f["lines/Line1"].attrs["converged"]) == 1


def test_a_nan_along_a_line_is_never_written(monkeypatch, tmp_path):
    """A NaN in a line's positions along S (on the ranks that hold it), which no end
    force or tension carries: RodDivergedError on every rank before anything is
    written."""
    from petsc_rod.errors import RodDivergedError
    from petsc_rod.io import line_table

    record = line_table.final_record

    def with_nan(problem):
        vertex, attributes = record(problem)
        if len(vertex["r"]):        # not an end's number: only along the line
            vertex["r"][0, 2] = np.nan
        return vertex, attributes
    monkeypatch.setattr(line_table, "final_record", with_nan)
    path = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path / "sys.h5"))
    with pytest.raises(RodDivergedError, match="non-finite"):
        solve_system(free_body_system(), output=path, table=path[:-3] + ".csv")
    assert not [name for name in os.listdir(os.path.dirname(path))]


def test_a_buoyant_free_point_above_the_surface_is_noted(tmp_path):
    """tests/data/moordyn/drag_buoy.dat at rest: its free buoy's 10 m^3 lift more than
    its chains weigh, and it ends 0.50 m above the sea surface with its whole buoyancy
    (a point's, as in MoorDyn): the run says so in a note naming it and the height;
    with 6 m^3 it stays 7.7 m under water, and no note."""
    path = os.path.join(os.path.dirname(__file__), "..", "data", "moordyn", "drag_buoy.dat")
    with open(path, encoding="utf-8") as deck:
        text = deck.read()
    row = "2     Free        0.0     0.0      -10.0   1000   10      5      0"
    assert row in text
    smaller = tmp_path / "smaller_buoy.dat"            # each rank's own folder
    smaller.write_text(text.replace(row, row.replace("1000   10 ", "1000   6  ")))
    for deck, noted in ((path, True), (str(smaller), False)):
        system, notes = read_moordyn(deck)
        said = []
        results = solve_system(system, say=said.append, notes=notes)
        above = [line for line in said if "above the sea surface" in line]
        height = results.points["Point2"][2]
        if noted:
            assert 0.4 < height < 0.6
            assert above == [f"petsc_rod: note: point Point2 ends {height:.3g} m above the "
                             "sea surface, buoyed all the same by its 10 m^3 (a point's "
                             "volume is buoyant wherever it is, as in MoorDyn; a buoy that "
                             "floats at the surface is a body with its waterplane)"]
        else:
            assert -8.0 < height < -7.4 and above == []
