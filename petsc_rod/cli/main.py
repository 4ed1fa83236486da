"""Command line: read the -rod_* options, check them and what the run needs before any
work, build the scene, run the continuation, write, report. Returns the process exit
code (docs/errors.md: 0 converged, 2 bad input, 3 not converged,
4 diverged or a PETSc error during the solve, 5 the result could not be written,
128 + n stopped by signal n)."""

import contextlib
import os
import signal
import sys
import time

import numpy as np
from petsc4py import PETSc

from petsc_rod import resources
from petsc_rod.cli import messages
from petsc_rod.cli.options import (BY_NAME, OPTIONS, SOLVER_PREFIXES, check_anderson_depth,
                                   check_same_on_every_rank, check_snes_type,
                                   check_substructuring_switches, format_value,
                                   help_text, read_options, unused_options, values_of)
from petsc_rod.cli.options_files import every_options_file
from petsc_rod.cli.scene_options import (check_stability_asked, mesh_pieces, restart_path,
                                         rounded_down, scene_from_options,
                                         settings_from_options)
from petsc_rod.cli.session import run_continuation
from petsc_rod.cli.signals import Interrupts
from petsc_rod.environment.profiles import read_seabed_profile
from petsc_rod.errors import NoCatenaryStart, RodDivergedError, RodError, RodInputError
from petsc_rod.cli.modes import check_modes_inputs, report_modes, solve_for_run, shapes_path
from petsc_rod.io import line_table, outputs, provenance
from petsc_rod.io import results as io
from petsc_rod.io.same_file import replaced_input
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.iteration.driver import UzawaSolver
from petsc_rod.mesh.mesh import (MIN_RELATIVE_ELEMENT, Mesh, end_element_lengths,
                                 fewest_elements, largest_grading)
from petsc_rod.problem.problem import RodProblem
from petsc_rod.scenes import starts
from petsc_rod.scenes.blend import BlendedPath
from petsc_rod.tables import read_text

# The options that name a file the run reads.
INPUT_FILE_OPTIONS = tuple(option.name for option in OPTIONS
                           if option.metavar == "FILE" and option.name != "rod_output")
# How long the ranks wait for each other after a PETSc error before taking it for one
# rank's alone, s.
FAILURE_WAIT = 10.0


def options_record(texts=None):
    """The whole options database, with ``texts`` {name: text} in place of its own
    where given, as '-name value' lines (the file's ``options``)."""
    options = {**PETSc.Options().getAll(), **(texts or {})}
    return "\n".join(f"-{k} {v}".rstrip() for k, v in sorted(options.items()))


