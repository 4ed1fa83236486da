"""Rigid bodies' kinematics and their own loads (weight, buoyancy, hydrostatics, the
external load) for the coupled equilibrium (system/equilibrium.py); numpy only, every
function over a leading axis of bodies.

A body's pose is its reference point X (3,), m, and the rotation R (3, 3) that takes
body axes to global ones; a body-axes point p is at x = X + R p. The pose changes by a
translation dX and a small rotation dtheta (3,), rad, applied on the left,
R <- exp([dtheta]x) R, so that dx = dX + dtheta x (R p) = dX - [R p]x dtheta. Loads are
a force F (3,), N, and a moment M (3,), N m, about X, in global axes: the 6-vector
(F, M), the generalised force conjugate to (dX, dtheta).
"""

import numpy as np

from petsc_rod.model.system_check import rotation, tait_bryan_zyx

DOF_NAMES = ("x", "y", "z", "roll", "pitch", "yaw")


def skew(v):
    """[v]x, (..., 3, 3), with [v]x w = v x w."""
    v = np.asarray(v, dtype=float)
    zero = np.zeros(v.shape[:-1])
    return np.stack([np.stack([zero, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], zero, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], zero], -1)], -2)


def _series(angle, small, exact, limit, slope):
    """exact(angle) where angle >= small, else its series limit + slope angle^2 (the
    formula's cancellation below ``small``)."""
    safe = np.where(angle < small, 1.0, angle)
    return np.where(angle < small, limit + slope * angle**2, exact(safe))


def exp_rotation(theta):
    """exp([theta]x), (..., 3, 3), by Rodrigues' formula."""
    theta = np.asarray(theta, dtype=float)
    angle = np.linalg.norm(theta, axis=-1)[..., None, None]
    K = skew(theta)
    a = _series(angle, 1e-4, lambda t: np.sin(t) / t, 1.0, -1.0 / 6.0)
    b = _series(angle, 1e-4, lambda t: (1.0 - np.cos(t)) / t**2, 0.5, -1.0 / 24.0)
    return np.eye(3) + a * K + b * K @ K


def log_rotation(R):
    """theta (..., 3) with exp([theta]x) = R, |theta| < pi."""
    cos = np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0)
    angle = np.arccos(cos)
    axial = 0.5 * np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                            R[..., 1, 0] - R[..., 0, 1]], -1)
    return _series(angle, 1e-4, lambda t: t / np.sin(t), 1.0, 1.0 / 6.0)[..., None] * axial


def log_jacobian(theta):
    """d log(exp([dtheta]x) exp([theta]x)) / d dtheta at dtheta = 0, (..., 3, 3): the
    inverse left Jacobian of SO(3), I - [theta]x / 2 + c [theta]x^2 with
    c = 1/a^2 - (1 + cos a) / (2 a sin a), a = |theta|."""
    angle = np.linalg.norm(theta, axis=-1)[..., None, None]
    K = skew(theta)
    c = _series(angle, 1e-3, lambda t: 1.0 / t**2 - (1.0 + np.cos(t)) / (2 * t * np.sin(t)),
                1.0 / 12.0, 1.0 / 720.0)
    return np.eye(3) - 0.5 * K + c * K @ K


def lever_map(arms):
    """T (n, 3, 6): dx = T (dX, dtheta) of body points at arms a = R p (n, 3):
    [I, -[a]x]."""
    arms = np.asarray(arms, dtype=float).reshape(-1, 3)
    return np.concatenate([np.broadcast_to(np.eye(3), arms.shape[:1] + (3, 3)),
                           -skew(arms)], axis=-1)


def lever_stiffness(arms, forces):
    """The geometric part of d M/d dtheta, (..., 3, 3), of forces (..., k, 3) at arms
    (..., k, 3) from X that turn with the body: the moment a x F changes with the arm,
    da = dtheta x a, so dM = (dtheta x a) x F = [F]x [a]x dtheta, summed over the k
    forces. It is not symmetric: [F]x[a]x - ([F]x[a]x)^T = [F x a]x (Jacobi's
    identity), so its antisymmetric part is -[M]x / 2, M = sum a x F the forces'
    moment about X."""
    return np.einsum("...kij,...kjl->...il", skew(forces), skew(arms))


