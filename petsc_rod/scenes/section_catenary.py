"""The inextensible catenary of a line of sections (numpy only): the start of a line whose
weight changes along it (a lazy wave's buoyancy section, a clump), starts.py.

A perfectly flexible line of length L carries a vertical load per metre -w(S) e_z,
piecewise constant (w_k > 0 down, < 0 buoyant), from the start at the origin to the end
a horizontal distance X along e_h and Z up. Its force n(S), the pull of the part beyond S
on the part before, is H e_h + V(S) e_z with H constant and V' = w (n' + f = 0); its
tangent is n / |n|. On a piece of length dS and weight w starting at V0 (V1 = V0 + w dS,
|n| = sqrt(H^2 + V^2)) the line advances by

    dx = (H / w) (asinh(V1 / H) - asinh(V0 / H))     (H dS / |n| as w -> 0),
    dz = (|n1| - |n0|) / w = dS (V0 + V1) / (|n0| + |n1|)     (no cancellation).

Two unknowns fix the shape: H, and either V(0) (the line hangs from the start) or the
grounded length a (the start lies on a flat, frictionless seabed: the line rests on it,
straight and under the tension H, up to the touchdown point S = a, where it lifts off
with V(a) = 0). H makes the span X for a given V(0) or a (x(L) grows with H), and the
rise Z fixes the other: z(L) grows with V(0), and falls as a grows where the weight at
the touchdown w(a) is positive (dz(L)/da = -w(a) det / (dx(L)/dH), det >= 0 by
Cauchy-Schwarz). Both are bracketed and bisected to adjacent doubles
(catenary.increasing_roots). A line that rests on the seabed must leave it going up and
stay above it: a touchdown on a buoyant or weightless piece, or a suspended part that
dips below the seabed (a sag bend after a buoyant arch in shallow water), is refused. A
uniform weight gives the catenary and the catenary with touchdown of catenary.py and
touchdown.py.
"""

import functools
from dataclasses import dataclass

import numpy as np

from petsc_rod.scenes.catenary import increasing_roots

# A piece whose weight changes V by less than this fraction of |n| is taken as straight
# in dx (the error is of its square).
STRAIGHT_PIECE = 1e-8
# The most doublings of a bracket before the scene is said to have no catenary, and how
# many are tried in one call.
MAX_DOUBLINGS = 200
CHUNK = 8
INNER_DEPTH, OUTER_DEPTH = 4, 4


@dataclass(frozen=True)
class SectionCatenary:
    """The solved line: H (N), the grounded length a (m, 0 when it hangs from the start),
    V(0) (N) and the pieces (ends (m + 1,) in S, weights (m,) N/m)."""

    H: float
    grounded: float
    V0: float
    ends: np.ndarray
    weights: np.ndarray

    def _pieces(self):
        """The suspended pieces: their starts, lengths and weights, and x, z, V at their
        starts (the grounded stretch [0, a] is straight along e_h, at V = 0)."""
        ends = np.concatenate([[self.grounded], self.ends[self.ends > self.grounded]])
        weights = self.weights[np.searchsorted(self.ends, ends[:-1], side="right") - 1]
        lengths = np.diff(ends)
        V = self.V0 + np.concatenate([[0.0], np.cumsum(weights * lengths)])
        dx, dz = advance(self.H, V[:-1], weights, lengths)
        x = self.grounded + np.concatenate([[0.0], np.cumsum(dx)])
        z = np.concatenate([[0.0], np.cumsum(dz)])
        return ends, weights, x, z, V

    def end_point(self):
        """(x(L), z(L)), m."""
        _, _, x, z, _ = self._pieces()
        return x[-1], z[-1]

    def at(self, S):
        """(x, z, V) at arc lengths S (any shape): m, m, N."""
        S = np.asarray(S, dtype=float)
        ends, weights, x, z, V = self._pieces()
        piece = np.clip(np.searchsorted(ends, S, side="right") - 1, 0, len(weights) - 1)
        length = np.clip(S - ends[piece], 0.0, None)
        dx, dz = advance(self.H, V[piece], weights[piece], length)
        on_seabed = S < self.grounded
        return (np.where(on_seabed, S, x[piece] + dx), np.where(on_seabed, 0.0, z[piece] + dz),
                np.where(on_seabed, 0.0, V[piece] + weights[piece] * length))