def run(comm=None, texts=None):
    """The whole program on ``comm``; returns the exit code. Only this function opens,
    finishes or aborts the result file, and destroys the PETSc objects. ``texts``
    {name: text}: the -rod_* options of the run (a sweep's case, sweep/runner.py), in
    place of those of PETSc's options database, which then gives the solvers' options
    (-rod_snes_*, -rod_slope_ksp_*, ...) alone."""
    comm = comm or PETSc.COMM_WORLD
    database = PETSc.Options()
    mesh = problem = solver = writer = None

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    # where the ranks agree on a PETSc error (made now: creating it is collective)
    failures = comm.tompi4py().Dup()

    with Interrupts(comm) as interrupts:
        try:
            if texts is None:
                check_same_on_every_rank(comm)
                values, given = read_options()
            else:                           # the same on every rank: the sweep's
                values, given = values_of(texts)
            check_anderson_depth()          # before any PETSc object is made
            check_snes_type()
            check_substructuring_switches()
            if database.hasName("help"):
                for line in help_text():
                    say(line)
            scene = scene_from_options(values, given)
            settings = settings_from_options(values, scene)
            pieces = mesh_pieces(values, scene, given)
            if pieces is not None:          # the sections' elements, every section end a vertex
                values["rod_elements"] = int(pieces.counts.sum())
            check_mesh(comm, values, resources.bytes_per_element(
                scene.seabed is not None
                and (settings.newton or settings.check_stability)),
                None if pieces is None or "rod_elements" in given else
                f"-rod_sections ({values['rod_elements']} elements in all)")
            check_stability_asked(values, scene, given)
            check_modes_inputs(values, scene, comm)
            if values["rod_output"]:
                io.check_output_path(values["rod_output"], comm)
            if values["rod_table"]:
                line_table.check_table_path(values["rod_table"], values["rod_output"], comm)
            check_inputs_kept(values, comm)
            mesh = Mesh(comm, values["rod_elements"], scene.length, values["rod_mesh_grading"],
                        pieces)
            path_scene, notes = walked_scene(scene, values, comm)
            problem, solver = build_solver(mesh, path_scene, settings, say)
            check_stability_possible(problem, "rod_al_stability" in given
                                     and values["rod_al_stability"])
            if database.hasName("help"):
                return 0
            start = start_from(problem, values, given, say)
            for note in notes:              # once the file is known to fit this run
                say(note)
            if values["rod_output"]:
                writer = io.ResultWriter(
                    values["rod_output"], mesh,
                    io.minimum_bytes(mesh, outputs.restart_state(problem), values["rod_steps"]),
                    run_record(values, solver, start))
            # a walk from the file's scene starts at its own s = 0, the file's state
            path = PathSettings(steps=values["rod_steps"],
                                start=start if path_scene is scene else 0.0,
                                imperfection=values["rod_imperfection"],
                                max_halvings=values["rod_max_halvings"],
                                track_link=values["rod_track_link"])
            modes = []                      # -rod_modes: found before the file is finished

            def find_modes(writer):
                modes.append(solve_for_run(problem, values, writer))
            code = run_continuation(solver, path, say=say, writer=writer,
                                    options=options_record(texts), interrupts=interrupts,
                                    before_finish=find_modes if values["rod_modes"] else None
                                    ).code
            writer = None
            if code == 0:                   # the CSV table of the converged result
                line_table.finish_run(problem, values["rod_table"], say)
                if modes:
                    report_modes(problem, values, modes[0], say)
            elif values["rod_table"]:       # none for this run: not an earlier run's either
                line_table.discard(values["rod_table"], comm, say)
            for name in unused_options():
                say(f"petsc_rod: warning: option -{name} was set but not used")
            return code
        except RodError as error:
            if getattr(error, "signal_number", 0) == signal.SIGPIPE:
                # the output is a pipe nobody reads any more: the line goes to stderr
                if comm.getRank() == 0:
                    sys.stderr.write(f"petsc_rod: error: {error}\n")
            else:
                say(f"petsc_rod: error: {error}")
            database.setValue("options_left", "0")
            return error.exit_code
        except PETSc.Error as error:        # inside a solve: the SNES's own options, say
            if not every_rank_failed(failures):
                abort_alone(comm, petsc_failure(error), getattr(writer, "partial", None))
            say(f"petsc_rod: error: {petsc_failure(error)}")
            database.setValue("options_left", "0")
            return RodDivergedError.exit_code
        except Exception as error:          # a numpy error, say: one rank's or every rank's
            if not every_rank_failed(failures):
                abort_alone(comm, alone_failure(comm, error), getattr(writer, "partial", None))
            raise                           # every rank's: the partial file goes in finally
        finally:
            if writer is not None:          # any failure before the file was finished
                writer.abort()
            destroy_run(solver, problem, mesh)
            failures.Free()


def destroy_run(solver, problem, mesh):
    """Destroy what a run built, in reverse order, skipping what was not built (None);
    collective (cli.main.run, api.run.solve)."""
    for built in (solver, problem, mesh):
        if built is not None:
            built.destroy()


def petsc_message(error):
    """The last line of a PETSc.Error's report (PETSc's own message), without its rank."""
    return str(error).strip().splitlines()[-1].split("] ", 1)[-1]


def petsc_failure(error):
    """The one line of a PETSc error raised during the run (exit 4, no result file)."""
    solvers = ", ".join(f"-{prefix}*" for prefix in SOLVER_PREFIXES
                        if prefix != "rod_snes_")
    return (f"PETSc failed during the solve: {petsc_message(error)}; check the "
            "-rod_snes_* options (the iteration has no Jacobian) and the solvers' "
            f"{solvers} options")


