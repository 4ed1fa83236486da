"""The matrices' split of the stiffness (problem/penalty.py matrix_split), numpy only:
positive coefficients, the convex split unchanged, and positive definite matrices at a
small penalty on any mesh."""

import numpy as np
import pytest

from petsc_rod.frames import split_coefficients
from petsc_rod.problem.penalty import matrix_split
from petsc_rod.mesh.elements import p2_element_matrices


def assembled(element_matrices):
    """Global matrix of a uniform chain of P2 elements (dofs 2e, 2e + 1, 2e + 2)."""
    ne = element_matrices.shape[0]
    a = np.zeros((2 * ne + 1, 2 * ne + 1))
    for e, block in enumerate(element_matrices):
        a[2 * e:2 * e + 3, 2 * e:2 * e + 3] += block
    return a


@pytest.mark.parametrize("stiffness", [(235.0, 360.0, 100.0), (1.0, 1000.0, 1.0),
                                       (1.0, 1.0, 10.0), (50.0, 1.0, 1.0)])
def test_matrix_split_is_positive_and_keeps_the_positive_coefficients(stiffness):
    a = split_coefficients(stiffness)
    c = matrix_split(a)
    assert (a < 0).sum() == 1
    assert np.all(c > 0)
    assert np.all(c[a > 0] == a[a > 0])
    assert c[a < 0] == a.max()


def test_convex_split_is_unchanged():
    a = split_coefficients([235.0, 360.0, 200.0])
    assert np.all(matrix_split(a) == a)


@pytest.mark.parametrize("elements", [20, 400])
def test_matrices_are_positive_definite_at_a_small_penalty_on_any_mesh(elements):
    """The true split's matrix 2 a_2 K + R W is indefinite at this R and mesh (which is
    why the old method raised R like 1/h^2); the matrix actually used is not."""
    a = split_coefficients([235.0, 360.0, 100.0])
    h = np.full(elements, 20.0 / elements)
    penalty = 1.0
    true = np.linalg.eigvalsh(assembled(p2_element_matrices(h, 2 * a[1], penalty)))[0]
    used = np.linalg.eigvalsh(assembled(p2_element_matrices(h, 2 * matrix_split(a)[1],
                                                            penalty)))[0]
    assert true < 0 < used
