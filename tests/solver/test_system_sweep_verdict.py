"""The system's verdict at every case of a watch circle and of load-excursion curves
(system/excursions.py, api/system_sweeps.py; docs/systems.md "Excursions and the watch
circle"): the small free body (tests/data/moordyn/small_free_body.dat) stable at every
heading, its lowest eigenvalue at heading 0 the Equilibrium's own verdict under the
same load solved directly; the same body with Line1 crossed under it
(tests/data/moordyn/crossed_line.dat: its fairlead at x = -5 m, its anchor at x = 55 m)
stable at rest but a saddle in yaw under 60 kN towards -x (the crossed line, taut,
pulls its fairlead across the body: turning the body shortens it), its watch circle's
case reported as a saddle in the table, the file's group and the run's lines. Serially
and under mpiexec -n 2 (the lines split over the ranks)."""

import os

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import REPO_ROOT
from petsc_rod.api import read_moordyn
from petsc_rod.api.system_sweeps import file_group, run_lines, sweep_saddles, table_text
from petsc_rod.system.equilibrium import SystemSolver
from petsc_rod.system.excursions import loaded, watch_circle
from petsc_rod.system.held_line import held_lines

pytestmark = pytest.mark.solver

DATA = os.path.join(REPO_ROOT, "tests", "data", "moordyn")
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}


def solver_of(system):
    return SystemSolver(system, held_lines(system, TIGHT), PETSc.COMM_WORLD)


def test_the_small_free_bodys_watch_circle_is_stable_at_every_heading():
    system, _ = read_moordyn(os.path.join(DATA, "small_free_body.dat"))
    solver = solver_of(system)
    try:
        circle = watch_circle(solver, "Body1", 2e4, [0.0, 180.0])
    finally:
        solver.destroy()
    direct = solver_of(loaded(system, "Body1", np.array([2e4, 0.0, 0.0])))
    try:
        own = direct.solve().verdict
    finally:
        direct.destroy()
    assert circle.stable.tolist() == [1, 1] and circle.saddles() == []
    assert own.stable is True
    # the warm watch circle's heading 0 is the direct solve's equilibrium
    assert circle.lowest_eigenvalue[0] == pytest.approx(own.lowest, rel=1e-8)
    assert np.all(circle.lowest_eigenvalue > 1e3)                   # N/m
    assert circle.verdict_text() == "all stable"
    assert table_text(circle).splitlines()[0].startswith(
        "heading (deg),load (N),x_offset (m),y_offset (m),x (m),y (m),z (m),roll (rad),"
        "pitch (rad),yaw (rad),verdict,lowest_eigenvalue (N/m),max_tension (N)")
    assert [row.split(",")[10] for row in table_text(circle).splitlines()[1:]] == \
        ["stable"] * 2
    data, attributes, units = file_group(circle)
    assert data["verdict"].tolist() == [1.0, 1.0]
    assert data["lowest_eigenvalue"] == pytest.approx(circle.lowest_eigenvalue, rel=0)
    assert units["lowest_eigenvalue"] == "N/m"
    assert attributes["converged"] == 1 and attributes["saddles"] == 0
    assert ("petsc_rod: watch circle: 2 heading(s), the system's verdict: all stable"
            in run_lines({"watch_circle": circle}))
    assert sweep_saddles({"watch_circle": circle}) == ""


def test_a_saddle_in_the_watch_circle_is_kept_and_marked():
    system, _ = read_moordyn(os.path.join(DATA, "crossed_line.dat"), 2.0)
    solver = solver_of(system)
    try:
        rest = solver.solve().verdict
        circle = watch_circle(solver, "Body1", 6e4, [180.0])
    finally:
        solver.destroy()
    assert rest.stable is True
    assert circle.stable.tolist() == [0]
    assert circle.lowest_eigenvalue[0] < -1e3                       # N/m, in yaw
    assert circle.saddles() == [(180.0, 6e4)]
    # its numbers are kept: the body pushed 7.7 m towards -x, yaw 0 by symmetry
    assert np.all(np.isfinite(circle.poses)) and circle.offsets[0, 0] < -7.0
    assert abs(circle.poses[0, 5]) < 1e-6
    rows = [row.split(",") for row in table_text(circle).splitlines()]
    column = rows[0].index("verdict")
    assert rows[1][column] == "saddle"
    assert float(rows[1][column + 1]) == pytest.approx(circle.lowest_eigenvalue[0],
                                                        rel=1e-11)
    data, attributes, _ = file_group(circle)
    assert data["verdict"].tolist() == [0.0]
    assert attributes["converged"] == 0 and attributes["saddles"] == 1
    assert attributes["system_verdict"] == "1 saddle(s) of the system: heading 180 deg"
    assert run_lines({"watch_circle": circle})[-1] == (
        "petsc_rod: watch circle: 1 heading(s), the system's verdict: 1 saddle(s) of the "
        "system: heading 180 deg")
    assert sweep_saddles({"watch_circle": circle}) == (
        "the watch circle of Body1 has 1 saddle(s) of the system: heading 180 deg")
