"""Boundary conditions and loads of a scene, and the continuation path to them (§5, §7).

The reference state is straight along e_x from the origin, with d1 = e_y, d2 = e_z,
d3 = e_x. The end S = 0 stays at the origin in the reference frame (if it is held).
Every position a Scene holds (the end position, the seabed's and the sea surface's
heights) is in the solver's frame, whose origin is the start; ``start_position`` is
where that origin is (-rod_start_position: an anchor anywhere), added to every position
the run reports and subtracted from every one it reads (docs/method.md §5);
the end S = L and the loads are reached along the path t in [0, 1]:
position (1 - t) L e_x + t r_L, frame exp(t log Q) then a roll t * twist about the
current tangent, and forces scaled by t. Every quantity is in SI units.
"""

from dataclasses import dataclass, field

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.frames import REFERENCE_FRAME, rotation_about, rotation_log
from petsc_rod.model.derived import TAUT_GAP, applied_forces
from petsc_rod.model.model import check_chord, check_positive
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.scenes.line import piecewise_constant, piecewise_linear
from petsc_rod.scenes.starts import start_direction


def rolled_frame(frame, angle):
    """``frame`` (rows d1, d2, d3) rolled by ``angle`` rad about its own d3."""
    return frame @ rotation_about(frame[2], angle).T


@dataclass
class EndState:
    """What is prescribed at one end for one load factor."""

    kind: str
    position: np.ndarray
    frame: np.ndarray
    force: np.ndarray


