"""What a study scripts: the model (petsc_rod/model: line types, a line of sections, its
two ends, the sea, the attachments, docs/riser.md) with the load path that solves it
(steps, initial shape) and any other -rod_* option by name.

api.run.solve compiles the model into the solver's Scene (compile.py) with every check
of the command line, naming the model's fields, and records its run from the model's
values (Model.model_values), no option text between; ``Model.write_options`` exports the
same problem as an options file and its tables, which the command line solves to the
same numbers. Nothing here knows PETSc; the run is api/run.py.
"""

from dataclasses import dataclass, field

import numpy as np

from petsc_rod import model as physical
from petsc_rod.errors import RodInputError
from petsc_rod.model import (Attachment, End, Environment, Line, LineType,  # noqa: F401
                             UniformLine)
from petsc_rod.model.end import KINDS
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.model.sea import GRAVITY, WATER_DENSITY
from petsc_rod.model.values import whole

# Options a Model's fields give (Line, End, Environment, Attachment), or solve's output=;
# a restart (initial) walks a file's scene, which the API leaves to the command line.
MODEL_OPTIONS = ("line_types", "sections", "length", "stiffness", "load", "load_breaks",
                 "axial_stiffness", "drag", "elements", "mesh_grading", "output", "initial",
                 "initial_load_factor", "initial_friction_anchors", "point_loads",
                 "point_load", "current", "current_profile")
# The columns of a -rod_line_types table the export writes (model/line_type.py).
COLUMNS = ("name", "od", "mass", "gj", "ei", "ei1", "ei2", "ei_start", "ei_end", "ea", "cd",
           "drag_d", "id", "smys", "stress_od", "ca")


def _number(value):
    """A float as text that parses back to the same float (repr)."""
    return repr(float(value))


def _numbers(values):
    return ",".join(_number(v) for v in np.ravel(values))


def type_row(kind):
    """The LineType's row of a -rod_line_types table, in COLUMNS order ('-' blank)."""
    blank = "-"
    ei = np.ravel(kind.ei).astype(float)
    if kind.ei_end is not None:
        bending = [blank, blank, blank, _number(ei[0]), _number(kind.ei_end)]
    elif ei.size == 1:
        bending = [_number(ei[0]), blank, blank, blank, blank]
    else:
        bending = [blank, _number(ei[0]), _number(ei[1]), blank, blank]
    return ([kind.name, _number(kind.od), _number(kind.mass), _number(kind.gj)] + bending
            + [_number(kind.ea), _number(kind.cd),
               blank if kind.drag_d is None else _number(kind.drag_d), _number(kind.id),
               blank if kind.smys is None else _number(kind.smys),
               blank if kind.stress_od is None else _number(kind.stress_od),
               blank if kind.ca is None else _number(kind.ca)])


def line_types_table(types):
    """The text of a -rod_line_types table of the LineTypes ``types``."""
    rows = [list(COLUMNS)] + [type_row(t) for t in types]
    widths = [max(len(row[k]) for row in rows) for k in range(len(COLUMNS))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip()
                     for row in rows) + "\n"


def sections_text(line):
    """-rod_sections TYPE:LENGTH:ELEMENTS,... of a Line."""
    return ",".join(f"{entry[0].name}:{_number(entry[1])}:{int(count)}"
                    for entry, count in zip(line.sections, line.element_counts(
                        FIELD_NAMES)))


def _vector(values):
    """Numbers as the float array an option's parser gives them (cli/options._reals)."""
    return np.asarray(values, dtype=float).ravel()


def option_text(value):
    """An option's value as text its parser reads back to the same value (a float by
    its repr, a whole number or a switch as an integer, text as it is)."""
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, int)):
        return str(int(value))
    return _numbers(value)


