"""The step controller (iteration/controller.py): its decisions from the rows it is given,
and the budgets it keeps, without a solver."""

import numpy as np
import pytest

from petsc_rod.errors import RodIterationDiverged
from petsc_rod.iteration import controller as control
from petsc_rod.iteration import events
from petsc_rod.iteration.stopping import STOP_MAX_IT, STOP_OBSERVER, Settings

SETTINGS = Settings(asked_penalty=1.0, max_it=100, rtol=1e-9, ctol=1e-9)


def fed(rows, newton=False, settings=SETTINGS, observer=None):
    """A controller that has seen ``rows`` (change, residual), deciding after each; the
    decisions."""
    step = control.StepController(settings, ceiling=1.0, newton=newton, label="step 1/1 ",
                                  observer=observer)
    decisions = [step.observe(change, residual, penalty=1.0) for change, residual in rows]
    return step, decisions


def test_it_iterates_until_both_tests_hold():
    step, decisions = fed([(1e-3, 1e-3), (1e-10, 1e-3), (1e-10, 1e-10)])
    assert [d.action for d in decisions] == [control.Action.ITERATE] * 2 + [control.Action.CONVERGED]
    assert step.converged and step.finished
    report = step.report()
    assert report.converged and report.iterations == 3 and report.reason == ""


def test_a_decision_is_taken_at_every_row_and_kept_until_the_next():
    calls = []
    step, _ = fed([(1e-3, 1e-3), (1e-10, 1e-10)],
                  observer=lambda *row: calls.append(row) and False)
    assert calls == [(1, 1e-3, 1e-3), (2, 1e-10, 1e-10)]
    assert step.current.action is control.Action.CONVERGED and step.finished
    step.resume()
    assert step.current.action is control.Action.ITERATE and not step.finished


def test_a_diverged_row_ends_the_step_with_an_error_that_names_no_option():
    step, decisions = fed([(1e-3, 1e-3), (np.nan, 1.0)])
    assert decisions[-1].action is control.Action.DIVERGED
    assert isinstance(step.error, RodIterationDiverged) and step.error.iterations == 2
    assert str(step.error).startswith("step 1/1 iteration 2: the iteration diverged")
    assert "-rod_" not in str(step.error)


def test_the_cap_and_the_observer_stop_the_step():
    _, decisions = fed([(1e-3, 1e-3)] * 100)
    assert decisions[-1] == control.Decision(control.Action.STOP, STOP_MAX_IT)
    assert all(d.action is control.Action.ITERATE for d in decisions[:-1])
    step, decisions = fed([(1e-3, 1e-3)], observer=lambda *row: True)
    assert decisions[-1] == control.Decision(control.Action.STOP, STOP_OBSERVER)
    assert step.report().reason == STOP_OBSERVER and not step.report().converged


def slow(n, rate=0.99, start=0.05):
    """n rows near a solution falling by ``rate`` per iteration: many iterations to go."""
    return [(start * rate**k, start * rate**k) for k in range(n)]


def test_newton_is_tried_from_newton_after_on_a_slow_step_and_waits_longer_after_a_failure():
    after = control.NEWTON_AFTER
    step, decisions = fed(slow(after + 5), newton=True)
    actions = [d.action for d in decisions]
    first = actions.index(control.Action.TRY_NEWTON)
    assert first + 1 >= after and all(a is control.Action.ITERATE for a in actions[:first])
    step.resume()
    step.newton_failures += 1
    step.wait_for_newton()
    assert step.newton_next == len(step.history) + 2 * after
    _, without = fed(slow(after + 5), newton=False)
    assert all(d.action is control.Action.ITERATE for d in without)


def test_newton_is_not_tried_far_from_a_solution_or_on_a_fast_step():
    _, far = fed(slow(60, start=0.5), newton=True)           # above NEWTON_SWITCH
    assert control.Action.TRY_NEWTON not in [d.action for d in far[:10]]
    _, fast = fed(slow(60, rate=0.3), newton=True)           # converges before it pays
    assert control.Action.TRY_NEWTON not in [d.action for d in fast]


