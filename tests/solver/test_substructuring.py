"""The substructuring solve of the global step (global_step/substructuring.py).

On COMM_WORLD the chain matrices are split over the ranks; the solve must agree with
PETSc's serial Cholesky factorisation of the same matrix on one rank to round-off, for
the plain and the bordered (chord-constrained) problem, for partitions where a rank owns
a single vertex, and through the KSP (python PC) as well as through ScalarProblem's
multiple right-hand-side path. Under a serial run COMM_WORLD is one rank: the solve is
then the interior Cholesky alone.
"""

from contextlib import contextmanager

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import gather, global_max
from petsc_rod.global_step import substructuring
from petsc_rod.global_step.matrices import ScalarProblem, assemble_matrix
from petsc_rod.mesh.elements import element_integrals, p2_element_matrices
from petsc_rod.mesh.fields import VectorField
from petsc_rod.mesh.mesh import Mesh

# round-off of a direct solve of these matrices (condition ~ 1e4 to 1e6 here), relative
# to the size of the solution
ROUND_OFF = 1e-12


@contextmanager
def destroyed_after(*objects):
    """The block, then ``destroy()`` of each object, in order, whatever the block did
    (collective: every rank runs the same block)."""
    try:
        yield
    finally:
        for obj in objects:
            obj.destroy()


def chain_matrix(comm, n_elements, prescribed_rows=()):
    """A graded mesh's P2 matrix 2 K + 50 W with the given rows made identity rows (1
    and 2 elements cannot be graded: uniform, as they always were built)."""
    mesh = Mesh(comm, n_elements, 2.0, grading=3.0 if n_elements > 2 else 1.0)
    matrix = assemble_matrix(mesh, p2_element_matrices(mesh.element_h, 2.0, 50.0))
    rows = np.array(prescribed_rows, dtype=PETSc.IntType)
    start, end = matrix.getOwnershipRange()
    matrix.zeroRowsColumns(rows[(rows >= start) & (rows < end)], diag=1.0)
    return mesh, matrix


def right_hand_sides(mesh, k):
    """k smooth-and-rough right-hand sides on the owned rows, the same on any partition."""
    start, end = 2 * mesh.vertex_start, 2 * mesh.vertex_end
    rows = np.arange(start, end)
    return [np.sin(0.37 * (j + 1) * rows) + (j + 1) * np.cos(0.011 * rows) for j in range(k)]


def serial_cholesky(n_elements, prescribed_rows, rhs):
    """The reference: PETSc's Cholesky of the whole matrix on one rank."""
    mesh, matrix = chain_matrix(PETSc.COMM_SELF, n_elements, prescribed_rows)
    ksp = PETSc.KSP().create(comm=PETSc.COMM_SELF)
    try:
        ksp.setOperators(matrix)
        ksp.setType(PETSc.KSP.Type.PREONLY)
        ksp.getPC().setType(PETSc.PC.Type.CHOLESKY)
        b, x = matrix.createVecs()
        out = []
        for column in rhs:
            b.getArray()[:] = column
            ksp.solve(b, x)
            out.append(x.getArray().copy())
        b.destroy()
        x.destroy()
        return out
    finally:
        ksp.destroy()
        matrix.destroy()
        mesh.destroy()


def solved(solver, rhs):
    """The solver's solutions of the right-hand sides ``rhs`` (local arrays)."""
    solution = [np.zeros_like(column) for column in rhs]
    solver.solve(rhs, solution)
    return solution


def assert_solves(comm, matrix, rhs, solution):
    """A x = b to round-off for every column, on the owned rows of every rank."""
    b, x = matrix.createVecs()
    try:
        for column, y in zip(rhs, solution):
            x.getArray()[:] = y
            matrix.mult(x, b)
            scale = global_max(comm, np.abs(column).max())
            assert global_max(comm, np.abs(b.getArray() - column).max()) <= ROUND_OFF * scale
    finally:
        b.destroy()
        x.destroy()


