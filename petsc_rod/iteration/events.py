"""What a run of the continuation (continuation.py) tells as it goes: one event per thing
that happened, in order. The continuation yields them and never formats or writes;
cli/session.py walks them, with cli/lines.py for the lines a user reads and io/ for the
result file.
"""

from dataclasses import dataclass


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
