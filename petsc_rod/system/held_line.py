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
start's height z_a (a node's height is z_a plus the integral of the slope). With
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
SecondVariation.position_shift), with Y_C = A^-1 C^T, Y_P = A^-1 P, S = C Y_C (3, 3):

    dmu = -S^-1 (dc + C Y_P dz_a),   dy = -Y_P dz_a - Y_C dmu,
    dF_b = dmu,   dF_a = dPsi_0 - (P.dy + sum_n k w_n dz_a) e_z - dmu,

Psi_0 the resultant at S = 0 of a load that follows the line (the drag: a row of the
Jacobian's unknowns, so dPsi_0 a row of dy), sum_n over the nodes in contact. One
factorisation of A (the stability test's LDL^T of H unshifted, or J's LU; by
substructuring on several ranks) and four solves: no finite differences. Without a
current K = -Hess Phi: symmetric, and negative semi-definite for a stable line (moving
an end outward pulls it back: the restoring stiffness of a point is -K); without a
seabed K_aa = K_bb = -K_ab = -S^-1 (a translation of the whole line changes nothing).
In a uniform current K is not symmetric: the drag has no potential, and its resultant
turns with the line (K[:, :3] = -K[:, 3:] still holds without a seabed). The seabed's
contact is semi-smooth: an anchor exactly on the seabed has a one-sided vertical
stiffness of its own (its node enters the contact when pressed in), and K gives the
lifting side (its node counts as in contact only below the seabed).

A clamped end holds the frame the model gives it: its moment is end_moments(), but a
turn of the clamp's frame is no input yet (no rotational stiffness). On an extensible line the clamp's own node's stretch is held in
H, as the Newton steps hold it (docs/method.md §12: it comes from the force balance),
so there K misses that node's share: 7e-5 of the largest entry on a 40-element line,
against 3e-9 inextensible.

What it refuses (RodInputError, one line): a stiffness where it would not be exact: the
seabed's friction (it dissipates), a sloping or profiled seabed (its contact lagged), a
sheared current (the depth derivative of its drag is not in J), and any load outside
the Newton system (the sea surface's wet and dry parts, attachments that reach it).

Every call is collective on the line's communicator, never COMM_WORLD: a system puts
each line on its own sub-communicator.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.jacobian import NewtonJacobian
from petsc_rod.cli.line_run import BuiltLine, plan_line, values_of
from petsc_rod.compile import compile_scene
from petsc_rod.errors import NoCatenaryStart, RodError, RodInputError
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.iteration import events
from petsc_rod.iteration.continuation import PathSettings, continuation
from petsc_rod.iteration.newton import NewtonSolver
from petsc_rod.model.end import End
from petsc_rod.model.model import Model, Span
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.model.system_check import connection_position
from petsc_rod.quantities.riser_numbers import (_extreme, effective_tension,
                                             points_on_held_ends, top_end, touchdown)
from petsc_rod.scenes import starts
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

    def __getattr__(self, name):
        if name in ("scene", "moves"):
            raise AttributeError(name)
        return getattr(self.scene, name)

    def move(self, start, end):
        """Walk from the ends at the path's end (s = 1) to ``start``, ``end`` (3,), m,
        in the scene's frame."""
        self.moves = (self.start_state(1.0).position, np.asarray(start, dtype=float),
                      self.end_state(1.0).position, np.asarray(end, dtype=float))

    def hold(self, start, end):
        """The ends held at ``start``, ``end`` (3,) all along the path (after a walk
        that failed: back where they were)."""
        self.moves = (np.asarray(start, dtype=float),) * 2 + (np.asarray(end, dtype=float),) * 2

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
        return EndState(state.kind, (1.0 - s) * old + s * new, state.frame, state.force)


class _CurvatureRecorder:
    """What a term's add_hessian gives the positions (Term.add_hessian): the seabed's
    k w_n at the nodes in contact, recorded instead of assembled."""

    def __init__(self, problem):
        self.problem = problem
        self.heights = None

    def add_height_curvature(self, curvature):
        self.heights = np.asarray(curvature, dtype=float)

    def add_position_curvature(self, values, components):
        raise RodInputError("a line whose energy reads its horizontal positions (the "
                            "seabed's friction) has no exact stiffness here")


def _at_vertex(mesh, values, index):
    """values[index] of the owned vertex ``index`` (global), on every rank. Collective."""
    local = np.zeros(np.shape(values)[1:])
    if mesh.vertex_start <= index < mesh.vertex_end:
        local = np.asarray(values[index - mesh.vertex_start], dtype=float)
    return mesh.global_sum(local)


def _point(name, value):
    point = np.asarray(value, dtype=float)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise RodInputError(f"HeldLine.solve: {name} {value!r}: three finite numbers (m)")
    return point


class HeldLine:
    """A line of the typed model held at its two ends, on the ranks of ``comm`` (a
    PETSc communicator: the line's own; collective on it alone).

    ``span``: a model.model.Span (or a model.Model, whose one span is taken) with both
    ends held (pin or clamp; a clamp's frame is held as given); ``environment``: the
    sea (model.sea.Environment; a Model's own by default); ``options``: -rod_* options
    without ``rod_`` that tune the solver ({'al_rtol': 1e-10}).

    solve(start_position, end_position) -> bool; end_forces() -> (2, 3);
    end_moments() -> (2, 3); stiffness() -> (6, 6); stable() -> bool or None;
    positions() -> (2, 3); summary() -> dict; centreline() -> (n + 1, 3) or None;
    destroy(). ``iterations``: those of the last solve."""

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
        self.iterations = 0
        self.converged = False

    @classmethod
    def of_system_line(cls, line, start, end, comm, environment, options=None):
        """The HeldLine of a model.system.SystemLine ``line`` whose ends are first at
        ``start`` and ``end`` ((3,), m, absolute: where the system's points and bodies
        put its connections): a 'pin' connection a pinned End, 'flex' a pinned End with
        the connection's rotational stiffness (its axis the line's start direction),
        'clamp' a clamped End in the reference frame (the body's frame is not passed
        yet)."""
        def end_of(connection, position):
            kind = "clamp" if connection.kind == "clamp" else "pin"
            stiffness = connection.stiffness if connection.kind == "flex" else None
            return End(kind=kind, position=tuple(float(v) for v in position),
                       stiffness=stiffness)

        span = Span(line.line, end_of(line.start, start), end_of(line.end, end),
                    tuple(line.attachments))
        return cls(span, comm, environment, options)

    # --- building ----------------------------------------------------------------------
    def _model(self, start, end):
        """The line's Model with its ends at ``start``, ``end`` (absolute, m)."""
        import dataclasses
        span = self.span
        return Model(span.line, dataclasses.replace(span.start, position=start),
                     dataclasses.replace(span.end, position=end), self.environment,
                     tuple(span.attachments))

    def _build(self, start, end):
        """The line's run built on the one path of a line (cli/line_run.py: plan_line,
        BuiltLine: its mesh, problem and solver made and destroyed together) with the
        ends at ``start``, ``end``, its problem walking HeldEnds: its frame's origin is
        ``start`` for the line's life. Collective."""
        plan = plan_line(self.comm, self._model(start, end), self.values, self.given,
                         FIELD_NAMES)
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
        self.newton = self.built.own(NewtonSolver(self.problem))

    def _release(self):
        if self.built is not None:          # its own objects and those it was given
            self.built.destroy()
        self.jacobian = None
        self.built = self.mesh = self.problem = self.solver = self.newton = self.path = None

    # --- solving -----------------------------------------------------------------------
    def solve(self, start_position, end_position):
        """The line's equilibrium with its start held at ``start_position`` and its end
        at ``end_position`` ((3,) each, m, absolute): the first time (and after a first
        solve that failed) from the catenary start in one step, as the command line
        starts; later walked in one step (halved where it fails, up to 4 times) from
        the last converged equilibrium, the ends moved in straight lines. Returns
        whether it converged; a failed walk leaves the last equilibrium as it was.
        Collective."""
        a, b = _point("start_position", start_position), _point("end_position", end_position)
        if self.problem is None or not self.converged:
            self._release()
            self._build(a, b)
            return self._first()
        return self._walk(a - self.origin, b - self.origin)

    def _first(self):
        problem = self.problem
        try:
            curve = starts.catenary_start(self.path, 1.0)
        except NoCatenaryStart:
            problem.state.set_straight()
        else:
            problem.state.set_from_curve(curve)
        self.converged = self._run(PathSettings(steps=1, track_link=False))
        return self.converged

    def _walk(self, a, b):
        state = self.problem.state
        saved = state.snapshot()
        old = (self.path.start_state(1.0).position, self.path.end_state(1.0).position)
        self.path.move(a, b)
        if self._run(PathSettings(steps=1, track_link=False)):
            self.path.hold(a, b)
            return True
        state.restore(saved)
        self.path.hold(*old)
        self.problem.prepare(1.0)
        return False

    def _run(self, path):
        """The continuation on ``path``: whether it converged (a divergence, a PETSc
        error of its solves, is a failure). Collective."""
        self.iterations = 0
        try:
            for event in continuation(self.solver, path):
                if isinstance(event, events.RunFinished):
                    self.iterations = event.iterations
                    return bool(event.converged)
                if isinstance(event, events.RunDiverged):
                    return False
        except (RodError, PETSc.Error, FloatingPointError):
            return False
        return False

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
        this once at its own equilibrium. Collective."""
        self._check_solved()
        if not self.problem.conservative:
            return None
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
        return np.array([_at_vertex(mesh, m, 0), -_at_vertex(mesh, m, mesh.n_elements)])

    def stiffness(self):
        """d(end_forces)/d(start position, end position), (6, 6), N/m: K[i, j] the
        derivative of force component i (0-2 on the start, 3-5 on the end) in position
        component j (0-2 of the start, 3-5 of the end), at the last equilibrium, from
        the line's factored second variation, or in a uniform current its Newton
        Jacobian (module docstring). Symmetric and negative semi-definite for a stable
        line without a current. Collective."""
        self._check_solved()
        problem = self.problem
        self._check_exact()
        state = problem.state
        saved = state.snapshot()
        frames = state.tau.copy()
        held = ~problem.free_nodes
        frames[held] = state.node_directors()[held]
        vecs = []
        try:
            self.newton.lagrangian_gradient(frames, state.chord_multiplier.copy())
            hessian = problem.second_variation()
            recorder = _CurvatureRecorder(problem)
            for term in problem.terms:
                if term.position_components:
                    term.add_hessian(recorder)
            columns = hessian.chord_forms(frames[:, 2])
            vecs.extend(columns)
            shift = None
            if recorder.heights is not None:
                shift = hessian.position_shift(recorder.heights, 2)
                vecs.append(shift)
            if hessian.resultants:
                if self.jacobian is None:
                    self.jacobian = self.built.own(NewtonJacobian(hessian))
                self.jacobian.assemble()
                solver = self.jacobian
            else:
                hessian.factorise(0.0)
                solver = hessian
            solved = solver.solve_many(columns + ([] if shift is None else [shift]))
            vecs.extend(solved)
            response = self._response(hessian, columns, shift, solved,
                                      recorder.heights)
        finally:
            for vec in vecs:
                vec.destroy()
            state.restore(saved)
        chain = np.zeros((4, 6))                            # (z_a, c) of (x_a, x_b)
        chain[0, 2] = 1.0
        chain[1:, :3] = -np.eye(3)
        chain[1:, 3:] = np.eye(3)
        return response @ chain

    def _response(self, hessian, columns, shift, solved, heights):
        """d(F_a, F_b)/d(z_a, c), (6, 4), from the solves Y = A^-1 [C^T, P] (A: H, or
        J in a current): dmu = -S^-1 (dc + C Y_P dz), dy = -Y_P dz - Y_C dmu, F_b = mu,
        F_a = W + Psi_0 + R_s e_z - mu with Psi_0 the load's resultant at S = 0 that
        follows the shape (the drag's, a row of dy) and R_s the seabed's whole reaction,
        dR_s = -(P.dy + sum k w_n dz). Collective."""
        mesh = self.mesh
        Y_C, Y_P = solved[:3], solved[3:]
        schur = np.array([[c.dot(y) for y in Y_C] for c in columns])
        if not np.all(np.isfinite(schur)):
            raise np.linalg.LinAlgError("the line's second variation could not be "
                                        "factored at its equilibrium")
        inverse = np.linalg.inv(schur)
        along = np.array([c.dot(Y_P[0]) for c in columns]) if Y_P else np.zeros(3)
        dmu = np.zeros((3, 4))                              # d mu / d(z_a, c)
        dmu[:, 0] = -inverse @ along
        dmu[:, 1:] = -inverse

        def of_dy(values_C, value_P):
            """A linear functional of dy (values on Y_C (.., 3) and on Y_P (..,))
            as a function of (z_a, c)."""
            return -np.multiply.outer(value_P, [1.0, 0.0, 0.0, 0.0]) - values_C @ dmu

        start = -dmu.copy()
        if hessian.resultants:
            slot = hessian.resultant_slot
            first = [y.getArray(readonly=True).reshape(-1, hessian.block)[0, slot:slot + 3]
                     if mesh.on_lower_boundary else np.zeros(3) for y in solved]
            first = mesh.global_sum(np.array(first))        # (3 or 4, 3): Psi_0 of each Y
            start += of_dy(first[:3].T, first[3] if Y_P else np.zeros(3))
        if shift is not None:
            moved = of_dy(np.array([shift.dot(y) for y in Y_C]), shift.dot(Y_P[0]))
            moved[0] += mesh.global_sum(float(heights.sum()))
            start[2] -= moved                               # P.dy + sum k w_n dz
        return np.vstack([start, dmu])

    def _check_solved(self):
        if self.problem is None or not self.converged:
            raise RodInputError("HeldLine: no converged equilibrium yet (solve first, and "
                                "check what it returns)")

    def _check_exact(self):
        """Refuse a stiffness where it would not be exact (module docstring)."""
        scene = self.scene
        current = scene.current
        if current is not None and np.ptp(current.velocities, axis=0).max() > 0:
            raise RodInputError("HeldLine.stiffness: a current profile's depth derivative "
                                "is not in the Newton Jacobian: no exact stiffness in a "
                                "sheared current (a uniform one has one)")
        if scene.seabed is not None and scene.seabed.friction is not None:
            raise RodInputError("HeldLine.stiffness: the seabed's friction dissipates: no "
                                "exact stiffness of a line with friction")
        if scene.seabed is not None and not scene.seabed.flat:
            raise RodInputError("HeldLine.stiffness: exact on a flat seabed only (a "
                                "sloping or profiled one's contact is lagged)")
        loose = [term for term in self.problem.terms if not term.in_newton
                 or not (term.conservative or term.follower)]
        if loose:
            loads = "; ".join(dict.fromkeys(term.newton_gap or type(term).__name__
                                            for term in loose))
            raise RodInputError(f"HeldLine.stiffness: loads outside the Newton system "
                                f"({loads}): no exact stiffness")

    def destroy(self):
        """Free the line's PETSc objects (its BuiltLine's, its Newton solver's). Collective."""
        self._release()


def held_lines(system, options=None):
    """The SystemSolver's ``make_line(system_line, comm)`` of ``system`` (a
    model.system.System): each line a HeldLine in the system's environment with its
    ends first where the system's points and bodies put them
    (model.system_check.connection_position);
    ``options`` as HeldLine's."""
    def make_line(line, comm):
        start, end = (connection_position(system.node(c.to), c)
                      for c in (line.start, line.end))
        return HeldLine.of_system_line(line, start, end, comm, system.environment, options)
    return make_line
