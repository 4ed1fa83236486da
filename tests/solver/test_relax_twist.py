"""RodProblem.relax_twist: the twist a step adds to a line of round sections clamped at
both ends, spread as a uniform torque before the step (docs/method.md §7, "The twist of
round sections"), the same on any number of ranks (a rank without elements included)."""

import numpy as np
import pytest

from helpers import gather
from petsc_rod.frames import roll_between
from petsc_rod.iteration.controller import NEWTON_AFTER
from petsc_rod.scenes.scene import REFERENCE_FRAME


def rolled_line(solver_factory, comm, n_elements, length, penalty, stiffness=(1.0, 1.0, 0.5)):
    """The straight state of a clamped-clamped rod whose end is rolled by 2 rad, relaxed
    for load factor 1: (S, roll of each node's tau against the straight frame, the end
    frame's roll), gathered."""
    scene = dict(length=length, stiffness=stiffness, start="clamp", end="clamp",
                 end_twist=2.0)
    mesh, solver = solver_factory(comm, n_elements, scene, penalty)
    problem = solver.problem
    problem.state.set_straight()
    problem.relax_twist(0.0, 1.0, NEWTON_AFTER)
    tau = gather(comm, problem.state.tau)
    S = gather(comm, mesh.node_S())
    end = roll_between(REFERENCE_FRAME, problem.scene.end_state(1.0).frame)
    return S, roll_between(np.broadcast_to(REFERENCE_FRAME, tau.shape), tau), end


@pytest.mark.parametrize("n_elements", [2, 9])
def test_a_long_line_is_rolled_to_a_uniform_twist(comm, solver_factory, n_elements):
    """100 m at R = 1e3 N: the slowest roll mode needs sqrt(R L^2 / K3) / pi = 1.4e3
    iterations an e-fold, so the roll is made: phi(S) = a S / L up to the clamped end,
    whose tau is the clamp's to set."""
    S, roll, end = rolled_line(solver_factory, comm, n_elements, 100.0, 1e3)
    assert abs(end) == pytest.approx(2.0, abs=1e-12)
    assert np.abs(roll[:-1] - end * S[:-1] / 100.0).max() < 1e-12
    assert abs(roll[-1]) < 1e-12


def test_a_short_rod_is_left_to_the_iteration(comm, solver_factory):
    """1 m at R = 100 N (the penalty of its stiffness): sqrt(R L^2 / K3) / pi = 4.5 <
    NEWTON_AFTER, nothing is rolled."""
    _, roll, _ = rolled_line(solver_factory, comm, 9, 1.0, 100.0)
    assert np.all(roll == 0.0)


def test_a_line_with_unequal_bending_stiffnesses_is_not_rolled(comm, solver_factory):
    """K1 != K2: the torque is not uniform at equilibrium; nothing is rolled."""
    _, roll, _ = rolled_line(solver_factory, comm, 9, 100.0, 1e3, stiffness=(1.0, 2.0, 0.5))
    assert np.all(roll == 0.0)
