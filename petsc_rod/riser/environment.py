"""The sea around a riser: seabed, current, drag (made from the options by
cli/scene_options.py), the current profile file, and the checks against the scene.

z is up. The seabed is the plane z = height; the current a velocity field of z only
(uniform, or a profile of depth below the sea surface). Every quantity in SI units.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.scenes.boundary import is_held
from petsc_rod.tables import numbered_rows, read_text

# The default seabed stiffness lets the line's own weight press it this far in (m).
DEFAULT_PENETRATION = 1e-3
# The stiffest seabed accepted lets the line's mean load press it in by this fraction of
# the length: 50 times the round-off of a height (2.2e-16 L), below which the contact is
# decided by round-off and a stiffer seabed changes nothing but the conditioning of the
# vertical problem (largest_stiffness).
MIN_RELATIVE_PENETRATION = 1e-14


@dataclass(frozen=True)
class Friction:
    """Coulomb friction of the seabed (riser/friction.py, docs/riser.md §3b): the
    coefficients along the line (``axial``) and across it (``lateral``), both positive,
    1; the stick stiffness ``stiffness`` (N/m per m of line per m of slip, N/m^2) of
    the elastic-perfectly-plastic spring that stands for the stick: a grounded point
    moves up to mu R / stiffness before it slides (R its contact reaction, N/m)."""

    axial: float
    lateral: float
    stiffness: float


@dataclass(frozen=True)
class Seabed:
    """An elastic seabed, frictionless unless it has a ``friction`` (Friction): the plane z = ``height`` (m), or, with a ``shape``
    (riser/bathymetry.py: a sloping Plane or a Profile), the surface z = z_b(x, y), its
    ``height`` then z_b under the scene's origin. It pushes a line below it out along
    its unit normal N = (-g, 1) / sqrt(1 + |g|^2) (g = grad z_b) with k times the normal
    penetration per metre of line, k = ``stiffness`` (N/m per m of line per m of
    penetration, i.e. N/m^2).

    With p = (z_b(x, y) - z)_+ the vertical penetration and p cos(theta) the normal one
    (tan(theta) = |g|), the force per metre is k p cos(theta) N = k_v p (-g, 1) with
    k_v = k / (1 + |g|^2): the vertical part k_v p, the horizontal part -k_v p g (N
    tan(theta) downhill). It is minus the gradient of the energy k_v/2 p^2 per metre on
    a plane (k_v constant). On the flat seabed k_v = k and the force is k p e_z."""

    height: float
    stiffness: float
    shape: object = None
    friction: Friction = None             # None: frictionless

    @property
    def flat(self):
        """The plane z = height (no shape)."""
        return self.shape is None

    def heights(self, x, y):
        """z_b at horizontal positions (x, y), m, the shape of x."""
        if self.shape is None:
            return np.full(np.shape(x), self.height)
        return self.shape.height(x, y)

    def gradients(self, x, y):
        """grad z_b at (x, y), (shape of x) + (2,)."""
        if self.shape is None:
            return np.zeros(np.shape(x) + (2,))
        return self.shape.gradient(x, y)

    def vertical_stiffness(self, gradient):
        """k_v = k / (1 + |g|^2) (N/m^2) for gradients (..., 2)."""
        return self.stiffness / (1.0 + np.sum(np.asarray(gradient)**2, axis=-1))

    def gap(self, r):
        """z - z_b(x, y) at positions r (..., 3), m: negative below the seabed."""
        if self.shape is None:
            return r[..., 2] - self.height
        return r[..., 2] - self.shape.height(r[..., 0], r[..., 1])

    def force(self, r):
        """The seabed's force per metre on the line at positions r (n, 3), N/m, (n, 3)
        (class docstring); on the flat seabed (0, 0, k (z_b - z)_+)."""
        force = np.zeros(np.shape(r))
        if self.shape is None:
            force[:, 2] = self.stiffness * np.maximum(self.height - r[:, 2], 0.0)
            return force
        g = self.shape.gradient(r[:, 0], r[:, 1])
        push = self.vertical_stiffness(g) * np.maximum(-self.gap(r), 0.0)
        force[:, :2] = -push[:, None] * g
        force[:, 2] = push
        return force

    def reaction(self, r):
        """|force| (N/m) at positions r (n, 3): k times the normal penetration,
        k (z_b - z)_+ cos(theta)."""
        if self.shape is None:
            return self.stiffness * np.maximum(self.height - r[:, 2], 0.0)
        g = self.shape.gradient(r[:, 0], r[:, 1])
        return (self.stiffness * np.maximum(-self.gap(r), 0.0)
                / np.sqrt(1.0 + np.sum(g**2, axis=-1)))


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


def read_seabed_profile(path, largest=np.inf):
    """The rows of a seabed profile or grid file, (n, 2) 'distance height' or (n, 3)
    'x y height' (m; '#' starts a comment, commas allowed; x, y from the seabed origin,
    heights absolute): every row of the same count, at least two rows, every magnitude at
    most ``largest``; a profile's distances strictly increasing (a height for each
    distance: the profile is a function), a grid checked by ``grid_axes``.
    RodInputError otherwise, naming the line."""
    def refuse(what):
        raise RodInputError(f"-rod_seabed_profile {path}: {what}")

    rows = numbered_rows(path, "-rod_seabed_profile")
    expected = ("expected rows of 2 numbers, distance along -rod_seabed_direction from "
                "-rod_seabed_origin (m) and height (m, z up), or of 3, x, y from the "
                "seabed origin and height (a grid)")
    table = []
    for k, row in rows:
        try:
            values = [float(v) for v in row]
        except ValueError:
            refuse(f"line {k} '{' '.join(row)}': {expected}")
        if len(values) not in (2, 3) or (table and len(values) != len(table[0][1])):
            refuse(f"line {k} '{' '.join(row)}': {expected}, the same in every row")
        if not np.all(np.isfinite(values)) or np.any(np.abs(values) > largest):
            refuse(f"line {k}: a number that is not finite or above {largest:g} in "
                   "magnitude; give distances and heights in m")
        table.append((k, values))
    if len(table) < 2:
        refuse(f"needs at least 2 rows; {expected}")
    lines_of, data = [k for k, _ in table], np.array([v for _, v in table])
    if data.shape[1] == 3:
        grid_axes(data, refuse)
        return data
    steps = np.diff(data[:, 0])
    if np.any(steps <= 0):
        i = int(np.flatnonzero(steps <= 0)[0])
        refuse(f"line {lines_of[i + 1]}: distance {data[i + 1, 0]:g} m after "
               f"{data[i, 0]:g} m; the distances must increase strictly from row to row "
               "(a seabed profile is one height per distance; sort the rows and drop "
               "repeated distances)")
    return data


def grid_axes(table, refuse):
    """(xs (nx,), ys (ny,), heights (nx, ny)) of grid rows 'x y height' (n, 3) in any
    order, every x with every y exactly once, at least 2 of each; else refuse(what)."""
    xs, ys = np.unique(table[:, 0]), np.unique(table[:, 1])
    order = np.lexsort((table[:, 1], table[:, 0]))
    ordered = table[order]
    if (xs.size < 2 or ys.size < 2 or len(table) != xs.size * ys.size
            or np.any(ordered[:, 0] != np.repeat(xs, ys.size))
            or np.any(ordered[:, 1] != np.tile(ys, xs.size))):
        refuse(f"a grid's rows must hold every x with every y exactly once, at least 2 of "
               f"each (found {xs.size} x values, {ys.size} y values and {len(table)} rows; "
               f"a full grid of them has {xs.size * ys.size})")
    return xs, ys, ordered[:, 2].reshape(xs.size, ys.size)


def check_ends_above(seabed, ends, length, origin_z=0.0, option="-rod_seabed"):
    """Refuse a held end below the seabed (``ends``: (name, EndState) pairs at t = 1); an
    end on it (an anchor) is fine, to round-off of the length. Heights in the scene's
    frame; the message adds ``origin_z`` (the start's z, m) to show the options' own and
    names the flat seabed's height ``option``."""
    if seabed is None:
        return
    for name, state in ends:
        depth = -float(seabed.gap(np.asarray(state.position, dtype=float)))
        if is_held(state) and depth > 1e-12 * length:
            below = depth + state.position[2] + origin_z
            where = (f"{option} {seabed.height + origin_z:g}" if seabed.flat
                     else f"the seabed is at z = {below:.6g} m there")
            raise RodInputError(
                f"{name}: the end is held at z = {state.position[2] + origin_z:.6g} m, "
                f"{depth:.3g} m below the seabed ({where}); hold it on or above it")


def check_covered(seabed, points, what, option="-rod_seabed_profile"):
    """Refuse a seabed profile that does not reach under ``points`` (n, 3), positions in
    the scene's frame that the line must lie over (its held ends, its start's nodes):
    ``what`` names them in the message."""
    if seabed is None or seabed.flat:
        return
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    outside = ~seabed.shape.covers(points[:, 0], points[:, 1])
    if np.any(outside):
        shape = seabed.shape
        if hasattr(shape, "xs"):
            u, v = points[:, 0] - shape.origin[0], points[:, 1] - shape.origin[1]
            raise RodInputError(
                f"{option}: the grid covers x from {shape.xs[0]:g} to {shape.xs[-1]:g} m "
                f"and y from {shape.ys[0]:g} to {shape.ys[-1]:g} m from the seabed origin "
                f"but {what} lie at x from {u.min():.6g} to {u.max():.6g} m, y from "
                f"{v.min():.6g} to {v.max():.6g} m; extend the grid to cover the line's "
                "footprint")
        d = shape.along(points[:, 0], points[:, 1])
        low, high = float(d.min()), float(d.max())
        raise RodInputError(
            f"{option}: the profile's distances run from {shape.distances[0]:g} to "
            f"{shape.distances[-1]:g} m but {what} lie from {low:.6g} to {high:.6g} m along "
            "its direction from the seabed origin; extend the profile's rows to cover the "
            "line's footprint")
