"""What a Newton step's matrices cost to assemble again (analysis/second_variation.py,
docs/performance.md "Newton steps"), on one rank (PETSc.COMM_SELF) and on all ranks
(PETSc.COMM_WORLD: under ``mpiexec -n 2`` the parallel run).

A riser with a seabed and a current (60 elements, its catenary start): H carries the
heights' chain and the resultants' identity rows, and the seabed's curvature is zero
off the contact.

(a) H assembled again at the same state (SecondVariation.update) is the same matrix bit
    for bit, its pattern kept; the update hands MatSetValues no block of zeros (the
    places they reserve are in the pattern since the first assembly) and not the
    resultants' identity (added through the diagonal);
(b) the drag's entries of the Newton Jacobian come in one block per element and kind of
    row (the frames' rows, the resultants' chain): each of those rows is searched once;
(c) the element blocks of the bending and torsion part of H (one batched product of the
    nodes' director matrices) against their definition by cross-product matrices,
    sum_i w_i K_ab [d_a,i]x^T [d_b,i]x, for directors that are not rotations (an
    iterate's fields), one stiffness and one per field.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.analysis.jacobian import NewtonJacobian
from petsc_rod.analysis.second_variation import SecondVariation, skew

from petsc_rod.environment.current import Current
from petsc_rod.environment.seabed import Seabed
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}

RISER = dict(length=1800.0, stiffness=(5.6e7, 5.6e7, 4.3e7), start="pin", end="pin",
             end_position=(1157.0, 0.0, 1000.0), load_values=[[0.0, 0.0, -1200.0]],
             seabed=Seabed(0.0, 1.2e6),
             current=Current.uniform((0.5, 0.0, 0.0), 1025.0, 1.2, 0.324))


@pytest.fixture(scope="module", params=list(COMMS))
def comm(request):
    return COMMS[request.param]


class CountingMatrix:
    """A Mat's stand-in that keeps every block handed to setValuesRCV."""

    def __init__(self, matrix):
        self._matrix = matrix
        self.blocks = []

    def setValuesRCV(self, rows, columns, values, addv=None):
        self.blocks.append((np.asarray(rows), np.asarray(columns), np.asarray(values)))
        self._matrix.setValuesRCV(rows, columns, values, addv=addv)

    def __getattr__(self, name):
        return getattr(self._matrix, name)


def counted(owner, work):
    """The blocks handed to ``owner.matrix``'s setValuesRCV while ``work()`` runs (the
    matrix stood in for by a CountingMatrix meanwhile)."""
    real = owner.matrix
    counting = CountingMatrix(real)
    owner.matrix = counting
    try:
        work()
    finally:
        owner.matrix = real
    return counting.blocks


def diagonal_places(rows, columns, targets):
    """How many places of blocks at ``rows`` (k, r) and ``columns`` (k, c) are on the
    diagonal in a row of ``targets``."""
    diagonal = rows[:, :, None] == columns[:, None, :]
    return int(np.sum(diagonal & np.isin(rows, targets)[:, :, None]))


def local_csr(matrix):
    indptr, indices, values = matrix.getValuesCSR()
    return indptr.copy(), indices.copy(), values.copy()


def riser_hessian(comm, solver_factory):
    """(mesh, H) of RISER at an iterate from its catenary start."""
    mesh, solver = solver_factory(comm, 60, RISER, 1e6)
    problem = solver.problem
    problem.state.set_from_curve(catenary_start(Scene(**dict(RISER, current=None)), 1.0))
    problem.prepare(1.0)
    problem.iterate()                   # multipliers of an iterate, the heights' contact
    return mesh, problem.second_variation()


def test_an_update_adds_no_zeros_and_gives_the_same_matrix(comm, solver_factory):
    mesh, hessian = riser_hessian(comm, solver_factory)
    assert hessian.resultants and hessian.positions
    before = local_csr(hessian.matrix)
    blocks = counted(hessian, hessian.update)
    after = local_csr(hessian.matrix)
    same = all(np.array_equal(a, b) for a, b in zip(before, after))
    assert mesh.global_min(int(same)) == 1
    # part of the line rests on the seabed, part hangs: the seabed's curvature is zero
    # on some nodes and not on others
    zero_blocks = sum(int(np.sum(~np.any(values != 0.0, axis=(1, 2))))
                      for _, _, values in blocks)
    assert mesh.global_sum(zero_blocks) == 0
    on_identity = sum(diagonal_places(rows, columns, hessian.resultant_rows)
                      for rows, columns, _ in blocks)
    assert mesh.global_sum(on_identity) == 0
    assert mesh.global_sum(sum(len(values) for _, _, values in blocks)) > 0


def test_the_drags_entries_come_in_one_block_per_kind_of_row(comm, solver_factory):
    mesh, hessian = riser_hessian(comm, solver_factory)
    jacobian = NewtonJacobian(hessian)
    try:
        jacobian.assemble()
        blocks = counted(jacobian, jacobian._add_terms)
    finally:
        jacobian.destroy()
    searched = sum(rows.size for rows, _, _ in blocks)
    # the frames' rows of the element's three nodes and the chain's three rows
    rows = mesh.n_local_elements * (3 * hessian.unknowns + 3)
    assert mesh.global_sum(searched) == mesh.global_sum(rows) > 0


@pytest.mark.parametrize("per_field", [False, True])
def test_element_blocks_are_those_of_the_cross_product_matrices(per_field):
    rng = np.random.default_rng(7)
    ne = 5
    d = rng.standard_normal((ne, 3, 3, 3))                 # (element, node, director, 3)
    weights = np.array([2.0, 3.0, 0.5])
    stiffness = rng.standard_normal((3, ne, 3, 3) if per_field else (ne, 3, 3))
    crossed = skew(d)                                       # (ne, node, i, 3, 3)
    expected = np.zeros((ne, 3, 3, 3, 3))
    for i in range(3):
        K = stiffness[i] if per_field else stiffness
        # [d_a,i]x^T [d_b,i]x, (ne, a, s, b, t)
        pair = np.einsum("eaks,ebkt->easbt", crossed[:, :, i], crossed[:, :, i])
        expected += weights[i] * K[:, :, None, :, None] * pair
    blocks = SecondVariation._element_blocks(d, weights, stiffness)
    assert np.allclose(blocks, expected, rtol=0.0, atol=1e-13 * np.abs(expected).max())
