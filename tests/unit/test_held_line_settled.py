"""When a HeldLine's solve counts as settled (petsc_rod/system/held_line.py: ``settled``,
read by settle() before the stiffness): only where the solve's last step ended at its
last converged Newton run or at the iteration after it, whatever ran before. The
continuation's events are scripted here (events.py), in the order continuation.py
yields them: an attempt's own events, then its StepHalved or StepEnded, then the run's
end."""

import pytest
from petsc4py import PETSc

from petsc_rod.api import End, Environment, Model, UniformLine
from petsc_rod.errors import RodDivergedError
from petsc_rod.iteration import events
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.iteration.newton import CONVERGED, FAILED
from petsc_rod.iteration.stopping import StepReport
from petsc_rod.system import held_line
from petsc_rod.system.held_line import HeldLine


def newton(iteration, outcome=CONVERGED):
    return events.NewtonAttempt("step 1/1 ", iteration, outcome)


def ended(iterations, t=1.0):
    report = StepReport(True, iterations, 1e-10, 1e-10)
    return events.StepEnded("step 1/1", t, report, 1, 0, 0, iterations, 0, 0.0)


HALVED = events.StepHalved("step 1/1", 1.0, "not converged", 1, 0.0, 0.5)
ESCAPED = events.SaddleLeft("step 1/1 ", 30, 0.3, False)
FINISHED = events.RunFinished(True, "step 1/1", None, 0, 0, 0, 0.0, 1.0)

PATHS = {
    "ends at the run": ([newton(20), ended(20)], True),
    "one iteration after it": ([newton(20), ended(21)], True),
    "after a failed run, at a converged one": ([newton(17, FAILED), newton(49), ended(49)],
                                               True),
    "iterates on after the run": ([newton(20), ended(35)], False),
    "a failed run after a converged one": ([newton(20), newton(40, FAILED), ended(60)],
                                           False),
    "leaves a saddle after the run": ([newton(20), ESCAPED, ended(30)], False),
    "its attempt undone, the retries plain": ([newton(17), HALVED, ended(15, 0.5),
                                               ended(9)], False),
    "a later step plain": ([newton(18), ended(18, 0.5), ended(12)], False),
    "the last step at its run": ([ended(12, 0.5), newton(18), ended(18)], True),
}


@pytest.mark.parametrize("name", list(PATHS))
def test_settled_only_where_the_last_step_ends_at_newton(name, monkeypatch):
    script, settled = PATHS[name]
    line = HeldLine(Model(UniformLine(length=10.0, stiffness=(1.0, 1.0, 1.0),
                                      load=(0, 0, -1.0), elements=4),
                          End.anchor((0.0, 0.0, 0.0)), End.anchor((8.0, 0.0, 0.0)),
                          Environment()), PETSc.COMM_SELF)
    monkeypatch.setattr(held_line, "continuation",
                        lambda solver, path, stop=None: iter(script + [FINISHED]))
    assert line._run(PathSettings(steps=1, track_link=False))
    assert line.settled is settled


def diverging(script):
    """The continuation of ``script`` that then raises a divergence, as a solve's
    failure inside an attempt does."""
    yield from script
    raise RodDivergedError("diverged")


FAILURES = {
    "a divergence after a settled half step": lambda: iter(
        [newton(20), ended(20, 0.5), events.RunDiverged(RodDivergedError("x"), 0.75, 1)]),
    "an error raised after a settled half step": lambda: diverging(
        [newton(20), ended(20, 0.5)]),
}


@pytest.mark.parametrize("name", list(FAILURES))
def test_a_failed_run_is_not_settled(name, monkeypatch):
    """A run that fails after a half step that ended at Newton (the review: the flag
    stayed true, and a walk's restored equilibrium then skipped its settling)."""
    line = HeldLine(Model(UniformLine(length=10.0, stiffness=(1.0, 1.0, 1.0),
                                      load=(0, 0, -1.0), elements=4),
                          End.anchor((0.0, 0.0, 0.0)), End.anchor((8.0, 0.0, 0.0)),
                          Environment()), PETSc.COMM_SELF)
    monkeypatch.setattr(held_line, "continuation",
                        lambda solver, path, stop=None: FAILURES[name]())
    assert not line._run(PathSettings(steps=1, track_link=False))
    assert line.settled is False


def test_a_failed_walk_puts_back_the_restored_equilibriums_flag(monkeypatch):
    """A walk that fails restores the last equilibrium (and the line stays converged):
    its settled flag comes back with it, not the failed run's (whose half step ended at
    a converged Newton run)."""
    line = HeldLine(Model(UniformLine(length=10.0, stiffness=(1.0, 1.0, 1.0),
                                      load=(0, 0, -1.0), elements=4),
                          End.anchor((0.0, 0.0, 0.0)), End.anchor((8.0, 0.0, 0.0)),
                          Environment()), PETSc.COMM_SELF)
    try:
        assert line.solve((0.0, 0.0, 0.0), (8.0, 0.0, 0.0))
        line.settled = False                # as a solve ended by the tolerances leaves it
        monkeypatch.setattr(held_line, "continuation",
                            lambda solver, path, stop=None: FAILURES[
                                "a divergence after a settled half step"]())
        assert not line.solve((0.0, 0.0, 0.0), (8.5, 0.0, 0.0))
        assert line.converged and line.settled is False
    finally:
        line.destroy()
