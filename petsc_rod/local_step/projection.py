"""The local step of the Uzawa iteration (docs/method.md §3 steps 2 and 3): the nearest
rotation at every node and the multiplier update, numpy only, vectorised over points.

Arrays of frames have shape (..., 3, 3) with rows d1, d2, d3 (docs/method.md §3).
"""

import threading

import numpy as np


# The projection works on blocks of BLOCK points: its work arrays (250 bytes a point,
# 2 MB) stay in cache across the twenty-odd elementwise operations of a Newton step, and
# each numpy call still has thousands of points to amortise its overhead on.
BLOCK = 8192
# After the first step every singular value of the Newton iterate X_k is >= 1, so
# |X_k - T| <= det X_k - 1 and the next step leaves |X_k - T|^2 / 2: below NEWTON_TOL
# that step is the last.
NEWTON_TOL = 1e-8
# Newton takes the points with det b > SINGULAR |b|_F^3 (below, det b is round-off of a
# singular b, or b is a reflection) and det b in DET_RANGE (cofactors neither over- nor
# underflow); of those, det X_1 - 1 grows like cond(b)^(4/3) / 8, and above
# ILL_CONDITIONED (cond b about 1e3) a point leaves Newton too. The others go to the
# eigen-solve.
SINGULAR = 1e-6
ILL_CONDITIONED = 1e3
DET_RANGE = (1e-290, 1e290)
MAX_STEPS = 10
# From this step on, once 7/8 of a block has converged the rest goes on as a smaller block.
COMPACT_AFTER = 3
# update_multipliers works on this many values at a time, through one reused buffer.
CHUNK = 1 << 17

_EYE = np.eye(3)[:, :, None]
_BUFFERS = threading.local()


def nearest_rotation(b, out=None):
    """The local step (§3 step 2): tau = argmax_{T in SO(3)} sum_i T_i . b_i.

    b: (..., 3, 3), rows b_i = R d_i + lambda_i. With b = U S V^T (SVD), the maximiser is
    T = U diag(1, 1, det(U V^T)) V^T: the polar factor of b with the sign fixed so that
    det T = +1 also when b is singular or a reflection. Returns (..., 3, 3), in ``out``
    when given (it may be b itself).

    Where det b > 0 and b is not ill-conditioned (every point of a running iteration,
    where b is near R times a rotation) T is the polar factor, by the scaled Newton
    iteration X <- (zeta X + (zeta X)^-T) / 2, zeta = det(X)^(-1/3) (polar_newton), on
    blocks of points so that its temporaries stay in cache. The other points (singular,
    reflected, ill-conditioned) are shifted to a matrix whose polar factor is T (shifted)
    and go through Newton again; what is left (rank 1, reflections with s2 = s3: several
    maximisers) goes to the eigen-solve of Horn's quaternion matrix
    (nearest_rotation_eigen). A b with NaN or Inf gives NaN.
    """
    b = np.asarray(b, dtype=float)
    if b.shape[-2:] != (3, 3):
        raise ValueError(f"nearest_rotation: b has shape {b.shape}, expected (..., 3, 3)")
    if out is None:
        out = np.empty(b.shape)
    elif (out.shape != b.shape or out.dtype != np.float64
          or not out.flags.c_contiguous):
        raise ValueError(f"nearest_rotation: out is {out.dtype} {out.shape}, expected a "
                         f"contiguous float64 array of shape {b.shape}")
    flat = b.reshape(-1, 3, 3)
    t = out.reshape(-1, 3, 3)
    pending = []        # (indices, copies of b) of points Newton left out, up to a block
    aliased = np.may_share_memory(out, b)   # then b is read from a copy of each block
    # a point where Newton breaks down (overflow, 0/0) fails its tests and is set aside
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for start in range(0, len(flat), BLOCK):
            block = flat[start:start + BLOCK]
            if aliased:
                copy = _buffer("block", block.size).reshape(block.shape)
                np.copyto(copy, block)
                block = copy
            missed = polar_newton(block, t[start:start + BLOCK])
            if missed is not None:
                pending.append((start + np.flatnonzero(missed), block[missed]))
            # together, a block at a time: a few per block would each cost a block's calls
            if pending and (sum(len(w) for w, _ in pending) >= BLOCK
                            or start + BLOCK >= len(flat)):
                where = np.concatenate([w for w, _ in pending])
                hard = np.concatenate([h for _, h in pending])
                rotation = np.empty_like(hard)
                left = polar_newton(shifted(hard), rotation)
                if left is not None:
                    rotation[left] = nearest_rotation_eigen(hard[left])
                t[where] = rotation
                pending = []
    return out


