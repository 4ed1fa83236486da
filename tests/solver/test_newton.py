"""Newton steps on the reduced problem near a solution (petsc_rod/iteration/newton.py,
docs/method.md §11), on 1 or several ranks.

- The steps converge quadratically, to the state the iteration alone reaches (same r and
  frames to 1e-9 at tolerances 1e-12), in fewer iterations.
- They stay quadratic on a fine mesh (1000 elements of a twisted clamped-clamped rod),
  where a solve with H + tolerance M in place of H made them linear.
- The handed-over state is a fixed point of the Uzawa map: one plain iteration moves it
  by round-off only.
- Newton does not take a step at a saddle: at the planar equilibrium of the paper scene
  (reached with the stability test off) it reports negative curvature and leaves the
  state as it was.
- A strongly anisotropic section (K2 = 100 K1, a non-convex split) converges in tens of
  iterations to the elastica.
"""

import numpy as np
import pytest

from helpers import CANTILEVER, PAPER_SCENE as PAPER, continuation, gather
from petsc_rod.iteration import newton
from petsc_rod.validation.closed_forms import cantilever_tip

TIGHT = 1e-12


def newton_turns(report):
    """The largest turn of each Newton step, rad (the rows newton records: residual 0)."""
    return [change for change, residual, _ in report.history if residual == 0.0]


def owned_fields(solver):
    comm = solver.problem.mesh.comm
    return {name: gather(comm, field.owned()) for name, field in
            (("r", solver.problem.state.r), ("d1", solver.problem.state.d1), ("d2", solver.problem.state.d2))}


def test_newton_is_quadratic_and_ends_where_the_iteration_alone_does(solver_factory, comm):
    results = {}
    for with_newton in (True, False):
        _, solver = solver_factory(comm, 16, CANTILEVER, 100.0, TIGHT, TIGHT, 5000,
                                   newton=with_newton)
        report = continuation(solver, steps=2)
        assert report.converged
        results[with_newton] = report, owned_fields(solver)
    (fast, with_fields), (slow, without_fields) = results[True], results[False]
    turns = newton_turns(fast)
    assert len(turns) >= 3 and turns[-1] < newton.STEP_TOLERANCE
    for before, after in zip(turns, turns[1:]):
        if before < 1e-2:               # in the basin: the error squares at each step
            assert after <= max(10 * before**2, 1e-11), turns
    assert fast.iterations < slow.iterations / 2
    for name, values in with_fields.items():
        assert np.abs(values - without_fields[name]).max() < 1e-9, name


def test_newton_stays_quadratic_on_a_fine_mesh(solver_factory, comm):
    # the first two load steps of options/greenhill.opts: the tolerance shift of the
    # inertia test grows like the square of the element count
    twisted = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="clamp",
                   end_position=(0.99, 0.01, 0.0), end_twist=1.2566371)
    _, solver = solver_factory(comm, 1000, twisted, 315.827, 1e-10, 1e-10, 5000)
    report = continuation(solver, steps=2, imperfection=0.01)
    assert report.converged
    turns = newton_turns(report)
    assert len(turns) >= 3 and turns[-1] < newton.STEP_TOLERANCE
    for before, after in zip(turns, turns[1:]):
        if before < 1e-2:
            assert after <= max(10 * before**2, 1e-11), turns


def test_the_handed_over_state_is_a_fixed_point_of_the_uzawa_map(solver_factory, comm):
    _, solver = solver_factory(comm, 16, CANTILEVER, 100.0, 1e-3, 1e-3, 5000, newton=False)
    assert continuation(solver, steps=1).converged          # near, not at, the solution
    polish = newton.NewtonSolver(solver.problem)
    try:
        assert polish.run() == newton.CONVERGED
        assert polish.least_penalty() < solver.penalty
    finally:
        polish.destroy()
    solver.problem.iterate()
    change, residual, _ = solver.problem.state.norms()
    assert change < 1e-12 and residual < 1e-12


def test_newton_takes_no_step_at_a_saddle(solver_factory, comm):
    _, solver = solver_factory(comm, 40, PAPER, 400.0, 1e-10, 1e-10, 5000)
    solver.settings.check_stability = False     # the accelerated iteration ends planar
    report = continuation(solver, steps=8)
    assert report.converged and report.newton_steps == 0
    planar = gather(comm, solver.problem.state.r.owned())
    assert np.abs(planar[:, 0, 2]).max() < 1e-8
    assert solver.newton.run() == newton.INDEFINITE
    assert np.array_equal(gather(comm, solver.problem.state.r.owned()), planar)   # left as it was


@pytest.mark.parametrize("ratio", [100.0])
def test_an_anisotropic_cantilever_converges_in_tens_of_iterations(solver_factory, comm,
                                                                   ratio):
    scene = dict(CANTILEVER, stiffness=(1.0, ratio, 1.0), end_force=(0.0, 0.0, -3.0))
    _, solver = solver_factory(comm, 32, scene, 100.0, 1e-9, 1e-9, 5000)
    report = continuation(solver, steps=2)
    assert report.converged and report.iterations < 60
    tip = cantilever_tip(1.0, 1.0, 3.0)
    r = gather(comm, solver.problem.state.r.owned())[-1, 0]
    assert np.abs(r - np.array([tip[0], 0.0, tip[1]])).max() < 1e-5
