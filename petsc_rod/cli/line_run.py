"""One line's run: the one path of the command line (cli/main.run; a sweep's cases run
through it) and of the Python API (api/run.solve), and the pieces a solver of several
lines builds each of its lines from. A compiled model and the run's values go through:

    plan_line(comm, model, values, given, names) -> LinePlan
        the Model compiled into its Scene (compile.py), the iteration's Settings, the
        mesh's pieces, and every check that needs no PETSc object (the mesh fits, the
        stability test can be made, the outputs can be written)
    BuiltLine(comm, plan): .build(say), or a with block
        the Mesh, RodProblem and UzawaSolver of the plan, made together (a restart's walk
        from its file's scene resolved: walked_scene); .start(say) sets the first
        state, .run(path, ...) runs the continuation (session.run_continuation) from the
        state it holds (run it again for a warm start from the last one); .destroy()
        destroys what was built
    run_line(comm, plan, say, ...) -> LineRun
        the whole run: built, started, run, written (the result file and -rod_table's CSV),
        destroyed, inside the ranks' failure protocol (AgreedFailures)

``values`` {'rod_<name>': value} are the run's -rod_* values as options.parse_values
gives them (steps, initial shape, imperfection, tolerances, output, table, restart), the
model's own fields beside them; ``given`` the names the caller set; ``names``
(model/names.Names) how a refusal names what the caller gave (the command line its
options, the API the model's fields and Model.options). This module is the one place
where a line's PETSc objects are created and destroyed.
"""

import contextlib
import os
import sys
import time
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from petsc_rod import resources
from petsc_rod.cli import messages
from petsc_rod.cli.phases import OUTPUT, SETUP, STEPS
from petsc_rod.cli.options import (BY_NAME, HOW_RUN, OPTIONS, SOLVER_PREFIXES,
                                   format_value, modes_asked, parse_values)
from petsc_rod.cli.scene_options import (OPTION_NAMES, check_stability_asked, checked_pieces,
                                         restart_path, rounded_down, settings_from_options)
from petsc_rod.cli.session import run_continuation
from petsc_rod.compile import compile_scene
from petsc_rod.environment.profiles import read_seabed_profile
from petsc_rod.errors import (NoCatenaryStart, RodDivergedError, RodInputError, on_every_rank,
                              petsc_message)
from petsc_rod.io import line_table, outputs, provenance
from petsc_rod.io import results as io
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.iteration.driver import UzawaSolver
from petsc_rod.mesh.mesh import (MIN_RELATIVE_ELEMENT, Mesh, end_element_lengths,
                                 fewest_elements, largest_grading)
from petsc_rod.model import UniformLine
from petsc_rod.problem.build import friction_terms, lay_friction_anchors
from petsc_rod.problem.problem import RodProblem
from petsc_rod.scenes import starts
from petsc_rod.scenes.blend import BlendedPath
from petsc_rod.tables import read_text

# How long the ranks wait for each other after an error before taking it for one rank's
# alone, s.
FAILURE_WAIT = 10.0


def _silent(line):
    """A say that says nothing."""


@dataclass
class LinePlan:
    """What a line's run needs before any PETSc object (plan_line): the ``model``, its
    compiled ``scene``, the iteration's ``settings``, the mesh's ``pieces`` (mesh.Pieces
    of a line of sections; None: one graded piece), the run's ``values`` (the element
    count, length and grading of the mesh put in) and ``given``, and the ``names``
    refusals use."""

    model: object
    scene: object
    settings: object
    pieces: object
    values: dict
    given: set
    names: object = OPTION_NAMES


def values_of(options):
    """(values, given) of a solver's ``options`` {name without ``rod_``: value}: every
    -rod_* option's value (options.parse_values: the rest their defaults) and the names
    given, for a line a caller builds itself (system/held_line.py)."""
    texts = {f"rod_{name}": str(value) for name, value in (options or {}).items()}
    return parse_values(texts), set(texts)