class Bodies:
    """The poses of model Bodies during the solve: X (n, 3), R (n, 3, 3), and the start
    poses X0, R0 the hydrostatic restoring is measured from; their mass, volume, cog,
    cob (body axes) and hydrostatic matrices K_h (n, 6, 6) (``hydrostatic_matrices``)."""

    def __init__(self, bodies, water_density, gravity):
        self.count = len(bodies)
        positions = np.array([b.position for b in bodies], dtype=float).reshape(-1, 6)
        self.X0, self.R0 = positions[:, :3], rotation(*positions[:, 3:].T)
        self.X, self.R = self.X0.copy(), self.R0.copy()
        self.mass = np.array([b.mass for b in bodies], dtype=float)
        self.volume = np.array([b.volume for b in bodies], dtype=float)
        self.cog = np.array([b.cog for b in bodies], dtype=float).reshape(-1, 3)
        self.cob = np.array([b.cob for b in bodies], dtype=float).reshape(-1, 3)
        self.given = np.array([b.hydrostatic is not None for b in bodies], dtype=bool)
        self.K = hydrostatic_matrices(bodies, water_density, gravity)
        self.rho, self.g = water_density, gravity

    def moved(self, steps):
        """The poses after the increments (dX, dtheta) (n, 6)."""
        other = object.__new__(Bodies)
        other.__dict__.update(self.__dict__)
        other.X = self.X + steps[:, :3]
        other.R = exp_rotation(steps[:, 3:]) @ self.R
        return other

    def placed(self, places, held):
        """The poses with the reference points' ``held`` components ((n, 3) bools) at
        ``places`` (n, 3), m, and the hydrostatic reference X0 with them (as a body
        made at that position has it); self where nothing changes."""
        if not np.any(held) or np.array_equal(self.X[held], places[held]):
            return self
        other = object.__new__(Bodies)
        other.__dict__.update(self.__dict__)
        other.X, other.X0 = self.X.copy(), self.X0.copy()
        other.X[held] = places[held]
        other.X0[held] = places[held]
        return other

    @property
    def positions(self):
        """(x, y, z, roll, pitch, yaw) (n, 6)."""
        return np.concatenate([self.X, tait_bryan_zyx(self.R)], axis=1)

    def own_loads(self, loads):
        """(loads (n, 6), d loads / d(dX, dtheta) (n, 6, 6)) of the bodies' weight at
        the cog, their buoyancy at the cob, their hydrostatic restoring -K_h (q - q0)
        (q - q0 = (X - X0, log(R R0^T)), its exact derivative K_h diag(I,
        log_jacobian)) and the external ``loads`` (n, 6) (the bodies', or a step of the
        continuation towards them). With a given ``hydrostatic`` matrix the buoyancy
        acts at the cob of the start pose, and only the weight's arm turns (the
        matrix holds the volume's restoring)."""
        n = self.count
        forces = np.zeros((n, 2, 3))
        forces[:, 0, 2] = -self.mass * self.g
        forces[:, 1, 2] = self.rho * self.volume * self.g
        buoyancy = np.where(self.given[:, None, None], self.R0, self.R)
        arms = np.stack([np.einsum("nij,nj->ni", self.R, self.cog),
                         np.einsum("nij,nj->ni", buoyancy, self.cob)], axis=1)
        theta = log_rotation(self.R @ np.swapaxes(self.R0, -1, -2))
        offsets = np.concatenate([self.X - self.X0, theta], axis=1)
        total = (np.concatenate([forces.sum(axis=1), np.cross(arms, forces).sum(axis=1)],
                                axis=1)
                 - np.einsum("nij,nj->ni", self.K, offsets) + loads)
        chain = np.broadcast_to(np.eye(6), (n, 6, 6)).copy()
        chain[:, 3:, 3:] = log_jacobian(theta)
        jacobian = -self.K @ chain
        turning = forces.copy()
        turning[self.given, 1] = 0.0
        jacobian[:, 3:, 3:] += lever_stiffness(arms, turning)
        return total, jacobian


def hydrostatic_matrices(bodies, water_density, gravity):
    """K_h (n, 6, 6) about each X: the given ``hydrostatic`` matrix, or the waterplane's
    diag(0, 0, rho g A, rho g Ixx, rho g Iyy, 0) (the volume's own restoring,
    rho g V z_b, comes from the buoyancy turning with the body)."""
    rho_g = water_density * gravity
    return np.array([np.reshape(b.hydrostatic, (6, 6)) if b.hydrostatic is not None else
                     np.diag([0.0, 0.0, rho_g * b.waterplane_area,
                              rho_g * b.waterplane_moments[0],
                              rho_g * b.waterplane_moments[1], 0.0])
                     for b in bodies], dtype=float).reshape(-1, 6, 6)
