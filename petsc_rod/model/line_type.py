"""Line types as a data sheet gives them, and the sections of a line they make
(docs/riser.md, "Line types and sections").

A line type is what a data sheet gives per metre (outer diameter, mass in air, bending,
torsional and axial stiffness, drag coefficient and diameter, bore, yield stress); a
section is a stretch of the line [start, end] of one line type in a given sea, whose
stiffness may taper linearly along it (a bend stiffener): the numbers along S the scene
reads (scenes/line.py).
"""

from dataclasses import dataclass
import math

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.values import optional, real, reals


@dataclass
class Section:
    """One section: S in [start, end] (m) of the line type ``name``.

    stiffness_start, stiffness_end: (K1, K2, K3) at its two ends, N m^2 (equal unless
    tapered); axial_stiffness: EA, N (inf: inextensible); weight: the load per metre,
    N/m, (3,) (the submerged weight along -z); drag: c = rho Cd D / 2, kg/m^2, of the
    normal Morison drag (0: none); od, id: outer and inner diameter, m (id 0: no bore);
    mass: kg/m in air; smys: the specified minimum yield stress of the pipe's wall, Pa
    (NaN: not given; quantities/stresses.py); stress_od: the outer diameter of the pipe's
    wall, m, below a buoyancy jacket or coating (NaN: od; quantities/pressures.py);
    ca: the added-mass coefficient normal to the line, 1, of the modes (analysis/mass.py;
    NaN: not given, -rod_modes_added_mass's).
    """

    name: str
    start: float
    end: float
    stiffness_start: np.ndarray
    stiffness_end: np.ndarray
    axial_stiffness: float = np.inf
    weight: np.ndarray = None
    drag: float = 0.0
    od: float = np.nan
    mass: float = np.nan
    id: float = 0.0
    smys: float = np.nan
    stress_od: float = np.nan
    ca: float = np.nan

    def __post_init__(self):
        self.stiffness_start = np.asarray(self.stiffness_start, dtype=float)
        self.stiffness_end = np.asarray(self.stiffness_end, dtype=float)
        self.weight = np.zeros(3) if self.weight is None else np.asarray(self.weight, float)

    def stiffness_is(self, stiffness):
        """Whether the section's stiffness is ``stiffness`` (3,) all along."""
        return bool(np.array_equal(self.stiffness_start, stiffness)
                    and np.array_equal(self.stiffness_end, stiffness))


@dataclass(frozen=True)
class LineType:
    """A line type as a data sheet gives it: ``od`` outer diameter (m), ``mass`` in air
    with contents (kg/m), ``ei`` bending stiffness (N m^2; a pair (EI1, EI2) about d1
    and d2 for an anisotropic line), ``gj`` torsional stiffness (N m^2), ``ea`` axial
    stiffness (N; inf: inextensible), ``cd`` normal drag coefficient (1), ``drag_d``
    hydrodynamic diameter (m; None: the od), ``id`` inner diameter (m; 0: no bore; the
    internal pressure's area, quantities/pressures.py), ``ei_end`` (N m^2) the bending
    stiffness at the end of each section of the type where it tapers linearly from
    ``ei`` (a bend stiffener), ``smys`` the wall's yield stress (Pa; None: no
    utilisation, quantities/stresses.py), ``stress_od`` the steel wall's outer diameter under
    a jacket or coating (m; None: the od: a buoyancy jacket or a coating has its own
    larger od for weight and drag, but the external pressure on it is carried by it),
    ``ca`` the added-mass coefficient normal to the line of the modes (1; None: not
    given, -rod_modes_added_mass's, default 1; analysis/mass.py). The submerged weight is (mass - rho_w pi od^2 / 4) g. The values' ranges are
    checked with the line's (check_line_types)."""

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
    ca: float = None

    def __post_init__(self):
        owner = f"LineType {self.name!r}"
        if not isinstance(self.name, str) or not self.name or len(self.name.split()) != 1 \
                or any(c in self.name for c in ",:#"):
            raise RodInputError(f"{owner}: a name is one word without , : or #")
        for name in ("od", "mass", "gj", "cd", "id"):
            real(f"{owner}.{name}", getattr(self, name))
        real(f"{owner}.ea", self.ea, allow_inf=True)
        bending = reals(f"{owner}.ei", self.ei, (1, 2))
        for name in ("drag_d", "ei_end", "smys", "stress_od", "ca"):
            optional(f"{owner}.{name}", getattr(self, name), real)
        if self.ei_end is not None and bending.size != 1:
            raise RodInputError(f"line type {self.name}: a taper (ei_end) takes one ei")

    @property
    def bending_start(self):
        """(EI1, EI2) at the start of each section of the type, N m^2."""
        ei = np.ravel(np.asarray(self.ei, dtype=float))
        return np.array([ei[0], ei[-1]])

    @property
    def bending_end(self):
        """(EI1, EI2) at the end of each section of the type, N m^2 (the start's unless
        tapered)."""
        if self.ei_end is None:
            return self.bending_start
        return np.array([float(self.ei_end), float(self.ei_end)])

    def submerged_weight(self, water_density, gravity):
        """(mass - rho_w pi od^2 / 4) g, N/m: positive sinks, negative floats."""
        return (self.mass - water_density * np.pi * self.od**2 / 4) * gravity

    def section(self, start, end, water_density, gravity):
        """The Section [start, end] (m) of this type in water of ``water_density``
        (kg/m^3) under ``gravity`` (m/s^2, along -z)."""
        drag_d = self.od if self.drag_d is None else self.drag_d
        return Section(self.name, start, end,
                       np.append(self.bending_start, self.gj),
                       np.append(self.bending_end, self.gj), self.ea,
                       np.array([0.0, 0.0, -self.submerged_weight(water_density, gravity)]),
                       0.5 * water_density * self.cd * drag_d, self.od, self.mass,
                       self.id, np.nan if self.smys is None else self.smys,
                       self.od if self.stress_od is None else self.stress_od,
                       np.nan if self.ca is None else self.ca)


