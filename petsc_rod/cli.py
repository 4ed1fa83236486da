"""Command line: read the -rod_* options, build the scene, run the continuation, write,
report. Returns the process exit code (0 converged, 2 bad input, 3 not converged,
4 diverged)."""

import time

import numpy as np
from petsc4py import PETSc

from . import io, outputs, starts
from .errors import RodError, RodInputError, RodNotConvergedError
from .mesh import Mesh
from .options import help_text, read_options, unused_options
from .scene import Scene
from .solver import STOP_STALLED, Settings, UzawaSolver


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


def default_penalty(scene):
    """R = max(400 max(K) / L^2, applied force / 2), N.

    The first term is the bending scale (the paper's R = 400 for K = 200..360 daN m^2 on
    20 m, within a factor of 4); the second is the scale of the tension, which the
    multiplier lambda3 has to reach by steps of at most 2R per iteration: a 3000 m
    catenary under 1 kN/m (tension ~1e6 N, K = 1e5 N m^2) diverges in the first
    iteration at 400 K / L^2 = 4.4 N and converges in 771 iterations at 1.5e6 N
    (docs/stability.md).
    """
    return max(400.0 * scene.stiffness.max() / scene.length**2, 0.5 * scene.applied_force())


def settings_from_options(values, scene):
    penalty = values["rod_al_penalty"]
    if penalty is None:
        penalty = default_penalty(scene)
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
        start_from(solver, values)
        if values["rod_output"]:
            writer = io.ResultWriter(values["rod_output"], mesh)
        code = continuation(solver, values["rod_steps"], values["rod_imperfection"], writer,
                            say, options_record())
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


def not_converged_reason(report, solver):
    """Why a step stopped without converging, and what to change."""
    settings = solver.settings
    numbers = (f"estimated distance {report.distance:.2e} for -rod_al_rtol {settings.rtol:.2g}, "
               f"constraint residual {report.constraint_residual:.2e} for -rod_al_ctol "
               f"{settings.ctol:.2g}")
    if report.reason == STOP_STALLED:
        return (f"stalled after {report.iterations} iterations ({numbers}): at their rate they "
                "would not meet the tolerances within -rod_al_max_it; the mesh's floor (about "
                "h^3) lies above them: use more -rod_elements or looser tolerances")
    hint = ""
    if settings.penalty < 0.1 * default_penalty(solver.scene):
        hint = (f"; -rod_al_penalty {settings.penalty:g} is far below the problem's scale "
                f"{default_penalty(solver.scene):.3g} (the default): raise it")
    return f"did not converge in {report.iterations} iterations ({numbers}){hint}"


def start_from(solver, values):
    """The state the first step starts from: a restart file, or -rod_initial_shape."""
    shape = values["rod_initial_shape"]
    if shape not in starts.SHAPES:
        raise RodInputError(f"-rod_initial_shape {shape}: unknown shape; use one of "
                            + "|".join(starts.SHAPES))
    if values["rod_initial"]:
        if shape != "straight":
            raise RodInputError("-rod_initial and -rod_initial_shape both set the start; "
                                "give one of them")
        outputs.set_state(solver, *io.read_state(values["rod_initial"], mesh=solver.mesh))
    elif shape == "catenary":
        solver.set_from_curve(starts.catenary_start(solver.scene, 1.0 / values["rod_steps"]))
    else:
        solver.set_straight()


def continuation(solver, steps, imperfection, writer, say, options):
    """Reach the scene in ``steps`` equal load increments, each warm-started (§7) from the
    last state with its cross-sections rolled by ``imperfection`` (see
    UzawaSolver.roll_cross_sections)."""
    mesh = solver.mesh
    clock = time.perf_counter()
    say(f"petsc_rod: {mesh.n_elements} elements on {mesh.comm.getSize()} rank(s), "
        f"R = {solver.settings.penalty:g}, {steps} step(s)")
    if solver.penalty > solver.settings.penalty:
        say(f"petsc_rod: the stiffness split is non-convex (method.md §2): R raised to "
            f"{solver.penalty:.6g} so the global step stays convex on this mesh "
            "(docs/stability.md)")
    total_iterations = 0
    for k in range(1, steps + 1):
        t = k / steps
        solver.roll_cross_sections(imperfection)
        report = solver.solve_step(t, label=f"step {k}/{steps} ")
        total_iterations += report.iterations
        vertex = outputs.vertex_fields(solver, t)
        energy = solver.energy()
        u3_start = mesh.global_sum(vertex["u"][0, 2] if mesh.on_lower_boundary else 0.0)
        attributes = {"converged": int(report.converged), "iterations": report.iterations,
                      "constraint_residual": report.constraint_residual,
                      "change": report.change, "estimated_distance": report.distance,
                      "energy": energy,
                      "wall_time": time.perf_counter() - clock, "ranks": mesh.comm.getSize(),
                      "options": options, "load_factor": t}
        say(f"step {k}/{steps}: load factor {t:.4g}, "
            f"{'converged' if report.converged else 'NOT converged'} in {report.iterations} "
            f"iterations, estimated distance {report.distance:.2e}, constraint residual (RMS) "
            f"{report.constraint_residual:.2e}, energy {energy:.10g} J, u3(0) {u3_start:.6g}")
        if writer is not None:
            writer.write_step(f"steps/{k}", vertex, outputs.restart_state(solver),
                              report.history, attributes)
        if not report.converged:
            break
    if writer is not None:
        writer.finish(f"steps/{k}", attributes)
    if not report.converged:
        say(f"petsc_rod: error: step {k}/{steps} {not_converged_reason(report, solver)}; "
            "the result file says converged = 0")
        return RodNotConvergedError.exit_code
    say(f"petsc_rod: converged, {total_iterations} iterations in "
        f"{time.perf_counter() - clock:.3g} s")
    return 0
