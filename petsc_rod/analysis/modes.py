"""The natural modes of a line about a converged static state: K phi = omega^2 M phi
(docs/modes.md, docs/method.md §10-§12), undamped (the drag is left out).

K is the second variation H of the stability test (analysis/second_variation.py: every
term's stiffness at the state, the seabed's springs, the stretch, the flex joints, the
load held fixed), with the chains of all three components of the node positions
(analysis/positions.py) made unknowns: the displacement of a vertex, u^c, is tied to the
rotations and stretches by u^c_e+1 - u^c_e - h_e SIMPSON.s^c_e = 0 (multiplier nu^c_e),
so that the translational kinetic energy is a banded mass on (u, omega) instead of a
dense one on the rotations alone. K is then the KKT matrix

    [ H   C^T ]          [ M  0 ]
    [ C   0   ],   M  =  [ 0  0 ]   (analysis/mass.py: lumped at the P2 nodes; a
                                      midpoint's displacement u_e + h_e HALF.s_e),

the held end's u pinned (u = 0), and with both ends held the other end's too: that
pin is the chord constraint of the stability test. The multipliers nu and the
stretches carry no mass; their eigenvalues are infinite and shift-invert maps them to
0 (the Newton Jacobian's resultants of a follower load are left out). M is positive
semi-definite and the pencil (K - sigma M) nonsingular at a stable state, so the
problem is SLEPc's GHEP with shift-invert about sigma = SHIFT (a small negative
omega^2) on the LDL^T of K - sigma M (global_step/ksp.direct_factor, the stability
test's: MUMPS on one rank, the chain's substructuring on several), whose inertia counts, less the n_elements negative eigenvalues per
component of the chains, the eigenvalues below sigma: a state with any is unstable,
and its modes are refused (never reported as vibrations). Where no node is clamped,
the sections have no polar inertia and the roll is free (K1 = K2), the roll is held
(SecondVariation.hold_roll): it has neither stiffness nor mass.

Options: the EPS reads -rod_modes_eps_* (and -rod_modes_st_*), the factorisation
-rod_modes_st_mat_mumps_icntl_* and -rod_modes_st_substructuring.
"""

import contextlib
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.mass import MassSettings, line_inertia, nodal_mass
from petsc_rod.analysis.second_variation import SecondVariation, unit
from petsc_rod.errors import RodDivergedError, petsc_message
from petsc_rod.global_step.ksp import direct_factor
from petsc_rod.scenes.boundary import is_held

PREFIX = "rod_modes_"
# The phases of solve_modes in -log_view: K and M, the factorisation of K - sigma M (and
# its inertia), the eigensolver, the shapes.
EVENTS = {name: PETSc.Log.Event(f"rod_modes_{name}")
          for name in ("operators", "factor", "eps", "shapes")}
STAGE = PETSc.Log.Stage("rod_modes")
# sigma: omega^2 of the shift, rad^2/s^2, just below 0 so that a free rigid mode
# (omega = 0) leaves K - sigma M nonsingular: the frequency 1e-4 Hz squared.
SHIFT = -(2 * np.pi * 1e-4) ** 2
# the Krylov subspace beyond the modes asked for (SLEPc's ncv = nev + max(SUBSPACE,
# nev / 2), -rod_modes_eps_ncv overrides it): SLEPc's own for few modes, fewer solves
# than its 2 nev for many; a smaller one can miss a copy of a repeated frequency (a
# straight line's pairs, which the iteration finds through round-off)
SUBSPACE = 15
# the classes of a mode by the share of its kinetic energy; "mixed" below DOMINANT
CLASSES = ("in-plane", "out-of-plane", "axial", "torsional")
DOMINANT = 0.6
# a mode below this frequency (Hz; a period of over 1000 s) is "rigid": a line's
# vibrations are faster, and the free roll of sections with polar inertia between pins
# has omega = 0 to round-off
RIGID = 1e-3
# a pair is reported only with its relative residual below RESIDUAL (_pairs)
RESIDUAL = 1e-3
# a band is cut where its ends (omega^2) are more than SLICE_SPAN apart, to at most
# SLICE_DEPTH halvings (_slice)
SLICE_SPAN = 1e4
SLICE_DEPTH = 12
# omega^2 far above any discretisation's eigenvalue (1e30 Hz squared): the inertia of
# K - COUNT_SHIFT M counts every finite eigenvalue (modes_count)
COUNT_SHIFT = (2 * np.pi * 1e30) ** 2
# the pairs a sub-band's solve asks for beyond its count: the eigensolver stops once it
# has as many as asked, and a free rigid mode of little mass can converge after the
# nearest vibration (those outside the sub-band are left out)
EXTRA = 4


