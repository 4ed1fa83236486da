"""PETSc glue of the global step: matrices assembled and factored once, right-hand sides.

Each of d1, d2 and the slope r' is one scalar SPD problem A x = b (P2) solved for
the x, y and z components with one factorisation (docs/method.md §3 step 1). Essential
conditions keep A symmetric: rows and columns of prescribed dofs are zeroed with a unit
diagonal, and the right-hand side is lifted by the unconstrained matrix times the
prescribed values. The slope problem of a rod held at both ends is bordered by the
constraint int slope dS = r(L) - r(0) (ScalarProblem.add_integral_constraint).
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.global_step import substructuring
from petsc_rod.global_step.ksp import chain_solver, check_solved
from petsc_rod.mesh.elements import GAUSS_POINTS, GAUSS_WEIGHTS, P2, p2_basis
from petsc_rod.mesh.fields import scatter_element_vectors


def element_rows(mesh):
    """Global row of each owned element's P2 dofs, (ne, 3). DMDA order is natural in 1-D."""
    first = np.arange(mesh.element_start, mesh.element_end)[:, None]
    return (2 * (first + P2.offsets[None, :]) + P2.slots[None, :]).astype(PETSc.IntType)


def assemble_matrix(mesh, element_matrices, rows=None):
    """The DMDA matrix sum_e of element matrices (ne, k, k) on the element rows ``rows``
    (ne, k), by default the P2 dofs (element_rows)."""
    rows = element_rows(mesh) if rows is None else rows
    matrix = mesh.da.createMatrix()
    if len(rows):        # a rank may own no element (e.g. 2 elements on 2 ranks), and
        # petsc4py's setValuesRCV divides by the number of rows
        matrix.setValuesRCV(rows, rows, element_matrices, addv=PETSc.InsertMode.ADD_VALUES)
    matrix.assemble()
    matrix.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return matrix