def advance(H, V0, w, dS):
    """(dx, dz) over pieces of lengths dS and weights w (N/m) from V0 (N), at the
    horizontal force H (N) (module docstring); arrays broadcast."""
    V0, w, dS = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (V0, w, dS)))
    V1 = V0 + w * dS
    n0, n1 = np.hypot(H, V0), np.hypot(H, V1)
    dz = dS * (V0 + V1) / (n0 + n1)
    straight = np.abs(w * dS) <= STRAIGHT_PIECE * n0
    safe_w = np.where(straight, 1.0, w)
    curved = (H / safe_w) * (np.arcsinh(V1 / H) - np.arcsinh(V0 / H))
    middle = np.hypot(H, 0.5 * (V0 + V1))
    return np.where(straight, H * dS / middle, curved), dz


def end_points(ends, weights, H, grounded, V0):
    """(x(L), z(L)) of many lines of the same pieces (ends (m + 1,), weights (m,)), m:
    line i has the horizontal force H[i] (N), the grounded length grounded[i] (m) and
    V(0) V0[i] (N), arrays that broadcast. SectionCatenary.end_point's numbers, to the
    bit: a piece on the seabed is one of length 0, which adds exact zeros."""
    H, grounded, V0 = (np.asarray(v, dtype=float)[..., None] for v in (H, grounded, V0))
    starts = np.maximum(ends[:-1], grounded)
    lengths = np.maximum(ends[1:], grounded) - starts
    rises = np.cumsum(weights * lengths, axis=-1)
    V = V0 + np.concatenate([np.zeros_like(rises[..., :1]), rises[..., :-1]], axis=-1)
    dx, dz = advance(H, V, weights, lengths)
    return (grounded[..., 0] + np.cumsum(dx, axis=-1)[..., -1],
            np.cumsum(dz, axis=-1)[..., -1])


def _bracketed(function, lower, upper):
    """Whether function(lower) < 0 < function(upper), a row each (the precondition of
    catenary.increasing_roots; rows and points as it has them)."""
    values = function(np.arange(np.size(lower)), np.stack([lower, upper], axis=1))
    return (values[:, 0] < 0.0) & (0.0 < values[:, 1])


def _brackets_above(function, start, refusal=None):
    """For each row, the first of start, 2 start, 4 start, ... where ``function`` > 0
    (rows and points as catenary.increasing_roots's), CHUNK doublings a call; NaN
    where there is none within MAX_DOUBLINGS. A NaN value before it raises
    ValueError(``refusal``) where given (as increasing_roots)."""
    start = np.asarray(start, dtype=float)
    found = np.full(start.shape, np.nan)
    left = np.arange(start.size)
    for first in range(0, MAX_DOUBLINGS, CHUNK):
        if not left.size:
            break
        points = start[left, None] * 2.0 ** np.arange(first, min(first + CHUNK,
                                                                  MAX_DOUBLINGS))
        values = function(left, points)
        stop = (values > 0) | (np.isnan(values) if refusal is not None else False)
        hit = stop.any(axis=1)
        at = np.argmax(stop[hit], axis=1)
        if np.isnan(values[hit, at]).any():
            raise ValueError(refusal)
        found[left[hit]] = points[hit, at]
        left = left[~hit]
    return found


NO_CATENARY = "section catenary: no catenary of these weights between the ends"


def solve(ends, weights, span, rise, on_seabed):
    """The SectionCatenary through (span, rise) from the origin (module docstring);
    ``on_seabed``: the start lies on the seabed, so the line may rest on it. ValueError
    where there is none: the ends L or more apart, on one vertical, or (on the seabed)
    too much line to lie taut between them. Solved once for its arguments (a run asks
    for its start twice: the penalty's tension scale and the start itself)."""
    return _solved(tuple(map(float, ends)), tuple(map(float, weights)), float(span),
                   float(rise), bool(on_seabed))


