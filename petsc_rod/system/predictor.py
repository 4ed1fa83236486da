"""The catenary predictor of a system's equilibrium (docs/systems.md, "Speed"): the same
system solved first with analytic elastic catenaries standing in for its rod lines, so
that the rods' first solves start at the ends where the system will settle and one
Newton at the full load finishes the solve (MoorPy's and MAP++'s lines, used here as a
start only; system/equilibrium.SystemSolver._solve).

**The line.** A uniform line of length L, submerged weight w (N/m, > 0) and axial
stiffness EA (N; inf: inextensible) between a lower end a and an upper end b, the chord
c = x_b - x_a of horizontal length l (direction e_h) and rise h >= 0, with horizontal
tension H and the vertical tension V at b. Hanging clear of the seabed (V >= w L, or a
lower end above the seabed), with V_a = V - w L (Irvine's elastic catenary):

    l = (H / w) (asinh(V / H) - asinh(V_a / H)) + H L / EA,
    h = (sqrt(H^2 + V^2) - sqrt(H^2 + V_a^2)) / w + (V L - w L^2 / 2) / EA;

resting on a flat frictionless seabed from a lower end lying on it (V < w L: the
grounded length L - V / w carries H):

    l = L - V / w + (H / w) asinh(V / H) + H L / EA,
    h = (H / w) (sqrt(1 + (V / H)^2) - 1) + V^2 / (2 EA w).

(H, V) solves these by Newton with their exact 2 x 2 Jacobian D = d(l, h)/d(H, V),
started from Peyrot and Goulois' guess. The forces ON the ends: F_b = -H e_h - V e_z,
F_a = H e_h + max(V_a, 0) e_z (grounded: the seabed carries the rest of the weight).
Their stiffness K = d(F_a, F_b)/d(x_a, x_b) (6, 6) is exact: d(H, V) = D^-1 (dl, dh),
dl = e_h . dc, dh = dc_z, de_h = (I - e_h e_h^T) dc_h / l, and the forces depend on
the chord alone (x_a moves them as -x_b does).

**Where a catenary stands in.** A line of one section of one line type (no
attachments, bending negligible: its bending length sqrt(EI / (w L)) below
BENDING_LENGTH of L, a MoorDyn chain's or rope's), pinned at both ends (a clamp or a
flex joint has moments a catenary has none of), sinking (w > 0), on no seabed or a flat
one without friction (a slope, a profile or a grid, or friction: the rods' equilibrium
differs), in still water or a current: a catenary carries none of its line's drag (the
free points' drag is the system's, in the prediction too), so the prediction is the
pose without it and the rods' Newton under the full loads moves the system from there.
Anything else: ``refusal`` says why and the solver takes its usual path. A line whose
catenary has no solution (too short for its span, a lower end above the seabed whose
catenary would pass below it) fails its solve, and the prediction with it.
"""

from dataclasses import replace

import numpy as np

from petsc_rod.errors import RodError
from petsc_rod.model.line import Line

# The largest bending length sqrt(EI / (w L)) of a line a catenary stands in for, as a
# fraction of its length: the hang-off's bending boundary layer is shorter than a
# hundredth of the line (a chain's EI of the rule of docs/systems.md, "EI = 0", is
# orders of magnitude below it).
BENDING_LENGTH = 1e-2
# The smallest move of a line's end, as a fraction of its length, from the system's
# start to the catenaries' equilibrium for which the prediction is used: a smaller move
# is a few iterations of the lines' walks from their first solves at the start, less
# than the Newton steps that take the rods from the catenaries' pose to their own.
NEAR = 1e-3
# The halvings of the catenaries' load step: a system whose catenaries need more is
# solved from its start (their continuation's cost would be the prediction's only)
HALVINGS = 4
# Newton on (H, V): the relative residual of (l, h) that ends it, its iterations
NEWTON_RTOL, NEWTON_ITERATIONS = 1e-12, 100


def refusal(system):
    """Why no catenary stands in for some line of ``system`` (a str), or None when
    every line can be one (module docstring)."""
    environment = system.environment
    if not system.lines:
        return "no lines"
    if environment.seabed_profile is not None or environment.seabed_slope:
        return "a seabed that is not flat"
    if environment.seabed is not None and environment.seabed_friction is not None:
        return "seabed friction"
    for line in system.lines:
        why = _line_refusal(line, environment)
        if why:
            return f"line {line.name}: {why}"
    return None


