"""The sea around a riser as given by the options, checked: seabed, current, drag.

z is up. The seabed is the plane z = height; the current a velocity field of z only
(uniform, or a profile of depth below the sea surface). Every quantity in SI units.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.scenes.boundary import is_held

# The default seabed stiffness lets the line's own weight press it this far in (m).
DEFAULT_PENETRATION = 1e-3


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
    c = rho C_d D / 2 (kg/m^2), so that the normal drag c |v_n| v_n is in N/m.
    """

    depths: np.ndarray
    velocities: np.ndarray
    surface: float
    drag: float

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


def seabed_from_options(values, given, load_values):
    """The Seabed of -rod_seabed and -rod_seabed_stiffness, or None."""
    if "rod_seabed" not in given:
        if "rod_seabed_stiffness" in given:
            raise RodInputError("-rod_seabed_stiffness needs -rod_seabed (the height of the "
                                "seabed plane)")
        return None
    stiffness = values["rod_seabed_stiffness"]
    if stiffness is None:
        stiffness = default_stiffness(load_values)
        if stiffness is None:
            raise RodInputError("-rod_seabed: no -rod_load points down to set the default "
                                "stiffness (weight / 1 mm); give -rod_seabed_stiffness")
    return Seabed(float(values["rod_seabed"]), float(stiffness))


def read_profile(path):
    """(depths (m,), velocities (m, 3)) from a text file of rows 'depth ux uy uz' (m,
    m/s; '#' starts a comment), depths strictly increasing. RodInputError otherwise."""
    def refuse(what):
        raise RodInputError(f"-rod_current_profile {path}: {what}")

    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            lines = handle.read().splitlines()
    except FileNotFoundError:
        refuse("no such file")
    except OSError as error:
        refuse(f"cannot be read ({error.strerror})")
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
    if np.any(np.diff(table[:, 0]) <= 0):
        refuse("the depths must increase strictly from row to row")
    return table[:, 0], table[:, 1:]


def current_from_options(values, given, surface_default):
    """The Current of -rod_current or -rod_current_profile with -rod_drag, or None.
    ``surface_default``: the sea surface height when -rod_sea_surface is not given."""
    uniform, profile = "rod_current" in given, "rod_current_profile" in given
    if uniform and profile:
        raise RodInputError("-rod_current and -rod_current_profile both give the current; "
                            "give one of them")
    if not (uniform or profile):
        for name in ("rod_drag", "rod_sea_surface"):
            if name in given:
                raise RodInputError(f"-{name} needs a current (-rod_current or "
                                    "-rod_current_profile)")
        return None
    if "rod_drag" not in given:
        raise RodInputError("a current needs -rod_drag rho,Cd,D (water density kg/m^3, drag "
                            "coefficient, hydrodynamic diameter m)")
    if "rod_sea_surface" in given and not profile:
        raise RodInputError("-rod_sea_surface needs -rod_current_profile (a uniform "
                            "current does not depend on depth)")
    if profile:
        depths, velocities = read_profile(values["rod_current_profile"])
    else:
        depths, velocities = np.zeros(1), np.asarray(values["rod_current"]).reshape(1, 3)
    surface = values["rod_sea_surface"]
    rho, cd, diameter = values["rod_drag"]
    return Current(depths, velocities, float(surface_default if surface is None else surface),
                   0.5 * rho * cd * diameter)


def check_ends_above(seabed, ends, length):
    """Refuse a held end below the seabed (``ends``: (name, EndState) pairs at t = 1); an
    end on it (an anchor) is fine, to round-off of the length."""
    if seabed is None:
        return
    for name, state in ends:
        depth = seabed.height - state.position[2]
        if is_held(state) and depth > 1e-12 * length:
            raise RodInputError(
                f"{name}: the end is held at z = {state.position[2]:.6g} m, {depth:.3g} m "
                f"below the seabed (-rod_seabed {seabed.height:g}); hold it on or above it")


def environment_from_options(values, given, scene):
    """(Seabed or None, Current or None) for a validated ``scene``, checked against it."""
    seabed = seabed_from_options(values, given, scene.load_values)
    ends = [("-rod_start", scene.start_state(t)) for t in (0.0, 1.0)]
    ends += [("-rod_end", scene.end_state(t)) for t in (0.0, 1.0)]
    check_ends_above(seabed, ends, scene.length)
    held = [state.position[2] for _, state in ends if is_held(state)]
    return seabed, current_from_options(values, given, max(held))