def symmetrised_text(symmetrised):
    """The words of ``symmetrised`` (count, ratio) of ModalOperators: '' where K is the
    terms' whole derivative, else where and how much K is their symmetric part only."""
    count, ratio = symmetrised
    if not count:
        return ""
    return (f"K takes the symmetric part of the seabed contact's stiffness at {count} "
            f"grounded node{'s' if count != 1 else ''} within delta/2 of a seabed profile's "
            f"row or grid line, or in a grid cell that twists (its antisymmetric part up "
            f"to {ratio:.3g} of it there: the lagged push turns over delta about a row, "
            "and with the penetration in a twisted cell, and has no energy; docs/riser.md "
            "§3a), so the modes are approximate there")


class ModesRefused(Exception):
    """The static state has eigenvalues of K - omega^2 M below 0: unstable, no modes;
    ``symmetrised`` as Modes'."""

    def __init__(self, negative, symmetrised=(0, 0.0)):
        note = symmetrised_text(symmetrised)
        super().__init__(f"the static state is unstable ({negative} negative eigenvalue"
                         f"{'s' if negative != 1 else ''} of K - omega^2 M): no vibration "
                         "modes about it" + (f" ({note})" if note else ""))
        self.negative = negative
        self.symmetrised = symmetrised


class ModesFailed(RodDivergedError):
    """PETSc or SLEPc failed in the modes' eigensolver (its set-up or its solve: an
    -rod_modes_eps_* or -rod_modes_st_* setting that check_options passes but EPSSetUp
    or EPSSolve refuses, the spectral transformation's solve): exit 4, no result file.
    The message is PETSc's, read where the error was raised (petsc4py keeps one
    traceback for all errors, which the EPS's destroy after it rewrites)."""

    def __init__(self, message):
        """A ModesFailed whose message is ``message`` as it is (of_error, of_line)."""
        super().__init__(message)

    @classmethod
    def of_error(cls, error):
        """From the PETSc.Error raised in the eigensolver (solve_modes)."""
        return cls(f"the modes' eigensolver (SLEPc) failed: {petsc_message(error)}; "
                   f"check the -{PREFIX}eps_* and -{PREFIX}st_* options")

    @classmethod
    def of_line(cls, name, text):
        """The failure of a system's line ``name``, from ``text``, the message of the
        ModesFailed its eigensolver raised (str(): the lines' share carries it as text
        to the ranks without the line, api/system_run.line_modes): "line NAME: TEXT"."""
        return cls(f"line {name}: {text}")

    def __reduce__(self):
        """Pickled (an MPI share of it) as its message."""
        return type(self), (str(self),)


@contextlib.contextmanager
def destroyed():
    """``with destroyed() as made:`` what is appended to ``made`` (PETSc objects, or
    ours with a destroy()) destroyed in reverse order when the block ends, every one
    even where another's destroy fails. Where the block raised, its exception goes on
    and a destroy's failure is dropped: an EPS whose solve failed inside SLEPc cannot be
    destroyed (its DS's dense matrix is left checked out, "Need to call
    MatDenseRestoreSubMatrix() first"), and that failure would replace the solve's and
    skip the destroys after it (FactorKSP's among them). Where the block succeeded, the
    first destroy's failure is raised once every one was tried."""
    made = []
    try:
        yield made
    except BaseException:
        _destroy(made, raising=False)
        raise
    _destroy(made, raising=True)


def _destroy(made, raising):
    """destroy() each of ``made``, last first; the first failure raised after all of
    them where ``raising``."""
    failure = None
    for thing in reversed(made):
        try:
            thing.destroy()
        except Exception as error:          # noqa: BLE001 (the others are destroyed too)
            failure = failure or error
    if raising and failure is not None:
        raise failure


@dataclass
class Modes:
    """The modes found, lowest first (n modes): ``omega2`` (rad^2/s^2), frequencies
    (Hz), periods (s), ``modal_mass`` (kg, of the shape normalised to a largest offset
    of 1 m), ``shares`` (n, 4) of the kinetic energy in CLASSES, ``labels``; per owned
    vertex ``S`` (n_v,), ``offset`` (n, n_v, 3) m and ``rotation`` (n, n_v, 3) rad; per
    owned element midpoint ``S_mid`` and ``curvature`` (n, n_e, 3) 1/m, the change of
    (u1, u2, u3) = (d1, d2, d3) . omega'."""

    omega2: np.ndarray
    modal_mass: np.ndarray
    shares: np.ndarray
    S: np.ndarray
    offset: np.ndarray
    rotation: np.ndarray
    S_mid: np.ndarray
    curvature: np.ndarray
    converged: int = 0
    labels: list = field(default_factory=list)
    # a band's (fmin, fmax, the count of its modes by the inertia), Hz; None: the lowest
    band: tuple = None
    # the modes asked for without a band (fewer where fewer converged and verified)
    asked: int = 0
    # the band's sub-bands (fmin, fmax), Hz, whose pairs did not all verify or whose
    # inertia decreased (their modes left out)
    slices: list = field(default_factory=list)
    # (count, ratio): the grounded nodes where K holds only the symmetric part of the
    # seabed's contact stiffness (a profile's rows; Term.symmetrised_nodes) and the
    # largest |B - B^T| / |B| there; (0, 0.0): K is exact
    symmetrised: tuple = (0, 0.0)

    @property
    def frequencies(self):
        return np.sqrt(np.maximum(self.omega2, 0.0)) / (2 * np.pi)

    @property
    def periods(self):
        f = self.frequencies
        return np.where(f > 0, 1 / np.where(f > 0, f, 1.0), np.inf)


