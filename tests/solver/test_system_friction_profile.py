"""A system's lines with Coulomb friction on a seabed profile (system/held_line.py,
"Friction" and "Seabed profile": the plane's friction law with the secant gradient g
read at each node, its turn g' e e^T and the limit mu R following the interpolant's
height z_b(d) and k_v(g): FrictionTerm._shape_rates), on
tests/data/moordyn/small_free_body.dat (a free buoyant body on three 70 m chains) read
by the API, friction mu = 0.5:

(a) the deck's second chain on a profile along +x, level at -30.2 m to a row at x = ROW
    and falling 1.2 m over the next 40 m, its grounded part spanning the row (some of
    its grounded nodes within delta / 2 = 2 m of it, where g' != 0), laid and its
    fairlead moved 4 m along x, its grounded nodes partly sticking, partly sliding: its
    end stiffness against central differences of re-solves, the same on one rank and
    on all. The re-solves are settled by Newton's steps (HeldLine.settle: the stationary
    point of the linearised gradient, which is the lagged iteration's fixed point,
    checked here) so that the differences are those of the fixed point to round-off
    rather than to the lagged iteration's tolerance;
(b) the body on its three chains on tests/solver/test_system_profile.py's profile (a row
    at x = 55 m, the chain to the anchor at x = 65 m grounded across it) with the
    friction: converged, that chain partly sliding, its 6 x 6 against central
    differences of the lines re-solved (and settled) at moved and turned poses, the
    same pose on one rank and on all.

(c) the same chain on a grid: that profile plus a twist TWIST (x - x_a) (y - y_a) about
    the anchor (bilinear, so exact on the grid), whose secant gradient turns in both
    directions (Dg's off-diagonal at every grounded node): its end stiffness against
    central differences of re-solves (measured 2.6e-8 of its largest entry, 1.11e5 N/m;
    with Dg left out of the friction's block 3.6e-6), the same on one rank and on all
    (1.6e-12).

Before, HeldLine.stiffness refused friction on a profile ("no exact stiffness of its
seabed friction with two coefficients or on a seabed profile"), then on a grid.
"""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.system.held_line import HeldLine

from test_system_clamped import COMMS, body_differences
from test_system_friction import (assert_same_pose, frictional, friction_states, pose,
                                  solved as solved_at)
from test_system_profile import TOLERANCE as PROFILE_TOLERANCE, on_a_profile

pytestmark = pytest.mark.solver

ANCHOR, FAIRLEAD = np.array([-32.5, 56.292, -30.0]), np.array([-2.5, 4.33, -5.0])
# the row the chain's grounded part spans, m along +x (about x = -30.3 to -25.8 after
# the move); rows 40 m apart at the closest: the secant turns over 4 m about each
ROW = -28.0
# the lines' tolerance: their walks take no Newton steps (the profile's lagged push), and
# the settled re-solves do not need a tighter one
TOLERANCE = {"al_rtol": 1e-8, "al_ctol": 1e-8, "al_stability": 0}
STEP = 1e-5
# the grid's twist, 1/m: 0.08 m at 20 m from the anchor in x and in y
TWIST = 2e-4


def on_the_profile(system, row):
    """``system``'s environment with its seabed the profile along +x from the origin,
    level at -30.2 m to ``row`` (m) and falling 1.2 m over the next 40 m."""
    rows = ((-100.0, -30.2), (row, -30.2), (row + 40.0, -31.4), (200.0, -31.4))
    return dataclasses.replace(system.environment, seabed=None, seabed_profile=rows,
                               seabed_direction=0.0, seabed_origin=(0.0, 0.0))


def settled_forces(line, ends):
    """The line's end forces (6,) re-solved at ``ends`` and settled (Newton's steps to
    its stationary point)."""
    assert line.solve(*ends)
    line.settle()
    assert line.settled
    return line.end_forces().ravel()


def settled_differences(line, ends, step):
    """(6, 6) central differences of the settled end forces in the six end coordinates."""
    columns = []
    for j in range(6):
        move = np.zeros(6)
        move[j] = step
        plus = settled_forces(line, (ends[0] + move[:3], ends[1] + move[3:]))
        minus = settled_forces(line, (ends[0] - move[:3], ends[1] - move[3:]))
        columns.append((plus - minus) / (2 * step))
    settled_forces(line, ends)
    return np.array(columns).T


def on_the_grid(system, row):
    """``system``'s environment with its seabed on_the_profile's plus
    TWIST (x - x_a) (y - y_a), x_a, y_a the anchor's, as a grid of x at the profile's
    rows and y from -100 to 200 m every 100 m."""
    xs = np.array([-100.0, row, row + 40.0, 200.0])
    heights = (-30.2, -30.2, -31.4, -31.4)
    rows = tuple((x, y, z + TWIST * (x - ANCHOR[0]) * (y - ANCHOR[1]))
                 for x, z in zip(xs, heights) for y in (-100.0, 0.0, 100.0, 200.0))
    return dataclasses.replace(system.environment, seabed=None, seabed_profile=rows,
                               seabed_origin=(0.0, 0.0))


SEABEDS = {"profile": on_the_profile, "grid": on_the_grid}
_LINES = {}


