"""The inextensible catenary resting on a flat, rigid, frictionless seabed (numpy only):
a start of the iteration (starts.py) and the closed form of the tests.

A perfectly flexible line of length L and weight w per metre (the load (0, 0, -w)) hangs
between two ends at heights h0, h1 >= 0 above the seabed, a horizontal distance X apart.
Where it rests on the seabed it is straight and horizontal (frictionless: the tension H
is the same all along it); each suspended part is a catenary of parameter a = H / w
whose vertex is its touchdown point, where it leaves the seabed tangentially. A part
hanging from a height h reaches the seabed after

    s(h) = sqrt(h^2 + 2 a h)   of arc length and   x(h) = a acosh(1 + h / a)

horizontally, and the grounded length is L - s(h0) - s(h1). The horizontal span fixes a:

    f(a) = L - s(h0) - s(h1) + x(h0) + x(h1) - X = 0,

with x - s increasing in a from -h (a -> 0) to 0 (a -> infinity), so that f has one
root when L - h0 - h1 < X < L. At arc length sigma from a touchdown point the height is
sqrt(a^2 + sigma^2) - a, the horizontal distance a asinh(sigma / a), the tangent
(a, sigma) / sqrt(a^2 + sigma^2) and the tension w sqrt(a^2 + sigma^2).
"""

import numpy as np

from petsc_rod.scenes.catenary import increasing_root
from petsc_rod.errors import NoCatenaryStart


def touchdown_parameter(length, span, h0, h1):
    """a = H / w (m) of the catenary with touchdown (module docstring). ValueError when
    the line is too long to be taut on the seabed (L >= X + h0 + h1) or too short to
    reach the ends (L <= X)."""
    if not (length - h0 - h1 < span < length):
        raise ValueError("touchdown catenary: needs L - h0 - h1 < X < L")

    def excess(a):
        s0, s1 = np.sqrt(h0**2 + 2 * a * h0), np.sqrt(h1**2 + 2 * a * h1)
        x0, x1 = a * np.arccosh(1 + h0 / a), a * np.arccosh(1 + h1 / a)
        return length - s0 - s1 + x0 + x1 - span

    upper = length
    while excess(upper) < 0:
        upper *= 2
    return increasing_root(excess, 1e-12 * length, upper)


def grounded_catenary(length, chord, weight, seabed, S):
    """(r, tangent, force) at arc lengths S of the line from the origin to ``chord`` (3,)
    under the load (0, 0, -weight) resting on the seabed z = ``seabed`` (m; the origin
    at or above it), each S.shape + (3,). ``force`` is n(S), the force of the part beyond
    S on the part before (tension times tangent). Also returns the grounded stretch
    (S_start, S_end) as a 4th item. ValueError where the line does not reach the seabed
    taut (see touchdown_parameter) or the ends are on one vertical."""
    chord = np.asarray(chord, dtype=float)
    horizontal = np.array([chord[0], chord[1], 0.0])
    span = np.linalg.norm(horizontal)
    if span <= 1e-9 * length:
        raise ValueError("touchdown catenary: the ends are on one vertical")
    along, up = horizontal / span, np.array([0.0, 0.0, 1.0])
    h0, h1 = -seabed, chord[2] - seabed
    a = touchdown_parameter(length, span, h0, h1)
    s0 = np.sqrt(h0**2 + 2 * a * h0)
    s1 = np.sqrt(h1**2 + 2 * a * h1)
    if s0 + s1 > length:
        raise ValueError("touchdown catenary: the line hangs clear of the seabed")
    x0 = a * np.arccosh(1 + h0 / a)
    S = np.asarray(S, dtype=float)
    # signed arc length from the nearer touchdown point: < 0 before the grounded
    # stretch, > 0 after it, 0 on it
    sigma = np.minimum(S - s0, 0.0) + np.maximum(S - (length - s1), 0.0)
    root = np.sqrt(a**2 + sigma**2)
    x = np.clip(S, s0, length - s1) - s0 + x0 + a * np.arcsinh(sigma / a)
    z = root - a
    r = x[..., None] * along + (z + seabed)[..., None] * up
    direction = a * along + sigma[..., None] * up
    tangent = direction / root[..., None]
    return r, tangent, weight * direction, (s0, length - s1)


def seabed_shape(scene, chord, load, hanging):
    """The shape S -> (r, tangent, force) of a catenary start (starts.catenary_start) with
    the seabed: ``hanging`` (the free catenary) when it stays above the seabed, else the
    grounded catenary. NoCatenaryStart when the load is not vertical (the grounded part
    would not lie still on a frictionless seabed) or the line cannot lie taut on it."""
    height = scene.seabed.height
    lowest = hanging(np.linspace(0.0, scene.length, 1025))[0][:, 2].min()
    if lowest >= height:
        return hanging
    if np.any(load[:2]) or load[2] >= 0:
        raise NoCatenaryStart("-rod_initial_shape catenary with -rod_seabed needs a "
                              "load straight down (0,0,-w)")
    try:
        grounded_catenary(scene.length, chord, -load[2], height, [0.0])
    except ValueError:
        raise NoCatenaryStart("-rod_initial_shape catenary with -rod_seabed: the line "
                              "is too long to lie taut on the seabed between its "
                              "ends") from None
    return lambda S: grounded_catenary(scene.length, chord, -load[2], height, S)[:3]