# The columns of a line-type table (-rod_line_types): required, and optional.
LINE_TYPE_COLUMNS = ("name", "od", "mass", "gj")
LINE_TYPE_OPTIONAL = ("ei", "ei1", "ei2", "ei_start", "ei_end", "ea", "cd", "drag_d", "id",
                      "smys", "stress_od", "ca")
# The ways of giving the bending stiffness, one per line type (the others' columns left
# blank, '-'): isotropic, anisotropic (about d1 and d2), and a linear taper along each
# section of the type.
BENDING_FORMS = (("ei",), ("ei1", "ei2"), ("ei_start", "ei_end"))


def table_columns(types):
    """The columns {name: (rows,)} a -rod_line_types table of the LineTypes ``types``
    reads as (tables.read_table: NaN for a blank)."""
    nan = np.nan
    rows = []
    for kind in types:
        ei = np.ravel(np.asarray(kind.ei, dtype=float))
        bending = ((nan, nan, nan, ei[0], kind.ei_end) if kind.ei_end is not None else
                   (ei[0], nan, nan, nan, nan) if ei.size == 1 else
                   (nan, ei[0], ei[1], nan, nan))
        rows.append((kind.od, kind.mass, kind.gj) + bending
                    + (kind.ea, kind.cd, nan if kind.drag_d is None else kind.drag_d,
                       kind.id, nan if kind.smys is None else kind.smys,
                       nan if kind.stress_od is None else kind.stress_od,
                       nan if kind.ca is None else kind.ca))
    numbers = np.array(rows, dtype=float).reshape(len(types), 15)
    names = ("od", "mass", "gj", "ei", "ei1", "ei2", "ei_start", "ei_end", "ea", "cd",
             "drag_d", "id", "smys", "stress_od", "ca")
    columns = {"name": [kind.name for kind in types]}
    columns.update({name: numbers[:, k] for k, name in enumerate(names)})
    return columns


