"""The numbers a riser engineer reads, from the vertex fields of one state (outputs.py):
vectorised on each rank's owned vertices and elements, combined by MPI reductions.

* effective tension n.t (N), t = d3 / |d3| the unit tangent, and the seabed reaction k (z_b - z)_+ (N/m) at the vertices
  (datasets ``effective_tension``, ``seabed_reaction``; on a seabed that is not flat the
  reaction is the normal force k (z_b - z)_+ cos(theta), environment.Seabed.reaction,
  and ``seabed_height`` z_b(x, y) under each vertex, m, absolute). With the submerged weight as the
  load, n.d3 is the effective tension of riser practice.
* the top: the held end that is higher (S = L on a tie); its tension |n| (N) and the
  angle of its tangent from the vertical (degrees);
* the touchdown point: where the line, followed from the top, first reaches the seabed
  (the gap z - z_b(x, y) changes sign between two vertices, interpolated linearly), its
  arc length and position, and its offset from the vertical plane through the ends
  (``touchdown_offset``: a current across, friction); the grounded length, the length of line below z_b; on a
  seabed profile or grid, the number of vertices beyond its rows, where it is taken
  level (``seabed_vertices_beyond``, said in the step line when not 0);
* an anchor that lifts off: where the line has no touchdown and its lower end is held
  (the anchor), ``anchor_uplift_S`` (m, that end's S), ``anchor_uplift_angle`` (deg,
  the angle above the horizontal of the tangent leaving the anchor into the line) and
  ``anchor_uplift_force`` (N, the upward part of the force the line exerts on the
  anchor, an attachment on it included: line_results.start_force / end_force), said in
  the step line and the run's final lines (an anchor resting on the seabed holds the
  line down by its own hold, not the seabed's: a gravity anchor or a pile must take it);
  ``anchor_uplift`` 1 when the anchor lifts off so, else 0 (a flag a table can show);
* the touchdown's horizontal position ``touchdown_x``, ``touchdown_y`` (m, absolute; NaN
  without a touchdown), the numbers a sweep's touchdown excursion is drawn from;
* the largest curvature |(u1, u2)| (1/m), the smallest bend radius 1 / max curvature (m),
  and where they occur.

Heights are compared in the solver's frame (origin at the start, docs/method.md §5); the
positions reported (touchdown, largest curvature) are absolute: the start position added.
"""

import numpy as np

from petsc_rod.physics.point_loads import PointLoads
from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities.report import FunctionReport
from petsc_rod.scenes.boundary import is_held

# The step line gives the touchdown's offset from the ends' plane when it is above this
# times the length (not round-off of an in-plane line).
OFFSET_SHOWN = 1e-9

# Units of the datasets and attributes this module adds to the result file.
DATASET_UNITS = {"effective_tension": "N", "seabed_reaction": "N/m", "seabed_height": "m"}
ATTRIBUTE_UNITS = {
    "top_tension": "N", "top_angle": "deg", "touchdown_S": "m", "touchdown_position": "m",
    "grounded_length": "m", "touchdown_offset": "m", "seabed_vertices_beyond": "1", "max_curvature": "1/m",
    "max_curvature_S": "m",
    "max_curvature_position": "m", "min_bend_radius": "m", "anchor_uplift_S": "m",
    "anchor_uplift_angle": "deg", "anchor_uplift_force": "N", "anchor_uplift": "1",
    "touchdown_x": "m", "touchdown_y": "m"}


def unit_tangent(vertex):
    """t = d3 / |d3| at the vertices, (n, 3): d3 = r' = (1 + eps) t on an extensible
    line (docs/method.md §12)."""
    return vertex["d3"] / np.linalg.norm(vertex["d3"], axis=1, keepdims=True)


def effective_tension(vertex):
    """n.t at the vertices, N, (n,)."""
    return np.einsum("nc,nc->n", vertex["n"], unit_tangent(vertex))


def top_end(problem):
    """0 or 1: which end is the top (the higher held end; the end S = L on a tie or when
    only that one is held)."""
    start, end = problem.start_state, problem.end_state
    if is_held(start) and (not is_held(end) or start.position[2] > end.position[2]):
        return 0
    return 1


def _at_vertex(mesh, values, index):
    """values[index] of the owned vertex ``index`` (global), on every rank. Collective."""
    local = np.zeros(np.shape(values)[1:])
    if mesh.vertex_start <= index < mesh.vertex_end:
        local = np.asarray(values[index - mesh.vertex_start], dtype=float)
    return mesh.global_sum(local)


