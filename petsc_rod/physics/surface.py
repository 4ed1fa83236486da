"""The sea surface as a term of physics (physics/term.py; docs/riser.md §2): the
buoyancy a line of sections does not have above it, built only where the line can reach
it (problem/build.py)."""

import numpy as np

from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.physics.iterate_heights import IterateHeights
from petsc_rod.physics.nodal_load import NodalLoadTerm
from petsc_rod.scenes.line import piecewise_constant

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
    of the iterate x = (tau, lambda / R) the SNES mixes (physics/iterate_heights.py, which
    says why). A load of the iterate like the drag, but without energy or Jacobian here:
    the scene has neither Newton steps nor the stability test. Built where the line can reach the surface
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
        self._heights = IterateHeights(mesh, "surface_tangents")

    def iterate_heights(self, state):
        """z at the owned P2 nodes, (n_nodes,), m, of the iterate's tangents
        (iterate_heights.IterateHeights). Collective."""
        self._heights.set(state, self.start_state, self.end_state)
        return self._heights.at_nodes()

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
        self._heights.destroy()


def reaches_surface(scene, held_heights):
    """Whether a line of sections with a given -rod_sea_surface may have a part out of
    the water: a held end (``held_heights``, m, the solver's frame) above z_s less the
    largest od / 2, or a buoyant section (one that could rise to it)."""
    if not scene.sections or scene.sea_surface is None:
        return False
    reach = max(section.od for section in scene.sections) / 2
    return (max(held_heights) > scene.sea_surface - reach
            or any(section.weight[2] > 0 for section in scene.sections))
