"""The straight start of a line with a seabed (docs/method.md §10, "The straight start
with a seabed"), on one rank (PETSc.COMM_SELF) and on all ranks (PETSc.COMM_WORLD: under
``mpiexec -n 2`` the parallel run).

(a) The first step of a heavy riser from its straight reference brings the end nearer
    than the length: the straight line buckles, and the iteration first meets the planar
    saddle. With a seabed out of reach the problem is the one without a seabed, and so
    must be the step: converged, at the same state. It was not: with a seabed the
    Newton attempts found H indefinite and the state was not left before it converged
    to the saddle (2000 iterations, not converged).
    With a seabed the early escape waits for a second indefinite attempt (c).
(b) A linear-algebra failure of the stability test (a second variation singular to
    round-off at a shift of its bisection) ends the step as a failed attempt, said in
    the step's report, instead of a traceback.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.analysis import stability
from petsc_rod.environment.seabed import Seabed
from petsc_rod.iteration import controller, newton, stopping
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}

# A 2 km steel line of 1.2 kN/m (EI 5.6e7 N m^2) from an anchor at the origin to a pin
# 1506 m away and 1000 m up; its first step of 40 from the straight reference (t = 1/40)
# brings the end 12 m nearer than the length, 25 m up.
HEAVY = dict(length=2000.0, stiffness=(5.6e7, 5.6e7, 4.3e7), start="pin", end="pin",
             end_position=(1506.0, 0.0, 1000.0), load_values=[[0.0, 0.0, -1200.0]])
FIRST_STEP = 1.0 / 40
ELEMENTS = 100


@pytest.fixture(scope="module", params=list(COMMS))
def comm(request):
    return COMMS[request.param]


def first_step(solver_factory, comm, scene):
    """(solver, report) of the first step from the straight reference."""
    _, solver = solver_factory(comm, ELEMENTS, scene, default_penalty(Scene(**scene)),
                               rtol=1e-9, ctol=1e-9, max_it=2000)
    solver.problem.state.set_straight()
    return solver, solver.solve_step(FIRST_STEP)


def test_a_straight_start_with_a_seabed_out_of_reach_leaves_its_saddle(comm, solver_factory):
    free, free_report = first_step(solver_factory, comm, HEAVY)
    below, report = first_step(solver_factory, comm, {**HEAVY, "seabed": Seabed(-4000.0, 1.2e6)})
    assert free_report.converged and free_report.stable
    assert report.converged and report.stable, report
    assert report.iterations < 600
    # the same equilibrium: the lowest point about 170 m below the anchor, the seabed
    # 3800 m below that
    lowest = below.problem.mesh.global_min(
        float(below.problem.state.node_positions()[:, 2].min()))
    assert -1000.0 < lowest < -10.0
    for a, b in ((free.problem.state.r, below.problem.state.r),
                 (free.problem.state.d1, below.problem.state.d1)):
        assert np.abs(a.owned() - b.owned()).max() < 1e-4 * HEAVY["length"]


def test_a_failed_factorisation_of_the_stability_test_fails_the_step(
        comm, solver_factory, monkeypatch):
    def fails(self):
        raise np.linalg.LinAlgError("Eigenvalues did not converge")

    monkeypatch.setattr(stability.StabilityTest, "descent_direction", fails)
    scene = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                 end_force=(0.0, -3.0, 0.0))
    _, solver = solver_factory(comm, 16, scene, 100.0, newton=False)
    solver.problem.state.set_straight()
    report = solver.solve_step(1.0)
    assert not report.converged
    assert report.reason == stopping.STOP_UNTESTED


@pytest.mark.parametrize("switch, first", [(True, True), (controller.NEWTON_SWITCH_FAR, False)])
def test_a_far_reaching_system_escapes_early_after_a_second_indefinite_attempt(switch, first):
    """Without a seabed one indefinite attempt near an equilibrium leaves the state at
    once; with one (NEWTON_SWITCH_FAR) the first attempt's H is an iterate's, and only a
    second, nearer, is taken for a saddle."""
    step = controller.StepController(stopping.Settings(asked_penalty=1.0), 1.0, switch)
    step.observe(1e-3, 1e-3, 1.0)
    step.newton_failed(newton.INDEFINITE)
    assert step.wants_early_escape() is first
    step.observe(1e-4, 1e-4, 1.0)
    step.newton_failed(newton.INDEFINITE)
    assert step.wants_early_escape() is True
