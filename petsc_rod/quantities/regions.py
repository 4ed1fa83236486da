"""The regions of a riser, a cable or a mooring line, and their largest effective
tension, smallest bend radius and largest bending moment (docs/riser.md §5a).

With sigma = |S - S_top| the arc length from the top (riser_numbers.top_end: the higher
held end), sigma_td that of the touchdown point (riser_numbers.touchdown; the far end when
the line does not reach the seabed) and L_s = sigma_td the suspended length:

* ``hang_off``: sigma in [0, 0.05 L_s], the top 5 % of the suspended length;
* the bends of the suspended line, from its crests and troughs: the elements where the
  slope's z component changes sign (the Hermite end slopes of each element) strictly
  above the touchdown point, an extreme dropped, with its neighbour, while it differs in
  height from that neighbour (or from the top or the touchdown point beside it) by less
  than 0.1 % of the suspended line's height span (the round-off wiggles of a flat stretch);
  each bend spans from midway to the previous point to midway to the next, in the order
  top, extremes, touchdown (or far end):
  ``sag_bend`` around the lowest trough; on a line with no trough (a catenary riser, a
  mooring line) around the touchdown point, from midway between it and the next point
  up (the top, or a crest) down to it: the lower half of a catenary's suspended length;
  ``hog_bend`` (``hog_bend_2``, ... from the top) around each crest (a lazy wave's arch);
* ``touchdown_zone``: sigma in [sigma_td - 0.05 L_s, sigma_td + 0.05 L_s];
* ``grounded``: the line beyond the touchdown point where it is in contact with the
  seabed, from sigma_td to where it leaves it (``grounded_2``, ... each later stretch in
  contact); ``free_span`` (``free_span_2``, ...) each stretch beyond the touchdown that
  is off it: a span over a seabed cliff or trench, or the line rising to an anchor held
  above the seabed. In contact means a gap z - z_b(x, y) below the contact's own scale,
  the largest penetration of the line into the seabed (its weight's on an elastic
  seabed: a grounded stretch lifted by less is resting on it); the stretches' ends are
  where the gap, linear along each element, crosses that scale.

A region that does not exist is omitted (no seabed or no touchdown: no touchdown zone,
no grounded part; no crest: no hog bend). Bounds are S intervals [a, b]; a vertex on a
bound counts in the region. Each rank finds its own elements' extremes; the few
candidates and each region's largest values are combined by allgathers of small lists.
"""

import numpy as np

from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities.line_results import bending_moment, curvature
from petsc_rod.quantities.report import FunctionReport
from petsc_rod.quantities.riser_numbers import (_at_vertex, effective_tension, top_end,
                                             touchdown)

ATTRIBUTE_UNITS = {"region_names": "text", "region_bounds": "m",
                   "region_max_tension": "N", "region_max_tension_S": "m",
                   "region_min_bend_radius": "m", "region_min_bend_radius_S": "m",
                   "region_max_bending_moment": "N m", "region_max_bending_moment_S": "m"}
# The hang-off and the half-width of the touchdown zone, of the suspended length.
END_FRACTION = 0.05
# An extreme lower than this fraction of the height span is a wiggle, not a bend.
PROMINENCE = 1e-3


def _extremes(problem):
    """[(S, z, +1 crest / -1 trough)] of this rank's elements whose end slopes' z
    components change sign, S where the linear interpolant of that component is 0 and z
    the higher (crest) or lower (trough) end height."""
    mesh = problem.mesh
    ghosted = problem.state.r.ghosted()
    left, right = mesh.element_ends(ghosted)
    z0, z1 = left[:, 0, 2], right[:, 0, 2]
    t0, t1 = left[:, 1, 2], right[:, 1, 2]
    crest = (t0 > 0) & (t1 <= 0)
    trough = (t0 < 0) & (t1 >= 0)
    found = []
    for mask, kind, pick in ((crest, 1, np.maximum), (trough, -1, np.minimum)):
        k = np.flatnonzero(mask)
        S = mesh.element_S[k] + mesh.element_h[k] * t0[k] / (t0[k] - t1[k])
        found += [(float(s), float(z), kind) for s, z in zip(S, pick(z0[k], z1[k]))]
    return found


