"""The substructured factorisation of the Newton steps' systems on several ranks
(global_step/chain_factor.py): on a chain of nodes of B unknowns laid out as the Newton
systems are (a rank's rows start at a vertex; element e couples nodes 2e, 2e + 1,
2e + 2), its solves agree with a dense solve of the whole matrix to round-off, for the
LU of an unsymmetric matrix and the LDL^T of a symmetric indefinite one, whose count of
negative eigenvalues is the dense matrix's; with ``rows`` (a submatrix of the kept rows,
as the second variation leaves out the drag's resultants) the left-out rows return the
right-hand side. A singular interface (a null vector through the whole chain, as the
free roll) gives a finite solution of the consistent system. direct_factor chooses it
on several ranks unless -<prefix>substructuring 0 (here the prefix test_chain_). Under a
serial run the factor is the interior's alone; under 3 or more ranks a middle rank has
both interfaces (run by hand, `mpiexec -n 3` and `-n 4`: CI runs 1 and 2). An operator
that is no chain, or a regular one with a singular interior, is factored by MUMPS on all
ranks; on one rank direct_factor's LU is PETSc's own in the natural order
(global_step/ksp.NaturalLU, MUMPS's only where its check fails) and its LDL^T MUMPS's."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import gather
from petsc_rod.global_step import chain_factor
from petsc_rod.global_step import ksp as solvers
from petsc_rod.global_step.chain_factor import ChainFactor, _column_range
from petsc_rod.global_step.substructuring import NotAChainError
from petsc_rod.mesh.mesh import Mesh

BLOCK = 3
N_ELEMENTS = 24


def chain(comm, kind, singular=False, scales=(1.0, 1.0, 1.0), column_scales=None):
    """(mesh, matrix, dense whole matrix) of random element blocks (3 B square, SPD
    plus a diagonal of either sign for the LDL^T; unsymmetric for the LU, its pattern
    too); ``singular``: symmetric positive semi-definite with each slot's constant as
    a null vector; ``scales`` multiply each slot's rows (B of them) and its columns,
    or ``column_scales`` these (R A C: equations and unknowns of different units)."""
    mesh = Mesh(comm, N_ELEMENTS, 1.0)
    n = BLOCK * (2 * N_ELEMENTS + 1)
    rng = np.random.default_rng(5)
    blocks = rng.standard_normal((N_ELEMENTS, 3 * BLOCK, 3 * BLOCK))
    if singular:
        difference = np.kron(np.array([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0]]), np.eye(BLOCK))
        blocks = np.array([difference.T @ np.diag(rng.uniform(1, 2, 2 * BLOCK)) @ difference
                           for _ in range(N_ELEMENTS)])
    elif kind == PETSc.PC.Type.CHOLESKY:
        blocks = blocks @ blocks.transpose(0, 2, 1) * 0.1
        signs = np.where(rng.random((N_ELEMENTS, 3 * BLOCK)) < 0.3, -4.0, 4.0)
        blocks += signs[:, :, None] * np.eye(3 * BLOCK)
    else:
        blocks += 6.0 * np.eye(3 * BLOCK)
        # the left vertex's rows do not reach the right vertex, whose rows reach back
        # to it: the interface's rows reach further into the previous rank than that
        # rank's rows reach the interface (as the drag's chain rows of J)
        blocks[:, :BLOCK, 2 * BLOCK:] = 0.0
    skipped = {(0, 2)} if kind == PETSc.PC.Type.LU and not singular else set()
    # unknowns of other units (turns against heights and resultants on the riser): D A D
    slots = np.tile(np.asarray(scales, dtype=float), 3)
    column_slots = slots if column_scales is None else np.tile(
        np.asarray(column_scales, dtype=float), 3)
    blocks = slots[None, :, None] * blocks * column_slots[None, None, :]
    dense = np.zeros((n, n))
    for e in range(N_ELEMENTS):
        rows = np.arange(2 * e * BLOCK, (2 * e + 3) * BLOCK)
        dense[np.ix_(rows, rows)] += blocks[e]
    first = 2 * mesh.vertex_start * BLOCK
    local = BLOCK * mesh.n_local_nodes
    matrix = PETSc.Mat().createAIJ(((local, n), (local, n)), nnz=(5 * BLOCK, 2 * BLOCK),
                                   comm=comm)
    for e in range(mesh.element_start, mesh.element_end):
        for a in range(3):
            for c in range(3):
                if (a, c) in skipped:
                    continue
                rows = np.arange((2 * e + a) * BLOCK, (2 * e + a + 1) * BLOCK,
                                 dtype=PETSc.IntType)
                columns = np.arange((2 * e + c) * BLOCK, (2 * e + c + 1) * BLOCK,
                                    dtype=PETSc.IntType)
                matrix.setValues(rows, columns, blocks[e, a * BLOCK:(a + 1) * BLOCK,
                                                       c * BLOCK:(c + 1) * BLOCK],
                                 addv=PETSc.InsertMode.ADD_VALUES)
    matrix.assemble()
    assert first == matrix.getOwnershipRange()[0]
    return mesh, matrix, dense


def self_and_transposed(comm, a, b):
    """Every rank's pair (a, b) and (b, a), for the dense copy."""
    return [pair for a_r, b_r in comm.tompi4py().allgather((a, b))
            for pair in ((a_r, b_r), (b_r, a_r))]


