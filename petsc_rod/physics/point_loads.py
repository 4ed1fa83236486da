"""The scene's point loads (attachments, scenes/point_loads.py) as a term of physics
(physics/term.py): dead forces P_p at arc lengths S_p, scaled by the load factor t
(on a restart's walk, the blend of two scenes' sets: Scene.point_loads).

Their work is sum_p P_p.r(S_p). With r(S) = r(a) + int_a^S r' from the held end a
(docs/method.md §5) it is r(a).sum_p P_p + int F.r' dS, each point adding a step to F:

    start held:            F_p(S) = P_p [S < S_p]
    start free, end held:  F_p(S) = P_p [S < S_p] - P_p = -P_p [S > S_p].

So, as for the distributed dead load (physics/dead_loads.py), the term is a fixed
right-hand side b = int F.g dS of the slope problem, its energy -(r(a).sum P + b.r'),
its gradient -b on d3 = r' and no curvature of its own (Newton and the stability test
keep working). b is exact wherever S_p falls: in the element e that holds it,
int_{S_e}^{S_p} N_k dS is the P2 basis integrated over the part of the element
(elements.p2_integrals at xi = (S_p - S_e) / h), whole elements before it give
int_e N_k, those after it nothing.

n(S) jumps by -P_p at S_p; at a vertex on S_p the reported n is the one just beyond it
(the point counted as before S). A point at a free end S = L acts as an end force there
(it is in n(L), Term.end_force). A point on a held end is carried by the support: the
line's n is that without it, and the end's reaction (quantities/line_results.end_numbers)
adds it (on_held_ends), so that the reactions balance every load.

An attachment with a drag area C_d A (m^2) in a current also feels the drag
D_p = 1/2 rho_w C_d A |v| v, v the current at r(S_p) (Scene.point_drags: times the
path's weight of each current), a point force of the iterate added to the slope's
right-hand side every iteration (add_iterate_load) the same way, at the heights of the
last global step, as the line's drag (drag.py). It has no energy: the term is then
neither conservative nor in the Newton steps (a current makes the line's drag term
neither anyway).

Above the sea surface z_s (Scene.sea_surface, a line of sections with -rod_sea_surface)
an attachment has neither buoyancy nor drag: P_p holds its buoyancy B_p = rho_w g V_p
e_z (Scene.point_buoyancies), so the term adds -(1 - w_p) B_p and takes w_p D_p, with
w_p = wet_fraction(z_p - z_s, V_p) at the point's height of the iterate, as the line's
buoyancy in air (physics/iterate_heights.py: the heights the SNES mixes): the
part of a sphere of the attachment's volume under the surface (a body wholly in or out
of the water as OrcaFlex's clump and buoy; between, the sphere's cap, so that a buoy
that floats finds its waterline). Forces of the iterate like the drag, without energy:
built where an attachment can reach the surface (reaches_surface), so that a scene whose
attachments stay under it keeps its dead forces, its energy and its Newton steps.
"""

import numpy as np

from petsc_rod.mesh.elements import P2, element_integrals, p2_basis, p2_integrals
from petsc_rod.mesh.fields import VectorField, scatter_element_vectors
from petsc_rod.physics.dead_loads import DeadLoads
from petsc_rod.physics.iterate_heights import IterateHeights, locate
from petsc_rod.physics.term import TermOutput
from petsc_rod.scenes.boundary import is_held

# Units of the attributes this term adds to each step of the result file.
ATTRIBUTE_UNITS = {"point_load_S": "m", "point_load_force": "N",
                   "point_load_position": "m", "point_load_drag": "N",
                   "point_load_names": "text", "point_load_wet": "1"}


def wet_fraction(height, volume):
    """The fraction under the sea surface of a sphere of ``volume`` V (m^3) whose centre is
    ``height`` (m) above it, the same shapes: with r = (3 V / 4 pi)^(1/3) and the
    submerged depth d = min(max(r - height, 0), 2 r), the cap's d^2 (3 r - d) / (4 r^3):
    1 wholly under (height <= -r), 0 wholly above (height >= r), 1/2 at the surface.
    A point of no volume: 1 under the surface, 0 above, 1/2 on it (a step)."""
    height = np.asarray(height, dtype=float)
    r = np.cbrt(3.0 * np.asarray(volume, dtype=float) / (4.0 * np.pi))
    d = np.clip(r - height, 0.0, 2.0 * r)
    sphere = d**2 * (3.0 * r - d) / (4.0 * np.where(r > 0, r, 1.0)**3)
    step = np.where(height < 0, 1.0, np.where(height > 0, 0.0, 0.5))
    return np.where(r > 0, sphere, step)


