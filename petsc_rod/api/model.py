"""What a study scripts: line types, a line of sections, its two ends, the sea, the
attachments (docs/riser.md), as plain values in SI units, and the -rod_* options they
stand for.

A Model is read exactly as the command line reads its options:
``Model.option_texts()`` gives their text, which cli/options.parse_values parses and
cli/scene_options makes into the Scene (with every check and message of the command
line), so that a model and the options file it writes (``Model.write_options``) solve
the same problem to round-off.
Nothing here knows PETSc; the run is api/run.py.
"""

from dataclasses import dataclass, field
import math

import numpy as np

from petsc_rod.errors import RodInputError

KINDS = ("pin", "clamp", "free")
# Options a Model's fields give (Line, End, Environment, Attachment), or solve's output=;
# a restart (initial) walks a file's scene, which the API leaves to the command line.
MODEL_OPTIONS = ("line_types", "sections", "length", "stiffness", "load", "load_breaks",
                 "axial_stiffness", "drag", "elements", "mesh_grading", "output", "initial",
                 "initial_load_factor", "point_loads", "point_load", "current",
                 "current_profile")


def _number(value):
    """A float as text that parses back to the same float (repr)."""
    return repr(float(value))


def _numbers(values):
    return ",".join(_number(v) for v in np.ravel(values))


