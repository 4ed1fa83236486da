"""The figure of a riser result file (matplotlib only; plots.py calls it for a file with
the riser datasets): the profile in the vertical plane through the ends with the seabed,
the effective tension and the curvature along the arc length."""

import numpy as np


def profile_plane(r):
    """Horizontal coordinate along the ends' horizontal direction, and z: (n,), (n,)."""
    chord = r[-1] - r[0]
    horizontal = np.array([chord[0], chord[1], 0.0])
    span = np.linalg.norm(horizontal)
    along = horizontal / span if span > 0 else np.array([1.0, 0.0, 0.0])
    return (r - r[0]) @ along, r[:, 2]


def section_colours(names):
    """A colour per line type name, in order of first appearance (tab10)."""
    import matplotlib
    palette = matplotlib.colormaps["tab10"].colors
    kinds = list(dict.fromkeys(names))
    return {name: palette[kinds.index(name) % len(palette)] for name in kinds}


def draw_sections(profile, S_axes, S, x, z, sections):
    """Each section of ``sections`` (names, bounds (k, 2)) drawn in its line type's
    colour on the profile (x, z at the vertices S) and shaded along S on ``S_axes``."""
    names, bounds = sections
    colours = section_colours(names)
    labelled = set()
    for name, (lo, hi) in zip(names, bounds):
        inside = (S >= lo) & (S <= hi)
        label = None if name in labelled else name
        labelled.add(name)
        profile.plot(x[inside], z[inside], "-", lw=2.5, color=colours[name], label=label)
        for axis in S_axes:
            axis.axvspan(lo, hi, color=colours[name], alpha=0.12, lw=0)


def draw_riser(figure, data):
    """Three panels on ``figure`` from ``data``: S, r, u (vertex datasets), tension
    (effective_tension), seabed (height or None), touchdown (S, position) or None,
    sections (names, bounds) or None."""
    axes = figure.subplots(1, 3)
    S, r = data["S"], data["r"]
    x, z = profile_plane(r)
    profile, tension_axis, curvature_axis = axes
    if data.get("sections") is not None:
        draw_sections(profile, (tension_axis, curvature_axis), S, x, z, data["sections"])
    else:
        profile.plot(x, z, "-", lw=1.5, label="line")
    profile.plot(x[[0, -1]], z[[0, -1]], "o", ms=4)
    if data["seabed"] is not None:
        profile.axhline(data["seabed"], color="saddlebrown", lw=2, label="seabed")
    if data["touchdown"] is not None and np.isfinite(data["touchdown"][0]):
        point = data["touchdown"][1]
        tx, tz = profile_plane(np.vstack([r[0], point, r[-1]]))
        profile.plot(tx[1], tz[1], "v", color="red", label=f"touchdown S = {data['touchdown'][0]:.4g} m")
    profile.set_xlabel("horizontal distance from the start (m)")
    profile.set_ylabel("z (m)")
    profile.set_title("profile in the vertical plane of the ends")
    profile.legend()
    tension_axis.plot(S, data["tension"] / 1e3)
    tension_axis.set_xlabel("S (m)")
    tension_axis.set_ylabel("effective tension n.t (kN)")
    tension_axis.set_title("effective tension")
    curvature = np.hypot(data["u"][:, 0], data["u"][:, 1])
    curvature_axis.plot(S, curvature)
    curvature_axis.set_xlabel("S (m)")
    curvature_axis.set_ylabel("curvature |(u1, u2)| (1/m)")
    curvature_axis.set_title("curvature (bend radius = 1 / curvature)")
    for axis in (tension_axis, curvature_axis):
        if data["touchdown"] is not None and np.isfinite(data["touchdown"][0]):
            axis.axvline(data["touchdown"][0], color="red", lw=0.8, ls="--")