@pytest.mark.parametrize("n_elements", [1, 3, 7, 40])
def test_chain_solver_agrees_with_serial_cholesky(n_elements):
    comm = PETSc.COMM_WORLD
    if comm.getSize() > n_elements + 1:
        pytest.skip("fewer vertices than ranks")
    fixed = (0, 1, 2 * n_elements, 2 * n_elements + 1)      # clamp, clamp, phantom
    mesh, matrix = chain_matrix(comm, n_elements, fixed)
    solver = substructuring.ChainSolver(matrix)
    with destroyed_after(solver, matrix, mesh):
        rhs = right_hand_sides(mesh, 3)
        solution = solved(solver, rhs)
        whole = [gather(comm, x) for x in solution]
        reference = serial_cholesky(n_elements, fixed, [gather(comm, b) for b in rhs])
        for x, y in zip(whole, reference):
            assert np.abs(x - y).max() <= ROUND_OFF * np.abs(y).max()
        assert_solves(comm, matrix, rhs, solution)


def test_every_rank_owns_interior_rows_and_the_interface_is_one_row_per_boundary():
    comm = PETSc.COMM_WORLD
    mesh, matrix = chain_matrix(comm, 20, (41,))      # the phantom slot pinned
    solver = substructuring.ChainSolver(matrix)
    with destroyed_after(solver, matrix, mesh):
        start, end = matrix.getOwnershipRange()
        assert solver.interior.matrix.getSize()[0] == end - start - (comm.getRank() > 0)
        assert solver.width == 1
        if comm.getSize() == 1:
            assert solver.schur is None
        else:       # S, of one row per boundary, positive definite (S's diagonal)
            assert solver.schur.matrix.getSize() == (comm.getSize() - 1,) * 2
            diagonal = solver.schur.matrix.getDiagonal()
            assert np.all(diagonal.getArray() > 0)
            diagonal.destroy()


def hermite_matrix(comm, n_elements):
    """A matrix in the Hermite layout of the riser's vertical problem: element e couples
    both dofs of its two vertices (rows 2e to 2e + 3), SPD element matrices; the value
    and the slope of a vertex both separate it, so the interface is 2 rows wide."""
    mesh = Mesh(comm, n_elements, 1.0)
    first = 2 * np.arange(mesh.element_start, mesh.element_end)[:, None]
    rows = (first + np.arange(4)[None, :]).astype(PETSc.IntType)
    rng = np.random.default_rng(7)
    b = rng.standard_normal((n_elements, 4, 4))
    elements = (b @ b.transpose(0, 2, 1) + np.eye(4))[mesh.element_start:mesh.element_end]
    matrix = mesh.da.createMatrix()
    if len(rows):
        matrix.setValuesRCV(rows, rows, elements, addv=PETSc.InsertMode.ADD_VALUES)
    matrix.assemble()
    return mesh, matrix, elements


def test_a_hermite_matrix_gets_an_interface_two_rows_wide():
    comm = PETSc.COMM_WORLD
    mesh, matrix, _ = hermite_matrix(comm, 12)
    solver = substructuring.ChainSolver(matrix)
    with destroyed_after(solver, matrix, mesh):
        assert solver.width == (2 if comm.getSize() > 1 else 1)
        rhs = right_hand_sides(mesh, 2)
        solution = solved(solver, rhs)
        assert_solves(comm, matrix, rhs, solution)


def set_symmetric(matrix, row, column, value):
    """Set the entries (row, column) and (column, row), both in this rank's rows."""
    matrix.setValue(row, column, value)
    matrix.setValue(column, row, value)


def test_refactor_keeps_the_interior_factor_where_a_zero_in_the_envelope_becomes_nonzero():
    # the riser's vertical problem: a vertex's value-slope entry cancels until the
    # seabed's spring acts there; the interior block keeps it as a zero (it lies in the
    # envelope Cholesky fills), so new values there are a numeric refactorisation
    comm = PETSc.COMM_WORLD
    mesh, matrix, _ = hermite_matrix(comm, 24)
    start, _ = matrix.getOwnershipRange()
    row = start + 4            # a vertex's value row, interior on every rank
    set_symmetric(matrix, row, row + 1, 0.0)
    matrix.assemble()
    solver = substructuring.ChainSolver(matrix)
    interior = solver.interior
    with destroyed_after(solver, matrix, mesh):
        set_symmetric(matrix, row, row + 1, 0.3)
        matrix.assemble()
        matrix.shift(1.0)
        assert solver.refactor(matrix)
        assert solver.interior is interior        # refactored, not made anew
        rhs = right_hand_sides(mesh, 2)
        solution = solved(solver, rhs)
        assert_solves(comm, matrix, rhs, solution)
        # the same factor as a solver made from the new matrix: the same numbers
        fresh = substructuring.ChainSolver(matrix)
        again = solved(fresh, rhs)
        fresh.destroy()
        assert all(np.array_equal(x, y) for x, y in zip(solution, again))