@dataclass
class Scene:
    length: float
    stiffness: np.ndarray
    start: str = "clamp"
    end: str = "free"
    end_position: np.ndarray = None
    end_frame: np.ndarray = None
    # the frame of a clamped start S = 0 (rows d1, d2, d3; default the reference)
    start_frame: np.ndarray = None
    end_twist: float = 0.0
    start_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    end_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    load_values: np.ndarray = field(default_factory=lambda: np.zeros((1, 3)))
    load_breaks: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # environment (petsc_rod/environment/): a Seabed and a Current, or None
    seabed: object = None
    current: object = None
    # the line as sections of line types (scenes/line.py), from S = 0; () for a uniform
    # line of -rod_stiffness (and -rod_axial_stiffness)
    sections: tuple = ()
    # EA, N: the uniform line's axial stiffness (inf: inextensible)
    axial_stiffness: float = np.inf
    # the pipe's pressures (quantities/pressures.py; a line of sections): the sea surface's
    # height in the solver's frame (m; None: the higher held end), the contents'
    # density (kg/m^3) and the internal pressure at the top (Pa)
    sea_surface: float = None
    contents_density: float = 0.0
    internal_pressure: float = 0.0
    # the stress check (quantities/stresses.py): the allowable von Mises stress is this
    # factor times the line types' smys (API RP 2RD operating basic allowable, 2/3)
    design_factor: float = 2.0 / 3.0
    # flex joints (physics/flex_joint.py): the rotational stiffness k (N m/rad) of a
    # pinned end, 0 for none, and the neutral axis a its d3 is held to (None: the line's
    # direction at that end in its start shape, resolved in __post_init__ where the joint
    # has a stiffness: starts.start_direction); fixed, not on the load path
    start_rotational_stiffness: float = 0.0
    end_rotational_stiffness: float = 0.0
    start_joint_axis: np.ndarray = None
    end_joint_axis: np.ndarray = None
    # point loads (attachments, scenes/point_loads.py): arc lengths S_p (n_p,), m, dead
    # forces P_p (n_p, 3), N, and labels
    point_load_S: np.ndarray = field(default_factory=lambda: np.zeros(0))
    point_load_forces: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    point_load_names: tuple = ()
    # their drag areas C_d A (n_p,), m^2: drag 1/2 rho_w C_d A |v| v in the current
    point_load_drag_areas: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # their displaced volumes V (n_p,), m^3, whose buoyancy rho_w g V e_z the forces
    # include: taken off again above the sea surface (physics/point_loads.py)
    point_load_volumes: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # where S = 0 is, m: the solver's frame has its origin there (module docstring)
    start_position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    # the sea and the Earth, for weights and buoyancies: rho_w, kg/m^3, and g, m/s^2
    water_density: float = 1025.0
    gravity: float = 9.80665

    def __post_init__(self):
        self.stiffness = np.asarray(self.stiffness, dtype=float)
        if self.end_position is None:
            self.end_position = np.array([self.length, 0.0, 0.0])
        if self.end_frame is None:
            self.end_frame = REFERENCE_FRAME.copy()
        if self.start_frame is None:
            self.start_frame = REFERENCE_FRAME.copy()
        self.end_position = np.asarray(self.end_position, dtype=float)
        self.start_position = np.asarray(self.start_position, dtype=float).reshape(3)
        self.start_force = np.asarray(self.start_force, dtype=float)
        self.end_force = np.asarray(self.end_force, dtype=float)
        self.end_frame = np.asarray(self.end_frame, dtype=float).reshape(3, 3)
        self.start_frame = np.asarray(self.start_frame, dtype=float).reshape(3, 3)
        for name in ("start_joint_axis", "end_joint_axis"):
            axis = getattr(self, name)
            if axis is not None:
                setattr(self, name, np.asarray(axis, dtype=float).ravel())
        self.load_values = np.asarray(self.load_values, dtype=float).reshape(-1, 3)
        self.load_breaks = np.asarray(self.load_breaks, dtype=float).ravel()
        self.point_load_S = np.asarray(self.point_load_S, dtype=float).ravel()
        self.point_load_forces = np.asarray(self.point_load_forces, dtype=float).reshape(-1, 3)
        self.point_load_drag_areas = np.asarray(self.point_load_drag_areas, dtype=float).ravel()
        if self.point_load_drag_areas.size == 0:
            self.point_load_drag_areas = np.zeros(self.point_load_S.size)
        self.point_load_volumes = np.asarray(self.point_load_volumes, dtype=float).ravel()
        if self.point_load_volumes.size == 0:
            self.point_load_volumes = np.zeros(self.point_load_S.size)
        if len(self.point_load_names) != self.point_load_S.size:
            self.point_load_names = tuple(f"point {k + 1}"
                                          for k in range(self.point_load_S.size))
        self._end_rotation = rotation_log(self.end_frame.T @ REFERENCE_FRAME)
        self._start_rotation = rotation_log(self.start_frame.T @ REFERENCE_FRAME)
        # a flex joint's default axis, from the start shape of the whole scene: its
        # seabed is part of it (compile.py gives the joints with the seabed)
        for which in ("start", "end"):
            if (getattr(self, f"{which}_joint_axis") is None
                    and float(getattr(self, f"{which}_rotational_stiffness")) > 0):
                setattr(self, f"{which}_joint_axis", start_direction(self, which))

    @property
    def uniform_stiffness(self):
        """Whether K1, K2, K3 are the same along the whole line (no section changes them):
        the global step then keeps its constant-coefficient matrices."""
        return all(section.stiffness_is(self.stiffness) for section in self.sections)

    def stiffness_at(self, S, inside=None):
        """(K1, K2, K3) at arc lengths S (...), N m^2 -> (..., 3): the section's, linear
        along a tapered one; -rod_stiffness on a uniform line. At a section end, the
        section after it, or the one holding ``inside`` (S's shape) where given: the
        one-sided limit from an element (``inside`` its midpoint)."""
        S = np.asarray(S, dtype=float)
        if not self.sections:
            return np.broadcast_to(self.stiffness, S.shape + (3,)).copy()
        return piecewise_linear(self.sections, S, "stiffness_start", "stiffness_end",
                                inside)

    def stiffness_values(self):
        """(K1, K2, K3) at both ends of every section, (2 m, 3), N m^2 ((1, 3): the
        uniform line's): the stiffness is linear along each section, so its extremes over
        the line, and the sign of any linear combination such as the split a_i
        (frames.split_coefficients) anywhere on it, are those of these values."""
        if not self.sections:
            return self.stiffness[None, :].copy()
        return np.array([k for section in self.sections
                         for k in (section.stiffness_start, section.stiffness_end)])

    @property
    def stiffness_breaks(self):
        """S where the stiffness may change its slope or jump: the ends of the sections
        inside the line, (m - 1,) (none on a uniform line). The element matrices are
        integrated piece by piece between them (elements.cut_gauss_rule)."""
        return np.array([section.start for section in self.sections[1:]], dtype=float)

    def axial_stiffness_at(self, S):
        """EA at arc lengths S (...), N -> (...): the section's (inf: inextensible);
        -rod_axial_stiffness on a uniform line."""
        S = np.asarray(S, dtype=float)
        if not self.sections:
            return np.full(S.shape, float(self.axial_stiffness))
        return piecewise_constant(self.sections, S, "axial_stiffness")

    def drag_at(self, S, current):
        """The drag coefficient c = rho Cd D / 2 (kg/m^2) at arc lengths S (...): each
        section's own on a line of sections, else the current's (-rod_drag)."""
        S = np.asarray(S, dtype=float)
        if not self.sections:
            return np.full(S.shape, float(current.drag))
        return piecewise_constant(self.sections, S, "drag")

    @property
    def extensible(self):
        """Whether some part of the line has a finite EA (nothing is built for stretch
        otherwise)."""
        values = ([s.axial_stiffness for s in self.sections] if self.sections
                  else [self.axial_stiffness])
        return bool(np.any(np.isfinite(values)))

    @property
    def taut(self):
        """Whether an inextensible line is held at both ends at least its length less
        TAUT_GAP (relative) apart: straight, with an axial force its inextensibility
        leaves undetermined (model/derived.check_taut)."""
        held = self.start != "free" and self.end != "free"
        chord = np.linalg.norm(self.end_position - self.start_state(1.0).position)
        return held and not self.extensible and chord >= self.length * (1 - TAUT_GAP)

    @property
    def loaded(self):
        """Whether anything but the held ends loads the line: a distributed load, a
        point load, a seabed, a current or an end force."""
        return bool(np.any(self.load_values) or np.any(self.start_force)
                    or np.any(self.end_force) or np.any(self.point_load_forces)
                    or self.seabed is not None or self.current is not None)

    @property
    def load_piece_ends(self):
        """S at the ends of the load pieces, (m + 1,)."""
        return np.concatenate([[0.0], self.load_breaks, [self.length]])

    def load_beyond(self, S, t):
        """int_S^L f dS of the piecewise-constant load at factor t: S (...) -> (..., 3).

        Piecewise linear in S, with kinks at the load breaks.
        """
        ends = self.load_piece_ends
        S = np.asarray(S, dtype=float)[..., None]
        overlap = np.clip(ends[1:] - np.maximum(ends[:-1], S), 0.0, None)
        return t * overlap @ self.load_values

    def point_loads(self, t):
        """(S_p (n_p,), t P_p (n_p, 3)): the point loads at load factor t, m and N
        (physics/point_loads.py)."""
        return self.point_load_S.copy(), t * self.point_load_forces

    def point_drags(self, t):
        """[(weight, Current, C_d A (n_p,))]: the attachments' drag at load factor t is
        sum weight 1/2 rho_w C_d A |v| v with v the current at each point
        (physics/point_loads.py), here t times the scene's current; [] without a current
        or a drag area (a restart's blended path: scenes/blend.py)."""
        if self.current is None or not np.any(self.point_load_drag_areas > 0):
            return []
        return [(t, self.current, self.point_load_drag_areas)]

    def point_buoyancies(self, t):
        """t rho_w g V_p (n_p,), N: the upward part of the point loads at load factor t
        that holds in the water only (physics/point_loads.py), aligned with
        point_loads(t)."""
        return t * self.water_density * self.gravity * self.point_load_volumes

    def point_volumes(self):
        """V_p (n_p,), m^3, aligned with point_loads(t) (a restart's walk: both scenes')."""
        return self.point_load_volumes

    def applied_force(self):
        """int_0^L |f| dS + |P_0| + |P_L| + sum_p |P_p| (and the drag) at t = 1, N: the
        scale of the internal force n (and of the multiplier lambda3 that converges to
        it)."""
        return float(sum(self.applied_forces().values()))

    def applied_forces(self):
        """The parts of applied_force by where they come from, N (model/derived.py
        applied_forces): {'load', 'drag', 'start_force', 'end_force', 'point_loads'}."""
        current = self.current
        return applied_forces(self.load_piece_ends, self.load_values, self.start_force,
                              self.end_force, self.point_load_forces,
                              self.point_load_drag_areas, self.water_density,
                              None if current is None else current.drag,
                              None if current is None else current.velocities)

    def end_rotation(self):
        """The angle (rad) by which a clamped end is turned at t = 1: that of -rod_end_frame
        plus |-rod_end_twist|, and that of -rod_start_frame where the start is clamped
        too (a bound on the turn between them); 0 at a pinned or free end."""
        if self.end != "clamp":
            return 0.0
        start = np.linalg.norm(self._start_rotation) if self.start == "clamp" else 0.0
        return float(np.linalg.norm(self._end_rotation) + abs(self.end_twist) + start)

    def start_state(self, t):
        """The start at load factor t: at the origin, its frame the reference turned by
        exp(t log Q0) (Q0 = -rod_start_frame, a clamp's; the reference by default), as
        end_state turns the end's."""
        angle = np.linalg.norm(self._start_rotation)
        q = (rotation_about(self._start_rotation, t * angle) if angle > 0 else np.eye(3))
        return EndState(self.start, np.zeros(3), REFERENCE_FRAME @ q.T, t * self.start_force)

    def end_state(self, t):
        position = (1 - t) * np.array([self.length, 0.0, 0.0]) + t * self.end_position
        tilted, roll = self.end_frame_parts(t)
        return EndState(self.end, position, rolled_frame(tilted, roll), t * self.end_force)

    def end_frame_parts(self, t):
        """The end frame at load factor t in its two parts: the reference frame turned by
        exp(t log Q) (rows d1, d2, d3), and the roll about its d3 that -rod_end_twist
        adds, t * twist rad (any size; rolled_frame puts them together)."""
        angle = np.linalg.norm(self._end_rotation)
        q = (rotation_about(self._end_rotation, t * angle) if angle > 0 else np.eye(3))
        return REFERENCE_FRAME @ q.T, t * self.end_twist

    def joints(self):
        """The flex joints, [(which, k, a)]: which 'start' or 'end', k > 0 the rotational
        stiffness (N m/rad), a the unit neutral axis (physics/flex_joint.py; the
        default resolved when the scene was made, start_direction)."""
        joints = []
        for which in ("start", "end"):
            k = float(getattr(self, f"{which}_rotational_stiffness"))
            if k > 0:
                axis = getattr(self, f"{which}_joint_axis")
                joints.append((which, k, axis / np.linalg.norm(axis)))
        return joints

    def drag_loads(self, t):
        """[(weight, Current)]: the drag at load factor t is the sum of each current's
        Morison drag times its weight, here t times the scene's current ([] without one;
        a restart's blended path has two, scenes/blend.py)."""
        return [] if self.current is None else [(t, self.current)]

    @property
    def link_axis(self):
        """The common end tangent e of a rod clamped at both ends whose end frame only
        rolls about it on the whole load path (its d3 stays e), else None: the scenes
        whose linking number is defined and tracked (analysis/link.py)."""
        axis = REFERENCE_FRAME[2]
        tilt = self._end_rotation - (self._end_rotation @ axis) * axis
        if (self.start != "clamp" or self.end != "clamp" or np.linalg.norm(tilt) > 1e-12
                or np.linalg.norm(self._start_rotation) > 0):
            return None
        return axis.copy()

    @property
    def axially_symmetric(self):
        """Whether every rotation about the x axis through the origin, together with a
        uniform roll of the sections, maps an equilibrium to an equilibrium: K1 = K2 all
        along the line (the roll costs nothing), every load along e_x, a held end S = L on
        the axis and a clamped one only rolled about e_x, no seabed, no current. Such a
        scene buckles into a family of equilibria (docs/method.md §10, which the solver
        reports)."""
        axis = REFERENCE_FRAME[2]
        off_axis = np.concatenate([self.start_force[1:], self.end_force[1:],
                                   self.load_values[:, 1:].ravel(),
                                   self.point_load_forces[:, 1:].ravel()])
        tilt = self._end_rotation - (self._end_rotation @ axis) * axis
        start_tilt = self._start_rotation - (self._start_rotation @ axis) * axis
        values = self.stiffness_values()
        return bool(np.all(values[:, 0] == values[:, 1]) and not np.any(off_axis)
                    and (self.end == "free" or not np.any(self.end_position[1:]))
                    and (self.end != "clamp" or np.linalg.norm(tilt) <= 1e-12)
                    and np.linalg.norm(start_tilt) <= 1e-12
                    and self.seabed is None and self.current is None)

    def end_roll(self, t):
        """The angle (rad) by which the end frame has rolled about link_axis at load
        factor t, counted continuously from t = 0 (end_state: the rotation of -rod_end_frame
        about e_x, then -rod_end_twist)."""
        return t * (self._end_rotation @ REFERENCE_FRAME[2] + self.end_twist)

    def _validate_sections(self):
        """The sections follow each other from S = 0 to L, each of positive length, with
        positive stiffnesses and EA (a Python caller's; a model's are made so,
        compile.py)."""
        starts = np.array([s.start for s in self.sections])
        ends = np.array([s.end for s in self.sections])
        if (starts[0] != 0.0 or ends[-1] != self.length or np.any(ends <= starts)
                or np.any(starts[1:] != ends[:-1])):
            raise RodInputError("the sections must follow each other from S = 0 to the "
                                "length, each of positive length")
        values = np.concatenate([[s.stiffness_start, s.stiffness_end] for s in self.sections])
        if not (np.all(values > 0) and np.all(np.isfinite(values))
                and all(s.axial_stiffness > 0 for s in self.sections)):
            raise RodInputError("the sections' K1, K2, K3 and EA must be positive (N m^2, N)")

    def validate(self, used=()):
        """Raise RodInputError on a scene a Python caller built that no cable can realise:
        a length, stiffness or EA that is not positive, sections that do not tile the
        line, or an inextensible line whose held ends are
        farther apart than its length (model.check_chord; an extensible one is then taut,
        docs/method.md §12). A scene compiled from a Model is checked by Model.check
        (``used``: kept for callers that pass the options they set)."""
        check_positive(self.length, self.stiffness, self.axial_stiffness, FIELD_NAMES)
        if self.sections:
            self._validate_sections()
        if self.start != "free" and self.end != "free":
            check_chord(float(np.linalg.norm(self.end_position)), self.length,
                        self.extensible, bool(self.sections), FIELD_NAMES)
