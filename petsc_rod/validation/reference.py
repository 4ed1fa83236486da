r"""Independent reference solutions of the static Kirchhoff rod by collocation.

This module solves the same continuum problem as the augmented-Lagrangian solver
(``docs/method.md`` §1) by a different method: the strong form of the equilibrium
equations, written as a first-order two-point boundary-value problem and solved by
``scipy.integrate.solve_bvp`` (4th-order Lobatto IIIA collocation with residual-based
mesh adaptation). It uses numpy, scipy and h5py only, never PETSc, and nothing of the
finite-element code, so agreement with petsc_rod is evidence for both.

Unknowns and equations
----------------------
Arc length ``S`` in ``[0, L]``. Thirteen unknown functions of ``S``:

    r  (3)  centreline,
    q  (4)  quaternion ``q = (q0, qv)`` of the director frame, d_i = R(q) e_i,
    n  (3)  internal force,
    m  (3)  internal moment,

``n(S)``, ``m(S)`` being the force and moment (about r(S)) that the part beyond ``S``
exerts on the part before it (docs/method.md §9). With no distributed load (f = g = 0):

    r' = d3                                  (inextensible, unshearable)
    q' = 1/2 q (x) (0, u),   u_i = (m . d_i) / K_i        (i = 1, 2, 3)
    n' = 0                                   (n' + f = 0)
    m' = -r' x n = -d3 x n                   (m' + r' x n + g = 0)

``(x)`` is the quaternion product (a0, a) (x) (b0, b) = (a0 b0 - a.b, a0 b + b0 a + a x b)
and ``u = (u1, u2, u3)`` the strains in the director basis: the Darboux vector is
``sum_i u_i d_i``, so that d_i' = (sum_j u_j d_j) x d_i, equivalently R' = R [u]_x, which
is the quaternion equation above. The constitutive law m = sum_i K_i u_i d_i is inverted
in the second line: u_i = m . d_i / K_i, with one stiffness triple for the whole line
(a line of sections, Scene.sections, is not covered: initial_guess_from_result refuses
its result file).

The rotation is evaluated in homogeneous form,

    R(q) = ((q0^2 - |qv|^2) I + 2 qv qv^T + 2 q0 [qv]_x) / |q|^2,

which is an exact rotation for every q != 0, so the frame is orthonormal at every
collocation point even where the discrete q is not exactly of unit length.

The quaternion norm, and why there is no extra gauge condition
---------------------------------------------------------------
For a pure quaternion p = (0, u), q . (q (x) p) = |q|^2 p0 = 0, so d|q|^2/dS = 0: the
ODE conserves |q| exactly. The clamp prescribes the whole frame at S = 0 through the
four conditions q(0) = q_clamp, with |q_clamp| = 1 (of the two quaternions of the clamp
frame, ``+q`` and ``-q``, one is chosen; both describe the same frame, and the solution
for ``-q_clamp`` is the negated q of the same rod). Those four conditions fix three
rotation angles *and* the norm, which is then 1 along the whole rod by the conservation
law. The count is therefore exact, 13 ODEs and 13 conditions:

    S = 0 (clamp):          r(0) = 0 (3),   q(0) = q_clamp (4)
    S = L, pinned end:      r(L) = r_end (3),  m(L) = 0 (3)   (free rotation)
    S = L, free end:        n(L) = F (3),      m(L) = 0 (3)   (dead end force F)

No frame condition has to be traded for a norm condition here. (That trade is needed
only where a frame is prescribed at an end whose quaternion is not an initial value,
e.g. a clamp at S = L: there one imposes the three components of the vector part of
conj(q_L) (x) q(L), and the norm |q(0)| = 1 at the other end in place of a fourth.)
Collocation does not conserve the quadratic invariant |q|^2 exactly; its drift is of
the order of the truncation error, it does not affect the frame (homogeneous R above),
and it is reported as ``quaternion_norm_error``.

Branches
--------
The planar (untwisted) configuration of the paper's scene (docs/method.md §8: clamp with
d1 = e_y, d2 = e_z, d3 = e_x, pinned end at (X_F, 20 - X_F, 0)) satisfies these equations
too: the plane z = 0 with d2 = e_z is invariant under the ODE and the boundary
conditions, so Newton's method started in it stays in it (:func:`planar_guess`). It
bends the rod about its stiff axis d2 (K2 = 360 > K1 = 235). The twisted, out-of-plane
branch, which has the lower energy, is reached from a twisted guess: a petsc_rod result
(:func:`initial_guess_from_result`) or :func:`shooting_guess` with approximate clamp
reactions. Followed in X_F (:func:`solve_paper_scene`) it is, near X_F = 20, the Euler
buckling of the clamped-pinned rod about the weak axis d1 (|n| -> 20.19 K1/L^2 = 11.86)
and, for K = (235, 360, 200), it joins the planar branch in a pitchfork near X_F = 5.15;
below that, continuation along y = 20 - x yields the planar state. Mirror images
(z -> -z, u1 and u3 change sign) are equally valid solutions (docs/method.md §9).

Accuracy
--------
``solve_bvp`` controls the relative collocation residual |r_mid| / (1 + |f|) <= tol at
the interval midpoints and refines the mesh until it holds; its Newton iteration gets the
exact Jacobian of the ODE by complex-step differentiation (the right-hand side is
analytic in y). :func:`self_check` estimates the actual error by solving at a coarse
tolerance and again on a refined node set at a finer one, and comparing.

Units: as petsc_rod (SI in its examples; the code is unit-agnostic).
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_bvp

__all__ = [
    "PAPER_CLAMP_FRAME",
    "RodBVPResult",
    "solve_rod_bvp",
    "initial_guess_from_result",
    "energy",
    "self_check",
    "planar_guess",
    "solve_paper_scene",
    "solve_cantilever_bvp",
    "shooting_guess",
    "quaternion_from_frame",
    "frame_from_quaternion",
]

PAPER_CLAMP_FRAME = np.array([[0.0, 1.0, 0.0],    # d1 = e_y
                              [0.0, 0.0, 1.0],    # d2 = e_z
                              [1.0, 0.0, 0.0]])   # d3 = e_x
"""The clamp frame of the paper's scene (docs/method.md §8); row i is d_{i+1}."""