def test_refactor_grows_the_interior_block_by_a_new_entry_outside_the_envelope():
    # the P2 chain's DMDA stencil holds zeros between a midpoint and the next midpoint,
    # left out of the interior block; one that becomes nonzero must enter it
    comm = PETSc.COMM_WORLD
    mesh, matrix = chain_matrix(comm, 40, (81,))      # the phantom slot pinned
    start, _ = matrix.getOwnershipRange()
    row = start + 3            # a midpoint row, interior on every rank
    solver = substructuring.ChainSolver(matrix)
    interior = solver.interior
    with destroyed_after(solver, matrix, mesh):
        set_symmetric(matrix, row, row + 2, 0.01)
        matrix.assemble()
        assert solver.refactor(matrix)
        assert solver.interior is not interior     # the pattern grew
        rhs = right_hand_sides(mesh, 2)
        solution = solved(solver, rhs)
        assert_solves(comm, matrix, rhs, solution)


def test_a_noted_row_whose_pattern_grew_is_refused_and_the_solver_made_anew():
    """A refactorisation told which rows changed (ksp.note_changed_rows) reads those
    rows alone; where one of them has an entry the pattern had not (a new nonzero two
    vertices away, within the rank), it takes none of the values and says so on every
    rank (refactor False), and a solver made from the new matrix solves it exactly."""
    comm = PETSc.COMM_WORLD
    mesh, matrix, _ = hermite_matrix(comm, 24)
    start, end = matrix.getOwnershipRange()
    grown = PETSc.Mat().createAIJ(matrix.getSizes(), nnz=(12, 4), comm=comm)
    grown.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    rows, cols, values = matrix.getValuesCSR()
    for i in range(len(rows) - 1):
        grown.setValues(start + i, cols[rows[i]:rows[i + 1]], values[rows[i]:rows[i + 1]])
    grown.assemble()
    solver = substructuring.ChainSolver(grown)
    row = start + 4             # a vertex's value row, interior on every rank
    with destroyed_after(solver, grown, matrix, mesh):
        set_symmetric(grown, row, row + 4, 0.01)
        grown.assemble()
        assert not solver.refactor(grown, changed=[row, row + 4])
        rhs = right_hand_sides(mesh, 2)
        # refused, the solver is as it was: the factorisation of the matrix before
        assert_solves(comm, matrix, rhs, solved(solver, rhs))
        fresh = substructuring.ChainSolver(grown)
        solution = solved(fresh, rhs)
        fresh.destroy()
        assert_solves(comm, grown, rhs, solution)


def test_a_matrix_that_is_no_chain_is_refused():
    comm = PETSc.COMM_WORLD
    if comm.getSize() == 1:
        pytest.skip("one rank: every matrix is its own interior block")
    mesh, matrix = chain_matrix(comm, 20)
    try:
        # couple the first row with the last: an interior row of the first rank with an
        # interior row of the last
        big = matrix.getSize()[0] - 2
        coupled = PETSc.Mat().createAIJ(matrix.getSizes(), nnz=(8, 8), comm=comm)
        coupled.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        rows, cols, values = matrix.getValuesCSR()
        start, _ = matrix.getOwnershipRange()
        for i in range(len(rows) - 1):
            coupled.setValues(start + i, cols[rows[i]:rows[i + 1]], values[rows[i]:rows[i + 1]])
        if comm.getRank() == 0:
            coupled.setValue(1, big, 0.01)
            coupled.setValue(big, 1, 0.01)
        coupled.assemble()
        with pytest.raises(substructuring.NotAChainError):
            substructuring.ChainSolver(coupled)
        coupled.destroy()
    finally:
        matrix.destroy()
        mesh.destroy()


