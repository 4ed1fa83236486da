"""The blended load path of a restart from another scene (scenes/blend.py), numpy only:
its ends are the file's scene at t_f and the new scene at 1, it is linear in between,
and the end frame turns along the geodesic, or rolls whole turns for a rod tracked for
its link."""

import numpy as np
import pytest

from petsc_rod.frames import rotation_about
from petsc_rod.scenes.blend import BlendedPath, blended_frame, differences
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene, rolled_frame


def tilted(axis, angle):
    """The reference frame turned by ``angle`` about ``axis`` (rows d1, d2, d3)."""
    return REFERENCE_FRAME @ rotation_about(axis, angle).T


OLD = Scene(length=2.0, stiffness=(1, 1, 1), end="clamp", end_position=[1.5, 0.3, 0.2],
            end_frame=tilted([0, 0, 1], 0.4), load_values=[[0, 0, -1]])
NEW = Scene(length=2.0, stiffness=(1, 1, 1), end="clamp", end_position=[1.2, -0.4, 0.5],
            end_frame=tilted([1, 1, 0], 1.1), end_twist=0.5,
            load_values=[[0, 1, 0], [0, 0, -3]], load_breaks=[0.7])


def test_the_walk_starts_at_the_files_scene_and_ends_at_the_new_one():
    path = BlendedPath(OLD, 0.6, NEW)
    for s, (scene, t) in ((0.0, (OLD, 0.6)), (1.0, (NEW, 1.0))):
        got, want = path.end_state(s), scene.end_state(t)
        assert np.allclose(got.position, want.position, atol=1e-15)
        assert np.allclose(got.frame, want.frame, atol=1e-14)
        S = np.linspace(0, 2, 9)
        assert np.allclose(path.load_beyond(S, s), scene.load_beyond(S, t), atol=1e-15)
    assert list(path.load_piece_ends) == [0.0, 0.7, 2.0]
    assert path.length == NEW.length and path.link_axis is None
    assert differences(OLD, NEW) == ["load_values", "load_breaks", "end_position",
                                     "end_frame", "end_twist"]


def test_the_walk_is_linear_and_the_frame_turns_along_the_geodesic():
    path = BlendedPath(OLD, 0.6, NEW)
    a, b = OLD.end_state(0.6), NEW.end_state(1.0)
    mid = path.end_state(0.5)
    assert np.allclose(mid.position, (a.position + b.position) / 2, atol=1e-15)
    S = np.array([0.3, 1.0])
    assert np.allclose(path.load_beyond(S, 0.5),
                       (OLD.load_beyond(S, 0.6) + NEW.load_beyond(S, 1.0)) / 2, atol=1e-15)
    # the frame before the twist halfway along the geodesic (the same rotation takes a's
    # to it and it to b's), then rolled by the mean of the two twists about its d3
    (tilt_a, roll_a), (tilt_b, roll_b) = OLD.end_frame_parts(0.6), NEW.end_frame_parts(1.0)
    tilt = rolled_frame(mid.frame, -(roll_a + roll_b) / 2)
    assert np.allclose(tilt.T @ tilt_a, tilt_b.T @ tilt, atol=1e-13)
    assert np.allclose(mid.frame @ mid.frame.T, np.eye(3), atol=1e-14)


def test_a_twist_above_pi_is_walked_whole_at_a_tilted_end():
    """A clamped end off the axis (no link tracked) whose -rod_end_twist goes from 0 to
    5 rad: the frame turns continuously through the whole 5 rad of roll. The geodesic
    between the twisted frames walked it the short way round (1.28 rad the other way),
    to another equilibrium."""
    old = Scene(length=1.0, stiffness=(1, 1, 1), end="clamp", end_position=[0.8, 0.3, 0],
                end_frame=tilted([0, 0, 1], 0.3))
    new = Scene(length=1.0, stiffness=(1, 1, 1), end="clamp", end_position=[0.8, 0.3, 0],
                end_frame=tilted([0, 0, 1], 0.3), end_twist=5.0)
    path = BlendedPath(old, 1.0, new)
    assert path.link_axis is None
    frames = [path.end_state(s).frame for s in np.linspace(0.0, 1.0, 1001)]
    turns = [np.arccos(np.clip((np.trace(b.T @ a) - 1) / 2, -1.0, 1.0))
             for a, b in zip(frames, frames[1:])]
    assert max(turns) < 1e-2 and abs(sum(turns) - 5.0) < 1e-6


def test_a_rod_tracked_for_its_link_rolls_whole_turns_continuously():
    """Both ends clamped on e_x: the roll walks from 2 turns to 3 turns and a quarter, all
    of it (the geodesic would skip the whole turn)."""
    old = Scene(length=1.0, stiffness=(1, 1, 1), end="clamp", end_position=[0.9, 0, 0],
                end_twist=4 * np.pi)
    new = Scene(length=1.0, stiffness=(1, 1, 1), end="clamp", end_position=[0.9, 0, 0],
                end_twist=6.5 * np.pi)
    path = BlendedPath(old, 1.0, new)
    assert np.array_equal(path.link_axis, [1.0, 0.0, 0.0])
    assert path.end_roll(0.0) == pytest.approx(4 * np.pi)
    assert path.end_roll(1.0) == pytest.approx(6.5 * np.pi)
    for s in (0.0, 0.4, 1.0):
        roll = path.end_roll(s)
        assert np.allclose(path.end_state(s).frame, tilted([1, 0, 0], roll), atol=1e-12)


def test_the_drag_is_walked_in_by_weights():
    """f = (1 - s) t_f f_A + s f_B: the file's current (none here) and the new one."""
    current = object()
    new = Scene(length=1.0, stiffness=(1, 1, 1), current=current)
    path = BlendedPath(Scene(length=1.0, stiffness=(1, 1, 1)), 0.5, new)
    assert path.drag_loads(0.25) == [(0.25, current)]
    both = BlendedPath(new, 0.5, new)
    assert both.drag_loads(0.25) == [(0.75 * 0.5, current), (0.25, current)]


def test_blended_frame_of_a_frame_with_itself_is_that_frame():
    a = tilted([0.2, -1, 0.5], 2.0)
    assert np.allclose(blended_frame(a, a, 0.3), a, atol=1e-15)


def test_a_walk_is_axially_symmetric_only_where_both_scenes_are():
    """An intermediate scene of a walk from an off-axis load to an on-axis one is not
    symmetric about e_x, so its states must not be turned (RodProblem.turn_to_canonical)."""
    on_axis = Scene(length=1.0, stiffness=(1, 1, 1), end_force=[-2.6, 0.0, 0.0])
    off_axis = Scene(length=1.0, stiffness=(1, 1, 1), end_force=[-2.6, 0.1, 0.0])
    assert on_axis.axially_symmetric and not off_axis.axially_symmetric
    assert BlendedPath(on_axis, 1.0, on_axis).axially_symmetric
    assert not BlendedPath(off_axis, 1.0, on_axis).axially_symmetric
    assert not BlendedPath(on_axis, 1.0, off_axis).axially_symmetric
