"""The seabed and the drag as terms of physics (physics/term.py; docs/riser.md), built
only for a scene that has them (problem/build.py).

* The seabed is part of the global step: the z slope is solved in Hermite dofs with the
  contact by an active-set loop (hermite.py, seabed.py) in place of the z component of
  the P2 solve (which then solves x and y only); when both ends are held, the z part of
  the chord multiplier is that problem's residual at z(L).
* The drag enters the slope problem's right-hand side like a dead load (loads.py),
  evaluated at the tangents tau3 of the iterate x = (tau, lambda / R) that the SNES
  mixes and at the heights of the last global step (for a current profile), times the
  weight the scene's path gives its current at the load factor t (Scene.drag_loads: t
  itself; on a restart's blended path two currents, scenes/blend.py): a function of the
  iterate, so that Anderson mixing sees it. It has no energy (a follower load).

The seabed is in the Newton steps (docs/method.md §11): its energy is a function of the
node heights, so its gradient in the slopes is the adjoint of their integral
(analysis/positions.position_gradient) and its curvature k w_n on the active nodes enters
the Newton system through the heights' chain (SecondVariation.add_height_curvature): a
semi-smooth Newton step, the active set that of the iterate. The drag is in them as a
follower (Term.follower): its gradient -b on the d3 rows at the frames' tangents, and its
linearisation in the unsymmetric Newton Jacobian through the resultants' chain
(analysis/jacobian.py).
"""

import numpy as np

from petsc_rod.analysis.positions import HEIGHT, position_gradient
from petsc_rod.analysis.second_variation import skew
from petsc_rod.mesh.elements import P2, element_integrals
from petsc_rod.mesh.fields import VectorField, element_dofs, scatter_element_vectors
from petsc_rod.physics.term import Term
from petsc_rod.riser.current import drag_jacobian, normal_drag
from petsc_rod.riser.hermite import HermiteProblem
from petsc_rod.riser.loads import NodalLoad
from petsc_rod.riser.seabed import SeabedContact, node_rows
from petsc_rod.scenes.boundary import is_held
from petsc_rod.scenes.line import piecewise_constant

# The KSP options prefix of the vertical (seabed) problem.
VERTICAL_PREFIX = "rod_z_"


class NodalLoadTerm(Term):
    """What the seabed and the drag share: a load per metre known at the P2 nodes
    (node_loads), whose share of n(S) is int_S^L f_h dS (loads.NodalLoad), plus, when the
    start is free, minus its whole resultant (the reaction at the held end)."""

    def __init__(self, mesh, name):
        self.mesh = mesh
        self.t = 0.0
        self.start_state = self.end_state = None
        self._nodes = VectorField(mesh, f"{name}_nodes")      # ghost exchange of nodal loads
        self._rhs = None                                      # made at the first add_to_rhs
        self._name = name
        self._gradient = None       # ghost exchange of a position gradient's element vectors

    def prepare(self, t, start, end):
        self.t, self.start_state, self.end_state = t, start, end

    def node_loads(self, state):
        """The load per metre at the owned P2 nodes, N/m, (n_nodes, 3)."""
        raise NotImplementedError

    def add_to_rhs(self, rhs, load):
        """Add int F.g dS of the loads.NodalLoad ``load`` to the slope's right-hand side
        ``rhs`` (VectorField), F(S) = int_S^L f_h dS + offset, the offset -int_0^L f_h when
        the start is free (docs/method.md §5)."""
        for vec, part in zip(rhs.components, self._load_field(load).components):
            vec.axpy(1.0, part)

    def load_vector(self, load):
        """add_to_rhs's int F.g dS at the owned P2 dofs, (2 n_owned, 3): rows in node
        order, the last vertex's phantom slot last, N. Collective."""
        return np.stack([vec.getArray(readonly=True)
                         for vec in self._load_field(load).components], axis=1)

    def _load_field(self, load):
        """int F.g dS of ``load`` (add_to_rhs) in a VectorField of the term's. Collective."""
        if self._rhs is None:
            self._rhs = VectorField(self.mesh, "nodal_load_rhs")
        offset = np.zeros(3) if is_held(self.start_state) else -load.total
        mesh = self.mesh
        self._rhs.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
            load.element_vectors(offset)))
        return self._rhs

    def add_position_gradient(self, g, state, derivatives):
        """Add the derivative of an energy (or work) of the node positions in the slopes
        into g's d3 rows: for each component c of ``derivatives`` {c: dE/dx^c at the
        owned nodes (n_nodes,), N}, sum_m dE/dx^c_m dx^c_m/ds^c_n
        (positions.position_gradient), the element vectors summed into the nodes by one
        ghost update. Collective."""
        mesh = self.mesh
        held_start = is_held(self.start_state)
        element = np.zeros((mesh.n_local_elements, 3, 3))
        factors = {}
        for c, derivative in derivatives.items():
            element[:, :, c], factors[c] = position_gradient(mesh, derivative, held_start)
        if self._gradient is None:
            self._gradient = VectorField(mesh, f"{self._name}_gradient")
        self._gradient.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2, element))
        n = g.shape[0]
        for c, factor in factors.items():
            g[:, 2, c] += (self._gradient.components[c].getArray(readonly=True)[:n]
                           + factor * state.node_weights)

    def _nodal_load(self, state):
        load = NodalLoad(self.mesh, self._nodes)
        load.set(self.node_loads(state))
        return load

    def force_beyond(self, state):
        """(n_owned, 3), N. Collective."""
        load = self._nodal_load(state)
        offset = np.zeros(3) if is_held(self.start_state) else -load.total
        return load.beyond_vertices() + offset

    def end_force(self, state):
        """0 when the start is held (the load is carried there), else -int_0^L f_h dS.
        Collective."""
        if is_held(self.start_state):
            return np.zeros(3)
        return -self._nodal_load(state).total

    def destroy(self):
        self._nodes.destroy()
        for field in (self._rhs, self._gradient):
            if field is not None:
                field.destroy()