def plan_line(comm, model, values, given, names=OPTION_NAMES, mesh_named=None):
    """The LinePlan of ``model`` (model.Model) with the run's ``values`` and ``given``
    (module docstring), every refusal worded with ``names``: the scene compiled on every
    rank (one RodInputError everywhere if any rank refuses it), the settings (the default
    penalty of the scene), the mesh (a line of sections meshed a piece per section with
    Line.element_counts, a uniform line's elements and grading), and the checks before
    any work: the mesh fits the machine and double precision (check_mesh;
    ``mesh_named(pieces, elements)`` how its message names the element count, None the
    default), a stability test asked with loads without an energy, the outputs' paths.
    Collective."""
    scene = on_every_rank(comm, compile_scene, model, names)
    settings = settings_from_options(values, scene, names)
    values = dict(values)
    line, pieces = model.line, None
    if isinstance(line, UniformLine):
        values.update(rod_elements=int(line.elements), rod_length=float(line.length))
        if line.grading is not None:
            values["rod_mesh_grading"] = float(line.grading)
    else:                       # the sections' elements, every section end a vertex
        pieces = checked_pieces(scene, line.element_counts(names), names["sections"])
        values["rod_elements"] = int(pieces.counts.sum())
    check_mesh(comm, values, resources.bytes_per_element(
        scene.seabed is not None and (settings.newton or settings.check_stability)),
        None if mesh_named is None else mesh_named(pieces, values["rod_elements"]))
    if modes_asked(values) or values["rod_modes_table"]:
        modes_of_run().check_modes_inputs(values, scene, comm)
    if values["rod_output"]:
        io.check_output_path(values["rod_output"], comm)
    if values["rod_table"]:
        line_table.check_table_path(values["rod_table"], values["rod_output"], comm)
    return LinePlan(model, scene, settings, pieces, values, set(given), names)


class BuiltLine:
    """The PETSc objects of a LinePlan's line: ``mesh`` (Mesh), ``problem`` (RodProblem)
    and ``solver`` (UzawaSolver), made by ``build`` and destroyed together by
    ``destroy`` (in reverse order, skipping what was not made); ``scene`` the scene the
    load path walks (the plan's, or a restart's walk from its file's scene) and
    ``notes`` the lines that say so; ``path_of(scene)``, when given, the load path the
    problem walks instead (a held line's, system/held_line.HeldEnds). ``with
    BuiltLine(comm, plan) as built:`` builds and destroys around the block; run_line
    calls build and destroy itself, so that the ranks agree on a failure before the
    collective destroy."""

    def __init__(self, comm, plan, path_of=None):
        self.comm, self.plan, self.path_of = comm, plan, path_of
        self.mesh = self.problem = self.solver = self.scene = None
        self.notes, self.first_load_factor, self.owned = [], 0.0, []

    def build(self, say=None):
        """Make the mesh, the problem and the solver (build_solver: a PETSc error while
        the solvers are set up is bad input); refuse a stability test asked of a problem
        with loads without an energy (scene_options.check_stability_asked). Collective."""
        plan, values = self.plan, self.plan.values
        self.mesh = Mesh(self.comm, values["rod_elements"], plan.scene.length,
                         values["rod_mesh_grading"], plan.pieces)
        self.scene, self.notes = walked_scene(plan.scene, values, self.comm)
        if self.path_of is not None:        # a caller's own load path over the scene
            self.scene = self.path_of(self.scene)
        self.problem, self.solver = build_solver(self.mesh, self.scene, plan.settings,
                                                 say or _silent)
        check_stability_asked(values, plan.given, plan.scene, self.problem, plan.names,
                              plan.names["al_stability"])
        return self

    def start(self, say=None):
        """Set the first state (start_from: a restart file or the initial shape) and say
        the restart's notes; returns the PathSettings of the run from it (the plan's
        steps, imperfection, halvings; a walk from a file's scene starts at its own s =
        0, the file's state)."""
        say = say or _silent
        values = self.plan.values
        start = start_from(self.problem, values, self.plan.given, say, self.plan.scene)
        for note in self.notes:             # once the file is known to fit this run
            say(note)
        self.first_load_factor = start
        return PathSettings(steps=values["rod_steps"],
                            start=start if self.scene is self.plan.scene else 0.0,
                            imperfection=values["rod_imperfection"],
                            max_halvings=values["rod_max_halvings"],
                            track_link=values["rod_track_link"])

    def run(self, path, say=None, writer=None, options="", interrupts=None,
            before_finish=None):
        """session.run_continuation of the built solver along ``path`` from the state it
        holds (``before_finish(writer)`` called before the result file is finished); a
        ContinuationResult."""
        return run_continuation(self.solver, path, say=say, writer=writer, options=options,
                                interrupts=interrupts, before_finish=before_finish)

    def own(self, made):
        """Take ``made`` (a PETSc object's owner made on the built problem by a caller:
        a held line's Newton solver, its Jacobian) to destroy before the solver, the
        problem and the mesh; returns it."""
        self.owned.append(made)
        return made

    def destroy(self):
        """Destroy what was built and what it was given to own (own), in reverse order,
        skipping what was not made. Collective."""
        for made in reversed(self.owned):
            made.destroy()
        self.owned = []
        for built in (self.solver, self.problem, self.mesh):
            if built is not None:
                built.destroy()
        self.mesh = self.problem = self.solver = None

    def __enter__(self):
        try:
            return self.build()
        except BaseException:
            self.destroy()
            raise

    def __exit__(self, *exception):
        self.destroy()
        return False


