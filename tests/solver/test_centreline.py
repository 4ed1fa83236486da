"""The centreline solved through its slope r' (petsc_rod/global_step/centreline.py).

* One global step equals the paper's Hermite-cubic step for r (a dense numpy solve of
  int 2 a3 r''.p'' + R r'.p' = int (R tau3 - lambda3).p' + int f.p + end forces, with
  r and r' prescribed at held and clamped ends): the same discrete problem in other
  unknowns, so vertex positions and slopes, r, r', r'' at the Gauss points, the reaction
  at S = L and the energy agree to round-off, for every kind of end, a graded mesh and a
  piecewise load broken inside elements.
* The round-off of one centreline solve at N = 3200 (petsc_rod.validation.roundoff) stays below
  1e-10; the Hermite r solve gave 5.7e-5 there (scripts/linear_solve_roundoff.py).

Serial and under mpiexec -n 2 (fields gathered, the prefix sum crosses ranks).
"""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import gather
from petsc_rod.mesh.elements import GAUSS_POINTS, GAUSS_WEIGHTS
from petsc_rod.frames import rotation_about, rotations, split_coefficients, strains
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.validation.roundoff import MULTIPLIER, centreline_solve_error
from petsc_rod.scenes.scene import REFERENCE_FRAME, Scene
from petsc_rod.iteration.driver import solver_for
from petsc_rod.iteration.stopping import Settings

LENGTH = 1.3
STIFFNESS = (1.0, 1.5, 0.8)
PENALTY = 50.0
LOADS = dict(load_values=[[0.5, -1.0, 0.2], [0.0, 2.0, -1.0], [1.0, 0.0, 0.5]],
             load_breaks=[0.4, 0.9])
CASES = {
    "clamp-clamp": dict(start="clamp", end="clamp", end_position=(0.9, 0.2, 0.1),
                        end_frame=REFERENCE_FRAME @ rotation_about([0.2, 0.3, 1.0], 0.5).T),
    "clamp-pin": dict(start="clamp", end="pin", end_position=(0.8, 0.3, 0.0)),
    "clamp-free": dict(start="clamp", end="free", end_force=(0.0, -1.0, 0.5)),
    "pin-clamp": dict(start="pin", end="clamp", end_position=(0.8, 0.3, 0.0)),
    "pin-pin": dict(start="pin", end="pin", end_position=(0.7, 0.4, -0.2)),
    "free-clamp": dict(start="free", end="clamp", start_force=(0.0, -1.0, 0.5)),
    "free-pin": dict(start="free", end="pin", start_force=(0.3, 0.2, -0.4),
                     end_position=(1.0, 0.1, 0.3)),
}
ROUND_OFF = 1e-12
SIMPSON_POINTS = np.array([0.0, 0.5, 1.0])
SIMPSON_WEIGHTS = np.array([1.0, 4.0, 1.0]) / 6


def hermite(x, h):
    """Hermite cubic shape functions at reference points x (ne, nq) of elements of
    lengths h (ne,): values, d/dS and d2/dS2 of N1 = 1 - 3x^2 + 2x^3,
    N2 = h(x - 2x^2 + x^3), N3 = 3x^2 - 2x^3, N4 = h(x^3 - x^2); each (ne, nq, 4)."""
    h = h[:, None]
    one = np.ones_like(x)
    phi = np.stack([1 - 3 * x**2 + 2 * x**3, h * (x - 2 * x**2 + x**3),
                    3 * x**2 - 2 * x**3, h * (x**3 - x**2)], axis=-1)
    dphi = np.stack([(6 * x**2 - 6 * x) / h, 1 - 4 * x + 3 * x**2,
                     (6 * x - 6 * x**2) / h, 3 * x**2 - 2 * x], axis=-1)
    ddphi = np.stack([(12 * x - 6) / h**2, (6 * x - 4) / h * one,
                      (6 - 12 * x) / h**2, (6 * x - 2) / h * one], axis=-1)
    return phi, dphi, ddphi


def hermite_load(S, scene, t):
    """Exact int f.p dS of the piecewise-constant load for each element's Hermite
    functions, (ne, 4, 3): Gauss on the parts of each element between the breaks."""
    a, h = S[:-1, None], np.diff(S)[:, None]
    out = np.zeros((S.size - 1, 4, 3))
    ends = scene.load_piece_ends
    for lo, hi, f in zip(ends[:-1], ends[1:], t * scene.load_values):
        x0, x1 = np.clip((lo - a) / h, 0, 1), np.clip((hi - a) / h, 0, 1)
        phi = hermite(x0 + (x1 - x0) * GAUSS_POINTS, h[:, 0])[0]
        out += np.einsum("eq,eqk->ek", h * (x1 - x0) * GAUSS_WEIGHTS, phi)[:, :, None] * f
    return out