_N_STATE = 13
_R, _Q, _N, _M = slice(0, 3), slice(3, 7), slice(7, 10), slice(10, 13)
_COMPLEX_STEP = 1e-30
_GAUSS_POINTS, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(6)


# --------------------------------------------------------------------------- quaternions

def _rotation_columns(q):
    r"""Directors d1, d2, d3 of the homogeneous rotation R(q) = (...)/|q|^2.

    ``q`` has shape (4, ...), real or complex (the formula is analytic in q, which the
    complex-step Jacobian relies on: |q|^2 is the sum of squares, not of moduli).
    Returns three arrays of shape (3, ...): the columns R e_1, R e_2, R e_3.
    """
    w, x, y, z = q
    s = w * w + x * x + y * y + z * z
    d1 = np.stack([w * w + x * x - y * y - z * z, 2 * (x * y + w * z), 2 * (x * z - w * y)])
    d2 = np.stack([2 * (x * y - w * z), w * w - x * x + y * y - z * z, 2 * (y * z + w * x)])
    d3 = np.stack([2 * (x * z + w * y), 2 * (y * z - w * x), w * w - x * x - y * y + z * z])
    return d1 / s, d2 / s, d3 / s


def frame_from_quaternion(q):
    """Frames of quaternions ``q`` (shape (..., 4), scalar first).

    Returns shape (..., 3, 3) with row i = d_{i+1} = R(q) e_{i+1}.
    """
    q = np.asarray(q, dtype=float)
    d1, d2, d3 = _rotation_columns(np.moveaxis(q, -1, 0))
    return np.stack([np.moveaxis(d1, 0, -1), np.moveaxis(d2, 0, -1),
                     np.moveaxis(d3, 0, -1)], axis=-2)


