"""The seabed as a term of physics (physics/term.py; docs/riser.md), built only for a
scene that has one (problem/build.py).

The seabed is part of the global step: the z slope is solved in Hermite dofs with the
contact by an active-set loop (global_step/hermite.py, global_step/seabed_contact.py) in
place of the z component of the P2 solve (which then solves x and y only); when both
ends are held, the z part of the chord multiplier is that problem's residual at z(L).

The seabed is in the Newton steps (docs/method.md §11): its energy is a function of the
node heights, so its gradient in the slopes is the adjoint of their integral
(analysis/positions.position_gradient) and its curvature k w_n on the active nodes enters
the Newton system through the heights' chain (SecondVariation.add_height_curvature): a
semi-smooth Newton step, the active set that of the iterate.

On a seabed profile or grid the Newton steps take the lagged iteration's fixed point
(physics/slope_load.py) linearised: the force at the state's positions in the gradient,
and its whole derivative B_n (Seabed.profile_derivatives, unsymmetric near a row or grid
line) on the x, y, z chains, H its symmetric part and the Newton Jacobian the rest
(add_jacobian; ``unsymmetric``). Their stationary point is that fixed point, so a line's
run ends in Newton steps as on a plane, and a line of a system has its exact stiffness
from the same system (system/held_line.py). H is the modes' K (analysis/modes.py):
farther than delta/2 from every row B_n = k w_n N N^T, a plane's with the node's own
normal, so K is exact there; nearer, symmetrised_nodes says where it is not.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.positions import HEIGHT
from petsc_rod.global_step.hermite import HermiteProblem
from petsc_rod.global_step.seabed_contact import SeabedContact
from petsc_rod.physics.nodal_load import NodalLoadTerm

# The KSP options prefix of the vertical (seabed) problem.
VERTICAL_PREFIX = "rod_z_"
# A profile's block B_n is unsymmetric where |B_n - B_n^T| exceeds this fraction of
# |B_n| (symmetrised_nodes): far above the round-off of k_v a a^T formed as a product,
# far below the slope change of a row (|g - z_b'| of order the slopes).
ASYMMETRY = 1e-8


class SeabedTerm(NodalLoadTerm):
    """A flat elastic seabed (environment.Seabed) under the line: the z slope solved with
    the contact (module docstring); its energy k/2 sum_n w_n (z_b - z_n)_+^2."""

    slope_components = (HEIGHT,)
    position_components = (HEIGHT,)

    def __init__(self, mesh, seabed):
        super().__init__(mesh, "seabed")
        self.seabed = seabed
        if seabed.plane or self.profile:
            # a sloping plane's or a profile's penetration is along its normal: all
            # three components
            self.position_components = (0, 1, HEIGHT)
        self.vertical = self.contact = None
        self._solved = None         # the z slope of the contact's last solve (node_loads)

    @property
    def profile(self):
        """Whether the seabed is a profile or a grid, whose contact has a linearisation
        (Seabed.profile_derivatives: bathymetry.Profile, bathymetry.Grid)."""
        return self.seabed.shaped

    @property
    def unsymmetric(self):
        """On a profile or grid the Newton Jacobian holds its block's antisymmetric part
        (add_jacobian), beyond H: the steps solve with J (analysis/jacobian.py)."""
        return self.profile

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

    def set_clamp_stretch(self, start, end):
        self.vertical.set_clamp_stretch(start, end)

    def prepare(self, t, start, end):
        super().prepare(t, start, end)
        self.vertical.set_end_states(start, end)

    def solve_slope(self, rhs, state, bordered):
        """z' from the vertical problem with the contact (seabed_contact.SeabedContact.solve; on a
        flat seabed its first active set from the state's positions; a sloping or
        profiled one starts from an empty set, where the grounded part slides down the
        slope from its catenary: docs/riser.md §3)."""
        start = (state.r.ghosted() if self.contact.active is None and self.seabed.flat
                 else None)
        self.contact.solve(rhs.components[2], state.slope.components[2], start)
        self._solved = state.slope.components[2].getArray(readonly=True).copy()
        if bordered:
            state.chord_multiplier[2] = self.vertical.end_residual()

    def _height_derivatives(self, state):
        """dE_s/dz_n = -k w_n (z_b - z_n)_+ and d2E_s/dz_n^2 = k w_n [z_n < z_b] at the owned
        nodes, (n_nodes,) each, N and N/m, at the heights of the state's centreline (on
        a flat seabed; on another, _plane_derivatives)."""
        return self.seabed.height_derivatives(state.node_positions()[:, 2],
                                              state.node_weights)

    def energy(self, state):
        """E_s = sum_n w_n k_v,n / 2 (z_b,n - z_n)_+^2 at the state's centreline, J, with
        z_b,n and k_v,n under each node (environment.Seabed; k_v = k on a flat seabed).
        Collective."""
        return float(self.mesh.global_sum(self.seabed.energy(state.node_positions(),
                                                             state.node_weights)))

    def add_gradient(self, g, state):
        """dE_s/dr'_z at the nodes (add_position_gradient) into g's d3 z rows; on a
        sloping plane dE_s/dr' of all three components (Seabed.position_derivatives), on
        a profile or grid -w_n f_n's (Seabed.profile_derivatives). The state's r is
        that of its fields (RodProblem.energy_gradient). Collective."""
        if self.seabed.plane or self.profile:
            gradient = self._plane_derivatives(state)[0]
            self.add_position_gradient(g, state, {c: gradient[:, c] for c in range(3)})
            return
        self.add_position_gradient(g, state, {HEIGHT: self._height_derivatives(state)[0]})

    def add_hessian(self, hessian):
        """k w_n at the active nodes on their heights (the seabed's curvature, beyond what
        its gradient gives through the multipliers); on a sloping plane k w_n N N^T on
        the nodes' three position components; on a profile the symmetric part of its
        block B_n there (Seabed.profile_derivatives: k w_n N N^T with the node's own
        normal farther than delta/2 from every row; nearer, unsymmetric:
        symmetrised_nodes)."""
        if self.seabed.plane or self.profile:
            block = self._plane_derivatives(hessian.problem.state)[1]
            if self.profile:        # J carries the rest (add_jacobian)
                block = 0.5 * (block + block.transpose(0, 2, 1))
            hessian.add_position_curvature(block, self.position_components)
            return
        hessian.add_height_curvature(self._height_derivatives(hessian.problem.state)[1])

    def symmetrised_nodes(self, state):
        """(count, ratio) of Term.symmetrised_nodes: on a profile the owned grounded
        nodes whose block B_n has |B_n - B_n^T| above ASYMMETRY |B_n| (max-norms; within
        delta/2 of a row whose slopes differ), the largest ratio among them."""
        if not self.profile:
            return 0, 0.0
        block = self._plane_derivatives(state)[1]
        size = np.abs(block).max(axis=(1, 2))
        ratio = (np.abs(block - block.transpose(0, 2, 1)).max(axis=(1, 2))
                 / np.where(size > 0, size, 1.0))
        unsymmetric = ratio > ASYMMETRY
        return int(unsymmetric.sum()), float(ratio.max(initial=0.0))

    def add_jacobian(self, jacobian):
        """On a profile or grid: the antisymmetric part of its block B_n, which H leaves
        out, into the Newton Jacobian."""
        if not self.profile:
            return
        hessian = jacobian.hessian
        block = self._plane_derivatives(hessian.problem.state)[1]
        rest = 0.5 * (block - block.transpose(0, 2, 1))
        for rows, columns, blocks in hessian.position_blocks(
                rest, self.position_components, self.position_components):
            jacobian.add(rows, columns, blocks)

    def turn_columns(self, hessian, state, columns):
        """add_jacobian's entries in the global ``columns`` (held unknowns: a clamp's
        rotation or stretch, which moves its element's positions; system/held_line.py),
        one new Vec each, 0 on the held rows: with H's held columns
        (SecondVariation.full_columns) J's. Collective."""
        block = self._plane_derivatives(state)[1]
        triples = hessian.position_blocks(0.5 * (block - block.transpose(0, 2, 1)),
                                          self.position_components,
                                          self.position_components)
        vecs = []
        for column in columns:
            vec = hessian.matrix.createVecLeft()
            vec.zeroEntries()
            for rows, places, blocks in triples:
                at, slot = np.nonzero(places == column)
                if at.size:
                    vec.setValues(rows[at].ravel().astype(PETSc.IntType),
                                  blocks[at, :, slot].ravel(),
                                  addv=PETSc.InsertMode.ADD_VALUES)
            vec.assemble()
            hessian.zero_held(vec)
            vecs.append(vec)
        return vecs

    def position_derivatives(self, state):
        """The whole block B_n (n_nodes, 3, 3), N/m, of a profile or grid at the
        owned nodes of the state's centreline (Seabed.profile_derivatives): rows the
        gradient's components, columns the positions' (a line's end stiffness,
        system/held_line.py)."""
        return self._plane_derivatives(state)[1]

    def _plane_derivatives(self, state):
        """Seabed.position_derivatives at the owned nodes of the state's centreline
        (Seabed.profile_derivatives on a profile)."""
        if self.profile:
            return self.seabed.profile_derivatives(state.node_positions(),
                                                   state.node_weights)
        return self.seabed.position_derivatives(state.node_positions(), state.node_weights)

    def pressure(self, z):
        """The seabed's upward force per metre (N/m) at heights z."""
        return self.contact.pressure(z)

    def node_loads(self, state):
        loads = np.zeros((self.mesh.n_local_nodes, 3))
        if self.seabed.flat or not self.contact_solved(state):
            loads[:, 2] = self.seabed.force(state.node_positions())[:, 2]
        else:                           # a slope: the reaction the vertical problem carried
            loads[:, 2] = self.contact.node_force()[:, 2]
        return loads

    def contact_solved(self, state):
        """Whether the state's z slope is the one the contact's last vertical solve set:
        then the outputs read its reaction (the reaction the iteration carried, which
        does not amplify the positions' tolerance by k); after Newton steps on a sloping
        plane, which moved the state and not the contact, the state's own force
        (Seabed.force, as on the flat seabed). Collective."""
        if self.contact.solution is None or self._solved is None:
            return False
        same = np.array_equal(state.slope.components[2].getArray(readonly=True),
                              self._solved)
        return self.mesh.global_min(int(same)) == 1

    def _destroy_vertical(self):
        if self.vertical is not None:
            self.contact.destroy()
            self.vertical.destroy()
        self.vertical = self.contact = None

    def destroy(self):
        self._destroy_vertical()
        super().destroy()
