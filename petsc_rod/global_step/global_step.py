"""The global step of the Uzawa iteration (docs/method.md §3 step 1, §4, §5).

For each field g_i of (d1, d2, r' = d3), with tau and lambda fixed,

    (2 c_i K + R W) g_i = W (R tau_i - lambda_i) + 2 (c_i - a_i) K tau_i + b_i,

K the P2 stiffness matrix, W the lumped (Simpson) node mass, a_i the split of the
stiffness, c_i the coefficients of the matrices (penalty.matrix_split) and b_3 the loads
int F.g dS (centreline.py). The r' problem of a rod held at both ends is bordered by the
chord constraint int r' dS = r(L) - r(0); r follows from r' by integration. The three
matrices are assembled and factored once per penalty R.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.global_step.centreline import (anchor_work, load_offset,
                                              positions_from_increments)
from petsc_rod.global_step.matrices import ScalarProblem, assemble_matrix, load_ghosted
from petsc_rod.mesh.elements import element_integrals, p2_element_matrices
from petsc_rod.mesh.fields import CHUNK, VectorField, blocks, element_slices
from petsc_rod.riser.terms import RiserTerms
from petsc_rod.scenes import boundary

EVENTS = {name: PETSc.Log.Event(f"rod_{name}") for name in ("assembly", "rhs", "solve")}

# KSP option prefixes of the three problems, in frame order (-rod_slope_ksp_type, ...)
PREFIXES = ("rod_d1_", "rod_d2_", "rod_slope_")


class GlobalStep:
    """The three scalar problems at one penalty, with the end conditions and loads of
    the current load factor. Owns their PETSc objects; ``destroy()`` releases them."""

    def __init__(self, mesh, scene, split, matrix_split, penalty):
        self.mesh, self.scene = mesh, scene
        self.split, self.matrix_split = split, matrix_split
        self.start_state, self.end_state = scene.start_state(0.0), scene.end_state(0.0)
        self.bordered = boundary.is_held(self.start_state) and boundary.is_held(self.end_state)
        self.rhs = [VectorField(mesh, f"rhs_{n}") for n in ("d1", "d2", "slope")]
        self.load = VectorField(mesh, "load")
        self.load_offset = np.zeros(3)
        self.anchor_work = 0.0
        self.lags = bool(np.any(matrix_split != split))
        self._stiffness = None
        if self.lags:
            # two work vectors for K tau_i
            self._lagged_work = self.stiffness().createVecs()
        self.problems = []
        # int_e phi_k dS, (3, ne), and work arrays of the slope's integration
        self._integrals = np.ascontiguousarray(element_integrals(mesh.element_h).T)
        self._increments = np.zeros((3, mesh.n_local_elements))
        self._element_work = np.zeros(mesh.n_local_elements)
        self._target = np.zeros((min(mesh.n_local_nodes, CHUNK), 3, 3))   # w (R tau - lambda)
        # the seabed and the current (petsc_rod/riser), built only when the scene has them
        self.riser = RiserTerms(mesh, scene) if scene.seabed or scene.current else None
        # the slope components solved here: with a seabed z is the vertical problem's
        self._slope_components = (0, 1) if scene.seabed is not None else (0, 1, 2)
        self.build(penalty)

    def build(self, penalty):
        """(Re)assemble and factor the three problems at penalty R, N (the only place
        they are created)."""
        self._destroy_problems()
        mesh, h = self.mesh, self.mesh.element_h
        EVENTS["assembly"].begin()
        self.penalty = penalty
        self.problems = [ScalarProblem(
            mesh, p2_element_matrices(h, 2 * self.matrix_split[i], penalty),
            boundary.director_prescribed(i, self.start_state, self.end_state,
                                         mesh.n_elements), prefix)
            for i, prefix in enumerate(PREFIXES)]
        if self.bordered:
            self.problems[2].add_integral_constraint(element_integrals(h))
        self._set_prescribed()
        if self.riser is not None:
            self.riser.build(2 * self.matrix_split[2], penalty)
        EVENTS["assembly"].end()

    def ksps(self):
        """Every KSP of the global step: d1, d2, the slope, and the height's with a seabed."""
        riser = self.riser.ksps() if self.riser is not None else []
        return [problem.ksp for problem in self.problems] + riser

    @property
    def slope_problem(self):
        return self.problems[2]

    def prepare(self, t):
        """End conditions and loads at load factor t: the prescribed frame rows, and the
        slope's load int F.g dS with F(S) = int_S^L f dS + offset (centreline.py),
        integrated exactly between the load breaks."""
        scene = self.scene
        self.start_state, self.end_state = start, end = scene.start_state(t), scene.end_state(t)
        self._set_prescribed()
        total = scene.load_beyond(0.0, t)
        self.load_offset = load_offset(start, end, total)
        self.anchor_work = anchor_work(start, end, total)
        self.load.add_ghosted(load_ghosted(
            self.mesh, lambda S: scene.load_beyond(S, t) + self.load_offset,
            scene.load_piece_ends))
        if self.riser is not None:
            self.riser.prepare(t, start, end)

    def _set_prescribed(self):
        for i, problem in enumerate(self.problems):
            problem.set_prescribed(boundary.director_prescribed(
                i, self.start_state, self.end_state, self.mesh.n_elements))

    def solve(self, state):
        """Solve for d1, d2, r' and r of ``state`` (iteration/state.py) from its tau and
        lambda; with a border, the chord multiplier mu goes to state.chord_multiplier."""
        EVENTS["rhs"].begin()
        self._assemble_rhs(state.tau, state.lam, state.node_weights)
        if self.riser is not None:
            self.riser.add_loads(self.rhs[2], state)
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
        """2 (c_i - a_i) K tau_i on each field's right-hand side, where the matrix uses c_i
        instead of a_i: at a fixed point (d = tau) the equations are those of a_i."""
        n = self.mesh.n_local_nodes
        work, product = self._lagged_work
        for i, rhs in enumerate(self.rhs):
            factor = 2 * (self.matrix_split[i] - self.split[i])
            if factor == 0:
                continue
            for c, vec in enumerate(rhs.components):
                values = work.getArray()
                values[:n] = tau[:, i, c]
                values[n:] = 0.0
                self._stiffness.mult(work, product)
                vec.axpy(factor, product)

    def stiffness(self):
        """K = int g_k' g_l' dS on the P2 dofs (unit coefficient): the matrix of the
        lagged part and of the energy's gradient (iteration/newton.py), assembled on
        first use, once."""
        if self._stiffness is None:
            self._stiffness = assemble_matrix(
                self.mesh, p2_element_matrices(self.mesh.element_h, 1.0, 0.0))
        return self._stiffness

    def solve_centreline(self, state):
        """r' from its right-hand side rhs[2], bordered by r(L) - r(0) = int r' when both
        ends are held, then r at the vertices by integration. With a seabed the z slope
        is the vertical problem's (riser/terms.py), not solved here."""
        components = self._slope_components
        if self.bordered:
            chord = self.end_state.position - self.start_state.position
            state.chord_multiplier = self.slope_problem.solve_constrained(
                self.rhs[2], state.slope, chord, components)
        else:
            self.slope_problem.solve(self.rhs[2], state.slope, components)
        if self.riser is not None:
            self.riser.solve_vertical(self.rhs[2], state, self.bordered)
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
        positions = positions_from_increments(mesh, increments.T, self.start_state,
                                              self.end_state)
        for c, (r, slope) in enumerate(zip(state.r.components, state.slope.components)):
            values = r.getArray()
            values[0::2] = positions[:, c]
            values[1::2] = slope.getArray(readonly=True)[0::2]

    def load_work(self, state):
        """The work of the loads on the state, J: r(a).(applied forces) + int F.r' dS
        (centreline.anchor_work), less the seabed's stored energy (riser/seabed.py)."""
        work = self.anchor_work + sum(load.dot(slope) for load, slope
                                      in zip(self.load.components, state.slope.components))
        return work - (self.riser.energy() if self.riser is not None else 0.0)

    def end_reaction(self, state):
        """External force N on the rod at S = L, N: F(L) - mu (centreline.py), i.e. the
        dead force at a free end; -(int_0^L f dS + P_0) at a held end when the start is
        free; and -mu, the chord multiplier, when both ends are held."""
        return self.load_offset - state.chord_multiplier

    def _destroy_problems(self):
        for problem in self.problems:
            problem.destroy()
        self.problems = []

    def destroy(self):
        self._destroy_problems()
        if self.lags:
            for obj in self._lagged_work:
                obj.destroy()
        if self._stiffness is not None:
            self._stiffness.destroy()
        for obj in [*self.rhs, self.load]:
            obj.destroy()
        if self.riser is not None:
            self.riser.destroy()
