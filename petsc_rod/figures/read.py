"""A result file (docs/output.md) read into a ``Result``: what the figures draw, with
the derived quantities along the line (along.py) computed once."""

import os
from dataclasses import dataclass, field

import h5py
import numpy as np

from petsc_rod.figures import along


@dataclass
class Result:
    """One result file, in SI units, vertex arrays of shape (n,) or (n, 3)."""
    path: str
    name: str                   # the file's name without folder and .h5
    converged: bool
    stop_reason: str
    S: np.ndarray
    r: np.ndarray
    u: np.ndarray
    riser: bool                 # a seabed, a current, line types or attachments
    tension: np.ndarray         # effective tension n.t, N
    wall_tension: np.ndarray = None      # N, on a line of line types
    utilisation: np.ndarray = None       # von Mises over the allowable, on a line of
                                         # line types with a yield stress
    seabed_reaction: np.ndarray = None   # N/m, with a seabed
    bending_moment: np.ndarray = None    # |(m.d1, m.d2)|, N m
    curvature: np.ndarray = None         # (n, 2): in the vertical plane (+ sag), lateral
    seabed: float = None        # height of the seabed, m
    seabed_height: np.ndarray = None     # z_b under each vertex, m: a seabed not flat
    sea_surface: float = None   # height of the sea surface, m
    anchor: int = 0             # vertex index of the lower held end
    top: int = -1               # vertex index of the higher held end (the hang-off)
    touchdown_S: float = None
    touchdown_position: np.ndarray = None
    top_tension: float = None
    top_angle: float = None
    min_bend_radius: float = None
    min_bend_radius_S: float = None
    sections: list = field(default_factory=list)     # [(name, lo, hi)]
    attachments: list = field(default_factory=list)  # [(name, S, position (3,))]
    current: np.ndarray = None  # the current at the surface, m/s (3,)
    joints: list = field(default_factory=list)       # [(end, angle deg, moment N m)]


def text(value):
    """An HDF5 string attribute as str."""
    return value.decode() if isinstance(value, bytes) else str(value)


def number(attrs, key):
    """A float attribute, or None where it is absent, empty text or NaN."""
    if key not in attrs or isinstance(attrs[key], (str, bytes)):
        return None
    value = float(np.asarray(attrs[key]).ravel()[0])
    return value if np.isfinite(value) else None


def vector(attrs, key):
    """A (3,) attribute, or None where it is absent or empty text."""
    if key not in attrs or isinstance(attrs[key], (str, bytes)):
        return None
    return np.asarray(attrs[key], dtype=float)


def read_result(path, group=None):
    """The ``Result`` of result file ``path``, or of its ``group`` holding what a
    single line's file holds (a system's ``lines/<name>``, docs/output.md: named
    ``FILE: name``)."""
    with h5py.File(path, "r") as root:
        f = root[group] if group else root
        a = f.attrs
        p = f["parameters"].attrs if "parameters" in f else {}
        S, r, u = f["S"][:], f["r"][:], f["u"][:]
        d1, d2, d3 = f["d1"][:], f["d2"][:], f["d3"][:]
        optional = {name: f[name][:] for name in ("effective_tension", "wall_tension",
                                                   "seabed_reaction", "bending_moment",
                                                   "seabed_height", "utilisation")
                    if name in f}
        m, n = f["m"][:], f["n"][:]
        result = Result(
            path=str(path), name=os.path.basename(str(path)).removesuffix(".h5")
            + (f": {group.rsplit('/', 1)[-1]}" if group else ""),
            converged=bool(int(a["converged"])), stop_reason=text(a.get("stop_reason", "")),
            S=S, r=r, u=u,
            riser=("effective_tension" in f or "section_names" in a
                   or "point_load_S" in a),
            tension=optional.get("effective_tension", along.tension(n, d3)),
            wall_tension=optional.get("wall_tension"),
            utilisation=optional.get("utilisation"),
            seabed_reaction=optional.get("seabed_reaction"),
            bending_moment=optional.get("bending_moment", along.bending_moment(m, d1, d2)),
            curvature=along.curvature_components(u, d1, d2, d3),
            seabed=number(p, "seabed"), seabed_height=optional.get("seabed_height"),
            top_tension=number(a, "top_tension"), top_angle=number(a, "top_angle"),
            touchdown_S=number(a, "touchdown_S"),
            touchdown_position=vector(a, "touchdown_position"),
            min_bend_radius=number(a, "min_bend_radius"),
            min_bend_radius_S=number(a, "max_curvature_S"),
            current=surface_current(p))
        if result.touchdown_S is None:
            result.touchdown_position = None
        result.anchor, result.top = along.ends(r)
        result.joints = [(end, float(a[f"{end}_joint_angle"]), float(a[f"{end}_joint_moment"]))
                         for end in ("start", "end") if f"{end}_joint_angle" in a]
        sea = number(p, "sea_surface")
        result.sea_surface = sea if sea is not None else float(r[result.top, 2])
        if "section_names" in a:
            names = [text(name) for name in a["section_names"]]
            result.sections = [(name, float(lo), float(hi))
                               for name, (lo, hi) in zip(names, a["section_bounds"][:])]
        elif "load_breaks" in p:
            result.sections = load_pieces(p, float(S[-1]))
        if "point_load_S" in a:
            points = np.atleast_1d(a["point_load_S"][:])
            labels = text(a.get("point_load_names", "")).split(",")
            positions = np.reshape(a["point_load_position"][:], (-1, 3))
            result.attachments = [(labels[k] if k < len(labels) and labels[k] else f"P{k + 1}",
                                   float(points[k]), positions[k]) for k in range(len(points))]
    return result


def surface_current(parameters):
    """The current at the surface from the file's parameters (uniform, or the profile's
    first row), or None without a current."""
    current = vector(parameters, "current")
    if current is not None and current.size == 3 and np.any(current):
        return current
    if "current_profile_table" in parameters:
        table = np.asarray(parameters["current_profile_table"], dtype=float)
        if table.ndim == 2 and table.shape[1] >= 4:
            return table[np.argmin(table[:, 0]), 1:4]
    return None


def load_pieces(parameters, length):
    """A line given by load pieces (-rod_load, -rod_load_breaks) rather than line types:
    [(name, lo, hi)] a piece, named by its load, so that pieces of one load share a
    colour; [] for one piece."""
    breaks = parameters["load_breaks"]
    if isinstance(breaks, (str, bytes)) or np.size(breaks) == 0:
        return []
    loads = np.reshape(np.asarray(parameters["load"], dtype=float), (-1, 3))
    bounds = np.concatenate([[0.0], np.ravel(breaks), [length]])
    if len(loads) != len(bounds) - 1:
        return []
    return [(f"load fz = {fz:.4g} N/m", float(lo), float(hi))
            for (_, _, fz), lo, hi in zip(loads, bounds[:-1], bounds[1:])]
