"""A run of the continuation as the command line makes it: the events of
iteration/continuation.py said as lines (messages.py) and recorded in the result file
(io/outputs.py, io/results.py), with the run's errors raised as RodErrors. The command
line, the scripts and the tests call run_continuation."""

from dataclasses import dataclass

from petsc_rod.cli import messages
from petsc_rod.cli.phases import OUTPUT
from petsc_rod.errors import RodDivergedError, RodInterrupted, RodNotConvergedError
from petsc_rod.io import outputs
from petsc_rod.iteration import events
from petsc_rod.iteration.continuation import PathSettings, continuation
from petsc_rod.problem.penalty import friction_penalty


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


def run_continuation(solver, path=PathSettings(), *, say=None, writer=None, options="",
                     interrupts=None, before_finish=None):
    """Walk continuation(solver, path) (iteration/continuation.py) to its end.

    ``say(line)`` gets the lines (None: silent): a short line per step (lines.step_line),
    its details too (lines.step_details) when the solver's settings ask for the monitor,
    and the final summary (messages.summary) before the last line; ``writer``
    (io.results.ResultWriter or None) a group ``steps/<n>`` per StepEnded, with ``options`` (the options database as
    text) among its attributes, and is finished at the end. ``interrupts``
    (signals.Interrupts), if given, are asked after every iteration and before the file
    is finished: a signal ends the run with RodInterrupted, the steps written so far kept
    as a finished file of their own (ResultWriter.kept_name: converged = 0,
    stop_reason "interrupted", a restart file). A divergence with no halving left raises
    RodDivergedError. ``before_finish(writer)``, if given, is called once a run has
    converged, before the file is finished (the modes: cli/modes.py). Returns a
    ContinuationResult.
    """
    say = say or (lambda line: None)
    verbose = solver.settings.monitor       # -rod_al_monitor: each step's details too
    problem = solver.problem
    stop = None if interrupts is None else interrupts.received
    last = None                 # (group, attributes) of the last step written
    raises = []                 # the PenaltyRaised events of the attempt so far
    for event in continuation(solver, path, stop):
        if isinstance(event, events.RunStarted):
            say(messages.started(event))
            if solver.settings.newton and not problem.in_newton:
                say(messages.no_newton([t for t in problem.terms if not t.in_newton]))
        elif isinstance(event, events.PenaltyRaised):
            raises.append(event)
        elif isinstance(event, events.StepHalved):
            say(messages.halved(event))
            raises = []
        elif isinstance(event, events.StepEnded):
            group = f"steps/{event.number}"
            with OUTPUT:
                record = record_step(
                    problem, event.report, event.t, writer, group,
                    wall_time=event.wall_time, options=options, halvings=event.halvings,
                    total_halvings=event.total_halvings,
                    asked_penalty=solver.settings.asked_penalty,
                    total_iterations=event.total_iterations,
                    undone_iterations=event.undone_iterations)
                say(messages.step_line(event, record))
                if verbose:
                    say(messages.step_details(event, record))
            if raises:
                say(messages.raised(event.label, raises, problem.adapt_ceiling,
                                    problem.adapt_ceiling > problem.scale))
            raises = []
            last = (group, record.attributes)
        elif isinstance(event, events.RunDiverged):
            raise RodDivergedError(messages.diverged_message(event), event.error.iterations)
        elif isinstance(event, events.Interrupted):
            number = interrupts.received()
            kept = None
            if writer is not None and last is not None:     # keep what converged
                kept = writer.kept_name()
                writer.finish(last[0], {**last[1], "converged": 0,
                                        "stop_reason": "interrupted"}, kept)
            raise RodInterrupted(messages.interrupted(interrupts.name(number), event, kept),
                                 number)
        elif isinstance(event, events.RunFinished):
            if before_finish is not None and event.converged and last is not None:
                before_finish(writer)
            with OUTPUT:
                if writer is not None:
                    writer.finish(*last)
                if event.converged and last is not None:
                    for line in messages.summary(last[1]):
                        say(line)
                say(messages.finished(event, solver.settings, problem.scale,
                                      advised_penalty(problem, path)))
            code = 0 if event.converged else RodNotConvergedError.exit_code
            return ContinuationResult(code, event.report, event.iterations)
    raise RuntimeError("the continuation ended without a final event")


def advised_penalty(problem, path):
    """The penalty a run that did not converge is advised (penalty.friction_penalty),
    only where the measured cases were: seabed friction on an extensible line whose
    Newton steps do not finish its run (more than one load step, or a term outside the
    steps). Where one step's Newton steps finish it a stiffer penalty did worse (a short
    pinned line converged at its default and failed at EA / 10), so none there."""
    if problem.in_newton and path.steps <= 1:
        return None
    return friction_penalty(problem.scene)


def record_step(problem, report, t, writer, group, **common):
    """The io.outputs.StepRecord of the problem's state after a step at load factor t
    (``common``: the run's attributes so far), written as ``group`` when ``writer`` is
    not None. Collective."""
    record = outputs.step_record(problem, report, t, **common)
    if writer is not None:
        writer.write_step(group, record.vertex, outputs.restart_state(problem), report.history,
                          record.attributes, record.units)
    return record
