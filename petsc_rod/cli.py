"""Command line: read the -rod_* options, build the scene, run the continuation, write,
report. Returns the process exit code (0 converged, 2 bad input, 3 not converged,
4 diverged)."""

import numpy as np
from petsc4py import PETSc

from . import io, outputs, starts
from .errors import RodError, RodInputError
from .mesh import Mesh
from .options import help_text, read_options, unused_options
from .scene import Scene
from .continuation import continuation
from .solver import Settings, UzawaSolver, default_penalty


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
        penalty = default_penalty(scene)
    return Settings(penalty=penalty, max_it=values["rod_al_max_it"],
                    rtol=values["rod_al_rtol"], ctol=values["rod_al_ctol"],
                    monitor=values["rod_al_monitor"],
                    adapt_penalty=values["rod_al_adapt_penalty"])


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
                            say, options_record(), values["rod_max_halvings"],
                            values["rod_track_link"])
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


