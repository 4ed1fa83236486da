"""A rigid body's kinematics and its own loads (weight, buoyancy, hydrostatics, the
external load) for the coupled equilibrium (system/equilibrium.py); numpy only.

A body's pose is its reference point X (3,), m, and the rotation R (3, 3) that takes
body axes to global ones; a body-axes point p is at x = X + R p. The pose changes by a
translation dX and a small rotation dtheta (3,), rad, applied on the left,
R <- exp([dtheta]x) R, so that dx = dX + dtheta x (R p) = dX - [R p]x dtheta. Loads are
a force F (3,), N, and a moment M (3,), N m, about X, in global axes: the 6-vector
(F, M), the generalised force conjugate to (dX, dtheta).
"""

import numpy as np

DOF_NAMES = ("x", "y", "z", "roll", "pitch", "yaw")


def skew(v):
    """[v]x, (..., 3, 3), with [v]x w = v x w."""
    v = np.asarray(v, dtype=float)
    zero = np.zeros(v.shape[:-1])
    return np.stack([np.stack([zero, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], zero, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], zero], -1)], -2)


def rotation(roll, pitch, yaw):
    """R = R_z(yaw) R_y(pitch) R_x(roll), (3, 3) (model/system.Body's convention)."""
    cr, sr, cp, sp, cy, sy = (np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                              np.cos(yaw), np.sin(yaw))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def angles(R):
    """(roll, pitch, yaw), rad, of R = R_z(yaw) R_y(pitch) R_x(roll) (pitch in
    [-pi/2, pi/2])."""
    pitch = np.arcsin(np.clip(-R[2, 0], -1.0, 1.0))
    return np.array([np.arctan2(R[2, 1], R[2, 2]), pitch, np.arctan2(R[1, 0], R[0, 0])])


def exp_rotation(theta):
    """exp([theta]x), (3, 3), by Rodrigues' formula."""
    theta = np.asarray(theta, dtype=float)
    angle = np.linalg.norm(theta)
    K = skew(theta)
    if angle < 1e-8:                        # the series to second order, exact to ~1e-24
        return np.eye(3) + K + 0.5 * K @ K
    return (np.eye(3) + np.sin(angle) / angle * K
            + (1.0 - np.cos(angle)) / angle**2 * K @ K)


def log_rotation(R):
    """theta (3,) with exp([theta]x) = R, |theta| < pi."""
    cos = np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0)
    angle = np.arccos(cos)
    axial = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-8:
        return axial
    return angle / np.sin(angle) * axial


def log_jacobian(theta):
    """d log(exp([dtheta]x) exp([theta]x)) / d dtheta at dtheta = 0, (3, 3): the
    inverse left Jacobian of SO(3), I - [theta]x / 2 + c [theta]x^2 with
    c = 1/a^2 - (1 + cos a) / (2 a sin a), a = |theta|."""
    angle = np.linalg.norm(theta)
    K = skew(theta)
    c = (1.0 / 12.0 if angle < 1e-4 else
         1.0 / angle**2 - (1.0 + np.cos(angle)) / (2.0 * angle * np.sin(angle)))
    return np.eye(3) - 0.5 * K + c * K @ K


def lever_map(arms):
    """T (n, 3, 6): dx = T (dX, dtheta) of body points at arms a = R p (n, 3):
    [I, -[a]x]."""
    arms = np.asarray(arms, dtype=float).reshape(-1, 3)
    return np.concatenate([np.broadcast_to(np.eye(3), arms.shape[:1] + (3, 3)),
                           -skew(arms)], axis=-1)


def point_loads(arms, forces):
    """The 6-vector (sum F, sum a x F) of forces (n, 3) at arms (n, 3) from X."""
    arms = np.asarray(arms, dtype=float).reshape(-1, 3)
    forces = np.asarray(forces, dtype=float).reshape(-1, 3)
    return np.concatenate([forces.sum(axis=0), np.cross(arms, forces).sum(axis=0)])


