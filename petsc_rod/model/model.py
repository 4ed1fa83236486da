"""The model: a line between two ends, with its attachments, in the sea; and every
check that decides whether such a model can be solved, written on the model's fields
(a field left None was not given).

A Model is one line today; its line, ends and attachments are kept together in a Span,
so that a system of several spans meeting at points can hold a list of them.
"""

from dataclasses import dataclass, field

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.attachment import Attachment
from petsc_rod.model.derived import check_loads
from petsc_rod.model.end import KINDS, End
from petsc_rod.model.line import Line, UniformLine
from petsc_rod.model.line_type import check_line_types
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.model.sea import Environment
from petsc_rod.model.values import MAX_MAGNITUDE

# The frame of the straight reference, rows d1, d2, d3 = e_y, e_z, e_x.
REFERENCE_ROWS = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


@dataclass(frozen=True)
class Span:
    """A line with its two ends and the attachments along it."""

    line: object
    start: End
    end: End
    attachments: tuple = ()

    @property
    def sections(self):
        """Whether the line is of sections of line types."""
        return isinstance(self.line, Line)

    @property
    def length(self):
        return float(self.line.length)

    @property
    def extensible(self):
        """Whether some part of the line has a finite EA."""
        values = ([entry[0].ea for entry in self.line.sections] if self.sections
                  else [self.line.axial_stiffness])
        return bool(np.any(np.isfinite(np.asarray(values, dtype=float))))

    def origin(self):
        """Where S = 0 is, (3,), m."""
        return (np.zeros(3) if self.start.position is None
                else np.asarray(self.start.position, dtype=float))

    def end_offset(self):
        """The end S = L from the start, (3,), m (its default: (L, 0, 0))."""
        if self.end.position is None:
            return np.array([self.length, 0.0, 0.0])
        return np.asarray(self.end.position, dtype=float) - self.origin()


@dataclass(frozen=True)
class Model:
    """A line between two ends in the sea, with attachments: ``line`` a Line of
    sections of line types or a UniformLine, ``start`` and ``end`` its Ends at S = 0 and
    S = L, ``environment`` the sea (Environment), ``attachments`` (Attachment, ...)."""

    line: object
    start: End
    end: End
    environment: Environment = field(default_factory=Environment)
    attachments: tuple = ()

    def __post_init__(self):
        if not isinstance(self.line, (Line, UniformLine)):
            raise RodInputError(f"Model.line: expected an api.Line, not "
                                f"{type(self.line).__name__}")
        for name, kind in (("start", End), ("end", End), ("environment", Environment)):
            if not isinstance(getattr(self, name), kind):
                raise RodInputError(f"Model.{name}: expected an api.{kind.__name__}, not "
                                    f"{type(getattr(self, name)).__name__}")
        if isinstance(self.attachments, (str, bytes)) or not all(
                isinstance(a, Attachment) for a in self.attachments):
            raise RodInputError("Model.attachments: a sequence of api.Attachment")

    @property
    def spans(self):
        """The model's lines with their ends: one today."""
        return (Span(self.line, self.start, self.end, tuple(self.attachments)),)

    def check(self, names=FIELD_NAMES):
        """Raise RodInputError, its message worded with ``names`` (names.Names), on a
        model no line can realise or a field given where nothing uses it."""
        for span in self.spans:
            check_span(span, self.environment, names)
        check_sea(self.environment, self.spans, names)
        for span in self.spans:
            if span.sections:
                check_pipe(span.line, names)
        for span in self.spans:             # the loads derived from the fields
            check_loads(span, self.environment, names)


def check_span(span, sea, n):
    """The checks of one line with its ends and attachments (Model.check)."""
    line = span.line
    if span.sections:
        check_line_types(line.types(), n["line_types"], MAX_MAGNITUDE)
    else:
        check_uniform(line, n)
    check_ends(span, n)
    check_attachments(span, n)


def check_positive(length, stiffness, axial_stiffness, n):
    """A positive length (m), stiffnesses K1, K2, K3 (N m^2) and EA (N; inf:
    inextensible): of a uniform line (check_uniform) and of a Scene a Python caller
    built (Scene.validate)."""
    if not length > 0:
        raise RodInputError(f"{n['length']} {length:g}: the length must be positive")
    if not np.all(np.asarray(stiffness, dtype=float) > 0):
        raise RodInputError(f"{n['stiffness']}: K1, K2, K3 must all be positive (N m^2)")
    if not axial_stiffness > 0:
        raise RodInputError(f"{n['axial_stiffness']} {axial_stiffness:g}: EA must be "
                            "positive (N; default inf, inextensible)")


