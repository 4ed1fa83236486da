"""The load path of a restart whose scene differs from its file's (docs/method.md §7).

The file's state is an equilibrium of its scene A at load factor t_f; this run's scene
B is to be reached at t = 1. The path parameter s in [0, 1] walks from one to the other:
every quantity the load path carries is

    q(s) = (1 - s) q_A(t_f) + s q_B(1),

so that s = 0 is the file's equilibrium itself (the first step is a warm start, not a
jump) and s = 1 is this run's scene. The loads and forces are linear in their values,
so the blend of the loads is the load of the blended values, exactly; the end frame
before its -rod_end_twist turns along the geodesic from A's to B's and the twist is
blended linearly (of any size, Scene.end_frame_parts), except for a rod clamped at both
ends on one axis, whose whole end roll is blended linearly so that the linking number's
bookkeeping (Scene.end_roll) stays continuous. Everything the load path does not carry (length,
stiffness, end kinds, seabed) is B's from the first step.
"""

import dataclasses

import numpy as np

from petsc_rod.frames import rotation_about, rotation_log, rotations
from petsc_rod.scenes.scene import EndState, rolled_frame

# The Scene fields the load path carries, compared to tell whether a restart walks.
PATH_FIELDS = ("load_values", "load_breaks", "start_force", "end_force", "end_position",
               "end_frame", "start_frame", "end_twist", "current", "point_load_S", "point_load_forces",
               "point_load_drag_areas", "point_load_volumes")
# The Scene fields a restart takes from this run's scene at once.
FIXED_FIELDS = ("stiffness", "axial_stiffness", "start", "end", "seabed", "sections",
                "start_rotational_stiffness", "end_rotational_stiffness", "start_joint_axis",
                "end_joint_axis")


def _same(a, b):
    """Whether two field values are equal: arrays exactly (shape and bits), a Current
    by its depths, velocities, surface and drag, anything else by ==."""
    if a is None or b is None:
        return a is b
    if isinstance(a, tuple) or isinstance(b, tuple):        # sections
        return (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b)
                and all(_same(x, y) for x, y in zip(a, b)))
    if dataclasses.is_dataclass(a) and type(a) is type(b):
        return all(_same(getattr(a, f.name), getattr(b, f.name))
                   for f in dataclasses.fields(a))
    if hasattr(a, "velocities"):
        return all(_same(getattr(a, key), getattr(b, key))
                   for key in ("depths", "velocities", "surface", "drag"))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    return a == b


def differences(old, new, fields=PATH_FIELDS):
    """The names of ``fields`` in which Scene ``old`` and Scene ``new`` differ."""
    return [name for name in fields if not _same(getattr(old, name), getattr(new, name))]


def blended_frame(a, b, s, axis=None):
    """The end frame (rows d1, d2, d3) a fraction s of the way from frame ``a`` to frame
    ``b``: a @ exp(s log P)^T with P = b^T a the rotation that takes the rows of a to
    those of b (the geodesic, |log P| <= pi). With ``axis`` (the common tangent of a rod
    tracked for its link), a turned about it by s times ``axis`` (a rotation vector
    whose length is the roll to add, any size), so that a roll of a whole turn is walked,
    not skipped."""
    if axis is not None:
        angle = float(np.linalg.norm(axis))
        turn = rotation_about(axis, s * angle) if angle > 0 else np.eye(3)
        return a @ turn.T
    return a @ rotations(s * rotation_log(b.T @ a)).T


