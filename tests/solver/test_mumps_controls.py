"""The MUMPS factorisations of global_step/ksp.py read their controls under their own
prefixes: the LDL^T of the second variation (inertia_solver) under -rod_inertia_, with
MUMPS's own ordering unless given (ICNTL 7 = 7, automatic), and the Newton Jacobian's LU
(lu_solver) under -rod_newton_, with the approximate minimum fill ordering (ICNTL 7 = 2)
unless given (set_up_mumps; docs/performance.md). A default is in effect only during
the set-up: it is not left in the options database (it would be reported as an option
nobody used)."""

from contextlib import contextmanager

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.global_step.ksp import (INERTIA_PREFIX, NEWTON_PREFIX, inertia_solver,
                                       lu_solver, set_up_mumps)

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


@pytest.mark.parametrize("given", [None, "0"])
def test_the_newton_lu_takes_amf_unless_given(given):
    comm = PETSc.COMM_WORLD
    name = f"{NEWTON_PREFIX}mat_mumps_icntl_7"
    matrix = indefinite_matrix(comm)
    ksp = lu_solver(comm, matrix)
    try:
        with option_given(name, given) as options:
            set_up_mumps(ksp)
            assert options.hasName(name) == (given is not None)
        assert ksp.getPC().getFactorMatrix().getMumpsIcntl(7) == (
            2 if given is None else int(given))
        b, x = matrix.createVecs()
        b.set(1.0)
        ksp.solve(b, x)
        residual = b.duplicate()
        matrix.mult(x, residual)
        residual.axpy(-1.0, b)
        assert residual.norm() <= 1e-13 * np.sqrt(SIZE)
        for vec in (b, x, residual):
            vec.destroy()
    finally:
        ksp.destroy()
        matrix.destroy()
