"""A body held in its translations and free to turn (a vessel at a prescribed offset,
its pitch and roll in equilibrium), re-solved warm at an offset (SystemSolver.solve of
the system with the body's position moved in its held translations: the continuation
walks it there, its hydrostatic reference moved with it) is the fresh solver's
equilibrium at that offset; a move in a free direction is still refused. On the mock
springs of test_system_equilibrium.py."""

from dataclasses import replace

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.errors import RodInputError
from petsc_rod.system.equilibrium import Settings, SystemSolver

from test_system_equilibrium import equilibrium, spread, spring

pytestmark = pytest.mark.solver

HELD = (True, True, True, False, False, False)


def at(system, offset):
    body = system.bodies[0]
    position = np.array(body.position, dtype=float)
    position[:3] += offset
    return replace(system, bodies=(replace(body, position=tuple(position)),))


def test_a_held_body_moved_warm_is_the_fresh_equilibrium_there():
    base = spread(load=(2e5, 0, 0, 0, 0, 3e5), held=HELD)
    moved = at(base, (8.0, -5.0, 1.0))
    solver = SystemSolver(base, spring, PETSc.COMM_SELF, settings=Settings(rtol=1e-13))
    try:
        before = solver.solve()
        again = solver.solve(moved)
        turned = replace(base.bodies[0], position=(0.0, 0.0, 0.0, 0.1, 0.0, 0.0))
        with pytest.raises(RodInputError, match="re-solves its system"):
            solver.solve(replace(base, bodies=(turned,)))     # its roll is free
    finally:
        solver.destroy()
    _, fresh, _ = equilibrium(moved)
    assert again.bodies["floater"][:3] == pytest.approx([8.0, -5.0, 1.0], abs=1e-12)
    # the body turned in equilibrium at both places, differently
    assert np.abs(again.bodies["floater"][3:] - before.bodies["floater"][3:]).max() > 1e-3
    assert again.bodies["floater"] == pytest.approx(fresh.bodies["floater"], abs=1e-10)
    assert again.end_forces == pytest.approx(fresh.end_forces, rel=1e-9)
