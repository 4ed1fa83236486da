"""A system's line with Coulomb friction and a clamped or flex-jointed end
(system/held_line.py, "Friction": the friction's block in the rotations' response, its
transpose read by the seabed's reaction on the start, and J's columns at a clamp's held
rotation and stretch beyond H's), serially and on all ranks:

(a) the deck's 70 m chain (tests/data/moordyn/small_free_body.dat, friction mu = 0.5)
    laid between its anchor and the body's fairlead, then the fairlead moved 4 m along x
    so that part of its grounded length sticks and part slides: clamped at the fairlead
    (its frame along the laid chain's top, then turned 0.1 rad), on a flex joint there (its support turned 0.1 rad),
    or clamped at its anchor 3 cm above the seabed pointing 0.1 down (its first
    elements grounded): the 12 x 12 end stiffness against central differences of
    re-solves with the anchors held, the same on one rank and on all;
(b) an extensible line clamped at its anchor pointing 0.3 down, 5 cm above a frictional
    seabed, its clamp turned so that the grounded nodes beside it slide: the friction's
    entries of J at the clamp's rotation and stretch matter (without them the error is
    of the order of K), the 12 x 12 against differences;
(c) the small body on its three frictional chains, one clamped at the body: converged,
    every chain partly sliding, its 6 x 6 against central differences of the lines
    re-solved at moved and turned poses, the same pose on one rank and on all.
"""

import dataclasses

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import End, Environment, Model, UniformLine
from petsc_rod.frames import REFERENCE_FRAME, rotations
from petsc_rod.model.system import Connection
from petsc_rod.system.held_line import HeldLine

from test_held_line_rotations import differences, dipping_frame
from test_system_clamped import COMMS, body_differences
from test_system_friction import (TIGHT, assert_same_pose, frictional, friction_states, pose,
                                  solved)

pytestmark = pytest.mark.solver

ANCHOR, FAIRLEAD = np.array([-32.5, 56.292, -30.0]), np.array([-2.5, 4.33, -5.0])
MOVE = np.array([4.0, 0.0, 0.0])
# the laid chain's tangent at the fairlead (pointing up, out of the line)
TOP = np.array([0.2645, -0.4581, 0.8486])


def frame_along(d3):
    """A frame (rows d1, d2, d3) whose d3 is along ``d3``, d1 horizontal."""
    d3 = np.asarray(d3, dtype=float) / np.linalg.norm(d3)
    d1 = np.cross([0.0, 0.0, 1.0], d3)
    d1 /= np.linalg.norm(d1)
    return np.array([d1, np.cross(d3, d1), d3])


def heading_frame(dip):
    """The chain's horizontal heading from its anchor, pointing ``dip`` down."""
    heading = (FAIRLEAD - ANCHOR)[:2] / np.linalg.norm((FAIRLEAD - ANCHOR)[:2])
    return frame_along((heading[0], heading[1], -dip))


TURN = rotations(np.array([0.0, 0.0, 0.1])).T
# (the connection's kind at the start and at the end, the frames laid, the frames moved,
# the seabed's height, m)
CASES = {"clamped fairlead": ("pin", "clamp", (None, frame_along(TOP)),
                              (None, frame_along(TOP) @ TURN), -30.2),
         "flex joint at the fairlead": ("pin", "flex", (None, REFERENCE_FRAME),
                                        (None, REFERENCE_FRAME @ TURN), -30.2),
         "clamped grounded anchor": ("clamp", "pin", (heading_frame(0.1), None),
                                     (heading_frame(0.1), None), -30.03)}
# the central differences' step, m and rad: their error falls as the step grows to
# 3e-5 (the re-solves' remaining error over the step), then rises (the slides'
# curvature)
STEP = 3e-5

_LINES = {}


def line_stiffness(case, comm):
    """(K, its central differences, (sticking, grounded) element-node counts) of the
    deck's second chain with CASES[case]'s ends, laid between its anchor and the
    fairlead, then the fairlead moved by MOVE and the frames turned; kept."""
    key = (case, comm)
    if key not in _LINES:
        start, end, laid, turned, seabed = CASES[case]
        system = frictional(0.5)
        environment = dataclasses.replace(system.environment, seabed=seabed)
        chain = system.lines[1]
        chain = dataclasses.replace(
            chain, start=dataclasses.replace(chain.start, kind=start),
            end=dataclasses.replace(chain.end, kind=end,
                                    stiffness=2e4 if end == "flex" else None))
        line = HeldLine.of_system_line(chain, ANCHOR, FAIRLEAD, COMMS[comm], environment,
                                       {**TIGHT, "al_stability": 0},
                                       frames=tuple(f if k == "clamp" else None for f, k
                                                    in zip(laid, (start, end))))
        try:
            assert line.solve(ANCHOR, FAIRLEAD, *laid)
            moved = (ANCHOR, FAIRLEAD + MOVE)
            assert line.solve(*moved, *turned)
            term = line.friction[0]
            grounded = term.reaction > 0
            counts = (line.mesh.global_sum(float(np.sum(term.stick & grounded))),
                      line.mesh.global_sum(float(np.sum(grounded))))
            moments = line.end_moments()
            K = line.end_stiffness()
            _LINES[key] = (K, differences(line, list(turned), STEP, moved), counts, moments)
        finally:
            line.destroy()
    return _LINES[key]


