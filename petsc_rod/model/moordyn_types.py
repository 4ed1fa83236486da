"""MoorDyn's line types as petsc_rod's (model/line_type.LineType), with the bending and
torsional stiffness MoorDyn does not give (docs/systems.md, "EI = 0").

MoorDyn's lumped-mass line has no torsion and, for most chains and ropes, EI = 0; the
rod needs K1, K2, K3 > 0. A line type of EI = 0 gets a bending stiffness whose bending
length sqrt(EI / T) is BENDING_FRACTION of the line's element h at a tension T of the
line's scale, EI = (f h)^2 T, T = |w| D (its wet weight w, N/m, times the water depth
D, m: the order of the tension at its top); every line type gets GJ = EI / (1 + nu),
nu = POISSON (a solid round section: J = 2 I, G = E / 2 (1 + nu)).
"""

import math

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.line_type import LineType

# The bending length sqrt(EI / T) of a line given EI = 0, as a fraction of its element:
# below an element, so that the mesh, not the substituted EI, sets the shape at the
# ends and the touchdown (the end tensions change by about (f h kappa)^2, kappa <= w / T
# the catenary's curvature); not smaller, so that the bending terms of the global step,
# EI / h^3 against the tension's T / h, keep a ratio f^2 = 1e-2 well above round-off.
BENDING_FRACTION = 0.1
# Poisson's ratio of the torsional stiffness GJ = EI / (1 + nu) MoorDyn does not give.
POISSON = 0.3
# The columns of a MoorDyn version 2 line type, the first ten required.
TYPE_COLUMNS = ("TypeName", "Diam", "Mass/m", "EA", "BA/-zeta", "EI", "Cd", "Ca", "CdAx",
                "CaAx")


def number(where, column, text):
    """``text`` as a float; RodInputError naming ``where`` and ``column`` otherwise."""
    try:
        value = float(text)
    except ValueError:
        raise RodInputError(f"{where}: {column} {text!r} is not a number") from None
    if not math.isfinite(value):
        raise RodInputError(f"{where}: {column} {text!r} is not a finite number")
    return value


def stiffness(where, column, text, notes):
    """EA or EI (N, N m^2) from its column: a number, or 'static|dynamic...' (MoorDyn's
    viscoelastic forms) whose static value is the one of a static equilibrium (said in
    ``notes``); a tabulated (nonlinear) stiffness is refused."""
    first = text.split("|")[0]
    try:
        float(first)
    except ValueError:
        raise RodInputError(f"{where}: {column} {text!r}: a nonlinear (tabulated) "
                            "stiffness; petsc_rod's line is linearly elastic: give a "
                            "number") from None
    value = number(where, column, first)
    if "|" in text:
        notes.append(f"{where}: {column} {text}: the static value {value:g} is used (the "
                     "others are MoorDyn's dynamic stiffness)")
    return value


def type_row(row, place):
    """{name, od, mass, ea, ei, cd, ca} of one LINE TYPES row (tokens) at ``place``
    ('path:line'), notes of the viscoelastic forms said in row['notes']."""
    where = f"{place}: LINE TYPES: line type {row[0]}"
    if len(row) < len(TYPE_COLUMNS):
        raise RodInputError(
            f"{where}: {len(row)} columns, a MoorDyn version 2 line type has "
            f"{len(TYPE_COLUMNS)} or more ({' '.join(TYPE_COLUMNS)}); a version 1 file "
            "(no EI column) is not read")
    notes = []
    values = dict(name=row[0], od=number(where, "Diam", row[1]),
                  mass=number(where, "Mass/m", row[2]),
                  ea=stiffness(where, "EA", row[3], notes),
                  ei=stiffness(where, "EI", row[5], notes),
                  cd=number(where, "Cd", row[6]), ca=number(where, "Ca", row[7]),
                  notes=notes)
    for column in ("od", "mass", "ea"):
        if not values[column] > 0:
            raise RodInputError(f"{where}: {dict(od='Diam', mass='Mass/m', ea='EA')[column]}"
                                f" {values[column]:g} must be positive")
    if values["ei"] < 0 or values["cd"] < 0 or values["ca"] < 0:
        raise RodInputError(f"{where}: EI, Cd and Ca must not be negative")
    return values


def line_types(rows, lines, depth, water_density, gravity, path):
    """{name: LineType} of MoorDyn's line types ``rows`` ({name, od, mass, ea, ei, cd, ca}),
    and the notes of what was substituted. ``lines`` {type name: [(length m, element
    length m), ...]} of the lines of each type; ``depth`` (m; None: unknown, then the
    type's longest line stands for D). od and drag diameter: MoorDyn's Diam (the
    volume-equivalent diameter, so that the wet weight (mass - rho pi d^2 / 4) g is
    MoorDyn's); Cd on d l as MoorDyn's; Ca, the transverse added-mass coefficient, for the
    modes; EA as given; EI as given, or the rule of the
    module's docstring; GJ = EI / (1 + POISSON)."""
    types, notes = {}, []
    for row in rows:
        notes.extend(row["notes"])
        name, ei = row["name"], row["ei"]
        if not lines.get(name):                   # a type no line uses: not in the system
            continue
        if ei == 0:
            weight = abs(row["mass"] - water_density * np.pi * row["od"] ** 2 / 4) * gravity
            span = depth if depth else max(length for length, _ in lines[name])
            tension = weight * span
            if tension == 0:
                raise RodInputError(f"{path}: LINE TYPES: line type {name}: EI 0 and no "
                                    "weight in water to set the bending stiffness by "
                                    "(docs/systems.md); give its EI")
            element = min(h for _, h in lines[name])
            ei = (BENDING_FRACTION * element) ** 2 * tension
            notes.append(
                f"line type {name}: EI 0 in the file, given EI = {ei:.4g} N m^2 (bending "
                f"length {BENDING_FRACTION:g} of its {element:.4g} m elements at T = "
                f"{tension:.4g} N, its wet weight {weight:.4g} N/m times "
                f"{'the water depth' if depth else 'its length'} {span:.4g} m), too "
                "small to matter (docs/systems.md)")
        types[name] = LineType(name, row["od"], row["mass"], ei, ei / (1 + POISSON),
                               row["ea"], row["cd"], ca=row["ca"])
    if types:
        notes.append(f"every line type: GJ = EI / {1 + POISSON:g} (a solid round section, "
                     f"Poisson's ratio {POISSON:g}): MoorDyn gives no torsional stiffness")
    return types, notes
