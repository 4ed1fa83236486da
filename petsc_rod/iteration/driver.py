"""The augmented-Lagrangian (Uzawa, ALG2) iteration of docs/method.md §3, driven by a
PETSc SNES (§6), handing over to Newton steps near a solution (§11, newton.py), with the
stability test of §10 at each converged step.

One iteration: the global step (global_step/), the local step at every node
(local_step/projection.py), the multiplier update. The SNES sees the iteration as the
fixed-point problem F(x) = x - G(x) on x = sqrt(w) (tau, lambda / R) at the nodes; the
step's own tests (stopping.py) decide when it ends.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.link import FULLER_MARGIN, link_integrands
from petsc_rod.analysis.stability import SecondVariation
from petsc_rod.errors import RodDivergedError, RodInputError
from petsc_rod.frames import split_coefficients, strains
from petsc_rod.global_step.global_step import GlobalStep
from petsc_rod.iteration import penalty as penalty_policy
from petsc_rod.iteration import stopping
from petsc_rod.iteration import newton
from petsc_rod.iteration.state import RodState
from petsc_rod.local_step.projection import nearest_rotation, update_multipliers
from petsc_rod.mesh.elements import quadrature_weights
from petsc_rod.petsc_defaults import set_from_options_with_defaults
from petsc_rod.resources import anderson_depth, ranks_on_this_machine

EVENTS = {name: PETSc.Log.Event(f"rod_{name}") for name in ("projection", "multiplier", "norms")}

# The SNES type of the iteration unless -rod_snes_type says otherwise.
DEFAULT_SNES = "anderson"
SNES_REASONS = {getattr(PETSc.SNES.ConvergedReason, name): name.lower()
                for name in dir(PETSc.SNES.ConvergedReason) if not name.startswith("_")}

# A step that converged to a saddle goes on from its frames turned along the direction
# of negative curvature, the largest node turned by ESCAPE_ANGLE rad, the angle times
# ESCAPE_GROWTH and of the other sign at each further saddle, at most MAX_ESCAPES times
# (the turn must leave the saddle's basin of the accelerated iteration, §10).
ESCAPE_ANGLE = 0.3
MAX_ESCAPES = 5
ESCAPE_GROWTH = 2.0
# The iteration hands over to Newton steps on the reduced problem (newton.py) once a
# step has taken NEWTON_AFTER iterations and change and residual are both below
# NEWTON_SWITCH: near a solution, where the accelerated iteration is slow.
NEWTON_AFTER = 15
NEWTON_SWITCH = 0.1
# An attempt costs as much as tens of iterations (a sparse LDL^T factorisation per Newton
# step: docs/performance.md): it is made only while the iteration would still need more
# than NEWTON_WORTH iterations at its recent rate.
NEWTON_WORTH = 30
# After each attempt that did not converge the wait doubles (an attempt restarts the
# accelerated iteration). A Newton solution the Uzawa map cannot hold at the current
# penalty (newton.least_penalty) raises it to NEWTON_RAISE times the least that can.
NEWTON_RAISE = 2.0
# A state where Newton finds negative curvature is left at once (not first converged to)
# when change and residual are below EARLY_ESCAPE: near an equilibrium, so a saddle.
EARLY_ESCAPE = 1e-2


def check_anderson_depth():
    """Refuse a -rod_snes_anderson_m that is not a whole number of at least 1 (PETSc
    itself fails on it with a stack of messages)."""
    database = PETSc.Options()
    if database.hasName("rod_snes_anderson_m"):
        depth = database.getString("rod_snes_anderson_m", "")
        if not depth.isdigit() or int(depth) < 1:
            raise RodInputError(f"-rod_snes_anderson_m {depth}: the depth of Anderson "
                                "mixing is a whole number of at least 1")


def default_anderson_depth(mesh):
    """The depth of Anderson mixing unless -rod_snes_anderson_m says otherwise: the
    smallest over the ranks of resources.anderson_depth. Collective."""
    here = ranks_on_this_machine(mesh.comm)
    return int(mesh.global_min(anderson_depth(mesh.n_local_elements, here)))


class UzawaSolver:
    """The iteration on one mesh and scene: a RodState, a GlobalStep and the SNES that
    drives them. Owns every PETSc object of the solve; ``destroy()`` releases them."""

    def __init__(self, mesh, scene, settings):
        check_anderson_depth()          # before any PETSc object is made
        self.mesh, self.scene, self.settings = mesh, scene, settings
        self.split = split_coefficients(scene.stiffness)
        self.scale = penalty_policy.default_penalty(scene)
        self.state = RodState(mesh)
        self.global_step = GlobalStep(mesh, scene, self.split,
                                      penalty_policy.matrix_split(self.split),
                                      float(settings.asked_penalty))
        self.weights = quadrature_weights(mesh.element_h)
        self._root_weights = np.sqrt(self.state.node_weights)[:, None, None]
        self._step = None
        self._second_variation = None
        self._create_snes()
        self.newton = newton.NewtonPolish(self) if self.uses_newton else None

    @property
    def penalty(self):
        """The penalty R in use, N: the one asked for, or larger after a raise."""
        return self.global_step.penalty

    def _create_snes(self):
        """The SNES of the fixed-point problem, options -rod_snes_*: Anderson mixing by
        default (the combination of recent iterates of least residual), nrichardson with
        the basic line search for the plain iteration."""
        size = 18 * self.mesh.n_local_nodes
        self._x = PETSc.Vec().createMPI((size, PETSc.DECIDE), comm=self.mesh.comm)
        self._f = self._x.duplicate()
        snes = self.snes = PETSc.SNES().create(comm=self.mesh.comm)
        snes.setOptionsPrefix("rod_")
        snes.setType(DEFAULT_SNES)
        snes.setFunction(self._fixed_point_residual, self._f)
        snes.setConvergenceTest(self._converged)
        # the step's own tests end it (_outcome): SNES's counts must not come first
        snes.setTolerances(max_it=2**30)
        snes.setMaxFunctionEvaluations(2**30)
        defaults = {}
        kind = PETSc.Options().getString("rod_snes_type", DEFAULT_SNES)
        if kind == PETSc.SNES.Type.NRICHARDSON:
            # nrichardson's default line search (secant) is not the plain iteration
            defaults["rod_snes_linesearch_type"] = "basic"
        if kind == PETSc.SNES.Type.ANDERSON:
            defaults["rod_snes_anderson_m"] = str(default_anderson_depth(self.mesh))
        set_from_options_with_defaults(snes, defaults)

    # --- one continuation step ------------------------------------------------------
    def prepare_step(self, t):
        """End conditions and loads at load factor t (GlobalStep.prepare)."""
        self.global_step.prepare(t)

    def solve_step(self, t, label="", observer=None):
        """The iteration at load factor t until both stopping tests hold (stopping.py);
        then, with check_stability, the state is tested (§10) and a saddle is left along
        its negative curvature, up to MAX_ESCAPES times (the report says stable, or the
        step ends not converged with STOP_SADDLE).

        ``observer(iteration, change, residual)``, if given, is called (collectively)
        after each iteration's norms, e.g. to record the state at looser tolerances on
        the way (scripts/error_vs_time.py); if it returns True the step stops there,
        reported as not converged.
        """
        self.prepare_step(t)
        step = self._step = stopping.StepProgress(label, observer)
        try:
            self._iterate(step)
            while step.outcome == stopping.CONVERGED and self.tests_stability:
                if step.newton_verified == len(step.history) - 1:
                    step.stable = True      # Newton's last factorisation, one iteration ago
                    break
                step.stable, direction = self.check_stability()
                if step.stable is not False:
                    break
                if not self._escape(step, direction):
                    step.outcome = (False, stopping.STOP_SADDLE)
                    break
                step.outcome = step.stable = None
                self._iterate(step)
        finally:
            self._step = None
        if step.error is not None:
            raise step.error
        return stopping.StepReport.of(step)

    @property
    def uses_newton(self):
        """Whether the iteration hands over to Newton (newton.py): asked for, and the
        loads have an energy (no seabed or current: they are not part of E)."""
        return self.settings.newton and self.global_step.riser is None

    @property
    def tests_stability(self):
        """Whether converged steps are tested (§10): asked for, and the loads have an
        energy (a current's drag has none, docs/riser.md)."""
        return self.settings.check_stability and self.scene.current is None

    def _iterate(self, step):
        """Run the SNES from the current state until ``step`` has an outcome (a penalty
        raise starts it again from where it is)."""
        step.newton_next = len(step.history) + NEWTON_AFTER
        while True:
            self._pack(self._x)
            self.snes.solve(None, self._x)
            if step.outcome == stopping.TRY_NEWTON:
                step.outcome = None
                self._polish(step)
                step.newton_next = len(step.history) + NEWTON_AFTER * 2**step.newton_failures
                continue
            if step.outcome != stopping.RAISE_PENALTY:
                break
            self._raise_penalty(step, penalty_policy.raised_penalty(self.penalty, self.scale))
            step.outcome = None
        if step.outcome is None and step.error is None:   # the SNES stopped on its own test
            reason = self.snes.getConvergedReason()
            step.outcome = (False, f"snes_{SNES_REASONS.get(reason, reason)}")

    def _raise_penalty(self, step, penalty):
        """Refactor the global step at a larger penalty, recorded in the step's raises."""
        self.global_step.build(penalty)
        step.raises.append((len(step.history), penalty))

    def _escape(self, step, direction, early=False):
        """Turn the frames along ``direction`` (n_nodes, 3), a direction of negative
        curvature, the largest node by ESCAPE_ANGLE ESCAPE_GROWTH^k (-1)^k rad at the
        k-th escape of the step (early or not). Escapes from converged saddles and early
        ones (_polish) have a budget of MAX_ESCAPES each; False, and nothing turned,
        when it is spent."""
        if (step.early_escapes if early else step.escapes) == MAX_ESCAPES:
            return False
        k = step.escapes + step.early_escapes
        angle = ESCAPE_ANGLE * ESCAPE_GROWTH**k * (-1) ** k
        self.state.turn_frames(angle * direction / self.mesh.global_max(
            float(np.linalg.norm(direction, axis=1).max(initial=0.0))))
        if early:
            step.early_escapes += 1
        else:
            step.escapes += 1
        return True

    def _polish(self, step):
        """Newton steps from the current state (newton.py), each recorded as an
        iteration (change: its largest turn, rad; the frames are rotations). Where the
        second variation has a direction of negative curvature the state is near a
        saddle: with the stability test on, it is left now, as at convergence."""
        def record(turn):
            step.record(turn, 0.0)
            step.newton_steps += 1
        outcome = self.newton.run(record)
        if outcome == newton.CONVERGED:
            if self.newton.verified:
                step.newton_verified = len(step.history)
            least = self.newton.least_penalty()
            if least >= self.penalty:
                self._raise_penalty(step, NEWTON_RAISE * least)
            return
        step.newton_failures += 1
        change, residual = step.history[-1][:2] if step.history else (np.inf, np.inf)
        if (outcome != newton.INDEFINITE or not self.tests_stability
                or max(change, residual) > EARLY_ESCAPE or step.early_escapes == MAX_ESCAPES):
            return
        stable, direction = self.check_stability()
        if stable is False and self._escape(step, direction, early=True):
            # a new start: the turned state is given the wait after one failure
            step.newton_failures = 1

    def check_stability(self):
        """(stable, direction) of the current (converged) state (analysis/stability.py):
        True and None for a local minimiser; False and a rotation-vector field
        (n_nodes, 3) along which the energy decreases to second order for a saddle;
        None, None where the test cannot decide (a taut, straight rod)."""
        hessian = self.second_variation()
        if not hessian.decidable:
            return None, None
        direction = hessian.descent_direction()
        return direction is None, direction

    def second_variation(self):
        """The SecondVariation at the current state: one object for the solver's life,
        made at the first call and updated at the next ones, so that its factorisations
        share one symbolic analysis (the stability test and every Newton step)."""
        if self._second_variation is None:
            self._second_variation = SecondVariation(self)
        else:
            self._second_variation.update()
        return self._second_variation

    # --- the SNES's view of the iteration -----------------------------------------------
    def _fixed_point_residual(self, snes, x, f):
        """F(x) = x - G(x), G one iteration (``iterate``) of x = sqrt(w) (tau, lambda / R)
        (sqrt(w): the Euclidean norm of x is the L2 norm of the fields). Records the
        iteration's norms and decides, for _converged, whether the step is over."""
        step = self._step
        if step.finished:
            f.set(0.0)
            return
        self._unpack(x)
        iteration = len(step.history) + 1
        try:
            self.iterate()
        except RodDivergedError as error:
            step.error = RodDivergedError(f"{step.label}iteration {iteration}: {error}",
                                          iteration)
            f.set(0.0)
            return
        EVENTS["norms"].begin()
        change, residual = self.state.norms()
        EVENTS["norms"].end()
        step.record(change, residual)
        step.outcome = self._outcome(step, change, residual)
        if self.settings.monitor:
            PETSc.Sys.Print(f"  {step.label}it {iteration:5d}  change {change:.3e}  "
                            f"constraint {residual:.3e}", comm=self.mesh.comm)
        self._pack(f)
        f.aypx(-1.0, x)

    def _outcome(self, step, change, residual):
        """What the step does after an iteration: None (go on), RAISE_PENALTY, or
        (converged, reason); sets step.error when the iteration diverged."""
        settings, iteration = self.settings, len(step.history)
        if stopping.diverged(change, residual):
            step.error = RodDivergedError(
                f"{step.label}iteration {iteration}: the iteration diverged (change "
                f"{change:.3g}, constraint residual {residual:.3g}); try a larger "
                "-rod_al_penalty or more -rod_steps", iteration)
            return None
        if step.observer is not None and step.observer(iteration, change, residual):
            return (False, stopping.STOP_OBSERVER)
        if stopping.converged(settings, change, residual):
            return stopping.CONVERGED
        if (self.newton is not None and iteration >= step.newton_next
                and max(change, residual) <= NEWTON_SWITCH
                and stopping.remaining_iterations(step.history, settings.rtol,
                                                  settings.ctol) > NEWTON_WORTH):
            return stopping.TRY_NEWTON
        if (settings.adapt_penalty and iteration % penalty_policy.ADAPT_WINDOW == 0
                and penalty_policy.penalty_too_low(step.history, self.penalty, self.scale)):
            return stopping.RAISE_PENALTY
        return stopping.stall_outcome(settings, step.history)

    def _converged(self, snes, its, norms):
        """The SNES convergence test: the decision _fixed_point_residual took."""
        if self._step.finished:
            return PETSc.SNES.ConvergedReason.CONVERGED_ITS
        return PETSc.SNES.ConvergedReason.ITERATING

    def _pack(self, x):
        """x = sqrt(w) (tau, lambda / R), (n_nodes, 2, 3, 3) in the SNES vector."""
        values = x.getArray().reshape(-1, 2, 3, 3)
        np.multiply(self._root_weights, self.state.tau, out=values[:, 0])
        np.multiply(self._root_weights, self.state.lam, out=values[:, 1])
        values[:, 1] /= self.penalty

    def _unpack(self, x):
        values = x.getArray(readonly=True).reshape(-1, 2, 3, 3)
        np.divide(values[:, 0], self._root_weights, out=self.state.tau)
        np.multiply(values[:, 1], self.penalty / self._root_weights, out=self.state.lam)

    def iterate(self):
        """One iteration (docs/method.md §3): global step, local step (nearest rotation of
        R d + lambda at every node), multiplier update lambda += R (d - tau)."""
        state, R = self.state, self.penalty
        self.global_step.solve(state)
        EVENTS["projection"].begin()
        directors = state.take_directors()
        b = np.multiply(directors, R, out=state.tau)       # b = R d + lambda, in place
        b += state.lam
        nearest_rotation(b, out=state.tau)
        EVENTS["projection"].end()
        EVENTS["multiplier"].begin()
        update_multipliers(state.lam, directors, state.tau, R)
        EVENTS["multiplier"].end()

    # --- outputs --------------------------------------------------------------------
    def energy(self):
        """W = int w dS - int f.r dS - end forces . r (§6), J, with the strains u of the
        FE fields at the Gauss points."""
        p = self.state.point_values()
        u = strains(p["directors"], p["derivatives"])
        stored = 0.5 * np.sum(self.weights[:, :, None] * self.scene.stiffness * u**2)
        return self.mesh.global_sum(stored) - self.global_step.load_work(self.state)

    def link(self):
        """Twist and writhe of the current state, (Tw, Wr) in turns, Lk = Tw + Wr
        (analysis/link.py); None when the scene has no common end axis or a tangent comes
        within FULLER_MARGIN of pointing back along it."""
        axis = self.scene.link_axis
        if axis is None:
            return None
        p = self.state.point_values()
        twist, writhe, margin = link_integrands(p["directors"], p["derivatives"], axis)
        tw, wr, backward = self.mesh.global_sum(np.array([
            np.sum(self.weights * twist), np.sum(self.weights * writhe),
            np.sum(margin < FULLER_MARGIN)]))
        return None if backward else (float(tw), float(wr))

    def end_reaction(self):
        """External force N on the rod at S = L, N (GlobalStep.end_reaction)."""
        return self.global_step.end_reaction(self.state)

    def destroy(self):
        self.global_step.destroy()
        self.state.destroy()
        if self.newton is not None:
            self.newton.destroy()
        if self._second_variation is not None:
            self._second_variation.destroy()
        for obj in (self.snes, self._x, self._f):
            obj.destroy()
