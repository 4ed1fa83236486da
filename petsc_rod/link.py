"""The linking number of a rod clamped at both ends on a common axis (numpy only).

Why: the clamps prescribe the end frames, hence the end roll only modulo a whole turn. A
twisted rod reached by continuation keeps its linking number Lk = Tw + Wr
(Calugareanu-White), which grows by the end roll over 2 pi from one step to the next,
unless the rod passes through itself or around one of its ends (a motion that walls at
the clamps forbid). An iteration that takes a large step, as the Uzawa iteration may, can
land on an equilibrium of another Lk: the end frames are met, the state converges, and
it is not the twisted rod the load path describes (a rod clamped 0.9 L apart, twisted
at R = 100: a whole turn of twist lost in one step at 9.75 rad; one step of a whole turn,
which the clamps do not see at all: the untwisted rod; docs/stability.md, fix 9). The
continuation checks Lk after each step (continuation.py).

Tw = (1/2 pi) int u3 dS with u3 = d1'.d2 (kernels.strains). Wr, for a rod whose end
tangents both equal the axis e, is given by Fuller's formula relative to the straight rod
along e: Wr = (1/2 pi) int (e x t).t' / (1 + e.t) dS, t = r'; it is the writhe of the
rod closed by rays along -e and +e from its ends, exact as long as t never points along
-e (1 + e.t > 0). Both integrands are local: the integrals are sums over the quadrature
points of each rank, so nothing is gathered.
"""

import numpy as np

from .kernels import strains

# Fuller's formula is used where 1 + e.t stays above this at every point; a tangent that
# comes nearer to -e (a loop) leaves the link untracked for that state.
FULLER_MARGIN = 0.1


def link_integrands(directors, derivatives, axis):
    """Twist and writhe densities (turns per m) and 1 + e.t at points.

    directors, derivatives: (..., 3, 3), rows d1, d2, t = r' = d3 and their
    S-derivatives; axis: the common end tangent e (3,). Returns (twist, writhe, margin),
    each (...).
    """
    tangent, bend = directors[..., 2, :], derivatives[..., 2, :]
    margin = 1.0 + tangent @ axis
    twist = strains(directors, derivatives)[..., 2] / (2 * np.pi)
    writhe = np.einsum("...c,...c->...", np.cross(axis, tangent), bend) / (
        2 * np.pi * np.where(margin > 0, margin, np.inf))
    return twist, writhe, margin


# A step whose Lk differs from the expected one by more than this (turns) changed its
# class: whole turns are lost or gained, the discretisation error is far smaller
# (tests/test_link.py).
LINK_TOLERANCE = 0.25


def changed_class(link, expected):
    """Whether a state of (Tw, Wr) ``link`` is not on the load path's Lk ``expected``
    (turns); False when either is unknown (None)."""
    if link is None or expected is None:
        return False
    return abs(sum(link) - expected) > LINK_TOLERANCE


def gauss_writhe(points, axis, reach=50.0):
    """Writhe (turns) of a whole centreline by the Gauss double integral, an independent
    check of Fuller's formula (tests, scripts/stability_matrix.py; O(n^2) work and
    memory, n = len(points)).

    points: (n, 3) along a curve whose end tangents are ``axis``. The curve is closed as
    Fuller's formula assumes: rays of length ``reach`` along -axis and +axis from its ends
    (points geometrically spaced from the curve's own spacing), joined far away by a path
    whose offset across the axis varies linearly, so that the closure adds no writhe of its
    own. Wr = (1/4 pi) sum_{i != j} (T_i x T_j).(M_i - M_j) / |M_i - M_j|^3 over the
    segments T (midpoints M) of the closed polygon.
    """
    points = np.asarray(points, dtype=float)
    axis = np.asarray(axis, dtype=float)
    first, last = points[0], points[-1]
    spacing = np.linalg.norm(points[1] - points[0])
    ray = np.geomspace(spacing, reach, 200)[:, None] * axis
    # "up": any direction across the axis, for the far side of the closure
    up = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    up = reach * up / np.linalg.norm(up)
    u = np.linspace(0.0, 1.0, 100)[1:-1, None]
    far_end, far_start = last + reach * axis, first - reach * axis
    closure = np.concatenate([
        last + ray, far_end + u * up,
        far_end + up + np.linspace(0.0, 1.0, 200)[:, None] * (far_start - far_end),
        far_start + (1 - u) * up, (first - ray)[::-1]])
    polygon = np.concatenate([points, closure])
    segments = np.roll(polygon, -1, axis=0) - polygon
    midpoints = polygon + 0.5 * segments
    offsets = midpoints[:, None, :] - midpoints[None, :, :]
    distance = np.linalg.norm(offsets, axis=2)
    np.fill_diagonal(distance, np.inf)
    crossed = np.cross(segments[:, None, :], segments[None, :, :])
    return float(np.sum(np.einsum("ijk,ijk->ij", crossed, offsets) / distance**3) / (4 * np.pi))
