"""One line of a system as a component: held at its two ends, solved again whenever
they move (warm-started from its last equilibrium), with the forces it exerts on them
and their exact linearisation in the ends' positions (docs/method.md §13).

**The line as a function of its ends.** With q the line's unknowns (the nodes'
rotations, their stretch on an extensible line, and the positions' chains where a term
reads the positions: analysis/positions.py), the equilibrium with the ends at x_a
(S = 0) and x_b (S = L) is the stationary point of

    L(q, mu) = F(q; z_a) + mu . (C(q) - (x_b - x_a)),

F the energy with the work of the loads, C(q) = int r' dS the chord and mu its
multiplier (iteration/newton.py). The loads per metre do not depend on where the line
is, so F depends on x_a only through the positions' terms: on a flat seabed through the
start's height z_a (a node's height is z_a plus the integral of the slope); on a sloping
plane through the whole x_a (its energy reads the normal penetration), and the data
below are (x_a, c) with one P per component (_plane_response). With
G(z_a, c) = F at the equilibrium of chord c, the line's potential as a function of its
ends is Phi(x_a, x_b) = G(z_a, x_b - x_a) - W . x_a, W the load's resultant.

**End forces.** The force the line exerts ON its start point and ON its end point,
global axes, N: F_b = -dPhi/dx_b = mu (beside an attachment sitting on the end), and
F_a = -dPhi/dx_a = W + (the seabed's and the attachments' forces) - mu = n(0): the
reactions the single-line solver reports (quantities/line_results.py: ``start_force``,
``end_force``), F_a + F_b = the whole applied load.

**Stiffness.** K = d(F_a, F_b)/d(x_a, x_b), (6, 6), N/m, rows the forces (a then b),
columns the positions (a then b). Linearise the equilibrium in its data, the chord
c = x_b - x_a and the start's height z_a: with A the matrix of the Newton system at the
equilibrium (H, the second variation, analysis/second_variation.py; in a current the
Newton Jacobian J, analysis/jacobian.py), C^T the chord forms (3 columns) and
P = dgrad L/dz_a (the seabed's curvature times each node's height row,
SecondVariation.position_shift; in a sheared current plus the drag's columns on the
heights summed, DragTerm.height_shift: the line raised meets another current), with Y_C = A^-1 C^T, Y_P = A^-1 P, S = C Y_C (3, 3):

    dmu = -S^-1 (dc + C Y_P dz_a),   dy = -Y_P dz_a - Y_C dmu,
    dF_b = dmu,   dF_a = dPsi_0 - (P.dy + sum_n k w_n dz_a) e_z - dmu,

Psi_0 the resultant at S = 0 of a load that follows the line (the drag: a row of the
Jacobian's unknowns, so dPsi_0 a row of dy), sum_n over the nodes in contact. One
factorisation of A (the stability test's LDL^T of H unshifted, or J's LU; by
substructuring on several ranks) and four solves: no finite differences. All of it holds at
a stationary point of L: where the last solve ended by the iteration's tolerances and not
in Newton's steps, settle() takes those steps first (a walk after a small move leaves
|grad L| that a grounded line's sideways stiffness feels). Without a
current K = -Hess Phi: symmetric, and negative semi-definite for a stable line (moving
an end outward pulls it back: the restoring stiffness of a point is -K); without a
seabed K_aa = K_bb = -K_ab = -S^-1 (a translation of the whole line changes nothing).
In a uniform current K is not symmetric: the drag has no potential, and its resultant
turns with the line (K[:, :3] = -K[:, 3:] still holds without a seabed). The seabed's
contact is semi-smooth: an anchor exactly on the seabed has a one-sided vertical
stiffness of its own (its node enters the contact when pressed in), and K gives the
lifting side (its node counts as in contact only below the seabed).

**Rotations.** A clamped end's frame is an input (solve(..., start_frame, end_frame),
walked along the geodesic) and end_stiffness() gives the (12, 12) of the forces and the
moments (end_moments) on both ends against the ends' positions and small rotations
theta of the clamps' frames, Q -> exp([theta]x) Q. Turning a clamp moves a held
unknown, its node's rotation, from 0 to theta: the free unknowns see the held columns
of H times theta (SecondVariation.full_columns) and the chord moves by -w_n [t_n]x theta
at that node; on an extensible line the clamped node's stretch, held in H and set by
the force balance EA (k - 1) = n.d3 (docs/method.md §12), is one more such datum, solved
for with the rest (so end_stiffness's forces against the positions are exact there too,
where stiffness() misses that node's share: 7e-5 of the largest entry on a 40-element
line, against 3e-9 inextensible). The moment at an end vertex is K u of the end
element's three nodes' frames (io/outputs.vertex_fields); its derivative in those
nodes' rotations and stretches is taken by a complex step of that closed form. Not
symmetric: the moments are the constitutive K u at the vertex, not the energy's
conjugate of the clamp's rotation (they differ by O(h) terms, so dF/dtheta is not
(dM/dx)^T), and the rotations are increments on the left (a skew part of the order of
[M]x in the rotation block); the forces' position block is symmetric without a current
(to 7e-8 of the largest entry with extensible clamps, whose stretch rule is not the
energy's). In a current the drag at the clamped node turns with the clamp: J's columns
at its held rotation are H's (full_columns) plus the drag's (DragTerm.turn_columns), and
the start's force moves with the drag's resultant Psi_0 in every datum. A flex joint's
support frame D given to solve turns its axis, a = D^T D_ref a_0; turning it by delta is
a data change of the joint's gradient at its (free) node, solved for like a clamp's, and
its moment on the support is the joint's, -k (theta / sin theta) d3 x a; at an
extensible end too, where the joint acts in the local step (its gradient in rotations,
of the tangent's direction only, is the same function of d3 and a).

**Friction.** The seabed's friction (physics/friction.py) holds each grounded node to
an anchor. A held line's anchors are its nodes where its first solve starts (the line as
laid: its catenary between the ends' first positions, in the line's frame, whose origin
is fixed for its life) and stay there (FrictionTerm.hold_anchors: no return map at the
end of a step): its equilibrium is then a function of its ends alone, whatever walks,
halvings and trials reached them (OrcaFlex's statics within one load step). Its gradient
reads every node's horizontal position, so the data are the start's whole x_a, as on a
plane (_plane_response), with the position block H_n (n_nodes, 3, 3) at the owned
nodes: the seabed's (k w_n at (z, z); on a sloping plane k w_n N N^T) plus the
friction's Newton block (FrictionTerm.position_derivatives: stick k_s w I, slide the
secant block and the z column of the limit mu R following the contact; on a plane all
three rows, the friction's vertical part g.f = g^T times its horizontal rows, and the
limit following x as well, k cos(theta) d g^T): unsymmetric, so A is J (its LU), and
the forces read the block through its transpose. A sliding node's stiffness is the
loading tangent (the slip continued); unloading it would stick. With one coefficient
only (FrictionTerm.held_exact), on a flat seabed, a sloping plane, a profile or a grid
(below).
settle() records the friction of the settled state (FrictionTerm.follow_state), which
the end forces read. At a clamped or flex-jointed end the rotations' response takes the
same block: the seabed's reaction on the start read through H_n's transpose in the
free unknowns and in the held data's rows alike, and the held data's right-hand sides
J's columns, not H's: the friction's entries of J beyond H (the limit following the
contact, on a sliding node of the clamped node's element) read off the assembled J
(_add_jacobian_columns).

On a sloping plane the rotations' response takes the plane's data (x_a, c): three
solves Y_j = A^-1 P_j, and the seabed's reaction on the start moved in each of its rows
by the held data through P_i's held rows (_rotation_response).

**Seabed profile.** The line's equilibrium on a profile is the fixed point of its lagged
iteration (physics/slope_load.py; its run ends in Newton steps on the linearisation
below): a node's penetration reads the interpolant's height z_b(d), its push the secant
gradient g(d), with k_v = k / (1 + g^2). Its derivative in the ends is the full
linearisation there, per grounded node the block B_n = d(-w_n f_n)/dr_n of
Seabed.profile_derivatives (z_b', g, its rate g' and k_v's turn with g), which the
seabed term puts into the Newton system for this line alone
(SeabedTerm.profile, as in the line's own run: H its symmetric part, J the rest):
unsymmetric within delta / 2 of a row, where g != z_b', so A is J (its LU), the
data are (x_a, c) as on a plane with the block per node, and the forces read it
through its transpose (as the friction's); a clamp's or a joint's held columns of J
take the block's antisymmetric part too (SeabedTerm.turn_columns). Away from the rows
B_n is the plane's k w_n N N^T with the node's own normal. settle() takes Newton's
steps on that system: their stationary point is the iteration's fixed point. A seabed
grid the same way, its slopes vectors in the plan (Grid.slopes: grad z_b, g and
Dg = dg/d(x, y)), B_n unsymmetric within delta / 2 of a grid line.
With the seabed's friction (one coefficient) on a profile or grid the fixed point's
friction is the plane's law with g read at each node, F = (f, g(x).f),
R = k cos(theta) (z_b(x) - z)_+: its block is the plane's with the limit following x
through grad z_b and k_v(g), g.f turning with Dg (a profile's g' e e^T), and |d|_G's
G = I + g g^T turning too (FrictionTerm._shape_rates),
added to B_n in the recorded block (the friction's rows after the profile's); a clamp's
held columns of J are then read off the assembled J whole (_add_jacobian_columns, which
holds the profile's share too).

What it refuses (RodInputError, one line): a stiffness where it would not be exact: the
seabed's friction with two coefficients (no Newton steps; its axes turn with the
tangent); any load outside the
Newton system (the sea surface's wet and dry parts, attachments that reach it).

Every call is collective on the line's communicator, never COMM_WORLD: a system puts
each line on its own sub-communicator.
"""

