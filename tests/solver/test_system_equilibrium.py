"""The coupled equilibrium of a system (petsc_rod/system/equilibrium.py) with mock lines
that keep the held line's protocol exactly: a nonlinear axial spring between its ends,
F = k (|d| - L0) d / |d| on the start (d = end - start), with its analytic 6 x 6; and
the elastic catenary on a frictionless seabed (validation/elastic_catenary.py) with a
central-difference 6 x 6 (here only). Serially and under mpiexec -n 2 (the lines split
over the ranks)."""

from dataclasses import replace

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.errors import RodDivergedError, RodInputError
from petsc_rod.model.line import UniformLine
from petsc_rod.model.sea import Environment
from petsc_rod.model.system import Body, Connection, Point, System, SystemLine
from petsc_rod.system.bodies import exp_rotation, log_rotation, skew
from petsc_rod.model.system_check import tait_bryan_zyx
from petsc_rod.system.equilibrium import Loads, Settings, SystemSolver, solve_system
from petsc_rod.validation.elastic_catenary import elastic_catenary

G, RHO = 9.80665, 1025.0


class SpringLine:
    """A held line of the protocol: an axial spring of stiffness ``k`` (N/m) and rest
    length ``rest`` (m), which fails (keeping its last state, as a warm-started line
    does) for a span beyond ``limit``."""

    made = []

    def __init__(self, k, rest, comm, limit=np.inf):
        self.k, self.rest, self.ranks, self.limit = k, rest, comm.size, limit
        self.ends = None
        SpringLine.made.append(self)

    def solve(self, start, end):
        ends = np.array([start, end], dtype=float)
        if np.linalg.norm(ends[1] - ends[0]) >= self.limit:
            return False
        self.ends = ends
        return True

    def end_forces(self):
        d = self.ends[1] - self.ends[0]
        length = np.linalg.norm(d)
        f = self.k * (length - self.rest) * d / length
        return np.array([f, -f])

    def stiffness(self):
        d = self.ends[1] - self.ends[0]
        length = np.linalg.norm(d)
        u = d / length
        K = self.k * ((1 - self.rest / length) * np.eye(3) + self.rest / length * np.outer(u, u))
        return np.block([[-K, K], [K, -K]])

    def destroy(self):
        self.ends = None


def spring(line, comm):
    """The factory: the spring's k and rest length ride on the UniformLine's stiffness
    and length (a mock's convention)."""
    return SpringLine(line.line.stiffness[0], line.line.length, comm,
                      limit=line.line.stiffness[1])


def link(name, start, end, k, rest, limit=1e9, start_local=(0, 0, 0), end_local=(0, 0, 0),
         elements=10):
    return SystemLine(name, UniformLine(length=rest, stiffness=(k, limit, 1.0),
                                        elements=elements),
                      Connection(start, start_local), Connection(end, end_local))


def spread(load=(0.0,) * 6, radius=60.0, fairlead=10.0, depth=50.0, k=2e5, rest=60.0,
           clump=None, held=(False,) * 6, limit=1e9):
    """A floater on three springs at 120 degrees to anchors on the seabed, its
    fairleads at ``fairlead`` m from its axis, 5 m below its reference point; with
    ``clump`` (mass kg) one line is two springs joined at a free clump weight; the
    springs fail beyond a span of ``limit``."""
    headings = np.radians([0.0, 120.0, 240.0])
    out = np.stack([np.cos(headings), np.sin(headings), np.zeros(3)], axis=1)
    points = [Point(f"anchor{i}", "fixed", tuple(radius * out[i] + (0, 0, -depth)))
              for i in range(3)]
    lines = [link(f"line{i}", f"anchor{i}", "floater", k, rest, limit,
                  end_local=tuple(fairlead * out[i] + (0, 0, -5.0))) for i in range(3)]
    if clump is not None:
        middle = 0.5 * (np.array(points[0].position) + fairlead * out[0] + (0, 0, -5))
        points.append(Point("clump", "free", tuple(middle), mass=clump))
        lines[0] = link("line0a", "anchor0", "clump", 2 * k, rest / 2)
        lines.append(link("line0b", "clump", "floater", 2 * k, rest / 2,
                          start_local=(0, 0, 0), end_local=tuple(fairlead * out[0] + (0, 0, -5))))
    body = Body("floater", mass=2e6, cog=(0.0, 0.0, -8.0), volume=2.2e3, cob=(0.0, 0.0, -6.0),
                waterplane_area=120.0, waterplane_moments=(4e3, 4e3), load=load, held=held)
    return System(lines=tuple(lines), points=tuple(points), bodies=(body,),
                  environment=Environment(water_density=RHO, gravity=G))