def quaternion_from_frame(frames):
    r"""Unit quaternions (scalar first) of frames given as rows d1, d2, d3.

    ``frames`` has shape (3, 3) or (n, 3, 3), ``frames[k, i]`` = d_{i+1}(S_k). The
    rotation matrix is R = [d1 d2 d3] (directors as columns), orthonormalised first by its
    polar factor (petsc_rod's vertex frames are orthonormal only to its constraint
    tolerance). Shepperd's method picks the largest of 4 q0^2, 4 qx^2, ... for stability.
    For a sequence of frames the signs are made continuous (q_k . q_{k-1} >= 0), starting
    with q0 >= 0 at the first frame.
    """
    frames = np.asarray(frames, dtype=float)
    single = frames.ndim == 2
    frames = frames.reshape(-1, 3, 3)
    out = np.empty((frames.shape[0], 4))
    for k, rows in enumerate(frames):
        u_, _, vt = np.linalg.svd(rows.T)
        rot = u_ @ np.diag([1.0, 1.0, np.linalg.det(u_ @ vt)]) @ vt
        trace = np.trace(rot)
        candidates = np.array([trace, rot[0, 0], rot[1, 1], rot[2, 2]])
        i = int(np.argmax(candidates))
        if i == 0:
            w = 0.5 * np.sqrt(1.0 + trace)
            q = [w, (rot[2, 1] - rot[1, 2]) / (4 * w), (rot[0, 2] - rot[2, 0]) / (4 * w),
                 (rot[1, 0] - rot[0, 1]) / (4 * w)]
        elif i == 1:
            x = 0.5 * np.sqrt(1.0 + 2 * rot[0, 0] - trace)
            q = [(rot[2, 1] - rot[1, 2]) / (4 * x), x, (rot[0, 1] + rot[1, 0]) / (4 * x),
                 (rot[0, 2] + rot[2, 0]) / (4 * x)]
        elif i == 2:
            y = 0.5 * np.sqrt(1.0 + 2 * rot[1, 1] - trace)
            q = [(rot[0, 2] - rot[2, 0]) / (4 * y), (rot[0, 1] + rot[1, 0]) / (4 * y), y,
                 (rot[1, 2] + rot[2, 1]) / (4 * y)]
        else:
            z = 0.5 * np.sqrt(1.0 + 2 * rot[2, 2] - trace)
            q = [(rot[1, 0] - rot[0, 1]) / (4 * z), (rot[0, 2] + rot[2, 0]) / (4 * z),
                 (rot[1, 2] + rot[2, 1]) / (4 * z), z]
        out[k] = q
    if out[0, 0] < 0.0:
        out[0] = -out[0]
    for k in range(1, out.shape[0]):
        if np.dot(out[k], out[k - 1]) < 0.0:
            out[k] = -out[k]
    return out[0] if single else out


# ------------------------------------------------------------------------------- the ODE

def _strains(q, m, stiffness):
    """u_i = m . d_i / K_i and the directors, for state slices of shape (4, M), (3, M)."""
    d1, d2, d3 = _rotation_columns(q)
    u = np.stack([np.sum(m * d1, axis=0) / stiffness[0],
                  np.sum(m * d2, axis=0) / stiffness[1],
                  np.sum(m * d3, axis=0) / stiffness[2]])
    return u, (d1, d2, d3)


def _rhs(y, stiffness):
    r"""Right-hand side of the 13 ODEs for states y of shape (13, M) (real or complex).

        r' = d3,  q' = 1/2 q (x) (0, u),  n' = 0,  m' = -d3 x n.
    """
    q, n, m = y[_Q], y[_N], y[_M]
    u, (_, _, d3) = _strains(q, m, stiffness)
    w, v = q[0], q[1:]
    dq = np.concatenate([(-0.5 * np.sum(v * u, axis=0))[None],
                         0.5 * (w * u + np.cross(v, u, axis=0))])
    dm = -np.cross(d3, n, axis=0)
    return np.concatenate([d3, dq, np.zeros_like(n), dm])


def _rhs_jacobian(y, stiffness):
    """d(rhs)/dy, shape (13, 13, M), exact to rounding by complex steps."""
    jac = np.empty((_N_STATE, _N_STATE, y.shape[1]))
    for j in range(_N_STATE):
        yc = y.astype(complex)
        yc[j] += 1j * _COMPLEX_STEP
        jac[:, j, :] = _rhs(yc, stiffness).imag / _COMPLEX_STEP
    return jac


# ------------------------------------------------------------------------------ results

