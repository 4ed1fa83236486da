"""The sea around a riser: seabed, current, drag (made from the options by
cli/scene_options.py), the current profile file, and the checks against the scene.

z is up. The seabed is the plane z = height; the current a velocity field of z only
(uniform, or a profile of depth below the sea surface). Every quantity in SI units.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.scenes.boundary import is_held
from petsc_rod.tables import read_text

# The default seabed stiffness lets the line's own weight press it this far in (m).
DEFAULT_PENETRATION = 1e-3
# The stiffest seabed accepted lets the line's mean load press it in by this fraction of
# the length: 50 times the round-off of a height (2.2e-16 L), below which the contact is
# decided by round-off and a stiffer seabed changes nothing but the conditioning of the
# vertical problem (largest_stiffness).
MIN_RELATIVE_PENETRATION = 1e-14


@dataclass(frozen=True)
class Seabed:
    """A flat, frictionless, elastic seabed: the plane z = ``height`` (m) pushes a line
    below it up with k (height - z) per metre of line, k = ``stiffness`` (N/m per m of
    line per m of penetration, i.e. N/m^2)."""

    height: float
    stiffness: float


@dataclass(frozen=True)
class Current:
    """A steady current and the Morison drag coefficient of the line.

    ``depths`` (m,) increasing depths below the sea surface z = ``surface`` and
    ``velocities`` (m, 3) the current there (m/s), linear in between and constant
    beyond the first and last rows; a uniform current is one row. ``drag`` is
    c = rho C_d D / 2 (kg/m^2), so that the normal drag c |v_n| v_n is in N/m: made
    from the command line's inputs rho, C_d, D by ``Current.morison`` (``uniform`` for
    one velocity), as -rod_drag gives them.
    """

    depths: np.ndarray
    velocities: np.ndarray
    surface: float
    drag: float

    @classmethod
    def morison(cls, depths, velocities, surface, water_density, cd, diameter):
        """The current of ``depths`` (m,), m, ``velocities`` (m, 3), m/s, below the sea
        surface z = ``surface`` (m) on a line of Morison normal drag coefficient ``cd``
        (1) and hydrodynamic diameter ``diameter`` (m) in water of ``water_density``
        (kg/m^3): drag c = rho C_d D / 2 (kg/m^2), as -rod_drag rho,Cd,D."""
        return cls(np.asarray(depths, dtype=float).reshape(-1),
                   np.asarray(velocities, dtype=float).reshape(-1, 3), float(surface),
                   0.5 * float(water_density) * float(cd) * float(diameter))

    @classmethod
    def uniform(cls, velocity, water_density, cd, diameter, surface=0.0):
        """A uniform current ``velocity`` (3,), m/s, with the drag of ``morison``; the
        surface (m) only matters to a profile, kept for the record."""
        return cls.morison([0.0], [velocity], surface, water_density, cd, diameter)

    def velocity(self, z):
        """The current at heights z (n,), (n, 3)."""
        depth = self.surface - np.asarray(z, dtype=float)
        return np.stack([np.interp(depth, self.depths, self.velocities[:, c])
                         for c in range(3)], axis=-1)

    def largest_drag(self):
        """c max |v|^2 (N/m): the largest drag per metre the current can exert."""
        return float(self.drag * np.max(np.sum(self.velocities**2, axis=1)))


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


def read_profile(path, largest=np.inf):
    """(depths (m,), velocities (m, 3)) from a text file of rows 'depth ux uy uz' (m,
    m/s; '#' starts a comment), depths strictly increasing, every magnitude at most
    ``largest`` (the bound of the options' numbers). RodInputError otherwise."""
    def refuse(what):
        raise RodInputError(f"-rod_current_profile {path}: {what}")

    lines = read_text(path, "-rod_current_profile").splitlines()
    rows = [line.split("#", 1)[0].replace(",", " ").split() for line in lines]
    rows = [row for row in rows if row]
    try:
        table = np.array([[float(v) for v in row] for row in rows], dtype=float)
    except ValueError:
        refuse("expected rows of 4 numbers: depth (m), ux, uy, uz (m/s)")
    if table.ndim != 2 or table.shape[0] == 0 or table.shape[1] != 4:
        refuse("expected rows of 4 numbers: depth (m), ux, uy, uz (m/s)")
    if not np.all(np.isfinite(table)):
        refuse("holds a number that is not finite")
    if np.any(np.abs(table) > largest):
        row = int(np.flatnonzero(np.any(np.abs(table) > largest, axis=1))[0])
        refuse(f"row {row + 1} holds a magnitude above {largest:g}, which the solver cannot "
               "carry through products such as the drag c |v|^2; give depths in m and "
               "velocities in m/s")
    if np.any(np.diff(table[:, 0]) <= 0):
        refuse("the depths must increase strictly from row to row")
    return table[:, 0], table[:, 1:]


def check_ends_above(seabed, ends, length, origin_z=0.0):
    """Refuse a held end below the seabed (``ends``: (name, EndState) pairs at t = 1); an
    end on it (an anchor) is fine, to round-off of the length. Heights in the scene's
    frame; the message adds ``origin_z`` (the start's z, m) to show the options' own."""
    if seabed is None:
        return
    for name, state in ends:
        depth = seabed.height - state.position[2]
        if is_held(state) and depth > 1e-12 * length:
            raise RodInputError(
                f"{name}: the end is held at z = {state.position[2] + origin_z:.6g} m, "
                f"{depth:.3g} m below the seabed (-rod_seabed {seabed.height + origin_z:g}); "
                "hold it on or above it")