class CatenaryLine:
    """A held line of the protocol: the elastic catenary of ``length`` (m), weight
    ``weight`` (N/m) and EA (N) from its start to its end in the vertical plane through
    both, resting on a flat frictionless seabed at height ``seabed`` (m) when its start
    is on it; its stiffness by central differences of step ``h`` (m)."""

    def __init__(self, length, weight, axial_stiffness, seabed, h=1e-3):
        self.data, self.h, self.ends = (length, weight, axial_stiffness), h, None
        self.seabed = seabed

    def forces_at(self, ends):
        """Its end forces (2, 3) between ``ends`` (2, 3); it rests on the seabed when
        its start is on it."""
        d = ends[1] - ends[0]
        span = np.hypot(d[0], d[1])
        along = np.array([d[0], d[1], 0.0]) / span
        line = elastic_catenary(*self.data, span, d[2], on_seabed=ends[0, 2] <= self.seabed)
        top = line.V_A + line.weight * (line.length - line.grounded)
        return np.array([line.H * along + (0, 0, line.V_A), -line.H * along - (0, 0, top)])

    def solve(self, start, end):
        self.ends = np.array([start, end], dtype=float)
        return True

    def end_forces(self):
        return self.forces_at(self.ends)

    def stiffness(self):
        steps = self.h * np.eye(6).reshape(6, 2, 3)
        return np.stack([(self.forces_at(self.ends + e) - self.forces_at(self.ends - e)).ravel()
                         / (2 * self.h) for e in steps], axis=1)

    def destroy(self):
        self.ends = None


def test_the_oc3_hywind_mooring_stiffness_is_the_published_one():
    """OC3-Hywind's three catenaries (Jonkman, Definition of the floating system for
    phase IV of OC3, NREL/TP-500-47566, 2010: anchors at 853.87 m radius in 320 m of
    water, fairleads at 5.2 m radius 70 m deep, 902.2 m of 698.094 N/m, EA 384.243 MN,
    lines at 180, 60 and 300 degrees): its linearised mooring stiffness about the
    platform's reference point at rest, as published to four figures (the crow's
    foot's added yaw spring left out)."""
    headings = np.radians([180.0, 60.0, 300.0])
    out = np.stack([np.cos(headings), np.sin(headings), np.zeros(3)], axis=1)
    system = System(
        lines=tuple(SystemLine(f"line{i}", UniformLine(length=902.2),
                               Connection(f"anchor{i}"),
                               Connection("spar", tuple(5.2 * out[i] + (0, 0, -70.0))))
                    for i in range(3)),
        points=tuple(Point(f"anchor{i}", "fixed", tuple(853.87 * out[i] + (0, 0, -320.0)))
                     for i in range(3)),
        bodies=(Body("spar", held=(True,) * 6),))
    _, stiffness = solve_system(system, lambda line, comm: CatenaryLine(
        902.2, 698.094, 384.243e6, seabed=-320.0))
    K = stiffness["spar"].matrix
    published = {(0, 0): 41180.0, (1, 1): 41180.0, (2, 2): 11940.0, (3, 3): 311.1e6,
                 (4, 4): 311.1e6, (5, 5): 11.56e6, (0, 4): -2.821e6, (1, 3): 2.821e6,
                 (4, 0): -2.821e6, (3, 1): 2.821e6}
    for (i, j), value in published.items():
        assert K[i, j] == pytest.approx(value, rel=2.5e-3), (i, j)
    assert stiffness["spar"].asymmetry < 1e-9             # the lines' moment is zero