def check_uniform(line, n):
    """A uniform line: positive length, stiffness and EA, as many load pieces as breaks
    allow, the breaks increasing inside the line."""
    check_positive(line.length, line.stiffness, line.axial_stiffness, n)
    load = np.asarray(line.load, dtype=float)
    if load.size % 3:
        raise RodInputError(f"{n['load']}: give 3 values (fx,fy,fz) per load piece")
    pieces, breaks = load.reshape(-1, 3), np.asarray(line.load_breaks, dtype=float).ravel()
    if len(pieces) != len(breaks) + 1:
        raise RodInputError(
            f"{n['load']} has {len(pieces)} pieces of 3 values but "
            f"{n['load_breaks']} gives {len(breaks)} breaks; give 3 (m) values for m pieces "
            "and m - 1 breaks")
    ends = np.concatenate([[0.0], breaks, [line.length]])
    if np.any(np.diff(ends) <= 0):
        raise RodInputError(f"{n['load_breaks']}: the breaks must increase strictly inside "
                            f"(0, {n['length']})")


def check_pipe(line, n):
    """Refuse a pipe setting that does nothing without its partner in the line types:
    the internal pressure and the contents' density act on the bore (no type with an
    id > 0: no bore), the design factor scales the yield stress (no type with smys: no
    utilisation)."""
    types = line.types()
    bore = any(kind.id > 0 for kind in types)
    yield_stress = any(kind.smys is not None for kind in types)
    if line.design_factor is not None and not 0 < line.design_factor <= 1:
        raise RodInputError(f"{n['design_factor']} {line.design_factor:g}: must be in (0, 1]")
    for name in ("contents_density", "internal_pressure"):
        if getattr(line, name) is not None and getattr(line, name) < 0:
            raise RodInputError(f"{n[name]} {getattr(line, name):g}: must not be negative")
    for name, present, partner in (
            ("internal_pressure", bore, "an id column (the bore it acts on)"),
            ("contents_density", bore, "an id column (the bore the contents fill)"),
            ("design_factor", yield_stress,
             "an smys column (the yield stress it scales into the allowable stress)")):
        # a zero pressure or density is the default, no setting (the API's Line took 0)
        if (getattr(line, name) if name != "design_factor"
                else getattr(line, name) is not None) and not present:
            raise RodInputError(f"{n[name]} needs a line type with {partner}: no line type "
                                f"of {n['sections']} has one; give it in {n['line_types']}, "
                                f"or drop {n[name]}")


def frame_rows(frame):
    """A frame's rows (3, 3) from its 9 numbers (None: the reference's)."""
    return (REFERENCE_ROWS.copy() if frame is None
            else np.asarray(frame, dtype=float).reshape(3, 3))


def check_chord(chord, length, extensible, sections, n):
    """Refuse an inextensible line whose held ends are ``chord`` m apart, more than its
    ``length`` (an extensible one is then taut, with a tension set by its stretch,
    docs/method.md §12)."""
    if chord > length * (1 + 1e-12) and not extensible:
        raise RodInputError(
            f"{n['end_position']}: the ends are {chord:.15g} m apart, "
            f"{chord - length:.3g} m more than the cable's length {length:.15g} m "
            "(inextensible); " + ("bring the end within the sections' length, or give "
                                  "the line types an ea column (EA, N)" if sections
                                  else f"bring the end within {n['length']}, or give "
                                  f"{n['axial_stiffness']}"))


