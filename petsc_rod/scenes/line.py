"""The numbers along S of a line of sections (model/line_type.Section: docs/riser.md,
"Line types and sections"): the scene's stiffness_at, axial_stiffness_at and drag_at,
and the reports', are read from its sections here; and the -rod_sections text.
"""

import numpy as np

from petsc_rod.errors import RodInputError


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


def parse_sections(text, option):
    """[(type name, length m, elements or None)] from 'TYPE:LENGTH[:ELEMENTS],...';
    RodInputError naming ``option`` for an entry of another form, a length that is not
    positive or a count that is not a whole number of at least 1."""
    entries = []
    for entry in text.split(","):
        parts = entry.strip().split(":")
        if len(parts) not in (2, 3) or not parts[0]:
            raise RodInputError(f"{option}: '{entry}' is not TYPE:LENGTH[:ELEMENTS]")
        try:
            length = float(parts[1])
        except ValueError:
            raise RodInputError(f"{option}: '{entry}': the length '{parts[1]}' is not a "
                                "number (m)") from None
        if not (np.isfinite(length) and length > 0):
            raise RodInputError(f"{option}: '{entry}': the length must be positive (m)")
        count = None
        if len(parts) == 3:
            try:
                count = int(parts[2])
            except ValueError:
                count = 0
            if count < 1:
                raise RodInputError(f"{option}: '{entry}': the element count '{parts[2]}' "
                                    "must be a whole number of at least 1")
        entries.append((parts[0], length, count))
    return entries
