"""The second variation H of the discrete energy on the constraint set at a state: the
matrix a Newton step solves with (iteration/newton.py), the stability test factors
(analysis/stability.py) and a modal analysis would take with its mass M
(docs/method.md §10, §11).

At a converged state the nodal frames are rotations, d_n = tau_n, and a variation turns
each by a small rotation vector omega_n: delta d_i = omega x d_i, to second order
omega x (omega x d_i) / 2. With the discrete energy E = sum_i d_i^T K_{a_i} d_i - work and
its gradient at the solution, grad_{d_i} E = -w lambda_i (the global step's optimality
at d = tau; the reaction mu of a chord constraint is linear and drops out), the second
variation is

    H[omega, omega] = sum_i 2 (omega x d_i)^T K_{a_i} (omega x d_i)
                      - sum_n w_n sum_i lambda_{n,i} . (omega_n x (omega_n x d_{n,i}))

(K_{a_i} = a_i K, K the unit P2 stiffness, on a line of uniform stiffness; the matrix of
the coefficient a_i(S) where it varies, coefficients.FieldCoefficients)

on the omega with omega_n = 0 at a clamp and, when both ends are held,
sum_n w_n (omega_n x tau3_n) = 0 (the chord int r' dS stays fixed): the constraint,
kept as an orthonormal basis of its forms (``constraint``; in a Newton step's test
where K1 = K2, with the mean roll too: constrain_roll). The mass is the lumped
M = diag(w_n) on the rotations.

On an extensible line (docs/method.md §12) the unknowns of a node are (omega_n, k_n),
k = 1 + eps its stretch, 4 per node: the fields are g = (d1, d2, k d3), the energy is
E(g) + sum_n w_n EA_n eps_n^2 / 2, and a variation is delta g_i = omega x g_i +
delta_k d3 delta_i3, to second order omega x (omega x g_i) / 2 + delta_k omega x d3
delta_i3. So H gains the rows of k:

    H[omega_a, k_b] = 2 a3 K_ab (g3_a x d3_b) - w_a (d3_a x lambda3_a) delta_ab,
    H[k_a, k_b]     = 2 a3 K_ab d3_a.d3_b + w_a EA_a delta_ab   (AxialStretch.add_hessian),

and the chord forms the columns w_n d3_n of delta int r' dS. The stretch of a clamped
node (from the force balance, §12) and of a node with EA infinite is held: its row is
replaced by the identity, as a clamped rotation is.

A term whose energy depends on components of the node positions (the seabed on the
heights, the friction on the horizontal positions: Term.position_components) makes the
vertex positions u^c_i of those components and the multipliers nu^c_e of their chains
unknowns too (analysis/positions.py): one more unknown per node and component, u at a
vertex and nu at a midpoint. H is then the KKT matrix of the chains, whose inertia has
n_elements negative eigenvalues per component more than the second variation on the
rotations; they are counted off (analysis/stability.py), and the mass of the extra unknowns is 0 (a shift moves
the rotations' eigenvalues only). A load that
follows the line (the drag, Term.follower) adds three more per node, the resultants of
the Newton Jacobian (analysis/jacobian.py): identity rows here, H being the second
variation with that load held fixed.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.positions import HALF, HEIGHT, SIMPSON, slope_rows
from petsc_rod.mesh.elements import P2
from petsc_rod.mesh.fields import element_dofs
from petsc_rod.global_step.centreline import chains_from_start

# A negative eigenvalue of H / M counts when it is below -TOLERANCE max_i |H_ii| / M_ii
# (SecondVariation.tolerance): far above round-off, far below a buckling mode's.
TOLERANCE = 1e-9
# Chord forms whose Gram eigenvalue is below this fraction of the largest are dependent.
RANK_TOLERANCE = 1e-12


def unit(v):
    """v / |v| along the last axis (the unit tangent d3 of a stretched one k d3)."""
    return v / np.sqrt(np.einsum("...c,...c->...", v, v))[..., None]


def skew(v):
    """Cross-product matrices [v]x with [v]x w = v x w: (..., 3) -> (..., 3, 3)."""
    out = np.zeros(v.shape + (3,))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


class SecondVariation:
    """H of the module docstring at the state of a problem (problem/problem.py) at the
    last construction or ``update()``, as a PETSc matrix on the rotation vectors of the
    P2 nodes (3 per node, node n = 2 vertex + slot; 4 on an extensible line, the fourth
    the stretch k; ``unknowns`` of them, and, ``block`` in all, one more per component of
    the positions the terms read (u at a vertex, nu at a midpoint; slots
    ``position_slot``) and three more when a load follows the line (the resultants):
    module docstring), with its diagonal, the mass M (``mass``), the constraint's
    orthonormal forms (``constraint``) and the rows held (``held_rows``); the problem's
    terms add their own curvature (Term.add_hessian). What is computed from H (a
    factorisation: analysis/stability.py) hears of each change through
    ``_matrix_changed`` and ``_constraint_changed``. Collective; ``destroy()`` frees
    every PETSc object."""

    def __init__(self, problem, positions=(), newton=True):
        self.problem = problem
        mesh = problem.mesh
        self.comm = mesh.comm
        # unknowns per node: the rotation vector, and on an extensible line its stretch
        self.stretch = getattr(problem, "axial", None) is not None
        self.unknowns = 4 if self.stretch else 3
        # the positions' chains (analysis/positions.py) of the components the terms'
        # energies read (and ``positions``: the modes' mass, analysis/modes.py), one slot
        # each after the node's unknowns
        self.positions = tuple(sorted({c for term in problem.terms
                                       for c in term.position_components
                                       + (term.jacobian_positions if newton else ())}
                                      | set(positions)))
        self.position_slot = {c: self.unknowns + i for i, c in enumerate(self.positions)}
        # the resultants' chain of a load that follows the line (analysis/jacobian.py):
        # three slots per node, identity rows here (H is the frozen load's); not where H
        # serves no Newton step (``newton`` False: the modes, analysis/modes.py)
        self.resultants = newton and any(term.follower for term in problem.terms)
        self.resultant_slot = self.unknowns + len(self.positions)
        self.block = block = self.resultant_slot + 3 * int(self.resultants)
        # the chains' multipliers: negative eigenvalues of the KKT matrix beyond H's
        self.chain_constraints = mesh.n_elements * len(self.positions)
        n_local = block * mesh.n_local_nodes
        self.first_row = 2 * block * mesh.vertex_start
        self.matrix = PETSc.Mat().createAIJ(((n_local, None), (n_local, None)),
                                            nnz=(5 * block, 2 * block), comm=self.comm)
        self.matrix.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        self.held_rows = self._clamped_rows()
        # the resultants' rows: identities in H (added in _assemble, no zeroRowsColumns:
        # it costs seconds on ten thousand rows)
        nodes = self.first_row + block * np.arange(mesh.n_local_nodes)
        self.resultant_rows = ((nodes[:, None] + self.resultant_slot + np.arange(3)).ravel()
                               if self.resultants else np.zeros(0, dtype=int))
        self._diagonal = self.matrix.createVecLeft()
        self._reserved = not newton      # J's pattern in H (_assemble)
        # whether H's pattern is made (the first assembly): zeroEntries keeps it, so an
        # update adds no block of zeros (_add_blocks) and sets the resultants' identity
        # through the diagonal (_assemble)
        self._patterned = False
        self._identity = None
        # global columns whose H e_j before the held rows are cleared a caller asks for
        # at the next update (``full_columns``)
        self.keep_columns, self.kept_columns = (), []
        self.constraint = []
        self._fill()
        self.mass = self._mass()
        self._mass_or_one = self.mass.copy()           # M with 1 where it is 0
        ones = self._mass_or_one.getArray()
        ones[ones == 0.0] = 1.0
        self._work = self.mass.duplicate()

    def update(self):
        """H at the problem's current state, in the same matrix. Its nonzero pattern is
        the mesh's, so the factorisations that follow reuse MUMPS's analysis (the
        symbolic factorisation, most of a first factorisation's cost:
        docs/performance.md)."""
        self.matrix.zeroEntries()
        self._fill()

    def _fill(self):
        """Assemble H at the current state, with its diagonal and the chord constraint;
        the factorisation and the constraint solves of the previous H are stale."""
        self._matrix_changed()
        self._assemble()
        for vec in self.kept_columns:
            vec.destroy()
        self.kept_columns = [self._column(j) for j in self.keep_columns]
        self.matrix.zeroRowsColumns(self.held_rows, diag=1.0)
        self.matrix.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.matrix.getDiagonal(self._diagonal)
        for vec in self.constraint:
            vec.destroy()
        self.constraint = self._chord_columns() if self.problem.bordered else []
        # a taut, straight rod: the chord fixes the whole state and its forms are
        # dependent; the second variation says nothing there (no constraint
        # qualification), and the state is the only one the ends allow
        self.decidable = len(self.constraint) == 3 or not self.problem.bordered

    def full_columns(self, columns):
        """H e_j for the global ``columns`` (held ones: a clamped node's rotation) as H
        is before its held rows and columns become the identity, 0 on the held rows:
        how the gradient of the free unknowns moves when a held unknown is moved (a
        clamp's frame turned, system/held_line.py). New Vecs; assembles H again at the
        current state. Collective."""
        self.keep_columns = tuple(int(j) for j in columns)
        try:
            self.update()
        finally:
            self.keep_columns = ()
        kept, self.kept_columns = self.kept_columns, []
        return kept

    def _column(self, j):
        unit_vec = self.matrix.createVecRight()
        unit_vec.zeroEntries()
        low, high = unit_vec.getOwnershipRange()
        if low <= j < high:
            unit_vec.setValue(j, 1.0)
        unit_vec.assemble()
        column = self.matrix.createVecLeft()
        self.matrix.mult(unit_vec, column)
        unit_vec.destroy()
        self._zero_clamped(column)
        return column

    # --- assembly -------------------------------------------------------------------
    def _assemble(self):
        problem, mesh = self.problem, self.problem.mesh
        ne = mesh.n_local_elements
        # directors at the 3 nodes of each owned element, (ne, 3 nodes, 3 dirs, 3); the
        # ghost exchange is collective, also on a rank that owns no element
        d = np.stack([element_dofs(f.ghosted(), mesh.element_local, P2)
                      for f in problem.state.frame_fields], axis=2)
        B, U = self.block, self.unknowns
        if ne:
            # 2 a_i times the unit K, or each field's K_{2 a_i} along a line of sections
            weights, stiffness = problem.coefficients.hessian_stiffness()
            blocks = self._element_blocks(d, weights, stiffness)
            if self.stretch:                    # the slope's 2 a3 K, field 3's own
                third = stiffness[2] if np.ndim(stiffness) == 4 else stiffness
                blocks = self._stretch_blocks(d, weights[2], third, blocks)
            rows = (self.first_row + B * (2 * np.arange(ne)[:, None] + np.arange(3)[None, :]))
            rows = (rows[:, :, None] + np.arange(U)).reshape(ne, 3 * U).astype(PETSc.IntType)
            self.matrix.setValuesRCV(rows, rows, blocks.reshape(ne, 3 * U, 3 * U),
                                     addv=PETSc.InsertMode.ADD_VALUES)
        # the curvature of the constraint set: -w_n sum_i [sym(lambda_i d_i^T) - lambda_i.d_i I]
        tau, lam, w = problem.state.tau, problem.state.lam, problem.state.node_weights
        outer = np.matmul(lam.transpose(0, 2, 1), tau)        # sum_i lambda_i d_i^T
        dots = np.trace(outer, axis1=1, axis2=2)
        local = -w[:, None, None] * (0.5 * (outer + outer.transpose(0, 2, 1))
                                     - dots[:, None, None] * np.eye(3))
        if self.stretch:
            # (omega_n, k_n): -w_n d3_n x lambda3_n, d3 the unit tangent
            coupling = -w[:, None] * np.cross(unit(tau[:, 2]), lam[:, 2])
            local = np.concatenate([np.concatenate([local, coupling[:, :, None]], axis=2),
                                    np.concatenate([coupling[:, None, :],
                                                    np.zeros((len(w), 1, 1))], axis=2)],
                                   axis=1)
        rows = (self.first_row + B * np.arange(mesh.n_local_nodes)[:, None]
                + np.arange(U)).astype(PETSc.IntType)
        if rows.size:
            self.matrix.setValuesRCV(rows, rows, local, addv=PETSc.InsertMode.ADD_VALUES)
        if self.positions:
            self._add_chains(d)
        if self.resultants and not self._patterned:
            self._add_blocks(self.resultant_rows[:, None], self.resultant_rows[:, None],
                             np.ones((self.resultant_rows.size, 1, 1)))
        for term in problem.terms:
            term.add_hessian(self)
        if not self._reserved:
            # the Newton Jacobian's entries beyond H as zeros, kept by zeroEntries:
            # J is then a copy of H on its pattern (analysis/jacobian.py)
            for term in problem.terms:
                for rows, columns in term.jacobian_pattern(self):
                    self._add_blocks(rows, columns,
                                     np.zeros(rows.shape + columns.shape[1:]))
            self._reserved = True
        self.matrix.assemble()
        if not self._patterned:
            self._compact()
        if self.resultants and self._patterned:
            # the resultants' identity rows by the diagonal of the assembled matrix, in
            # place: one pass, where the same ones by blocks cost a search in each row
            self.matrix.setDiagonal(self._resultant_identity(),
                                    addv=PETSc.InsertMode.ADD_VALUES)
        self._patterned = True

    def _compact(self):
        """H in storage of its own pattern after the first assembly: the preallocation is
        a bound (every unknown of the 5 nodes of a node's elements, each slot a row),
        which PETSc keeps allocated beside the entries used, and the pattern is fixed
        from here on (``update``)."""
        compact = self.matrix.duplicate(copy=True)
        compact.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        self.matrix.destroy()
        self.matrix = compact

    def _resultant_identity(self):
        """A Vec of 1 on the resultants' rows and 0 elsewhere (made once)."""
        if self._identity is None:
            self._identity = self.matrix.createVecLeft()
            self._identity.zeroEntries()
            self._identity.getArray()[self.resultant_rows - self.first_row] = 1.0
        return self._identity

    # --- the positions' chains (module docstring, analysis/positions.py) -----------------
    def _add_chains(self, d):
        """Each chain's rows nu^c_e (u^c_e+1 - u^c_e - h_e SIMPSON.s^c_e = 0) and their
        transposes, from the fields d (ne, 3 nodes, 3 dirs, 3); keeps, per component, the
        midpoint's position as a row on (u^c_e, the element's unknowns) for
        position_blocks."""
        mesh, B, U = self.problem.mesh, self.block, self.unknowns
        ne = mesh.n_local_elements
        h = mesh.element_h
        nodes = self.first_row + B * (2 * np.arange(ne)[:, None] + np.arange(3)[None, :])
        unknowns = (nodes[:, :, None] + np.arange(U)).reshape(ne, 3 * U)
        self._midpoint_index, self._midpoint_rows = {}, {}
        for component, slot in self.position_slot.items():
            # the slopes' rows on the element's unknowns (ne, 3, U)
            rows = slope_rows(d[:, :, 2, :], self.stretch, component) if ne else \
                np.zeros((0, 3, U))
            ends = nodes[:, [0, 2]] + slot                          # u_e, u_e+1
            coefficients = np.concatenate([
                -np.ones((ne, 1)), np.ones((ne, 1)),
                (-h[:, None, None] * SIMPSON[None, :, None] * rows).reshape(ne, 3 * U)],
                axis=1)
            multiplier = (nodes[:, 1] + slot)[:, None]
            columns = np.concatenate([ends, unknowns], axis=1)
            self._midpoint_index[component] = np.concatenate([ends[:, :1], unknowns], axis=1)
            self._midpoint_rows[component] = np.concatenate(
                [np.ones((ne, 1)),
                 (h[:, None, None] * HALF[None, :, None] * rows).reshape(ne, 3 * U)], axis=1)
            if ne:
                self._add_blocks(multiplier, columns, coefficients[:, None, :])
                self._add_blocks(columns, multiplier, coefficients[:, :, None])
                # a 0 on nu's diagonal: in the pattern, so that a shift (setDiagonal)
                # adds no nonzero to the copy the factorisations were analysed for
                self._add_blocks(multiplier, multiplier, np.zeros((ne, 1, 1)))

    def _add_blocks(self, rows, columns, values):
        """Add ``values`` (k, len rows, len columns) at global ``rows`` (k, r) and
        ``columns`` (k, c). Once the pattern is made a block of zeros adds nothing and is
        left out (the seabed's curvature off the contact, the zeros that only reserve
        places): MatSetValues searches each of a block's rows."""
        if self._patterned:
            kept = np.any(values != 0.0, axis=(1, 2))
            if not kept.all():
                rows, columns, values = rows[kept], columns[kept], values[kept]
            if not len(rows):
                return
        self.matrix.setValuesRCV(rows.astype(PETSc.IntType), columns.astype(PETSc.IntType),
                                 values, addv=PETSc.InsertMode.ADD_VALUES)

    def position_blocks(self, values, rows, columns):
        """The entries sum_ij values[n, i, j] delta x^{rows_i}_n delta x^{columns_j}_n of a
        second derivative in the node positions, ``values`` (n_nodes, len rows, len
        columns) at the owned nodes (rows and columns: components among ``positions``),
        as (rows, columns, blocks) triples for an add (this matrix's, or the Newton
        Jacobian's): at a vertex on its u's; at a midpoint, whose position is
        u_e + h_e HALF.s_e, outer products of those rows on (u_e, the element's
        unknowns). Needs the chains of the last assembly (_add_chains)."""
        values = np.asarray(values, dtype=float)
        mesh, B = self.problem.mesh, self.block
        ne = mesh.n_local_elements
        vertices = self.first_row + B * np.arange(0, values.shape[0], 2)
        triples = [(vertices[:, None] + np.array([self.position_slot[a] for a in rows]),
                    vertices[:, None] + np.array([self.position_slot[b] for b in columns]),
                    values[0::2])]
        if ne:
            middle = values[1:2 * ne:2]
            for i, a in enumerate(rows):
                for j, b in enumerate(columns):
                    triples.append((self._midpoint_index[a], self._midpoint_index[b],
                                    middle[:, i, j, None, None]
                                    * self._midpoint_rows[a][:, :, None]
                                    * self._midpoint_rows[b][:, None, :]))
        return [t for t in triples if t[0].size]

    def midpoint_row(self, component):
        """The midpoint's position of ``component`` as a row on (u_e, the element's
        unknowns), (ne, 1 + 3 U), per owned element: u_e + h_e HALF.s_e at the last
        assembly (a term's Jacobian entries in the positions, physics/drag.py)."""
        return self._midpoint_rows[component]

    def add_position_curvature(self, values, components):
        """Add a position energy's second derivative (module docstring of positions.py),
        ``values`` (n_nodes, m, m) in the ``components`` (m,) of the owned nodes' positions,
        N/m (Term.add_hessian, before assembly)."""
        for rows, columns, blocks in self.position_blocks(values, components, components):
            self._add_blocks(rows, columns, blocks)

    def position_shift(self, values, component, held=False):
        """The Vec sum_n values_n dx^c_n/dy of the owned nodes' ``values`` (n_nodes,)
        (a position energy's second derivative, N/m) times the derivative of component c
        of node n's position in the unknowns y: at a vertex its u^c, at a midpoint the
        row of u^c_e + h_e HALF.s^c_e (position_blocks). It is d(gradient)/d(shift):
        how the gradient of that energy moves when every position of component c is
        shifted by 1 m (the held end moved, system/held_line.py); 0 on held rows
        (``held``: kept there, for a held unknown's share). Needs the chains of the last
        assembly. Collective."""
        values = np.asarray(values, dtype=float)
        vec = self.matrix.createVecLeft()
        vec.zeroEntries()
        slot = self.position_slot[component]
        vertices = self.first_row + self.block * np.arange(0, values.shape[0], 2) + slot
        ne = self.problem.mesh.n_local_elements
        rows = [vertices]
        entries = [values[0::2]]
        if ne:
            rows.append(self._midpoint_index[component].ravel())
            entries.append((values[1:2 * ne:2, None]
                            * self._midpoint_rows[component]).ravel())
        vec.setValues(np.concatenate(rows).astype(PETSc.IntType), np.concatenate(entries),
                      addv=PETSc.InsertMode.ADD_VALUES)
        vec.assemble()
        if not held:
            self._zero_clamped(vec)
        return vec

    def add_height_curvature(self, curvature):
        """Add a height energy's second derivative d2E/dz_n^2 (n_nodes,), N/m, at the owned
        nodes (add_position_curvature of the heights alone)."""
        self.add_position_curvature(np.asarray(curvature, dtype=float)[:, None, None],
                                    (HEIGHT,))

    @staticmethod
    def _element_blocks(d, weights, stiffness):
        """The element blocks of the bending and torsion part of H, (ne, 3, 3, 3, 3)
        indexed (node a, component s, node b, component t):
        sum_i weights_i K_ab ([d_a,i]x^T [d_b,i]x)_st with [u]x^T [v]x = (u.v) I - v u^T,
        for directors d (ne, node, director i, 3) and element matrices K (ne, 3, 3):
        with P_ab = sum_i weights_i d_b,i d_a,i^T (3 x 3, one batched product of the
        nodes' director matrices), K_ab (tr(P_ab) I - P_ab) (cheaper than an einsum over
        the cross-product matrices, and than a broadcast product per director:
        docs/performance.md). Element matrices (3, ne, 3, 3), one K_i per field (a
        stiffness varying along the line): sum_i weights_i K_i,ab (...)_st."""
        if np.ndim(stiffness) == 4:
            return sum(SecondVariation._element_blocks(d[:, :, i:i + 1], weights[i:i + 1],
                                                       stiffness[i]) for i in range(3))
        weighted = d * np.asarray(weights, dtype=float)[None, None, :, None]
        # P[e, a, b, s, t] = sum_i weights_i d_b,i[s] d_a,i[t]
        products = np.matmul(weighted.transpose(0, 1, 3, 2)[:, None], d[:, :, None])
        traces = np.trace(products, axis1=3, axis2=4)                    # (ne, a, b)
        blocks = np.negative(products.transpose(0, 1, 3, 2, 4))           # (ne, a, s, b, t)
        for s in range(3):
            blocks[:, :, s, :, s] += traces
        blocks *= stiffness[:, :, None, :, None]
        return blocks

    @staticmethod
    def _stretch_blocks(d, weight, stiffness, blocks):
        """The element blocks with the stretch rows, (ne, 3, 4, 3, 4), from those of the
        rotations ``blocks`` (ne, 3, 3, 3, 3): weight K_ab (g3_a x d3_b) in (omega_a, k_b),
        its transpose, and weight K_ab d3_a.d3_b in (k_a, k_b), weight = 2 a3, for the
        fields d (ne, node, director i, 3) whose third row is g3 = k d3."""
        ne = d.shape[0]
        g3 = d[:, :, 2, :]                                            # (ne, node, 3)
        d3 = unit(g3)
        out = np.zeros((ne, 3, 4, 3, 4))
        out[:, :, :3, :, :3] = blocks
        cross = np.cross(g3[:, :, None, :], d3[:, None, :, :])        # (ne, a, b, 3)
        coupling = weight * stiffness[:, :, :, None] * cross
        out[:, :, :3, :, 3] = coupling.transpose(0, 1, 3, 2)
        out[:, :, 3, :, :3] = coupling.transpose(0, 2, 1, 3)
        out[:, :, 3, :, 3] = weight * stiffness * np.matmul(d3, d3.transpose(0, 2, 1))
        return out

    def add_strain_diagonal(self, values):
        """Add values (n_nodes,) to the diagonal of the stretch rows (a term's curvature
        in k, AxialStretch.add_hessian), before assembly."""
        rows = (self.first_row + self.block * np.arange(len(values)) + 3)[:, None]
        if rows.size:
            rows = rows.astype(PETSc.IntType)
            self.matrix.setValuesRCV(rows, rows, np.asarray(values, float)[:, None, None],
                                     addv=PETSc.InsertMode.ADD_VALUES)

    def _clamped_rows(self):
        """Global rows of the rotation vectors at clamped nodes (and, on an extensible
        line, of the stretch held there and where EA is infinite; with the positions'
        chains, of the positions at the held end). A clamped node's chain unknowns (u,
        nu, the resultants) are not held: the chains run through it."""
        nodes = np.flatnonzero(~self.problem.free_nodes)
        B = self.block
        rows = (self.first_row + B * nodes[:, None] + np.arange(self.unknowns)).ravel()
        if self.stretch:
            held = np.flatnonzero(~np.isfinite(self.problem.axial) & self.problem.free_nodes)
            rows = np.sort(np.concatenate([rows, self.first_row + B * held + 3]))
        if self.positions:
            # the position at the chains' origin (the start's, else the end's:
            # centreline.chains_from_start) is held: u_a = 0
            mesh, problem = self.problem.mesh, self.problem
            if chains_from_start(problem.state, problem.start_state, problem.end_state):
                anchor = [0] if mesh.on_lower_boundary else []
            else:
                anchor = [mesh.n_local_nodes - 1] if mesh.on_upper_boundary else []
            slots = np.array(list(self.position_slot.values()))
            pins = (self.first_row + B * np.array(anchor, dtype=int)[:, None]
                    + slots[None, :]).ravel()
            rows = np.sort(np.concatenate([rows, pins]))
        return rows.astype(PETSc.IntType)

    def chord_forms(self, tangents):
        """The 3 linear forms omega -> sum_n w_n (omega_n x t_n)_k, the first variation of
        the chord int r' dS at tangents t (n_nodes, 3), as Vecs (zero at clamped rows);
        on an extensible line t = k d3 and the forms have the stretch columns
        delta_k -> sum_n w_n delta_k_n d3_n."""
        w = self.problem.state.node_weights
        forms = -w[:, None, None] * skew(tangents)                     # (n, k, 3)
        if self.stretch:
            forms = np.concatenate([forms, (w[:, None] * unit(tangents))[:, :, None]],
                                   axis=2)                              # (n, k, 4)
        if self.block > self.unknowns:                   # 0 on u, nu and the resultants
            forms = np.concatenate([forms, np.zeros(forms.shape[:2]
                                                    + (self.block - self.unknowns,))], axis=2)
        columns = []
        for k in range(3):
            vec = self.matrix.createVecLeft()
            vec.getArray()[:] = forms[:, k, :].ravel()
            self._zero_clamped(vec)
            columns.append(vec)
        return columns

    def constrain_roll(self, tangents):
        """Add the mean roll omega -> sum_n w_n omega_n . t_n / |t_n| (tangents t
        (n_nodes, 3)) to the constraints of the inertia test, until the next update: where
        K1 = K2 all along and nothing is clamped, turning every section by one angle about
        its tangent is a null vector of H (the free roll, which the Newton steps leave
        out), and an iterate's multipliers make its eigenvalue slightly negative
        (docs/method.md §11, "The free roll")."""
        self._constraint_changed()
        self.constraint = self._independent(self.constraint + [self.roll_form(tangents)])

    def roll_form(self, tangents):
        """The mean roll omega -> sum_n w_n omega_n . t_n / |t_n| at tangents t (n_nodes,
        3), as a new Vec (zero at clamped rows and off the rotations)."""
        w = self.problem.state.node_weights
        vec = self.to_vec(np.concatenate(
            [w[:, None] * unit(tangents), np.zeros((len(w), self.unknowns - 3))], axis=1))
        self._zero_clamped(vec)
        return vec

    def _chord_columns(self):
        """An orthonormal basis of the chord forms at tau3 (the constraint of the test)."""
        return self._independent(self.chord_forms(self.problem.state.tau[:, 2]))

    @staticmethod
    def _independent(columns):
        """An orthonormal basis of the span of ``columns`` (Vecs): a straight rod's chord
        form along its own axis vanishes, and the inertia formula needs independent
        constraints."""
        gram = np.array([[a.dot(b) for b in columns] for a in columns])
        values, vectors = np.linalg.eigh(gram)
        keep = values > RANK_TOLERANCE * max(values.max(), np.finfo(float).tiny)
        basis = []
        for value, coefficients in zip(values[keep], vectors.T[keep]):
            vec = columns[0].duplicate()
            vec.zeroEntries()
            vec.maxpy(coefficients / np.sqrt(value), columns)
            basis.append(vec)
        for vec in columns:
            vec.destroy()
        return basis

    def _mass(self):
        """The lumped mass diag(w_n) on each rotation component (0 at the clamped rows,
        whose unit diagonal no shift moves), as a Vec."""
        vec = self.matrix.createVecLeft()
        mass = np.zeros((self.problem.mesh.n_local_nodes, self.block))
        mass[:, :self.unknowns] = self.problem.state.node_weights[:, None]
        vec.getArray()[:] = mass.ravel()
        self._zero_clamped(vec)
        return vec

    def hold_roll(self, tangents):
        """Add P w_n t_n t_n^T to each free node's rotation block (t_n the unit tangent at
        tangents (n_nodes, 3), P = max_i |H_ii| / M_ii, the scale of ``tolerance``), until
        the next update: each section's turn about its own tangent held, so that the
        inertia test and the solves are those of the bending (docs/stability.md, "The
        hanging chain"). Collective."""
        t = unit(tangents)
        scale = self.tolerance() / TOLERANCE
        w = self.problem.state.node_weights * self.problem.free_nodes
        blocks = np.zeros((len(w), self.unknowns, self.unknowns))
        blocks[:, :3, :3] = scale * w[:, None, None] * np.einsum("nk,nl->nkl", t, t)
        rows = (self.first_row + self.block * np.arange(len(w))[:, None]
                + np.arange(self.unknowns)).astype(PETSc.IntType)
        if rows.size:
            self.matrix.setValuesRCV(rows, rows, blocks, addv=PETSc.InsertMode.ADD_VALUES)
        self.matrix.assemble()
        self._matrix_changed()

    def to_vec(self, values):
        """A new Vec from the nodes' unknowns ``values`` (n_nodes, unknowns), 0 on u, nu."""
        vec = self.matrix.createVecLeft()
        array = vec.getArray().reshape(-1, self.block)
        array[:] = 0.0
        array[:, :self.unknowns] = values
        return vec

    def from_vec(self, vec):
        """The nodes' unknowns (n_nodes, unknowns) of a Vec (u, nu left out), a copy."""
        return vec.getArray(readonly=True).reshape(-1, self.block)[:, :self.unknowns].copy()

    def zero_held(self, vec):
        """``vec`` set to 0 on the held rows (J's identity rows drop a term's entries
        there too)."""
        self._zero_clamped(vec)

    def _zero_clamped(self, vec):
        local = self.held_rows - self.first_row
        vec.getArray()[local] = 0.0

    def tolerance(self):
        """TOLERANCE times max_i |H_ii| / M_ii: an eigenvalue of H / M above -tolerance
        is zero to round-off (the free roll of a section with K1 = K2 between pins)."""
        self._work.pointwiseDivide(self._diagonal, self._mass_or_one)
        # the rotations' rows: EA w on the stretch rows, or the seabed's k w on the
        # heights, is no scale of a buckling mode
        ratios = np.abs(self._work.getArray(readonly=True).reshape(-1, self.block)[:, :3])
        return TOLERANCE * self.problem.mesh.global_max(float(ratios.max(initial=0.0)))

    def _matrix_changed(self):
        """H has changed (an update, a held roll): nothing to do here; a factorisation of
        it is stale (StabilityTest)."""

    def _constraint_changed(self):
        """The constraint's forms are about to change (the mean roll added): nothing to do
        here; solves for the old ones are stale (StabilityTest)."""

    def destroy(self):
        for obj in [self.matrix, self.mass, self._mass_or_one, self._work, self._diagonal,
                    *self.constraint, *self.kept_columns,
                    *([self._identity] if self._identity is not None else [])]:
            obj.destroy()
