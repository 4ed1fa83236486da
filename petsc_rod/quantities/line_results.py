"""Results along the line as an engineer reads them (docs/riser.md §5, docs/output.md),
from the vertex fields of one state (io/outputs.py), for every scene: vectorised on each
rank's owned vertices; the ends' numbers read from the ranks that own them.

At the vertices, (n,) each, with t = d3 / |d3| the unit tangent:

* ``curvature`` |(u1, u2)| (1/m; the signed components are ``u``), ``bend_radius``
  1 / |(u1, u2)| (m, inf where straight);
* ``bending_moment`` |(m.d1, m.d2)| (N m) and ``torque`` m.t (N m);
* ``shear`` |n - (n.t) t| (N), the force across the line;
* ``declination``: the angle of t (toward increasing S) from the upward vertical,
  acos(t_z), 0 to 180 deg (OrcaFlex's declination);

The effective tension n.t is not among them: the riser numbers (riser_numbers.py) write
it for a scene with a seabed or a current, and a file with it is drawn as a riser's
(plots.py); the CSV table has it for every scene (io/line_table.py).

Attributes: ``start_force``, ``start_moment``, ``end_force``, ``end_moment`` (3,), the
force (N) and moment (N m) the line exerts on its support at S = 0 and S = L, in the
global axes: n(0) and m(0) at the start, -n(L) and -m(L) at the end (n(S), m(S) the
force and moment the part beyond S exerts on the part before it, docs/method.md §6).
So start_force + end_force = int f dS, the applied loads (the weight, the drag, the
seabed's and attachments' forces): what the supports carry. An attachment on a held end
is carried by its support: it is added to that end's force (it is not in the line's n). At a free end they are the
applied end force and moment with the sign of a support's. And the hang-off, the higher
held end (riser_numbers.top_end): ``hang_off_S`` (m), ``hang_off_declination`` (deg, the
angle from the upward vertical of the tangent pointing away from the line: d3 at S = L,
-d3 at S = 0; 0 to 180) and ``hang_off_azimuth`` (deg, the direction of that tangent's
horizontal projection, from +x toward +y, in (-180, 180]; NaN where the tangent is
vertical to 1e-12).

The fairlead and the anchor as a mooring or riser engineer reads them: the fairlead is
the top (riser_numbers.top_end), the anchor the other end when it is held. With F the
force the line exerts on that support (start_force or end_force, global axes, N):
``fairlead_force_x``, ``_y``, ``_z`` the components of F at the top;
``fairlead_tension`` |F|; ``fairlead_horizontal`` |(F_x, F_y)| (the catenary's H, the
horizontal restoring force of a mooring line); ``fairlead_vertical`` -F_z (the weight the
top carries, positive for a hanging line: the catenary's V); ``fairlead_position`` (3,)
where it is, m, absolute. ``anchor_tension`` |F|, ``anchor_horizontal`` |(F_x, F_y)|,
``anchor_vertical`` F_z (the upward pull on the anchor, positive when it lifts the
anchor) and ``anchor_position`` (3,) of the anchor, when it is held.
"""

import numpy as np

from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities.report import FunctionReport
from petsc_rod.quantities.riser_numbers import (_at_vertex, effective_tension,
                                             points_on_held_ends, top_end, unit_tangent)
from petsc_rod.scenes.boundary import is_held

DATASET_UNITS = {"curvature": "1/m", "bend_radius": "m", "bending_moment": "N m",
                 "torque": "N m", "shear": "N", "declination": "deg"}
ATTRIBUTE_UNITS = {"start_force": "N", "start_moment": "N m", "end_force": "N",
                   "end_moment": "N m", "hang_off_S": "m", "hang_off_declination": "deg",
                   "hang_off_azimuth": "deg", "fairlead_force_x": "N",
                   "fairlead_force_y": "N", "fairlead_force_z": "N", "fairlead_tension": "N",
                   "fairlead_horizontal": "N", "fairlead_vertical": "N",
                   "fairlead_position": "m", "anchor_tension": "N", "anchor_horizontal": "N",
                   "anchor_vertical": "N", "anchor_position": "m"}
# A horizontal projection shorter than this (of a unit tangent) has no azimuth.
VERTICAL = 1e-12


def curvature(vertex):
    """|(u1, u2)| at the vertices, 1/m, (n,)."""
    return np.hypot(vertex["u"][:, 0], vertex["u"][:, 1])