def uniform_values(line):
    """{'rod_<name>': value} of the options a UniformLine stands for."""
    values = {"rod_length": float(line.length), "rod_stiffness": _vector(line.stiffness),
              "rod_load": _vector(line.load), "rod_elements": int(line.elements)}
    if np.size(line.load_breaks):
        values["rod_load_breaks"] = _vector(line.load_breaks)
    if np.isfinite(line.axial_stiffness):
        values["rod_axial_stiffness"] = float(line.axial_stiffness)
    if line.drag is not None:
        values["rod_drag"] = _vector(line.drag)
    if line.grading is not None:
        values["rod_mesh_grading"] = float(line.grading)
    return values


@dataclass(frozen=True)
class Model(physical.Model):
    """The model (model.Model: a line between two ends in the sea, with attachments),
    solved in ``steps`` continuation steps from ``initial_shape`` ('catenary': the
    catenary of the sections; 'straight'); ``options`` {name: value} any other -rod_*
    option, without 'rod_' (e.g. {'al_rtol': 1e-10}). Solve it with api.run.solve."""

    steps: int = 1
    initial_shape: str = "catenary"
    options: dict = field(default_factory=dict)

    def __post_init__(self):
        super().__post_init__()
        if not whole(self.steps) or self.steps < 1:
            raise RodInputError(f"Model.steps {self.steps!r}: a whole number of at least 1")
        if not isinstance(self.initial_shape, str):
            raise RodInputError(f"Model.initial_shape {self.initial_shape!r}: 'catenary' or "
                                "'straight'")
        if not isinstance(self.options, dict) or not all(
                isinstance(name, str) for name in self.options):
            raise RodInputError("Model.options: a dict {name: value} of -rod_* options "
                                "without 'rod_' (e.g. {'al_rtol': 1e-10})")

    def model_values(self, line_types="<line types>"):
        """{'rod_<name>': value} of the options this model's own fields stand for, as the
        command line's parser gives them (float, int, text, float arrays: options.
        parse_values), without text between: the parameters its run records (api/run.py)
        and, as text, its export (option_texts). ``line_types`` the name said for the line
        types' table (the table itself: ``line_types_text``); the attachments and the
        current's and seabed's profiles are named by placeholders (their rows are
        tables)."""
        values = {"rod_steps": int(self.steps), "rod_initial_shape": self.initial_shape}
        if isinstance(self.line, Line):
            values.update(rod_line_types=line_types, rod_sections=sections_text(self.line))
            for name in ("contents_density", "internal_pressure", "design_factor"):
                if getattr(self.line, name) is not None:
                    values[f"rod_{name}"] = float(getattr(self.line, name))
        else:
            values.update(uniform_values(self.line))
        for which, end in (("start", self.start), ("end", self.end)):
            if end.kind not in KINDS:
                raise RodInputError(f"Model.{which}: kind {end.kind!r}; use one of {KINDS}")
            values[f"rod_{which}"] = end.kind
            if end.position is not None:
                values[f"rod_{which}_position"] = _vector(end.position)
            if end.stiffness is not None:
                values[f"rod_{which}_rotational_stiffness"] = float(end.stiffness)
            for name, value in (("joint_axis", end.axis), ("force", end.force),
                                ("frame", end.frame)):
                if value is not None:
                    values[f"rod_{which}_{name}"] = _vector(value)
            if end.twist is not None:
                values[f"rod_{which}_twist"] = float(end.twist)
        sea = self.environment
        for name, value in (("seabed", sea.seabed), ("seabed_stiffness", sea.seabed_stiffness),
                            ("seabed_friction_stiffness", sea.seabed_friction_stiffness),
                            ("sea_surface", sea.surface), ("seabed_slope", sea.seabed_slope)):
            if value is not None:
                values[f"rod_{name}"] = float(value)
        for name in ("seabed_friction", "seabed_direction", "seabed_origin"):
            if getattr(sea, name) is not None:
                values[f"rod_{name}"] = _vector(np.atleast_1d(getattr(sea, name)))
        if sea.seabed_profile is not None:
            values["rod_seabed_profile"] = "<seabed profile>"
        if sea.current is not None:
            if sea.profile() is None:
                values["rod_current"] = _vector(sea.current)
            else:
                values["rod_current_profile"] = "<current profile>"
        if (sea.water_density, sea.gravity) != (WATER_DENSITY, GRAVITY):
            values["rod_water_density"] = float(sea.water_density)
            values["rod_gravity"] = float(sea.gravity)
        if self.attachments:
            values["rod_point_loads"] = "<attachments>"
        return values

    def options_texts(self):
        """{'rod_<name>': text} of Model.options (for the command line's parser, which
        checks them); RodInputError for one the model's own fields give (model_values),
        or solve's output=, or a restart's (the command line's)."""
        own = self.model_values()
        texts = {}
        for name, value in self.options.items():
            if name in MODEL_OPTIONS or f"rod_{name}" in own:
                raise RodInputError(f"Model.options {name!r}: the model's own fields give "
                                    "it (or solve's output=); restarts are the command "
                                    "line's (Model.write_options)")
            texts[f"rod_{name}"] = option_text(value)
        return texts

    def option_texts(self, line_types="<line types>"):
        """{'rod_<name>': text} of the options this model stands for, its own fields'
        (model_values) and Model.options: the export of write_options (a run of the
        model reads none of it)."""
        return {**{name: option_text(value)
                   for name, value in self.model_values(line_types).items()},
                **self.options_texts()}

    def write_options(self, path):
        """Write the model as an options file ``path`` (``python -m petsc_rod
        -options_file path`` solves it) and the tables it names beside it: ``path`` with
        '.line_types.txt', '.point_loads.txt', '.current.txt', '.seabed.txt' for '.opts'.
        Call it on one rank."""
        stem = str(path).removesuffix(".opts")
        files = {}
        if isinstance(self.line, Line):
            files["rod_line_types"] = (f"{stem}.line_types.txt", self.line_types_text())
        if self.attachments:
            files["rod_point_loads"] = (f"{stem}.point_loads.txt", self.attachment_table())
        profile = self.environment.profile()
        if profile is not None:
            rows = np.column_stack(profile)
            files["rod_current_profile"] = (f"{stem}.current.txt", "".join(
                " ".join(_number(v) for v in row) + "\n" for row in rows))
        if self.environment.seabed_profile is not None:
            files["rod_seabed_profile"] = (f"{stem}.seabed.txt", "".join(
                " ".join(_number(v) for v in row) + "\n"
                for row in np.asarray(self.environment.seabed_profile, dtype=float)))
        texts = self.option_texts()
        for name, (file, content) in files.items():
            with open(file, "w", encoding="utf-8") as out:
                out.write(content)
            texts[name] = file
        with open(path, "w", encoding="utf-8") as out:
            out.write("# written by petsc_rod.api.Model.write_options\n"
                      + "".join(f"-{name} {text}\n" for name, text in texts.items()))

    def line_types_text(self):
        """The -rod_line_types table of the line's types; RodInputError for two types of
        one name that differ; '' for a UniformLine."""
        if not isinstance(self.line, Line):
            return ""
        types = self.line.types()
        for entry in self.line.sections:
            if type_row(entry[0]) != type_row(types[[t.name for t in types].index(
                    entry[0].name)]):
                raise RodInputError(f"two different line types are named {entry[0].name}")
        return line_types_table(types)

    def attachment_table(self):
        """The attachments as a -rod_point_loads table's text (s, mass, volume, fx, fy,
        fz, cda, name)."""
        rows = ["s mass volume fx fy fz cda name"]
        for k, a in enumerate(self.attachments):
            name = (a.name or f"point_{k + 1}").replace(" ", "_")
            rows.append(" ".join([_number(a.S), _number(a.mass), _number(a.volume),
                                  _numbers(a.force).replace(",", " "), _number(a.cda), name]))
        return "\n".join(rows) + "\n"