def classify(shares, frequencies):
    """The class of each mode from its shares (n, 4): 'rigid' below RIGID Hz, else the
    largest share's if at least DOMINANT, else 'mixed'."""
    largest = np.argmax(shares, axis=1)
    return ["rigid" if frequencies[i] < RIGID else
            CLASSES[k] if shares[i, k] >= DOMINANT else "mixed"
            for i, k in enumerate(largest)]


def submerged(problem):
    """Whether each owned P2 node is at or below the sea surface (n,): the scene's
    sea_surface, else the higher held end's height (quantities/pressures.py's); all of
    them where no end is held."""
    scene = problem.scene
    heights = [state.position[2] for state in (problem.start_state, problem.end_state)
               if is_held(state)]
    surface = scene.sea_surface if scene.sea_surface is not None else \
        (max(heights) if heights else np.inf)
    return problem.state.node_positions()[:, 2] <= surface + 1e-9 * scene.length


class ModalOperators(SecondVariation):
    """K and M of the module docstring at the problem's state: SecondVariation with the
    chains of x, y and z (without the Newton Jacobian's resultants and pattern), the other end's displacement pinned where both are held, and
    the mass ``mass_matrix``. Collective; ``destroy()`` frees every PETSc object."""

    def __init__(self, problem, settings=MassSettings()):
        self.settings = settings
        super().__init__(problem, positions=(0, 1, 2), newton=False)
        tangents = problem.state.tau[:, 2]
        self.translation, self.rotation = nodal_mass(problem.scene, problem.mesh, tangents,
                                                     settings, submerged(problem))
        polar = line_inertia(problem.scene, problem.mesh.node_S(), settings)[2]
        mesh = problem.mesh
        if mesh.global_sum(int((~problem.free_nodes).sum())) == 0 \
                and mesh.global_max(float(np.abs(polar).max(initial=0.0))) == 0.0:
            self.hold_roll(tangents)
        self.mass_matrix = self._mass_matrix()
        found = np.array([term.symmetrised_nodes(problem.state) for term in problem.terms]
                         or [(0, 0.0)], dtype=float)
        self.symmetrised = (int(mesh.global_sum(found[:, 0].sum())),
                            float(mesh.global_max(found[:, 1].max())))

    def _clamped_rows(self):
        rows = super()._clamped_rows()
        mesh, problem = self.problem.mesh, self.problem
        if not (is_held(problem.start_state) and is_held(problem.end_state)) \
                or not mesh.on_upper_boundary:
            return rows
        slots = np.array(list(self.position_slot.values()))
        far = self.first_row + self.block * (mesh.n_local_nodes - 1) + slots
        return np.union1d(rows, far).astype(PETSc.IntType)

    def _mass_matrix(self):
        """M (module docstring) on the layout of K: the translation blocks through the
        chains' vertex and midpoint rows (position_blocks), the rotation blocks on the
        rotations; 0 on the held rows."""
        mesh, B = self.problem.mesh, self.block
        n_local = B * mesh.n_local_nodes
        mass = PETSc.Mat().createAIJ(((n_local, None), (n_local, None)),
                                     nnz=(5 * B, 2 * B), comm=self.comm)
        mass.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        for rows, blocks in self._translation_blocks():
            rows = rows.astype(PETSc.IntType)
            mass.setValuesRCV(rows, rows, blocks, addv=PETSc.InsertMode.ADD_VALUES)
        rows = (self.first_row + B * np.arange(mesh.n_local_nodes)[:, None]
                + np.arange(3)).astype(PETSc.IntType)
        if rows.size:
            mass.setValuesRCV(rows, rows, self.rotation, addv=PETSc.InsertMode.ADD_VALUES)
        mass.assemble()
        mass.zeroRowsColumns(self.held_rows, diag=0.0)
        mass.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        return mass

    def _add_chains(self, d):
        """The chains (SecondVariation's), and M's translation pattern as zeros: K's
        pattern then holds M's, so that K - sigma M is an axpy on K's pattern."""
        super()._add_chains(d)
        for rows in self._translation_rows():
            self._add_blocks(rows, rows, np.zeros(rows.shape + rows.shape[1:]))

    def _translation_rows(self):
        """The rows of the translation blocks (_translation_blocks): the vertices' (u^x,
        u^y, u^z) (n_v, 3) and, per element, (u^x_e, u^y_e, u^z_e, the element's
        unknowns) (n_e, 3 + width); the empty ones left out."""
        mesh, B = self.problem.mesh, self.block
        vertices = self.first_row + B * np.arange(0, mesh.n_local_nodes, 2)
        slots = np.array([self.position_slot[c] for c in (0, 1, 2)])
        rows = [vertices[:, None] + slots]
        if mesh.n_local_elements:
            rows.append(np.concatenate([self._midpoint_index[c][:, :1] for c in (0, 1, 2)]
                                       + [self._midpoint_index[0][:, 1:]], axis=1))
        return [r for r in rows if r.size]

    def _translation_blocks(self):
        """The translation masses T_n (n, 3, 3) as (rows, blocks): at a vertex on its
        (u^x, u^y, u^z); at a midpoint, whose position component c is the row
        R_c = (1, h_e HALF.s^c_e) on (u^c_e, the element's unknowns), sum_ab T_ab R_a R_b^T
        on (u^x_e, u^y_e, u^z_e, the element's unknowns) in one block per element
        (position_blocks' entries, added at once)."""
        mesh = self.problem.mesh
        T = self.translation
        rows = self._translation_rows()
        triples = [(rows[0], T[0::2])] if T.shape[0] else []
        ne = mesh.n_local_elements
        if ne:
            width = self._midpoint_rows[0].shape[1] - 1           # the element's unknowns
            R = np.zeros((3, ne, 3 + width))
            for c in (0, 1, 2):
                R[c, :, c] = self._midpoint_rows[c][:, 0]
                R[c, :, 3:] = self._midpoint_rows[c][:, 1:]
            middle = T[1:2 * ne:2]                                   # (ne, 3, 3)
            R = R.transpose(1, 0, 2)                                 # (ne, 3, 3 + width)
            # R^T T R per element as two batched products (a three-operand einsum
            # does not pair them)
            blocks = np.matmul(R.transpose(0, 2, 1), np.matmul(middle, R))
            triples.append((rows[-1], blocks))
        return [t for t in triples if t[0].size]

    def destroy(self):
        self.mass_matrix.destroy()
        super().destroy()


