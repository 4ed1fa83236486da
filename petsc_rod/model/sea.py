"""The sea a line lies in: the water and gravity, the sea surface, the seabed (flat,
a plane, a profile or a grid; its stiffness and friction) and the current (uniform or a
profile)."""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.values import optional, real, reals

WATER_DENSITY = 1025.0
GRAVITY = 9.80665

# The default seabed stiffness lets the line's own weight press it this far in (m).
DEFAULT_PENETRATION = 1e-3
# The stiffest seabed accepted lets the line's mean load press it in by this fraction of
# the length: 50 times the round-off of a height (2.2e-16 L), below which the contact is
# decided by round-off and a stiffer seabed changes nothing but the conditioning of the
# vertical problem (largest_stiffness).
MIN_RELATIVE_PENETRATION = 1e-14


def _shape(value):
    """np.shape(value), None for rows of several lengths."""
    try:
        return np.shape(value)
    except ValueError:
        return None


def _rows(owner, rows, widths, what):
    """``rows`` as a float array (n, w), w one of ``widths``; RodInputError naming
    ``owner`` and saying ``what`` they are otherwise."""
    shape = _shape(rows)
    if not (shape and len(shape) == 2 and shape[1] in widths):
        raise RodInputError(f"{owner} {rows!r}: {what}")
    return reals(owner, rows, (int(np.prod(shape)),)).reshape(shape)


@dataclass(frozen=True)
class Environment:
    """The sea: a seabed at height ``seabed`` (m; None: none; through ``seabed_origin``
    where it slopes) rising at ``seabed_slope`` degrees along ``seabed_direction`` (an
    azimuth in degrees from +x, or a horizontal vector; None: +x), or the heights of
    ``seabed_profile`` (rows distance, height along the direction, or x, y, height from
    ``seabed_origin``; in place of ``seabed``); of stiffness ``seabed_stiffness`` (N/m^2;
    None: weight / 1 mm) with Coulomb friction ``seabed_friction`` (None: none; mu, or
    (mu_axial, mu_lateral)) of stick stiffness ``seabed_friction_stiffness`` (N/m^2;
    None: a tenth of the seabed's; docs/riser.md §3b); the sea surface at height
    ``surface`` (m; None: the higher held end); a ``current``: None, a velocity (3,) in
    m/s (uniform), or a profile of rows (depth m, ux, uy, uz m/s) below the surface;
    ``water_density`` (kg/m^3) and ``gravity`` (m/s^2). Heights are absolute, z up."""

    seabed: float = None
    seabed_stiffness: float = None
    seabed_friction: object = None
    seabed_friction_stiffness: float = None
    surface: float = None
    current: object = None
    water_density: float = WATER_DENSITY
    gravity: float = GRAVITY
    seabed_slope: float = None
    seabed_direction: object = None
    seabed_origin: object = None
    seabed_profile: object = None

    def __post_init__(self):
        for name in ("seabed", "seabed_stiffness", "seabed_friction_stiffness", "surface",
                     "seabed_slope"):
            optional(f"Environment.{name}", getattr(self, name), real)
        for name in ("seabed_friction", "seabed_direction"):     # sizes: Model.check
            value = getattr(self, name)
            size = None if value is None or _shape(value) is None else np.size(value)
            optional(f"Environment.{name}", value, reals, (size,))
        optional("Environment.seabed_origin", self.seabed_origin, reals, (2,))
        real("Environment.water_density", self.water_density)
        real("Environment.gravity", self.gravity)
        if self.current is not None:
            if _shape(self.current) == (3,):
                reals("Environment.current", self.current, (3,))
            else:
                _rows("Environment.current", self.current, (4,), "a velocity (3 numbers, "
                      "m/s) or rows (depth m, ux, uy, uz m/s)")
        optional("Environment.seabed_profile", self.seabed_profile, _rows, (2, 3),
                 "rows (distance, height) or (x, y, height), m")

    @property
    def has_seabed(self):
        """Whether there is a seabed (a height or a profile)."""
        return self.seabed is not None or self.seabed_profile is not None

    def seabed_unit_direction(self):
        """The unit horizontal vector (2,) of the seabed's direction (an azimuth in
        degrees, or a vector dx,dy), default +x."""
        given = self.seabed_direction
        if given is None:
            return np.array([1.0, 0.0])
        given = np.atleast_1d(np.asarray(given, dtype=float))
        if given.size == 1:
            angle = np.radians(given[0])
            return np.array([np.cos(angle), np.sin(angle)])
        return given / float(np.hypot(*given))

    def plane_height(self, x, y):
        """The seabed's height (m) at the horizontal position (x, y), m, of a flat or
        sloping plane: z_b = seabed + tan(slope) ((x, y) - origin).e; None without a
        seabed or with a profile or grid."""
        if self.seabed is None or self.seabed_profile is not None:
            return None
        if not self.seabed_slope:
            return float(self.seabed)
        origin = np.asarray(self.seabed_origin if self.seabed_origin is not None
                            else (0.0, 0.0), dtype=float)
        along = float(np.dot(np.array([x, y], dtype=float) - origin,
                             self.seabed_unit_direction()))
        return float(self.seabed) + float(np.tan(np.radians(self.seabed_slope))) * along

    def profile(self):
        """(depths (m,), velocities (m, 3)) of a current profile, None for a uniform
        current or none."""
        rows = None if self.current is None else np.asarray(self.current, dtype=float)
        if rows is None or rows.ndim == 1:
            return None
        return rows[:, 0].copy(), rows[:, 1:].copy()

    def current_rows(self):
        """(depths (m,), velocities (m, 3)) of the current, a uniform one as one row at
        depth 0; None without a current."""
        if self.current is None:
            return None
        profile = self.profile()
        if profile is not None:
            return profile
        return np.zeros(1), np.asarray(self.current, dtype=float).reshape(1, 3)


def default_stiffness(load_values):
    """k = w / DEFAULT_PENETRATION (N/m^2), w the largest downward load per metre over
    the load pieces (N/m): the line's own weight presses the seabed in by about 1 mm.
    None when no piece points down."""
    downward = float(np.max(-np.asarray(load_values)[:, 2], initial=0.0))
    return downward / DEFAULT_PENETRATION if downward > 0 else None


def largest_stiffness(applied_force, length):
    """k_max = (F / L) / (MIN_RELATIVE_PENETRATION L), N/m^2: the seabed under which the
    mean load per metre F / L (F = Scene.applied_force, N) sinks 1e-14 L.

    Why this bound: the vertical problem's matrix adds k w_n (w_n ~ h, the Simpson
    weights) to the elastic and penalty terms, whose diagonal is at least about R / h
    with R >= F / 2 (the default penalty's tension scale); the ratio k h^2 / R then stays
    below 2 (h / L)^2 / MIN_RELATIVE_PENETRATION <= 2e14, within double precision's
    1 / eps = 4.5e15, on any mesh. A stiffer seabed would hold the line to within
    round-off of its height anyway, so nothing physical is refused.
    """
    return applied_force / length / (MIN_RELATIVE_PENETRATION * length)
