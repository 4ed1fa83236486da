"""The augmented-Lagrangian (Uzawa, ALG2) iteration of docs/method.md §3, driven by a
PETSc SNES (§6), with the stability test of §10 at each converged step.

State: d1, d2 and the slope theta = r' = d3 (P2 VectorFields on the DMDA), the
centreline r at the vertices (a VectorField holding the Hermite pair (r, r') of each
vertex, recovered from theta by integration, centreline.py) and, at the owned P2 nodes,
tau and lambda, arrays (n_nodes, 3 directors, 3 components) with director rows d1, d2,
d3 = r'. One iteration: global step (three scalar SPD solves per field, factorisations
reused), local step (nearest rotation at every node), multiplier update.
"""

import time
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from . import boundary, starts
from .assembly import ScalarProblem, assemble_matrix, load_ghosted
from .centreline import (anchor_work, load_offset, midpoint_slopes, positions_at_points,
                         vertex_positions)
from .errors import RodDivergedError, RodInputError
from .fe import (GAUSS_POINTS, P2, element_integrals, p2_basis,
                 p2_element_matrices, p2_integrals, quadrature_weights)
from .fields import VectorField, at_points, element_dofs
from .kernels import (nearest_rotation, rotations, split_coefficients, strains,
                      update_multipliers)
from .link import FULLER_MARGIN, link_integrands
from .options import set_from_options_with_defaults
from .resources import anderson_depth, ranks_on_this_machine
from .riser.terms import RiserTerms
from .stability import SecondVariation

EVENTS = {name: PETSc.Log.Event(f"rod_{name}")
          for name in ("assembly", "rhs", "solve", "projection", "multiplier", "norms")}


# An RMS constraint residual this large means the directors are no longer near unit
# vectors: the iteration has left every meaningful state.
DIVERGED_RESIDUAL = 1e3


@dataclass
class Settings:
    penalty: float
    max_it: int = 2000
    rtol: float = 1e-9
    ctol: float = 1e-9
    monitor: bool = False
    adapt_penalty: bool = True      # raise a penalty far below the scale (raise_penalty)
    check_stability: bool = True    # test the second variation at convergence (stability.py)


@dataclass
class StepReport:
    converged: bool
    iterations: int
    change: float           # the last iteration's relative change
    constraint_residual: float
    history: list = field(default_factory=list)   # (change, residual, wall time) rows
    reason: str = ""        # why a step that did not converge stopped (STOP_* below)
    penalty_raises: list = field(default_factory=list)  # (iteration, new R) rows
    link: tuple = None          # (Tw, Wr) after the step, turns (UzawaSolver.link)
    link_expected: float = None     # the Lk the load path leads to, turns (continuation)
    stable: bool = None     # the second variation is positive (stability.py); None: unchecked
    escapes: int = 0        # saddles the step converged to and left

    @property
    def stalled(self):
        return self.reason == STOP_STALLED


# The SNES type of the iteration unless -rod_snes_type says otherwise.
DEFAULT_SNES = "anderson"
SNES_REASONS = {getattr(PETSc.SNES.ConvergedReason, name): name.lower()
                for name in dir(PETSc.SNES.ConvergedReason) if not name.startswith("_")}

STOP_MAX_IT = "max_it"
STOP_STALLED = "stalled"
STOP_OBSERVER = "observer"
STOP_LINK = "link"              # converged, to a state of another linking number (link.py)
# The stall test looks at windows of this many iterations (stalled_projection) ...
STALL_WINDOW = 1000
# ... and only once both stopping quantities are within this factor of their tolerances
# (an iterate still far away, e.g. leaving an unstable branch, may see them grow for a
# while and is not stalled).
STALL_FACTOR = 10.0
# A rate that would need more than this many times the remaining budget is a stall; a
# slower one is given the budget (an iterate leaving a nearly symmetric state speeds up:
# its rate over one window underestimates it).
STALL_MARGIN = 10.0
# The test reads 3 windows of history; it runs every this many iterations, so that its
# Python work (0.12 ms measured, a seventh of an iteration on 80 elements) stays out of
# most iterations.
STALL_CHECK_EVERY = STALL_WINDOW // 10


RAISE_PENALTY = "raise_penalty"     # the step goes on with a larger R (raise_penalty)
CONVERGED = (True, "")
STOP_SADDLE = "saddle"      # converged, to a saddle, MAX_ESCAPES times
# A step that converged to a saddle goes on from its frames turned along the direction
# of negative curvature, the largest node turned by ESCAPE_ANGLE rad, the angle times
# ESCAPE_GROWTH and of the other sign at each further saddle, at most MAX_ESCAPES times
# (large enough to leave the saddle's basin of the accelerated iteration: 0.1 rad did not
# on the paper scene, docs/stability.md).
ESCAPE_ANGLE = 0.3
MAX_ESCAPES = 5
ESCAPE_GROWTH = 2.0