def _real(owner, value, allow_inf=False):
    """``value`` (a number, not text or bool) as a float, finite (or +inf where
    ``allow_inf``); RodInputError naming ``owner`` (e.g. 'End.stiffness') otherwise."""
    if isinstance(value, (str, bytes, bool, np.bool_)) or value is None:
        raise RodInputError(f"{owner} {value!r}: expected a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise RodInputError(f"{owner} {value!r}: expected a number") from None
    if not (math.isfinite(number) or (allow_inf and number == math.inf)):
        raise RodInputError(f"{owner} {value!r}: expected a finite number")
    return number


def _reals(owner, values, sizes):
    """``values`` as a float array of one of the sizes ``sizes``, every entry a finite
    number (not text or bool); RodInputError naming ``owner`` otherwise."""
    expected = f"expected {' or '.join(map(str, sizes))} numbers"
    try:
        array = np.asarray(values)
    except (TypeError, ValueError):             # rows of several lengths
        array = np.asarray(None)
    if array.dtype.kind not in "iuf" or array.size not in sizes:
        raise RodInputError(f"{owner} {values!r}: {expected}")
    array = array.astype(float).ravel()
    if not np.all(np.isfinite(array)):
        raise RodInputError(f"{owner} {values!r}: {expected}, finite")
    return array


def _optional(owner, value, check, *args):
    """``check(owner, value, *args)`` of a field that may be None."""
    return None if value is None else check(owner, value, *args)


@dataclass(frozen=True)
class LineType:
    """A line type as a data sheet gives it (scenes/line.LineType):

    ``od`` outer diameter (m), ``mass`` in air with contents (kg/m), ``ei`` bending
    stiffness (N m^2; a pair (EI1, EI2) about d1 and d2 for an anisotropic line),
    ``gj`` torsional stiffness (N m^2), ``ea`` axial stiffness (N; inf: inextensible),
    ``cd`` normal drag coefficient (1), ``drag_d`` hydrodynamic diameter (m; None: the
    od), ``id`` inner diameter (m; 0: no bore), ``ei_end`` (N m^2) the bending
    stiffness at the end of each section of the type where it tapers linearly from
    ``ei`` (a bend stiffener), ``smys`` the wall's yield stress (Pa; None: no
    utilisation), ``stress_od`` the steel wall's outer diameter under a jacket or
    coating (m; None: the od). The submerged weight is (mass - rho_w pi od^2 / 4) g.
    """

    name: str
    od: float
    mass: float
    ei: object
    gj: float
    ea: float = math.inf
    cd: float = 0.0
    drag_d: float = None
    id: float = 0.0
    ei_end: float = None
    smys: float = None
    stress_od: float = None

    def __post_init__(self):
        owner = f"LineType {self.name!r}"
        if not isinstance(self.name, str) or not self.name or len(self.name.split()) != 1 \
                or any(c in self.name for c in ",:#"):
            raise RodInputError(f"{owner}: a name is one word without , : or #")
        for name in ("od", "mass", "gj", "cd", "id"):
            _real(f"{owner}.{name}", getattr(self, name))
        _real(f"{owner}.ea", self.ea, allow_inf=True)
        _reals(f"{owner}.ei", self.ei, (1, 2))
        for name in ("drag_d", "ei_end", "smys", "stress_od"):
            _optional(f"{owner}.{name}", getattr(self, name), _real)

    def row(self):
        """The type's row of a -rod_line_types table, in COLUMNS order ('-' blank)."""
        blank = "-"
        ei = np.ravel(self.ei).astype(float)
        if self.ei_end is not None:
            if ei.size != 1:
                raise RodInputError(f"line type {self.name}: a taper (ei_end) takes one ei")
            bending = [blank, blank, blank, _number(ei[0]), _number(self.ei_end)]
        elif ei.size == 1:
            bending = [_number(ei[0]), blank, blank, blank, blank]
        elif ei.size == 2:
            bending = [blank, _number(ei[0]), _number(ei[1]), blank, blank]
        else:
            raise RodInputError(f"line type {self.name}: ei is one number or a pair (EI1, EI2)")
        return ([self.name, _number(self.od), _number(self.mass), _number(self.gj)] + bending
                + [_number(self.ea), _number(self.cd),
                   blank if self.drag_d is None else _number(self.drag_d), _number(self.id),
                   blank if self.smys is None else _number(self.smys),
                   blank if self.stress_od is None else _number(self.stress_od)])


# The columns LineType.row fills (scenes/line.py: LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL).
COLUMNS = ("name", "od", "mass", "gj", "ei", "ei1", "ei2", "ei_start", "ei_end", "ea", "cd",
           "drag_d", "id", "smys", "stress_od")


def line_types_table(types):
    """The text of a -rod_line_types table of the LineTypes ``types``."""
    rows = [list(COLUMNS)] + [t.row() for t in types]
    widths = [max(len(row[k]) for row in rows) for k in range(len(COLUMNS))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip()
                     for row in rows) + "\n"


@dataclass(frozen=True)
class Line:
    """The line from S = 0: ``sections`` a sequence of (LineType, length m) or
    (LineType, length m, elements), with ``element_length`` (m) the elements of those
    without a count (each at least 1). ``contents_density`` (kg/m^3) and
    ``internal_pressure`` at the top (Pa) give the reported pressures and wall tension
    (quantities/pressures.py)."""

    sections: tuple
    element_length: float = 1.0
    contents_density: float = 0.0
    internal_pressure: float = 0.0

    def __post_init__(self):
        if not _real("Line.element_length", self.element_length) > 0:
            raise RodInputError(f"Line.element_length {self.element_length!r}: must be a "
                                "positive length (m), the elements of the sections without "
                                "a count")
        _real("Line.contents_density", self.contents_density)
        _real("Line.internal_pressure", self.internal_pressure)
        if isinstance(self.sections, (str, bytes)) or not hasattr(self.sections, "__len__") \
                or not len(self.sections):
            raise RodInputError("Line.sections: a sequence of (LineType, length m) or "
                                "(LineType, length m, elements)")
        for k, entry in enumerate(self.sections):
            owner = f"Line.sections[{k}]"
            if isinstance(entry, (str, bytes)) or not hasattr(entry, "__len__") \
                    or len(entry) not in (2, 3) or not isinstance(entry[0], LineType):
                raise RodInputError(f"{owner} {entry!r}: expected (LineType, length m) or "
                                    "(LineType, length m, elements)")
            if not _real(f"{owner} length", entry[1]) > 0:
                raise RodInputError(f"{owner}: the length {entry[1]!r} must be positive (m)")
            if len(entry) == 3 and (isinstance(entry[2], (bool, np.bool_))
                                    or not isinstance(entry[2], (int, np.integer))
                                    or entry[2] < 1):
                raise RodInputError(f"{owner}: the element count {entry[2]!r} must be a "
                                    "whole number of at least 1")

    def types(self):
        """The distinct LineTypes, in the order met; RodInputError for two types of one
        name that differ."""
        found = {}
        for entry in self.sections:
            kind = entry[0]
            if found.setdefault(kind.name, kind).row() != kind.row():
                raise RodInputError(f"two different line types are named {kind.name}")
        return list(found.values())

    def sections_text(self):
        """-rod_sections TYPE:LENGTH:ELEMENTS,..."""
        parts = []
        for entry in self.sections:
            kind, length = entry[0], float(entry[1])
            count = entry[2] if len(entry) > 2 else max(1, round(length / self.element_length))
            parts.append(f"{kind.name}:{_number(length)}:{int(count)}")
        return ",".join(parts)

    @property
    def length(self):
        """m."""
        return float(sum(entry[1] for entry in self.sections))


@dataclass(frozen=True)
class End:
    """One end of the line: ``kind`` 'pin' (held in position: an anchor, a hang-off),
    'clamp' (position and frame) or 'free'; ``position`` (3,), m, absolute, z up (a
    held end's); a flex joint at a pin of rotational stiffness ``stiffness`` (N m/rad)
    about ``axis`` (3,) (None: the line's direction at that end in its start shape,
    Scene.joint_axis; docs/riser.md §8); ``force`` (3,), N, a dead force
    at a free end."""

    kind: str = "pin"
    position: tuple = None
    stiffness: float = 0.0
    axis: tuple = None
    force: tuple = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise RodInputError(f"End.kind {self.kind!r}: use one of {', '.join(KINDS)}")
        _real("End.stiffness", self.stiffness)
        for name in ("position", "axis", "force"):
            _optional(f"End.{name}", getattr(self, name), _reals, (3,))

    @classmethod
    def anchor(cls, position):
        """A pinned end at ``position`` (m), on the seabed or above it."""
        return cls("pin", tuple(position))

    @classmethod
    def hang_off(cls, position, flex_joint=0.0, axis=None):
        """The vessel's end at ``position`` (m): a pin, or a flex joint of stiffness
        ``flex_joint`` (N m/rad) about ``axis`` (default: the line's direction at the
        hang-off in its catenary, where the joint is unloaded: Scene.joint_axis)."""
        return cls("pin", tuple(position), flex_joint, None if axis is None else tuple(axis))


@dataclass(frozen=True)
class Attachment:
    """A clump weight, a buoyancy module or a point force at arc length ``S`` (m):
    ``mass`` in air (kg), displaced ``volume`` (m^3), ``force`` (3,), N, drag area
    ``cda`` = C_d A (m^2) in a current (scenes/point_loads.py)."""

    S: float
    mass: float = 0.0
    volume: float = 0.0
    force: tuple = (0.0, 0.0, 0.0)
    cda: float = 0.0
    name: str = None

    def __post_init__(self):
        for name in ("S", "mass", "volume", "cda"):
            _real(f"Attachment.{name}", getattr(self, name))
        _reals("Attachment.force", self.force, (3,))
        if self.name is not None and (not isinstance(self.name, str) or "\n" in self.name):
            raise RodInputError(f"Attachment.name {self.name!r}: a name is one line of text")


@dataclass(frozen=True)
class Environment:
    """The sea: a flat seabed at height ``seabed`` (m; None: none) of stiffness
    ``seabed_stiffness`` (N/m^2; None: weight / 1 mm) with Coulomb friction
    ``seabed_friction`` (None: none; mu, or (mu_axial, mu_lateral)) of stick stiffness
    ``seabed_friction_stiffness`` (N/m^2; None: a tenth of the seabed's; docs/riser.md
    §3b), the sea surface at height
    ``surface`` (m; None: the higher held end), a ``current``: None, a velocity (3,) in
    m/s (uniform), or a profile of rows (depth m, ux, uy, uz m/s) below the surface;
    ``water_density`` (kg/m^3) and ``gravity`` (m/s^2)."""

    seabed: float = None
    seabed_stiffness: float = None
    seabed_friction: object = None
    seabed_friction_stiffness: float = None
    surface: float = None
    current: object = None
    water_density: float = 1025.0
    gravity: float = 9.80665

    def __post_init__(self):
        for name in ("seabed", "seabed_stiffness", "seabed_friction_stiffness", "surface"):
            _optional(f"Environment.{name}", getattr(self, name), _real)
        _optional("Environment.seabed_friction", self.seabed_friction, _reals, (1, 2))
        _real("Environment.water_density", self.water_density)
        _real("Environment.gravity", self.gravity)
        if self.current is not None:
            try:
                shape = np.shape(self.current)
            except ValueError:                  # rows of several lengths
                shape = None
            if shape != (3,) and not (shape and len(shape) == 2 and shape[1] == 4):
                raise RodInputError(f"Environment.current {self.current!r}: a velocity (3 "
                                    "numbers, m/s) or rows (depth m, ux, uy, uz m/s)")
            _reals("Environment.current", self.current, (int(np.prod(shape)),))

    def profile(self):
        """(depths (m,), velocities (m, 3)) of a current profile, None for a uniform
        current or none."""
        rows = None if self.current is None else np.asarray(self.current, dtype=float)
        if rows is None or rows.ndim == 1:
            return None
        if rows.ndim != 2 or rows.shape[1] != 4:
            raise RodInputError("Environment.current: a velocity (3,) or rows (depth, ux, "
                                "uy, uz)")
        return rows[:, 0].copy(), rows[:, 1:].copy()


@dataclass(frozen=True)
class Model:
    """A line between two ends in the sea, with attachments, solved in ``steps``
    continuation steps from ``initial_shape`` ('catenary': the catenary of the sections;
    'straight'); ``options`` {name: value} any other -rod_* option, without 'rod_'
    (e.g. {'al_rtol': 1e-10}). Solve it with api.run.solve."""

    line: Line
    start: End
    end: End
    environment: Environment = field(default_factory=Environment)
    attachments: tuple = ()
    steps: int = 1
    initial_shape: str = "catenary"
    options: dict = field(default_factory=dict)

    def __post_init__(self):
        for name, kind in (("line", Line), ("start", End), ("end", End),
                           ("environment", Environment)):
            if not isinstance(getattr(self, name), kind):
                raise RodInputError(f"Model.{name}: expected an api.{kind.__name__}, not "
                                    f"{type(getattr(self, name)).__name__}")
        if isinstance(self.attachments, (str, bytes)) or not all(
                isinstance(a, Attachment) for a in self.attachments):
            raise RodInputError("Model.attachments: a sequence of api.Attachment")
        if isinstance(self.steps, (bool, np.bool_)) or not isinstance(
                self.steps, (int, np.integer)) or self.steps < 1:
            raise RodInputError(f"Model.steps {self.steps!r}: a whole number of at least 1")
        if not isinstance(self.initial_shape, str):
            raise RodInputError(f"Model.initial_shape {self.initial_shape!r}: 'catenary' or "
                                "'straight'")
        if not isinstance(self.options, dict) or not all(
                isinstance(name, str) for name in self.options):
            raise RodInputError("Model.options: a dict {name: value} of -rod_* options "
                                "without 'rod_' (e.g. {'al_rtol': 1e-10})")

    def option_texts(self, line_types="<line types>"):
        """{'rod_<name>': text} of the options this model stands for; ``line_types`` the
        name said for the line types' table (the table itself: ``line_types_text``)."""
        texts = {"rod_line_types": line_types, "rod_sections": self.line.sections_text(),
                 "rod_steps": str(int(self.steps)), "rod_initial_shape": self.initial_shape}
        if self.line.contents_density:
            texts["rod_contents_density"] = _number(self.line.contents_density)
        if self.line.internal_pressure:
            texts["rod_internal_pressure"] = _number(self.line.internal_pressure)
        for which, end in (("start", self.start), ("end", self.end)):
            if end.kind not in KINDS:
                raise RodInputError(f"Model.{which}: kind {end.kind!r}; use one of {KINDS}")
            texts[f"rod_{which}"] = end.kind
            if end.position is not None:
                texts[f"rod_{which}_position"] = _numbers(end.position)
            if end.stiffness:
                texts[f"rod_{which}_rotational_stiffness"] = _number(end.stiffness)
            if end.axis is not None:
                texts[f"rod_{which}_joint_axis"] = _numbers(end.axis)
            if end.force is not None:
                texts[f"rod_{which}_force"] = _numbers(end.force)
        sea = self.environment
        for name, value in (("seabed", sea.seabed), ("seabed_stiffness", sea.seabed_stiffness),
                            ("seabed_friction_stiffness", sea.seabed_friction_stiffness),
                            ("sea_surface", sea.surface)):
            if value is not None:
                texts[f"rod_{name}"] = _number(value)
        if sea.seabed_friction is not None:
            texts["rod_seabed_friction"] = _numbers(np.atleast_1d(sea.seabed_friction))
        if sea.current is not None:
            if sea.profile() is None:
                texts["rod_current"] = _numbers(sea.current)
            else:
                texts["rod_current_profile"] = "<current profile>"
        if sea.water_density != 1025.0 or sea.gravity != 9.80665:
            texts["rod_water_density"] = _number(sea.water_density)
            texts["rod_gravity"] = _number(sea.gravity)
        if self.attachments:
            texts["rod_point_loads"] = "<attachments>"
        for name, value in self.options.items():
            if name in MODEL_OPTIONS or f"rod_{name}" in texts:
                raise RodInputError(f"Model.options {name!r}: the model's own fields give "
                                    "it (or solve's output=); restarts are the command "
                                    "line's (Model.write_options)")
            texts[f"rod_{name}"] = (value if isinstance(value, str) else
                                    str(int(value)) if isinstance(value, (bool, int)) else
                                    _numbers(value))
        return texts

    def write_options(self, path):
        """Write the model as an options file ``path`` (``python -m petsc_rod
        -options_file path`` solves it) and the tables it names beside it: ``path`` with
        '.line_types.txt', '.point_loads.txt', '.current.txt' for '.opts'. Call it on
        one rank."""
        stem = str(path).removesuffix(".opts")
        files = {"rod_line_types": (f"{stem}.line_types.txt", self.line_types_text())}
        if self.attachments:
            files["rod_point_loads"] = (f"{stem}.point_loads.txt", self.attachment_table())
        profile = self.environment.profile()
        if profile is not None:
            rows = np.column_stack(profile)
            files["rod_current_profile"] = (f"{stem}.current.txt", "".join(
                " ".join(_number(v) for v in row) + "\n" for row in rows))
        texts = self.option_texts()
        for name, (file, content) in files.items():
            with open(file, "w", encoding="utf-8") as out:
                out.write(content)
            texts[name] = file
        with open(path, "w", encoding="utf-8") as out:
            out.write("# written by petsc_rod.api.Model.write_options\n"
                      + "".join(f"-{name} {text}\n" for name, text in texts.items()))

    def line_types_text(self):
        """The -rod_line_types table of the line's types."""
        return line_types_table(self.line.types())

    def attachment_table(self):
        """The attachments as a -rod_point_loads table's text (s, mass, volume, fx, fy,
        fz, cda, name)."""
        rows = ["s mass volume fx fy fz cda name"]
        for k, a in enumerate(self.attachments):
            name = (a.name or f"point_{k + 1}").replace(" ", "_")
            rows.append(" ".join([_number(a.S), _number(a.mass), _number(a.volume),
                                  _numbers(a.force).replace(",", " "), _number(a.cda), name]))
        return "\n".join(rows) + "\n"
