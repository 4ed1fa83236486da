"""The elastic catenary, hanging or resting on a flat frictionless seabed: the classical
closed form of an extensible, perfectly flexible line (Irvine, Cable Structures, 1981,
§2.2; the mooring-line form of MoorPy's catenary without seabed friction), for the checks
of axial stretch (tests, scripts/stability_matrix.py).

A line of unstretched length L, weight w per metre of unstretched line (N/m, along
-z) and axial stiffness EA (N), from an anchor at the origin on the seabed z = 0 to an
end at (X, Z) in the vertical plane of e_x. Its tension is T = sqrt(H^2 + V^2), H the
constant horizontal force and V(s) = V_A + w s the vertical one at unstretched arc length
s, and its strain T / EA. Where it hangs from the anchor (V_A > 0):

    x(s) = H s / EA + (H / w) (asinh((V_A + w s) / H) - asinh(V_A / H)),
    z(s) = (V_A s + w s^2 / 2) / EA + (T(s) - T(0)) / w.

Where V_A would be negative it rests on the seabed, straight and under H, up to the
touchdown at s = L_B (x = L_B (1 + H / EA)), and hangs from there with V_A = 0. The two
unknowns (H and V_A, or H and L_B) are found by nested bracketing (scipy.optimize.brentq).
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq


@dataclass(frozen=True)
class ElasticCatenary:
    """A solved line: H (N), V_A (N, 0 on the seabed), grounded unstretched length L_B
    (m), and the data L (m), w (N/m), EA (N)."""

    H: float
    V_A: float
    grounded: float
    length: float
    weight: float
    axial_stiffness: float

    def at(self, s):
        """(x, z, tension) at unstretched arc lengths s (any shape): m, m, N."""
        s = np.asarray(s, dtype=float)
        H, w, EA = self.H, self.weight, self.axial_stiffness
        hanging = np.clip(s - self.grounded, 0.0, None)            # from the touchdown
        V = self.V_A + w * hanging
        T0 = np.hypot(H, self.V_A)
        T = np.hypot(H, V)
        x = (self.grounded * (1 + H / EA) + H * hanging / EA
             + (H / w) * (np.arcsinh(V / H) - np.arcsinh(self.V_A / H)))
        z = (self.V_A * hanging + 0.5 * w * hanging**2) / EA + (T - T0) / w
        on_seabed = s < self.grounded
        return (np.where(on_seabed, s * (1 + H / EA), x), np.where(on_seabed, 0.0, z),
                np.where(on_seabed, H, T))

    def end_point(self):
        x, z, _ = self.at(self.length)
        return float(x), float(z)


def _bracket(function, start):
    """An upper end above ``start`` > 0 where the increasing ``function`` is positive."""
    upper = start
    for _ in range(200):
        if function(upper) > 0:
            return upper
        upper *= 2.0
    raise ValueError("elastic catenary: no bracket (the end cannot be reached)")


def elastic_catenary(length, weight, axial_stiffness, span, rise, on_seabed=True):
    """The ElasticCatenary from the anchor at the origin to (span, rise) (module
    docstring); ``on_seabed`` lets the line rest on the seabed z = 0 (else it hangs,
    V_A of any sign)."""
    scale = weight * length

    def line(H, V_A, grounded):
        return ElasticCatenary(H, V_A, grounded, length, weight, axial_stiffness)

    def spanned(V_A, grounded):
        """The line whose H makes the span, for the given V_A and L_B."""
        def excess(H):
            return line(H, V_A, grounded).end_point()[0] - span
        return line(brentq(excess, 1e-30 * scale, _bracket(excess, scale), xtol=1e-300,
                           rtol=4 * np.finfo(float).eps, maxiter=500), V_A, grounded)

    def climb(V_A):                       # z(L) - rise, increasing in V_A
        return spanned(V_A, 0.0).end_point()[1] - rise

    if on_seabed and climb(0.0) >= 0.0:
        def sink(grounded):               # rise - z(L), increasing in L_B
            return rise - spanned(0.0, grounded).end_point()[1]
        grounded = brentq(sink, 0.0, min(length, span) * (1 - 1e-12), xtol=1e-300,
                          rtol=4 * np.finfo(float).eps, maxiter=500)
        return spanned(0.0, grounded)
    upper = _bracket(climb, scale)
    lower = 0.0 if on_seabed else -_bracket(lambda v: -climb(-v), scale)
    V_A = brentq(climb, lower, upper, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
    return spanned(V_A, 0.0)