@dataclass
class StepProgress:
    """What one step has done so far (UzawaSolver.solve_step): a (change, residual,
    wall time) row per iteration, the penalty raises, and the outcome once decided:
    (converged, reason), or RAISE_PENALTY, or the error that ended it."""

    label: str
    observer: object
    clock: float = field(default_factory=time.perf_counter)
    history: list = field(default_factory=list)
    raises: list = field(default_factory=list)
    outcome: object = None
    error: Exception = None
    stable: bool = None         # a local minimiser (stability.py); None: not checked
    escapes: int = 0            # saddles left on the way

    @property
    def finished(self):
        return self.outcome is not None or self.error is not None


def stalled_projection(values, target, budget):
    """Whether ``values`` (one per iteration, newest last), at their rate over the last
    STALL_WINDOW iterations, would need more than STALL_MARGIN times ``budget`` further
    iterations to fall to ``target``.

    The rate compares the smallest value of the last window with that of the window
    before (both quantities oscillate from one iteration to the next); no progress at all
    counts only when it lasts two windows (an iterate leaving a nearly symmetric state
    can mark time for a while and then go on). If the minimum
    falls by a factor q per window, reaching the target takes log(target / v_min) / log(q)
    windows. Why a step stalls: on a mesh too coarse for the tolerance the discrete
    constraint cannot be met (the residual settles on a floor, about h^3, and creeps down
    by 0.13% per 1000 iterations on 2 elements twisted by 0.5 rad), and the multipliers
    then drift, which keeps the change per iteration at a floor of its own. This test
    ends such a step with its reason instead of running out -rod_al_max_it.
    """
    if len(values) < 3 * STALL_WINDOW:
        return False
    oldest, before, recent = (min(values[-k * STALL_WINDOW:len(values) - (k - 1) * STALL_WINDOW])
                              for k in (3, 2, 1))
    if recent <= target:
        return False
    if recent >= before:
        return before >= oldest           # no progress over two windows in a row
    windows = np.log(target / recent) / np.log(recent / before)
    return windows * STALL_WINDOW > STALL_MARGIN * budget


def stalled(history, rtol, ctol, budget):
    """The stall test of UzawaSolver.solve_step on its (change, residual, time) rows: once
    the change and the constraint residual are within STALL_FACTOR of their tolerances
    (or the change is below rtol: the iterate no longer moves, e.g. a straight rod whose
    ends are brought together along its axis, held by its symmetry in a state that cannot
    meet the constraint), whether either would not reach its tolerance within ``budget``
    iterations (stalled_projection)."""
    change, residual = history[-1][:2]
    if change > STALL_FACTOR * rtol:
        return False
    if residual > STALL_FACTOR * ctol and change > rtol:
        return False
    window = history[-3 * STALL_WINDOW:]
    return any(stalled_projection([row[column] for row in window], tolerance, budget)
               for column, tolerance in ((0, rtol), (1, ctol)))


# A convex split's penalty below ADAPT_BELOW times the problem's scale (default_penalty)
# is multiplied by ADAPT_FACTOR, up to the scale, whenever the constraint residual has
# fallen by less than the factor ADAPT_PROGRESS over the last ADAPT_WINDOW iterations
# (UzawaSolver.raise_penalty).
ADAPT_BELOW = 0.1
ADAPT_FACTOR = 10.0
ADAPT_PROGRESS = 0.5
ADAPT_WINDOW = 200


def penalty_too_low(history, penalty, scale):
    """Whether a step's (change, residual, time) rows call for a larger penalty: R below
    ADAPT_BELOW times the scale, and the residual of the last row more than ADAPT_PROGRESS
    times that of ADAPT_WINDOW rows before."""
    if penalty >= ADAPT_BELOW * scale or len(history) <= ADAPT_WINDOW:
        return False
    return history[-1][1] > ADAPT_PROGRESS * history[-1 - ADAPT_WINDOW][1]


def matrix_split(split):
    """The coefficients c_i of the global step's matrices 2 c_i K + R W (docs/method.md §2).

    Where every a_i > 0, c = a. A stiffness above the sum of the other two makes one
    a_j < 0 (a flat section; K3 > K1 + K2 in torsion): its matrix would be indefinite
    unless R grew like 1/h^2. Instead c_j = max_i a_i, and the difference
    2 (c_j - a_j) K tau_j goes to the right-hand side (UzawaSolver._add_lagged_part): the
    fixed points are those of the a_i, and the matrix of d_j keeps a stiffness of the
    size of the other two, so that the iteration stays stable at any h.
    """
    return np.where(split < 0, split.max(), split)


