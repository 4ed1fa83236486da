"""The figures of a system of lines, points and bodies (docs/systems.md), drawn from
plain arrays (system/outputs.picture, system/excursions' results):

* ``system_figure``: the plan (x, y, equal scales) and the elevation (x, z, looking
  along +y) of every line's centreline, the points (anchors, free points, prescribed
  points), the bodies' reference points and fairleads, the seabed and the sea surface;
* ``watch_circle_figure``: the reference point's offsets under a load turned through
  the headings, and the largest tension and the smallest grounded length of the lines
  against the heading;
* ``excursion_figure``: the load-excursion curves, the restoring force against the
  offset along each heading, and the largest tension and the smallest grounded length
  against the offset.

In both, a case that is a saddle of the system (system/excursions.py's verdict) is
marked with a red cross.

Each is laid out at fixed margins (a figure of SIZE inches), as the riser's figure."""

import matplotlib.pyplot as plt
import numpy as np

from petsc_rod.figures import style

SIZE = (16, 7.5)
CURVES_SIZE = (16, 5.5)
# Fixed margins (in): left of an axes (tick labels and axis label), between axes, right,
# below (tick labels and axis label), above (title lines).
LEFT, GAP, RIGHT, BOTTOM, TOP = 0.8, 1.0, 0.2, 0.6, 0.95
# Lines drawn each in a colour of their own (and named in the legend) up to this many;
# more (an array) in one colour.
NAMED_LINES = 10
POINT_MARKS = {"fixed": ("s", style.END, "anchor (fixed point)"),
               "free": ("D", style.ATTACHMENT, "free point"),
               "prescribed": ("^", style.END, "prescribed point")}
BODY = (0.0, 0.45, 0.25)            # the bodies' reference points and fairleads
SADDLE = (0.85, 0.1, 0.1)           # a sweep's case that is a saddle of the system


def _row(size, columns, ratios=None):
    """A figure of ``size`` with one row of ``columns`` axes at the fixed margins."""
    width, height = size
    figure = plt.figure(figsize=size)
    span = width - LEFT - RIGHT
    grid = figure.add_gridspec(1, columns, left=LEFT / width, right=1 - RIGHT / width,
                               bottom=BOTTOM / height, top=1 - TOP / height,
                               wspace=GAP * columns / (span - GAP * (columns - 1)),
                               width_ratios=ratios)
    return figure, [figure.add_subplot(grid[k]) for k in range(columns)]


def _scale(values):
    """(divisor, unit) of forces ``values`` (N): MN, kN or N by their largest."""
    largest = float(np.nanmax(np.abs(np.asarray(values, float)), initial=0.0))
    return next((d, u) for d, u in ((1e6, "MN"), (1e3, "kN"), (1.0, "N"))
                if largest >= d or d == 1.0)


def _plain(*axes):
    """No offset or scientific notation on the axes' ticks; a curve flat to a thousandth
    of its value (a symmetric spread's watch circle) drawn flat, in limits of +-0.1 %
    of it, so that its tick labels stay short."""
    for axis in axes:
        axis.ticklabel_format(useOffset=False, style="plain")
        values = np.concatenate([line.get_ydata() for line in axis.get_lines()
                                 if len(line.get_xdata()) > 2] or [[np.nan]])
        values = values[np.isfinite(values)]
        if values.size and np.ptp(values) < 1e-3 * np.abs(values).mean():
            middle = values.mean()
            axis.set_ylim(middle - 1e-3 * abs(middle), middle + 1e-3 * abs(middle))


def _line_colours(names):
    if len(names) > NAMED_LINES:
        return {name: style.LINE for name in names}, False
    return {name: style.case_colour(k) for k, name in enumerate(names)}, True


