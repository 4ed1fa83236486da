"""Newton steps with a current (docs/method.md §11, "A load without potential";
analysis/jacobian.py), on one rank (PETSc.COMM_SELF) and on all ranks
(PETSc.COMM_WORLD: under ``mpiexec -n 2`` the parallel run).

The drag has no energy: the Newton steps solve with the Jacobian J of the gradient,
H plus the drag's linearisation through the resultants' chain, factored by LU.

(a) J [v; u(v); Psi(v)] against central differences of the gradient along v at a
    converged state (where H's symmetrised curvature term is the exact one), u the
    heights' and Psi the resultants' first variations (central differences of the
    centreline and of the drag's resultant beyond each vertex): the frames' rows equal
    the derivative, the resultants' rows vanish; J assembled again at the same state
    (a copy of H on H's pattern, which holds the drag's places) is the same matrix. A
    catenary in a current across its plane between pins, inextensible and extensible,
    and a hanging line (free start, clamped end) in a current (the seabed's part of J,
    through the heights' chain, is test_seabed_newton's);
(b) Newton steps on the catenary reach the iteration's state in fewer iterations;
(c) the LDL^T of H leaves the resultants' identity rows out (SecondVariation's kept
    rows): its inertia and its solves are those of the whole H, factored apart;
(d) near the solution the steps reuse the last factorisation (chord steps,
    newton.FREEZE_TURN), and reach the state of exact steps; a chord step solves one
    right-hand side, and the attempt ends at the first whose rest (the error its
    contraction leaves) is below newton.STEP_TOLERANCE.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.environment.current import Current
from petsc_rod.global_step.chain_factor import stored_entries
from petsc_rod.global_step.ksp import inertia_solver
from petsc_rod.iteration.newton import NewtonSolver
from petsc_rod.physics.drag import DragTerm
from petsc_rod.scenes.starts import catenary_start
from test_seabed_newton import heights, moved, random_direction

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}


@pytest.fixture(scope="module", params=list(COMMS))
def comm(request):
    return COMMS[request.param]


# 10 m of line, 1 N/m, EI 0.1 N m^2, in a current of 1 m/s across its plane whose drag
# (rho Cd D / 2 = 0.3 kg/m^2: 0.3 N/m) is a third of the weight
CURRENT = Current.uniform((0.0, 1.0, 0.0), 1000.0, 1.2, 5e-4)
LINES = {
    "catenary": dict(length=10.0, stiffness=(1e-1, 1e-1, 1e-1), start="pin", end="pin",
                     end_position=(7.0, 0.0, 4.0), load_values=[[0.0, 0.0, -1.0]],
                     current=CURRENT),
    "catenary, EA": dict(length=10.0, stiffness=(1e-1, 1e-1, 1e-1), start="pin", end="pin",
                         end_position=(7.0, 0.0, 4.0), load_values=[[0.0, 0.0, -1.0]],
                         current=CURRENT, axial_stiffness=50.0),
    "hanging": dict(length=10.0, stiffness=(1.0, 1.0, 1.0), start="free", end="clamp",
                    end_position=(0.0, 0.0, 10.0),
                    end_frame=((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
                    load_values=[[0.0, 0.0, -1.0]], current=CURRENT),
}
def converged(solver_factory, comm, scene, newton, n_elements=40):
    mesh, solver = solver_factory(comm, n_elements, scene, 200.0, rtol=1e-12, ctol=1e-12,
                                  max_it=20000, newton=newton)
    problem = solver.problem
    if problem.bordered:
        start = dict(scene, current=None)
        problem.state.set_from_curve(catenary_start(type(problem.scene)(**start), 1.0))
    else:
        problem.state.set_straight()
    return mesh, solver, solver.solve_step(1.0)


@pytest.mark.parametrize("line", list(LINES))
def test_jacobian_against_finite_differences(comm, solver_factory, line):
    mesh, solver, report = converged(solver_factory, comm, LINES[line], newton=True,
                                     n_elements=20)
    assert report.converged
    problem = solver.problem
    polish = NewtonSolver(problem)
    try:
        state = problem.state
        frames, mu = state.tau.copy(), state.chord_multiplier.copy()
        gradient = polish.lagrangian_gradient(frames, mu)
        hessian = problem.second_variation()
        jacobian = polish._jacobian_of(hessian)
        # J again at the same state: a copy of H's values on H's pattern (which holds
        # the drag's places from its first assembly), the same matrix exactly
        assert stored_entries(jacobian.matrix, "nz_used") == \
            stored_entries(hessian.matrix, "nz_used")
        first = jacobian.matrix.duplicate(copy=True)
        jacobian = polish._jacobian_of(hessian)
        first.axpy(-1.0, jacobian.matrix, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        assert first.norm(PETSc.NormType.INFINITY) == 0.0
        first.destroy()
        n, B, U = mesh.n_local_nodes, hessian.block, hessian.unknowns
        drag = next(term for term in problem.terms if isinstance(term, DragTerm))
        v = random_direction(polish, 3000)
        s = 1e-6

        def evaluate(h):
            """(grad L, heights, the drag's resultant beyond the vertices) at frames + h v."""
            at = moved(polish, frames, h * v)
            g = polish.lagrangian_gradient(at, mu)
            z = heights(problem, at)
            drag.drag.set(drag.node_loads(state, state.node_directors()[:, 2].copy()))
            return g, z, drag.force_beyond(state)

        (g_plus, z_plus, f_plus), (g_minus, z_minus, f_minus) = evaluate(s), evaluate(-s)
        derivative = (g_plus - g_minus) / (2 * s)
        x = hessian.to_vec(v)
        rows = x.getArray().reshape(n, B)
        if hessian.positions:
            rows[0::2, U] = ((z_plus - z_minus) / (2 * s))[0::2]
        rows[0::2, hessian.resultant_slot:] = (f_plus - f_minus) / (2 * s)
        y = x.duplicate()
        jacobian.matrix.mult(x, y)
        product = y.getArray(readonly=True).reshape(n, B)
        scale = mesh.global_max(float(np.abs(derivative).max()))
        frames_error = mesh.global_max(float(np.abs(product[:, :U] - derivative).max()))
        resultant_scale = mesh.global_max(float(np.abs(rows[:, hessian.resultant_slot:]).max()))
        chain_error = mesh.global_max(float(np.abs(product[:, hessian.resultant_slot:]).max()))
        x.destroy()
        y.destroy()
        del gradient
        # observed: frames' rows 6e-11 .. 1e-9 of the largest, the chain 1e-9 of Psi
        # (central differences at s = 1e-6: O(s^2) and round-off eps |g| / s)
        assert frames_error < 1e-7 * scale
        assert chain_error < 1e-7 * resultant_scale
    finally:
        polish.destroy()


# --- (b) Newton steps in a current -----------------------------------------------------------
def test_h_is_stored_in_its_own_pattern(comm, solver_factory):
    """H (with the heights' chain, the resultants and the drag's places in J) holds no
    storage beyond the entries its first assembly made: its preallocation (every unknown
    of a node's 5 nodes, each row) is only a bound, about 2.7 times the entries on the
    18 000-element riser, and PETSc keeps the rest allocated; J is made from it. The
    entries stay those of the pattern at the next assembly."""
    mesh, solver, report = converged(solver_factory, comm, LINES["catenary"], newton=True,
                                     n_elements=20)
    problem = solver.problem
    hessian = problem.second_variation()
    used = stored_entries(hessian.matrix, "nz_used")
    assert used > 0
    assert stored_entries(hessian.matrix, "nz_allocated") == used
    hessian.update()
    assert stored_entries(hessian.matrix, "nz_allocated") == used
    assert stored_entries(hessian.matrix, "nz_used") == used


def test_the_attempt_runs_without_andersons_history(comm, solver_factory, monkeypatch):
    """Anderson's history (2 m vectors of the node state, 311 MB on the 18 000-element
    riser at m = 30) is freed before each Newton attempt, which does not read it (the
    next solve of the map starts its own), so the attempt's factorisations take its
    memory; the run still converges by Newton steps."""
    mesh, solver = solver_factory(comm, 20, LINES["catenary"], 200.0, rtol=1e-12,
                                  ctol=1e-12, max_it=20000, newton=True)
    problem = solver.problem
    problem.state.set_from_curve(catenary_start(
        type(problem.scene)(**dict(LINES["catenary"], current=None)), 1.0))
    events = []
    release, attempt = solver.release_work, solver.newton.run
    monkeypatch.setattr(solver, "release_work",
                        lambda: (events.append("release"), release())[1])
    monkeypatch.setattr(solver.newton, "run",
                        lambda *args: (events.append("attempt"), attempt(*args))[1])
    report = solver.solve_step(1.0)
    assert report.converged and report.newton_steps > 0
    attempts = [i for i, event in enumerate(events) if event == "attempt"]
    assert attempts
    assert all(i > 0 and events[i - 1] == "release" for i in attempts)


def test_newton_in_a_current_reaches_the_iterations_state(comm, solver_factory):
    """The catenary of (a) in the current across its plane, at 20 elements from its
    catenary, with and without Newton steps: the same state to the tolerance, in a
    fraction of the iterations (measured at 40 elements: 111 with 5 Newton steps
    against 1342)."""
    runs = {newton: converged(solver_factory, comm, LINES["catenary"], newton=newton,
                              n_elements=20)
            for newton in (False, True)}
    (_, plain, plain_report), (_, polished, report) = runs[False], runs[True]
    assert plain_report.converged and report.converged
    assert report.newton_steps > 0
    assert report.iterations < 0.2 * plain_report.iterations
    # r and r' (d1, d2 are those of a family: the free roll of K1 = K2 between pins)
    for field in ("r", "slope"):
        a = getattr(plain.problem.state, field).owned()
        b = getattr(polished.problem.state, field).owned()
        assert np.abs(a - b).max() < 1e-8
    assert np.allclose(plain.problem.end_reaction(), polished.problem.end_reaction(),
                       rtol=0, atol=1e-8)


# --- (c) the LDL^T without the resultants' rows -------------------------------------------------
def test_the_ldlt_without_the_resultants_rows_is_that_of_the_whole_h(comm, solver_factory):
    """At the converged catenary in the current (K1 != K2: no free roll, so H is
    regular), H - shift M for shifts from 0 to well into the spectrum: the negative
    pivots SecondVariation counts (its factor leaves out the resultants' identity rows)
    equal those of the whole matrix factored by MUMPS, and its solve equals that of the
    whole matrix."""
    line = dict(LINES["catenary"], stiffness=(1e-1, 2e-1, 1e-1))
    mesh, solver, report = converged(solver_factory, comm, line, newton=True, n_elements=20)
    assert report.converged
    hessian = solver.problem.second_variation()
    assert hessian.resultants and hessian.shifted.getSize()[0] < hessian.matrix.getSize()[0]
    whole = hessian.matrix.duplicate(copy=True)
    ksp, factor = inertia_solver(whole.getComm(), whole)
    rhs, expected = whole.createVecs()
    rhs.setRandom()
    counts = []
    try:
        for shift in (0.0, 1e-2, 1e-1, 1.0):
            hessian.matrix.copy(whole)
            scaled = hessian.mass.copy()
            scaled.scale(-shift)
            whole.setDiagonal(scaled, addv=PETSc.InsertMode.ADD_VALUES)
            scaled.destroy()
            ksp.setOperators(whole)
            ksp.setUp()
            hessian.factorise(shift)
            counts.append(hessian.negative_pivots())
            assert counts[-1] == factor.getInertia()[0] - hessian.chain_constraints
            ksp.solve(rhs, expected)
            solution = hessian.solve(rhs)
            solution.axpy(-1.0, expected)
            assert solution.norm() < 1e-10 * expected.norm()
            solution.destroy()
        assert counts[0] == 0 and counts[-1] > 0        # positive definite, then not
    finally:
        for obj in (ksp, whole, rhs, expected):
            obj.destroy()


# --- (d) chord steps near the solution ------------------------------------------------------
def test_chord_steps_reuse_the_factors_and_reach_the_same_state(comm, solver_factory,
                                                                monkeypatch):
    """The catenary of (c) (K1 != K2) at 40 elements with Newton steps: where the previous
    step turned by at most FREEZE_TURN the step reuses the last J's LU (a chord step),
    so J is factored fewer times than steps are taken, where exact steps (FREEZE_TURN =
    0) factor it at every step; both reach the same state, to the tolerance (measured:
    turns 0.39, 0.15, 1.8e-3, 9.8e-6, then a chord step of 6.9e-13 rad)."""
    from petsc_rod.analysis.jacobian import NewtonJacobian
    from petsc_rod.iteration import newton as newton_module
    factored = []
    assemble = NewtonJacobian.assemble

    def counted(self):
        factored.append(1)
        assemble(self)

    monkeypatch.setattr(NewtonJacobian, "assemble", counted)
    runs = {}
    for freeze in (newton_module.FREEZE_TURN, 0.0):
        monkeypatch.setattr(newton_module, "FREEZE_TURN", freeze)
        factored.clear()
        _, solver, report = converged(solver_factory, comm,
                                      dict(LINES["catenary"], stiffness=(1e-1, 2e-1, 1e-1)),
                                      newton=True, n_elements=40)
        assert report.converged and report.newton_steps > 0
        runs[freeze] = (report.newton_steps, len(factored),
                        solver.problem.state.r.owned().copy())
    (steps, factorisations, r), (exact_steps, exact_factorisations, exact_r) = runs.values()
    assert factorisations < steps
    assert exact_factorisations == exact_steps
    assert np.abs(r - exact_r).max() < 1e-9


def test_a_chord_step_solves_one_right_hand_side_and_ends_by_its_rest(comm, solver_factory,
                                                                      monkeypatch):
    """The catenary of (d) with chord steps from 1e-2 rad (FREEZE_TURN), so that two are
    taken (measured: exact steps of 0.39, 0.15 and 1.8e-3 rad, then chord steps of
    9.8e-6 and 3.3e-9 rad). An exact step solves J for its right-hand side and the three
    chord forms between the pins (4 columns); a chord step for its right-hand side alone,
    the forms' solves being the last exact step's. The attempt ends at the first chord
    step whose rest theta / (1 - theta) turn (theta the turn over the previous one) is
    below STEP_TOLERANCE, though its turn is not, at the state of exact steps to 1e-9."""
    from petsc_rod.analysis.jacobian import NewtonJacobian
    from petsc_rod.iteration import newton as newton_module
    events = []
    assemble, solve_many = NewtonJacobian.assemble, NewtonJacobian.solve_many

    def factored(self):
        events.append("factor")
        assemble(self)

    def solved(self, columns):
        events.append(len(columns))
        return solve_many(self, columns)

    monkeypatch.setattr(NewtonJacobian, "assemble", factored)
    monkeypatch.setattr(NewtonJacobian, "solve_many", solved)
    scene = dict(LINES["catenary"], stiffness=(1e-1, 2e-1, 1e-1))
    states = {}
    for freeze in (1e-2, 0.0):
        monkeypatch.setattr(newton_module, "FREEZE_TURN", freeze)
        events.clear()
        _, solver, report = converged(solver_factory, comm, scene, newton=True)
        assert report.converged
        states[freeze] = (list(events), [change for change, residual, _ in report.history
                                         if residual == 0.0],
                          solver.problem.state.r.owned().copy())
    (events, turns, r), (_, _, exact_r) = states.values()
    exact = [columns for before, columns in zip(events, events[1:]) if before == "factor"]
    chords = [columns for before, columns in zip(events, events[1:])
              if before != "factor" and columns != "factor"]
    assert exact and set(exact) == {4}
    assert len(chords) >= 2 and set(chords) == {1}
    rests = [newton_module._chord_rest(turn, previous)
             for previous, turn in zip(turns, turns[1:])][-len(chords):]
    assert turns[-1] > newton_module.STEP_TOLERANCE
    assert rests[-1] < newton_module.STEP_TOLERANCE <= min(rests[:-1])
    assert np.abs(r - exact_r).max() < 1e-9


def recorded_steps(monkeypatch):
    """The list to which each assembly (and LU) of the Newton Jacobian appends "J" and
    each inertia test of H "H", in order, while ``monkeypatch`` holds."""
    from petsc_rod.analysis.jacobian import NewtonJacobian
    events = []
    assemble = NewtonJacobian.assemble
    positive_definite = NewtonSolver._positive_definite

    def factored(self):
        events.append("J")
        assemble(self)

    def tested(hessian, regularised=False):
        events.append("H")
        return positive_definite(hessian, regularised)

    monkeypatch.setattr(NewtonJacobian, "assemble", factored)
    monkeypatch.setattr(NewtonSolver, "_positive_definite", staticmethod(tested))
    return events


def test_an_exact_step_after_a_small_tested_one_is_taken_without_the_inertia_test(
        comm, solver_factory, monkeypatch):
    """The catenary of (d) with exact steps only (FREEZE_TURN = 0; measured turns 0.39,
    0.15, 1.8e-3, 9.8e-6 rad, then one below STEP_TOLERANCE): the step after the tested
    one of 9.8e-6 rad (at most INERTIA_TURN) is taken without H's inertia test (its
    solves are J's), so H is tested at one step fewer than J is factored; the others
    are tested, the first steps' turns being above INERTIA_TURN. The state is that of
    the attempt that tests every step (INERTIA_TURN = 0), to round-off."""
    from petsc_rod.iteration import newton as newton_module
    events = recorded_steps(monkeypatch)
    monkeypatch.setattr(newton_module, "FREEZE_TURN", 0.0)
    scene = dict(LINES["catenary"], stiffness=(1e-1, 2e-1, 1e-1))
    runs = []
    for inertia_turn in (newton_module.INERTIA_TURN, 0.0):
        monkeypatch.setattr(newton_module, "INERTIA_TURN", inertia_turn)
        events.clear()
        _, solver, report = converged(solver_factory, comm, scene, newton=True)
        assert report.converged and report.newton_steps >= 4
        runs.append((events.count("H"), events.count("J"),
                     solver.problem.state.r.owned().copy()))
    (tests, factorisations, r), (all_tests, all_factorisations, all_r) = runs
    assert factorisations == all_factorisations >= 4
    assert all_tests == all_factorisations
    assert tests == factorisations - 1
    assert np.abs(r - all_r).max() < 1e-12


def test_a_first_step_with_the_iterations_curvature_vouches_for_no_trusted_step(
        comm, solver_factory, monkeypatch):
    """A line whose heights enter (the catenary of (d) on a seabed at its start): its
    first step's inertia test is of H with the iteration's multipliers, not of the
    state's own H, so the next exact step is tested even where every turn would allow a
    trusted one (INERTIA_TURN = 1 rad): an H test between the first two factorisations
    of J (the review found the state's own H indefinite at such a trusted step)."""
    from petsc_rod.environment.seabed import Seabed
    from petsc_rod.iteration import newton as newton_module
    events = recorded_steps(monkeypatch)
    monkeypatch.setattr(newton_module, "FREEZE_TURN", 0.0)
    monkeypatch.setattr(newton_module, "INERTIA_TURN", 1.0)
    scene = dict(LINES["catenary"], seabed=Seabed(0.0, 1e3))
    _, solver, report = converged(solver_factory, comm, scene, newton=True)
    assert report.converged and solver.newton.reads_positions
    assert events.count("J") >= 3
    first, second = [k for k, event in enumerate(events) if event == "J"][:2]
    assert "H" in events[:first] and "H" in events[first:second]


def test_each_rank_s_interior_of_a_riser_s_jacobian_is_factored_in_its_natural_order(
        solver_factory):
    """On several ranks each rank's interior of J is PETSc's LU in the natural order
    (ksp.NaturalLU, as one rank factors the whole J), which passes its check on a steel
    riser with a seabed in a current across (options/riser_catenary.opts at 900
    elements, converged): numbered from its end, as MUMPS's interior of the first rank
    is (ChainFactor's ``reorder``), the elimination meets the zero diagonal of a chain's
    multiplier first, and the check hands that interior over to MUMPS."""
    from test_seabed_newton import STEEL_RISER
    from petsc_rod.global_step.chain_factor import ChainFactor
    from petsc_rod.global_step.ksp import NaturalLU
    from petsc_rod.problem.penalty import default_penalty
    from petsc_rod.scenes.scene import Scene
    from petsc_rod.scenes.starts import largest_tension
    comm = PETSc.COMM_WORLD
    if comm.getSize() == 1:
        pytest.skip("the interiors are those of several ranks")
    riser = dict(STEEL_RISER, current=Current.uniform((0.0, 1.0, 0.0), 1025.0, 1.2, 0.3))
    scene = Scene(**riser)
    mesh, solver = solver_factory(comm, 900, riser,
                                  default_penalty(scene, largest_tension(scene)),
                                  rtol=1e-9, ctol=1e-9, max_it=2000, newton=True)
    solver.problem.state.set_from_curve(catenary_start(Scene(**STEEL_RISER), 1.0))
    assert solver.solve_step(1.0).converged
    polish = NewtonSolver(solver.problem)
    reordered = None
    try:
        state = solver.problem.state
        polish.lagrangian_gradient(state.tau.copy(), state.chord_multiplier.copy())
        hessian = solver.problem.second_variation()
        jacobian = polish._jacobian_of(hessian)
        factor = jacobian.factor
        # every rank's (substructured, reversed, handed over), gathered before any
        # assertion: an assertion on one rank would leave the others in a collective
        ranks = comm.tompi4py().allgather((
            factor.substructured, factor.factor.reversed, factor.factor.solver.fell_back))
        assert ranks == [(True, False, False)] * comm.getSize()
        block = hessian.block
        reordered = ChainFactor(jacobian.matrix, PETSc.PC.Type.LU, block,
                                lambda interior: NaturalLU(interior, block, "test_reorder_"))
        reordered.set_up(jacobian.matrix)
        ranks = comm.tompi4py().allgather((reordered.reversed, reordered.solver.fell_back))
        assert ranks == [(True, True)] + [(False, False)] * (comm.getSize() - 1)
    finally:
        if reordered is not None:
            reordered.destroy()
        polish.destroy()
