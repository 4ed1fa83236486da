"""The catenary predictor of a system's first solve (system/predictor.py,
docs/systems.md "Speed"): its elastic catenary's stiffness is exact, a system's first
solve starts from the catenaries' equilibrium and lands where the continuation from the
unloaded system does, and where the rods' Newton from the prediction fails the solver is
today's from its start, bit for bit. On one rank and on two."""

import dataclasses
import os

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import REPO_ROOT
from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import held_lines
from petsc_rod.system.predictor import CatenaryLine, predict, refusal

pytestmark = pytest.mark.solver


def small_system(load=(3e4, 1e4, 0, 0, 0, 0)):
    """The free body on three 70 m chains in 30 m of water (10 elements a line) under
    ``load``: 30 kN and 10 kN of surge and sway move it 3.9 m."""
    system, _ = read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                          "small_free_body.dat"))
    return dataclasses.replace(system, bodies=(dataclasses.replace(system.bodies[0],
                                                                   load=load),))


def solved(system, predict):
    solver = SystemSolver(system, held_lines(system), PETSc.COMM_WORLD,
                          settings=Settings(predictor=predict))
    try:
        result = solver.solve()
        return result, solver.body_stiffness("Body1").matrix, solver.prediction
    finally:
        solver.destroy()


@pytest.mark.parametrize("ends", [((0.0, 0.0, -30.0), (60.0, 5.0, -5.0)),      # grounded
                                  ((0.0, 0.0, -30.0), (66.0, 10.0, -5.0)),     # hanging
                                  ((60.0, 5.0, -5.0), (0.0, 0.0, -20.0))])     # above, flipped
def test_the_catenarys_stiffness_is_its_forces_derivative(ends):
    """K = d(F_a, F_b)/d(x_a, x_b) against central differences of the closed form (to
    1e-6 of its largest entry), the forces balancing the suspended weight."""
    line = CatenaryLine(small_system().lines[0], small_system().environment)
    start, end = (np.array(e) for e in ends)
    assert line.solve(start, end)
    F, K = line.end_forces(), line.stiffness()
    h = 1e-5
    columns = []
    for j in range(6):
        step = np.zeros(6)
        step[j] = h
        plus, minus = CatenaryLine(small_system().lines[0], small_system().environment), \
            CatenaryLine(small_system().lines[0], small_system().environment)
        assert plus.solve(start + step[:3], end + step[3:])
        assert minus.solve(start - step[:3], end - step[3:])
        columns.append((plus.end_forces() - minus.end_forces()).ravel() / (2 * h))
    assert np.abs(np.array(columns).T - K).max() < 1e-6 * np.abs(K).max()
    # the ends' horizontal forces balance; the vertical ones carry at most the weight
    assert np.abs(F[0, :2] + F[1, :2]).max() < 1e-9 * np.abs(F).max()
    assert -(F[0, 2] + F[1, 2]) <= line.w * line.L * (1 + 1e-12)


def test_the_first_solve_starts_from_the_catenaries_and_lands_where_it_did():
    """The predicted solve takes fewer Newton steps (3 against 10) and its pose is the
    continuation's to 1e-6 m and rad (both at the residual's tolerance), K to 1e-6."""
    system = small_system()
    predicted, K, used = solved(system, True)
    plain, K_plain, unused = solved(system, False)
    assert used == "used" and unused is None
    assert predicted.iterations < plain.iterations
    assert np.abs(predicted.bodies["Body1"] - plain.bodies["Body1"]).max() < 1e-6
    assert np.abs(plain.bodies["Body1"][:2] - (3.898, 0.7395)).max() < 1e-3
    assert np.abs(K - K_plain).max() < 1e-6 * np.abs(K_plain).max()


def test_in_a_current_the_prediction_lands_where_the_continuation_does():
    """In a current turning and slowing with depth (1 m/s along +y at the surface, 0.5
    m/s at 30 m, 0.3 then 0.5 along +x) the catenaries carry no drag, so the prediction
    is the pose without the lines' drag; the rods' Newton from it takes fewer steps (6
    against 14) to the continuation's pose, to 1e-6 m and rad, and K to 1e-6 of its
    largest entry; the current moves the body (0.13 m along x, 0.10 m along y, from
    the pose in still water), so the test is not of still water."""
    system = small_system()
    current = np.array([[0.0, 0.3, 1.0, 0.0], [30.0, 0.5, 0.5, 0.0]])
    wet = dataclasses.replace(system, environment=dataclasses.replace(
        system.environment, current=current))
    predicted, K, used = solved(wet, True)
    plain, K_plain, unused = solved(wet, False)
    still, _, _ = solved(system, True)
    assert used == "used" and unused is None
    assert predicted.iterations < plain.iterations
    assert np.abs(predicted.bodies["Body1"] - plain.bodies["Body1"]).max() < 1e-6
    assert np.abs(K - K_plain).max() < 1e-6 * np.abs(K_plain).max()
    drift = plain.bodies["Body1"][:2] - still.bodies["Body1"][:2]
    assert drift[0] > 0.1 and drift[1] > 0.05


