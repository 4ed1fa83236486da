"""The coupled static equilibrium of a System (model/system.py): lines, free points and
rigid bodies in equilibrium together (docs/systems.md, "The coupled equilibrium").

Unknowns: each free point's position (3) and each body's free degrees of freedom of
(dX, dtheta) (6; the rotation an increment on the left, R <- exp([dtheta]x) R,
system/bodies.py). Residual, a force (N) per point and a force and moment (N, N m, about
the body's reference point X) per body, global axes:

    point:  sum_lines f_end + (rho_w V - m) g e_z + F_point + drag in a current
    body:   sum_lines (f, (x_f - X) x f), x_f = X + R p  + weight at the cog + buoyancy
            at the cob - K_h (q - q0) + load

with f the force a line exerts on its end (line.end_forces()); the continuation moves
the external loads (F_point, load) and the held points' positions from those of the
last equilibrium (the first time: no loads) to the system's by a load factor.

Jacobian: each line's exact 6 x 6 stiffness K = d f / d(x_start, x_end)
(line.stiffness()) mapped through each end's dx_f = T dq, T = I on a free point and
T = [I, -[R p]x] (3 x 6) on a body, giving T_i^T K_ij T_j; plus, per body end, the
geometric term of the moment's lever arm turning with the body,

    d((R p) x f) = (dtheta x R p) x f + (R p) x df,   (dtheta x a) x f = [f]x [a]x dtheta,

(bodies.lever_stiffness) which is not symmetric: by Jacobi's identity
[f]x[a]x - [a]x[f]x = [f x a]x, so its antisymmetric part is -[a x f]x / 2, half the
skew matrix of the force's moment about X. Turning the body turns the arm, and so
changes the moment even with the force held; this is where the rotational block's
asymmetry comes from, and it vanishes only where the moments of the forces at arms
vanish (BodyStiffness: the mooring stiffness's K - K^T is exactly [M_lines]x). Plus
the hydrostatics and the weight's and buoyancy's own lever terms (bodies.Bodies).

Newton with a backtracking line search on the scaled residual's norm, inside a
continuation of the load factor from 0 to 1 (the step halved when an attempt fails: a
line that does not converge, a singular or non-finite Jacobian, a line search that finds
no decrease). The lines are solved where system/placement.py puts them; every rank
holds every line's end forces and stiffness (small arrays) and solves the same small
Newton system, so every rank has the same numbers on any number of ranks.

A line is made by ``make_line(system_line, comm)`` (comm: its group's PETSc.Comm,
collective on it) and has ``solve(start (3,), end (3,)) -> bool``, ``end_forces() ->
(2, 3)`` (N, on its start and end points), ``stiffness() -> (6, 6)`` (d end_forces.ravel()
/ d(start, end)) and ``destroy()``; a line with a clamped or flex end at a body also
``solve(start, end, start_frame, end_frame)`` (the clamp's frame, or the frame a flex
joint's axis turns with, turns with the body),
``end_moments() -> (2, 3)`` (N m, added to the body's moment) and ``end_stiffness() ->
(12, 12)`` (forces and moments against positions and rotations of both ends), mapped
through [T; 0 I] (Linearised, lines_part).
"""

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from petsc_rod.errors import (RodDivergedError, RodError, RodInputError, RodInterrupted,
                              on_every_rank)
from petsc_rod.frames import REFERENCE_FRAME
from petsc_rod.system.bodies import DOF_NAMES, Bodies, lever_map, skew
from petsc_rod.system.placement import Placement, line_elements
from petsc_rod.system.predictor import predict
from petsc_rod.system.verdict import system_verdict


class HeldLine(Protocol):
    """What the solver asks of a line (a held line, system/held_line.py, or a test's
    mock): made by ``make_line(system_line, comm)``, collective on ``comm``."""

    def solve(self, start, end):
        """Its equilibrium with its ends held at ``start`` and ``end`` (3,), m, from
        its last state; True when it converged. Collective on its comm."""

    def end_forces(self):
        """(2, 3), N, global axes: the forces it exerts on its start and end points."""

    def stiffness(self):
        """(6, 6): d end_forces().ravel() / d(start, end), exact."""

    def destroy(self):
        """Free its PETSc objects."""


@dataclass(frozen=True)
class Settings:
    """``rtol``: the scaled residual's norm (forces / the force scale, moments / (the
    force scale x the length scale)) that ends Newton; ``floor``: a scaled residual
    below it that no step of the line search reduces is the lines' own accuracy (their
    end forces are converged to their tolerances, not to round-off) and is accepted
    (above it, before failing, Newton takes the lines to their stationary points and
    goes on: SystemSolver.newton);
    ``max_iterations`` per attempt, beyond which Newton goes on only below the floor
    while each step halves the residual (below the floor, two Newton steps in a row that
    do not halve the residual end it too: the same accuracy); ``load_steps``: the
    continuation's first step is 1 / load_steps; ``max_halvings`` of a failing step;
    ``line_search`` halvings of a
    Newton step; ``predictor``: a solver's first solve starts where the system's
    catenaries settle (system/predictor.py) when its lines allow it (``make_line``'s
    ``predictable``) and ``load_steps`` is 1; False: always the continuation from the
    unloaded system; ``prediction_budget``: the iterations each line's first solve at
    the prediction may take (one attempt, no halvings: HeldLine.budget), beyond which
    the prediction is given up (SystemSolver._first_solves)."""

    rtol: float = 1e-10
    floor: float = 1e-7
    max_iterations: int = 30
    load_steps: int = 1
    max_halvings: int = 12
    line_search: int = 10
    predictor: bool = True
    prediction_budget: int = 200


