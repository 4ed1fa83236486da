"""A system's lines in the sea's own terms (petsc_rod/system/held_line.py): a sheared
current, a riser clamped to the body in a current, serially and on all ranks: the body's
6 x 6 (its Jacobian blocks from the riser's exact end stiffness, the drag's depth
derivative and its columns at the clamp in the riser's Newton Jacobian) against
central differences of the lines re-solved at moved and turned poses (the body and
springs of test_system_clamped.py)."""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.model.line import UniformLine
from petsc_rod.model.sea import Environment
from petsc_rod.system.equilibrium import Settings, SystemSolver

from test_system_clamped import COMMS, body_differences, factory, moored

pytestmark = pytest.mark.solver

# turning and slowing with depth below the sea surface (z = 0: the system's, none given)
SHEARED = ((0.0, 0.0, 0.6, 0.0), (30.0, 0.4, 0.1, 0.0))


def in_the_sea(environment, drag=(1025.0, 1.2, 0.2), kind="pin"):
    """moored(``kind``) with its riser of Morison drag ``drag`` in ``environment``."""
    system = moored(kind)
    riser = system.lines[3]
    line = dataclasses.replace(riser.line, drag=drag)
    return dataclasses.replace(system, lines=system.lines[:3] + (
        dataclasses.replace(riser, line=line),), environment=environment)


def assert_exact_body_stiffness(system, comm, make_line=None, body="buoy"):
    """The system solved (its lines from ``make_line``; None: factory's); its ``body``'s
    6 x 6 against central differences of the lines re-solved at moved and turned poses,
    to 1e-6 of its largest entry. Returns the solver (destroyed by the caller)."""
    solver = SystemSolver(system, make_line or factory(system), COMMS[comm],
                          settings=Settings(rtol=1e-12))
    try:
        assert solver.solve().load_factor == 1.0
        K = solver.body_stiffness(body).matrix
        numeric = body_differences(solver)
        scale = np.abs(K).max()
        error = np.abs(K - numeric).max() / scale
        print(f"K against differences {error:.3g} of {scale:.6g}")
        assert error < 1e-6
    except BaseException:
        solver.destroy()
        raise
    return solver


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_riser_in_a_sheared_current_has_the_exact_body_stiffness(comm):
    solver = assert_exact_body_stiffness(in_the_sea(Environment(current=SHEARED)), comm)
    try:
        # the current pushes the riser: the body's offset along y
        assert solver.state.bodies.X[0][1] > 0.05
    finally:
        solver.destroy()


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_riser_clamped_to_the_body_in_a_current_has_the_exact_body_stiffness(comm):
    """The clamp turns with the body and the drag at the clamped node with it."""
    system = in_the_sea(Environment(current=(0.2, 0.5, 0.0)), kind="clamp")
    assert_exact_body_stiffness(system, comm).destroy()
