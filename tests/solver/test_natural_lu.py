"""The Newton Jacobian's LU on one rank (global_step/ksp.NaturalLU): PETSc's own LU in
the natural order, checked at each factorisation by the backward and forward errors of
two solves, and MUMPS's threshold-pivoting LU from the first factorisation that fails
the check (a zero pivot, or growth without pivoting), for the rest of its life.

(a) a band whose elimination in its order is stable stays with PETSc's LU and solves as
    a dense LU with pivoting does;
(b) a diagonal entry not stored, a zero pivot, and a pivot so small that the
    elimination grows by 1e10 hand the factorisation to MUMPS, whose solves are then
    those of the dense LU (where the unpivoted LU's are off by far more); so does a
    null vector whose pivot the elimination keeps at the round-off, which only the
    forward error shows;
(c) Newton steps in a current reach the same state with -rod_newton_lu petsc (the
    default) as with mumps, in the same iterations, on a line hanging from a clamp and
    on a catenary between pins whose free roll (K1 = K2) makes J nearly singular near
    the solution (PETSc's factors pass their check there: eta 1.3e-16).
"""

from contextlib import contextmanager

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.global_step import ksp
from petsc_rod.global_step.ksp import NEWTON_PREFIX, NaturalLU
from test_drag_newton import LINES, converged

SIZE = 40


def banded(first_pivot=None, stored=True):
    """An unsymmetric tridiagonal matrix on one rank, diagonal (-1)^i (2 + i / SIZE),
    0.1 below and 0.3 above it (eigenvalues within 0.4 of the diagonal: regular and
    indefinite); with ``first_pivot`` its first diagonal entry is that and its first
    off-diagonal pair 1, so that the elimination in order meets that pivot (a 0 among
    the stored entries where ``stored``, else left out of the pattern). The Mat and its
    dense copy."""
    dense = np.zeros((SIZE, SIZE))
    i = np.arange(SIZE)
    dense[i, i] = (-1.0) ** i * (2.0 + i / SIZE)
    dense[i[1:], i[:-1]] = 0.1
    dense[i[:-1], i[1:]] = 0.3
    if first_pivot is not None:
        dense[0, 0], dense[0, 1], dense[1, 0] = first_pivot, 1.0, 1.0
    rows, columns = np.nonzero(dense)
    if first_pivot == 0.0 and stored:
        rows, columns = np.append(rows, 0), np.append(columns, 0)
    return sequential(dense, rows, columns), dense


def sequential(dense, rows, columns):
    """A sequential AIJ Mat of ``dense``'s entries at (rows, columns), assembled."""
    matrix = PETSc.Mat().createAIJ(dense.shape, nnz=3, comm=PETSc.COMM_SELF)
    for row, column in zip(rows, columns):
        matrix.setValue(int(row), int(column), dense[row, column])
    matrix.assemble()
    return matrix


def right_hand_sides(count=3):
    return [np.cos(np.arange(SIZE) * (k + 1.0)) for k in range(count)]


def factored(matrix):
    factor = NaturalLU(matrix, 1, NEWTON_PREFIX)
    factor.set_up(matrix)
    return factor


def relative_errors(factor, dense):
    columns = right_hand_sides()
    solutions = factor.solve_columns(columns)
    return [np.abs(x - np.linalg.solve(dense, b)).max() / np.abs(np.linalg.solve(dense, b)).max()
            for x, b in zip(solutions, columns)]


# --- (a) -------------------------------------------------------------------------------------
def test_a_stable_band_stays_with_petscs_lu():
    matrix, dense = banded()
    factor = factored(matrix)
    try:
        assert not factor.fell_back
        assert max(relative_errors(factor, dense)) < 1e-13
    finally:
        factor.destroy()
        matrix.destroy()


# --- (b) -------------------------------------------------------------------------------------
def unpivoted_error(matrix, dense):
    """The relative error of PETSc's LU in the natural order, unchecked, on the first
    right-hand side."""
    solver = PETSc.KSP().create(comm=PETSc.COMM_SELF)
    solver.setOperators(matrix)
    solver.setType(PETSc.KSP.Type.PREONLY)
    solver.getPC().setType(PETSc.PC.Type.LU)
    solver.getPC().setFactorOrdering("natural")
    right, solution = matrix.createVecs()
    right.getArray()[:] = right_hand_sides(1)[0]
    try:
        solver.solve(right, solution)
        exact = np.linalg.solve(dense, right_hand_sides(1)[0])
        return np.abs(solution.getArray() - exact).max() / np.abs(exact).max()
    finally:
        for obj in (solver, right, solution):
            obj.destroy()


