"""The linking number of a rod clamped at both ends on a common axis (numpy only).

Why: the clamps prescribe the end frames, hence the end roll only modulo a whole turn. A
twisted rod reached by continuation keeps its linking number Lk = Tw + Wr
(Calugareanu-White), which grows by the end roll over 2 pi from one step to the next,
unless the rod passes through itself or around one of its ends (a motion that walls at
the clamps forbid). An iteration that takes a large step, as the Uzawa iteration may, can
land on an equilibrium of another Lk: the end frames are met, the state converges, and
it is not the twisted rod the load path describes (one step of a whole turn, which the
clamps do not see at all, gives the untwisted rod; measured cases in docs/stability.md,
"Twist and Greenhill"). The continuation checks Lk after each step
(iteration/continuation.py).

Tw = (1/2 pi) int u3 dS with u3 = d1'.d2 (frames.strains). Wr, for a rod whose end
tangents both equal the axis e, is given by Fuller's formula relative to the straight rod
along e: Wr = (1/2 pi) int (e x t).t' / (1 + e.t) dS, t = r'; it is the writhe of the
rod closed by rays along -e and +e from its ends, exact as long as t never points along
-e (1 + e.t > 0). Both integrands are local: the integrals are sums over the quadrature
points of each rank, so nothing is gathered.
"""

import numpy as np

from petsc_rod.frames import strains

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
# (tests/unit/test_link_formulas.py).
LINK_TOLERANCE = 0.25


def changed_class(link, expected):
    """Whether a state of (Tw, Wr) ``link`` is not on the load path's Lk ``expected``
    (turns); False when either is unknown (None)."""
    if link is None or expected is None:
        return False
    return abs(sum(link) - expected) > LINK_TOLERANCE

