"""The centreline from its slope: r(S) = r(a) + int_a^S slope, slope = r' in P2 (numpy).

The global step solves for slope instead of r (mesh/elements.py): the map (r at a held
end, slope in P2) <-> Hermite cubic r is a bijection, so the discrete problem is the
paper's, only better conditioned. In slope the r equation of §3 step 1 reads, for all P2 g,

    int 2 a3 slope'.g' + R slope.g = int (R tau3 - lambda3).g + int F.g  (- mu . int g),

where the load F comes from int f.p dS + end forces with p(S) = p(a) + int_a^S g:

* start held (clamp or pin): p(0) = 0, F(S) = int_S^L f dS + P_L (P_L the dead force at a
  free end S = L, else 0);
* start free (force P_0), end held: p(L) = 0, F(S) = -(int_0^S f dS + P_0)
  = int_S^L f dS - (int_0^L f dS + P_0).

Both ends held: r(L) - r(0) = int_0^L slope dS is a constraint with multiplier mu
(matrices.ScalarProblem.add_integral_constraint); mu = -N, N the reaction at S = L.
"""

import numpy as np

from petsc_rod.scenes.boundary import is_held


def load_offset(start, end, total_load):
    """The constant part of F(S) - int_S^L f dS (module docstring): P_L (if the end is
    free) when the start is held, else -(int_0^L f dS + P_0). ``total_load`` (3,)."""
    if is_held(start):
        return end.force if end.kind == "free" else np.zeros(3)
    return -(total_load + start.force)


def anchor_work(start, end, total_load):
    """The part of the load work int f.r dS + P_0.r(0) + P_L.r(L) that slope does not
    carry: r(a).(int f dS + dead end forces), with a the end r is integrated from.
    The rest is int F.slope dS (F as in the module docstring)."""
    applied = total_load + sum(state.force for state in (start, end) if state.kind == "free")
    anchor = start if is_held(start) else end
    return float(anchor.position @ applied)


def chains_from_start(state, start, end):
    """Whether the centreline, and the Newton steps' chains of the positions
    (analysis/positions.py), run from the start: where it is held, but not where the
    state's line runs them from its end (``RodState.chains_from_end``, lower_end_first)."""
    return is_held(start) and not getattr(state, "chains_from_end", False)


def lower_end_first(start, end):
    """Whether a line held at both ends, ``start`` and ``end`` its end states at the
    full load, has its end the lower (an anchor given as the end, the fairlead as the
    start): where a term reads the grounded positions horizontally (the seabed's
    friction) its centreline and chains then run from that end, and its grounded part
    hangs from the end it lies at, as a line given from its anchor hangs from its start:
    an iterate's errors in angle over the suspended part, and its chord's error, are
    then no errors of the grounded positions (docs/riser.md §3b, "The path")."""
    return is_held(start) and is_held(end) and end.position[2] < start.position[2]


def positions_from_increments(mesh, increments, start, end, from_start=None):
    """r at the owned vertices from int_e slope dS of the owned elements (ne, 3): across
    ranks the running sum is a prefix sum (Mesh.prefix_sum). From a held start,
    r_i = r(0) + sum_{e < i} int_e slope; from a held end (free start, or
    ``from_start`` False: chains_from_start), r_i = r(L) - sum_{e >= i} int_e slope.
    Returns (n_owned, 3).
    """
    before = mesh.prefix_sum(increments)
    if is_held(start) if from_start is None else from_start:
        return start.position + before
    return end.position - mesh.global_sum(increments.sum(axis=0)) + before


def positions_at_points(left, slope, integrals):
    """r at points of elements: r(S_e) + int_{S_e}^S slope dS, exact for the P2 slope.

    left: r at each element's left vertex (ne, 3); slope: element dofs (ne, 3, 3);
    integrals: elements.p2_integrals at the points (ne, nq, 3). Returns (ne, nq, 3).
    """
    return left[:, None, :] + np.einsum("eqk,ekc->eqc", integrals, slope)


def midpoint_slopes(r0, slope0, r1, slope1, h):
    """slope at element midpoints from Hermite dofs: the derivative of the cubic with
    end values r0, r1 and slopes slope0, slope1 at S = (S_e + S_e+1)/2,
    1.5 (r1 - r0)/h - (slope0 + slope1)/4. Arrays (ne, 3), h (ne,)."""
    return 1.5 * (r1 - r0) / h[:, None] - 0.25 * (slope0 + slope1)