def test_a_catenary_split_at_a_massless_free_point_is_the_unsplit_catenary():
    """OC3-Hywind's line resting on the seabed, split in its hanging part at a free
    point of no mass: the point goes where the unsplit line's point of that arc length
    is, and the fairlead's force is the unsplit line's."""
    L, w, EA, span, rise = 902.2, 698.094, 384.243e6, 848.67, 250.0
    whole = elastic_catenary(L, w, EA, span, rise)
    lower = whole.grounded + 0.5 * (L - whole.grounded)
    x, z = (float(v) for v in whole.at(lower)[:2])
    lengths = {"lower": lower, "upper": L - lower}
    system = System(lines=(SystemLine("lower", UniformLine(length=lower),
                                      Connection("anchor"), Connection("joint")),
                           SystemLine("upper", UniformLine(length=L - lower),
                                      Connection("joint"), Connection("fairlead"))),
                    points=(Point("anchor", "fixed", (0.0, 0.0, -320.0)),
                            Point("joint", "free", (x + 5.0, 2.0, z - 323.0)),
                            Point("fairlead", "fixed", (span, 0.0, rise - 320.0))))
    result, _ = solve_system(system, lambda line, comm: CatenaryLine(
        lengths[line.name], w, EA, seabed=-320.0), PETSc.COMM_SELF)
    assert result.points["joint"] == pytest.approx([x, 0.0, z - 320.0], abs=1e-6)
    top = whole.V_A + w * (L - whole.grounded)
    assert result.end_forces[1, 1] == pytest.approx([-whole.H, 0.0, -top], rel=1e-9,
                                                    abs=1e-12 * whole.H)


def test_a_free_point_between_springs_sits_where_the_closed_form_puts_it():
    """... pushed by a force and by a current's drag 0.5 rho C_d A u^2."""
    k1, k2, L1, L2, span, Fx, u, cda = 3e4, 5e4, 4.0, 3.0, 10.0, 2e4, 0.8, 2.0
    system = System(lines=(link("left", "a", "p", k1, L1), link("right", "p", "b", k2, L2)),
                    points=(Point("a", "fixed", (0, 0, 0)), Point("b", "fixed", (span, 0, 0)),
                            Point("p", "free", (6.0, 0.3, -0.2), force=(Fx, 0, 0), cda=cda)),
                    environment=Environment(current=(u, 0.0, 0.0)))
    result, _ = solve_system(system, spring, PETSc.COMM_SELF)
    x = (k1 * L1 + k2 * (span - L2) + Fx + 0.5 * RHO * cda * u**2) / (k1 + k2)
    assert result.points["p"] == pytest.approx([x, 0.0, 0.0], abs=1e-12 * span)
    assert result.load_factor == 1.0
    assert result.residual < 1e-10


def test_a_symmetric_spread_has_no_net_horizontal_force_and_equal_stiffnesses():
    solver = SystemSolver(spread(), spring, PETSc.COMM_SELF)
    try:
        result = solver.solve()
        K = solver.body_stiffness("floater")
    finally:
        solver.destroy()
    position = result.bodies["floater"]
    horizontal = result.end_forces[:, 1, :2].sum(axis=0)
    tension = np.abs(result.end_forces[:, 1]).max()
    assert np.abs(horizontal).max() < 1e-12 * tension
    assert np.abs(position[[0, 1, 3, 4, 5]]).max() < 1e-12
    M = K.matrix
    assert M[0, 0] > 0 and M[0, 0] == pytest.approx(M[1, 1], rel=1e-12)
    assert M[3, 3] == pytest.approx(M[4, 4], rel=1e-12)
    assert abs(M[0, 1]) < 1e-12 * M[0, 0]
    assert K.asymmetry < 1e-12                  # no moment about the reference point


def equilibrium(system, comm=PETSc.COMM_SELF):
    """(solver, its Equilibrium, {body: BodyStiffness}), tightly converged."""
    solver = SystemSolver(system, spring, comm, settings=Settings(rtol=1e-13))
    try:
        result = solver.solve()
        return solver, result, {b.name: solver.body_stiffness(b.name) for b in system.bodies}
    finally:
        solver.destroy()


def lines_on_body(system, pose_X, pose_R, name="floater"):
    """The lines' (F, M) on the body held at (X, R), the free points re-equilibrated."""
    body = system.bodies[0]
    moved = Body(body.name, position=tuple(pose_X) + tuple(tait_bryan_zyx(pose_R)),
                 held=(True,) * 6)
    held = System(lines=system.lines, points=system.points, bodies=(moved,),
                  environment=system.environment)
    solver = SystemSolver(held, spring, PETSc.COMM_SELF, settings=Settings(rtol=1e-14))
    try:
        solver.solve()
        r, _ = solver.lines_part(solver.state, solver.forces, solver.stiffnesses)
        return r[solver.layout.body_dofs[0]]
    finally:
        solver.destroy()