import dataclasses

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.jacobian import NewtonJacobian
from petsc_rod.analysis.second_variation import skew
from petsc_rod.cli.line_run import BuiltLine, plan_line, values_of
from petsc_rod.compile import compile_scene
from petsc_rod.errors import NoCatenaryStart, RodError, RodInputError
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.iteration import events
from petsc_rod.iteration.continuation import PathSettings, continuation
from petsc_rod.iteration.newton import CONVERGED, NewtonSolver
from petsc_rod.frames import REFERENCE_FRAME
from petsc_rod.global_step.chain_factor import NULL_PIVOT
from petsc_rod.model.derived import Loads
from petsc_rod.model.end import End
from petsc_rod.physics.flex_joint import (FlexJoint, curvature_factor, joint_angle,
                                         slope_factor)
from petsc_rod.physics.friction import FrictionTerm
from petsc_rod.physics.seabed import SeabedTerm
from petsc_rod.model.model import Model, Span
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.model.system_check import connection_frame, connection_position
from petsc_rod.quantities.riser_numbers import (_extreme, effective_tension,
                                             points_on_held_ends, top_end, touchdown)
from petsc_rod.scenes import starts
from petsc_rod.scenes.blend import blended_frame
from petsc_rod.scenes.scene import EndState


# The units of HeldLine.summary's numbers.
SUMMARY_UNITS = {"max_tension": "N", "max_tension_S": "m", "max_tension_position": "m",
                 "start_tension": "N", "end_tension": "N", "start_force": "N",
                 "end_force": "N", "touchdown_S": "m", "touchdown_position": "m",
                 "grounded_length": "m"}


class HeldEnds:
    """The load path of a held line's problem (the interface of scenes/blend.py's
    BlendedPath): the ``scene``'s own path (its load factor t) until the ends are first
    moved (``move``); from then on every load at its full value and the ends walked in
    straight lines, s in [0, 1], from where they were to where they go, in the
    scene's frame (origin: the scene's start). Anything else is the scene's."""

    def __init__(self, scene):
        self.scene = scene
        self.moves = None           # (a from, a to, b from, b to), (3,) each
        self.turns = None           # the frames (a from, a to, b from, b to), (3, 3) each

    def __getattr__(self, name):
        if name in ("scene", "moves", "turns"):
            raise AttributeError(name)
        return getattr(self.scene, name)

    def move(self, start, end, start_frame=None, end_frame=None):
        """Walk from the ends at the path's end (s = 1) to ``start``, ``end`` (3,), m,
        in the scene's frame, and a clamped end's frame (3, 3) (rows d1, d2, d3) from
        where it is to ``start_frame``, ``end_frame`` along the geodesic
        (scenes/blend.blended_frame; None: held as it is)."""
        a, b = self.start_state(1.0), self.end_state(1.0)
        self.moves = (a.position, np.asarray(start, dtype=float),
                      b.position, np.asarray(end, dtype=float))
        self.turns = (a.frame, a.frame if start_frame is None else start_frame,
                      b.frame, b.frame if end_frame is None else end_frame)

    def hold(self, start, end, start_frame=None, end_frame=None):
        """The ends held at ``start``, ``end`` (3,) all along the path (after a walk
        that failed: back where they were), a clamp's frame at ``start_frame``,
        ``end_frame`` (None: where it is)."""
        a = self.start_state(1.0).frame if start_frame is None else start_frame
        b = self.end_state(1.0).frame if end_frame is None else end_frame
        self.moves = (np.asarray(start, dtype=float),) * 2 + (np.asarray(end, dtype=float),) * 2
        self.turns = (a, a, b, b)

    def _t(self, t):
        return 1.0 if self.moves is not None else t

    @property
    def axially_symmetric(self):
        """Moved ends are off the x axis in general: no family of turned equilibria."""
        return self.moves is None and self.scene.axially_symmetric

    def load_beyond(self, S, t):
        return self.scene.load_beyond(S, self._t(t))

    def point_loads(self, t):
        return self.scene.point_loads(self._t(t))

    def point_drags(self, t):
        return self.scene.point_drags(self._t(t))

    def point_buoyancies(self, t):
        return self.scene.point_buoyancies(self._t(t))

    def drag_loads(self, t):
        return self.scene.drag_loads(self._t(t))

    def end_roll(self, t):
        return self.scene.end_roll(self._t(t))

    def end_frame_parts(self, t):
        return self.scene.end_frame_parts(self._t(t))

    def start_state(self, t):
        return self._held(self.scene.start_state(self._t(t)), t, 0)

    def end_state(self, t):
        return self._held(self.scene.end_state(self._t(t)), t, 2)

    def _held(self, state, s, first):
        if self.moves is None:
            return state
        old, new = self.moves[first], self.moves[first + 1]
        frame = state.frame
        if state.kind == "clamp":
            frame = blended_frame(self.turns[first], self.turns[first + 1], s)
        return EndState(state.kind, (1.0 - s) * old + s * new, frame, state.force)


class _CurvatureRecorder:
    """What a term's add_hessian gives the positions (Term.add_hessian): the seabed's
    k w_n at the nodes in contact, recorded instead of assembled."""

    def __init__(self, problem):
        self.problem = problem
        self.heights = None
        self.positions = None       # a sloping plane's k w_n N N^T (n_nodes, 3, 3)

    def add_height_curvature(self, curvature):
        self.heights = np.asarray(curvature, dtype=float)

    def add_position_curvature(self, values, components):
        if tuple(components) != (0, 1, 2):
            raise RodInputError("a line whose energy reads its horizontal positions (the "
                                "seabed's friction) has no exact stiffness here")
        self.positions = np.asarray(values, dtype=float)

    def add_friction(self, terms):
        """The frictional line's whole position block H_n (n_nodes, 3, 3) at the owned
        nodes, rows the gradient's components, columns the positions': the seabed's
        (k w_n at (z, z) on a flat seabed, the heights' own record folded in; on a
        sloping plane its k w_n N N^T) plus the friction's
        FrictionTerm.position_derivatives (unsymmetric: rows (x, y) on a flat seabed,
        its z column the limit mu R following the contact; on a plane all three rows,
        the vertical part g.f, and the limit following x as well). The response then
        takes the start's three position data (_plane_response)."""
        state = self.problem.state
        block = np.zeros((state.node_weights.shape[0], 3, 3))
        if self.positions is not None:
            block += self.positions
        if self.heights is not None:
            block[:, 2, 2] = self.heights
        for term in terms:
            rows = term.position_derivatives(state)
            block[:, :rows.shape[1]] += rows
        self.positions, self.heights = block, None


def _at_vertex(mesh, values, index):
    """values[index] of the owned vertex ``index`` (global), on every rank. Collective."""
    local = np.zeros(np.shape(values)[1:])
    if mesh.vertex_start <= index < mesh.vertex_end:
        local = np.asarray(values[index - mesh.vertex_start], dtype=float)
    return mesh.global_sum(local)


def _vertex_moment(F, h, stiffness, e):
    """The moment K_i u_i d_i at the end vertex (e = 0: S = 0 of the first element; 1:
    S = L of the last) from the frames F (3 nodes, 3 rows, 3) of that element, rows d1,
    d2 and the slope (frames.strains' skew part of D'^T D^-T, P2 derivatives at the
    vertex): io/outputs.vertex_fields' m, written for complex values."""
    d = F[0] if e == 0 else F[2]
    dd = ((-3.0 * F[0] + 4.0 * F[1] - F[2]) if e == 0 else (F[0] - 4.0 * F[1] + 3.0 * F[2])) / h
    rate = dd.T @ np.linalg.inv(d.T)
    omega = 0.5 * np.array([rate[2, 1] - rate[1, 2], rate[0, 2] - rate[2, 0],
                            rate[1, 0] - rate[0, 1]])
    u = d @ omega
    return (stiffness * u) @ d


def _moment_jacobian(F, h, stiffness, e, unknowns):
    """d m / d(node k's rotation omega, and stretch on an extensible line), (3, 3 nodes,
    unknowns): a rotation turns the node's rows, delta F_i = omega x F_i, a stretch the
    slope, delta F_3 = delta_k F_3 / |F_3|; by a complex step of _vertex_moment (exact
    to round-off)."""
    step = 1e-30
    out = np.zeros((3, 3, unknowns))
    for k in range(3):
        for j in range(unknowns):
            change = np.zeros((3, 3))
            if j < 3:
                change = np.cross(np.eye(3)[j], F[k])
            else:
                change[2] = F[k, 2] / np.linalg.norm(F[k, 2])
            G = F.astype(complex)
            G[k] = G[k] + 1j * step * change
            out[:, k, j] = _vertex_moment(G, h, stiffness, e).imag / step
    return out


def _joint_moment(k, d, a):
    """The moment a flex joint of stiffness k exerts on its support, N m: -dE/ddelta for
    the support turned by delta (its axis a -> a + delta x a), E = k theta^2 / 2,
    theta = angle(d, a); as E depends on d and a through their relative turn only, it is
    dE/domega = d x dE/dd = -k (theta / sin theta) d x a (k theta about a x d)."""
    return -k * slope_factor(joint_angle(d, a)) * np.cross(d, a)


