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

Neither is yet in the Newton steps (in_newton False): the iteration alone converges
with them.
"""

import numpy as np

from petsc_rod.mesh.elements import P2
from petsc_rod.mesh.fields import VectorField, scatter_element_vectors
from petsc_rod.physics.term import Term
from petsc_rod.riser.current import normal_drag
from petsc_rod.riser.hermite import VerticalProblem
from petsc_rod.riser.loads import NodalLoad
from petsc_rod.riser.seabed import SeabedContact
from petsc_rod.scenes.boundary import is_held

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

    def prepare(self, t, start, end):
        self.t, self.start_state, self.end_state = t, start, end

    def node_loads(self, state):
        """The load per metre at the owned P2 nodes, N/m, (n_nodes, 3)."""
        raise NotImplementedError

    def add_to_rhs(self, rhs, load):
        """Add int F.g dS of the loads.NodalLoad ``load`` to the slope's right-hand side
        ``rhs`` (VectorField), F(S) = int_S^L f_h dS + offset, the offset -int_0^L f_h when
        the start is free (docs/method.md §5)."""
        if self._rhs is None:
            self._rhs = VectorField(self.mesh, "nodal_load_rhs")
        offset = np.zeros(3) if is_held(self.start_state) else -load.total
        mesh = self.mesh
        self._rhs.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
            load.element_vectors(offset)))
        for vec, part in zip(rhs.components, self._rhs.components):
            vec.axpy(1.0, part)

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
        if self._rhs is not None:
            self._rhs.destroy()


class SeabedTerm(NodalLoadTerm):
    """A flat elastic seabed (environment.Seabed) under the line: the z slope solved with
    the contact (module docstring); its energy k/2 sum_n w_n (z_b - z_n)_+^2."""

    slope_components = (2,)
    in_newton = False           # its gradient and Hessian are not in the Newton steps yet

    def __init__(self, mesh, seabed):
        super().__init__(mesh, "seabed")
        self.seabed = seabed
        self.y = None                   # Hermite dofs of z after the last global step
        self.vertical = self.contact = None

    def build(self, slope_matrices, penalty):
        """The vertical problem with the slope problem's element matrices 2 c3 K + R W
        (ne, 3, 3): at the start and after every penalty raise."""
        self._destroy_vertical()
        self.vertical = VerticalProblem(self.mesh, slope_matrices, VERTICAL_PREFIX)
        self.contact = SeabedContact(self.mesh, self.seabed, self.vertical)
        if self.start_state is not None:
            self.vertical.set_end_states(self.start_state, self.end_state)

    def ksps(self):
        return [self.vertical.ksp]

    def prepare(self, t, start, end):
        super().prepare(t, start, end)
        self.vertical.set_end_states(start, end)

    def solve_slope(self, rhs, state, bordered):
        """z' from the vertical problem with the contact (seabed.SeabedContact.solve)."""
        self.y = self.contact.solve(rhs.components[2], state.slope.components[2])
        if bordered:
            state.chord_multiplier[2] = self.vertical.end_residual()

    def energy(self, state):
        """E_s at the last global step's heights, J."""
        if self.y is None:
            return 0.0
        return self.contact.energy(self.y)

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
    follower load of the iterate (module docstring)."""

    conservative = False
    in_newton = False

    def __init__(self, mesh, scene):
        super().__init__(mesh, "drag")
        self.scene = scene
        self.drag = NodalLoad(mesh, self._nodes)
        self._node_S = mesh.node_S()            # where each node's section's drag applies

    def node_loads(self, state):
        """sum_k w_k c_k |v_n,k| v_n,k at the owned nodes (N/m), (n_nodes, 3), over the
        (weight, current) pairs of scene.drag_loads(t) (w = t for one current), from the
        tangents tau3 and, for a current that varies with depth, the heights of the last
        global step. Collective when one does (a ghost exchange)."""
        currents = self.scene.drag_loads(self.t)
        z = (state.node_positions()[:, 2] if any(c.depths.size > 1 for _, c in currents)
             else np.zeros(self.mesh.n_local_nodes))
        return sum(w * normal_drag(state.tau[:, 2], c.velocity(z),
                                   self.scene.drag_at(self._node_S, c)[:, None])
                   for w, c in currents)

    def add_iterate_load(self, rhs, state):
        """Add the drag's int F.g to the slope problem's right-hand side."""
        self.drag.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.drag)