def alone_failure(comm, error):
    """The one line of an exception other than RodError and PETSc.Error (a numpy error,
    say) that only this rank raised: the other ranks cannot be told, the run is aborted."""
    words = f"{type(error).__name__}: {error}".splitlines()[0]
    return (f"rank {comm.getRank()} failed alone ({words}); the other ranks wait in a "
            "collective call and cannot be told, so the run is aborted and writes no result")


def every_rank_failed(failures, wait=None):
    """Whether every rank of communicator ``failures`` (used for nothing else) reaches
    this call within ``wait`` seconds (None: FAILURE_WAIT), as all do after an error that
    every rank raised; a rank-local error leaves the others inside a collective call."""
    request = failures.Ibarrier()
    deadline = time.monotonic() + (FAILURE_WAIT if wait is None else wait)
    while not request.Test():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def abort_alone(comm, message, partial=None):
    """End every rank after an error that only this one raised (the others wait in a
    collective call and cannot be told): the line, the partial file ``partial`` removed
    by its name (the collective close cannot be made), then MPI_Abort with exit 4."""
    sys.stdout.write(f"petsc_rod: error: {message}\n")
    sys.stdout.flush()
    if partial is not None:
        with contextlib.suppress(OSError):
            os.remove(partial)
    comm.tompi4py().Abort(RodDivergedError.exit_code)


def check_mesh(comm, values, per_element=resources.BYTES_PER_ELEMENT, named=None):
    """Refuse, before it is allocated, a mesh the machine cannot hold (``per_element``
    bytes an element: resources.bytes_per_element), a grading the
    mesh's smooth map cannot build on that many elements (mesh.largest_grading: 1 for 1
    or 2 elements, about 3 N^2 / pi^2 for N), or one whose smallest elements double
    precision cannot resolve. Any mesh of N elements whose largest element is q times its
    smallest has a smallest element of at most L / (N - 1 + q): that bound is checked
    first, so a grading no mesh could resolve is said as such. ``named``: how a message
    names the element count (resources.check_elements_fit)."""
    elements, length = values["rod_elements"], values["rod_length"]
    grading = values["rod_mesh_grading"]
    resources.check_elements_fit(comm, elements, per_element, named)

    def unresolved(smallest):
        return RodInputError(
            f"-rod_mesh_grading {grading:g} with {elements} elements: the end elements "
            f"would be {smallest / length:.2g} of the length, below what double precision "
            f"resolves ({MIN_RELATIVE_ELEMENT:g}); use a smaller grading or fewer elements")

    if not length / (elements - 1 + grading) >= MIN_RELATIVE_ELEMENT * length:
        raise unresolved(length / (elements - 1 + grading))
    largest = largest_grading(elements)
    if grading > largest:
        fix = f"-rod_elements {fewest_elements(grading)} or more"
        if largest > 1:
            fix = f"-rod_mesh_grading {rounded_down(largest, 6):.6g} or less, or " + fix
        else:
            fix = "-rod_mesh_grading 1 (uniform), or " + fix
        raise RodInputError(
            f"-rod_mesh_grading {grading:g} with {elements} elements: the graded mesh "
            f"S = L(t - beta sin(2 pi t)/2 pi) reaches a largest / smallest element of at "
            f"most {largest:.6g} on {elements} element(s); use {fix}")
    smallest = end_element_lengths(elements, length, grading).min()
    if not smallest >= MIN_RELATIVE_ELEMENT * length:
        raise unresolved(smallest)


