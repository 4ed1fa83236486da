"""The picture of a line's modes from the CSV files of -rod_modes_table (docs/modes.md):
one panel per mode (at most MAX_PANELS), its offsets x, y, z along S normalised to a
largest offset of 1, titled with its frequency, period and class (matplotlib only), and
where the shapes' file lies beside the table (shapes_path)."""

import os

import numpy as np

MAX_PANELS = 12
COLUMNS = 3


def shapes_path(path):
    """FILE_shapes.csv beside the modes' table FILE.csv (cli/modes.shapes_path)."""
    stem, extension = os.path.splitext(path)
    return f"{stem}_shapes{extension or '.csv'}"


def read_modes(path):
    """(table, shapes): the modes' table of ``path`` (a structured array, a row per
    mode) and the shapes' rows (n, 11: mode, S, offsets x y z, rotations x y z, curvature
    1 and 2, twist)."""
    table = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True, dtype=None,
                                        encoding="utf-8"))
    shapes = np.loadtxt(shapes_path(path), delimiter=",", skiprows=1, ndmin=2)
    return table, shapes


def modes_figure(path):
    """The Figure of the modes of table ``path`` (matplotlib imported here: the command
    line imports this module for shapes_path alone)."""
    from matplotlib.figure import Figure
    table, shapes = read_modes(path)
    count = min(len(table), MAX_PANELS)
    rows = (count + COLUMNS - 1) // COLUMNS
    figure = Figure(figsize=(4.2 * COLUMNS, 2.6 * rows), layout="constrained")
    axes = figure.subplots(rows, COLUMNS, squeeze=False, sharex=True)
    for k, ax in enumerate(axes.flat):
        if k >= count:
            ax.set_visible(False)
            continue
        row = table[k]
        mine = shapes[shapes[:, 0] == row["mode"]]
        for c, (name, colour) in enumerate(zip("xyz", ("C0", "C1", "C2"))):
            ax.plot(mine[:, 1], mine[:, 2 + c], color=colour, lw=1.2, label=name)
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_title(f"mode {int(row['mode'])}: {row['frequency_Hz']:.4g} Hz, "
                     f"T {row['period_s']:.4g} s, {row['class']}", fontsize=9)
        ax.set_ylim(-1.08, 1.08)
        if k % COLUMNS == 0:
            ax.set_ylabel("offset (1 = largest)")
        if k >= count - COLUMNS:
            ax.set_xlabel("S (m)")
    axes.flat[0].legend(loc="upper right", fontsize=8, ncol=3)
    return figure
