"""The shape of a seabed that is not flat (docs/riser.md §1a): a plane of given slope and
direction, or a profile of heights along a direction; its height z_b(x, y), gradient
and unit normal at given horizontal positions, vectorised (any shape of x and y).

Conventions, those of OrcaFlex's seabed data: a seabed origin p0 = (x0, y0) on the
seabed, a direction e = (cos beta, sin beta), beta the azimuth from +x toward +y
(anticlockwise seen from above), and d = (p - p0).e the distance along it.

* ``Plane``: z_b = z0 + tan(alpha) d, alpha the largest upward slope (rad; negative:
  the seabed falls along e), constant across e. gradient g = tan(alpha) e.
* ``Profile``: z_b = the linear interpolant of the rows (d_i, z_i), d_i strictly
  increasing, constant across e and beyond the first and last rows. Its gradient is
  the secant over a width delta = SMOOTHING times the closest rows' spacing,
  g = (z_b(d + delta/2) - z_b(d - delta/2)) / delta e: the segment's slope away from the
  rows, and turning linearly from one segment's to the next over delta about a row
  (and to 0 about the first and last). Why: the contact's horizontal push is lagged
  (physics/slope_load.py), and with the slope jumping at a row a node there flips between the
  two pushes from one iteration to the next and the iteration never settles
  (docs/riser.md §3a); a gradient continuous in the position gives it a fixed point.
  ``covers`` tells whether a point lies within the rows.
* ``Grid``: bilinear in each cell of a rectangular grid, its gradient the secant over
  SMOOTHING times the closest grid lines' spacing along x and along y, for the same
  reason.

The unit normal pointing up out of the seabed is (-g, 1) / sqrt(1 + |g|^2), and the
local slope atan |g|. Heights in m, in whichever frame the shape was made in
(``moved``: the same seabed in a frame whose origin is at ``offset``).
"""

from dataclasses import dataclass

import numpy as np

# The width over which a profile's or grid's slope turns at a row or grid line, of the
# closest rows' spacing (module docstring).
SMOOTHING = 0.1


def unit_normal(gradient):
    """(-g, 1) / sqrt(1 + |g|^2) of gradients (..., 2): (..., 3)."""
    g = np.asarray(gradient, dtype=float)
    normal = np.concatenate([-g, np.ones(g.shape[:-1] + (1,))], axis=-1)
    return normal / np.sqrt(1.0 + np.sum(g**2, axis=-1, keepdims=True))


@dataclass(frozen=True)
class Plane:
    """z_b = z0 + g.((x, y) - origin): ``origin`` (2,) m, ``z0`` m, ``slope_vector`` g
    (2,) = tan(alpha) e (module docstring)."""

    origin: np.ndarray
    z0: float
    slope_vector: np.ndarray

    @classmethod
    def sloping(cls, origin, z0, slope_deg, direction):
        """The plane through (origin, z0) rising at ``slope_deg`` degrees along the unit
        horizontal vector ``direction`` (2,)."""
        e = np.asarray(direction, dtype=float)
        return cls(np.asarray(origin, dtype=float), float(z0),
                   np.tan(np.radians(slope_deg)) * e)

    def height(self, x, y):
        """z_b at (x, y), m, the shape of x."""
        return (self.z0 + self.slope_vector[0] * (np.asarray(x, dtype=float) - self.origin[0])
                + self.slope_vector[1] * (np.asarray(y, dtype=float) - self.origin[1]))

    def gradient(self, x, y):
        """dz_b/d(x, y), (shape of x) + (2,)."""
        return np.broadcast_to(self.slope_vector, np.shape(x) + (2,)).copy()

    def normal(self, x, y):
        """The unit normal up out of the seabed, (shape of x) + (3,)."""
        return unit_normal(self.gradient(x, y))

    def covers(self, x, y):
        """A plane covers every point."""
        return np.ones(np.shape(x), dtype=bool)

    def moved(self, offset):
        """The same plane in the frame whose origin is at ``offset`` (3,)."""
        return Plane(self.origin - offset[:2], self.z0 - offset[2], self.slope_vector)