def check_inputs_kept(values, comm):
    """Refuse, before any work, an output (-rod_output, -rod_table and its regions'
    table, -rod_modes_table and its shapes') that names one of the run's inputs, which writing it would replace: an
    options file, or the file of an input option (-rod_initial, -rod_line_types,
    -rod_point_loads, the profiles: every option whose value is a FILE). Collective:
    rank 0 decides."""
    written = [("-rod_output", values["rod_output"])]
    if values["rod_table"]:
        written += [("-rod_table", values["rod_table"]),
                    ("the regions' table of -rod_table",
                     line_table.regions_path(values["rod_table"]))]
    if values["rod_modes_table"]:
        written += [("-rod_modes_table", values["rod_modes_table"]),
                    ("the shapes' table of -rod_modes_table",
                     shapes_path(values["rod_modes_table"]))]
    clash = None
    if comm.getRank() == 0:
        read = [("-options_file", path) for path in every_options_file(sys.argv)]
        read += [(f"-{name}", values[name]) for name in INPUT_FILE_OPTIONS]
        clash = replaced_input(written, read)
    clash = comm.tompi4py().bcast(clash, root=0)
    if clash:
        raise RodInputError(clash)


def build_solver(mesh, scene, settings, say):
    """(RodProblem, UzawaSolver), the solver saying a monitor line per iteration with
    -rod_al_monitor; a PETSc error while they set up their solvers (an unknown
    -rod_slope_ksp_type, say) is bad input (what was made is destroyed)."""
    def say_monitor(*row):
        say(messages.monitor(*row))

    monitor = say_monitor if settings.monitor else None
    problem = None
    try:
        problem = RodProblem(mesh, scene, settings.asked_penalty)
        return problem, UzawaSolver(problem, settings, monitor)
    except PETSc.Error as error:
        if problem is not None:
            problem.destroy()
        raise RodInputError(f"PETSc refused the solver options: {petsc_message(error)}; "
                            "check the "
                            "-rod_slope_*, -rod_d1_*, -rod_d2_* and -rod_snes_* options") from None


def check_stability_possible(problem, asked):
    """Refuse -rod_al_stability 1, ``asked`` (given, true), for a problem with a term that
    has no energy (Term.conservative False: a sloping seabed's lagged contact force, the
    sea surface's wet and dry parts, attachments that can reach the surface), beside the
    current and the friction that scene_options.check_stability_asked names by their
    options: the test would be left out without a word (UzawaSolver.tests_stability)."""
    if not asked or problem.conservative:
        return
    loads = "; ".join(dict.fromkeys(term.newton_gap or type(term).__name__
                                    for term in problem.terms if not term.conservative))
    raise RodInputError(f"-rod_al_stability 1: the stability test is of the second "
                        f"variation of the energy, and this scene has loads without one "
                        f"({loads}); drop -rod_al_stability (such a run gives no "
                        "stability verdict)")


def start_from(problem, values, given, say):
    """Set the state the first step starts from, a restart file or -rod_initial_shape;
    returns the load factor the load path goes on from (0 but for a restart). A catenary
    start that cannot be drawn for a sound scene (NoCatenaryStart: discrete buoyancy
    modules on a grounded line, a buoyancy section whose catenary dips below the seabed)
    becomes the straight start, in one line saying why."""
    shape = values["rod_initial_shape"]
    if shape not in starts.SHAPES:
        raise RodInputError(f"-rod_initial_shape {shape}: unknown shape; use one of "
                            + "|".join(starts.SHAPES))
    if values["rod_initial"]:
        if shape != "straight":         # e.g. a scene file's: the restart file starts it
            say(f"petsc_rod: -rod_initial_shape {shape} is not used: the restart file "
                f"{values['rod_initial']} is the start")
        return restart_from(problem, values["rod_initial"], values["rod_initial_load_factor"],
                            say)
    if "rod_initial_load_factor" in given:
        raise RodInputError("-rod_initial_load_factor needs -rod_initial (the state it is "
                            "the load factor of); drop it or give the file")
    if shape == "catenary":
        try:
            curve = starts.catenary_start(problem.scene, 1.0 / values["rod_steps"])
        except NoCatenaryStart as reason:   # a sound scene: the paper's trivial start
            say(f"petsc_rod: {reason}: the run starts from the straight line instead "
                "(-rod_initial_shape straight)")
            problem.state.set_straight()
        else:
            problem.state.set_from_curve(curve)
    else:
        problem.state.set_straight()
    return 0.0


