"""The linking number Lk = Tw + Wr of rods clamped at both ends
(petsc_rod/analysis/link.py) and the continuation's check that a step keeps it
(docs/stability.md, "Twist and Greenhill").

- Fuller's writhe against the Gauss double integral, on a curve given in closed form
  and on a converged writhed rod;
- Calugareanu-White on the solver's states: Tw + Wr is the end roll over 2 pi;
- a step that rolls the end by a whole turn (the clamps see no roll at all) is refused
  instead of returning the untwisted rod.
"""

import re

import numpy as np
import pytest

from helpers import continuation as reach_load, gather
from petsc_rod.iteration.continuation import continuation
from petsc_rod.errors import RodNotConvergedError
from petsc_rod.frames import rotation_about
from petsc_rod.analysis.link import LINK_TOLERANCE, changed_class, link_integrands
from petsc_rod.validation.writhe import gauss_writhe
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene

AXIS = np.array([1.0, 0.0, 0.0])


def test_end_roll_is_the_roll_of_the_end_frame():
    alpha, twist = 2.5, 7.0
    end_frame = REFERENCE_FRAME @ rotation_about(AXIS, alpha).T
    scene = Scene(length=1.0, stiffness=(1, 1, 1), start="clamp", end="clamp",
                  end_frame=end_frame, end_twist=twist)
    assert np.array_equal(scene.link_axis, AXIS)
    for t in (0.1, 0.5, 1.0):
        roll = scene.end_roll(t)
        assert roll == pytest.approx(t * (alpha + twist), rel=1e-14)
        expected = REFERENCE_FRAME @ rotation_about(AXIS, roll).T
        assert np.abs(scene.end_state(t).frame - expected).max() < 1e-12


def test_the_link_is_tracked_only_on_a_common_end_axis():
    tilted = REFERENCE_FRAME @ rotation_about([0.0, 0.0, 1.0], 0.3).T
    assert Scene(length=1.0, stiffness=(1, 1, 1), start="clamp", end="clamp",
                 end_frame=tilted).link_axis is None
    assert Scene(length=1.0, stiffness=(1, 1, 1), start="clamp", end="pin").link_axis is None


def test_changed_class_needs_a_quarter_turn():
    assert not changed_class((1.4, 0.1 + 0.9 * LINK_TOLERANCE), 1.5)
    assert changed_class((0.4, 0.1), 1.5)
    assert not changed_class(None, 1.5) and not changed_class((0.4, 0.1), None)


def closed_form_curve(n):
    """A non-planar curve with tangent e_x at both ends, its derivative in closed form:
    t = (cos a, sin a cos b, sin a sin b), a = 1.2 sin^2(pi s), b = 5 s, s in [0, 1]."""
    s = np.linspace(0.0, 1.0, n)
    a, da = 1.2 * np.sin(np.pi * s) ** 2, 1.2 * np.pi * np.sin(2 * np.pi * s)
    b, db = 5.0 * s, 5.0
    tangent = np.stack([np.cos(a), np.sin(a) * np.cos(b), np.sin(a) * np.sin(b)], axis=1)
    bend = np.stack([-np.sin(a) * da, np.cos(a) * np.cos(b) * da - np.sin(a) * np.sin(b) * db,
                     np.cos(a) * np.sin(b) * da + np.sin(a) * np.cos(b) * db], axis=1)
    return s, tangent, bend


def test_fuller_writhe_is_the_gauss_integral():
    """Fuller's integrand (link_integrands) integrated on a fine grid against the Gauss
    double integral of the curve closed by rays (gauss_writhe), 1001 points on it."""
    s, tangent, bend = closed_form_curve(20001)
    frames = np.zeros(s.shape + (3, 3))
    frames[:, 2], derivatives = tangent, np.zeros(s.shape + (3, 3))
    derivatives[:, 2] = bend
    _, writhe, margin = link_integrands(frames, derivatives, AXIS)
    assert margin.min() > 1.3
    fuller = np.trapz(writhe, s)
    coarse = slice(None, None, 20)
    steps = np.diff(s[coarse])[:, None] * 0.5 * (tangent[coarse][1:] + tangent[coarse][:-1])
    points = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    gauss = gauss_writhe(points, AXIS)
    assert abs(fuller) > 0.05                       # a curve that does writhe
    assert gauss == pytest.approx(fuller, abs=2e-3)


SLACK = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="clamp",
             end_position=(0.9, 0.1, 0.0), end_twist=2 * np.pi)


def test_a_twisted_rod_with_slack_writhes_and_keeps_its_link(solver_factory, comm):
    """Clamped at both ends 0.9 L apart (0.1 L to the side), the end rolled by one turn in
    10 steps: Lk = Tw + Wr = 1 turn, part of it writhe; the solver's Fuller writhe and
    the Gauss integral of its centreline agree (same on 1 and 2 ranks)."""
    mesh, solver = solver_factory(comm, 64, SLACK, 100.0, 1e-6, 1e-5, 20000)
    report = reach_load(solver, steps=10, imperfection=0.01)
    assert report.converged
    twist, writhe = solver.link()
    assert twist + writhe == pytest.approx(1.0, abs=2e-3)
    assert 0.03 < writhe < 0.1
    points = gather(comm, solver.state.r.owned()[:, 0])
    assert gauss_writhe(points, AXIS) == pytest.approx(writhe, abs=2e-3)


PURE_TWIST = dict(length=1.0, stiffness=(1.0, 1.0, 0.5), start="clamp", end="clamp",
                  end_twist=2 * np.pi)


def test_a_whole_turn_in_one_step_is_refused(solver_factory, comm):
    """The end rolled by 2 pi in one step is the unrolled clamp: the iteration settles on
    the untwisted rod, which the link check refuses (exit 3); in 4 steps the rod keeps
    its turn, all of it twist (u3 = 2 pi / L)."""
    mesh, solver = solver_factory(comm, 32, PURE_TWIST, 100.0, 1e-8, 1e-5, 5000)
    solver.state.set_straight()
    lines = []
    code = continuation(solver, 1, say=lines.append, max_halvings=0).code
    assert code == RodNotConvergedError.exit_code, "\n".join(lines)
    found = re.search(r"linking number is (-?[0-9.]+) turns .* not the 1.000 turns", lines[-1])
    assert found and abs(float(found.group(1))) < 1e-3, lines[-1]
    solver.state.set_straight()                           # -rod_track_link 0: accepted
    lines = []
    assert continuation(solver, 1, say=lines.append, max_halvings=0, track_link=False).code == 0
    assert abs(sum(solver.link())) < 1e-3
    solver.state.set_straight()
    lines = []
    assert continuation(solver, 4, say=lines.append, max_halvings=0).code == 0, "\n".join(lines)
    twist, writhe = solver.link()
    # the twist integral of the P2 frames, O(h^4) from its limit: 3.1e-6 on 32 elements
    assert twist == pytest.approx(1.0, abs=1e-5) and abs(writhe) < 1e-9
    assert "link 1.0000 turns = twist 1.0000 + writhe" in [
        line for line in lines if line.startswith("step 4/4")][0]