def line_types_from_table(table, option, largest=np.inf):
    """{name: LineType} from the columns of a -rod_line_types table (petsc_rod/tables.py
    read_table with LINE_TYPE_COLUMNS and LINE_TYPE_OPTIONAL); RodInputError naming
    ``option`` for a row that does not give exactly one bending form (the other forms'
    columns left blank, '-') or gives a value out of range: the bounds of the options'
    numbers (``largest``, values.MAX_MAGNITUDE), every magnitude at most it and a
    stiffness, diameter or mass at least its inverse, as -rod_stiffness is."""
    names = table["name"]
    for name, values in table.items():
        if name == "name":
            continue
        big = np.flatnonzero(np.isfinite(values) & (np.abs(values) > largest))
        if big.size:
            row = int(big[0])
            raise RodInputError(f"{option}: line type {names[row]}: {name} "
                                f"{values[row]:g} is out of range: magnitudes above "
                                f"{largest:g} are refused, as in the options")
    rows = len(names)
    if len(set(names)) != rows:
        raise RodInputError(f"{option}: a line type is named twice")
    column = lambda name, default: table.get(name, np.full(rows, default))  # noqa: E731
    given = np.stack([np.all([np.isfinite(column(name, np.nan)) for name in form], axis=0)
                      for form in BENDING_FORMS])                  # (forms, rows)
    partly = np.stack([np.any([np.isfinite(column(name, np.nan)) for name in form], axis=0)
                       for form in BENDING_FORMS])
    bad = (given.sum(axis=0) != 1) | (partly.sum(axis=0) != 1)
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise RodInputError(
            f"{option}: line type {names[row]}: give its bending stiffness (N m^2) in one "
            "of the forms ei; ei1 and ei2 (about d1 and d2); ei_start and ei_end (tapered "
            "along each of its sections), the other columns left blank ('-')")
    form = np.argmax(given, axis=0)                                  # (rows,)
    ei, ei1, ei2, ei_start, ei_end = (column(name, np.nan) for name in
                                      ("ei", "ei1", "ei2", "ei_start", "ei_end"))
    # each form's (K1, K2) at a section's start and end
    forms = ((ei, ei, ei, ei), (ei1, ei2, ei1, ei2), (ei_start, ei_start, ei_end, ei_end))
    start, end = np.empty((rows, 2)), np.empty((rows, 2))
    for k, (k1_start, k2_start, k1_end, k2_end) in enumerate(forms):
        start[form == k] = np.stack([k1_start, k2_start], axis=1)[form == k]
        end[form == k] = np.stack([k1_end, k2_end], axis=1)[form == k]
    drag_d = np.where(np.isfinite(column("drag_d", np.nan)), column("drag_d", np.nan),
                      table["od"])
    ea = np.where(np.isnan(column("ea", np.inf)), np.inf, column("ea", np.inf))
    cd = np.where(np.isnan(column("cd", 0.0)), 0.0, column("cd", 0.0))
    inner = np.where(np.isnan(column("id", 0.0)), 0.0, column("id", 0.0))
    positive = {"od": table["od"], "mass": table["mass"], "gj": table["gj"], "ea": ea,
                "drag_d": drag_d, "ei": np.minimum(start, end).min(axis=1)}
    for name, values in positive.items():
        bad = ~(values >= 1 / largest) if name != "mass" else ~(values > 0)
        if np.any(bad):
            row = int(np.flatnonzero(bad)[0])
            least = f" (at least {1 / largest:g}, as in the options)" if values[row] > 0 else ""
            raise RodInputError(f"{option}: line type {names[row]}: {name} "
                                f"{values[row]:g} must be positive{least}")
        if name != "ea" and not np.all(np.isfinite(values)):
            row = int(np.flatnonzero(~np.isfinite(values))[0])
            raise RodInputError(f"{option}: line type {names[row]}: {name} must be finite "
                                "(only ea may be inf: inextensible)")
    bad = ~((inner >= 0) & (inner < table["od"]))
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise RodInputError(f"{option}: line type {names[row]}: id {inner[row]:g} must be "
                            f"0 or more and below od {table['od'][row]:g} (m)")
    smys = column("smys", np.nan)
    bad = ~np.isnan(smys) & ~((smys > 0) & np.isfinite(smys))
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise RodInputError(f"{option}: line type {names[row]}: smys {smys[row]:g} must be "
                            "a positive, finite yield stress (Pa), or blank ('-')")
    wall = column("stress_od", np.nan)
    wall = np.where(np.isnan(wall), table["od"], wall)
    bad = ~((wall > inner) & (wall <= table["od"]) & np.isfinite(wall))
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise RodInputError(f"{option}: line type {names[row]}: stress_od {wall[row]:g} must "
                            f"be above id {inner[row]:g} and at most od {table['od'][row]:g} (m)")
    if not np.all((cd >= 0) & np.isfinite(cd)):
        row = int(np.flatnonzero(~((cd >= 0) & np.isfinite(cd)))[0])
        raise RodInputError(f"{option}: line type {names[row]}: cd {cd[row]:g} must be a "
                            "finite number, 0 or more")
    ca = column("ca", np.nan)
    bad = ~np.isnan(ca) & ~((ca >= 0) & np.isfinite(ca))
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise RodInputError(f"{option}: line type {names[row]}: ca {ca[row]:g} must be a "
                            "finite added-mass coefficient, 0 or more, or blank ('-')")
    bending = [start[i, 0] if form[i] != 1 else (start[i, 0], start[i, 1])
               for i in range(rows)]
    return {name: LineType(name, table["od"][i], table["mass"][i], bending[i],
                           table["gj"][i], ea[i], cd[i], drag_d[i], inner[i],
                           end[i, 0] if form[i] == 2 else None,
                           None if np.isnan(smys[i]) else smys[i], wall[i],
                           None if np.isnan(ca[i]) else ca[i])
            for i, name in enumerate(names)}


def _values(kind):
    """The numbers of a LineType, comparable."""
    return (kind.od, kind.mass, tuple(np.ravel(kind.ei)), kind.gj, kind.ea, kind.cd,
            kind.drag_d, kind.id, kind.ei_end, kind.smys, kind.stress_od, kind.ca)


def check_line_types(types, option, largest):
    """Refuse LineTypes ``types`` whose values a -rod_line_types table of them would be
    refused for (line_types_from_table), or two types of one name that differ; the
    message names them as ``option``."""
    found = {}
    for kind in types:
        if _values(found.setdefault(kind.name, kind)) != _values(kind):
            raise RodInputError(f"two different line types are named {kind.name}")
    line_types_from_table(table_columns(list(found.values())), option, largest)