def system_figure(lines, points=(), bodies=(), seabed=None, surface=0.0, title=None):
    """The plan and the elevation of a system: ``lines`` {name: (n, 3) centreline, m},
    ``points`` [(name, kind, (3,))] (kind 'fixed', 'free' or 'prescribed'), ``bodies``
    [(name, reference point (3,), fairleads (k, 3))], ``seabed`` a flat seabed's height
    (m) or None, ``surface`` the sea surface's height (m), ``title`` the figure's."""
    figure, (plan, elevation) = _row(SIZE, 2, ratios=[1.0, 1.6])
    colours, named = _line_colours(list(lines))
    for name, r in lines.items():
        r = np.asarray(r, dtype=float)
        label = name if named else None
        plan.plot(r[:, 0], r[:, 1], "-", lw=1.8, color=colours[name], label=label)
        elevation.plot(r[:, 0], r[:, 2], "-", lw=1.8, color=colours[name], label=label)
    for kind, (marker, colour, text) in POINT_MARKS.items():
        at = np.array([p[2] for p in points if p[1] == kind], dtype=float).reshape(-1, 3)
        if at.size:
            for axis, k in ((plan, 1), (elevation, 2)):
                axis.plot(at[:, 0], at[:, k], marker, color=colour, ms=6, ls="none",
                          label=text if axis is elevation else None)
    for k, (name, X, fairleads) in enumerate(bodies):
        X, fairleads = np.asarray(X, float), np.asarray(fairleads, float).reshape(-1, 3)
        for axis, j in ((plan, 1), (elevation, 2)):
            axis.plot(fairleads[:, 0], fairleads[:, j], "o", color=BODY, ms=4, ls="none",
                      label="fairleads" if axis is elevation and k == 0 else None)
            axis.plot(X[0], X[j], "P", color=BODY, ms=11, mec="white", mew=0.8, ls="none",
                      label="bodies' reference points" if axis is elevation and k == 0
                      else None)
        if len(bodies) <= NAMED_LINES:
            plan.annotate(name, (X[0], X[1]), xytext=(6, 6), textcoords="offset points",
                          color=BODY, fontsize=9)
    z = np.concatenate([np.asarray(r, float)[:, 2] for r in lines.values()]
                       + [np.asarray([p[2][2] for p in points], float)]
                       + [[surface]] + ([[seabed]] if seabed is not None else []))
    low, high = z.min(), z.max()
    margin = 0.08 * max(high - low, 1e-9)
    elevation.set_ylim(low - margin, high + margin)
    elevation.axhline(surface, color=style.SEA, lw=2, zorder=0)
    elevation.text(0.5, surface, "sea surface", color=style.SEA, va="bottom", ha="center",
                   transform=elevation.get_yaxis_transform(), fontsize=9)
    if seabed is not None:
        elevation.axhspan(low - 2 * margin, seabed, color=style.SEABED_FILL, zorder=0, lw=0)
        elevation.axhline(seabed, color=style.SEABED, lw=2, zorder=0.5)
        elevation.text(0.99, seabed, "seabed ", color=style.SEABED, va="top", ha="right",
                       transform=elevation.get_yaxis_transform(), fontsize=9)
    plan.set_aspect("equal", adjustable="datalim")
    plan.set_xlabel("x (m)")
    plan.set_ylabel("y (m)")
    counts = ", ".join(f"{n} {one if n == 1 else many}" for n, one, many in
                       ((len(lines), "line", "lines"), (len(points), "point", "points"),
                        (len(bodies), "body", "bodies")))
    plan.set_title(f"plan: {counts}", fontsize=10)
    elevation.set_xlabel("x (m)")
    elevation.set_ylabel("z (m)")
    elevation.set_title("elevation: looking along +y", fontsize=10)
    elevation.legend(loc="best", fontsize=8, framealpha=0.9,
                     ncol=2 if named and len(lines) > 4 else 1)
    figure.suptitle(title or "the system at its equilibrium", y=1 - 0.1 / SIZE[1],
                    va="top")
    return figure


def _saddles(axis, x, y, saddle):
    """Mark the cases ``saddle`` (a bool array of ``x``'s shape, or None) of the
    curves (``x``, ``y``) on ``axis``: saddles of the system, kept in the results."""
    if saddle is None or not np.any(saddle):
        return
    saddle = np.asarray(saddle, bool)
    axis.plot(np.asarray(x, float)[saddle], np.asarray(y, float)[saddle], "X",
              color=SADDLE, ms=11, ls="none", label="saddle of the system")