@dataclass
class RodBVPResult:
    """A collocation solution of the rod equations (see the module docstring).

    Arrays are sampled at the final collocation mesh ``S`` (shape (M,)); vectors have
    shape (M, 3) in the fixed basis, except ``u`` which holds (u1, u2, u3) in the
    director basis. ``sol`` is scipy's C^1 cubic interpolant of the state (13 rows: r, q,
    n, m), ``max_residual`` the largest relative collocation residual, ``bc_residual`` the
    largest boundary-condition residual, ``quaternion_norm_error`` max | |q| - 1 |.
    """

    S: np.ndarray
    r: np.ndarray
    q: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    d3: np.ndarray
    u: np.ndarray
    n: np.ndarray
    m: np.ndarray
    status: int
    success: bool
    message: str
    max_residual: float
    bc_residual: float
    quaternion_norm_error: float
    length: float
    stiffness: np.ndarray
    clamp_frame: np.ndarray
    end_position: object
    end_force: object
    tol: float
    sol: object = field(repr=False)

    def sample(self, S):
        """State at arc lengths ``S``: dict with r, d1, d2, d3, u, n, m (shape (len(S), 3))."""
        S = np.atleast_1d(np.asarray(S, dtype=float))
        y = self.sol(S)
        u, (d1, d2, d3) = _strains(y[_Q], y[_M], self.stiffness)
        return {"S": S, "r": y[_R].T, "d1": d1.T, "d2": d2.T, "d3": d3.T, "u": u.T,
                "n": y[_N].T, "m": y[_M].T, "q": y[_Q].T}

    def as_guess(self):
        """This solution as (S, r, frames, n, m), the initial-guess arguments of solve_rod_bvp."""
        frames = np.stack([self.d1, self.d2, self.d3], axis=1)
        return self.S, self.r, frames, self.n, self.m


# ------------------------------------------------------------------------------- solver