class SeabedTerm(NodalLoadTerm):
    """A flat elastic seabed (environment.Seabed) under the line: the z slope solved with
    the contact (module docstring); its energy k/2 sum_n w_n (z_b - z_n)_+^2."""

    slope_components = (HEIGHT,)
    position_components = (HEIGHT,)

    def __init__(self, mesh, seabed):
        super().__init__(mesh, "seabed")
        self.seabed = seabed
        self.vertical = self.contact = None

    def build(self, slope_matrices, penalty):
        """The vertical problem with the slope problem's element matrices 2 c3 K + R W
        (ne, 3, 3): at the start and after every penalty raise."""
        self._destroy_vertical()
        self.vertical = HermiteProblem(self.mesh, slope_matrices, VERTICAL_PREFIX)
        self.contact = SeabedContact(self.mesh, self.seabed, self.vertical)
        if self.start_state is not None:
            self.vertical.set_end_states(self.start_state, self.end_state)

    def ksps(self):
        return [self.vertical.ksp]

    def prepare(self, t, start, end):
        super().prepare(t, start, end)
        self.vertical.set_end_states(start, end)

    def solve_slope(self, rhs, state, bordered):
        """z' from the vertical problem with the contact (seabed.SeabedContact.solve; on a
        flat seabed its first active set from the state's positions: on the matrix's
        riser on a seabed sloping 3 deg across its plane, whose grounded part slides
        down the slope from its catenary, the iteration then stagnated for 1200
        iterations, against 80 from an empty set, docs/riser.md)."""
        start = (state.r.ghosted() if self.contact.active is None and self.seabed.flat
                 else None)
        self.contact.solve(rhs.components[2], state.slope.components[2], start)
        if bordered:
            state.chord_multiplier[2] = self.vertical.end_residual()

    def _height_derivatives(self, state):
        """dE_s/dz_n = -k w_n (z_b - z_n)_+ and d2E_s/dz_n^2 = k w_n [z_n < z_b] at the owned
        nodes, (n_nodes,) each, N and N/m, at the heights of the state's centreline (on
        a flat seabed: the Newton steps are not taken on another, slope_load.py)."""
        gap = self.seabed.height - state.node_positions()[:, 2]
        spring = self.seabed.stiffness * state.node_weights * (gap > 0)
        return -spring * gap, spring

    def energy(self, state):
        """E_s = sum_n w_n k_v,n / 2 (z_b,n - z_n)_+^2 at the state's centreline, J, with
        z_b,n and k_v,n under each node (environment.Seabed; k_v = k on a flat seabed).
        Collective."""
        r = state.node_positions()
        gap = np.maximum(-self.seabed.gap(r), 0.0)
        stiffness = self.seabed.vertical_stiffness(self.seabed.gradients(r[:, 0], r[:, 1]))
        return float(self.mesh.global_sum(0.5 * np.sum(stiffness * state.node_weights
                                                       * gap**2)))

    def add_gradient(self, g, state):
        """dE_s/dr'_z at the nodes (add_position_gradient) into g's d3 z rows; the
        state's r is that of its fields (RodProblem.energy_gradient). Collective."""
        self.add_position_gradient(g, state, {HEIGHT: self._height_derivatives(state)[0]})

    def add_hessian(self, hessian):
        """k w_n at the active nodes on their heights (the seabed's curvature, beyond what
        its gradient gives through the multipliers)."""
        hessian.add_height_curvature(self._height_derivatives(hessian.problem.state)[1])

    def pressure(self, z):
        """The seabed's upward force per metre (N/m) at heights z."""
        return self.contact.pressure(z)

    def node_loads(self, state):
        loads = np.zeros((self.mesh.n_local_nodes, 3))
        if self.seabed.flat or self.contact.solution is None:
            loads[:, 2] = self.seabed.force(state.node_positions())[:, 2]
        else:                           # a slope: the reaction the vertical problem carried
            loads[:, 2] = self.contact.node_force()[:, 2]
        return loads

    def _destroy_vertical(self):
        if self.vertical is not None:
            self.contact.destroy()
            self.vertical.destroy()
        self.vertical = self.contact = None

    def destroy(self):
        self._destroy_vertical()
        super().destroy()


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
        the fields' tangents and heights. The depth derivative of a current profile is
        left out (J is then inexact on a sheared current: the steps converge linearly,
        fast where the shear over a step's height change is small)."""
        mesh, hessian = self.mesh, jacobian.hessian
        state = jacobian.problem.state
        ne = mesh.n_local_elements
        if not ne:
            return
        U = hessian.unknowns
        x_rows, turns, psi, row, other = self._jacobian_indices(hessian)
        tangents = element_dofs(state.slope.ghosted(), mesh.element_local, P2)   # (ne, 3, 3)
        h = mesh.element_h
        r = state.r.ghosted()[:, :, 2]                     # Hermite (z, z') at the vertices
        z = np.einsum("enk,ek->en", node_rows(h),
                      np.concatenate(mesh.element_ends(r), axis=1))      # (ne, 3 nodes)
        S = mesh.element_S[:, None] + h[:, None] * np.array([0.0, 0.5, 1.0])
        flat_t = tangents.reshape(-1, 3)
        G = sum(w * drag_jacobian(flat_t, c.velocity(z.ravel()),
                                  self.scene.drag_at(S.ravel(), c))
                for w, c in self.scene.drag_loads(self.t)).reshape(ne, 3, 3, 3)
        # the frames' rows of -delta b: -[t]x on omega, -t/|t| on the stretch
        rows_map = -skew(tangents)                                               # (ne, a, 3, 3)
        if U == 4:
            unit = tangents / np.linalg.norm(tangents, axis=2, keepdims=True)
            rows_map = np.concatenate([rows_map, -unit[:, :, None, :]], axis=2)  # (ne, a, 4, 3)
        integrals = element_integrals(h)                                         # (ne, 3)
        tails = self.drag.tail_integrals                                         # (ne, a, b)
        jacobian.add(x_rows, psi[:, 1],
                     (rows_map * integrals[:, :, None, None]).reshape(ne, 3 * U, 3))
        # rows_map_a tails_ab G_b for each node pair (a, b) of an element, (ne, a, b, U,
        # 3), by a batched matmul (a three-operand einsum loops over every index:
        # docs/performance.md), then in the order of the rows (a, U) and columns (b, 3)
        coupling = np.matmul(rows_map[:, :, None], G[:, None])
        coupling *= tails[:, :, :, None, None]
        jacobian.add(x_rows, turns, coupling.transpose(0, 1, 3, 2, 4).reshape(ne, 3 * U, 9))
        # the chain: Psi_e - Psi_e+1 - sum_l I_l G_l omega_l = 0 in Psi_e's row from a
        # held start, its negative in Psi_e+1's from a held end (the diagonal 1 is H's)
        sign = -1.0 if is_held(self.start_state) else 1.0
        jacobian.add(row, other, np.broadcast_to(-np.eye(3), (ne, 3, 3)))
        chain = sign * np.einsum("eb,ebjk->ejbk", integrals, G).reshape(ne, 3, 9)
        jacobian.add(row, turns, chain)

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

    def jacobian_pattern(self, hessian):
        """add_jacobian's blocks (Term.jacobian_pattern)."""
        if not self.mesh.n_local_elements:
            return []
        x_rows, turns, psi, row, other = self._jacobian_indices(hessian)
        return [(x_rows, psi[:, 1]), (x_rows, turns), (row, other), (row, turns)]

    def add_iterate_load(self, rhs, state):
        """Add the drag's int F.g to the slope problem's right-hand side."""
        self.drag.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.drag)