def check_ends(span, n):
    """The ends: a known kind, not both free, held within the line's length, frames
    orthonormal and right-handed, and each field given only to the kind that uses it."""
    start, end = span.start, span.end
    for key, kind in (("start", start.kind), ("end", end.kind)):
        if kind not in KINDS:
            raise RodInputError(f"{n[key]} {kind}: unknown end condition; use one of "
                                + "|".join(("clamp", "pin", "free")))
    if start.kind == "free" and end.kind == "free":
        raise RodInputError(f"{n['start']} free and {n['end']} free: nothing holds the "
                            "cable (a rigid motion is free); hold one end with clamp or pin")
    held = start.kind != "free" and end.kind != "free"
    if held:
        check_chord(float(np.linalg.norm(span.end_offset())), span.length, span.extensible,
                    span.sections, n)
    for key, frame in (("end_frame", end.frame), ("start_frame", start.frame)):
        rows = frame_rows(frame)
        if np.abs(rows @ rows.T - np.eye(3)).max() > 1e-8 or np.linalg.det(rows) < 0:
            raise RodInputError(f"{n[key]}: the rows d1, d2, d3 must be orthonormal and "
                                "right-handed (d3 = d1 x d2)")
    if start.twist is not None:
        raise RodInputError(f"{n['start_twist']}: the roll of the clamped end S = L is the "
                            f"end's ({n['end_twist']}); turn the start by its frame")
    if start.frame is not None and start.kind != "clamp":
        raise RodInputError(f"{n['start_frame']} needs {n['start']} clamp (the start is "
                            f"{start.kind}); drop it or change {n['start']}")
    requires = (("end_frame", end.frame, ("clamp",)), ("end_twist", end.twist, ("clamp",)),
                ("end_position", end.position, ("clamp", "pin")),
                ("end_force", end.force, ("free",)))
    for key, value, kinds in requires:
        if value is not None and end.kind not in kinds:
            raise RodInputError(f"{n[key]} needs {n['end']} {'|'.join(kinds)} "
                                f"(the end is {end.kind}); drop it or change {n['end']}")
    if start.position is not None and start.kind == "free":
        raise RodInputError(f"{n['start_position']} needs a held start ({n['start']} clamp|"
                            "pin): a free start goes where the loads take it; drop it, or "
                            f"give {n['end_position']} for the held end")
    if start.force is not None and start.kind != "free":
        raise RodInputError(f"{n['start_force']} needs {n['start']} free (the start is "
                            f"{start.kind}); drop it or change {n['start']}")
    check_joints(span, n)


def check_joints(span, n):
    """A flex joint (an End's stiffness and axis) is a spring at a pinned end: k finite
    and not negative, the axis not zero and given only with k > 0, and the end a pin (a
    clamp holds the frame already, a free end has nothing to turn against)."""
    for which, end in (("start", span.start), ("end", span.end)):
        k = 0.0 if end.stiffness is None else float(end.stiffness)
        stiffness, axis_name = n[f"{which}_rotational_stiffness"], n[f"{which}_joint_axis"]
        if not np.isfinite(k) or k < 0:
            raise RodInputError(
                f"{stiffness} {k:g}: must be finite and not negative (N m/rad; 0 is a pin; "
                f"for an end held in full use {n[which]} clamp)")
        axis = None if end.axis is None else np.asarray(end.axis, dtype=float).ravel()
        if axis is not None and (axis.shape != (3,) or not np.all(np.isfinite(axis))
                                 or np.linalg.norm(axis) == 0):
            raise RodInputError(f"{axis_name}: give a nonzero vector x,y,z (the joint's "
                                "neutral axis; it is normalised)")
        if axis is not None and k == 0:
            raise RodInputError(
                f"{axis_name} needs {stiffness} k > 0 (the axis of a flex joint; without "
                "one the end is a plain pin)")
        for name, given in ((stiffness, bool(end.stiffness)),     # 0: no joint
                            (axis_name, axis is not None)):
            if (given or k > 0) and end.kind != "pin":
                raise RodInputError(
                    f"{name} needs {n[which]} pin (the {which} is {end.kind}): a flex "
                    "joint is a rotational spring at a pinned end; drop it or set "
                    f"{n[which]} pin")


def check_attachments(span, n):
    """Each attachment on the line, its mass, volume and drag area not negative."""
    if not span.attachments:
        return
    S = np.array([a.S for a in span.attachments], dtype=float)
    outside = np.flatnonzero((S < 0) | (S > span.length))
    if outside.size:
        k = int(outside[0])
        label = span.attachments[k].name or f"point {k + 1}"
        raise RodInputError(
            f"{n['point_loads']}: {label} at s = {S[k]:.6g} m is beyond "
            f"the line (0 <= s <= {n['length']} {span.length:.6g} m); give an arc length "
            "on the line")
    values = np.array([(a.mass, a.volume, a.cda) for a in span.attachments])
    if np.any(values < 0):
        raise RodInputError(f"{n['point_loads']}: an attachment's mass, volume and cda "
                            "must not be negative")