def hermite_step(S, scene, t, target):
    """The Hermite r step solved densely: vertex dofs (N + 1, 2, 3) (r, r'), the reaction
    at S = L ((A r - b) at the r(L) row; the dead force at a free end), the load work
    (load vector . dofs) and max |b|, the size of the terms the reaction cancels.
    ``target`` = R tau3 - lambda3 at the P2 nodes (2N + 1, 3): the penalty term and the
    right-hand side by Simpson's rule on each element (the nodal quadrature)."""
    n, h = S.size - 1, np.diff(S)
    _, _, ddphi = hermite(np.broadcast_to(GAUSS_POINTS, (n, 3)), h)
    w = h[:, None] * GAUSS_WEIGHTS
    _, dphi, _ = hermite(np.broadcast_to(SIMPSON_POINTS, (n, 3)), h)
    simpson = h[:, None] * SIMPSON_WEIGHTS
    bending = 2 * split_coefficients(scene.stiffness)[2]
    matrices = (bending * np.einsum("eq,eqk,eql->ekl", w, ddphi, ddphi)
                + PENALTY * np.einsum("eq,eqk,eql->ekl", simpson, dphi, dphi))
    target = np.stack([target[0:-1:2], target[1::2], target[2::2]], axis=1)   # (n, 3, 3)
    dofs = 2 * np.arange(n)[:, None] + np.arange(4)
    a = np.zeros((2 * n + 2, 2 * n + 2))
    np.add.at(a, (dofs[:, :, None], dofs[:, None, :]), matrices)
    load = np.zeros((2 * n + 2, 3))
    np.add.at(load, dofs, hermite_load(S, scene, t))
    start, end = scene.start_state(t), scene.end_state(t)
    fixed = {}
    for row, state in ((0, start), (2 * n, end)):
        if state.kind == "free":
            load[row] += state.force
        else:
            fixed[row] = state.position
        if state.kind == "clamp":
            fixed[row + 1] = state.frame[2]
    b = load.copy()
    np.add.at(b, dofs, np.einsum("eq,eqk,eqc->ekc", simpson, dphi, target))
    x = np.zeros_like(b)
    rows = np.array(list(fixed))
    x[rows] = np.array(list(fixed.values()))
    free = np.setdiff1d(np.arange(2 * n + 2), rows)
    x[free] = np.linalg.solve(a[np.ix_(free, free)], b[free] - a[np.ix_(free, rows)] @ x[rows])
    reaction = end.force if end.kind == "free" else (a @ x - b)[2 * n]
    return x.reshape(n + 1, 2, 3), reaction, float(np.sum(load * x)), np.abs(b).max()


@pytest.fixture(scope="module", params=list(CASES))
def one_step(request):
    """One global step of the solver from random frames tau (rotations, as the local
    step makes them, varying smoothly along the rod) and random lambda, the same on
    every rank, and the Hermite step from the same data."""
    comm = PETSc.COMM_WORLD
    scene = Scene(length=LENGTH, stiffness=STIFFNESS, **CASES[request.param], **LOADS)
    mesh = Mesh(comm, 6, LENGTH, grading=2.0)
    solver = solver_for(mesh, scene, Settings(asked_penalty=PENALTY))
    try:
        solver.problem.state.set_straight()
        solver.problem.prepare(1.0)
        rng = np.random.default_rng(7)
        # tau: a smooth random field of rotations, so that the interpolated frames
        # stay well conditioned (the strains resolve D' on D^-1)
        x = np.linspace(0.0, 1.0, 2 * mesh.n_elements + 1)[:, None]
        a, b, c = rng.standard_normal((3, 1, 3))
        tau = rotations(a + b * x + c * x**2)
        lam = rng.standard_normal((x.size, 3, 3))
        owned = slice(2 * mesh.vertex_start, 2 * mesh.vertex_start + mesh.n_local_nodes)
        solver.problem.state.tau[:], solver.problem.state.lam[:] = tau[owned], lam[owned]
        solver.problem.iterate()
        points = {key: gather(comm, value) for key, value in solver.problem.state.point_values().items()}
        result = dict(r=gather(comm, solver.problem.state.r.owned()), points=points,
                      reaction=solver.problem.end_reaction(), energy=solver.problem.energy())
        S = mesh.coordinates(np.arange(mesh.n_vertices))
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()
    result["hermite"] = hermite_step(S, scene, 1.0, PENALTY * tau[:, 2] - lam[:, 2])
    result["S"], result["scene"] = S, scene
    return result


