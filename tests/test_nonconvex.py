"""The non-convex split (a stiffness above the sum of the other two, method.md §2).

The penalty is raised above the floor 2 |a_i| 60 / h^2 that keeps the global-step
matrices positive definite (solver.effective_penalty). These tests check the floor itself
(the element bound is sharp: below it the assembled matrix is indefinite) and that a
non-convex section reaches the right equilibrium.
"""

import numpy as np
import pytest
import scipy.linalg

from helpers import continuation, gather
from petsc_rod.closed_forms import cantilever_tip
from petsc_rod.fe import (GAUSS_POINTS, STIFFNESS_TO_MASS_MAX, gram, p2_basis,
                          p2_element_matrices, quadrature_weights)
from petsc_rod.kernels import split_coefficients
from petsc_rod.outputs import vertex_fields
from petsc_rod.solver import NONCONVEX_MARGIN, effective_penalty


def test_stiffness_to_mass_bound_of_the_p2_element():
    """lambda_max(K_e, M_e) h^2 = 60 for the P2 pair (int g'.g', int g.g) of every field
    of the global step (d1, d2 and the slope theta = r')."""
    h = np.array([1.0])
    w = quadrature_weights(h)
    phi, dphi = p2_basis(GAUSS_POINTS, h)
    p2 = scipy.linalg.eigh(gram(w, dphi, dphi)[0], gram(w, phi, phi)[0], eigvals_only=True)
    assert abs(p2.max() - STIFFNESS_TO_MASS_MAX) < 1e-9


def assembled(element_matrices):
    """Global matrix of a uniform chain of P2 elements (dofs 2e, 2e + 1, 2e + 2)."""
    ne = element_matrices.shape[0]
    a = np.zeros((2 * ne + 1, 2 * ne + 1))
    for e, block in enumerate(element_matrices):
        a[2 * e:2 * e + 3, 2 * e:2 * e + 3] += block
    return a


@pytest.mark.serial
def test_penalty_floor_makes_the_director_matrix_positive_definite():
    """K = (235, 360, 100): a2 = -6.25. At NONCONVEX_MARGIN times the floor the smallest
    eigenvalue of 2 a2 K + R M is positive; at half the floor it is negative."""
    stiffness = np.array([235.0, 360.0, 100.0])
    a = split_coefficients(stiffness)
    h = np.full(20, 1.0)
    penalty = effective_penalty(400.0, a, h.min())
    floor = 2 * 6.25 * STIFFNESS_TO_MASS_MAX / h.min()**2
    assert np.isclose(penalty, NONCONVEX_MARGIN * floor)
    smallest = np.linalg.eigvalsh(assembled(p2_element_matrices(h, 2 * a[1], penalty)))[0]
    assert smallest > 0
    below = np.linalg.eigvalsh(assembled(p2_element_matrices(h, 2 * a[1], 0.5 * floor)))[0]
    assert below < 0
    convex = effective_penalty(400.0, split_coefficients([235.0, 360.0, 200.0]), h.min())
    assert convex == 400.0


@pytest.mark.serial
def test_penalty_floor_of_the_r_matrix():
    """K3 > K1 + K2 makes a3 < 0: the slope matrix 2 a3 K + R M (theta = r') with the
    raised penalty is positive definite; at half the floor it is not."""
    a = split_coefficients([1.0, 1.0, 10.0])
    h = np.full(20, 0.1)
    penalty = effective_penalty(1.0, a, h.min())
    assert np.linalg.eigvalsh(assembled(p2_element_matrices(h, 2 * a[2], penalty)))[0] > 0
    floor = 2 * abs(a[2]) * STIFFNESS_TO_MASS_MAX / h.min()**2
    below = assembled(p2_element_matrices(h, 2 * a[2], 0.5 * floor))
    assert np.linalg.eigvalsh(below)[0] < 0


def test_nonconvex_cantilever_against_elastica(comm, solver_factory):
    """A ribbon-like section K = (1, 3, 1) (a2 = -0.25) bent in its stiff plane by a tip
    force P L^2 / K2 = 1.5 (below lateral-torsional buckling, P_cr L^2 ~ 4 sqrt(K1 K3)):
    planar, tip within 2e-3 of the elastica with EI = K2 on 8 elements (measured 1.2e-3,
    the penalty is 7680 for a stiffness of 3), on 1 and 2 ranks."""
    scene = dict(length=1.0, stiffness=[1.0, 3.0, 1.0], start="clamp", end="free",
                 end_force=[0.0, -4.5, 0.0])
    mesh, solver = solver_factory(comm, 8, scene, penalty=7680.0, rtol=1e-8, ctol=1e-5,
                                  max_it=30000)
    report = continuation(solver)
    assert report.converged
    r = gather(comm, vertex_fields(solver, 1.0)["r"])
    assert np.abs(r[-1, :2] - cantilever_tip(1.0, 3.0, 4.5)).max() < 2e-3
    assert np.abs(r[:, 2]).max() < 1e-10
