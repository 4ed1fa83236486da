"""The system's own stability at its equilibrium (docs/systems.md, "The system's
verdict"): each line is tested with its ends held (HeldLine.stable), but a Newton on
the points' and bodies' unknowns can land on a saddle of the system whose lines are
each stable (a body whose cog stands high above its moorings' restoring, upright by
symmetry: each line a minimiser with its ends held, the body a saddle in roll and
pitch). Numpy only; every rank computes the same numbers from the solver's small
arrays.

    K = -dR/dq          over the free unknowns q of system/equilibrium.Layout

is the Jacobian the Newton uses (the lines' exact stiffnesses through the ends' lever
maps, the arms turning, the weight's and buoyancy's arms, the hydrostatics). For a
conservative system R = -dV/dq of a total potential V, and q's rotations are
increments on the left (R <- exp([dtheta]x) R), so K is V's second derivative along
the group: its antisymmetric part is half the skew matrix of the residual's moment,
[M]x / 2 per body (Jacobi's identity, system/bodies.lever_stiffness), which vanishes
at an equilibrium, and its symmetric part is the Hessian of V in the exponential
coordinates about the equilibrium (exp's second-order term [theta]x^2 / 2 is
symmetric and multiplies the gradient, zero there). So the test is

    H = (K + K^T) / 2,   D H D,  D = diag(1 on translations, 1 / l on rotations)

(l the solver's length scale: every entry N/m; Sylvester's law of inertia keeps the
signs of the eigenvalues under the congruence): all eigenvalues positive, a strict
local minimiser of V (stable); one below -TOLERANCE times the largest |eigenvalue|, a
saddle; the lowest within it, no verdict (neutral to round-off).

Not conservative, no verdict (None, with the reason), as a single line with drag
(docs/stability.md): a current (the drag on the lines and points has no potential),
seabed friction (it dissipates), a body's load with a moment (a moment fixed in space
is not the gradient of a potential over rotations; it is what leaves K's rotational
block unsymmetric at the equilibrium: K - K^T = -[M_load]x).
"""

from dataclasses import dataclass

import numpy as np

# an eigenvalue of D H D below -TOLERANCE times the largest |eigenvalue| is negative;
# the lines' stiffnesses are exact to their solves' tolerances, far inside it
TOLERANCE = 1e-8


@dataclass(frozen=True)
class SystemVerdict:
    """``stable``: True a strict local minimiser of the system's potential in its free
    unknowns, False a saddle, None no verdict (``reason`` says why); ``negative`` the
    number of negative eigenvalues of D H D (module docstring), ``lowest`` the lowest
    (N/m: rotations scaled by ``length``, m), ``dof`` (node, 'x'...'yaw') the unknown
    with the largest entry of its eigenvector (None where there is no eigenvalue)."""

    stable: object
    negative: int = 0
    lowest: float = float("nan")
    dof: tuple = None
    length: float = 1.0
    reason: str = ""

    def text(self):
        """The run's words: 'stable', 'a saddle of the system: ...', or 'no verdict:
        ...'."""
        if self.stable is None:
            return f"no verdict: {self.reason}"
        if self.stable:
            return (f"stable (the lowest eigenvalue of its stiffness {self.lowest:.6g} "
                    f"N/m, mostly in {self.dof[0]} {self.dof[1]})")
        return (f"a saddle of the system: its stiffness has {self.negative} negative "
                f"eigenvalue(s), the lowest {self.lowest:.6g} N/m, mostly in {self.dof[0]} "
                f"{self.dof[1]}")

    def code(self):
        """The result file's ``system_stable``: 1 stable, 0 a saddle, -1 no verdict."""
        return -1 if self.stable is None else int(self.stable)


def not_conservative(system):
    """Why ``system`` has no potential (module docstring), '' where it has one."""
    environment = system.environment
    current = environment.current
    if current is not None and np.any(np.asarray(current, dtype=float)[..., -3:] != 0):
        return ("a current: its drag on the lines and points is not conservative "
                "(no potential energy), so the stiffness's eigenvalues say nothing of "
                "stability")
    if environment.seabed_friction is not None and np.any(
            np.asarray(environment.seabed_friction, dtype=float) != 0):
        return "seabed friction, which is not conservative (it dissipates)"
    for body in system.bodies:
        if np.any(np.asarray(body.load, dtype=float)[3:] != 0):
            return (f"body {body.name}'s load has a moment, fixed in space, which is not "
                    "conservative over rotations (it leaves the stiffness unsymmetric)")
    return ""


def system_verdict(solver):
    """The SystemVerdict of ``solver``'s system at its state (after its solve: the
    lines' forces and stiffnesses there). The same on every rank."""
    reason = not_conservative(solver.system)
    if reason:
        return SystemVerdict(None, reason=reason)
    layout = solver.layout
    free = layout.free
    if not free.size:
        return SystemVerdict(None, reason="no free point or body degree of freedom")
    _, J = solver.residual(solver.state, solver.loads, solver.forces, solver.stiffnesses)
    K = -J[np.ix_(free, free)]
    scale = np.where(layout.is_moment[free], 1.0 / solver.length, 1.0)
    H = 0.5 * (K + K.T) * np.outer(scale, scale)
    if not np.all(np.isfinite(H)):
        return SystemVerdict(None, length=solver.length,
                             reason="the system's stiffness is not finite")
    values, vectors = np.linalg.eigh(H)
    size = max(float(np.abs(values).max()), np.finfo(float).tiny)
    negative = int(np.count_nonzero(values < -TOLERANCE * size))
    dof = layout.names[free[int(np.argmax(np.abs(vectors[:, 0])))]]
    if not negative and values[0] <= TOLERANCE * size:
        return SystemVerdict(None, 0, float(values[0]), dof, solver.length,
                             "its stiffness is singular to round-off (a neutral "
                             f"direction, mostly in {dof[0]} {dof[1]})")
    return SystemVerdict(negative == 0, negative, float(values[0]), dof, solver.length)
