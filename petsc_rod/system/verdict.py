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

A line that is a saddle of its own energy with its ends held (HeldLine.stable False,
Equilibrium.unstable) makes the system a saddle too, whatever K says: the total
potential's Hessian in (the lines' unknowns, q) is congruent to the lines' Hessians with
their ends held beside K (the Schur complement, which K is), so a negative direction of
one line is one of the whole (Sylvester). A slack chain pushed into compression at its
anchor under a large body load is such a line: the watch circle reached different
equilibria there from different neighbours, each said stable before.

Not conservative, no verdict (None, with the reason), as a single line with drag
(docs/stability.md): a current (the drag on the lines and points has no potential),
seabed friction (it dissipates), a body's load with a moment (a moment fixed in space
is not the gradient of a potential over rotations; it is what leaves K's rotational
block unsymmetric at the equilibrium: K - K^T = -[M_load]x).
"""

from dataclasses import dataclass, replace

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
    with the largest entry of its eigenvector (None where there is no eigenvalue);
    ``lines`` the names of the lines that are saddles with their ends held (the system is
    then a saddle: module docstring)."""

    stable: object
    negative: int = 0
    lowest: float = float("nan")
    dof: tuple = None
    length: float = 1.0
    reason: str = ""
    lines: tuple = ()

    def text(self):
        """The run's words: 'stable', 'a saddle of the system: ...', or 'no verdict:
        ...'."""
        if self.stable is None:
            return f"no verdict: {self.reason}"
        if self.lines:
            several = len(self.lines) > 1
            text = (f"a saddle of the system: line{'s' if several else ''} "
                    f"{', '.join(self.lines)} {'are saddles' if several else 'is a saddle'} "
                    f"of {'their' if several else 'its'} energy with the ends held (a lower "
                    "energy with the points and bodies where they are)")
            if self.negative:
                text += (f", and its stiffness has {self.negative} negative eigenvalue(s), "
                         f"the lowest {self.lowest:.6g} N/m, mostly in {self.dof[0]} "
                         f"{self.dof[1]}")
            return text
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


def system_verdict(solver, line_verdicts=None):
    """The SystemVerdict of ``solver``'s system at its state (after its solve: the
    lines' forces and stiffnesses there), ``line_verdicts`` {line name: True, False a
    saddle with its ends held, None} (SystemSolver.line_verdicts): a saddle where some
    line is one (module docstring). The same on every rank."""
    reason = not_conservative(solver.system)
    if reason:
        return SystemVerdict(None, reason=reason)
    saddles = tuple(name for name, verdict in (line_verdicts or {}).items()
                    if verdict is False)
    verdict = _stiffness_verdict(solver)
    if saddles:
        return replace(verdict, stable=False, lines=saddles)
    return verdict


def _stiffness_verdict(solver):
    """The SystemVerdict of the system's stiffness K alone (module docstring)."""
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
