"""A system's lines on a seabed profile (system/held_line.py: the profile's contact in
each line's Newton system, Seabed.profile_derivatives, at the fixed point of the line's
lagged iteration): tests/data/moordyn/small_free_body.dat (a free buoyant body on
three 70 m chains) read by the API with its seabed a profile along +x, level at
-30.2 m up to a row at x = ROW and falling beyond it, so that the grounded part of the
chain to the anchor at x = 65 m spans the row, some of its nodes within delta / 2 of it
(where the secant's turn g' enters the block). The body's 6 x 6 against central
differences of the lines re-solved at moved and turned poses, serially and on all
ranks, and the same pose and stiffness either way."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import read_moordyn
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import held_lines

from test_system_clamped import body_differences

pytestmark = pytest.mark.solver

DECK = Path(__file__).parents[1] / "data" / "moordyn" / "small_free_body.dat"
# a profile's walks take no Newton steps (its lagged push keeps the run out of them):
# the lines' tolerance of a few seconds' test, and differences' steps to match
# (1e-3 m, 1e-4 rad: their noise 4e-6 of K with the usual 1e-4 m)
TOLERANCE = {"al_rtol": 1e-10, "al_ctol": 1e-10}
STEPS = (1e-3,) * 3 + (1e-4,) * 3
# the row the chain's grounded part spans, m along +x; the rows 40 m apart at the
# closest, so the secant turns over delta = 4 m about each
ROW = 55.0
PROFILE = ((-100.0, -30.2), (ROW, -30.2), (ROW + 40.0, -31.4), (200.0, -31.4))
# the body's start: near its equilibrium on the profile (m), so that the system's first
# step walks each line a little
START = (0.0, 0.0, 1.4, 0.0, 0.0, 0.0)


def on_a_profile():
    """The deck's system with its seabed PROFILE along +x from the origin, its body
    starting at START."""
    system, _ = read_moordyn(str(DECK))
    environment = dataclasses.replace(system.environment, seabed=None,
                                      seabed_profile=PROFILE, seabed_direction=0.0,
                                      seabed_origin=(0.0, 0.0))
    body = dataclasses.replace(system.bodies[0], position=START)
    return dataclasses.replace(system, bodies=(body,), environment=environment)


def solved(comm, system):
    solver = SystemSolver(system, held_lines(system, TOLERANCE), comm,
                          settings=Settings(rtol=1e-12))
    try:
        assert solver.solve().load_factor == 1.0
    except BaseException:
        solver.destroy()
        raise
    return solver


def grounded_near_the_row(solver):
    """The distances along the profile (m) of the lines' grounded nodes on this rank
    where the secant turns (g' != 0), all of them within 3 m of ROW."""
    near = []
    for line in solver.lines.values():
        seabed = line.scene.seabed
        r = line.problem.state.node_positions()
        d = seabed.shape.along(r[:, 0], r[:, 1])
        turning = (seabed.gap(r) < 0) & (seabed.shape.slopes(r[:, 0], r[:, 1])[2] != 0)
        assert np.all(np.abs(d[turning] - ROW) < 3.0)
        near.extend(d[turning])
    return near


def same_on_one_rank_and_all(system, turning, at_least):
    """``system`` solved on one rank and on all: the same pose and stiffness; on all, at
    least ``at_least`` grounded nodes in the secant's turn (``turning(solver)``: this
    rank's) and its stiffness against differences. Its pose on all ranks."""
    alone = solved(PETSc.COMM_SELF, system)
    try:
        X1, K1 = alone.state.bodies.X[0].copy(), alone.body_stiffness("Body1").matrix.copy()
    finally:
        alone.destroy()
    solver = solved(PETSc.COMM_WORLD, system)
    try:
        near = PETSc.COMM_WORLD.tompi4py().allgather(len(turning(solver)))
        assert sum(near) >= at_least               # the secant's turn in the block
        X, K = solver.state.bodies.X[0], solver.body_stiffness("Body1").matrix
        assert np.abs(X - X1).max() < 1e-9
        assert np.abs(K - K1).max() < 1e-8 * np.abs(K1).max()
        error = np.abs(K - body_differences(solver, STEPS)).max() / np.abs(K).max()
        print(f"K against differences {error:.3g} of {np.abs(K).max():.6g}")
        assert error < 1e-6
        print("body", X)
        return X.copy()
    finally:
        solver.destroy()


def test_a_body_moored_on_a_profile_has_the_exact_stiffness_on_one_rank_and_all():
    """The system solved on one rank and on all: the same pose and stiffness; on all,
    its stiffness against differences."""
    X = same_on_one_rank_and_all(on_a_profile(), grounded_near_the_row, 4)
    # the profile falls beyond the row: the chain's grounded part pulls the body
    # toward the anchor at x = 65 m
    assert X[0] > 1e-3
