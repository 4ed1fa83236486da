"""The continuation (docs/method.md §7): the load path from the start to the scene in
``-rod_steps`` steps, each warm-started from the last converged state, halved when a step
fails, reported one line per step and written one group per step."""

import time
from dataclasses import dataclass, replace

import numpy as np

from petsc_rod.io import outputs
from petsc_rod.errors import RodDivergedError, RodInterrupted, RodNotConvergedError
from petsc_rod.analysis.link import changed_class
from petsc_rod.iteration.penalty import ADAPT_WINDOW
from petsc_rod.iteration.stopping import STOP_LINK, STOP_OBSERVER, STOP_SADDLE
from petsc_rod.riser.quantities import riser_report


def not_converged_reason(report, solver):
    """Why a step stopped without converging, and what to change."""
    settings = solver.settings
    numbers = (f"change {report.change:.2e} for -rod_al_rtol {settings.rtol:.2g}, "
               f"constraint residual {report.constraint_residual:.2e} for -rod_al_ctol "
               f"{settings.ctol:.2g}")
    if report.reason == STOP_LINK:
        tw, wr = report.link
        return (f"converged to a state whose linking number is {tw + wr:.3f} turns (twist "
                f"{tw:.3f} + writhe {wr:.3f}), not the {report.link_expected:.3f} turns the "
                "load path leads to: the clamps fix the end roll only modulo a turn, and the "
                "iteration passed the rod around one of its ends or through itself, which "
                "walls at the clamps forbid (docs/stability.md); take more -rod_steps")
    if report.reason == STOP_SADDLE:
        return (f"converged {report.escapes + 1} times to a saddle, an equilibrium that is not "
                "a minimiser, after turning the frames along its direction of negative "
                "curvature each time: take more -rod_steps, or -rod_imperfection")
    if report.stalled:
        return (f"stalled after {report.iterations} iterations ({numbers}): at their rate they "
                "would not meet the tolerances within -rod_al_max_it: tolerances near round-off "
                "for this mesh and these forces (loosen them), or a slowly contracting "
                "iteration (take more -rod_steps or a larger -rod_al_max_it)")
    hint = ""
    if settings.asked_penalty < 0.1 * solver.scale:
        hint = (f"; -rod_al_penalty {settings.asked_penalty:g} is far below the problem's scale "
                f"{solver.scale:.3g} (the default): raise it")
    return f"did not converge in {report.iterations} iterations ({numbers}){hint}"


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
    def can_halve(self):
        return self.increment > 1

    def halve(self):
        self.increment //= 2
        self.halvings += 1
        self.step_halvings += 1

    def given_up(self):
        """What a run's failure message adds once halvings were tried ('' before)."""
        if not self.halvings:
            return ""
        return (f"; load factor {self.next_factor:.6g} after {self.halvings} halving(s) of "
                "the step (-rod_max_halvings)")

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

    def accept(self, t, solver):
        self.accepted = self.accepted[-1:] + [(t, solver.state.tau.copy(), solver.state.lam.copy())]

    def predict(self, solver, t):
        """Set the solver's tau and lambda for load factor t (its current state must be
        the last accepted one)."""
        if len(self.accepted) < 2:
            return
        (t0, tau0, lam0), (t1, tau1, lam1) = self.accepted
        ratio = (t - t1) / (t1 - t0)
        solver.state.tau[:] = tau1 + ratio * (tau1 - tau0)
        solver.state.lam[:] = lam1 + ratio * (lam1 - lam0)


def attempt(solver, t, imperfection, label, expected_link=None, stop=None):
    """One try at load factor t from the current state, its cross-sections rolled first:
    (report, failure), ``failure`` None when the step converged, the RodDivergedError
    when it diverged (report None), else a sentence saying how far it got (short: the
    run goes on; not_converged_reason is the final one, with its advice). A converged
    state whose linking number is not ``expected_link`` (turns, link.py) is a failure.
    ``stop()`` (collective), if given, is asked after every iteration whether to stop
    (the report's reason is then STOP_OBSERVER)."""
    solver.state.roll_cross_sections(imperfection)
    observer = None if stop is None else (lambda iteration, change, residual: stop())
    try:
        report = solver.solve_step(t, label=label, observer=observer)
    except RodDivergedError as error:
        return None, error
    if report.reason == STOP_OBSERVER:
        return report, "interrupted"
    if report.converged:
        report = replace(report, link=solver.link(), link_expected=expected_link)
        if not changed_class(report.link, expected_link):
            return report, None
        report = replace(report, converged=False, reason=STOP_LINK)
        return report, (f"converged in {report.iterations} iterations to a linking number "
                        f"of {sum(report.link):.3f} turns, not {expected_link:.3f}")
    return report, (f"not converged in {report.iterations} iterations (change "
                    f"{report.change:.2e}, constraint residual (RMS) "
                    f"{report.constraint_residual:.2e})")


