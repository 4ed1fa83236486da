"""The state of the iteration (docs/method.md §3, §4): the fields of the global step and
the node values of the local step, how a state is started, saved and measured.

* d1, d2 and the slope r' = d3: P2 VectorFields on the DMDA (slots: vertex, midpoint);
* r: a VectorField holding the Hermite pair (r, r') at each vertex, recovered from the
  slope by integration (global_step/centreline.py);
* tau and lambda at the owned P2 nodes, arrays (n_nodes, 3 directors, 3 components)
  with director rows d1, d2, d3; on an extensible line (docs/method.md §12) tau's third
  row is the stretched tangent (1 + eps) tau3, so that the strain eps is carried with
  tau wherever tau goes (steps, snapshots, the predictor, turns, restart files);
* mu, the multiplier of the chord constraint r(L) - r(0) = int r' dS (both ends held).
"""

from typing import NamedTuple

import numpy as np

from petsc_rod.global_step.centreline import midpoint_slopes, positions_at_points
from petsc_rod.mesh.elements import GAUSS_POINTS, P2, p2_basis, p2_integrals
from petsc_rod.mesh.fields import VectorField, at_points, element_dofs
from petsc_rod.frames import rotation_about, rotations
from petsc_rod.problem.node_values import NodeValues
from petsc_rod.scenes import starts
from petsc_rod.scenes.scene import REFERENCE_FRAME

# Deformations smaller than this, relative to |X|, are resolved to rtol times it of |X|
# (1e-14 at the default rtol: near round-off, which the iteration reaches: docs/method.md
# §6), not relative to themselves.
DEFORMATION_FLOOR = 1e-5

# A state whose weighted off-axis moment |v| (RodState.canonical_angle) is below this
# times L^2 is not turned: straight to round-off.
CANONICAL_FLOOR = 1e-8


class Norms(NamedTuple):
    """The stopping quantities of one iteration (RodState.norms): the change relative to
    |X|, the RMS constraint residual, and ``scale``, the relative size of the deformation
    in [DEFORMATION_FLOOR, 1] that the stopping test divides both by."""

    change: float
    residual: float
    scale: float


