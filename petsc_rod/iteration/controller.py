"""The step controller: what one continuation step does next after each iteration, as a
small state machine with a typed decision (docs/design.md, "One step").

The solver (driver.py) hands every iteration's (change, residual) to ``observe``, which
decides at once (a SNES may evaluate the map more than once per convergence test:
ngmres, qn); the SNES's convergence test only reads whether the decision ends the solve.
A Decision is one of

    ITERATE        go on with the SNES
    CONVERGED      both stopping tests hold (§6)
    TRY_NEWTON     near a solution and still slow: Newton steps (§11), then the SNES again
                   (or CONVERGED at the attempt: newton_converged)
    RAISE_PENALTY  R far below its ceiling, the residual not falling: refactor
    STOP           not converged, with a reason (stopping.STOP_* or "snes_<reason>")
    DIVERGED       the iteration diverged; ``error`` holds the RodDivergedError

The controller owns the step's record (its rows, penalty raises, Newton steps, escapes,
and the events of events.py that say them), the Newton schedule (when an attempt may be
made again, whether a Newton solution needs a larger penalty), and the budgets of the
escapes from saddles (§10). It reads values and returns decisions; it touches no PETSc
object and no state: the solver acts.
"""

import enum
import time
from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodDivergedError, RodIterationDiverged
from petsc_rod.iteration import events, stopping
from petsc_rod.problem.penalty import ADAPT_WINDOW, penalty_too_low

# The iteration hands over to Newton steps on the reduced problem (newton.py) once a
# step has taken NEWTON_AFTER iterations and change and residual are both below
# NEWTON_SWITCH: near a solution, where the accelerated iteration is slow.
NEWTON_AFTER = 15
NEWTON_SWITCH = 0.1
# Where the Newton system reads what the whole line beyond a node does (the heights a
# seabed reads, the drag's resultants: docs/method.md §11), an iterate at 0.1 is
# metres off in height or in the resultant and every attempt finds H indefinite; each
# attempt restarts Anderson's history, so that their restarts can keep a step from
# converging. There the switch is at NEWTON_SWITCH_FAR (docs/method.md §11).
NEWTON_SWITCH_FAR = 1e-2
# An attempt costs as much as tens of iterations (a sparse LDL^T factorisation per Newton
# step: docs/performance.md): it is made only while the iteration would still need more
# than NEWTON_WORTH iterations at its recent rate. After each attempt that did not
# converge the wait doubles (an attempt restarts the accelerated iteration). Not where
# the switch is NEWTON_SWITCH_FAR (a seabed, a current): there the rate keeps falling
# (the grounded span's slow modes) and the estimate at the recent rate is no guide
# (docs/method.md §11).
NEWTON_WORTH = 30
# A state where Newton finds negative curvature is left at once (not first converged to)
# when change and residual are below EARLY_ESCAPE: near an equilibrium, so a saddle.
EARLY_ESCAPE = 1e-2
# A step that converged to a saddle goes on from its frames turned along the direction
# of negative curvature, the largest node turned by ESCAPE_ANGLE rad, the angle times
# ESCAPE_GROWTH and of the other sign at each further saddle, at most MAX_ESCAPES times
# (the turn must leave the saddle's basin of the accelerated iteration, §10); the early
# escapes have a budget of their own of the same size.
ESCAPE_ANGLE = 0.3
MAX_ESCAPES = 5
ESCAPE_GROWTH = 2.0
# A Newton solution the Uzawa map cannot hold at the current penalty
# (newton.least_penalty) raises it to NEWTON_RAISE times the least that can.
NEWTON_RAISE = 2.0


class Action(enum.Enum):
    ITERATE = "iterate"
    CONVERGED = "converged"
    TRY_NEWTON = "try_newton"
    RAISE_PENALTY = "raise_penalty"
    STOP = "stop"
    DIVERGED = "diverged"


@dataclass(frozen=True)
class Decision:
    action: Action
    reason: str = ""            # why a STOP stopped

    @property
    def ends_solve(self):
        """Whether the SNES solve ends here (every action but ITERATE)."""
        return self.action is not Action.ITERATE


ITERATE = Decision(Action.ITERATE)


