"""A line as engineers specify it: a sequence of sections of named line types from
S = 0 (docs/riser.md, "Line types and sections").

A line type is what a data sheet gives per metre (outer diameter, mass in air, bending,
torsional and axial stiffness, drag coefficient and diameter); a section is a stretch of
the line [start, end] of one line type, whose stiffness may taper linearly along it (a
bend stiffener). The scene's numerical data along S (stiffness_at, axial_stiffness_at,
the weight pieces and the drag per metre) are read from the sections here.
"""

from dataclasses import dataclass

import numpy as np


@dataclass
class Section:
    """One section: S in [start, end] (m) of the line type ``name``.

    stiffness_start, stiffness_end: (K1, K2, K3) at its two ends, N m^2 (equal unless
    tapered); axial_stiffness: EA, N (inf: inextensible); weight: the load per metre,
    N/m, (3,) (the submerged weight along -z); drag: c = rho Cd D / 2, kg/m^2, of the
    normal Morison drag (0: none); od: outer diameter, m; mass: kg/m in air.
    """

    name: str
    start: float
    end: float
    stiffness_start: np.ndarray
    stiffness_end: np.ndarray
    axial_stiffness: float = np.inf
    weight: np.ndarray = None
    drag: float = 0.0
    od: float = np.nan
    mass: float = np.nan

    def __post_init__(self):
        self.stiffness_start = np.asarray(self.stiffness_start, dtype=float)
        self.stiffness_end = np.asarray(self.stiffness_end, dtype=float)
        self.weight = np.zeros(3) if self.weight is None else np.asarray(self.weight, float)

    def stiffness_is(self, stiffness):
        """Whether the section's stiffness is ``stiffness`` (3,) all along."""
        return bool(np.array_equal(self.stiffness_start, stiffness)
                    and np.array_equal(self.stiffness_end, stiffness))


def section_index(sections, S):
    """The index of the section holding each S (...); a section end belongs to the
    section after it, the line's end S = L to the last section."""
    ends = np.array([section.start for section in sections[1:]])
    return np.searchsorted(ends, np.asarray(S, dtype=float), side="right")


def piecewise_linear(sections, S, start_name, end_name, inside=None):
    """The (...)-shaped S mapped to (..., k): each section's value ``start_name`` at its
    start varying linearly to ``end_name`` at its end. ``inside`` (S's shape; default S)
    picks the section: at a section end, the value of the section that holds ``inside``
    (a one-sided limit)."""
    index = section_index(sections, S if inside is None else inside)
    starts = np.array([getattr(s, start_name) for s in sections], dtype=float)
    ends = np.array([getattr(s, end_name) for s in sections], dtype=float)
    lo = np.array([s.start for s in sections])
    hi = np.array([s.end for s in sections])
    fraction = np.clip((np.asarray(S, dtype=float) - lo[index]) / (hi - lo)[index], 0.0, 1.0)
    fraction = fraction[..., None] if starts.ndim > 1 else fraction
    return starts[index] + fraction * (ends[index] - starts[index])


def piecewise_constant(sections, S, name):
    """Each S (...) mapped to the value ``name`` of its section."""
    values = np.array([getattr(s, name) for s in sections], dtype=float)
    return values[section_index(sections, S)]
