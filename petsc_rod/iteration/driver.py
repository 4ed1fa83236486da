"""How the problem is solved: the augmented-Lagrangian (Uzawa, ALG2) iteration of
docs/method.md §3 driven by a PETSc SNES (§6), handing over to Newton steps near a
solution (§11, newton.py), with the stability test of §10 at each converged step.

The problem (problem/problem.py) is the map G, one Uzawa iteration; the SNES sees it as
the fixed-point problem F(x) = x - G(x) on x = sqrt(w) (tau, lambda / R) at the nodes.
The step controller (controller.py) decides after each iteration whether the step goes
on, has converged, tries Newton, raises the penalty or stops; the SNES's convergence
test ends the solve on a decision that says so, and the solver acts on it.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.errors import RodDivergedError
from petsc_rod.iteration import controller as control
from petsc_rod.iteration import events, newton, stopping
from petsc_rod.petsc_defaults import set_from_options_with_defaults
from petsc_rod.problem import penalty as penalty_policy
from petsc_rod.problem.build import lay_friction_anchors
from petsc_rod.problem.problem import RodProblem
from petsc_rod.resources import anderson_depth, ranks_on_this_machine

# The SNES type of the iteration unless -rod_snes_type says otherwise.
DEFAULT_SNES = "anderson"
# The SNES types that can drive the map: they need only the residual F(x) = x - G(x),
# which has no Jacobian; the others (newtonls, ngs, fas, nasm, ...) fail in their first
# solve.
FUNCTION_ONLY_SNES = ("anderson", "nrichardson", "ngmres", "qn", "ncg")
# The types whose work release_work frees: a history of depth m worth its memory. QN's
# reset leaves its LMVM matrix unusable in PETSc 3.18 (a segmentation fault at the next
# solve: tests/system/test_hostile_cli.py), and the others keep little.
RELEASED_SNES = ("anderson", "ngmres")
SNES_REASONS = {getattr(PETSc.SNES.ConvergedReason, name): name.lower()
                for name in dir(PETSc.SNES.ConvergedReason) if not name.startswith("_")}
# -log_view's event of the stability test of a converged step (§10).
STABILITY_EVENT = PETSc.Log.Event("rod_stability")


def default_anderson_depth(mesh):
    """The depth of Anderson mixing unless -rod_snes_anderson_m says otherwise: the
    smallest over the ranks of resources.anderson_depth. Collective."""
    here = ranks_on_this_machine(mesh.comm)
    return int(mesh.global_min(anderson_depth(mesh.n_local_elements, here)))


class UzawaSolver:
    """The iteration on a RodProblem with the user's stopping.Settings: the SNES that
    drives the problem's map, the Newton steps and the stability test of each step.
    ``monitor(label, iteration, change, residual)``, if given, is called after every
    iteration (the command line's -rod_al_monitor prints with it). Owns the SNES, its
    vectors and the Newton steps' work; ``destroy()`` releases them (the problem is its
    creator's to destroy)."""

    def __init__(self, problem, settings, monitor=None):
        self.problem, self.settings, self.monitor = problem, settings, monitor
        self._root_weights = np.sqrt(problem.state.node_weights)[:, None]
        self._controller = None
        self._create_snes()
        self.newton = newton.NewtonSolver(problem) if self.uses_newton else None

    @property
    def penalty(self):
        """The penalty R in use, N: the one asked for, or larger after a raise."""
        return self.problem.penalty

    def _create_snes(self):
        """The SNES of the fixed-point problem, options -rod_snes_*: Anderson mixing by
        default (the combination of recent iterates of least residual), nrichardson with
        the basic line search for the plain iteration."""
        mesh = self.problem.mesh
        size = 18 * mesh.n_local_nodes
        self._x = PETSc.Vec().createMPI((size, PETSc.DECIDE), comm=mesh.comm)
        self._f = self._x.duplicate()
        snes = self.snes = PETSc.SNES().create(comm=mesh.comm)
        snes.setOptionsPrefix("rod_")
        snes.setType(DEFAULT_SNES)
        snes.setFunction(self._fixed_point_residual, self._f)
        snes.setConvergenceTest(self._converged)
        # the step controller ends a solve: SNES's counts must not come first
        snes.setTolerances(max_it=2**30)
        snes.setMaxFunctionEvaluations(2**30)
        defaults = {}
        kind = PETSc.Options().getString("rod_snes_type", DEFAULT_SNES)
        if kind == PETSc.SNES.Type.NRICHARDSON:
            # nrichardson's default line search (secant) is not the plain iteration
            defaults["rod_snes_linesearch_type"] = "basic"
        if kind == PETSc.SNES.Type.ANDERSON:
            defaults["rod_snes_anderson_m"] = str(default_anderson_depth(mesh))
        set_from_options_with_defaults(snes, defaults)

    @property
    def uses_newton(self):
        """Whether the iteration hands over to Newton (newton.py): asked for, and every
        term of the problem is in the Newton steps."""
        return self.settings.newton and self.problem.in_newton

    @property
    def tests_stability(self):
        """Whether converged steps get a stability verdict (§10): asked for, and every
        term has an energy (a current's drag has none, docs/riser.md)."""
        return self.settings.check_stability and self.problem.conservative

    @property
    def checks_curvature(self):
        """Whether converged steps are tested for a negative direction of H and leave it
        (§10): asked for (-rod_al_stability, on by default), whatever the terms. On a
        problem with a term without an energy (a current's drag, seabed friction) H is
        the second variation of the energy of the line and its conservative loads with
        the symmetric part of the other terms' linearisation: H positive definite is no
        stability verdict there (``_verdict``), but a negative direction is a state no
        engineer wants handed back, such as a line compressed into an arch between its
        ends, which a straight start with a stiff penalty can converge to; it is left as
        a conservative line's saddle is, and a step that cannot leave it ends not
        converged (STOP_SADDLE). Only where every term is in the Newton steps (their H
        exact: not a line through the sea surface, a profile's or grid's friction, two
        friction coefficients, whose stiffness H leaves out), and not where seabed
        friction holds some node (its FrictionTerm.holds): the slide's dissipation,
        which H leaves out, can hold a state along H's negative direction.
        Collective."""
        if not self.settings.check_stability:
            return False
        if self.problem.conservative:
            return True
        if not self.problem.in_newton:
            return False
        state = self.problem.state
        return not any(term.holds(state) for term in self.problem.terms)

    def _verdict(self, stable):
        """The step's recorded verdict of a test that found ``stable`` (True, False,
        None): itself on a conservative problem, None (no verdict: the file's stable -1)
        where a term has no energy, whatever the test found."""
        return stable if self.tests_stability else None

    # --- one continuation step ------------------------------------------------------
    def solve_step(self, t, label="", observer=None):
        """The iteration at load factor t until the step controller ends it; a
        converged state is then tested (§10, with check_stability) and a saddle is left
        along its negative curvature, within the controller's budget (the report says
        stable, or the step ends not converged with STOP_SADDLE).

        ``observer(iteration, change, residual)``, if given, is called (collectively)
        after each iteration's norms, e.g. to record the state at looser tolerances on
        the way (scripts/error_vs_time.py); if it returns True the step stops there,
        reported as not converged. Returns a stopping.StepReport; raises the
        RodDivergedError of a step that diverged.
        """
        self.problem.prepare(t)
        step = self._controller = control.StepController(
            self.settings, self.problem.adapt_ceiling, self._newton_switch(), label,
            observer)
        try:
            self._iterate(step)
            while step.converged and self.checks_curvature:
                if step.verified_by_newton:
                    # Newton's last factorisation, at the attempt the step ended at or
                    # one iteration before, showed it stable
                    step.stability_tested(self._verdict(True))
                    break
                # the iteration's work is not needed while H is factored: its memory
                # goes to the factorisation (the next solve sets the SNES up again)
                self.release_work()
                try:
                    stable, direction = self.check_stability()
                except np.linalg.LinAlgError:
                    # H - sigma M singular to round-off at a shift of the test: no
                    # verdict, a failed attempt of the step (the continuation halves it);
                    # where a term has no energy (no verdict to give) the step stays
                    # converged, its curvature unchecked
                    if self.tests_stability:
                        step.stop(stopping.STOP_UNTESTED)
                    break
                step.stability_tested(self._verdict(stable))
                if stable is not False:
                    break
                angle = step.escape_angle()
                if angle is None:
                    step.stop(stopping.STOP_SADDLE)
                    break
                self._turn(angle, direction)
                step.stability_tested(None)
                step.resume()
                self._iterate(step)
        finally:
            self._controller = None
        if step.error is not None:
            raise step.error
        if step.converged:
            # the member of a symmetric scene's family that no partition chooses (§10)
            self.problem.turn_to_canonical()
        return step.report()

    def _iterate(self, step):
        """Run the SNES from the current state until the controller ends the step (a
        Newton attempt or a penalty raise starts it again from where it is)."""
        step.start_iterating()
        while True:
            self._pack(self._x)
            self.snes.solve(None, self._x)
            decision = step.current
            if not decision.ends_solve:         # the SNES's own stop
                reason = self.snes.getConvergedReason()
                step.stop(f"snes_{SNES_REASONS.get(reason, reason)}")
                return
            if decision.action is control.Action.TRY_NEWTON:
                step.resume()
                # the history is not read by the attempt, and the next solve starts its
                # own: its memory goes to the attempt's factorisations
                self.release_work()
                self._try_newton(step)
                if step.finished:       # converged in Newton's terms, or the observer
                    return
                step.wait_for_newton()
            elif decision.action is control.Action.RAISE_PENALTY:
                step.resume()
                self._raise_penalty(step, penalty_policy.raised_penalty(
                    self.penalty, self.problem.adapt_ceiling), events.RAISED_STALLING)
            else:
                return

    def _raise_penalty(self, step, penalty, reason):
        """Refactor the global step at a larger penalty, recorded by the controller."""
        self.problem.rebuild(penalty)
        step.raised(penalty, reason)

    def _turn(self, angle, direction):
        """Turn the frames along ``direction`` (n_nodes, 3), a direction of negative
        curvature, the largest node by ``angle`` rad (RodState.turn_frames); on an
        extensible line (n_nodes, 4), the stretch moved along its fourth column in
        proportion."""
        problem = self.problem
        largest = problem.mesh.global_max(float(np.linalg.norm(direction[:, :3], axis=1)
                                                .max(initial=0.0)))
        problem.state.turn_frames(angle * direction / largest)

    def _newton_switch(self):
        """False without Newton steps; the controller's switch threshold where the Newton
        system reads the whole line beyond a node (heights, resultants:
        NEWTON_SWITCH_FAR), else True (NEWTON_SWITCH)."""
        if self.newton is None:
            return False
        if self.newton.reads_positions or self.newton.unsymmetric:
            return control.NEWTON_SWITCH_FAR
        return True

    def _try_newton(self, step):
        """Newton steps from the current state (newton.py), each recorded as an
        iteration (change: its largest turn, rad; the frames are rotations). Where the
        second variation has a direction of negative curvature the state is near a
        saddle: with the stability test on, it is left now, as at convergence."""
        outcome = self.newton.run(step.record_newton_step)
        if outcome == newton.CONVERGED:
            raised = step.newton_converged(self.newton.verified, self.newton.least_penalty(),
                                           self.penalty, self.newton.solved_norms)
            if raised is not None:
                self._raise_penalty(step, raised, events.RAISED_NEWTON)
            return
        step.newton_failed(outcome)
        # the test reads the iteration's multipliers, not Newton's -g / w (with a seabed
        # an iterate's -g / w holds its answer to errors of metres in height and makes
        # H indefinite far from any saddle, newton._newton_step): a line with a seabed
        # is left early too (after a second indefinite attempt: wants_early_escape), as
        # a straight start must, whose first steps end the line nearer than its length
        # and buckle it (docs/method.md §10)
        if (outcome != newton.INDEFINITE or not self.checks_curvature
                or not step.wants_early_escape()):
            return
        try:
            stable, direction = self.check_stability()
        except np.linalg.LinAlgError:          # no verdict: the iteration goes on
            return
        if stable is False:
            angle = step.escape_angle(early=True)
            if angle is not None:
                self._turn(angle, direction)

    def release_work(self):
        """Free the SNES's work vectors, Anderson's history among them (2 m + 5 vectors
        of the node state, 576 bytes per element per unit of depth m, and five more:
        docs/performance.md, "Memory for long lines"), until its next solve sets it up
        again. Each solve starts its history empty, so the iterates are the same. Only
        for the RELEASED_SNES types."""
        if self.snes.getType() not in RELEASED_SNES:
            return
        self.snes.reset()
        # SNESReset drops the residual vector with the rest: give it back, so that the
        # next set-up does not make another
        self.snes.setFunction(self._fixed_point_residual, self._f)

    def check_stability(self):
        """(stable, direction) of the current (converged) state: the verdict of the
        stability test (analysis/stability.StabilityTest.verdict), in -log_view's event
        rod_stability."""
        with STABILITY_EVENT:
            return self.problem.second_variation().verdict()

    # --- the SNES's view of the iteration -----------------------------------------------
    def _fixed_point_residual(self, snes, x, f):
        """F(x) = x - G(x), G one iteration of the problem (RodProblem.iterate) on
        x = sqrt(w) (tau, lambda / R) (sqrt(w): the Euclidean norm of x is the L2 norm
        of the fields); the iteration's norms go to the controller. Once the controller
        has ended the solve, or when the iteration fails, F = 0 and nothing is done."""
        step = self._controller
        if step.finished:
            f.set(0.0)
            return
        self._unpack(x)
        try:
            self.problem.iterate()
        except RodDivergedError as error:
            step.fail(error)
            f.set(0.0)
            return
        norms = self.problem.norms()
        step.observe(norms.change, norms.residual, self.penalty, norms.scale)
        if self.monitor is not None:
            self.monitor(step.label, len(step.history), norms.change / norms.scale,
                         norms.residual / norms.scale)
        self._pack(f)
        f.aypx(-1.0, x)

    def _converged(self, snes, its, norms):
        """The SNES convergence test: whether the controller's last decision ends the
        solve."""
        if self._controller.finished:
            return PETSc.SNES.ConvergedReason.CONVERGED_ITS
        return PETSc.SNES.ConvergedReason.ITERATING

    def _pack(self, x):
        """x = sqrt(w) (tau, lambda / R), (n_nodes, 2, 3, 3) in the SNES vector. Each
        node's nine numbers are one row (rows of nine, not of three, in numpy's inner
        loops: the same products, a third less time)."""
        state = self.problem.state
        values = x.getArray().reshape(-1, 2, 9)
        np.multiply(self._root_weights, _rows(state.tau), out=values[:, 0])
        np.multiply(self._root_weights, _rows(state.lam), out=values[:, 1])
        values[:, 1] /= self.penalty

    def _unpack(self, x):
        state = self.problem.state
        values = x.getArray(readonly=True).reshape(-1, 2, 9)
        np.divide(values[:, 0], self._root_weights, out=_rows(state.tau))
        np.multiply(values[:, 1], self.penalty / self._root_weights, out=_rows(state.lam))

    def destroy(self):
        if self.newton is not None:
            self.newton.destroy()
        for obj in (self.snes, self._x, self._f):
            obj.destroy()


def _rows(frames):
    """(n, 3, 3) frames as a view (n, 9), never a copy (setting the shape raises where
    a view cannot be made: an out= into a copy would be lost)."""
    rows = frames.view()
    rows.shape = (frames.shape[0], 9)
    return rows


def solver_for(mesh, scene, settings, say=None):
    """The UzawaSolver of a new RodProblem of ``scene`` on ``mesh`` at the asked penalty
    of ``settings`` (what a script or a test makes), the seabed friction's anchors laid
    as the command line and the API lay them (problem/build.lay_friction_anchors: the
    catenary between the user's ends, for every load step, whatever start the caller
    sets), its line where none can be drawn said by ``say`` (default: printed on
    the mesh's rank 0). The caller destroys both: ``solver.destroy();
    solver.problem.destroy()``. Collective."""
    problem = RodProblem(mesh, scene, settings.asked_penalty)
    try:
        lay_friction_anchors(problem,
                             say or (lambda text: PETSc.Sys.Print(text, comm=mesh.comm)))
        return UzawaSolver(problem, settings)
    except Exception:
        problem.destroy()
        raise