class FactorPC:
    """A python PC that solves with a factorisation of global_step/ksp.direct_factor
    (MUMPS's LDL^T on one rank, the chain's substructuring on several): the spectral
    transformation's solves with the factor whose inertia was counted."""

    def __init__(self, factor):
        self.factor = factor

    def apply(self, pc, x, y):
        y.getArray()[:] = self.factor.solve_columns([x.getArray(readonly=True)])[0]


class FactorKSP:
    """The spectral transformation's KSP ``ksp``: preonly + FactorPC(factor) for
    ``operator``, options under PREFIX + 'st_'. destroy() turns its PC into PCNONE
    first, which drops the python context while the interpreter runs: a reference to
    the PC that outlives the solve (the one PETSc hands FactorPC.apply, kept by the
    traceback of an error raised in the solve) is destroyed by PETSc's garbage
    collection in PetscFinalize, after the interpreter has ended, where a python PC's
    destroy would call it: a segmentation fault."""

    def __init__(self, operator, factor):
        self.ksp = PETSc.KSP().create(comm=operator.getComm())
        try:
            self.ksp.setOptionsPrefix(PREFIX + "st_")
            self.ksp.setOperators(operator)
            self.ksp.setType(PETSc.KSP.Type.PREONLY)
            pc = self.ksp.getPC()
            pc.setType(PETSc.PC.Type.PYTHON)
            pc.setPythonContext(FactorPC(factor))
        except BaseException:
            self.destroy()
            raise

    def destroy(self):
        """Free the KSP and its PC, the PC made PCNONE first; a second call does
        nothing."""
        if self.ksp is None:
            return
        ksp, self.ksp = self.ksp, None
        pc = ksp.getPC()
        try:
            pc.setType(PETSc.PC.Type.NONE)
        finally:
            try:
                pc.destroy()
            finally:
                ksp.destroy()


def start_slepc():
    """SLEPc, initialised on first use (slepc4py's import): every rank of a run must make
    this call before any rank's first modes, even where its own lines need none (their
    modes refused or failed first, or none of the run's lines on that rank). SLEPc
    initialised on some ranks only leaves the process hanging at its exit: PETSc's
    clean-up of deferred destructions at finalisation is collective on
    PETSC_COMM_WORLD, and only the ranks that started SLEPc enter it. Returns the
    SLEPc module. Collective in that sense."""
    from slepc4py import SLEPc
    return SLEPc


def check_options(comm):
    """Set up, from the options database, an EPS with the modes' prefix (its ST a shift
    and invert, as solve_modes's) and destroy it: a PETSc.Error for a bad
    -rod_modes_eps_* or -rod_modes_st_* option, found before any work. Collective."""
    SLEPc = start_slepc()
    eps = SLEPc.EPS().create(comm=comm)
    try:
        eps.getST().setType(SLEPc.ST.Type.SINVERT)
        eps.setOptionsPrefix(PREFIX)
        eps.setFromOptions()
    finally:
        eps.destroy()


