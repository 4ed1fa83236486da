"""Direct factorisations of the Newton steps' systems on several ranks, by
substructuring (docs/performance.md, "Newton steps"; docs/options.md).

The Newton Jacobian J (analysis/jacobian.py) and the second variation H
(analysis/second_variation.py) are chains of nodes: B unknowns a node, the nodes of a rank in
contiguous rows, every rank's rows starting at a vertex, a node's rows coupled only to
the nodes of its elements. MUMPS on several ranks factors such a chain no faster than
on one (its elimination tree is a path) and solves it slower. As the global step's
substructuring.py does for its scalar chains, the first node of every rank but the
first is the interface (G_p, B rows, on rank p) and the rest of a rank's rows its
interior I_p, which couples to G_p and G_p+1 only:

    A_II y = b_I                      (each rank its own interior, sequentially)
    S x_G = b_G - A_GI y,   S = A_GG - A_GI W,   W = A_II^-1 A_IG,
    x_I = y - W x_G.

The interiors are factored as the whole is on one rank: an LU by PETSc's own in the
natural order (ksp.NaturalLU: checked, MUMPS's where the check fails; -rod_newton_lu
mumps for MUMPS's throughout), an LDL^T by MUMPS (its null pivots and inertia).

W has 2 B columns a rank (B where a rank has one neighbour) and is made at each
factorisation, with one solve of sparse right-hand sides (A_IG is nonzero on the
interior's first and last few rows only: MUMPS's forward elimination visits the paths
of its elimination tree from them to the root, near which the AMF ordering places the
first rows of the numbering, so the first rank, whose coupling is its interior's tail,
numbers a MUMPS LU's interior from its end, while an LDL^T, whose factorisation that
order slows by more than it saves in W, keeps the natural order and then factors the
rank's diagonal block itself, without extracting it; PETSc's LU solves them as dense
columns, in the natural order on every rank); S is ((P - 1) B) square, block
tridiagonal, assembled from every rank's contribution and inverted on every rank: dense,
equilibrated (R S C by Ruiz's iteration, every row and column's largest entry about
1; E S E of a symmetric S: its unknowns are turns, heights and resultants, whose
scales differ by 1e7 on the riser) and pseudo-inverted,
its null directions (a null pivot: the free roll) dropped. Of a symmetric matrix the
number of negative eigenvalues is the interiors' (their LDL^T's) plus S's
(Haynsworth's inertia additivity, which needs regular interiors: an interior with a
null pivot is refused, SingularInteriorError; E S E has S's inertia, Sylvester), what
the stability test and the Newton steps' positive-definiteness test count.

A solve is a local solve, an allgather of 2 B k numbers a rank (k right-hand sides), a
dense product with S^-1 and x_I -= W x_G: the work of the serial factorisation divided
by the ranks, plus the interface's on every rank (its inverse O(((P - 1) B)^3) a
factorisation, its product O(((P - 1) B)^2 k) a solve: small on a few ranks, not
scalable to many; the costs: docs/performance.md, "Newton steps"). The ChainFactor owns
its PETSc objects (the interior submatrix, on the first rank of an LDL^T a reference to the
diagonal block itself, and its sequential factorisation, the index set of the interior
rows where it is not the whole block): ``destroy()``.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.global_step.substructuring import NotAChainError, csr_positions, row_reduce

# The equilibrated interface's pseudo-inverse drops singular values (eigenvalues) below
# this fraction of the largest: a null pivot, the free roll of a section with K1 = K2
# between pins, dropped as MUMPS on all ranks drops it (docs/performance.md, "Newton
# steps").
NULL_PIVOT = 1e-13
# Ruiz sweeps of the Schur complement's equilibration: each halves the logarithm of a
# row's or column's largest entry, so 20 bring a range of 1e16 to within 4e-5 of 1.
RUIZ_SWEEPS = 20


class SingularInteriorError(NotAChainError):
    """A rank's interior block is singular (a null pivot of its LDL^T or LU): the
    substructuring does not apply to this matrix, whatever the whole's regularity."""


