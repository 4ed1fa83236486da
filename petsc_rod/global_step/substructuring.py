"""Exact parallel solve of the global step's chain matrices by substructuring.

The matrices of the global step (matrices.ScalarProblem) are P2 chains on a 1-D DMDA:
row i couples only to rows within two of it, and every rank owns a contiguous range of
rows [start_p, end_p). Take as the interface G the first row g_p = start_p of every rank
but the first (a vertex dof: the P2 elements on either side meet there). Removing G
splits the chain into independent interior blocks I_p = [start_p + (p > 0), end_p), one
per rank, and I_p is coupled to the interface only through g_p and g_{p+1}. With the
interior rows ordered first, A = [A_II A_IG; A_GI A_GG] and

    A_II y = b_I                       (each rank its own block, a local Cholesky solve)
    S x_G = b_G - A_GI y,   S = A_GG - A_GI W,   W = A_II^-1 A_IG
    x_I = y - W x_G.

W has two columns per rank (g_p, g_{p+1}) and S is (P-1) x (P-1) and tridiagonal; both
are formed once per matrix (set-up: two local solves and one allgather), and S is
factored on every rank (PETSc's sequential Cholesky, like the interior blocks). A solve
is then one local half-chain Cholesky solve per right-hand side, an allgather of 2 k
numbers per rank (k right-hand sides),
the small tridiagonal solve, and x_I -= W x_G: it does the work of the serial Cholesky
divided by the ranks, where CG with block Jacobi needs several matrix products, local
solves and reductions per right-hand side (docs/performance.md).

``ChainSolver`` does the algebra on numpy views of the local rows; ``InterfacePC`` is
the same solve as a PETSc python preconditioner (``-rod_d1_pc_type python
-rod_d1_pc_python_type petsc_rod.global_step.substructuring.InterfacePC``), exact, so
that KSP preonly with it is a direct solver. The PETSc objects (the interior matrix, its factor,
two work vectors, the same for S: SeqCholesky) are created in ChainSolver.__init__ and
destroyed in ChainSolver.destroy().
"""

import numpy as np
from petsc4py import PETSc

PYTHON_TYPE = "petsc_rod.global_step.substructuring.InterfacePC"


class SeqCholesky:
    """A sequential sparse SPD matrix given in CSR (indptr, indices, values) with its
    PETSc Cholesky factor in the natural order (a band matrix: no fill), and
    solve(b, x) on numpy arrays without copies (the arrays are placed in two Vecs)."""

    def __init__(self, n, indptr, indices, values):
        self.matrix = PETSc.Mat().createAIJ(
            (n, n), comm=PETSc.COMM_SELF,
            csr=(np.asarray(indptr, dtype=PETSc.IntType),
                 np.asarray(indices, dtype=PETSc.IntType), np.asarray(values, dtype=float)))
        self.matrix.assemble()
        self.matrix.setOption(PETSc.Mat.Option.SPD, True)
        self._pc = PETSc.PC().create(comm=PETSc.COMM_SELF)
        self._pc.setOperators(self.matrix)
        self._pc.setType(PETSc.PC.Type.CHOLESKY)
        self._pc.setFactorOrdering(PETSc.Mat.OrderingType.NATURAL)
        self._pc.setUp()
        self.factor = self._pc.getFactorMatrix()
        self._b = PETSc.Vec().createSeq(n, comm=PETSc.COMM_SELF)
        self._x = self._b.duplicate()

    def solve(self, b, x):
        """x = A^-1 b, contiguous float arrays (n,)."""
        self._b.placeArray(b)
        self._x.placeArray(x)
        try:
            self.factor.solve(self._b, self._x)
        finally:
            self._b.resetArray()
            self._x.resetArray()

    def destroy(self):
        for obj in (self._pc, self.matrix, self._b, self._x):
            obj.destroy()


class NotAChainError(ValueError):
    """The matrix couples an interior row to a row of another rank other than the next
    rank's first row: the substructuring of this module does not apply."""


