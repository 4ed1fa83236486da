"""The scene's dead loads as a term (physics/term.py): the piecewise-constant distributed
load f(S) (N/m) and the dead forces at free ends, scaled by the load factor t
(docs/method.md §5).

Their work is r(a).(int f dS + dead end forces) + int F.r' dS with
F(S) = int_S^L f dS + offset (global_step/centreline.py), a linear function of the slope:
the term is the fixed right-hand side b = int F.g dS of the slope problem, its energy
-(r(a).applied + b.r'), its gradient -b on d3 = r', and no curvature of its own.
"""

import numpy as np

from petsc_rod.global_step.centreline import anchor_work, load_offset
from petsc_rod.global_step.matrices import load_ghosted
from petsc_rod.mesh.fields import VectorField
from petsc_rod.physics.term import Term


class DeadLoads(Term):
    """The dead loads of a Scene on a Mesh. Owns the VectorField of b; ``destroy()``."""

    # the scene's own loads, which Scene.axially_symmetric checks
    axially_symmetric = True

    def __init__(self, mesh, scene):
        self.mesh, self.scene = mesh, scene
        self.t = 0.0
        self.load = VectorField(mesh, "load")          # b = int F.g dS on the P2 dofs
        self.offset = np.zeros(3)                      # F(S) - int_S^L f dS, N
        self.anchor_work = 0.0                         # r(a).(applied forces), J

    def prepare(self, t, start, end):
        """b, the offset and the anchor's work at load factor t (centreline.py), b
        integrated exactly between the load breaks."""
        scene = self.scene
        total = scene.load_beyond(0.0, t)
        self.t = t
        self.offset = load_offset(start, end, total)
        self.anchor_work = anchor_work(start, end, total)
        self.load.add_ghosted(load_ghosted(
            self.mesh, lambda S: scene.load_beyond(S, t) + self.offset, scene.load_piece_ends))

    def add_step_load(self, load):
        for target, vec in zip(load.components, self.load.components):
            target.axpy(1.0, vec)

    def energy(self, state):
        """-(r(a).applied + b.r'), J (the work of the loads, with its sign in E)."""
        work = self.anchor_work + sum(load.dot(slope) for load, slope
                                      in zip(self.load.components, state.slope.components))
        return -work

    def add_gradient(self, g, state):
        """-b on the rows of d3 = r'."""
        n = g.shape[0]
        for c, vec in enumerate(self.load.components):
            g[:, 2, c] -= vec.getArray(readonly=True)[:n]

    def force_beyond(self, state):
        """int_S^L f dS + offset at the owned vertices (the offset: the dead force at a
        free end S = L, or minus the whole load when the start is free), N."""
        return self.scene.load_beyond(self.mesh.vertex_S, self.t) + self.offset

    def end_force(self, state):
        return self.offset

    def destroy(self):
        self.load.destroy()