# The default of -rod_max_halvings: halvings of the step on the way to each t_k.
MAX_HALVINGS = 4


@dataclass
class ContinuationResult:
    """How a continuation ended: the process exit code (0, or RodNotConvergedError's),
    the last step's report, and the iterations of the whole run."""

    code: int
    report: object
    iterations: int

    @property
    def converged(self):
        return self.code == 0


def continuation(solver, steps, imperfection=0.0, *, writer=None, say=None, options="",
                 max_halvings=MAX_HALVINGS, track_link=True, start=0.0, end=1.0,
                 interrupts=None, on_step=None):
    """Reach load factor ``end`` in ``steps`` equal increments from ``start`` (0, or a
    restart's), each warm-started (§7) from the last state with its cross-sections
    rolled by ``imperfection`` (RodState.roll_cross_sections) and tau, lambda
    extrapolated (Predictor). A step that does not converge or diverges is undone
    (RodState.snapshot/restore) and retried with half the increment, at most
    ``max_halvings`` times on the way to each t_k (LoadPath); so is a step that converged
    to another linking number (link.py) when ``track_link``.

    The one loop of the project: the command line, the scripts and the tests all call
    it. ``writer`` (io.results.ResultWriter or None) gets a group ``steps/<n>`` per
    accepted step and the failed one that ends a run; ``say(line)`` gets the step lines
    (None: silent); ``on_step(t, report)``, if given, is called after each accepted step
    and the failed last one. ``interrupts`` (signals.Interrupts), if given, are asked
    after every iteration and before the file is finished: a signal ends the run with
    RodInterrupted. Returns a ContinuationResult.
    """
    say = say or (lambda line: None)
    mesh = solver.mesh
    clock = time.perf_counter()
    path = LoadPath(steps, max_halvings, start, end)
    stop = None if interrupts is None else interrupts.received
    origin = f" from load factor {start:.6g}" if start > 0 else ""
    penalty = solver.settings.asked_penalty
    say(f"petsc_rod: {mesh.n_elements} elements on {mesh.comm.getSize()} rank(s), "
        f"R = {penalty:g}, {path.steps} step(s){origin}")
    predictor = Predictor()
    predictor.accept(start, solver)
    totals = {"total_iterations": 0, "undone_iterations": 0}
    written = 0
    # (Tw, Wr) of the last accepted state (of the start, then of each step), or None
    link = solver.link() if track_link else None
    while not path.finished:
        t, label = path.next_factor, f"step {path.step}/{path.steps}"
        saved = solver.state.snapshot()
        predictor.predict(solver, t)
        report, failure = attempt(solver, t, imperfection, f"{label} ",
                                  expected_link(solver.scene, link, path.factor(path.reached), t),
                                  stop)
        if failure == "interrupted":
            raise interrupted(interrupts, f"in {label} at load factor {t:.6g}, iteration "
                              f"{report.iterations}", path)
        iterations = (failure.iterations or 0) if report is None else report.iterations
        totals["total_iterations"] += iterations
        # a stalled step is not halved: a smaller step does not move what stops it
        stalled = report is not None and report.stalled
        if failure is not None and path.can_halve and not stalled:
            solver.state.restore(saved)
            path.halve()
            totals["undone_iterations"] += iterations
            reason = str(failure).removeprefix(f"{label} ")   # a divergence names the step
            say(f"petsc_rod: {label} at load factor {t:.6g}: {reason}; halving "
                f"{path.halvings}: retrying from load factor {path.factor(path.reached):.6g} "
                f"with increment {path.factor(path.increment) - path.factor(0):.6g}")
            continue
        if report is None:
            raise RodDivergedError(f"{failure}{path.given_up()}", failure.iterations) from None
        written += 1
        attributes = record_step(solver, report, t, label, say, writer, f"steps/{written}",
                                 wall_time=time.perf_counter() - clock, options=options,
                                 halvings=path.step_halvings, total_halvings=path.halvings,
                                 asked_penalty=penalty, **totals)
        if on_step is not None:
            on_step(t, report)
        if not report.converged:
            break
        path.accept()
        predictor.accept(t, solver)
        link = report.link if track_link else None
    if stop is not None and stop():
        raise interrupted(interrupts, "after the last step", path)
    if writer is not None:
        writer.finish(f"steps/{written}", attributes)
    if not report.converged:
        say(f"petsc_rod: error: {label} {not_converged_reason(report, solver)}"
            f"{path.given_up()}; the result file says converged = 0")
        return ContinuationResult(RodNotConvergedError.exit_code, report,
                                  totals["total_iterations"])
    say(f"petsc_rod: converged, {totals['total_iterations']} iterations in "
        f"{time.perf_counter() - clock:.3g} s, {path.halvings} halving(s) of the step "
        f"({totals['undone_iterations']} iterations undone)")
    return ContinuationResult(0, report, totals["total_iterations"])


