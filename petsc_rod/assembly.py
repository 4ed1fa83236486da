"""PETSc glue of the global step: matrices assembled and factored once, right-hand sides.

Each of r, d1, d2 is one scalar SPD problem A x = b solved for the x, y and z
components with one factorisation (method.md §3 step 1). Essential conditions keep
A symmetric: rows and columns of prescribed dofs are zeroed with a unit diagonal, and
the right-hand side is lifted by the unconstrained matrix times the prescribed values.
"""

import numpy as np
from petsc4py import PETSc

from .errors import RodDivergedError
from .fe import HERMITE, hermite_integrals
from .fields import scatter_element_vectors

KSP_REASONS = {getattr(PETSc.KSP.ConvergedReason, name): name
               for name in dir(PETSc.KSP.ConvergedReason) if not name.startswith("_")}


def element_rows(mesh, element):
    """Global row of each owned element's dofs, (ne, ndofs). DMDA order is natural in 1-D."""
    first = np.arange(mesh.element_start, mesh.element_end)[:, None]
    return (2 * (first + element.offsets[None, :]) + element.slots[None, :]).astype(
        PETSc.IntType)


class ScalarProblem:
    """One scalar SPD operator of the global step with its KSP.

    ``element_matrices`` (ne, k, k) are summed into the DMDA matrix; ``prescribed`` is a
    list of (vertex, slot, value) whose rows are constrained. KSP options are read with
    ``prefix``; the default is a direct Cholesky factorisation (MUMPS on several ranks).
    """

    def __init__(self, mesh, element, element_matrices, prescribed, prefix):
        self.mesh = mesh
        self.name = prefix
        rows = element_rows(mesh, element)
        self.full = mesh.da.createMatrix()
        self.full.setValuesRCV(rows, rows, element_matrices, addv=PETSc.InsertMode.ADD_VALUES)
        self.full.assemble()
        self.full.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.constrained = self.full.duplicate(copy=True)
        start, end = self.full.getOwnershipRange()
        self.fixed_rows = np.array([2 * v + s for v, s, _ in prescribed], dtype=PETSc.IntType)
        self._owned = (self.fixed_rows >= start) & (self.fixed_rows < end)
        self.constrained.zeroRowsColumns(self.fixed_rows[self._owned], diag=1.0)
        self.constrained.setOption(PETSc.Mat.Option.SPD, True)
        self._local_rows = self.fixed_rows[self._owned] - start
        self._fixed_values = np.zeros((int(self._owned.sum()), 3))
        self._lift = [self.full.createVecLeft() for _ in range(3)]
        self._work = self.full.createVecLeft()
        sizes = [(end - start, self.full.getSize()[0]), (3, 3)]
        self._rhs_block = PETSc.Mat().createDense(sizes, comm=mesh.comm)
        self._rhs_block.setUp()
        self._solution_block = self._rhs_block.duplicate()
        self.ksp = PETSc.KSP().create(comm=mesh.comm)
        self.ksp.setOperators(self.constrained)
        self.ksp.setType(PETSc.KSP.Type.PREONLY)
        pc = self.ksp.getPC()
        pc.setType(PETSc.PC.Type.CHOLESKY)
        if mesh.comm.getSize() > 1:
            pc.setFactorSolverType("mumps")
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setFromOptions()
        self.ksp.setUp()
        self._report_failed_factorisation()
        self._factor = (pc.getFactorMatrix() if self.ksp.getType() == PETSc.KSP.Type.PREONLY
                        and pc.getType() in (PETSc.PC.Type.CHOLESKY, PETSc.PC.Type.LU)
                        else None)

    def set_prescribed(self, prescribed):
        """New prescribed values (same rows); computes the lifting A_full x_bc once."""
        self._fixed_values = np.array([value for _, _, value in prescribed]).reshape(-1, 3)[
            self._owned]
        for c, lift in enumerate(self._lift):
            self._work.zeroEntries()
            self._work.getArray()[self._local_rows] = self._fixed_values[:, c]
            self.full.mult(self._work, lift)
            lift.getArray()[self._local_rows] = 0.0

    def solve(self, rhs, solution):
        """Solve for the three components: rhs, solution are VectorFields.

        With a direct solver (preonly + Cholesky or LU) the three right-hand sides go to
        the factorisation together (MatMatSolve): MUMPS then makes one pass instead of
        three, half the solve time on 2 ranks (README, "Performance"). Any other KSP solves
        them one by one.
        """
        block = self._rhs_block.getDenseArray()
        for c in range(3):
            block[:, c] = rhs.components[c].getArray(readonly=True)
            block[:, c] -= self._lift[c].getArray(readonly=True)
            block[self._local_rows, c] = self._fixed_values[:, c]
        self._rhs_block.assemble()
        if self._factor is not None:
            self._factor.matSolve(self._rhs_block, self._solution_block)
            result = self._solution_block.getDenseArray()
            for c in range(3):
                solution.components[c].getArray()[:] = result[:, c]
            return
        for c in range(3):
            self._work.getArray()[:] = block[:, c]
            self._solve_one(self._work, solution.components[c])

    def _report_failed_factorisation(self):
        """One solve with a zero right-hand side: KSPSolve is what reports a failed set-up
        (this petsc4py has no PCGetFailedReason), and the MatMatSolve path skips it."""
        zero = self.full.createVecLeft()
        solution = zero.duplicate()
        try:
            self._solve_one(zero, solution)
        finally:
            zero.destroy()
            solution.destroy()

    def _solve_one(self, rhs, solution):
        self.ksp.solve(rhs, solution)
        reason = self.ksp.getConvergedReason()
        if reason < 0:
            raise RodDivergedError(f"linear solver -{self.name} failed: "
                                   f"{KSP_REASONS.get(reason, reason)}")

    def residual_at(self, solution, rhs, row):
        """(A_full x - b)[row] for the three components: the reaction at a prescribed dof."""
        values = np.zeros(3)
        start, end = self.full.getOwnershipRange()
        for c in range(3):
            self.full.mult(solution.components[c], self._work)
            self._work.axpy(-1.0, rhs.components[c])
            if start <= row < end:
                values[c] = self._work.getArray(readonly=True)[row - start]
        return self.mesh.global_sum(values)

    def destroy(self):
        for obj in [self.ksp, self.full, self.constrained, self._work, self._rhs_block,
                    self._solution_block] + self._lift:
            obj.destroy()


