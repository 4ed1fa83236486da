"""The P2 reference element on [0, 1] and its element matrices (numpy only).

Every field of the global step lives in the same P2 Lagrange space (docs/method.md §4,
with the centreline recast): d1, d2, and the slope r' of the centreline. The
paper's C^1 Hermite cubic r has a C^0 piecewise-quadratic derivative, so a P2 slope
together with r(0) is the same discrete space; r itself is recovered by integrating
the slope (centreline.py), which keeps the r matrix second order (condition ~N^2) instead
of the fourth-order Hermite one (~N^4). Element dofs ``[g(S_e), g(midpoint of e),
g(S_e+1)]``.

They are stored on a 1-D DMDA with 2 dofs per vertex: the P2 pair (vertex value,
midpoint value of the element to the right of the vertex). ``Element.offsets`` /
``Element.slots`` say where element dof k lives: vertex ``e + offsets[k]``, slot
``slots[k]``.

The constraint d_i = tau_i and its multipliers live at the P2 nodes (vertices and
midpoints), with Simpson's weights h (1/6, 4/6, 1/6): the penalty term of the global step
is a diagonal (lumped) mass, and the local step acts on the very dofs of the fields
(docs/method.md §4). The 3-point Gauss rule integrates the stiffness, the loads and the
energy exactly on a straight element.
"""

from dataclasses import dataclass

import numpy as np

GAUSS_POINTS = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
GAUSS_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0


@dataclass(frozen=True)
class Element:
    """Dof layout of one reference element on the two-slot vertex storage."""

    name: str
    offsets: np.ndarray
    slots: np.ndarray

    @property
    def ndofs(self):
        return self.offsets.size


P2 = Element("p2", np.array([0, 0, 1]), np.array([0, 1, 0]))


def _reference_points(xi, h):
    """Points xi as (ne or 1, nq) and lengths h as (ne, 1), for broadcasting."""
    x = np.asarray(xi, dtype=float)
    return (x[None, :] if x.ndim == 1 else x), np.asarray(h, dtype=float)[:, None]


def p2_basis(xi, h):
    """P2 Lagrange shape functions (left vertex, midpoint, right vertex) and d/dS.

    xi: reference points, (nq,) shared by all elements or (ne, nq); h: (ne,) lengths.
    N0 = (1 - x)(1 - 2x), N1 = 4x(1 - x), N2 = x(2x - 1). Returns (phi, dphi), each
    (ne, nq, 3).
    """
    x, h = _reference_points(xi, h)
    one = np.ones_like(h)
    phi = np.stack(np.broadcast_arrays(
        (1 - x) * (1 - 2 * x) * one, 4 * x * (1 - x) * one, x * (2 * x - 1) * one), axis=-1)
    dphi = np.stack(np.broadcast_arrays(
        (4 * x - 3) / h, (4 - 8 * x) / h, (4 * x - 1) / h), axis=-1)
    return phi, dphi


def p2_integrals(xi, h):
    """Integrals of the P2 shape functions from the element start, int_{S_e}^{S(xi)} N_k dS
    = h int_0^xi N_k: h (x - 3x^2/2 + 2x^3/3, 2x^2 - 4x^3/3, 2x^3/3 - x^2/2).

    At xi = 1 they are h (1/6, 2/3, 1/6) (Simpson's weights). Returns (ne, nq, 3).
    """
    x, h = _reference_points(xi, h)
    return h[..., None] * np.stack(np.broadcast_arrays(
        x - 1.5 * x**2 + 2 * x**3 / 3, 2 * x**2 - 4 * x**3 / 3, 2 * x**3 / 3 - 0.5 * x**2),
        axis=-1)


def element_integrals(h):
    """int_e N_k dS = h (1/6, 2/3, 1/6) of each element, (ne, 3)."""
    return p2_integrals(np.ones(1), h)[:, 0]


def quadrature_weights(h):
    """Physical Gauss weights w_q h_e, shape (ne, nq)."""
    return np.asarray(h, dtype=float)[:, None] * GAUSS_WEIGHTS[None, :]


def gram(weights, a, b):
    """Element matrices int a_k b_l dS by quadrature: (ne, nq), (ne, nq, k) -> (ne, k, k)."""
    return np.einsum("eq,eqk,eql->ekl", weights, a, b)


