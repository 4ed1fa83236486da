"""The pointwise projection of the Uzawa iteration (docs/method.md §1-§3), numpy only.

nearest_rotation(b) is the local step: the T in SO(3) maximising sum_i T_i . b_i =
trace(T b^T). It is checked against a brute force (local perturbations along every
direction of so(3), and 20000 uniformly random rotations), and against the SVD formula
(nearest_rotation_svd) on each class of input of scripts/benchmark_projection.py, across
the blocks it works on.
"""

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from helpers import REPO_ROOT
from petsc_rod.frames import rotation_about, rotation_log, split_coefficients, strains
from petsc_rod.local_step import projection
from petsc_rod.local_step.projection import (nearest_rotation, nearest_rotation_eigen,
                                             nearest_rotation_svd, polar_newton, shifted,
                                             update_multipliers)

ROUND_OFF = 1e-12


def objective(t, b):
    """sum_i T_i . b_i = trace(T b^T), broadcast over leading axes."""
    return np.einsum("...ij,...ij->...", t, b)


def hat(w):
    """Skew matrix with hat(w) x = w x x."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def random_rotations(rng, n):
    """n uniformly distributed rotations, from uniformly random unit quaternions."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return Rotation.from_quat(q).as_matrix()


def assert_proper_rotation(t, tol=ROUND_OFF):
    t = np.asarray(t)
    eye = np.broadcast_to(np.eye(3), t.shape)
    assert np.abs(t @ np.swapaxes(t, -1, -2) - eye).max() < tol
    assert np.abs(np.linalg.det(t) - 1.0).max() < tol


def nearest_one(b):
    """nearest_rotation of one (3, 3) matrix, through the batched path (see
    test_nearest_rotation_accepts_a_single_matrix for the unbatched call)."""
    return nearest_rotation(np.asarray(b, dtype=float)[None])[0]


def known_optimum(b):
    """max over SO(3) of trace(T b^T) for b = U S V^T: s1 + s2 + sign(det U V^T) s3."""
    u, s, vt = np.linalg.svd(b)
    return s[0] + s[1] + np.sign(np.linalg.det(u @ vt)) * s[2]


# --- nearest_rotation ------------------------------------------------------------------

def test_nearest_rotation_is_a_proper_rotation():
    rng = np.random.default_rng(1)
    b = rng.normal(size=(500, 3, 3)) * rng.uniform(0.01, 100.0, size=(500, 1, 1))
    t = nearest_rotation(b)
    assert t.shape == b.shape
    assert_proper_rotation(t)
    # about half of random matrices have det b < 0: the sign fix is exercised
    assert np.sum(np.linalg.det(b) < 0) > 100


def test_nearest_rotation_beats_local_perturbations_and_random_rotations():
    rng = np.random.default_rng(2)
    samples = random_rotations(rng, 20000)
    b = rng.normal(size=(50, 3, 3))
    b[10:20] = -b[10:20]          # -b has the opposite det: reflections for sure
    t = nearest_rotation(b)
    for bk, tk in zip(b, t):
        best = objective(tk, bk)
        # every direction of so(3), two step sizes
        skews = [hat(w) for w in rng.normal(size=(40, 3))]
        for eps in (1e-1, 1e-3):
            moved = np.array([tk @ expm(eps * a) for a in skews])
            assert np.all(best >= objective(moved, bk) - ROUND_OFF)
        assert best >= objective(samples, bk).max() - ROUND_OFF


@pytest.mark.parametrize("seed", range(3))
def test_nearest_rotation_of_a_rotation_is_itself(seed):
    rng = np.random.default_rng(10 + seed)
    q = random_rotations(rng, 200)
    assert np.abs(nearest_rotation(q) - q).max() < ROUND_OFF
    scale = rng.uniform(1e-3, 1e3, size=(200, 1, 1))
    assert np.abs(nearest_rotation(scale * q) - q).max() < ROUND_OFF


def test_nearest_rotation_of_q_s_pt_is_q_pt():
    rng = np.random.default_rng(3)
    q, p = random_rotations(rng, 2)
    b = q @ np.diag([3.0, 2.0, 1.0]) @ p.T
    assert np.abs(nearest_one(b) - q @ p.T).max() < ROUND_OFF


@pytest.mark.parametrize("name", ["zero", "rank1", "rank2", "diag(1,1,-1)", "-I",
                                  "diag(3,2,-1)", "random reflection", "nearly singular"])