def shifted(b):
    """b + cof(b) / s1 for (m, 3, 3) b: where its det is > 0, its polar factor is T(b).

    With b = U diag(s1, s2, s3) V^T, U and V rotations (s3 < 0 for a reflection), the
    cofactor matrix is U diag(s2 s3, s1 s3, s1 s2) V^T, so b + a cof(b) = U diag(s1 + a s2
    s3, s2 + a s1 s3, s3 + a s1 s2) V^T. For 0 < a <= 1/s1 the first entry is positive,
    and where the shifted matrix has det > 0 so are the others (for a reflection when
    s3 < s2, a unique maximiser): its polar factor is U V^T, the maximiser of b, with
    condition s1 / (s2 + s3) like the maximiser's own. Reflections and singular b thus
    go through Newton as well. s1^2 <= mu: Newton on det(mu I - b^T b) from mu = |b|_F^2.
    """
    cof = np.cross(b[:, [1, 2, 0]], b[:, [2, 0, 1]])
    frobenius = np.einsum("nij,nij->n", b, b)
    minors = np.einsum("nij,nij->n", cof, cof)
    det = np.einsum("nj,nj->n", b[:, 0], cof[:, 0])
    mu = frobenius.copy()
    for _ in range(3):
        mu -= (((mu - frobenius) * mu + minors) * mu - det * det) / (
            (3.0 * mu - 2.0 * frobenius) * mu + minors)
    return b + cof / np.sqrt(mu)[:, None, None]


def polar_newton(b, out, steps=None, iterate=False):
    """Orthogonal polar factors of the (nb, 3, 3) matrices b into out, where Newton suits.

    Scaled Newton X <- (zeta X + (zeta X)^-T) / 2, zeta = det(X)^(-1/3), carried as the
    multiple M = 2 X / zeta_prev: M <- M + zeta C(M), C the cofactor matrix (so that
    X^-T = C / det), two operations per component instead of three; zeta is scale free.
    The nine components are contiguous rows of length nb, each row of M extended by its
    first two columns, so that the cross products C_i = M_(i+1) x M_(i+2) are three
    products of contiguous slices. Once 7/8 of the points have converged the others go on
    as a smaller block (their X, with ``iterate``: its singular values are >= 1), so that a
    few slow points do not hold the whole block. Returns the mask of the points left out
    (their out is meaningless), or None.
    """
    nb = len(b)
    steps = MAX_STEPS if steps is None else steps
    s = _buffer("rows", 15 * nb).reshape(3, 5, nb)
    cof = _buffer("cofactors", 9 * nb).reshape(3, 3, nb)
    tmp = _buffer("product", 3 * nb).reshape(3, nb)
    det, previous, ratio, zeta = (_buffer(name, nb)
                                  for name in ("det", "previous", "ratio", "zeta"))
    m = s[:, :3]
    np.copyto(m, b.transpose(1, 2, 0))
    np.multiply(m, m, out=cof)
    frobenius = np.sum(cof.reshape(9, nb), axis=0, out=ratio)   # |b|_F^2
    done = converged = False
    for step in range(steps):
        np.copyto(s[:, 3:], s[:, :2])
        for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
            np.multiply(s[j, 1:4], s[k, 2:5], out=cof[i])
            np.multiply(s[j, 2:5], s[k, 1:4], out=tmp)
            np.subtract(cof[i], tmp, out=cof[i])
        np.multiply(m[0], cof[0], out=tmp)
        np.add(tmp[0], tmp[1], out=det)
        np.add(det, tmp[2], out=det)
        if step == 0:
            np.multiply(frobenius, frobenius, out=zeta)
            zeta *= frobenius
            zeta *= SINGULAR**2
            missed = ~((det > DET_RANGE[0]) & (det < DET_RANGE[1]) & (det * det > zeta))
            if missed.all():
                return missed
            _set_identity(missed, m, cof, det)
            if iterate:
                np.multiply(det, 8.0, out=ratio)
        else:
            np.divide(det, previous, out=ratio)     # det M_k / det M_(k-1) = 8 det X_k
        if step == 1 and not iterate:   # det X_1 >= 1 in exact arithmetic: below 1/2 a breakdown
            ill = ~((ratio > 4.0) & (ratio < 8.0 * (1.0 + ILL_CONDITIONED)))
            missed |= ill
            _set_identity(ill, m, cof, det)
            ratio[ill] = 8.0
        np.cbrt(det, out=zeta)
        np.divide(1.0, zeta, out=zeta)
        np.multiply(cof, zeta, out=cof)
        if step > 0 or iterate:
            converged = ratio.max() < 8.0 * (1.0 + NEWTON_TOL)
            done = converged or step == steps - 1
            if not done and step >= COMPACT_AFTER:
                slow = ~(ratio < 8.0 * (1.0 + NEWTON_TOL))
                done = np.count_nonzero(slow) <= nb // 8
        np.add(m, cof, out=m)
        if done:
            break
        det, previous = previous, det
    zeta *= 0.5
    np.multiply(m, zeta, out=cof)
    np.copyto(out.reshape(nb, 9), cof.reshape(9, nb).T)
    if not converged:
        slow = (~(ratio < 8.0 * (1.0 + NEWTON_TOL)) if step > 0 or iterate
                else np.ones(nb, dtype=bool))
        if step < steps - 1 and slow.any():
            # X_(k+1) of the slow points is in out: continue from it as a block of its own
            sub = np.flatnonzero(slow)
            x = out[sub]
            slow_missed = polar_newton(x, x, steps - step - 1, iterate=True)
            out[sub] = x
            slow[sub] = False if slow_missed is None else slow_missed
        missed |= slow
    return missed if missed.any() else None


