"""The continuation (docs/method.md §7): the load path from the start to the scene in
``steps`` steps, each warm-started from the last converged state, halved when a step
fails. The run is a generator of events (events.py): it says what happened and leaves
the lines and the file to its caller (cli/session.py)."""

import time
from dataclasses import dataclass, replace

import numpy as np

from petsc_rod.analysis.link import changed_class
from petsc_rod.errors import RodDivergedError
from petsc_rod.iteration import events
from petsc_rod.iteration.controller import NEWTON_AFTER
from petsc_rod.iteration.stopping import STOP_LINK, STOP_OBSERVER

# The most halvings a path may be asked for: the load factors are counted in whole
# units of 1/(K 2^n) (LoadPath), which must stay exact integers.
MAX_HALVINGS_CAP = 50


@dataclass(frozen=True)
class PathSettings:
    """What the user asks of the load path (docs/method.md §7; the command line's
    defaults are these, cli/options.py reads them from here)."""

    steps: int = 1                  # regular steps t_k = t_0 + (t_end - t_0) k / steps
    imperfection: float = 0.0       # roll of the sections at each step's start, rad
    max_halvings: int = 4           # halvings of the step on the way to each t_k
    track_link: bool = True         # refuse a step of another linking number (link.py)
    start: float = 0.0              # the load factor the path starts from (a restart's)
    end: float = 1.0                # and ends at