def bend_radius(kappa):
    """1 / kappa, m, inf where kappa is 0."""
    with np.errstate(divide="ignore"):
        return np.where(kappa > 0, 1.0 / kappa, np.inf)


def bending_moment(vertex):
    """|(m.d1, m.d2)| at the vertices, N m, (n,)."""
    m = vertex["m"]
    return np.hypot(np.einsum("nc,nc->n", m, vertex["d1"]),
                    np.einsum("nc,nc->n", m, vertex["d2"]))


def torque(vertex):
    """m.t at the vertices, N m, (n,)."""
    return np.einsum("nc,nc->n", vertex["m"], unit_tangent(vertex))


def shear(vertex):
    """|n - (n.t) t| at the vertices, N, (n,)."""
    t = unit_tangent(vertex)
    across = vertex["n"] - effective_tension(vertex)[:, None] * t
    return np.linalg.norm(across, axis=1)


def declination(tangent):
    """The angle of the unit vectors ``tangent`` (..., 3) from the upward vertical, deg,
    0 to 180."""
    return np.degrees(np.arccos(np.clip(tangent[..., 2], -1.0, 1.0)))


def azimuth(tangent):
    """The direction of the horizontal projection of ``tangent`` (3,), deg from +x toward
    +y in (-180, 180]; NaN for a vertical tangent."""
    if np.hypot(tangent[0], tangent[1]) < VERTICAL:
        return np.nan
    angle = float(np.degrees(np.arctan2(tangent[1], tangent[0])))
    return angle + 360.0 if angle <= -180.0 else angle     # -0 in y: 180, not -180


def line_fields(vertex):
    """The datasets of DATASET_UNITS at the vertices."""
    kappa = curvature(vertex)
    return {"curvature": kappa, "bend_radius": bend_radius(kappa),
            "bending_moment": bending_moment(vertex), "torque": torque(vertex),
            "shear": shear(vertex), "declination": declination(unit_tangent(vertex))}


def end_numbers(problem, vertex):
    """The attributes of ATTRIBUTE_UNITS (module docstring). Collective."""
    mesh = problem.mesh
    last = mesh.n_elements
    n0, m0 = _at_vertex(mesh, vertex["n"], 0), _at_vertex(mesh, vertex["m"], 0)
    nL, mL = _at_vertex(mesh, vertex["n"], last), _at_vertex(mesh, vertex["m"], last)
    top = top_end(problem)
    tangent = _at_vertex(mesh, unit_tangent(vertex), top * last)
    away = tangent if top == 1 else -tangent             # out of the line at the top
    on_start, on_end = points_on_held_ends(problem)
    forces = (n0 + on_start, -nL + on_end)
    numbers = {"start_force": forces[0], "start_moment": m0, "end_force": forces[1],
               "end_moment": -mL,
               "hang_off_S": float(top * mesh.length),
               "hang_off_declination": float(declination(away)),
               "hang_off_azimuth": azimuth(away)}
    origin = problem.scene.start_position          # positions absolute (riser_numbers)
    positions = [_at_vertex(mesh, vertex["r"], index) + origin for index in (0, last)]
    fairlead = forces[top]
    numbers.update(fairlead_force_x=float(fairlead[0]), fairlead_force_y=float(fairlead[1]),
                   fairlead_force_z=float(fairlead[2]),
                   fairlead_tension=float(np.linalg.norm(fairlead)),
                   fairlead_horizontal=float(np.hypot(fairlead[0], fairlead[1])),
                   fairlead_vertical=float(-fairlead[2]), fairlead_position=positions[top])
    if is_held(problem.end_state if top == 0 else problem.start_state):
        anchor = forces[1 - top]
        numbers.update(anchor_tension=float(np.linalg.norm(anchor)),
                       anchor_horizontal=float(np.hypot(anchor[0], anchor[1])),
                       anchor_vertical=float(anchor[2]), anchor_position=positions[1 - top])
    return numbers


def line_report(problem, vertex):
    """The datasets along the line and the end numbers. Collective."""
    return TermOutput(line_fields(vertex), end_numbers(problem, vertex))


class LineResults(FunctionReport):
    """The results along the line and at its ends (line_report); built for every scene
    (problem/build.py)."""

    name, report = "line_results", line_report
    dataset_units, attribute_units = DATASET_UNITS, ATTRIBUTE_UNITS