def _line_refusal(line, environment):
    if line.attachments:
        return "attachments"
    if any(c.kind != "pin" for c in (line.start, line.end)):
        return "a clamped or flex-jointed end"
    model = line.line
    if not isinstance(model, Line) or len(model.sections) != 1:
        return "not one section of one line type"
    kind = model.sections[0][0]
    if kind.ei_end is not None:
        return "a tapered bending stiffness"
    w = kind.submerged_weight(environment.water_density, environment.gravity)
    if not w > 0:
        return "not sinking"
    ei = float(np.max(np.asarray(kind.ei, dtype=float)))
    if np.sqrt(ei / (w * model.length)) > BENDING_LENGTH * model.length:
        return "a bending stiffness that matters"
    return None


def catenary_span(H, V, w, L, EA, grounded):
    """((l, h), D = d(l, h)/d(H, V) (2, 2)) of the elastic catenary (module
    docstring); ``grounded``: resting on the seabed from its lower end (V < w L)."""
    compliance = L / EA
    r = V / H
    root = np.sqrt(1.0 + r * r)
    if grounded:
        l = L - V / w + H / w * np.arcsinh(r) + H * compliance
        h = H / w * (root - 1.0) + V * V / (2.0 * EA * w)
        D = np.array([[(np.arcsinh(r) - r / root) / w + compliance, (1.0 / root - 1.0) / w],
                      [(1.0 / root - 1.0) / w, r / root / w + V / (EA * w)]])
        return np.array([l, h]), D
    ra = (V - w * L) / H
    root_a = np.sqrt(1.0 + ra * ra)
    l = H / w * (np.arcsinh(r) - np.arcsinh(ra)) + H * compliance
    h = H / w * (root - root_a) + (V * L - 0.5 * w * L * L) / EA
    cross = (1.0 / root - 1.0 / root_a) / w
    D = np.array([[(np.arcsinh(r) - np.arcsinh(ra) - r / root + ra / root_a) / w
                   + compliance, cross],
                  [cross, (r / root - ra / root_a) / w + compliance]])
    return np.array([l, h]), D