def test_the_body_stiffness_is_the_derivative_of_re_solved_equilibria():
    system = spread(load=(3e5, 1e5, 0.0, 0.0, 0.0, 2e6), clump=2e4)
    _, result, stiffness = equilibrium(system)
    K = stiffness["floater"]
    R = result.rotations["floater"]
    X = result.bodies["floater"][:3]
    h = np.array([1e-3] * 3 + [1e-5] * 3)
    numeric = np.empty((6, 6))
    for j in range(6):
        step = np.zeros(6)
        step[j] = h[j]
        plus = lines_on_body(system, X + step[:3], exp_rotation(step[3:]) @ R)
        minus = lines_on_body(system, X - step[:3], exp_rotation(-step[3:]) @ R)
        numeric[:, j] = -(plus - minus) / (2 * h[j])
    scale = np.abs(K.matrix).max()
    assert np.abs(K.matrix - numeric).max() < 1e-8 * scale
    # the asymmetry is the lines' moment about the reference point, exactly
    assert np.abs(K.moment).max() > 1e5
    antisymmetric = K.matrix - K.matrix.T
    assert antisymmetric[3:, 3:] == pytest.approx(skew(K.moment), abs=1e-9 * scale)
    assert np.abs(antisymmetric[:3]).max() < 1e-9 * scale
    assert K.asymmetry == pytest.approx(np.linalg.norm(antisymmetric)
                                        / np.linalg.norm(K.matrix), rel=1e-12)
    assert K.asymmetry > 1e-4


def test_the_jacobian_is_the_derivative_of_the_residual_for_two_bodies_and_a_buoy():
    """Two floaters moored apart, joined by a line through a free buoy (in a current
    profile) and by a line from fairlead to fairlead, turned and offset away from
    equilibrium: the assembled Jacobian of every unknown (the cross-body blocks, the
    lever terms, the hydrostatics, the buoy's drag changing with its depth) against
    central differences of the residual with the lines re-solved."""
    one, two = spread(load=(1e5, 0, 0, 0, 0, 1e6)), spread()
    far = (300.0, 40.0, 0.0)
    bodies = (one.bodies[0], replace(two.bodies[0], name="other",
                                     position=far + (0.02, -0.01, 0.3)))
    points = one.points + tuple(replace(p, name=p.name + "b", position=tuple(
        np.add(p.position, far))) for p in two.points) + (
        Point("buoy", "free", (150.0, 20.0, -20.0), volume=20.0, mass=2e3, cda=5.0),)
    lines = one.lines + tuple(replace(l, name=l.name + "b", start=Connection(
        l.start.to + "b"), end=Connection("other", l.end.local)) for l in two.lines) + (
        link("to_buoy", "floater", "buoy", 5e4, 100.0, start_local=(10.0, 0, -5.0)),
        link("from_buoy", "buoy", "other", 5e4, 100.0, end_local=(-10.0, 0, -5.0)),
        link("across", "floater", "other", 1e4, 250.0, start_local=(0, 10.0, -5.0),
             end_local=(0, -10.0, -5.0)))
    profile = ((0.0, 1.0, 0.2, 0.0), (50.0, 0.5, 0.1, 0.0), (200.0, 0.0, 0.0, 0.0))
    system = System(lines=lines, points=points, bodies=bodies,
                    environment=Environment(current=profile, surface=0.0))
    solver = SystemSolver(system, spring, PETSc.COMM_SELF)
    try:
        state = solver.state.moved(np.linspace(-0.5, 0.6, solver.layout.size)
                                   * np.where(solver.layout.is_moment, 0.05, 1.0),
                                   solver.layout)
        loads = solver.loads.towards(Loads.of(system, solver.layout), 0.7)

        def residual(at):
            return solver.residual(at, loads, *solver.evaluate(at)[1:])

        _, J = residual(state)
        numeric = np.empty_like(J)
        for j in range(J.shape[1]):
            h = 1e-6 if solver.layout.is_moment[j] else 1e-4
            step = np.zeros(J.shape[1])
            step[j] = h
            numeric[:, j] = (residual(state.moved(step, solver.layout))[0]
                             - residual(state.moved(-step, solver.layout))[0]) / (2 * h)
    finally:
        solver.destroy()
    assert J.shape == (3 + 12, 3 + 12)
    assert np.abs(J - numeric).max() < 1e-8 * np.abs(J).max()
    assert np.abs(J[3:9, 9:]).max() > 1e3            # the bodies are coupled
    assert abs(J[0, 2]) > 10.0                      # the drag's change with depth