def watch_circle_figure(offsets, headings, max_tension, min_grounded, load, body="",
                        title=None, saddle=None):
    """The watch circle of ``body`` under a horizontal ``load`` (N) turned through
    ``headings`` (h,), deg: the reference point's horizontal ``offsets`` (h, 2), m, from
    its rest; the lines' largest tension (h,), N, and smallest grounded length (h,), m
    (all NaN: no seabed, not drawn), against the heading; ``saddle`` (h,) bool, the
    headings whose equilibrium is a saddle of the system, marked (None: none)."""
    offsets = np.asarray(offsets, float).reshape(-1, 2)
    headings = np.asarray(headings, float)
    figure, (circle, tension, grounded) = _row(CURVES_SIZE, 3, ratios=[1.0, 1.2, 1.2])
    closed = np.vstack([offsets, offsets[:1]]) if len(offsets) > 2 else offsets
    circle.plot(closed[:, 0], closed[:, 1], "-", color=style.LINE, lw=1.8)
    circle.plot(offsets[:, 0], offsets[:, 1], "o", color=style.LINE, ms=4)
    _saddles(circle, offsets[:, 0], offsets[:, 1], saddle)
    circle.plot([0.0], [0.0], "P", color=BODY, ms=10, label="at rest")
    reach = max(float(np.abs(offsets).max(initial=0.0)), 1e-9)
    for angle in np.radians(headings):       # the load's direction at each heading
        circle.plot([0, 0.25 * reach * np.cos(angle)], [0, 0.25 * reach * np.sin(angle)],
                    ":", color=style.PROJECTION, lw=0.8)
    circle.set_aspect("equal", adjustable="datalim")
    circle.set_xlabel("x offset (m)")
    circle.set_ylabel("y offset (m)")
    largest = float(np.linalg.norm(offsets, axis=1).max(initial=0.0))
    circle.set_title(f"watch circle: largest offset {largest:.4g} m", fontsize=10)
    circle.legend(loc="best", fontsize=8)
    divisor, unit = _scale(max_tension)
    tension.plot(headings, np.asarray(max_tension, float) / divisor, "o-", color="black",
                 ms=4)
    tension.set_xlabel("heading of the load (deg)")
    tension.set_ylabel(f"largest tension ({unit})")
    tension.set_title(f"largest tension of any line: {np.nanmax(max_tension) / divisor:.6g} "
                      f"{unit}", fontsize=10)
    _grounded(grounded, headings, min_grounded, "heading of the load (deg)")
    _plain(tension, grounded)
    circle.ticklabel_format(useOffset=False, style="plain")
    load_divisor, load_unit = _scale([load])
    figure.suptitle(title or f"{body}: watch circle under {load / load_divisor:.4g} "
                    f"{load_unit}",
                    y=1 - 0.1 / CURVES_SIZE[1], va="top")
    return figure


def _grounded(axis, x, grounded, label):
    """The smallest grounded length against ``x`` (one curve or one per row)."""
    grounded = np.asarray(grounded, float)
    axis.set_xlabel(label)
    axis.set_ylabel("smallest grounded length (m)")
    if np.all(np.isnan(grounded)):
        axis.set_title("no line on a seabed", fontsize=10)
        return
    for k, (xs, ys) in enumerate(zip(np.atleast_2d(x), np.atleast_2d(grounded))):
        axis.plot(xs, ys, "o-", color=style.case_colour(k) if grounded.ndim > 1 else "black",
                  ms=4)
    axis.set_title(f"smallest grounded length of any line: {np.nanmin(grounded):.4g} m",
                   fontsize=10)


def excursion_figure(offsets, restoring, headings, max_tension, min_grounded, body="",
                     title=None, saddle=None):
    """The load-excursion curves of ``body``: for each of ``headings`` (h,), deg, the
    restoring force ``restoring`` (h, m), N, against the ``offsets`` (h, m), m, along
    the heading; the lines' largest tension (h, m), N, and smallest grounded length
    (h, m), m, against the offset; ``saddle`` (h, m) bool, the cases whose equilibrium
    is a saddle of the system, marked (None: none)."""
    offsets, restoring = np.asarray(offsets, float), np.asarray(restoring, float)
    figure, (force, tension, grounded) = _row(CURVES_SIZE, 3)
    (f_divisor, f_unit), (t_divisor, t_unit) = _scale(restoring), _scale(max_tension)
    for k, heading in enumerate(np.asarray(headings, float)):
        colour = style.case_colour(k)
        force.plot(offsets[k], restoring[k] / f_divisor, "o-", color=colour, ms=4,
                   label=f"{heading:g} deg")
        tension.plot(offsets[k], np.asarray(max_tension, float)[k] / t_divisor, "o-",
                     color=colour, ms=4)
    _saddles(force, offsets, restoring / f_divisor, saddle)
    force.set_xlabel("offset along the heading (m)")
    force.set_ylabel(f"restoring force ({f_unit})")
    force.set_title("restoring force against offset", fontsize=10)
    force.legend(title="heading", fontsize=8, title_fontsize=8)
    tension.set_xlabel("offset along the heading (m)")
    tension.set_ylabel(f"largest tension ({t_unit})")
    tension.set_title(f"largest tension of any line: {np.nanmax(max_tension) / t_divisor:.6g} "
                      f"{t_unit}", fontsize=10)
    _grounded(grounded, offsets, min_grounded, "offset along the heading (m)")
    _plain(force, tension, grounded)
    figure.suptitle(title or f"{body}: load-excursion curves", y=1 - 0.1 / CURVES_SIZE[1],
                    va="top")
    return figure
