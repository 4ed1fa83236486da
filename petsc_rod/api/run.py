"""solve(model): a Model (api/model.py) compiled into its Scene (compile.py, with the
model's checks naming its fields) and solved as the command line solves its options
(cli/main.py): the same mesh, solver, start and continuation
(cli/session.run_continuation), on the ranks of ``comm``. The one place of the API that
creates and destroys PETSc objects; what it returns holds numpy arrays only
(api/results.py)."""

import dataclasses
import hashlib
import re

import numpy as np

from petsc_rod.api.model import Line, Model, UniformLine
from petsc_rod.api.results import Results
from petsc_rod.cli.main import (abort_alone, alone_failure, build_solver, check_mesh,
                                destroy_run, every_rank_failed, run_record, start_from)
from petsc_rod.cli.options import BY_NAME, SOLVER_PREFIXES, nearest_hint, parse_values
from petsc_rod.cli.scene_options import (check_stability_asked, checked_pieces,
                                         settings_from_options)
from petsc_rod.compile import compile_scene
from petsc_rod.cli.session import run_continuation
from petsc_rod.errors import RodInputError, on_every_rank
from petsc_rod.io import outputs
from petsc_rod.io import results as io
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.environment.profiles import read_seabed_profile


class _LastStep:
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

    def kept_name(self):
        return self.inner.kept_name() if self.inner is not None else None

    def abort(self):
        if self.inner is not None:
            self.inner.abort()


def _run_record(model, values, solver, start, output):
    """cli.main.run_record of the model's run: every option the model stands for (its
    export, Model.option_texts) with the run's ``values``, its line types' table and
    seabed rows (which the command line reads from their files)."""
    export = {**parse_values(model.option_texts()), "rod_elements": values["rod_elements"],
              "rod_output": output, "rod_line_types": None, "rod_seabed_profile": None}
    record = run_record(export, solver, start)
    if isinstance(model.line, Line):
        record.parameters["line_types"] = "(Python API)"
        record.parameters["line_types_table"] = model.line_types_text()
        record.units["line_types_table"] = "text"
    if model.environment.seabed_profile is not None:
        record.parameters["seabed_profile"] = "(Python API)"
        record.parameters["seabed_profile_table"] = np.asarray(
            model.environment.seabed_profile, dtype=float)
        record.units["seabed_profile_table"] = "m (distance, height; or x, y, height)"
    return record


# The model's field an option of Model.options sets (where the model leaves it None or
# at its default): (part of the model, field).
OPTION_FIELDS = {
    **{name: ("line", name) for name in ("contents_density", "internal_pressure",
                                         "design_factor")},
    **{name: ("environment", name) for name in (
        "water_density", "gravity", "seabed", "seabed_stiffness", "seabed_friction",
        "seabed_friction_stiffness", "seabed_slope", "seabed_direction", "seabed_origin",
        "seabed_profile")},
    "sea_surface": ("environment", "surface"),
    **{f"{which}{option}": (which, name) for which in ("start", "end")
       for option, name in (("_position", "position"), ("_rotational_stiffness", "stiffness"),
                            ("_joint_axis", "axis"), ("_force", "force"), ("_frame", "frame"),
                            ("_twist", "twist"))}}


def in_model_terms(error):
    """RodInputError ``error`` of an option of Model.options, refused as the command line
    refuses it, the option named as Model.options names it."""
    text = re.sub(r"-rod_(\w+)", lambda match: f"Model.options {match.group(1)!r}",
                  str(error))
    return RodInputError(text)


def check_options_known(model):
    """Refuse a name of Model.options that is not a -rod_* option, with the nearest
    known name, as the command line refuses it; and a solver option (-rod_newton_*, ...),
    which only PETSc's options database gives its solver."""
    for name in model.options:
        full = f"rod_{name}"
        if full.startswith(SOLVER_PREFIXES) and full not in BY_NAME:
            raise RodInputError(f"Model.options {name!r}: the solvers' options are read "
                                "from PETSc's options database; set -" + full + " there "
                                "(petsc4py.PETSc.Options().setValue) or on the command line")
        if full not in BY_NAME:
            hint = nearest_hint(full).replace("-rod_", "'").replace("?", "'?")
            raise RodInputError(f"Model.options {name!r}: not a petsc_rod option{hint}")


def model_digest(model):
    """A digest of everything ``model`` gives the run: its option texts and the tables
    it writes (line types, attachments, current profile, seabed rows)."""
    texts = model.option_texts()
    profile = model.environment.profile()
    seabed = model.environment.seabed_profile
    whole = [sorted(texts.items()), model.line_types_text(), model.attachment_table(),
             None if profile is None else [p.tobytes() for p in profile],
             None if seabed is None else np.asarray(seabed, dtype=float).tobytes()]
    return hashlib.sha256(repr(whole).encode()).hexdigest()


def check_same_model(comm, model):
    """Refuse, on every rank of ``comm``, a model that any rank finds bad or that differs
    between ranks (an answer of neither, or a crash in the first collective call of a
    mesh built of other element lengths). Collective."""
    digests = comm.tompi4py().allgather(on_every_rank(comm, model_digest, model))
    if len(set(digests)) != 1:
        rank = next(k for k, digest in enumerate(digests) if digest != digests[0])
        raise RodInputError(f"rank {rank} was given another model than rank 0; give every "
                            "rank the same Model (built from the same numbers)")


