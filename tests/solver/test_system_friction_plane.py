"""A system's lines with Coulomb friction on a sloping plane (system/held_line.py,
"Friction": the plane's friction block (n, 3, 3), its vertical part g.f and the limit
mu R following x as well as z, written into the held line's response), serially and on
all ranks, on tests/data/moordyn/small_free_body.dat (a free buoyant body on three 70 m
chains) read by the API, friction mu = 0.5:

(a) a frictional chain on a plane rising 4 degrees along +x (the chain's heading 60
    degrees off it: the start's three position data all matter), its grounded nodes
    partly sticking, partly sliding: its end stiffness against central differences of
    re-solves, the same on one rank and on all; the deck's 70 m chain (its grounded
    part on the first rank of two) and an 80 m one (its grounded part on both);
(b) the body on its three chains, the anchors 0.2 m above a plane rising 3 degrees
    toward 45 degrees, under a side load: converged, every chain sticks and slides, the
    body's 6 x 6 against central differences of the lines re-solved at moved and turned
    poses, the same pose on one rank and on all;
(c) a clamped frictional chain on the plane: its 12 x 12 end stiffness against central
    differences of re-solves.
"""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.frames import rotations
from petsc_rod.system.held_line import HeldLine

from test_held_line import differences
from test_held_line_rotations import differences as rotation_differences
from test_system_clamped import COMMS
from test_system_friction import (TIGHT, assert_body_stiffness_is_the_derivative,
                                  assert_same_pose, frictional, friction_states, pose,
                                  solved)
from test_system_friction_clamped import TOP, frame_along

pytestmark = pytest.mark.solver

ANCHOR, FAIRLEAD = np.array([-32.5, 56.292, -30.0]), np.array([-2.5, 4.33, -5.0])
# the chain's length, m (1 m elements): the deck's, and one whose grounded part crosses
# the middle (the boundary of two ranks' nodes)
CASES = {"the deck's chain": 70.0, "a longer chain": 80.0}


def on_the_plane(system, slope, direction, origin):
    """``system``'s environment with its seabed the plane through ``origin`` (x, y) at
    the seabed's height, rising ``slope`` degrees toward ``direction`` degrees."""
    return dataclasses.replace(system.environment, seabed_slope=slope,
                               seabed_direction=direction, seabed_origin=origin)


_LINES = {}


def line_stiffness(case, comm):
    """(K, its central differences (1e-5 m), (sticking, grounded) element-node counts,
    the grounded element nodes on each rank) of the deck's second chain (its length
    CASES[case]) on a plane rising 4 degrees along +x through its anchor (0.2 m below
    it), laid between its anchor and the fairlead and the fairlead then moved 4 m along
    x; kept."""
    key = (case, comm)
    if key not in _LINES:
        system = frictional(0.5)
        environment = on_the_plane(system, 4.0, 0.0, tuple(ANCHOR[:2]))
        chain = system.lines[1]
        kind = chain.line.sections[0][0]
        chain = dataclasses.replace(chain, line=dataclasses.replace(
            chain.line, sections=[(kind, CASES[case], int(CASES[case]))]))
        line = HeldLine.of_system_line(chain, ANCHOR, FAIRLEAD, COMMS[comm], environment,
                                       {**TIGHT, "al_stability": 0})
        try:
            assert line.solve(ANCHOR, FAIRLEAD)
            moved = (ANCHOR, FAIRLEAD + np.array([4.0, 0.0, 0.0]))
            assert line.solve(*moved)
            term = line.friction[0]
            grounded = term.reaction > 0
            counts = (line.mesh.global_sum(float(np.sum(term.stick & grounded))),
                      line.mesh.global_sum(float(np.sum(grounded))))
            ranks = line.comm.tompi4py().allgather(int(np.sum(grounded)))
            K = line.stiffness()
            _LINES[key] = (K, differences(line, moved, 1e-5), counts, ranks)
        finally:
            line.destroy()
    return _LINES[key]


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("case", list(CASES))
def test_a_frictional_line_on_a_plane_has_the_exact_stiffness(case, comm):
    K, numeric, (stick, total), ranks = line_stiffness(case, comm)
    assert 5 <= stick <= total - 5                  # part sticks, part slides
    scale = np.abs(K).max()
    # the limit mu R follows the contact: K is not symmetric
    assert np.abs(K - K.T).max() > 1e-4 * scale
    # the plane moves the start's horizontal force with its height and back
    assert np.abs(K[:2, 2]).max() > 1e-3 * scale and np.abs(K[2, :2]).max() > 1e-3 * scale
    error = np.abs(K - numeric).max() / scale
    print(f"{stick:g} of {total:g} grounded nodes stick (per rank {ranks}); K against "
          f"differences {error:.3g} of {scale:.6g}")
    assert error < 8e-7


@pytest.mark.parametrize("case", list(CASES))
def test_one_rank_and_all_give_the_line_the_same_stiffness(case):
    """On two ranks the deck's chain's grounded nodes are all on the first, the longer
    chain's on both."""
    alone, spread = (line_stiffness(case, comm)[0] for comm in COMMS)
    ranks = line_stiffness(case, "all ranks")[3]
    if case == "a longer chain" and len(ranks) == 2:
        assert min(ranks) > 0
    difference = np.abs(spread - alone).max() / np.abs(alone).max()
    print(f"grounded nodes per rank {ranks}; K on one rank and on all differ by "
          f"{difference:.3g} of the largest entry")
    assert difference < 1e-8


