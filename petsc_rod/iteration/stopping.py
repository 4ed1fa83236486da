"""When a step of the iteration ends (docs/method.md §6): what the user asks of the
iteration (Settings), the stopping tests, the divergence and stall rules, and the report
of a finished step.

Every rule here reads the step's history of (change, constraint residual, wall time)
rows, one per iteration, and returns a verdict; the step controller (controller.py)
turns them into its decisions, and nothing here touches the solver's state.
"""

from dataclasses import dataclass, field

import numpy as np

# An RMS constraint residual this large means the directors are no longer near unit
# vectors: the iteration has left every meaningful state.
DIVERGED_RESIDUAL = 1e3

# Reasons a step that did not converge gives (StepReport.reason); a SNES that stops on
# its own test gives "snes_<its reason>".
STOP_MAX_IT = "max_it"
STOP_STALLED = "stalled"
STOP_OBSERVER = "observer"      # the caller's observer asked to stop
STOP_LINK = "link"              # converged, to a state of another linking number (link.py)
STOP_SADDLE = "saddle"          # converged to a saddle, and left it too often
STOP_UNTESTED = "untested"      # converged, the stability test's factorisation failed

# The stall test looks at windows of STALL_WINDOW iterations (stalled_projection), and
# only once both stopping quantities are within STALL_FACTOR of their tolerances: an
# iterate still far away, e.g. leaving an unstable branch, may see them grow for a while
# and is not stalled. A rate that would need more than STALL_MARGIN times the remaining
# budget is a stall. The test runs every STALL_CHECK_EVERY iterations, out of the way of
# most of them.
STALL_WINDOW = 1000
STALL_FACTOR = 10.0
STALL_MARGIN = 10.0
STALL_CHECK_EVERY = STALL_WINDOW // 10


@dataclass
class Settings:
    """What the user asks of the iteration (docs/method.md §6). The defaults here are
    the command line's (cli/options.py reads them from this class)."""

    asked_penalty: float            # R asked for, N (penalty.default_penalty by default)
    max_it: int = 2000
    rtol: float = 1e-9
    ctol: float = 1e-9
    monitor: bool = False
    adapt_penalty: bool = True      # raise a penalty far below its ceiling (penalty.py)
    check_stability: bool = True    # test the second variation at convergence (§10)
    newton: bool = True             # Newton steps near a solution (newton.py)


@dataclass
class StepReport:
    """What a finished step reports (UzawaSolver.solve_step, controller.report)."""

    converged: bool
    iterations: int
    change: float           # the last iteration's change, over the deformation (state.Norms)
    constraint_residual: float
    history: list = field(default_factory=list)   # (change, residual, wall time) rows
    reason: str = ""        # why a step that did not converge stopped (STOP_* above)
    penalty_raises: list = field(default_factory=list)  # (iteration, new R) rows
    link: tuple = None          # (Tw, Wr) after the step, turns (UzawaSolver.link)
    link_expected: float = None     # the Lk the load path leads to, turns (continuation)
    stable: bool = None     # the second variation is positive (§10); None: unchecked
    escapes: int = 0        # saddles the step converged to and left
    newton_steps: int = 0   # of the iterations, Newton steps on the reduced problem
    events: tuple = ()      # what happened in the step (events.py: SaddleLeft, ...)

    @property
    def stalled(self):
        return self.reason == STOP_STALLED


def remaining_iterations(history, rtol, ctol, window=10):
    """Iterations the step would still need at its recent rate, estimated from the rows
    of ``history``: with q = max(change / rtol, residual / ctol) (above 1 until both
    tests hold), the smallest q of the last 3 rows against that of the 3 rows ``window``
    iterations earlier gives a rate rho per iteration, and log(q) / -log(rho) iterations
    remain. inf when there are too few rows or q did not fall (the accelerated iteration
    is not monotone: the minima of short runs of rows smooth it).
    """
    if len(history) < window + 3:
        return np.inf
    with np.errstate(divide="ignore", invalid="ignore"):      # a tolerance of 0: inf
        distance = [max(np.float64(change) / rtol, np.float64(residual) / ctol)
                    for change, residual, _ in history[-window - 3:]]
    now = min(distance[-3:])
    before = min(distance[:3])
    if now <= 1.0:
        return 0.0
    if now >= before:
        return np.inf
    return np.log(now) / (np.log(before / now) / window)


def diverged(change, residual):
    """A non-finite norm, or directors far from unit vectors."""
    return not (np.isfinite(change) and np.isfinite(residual)) or residual > DIVERGED_RESIDUAL


def converged(settings, change, residual):
    """Both stopping tests of §6: change <= rtol and RMS constraint residual <= ctol."""
    return change <= settings.rtol and residual <= settings.ctol


def stalled_projection(values, target, budget):
    """Whether ``values`` (one per iteration, newest last), at their rate over the last
    STALL_WINDOW iterations, would need more than STALL_MARGIN times ``budget`` further
    iterations to fall to ``target``.

    The rate compares the smallest value of the last window with that of the window
    before (both quantities oscillate from one iteration to the next): if it falls by a
    factor q per window, reaching the target takes log(target / v_min) / log(q) windows.
    No progress at all counts only when it lasts two windows (an iterate leaving a nearly
    symmetric state can mark time for a while and then go on).
    """
    if len(values) < 3 * STALL_WINDOW:
        return False
    oldest, before, recent = (min(values[-k * STALL_WINDOW:len(values) - (k - 1) * STALL_WINDOW])
                              for k in (3, 2, 1))
    if recent <= target:
        return False
    if recent >= before:
        return before >= oldest           # no progress over two windows in a row
    windows = np.log(target / recent) / np.log(recent / before)
    return windows * STALL_WINDOW > STALL_MARGIN * budget


def stalled(history, rtol, ctol, budget):
    """Whether a step whose change and residual are within STALL_FACTOR of their
    tolerances (or whose change is below rtol: the iterate no longer moves, e.g. held by
    a symmetry in a state that cannot meet the constraint) would not reach a tolerance
    within ``budget`` iterations (stalled_projection on each column of ``history``)."""
    change, residual = history[-1][:2]
    if change > STALL_FACTOR * rtol:
        return False
    if residual > STALL_FACTOR * ctol and change > rtol:
        return False
    window = history[-3 * STALL_WINDOW:]
    return any(stalled_projection([row[column] for row in window], tolerance, budget)
               for column, tolerance in ((0, rtol), (1, ctol)))


def stall_reason(settings, history, deformation=1.0):
    """STOP_STALLED every STALL_CHECK_EVERY iterations if ``stalled``, or STOP_MAX_IT at
    the cap, else None. ``history`` holds the undivided change and residual, so the
    targets are the stopping test's tolerances times the deformation's relative size
    (state.Norms): a step stuck above them, below rtol and ctol, is a stall too."""
    iteration = len(history)
    if iteration >= settings.max_it:
        return STOP_MAX_IT
    if iteration % STALL_CHECK_EVERY == 0 and stalled(
            history, settings.rtol * deformation, settings.ctol * deformation,
            settings.max_it - iteration):
        return STOP_STALLED
    return None