class StepController:
    """One step's state machine (module docstring). ``settings`` (stopping.Settings),
    ``ceiling`` that of R's raises (N; RodProblem.adapt_ceiling), ``newton``
    whether Newton steps may be tried (True, or the switch's threshold in place of
    NEWTON_SWITCH),
    ``label`` the step's name in messages, ``observer(iteration, change, residual)``
    asked after every iteration (True: stop, STOP_OBSERVER), with change and residual
    divided by the deformation's size, as the stopping test reads them."""

    def __init__(self, settings, ceiling, newton, label="", observer=None):
        self.settings, self.ceiling, self.newton = settings, ceiling, bool(newton)
        self.newton_switch = NEWTON_SWITCH if newton is True else float(newton or 0.0)
        # a far-reaching Newton system (NEWTON_SWITCH_FAR): no NEWTON_WORTH test
        self.newton_far = self.newton and newton is not True
        self.label, self.observer = label, observer
        self.clock = time.perf_counter()
        self.history = []           # (change, residual, wall time) rows, one per iteration
        # the relative size of the deformation at the last Uzawa iteration (state.Norms):
        # the stopping test divides change and residual by it
        self.deformation = 1.0
        self.raises = []            # (iteration, new R)
        self.decision = None        # the last one, None before any and after resume()
        self.error = None           # the RodDivergedError that ended the step
        self.stable = None          # a local minimiser (stability.py); None: not checked
        self.escapes = 0            # saddles converged to and left
        self.early_escapes = 0      # saddles left before converging to them
        self.newton_steps = 0       # Newton steps taken, counted in history
        self.newton_failures = 0    # attempts that did not converge
        self.newton_next = NEWTON_AFTER     # the iteration from which Newton may be tried
        # the iteration at which Newton converged with H positive definite on the
        # constraint set (the stability test's own criterion)
        self.newton_verified = None
        self.events = []            # what happened in the step (events.py), in order

    # --- what happened --------------------------------------------------------------
    def _record(self, change, residual):
        self.history.append((change, residual, time.perf_counter() - self.clock))

    def observe(self, change, residual, penalty, deformation=1.0):
        """A Uzawa iteration's norms at penalty R (N) and the relative size of the
        deformation (RodState.norms): recorded, and the Decision after it taken (and
        returned). Only the stopping test (and the report) divides change and residual
        by the deformation; the rules that steer the iteration read them as they are,
        so that a deformation of order one is iterated as without it."""
        self._record(change, residual)
        self.deformation = deformation
        self.decision = self._decide(penalty)
        return self.decision

    def record_newton_step(self, turn):
        """A Newton step, recorded as an iteration (change: its largest turn, rad)."""
        self._record(turn, 0.0)
        self.newton_steps += 1

    def fail(self, error):
        """The iteration itself failed (a RodDivergedError: a linear solver failed)."""
        iteration = len(self.history) + 1
        self.error = RodDivergedError(f"{self.label}iteration {iteration}: {error}", iteration)
        self.decision = Decision(Action.DIVERGED)

    def raised(self, penalty, reason):
        """The solver refactored at penalty R (N), for ``reason`` (events.PenaltyRaised)."""
        self.raises.append((len(self.history), penalty))
        self.events.append(events.PenaltyRaised(self.label, len(self.history), penalty, reason))

    # --- the decision ---------------------------------------------------------------
    @property
    def current(self):
        """The last decision, ITERATE before any and after ``resume``."""
        return self.decision if self.decision is not None else ITERATE

    def _decide(self, penalty):
        settings, iteration = self.settings, len(self.history)
        change, residual = self.history[-1][:2]
        if stopping.diverged(change, residual):
            self.error = RodIterationDiverged(
                f"{self.label}iteration {iteration}: the iteration diverged (change "
                f"{change:.3g}, constraint residual {residual:.3g})", iteration)
            return Decision(Action.DIVERGED)
        if self.observer is not None and self.observer(iteration, change / self.deformation,
                                                       residual / self.deformation):
            return Decision(Action.STOP, stopping.STOP_OBSERVER)
        if stopping.converged(settings, change / self.deformation,
                              residual / self.deformation):
            return Decision(Action.CONVERGED)
        if (self.newton and iteration >= self.newton_next
                and max(change, residual) <= self.newton_switch
                and (self.newton_far or stopping.remaining_iterations(
                    self.history, settings.rtol, settings.ctol) > NEWTON_WORTH)):
            return Decision(Action.TRY_NEWTON)
        if (settings.adapt_penalty and iteration % ADAPT_WINDOW == 0
                and penalty_too_low(self.history, penalty, self.ceiling)):
            return Decision(Action.RAISE_PENALTY)
        stop = stopping.stall_reason(settings, self.history, self.deformation)
        return ITERATE if stop is None else Decision(Action.STOP, stop)

    def stop(self, reason):
        """End the step not converged, for ``reason``."""
        self.decision = Decision(Action.STOP, reason)

    def resume(self):
        """The solver acted on the last decision (a Newton attempt, a raise, an escape):
        the step goes on."""
        self.decision = None

    @property
    def finished(self):
        """A decision that ends the SNES solve has been taken."""
        return self.decision is not None and self.decision.ends_solve

    @property
    def converged(self):
        return self.decision is not None and self.decision.action is Action.CONVERGED

    # --- the Newton schedule ----------------------------------------------------------
    def start_iterating(self):
        """The SNES starts (again, after an escape): Newton waits NEWTON_AFTER iterations."""
        self.newton_next = len(self.history) + NEWTON_AFTER

    def wait_for_newton(self):
        """Newton may be tried again NEWTON_AFTER 2^failures iterations from now."""
        self.newton_next = len(self.history) + NEWTON_AFTER * 2**self.newton_failures

    def newton_converged(self, verified, least_penalty, penalty, norms=None):
        """An attempt converged; ``verified``: with H positive definite on the constraint
        set at its last step. ``norms``: the stopping quantities of its last step
        (state.Norms, measured as §6 measures an iteration: the change of X from the
        state before it, the residual of the constraints, exact to round-off at a
        Newton state) where its steps converged on the whole problem
        (newton.NewtonSolver.solved_norms), None where it met the round-off floor. With
        them the last step's row holds them, the observer is asked, and the step
        converges there, in Newton's terms, where they pass the stopping test: the
        state is Newton's solution, not iterated again (docs/method.md §11,
        "Convergence in Newton's terms"). Returns the penalty to raise R (N) to when
        the handed-over state needs at least ``least_penalty`` to stay a fixed point,
        else None."""
        self.events.append(events.NewtonAttempt(self.label, len(self.history), "converged"))
        if verified:
            self.newton_verified = len(self.history)
        if norms is not None:
            self.history[-1] = (norms.change, norms.residual, self.history[-1][2])
            self.deformation = norms.scale
            change, residual = norms.change / norms.scale, norms.residual / norms.scale
            if self.observer is not None and self.observer(len(self.history), change,
                                                           residual):
                self.decision = Decision(Action.STOP, stopping.STOP_OBSERVER)
            elif stopping.converged(self.settings, change, residual):
                self.decision = Decision(Action.CONVERGED)
        return NEWTON_RAISE * least_penalty if least_penalty >= penalty else None

    def newton_failed(self, outcome):
        """An attempt did not converge (``outcome``: newton.INDEFINITE or FAILED)."""
        self.events.append(events.NewtonAttempt(self.label, len(self.history), outcome))
        self.newton_failures += 1
        if self.newton_switch < NEWTON_SWITCH:
            # the far-reaching systems (NEWTON_SWITCH_FAR): an iterate where the attempt
            # failed was too far for it; the next waits for one ten times nearer
            self.newton_switch /= 10

    def stability_tested(self, stable):
        """The stability test's verdict on the converged state (True, False, None)."""
        self.stable = stable

    @property
    def verified_by_newton(self):
        """Newton's last factorisation showed the state stable: the step converged at
        its attempt, or at the iteration after it."""
        return self.newton_verified is not None and \
            len(self.history) - self.newton_verified in (0, 1)

    def wants_early_escape(self):
        """After an attempt that found negative curvature: whether the state is near
        enough an equilibrium (EARLY_ESCAPE) to be taken for a saddle and left now, with
        the early escapes' budget not spent."""
        if self.newton_far and self.newton_failures < 2:
            # a far-reaching system (a seabed, a current): one attempt's H is that of
            # an iterate metres off in height, indefinite where the iteration may go on
            # to a minimiser by itself; a second, at an iterate ten times nearer, says
            # that it lingers by a saddle (docs/method.md §10)
            return False
        change, residual = self.history[-1][:2] if self.history else (np.inf, np.inf)
        return max(change, residual) <= EARLY_ESCAPE and self.early_escapes < MAX_ESCAPES

    # --- escapes from saddles ---------------------------------------------------------
    def escape_angle(self, early=False):
        """The angle (rad) of the next escape, ESCAPE_ANGLE ESCAPE_GROWTH^k (-1)^k at the
        k-th escape of the step (early or not), counted as taken; None when its budget
        (MAX_ESCAPES each) is spent."""
        if (self.early_escapes if early else self.escapes) == MAX_ESCAPES:
            return None
        k = self.escapes + self.early_escapes
        if early:
            self.early_escapes += 1
            # a new start: the turned state is given the wait after one failure
            self.newton_failures = 1
        else:
            self.escapes += 1
        angle = ESCAPE_ANGLE * ESCAPE_GROWTH**k * (-1) ** k
        self.events.append(events.SaddleLeft(self.label, len(self.history), angle, early))
        return angle

    # --- the end ----------------------------------------------------------------------
    def report(self):
        """The StepReport of the finished step."""
        decision = self.decision
        converged = decision.action is Action.CONVERGED
        change, residual = self.history[-1][:2] if self.history else (np.inf, np.inf)
        # as the stopping test reads them
        change, residual = change / self.deformation, residual / self.deformation
        return stopping.StepReport(converged, len(self.history), change, residual,
                                   self.history, "" if converged else decision.reason,
                                   self.raises, stable=self.stable,
                                   escapes=self.escapes + self.early_escapes,
                                   newton_steps=self.newton_steps, events=tuple(self.events))
