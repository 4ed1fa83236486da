r"""Closed-form reference solutions for Kirchhoff rods.

These functions are independent of PETSc and of any discretisation; the
test-suite uses them as exact references.  Only numpy and scipy.special
(plus ``scipy.optimize.brentq`` for one scalar root) are used.

Units are SI throughout: lengths in m, bending and torsional stiffnesses
in N m^2, forces in N, torques in N m, angles in rad.

Cantilever elastica (Bisshopp & Drucker 1945; Frisch-Fay, *Flexible Bars*)
--------------------------------------------------------------------------
An inextensible, unshearable planar rod of length ``L`` lies along +x in
its reference state, is clamped at ``S = 0`` (``r(0) = 0``, tangent
``e_x``) and carries a dead tip force ``F = (0, -P, 0)`` at ``S = L``.
Let ``theta(S)`` be the angle of the tangent *below* the x axis, so
``x' = cos(theta)`` and ``y' = -sin(theta)``.  The internal force is the
constant ``n = F``; the moment balance ``m' + r' x n = 0`` with the
bending moment ``m = -EI theta'`` gives

    EI theta'' + P cos(theta) = 0,   theta(0) = 0,   theta'(L) = 0.

Multiplying by ``theta'`` and integrating from ``S`` to ``L``:

    theta'^2 = (2 P / EI) (sin(theta_L) - sin(theta)),

with ``theta_L = theta(L)`` in ``[0, pi/2)`` and ``theta' >= 0``.
Substitute ``1 + sin(theta) = 2 k^2 sin^2(phi)`` with

    k^2 = m = (1 + sin(theta_L)) / 2,  i.e.  k = sin(pi/4 + theta_L/2),

so that ``phi = pi/2`` at the tip and ``sin(phi_1) = 1/(sqrt(2) k)`` at the
clamp.  Then ``sin(theta_L) - sin(theta) = 2 k^2 cos^2(phi)``,
``cos(theta) = 2 k sin(phi) Delta(phi)`` with
``Delta(phi) = sqrt(1 - k^2 sin^2(phi))`` and
``d theta = 2 k cos(phi) d phi / Delta``, hence

    dS = sqrt(EI/P) d phi / Delta(phi),
    S sqrt(P/EI) = F(phi, k) - F(phi_1, k),                        (1)
    L sqrt(P/EI) = K(k) - F(phi_1, k),                             (2)
    dx = cos(theta) dS = 2 k sqrt(EI/P) sin(phi) d phi,
    x(S) = 2 k sqrt(EI/P) (cos(phi_1) - cos(phi)),                 (3)
    dy = -sin(theta) dS = sqrt(EI/P) (2 Delta - 1/Delta) d phi,
    y(S) = 2 sqrt(EI/P) (E(phi, k) - E(phi_1, k)) - S.             (4)

``F`` and ``E`` are the incomplete elliptic integrals of the first and
second kind, ``K`` and ``E`` (one argument) the complete ones.  At the tip
(3) gives ``x_L = 2 k sqrt(EI/P) cos(phi_1) = sqrt(2 EI sin(theta_L) / P)``
and (4) the classic deflection
``delta = -y_L = L - 2 sqrt(EI/P) (E(k) - E(phi_1, k))``.

Numerically stable form
-----------------------
Write ``t = sin(theta_L)`` and ``c = 1 - t``; then ``m = (1 + t)/2``,
``k'^2 = 1 - m = c/2``, ``tan(phi_1) = 1/sqrt(t)``, and at the clamp
``sn u_1 = 1/sqrt(1+t)``, ``cn u_1 = sqrt(t/(1+t))``, ``dn u_1 = 1/sqrt(2)``
for ``u_1 = F(phi_1, k)``.  The differences ``K - F(phi_1)`` and
``E - E(phi_1)`` cancel badly for small loads, so the addition theorems
(``F(phi_1) + F(psi) = K`` when ``tan(phi_1) tan(psi) = 1/k'``)

    K(k) - F(phi_1, k) = F(psi, k),
    E(k) - E(phi_1, k) = E(psi, k) - k^2 sin(phi_1) sin(psi)
                       = E(psi, k) - sqrt(2 t) / 2,
    sin^2(psi) = 2 t / (1 + t),  cos^2(psi) = c / (1 + t),  Delta^2(psi) = c,

turn (2) and the tip position into

    sqrt(P L^2 / EI) = F(psi, k),                                     (2')
    x_L = sqrt(EI/P) sqrt(2 t),
    delta = L - sqrt(EI/P) (2 E(psi, k) - sqrt(2 t)).                 (5)

Along the rod, let ``w = S sqrt(P/EI)`` and ``chi = am(w | m)``, i.e.
``F(chi, k) = w``.  Jacobi's addition formulas for ``u = u_1 + w`` give

    sin(phi) = (cos(chi) Delta(chi) + sqrt(t/2) sin(chi)) / N,
    cos(phi) = (sqrt(t) cos(chi) - sin(chi) Delta(chi) / sqrt(2)) / N,
    N = sqrt(1 + t) (1 - sin^2(chi) / 2),
    Delta(phi) = (Delta(chi) / sqrt(2) - sqrt(t) sin(chi) cos(chi) / 2)
                 / (1 - sin^2(chi) / 2),

the addition formula for Jacobi's epsilon function turns (4) into

    y(S) = sqrt(EI/P) (2 E(chi, k) - sqrt(1 + t) sin(phi) sin(chi)) - S,  (4')

and (3) and the angle become

    x(S) = sqrt(EI/P) (sqrt(2 t) - 2 k cos(phi)),                     (3')
    sin(theta) = t - 2 m cos^2(phi),   cos(theta) = 2 k sin(phi) Delta(phi).

All elliptic integrals are evaluated in Carlson's symmetric form,

    F(a, k) = sin(a) R_F(cos^2 a, Delta^2, 1),
    E(a, k) = F(a, k) - (m/3) sin^3(a) R_D(cos^2 a, Delta^2, 1),
    Delta^2 = cos^2(a) + k'^2 sin^2(a),

so that ``k'^2 = c/2`` enters directly and never as ``1 - m``: for large
loads ``c`` is far below the double-precision spacing of ``m`` near 1
(``c ~ 32 exp(-2 sqrt(P L^2/EI))``).  The unknown is the logit
``z = ln(t/c)`` (``t = expit(z)``, ``c = expit(-z)``), written as the
offset from the small-load value ``ln(P L^2 / (2 EI))`` and found from (2')
by ``brentq`` to full double precision; ``chi`` is found from ``F(chi) = w``
by Newton's method started from ``scipy.special.ellipj``'s amplitude
(which, like all SciPy elliptic functions, takes the *parameter*
``m = k^2``, not the modulus ``k``).

Accuracy and range: positions agree with 400-digit mpmath evaluations of
(1)-(4) to a few ``eps L`` and angles to a few ``eps`` for
``1e-8 <= P L^2/EI <= 1e5``.  Loads whose ``t`` or ``c`` would fall below
1e-290 (``P L^2/EI`` above about 1.4e5 or below about 1e-289) raise
ValueError.
"""

