"""A system's lines on a seabed grid (system/held_line.py: the grid's contact in each
line's Newton system, Seabed.profile_derivatives with Grid.slopes, at the fixed point
of the line's lagged iteration): tests/data/moordyn/small_free_body.dat (a free
buoyant body on three 70 m chains) read by the API with its seabed a grid level at
-30.2 m up to x = -20 m, sloping in x and in y (with a twist) beyond, and falling 0.03
more along x beyond a grid line at x = LINE, so that the grounded part of the chain
to the anchor at x = 65 m spans it, some of its nodes within delta / 2 of it (where
the secant's turn Dg enters the block); the chains to the other anchors, heading 120
degrees off the grid's axes, ground mostly on its level part, where the lagged
iteration's walks are short. The body's 6 x 6 against
central differences of the lines re-solved at moved and turned poses, serially and on
all ranks, and the same pose and stiffness either way (as test_system_profile's)."""

import dataclasses

import numpy as np
import pytest

from petsc_rod.api import read_moordyn

from test_system_profile import DECK, START, same_on_one_rank_and_all

pytestmark = pytest.mark.solver

# the grid line the chain's grounded part spans, m along +x; the lines 40 m apart at
# the closest along x, so the secant turns over 4 m about each
LINE = 55.0
XS, YS = (-100.0, -20.0, LINE, LINE + 40.0, 200.0), (-100.0, 30.0, 100.0)
GRID = tuple((x, y, -30.2 + max(x + 20.0, 0.0) * (-0.004 + 3e-5 * y)
                - 0.03 * max(x - LINE, 0.0)) for x in XS for y in YS)


def on_a_grid():
    """The deck's system with its seabed GRID from the origin, its body starting at
    START."""
    system, _ = read_moordyn(str(DECK))
    environment = dataclasses.replace(system.environment, seabed=None,
                                      seabed_profile=GRID, seabed_origin=(0.0, 0.0))
    body = dataclasses.replace(system.bodies[0], position=START)
    return dataclasses.replace(system, bodies=(body,), environment=environment)


def grounded_at_the_line(solver):
    """The x (m) of the lines' grounded nodes on this rank where the secant turns
    (g != grad z_b), all of them within 3 m of LINE."""
    near = []
    for line in solver.lines.values():
        seabed = line.scene.seabed
        r = line.problem.state.node_positions()
        rise, g, _ = seabed.shape.slopes(r[:, 0], r[:, 1])
        turning = (seabed.gap(r) < 0) & (np.abs(g - rise).max(axis=1) > 1e-12)
        x = r[turning, 0] - seabed.shape.origin[0]
        assert np.all(np.abs(x - LINE) < 3.0)
        near.extend(x)
    return near


def test_a_body_moored_on_a_grid_has_the_exact_stiffness_on_one_rank_and_all():
    """The system solved on one rank and on all: the same pose and stiffness; on all,
    its stiffness against differences."""
    X = same_on_one_rank_and_all(on_a_grid(), grounded_at_the_line, 4)
    # the grid falls along x and beyond the line: the body drifts toward +x; and it
    # rises along y under the chain to x = 65 m: toward -y
    assert X[0] > 1e-3 and X[1] < -1e-4
