"""The numbers of each section of a line of line types (scenes/line.py), for the step
line and the result file (docs/output.md): the section's name and bounds, its largest
effective tension n.t (N) and curvature |(u1, u2)| (1/m), the smallest bend radius
1 / max curvature (m), and where they occur. A vertex at a section end counts in both
sections. Vectorised on each rank's owned vertices, combined by one allgather of
(sections x 4) numbers.
"""

import numpy as np

from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities.report import FunctionReport
from petsc_rod.quantities.riser_numbers import effective_tension
from petsc_rod.scenes.line import section_index

DATASET_UNITS = {"section": "1"}
ATTRIBUTE_UNITS = {"section_names": "text", "section_bounds": "m",
                   "section_max_tension": "N", "section_max_tension_S": "m",
                   "section_max_curvature": "1/m", "section_max_curvature_S": "m",
                   "section_min_bend_radius": "m"}


def _largest_per_section(values, S, sections):
    """(largest value, its S) per section, (k, 2), NaN for a section with no owned
    vertex: a vertex at an end counts in both sections it closes."""
    k = len(sections)
    result = np.full((k, 2), np.nan)
    starts = np.array([s.start for s in sections])
    ends = np.array([s.end for s in sections])
    inside = (S[:, None] >= starts[None, :]) & (S[:, None] <= ends[None, :])   # (n, k)
    masked = np.where(inside, values[:, None], -np.inf)
    if S.size:
        best = np.argmax(masked, axis=0)
        found = np.isfinite(masked[best, np.arange(k)])
        result[found, 0] = values[best[found]]
        result[found, 1] = S[best[found]]
    return result


def _combine(comm, local):
    """The entry with the largest value per row over the ranks' (k, 2) arrays."""
    every = np.array(comm.tompi4py().allgather(local))            # (ranks, k, 2)
    value = np.where(np.isnan(every[:, :, 0]), -np.inf, every[:, :, 0])
    pick = np.argmax(value, axis=0)
    return every[pick, np.arange(every.shape[1])]


def section_report(mesh, sections, vertex, element_ends=None):
    """A TermOutput: the dataset ``section`` (the index of each vertex's section, the
    later one at an end), the attributes of ATTRIBUTE_UNITS and a phrase per section for
    the step line. The curvature of a section is taken from its own elements' one-sided
    strains ``element_ends`` (RodProblem.end_strains: S (ne, 2), u (ne, 2, 3)),
    so that a stiff section next to a soft one is not charged with the soft one's
    curvature at their common vertex (the vertex strain is the mean of both sides); from
    the vertex strains where they are not given. Collective."""
    S = vertex["S"]
    tension = effective_tension(vertex)
    most_tension = _combine(mesh.comm, _largest_per_section(tension, S, sections))
    if element_ends is None:
        curvature_S, curvature = S, np.hypot(vertex["u"][:, 0], vertex["u"][:, 1])
        most_curved = _combine(mesh.comm, _largest_per_section(curvature, S, sections))
    else:
        ends_S, u = element_ends
        curvature = np.hypot(u[..., 0], u[..., 1])                   # (ne, 2)
        middle = ends_S.mean(axis=1)
        index = section_index(sections, middle)                      # each element's own
        local = np.full((len(sections), 2), np.nan)
        for k in np.unique(index):               # the sections (a handful), not elements
            mine = index == k
            values, where = curvature[mine].ravel(), ends_S[mine].ravel()
            best = int(np.argmax(values))
            local[k] = values[best], where[best]
        most_curved = _combine(mesh.comm, local)
    with np.errstate(divide="ignore"):
        radius = np.where(most_curved[:, 0] > 0, 1.0 / most_curved[:, 0], np.inf)
    attributes = {
        "section_names": [s.name for s in sections],
        "section_bounds": np.array([[s.start, s.end] for s in sections]),
        "section_max_tension": most_tension[:, 0], "section_max_tension_S": most_tension[:, 1],
        "section_max_curvature": most_curved[:, 0],
        "section_max_curvature_S": most_curved[:, 1], "section_min_bend_radius": radius}
    text = "; ".join(
        f"{s.name} [{s.start:.6g}, {s.end:.6g}] m: tension up to {most_tension[i, 0]:.4g} N, "
        f"bend radius down to {radius[i]:.4g} m at S = {most_curved[i, 1]:.6g} m"
        for i, s in enumerate(sections))
    return TermOutput({"section": section_index(sections, S).astype(float)}, attributes,
                      "sections: " + text)


def section_numbers(problem, vertex, sections):
    """section_report of the problem's state, with its owned elements' one-sided
    strains. Collective."""
    mesh = problem.mesh
    owned = np.arange(mesh.element_start, mesh.element_end)
    return section_report(mesh, sections, vertex, problem.end_strains(owned))


class SectionNumbers(FunctionReport):
    """The sections' numbers (section_numbers), made with the sections of a line of
    sections (problem/build.py)."""

    name, report = "section_numbers", section_numbers
    dataset_units, attribute_units = DATASET_UNITS, ATTRIBUTE_UNITS
