"""The natural modes of a system's bodies and free points on their lines about the
coupled equilibrium (docs/modes.md, "The coupled system's modes"): the floater's
natural periods on its moorings, MoorPy's and OrcaFlex's first look. Numpy only; every
rank computes the same numbers from the solver's small arrays.

    K x = omega^2 M x     over the free unknowns q of system/equilibrium.Layout

K = -dR/dq, the Jacobian of the equilibrium's residual at the solution (the one its
Newton uses): each line's exact stiffness (its factored second variation) through the
ends' lever maps, the fairleads' arms turning, the weight's and buoyancy's arms, the
waterplane's or a given hydrostatic matrix; it is not symmetrised (a constant external
moment makes its rotational block unsymmetric, docs/systems.md), so the problem is
solved as the eigenvalues of M^-1 K (numpy.linalg.eig). M is the rigid bodies' mass
about their reference points, in global axes, for the increments (dX, dtheta):

    M_b = [[m I, -m [c]x], [m [c]x, R I_g R^T + m ([c]x)^T [c]x]] + T A T^T,
    c = R cog,  T = diag(R, R)

(A the body's added mass, body axes), each free point's (m + ca rho V) I, and, where
asked, each line's mass in air lumped half at each end (a body end's point mass m_e at
its arm a adds L^T m_e L, L = [I, -[a]x]). The lines are quasi-static in these modes:
their stiffness is their static one at the equilibrium, their own dynamics is in their
modes with the ends held (analysis/modes.py). Unknowns without mass (a massless joint,
a body's rotation with no inertia) follow quasi-statically: condensed out of K
(K_rr - K_r0 K_00^-1 K_0r in a basis split by M's null space), then recovered.

An equilibrium with a negative eigenvalue of M^-1 K (a divergence), or with a complex
pair beyond round-off (a circulatory stiffness), has no vibration modes about it:
SystemModesRefused says which, never a frequency.
"""

from dataclasses import dataclass

import numpy as np

from petsc_rod.analysis.modes import Modes
from petsc_rod.errors import RodInputError
from petsc_rod.model.line import UniformLine
from petsc_rod.system.bodies import lever_map, skew

# |Im lambda| / |lambda| above this is a complex pair (a flutter of the circulatory
# stiffness), not round-off of a symmetric problem's degenerate pair
COMPLEX = 1e-6
# an eigenvalue below -NEGATIVE times the largest |lambda| is negative (unstable); M's
# eigenvalues below ZERO_MASS times its largest are its null space (massless unknowns)
NEGATIVE = 1e-10
ZERO_MASS = 1e-12


class SystemModesRefused(Exception):
    """The equilibrium has no vibration modes: ``negative`` eigenvalues of M^-1 K below
    0, ``complex`` pairs; or ``reason`` (no free unknown with mass)."""

    def __init__(self, reason, negative=0, complex_=0):
        super().__init__(reason)
        self.negative, self.complex = negative, complex_


@dataclass
class SystemModes:
    """The modes of the free unknowns, lowest first (n): ``omega2`` (rad^2/s^2),
    ``shapes`` (n, k) on the unknowns ``dofs`` [(point or body, 'x'...'yaw')] (m, rad),
    each normalised to 1 at its dominant unknown (the largest share), that entry
    positive; ``shares`` (n, k) of the kinetic energy on the mass matrix's diagonal,
    M_ii x_i^2 / sum_j M_jj x_j^2; ``modal_mass`` x^T M x of the normalised shape (kg,
    or kg m^2 where the dominant unknown is a rotation); ``labels`` the dominant
    unknowns' names; ``condensed`` the number of massless combinations of the unknowns
    (M's null space: a body without inertia turning about its cog) that follow
    quasi-statically;
    ``imaginary`` the largest |Im lambda| / |lambda| left as round-off; ``line_mass``
    whether the lines' mass is lumped at their ends; ``stiffness`` (k, k), ``mass``
    (k, k) the matrices solved."""

    omega2: np.ndarray
    shapes: np.ndarray
    shares: np.ndarray
    modal_mass: np.ndarray
    dofs: list
    labels: list
    condensed: int = 0
    imaginary: float = 0.0
    line_mass: bool = False
    stiffness: np.ndarray = None
    mass: np.ndarray = None

    # Hz and s of omega2, as a line's modes have them
    frequencies = Modes.frequencies
    periods = Modes.periods


