"""A component of the slope problem in Hermite dofs, where a spring on that coordinate
of the nodes is banded (docs/riser.md, "The seabed in the global step"): z for the
seabed, x and y for its friction (physics/friction.py). Written below for z.

The global step solves for the slope r' (P2), not for r (docs/method.md §4). A
seabed spring acts on z = z(a) + int_a^S r'_z, a non-local function of the slope: its
matrix in the slope's dofs would be dense. The pair (z(a), r'_z in P2) is the same space as the
C^1 Hermite cubic z with dofs y = (z_i, z'_i) at the vertices, and the map y -> r'_z is
local (element e, h its length):

    r'_z(S_e) = z'_e,   r'_z(S_e+1) = z'_e+1,
    r'_z(midpoint) = 3/2 (z_e+1 - z_e) / h - (z'_e + z'_e+1) / 4,

r'_z = T y with T banded. The r'_z problem A r'_z = b becomes T^T A T y = T^T b,
the same equations in other coordinates (banded, SPD), where a spring at a node adds a
local term. A held end prescribes z there (the chord condition of the slope problem
becomes z(L) = z_L), a clamp z' there. The Hermite pair (z_i, z'_i) sits in the two slots
of vertex i of the mesh's DMDA, as the P2 pair (vertex, midpoint) of the slope does.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.global_step.ksp import chain_solver, check_solved, note_changed_rows
from petsc_rod.global_step.matrices import assemble_matrix
from petsc_rod.scenes.boundary import is_held


def hermite_rows(mesh):
    """Global rows (z_e, z'_e, z_e+1, z'_e+1) of each owned element, (ne, 4)."""
    first = 2 * np.arange(mesh.element_start, mesh.element_end)[:, None]
    return (first + np.arange(4)[None, :]).astype(PETSc.IntType)


def slope_map(h):
    """T_e, (ne, 3, 4): the element's P2 slope dofs (left, midpoint, right) from its
    Hermite dofs (z_e, z'_e, z_e+1, z'_e+1)."""
    h = np.asarray(h, dtype=float)
    T = np.zeros((h.size, 3, 4))
    T[:, 0, 1] = T[:, 2, 3] = 1.0
    T[:, 1, 0], T[:, 1, 2] = -1.5 / h, 1.5 / h
    T[:, 1, 1] = T[:, 1, 3] = -0.25
    return T


def midpoint_values(h):
    """e_m, (ne, 4): z at the element's midpoint from its Hermite dofs,
    (z_e + z_e+1) / 2 + h (z'_e - z'_e+1) / 8."""
    h = np.asarray(h, dtype=float)
    return np.stack([np.full_like(h, 0.5), h / 8, np.full_like(h, 0.5), -h / 8], axis=1)


class HermiteProblem:
    """T^T A T y = T^T b for the component ``component`` (0, 1, 2: x, y, z) of the slope,
    plus a symmetric term added per element (set_added: the seabed's springs on z, the
    friction's on x and y), with essential conditions on y.

    ``slope_matrices`` (ne, 3, 3) are the element matrices of the slope problem (2 c3 K +
    R W). The KSP (prefix ``prefix``) is the chain solver of the global step
    (ksp.chain_solver: Cholesky in the natural order on one rank, the exact
    substructuring on several).

    ``matrix_of``: another HermiteProblem of the same mesh, slope matrices and added
    element matrices whose matrix this one shares (the friction's y problem shares x's:
    the same springs k_n w_n on both coordinates, and the same fixed rows, a held end
    holding both and a clamp both slopes): only the right-hand side, the fixed values
    and the solution are this one's, and where the options under both prefixes are the
    same (the defaults), its KSP solves with the other's PC, so the matrix is factored
    once for both (on several ranks each factorisation is the substructuring's set-up:
    collectives, local solves and Python calls, and friction's secant loop factors
    afresh at every pass; docs/performance.md, "Two ranks or one").
    """

    def __init__(self, mesh, slope_matrices, prefix, component=2, matrix_of=None):
        self.mesh = mesh
        self.component = component
        self.name = prefix
        self.matrix_of = matrix_of
        h = mesh.element_h
        self.rows = hermite_rows(mesh)
        if matrix_of is None:
            T = slope_map(h)
            self.base = assemble_matrix(
                mesh, np.einsum("eki,ekl,elj->eij", T, slope_matrices, T), self.rows)
            self.to_slope = self._slope_matrix(T)
            self.matrix = self.base.duplicate(copy=True)
            self.constrained = self.base.duplicate(copy=True)
        else:
            self.base, self.to_slope, self.matrix, self.constrained = (
                matrix_of.base, matrix_of.to_slope, matrix_of.matrix, matrix_of.constrained)
        self.added_rhs = self.base.createVecLeft()
        self.rhs, self.solution, self.bc, self._work, self._product, self._projected = (
            self.base.createVecLeft() for _ in range(6))
        self.fixed = np.zeros(0, dtype=PETSc.IntType)
        self._ends = None               # the last set_end_states' (start, end)
        # 1 + eps at a clamped start and end of an extensible line (set_clamp_stretch)
        self.clamp_stretch = (1.0, 1.0)
        self._added = None              # the last set_added's (matrices, vectors)
        # the slope problem's solver and defaults: the natural order on one rank, in
        # which the chain is a band matrix without fill
        self.ksp = chain_solver(mesh.comm, self.constrained, prefix)
        if matrix_of is not None and (options_under(prefix)
                                      == options_under(matrix_of.name)):
            self.ksp.setPC(matrix_of.ksp.getPC())

    def _slope_matrix(self, T):
        """T as a DMDA matrix: rows the P2 slope dofs, columns the Hermite dofs (the
        phantom midpoint row of the last vertex stays empty: slope is zero there)."""
        mesh = self.mesh
        matrix = mesh.da.createMatrix()
        vertices = np.arange(mesh.vertex_start, mesh.vertex_end, dtype=PETSc.IntType)
        matrix.setValuesRCV((2 * vertices)[:, None], (2 * vertices + 1)[:, None],
                            np.ones((vertices.size, 1, 1)))
        if len(self.rows):
            matrix.setValuesRCV(self.rows[:, :1] + 1, self.rows, T[:, 1:2, :])
        matrix.assemble()
        return matrix

    def set_end_states(self, start, end):
        """Essential conditions from the end states: the coordinate at a held end, its
        slope at a clamp, d3's component times the clamp's 1 + eps (clamp_stretch)."""
        self._ends = (start, end)
        fixed = self._fixed_rows()
        start_row, end_row = self.base.getOwnershipRange()
        self.fixed = np.array([r for r, _ in fixed], dtype=PETSc.IntType)
        self._local_fixed = np.array([r - start_row for r, _ in fixed
                                      if start_row <= r < end_row], dtype=np.int64)
        self._set_fixed_values()
        if self.matrix_of is None:
            self._constrain()
        elif not np.array_equal(self.fixed, self.matrix_of.fixed):
            raise ValueError(f"{self.name}: fixed rows {self.fixed} differ from those of "
                             f"the matrix it shares ({self.matrix_of.fixed})")

    def set_clamp_stretch(self, start, end):
        """1 + eps at a clamped start and end (docs/method.md §12): the slope prescribed
        there becomes (1 + eps) d3's component, as in the P2 slope problem
        (GlobalStep.set_clamp_stretch). The fixed rows stay, so only their values and
        the lifting change (no refactorisation)."""
        stretch = (float(start), float(end))
        if stretch != self.clamp_stretch:
            self.clamp_stretch = stretch
            if self._ends is not None:
                self._set_fixed_values()

    def _fixed_rows(self):
        """[(row, value)] of the essential conditions of the last end states."""
        last = 2 * self.mesh.n_elements
        fixed = []
        for row, state, stretch in zip((0, last), self._ends, self.clamp_stretch):
            if is_held(state):
                fixed.append((row, state.position[self.component]))
            if state.kind == "clamp":
                fixed.append((row + 1, stretch * state.frame[2, self.component]))
        return fixed

    def _set_fixed_values(self):
        """The owned fixed rows' values (_fixed_rows) into bc, the lifting's vector, and
        _fixed_values."""
        start_row, end_row = self.base.getOwnershipRange()
        self._fixed_values = np.array([v for r, v in self._fixed_rows()
                                       if start_row <= r < end_row], dtype=float)
        self.bc.zeroEntries()
        self.bc.getArray()[self._local_fixed] = self._fixed_values

    def set_added(self, element_matrices, element_vectors):
        """Add sum_e element_matrices (ne, 4, 4) to the matrix and sum_e element_vectors
        (ne, 4) to the right-hand side (replacing the last ones); refactored at the next
        solve. After the first call only the elements whose terms changed are added
        again, as the difference, to the matrix and to its constrained copy (the fixed
        rows and columns left out): the seabed's active set moves at a few nodes near the
        touchdown between iterations, and a full assembly, copy and zeroing of the
        rows cost as much as the rest of the vertical problem. The constrained matrix
        gets the same sums in the same order as the matrix, so it stays the matrix with
        the fixed rows and columns zeroed."""
        matrices = np.asarray(element_matrices, dtype=float)
        vectors = np.asarray(element_vectors, dtype=float)
        if self.matrix_of is not None:
            self._add_vectors(vectors)
            return
        if self._added is None:
            self.base.copy(self.matrix, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            if len(self.rows):
                self.matrix.setValuesRCV(self.rows, self.rows, matrices,
                                         addv=PETSc.InsertMode.ADD_VALUES)
            self._add_vectors(vectors)
            self._added = (matrices.copy(), self._added[1])
            self.matrix.assemble()
            self._constrain()
            return
        last_matrices = self._added[0]
        changed = np.any(matrices != last_matrices, axis=(1, 2))
        rows = self.rows[changed]
        before = self.constrained.stateGet()
        if len(rows):
            delta = matrices[changed] - last_matrices[changed]
            self.matrix.setValuesRCV(rows, rows, delta, addv=PETSc.InsertMode.ADD_VALUES)
            free = np.all(rows[..., None] != self.fixed, axis=-1)    # a few fixed rows
            self.constrained.setValuesRCV(rows, rows, delta * free[:, :, None] * free[:, None, :],
                                          addv=PETSc.InsertMode.ADD_VALUES)
            np.copyto(last_matrices, matrices)
        rows = np.concatenate([rows, self._add_vectors(vectors)])
        for obj in (self.matrix, self.constrained):
            obj.assemble()
        # the rows the changed elements add into, and the first owned vertex's (z, z'),
        # which the previous rank's last element adds into: on several ranks the
        # substructuring's refactorisation reads these rows alone
        first = self.constrained.getOwnershipRange()[0]
        note_changed_rows(self.ksp, np.concatenate([rows.ravel(), [first, first + 1]]),
                          before)

    def _add_vectors(self, vectors):
        """The right-hand side's part of set_added, the whole of it for a problem that
        shares another's matrix (``matrix_of``, which set_added the same element
        matrices): sum_e ``vectors`` (ne, 4) at the first call, after it only the
        elements whose vectors changed, as the difference. Returns the rows of those
        elements (k, 4)."""
        if self._added is None:
            self.added_rhs.zeroEntries()
            if len(self.rows):
                self.added_rhs.setValues(self.rows.ravel(), vectors.ravel(),
                                         addv=PETSc.InsertMode.ADD_VALUES)
            self._added = (None, vectors.copy())
            rows = self.rows
        else:
            last = self._added[1]
            changed = np.any(vectors != last, axis=1)
            rows = self.rows[changed]
            if len(rows):
                self.added_rhs.setValues(rows.ravel(),
                                         np.ravel(vectors[changed] - last[changed]),
                                         addv=PETSc.InsertMode.ADD_VALUES)
                np.copyto(last, vectors)
        self.added_rhs.assemble()
        return rows

    def set_added_rhs(self, element_vectors):
        """Replace the added right-hand side by sum_e element_vectors (ne, 4), the added
        matrix kept (a seabed whose heights moved but not its springs); set_added's
        record of the last vectors follows, so that its next differences start here."""
        vectors = np.asarray(element_vectors, dtype=float)
        self.added_rhs.zeroEntries()
        if len(self.rows):
            self.added_rhs.setValues(self.rows.ravel(), vectors.ravel(),
                                     addv=PETSc.InsertMode.ADD_VALUES)
        self.added_rhs.assemble()
        if self._added is not None:
            np.copyto(self._added[1], vectors)

    def _constrain(self):
        self.matrix.copy(self.constrained, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self.constrained.zeroRowsColumns(self.fixed, diag=1.0)

    def solve(self, slope_rhs, slope):
        """y from the slope problem's right-hand side ``slope_rhs`` (its z component, a Vec
        in P2 layout); sets ``slope`` (Vec) = T y and returns y (a Vec owned here)."""
        self.project(slope_rhs)
        self.solve_projected()
        self.set_slope(slope)
        return self.solution

    def project(self, slope_rhs):
        """T^T b of the slope problem's right-hand side ``slope_rhs`` (a Vec in P2 layout),
        kept for solve_projected: friction's secant loop solves again with new springs
        and the same b (one product, a ghost exchange, less a pass). Collective."""
        self.to_slope.multTranspose(slope_rhs, self._projected)

    def solve_projected(self):
        """y of the last ``project``'s T^T b, the added right-hand side and the fixed
        values (the lifting by the matrix of now); returns y (a Vec owned here)."""
        self._projected.copy(self.rhs)
        self.rhs.axpy(1.0, self.added_rhs)
        self.matrix.mult(self.bc, self._product)            # the lifting
        self.rhs.copy(self._work)
        self._work.axpy(-1.0, self._product)
        self._work.getArray()[self._local_fixed] = self._fixed_values
        self.ksp.solve(self._work, self.solution)
        check_solved(self.ksp, self.name)
        return self.solution

    def set_slope(self, slope):
        """``slope`` (Vec, P2 layout) = T y of the last solve. Collective."""
        self.to_slope.mult(self.solution, slope)

    def end_residual(self):
        """(b - M y) at the row of z(L) after a solve (summed over the ranks): the
        component's part of the chord multiplier mu of the slope problem, T^T c = e_z(L) - e_z(0)
        (docs/riser.md). Collective."""
        residual = self._product
        self.matrix.mult(self.solution, residual)
        residual.aypx(-1.0, self.rhs)
        row = 2 * self.mesh.n_elements
        start, end = residual.getOwnershipRange()
        local = residual.getArray(readonly=True)[row - start] if start <= row < end else 0.0
        return float(self.mesh.global_sum(local))

    def destroy(self):
        shared = (() if self.matrix_of is not None
                  else (self.base, self.to_slope, self.matrix, self.constrained))
        for obj in (self.ksp, *shared, self.added_rhs, self.rhs, self.solution, self.bc,
                    self._work, self._product, self._projected):
            obj.destroy()


def options_under(prefix):
    """{name after ``prefix``: value} of the options database's entries under
    ``prefix``: two prefixes whose dicts are equal configure their solvers alike."""
    return {name[len(prefix):]: value for name, value in PETSc.Options().getAll().items()
            if name.startswith(prefix)}