def problem_on(comm, prefix, bordered):
    """A ScalarProblem of a clamped start and a pinned end (phantom pinned), and its
    solution for three right-hand sides; with ``bordered`` the chord constraint too."""
    n_elements = 30
    mesh = Mesh(comm, n_elements, 2.0, grading=2.0)
    prescribed = [(0, 0, np.array([0.0, 0.6, 0.8])), (n_elements, 1, np.zeros(3))]
    problem = ScalarProblem(mesh, p2_element_matrices(mesh.element_h, 3.0, 20.0),
                            prescribed, prefix)
    rhs, solution = VectorField(mesh, "rhs"), VectorField(mesh, "x")
    try:
        problem.set_prescribed(prescribed)
        for c, vec in enumerate(rhs.components):
            vec.getArray()[:] = right_hand_sides(mesh, 3)[c]
        multiplier = None
        if bordered:
            problem.add_integral_constraint(element_integrals(mesh.element_h))
            multiplier = problem.solve_constrained(rhs, solution, np.array([1.2, 0.3, -0.4]))
        else:
            problem.solve(rhs, solution)
        kind = problem.ksp.getPC().getType()
        return gather(comm, solution.owned()), multiplier, kind
    finally:
        problem.destroy()
        rhs.destroy()
        solution.destroy()
        mesh.destroy()


@pytest.mark.parametrize("bordered", [False, True])
def test_scalar_problem_on_all_ranks_agrees_with_one_rank(bordered):
    """The default solver on COMM_WORLD (the substructuring PC on several ranks) against
    the serial default (Cholesky) on COMM_SELF: the fields and the chord multiplier."""
    many, mu_many, kind = problem_on(PETSc.COMM_WORLD, "test_sub_", bordered)
    one, mu_one, _ = problem_on(PETSc.COMM_SELF, "test_sub_", bordered)
    if PETSc.COMM_WORLD.getSize() > 1:
        assert kind == PETSc.PC.Type.PYTHON
    assert np.abs(many - one).max() <= ROUND_OFF * np.abs(one).max()
    assert np.abs(many[0, 0] - [0.0, 0.6, 0.8]).max() == 0.0      # the clamp, exactly
    if bordered:
        assert np.abs(mu_many - mu_one).max() <= ROUND_OFF * np.abs(mu_one).max()


def python_pc_ksp(matrix, prefix):
    """A preonly KSP on ``matrix`` whose PC is the substructuring's python PC, chosen by
    options under ``prefix`` as a user would (the options removed once read)."""
    database = PETSc.Options()
    names = {f"{prefix}pc_type": "python",
             f"{prefix}pc_python_type": substructuring.PYTHON_TYPE}
    for name, value in names.items():
        database.setValue(name, value)
    ksp = PETSc.KSP().create(comm=matrix.getComm())
    try:
        ksp.setOperators(matrix)
        ksp.setType(PETSc.KSP.Type.PREONLY)
        ksp.setOptionsPrefix(prefix)
        ksp.setFromOptions()
    finally:
        for name in names:
            database.delValue(name)
    return ksp


def test_the_python_pc_is_selected_by_options_and_solves_through_ksp():
    """-<prefix>pc_type python with the PC's class: exact through KSPSolve (the path of
    any caller that is not ScalarProblem.solve), on one rank too."""
    comm = PETSc.COMM_WORLD
    fixed = (0, 81)
    mesh, matrix = chain_matrix(comm, 40, fixed)
    ksp = python_pc_ksp(matrix, "test_pc_")
    try:
        assert ksp.getPC().getType() == PETSc.PC.Type.PYTHON
        b, x = matrix.createVecs()
        b.getArray()[:] = right_hand_sides(mesh, 1)[0]
        ksp.solve(b, x)
        assert ksp.getConvergedReason() > 0
        reference, = serial_cholesky(40, fixed, [gather(comm, b.getArray())])
        whole = gather(comm, x.getArray())
        assert np.abs(whole - reference).max() <= ROUND_OFF * np.abs(reference).max()
        b.destroy()
        x.destroy()
    finally:
        for obj in (ksp, matrix, mesh):
            obj.destroy()


def test_one_rank_keeps_the_cholesky_factorisation():
    _, _, kind = problem_on(PETSc.COMM_SELF, "test_sub_", False)
    assert kind == PETSc.PC.Type.CHOLESKY