def rigid_mass(mass, cog, inertia, added, R):
    """(6, 6) of one body (module docstring): ``mass`` kg, ``cog`` (3,) and ``inertia``
    (3, 3) about it in body axes, ``added`` (6, 6) body axes, R (3, 3) body to global."""
    c = R @ np.asarray(cog, dtype=float)
    C = skew(c)
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[:3, 3:] = -mass * C
    M[3:, :3] = mass * C
    M[3:, 3:] = R @ inertia @ R.T + mass * C.T @ C
    T = np.zeros((6, 6))
    T[:3, :3] = T[3:, 3:] = R
    return M + T @ added @ T.T


def inertia_tensor(body):
    """(3, 3) of Body.inertia (None: zero; 3 numbers: the diagonal)."""
    if body.inertia is None:
        return np.zeros((3, 3))
    values = np.asarray(body.inertia, dtype=float).ravel()
    return np.diag(values) if values.size == 3 else values.reshape(3, 3)


def line_masses(system):
    """(n_lines,): each line's mass in air, kg: its sections' line types' mass per
    length times their lengths, a UniformLine's ``mass`` times its length (its load is
    a weight in water: check_line_masses refuses one without a mass)."""
    check_line_masses(system)
    return np.array([float(line.line.mass * line.line.length)
                     if isinstance(line.line, UniformLine) else
                     float(sum(entry[0].mass * float(entry[1])
                               for entry in line.line.sections))
                     for line in system.lines])


def check_line_masses(system, option="system_modes_line_mass"):
    """RodInputError where a line's mass in air is not known for ``option`` (the lines'
    mass lumped at their ends): a UniformLine without ``mass``."""
    for line in system.lines:
        if isinstance(line.line, UniformLine) and line.line.mass is None:
            raise RodInputError(f"{option}: line {line.name} is a UniformLine without a "
                                "mass in air (its load is a weight in water, not a mass): "
                                "give UniformLine.mass (kg/m) or sections of line types")


def mass_matrix(solver, line_mass=False):
    """M (layout.size, layout.size) of the solver's system at its state (module
    docstring)."""
    system, layout, state = solver.system, solver.layout, solver.state
    rho = solver.rho
    M = np.zeros((layout.size, layout.size))
    for i, body in enumerate(system.bodies):
        added = (np.zeros((6, 6)) if body.added_mass is None else
                 np.reshape(np.asarray(body.added_mass, dtype=float), (6, 6)))
        dofs = layout.body_dofs[i]
        M[np.ix_(dofs, dofs)] += rigid_mass(body.mass, body.cog, inertia_tensor(body),
                                             added, state.bodies.R[i])
    for j, index in enumerate(layout.point_index):
        point = system.points[index]
        dofs = layout.point_dofs[3 * j:3 * j + 3]
        M[dofs, dofs] += point.mass + point.ca * rho * point.volume
    if line_mass:
        arms = solver.arms(state)
        halves = np.repeat(line_masses(system)[:, None] / 2, 2, axis=1)   # (n, 2)
        for k in range(len(system.lines)):
            for end in range(2):
                dofs = layout.ends[k, end]
                if layout.body_end[k, end] >= 0:
                    L = lever_map(arms[k, end])[0]
                    M[np.ix_(dofs, dofs)] += halves[k, end] * L.T @ L
                elif dofs[0] < layout.size:
                    M[dofs[:3], dofs[:3]] += halves[k, end]
    return M


def condensed(K, M):
    """(K_r, M_r, recover, massless) of K and M split by M's null space: Q = [Q_r,
    Q_0] from M's eigenvectors, K_r = K'_rr - K'_r0 K'_00^-1 K'_0r in that basis,
    M_r = Q_r^T M Q_r; recover(y) the full shapes Q_r y + Q_0 z, z = -K'_00^-1 K'_0r y;
    ``massless`` the dimension of M's null space."""
    values, vectors = np.linalg.eigh((M + M.T) / 2)
    scale = max(float(np.abs(values).max(initial=0.0)), np.finfo(float).tiny)
    zero = values <= ZERO_MASS * scale
    Qr, Q0 = vectors[:, ~zero], vectors[:, zero]
    massless = int(zero.sum())
    if not zero.any():
        return K, M, (lambda y: y), massless
    K00 = Q0.T @ K @ Q0
    K0r = Q0.T @ K @ Qr
    follow = -np.linalg.solve(K00, K0r)                      # z = follow y
    K_r = Qr.T @ K @ Qr + Qr.T @ K @ Q0 @ follow
    M_r = Qr.T @ M @ Qr
    return K_r, M_r, (lambda y: Qr @ y + Q0 @ (follow @ y)), massless


