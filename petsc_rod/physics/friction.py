"""Coulomb friction of the seabed in statics (docs/riser.md §3b), a term of physics
(physics/term.py) built beside the seabed's where -rod_seabed_friction is given.

The model (that of OrcaFlex's and RIFLEX's statics): at each grounded P2 node n, the
seabed holds the line's horizontal position x_n (2,) to an anchor a_n by an
elastic-perfectly-plastic spring: the friction per metre is

    f_n = -k_s (x_n - a_n)                 if |k_s (x_n - a_n)|_mu <= R_n   (stick),
    f_n = -k_s (x_n - a_n) R_n / |.|_mu    otherwise                        (slide),

with R_n the normal contact reaction (N/m, seabed_contact.SeabedContact.reaction), k_s the stick
stiffness (N/m^2, -rod_seabed_friction_stiffness) and |f|_mu the elliptic norm
sqrt((f.a / mu_a)^2 + (f.l / mu_l)^2) in the node's axial and lateral horizontal
directions a, l (so a sliding node is resisted by mu R, mu between mu_a along the line
and mu_l across it, opposite its slip). On a seabed that is not flat the friction lies in
its tangent plane: its horizontal part is f, its vertical part g.f (g = grad z_b), and
the norm is that of the whole force, |f|_mu sqrt(1 + (g.f)^2 / |f|^2) (so a block on an
incline of angle theta sticks up to tan(theta) = mu).

Friction depends on the path: the anchors are the line as laid. From a run's start
(problem/build.lay_friction_anchors) they are the catenary between the ends the user
gave, at every load step's load factor t and whatever the start shape (``laying``, laid
by ``prepare``): the load steps are a numerical continuation from the straight
reference, no history of the line, and the answer is the equilibrium relative to the
line as laid, whatever the number of steps (a line given from its fairlead hangs clear
of the seabed in its first steps, and anchors moved there are where its nodes hung, not
where they land). Otherwise (a
restart, whose file's positions are the anchors, or where no catenary can be drawn, the
nodes' positions where the run starts) at the end of every accepted load step each
anchor moves to x_n + f_n / k_s (the return map of plasticity: a sticking node keeps
its anchor, a sliding one drags it along, a node off the seabed carries none). A line of
a system holds its anchors where its first solve started (``hold_anchors``,
system/held_line.py): its equilibrium is a function of its ends.

In the global step the friction is implicit, like the seabed: x and y are solved in
Hermite dofs (global_step/hermite.py), where a spring on a node's position is banded, in place of
the P2 solve of their slopes, with a spring k_n w_n toward its anchor at every node: k_s
at a sticking node, the secant k_s R_n / |k_s (x_n - a_n)|_mu at a sliding one (whose
force is then the sliding friction). The springs are those of the last solve's positions
and the loop solves again until none changes by more than SECANT_RTOL k_s: the secant
(Kacanov) iteration, of a convex problem for an isotropic mu and given R (with mu_a !=
mu_l the law has no convex potential), which never carries a node past its anchor.
A sliding force held fixed instead flipped its sign from one solve to the next and the
map cycled (docs/riser.md §3b). The contact reaction is that of the same
global step's vertical solve (the seabed term comes first). Why implicit: an explicit
(lagged) spring k_s on a grounded stretch is amplified k_s l^2 / R per iteration
(global_step/seabed_contact.py).

In the Newton steps (docs/method.md §11, "Terms of the positions"), with one
coefficient (mu_a = mu_l), on any seabed (flat, a sloping plane, a profile or a grid:
below): within a load step the anchors
are fixed, and the law above is a function of the node positions, f_n(x_n, z_n), through
d_n = x_n - a_n and R_n = k (z_b - z_n)_+. Its work enters the gradient like the
seabed's energy, -w_n f_n on the horizontal positions, carried by their chains
(analysis/positions.py; ``position_components`` (0, 1)), and its derivative -w_n df_n is
the Newton system's block of the friction (a semi-smooth Newton step: stick, slide and
off the seabed those of the iterate):

    stick:  w_n k_s I,
    slide:  w_n R_n / |d_n|_mu (I - d_n (M_n d_n)^T / |d_n|_mu^2)   on x_n,
            -w_n k d_n / |d_n|_mu                                   on z_n,

with |d|_mu^2 = d^T M d, M = a a^T / mu_a^2 + l l^T / mu_l^2 (with one coefficient
M = I / mu^2 and the slide's block is symmetric). It goes into H (the safeguard and the
stability test see the friction with its limit held at its current value); the z column
(the limit follows the contact reaction) into the unsymmetric Newton Jacobian
(``unsymmetric``; analysis/jacobian.py). With mu_a != mu_l the slide's block is
unsymmetric, its symmetric part indefinite where the slip is oblique to the line, and
the turn of the axes a, l with the tangent, left out, is of the order of R: the steps
failed there (docs/riser.md §3b), so such a run takes none (``in_newton``).

On a sloping plane z_b = z_0 + g.x (g constant) the force is F_n = (f_n, g.f_n) on
(x_n, z_n), its size |d|_G = sqrt(d^T G d) / mu with G = I + g g^T (the tangent-plane
norm above), and the limit R_n = k cos(theta) (z_b(x_n) - z_n)_+ follows x_n as well as
z_n (_plane_law): -w dF/d(x, z) has rows (I; g^T) times

    stick:  w_n k_s I                                                     on x_n,
    slide:  w_n [R_n / |d|_G (I - d (G d)^T / (mu^2 |d|_G^2))
                 + k cos(theta) d g^T / |d|_G]                            on x_n,
            -w_n k cos(theta) d / |d|_G                                   on z_n.

H takes the limit held and the slip's turn in the horizontal plane,
w_n R_n / |d|_G (I - d d^T / |d|^2), which is positive semidefinite; J the rest. The
global step carries g.f as its work through the heights' chain (add_iterate_load), so
that its fixed point is the Newton steps' stationary point. Not conservative: friction
dissipates, so the run gives no stability verdict (as with the drag).

On a seabed profile or grid the global step's fixed point (the contact's heights and
gradients lagged, slope_load.py) has the plane's law with each node's own secant
gradient g = g(x) (2,) (environment/bathymetry.py), cos(theta) = 1 / sqrt(1 + |g|^2),
and limit R = k cos(theta) p, p = (z_b(x) - z)_+ under the interpolant z_b (m). The
Newton steps take that fixed point's derivative (_plane_law, _shape_rates), so their
stationary point is the iteration's: the plane's block with, per grounded node,

    dR/dx = k cos(theta) (grad z_b - p cos^2(theta) Dg^T g)   (2,), N/m^2, in place of
            the plane's k cos(theta) g (d cos/dx = -cos^3 Dg^T g),
    mu^2 |d|_G d|d|_G/dx = G d + (g.d) Dg^T d                 (2,), m, in place of G d
            (from mu^2 |d|_G^2 = d.d + (g.d)^2),
    d(g.f)/dx = g^T df/dx + f^T Dg                            (2,), N/m^2: the vertical
            row -w d(g.f)/dx is g^T times the horizontal rows less w f^T Dg,

grad z_b (2,) the interpolant's own slope (1), Dg_ij = dg_i/dx_j (2, 2) the secant's
derivative (1/m), both from Seabed.plan_slopes: on a grid the bilinear cells' slopes
and Dg in two directions (bathymetry.Grid.slopes), on a profile along its direction e,
Dg = g' e e^T (Profile.slopes). Farther than delta/2 from every row or grid line Dg is
a profile's 0 and a grid cell's twist (its off-diagonal), and the block is the plane's
with the node's own g where Dg = 0. Unsymmetric: H takes its share as on a plane, J
the rest. A line of a system takes the same block for its stiffness (``held_exact``).
"""

