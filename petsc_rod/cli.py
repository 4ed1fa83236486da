"""Command line: read the -rod_* options, build the scene, run the continuation, write,
report. Returns the process exit code (0 converged, 2 bad input, 3 not converged,
4 diverged)."""

import time

import numpy as np
from petsc4py import PETSc

from . import io, outputs
from .errors import RodDivergedError, RodError, RodInputError, RodNotConvergedError
from .mesh import Mesh
from .options import help_text, read_options, unused_options
from .scene import Scene
from .solver import Settings, UzawaSolver


def scene_from_options(values, given):
    """A validated Scene from parsed option values."""
    load = np.asarray(values["rod_load"])
    if load.size % 3:
        raise RodInputError("-rod_load: give 3 values (fx,fy,fz) per load piece")
    scene = Scene(length=values["rod_length"], stiffness=values["rod_stiffness"],
                  start=values["rod_start"], end=values["rod_end"],
                  end_position=values["rod_end_position"], end_frame=values["rod_end_frame"],
                  end_twist=values["rod_end_twist"], start_force=values["rod_start_force"],
                  end_force=values["rod_end_force"], load_values=load.reshape(-1, 3),
                  load_breaks=values["rod_load_breaks"])
    scene.validate(given)
    return scene


def settings_from_options(values, scene):
    penalty = values["rod_al_penalty"]
    if penalty is None:
        penalty = 400.0 * scene.stiffness.max() / scene.length**2
    return Settings(penalty=penalty, max_it=values["rod_al_max_it"],
                    rtol=values["rod_al_rtol"], ctol=values["rod_al_ctol"],
                    monitor=values["rod_al_monitor"])


def options_record():
    """The whole options database as '-name value' lines (the file's ``options``)."""
    return "\n".join(f"-{k} {v}".rstrip() for k, v in sorted(PETSc.Options().getAll().items()))


def run(comm=None):
    """The whole program on ``comm``; returns the exit code. Only this function opens,
    finishes or aborts the result file, and destroys the PETSc objects."""
    comm = comm or PETSc.COMM_WORLD
    database = PETSc.Options()
    mesh = solver = writer = None

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    try:
        values, given = read_options()
        if database.hasName("help"):
            for line in help_text():
                say(line)
        scene = scene_from_options(values, given)
        settings = settings_from_options(values, scene)
        mesh = Mesh(comm, values["rod_elements"], scene.length, values["rod_mesh_grading"])
        solver = UzawaSolver(mesh, scene, settings)
        if database.hasName("help"):
            return 0
        if values["rod_initial"]:
            outputs.set_state(solver, *io.read_state(values["rod_initial"], mesh))
        else:
            solver.set_straight()
        if values["rod_output"]:
            writer = io.ResultWriter(values["rod_output"], mesh)
        code = continuation(solver, values["rod_steps"], values["rod_imperfection"], writer,
                            say, options_record(), values["rod_max_halvings"])
        writer = None
        for name in unused_options():
            say(f"petsc_rod: warning: option -{name} was set but not used")
        return code
    except RodError as error:
        say(f"petsc_rod: error: {error}")
        database.setValue("options_left", "0")
        return error.exit_code
    finally:
        if writer is not None:          # any failure before the file was finished
            writer.abort()
        if solver is not None:
            solver.destroy()
        if mesh is not None:
            mesh.destroy()


class LoadPath:
    """The load factors of the continuation: ``steps`` regular steps t_k = k/K, and the
    sub-steps by which a step that failed is retried.

    A failed attempt halves the increment (a smaller step starts nearer its solution,
    §7), at most ``max_halvings`` times on the way to one t_k; an accepted sub-step keeps
    the halved increment until t_k is reached, then the regular one is taken again.
    Load factors are counted in whole units of 1/(K 2^max_halvings), so that every t_k is
    reached exactly and is k/K to the last bit, as without halving.
    """

    def __init__(self, steps, max_halvings):
        self.steps = steps
        self.units_per_step = 2**max_halvings
        self.reached = 0                          # units: the last accepted load factor
        self.increment = self.units_per_step      # units
        self.halvings = 0                         # in the whole run

    def factor(self, units):
        """The load factor of a number of units."""
        return units / (self.steps * self.units_per_step)

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


