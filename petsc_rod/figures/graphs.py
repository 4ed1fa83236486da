"""The graphs against the arc length S: effective (and wall) tension, the curvature in
the vertical plane and out of it against an allowable bend radius, the bending moment,
the utilisation against its limit 1 (where the file has it) and the seabed reaction. Each ``draw_*`` draws one result on one axis, in the colours of
one line (``colour`` None) or of a case of a sweep; ``mark_along`` shades the sections
and marks the touchdown and the attachments."""

import numpy as np

from petsc_rod.figures import style

LATERAL = 0.01      # lateral curvature drawn where it reaches this share of the vertical


def draw_tension(axis, result, colour=None, label=None):
    """Effective tension n.t and, on a line of line types, the wall tension (kN)."""
    axis.plot(result.S, result.tension / 1e3, "-", color=colour or "black",
              label=label or "effective tension")
    if result.wall_tension is not None:
        axis.plot(result.S, result.wall_tension / 1e3, "--", lw=1, color=colour or "dimgray",
                  label=None if colour else "wall tension")
    axis.set_ylabel("tension (kN)")
    axis.set_title("effective tension" + (" (solid), wall tension (dashed)"
                                          if result.wall_tension is not None else ""),
                   fontsize=10)


def draw_curvature(axis, result, colour=None, label=None, allowable=None):
    """The curvature in the vertical plane (+ sag bend, - hog bend) and, where the line
    bends in plan, the lateral curvature (1/m); ``allowable``: the allowable bend radius
    (m), drawn as +-1/allowable."""
    vertical, lateral = result.curvature[:, 0], result.curvature[:, 1]
    axis.plot(result.S, vertical, "-", color=colour or "black",
              label=label or "in the vertical plane")
    if np.abs(lateral).max() > LATERAL * max(np.abs(vertical).max(), 1e-300):
        axis.plot(result.S, lateral, ":", color=colour or "dimgray",
                  label=None if colour else "lateral (in plan)")
    if allowable:
        axis.plot(result.S[[0, 0]], [-1.1 / allowable, 1.1 / allowable], alpha=0)
        for sign in (1, -1):
            axis.axhline(sign / allowable, color=style.ALLOWABLE, ls="--", lw=1,
                         label=f"allowable bend radius {allowable:g} m" if sign > 0 else None)
    axis.axhline(0, color="gray", lw=0.5)
    axis.set_ylabel("curvature (1/m)")
    title = "curvature: + sag bend, - hog bend"
    if colour is None:
        k = int(np.argmax(np.hypot(vertical, lateral)))
        radius = 1 / max(np.hypot(vertical, lateral)[k], 1e-300)
        title = f"{title}\nsmallest bend radius {radius:.3g} m at S = {result.S[k]:.0f} m"
        if allowable and radius < allowable:
            title += "  BELOW THE ALLOWABLE"
    else:
        title += "; dotted: lateral"
        if allowable:
            title += f"\nred dashed: allowable bend radius {allowable:g} m"
    axis.set_title(title, fontsize=10)


def draw_moment(axis, result, colour=None, label=None):
    """The bending moment's magnitude (kN m)."""
    axis.plot(result.S, result.bending_moment / 1e3, "-", color=colour or "black", label=label)
    axis.set_ylabel("bending moment (kN m)")
    axis.set_title("bending moment |(m.d1, m.d2)|", fontsize=10)


def draw_reaction(axis, result, colour=None, label=None):
    """The seabed's reaction per metre (kN/m)."""
    if result.seabed_reaction is None:
        return
    reaction = result.seabed_reaction / 1e3
    if colour is None:
        axis.fill_between(result.S, reaction, color=style.SEABED_FILL, lw=0)
    axis.plot(result.S, reaction, "-", color=colour or style.SEABED, label=label)
    axis.set_ylabel("seabed reaction (kN/m)")
    axis.set_title("seabed reaction", fontsize=10)


def draw_utilisation(axis, result, colour=None, label=None):
    """The utilisation, von Mises over the allowable stress (reports/stresses.py), with
    its limit 1 (dashed); NaN where a section has no yield stress is left out."""
    if result.utilisation is None:
        return
    axis.plot(result.S, result.utilisation, "-", color=colour or "black", label=label)
    axis.axhline(1.0, color=style.ALLOWABLE, ls="--", lw=1,
                 label=None if colour else "limit 1")
    axis.set_ylabel("utilisation")
    title = "utilisation: von Mises / allowable"
    finite = np.isfinite(result.utilisation)
    if colour is None and finite.any():
        k = int(np.nanargmax(np.where(finite, result.utilisation, np.nan)))
        title += f"\nlargest {result.utilisation[k]:.3g} at S = {result.S[k]:.0f} m"
        if result.utilisation[k] > 1.0:
            title += "  ABOVE 1"
    axis.set_title(title, fontsize=10)


GRAPHS = (draw_tension, draw_curvature, draw_moment, draw_utilisation, draw_reaction)


def graphs_for(results):
    """The graphs to draw for ``results``: the utilisation and the seabed reaction only
    where a result has them."""
    return [g for g in GRAPHS
            if (g is not draw_reaction or any(r.seabed_reaction is not None for r in results))
            and (g is not draw_utilisation or any(r.utilisation is not None and
                                                  np.isfinite(r.utilisation).any()
                                                  for r in results))]


def mark_along(axis, result, colour=None, named=False):
    """The sections shaded (one result), the touchdown (dashed) and the attachments
    (dotted) as vertical lines, in ``colour`` for a case of a sweep; ``named``: with
    legend labels (on one graph of a figure)."""
    if colour is None and result.sections:
        colours = style.section_colours([name for name, _, _ in result.sections])
        for name, lo, hi in result.sections:
            axis.axvspan(lo, hi, color=colours[name], alpha=0.12, lw=0)
    if result.touchdown_S is not None:
        axis.axvline(result.touchdown_S, color=colour or style.TOUCHDOWN, lw=0.8, ls="--",
                     label="touchdown" if named else None)
    for k, (_, S_p, _) in enumerate(result.attachments):
        axis.axvline(S_p, color=colour or style.ATTACHMENT, lw=0.8, ls=":",
                     label="attachments" if named and k == 0 else None)
    axis.set_xlabel("S (m)")
    axis.set_xlim(result.S[0], result.S[-1])