def test_a_loaded_body_balances_forces_and_moments_to_round_off():
    load = np.array([4e5, -2e5, 1e5, 3e6, -2e6, 5e6])
    system = spread(load=tuple(load), clump=1e4)
    _, result, _ = equilibrium(system)
    body = system.bodies[0]
    R = result.rotations["floater"]
    X = result.bodies["floater"][:3]
    # every force on the body recomputed here from the mock lines at the solution
    F, M = load[:3].copy(), load[3:].copy()
    for line in system.lines:
        for j, c in enumerate((line.start, line.end)):
            other = (line.end, line.start)[j]
            if c.to != "floater":
                continue
            here = X + R @ np.array(c.local)
            there = (X + R @ np.array(other.local) if other.to == "floater"
                     else result.points[other.to])
            d = here - there
            length = np.linalg.norm(d)
            f = -line.line.stiffness[0] * (length - line.line.length) * d / length
            F += f
            M += np.cross(here - X, f)
    for force, arm in (((0, 0, -body.mass * G), body.cog), ((0, 0, RHO * G * body.volume), body.cob)):
        F += force
        M += np.cross(R @ np.array(arm), force)
    z, (roll, pitch) = X[2], log_rotation(R)[:2]
    F[2] -= RHO * G * body.waterplane_area * z
    M[0] -= RHO * G * body.waterplane_moments[0] * roll
    M[1] -= RHO * G * body.waterplane_moments[1] * pitch
    scale = np.abs(result.end_forces).max()
    assert np.abs(result.bodies["floater"][:2]).max() > 0.5      # it moved
    assert np.abs(F).max() < 1e-12 * scale
    assert np.abs(M).max() < 1e-12 * scale * 10.0           # levers of about 10 m


def test_a_large_offset_is_reached_by_halving_the_load_steps():
    system = spread(load=(6e6, 0, 0, 0, 0, 0))
    _, direct, _ = equilibrium(system)
    # too few Newton iterations for the whole offset at once (the residual still above
    # the floor when they are spent)
    solver = SystemSolver(system, spring, PETSc.COMM_SELF,
                          settings=Settings(rtol=1e-10, max_iterations=2))
    try:
        result = solver.solve()
    finally:
        solver.destroy()
    assert direct.bodies["floater"][0] > 20.0
    assert result.halvings > 0 and result.load_factor == 1.0
    assert result.bodies["floater"] == pytest.approx(direct.bodies["floater"], abs=1e-9)


def test_newton_spent_below_the_floor_goes_on_while_each_step_halves_the_residual():
    """Newton's iterations spent with the scaled residual below Settings.floor and
    halved by the last step (the quadratic tail of a long damped approach) go on while
    each step halves it, to rtol; above the floor they fail. Without halvings, rtol
    1e-13 out of reach in 3 iterations a load step."""
    system = spread(load=(2e6, 0, 0, 0, 0, 0))
    _, direct, _ = equilibrium(system)
    found = {}
    for budget in (2, 3):
        solver = SystemSolver(system, spring, PETSc.COMM_SELF,
                              settings=Settings(rtol=1e-13, max_iterations=budget,
                                                max_halvings=0))
        try:
            found[budget] = solver.solve()
        except RodDivergedError as error:
            found[budget] = error
        finally:
            solver.destroy()
    assert isinstance(found[2], RodDivergedError)
    assert "Newton did not converge in 2 iterations" in str(found[2])
    result = found[3]
    assert result.residual <= 1e-13 and result.load_factor == 1.0
    assert result.iterations > 6
    assert result.bodies["floater"] == pytest.approx(direct.bodies["floater"], abs=1e-12)


