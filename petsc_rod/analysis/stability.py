"""Which equilibrium a step reached: the inertia of the second variation H on the
constraint set (analysis/second_variation.py), and a direction that leaves a saddle
(docs/method.md §10).

The state is a local minimiser when H is positive semi-definite on the constraint set,
a saddle when H has a negative eigenvalue there. Sylvester's law of inertia counts those
without an eigen-solve: the symmetric-indefinite factorisation of H (MUMPS; on several
ranks by substructuring, global_step/chain_factor.py: the interiors' negative pivots
plus the interface Schur complement's negative eigenvalues) gives the number of negative
eigenvalues, and the chord constraint is taken into account by the Schur complement,
n_neg(H on the constraint) = n_neg(H) + n_pos(C^T H^-1 C) - m (C: its m columns, the
chord's 3 and, in a Newton step's test where K1 = K2, the mean roll: constrain_roll).
The plain iteration is a descent method and leaves a saddle by itself, slowly; an
accelerated one may converge to it, hence this check. With the positions' chains H is
a KKT matrix, whose inertia has n_elements negative eigenvalues per component more than
the second variation on the rotations: they are counted off (negative_pivots). A Newton
step solves with the same factorisation of H - shift M (iteration/newton.py).
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.second_variation import SecondVariation
from petsc_rod.global_step.ksp import INERTIA_PREFIX, direct_factor, solve_vecs
from petsc_rod.petsc_defaults import defaults_in_effect

# MUMPS's threshold of a null pivot (CNTL 3; negative: absolute) where the chains run
# from a line's end (centreline.chains_from_start): there its default, relative to the
# matrix's norm, took one of the chains' pivots for null and the count of negative
# eigenvalues came out one short of the chains' own (docs/riser.md §3b, "The path").
NULL_PIVOT = -1e-300

# Inverse-iteration steps for the direction of negative curvature.
INVERSE_STEPS = 8
# Start of the inverse iteration: sin(GOLDEN i^1.5) at row i (no pattern a mode could
# be orthogonal to).
GOLDEN = 0.5 * (1 + 5**0.5)


class StabilityTest(SecondVariation):
    """The second variation H at a problem's state (SecondVariation) with the LDL^T of
    H - shift M: the inertia test on the constraint set (negative_directions), the solves
    a Newton step makes with the same factor, the direction of negative curvature by
    inverse iteration (descent_direction) and the verdict on the state (verdict).
    Collective; ``destroy()`` frees every PETSc object."""

    def __init__(self, problem):
        self._factored = False
        self._constraint_solves = []      # (H - shift M)^-1 of each, at the last factorisation
        super().__init__(problem)
        self._create_solver()

    def _matrix_changed(self):
        """H changed: the factorisation and the constraint solves are stale."""
        self._factored = False
        self._drop_constraint_solves()

    def _constraint_changed(self):
        """The constraint's forms change: the solves for them are stale (H's factor is
        not)."""
        self._drop_constraint_solves()

    def verdict(self):
        """(stable, direction) of the state (a converged one): True and None for a local
        minimiser; False and a rotation-vector field (n_nodes, 3) along which the energy
        decreases to second order for a saddle (descent_direction); None, None where the
        test cannot decide (a taut, straight rod: ``decidable``)."""
        if not self.decidable:
            return None, None
        direction = self.descent_direction()
        return direction is None, direction

    def _create_solver(self):
        """One LDL^T (global_step/ksp.direct_factor: MUMPS's, by substructuring on several
        ranks) for H - shift M at every shift: the symbolic factorisation is made once,
        the numeric one per shift. The factored matrix is a copy of H (``shifted``), its
        diagonal shifted: H itself is not factored in place, because each update of H
        takes its held rows out of its pattern and puts them back (zeroRowsColumns), a
        new nonzero pattern to PETSc, whose set-up of MUMPS again on a changed pattern
        fails in PETSc 3.18 ("Ordering type cannot be null",
        tests/solver/test_seabed_newton.py); the copy keeps one pattern. With a follower
        load the factored matrix is a submatrix that leaves out the resultants' identity
        rows (``_kept``): they are decoupled from the rest with eigenvalue 1 (nothing to
        count), and they made MUMPS's analysis on several ranks slow
        (docs/performance.md)."""
        self._kept = self._kept_mass = self._kept_rows = self.shifted = None
        if self.resultants:
            start, end = self.matrix.getOwnershipRange()
            kept = np.setdiff1d(np.arange(start, end), self.resultant_rows)
            self._kept_rows = kept - start          # local rows of the factored matrix
            self._kept = PETSc.IS().createGeneral(kept.astype(PETSc.IntType), comm=self.comm)
            self.shifted = self.matrix.createSubMatrix(self._kept, self._kept)
            self.shifted.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            view = self.mass.getSubVector(self._kept)
            self._kept_mass = view.copy()
            self.mass.restoreSubVector(self._kept, view)
        else:
            self.shifted = self.matrix.duplicate(copy=True)
        self.shifted.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self._shift_work = self.shifted.createVecLeft()
        # the factored rows come node by node: block less the resultants' three
        kept_block = self.block - 3 * int(self.resultants)
        self.solver = direct_factor(self.shifted, PETSc.PC.Type.CHOLESKY, kept_block,
                                    INERTIA_PREFIX)

    def factorise(self, shift):
        """Factor H - shift M (the constraint solves of the previous factorisation are
        dropped); H is as it was afterwards."""
        self._drop_constraint_solves()
        if self._kept is None:
            self.matrix.copy(self.shifted, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            self.mass.copy(self._shift_work)
        else:
            self.matrix.createSubMatrix(self._kept, self._kept, submat=self.shifted)
            self._kept_mass.copy(self._shift_work)
        self._shift_work.scale(-shift)
        self.shifted.setDiagonal(self._shift_work, addv=PETSc.InsertMode.ADD_VALUES)
        pivots = ({f"{INERTIA_PREFIX}mat_mumps_cntl_3": str(NULL_PIVOT)}
                  if self.problem.state.chains_from_end else {})
        with defaults_in_effect(pivots):
            self.solver.set_up(self.shifted)
        self._factored = True

    def solve(self, rhs):
        """(H - shift M)^-1 rhs, a new Vec, with the last ``factorise`` (of this H)."""
        return self.solve_many([rhs])[0]

    def solve_many(self, columns):
        """[(H - shift M)^-1 c for the Vecs c of ``columns``], new Vecs, with the last
        ``factorise`` (of this H), in one solve (global_step/ksp.solve_vecs); on
        the resultants' identity rows (left out of the factor, _create_solver) the
        solution is c."""
        self._check_factored()
        return solve_vecs(self.solver, columns, self._kept_rows)

    def _solve_into(self, rhs, solution):
        """solution = (H - shift M)^-1 rhs with the last factorisation (as solve_many)."""
        self._check_factored()
        solution.getArray()[:] = self.solver.solve_columns([rhs.getArray(readonly=True)],
                                                           self._kept_rows)[0]

    def _check_factored(self):
        if not self._factored:
            raise RuntimeError("StabilityTest needs factorise after the last update to solve")

    def negative_directions(self, shift):
        """Eigenvalues of H below ``shift`` (times the mass M) on the constraint set."""
        self.factorise(shift)
        negative = self.negative_pivots()
        if not self.constraint:
            return int(negative)
        self._constraint_solves = self.solve_many(self.constraint)
        schur = np.array([[c.dot(y) for y in self._constraint_solves] for c in self.constraint])
        if not np.all(np.isfinite(schur)):
            # a failed factorisation (its solves give Inf): no count, on every rank alike
            # (the dot products are reduced)
            raise np.linalg.LinAlgError("the inertia test's constraint solves are not finite")
        return int(negative) + int(np.sum(np.linalg.eigvalsh(schur) > 0)) - len(self.constraint)

    def negative_pivots(self):
        """Negative eigenvalues of the last factorisation's H - shift M, those of the
        positions' chains counted off (module docstring)."""
        return self.solver.negative_pivots() - self.chain_constraints

    def solve_in_constraint_span(self, columns):
        """(H - shift M)^-1 c, new Vecs, for the Vecs c of ``columns`` that lie in the span
        of the constraint's orthonormal basis b_j (the chord forms at the state's
        tangents), without a new solve: c = sum_j (b_j . c) b_j, so the solution is
        sum_j (b_j . c) (H - shift M)^-1 b_j, from the solves of the last
        ``negative_directions``."""
        if len(self._constraint_solves) != len(self.constraint) or not self.constraint:
            raise RuntimeError("solve_in_constraint_span needs negative_directions first")
        solutions = []
        for column in columns:
            y = column.duplicate()
            y.zeroEntries()
            y.maxpy([b.dot(column) for b in self.constraint], self._constraint_solves)
            solutions.append(y)
        return solutions

    def _drop_constraint_solves(self):
        for vec in self._constraint_solves:
            vec.destroy()
        self._constraint_solves = []

    def lower_bound(self):
        """Gershgorin: every eigenvalue of H / M is at least min_i (H_ii - sum_j |H_ij|)
        / M_ii (M diagonal). With the positions' chains H is a KKT matrix, to which the
        bound does not apply: the shift is lowered tenfold from -tolerance until no
        eigenvalue lies below it (one factorisation each)."""
        if self.positions:
            lower = -10 * self.tolerance()
            while self.negative_directions(lower) > 0:
                lower *= 10
            return lower
        indptr, _, values = self.matrix.getValuesCSR()
        absolute = np.add.reduceat(np.abs(values), indptr[:-1]) if values.size else np.zeros(0)
        diagonal = self._diagonal.getArray(readonly=True)
        bound = (diagonal + np.abs(diagonal) - absolute) / self._mass_or_one.getArray(readonly=True)
        return self.problem.mesh.global_min(float(bound.min(initial=0.0)))

    def descent_direction(self):
        """A unit rotation-vector field along the mode of H's lowest eigenvalue, (n_nodes,
        3) (on an extensible line (n_nodes, 4): the rotation vector and the stretch k), or
        None when H has no eigenvalue below -tolerance() on the constraint set. The field
        is an escape direction, not the eigenvector: the iteration solves without the
        chord constraint and the last projection onto it adds a node-to-node zigzag, so
        its own curvature can be positive while it lies mostly along the mode
        (docs/stability.md, "The direction at a saddle"). The lowest
        eigenvalue is bracketed by bisection on the inertia between the Gershgorin bound
        and -tolerance to within a factor 2, and inverse iteration at the lower end
        converges to its eigenvector at a rate of at most 1/2 per step."""
        upper = -self.tolerance()
        if self.negative_directions(upper) == 0:
            return None
        lower = min(self.lower_bound(), 2 * upper)
        while lower < 2 * upper:
            middle = -np.sqrt(lower * upper)
            if self.negative_directions(middle) > 0:
                upper = middle
            else:
                lower = middle
        self.factorise(lower)
        vector = self.matrix.createVecLeft()
        # a start with a component along every eigenvector, the same on any number of ranks
        start, end = vector.getOwnershipRange()
        vector.getArray()[:] = np.sin(GOLDEN * np.arange(start, end) ** 1.5)
        self._zero_clamped(vector)
        work = vector.duplicate()
        for _ in range(INVERSE_STEPS):
            self._zero_chains(vector)
            self._project(vector)
            self._solve_into(vector, work)
            work.copy(vector)
            self._zero_chains(vector)
            vector.scale(1.0 / vector.norm())
        self._project(vector)
        direction = self.from_vec(vector)
        vector.destroy()
        work.destroy()
        return direction

    def _zero_chains(self, vector):
        """0 on the chains' unknowns u, nu and the resultants' (the inverse iteration's
        right-hand sides)."""
        if self.block > self.unknowns:
            vector.getArray().reshape(-1, self.block)[:, self.unknowns:] = 0.0

    def _project(self, vector):
        """Remove the components along the (orthonormal) chord forms."""
        for c in self.constraint:
            vector.axpy(-c.dot(vector), c)

    def destroy(self):
        self._drop_constraint_solves()
        for obj in [self.solver, self.shifted, self._shift_work,
                    *[obj for obj in (self._kept, self._kept_mass) if obj is not None]]:
            obj.destroy()
        super().destroy()
