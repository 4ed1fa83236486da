"""frames.roll_between, the twist between neighbouring frames that problem.relax_twist
spreads (docs/method.md §7, "The twist of round sections")."""

import numpy as np

from petsc_rod.frames import roll_between, rotation_about
from petsc_rod.problem.state import rolled
from petsc_rod.scenes.scene import REFERENCE_FRAME


def twisted_arc(curvature, twist, S):
    """Frames (len(S), 3, 3), rows d1, d2, d3, of an arc of a circle of ``curvature``
    1/m in the x-z plane whose sections roll about the tangent at ``twist`` rad/m: the
    reference frame turned about e_y by curvature S, then rolled by twist S."""
    turned = np.stack([REFERENCE_FRAME @ rotation_about([0.0, 1.0, 0.0], -curvature * s).T
                       for s in S])
    d1, d2 = rolled(turned[:, 0], turned[:, 1], twist * S[:, None])
    return np.stack([d1, d2, turned[:, 2]], axis=1)


def test_on_a_straight_rod_it_is_the_roll_exactly():
    rng = np.random.default_rng(3)
    S = np.linspace(0.0, 1.0, 41)
    roll = np.cumsum(rng.uniform(-3.0, 3.0, S.size))
    frames = twisted_arc(0.0, 0.0, S)
    d1, d2 = rolled(frames[:, 0], frames[:, 1], roll[:, None])
    frames = np.stack([d1, d2, frames[:, 2]], axis=1)
    # the tangent is d3 = e_x: the increments are the rolls' differences, wrapped
    expected = np.angle(np.exp(1j * np.diff(roll)))
    assert np.abs(roll_between(frames[:-1], frames[1:]) - expected).max() < 1e-12


def test_on_a_bent_rod_it_is_the_roll_of_the_sections():
    """A planar arc (curvature 2 1/m) whose untwisted frames are turned about e_y, its
    sections rolled by phi(S) = 5 S^2 + sin 3S: the increments are phi's differences
    (the twist u3 = phi' integrated), whatever the bend between the nodes."""
    S = np.linspace(0.0, 1.0, 21)
    phi = 5.0 * S**2 + np.sin(3.0 * S)
    frames = twisted_arc(2.0, 0.0, S)
    d1, d2 = rolled(frames[:, 0], frames[:, 1], phi[:, None])
    frames = np.stack([d1, d2, frames[:, 2]], axis=1)
    assert np.abs(roll_between(frames[:-1], frames[1:]) - np.diff(phi)).max() < 1e-12
    # and the twisted arc of the helper: u3 dS
    twisted = twisted_arc(2.0, 5.0, S)
    assert np.abs(roll_between(twisted[:-1], twisted[1:]) - 5.0 * np.diff(S)).max() < 1e-12