class ChainFactor:
    """The factorisation of the module docstring of an assembled MPIAIJ ``matrix`` (its
    pattern; the values are read at each ``set_up``) with ``block`` unknowns a node:
    ``kind`` PETSc.PC.Type.LU or CHOLESKY (then symmetric, with its inertia). The
    interiors' sequential factorisations are those ``make_interior(operator)`` gives
    (ksp.MumpsFactor, or of an LU ksp.NaturalLU, as on one rank), each with
    ``set_up(operator)``, ``null_pivot()``, ``failed()``, ``negative_pivots()`` (of an
    LDL^T), ``solve(right)`` ((n_I, k) Fortran-ordered columns; it returns a new,
    writeable (n_I, k) array, which the solves correct in place) and
    ``solve_sparse(rows, values)`` (W's: (k, n_I)) and ``destroy()``; ``reorder``
    False where they eliminate in the order given (NaturalLU). Raises
    NotAChainError where a rank's rows couple otherwise (on every rank): a rank without
    an interior node, a middle rank whose interface reaches the next one's (a single
    element).

    Stored: W (2 B, n_I) (its columns as rows: the own interface's B first where there
    is one, then the next's; along the interior in the factor's order, below), the own
    interface's rows A_G_p,I_p on the interior's first head_columns columns (B,
    head_columns), and the next interface's rows A_G_p+1,I_p on its last next_back (B,
    next_back); ``reversed``: the interior block's rows are the rank's interior rows
    from its last (the first rank's, of an LU). Arrays along the interior (W, the
    solves' columns) stay in that factor's order, reversed or not, from the gather of
    the right-hand sides to the scatter of the solutions; ``_natural`` reads a range of
    the natural order from them (the interface's couplings)."""

    def __init__(self, matrix, kind, block, make_interior, reorder=True):
        comm = matrix.getComm()
        self._mpi = comm.tompi4py()
        self.size, self.rank = comm.getSize(), comm.getRank()
        self.kind, self.block = kind, block
        self._make_interior = make_interior
        self.symmetric = kind == PETSc.PC.Type.CHOLESKY
        start, end = matrix.getOwnershipRange()
        self.n = end - start
        self.offset = block if self.rank > 0 else 0
        self.has_next = self.rank < self.size - 1
        self._split(matrix)
        # the first rank's interior of an LU numbered from its end (``reorder``: for
        # MUMPS's): its couplings, to the next interface, come first, near the root of
        # the elimination tree (W's solve); an LDL^T's factorisation takes longer in that
        # order than W's solve saves (docs/performance.md, "Newton steps"): the natural
        # order, in which the first rank's interior is its diagonal block, taken without
        # a copy. An elimination without pivoting (NaturalLU) keeps the natural order:
        # from the end it meets the zero diagonal of a chain's multiplier first
        self.reversed = (reorder and self.offset == 0 and self.has_next
                         and not self.symmetric)
        # the interior rows: None where they are the whole diagonal block (the first
        # rank's LDL^T; one rank, in tests only: direct_factor substructures on
        # several), whose interior is then the block itself, a reference taken at each
        # set_up (nothing here changes it in place); else a stride where the order is
        # the natural one (MatCreateSubMatrix copies contiguous columns row by row,
        # faster than for a general index set: docs/performance.md, "Newton steps"),
        # the reversed rows where it is not
        if self.reversed:
            interior = np.arange(self.n - 1, self.offset - 1, -1, dtype=PETSc.IntType)
            self._index = PETSc.IS().createGeneral(interior, comm=PETSc.COMM_SELF)
        elif self.offset:
            self._index = PETSc.IS().createStride(self.n - self.offset, self.offset, 1,
                                                  comm=PETSc.COMM_SELF)
        else:
            self._index = None
        self.interior = None
        self.solver = None
        self.failed = False
        self.negative = None

    def _split(self, matrix):
        """The reaches of the couplings (_reach) and the local pattern's size, checked on
        every rank; NotAChainError (on every rank) where they are no chain's."""
        start, end = matrix.getOwnershipRange()
        why = self._reach(matrix, start, end)
        refused = [text for text in self._mpi.allgather(why) if text is not None]
        if refused:
            raise NotAChainError(refused[0])
        # how far the next rank's interface rows reach back into this rank's rows (the
        # columns of A_G_p+1,I_p; of an unsymmetric matrix not those of A_I_p,G_p+1)
        backs = self._mpi.allgather(self.back)
        self.next_back = backs[self.rank + 1] if self.has_next else 0
        if not all(self._mpi.allgather(self.next_back <= self.n - self.offset)):
            raise NotAChainError("an interface's rows reach beyond the previous rank's "
                                 "interior")
        self._nonzeros = stored_entries(matrix)

    def _reach(self, matrix, start, end):
        """None where the local rows couple as a chain split at the ranks' first nodes,
        else why not; sets how far the couplings reach (in rows of this rank):
        ``head`` the interior rows coupled to the own interface's columns, ``head_columns``
        the interior columns the own interface's rows couple to, ``tail`` the interior
        rows coupled to the next interface's columns, ``back`` the previous rank's rows
        (counted back from its end) whose columns the own interface's rows couple to."""
        B, off = self.block, self.offset
        if self.n - off < B:
            return f"rows {start} to {end - 1}: no interior node on a rank"
        if self.n % B:
            return f"rows {start} to {end - 1}: not whole nodes of {B} unknowns"
        lowest, highest = _column_range(matrix, start, end, edge=3 * B)
        # an interior row reaches the own interface, the interior and the next rank's
        # interface: columns [start, end + B); the interface's rows reach back into the
        # previous rank and forward into the interior, not beyond it
        stray = lowest < start
        stray[off:] |= highest[off:] >= end + B
        stray[:off] = highest[:off] >= end
        if stray.any():
            i = int(np.flatnonzero(stray)[0])
            column = lowest[i] if i >= off and lowest[i] < start else highest[i]
            return (f"row {start + i} couples to row {column}: not a chain split "
                    "at the ranks' first nodes")
        interior_low, interior_high = lowest[off:], highest[off:]
        own = np.flatnonzero(interior_low < start + off)
        self.head = int(own[-1]) + 1 if own.size else 0
        following = np.flatnonzero(interior_high >= end)
        self.tail = self.n - off - int(following[0]) if following.size else 0
        interface_high, interface_low = highest[:off], lowest[:off]
        reached = interface_high[interface_high >= start + off]
        self.head_columns = int(reached.max()) + 1 - start - off if reached.size else 0
        backward = interface_low[interface_low < start]
        self.back = start - int(backward.min()) if backward.size else 0
        return None

    # --- the factorisation ------------------------------------------------------------
    def set_up(self, matrix):
        """Factor ``matrix`` (the pattern of the one this was made for, or grown; the
        interior's symbolic factorisation is kept while the pattern stays). Raises
        NotAChainError (on every rank) where the grown pattern is no chain's, and its
        SingularInteriorError where a rank's interior has a null pivot. Collective."""
        B, off = self.block, self.offset
        start, end = matrix.getOwnershipRange()
        if self._mpi.allreduce(int(stored_entries(matrix) != self._nonzeros)):
            # the pattern grew (a new nonzero): the reaches and the interior anew
            self._split(matrix)
            for obj in (self.solver, self.interior):
                if obj is not None:
                    obj.destroy()
            self.solver = self.interior = None
        diagonal = matrix.getDiagonalBlock()        # a reference of its own
        if self._index is None:
            if self.interior is not None:
                self.interior.destroy()
            self.interior = diagonal
        else:
            self.interior = diagonal.createSubMatrix(self._index, self._index,
                                                     submat=self.interior)
            diagonal.destroy()
        if self.solver is None:
            self.solver = self._make_interior(self.interior)
        self.solver.set_up(self.interior)
        # a null pivot of an interior (MUMPS detects it, ICNTL 24, and goes on) voids
        # W, S and the inertia count (Haynsworth needs A_II nonsingular), though the
        # whole matrix may be regular (a saddle's multiplier coupled to the interface
        # alone): the caller factors the whole instead (ksp.direct_factor). On one rank
        # the interior is the whole, whose null pivots are its own (as MUMPS's)
        if self.size > 1 and self._mpi.allreduce(int(self.solver.null_pivot())):
            raise SingularInteriorError("a rank's interior has a null pivot")
        self.failed = bool(self._mpi.allreduce(int(self.solver.failed())))
        # a failed factorisation: solves give Inf, and a symmetric matrix counts as all
        # negative (no step is taken with it)
        self.negative = matrix.getSize()[0] if self.symmetric else None
        if self.failed:
            return
        n_interior = self.n - off
        # the couplings: A_I,G (W's right-hand sides, on the interior's first head rows
        # and last tail rows) and A_G,I on the reaching rows
        head = np.arange(start + off, start + off + self.head, dtype=PETSc.IntType)
        tail = np.arange(end - self.tail, end, dtype=PETSc.IntType)
        own = np.arange(start, start + off, dtype=PETSc.IntType)
        following = np.arange(end, end + B, dtype=PETSc.IntType) if self.has_next else own[:0]
        coupled = np.union1d(np.arange(self.head), np.arange(n_interior - self.tail, n_interior))
        couplings = np.zeros((coupled.size, len(own) + len(following)))
        if off:
            couplings[:self.head, :B] = matrix.getValues(head, own) if self.head else 0.0
            reached = np.arange(start + off, start + off + self.head_columns,
                                dtype=PETSc.IntType)
            self._own_rows = (matrix.getValues(own, reached) if self.head_columns
                              else np.zeros((B, 0)))
            self._own_block = matrix.getValues(own, own)
        if self.has_next and self.tail:
            couplings[coupled.size - self.tail:, off:] = matrix.getValues(tail, following)
        # A_G_p,I_p-1: the own interface's rows on the previous rank's reaching columns,
        # sent to that rank, which holds y and W of I_p-1
        previous = (matrix.getValues(own, np.arange(start - self.back, start,
                                                     dtype=PETSc.IntType))
                    if off and self.back else np.zeros((B if off else 0, 0)))
        received = self._mpi.allgather(previous)
        self._next_rows = received[self.rank + 1] if self.has_next else np.zeros((0, 0))
        self.W = self._coupling_solve(coupled, couplings)
        self._factor_interface(self.solver.negative_pivots() if self.symmetric else 0)

    def _coupling_solve(self, rows, values):
        """W = A_II^-1 A_IG, (k, n_interior) in the factor's order, from A_IG's nonzero
        ``rows`` (the interior's natural numbering) and their ``values`` (len(rows), k),
        by sparse right-hand sides."""
        n_interior = self.n - self.offset
        if not rows.size:
            return np.zeros((values.shape[1], n_interior))
        if self.reversed:
            rows = n_interior - 1 - rows
        return self.solver.solve_sparse(rows, values)

    def _natural(self, array, start, stop):
        """The interior's natural positions start to stop - 1 of ``array`` (along its
        last axis, the interior in the factor's order), in the natural order: a view."""
        if not self.reversed:
            return array[..., start:stop]
        n_interior = self.n - self.offset
        return array[..., n_interior - stop:n_interior - start][..., ::-1]

    def _factor_interface(self, interior_negative):
        """S from every rank's contributions (module docstring), its pseudo-inverse, and
        (symmetric) the negative eigenvalues of the whole matrix, from the interiors'
        counts ``interior_negative`` (this rank's) and S's, the same on every rank
        (rank 0's). Not finite: failed."""
        B, off = self.block, self.offset
        m = (self.size - 1) * B
        parts = []
        own_slot = (self.rank - 1) * B if off else None
        next_slot = self.rank * B if self.has_next else None
        # A_GI W on the interior columns the interface rows reach (the first
        # head_columns, the last next_back): A_GI is zero elsewhere; W's first B rows
        # are the own interface's columns, its last B the next one's
        n_interior = self.n - off
        if off:
            rows = self._own_rows
            reached = self._natural(self.W, 0, self.head_columns)
            parts.append((own_slot, own_slot, self._own_block - rows @ reached[:B].T))
            if self.has_next:
                parts.append((own_slot, next_slot, -rows @ reached[-B:].T))
        if self.has_next:
            rows = self._next_rows
            reached = self._natural(self.W, n_interior - self.next_back, n_interior)
            parts.append((next_slot, next_slot, -rows @ reached[-B:].T))
            if off:
                parts.append((next_slot, own_slot, -rows @ reached[:B].T))
        schur = np.zeros((m, m))
        for rank_parts in self._mpi.allgather(parts):
            for i, j, values in rank_parts:
                schur[i:i + B, j:j + B] += values
        negative = self._mpi.allreduce(interior_negative)
        if not np.all(np.isfinite(schur)):
            self.failed = True
            return
        rows, columns = _equilibration(schur, self.symmetric)
        balanced = rows[:, None] * schur * columns[None, :]
        if self.symmetric:
            values, vectors = np.linalg.eigh(0.5 * (balanced + balanced.T))
            kept = np.abs(values) > NULL_PIVOT * np.abs(values).max(initial=0.0)
            inverse = (vectors[:, kept] / values[kept]) @ vectors[:, kept].T
            self.negative = self._mpi.bcast(negative + int(np.sum(values[kept] < 0)), root=0)
        else:
            inverse = np.linalg.pinv(balanced, rcond=NULL_PIVOT) if m else balanced
        # S = R^-1 balanced C^-1, so S^+ = C balanced^+ R
        self._inverse = columns[:, None] * inverse * rows[None, :]

    # --- solves ---------------------------------------------------------------------
    def solve_columns(self, columns, rows=None):
        """x_j = A^-1 b_j for the local arrays ``columns`` (as ksp.solve_columns: ``rows``
        the local rows of a submatrix in the columns' layout, the others returning b_j;
        Inf where the factorisation failed). Each column's interior rows are read once
        into a Fortran-ordered right-hand side in the factor's order, the interior's
        factorisation solves into a new array of the same layout, the interface's corrections
        act on it in place, and each solution is written from it once (where ``rows``
        is given, over a copy of the column). Collective."""
        columns = [np.asarray(column) for column in columns]
        if not columns:
            return []
        B, off, k = self.block, self.offset, len(columns)
        n_interior = self.n - off
        # the interior's rows in the factor's order, as positions in a column (a
        # reversed interior is the first rank's: off is 0 there)
        in_factor_order = slice(None, None, -1) if self.reversed else slice(off, None)
        if rows is not None:
            rows = np.asarray(rows)
            interface_rows, interior_rows = rows[:off], rows[in_factor_order]
        else:
            interface_rows, interior_rows = slice(0, off), in_factor_order
        right = np.empty((n_interior, k), dtype=PETSc.ScalarType, order="F")
        for j, column in enumerate(columns):
            if rows is None:
                right[:, j] = column[interior_rows]
            else:   # gathered straight into the column, no temporary ("clip": no
                # buffered copy for the bounds check; the rows are the submatrix's own)
                np.take(column, interior_rows, out=right[:, j], mode="clip")
        b_interface = np.array([column[interface_rows] for column in columns])   # (k, off)
        if self.failed:
            y, x_interface = np.full((k, n_interior), np.inf), np.full((k, off), np.inf)
        else:
            y = self.solver.solve(right).T                  # (k, n_I), factor's order
            sent = np.zeros((2, B, k))
            if off:
                sent[0] = b_interface.T - self._own_rows @ self._natural(
                    y, 0, self.head_columns).T
            if self.has_next:
                sent[1] = -self._next_rows @ self._natural(
                    y, n_interior - self.next_back, n_interior).T
            parts = np.empty((self.size, 2, B, k))
            self._mpi.Allgather(sent, parts)
            right_side = (parts[1:, 0] + parts[:-1, 1]).reshape(-1, k)
            interface = self._inverse @ right_side                          # ((P-1) B, k)
            x_interface = np.zeros((k, off))
            if off:
                x_own = interface[(self.rank - 1) * B:self.rank * B]
                x_interface[:] = x_own.T
                y -= x_own.T @ self.W[:B]
            if self.has_next:
                y -= interface[self.rank * B:(self.rank + 1) * B].T @ self.W[-B:]
        solutions = []
        for j, column in enumerate(columns):
            solution = column.copy() if rows is not None else np.empty(len(column))
            solution[interface_rows] = x_interface[j]
            solution[interior_rows] = y[j]
            solutions.append(solution)
        return solutions

    def negative_pivots(self):
        """The number of negative eigenvalues of the last factorised symmetric matrix."""
        return self.negative

    def destroy(self):
        for obj in (self.solver, self.interior, self._index):
            if obj is not None:
                obj.destroy()