def modes_count(problem, settings=MassSettings()):
    """How many modes the problem's discretisation has: the finite eigenvalues of
    K phi = omega^2 M phi (the rank of M on the constrained unknowns; the massless
    unknowns' are infinite), counted by the inertia of K - sigma M at sigma =
    COUNT_SHIFT (_below: as -rod_modes_range 0,1e30 counts them). At the problem's
    state, any (the count is M's rank, which the state leaves; a start that is not
    stable counts its negative eigenvalues too). One factorisation. Collective."""
    STAGE.push()
    try:
        with destroyed() as made:
            operators = ModalOperators(problem, settings)
            made.append(operators)
            shifted = operators.matrix.duplicate(copy=True)
            made.append(shifted)
            shifted.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            return _below(operators, shifted, COUNT_SHIFT)
    finally:
        STAGE.pop()


def solve_modes(problem, count, settings=MassSettings(), band=None):
    """The ``count`` lowest modes (Modes) of the problem's converged state, or
    ModesRefused where the state is unstable. With ``band`` (fmin, fmax), Hz, every
    mode in it instead (``count`` unused): the inertia of K - sigma M at both ends
    counts them (Sylvester: the eigenvalues below sigma), and the band is sliced into
    sub-bands (_slice), each solved about its middle omega^2 for the many its inertia
    counts (every other eigenvalue is farther from the middle); ``Modes.slices`` names
    those left short. Every pair is verified (_pairs). Collective."""
    SLEPc = start_slepc()
    if band is None and count < 1:
        raise ValueError(f"solve_modes needs a positive number of modes, got {count}")
    STAGE.push()
    try:
        return _solve_modes(problem, count, settings, SLEPc, band)
    finally:
        STAGE.pop()


def band_shifts(band):
    """(sigma_low, sigma_high), rad^2/s^2, of a band (fmin, fmax), Hz: (2 pi f)^2, and
    SHIFT for fmin = 0 (a free rigid mode at omega = 0 counts in the band)."""
    return tuple((2 * np.pi * f) ** 2 if f > 0 else SHIFT for f in band)