def line_stiffness(comm, seabed="profile"):
    """(K, its settled central differences, (sticking, grounded) element-node counts,
    the grounded element nodes where the secant turns (Dg != 0; on the grid those
    where it turns across too, Dg_xy != 0), the relative move of the end forces by
    settling the lagged solve) of the deck's second chain on the ``seabed`` (SEABEDS),
    laid between its anchor and the fairlead and the fairlead then moved 4 m along x;
    kept."""
    if (comm, seabed) not in _LINES:
        system = frictional(0.5)
        line = HeldLine.of_system_line(system.lines[1], ANCHOR, FAIRLEAD, COMMS[comm],
                                       SEABEDS[seabed](system, ROW), TOLERANCE)
        try:
            assert line.solve(ANCHOR, FAIRLEAD)
            moved = (ANCHOR, FAIRLEAD + np.array([4.0, 0.0, 0.0]))
            assert line.solve(*moved)
            lagged = line.end_forces().ravel()
            term = line.friction[0]
            grounded = term.reaction > 0
            nodes = term.positions                  # the line's frame, as its seabed
            rate = line.scene.seabed.plan_slopes(nodes[..., 0].ravel(),
                                                 nodes[..., 1].ravel())[2]
            turning = grounded.ravel() & (np.abs(rate[:, 0, 1] if seabed == "grid"
                                                 else rate).sum(axis=-1).sum(axis=-1) > 0)
            counts = [line.mesh.global_sum(float(np.sum(c)))
                      for c in (term.stick & grounded, grounded, turning)]
            K = line.stiffness()
            settle = np.abs(line.end_forces().ravel() - lagged).max() / np.abs(lagged).max()
            _LINES[comm, seabed] = (K, settled_differences(line, moved, STEP), counts[:2],
                            counts[2], settle)
        finally:
            line.destroy()
    return _LINES[comm, seabed]


@pytest.mark.parametrize("seabed", list(SEABEDS))
@pytest.mark.parametrize("comm", list(COMMS))
def test_a_frictional_line_on_a_profile_has_the_exact_stiffness(comm, seabed):
    """(a) and (c): on the grid the secant turns across (Dg's off-diagonal,
    FrictionTerm._shape_rates) at 10 or more grounded nodes."""
    K, numeric, (stick, total), turning, settle = line_stiffness(comm, seabed)
    assert 5 <= stick <= total - 5                  # part sticks, part slides
    assert turning >= (4 if seabed == "profile" else 10)   # the secant's turn in the block
    # settling moves the lagged solve's forces by its tolerance only: the Newton steps'
    # stationary point is the lagged iteration's fixed point
    assert settle < 1e-6
    scale = np.abs(K).max()
    assert np.abs(K - K.T).max() > 1e-4 * scale     # the limit follows the contact
    error = np.abs(K - numeric).max() / scale
    print(f"{seabed}: {stick:g} of {total:g} grounded nodes stick, {turning:g} in the "
          f"secant's turn; settling moved the forces {settle:.3g}; K against differences "
          f"{error:.3g} of {scale:.6g}")
    assert error < 2e-7


@pytest.mark.parametrize("seabed", list(SEABEDS))
def test_one_rank_and_all_give_the_line_the_same_stiffness(seabed):
    alone, spread = (line_stiffness(comm, seabed)[0] for comm in COMMS)
    difference = np.abs(spread - alone).max() / np.abs(alone).max()
    print(f"K on one rank and on all differ by {difference:.3g} of the largest entry")
    assert difference < 1e-8



def on_a_frictional_profile():
    """tests/solver/test_system_profile.py's system (the body on its three chains, the
    chain to the anchor at x = 65 m grounded across the row at x = 55 m) with the
    seabed's friction."""
    system = on_a_profile()
    environment = dataclasses.replace(system.environment, seabed_friction=0.5)
    return dataclasses.replace(system, environment=environment)


def solved(comm):
    """The body on its chains on the frictional profile, solved on ``comm`` (the lines
    at the profile's tolerance)."""
    return solved_at(on_a_frictional_profile(), comm, tolerance=PROFILE_TOLERANCE)


# the body's equilibrium on one rank (the one-rank spread's, or solved for the test)
_ALONE = {}


@pytest.fixture(scope="module", params=list(COMMS))
def spread(request):
    solver, result = solved(COMMS[request.param])
    if request.param == "one rank":
        _ALONE["alone"] = result
    yield solver, result
    solver.destroy()


def test_a_body_on_frictional_lines_on_a_profile(spread):
    """Converged; the chain across the row partly slides; the 6 x 6 against central
    differences of the lines re-solved (and settled) at moved and turned poses."""
    solver, result = spread
    states = friction_states(solver)
    print(f"states {states}, pose {pose(result)}")
    stick, grounded = states[0]
    assert 0 < stick < grounded
    K = solver.body_stiffness("Body1").matrix
    scale = np.abs(K).max()
    error = np.abs(K - body_differences(solver, settle=True)).max() / scale
    print(f"K against differences {error:.3g} of {scale:.6g}")
    assert error < 1e-7


def test_one_rank_and_all_give_the_body_on_a_profile_the_same_pose(spread):
    if "alone" not in _ALONE:
        solver, _ALONE["alone"] = solved(PETSc.COMM_SELF)
        solver.destroy()
    print(f"pose {pose(_ALONE['alone'])}")
    assert_same_pose(spread[1], _ALONE["alone"])
