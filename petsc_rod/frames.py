"""Director frames and their strains (numpy only, vectorised over points).

Arrays of frames have shape (..., 3, 3) with rows d1, d2, d3 (docs/method.md §1, §2).
"""

import numpy as np

# The frame of the straight reference state r = S e_x: rows d1 = e_y, d2 = e_z, d3 = e_x.
REFERENCE_FRAME = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
# |det D| below which strains() takes the pseudo-inverse of a frame
SINGULAR_FRAME = 1e-12
# Points whose strains strains() computes at once.
STRAIN_BLOCK = 8192


def strains(d, dd):
    """Strains u_i in the director basis: the components on the directors of the frame's
    rate of rotation omega (§1, §6). d, dd: (..., 3, 3), rows d1, d2, d3 and d1', d2',
    d3'; returns (..., 3).

    For a field of rotations, d_i' = omega x d_i, i.e. [omega]x = D'^T D (D the matrix of
    rows d_i), and u_i = d_i . omega gives u1 = d2'.d3, u2 = d3'.d1, u3 = d1'.d2. The
    discrete directors are orthonormal at the nodes only; in general [omega]x is taken as
    the skew part of D'^T D^-T: what rotates counts, the small stretch and shear of the
    interpolated directors between the nodes (a discretisation artefact) does not (at a
    node this is u1 = (d2'.d3 - d3'.d2) / 2 and the like). It makes the energy's
    discretisation error several times smaller (docs/accuracy.md).
    A singular D (a frame with a zero director) takes the pseudo-inverse.
    """
    shape = np.shape(d)
    d = np.asarray(d, dtype=float).reshape(-1, 3, 3)
    dd = np.asarray(dd, dtype=float).reshape(-1, 3, 3)
    u = np.empty((d.shape[0], 3))
    # in blocks of points: the inverses and rates of a long line's points at once were
    # several arrays of its size beside the run's (docs/performance.md, "Memory for
    # long lines"); each point's value is its own
    for start in range(0, d.shape[0], STRAIN_BLOCK):
        block = slice(start, start + STRAIN_BLOCK)
        u[block] = _strains(d[block], dd[block])
    return u.reshape(shape[:-1])


def _strains(d, dd):
    """strains of (n, 3, 3) frames d and their derivatives dd, (n, 3)."""
    transposed = np.swapaxes(d, -1, -2)
    inverse = np.empty_like(d)
    regular = np.abs(np.linalg.det(d)) > SINGULAR_FRAME
    inverse[regular] = np.linalg.inv(transposed[regular])
    inverse[~regular] = np.linalg.pinv(transposed[~regular])
    rate = np.einsum("nji,njk->nik", dd, inverse)
    omega = 0.5 * np.stack([rate[:, 2, 1] - rate[:, 1, 2], rate[:, 0, 2] - rate[:, 2, 0],
                            rate[:, 1, 0] - rate[:, 0, 1]], axis=-1)
    return np.einsum("nic,nc->ni", d, omega)


def split_coefficients(stiffness):
    """a_i of the quadratic form w = a1|d1'|^2 + a2|d2'|^2 + a3|r''|^2 (§2), N m^2.

    a1 = (K2 + K3 - K1)/4, a2 = (K3 + K1 - K2)/4, a3 = (K1 + K2 - K3)/4, pointwise:
    stiffness (..., 3) -> (..., 3), one triple per point of a line whose stiffness varies
    along S (Scene.stiffness_at), or (3,) -> (3,) for a uniform one.
    """
    k = np.asarray(stiffness, dtype=float)
    k1, k2, k3 = k[..., 0], k[..., 1], k[..., 2]
    return np.stack([k2 + k3 - k1, k3 + k1 - k2, k1 + k2 - k3], axis=-1) / 4.0


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


def roll_between(first, second):
    """The roll (rad, in (-pi, pi]) that takes frames ``first`` to ``second`` (..., 3, 3),
    rows d1, d2, d3, about their tangent: atan2(d1'.d2 - d2'.d1, d1'.d1 + d2'.d2), primes
    ``second``'s. Between neighbouring nodes of a rod it measures the twist u3 dS
    (u3 = d1'.d2, strains), exactly where the frames differ by a roll and a bend in one
    plane (tests/unit/test_roll_between.py); rolling ``second`` by a about its d3,
    (d1, d2) -> (cos a d1 + sin a d2, -sin a d1 + cos a d2), adds a to it where the
    tangents agree."""
    def dot(i, j):
        return np.einsum("...c,...c->...", second[..., i, :], first[..., j, :])
    return np.arctan2(dot(0, 1) - dot(1, 0), dot(0, 0) + dot(1, 1))