def default_penalty(scene):
    """R = max(100 sqrt(min(K) max(K)) / L^2, applied force / 2, 2 M^2 / min(K1, K2)), N.

    The first term is the bending and torsion scale. The iteration count grows with R
    over the softest stiffness and fails when R is far below the stiffest one, hence
    their geometric mean (measured, docs/stability.md: pure twist with K3 = 0.01 K1
    converges in 2003 iterations at R = 4 and not in 20000 at the former default
    400 max(K) / L^2; a cantilever loaded to P L^2 / K1 = 3 with K3 = 0.01 K1 does not
    converge at R = 1 and does in 1627 at R = 10; K = (1, 1, 1): 473, 1157 and 4016
    iterations at R = 30, 100 and 400). For the paper's data it gives 67 N, close to the
    fastest R measured there (90 N, docs/error_vs_time.md). The second term is the scale
    of the tension, which the multiplier lambda3 has to reach by steps of at most 2R per
    iteration: a 3000 m catenary under 1 kN/m (tension ~1e6 N, K = 1e5 N m^2) diverges
    in the first iteration at 400 K / L^2 = 4.4 N and converges in 771 iterations at
    1.5e6 N. The third is the scale of the twisting moment M = K3 a / L of a clamped end
    turned by an angle a: M^2 / K_b, K_b = min(K1, K2), is four times the axial
    compression the moment stands for in Greenhill's buckling condition
    (M / 2K_b)^2 + P / K_b = (pi / L)^2. Below it the iteration leaves a twisted rod's
    branch: clamped 0.9 L apart and twisted, K = 1, R = 100 loses a whole turn of link at
    9.75 rad (M^2 / K_b = 95 N) and R = 150 at 11.9 rad (142 N), while R = 200 keeps it
    to 4 pi (158 N; docs/stability.md, fix 9).
    """
    stiffness = scene.stiffness
    bending = 100.0 * np.sqrt(stiffness.min() * stiffness.max()) / scene.length**2
    moment = stiffness[2] * scene.end_rotation() / scene.length
    twist = 2.0 * moment**2 / stiffness[:2].min()
    return max(bending, 0.5 * scene.applied_force(), twist)


def check_anderson_depth():
    """Refuse a -rod_snes_anderson_m that is not a whole number of at least 1 (PETSc
    itself fails on it with a stack of messages)."""
    database = PETSc.Options()
    if database.hasName("rod_snes_anderson_m"):
        depth = database.getString("rod_snes_anderson_m", "")
        if not depth.isdigit() or int(depth) < 1:
            raise RodInputError(f"-rod_snes_anderson_m {depth}: the depth of Anderson "
                                "mixing is a whole number of at least 1")