def solve_rod_bvp(length, stiffness, end_position, initial_S, initial_r, initial_frames,
                  initial_n, initial_m, tol=1e-10, max_nodes=200000, end_force=None,
                  clamp_frame=PAPER_CLAMP_FRAME, bc_tol=None):
    r"""Solve the clamped rod by collocation (equations in the module docstring).

    Parameters
    ----------
    length : float
        L > 0.
    stiffness : sequence of 3 floats
        (K1, K2, K3) > 0: bending about d1, bending about d2, torsion.
    end_position : array_like (3,) or None
        Pinned end r(L) = end_position with m(L) = 0. ``None`` for a free end loaded by
        the dead force ``end_force`` (then n(L) = end_force, m(L) = 0).
    initial_S : array_like (k,)
        Increasing arc lengths from 0 to L: the initial collocation mesh.
    initial_r, initial_n, initial_m : array_like (k, 3)
        Initial guesses of r, n, m at ``initial_S``.
    initial_frames : array_like (k, 3, 3)
        Initial director frames, ``initial_frames[j, i]`` = d_{i+1}(S_j); turned into a
        sign-continuous quaternion sequence whose first element is the clamp's.
    tol : float
        solve_bvp's relative collocation-residual tolerance.
    max_nodes : int
        Largest mesh solve_bvp may build.
    end_force : array_like (3,) or None
        The dead end force of a free end (only with ``end_position=None``).
    clamp_frame : array_like (3, 3)
        Rows d1, d2, d3 at the clamp S = 0 (default: the paper's e_y, e_z, e_x).
    bc_tol : float or None
        Boundary-condition tolerance (default: ``tol``).

    Returns
    -------
    RodBVPResult
        ``status`` and ``message`` are solve_bvp's (0 = converged); the caller decides what
        to do with a failure (nothing is raised for it).
    """
    length = float(length)
    if not (np.isfinite(length) and length > 0.0):
        raise ValueError(f"length must be positive, got {length!r}")
    stiffness = np.asarray(stiffness, dtype=float).reshape(3)
    if np.any(~np.isfinite(stiffness)) or np.any(stiffness <= 0.0):
        raise ValueError(f"stiffnesses must be positive, got {stiffness!r}")
    if (end_position is None) == (end_force is None):
        raise ValueError("give exactly one of end_position (pinned end) and end_force (free end)")
    S = np.asarray(initial_S, dtype=float)
    if S.ndim != 1 or S.size < 2 or np.any(np.diff(S) <= 0.0) or abs(S[0]) > 1e-12 * length \
            or abs(S[-1] - length) > 1e-12 * length:
        raise ValueError("initial_S must increase strictly from 0 to length")
    S = S.copy()
    S[0], S[-1] = 0.0, length
    clamp_frame = np.asarray(clamp_frame, dtype=float).reshape(3, 3)
    if not (np.allclose(clamp_frame @ clamp_frame.T, np.eye(3), atol=1e-12)
            and np.linalg.det(clamp_frame) > 0.0):
        raise ValueError("clamp_frame must be a right-handed orthonormal frame (rows d1, d2, d3)")
    q_clamp = quaternion_from_frame(clamp_frame)

    q_guess = quaternion_from_frame(initial_frames)
    if np.dot(q_guess[0], q_clamp) < 0.0:
        q_guess = -q_guess
    y_guess = np.concatenate([np.asarray(initial_r, dtype=float).T, q_guess.T,
                              np.asarray(initial_n, dtype=float).T,
                              np.asarray(initial_m, dtype=float).T])
    if y_guess.shape != (_N_STATE, S.size):
        raise ValueError("initial guesses must have one row per entry of initial_S")

    pinned = end_position is not None
    end_value = np.asarray(end_position if pinned else end_force, dtype=float).reshape(3)

    def fun(_, y):
        return _rhs(y, stiffness)

    def fun_jac(_, y):
        return _rhs_jacobian(y, stiffness)

    def bc(ya, yb):
        end = yb[_R] if pinned else yb[_N]
        return np.concatenate([ya[_R], ya[_Q] - q_clamp, end - end_value, yb[_M]])

    def bc_jac(ya, yb):
        jac_a = np.zeros((_N_STATE, _N_STATE))
        jac_b = np.zeros((_N_STATE, _N_STATE))
        jac_a[0:7, 0:7] = np.eye(7)
        jac_b[7:10, _R if pinned else _N] = np.eye(3)
        jac_b[10:13, _M] = np.eye(3)
        return jac_a, jac_b

    sol = solve_bvp(fun, bc, S, y_guess, fun_jac=fun_jac, bc_jac=bc_jac, tol=tol,
                    max_nodes=max_nodes, bc_tol=tol if bc_tol is None else bc_tol)
    y = sol.y
    u, (d1, d2, d3) = _strains(y[_Q], y[_M], stiffness)
    residual = float(np.max(sol.rms_residuals)) if sol.rms_residuals is not None else np.inf
    return RodBVPResult(
        S=sol.x, r=y[_R].T, q=y[_Q].T, d1=d1.T, d2=d2.T, d3=d3.T, u=u.T, n=y[_N].T,
        m=y[_M].T, status=int(sol.status), success=bool(sol.success), message=sol.message,
        max_residual=residual, bc_residual=float(np.max(np.abs(bc(y[:, 0], y[:, -1])))),
        quaternion_norm_error=float(np.max(np.abs(np.sqrt(np.sum(y[_Q] ** 2, axis=0)) - 1))),
        length=length, stiffness=stiffness, clamp_frame=clamp_frame,
        end_position=None if not pinned else end_value.copy(),
        end_force=None if pinned else end_value.copy(), tol=float(tol), sol=sol.sol)


def _refined(S, times):
    """``S`` with every interval bisected ``times`` times."""
    for _ in range(times):
        S = np.sort(np.concatenate([S, 0.5 * (S[1:] + S[:-1])]))
    return S


def _resolve(result, tol, S):
    """Solve ``result``'s problem again at ``tol``, started from ``result`` sampled at ``S``."""
    state = result.sample(S)
    frames = np.stack([state["d1"], state["d2"], state["d3"]], axis=1)
    return solve_rod_bvp(result.length, result.stiffness, result.end_position, S, state["r"],
                         frames, state["n"], state["m"], tol=tol, end_force=result.end_force,
                         clamp_frame=result.clamp_frame)


# ------------------------------------------------------------------------------ outputs

