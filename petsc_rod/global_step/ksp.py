"""The direct solvers of the project, made in one place: the chain solvers of the global
step (the three P2 problems, and the seabed's vertical problem), the MUMPS LDL^T of
the second variation (analysis/stability.py, options -rod_inertia_*) and the LU of the
Newton Jacobian with a drag or friction (analysis/jacobian.py, -rod_newton_*), both
through direct_factor: on one rank the LDL^T by MUMPS and the LU by PETSc's own in the
natural order (NaturalLU, checked, MUMPS's where the check fails); on several by
substructuring (chain_factor.ChainFactor, each rank's interior as on one rank).

A chain solver is preonly + Cholesky under its own options prefix, with the project's
defaults in effect where the user gave none (petsc_defaults.py): PETSc's Cholesky in
the natural order on one rank (SERIAL_DEFAULTS) and the exact substructuring PC on
several (PARALLEL_DEFAULTS); ``-<prefix>ksp_type``, ``-<prefix>pc_type`` and the rest
override them as for any PETSc KSP.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.errors import RodDivergedError, RodInputError
from petsc_rod.global_step import substructuring
from petsc_rod.global_step.chain_factor import ChainFactor
from petsc_rod.petsc_defaults import defaults_in_effect, set_from_options_with_defaults

KSP_REASONS = {getattr(PETSc.KSP.ConvergedReason, name): name
               for name in dir(PETSc.KSP.ConvergedReason) if not name.startswith("_")}

# The global step on several ranks, unless the options say otherwise: the exact
# substructuring solve of substructuring.py as a python PC (each rank a local Cholesky
# solve of its half of the chain, and a tridiagonal interface system of one unknown per
# rank boundary). It does the serial Cholesky's work divided by the ranks; CG with block
# Jacobi (a few iterations, each a product, a local solve and reductions) and MUMPS (a
# slow solve phase on chains) are slower (docs/performance.md).
PARALLEL_DEFAULTS = {"ksp_type": "preonly", "pc_type": "python",
                     "pc_python_type": substructuring.PYTHON_TYPE}
# On one rank: PETSc's Cholesky in the natural order, in which the chain is a band
# matrix: no fill (the default nested dissection order of PCCHOLESKY fills in and is
# slower here, docs/performance.md).
SERIAL_DEFAULTS = {"pc_factor_mat_ordering_type": "natural"}


def chain_solver(comm, operator, prefix):
    """A KSP for the SPD chain matrix ``operator`` (a DMDA matrix): preonly + Cholesky,
    options read under ``prefix`` with SERIAL_DEFAULTS on one rank and
    PARALLEL_DEFAULTS on several in effect. Not yet set up; the caller owns it."""
    ksp = PETSc.KSP().create(comm=comm)
    ksp.setOperators(operator)
    ksp.setType(PETSc.KSP.Type.PREONLY)
    ksp.getPC().setType(PETSc.PC.Type.CHOLESKY)
    ksp.setOptionsPrefix(prefix)
    defaults = PARALLEL_DEFAULTS if comm.getSize() > 1 else SERIAL_DEFAULTS
    set_from_options_with_defaults(
        ksp, {f"{prefix}{key}": value for key, value in defaults.items()})
    return ksp


def note_changed_rows(ksp, rows, before):
    """Tell the substructuring PC of ``ksp``, where it has one, that only the values of
    ``rows`` (global indices) of its operator changed since the operator's object state
    ``before`` (substructuring.InterfacePC.note_changed_rows: its next refactorisation
    reads those rows alone); any other PC reads the matrix as PETSc gives it."""
    pc = ksp.getPC()
    if pc.getType() != PETSc.PC.Type.PYTHON:
        return
    context = pc.getPythonContext()
    if isinstance(context, substructuring.InterfacePC):
        context.note_changed_rows(ksp.getOperators()[1], rows, before)


# The options prefixes of the LDL^T of the second variation (analysis/stability.py: the
# stability test and the Newton steps' positive-definiteness test) and of the Newton
# Jacobian's LU (analysis/jacobian.py).
INERTIA_PREFIX = "rod_inertia_"
NEWTON_PREFIX = "rod_newton_"


def mumps_defaults(kind, block=None):
    """The MUMPS controls in effect at a set-up (set_up_mumps) unless the options give
    them, for a factorisation ``kind`` (PETSc.PC.Type.CHOLESKY or LU) of a matrix whose
    unknowns come in ``block``s of a node (docs/performance.md): for the LU the AMF
    ordering (ICNTL 7 = 2), an analysis many times faster than MUMPS's own choice,
    PORD, on these chains, on the graph of the nodes (ICNTL 15 = -block) where the
    block is given. The LDL^T keeps MUMPS's choice (AMF on one rank, PORD on several)
    on the unknowns' graph.

    The nodes' graph: AMF on the unknowns' graph makes the elimination tree a path of
    one node per unknown, and MUMPS's mapping of a path onto several ranks grows like
    the square of its length; a node per P2 node shortens it by the block, and on one
    rank the factorisation and the solves are faster as well (docs/performance.md,
    "Newton steps"). Not defaults: PORD on the nodes' graph for the LU on several ranks
    (a faster analysis still, larger factors); the LDL^T on the nodes' graph, whose
    solves were not finite on a riser with seabed friction.
    """
    if kind != PETSc.PC.Type.LU:
        return {}
    defaults = {"mat_mumps_icntl_7": "2"}
    if block is not None and block > 1:
        defaults["mat_mumps_icntl_15"] = str(-int(block))
    return defaults


def inertia_solver(comm, operator, prefix=INERTIA_PREFIX):
    """(ksp, factor): preonly + MUMPS's symmetric-indefinite factorisation of
    ``operator``, reporting the inertia of the whole matrix on every rank (ICNTL 13) and
    detecting null pivots instead of failing on them (ICNTL 24); MUMPS's controls read
    under ``prefix`` (-<prefix>mat_mumps_icntl_*; the KSP and PC are not the options':
    the inertia needs this factorisation). Set it up with set_up_mumps; the symbolic
    factorisation is made at the first set-up and kept while the pattern stays. The
    caller owns the KSP (the factor is the PC's)."""
    ksp, factor = _mumps(comm, operator, PETSc.PC.Type.CHOLESKY, prefix)
    factor.setMumpsIcntl(13, 1)
    return ksp, factor


def lu_solver(comm, operator, prefix=NEWTON_PREFIX):
    """A KSP for an unsymmetric ``operator``: preonly + MUMPS's LU with null pivots
    detected (ICNTL 24) (the Newton Jacobian of a problem with a load that has no
    potential, analysis/jacobian.py): the free roll of a section with K1 = K2 between
    pins is a null vector. Options under ``prefix``; set it up with set_up_mumps. The
    caller owns it."""
    ksp = _mumps(comm, operator, PETSc.PC.Type.LU, prefix)[0]
    ksp.setFromOptions()
    return ksp


# MUMPS's errors of a workspace too small for the factors (INFOG(1): -8, -9 integer and
# real workspace of the factorisation, -11, -12, -14 of the solve, -15, -17, -20 of its
# buffers), which more relaxation of the analysis's estimate (ICNTL 14) cures: on an
# unsymmetric Jacobian the pivots that the threshold pivoting delays grow the factors
# beyond the estimate made from the pattern. Each retry multiplies the relaxation by
# WORKSPACE_GROWTH, at most WORKSPACE_RETRIES times; a factorisation that still fails
# is a failed one (its solves give Inf, and the Newton attempt fails).
WORKSPACE_ERRORS = (-8, -9, -11, -12, -14, -15, -17, -20)
WORKSPACE_GROWTH = 4
WORKSPACE_RETRIES = 3


def set_up_mumps(ksp, block=None):
    """``ksp.setUp()`` for an inertia_solver or lu_solver, with mumps_defaults in effect
    under its prefix (MUMPS reads its controls at the symbolic factorisation;
    MatMumpsSetIcntl(7) before it does not take in PETSc 3.18). ``block``: the
    unknowns of a node, where the matrix's rows come node by node (the LU then analyses
    the nodes' graph)."""
    prefix = ksp.getOptionsPrefix() or ""
    defaults = mumps_defaults(ksp.getPC().getType(), block)
    with defaults_in_effect({f"{prefix}{key}": value for key, value in defaults.items()}):
        ksp.setUp()
        for _ in range(WORKSPACE_RETRIES):
            factor = ksp.getPC().getFactorMatrix()
            if factor.getMumpsInfog(1) not in WORKSPACE_ERRORS:
                break
            _with_more_workspace(ksp, factor)
            ksp.setUp()


def _with_more_workspace(ksp, factor):
    """Give ``ksp`` a new MUMPS factor of its operator with the controls of the failed
    ``factor`` (the inertia's ICNTL 13, the null pivots' 24) and WORKSPACE_GROWTH times
    its relaxation (ICNTL 14), to be set up: PETSc does not factor again with a factor
    whose last factorisation failed (it takes the error for the analysis's), so the
    retry needs a new factor, made after ksp.reset()."""
    kept = {control: factor.getMumpsIcntl(control) for control in (13, 24)}
    relaxation = WORKSPACE_GROWTH * max(factor.getMumpsIcntl(14), 1)
    operator = ksp.getOperators()[0]
    pc = ksp.getPC()
    factorisation = pc.getType()
    ksp.reset()
    ksp.setOperators(operator)
    factor = _mumps_factor(pc, factorisation, ksp.getOptionsPrefix())
    for control, value in kept.items():
        factor.setMumpsIcntl(control, value)
    factor.setMumpsIcntl(14, relaxation)


def solve_columns(ksp, columns, rows=None):
    """x_j = A^-1 b_j for the local arrays ``columns`` (k of them, (n_local,) each) with
    the factored operator A of a set-up inertia_solver or lu_solver, in one MatMatSolve
    (solve_dense: one call into MUMPS's solve phase, whose cost is a fixed part and a
    part per column: docs/performance.md, "Newton steps").
    ``rows``: where A is a submatrix of the columns' layout (analysis/stability.py leaves
    rows out), the local indices of its rows in them; the other rows of x_j are b_j.
    Returns the k arrays x_j (solved_columns). Collective; a failed factorisation gives
    Inf, as a failed KSP solve does (the Newton steps stop at a step that is not
    finite)."""
    return solved_columns(columns, rows, lambda right: solve_dense(ksp, right))


def solved_columns(columns, rows, solve):
    """The k arrays x_j = b_j with their ``rows`` (every row where None) replaced by the
    solutions of the block solve ``solve``, for the local arrays b_j ``columns`` (k of
    them, (n_local,) each): the ``rows`` of each b_j packed as the columns of a new
    Fortran-ordered array B (r, k) of PETSc's scalar type (r = n_local or len(rows)),
    as solve_dense takes it, and ``solve(B)`` -> X (r, k), whose column j is unpacked
    into x_j's rows. The packing of solve_columns and NaturalLU.solve_columns; no
    columns give an empty list without a solve."""
    columns = [np.asarray(column) for column in columns]
    solutions = [column.copy() for column in columns]
    if not columns:
        return solutions
    right = np.empty((columns[0].size if rows is None else len(rows), len(columns)),
                     dtype=PETSc.ScalarType, order="F")
    for j, column in enumerate(columns):
        right[:, j] = column if rows is None else column[rows]
    values = solve(right)
    for j, solution in enumerate(solutions):
        if rows is None:
            solution[:] = values[:, j]
        else:
            solution[rows] = values[:, j]
    return solutions


def solve_dense(ksp, right):
    """X = A^-1 B for the k columns of ``right`` (n, k), in Fortran order (each column
    contiguous, as PETSc's dense matrices hold them), with the factored operator A of
    a set-up inertia_solver or lu_solver (or NaturalLU's KSP, whose factorisations
    that fail are never solved with); on several ranks n is the rank's rows of A. One
    MatMatSolve on dense matrices laid on ``right`` and on the new array X, which it
    returns, (n, k) in Fortran order. No column is copied in Python on the way in or
    out (PETSc copies B into X once, for MUMPS to solve in place): solve_columns copies
    each twice more (into B, out of X), work that a rank's half of a chain pays as the
    whole chain does (docs/performance.md, "Newton steps"). A failed factorisation
    gives Inf. Collective."""
    factor = ksp.getPC().getFactorMatrix()
    solution = np.empty(right.shape, dtype=PETSc.ScalarType, order="F")
    if ksp.getPC().getFactorSolverType() == "mumps" and factor.getMumpsInfog(1) < 0:
        solution[:] = np.inf
        return solution
    comm = ksp.getOperators()[0].getComm()
    matrices = [_dense_on(array, comm) for array in (right, solution)]
    try:
        factor.matSolve(*matrices)
    finally:
        for matrix in matrices:
            matrix.destroy()
    return solution


def solve_sparse_columns(ksp, rows, values):
    """x_j = A^-1 b_j for right-hand sides zero but at the ``rows`` (r,) of the local
    operator, where b_j is values[:, j] (``values`` (r, k)), with the factored operator
    A of a sequential inertia_solver or lu_solver: MUMPS's sparse right-hand sides
    (ICNTL 20, through MatMatSolve of a transposed AIJ), whose forward elimination visits
    only the paths of the elimination tree from those rows to its root, cheaper than a
    dense solve where the rows sit near the root (docs/performance.md, "Newton steps";
    the backward one gives every row). ``rows`` distinct. Returns x, (k, n), C-contiguous
    (the transpose of the solve's own Fortran-ordered array, not a copy). A failed
    factorisation gives Inf."""
    factor = ksp.getPC().getFactorMatrix()
    operator = ksp.getOperators()[0]
    comm, n, k = operator.getComm(), operator.getSize()[0], values.shape[1]
    if factor.getMumpsInfog(1) < 0:
        return np.full((k, n), np.inf)
    order = np.argsort(rows)
    solution = np.empty((n, k), dtype=PETSc.ScalarType, order="F")
    transposed = PETSc.Mat().createAIJ((k, n), nnz=len(rows), comm=comm)
    right = unknown = None
    try:
        transposed.setValuesCSR(np.arange(k + 1, dtype=PETSc.IntType) * len(rows),
                                np.tile(np.asarray(rows, dtype=PETSc.IntType)[order], k),
                                np.ascontiguousarray(values[order].T))
        transposed.assemble()
        right = PETSc.Mat().createTranspose(transposed)
        unknown = _dense_on(solution)
        factor.matSolve(right, unknown)
        return solution.T
    finally:
        for obj in (right, transposed, unknown):
            if obj is not None:
                obj.destroy()


def _dense_on(array, comm=PETSc.COMM_SELF):
    """A dense Mat on ``comm`` whose values are the (n, k) ``array`` itself (petsc4py
    keeps a reference to it), assembled: on several ranks each rank's n rows, the k
    columns whole on every rank (PETSc's MPI dense storage). The array must be
    writeable, Fortran-ordered and of PETSc's scalar type: petsc4py would otherwise
    copy it without a word, and a solve into the Mat would leave the array as it was.
    Collective."""
    if not (array.flags.f_contiguous and array.flags.writeable
            and array.dtype == PETSc.ScalarType):
        raise ValueError("a dense Mat laid on an array needs a writeable Fortran-ordered "
                         f"{np.dtype(PETSc.ScalarType)} array")
    rows, k = array.shape
    matrix = PETSc.Mat().createDense(((rows, PETSc.DECIDE), (PETSc.DECIDE, k)), array=array,
                                     comm=comm)
    matrix.assemble()
    return matrix


def solve_vecs(factor, vecs, rows=None):
    """``factor.solve_columns`` (a direct_factor's) for the Vecs ``vecs``: new Vecs
    x_j = A^-1 b_j (the caller's to destroy). Collective."""
    arrays = factor.solve_columns([vec.getArray(readonly=True) for vec in vecs], rows)
    solutions = []
    for vec, array in zip(vecs, arrays):
        solution = vec.duplicate()
        solution.getArray()[:] = array
        solutions.append(solution)
    return solutions


# The package of the Newton Jacobian's LU on one rank and of each rank's interior on
# several (-rod_newton_lu): PETSc's own in
# the natural order (NaturalLU), or MUMPS's (MumpsFactor). The LDL^T of the second
# variation is MUMPS's: its null pivots (a section's free roll) are detected as null,
# which the callers rely on (docs/performance.md, "Newton steps").
LU_PACKAGE = "lu"
LU_PACKAGES = ("petsc", "mumps")
DEFAULT_LU_PACKAGE = "petsc"
# NaturalLU accepts its factorisation where the normwise backward error of its check
# solves is at most this (1e-15 to 6e-15 on the 18 000-element riser's Jacobians;
# docs/performance.md, "Newton steps"): growth of the elimination shows here ...
BACKWARD_ERROR_LIMIT = 1e-12
# ... and where their forward error is at most this (1.3e-5 to 2.2e-5 there, the
# Jacobian ill-conditioned: MUMPS's 2e-6): a null vector whose pivot the elimination
# keeps at the round-off makes it large (2e-3 to 24 in the second variation of a held
# line with a free roll, docs/performance.md).
FORWARD_ERROR_LIMIT = 1e-3
# The check's solutions z(i) at the rows i: no zero and no pattern the factors' errors
# could cancel on; two, as one alone can meet a kept null pivot with a small error.
GOLDEN = 0.5 * (1 + 5**0.5)
CHECK_SOLUTIONS = (lambda i: np.sin(GOLDEN * (i + 1.0) ** 1.5),
                   lambda i: np.cos(GOLDEN * (i + 1.0)))


def lu_package(prefix):
    """The LU package ``-<prefix>lu`` names (one of LU_PACKAGES; default
    DEFAULT_LU_PACKAGE); RodInputError for another (cli/options.check_factor_switches
    asks before any work)."""
    name = f"{prefix}{LU_PACKAGE}"
    package = PETSc.Options().getString(name, DEFAULT_LU_PACKAGE)
    if package not in LU_PACKAGES:
        raise RodInputError(
            f"-{name} {package}: expected {' or '.join(LU_PACKAGES)} (the package of the "
            "Newton steps' LU: PETSc's own in the natural order, or MUMPS's)")
    return package


class NaturalLU:
    """PETSc's own LU of a sequential ``operator`` in the natural order (its KSP and PC
    are not options: the check needs this factorisation; MUMPS's under ``prefix``
    where it hands over): the Newton Jacobian on one rank (analysis/jacobian.py) and
    each rank's interior of it on several (chain_factor.py), a band of nodes whose
    elimination in its own order fills only the band. On the
    18 000-element riser its first factorisation takes 69 ms and the next 20 ms,
    MUMPS's 277 and 156 ms, a solve 3 ms against 24 (docs/performance.md, "Newton
    steps").

    It does not pivot. Each set_up checks the factors by two solves, A x = b with
    b = A z for the CHECK_SOLUTIONS z: their normwise backward error

        eta = |A x - b|_inf / (|A|_inf |x|_inf + |b|_inf)

    (Rigal and Gaches), which a stable factorisation keeps near the round-off, and
    their forward error |x - z|_inf / |z|_inf, which a null vector whose pivot the
    elimination kept at the round-off makes large. (Row by row, against each row's
    largest entry, the backward errors are larger than MUMPS's in the rows of small
    entries, the multipliers' of the positions' chains: 1e-9 against 1e-13 on that
    riser; the steps, which correct their own errors, and the results were the same.)
    A zero pivot (PETSc's test, relative to its row's entries) gives Inf, and a
    diagonal entry not stored fails the symbolic factorisation. Where either error is
    not finite or above its limit the operator is factored by MumpsFactor (threshold
    pivoting, null pivots detected), for the rest of this object's life
    (``fell_back``). The interface direct_factor's factorisations share (set_up,
    solve_columns, destroy; ``substructured`` False). Owns its KSP or its
    MumpsFactor."""

    substructured = False

    def __init__(self, operator, block, prefix):
        self.block, self.prefix = block, prefix
        self.mumps = None
        self.ksp = PETSc.KSP().create(comm=operator.getComm())
        self.ksp.setOperators(operator)
        self.ksp.setType(PETSc.KSP.Type.PREONLY)
        self.ksp.getPC().setType(PETSc.PC.Type.LU)
        self.ksp.getPC().setFactorSolverType("petsc")
        self.ksp.getPC().setFactorOrdering(PETSc.Mat.OrderingType.NATURAL)

    @property
    def fell_back(self):
        """Whether MUMPS's LU has taken over (a set_up's check failed)."""
        return self.mumps is not None

    def set_up(self, operator):
        """Factor ``operator`` (the symbolic factorisation kept while its pattern
        stays), by MUMPS from the first factorisation that fails the check."""
        if self.mumps is None:
            self.ksp.setOperators(operator)
            try:
                self.ksp.setUp()
                factored = True
            except PETSc.Error:         # a diagonal entry not stored: no pivot in order
                factored = False
            if factored:
                backward, forward = self.errors(operator)
                if backward <= BACKWARD_ERROR_LIMIT and forward <= FORWARD_ERROR_LIMIT:
                    return
            self.ksp.destroy()
            self.ksp = None
            self.mumps = MumpsFactor(operator, PETSc.PC.Type.LU, self.block, self.prefix)
        self.mumps.set_up(operator)

    def errors(self, operator):
        """(eta, the forward error) of the solves of A x = A z for the CHECK_SOLUTIONS z
        with the factors just made, the largest of each; Inf where a solve is not
        finite (a failed factorisation solves to Inf). The solves are the factor's own,
        not the KSP's, which would read the options database's -ksp_*."""
        exact, right, solution, residual = (operator.createVecRight(),
                                            operator.createVecLeft(),
                                            operator.createVecRight(),
                                            operator.createVecLeft())
        infinity = PETSc.NormType.INFINITY
        norm = operator.norm(infinity)
        factor = self.ksp.getPC().getFactorMatrix()
        try:
            start, end = exact.getOwnershipRange()
            backward, forward = [], []
            for solution_of in CHECK_SOLUTIONS:
                exact.getArray()[:] = solution_of(np.arange(start, end))
                operator.mult(exact, right)
                factor.solve(right, solution)
                operator.mult(solution, residual)
                residual.axpy(-1.0, right)
                backward.append(residual.norm(infinity)
                                / (norm * solution.norm(infinity) + right.norm(infinity)))
                residual.waxpy(-1.0, exact, solution)
                forward.append(residual.norm(infinity) / exact.norm(infinity))
            found = (np.max(backward), np.max(forward))       # NaN kept
            return tuple(value if np.isfinite(value) else np.inf for value in found)
        finally:
            for vec in (exact, right, solution, residual):
                vec.destroy()

    def null_pivot(self):
        """Whether the factorisation has a null pivot: MUMPS's detection, where it has
        taken over (a kept null pivot fails this one's check)."""
        return self.mumps is not None and self.mumps.null_pivot()

    def failed(self):
        """Whether the last factorisation failed (MUMPS's, where it has taken over: this
        one's failures hand over)."""
        return self.mumps is not None and self.mumps.failed()

    def solve(self, right):
        """X = A^-1 B for the Fortran-ordered (n, k) ``right``, a new (n, k) array in
        Fortran order, refined once (solve_columns)."""
        if self.mumps is not None:
            return self.mumps.solve(right)
        return self._refined_solve(right)

    def solve_sparse(self, rows, values):
        """As MumpsFactor.solve_sparse (x (k, n), C-contiguous), by a dense solve of the
        right-hand sides made whole: an elimination in the natural order visits every
        row whatever the right-hand side."""
        if self.mumps is not None:
            return self.mumps.solve_sparse(rows, values)
        n = self.ksp.getOperators()[0].getSize()[0]
        right = np.zeros((n, values.shape[1]), dtype=PETSc.ScalarType, order="F")
        right[rows] = values
        return self._refined_solve(right).T

    def solve_columns(self, columns, rows=None):
        """As ksp.solve_columns, each solve refined once: x += F^-1 (b - A x), with the
        residual in the working precision, which makes the solves of an elimination
        without pivoting as accurate as a pivoting one's (Skeel's one step of
        iterative refinement): without it the row-by-row errors above let the chain
        with seabed friction of tests/system/test_friction_penalty_advice_cli.py take
        555 iterations against MUMPS's 392 and stop 1.2e-6 m from MUMPS's answer.
        MUMPS's unrefined solves where it has taken over (``solve``)."""
        return solved_columns(columns, rows, self.solve)

    def _refined_solve(self, right):
        """X = A^-1 B for the Fortran-ordered (n, k) ``right`` B (solve_dense's), refined
        once as solve_columns says."""
        values = solve_dense(self.ksp, right)
        known = _dense_on(values)
        product = self.ksp.getOperators()[0].matMult(known)
        try:
            values += solve_dense(self.ksp, np.asfortranarray(right - product.getDenseArray()))
        finally:
            known.destroy()
            product.destroy()
        return values

    def destroy(self):
        for obj in (self.ksp, self.mumps):
            if obj is not None:
                obj.destroy()


# Where the Newton steps' systems are factored by substructuring on several ranks
# (chain_factor.py) unless -<prefix>substructuring 0: MUMPS on all ranks factors these
# chains no faster than on one and solves them slower (docs/performance.md).
SUBSTRUCTURING = "substructuring"


def mumps_solver(comm, operator, kind, prefix):
    """The KSP of MUMPS's factorisation ``kind`` of ``operator`` on ``comm``: lu_solver
    for PETSc.PC.Type.LU, inertia_solver's for CHOLESKY, options under ``prefix``."""
    if kind == PETSc.PC.Type.LU:
        return lu_solver(comm, operator, prefix)
    return inertia_solver(comm, operator, prefix)[0]


class MumpsFactor:
    """MUMPS's factorisation ``kind`` (PETSc.PC.Type.LU: lu_solver; CHOLESKY:
    inertia_solver) of an operator on its ranks, under ``prefix``, with ``block``
    unknowns a node (set_up_mumps); the interface direct_factor's factorisations share
    (set_up, solve_columns, negative_pivots, destroy; ``substructured`` False). Owns
    its KSP."""

    substructured = False

    def __init__(self, operator, kind, block, prefix):
        self.ksp = mumps_solver(operator.getComm(), operator, kind, prefix)
        self.block = block

    def set_up(self, operator):
        """Factor ``operator`` (the symbolic factorisation kept while its pattern
        stays). Collective."""
        self.ksp.setOperators(operator)
        set_up_mumps(self.ksp, self.block)

    def solve_columns(self, columns, rows=None):
        return solve_columns(self.ksp, columns, rows)

    def null_pivot(self):
        """Whether MUMPS found a null pivot in the last factorisation (INFOG(28),
        ICNTL 24)."""
        return self.ksp.getPC().getFactorMatrix().getMumpsInfog(28) > 0

    def failed(self):
        """Whether the last factorisation failed (INFOG(1) < 0)."""
        return self.ksp.getPC().getFactorMatrix().getMumpsInfog(1) < 0

    def solve(self, right):
        """solve_dense with this factorisation."""
        return solve_dense(self.ksp, right)

    def solve_sparse(self, rows, values):
        """solve_sparse_columns with this (sequential) factorisation."""
        return solve_sparse_columns(self.ksp, rows, values)

    def negative_pivots(self):
        """Negative eigenvalues of the last factorised (symmetric) operator (ICNTL 13)."""
        return int(self.ksp.getPC().getFactorMatrix().getInertia()[0])

    def destroy(self):
        self.ksp.destroy()


class SubstructuredFactor:
    """A ChainFactor while it applies, MumpsFactor from the first set_up where it does
    not (a pattern grown into no chain, a singular interior: chain_factor's
    NotAChainError), for the rest of its life; the interface direct_factor's
    factorisations share. ``substructured`` says which. The interiors of an LU are
    NaturalLU's unless -<prefix>lu mumps (``natural``), in their natural order; else
    MUMPS's. Owns the one it holds."""

    def __init__(self, operator, kind, block, prefix):
        self.kind, self.block, self.prefix = kind, block, prefix
        self.natural = kind == PETSc.PC.Type.LU and lu_package(prefix) == DEFAULT_LU_PACKAGE
        self.factor = ChainFactor(operator, kind, block, self._interior_factor,
                                  reorder=not self.natural)

    def _interior_factor(self, interior):
        """The factorisation of a rank's (sequential) ``interior``: an LU as on one rank
        (NaturalLU unless -<prefix>lu mumps), an LDL^T by MUMPS."""
        if self.natural:
            return NaturalLU(interior, self.block, self.prefix)
        return MumpsFactor(interior, self.kind, self.block, self.prefix)

    @property
    def substructured(self):
        return isinstance(self.factor, ChainFactor)

    def set_up(self, operator):
        if self.substructured:
            try:
                self.factor.set_up(operator)
                return
            except substructuring.NotAChainError:
                self.factor.destroy()
                self.factor = MumpsFactor(operator, self.kind, self.block, self.prefix)
        self.factor.set_up(operator)

    def solve_columns(self, columns, rows=None):
        return self.factor.solve_columns(columns, rows)

    def negative_pivots(self):
        return self.factor.negative_pivots()

    def destroy(self):
        self.factor.destroy()


def direct_factor(operator, kind, block, prefix):
    """The factorisation ``kind`` (LU or CHOLESKY) of the Newton steps' ``operator``, a
    chain of nodes of ``block`` unknowns (analysis/jacobian.py, analysis/second_variation.py):
    on several ranks by substructuring (SubstructuredFactor: each rank its interior as
    on one rank, the interface's Schur complement on every rank, MUMPS on all ranks
    where that does not apply) unless -<prefix>substructuring 0 or the operator is no
    chain; on one rank the LU by NaturalLU unless -<prefix>lu mumps; else MumpsFactor.
    Collective."""
    comm = operator.getComm()
    # the package is read on any number of ranks: given, it is used
    if (kind == PETSc.PC.Type.LU and lu_package(prefix) == DEFAULT_LU_PACKAGE
            and comm.getSize() == 1):
        return NaturalLU(operator, block, prefix)
    chosen = PETSc.Options().getBool(f"{prefix}{SUBSTRUCTURING}", True)
    if comm.getSize() > 1 and chosen:
        try:
            return SubstructuredFactor(operator, kind, block, prefix)
        except substructuring.NotAChainError:
            pass
    return MumpsFactor(operator, kind, block, prefix)


def _mumps(comm, operator, factorisation, prefix=None):
    """(ksp, factor): preonly + MUMPS's ``factorisation`` of ``operator``, null pivots
    detected instead of fatal (ICNTL 24); options under ``prefix``, the factor's
    (-<prefix>mat_mumps_icntl_*) included."""
    ksp = PETSc.KSP().create(comm=comm)
    if prefix is not None:
        ksp.setOptionsPrefix(prefix)
    ksp.setOperators(operator)
    ksp.setType(PETSc.KSP.Type.PREONLY)
    factor = _mumps_factor(ksp.getPC(), factorisation, prefix)
    factor.setMumpsIcntl(24, 1)
    return ksp, factor


def _mumps_factor(pc, factorisation, prefix):
    """MUMPS's factor matrix of ``factorisation`` for ``pc`` (its operator set), options
    under ``prefix``, not yet set up."""
    pc.setType(factorisation)
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    factor = pc.getFactorMatrix()
    if prefix is not None:
        factor.setOptionsPrefix(prefix)     # MatGetFactor gave it none (PETSc 3.18)
    return factor


def check_solved(ksp, name):
    """Raise RodDivergedError when the last solve of ``ksp`` failed; ``name`` is the
    solver's options prefix, as the message gives it."""
    reason = ksp.getConvergedReason()
    if reason < 0:
        raise RodDivergedError(f"linear solver -{name} failed: {KSP_REASONS.get(reason, reason)}")