class RodState:
    """Owns the state's Vecs; ``destroy()`` releases them."""

    def __init__(self, mesh):
        self.mesh = mesh
        # the centreline from the lower end of a line held at both ends
        # (centreline.chains_from_start): set where a term asks for it
        self.chains_from_end = False
        self.d1, self.d2, self.slope, self.r = (VectorField(mesh, n)
                                                for n in ("d1", "d2", "slope", "r"))
        shape = (mesh.n_local_nodes, 3, 3)
        self.tau = np.zeros(shape)
        self.lam = np.zeros(shape)
        self.chord_multiplier = np.zeros(3)
        self.node_weights = mesh.node_weights()
        h = mesh.element_h
        self._gauss = p2_basis(GAUSS_POINTS, h), p2_integrals(GAUSS_POINTS, h)
        self._nodes = NodeValues(mesh)
        # S at the nodes: the unstressed reference state there, S e_x and the reference
        # frame (starts.straight), is what the deformation is measured from (norms)
        self._node_S = mesh.node_S()

    @property
    def frame_fields(self):
        """The P2 fields of the global step in frame order: d1, d2, r' = d3."""
        return self.d1, self.d2, self.slope

    # --- starts ---------------------------------------------------------------------
    def set_straight(self):
        """The straight reference state: r = S e_x, frame (e_y, e_z, e_x), lambda = 0."""
        self.set_from_curve(starts.straight)

    def set_from_curve(self, curve):
        """Start from a smooth curve S -> (r, frame, force) (scenes/starts.py): r and
        r' = d3 at the vertices (the slope's midpoints from the Hermite cubic they
        define), d1, d2 at the vertices and midpoints, tau = frame at the nodes,
        lambda3 = force there and lambda1 = lambda2 = 0."""
        mesh = self.mesh
        vertex_S, midpoint_S = self._owned_vertex_and_midpoint_S()
        positions, vertex_frame, _ = curve(vertex_S)
        self.set_centreline(positions, vertex_frame[:, 2])
        _, midpoint_frame, _ = curve(midpoint_S)
        for index, director in enumerate(self.frame_fields[:2]):
            director.set_owned(np.stack([vertex_frame[:, index], midpoint_frame[:, index]],
                                        axis=1))
        _, node_frame, node_force = curve(mesh.node_S())
        self.tau[:] = node_frame
        self.lam[:] = 0.0
        self.lam[:, 2] = node_force
        self.remember()

    def roll_cross_sections(self, amplitude):
        """Roll the cross-sections about their tangent by phi(S) = amplitude sin(pi S / 2L)
        rad (zero at S = 0): (d1, d2) -> (cos phi d1 + sin phi d2, -sin phi d1 +
        cos phi d2), likewise (tau1, tau2) and (lambda1, lambda2). It changes the start,
        not the problem, so that a symmetric start (e.g. a planar one) can leave a
        symmetric equilibrium that is not a minimiser (docs/method.md §7)."""
        if amplitude == 0.0:
            return
        mesh = self.mesh
        slot_S = np.stack(self._owned_vertex_and_midpoint_S(), axis=1)
        slot_angle = amplitude * np.sin(np.pi * slot_S / (2 * mesh.length))
        node_angle = amplitude * np.sin(np.pi * mesh.node_S() / (2 * mesh.length))
        d1, d2 = rolled(self.d1.owned(), self.d2.owned(), slot_angle[..., None])
        self.d1.set_owned(d1)
        self.d2.set_owned(d2)
        for frames in (self.tau, self.lam):
            frames[:, 0], frames[:, 1] = rolled(frames[:, 0], frames[:, 1],
                                                node_angle[..., None])
        self.remember()

    def roll_nodes(self, angle):
        """Roll tau and lambda at each node about its tangent by ``angle`` (n_nodes,) rad:
        rows (t1, t2) -> (cos a t1 + sin a t2, -sin a t1 + cos a t2), t3 kept (the
        stretched tangent too). The fields are the next global step's to make."""
        for frames in (self.tau, self.lam):
            frames[:, 0], frames[:, 1] = rolled(frames[:, 0], frames[:, 1], angle[:, None])

    def turn_frames(self, omega):
        """Turn tau and lambda at each node by exp([omega_n]x), omega (n_nodes, 3):
        rows t_i -> Q t_i (leaving a saddle, docs/method.md §10). On an extensible line
        omega may be (n_nodes, 4): its last column moves the stretch, k -> k + omega_n3
        (kept above k / 2: the line is not turned inside out), i.e. tau3 scaled."""
        turn = rotations(omega[:, :3])
        self.tau[:] = np.einsum("nkl,nil->nik", turn, self.tau)
        self.lam[:] = np.einsum("nkl,nil->nik", turn, self.lam)
        if omega.shape[1] == 4:
            k = 1.0 + self.strain()
            self.tau[:, 2] *= (np.maximum(k + omega[:, 3], 0.5 * k) / k)[:, None]

    def canonical_angle(self):
        """The angle (rad) of the turn about e_x that takes this state to the canonical
        member of its family in an axially symmetric scene (docs/method.md §10): the
        turn that points v = int (1 + S/L) (r_y, r_z) dS along +y. None where |v| is
        below CANONICAL_FLOOR L^2 (a straight rod: no family to choose from). The weight
        has an even and an odd part in S, so that neither a symmetric nor an
        antisymmetric bow gives v = 0. v is a sum over the nodes (one allreduce): the
        same on any number of ranks to round-off."""
        mesh = self.mesh
        weight = self.node_weights * (1 + mesh.node_S() / mesh.length)
        v = mesh.global_sum(weight @ self.node_positions()[:, 1:])
        if np.hypot(*v) <= CANONICAL_FLOOR * mesh.length**2:
            return None
        return -float(np.arctan2(v[1], v[0]))

    def turn_about_axis(self, angle):
        """Turn the whole state by ``angle`` rad about the x axis through the origin and
        roll every section back by -angle about its own d3: r, r', d_i, tau_i, lambda_i
        and mu -> Q (.) with Q the rotation about e_x, then (d1, d2) and their tau,
        lambda rolled (``rolled``). Where d3 = e_x (a clamp in an axially symmetric
        scene) the two cancel; with K1 = K2 the roll costs nothing: an equilibrium goes
        to an equilibrium, a fixed point of the iteration to a fixed point."""
        q = rotation_about(REFERENCE_FRAME[2], angle)   # e_x, the axis of the scene
        for field in (self.r, self.slope):
            field.set_owned(field.owned() @ q.T)
        d1, d2 = rolled(self.d1.owned() @ q.T, self.d2.owned() @ q.T, -angle)
        self.d1.set_owned(d1)
        self.d2.set_owned(d2)
        for frames in (self.tau, self.lam):
            frames[:] = frames @ q.T
            frames[:, 0], frames[:, 1] = rolled(frames[:, 0], frames[:, 1], -angle)
        self.chord_multiplier = q @ self.chord_multiplier
        self.remember()

    def set_node_directors(self, frames):
        """d1, d2 and r' = d3 at the owned P2 nodes from frames (n_nodes, 3, 3), rows
        d1, d2, d3 (the last vertex's phantom midpoint slot set to 0)."""
        n_vertices = self.d1.components[0].getLocalSize() // 2
        slots = np.zeros((2 * n_vertices, 3, 3))
        slots[:frames.shape[0]] = frames
        for i, field in enumerate(self.frame_fields):
            field.set_owned(slots[:, i].reshape(n_vertices, 2, 3))

    def set_centreline(self, positions, slopes):
        """r and r' from Hermite vertex data (n_owned, 3) each, e.g. a restart: the slope
        field takes r' at the vertices and the cubic's derivative at the midpoints."""
        mesh = self.mesh
        self.r.set_owned(np.stack([positions, slopes], axis=1))
        ghosted, left = self.r.ghosted(), mesh.element_local
        slope = np.zeros((positions.shape[0], 2, 3))
        slope[:, 0] = slopes
        slope[:mesh.n_local_elements, 1] = midpoint_slopes(
            ghosted[left, 0], ghosted[left, 1], ghosted[left + 1, 0], ghosted[left + 1, 1],
            mesh.element_h)
        self.slope.set_owned(slope)

    def _owned_vertex_and_midpoint_S(self):
        """S at the owned vertices and at the P2 midpoints after them, (n_owned,) each
        (the last vertex's midpoint slot is a phantom past the end)."""
        mesh = self.mesh
        owned = np.arange(mesh.vertex_start, mesh.vertex_end)
        vertex_S = mesh.coordinates(owned)
        return vertex_S, (vertex_S + mesh.coordinates(owned + 1)) / 2

    # --- save and restore -------------------------------------------------------------
    def snapshot(self):
        """Copies of this rank's share of the state a warm start needs (r, d, tau,
        lambda, mu), so that a failed continuation step can be undone (``restore``).
        Owned arrays only: nothing is gathered or communicated."""
        state = {name: field.owned() for name, field in self._fields().items()}
        state.update(tau=self.tau.copy(), lam=self.lam.copy(),
                     chord_multiplier=self.chord_multiplier.copy())
        return state

    def restore(self, snapshot):
        """Put back a ``snapshot`` bit for bit, e.g. after a step that diverged and left
        NaN in the fields."""
        for name, field in self._fields().items():
            field.set_owned(snapshot[name])
        self.tau[:] = snapshot["tau"]
        self.lam[:] = snapshot["lam"]
        self.chord_multiplier = snapshot["chord_multiplier"].copy()
        self.remember()

    def _fields(self):
        return {"r": self.r, "slope": self.slope, "d1": self.d1, "d2": self.d2}

    # --- values at nodes and points ---------------------------------------------------
    def node_directors(self):
        """d1, d2 and r' = d3 at the owned P2 nodes, rows, (n_nodes, 3, 3): the dofs of
        the fields themselves (the phantom slot of the last vertex left out). The array
        is the state's own, overwritten by the next call (node_values.py)."""
        return self._nodes.take_directors(self.frame_fields)

    def node_positions(self):
        """r at the owned P2 nodes, (n_nodes, 3): the vertex values, and at each midpoint
        r(S_e) + int r' over the element's first half, h (5 r'_0 + 8 r'_m - r'_1) / 24
        (exact for the P2 slope). The state's own array, overwritten by the next call."""
        return self._nodes.take_positions(self.r, self.slope)

    def point_values(self):
        """r, directors and their derivatives at the Gauss points of the owned elements."""
        return self.evaluate(self.mesh.element_local, *self._gauss)

    def evaluate(self, element_local, p2, integrals):
        """Fields at points of the given elements (ghosted local indices, (ne,)).

        p2 = (phi, dphi) and integrals (elements.p2_integrals) tabulated at the points,
        (ne, nq, 3). Returns r (ne, nq, 3), directors and derivatives (ne, nq, 3, 3), rows
        d1, d2, r' and d1', d2', r''; r = r(S_e) + int_{S_e}^S r'.
        """
        dofs = [element_dofs(f.ghosted(), element_local, P2) for f in self.frame_fields]
        left = self.r.ghosted()[element_local, 0]
        directors = np.stack([at_points(p2[0], d) for d in dofs], axis=2)
        derivatives = np.stack([at_points(p2[1], d) for d in dofs], axis=2)
        return {"r": positions_at_points(left, dofs[2], integrals), "directors": directors,
                "derivatives": derivatives}

    # --- the stopping quantities ------------------------------------------------------
    def remember(self):
        """Take the current fields as the reference of the next change."""
        self.node_directors()
        self.node_positions()
        self._nodes.remember()

    def take_directors(self):
        """The node directors of the fields the global step just solved for, kept for
        the residual of ``norms`` (n_nodes, 3, 3)."""
        return self.node_directors()

    def strain(self):
        """The axial strain eps at the owned P2 nodes, (n_nodes,): |tau3| - 1, tau3 being
        the stretched target (1 + eps) tau3 of the local step (docs/method.md §12); 0 to
        round-off on an inextensible line."""
        return np.sqrt(np.einsum("nc,nc->n", self.tau[:, 2], self.tau[:, 2])) - 1.0

    def norms(self):
        """The stopping quantities of the last iteration (docs/method.md §6), measured
        against the size of the deformation, so that they mean the distance to the
        solution whatever that size (one allreduce). With X = (r, d1, d2, r') at the
        nodes, X^ref the unstressed reference state and d_n the directors of the last
        take_directors (or remember):

            change   = sqrt(sum_n w_n |X_n - X_n^prev|^2 / sum_n w_n |X_n|^2),
            residual = sqrt(sum_n w_n |d_n - tau_n|^2 / L),
            deformation = sqrt(sum_n w_n |X_n - X_n^ref|^2 / sum_n w_n |X_n|^2),
            s = min(1, max(deformation, DEFORMATION_FLOOR)).

        The stopping test reads change / s and residual / s: a deformation of the order
        of the state (s = 1) is tested relative to |X|, a small one relative to itself,
        down to DEFORMATION_FLOOR (below it, to rtol DEFORMATION_FLOOR of |X|, near
        round-off). Returns Norms(change, residual, scale = s).
        """
        self.node_positions()
        gap, size, step, deformation = self.mesh.global_sum(self._nodes.stopping_sums(
            self.tau, self.node_weights, self._node_S))
        if size <= 0:
            return Norms(np.inf, np.inf, 1.0)
        scale = min(1.0, max(np.sqrt(deformation / size), DEFORMATION_FLOOR))
        return Norms(np.sqrt(step / size), np.sqrt(gap / self.mesh.length), scale)

    def destroy(self):
        for obj in [*self.frame_fields, self.r]:
            obj.destroy()


def rolled(first, second, angle):
    """(cos a first + sin a second, -sin a first + cos a second), broadcasting ``angle``."""
    c, s = np.cos(angle), np.sin(angle)
    return c * first + s * second, -s * first + c * second
