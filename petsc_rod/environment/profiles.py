"""The environment's text files: a current profile (read_profile) and a seabed profile
or grid (read_seabed_profile), checked row by row; RodInputError naming the file."""

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.tables import numbered_rows, read_text


def read_profile(path, largest=np.inf):
    """(depths (m,), velocities (m, 3)) from a text file of rows 'depth ux uy uz' (m,
    m/s; '#' starts a comment), depths strictly increasing from 0 or more (below the sea
    surface: a negative one is a height z given for a depth), every magnitude at most
    ``largest`` (the bound of the options' numbers). RodInputError otherwise."""
    def refuse(what):
        raise RodInputError(f"-rod_current_profile {path}: {what}")

    lines = read_text(path, "-rod_current_profile").splitlines()
    rows = [line.split("#", 1)[0].replace(",", " ").split() for line in lines]
    rows = [row for row in rows if row]
    try:
        table = np.array([[float(v) for v in row] for row in rows], dtype=float)
    except ValueError:
        refuse("expected rows of 4 numbers: depth (m), ux, uy, uz (m/s)")
    if table.ndim != 2 or table.shape[0] == 0 or table.shape[1] != 4:
        refuse("expected rows of 4 numbers: depth (m), ux, uy, uz (m/s)")
    if not np.all(np.isfinite(table)):
        refuse("holds a number that is not finite")
    if np.any(np.abs(table) > largest):
        row = int(np.flatnonzero(np.any(np.abs(table) > largest, axis=1))[0])
        refuse(f"row {row + 1} holds a magnitude above {largest:g}, which the solver cannot "
               "carry through products such as the drag c |v|^2; give depths in m and "
               "velocities in m/s")
    if np.any(np.diff(table[:, 0]) <= 0):
        refuse("the depths must increase strictly from row to row")
    if table[0, 0] < 0:
        refuse(f"row 1's depth {table[0, 0]:g} m is above the sea surface: depths are "
               "measured down from it (m, 0 or more), not heights z")
    return table[:, 0], table[:, 1:]


def read_seabed_profile(path, largest=np.inf):
    """The rows of a seabed profile or grid file, (n, 2) 'distance height' or (n, 3)
    'x y height' (m; '#' starts a comment, commas allowed; x, y from the seabed origin,
    heights absolute): every row of the same count, at least two rows, every magnitude at
    most ``largest``; a profile's distances strictly increasing (a height for each
    distance: the profile is a function), a grid checked by ``grid_axes``.
    RodInputError otherwise, naming the line."""
    def refuse(what):
        raise RodInputError(f"-rod_seabed_profile {path}: {what}")

    rows = numbered_rows(path, "-rod_seabed_profile")
    expected = ("expected rows of 2 numbers, distance along -rod_seabed_direction from "
                "-rod_seabed_origin (m) and height (m, z up), or of 3, x, y from the "
                "seabed origin and height (a grid)")
    table = []
    for k, row in rows:
        try:
            values = [float(v) for v in row]
        except ValueError:
            refuse(f"line {k} '{' '.join(row)}': {expected}")
        if len(values) not in (2, 3) or (table and len(values) != len(table[0][1])):
            refuse(f"line {k} '{' '.join(row)}': {expected}, the same in every row")
        if not np.all(np.isfinite(values)) or np.any(np.abs(values) > largest):
            refuse(f"line {k}: a number that is not finite or above {largest:g} in "
                   "magnitude; give distances and heights in m")
        table.append((k, values))
    if len(table) < 2:
        refuse(f"needs at least 2 rows; {expected}")
    lines_of, data = [k for k, _ in table], np.array([v for _, v in table])
    if data.shape[1] == 3:
        grid_axes(data, refuse)
        return data
    steps = np.diff(data[:, 0])
    if np.any(steps <= 0):
        i = int(np.flatnonzero(steps <= 0)[0])
        refuse(f"line {lines_of[i + 1]}: distance {data[i + 1, 0]:g} m after "
               f"{data[i, 0]:g} m; the distances must increase strictly from row to row "
               "(a seabed profile is one height per distance; sort the rows and drop "
               "repeated distances)")
    return data


def grid_axes(table, refuse):
    """(xs (nx,), ys (ny,), heights (nx, ny)) of grid rows 'x y height' (n, 3) in any
    order, every x with every y exactly once, at least 2 of each; else refuse(what)."""
    xs, ys = np.unique(table[:, 0]), np.unique(table[:, 1])
    order = np.lexsort((table[:, 1], table[:, 0]))
    ordered = table[order]
    if (xs.size < 2 or ys.size < 2 or len(table) != xs.size * ys.size
            or np.any(ordered[:, 0] != np.repeat(xs, ys.size))
            or np.any(ordered[:, 1] != np.tile(ys, xs.size))):
        refuse(f"a grid's rows must hold every x with every y exactly once, at least 2 of "
               f"each (found {xs.size} x values, {ys.size} y values and {len(table)} rows; "
               f"a full grid of them has {xs.size * ys.size})")
    return xs, ys, ordered[:, 2].reshape(xs.size, ys.size)
