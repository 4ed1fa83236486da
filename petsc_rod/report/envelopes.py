"""Range graphs of a sweep (h5py, numpy, matplotlib; serial): the quantities along S
of every converged case, and their envelope (the least and the largest over the
cases at each S).

The quantities are read from the result files where they are datasets
(``effective_tension``, ``wall_tension``, ``bend_radius``, ``curvature``,
``bending_moment``, ``von_mises``, ``utilisation``, ``declination``: the newer ones only
where the files have them); the bend radius of a file without the dataset is
1 / |(u1, u2)| from its strains ``u`` (docs/output.md), its curvature |(u1, u2)|, the
tension of a file without ``effective_tension`` is |n|, and the seabed clearance is
z - z_b (m) where the file has a seabed (seabed_under). The envelope is drawn on
every S of every case (their union): each case is interpolated onto the S within its
own length and has no value beyond it, so a longer case is not cut at a shorter one's
end and a shorter one is not extended past its own.
"""

import h5py
import numpy as np

# (dataset, label, unit, which side of the envelope the design check reads)
QUANTITIES = [
    ("effective_tension", "effective tension", "N", "max"),
    ("wall_tension", "wall tension", "N", "max"),
    ("bend_radius", "bend radius", "m", "min"),
    ("curvature", "curvature", "1/m", "max"),
    ("bending_moment", "bending moment", "N m", "max"),
    ("von_mises", "von Mises stress", "Pa", "max"),
    ("utilisation", "utilisation", "1", "max"),
    ("declination", "declination", "deg", "max"),
    ("seabed_clearance", "seabed clearance", "m", "min"),
]
# Units shown on the graphs instead of the files' SI ones: (unit, factor, shown unit).
SHOWN = {"N": (1e-3, "kN"), "Pa": (1e-6, "MPa"), "N m": (1e-3, "kN m")}
# Quantities derived from other datasets (along_line), not read by name.
DERIVED = ("seabed_clearance",)
# Bend radii above this many times the smallest one in the sweep are cut off the graph
# (a straight stretch has an infinite radius).
RADIUS_RANGE = 100.0


def along_line(path):
    """{'S': S, quantity: values along S} of result file ``path`` for the QUANTITIES it
    has or that follow from its datasets (bend radius from u, tension |n|)."""
    with h5py.File(path, "r") as f:
        data = {"S": f["S"][:]}
        for name, *_ in QUANTITIES:
            if name not in DERIVED and name in f and f[name].shape == data["S"].shape:
                data[name] = f[name][:].astype(float)
        if "bend_radius" not in data and "u" in f:
            curvature = np.hypot(f["u"][:, 0], f["u"][:, 1])
            with np.errstate(divide="ignore"):
                data["bend_radius"] = np.where(curvature > 0, 1.0 / curvature, np.inf)
        if "effective_tension" not in data and "n" in f:
            data["effective_tension"] = np.linalg.norm(f["n"][:], axis=1)
        if "curvature" not in data and "u" in f:
            data["curvature"] = np.hypot(f["u"][:, 0], f["u"][:, 1])
        seabed = seabed_under(f)
        if seabed is not None and "r" in f:
            data["seabed_clearance"] = f["r"][:, 2] - seabed
    return data


def seabed_under(f):
    """z_b (m, absolute) under each vertex of the open result file ``f``: its
    ``seabed_height`` dataset (a seabed not flat) or its flat seabed's height
    (``parameters`` ``seabed``); None without a seabed."""
    if "seabed_height" in f:
        return f["seabed_height"][:].astype(float)
    parameters = f.get("parameters")
    level = parameters.attrs.get("seabed") if parameters is not None else None
    try:
        level = float(np.asarray(level).ravel()[0])
    except (TypeError, ValueError, IndexError):
        return None
    return level if np.isfinite(level) else None


def on_arcs(S, case_S, values):
    """``values`` (at ``case_S``, increasing) at the arc lengths ``S``: the value itself
    where S is one of case_S (an infinite bend radius stays infinite), linear between
    them, NaN outside [case_S[0], case_S[-1]] (not extended past the case's ends)."""
    index = np.clip(np.searchsorted(case_S, S), 0, case_S.size - 1)
    exact = case_S[index] == S
    finite = np.isfinite(values)
    between = np.interp(S, case_S[finite], values[finite]) if finite.any() \
        else np.full(S.shape, np.inf)
    inside = (S >= case_S[0]) & (S <= case_S[-1])
    return np.where(exact, values[index], np.where(inside, between, np.nan))


