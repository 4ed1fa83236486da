"""The seabed as a unilateral spring in the global step, solved implicitly (docs/riser.md).

Energy of the seabed z = z_b with stiffness k (N/m^2), with Simpson's rule at the P2
nodes (the quadrature of the constraint, docs/method.md §4):

    E_s = k/2 sum_n w_n (z_b - z_n)_+^2,

so the line presses the seabed with k (z_b - z_n)_+ per metre at node n, upwards. E_s is
convex and piecewise quadratic in the Hermite dofs y of the vertical problem
(hermite.py). The global step minimises it exactly with the rest of the augmented
Lagrangian by an active-set (semi-smooth Newton) loop: with A the nodes below z_b,
solve (M + k sum_A w_n e_n e_n^T) y = b + k z_b sum_A w_n e_n, take the new A, and repeat
until A no longer changes (e_n: z_n from the element's Hermite dofs). The matrix is
refactored only when A changes.

A seabed that is not flat (environment.Seabed with a shape: slope, profile) has at each
node the height z_b,n = z_b(x_n, y_n) and the vertical stiffness k_n = k / (1 + |g_n|^2)
at the node's horizontal position of the last global step (``follow``, lagged like the
drag's depths): E_s = 1/2 sum_n k_n w_n (z_b,n - z_n)_+^2, the same loop. The
horizontal part of the normal force, -k_n (z_b,n - z_n)_+ g_n, is a nodal load of the
iterate (physics/slope_load.py). On a plane k_n is constant and only the right-hand side
follows the line; on a profile the matrix is rebuilt when a node's k_n changes (it
crosses a row). Why implicit: the iteration's compliance to a load on a
stretch l of line is about l^2 / R, so an explicit (lagged) spring k is amplified
k l^2 / R times per iteration, 1e5 or more for a seabed stiff enough to hold the line
within a millimetre (docs/riser.md).
"""

import numpy as np

from petsc_rod.global_step.hermite import midpoint_values
from petsc_rod.mesh.elements import NODE_WEIGHTS

# The active-set loop of one global step ends after this many solves even if the set
# still changes; the next iteration starts from the last set (a cycle between two sets
# differs by nodes within round-off of z_b, whose force is negligible).
MAX_SOLVES = 30
# The first active set of a line (SeabedContact.solve from the positions it starts from):
# the nodes below z_b or on it, within this many metres above it (a catenary start lays
# its grounded part on z_b exactly, to round-off).
TOUCHING = 1e-6


def owned_nodes(mesh, per_element):
    """Values at the element nodes (ne, 3 nodes, ...) as values at the owned P2 nodes
    (n_local_nodes, ...): each element's left vertex and midpoint, and the last vertex
    from the last element's right node when this rank owns it (a vertex shared by two
    elements has the same value in both)."""
    per_element = np.asarray(per_element)
    ne = mesh.n_local_elements
    nodes = np.zeros((mesh.n_local_nodes,) + per_element.shape[2:])
    nodes[0:2 * ne:2] = per_element[:, 0]
    nodes[1:2 * ne:2] = per_element[:, 1]
    if mesh.n_local_nodes > 2 * ne and ne:
        nodes[-1] = per_element[-1, 2]
    return nodes


def node_rows(h):
    """E, (ne, 3 nodes, 4): z at the element's (left vertex, midpoint, right vertex) as
    rows acting on its Hermite dofs (z_e, z'_e, z_e+1, z'_e+1)."""
    rows = np.zeros((np.size(h), 3, 4))
    rows[:, 0, 0] = rows[:, 2, 2] = 1.0
    rows[:, 1] = midpoint_values(h)
    return rows


