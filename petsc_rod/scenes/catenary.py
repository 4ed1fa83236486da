"""The inextensible catenary (numpy only): a start of the iteration (starts.py) and a
closed form the tests compare against (petsc_rod.validation.closed_forms re-exports it).
"""

import numpy as np


def _require_positive(name, value):
    """Raise ValueError unless ``value`` is a finite number > 0."""
    if not (np.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be positive and finite, got {value!r}")


def increasing_root(function, lower, upper):
    """The root of an increasing ``function`` in [lower, upper] (function(lower) < 0 <
    function(upper)), bisected until the bracket is two adjacent doubles."""
    while True:
        middle = 0.5 * (lower + upper)
        if not lower < middle < upper:
            return middle
        if function(middle) < 0.0:
            lower = middle
        else:
            upper = middle


def increasing_roots(function, lower, upper, depth=5, refusal=None):
    """increasing_root of many increasing functions at once: ``function(rows, points)``
    maps rows (indices, (r,)) and points (r, k) to values (r, k), row i's by function
    i; ``lower``, ``upper`` (n,) bracket each root (function(lower) < 0 <
    function(upper)). Each row visits the midpoints increasing_root visits, so its root
    is the same double; ``depth`` halvings are evaluated in one call (the 2**depth - 1
    midpoints they may need), so that a root takes about 60 / depth calls. A NaN on a
    row's path is taken as above the root, as increasing_root does, or raises
    ValueError(``refusal``) where given (the function has no value there)."""
    lower, upper = np.array(lower, dtype=float), np.array(upper, dtype=float)
    roots = np.full(lower.shape, np.nan)
    open_rows = np.arange(lower.size)
    while open_rows.size:
        # the ends of the 2**depth intervals of depth halvings, in order: the midpoints of
        # level l are every 2**(depth - l)-th from the 2**(depth - l - 1)-th
        ends = np.stack([lower[open_rows], upper[open_rows]], axis=1)
        for _ in range(depth):
            finer = np.empty((open_rows.size, 2 * ends.shape[1] - 1))
            finer[:, ::2], finer[:, 1::2] = ends, 0.5 * (ends[:, :-1] + ends[:, 1:])
            ends = finer
        values = np.full(ends.shape, np.nan)
        values[:, 1:-1] = function(open_rows, ends[:, 1:-1])
        ends, values = ends.ravel(), values.ravel()
        low = np.arange(open_rows.size) * (2 ** depth + 1)      # positions in ends
        high = low + 2 ** depth
        going = np.ones(open_rows.size, bool)
        for _ in range(depth):
            at = (low + high) // 2
            middle = ends[at]
            done = going & ~((ends[low] < middle) & (middle < ends[high]))
            roots[open_rows[done]] = middle[done]
            going &= ~done
            if refusal is not None and np.any(going & np.isnan(values[at])):
                raise ValueError(refusal)
            below = values[at] < 0.0
            low, high = np.where(below, at, low), np.where(below, high, at)
        lower[open_rows], upper[open_rows] = ends[low], ends[high]
        open_rows = open_rows[going]
    return roots


def catenary_axes(length, chord, load):
    """The unit vectors (e_v, e_h) of a catenary's plane: up (against the load) and along
    the horizontal part of the chord. ValueError when there is no catenary: a length or
    load that is not positive, a chord not shorter than the cable, or a chord along the
    load."""
    _require_positive("length", length)
    chord, load = np.asarray(chord, dtype=float), np.asarray(load, dtype=float)
    weight = np.linalg.norm(load)
    _require_positive("load", weight)
    up = -load / weight
    horizontal = chord - (chord @ up) * up
    span = np.linalg.norm(horizontal)
    if not (np.linalg.norm(chord) < length and span > 1e-9 * length):
        raise ValueError("catenary: the chord must be shorter than the cable and not "
                         "parallel to the load")
    return up, horizontal / span


def catenary(length, chord, load, s):
    r"""The inextensible catenary through two held ends under a uniform dead load.

    A perfectly flexible cable of length ``L`` hangs from ``r(0) = 0`` to
    ``r(L) = chord`` under the load ``f`` per unit length (vector, N/m).  With
    ``w = |f|``, ``e_v = -f / w`` (up), the rise ``v = chord . e_v``, the span
    ``s_h = |chord - v e_v|`` along ``e_h``, and ``x`` the horizontal coordinate from
    the lowest point (the vertex) of ``z = a cosh(x / a)``:

        L^2 - v^2 = (2 a sinh(s_h / 2a))^2      (the parameter a = H / w),
        v / L = tanh(x_c / a)                   (x_c: the mid-span abscissa),
        S(x) = a (sinh(x / a) - sinh(x_0 / a)),  x_0 = x_c - s_h / 2,

    so that ``x(S) = a asinh(S / a + sinh(x_0 / a))`` and

        r(S) = (x - x_0) e_h + a (cosh(x / a) - cosh(x_0 / a)) e_v,
        r'(S) = (e_h + sinh(x / a) e_v) / cosh(x / a),
        n(S) = H (e_h + sinh(x / a) e_v)        (n' + f = 0, tension H cosh(x / a)).

    ``n`` is the force the part beyond S exerts on the part before it (docs/method.md §6).
    Returns ``(r, tangent, force)`` at the arc lengths ``s``, each ``s.shape + (3,)``.
    """
    up, along = catenary_axes(length, chord, load)
    chord = np.asarray(chord, dtype=float)
    weight = np.linalg.norm(load)
    rise, span = float(chord @ up), float(chord @ along)
    target = np.sqrt(length**2 - rise**2) / span     # 2a sinh(span/2a) / span, > 1
    # q = span / 2a solves sinh(q) / q = target; sinh(q)/q is increasing on q > 0.
    q = increasing_root(lambda q: np.sinh(q) / q - target, 1e-12, np.arcsinh(target) + 50.0)
    a = span / (2 * q)
    x0 = a * np.arctanh(rise / length) - span / 2
    x = a * np.arcsinh(np.asarray(s, dtype=float) / a + np.sinh(x0 / a))
    sh, ch = np.sinh(x / a)[..., None], np.cosh(x / a)[..., None]
    r = (x - x0)[..., None] * along + a * (ch - np.cosh(x0 / a)) * up
    direction = along + sh * up
    return r, direction / ch, weight * a * direction