def test_a_solver_re_solves_under_new_loads_from_its_last_equilibrium():
    """A watch circle's step: the body's load turned, an anchor moved (a prescribed
    point); the answer is a fresh solver's, reached in fewer iterations."""
    first = spread(load=(1e6, 0, 0, 0, 0, 0))
    turned = spread(load=(0, 1e6, 0, 0, 0, 0))
    anchor = turned.points[1]
    moved = System(lines=turned.lines, bodies=turned.bodies, environment=turned.environment,
                   points=(turned.points[0], replace(anchor, kind="prescribed"),
                           turned.points[2]))
    moved_first = System(lines=first.lines, bodies=first.bodies,
                         environment=first.environment, points=moved.points)
    moved = System(lines=moved.lines, bodies=moved.bodies, environment=moved.environment,
                   points=(moved.points[0], replace(moved.points[1], position=tuple(
                       np.array(anchor.position) + (3.0, -2.0, 0.0))), moved.points[2]))
    settings = Settings(rtol=1e-13)
    solver = SystemSolver(moved_first, spring, PETSc.COMM_SELF, settings=settings)
    try:
        solver.solve()
        again = solver.solve(moved)
        with pytest.raises(RodInputError, match="re-solves its system under other body "
                                                "loads, point forces or held points"):
            solver.solve(spread(load=(0, 1e6, 0, 0, 0, 0), k=3e5))
    finally:
        solver.destroy()
    _, fresh, _ = equilibrium(moved)
    assert again.bodies["floater"] == pytest.approx(fresh.bodies["floater"], abs=1e-10)
    assert again.points["anchor1"] == pytest.approx(np.array(anchor.position) + (3, -2, 0))
    assert again.iterations < fresh.iterations


class NoisyLine(SpringLine):
    """A spring whose end forces carry an error of up to 1e-9 of themselves that
    changes from solve to solve, as that of a line converged to its own tolerance from
    its last state does."""

    solves = 0

    def solve(self, start, end):
        self.solves += 1
        return super().solve(start, end)

    def end_forces(self):
        return super().end_forces() * (1.0 + 1e-9 * np.sin(self.solves))


class CountingLine(SpringLine):
    """A spring that counts its stiffness's evaluations."""

    def stiffness(self):
        self.linearised = getattr(self, "linearised", 0) + 1
        return super().stiffness()


def counting(line, comm):
    return CountingLine(line.line.stiffness[0], line.line.length, comm,
                        limit=line.line.stiffness[1])


@pytest.mark.parametrize("load", [(4e5, -2e5, 1e5, 3e6, -2e6, 5e6), (0.0,) * 6])
def test_each_line_is_linearised_once_a_step_and_once_for_the_report(load):
    """A trial's stiffness is asked only where a step reads it: each line's once for each
    Newton step (the start's serves the first) and once at the equilibrium reported,
    not at the last step's trial too."""
    SpringLine.made = []
    solver = SystemSolver(spread(load=load), counting, PETSc.COMM_SELF,
                          settings=Settings(rtol=1e-13))
    try:
        result = solver.solve()
        K = solver.body_stiffness("floater").matrix
        assert result.iterations > 0 and np.all(np.isfinite(K))
        assert [line.linearised for line in SpringLine.made] == \
            [result.iterations + 1] * 3
    finally:
        solver.destroy()


class BreakingLine(CountingLine):
    """A counting spring whose stiffness fails (a LinAlgError, as a line's Schur solve
    may) from its ``works + 1``-th evaluation on."""

    works = 0

    def stiffness(self):
        if getattr(self, "linearised", 0) >= self.works:
            raise np.linalg.LinAlgError("singular")
        return super().stiffness()


def test_a_stiffness_that_fails_at_the_equilibrium_is_a_failed_solve():
    """The Newton steps converge, but the lines' stiffness at the equilibrium (asked for
    the report: the iterations ended at a trial, which takes none) fails: the solve fails
    with one line's message (a RodDivergedError), not a traceback when the body's
    stiffness is read (the review)."""
    load = (4e5, -2e5, 1e5, 3e6, -2e6, 5e6)
    SpringLine.made = []
    solver = SystemSolver(spread(load=load), counting, PETSc.COMM_SELF,
                          settings=Settings(rtol=1e-13))
    try:
        steps = solver.solve().iterations
    finally:
        solver.destroy()
    BreakingLine.works = steps

    def breaking(line, comm):
        return BreakingLine(line.line.stiffness[0], line.line.length, comm,
                            limit=line.line.stiffness[1])
    solver = SystemSolver(spread(load=load), breaking, PETSc.COMM_SELF,
                          settings=Settings(rtol=1e-13))
    try:
        with pytest.raises(RodDivergedError, match="stiffness at the equilibrium failed"):
            solver.solve()
    finally:
        solver.destroy()


