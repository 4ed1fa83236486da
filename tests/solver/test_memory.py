"""What a long run keeps in memory (docs/performance.md, "Memory for long lines").

- The SNES's work vectors (Anderson's history) are freed before the stability test
  factors H (UzawaSolver.release_work), and the next step sets the SNES up again: the
  run goes on to the same answer.
- The stability test factors a copy of H, its diagonal shifted by -shift M (H's own
  pattern changes with each update: analysis/stability.py): H is bit for bit as it was,
  and the factor is that of H - shift M.
- The global step keeps one matrix per chain: the liftings A_full x_bc come from the
  prescribed columns of the unconstrained matrix, bit for bit its product.

Serial and under mpiexec -n 2.
"""

import numpy as np

from helpers import PAPER_SCENE as PAPER, continuation
from petsc_rod.global_step.matrices import assemble_matrix
from petsc_rod.scenes.scene import REFERENCE_FRAME

CLAMPED = dict(PAPER, end="clamp", end_frame=REFERENCE_FRAME)


def test_the_iteration_work_is_freed_while_h_is_factored(solver_factory, comm, monkeypatch):
    # without Newton steps: every test is a converged step's (a Newton attempt's early
    # test comes in the middle of the iteration, which keeps its work)
    _, solver = solver_factory(comm, 24, PAPER, 400.0, 1e-3, 1e-3, 5000, newton=False)
    iterating, testing = [], []         # references to the SNES's solution x
    solver.monitor = lambda *row: iterating.append(solver._x.getRefCount())
    test = type(solver).check_stability

    def counted_test(self):
        testing.append(self._x.getRefCount())
        return test(self)
    monkeypatch.setattr(type(solver), "check_stability", counted_test)
    report = continuation(solver, steps=2)
    assert report.converged and report.stable
    # a set-up SNES holds x as its solution; SNESReset (release_work) lets it go with
    # Anderson's history, and the next step's solve takes it again
    assert testing and max(testing) < min(iterating)
    # and the run goes on to the same answer, bit for bit, as with the work kept
    monkeypatch.undo()
    _, kept = solver_factory(comm, 24, PAPER, 400.0, 1e-3, 1e-3, 5000, newton=False)
    monkeypatch.setattr(type(kept), "release_work", lambda self: None)
    kept_report = continuation(kept, steps=2)
    assert kept_report.converged and kept_report.iterations == report.iterations
    freed, held = solver.problem.state.snapshot(), kept.problem.state.snapshot()
    assert set(freed) == set(held) and "r" in freed
    for name in freed:
        assert np.array_equal(freed[name], held[name]), name


def csr(matrix):
    """The matrix's local rows (indptr, indices, values), copies."""
    return tuple(np.array(part, copy=True) for part in matrix.getValuesCSR())


def test_the_stability_test_leaves_h_as_it_was_and_factors_h_less_its_shift(solver_factory,
                                                                             comm):
    _, solver = solver_factory(comm, 24, PAPER, 400.0, 1e-3, 1e-3, 5000)
    assert continuation(solver, steps=2).converged
    hessian = solver.problem.second_variation()
    before = csr(hessian.matrix)
    shift = 0.37 * hessian.lower_bound()
    hessian.factorise(shift)
    after = csr(hessian.matrix)
    for old, new in zip(before, after):
        assert np.array_equal(old, new)
    # the factor is that of H - shift M: (H - shift M) x = b to round-off
    rhs = hessian.matrix.createVecLeft()
    start, end = rhs.getOwnershipRange()
    rhs.getArray()[:] = np.cos(np.arange(start, end))
    hessian._zero_clamped(rhs)
    x = hessian.solve(rhs)
    residual = rhs.duplicate()
    hessian.matrix.mult(x, residual)
    mass_x = x.duplicate()
    mass_x.pointwiseMult(hessian.mass, x)
    residual.axpy(-shift, mass_x)
    residual.axpy(-1.0, rhs)
    try:
        assert residual.norm() < 1e-9 * rhs.norm() * max(1.0, x.norm())
        assert x.norm() > 0.0
    finally:
        for vec in (rhs, x, residual, mass_x):
            vec.destroy()


def test_the_liftings_are_the_unconstrained_products(solver_factory, comm):
    mesh, solver = solver_factory(comm, 6, CLAMPED, 400.0, 1e-3, 1e-3, 5000)
    step = solver.problem.global_step
    step.prepare(0.5)
    for i, problem in enumerate(step.problems):
        assert not hasattr(problem, "full")     # one matrix kept per chain
        matrices = step.coefficients.global_step_matrices(i, step.penalty)
        full = (step.unconstrained_slope_matrix() if i == 2
                else assemble_matrix(mesh, matrices))
        start, _ = full.getOwnershipRange()
        x, lift = full.createVecs()
        lifts = []
        for c in range(3):
            x.zeroEntries()
            x.getArray()[problem._local_rows] = problem._fixed_values[:, c]
            full.mult(x, lift)
            values = lift.getArray(readonly=True).copy()
            values[problem._local_rows] = 0.0
            lifts.append(values)
        lifts = np.stack(lifts, axis=1)
        rows = np.flatnonzero(np.any(lifts != 0.0, axis=1))
        assert np.array_equal(rows, problem._lift_rows)
        assert np.array_equal(lifts[rows], problem._lift_values)
        # the clamps prescribe every field at both ends: rows coupled on the end ranks
        total = comm.tompi4py().allreduce(len(rows))
        assert total >= 2
        for obj in (full, x, lift):
            obj.destroy()


def test_strains_of_many_points_hold_no_array_of_their_size_but_the_answer():
    import tracemalloc

    from petsc_rod.frames import strains
    rng = np.random.default_rng(3)
    n = 40000
    d, dd = rng.normal(size=(n, 3, 3)), rng.normal(size=(n, 3, 3))
    d[7] = 0.0                                  # a singular frame: the pseudo-inverse
    tracemalloc.start()
    try:
        u = strains(d, dd)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # the answer (n, 3) and blocks of points; at once: inverses, rates (n, 3, 3) each
    assert peak < u.nbytes + d.nbytes
    # each point's strains are its own: the same bits as the points one block apart
    assert np.array_equal(u[1:2], strains(d[1:2], dd[1:2]))
    assert np.array_equal(u[-3:], strains(d[-3:], dd[-3:]))
    assert np.all(np.isfinite(u))
