"""What the terms of physics that load the line at its P2 nodes share (NodalLoadTerm):
the seabed (seabed.py), the drag (drag.py), the sea surface (surface.py), the friction
(friction.py) and the slope's horizontal contact (slope_load.py)."""

import numpy as np

from petsc_rod.analysis.positions import position_gradient
from petsc_rod.global_step.centreline import chains_from_start
from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.mesh.elements import P2
from petsc_rod.mesh.fields import VectorField, scatter_element_vectors
from petsc_rod.physics.term import Term
from petsc_rod.scenes.boundary import is_held


class NodalLoadTerm(Term):
    """What the seabed and the drag share: a load per metre known at the P2 nodes
    (node_loads), whose share of n(S) is int_S^L f_h dS (global_step/nodal_loads.NodalLoad),
    plus, when the start is free, minus its whole resultant (the reaction at the held
    end)."""

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
        """Add int F.g dS of the nodal_loads.NodalLoad ``load`` to the slope's right-hand side
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
        held_start = chains_from_start(state, self.start_state, self.end_state)
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
