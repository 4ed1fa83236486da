"""What the Uzawa solver calls, each iteration, for a scene with a seabed or a current
(docs/riser.md); the solver holds None instead when the scene has neither.

* The drag enters the slope problem's right-hand side like a dead load (loads.py),
  evaluated at the tangents tau3 of the iterate x = (tau, lambda / R) that the SNES
  mixes, and at the heights of the last global step (the current profile), times the
  load factor t: a function of the iterate, so that Anderson mixing sees it.
* The seabed is part of the global step: the z slope is solved in Hermite dofs with
  the contact by an active-set loop (hermite.py, seabed.py), replacing the z component of
  the P2 solve; when both ends are held, the z part of the chord multiplier is that
  problem's residual at z(L).
"""

import numpy as np

from ..boundary import is_held
from ..fe import P2, p2_element_matrices
from ..fields import VectorField, scatter_element_vectors
from .current import normal_drag
from .hermite import VerticalProblem
from .loads import NodalLoad
from .seabed import SeabedContact

# The KSP options prefix of the vertical (seabed) problem.
VERTICAL_PREFIX = "rod_z_"


class RiserTerms:
    """The seabed and drag terms of one UzawaSolver (see the module docstring)."""

    def __init__(self, solver):
        mesh, scene = solver.mesh, solver.scene
        self.mesh, self.seabed, self.current = mesh, scene.seabed, scene.current
        self.t = 0.0
        self.y = None                   # Hermite dofs of z after the last global step
        self.vertical = self.contact = None
        self._penalty = None
        self._nodes = VectorField(mesh, "riser_nodes")      # ghost exchange of nodal loads
        self._rhs = VectorField(mesh, "riser_rhs")
        self.drag = NodalLoad(mesh, self._nodes) if self.current is not None else None

    # --- set-up -------------------------------------------------------------------
    def _build_vertical(self, solver):
        """The vertical problem at the solver's current R (again after a raise)."""
        if self.vertical is not None:
            self.contact.destroy()
            self.vertical.destroy()
        h = self.mesh.element_h
        matrices = p2_element_matrices(h, 2 * solver.matrix_split[2], solver.penalty)
        self.vertical = VerticalProblem(self.mesh, matrices, VERTICAL_PREFIX)
        self.contact = SeabedContact(self.mesh, self.seabed, self.vertical)
        self._penalty = solver.penalty

    def prepare_step(self, solver, t):
        """The load factor and the end states of a step (UzawaSolver.prepare_step)."""
        self.t = t
        if self.seabed is not None:
            if self._penalty != solver.penalty:
                self._build_vertical(solver)
            self.vertical.set_prescribed(solver.start_state, solver.end_state)

    # --- each iteration ------------------------------------------------------------
    def add_loads(self, solver):
        """Add the drag's int F.g to the slope problem's right-hand side ``solver.rhs[2]``."""
        if self.drag is None:
            return
        current = self.current
        self.drag.set(self.t * normal_drag(solver.tau[:, 2],
                                           current.velocity(solver._positions[:, 2]),
                                           current.drag))
        offset = np.zeros(3) if is_held(solver.start_state) else -self.drag.total
        mesh = self.mesh
        self._rhs.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
            self.drag.element_vectors(offset)))
        for vec, load in zip(solver.rhs[2].components, self._rhs.components):
            vec.axpy(1.0, load)

    def solve_vertical(self, solver):
        """Replace the z slope by the solution with the seabed (after the P2 solve)."""
        if self.seabed is None:
            return
        if self._penalty != solver.penalty:           # raised (UzawaSolver.raise_penalty)
            self._build_vertical(solver)
            self.vertical.set_prescribed(solver.start_state, solver.end_state)
        self.y = self.contact.solve(solver.rhs[2].components[2], solver.theta.components[2])
        if solver.bordered:
            solver._multiplier[2] = self.vertical.end_residual()

    # --- outputs ---------------------------------------------------------------------
    def node_heights(self, solver):
        """z at the owned P2 nodes, (n_nodes,)."""
        return solver.node_positions()[:, 2]

    def seabed_pressure(self, z):
        """The seabed's upward force per metre (N/m) at heights z; zero without a seabed."""
        if self.seabed is None:
            return np.zeros_like(z)
        return self.contact.pressure(z)

    def node_loads(self, solver):
        """The state's loads per metre at the owned nodes, drag and seabed, (n_nodes, 3)."""
        loads = np.zeros((self.mesh.n_local_nodes, 3))
        if self.drag is not None:
            loads[:, :] = self.t * normal_drag(solver.tau[:, 2], self.current.velocity(
                solver._positions[:, 2]), self.current.drag)
        loads[:, 2] += self.seabed_pressure(self.node_heights(solver))
        return loads

    def force_beyond(self, solver):
        """The part of n(S) at the owned vertices that the drag and the seabed make,
        int_S^L f_h dS, plus, when the start is free, their share -int_0^L f_h of the
        reaction at the held end (docs/method.md §6). (n_owned, 3). Collective."""
        load = NodalLoad(self.mesh, self._nodes)
        load.set(self.node_loads(solver))
        offset = np.zeros(3) if is_held(solver.start_state) else -load.total
        return load.beyond_vertices() + offset

    def energy(self):
        """The seabed's stored energy (J); the drag has none (it is not conservative)."""
        if self.seabed is None or self.y is None:
            return 0.0
        return self.contact.energy(self.y)

    def destroy(self):
        if self.vertical is not None:
            self.contact.destroy()
            self.vertical.destroy()
        self._nodes.destroy()
        self._rhs.destroy()