def reaches_surface(scene):
    """The sea surface z_s of a line of sections (Scene.sea_surface) where one of its
    attachments that has a volume or a drag area may rise to it, else None: a held end
    above z_s less the largest attachment's radius, a buoyant attachment or a buoyant
    section (that could lift the line to it)."""
    surface = getattr(scene, "sea_surface", None)
    volumes = scene.point_volumes()
    if surface is None or not (np.any(volumes > 0) or scene.point_drags(1.0)):
        return None
    reach = float(np.cbrt(3.0 * volumes.max(initial=0.0) / (4.0 * np.pi)))
    held = [state.position[2] for state in (scene.start_state(1.0), scene.end_state(1.0))
            if is_held(state)]
    buoyant = (np.any(scene.point_loads(1.0)[1][:, 2] > 0)
               or any(section.weight[2] > 0 for section in scene.sections))
    return surface if buoyant or max(held) > surface - reach else None


def point_load_element_vectors(mesh, S, force, offset):
    """int_e F.g_k dS on the owned elements, (ne, 3 dofs, 3 components), N m, with
    F(S) = sum_p force_p [S < S_p] + offset: S (n_p,) m, force (n_p, 3) N, offset (3,) N.
    Exact: the steps are integrated over the part of each element before S_p."""
    h = mesh.element_h
    xi = np.clip((np.asarray(S)[None, :] - mesh.element_S[:, None]) / h[:, None], 0.0, 1.0)
    before = p2_integrals(xi, h)                          # int_{S_e}^{min(S_p, S_e+1)} N_k
    return (np.einsum("epk,pc->ekc", before, force)
            + element_integrals(h)[:, :, None] * np.asarray(offset)[None, None, :])


