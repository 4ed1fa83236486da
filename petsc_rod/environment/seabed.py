"""The seabed under a line (made from the options by cli/scene_options.py): its
elastic law, its friction, its stiffness bounds and the checks against the scene.

z is up. The seabed is the plane z = height, or a shape (bathymetry.py). Every quantity
in SI units.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
# the seabed's default and largest stiffness are the model's (its checks use them)
from petsc_rod.model.sea import (DEFAULT_PENETRATION, MIN_RELATIVE_PENETRATION,  # noqa: F401
                                 default_stiffness, largest_stiffness)
from petsc_rod.scenes.boundary import is_held


@dataclass(frozen=True)
class Friction:
    """Coulomb friction of the seabed (physics/friction.py, docs/riser.md §3b): the
    coefficients along the line (``axial``) and across it (``lateral``), both positive,
    1; the stick stiffness ``stiffness`` (N/m per m of line per m of slip, N/m^2) of
    the elastic-perfectly-plastic spring that stands for the stick: a grounded point
    moves up to mu R / stiffness before it slides (R its contact reaction, N/m)."""

    axial: float
    lateral: float
    stiffness: float


@dataclass(frozen=True)
class Seabed:
    """An elastic seabed, frictionless unless it has a ``friction`` (Friction): the
    plane z = ``height`` (m), or, with a ``shape`` (environment/bathymetry.py: a
    sloping Plane, a Profile or a Grid), the surface z = z_b(x, y), its
    ``height`` then z_b under the scene's origin. It pushes a line below it out along
    its unit normal N = (-g, 1) / sqrt(1 + |g|^2) (g = grad z_b) with k times the normal
    penetration per metre of line, k = ``stiffness`` (N/m per m of line per m of
    penetration, i.e. N/m^2).

    With p = (z_b(x, y) - z)_+ the vertical penetration and p cos(theta) the normal one
    (tan(theta) = |g|), the force per metre is k p cos(theta) N = k_v p (-g, 1) with
    k_v = k / (1 + |g|^2): the vertical part k_v p, the horizontal part -k_v p g (N
    tan(theta) downhill). It is minus the gradient of the energy k_v/2 p^2 per metre on
    a plane (k_v constant). On the flat seabed k_v = k and the force is k p e_z.

    The contact law is written here once (penetration, push, normal_force,
    slope_factor, in_contact, height_derivatives, energy) and read by the seabed's term
    (physics/seabed.py), its active-set solve in the global step
    (global_step/seabed_contact.py, at the z_b and k_v it lags), its friction
    (physics/friction.py), its slope load (physics/slope_load.py) and the reports
    (force, reaction)."""

    height: float
    stiffness: float
    shape: object = None
    friction: Friction = None             # None: frictionless

    @property
    def flat(self):
        """The plane z = height (no shape)."""
        return self.shape is None

    @property
    def plane(self):
        """A sloping plane (bathymetry.Plane): one normal everywhere, so its energy is
        a quadratic of the normal penetration with a constant Hessian on the contact
        (position_derivatives)."""
        return self.shape is not None and hasattr(self.shape, "slope_vector")

    @property
    def shaped(self):
        """A profile or a grid of heights (bathymetry.Profile, bathymetry.Grid), whose
        slope turns: its contact's linearisation is profile_derivatives'."""
        return (not self.flat and not self.plane
                and hasattr(self.shape, "slopes"))

    @property
    def along_direction(self):
        """A profile (heights along a direction e), not a grid: its secant gradient
        turns along e alone (plan_slopes)."""
        return self.shaped and hasattr(self.shape, "direction")

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

    # --- the contact law (class docstring) -------------------------------------------
    def penetration(self, z, base=None):
        """p = (z_b - z)_+ (m), the vertical penetration of heights z under the seabed
        heights ``base`` (z_b, m, broadcast with z; default the flat seabed's height)."""
        return np.maximum((self.height if base is None else base) - z, 0.0)

    def in_contact(self, z, base=None):
        """Whether heights z lie below the seabed heights ``base`` (default the flat
        seabed's height): the nodes where the law's spring acts (p > 0)."""
        return z < (self.height if base is None else base)

    def push(self, z, base=None, stiffness=None):
        """k_v p (N/m): the vertical part of the seabed's force per metre at heights z
        under ``base`` (penetration), with the vertical stiffness ``stiffness`` (k_v,
        N/m^2, vertical_stiffness; default k, the flat seabed's)."""
        k_v = self.stiffness if stiffness is None else stiffness
        return k_v * self.penetration(z, base)

    def slope_factor(self, gradient):
        """sqrt(1 + |g|^2) = 1 / cos(theta) for gradients (..., 2): the normal force per
        metre is k_v p sqrt(1 + |g|^2) = k p cos(theta)."""
        return np.sqrt(1.0 + np.sum(gradient**2, axis=-1))

    @staticmethod
    def normal_force(push, gradient):
        """k_v p (-g, 1) (N/m), (..., 3): the force along the seabed's normal from its
        vertical part ``push`` (...,) (push) and the gradients g (..., 2)."""
        return np.concatenate([-push[..., None] * gradient, push[..., None]], axis=-1)

    def height_derivatives(self, z, weights):
        """(dE/dz_n, d2E/dz_n^2) of E = k/2 sum_n w_n (z_b - z_n)_+^2 on the flat seabed at
        the node heights z (n,) with weights w_n (n,), m: -k w_n (z_b - z_n)_+ (N) and
        k w_n [z_n < z_b] (N/m)."""
        gap = self.height - z
        spring = self.stiffness * weights * (gap > 0)
        return -spring * gap, spring

    def position_derivatives(self, r, weights):
        """(dE/dr_n, d2E/dr_n^2) of E = k/2 sum_n w_n (N.(r_b - r_n))_+^2 on a sloping plane
        (plane) at node positions r (n, 3) with weights w_n (n,), m; N the unit normal
        (-g, 1) / sqrt(1 + |g|^2) and N.(r_b - r_n) = (z_b(x_n, y_n) - z_n) cos(theta)
        the normal penetration d_n: -k w_n d_n N (N, (n, 3)) and k w_n N N^T on the
        nodes with d_n > 0 (N/m, (n, 3, 3)). The flat seabed's height_derivatives with
        N = e_z; the energy is energy()'s, k_v/2 p^2 = k/2 d^2."""
        g = self.shape.gradient(r[:, 0], r[:, 1])
        normal = self.shape.normal(r[:, 0], r[:, 1])
        depth = (self.shape.height(r[:, 0], r[:, 1]) - r[:, 2]) / self.slope_factor(g)
        spring = self.stiffness * weights * (depth > 0)
        return ((-spring * depth)[:, None] * normal,
                spring[:, None, None] * normal[:, :, None] * normal[:, None, :])

    def plan_slopes(self, x, y):
        """(grad z_b, g, Dg) of a profile or grid at (x, y) (n,), in the plan: the
        interpolant's own slope (n, 2), the secant gradient (n, 2) and its derivative
        dg_i/dx_j (n, 2, 2), 1/m (bathymetry.Grid.slopes); a profile's slopes along its
        direction e (Profile.slopes: z_b', g, g') as z_b' e, g e and g' e e^T."""
        slopes = self.shape.slopes(x, y)
        if not self.along_direction:
            return slopes
        rise, g, rate = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in slopes))
        e = self.shape.direction
        return rise[:, None] * e, g[:, None] * e, rate[:, None, None] * np.outer(e, e)

    def profile_derivatives(self, r, weights):
        """(G, B) of a profile or grid (bathymetry.Profile, Grid) at node positions r
        (n, 3) with weights w_n (n,), m: G_n = -w_n f_n, the share of the gradient of the
        force f_n = k_v p_n (-g_n, 1) (force; p_n = (z_b(x_n, y_n) - z_n)_+, g_n the
        secant gradient (2,), k_v = k / (1 + |g_n|^2): the force of the line's lagged
        iteration at its fixed point, physics/slope_load.py), N, (n, 3); and
        B_n = dG_n/dr_n, N/m, (n, 3, 3), rows G's components, columns the position's.
        With a = (g, -1), grad z_b the interpolant's own slope and Dg = dg/d(x, y)
        (plan_slopes), G_n = w_n k_v p a and dp/dr = (grad z_b, -1),
        dk_v/dr = (Dg^T dk_v/dg, 0), dk_v/dg = -2 g k_v^2 / k, da/dr = [[Dg, 0], [0, 0]]:

            B_n = w_n [a (k_v (grad z_b, -1) + p (Dg^T dk_v/dg, 0))^T
                       + k_v p [[Dg, 0], [0, 0]]]

        on the nodes with p_n > 0 (a profile's Dg = g' e e^T). Not symmetric where
        g != grad z_b (within delta/2 of a row or grid line); farther from them on a
        profile Dg = 0 and B_n = k w_n N N^T, a plane's (position_derivatives) with the
        node's own normal."""
        x, y = r[:, 0], r[:, 1]
        rise, g, rate = self.plan_slopes(x, y)
        p = self.penetration(r[:, 2], self.shape.height(x, y))
        k_v = self.vertical_stiffness(g)
        e_z = np.array([0.0, 0.0, 1.0])
        a = np.append(g, np.zeros((g.shape[0], 1)), axis=1) - e_z
        turn = np.einsum("nij,ni->nj", rate, (-2.0 * k_v**2 / self.stiffness)[:, None] * g)
        moved = (k_v[:, None] * (np.append(rise, np.zeros((g.shape[0], 1)), axis=1) - e_z)
                 + np.append(p[:, None] * turn, np.zeros((g.shape[0], 1)), axis=1))
        block = a[:, :, None] * moved[:, None, :]
        block[:, :2, :2] += (k_v * p)[:, None, None] * rate
        spring = weights * (p > 0)
        return ((weights * k_v * p)[:, None] * a, spring[:, None, None] * block)

    def energy(self, r, weights):
        """sum_n w_n k_v,n / 2 p_n^2 (J) at node positions r (n, 3) with weights w_n (n,),
        m, z_b and k_v under each node (this rank's part of the energy)."""
        p = self.penetration(r[:, 2], self.heights(r[:, 0], r[:, 1]))
        stiffness = self.vertical_stiffness(self.gradients(r[:, 0], r[:, 1]))
        return 0.5 * np.sum(stiffness * weights * p**2)

    def force(self, r):
        """The seabed's force per metre on the line at positions r (n, 3), N/m, (n, 3)
        (class docstring); on the flat seabed (0, 0, k (z_b - z)_+)."""
        if self.shape is None:
            force = np.zeros(np.shape(r))
            force[:, 2] = self.push(r[:, 2])
            return force
        g = self.shape.gradient(r[:, 0], r[:, 1])
        return self.normal_force(self.push(r[:, 2], self.shape.height(r[:, 0], r[:, 1]),
                                           self.vertical_stiffness(g)), g)

    def reaction(self, r):
        """|force| (N/m) at positions r (n, 3): k times the normal penetration,
        k (z_b - z)_+ cos(theta)."""
        if self.shape is None:
            return self.push(r[:, 2])
        g = self.shape.gradient(r[:, 0], r[:, 1])
        return (self.push(r[:, 2], self.shape.height(r[:, 0], r[:, 1]))
                / self.slope_factor(g))


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