def dry_fraction(height, radius):
    """The fraction of a circular section of ``radius`` (m) whose centre is ``height``
    (m) above the sea surface that lies above it, the same shapes: 0 submerged (height
    <= -radius), 1 dry (height >= radius), between them the circle's segment,
    1 - (acos u - u sqrt(1 - u^2)) / pi with u = height / radius (1/2 at the surface)."""
    u = np.clip(np.asarray(height, dtype=float) / radius, -1.0, 1.0)
    return 1.0 - (np.arccos(u) - u * np.sqrt(1.0 - u**2)) / np.pi


class SurfaceTerm(NodalLoadTerm):
    """The buoyancy a line of sections does not have above the sea surface z_s
    (Scene.sea_surface, -rod_sea_surface): its load pieces are the submerged weights
    (mass - rho_w pi od^2 / 4) g (scenes/line.py); where a section is out of the water
    it weighs mass g, so this term adds the buoyancy back as a downward load per metre
    -t rho_w g (pi od^2 / 4) phi e_z, phi = dry_fraction(z - z_s, od / 2) of each node's
    section at the node's height: in the water nothing, in the air the whole buoyancy,
    across the surface the part of the circle above it (the area of a horizontal
    section exactly; a smooth law whose width is the diameter). The heights are those
    of the iterate x = (tau, lambda / R) the SNES mixes, z(S) = z_a + int tau3_z from
    the held end a (P2 in S, integrated exactly; iterate_heights), so that the map is a
    function of x and Anderson mixing sees the load's dependence on it: with the heights
    of the last global step (hidden from the mixing) the iteration cycled between two
    states, the crossing moving the weight and the weight the crossing. A load of the
    iterate like the drag, but without energy or Jacobian here: the scene has neither
    Newton steps nor the stability test. Built where the line can reach the surface
    (problem/build.py: a held end within od / 2 of it or above, or a buoyant
    section)."""

    conservative = in_newton = False
    newton_gap = ("a line of sections that reaches the sea surface (its weight in air "
                  "there: docs/riser.md §2)")

    def __init__(self, mesh, scene):
        super().__init__(mesh, "surface")
        self.scene = scene
        od = piecewise_constant(scene.sections, mesh.node_S(), "od")
        self.radius = od / 2
        self.buoyancy = scene.water_density * scene.gravity * np.pi * od**2 / 4
        self.load = NodalLoad(mesh, self._nodes)
        self._tangents = NodalLoad(mesh, VectorField(mesh, "surface_tangents"))

    def iterate_heights(self, state):
        """z at the owned P2 nodes, (n_nodes,), m, integrated from the iterate's tangents
        tau3 (P2 in S: at a vertex z_a + int_0^S, at a midpoint its element's first
        vertex's plus h (5 t_0 + 8 t_m - t_1) / 24), from the start when it is held,
        else back from the held end. Collective (a ghost exchange and a prefix sum)."""
        mesh, tangents = self.mesh, self._tangents
        tangents.set(np.ascontiguousarray(state.tau[:, 2]))
        if is_held(self.start_state):
            vertices = self.start_state.position[2] + tangents.before[:, 2]
        else:
            vertices = (self.end_state.position[2] - tangents.total[2]
                        + tangents.before[:, 2])
        z = np.empty(mesh.n_local_nodes)
        z[0::2] = vertices[:z[0::2].size]
        t = tangents.element_values[:, :, 2]
        ne = mesh.n_local_elements
        z[1:2 * ne:2] = vertices[:ne] + mesh.element_h * (5 * t[:, 0] + 8 * t[:, 1]
                                                          - t[:, 2]) / 24
        return z

    def dry(self, state):
        """phi, the dry fraction of each owned P2 node's section at the iterate's heights,
        (n_nodes,). Collective."""
        return dry_fraction(self.iterate_heights(state) - self.scene.sea_surface,
                            self.radius)

    def node_loads(self, state):
        """-t rho_w g A_o phi e_z at the owned P2 nodes, N/m, (n_nodes, 3). Collective."""
        phi = self.dry(state)
        loads = np.zeros((phi.size, 3))
        loads[:, 2] = -self.t * self.buoyancy * phi
        return loads

    def add_iterate_load(self, rhs, state):
        """Add the load's int F.g to the slope problem's right-hand side. Collective."""
        self.load.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.load)

    def destroy(self):
        super().destroy()
        self._tangents._field.destroy()


def reaches_surface(scene, held_heights):
    """Whether a line of sections with a given -rod_sea_surface may have a part out of
    the water: a held end (``held_heights``, m, the solver's frame) above z_s less the
    largest od / 2, or a buoyant section (one that could rise to it)."""
    if not scene.sections or scene.sea_surface is None:
        return False
    reach = max(section.od for section in scene.sections) / 2
    return (max(held_heights) > scene.sea_surface - reach
            or any(section.weight[2] > 0 for section in scene.sections))
