"""A penalty far below the problem's scale is raised on the way (problem/penalty.py)
and the cantilever reaches the elastica; kept low, the step does not converge."""

import numpy as np
import pytest

from helpers import CANTILEVER, continuation, gather
from petsc_rod.validation.closed_forms import cantilever_tip


@pytest.mark.parametrize("adapt", [True, pytest.param(False, marks=pytest.mark.slow)])
def test_a_penalty_far_below_the_scale_is_raised_and_the_elastica_reached(
        solver_factory, comm, adapt):
    """Cantilever P L^2/K = 3 at R = 1e-3 K/L^2 (scale 100): raised tenfold four times to
    10, the tip meets the elastica to 1e-5; kept at 1e-3 (-rod_al_adapt_penalty 0) the
    residual is still above 0.1 after 2000 iterations (docs/stability.md, "Planar
    bending")."""
    # the raise rule of the iteration itself (Newton raises R its own way, newton.py)
    mesh, solver = solver_factory(comm, 32, CANTILEVER, 1e-3, 1e-7, 1e-5, 2000, newton=False)
    solver.settings.adapt_penalty = adapt
    report = continuation(solver, steps=2)
    if not adapt:
        assert not report.converged and report.constraint_residual > 0.1
        assert solver.penalty == 1e-3
        return
    assert report.converged
    assert solver.penalty == pytest.approx(10.0)
    tip = gather(comm, solver.problem.state.r.owned()[:, 0])[-1]
    x, y = cantilever_tip(1.0, 1.0, 3.0)
    assert np.abs(tip - [x, y, 0.0]).max() < 1e-5