def _joint_jacobians(k, d, a):
    """(J_d, J_a), (3, 3) each: d _joint_moment = J_d dd + J_a da for unit d, a:
    dG = -k (-f'' dc v + (theta / sin theta) dv), v = d x a, c = d.a, f'' the joint's
    curvature factor (sin theta - theta cos theta) / sin^3 theta."""
    theta = joint_angle(d, a)
    v = np.cross(d, a)
    f2, s = curvature_factor(theta), slope_factor(theta)
    return (-k * (-f2 * np.outer(v, a) - s * skew(a)),
            -k * (-f2 * np.outer(v, d) + s * skew(d)))


def _point(name, value):
    point = np.asarray(value, dtype=float)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise RodInputError(f"HeldLine.solve: {name} {value!r}: three finite numbers (m)")
    return point


def _refine(solver, rights, solved):
    """One step of iterative refinement of the solves x_j = J^-1 b_j (``solved``, of the
    Vecs ``rights``), in place: x_j <- x_j + J^-1 (b_j - J x_j), with the factored
    NewtonJacobian ``solver``'s own matrix. Where the factor kept the free roll's null
    pivot at the size of round-off (the substructured factor's interface may keep it or
    drop it, as round-off of the state falls: _held_forms), its solves carry errors
    beyond the roll's direction, which the Schur step holding the roll's form does not
    remove and this step does. Returns the work Vecs, the caller's to destroy.
    Collective."""
    residuals = []
    for b, x in zip(rights, solved):
        residual = b.duplicate()
        solver.matrix.mult(x, residual)
        residual.aypx(-1.0, b)                      # b - J x
        residuals.append(residual)
    corrections = solver.solve_many(residuals)
    for x, dx in zip(solved, corrections):
        x.axpy(1.0, dx)
    return residuals + corrections


def _ends_at_newton(event, newton_at):
    """Whether the attempt that ``event`` ends (a StepEnded; a StepHalved undoes it)
    leaves the state where its last Newton run converged, at iteration ``newton_at``
    (None: no such run, or the frames turned after it): the step ended at that run or
    at the iteration after it, which moves a Newton state by the map's round-off only
    (iteration/driver.py, controller.verified_by_newton). A later step of the path, a
    halved attempt's retry, or more iterations after the run (the map iterating on
    after a hand-over at the round-off floor, an escape) end elsewhere."""
    return (isinstance(event, events.StepEnded) and newton_at is not None
            and event.report.iterations - newton_at in (0, 1))


def _verified(newton):
    """Whether ``newton``'s (a NewtonSolver's, None without Newton steps) last run's
    last H passed the inertia test on the constraint set (NewtonSolver.verified)."""
    return newton is not None and bool(newton.verified)


