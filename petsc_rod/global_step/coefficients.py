"""The stiffness of the three fields d1, d2, r' along the line, on this rank's elements
(docs/method.md §2, §4; numpy only).

The energy w = a1|d1'|^2 + a2|d2'|^2 + a3|r''|^2 has a_i = a_i(S) from the stiffness
(K1, K2, K3)(S) of the scene (Scene.stiffness_at), pointwise (frames.split_coefficients),
and the global step's matrices use c_i(S), the matrices' split of a_i(S) at each point
(problem/penalty.matrix_split: c_j = max_i a_i where a_j < 0). Each field i has three
stiffness matrices, with K_s = int s(S) g_k' g_l' dS the P2 stiffness of a coefficient s:

    the energy's  K_{2 a_i},   the global step's  K_{2 c_i},   the lagged part's
    K_{2 (c_i - a_i)} = K_{2 c_i} - K_{2 a_i} (its right-hand side, GlobalStep).

On a line of uniform stiffness (Scene.uniform_stiffness) every s is a constant, and
each matrix is that constant times the one unit-coefficient K: the code path of the
constant triple, kept unchanged (the same arithmetic, the same bits). Otherwise each is
integrated on each element by the 3-point Gauss rule on its pieces between the section
ends (elements.cut_gauss_rule): exact for a stiffness linear along each section (a
taper) whether or not a section end falls inside an element. The matrices' c_i is
taken at the quadrature points, like a_i, so that K_{2 c_i} - K_{2 (c_i - a_i)} is
K_{2 a_i} to round-off and the fixed points are those of the true split.
"""

import numpy as np

from petsc_rod.frames import split_coefficients
from petsc_rod.mesh.elements import (cut_gauss_rule, lumped_mass, p2_element_matrices,
                                     p2_stiffness_matrices)

# The parts of a field's stiffness (FieldCoefficients.part).
ENERGY, LAGGED = "energy", "lagged"


class FieldCoefficients:
    """The coefficients of the three fields' stiffness on the owned elements of a mesh
    (``element_S``, ``element_h``, (ne,), m) for a Scene, with ``matrix_split`` the
    policy c(a) (penalty.matrix_split, pointwise on (..., 3)).

    uniform: the line's stiffness is one triple (Scene.uniform_stiffness); then
    ``split`` and ``matrix_split`` are the a_i and c_i, (3,), N m^2.
    lagged_fields: the fields i with a_i < 0 somewhere on the line (their matrices use
    c_i != a_i), decided from the stiffness at the section ends (Scene.stiffness_values:
    the a_i are linear along each section), so the same on every rank.
    """

    def __init__(self, scene, element_S, element_h, matrix_split):
        self.h = np.asarray(element_h, dtype=float)
        self.uniform = scene.uniform_stiffness
        ends = split_coefficients(scene.stiffness_values())            # (2 m, 3)
        self.lagged_fields = tuple(int(i) for i in np.flatnonzero(np.any(ends < 0, axis=0)))
        self._matrices = {}
        if self.uniform:
            self.split = split_coefficients(scene.stiffness)
            self.matrix_split = matrix_split(self.split)
            return
        xi, weights = cut_gauss_rule(element_S, self.h, scene.stiffness_breaks)
        S = np.asarray(element_S, dtype=float)[:, None] + xi * self.h[:, None]
        a = split_coefficients(scene.stiffness_at(S))                   # (ne, nq, 3)
        c = matrix_split(a)
        self._matrices = {
            ENERGY: p2_stiffness_matrices(self.h, xi, weights, 2 * a),     # (3, ne, 3, 3)
            "matrix": p2_stiffness_matrices(self.h, xi, weights, 2 * c),
            LAGGED: p2_stiffness_matrices(self.h, xi, weights, 2 * (c - a))}

    def global_step_matrices(self, i, penalty):
        """Element matrices of field i's global-step matrix 2 c_i K + R W at penalty R
        (N), (ne, 3, 3)."""
        if self.uniform:
            return p2_element_matrices(self.h, 2 * self.matrix_split[i], penalty)
        return self._matrices["matrix"][i] + penalty * lumped_mass(self.h)

    def part(self, i, name):
        """Field i's ENERGY stiffness 2 a_i K or its LAGGED part 2 (c_i - a_i) K as
        (factor, key, element_matrices): ``factor`` times the matrix assembled from
        ``element_matrices()`` (ne, 3, 3); parts with the same key are one matrix (on a
        uniform line the unit-coefficient K, with the constant as the factor)."""
        if self.uniform:
            a, c = self.split[i], self.matrix_split[i]
            factor = 2 * a if name == ENERGY else 2 * (c - a)
            return factor, "unit", lambda: p2_element_matrices(self.h, 1.0, 0.0)
        return 1.0, (name, i), lambda: self._matrices[name][i]

    def hessian_stiffness(self):
        """The bending and torsion part of the second variation (analysis/second_variation.py)
        as (weights, element matrices): uniform, the three 2 a_i (3,) and the unit K
        (ne, 3, 3); otherwise ones and each field's K_{2 a_i} (3, ne, 3, 3)."""
        if self.uniform:
            return 2 * np.asarray(self.split), p2_element_matrices(self.h, 1.0, 0.0)
        return np.ones(3), self._matrices[ENERGY]
