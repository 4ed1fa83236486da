"""Scene.axially_symmetric: the scenes whose equilibria come in families turned about the
x axis (docs/method.md §10), and those one change takes out of it."""

import numpy as np
import pytest

from petsc_rod.frames import rotation_about
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene

PINNED = dict(length=1.0, stiffness=(1.0, 1.0, 0.7), start="pin", end="pin",
              end_position=(0.5, 0.0, 0.0), end_force=(-1.0, 0.0, 0.0),
              load_values=[(2.0, 0.0, 0.0)])


@pytest.mark.parametrize("changes", [
    {}, dict(end="free"), dict(start="clamp", end="clamp", end_twist=3.0),
    dict(start="clamp", end="clamp", end_frame=REFERENCE_FRAME @ rotation_about((1, 0, 0), 0.4).T)])
def test_symmetric(changes):
    assert Scene(**dict(PINNED, **changes)).axially_symmetric


@pytest.mark.parametrize("changes", [
    dict(stiffness=(1.0, 1.0 + 1e-12, 0.7)),            # K1 != K2: the roll costs energy
    dict(end_position=(0.5, 1e-9, 0.0)),                # the held end off the axis
    dict(end_force=(-1.0, 0.0, 1e-9)),
    dict(start_force=(0.0, 0.1, 0.0)),
    dict(load_values=[(2.0, 0.0, -9.81)]),
    dict(start="clamp", end="clamp",                    # the end tangent tilted
         end_frame=REFERENCE_FRAME @ rotation_about((0, 0, 1), 0.1).T)])
def test_not_symmetric(changes):
    assert not Scene(**dict(PINNED, **changes)).axially_symmetric


def test_a_free_end_off_the_axis_does_not_matter():
    scene = Scene(**dict(PINNED, end="free", end_position=np.array([0.5, 0.3, 0.0])))
    assert scene.axially_symmetric