@dataclass(frozen=True)
class Profile:
    """z_b the linear interpolant of ``heights`` (m,) at ``distances`` (m,), strictly
    increasing, along the unit horizontal vector ``direction`` (2,) from ``origin``
    (2,) (module docstring)."""

    origin: np.ndarray
    direction: np.ndarray
    distances: np.ndarray
    heights: np.ndarray

    def along(self, x, y):
        """d = ((x, y) - origin).e, the shape of x."""
        return ((np.asarray(x, dtype=float) - self.origin[0]) * self.direction[0]
                + (np.asarray(y, dtype=float) - self.origin[1]) * self.direction[1])

    def height(self, x, y):
        return np.interp(self.along(x, y), self.distances, self.heights)

    def gradient(self, x, y):
        """The secant slope over SMOOTHING times the closest rows' spacing along e
        (module docstring), (shape of x) + (2,)."""
        return self._secant(self.along(x, y))[..., None] * self.direction

    def _half_width(self):
        """delta / 2, m: half the width SMOOTHING times the closest rows' spacing."""
        return 0.5 * SMOOTHING * np.min(np.diff(self.distances))

    def _secant(self, d):
        """g(d) = (z_b(d + delta/2) - z_b(d - delta/2)) / delta, the slope along e of
        ``gradient`` at distances d (any shape)."""
        half = self._half_width()
        return (np.interp(d + half, self.distances, self.heights)
                - np.interp(d - half, self.distances, self.heights)) / (2 * half)

    def _rise(self, d):
        """z_b'(d): the slope of the segment that holds d (the one after a row at a
        row), 0 before the first row and from the last one on, at distances d."""
        segments = np.diff(self.heights) / np.diff(self.distances)
        index = np.searchsorted(self.distances, d, side="right") - 1
        inside = (index >= 0) & (index < segments.size)
        return np.where(inside, segments[np.clip(index, 0, segments.size - 1)], 0.0)

    def slopes(self, x, y):
        """(z_b', g, g') at (x, y), each the shape of x, along e: the interpolant's own
        slope z_b'(d) (what moves a point's penetration), the secant g(d) of
        ``gradient`` (what turns its push) and g'(d) = (z_b'(d + delta/2)
        - z_b'(d - delta/2)) / delta, the secant's rate, 1/m: 0 farther than delta/2
        from every row, where g = z_b' (a line's exact stiffness on the profile,
        Seabed.profile_derivatives)."""
        d = self.along(x, y)
        half = self._half_width()
        return (self._rise(d), self._secant(d),
                (self._rise(d + half) - self._rise(d - half)) / (2 * half))

    def normal(self, x, y):
        return unit_normal(self.gradient(x, y))

    def covers(self, x, y):
        """Whether (x, y) lies within the profile's rows, d_0 <= d <= d_last."""
        d = self.along(x, y)
        return (d >= self.distances[0]) & (d <= self.distances[-1])

    def moved(self, offset):
        return Profile(self.origin - offset[:2], self.direction, self.distances,
                       self.heights - offset[2])


