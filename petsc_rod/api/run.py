"""solve(model): a Model (api/model.py) solved as the command line solves its options
(cli/main.py): the same Scene (cli/scene_options.py), checks, mesh, solver, start and
continuation (cli/session.run_continuation), on the ranks of ``comm``. The one place of
the API that creates and destroys PETSc objects; what it returns holds numpy arrays
only (api/results.py)."""

import hashlib
import re

import numpy as np

from petsc_rod.api.model import Model
from petsc_rod.api.results import Results
from petsc_rod.cli.main import (abort_alone, alone_failure, build_solver, check_mesh,
                                check_stability_possible,
                                destroy_run, every_rank_failed, run_record, start_from)
from petsc_rod.cli.options import BY_NAME, SOLVER_PREFIXES, nearest_hint, parse_values
from petsc_rod.cli.scene_options import (check_stability_asked, mesh_pieces, scene_from_options,
                                         settings_from_options)
from petsc_rod.cli.session import run_continuation
from petsc_rod.errors import RodInputError, on_every_rank
from petsc_rod.io import outputs
from petsc_rod.io import results as io
from petsc_rod.iteration.continuation import PathSettings
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.scenes.point_loads import attachment_forces, beyond_the_line


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


def _points(model, length):
    """(S, forces (n, 3), drag areas, volumes) of the model's attachments, or None."""
    if not model.attachments:
        return None
    sea = model.environment
    S = np.array([a.S for a in model.attachments], dtype=float)
    k = beyond_the_line(S, length)
    if k is not None:
        raise RodInputError(f"attachment {k + 1}: S = {S[k]:.6g} m is beyond the line "
                            f"[0, {length:.6g}] m")
    columns = {"s": S, "mass": [a.mass for a in model.attachments],
               "volume": [a.volume for a in model.attachments],
               **{f"f{c}": [a.force[i] for a in model.attachments]
                  for i, c in enumerate("xyz")}}
    areas = np.array([a.cda for a in model.attachments], dtype=float)
    if np.any(np.asarray(columns["mass"]) < 0) or np.any(np.asarray(columns["volume"]) < 0) \
            or np.any(areas < 0):
        raise RodInputError("an attachment's mass, volume and cda must not be negative")
    return (S, attachment_forces(columns, sea.water_density, sea.gravity), areas,
            np.asarray(columns["volume"], dtype=float))


def _run_record(model, values, solver, start, output):
    """cli.main.run_record of the model's run, with its line types' table (which the
    command line reads from its file) and the model's option texts."""
    record = run_record({**values, "rod_output": output, "rod_line_types": None}, solver,
                        start)
    record.parameters["line_types"] = "(Python API)"
    record.parameters["line_types_table"] = model.line_types_text()
    record.units["line_types_table"] = "text"
    return record


# The model's field behind each option it stands for (Model.option_texts), so that a
# refusal of the command line's checks names what the caller gave.
MODEL_FIELDS = {"rod_sections": "Line.sections", "rod_line_types": "the LineTypes",
                "rod_contents_density": "Line.contents_density",
                "rod_internal_pressure": "Line.internal_pressure",
                "rod_steps": "Model.steps", "rod_initial_shape": "Model.initial_shape",
                "rod_point_loads": "Model.attachments",
                "rod_current": "Environment.current",
                "rod_current_profile": "Environment.current",
                "rod_sea_surface": "Environment.surface",
                **{f"rod_{name}": f"Environment.{name}" for name in (
                    "seabed", "seabed_stiffness", "seabed_friction",
                    "seabed_friction_stiffness", "water_density", "gravity")},
                **{f"rod_{end}{option}": f"Model.{end}{field}" for end in ("start", "end")
                   for option, field in (("", ""), ("_position", ".position"),
                                         ("_rotational_stiffness", ".stiffness"),
                                         ("_joint_axis", ".axis"), ("_force", ".force"))}}


def in_model_terms(error):
    """RodInputError ``error`` of the command line's checks, its options named as the
    model's fields (MODEL_FIELDS; a table's stand-in name, '<line types>', dropped)."""
    text = re.sub(r"-(rod_\w+)(?: <[a-z ]+>)?",
                  lambda match: MODEL_FIELDS.get(match.group(1), match.group(0)), str(error))
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
    it writes (line types, attachments, current profile)."""
    texts = model.option_texts()
    profile = model.environment.profile()
    whole = [sorted(texts.items()), model.line_types_text(), model.attachment_table(),
             None if profile is None else [p.tobytes() for p in profile]]
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


def scene_of(model):
    """(Scene, option values, given names) of ``model``: its options parsed and made into
    a validated Scene by the command line's own functions."""
    if not isinstance(model, Model):
        raise RodInputError(f"solve takes an api.Model, not {type(model).__name__}")
    check_options_known(model)
    texts = model.option_texts()
    values = parse_values(texts)
    given = set(texts)
    scene = scene_from_options(values, given, model.environment.profile(),
                               model.line_types_text(), _points(model, model.line.length))
    if model.attachments:
        scene.point_load_names = tuple(a.name or f"point {k + 1}"
                                       for k, a in enumerate(model.attachments))
    return scene, values, given


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
    try:
        scene, values, given = on_every_rank(comm, scene_of, model)
        settings = settings_from_options(values, scene)
        check_stability_asked(values, scene, given)
        pieces = mesh_pieces(values, scene)
    except RodInputError as error:
        raise in_model_terms(error) from None
    values["rod_elements"] = int(pieces.counts.sum())
    check_mesh(comm, values, named=f"the model's Line ({values['rod_elements']} elements in "
                                   "all: its sections' counts and element_length)")
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
        check_stability_possible(problem, "rod_al_stability" in given
                                 and values["rod_al_stability"])
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