def attempt(solver, t, imperfection, label):
    """One try at load factor t from the current state, its cross-sections rolled first:
    (report, failure), ``failure`` None when the step converged, the RodDivergedError
    when it diverged (report None), else a sentence saying how far it got."""
    solver.roll_cross_sections(imperfection)
    try:
        report = solver.solve_step(t, label=label)
    except RodDivergedError as error:
        return None, error
    if report.converged:
        return report, None
    return report, (f"not converged in {report.iterations} iterations (change "
                    f"{report.change:.2e}, constraint residual (RMS) "
                    f"{report.constraint_residual:.2e})")


def continuation(solver, steps, imperfection, writer, say, options, max_halvings):
    """Reach the scene in ``steps`` equal load increments, each warm-started (§7) from the
    last state with its cross-sections rolled by ``imperfection`` (see
    UzawaSolver.roll_cross_sections). A step that does not converge or diverges is undone
    (UzawaSolver.snapshot/restore) and retried with half the increment, at most
    ``max_halvings`` times on the way to each t_k (LoadPath); the file has one group
    ``steps/<n>`` per accepted step, and the failed one that ends a run."""
    mesh = solver.mesh
    clock = time.perf_counter()
    say(f"petsc_rod: {mesh.n_elements} elements on {mesh.comm.getSize()} rank(s), "
        f"R = {solver.settings.penalty:g}, {steps} step(s)")
    if solver.penalty > solver.settings.penalty:
        say(f"petsc_rod: the stiffness split is non-convex (method.md §2): R raised to "
            f"{solver.penalty:.6g} so the global step stays convex on this mesh, and "
            f"the change test tightened to {solver.change_tolerance:.3g} to match "
            "(docs/stability.md)")
    path = LoadPath(steps, max_halvings)
    total_iterations = undone_iterations = written = 0
    while not path.finished:
        t, label = path.next_factor, f"step {path.step}/{steps}"
        saved = solver.snapshot()
        report, failure = attempt(solver, t, imperfection, f"{label} ")
        iterations = (failure.iterations or 0) if report is None else report.iterations
        total_iterations += iterations
        if failure is not None and path.can_halve:
            solver.restore(saved)
            path.halve()
            undone_iterations += iterations
            reason = str(failure).removeprefix(f"{label} ")   # a divergence names the step
            say(f"petsc_rod: {label} at load factor {t:.6g}: {reason}; halving "
                f"{path.halvings}: retrying from load factor {path.factor(path.reached):.6g} "
                f"with increment {path.factor(path.increment):.6g}")
            continue
        if report is None:
            raise RodDivergedError(f"{failure}{path.given_up()}", failure.iterations) from None
        written += 1
        attributes = record_step(solver, report, t, label, say, writer, f"steps/{written}",
                                 wall_time=time.perf_counter() - clock, options=options)
        if not report.converged:
            break
        path.accept()
    if writer is not None:
        writer.finish(f"steps/{written}", attributes)
    if not report.converged:
        say(f"petsc_rod: error: {label} did not converge in {report.iterations} "
            f"iterations (-rod_al_max_it){path.given_up()}; the result file says "
            "converged = 0")
        return RodNotConvergedError.exit_code
    say(f"petsc_rod: converged, {total_iterations} iterations in "
        f"{time.perf_counter() - clock:.3g} s, {path.halvings} halving(s) of the step "
        f"({undone_iterations} iterations undone)")
    return 0


def record_step(solver, report, t, label, say, writer, group, **common):
    """Say the state after a step at load factor t and write it as ``group`` (with the
    attributes ``common`` to the run: wall_time, options); returns the group's attributes."""
    mesh = solver.mesh
    vertex = outputs.vertex_fields(solver, t)
    energy = solver.energy()
    u3_start = mesh.global_sum(vertex["u"][0, 2] if mesh.on_lower_boundary else 0.0)
    attributes = {"converged": int(report.converged), "iterations": report.iterations,
                  "constraint_residual": report.constraint_residual,
                  "change": report.change, "energy": energy, "ranks": mesh.comm.getSize(),
                  "load_factor": t, **common}
    say(f"{label}: load factor {t:.4g}, "
        f"{'converged' if report.converged else 'NOT converged'} in {report.iterations} "
        f"iterations, change {report.change:.2e}, constraint residual (RMS) "
        f"{report.constraint_residual:.2e}, energy {energy:.10g} J, u3(0) {u3_start:.6g}")
    if writer is not None:
        writer.write_step(group, vertex, outputs.restart_state(solver), report.history,
                          attributes)
    return attributes
