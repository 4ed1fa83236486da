"""Round-off of one centreline solve (slope matrix, bordering, integration), measured.

A known smooth centreline whose slope is one quadratic over the whole rod,
slope*(S) = A N0(s) + M N1(s) + B N2(s) (s = S/L, N_k the P2 shape functions on
[0, 1]), lies exactly in the P2 space of every mesh, and r*(S) = r(a) + int_a^S slope*
is a cubic known in closed form: the recovered r has no discretisation error, only
round-off. slope* takes the prescribed slope at a clamped end, and when both ends are
held M makes int_0^L slope* dS the prescribed chord. Used by
scripts/linear_solve_roundoff.py and tests/solver/test_centreline.py.
"""

import numpy as np

from petsc_rod.scenes.boundary import is_held
from petsc_rod.mesh.elements import P2, element_integrals, p2_basis, p2_integrals
from petsc_rod.mesh.fields import scatter_element_vectors

# Slopes at S = 0, S = L and at the middle where no condition fixes them.
FREE_SLOPES = np.array([[1.0, 0.3, -0.2], [0.5, -0.4, 0.6], [0.2, 0.9, 0.3]])
# The multiplier of the integral constraint put into the right-hand side (both ends held).
MULTIPLIER = np.array([0.3, -0.2, 0.1])


def quadratic_slope(length, start, end):
    """Nodal values (A, M, B), (3, 3), of slope* at s = 0, 1/2, 1 for the end states.

    A (B) is d3 of a clamped start (end); both ends held: int slope* = L (A + 4M + B)/6
    = r(L) - r(0) gives M.
    """
    a, b, m = FREE_SLOPES
    a = start.frame[2] if start.kind == "clamp" else a
    b = end.frame[2] if end.kind == "clamp" else b
    if is_held(start) and is_held(end):
        m = (6.0 * (end.position - start.position) / length - a - b) / 4.0
    return np.stack([a, m, b])


def exact_centreline(length, nodal, start, end, S):
    """r*(S) = r(a) + int_a^S slope* dS from the held end a, (n, 3)."""
    def primitive(S):
        return p2_integrals(np.asarray(S)[None, :] / length, np.array([length]))[0] @ nodal
    if is_held(start):
        return start.position + primitive(S) - primitive(np.zeros(1))
    return end.position + primitive(S) - primitive(np.array([length]))


def centreline_solve_error(problem, t=1.0):
    """max |r - r*| / max |r*| over the vertices after one centreline solve whose exact
    discrete solution is slope* (and mu = MULTIPLIER when both ends are held).

    The right-hand side is A slope* (+ mu int g), with A the full slope matrix; the
    solve is the run's (GlobalStep.solve_centreline). Overwrites the problem's state.
    """
    mesh = problem.mesh
    problem.prepare(t)
    start, end = problem.start_state, problem.end_state
    nodal = quadratic_slope(mesh.length, start, end)
    owned = np.arange(mesh.vertex_start, mesh.vertex_end)
    S = mesh.coordinates(owned)
    slots = np.stack([S, (S + mesh.coordinates(owned + 1)) / 2], axis=1)
    # slope* at the vertices and midpoints: one P2 element spanning [0, L], at s = S/L
    slope = p2_basis(slots.ravel() / mesh.length, np.ones(1))[0][0] @ nodal
    slope = slope.reshape(-1, 2, 3)
    slope[mesh.n_local_elements:, 1] = 0.0                   # the phantom slot
    problem.state.slope.set_owned(slope)
    bordered = MULTIPLIER if problem.global_step.bordered else np.zeros(3)
    contributions = element_integrals(mesh.element_h)[:, :, None] * bordered
    problem.global_step.rhs[2].add_ghosted(scatter_element_vectors(
        mesh.ghost_end - mesh.ghost_start, mesh.element_local, P2, contributions))
    full = problem.global_step.unconstrained_slope_matrix()
    for x, b in zip(problem.state.slope.components, problem.global_step.rhs[2].components):
        full.multAdd(x, b, b)
    full.destroy()
    problem.global_step.solve_centreline(problem.state)
    exact = exact_centreline(mesh.length, nodal, start, end, S)
    error = mesh.global_max(float(np.abs(problem.state.r.owned()[:, 0] - exact).max(initial=0.0)))
    return error / mesh.global_max(float(np.abs(exact).max(initial=0.0)))
