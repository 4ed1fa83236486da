"""The Newton Jacobian of a problem whose load follows the line (the drag of a current),
kept banded by a chain of resultants (docs/method.md §11, "A load without potential"),
or with another term whose derivative is not symmetric (``Term.unsymmetric``: the
seabed friction, whose limit follows the contact reaction, physics/friction.py).

A load f_j given at the P2 nodes (N/m, interpolated in P2) enters the gradient of the
reduced problem as -b on the d3 rows, b_n = int F phi_n dS with F(S) = int_S^L f_h dS
(plus, when the start is free, minus the whole: F(S) = -int_0^S f_h), the resultant of
the load beyond S (global_step/nodal_loads.py). Where f depends on the frames (the drag on the
tangent), b depends on every node beyond n: its derivative is dense. It is kept banded
by making the resultants at the vertices, Psi_i = delta F(S_i) (3 each), unknowns with
one equation per element,

    Psi_e - Psi_e+1 - sum_l I_e,l delta f_e,l = 0,    I_e = int_e phi (Simpson's),

in the row of Psi_e from a held start (Psi_N = 0), of Psi_e+1 from a held end
(Psi_0 = 0, the equation's sign reversed), and

    delta b_n = sum_{e ni n} ( I_e,n Psi_e+1 + sum_l T_e,nl delta f_e,l ),
    T_e,nl = int_e phi_n(S) int_S^{S_e+1} phi_l dS'.

The frames' rows take -t_n x delta b_n (omega) and -d3_n . delta b_n (the stretch),
delta f_l = G_l omega_l (physics/drag.py drag_jacobian). The matrix is that of H
(analysis/second_variation.py, with the resultants' slots as identity rows) plus these
entries (a copy of H's values on H's pattern, which holds these places as zeros from
H's first assembly: Term.jacobian_pattern): unsymmetric, factored by
global_step/ksp.direct_factor (on one rank PETSc's LU in the natural order, checked,
MUMPS's LU where the check fails; on several by substructuring, each rank its interior
by that same checked LU; options -rod_newton_*). H's curvature term is the load's at its current
value, symmetrised: the antisymmetric rest is the torque balance, zero at a solution,
so the steps still converge quadratically.
"""

from petsc4py import PETSc

from petsc_rod.global_step.chain_factor import stored_entries
from petsc_rod.global_step.ksp import NEWTON_PREFIX, direct_factor, solve_vecs


class NewtonJacobian:
    """J on the layout of a SecondVariation ``hessian`` (its chains' and resultants'
    slots), made from H and the unsymmetric terms' add_jacobian at each ``assemble``;
    owns its matrix and LU factorisation (ksp.direct_factor), ``destroy()``."""

    def __init__(self, hessian):
        self.hessian = hessian
        self.problem = hessian.problem
        self.matrix = None
        self.factor = None
        self._h_entries = None          # H's stored entries when J took its values

    def assemble(self):
        """J at the state H was last assembled at, factored. Collective."""
        hessian = self.hessian
        added = False                               # the terms' entries in J already
        if self.matrix is None and self._reserved():
            # a copy of H, whose pattern holds the terms' entries (Term.jacobian_pattern);
            # the pattern is kept through zeroRows: one symbolic factorisation for the run
            self.matrix = hessian.matrix.duplicate(copy=True)
            self.matrix.setOption(PETSc.Mat.Option.SYMMETRIC, False)
        elif self.matrix is None:
            # a term's entries that H's pattern does not hold (the friction's): in H's
            # preallocation (a node's row meets the 5 nodes of its elements), then H
            # added (MatAXPY: the union of the patterns); the copy of H's pattern would
            # take them as new nonzeros, each a reallocation of the whole matrix
            block = hessian.block
            self.matrix = PETSc.Mat().createAIJ(hessian.matrix.getSizes(),
                                                nnz=(5 * block, 2 * block),
                                                comm=self.problem.mesh.comm)
            self.matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
            self._add_terms()
            added = True
            self.matrix.axpy(1.0, hessian.matrix,
                             structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        elif self._pattern_of_h():
            # the same pattern as H: a copy of the values (MatCopy), far cheaper than
            # MatAXPY's general path (docs/performance.md, "Newton steps")
            hessian.matrix.copy(self.matrix,
                                structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        else:
            # J holds entries beyond H's pattern: H's added row by row (MatAXPY)
            self.matrix.zeroEntries()
            self.matrix.axpy(1.0, hessian.matrix,
                             structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        self.matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        self.matrix.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self._h_entries = stored_entries(hessian.matrix, "nz_used")
        if not added:
            self._add_terms()
        # the held unknowns keep their identity rows (what the followers added there
        # is dropped); their columns meet a zero step
        self.matrix.zeroRows(hessian.held_rows, diag=1.0)
        if self.factor is None:
            # the rows come node by node, hessian.block each: the LU's analysis on the
            # nodes' graph (ksp.mumps_defaults), the ranks' first nodes the interface of
            # the substructuring (chain_factor.py)
            self.factor = direct_factor(self.matrix, PETSc.PC.Type.LU, hessian.block,
                                        NEWTON_PREFIX)
        self.factor.set_up(self.matrix)

    def _reserved(self):
        """Whether H's pattern holds every unsymmetric term's entries of J (each term
        that reserves them there by its jacobian_pattern says so: Term.jacobian_reserved)."""
        return all(term.jacobian_reserved for term in self.problem.terms
                   if term.unsymmetric)

    def _pattern_of_h(self):
        """Whether J's pattern is H's on every rank: J was H's copy or holds H's pattern,
        and only grows (new nonzeros), and H's count of stored entries is the one J was
        made from, so the same count is the same pattern. Collective."""
        h_entries = stored_entries(self.hessian.matrix, "nz_used")
        same = (h_entries == self._h_entries
                and stored_entries(self.matrix, "nz_used") == h_entries)
        return bool(self.problem.mesh.global_min(int(same)))

    def _add_terms(self):
        """The unsymmetric terms' entries (Term.add_jacobian) added, and J assembled."""
        for term in self.problem.terms:
            term.add_jacobian(self)
        self.matrix.assemble()

    def add(self, rows, columns, values):
        """Add blocks ``values`` (k, len rows, len columns) at global ``rows`` (k, r) and
        ``columns`` (k, c), before assembly."""
        if len(rows):
            self.matrix.setValuesRCV(rows.astype(PETSc.IntType), columns.astype(PETSc.IntType),
                                     values, addv=PETSc.InsertMode.ADD_VALUES)

    def solve_many(self, columns):
        """[J^-1 c for the Vecs c of ``columns``], new Vecs, in one solve
        (global_step/ksp.solve_vecs)."""
        return solve_vecs(self.factor, columns)

    def destroy(self):
        for obj in (self.factor, self.matrix):
            if obj is not None:
                obj.destroy()