def factor_of(matrix, kind, interior=solvers.MumpsFactor):
    """The ChainFactor of ``matrix``, set up, its interiors factored by ``interior``
    (ksp.MumpsFactor, or ksp.NaturalLU of an LU)."""
    def make(local):
        if interior is solvers.NaturalLU:
            return solvers.NaturalLU(local, BLOCK, "test_chain_")
        return interior(local, kind, BLOCK, "test_chain_")
    factor = ChainFactor(matrix, kind, BLOCK, make, reorder=interior is not solvers.NaturalLU)
    factor.set_up(matrix)
    return factor


@pytest.mark.parametrize("kind, scales, column_scales, interior", [
    (kind, scales, None, solvers.MumpsFactor)
    for kind in (PETSc.PC.Type.LU, PETSc.PC.Type.CHOLESKY)
    for scales in ((1.0, 1.0, 1.0), (1.0, 1e4, 1e-4))] + [
    (PETSc.PC.Type.LU, (1e3, 1.0, 1e-3), (1e-2, 1e3, 1.0), solvers.MumpsFactor)] + [
    (PETSc.PC.Type.LU, scales, column_scales, solvers.NaturalLU)
    for scales, column_scales in (((1.0, 1.0, 1.0), None), ((1.0, 1e4, 1e-4), None),
                                  ((1e3, 1.0, 1e-3), (1e-2, 1e3, 1.0)))])