class HeldLine:
    """A line of the typed model held at its two ends, on the ranks of ``comm`` (a
    PETSc communicator: the line's own; collective on it alone).

    ``span``: a model.model.Span (or a model.Model, whose one span is taken) with both
    ends held (pin or clamp; a clamp's frame as given, or as solve turns it; a pin may
    carry a flex joint, whose axis solve turns with its support); ``environment``: the
    sea (model.sea.Environment; a Model's own by default); ``options``: -rod_* options
    without ``rod_`` that tune the solver ({'al_rtol': 1e-10}).

    solve(start_position, end_position, start_frame=None, end_frame=None) -> bool;
    end_forces() -> (2, 3); end_moments() -> (2, 3); stiffness() -> (6, 6);
    end_stiffness() -> (12, 12); settle(); stable() -> bool or None;
    positions() -> (2, 3); summary() -> dict; centreline() -> (n + 1, 3) or None;
    destroy(). ``iterations``: those of the last solve (of its one attempt where it
    diverged). ``budget``: None, or the iteration cap of a first solve (one attempt, no
    halvings: a system's prediction, SystemSolver._first_solves)."""

    def __init__(self, span, comm, environment=None, options=None):
        if isinstance(span, Model):
            environment = environment or span.environment
            span = span.spans[0]
        if environment is None:
            raise RodInputError("HeldLine: give the line's environment (model.Environment)")
        self.span, self.environment, self.comm = span, environment, comm
        for which in ("start", "end"):
            if getattr(span, which).kind not in ("pin", "clamp"):
                raise RodInputError(f"HeldLine: the line's {which} is "
                                    f"{getattr(span, which).kind}; a line of a system is "
                                    "held at both ends (pin or clamp)")
        self.values, self.given = values_of(options)
        self.scene = compile_scene(self._model(span.start.position, span.end.position),
                                   FIELD_NAMES)
        self.built = self.mesh = self.problem = self.solver = self.newton = self.path = None
        self.jacobian = None
        self.friction = []                  # the FrictionTerm, its anchors held
        self.profile = None                 # the SeabedTerm of a profile or grid
        # where a frictional line is laid, (start, end) absolute (None: where its first
        # solve asks): the first solve starts there and walks to its ends
        self.laid = None
        self.frames = (None, None)          # the clamps' frames last asked for
        self.axes = {}
        self.iterations = 0
        self.converged = False
        # the iteration cap of a first solve at a system's prediction (SystemSolver.
        # _first_solves), one attempt without halvings; None: the line's own budget
        self.budget = None
        # the run's stop signals (cli/signals.Interrupts), asked on the line's
        # communicator after every iteration of its solves (a walk stops at once, a
        # failure); None: not asked (the system's solver sets it: SystemSolver.evaluate)
        self.interrupts = None
        self.settled = False                # the last solve ended at Newton's convergence
        # ... and that Newton run's last H was positive definite on the constraint set
        # (NewtonSolver.verified): the stability test's own criterion (stable)
        self.verified = False
        self.settles = True                 # stiffness() first settles the line (settle)
        self.name = "the line"              # how a refusal names it (of_system_line)

    @classmethod
    def of_system_line(cls, line, start, end, comm, environment, options=None,
                       frames=(None, None)):
        """The HeldLine of a model.system.SystemLine ``line`` whose ends are first at
        ``start`` and ``end`` ((3,), m, absolute: where the system's points and bodies
        put its connections): a 'pin' connection a pinned End, 'flex' a pinned End with
        the connection's rotational stiffness (its axis the line's start direction, or
        with a Connection.direction the reference d3 e_x, which the support's frame
        given to solve turns: a = D^T D_ref e_x, D's d3), 'clamp' a clamped End in
        ``frames`` ((3, 3) global, or None: the reference frame) at the start (a system
        then passes the frame turned with its body to solve, and a flex joint's support
        frame likewise)."""
        def end_of(connection, position, frame):
            kind = "clamp" if connection.kind == "clamp" else "pin"
            stiffness = connection.stiffness if connection.kind == "flex" else None
            axis = (tuple(REFERENCE_FRAME[2]) if stiffness is not None
                    and connection.direction is not None else None)
            frame = (tuple(float(v) for v in np.ravel(frame))
                     if kind == "clamp" and frame is not None else None)
            return End(kind=kind, position=tuple(float(v) for v in position),
                       stiffness=stiffness, axis=axis, frame=frame)

        span = Span(line.line, end_of(line.start, start, frames[0]),
                    end_of(line.end, end, frames[1]), tuple(line.attachments))
        held = cls(span, comm, environment, options)
        held.name = f"line {line.name}"
        return held

    # --- building ----------------------------------------------------------------------
    def _model(self, start, end, frames=(None, None)):
        """The line's Model with its ends at ``start``, ``end`` (absolute, m), a clamp's
        frame at ``frames`` ((3, 3) or None: the span's)."""
        def at(end_, position, frame):
            if frame is None or end_.kind != "clamp":
                return dataclasses.replace(end_, position=position)
            return dataclasses.replace(end_, position=position,
                                       frame=tuple(float(v) for v in np.ravel(frame)))
        span = self.span
        return Model(span.line, at(span.start, start, frames[0]),
                     at(span.end, end, frames[1]), self.environment,
                     tuple(span.attachments))

    def _build(self, start, end, frames=(None, None)):
        """The line's run built on the one path of a line (cli/line_run.py: plan_line,
        BuiltLine: its mesh, problem and solver made and destroyed together) with the
        ends at ``start``, ``end``, its problem walking HeldEnds: its frame's origin is
        ``start`` for the line's life. Collective."""
        plan = plan_line(self.comm, self._model(start, end, frames), self.values, self.given,
                         FIELD_NAMES, self._mesh_named)
        self.built = BuiltLine(self.comm, plan, path_of=HeldEnds)
        try:
            self.built.build()
        except BaseException:
            self.built.destroy()
            raise
        self.scene = plan.scene
        self.origin = np.array(plan.scene.start_position, dtype=float)
        self.mesh, self.problem, self.solver = (self.built.mesh, self.built.problem,
                                                self.built.solver)
        self.path = self.built.scene
        self.profile = self._profile_term()
        self.newton = self.built.own(NewtonSolver(self.problem))
        # each flex joint's neutral axis at the reference frame (turned by a frame given)
        self.axes = {("start", "end").index(t.which): (t, t.axis.copy())
                     for t in self.problem.terms if isinstance(t, FlexJoint)}
        # the friction's anchors: the first solve's start (the line as laid), held for
        # the line's life (module docstring, "Friction")
        self.friction = [t for t in self.problem.terms if isinstance(t, FrictionTerm)]
        for term in self.friction:
            term.hold_anchors = True
        # the end stiffness reads the positions from the start (add_friction)
        self.problem.state.chains_from_end = False

    def _mesh_named(self, pieces, elements):
        """How a mesh too large for the machine names the line's element count."""
        return (f"{self.name}: {elements} elements (its sections' counts: a MoorDyn "
                "line's NumSegs, or its length over the system's element length)")

    def _release(self):
        if self.built is not None:          # its own objects and those it was given
            self.built.destroy()
        self.jacobian = self.profile = None
        self.friction = []
        self.built = self.mesh = self.problem = self.solver = self.newton = self.path = None

    # --- solving -----------------------------------------------------------------------
    def solve(self, start_position, end_position, start_frame=None, end_frame=None):
        """The line's equilibrium with its start held at ``start_position`` and its end
        at ``end_position`` ((3,) each, m, absolute), a clamped end's frame at
        ``start_frame``, ``end_frame`` ((3, 3), rows d1, d2, d3, global axes, as
        model.End.frame; None: where it is, the model's at first): the first time (and
        after a first solve that failed) from the catenary start in one step, as the
        command line starts; later walked in one step (halved where it fails, up to 4
        times) from the last converged equilibrium, the ends moved in straight lines and
        the frames turned along the geodesic. Where the line is ``laid`` elsewhere
        (a frictional line of a system moved by an offset), its first solve is there
        and walks to these ends. Returns whether it converged; a failed walk leaves the
        last equilibrium as it was. Collective."""
        a, b = _point("start_position", start_position), _point("end_position", end_position)
        frames = tuple(given if given is not None else last for given, last in
                       zip((self._frame("start", start_frame), self._frame("end", end_frame)),
                           self.frames))
        self.frames = frames
        if self.problem is None or not self.converged:
            self._release()
            laid = (a, b) if self.laid is None else self.laid
            self._build(*laid, frames)
            self._turn_joints(frames)
            if not self._first() or self.laid is None:
                return self.converged
        return self._walk(a - self.origin, b - self.origin, frames)

    def _turn_joints(self, frames):
        """Each flex joint's axis turned with its support's frame D (rows d1, d2, d3):
        a = D^T D_ref a_0, the rotation that takes the reference frame's rows to D's."""
        for e, (term, axis) in self.axes.items():
            if frames[e] is not None:
                term.axis = frames[e].T @ REFERENCE_FRAME @ axis

    def _frame(self, which, frame):
        """A clamped end's frame (3, 3) checked (None passes), or RodInputError."""
        if frame is None:
            return None
        end = getattr(self.span, which)
        if end.kind != "clamp" and end.stiffness is None:
            raise RodInputError(f"HeldLine.solve: a {which}_frame for a "
                                f"{end.kind} end: only a clamp or a flex joint holds a "
                                "frame")
        q = np.asarray(frame, dtype=float)
        if (q.shape != (3, 3) or not np.all(np.isfinite(q))
                or np.abs(q @ q.T - np.eye(3)).max() > 1e-9 or np.linalg.det(q) < 0):
            raise RodInputError(f"HeldLine.solve: {which}_frame: a rotation (3, 3), "
                                "rows d1, d2, d3 orthonormal and right-handed")
        return q

    def _first(self):
        """The first solve, from the catenary (or the chord, or straight) in one step,
        halved up to 4 times at the solver's iteration cap each; with a ``budget``, one
        attempt within it: a start a system's predictor guessed may be far from any
        equilibrium of the line, and giving it up early costs little (the system then
        starts from its unloaded pose)."""
        problem = self.problem
        if starts.lies_straight(self.path, 1.0):        # taut: no catenary
            problem.state.set_from_curve(starts.chord_start(self.path, 1.0))
        else:
            try:
                curve = starts.catenary_start(self.path, 1.0)
            except NoCatenaryStart:
                problem.state.set_straight()
            else:
                problem.state.set_from_curve(curve)
        path, settings = PathSettings(steps=1, track_link=False), self.solver.settings
        if self.budget is not None:         # a prediction's: one attempt, capped
            path = dataclasses.replace(path, max_halvings=0)
            self.solver.settings = dataclasses.replace(
                settings, max_it=min(settings.max_it, int(self.budget)))
        try:
            self.converged = self._run(path)
        finally:
            self.solver.settings = settings
        return self.converged

    def _walk(self, a, b, frames):
        state = self.problem.state
        saved, settled, verified = state.snapshot(), self.settled, self.verified
        frictions = [term.snapshot() for term in self.friction]
        ends = (self.path.start_state(1.0), self.path.end_state(1.0))
        axes = {e: term.axis for e, (term, _) in self.axes.items()}
        self.path.move(a, b, *frames)
        self._turn_joints(frames)
        if self._run(PathSettings(steps=1, track_link=False)):
            self.path.hold(a, b, *frames)
            return True
        for e, (term, _) in self.axes.items():
            term.axis = axes[e]
        state.restore(saved)
        for term, record in zip(self.friction, frictions):
            term.restore(record)                # its end forces read the friction's
        self.settled, self.verified = settled, verified     # the restored equilibrium's
        self.path.hold(ends[0].position, ends[1].position, ends[0].frame, ends[1].frame)
        self.problem.prepare(1.0)
        return False

    def _run(self, path):
        """The continuation on ``path``: whether it converged (a divergence, a PETSc
        error of its solves, is a failure). Collective."""
        self.iterations = 0
        self.settled = self.verified = False
        newton_at = None        # the iteration of the attempt's last converged Newton run
        converged = False
        try:
            for event in continuation(self.solver, path, stop=self._stop()):
                if isinstance(event, events.NewtonAttempt):
                    newton_at = event.iteration if event.outcome == CONVERGED else None
                elif isinstance(event, events.SaddleLeft):
                    newton_at = None            # the frames turned off Newton's state
                elif isinstance(event, (events.StepHalved, events.StepEnded)):
                    self.settled = _ends_at_newton(event, newton_at)
                    # the run was the iteration's own Newton's
                    self.verified = self.settled and _verified(getattr(self.solver, "newton",
                                                                       None))
                    newton_at = None
                if isinstance(event, events.RunFinished):
                    self.iterations = event.iterations
                    converged = bool(event.converged)
                    break
                if isinstance(event, events.RunDiverged):
                    # the attempt's own (a run without halvings: all it spent)
                    self.iterations = int(getattr(event.error, "iterations", 0) or 0)
                    break
        except (RodError, PETSc.Error, FloatingPointError):
            pass
        finally:
            if not converged:
                # a failed run's state is no equilibrium
                self.settled = self.verified = False
        return converged

    def _stop(self):
        """continuation's ``stop``: whether a rank of the line received a stop signal
        (``interrupts``; collective on the line's communicator), None without them."""
        interrupts = self.interrupts
        if interrupts is None:
            return None
        return lambda: bool(interrupts.received(self.comm))

    # --- what it gives the system --------------------------------------------------------
    def positions(self):
        """The held ends where the last solve put them, (2, 3), m, absolute."""
        return np.array([self.path.start_state(1.0).position,
                         self.path.end_state(1.0).position]) + self.origin

    def end_forces(self):
        """(2, 3), N, global axes: the force the line exerts ON its start point (row 0)
        and ON its end point (row 1), an attachment that sits on an end included: n(0)
        and -n(L) (module docstring; line_results' start_force and end_force).
        Collective."""
        self._check_solved()
        problem, mesh = self.problem, self.mesh
        n = problem.internal_force()
        on_start, on_end = points_on_held_ends(problem)
        return np.array([_at_vertex(mesh, n, 0) + on_start,
                         -_at_vertex(mesh, n, mesh.n_elements) + on_end])

    def summary(self):
        """What the line reports at its last equilibrium beyond its end forces, as the
        single-line reports compute them (quantities/riser_numbers.py; units
        SUMMARY_UNITS), on every rank of its communicator:

        ``max_tension`` the largest effective tension n.t over the vertices (N), at arc
        length ``max_tension_S`` (m) and ``max_tension_position`` (3,) (m, absolute);
        ``start_tension``, ``end_tension`` n.t at S = 0 and S = L: the end element's
        tension along the line (N); ``start_force``, ``end_force`` |end_forces()| (N):
        the force on the point, which differs from the tension along the line by the
        shear an end carries and by an attachment sitting on the end;
        ``touchdown_S``, ``touchdown_position`` where the line, followed from its higher
        end, first reaches the seabed (NaN without one or when it does not reach it) and
        ``grounded_length`` the length below the seabed's height (m; NaN without a
        seabed). Only reductions of a few numbers: no field is gathered. Collective."""
        self._check_solved()
        problem, mesh = self.problem, self.mesh
        r = problem.state.r.owned()
        vertex = {"n": problem.internal_force(), "d3": r[:, 1]}
        tension = effective_tension(vertex)
        k = int(np.argmax(tension)) if tension.size else 0
        local = ((tension[k], mesh.vertex_S[k], r[k, 0]) if tension.size
                 else (None, None, None))
        largest, largest_S, largest_r = _extreme(mesh, local[0], local, largest=True)
        ends = [float(_at_vertex(mesh, tension, index)) for index in (0, mesh.n_elements)]
        forces = np.linalg.norm(self.end_forces(), axis=1)
        seabed = self.scene.seabed
        if seabed is None:
            S, position, grounded = np.nan, np.full(3, np.nan), np.nan
        else:
            S, position, grounded = touchdown(problem, seabed, top_end(problem))
        return {"max_tension": float(largest), "max_tension_S": float(largest_S),
                "max_tension_position": np.asarray(largest_r, dtype=float) + self.origin,
                "start_tension": ends[0], "end_tension": ends[1],
                "start_force": float(forces[0]), "end_force": float(forces[1]),
                "touchdown_S": float(S), "touchdown_position": position + self.origin,
                "grounded_length": float(grounded)}

    def centreline(self):
        """The centreline's vertices at the last equilibrium, (n + 1, 3), m, absolute,
        gathered to the first rank of the line's communicator (None on the others): for
        a picture only. Collective."""
        self._check_solved()
        parts = self.comm.tompi4py().gather(self.problem.state.r.owned()[:, 0], root=0)
        return None if parts is None else np.concatenate(parts) + self.origin

    def stable(self):
        """The stability test's verdict on the last equilibrium (docs/method.md §10):
        True a local minimiser, False a saddle, None undecided or a line whose loads
        have no energy (a current). A system may solve its lines with the test off
        (options {'al_stability': 0}: a third of a small warm re-solve's time) and ask
        this once at its own equilibrium. Where the line is settled by a Newton run
        whose last H passed the inertia test on the constraint set (``verified``),
        that test is the verdict, True, without a factorisation of its own, as a
        single line's step that ends at Newton takes it (iteration/driver.py).
        Collective."""
        self._check_solved()
        if not self.problem.conservative:
            return None
        if self.settled and self.verified:
            return True
        try:
            return self.solver.check_stability()[0]
        except np.linalg.LinAlgError:
            return None

    def end_moments(self):
        """(2, 3), N m, global axes: the moment the line exerts on its start's support
        (row 0) and on its end's (row 1), m(0) and -m(L) (line_results' start_moment and
        end_moment): a clamp's reaction; at a pin the bending of the end element's strain
        (small: of the discretisation, not a reaction). Collective."""
        self._check_solved()
        mesh = self.mesh
        m = vertex_fields(self.problem)["m"]
        moments = np.array([_at_vertex(mesh, m, 0), -_at_vertex(mesh, m, mesh.n_elements)])
        for e, d, term in self._joint_tangents(field=True):
            moments[e] = _joint_moment(term.k, d, term.axis)
        return moments

    def _joint_tangents(self, field=False):
        """[(end, d, term)] of the flex joints: the unit end tangent d (3,) on every rank
        (the slope field's with ``field``, else tau3). Collective."""
        out = []
        last = 2 * self.mesh.n_elements
        tangents = (self.problem.state.node_directors()[:, 2] if field
                    else self.problem.state.tau[:, 2])
        for e, (term, _) in sorted(self.axes.items()):
            d = self._node_values([tangents], [(0, last)[e]])[0, 0]
            out.append((e, d / np.linalg.norm(d), term))
        return out

    def stiffness(self):
        """d(end_forces)/d(start position, end position), (6, 6), N/m: K[i, j] the
        derivative of force component i (0-2 on the start, 3-5 on the end) in position
        component j (0-2 of the start, 3-5 of the end), at the last equilibrium, from
        the line's factored second variation, or in a current its Newton Jacobian
        (module docstring). Symmetric and negative semi-definite for a stable
        line without a current. Collective."""
        return self._linearised(False)

    def end_stiffness(self):
        """d(F_a, F_b, M_a, M_b)/d(x_a, x_b, theta_a, theta_b), (12, 12): the forces
        (end_forces, N) and moments (end_moments, N m) on both ends against the ends'
        positions (m) and small rotations theta of their clamps' frames (rad, global
        axes: the frame Q turned to exp([theta]x) Q; at a flex joint its support's frame,
        which turns the joint's axis); a pinned end's theta columns are zero. The first
        6 x 6 is stiffness(). From the same factored second variation (module docstring,
        "Rotations"), its solves with J holding the free roll (round sections, nothing
        clamped, in a current: flex joints and pins at the ends) where the factor kept
        that roll's null pivot, as stiffness()'s do (_held_forms; docs/systems.md).
        Collective."""
        return self._linearised(True)

    def settle(self):
        """Newton's steps from where the line stands to its stationary point (to
        iteration/newton.py's STEP_TOLERANCE), kept where they converge, unless the last
        solve ended at Newton's convergence (its last step at a converged Newton run, or
        one iteration after it: _ends_at_newton): the second variation is the stiffness at a
        stationary point only, and a walk stopped by the iteration's tolerances (its
        change per iteration below rtol after a small move) leaves |grad L| far above
        Newton's, which a grounded line's sideways stiffness feels (docs/systems.md,
        "The stiffness at the lines' stationary points"). stiffness() and
        end_stiffness() call it first where ``settles`` (a system's lines: only for the
        stiffness it reports, SystemSolver.evaluate); the friction's force then
        recorded at the settled state (FrictionTerm.follow_state), which the end forces
        read. Nothing where the stiffness is not exact (_check_exact). Collective."""
        self._check_solved()
        try:
            self._check_exact()
        except RodInputError:
            return
        if not self.settled:
            self.settled = self.newton.run() == CONVERGED
            self.verified = self.settled and _verified(self.newton)
            for term in self.friction if self.settled else ():
                term.follow_state(self.problem.state)   # the end forces read its

    def _clamp_nodes(self):
        """[(end 0 or 1, global P2 node)] of the clamped ends."""
        last = 2 * self.mesh.n_elements
        return [(e, node) for e, (which, node) in enumerate((("start", 0), ("end", last)))
                if getattr(self.span, which).kind == "clamp"]

    def _linearised(self, rotations):
        self._check_solved()
        problem = self.problem
        self._check_exact()
        if self.settles:
            self.settle()
        clamps = self._clamp_nodes() if rotations else []
        held_data = ([], {})
        state = problem.state
        saved = state.snapshot()
        frames = state.tau.copy()
        held = ~problem.free_nodes
        frames[held] = state.node_directors()[held]
        vecs = []
        try:
            self.newton.lagrangian_gradient(frames, state.chord_multiplier.copy())
            hessian = problem.second_variation()
            held_data = self._held_data(hessian, clamps)
            turned = hessian.full_columns([hessian.block * node + k for _, node, k
                                           in held_data[0]]) if clamps else []
            vecs.extend(turned)
            if clamps and hessian.resultants and not self.friction:
                # J's columns at the clamps' rotations: the drag at the clamped node
                # turns with it (DragTerm.turn_columns)
                self._add_turn_columns(hessian, held_data[0], turned, vecs)
            if not self.friction:   # else J's columns read off whole (below)
                self._add_profile_columns(hessian, held_data[0], turned, vecs)
            flexed = self._flexed(hessian) if rotations else []
            for entry in flexed:
                turned.extend(entry[-1])
                vecs.extend(entry[-1])
            recorder = _CurvatureRecorder(problem)
            for term in problem.terms:
                if term.position_components and term not in self.friction:
                    term.add_hessian(recorder)
            self._record_profile(recorder)
            if self.friction:
                recorder.add_friction(self.friction)
            unsymmetric = (hessian.resultants or bool(self.friction)
                           or self.profile is not None)
            columns = hessian.chord_forms(frames[:, 2])
            if self.newton.free_roll and unsymmetric:
                # round sections, nothing clamped (a flex joint holds no roll): one roll
                # of every section about its tangent is a null vector of J (the drag
                # has no entries along it); an LU that keeps its pivot gives the solves
                # whatever round-off puts there, which moves the stiffness; held by a
                # constraint, its multiplier dropped, as in the Newton steps
                # (_held_forms)
                columns.append(hessian.roll_form(frames[:, 2]))
            vecs.extend(columns)
            shift = None
            if recorder.heights is not None:
                shift = hessian.position_shift(recorder.heights, 2)
                vecs.append(shift)
            planes = readers = []
            if recorder.positions is not None:
                planes = readers = self._plane_shifts(hessian, recorder.positions)
                vecs.extend(planes)
                shift = planes[2]
                if self.friction or self.profile is not None:
                    # unsymmetric: the forces read its transpose
                    readers = self._plane_shifts(
                        hessian, recorder.positions.transpose(0, 2, 1))
                    vecs.extend(readers)
            # a sheared current: the start raised moves the drag of every node too
            pushes = [v for v in (term.height_shift(hessian, state) for term in problem.terms
                                  if term.jacobian_positions) if v is not None]
            vecs.extend(pushes)
            lift = shift
            if pushes:
                lift = pushes[0].duplicate()
                vecs.append(lift)
                lift.zeroEntries()
                lift.maxpy([1.0] * len(pushes), pushes)
                if shift is not None:
                    lift.axpy(1.0, shift)
            if unsymmetric:
                if self.jacobian is None:
                    self.jacobian = self.built.own(NewtonJacobian(hessian))
                self.jacobian.assemble()
                solver = self.jacobian
                if clamps and self.friction:
                    # J's columns at the held data beyond H's: the friction's (and a
                    # drag's) entries there, read off the assembled J
                    self._add_jacobian_columns(hessian, held_data[0], turned, vecs)
            else:
                hessian.factorise(0.0)
                solver = hessian
            shifts = [] if lift is None else [lift]
            if planes:
                shifts = planes[:2] + shifts
            rights = columns + shifts + turned
            solved = solver.solve_many(rights)
            vecs.extend(solved)
            if solver is self.jacobian:
                vecs.extend(_refine(solver, rights, solved))
            if planes:
                response = self._plane_response(hessian, columns, readers,
                                                solved[:len(columns) + len(shifts)],
                                                recorder.positions, solver)
                # the reaction's rows read H_n's transpose (readers; with the friction
                # or a profile's block unsymmetric, else the same)
                seabed = [(i, readers[i], self._plane_held_shift(
                    hessian, recorder.positions.transpose(0, 2, 1), i)) for i in range(3)]
            else:
                response = self._response(hessian, columns, shift,
                                          solved[:len(columns) + len(shifts)],
                                          recorder.heights, solver)
                seabed = [] if shift is None else [(2, shift, self._height_held_shift(
                    hessian, recorder.heights))]
            if rotations:
                response = self._rotation_response(hessian, frames, columns, solved,
                                                   *held_data, response, flexed,
                                                   len(shifts), seabed, solver=solver)
        finally:
            for vec in vecs:
                vec.destroy()
            state.restore(saved)
        if planes:                                          # (x_a, c) of (x_a, x_b)
            chain = np.block([[np.eye(3), np.zeros((3, 3))], [-np.eye(3), np.eye(3)]])
        else:                                               # (z_a, c) of (x_a, x_b)
            chain = np.zeros((4, 6))
            chain[0, 2] = 1.0
            chain[1:, :3] = -np.eye(3)
            chain[1:, 3:] = np.eye(3)
        if not rotations:
            return response @ chain
        full = np.zeros((chain.shape[0] + 6, 12))           # (data, th_a, th_b)
        full[:-6, :6] = chain
        full[-6:, 6:] = np.eye(6)
        return response @ full

    def _node_values(self, arrays, nodes):
        """The values of the global P2 ``nodes`` of per-owned-node ``arrays`` (list of
        (n_local_nodes, ...)), on every rank: (len(arrays), len(nodes), ...).
        Collective."""
        mesh = self.mesh
        first = 2 * mesh.vertex_start
        n_local = arrays[0].shape[0]
        out = np.zeros((len(arrays), len(nodes)) + arrays[0].shape[1:])
        for j, node in enumerate(nodes):
            if first <= node < first + n_local:
                out[:, j] = [a[node - first] for a in arrays]
        return mesh.global_sum(out)

    def _flexed(self, hessian):
        """[(end, node, J_d, J_a, a, d, columns)] of the flex joints: turning the
        support by delta turns the axis, a data change of the joint's gradient in its
        node's rotation, G = _joint_moment (dE/domega): ``columns`` the three Vecs
        J_a (e_k x a) on that node's rows (new Vecs). Collective."""
        out = []
        last = 2 * self.mesh.n_elements
        for e, d, term in self._joint_tangents():
            node = (0, last)[e]
            a = term.axis
            J_d, J_a = _joint_jacobians(term.k, d, a)
            columns = []
            for k in range(3):
                vec = hessian.matrix.createVecLeft()
                vec.zeroEntries()
                low, high = vec.getOwnershipRange()
                rows = hessian.block * node + np.arange(3)
                if low <= rows[0] < high:
                    vec.setValues(rows.astype(PETSc.IntType),
                                  J_a @ np.cross(np.eye(3)[k], a))
                vec.assemble()
                columns.append(vec)
            out.append((e, node, J_d, J_a, a, d, columns))
        return out

    def _add_turn_columns(self, hessian, held, turned, vecs):
        """Add the followers' entries of J (DragTerm.turn_columns) to H's columns
        ``turned`` at the held rotations of ``held`` [(end, node, slot)]; the new Vecs
        go to ``vecs`` to be freed. Collective."""
        rotated = [j for j, (_, _, k) in enumerate(held) if k < 3]
        columns = [hessian.block * held[j][1] + held[j][2] for j in rotated]
        for term in self.problem.terms:
            if term.follower:
                extra = term.turn_columns(hessian, self.problem.state, columns)
                vecs.extend(extra)
                for j, vec in zip(rotated, extra):
                    turned[j].axpy(1.0, vec)

    def _add_profile_columns(self, hessian, held, turned, vecs):
        """On a seabed profile, add J's entries beyond H (SeabedTerm.turn_columns: the
        block's antisymmetric part) to H's columns ``turned`` at the held unknowns of
        ``held`` [(end, node, slot)], rotations and stretches; the new Vecs go to
        ``vecs`` to be freed. Collective."""
        if self.profile is None or not held:
            return
        extra = self.profile.turn_columns(hessian, self.problem.state,
                                          [hessian.block * node + k for _, node, k in held])
        vecs.extend(extra)
        for column, vec in zip(turned, extra):
            column.axpy(1.0, vec)

    def _add_jacobian_columns(self, hessian, held, turned, vecs):
        """Add J's entries beyond H's in the held data's columns (a clamp's rotation
        and stretch, [(end, node, slot)] ``held``) to H's columns ``turned``, read off the
        assembled Newton Jacobian: J is H with its held columns cleared plus the
        unsymmetric terms' entries (Term.add_jacobian), which keep those columns, with
        identity rows at the held unknowns, so J e_j with the held rows cleared is the
        terms' share of d(gradient)/d(held datum j): the friction's block through the
        clamped node's slope in its first element's midpoint (and a drag's turn,
        DragTerm.turn_columns). The new Vecs go to ``vecs`` to be freed. Collective."""
        matrix = self.jacobian.matrix
        unit_vec = matrix.createVecRight()
        vecs.append(unit_vec)
        low, high = unit_vec.getOwnershipRange()
        for j, (_, node, slot) in enumerate(held):
            column = hessian.block * node + slot
            unit_vec.zeroEntries()
            if low <= column < high:
                unit_vec.setValue(column, 1.0)
            unit_vec.assemble()
            extra = matrix.createVecLeft()
            vecs.append(extra)
            matrix.mult(unit_vec, extra)
            hessian.zero_held(extra)
            turned[j].axpy(1.0, extra)

    def _held_data(self, hessian, clamps):
        """The held unknowns a clamp's data moves: [(end, node, slot)], slot 0-2 its
        rotation and 3 its stretch (an extensible line's clamped node, EA finite: held in
        H, set by the force balance, docs/method.md §12), with that node's EA (inf
        where none). Collective."""
        held = [(e, node, k) for e, node in clamps for k in range(3)]
        axial = np.full(len(clamps), np.inf)
        if hessian.stretch and clamps:
            axial = self._node_values([self.problem.axial], [n for _, n in clamps])[0]
            held += [(e, node, 3) for (e, node), ea in zip(clamps, axial) if np.isfinite(ea)]
        return held, dict(zip([e for e, _ in clamps], axial))

    def _rotation_response(self, hessian, frames, columns, solved, held, axial, response,
                           flexed=(), shifts=0, seabed=(), solver=None):
        """d(F_a, F_b, M_a, M_b)/d(s, c, theta_a, theta_b), (12, p + 9): s the start's
        data of ``response`` ((6, p + 3), d(F_a, F_b)/d(s, c): _response's, s = z_a,
        p = 1, or on a sloping plane _plane_response's, s = x_a, p = 3).

        A clamp turned by theta holds its node's rotation at theta instead of 0: the
        free unknowns see B theta on their right-hand side (B the held columns of H,
        hessian.full_columns) and the chord moves by G theta, G = -w_n [t_n]x at the
        clamped node; on an extensible line the clamped node's stretch k is held data
        too (B its column, G = w_n t_n / |t_n|), fixed by the force balance
        EA (k - 1) = n.d3 at that end. With the held data h (theta, and those
        stretches), Y_T = A^-1 B:
        dmu = -S^-1 (dc + C Y_P dz + (C Y_T - G) h), dy = -Y_P dz - Y_C dmu - Y_T h,
        then dk = (dn.d3 + n.(theta x d3)) / EA solved for. The moment m at an end
        vertex is K u of the end element's three nodes' frames
        (io/outputs.vertex_fields): its derivative in each node's rotation and stretch
        by a complex step of that closed form, applied to dy at the free nodes and to
        the held data at a clamped one. The free roll's form, a fourth of ``columns``
        (held at 0 by every datum, its multiplier dropped), as in _response
        (_held_forms). ``shifts``: the solves Y_P = A^-1 P of the start's data (0, 1:
        P for z_a, 3: P_j for x_a), after the forms' in ``solved``; ``seabed``: [(row,
        P_i, P_i with its held rows)] of the seabed's reaction on the start, dR_s,i =
        -(P_i.dy + the held data's share), row i of F_a (with the friction the shifts of
        H_n's transpose, _plane_response's Q_i)."""
        mesh, B, U = self.mesh, hessian.block, hessian.unknowns
        p = response.shape[1] - 3                           # the start's data: 1 or 3
        base = p + 3                                        # the first rotation's column
        n_h = len(held) + 3 * len(flexed)
        n_d = base + 6 + sum(k == 3 for _, _, k in held)    # data: s, c, thetas, stretches
        n_s = len(columns)                                  # the solves of the forms
        Y_P = solved[n_s:n_s + shifts]
        Y_T = solved[n_s + len(Y_P):]
        n_p = len(Y_P)
        columns, Y_C, schur = self._held_forms(columns, solved[:n_s], solver)
        n_c = len(columns)
        used = Y_C + Y_P + Y_T                              # the solves the response reads
        data = []                                           # the data column of each held
        stretches = []
        for e, node, k in held:
            if k < 3:
                data.append(base + 3 * e + k)
            else:
                data.append(base + 6 + len(stretches))
                stretches.append(e)
        data += [base + 3 * entry[0] + k for entry in flexed for k in range(3)]
        inverse = np.linalg.inv(schur)
        nodes_held = [node for _, node, _ in held]
        w = self._node_values([self.problem.state.node_weights], nodes_held)[0]
        t = self._node_values([frames[:, 2]], nodes_held)[0]
        G = np.zeros((n_c, n_d))                            # the roll's row: held at 0
        CY_T = np.zeros((n_c, n_d))
        for j, (e, node, k) in enumerate(held):
            G[:3, data[j]] = (-w[j] * skew(t[j])[:, k] if k < 3
                              else w[j] * t[j] / np.linalg.norm(t[j]))
            CY_T[:, data[j]] = [c.dot(Y_T[j]) for c in columns]
        for j in range(len(held), n_h):                     # a flex joint's axis
            CY_T[:, data[j]] = [c.dot(Y_T[j]) for c in columns]
        along = np.array([[c.dot(y) for y in Y_P] for c in columns]).reshape(n_c, n_p)
        multipliers = -inverse @ (CY_T - G)                 # d (mu, roll's) / d(data)
        multipliers[:, :p] = 0.0
        multipliers[:, :n_p] = -inverse @ along
        multipliers[:, p:base] = -inverse[:, :3]
        dmu = multipliers[:3]
        onto = np.eye(n_p, n_d)                             # Y_P onto the start's data

        def of_dy(values_C, values_P, values_T):
            """A linear functional of dy (its values on Y_C (.., n_c), the Y_P (..,
            n_p) and the Y_T (.., n_h)) as a function of the data."""
            out = -values_P @ onto - values_C @ multipliers
            for j, col in enumerate(data):
                out[..., col] -= values_T[..., j]
            return out

        forces = np.zeros((6, n_d))
        forces[3:] = dmu
        forces[:3] = -dmu
        if hessian.resultants:                              # the drag's resultant Psi_0
            slot = hessian.resultant_slot
            first = mesh.global_sum(np.array(
                [y.getArray(readonly=True).reshape(-1, B)[0, slot:slot + 3]
                 if mesh.on_lower_boundary else np.zeros(3) for y in used]))
            forces[:3] += of_dy(first[:n_c].T, first[n_c:n_c + n_p].T,
                                first[n_c + n_p:].T)
        forces[:3, :base] = response[:3]
        for row, shift, held_shift in seabed:
            moved = of_dy(np.array([shift.dot(y) for y in Y_C]),
                          np.array([shift.dot(y) for y in Y_P]),
                          np.array([shift.dot(y) for y in Y_T]))
            full = held_shift()
            try:
                at = self._node_values([full.getArray(readonly=True).reshape(-1, B)[:, :U]],
                                       nodes_held)[0]
            finally:
                full.destroy()
            for j, (e, node, k) in enumerate(held):
                moved[data[j]] += at[j, k]
            forces[row, base:] -= moved[base:]
        # the moments: the three nodes of each end element
        last = 2 * mesh.n_elements
        ends = ([0, 1, 2], [last - 2, last - 1, last])
        arrays = [y.getArray(readonly=True).reshape(-1, B)[:, :U] for y in used]
        values = self._node_values(arrays, ends[0] + ends[1])          # (vecs, 6, U)
        fields = self._node_values([self.problem.state.node_directors()],
                                   ends[0] + ends[1])[0]
        S = np.array([_at_vertex(mesh, mesh.vertex_S, index) for index in
                      (0, 1, mesh.n_elements - 1, mesh.n_elements)])
        moments = np.zeros((6, n_d))
        for e in (0, 1):
            h = S[1] - S[0] if e == 0 else S[3] - S[2]
            jac = _moment_jacobian(fields[3 * e:3 * e + 3], h,
                                   self._end_stiffness_values(e, S), e, U)
            for k in range(3):
                v = values[:, 3 * e + k]                                # (vecs, U)
                delta = of_dy(v[:n_c].T, v[n_c:n_c + n_p].T,
                              v[n_c + n_p:].T if n_h else np.zeros((U, 0)))
                for j, (end, node, slot) in enumerate(held):
                    if node == ends[e][k]:
                        delta[slot, data[j]] += 1.0
                moments[3 * e:3 * e + 3] += (1.0 if e == 0 else -1.0) * jac[:, k] @ delta
        for e, node, J_d, J_a, a, d, _ in flexed:           # the joint's moment
            v = values[:, 0 if e == 0 else 5]
            delta = of_dy(v[:n_c].T, v[n_c:n_c + n_p].T,
                          v[n_c + n_p:].T if n_h else np.zeros((U, 0)))
            moments[3 * e:3 * e + 3] = J_d @ (-skew(d) @ delta[:3])
            moments[3 * e:3 * e + 3, base + 3 * e:base + 3 + 3 * e] += J_a @ (-skew(a))
        out = np.vstack([forces, moments])
        if not stretches:
            return out
        # the clamps' stretches from their force balance: dk = rows @ (data, dk)
        rows = np.zeros((len(stretches), n_d))
        for i, e in enumerate(stretches):
            d3 = t[data.index(base + 6 + i)]
            d3 = d3 / np.linalg.norm(d3)
            force = self.end_forces()[e]
            n = force - points_on_held_ends(self.problem)[e] if e == 0 else \
                -(force - points_on_held_ends(self.problem)[e])
            sign = 1.0 if e == 0 else -1.0                  # n(0) = F_a, n(L) = -F_b
            rows[i] = sign * d3 @ out[3 * e:3 * e + 3] / axial[e]
            rows[i, base + 3 * e:base + 3 + 3 * e] += np.cross(d3, n) / axial[e]
        own = rows[:, base + 6:]
        solved_k = np.linalg.solve(np.eye(len(stretches)) - own, rows[:, :base + 6])
        return out[:, :base + 6] + out[:, base + 6:] @ solved_k

    def _end_stiffness_values(self, e, S):
        """(K1, K2, K3) of the end element of end ``e`` at its end (vertex_fields')."""
        scene = self.scene
        if scene.uniform_stiffness:
            return np.asarray(scene.stiffness, dtype=float)
        at, inside = (S[0], 0.5 * (S[0] + S[1])) if e == 0 else (S[3], 0.5 * (S[2] + S[3]))
        return scene.stiffness_at(np.array([at]), inside=np.array([inside]))[0]

    @staticmethod
    def _held_forms(columns, solved, solver):
        """(forms, their solves, S) of the constraints the Schur solve holds: the chord's
        three forms C^T, and a fourth, the free roll's r, only where the factor of A
        kept the roll's null pivot: r.A^-1 r above r.r / (NULL_PIVOT |A|_inf) (where the
        factor dropped that direction itself, the substructured interface's
        pseudo-inverse, the roll's Schur entry is of the matrix's own size); S = C Y_C
        (n_c, n_c) of the forms kept. LinAlgError where S is not finite (A not
        factored). Collective."""
        schur = np.array([[c.dot(y) for y in solved] for c in columns])
        if not np.all(np.isfinite(schur)):
            raise np.linalg.LinAlgError("the line's second variation could not be "
                                        "factored at its equilibrium")
        if len(columns) == 4 and abs(schur[3, 3]) \
                * solver.matrix.norm(PETSc.NormType.INFINITY) \
                < columns[3].dot(columns[3]) / NULL_PIVOT:
            return columns[:3], solved[:3], schur[:3, :3]
        return list(columns), list(solved), schur

    def _response(self, hessian, columns, shift, solved, heights, solver=None):
        """d(F_a, F_b)/d(z_a, c), (6, 4), from the solves Y = A^-1 [C^T, P] (A: H, or
        J in a current): dmu = -S^-1 (dc + C Y_P dz), dy = -Y_P dz - Y_C dmu, F_b = mu,
        F_a = W + Psi_0 + R_s e_z - mu with Psi_0 the load's resultant at S = 0 that
        follows the shape (the drag's, a row of dy) and R_s the seabed's whole reaction,
        dR_s = -(P.dy + sum k w_n dz). A fourth column, the free roll's form, held at 0
        with its multiplier dropped where the factor kept its pivot (_held_forms).
        Collective."""
        mesh = self.mesh
        Y_P = solved[len(columns):]
        columns, Y_C, schur = self._held_forms(columns, solved[:len(columns)], solver)
        n_c = len(columns)                  # the chord's three, and the roll's (held 0)
        inverse = np.linalg.inv(schur)
        along = np.array([c.dot(Y_P[0]) for c in columns]) if Y_P else np.zeros(n_c)
        multipliers = np.zeros((n_c, 4))                    # d (mu, roll's) / d(z_a, c)
        multipliers[:, 0] = -inverse @ along
        multipliers[:, 1:] = -inverse[:, :3]
        dmu = multipliers[:3]

        def of_dy(values_C, value_P):
            """A linear functional of dy (values on Y_C (.., 3) and on Y_P (..,))
            as a function of (z_a, c)."""
            return -np.multiply.outer(value_P, [1.0, 0.0, 0.0, 0.0]) - values_C @ multipliers

        start = -dmu.copy()
        if hessian.resultants:
            slot = hessian.resultant_slot
            first = [y.getArray(readonly=True).reshape(-1, hessian.block)[0, slot:slot + 3]
                     if mesh.on_lower_boundary else np.zeros(3) for y in Y_C + Y_P]
            first = mesh.global_sum(np.array(first))        # (n_c [+ 1], 3): Psi_0 of each Y
            start += of_dy(first[:n_c].T, first[n_c] if Y_P else np.zeros(3))
        if shift is not None:
            moved = of_dy(np.array([shift.dot(y) for y in Y_C]), shift.dot(Y_P[0]))
            moved[0] += mesh.global_sum(float(heights.sum()))
            start[2] -= moved                               # P.dy + sum k w_n dz
        return np.vstack([start, dmu])

    @staticmethod
    def _height_held_shift(hessian, heights):
        """A function giving P = d(grad L)/dz_a with its held rows kept (a new Vec):
        the held data's share of the flat seabed's reaction (_rotation_response)."""
        return lambda: hessian.position_shift(heights, 2, held=True)

    @staticmethod
    def _plane_held_shift(hessian, curvature, j):
        """A function giving P_j (_plane_shift) with its held rows kept (a new Vec):
        the held data's share of the plane's reaction along axis j
        (_rotation_response)."""
        return lambda: HeldLine._plane_shift(hessian, curvature, j, held=True)

    @staticmethod
    def _plane_shift(hessian, curvature, j, held=False):
        """P_j = sum_c sum_n H_n[c, j] dx^c_n/dy (a new Vec): how the gradient moves when
        every node is shifted by 1 m along axis j (the start moved), H_n = k w_n N N^T
        the sloping plane's curvature at the owned nodes (n_nodes, 3, 3)
        (SecondVariation.position_shift per component; ``held``: its held rows kept).
        Collective."""
        total = hessian.position_shift(curvature[:, 0, j], 0, held=held)
        for c in (1, 2):
            part = hessian.position_shift(curvature[:, c, j], c, held=held)
            total.axpy(1.0, part)
            part.destroy()
        return total

    @staticmethod
    def _plane_shifts(hessian, curvature):
        """[P_x, P_y, P_z] (_plane_shift; three new Vecs). Collective."""
        return [HeldLine._plane_shift(hessian, curvature, j) for j in range(3)]

    def _plane_response(self, hessian, columns, planes, solved, curvature, solver):
        """d(F_a, F_b)/d(x_a, c), (6, 6), on a sloping plane: _response with the start's
        whole position as data. With Y_C = A^-1 C^T and Y_j = A^-1 L_j (L_j = P_j, the
        sheared drag's height columns added to L_z): dmu = -S^-1 (dc + C Y_j dx_a,j),
        dy = -Y_j dx_a,j - Y_C dmu, F_b = mu, F_a = W + Psi_0 + R_s - mu with R_s the
        seabed's whole reaction, dR_s,i = -(Q_i.dy + sum_n H_n[i, j] dx_a,j), the
        functionals ``planes`` Q_i = sum_j sum_n H_n[i, j] dx^j_n/dy: P_i where H_n is
        symmetric (the plane), the shifts of H_n's transpose with the friction (its
        force on the line, part of R_s, reads the heights, and on a plane the
        horizontal positions through the limit: H_n is not symmetric). Collective."""
        mesh = self.mesh
        n_all = len(columns)
        Y_P = solved[n_all:n_all + 3]
        columns, Y_C, schur = self._held_forms(columns, solved[:n_all], solver)
        n_c = len(columns)
        inverse = np.linalg.inv(schur)
        along = np.array([[c.dot(y) for y in Y_P] for c in columns])     # (n_c, 3)
        multipliers = np.zeros((n_c, 6))                    # d (mu, roll's) / d(x_a, c)
        multipliers[:, :3] = -inverse @ along
        multipliers[:, 3:] = -inverse[:, :3]
        dmu = multipliers[:3]

        def of_dy(values_C, values_P):
            """A linear functional of dy (its values on Y_C (.., n_c) and on the Y_j
            (.., 3)) as a function of (x_a, c)."""
            return -np.concatenate([values_P, np.zeros(values_P.shape[:-1] + (3,))],
                                   axis=-1) - values_C @ multipliers

        start = -dmu.copy()
        if hessian.resultants:
            slot = hessian.resultant_slot
            first = [y.getArray(readonly=True).reshape(-1, hessian.block)[0, slot:slot + 3]
                     if mesh.on_lower_boundary else np.zeros(3) for y in Y_C + Y_P]
            first = mesh.global_sum(np.array(first))        # (n_c + 3, 3): Psi_0 of each Y
            start += of_dy(first[:n_c].T, first[n_c:].T)
        moved = of_dy(np.array([[p.dot(y) for y in Y_C] for p in planes]),
                      np.array([[p.dot(y) for y in Y_P] for p in planes]))
        moved[:, :3] += mesh.global_sum(curvature.sum(axis=0))
        start -= moved                                      # P_i.dy + sum_n H_n dx_a
        return np.vstack([start, dmu])

    def _profile_term(self):
        """The SeabedTerm of a seabed profile or grid, whose contact its Newton system
        holds linearised (SeabedTerm.profile), or None on another seabed or none."""
        return next((term for term in self.problem.terms
                     if isinstance(term, SeabedTerm) and term.profile), None)

    def _record_profile(self, recorder):
        """On a seabed profile, the recorder's block the profile's whole B_n
        (SeabedTerm.position_derivatives), unsymmetric near a row, where its
        add_hessian gave H's symmetric part."""
        if self.profile is not None:
            recorder.positions = self.profile.position_derivatives(self.problem.state)

    def _check_solved(self):
        if self.problem is None or not self.converged:
            raise RodInputError("HeldLine: no converged equilibrium yet (solve first, and "
                                "check what it returns)")

    def _check_exact(self):
        """Refuse a stiffness where it would not be exact (module docstring)."""
        if any(not term.held_exact for term in self.friction):
            raise RodInputError(f"{self.name}: seabed friction with two coefficients "
                                "(axial and lateral: MoorDyn's MU_KA and MU_KT) gives no "
                                "exact stiffness for the system's Newton: give the "
                                "friction one coefficient")
        # a profile's or grid's lagged push: its linearisation is the seabed term's
        # (SeabedTerm.profile)
        lagged = {term for term in self.problem.terms if self.profile is not None
                  and getattr(term, "contact", None) is self.profile}
        loose = [term for term in self.problem.terms
                 if term not in lagged and term not in self.friction
                 and not (term.in_newton and (term.conservative or term.follower))]
        if loose:
            loads = "; ".join(dict.fromkeys(term.newton_gap or type(term).__name__
                                            for term in loose))
            raise RodInputError(f"{self.name}: loads outside the Newton steps "
                                f"({loads}) give no exact stiffness for the system's "
                                "Newton")

    def destroy(self):
        """Free the line's PETSc objects (its BuiltLine's, its Newton solver's). Collective."""
        self._release()