class ScalarProblem:
    """One scalar SPD operator of the global step with its KSP.

    ``element_matrices`` (ne, 3, 3) are summed into the DMDA matrix; ``prescribed`` is a
    list of (vertex, slot, value) whose rows are constrained. KSP options are read with
    ``prefix`` (ksp.chain_solver: a direct Cholesky factorisation by default).
    """

    def __init__(self, mesh, element_matrices, prescribed, prefix):
        self.mesh = mesh
        self.name = prefix
        self._rows = element_rows(mesh)
        self.constrained = assemble_matrix(mesh, element_matrices)
        start, end = self.constrained.getOwnershipRange()
        self.fixed_rows = np.array([2 * v + s for v, s, _ in prescribed], dtype=PETSc.IntType)
        self._owned = (self.fixed_rows >= start) & (self.fixed_rows < end)
        self._local_rows = self.fixed_rows[self._owned] - start
        self._fixed_values = np.zeros((int(self._owned.sum()), 3))
        self._couplings(start)
        self.constrained.zeroRowsColumns(self.fixed_rows[self._owned], diag=1.0)
        self.constrained.setOption(PETSc.Mat.Option.SPD, True)
        self.ksp = chain_solver(mesh.comm, self.constrained, prefix)
        self.ksp.setUp()
        self._report_failed_factorisation()
        self._factor, self._columns = self._direct_solver()
        self._blocks = []           # dense right-hand sides and solutions for MatMatSolve
        if self._factor is not None:
            sizes = [(end - start, self.constrained.getSize()[0]), (3, 3)]
            self._blocks = [PETSc.Mat().createDense(sizes, comm=mesh.comm) for _ in range(2)]
            for block in self._blocks:
                block.setUp()
        self._border = []            # c and w = A^-1 c of the integral constraint, if any

    def _direct_solver(self):
        """How solve() reaches an exact solver past KSPSolve: (factor, None) for a
        factorisation with a multiple right-hand-side solve of its own (MatMatSolve:
        MUMPS, ...); (None, solve) with solve(b, x) on lists of component Vecs for PETSc's
        own factorisation (column by column, as its MatMatSolve would, without copying
        into a dense block) and for the substructuring PC (its three right-hand sides
        share one interface reduction); (None, None) for any other KSP (one KSPSolve per
        component)."""
        pc = self.ksp.getPC()
        if self.ksp.getType() != PETSc.KSP.Type.PREONLY:
            return None, None
        if pc.getType() == PETSc.PC.Type.PYTHON:
            context = pc.getPythonContext()
            if isinstance(context, substructuring.InterfacePC):
                return None, lambda b, x: context.solver.solve(
                    [v.getArray(readonly=True) for v in b], [v.getArray() for v in x])
            return None, None
        if pc.getType() not in (PETSc.PC.Type.CHOLESKY, PETSc.PC.Type.LU):
            return None, None
        factor = pc.getFactorMatrix()
        if pc.getFactorSolverType() != PETSc.Mat.SolverType.PETSC:
            return factor, None
        return None, lambda b, x: [factor.solve(*pair) for pair in zip(b, x)]

    def add_integral_constraint(self, element_integrals):
        """Border A with the row c, c_k = int phi_k dS, for the constraint c.x = target
        (one per component, the same row for x, y and z): the system becomes
        [A c; c^T 0] [x; mu] = [b; target].

        It is solved by the Schur complement (solve_constrained); here, once, w = A^-1 c0
        with c0 = c with the prescribed rows zeroed (so w vanishes there and the
        correction x - mu w keeps the prescribed values), and c.w = c0^T A^-1 c0 > 0.
        ``element_integrals`` (ne, 3) are the element contributions int_e phi_k dS.
        """
        c = self.constrained.createVecLeft()
        c.setValues(self._rows.ravel(), np.ravel(element_integrals),
                    addv=PETSc.InsertMode.ADD_VALUES)
        c.assemble()
        free = c.copy()
        free.getArray()[self._local_rows] = 0.0
        w = free.duplicate()
        try:
            self._solve_one(free, w)
        finally:
            free.destroy()
        self._border = [c, w]
        self._c_dot_w = c.dot(w)

    def _couplings(self, start):
        """The columns of the unconstrained matrix at the prescribed dofs, A e_j, on the
        owned rows they reach (``_coupled_rows``, local; ``_coupling`` (rows, prescribed
        dofs)), before its prescribed rows and columns are cleared: all the lifting
        needs of it, so that the matrix is not kept twice. Collective."""
        matrix = self.constrained
        unit, column = matrix.createVecs()
        columns = []
        try:
            for j in self.fixed_rows:
                unit.zeroEntries()
                if start <= j < start + unit.getLocalSize():
                    unit.getArray()[j - start] = 1.0
                matrix.mult(unit, column)
                columns.append(column.getArray(readonly=True).copy())
        finally:
            unit.destroy()
            column.destroy()
        columns = np.array(columns).reshape(len(self.fixed_rows), -1).T
        self._coupled_rows = np.flatnonzero(np.any(columns != 0.0, axis=1))
        self._coupling = columns[self._coupled_rows]

    def set_prescribed(self, prescribed):
        """New prescribed values (same rows); computes the lifting A_full x_bc, kept
        sparse: it is nonzero only on the rows coupled to a prescribed one. Summed over
        the prescribed dofs in the order of their rows, as a product with A_full would
        sum them."""
        values = np.array([value for _, _, value in prescribed]).reshape(-1, 3)
        self._fixed_values = values[self._owned]
        lifts = np.zeros((len(self._coupled_rows), 3))
        for j in np.argsort(self.fixed_rows, kind="stable"):
            lifts += self._coupling[:, j, None] * values[j]
        lifts[np.isin(self._coupled_rows, self._local_rows)] = 0.0
        nonzero = np.any(lifts != 0.0, axis=1)
        self._lift_rows = self._coupled_rows[nonzero]
        self._lift_values = lifts[nonzero]

    def solve(self, rhs, solution, components=(0, 1, 2)):
        """Solve for the given components (x, y, z by default): rhs, solution are
        VectorFields; the other components of ``solution`` are left as they are (the
        seabed's vertical problem solves z its own way, physics/seabed.py).

        The prescribed rows of ``rhs`` take the prescribed values and the lifting is
        subtracted from the rows next to them, in place, for the solve only: those few
        entries are put back afterwards (the riser's vertical problem reads the same
        right-hand side). A direct solver is called past KSPSolve (_direct_solver):
        PETSc's factorisation and the substructuring PC column by column on the Vecs, a
        factorisation with a multiple right-hand-side solve (MUMPS) with the three
        right-hand sides together (MatMatSolve: one pass instead of three,
        docs/performance.md). Any other KSP solves them one by one.
        """
        touched = np.concatenate([self._lift_rows, self._local_rows])
        kept = []
        for c, vec in enumerate(rhs.components):
            values = vec.getArray()
            kept.append(values[touched])
            values[self._lift_rows] -= self._lift_values[:, c]
            values[self._local_rows] = self._fixed_values[:, c]
        try:
            self._solve_columns(rhs, solution, components)
        finally:
            for vec, values in zip(rhs.components, kept):
                vec.getArray()[touched] = values

    def _solve_columns(self, rhs, solution, components):
        if self._columns is not None:
            self._columns([rhs.components[c] for c in components],
                          [solution.components[c] for c in components])
            return
        if self._factor is not None:        # the block of three (any other is left alone)
            rhs_block, solution_block = self._blocks
            block = rhs_block.getDenseArray()
            for c, vec in enumerate(rhs.components):
                block[:, c] = vec.getArray(readonly=True)
            rhs_block.assemble()
            self._factor.matSolve(rhs_block, solution_block)
            result = solution_block.getDenseArray()
            for c in components:
                solution.components[c].getArray()[:] = result[:, c]
            return
        for c in components:
            self._solve_one(rhs.components[c], solution.components[c])

    def solve_constrained(self, rhs, solution, target, components=(0, 1, 2)):
        """Solve the bordered system of add_integral_constraint for the given components.

        x0 = A^-1 b (solve), then mu = (c.x0 - target) / (c.w) and x = x0 - mu w, so that
        c.x = target. ``target`` (3,); returns mu (3,), the multiplier of the constraint
        (one allreduce for the three components; 0 for a component not solved).
        """
        c, w = self._border
        self.solve(rhs, solution, components)
        # einsum, not a BLAS dot: a threaded OpenBLAS ddot waits for its threads on a
        # busy machine (docs/performance.md)
        local = np.zeros(3)
        for k in components:
            local[k] = np.einsum("i,i->", c.getArray(readonly=True),
                                 solution.components[k].getArray(readonly=True))
        mu = np.zeros(3)
        solved = list(components)
        mu[solved] = (self.mesh.global_sum(local)[solved] - target[solved]) / self._c_dot_w
        for k in components:
            solution.components[k].axpy(-mu[k], w)
        return mu

    def _report_failed_factorisation(self):
        """One solve with a zero right-hand side: KSPSolve is what reports a failed set-up
        (this petsc4py has no PCGetFailedReason), and the MatMatSolve path skips it."""
        zero = self.constrained.createVecLeft()
        solution = zero.duplicate()
        try:
            self._solve_one(zero, solution)
        finally:
            zero.destroy()
            solution.destroy()

    def _solve_one(self, rhs, solution):
        self.ksp.solve(rhs, solution)
        check_solved(self.ksp, self.name)

    def destroy(self):
        for obj in [self.ksp, self.constrained] + self._blocks + self._border:
            obj.destroy()