@pytest.mark.parametrize("first_pivot, stored", [(0.0, False), (0.0, True), (1e-10, True)],
                         ids=["diagonal not stored", "zero pivot", "growth 1e10"])
def test_a_failed_elimination_hands_the_factorisation_to_mumps(first_pivot, stored):
    matrix, dense = banded(first_pivot, stored)
    factor = factored(matrix)
    try:
        assert factor.fell_back
        assert max(relative_errors(factor, dense)) < 1e-13
        # the next factorisation is MUMPS's too, at once
        factor.set_up(matrix)
        assert factor.fell_back and max(relative_errors(factor, dense)) < 1e-13
    finally:
        factor.destroy()
    if first_pivot:
        # what the check caught: the unpivoted solve's error, a million times MUMPS's
        assert unpivoted_error(matrix, dense) > 1e-10
    matrix.destroy()


def laplacian_of_a_chain(n=200, seed=2):
    """An unsymmetric tridiagonal matrix on one rank whose rows sum to zero (weights
    0.5 to 2 below and above the diagonal), its last entry moved by 1e-15: singular to
    the round-off, its null vector the ones. (With seed 2 the elimination's last pivot
    passes PETSc's zero-pivot test; with seeds 0 and 1 it does not, and the check
    sees Inf.)"""
    rng = np.random.default_rng(seed)
    dense = np.zeros((n, n))
    i = np.arange(n - 1)
    dense[i, i + 1] = -rng.uniform(0.5, 2.0, n - 1)
    dense[i + 1, i] = -rng.uniform(0.5, 2.0, n - 1)
    dense[np.arange(n), np.arange(n)] = -dense.sum(axis=1)
    dense[-1, -1] += 1e-15 * rng.standard_normal()      # singular to the round-off
    return sequential(dense, *np.nonzero(dense))


def test_a_null_pivot_kept_at_the_round_off_is_caught_by_the_forward_error():
    """The elimination in order keeps the singular chain's last pivot at the round-off
    (above PETSc's zero-pivot test): the solves' backward error stays at the round-off,
    their forward error (the null vector's component) is of order 1; MUMPS takes over
    (its null pivot detected)."""
    matrix = laplacian_of_a_chain()
    alone = NaturalLU(matrix, 1, NEWTON_PREFIX)
    factor = None
    try:
        alone.ksp.setUp()
        backward, forward = alone.errors(matrix)
        assert backward < 1e-15 and forward > 1.0
        factor = factored(matrix)
        assert factor.fell_back
    finally:
        for obj in (alone, factor, matrix):
            if obj is not None:
                obj.destroy()


# --- (c) -------------------------------------------------------------------------------------
@contextmanager
def newton_lu(package):
    """-rod_newton_lu ``package`` for the block."""
    options = PETSc.Options()
    options[f"{NEWTON_PREFIX}{ksp.LU_PACKAGE}"] = package
    try:
        yield
    finally:
        options.delValue(f"{NEWTON_PREFIX}{ksp.LU_PACKAGE}")


@pytest.mark.parametrize("line", ["hanging", "catenary"])
def test_newton_steps_reach_the_state_of_mumps_lu(solver_factory, monkeypatch, line):
    comm = PETSc.COMM_SELF
    made = []
    make = ksp.NaturalLU.__init__
    monkeypatch.setattr(ksp.NaturalLU, "__init__",
                        lambda self, *args: (made.append(self), make(self, *args))[1])
    runs = {}
    for package in ("mumps", "petsc"):
        with newton_lu(package):
            runs[package] = converged(solver_factory, comm, LINES[line], newton=True,
                                      n_elements=20)
    (_, by_mumps, mumps_report), (_, by_petsc, report) = runs["mumps"], runs["petsc"]
    assert mumps_report.converged and report.converged and report.newton_steps > 0
    # -rod_newton_lu mumps makes none; petsc's factors pass their check
    assert len(made) == 1 and not made[0].fell_back
    assert report.iterations == mumps_report.iterations
    for field in ("r", "slope"):
        a = getattr(by_mumps.problem.state, field).owned()
        b = getattr(by_petsc.problem.state, field).owned()
        assert np.abs(a - b).max() < 1e-10