def test_a_refactorisation_reads_only_the_rows_noted_as_changed(monkeypatch):
    """The riser's vertical problem changes a few elements at each change of the
    seabed's active set and notes their rows (ksp.note_changed_rows): the next set-up
    reads those rows alone, and the solves stay exact. A change not noted, before or
    after a noted one, before the next set-up, makes the set-up read every row (else the
    factor would be of a matrix that is not the operator)."""
    from petsc_rod.global_step.ksp import note_changed_rows
    comm = PETSc.COMM_WORLD
    mesh, matrix, _ = hermite_matrix(comm, 24)
    ksp = python_pc_ksp(matrix, "test_rows_")
    read = []                   # the rows each refactorisation was told of
    taken = []                  # whether it took the values (else a new solver is made)
    refactor = substructuring.ChainSolver.refactor

    def recorded(self, operator, changed=None):
        read.append(None if changed is None else sorted(changed))
        taken.append(refactor(self, operator, changed))
        return taken[-1]

    monkeypatch.setattr(substructuring.ChainSolver, "refactor", recorded)
    b, x = matrix.createVecs()
    start, _ = matrix.getOwnershipRange()

    def add_to_element(element, value, noted):
        """value I added to an element's 4 x 4 block (rows 2e to 2e + 3), by the rank
        that owns the element, noted as changed on every rank or not."""
        rows = 2 * element + np.arange(4)
        before = matrix.stateGet()
        if mesh.element_start <= element < mesh.element_end:
            matrix.setValuesRCV(rows[None, :].astype(PETSc.IntType),
                                rows[None, :].astype(PETSc.IntType),
                                value * np.eye(4)[None], addv=PETSc.InsertMode.ADD_VALUES)
        matrix.assemble()
        if noted:
            note_changed_rows(ksp, np.concatenate([rows, [start, start + 1]]), before)

    def solve_exactly():
        b.getArray()[:] = right_hand_sides(mesh, 1)[0]
        ksp.solve(b, x)
        assert_solves(comm, matrix, [b.getArray().copy()], [x.getArray().copy()])

    try:
        solve_exactly()
        element = mesh.element_start + 2            # an interior element on every rank
        add_to_element(element, 0.5, noted=True)
        solve_exactly()
        owned = [r for r in list(2 * element + np.arange(4)) + [start, start + 1]
                 if matrix.getOwnershipRange()[0] <= r < matrix.getOwnershipRange()[1]]
        assert read[-1] == sorted(set(owned))
        assert taken[-1]            # the noted rows' values taken, not a new solver
        add_to_element(element + 1, 0.25, noted=False)      # not noted: every row read
        solve_exactly()
        assert read[-1] is None
        add_to_element(element, 0.5, noted=False)           # not noted, then noted
        add_to_element(element + 1, 0.5, noted=True)
        solve_exactly()
        assert read[-1] is None
        add_to_element(element, 0.5, noted=True)            # noted, then not noted
        add_to_element(element + 1, 0.5, noted=False)
        solve_exactly()
        assert read[-1] is None
    finally:
        for obj in (ksp, b, x, matrix, mesh):
            obj.destroy()