def envelopes(cases):
    """(S, {quantity: (values of each case (cases, n), least, largest)}) on the union of
    the cases' S (each case NaN beyond its own length: on_arcs), for the quantities every
    case has. ``cases``: along_line dicts."""
    S = cases[0]["S"]
    if any(c["S"].shape != S.shape or not np.array_equal(c["S"], S) for c in cases):
        S = np.unique(np.concatenate([c["S"] for c in cases]))
    # the quantities every case has, with a finite value somewhere (a straight line's
    # bend radius is inf all along, a line type without smys has no utilisation)
    names = [name for name, *_ in QUANTITIES
             if all(name in c for c in cases)
             and any(np.any(np.isfinite(c[name])) for c in cases)]
    result = {}
    for name in names:
        stacked = np.array([c[name] if c["S"].shape == S.shape and np.array_equal(c["S"], S)
                            else on_arcs(S, c["S"], c[name]) for c in cases])
        # fmin/fmax skip a case's NaN where it does not reach
        result[name] = (stacked, np.fmin.reduce(stacked, axis=0),
                        np.fmax.reduce(stacked, axis=0))
    return S, result


def shown(name):
    """(label, factor to the unit shown, unit shown ('' for a ratio), side) of quantity
    ``name``."""
    info = {name: (label, unit, side) for name, label, unit, side in QUANTITIES}
    label, unit, side = info[name]
    factor, unit = SHOWN.get(unit, (1.0, unit))
    return label, factor, "" if unit == "1" else unit, side


def governing(S, entry, side):
    """(case index, S, value) of the extreme on the design side over every case of
    ``entry`` (envelopes' (stacked, least, largest)); None where nothing is finite."""
    stacked = np.where(np.isfinite(entry[0]), entry[0], np.nan)
    if not np.any(np.isfinite(stacked)):
        return None
    flat = np.nanargmax(stacked) if side == "max" else np.nanargmin(stacked)
    case, k = np.unravel_index(flat, stacked.shape)
    return int(case), float(S[k]), float(stacked[case, k])


def panel(axis, S, name, entry, labels, limit=None):
    """Quantity ``name`` on ``axis``: each case a thin line, the envelope shaded between
    the least and largest values, the design side bold, ``limit`` (in the file's unit)
    a red dashed line; returns (the extreme on the design side shown, unit shown)."""
    stacked, least, largest = entry
    label, factor, unit, side = shown(name)
    stacked, least, largest = stacked * factor, least * factor, largest * factor
    finite = np.isfinite(stacked)
    for values, case in zip(stacked, labels):
        axis.plot(S, np.where(np.isfinite(values), values, np.nan), lw=0.8, alpha=0.7,
                  label=case)
    lower = np.where(np.isfinite(least), least, np.nan)
    upper = np.where(np.isfinite(largest), largest, np.nan)
    if name == "bend_radius":
        smallest = np.nanmin(np.where(finite, stacked, np.nan))
        top = smallest * RADIUS_RANGE
        upper = np.minimum(np.where(np.isfinite(largest), largest, top), top)
        axis.set_yscale("log")
        axis.set_ylim(min(smallest, limit * factor if limit else smallest) / 1.5, top)
    axis.fill_between(S, lower, upper, color="0.8", alpha=0.6, lw=0, label="envelope")
    bound = largest if side == "max" else least
    axis.plot(S, np.where(np.isfinite(bound), bound, np.nan), "k-", lw=1.6,
              label=f"{side} over cases")
    if limit is not None:
        axis.axhline(limit * factor, color="tab:red", ls="--", lw=1.4,
                     label=f"limit {limit * factor:.4g}{' ' + unit if unit else ''}")
    axis.set_xlabel("S (m)")
    axis.set_ylabel(f"{label} ({unit})" if unit else label)
    axis.grid(True, alpha=0.3)
    extreme = np.nanmax(bound) if side == "max" else np.nanmin(bound)
    return extreme, unit


def draw(figure, S, result, labels):
    """The range graphs on ``figure``: one panel per quantity (panel), titled with the
    extreme on the design side."""
    names = list(result)
    axes = figure.subplots(1, len(names), squeeze=False)[0]
    for axis, name in zip(axes, names):
        extreme, unit = panel(axis, S, name, result[name], labels)
        label, _, _, side = shown(name)
        axis.set_title(f"{label}: {side} {extreme:.4g}{' ' + unit if unit else ''}")
    if names:
        axes[0].legend(fontsize=7, loc="best")
    return figure


def draw_one(figure, S, name, entry, labels, limit=None):
    """One quantity's range graph on ``figure`` (panel), titled with its extreme on the
    design side and the case that governs it, e.g. 'effective tension: max 1650 kN, case
    far50 at S = 1800 m'."""
    axis = figure.subplots()
    panel(axis, S, name, entry, labels, limit)
    label, factor, unit, side = shown(name)
    case, where, value = governing(S, entry, side)
    axis.set_title(f"{label}: {side} {value * factor:.4g}{' ' + unit if unit else ''}, "
                   f"case {labels[case]} at S = {where:.4g} m", fontsize=10)
    axis.legend(fontsize=7, loc="best", ncol=2)
    return figure