def _solve2(D, b):
    """D^-1 b of a 2 x 2 D by its adjugate (non-finite where D is singular)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.array([[D[1, 1], -D[0, 1]], [-D[1, 0], D[0, 0]]]) @ b / (
            D[0, 0] * D[1, 1] - D[0, 1] * D[1, 0])


class CatenaryLine:
    """A system line as an elastic catenary (module docstring), with the HeldLine
    protocol of system/equilibrium.py: solve(start, end) -> bool, end_forces() (2, 3),
    stiffness() (6, 6), destroy(); ``seabed`` the flat seabed's height (m) or None."""

    def __init__(self, line, environment):
        model = line.line
        kind = model.sections[0][0]
        self.name = line.name
        self.L, self.EA = model.length, float(kind.ea)
        self.w = kind.submerged_weight(environment.water_density, environment.gravity)
        self.seabed = environment.seabed
        self.HV = None                      # the last solution, the next one's start
        self.forces = self.K = None

    def solve(self, start, end):
        """The catenary between ``start`` and ``end`` (3,), m, from the last one's (H, V);
        False where it has none: the ends on one vertical, the lower end below the
        seabed, Newton failing, a hanging line through the seabed."""
        start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
        flip = end[2] < start[2]
        a, b = (end, start) if flip else (start, end)
        chord = b - a
        l, h = float(np.hypot(chord[0], chord[1])), float(chord[2])
        if not l > 1e-9 * self.L:
            return False                    # on one vertical: no catenary's H
        grounded_ok = False
        if self.seabed is not None:
            if a[2] < self.seabed - 1e-6 * self.L:
                return False
            grounded_ok = abs(a[2] - self.seabed) <= 1e-6 * self.L
        found = self._solve(l, h, grounded_ok)
        if found is None:
            return False
        H, V, D, grounded = found
        if not grounded and self.seabed is not None and not self._clear(a[2], H, V):
            return False
        e = np.array([chord[0] / l, chord[1] / l, 0.0])
        z = np.array([0.0, 0.0, 1.0])
        Va = 0.0 if grounded else V - self.w * self.L
        f_b = -H * e - V * z
        f_a = H * e + Va * z
        # d(H, V)/d chord: (dl, dh) = (e . dc, dc_z)
        dHV = _solve2(D, np.vstack([e, z]))                     # (2, 3)
        turn = (np.diag([1.0, 1.0, 0.0]) - np.outer(e, e)) / l  # de_h / dc
        d_b = -np.outer(e, dHV[0]) - H * turn - np.outer(z, dHV[1])
        d_a = np.outer(e, dHV[0]) + H * turn + (0.0 if grounded else np.outer(z, dHV[1]))
        forces = np.array([f_a, f_b])
        dF = np.vstack([d_a, d_b])                              # (6, 3): d(F_a, F_b)/dc
        K = np.hstack([-dF, dF])                                # columns (x_a, x_b)
        if not np.all(np.isfinite(K)):
            return False
        if flip:                                                # the line's own order
            order = np.r_[3:6, 0:3]
            forces, K = forces[::-1], K[np.ix_(order, order)]
        self.forces, self.K = forces, K
        self.HV = (H, V)
        return True

    def _clear(self, height, H, V):
        """Whether the hanging catenary of (H, V) from a lower end at ``height`` (m)
        stays above the seabed."""
        Va = V - self.w * self.L
        if Va >= 0.0:
            return True                     # rising all along from a
        # its lowest point, where the vertical tension vanishes (inextensible sag)
        sag = H / self.w * (np.sqrt(1.0 + (Va / H) ** 2) - 1.0)
        return height - sag >= self.seabed - 1e-6 * self.L

    def _solve(self, l, h, grounded_ok):
        """(H, V, D, grounded) of the span (l, h), None where Newton fails."""
        w, L = self.w, self.L
        if self.HV is not None:
            H, V = self.HV
        else:
            chord = np.hypot(l, h)
            lam = (0.2 if L <= chord else
                   np.sqrt(max(3.0 * ((L * L - h * h) / (l * l) - 1.0), 1e-12)))
            H = max(abs(0.5 * w * l / lam), 1e-6 * w * L)
            V = 0.5 * w * (h / np.tanh(lam) + L)
        target, scale = np.array([l, h]), max(l, abs(h), 1e-9 * L)
        for _ in range(NEWTON_ITERATIONS):
            grounded = grounded_ok and V < w * L
            span, D = catenary_span(H, V, w, L, self.EA, grounded)
            miss = span - target
            norm = np.linalg.norm(miss)
            if norm <= NEWTON_RTOL * scale:
                return H, V, D, grounded
            dH, dV = -_solve2(D, miss)
            if not (np.isfinite(dH) and np.isfinite(dV)):
                return None
            alpha = 1.0
            while H + alpha * dH <= 0.0 or (grounded_ok and V + alpha * dV < 0.0):
                alpha *= 0.5                # H stays positive, a grounded V too
                if alpha < 1e-12:
                    return None
            for _ in range(40):
                H1, V1 = H + alpha * dH, V + alpha * dV
                g1 = grounded_ok and V1 < w * L
                trial = np.linalg.norm(catenary_span(H1, V1, w, L, self.EA, g1)[0] - target)
                if trial < norm or alpha < 1e-6:
                    break
                alpha *= 0.5
            H, V = H1, V1
        return None

    def end_forces(self):
        return self.forces.copy()

    def stiffness(self):
        return self.K.copy()

    def destroy(self):
        pass


def catenary_lines(system):
    """The ``make_line(system_line, comm)`` of SystemSolver for ``system``'s lines as
    catenaries (refusal must be None); comm unused (a catenary is a few numbers)."""
    def make_line(line, comm):
        return CatenaryLine(line, system.environment)

    return make_line


def predict(system, settings, solver_type, comm):
    """(State of the catenaries' equilibrium, None) of ``system`` under its loads
    (``settings``: the system's, with at most HALVINGS halvings), solved by
    ``solver_type`` (system/equilibrium.SystemSolver, handed in by the solver that asks:
    this module stands below it) with catenary_lines on ``comm``, the asking solver's
    communicator (PETSc.Comm): its placement deals the catenaries over the ranks as it
    deals the rods, each rank solves its share and the solver shares their forces and
    stiffnesses, so every rank ends with the same state. (None, why) where no catenary
    stands in for a line, the catenaries' system has no equilibrium, or no line's end
    moves by NEAR of its length from the system's start to it. Collective on ``comm``."""
    why = refusal(system)
    if why:
        return None, why
    solver = solver_type(system, catenary_lines(system), comm,
                         settings=replace(settings, predictor=False,
                                          max_halvings=min(settings.max_halvings, HALVINGS)))
    try:
        start = solver.end_positions(solver.state)
        solver.solve()
        moves = np.linalg.norm(solver.end_positions(solver.state) - start, axis=2).max(axis=1)
        lengths = np.array([line.line.length for line in system.lines])
        if not np.any(moves > NEAR * lengths):
            return None, (f"the catenaries' ends move {float(np.max(moves / lengths)):.2g} "
                          f"of their lengths, less than {NEAR:g}: solved from the start")
        return solver.state, None
    except RodError as error:
        return None, f"the catenaries' system: {error}"
    finally:
        solver.destroy()