def test_a_change_beside_a_rank_boundary_refactors_the_next_rank_s_interface():
    """The riser's vertical problem (global_step/hermite.py): a spring changed on the last
    element of a rank adds into the next rank's first vertex (z, z'), its interface
    rows, though none of that rank's elements changed. HermiteProblem.set_added notes
    those rows on every rank, so the refactorisation that reads only noted rows
    (ksp.note_changed_rows) reads them there; the solve then equals a new problem's
    with the same springs, to round-off. On one rank the element is the middle one."""
    from petsc_rod.global_step.hermite import HermiteProblem
    from petsc_rod.scenes.scene import EndState
    comm = PETSc.COMM_WORLD
    n_elements = 24
    mesh = Mesh(comm, n_elements, 2.0)
    starts = comm.tompi4py().allgather(mesh.element_start)
    changed_element = starts[1] - 1 if comm.getSize() > 1 else n_elements // 2
    slope_matrices = p2_element_matrices(mesh.element_h, 2.0, 50.0)
    ends = [EndState("pin", np.array(p, dtype=float), np.eye(3), np.zeros(3))
            for p in ((0.0, 0.0, 0.0), (2.0, 0.0, 0.5))]
    owned = np.arange(mesh.element_start, mesh.element_end)

    def springs(stiffer):
        """k I on each element's (z, z') of both vertices, k larger on one element."""
        k = 10.0 + 40.0 * (owned == changed_element) * stiffer
        return k[:, None, None] * np.eye(4), 0.1 * k[:, None] * np.ones(4)

    def hermite_solution(problem):
        slope_rhs = mesh.da.createGlobalVec()
        slope = slope_rhs.duplicate()
        vertices = np.arange(2 * mesh.vertex_start, 2 * mesh.vertex_end)
        slope_rhs.getArray()[:] = np.sin(0.3 * vertices)
        y = problem.solve(slope_rhs, slope).getArray().copy()
        for vec in (slope_rhs, slope):
            vec.destroy()
        return y

    updated = HermiteProblem(mesh, slope_matrices, "test_boundary_")
    fresh = HermiteProblem(mesh, slope_matrices, "test_boundary_fresh_")
    with destroyed_after(updated, fresh, mesh):
        for problem in (updated, fresh):
            problem.set_end_states(*ends)
        updated.set_added(*springs(False))
        hermite_solution(updated)                   # factored with the first springs
        updated.set_added(*springs(True))           # refactored from the noted rows
        fresh.set_added(*springs(True))
        y, reference = hermite_solution(updated), hermite_solution(fresh)
        scale = global_max(comm, np.abs(reference).max())
        assert global_max(comm, np.abs(y - reference).max()) <= ROUND_OFF * scale
        if comm.getSize() > 1 and comm.getRank() == 1:
            assert mesh.element_start == changed_element + 1      # none of its own


def test_a_problem_sharing_another_s_matrix_solves_with_its_factor():
    """The friction's y problem shares x's matrix and PC (HermiteProblem(matrix_of=...)):
    after both take the same springs and their own right-hand sides, y's solve is
    bitwise that of a problem with its own matrix, and the matrix is factored once for
    both (one PC set-up, x's PC the one y's KSP solves with)."""
    from petsc_rod.global_step.hermite import HermiteProblem
    from petsc_rod.scenes.scene import EndState
    comm = PETSc.COMM_WORLD
    mesh = Mesh(comm, 24, 2.0)
    slope_matrices = p2_element_matrices(mesh.element_h, 2.0, 50.0)
    ends = [EndState("pin", np.array(p, dtype=float), np.eye(3), np.zeros(3))
            for p in ((0.0, 0.3, 0.0), (2.0, -0.2, 0.5))]
    owned = np.arange(mesh.element_start, mesh.element_end)
    k = 10.0 + owned % 5
    matrices = k[:, None, None] * np.eye(4)
    x_vectors, y_vectors = 0.1 * k[:, None] * np.ones(4), -0.2 * k[:, None] * np.ones(4)
    slope_rhs = mesh.da.createGlobalVec()
    slope = slope_rhs.duplicate()
    vertices = np.arange(2 * mesh.vertex_start, 2 * mesh.vertex_end)
    slope_rhs.getArray()[:] = np.cos(0.3 * vertices)
    x = HermiteProblem(mesh, slope_matrices, "test_share_x_", 0)
    y = HermiteProblem(mesh, slope_matrices, "test_share_y_", 1, matrix_of=x)
    alone = HermiteProblem(mesh, slope_matrices, "test_share_alone_", 1)
    with destroyed_after(alone, y, x, mesh, slope_rhs, slope):
        for problem, vectors in ((x, x_vectors), (y, y_vectors), (alone, y_vectors)):
            problem.set_end_states(*ends)
            problem.set_added(matrices, vectors)
        assert y.ksp.getPC().handle == x.ksp.getPC().handle
        PETSc.Log.begin()
        set_ups = PETSc.Log.Event("PCSetUp")
        x.solve(slope_rhs, slope)
        count = set_ups.getPerfInfo()["count"]
        shared = y.solve(slope_rhs, slope).getArray().copy()
        assert set_ups.getPerfInfo()["count"] == count      # y's solve set nothing up
        alone.solve(slope_rhs, slope)
        assert set_ups.getPerfInfo()["count"] == count + 1  # a problem on its own does
        assert np.array_equal(shared, alone.solution.getArray())
        assert not np.array_equal(shared, x.solution.getArray())