class LastStep:
    """A writer for run_continuation that keeps the last step's vertex datasets and
    attributes (copies of this rank's owned arrays), passing everything on to a
    io.results.ResultWriter ``inner`` when there is one."""

    def __init__(self, inner=None):
        self.inner, self.vertex, self.attributes, self.units = inner, None, None, ({}, {})

    def write_step(self, group, vertex, state, history, attributes, units=None):
        self.vertex = {name: np.array(value, copy=True) for name, value in vertex.items()}
        self.attributes = dict(attributes)
        self.units = units or ({}, {})
        if self.inner is not None:
            self.inner.write_step(group, vertex, state, history, attributes, units)

    def finish(self, *args):
        if self.inner is not None:
            self.inner.finish(*args)

    def write_modes(self, modes):
        if self.inner is not None:
            self.inner.write_modes(modes)

    def kept_name(self):
        return self.inner.kept_name() if self.inner is not None else None


@dataclass
class LineRun:
    """How run_line's run ended: the ContinuationResult ``result`` (code, last report,
    iterations), the last step ``last`` (a LastStep: this rank's vertex arrays,
    attributes and units; None unless asked), the mesh's ``elements`` and the modes of
    -rod_modes about the converged state (analysis/modes.Modes, or the ModesRefused that
    says why there are none; None unless asked and converged)."""

    result: object
    last: object
    elements: int
    modes: object = None


class AgreedFailures:
    """``with AgreedFailures(comm) as failures:`` the ranks' protocol for an exception
    raised in the block (but a BaseException that is not an Exception): if every rank
    raised one (every_rank_failed) it goes on, to be said or raised by the caller; if
    this rank raised it alone, the others wait in a collective call and cannot be told:
    the partial result file of ``failures.writer`` is removed and every rank ends
    (abort_alone). Its communicator is made when it is (collective)."""

    def __init__(self, comm):
        self.comm, self.writer = comm, None
        self._failures = comm.tompi4py().Dup()

    def __enter__(self):
        return self

    def __exit__(self, kind, error, trace):
        try:
            if isinstance(error, Exception) and not every_rank_failed(self._failures):
                words = (petsc_failure(error) if isinstance(error, PETSc.Error)
                         else alone_failure(self.comm, error))
                abort_alone(self.comm, words, getattr(self.writer, "partial", None))
        finally:
            self._failures.Free()
        return False


def modes_of_run():
    """cli/modes.py, imported here: only a run with -rod_modes or -rod_modes_table loads
    the modes' modules (analysis/modes.py and SLEPc)."""
    from petsc_rod.cli import modes
    return modes