class BlendedPath:
    """The scene of a restart's walk from Scene ``old`` at load factor ``t_old`` (the
    file's) to Scene ``new`` at 1 (module docstring), with the interface the terms, the
    global step and the continuation ask of a scene's path: start_state(s), end_state(s),
    load_beyond(S, s), load_piece_ends, point_loads(s), point_drags(s),
    point_buoyancies(s), point_volumes(), end_roll(s),
    link_axis, drag_loads(s). Any other attribute (length, stiffness, seabed,
    applied_force, ...) is ``new``'s."""

    def __init__(self, old, t_old, new):
        self.old, self.t_old, self.new = old, float(t_old), new
        # a rod tracked for its link in both scenes: the roll walked about the axis
        self._axis = new.link_axis if old.link_axis is not None else None

    def __getattr__(self, name):
        """What the load path does not carry is the new scene's."""
        if name in ("old", "new", "t_old", "_axis"):
            raise AttributeError(name)
        return getattr(self.new, name)

    @property
    def link_axis(self):
        return self._axis

    @property
    def axially_symmetric(self):
        """The walk is symmetric about the x axis only where both scenes are (an
        intermediate scene of a walk from an asymmetric one is not: its states must not
        be turned, RodProblem.turn_to_canonical)."""
        return self.old.axially_symmetric and self.new.axially_symmetric

    @property
    def load_piece_ends(self):
        """S at the ends of the pieces of either load, (m + 1,): the blend is piecewise
        constant between them (their union)."""
        return np.union1d(self.old.load_piece_ends, self.new.load_piece_ends)

    def load_beyond(self, S, s):
        """int_S^L f dS of the blended load, (1 - s) F_A(S, t_f) + s F_B(S, 1), N:
        S (...) -> (..., 3); exact, the load being linear in its values."""
        return ((1 - s) * self.old.load_beyond(S, self.t_old)
                + s * self.new.load_beyond(S, 1.0))

    def point_loads(self, s):
        """(S_p, P_p) of the blend: A's points with their forces at t_f times (1 - s) and
        B's at 1 times s (each a dead load, linear in its value: physics/point_loads.py)."""
        (S_a, P_a), (S_b, P_b) = self.old.point_loads(self.t_old), self.new.point_loads(1.0)
        return np.concatenate([S_a, S_b]), np.concatenate([(1 - s) * P_a, s * P_b])

    def point_drags(self, s):
        """[(weight, Current, C_d A)] of the blend, aligned with point_loads(s): A's
        attachments in A's current times (1 - s), B's in B's times s (as drag_loads)."""
        n_old, n_new = (scene.point_loads(1.0)[0].size for scene in (self.old, self.new))
        return ([((1 - s) * w, c, np.concatenate([a, np.zeros(n_new)]))
                 for w, c, a in self.old.point_drags(self.t_old)]
                + [(s * w, c, np.concatenate([np.zeros(n_old), a]))
                   for w, c, a in self.new.point_drags(1.0)])

    def point_buoyancies(self, s):
        """The blend's rho_w g V_p (n_p,), N, aligned with point_loads(s): A's at t_f times
        (1 - s), B's at 1 times s."""
        return np.concatenate([(1 - s) * self.old.point_buoyancies(self.t_old),
                               s * self.new.point_buoyancies(1.0)])

    def point_volumes(self):
        """A's volumes and B's, aligned with point_loads(s), m^3."""
        return np.concatenate([self.old.point_volumes(), self.new.point_volumes()])

    def end_roll(self, s):
        """(1 - s) roll_A(t_f) + s roll_B(1), rad: continuous along the walk."""
        return (1 - s) * self.old.end_roll(self.t_old) + s * self.new.end_roll(1.0)

    def _blended_end(self, a, b, s, frame):
        """The EndState of kind b.kind with position and force blended linearly and the
        given ``frame``. Where the kinds differ, b's values from the first step (what a
        held end means in one scene, it does not in the other)."""
        if a.kind != b.kind:
            return b
        return EndState(b.kind, (1 - s) * a.position + s * b.position, frame,
                        (1 - s) * a.force + s * b.force)

    def start_state(self, s):
        a, b = self.old.start_state(self.t_old), self.new.start_state(1.0)
        return self._blended_end(a, b, s, blended_frame(a.frame, b.frame, s))

    def end_state(self, s):
        """The end frame as Scene.end_state builds it, in its two parts: the geodesic
        between the two scenes' frames before their -rod_end_twist, then the blended
        roll (1 - s) t_f twist_A + s twist_B about its d3, of any size (a geodesic
        between the rolled frames would walk a roll above pi the short way round). For a
        rod tracked for its link, the whole roll about the axis (blended_frame)."""
        a, b = self.old.end_state(self.t_old), self.new.end_state(1.0)
        if self._axis is not None:
            roll = self.new.end_roll(1.0) - self.old.end_roll(self.t_old)
            frame = blended_frame(a.frame, b.frame, s, self._axis * roll)
        else:
            (tilt_a, roll_a), (tilt_b, roll_b) = (self.old.end_frame_parts(self.t_old),
                                                  self.new.end_frame_parts(1.0))
            frame = rolled_frame(blended_frame(tilt_a, tilt_b, s), (1 - s) * roll_a + s * roll_b)
        return self._blended_end(a, b, s, frame)

    def drag_loads(self, s):
        """[(weight, Current)]: the drag is (1 - s) t_f f_A + s f_B, the sum of each
        current's drag c |v_n| v_n times its weight (physics/drag.py DragTerm)."""
        return ([((1 - s) * w, c) for w, c in self.old.drag_loads(self.t_old)]
                + [(s * w, c) for w, c in self.new.drag_loads(1.0)])