def energy(result):
    r"""Stored energy W = int_0^L 1/2 (K1 u1^2 + K2 u2^2 + K3 u3^2) dS (no loads).

    For a :class:`RodBVPResult` the integral is taken over the collocation mesh with a
    6-point Gauss rule per interval on scipy's cubic interpolant of (q, m), from which
    u_i = m . d_i / K_i. For a dict of vertex samples (``S``, ``u`` and ``stiffness``, as
    from :func:`initial_guess_from_result`) the trapezoidal rule is used instead.
    """
    if isinstance(result, RodBVPResult):
        a, b = result.S[:-1], result.S[1:]
        half = 0.5 * (b - a)
        points = (0.5 * (a + b))[:, None] + half[:, None] * _GAUSS_POINTS[None, :]
        y = result.sol(points.ravel())
        u, _ = _strains(y[_Q], y[_M], result.stiffness)
        density = 0.5 * np.sum(result.stiffness[:, None] * u ** 2, axis=0).reshape(points.shape)
        return float(np.sum(half * (density @ _GAUSS_WEIGHTS)))
    stiffness = np.asarray(result["stiffness"], dtype=float)
    density = 0.5 * np.sum(stiffness[None, :] * np.asarray(result["u"]) ** 2, axis=1)
    S = np.asarray(result["S"])
    return float(np.sum(0.5 * (density[1:] + density[:-1]) * np.diff(S)))


def self_check(result, coarse_tol=1e-8, fine_tol=1e-10, coarse_nodes=81, refinements=2,
               samples=4001):
    r"""Error estimate: the same problem solved coarsely and finely, and compared.

    1. *coarse*: ``result`` sampled at ``coarse_nodes`` equally spaced points is the
       initial mesh and guess of a solve at ``tol = coarse_tol`` (solve_bvp only ever
       adds nodes, so starting from a coarse mesh makes this a genuine ``coarse_tol``
       solution, not a copy of ``result``);
    2. *fine*: the coarse solution on its own mesh bisected ``refinements`` times
       (the method is of 4th order: each bisection divides the error by about 16),
       solved at ``tol = fine_tol``.

    The two are compared at ``samples`` equally spaced arc lengths. The fine error is much
    smaller than the coarse one, so the difference estimates the error of a
    ``coarse_tol`` solution. Measured on the paper scene (X_F = 16) against a tol-1e-10
    solution on a twice-bisected mesh, the maximum position errors are 3.7e-10 at
    tol 1e-8, 1.1e-11 at tol 1e-9 and 7e-13 at tol 1e-10. (solve_bvp cannot reach
    tol = 1e-11 on this problem: its residual estimate meets the rounding floor and the
    mesh grows to ``max_nodes``; hence the refined node set for the fine solve.)

    Returns
    -------
    dict
        ``position``: max |r_coarse - r_fine|; ``frame``: max |d_i coarse - d_i fine|;
        ``u3_clamp``: |u3_coarse(0) - u3_fine(0)|; ``end_force``: |n_coarse(L) - n_fine(L)|;
        ``energy``: |W_coarse - W_fine|; ``coarse_status``, ``fine_status`` (0 = converged);
        ``coarse``, ``fine``: the two :class:`RodBVPResult`.
    """
    coarse = _resolve(result, coarse_tol, np.linspace(0.0, result.length, coarse_nodes))
    fine = _resolve(coarse, fine_tol, _refined(coarse.S, refinements))
    grid = np.linspace(0.0, result.length, samples)
    a, b = coarse.sample(grid), fine.sample(grid)
    return {
        "position": float(np.max(np.linalg.norm(a["r"] - b["r"], axis=1))),
        "frame": float(max(np.max(np.linalg.norm(a[k] - b[k], axis=1))
                           for k in ("d1", "d2", "d3"))),
        "u3_clamp": float(abs(coarse.u[0, 2] - fine.u[0, 2])),
        "end_force": float(np.linalg.norm(coarse.n[-1] - fine.n[-1])),
        "energy": float(abs(energy(coarse) - energy(fine))),
        "coarse_status": coarse.status, "fine_status": fine.status,
        "coarse": coarse, "fine": fine,
    }


# --------------------------------------------------------------------- initial guesses

# The options of a line whose stiffness varies along S (Scene.sections): the reference
# takes one stiffness triple (K_i constant in u_i = m . d_i / K_i) and refuses them.
SECTION_OPTIONS = ("-rod_sections", "-rod_line_types")