def _set_identity(mask, m, cof, det):
    """Points left to the eigen-solve become X = I (converged at once), if any."""
    if mask.any():
        m[:, :, mask] = _EYE
        cof[:, :, mask] = _EYE
        det[mask] = 1.0


def _buffer(name, size):
    """This thread's work array ``name``, its first ``size`` values: allocated once (and
    when a larger one is asked for), not at every call."""
    buffers = _BUFFERS.__dict__.setdefault("arrays", {})
    array = buffers.get(name)
    if array is None or array.size < size:
        array = buffers[name] = np.empty(size)
    return array[:size]


def nearest_rotation_eigen(b):
    """The maximiser for any (n, 3, 3) b, by Horn's quaternion method.

    With T = T(q) for a unit quaternion q, sum_i T_i . b_i = q^T K q, K the symmetric
    traceless 4 x 4 matrix of b (horn_matrix): q is the eigenvector of the largest
    eigenvalue of K (LAPACK), which is s1 + s2 + sign(det b) s3, and T(q) is a proper
    rotation whatever b (singular, reflected). One symmetric eigen-solve per point
    instead of an SVD. A b with NaN or Inf gives NaN.
    """
    b = np.asarray(b, dtype=float).reshape(-1, 3, 3)
    finite = np.isfinite(b).all(axis=(1, 2))
    if finite.all():
        return quaternion_rotation(np.linalg.eigh(horn_matrix(b))[1][:, :, 3])
    t = np.full(b.shape, np.nan)
    t[finite] = nearest_rotation_eigen(b[finite])
    return t


def horn_matrix(b):
    """K (n, 4, 4) with q^T K q = sum_ij T(q)_ij b_ij (quaternion_rotation), q = (w, x, y, z)."""
    (b00, b01, b02), (b10, b11, b12), (b20, b21, b22) = b.transpose(1, 2, 0)
    k = np.empty((len(b), 4, 4))
    k[:, 0, 0] = b00 + b11 + b22
    k[:, 1, 1] = b00 - b11 - b22
    k[:, 2, 2] = b11 - b00 - b22
    k[:, 3, 3] = b22 - b00 - b11
    for (i, j), value in {(0, 1): b21 - b12, (0, 2): b02 - b20, (0, 3): b10 - b01,
                          (1, 2): b01 + b10, (1, 3): b02 + b20, (2, 3): b12 + b21}.items():
        k[:, i, j] = k[:, j, i] = value
    return k


