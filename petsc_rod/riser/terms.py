"""What the global step (global_step/global_step.py) calls for a scene with a seabed or
a current (docs/riser.md); it holds None instead when the scene has neither.

* The drag enters the slope problem's right-hand side like a dead load (loads.py),
  evaluated at the tangents tau3 of the iterate x = (tau, lambda / R) that the SNES
  mixes and at the heights of the last global step (for a current profile), times the
  load factor t: a function of the iterate, so that Anderson mixing sees it.
* The seabed is part of the global step: the z slope is solved in Hermite dofs with the
  contact by an active-set loop (hermite.py, seabed.py) in place of the z component of
  the P2 solve (which then solves x and y only); when both ends are held, the z part of
  the chord multiplier is that problem's residual at z(L).
"""

import numpy as np

from petsc_rod.mesh.elements import P2, p2_element_matrices
from petsc_rod.mesh.fields import VectorField, scatter_element_vectors
from petsc_rod.riser.current import normal_drag
from petsc_rod.riser.hermite import VerticalProblem
from petsc_rod.riser.loads import NodalLoad
from petsc_rod.riser.seabed import SeabedContact
from petsc_rod.scenes.boundary import is_held

# The KSP options prefix of the vertical (seabed) problem.
VERTICAL_PREFIX = "rod_z_"


class RiserTerms:
    """The seabed and drag terms of one GlobalStep (see the module docstring)."""

    def __init__(self, mesh, scene):
        self.mesh, self.seabed, self.current = mesh, scene.seabed, scene.current
        self.t = 0.0
        self.start_state = self.end_state = None
        self.y = None                   # Hermite dofs of z after the last global step
        self.vertical = self.contact = None
        self._nodes = VectorField(mesh, "riser_nodes")      # ghost exchange of nodal loads
        self._rhs = VectorField(mesh, "riser_rhs")
        self.drag = NodalLoad(mesh, self._nodes) if self.current is not None else None

    def build(self, slope_stiffness, penalty):
        """The vertical problem with the slope problem's coefficients 2 c3 (N m^2) and R
        (N): at the start and after every penalty raise (GlobalStep.build)."""
        if self.seabed is None:
            return
        self._destroy_vertical()
        matrices = p2_element_matrices(self.mesh.element_h, slope_stiffness, penalty)
        self.vertical = VerticalProblem(self.mesh, matrices, VERTICAL_PREFIX)
        self.contact = SeabedContact(self.mesh, self.seabed, self.vertical)
        if self.start_state is not None:
            self.vertical.set_prescribed(self.start_state, self.end_state)

    def ksps(self):
        """The KSP of the vertical problem, where there is a seabed."""
        return [self.vertical.ksp] if self.vertical is not None else []

    def prepare(self, t, start_state, end_state):
        """The load factor and end states of a step (GlobalStep.prepare)."""
        self.t, self.start_state, self.end_state = t, start_state, end_state
        if self.vertical is not None:
            self.vertical.set_prescribed(start_state, end_state)

    # --- each iteration ------------------------------------------------------------
    def drag_at_nodes(self, state):
        """t c |v_n| v_n at the owned nodes (N/m), (n_nodes, 3), from the tangents tau3
        and, for a current that varies with depth, the heights of the last global step.
        Collective when it does (a ghost exchange)."""
        current = self.current
        z = (state.node_positions()[:, 2] if current.depths.size > 1
             else np.zeros(self.mesh.n_local_nodes))
        return self.t * normal_drag(state.tau[:, 2], current.velocity(z), current.drag)

    def add_loads(self, slope_rhs, state):
        """Add the drag's int F.g to the slope problem's right-hand side (a VectorField)."""
        if self.drag is None:
            return
        self.drag.set(self.drag_at_nodes(state))
        offset = np.zeros(3) if is_held(self.start_state) else -self.drag.total
        mesh = self.mesh
        self._rhs.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
            self.drag.element_vectors(offset)))
        for vec, load in zip(slope_rhs.components, self._rhs.components):
            vec.axpy(1.0, load)

    def solve_vertical(self, slope_rhs, state, bordered):
        """Replace the z slope of ``state`` by the solution with the seabed (after the P2
        solve); with both ends held, the z part of state.chord_multiplier too."""
        if self.seabed is None:
            return
        self.y = self.contact.solve(slope_rhs.components[2], state.slope.components[2])
        if bordered:
            state.chord_multiplier[2] = self.vertical.end_residual()

    # --- outputs ---------------------------------------------------------------------
    def seabed_pressure(self, z):
        """The seabed's upward force per metre (N/m) at heights z; zero without a seabed."""
        if self.seabed is None:
            return np.zeros_like(z)
        return self.contact.pressure(z)

    def node_loads(self, state):
        """The state's loads per metre at the owned nodes, drag and seabed, (n_nodes, 3)."""
        loads = np.zeros((self.mesh.n_local_nodes, 3))
        if self.drag is not None:
            loads += self.drag_at_nodes(state)
        loads[:, 2] += self.seabed_pressure(state.node_positions()[:, 2])
        return loads

    def force_beyond(self, state):
        """The part of n(S) at the owned vertices that the drag and the seabed make,
        int_S^L f_h dS, plus, when the start is free, their share -int_0^L f_h of the
        reaction at the held end (docs/method.md §6). (n_owned, 3). Collective."""
        load = NodalLoad(self.mesh, self._nodes)
        load.set(self.node_loads(state))
        offset = np.zeros(3) if is_held(self.start_state) else -load.total
        return load.beyond_vertices() + offset

    def energy(self):
        """The seabed's stored energy (J); the drag has none (it is not conservative)."""
        if self.seabed is None or self.y is None:
            return 0.0
        return self.contact.energy(self.y)

    def _destroy_vertical(self):
        if self.vertical is not None:
            self.contact.destroy()
            self.vertical.destroy()
        self.vertical = self.contact = None

    def destroy(self):
        self._destroy_vertical()
        self._nodes.destroy()
        self._rhs.destroy()
