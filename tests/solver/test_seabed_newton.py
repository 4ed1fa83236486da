"""Newton steps and the stability test with a seabed (docs/method.md §11, "Terms of the
heights"; analysis/positions.py), on one rank (PETSc.COMM_SELF) and on all ranks
(PETSc.COMM_WORLD: under ``mpiexec -n 2`` the parallel run).

The seabed's energy k/2 sum_n w_n (z_b - z_n)_+^2 reads the node heights, integrals of
the frames; the Newton system carries the vertex heights and the multipliers of their
chain, so that its matrix stays banded:

(a) the gradient against central differences of the Lagrangian, and the reduced
    Hessian's quadratic form [v; u(v); 0]^T K [v; u(v); 0] (u(v) the heights' first
    variation, from central differences of the centreline) against second differences,
    at a state away from any solution with part of the line below the seabed, for pins
    (the chord), a clamp and a free end, a free start and a clamped end, each
    inextensible and extensible;
(b) the KKT matrix's inertia, less the chain's multipliers, is that of the reduced
    Hessian: against the eigenvalues of Z^T K Z (Z a basis of the chain's null space), on
    one rank;
(c) the grounded line of test_riser with Newton steps: fewer iterations, the same state
    to the tolerance, the same errors against the closed form, and stable;
(d) a steel riser (options/riser_catenary.opts without its current) whose touchdown's
    active set settles during the steps: the attempt converges, the iteration's state;
(e) the same riser's first global step starts its active-set loop from the catenary's
    touchdown, not from an empty set;
(f) the same riser's step ends at its Newton attempt, with Newton's state: the same at
    R and 4 R, where the Uzawa map's fixed point depends on R by its round-off.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import gather
from petsc_rod.environment.seabed import Seabed
from petsc_rod.frames import rotations
from petsc_rod.iteration.newton import NewtonSolver
from petsc_rod.physics.seabed import SeabedTerm
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene
from test_riser import GROUNDED, grounded_errors
from test_stretch_newton import lagrangian as chord_lagrangian

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}


@pytest.fixture(scope="module", params=list(COMMS))
def comm(request):
    return COMMS[request.param]


# Bending comparable to the loads, a seabed spring of 50 N/m^2 (its curvature k w ~ 2 N/m
# on 12 elements: as large as the bending's), EA 10 N where extensible.
FD_SCENE = dict(length=1.0, stiffness=(1e-2, 2e-2, 1.5e-2), load_values=[[0.0, 0.3, -1.0]])
FD_ENDS = {"pins": dict(start="pin", end="pin", end_position=(0.8, 0.0, 0.1)),
           "clamp and free": dict(start="clamp", end="free"),
           "free and clamp": dict(start="free", end="clamp")}
SEABED_STIFFNESS = 50.0


def lagrangian(problem, frames, mu, work):
    """F + mu.c (test_stretch_newton.lagrangian) with the centreline integrated from the
    frames, whose heights the seabed reads."""
    problem.state.set_node_directors(frames)
    problem.global_step.integrate_slope(problem.state)
    return chord_lagrangian(problem, frames, mu, work)


def moved(polish, frames, step):
    """Frames turned (and on an extensible line stretched) by ``step`` (n, 3 or 4)."""
    if polish.stretch:
        return polish._stretched(frames, step)
    return np.einsum("nkl,nil->nik", rotations(step), frames)


def random_direction(polish, seed):
    """A variation of the nodes' unknowns (n_nodes, 3 or 4), the same on any number of
    ranks (node i's row from the generator seeded ``seed`` + i), 0 where held."""
    problem = polish.problem
    mesh = problem.mesh
    nodes = 2 * mesh.vertex_start + np.arange(mesh.n_local_nodes)
    unknowns = 4 if polish.stretch else 3
    v = np.array([np.random.default_rng(seed + i).standard_normal(4)
                  for i in nodes])[:, :unknowns]
    v[~problem.free_nodes] = 0.0
    if polish.stretch:
        v[polish._held_stretch, 3] = 0.0
    return v


def heights(problem, frames):
    problem.state.set_node_directors(frames)
    problem.global_step.integrate_slope(problem.state)
    return problem.state.node_positions()[:, 2].copy()


def seabed_between_nodes(comm, problem, frames):
    """A seabed height inside the widest gap between the node heights of the middle half
    (no node within a tenth of the gap of it: the central differences below stay on
    one side of the kink of (z_b - z)_+), set on the problem's seabed term."""
    z = np.sort(gather(comm, heights(problem, frames)))
    middle = z[len(z) // 4: 3 * len(z) // 4 + 1]
    gap = np.argmax(np.diff(middle))
    height = 0.5 * (middle[gap] + middle[gap + 1])
    for term in problem.terms:
        if isinstance(term, SeabedTerm):
            term.seabed = Seabed(height, SEABED_STIFFNESS)
    return height, np.diff(middle)[gap]


@pytest.mark.parametrize("extensible", [False, True], ids=["inextensible", "EA"])
@pytest.mark.parametrize("ends", list(FD_ENDS))
def test_gradient_and_hessian_against_finite_differences(comm, solver_factory, ends,
                                                         extensible):
    scene = {**FD_SCENE, **FD_ENDS[ends], "seabed": Seabed(0.0, SEABED_STIFFNESS),
             **({"axial_stiffness": 10.0} if extensible else {})}
    mesh, solver = solver_factory(comm, 12, scene, 5.0, newton=False)
    problem = solver.problem
    polish = NewtonSolver(problem)
    work = problem.field_stiffness(0)[1].createVecLeft()
    try:
        problem.prepare(1.0)
        problem.state.set_straight()
        n = mesh.n_local_nodes
        U = 4 if extensible else 3
        nodes = 2 * mesh.vertex_start + np.arange(n)
        random = np.array([np.random.default_rng(2000 + i).standard_normal(12)
                           for i in nodes]).reshape(n, 3, 4)[:, :, :U]
        held = np.zeros((n, U), dtype=bool)
        held[~problem.free_nodes] = True
        if extensible:
            held[polish._held_stretch, 3] = True
            random[:, :, 3] *= 0.25
        start = 0.4 * random[:, 0]
        start[held] = 0.0
        frames = moved(polish, problem.state.tau.copy(), start)
        height, gap = seabed_between_nodes(comm, problem, frames)
        below = mesh.global_sum(int(np.sum(heights(problem, frames) < height)))
        assert 3 <= below <= mesh.global_sum(n) - 3      # the contact matters
        mu = np.array([0.3, -0.2, 0.5])
        gradient = polish.lagrangian_gradient(frames, mu)
        hessian = problem.second_variation()
        assert hessian.positions == (2,) and hessian.block == U + 1
        v = random[:, 1].copy()
        v[held] = 0.0
        # [v; u(v); 0]: u the vertex heights' first variation (0 at the held end)
        t = 1e-6
        u = (heights(problem, moved(polish, frames, t * v))
             - heights(problem, moved(polish, frames, -t * v))) / (2 * t)
        # no node crosses the seabed along +-s v (a fifth of the way to it)
        s = min(1e-4, 0.1 * gap / mesh.global_max(float(np.abs(u).max())))
        values = [lagrangian(problem, moved(polish, frames, h * v), mu, work)
                  for h in (s, 0.0, -s)]
        slope = mesh.global_sum(np.sum(gradient * v))
        gradient_error = abs((values[0] - values[2]) / (2 * s) - slope) / abs(slope)
        x = hessian.to_vec(v)
        x.getArray().reshape(n, U + 1)[0::2, U] = u[0::2]
        y = x.duplicate()
        hessian.matrix.mult(x, y)
        quadratic = x.dot(y)
        second = (values[0] - 2 * values[1] + values[2]) / s**2
        hessian_error = abs(second - quadratic) / abs(quadratic)
        x.destroy()
        y.destroy()
        # observed on 1 and 2 ranks: gradient 1.1e-8 .. 1.7e-8 (O(s^2)), Hessian 1e-10 ..
        # 1e-8 (round-off of a second difference, eps |F| / s^2)
        assert gradient_error < 1e-6
        assert hessian_error < 1e-6
    finally:
        work.destroy()
        polish.destroy()


# --- (b) the inertia of the KKT matrix -----------------------------------------------------
def test_inertia_counts_the_reduced_hessian(solver_factory):
    """A line partly on the seabed, 30 iterations from the straight start (H indefinite
    there) and converged (positive definite): the negative pivots less the chain's
    multipliers (SecondVariation.negative_pivots) against the negative eigenvalues of
    Z^T (K_pp - shift M) Z at the test's shift, K_pp the matrix on the primal unknowns
    (x, u) and Z a basis of the null space of the chain's rows (the chord's forms with
    them)."""
    scene = dict(length=10.0, stiffness=(1e-1, 1e-1, 1e-1), start="pin", end="pin",
                 end_position=(7.0, 0.0, 4.0), load_values=[[0.0, 0.0, -1.0]],
                 seabed=Seabed(0.0, 1e3))
    mesh, solver = solver_factory(PETSc.COMM_SELF, 20, scene, 50.0, newton=False)
    problem = solver.problem
    problem.prepare(1.0)
    problem.state.set_straight()
    counts = []
    for iterations in (30, 2000):
        for _ in range(iterations - (30 if counts else 0)):
            problem.iterate()
        hessian = problem.second_variation()
        K = hessian.matrix.convert("dense").getDenseArray().copy()
        rows = np.arange(K.shape[0]).reshape(-1, hessian.block)
        nu = rows[1::2, hessian.unknowns]
        primal = np.setdiff1d(rows.ravel(), nu)
        chord = np.array([c.getArray()[primal] for c in hessian.constraint])
        constraints = np.vstack([K[np.ix_(nu, primal)], chord])
        _, singular, vh = np.linalg.svd(constraints)
        Z = vh[len(singular):].T
        # the inertia of Z^T (K - shift M) Z, M the mass (0 on u), at the test's shift
        # -tolerance (a free roll between pins is an eigenvalue 0)
        shift = -hessian.tolerance()
        mass = hessian.mass.getArray()[primal]
        reduced = np.linalg.eigvalsh(Z.T @ (K[np.ix_(primal, primal)] - shift * np.diag(mass))
                                     @ Z)
        assert np.abs(reduced).min() > 1e-12 * np.abs(reduced).max()      # decidable
        counts.append((hessian.negative_directions(shift), int(np.sum(reduced < 0))))
    assert counts[0][0] == counts[0][1] > 0          # an iterate: indefinite
    assert counts[1] == (0, 0)                       # the equilibrium: a minimiser


# --- (c) Newton steps on the grounded line ------------------------------------------------
def test_newton_on_the_grounded_line(comm, solver_factory):
    """The grounded line of test_riser (10 m, 5.5 m of it on the seabed) at 80 elements
    from its catenary with and without Newton steps: the same errors against the closed
    form to the iteration's tolerance, stable, in fewer iterations (measured: 19 with 3
    Newton steps against 60; r error 8.3805e-5 m both, differing by 6e-13)."""
    runs = {newton: grounded_errors(comm, solver_factory, 80, newton=newton, start="catenary")
            for newton in (False, True)}
    plain, polished = runs[False], runs[True]
    assert polished["report"].converged and polished["report"].stable
    assert polished["report"].newton_steps > 0
    assert polished["report"].iterations < 0.5 * plain["report"].iterations
    assert abs(polished["r"] - plain["r"]) < 1e-10
    assert abs(polished["n"] - plain["n"]) < 1e-9


# --- (d) a steel riser whose touchdown settles during the Newton steps --------------------
# options/riser_catenary.opts without its current: a 12-inch steel riser, 1800 m from an
# anchor to a pin 1157 m away and 1000 m up, about 560 m of it on the seabed.
STEEL_RISER = dict(length=1800.0, stiffness=(5.6e7, 5.6e7, 4.3e7), start="pin", end="pin",
                   end_position=(1157.0, 0.0, 1000.0), load_values=[[0.0, 0.0, -1200.0]],
                   seabed=Seabed(0.0, 1.2e6))


def steel_riser(solver_factory, comm, newton):
    """(report, gathered vertex positions) of STEEL_RISER at 900 elements from its
    catenary, at the command line's default penalty (the start's tension) and
    tolerance, its first active-set loop from an empty set (as before (e)): the
    touchdown then settles during the Newton steps."""
    from petsc_rod.scenes.starts import catenary_start, largest_tension
    scene = Scene(**STEEL_RISER)
    penalty = default_penalty(scene, largest_tension(scene, 1.0))
    mesh, solver = solver_factory(comm, 900, STEEL_RISER, penalty, rtol=1e-9, ctol=1e-9,
                                  max_it=2000, newton=newton)
    solver.problem.state.set_from_curve(catenary_start(scene, 1.0))
    empty_contact(solver.problem)
    report = solver.solve_step(1.0)
    return report, gather(comm, solver.problem.state.r.owned())


def seabed_contact(problem):
    """The seabed term's SeabedContact (global_step/seabed_contact.py)."""
    return next(term for term in problem.terms if isinstance(term, SeabedTerm)).contact


def empty_contact(problem):
    """The first active-set loop from an empty set, not from the start's contact."""
    contact = seabed_contact(problem)
    contact._set_active(np.zeros(contact.weights.shape, dtype=bool))


def test_the_newton_attempt_converges_while_the_touchdown_settles(comm, solver_factory,
                                                                  monkeypatch):
    """The steel riser's one Newton attempt converges and the step ends in about 20
    iterations (measured: 22, 6 of them Newton steps), where before it failed at its
    second step and the iteration took 84: after a first turn of 0.016 rad H is
    indefinite (the step is taken again with the iteration's curvature), and the steps
    turn by 5.4e-4, then 5.0e-4 rad (the touchdown's active set settling: a step that
    does not shrink is taken where |grad L| halved), then 1.3e-4, 6.2e-10 and 1.6e-14.
    The state is the iteration's without Newton steps, to its tolerance."""
    from petsc_rod.iteration.events import NewtonAttempt
    from petsc_rod.iteration.newton import SHRINK
    curvatures = []                 # whether each step took the iteration's curvature
    step = NewtonSolver._newton_step

    def recorded(self, frames, g, mu, regularised=False, curvature=None, frozen=False):
        curvatures.append(curvature is not None)
        return step(self, frames, g, mu, regularised, curvature, frozen)

    monkeypatch.setattr(NewtonSolver, "_newton_step", recorded)
    (plain, r_plain), (polished, r) = (steel_riser(solver_factory, comm, newton)
                                       for newton in (False, True))
    assert plain.converged and polished.converged
    attempts = [event.outcome for event in polished.events if isinstance(event, NewtonAttempt)]
    assert attempts == ["converged"]
    assert polished.iterations <= 30 < plain.iterations
    assert sum(curvatures) >= 2                    # the first step and a retaken one
    turns = [row[0] for row in polished.history if row[1] == 0.0]      # Newton's rows
    assert any(b > SHRINK * a for a, b in zip(turns, turns[1:]))       # a settling step
    assert np.abs(r - r_plain).max() < 1e-6          # m, on 1800 m


# --- (e) the first active set: the start's touchdown --------------------------------------
def first_loop_solves(solver_factory, comm, from_start):
    """(solves, nodes that changed side) of the first global step's active-set loop
    (global_step/seabed_contact.py) on STEEL_RISER at 900 elements from its catenary;
    ``from_start``: the loop starts from the start's contact (the default), else from an
    empty set."""
    from petsc_rod.global_step.seabed_contact import TOUCHING
    from petsc_rod.scenes.starts import catenary_start, largest_tension
    scene = Scene(**STEEL_RISER)
    penalty = default_penalty(scene, largest_tension(scene, 1.0))
    mesh, solver = solver_factory(comm, 900, STEEL_RISER, penalty)
    problem = solver.problem
    problem.state.set_from_curve(catenary_start(scene, 1.0))
    problem.prepare(1.0)
    contact = seabed_contact(problem)
    start = contact._heights_of(problem.state.r.ghosted()[..., 2]) < contact.base + TOUCHING
    if not from_start:
        empty_contact(problem)
    problem.iterate()
    moved = mesh.global_sum(int(np.sum(contact.active != start)))
    return mesh.global_sum(contact.solves) // comm.getSize(), moved


def test_the_first_active_set_is_the_start_s_touchdown(comm, solver_factory):
    """From the catenary start the first global step's loop takes a few solves
    (measured: 2, with 3 nodes changing side), where from an empty set the line fell
    through the seabed and each solve lifted about 6 nodes beside the touchdown: the loop
    stopped at MAX_SOLVES (30) with the set still changing. The catenary lays its grounded
    part on z_b to round-off: most of the line is in contact from the first solve."""
    from petsc_rod.global_step.seabed_contact import MAX_SOLVES
    solves, moved = first_loop_solves(solver_factory, comm, from_start=True)
    assert solves <= 4 and moved <= 20
    empty_solves, _ = first_loop_solves(solver_factory, comm, from_start=False)
    assert empty_solves == MAX_SOLVES


# --- (f) the step ends at the attempt, with Newton's state -------------------------------
def newton_solution(solver_factory, comm, factor):
    """(report, gathered vertex positions, gathered internal force n, N) of STEEL_RISER
    at 900 elements from its catenary at ``factor`` times the default penalty."""
    from petsc_rod.scenes.starts import catenary_start, largest_tension
    scene = Scene(**STEEL_RISER)
    penalty = factor * default_penalty(scene, largest_tension(scene, 1.0))
    mesh, solver = solver_factory(comm, 900, STEEL_RISER, penalty, rtol=1e-9, ctol=1e-9,
                                  max_it=2000)
    solver.problem.state.set_from_curve(catenary_start(scene, 1.0))
    report = solver.solve_step(1.0)
    return (report, gather(comm, solver.problem.state.r.owned()[:, 0]),
            gather(comm, solver.problem.internal_force()))


def test_the_step_ends_at_the_attempt_with_newton_s_state(comm, solver_factory):
    """The attempt converges on the whole problem and its last step passes the stopping
    tests (docs/method.md §11, "Convergence in Newton's terms"): the step ends there,
    and its state does not depend on R (measured: 2e-12 m and 8e-9 N between R and 4 R).
    Iterating on from the hand-over, as before, ended at the map's fixed point, which
    does: 4e-9 m and 6e-5 N apart (3e-6 m and 1e-2 N for the map alone at its
    tolerance). The internal force reads the attempt's chord multiplier."""
    from petsc_rod.iteration.events import NewtonAttempt
    runs = [newton_solution(solver_factory, comm, factor) for factor in (1.0, 4.0)]
    for report, _, _ in runs:
        attempts = [event for event in report.events if isinstance(event, NewtonAttempt)]
        assert report.converged and attempts[-1].outcome == "converged"
        assert attempts[-1].iteration == report.iterations      # no iteration after it
        assert report.change <= 1e-9 and report.constraint_residual <= 1e-9
    (_, r, n), (_, r_4, n_4) = runs
    assert np.abs(r - r_4).max() < 1e-10                        # m, on 1800 m
    assert np.abs(n - n_4).max() < 1e-6                         # N, of 1.5e6
