"""A line from S = 0: of sections of line types (Line), or the uniform line of one
stiffness under piecewise-constant loads that the command line also poses
(UniformLine); each with what meshes it (element counts)."""

from dataclasses import dataclass
import math

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.line_type import LineType
from petsc_rod.model.values import optional, real, reals, whole

# The elements of a line whose mesh is not given otherwise (-rod_elements' default).
DEFAULT_ELEMENTS = 64
# The fewest elements a line of sections is meshed with along its length: an element
# longer than the length over this is a chord across a quarter of the line or more,
# which cannot represent the shape of a line of several sections (a 2300 m section of
# one element). A uniform line keeps any count: 2 elements of the P2 rod converge at the
# mesh's order (docs/stability.md, group mesh).
MIN_LINE_ELEMENTS = 4


@dataclass(frozen=True)
class Line:
    """The line from S = 0 as sections of line types: ``sections`` a sequence of
    (LineType, length m) or (LineType, length m, elements). The elements of a section
    without a count: ``elements`` (the whole line's count, shared out by length among
    them, at least 1 each) where given, else length / ``element_length`` (m, rounded, at
    least 1) where that is given, else DEFAULT_ELEMENTS shared out. The pipe:
    ``contents_density`` (kg/m^3) and ``internal_pressure`` at the top (Pa) give the
    reported pressures and wall tension (quantities/pressures.py), ``design_factor`` the
    allowable stress of a type with smys (quantities/stresses.py; None: 2/3); None: not
    given (0)."""

    sections: tuple
    element_length: float = 1.0
    contents_density: float = None
    internal_pressure: float = None
    design_factor: float = None
    elements: int = None

    def __post_init__(self):
        if self.element_length is not None and not real(
                "Line.element_length", self.element_length) > 0:
            raise RodInputError(f"Line.element_length {self.element_length!r}: must be a "
                                "positive length (m), the elements of the sections without "
                                "a count")
        for name in ("contents_density", "internal_pressure", "design_factor"):
            optional(f"Line.{name}", getattr(self, name), real)
        if self.elements is not None and not (whole(self.elements) and self.elements >= 1):
            raise RodInputError(f"Line.elements {self.elements!r}: a whole number of at "
                                "least 1")
        if isinstance(self.sections, (str, bytes)) or not hasattr(self.sections, "__len__") \
                or not len(self.sections):
            raise RodInputError("Line.sections: a sequence of (LineType, length m) or "
                                "(LineType, length m, elements)")
        for k, entry in enumerate(self.sections):
            owner = f"Line.sections[{k}]"
            if isinstance(entry, (str, bytes)) or not hasattr(entry, "__len__") \
                    or len(entry) not in (2, 3) or not isinstance(entry[0], LineType):
                raise RodInputError(f"{owner} {entry!r}: expected (LineType, length m) or "
                                    "(LineType, length m, elements)")
            if not real(f"{owner} length", entry[1]) > 0:
                raise RodInputError(f"{owner}: the length {entry[1]!r} must be positive (m)")
            if len(entry) == 3 and (not whole(entry[2]) or entry[2] < 1):
                raise RodInputError(f"{owner}: the element count {entry[2]!r} must be a "
                                    "whole number of at least 1")

    def types(self):
        """The distinct LineTypes, in the order met."""
        found = {}
        for entry in self.sections:
            found.setdefault(entry[0].name, entry[0])
        return list(found.values())

    @property
    def lengths(self):
        """Each section's length, (m,), m."""
        return np.array([float(entry[1]) for entry in self.sections])

    @property
    def ends(self):
        """S at the sections' ends, (m + 1,), m, from 0."""
        return np.concatenate([[0.0], np.cumsum(self.lengths)])

    @property
    def length(self):
        """m."""
        return float(self.ends[-1])

    def section_list(self, water_density, gravity):
        """The Sections (line_type.Section) of the line in water of ``water_density``
        (kg/m^3) under ``gravity`` (m/s^2)."""
        ends = self.ends
        return [entry[0].section(ends[k], ends[k + 1], water_density, gravity)
                for k, entry in enumerate(self.sections)]

    def element_counts(self, names):
        """The element count of each section (class docstring), (m,): element_counts
        of its sections, worded with ``names`` (names.Names)."""
        counts = [entry[2] if len(entry) > 2 else None for entry in self.sections]
        if self.elements is None and self.element_length is not None:
            counts = [c if c is not None else max(1, round(length / self.element_length))
                      for c, length in zip(counts, self.lengths)]
        given = self.elements is not None
        return element_counts([entry[0].name for entry in self.sections], self.lengths,
                              counts, self.elements if given else DEFAULT_ELEMENTS, given,
                              names)