@dataclass
class State:
    """Free and held points' positions (n_points, 3) and the bodies' poses (Bodies)."""

    points: np.ndarray
    bodies: Bodies

    def moved(self, step, layout):
        """The state after the increment ``step`` (layout.size,) of every unknown."""
        points = self.points.copy()
        points[layout.point_index] += step[layout.point_dofs].reshape(-1, 3)
        return State(points, self.bodies.moved(step[layout.body_dofs]))


@dataclass(frozen=True)
class Loads:
    """What the continuation moves: the bodies' external loads (n_bodies, 6), the free
    points' forces (n_free, 3), the held points' positions (n_points, 3) (the free
    points' rows unused) and the bodies' reference points (n_bodies, 3) (their held
    components: a body held in x, y or z moved to an offset)."""

    bodies: np.ndarray
    forces: np.ndarray
    held: np.ndarray
    places: np.ndarray

    @classmethod
    def of(cls, system, layout):
        return cls(np.array([b.load for b in system.bodies], dtype=float).reshape(-1, 6),
                   np.array([system.points[i].force for i in layout.point_index],
                            dtype=float).reshape(-1, 3),
                   np.array([p.position for p in system.points], dtype=float).reshape(-1, 3),
                   np.array([b.position[:3] for b in system.bodies],
                            dtype=float).reshape(-1, 3))

    def _pairs(self, other):
        return ((self.bodies, other.bodies), (self.forces, other.forces),
                (self.held, other.held), (self.places, other.places))

    def towards(self, other, factor):
        """self + factor (other - self)."""
        return Loads(*(a + factor * (b - a) for a, b in self._pairs(other)))

    def unloaded(self):
        return Loads(0.0 * self.bodies, 0.0 * self.forces, self.held, self.places)

    def same(self, other):
        return all(np.array_equal(a, b) for a, b in self._pairs(other))


@dataclass(frozen=True)
class Linearised:
    """The lines' end moments and stiffnesses at one evaluation: ``matrix`` (n, 12, 12),
    d(F_a, F_b, M_a, M_b)/d(x_a, x_b, theta_a, theta_b) (HeldLine.end_stiffness; a
    line with no clamp at a body: its 6 x 6 in the first block, the rest 0), ``moments``
    (n, 2, 3), N m, each end's moment on its body (0 but at a clamp at a body)."""

    matrix: np.ndarray
    moments: np.ndarray


# (F_a, M_a, F_b, M_b) of end_stiffness's rows and columns (F_a, F_b, M_a, M_b)
BY_END = np.array([0, 1, 2, 6, 7, 8, 3, 4, 5, 9, 10, 11])


@dataclass(frozen=True)
class BodyStiffness:
    """The 6 x 6 mooring stiffness of a body, K = -d(F, M)/d(dX, dtheta) of the lines'
    loads about ``reference`` (the body's reference point, global axes; N/m, N, N m/rad),
    the free points condensed (they re-equilibrate) and the other bodies held;
    ``moment`` (3,), N m: the lines' moment about the reference point; ``asymmetry``:
    |K - K^T|_F / |K|_F (0 for a body no line holds). Its rotational block's
    antisymmetric part is exactly [moment]x / 2: turning the body turns the fairleads'
    arms, which changes the lines' moment by [f]x [a]x dtheta even with their forces
    held, a term symmetric only where the lines' moment vanishes (docs/systems.md)."""

    matrix: np.ndarray
    reference: np.ndarray
    moment: np.ndarray
    asymmetry: float


@dataclass(frozen=True)
class Equilibrium:
    """A converged system: ``points`` {name: position (3,)}, ``bodies`` {name:
    (x, y, z, roll, pitch, yaw) (6,)}, ``rotations`` {name: R (3, 3)}, ``end_forces``
    (n_lines, 2, 3), N, on each line's start and end, ``load_factor`` (1 when
    complete), ``iterations`` (Newton's, over the continuation), ``residual`` (the scaled
    norm), ``stable`` {line name: True a local minimiser of its energy, False a saddle,
    None undecided} (SystemSolver.line_verdicts: each line tested once, here), and
    ``unstable`` the names of the lines whose verdict is False, in the system's order;
    ``verdict`` the system's own stability in its free unknowns (system/verdict.py:
    SystemVerdict, stable True, False a saddle of the system, None not conservative)."""

    points: dict
    bodies: dict
    rotations: dict
    end_forces: np.ndarray
    load_factor: float
    iterations: int
    halvings: int
    residual: float
    unstable: tuple = ()
    stable: dict = None
    verdict: object = None


