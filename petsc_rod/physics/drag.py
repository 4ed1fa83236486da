"""Morison drag of a steady current on the line, normal component only (docs/riser.md).

Per metre of line with unit tangent t, in a current v (m/s):

    f = c |v_n| v_n,   v_n = v - (v.t) t,   c = rho C_d D / 2  (kg/m^2; f in N/m).

The tangential (skin friction) drag is not modelled. The drag follows the line: it is
evaluated at the deformed state, lagged by one iteration (DragTerm). Its derivative in a
turn omega of the tangent, delta t = omega x t, is (drag_jacobian)

    delta f = c (|v_n| I + v_n v_n^T / |v_n|) (t v^T + (v.t) I) [t]x omega

(delta v_n = -(t v^T + (v.t) I) delta t; f is C^1 with zero derivative where v_n = 0).

The drag as a term of physics (DragTerm) enters the slope problem's right-hand side
like a dead load (global_step/nodal_loads.py), evaluated at the tangents tau3 of the
iterate x = (tau, lambda / R) that the SNES mixes and at the heights of the last global
step (for a current profile), times the weight the scene's path gives its current at the
load factor t (Scene.drag_loads: t itself; on a restart's blended path two currents,
scenes/blend.py): a function of the iterate, so that Anderson mixing sees it. It has no
energy (a follower load). It is in the Newton steps as a follower (Term.follower): its
gradient -b on the d3 rows at the frames' tangents, and its linearisation in the
unsymmetric Newton Jacobian through the resultants' chain (analysis/jacobian.py).
"""

import numpy as np

from petsc4py import PETSc

from petsc_rod.analysis.positions import HEIGHT
from petsc_rod.analysis.second_variation import skew
from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.global_step.seabed_contact import node_rows
from petsc_rod.mesh.elements import P2, element_integrals
from petsc_rod.mesh.fields import element_dofs
from petsc_rod.physics.nodal_load import NodalLoadTerm
from petsc_rod.scenes.boundary import is_held


def normal_drag(tangent, velocity, drag):
    """f = c |v_n| v_n, (n, 3) N/m, for tangents (n, 3) (normalised here), current
    velocities (n, 3) m/s and c = ``drag`` (kg/m^2)."""
    t = _unit(tangent)
    normal = velocity - np.einsum("nc,nc->n", velocity, t)[:, None] * t
    return drag * np.sqrt(_squares(normal))[:, None] * normal


def drag_jacobian(tangent, velocity, drag):
    """G, (n, 3, 3): the derivative of normal_drag in a turn omega of each tangent,
    delta f = G omega (module docstring), for tangents (n, 3) (normalised here), current
    velocities (n, 3) m/s and c = ``drag`` (n,) kg/m^2."""
    t = _unit(tangent)
    along = np.einsum("nc,nc->n", velocity, t)
    normal = velocity - along[:, None] * t
    speed = np.linalg.norm(normal, axis=1)
    unit_normal = np.divide(normal, speed[:, None], out=np.zeros_like(normal),
                            where=speed[:, None] > 0)
    eye = np.eye(3)[None]
    stiffness = np.asarray(drag, dtype=float).reshape(-1)[:, None, None] * (
        speed[:, None, None] * eye + speed[:, None, None]
        * unit_normal[:, :, None] * unit_normal[:, None, :])
    turn = t[:, :, None] * velocity[:, None, :] + along[:, None, None] * eye
    return stiffness @ turn @ skew(t)


def drag_height_derivative(tangent, velocity, rate, drag):
    """df/dz, (n, 3) N/m^2: the derivative of normal_drag in the height of its node,
    through the current's rate dv/dz ``rate`` (n, 3) 1/s (Current.height_derivative):
    c (|v_n| I + v_n v_n^T / |v_n|) (I - t t^T) dv/dz, for tangents (n, 3) (normalised
    here), velocities (n, 3) m/s and c = ``drag`` (n,) kg/m^2."""
    t = _unit(tangent)
    normal = velocity - np.einsum("nc,nc->n", velocity, t)[:, None] * t
    speed = np.sqrt(_squares(normal))
    dv_n = rate - np.einsum("nc,nc->n", rate, t)[:, None] * t
    along = np.divide(np.einsum("nc,nc->n", normal, dv_n), speed, out=np.zeros_like(speed),
                      where=speed > 0)
    return np.asarray(drag, dtype=float).reshape(-1)[:, None] * (
        speed[:, None] * dv_n + along[:, None] * normal)


def _unit(tangent):
    """The unit tangents of rows (n, 3), 0 where a row is 0: a node that the stretched
    local step compressed to a point (k = 0, docs/method.md §12) has no direction, and
    the whole current is normal to it (its drag is then finite, and its derivative 0)."""
    length = np.sqrt(_squares(tangent))[:, None]
    return np.divide(tangent, length, out=np.zeros_like(tangent, dtype=float),
                     where=length > 0)


