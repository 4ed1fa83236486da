"""The positions of the nodes in the Newton system: a banded chain instead of a dense
integral (docs/method.md §11, "Terms of the positions").

The reduced problem's unknowns are the frames; the centreline is their integral, so
component c of node m's position, x^c_m = x^c(a) + int_a^{S_m} r'_c dS (a the held
end), depends on every slope dof between a and S_m. A term whose energy depends on the
positions (the seabed on the heights, k/2 sum_m w_m (z_b - z_m)_+^2; the friction on the
horizontal positions) therefore has a dense Hessian in the frames, J^T diag(E_xx) J
with J the cumulative quadrature. It is kept banded by making the vertex positions of
the components the terms read unknowns of the Newton system, tied to the slopes by one
equation per element and component (the exact integral of the P2 slope, Simpson's
rule):

    u^c_{e+1} - u^c_e - h_e (s_L + 4 s_M + s_R) / 6 = 0          (multiplier nu^c_e),
    x^c(vertex i) = u^c_i,   x^c(midpoint of e) = u^c_e + h_e (5 s_L + 8 s_M - s_R) / 24,

s = r'_c at the element's nodes (left vertex, midpoint, right vertex), whose variation
is a row of the node's unknowns: delta s_n = (omega_n x t_n)_c + delta_k_n (d3_n)_c
(t = k d3 the stretched tangent; no stretch column on an inextensible line). The
position at the held end is held (u^c_a = 0). The system stays symmetric: (omega, u)
are primal unknowns and nu the multipliers of the chains, so the KKT matrix has one
negative eigenvalue per element and component more than the reduced Hessian
(StabilityTest.negative_pivots counts them off).

This module holds the chain's coefficients and the gradient of a position energy in the
slopes (the adjoint of the chain: a suffix sum, one MPI scan). numpy only.
"""

import numpy as np

from petsc_rod.mesh.elements import HALF_ELEMENT, NODE_WEIGHTS

# x(S_e+1) - x(S_e) = h sum_k SIMPSON_k s_k and x(midpoint) - x(S_e) = h sum_k HALF_k s_k
SIMPSON = NODE_WEIGHTS
HALF = HALF_ELEMENT
# The heights: the component the seabed reads.
HEIGHT = 2


def slope_rows(tangents, stretch, component=HEIGHT):
    """delta r'_c at each node as a row of its unknowns, (n, 3) or (n, 4) with the
    stretch: (omega x t)_c = omega_{c+1} t_{c+2} - omega_{c+2} t_{c+1} (indices mod 3;
    for c = z: omega_x t_y - omega_y t_x), and d3_c for delta_k. ``tangents`` (n, 3) the
    fields' third rows t = k d3."""
    t = np.asarray(tangents, dtype=float)
    rows = np.zeros(t.shape[:-1] + (4 if stretch else 3,))
    following, previous = (component + 1) % 3, (component + 2) % 3
    rows[..., following] = t[..., previous]
    rows[..., previous] = -t[..., following]
    if stretch:
        rows[..., 3] = t[..., component] / np.linalg.norm(t, axis=-1)
    return rows


def position_gradient(mesh, dE_dx, held_start):
    """dE/ds_n, the derivative of an energy of one component x of the node positions in
    that component's slope dofs s = r'_c at the owned nodes, (n_nodes,), from dE/dx_m at
    the owned nodes ``dE_dx`` (n_nodes,) (the positions x_m = x(a) + int_a^{S_m} s, a
    the held end): sum_m dE/dx_m dx_m/ds_n.

    From a held start, element e gives its nodes h_e (SIMPSON tail_e + HALF a_M(e)),
    tail_e the sum of dE/dx over the nodes at and beyond its right vertex, a_M(e) its
    midpoint's; from a held end (free start) x_m = x(L) - int_{S_m}^L s, which is the
    same less int_0^L s, so every node n also gets -w_n sum_m dE/dx_m. Returns
    (element vectors (ne, 3), to be summed into the nodes by a ghost update, since a
    rank's last element reaches the next rank's first vertex; the factor of w_n every
    node gets). Collective (one scan, one sum)."""
    a = np.asarray(dE_dx, dtype=float)
    ne = mesh.n_local_elements
    pairs = a[0:2 * ne:2] + a[1:2 * ne:2]                 # (vertex e, midpoint e) of element e
    total = float(mesh.global_sum(float(a.sum())))
    # the sum over the nodes before element e's right vertex: prefix over elements
    before = mesh.prefix_sum(pairs)                       # at the owned vertices, (n_owned,)
    tail = total - (before[:ne] + pairs)                  # (ne,)
    h = mesh.element_h
    vectors = h[:, None] * (tail[:, None] * SIMPSON[None, :]
                            + a[1:2 * ne:2, None] * HALF[None, :])
    return vectors, (0.0 if held_start else -total)