def initial_guess_from_result(path):
    """Initial guess from a petsc_rod HDF5 result file (format: docs/output.md).

    Reads the vertex datasets ``S`` (n,), ``r``, ``d1``, ``d2``, ``d3``, ``u``, ``n``,
    ``m`` (n, 3) of the file's last step (the root links to it), and the stiffness from
    the ``options`` attribute when present (``-rod_stiffness K1,K2,K3``).

    Returns
    -------
    dict
        ``S``, ``r``, ``frames`` (n, 3, 3) with rows d1, d2, d3, ``n``, ``m``, ``u``,
        ``energy`` (the file's attribute, or None) and ``stiffness`` (or None); the first
        five are the initial-guess arguments of :func:`solve_rod_bvp`.
    """
    import h5py

    with h5py.File(path, "r") as f:
        data = {key: np.array(f[key], dtype=float) for key in
                ("S", "r", "d1", "d2", "d3", "u", "n", "m")}
        stored_energy = float(f.attrs["energy"]) if "energy" in f.attrs else None
        options = f.attrs.get("options", "")
    if isinstance(options, bytes):
        options = options.decode()
    stiffness = None
    for line in str(options).splitlines():
        words = line.split()
        if words and words[0] in SECTION_OPTIONS:
            raise ValueError(f"{path}: a line of sections ({words[0]}); the collocation "
                             "reference solves a line of one stiffness only")
        if len(words) == 2 and words[0] == "-rod_stiffness":
            stiffness = np.array([float(v) for v in words[1].split(",")])
    frames = np.stack([data["d1"], data["d2"], data["d3"]], axis=1)
    return {"S": data["S"], "r": data["r"], "frames": frames, "n": data["n"],
            "m": data["m"], "u": data["u"], "energy": stored_energy, "stiffness": stiffness}


def planar_guess(end_x, length=20.0, nodes=81):
    r"""A rough planar guess (z = 0, d2 = e_z) for the paper's pinned scene.

    Heading h(S) = c s (2 - s), s = S/L (zero curvature at the pinned end), with
    c = 1.5 atan2(L - end_x, end_x) so that the chord points roughly at (end_x, L - end_x);
    d3 = (cos h, sin h, 0), d1 = (-sin h, cos h, 0), d2 = e_z; r by the trapezoidal rule
    on r' = d3; n a unit compression along the chord and m(S) = (r(L) - r(S)) x n (the
    moment balance for constant n with m(L) = 0). The plane z = 0 with d2 = e_z is
    invariant under the ODE, the boundary conditions and Newton's method, so this guess
    leads to the planar branch. Returns (S, r, frames, n, m).
    """
    S = np.linspace(0.0, length, nodes)
    s = S / length
    heading = 1.5 * np.arctan2(length - end_x, end_x) * s * (2.0 - s)
    zero, one = np.zeros_like(S), np.ones_like(S)
    d1 = np.stack([-np.sin(heading), np.cos(heading), zero], axis=1)
    d2 = np.stack([zero, zero, one], axis=1)
    d3 = np.stack([np.cos(heading), np.sin(heading), zero], axis=1)
    r = np.concatenate([np.zeros((1, 3)),
                        np.cumsum(0.5 * (d3[1:] + d3[:-1]) * np.diff(S)[:, None], axis=0)])
    chord = np.array([end_x, length - end_x, 0.0])
    n = np.tile(-chord / np.linalg.norm(chord), (nodes, 1))
    m = np.cross(r[-1] - r, n)
    return S, r, np.stack([d1, d2, d3], axis=1), n, m