class SettledLine(CountingLine):
    """A counting spring that says it stands at its stationary point (HeldLine's
    ``settled``): settling it changes nothing."""

    settled = True

    def settle(self):
        pass


def settled(line, comm):
    return SettledLine(line.line.stiffness[0], line.line.length, comm,
                       limit=line.line.stiffness[1])


@pytest.mark.parametrize("held", [True, False])
def test_a_settled_line_is_not_linearised_again_where_it_stands(held):
    """The equilibrium reported where the lines were last linearised (a held body: the
    start) takes the settled lines' stiffnesses as they were: once each in all."""
    SpringLine.made = []
    solver = SystemSolver(spread(held=(held,) * 6), settled, PETSc.COMM_SELF,
                          settings=Settings(rtol=1e-13))
    try:
        result = solver.solve()
        K = solver.body_stiffness("floater").matrix
        assert np.all(np.isfinite(K)) and np.abs(K).max() > 0.0
        assert [line.linearised for line in SpringLine.made] == \
            [result.iterations + 1] * 3
    finally:
        solver.destroy()


def test_a_residual_at_the_lines_accuracy_is_accepted_below_the_floor():
    system = spread(load=(1e6, 0, 0, 0, 0, 0))
    noisy = lambda line, comm: NoisyLine(line.line.stiffness[0], line.line.length, comm)
    refused(system, noisy, RodDivergedError, "the line search found no decrease",
            rtol=1e-15, floor=0.0, max_halvings=1)
    solver = SystemSolver(system, noisy, PETSc.COMM_SELF, settings=Settings(rtol=1e-15))
    try:
        result = solver.solve()
    finally:
        solver.destroy()
    _, exact, _ = equilibrium(system)
    assert 1e-15 < result.residual < 1e-10
    assert result.bodies["floater"] == pytest.approx(exact.bodies["floater"], abs=1e-7)


def test_newton_spent_at_the_lines_accuracy_ends_there():
    """Newton's iterations spent below the floor after a step that did not halve the
    residual (lines whose end forces carry an error of 1e-9 of themselves: NoisyLine)
    end it there, converged at the lines' accuracy; rtol 1e-15 out of reach, 3
    iterations a load step, no halvings."""
    system = spread(load=(1e6, 0, 0, 0, 0, 0))
    noisy = lambda line, comm: NoisyLine(line.line.stiffness[0], line.line.length, comm)
    solver = SystemSolver(system, noisy, PETSc.COMM_SELF,
                          settings=Settings(rtol=1e-15, max_iterations=3, max_halvings=0))
    try:
        result = solver.solve()
    finally:
        solver.destroy()
    _, exact, _ = equilibrium(system)
    assert 1e-15 < result.residual <= Settings().floor and result.load_factor == 1.0
    assert result.bodies["floater"] == pytest.approx(exact.bodies["floater"], abs=1e-9)


def test_a_body_on_its_hydrostatics_alone_floats_where_its_weight_is_buoyed():
    """No line: heave z = (rho V - m) g / (rho g A), on every rank."""
    body = Body("barge", mass=1e6, volume=1000.0, waterplane_area=400.0,
                waterplane_moments=(2e4, 3e4), cob=(0, 0, -1.0), cog=(0, 0, -0.5),
                held=(True, True, False, False, False, True))      # nothing holds them
    result, stiffness = solve_system(System(lines=(), bodies=(body,)), spring)
    z = (RHO * 1000.0 - 1e6) / (RHO * 400.0)
    assert result.bodies["barge"] == pytest.approx([0, 0, z, 0, 0, 0], abs=1e-12)
    assert not stiffness["barge"].matrix.any() and stiffness["barge"].asymmetry == 0.0