def test_vertex_positions_and_slopes_are_the_hermite_ones(one_step):
    dofs = one_step["hermite"][0]
    assert np.abs(one_step["r"] - dofs).max() < ROUND_OFF * np.abs(dofs).max()
    assert np.abs(dofs[:, 0] - one_step["S"][:, None] * [1, 0, 0]).max() > 0.01


def test_gauss_point_values_are_the_hermite_ones(one_step):
    """r, r' and r'' at the Gauss points (evaluate: r from the exact integral of theta)."""
    S, points = one_step["S"], one_step["points"]
    dofs = one_step["hermite"][0]
    element = np.concatenate([dofs[:-1], dofs[1:]], axis=1)              # (N, 4, 3)
    basis = hermite(np.broadcast_to(GAUSS_POINTS, (S.size - 1, 3)), np.diff(S))
    for computed, phi in zip((points["r"], points["directors"][:, :, 2],
                              points["derivatives"][:, :, 2]), basis):
        expected = np.einsum("eqk,ekc->eqc", phi, element)
        assert np.abs(computed - expected).max() < ROUND_OFF * np.abs(expected).max()


def test_reaction_at_the_end_is_the_hermite_one(one_step):
    """The multiplier of int theta = r(L) - r(0) (both ends held), the force balance
    (free start) or the dead force (free end), against the Hermite FE reaction, a
    residual A r - b that cancels terms as large as the right-hand side b."""
    _, reaction, _, size = one_step["hermite"]
    assert np.abs(one_step["reaction"] - reaction).max() < ROUND_OFF * size
    assert np.abs(reaction).max() > 0.1


def test_energy_is_the_hermite_one(one_step):
    """W = int w dS - load work, with r', r'' of the Hermite solution and the solver's
    d1, d2: the load work r(a).F + int F.theta is the Hermite load vector . dofs."""
    S, points = one_step["S"], one_step["points"]
    dofs, _, work, _ = one_step["hermite"]
    element = np.concatenate([dofs[:-1], dofs[1:]], axis=1)
    _, dphi, ddphi = hermite(np.broadcast_to(GAUSS_POINTS, (S.size - 1, 3)), np.diff(S))
    directors, derivatives = points["directors"].copy(), points["derivatives"].copy()
    directors[:, :, 2] = np.einsum("eqk,ekc->eqc", dphi, element)
    derivatives[:, :, 2] = np.einsum("eqk,ekc->eqc", ddphi, element)
    u = strains(directors, derivatives)
    w = np.diff(S)[:, None] * GAUSS_WEIGHTS
    stored = 0.5 * np.sum(w[:, :, None] * one_step["scene"].stiffness * u**2)
    bound = ROUND_OFF * max(stored, abs(work))
    assert abs(one_step["energy"] - (stored - work)) < bound


@pytest.mark.parametrize("scene", [
    dict(length=1.0, stiffness=[1.0, 1.0, 1.0], start="clamp", end="free",
         end_force=[0.0, -3.0, 0.0]),
    dict(length=20.0, stiffness=[235.0, 360.0, 200.0], start="clamp", end="pin",
         end_position=[16.0, 4.0, 0.0])], ids=["cantilever", "paper"])
def test_centreline_solve_round_off_at_3200_elements(comm, scene):
    """One factorisation of the slope matrix (N = 3200, R = 400), a right-hand side
    whose exact solution is a known cubic centreline: measured 1.4e-12 for both scenes
    (the Hermite r solve: 5.7e-5 and 6.8e-7). The paper scene is bordered: the
    multiplier put into the right-hand side comes back (measured to 4.3e-10: it is the
    small difference c.theta0 - (r(L) - r(0)) of terms of size 16 m, over c.w)."""
    scene = Scene(**scene)
    mesh = Mesh(comm, 3200, scene.length)
    solver = solver_for(mesh, scene, Settings(asked_penalty=400.0))
    try:
        assert centreline_solve_error(solver.problem) < 1e-10
        if solver.problem.global_step.bordered:
            assert np.abs(solver.problem.end_reaction() + MULTIPLIER).max() < 1e-8
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()