# Simpson's weights of the P2 nodes (left vertex, midpoint, right vertex) on [0, 1].
NODE_WEIGHTS = np.array([1.0, 4.0, 1.0]) / 6.0
# int_0^{1/2} of the P2 shape functions on [0, 1]: r(S_e + h/2) - r(S_e) =
# h (5 r'_0 + 8 r'_m - r'_1) / 24 for a P2 slope r'
HALF_ELEMENT = np.array([5.0, 8.0, -1.0]) / 24.0


def lumped_mass(h):
    """The Simpson node mass of each element, h diag(1, 4, 1)/6, (ne, 3, 3): the
    penalty's W (docs/method.md §4)."""
    return np.asarray(h, dtype=float)[:, None, None] * np.diag(NODE_WEIGHTS)[None]


def p2_element_matrices(h, stiffness, penalty):
    """Element matrices of one field of the global step (docs/method.md §3):
    int s g'.k' dS + R sum_n w_n g_n k_n, the penalty mass lumped at the nodes.

    For d_a (a = 1, 2) s = 2 a_a; for the slope r' = d3, s = 2 a3 (the r equation
    int 2 a3 r''.p'' with slope = r', g = p'). ``penalty`` is R (N). Returns (ne, 3, 3).
    A coefficient that varies along the element: p2_stiffness_matrices.
    """
    _, dphi = p2_basis(GAUSS_POINTS, h)
    w = quadrature_weights(h)
    return stiffness * gram(w, dphi, dphi) + penalty * lumped_mass(h)


# Cut fractions this close to an element's end are its end: a break at a vertex (a
# section end on a mesh built to have it there) cuts nothing, whatever the round-off
# of S at the vertex.
CUT_SNAP = 1e-12


def cut_gauss_rule(element_S, h, breaks):
    """The 3-point Gauss rule on the pieces of each element between the ``breaks`` (S,
    sorted) inside it: reference points xi (ne, 3 P) and physical weights (ne, 3 P), P the
    largest number of pieces of an element (1 where no break falls inside an element;
    shorter elements pad with pieces of zero weight).

    A coefficient linear on each piece (a stiffness constant or tapered along each
    section of a line, the breaks its section ends) times a product of two P2
    derivatives is a cubic on each piece, which this rule integrates exactly. Vectorised:
    the pieces of positive length of each element are moved to the first columns.
    """
    a = np.asarray(element_S, dtype=float)[:, None]
    h = np.asarray(h, dtype=float)[:, None]
    cuts = np.clip((np.asarray(breaks, dtype=float)[None, :] - a) / h, 0.0, 1.0)
    cuts = np.where(cuts < CUT_SNAP, 0.0, np.where(cuts > 1.0 - CUT_SNAP, 1.0, cuts))
    cuts = np.concatenate([np.zeros_like(a), cuts, np.ones_like(a)], axis=1)
    lo, hi = cuts[:, :-1], cuts[:, 1:]
    order = np.argsort(hi <= lo, axis=1, kind="stable")       # positive pieces first
    pieces = max(int(np.max(np.sum(hi > lo, axis=1), initial=1)), 1)
    lo = np.take_along_axis(lo, order, axis=1)[:, :pieces, None]
    hi = np.take_along_axis(hi, order, axis=1)[:, :pieces, None]
    shape = (len(a), pieces * GAUSS_POINTS.size)
    xi = (lo + (hi - lo) * GAUSS_POINTS).reshape(shape)
    weights = (h[:, :, None] * (hi - lo) * GAUSS_WEIGHTS).reshape(shape)
    return xi, weights


def p2_stiffness_matrices(h, xi, weights, coefficients):
    """int s_f(S) g_k' g_l' dS of each element for coefficients s_f varying along it,
    by the quadrature (xi, weights) of cut_gauss_rule: coefficients (ne, nq, m) at its
    points -> (m, ne, 3, 3), one set of element matrices per coefficient (the three
    fields' 2 a_i, N m^2, docs/method.md §2, §4)."""
    _, dphi = p2_basis(xi, h)
    return np.einsum("eq,eqf,eqk,eql->fekl", weights, coefficients, dphi, dphi)
