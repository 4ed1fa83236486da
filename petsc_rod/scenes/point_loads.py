"""Attachments: point masses, clump weights, buoyancy modules and point forces at given
arc lengths (docs/riser.md, "Attachments"), read from the options into the scene's point
loads (S_p, P_p): arc lengths (n_p,) in m and dead forces (n_p, 3) in N.

A row of ``-rod_point_loads FILE`` gives the arc length ``s`` (m) and any of ``mass``
(kg in air), ``volume`` (displaced volume, m^3), ``fx``, ``fy``, ``fz`` (a point force,
N), ``cda`` (a drag area C_d A, m^2: the drag 1/2 rho_w C_d A |v| v in a current) and
``name`` (a label); its force is

    P = (fx, fy, fz) + (rho_w volume - mass) g e_z,

z up, rho_w the water density (-rod_water_density, kg/m^3) and g the gravity
(-rod_gravity, m/s^2): a clump weight pulls down, a buoyancy module up. The buoyancy
rho_w g volume e_z holds in the water only: the volumes are kept beside the forces so
that above -rod_sea_surface the term takes it off again (physics/point_loads.py). The quick form
``-rod_point_load S,fx,fy,fz[,...]`` gives forces alone. The term that applies them is
physics/point_loads.py.
"""

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.tables import numbered_rows

# The columns a table may name; ``s`` is required. Every column but ``name`` is a number.
COLUMNS = ("s", "mass", "volume", "fx", "fy", "fz", "cda", "name")
COLUMN_UNITS = {"s": "m", "mass": "kg", "volume": "m^3", "fx": "N", "fy": "N", "fz": "N",
                "cda": "m^2"}


def attachment_forces(columns, density, gravity):
    """P = (fx, fy, fz) + (rho_w V - m) g e_z (module docstring), N, (n_p, 3), from
    the numeric ``columns`` {name: (n_p,)} (absent ones zero)."""
    n = len(columns["s"])
    get = lambda name: np.asarray(columns.get(name, np.zeros(n)), dtype=float)  # noqa: E731
    force = np.stack([get("fx"), get("fy"), get("fz")], axis=-1)
    force[:, 2] += (density * get("volume") - get("mass")) * gravity
    return force


def beyond_the_line(S, length):
    """The index of the first arc length outside [0, L], or None."""
    outside = np.flatnonzero((np.asarray(S) < 0) | (np.asarray(S) > length))
    return int(outside[0]) if outside.size else None


def read_point_loads(path, density, gravity, length, largest=np.inf):
    """(S (n_p,), forces (n_p, 3), names (n_p,), drag areas (n_p,), volumes (n_p,)) from
    the table ``path`` (module
    docstring): whitespace or comma separated, a header row naming the columns, '#'
    starts a comment. Every problem is one RodInputError that says what to fix: no
    file, no ``s`` column, an unknown or repeated column, a row of another length, a
    value that is not a finite number of magnitude at most ``largest``, a negative mass,
    volume or drag area, an arc length beyond the line [0, ``length``]."""
    option = f"-rod_point_loads {path}"

    def refuse(what):
        raise RodInputError(f"{option}: {what}")

    rows = numbered_rows(path, "-rod_point_loads")
    if not rows:
        refuse("is empty; give a header row (s and any of mass volume fx fy fz name) and "
               "one row per attachment")
    header = [name.lower() for name in rows[0][1]]
    unknown = [name for name in header if name not in COLUMNS]
    if unknown:
        refuse(f"unknown column {unknown[0]!r} in the header row; the columns are "
               + " ".join(COLUMNS) + " (s required)")
    if len(set(header)) != len(header):
        refuse("a column is named twice in the header row")
    if "s" not in header:
        refuse("no 's' column (the arc length of each attachment, m) in the header row "
               "'" + " ".join(header) + "'")
    body = rows[1:]
    if not body:
        refuse("has a header row but no attachment; give one row per attachment")
    for number, row in body:
        if len(row) != len(header):
            refuse(f"line {number} has {len(row)} values for the {len(header)} columns "
                   f"{' '.join(header)}")
    columns = {}
    for c, name in enumerate(header):
        values = [row[c] for _, row in body]
        if name == "name":
            columns[name] = values
            continue
        numbers = np.empty(len(values))
        for k, text in enumerate(values):
            try:
                numbers[k] = float(text)
            except ValueError:
                refuse(f"line {body[k][0]}, column {name}: {text!r} is not a number "
                       f"({COLUMN_UNITS[name]})")
            if not np.isfinite(numbers[k]) or abs(numbers[k]) > largest:
                refuse(f"line {body[k][0]}, column {name}: {text} is not a finite number "
                       f"of magnitude at most {largest:g} ({COLUMN_UNITS[name]})")
        if name in ("mass", "volume", "cda") and np.any(numbers < 0):
            k = int(np.flatnonzero(numbers < 0)[0])
            refuse(f"line {body[k][0]}, column {name}: a {name} must not be negative")
        columns[name] = numbers
    k = beyond_the_line(columns["s"], length)
    if k is not None:
        refuse(f"line {body[k][0]}: s = {columns['s'][k]:.6g} m is beyond the line (0 <= s "
               f"<= L = {length:.6g} m, its length); give an arc length on the line")
    names = columns.pop("name", [f"point {k + 1}" for k in range(len(body))])
    areas = columns.get("cda", np.zeros(len(body)))
    volumes = columns.get("volume", np.zeros(len(body)))
    return (columns["s"], attachment_forces(columns, density, gravity), tuple(names), areas,
            volumes)


def quick_point_loads(values, length):
    """(S, forces, names, drag areas and volumes (zero)) of -rod_point_load
    S,fx,fy,fz[,...] (a flat array of 4 numbers per point), each S on the line
    [0, ``length``]."""
    values = np.asarray(values, dtype=float)
    if values.size % 4:
        raise RodInputError(f"-rod_point_load: {values.size} numbers; give 4 (S,fx,fy,fz: "
                            "m, N) per point")
    table = values.reshape(-1, 4)
    k = beyond_the_line(table[:, 0], length)
    if k is not None:
        raise RodInputError(
            f"-rod_point_load: point {k + 1} at S = {table[k, 0]:.6g} m is beyond the line "
            f"(0 <= S <= L = {length:.6g} m, its length); give an arc length on the line")
    return (table[:, 0], table[:, 1:], tuple(f"point {k + 1}" for k in range(len(table))),
            np.zeros(len(table)), np.zeros(len(table)))
