"""The linking number's formulas (analysis/link.py), numpy only: the end roll, where the
link is tracked, the quarter-turn class test, and Fuller's writhe against the Gauss
double integral on a curve given in closed form."""

import numpy as np
import pytest

from petsc_rod.analysis.link import LINK_TOLERANCE, changed_class, link_integrands
from petsc_rod.frames import rotation_about
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene
from petsc_rod.validation.writhe import gauss_writhe


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