def points_on_held_ends(problem):
    """(P at S = 0, P at S = L), N: the point loads that sit on a held end, which its
    support carries beside the line's n (PointLoads.on_held_ends). Collective."""
    on_start, on_end = np.zeros(3), np.zeros(3)
    for term in problem.terms:
        if isinstance(term, PointLoads):
            start, end = term.on_held_ends(problem.state, is_held(problem.start_state),
                                           is_held(problem.end_state))
            on_start, on_end = on_start + start, on_end + end
    return on_start, on_end


def anchor_uplift(problem, vertex, top):
    """{anchor_uplift_S, anchor_uplift_angle, anchor_uplift_force} (module docstring) of
    the held end other than the top ``top``; {} when it is not held. Collective."""
    lower = 1 - top
    if not is_held(problem.end_state if lower else problem.start_state):
        return {}
    mesh = problem.mesh
    index = lower * mesh.n_elements
    tangent = _at_vertex(mesh, unit_tangent(vertex), index) * (-1.0 if lower else 1.0)
    n = _at_vertex(mesh, vertex["n"], index)
    on_ends = points_on_held_ends(problem)
    force = -n + on_ends[1] if lower else n + on_ends[0]
    return {"anchor_uplift_S": float(lower * mesh.length),
            "anchor_uplift_angle": float(np.degrees(np.arcsin(np.clip(tangent[2], -1, 1)))),
            "anchor_uplift_force": float(force[2])}


def _extreme(mesh, key, payload, largest):
    """The payload of the rank whose ``key`` is the largest (or smallest); ``key`` None
    where a rank has no candidate. Collective (small objects only)."""
    candidates = [c for c in mesh.comm.tompi4py().allgather((key, payload)) if c[0] is not None]
    if not candidates:
        return None
    pick = max if largest else min
    return pick(candidates, key=lambda c: c[0])[1]


def touchdown(problem, seabed, top):
    """(S, position (3,), grounded length) of the touchdown point (module docstring) on
    the environment.Seabed ``seabed``; S and position NaN when the line does not reach
    it. Collective."""
    mesh = problem.mesh
    ghosted = problem.state.r.ghosted()[:, 0]
    r0, r1 = mesh.element_ends(ghosted)
    gap0, gap1 = seabed.gap(r0), seabed.gap(r1)
    S0, S1 = mesh.element_S, mesh.element_S + mesh.element_h
    # the fraction of each element below the seabed, with its heights linear in S: 1 or 0
    # when both ends are on one side, else the crossing's gap0 / (gap0 - gap1) from the
    # lower end; divided only where the ends straddle z_b (np.where would divide by the
    # zero gap0 - gap1 of an element lying flat, and warn)
    straddles = (gap0 < 0) != (gap1 < 0)
    lower_gap = np.where(gap0 < 0, gap0, gap1)
    crossing_fraction = np.divide(lower_gap, lower_gap - np.where(gap0 < 0, gap1, gap0),
                                  out=np.zeros_like(gap0), where=straddles)
    below = np.where(straddles, crossing_fraction, (gap0 < 0) & (gap1 < 0)).astype(float)
    grounded = float(mesh.global_sum(np.sum(below * mesh.element_h)))
    # toward the top: the element whose end nearer the top is off the seabed and the
    # other end on it (or the top vertex itself on it)
    near, far = (gap0, gap1) if top == 0 else (gap1, gap0)
    crossing = np.flatnonzero((near >= 0) & (far < 0))
    fraction = far[crossing] / (far[crossing] - near[crossing])     # from the far end
    if top == 0:
        S = S1[crossing] - fraction * (S1[crossing] - S0[crossing])
        position = r1[crossing] + fraction[:, None] * (r0[crossing] - r1[crossing])
    else:
        S = S0[crossing] + fraction * (S1[crossing] - S0[crossing])
        position = r0[crossing] + fraction[:, None] * (r1[crossing] - r0[crossing])
    local = (None, None)
    if S.size:
        pick = np.argmin(S) if top == 0 else np.argmax(S)
        local = (S[pick], position[pick])
    found = _extreme(mesh, local[0], local, largest=top == 1)
    end_gap = _at_vertex(mesh, seabed.gap(problem.state.r.owned()[:, 0]), top * mesh.n_elements)
    if end_gap < 0:                    # the line lies on the seabed up to the top
        found = (top * mesh.length,
                 _at_vertex(mesh, problem.state.r.owned()[:, 0], top * mesh.n_elements))
    if found is None:
        return np.nan, np.full(3, np.nan), grounded
    return float(found[0]), np.asarray(found[1], dtype=float), grounded