def options_of(model):
    """(values, given) of the -rod_* options the run takes from ``model``: its steps and
    initial shape and Model.options, parsed and checked as the command line's (the rest
    their defaults); RodInputError naming Model.options for a bad one."""
    check_options_known(model)
    texts = model.option_texts()        # refuses an option the model's fields give
    own = {name: texts[name] for name in ("rod_steps", "rod_initial_shape")}
    own.update({f"rod_{name}": texts[f"rod_{name}"] for name in model.options})
    try:
        return parse_values(own), set(own)
    except RodInputError as error:
        raise in_model_terms(error) from None


def with_options(model, values):
    """``model`` with the fields Model.options sets (OPTION_FIELDS) set from their parsed
    ``values`` (a seabed profile's rows read from its file)."""
    parts = {}
    for name in model.options:
        if name not in OPTION_FIELDS:
            continue
        part, field = OPTION_FIELDS[name]
        value = values[f"rod_{name}"]
        if name == "seabed_profile":
            value = read_seabed_profile(value)
        parts.setdefault(part, {})[field] = value
    changed = {part: dataclasses.replace(getattr(model, part), **fields)
               for part, fields in parts.items()}
    return dataclasses.replace(model, **changed) if changed else model


def scene_of(model):
    """(Scene, option values, given names) of ``model``: the model, with the fields its
    options set, compiled (compile.py) with its refusals naming its fields; the
    values of the options the run takes from it (options_of)."""
    if not isinstance(model, Model):
        raise RodInputError(f"solve takes an api.Model, not {type(model).__name__}")
    values, given = options_of(model)
    return compile_scene(with_options(model, values), FIELD_NAMES), values, given


def mesh_of(line, scene, values):
    """(mesh.Pieces or None, how a message names the element count) of the model's
    line, its element count and grading put into ``values`` (check_mesh, Mesh): a Line's
    sections meshed one piece each, a UniformLine's elements graded."""
    if isinstance(line, UniformLine):
        values.update(rod_elements=int(line.elements), rod_length=float(line.length))
        if line.grading is not None:
            values["rod_mesh_grading"] = float(line.grading)
        return None, f"UniformLine.elements ({values['rod_elements']})"
    pieces = checked_pieces(scene, line.element_counts(FIELD_NAMES), FIELD_NAMES["sections"])
    values["rod_elements"] = int(pieces.counts.sum())
    return pieces, (f"the model's Line ({values['rod_elements']} elements in all: its "
                    "sections' counts and element_length)")


def solve(model, comm=None, output=None, say=None):
    """Solve ``model`` (api.Model) on the ranks of ``comm`` (a PETSc communicator;
    default PETSc.COMM_WORLD); collective. ``output``: a result file to write as well
    (HDF5, docs/output.md), as -rod_output; ``say(line)`` gets the command line's
    lines (None: silent). Returns an api.Results at the last load factor (its
    ``converged`` says whether it is 1); RodInputError for a model the command line
    would refuse, RodDivergedError for a run that diverged."""
    from petsc4py import PETSc

    comm = comm or PETSc.COMM_WORLD
    if not isinstance(model, Model):
        raise RodInputError(f"solve takes an api.Model, not {type(model).__name__}")
    check_same_model(comm, model)
    scene, values, given = on_every_rank(comm, scene_of, model)
    settings = settings_from_options(values, scene, FIELD_NAMES)
    pieces, named = mesh_of(model.line, scene, values)
    check_mesh(comm, values, named=named)
    if output:
        io.check_output_path(output, comm)
    mesh = problem = solver = keeper = None
    say = say or (lambda line: None)
    # where the ranks agree on a failure (made now: creating it is collective)
    failures = comm.tompi4py().Dup()
    try:
        mesh = Mesh(comm, values["rod_elements"], scene.length, values["rod_mesh_grading"],
                    pieces)
        problem, solver = build_solver(mesh, scene, settings, say)
        check_stability_asked(values, given, scene, problem, FIELD_NAMES,
                              "Model.options['al_stability']")
        start = start_from(problem, values, given, say)
        inner = None
        if output:
            inner = io.ResultWriter(
                output, mesh,
                io.minimum_bytes(mesh, outputs.restart_state(problem), values["rod_steps"]),
                _run_record(model, values, solver, start, output))
        keeper = _LastStep(inner)
        path = PathSettings(steps=values["rod_steps"], imperfection=values["rod_imperfection"],
                            max_halvings=values["rod_max_halvings"],
                            track_link=values["rod_track_link"])
        result = run_continuation(solver, path, say=say, writer=keeper)
        keeper.inner = None                     # finished
        return Results(keeper.vertex, keeper.attributes, result.converged,
                       comm.tompi4py(), mesh.n_elements, keeper.units)
    except Exception as error:
        # one rank's alone (a numpy error, say): the others wait in a collective call
        if not every_rank_failed(failures):
            inner = keeper.inner if keeper is not None else None
            abort_alone(comm, alone_failure(comm, error), getattr(inner, "partial", None))
        raise
    finally:
        if keeper is not None:
            keeper.abort()
        destroy_run(solver, problem, mesh)
        failures.Free()