@functools.lru_cache(maxsize=16)
@np.errstate(over="ignore", invalid="ignore")
def _solved(ends, weights, span, rise, on_seabed):
    """solve, its arguments as hashable numbers. The nested roots of the module
    docstring, each bisected to adjacent doubles, many lines at once: every point the
    outer bisection may visit (a or V(0)) with the inner one (H) of each. A line
    without an H (NaN) is refused where the outer bisection visits it; the points it
    does not visit may overflow (an H of 1e-300 under a V(0) far from the root) without
    a warning."""
    ends, weights = np.array(ends), np.array(weights)
    ends.flags.writeable = weights.flags.writeable = False     # shared by the cache's users
    length = ends[-1]
    if not (np.hypot(span, rise) < length and span > 1e-9 * length):
        raise ValueError("section catenary: the ends must be less than L apart and not on "
                         "one vertical")
    scale = float(np.abs(weights) @ np.diff(ends))          # N: the whole weight
    if scale == 0.0:
        raise ValueError("section catenary: the line has no weight")

    def spanned(grounded, V0):
        """H (n,) of the lines of grounded lengths and V(0) (n,) that make the span; NaN
        where none is bracketed."""
        def excess(rows, H):
            return end_points(ends, weights, H, grounded[rows, None], V0[rows, None])[0] - span
        H = np.full(grounded.shape, np.nan)
        upper = _brackets_above(excess, np.full(grounded.shape, scale))
        lower = np.full(grounded.shape, 1e-300)
        found = np.flatnonzero(~np.isnan(upper))
        found = found[_bracketed(lambda rows, H: excess(found[rows], H), lower[found],
                                 upper[found])]
        H[found] = increasing_roots(lambda rows, H: excess(found[rows], H), lower[found],
                                    upper[found], depth=INNER_DEPTH)
        return H

    def end_heights(grounded, V0):
        """z(L) of the spanned lines of grounded lengths and V(0) (any one shape)."""
        grounded, V0 = np.broadcast_arrays(grounded, V0)
        flat = grounded.ravel(), V0.ravel()
        return end_points(ends, weights, spanned(*flat), *flat)[1].reshape(grounded.shape)

    def climb(rows, V0):                            # z(L) - Z, increasing in V(0)
        return end_heights(0.0, V0) - rise

    def sink(rows, grounded):                       # increasing in a
        return rise - end_heights(grounded, 0.0)

    def at(function, point):
        value = function(None, np.full((1, 1), point))[0, 0]
        if np.isnan(value):                         # no H at this a or V(0)
            raise ValueError(NO_CATENARY)
        return value

    def root(function, lower, upper):
        if not _bracketed(function, [lower], [upper])[0]:
            raise ValueError(NO_CATENARY)
        return float(increasing_roots(function, [lower], [upper], depth=OUTER_DEPTH,
                                      refusal=NO_CATENARY)[0])

    def first_above(function):
        found = float(_brackets_above(function, [scale], refusal=NO_CATENARY)[0])
        if np.isnan(found):
            raise ValueError("section catenary: no bracket")
        return found

    if on_seabed and at(climb, 0.0) >= 0.0:
        # too much rise with V(0) = 0: the line rests on the seabed up to a
        if at(sink, span * (1 - 1e-12)) <= 0.0:
            raise ValueError("section catenary: the line is too long to lie taut on the "
                             "seabed between its ends")
        grounded, V0 = root(sink, 0.0, span * (1 - 1e-12)), 0.0
    else:
        upper = first_above(climb)
        lower = 0.0 if on_seabed else -first_above(lambda rows, v: -climb(rows, -v))
        grounded, V0 = 0.0, root(climb, lower, upper)
    H = float(spanned(np.array([grounded]), np.array([V0]))[0])
    solved = SectionCatenary(H, grounded, V0, ends, weights)
    if on_seabed:
        _check_above_seabed(solved, length)
    return solved


def _check_above_seabed(line, length):
    """ValueError unless the suspended part of a line resting on the seabed z = 0 leaves
    it going up (a positive weight at the touchdown) and stays above it (sampled at 4096
    points, to 1e-9 L)."""
    piece = np.searchsorted(line.ends, line.grounded, side="right") - 1
    if line.grounded > 0.0 and line.weights[min(piece, len(line.weights) - 1)] <= 0.0:
        raise ValueError("section catenary: the touchdown falls on a buoyant or weightless "
                         "piece")
    S = np.linspace(line.grounded, length, 4097)
    if line.at(S)[1].min() < -1e-9 * length:
        raise ValueError("section catenary: the line would pass below the seabed")
