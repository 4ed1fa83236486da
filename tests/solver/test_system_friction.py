"""A system's lines on a seabed with Coulomb friction (system/held_line.py: each line's
friction anchors held where its first solve started, the line as laid, so that its
equilibrium is a function of its ends alone; physics/friction.py), serially and on all
ranks, on tests/data/moordyn/small_free_body.dat (a free buoyant body on three 70 m
chains) read by the API, its seabed 0.2 m below the anchors (no anchor's contact
one-sided) with friction mu:

(a) a frictional line's stiffness (the friction's Newton Jacobian, J's LU) against
    central differences of its re-solves, its fairlead pulled sideways so that part of
    its grounded length sticks and part slides;
(b) the body under a side load: converged, its force and moment balance recomputed from
    the lines' end forces to round-off, its 6 x 6 against central differences of the
    lines re-solved at moved and turned poses, the same pose on one rank and on all;
(c) the answer does not depend on the trials: the equilibrium reached in one load step,
    by a continuation, and after a detour through another load, the same to the floor;
(d) a friction so large that every grounded node sticks: the pose does not depend on
    mu; a friction that vanishes: the frictionless system's pose;
(e) two coefficients (no Newton steps) refused in one line naming the line, on a flat
    seabed and on a sloping plane (one coefficient on a plane:
    test_system_friction_plane.py).
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import read_moordyn
from petsc_rod.errors import RodInputError
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import HeldLine, friction_notes, held_lines

from test_held_line import differences
from test_system_clamped import COMMS, body_differences

pytestmark = pytest.mark.solver

DECK = Path(__file__).parents[1] / "data" / "moordyn" / "small_free_body.dat"
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
# a side load on the body, N: it drags the chains' touchdowns across the seabed
SIDE = (2e4, 6e3, 0.0, 0.0, 0.0, 0.0)
FLOOR = Settings().floor


def frictional(mu, load=SIDE):
    """The deck's system, its seabed at z = -30.2 with friction ``mu`` (None: none),
    its body loaded by ``load`` (6,)."""
    system, _ = read_moordyn(str(DECK))
    environment = dataclasses.replace(system.environment, seabed=-30.2, seabed_friction=mu)
    body = dataclasses.replace(system.bodies[0], load=tuple(load))
    return dataclasses.replace(system, environment=environment, bodies=(body,))


def solved(system, comm, load_steps=1, tolerance=TIGHT):
    solver = SystemSolver(system, held_lines(system, tolerance), comm,
                          settings=Settings(rtol=1e-12, load_steps=load_steps))
    try:
        result = solver.solve()
    except BaseException:
        solver.destroy()
        raise
    assert result.load_factor == 1.0
    return solver, result


def pose(result):
    return np.asarray(result.bodies["Body1"], dtype=float)


def friction_states(solver):
    """[(sticking, grounded) node counts] of every line, on every rank."""
    def counts(line):
        term = line.friction[0]
        grounded = term.reaction > 0
        return (line.mesh.global_sum(float(np.sum(term.stick & grounded))),
                line.mesh.global_sum(float(np.sum(grounded))))
    return solver.collect(counts)


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_frictional_line_has_the_exact_stiffness(comm):
    """The deck's second chain laid from its anchor to the body's fairlead, then the
    fairlead pulled 4 m along x: its grounded nodes near the touchdown slide, those
    near the anchor stick. K (the friction's block in J: stick k_s w I, slide the
    secant block and the z column) against central differences of re-solves (1e-5 m:
    the slides' curvature makes the differences' own error O(h^2), 3.6e-6 of the
    largest entry at 1e-4 m)."""
    system = frictional(0.5)
    ends = (np.array([-32.5, 56.292, -30.0]), np.array([-2.5, 4.33, -5.0]))
    line = HeldLine.of_system_line(system.lines[1], *ends, COMMS[comm], system.environment,
                                   {**TIGHT, "al_stability": 0})
    try:
        assert line.solve(*ends)
        moved = (ends[0], ends[1] + np.array([4.0, 0.0, 0.0]))
        assert line.solve(*moved)
        term = line.friction[0]
        grounded = term.reaction > 0
        stick = line.mesh.global_sum(float(np.sum(term.stick & grounded)))
        total = line.mesh.global_sum(float(np.sum(grounded)))
        assert 5 <= stick <= total - 5                  # part sticks, part slides
        K = line.stiffness()
        scale = np.abs(K).max()
        # the limit mu R follows the contact: K is not symmetric
        assert np.abs(K - K.T).max() > 1e-5 * scale
        error = np.abs(K - differences(line, moved, 1e-5)).max() / scale
        print(f"{stick:g} of {total:g} grounded nodes stick; K against differences "
              f"{error:.3g} of {scale:.6g}")
        assert error < 2e-6
    finally:
        line.destroy()


@pytest.fixture(scope="module", params=list(COMMS))
def spread(request):
    solver, result = solved(frictional(0.5), COMMS[request.param])
    yield solver, result
    solver.destroy()


def test_a_body_on_frictional_lines_balances(spread):
    solver, result = spread
    assert result.residual <= 1e-12
    states = friction_states(solver)
    assert all(0 < stick < grounded for stick, grounded in states)     # each line slides
    state, layout = solver.state, solver.layout
    ok, forces, linearised = solver.evaluate(state)
    assert ok
    on_body = layout.body_end == 0
    force = forces[on_body].sum(axis=0)
    moment = np.cross(solver.arms(state)[on_body], forces[on_body]).sum(axis=0)
    own, _ = solver.own_part(state, solver.loads)
    total = np.concatenate([force, moment]) + own[layout.body_dofs[0]]
    print(f"states {states}; balance {np.abs(total[:3]).max():.3g} N, "
          f"{np.abs(total[3:]).max():.3g} N m")
    assert np.abs(total[:3]).max() < 1e-9 * np.abs(forces).max()
    assert np.abs(total[3:]).max() < 1e-9 * 5.0 * np.abs(forces).max()     # 5 m arms
    # the side load moved the body along it, less far than without friction
    assert 1.0 < pose(result)[0] < pose(solved_once(None))[0]


_FRICTIONLESS = {}


def solved_once(mu, load=SIDE):
    """The pose of the system with friction ``mu`` under ``load``, on one rank (kept)."""
    key = (mu, tuple(load))
    if key not in _FRICTIONLESS:
        solver, result = solved(frictional(mu, load), PETSc.COMM_SELF)
        _FRICTIONLESS[key] = (result, friction_states(solver) if mu else None)
        solver.destroy()
    return _FRICTIONLESS[key][0]


def assert_body_stiffness_is_the_derivative(solver):
    """The body's 6 x 6 against central differences of the lines re-solved at moved
    and turned poses, to 1e-6 of its largest entry."""
    K = solver.body_stiffness("Body1").matrix
    scale = np.abs(K).max()
    error = np.abs(K - body_differences(solver)).max() / scale
    print(f"K against differences {error:.3g} of {scale:.6g}")
    assert error < 1e-6


def assert_same_pose(result, alone):
    """The pose of ``result`` and ``alone`` to the floor, their lines' end forces to
    the floor of the largest."""
    difference = np.abs(pose(result) - pose(alone)).max()
    print(f"pose difference {difference:.3g}")
    assert difference < FLOOR
    assert np.abs(result.end_forces - alone.end_forces).max() \
        < FLOOR * np.abs(alone.end_forces).max()


def test_the_body_stiffness_is_the_derivative(spread):
    assert_body_stiffness_is_the_derivative(spread[0])


def test_one_rank_and_all_agree(spread):
    assert_same_pose(spread[1], solved_once(0.5))


def test_a_continuation_reaches_the_one_step_equilibrium():
    """One load step against four (the continuation's trials and their lines' walks):
    anchors that moved with the trials' slips would leave each path its own
    equilibrium."""
    direct = solved_once(0.5)
    solver, steps = solved(frictional(0.5), PETSc.COMM_SELF, load_steps=4)
    solver.destroy()
    difference = np.abs(pose(steps) - pose(direct)).max()
    print(f"pose difference {difference:.3g}")
    assert difference < FLOOR


def test_a_detour_through_another_load_comes_back():
    """The side load turned by 90 degrees and doubled first, then the side load from
    there (the lines walked across and back, as a sweep's cases): the one-step
    equilibrium again."""
    detour = frictional(0.5, (-2 * SIDE[1], 2 * SIDE[0], 0.0, 0.0, 0.0, 0.0))
    solver, first = solved(detour, PETSc.COMM_SELF)
    try:
        back = solver.solve(frictional(0.5))
    finally:
        solver.destroy()
    direct = solved_once(0.5)
    assert np.abs(pose(first) - pose(direct))[:2].max() > 1.0         # went far
    difference = np.abs(pose(back) - pose(direct)).max()
    print(f"pose difference {difference:.3g}")
    assert difference < FLOOR


def test_a_friction_so_large_that_every_node_sticks():
    """mu 1e3 and 1e4: every grounded node sticks, the friction is the stick springs'
    alone and the pose the same (to round-off of the lines' tolerances); they hold
    the body back against the frictionless pose."""
    stuck = [solved_once(mu) for mu in (1e3, 1e4)]
    for mu in (1e3, 1e4):
        assert all(stick == grounded for stick, grounded in _FRICTIONLESS[(mu, SIDE)][1])
    difference = np.abs(pose(stuck[0]) - pose(stuck[1])).max()
    held_back = pose(solved_once(None))[0] - pose(stuck[0])[0]
    print(f"sticking poses differ by {difference:.3g}; the friction held the body back "
          f"{held_back:.3g} m")
    assert difference < 1e-9
    assert held_back > 0.01


def test_a_vanishing_friction_is_the_frictionless_system():
    """mu 1e-12 (the model takes a positive mu): the frictionless system's pose."""
    slip = np.abs(pose(solved_once(1e-12)) - pose(solved_once(None))).max()
    print(f"vanishing friction's pose from the frictionless one {slip:.3g}")
    assert slip < 1e-9


def refusal(system_line, environment, ends, ask):
    """The message of the RodInputError that ``ask`` (a HeldLine's method) raises on
    ``system_line`` solved on one rank between ``ends`` in ``environment``: one line,
    naming the line."""
    line = HeldLine.of_system_line(system_line, *ends, PETSc.COMM_SELF, environment,
                                   {"al_stability": 0})
    try:
        assert line.solve(*ends)
        with pytest.raises(RodInputError) as refused:
            ask(line)
    finally:
        line.destroy()
    message = str(refused.value)
    assert "\n" not in message
    assert f"line {system_line.name}" in message
    return message


@pytest.mark.parametrize("case", ["two coefficients", "two coefficients on a sloping plane",
                                  "two coefficients on a seabed grid"])
def test_two_coefficients_are_refused_in_one_line_naming_the_line(case):
    """mu_a != mu_l takes no Newton steps (physics/friction.py), on a flat seabed, a
    sloping plane or a grid: no exact stiffness; the refusal names the line and what
    to change. The run says once what the friction is measured from. (One
    coefficient on a grid is exact: tests/solver/test_system_friction_profile.py.)"""
    system = frictional((0.5, 0.8))
    environment = system.environment
    if case == "two coefficients on a sloping plane":
        environment = dataclasses.replace(system.environment, seabed_slope=2.0,
                                          seabed_direction=30.0,
                                          seabed_origin=(-32.5, 56.292))
    if case == "two coefficients on a seabed grid":
        level = tuple((x, y, -30.2) for x in (-100.0, 100.0) for y in (-100.0, 100.0))
        environment = dataclasses.replace(system.environment, seabed=None,
                                          seabed_profile=level, seabed_origin=(0.0, 0.0))
    ends = (np.array([-32.5, 56.292, -30.0]), np.array([-2.5, 4.33, -5.0]))
    message = refusal(system.lines[1], environment, ends, HeldLine.stiffness)
    assert message.startswith("line Line2: seabed friction with two coefficients")
    assert "one coefficient" in message
    assert friction_notes(frictional(None)) == ()
    (note,) = friction_notes(system)
    assert "as-laid" in note


def test_a_line_laid_elsewhere_is_measured_from_where_it_was_laid():
    """A sweep's cases (offsets of held points) on a fresh solver or warm from another
    case: a frictional line is laid where the system file puts its ends (held_lines'
    ``laid``) and walked to the case's; so its equilibrium at an offset is the same
    whether it came there directly or through another offset. Laid at the offset
    itself instead, its anchors (and its forces) differ."""
    base = frictional(0.5)
    moved = dataclasses.replace(base, points=tuple(
        dataclasses.replace(p, position=tuple(np.add(p.position, (3.0, -2.0, 0.0))))
        if p.name == "Point2" else p for p in base.points))
    line = moved.lines[1]
    assert line.start.to == "Point2"
    start, end = np.array(moved.node("Point2").position), np.array([-2.5, 4.33, -5.0])
    detour = start + np.array([-6.0, 1.0, 0.0])
    make = held_lines(moved, TIGHT, laid=base)
    lines = [make(line, PETSc.COMM_SELF) for _ in range(2)]
    plain = held_lines(moved, TIGHT)(line, PETSc.COMM_SELF)
    try:
        assert lines[0].laid is not None and plain.laid is None
        assert lines[0].solve(detour, end) and lines[0].solve(start, end)
        assert lines[1].solve(start, end)
        assert plain.solve(start, end)
        forces = [held.end_forces() for held in lines + [plain]]
        scale = np.abs(forces[0]).max()
        same = np.abs(forces[0] - forces[1]).max() / scale
        other = np.abs(forces[2] - forces[1]).max() / scale
        print(f"through a detour {same:.3g}, laid at the offset {other:.3g} of {scale:.6g} N")
        assert same < 1e-9
        assert other > 1e-4
    finally:
        for held in lines + [plain]:
            held.destroy()