def _squares(vectors):
    """|v|^2 of rows (n, 3): an einsum, a third of np.linalg.norm's passes (once per
    iteration at every node with a current)."""
    return np.einsum("nc,nc->n", vectors, vectors)


class DragTerm(NodalLoadTerm):
    """The Morison normal drag of a steady current (environment.Current) on the line, a
    follower load of the iterate (module docstring); in the Newton steps through its
    linearisation (analysis/jacobian.py)."""

    conservative = False
    follower = unsymmetric = jacobian_reserved = True

    def __init__(self, mesh, scene, surface=None):
        super().__init__(mesh, "drag")
        self.scene = scene
        # a line that reaches the sea surface (SurfaceTerm): the drag on the part of
        # each section under it only
        self.surface = surface
        self.drag = NodalLoad(mesh, self._nodes)
        self._node_S = mesh.node_S()            # where each node's section's drag applies
        # a current that varies with depth: its drag reads the heights, whose chain the
        # Newton Jacobian then carries (add_jacobian)
        self.jacobian_positions = ((HEIGHT,) if any(c.depths.size > 1 for _, c
                                                     in scene.drag_loads(1.0)) else ())

    def node_loads(self, state, tangents=None):
        """sum_k w_k c_k |v_n,k| v_n,k at the owned nodes (N/m), (n_nodes, 3), over the
        (weight, current) pairs of scene.drag_loads(t) (w = t for one current), from the
        tangents tau3 (or ``tangents``, (n_nodes, 3)) and, for a current that varies with
        depth, the heights of the last global step. Collective when one does (a ghost
        exchange)."""
        currents = self.scene.drag_loads(self.t)
        z = (state.node_positions()[:, 2] if any(c.depths.size > 1 for _, c in currents)
             else np.zeros(self.mesh.n_local_nodes))
        tangents = state.tau[:, 2] if tangents is None else tangents
        loads = sum(w * normal_drag(tangents, c.velocity(z),
                                    self.scene.drag_at(self._node_S, c)[:, None])
                    for w, c in currents)
        if self.surface is not None:
            loads = loads * (1.0 - self.surface.dry(state))[:, None]
        return loads

    def add_gradient(self, g, state):
        """-b on the d3 rows, b = int F.g dS of the drag at the fields' tangents (the
        frames, in the Newton steps) and the heights of their centreline
        (RodProblem.energy_gradient integrates it). Collective."""
        self.drag.set(self.node_loads(state, state.node_directors()[:, 2].copy()))
        g[:, 2, :] -= self.load_vector(self.drag)[:g.shape[0]]

    def add_jacobian(self, jacobian):
        """The drag's entries of J (analysis/jacobian.py module docstring): the frames'
        rows on the resultants and on the element's turns, and the resultants' chain, at
        the fields' tangents and heights; in a current that varies with depth, the same
        rows on the heights' chain too (delta f_l = (df/dz)_l dz_l, dz_l a vertex's u or
        a midpoint's u_e + h_e HALF.s_e: analysis/positions.py), so that J is exact on a
        sheared current."""
        parts = self._linearisation(jacobian.hessian, jacobian.problem.state)
        if parts is None:
            return
        x_rows, turns, psi, row, other, rows_map, integrals, tails, G, heights = parts
        ne, U = len(x_rows), jacobian.hessian.unknowns
        # the frames' rows on the element's turns and on the far vertex's resultants (and
        # the heights), in one block per element, the columns of _jacobian_blocks:
        # rows_map_a tails_ab G_b for each node pair (a, b), (ne, a, b, U, 3), by a
        # batched matmul (a three-operand einsum loops over every index:
        # docs/performance.md), then in the order of the rows (a, U) and columns (b, 3)
        coupling = np.matmul(rows_map[:, :, None], G[:, None])
        coupling *= tails[:, :, :, None, None]
        frames = [coupling.transpose(0, 1, 3, 2, 4).reshape(ne, 3 * U, 9),
                  (rows_map * integrals[:, :, None, None]).reshape(ne, 3 * U, 3)]
        # the chain: Psi_e - Psi_e+1 - sum_l I_l G_l omega_l = 0 in Psi_e's row from a
        # held start, its negative in Psi_e+1's from a held end (the diagonal 1 is H's)
        sign = -1.0 if is_held(self.start_state) else 1.0
        chain = [sign * np.einsum("eb,ebjk->ejbk", integrals, G).reshape(ne, 3, 9),
                 np.broadcast_to(-np.eye(3), (ne, 3, 3))]
        columns = [turns, psi[:, 1]], [turns, other]
        if heights is not None:
            height_columns, frames_rows, chain_rows, Z = heights
            frames.append(np.matmul(frames_rows, Z))
            chain.append(np.matmul(chain_rows, Z))
            for kept in columns:
                kept.append(height_columns)
        jacobian.add(x_rows, np.concatenate(columns[0], axis=1),
                     np.concatenate(frames, axis=2))
        jacobian.add(row, np.concatenate(columns[1], axis=1), np.concatenate(chain, axis=2))

    def add_hessian(self, hessian):
        """No curvature (the drag has no energy); where the heights' chain is for the
        drag's Jacobian alone, zeros on its diagonal, so that a shift of H
        (analysis/stability.py) meets no new nonzero there."""
        if self.jacobian_positions and HEIGHT in hessian.position_slot:
            hessian.add_height_curvature(np.zeros(self.mesh.n_local_nodes))

    def height_shift(self, hessian, state):
        """The Vec d(residual)/dz_0 of the drag: every node's height raised by 1 m (the
        held start moved up, system/held_line.py), delta f_l = (df/dz)_l on the frames'
        rows and the resultants' chain as in add_jacobian; None where the current does
        not vary with depth. Collective."""
        if not self.jacobian_positions:
            return None
        parts = self._linearisation(hessian, state)
        vec = hessian.matrix.createVecLeft()
        vec.zeroEntries()
        if parts is not None:
            x_rows, row, heights = parts[0], parts[3], parts[-1]
            _, frames_rows, chain_rows, _ = heights
            vec.setValues(np.concatenate([x_rows.ravel(), row.ravel()]).astype(PETSc.IntType),
                          np.concatenate([frames_rows.sum(axis=2).ravel(),
                                          chain_rows.sum(axis=2).ravel()]),
                          addv=PETSc.InsertMode.ADD_VALUES)
        vec.assemble()
        hessian.zero_held(vec)
        return vec

    def turn_columns(self, hessian, state, columns):
        """The drag's entries of J in the global ``columns`` (a held node's rotation:
        a clamp's, which its turn moves, system/held_line.py), one new Vec each, 0 on
        the held rows: the frames' rows' coupling and the resultants' chain of
        add_jacobian in those columns. Collective."""
        parts = self._linearisation(hessian, state)
        vecs = []
        for column in columns:
            vec = hessian.matrix.createVecLeft()
            vec.zeroEntries()
            if parts is not None:
                x_rows, turns, _, row, _, rows_map, integrals, tails, G, _ = parts
                ne, U = len(x_rows), hessian.unknowns
                elements, slots = np.nonzero(turns == column)
                for e, slot in zip(elements, slots):
                    b, k = divmod(int(slot), 3)
                    # rows_map_a tails_ab G_b e_k on the frames' rows, and the chain's
                    # sign I_b G_b e_k (add_jacobian)
                    frames = (np.matmul(rows_map[e], G[e, b][:, k]) * tails[e, :, b, None])
                    sign = -1.0 if is_held(self.start_state) else 1.0
                    chain = sign * integrals[e, b] * G[e, b][:, k]
                    vec.setValues(np.concatenate([x_rows[e], row[e]]).astype(PETSc.IntType),
                                  np.concatenate([frames.reshape(3 * U), chain]),
                                  addv=PETSc.InsertMode.ADD_VALUES)
            vec.assemble()
            hessian.zero_held(vec)
            vecs.append(vec)
        return vecs

    def _linearisation(self, hessian, state):
        """The pieces of add_jacobian at ``state`` on ``hessian``'s layout, per owned
        element (None where this rank owns none): its indices (_jacobian_indices), the
        frames' rows of -delta b (ne, 3, U, 3), the node integrals I (ne, 3), the tails
        T (ne, 3, 3), the turns' G (ne, 3, 3, 3), and in a sheared current the heights'
        (columns (ne, 2 + 3 U): u_e, u_e+1, the element's unknowns; the frames' rows
        sum_b tails_ab rows_map_a (df/dz)_b (ne, 3 U, 3 nodes); the chain's
        sign I_b (df/dz)_b (ne, 3, 3 nodes); Z (ne, 3 nodes, 2 + 3 U) each node's height
        as a row on those columns), else None."""
        mesh = self.mesh
        ne = mesh.n_local_elements
        if not ne:
            return None
        U = hessian.unknowns
        x_rows, turns, psi, row, other = self._jacobian_indices(hessian)
        tangents = element_dofs(state.slope.ghosted(), mesh.element_local, P2)   # (ne, 3, 3)
        h = mesh.element_h
        r = state.r.ghosted()[:, :, 2]                     # Hermite (z, z') at the vertices
        z = np.einsum("enk,ek->en", node_rows(h),
                      np.concatenate(mesh.element_ends(r), axis=1))      # (ne, 3 nodes)
        S = mesh.element_S[:, None] + h[:, None] * np.array([0.0, 0.5, 1.0])
        flat_t = tangents.reshape(-1, 3)
        currents = self.scene.drag_loads(self.t)
        G = sum(w * drag_jacobian(flat_t, c.velocity(z.ravel()),
                                  self.scene.drag_at(S.ravel(), c))
                for w, c in currents).reshape(ne, 3, 3, 3)
        # the frames' rows of -delta b: -[t]x on omega, -t/|t| on the stretch
        rows_map = -skew(tangents)                                               # (ne, a, 3, 3)
        if U == 4:
            unit = tangents / np.linalg.norm(tangents, axis=2, keepdims=True)
            rows_map = np.concatenate([rows_map, -unit[:, :, None, :]], axis=2)  # (ne, a, 4, 3)
        integrals = element_integrals(h)                                         # (ne, 3)
        tails = self.drag.tail_integrals                                         # (ne, a, b)
        heights = None
        if self.jacobian_positions:
            D = sum(w * drag_height_derivative(flat_t, c.velocity(z.ravel()),
                                               c.height_derivative(z.ravel()),
                                               self.scene.drag_at(S.ravel(), c))
                    for w, c in currents).reshape(ne, 3, 3)                     # (ne, b, 3)
            sign = -1.0 if is_held(self.start_state) else 1.0
            # rows_map_a (df/dz)_b tails_ab: (ne, a, U, b)
            frames_rows = (np.matmul(rows_map, D.transpose(0, 2, 1)[:, None])
                           * tails[:, :, None, :]).reshape(ne, 3 * U, 3)
            chain_rows = sign * (integrals[:, None, :] * D.transpose(0, 2, 1))  # (ne, 3, b)
            slot = hessian.position_slot[HEIGHT]
            middle = hessian.midpoint_row(HEIGHT)                               # (ne, 1 + 3 U)
            Z = np.zeros((ne, 3, 2 + 3 * U))
            Z[:, 0, 0] = Z[:, 2, 1] = 1.0
            Z[:, 1, 0] = middle[:, 0]
            Z[:, 1, 2:] = middle[:, 1:]
            heights = (self._height_columns(x_rows, slot, U), frames_rows, chain_rows, Z)
        return x_rows, turns, psi, row, other, rows_map, integrals, tails, G, heights

    def _jacobian_indices(self, hessian):
        """The global rows and columns of add_jacobian's blocks, per owned element (ne):
        the frames' rows of its three nodes (ne, 3 U), their turns (ne, 9), the
        resultants at its two vertices (ne, 2, 3), and the chain's rows and the other
        vertex's resultants (ne, 3) each (Psi_e's row from a held start, Psi_e+1's from
        a held end)."""
        ne = self.mesh.n_local_elements
        B, U, P = hessian.block, hessian.unknowns, hessian.resultant_slot
        base = hessian.first_row + B * (2 * np.arange(ne)[:, None] + np.arange(3)[None, :])
        x_rows = (base[:, :, None] + np.arange(U)).reshape(ne, 3 * U)
        turns = (base[:, :, None] + np.arange(3)).reshape(ne, 9)
        psi = base[:, [0, 2]][:, :, None] + P + np.arange(3)                     # (ne, 2, 3)
        row, other = (psi[:, 0], psi[:, 1]) if is_held(self.start_state) else \
            (psi[:, 1], psi[:, 0])
        return x_rows, turns, psi, row, other

    @staticmethod
    def _height_columns(x_rows, slot, unknowns):
        """The columns of the heights' entries per element, (ne, 2 + 3 U): u at its
        two vertices (their first row plus the heights' ``slot``), then its nodes'
        unknowns (``x_rows``)."""
        first = x_rows[:, ::unknowns]                       # each node's first row
        return np.concatenate([first[:, [0, 2]] + slot, x_rows], axis=1)

    def jacobian_pattern(self, hessian):
        """add_jacobian's blocks (Term.jacobian_pattern)."""
        if not self.mesh.n_local_elements:
            return []
        x_rows, turns, psi, row, other = self._jacobian_indices(hessian)
        columns = [turns, psi[:, 1]], [turns, other]
        if self.jacobian_positions:
            heights = self._height_columns(x_rows, hessian.position_slot[HEIGHT],
                                           hessian.unknowns)
            for kept in columns:
                kept.append(heights)
        # one block per row set: MatSetValues searches each row of a block once
        return [(x_rows, np.concatenate(columns[0], axis=1)),
                (row, np.concatenate(columns[1], axis=1))]

    def add_iterate_load(self, rhs, state):
        """Add the drag's int F.g to the slope problem's right-hand side."""
        self.drag.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.drag)