def _shift_to(shifted, K, M, sigma):
    """shifted = K - sigma M, on K's pattern."""
    K.copy(shifted, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
    shifted.axpy(-sigma, M, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)


def _solve_modes(problem, count, settings, SLEPc, band=None):
    """solve_modes in its -log_view stage."""
    # what was made, destroyed in reverse order however far the set-up got
    with destroyed() as made:
        with EVENTS["operators"]:
            operators = ModalOperators(problem, settings)
            made.append(operators)
            K, M = operators.matrix, operators.mass_matrix
            shifted = K.duplicate(copy=True)
            made.append(shifted)
            shifted.axpy(-SHIFT, M, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            shifted.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        factor = direct_factor(shifted, PETSc.PC.Type.CHOLESKY, operators.block,
                               PREFIX + "st_")
        made.append(factor)
        with EVENTS["factor"]:
            factor.set_up(shifted)
            negative = factor.negative_pivots() - operators.chain_constraints
        if negative > 0:
            raise ModesRefused(int(negative), operators.symmetrised)
        if band is None:
            modes = _assemble(operators, *_pairs(operators, shifted, factor, SLEPc, count,
                                                 SHIFT, (SHIFT, np.inf)))
            modes.asked = count
            modes.symmetrised = operators.symmetrised
            return modes
        window = band_shifts(band)
        ends = [_below(operators, shifted, sigma) for sigma in window]
        found, failed = _slice(operators, shifted, SLEPc, window, ends, 0)
        if len(found[0]) == 0:
            modes = _empty_modes(problem.mesh, band)
            modes.converged = found[3]
        else:
            modes = _assemble(operators, *found)
        modes.band = (band[0], band[1], int(ends[1] - ends[0]))
        modes.slices = [tuple(np.sqrt(np.maximum(w, 0.0)) / (2 * np.pi)) for w in failed]
        modes.symmetrised = operators.symmetrised
        return modes


def _empty_modes(mesh, band):
    """The Modes of a band without any (band[2] = 0)."""
    n_v, n_e = len(mesh.vertex_S), mesh.n_local_elements
    return Modes(np.zeros(0), np.zeros(0), np.zeros((0, len(CLASSES))), mesh.vertex_S,
                 np.zeros((0, n_v, 3)), np.zeros((0, n_v, 3)),
                 mesh.element_S + mesh.element_h / 2, np.zeros((0, n_e, 3)), 0, [],
                 (band[0], band[1], 0))


def _below(operators, shifted, sigma):
    """The eigenvalues of K - omega^2 M below ``sigma`` (rad^2/s^2): the negative pivots
    of the LDL^T of K - sigma M (left in ``shifted``) less the chains' constraints
    (Sylvester). Collective."""
    with destroyed() as made:
        factor = _factored(operators, shifted, sigma)
        made.append(factor)
        return int(factor.negative_pivots() - operators.chain_constraints)


def _factored(operators, shifted, sigma):
    """A new factorisation (direct_factor) of ``shifted`` = K - sigma M: its own
    analysis at sigma, as MUMPS's ordering and pivoting of a matrix analysed at a
    far other shift (M's entries at a sigma far above the modes) lose the digits of
    the factor's solves and inertia. Collective; the caller destroys it."""
    with EVENTS["factor"]:
        _shift_to(shifted, operators.matrix, operators.mass_matrix, sigma)
        factor = direct_factor(shifted, PETSc.PC.Type.CHOLESKY, operators.block,
                               PREFIX + "st_")
        try:
            factor.set_up(shifted)
        except Exception:
            factor.destroy()
            raise
        return factor


def _slice(operators, shifted, SLEPc, window, ends, depth):
    """The verified pairs (_pairs' tuple) of every eigenvalue in ``window`` (omega^2 from,
    to), which the inertia counts ``ends`` (below each end) hold, and the sub-bands
    (omega^2 from, to) left short: unverified at the depth SLICE_DEPTH, or where the
    inertia decreases. A sub-band whose ends are more
    than SLICE_SPAN apart in omega^2 (from RIGID's omega^2 where it starts at 0), or
    whose solve about its middle verifies fewer pairs than it holds, is cut at its
    geometric middle (the inertia there counts each half's): one shift at the middle of
    a wide band keeps none of the low eigenvalues' digits in sigma + 1/theta. A
    sub-band is solved about its middle, or about SHIFT where it starts at 0. An empty
    one costs no solve. Collective."""
    count = ends[1] - ends[0]
    if count < 0:
        # the inertia decreases: K - sigma M lost its digits at a sigma far above the
        # discretisation's eigenvalues; nothing in the sub-band can be counted
        return _no_pairs(operators), [window]
    if count == 0:
        return _no_pairs(operators), []
    low = max(window[0], (2 * np.pi * RIGID) ** 2)
    wide = window[1] > SLICE_SPAN * low
    if not wide:
        # from the band's start at 0 the lowest ``count`` above SHIFT are the
        # sub-band's (the stable state has none below): the free rigid modes, whose
        # small mass the Krylov space misses about a shift above them, found as
        # without a band
        shift = SHIFT if window[0] <= SHIFT else 0.5 * (window[0] + window[1])
        with destroyed() as made:
            factor = _factored(operators, shifted, shift)
            made.append(factor)
            found = _pairs(operators, shifted, factor, SLEPc, count, shift, window, EXTRA)
        if len(found[0]) == count:
            return found, []
        if depth >= SLICE_DEPTH:
            return found, [window]
    if depth >= SLICE_DEPTH:
        return _no_pairs(operators), [window]
    middle = np.sqrt(low * window[1])
    inside = _below(operators, shifted, middle)
    lower, failed_lower = _slice(operators, shifted, SLEPc, (window[0], middle),
                                 (ends[0], inside), depth + 1)
    upper, failed_upper = _slice(operators, shifted, SLEPc, (middle, window[1]),
                                 (inside, ends[1]), depth + 1)
    return (tuple(np.concatenate([a, b]) for a, b in zip(lower[:3], upper[:3]))
            + (lower[3] + upper[3],)), failed_lower + failed_upper


def _no_pairs(operators):
    """_pairs' tuple without any pair."""
    n = operators.problem.mesh.n_local_nodes
    return np.zeros(0), np.zeros((0, n, operators.block)), np.zeros(0), 0


def default_subspace(count):
    """SLEPc's ncv for ``count`` modes asked of the eigensolver unless
    -rod_modes_eps_ncv says otherwise: count + max(SUBSPACE, count // 2)."""
    return count + max(SUBSPACE, count // 2)


def _pairs(operators, shifted, factor, SLEPc, count, shift, window, extra=0):
    """(omega2 (k,), vectors (k, n_nodes, block), phi^T M phi (k,), converged) of the
    lowest ``count`` verified eigenpairs of K phi = omega^2 M phi in ``window`` (omega^2
    from, to), found by shift-and-invert about ``shift`` (``shifted`` = K - shift M,
    factored in ``factor``), ``extra`` more asked of the eigensolver. omega^2 is each
    vector's Rayleigh quotient phi^T K phi / phi^T M phi (the eigensolver's
    shift + 1/theta loses the digits of an eigenvalue far below the shift); a pair is
    kept where its relative residual ||K phi - omega^2 M phi|| / (||K phi|| +
    omega^2 ||M phi||) is below RESIDUAL (or, for a rigid mode, ||K phi|| and the
    residual below RESIDUAL ||K||_inf ||phi||), phi^T M phi > 0 and
    omega^2 in the window. An eigenvalue below SHIFT is one of the massless unknowns'
    infinite ones that the spectral transformation returned with the wrong sign: left
    out. ModesFailed where PETSc or SLEPc fails in the eigensolver. Collective."""
    K, M = operators.matrix, operators.mass_matrix
    # everything made or referenced here (the EPS's ST too: getST's reference) is
    # destroyed here, however the solve ended (destroyed(), FactorKSP)
    with destroyed() as made:
        ksp = FactorKSP(shifted, factor)
        made.append(ksp)
        eps = SLEPc.EPS().create(comm=operators.comm)
        made.append(eps)
        st = eps.getST()
        made.append(st)
        vector, Kx, Mx = M.createVecRight(), M.createVecRight(), M.createVecRight()
        made.extend((vector, Kx, Mx))
        try:
            eps.setOperators(shifted, M)
            eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
            eps.setDimensions(count + extra, extra + default_subspace(count))
            # the purification's solves (one per vector) change no shape: the massless
            # unknowns' components it removes are not read (u and omega are)
            eps.setPurify(False)
            eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
            eps.setTarget(0.0)
            st.setType(SLEPc.ST.Type.SINVERT)
            st.setKSP(ksp.ksp)
            eps.setOptionsPrefix(PREFIX)
            eps.setFromOptions()
            with EVENTS["eps"]:
                eps.solve()
        except PETSc.Error as error:
            raise ModesFailed.of_error(error) from None
        converged = eps.getConverged()
        scale = K.norm(PETSc.NormType.INFINITY)
        values, vectors, masses = [], [], []
        for i in range(converged):
            if eps.getEigenvalue(i).real + shift < SHIFT:
                continue
            eps.getEigenvector(i, vector)
            K.mult(vector, Kx)
            M.mult(vector, Mx)
            mass = vector.dot(Mx)
            if not mass > 0:
                continue
            value = vector.dot(Kx) / mass
            stiffness, inertia = Kx.norm(), Mx.norm()
            Kx.axpy(-value, Mx)
            residual = Kx.norm()
            # a zero-frequency mode (a free roll) is checked against K's size, as its
            # own Kx vanishes; a vibration always against its own K x and M x, however
            # small they are beside K's norm (a stiff line's low modes)
            rigid = value < (2 * np.pi * RIGID) ** 2 and \
                residual <= RESIDUAL * scale * vector.norm() and \
                stiffness <= RESIDUAL * scale * vector.norm()
            if not (residual <= RESIDUAL * (stiffness + abs(value) * inertia) or rigid) \
                    or not window[0] <= value <= window[1]:
                continue
            values.append(value)
            masses.append(mass)
            vectors.append(vector.getArray(readonly=True).reshape(-1, operators.block)
                           .copy())
        order = np.argsort(values)[:count]
        n = operators.problem.mesh.n_local_nodes
        return (np.array(values)[order].reshape(-1),
                np.array(vectors).reshape(-1, n, operators.block)[order],
                np.array(masses)[order].reshape(-1), converged)


def _assemble(operators, omega2, vectors, masses, converged):
    """Modes of verified pairs (_pairs), lowest first; their shapes taken all at once
    (_shapes: one reduction over the ranks per quantity, not per mode)."""
    mesh = operators.problem.mesh
    order = np.argsort(omega2, kind="stable")
    omega2, vectors, masses = omega2[order], vectors[order], masses[order]
    modal_mass, shares, offset, rotation, curvature = _shapes(operators, vectors, masses)
    S_mid = mesh.element_S + mesh.element_h / 2
    return Modes(omega2, modal_mass, shares, mesh.vertex_S, offset, rotation, S_mid,
                 curvature, converged,
                 classify(shares, np.sqrt(np.maximum(omega2, 0.0)) / (2 * np.pi)))


def _shapes(operators, vectors, masses):
    """(modal masses (k,), shares (k, 4), offsets (k, n_v, 3), rotations (k, n_v, 3),
    curvatures (k, n_e, 3)) of the eigenvectors ``vectors`` (k, n_nodes, block), whose
    phi^T M phi are ``masses`` (k,): each normalised to a largest offset of 1 (a
    torsional mode, at least DOMINANT of its energy in the roll, to a largest rotation
    of 1 rad) with that largest entry positive (the first along the line where several
    are). Collective."""
    problem, mesh = operators.problem, operators.problem.mesh
    k = vectors.shape[0]
    slots = [operators.position_slot[c] for c in (0, 1, 2)]
    offset = vectors[:, 0::2][:, :, slots]                     # (k, n_v, 3)
    omega = vectors[:, :, :3]                                   # (k, n_nodes, 3)
    shares = _shares(operators, offset, omega).reshape(k, len(CLASSES))
    torsional = shares[:, CLASSES.index("torsional")] >= DOMINANT
    sizes = [np.abs(omega[j]).max(axis=1) if torsional[j] else
             np.linalg.norm(offset[j], axis=1) for j in range(k)]
    signed = [omega[j] if torsional[j] else offset[j] for j in range(k)]
    local_largest = np.array([size.max(initial=0.0) for size in sizes])
    largest = mesh.global_max(local_largest)
    local = np.array([int(np.argmax(size)) if size.size else -1 for size in sizes])
    here = (local >= 0) & (local_largest >= largest * (1 - 1e-12))
    # rank order: 2 vertex_start + local increases along the line on either array
    index = np.where(here, 2 * mesh.vertex_start + local, np.iinfo(np.int32).max)
    first = mesh.global_min(index.astype(float))
    entries = np.array([signed[j][local[j]][np.argmax(np.abs(signed[j][local[j]]))]
                        if here[j] and index[j] == first[j] else 0.0 for j in range(k)])
    sign = np.where(np.asarray(mesh.global_sum(entries)) >= 0, 1.0, -1.0)
    scale = sign / largest
    omega = omega * scale[:, None, None]
    return (masses * scale**2, shares, offset * scale[:, None, None], omega[:, 0::2],
            _curvature(problem, omega))


def _plane_normal(problem):
    """The unit normal of the vertical plane that holds the static line best (its
    principal horizontal direction, e_x where it has none). Collective."""
    mesh = problem.mesh
    r = problem.state.node_positions()[0::2]
    xy = r[:, :2]
    sums = mesh.global_sum(np.concatenate([[len(xy)], xy.sum(axis=0),
                                           np.einsum("ni,nj->ij", xy, xy).ravel()]))
    mean = sums[1:3] / sums[0]
    spread = sums[3:].reshape(2, 2) / sums[0] - np.outer(mean, mean)
    values, vectors = np.linalg.eigh(spread)
    along = vectors[:, 1] if values[1] > 1e-12 * problem.scene.length**2 else np.array([1.0, 0])
    return np.array([-along[1], along[0], 0.0])


def _shares(operators, offset, omega):
    """The shares of the kinetic energy (in-plane, out-of-plane, axial, torsional) of
    shapes, (k, 4): offsets (k, n_v, 3) and rotations (k, n_nodes, 3); the
    displacements at the vertices with their trapezoid masses, the rotations at the P2
    nodes with their rotary inertia; a rotation about the plane's normal is in-plane
    bending, about the in-plane normal out-of-plane bending. Collective (one reduction
    for all k)."""
    problem, mesh = operators.problem, operators.problem.mesh
    normal = _plane_normal(problem)
    t = unit(problem.state.tau[:, 2])
    tv = t[0::2]
    S = mesh.vertex_S
    m, added, _ = line_inertia(problem.scene, S, operators.settings)
    vertex_w = 3 * mesh.node_weights()[0::2]      # (h_left + h_right) / 2
    axial = np.einsum("knc,nc->kn", offset, tv)
    out = offset @ normal
    inplane = np.maximum(np.sum(offset**2, axis=2) - axial**2 - out**2, 0.0)
    rotation = operators.rotation
    torsion = np.einsum("knc,nc->kn", omega, t)
    about_normal = omega @ normal
    polar = np.einsum("nc,nck,nk->n", t, rotation, t)       # w J
    energies = np.stack([
        inplane @ (vertex_w * (m + added)) + (about_normal**2) @ (polar / 2),
        out**2 @ (vertex_w * (m + added))
        + np.maximum(np.sum(omega**2, axis=2) - torsion**2 - about_normal**2, 0.0)
        @ (polar / 2),
        axial**2 @ (vertex_w * m),
        torsion**2 @ polar], axis=1)
    energies = np.asarray(mesh.global_sum(energies))
    return energies / np.maximum(energies.sum(axis=1, keepdims=True), np.finfo(float).tiny)


def _curvature(problem, omega):
    """(d1, d2, d3) . omega' at the owned elements' midpoints, (k, n_e, 3), 1/m, of the
    rotations ``omega`` (k, n_nodes, 3): omega' of the P2 field there,
    (omega_right - omega_left) / h. Collective (one exchange for all k)."""
    mesh = problem.mesh
    ne = mesh.n_local_elements
    vertices = np.moveaxis(omega[:, 0::2], 1, 0)                # (n_v, k, 3)
    following = mesh.first_of_next_rank(np.ascontiguousarray(vertices))   # (k, 3)
    right = np.concatenate([vertices[1:], following[None]])[:ne]          # (n_e, k, 3)
    derivative = (right - vertices[:ne]) / mesh.element_h[:, None, None]
    d = problem.state.tau[1:2 * ne:2]                       # (n_e, 3 directors, 3)
    return np.einsum("eic,ekc->kei", d, derivative)
