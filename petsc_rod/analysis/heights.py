"""The heights of the nodes in the Newton system: a banded chain instead of a dense
integral (docs/method.md §11, "Terms of the heights").

The reduced problem's unknowns are the frames; the centreline is their integral, so the
height of node m, z_m = z(a) + int_a^{S_m} r'_z dS (a the held end), depends on every
slope dof between a and S_m. A term whose energy depends on the heights (the seabed,
k/2 sum_m w_m (z_b - z_m)_+^2) therefore has a dense Hessian in the frames,
J^T diag(E_zz) J with J the cumulative quadrature. It is kept banded by making the
vertex heights unknowns of the Newton system, tied to the slopes by one equation per
element (the exact integral of the P2 slope, Simpson's rule):

    u_{e+1} - u_e - h_e (s_L + 4 s_M + s_R) / 6 = 0            (multiplier nu_e),
    z(vertex i) = u_i,   z(midpoint of e) = u_e + h_e (5 s_L + 8 s_M - s_R) / 24,

s = r'_z at the element's nodes (left vertex, midpoint, right vertex), whose variation
is a row of the node's unknowns: delta s_n = (omega_n x t_n)_z + delta_k_n (d3_n)_z
(t = k d3 the stretched tangent; no stretch column on an inextensible line). The height
at the held end is held (u_a = 0). The system stays symmetric: (x, u) are primal
unknowns and nu the multipliers of the chain, so the KKT matrix has one negative
eigenvalue per element more than the reduced Hessian (SecondVariation counts them off).

This module holds the chain's coefficients and the gradient of a height energy in the
slopes (the adjoint of the chain: a suffix sum, one MPI scan). numpy only.
"""

import numpy as np

from petsc_rod.mesh.elements import HALF_ELEMENT, NODE_WEIGHTS

# z(S_e+1) - z(S_e) = h sum_k SIMPSON_k s_k and z(midpoint) - z(S_e) = h sum_k HALF_k s_k
SIMPSON = NODE_WEIGHTS
HALF = HALF_ELEMENT


def slope_rows(tangents, stretch):
    """delta r'_z at each node as a row of its unknowns, (n, 3) or (n, 4) with the stretch:
    (omega x t)_z = omega_x t_y - omega_y t_x, and d3_z for delta_k. ``tangents`` (n, 3)
    the fields' third rows t = k d3."""
    t = np.asarray(tangents, dtype=float)
    rows = np.zeros(t.shape[:-1] + (4 if stretch else 3,))
    rows[..., 0], rows[..., 1] = t[..., 1], -t[..., 0]
    if stretch:
        rows[..., 3] = t[..., 2] / np.linalg.norm(t, axis=-1)
    return rows


def height_gradient(mesh, dE_dz, held_start):
    """dE/ds_n, the derivative of an energy of the node heights in the slope dofs r'_z at
    the owned nodes, (n_nodes,), from dE/dz_m at the owned nodes ``dE_dz`` (n_nodes,)
    (the heights z_m = z(a) + int_a^{S_m} r'_z, a the held end): sum_m dE/dz_m dz_m/ds_n.

    From a held start, element e gives its nodes h_e (SIMPSON tail_e + HALF a_M(e)),
    tail_e the sum of dE/dz over the nodes at and beyond its right vertex, a_M(e) its
    midpoint's; from a held end (free start) z_m = z(L) - int_{S_m}^L r'_z, which is the
    same less int_0^L r'_z, so every node n also gets -w_n sum_m dE/dz_m. Returns
    (element vectors (ne, 3), to be summed into the nodes by a ghost update, since a
    rank's last element reaches the next rank's first vertex; the factor of w_n every
    node gets). Collective (one scan, one sum)."""
    a = np.asarray(dE_dz, dtype=float)
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