def _pruned(points, span):
    """``points`` [(sigma, z, kind)] from the top (kind 0: the top or the last point)
    without the extremes whose height differs from a neighbour's by less than
    PROMINENCE span (an interior pair, or an interior point beside an end)."""
    points = list(points)
    while True:
        gaps = [abs(points[i + 1][1] - points[i][1]) for i in range(len(points) - 1)]
        small = [i for i, gap in enumerate(gaps) if gap < PROMINENCE * span
                 and (points[i][2] != 0 or points[i + 1][2] != 0)]
        if not small:
            return points
        i = small[0]
        drop = {j for j in (i, i + 1) if points[j][2] != 0}
        points = [p for j, p in enumerate(points) if j not in drop]


def _contact_changes(problem, seabed):
    """S (list) where the line enters or leaves contact with the environment.Seabed
    ``seabed`` on this rank's elements (module docstring: the gap, linear along each
    element, crossing the largest penetration of the whole line). Collective."""
    mesh = problem.mesh
    scale = max(0.0, -mesh.global_min(float(np.min(
        seabed.gap(problem.state.r.owned()[:, 0]), initial=np.inf))))
    r0, r1 = mesh.element_ends(problem.state.r.ghosted()[:, 0])
    g0, g1 = seabed.gap(r0) - scale, seabed.gap(r1) - scale
    k = np.flatnonzero((g0 <= 0) != (g1 <= 0))
    return (mesh.element_S[k] + mesh.element_h[k] * g0[k] / (g0[k] - g1[k])).tolist()


def _beyond_touchdown(length, td_sigma, changes):
    """[(name, (a, b) in sigma)] of the stretches from the touchdown to the far end,
    in contact (``grounded``, ``grounded_2``, ...) or not (``free_span``, ...), from
    the sigmas ``changes`` where the contact changes (those beyond td_sigma count)."""
    ends = [td_sigma] + sorted(c for c in changes if td_sigma < c < length) + [length]
    regions, counts = [], {"grounded": 0, "free_span": 0}
    for k in range(len(ends) - 1):
        kind = "grounded" if k % 2 == 0 else "free_span"
        counts[kind] += 1
        name = kind if counts[kind] == 1 else f"{kind}_{counts[kind]}"
        if ends[k + 1] > ends[k]:
            regions.append((name, (ends[k], ends[k + 1])))
    return regions


def region_bounds(length, top, extremes, top_z, td_sigma, td_z, contact_changes=()):
    """[(name, (a, b) in S)] (module docstring) from the extremes [(S, z, kind)] of the
    whole line, the top end (0 or 1) and its height, the touchdown's sigma (NaN: none)
    and height (the far end's when there is no touchdown), and the S where the line
    enters or leaves contact (_contact_changes; none: in contact from the touchdown to
    the far end)."""
    sigma = (lambda S: abs(S - top * length))
    to_S = (lambda s: top * length + (1 - 2 * top) * s)
    grounded = np.isfinite(td_sigma)
    end = td_sigma if grounded else length
    inside = [(sigma(S), z, kind) for S, z, kind in extremes if 0 < sigma(S) < end]
    points = sorted(inside)
    heights = [top_z, td_z] + [z for _, z, _ in points]
    points = _pruned([(0.0, top_z, 0)] + points + [(end, td_z, 0)],
                     max(heights) - min(heights))
    suspended = end
    regions = [("hang_off", (0.0, END_FRACTION * suspended))]

    def around(i):
        before = (points[i - 1][0] + points[i][0]) / 2
        after = (points[i][0] + points[i + 1][0]) / 2 if i + 1 < len(points) else points[i][0]
        return (before, after)

    troughs = [i for i, p in enumerate(points) if p[2] == -1]
    if troughs:
        regions.append(("sag_bend", around(min(troughs, key=lambda i: points[i][1]))))
    elif grounded:
        regions.append(("sag_bend", around(len(points) - 1)))
    crests = [i for i, p in enumerate(points) if p[2] == 1]
    regions += [("hog_bend" if k == 0 else f"hog_bend_{k + 1}", around(i))
                for k, i in enumerate(crests)]
    if grounded:
        half = END_FRACTION * suspended
        regions.append(("touchdown_zone", (max(0.0, td_sigma - half),
                                           min(length, td_sigma + half))))
        if td_sigma < length:
            regions += _beyond_touchdown(length, td_sigma,
                                         [sigma(S) for S in contact_changes])
    return [(name, tuple(sorted((to_S(a), to_S(b))))) for name, (a, b) in regions]


