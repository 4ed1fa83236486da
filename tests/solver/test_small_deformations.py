"""Small deformations converge to the solution of the problem posed (docs/method.md §6).

The stopping tests measure the change and the constraint residual against the size of
the deformation, so a deformation of 1e-8 of the rod's size is resolved as well as one
of order one: with the default tolerances (stopping.Settings), each case below is
within 1e-6 of linear theory. Linear theory is exact to O((P L^2 / EI)^2) or
O(angle^2) here, and the P2 slope holds the cubic deflection and the uniform twist
exactly. With the former test (change relative to |X|) these runs stopped after one or
two iterations: the stiff cantilever's tip deflection was 2.79e-10 m against 1e-8, the
tiny twist's u3 off by a factor 4.4. Serial and under mpiexec -n 2.
"""

import numpy as np
import pytest

from helpers import continuation, gather
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.iteration.stopping import Settings
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene

DEFAULTS = Settings(asked_penalty=0.0)
BOUND = 1e-6            # relative to the deformation


def solve(comm, solver_factory, scene, steps=2):
    """The scene at the command line's defaults (penalty, rtol, ctol) on 16 elements;
    the vertex fields gathered on every rank."""
    _, solver = solver_factory(comm, 16, scene, default_penalty(Scene(**scene)),
                               DEFAULTS.rtol, DEFAULTS.ctol, DEFAULTS.max_it)
    report = continuation(solver, steps=steps)
    assert report.converged
    fields = {key: gather(comm, value) for key, value in vertex_fields(solver.problem).items()}
    return report, fields


@pytest.mark.parametrize("length, stiffness, force", [
    (1.0, 1e8, 3.0),            # stiff: the case
    (1e-3, 1.0, 0.03),          # short: a 1 mm rod
    (1.0, 1.0, 1e-8),           # a tiny load
])
def test_a_small_tip_deflection_is_resolved(comm, solver_factory, length, stiffness, force):
    scene = dict(length=length, stiffness=(stiffness,) * 3, start="clamp", end="free",
                 end_force=(0.0, -force, 0.0))
    report, fields = solve(comm, solver_factory, scene)
    exact = force * length**3 / (3 * stiffness)            # P L^3 / 3 EI
    deflection = -fields["r"][-1, 1]
    assert abs(deflection - exact) / exact < BOUND
    assert report.iterations > 2        # the former test stopped after 1 or 2


def test_a_tiny_twist_is_resolved(comm, solver_factory):
    angle = 1e-8
    scene = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="clamp",
                 end_twist=angle)
    _, fields = solve(comm, solver_factory, scene)
    assert np.abs(fields["u"][:, 2] - angle).max() / angle < BOUND
    assert np.abs(fields["u"][:, :2]).max() < BOUND * angle


def test_the_norms_are_relative_to_the_deformation(comm, solver_factory):
    """RodState.norms: scale is the deformation's relative size (1 for a large one,
    DEFORMATION_FLOOR below it), which the stopping test divides change and residual by."""
    from petsc_rod.problem.state import DEFORMATION_FLOOR
    scene = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free",
                 end_force=(0.0, -1e-12, 0.0))
    _, solver = solver_factory(comm, 16, scene, 100.0)
    state = solver.problem.state
    state.set_straight()
    solver.problem.prepare(1.0)
    solver.problem.iterate()
    assert state.norms().scale == DEFORMATION_FLOOR     # a deflection of 3e-13 m
    bent = dict(scene, end_force=(0.0, -3.0, 0.0))
    _, solver = solver_factory(comm, 16, bent, 100.0)
    assert continuation(solver, steps=2).converged
    solver.problem.iterate()
    norms = solver.problem.state.norms()
    assert DEFORMATION_FLOOR < norms.scale < 1.0        # tip 0.6 L down, turned by 1.1 rad
    assert norms.change / norms.scale < DEFAULTS.rtol
    assert norms.residual / norms.scale < DEFAULTS.ctol