def test_solves_and_inertia_agree_with_a_dense_factorisation(kind, scales, column_scales,
                                                             interior):
    """Unknowns of units 1e8 apart too (D A D, D the slots' scales): the interface's
    Schur complement spans 1e16 there, and its inertia and inverse must not lose the
    small ones; of the LU also equations and unknowns of other scales (R A C), with
    the interiors factored by MUMPS and by PETSc's own LU in the natural order (as
    ksp.direct_factor does by default), which must not hand over to MUMPS here. The
    solutions are compared in the unscaled unknowns C x, with A's own dense solve (the
    scaled matrix's is 1e8 times worse conditioned), to round-off."""
    comm = PETSc.COMM_WORLD
    mesh, matrix, dense = chain(comm, kind, scales=scales, column_scales=column_scales)
    slots = np.tile(np.asarray(scales), len(dense) // BLOCK)
    column_slots = slots if column_scales is None else np.tile(
        np.asarray(column_scales), len(dense) // BLOCK)
    factor = factor_of(matrix, kind, interior)
    if interior is solvers.NaturalLU:
        assert not factor.solver.fell_back

    def assert_solves(column, solution):
        unscaled = dense / slots[:, None] / column_slots[None, :]
        expected = np.linalg.solve(unscaled, gather(comm, column) / slots)
        error = column_slots * gather(comm, solution) - expected
        assert np.abs(error).max() <= 1e-12 * np.abs(expected).max()

    try:
        start, end = matrix.getOwnershipRange()
        columns = [np.sin((j + 1) * np.arange(start, end)) for j in range(3)]
        for column, solution in zip(columns, factor.solve_columns(columns)):
            assert_solves(column, solution)
        if kind == PETSc.PC.Type.CHOLESKY:
            # of the unscaled matrix, whose inertia D A D has (Sylvester): eigvalsh of
            # the scaled one miscounts (39 against 35) at 1e-16 of its 1e8 norm
            unscaled = dense / slots[:, None] / slots[None, :]
            negative = int(np.sum(np.linalg.eigvalsh(unscaled) < 0))
            assert negative > 0 and factor.negative_pivots() == negative
        # new values on the same pattern, then a new nonzero inside each rank's interior
        # (a wider band there): the factorisation and its inertia follow them
        matrix.shift(0.5)
        dense += 0.5 * np.eye(len(dense))
        for grown in (False, True):
            if grown:
                first = start + (BLOCK if comm.getRank() > 0 else 0)
                a, b = first + 1, first + 3 * BLOCK + 1
                matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
                matrix.setValue(a, b, 0.25)
                matrix.setValue(b, a, 0.25)
                matrix.assemble()
                for i, j in self_and_transposed(comm, a, b):
                    dense[i, j] += 0.25
            factor.set_up(matrix)
            assert_solves(columns[0], factor.solve_columns(columns[:1])[0])
            if kind == PETSc.PC.Type.CHOLESKY:
                unscaled = dense / slots[:, None] / slots[None, :]
                assert factor.negative_pivots() == int(np.sum(np.linalg.eigvalsh(unscaled) < 0))
    finally:
        factor.destroy()
        matrix.destroy()
        mesh.destroy()


@pytest.mark.parametrize("kind", [PETSc.PC.Type.CHOLESKY, PETSc.PC.Type.LU])
def test_a_submatrix_s_left_out_rows_return_the_right_hand_side(kind):
    """The second variation's kept rows (analysis/stability.py): a submatrix's solve
    gathers its rows from the columns and scatters them back, the others keeping the
    right-hand side; of the LU also with the first rank's interior reversed."""
    comm = PETSc.COMM_WORLD
    mesh, matrix, dense = chain(comm, kind)
    start, end = matrix.getOwnershipRange()
    kept = np.arange(start, end)[np.arange(start, end) % BLOCK != 2]     # 2 of 3 a node
    index = PETSc.IS().createGeneral(kept.astype(PETSc.IntType), comm=comm)
    sub = matrix.createSubMatrix(index, index)

    def make(local):
        return solvers.MumpsFactor(local, kind, BLOCK - 1, "test_chain_")
    factor = ChainFactor(sub, kind, BLOCK - 1, make)
    try:
        factor.set_up(sub)
        column = np.cos(np.arange(start, end))
        solution = factor.solve_columns([column], kept - start)[0]
        whole_kept = np.flatnonzero(np.arange(len(dense)) % BLOCK != 2)
        expected = np.linalg.solve(dense[np.ix_(whole_kept, whole_kept)],
                                   gather(comm, column[kept - start]))
        assert np.abs(gather(comm, solution[kept - start]) - expected).max() <= 1e-12 * np.abs(
            expected).max()
        left_out = np.setdiff1d(np.arange(end - start), kept - start)
        assert np.array_equal(solution[left_out], column[left_out])
    finally:
        for obj in (factor, sub, index, matrix, mesh):
            obj.destroy()


def test_a_null_vector_through_the_chain_gives_a_finite_consistent_solution():
    """The element blocks act on differences of neighbouring nodes: each slot's constant
    is a null vector through the whole chain (as the free roll), which every rank's
    interior block, coupled to its interfaces, does not have, and the interface's
    Schur complement does. A right-hand side orthogonal to them is solved to round-off,
    with no Inf or NaN."""
    comm = PETSc.COMM_WORLD
    kind = PETSc.PC.Type.CHOLESKY
    mesh, matrix, dense = chain(comm, kind, singular=True)
    start, end = matrix.getOwnershipRange()
    factor = factor_of(matrix, kind)
    try:
        whole = np.sin(np.arange(len(dense)) * 0.7).reshape(-1, BLOCK)
        whole -= whole.mean(axis=0)                  # orthogonal to the null vectors
        column = whole.ravel()[start:end]
        solution = factor.solve_columns([column])[0]
        assert np.all(np.isfinite(solution))
        residual = dense @ gather(comm, solution) - whole.ravel()
        assert np.abs(residual).max() <= 1e-10 * np.abs(whole).max()
    finally:
        factor.destroy()
        matrix.destroy()
        mesh.destroy()


@pytest.mark.parametrize("given", [None, "0"])
def test_direct_factor_substructures_on_several_ranks_unless_told_not_to(given):
    comm = PETSc.COMM_WORLD
    mesh, matrix, _ = chain(comm, PETSc.PC.Type.LU)
    options = PETSc.Options()
    if given is not None:
        options["test_chain_substructuring"] = given
    factor = solvers.direct_factor(matrix, PETSc.PC.Type.LU, BLOCK, "test_chain_")
    try:
        substructured = comm.getSize() > 1 and given is None
        assert factor.substructured == substructured
    finally:
        if given is not None:
            options.delValue("test_chain_substructuring")
        factor.destroy()
        matrix.destroy()
        mesh.destroy()


def test_an_operator_that_is_no_chain_is_factored_by_mumps_on_all_ranks():
    """A coupling of the first node to the last (a ring, as no Newton system of a line
    has): on several ranks the interface does not separate the ranks' interiors, so
    direct_factor falls back to MUMPS on all ranks (on one rank the LU is PETSc's own in
    the natural order, NaturalLU, whose check the ring's factors pass), whose solve
    agrees with the dense one."""
    comm = PETSc.COMM_WORLD
    mesh, matrix, dense = chain(comm, PETSc.PC.Type.LU)
    n = len(dense)
    matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    if comm.getRank() == 0:
        matrix.setValue(0, n - 1, 0.5)
        matrix.setValue(n - 1, 0, -0.5)
    matrix.assemble()
    dense[0, n - 1] += 0.5
    dense[n - 1, 0] -= 0.5
    factor = solvers.direct_factor(matrix, PETSc.PC.Type.LU, BLOCK, "test_chain_")
    try:
        assert not factor.substructured
        factor.set_up(matrix)
        if comm.getSize() == 1:
            assert isinstance(factor, solvers.NaturalLU) and not factor.fell_back
        else:
            assert isinstance(factor, solvers.MumpsFactor)
        start, end = matrix.getOwnershipRange()
        column = np.sin(np.arange(start, end) + 0.3)
        solution = factor.solve_columns([column])[0]
        expected = np.linalg.solve(dense, gather(comm, column))
        assert np.abs(gather(comm, solution) - expected).max() <= 1e-12 * np.abs(
            expected).max()
    finally:
        factor.destroy()
        matrix.destroy()
        mesh.destroy()


def sequential_mumps(kind, rng, n=40):
    """(dense, matrix, ksp): an n x n matrix, unsymmetric for the LU, symmetric
    indefinite for the LDL^T, as a dense array and as a sequential AIJ, and its MUMPS
    factorisation ``kind``, set up (the caller destroys the ksp and the matrix)."""
    dense = rng.standard_normal((n, n)) + 8.0 * np.eye(n)
    if kind == PETSc.PC.Type.CHOLESKY:
        dense = dense + dense.T - 24.0 * np.diag(rng.random(n) < 0.3)
    matrix = PETSc.Mat().createAIJ((n, n), nnz=n, comm=PETSc.COMM_SELF)
    matrix.setValuesCSR(np.arange(n + 1, dtype=PETSc.IntType) * n,
                        np.tile(np.arange(n, dtype=PETSc.IntType), n), dense.ravel())
    matrix.assemble()
    ksp = solvers.mumps_solver(PETSc.COMM_SELF, matrix, kind, "test_chain_")
    solvers.set_up_mumps(ksp)
    return dense, matrix, ksp


@pytest.mark.parametrize("kind", [PETSc.PC.Type.LU, PETSc.PC.Type.CHOLESKY])
def test_sparse_right_hand_sides_solve_as_dense_ones(kind):
    """ksp.solve_sparse_columns (W's solve) on a sequential MUMPS factorisation: k = 3
    right-hand sides nonzero on a few rows given out of order, against a dense solve of
    the same matrix."""
    rng = np.random.default_rng(3)
    dense, matrix, ksp = sequential_mumps(kind, rng)
    n = len(dense)
    try:
        rows = np.array([37, 2, 19, 3, 0])
        values = rng.standard_normal((len(rows), 3))
        right = np.zeros((n, 3))
        right[rows] = values
        solution = solvers.solve_sparse_columns(ksp, rows, values)
        expected = np.linalg.solve(dense, right).T
        assert solution.shape == (3, n)
        assert np.abs(solution - expected).max() <= 1e-12 * np.abs(expected).max()
    finally:
        ksp.destroy()
        matrix.destroy()


@pytest.mark.parametrize("kind", [PETSc.PC.Type.LU, PETSc.PC.Type.CHOLESKY])
def test_dense_right_hand_sides_solve_in_the_arrays_given(kind):
    """ksp.solve_dense (the interiors' solves): k = 3 Fortran-ordered columns against a
    dense solve of the same matrix, the right-hand sides left as they were; an array
    petsc4py would copy (C-ordered) is refused, not solved into a copy."""
    rng = np.random.default_rng(5)
    dense, matrix, ksp = sequential_mumps(kind, rng)
    n = len(dense)
    try:
        right = np.asfortranarray(rng.standard_normal((n, 3)))
        given = right.copy()
        solution = solvers.solve_dense(ksp, right)
        expected = np.linalg.solve(dense, given)
        assert solution.shape == (n, 3) and solution.flags.f_contiguous
        assert np.abs(solution - expected).max() <= 1e-12 * np.abs(expected).max()
        assert np.array_equal(right, given)
        with pytest.raises(ValueError, match="Fortran-ordered"):
            solvers.solve_dense(ksp, np.ascontiguousarray(rng.standard_normal((n, 3))))
    finally:
        ksp.destroy()
        matrix.destroy()


@pytest.mark.parametrize("stray", [False, True], ids=["chain", "a middle row beyond"])
def test_each_row_s_column_range_is_its_least_and_greatest_column(stray, monkeypatch):
    """chain_factor._column_range (the chain's reaches) against every entry of the
    local rows (MatGetRow): on the chain, whose entries beyond the diagonal block lie on
    the ranks' first and last rows (read one by one), and with a middle row of every
    rank coupled beyond the next rank's interface (the whole local pattern read): the
    least and greatest columns of every row; the second is no chain on several ranks
    (ChainFactor refuses it). On several ranks _column_range takes the chain's reaches
    from its edge rows (_edge_rows gives them) and the stray row's from the whole pattern
    (_edge_rows gives None), where that row lies beyond the edge rows."""
    comm = PETSc.COMM_WORLD
    mesh, matrix, dense = chain(comm, PETSc.PC.Type.LU)
    n = len(dense)
    start, end = matrix.getOwnershipRange()
    middle, edge = (start + end) // 2, 3 * BLOCK
    if stray:
        matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        matrix.setValue(middle, (end + BLOCK) % n, 0.25)
    matrix.assemble()
    edge_rows = []                  # what _edge_rows gave inside _column_range
    original = chain_factor._edge_rows

    def recorded(*args):
        edge_rows.append(original(*args))
        return edge_rows[-1]

    monkeypatch.setattr(chain_factor, "_edge_rows", recorded)
    try:
        if stray and comm.getSize() > 1:          # collective: before any assertion
            with pytest.raises(NotAChainError):
                ChainFactor(matrix, PETSc.PC.Type.LU, BLOCK, None)
        edge_rows.clear()
        lowest, highest = _column_range(matrix, start, end, edge=edge)
        if comm.getSize() == 1:
            assert edge_rows == []                  # no rows beyond a block
        elif not stray:
            assert len(edge_rows) == 1 and edge_rows[0] is not None
        elif start + edge <= middle < end - edge:
            assert edge_rows == [None]
        reaches = np.array([(row.min(), row.max()) for row in
                            (matrix.getRow(r)[0] for r in range(start, end))])
        assert np.array_equal(lowest, reaches[:, 0])
        assert np.array_equal(highest, reaches[:, 1])
    finally:
        matrix.destroy()
        mesh.destroy()


@pytest.mark.parametrize("kind", [PETSc.PC.Type.LU, PETSc.PC.Type.CHOLESKY])
def test_a_singular_interior_of_a_regular_matrix_is_factored_whole(kind):
    """An unknown j of the last rank's interior coupled to its interface unknown g alone,
    with no diagonal (a saddle's multiplier: rows j and g read x_g = b_j and fix x_j):
    the whole matrix is regular, the interior singular (a null pivot, MUMPS's INFOG 28),
    so the substructuring does not apply. From that set_up on, the factor is MUMPS's on
    all ranks, whose solves and inertia are the dense matrix's. On one rank, where the
    interior is the whole matrix, the LU is PETSc's own in the natural order
    (NaturalLU, whose check its factors pass: the rows eliminated before j, g the first,
    make j's pivot nonzero) and the LDL^T MUMPS's."""
    comm = PETSc.COMM_WORLD
    mesh, matrix, dense = chain(comm, kind)
    start, end = matrix.getOwnershipRange()
    g = comm.tompi4py().allgather(start)[-1]
    j = g + BLOCK + 1
    last = comm.getRank() == comm.getSize() - 1
    matrix.zeroRowsColumns([j] if last else [], diag=0.0)
    matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    if last:
        matrix.setValue(j, g, 1.0)
        matrix.setValue(g, j, 1.0)
    matrix.assemble()
    dense[j, :] = 0.0
    dense[:, j] = 0.0
    dense[j, g] = dense[g, j] = 1.0
    factor = solvers.direct_factor(matrix, kind, BLOCK, "test_chain_")
    try:
        factor.set_up(matrix)
        assert not factor.substructured
        if comm.getSize() == 1 and kind == PETSc.PC.Type.LU:
            assert isinstance(factor, solvers.NaturalLU) and not factor.fell_back
        else:
            assert isinstance(getattr(factor, "factor", factor), solvers.MumpsFactor)
        column = np.cos(0.3 * np.arange(start, end))
        solution = factor.solve_columns([column])[0]
        expected = np.linalg.solve(dense, gather(comm, column))
        assert np.abs(gather(comm, solution) - expected).max() <= 1e-12 * np.abs(
            expected).max()
        if kind == PETSc.PC.Type.CHOLESKY:
            negative = int(np.sum(np.linalg.eigvalsh(dense) < 0))
            assert factor.negative_pivots() == negative
    finally:
        factor.destroy()
        matrix.destroy()
        mesh.destroy()