@dataclass(frozen=True)
class Grid:
    """z_b bilinear on a rectangular grid of heights ``heights`` (nx, ny) at ``xs`` (nx,)
    and ``ys`` (ny,), strictly increasing, measured from ``origin`` (2,) along +x and +y
    (a 3-D bathymetry: OrcaFlex's 3D seabed, Flexcom's 3D profile, on a regular grid).
    In a cell, with (s, t) in [0, 1]^2 the position's fractions,
    z_b = (1-s)(1-t) z00 + s(1-t) z10 + (1-s) t z01 + s t z11; level beyond the grid's
    edges at the nearest edge's heights; its gradient the secant of the module
    docstring (the bilinear form's own slope inside a cell away from its edges);
    ``covers`` tells whether a point lies within it."""

    origin: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    heights: np.ndarray

    def _cell(self, x, y):
        """(i, j, s, t): cell indices and fractions, clipped to the grid (level
        beyond it)."""
        u = np.asarray(x, dtype=float) - self.origin[0]
        v = np.asarray(y, dtype=float) - self.origin[1]
        i = np.clip(np.searchsorted(self.xs, u, side="right") - 1, 0, self.xs.size - 2)
        j = np.clip(np.searchsorted(self.ys, v, side="right") - 1, 0, self.ys.size - 2)
        dx, dy = self.xs[i + 1] - self.xs[i], self.ys[j + 1] - self.ys[j]
        s = np.clip((u - self.xs[i]) / dx, 0.0, 1.0)
        t = np.clip((v - self.ys[j]) / dy, 0.0, 1.0)
        return i, j, s, t

    def height(self, x, y):
        i, j, s, t = self._cell(x, y)
        z = self.heights
        return ((1 - s) * (1 - t) * z[i, j] + s * (1 - t) * z[i + 1, j]
                + (1 - s) * t * z[i, j + 1] + s * t * z[i + 1, j + 1])

    def _half_widths(self):
        """(hx, hy), m: half the widths SMOOTHING times the closest grid lines' spacing
        along x and along y."""
        return (0.5 * SMOOTHING * np.min(np.diff(self.xs)),
                0.5 * SMOOTHING * np.min(np.diff(self.ys)))

    def gradient(self, x, y):
        """The secant slopes over SMOOTHING times the closest grid lines' spacing along
        x and y (module docstring), (shape of x) + (2,)."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        hx, hy = self._half_widths()
        gx = (self.height(x + hx, y) - self.height(x - hx, y)) / (2 * hx)
        gy = (self.height(x, y + hy) - self.height(x, y - hy)) / (2 * hy)
        return np.stack([gx, gy], axis=-1)

    def _rise(self, x, y):
        """grad z_b of the bilinear interpolant, (shape of x) + (2,): in the cell that
        holds (x, y) (the one after a grid line on it),
        dz_b/dx = ((1-t)(z10 - z00) + t (z11 - z01)) / dx and
        dz_b/dy = ((1-s)(z01 - z00) + s (z11 - z10)) / dy; beyond an edge the component
        across it 0 (level there), the one along it the edge's."""
        u = np.asarray(x, dtype=float) - self.origin[0]
        v = np.asarray(y, dtype=float) - self.origin[1]
        i, j, s, t = self._cell(x, y)
        z = self.heights
        zx = (((1 - t) * (z[i + 1, j] - z[i, j]) + t * (z[i + 1, j + 1] - z[i, j + 1]))
              / (self.xs[i + 1] - self.xs[i]))
        zy = (((1 - s) * (z[i, j + 1] - z[i, j]) + s * (z[i + 1, j + 1] - z[i + 1, j]))
              / (self.ys[j + 1] - self.ys[j]))
        zx = np.where((u >= self.xs[0]) & (u < self.xs[-1]), zx, 0.0)
        zy = np.where((v >= self.ys[0]) & (v < self.ys[-1]), zy, 0.0)
        return np.stack([zx, zy], axis=-1)

    def slopes(self, x, y):
        """(grad z_b, g, Dg) at (x, y): the interpolant's own slope (..., 2) (what moves
        a point's penetration), the secant gradient g (..., 2) of ``gradient`` (what
        turns its push) and its derivative Dg_ij = dg_i/dx_j (..., 2, 2), 1/m, exact
        for the piecewise-bilinear z_b: with hx, hy the secant's half widths,
        Dg_xj = (d_j z_b(x + hx, y) - d_j z_b(x - hx, y)) / (2 hx) and
        Dg_yj = (d_j z_b(x, y + hy) - d_j z_b(x, y - hy)) / (2 hy) (a line's exact
        stiffness on the grid, Seabed.profile_derivatives). Within a cell and farther
        than hx, hy from its edges g = grad z_b and Dg is the bilinear form's own
        Hessian (0 on its diagonal)."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        hx, hy = self._half_widths()
        rate = np.stack([(self._rise(x + hx, y) - self._rise(x - hx, y)) / (2 * hx),
                         (self._rise(x, y + hy) - self._rise(x, y - hy)) / (2 * hy)],
                        axis=-2)
        return self._rise(x, y), self.gradient(x, y), rate

    def normal(self, x, y):
        return unit_normal(self.gradient(x, y))

    def covers(self, x, y):
        u = np.asarray(x, dtype=float) - self.origin[0]
        v = np.asarray(y, dtype=float) - self.origin[1]
        return ((u >= self.xs[0]) & (u <= self.xs[-1]) & (v >= self.ys[0])
                & (v <= self.ys[-1]))

    def along(self, x, y):
        """The distance from the origin along +x (the messages' measure)."""
        return np.asarray(x, dtype=float) - self.origin[0]

    def moved(self, offset):
        return Grid(self.origin - offset[:2], self.xs, self.ys, self.heights - offset[2])