def test_a_warm_re_solve_says_nothing_of_the_predictor():
    """The first solve predicted ("used"); a re-solve under another load starts from the
    last equilibrium (a sweep's warm case) and its ``prediction`` is None, so the run
    does not repeat the note for it."""
    system = small_system()
    solver = SystemSolver(system, held_lines(system), PETSc.COMM_WORLD)
    try:
        solver.solve()
        assert solver.prediction == "used"
        solver.solve(small_system((2e4, 1e4, 0, 0, 0, 0)))
        assert solver.prediction is None
    finally:
        solver.destroy()


def test_a_failed_prediction_is_the_plain_solve_bit_for_bit(monkeypatch):
    """The rods failing at the predicted pose (their first evaluation there made to
    fail): the solver's lines are made again and it solves from its start as without
    the predictor, bit for bit."""
    from petsc_rod.errors import RodDivergedError

    check = SystemSolver.check_restoring

    def failing_first(self):
        if self.settings.predictor and not getattr(self, "failed_once", False):
            self.failed_once, self.failure = True, "made to fail"    # as evaluate's
            raise RodDivergedError(f"system: at the start, {self.failure}")
        return check(self)
    monkeypatch.setattr(SystemSolver, "check_restoring", failing_first)
    system = small_system()
    failed, K, why = solved(system, True)
    plain, K_plain, _ = solved(system, False)
    assert why.startswith("failed (at the prediction, each line's first solve within "
                          f"{Settings().prediction_budget} iterations: made to fail)")
    assert np.array_equal(failed.bodies["Body1"], plain.bodies["Body1"])
    assert np.array_equal(K, K_plain)
    assert failed.iterations == plain.iterations


def drag_buoy(current):
    """The free buoy (1000 kg, 10 m^3, a drag area of 5 m^2) on two 110 m chains from
    anchors 200 m apart in 30 m of water, 10 m down at the start, in ``current``."""
    system, _ = read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                          "drag_buoy.dat"))
    return dataclasses.replace(system, environment=dataclasses.replace(
        system.environment, current=current))


def test_a_failed_prediction_costs_the_lines_at_most_their_cap():
    """In 0.5 m/s across, the catenaries' pose (the buoy without the lines' drag) is one
    the rods do not reach from their catenary starts within their cap: each line's first
    solve there stops at Settings.prediction_budget iterations in one attempt (without
    the cap they ran 1785 and 1834 iterations there, in 1 m/s 22 074 together), the
    prediction fails, and the solver solves from the unloaded system to the pose
    without the predictor (bit for bit: the same solve), 3.70 m across and 0.38 m above
    the surface (a free point keeps its volume's buoyancy there, as MoorDyn's does:
    its 10 m^3 lift more than the chains weigh)."""
    budget = Settings().prediction_budget
    system = drag_buoy((0.0, 0.5, 0.0))
    solver = SystemSolver(system, held_lines(system), PETSc.COMM_WORLD)
    try:
        result = solver.solve()
        why, spent = solver.prediction, solver.predicted_iterations
    finally:
        solver.destroy()
    plain = SystemSolver(system, held_lines(system), PETSc.COMM_WORLD,
                         settings=Settings(predictor=False))
    try:
        expected = plain.solve()
        assert plain.predicted_iterations is None
    finally:
        plain.destroy()
    assert why.startswith(f"failed (at the prediction, each line's first solve within "
                          f"{budget} iterations: line Line1 did not converge)")
    assert sorted(spent) == ["Line1", "Line2"]
    assert all(0 < n <= budget for n in spent.values()), spent
    assert np.array_equal(result.points["Point2"], expected.points["Point2"])
    assert result.iterations == expected.iterations
    assert np.abs(result.points["Point2"] - (0.0, 3.7000, 0.3816)).max() < 1e-4


def test_what_a_catenary_cannot_stand_in_for():
    system = small_system()
    assert refusal(system) is None
    wet = dataclasses.replace(system.environment, current=(0.5, 0.0, 0.0))
    assert refusal(dataclasses.replace(system, environment=wet)) is None     # a start only
    rough = dataclasses.replace(system.environment, seabed_friction=0.5)
    assert refusal(dataclasses.replace(system, environment=rough)) == "seabed friction"
    clamped = dataclasses.replace(system.lines[1], end=dataclasses.replace(
        system.lines[1].end, kind="clamp"))
    assert refusal(dataclasses.replace(system, lines=(system.lines[0], clamped,
                                                      system.lines[2]))) == \
        "line Line2: a clamped or flex-jointed end"
    # a body given where the catenaries rest (1.6464 m up) barely moves: not used
    rest = small_system((0, 0, 0, 0, 0, 0))
    state, why = predict(rest, Settings(), SystemSolver, PETSc.COMM_WORLD)
    assert why is None and state.bodies.positions[0][2] == pytest.approx(1.6464, abs=1e-3)
    there = dataclasses.replace(rest.bodies[0], position=(0, 0, 1.6464, 0, 0, 0))
    state, why = predict(dataclasses.replace(rest, bodies=(there,)), Settings(),
                         SystemSolver, PETSc.COMM_WORLD)
    assert state is None and why.startswith("the catenaries' ends move")