def test_nearest_rotation_degenerate_inputs(name):
    rng = np.random.default_rng(4)
    q, p = random_rotations(rng, 2)
    x, y = rng.normal(size=(2, 3))
    b = {"zero": np.zeros((3, 3)),
         "rank1": np.outer(x, y),
         "rank2": q @ np.diag([2.0, 0.5, 0.0]) @ p.T,
         "diag(1,1,-1)": np.diag([1.0, 1.0, -1.0]),
         "-I": -np.eye(3),
         "diag(3,2,-1)": np.diag([3.0, 2.0, -1.0]),
         "random reflection": q @ np.diag([3.0, 1.5, 0.7]) @ p.T @ np.diag([1.0, 1.0, -1.0]),
         "nearly singular": q @ np.diag([2.0, 1.0, 1e-14]) @ p.T}[name]
    t = nearest_one(b)
    assert_proper_rotation(t)
    best = objective(t, b)
    samples = random_rotations(rng, 20000)
    assert best >= objective(samples, b).max() - ROUND_OFF
    expected = {"zero": 0.0, "rank1": np.linalg.norm(x) * np.linalg.norm(y), "rank2": 2.5,
                "diag(1,1,-1)": 1.0, "-I": 1.0, "diag(3,2,-1)": 4.0,
                "random reflection": 3.0 + 1.5 - 0.7, "nearly singular": 3.0}[name]
    assert best == pytest.approx(expected, abs=1e-12)
    assert best == pytest.approx(known_optimum(b), abs=1e-12)
    if name == "diag(3,2,-1)":
        assert np.abs(t - np.eye(3)).max() < ROUND_OFF


def test_nearest_rotation_is_vectorised():
    rng = np.random.default_rng(5)
    b = rng.normal(size=(4, 5, 3, 3))
    b[0, 0] = np.diag([1.0, 1.0, -1.0])
    b[1, 2] = 0.0
    t = nearest_rotation(b)
    assert t.shape == (4, 5, 3, 3)
    for i in range(4):
        for j in range(5):
            assert np.abs(t[i, j] - nearest_one(b[i, j])).max() < ROUND_OFF
    assert np.abs(nearest_rotation(b[2]) - t[2]).max() < ROUND_OFF
    assert_proper_rotation(t)


def test_nearest_rotation_accepts_a_single_matrix():
    q = rotation_about([1.0, 2.0, 3.0], 0.7)
    assert np.abs(nearest_rotation(2.0 * q) - q).max() < ROUND_OFF
    t = nearest_rotation(np.diag([1.0, 1.0, -1.0]))
    assert_proper_rotation(t)


def test_nearest_rotation_of_nan_or_inf_is_nan_not_an_error():
    """A diverged iteration must reach the collective divergence test (the norms), not
    stop one rank in the SVD (LinAlgError)."""
    b = np.stack([2.0 * np.eye(3)] * 3)
    b[1, 0, 0] = np.nan
    b[2, 1, 2] = np.inf
    with np.errstate(invalid="ignore"):
        t = nearest_rotation(b)
    assert np.array_equal(t[0], np.eye(3))
    assert np.isnan(t[1:]).all()


def test_nearest_rotation_does_not_modify_its_input():
    rng = np.random.default_rng(6)
    b = rng.normal(size=(7, 3, 3))
    copy = b.copy()
    nearest_rotation(b)
    assert np.array_equal(b, copy)


def with_singular_values(rng, s):
    """Q diag(s) P^T for random rotations Q, P; s (n, 3)."""
    q, p = random_rotations(rng, len(s)), random_rotations(rng, len(s))
    return np.einsum("nij,nj,nkj->nik", q, s, p)