def check_sea(sea, spans, n):
    """The sea's fields in range, and the seabed's and the current's given only with what
    they need."""
    check_ranges(sea, n)
    check_seabed(sea, n)
    sections = any(span.sections for span in spans)
    drags = [span.line.drag for span in spans if not span.sections]
    if sea.current is None:
        if any(drag is not None for drag in drags):
            raise RodInputError(f"{n['drag']} needs a current ({n['current']} or "
                                f"{n['current_profile']})")
        if sea.surface is not None and not sections:
            raise RodInputError(f"{n['sea_surface']} needs a current ({n['current']} or "
                                f"{n['current_profile']})")
        return
    if any(drag is None for drag in drags):
        raise RodInputError(f"a current needs {n['drag']} rho,Cd,D (water density kg/m^3, "
                            "drag coefficient, hydrodynamic diameter m)")
    if sea.surface is not None and sea.profile() is None and not sections:
        raise RodInputError(f"{n['sea_surface']} needs {n['current_profile']} (a uniform "
                            "current does not depend on depth) or "
                            f"{n['sections']} (the external pressure)")


# The ranges of the sea's numbers (as the command line's options hold them).
SEA_RANGES = (
    ("water_density", lambda v: v >= 0, "must not be negative"),
    ("gravity", lambda v: v >= 0, "must not be negative"),
    ("seabed_stiffness", lambda v: v >= 1 / MAX_MAGNITUDE,
     f"must be positive (at least {1 / MAX_MAGNITUDE:g})"),
    ("seabed_friction_stiffness", lambda v: v >= 1 / MAX_MAGNITUDE,
     f"must be positive (at least {1 / MAX_MAGNITUDE:g})"),
    ("seabed_friction", lambda v: np.all(np.asarray(v) > 0), "must be positive"),
    ("seabed_slope", lambda v: abs(v) < 90, "must lie strictly between -90 and 90 degrees "
     "(a seabed's slope above the horizontal; moderate slopes, a few degrees, are the "
     "model's range)"))


def check_ranges(sea, n):
    """The sea's numbers within their ranges (SEA_RANGES)."""
    for key, holds, what in SEA_RANGES:
        value = getattr(sea, key)
        if value is not None and not holds(value):
            raise RodInputError(f"{n[key]} {value!r}: {what}")


def check_seabed(sea, n):
    """The seabed's shape, stiffness and friction given only with a seabed, one shape at
    a time, a direction of one of its two forms."""
    profile = sea.seabed_profile is not None
    if not sea.has_seabed:
        for key in ("seabed_stiffness", "seabed_slope", "seabed_direction", "seabed_origin",
                    "seabed_friction", "seabed_friction_stiffness"):
            if getattr(sea, key) is not None:
                raise RodInputError(f"{n[key]} needs {n['seabed']} (the seabed's height) or "
                                    f"{n['seabed_profile']}")
        return
    if sea.seabed_friction is None and sea.seabed_friction_stiffness is not None:
        raise RodInputError(f"{n['seabed_friction_stiffness']} needs {n['seabed_friction']} "
                            "(the friction coefficient)")
    if sea.seabed_friction is not None:
        mu = np.atleast_1d(np.asarray(sea.seabed_friction, dtype=float))
        if mu.size not in (1, 2):
            raise RodInputError(f"{n['seabed_friction']} {','.join(f'{v:g}' for v in mu)}: "
                                "give one coefficient mu or two, mu_axial,mu_lateral")
    if profile and (sea.seabed is not None or sea.seabed_slope is not None):
        raise RodInputError(f"{n['seabed_profile']} gives the seabed's heights: drop "
                            f"{n['seabed']} and {n['seabed_slope']}, or the profile")
    if not profile and sea.seabed_slope is None:
        for key in ("seabed_direction", "seabed_origin"):
            if getattr(sea, key) is not None:
                raise RodInputError(f"{n[key]} needs {n['seabed_slope']} or "
                                    f"{n['seabed_profile']} (the flat {n['seabed']} has no "
                                    f"direction or origin); give one of them, or drop "
                                    f"{n[key]}")
    if sea.seabed_direction is not None:
        given = np.atleast_1d(np.asarray(sea.seabed_direction, dtype=float))
        if given.size != 1 and (given.size != 2 or float(np.hypot(*given)) == 0):
            raise RodInputError(
                f"{n['seabed_direction']} {','.join(f'{v:g}' for v in given)}: give an "
                "azimuth in degrees (one number) or a horizontal vector dx,dy (two "
                "numbers, not both 0)")
    if profile and np.shape(sea.seabed_profile)[1] == 3 and sea.seabed_direction is not None:
        raise RodInputError(f"{n['seabed_direction']}: a grid's rows give x and y (from "
                            f"{n['seabed_origin']}); drop the direction")