class LoadPath:
    """The load factors of the continuation: ``steps`` regular steps
    t_k = t_0 + (t_end - t_0) k/K (t_0 = 0 and t_end = 1 for a whole run; t_0 > 0 for a
    restart; from t_0 = t_end, one step at t_end), and the sub-steps by which a step that
    failed is retried.

    A failed attempt halves the increment (a smaller step starts nearer its solution,
    §7), at most ``max_halvings`` times on the way to one t_k; an accepted sub-step keeps
    the halved increment until t_k is reached, then the regular one is taken again.
    Load factors are counted in whole units of 1/(K 2^max_halvings), so that every t_k is
    reached exactly and is k/K to the last bit, as without halving.
    """

    def __init__(self, steps, max_halvings, start=0.0, end=1.0):
        self.start, self.end = start, end
        self.steps = steps if start < end else 1
        self.units_per_step = 2**max_halvings
        self.reached = 0                          # units: the last accepted load factor
        self.increment = self.units_per_step      # units
        self.halvings = 0                         # in the whole run
        self.step_halvings = 0                    # on the way to the next t_k

    def factor(self, units):
        """The load factor of a number of units (``end`` exactly at the end of the path)."""
        total = self.steps * self.units_per_step
        if units == total:
            return self.end
        return self.start + (self.end - self.start) * (units / total)

    @property
    def step(self):
        """The regular step k (from 1) being worked towards."""
        return self.reached // self.units_per_step + 1

    @property
    def next_factor(self):
        """The load factor of the next attempt."""
        return self.factor(self.reached + self.increment)

    @property
    def finished(self):
        return self.reached == self.steps * self.units_per_step

    @property
    def nothing_to_halve(self):
        """Whether half the increment would not move the load factor at all:
        factor(reached + increment / 2) == factor(reached) in floating point. So it is on
        a path from t_0 = t_end (a restart at its end load factor: every step is the same
        load) and below the round-off of t; a retry there would repeat the failed attempt
        exactly, so the run must end instead."""
        half = max(self.increment // 2, 1)
        return self.factor(self.reached + half) == self.factor(self.reached)

    @property
    def can_halve(self):
        """A failed attempt may be retried with half the increment: halvings are left
        (increment > 1 unit) and the half increment still moves the load factor."""
        return self.increment > 1 and not self.nothing_to_halve

    def halve(self):
        self.increment //= 2
        self.halvings += 1
        self.step_halvings += 1

    def accept(self):
        """The attempt at ``next_factor`` converged: go on from there."""
        self.reached += self.increment
        if self.reached % self.units_per_step == 0:
            self.increment = self.units_per_step
            self.step_halvings = 0


class Predictor:
    """The start of a step: the state (tau, lambda) extrapolated linearly in the load
    factor from the last two accepted steps (docs/method.md §7), so that the iteration
    starts O(dt^2) from its solution instead of O(dt); with fewer than two, the last
    state as it is."""

    def __init__(self):
        self.accepted = []          # (t, tau, lambda) of the last two accepted states

    def accept(self, t, state):
        self.accepted = self.accepted[-1:] + [(t, state.tau.copy(), state.lam.copy())]

    def predict(self, state, t):
        """Set the RodState's tau and lambda for load factor t (its current state must
        be the last accepted one)."""
        if len(self.accepted) < 2:
            return
        (t0, tau0, lam0), (t1, tau1, lam1) = self.accepted
        ratio = (t - t1) / (t1 - t0)
        state.tau[:] = tau1 + ratio * (tau1 - tau0)
        state.lam[:] = lam1 + ratio * (lam1 - lam0)


def attempt(solver, t, imperfection, label, expected_link=None, stop=None, t_from=None):
    """One try at load factor t from the current state, its cross-sections rolled first:
    (report, failure), ``failure`` None when the step converged, the RodDivergedError
    when it diverged (report None), else a sentence saying how far it got. A converged
    state whose linking number is not ``expected_link`` (turns, link.py) is a failure.
    ``stop()`` (collective), if given, is asked after every iteration whether to stop
    (the report's reason is then STOP_OBSERVER, the failure "interrupted"). ``t_from``:
    the load factor of the state it starts from (the last accepted; None: t's, nothing
    walked), whose end frames the twist's relaxation walks from (RodProblem.relax_twist)."""
    problem = solver.problem
    # the twist of round sections spread before the first Newton attempt may be made
    problem.relax_twist(t if t_from is None else t_from, t, NEWTON_AFTER)
    problem.state.roll_cross_sections(imperfection)
    observer = None if stop is None else (lambda iteration, change, residual: stop())
    try:
        report = solver.solve_step(t, label=label, observer=observer)
    except RodDivergedError as error:
        return None, error
    if report.reason == STOP_OBSERVER:
        return report, "interrupted"
    if report.converged:
        report = replace(report, link=problem.link(), link_expected=expected_link)
        if not changed_class(report.link, expected_link):
            return report, None
        report = replace(report, converged=False, reason=STOP_LINK)
        return report, (f"converged in {report.iterations} iterations to a linking number "
                        f"of {sum(report.link):.3f} turns, not {expected_link:.3f}")
    return report, (f"not converged in {report.iterations} iterations (change "
                    f"{report.change:.2e}, constraint residual (RMS) "
                    f"{report.constraint_residual:.2e})")


def continuation(solver, path=PathSettings(), stop=None):
    """Reach load factor ``path.end`` in ``path.steps`` equal increments from
    ``path.start`` (0, or a restart's), each warm-started (§7) from the last state with
    its cross-sections rolled by ``path.imperfection`` (RodState.roll_cross_sections)
    and tau, lambda extrapolated (Predictor). A step that does not converge or diverges
    is undone (RodState.snapshot/restore) and retried with half the increment, at most
    ``path.max_halvings`` times on the way to each t_k (LoadPath); so is a step that
    converged to another linking number (link.py) when ``path.track_link``. ``stop()``
    (collective), if given, is asked after every iteration and after the last step:
    True ends the run.

    The one loop of the project: the command line, the scripts and the tests all walk
    it (cli/session.py). Yields the events of events.py: RunStarted; per attempt the
    step's own (SaddleLeft, PenaltyRaised, NewtonAttempt), then StepHalved or StepEnded
    (the problem's state is the step's while it is handled); then one of RunFinished,
    RunDiverged or Interrupted.
    """
    problem = solver.problem
    state, mesh = problem.state, problem.mesh
    clock = time.perf_counter()
    settings, track_link = path, path.track_link
    path = LoadPath(settings.steps, settings.max_halvings, settings.start, settings.end)
    yield events.RunStarted(mesh.n_elements, mesh.comm.getSize(), solver.settings.asked_penalty,
                            path.steps, settings.start)
    predictor = Predictor()
    predictor.accept(settings.start, state)
    total, undone, written = 0, 0, 0
    # (Tw, Wr) of the last accepted state (of the start, then of each step), or None
    link = problem.link() if track_link else None
    while not path.finished:
        t, label = path.next_factor, f"step {path.step}/{path.steps}"
        saved = state.snapshot()
        predictor.predict(state, t)
        report, failure = attempt(solver, t, settings.imperfection, f"{label} ",
                                  expected_link(problem.scene, link, path.factor(path.reached), t),
                                  stop, path.factor(path.reached))
        if failure == "interrupted":
            yield events.Interrupted(f"in {label} at load factor {t:.6g}, iteration "
                                     f"{report.iterations}", path.factor(path.reached))
            return
        if report is not None:
            yield from report.events         # what happened within the attempt
        iterations = (failure.iterations or 0) if report is None else report.iterations
        total += iterations
        # a stalled step is not halved: a smaller step does not move what stops it
        stalled = report is not None and report.stalled
        if failure is not None and path.can_halve and not stalled:
            state.restore(saved)
            path.halve()
            undone += iterations
            yield events.StepHalved(label, t, failure, path.halvings, path.factor(path.reached),
                                    path.factor(path.increment) - path.factor(0))
            continue
        if report is None:
            yield events.RunDiverged(failure, path.next_factor, path.halvings,
                                     path.nothing_to_halve)
            return
        written += 1
        yield events.StepEnded(label, t, report, written, path.step_halvings, path.halvings,
                               total, undone, time.perf_counter() - clock)
        if not report.converged:
            break
        path.accept()
        predictor.accept(t, state)
        problem.accept_step()
        link = report.link if track_link else None
    if stop is not None and stop():
        yield events.Interrupted("after the last step", path.factor(path.reached))
        return
    yield events.RunFinished(report.converged, label, report, total, undone, path.halvings,
                             time.perf_counter() - clock, path.next_factor,
                             not report.converged and path.nothing_to_halve)


def expected_link(scene, link, t_from, t):
    """The linking number (turns) a step from load factor t_from to t should reach: that of
    the state it starts from, (Tw, Wr) ``link``, plus the end roll over the step over 2 pi
    (link.py); None when that link is not known (not tracked)."""
    if link is None:
        return None
    return sum(link) + (scene.end_roll(t) - scene.end_roll(t_from)) / (2 * np.pi)