def input_class(name, n, rng):
    """The input classes of scripts/benchmark_projection.py, and two more."""
    if name == "near":          # a running iteration: R (rotation + perturbation)
        return 400.0 * (random_rotations(rng, n) + 0.05 * rng.normal(size=(n, 3, 3)))
    if name == "far":           # a start far from any rotation, det > 0
        b = rng.normal(size=(n, 3, 3))
        b[np.linalg.det(b) < 0] *= -1.0
        return b
    if name == "rank 2":
        return with_singular_values(rng, np.stack(
            [rng.uniform(1.5, 2.0, n), rng.uniform(0.5, 1.2, n), np.zeros(n)], axis=1))
    if name == "reflected":     # det < 0 with s2 - s3 not small: a unique maximiser
        return with_singular_values(rng, np.stack(
            [rng.uniform(1.5, 2.0, n), rng.uniform(0.9, 1.4, n), -rng.uniform(0.1, 0.8, n)],
            axis=1))
    if name == "ill-conditioned":   # det > 0, cond 1e4..1e8: left to the eigen-solve
        return with_singular_values(rng, np.stack(
            [np.ones(n), rng.uniform(0.3, 1.0, n), 10.0 ** rng.uniform(-8, -4, n)], axis=1))
    if name == "mixed":         # every class, shuffled, with scales 1e-3..1e3
        parts = [input_class(other, n // 5 + 1, rng) for other in
                 ("near", "far", "rank 2", "reflected", "ill-conditioned")]
        b = rng.permutation(np.concatenate(parts))[:n]
        return b * 10.0 ** rng.uniform(-3, 3, size=(n, 1, 1))
    raise ValueError(name)


CLASSES = ["near", "far", "rank 2", "reflected", "ill-conditioned", "mixed"]


@pytest.mark.parametrize("name", CLASSES)
def test_nearest_rotation_equals_the_svd_on_each_input_class(name):
    rng = np.random.default_rng(20)
    b = input_class(name, 3000, rng)
    t = nearest_rotation(b)
    assert np.abs(t - nearest_rotation_svd(b)).max() < ROUND_OFF
    assert_proper_rotation(t)


def test_nearest_rotation_rank_one_is_a_proper_maximiser():
    """b = x y^T: the maximiser is not unique (any rotation taking y/|y| to x/|x|); the
    value is |x| |y|."""
    rng = np.random.default_rng(21)
    x, y = rng.normal(size=(2, 500, 3))
    b = x[:, :, None] * y[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):     # left to the eigen-solve
        assert polar_newton(shifted(b), np.empty_like(b)).all()
    t = nearest_rotation(b)
    assert_proper_rotation(t)
    optimum = np.linalg.norm(x, axis=1) * np.linalg.norm(y, axis=1)
    assert np.abs(objective(t, b) - optimum).max() < ROUND_OFF * optimum.max()


@pytest.mark.parametrize("name, share", [("near", 0.0), ("far", 0.01)])
def test_newton_takes_the_points_of_a_running_iteration(name, share):
    """Only hard points go to the eigen-solve: none of a running iteration's, and of
    random matrices with det > 0 only the ill-conditioned ones (cond above about 1e3)."""
    b = input_class(name, 2000, np.random.default_rng(22))
    polar = np.empty_like(b)
    missed = polar_newton(b, polar)
    missed = np.zeros(len(b), dtype=bool) if missed is None else missed
    assert missed.mean() <= share
    assert np.abs(polar[~missed] - nearest_rotation_svd(b[~missed])).max() < ROUND_OFF


@pytest.mark.parametrize("name", ["rank 2", "reflected", "ill-conditioned"])
def test_hard_points_go_through_newton_shifted(name):
    """Newton leaves singular, reflected and ill-conditioned b out; b + cof(b) / s1 has
    the maximiser of b as its polar factor, and Newton takes it."""
    b = input_class(name, 300, np.random.default_rng(23))
    missed = polar_newton(b, np.empty_like(b))
    assert missed is not None and missed.all()
    t = np.empty_like(b)
    with np.errstate(divide="ignore", invalid="ignore"):
        assert polar_newton(shifted(b), t) is None
    assert np.abs(t - nearest_rotation_svd(b)).max() < ROUND_OFF


@pytest.mark.parametrize("name", ["rank 2", "reflected", "ill-conditioned", "far"])
def test_nearest_rotation_eigen_equals_the_svd(name):
    b = input_class(name, 300, np.random.default_rng(33))
    assert np.abs(nearest_rotation_eigen(b) - nearest_rotation_svd(b)).max() < ROUND_OFF


def test_nearest_rotation_nan_or_inf_anywhere_in_a_block():
    """Non-finite points give NaN, at any position and however many; the others are
    unaffected."""
    rng = np.random.default_rng(24)
    b = input_class("mixed", 1000, rng)
    expected = nearest_rotation_svd(b)
    bad = rng.choice(1000, size=50, replace=False)
    b[bad[:25], rng.integers(0, 3, 25), rng.integers(0, 3, 25)] = np.nan
    b[bad[25:], rng.integers(0, 3, 25), rng.integers(0, 3, 25)] = -np.inf
    t = nearest_rotation(b)
    assert np.isnan(t[bad]).all()
    good = np.setdiff1d(np.arange(1000), bad)
    assert np.abs(t[good] - expected[good]).max() < ROUND_OFF
    assert np.isnan(nearest_rotation(np.full((4, 3, 3), np.inf))).all()


@pytest.mark.parametrize("shape", [(40, 3, 3, 3), (60, 2, 3, 3), (2, 3, 4, 3, 3)])
def test_nearest_rotation_leading_dimensions(shape):
    rng = np.random.default_rng(25)
    n = int(np.prod(shape[:-2]))
    b = input_class("mixed", n, rng).reshape(shape)
    t = nearest_rotation(b)
    assert t.shape == shape
    assert np.abs(t.reshape(-1, 3, 3) - nearest_rotation_svd(b.reshape(-1, 3, 3))).max() \
        < ROUND_OFF


@pytest.mark.parametrize("block", [1, 7, 64])
@pytest.mark.parametrize("n", [0, 1, 2, 6, 7, 8, 63, 64, 65, 200])
def test_nearest_rotation_block_boundaries(monkeypatch, block, n):
    """Any n against any block size: whole blocks, a partial last one, n < block, n = 0;
    hard points at the blocks' ends."""
    monkeypatch.setattr(projection, "BLOCK", block)
    rng = np.random.default_rng(26)
    b = input_class("near", max(n, 1), rng)[:n]
    ends = np.arange(n)[(np.arange(n) % block == 0) | (np.arange(n) % block == block - 1)]
    if len(ends[::2]):
        b[ends[::2]] = input_class("reflected", len(ends[::2]), rng)
    t = nearest_rotation(b)
    assert t.shape == (n, 3, 3)
    if n:
        assert np.abs(t - nearest_rotation_svd(b)).max() < ROUND_OFF


def test_points_newton_has_not_converged_go_to_the_eigen_solve(monkeypatch):
    """With too few steps allowed, the points not converged are caught, not returned."""
    monkeypatch.setattr(projection, "MAX_STEPS", 3)
    b = input_class("far", 300, np.random.default_rng(31))
    assert polar_newton(b, np.empty_like(b)).mean() > 0.5
    assert np.abs(nearest_rotation(b) - nearest_rotation_svd(b)).max() < ROUND_OFF


@pytest.mark.parametrize("far", [1, 30, 300])
def test_slow_points_go_on_as_a_smaller_block(monkeypatch, far):
    """A few points far from a rotation among near ones: once the near ones have
    converged, the far ones continue from their iterate alone, with the same result."""
    rng = np.random.default_rng(32)
    b = input_class("near", 1000, rng)
    b[rng.choice(1000, far, replace=False)] = input_class("far", far, rng)
    calls = []
    newton = projection.polar_newton

    def spy(b, out, steps=None, iterate=False):
        calls.append((len(b), iterate))
        return newton(b, out, steps, iterate)

    monkeypatch.setattr(projection, "polar_newton", spy)
    assert np.abs(nearest_rotation(b) - nearest_rotation_svd(b)).max() < ROUND_OFF
    assert calls[0] == (1000, False)
    assert 1 < len(calls) and all(n <= far and iterate for n, iterate in calls[1:])


def test_nearest_rotation_at_the_block_size():
    """The block size itself, once over: a full block, then a partial one."""
    rng = np.random.default_rng(27)
    b = input_class("mixed", projection.BLOCK + 3, rng)
    assert np.abs(nearest_rotation(b) - nearest_rotation_svd(b)).max() < ROUND_OFF


def test_nearest_rotation_into_out_and_in_place():
    rng = np.random.default_rng(28)
    b = input_class("mixed", 500, rng).reshape(50, 10, 3, 3)
    expected = nearest_rotation_svd(b.reshape(-1, 3, 3)).reshape(b.shape)
    out = np.empty_like(b)
    assert nearest_rotation(b, out=out) is out
    assert np.abs(out - expected).max() < ROUND_OFF
    assert nearest_rotation(b, out=b) is b           # out may be b itself
    assert np.abs(b - expected).max() < ROUND_OFF
    with pytest.raises(ValueError):
        nearest_rotation(b, out=np.empty((500, 3, 3)))
    with pytest.raises(ValueError):
        nearest_rotation(np.ones((4, 9)))


def test_nearest_rotation_of_scaled_points():
    """Newton is scale free and the eigen-solve takes what it cannot: the same rotation
    from 1e-120 to 1e120."""
    rng = np.random.default_rng(29)
    b = input_class("far", 100, rng)
    expected = nearest_rotation_svd(b)
    for scale in (1e-120, 1e-95, 1e-30, 1e30, 1e95, 1e120):
        assert np.abs(nearest_rotation(scale * b) - expected).max() < ROUND_OFF


def test_benchmark_projection_script(monkeypatch, capsys):
    """scripts/benchmark_projection.py on small counts: a row per class and size, the
    kernel within round-off of the SVD."""
    import importlib.util
    import os
    path = os.path.join(REPO_ROOT,
                        "scripts", "benchmark_projection.py")
    spec = importlib.util.spec_from_file_location("benchmark_projection", path)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    monkeypatch.setattr(script, "BUDGET", 0.0)
    monkeypatch.setattr("sys.argv", ["benchmark_projection.py", "--sizes", "50,300"])
    script.main()
    rows = [line.split("|")[1:-1] for line in capsys.readouterr().out.splitlines()
            if line.startswith("| ") and not line.startswith("| input")]
    assert [(row[0].strip(), int(float(row[1]))) for row in rows] == [
        (name, n) for name in script.CLASSES for n in (50, 300)]
    assert max(float(row[5]) for row in rows) < ROUND_OFF        # dev
    assert max(float(row[6]) for row in rows) < ROUND_OFF        # objective shortfall


# --- multipliers -----------------------------------------------------------------------

def test_update_multipliers_in_place():
    rng = np.random.default_rng(7)
    lam = rng.normal(size=(6, 3, 3, 3))
    d = rng.normal(size=lam.shape)
    tau = rng.normal(size=lam.shape)
    expected = lam + 400.0 * (d - tau)
    out = update_multipliers(lam, d, tau, 400.0)
    assert out is lam
    assert np.abs(lam - expected).max() < 1e-12
    # a feasible point (d = tau) leaves lambda unchanged
    before = lam.copy()
    update_multipliers(lam, tau, tau, 400.0)
    assert np.array_equal(lam, before)


@pytest.mark.parametrize("size", [1, 1000, projection.CHUNK, 2 * projection.CHUNK + 5])
def test_update_multipliers_in_chunks(size):
    """Across the chunks it works in, and broadcast when the shapes differ."""
    rng = np.random.default_rng(30)
    lam, d, tau = rng.normal(size=(3, size, 3))
    expected = lam + 400.0 * (d - tau)
    update_multipliers(lam, d, tau, 400.0)
    assert np.abs(lam - expected).max() < 1e-12
    expected = lam + 2.0 * (d[:1] - tau)
    update_multipliers(lam, d[:1], tau, 2.0)
    assert np.abs(lam - expected).max() < 1e-12


# --- strains ---------------------------------------------------------------------------

def helix_frame(S, a, b):
    """Frenet frame of the helix (a cos(S/c), a sin(S/c), b S/c), c = sqrt(a^2 + b^2),
    as rows d1 = normal, d2 = binormal, d3 = tangent; curvature a/c^2, torsion b/c^2."""
    c = np.hypot(a, b)
    phi = np.asarray(S) / c
    tangent = np.stack([-a * np.sin(phi), a * np.cos(phi), b * np.ones_like(phi)], -1) / c
    normal = np.stack([-np.cos(phi), -np.sin(phi), np.zeros_like(phi)], -1)
    binormal = np.cross(tangent, normal)
    return np.stack([normal, binormal, tangent], axis=-2)


def test_strains_of_a_helix():
    a, b = 0.7, 0.3
    c2 = a**2 + b**2
    S = np.linspace(0.0, 5.0, 23)
    h = 1e-5
    d = helix_frame(S, a, b)
    dd = (helix_frame(S + h, a, b) - helix_frame(S - h, a, b)) / (2 * h)
    u = strains(d, dd)
    assert u.shape == (23, 3)
    # Darboux vector tau t + kappa B: no bending about the normal d1
    expected = np.array([0.0, a / c2, b / c2])
    assert np.abs(u - expected).max() < 1e-8


def test_strains_of_a_frame_with_constant_body_darboux_vector():
    """Lambda(S) = Lambda0 expm(S hat(kappa)) (columns d_i) has d_i' = u x d_i with
    u = kappa_j d_j: strains returns kappa, whatever Lambda0."""
    rng = np.random.default_rng(8)
    kappa = np.array([0.4, -1.3, 2.1])
    lam0 = random_rotations(rng, 1)[0]
    S = np.linspace(-1.0, 2.0, 11)
    frames = np.array([(lam0 @ expm(s * hat(kappa))).T for s in S])
    h = 1e-5
    dd = np.array([((lam0 @ expm((s + h) * hat(kappa))).T
                    - (lam0 @ expm((s - h) * hat(kappa))).T) / (2 * h) for s in S])
    u = strains(frames, dd)
    assert np.abs(u - kappa).max() < 1e-8
    # and the energy identity of §2: |d_i'|^2 = |u|^2 - u_i^2
    norms = np.sum(dd**2, axis=-1)
    assert np.abs(norms - (kappa @ kappa - kappa**2)).max() < 1e-8


# --- split coefficients (§2) -------------------------------------------------------------

@pytest.mark.parametrize("stiffness, expected", [
    ((1.0, 1.5, 0.8), (0.325, 0.075, 0.425)),
    ((1.0, 1.0, 1.0), (0.25, 0.25, 0.25)),
    ((235.0, 360.0, 200.0), (81.25, 18.75, 98.75)),
    ((235.0, 360.0, 100.0), (56.25, -6.25, 123.75)),     # the non-convex reading of §8
])
def test_split_coefficients(stiffness, expected):
    assert np.allclose(split_coefficients(stiffness), expected, rtol=0, atol=1e-12)


def test_split_reproduces_the_stored_energy():
    """a1|d1'|^2 + a2|d2'|^2 + a3|d3'|^2 = 1/2 sum K_i u_i^2 on orthonormal frames."""
    rng = np.random.default_rng(9)
    k = np.array([1.0, 1.5, 0.8])
    a = split_coefficients(k)
    for _ in range(5):
        kappa = rng.normal(size=3)
        lam0 = random_rotations(rng, 1)[0]
        d = lam0.T
        dd = (lam0 @ hat(kappa)).T           # derivative at S = 0 of the frame above
        split = np.sum(a * np.sum(dd**2, axis=-1))
        stored = 0.5 * np.sum(k * strains(d, dd) ** 2)
        assert split == pytest.approx(stored, rel=1e-12)
        assert stored == pytest.approx(0.5 * np.sum(k * kappa**2), rel=1e-12)


# --- rotations -------------------------------------------------------------------------

def test_rotation_about_matches_scipy():
    rng = np.random.default_rng(11)
    for _ in range(50):
        axis = rng.normal(size=3)
        angle = rng.uniform(-7.0, 7.0)
        q = rotation_about(axis, angle)
        expected = Rotation.from_rotvec(angle * axis / np.linalg.norm(axis)).as_matrix()
        assert np.abs(q - expected).max() < ROUND_OFF
        assert_proper_rotation(q)
    # a quarter turn about e_z takes e_x to e_y
    assert np.abs(rotation_about([0, 0, 2.0], np.pi / 2) @ [1, 0, 0] - [0, 1, 0]).max() < 1e-15


def test_rotation_log_round_trip():
    rng = np.random.default_rng(12)
    for angle in np.concatenate([rng.uniform(1e-3, np.pi - 1e-2, 100), [0.3, 1.0, 3.0]]):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        w = rotation_log(rotation_about(axis, angle))
        assert np.abs(w - angle * axis).max() < 1e-11
        assert np.abs(rotation_about(w, np.linalg.norm(w))
                      - rotation_about(axis, angle)).max() < ROUND_OFF
    assert np.array_equal(rotation_log(np.eye(3)), np.zeros(3))
    # a half turn: the axis up to sign
    w = rotation_log(rotation_about([0.0, 0.6, 0.8], np.pi))
    assert np.linalg.norm(w) == pytest.approx(np.pi, abs=1e-12)
    assert np.abs(np.abs(w / np.pi) - [0.0, 0.6, 0.8]).max() < 1e-12


def test_rotation_log_near_half_turn_and_tiny_angles():
    rng = np.random.default_rng(13)
    worst = 0.0
    for angle in (1e-10, 1e-8, 1e-6, np.pi - 1e-2, np.pi - 1e-4, np.pi - 1e-6,
                  np.pi - 1e-7, np.pi - 1e-9):
        for _ in range(50):
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            q = rotation_about(axis, angle)
            w = rotation_log(q)
            worst = max(worst, np.abs(w - angle * axis).max())
    assert worst < 1e-10