class PointLoads(DeadLoads):
    """The point loads of a Scene (or of a restart's BlendedPath) on a Mesh: a dead load
    (DeadLoads: energy, gradient and step load from b) with its own b, anchor work and
    share of n(S). Owns the VectorField of b; ``destroy()``."""

    attribute_units = ATTRIBUTE_UNITS

    def __init__(self, mesh, scene):
        super().__init__(mesh, scene)
        self.load.destroy()
        self.load = VectorField(mesh, "point_loads")      # b = int F.g dS on the P2 dofs
        self.S, self.force = scene.point_loads(0.0)
        self.held_start = True
        # the drag of attachments in a current and their buoyancy in the water only
        # (module docstring): forces of the iterate, no energy
        self.dragged = bool(scene.point_drags(0.5))
        self.surface = reaches_surface(scene)
        iterative = self.dragged or self.surface is not None
        self.conservative = self.in_newton = not iterative
        self.newton_gap = ("attachments that can reach the sea surface (docs/riser.md §9)"
                           if self.surface is not None else
                           "attachments with a drag area (docs/riser.md §9)"
                           if self.dragged else "")
        self._drag_rhs = VectorField(mesh, "point_drag_rhs") if iterative else None
        self._heights = (IterateHeights(mesh, "point_tangents")
                         if self.surface is not None else None)
        self.start_state = self.end_state = None

    @property
    def axially_symmetric(self):
        """Every point force along e_x (at t = 1): a turn about the x axis maps the loads
        to themselves."""
        return not np.any(self.scene.point_loads(1.0)[1][:, 1:])

    def prepare(self, t, start, end):
        """b, the offset and the anchor's work at load factor t (module docstring)."""
        self.t = t
        self.S, self.force = self.scene.point_loads(t)
        total = self.force.sum(axis=0)
        self.held_start = is_held(start)
        self.start_state, self.end_state = start, end
        self.offset = np.zeros(3) if self.held_start else -total
        anchor = start if self.held_start else end
        self.anchor_work = float(anchor.position @ total)
        mesh = self.mesh
        self.load.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
            point_load_element_vectors(mesh, self.S, self.force, self.offset)))

    def iterate_forces(self, state):
        """(D, C, w): the drags w_p D_p, the buoyancy taken off above the surface
        C_p = -(1 - w_p) B_p e_z, N, (n_p, 3) each, and the wet fractions w_p (n_p,)
        (module docstring): the drag at the points' heights of the last global step
        (where a current varies with depth), as the line's (drag.py), the wet fraction
        at the iterate's (where a surface is reached), as the line's buoyancy in air
        (surface.py). Zero drag without a drag area; w = 1 and C = 0 without a surface.
        Collective."""
        drags = self.scene.point_drags(self.t) if self.dragged else []
        profile = any(c.depths.size > 1 for _, c, _ in drags)
        z = self.positions(state)[:, 2] if profile else np.zeros(self.S.size)
        wet = np.ones(self.S.size)
        if self.surface is not None:
            self._heights.set(state, self.start_state, self.end_state)
            wet = wet_fraction(self._heights.at(self.S) - self.surface,
                               self.scene.point_volumes())
        drag = np.zeros_like(self.force)
        for weight, current, area in drags:
            v = current.velocity(z)
            drag += (weight * 0.5 * self.scene.water_density * area
                     * np.linalg.norm(v, axis=1))[:, None] * v
        lift = np.zeros_like(self.force)
        if self.surface is not None:
            lift[:, 2] = -(1.0 - wet) * self.scene.point_buoyancies(self.t)
        return drag * wet[:, None], lift, wet

    def drag_forces(self, state):
        """D_p = sum_k w_k 1/2 rho_w C_d A_p |v_k| v_k, N, (n_p, 3), v_k the current k at
        the points' heights, times the wet fraction (iterate_forces). Collective."""
        return self.iterate_forces(state)[0]

    def add_iterate_load(self, rhs, state):
        """Add the int F.g of the attachments' drag and of the buoyancy taken off above
        the surface to the slope's right-hand side (F their steps, offset as for the dead
        forces). Collective."""
        if self._drag_rhs is None:
            return
        drag, lift, _ = self.iterate_forces(state)
        force = drag + lift
        offset = np.zeros(3) if self.held_start else -force.sum(axis=0)
        mesh = self.mesh
        self._drag_rhs.add_ghosted(scatter_element_vectors(
            mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2,
            point_load_element_vectors(mesh, self.S, force, offset)))
        for vec, part in zip(rhs.components, self._drag_rhs.components):
            vec.axpy(1.0, part)

    def _total_force(self, state):
        """The dead forces and the forces of the iterate, (n_p, 3), N. Collective."""
        if self._drag_rhs is None:
            return self.force
        drag, lift, _ = self.iterate_forces(state)
        return self.force + drag + lift

    def _at_end(self):
        """The points at S = L (they act as a force at the end), (n_p,) bool."""
        return self.S >= self.mesh.length

    def force_beyond(self, state):
        """sum_p P_p [S_i < S_p or S_p = L] + offset at the owned vertices, N,
        (n_owned, 3)."""
        force = self._total_force(state)
        offset = np.zeros(3) if self.held_start else -force.sum(axis=0)
        beyond = (self.S[None, :] > self.mesh.vertex_S[:, None]) | self._at_end()[None, :]
        return beyond.astype(float) @ force + offset

    def end_force(self, state):
        force = self._total_force(state)
        offset = np.zeros(3) if self.held_start else -force.sum(axis=0)
        return force[self._at_end()].sum(axis=0) + offset

    def on_held_ends(self, state, start_held, end_held):
        """(the points' forces at S = 0, at S = L), N, (3,) each: the sum of the dead
        forces (and drags) of the points that sit on a held end, which the support
        carries: such a force never reaches the line's n (a held start's n(0+) does not
        see it; at a held end the chord multiplier takes it), so the support's reaction
        (line_results.end_numbers) adds it. Zero at a free end, where the point acts as
        an end force and is in n already. Collective."""
        force = self._total_force(state)
        at_start = force[self.S <= 0.0].sum(axis=0) if start_held else np.zeros(3)
        at_end = force[self._at_end()].sum(axis=0) if end_held else np.zeros(3)
        return at_start, at_end

    def positions(self, state):
        """r(S_p) of every point, (n_p, 3), m, on every rank: the rank that owns the
        element holding S_p (the last element for S_p = L) evaluates r(S_e) +
        int_{S_e}^{S_p} r'. Collective."""
        mesh = self.mesh
        local = np.zeros((self.S.size, 3))
        mine, e, xi, h = locate(mesh, self.S)
        # on every rank, with or without a point: the ghost updates are collective
        values = state.evaluate(mesh.element_local[e], p2_basis(xi, h), p2_integrals(xi, h))
        local[mine] = values["r"][:, 0]
        return mesh.global_sum(local)

    def outputs(self, problem, vertex):
        """The points' S, forces at the step's load factor (without the buoyancy above the
        surface) and absolute positions (the start position added, docs/method.md §5)
        (attributes point_load_S (n_p,), point_load_force and point_load_position
        (n_p, 3), point_load_names their labels joined by commas, in a current
        point_load_drag (n_p, 3), where the surface is reached point_load_wet (n_p,)).
        Collective."""
        if not self.S.size:
            return None
        positions = self.positions(problem.state) + problem.scene.start_position
        drag, lift, wet = self.iterate_forces(problem.state)
        attributes = {"point_load_S": self.S.copy(), "point_load_force": self.force + lift,
                      "point_load_position": positions}
        if self.dragged:
            attributes["point_load_drag"] = drag
        if self.surface is not None:
            attributes["point_load_wet"] = wet
        names = self.scene.point_load_names          # a table's labels (no comma in them)
        if len(names) == self.S.size:                # (a restart's walk has both scenes')
            attributes["point_load_names"] = ",".join(names)
        return TermOutput(attributes=attributes)

    def destroy(self):
        super().destroy()
        if self._drag_rhs is not None:
            self._drag_rhs.destroy()
        if self._heights is not None:
            self._heights.destroy()
