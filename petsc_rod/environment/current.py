"""A steady current and the line's Morison drag coefficient (made from the options by
cli/scene_options.py): a velocity field of z only (uniform, or a profile of depth below
the sea surface). Every quantity in SI units."""

from dataclasses import dataclass

import numpy as np


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

    def height_derivative(self, z):
        """dv/dz at heights z (n,), (n, 3), 1/s: minus the slope of ``velocity`` in the
        depth, that of the rows' segment holding the depth (the deeper one at a row), 0
        beyond the first and last rows and for a uniform current."""
        depth = self.surface - np.asarray(z, dtype=float)
        out = np.zeros(depth.shape + (3,))
        if self.depths.size < 2:
            return out
        k = np.clip(np.searchsorted(self.depths, depth, side="right") - 1, 0,
                    self.depths.size - 2)
        slope = np.diff(self.velocities, axis=0) / np.diff(self.depths)[:, None]
        inside = (depth >= self.depths[0]) & (depth < self.depths[-1])
        out[inside] = -slope[k[inside]]
        return out

    def largest_drag(self):
        """c max |v|^2 (N/m): the largest drag per metre the current can exert."""
        return float(self.drag * np.max(np.sum(self.velocities**2, axis=1)))
