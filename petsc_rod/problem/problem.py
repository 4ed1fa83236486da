"""What is solved: the discrete rod problem on one mesh and scene (docs/method.md §2-§6),
apart from how it is solved (iteration/driver.py: the SNES and the step controller).

A RodProblem holds the mesh, the scene, the state (problem/state.py), the global step
(global_step/), the list of terms of physics (physics/term.py) that the scene needs and
its reports beside them (quantities/report.py; both made by problem/build.py). It answers
what the method and its users ask of the problem: one Uzawa iteration G (the map the
SNES mixes), the energy E and its gradient, the second variation
(analysis/second_variation.py), the link, the end reaction and the internal force, and the
terms' and reports' outputs with their units. The Newton steps, the stability test, the
outputs and the riser numbers take a RodProblem, never the solver.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.link import FULLER_MARGIN, link_integrands
from petsc_rod.analysis.stability import StabilityTest
from petsc_rod.frames import roll_between, strains
from petsc_rod.global_step.centreline import lower_end_first
from petsc_rod.global_step.coefficients import FieldCoefficients
from petsc_rod.global_step.global_step import GlobalStep
from petsc_rod.local_step.projection import (ITERATION_PASSES, nearest_rotation,
                                             stretched_rotation, update_multipliers)
from petsc_rod.mesh.elements import (cut_gauss_rule, p2_basis, p2_integrals,
                                     quadrature_weights)
from petsc_rod.problem import penalty as penalty_policy
from petsc_rod.physics.flex_joint import FlexJoint, joint_local_step
from petsc_rod.problem.build import scene_reports, scene_terms
from petsc_rod.problem.state import RodState
from petsc_rod.scenes.boundary import clamped_nodes

# The load path's roll of a clamp over one step is summed over this many pieces of it
# (RodProblem._path_roll), each of less than half a turn.
PATH_PIECES = 64

EVENTS = {name: PETSc.Log.Event(f"rod_{name}") for name in ("projection", "multiplier", "norms")}


class RodProblem:
    """The problem of a Scene on a Mesh at an asked penalty R (N), with the ``terms``
    (physics/term.py) and the ``reports`` (quantities/report.py; default: those the scene
    needs, problem/build.py). Owns the state, the global step, the terms and the second
    variation; ``destroy()`` releases them."""

    def __init__(self, mesh, scene, penalty, terms=None, reports=None):
        self.mesh, self.scene = mesh, scene
        self.terms = list(scene_terms(mesh, scene) if terms is None else terms)
        self.reports = list(scene_reports(scene, self.terms) if reports is None
                            else reports)
        # the fields' stiffness along the line: a_i, c_i and their matrices (§2)
        self.coefficients = FieldCoefficients(scene, mesh.element_S, mesh.element_h,
                                              penalty_policy.matrix_split)
        # the problem's scale of R, N (penalty.default_penalty): what "far below" means
        self.scale = penalty_policy.default_penalty(scene)
        # the largest R a stalling iteration raises it to (penalty.adapt_ceiling)
        self.adapt_ceiling = penalty_policy.adapt_ceiling(scene, self.scale)
        # flex joints on an extensible end act in the local step at their node (§12),
        # not in the global step: marked before it is built
        self._local_joints = []
        if scene.extensible:
            for term in self.terms:
                if isinstance(term, FlexJoint) and np.isfinite(scene.axial_stiffness_at(
                        0.0 if term.which == "start" else scene.length)):
                    term.local = True
                    if term.node is not None:
                        self._local_joints.append(term)
        self.state = RodState(mesh)
        self.state.chains_from_end = (
            any(term.chains_from_end for term in self.terms)
            and lower_end_first(scene.start_state(1.0), scene.end_state(1.0)))
        try:
            self.global_step = GlobalStep(mesh, scene, self.coefficients, float(penalty),
                                          self.terms)
        except Exception:           # a solver the options refuse: free what was made
            for term in self.terms:
                term.destroy()
            self.state.destroy()
            raise
        self.weights = quadrature_weights(mesh.element_h)
        self._energy_rule = self._stored_energy_rule()
        # the ends' kinds do not change: the clamped nodes are those of the whole run
        self.free_nodes = ~clamped_nodes(mesh, self.start_state, self.end_state)
        # round sections between two clamps: the torque is uniform at equilibrium
        # (relax_twist)
        values = scene.stiffness_values()
        self.relaxes_twist = bool(scene.start == "clamp" and scene.end == "clamp"
                                  and np.all(values[:, 0] == values[:, 1]))
        self._second_variation = None
        # EA at the owned nodes, N, for the stretched local step (§12); None, and nothing
        # built for stretch, on an inextensible line
        self.axial = scene.axial_stiffness_at(mesh.node_S()) if scene.extensible else None
        # a clamp prescribes the slope, so its stretch comes from the force balance
        # (_stretch_clamps)
        self._stretched_clamps = self.axial is not None and "clamp" in (scene.start,
                                                                         scene.end)

    # --- what the terms allow ---------------------------------------------------------
    @property
    def conservative(self):
        """Every term has an energy: the stability test (§10) applies."""
        return all(term.conservative for term in self.terms)

    @property
    def in_newton(self):
        """Every term's energy, gradient and Hessian are exact: Newton steps (§11) apply."""
        return all(term.in_newton for term in self.terms)

    @property
    def axially_symmetric(self):
        """The scene and every term are unchanged by a turn about the x axis (with the
        sections' roll): equilibria come in families (§10, ``turn_to_canonical``)."""
        return self.scene.axially_symmetric and all(term.axially_symmetric
                                                    for term in self.terms)

    def accept_step(self):
        """The state is an accepted load step's equilibrium: the terms commit their path
        memory (Term.accept_step). Collective."""
        for term in self.terms:
            term.accept_step(self.state)

    # --- the global step and the map --------------------------------------------------------
    @property
    def penalty(self):
        """The penalty R of the global step's factorisation, N."""
        return self.global_step.penalty

    def rebuild(self, penalty):
        """Refactor the global step at penalty R, N (GlobalStep.build)."""
        self.global_step.build(penalty)

    @property
    def start_state(self):
        """The end conditions at S = 0 of the last ``prepare`` (scenes.EndState)."""
        return self.global_step.start_state

    @property
    def end_state(self):
        return self.global_step.end_state

    @property
    def bordered(self):
        """Both ends held: the chord int r' dS = r(L) - r(0) is a constraint."""
        return self.global_step.bordered

    def prepare(self, t):
        """End conditions and loads at load factor t (GlobalStep.prepare)."""
        self.global_step.prepare(t)

    def relax_twist(self, t_from, t, within):
        """Roll the sections of a line of round sections (K1 = K2 all along) clamped at
        both ends at the start of a step from load factor t_from to t, so that the twist
        the step adds is spread as a uniform torque, keeping the clamps' frames and the
        centreline (docs/method.md §7, "The twist of round sections"), where the
        iteration would not spread it itself ``within`` iterations.

        With K1 = K2 the torque m3 = K3 u3 is the same all along at equilibrium (m3' =
        m'.d3 + m.d3' = -(r' x n).d3 + K1 (d3 x d3').d3' = 0; no term applies a
        distributed moment). The fields still hold the state at t_from, such an
        equilibrium (or the start); tau holds the step's start. A roll phi(S) of the
        sections about their tangent changes u3 by phi' and nothing else, so the roll with
        phi(0) = phi(L) = 0 and phi' = u3_fields - u3_tau + dM / K3 (dM the one value
        that closes it) gives tau the twist at t_from plus a uniform torque increment:
        what the iteration reaches only by diffusion from the clamp, the slowest mode of a
        long twisted line (which kept Newton steps from converging). u3 dS between
        neighbouring nodes is frames.roll_between, the clamped nodes taken at their
        frames at t_from in both; the clamps' roll from t_from to t is added to the end
        gaps of tau as the load path walks it (_path_roll): a roll of any size, which the
        frames at t alone give only modulo a turn (a step of half a turn could go either
        way). On a converged state the roll is zero.

        The iteration damps the slowest roll mode, phi ~ sin(pi S / L), by about
        1 - pi^2 K3 / (R L^2) per plain iteration (the global step's 2 a K + R W on a
        roll, a1 = a2 = K3 / 2), and Anderson's mixing, like a Krylov method, needs about
        the square root of the plain count: e-folds take sqrt(R L int dS / K3) / pi
        iterations. Where that is within ``within`` (a short rod, the penalty of its
        stiffness) the twist spreads before a Newton attempt and the roll is not made:
        it would only move the iteration's first steps (docs/method.md §7). Elsewhere
        nothing. Collective."""
        if not self.relaxes_twist:
            return
        mesh, state = self.mesh, self.state
        frames = np.stack([state.tau, state.node_directors()], axis=1)   # (n, 2, 3, 3)
        if mesh.on_lower_boundary:
            frames[0] = self.scene.start_state(t_from).frame
        if mesh.on_upper_boundary:
            frames[-1] = self.scene.end_state(t_from).frame
        # the next rank's first node (its clamped end where it owns no element)
        following = mesh.first_of_next_rank(frames)
        if not mesh.on_upper_boundary:
            frames = np.concatenate([frames, following[None]])
        # per gap between neighbouring nodes, two per owned element (vertex to midpoint,
        # midpoint to the next vertex): the twist's change and the compliance dS / K3
        added = np.subtract(*roll_between(frames[:-1], frames[1:]).T)
        # the clamps' own roll over the step, in the gaps next to them: the first of the
        # rank of element 0, the last of the rank of the last element (not always the
        # rank of the last node)
        if mesh.on_lower_boundary and added.size:
            added[0] -= self._path_roll("start", t_from, t)
        if mesh.element_end == mesh.n_elements and added.size:
            added[-1] += self._path_roll("end", t_from, t)
        h = np.repeat(mesh.element_h / 2, 2)
        middle = np.repeat(mesh.element_S, 2) + h * np.tile([0.5, 1.5], mesh.n_local_elements)
        compliance = h / self.scene.stiffness_at(middle)[:, 2]
        total = mesh.global_sum(np.array([added.sum(), compliance.sum()]))
        if self.penalty * mesh.length * total[1] <= (np.pi * within)**2:
            return
        change = (total[0] / total[1]) * compliance - added
        vertex = mesh.prefix_sum(change[0::2] + change[1::2])
        angle = np.empty(mesh.n_local_nodes)
        angle[0::2] = vertex
        angle[1::2] = vertex[:mesh.n_local_elements] + change[0::2]
        state.roll_nodes(angle)

    def _path_roll(self, which, t_from, t):
        """The roll (rad) of the clamped frame at ``which`` end ('start', 'end') about its
        tangent from load factor t_from to t as the load path walks it: the sum of
        frames.roll_between over PATH_PIECES equal pieces (any size below PATH_PIECES
        half turns)."""
        s = np.linspace(t_from, t, PATH_PIECES + 1)
        states = getattr(self.scene, f"{which}_state")
        ends = np.array([states(value).frame for value in s])
        return float(np.sum(roll_between(ends[:-1], ends[1:])))

    def iterate(self):
        """One iteration G (docs/method.md §3): global step, local step (nearest rotation
        of R d + lambda at every node), multiplier update lambda += R (d - tau).

        On an extensible line (§12) the local step also finds the strain eps at each
        node (projection.stretched_rotation: one majorise-minimise pass from the last
        eps, the passes being carried by the iteration itself) and tau holds the
        targets (tau1, tau2, (1 + eps) tau3): the global step, the multiplier update
        and the residual read the stretched tangent where they read tau3. A flex joint
        on an extensible end replaces its node's targets by those of its own local step
        (flex_joint.joint_local_step, from the node's last rotation; §12)."""
        state, R = self.state, self.penalty
        self.global_step.solve(state)
        EVENTS["projection"].begin()
        directors = state.take_directors()
        stretch = None if self.axial is None else 1.0 + state.strain()
        starts = [self._joint_start(term.node) for term in self._local_joints]
        b = np.multiply(directors, R, out=state.tau)       # b = R d + lambda, in place
        b += state.lam
        if stretch is None:
            nearest_rotation(b, out=state.tau)
        else:
            stretched_rotation(b, self.axial, R, start=stretch, out=state.tau,
                               passes=ITERATION_PASSES)
            for term, start in zip(self._local_joints, starts):
                node = term.node
                b_node = R * directors[node] + state.lam[node]
                state.tau[node] = joint_local_step(
                    b_node, start, term.axis, term.k / state.node_weights[node],
                    self.axial[node], R)
            if self._stretched_clamps:
                self._stretch_clamps()
        EVENTS["projection"].end()
        EVENTS["multiplier"].begin()
        update_multipliers(state.lam, directors, state.tau, R)
        EVENTS["multiplier"].end()

    def _joint_start(self, node):
        """The rotation of the last targets at a joint's ``node`` (their third row
        normalised), the start of its local step's Newton iteration."""
        start = self.state.tau[node].copy()
        start[2] /= np.linalg.norm(start[2])
        return nearest_rotation(start[None])[0]

    def _stretch_clamps(self):
        """At a clamped end the slope is prescribed, r' = (1 + eps) d3, and the local
        step's multiplier there meets no equation: eps is taken from the force balance,
        EA eps = n.d3 with n the internal force of the last global step at that end
        (one iteration behind; docs/method.md §12), 1 + eps >= 0. Sets the clamped
        nodes' targets (1 + eps) tau3, tau3 = tau1 x tau2 (the local step's stretch there
        may be 0, its tau3 row then zero), and the prescribed slope of the next global
        step, in the P2 problem and in the seabed's and the friction's Hermite problems.
        Collective."""
        mesh, state = self.mesh, self.state
        force = self.internal_force()
        ends = ((self.start_state, 0, mesh.on_lower_boundary),
                (self.end_state, -1, mesh.on_upper_boundary))
        strain = np.zeros(2)
        for j, (end, index, owner) in enumerate(ends):
            if end.kind == "clamp" and owner and np.isfinite(self.axial[index]):
                strain[j] = force[index] @ end.frame[2] / self.axial[index]
        # k >= 0, as in the local step (a line is not turned inside out)
        stretch = np.maximum(1.0 + mesh.global_sum(strain), 0.0)
        for j, (end, index, owner) in enumerate(ends):
            if end.kind == "clamp" and owner:
                # tau3 = tau1 x tau2: the local step's stretch there may be 0
                targets = state.tau[index]
                targets[2] = stretch[j] * np.cross(targets[0], targets[1])
        self.global_step.set_clamp_stretch(*stretch)

    def end_strains(self, elements):
        """The one-sided strains at both ends of the given global ``elements`` (their
        dofs in this rank's ghosted vectors): (S (ne, 2), m, u (ne, 2, 3), 1/m), each
        element's own limit (u jumps across elements where the stiffness jumps at a
        section end, and by the discretisation elsewhere)."""
        mesh = self.mesh
        left = mesh.coordinates(elements)
        h = mesh.coordinates(elements + 1) - left
        ends = np.array([0.0, 1.0])
        values = self.state.evaluate(elements - mesh.ghost_start, p2_basis(ends, h),
                                     p2_integrals(ends, h))
        S = left[:, None] + ends[None, :] * h[:, None]
        return S, strains(values["directors"], values["derivatives"])

    def norms(self):
        """The change and RMS constraint residual of the last iteration, relative to the
        size of the deformation (§6, RodState.norms: a state.Norms; one allreduce)."""
        EVENTS["norms"].begin()
        try:
            return self.state.norms()
        finally:
            EVENTS["norms"].end()

    # --- the energy and its derivatives ------------------------------------------------
    def energy(self):
        """E = int w dS (the strains u of the FE fields and the stiffness K at the Gauss
        points; those of the pieces between section ends where K varies) plus every
        term's part (the work of the loads with its sign, the seabed's stored energy), J
        (§6). Collective."""
        tables, weights, stiffness = self._energy_rule
        p = (self.state.point_values() if tables is None
             else self.state.evaluate(self.mesh.element_local, *tables))
        u = strains(p["directors"], p["derivatives"])
        stored = 0.5 * np.sum(weights[:, :, None] * stiffness * u**2)
        return self.mesh.global_sum(stored) + sum(term.energy(self.state)
                                                  for term in self.terms)

    def _stored_energy_rule(self):
        """The quadrature of the stored energy int 1/2 K_i u_i^2 dS: (tables, weights,
        K). On a uniform line the state's Gauss points (tables None), self.weights and
        the constant triple (3,); otherwise the Gauss points of the pieces of each element
        between the section ends (elements.cut_gauss_rule, the pieces of the matrices),
        as (p2_basis, p2_integrals) tables at them, their weights and K there, (ne, nq, 3)."""
        mesh, scene = self.mesh, self.scene
        if scene.uniform_stiffness:
            return None, self.weights, scene.stiffness
        h = mesh.element_h
        xi, weights = cut_gauss_rule(mesh.element_S, h, scene.stiffness_breaks)
        tables = (p2_basis(xi, h), p2_integrals(xi, h))
        return tables, weights, scene.stiffness_at(mesh.element_S[:, None] + xi * h[:, None])

    def field_stiffness(self, i):
        """Field i's 2 a_i K as (factor, Mat) (GlobalStep.field_stiffness): on a uniform
        line the unit-coefficient K and 2 a_i, otherwise int 2 a_i(S) g_k' g_l' dS and 1."""
        return self.global_step.field_stiffness(i)

    def energy_gradient(self, work):
        """g_i = dE/dd_i at the owned P2 nodes, (n_nodes, 3, 3), with the fields of the
        state as the frames: 2 a_i K d_i (a_i varying along a line of sections) and the
        terms' (Term.add_gradient: -b on d3 for the loads; r is integrated from the fields
        first where a term reads the heights). ``work``: a Vec of K's layout for the
        products."""
        n = self.mesh.n_local_nodes
        g = np.empty((n, 3, 3))
        if any(term.position_components or term.follower for term in self.terms):
            # the centreline of the fields, whose positions those terms read
            self.global_step.integrate_slope(self.state)
        for i, field in enumerate(self.state.frame_fields):
            factor, stiffness = self.field_stiffness(i)
            for c, vec in enumerate(field.components):
                stiffness.mult(vec, work)
                g[:, i, c] = factor * work.getArray(readonly=True)[:n]
        for term in self.terms:
            term.add_gradient(g, self.state)
        return g

    def second_variation(self):
        """The second variation at the current state with its stability test
        (analysis/stability.StabilityTest, a SecondVariation): one object for the
        problem's life, made at the first call and updated at the next ones, so that its
        factorisations share one symbolic analysis (the stability test and every Newton
        step)."""
        if self._second_variation is None:
            self._second_variation = StabilityTest(self)
        else:
            self._second_variation.update()
        return self._second_variation

    def turn_to_canonical(self):
        """In an axially symmetric problem (``axially_symmetric``) turn the state about
        the axis to the canonical member of its family of equilibria
        (RodState.canonical_angle, docs/method.md §10); elsewhere nothing. Which member
        an iteration reaches depends on round-off that an accelerated iteration
        amplifies, so on the partition; the canonical one does not. Collective."""
        if not self.axially_symmetric:
            return
        angle = self.state.canonical_angle()
        if angle is not None:
            self.state.turn_about_axis(angle)

    # --- what the outputs read ----------------------------------------------------------
    def link(self):
        """Twist and writhe of the current state, (Tw, Wr) in turns, Lk = Tw + Wr
        (analysis/link.py); None when the scene has no common end axis or a tangent comes
        within FULLER_MARGIN of pointing back along it."""
        axis = self.scene.link_axis
        if axis is None:
            return None
        p = self.state.point_values()
        twist, writhe, margin = link_integrands(p["directors"], p["derivatives"], axis)
        tw, wr, backward = self.mesh.global_sum(np.array([
            np.sum(self.weights * twist), np.sum(self.weights * writhe),
            np.sum(margin < FULLER_MARGIN)]))
        return None if backward else (float(tw), float(wr))

    def end_reaction(self):
        """External force on the rod at S = L, N: the terms' shares (Term.end_force: the
        dead force at a free end; -(the whole load and P_0) at a held end when the start
        is free) less the chord multiplier mu when both ends are held. Collective."""
        shares = [term.end_force(self.state) for term in self.terms]
        return sum(share for share in shares if share is not None) - self.state.chord_multiplier

    def internal_force(self):
        """n(S) at the owned vertices, (n_owned, 3), N: the terms' shares
        (Term.force_beyond) less mu. Collective."""
        shares = [term.force_beyond(self.state) for term in self.terms]
        return sum(share for share in shares if share is not None) - self.state.chord_multiplier

    def outputs(self, vertex):
        """The TermOutputs of the terms, then of the reports, for the vertex fields
        ``vertex``, in list order (None left out). Collective."""
        outputs = [source.outputs(self, vertex) for source in (*self.terms, *self.reports)]
        return [output for output in outputs if output is not None]

    def units(self):
        """({dataset: unit}, {attribute: unit}) of what the terms' and the reports'
        outputs write (their dataset_units and attribute_units)."""
        datasets, attributes = {}, {}
        for source in (*self.terms, *self.reports):
            datasets.update(source.dataset_units)
            attributes.update(source.attribute_units)
        return datasets, attributes

    def destroy(self):
        if self._second_variation is not None:
            self._second_variation.destroy()
        self.global_step.destroy()
        for term in self.terms:
            term.destroy()
        self.state.destroy()
