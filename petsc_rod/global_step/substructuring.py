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
are formed once per matrix (set-up: two local solves and one Allgather of a few numbers
a rank), and S is factored on every rank (PETSc's sequential Cholesky, like the interior
blocks). A matrix whose values change on the same pattern (the riser's vertical problem
at each change of the seabed's active set) is refactored numerically
(``ChainSolver.refactor``): the symbolic factorisation of the interior blocks is kept,
and where the caller noted which rows changed (``InterfacePC.note_changed_rows``: the
vertical problem, a few elements beside the touchdown) only those rows are read (not
every row by MatGetRow) and only their entries copied into the interior block
(docs/performance.md has the costs). A solve
is then one local half-chain Cholesky solve per right-hand side, an allgather of 2 k
numbers per rank (k right-hand sides),
the small tridiagonal solve, and x_I -= W x_G: it does the work of the serial Cholesky
divided by the ranks, where CG with block Jacobi needs several matrix products, local
solves and reductions per right-hand side (docs/performance.md).

``ChainSolver`` does the algebra on numpy views of the local rows; ``InterfacePC`` is
the same solve as a PETSc python preconditioner (``-rod_d1_pc_type python
-rod_d1_pc_python_type petsc_rod.global_step.substructuring.InterfacePC``), exact, so
that KSP preonly with it is a direct solver. The PETSc objects (the interior matrix, its
factor, two work vectors, the same for S: SeqCholesky) are ChainSolver's: made in
__init__ (the interior's anew by refactor where its pattern grows) and destroyed in
ChainSolver.destroy().
"""

import numpy as np
from petsc4py import PETSc

PYTHON_TYPE = "petsc_rod.global_step.substructuring.InterfacePC"


class SeqCholesky:
    """A sequential sparse SPD matrix given in CSR (indptr, indices, values) with its
    PETSc Cholesky factor in the natural order (a band matrix: no fill), solve(b, x) on
    numpy arrays without copies (the arrays are placed in two Vecs), and refactor(values)
    for new values on the same pattern. The matrix uses this object's CSR arrays as its
    own (MatCreateSeqAIJWithArrays), so that new values are a copy into them, not a
    MatSetValues per row."""

    def __init__(self, n, indptr, indices, values):
        self._csr = (np.array(indptr, dtype=PETSc.IntType),
                     np.array(indices, dtype=PETSc.IntType),
                     np.array(values, dtype=PETSc.ScalarType))
        self.matrix = PETSc.Mat().createAIJWithArrays((n, n), self._csr,
                                                      comm=PETSc.COMM_SELF)
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

    def refactor(self, values, positions=slice(None)):
        """The numeric factorisation of the matrix with ``values`` in place of its own at
        the CSR ``positions`` (indices into its values; all of them by default), on the
        same CSR pattern (the symbolic one kept): the values copied into the matrix's own
        array, and its state raised (an assembly) so that the PC factors again."""
        self._csr[2][positions] = values
        self.matrix.assemble()
        self._pc.setUp()

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


def csr_positions(firsts, lengths):
    """The positions firsts[i], ..., firsts[i] + lengths[i] - 1 of some rows' entries
    in a CSR array, row after row, as one int64 array (sum(lengths),): np.repeat of each
    row's offset from its place in the result plus a running count, not one arange a
    row."""
    lengths = np.asarray(lengths, dtype=np.int64)
    offsets = np.asarray(firsts, dtype=np.int64) - (np.cumsum(lengths) - lengths)
    return np.repeat(offsets, lengths) + np.arange(lengths.sum())


def row_reduce(ufunc, indptr, values, empty):
    """``ufunc`` (np.minimum, np.maximum) over each row's entries ``values`` (nnz,) of a
    CSR pattern with row pointers ``indptr`` (n + 1,), as an (n,) int64 array; ``empty``
    where a row has none. One pass over the entries in C (reduceat), where the checks
    and envelopes that follow look at n rows, not at every entry."""
    n = len(indptr) - 1
    reduced = np.full(n, empty, dtype=np.int64)
    filled = np.flatnonzero(np.diff(indptr) > 0)
    if filled.size:
        reduced[filled] = ufunc.reduceat(values, indptr[:-1][filled])
    return reduced


class NotAChainError(ValueError):
    """The matrix couples an interior row to a row of another rank other than the next
    rank's first row: the substructuring of this module does not apply."""


# Interface widths tried, in order: 1 for the P2 chains of the global step (a vertex
# value separates), 2 for a Hermite matrix in the same DMDA layout (the riser's vertical
# problem: a vertex's value and slope).
WIDTHS = (1, 2)


class ChainSolver:
    """Exact solve with an assembled, symmetric positive definite AIJ ``matrix``
    distributed by contiguous rows, coupled across ranks as a chain (module docstring):
    the interface of a rank but the first is its first w rows, w the first of WIDTHS
    that splits the matrix (the same on every rank); A_GI is taken as A_IG^T.

    Shapes (local): n = owned rows, n_I = n - offset interior rows (offset = w on every
    rank but the first), W stored transposed (2w, n_I): rows for the w own interface
    rows, then the next rank's w; the interface system ((P-1) w, (P-1) w), banded.
    """

    def __init__(self, matrix):
        comm = matrix.getComm()
        self._mpi = comm.tompi4py()
        self.size, self.rank = comm.getSize(), comm.getRank()
        start, end = matrix.getOwnershipRange()
        self.last = self.rank == self.size - 1
        rows, cols, values = matrix.getValuesCSR()
        row_of = np.repeat(np.arange(start, end), np.diff(rows))
        self._outside = {}
        for width in WIDTHS:
            why = self._split(row_of, cols, values, start, end, width)
            refused = [text for text in self._mpi.allgather(why) if text is not None]
            if not refused:     # decided on every rank: the others would wait otherwise
                break
        else:
            raise NotAChainError(refused[0])
        self.width = width
        first = start + self.offset
        n_interior = end - first
        self._inside = (row_of >= first) & (cols >= first) & (cols < end)
        self._keep = self._envelope(rows, row_of, cols, values, start, end)
        self.interior = self._interior_block(row_of, cols, values, first, n_interior)
        self.W = np.zeros((2 * width, n_interior))     # rows: columns of W, contiguous
        self._work = np.zeros(n_interior)
        self.schur = None
        self._pattern = (rows, cols, row_of)        # the local rows' (refactor)
        self._values = values                       # their values, of the last factorisation
        self._couple_and_reduce(values, start, end)

    def _envelope(self, indptr, row_of, cols, values, start, end):
        """Which entries of the local rows make the interior block A_II: its nonzero
        ones, its diagonal, and its zeros within the envelope of the nonzero ones (entry
        (i, j) with min(i, j) at or right of the first nonzero column of row max(i, j)).
        A banded factor in the natural order lies within that envelope, so the zeros
        there widen nothing; kept, they keep the pattern when one becomes nonzero
        (refactor): the coupling of a vertex's value and slope in the riser's vertical
        problem cancels on a uniform mesh until the seabed's spring acts at the vertex.
        Zeros outside the envelope are left out: the P2 chains' DMDA stencil couples a
        midpoint to the next midpoint with zeros, which would widen the band."""
        nonzero = self._inside & ((values != 0.0) | (cols == row_of))
        # each row's first nonzero column (end where it has none)
        first_column = row_reduce(np.minimum, indptr, np.where(nonzero, cols, end), end)
        later = np.maximum(row_of, cols)
        within = np.zeros_like(nonzero)
        within[self._inside] = (np.minimum(row_of, cols)[self._inside]
                                >= first_column[later[self._inside] - start])
        return nonzero | within

    def _interior_block(self, row_of, cols, values, first, n_interior):
        """A_II, the entries self._keep of the local rows, factored; self._position: where
        each local entry kept lies among A_II's values (refactor)."""
        self._position = np.cumsum(self._keep) - 1
        counts = np.bincount(row_of[self._keep] - first, minlength=n_interior)
        indptr = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
        return SeqCholesky(n_interior, indptr, cols[self._keep] - first, values[self._keep])

    def _couple_and_reduce(self, values, start, end):
        """W from the interior factor and the couplings, and S factored (_factor_interface)."""
        self.W[:] = 0.0
        for column, (index, value) in enumerate(self._coupling):
            if index.size:
                b = np.zeros(self.W.shape[1])
                b[index] = value
                self.interior.solve(b, self.W[column])
        self._factor_interface(values, start, end)

    def refactor(self, matrix, changed=None):
        """Take the values of ``matrix`` where its local rows have the pattern of the
        one this solver was made from and it is still a chain split at the same
        interface: the interior block refactored numerically (its symbolic
        factorisation kept; an entry that became zero stays as a zero), W and S made
        anew. Where an interior entry left out as a zero (_envelope) is not, the
        interior block's pattern grows by it and is factored anew, symbolic phase
        included; it keeps the entry from then on. ``changed``: the only owned rows
        (global indices) whose values differ from the last factorisation's, read alone
        (InterfacePC.note_changed_rows), else every row is read (MatGetRow row by row:
        most of the cost of a refactorisation of the seabed's vertical problem). Returns
        whether it took the values (on every rank; if not, the solver is as it was, and
        ``matrix`` needs a new ChainSolver). Collective."""
        start, end = matrix.getOwnershipRange()
        old_rows, old_cols, row_of = self._pattern
        cols = old_cols
        if changed is None:
            rows, cols, values = matrix.getValuesCSR()
            fits = np.array_equal(rows, old_rows) and np.array_equal(cols, old_cols)
            entries = np.arange(len(values))
        else:
            values, fits, entries = self._read_rows(matrix, changed, start)
        coupling = self._coupling
        if fits:
            fits = self._split(row_of, cols, values, start, end, self.width) is None
        if not all(self._mpi.allgather(fits)):
            self._coupling = coupling                   # as it was
            return False
        grown = entries[(values[entries] != 0.0) & self._inside[entries] & ~self._keep[entries]]
        if grown.size:
            self._keep[grown] = True
            self.interior.destroy()
            first = start + self.offset
            self.interior = self._interior_block(row_of, cols, values, first, end - first)
        else:
            kept = entries[self._keep[entries]]
            self.interior.refactor(values[kept], self._position[kept])
        self._values = values
        self._couple_and_reduce(values, start, end)
        return True

    def _read_rows(self, matrix, changed, start):
        """(values, fits, entries): the last factorisation's values with those of the
        ``changed`` rows (global indices, owned) read from ``matrix`` (MatGetRow each) at
        their ``entries`` (positions in the local CSR), and whether those rows still have
        the pattern's columns (else the values are not to be used). One comparison and
        one copy for all the rows, not one a row (a change of the seabed's active set
        notes about 20 rows)."""
        indptr, cols = self._pattern[:2]
        local = np.asarray(changed, dtype=np.int64) - start
        firsts, lengths = indptr[local], indptr[local + 1] - indptr[local]
        read = [matrix.getRow(int(row)) for row in changed]
        entries = csr_positions(firsts, lengths)
        values = self._values.copy()
        if not read:
            return values, True, entries
        fits = (np.array_equal([len(row_cols) for row_cols, _ in read], lengths)
                and np.array_equal(np.concatenate([c for c, _ in read]), cols[entries]))
        if fits:
            values[entries] = np.concatenate([v for _, v in read])
        return values, fits, entries

    def _split(self, row_of, cols, values, start, end, width):
        """With the interface ``width`` rows wide: None if it splits the matrix (and the
        interior rows' couplings A_IG as 2w sparse columns in self._coupling), else why
        not."""
        self.offset = width if self.rank > 0 else 0
        first = start + self.offset
        if end - first <= 0:
            return f"rows {start} to {end - 1}: no interior row with an interface of {width}"
        # the interior rows' entries outside the interior block (the pattern's, found
        # once per width: a refactorisation reads only these)
        if width not in self._outside:
            self._outside[width] = np.flatnonzero((row_of >= first)
                                                  & ((cols < first) | (cols >= end)))
        outside = self._outside[width]
        outside_rows, outside_cols = row_of[outside], cols[outside]
        outside_values = values[outside]
        nonzero = outside_values != 0.0
        own = [start + k if self.offset else -1 for k in range(width)]
        following = [end + k if not self.last else -1 for k in range(width)]
        masks = [nonzero & (outside_cols == col) for col in own + following]
        stray = nonzero & ~np.any(masks, axis=0)
        if stray.any():
            return (f"row {outside_rows[stray][0]} couples to row {outside_cols[stray][0]} "
                    "of another rank: not a chain split at the ranks' first rows")
        self._coupling = [(outside_rows[mask] - first, outside_values[mask]) for mask in masks]
        return None

    def _factor_interface(self, values, start, end):
        """S = A_GG - A_GI W, block tridiagonal with w x w blocks (interface numbering:
        (q - 1) w + k for row k of rank q's interface): every rank sends its part of S on
        its two neighbouring interfaces, own then next (_interface_part), in one
        Allgather of (2w, 2w) numbers; every rank sums them in the same order into S's
        fixed pattern (_schur_pattern) and factors it (refactored after the first)."""
        n = (self.size - 1) * self.width
        if not n:
            return
        parts = np.empty((self.size,) + (2 * self.width,) * 2)
        self._mpi.Allgather(self._interface_part(values, start, end), parts)
        if self.schur is None:
            self._schur_pattern()
        indptr, columns, positions, taken = self._schur
        summed = np.bincount(positions, weights=parts[taken], minlength=len(columns))
        if self.schur is None:
            self.schur = SeqCholesky(n, indptr, columns, summed)
            self._interface = np.zeros(n)
        else:
            self.schur.refactor(summed)

    def _interface_part(self, values, start, end):
        """This rank's part of S, (2w, 2w) on its own interface's w rows (none on the
        first rank) then the next rank's (none on the last): its own interface rows'
        entries of A_GG, on the own interface and the next one (with the symmetric
        entry), and -A_GI W on both."""
        w = self.width
        part = np.zeros((2 * w, 2 * w))
        if self.offset:
            indptr, cols = self._pattern[:2]
            for k in range(w):                          # the own interface's rows
                row = slice(indptr[k], indptr[k + 1])
                row_cols, row_values = cols[row], values[row]
                own = (row_cols >= start) & (row_cols < start + w)
                part[k, row_cols[own] - start] += row_values[own]
                if not self.last:
                    following = (row_cols >= end) & (row_cols < end + w)
                    part[k, w + row_cols[following] - end] += row_values[following]
                    part[w + row_cols[following] - end, k] += row_values[following]
        for a, (index, value) in enumerate(self._coupling):
            if index.size:                  # W's row is zero where its coupling is empty
                part[a] -= self.W[:, index] @ value
        return part

    def _schur_pattern(self):
        """S's CSR pattern, block tridiagonal: row r of interface block q = r // w holds
        the columns of blocks q - 1 to q + 1 (those that exist), every entry stored; and
        where rank p's part (_interface_part) adds into its values: self._schur =
        (indptr, columns, positions, taken), ``taken`` the entries of the parts
        (P, 2w, 2w) that exist (the own interface on ranks after the first, the next one
        on ranks before the last) and ``positions`` their places among S's values."""
        w, P = self.width, self.size
        n = (P - 1) * w
        block = np.arange(n) // w
        first = np.maximum(block - 1, 0) * w
        indptr = np.r_[0, np.cumsum(np.minimum(block + 2, P - 1) * w - first)]
        row_of_entry = np.repeat(np.arange(n), np.diff(indptr))
        columns = first[row_of_entry] + np.arange(indptr[-1]) - indptr[row_of_entry]
        rank = np.arange(P)[:, None]
        slot = np.arange(2 * w)[None, :]
        index = np.where(slot < w, (rank - 1) * w + slot, rank * w + slot - w)   # (P, 2w)
        exists = np.where(slot < w, rank > 0, rank < P - 1)
        taken = exists[:, :, None] & exists[:, None, :]                      # (P, 2w, 2w)
        rows = np.broadcast_to(index[:, :, None], taken.shape)[taken]
        cols = np.broadcast_to(index[:, None, :], taken.shape)[taken]
        self._schur = (indptr, columns, indptr[rows] + cols - first[rows], taken)

    def solve(self, rhs, solution):
        """solution = A^-1 rhs for k right-hand sides: lists of k local arrays (n,) of
        owned rows (rhs is read only), one allgather of 2 w k numbers per rank."""
        k, w, off = len(rhs), self.width, self.offset
        sent = np.zeros((2 * w, k))
        for c, (b, x) in enumerate(zip(rhs, solution)):
            interior = x[off:]
            self.interior.solve(b[off:], interior)
            for a, (index, value) in enumerate(self._coupling):
                if index.size:
                    sent[a, c] = -(value @ interior[index])
            sent[:off, c] += b[:off]
        if self.size == 1:
            return
        parts = np.empty((self.size, 2 * w, k))
        self._mpi.Allgather(sent, parts)
        rhs_interface = (parts[1:, :w] + parts[:-1, w:]).reshape(-1, k)   # ((P-1) w, k)
        values = np.zeros((2 * w, k))       # x_G on the own and the next interface
        lo = (self.rank - 1) * w
        for c in range(k):
            self.schur.solve(np.ascontiguousarray(rhs_interface[:, c]), self._interface)
            if off:
                values[:w, c] = self._interface[lo:lo + w]
            if not self.last:
                values[w:, c] = self._interface[lo + w:lo + 2 * w]
        work = self._work
        for c, x in enumerate(solution):
            interior = x[off:]
            for a, (index, _) in enumerate(self._coupling):
                if index.size:                  # W's column is zero otherwise
                    interior -= np.multiply(self.W[a], values[a, c], out=work)
            x[:off] = values[:off, c]

    def destroy(self):
        for obj in (self.interior, self.schur):
            if obj is not None:
                obj.destroy()


class InterfacePC:
    """ChainSolver as the context of a PETSc python PC: apply(pc, b, x) is x = A^-1 b,
    exact (KSP preonly with it is a direct solver). The operator is the PC's Pmat."""

    def __init__(self):
        self.solver = None
        self._state = None          # (Pmat, its object state) at the last set-up
        self._changes = None        # (Pmat, state, owned rows) noted since (note_changed_rows)

    def note_changed_rows(self, pmat, rows, before):
        """The caller changed only the values of ``rows`` (global indices; the owned
        ones are kept) of the Pmat, from its object state ``before`` to its state now:
        the next set-up reads only those rows (ChainSolver.refactor). Notes follow one
        another from the last set-up's state; where the state moved otherwise (a change
        not noted) the next set-up reads every row."""
        start, end = pmat.getOwnershipRange()
        rows = np.asarray(rows, dtype=np.int64)
        rows = rows[(rows >= start) & (rows < end)]
        if (self._changes is not None and self._changes[0] == pmat.handle
                and self._changes[1] == before):
            rows = np.union1d(self._changes[2], rows)
        elif (pmat.handle, before) != self._state:
            self._changes = None
            return
        self._changes = (pmat.handle, pmat.stateGet(), np.unique(rows))

    def setUp(self, pc):
        """The solver of the PC's Pmat: the last one refactored where the pattern is
        the same (ChainSolver.refactor; only the rows noted as changed where every
        change since the last set-up was noted), else a new one."""
        _, pmat = pc.getOperators()
        state = pmat.stateGet()
        changed = (self._changes[2] if self._changes is not None
                   and self._changes[:2] == (pmat.handle, state) else None)
        if changed is not None and 2 * len(changed) > pmat.getLocalSize()[0]:
            # most rows (friction's springs on a grounded stretch): one read of them all
            # (MatGetRow in C) is cheaper than a MatGetRow call a row from Python
            changed = None
        self._changes = None
        self._state = (pmat.handle, state)
        if self.solver is not None and self.solver.refactor(pmat, changed):
            return
        self.destroy(pc)
        self.solver = ChainSolver(pmat)

    def apply(self, pc, b, x):
        self.solver.solve([b.getArray(readonly=True)], [x.getArray()])

    def destroy(self, pc):
        if self.solver is not None and not PETSc.Sys.isFinalized():
            self.solver.destroy()
            self.solver = None
