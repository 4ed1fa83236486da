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

Before, HeldLine.stiffness refused friction on a profile ("no exact stiffness of its
seabed friction with two coefficients or on a seabed profile").
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


_LINES = {}


def line_stiffness(comm):
    """(K, its settled central differences, (sticking, grounded) element-node counts,
    the grounded element nodes where the secant turns, the relative move of the end
    forces by settling the lagged solve) of the deck's second chain on the profile,
    laid between its anchor and the fairlead and the fairlead then moved 4 m along x;
    kept."""
    if comm not in _LINES:
        system = frictional(0.5)
        line = HeldLine.of_system_line(system.lines[1], ANCHOR, FAIRLEAD, COMMS[comm],
                                       on_the_profile(system, ROW), TOLERANCE)
        try:
            assert line.solve(ANCHOR, FAIRLEAD)
            moved = (ANCHOR, FAIRLEAD + np.array([4.0, 0.0, 0.0]))
            assert line.solve(*moved)
            lagged = line.end_forces().ravel()
            term = line.friction[0]
            grounded = term.reaction > 0
            nodes = term.positions                  # the line's frame, as its seabed
            turning = grounded & (line.scene.seabed.shape.slopes(
                nodes[..., 0], nodes[..., 1])[2] != 0)
            counts = [line.mesh.global_sum(float(np.sum(c)))
                      for c in (term.stick & grounded, grounded, turning)]
            K = line.stiffness()
            settle = np.abs(line.end_forces().ravel() - lagged).max() / np.abs(lagged).max()
            _LINES[comm] = (K, settled_differences(line, moved, STEP), counts[:2],
                            counts[2], settle)
        finally:
            line.destroy()
    return _LINES[comm]


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_frictional_line_on_a_profile_has_the_exact_stiffness(comm):
    K, numeric, (stick, total), turning, settle = line_stiffness(comm)
    assert 5 <= stick <= total - 5                  # part sticks, part slides
    assert turning >= 4                             # the secant's turn in the block
    # settling moves the lagged solve's forces by its tolerance only: the Newton steps'
    # stationary point is the lagged iteration's fixed point
    assert settle < 1e-6
    scale = np.abs(K).max()
    assert np.abs(K - K.T).max() > 1e-4 * scale     # the limit follows the contact
    error = np.abs(K - numeric).max() / scale
    print(f"{stick:g} of {total:g} grounded nodes stick, {turning:g} in the secant's "
          f"turn; settling moved the forces {settle:.3g}; K against differences "
          f"{error:.3g} of {scale:.6g}")
    assert error < 2e-7


def test_one_rank_and_all_give_the_line_on_a_profile_the_same_stiffness():
    alone, spread = (line_stiffness(comm)[0] for comm in COMMS)
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
