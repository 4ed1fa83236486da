"""Reference elements on [0, 1] and their element matrices (numpy only).

Two elements live on the same vertices (method.md §4):

* Hermite cubic (C^1) for each Cartesian component of r: element dofs
  ``[r(S_e), r'(S_e), r(S_e+1), r'(S_e+1)]`` with physical (not reference) slopes;
* P2 Lagrange for each component of d1, d2: element dofs
  ``[d(S_e), d(midpoint of e), d(S_e+1)]``.

Both are stored on a 1-D DMDA with 2 dofs per vertex: the Hermite pair (value, slope),
or the P2 pair (vertex value, midpoint value of the element to the right of the vertex).
``Element.offsets`` / ``Element.slots`` say where element dof k lives: vertex
``e + offsets[k]``, slot ``slots[k]``.

The 3-point Gauss rule integrates every product of the global step exactly on a
straight element (degree <= 5), and tau, lambda live at its points.
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


HERMITE = Element("hermite", np.array([0, 0, 1, 1]), np.array([0, 1, 0, 1]))
P2 = Element("p2", np.array([0, 0, 1]), np.array([0, 1, 0]))


def hermite_basis(xi, h):
    """Hermite cubic shape functions and their S-derivatives.

    xi: (nq,) reference points in [0, 1]; h: (ne,) element lengths.
    Returns (phi, dphi, ddphi), each (ne, nq, 4): values, d/dS and d2/dS2 of
    N1 = 1 - 3x^2 + 2x^3, N2 = h(x - 2x^2 + x^3), N3 = 3x^2 - 2x^3, N4 = h(x^3 - x^2).
    """
    x = np.asarray(xi, dtype=float)[None, :]
    h = np.asarray(h, dtype=float)[:, None]
    one = np.ones_like(h)
    phi = np.stack(np.broadcast_arrays(
        (1 - 3 * x**2 + 2 * x**3) * one, h * (x - 2 * x**2 + x**3),
        (3 * x**2 - 2 * x**3) * one, h * (x**3 - x**2)), axis=-1)
    dphi = np.stack(np.broadcast_arrays(
        (-6 * x + 6 * x**2) / h, (1 - 4 * x + 3 * x**2) * one,
        (6 * x - 6 * x**2) / h, (3 * x**2 - 2 * x) * one), axis=-1)
    ddphi = np.stack(np.broadcast_arrays(
        (-6 + 12 * x) / h**2, (-4 + 6 * x) / h,
        (6 - 12 * x) / h**2, (6 * x - 2) / h), axis=-1)
    return phi, dphi, ddphi


def p2_basis(xi, h):
    """P2 Lagrange shape functions (left vertex, midpoint, right vertex) and d/dS.

    Returns (phi, dphi), each (ne, nq, 3).
    """
    x = np.asarray(xi, dtype=float)[None, :]
    h = np.asarray(h, dtype=float)[:, None]
    one = np.ones_like(h)
    phi = np.stack(np.broadcast_arrays(
        (1 - x) * (1 - 2 * x) * one, 4 * x * (1 - x) * one, x * (2 * x - 1) * one), axis=-1)
    dphi = np.stack(np.broadcast_arrays(
        (4 * x - 3) / h, (4 - 8 * x) / h, (4 * x - 1) / h), axis=-1)
    return phi, dphi


def quadrature_weights(h):
    """Physical Gauss weights w_q h_e, shape (ne, nq)."""
    return np.asarray(h, dtype=float)[:, None] * GAUSS_WEIGHTS[None, :]


def gram(weights, a, b):
    """Element matrices int a_k b_l dS by quadrature: (ne, nq), (ne, nq, k) -> (ne, k, k)."""
    return np.einsum("eq,eqk,eql->ekl", weights, a, b)


# Largest generalised eigenvalue of (stiffness, mass) on one element of length h, times
# h^2, for both pairs of the global step: P2 (int g'.g', int g.g) and Hermite
# (int p''.p'', int p'.p'); both are 60 (computed in tests/test_nonconvex.py). The global
# eigenvalue is bounded by the largest element one.
STIFFNESS_TO_MASS_MAX = 60.0


def r_element_matrices(h, bending, penalty):
    """Element matrices of the r problem (§3 step 1): int 2 a3 r''.p'' + R r'.p'.

    ``bending`` is 2 a3 (N m^2), ``penalty`` is R (N). Returns (ne, 4, 4).
    """
    _, dphi, ddphi = hermite_basis(GAUSS_POINTS, h)
    w = quadrature_weights(h)
    return bending * gram(w, ddphi, ddphi) + penalty * gram(w, dphi, dphi)


def d_element_matrices(h, stiffness, penalty):
    """Element matrices of a director problem: int 2 a_a d'.g' + R d.g. Returns (ne, 3, 3)."""
    phi, dphi = p2_basis(GAUSS_POINTS, h)
    w = quadrature_weights(h)
    return stiffness * gram(w, dphi, dphi) + penalty * gram(w, phi, phi)


def hermite_integrals(h, xi0, xi1):
    """Exact int over reference sub-intervals [xi0, xi1] of the Hermite shape functions.

    Used for piecewise-constant loads whose breaks fall inside an element:
    int_{S(xi0)}^{S(xi1)} phi_k dS = h int_{xi0}^{xi1} N_k dxi.  Arrays (ne,) -> (ne, 4).
    """
    h = np.asarray(h, dtype=float)

    def antiderivatives(x):
        return np.stack([x - x**3 + x**4 / 2, h * (x**2 / 2 - 2 * x**3 / 3 + x**4 / 4),
                         x**3 - x**4 / 2, h * (x**4 / 4 - x**3 / 3)], axis=-1)

    return h[:, None] * (antiderivatives(np.asarray(xi1)) - antiderivatives(np.asarray(xi0)))