def load_element_vectors(mesh, load, breaks):
    """Exact int_e F(S) g_k dS over the owned elements, (ne, 3, 3), for a load function
    F: S (...) -> (..., 3) that is linear between consecutive ``breaks`` (sorted).

    Each element is cut at the breaks inside it; on each piece F g_k is a cubic, which
    3-point Gauss integrates exactly. The loop runs over the breaks, not the elements.
    """
    a, h = mesh.element_S[:, None], mesh.element_h[:, None]
    cuts = np.clip((np.asarray(breaks, dtype=float)[None, :] - a) / h, 0.0, 1.0)
    cuts = np.concatenate([np.zeros_like(a), cuts, np.ones_like(a)], axis=1)
    out = np.zeros((mesh.n_local_elements, P2.ndofs, 3))
    for lo, hi in zip(cuts.T[:-1, :, None], cuts.T[1:, :, None]):
        x = lo + (hi - lo) * GAUSS_POINTS[None, :]
        phi, _ = p2_basis(x, mesh.element_h)
        out += np.einsum("eq,eqk,eqc->ekc", h * (hi - lo) * GAUSS_WEIGHTS, phi, load(a + h * x))
    return out


def load_ghosted(mesh, load, breaks):
    """The load part int F.g of the slope right-hand side on the ghosted vertices,
    (n_ghosted, 2, 3) (load_element_vectors summed into the vertex slots)."""
    return scatter_element_vectors(mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
                                   load_element_vectors(mesh, load, breaks))
