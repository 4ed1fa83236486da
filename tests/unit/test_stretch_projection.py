"""The local step with axial stretch (docs/method.md §12), numpy only:
projection.stretched_rotation maximises b1.T1 + b2.T2 + k b3.T3 - R k^2/2 - EA (k-1)^2/2
over T in SO(3) and k, checked against perturbations of T and k, the closed form of k,
and the plain projection where EA is infinite."""

import numpy as np
from scipy.linalg import expm

from petsc_rod.local_step.projection import nearest_rotation, stretched_rotation

RNG = np.random.default_rng(7)


def objective(t, k, b, R, ea):
    return (np.einsum("nc,nc->n", b[:, 0], t[:, 0]) + np.einsum("nc,nc->n", b[:, 1], t[:, 1])
            + k * np.einsum("nc,nc->n", b[:, 2], t[:, 2]) - R * k**2 / 2 - ea * (k - 1)**2 / 2)


def frames_near_rotations(n, R, spread):
    """b = R (rotation with a stretched third row) + noise: what the iteration meets."""
    q = np.linalg.qr(RNG.normal(size=(n, 3, 3)))[0]
    q *= np.sign(np.linalg.det(q))[:, None, None]
    q[:, 2] *= 1 + 0.1 * RNG.random(n)[:, None]
    return R * q + spread * R * RNG.normal(size=(n, 3, 3))


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def test_stretched_rotation_is_a_maximiser():
    R, n = 3.0, 200
    for ea in (0.5, 30.0, 1e6):
        b = frames_near_rotations(n, R, 0.2)
        axial = np.full(n, ea)
        target = stretched_rotation(b, axial, R)
        k = np.linalg.norm(target[:, 2], axis=1)
        t = target.copy()
        t[:, 2] /= k[:, None]
        assert np.abs(t @ t.transpose(0, 2, 1) - np.eye(3)).max() < 1e-12
        assert np.all(np.linalg.det(t) > 0)
        # k is optimal for T: (b3.T3 + EA) / (R + EA)
        s = np.einsum("nc,nc->n", b[:, 2], t[:, 2])
        assert np.abs(k - (s + ea) / (R + ea)).max() < 1e-13
        best = objective(t, k, b, R, ea)
        for _ in range(20):
            turn = np.array([expm(hat(w)) for w in 1e-3 * RNG.normal(size=(n, 3))])
            dk = 1e-3 * RNG.normal(size=n)
            assert np.all(objective(t @ turn.transpose(0, 2, 1), k + dk, b, R, ea)
                          <= best + 1e-12 * np.abs(best))


def test_infinite_EA_is_the_plain_projection():
    R, n = 2.0, 50
    b = frames_near_rotations(n, R, 0.3)
    axial = np.full(n, np.inf)
    axial[::2] = 10.0
    target = stretched_rotation(b, axial, R)
    plain = nearest_rotation(b)
    assert np.array_equal(target[1::2], plain[1::2])
    assert not np.allclose(target[::2], plain[::2])


def test_in_place_and_warm_start():
    R, n = 1.0, 64
    b = frames_near_rotations(n, R, 0.1)
    axial = np.full(n, 5.0)
    cold = stretched_rotation(b, axial, R)
    k = np.linalg.norm(cold[:, 2], axis=1)
    warm = b.copy()
    stretched_rotation(warm, axial, R, start=k, out=warm)
    assert np.abs(warm - cold).max() < 1e-13
