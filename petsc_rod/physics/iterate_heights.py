"""The heights of the iterate x = (tau, lambda / R) the SNES mixes: z(S) = z_a + int tau3_z
from the held end a (P2 in S, integrated exactly), at the owned P2 nodes and at given
arc lengths. The loads that switch at the sea surface read them (physics/surface.py, the
line's buoyancy in air; physics/point_loads.py, the attachments' wet fraction), so that
the map is a function of x and Anderson mixing sees the load's dependence on it: with
the heights of the last global step (hidden from the mixing) the iteration cycled
between two states, the crossing moving the weight and the weight the crossing."""

import numpy as np

from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.mesh.elements import p2_integrals
from petsc_rod.mesh.fields import VectorField
from petsc_rod.scenes.boundary import is_held


def locate(mesh, S):
    """The points at arc lengths ``S`` (n_p,) that this rank's elements hold: (mine
    (n_p,) bool, e (n_mine,) local element, xi (n_mine, 1) in [0, 1], h (n_mine,) m);
    the element holding S_p is the one it starts (the last element for S_p = L)."""
    mine = np.zeros(S.size, dtype=bool)
    e = np.zeros(0, dtype=int)
    if mesh.n_local_elements:
        ends = np.append(mesh.element_S, mesh.coordinates(mesh.element_end))
        last = mesh.element_end == mesh.n_elements
        mine = (S >= ends[0]) & ((S < ends[-1]) | (last & (S <= ends[-1])))
        e = np.clip(np.searchsorted(ends, S[mine], side="right") - 1,
                    0, mesh.n_local_elements - 1)
    h = mesh.element_h[e]
    xi = np.clip((S[mine] - mesh.element_S[e]) / h, 0.0, 1.0)[:, None]
    return mine, e, xi, h


class IterateHeights:
    """z of the iterate's tangents on a Mesh (module docstring); ``set`` then
    ``at_nodes`` or ``at``. Owns a VectorField; ``destroy()``."""

    def __init__(self, mesh, name):
        self.mesh = mesh
        self._tangents = NodalLoad(mesh, VectorField(mesh, name))
        self._vertices = None

    def set(self, state, start, end):
        """Take the iterate's tangents tau3 of ``state``, the held end among the
        EndStates ``start`` and ``end``: from the start when it is held, else back from
        the end. Collective (a ghost exchange and a prefix sum)."""
        tangents = self._tangents
        tangents.set(np.ascontiguousarray(state.tau[:, 2]))
        if is_held(start):
            self._vertices = start.position[2] + tangents.before[:, 2]
        else:
            self._vertices = end.position[2] - tangents.total[2] + tangents.before[:, 2]

    def at_nodes(self):
        """z at the owned P2 nodes, (n_nodes,), m: at a vertex z_a + int_0^S, at a
        midpoint its element's first vertex's plus h (5 t_0 + 8 t_m - t_1) / 24."""
        mesh, vertices = self.mesh, self._vertices
        z = np.empty(mesh.n_local_nodes)
        z[0::2] = vertices[:z[0::2].size]
        t = self._tangents.element_values[:, :, 2]
        ne = mesh.n_local_elements
        z[1:2 * ne:2] = vertices[:ne] + mesh.element_h * (5 * t[:, 0] + 8 * t[:, 1]
                                                          - t[:, 2]) / 24
        return z

    def at(self, S):
        """z at arc lengths ``S`` (n_p,), m, on every rank: the rank whose element holds
        S_p adds int_{S_e}^{S_p} tau3_z to its first vertex's. Collective."""
        mesh = self.mesh
        mine, e, xi, h = locate(mesh, S)
        local = np.zeros(S.size)
        t = self._tangents.element_values[e, :, 2]
        local[mine] = self._vertices[e] + np.einsum("pk,pk->p", p2_integrals(xi, h)[:, 0], t)
        return mesh.global_sum(local)

    def destroy(self):
        self._tangents._field.destroy()