class Layout:
    """Where each node's unknowns are: 3 per free point, 6 per body (its held ones
    removed in the solve: ``free``); ``ends`` (n_lines, 2, 6) the unknowns each line
    end moves (``size`` marks none), ``body_end`` (n_lines, 2) the body of an end
    (-1: a point) and ``local`` (n_lines, 2, 3) its body point."""

    def __init__(self, system):
        names = [p.name for p in system.points] + [b.name for b in system.bodies]
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:
            raise RodInputError(f"System: two points or bodies are named {twice[0]!r}; "
                                "give each its own name")
        kinds = np.array([p.kind for p in system.points], dtype=object)
        self.point_index = np.flatnonzero(kinds == "free")
        self.held_points = np.flatnonzero(kinds != "free")
        n_free, n_bodies = self.point_index.size, len(system.bodies)
        self.size = 3 * n_free + 6 * n_bodies
        point_dof = np.full((len(system.points), 3), self.size)
        point_dof[self.point_index] = np.arange(3 * n_free).reshape(-1, 3)
        self.point_dofs = np.arange(3 * n_free)
        self.body_dofs = 3 * n_free + np.arange(6 * n_bodies).reshape(n_bodies, 6)
        held = np.array([b.held for b in system.bodies], dtype=bool).reshape(-1, 6)
        self.held_places = held[:, :3]
        self.free = np.concatenate([self.point_dofs, self.body_dofs[~held]])
        self.free.sort()
        self.names = ([(system.points[i].name, DOF_NAMES[k]) for i in self.point_index
                       for k in range(3)]
                      + [(b.name, DOF_NAMES[k]) for b in system.bodies for k in range(6)])
        self.is_moment = np.zeros(self.size, dtype=bool)
        self.is_moment[self.body_dofs[:, 3:].ravel()] = True
        where = {p.name: ("point", i) for i, p in enumerate(system.points)}
        where.update({b.name: ("body", i) for i, b in enumerate(system.bodies)})
        n = len(system.lines)
        self.ends = np.full((n, 2, 6), self.size)
        self.body_end = np.full((n, 2), -1)
        self.point_end = np.full((n, 2), -1)
        self.local = np.zeros((n, 2, 3))
        # a clamped or flex end at a body: its frame (a flex joint's axis) turns with the
        # body, its moment acts on it
        self.turned = np.zeros((n, 2), dtype=bool)
        # the line's end frame a clamp or flex joint holds, body axes (Connection.
        # line_frame); None: the reference frame at the body's start pose
        self.frames = [[None, None] for _ in range(n)]
        for k, line in enumerate(system.lines):
            for j, connection in enumerate((line.start, line.end)):
                if connection.to not in where:
                    system.node(connection.to)              # its one-line error
                kind, i = where[connection.to]
                self._check(line.name, ("start", "end")[j], connection, kind,
                            system.points[i].kind if kind == "point" else "body")
                if kind == "body":
                    self.turned[k, j] = connection.kind in ("clamp", "flex")
                    self.frames[k][j] = connection.line_frame(j == 1)
                    self.body_end[k, j] = i
                    self.ends[k, j] = self.body_dofs[i]
                    self.local[k, j] = connection.local
                else:
                    self.point_end[k, j] = i
                    self.ends[k, j, :3] = point_dof[i]
        reached = np.zeros(len(system.points), dtype=bool)
        reached[self.point_end[self.point_end >= 0]] = True
        lonely = [system.points[i].name for i in self.point_index if not reached[i]]
        if lonely:
            raise RodInputError(f"point {lonely[0]}: free, but no line ends at it, so "
                                "nothing holds it: connect a line or make it fixed")

    @staticmethod
    def _check(line, which, connection, kind, node_kind):
        if node_kind == "free" and connection.kind != "pin":
            raise RodInputError(
                f"line {line}: {which}: a {connection.kind} end at the free point "
                f"{connection.to}, which has no rotation to hold the end's frame: use kind "
                "'pin', or a body")
        if kind == "point" and np.any(np.asarray(connection.local, dtype=float) != 0):
            raise RodInputError(f"line {line}: {which}: local {connection.local!r} at the "
                                f"point {connection.to}, which has no axes: leave it zero")


def _moved_where_held(new, old):
    """Whether Body ``new`` is at ``old``'s position but in its held translations."""
    moved = np.asarray(new.position, dtype=float) != np.asarray(old.position, dtype=float)
    return not np.any(moved & ~np.concatenate([np.asarray(old.held[:3], dtype=bool),
                                                np.zeros(3, dtype=bool)]))


