"""A linear-algebra failure inside a Newton attempt is a failed attempt (iteration/
newton.py, "A linear-algebra failure"), never a traceback: the state is left as it was
and the iteration goes on. On one rank (PETSc.COMM_SELF) and on all ranks
(PETSc.COMM_WORLD: under ``mpiexec -n 2`` the parallel run, where every rank must take
the same decision or the next collective call would hang).

(a) A factorisation that failed gives Inf solves (ksp.solve_columns): the Jacobian's
    (a catenary in a current, unsymmetric steps) and the LDL^T of the
    positive-definiteness test (the same catenary without the current, whose
    constraint solves then fill the inertia's Schur matrix with NaN: LAPACK's
    "Eigenvalues did not converge").
(b) A state the steps cannot start from: an extensible line with a node compressed to
    a point (k = 0, which the stretched local step allows; a soft line,
    options/riser_catenary.opts -rod_axial_stiffness 1e3, reaches it).
(c) MUMPS's workspace errors (INFOG(1) = -9 after the pivots grew the factors: the
    friction's Jacobian on a rank's interior, options/riser_catenary.opts
    -rod_current 0,1,0 -rod_seabed_friction 0.5 on 2 ranks) are retried with more
    workspace (ksp.set_up_mumps).
"""

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.analysis.jacobian import NewtonJacobian
from petsc_rod.analysis.stability import StabilityTest
from petsc_rod.environment.current import Current
from petsc_rod.global_step import ksp as ksp_module
from petsc_rod.iteration import newton
from petsc_rod.iteration.newton import NewtonSolver

COMMS = {"one rank": PETSc.COMM_SELF, "all ranks": PETSc.COMM_WORLD}

CURRENT = Current.uniform((0.0, 1.0, 0.0), 1000.0, 1.2, 5e-4)
CATENARY = dict(length=10.0, stiffness=(1e-1, 1e-1, 1e-1), start="pin", end="pin",
                end_position=(7.0, 0.0, 4.0), load_values=[[0.0, 0.0, -1.0]])


@pytest.fixture(scope="module", params=list(COMMS))
def comm(request):
    return COMMS[request.param]


def near_solution(solver_factory, comm, scene):
    """The problem of a solver whose state is at most 400 iterations of the map from
    straight (no Newton), near the solution: where an attempt would start."""
    mesh, solver = solver_factory(comm, 20, scene, 200.0, rtol=1e-4, ctol=1e-4,
                                  max_it=400, newton=False)
    solver.problem.state.set_straight()
    solver.solve_step(1.0)
    return solver.problem


def infinite_solves(self, columns, *args):
    """A failed factorisation's solves (ksp.solve_columns): Inf."""
    solutions = []
    for column in columns:
        solution = column.duplicate()
        solution.set(np.inf)
        solutions.append(solution)
    return solutions


def attempt(problem):
    """(outcome, whether the state is bit for bit as before) of one Newton attempt."""
    before = problem.state.snapshot()
    polish = NewtonSolver(problem)
    try:
        outcome = polish.run()
    finally:
        polish.destroy()
    after = problem.state.snapshot()
    same = all(np.array_equal(np.asarray(before[key]), np.asarray(after[key]))
               for key in before)
    return outcome, same


@pytest.mark.parametrize("failing", ["jacobian", "inertia"])
def test_a_failed_factorisation_is_a_failed_attempt(comm, solver_factory, monkeypatch,
                                                     failing):
    scene = dict(CATENARY, current=CURRENT) if failing == "jacobian" else CATENARY
    problem = near_solution(solver_factory, comm, scene)
    # the attempt works with the factorisations' own solves
    outcome, _ = attempt(problem)
    assert outcome == newton.CONVERGED
    problem = near_solution(solver_factory, comm, scene)
    owner = NewtonJacobian if failing == "jacobian" else StabilityTest
    monkeypatch.setattr(owner, "solve_many", infinite_solves)
    outcome, same = attempt(problem)
    assert outcome == newton.FAILED
    assert same


def test_a_point_of_the_line_compressed_to_nothing_is_a_failed_attempt(comm,
                                                                        solver_factory):
    problem = near_solution(solver_factory, comm, dict(CATENARY, current=CURRENT,
                                                       axial_stiffness=50.0))
    state = problem.state
    # one node of the last rank (every rank must fail with it)
    if comm.getRank() == comm.getSize() - 1:
        state.tau[len(state.tau) // 2, 2] = 0.0
    with np.errstate(all="raise"):      # no NaN made on the way to the verdict
        outcome, same = attempt(problem)
    assert outcome == newton.FAILED
    assert same


class _Reporting:
    """A proxy of an object whose method ``name`` gives ``values`` first, then the
    object's own."""

    def __init__(self, wrapped, **replaced):
        self._wrapped, self._replaced = wrapped, replaced

    def __getattr__(self, name):
        return self._replaced.get(name, getattr(self._wrapped, name))


def test_a_workspace_error_is_factored_again_with_more_workspace():
    """A factorisation that reported -9 (its workspace too small) is made again, on a
    new factor with four times the relaxation and the controls kept, and solves."""
    n = 30
    matrix = PETSc.Mat().createAIJ((n, n), nnz=3, comm=PETSc.COMM_SELF)
    for i in range(n):
        columns = np.arange(max(i - 1, 0), min(i + 2, n), dtype=PETSc.IntType)
        matrix.setValues([i], columns, np.where(columns == i, 4.0, -1.0 + 0.5 * (columns > i)))
    matrix.assemble()
    ksp = ksp_module.lu_solver(PETSc.COMM_SELF, matrix)
    first = ksp.getPC().getFactorMatrix()
    reported = iter([-9])

    def infog(index, factor=first):
        return next(reported, factor.getMumpsInfog(index)) if index == 1 else \
            factor.getMumpsInfog(index)

    class PC(_Reporting):
        def getFactorMatrix(self):
            factor = self._wrapped.getFactorMatrix()
            if factor.handle == first.handle:     # the first factor reports -9 once
                return _Reporting(factor, getMumpsInfog=infog)
            return factor

    class KSP(_Reporting):
        def getPC(self):
            return PC(self._wrapped.getPC())

    try:
        ksp_module.set_up_mumps(KSP(ksp), block=1)
        factor = ksp.getPC().getFactorMatrix()
        assert factor.handle != first.handle
        assert factor.getMumpsInfog(1) == 0
        assert factor.getMumpsIcntl(14) == ksp_module.WORKSPACE_GROWTH * 20
        assert factor.getMumpsIcntl(24) == 1
        assert factor.getOptionsPrefix() == ksp_module.NEWTON_PREFIX
        right = np.arange(1.0, n + 1.0)
        solution = ksp_module.solve_columns(ksp, [right])[0]
        dense = matrix.convert("dense").getDenseArray()
        assert np.abs(dense @ solution - right).max() < 1e-12 * np.abs(right).max()
    finally:
        ksp.destroy()
        matrix.destroy()