def element_counts(types, lengths, counts, total, given, names):
    """The element count of each section of line types ``types`` and ``lengths`` (m),
    (m,): its own count where ``counts`` gives one (None: not), the rest of
    ``elements`` (None: not given, DEFAULT_ELEMENTS) shared out by length; RodInputError
    for an ``elements`` that disagrees with counts given for every section, or too few
    to give each section without a count one, or a section meshed too coarsely to
    represent the line (check_represented)."""
    lengths = np.asarray(lengths, dtype=float)
    if given and all(c is not None for c in counts) and sum(counts) != total:
        raise RodInputError(
            f"{names['elements']} {total}: {names['sections']} gives every section "
            f"its elements, {sum(counts)} in all; drop {names['elements']} or a "
            "section's count")
    shared = np.array([c is None for c in counts])
    given_counts = int(sum(c for c in counts if c is not None))
    counts = section_elements(lengths, counts, total)
    if given and np.any(shared) and counts.sum() != total:
        raise RodInputError(
            f"{names['elements']} {total}: {names['sections']} gives {given_counts} "
            f"elements to the sections with a count and needs at least one for each of "
            f"the {int(shared.sum())} without, {int(counts.sum())} in all; give "
            f"{names['elements']} {int(counts.sum())} or more")
    check_represented(types, lengths, counts, shared, given_counts,
                      float(np.cumsum(lengths)[-1]),
                      f"{names['elements']} {total}" if given else
                      f"{names['sections']} (the default {names['elements']} {total})",
                      names)
    return counts


def section_elements(lengths, counts, total):
    """The element count of each section: its own where given, else the share of the
    ``total`` left over in proportion to its length, at least 1 each, the shares rounded
    down and the elements left given to the largest remainders (so that the counts add
    up to ``total`` whenever that leaves each section one)."""
    lengths = np.asarray(lengths, dtype=float)
    given = np.array([c is not None for c in counts])
    result = np.array([c or 0 for c in counts])
    free = ~given
    if np.any(free):
        left = max(total - result[given].sum(), int(free.sum()))
        share = lengths[free] / lengths[free].sum() * left
        whole_share = np.maximum(1, np.floor(share)).astype(int)
        spare = left - int(whole_share.sum())
        if spare > 0:
            order = np.argsort(-(share - np.floor(share)), kind="stable")[:spare]
            whole_share[order] += 1
        result[free] = whole_share
    return result


def check_represented(types, lengths, counts, shared, given_counts, length, sharing,
                      names):
    """Refuse a section whose elements (``counts`` of the sections of line types
    ``types``, ``shared`` those
    without their own count) are longer than length / MIN_LINE_ELEMENTS, saying what
    mesh is needed: the section's own count, or the element count that shares enough
    out to those without one (``sharing``: how the message names what shared them)."""
    element = lengths / counts
    coarse = np.flatnonzero(element > length / MIN_LINE_ELEMENTS)
    if not coarse.size:
        return
    k = int(coarse[0])
    name, section = types[k], lengths[k]
    what = (f"section {k + 1} ({name}, {section:g} m) has {int(counts[k])} element(s) of "
            f"{element[k]:.4g} m, longer than 1/{MIN_LINE_ELEMENTS} of the line "
            f"({length:g} m): a mesh that coarse cannot represent the line's shape")
    needed = int(np.ceil(MIN_LINE_ELEMENTS * section / length))
    if not shared[k]:
        raise RodInputError(f"{names['sections']}: {what}; give it at least {needed} "
                            f"elements ({name}:{section:g}:{needed})")
    total = given_counts + int(np.ceil(MIN_LINE_ELEMENTS * lengths[shared].sum() / length)
                               ) + int(shared.sum())
    raise RodInputError(f"{sharing}: {what}; give {names['elements']} {total} or more (or "
                        f"the section its own count, {name}:{section:g}:{needed})")


@dataclass(frozen=True)
class UniformLine:
    """A line of one ``stiffness`` (K1, K2, K3, N m^2) and ``length`` (m) under a
    piecewise-constant dead ``load`` ((m, 3) N/m) changing at ``load_breaks`` ((m - 1,)
    m), of axial stiffness ``axial_stiffness`` (EA, N; inf: inextensible) and, in a
    current, the normal drag ``drag`` (rho kg/m^3, Cd, D m; None: none), meshed with
    ``elements`` elements graded by ``grading`` (None: the mesh's default); ``mass``
    its mass per length in air, kg/m, of a system's modes with the lines' mass
    (system/body_modes.line_masses; None: not given: the load is a weight in water,
    not a mass)."""

    length: float = 1.0
    stiffness: object = (1.0, 1.0, 1.0)
    load: object = ((0.0, 0.0, 0.0),)
    load_breaks: object = ()
    axial_stiffness: float = math.inf
    drag: object = None
    elements: int = DEFAULT_ELEMENTS
    grading: float = None
    mass: float = None

    def __post_init__(self):
        real("UniformLine.length", self.length)
        optional("UniformLine.mass", self.mass, real)
        if self.mass is not None and not self.mass >= 0:
            raise RodInputError(f"UniformLine.mass {self.mass!r}: a mass per length in "
                                "air, kg/m, at least 0")
        reals("UniformLine.stiffness", self.stiffness, (3,))
        real("UniformLine.axial_stiffness", self.axial_stiffness, allow_inf=True)
        optional("UniformLine.drag", self.drag, reals, (3,))

    @property
    def load_values(self):
        """The load pieces, (m, 3), N/m."""
        return np.asarray(self.load, dtype=float).reshape(-1, 3)