def system_modes(solver, line_mass=False):
    """The SystemModes of the solver's system at its equilibrium (after solver.solve()):
    every mode of its free unknowns; SystemModesRefused where the equilibrium is
    unstable or its modes complex (module docstring). The same on every rank."""
    layout = solver.layout
    free = layout.free
    if not free.size:
        raise SystemModesRefused("no free point or body degree of freedom")
    _, J = solver.residual(solver.state, solver.loads, solver.forces, solver.stiffnesses)
    K = -J[np.ix_(free, free)]
    M = mass_matrix(solver, line_mass)[np.ix_(free, free)]
    if not np.any(M):
        raise SystemModesRefused("no free point or body has mass: give the bodies mass "
                                 "(and inertia), the free points mass, or lump the lines' "
                                 "mass at their ends")
    try:
        K_r, M_r, recover, massless = condensed(K, M)
        values, vectors = np.linalg.eig(np.linalg.solve(M_r, K_r))
    except np.linalg.LinAlgError:
        raise SystemModesRefused("the stiffness of the massless unknowns is singular: "
                                 "nothing holds them quasi-statically") from None
    size = max(float(np.abs(values).max(initial=0.0)), np.finfo(float).tiny)
    ratio = np.abs(values.imag) / np.maximum(np.abs(values), np.finfo(float).tiny)
    complex_ = int(np.count_nonzero(ratio > COMPLEX))
    negative = int(np.count_nonzero((values.real < -NEGATIVE * size) & (ratio <= COMPLEX)))
    if negative or complex_:
        parts = ([f"{negative} negative eigenvalue{'s' if negative != 1 else ''} of "
                  "M^-1 K (it diverges)"] if negative else []) + \
                ([f"{complex_} complex eigenvalue{'s' if complex_ != 1 else ''} of M^-1 K "
                  "(a non-conservative stiffness: it flutters)"] if complex_ else [])
        raise SystemModesRefused(f"the system's equilibrium is unstable ({'; '.join(parts)}"
                                 "): no vibration modes about it", negative, complex_)
    order = np.argsort(values.real)
    omega2 = np.maximum(values.real[order], 0.0)
    shapes = recover(vectors.real[:, order]).T                  # (n, k)
    names = [layout.names[i] for i in free]
    diagonal = np.diag(M)
    energy = shapes**2 * diagonal
    shares = energy / np.maximum(energy.sum(axis=1, keepdims=True), np.finfo(float).tiny)
    dominant = np.argmax(shares, axis=1)
    rows = np.arange(len(order))
    shapes = shapes / shapes[rows, dominant][:, None]
    modal_mass = np.einsum("ni,ij,nj->n", shapes, M, shapes)
    return SystemModes(omega2, shapes, shares, modal_mass, names,
                       [f"{names[i][0]} {names[i][1]}" for i in dominant],
                       massless,
                       float(ratio.max(initial=0.0)), bool(line_mass), K, M)


def table_lines(modes):
    """The run's lines of the system's modes: a heading saying what they are, one line
    per mode (f, T, modal mass, the dominant unknown and the shares over 0.05)."""
    what = ("the lines' mass lumped half at each end" if modes.line_mass else
            "the lines' mass left out")
    lines = [f"system modes: {len(modes.omega2)} of the bodies and free points about the "
             "equilibrium (undamped; the lines quasi-static: their static stiffness, "
             f"{what}; their own dynamics in their modes with the ends held)"]
    if modes.condensed:
        lines.append(f"  {modes.condensed} massless combination(s) of the unknowns (M's "
                     "null space: a body without inertia turning about its cog, a massless "
                     "point) follow quasi-statically")
    lines.append(f"  {'mode':>4} {'f (Hz)':>12} {'T (s)':>12} {'modal mass':>14}  "
                 "dominant (shares of the kinetic energy)")
    for k in range(len(modes.omega2)):
        big = np.flatnonzero(modes.shares[k] >= 0.05)
        big = big[np.argsort(-modes.shares[k][big])]
        shares = ", ".join(f"{modes.dofs[i][0]} {modes.dofs[i][1]} {modes.shares[k][i]:.2f}"
                           for i in big)
        lines.append(f"  {k + 1:>4} {modes.frequencies[k]:12.6g} {modes.periods[k]:12.6g} "
                     f"{modes.modal_mass[k]:14.6g}  {modes.labels[k]} ({shares})")
    return lines
