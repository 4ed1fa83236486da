"""Range graphs of a sweep (h5py, numpy, matplotlib; serial): the quantities along S
of every converged case, and their envelope (the least and the largest over the
cases at each S).

The quantities are read from the result files where they are datasets
(``effective_tension``, ``wall_tension``, ``bend_radius``, ``von_mises``,
``utilisation``: the newer ones only where the files have them); the bend radius of a
file without the dataset is 1 / |(u1, u2)| from its strains ``u`` (docs/output.md), and
the tension of a file without ``effective_tension`` is |n|. The envelope is drawn on
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
    ("von_mises", "von Mises stress", "Pa", "max"),
    ("utilisation", "utilisation", "1", "max"),
]
# Units shown on the graphs instead of the files' SI ones: (unit, factor, shown unit).
SHOWN = {"N": (1e-3, "kN"), "Pa": (1e-6, "MPa")}
# Bend radii above this many times the smallest one in the sweep are cut off the graph
# (a straight stretch has an infinite radius).
RADIUS_RANGE = 100.0


def along_line(path):
    """{'S': S, quantity: values along S} of result file ``path`` for the QUANTITIES it
    has or that follow from its datasets (bend radius from u, tension |n|)."""
    with h5py.File(path, "r") as f:
        data = {"S": f["S"][:]}
        for name, *_ in QUANTITIES:
            if name in f and f[name].shape == data["S"].shape:
                data[name] = f[name][:].astype(float)
        if "bend_radius" not in data and "u" in f:
            curvature = np.hypot(f["u"][:, 0], f["u"][:, 1])
            with np.errstate(divide="ignore"):
                data["bend_radius"] = np.where(curvature > 0, 1.0 / curvature, np.inf)
        if "effective_tension" not in data and "n" in f:
            data["effective_tension"] = np.linalg.norm(f["n"][:], axis=1)
    return data


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


def draw(figure, S, result, labels):
    """The range graphs on ``figure``: one panel per quantity, each case a thin line,
    the envelope shaded between the least and largest values, the design side bold."""
    info = {name: (label, unit, side) for name, label, unit, side in QUANTITIES}
    names = list(result)
    axes = figure.subplots(1, len(names), squeeze=False)[0]
    for axis, name in zip(axes, names):
        stacked, least, largest = result[name]
        label, unit, side = info[name]
        factor, unit = SHOWN.get(unit, (1.0, unit))
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
            axis.set_ylim(smallest / 1.5, top)
        axis.fill_between(S, lower, upper, color="0.8", alpha=0.6, lw=0, label="envelope")
        bound = largest if side == "max" else least
        axis.plot(S, np.where(np.isfinite(bound), bound, np.nan), "k-", lw=1.6,
                  label=f"{side} over cases")
        axis.set_xlabel("S (m)")
        axis.set_ylabel(f"{label} ({unit})")
        extreme = np.nanmax(bound) if side == "max" else np.nanmin(bound)
        axis.set_title(f"{label}: {side} {extreme:.4g} {unit}")
        axis.grid(True, alpha=0.3)
    if names:
        axes[0].legend(fontsize=7, loc="best")
    return figure