def walked_scene(scene, values, comm):
    """(the scene this run's load path walks, the lines that say so): ``scene``, or for
    a restart whose file's scene (rebuilt from its ``parameters`` group) differs in what
    the load path carries, the walk from the file's scene at its load factor to ``scene``
    in -rod_steps steps (scene_options.restart_path, docs/method.md §7), said in one line;
    what else differs is ``scene``'s from the first step, said in another. A file whose
    parameters lack an option (an older version's, or one written through the Python API)
    is taken as a file of ``scene``, as a file without them: its scene is not rebuilt
    from defaults. Collective."""
    path = values["rod_initial"]
    record = io.read_parameters(path, comm) if path else None
    if record is None:
        return scene, []
    parameters, t_file, walked_file = record
    if walked_file and t_file < 1.0:
        raise RodInputError(
            f"-rod_initial {path}: written part way along a restart's walk from another "
            f"scene (s = {t_file:.6g}), its state is the equilibrium of a scene between the "
            "two; restart from the file that walk started from")
    missing = [option.name for option in OPTIONS
               if option.name.removeprefix("rod_") not in parameters]
    if missing:
        return scene, [f"petsc_rod: restart: the file's parameters lack -{missing[0]}"
                       f"{' and more' if len(missing) > 1 else ''}; its scene is taken as "
                       "this run's"]
    if values["rod_initial_load_factor"] is not None:
        t_file = values["rod_initial_load_factor"]
    try:
        walked, differ, fixed = restart_path(scene, parameters, t_file)
    except RodInputError as error:
        raise RodInputError(f"-rod_initial {path}: its parameters do not make a scene "
                            f"({error})") from None
    notes = []
    if walked is not scene:
        notes.append(f"petsc_rod: restart: walks from the file's scene at load factor "
                     f"{t_file:.6g} to this one in {values['rod_steps']} step(s) (load factor "
                     f"s of the walk, 0 the file's state, 1 this scene); they differ in "
                     f"{', '.join(differ)}")
    if fixed:
        notes.append(f"petsc_rod: restart: {', '.join(fixed)} differ(s) from the file's; "
                     "this run's value(s) hold from the first step")
    return walked, notes


def restart_from(problem, path, load_factor, say):
    """Set the state of result file ``path`` (validated by io.read_restart against this
    run's arrays); returns ``load_factor``, or the file's when it is None."""
    restart = io.read_restart(path, problem.mesh, outputs.restart_state(problem))
    # the file's r is absolute: its shape is taken from its own start (docs/method.md §5)
    record = io.read_parameters(path, problem.mesh.comm)
    origin = "" if record is None else record[0].get("start_position", "")
    if not isinstance(origin, str):
        restart.vertex["r"] = restart.vertex["r"] - np.asarray(origin, dtype=float)
    outputs.set_state(problem, restart.vertex, restart.state)
    if not restart.converged:
        say(f"petsc_rod: warning: -rod_initial {path} says converged = 0: the run starts "
            f"from a state that did not converge (at load factor {restart.load_factor:.6g})")
    start = restart.load_factor if load_factor is None else load_factor
    say(f"petsc_rod: restart from {path}, load factor {start:.6g}"
        + (" (-rod_initial_load_factor)" if load_factor is not None else
           " (the file's; -rod_initial_load_factor 0 walks the load path again)"))
    return start


def run_record(values, solver, start):
    """What the result file's root says about the run: version, commit and the options in
    effect as text, and the group ``parameters`` (every option in effect, defaults and
    the solvers' included, as numbers with their units)."""
    parameters, units = options_in_effect(values, solver, start)
    text = "\n".join(f"-rod_{name} {format_value(value)}" for name, value in parameters.items()
                     if not (isinstance(value, str) and value == ""))
    attributes = {"version": provenance.version(), "commit": provenance.commit(),
                  "options_in_effect": text,
                  # the load factors are a walk's s (scenes/blend.py): read_parameters
                  "restart_walk": int(isinstance(solver.problem.scene, BlendedPath))}
    shaped = {**parameters, "load": np.asarray(parameters["load"]).reshape(-1, 3),
              "end_frame": np.asarray(parameters["end_frame"]).reshape(3, 3),
              "start_frame": np.asarray(parameters["start_frame"]).reshape(3, 3)}
    return io.RunRecord(attributes, shaped, units)