import numpy as np
from scipy.optimize import brentq
from scipy.special import elliprd, elliprf, ellipj, expit

from petsc_rod.scenes.catenary import catenary, catenary_axes  # noqa: F401  (the runtime's, re-exported)

__all__ = ["cantilever_tip", "cantilever_shape", "twisted_rod", "catenary", "catenary_axes"]

_EPS = np.finfo(float).eps
_SMALLEST_RESOLVED_SINE = 1e-290
_NEWTON_MAX_ITERATIONS = 200


def _require_positive(name, value):
    """Raise ValueError unless ``value`` is a finite number > 0."""
    if not (np.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be positive and finite, got {value!r}")


def _require_non_negative(name, value):
    """Raise ValueError unless ``value`` is a finite number >= 0."""
    if not (np.isfinite(value) and value >= 0.0):
        raise ValueError(f"{name} must be non-negative and finite, got {value!r}")


def _validate_cantilever(length, bending_stiffness, force):
    """Check the cantilever inputs; return them as floats."""
    _require_positive("length", length)
    _require_positive("bending_stiffness", bending_stiffness)
    _require_non_negative("force", force)
    return float(length), float(bending_stiffness), float(force)


def _carlson_integrals(sin_a, cos2_a, delta2, m):
    r"""Return ``(F(a, k), E(a, k))`` for ``0 <= a <= pi/2`` in Carlson form.

    ``F = sin(a) R_F(cos^2 a, Delta^2, 1)`` and
    ``E = F - (m/3) sin^3(a) R_D(cos^2 a, Delta^2, 1)`` with
    ``Delta^2 = 1 - m sin^2(a)`` supplied by the caller.
    """
    first = sin_a * elliprf(cos2_a, delta2, 1.0)
    second = first - (m / 3.0) * sin_a**3 * elliprd(cos2_a, delta2, 1.0)
    return first, second


class _TipAngle:
    r"""``t = sin(theta_L)`` and ``c = 1 - sin(theta_L)``, each to full relative precision."""

    def __init__(self, half_load, offset):
        """Set ``t/c = exp(z)``, ``z = ln(half_load) + offset``.

        For ``z < 0`` the ratio ``r = half_load exp(offset)`` is formed
        directly, so that the rounding of ``z`` (absolute, hence large
        relative to ``t`` when ``|z|`` is large) does not enter ``t``.
        """
        logit = np.log(half_load) + offset
        if logit < 0.0:
            ratio = half_load * np.exp(offset)
            self.t, self.c = ratio / (1.0 + ratio), 1.0 / (1.0 + ratio)
        else:
            self.t, self.c = float(expit(logit)), float(expit(-logit))
        self.m = 0.5 * (1.0 + self.t)
        self.m_complement = 0.5 * self.c

    def psi_first_kind(self):
        r"""Return ``F(psi, k) = sin(psi) R_F(cos^2 psi, c, 1)``, ``sin^2(psi) = 2t/(1+t)``."""
        sin_psi = np.sqrt(2.0 * self.t / (1.0 + self.t))
        return sin_psi * elliprf(self.c / (1.0 + self.t), self.c, 1.0)

    def psi_second_kind(self):
        r"""Return ``E(psi, k)``, ``sin^2(psi) = 2t/(1+t)``, ``Delta^2(psi) = c``."""
        sin_psi = np.sqrt(2.0 * self.t / (1.0 + self.t))
        return _carlson_integrals(sin_psi, self.c / (1.0 + self.t), self.c, self.m)[1]


def _solve_tip_angle(load_parameter):
    r"""Solve (2') ``F(psi, k) = sqrt(alpha)`` for the tip angle, ``alpha = P L^2/EI > 0``.

    The residual increases monotonically in the logit ``z = ln(t/c)``.  The
    unknown is the offset ``d = z - ln(alpha/2)`` from the small-load
    guess ``t = alpha/2``, so that brentq's relative tolerance on ``d``
    gives ``t`` to full relative precision for small loads; the bracket
    is grown geometrically around ``d = 0``.
    """
    target = np.sqrt(load_parameter)
    half_load = 0.5 * load_parameter

    def residual(offset):
        return _TipAngle(half_load, offset).psi_first_kind() - target

    lower, upper, step = -1.0, 1.0, 1.0
    while residual(lower) > 0.0:
        lower -= step
        step *= 2.0
    step = 1.0
    while residual(upper) < 0.0:
        upper += step
        step *= 2.0
    offset = brentq(residual, lower, upper, xtol=1e-15, rtol=4.0 * _EPS, maxiter=500)
    tip = _TipAngle(half_load, offset)
    if tip.c < _SMALLEST_RESOLVED_SINE or tip.t < _SMALLEST_RESOLVED_SINE:
        raise ValueError(f"load P L^2/EI = {load_parameter:g} is outside the double-precision range")
    return tip


def _jacobi_amplitude(w, tip):
    r"""Return ``(sin(chi), cos(chi))`` for ``chi = am(w | m)``, i.e. ``F(chi, k) = w``.

    Newton's method on ``F(chi) - w`` (``dF/dchi = 1/Delta(chi)``) in
    Carlson form, started from ``scipy.special.ellipj``'s amplitude.  Where
    ``chi > pi/4`` the iterate is the complement ``beta = pi/2 - chi`` so
    that ``cos(chi) = sin(beta)`` keeps full relative precision near the
    tip, where it can be far below the spacing of doubles near ``pi/2``.
    The iteration stops once the step is below the uncertainty
    ``~ eps (angle + w Delta)`` that rounding of ``F`` leaves in the angle.
    """
    w = np.asarray(w, dtype=float)
    amplitude = np.clip(ellipj(w, tip.m)[3], 0.0, 0.5 * np.pi)
    complemented = amplitude > 0.25 * np.pi
    angle = np.where(complemented, 0.5 * np.pi - amplitude, amplitude)
    direction = np.where(complemented, -1.0, 1.0)
    for _ in range(_NEWTON_MAX_ITERATIONS):
        sin_angle, cos_angle = np.sin(angle), np.cos(angle)
        sin_chi = np.where(complemented, cos_angle, sin_angle)
        cos_chi = np.where(complemented, sin_angle, cos_angle)
        delta2 = cos_chi**2 + tip.m_complement * sin_chi**2
        first, _ = _carlson_integrals(sin_chi, cos_chi**2, delta2, tip.m)
        step = direction * (first - w) * np.sqrt(delta2)
        if np.all(np.abs(step) <= 8.0 * _EPS * (angle + w * np.sqrt(delta2))):
            return sin_chi, cos_chi
        angle = np.clip(angle - step, 0.0, 0.5 * np.pi)
    raise RuntimeError("Newton iteration for the Jacobi amplitude did not converge")


def cantilever_tip(length, bending_stiffness, force):
    r"""Tip position of the clamped-free planar elastica under a dead tip load.

    Rod of length ``L`` (m) along +x, clamped at the origin, with bending
    stiffness ``EI`` (N m^2) and tip force ``(0, -P, 0)``, ``P = force``
    (N, ``P >= 0``).  With ``k^2 = m = (1 + sin(theta_L))/2`` and
    ``sin(phi_1) = 1/(sqrt(2) k)`` (see the module docstring):

        sqrt(P L^2 / EI) = K(k) - F(phi_1, k)          (fixes k, theta_L)
        x_tip = sqrt(2 EI sin(theta_L) / P) = 2 k sqrt(EI/P) cos(phi_1)
        y_tip = -delta = -(L - 2 sqrt(EI/P) (E(k) - E(phi_1, k)))

    evaluated in the cancellation-free forms (2') and (5) of the module
    docstring.  For ``P = 0`` the rod stays straight: ``(L, 0)``.
    Raises ValueError for ``L <= 0``, ``EI <= 0``, ``P < 0`` or a load
    outside the double-precision range (see the module docstring).

    Returns
    -------
    numpy.ndarray, shape (2,)
        ``(x_tip, y_tip)`` in m; ``y_tip <= 0``.
    """
    length, stiffness, force = _validate_cantilever(length, bending_stiffness, force)
    if force == 0.0:
        return np.array([length, 0.0])
    tip = _solve_tip_angle(force * length**2 / stiffness)
    scale = np.sqrt(stiffness / force)
    second_psi = tip.psi_second_kind()
    x_tip = scale * np.sqrt(2.0 * tip.t)
    deflection = length - scale * (2.0 * second_psi - np.sqrt(2.0 * tip.t))
    return np.array([x_tip, -deflection])


def cantilever_shape(length, bending_stiffness, force, s):
    r"""Tangent angle and centreline of the cantilever elastica at arc lengths ``s``.

    Same problem as :func:`cantilever_tip`.  With ``w = s sqrt(P/EI)`` and
    ``chi = am(w | m)`` (``F(chi, k) = w``), the Jacobi amplitude
    ``phi = am(F(phi_1, k) + w | m)`` follows from the addition formulas and

        sin(theta) = 2 k^2 sin^2(phi) - 1,   cos(theta) = 2 k sin(phi) Delta(phi),
        x(s) = 2 k sqrt(EI/P) (cos(phi_1) - cos(phi)),
        y(s) = 2 sqrt(EI/P) (E(phi, k) - E(phi_1, k)) - s,

    evaluated as (3') and (4') of the module docstring.  ``theta`` is the
    angle of the tangent below the x axis (rad); the unit tangent is
    ``(cos(theta), -sin(theta))``.

    Parameters
    ----------
    length, bending_stiffness, force : float
        ``L`` (m), ``EI`` (N m^2), ``P >= 0`` (N).
    s : array_like
        Arc lengths in ``[0, L]`` (m), any shape.

    Returns
    -------
    theta, x, y : numpy.ndarray
        Each of shape ``np.shape(s)``; ``x, y`` in m.
    """
    length, stiffness, force = _validate_cantilever(length, bending_stiffness, force)
    s = np.asarray(s, dtype=float)
    if np.any(~np.isfinite(s)) or np.any(s < 0.0) or np.any(s > length):
        raise ValueError(f"arc lengths s must lie in [0, {length!r}]")
    if force == 0.0:
        return np.zeros_like(s), s.copy(), np.zeros_like(s)
    tip = _solve_tip_angle(force * length**2 / stiffness)
    scale = np.sqrt(stiffness / force)
    t, k = tip.t, np.sqrt(tip.m)

    sin_chi, cos_chi = _jacobi_amplitude(s / scale, tip)
    delta_chi = np.sqrt(cos_chi**2 + tip.m_complement * sin_chi**2)
    second_chi = _carlson_integrals(sin_chi, cos_chi**2, delta_chi**2, tip.m)[1]

    denominator = 1.0 - 0.5 * sin_chi**2
    norm = np.sqrt(1.0 + t) * denominator
    sin_phi = (cos_chi * delta_chi + np.sqrt(0.5 * t) * sin_chi) / norm
    cos_phi = (np.sqrt(t) * cos_chi - sin_chi * delta_chi / np.sqrt(2.0)) / norm
    delta_phi = (delta_chi / np.sqrt(2.0) - 0.5 * np.sqrt(t) * sin_chi * cos_chi) / denominator

    theta = np.arctan2(t - 2.0 * tip.m * cos_phi**2, 2.0 * k * sin_phi * delta_phi)
    x = scale * (np.sqrt(2.0 * t) - 2.0 * k * cos_phi)
    y = scale * (2.0 * second_chi - np.sqrt(1.0 + t) * sin_phi * sin_chi) - s
    return theta, x, y


def twisted_rod(length, torsion_stiffness, angle):
    r"""Uniform twist of a straight rod whose end is rotated by ``angle``.

    For a straight rod of length ``L`` (m) with torsional stiffness ``K3``
    (N m^2), clamped at ``S = 0`` and with its end section rotated by
    ``angle`` (rad) about the axis, the twist strain and the torque are
    uniform:

        u3 = angle / L   (rad/m),     torque = K3 u3 = K3 angle / L   (N m).

    Returns
    -------
    dict
        ``{'u3': float, 'torque': float}``.
    """
    _require_positive("length", length)
    _require_positive("torsion_stiffness", torsion_stiffness)
    twist = float(angle) / float(length)
    return {"u3": twist, "torque": float(torsion_stiffness) * twist}


def elastic_catenary(length, axial_stiffness, weight, span, rise):
    """Irvine's elastic catenary (H. M. Irvine, Cable Structures, 1981, §2.2): a cable of
    unstretched length L and axial stiffness EA (N) under a uniform weight w per metre of
    unstretched line (N/m, along -z), from a pin at the origin to a pin at (span, rise)
    (m, span > 0, z up). With H the horizontal tension and V the upward reaction at the
    origin, the force in the line at s is (H, w s - V), its tension T(s) = |.|, the
    stretch 1 + T/EA, r' = (1 + T/EA) (H, w s - V) / T and

        x(s) = H s / EA + (H / w) [asinh(V / H) - asinh((V - w s) / H)],
        z(s) = (w s^2 / 2 - V s) / EA + (H / w) [sqrt(1 + ((w s - V) / H)^2)
                                                  - sqrt(1 + (V / H)^2)].

    H, V solve x(L) = span, z(L) = rise (Newton from the inextensible catenary's
    shape-free guess, scipy's fsolve). Returns (H, V, positions) with positions(s) the
    (..., 2) array (x, z) of the centreline at unstretched arc lengths s.
    """
    from scipy.optimize import fsolve

    for name, value in (("length", length), ("axial_stiffness", axial_stiffness),
                        ("weight", weight), ("span", span)):
        _require_positive(name, value)
    L, EA, w = float(length), float(axial_stiffness), float(weight)

    def positions(s, H, V):
        s = np.asarray(s, dtype=float)
        x = H * s / EA + H / w * (np.arcsinh(V / H) - np.arcsinh((V - w * s) / H))
        z = ((w * s**2 / 2 - V * s) / EA
             + H / w * (np.hypot(1.0, (w * s - V) / H) - np.hypot(1.0, V / H)))
        return np.stack([x, z], axis=-1)

    def residual(unknowns):
        H, V = np.exp(unknowns[0]), unknowns[1]
        return positions(L, H, V) - np.array([span, rise])

    guess = [np.log(w * L), w * L / 2]
    solution, _, _, message = fsolve(residual, guess, xtol=1e-14, full_output=True)
    if np.abs(residual(solution)).max() > 1e-12 * L:
        raise ValueError(f"elastic_catenary: no solution ({message})")
    H, V = float(np.exp(solution[0])), float(solution[1])
    return H, V, lambda s: positions(s, H, V)
