"""A line as engineers specify it: a sequence of sections of named line types from
S = 0 (docs/riser.md, "Line types and sections").

A line type is what a data sheet gives per metre (outer diameter, mass in air, bending,
torsional and axial stiffness, drag coefficient and diameter); a section is a stretch of
the line [start, end] of one line type, whose stiffness may taper linearly along it (a
bend stiffener). The scene's numerical data along S (stiffness_at, axial_stiffness_at,
the weight pieces and the drag per metre) are read from the sections here.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError


@dataclass
class Section:
    """One section: S in [start, end] (m) of the line type ``name``.

    stiffness_start, stiffness_end: (K1, K2, K3) at its two ends, N m^2 (equal unless
    tapered); axial_stiffness: EA, N (inf: inextensible); weight: the load per metre,
    N/m, (3,) (the submerged weight along -z); drag: c = rho Cd D / 2, kg/m^2, of the
    normal Morison drag (0: none); od, id: outer and inner diameter, m (id 0: no bore);
    mass: kg/m in air; smys: the specified minimum yield stress of the pipe's wall, Pa
    (NaN: not given; quantities/stresses.py); stress_od: the outer diameter of the pipe's
    wall, m, below a buoyancy jacket or coating (NaN: od; quantities/pressures.py).
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

    def __post_init__(self):
        self.stiffness_start = np.asarray(self.stiffness_start, dtype=float)
        self.stiffness_end = np.asarray(self.stiffness_end, dtype=float)
        self.weight = np.zeros(3) if self.weight is None else np.asarray(self.weight, float)

    def stiffness_is(self, stiffness):
        """Whether the section's stiffness is ``stiffness`` (3,) all along."""
        return bool(np.array_equal(self.stiffness_start, stiffness)
                    and np.array_equal(self.stiffness_end, stiffness))


def section_index(sections, S):
    """The index of the section holding each S (...); a section end belongs to the
    section after it, the line's end S = L to the last section."""
    ends = np.array([section.start for section in sections[1:]])
    return np.searchsorted(ends, np.asarray(S, dtype=float), side="right")


def piecewise_linear(sections, S, start_name, end_name, inside=None):
    """The (...)-shaped S mapped to (..., k): each section's value ``start_name`` at its
    start varying linearly to ``end_name`` at its end. ``inside`` (S's shape; default S)
    picks the section: at a section end, the value of the section that holds ``inside``
    (a one-sided limit)."""
    index = section_index(sections, S if inside is None else inside)
    starts = np.array([getattr(s, start_name) for s in sections], dtype=float)
    ends = np.array([getattr(s, end_name) for s in sections], dtype=float)
    lo = np.array([s.start for s in sections])
    hi = np.array([s.end for s in sections])
    fraction = np.clip((np.asarray(S, dtype=float) - lo[index]) / (hi - lo)[index], 0.0, 1.0)
    fraction = fraction[..., None] if starts.ndim > 1 else fraction
    return starts[index] + fraction * (ends[index] - starts[index])


def piecewise_constant(sections, S, name):
    """Each S (...) mapped to the value ``name`` of its section."""
    values = np.array([getattr(s, name) for s in sections], dtype=float)
    return values[section_index(sections, S)]


# The columns of a line-type table (-rod_line_types): required, and optional.
LINE_TYPE_COLUMNS = ("name", "od", "mass", "gj")
LINE_TYPE_OPTIONAL = ("ei", "ei1", "ei2", "ei_start", "ei_end", "ea", "cd", "drag_d", "id",
                      "smys", "stress_od")
# The ways of giving the bending stiffness, one per line type (the others' columns left
# blank, '-'): isotropic, anisotropic (about d1 and d2), and a linear taper along each
# section of the type.
BENDING_FORMS = (("ei",), ("ei1", "ei2"), ("ei_start", "ei_end"))


