"""The catenary on an incline: an inextensible, perfectly flexible line resting on a
rigid, frictionless plane seabed of slope alpha and hanging from there to its top end,
for the checks of the sloping seabed (tests/solver/test_seabed_slope.py; docs/riser.md
§6). The classical problem of a mooring line or a riser on a sloping seabed (e.g.
O. M. Faltinsen, Sea Loads on Ships and Offshore Structures, 1990, §8, for the flat
case; the slope enters only through the grounded part's equilibrium).

In the vertical plane of the ends, x horizontal from the anchor (at the origin, on the
seabed) toward the top end at (X, Z), z up, the seabed is z = x tan(alpha) (alpha > 0:
it rises toward the top). w is the weight per metre (N/m, along -z), L the length.

* The grounded part, 0 <= s <= L_g, lies straight along u = (cos alpha, sin alpha).
  The seabed pushes normal to itself with N = w cos(alpha) per metre, and without
  friction the tangential balance T' = w sin(alpha) makes the tension
  T(s) = T_td - w sin(alpha) (L_g - s), T_td = H / cos(alpha) at the touchdown point.
* The suspended part, sigma = s - L_g in [0, L - L_g], is a catenary of horizontal
  force H (a = H / w) leaving the seabed tangentially, V(sigma) = H tan(alpha) + w sigma:

      x = L_g cos(alpha) + a (asinh(V / H) - asinh(tan(alpha))),
      z = L_g sin(alpha) + a (sqrt(1 + (V / H)^2) - 1 / cos(alpha)),

  and the force n = (H, V) (the part beyond S on the part before), tangent n / |n|.
* The unknowns a and L_g: with v = (-sin(alpha), cos(alpha)) the normal to the
  seabed and D(a, sigma) the suspended part's extent (x, z) from its touchdown point,

      v.D(a, L - L_g) = v.(X, Z)               (the top's height above the incline),
      L_g + u.D(a, L - L_g) = u.(X, Z)          (its distance along it).

  The first fixes the suspended length for each a (v.D grows with sigma: the tangent
  turns up from the seabed), the second a, both by brentq. alpha = 0 is the catenary
  with touchdown of scenes/touchdown.py.

A solution needs 0 < L_g < L and T at the anchor, T_0 = H / cos(alpha) - w sin(alpha)
L_g, positive (else the grounded part would be in compression: it would slide down to
the anchor and pile up); ValueError otherwise.
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

TIGHT = dict(xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)


@dataclass(frozen=True)
class InclineCatenary:
    """A solved line (module docstring): H (N), the grounded length L_g (m), and the
    data L (m), w (N/m), alpha (rad)."""

    H: float
    grounded: float
    length: float
    weight: float
    alpha: float

    def at(self, S):
        """(x, z, n (2,: horizontal, vertical), tension) at arc lengths S (any shape):
        m, m, N, N."""
        S = np.asarray(S, dtype=float)
        H, w, a, alpha = self.H, self.weight, self.H / self.weight, self.alpha
        on = S < self.grounded
        sigma = np.maximum(S - self.grounded, 0.0)
        V = H * np.tan(alpha) + w * sigma
        x = self.grounded * np.cos(alpha) + a * (np.arcsinh(V / H) - np.arcsinh(np.tan(alpha)))
        z = self.grounded * np.sin(alpha) + a * (np.hypot(1.0, V / H) - 1.0 / np.cos(alpha))
        T_ground = H / np.cos(alpha) - w * np.sin(alpha) * (self.grounded - S)
        x = np.where(on, S * np.cos(alpha), x)
        z = np.where(on, S * np.sin(alpha), z)
        n = np.stack([np.where(on, T_ground * np.cos(alpha), H),
                      np.where(on, T_ground * np.sin(alpha), V)], axis=-1)
        return x, z, n, np.linalg.norm(n, axis=-1)

    @property
    def anchor_tension(self):
        """T_0 = H / cos(alpha) - w sin(alpha) L_g, N."""
        return self.H / np.cos(self.alpha) - self.weight * np.sin(self.alpha) * self.grounded


def _suspended(a, sigma, alpha):
    """D(a, sigma) (module docstring): the extent (x, z) of a suspended length sigma."""
    t = np.tan(alpha)
    V = t + sigma / a                                      # V / H
    return np.array([a * (np.arcsinh(V) - np.arcsinh(t)),
                     a * (np.hypot(1.0, V) - np.hypot(1.0, t))])


def incline_catenary(length, weight, alpha, span, rise):
    """The InclineCatenary from the anchor at the origin on the seabed z = x tan(alpha)
    to the top end at horizontal distance ``span`` and height ``rise`` (m), ``alpha`` in
    rad. ValueError where the line does not rest on the seabed taut (module docstring)."""
    u = np.array([np.cos(alpha), np.sin(alpha)])
    v = np.array([-np.sin(alpha), np.cos(alpha)])
    top = np.array([span, rise], dtype=float)
    height, distance = float(v @ top), float(u @ top)
    if height <= 0 or length <= np.hypot(span, rise):
        raise ValueError("incline catenary: the top end must be above the seabed and "
                         "nearer than the length")

    def suspended_length(a):
        """sigma with v.D(a, sigma) = height (module docstring), or L if none."""
        def rise_of(sigma):
            return float(v @ _suspended(a, sigma, alpha)) - height
        if rise_of(length) < 0:
            return length
        return brentq(rise_of, 0.0, length, **TIGHT)

    def excess(a):                 # L_g + u.D - u.(X, Z), increasing in a
        sigma = suspended_length(a)
        return length - sigma + float(u @ _suspended(a, sigma, alpha)) - distance

    lower, upper = 1e-9 * length, length
    while excess(upper) < 0:
        upper *= 2.0
        if upper > 1e12 * length:
            raise ValueError("incline catenary: no solution (the line is too short)")
    if excess(lower) > 0:
        raise ValueError("incline catenary: the line is too long to lie taut")
    a = brentq(excess, lower, upper, **TIGHT)
    sigma = suspended_length(a)
    line = InclineCatenary(a * weight, length - sigma, length, weight, alpha)
    if not (0 < line.grounded < length) or line.anchor_tension <= 0:
        raise ValueError("incline catenary: the line does not rest on the seabed taut "
                         f"(grounded {line.grounded:g} m, anchor tension "
                         f"{line.anchor_tension:g} N)")
    return line