class ChainSolver:
    """Exact solve with an assembled, symmetric positive definite AIJ ``matrix``
    distributed by contiguous rows, coupled across ranks as a chain (module docstring);
    A_GI is taken as A_IG^T (the symmetry), every rank must own two rows or more.

    Shapes (local): n = owned rows, n_I = n - offset interior rows (offset = 1 on every
    rank but the first), W stored transposed (2, n_I), the interface system (P-1, P-1).
    """

    def __init__(self, matrix):
        comm = matrix.getComm()
        self._mpi = comm.tompi4py()
        self.size, rank = comm.getSize(), comm.getRank()
        start, end = matrix.getOwnershipRange()
        self.offset = 1 if rank > 0 else 0
        self.last = rank == self.size - 1
        first = start + self.offset
        n_interior = end - first
        rows, cols, values = matrix.getValuesCSR()
        row_of = np.repeat(np.arange(start, end), np.diff(rows))
        nonzero = values != 0.0
        interior_row = row_of >= first
        inside = (cols >= first) & (cols < end)
        # couplings of the interior rows: to I_p, to g_p (= start), to g_{p+1} (= end)
        left = interior_row & nonzero & (cols == start) & (self.offset == 1)
        right = interior_row & nonzero & (cols == end) & (not self.last)
        stray = interior_row & nonzero & ~inside & ~left & ~right
        why = None
        if stray.any():
            why = (f"row {row_of[stray][0]} couples to row {cols[stray][0]} of another "
                   "rank: not a chain split at the ranks' first rows")
        elif n_interior <= 0:
            why = f"rows {start} to {end - 1}: a rank with no interior row"
        refused = [text for text in self._mpi.allgather(why) if text is not None]
        if refused:             # on every rank: the others would wait in the allgather
            raise NotAChainError(refused[0])
        keep = interior_row & inside & (nonzero | (cols == row_of))
        counts = np.bincount(row_of[keep] - first, minlength=n_interior)
        indptr = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
        self.interior = SeqCholesky(n_interior, indptr, cols[keep] - first, values[keep])
        # A_IG as two sparse columns (interior indices, values); W = A_II^-1 A_IG
        self._coupling = [(row_of[mask] - first, values[mask]) for mask in (left, right)]
        self.W = np.zeros((2, n_interior))     # rows: columns of W, contiguous
        self._work = np.zeros(n_interior)
        for column, (index, value) in enumerate(self._coupling):
            if index.size:
                b = np.zeros(n_interior)
                b[index] = value
                self.interior.solve(b, self.W[column])
        self._factor_interface(row_of, cols, values, start, end)

    def _factor_interface(self, row_of, cols, values, start, end):
        """S = A_GG - A_GI W, tridiagonal: each rank sends (A_{g_p g_p}, A_{g_p g_p+1},
        and its 2x2 A_GI W on (g_p, g_p+1)); every rank assembles and factors S."""
        local = np.zeros(5)
        if self.offset:
            own = row_of == start
            local[0] = values[own & (cols == start)].sum()
            local[1] = values[own & (cols == end)].sum() if not self.last else 0.0
        for column, (index, value) in enumerate(self._coupling):
            for other in range(2):
                if index.size:
                    local[2 + column + other] += value @ self.W[other, index]
        parts = np.empty((self.size, 5))
        self._mpi.Allgather(local, parts)
        # local[2:]: (L.W_L, L.W_R + R.W_L, R.W_R) summed as 2 + column + other
        n = self.size - 1
        self.diagonal = parts[1:, 0] - parts[1:, 2] - parts[:-1, 4]
        self.off_diagonal = parts[1:-1, 1] - 0.5 * parts[1:-1, 3]
        self.schur = None
        if n:
            rows = np.arange(n)
            indices = np.stack([rows - 1, rows, rows + 1], axis=1)
            entries = np.stack([np.r_[0.0, self.off_diagonal], self.diagonal,
                                np.r_[self.off_diagonal, 0.0]], axis=1)
            inside = (indices >= 0) & (indices < n)
            self.schur = SeqCholesky(n, np.r_[0, np.cumsum(inside.sum(axis=1))],
                                     indices[inside], entries[inside])
            self._interface = np.zeros(n)

    def solve(self, rhs, solution):
        """solution = A^-1 rhs for k right-hand sides: lists of k local arrays (n,) of
        owned rows (rhs is read only), one allgather of 2k numbers per rank."""
        k = len(rhs)
        off = self.offset
        sent = np.zeros((2, k))
        for c, (b, x) in enumerate(zip(rhs, solution)):
            self.interior.solve(b[off:], x[off:])
            (left_index, left_value), (right_index, right_value) = self._coupling
            if off:
                sent[0, c] = b[0] - left_value @ x[off:][left_index]
            if right_index.size:
                sent[1, c] = -(right_value @ x[off:][right_index])
        if self.size == 1:
            return
        parts = np.empty((self.size, 2, k))
        self._mpi.Allgather(sent, parts)
        rhs_interface = parts[1:, 0] + parts[:-1, 1]          # (P-1, k)
        rank = self._mpi.Get_rank()
        own, following = np.zeros(k), np.zeros(k)
        for c in range(k):
            self.schur.solve(np.ascontiguousarray(rhs_interface[:, c]), self._interface)
            own[c] = self._interface[rank - 1] if off else 0.0
            following[c] = self._interface[rank] if not self.last else 0.0
        work = self._work
        for c, x in enumerate(solution):
            interior = x[off:]
            for column, value in ((0, own[c]), (1, following[c])):
                if self._coupling[column][0].size:      # W's column is zero otherwise
                    interior -= np.multiply(self.W[column], value, out=work)
            if off:
                x[0] = own[c]

    def destroy(self):
        for obj in (self.interior, self.schur):
            if obj is not None:
                obj.destroy()


class InterfacePC:
    """ChainSolver as the context of a PETSc python PC: apply(pc, b, x) is x = A^-1 b,
    exact (KSP preonly with it is a direct solver). The operator is the PC's Pmat."""

    def __init__(self):
        self.solver = None

    def setUp(self, pc):
        self.destroy(pc)
        _, pmat = pc.getOperators()
        self.solver = ChainSolver(pmat)

    def apply(self, pc, b, x):
        self.solver.solve([b.getArray(readonly=True)], [x.getArray()])

    def destroy(self, pc):
        if self.solver is not None and not PETSc.Sys.isFinalized():
            self.solver.destroy()
            self.solver = None