import numpy as np

from petsc_rod.analysis.positions import HEIGHT
from petsc_rod.global_step.hermite import HermiteProblem, slope_map
from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.global_step.seabed_contact import MAX_SOLVES, node_rows, owned_nodes
from petsc_rod.mesh.elements import NODE_WEIGHTS
from petsc_rod.physics.nodal_load import NodalLoadTerm
from petsc_rod.physics.term import TermOutput

# The secant loop of one global step ends when no node's spring changed by more than
# this times k_s (the next global step starts from the last springs): a tighter bound
# costs solves without saving iterations (docs/riser.md §3b).
SECANT_RTOL = 1e-2

# The KSP options prefixes of the x and y problems.
PREFIXES = ("rod_x_", "rod_y_")

# Units of the datasets and attributes this module adds to the result file.
DATASET_UNITS = {"friction_force": "N/m", "friction_state": "1"}
ATTRIBUTE_UNITS = {"friction_stick_length": "m", "friction_slide_length": "m",
                   "friction_max_force": "N/m", "friction_max_use": "1",
                   "friction_stick_nodes": "1", "friction_slide_nodes": "1",
                   "friction_stick_max_use": "1", "friction_band": "m"}

# friction_state at a vertex: off the seabed, sticking, sliding
OFF, STICK, SLIDE = 0, 1, 2


def elliptic_norm(force, tangents, friction):
    """|f|_mu = sqrt((f.a / mu_a)^2 + (f.l / mu_l)^2), (...), of horizontal forces
    ``force`` (..., 2) with a the unit horizontal part of ``tangents`` (..., 2) and l
    a turned by 90 degrees (a = e_x where the tangent is vertical: there the norm is
    taken isotropic in mu_l, a grounded line being near horizontal)."""
    length = np.linalg.norm(tangents, axis=-1, keepdims=True)
    axial = np.divide(tangents, length, out=np.zeros_like(tangents), where=length > 0)
    axial[length[..., 0] == 0] = (1.0, 0.0)
    along = np.einsum("...c,...c->...", force, axial)
    across = force[..., 1] * axial[..., 0] - force[..., 0] * axial[..., 1]
    return np.hypot(along / friction.axial, across / friction.lateral)