def friction_notes(system):
    """The run's note on a system whose seabed has friction (a tuple of one line, or
    none): what its friction is measured from (module docstring, "Friction")."""
    if system.environment.seabed_friction is None:
        return ()
    return ("seabed friction measured from the lines' as-laid shapes: each line's "
            "friction anchors are its nodes where its first solve starts (the catenary "
            "between its ends' start positions, before any offset), held through the "
            "whole solve, its load steps, sweeps and cases "
            '(docs/systems.md, "Seabed friction")',)


def line_sea(line, environment):
    """The sea a system line ``line`` is solved in: the system's ``environment``, without
    its current where the line is one of sections that takes no drag (its line types'
    c = rho Cd D / 2 all 0, MoorDyn's Cd 0 columns, and no attachment with a drag area),
    which a single line in a current is refused for (model/derived.check_current_drag):
    the system's current pushes its other lines and its free points. A uniform line
    keeps it (its drag, given with the line, may be 0)."""
    if environment.current is None:
        return environment
    span = Span(line.line, End("pin"), End("pin"), tuple(line.attachments))
    if not span.sections:
        return environment
    loads = Loads.of(span, environment)
    if loads.drag or np.any(loads.drag_areas > 0):
        return environment
    return dataclasses.replace(environment, current=None)


