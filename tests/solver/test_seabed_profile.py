"""A seabed profile in the Newton system (environment/bathymetry.py Profile: its height
box-smoothed over delta at the rows, with a curvature; Seabed.position_derivatives;
docs/riser.md §3a), on one rank (PETSc.COMM_SELF) and on all (PETSc.COMM_WORLD: under
``mpiexec -n 2`` the parallel run):

(a) test_held_line's mooring line on a profile whose slope turns by 3 degrees at a row
    8 m from the anchor, under its grounded part (nodes within delta/2 of the row in
    contact): with Newton steps it converges in fewer iterations than the plain
    iteration, to the same state, and is tested stable; the same on one rank and all;
(b) its HeldLine.stiffness (the profile's contact and curvature in the line's Newton
    system) against central differences of re-solves, every entry; and with the turn
    at 55 m, where the touchdown lies within the row's rounding;
(c) tests/data/moordyn/small_free_body.dat's body moored over a profile with a row under
    each chain's grounded part: its 6 x 6 against central differences of the
    equilibrium (test_system_environment.assert_exact_body_stiffness).
"""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import read_moordyn, solve
from petsc_rod.system.held_line import held_lines
from test_held_line import MOORING, TIGHT, against_differences, held, sloped_model
from test_system_environment import assert_exact_body_stiffness
from test_system_slope import DECK

pytestmark = pytest.mark.solver

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}
RISE = np.tan(np.radians(3.0))
# level to 8 m from the anchor (0.2 m below it), rising at 3 degrees beyond: one row
# under the grounded part; delta = 0.1 x 108 m
KINKED = ((-100.0, -30.2), (8.0, -30.2), (200.0, -30.2 + 192.0 * RISE))


def kinked_model(newton=True):
    model = sloped_model(seabed_profile=KINKED)
    return dataclasses.replace(model, options={**TIGHT, "al_newton": newton,
                                               "al_stability": newton})


def grounded_at_the_row(line):
    """The number of nodes in contact within delta/2 of the row (where h_s'' != 0)."""
    r = line.problem.state.node_positions()
    seabed = line.scene.seabed
    touching = r[:, 2] < seabed.heights(r[:, 0], r[:, 1])
    bent = seabed.shape.curvature(r[:, 0], r[:, 1]) != 0
    return line.mesh.global_sum(int(np.sum(touching & bent)))


def test_newton_on_a_kinked_profile_converges_to_the_plain_iteration_s_state():
    runs = {}
    for comm, newton in (("one rank", True), ("all ranks", True), ("one rank", False)):
        runs[comm, newton] = solve(kinked_model(newton), comm=COMMS[comm]).scalars
    newton, plain = runs["one rank", True], runs["one rank", False]
    print({key: (run["iterations"], run["newton_steps"]) for key, run in runs.items()})
    assert newton["converged"] and plain["converged"]
    # measured: 20 iterations (5 Newton steps) against 73
    assert newton["newton_steps"] > 0 and plain["newton_steps"] == 0
    assert newton["iterations"] < 0.5 * plain["iterations"]
    assert newton["stable"] == 1
    for key in ("fairlead_force_x", "fairlead_force_z", "anchor_horizontal",
                "anchor_vertical", "touchdown_S", "grounded_length"):
        assert newton[key] == pytest.approx(plain[key], rel=1e-9, abs=1e-9), key
        every = runs["all ranks", True]
        assert every[key] == pytest.approx(newton[key], rel=1e-9, abs=1e-9), key
    assert every["stable"] == 1


# the same turn at 55 m: the touchdown (56.3 m) within the row's rounding (delta = 14.5 m)
AT_THE_TOUCHDOWN = ((-100.0, -30.2), (55.0, -30.2), (200.0, -30.2 + 145.0 * RISE))


@pytest.mark.parametrize("rows", [KINKED, AT_THE_TOUCHDOWN], ids=["grounded", "touchdown"])
@pytest.mark.parametrize("comm", list(COMMS))
def test_stiffness_on_a_kinked_profile(comm, rows):
    """The (6, 6) against central differences of re-solves (measured 5.6e-8 and 3.4e-9
    on one rank, 2.3e-8 and 5.5e-9 on two; 1.0e-2 and 3.4e-3 with the curvature's terms
    left out)."""
    line = held(sloped_model(seabed_profile=rows), COMMS[comm], MOORING)
    try:
        assert grounded_at_the_row(line) >= 5
        K = line.stiffness()
        assert np.abs(K - K.T).max() < 1e-10 * np.abs(K).max()
        assert against_differences(line, K) < 1e-6
    finally:
        line.destroy()


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_body_moored_over_a_profile_has_the_exact_stiffness(comm):
    """Rows at x = -24 m (under the two chains to the anchors at x = -32.5 m: the seabed
    falls 2 degrees toward them) and x = 50 m (under the chain to x = 65 m: it falls 2
    degrees beyond), level between."""
    rise = np.tan(np.radians(2.0))
    rows = ((-100.0, -30.2 - 76.0 * rise), (-24.0, -30.2), (50.0, -30.2),
            (200.0, -30.2 - 150.0 * rise))
    system, _ = read_moordyn(str(DECK))
    environment = dataclasses.replace(system.environment, seabed=None, seabed_profile=rows,
                                      seabed_direction=0.0, seabed_origin=(0.0, 0.0))
    system = dataclasses.replace(system, environment=environment)
    solver = assert_exact_body_stiffness(system, comm, held_lines(system, TIGHT), "Body1")
    try:
        for line in solver.lines.values():
            if line is not None:
                assert grounded_at_the_row(line) >= 5
    finally:
        solver.destroy()