def test_the_same_numbers_on_one_rank_and_on_every_rank():
    """COMM_SELF (every line on this rank) against COMM_WORLD: on 2 ranks the four
    lines are two a rank, and a lone line spans both ranks."""
    system = spread(load=(3e5, 1e5, 0.0, 0.0, 0.0, 2e6), clump=2e4)
    _, alone, k_alone = equilibrium(system, PETSc.COMM_SELF)
    SpringLine.made = []
    _, shared, k_shared = equilibrium(system, PETSc.COMM_WORLD)
    size = PETSc.COMM_WORLD.size
    assert len(SpringLine.made) == {1: 4, 2: 2}[size]
    assert all(line.ranks == 1 for line in SpringLine.made)
    assert np.array_equal(alone.bodies["floater"], shared.bodies["floater"])
    assert np.array_equal(alone.end_forces, shared.end_forces)
    assert np.array_equal(k_alone["floater"].matrix, k_shared["floater"].matrix)
    hanging = System(lines=(link("only", "top", "clump", 1e4, 5.0),),
                     points=(Point("top", "fixed", (0, 0, 0)),
                             Point("clump", "free", (0.5, 0.2, -6.0), mass=100.0)))
    SpringLine.made = []
    result, _ = solve_system(hanging, spring, PETSc.COMM_WORLD)
    assert [line.ranks for line in SpringLine.made] == [size]
    assert result.points["clump"] == pytest.approx([0, 0, -5.0 - 100.0 * G / 1e4], abs=1e-12)


def test_bad_systems_get_one_line_each():
    lonely = System(lines=(link("a", "p", "q", 1e3, 1.0),),
                    points=(Point("p", "fixed", (0, 0, 0)), Point("q", "fixed", (2, 0, 0)),
                            Point("r", "free", (1, 1, 1))))
    with pytest.raises(RodInputError, match="point r: free, but no line ends at it"):
        SystemSolver(lonely, spring, PETSc.COMM_SELF)
    # fairleads on the body's axis: nothing resists its yaw
    axis = spread(fairlead=0.0)
    refused(axis, spring, RodInputError, "body floater: nothing restores its yaw")
    # ... held, it solves; held in every degree of freedom, nothing is left to solve
    solve_system(spread(fairlead=0.0, held=(False,) * 5 + (True,)), spring, PETSc.COMM_SELF)
    result, _ = solve_system(spread(held=(True,) * 6), spring, PETSc.COMM_SELF)
    assert result.iterations == 0 and result.bodies["floater"].tolist() == [0.0] * 6
    missing = System(lines=(link("a", "p", "nowhere", 1e3, 1.0),),
                     points=(Point("p", "fixed", (0, 0, 0)),))
    with pytest.raises(RodInputError, match="no point or body is named 'nowhere'"):
        SystemSolver(missing, spring, PETSc.COMM_SELF)
    # a line that cannot reach its span at any load step: one line, no traceback
    refused(spread(load=(6e6, 0, 0, 0, 0, 0), limit=75.0), spring, RodDivergedError,
            "after 3 halvings .*line line[0-9] did not converge at the full step",
            max_halvings=3)


def refused(system, make_line, error, match, comm=PETSc.COMM_SELF, **settings):
    """Solving ``system`` raises ``error`` saying ``match``."""
    solver = SystemSolver(system, make_line, comm, settings=Settings(**settings))
    try:
        with pytest.raises(error, match=match):
            solver.solve()
    finally:
        solver.destroy()


class PickyLine(SpringLine):
    """A spring that refuses (RodInputError, as a line too short for its span does) a
    span beyond its limit."""

    def solve(self, start, end):
        if np.linalg.norm(np.subtract(end, start)) >= self.limit:
            raise RodInputError(f"a span of {np.linalg.norm(np.subtract(end, start)):.1f} m: "
                                "the line is too short")
        return super().solve(start, end)


def picky(line, comm):
    return PickyLine(line.line.stiffness[0], line.line.length, comm,
                     limit=line.line.stiffness[1])


def test_a_line_that_refuses_its_ends_fails_the_attempt_but_is_an_error_at_the_start():
    """On every rank alike: the line that refuses lives on one rank of two."""
    refused(spread(load=(6e6, 0, 0, 0, 0, 0), limit=75.0), picky, RodDivergedError,
            r"after 2 halvings .*line line[0-9] refused its ends \(a span of",
            PETSc.COMM_WORLD, max_halvings=2)
    tight = spread(held=(True,) * 6, limit=60.0)
    refused(replace(tight, lines=tight.lines[:1]), picky, RodInputError,
            "the line is too short", PETSc.COMM_WORLD)