def _equilibration(matrix, symmetric, sweeps=RUIZ_SWEEPS):
    """(r, c): row and column scales that bring every row and column of the dense
    ``matrix`` to a largest entry of about 1, by Ruiz's iteration: r_i /= sqrt(max_j
    |M_ij|), c_j /= sqrt(max_i |M_ij|) for M = diag(r) A diag(c), repeated (it halves
    the logarithm of each row's and column's distance from 1 a sweep, whatever the
    units of the unknowns and of the equations: D A D and R A C alike). Of a symmetric
    matrix r = c at every sweep (E A E keeps the inertia, Sylvester). A zero row or
    column keeps 1."""
    def inverse_root(largest):
        return 1.0 / np.sqrt(np.where(largest > 0.0, largest, 1.0))
    magnitude = np.abs(matrix)
    rows, columns = np.ones(len(matrix)), np.ones(len(matrix))
    for _ in range(sweeps):
        scaled = rows[:, None] * magnitude * columns[None, :]
        rows = rows * inverse_root(scaled.max(axis=1, initial=0.0))
        columns = rows.copy() if symmetric else columns * inverse_root(
            scaled.max(axis=0, initial=0.0))
    return rows, columns


def _column_range(matrix, start, end, edge=None):
    """(lowest, highest), (n,) each: every local row's least and greatest global column
    (end and start - 1 where it has no entry). From the diagonal block's CSR pattern,
    whose rows PETSc keeps sorted (its first and last entry), and, for the rows with
    entries beyond it (a chain's couplings to the previous and next ranks), from those
    rows' own entries: read one by one on the first and last ``edge`` rows where these
    hold every entry beyond the block (the local count of stored entries less the
    block's), else from the whole local pattern (MatGetRowIJ, which copies the local rows
    with their values), not the whole CSR with its values and a reduction over every
    entry (the costs: docs/performance.md, "Newton steps")."""
    several = matrix.getComm().getSize() > 1
    indptr, columns = (matrix.getDiagonalBlock() if several else matrix).getRowIJ()
    first_column = matrix.getOwnershipRangeColumn()[0]      # the block's column 0
    n = end - start
    lowest = np.full(n, end, dtype=np.int64)
    highest = np.full(n, start - 1, dtype=np.int64)
    filled = np.flatnonzero(np.diff(indptr) > 0)
    lowest[filled] = columns[indptr[filled]] + first_column
    highest[filled] = columns[indptr[filled + 1] - 1] + first_column
    if not several:
        return lowest, highest
    beyond_block = stored_entries(matrix, "nz_used") - int(indptr[-1])
    if beyond_block == 0:
        return lowest, highest
    edge_rows = _edge_rows(matrix, start, indptr, edge, beyond_block)
    if edge_rows is not None:
        for row, row_columns in edge_rows:
            if len(row_columns):
                lowest[row], highest[row] = row_columns.min(), row_columns.max()
        return lowest, highest
    whole_indptr, whole_columns = matrix.getRowIJ()
    beyond = np.flatnonzero(np.diff(whole_indptr) > np.diff(indptr))
    counts = np.diff(whole_indptr)[beyond]
    entries = csr_positions(whole_indptr[beyond], counts)
    spans = np.r_[0, np.cumsum(counts)]
    lowest[beyond] = row_reduce(np.minimum, spans, whole_columns[entries], end)
    highest[beyond] = row_reduce(np.maximum, spans, whole_columns[entries], start - 1)
    return lowest, highest


def _edge_rows(matrix, start, indptr, edge, beyond_block):
    """[(row, its global columns)] of the first and last ``edge`` local rows (local
    numbers; MatGetRow one by one) where these hold all ``beyond_block`` entries of the
    local rows beyond the diagonal block (whose CSR row pointers are ``indptr``), else
    None: a chain's couplings to the neighbouring ranks sit there, and then the reaches
    need no other row's entries (_column_range)."""
    n = len(indptr) - 1
    edge = edge or 0
    rows = np.unique(np.r_[np.arange(min(edge, n)), np.arange(max(n - edge, 0), n)])
    entries = [matrix.getRow(start + int(row))[0] for row in rows]
    outside = sum(len(row_columns) for row_columns in entries) - int(
        np.sum(np.diff(indptr)[rows]))
    return list(zip(rows, entries)) if outside == beyond_block else None


def stored_entries(matrix, kind="nz_allocated"):
    """The nonzeros allocated (a change of pattern), or ``kind`` "nz_used" stored, in
    this rank's rows of ``matrix``."""
    return int(matrix.getInfo(PETSc.Mat.InfoType.LOCAL)[kind])