class SeabedContact:
    """The seabed term of a VerticalProblem and its active-set solve."""

    def __init__(self, mesh, seabed, problem):
        self.mesh, self.seabed, self.problem = mesh, seabed, problem
        h = mesh.element_h
        self.weights = h[:, None] * NODE_WEIGHTS[None, :]          # (ne, 3), per element
        self.rows = node_rows(h)
        self.active = None                                          # (ne, 3) booleans
        self._elements = None       # the element matrices and vectors of the last set
        # z_b and k at the nodes: the flat seabed's numbers, else (ne, 3) arrays (follow)
        self.base, self.stiffness = seabed.height, seabed.stiffness
        self.gradients = None                                       # (ne, 3, 2), follow
        self.solution = None                # the Hermite dofs y of the last solve (a Vec)
        self.solves = 0                                             # since the last reset
        self._local = mesh.da.createLocalVec()

    def _set_active(self, active, only_changed=False):
        """The spring k w_n at the active nodes: element matrices E^T diag(k w) E and
        vectors k z_b E^T (k w), (ne, 4, 4) and (ne, 4). ``only_changed``: k and z_b as
        at the last call, so that only the elements where the set changed are made
        anew (the active set moves at a few nodes near the touchdown), in place (the
        vertical problem keeps copies)."""
        if only_changed and self._elements is not None:
            matrices, vectors = self._elements
            changed = np.flatnonzero(np.any(active != self.active, axis=1))
            matrices[changed], vectors[changed] = self._element_terms(active, changed)
        else:
            matrices, vectors = self._element_terms(active, slice(None))
        self._elements = matrices, vectors
        self.problem.set_added(matrices, vectors)
        self.active = active

    def _element_terms(self, active, elements):
        """The element matrices and vectors of _set_active for ``elements`` (an index)."""
        stiffness = self.stiffness[elements] if np.ndim(self.stiffness) else self.stiffness
        spring = stiffness * self.weights[elements] * active[elements]
        rows = self.rows[elements]
        weighted = rows.transpose(0, 2, 1) * spring[:, None, :]             # (k, 4, 3)
        base = self.base[elements] if np.ndim(self.base) else self.base
        return np.matmul(weighted, rows), self._pull(weighted, base)

    def _pull(self, weighted, base=None):
        """k z_b E^T (k w) of the active nodes, (k, 4), from E^T diag(k w), (k, 4, 3),
        and z_b (a number, or (k, 3): the seabed's heights of those elements)."""
        base = self.base if base is None else base
        if np.ndim(base) == 0:
            return base * weighted.sum(axis=2)
        return np.einsum("ekn,en->ek", weighted, base)

    def follow(self, ghosted_r):
        """A seabed that is not flat: z_b and k at the nodes from the positions of the
        last global step, ``ghosted_r`` the r field's ghosted (vertex, slope) pairs
        (n_ghosted, 2, 3) (module docstring). The matrix is rebuilt if k changed at an
        active node, else only the right-hand side."""
        left, right = self.mesh.element_ends(ghosted_r)
        dofs = np.concatenate([left, right], axis=1)                      # (ne, 4, 3)
        nodes = np.einsum("enk,ekc->enc", self.rows, dofs)                  # (ne, 3, 3)
        x, y = nodes[..., 0], nodes[..., 1]
        stiffness = self.seabed.vertical_stiffness(self.seabed.gradients(x, y))
        changed = np.shape(self.stiffness) != stiffness.shape or np.any(
            self.stiffness != stiffness)
        self.base, self.stiffness = self.seabed.heights(x, y), stiffness
        self.gradients = self.seabed.gradients(x, y)                       # (ne, 3, 2)
        if self.active is None:
            return
        if self.mesh.global_sum(int(changed)):
            self._set_active(self.active)
        else:
            spring = self.stiffness * self.weights * self.active
            vectors = self._pull(self.rows.transpose(0, 2, 1) * spring[:, None, :])
            self.problem.set_added_rhs(vectors)
            self._elements = self._elements[0], vectors

    def heights(self, y):
        """z at the three nodes of each owned element, (ne, 3), from the Hermite dofs y."""
        self.mesh.da.globalToLocal(y, self._local)
        return self._heights_of(self._local.getArray(readonly=True).reshape(-1, 2))

    def _heights_of(self, ghosted):
        """z at the three nodes of each owned element, (ne, 3), from ghosted Hermite pairs
        (z, z') at the vertices, (n_ghosted, 2)."""
        dofs = np.concatenate(self.mesh.element_ends(ghosted), axis=1)
        return np.einsum("enk,ek->en", self.rows, dofs)

    def solve(self, slope_rhs, slope, ghosted_r=None):
        """The vertical problem with the seabed (module docstring): sets ``slope`` (the z
        slope) and returns the Hermite dofs y. The first solve's active set is that of
        the positions ``ghosted_r`` (the r field's ghosted (vertex, slope) pairs,
        (n_ghosted, 2, 3): the state the iteration starts from; the nodes on z_b
        within TOUCHING, or below it) where given, else empty:
        from an empty set the line falls through the seabed, and each solve after that
        lifts only the nodes beside the touchdown (about 120 of them a solve, 60 solves
        on options/riser_catenary.opts at 18 000 elements from a catenary start whose
        touchdown is within metres of the solution's). Collective."""
        if self.active is None:
            if ghosted_r is None:
                self._set_active(np.zeros(self.weights.shape, dtype=bool))
            else:
                heights = self._heights_of(ghosted_r[..., 2])
                self._set_active(self.seabed.in_contact(heights, self.base + TOUCHING))
        for _ in range(MAX_SOLVES):
            y = self.problem.solve(slope_rhs, slope)
            self.solves += 1
            active = self.seabed.in_contact(self.heights(y), self.base)
            if not self.mesh.global_sum(int(np.any(active != self.active))):
                break
            self._set_active(active, only_changed=True)
        self.solution = y
        return y

    def node_force(self):
        """k_n (z_b,n - z_n)_+ (-g_n, 1) at the owned P2 nodes (N/m), (n_nodes, 3), of a
        seabed that is not flat: the normal force with the penetration of the last
        vertical solve's heights z_n under the z_b,n, k_n, g_n it was solved with (the
        ``follow`` before it), so that it is the reaction that problem carried
        (physics/slope_load.py). Collective. Zero before a solve after the first ``follow`` (the
        start; a contact rebuilt at a penalty raise: one iteration without the push)."""
        if self.gradients is None or self.solution is None:
            return np.zeros((self.mesh.n_local_nodes, 3))
        return owned_nodes(self.mesh, self.seabed.normal_force(self._push(), self.gradients))

    def reaction(self):
        """R = k (z_b,n - z_n)_+ cos(theta_n) at the element nodes (ne, 3), N/m: the
        normal contact force per metre of the last vertical solve (environment.Seabed;
        k_v sqrt(1 + |g|^2) = k cos(theta)). Collective."""
        push = self._push()
        if self.gradients is None:
            return push
        return push * self.seabed.slope_factor(self.gradients)

    def _push(self):
        """k_n (z_b,n - z_n)_+ at the element nodes (ne, 3), N/m, of the last vertical
        solve's heights (Seabed.push at the z_b and k the solve had). Collective."""
        return self.seabed.push(self.heights(self.solution), self.base, self.stiffness)

    def pressure(self, z):
        """k (z_b - z)_+ (N/m), the seabed's upward force per metre of line at heights z."""
        return self.seabed.push(z)

    def destroy(self):
        self._local.destroy()