def load_element_vectors(mesh, piece_ends, piece_values):
    """Exact int f.p dS over owned elements for a piecewise-constant load, (ne, 4, 3).

    piece_ends: (m + 1,) breaks in S; piece_values: (m, 3) load of each piece, N/m.
    """
    a = mesh.element_S
    h = mesh.element_h
    out = np.zeros((mesh.n_local_elements, HERMITE.ndofs, 3))
    for lo, hi, f in zip(piece_ends[:-1], piece_ends[1:], piece_values):
        xi0 = np.clip((lo - a) / h, 0.0, 1.0)
        xi1 = np.clip((hi - a) / h, 0.0, 1.0)
        out += hermite_integrals(h, xi0, xi1)[:, :, None] * f[None, None, :]
    return out


def load_ghosted(mesh, piece_ends, piece_values, start_force, end_force):
    """Load part of the r right-hand side on the ghosted vertices, (n_ghosted, 2, 3):
    distributed dead load plus dead forces at free ends (a natural condition, §5)."""
    n_ghosted = mesh.ghost_end - mesh.ghost_start
    out = scatter_element_vectors(n_ghosted, mesh.element_local, HERMITE,
                                  load_element_vectors(mesh, piece_ends, piece_values))
    if mesh.on_lower_boundary:
        out[0 - mesh.ghost_start, 0] += start_force
    if mesh.on_upper_boundary:
        out[mesh.n_elements - mesh.ghost_start, 0] += end_force
    return out
