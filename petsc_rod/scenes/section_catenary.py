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
(catenary.increasing_root). A line that rests on the seabed must leave it going up and
stay above it: a touchdown on a buoyant or weightless piece, or a suspended part that
dips below the seabed (a sag bend after a buoyant arch in shallow water), is refused. A
uniform weight gives the catenary and the catenary with touchdown of catenary.py and
touchdown.py.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.scenes.catenary import increasing_root

# A piece whose weight changes V by less than this fraction of |n| is taken as straight
# in dx (the error is of its square).
STRAIGHT_PIECE = 1e-8
# The most doublings of a bracket before the scene is said to have no catenary.
MAX_DOUBLINGS = 200


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


def _root(function, lower, upper):
    """catenary.increasing_root, with its precondition function(lower) < 0 <
    function(upper) checked (ValueError: no catenary)."""
    if not function(lower) < 0.0 < function(upper):
        raise ValueError("section catenary: no catenary of these weights between the ends")
    return increasing_root(function, lower, upper)


def _bracket_above(function, start):
    """The first of start, 2 start, 4 start, ... where ``function`` > 0; ValueError when
    none is within MAX_DOUBLINGS."""
    value = start
    for _ in range(MAX_DOUBLINGS):
        if function(value) > 0:
            return value
        value *= 2
    raise ValueError("section catenary: no bracket")


def solve(ends, weights, span, rise, on_seabed):
    """The SectionCatenary through (span, rise) from the origin (module docstring);
    ``on_seabed``: the start lies on the seabed, so the line may rest on it. ValueError
    where there is none: the ends L or more apart, on one vertical, or (on the seabed)
    too much line to lie taut between them."""
    ends, weights = np.asarray(ends, dtype=float), np.asarray(weights, dtype=float)
    length = ends[-1]
    if not (np.hypot(span, rise) < length and span > 1e-9 * length):
        raise ValueError("section catenary: the ends must be less than L apart and not on "
                         "one vertical")
    scale = float(np.abs(weights) @ np.diff(ends))          # N: the whole weight
    if scale == 0.0:
        raise ValueError("section catenary: the line has no weight")

    def line(H, grounded, V0):
        return SectionCatenary(H, grounded, V0, ends, weights)

    def spanned(grounded, V0):
        """The line of the given a, V(0) whose H makes the span."""
        def excess(H):
            return line(H, grounded, V0).end_point()[0] - span
        upper = _bracket_above(excess, scale)
        return line(_root(excess, 1e-300, upper), grounded, V0)

    def climb(V0):                                  # z(L) - Z, increasing in V(0)
        return spanned(0.0, V0).end_point()[1] - rise

    if on_seabed and climb(0.0) >= 0.0:
        # too much rise with V(0) = 0: the line rests on the seabed up to a
        def sink(grounded):                         # increasing in a
            return rise - spanned(grounded, 0.0).end_point()[1]
        if sink(span * (1 - 1e-12)) <= 0.0:
            raise ValueError("section catenary: the line is too long to lie taut on the "
                             "seabed between its ends")
        solved = spanned(_root(sink, 0.0, span * (1 - 1e-12)), 0.0)
    else:
        upper = _bracket_above(climb, scale)
        lower = 0.0 if on_seabed else -_bracket_above(lambda v: -climb(-v), scale)
        solved = spanned(0.0, _root(climb, lower, upper))
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
