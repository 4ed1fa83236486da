"""The line in space: an elevation (height against the true horizontal distance from
the anchor, so that a line pushed sideways keeps its true spread) and a plan (x, y),
with the sea surface, the seabed, the anchor, the hang-off, the touchdown point, the
sections in their line types' colours and the attachments."""

import numpy as np
from matplotlib.transforms import offset_copy

from petsc_rod.figures import along, style

OUT_OF_PLANE = 0.01     # a line this far out of the plane of its ends, over the span,
                        # also gets its projection on that plane drawn in the elevation


def pieces(result, colour):
    """[(mask, colour, label)]: the line's stretches to draw, a section each in its line
    type's colour, or the whole line in ``colour``."""
    if colour is not None or not result.sections:
        return [(np.ones(len(result.S), bool), colour or style.LINE, None)]
    colours = style.section_colours([name for name, _, _ in result.sections])
    drawn, seen = [], set()
    for name, lo, hi in result.sections:
        drawn.append(((result.S >= lo) & (result.S <= hi), colours[name],
                      None if name in seen else name))
        seen.add(name)
    return drawn


def draw_line(axis, x, y, result, colour, label):
    """The line through (x, y) in its pieces' colours; the first piece gets ``label``
    when the pieces have none of their own."""
    for k, (inside, piece_colour, piece_label) in enumerate(pieces(result, colour)):
        axis.plot(x[inside], y[inside], "-", lw=2.2, color=piece_colour,
                  label=piece_label if piece_label else (label if k == 0 else None))


def draw_marks(axis, x, y, result, colour=None, names=True):
    """The anchor, the hang-off, the touchdown and the attachments at their (x, y),
    ``x``, ``y`` being the vertices' coordinates in this panel; ``names``: labelled for
    the legend."""
    def label(text):
        return text if names else None
    a, t = result.anchor, result.top
    axis.plot(x[a], y[a], "s", color=colour or style.END, ms=6, label=label("anchor"))
    axis.plot(x[t], y[t], "^", color=colour or style.END, ms=8, label=label("hang-off"))
    if result.touchdown_S is not None:
        k = np.searchsorted(result.S, result.touchdown_S)
        k = min(max(k, 1), len(result.S) - 1)
        w = (result.touchdown_S - result.S[k - 1]) / (result.S[k] - result.S[k - 1])
        axis.plot((1 - w) * x[k - 1] + w * x[k], (1 - w) * y[k - 1] + w * y[k], "v",
                  color=colour or style.TOUCHDOWN, ms=9, mec="white", mew=0.8,
                  label=label(f"touchdown, S = {result.touchdown_S:.1f} m"))
    if result.attachments:
        S_p = [s for _, s, _ in result.attachments]
        xs, ys = np.interp(S_p, result.S, x), np.interp(S_p, result.S, y)
        listed = ", ".join(name for name, _, _ in result.attachments)
        if len(listed) > 40:
            listed = f"{len(result.attachments)}"
        axis.plot(xs, ys, "D", color=colour or style.ATTACHMENT, ms=5, mec="white", mew=0.6,
                  label=label(f"attachments: {listed}"))


def elevation_coordinates(result):
    """(x, z): the true horizontal distance from the anchor, and the height."""
    return along.horizontal_distance(result.r, result.r[result.anchor]), result.r[:, 2]


def draw_elevation(axis, result, colour=None, label=None, single=True):
    """The elevation of ``result``; ``colour`` and ``label``: one colour for the whole
    line (a case of a sweep) instead of the sections'; ``single``: the only line drawn
    (marks named in the legend, the projection on the plane of the ends where the line
    leaves it)."""
    x, z = elevation_coordinates(result)
    r, a, t = result.r, result.anchor, result.top
    offset = along.plane_offset(r, a, t)
    span = max(float(np.hypot(*(r[t, :2] - r[a, :2]))), 1e-300)
    if single and np.abs(offset).max() > OUT_OF_PLANE * span:
        chord = (r[t, :2] - r[a, :2]) / span
        axis.plot((r[:, :2] - r[a, :2]) @ chord, z, "--", lw=1.2, color=style.PROJECTION,
                  label="projected on the vertical plane of the ends")
    draw_line(axis, x, z, result, colour, label)
    draw_marks(axis, x, z, result, colour, names=single)
    axis.set_xlabel("horizontal distance from the anchor (m)")
    axis.set_ylabel("z (m)")