def quaternion_rotation(q):
    """Rotation matrices (n, 3, 3) of unit quaternions q = (w, x, y, z), (n, 4)."""
    w, x, y, z = q.T
    return np.stack([w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
                    axis=1).reshape(-1, 3, 3)


def nearest_rotation_svd(b):
    """The same maximiser by SVD, for any (n, 3, 3), singular or reflected included."""
    u, _, vt = np.linalg.svd(b)
    sign = np.where(np.linalg.det(u @ vt) < 0, -1.0, 1.0)
    u[..., :, 2] *= sign[..., None]
    return u @ vt


def update_multipliers(lam, directors, tau, penalty):
    """Multiplier update (§3 step 3): lambda_i <- lambda_i + R (d_i - tau_i), in place.

    In chunks through one small buffer: no temporaries of the size of lambda (arrays of
    other shapes are broadcast the plain way).
    """
    if not (lam.flags.c_contiguous and lam.shape == np.shape(directors) == np.shape(tau)):
        lam += penalty * (directors - tau)
        return lam
    flat_lam, flat_d, flat_tau = (np.asarray(a).reshape(-1) for a in (lam, directors, tau))
    buffer = _buffer("chunk", min(CHUNK, flat_lam.size))
    for start in range(0, flat_lam.size, CHUNK):
        part = slice(start, start + CHUNK)
        tmp = buffer[:len(flat_lam[part])]
        np.subtract(flat_d[part], flat_tau[part], out=tmp)
        tmp *= penalty
        flat_lam[part] += tmp
    return lam


# The stretched local step (stretched_rotation) stops its majorise-minimise passes once
# no point's 1 + eps moves by more than STRETCH_TOL in a pass, after at most
# STRETCH_PASSES; what is left is carried to the next iteration in the state (the
# passes start from the last 1 + eps), so a fixed point of the iteration is one of the
# passes too, whatever their number. The iteration takes ITERATION_PASSES: one pass
# an iteration, the pass joining the fixed-point iteration, took as few iterations as
# converged passes at half the cost (docs/method.md §12).
STRETCH_TOL = 1e-14
STRETCH_PASSES = 8
ITERATION_PASSES = 1


def stretched_rotation(b, axial, penalty, start=None, out=None, passes=STRETCH_PASSES):
    """The local step with axial stretch (docs/method.md §12): at each node maximise over
    T in SO(3) and k = 1 + eps

        b1.T1 + b2.T2 + k b3.T3 - R k^2 / 2 - EA (k - 1)^2 / 2,

    i.e. minimise sum_i [R/2 |g_i - t_i|^2 - lambda_i.t_i] + EA eps^2 / 2 over the targets
    t = (T1, T2, k T3), b_i = R g_i + lambda_i. For fixed T, k = (b3.T3 + EA)/(R + EA); T
    then maximises b1.T1 + b2.T2 + (b3.T3 + EA)^2 / (2 (R + EA)), a convex function of
    T: its tangent at T_j is a minorant, whose maximiser is the polar factor of b with
    the row b3 scaled by k_j (nearest_rotation). Each pass thus increases the objective
    (majorise-minimise); it contracts by about R/(R + EA) times the misalignment of the
    rows of b, a few passes at EA >> R.

    b: (n, 3, 3) rows b_i, N; axial: EA (n,), N (inf: k = 1, the plain projection);
    penalty: R, N; start: k of the first pass (n,) (default 1); passes: at most that
    many (each one polar factor per point). k is kept >= 0 (a line is not turned inside
    out). Returns the targets (n, 3, 3), rows (T1, T2, k T3), in
    ``out`` when given (it may be b itself): |row 3| - 1 is the strain eps.
    """
    b = np.array(b, dtype=float)            # a copy: out may be b
    n = b.shape[0]
    finite = np.isfinite(axial)
    ea = np.where(finite, axial, 0.0)
    k = np.ones(n) if start is None else np.where(finite, start, 1.0)
    scaled = np.empty_like(b)
    rotation = np.empty_like(b)
    for _ in range(passes):
        np.copyto(scaled, b)
        scaled[:, 2] *= k[:, None]
        nearest_rotation(scaled, out=rotation)
        s = np.einsum("nc,nc->n", b[:, 2], rotation[:, 2])
        new = np.where(finite, np.maximum((s + ea) / (penalty + ea), 0.0), 1.0)
        moved = np.abs(new - k).max(initial=0.0)
        k = new
        if moved <= STRETCH_TOL:
            break
    if out is None:
        out = np.empty_like(b)
    np.copyto(out, rotation)
    out[:, 2] *= k[:, None]
    return out