def held_lines(system, options=None, laid=None):
    """The ``make_line(system_line, comm)`` of system/equilibrium.SystemSolver for the
    real lines of ``system`` (a model.system.System): each a HeldLine whose ends are
    first where the system's points and bodies put its connections at their start
    positions (system_check.connection_position), a clamp's frame where its
    Connection.direction puts it at its body's start pose (connection_frame), in the
    system's environment, tuned
    by ``options`` (-rod_* options without ``rod_``). The lines' own stability test is
    off ({'al_stability': 0} unless ``options`` says otherwise): the system tests each
    line once at its equilibrium (SystemSolver.line_verdicts, HeldLine.stable)
    instead of after each of its re-solves; and they are settled at their stationary
    points (HeldLine.settle) for the stiffness the system reports only, not for its
    iterations' Jacobian. A current profile's depths are below the
    system's sea surface, z = 0 where the Environment gives none (as the free points'
    drag, system/equilibrium.py), not below each line's higher end as for a single
    line: the lines and points of a system share one sea. ``laid``: a System with the
    same points and bodies (the system file's, before a run's or a sweep case's
    offsets) whose start positions lay each frictional line (HeldLine.laid: its
    friction's anchors; None: ``system``'s own), so that every case measures its
    friction from the same laid lines."""
    options = {"al_stability": 0, **(options or {})}
    environment = system.environment
    if environment.profile() is not None and environment.surface is None:
        environment = dataclasses.replace(environment, surface=0.0)

    def make_line(line, comm):
        start, end = (connection_position(system.node(c.to), c)
                      for c in (line.start, line.end))
        frames = tuple(connection_frame(system.node(c.to), c, e == 1)
                       if c.kind == "clamp" and not hasattr(system.node(c.to), "kind")
                       else None for e, c in enumerate((line.start, line.end)))
        held = HeldLine.of_system_line(line, start, end, comm,
                                       line_sea(line, environment), options, frames)
        if laid is not None and environment.seabed_friction is not None:
            ends = tuple(connection_position(laid.node(c.to), c)
                         for c in (line.start, line.end))
            if not (np.array_equal(ends[0], start) and np.array_equal(ends[1], end)):
                held.laid = tuple(np.asarray(e, dtype=float) for e in ends)
        held.settles = False                # SystemSolver.evaluate settles it when it reports
        return held

    make_line.predictable = True            # rods a catenary may stand in for (predictor)
    return make_line
