"""What a run of the continuation (continuation.py) tells as it goes: one event per thing
that happened, in order: within an attempt (SaddleLeft, PenaltyRaised, NewtonAttempt,
recorded by the step controller), then the attempt's end (StepHalved or StepEnded), and
the run's. The continuation yields them and never formats or writes;
cli/session.py walks them, with cli/messages.py for the lines a user reads and io/ for the
result file.
"""

from dataclasses import dataclass


# Why the penalty was raised (PenaltyRaised.reason).
RAISED_STALLING = "stalling"    # far below its ceiling, residual not falling (penalty.py)
RAISED_NEWTON = "newton"        # a Newton solution needs a larger R to stay a fixed point


@dataclass(frozen=True)
class SaddleLeft:
    """In a step, at iteration ``iteration``: the frames were turned by ``angle`` rad
    along a direction of negative curvature (§10); ``early``: before the iteration had
    converged to the saddle (a Newton attempt found the negative curvature)."""

    label: str
    iteration: int
    angle: float
    early: bool


@dataclass(frozen=True)
class PenaltyRaised:
    """In a step, at iteration ``iteration``: R raised to ``penalty`` (N), the matrices
    refactored, for ``reason`` (RAISED_STALLING or RAISED_NEWTON)."""

    label: str
    iteration: int
    penalty: float
    reason: str


@dataclass(frozen=True)
class NewtonAttempt:
    """In a step, after iteration ``iteration``: an attempt of Newton steps ended with
    ``outcome`` (newton.CONVERGED, INDEFINITE or FAILED)."""

    label: str
    iteration: int
    outcome: str


@dataclass(frozen=True)
class RunStarted:
    """Before the first step: the mesh, the ranks, the asked penalty R (N), the regular
    steps and the load factor the path starts from."""

    elements: int
    ranks: int
    penalty: float
    steps: int
    start: float


@dataclass(frozen=True)
class StepHalved:
    """An attempt at load factor t failed and is undone (``failure``: how, a sentence, or
    the RodDivergedError of an attempt that diverged); the step is tried again from
    ``retry_from`` with ``increment`` (load factors), the ``halvings``-th halving of the
    run."""

    label: str
    t: float
    failure: object
    halvings: int
    retry_from: float
    increment: float


@dataclass(frozen=True)
class StepEnded:
    """A step ended at load factor t with its stopping.StepReport: accepted (converged)
    or the failed one that ends the run. The problem's state is that step's while the
    event is handled. ``number``: its group number in the file (from 1);
    ``halvings`` of this step and ``total_halvings`` of the run; the run's iterations so
    far (``total_iterations``, ``undone_iterations``) and wall time (s)."""

    label: str
    t: float
    report: object
    number: int
    halvings: int
    total_halvings: int
    total_iterations: int
    undone_iterations: int
    wall_time: float


@dataclass(frozen=True)
class RunDiverged:
    """The run ends: a step diverged (``error``, a RodDivergedError) with no halving
    left; ``load_factor`` of the last attempt after ``halvings`` halvings of the run."""

    error: Exception
    load_factor: float
    halvings: int
    nothing_to_halve: bool = False      # the step could not be halved: it moves no load


@dataclass(frozen=True)
class Interrupted:
    """The run ends: the caller's stop() said so ``where``; ``last_factor`` is the last
    converged load factor."""

    where: str
    last_factor: float


@dataclass(frozen=True)
class RunFinished:
    """The run ends after its last step: converged to the end of the path, or not (the
    last StepEnded says how); its iterations (``undone``: those of halved attempts),
    halvings and wall time (s); ``load_factor`` of the last attempt."""

    converged: bool
    label: str
    report: object
    iterations: int
    undone: int
    halvings: int
    wall_time: float
    load_factor: float
    nothing_to_halve: bool = False      # the last step failed and moves no load to halve