def on_a_plane(mu=0.5):
    """frictional(``mu``) on the plane through (0, 0, -30.2) rising 3 degrees toward 45
    degrees, each anchor 0.2 m above it."""
    system = frictional(mu)
    environment = on_the_plane(system, 3.0, 45.0, (0.0, 0.0))
    rise = np.tan(np.radians(3.0)) * np.array([np.cos(np.radians(45.0)),
                                               np.sin(np.radians(45.0))])
    points = tuple(dataclasses.replace(p, position=(p.position[0], p.position[1],
                                                    -30.0 + rise @ p.position[:2]))
                   if p.kind == "fixed" else p for p in system.points)
    return dataclasses.replace(system, environment=environment, points=points)


# the body's equilibrium on one rank (the one-rank spread's, or solved for the test)
_ALONE = {}


@pytest.fixture(scope="module", params=list(COMMS))
def spread(request):
    solver, result = solved(on_a_plane(), COMMS[request.param])
    if request.param == "one rank":
        _ALONE["alone"] = result
    yield solver, result
    solver.destroy()


def test_a_body_on_frictional_lines_on_a_plane(spread):
    """Converged; every chain's grounded nodes partly stick, partly slide; the 6 x 6
    against central differences of the lines re-solved at moved and turned poses."""
    solver, result = spread
    assert result.residual <= 1e-12
    states = friction_states(solver)
    print(f"states {states}")
    assert all(0 < stick < grounded for stick, grounded in states)
    assert_body_stiffness_is_the_derivative(solver)


def test_one_rank_and_all_give_the_body_the_same_pose(spread):
    if "alone" not in _ALONE:
        solver, _ALONE["alone"] = solved(on_a_plane(), PETSc.COMM_SELF)
        solver.destroy()
    print(f"pose {pose(_ALONE['alone'])}")
    assert_same_pose(spread[1], _ALONE["alone"])


def test_a_clamped_frictional_line_on_a_plane_has_the_exact_end_stiffness():
    """The deck's chain clamped at its fairlead (its frame along the laid chain's top,
    then turned 0.1 rad), on the plane rising 4 degrees along +x, laid and its fairlead
    moved 4 m along x: the 12 x 12 against central differences of re-solves (before,
    refused: "pin the line's ends")."""
    system = frictional(0.5)
    chain = system.lines[1]
    chain = dataclasses.replace(chain, end=dataclasses.replace(chain.end, kind="clamp"))
    laid = (None, frame_along(TOP))
    turned = [None, laid[1] @ rotations(np.array([0.0, 0.0, 0.1])).T]
    line = HeldLine.of_system_line(chain, ANCHOR, FAIRLEAD, PETSc.COMM_SELF,
                                   on_the_plane(system, 4.0, 0.0, tuple(ANCHOR[:2])),
                                   {**TIGHT, "al_stability": 0}, frames=laid)
    try:
        assert line.solve(ANCHOR, FAIRLEAD, *laid)
        moved = (ANCHOR, FAIRLEAD + np.array([4.0, 0.0, 0.0]))
        assert line.solve(*moved, *turned)
        term = line.friction[0]
        grounded = term.reaction > 0
        stick = float(np.sum(term.stick & grounded))
        assert 5 <= stick <= np.sum(grounded) - 5
        K = line.end_stiffness()
        scale = np.abs(K).max()
        assert np.abs(K[:, 9:]).max() > 1e-3 * scale        # the clamp's rotations
        error = np.abs(K - rotation_differences(line, turned, 3e-5, moved)).max() / scale
        print(f"{stick:g} of {np.sum(grounded):g} grounded nodes stick; the 12 x 12 "
              f"against differences {error:.3g} of {scale:.6g}")
        assert error < 1e-6
    finally:
        line.destroy()


@pytest.mark.parametrize("slope", [0.0, 4.0])
def test_a_walk_that_fails_keeps_the_friction_of_the_last_equilibrium(slope):
    """A walk that fails restores the line's state and its friction's record (the
    springs, the force the end forces read): its end forces are the last equilibrium's,
    on a flat seabed to round-off and on the plane to the solve's tolerance (there the
    restored state's seabed force is its own, Seabed.force, where the equilibrium's was
    the reaction its last vertical solve carried: SeabedTerm.contact_solved), on all
    ranks. The friction of the failed walk left in the record moved them by about
    1e-2."""
    system = frictional(0.5)
    environment = (on_the_plane(system, slope, 0.0, tuple(ANCHOR[:2])) if slope
                   else system.environment)
    line = HeldLine.of_system_line(system.lines[1], ANCHOR, FAIRLEAD, PETSc.COMM_WORLD,
                                   environment, {**TIGHT, "al_stability": 0})
    moved = FAIRLEAD + np.array([4.0, 0.0, 0.0])
    try:
        assert line.solve(ANCHOR, FAIRLEAD) and line.solve(ANCHOR, moved)
        before = line.end_forces()
        # a budget no walk of 4 m can keep to (the controller reads it every step)
        line.solver.settings.max_it = 2
        assert not line.solve(ANCHOR, moved + np.array([4.0, 2.0, 0.0]))
        assert line.end_forces() == pytest.approx(before, rel=1e-9 if slope else 1e-12)
        line.solver.settings.max_it = 2000
        assert line.solve(ANCHOR, moved)
        assert line.end_forces() == pytest.approx(before, rel=1e-9)
    finally:
        line.destroy()