class SystemSolver:
    """The coupled equilibrium of ``system`` with lines made by ``make_line`` (module
    docstring) on the groups of ranks of ``comm`` (a PETSc.Comm; default COMM_WORLD)
    that system/placement.py lays out by ``sizes`` (elements per line; default the
    lines' element counts). Collective on ``comm``; ``destroy`` the lines after."""

    def __init__(self, system, make_line, comm=None, sizes=None, settings=Settings()):
        from petsc4py import PETSc
        self.system, self.settings = system, settings
        self.layout = Layout(system)
        environment = system.environment
        self.rho, self.g = environment.water_density, environment.gravity
        self.length = max([1.0] + [float(np.abs(np.asarray(v, float)).max()) for b in
                                   system.bodies for v in (b.cog, b.cob)]
                          + [float(np.abs(self.layout.local).max(initial=0.0))])
        sizes = [line_elements(line) for line in system.lines] if sizes is None else sizes
        self.comm = comm or PETSc.COMM_WORLD       # the catenary predictor's too
        self.placement = Placement.make(self.comm, sizes)
        self.make_line = make_line
        # the catenary predictor (_predicted): whether the first solve tries it, and
        # what it did in the last solve (None: not tried there; "used"; else why not,
        # or why it failed)
        # (not where a continuation in load steps is asked for: Settings.load_steps)
        self.predictable = (settings.predictor and settings.load_steps == 1
                            and getattr(make_line, "predictable", False))
        self.prediction = None
        # {line name: iterations} of the lines' first solves at the prediction (None:
        # none tried), on every rank
        self.predicted_iterations = None
        self.lines = {}
        # the run's stop signals (cli/signals.Interrupts: received() collective, name()),
        # asked before every Newton iteration and after a failed one, and handed to the
        # lines, which ask after every iteration of their walks; None: not asked
        self.interrupts = None
        self.first = system
        self._start(system)

    def _start(self, system):
        """The lines made (collective) and the solver at ``system``'s start, unloaded."""

        def make_mine():
            for k in self.placement.mine:
                self.lines[int(k)] = self.make_line(system.lines[k],
                                                    self.placement.line_comm)

        try:                                    # a line refused on one group, on all
            on_every_rank(self.placement.mpi, make_mine)
        except BaseException:
            self.destroy()
            raise
        self.state = State(np.array([p.position for p in system.points],
                                    dtype=float).reshape(-1, 3),
                           Bodies(system.bodies, self.rho, self.g))
        self.forces = self.stiffnesses = None
        self.failure, self.checked, self.last = "", False, None
        self.mine = {}                          # this rank's lines' last results
        self.factor = 0.0                       # the load factor the Newton works at
        self.loads = Loads.of(system, self.layout).unloaded()

    def destroy(self):
        self._drop_lines()
        self.placement.destroy()

    def _drop_lines(self):
        for line in self.lines.values():
            line.destroy()
        self.lines = {}

    # -- the lines --------------------------------------------------------------------

    def arms(self, state):
        """(n_lines, 2, 3): each body end's arm R p from its body's X (0 at a point)."""
        layout = self.layout
        arms = np.zeros(layout.local.shape)
        on_body = layout.body_end >= 0
        if np.any(on_body):
            arms[on_body] = np.einsum("nij,nj->ni", state.bodies.R[layout.body_end[on_body]],
                                      layout.local[on_body])
        return arms

    def end_positions(self, state):
        """(n_lines, 2, 3): each line end's position, a point's or X + R p."""
        layout = self.layout
        positions = self.arms(state)
        on_point, on_body = layout.point_end >= 0, layout.body_end >= 0
        positions[on_point] = state.points[layout.point_end[on_point]]
        if np.any(on_body):
            positions[on_body] += state.bodies.X[layout.body_end[on_body]]
        return positions

    def end_frames(self, state):
        """[(start frame, end frame)] per line: a clamp at a body's (3, 3), rows d1, d2,
        d3, turning with it, D = D_b R^T (each row d_i = R d_i,b), D_b the line's end
        frame in the body's axes (Connection.line_frame), or where the connection gives
        none the line's start frame (the reference, frames.REFERENCE_FRAME) at the
        body's start rotation R0, D_b = D_ref R0; None elsewhere. A flex joint's axis
        turns with the same D (held_line.HeldLine: a = D^T D_ref a_0)."""
        layout, bodies = self.layout, state.bodies
        out = []
        for k in range(len(self.system.lines)):
            ends = []
            for j in (0, 1):
                body = layout.body_end[k, j]
                if not layout.turned[k, j]:
                    ends.append(None)
                    continue
                frame = layout.frames[k][j]
                if frame is None:
                    frame = REFERENCE_FRAME @ bodies.R0[body]
                ends.append(frame @ bodies.R[body].T)
            out.append(tuple(ends))
        return out

    def evaluate(self, state, strict=False, settle=False, linearise=True):
        """Solve every line at ``state``'s end positions (and a clamp's frame at a body:
        end_frames) (this rank's lines in turn) and share the results: (converged, end
        forces (n, 2, 3), Linearised). A line with a clamp at a body is asked for
        solve(start, end, start_frame, end_frame), end_moments() and end_stiffness();
        the others keep the four-method protocol. A line that raises a solver's RodError
        has not converged; one that refuses its ends (RodInputError: a span it cannot
        reach) has not either, except when ``strict`` (the start, where the system itself
        is at fault): then its error is raised on every rank. The ends of the last
        successful evaluation are not solved again. ``settle``: each line that can
        (HeldLine.settle) first taken to its stationary point, for the stiffness a
        system reports (the iterations' Jacobian needs only the lines' tolerances).
        Without ``linearise`` the lines' stiffnesses are left out (Linearised.matrix
        None: a trial whose Jacobian no step may need); asked again at the same ends
        with it, they are added without solving the lines again. A line that stands
        there at its stationary point already (``settled``) keeps its last results
        (settling it changes nothing, nor its stiffness)."""
        layout = self.layout
        positions = self.end_positions(state)
        key = (positions, state.bodies.R)
        there = self.last is not None and all(np.array_equal(a, b)
                                              for a, b in zip(key, self.last[0]))
        if there and not settle and (self.last[1][2].matrix is not None or not linearise):
            return self.last[1]                 # the lines stand there already
        frames = self.end_frames(state)
        mine = {}
        linearised = there and self.last[1][2].matrix is not None
        for k, line in self.lines.items():
            turned = bool(layout.turned[k].any())
            if linearised and getattr(line, "settled", False) and self.mine[k][0]:
                mine[k] = self.mine[k]
                continue
            if hasattr(line, "interrupts"):
                line.interrupts = self.interrupts   # a walk stops at a stop signal
            try:
                ok = there or bool(line.solve(positions[k, 0], positions[k, 1], *frames[k])
                                   if turned else line.solve(positions[k, 0], positions[k, 1]))
                if ok and settle and hasattr(line, "settle"):
                    line.settle()
                if not ok:
                    mine[k] = (False,)
                elif turned:        # a refused end stiffness: below, on every rank
                    mine[k] = (True, line.end_forces(),
                               line.end_stiffness() if linearise else None,
                               line.end_moments())
                else:
                    mine[k] = (True, line.end_forces(),
                               line.stiffness() if linearise else None)
            except RodInputError as error:      # raised below on every rank
                mine[k] = (False, error)
            except (RodError, np.linalg.LinAlgError):
                mine[k] = (False,)
        self.last = None
        self.mine = mine
        shared = self.placement.share(mine)
        refused = [shared[k][1] for k in sorted(shared) if len(shared[k]) == 2]
        if refused and strict:
            raise refused[0]
        n = len(self.system.lines)
        failed = [k for k in range(n) if not shared[k][0]]
        if failed:
            name, entry = self.system.lines[failed[0]].name, shared[failed[0]]
            self.failure = (f"line {name} refused its ends ({entry[1]})" if len(entry) == 2
                            else f"line {name} did not converge")
            return False, None, None
        forces = np.array([shared[k][1] for k in range(n)]).reshape(-1, 2, 3)
        matrix, moments = np.zeros((n, 12, 12)), np.zeros((n, 2, 3))
        for k in range(n):
            if len(shared[k]) == 4:
                moments[k] = shared[k][3]
            if linearise and len(shared[k]) == 4:
                matrix[k] = shared[k][2]
            elif linearise:
                matrix[k, :6, :6] = shared[k][2]
        # a pinned end's moment (of the discretisation, not a reaction) is not applied
        off = ~layout.turned
        moments[off] = 0.0
        rows = np.zeros((n, 12), dtype=bool)
        rows[:, 6:9], rows[:, 9:] = off[:, :1], off[:, 1:]
        matrix[rows] = 0.0
        self.last = (key, (True, forces, Linearised(matrix if linearise else None, moments)))
        return self.last[1]

    # -- residual and Jacobian ---------------------------------------------------------

    def lines_part(self, state, forces, stiffness):
        """The lines' generalised forces r (size,) and their Jacobian J (size, size)
        (module docstring; the last row and column of the (size + 1)^2 work arrays
        collect the held ends), from their end ``forces`` (n, 2, 3) and ``stiffness``
        (Linearised): an end at a body moves by dx = T dq and a clamp there turns by
        dtheta, so each end's (f, M) acts through [T; 0 I] (6 x 6). J is None where the
        stiffnesses were left out (evaluate's ``linearise``)."""
        layout, n = self.layout, len(self.system.lines)
        arms = self.arms(state)
        T = lever_map(arms.reshape(-1, 3)).reshape(n, 2, 3, 6)
        on_point = layout.body_end < 0
        T[on_point, :, 3:] = 0.0                    # a point's end has no rotation
        maps = np.zeros((n, 2, 6, 6))
        maps[:, :, :3] = T
        maps[:, :, 3:, 3:] = layout.turned[:, :, None, None] * np.eye(3)
        loads = np.concatenate([forces, stiffness.moments], axis=2)      # (n, 2, 6)
        size = layout.size + 1
        r = np.zeros(size)
        np.add.at(r, layout.ends, np.einsum("njia,nji->nja", maps, loads))
        if stiffness.matrix is None:
            return r[:-1], None
        K = stiffness.matrix[:, BY_END][:, :, BY_END].reshape(n, 2, 6, 2, 6)
        blocks = np.einsum("niba,nibjc,njcd->nijad", maps, K, maps)     # (n, 2, 2, 6, 6)
        rows = np.broadcast_to(layout.ends[:, :, None, :, None], blocks.shape)
        cols = np.broadcast_to(layout.ends[:, None, :, None, :], blocks.shape)
        J = np.zeros((size, size))
        np.add.at(J, (rows, cols), blocks)
        geometric = np.einsum("njab,njbc->njac", skew(forces), skew(arms))
        spin = layout.ends[:, :, 3:]
        np.add.at(J, (np.broadcast_to(spin[..., :, None], geometric.shape),
                      np.broadcast_to(spin[..., None, :], geometric.shape)), geometric)
        return r[:-1], J[:-1, :-1]

    def own_part(self, state, loads):
        """The points' and bodies' own loads (size,) and their Jacobian, under the
        external ``loads`` (Loads)."""
        layout = self.layout
        r = np.zeros(layout.size)
        J = np.zeros((layout.size, layout.size))
        if layout.point_dofs.size:
            points = [self.system.points[i] for i in layout.point_index]
            mass, volume, cda = (np.array([getattr(p, name) for p in points])
                                 for name in ("mass", "volume", "cda"))
            dead = np.outer((self.rho * volume - mass) * self.g, (0.0, 0.0, 1.0))
            drag, d_drag = self._drag(state.points[layout.point_index], cda)
            r[layout.point_dofs] = (dead + loads.forces + drag).ravel()
            dofs = layout.point_dofs.reshape(-1, 3)
            J[dofs, dofs[:, 2:]] += d_drag          # the drag changes with the depth
        if layout.body_dofs.size:
            own, jacobian = state.bodies.own_loads(loads.bodies)
            dofs = layout.body_dofs
            r[dofs] += own
            J[dofs[:, :, None], dofs[:, None, :]] += jacobian
        return r, J

    def _drag(self, positions, cda):
        """The current's drag on free points, 0.5 rho C_d A |u| u (n, 3), N, and its
        derivative in the points' heights (n, 3): a uniform current (none), or a
        profile's velocity, linear between its rows, at each point's depth below the
        surface (the Environment's surface, 0 when none), so du/dz = -du/d depth and
        d(|u| u) = (|u| I + u u^T / |u|) du."""
        n = positions.shape[0]
        current = self.system.environment.current
        if current is None or not np.any(cda):
            return np.zeros((n, 3)), np.zeros((n, 3))
        current = np.asarray(current, dtype=float)
        if current.shape == (3,):
            u, du = np.broadcast_to(current, (n, 3)), np.zeros((n, 3))
        else:
            depth = (self.system.environment.surface or 0.0) - positions[:, 2]
            rows, values = current[:, 0], current[:, 1:]
            u = np.stack([np.interp(depth, rows, column) for column in values.T], axis=-1)
            k = np.clip(np.searchsorted(rows, depth), 1, max(len(rows) - 1, 1))
            inside = ((depth > rows[0]) & (depth < rows[-1]))[:, None]
            slope = ((values[k] - values[k - 1])
                     / np.maximum(rows[k] - rows[k - 1], np.finfo(float).tiny)[:, None]
                     if len(rows) > 1 else np.zeros((n, 3)))
            du = -np.where(inside, slope, 0.0)
        speed = np.linalg.norm(u, axis=1)[:, None]
        factor = 0.5 * self.rho * cda[:, None]
        along = np.einsum("ni,ni->n", u, du)[:, None] / np.maximum(speed, np.finfo(float).tiny)
        return factor * speed * u, factor * (speed * du + along * u)

    def scales(self):
        """The residual's scale per unknown: the force scale (the largest line end
        force, dead force or load, at least 1 N) on forces, times the length scale
        (the bodies' largest lever, at least 1 m) on moments."""
        force = max([1.0] + [float(np.abs(self.forces).max(initial=0.0))]
                    + [abs(p.mass - self.rho * p.volume) * self.g + np.abs(p.force).max()
                       for p in self.system.points]
                    + [max(b.mass, self.rho * b.volume) * self.g + np.abs(b.load).max()
                       for b in self.system.bodies])
        return np.where(self.layout.is_moment, force * self.length, force)

    def residual(self, state, loads, forces, stiffness):
        r_lines, J_lines = self.lines_part(state, forces, stiffness)
        r_own, J_own = self.own_part(state, loads)
        return r_lines + r_own, None if J_lines is None else J_lines + J_own

    # -- Newton, continuation ------------------------------------------------------------

    def singular_dof(self, J, scale):
        """The (node, dof) names of the unknown the scaled free Jacobian cannot move
        (its null vector's largest entry), None when it is regular."""
        free = self.layout.free
        if not free.size:
            return None
        column = np.where(self.layout.is_moment, 1.0, self.length)
        scaled = J[np.ix_(free, free)] * column[free] / scale[free][:, None]
        if not np.all(np.isfinite(scaled)):
            return ("the Jacobian", "not finite")
        u, s, vt = np.linalg.svd(scaled)
        if s[-1] > 1e-12 * s[0]:
            return None
        return self.layout.names[free[int(np.argmax(np.abs(vt[-1])))]]

    def newton(self, state, loads, scale):
        """(state, iterations) at equilibrium under ``loads`` (Loads; the held points
        put at its positions), or (None, its iterations) with self.failure saying why.
        self.forces/stiffnesses: the lines' at the returned state. A line search without
        decrease above Settings.floor first makes Newton precise: the lines settled
        (HeldLine.settle) at the state and at every later trial, the residual then
        free of their tolerances' error; a second one fails. ``max_iterations`` spent,
        it goes on below the floor while each step halves the residual, and ends at the
        lines' accuracy at the first that does not (docs/systems.md)."""
        settings, free, held = self.settings, self.layout.free, self.layout.held_points
        state = State(state.points.copy(),
                      state.bodies.placed(loads.places, self.layout.held_places))
        state.points[held] = loads.held[held]
        ok, forces, stiffness = self.evaluate(state, linearise=False)
        if not ok:
            return None, 0
        r, J = self.residual(state, loads, forces, stiffness)
        norm = np.linalg.norm(r[free] / scale[free])
        stalled, precise = 0, False
        iteration = 0
        while True:
            self.forces, self.stiffnesses = forces, stiffness
            self.check_interrupted(iteration)
            if norm <= settings.rtol:
                self.norm = norm
                return state, iteration
            if iteration >= settings.max_iterations and not (
                    norm <= settings.floor and iteration > 0 and stalled == 0):
                # spent; below the floor Newton goes on while each step halves the
                # residual (its quadratic tail after a long damped approach: each such
                # step takes the residual at least halfway to rtol, so few are taken)
                break
            if J is None:
                # the lines' stiffnesses, left out of the evaluation until a step needs
                # them (the last one's never is: solve's settled evaluation gives them)
                ok, forces, stiffness = self.evaluate(state)
                if not ok:
                    return None, iteration
                self.stiffnesses = stiffness
                r, J = self.residual(state, loads, forces, stiffness)
            step = np.zeros(self.layout.size)
            try:
                step[free] = -np.linalg.solve(J[np.ix_(free, free)], r[free])
            except np.linalg.LinAlgError:
                step[free] = np.nan
            if not np.all(np.isfinite(step)):
                where = self.singular_dof(J, scale)
                self.failure = (f"the Jacobian is singular in {where[0]} {where[1]}"
                                if where else "the Newton step is not finite")
                return None, iteration
            alpha, full = 1.0, ""
            for _ in range(settings.line_search + 1):
                trial = state.moved(alpha * step, self.layout)
                ok, t_forces, t_stiffness = self.evaluate(trial, settle=precise,
                                                          linearise=False)
                full = full or ("" if ok or alpha < 1.0 else f" ({self.failure} at the "
                                                             "full step)")
                if ok:
                    t_r, t_J = self.residual(trial, loads, t_forces, t_stiffness)
                    t_norm = np.linalg.norm(t_r[free] / scale[free])
                    if t_norm <= (1.0 - 1e-4 * alpha) * norm:
                        break
                alpha *= 0.5
            else:
                if norm <= settings.floor:
                    self.norm = norm
                    return state, iteration
                if not precise:
                    # Above the floor the residual may still be the lines' own error
                    # (their end forces converged to -rod_al_rtol/-rod_al_ctol: a stiff
                    # line's EA times its constraint residual): the lines taken to their
                    # stationary points (HeldLine.settle, Newton's steps), here and at
                    # every trial from now on, and Newton goes on with their exact forces.
                    precise, stalled = True, 0
                    ok, forces, stiffness = self.evaluate(state, settle=True)
                    if not ok:
                        return None, iteration
                    r, J = self.residual(state, loads, forces, stiffness)
                    norm = np.linalg.norm(r[free] / scale[free])
                    iteration += 1              # counted as a step
                    continue
                self.failure = (f"the line search found no decrease of the residual "
                                f"{norm:.3g}{full}")
                return None, iteration
            stalled = stalled + 1 if t_norm > 0.5 * norm else 0
            state, forces, stiffness, r, J, norm = (trial, t_forces, t_stiffness, t_r,
                                                    t_J, t_norm)
            iteration += 1
            if norm <= settings.floor and stalled >= 2:
                # An exact Jacobian's step at least halves a residual that is not the
                # lines' own error: two steps in a row that did not are at the lines'
                # accuracy (a line re-solved after a tiny move takes one step of its
                # own iteration, and its end forces creep).
                self.forces, self.stiffnesses, self.norm = forces, stiffness, norm
                return state, iteration
        if norm <= settings.floor:
            # spent below the floor, the last step short of halving the residual: the
            # lines' accuracy, as two such steps in a row are
            self.norm = norm
            return state, iteration
        self.failure = (f"Newton did not converge in {settings.max_iterations} "
                        f"iterations (residual {norm:.3g})")
        return None, settings.max_iterations

    def check_interrupted(self, iteration=None):
        """RodInterrupted when a rank received a stop signal (``interrupts``): asked by
        every rank at the same iteration (the Newton's steps are the same on every
        rank), so that all stop together, nothing written; without ``iteration``
        after a failure (a line's walk stopped by the signal). Collective."""
        number = 0 if self.interrupts is None else self.interrupts.received()
        if number:
            where = "" if iteration is None else f", iteration {iteration}"
            raise RodInterrupted(f"stopped by {self.interrupts.name(number)} during the "
                                 f"system's Newton (load factor {self.factor:.6g}{where}); "
                                 "nothing written", number)

    def check_restoring(self):
        """RodInputError naming a body's or a point's degree of freedom that nothing
        restores (the Jacobian at the start is singular in it)."""
        ok, forces, stiffness = self.evaluate(self.state, strict=True)
        if not ok:
            raise RodDivergedError(f"system: at the start, {self.failure}")
        self.forces = forces
        r, J = self.residual(self.state, self.loads, forces, stiffness)
        where = self.singular_dof(J, self.scales())
        if where is None:
            return
        node, dof = where
        if any(b.name == node for b in self.system.bodies):
            raise RodInputError(f"body {node}: nothing restores its {dof} (no line, weight "
                                "or hydrostatic stiffness resists it): hold it (Body.held) "
                                "or add a line or a hydrostatic stiffness")
        raise RodInputError(f"point {node}: nothing restores its {dof} (its lines are "
                            "slack or in line with it): make it fixed or connect another "
                            "line")

    def solve(self, system=None):
        """The Equilibrium (collective) under ``system``'s loads (None: the one the
        solver was made with; else the same system with other body loads, point
        forces or held points' positions, started from the last equilibrium with the
        lines as they stand): Newton where the last equilibrium was (the first time:
        the system unloaded), then the continuation of the loads towards the new ones,
        each failing step halved up to ``max_halvings`` times; RodDivergedError saying
        why when that did not help, RodInterrupted where a stop signal ended it (the
        lines' walks stop at one and fail). Leaves the lines at the solution.
        ``prediction`` says what the catenary predictor did in this solve (None: a
        re-solve, warm from the last equilibrium, tries none)."""
        self.prediction = None
        try:
            return self._solve(system)
        except RodDivergedError:
            self.check_interrupted()
            raise

    def _solve(self, system):
        settings = self.settings
        if system is not None:
            self.replace(system)
        if not self.checked and self.predictable:
            predicted = self._predicted()
            if predicted is not None:
                return predicted
        if not self.checked:
            self.check_restoring()
            self.checked = True
        scale = self.scales()
        target = Loads.of(self.system, self.layout)
        factor, step, halvings, total = ((1.0, 0.0, 0, 0) if self.loads.same(target) else
                                         (0.0, 1.0 / settings.load_steps, 0, 0))
        self.factor = factor
        state, iterations = self.newton(self.state, self.loads.towards(target, factor),
                                        scale)
        total += iterations
        if state is None:
            raise RodDivergedError(f"system: no equilibrium at load factor {factor:g}: "
                                   f"{self.failure}")
        self.state = state
        while factor < 1.0:
            to = self.factor = min(1.0, factor + step)
            state, iterations = self.newton(self.state, self.loads.towards(target, to),
                                            scale)
            total += iterations
            if state is None:
                halvings += 1
                if halvings > settings.max_halvings:
                    raise RodDivergedError(
                        f"system: no equilibrium at load factor {to:g} after "
                        f"{settings.max_halvings} halvings of the load step (from "
                        f"{factor:g}): {self.failure}")
                step *= 0.5
                continue
            self.state, factor, step = state, to, 2.0 * step
        self.loads = target
        return self._finish(factor, total, halvings)

    def _predicted(self):
        """The first solve from the catenaries' equilibrium (system/predictor.py): the
        lines' first solves at the ends it puts them (each within
        Settings.prediction_budget: _first_solves), then Newton under the full loads;
        None where no catenary stands in for a line, the catenaries have no
        equilibrium, a line fails there, or that Newton fails: the solver is then as
        made (its lines made again), for the continuation from the unloaded system.
        ``prediction`` says which. Collective (the catenaries dealt over the ranks as
        the rods are)."""
        self.predictable = False                # the first solve's only
        state, why = predict(self.system, self.settings, type(self), self.comm)
        if state is None:
            self.prediction = f"not used: {why}"
            return None
        target = Loads.of(self.system, self.layout)
        try:
            self.state = State(state.points, state.bodies)
            self._first_solves()
            self.checked, self.factor = True, 1.0
            solved, iterations = self.newton(self.state, target, self.scales())
            if solved is None:
                raise RodDivergedError(self.failure)
        except RodInterrupted:
            raise
        except RodError as error:
            self.check_interrupted()            # a stop signal failed the lines: stop
            self.prediction = f"failed ({error}); solved from the unloaded system"
            self._drop_lines()
            self._start(self.first)
            return None
        self.prediction = "used"
        self.state, self.loads = solved, target
        return self._finish(1.0, iterations, 0)

    def _first_solves(self):
        """check_restoring at the predicted state, each line's first solve there held to
        Settings.prediction_budget iterations in one attempt (HeldLine.budget): a
        prediction the rods cannot reach within it fails early, where the lines' own
        halvings and caps would spend thousands of iterations on it. The iterations
        each line took are left in ``predicted_iterations``. Collective."""
        budget = self.settings.prediction_budget
        capped = [line for line in self.lines.values() if hasattr(line, "budget")]
        for line in capped:
            line.budget = budget
        try:
            self.check_restoring()              # the lines' first solves, there
            failure = None
        except RodInterrupted:
            raise
        except RodDivergedError:
            failure = (f"at the prediction, each line's first solve within {budget} "
                       f"iterations: {self.failure}")
        finally:
            for line in capped:
                line.budget = None
        # collective: not in ``finally``, where one rank's own exception would meet
        # the others' next share
        spent = self.placement.share({k: int(getattr(line, "iterations", 0))
                                      for k, line in self.lines.items()})
        self.predicted_iterations = {self.system.lines[k].name: spent[k]
                                     for k in sorted(spent)}
        if failure is not None:
            raise RodDivergedError(failure)

    def _finish(self, factor, total, halvings):
        """The Equilibrium at the solver's state (solve), the lines left there."""
        # The lines may stand at the last trial; leave them at the solution, and report
        # the end forces and stiffness of the lines as they are left (a re-solve from a
        # trial differs by the lines' own tolerances).
        solved = self.evaluate(self.state, settle=True)
        if not solved[0] and self.stiffnesses.matrix is None:
            solved = self.evaluate(self.state)
        if solved[0]:
            self.forces, self.stiffnesses = solved[1], solved[2]
        if self.stiffnesses.matrix is None:
            # the lines' stiffness failed at the equilibrium itself (the iterations
            # ended at a trial, which takes none): no stiffness to report
            raise RodDivergedError(f"system: the lines' stiffness at the equilibrium "
                                   f"failed: {self.failure}")
        lines = self.line_verdicts()
        return self.result(factor, total, halvings, lines, system_verdict(self, lines))

    def line_verdicts(self):
        """{line name: line.stable()} of every line where it stands, in the system's
        order, on every rank: True a local minimiser of its energy, False a saddle, None
        undecided. The lines may be solved with their own stability test off during the
        iterations (a third of a warm re-solve) and are tested here once; the run's
        records read these verdicts. A line without ``stable`` (a mock) is not tested
        (None). Collective."""
        verdicts = self.placement.share({k: getattr(line, "stable", lambda: None)()
                                         for k, line in self.lines.items()})
        return {self.system.lines[k].name: verdicts[k] for k in sorted(verdicts)}

    def replace(self, system):
        """Take ``system``'s loads: RodInputError unless it differs from the solver's
        only in the bodies' loads, the points' forces, the held points' positions and
        the bodies' reference points in their held translations."""
        old = self.system
        same = (repr(system.lines) == repr(old.lines)
                and repr(system.environment) == repr(old.environment)
                and len(system.points) == len(old.points)
                and len(system.bodies) == len(old.bodies)
                and all(replace(new, load=b.load, position=b.position) == b
                        and _moved_where_held(new, b)
                        for new, b in zip(system.bodies, old.bodies))
                and all(replace(new, force=p.force, position=p.position) == p
                        for new, p in zip(system.points, old.points)))
        if not same:
            raise RodInputError("system: a solver re-solves its system under other body "
                                "loads, point forces or held points' positions (and "
                                "bodies' positions in their held translations) only; make "
                                "a new one for any other change")
        self.system = system

    def result(self, factor, iterations, halvings, stable=None, own=None):
        """The Equilibrium at the solver's state: ``stable`` the lines' verdicts, ``own``
        the system's (SystemVerdict)."""
        state, names = self.state, [b.name for b in self.system.bodies]
        points = {p.name: state.points[i].copy() for i, p in enumerate(self.system.points)}
        return Equilibrium(points,
                           dict(zip(names, state.bodies.positions)),
                           dict(zip(names, state.bodies.R.copy())),
                           self.forces.copy(), factor, iterations, halvings,
                           float(self.norm),
                           tuple(name for name, verdict in (stable or {}).items()
                                 if verdict is False), dict(stable or {}), own)

    # -- the lines' own results -------------------------------------------------------------

    def collect(self, ask, root=None):
        """[ask(line) for every line of the system], in the system's order: ``ask`` is
        called on this rank's lines (collective on each line's communicator: every rank
        of a group calls it) and what its group's root returns is shared to every rank
        (``root`` None; small values) or gathered to rank ``root`` only (None on the
        others: a picture's centrelines). Collective on the solver's communicator."""
        mine = {k: ask(line) for k, line in sorted(self.lines.items())}
        if root is None:
            shared = self.placement.share(mine)
        else:
            shared = self.placement.gather(mine, root)
            if shared is None:
                return None
        return [shared[k] for k in range(len(self.system.lines))]

    # -- the mooring stiffness -----------------------------------------------------------

    def body_stiffness(self, name):
        """The BodyStiffness of the body ``name`` at the current state: the lines'
        Jacobian J (lines_part), the free points condensed,
        K = -(J_bb - J_bp J_pp^-1 J_pb); not symmetrised."""
        index = [b.name for b in self.system.bodies].index(name)
        r, J = self.lines_part(self.state, self.forces, self.stiffnesses)
        b, p = self.layout.body_dofs[index], self.layout.point_dofs
        K = -J[np.ix_(b, b)]
        if p.size:
            K += J[np.ix_(b, p)] @ np.linalg.solve(J[np.ix_(p, p)], J[np.ix_(p, b)])
        moment = r[b[3:]]
        size = np.linalg.norm(K)
        asymmetry = np.linalg.norm(K - K.T) / size if size > 0 else 0.0   # no line: K = 0
        return BodyStiffness(K, self.state.bodies.X[index].copy(), moment, float(asymmetry))


def solve_system(system, make_line, comm=None, sizes=None, settings=Settings(),
                 stiffness=True):
    """(Equilibrium, {body name: BodyStiffness}) of ``system`` (SystemSolver); the
    lines are destroyed before it returns. Collective on ``comm``."""
    solver = SystemSolver(system, make_line, comm, sizes, settings)
    try:
        result = solver.solve()
        stiffnesses = ({b.name: solver.body_stiffness(b.name) for b in system.bodies}
                       if stiffness else {})
        return result, stiffnesses
    finally:
        solver.destroy()
