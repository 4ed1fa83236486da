"""The MUMPS factorisations of global_step/ksp.py read their controls under their own
prefixes: the LDL^T of the second variation (inertia_solver) under -rod_inertia_, with
MUMPS's own ordering unless given (ICNTL 7 = 7, automatic), and the Newton Jacobian's LU
(lu_solver) under -rod_newton_, with the approximate minimum fill ordering (ICNTL 7 = 2)
unless given, on the graph of the nodes (ICNTL 15 = -B) where the caller gives the B
unknowns of a node (set_up_mumps; docs/performance.md). A default is in effect only during
the set-up: it is not left in the options database (it would be reported as an option
nobody used). solve_columns solves several right-hand sides in one MatMatSolve."""

from contextlib import contextmanager

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.global_step.ksp import (INERTIA_PREFIX, NEWTON_PREFIX, inertia_solver,
                                       lu_solver, set_up_mumps, solve_columns)

SIZE = 40
MUMPS_AUTOMATIC = 7          # ICNTL(7)'s value for "MUMPS chooses the ordering"


def indefinite_matrix(comm):
    """A symmetric tridiagonal matrix, diagonal d_i = (-1)^i (2 + i / SIZE), off-diagonal
    0.1: its eigenvalues are within 0.2 of the diagonal's, so half of them are negative."""
    matrix = PETSc.Mat().createAIJ((SIZE, SIZE), nnz=(3, 2), comm=comm)
    start, end = matrix.getOwnershipRange()
    for i in range(start, end):
        matrix.setValue(i, i, (-1.0) ** i * (2.0 + i / SIZE))
        for j in (i - 1, i + 1):
            if 0 <= j < SIZE:
                matrix.setValue(i, j, 0.1)
    matrix.assemble()
    return matrix


@contextmanager
def option_given(name, value):
    """-name value in the options database for the block (nothing where value is None)."""
    options = PETSc.Options()
    if value is not None:
        options[name] = value
    try:
        yield options
    finally:
        if value is not None:
            options.delValue(name)


@pytest.mark.parametrize("given", [None, "2"])
def test_the_ldlt_reads_its_prefix_and_counts_the_negative_eigenvalues(given):
    comm = PETSc.COMM_WORLD
    matrix = indefinite_matrix(comm)
    ksp, factor = inertia_solver(comm, matrix)
    try:
        with option_given(f"{INERTIA_PREFIX}mat_mumps_icntl_7", given):
            set_up_mumps(ksp)
        assert factor.getMumpsIcntl(7) == (MUMPS_AUTOMATIC if given is None else int(given))
        assert factor.getInertia()[0] == SIZE // 2
    finally:
        ksp.destroy()
        matrix.destroy()


@pytest.mark.parametrize("kind", ["lu", "ldlt"])
def test_several_right_hand_sides_at_once_are_the_solves_one_by_one(kind):
    """solve_columns: k right-hand sides in one MatMatSolve give KSP's solves of each,
    for the LU of an unsymmetric matrix and the LDL^T of an indefinite one; with
    ``rows`` (a submatrix of the rows kept) the rows left out return the right-hand
    side (SecondVariation's resultants' identity rows)."""
    comm = PETSc.COMM_WORLD
    matrix = indefinite_matrix(comm)
    start, end = matrix.getOwnershipRange()
    if kind == "lu":                    # unsymmetric: a superdiagonal of its own
        for i in range(start, min(end, SIZE - 1)):
            matrix.setValue(i, i + 1, 0.3)
        matrix.assemble()
        ksp = lu_solver(comm, matrix)
    else:
        ksp = inertia_solver(comm, matrix)[0]
    kept = np.arange(start, end)[np.arange(start, end) % 3 != 1]   # every third left out
    index = PETSc.IS().createGeneral(kept.astype(PETSc.IntType), comm=comm)
    sub = matrix.createSubMatrix(index, index)
    sub_ksp = lu_solver(comm, sub) if kind == "lu" else inertia_solver(comm, sub)[0]
    b, x = matrix.createVecs()
    sub_b, sub_x = sub.createVecs()
    try:
        for solver in (ksp, sub_ksp):
            set_up_mumps(solver)
        columns = [np.sin((j + 1) * np.arange(start, end)) for j in range(3)]
        for j, solution in enumerate(solve_columns(ksp, columns)):
            b.getArray()[:] = columns[j]
            ksp.solve(b, x)
            assert np.abs(solution - x.getArray()).max() <= 1e-13 * np.abs(x.getArray()).max()
        rows = kept - start
        for j, solution in enumerate(solve_columns(sub_ksp, columns, rows)):
            sub_b.getArray()[:] = columns[j][rows]
            sub_ksp.solve(sub_b, sub_x)
            assert np.abs(solution[rows] - sub_x.getArray()).max() <= 1e-13 * np.abs(
                sub_x.getArray()).max()
            left_out = np.setdiff1d(np.arange(end - start), rows)
            assert np.array_equal(solution[left_out], columns[j][left_out])
    finally:
        for obj in (ksp, sub_ksp, sub, index, matrix, b, x, sub_b, sub_x):
            obj.destroy()


@pytest.mark.parametrize("control, block, given, expected", [
    (7, None, None, 2), (7, None, "0", 0),                  # AMF unless given
    (15, None, None, 0), (15, 2, None, -2), (15, 2, "-4", -4)])
def test_the_newton_lu_s_ordering_controls(control, block, given, expected):
    """ICNTL 7 = 2 (AMF) unless given; ICNTL 15 = -B with a block of B unknowns a node
    (NewtonJacobian passes the second variation's), 0 (the unknowns' graph) without
    one, the option where given; a given option stays the user's, a default does not
    stay in the database; the solve is exact either way."""
    comm = PETSc.COMM_WORLD
    name = f"{NEWTON_PREFIX}mat_mumps_icntl_{control}"
    matrix = indefinite_matrix(comm)
    ksp = lu_solver(comm, matrix)
    try:
        with option_given(name, given) as options:
            set_up_mumps(ksp, block)
            assert options.hasName(name) == (given is not None)
        assert ksp.getPC().getFactorMatrix().getMumpsIcntl(control) == expected
        column = np.cos(np.arange(*matrix.getOwnershipRange()))
        solution = solve_columns(ksp, [column])[0]
        b, x = matrix.createVecs()
        x.getArray()[:] = solution
        matrix.mult(x, b)
        assert np.abs(b.getArray() - column).max() <= 1e-13 * np.sqrt(SIZE)
        for vec in (b, x):
            vec.destroy()
    finally:
        ksp.destroy()
        matrix.destroy()
