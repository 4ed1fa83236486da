"""solve(model): a Model (api/model.py) run on the ranks of ``comm`` on the one path of
a line's run (cli/line_run.py: plan_line, run_line), which the command line takes too:
the model, with the fields its Model.options set, compiled into its Scene (compile.py,
the refusals naming its fields and its options), its mesh, solver, start and
continuation. What it returns holds numpy arrays only (api/results.py); the run's PETSc
objects are made and destroyed in run_line."""

import dataclasses
import hashlib
import re

import numpy as np

from petsc_rod.api.model import Line, Model
from petsc_rod.api.results import Results
from petsc_rod.cli.line_run import plan_line, run_line, run_record
from petsc_rod.cli.options import BY_NAME, SOLVER_PREFIXES, nearest_hint, parse_values
from petsc_rod.compile import compile_scene
from petsc_rod.errors import RodInputError, on_every_rank
from petsc_rod.model.names import FIELD_NAMES, Names
from petsc_rod.environment.profiles import read_seabed_profile


def _run_record(model, values, solver, start):
    """line_run.run_record of the model's run, the record the command line writes for the
    same problem: the run's ``values`` (Model.options and the defaults, the mesh's
    element count, the output) with the model's own fields as values
    (Model.model_values: no option text between), its line types' table and seabed rows
    (which the command line reads from their files)."""
    export = {**values, **model.model_values(), "rod_elements": values["rod_elements"],
              "rod_line_types": None, "rod_seabed_profile": None}
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
    refuses it, the option named as Model.options names it (Model.options['name'])."""
    text = re.sub(r"-rod_(\w+)", lambda match: f"Model.options[{match.group(1)!r}]",
                  str(error))
    return RodInputError(text)


def model_names(model):
    """How a refusal names what ``model`` gives (model/names.Names): its fields as
    FIELD_NAMES has them, and the fields an option of Model.options sets as that option
    (Model.options['end_twist'], not Model.end.twist, which the caller left unset)."""
    return Names({**FIELD_NAMES.table,
                  **{name: f"Model.options[{name!r}]" for name in model.options}},
                 FIELD_NAMES.fallback)


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
    """A digest of everything ``model`` gives the run: its values (Model.model_values),
    Model.options and the tables it writes (line types, attachments, current profile,
    seabed rows)."""
    values = [(name, value.tobytes() if isinstance(value, np.ndarray) else value)
              for name, value in sorted(model.model_values().items())]
    profile = model.environment.profile()
    seabed = model.environment.seabed_profile
    whole = [values, sorted(model.options_texts().items()), model.line_types_text(),
             model.attachment_table(),
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
    """(values, given) of the -rod_* options the run takes from ``model``: Model.options
    parsed and checked as the command line's (the rest their defaults) and its steps and
    initial shape; RodInputError naming Model.options for a bad one."""
    check_options_known(model)
    texts = model.options_texts()       # refuses an option the model's fields give
    try:
        values = parse_values(texts)
    except RodInputError as error:
        raise in_model_terms(error) from None
    values.update(rod_steps=int(model.steps), rod_initial_shape=model.initial_shape)
    return values, set(texts) | {"rod_steps", "rod_initial_shape"}


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


def prepared(model):
    """(the model with the fields its options set, option values, given names) of
    ``model`` (options_of, with_options)."""
    if not isinstance(model, Model):
        raise RodInputError(f"solve takes an api.Model, not {type(model).__name__}")
    values, given = options_of(model)
    return with_options(model, values), values, given


def scene_of(model):
    """(Scene, option values, given names) of ``model``: the model, with the fields its
    options set, compiled (compile.py) with its refusals naming its fields and its
    options (model_names); the values of the options the run takes from it
    (options_of)."""
    whole, values, given = prepared(model)
    return compile_scene(whole, model_names(model)), values, given


def mesh_named(pieces, elements):
    """How a refusal of the mesh names the model's element count (line_run.plan_line)."""
    if pieces is None:
        return f"UniformLine.elements ({elements})"
    return (f"the model's Line ({elements} elements in all: its sections' counts and "
            "element_length)")


def solve(model, comm=None, output=None, say=None):
    """Solve ``model`` (api.Model) on the ranks of ``comm`` (a PETSc communicator;
    default PETSc.COMM_WORLD); collective. ``output``: a result file to write as well
    (HDF5, docs/output.md), as -rod_output; ``say(line)`` gets the command line's
    lines (None: silent). Returns an api.Results at the last load factor (its
    ``converged`` says whether it is 1; its ``modes`` those of Model.options['modes'],
    or ``modes_refused`` why there are none); RodInputError for a model the command line
    would refuse, RodDivergedError for a run that diverged."""
    from petsc4py import PETSc

    comm = comm or PETSc.COMM_WORLD
    if not isinstance(model, Model):
        raise RodInputError(f"solve takes an api.Model, not {type(model).__name__}")
    check_same_model(comm, model)
    whole, values, given = on_every_rank(comm, prepared, model)
    values["rod_output"] = output or None
    plan = plan_line(comm, whole, values, given, model_names(model), mesh_named)
    run = run_line(comm, plan, say, keep_last=True,
                   record=lambda plan, solver, start: _run_record(model, plan.values,
                                                                  solver, start))
    last = run.last
    return Results(last.vertex, last.attributes, run.result.converged, comm.tompi4py(),
                   run.elements, last.units, run.modes)
