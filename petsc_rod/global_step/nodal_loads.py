"""Loads given by their values at the P2 nodes (the drag, the seabed's reaction): the
slope problem's right-hand side and the force they add to n(S).

Between the nodes the load is the P2 interpolant f_h of its nodal values, so that a
uniform nodal load is exactly the uniform dead load of the same value
(assembly.load_element_vectors). As for dead loads (docs/method.md §5) its work is
int F.g dS with F(S) = int_S^L f_h dS + offset; in element e,

    F(S) = B_e + int_S^{S_e+1} f_h dS,   B_e = int_{S_e+1}^L f_h dS,

a cubic in S, so 3-point Gauss integrates F g_k exactly. B_e needs the integrals of the
elements of later ranks: one prefix sum (Mesh.prefix_sum), nothing gathered.
"""

import numpy as np

from petsc_rod.mesh.elements import (GAUSS_POINTS, element_integrals, gram,
                                     p2_basis, p2_integrals, quadrature_weights)
from petsc_rod.mesh.fields import element_slices


class NodalLoad:
    """A load per metre given at the owned P2 nodes (set), on the mesh's elements."""

    def __init__(self, mesh, field):
        self.mesh = mesh
        self._field = field           # a VectorField, for the ghost exchange
        h = mesh.element_h
        phi, _ = p2_basis(GAUSS_POINTS, h)
        # the constant parts of element_vectors, made once: int_e g_k and
        # int_e g_k(S) int_S^{S_e+1} N_l dS, (ne, 3) and (ne, 3, 3)
        self._integrals = element_integrals(h)
        after = (self._integrals[:, None, :]
                 - p2_integrals(GAUSS_POINTS, h))          # int_S^{S_e+1} N_l, (ne, nq, 3)
        self.tail_integrals = gram(quadrature_weights(h), phi, after)
        self.element_values = None                     # (ne, 3 nodes, 3), made by set
        self.set(np.zeros((mesh.n_local_nodes, 3)))

    def set(self, values):
        """The nodal values (n_nodes, 3), N/m. Collective (a ghost exchange and a prefix
        sum). The owned nodes go straight into the field's slots (vertex, midpoint) and
        the element values are gathered from stride-2 views of its ghosted arrays
        (fields.element_slices): no (n, 2, 3) staging array, no index gather."""
        mesh = self.mesh
        ne = mesh.n_local_elements
        for c, vec in enumerate(self._field.components):
            slots = vec.getArray()
            slots[0::2] = values[0::2, c]
            slots[1:2 * ne:2] = values[1::2, c]
            slots[2 * ne + 1::2] = 0.0                  # the phantom midpoint of the last vertex
        first = int(mesh.element_local[0]) if ne else 0
        element_values = self.element_values
        if element_values is None or element_values.shape[0] != ne:
            element_values = self.element_values = np.empty((ne, 3, 3))
        for c, ghosted in enumerate(self._field.ghosted_components()):
            for k, dofs in enumerate(element_slices(ghosted, first, ne)):
                element_values[:, k, c] = dofs
        pieces = np.einsum("ek,ekc->ec", self._integrals, element_values)
        self.before = mesh.prefix_sum(pieces)          # int_0^{S_i} f_h at owned vertices
        self.total = mesh.global_sum(pieces.sum(axis=0))
        self._beyond = self.total - self.before[:mesh.n_local_elements] - pieces

    def beyond_vertices(self):
        """int_{S_i}^L f_h dS at the owned vertices, (n_owned, 3)."""
        return self.total - self.before

    def element_vectors(self, offset):
        """int_e F g_k dS, (ne, 3, 3), F(S) = int_S^L f_h dS + ``offset`` (3,): with
        F = B_e + offset + sum_l f_l int_S^{S_e+1} N_l, the integrals of g_k and of
        g_k int_S N_l are constants of the mesh (made in __init__)."""
        out = self._integrals[:, :, None] * (self._beyond + offset)[:, None, :]
        out += np.matmul(self.tail_integrals, self.element_values)
        return out