def draw_water(axis, result):
    """The sea surface and the seabed of ``result`` across the elevation, named on the
    panel; the lower limit set below the seabed, the upper above the surface. A seabed
    that is not flat (a slope, a profile) is drawn under the line, its height z_b under
    each vertex (the file's seabed_height) against the elevation's horizontal distance.
    The elevation fills its panel: its two scales differ (the plan's are equal)."""
    x, z = elevation_coordinates(result)
    bed = result.seabed_height
    floor = (bed.min() if bed is not None else
             result.seabed if result.seabed is not None else z.min())
    low = min(z.min(), floor)
    high = max(z.max(), result.sea_surface)
    margin = 0.08 * max(high - low, 1e-9)
    axis.set_ylim(low - margin, high + margin)
    axis.axhline(result.sea_surface, color=style.SEA, lw=2, zorder=0)
    axis.text(0.5, result.sea_surface, "sea surface", color=style.SEA, va="bottom",
              ha="center", transform=axis.get_yaxis_transform(), fontsize=9)
    if bed is not None:
        order = np.argsort(x, kind="stable")
        axis.fill_between(x[order], low - 2 * margin, bed[order], color=style.SEABED_FILL,
                          zorder=0, lw=0)
        axis.plot(x[order], bed[order], color=style.SEABED, lw=2, zorder=0.5)
        axis.text(x[order][-1], bed[order][-1], "seabed ", color=style.SEABED, va="top",
                  ha="right", fontsize=9)
    elif result.seabed is not None:
        axis.axhspan(low - 2 * margin, result.seabed, color=style.SEABED_FILL, zorder=0, lw=0)
        axis.axhline(result.seabed, color=style.SEABED, lw=2, zorder=0.5)
        axis.text(0.99, result.seabed, "seabed ", color=style.SEABED, va="top", ha="right",
                  transform=axis.get_yaxis_transform(), fontsize=9)


def padded(low, high, share=0.03):
    """(low, high) widened by ``share`` of their distance on each side."""
    pad = share * max(high - low, 1e-9)
    return low - pad, high + pad


def draw_plan(axis, result, colour=None, label=None, single=True):
    """The plan (x, y) of ``result``, with the straight line between its ends (the
    trace of their vertical plane) and, for one line, the current's direction; titled
    with the largest offset from that plane."""
    r, a, t = result.r, result.anchor, result.top
    if single:
        axis.plot(r[[a, t], 0], r[[a, t], 1], ":", lw=1, color=style.PROJECTION,
                  label="plane of the ends")
    draw_line(axis, r[:, 0], r[:, 1], result, colour, label)
    draw_marks(axis, r[:, 0], r[:, 1], result, colour, names=False)
    axis.set_xlabel("x (m)")
    axis.set_ylabel("y (m)")
    axis.set_aspect("equal", adjustable="datalim")
    if single:
        offset = along.plane_offset(r, a, t)
        k = int(np.argmax(np.abs(offset)))
        span = float(np.hypot(*(r[t, :2] - r[a, :2])))
        if abs(offset[k]) <= 1e-6 * max(span, 1.0):
            axis.set_title("plan: the line stays in the vertical plane of its ends",
                           fontsize=10)
        else:
            axis.set_title(f"plan: largest offset from the plane of the ends "
                           f"{abs(offset[k]):.3g} m at S = {result.S[k]:.0f} m", fontsize=10)
        if result.current is not None:
            draw_current(axis, result.current)


def draw_current(axis, current):
    """An arrow along the current's horizontal part, in the plan's upper left corner."""
    horizontal = np.asarray(current[:2], float)
    speed = float(np.linalg.norm(horizontal))
    if speed == 0:
        return
    direction = horizontal / speed
    head = offset_copy(axis.transAxes, axis.figure, x=16 * direction[0], y=16 * direction[1],
                       units="points")     # the arrow's middle at (0.1, 0.84) of the panel
    axis.annotate("", xy=(0.1, 0.84), xycoords=head,
                  xytext=(-32 * direction[0], -32 * direction[1]), textcoords="offset points",
                  arrowprops=dict(arrowstyle="-|>", color=style.SEA, lw=2))
    axis.text(0.02, 0.95, f"current {speed:.3g} m/s", transform=axis.transAxes,
              color=style.SEA, fontsize=9, ha="left")
