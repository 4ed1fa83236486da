"""The global step of the Uzawa iteration (docs/method.md §3 step 1, §4, §5).

For each field g_i of (d1, d2, r' = d3), with tau and lambda fixed,

    (2 c_i K + R W) g_i = W (R tau_i - lambda_i) + 2 (c_i - a_i) K tau_i + b_i,

K the P2 stiffness matrix, W the lumped (Simpson) node mass, a_i the split of the
stiffness, c_i the coefficients of the matrices (penalty.matrix_split) and b_3 the loads
int F.g dS (centreline.py). Where the stiffness varies along the line, a_i and c_i are
functions of S inside the integrals of K (coefficients.FieldCoefficients: 2 c_i K stands
for int 2 c_i(S) g_k' g_l' dS, and the lagged part is per element too). The r' problem
of a rod held at both ends is bordered by the chord constraint int r' dS = r(L) - r(0);
r follows from r' by integration. The three matrices are assembled and factored once per
penalty R.

The loads and whatever else the physics adds come from the problem's terms
(physics/term.py), called in list order: a term may add to the slope's matrix before
it is factored (add_slope_matrices: a flex joint's spring), the loads fixed over a
step are summed once per step into b_3 (add_step_load), those that depend on the
iterate are added every iteration (add_iterate_load), and a term may solve slope
components itself (solve_slope: the seabed's z).
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.global_step.centreline import chains_from_start, positions_from_increments
from petsc_rod.global_step.coefficients import ENERGY, LAGGED
from petsc_rod.global_step.matrices import ScalarProblem, assemble_matrix
from petsc_rod.mesh.elements import element_integrals
from petsc_rod.mesh.fields import CHUNK, VectorField, blocks, element_slices
from petsc_rod.scenes import boundary

EVENTS = {name: PETSc.Log.Event(f"rod_{name}") for name in ("assembly", "rhs", "solve")}

# KSP option prefixes of the three problems, in frame order (-rod_slope_ksp_type, ...)
PREFIXES = ("rod_d1_", "rod_d2_", "rod_slope_")


class GlobalStep:
    """The three scalar problems at one penalty, with the end conditions and loads of
    the current load factor, for the ``terms`` (physics/term.py) of the problem. Owns the
    problems' PETSc objects and the summed load; ``destroy()`` releases them (the terms
    are the problem's)."""

    def __init__(self, mesh, scene, coefficients, penalty, terms):
        self.mesh, self.scene, self.terms = mesh, scene, terms
        # the fields' stiffness along the line (coefficients.FieldCoefficients)
        self.coefficients = coefficients
        self.start_state, self.end_state = scene.start_state(0.0), scene.end_state(0.0)
        # 1 + eps at a clamped start and end: the prescribed slope is (1 + eps) d3 there
        # on an extensible line (set_clamp_stretch, docs/method.md §12); 1 otherwise
        self.clamp_stretch = (1.0, 1.0)
        self.bordered = boundary.is_held(self.start_state) and boundary.is_held(self.end_state)
        self.rhs = [VectorField(mesh, f"rhs_{n}") for n in ("d1", "d2", "slope")]
        self.load = VectorField(mesh, "step_load")     # b_3: the terms' loads of the step
        self.lags = bool(coefficients.lagged_fields)
        self._stiffness = {}            # the assembled stiffness matrices, by key
        if self.lags:
            # two work vectors for K tau_i
            self._lagged_work = self.field_stiffness(
                coefficients.lagged_fields[0], LAGGED)[1].createVecs()
        self.problems = []
        # int_e phi_k dS, (3, ne), and work arrays of the slope's integration
        self._integrals = np.ascontiguousarray(element_integrals(mesh.element_h).T)
        self._increments = np.zeros((3, mesh.n_local_elements))
        self._element_work = np.zeros(mesh.n_local_elements)
        self._target = np.zeros((min(mesh.n_local_nodes, CHUNK), 3, 3))   # w (R tau - lambda)
        # the slope components solved here: those no term solves itself
        elsewhere = {c for term in terms for c in term.slope_components}
        self._slope_components = tuple(c for c in range(3) if c not in elsewhere)
        try:
            self.build(penalty)
        except Exception:           # a solver the options refuse: free what was made
            self.destroy()
            raise

    def build(self, penalty):
        """(Re)assemble and factor the three problems at penalty R, N (the only place
        they are created)."""
        self._destroy_problems()
        mesh, h = self.mesh, self.mesh.element_h
        EVENTS["assembly"].begin()
        self.penalty = penalty
        matrices = [self.coefficients.global_step_matrices(i, penalty) for i in range(3)]
        for term in self.terms:                 # springs on the slope (the flex joints)
            term.add_slope_matrices(matrices[2])
        self.problems = [ScalarProblem(
            mesh, matrices[i],
            boundary.director_prescribed(i, self.start_state, self.end_state,
                                         mesh.n_elements), prefix)
            for i, prefix in enumerate(PREFIXES)]
        if self.bordered:
            self.problems[2].add_integral_constraint(element_integrals(h))
        self._set_prescribed()
        for term in self.terms:
            term.build(matrices[2], penalty)
            term.set_clamp_stretch(*self.clamp_stretch)
        EVENTS["assembly"].end()

    def unconstrained_slope_matrix(self):
        """The slope problem's matrix as build assembles it, before its prescribed rows
        and columns are cleared (the problems keep only the constrained one): a new Mat,
        the caller's to destroy (validation/roundoff.py)."""
        matrices = self.coefficients.global_step_matrices(2, self.penalty)
        for term in self.terms:
            term.add_slope_matrices(matrices)
        return assemble_matrix(self.mesh, matrices)

    def ksps(self):
        """Every KSP of the global step: d1, d2, the slope, and the terms' (the height's
        with a seabed)."""
        return [problem.ksp for problem in self.problems] + [
            ksp for term in self.terms for ksp in term.ksps()]

    @property
    def slope_problem(self):
        return self.problems[2]

    def prepare(self, t):
        """End conditions and loads at load factor t: the prescribed frame rows, the
        terms' step (Term.prepare), and b_3, the sum of their loads fixed over the step
        (Term.add_step_load: the dead loads' int F.g dS)."""
        scene = self.scene
        self.start_state, self.end_state = start, end = scene.start_state(t), scene.end_state(t)
        self._set_prescribed()
        for vec in self.load.components:
            vec.zeroEntries()
        for term in self.terms:
            term.prepare(t, start, end)
            term.add_step_load(self.load)

    def _set_prescribed(self):
        for i, problem in enumerate(self.problems):
            problem.set_prescribed(self._prescribed(i))

    def _prescribed(self, i):
        """The prescribed dofs of field i (boundary.director_prescribed), the slope's
        clamped vertex values scaled by clamp_stretch."""
        prescribed = boundary.director_prescribed(i, self.start_state, self.end_state,
                                                  self.mesh.n_elements)
        if i != 2 or self.clamp_stretch == (1.0, 1.0):
            return prescribed
        stretch = {0: self.clamp_stretch[0], self.mesh.n_elements: self.clamp_stretch[1]}
        return [(vertex, slot, value * stretch[vertex] if slot == boundary.VERTEX else value)
                for vertex, slot, value in prescribed]

    def set_clamp_stretch(self, start, end):
        """1 + eps at a clamped start and end (1 at an end that is not clamped): the
        slope prescribed there becomes (1 + eps) d3 (docs/method.md §12), in the P2 slope
        problem and in the terms' that solve slope components (the seabed's z, the
        friction's x and y). The same values on every rank; the slope's lifting is
        recomputed where they changed."""
        stretch = (float(start), float(end))
        if stretch != self.clamp_stretch:
            self.clamp_stretch = stretch
            if self.problems:
                self.problems[2].set_prescribed(self._prescribed(2))
                for term in self.terms:
                    term.set_clamp_stretch(*stretch)

    def solve(self, state):
        """Solve for d1, d2, r' and r of ``state`` (problem/state.py) from its tau and
        lambda; with a border, the chord multiplier mu goes to state.chord_multiplier."""
        EVENTS["rhs"].begin()
        self._assemble_rhs(state.tau, state.lam, state.node_weights)
        for term in self.terms:
            term.add_iterate_load(self.rhs[2], state)
        EVENTS["rhs"].end()
        EVENTS["solve"].begin()
        for problem, rhs, director in zip(self.problems[:2], self.rhs[:2],
                                          (state.d1, state.d2)):
            problem.solve(rhs, director)
        self.solve_centreline(state)
        EVENTS["solve"].end()

    def _assemble_rhs(self, tau, lam, weights):
        """Field i: sum_n w_n (R tau_i - lambda_i) g_n, the lagged part, and for r' the
        load. Block by block (fields.blocks): w (R tau - lambda) of a block is formed
        in a work array that stays in cache, and copied out to the nine Vecs (the load
        added on the way), instead of nine strided passes over an (n, 3, 3) array."""
        n = self.mesh.n_local_nodes
        loads = [vec.getArray(readonly=True) for vec in self.load.components]
        targets = [[vec.getArray() for vec in rhs.components] for rhs in self.rhs]
        for block in blocks(n):
            work = self._target[:block.stop - block.start]
            np.multiply(tau[block], self.penalty, out=work)
            work -= lam[block]
            work *= weights[block, None, None]
            for i, columns in enumerate(targets):
                for c, values in enumerate(columns):
                    if i == 2:
                        np.add(work[:, i, c], loads[c][block], out=values[block])
                    else:
                        values[block] = work[:, i, c]
        for i, columns in enumerate(targets):        # the phantom slot of the last vertex
            for c, values in enumerate(columns):
                values[n:] = loads[c][n:] if i == 2 else 0.0
        if self.lags:
            self._add_lagged_part(tau)

    def _add_lagged_part(self, tau):
        """2 (c_i - a_i) K tau_i on the right-hand side of each field i whose matrix uses
        c_i instead of a_i somewhere (coefficients.FieldCoefficients.lagged_fields; with
        a varying stiffness, int 2 (c_i - a_i)(S) g_k' g_l' dS, element by element): at a
        fixed point (d = tau) the equations are those of a_i."""
        n = self.mesh.n_local_nodes
        work, product = self._lagged_work
        for i in self.coefficients.lagged_fields:
            factor, matrix = self.field_stiffness(i, LAGGED)
            for c, vec in enumerate(self.rhs[i].components):
                values = work.getArray()
                values[:n] = tau[:, i, c]
                values[n:] = 0.0
                matrix.mult(work, product)
                vec.axpy(factor, product)

    def field_stiffness(self, i, part=ENERGY):
        """Field i's stiffness as (factor, Mat) on the P2 dofs: factor times the Mat is
        2 a_i K, the energy's (ENERGY: the energy's gradient in iteration/newton.py), or
        2 (c_i - a_i) K, the lagged part's (LAGGED). On a uniform line the Mat is the one
        unit-coefficient K = int g_k' g_l' dS and the factor the constant; otherwise the
        matrix of the coefficient along the line and 1 (coefficients.FieldCoefficients).
        Each is assembled on first use, once (collective)."""
        factor, key, element_matrices = self.coefficients.part(i, part)
        if key not in self._stiffness:
            self._stiffness[key] = assemble_matrix(self.mesh, element_matrices())
        return factor, self._stiffness[key]

    def solve_centreline(self, state):
        """r' from its right-hand side rhs[2], bordered by r(L) - r(0) = int r' when both
        ends are held, then r at the vertices by integration. The components a term
        solves itself (Term.solve_slope: with a seabed z) are left to it."""
        components = self._slope_components
        if not components:                      # every component solved by a term
            state.chord_multiplier = np.zeros(3)
        elif self.bordered:
            chord = self.end_state.position - self.start_state.position
            state.chord_multiplier = self.slope_problem.solve_constrained(
                self.rhs[2], state.slope, chord, components)
        else:
            self.slope_problem.solve(self.rhs[2], state.slope, components)
        for term in self.terms:
            term.solve_slope(self.rhs[2], state, self.bordered)
        self.integrate_slope(state)

    def integrate_slope(self, state):
        """r at the vertices from the slope (centreline.positions_from_increments), into
        the r field with the slope's vertex values: the element dofs are stride-2 views
        of the slope's ghosted arrays (fields.element_slices), no gather."""
        mesh = self.mesh
        ne = mesh.n_local_elements
        first = int(mesh.element_local[0]) if ne else 0
        increments, work = self._increments, self._element_work
        for c, ghosted in enumerate(state.slope.ghosted_components()):
            left, middle, right = element_slices(ghosted, first, ne)
            column = np.multiply(self._integrals[0], left, out=increments[c])
            column += np.multiply(self._integrals[1], middle, out=work)
            column += np.multiply(self._integrals[2], right, out=work)
        positions = positions_from_increments(
            mesh, increments.T, self.start_state, self.end_state,
            chains_from_start(state, self.start_state, self.end_state))
        for c, (r, slope) in enumerate(zip(state.r.components, state.slope.components)):
            values = r.getArray()
            values[0::2] = positions[:, c]
            values[1::2] = slope.getArray(readonly=True)[0::2]

    def _destroy_problems(self):
        for problem in self.problems:
            problem.destroy()
        self.problems = []

    def destroy(self):
        self._destroy_problems()
        if self.lags:
            for obj in self._lagged_work:
                obj.destroy()
        for matrix in self._stiffness.values():
            matrix.destroy()
        self._stiffness = {}
        for obj in [*self.rhs, self.load]:
            obj.destroy()