def solve_paper_scene(end_x, guess, stiffness=(235.0, 360.0, 200.0), length=20.0,
                      tol=1e-10, steps=1, nodes=201):
    r"""The paper's scene (docs/method.md §8) at X_F = ``end_x``, by continuation in X_F.

    Clamp at S = 0 (r = 0, d1 = e_y, d2 = e_z, d3 = e_x), pinned end
    r(L) = (X_F, L - X_F, 0), m(L) = 0. ``guess`` is (S, r, frames, n, m) (e.g. from
    :func:`initial_guess_from_result`, :func:`shooting_guess`, :func:`planar_guess`) or a
    :class:`RodBVPResult` at some X_F0. The end is moved from the guess's r(L) to the
    target in ``steps`` equal steps along the straight line (a tuple guess is used as it
    is for the first step, so with ``steps=1`` it is simply a guess for the target, and
    its r(L) need not be exact); each later solve starts from the
    previous solution resampled at ``nodes`` equally spaced points (solve_bvp never
    removes nodes, so without resampling the mesh of a long continuation only grows).
    Returns the last :class:`RodBVPResult` (check its ``status``: a failed step is
    returned as it is).
    """
    if isinstance(guess, RodBVPResult):
        start, result, first = guess.r[-1].copy(), guess, None
    else:
        start, result, first = np.asarray(guess[1], dtype=float)[-1], None, guess
    target = np.array([end_x, length - end_x, 0.0])
    for k in range(1, steps + 1):
        end = start + (target - start) * k / steps
        if result is None:
            S, r, frames, n, m = first
        else:
            S = np.linspace(0.0, length, nodes)
            state = result.sample(S)
            r, n, m = state["r"], state["n"], state["m"]
            frames = np.stack([state["d1"], state["d2"], state["d3"]], axis=1)
        result = solve_rod_bvp(length, stiffness, end, S, r, frames, n, m, tol=tol)
        if result.status != 0:
            return result
    return result


def solve_cantilever_bvp(length, bending_stiffness, force, tol=1e-10, nodes=41, steps=1):
    r"""Planar cantilever by the same collocation: clamp at 0, dead tip force (0, -P, 0).

    The rod lies along +x with the paper's clamp frame (d1 = e_y, d2 = e_z, d3 = e_x), so
    it bends in the x-y plane about d2: K = (EI, EI, EI) (only K2 matters for the planar
    solution). Free end: n(L) = (0, -P, 0), m(L) = 0, r(L) unknown. Started from the
    straight rod with n = F and m(S) = (r(L) - r(S)) x F, with ``steps`` load steps.
    Compare r(L)[:2] with ``closed_forms.cantilever_tip(length, bending_stiffness, force)``.
    """
    S = np.linspace(0.0, length, nodes)
    r = np.stack([S, 0 * S, 0 * S], axis=1)
    frames = np.tile(PAPER_CLAMP_FRAME, (nodes, 1, 1))
    m = None
    result = None
    for k in range(1, steps + 1):
        load = np.array([0.0, -force * k / steps, 0.0])
        if result is not None:
            S, r, frames, _, m = result.as_guess()
        n = np.tile(load, (S.size, 1))
        if m is None:
            m = np.cross(r[-1] - r, n)
        result = solve_rod_bvp(length, (bending_stiffness,) * 3, None, S, r, frames, n, m,
                               tol=tol, end_force=load)
        if result.status != 0:
            return result
    return result


def shooting_guess(length, stiffness, force, moment, nodes=81, clamp_frame=PAPER_CLAMP_FRAME):
    r"""Initial guess by integrating the rod ODEs from the clamp as an initial-value problem.

    With r(0) = 0, q(0) = q_clamp and the clamp reactions n(0) = ``force``,
    m(0) = ``moment`` given (e.g. rounded values of a known solution), the 13 ODEs of the
    module docstring are integrated to S = L by scipy's DOP853 (rtol 1e-10) and sampled at
    ``nodes`` equally spaced points. Six numbers thus define a complete, consistent guess
    (it satisfies every equation and the clamp conditions, and misses only the end
    conditions), close to the solution they were taken from when the IVP is not too
    sensitive over [0, L]. Returns (S, r, frames, n, m).
    """
    from scipy.integrate import solve_ivp

    stiffness = np.asarray(stiffness, dtype=float).reshape(3)
    y0 = np.concatenate([np.zeros(3), quaternion_from_frame(clamp_frame),
                         np.asarray(force, dtype=float), np.asarray(moment, dtype=float)])
    S = np.linspace(0.0, float(length), nodes)
    ivp = solve_ivp(lambda _, y: _rhs(y[:, None], stiffness)[:, 0], (0.0, float(length)), y0,
                    method="DOP853", t_eval=S, rtol=1e-10, atol=1e-12)
    if ivp.status != 0:
        raise RuntimeError(f"shooting guess: {ivp.message}")
    y = ivp.y
    frames = frame_from_quaternion(y[_Q].T)
    return S, y[_R].T, frames, y[_N].T, y[_M].T
