"""The array scene's generator (scripts/make_array.py) at 2 x 2: four free floaters on a
shared-anchor honeycomb (12 lines, 8 anchors, some shared), read from the MoorDyn file
it writes, solved with real lines (system/held_line.held_lines) on one rank and with
the lines spread over every rank: the same answer, and the floaters' lines balance the
steady force on them. Serially and under mpiexec -n 2."""

import os
import sys
import tempfile

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import REPO_ROOT
from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.system.equilibrium import solve_system
from petsc_rod.system.held_line import held_lines

sys.path.insert(0, os.path.join(REPO_ROOT, "scripts"))
import make_array  # noqa: E402

pytestmark = pytest.mark.solver


@pytest.fixture(scope="module")
def array():
    """The 2 x 2 array's System (40 m elements: 11 a line), read on every rank from a
    file of its own."""
    handle, path = tempfile.mkstemp(suffix=".dat")
    try:
        with os.fdopen(handle, "w") as file:
            file.write(make_array.deck(2, 2))
        system, _ = read_moordyn(path, element_length=40.0)
    finally:
        os.remove(path)
    return system


def test_the_2x2_array_is_the_same_on_one_rank_and_on_every_rank(array):
    alone, _ = solve_system(array, held_lines(array), PETSc.COMM_SELF, stiffness=False)
    if PETSc.COMM_WORLD.size > 1:           # on one rank the same solve twice
        spread, _ = solve_system(array, held_lines(array), PETSc.COMM_WORLD,
                                 stiffness=False)
        for name, pose in alone.bodies.items():
            assert np.array_equal(spread.bodies[name], pose), name
        assert np.array_equal(spread.end_forces, alone.end_forces)
    assert len({line.start.to for line in array.lines}) == 8          # anchors shared
    # the floaters' lines balance the steady 50 kN along x on each of them, to the
    # residual Newton stops at (Settings.floor: 1e-7 of the largest line force a
    # floater; measured 0.011 N along y)
    pull = alone.end_forces[:, 1, :].sum(axis=0)
    tolerance = 4 * 1e-7 * np.abs(alone.end_forces).max()
    assert pull[:2] == pytest.approx([-4 * make_array.FORCE, 0.0], abs=tolerance)
    # they move downwind by about the force over the spread's surge stiffness
    offsets = np.array([alone.bodies[b.name][0] - b.position[0] for b in array.bodies])
    assert np.all(offsets > 0.5) and np.all(offsets < 5.0)
