"""The excursion graphs of a sweep (numpy, matplotlib; serial), from its summary table
(sweep/summary.py: the same numbers as summary.csv): against the fairlead's offset (m),
the horizontal force at the fairlead (kN; a mooring line's load-excursion curve) and
the touchdown's excursion (m), one point a converged case, named, joined in the order of
the offset.
"""

import numpy as np

OFFSET = "fairlead_offset (m)"
# (column, label, factor to the unit shown, unit shown)
CURVES = [("fairlead_horizontal (N)", "horizontal force at the fairlead", 1e-3, "kN"),
          ("touchdown_excursion (m)", "touchdown excursion", 1.0, "m")]


def points(header, rows, codes):
    """(names, offsets, {column: values}) of the converged cases with an offset, sorted
    by offset, for the CURVES columns the table has; None with fewer than two."""
    if OFFSET not in header:
        return None
    where = {name: header.index(name) for name in [OFFSET] + [c for c, *_ in CURVES]
             if name in header}

    def number(value):
        return float(value) if isinstance(value, (int, float)) else np.nan

    chosen = [row for row, code in zip(rows, codes) if code == 0
              and np.isfinite(number(row[where[OFFSET]]))]
    if len(chosen) < 2:
        return None
    chosen.sort(key=lambda row: number(row[where[OFFSET]]))
    values = {column: np.array([number(row[k]) for row in chosen])
              for column, k in where.items() if column != OFFSET}
    return ([row[0] for row in chosen], np.array([number(row[where[OFFSET]]) for row in chosen]),
            values)


def draw(figure, names, offsets, values):
    """One panel per CURVES column with a finite value: the cases' points against the
    offset, each named."""
    shown = [(column, label, factor, unit) for column, label, factor, unit in CURVES
             if column in values and np.any(np.isfinite(values[column]))]
    axes = figure.subplots(1, max(len(shown), 1), squeeze=False)[0]
    for axis, (column, label, factor, unit) in zip(axes, shown):
        y = values[column] * factor
        axis.plot(offsets, y, "o-", color="tab:blue")
        for name, x, value in zip(names, offsets, y):
            if np.isfinite(value):
                axis.annotate(name, (x, value), textcoords="offset points", xytext=(4, 4),
                              fontsize=8)
        axis.set_xlabel("fairlead offset (m)")
        axis.set_ylabel(f"{label} ({unit})")
        axis.set_title(f"{label} against the offset")
        axis.grid(True, alpha=0.3)
    return figure