def tangent_factor(force, gradients):
    """|f_t| / |f| = sqrt(1 + (g.f)^2 / |f|^2), (...): the friction's whole size over
    that of its horizontal part f (..., 2) on a seabed of gradient g (..., 2); 1 where
    f = 0 or the seabed is flat (``gradients`` None)."""
    if gradients is None:
        return np.ones(force.shape[:-1])
    size = np.einsum("...c,...c->...", force, force)
    rise = np.einsum("...c,...c->...", force, gradients)
    return np.sqrt(1.0 + np.divide(rise**2, size, out=np.zeros_like(size), where=size > 0))


class FrictionTerm(NodalLoadTerm):
    """The seabed friction of the SeabedTerm ``seabed_term`` (module docstring)."""

    dataset_units = DATASET_UNITS
    attribute_units = ATTRIBUTE_UNITS

    slope_components = position_components = (0, 1)
    chains_from_end = True
    conservative = False
    unsymmetric = True
    # the recorded force, reactions and use are the last global step's (_record): a
    # step that Newton steps finish ends at the iteration after them (Term)
    outputs_of_state = False
    newton_gap = "seabed friction with two coefficients (docs/riser.md §3b)"

    def __init__(self, mesh, seabed_term):
        super().__init__(mesh, "friction")
        self.seabed_term = seabed_term
        self.friction = seabed_term.seabed.friction         # environment.Friction
        h = mesh.element_h
        self.weights = h[:, None] * NODE_WEIGHTS[None, :]          # (ne, 3)
        self.rows = node_rows(h)                                    # positions (ne, 3, 4)
        self.slope_rows = slope_map(h)                              # slopes (ne, 3, 4)
        self.problems = []
        ne = mesh.n_local_elements
        self.anchors = None                 # a_n (ne, 3, 2): from the first solve's start
        self.spring = np.zeros((ne, 3))             # k_n, N/m^2: k_s (stick), the secant
        self.force = np.zeros((ne, 3, 3))   # f at the last solve's positions, with g.f
        self.positions = None                       # x_n (ne, 3, 2) of the last solve
        self.reaction = np.zeros((ne, 3))           # R_n of the last solve
        self.use = np.zeros((ne, 3))                # |f|_mu / R of the last solve
        self.load = NodalLoad(mesh, self._nodes)
        self._local = mesh.da.createLocalVec()
        # the state may have been set by Newton steps (add_gradient ran since the last
        # global step): the next global step's springs are those of its positions
        # (solve_slope; after an attempt that failed, those of the restored state, the
        # last solve's)
        self._springs_stale = False
        # the anchors stay where the first solve put them (accept_step moves none): a
        # line of a system, whose equilibrium is then a function of its ends alone
        # (system/held_line.py)
        self.hold_anchors = False
        # the line as laid between the user's ends (S -> (r, frame, force)): the
        # anchors of every load step, which no step's end moves (prepare, accept_step;
        # problem/build.lay_friction_anchors); None: the return map's path from the
        # first solve's start or a restart's file
        self.laying = None
        self._held = None           # H's share on a plane of the last _plane_law (n, 2, 2)

    @property
    def in_newton(self):
        """With one coefficient, on any seabed: flat, a sloping plane, a profile or a
        grid (the law's derivatives with g read at each node and its turn,
        _shape_rates; module docstring)."""
        return self.friction.axial == self.friction.lateral

    @property
    def held_exact(self):
        """Whether a held line's stiffness with this friction is exact
        (system/held_line.py): where the Newton steps take it (``in_newton``), their
        block the derivative of the line's own fixed point."""
        return self.in_newton

    # --- the global step --------------------------------------------------------------
    def build(self, slope_matrices, penalty):
        """The x and y problems with the slope problem's element matrices (at the start
        and after every penalty raise; the anchors and the springs are kept)."""
        self._destroy_problems()
        x = HermiteProblem(self.mesh, slope_matrices, PREFIXES[0], 0)
        # y shares x's matrix (the same springs on both): factored once for both
        self.problems = [x, HermiteProblem(self.mesh, slope_matrices, PREFIXES[1], 1,
                                           matrix_of=x)]
        if self.start_state is not None:
            for problem in self.problems:
                problem.set_end_states(self.start_state, self.end_state)

    def ksps(self):
        return [problem.ksp for problem in self.problems]

    def set_clamp_stretch(self, start, end):
        for problem in self.problems:
            problem.set_clamp_stretch(start, end)

    def prepare(self, t, start, end):
        """The step's end states in both problems; with a ``laying``, the anchors at the
        line as laid (the same at every load factor t)."""
        super().prepare(t, start, end)
        if self.laying is not None and not self.hold_anchors:
            self.lay_anchors(self.laying)
        for problem in self.problems:
            problem.set_end_states(start, end)

    def add_iterate_load(self, rhs, state):
        """On a seabed that is not flat: the friction's vertical part g.f of the last
        solve on the slope's right-hand side (its z part, which the seabed's vertical
        problem solves; lagged like the slope's push, slope_load.py), as its work
        sum_n w_n (g.f)_n z_n through the heights' chain: the form of the Newton steps'
        gradient, so that the global step's fixed point is their stationary point (the
        P2 interpolant's int F.g differs by O(h^2)). Collective."""
        if self.seabed_term.seabed.flat:
            return
        if self._springs_stale:
            # after Newton steps: the friction at their positions (the last solve's is
            # that of the state before them)
            work = -self._newton_law(state)[0][:, 2]
        else:
            work = owned_nodes(self.mesh, self.force[..., 2]) * state.node_weights
        gradient = np.zeros((work.shape[0], 3, 3))
        self.add_position_gradient(gradient, state, {HEIGHT: -work})
        rhs.components[HEIGHT].getArray()[:work.shape[0]] -= gradient[:, 2, HEIGHT]

    def solve_slope(self, rhs, state, bordered):
        """x' and y' from the Hermite problems with the friction (module docstring): the
        secant loop over the nodes' springs; with both ends held their part of the chord
        multiplier. Collective."""
        contact = self.seabed_term.contact
        reaction = contact.reaction()
        gradients = contact.gradients
        if self.anchors is None:            # the start: the run's first global step
            r = state.r.ghosted()
            self.anchors = self._node_values([r[:, :, 0], r[:, :, 1]], self.rows)
        stiffness = self.friction.stiffness
        if self._springs_stale:
            self._springs_from(state, reaction)
        for c, problem in enumerate(self.problems):
            problem.project(rhs.components[c])          # b is the same at every pass
        for _ in range(MAX_SOLVES):
            self._set_springs()
            solutions = [self._ghosted(problem.solve_projected()) for problem in self.problems]
            positions = self._node_values(solutions, self.rows)
            tangents = self._node_values(solutions, self.slope_rows)
            trial = -stiffness * (positions - self.anchors)
            size = (elliptic_norm(trial, tangents, self.friction)
                    * tangent_factor(trial, gradients))
            spring = stiffness * np.divide(reaction, np.maximum(size, reaction),
                                           out=np.zeros_like(size), where=reaction > 0)
            change = self.mesh.global_max(float(np.max(np.abs(spring - self.spring),
                                                       initial=0.0)))
            self.spring = spring
            if change <= SECANT_RTOL * stiffness:
                break
        # the return map at the solved positions (the springs just updated): |f|_mu <= R
        # holds to round-off, where the force the solve carried (its springs one pass
        # behind) exceeds it by their last change (docs/riser.md §3b, "Outputs")
        force = -self.spring[..., None] * (positions - self.anchors)
        self._record(force, positions, tangents, reaction, gradients)
        for c, problem in enumerate(self.problems):     # the slopes of the last pass's y
            problem.set_slope(state.slope.components[c])
        if bordered:
            for c, problem in enumerate(self.problems):
                state.chord_multiplier[c] = problem.end_residual()

    def _record(self, force, positions, tangents, reaction, gradients):
        """Keep the friction ``force`` at the last solve's positions (the return map;
        with its vertical part g.f; the internal force, the outputs, the next step's
        anchors and a slope's lagged vertical load read it), positions, reactions and
        use |f|_mu / R."""
        self.positions, self.reaction = positions, reaction
        self.force[..., :2] = force
        self.force[..., 2] = (0.0 if gradients is None
                              else np.einsum("enc,enc->en", force, gradients))
        size = elliptic_norm(force, tangents, self.friction) * tangent_factor(force, gradients)
        self.use = np.divide(size, reaction, out=np.zeros_like(size), where=reaction > 0)

    def _springs_from(self, state, reaction):
        """The secant springs of the state's positions (those of the P2 slope's integral,
        RodState.node_positions) and the reactions ``reaction`` (ne, 3): after Newton
        steps, so that the global step that follows them starts from their friction and
        keeps their fixed point. Collective (a ghost exchange)."""
        self.load.set(state.node_positions())
        positions = self.load.element_values[..., :2].copy()
        self.load.set(state.node_directors()[:, 2])
        tangents = self.load.element_values[..., :2].copy()
        self._springs_from_positions(positions, tangents, reaction)
        self._springs_stale = False

    def _springs_from_positions(self, positions, tangents, reaction, gradients=False):
        """The secant springs (ne, 3) of the element nodes' horizontal ``positions``
        (ne, 3, 2), ``tangents`` (ne, 3, 2) and reactions ``reaction`` (ne, 3), on the
        seabed's ``gradients`` g (ne, 3, 2; None: flat; default the contact's, those of
        the last global step)."""
        if gradients is False:
            gradients = self.seabed_term.contact.gradients
        trial = -self.friction.stiffness * (positions - self.anchors)
        size = (elliptic_norm(trial, tangents, self.friction)
                * tangent_factor(trial, gradients))
        self.spring = self.friction.stiffness * np.divide(
            reaction, np.maximum(size, reaction), out=np.zeros_like(size), where=reaction > 0)

    def snapshot(self):
        """Copies of what the last solve left: the springs, the recorded force,
        positions, reactions and use (``_record``), so that a state restored to an
        earlier one (a held line's walk that failed, HeldLine._walk) reads its own
        friction, not the failed solve's (``restore``)."""
        return (self.spring.copy(), self.force.copy(),
                None if self.positions is None else self.positions.copy(),
                self.reaction.copy(), self.use.copy(), self._springs_stale)

    def restore(self, saved):
        """Put back what ``snapshot`` copied."""
        (self.spring, self.force, self.positions, self.reaction, self.use,
         self._springs_stale) = saved

    def lay_anchors(self, curve):
        """The anchors at the line as laid along ``curve`` (S -> (r, frame, force),
        scenes/starts.py), at every P2 node of the owned elements: its horizontal
        positions there (a run's start, problem/build.lay_friction_anchors)."""
        mesh = self.mesh
        S = mesh.element_S[:, None] + np.array([0.0, 0.5, 1.0]) * mesh.element_h[:, None]
        positions = curve(S.ravel())[0]
        self.anchors = positions[:, :2].reshape(S.shape + (2,)).copy()

    def holds(self, state):
        """Whether the friction acts on the state: some node on the seabed, on any rank
        (the law's derivative non-zero there). What the state is left for where H has a
        negative direction (driver.UzawaSolver.checks_curvature): the slide's
        dissipation is not in H, and a grounded line pushed across a sloping seabed is
        held by it where H has a negative direction (tests/solver/test_friction_newton.py).
        Collective."""
        if self.anchors is None:
            return False
        grounded = np.abs(self._newton_law(state)[1]).sum(axis=(1, 2)) > 0
        return self.mesh.global_sum(float(np.count_nonzero(grounded))) > 0

    @property
    def stick(self):
        """The nodes whose spring is the stick stiffness (ne, 3): grounded and within
        their limit."""
        return self.spring >= self.friction.stiffness

    def _set_springs(self):
        """The springs k_n w_n in both problems' matrices and k_n w_n a_n on their
        right-hand sides, (ne, 4, 4) and (ne, 4) per component (set_added: only the
        elements whose spring changed are added again; the solve refactors). Collective."""
        spring = self.spring * self.weights                                          # (ne, 3)
        transposed = self.rows.transpose(0, 2, 1)                                     # (ne, 4, 3)
        matrices = np.matmul(transposed * spring[:, None, :], self.rows)
        vectors = np.einsum("ekn,enc->cek", transposed, spring[..., None] * self.anchors)
        for problem, vector in zip(self.problems, vectors):
            problem.set_added(matrices, vector)

    def _node_values(self, ghosted, rows):
        """rows (ne, 3, 4) applied to each element's Hermite dofs, (ne, 3, 2), from the
        ghosted (value, slope) pairs (n_ghosted, 2) of x and y in ``ghosted``."""
        return np.stack([np.einsum("enk,ek->en", rows,
                                   np.concatenate(self.mesh.element_ends(pairs), axis=1))
                         for pairs in ghosted], axis=2)

    def _ghosted(self, vec):
        """The ghosted (value, slope) pairs of the Hermite solution ``vec``, (n_ghosted, 2)
        (a copy). Collective (a ghost exchange)."""
        self.mesh.da.globalToLocal(vec, self._local)
        return self._local.getArray(readonly=True).reshape(-1, 2).copy()

    # --- the Newton steps (module docstring) -------------------------------------------
    def _newton_law(self, state):
        """The law at the state's centreline (the frames' integral: the Newton steps), at
        the owned nodes: (-w_n F_n (n, m), N, the derivative of -w F in x (n, m, 2) and
        in z (n, m), N/m), F = f (m = 2) on a flat seabed, (f, g.f) (m = 3) on a sloping
        plane (module docstring)."""
        seabed = self.seabed_term.seabed
        r = state.node_positions().copy()
        tangents = state.node_directors()[:, 2, :2].copy()
        w = state.node_weights
        d = r[:, :2] - owned_nodes(self.mesh, self.anchors)
        stiffness = self.friction.stiffness
        if not seabed.flat:
            return self._plane_law(r, d, w)
        reaction = seabed.push(r[:, 2])
        norm = elliptic_norm(d, tangents, self.friction)                  # |d|_mu
        slide = (reaction > 0) & (stiffness * norm > reaction)
        stick = (reaction > 0) & ~slide
        force = np.where(stick[:, None], -stiffness * d, 0.0)
        scale = np.divide(reaction, norm, out=np.zeros_like(norm), where=slide)
        force[slide] = -(scale[:, None] * d)[slide]
        # M d: the metric's image of d, along a and l of the horizontal tangent
        length = np.linalg.norm(tangents, axis=1, keepdims=True)
        axial = np.divide(tangents, length, out=np.zeros_like(tangents), where=length > 0)
        axial[length[:, 0] == 0] = (1.0, 0.0)
        lateral = np.stack([-axial[:, 1], axial[:, 0]], axis=1)
        metric = (np.einsum("nc,nc->n", axial, d)[:, None] * axial / self.friction.axial**2
                  + np.einsum("nc,nc->n", lateral, d)[:, None] * lateral
                  / self.friction.lateral**2)
        squared = np.where(slide, norm**2, 1.0)
        in_x = (stick * stiffness)[:, None, None] * np.eye(2) + scale[:, None, None] * (
            np.eye(2) - d[:, :, None] * metric[:, None, :] / squared[:, None, None])
        in_z = -seabed.stiffness * np.divide(d, norm[:, None], out=np.zeros_like(d),
                                             where=slide[:, None])
        return -w[:, None] * force, w[:, None, None] * in_x, w[:, None] * in_z

    def _plane_law(self, r, d, w):
        """_newton_law on a sloping plane z_b = z_0 + g.x with one coefficient mu: the
        norm of the whole force |d|_G = sqrt(d^T G d) / mu, G = I + g g^T, and the limit
        R = k cos(theta) (z_b - z)_+ (Seabed.reaction), whose derivatives in x and z are
        k cos(theta) g and -k cos(theta) on the contact. Stick f = -k_s d; slide
        f = -R d / |d|_G, whose derivative in x is
        -R / |d|_G (I - d (G d)^T / (mu^2 |d|_G^2)) - d (k cos(theta) g)^T / |d|_G and in
        z d k cos(theta) / |d|_G; the vertical part g.f has g^T times them. On a
        profile or grid g is each node's secant gradient and the derivatives take
        its turn (_shape_rates). Returns (-w F (n, 3), -w dF/dx (n, 3, 2),
        -w dF/dz (n, 3)), N and N/m."""
        seabed = self.seabed_term.seabed
        mu, stiffness = self.friction.lateral, self.friction.stiffness
        g = seabed.gradients(r[:, 0], r[:, 1])                            # (n, 2)
        cosine = 1.0 / seabed.slope_factor(g)
        reaction = seabed.reaction(r)
        contact = reaction > 0
        metric = d + g * np.einsum("nc,nc->n", g, d)[:, None]              # G d
        norm = np.sqrt(np.einsum("nc,nc->n", d, metric)) / mu             # |d|_G
        slide = contact & (stiffness * norm > reaction)
        stick = contact & ~slide
        force = np.where(stick[:, None], -stiffness * d, 0.0)
        scale = np.divide(reaction, norm, out=np.zeros_like(norm), where=slide)
        force[slide] = -(scale[:, None] * d)[slide]
        squared = np.where(slide, mu**2 * norm**2, 1.0)
        limit = np.divide(seabed.stiffness * cosine, norm, out=np.zeros_like(norm),
                          where=slide)                                    # k cos / |d|_G
        lift = turn = None
        if seabed.shaped:
            lift, turn, metric = self._shape_rates(r, d, g, cosine, metric)
        in_x = ((stick * stiffness)[:, None, None] * np.eye(2)
                + scale[:, None, None] * (np.eye(2) - d[:, :, None] * metric[:, None, :]
                                          / squared[:, None, None])
                + limit[:, None, None] * d[:, :, None] * (g if lift is None
                                                          else lift)[:, None, :])
        in_z = -limit[:, None] * d
        # H's share, the limit held and the slip's turn measured in the horizontal plane:
        # positive semidefinite (the symmetric part of in_x is not: the d g^T of the
        # limit and G's oblique projection); J carries the rest (add_jacobian)
        length = np.where(slide, np.einsum("nc,nc->n", d, d), 1.0)
        self._held = w[:, None, None] * (
            (stick * stiffness)[:, None, None] * np.eye(2)
            + scale[:, None, None] * (np.eye(2) - d[:, :, None] * d[:, None, :]
                                      / length[:, None, None]))
        rise = np.einsum("nc,nc->n", g, force)
        vertical = np.einsum("nc,ncj->nj", g, in_x)
        if turn is not None:                # g.f with g turning: -f^T Dg
            vertical -= np.einsum("ni,nij->nj", force, turn)
        return (-w[:, None] * np.concatenate([force, rise[:, None]], axis=1),
                w[:, None, None] * np.concatenate([in_x, vertical[:, None]], axis=1),
                w[:, None] * np.concatenate([in_z, np.einsum("nc,nc->n", g, in_z)[:, None]],
                                            axis=1))

    def _shape_rates(self, r, d, g, cosine, metric):
        """What a seabed profile or grid (SeabedTerm.profile) adds to _plane_law's
        derivatives, at node positions r (n, 3) and slips d (n, 2), with the secant
        gradient g (n, 2), cos(theta) = 1 / sqrt(1 + |g|^2) (n,) and G d (n, 2): the
        derivative of the fixed point of the line's own iterations, whose friction is
        the plane's law with g = g(x) read at each node (module docstring). With
        grad z_b the interpolant's own slope (n, 2), Dg_ij = dg_i/dx_j the secant's
        derivative (n, 2, 2), 1/m (Seabed.plan_slopes: a grid's bilinear slopes; a
        profile's g' e e^T) and p = (z_b - z)_+ the penetration (n,), m, it returns

            lift = grad z_b - p cos^2(theta) Dg^T g    (n, 2), 1: dR/dx = k cos(theta)
                   lift, as R = k cos(theta) p with d cos/dx = -cos^3 Dg^T g,
            Dg                                         (n, 2, 2), 1/m: dg/dx (the
                   vertical part g.f turns: -w f^T Dg in its row on x),
            G d + (g.d) Dg^T d                         (n, 2), m: mu^2 |d|_G
                   d|d|_G/dx, from mu^2 |d|_G^2 = d.d + (g.d)^2.

        On a plane Dg = 0, lift = g and the rest is the plane's; on a profile
        Dg^T g = g' (g.e) e and Dg^T d = g' (d.e) e."""
        seabed = self.seabed_term.seabed
        rise, _, rate = seabed.plan_slopes(r[:, 0], r[:, 1])
        depth = seabed.penetration(r[:, 2], seabed.heights(r[:, 0], r[:, 1]))
        lift = rise - (depth * cosine**2)[:, None] * np.einsum("nij,ni->nj", rate, g)
        metric = metric + (np.einsum("nc,nc->n", g, d)[:, None]
                           * np.einsum("nij,ni->nj", rate, d))
        return lift, rate, metric

    def add_gradient(self, g, state):
        """-w_n f_n on the horizontal positions, into g's d3 x and y rows through their
        chains (NodalLoadTerm.add_position_gradient), at the state's centreline (the
        frames' integral, RodProblem.energy_gradient). Collective."""
        self._springs_stale = True
        if self.anchors is None:            # no global step yet: no reference
            return
        derivative = self._newton_law(state)[0]
        self.add_position_gradient(g, state, {c: derivative[:, c]
                                              for c in range(derivative.shape[1])})

    def add_hessian(self, hessian):
        """The symmetric part of -w_n df_n/dx_n on the horizontal positions (module
        docstring)."""
        if self.anchors is None:
            return
        in_x = self._newton_law(hessian.problem.state)[1][:, :2]
        held = (self._held if not self.seabed_term.seabed.flat
                else 0.5 * (in_x + in_x.transpose(0, 2, 1)))
        hessian.add_position_curvature(held, self.position_components)

    def add_jacobian(self, jacobian):
        """J beyond H: the antisymmetric part of -w_n df_n/dx_n (zero on a flat seabed
        with one coefficient) and its column on the heights (the limit mu R following
        the contact reaction), which the seabed's chain carries (the seabed term reads
        them); on a sloping plane all of -w dF/d(x, z) but H's share (_plane_law), with
        the rows of the heights (the vertical part g.f)."""
        if self.anchors is None:
            return
        hessian = jacobian.hessian
        _, in_x, in_z = self._newton_law(hessian.problem.state)
        rest = np.concatenate([in_x, in_z[:, :, None]], axis=2)
        horizontal = in_x[:, :2]
        if self.seabed_term.seabed.flat:
            rest[:, :2, :2] = 0.5 * (horizontal - horizontal.transpose(0, 2, 1))
        else:
            rest[:, :2, :2] -= self._held
        rows = self.position_components + ((HEIGHT,) if rest.shape[1] == 3 else ())
        for rows, columns, blocks in hessian.position_blocks(
                rest, rows, self.position_components + (HEIGHT,)):
            jacobian.add(rows, columns, blocks)

    def position_derivatives(self, state):
        """The whole derivative of -w_n f_n (the friction's share of the gradient on the
        horizontal positions) in the node's position (x, y, z), (n_nodes, 2, 3), N/m, at
        the owned nodes of the state's centreline: the Newton system's block (module
        docstring) with its z column (a line's end stiffness, system/held_line.py:
        the gradient's move when the whole line is shifted over fixed anchors)."""
        _, in_x, in_z = self._newton_law(state)
        return np.concatenate([in_x, in_z[:, :, None]], axis=2)

    def follow_state(self, state):
        """Record the friction of the state's own positions (the law of the Newton
        steps at fixed anchors) as if a global step had solved them: after Newton steps
        that no global step follows (HeldLine.settle), the internal force and the end
        forces read the friction of the state they stand at: the reaction of each
        node's whole position, k (z_b - z)_+ cos(theta) (Seabed.reaction), the
        tangent plane's factor and the vertical part g.f with its own gradient g (a
        profile's or grid's secant there, not the last global step's).
        Collective (a ghost exchange)."""
        if self.anchors is None:
            return
        seabed = self.seabed_term.seabed
        self.load.set(state.node_positions())
        nodes = self.load.element_values.copy()                     # (ne, 3, 3)
        self.load.set(state.node_directors()[:, 2])
        tangents = self.load.element_values[..., :2].copy()
        reaction = seabed.reaction(nodes.reshape(-1, 3)).reshape(nodes.shape[:2])
        gradients = None if seabed.flat else seabed.gradients(nodes[..., 0], nodes[..., 1])
        self._springs_from_positions(nodes[..., :2], tangents, reaction, gradients)
        force = -self.spring[..., None] * (nodes[..., :2] - self.anchors)
        self._record(force, nodes[..., :2], tangents, reaction, gradients)

    # --- the load path --------------------------------------------------------------
    def accept_step(self, state):
        """At the end of an accepted load step: every anchor to x_n + f_n / k_s of the
        last solve (the return map: a sticking node keeps its anchor, a sliding one's
        follows it, a node off the seabed has its own position); none where the anchors
        are held (``hold_anchors``) or laid for every step (``laying``)."""
        if self.positions is not None and not self.hold_anchors and self.laying is None:
            self.anchors = self.positions + self.force[..., :2] / self.friction.stiffness

    # --- outputs --------------------------------------------------------------------
    def node_loads(self, state):
        """The friction per metre at the owned P2 nodes of the last solve (N/m),
        (n_nodes, 3), for the internal force (NodalLoadTerm.force_beyond)."""
        return owned_nodes(self.mesh, self.force)

    def path_numbers(self):
        """How far the equilibrium is one of many (docs/riser.md §3b, "The path"): a
        sticking node balances anywhere within |k_s (x_n - a_n)|_mu <= R_n of its anchor,
        so another load path from the as-laid line could leave it elsewhere in that
        band. Returns (sticking P2 nodes, sliding P2 nodes, the largest use
        |f|_mu / R_n of a sticking node (its mobilisation, 1 at the slide), the largest
        band max(mu_a, mu_l) R_n / k_s of a sticking node, m), over the whole line (0
        where nothing sticks). Collective."""
        mesh = self.mesh
        grounded = owned_nodes(mesh, self.reaction) > 0
        stick = (owned_nodes(mesh, self.stick) > 0) & grounded
        counts = mesh.global_sum(np.array([np.count_nonzero(stick),
                                           np.count_nonzero(grounded & ~stick)], dtype=float))
        use = owned_nodes(mesh, self.use)[stick]
        band = (max(self.friction.axial, self.friction.lateral) / self.friction.stiffness
                * owned_nodes(mesh, self.reaction)[stick])
        return (int(counts[0]), int(counts[1]),
                mesh.global_max(float(use.max(initial=0.0))),
                mesh.global_max(float(band.max(initial=0.0))))

    def outputs(self, problem, vertex):
        """The friction force and state (off, stick, slide) at the vertices; the grounded
        lengths that stick and slide (Simpson weights of the P2 nodes), the largest
        friction per metre, the largest use |f|_mu / R and the path's numbers
        (path_numbers). Collective."""
        mesh = self.mesh
        grounded = self.reaction > 0
        stick = self.stick & grounded
        lengths = mesh.global_sum(np.array([np.sum(self.weights * stick),
                                            np.sum(self.weights * (grounded & ~stick))]))
        size = np.linalg.norm(self.force, axis=2)
        largest = mesh.global_max(float(size.max()) if size.size else 0.0)
        use = mesh.global_max(float(self.use.max()) if self.use.size else 0.0)
        stick_nodes, slide_nodes, stick_use, band = self.path_numbers()
        state = np.where(grounded, np.where(self.stick, STICK, SLIDE), OFF)
        vertices = owned_nodes(mesh, np.stack([self.force[..., c] for c in range(3)] + [state],
                                              axis=2))[0::2]
        attributes = {"friction_stick_length": float(lengths[0]),
                      "friction_slide_length": float(lengths[1]),
                      "friction_max_force": largest, "friction_max_use": use,
                      "friction_stick_nodes": stick_nodes, "friction_slide_nodes": slide_nodes,
                      "friction_stick_max_use": stick_use, "friction_band": band}
        text = (f"friction: {lengths[0]:.6g} m stick, {lengths[1]:.6g} m slide, largest "
                f"{largest:.4g} N/m")
        return TermOutput({"friction_force": vertices[:, :3],
                           "friction_state": vertices[:, 3].astype(np.int32)},
                          attributes, text)

    def _destroy_problems(self):
        for problem in self.problems:
            problem.destroy()
        self.problems = []

    def destroy(self):
        self._destroy_problems()
        self._local.destroy()
        super().destroy()