def options_in_effect(values, solver, start):
    """Every -rod_* option's value in effect, by name without ``rod_`` (the defaults that
    depend on the scene resolved, text options that were not given as ''), and its unit;
    the current profile's rows (``current_profile_table``) and the line types' table
    (``line_types_table``), not only their files' names;
    then each global-step solver's KSP, PC and factorisation package."""
    scene = solver.problem.scene
    origin = scene.start_position               # the scene's positions are from the start
    resolved = {"rod_end_position": scene.end_position + origin,
                "rod_start_position": origin, "rod_end_frame": scene.end_frame.ravel(),
                "rod_start_frame": scene.start_frame.ravel(),
                "rod_al_penalty": solver.settings.asked_penalty, "rod_initial_load_factor": start}
    if not np.isfinite(scene.axial_stiffness):  # inextensible: written as not given
        resolved["rod_axial_stiffness"] = None
    if scene.seabed is not None:                # the default stiffness (environment/seabed.py)
        resolved["rod_seabed_stiffness"] = scene.seabed.stiffness
        if scene.seabed.friction is not None:   # its default stick stiffness
            resolved["rod_seabed_friction_stiffness"] = scene.seabed.friction.stiffness
    if values["rod_current_profile"]:
        resolved["rod_sea_surface"] = scene.current.surface + origin[2]
    if scene.sections:                          # the length the sections add up to
        resolved["rod_length"] = scene.length
    parameters, units = {}, {}
    for option in OPTIONS:
        value = resolved.get(option.name, values[option.name])
        if value is None:
            value = ""
        if isinstance(value, bool):
            value = int(value)
        parameters[option.name.removeprefix("rod_")] = value
        units[option.name.removeprefix("rod_")] = BY_NAME[option.name].unit
    if values["rod_current_profile"]:           # the profile itself, to repeat the run
        current = scene.current
        parameters["current_profile_table"] = np.column_stack([current.depths,
                                                               current.velocities])
        units["current_profile_table"] = "m, m/s, m/s, m/s (depth, ux, uy, uz)"
    if values["rod_seabed_profile"]:            # the seabed profile itself, to repeat the run
        parameters["seabed_profile_table"] = read_seabed_profile(values["rod_seabed_profile"])
        units["seabed_profile_table"] = "m (distance, height; or x, y, height)"
    if values["rod_line_types"]:                # the line types' table, to repeat the run
        parameters["line_types_table"] = read_text(values["rod_line_types"],
                                                   "-rod_line_types")
        units["line_types_table"] = "text"
    if scene.point_load_S.size:                 # the attachments' forces, to repeat the run
        parameters["point_loads_table"] = np.column_stack([
            scene.point_load_S, scene.point_load_forces, scene.point_load_drag_areas,
            scene.point_load_volumes])
        units["point_loads_table"] = "m, N, N, N, m^2, m^3 (S, fx, fy, fz, CdA, volume)"
    for name, value in solver_types(solver).items():
        parameters[name] = value
        units[name] = "text"
    return parameters, units


def solver_types(solver):
    """{'<prefix>ksp_type': ..., '<prefix>pc_type': ..., '<prefix>pc_factor_mat_solver_type':
    ...} of the global step's solvers, prefixes without ``rod_``."""
    types = {}
    for ksp in solver.problem.global_step.ksps():
        prefix = (ksp.getOptionsPrefix() or "").removeprefix("rod_")
        pc = ksp.getPC()
        types[f"{prefix}ksp_type"] = ksp.getType()
        types[f"{prefix}pc_type"] = pc.getType()
        package = (pc.getFactorSolverType()
                   if pc.getType() in (PETSc.PC.Type.CHOLESKY, PETSc.PC.Type.LU) else None)
        if package:             # known once the factorisation is set up
            types[f"{prefix}pc_factor_mat_solver_type"] = package
    return types