def interrupted(interrupts, where, path):
    """The RodInterrupted that ends a run stopped by a signal ``where``."""
    number = interrupts.received()
    return RodInterrupted(f"interrupted by {interrupts.name(number)} {where}; the last "
                          f"converged load factor is {path.factor(path.reached):.6g}; no "
                          "result file is written", number)


def expected_link(scene, link, t_from, t):
    """The linking number (turns) a step from load factor t_from to t should reach: that of
    the state it starts from, (Tw, Wr) ``link``, plus the end roll over the step over 2 pi
    (link.py); None when that link is not known (not tracked)."""
    if link is None:
        return None
    return sum(link) + (scene.end_roll(t) - scene.end_roll(t_from)) / (2 * np.pi)


def stability_code(report):
    """The file's ``stable``: 1 a local minimiser, 0 a saddle, -1 not checked."""
    return -1 if report.stable is None else int(report.stable)


def stability_text(report):
    """The step line's account of which equilibrium was reached (stability.py)."""
    if report.stable is None:
        return ""
    if not report.stable:
        return ", a saddle (the second variation has a negative direction)"
    left = f" after leaving {report.escapes} saddle(s)" if report.escapes else ""
    return f", stable{left} (second variation positive)"


def newton_text(report):
    """The step line's count of Newton steps among the iterations (newton.py)."""
    return f" ({report.newton_steps} Newton)" if report.newton_steps else ""


def link_text(link):
    """The step line's account of the link, '' where it is not tracked."""
    if link is None:
        return ""
    tw, wr = link
    return f", link {tw + wr:.4f} turns = twist {tw:.4f} + writhe {wr:.4f}"


def record_step(solver, report, t, label, say, writer, group, **common):
    """Say the state after a step at load factor t and write it as ``group`` (with the
    attributes ``common`` to the run so far: wall_time, options, halvings and the
    totals); returns the group's attributes."""
    mesh = solver.mesh
    vertex = outputs.vertex_fields(solver, t)
    energy = solver.energy()
    u3_start = mesh.global_sum(vertex["u"][0, 2] if mesh.on_lower_boundary else 0.0)
    attributes = {"converged": int(report.converged),
                  "stop_reason": report.reason or "converged", "iterations": report.iterations,
                  "constraint_residual": report.constraint_residual,
                  "change": report.change, "stable": stability_code(report),
                  "newton_steps": report.newton_steps,
                  "energy": energy, "ranks": mesh.comm.getSize(),
                  "load_factor": t, "penalty": solver.penalty, **common}
    if report.link is not None:
        attributes.update(twist_turns=report.link[0], writhe_turns=report.link[1])
    riser = riser_report(solver, vertex) if solver.global_step.riser is not None else None
    if riser is not None:           # petsc_rod/riser/quantities.py
        vertex.update(riser.datasets)
        attributes.update(riser.attributes)
    say(f"{label}: load factor {t:.4g}, "
        f"{'converged' if report.converged else 'NOT converged'} in {report.iterations} "
        f"iterations{newton_text(report)}, change {report.change:.2e}, constraint residual (RMS) "
        f"{report.constraint_residual:.2e}, energy {energy:.10g} J, u3(0) {u3_start:.6g}"
        + link_text(report.link) + stability_text(report)
        + (f"; {riser.text}" if riser is not None else ""))
    if report.penalty_raises:
        raised = ", ".join(f"{R:.3g} at iteration {i}" for i, R in report.penalty_raises)
        say(f"petsc_rod: {label}: R raised to {raised} (matrices refactored): the "
            f"constraint residual fell by less than half in {ADAPT_WINDOW} iterations with "
            f"R far below the problem's scale {solver.scale:.3g} (-rod_al_adapt_penalty), "
            "or a Newton solution needed a larger R to stay a fixed point (-rod_al_newton)")
    if writer is not None:
        writer.write_step(group, vertex, outputs.restart_state(solver), report.history,
                          attributes)
    return attributes