def _extreme_per_region(values, S, bounds, largest):
    """(extreme value, its S) per region of ``bounds`` (k, 2) over this rank's vertices,
    NaN where it has none in the region."""
    inside = (S[:, None] >= bounds[None, :, 0]) & (S[:, None] <= bounds[None, :, 1])
    sign = 1.0 if largest else -1.0
    masked = np.where(inside, sign * values[:, None], -np.inf)
    result = np.full((len(bounds), 2), np.nan)
    if S.size:
        best = np.argmax(masked, axis=0)
        found = masked[best, np.arange(len(bounds))] > -np.inf
        result[found, 0] = values[best[found]]
        result[found, 1] = S[best[found]]
    return result


def _combine(comm, local, largest):
    """The extreme entry per row over the ranks' (k, 2) arrays."""
    every = np.array(comm.tompi4py().allgather(local))            # (ranks, k, 2)
    sign = 1.0 if largest else -1.0
    value = np.where(np.isnan(every[:, :, 0]), -np.inf, sign * every[:, :, 0])
    return every[np.argmax(value, axis=0), np.arange(every.shape[1])]


def region_report(problem, vertex, seabed=None):
    """A TermOutput with the attributes of ATTRIBUTE_UNITS. Collective."""
    mesh = problem.mesh
    top = top_end(problem)
    positions = problem.state.r.owned()[:, 0, 2]
    top_z = float(_at_vertex(mesh, positions, top * mesh.n_elements))
    td_sigma, td_z = np.nan, float(_at_vertex(mesh, positions, (1 - top) * mesh.n_elements))
    changes = []
    if seabed is not None:
        changes = [S for part in mesh.comm.tompi4py().allgather(
            _contact_changes(problem, seabed.seabed)) for S in part]
        S_td, position, _ = touchdown(problem, seabed.seabed, top)
        if np.isfinite(S_td):
            td_sigma, td_z = abs(S_td - top * mesh.length), float(position[2])
    extremes = [p for part in mesh.comm.tompi4py().allgather(_extremes(problem))
                for p in part]
    named = region_bounds(mesh.length, top, extremes, top_z, td_sigma, td_z, changes)
    bounds = np.array([b for _, b in named])
    S = vertex["S"]
    comm = mesh.comm
    tension = _combine(comm, _extreme_per_region(effective_tension(vertex), S, bounds,
                                                 True), True)
    kappa = _combine(comm, _extreme_per_region(curvature(vertex), S, bounds, True), True)
    moment = _combine(comm, _extreme_per_region(bending_moment(vertex), S, bounds, True),
                      True)
    with np.errstate(divide="ignore"):
        radius = np.where(kappa[:, 0] > 0, 1.0 / kappa[:, 0], np.inf)
    return TermOutput({}, {
        "region_names": [name for name, _ in named], "region_bounds": bounds,
        "region_max_tension": tension[:, 0], "region_max_tension_S": tension[:, 1],
        "region_min_bend_radius": radius, "region_min_bend_radius_S": kappa[:, 1],
        "region_max_bending_moment": moment[:, 0],
        "region_max_bending_moment_S": moment[:, 1]})


class LineRegions(FunctionReport):
    """The regions (region_report); built for a scene with a seabed, a current or line
    types, with the riser's SeabedTerm (or None)."""

    name, report, attribute_units = "regions", region_report, ATTRIBUTE_UNITS