@dataclass
class LineType:
    """A line type as a data sheet gives it: outer diameter ``od`` (m), ``mass`` in air
    with contents (kg/m), bending stiffnesses about d1 and d2 at the start and end of
    each section of the type (``bending_start``, ``bending_end``, N m^2, equal unless
    tapered), torsional ``gj`` (N m^2), axial ``ea`` (N, inf: inextensible), normal drag
    coefficient ``cd``, hydrodynamic diameter ``drag_d`` (m) and inner diameter ``id``
    (m, 0: no bore; the internal pressure's area, quantities/pressures.py), and the wall's
    specified minimum yield stress ``smys`` (Pa, NaN: not given; quantities/stresses.py), and
    ``stress_od`` the outer diameter of the steel wall that carries the wall tension and
    the stresses (m; default ``od``: a buoyancy jacket or a coating has its own larger
    ``od`` for weight and drag, but the external pressure on it is carried by it)."""

    name: str
    od: float
    mass: float
    bending_start: np.ndarray
    bending_end: np.ndarray
    gj: float
    ea: float = np.inf
    cd: float = 0.0
    drag_d: float = np.nan
    id: float = 0.0
    smys: float = np.nan
    stress_od: float = np.nan

    def submerged_weight(self, water_density, gravity):
        """(mass - rho_w pi od^2 / 4) g, N/m: positive sinks, negative floats."""
        return (self.mass - water_density * np.pi * self.od**2 / 4) * gravity

    def section(self, start, end, water_density, gravity):
        """The Section [start, end] (m) of this type in water of ``water_density``
        (kg/m^3) under ``gravity`` (m/s^2, along -z)."""
        return Section(self.name, start, end,
                       np.append(self.bending_start, self.gj),
                       np.append(self.bending_end, self.gj), self.ea,
                       np.array([0.0, 0.0, -self.submerged_weight(water_density, gravity)]),
                       0.5 * water_density * self.cd * self.drag_d, self.od, self.mass,
                       self.id, self.smys,
                       self.od if np.isnan(self.stress_od) else self.stress_od)


def line_types_from_table(table, option, largest=np.inf):
    """{name: LineType} from the columns of a -rod_line_types table (petsc_rod/tables.py
    read_table with LINE_TYPE_COLUMNS and LINE_TYPE_OPTIONAL); RodInputError naming
    ``option`` for a row that does not give exactly one bending form (the other forms'
    columns left blank, '-') or gives a value out of range: the bounds of the options'
    numbers (``largest``, cli/options.MAX_MAGNITUDE), every magnitude at most it and a
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
    column = lambda name, default: table.get(name, np.full(rows, default))
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
    return {name: LineType(name, table["od"][i], table["mass"][i], start[i], end[i],
                           table["gj"][i], ea[i], cd[i], drag_d[i], inner[i], smys[i],
                           wall[i])
            for i, name in enumerate(names)}


def parse_sections(text, option):
    """[(type name, length m, elements or None)] from 'TYPE:LENGTH[:ELEMENTS],...';
    RodInputError naming ``option`` for an entry of another form, a length that is not
    positive or a count that is not a whole number of at least 1."""
    entries = []
    for entry in text.split(","):
        parts = entry.strip().split(":")
        if len(parts) not in (2, 3) or not parts[0]:
            raise RodInputError(f"{option}: '{entry}' is not TYPE:LENGTH[:ELEMENTS]")
        try:
            length = float(parts[1])
        except ValueError:
            raise RodInputError(f"{option}: '{entry}': the length '{parts[1]}' is not a "
                                "number (m)") from None
        if not (np.isfinite(length) and length > 0):
            raise RodInputError(f"{option}: '{entry}': the length must be positive (m)")
        count = None
        if len(parts) == 3:
            try:
                count = int(parts[2])
            except ValueError:
                count = 0
            if count < 1:
                raise RodInputError(f"{option}: '{entry}': the element count '{parts[2]}' "
                                    "must be a whole number of at least 1")
        entries.append((parts[0], length, count))
    return entries


def section_elements(lengths, counts, total):
    """The element count of each section: its own where given, else the share of the
    ``total`` left over in proportion to its length, at least 1 each, the shares rounded
    down and the elements left given to the largest remainders (so that the counts add
    up to ``total`` whenever that leaves each section one)."""
    lengths = np.asarray(lengths, dtype=float)
    given = np.array([c is not None for c in counts])
    result = np.array([c or 0 for c in counts])
    free = ~given
    if np.any(free):
        left = max(total - result[given].sum(), int(free.sum()))
        share = lengths[free] / lengths[free].sum() * left
        whole = np.maximum(1, np.floor(share)).astype(int)
        spare = left - int(whole.sum())
        if spare > 0:
            order = np.argsort(-(share - np.floor(share)), kind="stable")[:spare]
            whole[order] += 1
        result[free] = whole
    return result