def plane_offset(point, start, end):
    """The signed horizontal distance (m) of ``point`` (3,) from the vertical plane
    through ``start`` and ``end`` (3,), positive to the left of start -> end seen from
    above; NaN when the two are one above the other (no plane)."""
    chord = np.asarray(end, dtype=float)[:2] - np.asarray(start, dtype=float)[:2]
    length = float(np.hypot(*chord))
    if length == 0.0:
        return np.nan
    relative = np.asarray(point, dtype=float)[:2] - np.asarray(start, dtype=float)[:2]
    return float(chord[0] * relative[1] - chord[1] * relative[0]) / length


def riser_report(problem, vertex, seabed=None):
    """The datasets, attributes and step-line text (a physics.term.TermOutput) of a riser
    scene from the vertex fields ``vertex`` (outputs.vertex_fields), with the touchdown
    on the SeabedTerm ``seabed`` if there is one. Collective."""
    mesh = problem.mesh
    z = vertex["r"][:, 2]
    tension = effective_tension(vertex)
    reaction = (seabed.seabed.reaction(vertex["r"]) if seabed is not None
                else np.zeros_like(z))
    datasets = {"effective_tension": tension, "seabed_reaction": reaction}
    if seabed is not None and not seabed.seabed.flat:
        r = vertex["r"]
        datasets["seabed_height"] = (seabed.seabed.heights(r[:, 0], r[:, 1])
                                     + problem.scene.start_position[2])
    top = top_end(problem)
    index = top * mesh.n_elements
    top_force = _at_vertex(mesh, vertex["n"], index)
    top_tangent = _at_vertex(mesh, unit_tangent(vertex), index)
    angle = float(np.degrees(np.arccos(min(1.0, abs(top_tangent[2])))))
    curvature = np.hypot(vertex["u"][:, 0], vertex["u"][:, 1])
    k = int(np.argmax(curvature)) if curvature.size else 0
    local = ((curvature[k], vertex["S"][k], vertex["r"][k]) if curvature.size
             else (None, None, None))
    kappa, kappa_S, kappa_r = _extreme(mesh, local[0], local, largest=True)
    origin = problem.scene.start_position       # positions reported absolute (§5)
    kappa_r = np.asarray(kappa_r, dtype=float) + origin
    attributes = {"top_tension": float(np.linalg.norm(top_force)), "top_angle": angle,
                  "max_curvature": float(kappa), "max_curvature_S": float(kappa_S),
                  "max_curvature_position": kappa_r,
                  "min_bend_radius": float(1.0 / kappa) if kappa > 0 else np.inf}
    text = (f"top tension {attributes['top_tension']:.6g} N at {angle:.3f} deg from the "
            f"vertical")
    if seabed is not None:
        S, position, grounded = touchdown(problem, seabed.seabed, top)
        offset = plane_offset(position, problem.start_state.position,
                              problem.end_state.position)
        position = position + origin
        attributes.update(touchdown_S=S, touchdown_position=position, grounded_length=grounded,
                          touchdown_offset=offset, touchdown_x=float(position[0]),
                          touchdown_y=float(position[1]))
        text += (f", touchdown at S = {S:.6g} m (x, y, z = "
                 + ", ".join(f"{v:.6g}" for v in position) + f"), grounded {grounded:.6g} m")
        uplift = anchor_uplift(problem, vertex, top) if np.isnan(S) else {}
        attributes["anchor_uplift"] = int(bool(uplift))
        if uplift:
            attributes.update(uplift)
            text += (f", the anchor at S = {uplift['anchor_uplift_S']:.6g} m lifts off at "
                     f"{uplift['anchor_uplift_angle']:.4g} deg above the horizontal, "
                     f"pulled up by {uplift['anchor_uplift_force']:.6g} N")
        if abs(offset) > OFFSET_SHOWN * mesh.length:
            text += f", {offset:.6g} m off the ends' plane"
        if not seabed.seabed.flat:       # a profile or grid taken level beyond its rows
            r = vertex["r"]
            beyond = int(mesh.global_sum(int(np.sum(~seabed.seabed.shape.covers(r[:, 0],
                                                                                r[:, 1])))))
            attributes["seabed_vertices_beyond"] = beyond
            if beyond:
                text += (f", {beyond} vertices beyond the seabed profile's rows (taken level "
                         "there: extend -rod_seabed_profile)")
    text += (f", largest curvature {kappa:.4g} 1/m (bend radius "
             f"{attributes['min_bend_radius']:.4g} m) at S = {kappa_S:.6g} m")
    return TermOutput(datasets, attributes, text)


class RiserNumbers(FunctionReport):
    """The riser numbers (riser_report): built for every scene with a seabed or a
    current, with the SeabedTerm (physics/seabed.py) or None."""

    name, report = "riser_numbers", riser_report
    dataset_units, attribute_units = DATASET_UNITS, ATTRIBUTE_UNITS