@pytest.mark.parametrize("comm", list(COMMS))
@pytest.mark.parametrize("case", list(CASES))
def test_a_clamped_frictional_line_has_the_exact_end_stiffness(case, comm):
    K, numeric, (stick, total), moments = line_stiffness(case, comm)
    assert 5 <= stick <= total - 5                  # part sticks, part slides
    e = 0 if CASES[case][0] == "clamp" else 1
    assert np.abs(moments[e]).max() > 10.0          # the clamp's or the joint's moment
    scale = np.abs(K).max()
    # the held end's rotations matter
    assert np.abs(K[:, 6 + 3 * e:9 + 3 * e]).max() > 1e-3 * scale
    error = np.abs(K - numeric).max() / scale
    print(f"{stick:g} of {total:g} grounded nodes stick; the 12 x 12 against "
          f"differences {error:.3g} of {scale:.6g}")
    assert error < 1e-6


@pytest.mark.parametrize("case", list(CASES))
def test_one_rank_and_all_give_the_same_end_stiffness(case):
    alone, spread = (line_stiffness(case, comm)[0] for comm in COMMS)
    difference = np.abs(spread - alone).max() / np.abs(alone).max()
    print(f"the 12 x 12 on one rank and on all differ by {difference:.3g} of the "
          "largest entry")
    assert difference < 1e-8


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_clamp_whose_grounded_neighbours_slide(comm):
    """The clamp's rotation and stretch move the first element's midpoint, which slides
    on the seabed: J's columns there carry the friction's limit following the contact
    (its z column), which H's do not: without them the rotations' columns are off by
    1.2 of K's largest entry."""
    ends = (np.array([0.0, 0.0, -30.0]), np.array([85.0, 0.0, 0.0]))
    line = UniformLine(length=100.0, stiffness=(50.0, 50.0, 50.0), load=(0, 0, -10.0),
                       elements=20, axial_stiffness=1e5)
    model = Model(line=line, start=End(kind="clamp", position=tuple(ends[0])),
                  end=End.anchor(tuple(ends[1])),
                  environment=Environment(seabed=-30.05, seabed_friction=0.5))
    held = HeldLine(model, COMMS[comm], options=TIGHT)
    try:
        assert held.solve(*ends, dipping_frame(0.3), None)
        moved = (ends[0], ends[1] + np.array([-3.0, 1.0, 0.0]))
        frames = [dipping_frame(0.3) @ rotations(np.array([0.0, 0.0, 0.2])).T, None]
        assert held.solve(*moved, *frames)
        term = held.friction[0]
        grounded = term.reaction > 0
        stick = held.mesh.global_sum(float(np.sum(term.stick & grounded)))
        total = held.mesh.global_sum(float(np.sum(grounded)))
        assert 5 <= stick <= total - 5
        K = held.end_stiffness()
        scale = np.abs(K).max()
        error = np.abs(K - differences(held, frames, 1e-4, moved)).max() / scale
        print(f"{stick:g} of {total:g} grounded nodes stick; the 12 x 12 against "
              f"differences {error:.3g} of {scale:.6g}")
        assert error < 1e-6
    finally:
        held.destroy()


def clamped_at_the_body():
    """frictional(0.5) with its second chain clamped at the body, along the laid
    chain's top (the direction into the line from the body, body axes), its d1
    horizontal: twisted by pi from the untwisted clamp, whose d2 at the line's end
    points down (Connection.line_frame), which the chain's laid frames would have to
    turn through (its first solve took 1620 iterations, a walk the iteration limit)."""
    system = frictional(0.5)
    lines = list(system.lines)
    lines[1] = dataclasses.replace(lines[1], end=Connection(
        lines[1].end.to, lines[1].end.local, "clamp", direction=tuple(-TOP), twist=np.pi))
    return dataclasses.replace(system, lines=tuple(lines))


@pytest.fixture(scope="module", params=list(COMMS))
def clamped_spread(request):
    solver, result = solved(clamped_at_the_body(), COMMS[request.param])
    yield solver, result
    solver.destroy()


def test_a_body_on_frictional_chains_one_clamped(clamped_spread):
    """Converged; every chain's grounded nodes partly stick, partly slide; the 6 x 6
    (the clamped chain's from its 12 x 12) against central differences of the lines
    re-solved at moved and turned poses, with steps of 3e-5 m and 3e-6 rad: at 1e-4 m a
    grounded node changes its state between the two re-solves of the x column (5.8e-6
    of the largest entry there)."""
    solver, result = clamped_spread
    assert result.residual <= 1e-12
    states = friction_states(solver)
    print(f"states {states}")
    assert all(0 < stick < grounded for stick, grounded in states)
    K = solver.body_stiffness("Body1").matrix
    scale = np.abs(K).max()
    error = np.abs(K - body_differences(solver, (3e-5,) * 3 + (3e-6,) * 3)).max() / scale
    print(f"K against differences {error:.3g} of {scale:.6g}")
    assert error < 1e-6


def test_one_rank_and_all_give_the_clamped_body_the_same_pose(clamped_spread):
    solver, alone = solved(clamped_at_the_body(), PETSc.COMM_SELF)
    solver.destroy()
    print(f"pose {pose(alone)}")
    assert_same_pose(clamped_spread[1], alone)
