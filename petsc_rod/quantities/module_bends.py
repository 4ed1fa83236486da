"""The global hog and sag bend radii of a line with discrete buoyancy modules, beside
the local kink radius at a module (docs/riser.md §9b).

A module is a point force on the line (physics/point_loads.py), so the line kinks at
each: the local bend radius 1 / |(u1, u2)| at a module is that of the kink (a point load
P on a line of tension T and bending stiffness EI turns it within a length sqrt(EI / T)),
not the radius of the arch the modules hold up, which is what a design checks. The
global radius is that of the tangent's turn over an averaging length L_a, the module
pitch (the median spacing of adjacent modules, m):

    theta(S) = angle(t(S - L_a / 2), t(S + L_a / 2)),   R_global(S) = L_a / theta(S),

t the unit tangent interpolated linearly between the vertices (and normalised), for
every vertex S whose window lies on the line. Over a circular arc of radius R kinked
every L_a, the window holds the turn of one pitch, L_a / R, wherever it sits: R. A
window turns in a sag bend where the tangent's change t(S + L_a/2) - t(S - L_a/2) points
up (the line concave upward), in a hog bend where it points down; locally the same with
the curvature vector dt/dS = u2 d1 - u1 d2 (d3' = u x d3).

Attributes: ``module_pitch`` (m, L_a), ``global_hog_bend_radius``,
``global_sag_bend_radius`` (m, the least R_global of each kind; inf where the line has no
such bend) with their window centres ``_S`` (m), and ``local_hog_bend_radius``,
``local_sag_bend_radius`` (m, the least 1 / |(u1, u2)| at the vertices of each kind)
with their ``_S``. The modules are the attachments whose force at load factor 1 points
up (a buoyancy module's lift exceeds its weight); the report is built for a scene with
two or more (problem/build.py). The tangents are gathered on every rank (a window spans
ranks; the vertex tangents are a small part of the state).
"""

import numpy as np

from petsc_rod.physics.term import TermOutput
from petsc_rod.quantities.report import Report
from petsc_rod.quantities.riser_numbers import unit_tangent

KINDS = ("hog", "sag")
ATTRIBUTE_UNITS = {"module_pitch": "m", **{
    f"{scope}_{kind}_bend_radius{tail}": "m" for scope in ("global", "local")
    for kind in KINDS for tail in ("", "_S")}}


def module_S(scene):
    """The arc lengths (m, sorted) of the attachments whose force at load factor 1
    points up: the buoyancy modules."""
    S, force = scene.point_loads(1.0)
    return np.sort(S[force[:, 2] > 0.0]) if S.size else S


def module_pitch(S):
    """The median spacing (m) of adjacent modules at ``S`` (sorted); NaN for fewer than
    two."""
    return float(np.median(np.diff(S))) if S.size > 1 else np.nan


def window_bend_radii(S, tangent, length):
    """(R_global (m), 1 up / -1 down / 0 straight, window centres (m)) over the
    windows of ``length`` centred at the vertices ``S`` (increasing, (n,)) whose window
    lies on [S[0], S[-1]], from the unit tangents ``tangent`` (n, 3) (module docstring)."""
    centres = S[(S - 0.5 * length >= S[0]) & (S + 0.5 * length <= S[-1])]

    def at(points):
        t = np.column_stack([np.interp(points, S, tangent[:, k]) for k in range(3)])
        return t / np.linalg.norm(t, axis=1, keepdims=True)

    before, after = at(centres - 0.5 * length), at(centres + 0.5 * length)
    turn = np.arctan2(np.linalg.norm(np.cross(before, after), axis=1),
                      np.einsum("nc,nc->n", before, after))
    with np.errstate(divide="ignore"):
        radius = np.where(turn > 0.0, length / turn, np.inf)
    return radius, np.sign(after[:, 2] - before[:, 2]), centres


def least_of_kinds(radius, side, S):
    """{kind: (the least radius (m) where ``side`` is +1 (sag) or -1 (hog), its S)};
    (inf, NaN) for a kind with no such point."""
    out = {}
    for kind, sign in zip(KINDS, (-1.0, 1.0)):
        mine = np.flatnonzero(side == sign)
        if mine.size == 0:
            out[kind] = (np.inf, np.nan)
        else:
            k = mine[np.argmin(radius[mine])]
            out[kind] = (float(radius[k]), float(S[k]))
    return out


def bend_numbers(S, tangent, u, d1, d2, length):
    """The attributes of ATTRIBUTE_UNITS but module_pitch from the whole line's vertex
    S (n,), unit tangents, strains u (n, >= 2) and directors d1, d2 (n, 3), over the
    averaging ``length`` (m)."""
    radius, side, centres = window_bend_radii(S, tangent, length)
    numbers = {}
    for kind, (value, where) in least_of_kinds(radius, side, centres).items():
        numbers[f"global_{kind}_bend_radius"], numbers[f"global_{kind}_bend_radius_S"] = \
            value, where
    curvature = np.hypot(u[:, 0], u[:, 1])
    bend = u[:, 1, None] * d1 - u[:, 0, None] * d2            # dt/dS
    with np.errstate(divide="ignore"):
        local = np.where(curvature > 0.0, 1.0 / curvature, np.inf)
    for kind, (value, where) in least_of_kinds(local, np.sign(bend[:, 2]), S).items():
        numbers[f"local_{kind}_bend_radius"], numbers[f"local_{kind}_bend_radius_S"] = \
            value, where
    return numbers


class ModuleBends(Report):
    """The global and local hog and sag bend radii (module docstring) of a scene with
    buoyancy modules at ``S`` (module_S, two or more)."""

    name = "module_bends"
    attribute_units = ATTRIBUTE_UNITS

    def __init__(self, S):
        self.pitch = module_pitch(S)

    def outputs(self, problem, vertex):
        comm = problem.mesh.comm.tompi4py()
        owned = np.column_stack([vertex["S"], unit_tangent(vertex), vertex["u"][:, :2],
                                 vertex["d1"], vertex["d2"]])
        every = np.concatenate(comm.allgather(owned))
        every = every[np.argsort(every[:, 0], kind="stable")]
        numbers = bend_numbers(every[:, 0], every[:, 1:4], every[:, 4:6], every[:, 6:9],
                               every[:, 9:12], self.pitch)
        numbers["module_pitch"] = self.pitch
        text = (f"over the module pitch {self.pitch:.4g} m the global hog bend radius "
                f"{numbers['global_hog_bend_radius']:.4g} m, sag "
                f"{numbers['global_sag_bend_radius']:.4g} m (the local kink "
                f"{numbers['local_hog_bend_radius']:.4g} m, "
                f"{numbers['local_sag_bend_radius']:.4g} m)")
        return TermOutput({}, numbers, text)
