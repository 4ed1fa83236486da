"""Pointwise kernels of the Uzawa iteration (numpy only, vectorised over points).

Arrays of frames have shape (..., 3, 3) with rows d1, d2, d3 (method.md §3).
"""

import numpy as np


# Newton is used where det b > WELL_CONDITIONED |b|_max^3 (the smallest singular value is
# then not tiny, so a few steps converge); elsewhere, and wherever it has not converged to
# ORTHOGONALITY, the SVD decides.
WELL_CONDITIONED = 1e-3
ORTHOGONALITY = 1e-13
NEWTON_STEPS = 12


def nearest_rotation(b):
    """The local step (§3 step 2): tau = argmax_{T in SO(3)} sum_i T_i . b_i.

    b: (..., 3, 3), rows b_i = R d_i + lambda_i. With b = U S V^T (SVD), the maximiser is
    T = U diag(1, 1, det(U V^T)) V^T: the polar factor of b with the sign fixed so that
    det T = +1 also when b is singular or a reflection. Returns (..., 3, 3).

    Where det b > 0 and b is well conditioned (every point of a running iteration, where
    b is near R times a rotation) T is the polar factor, computed by the scaled Newton
    iteration X <- (zeta X + (zeta X)^-T) / 2, zeta = det(X)^(-1/3), on the nine
    components as contiguous arrays: several times faster than a batched LAPACK SVD.
    The other points, and any that Newton leaves unconverged, go through the SVD.
    A b with NaN or Inf gives NaN.
    """
    b = np.asarray(b, dtype=float)
    flat = b.reshape(-1, 3, 3)
    scale = np.abs(flat).max(axis=(1, 2))
    scale[scale == 0] = 1.0
    x = np.ascontiguousarray((flat / scale[:, None, None]).transpose(1, 2, 0))  # (3, 3, n)
    newton = cofactors(x)[1] > WELL_CONDITIONED
    polar = polar_newton(x[:, :, newton])
    gram = np.einsum("ikn,jkn->ijn", polar, polar) - np.eye(3)[:, :, None]
    converged = np.abs(gram).max(axis=(0, 1)) < ORTHOGONALITY
    t = np.empty_like(flat)
    t[newton] = polar.transpose(2, 0, 1)
    rest = ~newton
    rest[np.flatnonzero(newton)[~converged]] = True
    # NaN/Inf (a diverged iteration) would make the SVD raise on this rank alone: give
    # NaN instead, which the iteration's collective norms report as a divergence.
    finite = np.isfinite(flat).all(axis=(1, 2))
    t[rest & ~finite] = np.nan
    t[rest & finite] = nearest_rotation_svd(flat[rest & finite])
    return t.reshape(b.shape)


def cofactors(x):
    """Cofactor matrices and determinants of matrices stored as (3, 3, n) components.

    Row i of the cofactor matrix is x_{i+1} x x_{i+2} (rows of x), so x^-T = C / det.
    """
    (a, b, c), (d, e, f), (g, h, i) = x
    cofactor = np.array([[e * i - f * h, f * g - d * i, d * h - e * g],
                         [h * c - i * b, i * a - g * c, g * b - h * a],
                         [b * f - c * e, c * d - a * f, a * e - b * d]])
    det = a * cofactor[0, 0] + b * cofactor[0, 1] + c * cofactor[0, 2]
    return cofactor, det


def polar_newton(x):
    """Orthogonal polar factor of (3, 3, n) matrices with positive determinant."""
    for _ in range(NEWTON_STEPS):
        cofactor, det = cofactors(x)
        zeta = np.cbrt(1.0 / det)
        x_next = 0.5 * (zeta * x + cofactor / (zeta * det))
        step = np.abs(x_next - x).max() if x.size else 0.0
        x = x_next
        if step < ORTHOGONALITY:
            break
    return x


def nearest_rotation_svd(b):
    """The same maximiser by SVD, for any (n, 3, 3), singular or reflected included."""
    u, _, vt = np.linalg.svd(b)
    sign = np.where(np.linalg.det(u @ vt) < 0, -1.0, 1.0)
    u[..., :, 2] *= sign[..., None]
    return u @ vt


def update_multipliers(lam, directors, tau, penalty):
    """Multiplier update (§3 step 3): lambda_i <- lambda_i + R (d_i - tau_i), in place."""
    lam += penalty * (directors - tau)
    return lam


def strains(d, dd):
    """Strains u_i in the director basis from directors and their S-derivatives (§1).

    d, dd: (..., 3, 3) rows d1, d2, d3 and d1', d2', d3'.
    u1 = d2'.d3, u2 = d3'.d1, u3 = d1'.d2.  Returns (..., 3).
    """
    return np.stack([np.einsum("...c,...c->...", dd[..., 1, :], d[..., 2, :]),
                     np.einsum("...c,...c->...", dd[..., 2, :], d[..., 0, :]),
                     np.einsum("...c,...c->...", dd[..., 0, :], d[..., 1, :])], axis=-1)


def split_coefficients(stiffness):
    """a_i of the quadratic form w = a1|d1'|^2 + a2|d2'|^2 + a3|r''|^2 (§2).

    a1 = (K2 + K3 - K1)/4, a2 = (K3 + K1 - K2)/4, a3 = (K1 + K2 - K3)/4.
    """
    k1, k2, k3 = stiffness
    return np.array([k2 + k3 - k1, k3 + k1 - k2, k1 + k2 - k3]) / 4.0


def rotation_about(axis, angle):
    """Rotation matrix (3, 3) of ``angle`` rad about the unit vector ``axis`` (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def rotations(omega):
    """Rotation matrices exp([omega]x) of rotation vectors omega (..., 3) (Rodrigues):
    I + sin(a) [k]x + (1 - cos a) [k]x^2 with a = |omega|, k = omega / a. (..., 3, 3)."""
    omega = np.asarray(omega, dtype=float)
    angle = np.linalg.norm(omega, axis=-1)[..., None, None]
    k = np.zeros(omega.shape + (3,))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -omega[..., 2], omega[..., 1], -omega[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    # sin(a)/a and (1 - cos a)/a^2, well defined at a = 0
    first = np.sinc(angle / np.pi)
    second = 0.5 * np.sinc(angle / (2 * np.pi)) ** 2
    return np.eye(3) + first * k + second * (k @ k)


def rotation_log(q):
    """Axis-angle vector w (3,) with rotation_about(w/|w|, |w|) = q, |w| in [0, pi].

    With s = (q - q^T)^vee = 2 sin(a) axis, the angle a = atan2(|s|, tr q - 1) is accurate
    over the whole range; w = s a / (2 sin a) below a half-turn's neighbourhood, and near
    a = pi the axis comes from the symmetric part (q + q^T)/2 - cos(a) I = (1 - cos a)
    axis axis^T, its sign from s.
    """
    skew = np.array([q[2, 1] - q[1, 2], q[0, 2] - q[2, 0], q[1, 0] - q[0, 1]])
    angle = np.arctan2(np.linalg.norm(skew), np.trace(q) - 1.0)
    if angle < np.pi / 2:
        return skew / (2.0 * np.sinc(angle / np.pi))
    outer = (q + q.T) / 2.0 - np.cos(angle) * np.eye(3)
    column = outer[:, np.argmax(np.diag(outer))]
    axis = column / np.linalg.norm(column)
    if axis @ skew < 0:
        axis = -axis
    return angle * axis