def test_escapes_alternate_grow_and_run_out():
    step = control.StepController(SETTINGS, 1.0, False)
    angles = [step.escape_angle() for _ in range(control.MAX_ESCAPES)]
    expected = [control.ESCAPE_ANGLE * control.ESCAPE_GROWTH**k * (-1)**k
                for k in range(control.MAX_ESCAPES)]
    assert angles == pytest.approx(expected)
    assert step.escape_angle() is None and step.escapes == control.MAX_ESCAPES
    early = step.escape_angle(early=True)           # a budget of its own, counted on
    assert early == pytest.approx(control.ESCAPE_ANGLE * control.ESCAPE_GROWTH**5 * -1)
    assert step.newton_failures == 1 and step.early_escapes == 1
    left = [event for event in step.events if isinstance(event, events.SaddleLeft)]
    assert [event.angle for event in left] == pytest.approx(expected + [early])
    assert [event.early for event in left] == [False] * control.MAX_ESCAPES + [True]


def test_a_newton_solution_that_needs_a_larger_penalty_raises_it():
    step = control.StepController(SETTINGS, 1.0, True)
    assert step.newton_converged(True, least_penalty=0.5, penalty=1.0) is None
    assert step.newton_converged(True, least_penalty=3.0, penalty=1.0) == pytest.approx(
        control.NEWTON_RAISE * 3.0)
    step.newton_failed("indefinite")
    assert step.newton_failures == 1
    outcomes = [event.outcome for event in step.events if isinstance(event, events.NewtonAttempt)]
    assert outcomes == ["converged", "converged", "indefinite"]


def newton_rows(norms, observer=None):
    """A controller after two iterations and two Newton steps (turns 1e-5 and 1e-11 rad)
    of an attempt that converged, with the last step's stopping quantities ``norms``."""
    from petsc_rod.problem.state import Norms
    step, _ = fed([(1e-3, 1e-3), (1e-4, 1e-4)], newton=True, observer=observer)
    step.resume()
    for turn in (1e-5, 1e-11):
        step.record_newton_step(turn)
    step.newton_converged(True, least_penalty=0.5, penalty=1.0,
                          norms=None if norms is None else Norms(*norms))
    return step


def test_a_newton_solution_whose_last_step_passes_the_tests_ends_the_step():
    """Measured as an iteration, the last step's change and residual over the
    deformation's scale are tested (docs/method.md §11, "Convergence in Newton's terms"),
    and its row holds them; the observer sees that row."""
    calls = []
    step = newton_rows((2e-12, 1e-13, 0.01), observer=lambda *row: calls.append(row) and False)
    assert step.converged and step.finished and step.verified_by_newton
    report = step.report()
    assert report.iterations == 4 and report.newton_steps == 2
    assert report.change == pytest.approx(2e-10) and report.constraint_residual == pytest.approx(1e-11)
    assert calls[-1] == (4, pytest.approx(2e-10), pytest.approx(1e-11))
    # over the scale the change fails rtol: the iteration goes on from the hand-over
    step = newton_rows((2e-11, 0.0, 0.01))
    assert not step.finished and step.history[-1][0] == 2e-11
    # at the round-off floor (no norms) the iteration goes on, the step's row the turn
    step = newton_rows(None)
    assert not step.finished and step.history[-1][0] == 1e-11
    assert step.verified_by_newton          # for the iteration after the attempt
    step.observe(1e-10, 1e-10, penalty=1.0)
    assert step.converged and step.verified_by_newton


def test_an_observer_can_stop_a_step_newton_solved():
    step = newton_rows((2e-12, 0.0, 1.0), observer=lambda *row: True)
    assert step.finished and not step.converged
    assert step.report().reason == STOP_OBSERVER