class UzawaSolver:
    """Owns every PETSc object of the solve; ``destroy()`` releases them all."""

    def __init__(self, mesh, scene, settings):
        check_anderson_depth()          # before any PETSc object is made
        self.mesh, self.scene, self.settings = mesh, scene, settings
        self.split = split_coefficients(scene.stiffness)
        self.matrix_split = matrix_split(self.split)
        self.penalty = float(settings.penalty)       # in use: raise_penalty may raise it
        self.scale = default_penalty(scene)
        self._lagged = None
        self.start_state, self.end_state = scene.start_state(0.0), scene.end_state(0.0)
        self.bordered = boundary.is_held(self.start_state) and boundary.is_held(self.end_state)
        self._build_problems()
        self.d1, self.d2, self.theta, self.r = (VectorField(mesh, n)
                                                for n in ("d1", "d2", "theta", "r"))
        self.rhs = [VectorField(mesh, f"rhs_{n}") for n in ("d1", "d2", "theta")]
        self.load = VectorField(mesh, "load")
        h = mesh.element_h
        self.p2 = p2_basis(GAUSS_POINTS, h)
        self.p2_integrals = p2_integrals(GAUSS_POINTS, h)
        self.weights = quadrature_weights(h)
        self.node_weights = mesh.node_weights()
        self._multiplier = np.zeros(3)
        # tau and lambda at the owned P2 nodes, rows d1, d2, d3 (docs/method.md §4)
        shape = (mesh.n_local_nodes, 3, 3)
        self.tau = np.zeros(shape)
        self.lam = np.zeros(shape)
        self._directors = np.zeros(shape)
        self._positions = np.zeros((mesh.n_local_nodes, 3))
        self._root_weights = np.sqrt(self.node_weights)[:, None, None]
        self._step = None
        self._create_snes()
        self._previous = None
        # the seabed and the current (petsc_rod/riser), built only when the scene has them
        self.riser = RiserTerms(self) if scene.seabed or scene.current else None

    def _build_problems(self):
        """The three scalar problems of the global step at the current R, with the
        prescribed values of the current end states (the only place they are created)."""
        mesh, h = self.mesh, self.mesh.element_h
        EVENTS["assembly"].begin()
        # frame order: d1, d2, theta = r' = d3
        self.problems = [ScalarProblem(
            mesh, p2_element_matrices(h, 2 * self.matrix_split[i], self.penalty),
            boundary.director_prescribed(i, self.start_state, self.end_state,
                                         mesh.n_elements), prefix)
            for i, prefix in enumerate(("rod_d1_", "rod_d2_", "rod_r_"))]
        self.d_problems, self.r_problem = self.problems[:2], self.problems[2]
        # Both ends held: r(L) - r(0) = int theta dS is a constraint of the theta problem.
        if self.bordered:
            self.r_problem.add_integral_constraint(element_integrals(h))
        self._set_prescribed()
        if self._lagged is None and np.any(self.matrix_split != self.split):
            # the stiffness K of the lagged part, and two work vectors for K tau_i
            self._lagged = assemble_matrix(mesh, p2_element_matrices(h, 1.0, 0.0))
            self._lagged_work = self._lagged.createVecs()
        EVENTS["assembly"].end()

    def _create_snes(self):
        """The SNES that drives the iteration (solve_step): the fixed-point problem
        x = G(x) as F(x) = x - G(x) on a vector of the node state, options -rod_snes_*.
        Its default, Anderson mixing, combines the last iterates into the one of least
        residual; nrichardson with the basic line search is the plain iteration."""
        size = 18 * self.mesh.n_local_nodes
        self._x = PETSc.Vec().createMPI((size, PETSc.DECIDE), comm=self.mesh.comm)
        self._f = self._x.duplicate()
        snes = self.snes = PETSc.SNES().create(comm=self.mesh.comm)
        snes.setOptionsPrefix("rod_")
        snes.setType(DEFAULT_SNES)
        snes.setFunction(self._fixed_point_residual, self._f)
        snes.setConvergenceTest(self._converged)
        # the step's own tests end it (_outcome): SNES's counts must not come first
        snes.setTolerances(max_it=2**30)
        snes.setMaxFunctionEvaluations(2**30)
        defaults = {}
        kind = PETSc.Options().getString("rod_snes_type", DEFAULT_SNES)
        if kind == PETSc.SNES.Type.NRICHARDSON:
            # nrichardson's default line search (secant) is not the plain iteration
            defaults["rod_snes_linesearch_type"] = "basic"
        if kind == PETSc.SNES.Type.ANDERSON:
            here = ranks_on_this_machine(self.mesh.comm)
            defaults["rod_snes_anderson_m"] = str(int(self.mesh.global_min(
                anderson_depth(self.mesh.n_local_elements, here))))
        set_from_options_with_defaults(snes, defaults)

    def _set_prescribed(self):
        """The end states' frame rows as the prescribed values of the three problems."""
        for i, problem in enumerate(self.problems):
            problem.set_prescribed(boundary.director_prescribed(
                i, self.start_state, self.end_state, self.mesh.n_elements))

    def _destroy_problems(self):
        for problem in self.problems:
            problem.destroy()

    def raise_penalty(self):
        """R <- min(ADAPT_FACTOR R, scale), the matrices assembled and factored anew.

        A penalty far below the problem's scale (default_penalty) makes the multiplier
        creep towards the internal forces by at most 2R per iteration: the cantilever at
        R = 1e-3 K/L^2 ended 10 000 iterations with a constraint residual of 0.25
        (docs/stability.md, fix 10). tau and lambda are kept: the iteration goes on from
        where it is, with the new R.
        """
        self.penalty = min(ADAPT_FACTOR * self.penalty, self.scale)
        self._destroy_problems()
        self._build_problems()

    # --- state ---------------------------------------------------------------------
    @property
    def frame_fields(self):
        """The P2 fields of the global step in frame order: d1, d2, theta = r' = d3."""
        return self.d1, self.d2, self.theta

    def set_straight(self):
        """The straight reference state: r = S e_x, frame (e_y, e_z, e_x), lambda = 0."""
        self.set_from_curve(starts.straight)

    def set_from_curve(self, curve):
        """Start from a smooth curve S -> (r, frame, force) (starts.py): r and theta = d3
        at the vertices (theta's midpoints from the Hermite cubic they define), d1, d2 at
        the vertices and midpoints, tau = frame at the nodes, lambda3 = force there and
        lambda1 = lambda2 = 0."""
        mesh = self.mesh
        owned = np.arange(mesh.vertex_start, mesh.vertex_end)
        vertex_S = mesh.coordinates(owned)
        midpoint_S = (vertex_S + mesh.coordinates(owned + 1)) / 2    # slot 1: P2 midpoint
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
        self.remember_state()

    def roll_cross_sections(self, amplitude):
        """Roll the current cross-sections about their tangent by
        phi(S) = amplitude sin(pi S / 2L) rad (zero at S = 0).

        (d1, d2) -> (cos phi d1 + sin phi d2, -sin phi d1 + cos phi d2), and likewise for
        (tau1, tau2) and (lambda1, lambda2): a rotation about d1 x d2 = d3. It changes the
        start of the iteration, not the problem, so that a symmetric start (e.g. a planar
        one) can leave a symmetric equilibrium that is not a minimiser (docs/method.md §7).
        """
        if amplitude == 0.0:
            return
        mesh = self.mesh
        owned = np.arange(mesh.vertex_start, mesh.vertex_end)
        vertex_S = mesh.coordinates(owned)
        midpoint_S = (vertex_S + mesh.coordinates(owned + 1)) / 2    # slot 1: P2 midpoint
        vertex_angle = np.stack([vertex_S, midpoint_S], axis=1)
        vertex_angle = amplitude * np.sin(np.pi * vertex_angle / (2 * mesh.length))
        node_angle = amplitude * np.sin(np.pi * mesh.node_S() / (2 * mesh.length))
        d1, d2 = rolled(self.d1.owned(), self.d2.owned(), vertex_angle[..., None])
        self.d1.set_owned(d1)
        self.d2.set_owned(d2)
        for frames in (self.tau, self.lam):
            frames[:, 0], frames[:, 1] = rolled(frames[:, 0], frames[:, 1],
                                                node_angle[..., None])
        self.remember_state()

    def set_centreline(self, positions, slopes):
        """r and theta from Hermite vertex data (n_owned, 3) each, e.g. a restart: theta is
        the slope at the vertices and the cubic's derivative at the midpoints."""
        mesh = self.mesh
        self.r.set_owned(np.stack([positions, slopes], axis=1))
        ghosted, left = self.r.ghosted(), mesh.element_local
        theta = np.zeros((positions.shape[0], 2, 3))
        theta[:, 0] = slopes
        theta[:mesh.n_local_elements, 1] = midpoint_slopes(
            ghosted[left, 0], ghosted[left, 1], ghosted[left + 1, 0], ghosted[left + 1, 1],
            mesh.element_h)
        self.theta.set_owned(theta)

    def snapshot(self):
        """Copies of this rank's share of the state a warm start needs (docs/method.md §3: r,
        d, tau, lambda; theta = r' with r), so that a failed continuation step can be
        undone (``restore``). Owned arrays only: nothing is gathered or communicated."""
        state = {name: field.owned() for name, field in self._state_fields().items()}
        state.update(tau=self.tau.copy(), lam=self.lam.copy(),
                     multiplier=self._multiplier.copy())
        return state

    def restore(self, snapshot):
        """Put back a ``snapshot`` exactly (bit for bit), e.g. after a step that diverged
        and left NaN in the fields. The prescribed values and loads stay those of the
        last ``solve_step``; the next one sets its own."""
        for name, field in self._state_fields().items():
            field.set_owned(snapshot[name])
        self.tau[:] = snapshot["tau"]
        self.lam[:] = snapshot["lam"]
        self._multiplier = snapshot["multiplier"].copy()
        self.remember_state()

    def _state_fields(self):
        """The VectorFields of the state, by name (the centreline r holds (r, r') at the
        vertices; theta = r' the P2 slope the global step solves for)."""
        return {"r": self.r, "theta": self.theta, "d1": self.d1, "d2": self.d2}

    def remember_state(self):
        """Take the current fields as the reference of the next change test."""
        self._directors = self.node_directors()
        self._positions = self.node_positions()
        self._previous = self._stacked()

    def _stacked(self):
        """(r, d1, d2, r') at the owned nodes, (n_nodes, 4, 3)."""
        return np.concatenate([self._positions[:, None, :], self._directors], axis=1)

    def node_directors(self):
        """d1, d2 and theta = r' = d3 at the owned P2 nodes, rows, (n_nodes, 3, 3): the
        dofs of the fields themselves (the phantom slot of the last vertex left out)."""
        n = self.mesh.n_local_nodes
        return np.stack([np.stack([c.getArray(readonly=True)[:n] for c in f.components],
                                  axis=-1) for f in self.frame_fields], axis=1)

    def node_positions(self):
        """r at the owned P2 nodes, (n_nodes, 3): the vertex values, and at each midpoint
        r(S_e) + int theta over the element's first half, h (5 theta_0 + 8 theta_m -
        theta_1) / 24 (exact for the P2 slope)."""
        mesh = self.mesh
        theta = element_dofs(self.theta.ghosted(), mesh.element_local, P2)
        vertices = self.r.owned()[:, 0]
        r = np.empty((mesh.n_local_nodes, 3))
        r[0::2] = vertices
        r[1::2] = vertices[:mesh.n_local_elements] + np.einsum(
            "ek,ekc->ec", p2_integrals(np.array([0.5]), mesh.element_h)[:, 0], theta)
        return r

    # --- one continuation step ------------------------------------------------------
    def prepare_step(self, t):
        """Prescribed values and loads at load factor t (lifting computed once).

        The load of the theta problem is int F.g with F(S) = int_S^L f dS + offset
        (centreline.load_offset), exactly integrated between the load breaks.
        """
        scene = self.scene
        start, end = scene.start_state(t), scene.end_state(t)
        self.start_state, self.end_state = start, end
        self._set_prescribed()
        total = scene.load_beyond(0.0, t)
        self._load_offset = load_offset(start, end, total)
        self._anchor_work = anchor_work(start, end, total)
        self.load.add_ghosted(load_ghosted(
            self.mesh, lambda S: scene.load_beyond(S, t) + self._load_offset,
            scene.load_piece_ends))
        if self.riser is not None:
            self.riser.prepare_step(self, t)

    def solve_step(self, t, label="", observer=None):
        """The iteration at load factor t, driven by the SNES ``-rod_snes_*`` (anderson by
        default, nrichardson for the plain iteration; docs/method.md §6), until both
        stopping tests hold: change <= rtol and RMS constraint residual <= ctol; then,
        with check_stability, the state is tested (§10) and a saddle is left along its
        negative curvature, up to MAX_ESCAPES times (the report says stable, or the step
        ends not converged with STOP_SADDLE). A step whose change and residual are within STALL_FACTOR of their
        tolerances but, at their rate, would not meet them within max_it stops early as
        stalled (stalled_projection). A penalty far below the problem's scale whose
        residual hardly falls is raised on the way (penalty_too_low, raise_penalty; the
        SNES starts again from the current state, and the report lists the raises).

        ``observer(iteration, change, residual)``, if given, is called (collectively)
        after each iteration's norms, e.g. to record the state at looser tolerances on
        the way (scripts/error_vs_time.py); if it returns True the step stops there,
        reported as not converged.
        """
        self.prepare_step(t)
        step = self._step = StepProgress(label, observer)
        try:
            self._iterate(step)
            while step.outcome == CONVERGED and self.settings.check_stability:
                step.stable, direction = self.check_stability()
                if step.stable is not False:
                    break
                if step.escapes == MAX_ESCAPES:
                    step.outcome = (False, STOP_SADDLE)
                    break
                # a saddle: turn the frames along the negative curvature, and go on
                angle = ESCAPE_ANGLE * ESCAPE_GROWTH**step.escapes * (-1) ** step.escapes
                self.turn_frames(angle * direction / self.mesh.global_max(
                    float(np.linalg.norm(direction, axis=1).max(initial=0.0))))
                step.escapes += 1
                step.outcome = step.stable = None
                self._iterate(step)
        finally:
            self._step = None
        if step.error is not None:
            raise step.error
        converged, reason = step.outcome
        change, residual = step.history[-1][:2] if step.history else (np.inf, np.inf)
        return StepReport(converged, len(step.history), change, residual, step.history,
                          reason, step.raises, stable=step.stable, escapes=step.escapes)

    def _iterate(self, step):
        """Run the SNES from the current state until ``step`` has an outcome (a penalty
        raise starts it again from where it is)."""
        while True:
            self._pack(self._x)
            self.snes.solve(None, self._x)
            if step.outcome != RAISE_PENALTY:
                break
            self.raise_penalty()
            step.raises.append((len(step.history), self.penalty))
            step.outcome = None
        if step.outcome is None and step.error is None:   # the SNES stopped on its own test
            reason = self.snes.getConvergedReason()
            step.outcome = (False, f"snes_{SNES_REASONS.get(reason, reason)}")

    def check_stability(self):
        """(stable, direction) of the current (converged) state (stability.py): True and
        None for a local minimiser; False and a rotation-vector field (n_nodes, 3) along
        which the energy decreases to second order for a saddle; None, None where the
        test cannot decide (a taut, straight rod)."""
        hessian = SecondVariation(self)
        try:
            if not hessian.decidable:
                return None, None
            direction = hessian.descent_direction()
            return direction is None, direction
        finally:
            hessian.destroy()

    def turn_frames(self, omega):
        """Turn tau and lambda at each node by the rotation exp([omega_n]x), (n_nodes, 3):
        rows t_i -> Q t_i. The next iteration starts from there."""
        turn = rotations(omega)
        self.tau[:] = np.einsum("nkl,nil->nik", turn, self.tau)
        self.lam[:] = np.einsum("nkl,nil->nik", turn, self.lam)

    def _fixed_point_residual(self, snes, x, f):
        """F(x) = x - G(x) for the SNES, G one iteration (iterate) of the state
        x = sqrt(w) (tau, lambda / R) at the nodes (sqrt(w): the Euclidean norm of x is
        the L2 norm of the fields). Records the iteration's norms and decides, for
        _converged, whether the step is over."""
        step = self._step
        if step.finished:
            f.set(0.0)
            return
        self._unpack(x)
        iteration = len(step.history) + 1
        try:
            self.iterate()
        except RodDivergedError as error:
            step.error = RodDivergedError(f"{step.label}iteration {iteration}: {error}",
                                          iteration)
            f.set(0.0)
            return
        change, residual = self.norms()
        step.history.append((change, residual, time.perf_counter() - step.clock))
        step.outcome = self._outcome(step, iteration, change, residual)
        if self.settings.monitor:
            PETSc.Sys.Print(f"  {step.label}it {iteration:5d}  change {change:.3e}  "
                            f"constraint {residual:.3e}", comm=self.mesh.comm)
        self._pack(f)
        f.aypx(-1.0, x)

    def _outcome(self, step, iteration, change, residual):
        """What the step does after an iteration: None (go on), RAISE_PENALTY, or
        (converged, reason); sets step.error when the iteration diverged."""
        settings = self.settings
        if not (np.isfinite(change) and np.isfinite(residual)) or residual > DIVERGED_RESIDUAL:
            step.error = RodDivergedError(
                f"{step.label}iteration {iteration}: the iteration diverged (change "
                f"{change:.3g}, constraint residual {residual:.3g}); try a larger "
                "-rod_al_penalty or more -rod_steps", iteration)
            return None
        if step.observer is not None and step.observer(iteration, change, residual):
            return (False, STOP_OBSERVER)
        if change <= settings.rtol and residual <= settings.ctol:
            return CONVERGED
        if iteration >= settings.max_it:
            return (False, STOP_MAX_IT)
        if (settings.adapt_penalty and iteration % ADAPT_WINDOW == 0
                and penalty_too_low(step.history, self.penalty, self.scale)):
            return RAISE_PENALTY
        if iteration % STALL_CHECK_EVERY == 0 and stalled(
                step.history, settings.rtol, settings.ctol, settings.max_it - iteration):
            return (False, STOP_STALLED)
        return None

    def _converged(self, snes, its, norms):
        """The SNES convergence test: the decision _fixed_point_residual took."""
        if self._step.finished:
            return PETSc.SNES.ConvergedReason.CONVERGED_ITS
        return PETSc.SNES.ConvergedReason.ITERATING

    def _pack(self, x):
        """x = sqrt(w) (tau, lambda / R), (n_nodes, 2, 3, 3) in the SNES vector."""
        values = x.getArray().reshape(-1, 2, 3, 3)
        values[:, 0] = self._root_weights * self.tau
        values[:, 1] = self._root_weights * self.lam / self.penalty

    def _unpack(self, x):
        values = x.getArray(readonly=True).reshape(-1, 2, 3, 3)
        self.tau[:] = values[:, 0] / self._root_weights
        self.lam[:] = values[:, 1] * (self.penalty / self._root_weights)

    def iterate(self):
        """One iteration n: global step, local step, multiplier update (docs/method.md §3),
        all three at the owned P2 nodes."""
        R = self.penalty
        n = self.mesh.n_local_nodes
        EVENTS["rhs"].begin()
        # field i (d1, d2, theta): sum_n w_n (R tau_i - lambda_i) g_n, plus the load for theta
        target = self.node_weights[:, None, None] * (R * self.tau - self.lam)
        for i, rhs in enumerate(self.rhs):
            for c, vec in enumerate(rhs.components):
                values = vec.getArray()
                values[:n] = target[:, i, c]
                values[n:] = 0.0
        for vec, load in zip(self.rhs[2].components, self.load.components):
            vec.axpy(1.0, load)
        if self.riser is not None:
            self.riser.add_loads(self)
        if self._lagged is not None:
            self._add_lagged_part()
        EVENTS["rhs"].end()
        EVENTS["solve"].begin()
        for problem, rhs, director in zip(self.d_problems, self.rhs[:2], (self.d1, self.d2)):
            problem.solve(rhs, director)
        self.solve_centreline()
        EVENTS["solve"].end()
        EVENTS["projection"].begin()
        self._directors = directors = self.node_directors()
        nearest_rotation(R * directors + self.lam, out=self.tau)
        EVENTS["projection"].end()
        EVENTS["multiplier"].begin()
        update_multipliers(self.lam, directors, self.tau, R)
        EVENTS["multiplier"].end()

    def _add_lagged_part(self):
        """2 (c_i - a_i) K tau_i on each field's right-hand side, where the matrix uses c_i
        instead of a_i: at a fixed point (d = tau) the equations are those of a_i."""
        n = self.mesh.n_local_nodes
        work, product = self._lagged_work
        for i, rhs in enumerate(self.rhs):
            factor = 2 * (self.matrix_split[i] - self.split[i])
            if factor == 0:
                continue
            for c, vec in enumerate(rhs.components):
                values = work.getArray()
                values[:n] = self.tau[:, i, c]
                values[n:] = 0.0
                self._lagged.mult(work, product)
                vec.axpy(factor, product)

    def solve_centreline(self):
        """theta from its right-hand side ``rhs[2]``, bordered by r(L) - r(0) = int theta
        when both ends are held (mu kept for end_reaction), then r at the vertices."""
        if self.bordered:
            chord = self.end_state.position - self.start_state.position
            self._multiplier = self.r_problem.solve_constrained(self.rhs[2], self.theta, chord)
        else:
            self.r_problem.solve(self.rhs[2], self.theta)
        if self.riser is not None:
            self.riser.solve_vertical(self)
        theta = element_dofs(self.theta.ghosted(), self.mesh.element_local, P2)
        positions = vertex_positions(self.mesh, theta, self.start_state, self.end_state)
        self.r.set_owned(np.stack([positions, self.theta.owned()[:, 0]], axis=1))

    def point_values(self):
        """r, directors and their derivatives at the Gauss points of the owned elements."""
        return self.evaluate(self.mesh.element_local, self.p2, self.p2_integrals)

    def evaluate(self, element_local, p2, integrals):
        """Fields at points of the given elements (ghosted local indices, (ne,)).

        p2 = (phi, dphi) and integrals (fe.p2_integrals) tabulated at the points,
        (ne, nq, 3). Returns r (ne, nq, 3), directors and derivatives (ne, nq, 3, 3), rows
        d1, d2, r' = theta and d1', d2', r'' = theta'; r = r(S_e) + int_{S_e}^S theta.
        """
        dofs = [element_dofs(f.ghosted(), element_local, P2) for f in self.frame_fields]
        left = self.r.ghosted()[element_local, 0]
        directors = np.stack([at_points(p2[0], d) for d in dofs], axis=2)
        derivatives = np.stack([at_points(p2[1], d) for d in dofs], axis=2)
        return {"r": positions_at_points(left, dofs[2], integrals), "directors": directors,
                "derivatives": derivatives}

    def norms(self):
        """Relative change of (r, r', d1, d2) and RMS constraint residual
        sqrt(sum_n w_n |d_n - tau_n|^2 / L) at the nodes (docs/method.md §6)."""
        EVENTS["norms"].begin()
        self._positions = self.node_positions()
        current = self._stacked()
        w = self.node_weights
        gap = w @ np.sum((self._directors - self.tau) ** 2, axis=(1, 2))
        size = w @ np.sum(current**2, axis=(1, 2))
        step = w @ np.sum((current - self._previous) ** 2, axis=(1, 2))
        gap, size, step = self.mesh.global_sum(np.array([gap, size, step]))
        self._previous = current
        EVENTS["norms"].end()
        change = np.sqrt(step / size) if size > 0 else np.inf
        return change, np.sqrt(gap / self.mesh.length)

    # --- outputs --------------------------------------------------------------------
    def energy(self):
        """W = int w dS - int f.r dS - end forces . r (§6), with u from the FE fields.

        The work is r(a).(applied forces) + int F.theta dS (centreline.anchor_work).
        """
        p = self.point_values()
        u = strains(p["directors"], p["derivatives"])
        stored = 0.5 * np.sum(self.weights[:, :, None] * self.scene.stiffness * u**2)
        work = self._anchor_work + sum(load.dot(theta) for load, theta
                                       in zip(self.load.components, self.theta.components))
        riser = self.riser.energy() if self.riser is not None else 0.0
        return self.mesh.global_sum(stored) - work + riser

    def link(self):
        """Twist and writhe of the current state, (Tw, Wr) in turns, Lk = Tw + Wr
        (link.py); None when the scene has no common end axis or a tangent comes within
        FULLER_MARGIN of pointing back along it."""
        axis = self.scene.link_axis
        if axis is None:
            return None
        p = self.point_values()
        twist, writhe, margin = link_integrands(p["directors"], p["derivatives"], axis)
        tw, wr, backward = self.mesh.global_sum(np.array([
            np.sum(self.weights * twist), np.sum(self.weights * writhe),
            np.sum(margin < FULLER_MARGIN)]))
        return None if backward else (float(tw), float(wr))

    def end_reaction(self):
        """External force N on the cable at S = L (N), n(S) = N + int_S^L f dS: F(L) - mu
        (centreline.py), i.e. the dead force at a free end; -(int_0^L f dS + P_0) at a held
        end when the start is free (force balance); and -mu, the multiplier of the last
        global step's constraint r(L) - r(0) = int theta, when both ends are held (the FE
        reaction, which contains lambda3)."""
        return self._load_offset - self._multiplier

    def destroy(self):
        self._destroy_problems()
        for obj in (self.snes, self._x, self._f):
            obj.destroy()
        if self._lagged is not None:
            for obj in (self._lagged, *self._lagged_work):
                obj.destroy()
        for obj in [*self.frame_fields, self.r, self.load, *self.rhs]:
            obj.destroy()
        if self.riser is not None:
            self.riser.destroy()


def rolled(first, second, angle):
    """(cos a first + sin a second, -sin a first + cos a second), broadcasting ``angle``."""
    c, s = np.cos(angle), np.sin(angle)
    return c * first + s * second, -s * first + c * second