def lever_stiffness(arms, forces):
    """The geometric part of d(F, M)/d(dX, dtheta), (6, 6), of forces (n, 3) at arms
    (n, 3) that turn with the body: the moment a x F changes with the arm,
    da = dtheta x a, so d M = (dtheta x a) x F = [F]x [a]x dtheta (the rotational
    block, summed over the forces; zero elsewhere). It is not symmetric:
    [F]x[a]x - ([F]x[a]x)^T = [F x a]x (Jacobi's identity), so the summed block's
    antisymmetric part is -[M]x / 2, M = sum a x F the forces' moment about X."""
    arms = np.asarray(arms, dtype=float).reshape(-1, 3)
    forces = np.asarray(forces, dtype=float).reshape(-1, 3)
    block = np.zeros((6, 6))
    block[3:, 3:] = np.einsum("nij,njk->ik", skew(forces), skew(arms))
    return block


class BodyPose:
    """The pose of a model Body during the solve: X (3,), R (3, 3), and the start pose
    X0, R0 the hydrostatic restoring is measured from."""

    def __init__(self, body):
        self.body = body
        self.X0 = np.asarray(body.position[:3], dtype=float)
        self.R0 = rotation(*body.position[3:])
        self.X, self.R = self.X0.copy(), self.R0.copy()
        self.free = ~np.asarray(body.held, dtype=bool)

    def copy(self):
        other = BodyPose(self.body)
        other.X, other.R = self.X.copy(), self.R.copy()
        return other

    def moved(self, step):
        """The pose after the increment (dX, dtheta) (6,)."""
        other = self.copy()
        other.X = self.X + step[:3]
        other.R = exp_rotation(step[3:]) @ self.R
        return other

    @property
    def position(self):
        """(x, y, z, roll, pitch, yaw) (6,)."""
        return np.concatenate([self.X, angles(self.R)])

    def hydrostatic_matrix(self, water_density, gravity):
        """K_h (6, 6) about X: the given ``hydrostatic`` matrix, or the waterplane's
        diag(0, 0, rho g A, rho g Ixx, rho g Iyy, 0) (the volume's own restoring,
        rho g V z_b, comes from the buoyancy turning with the body)."""
        body = self.body
        if body.hydrostatic is not None:
            return np.asarray(body.hydrostatic, dtype=float).reshape(6, 6)
        rho_g = water_density * gravity
        Ixx, Iyy = body.waterplane_moments
        return np.diag([0.0, 0.0, rho_g * body.waterplane_area, rho_g * Ixx, rho_g * Iyy,
                        0.0])

    def own_loads(self, water_density, gravity, load):
        """(loads (6,), d loads / d(dX, dtheta) (6, 6)) of the body's weight at the cog,
        its buoyancy at the cob, its hydrostatic restoring -K_h (q - q0) (q - q0 = (X -
        X0, log(R R0^T)), its exact derivative K_h diag(I, log_jacobian)) and the
        external ``load`` (6,) (the body's, or a step of the continuation towards it). With a given ``hydrostatic`` matrix the
        buoyancy acts at the cob of the start pose (its restoring is in the matrix)."""
        body = self.body
        weight = np.array([0.0, 0.0, -body.mass * gravity])
        lift = np.array([0.0, 0.0, water_density * body.volume * gravity])
        cob = self.R0 if body.hydrostatic is not None else self.R
        arms = np.stack([self.R @ np.asarray(body.cog, float),
                         cob @ np.asarray(body.cob, float)])
        turning = arms[:1] if body.hydrostatic is not None else arms
        forces = np.stack([weight, lift])
        theta = log_rotation(self.R @ self.R0.T)
        K = self.hydrostatic_matrix(water_density, gravity)
        loads = (point_loads(arms, forces) - K @ np.concatenate([self.X - self.X0, theta])
                 + np.asarray(load, dtype=float))
        chain = np.eye(6)
        chain[3:, 3:] = log_jacobian(theta)
        return loads, lever_stiffness(turning, forces[:len(turning)]) - K @ chain