def run_line(comm, plan, say=None, *, record=None, keep_last=False, options="",
             interrupts=None, check_only=False):
    """Run the LinePlan ``plan`` on ``comm``: build its line (BuiltLine), start it, run
    the continuation, write the result file (-rod_output, its root and parameters group
    ``record(plan, solver, start)``, default run_record of the plan's values) and, for a
    converged run, -rod_table's CSV (a run that did not converge removes an earlier
    one); destroy what was built. ``say(line)`` gets the lines (None: silent);
    ``keep_last`` keeps the last step's arrays (LineRun.last); ``options`` the options
    database as text for the steps' attributes; ``interrupts`` (signals.Interrupts) asked
    after every iteration; ``check_only`` stops once the line is built (-help), returning
    None. Returns a LineRun; the errors of the run are raised, once the ranks agree on
    them (AgreedFailures). Collective."""
    say = say or _silent
    values = plan.values
    built, writer = BuiltLine(comm, plan), None
    try:
        with AgreedFailures(comm) as failures:
            with SETUP:
                built.build(say)
                if check_only:
                    return None
                path = built.start(say)
                if values["rod_modes"]:     # more than the line has: refused now
                    modes_of_run().check_modes_count(built.problem, values)
            if values["rod_output"]:
                made = (record or default_record)(plan, built.solver, built.first_load_factor)
                writer = failures.writer = io.ResultWriter(
                    values["rod_output"], built.mesh,
                    io.minimum_bytes(built.mesh, outputs.restart_state(built.problem),
                                     values["rod_steps"]), made)
            last = LastStep(writer) if keep_last else None
            modes = []                      # -rod_modes: found before the file is finished

            def find_modes(writer):
                modes.append(modes_of_run().solve_for_run(built.problem, values, writer))
            with STEPS:
                result = built.run(path, say=say, writer=last or writer, options=options,
                                   interrupts=interrupts,
                                   before_finish=find_modes if modes_asked(values) else None)
            writer = failures.writer = None             # finished
            with OUTPUT:
                if result.code == 0:            # the CSV table of the converged result
                    line_table.finish_run(built.problem, values["rod_table"], say)
                    if modes:
                        modes_of_run().report_modes(built.problem, values, modes[0], say)
                elif values["rod_table"]:   # none for this run: not an earlier run's either
                    line_table.discard(values["rod_table"], comm, say)
            found = modes[0][0] if modes and result.code == 0 else None
            return LineRun(result, last, built.mesh.n_elements, found)
    finally:
        if writer is not None:              # any failure before the file was finished
            writer.abort()
        built.destroy()


def default_record(plan, solver, start):
    """run_record of the plan's values: the record of the command line's run."""
    return run_record(plan.values, solver, start)


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


def start_from(problem, values, given, say, scene=None):
    """Set the state the first step starts from, a restart file or -rod_initial_shape;
    returns the load factor the load path goes on from (0 but for a restart). A catenary
    start that cannot be drawn for a sound scene (NoCatenaryStart: discrete buoyancy
    modules on a grounded line, a buoyancy section whose catenary dips below the seabed)
    becomes the straight start, in one line saying why. The seabed friction's anchors of
    a run from its own start are the line as laid (lay_friction_anchors); a restart's are
    the file's positions (-rod_initial_friction_anchors file: the path goes on from the
    file's line), or the line as laid between the ends of ``scene`` (the run's own, the
    end of a restart's walk; default the problem's) with ``laid``, so that the answer is
    the run's from its own start whatever file started it (a sweep's warm start,
    sweep/runner.py), each said in one line on a scene with friction."""
    shape = values["rod_initial_shape"]
    if shape not in starts.SHAPES:
        raise RodInputError(f"-rod_initial_shape {shape}: unknown shape; use one of "
                            + "|".join(starts.SHAPES))
    if values["rod_initial"]:
        if shape != "straight":         # e.g. a scene file's: the restart file starts it
            say(f"petsc_rod: -rod_initial_shape {shape} is not used: the restart file "
                f"{values['rod_initial']} is the start")
        start = restart_from(problem, values["rod_initial"],
                             values["rod_initial_load_factor"], say)
        if not friction_terms(problem):
            return start
        if values["rod_initial_friction_anchors"] == "laid":
            if lay_friction_anchors(problem, say, scene):
                say("petsc_rod: restart: the seabed friction's anchors are laid on this "
                    "run's catenary between its ends, not the file's positions "
                    "(-rod_initial_friction_anchors laid)")
        else:
            say("petsc_rod: restart: the seabed friction's anchors are the file's "
                "positions, moved by the return map along this run's path "
                "(-rod_initial_friction_anchors file; laid: this run's own catenary's)")
        return start
    for name, what in (("rod_initial_load_factor", "the state it is the load factor of"),
                       ("rod_initial_friction_anchors", "the restart whose anchors it places")):
        if name in given:
            raise RodInputError(f"-{name} needs -rod_initial ({what}); drop it or give "
                                "the file")
    curve = None
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
    lay_friction_anchors(problem, say)
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
    missing = [option.name for option in OPTIONS if option.name not in HOW_RUN
               and option.name.removeprefix("rod_") not in parameters]
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
