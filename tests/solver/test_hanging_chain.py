"""A line of round sections pinned at S = 0 with a free lower end, from the straight
(horizontal) start: gravity swings it down to hang vertically (issue 47, "Traps";
docs/stability.md, "The hanging chain"). Its Newton attempts found H indefinite at every
iterate (the sections' roll, nearly free with GJ small, coupled to the bending by the
iterate's shear), and this one (20 elements, 2 steps) converged only after halvings
and saddle escapes; with the roll held in those steps (SecondVariation.hold_roll) it
converges in 70 iterations without either.

Closed form: an inextensible chain pinned at the origin hangs along -e_z,
r(S) = -S e_z, its tension w (L - S). On one rank and on all ranks (mpiexec -n 2)."""

import numpy as np
import pytest
from petsc4py import PETSc

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}
LENGTH = 100.0
WEIGHT = 2444.0           # N/m, the 120 mm chain of options/line_types/mooring_chain.txt
CHAIN = dict(length=LENGTH, stiffness=(1e3, 1e3, 1e3), start="pin", end="free",
             load_values=[[0.0, 0.0, -WEIGHT]])


@pytest.mark.parametrize("name", list(COMMS))
def test_a_pinned_chain_swings_down_to_hang_vertically(name, solver_factory):
    from petsc_rod.cli.session import run_continuation
    from petsc_rod.iteration.continuation import PathSettings
    from petsc_rod.problem.penalty import default_penalty
    from petsc_rod.scenes.scene import Scene
    _, solver = solver_factory(COMMS[name], 20, CHAIN, default_penalty(Scene(**CHAIN)),
                               rtol=1e-9, ctol=1e-9, max_it=2000)
    solver.problem.state.set_straight()
    result = run_continuation(solver, PathSettings(2), say=lambda line: None)
    assert result.converged and result.report.stable
    assert result.report.escapes == 0
    # the whole run, both steps: 70 iterations on 1 and 2 ranks (with the roll free
    # 2591 and a halving on 1 rank, 4759 and two on 2, each leaving saddles)
    assert result.iterations < 200
    state = solver.problem.state
    positions = state.node_positions()
    S = solver.problem.mesh.node_S()
    error = np.abs(positions - S[:, None] * np.array([0.0, 0.0, -1.0])).max()
    assert solver.problem.mesh.global_max(float(error)) < 1e-6 * LENGTH
