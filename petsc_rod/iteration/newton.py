"""Newton's method on the reduced problem, near a solution (docs/method.md §11).

The discrete problem the Uzawa iteration solves is: minimise

    E(d) = sum_i d_i^T K_{a_i} d_i - b . d3    (b the slope's load)

(K_{a_i} = int a_i(S) g_k' g_l' dS, the P2 stiffness of field i's coefficient: a_i K on a
line of uniform stiffness, K the unit one)

over frames d_n in SO(3) at the P2 nodes, with the clamped frames fixed and, when both
ends are held, the chord sum_n w_n d3_n = r(L) - r(0). Near a solution this module takes
Newton steps on it directly. A step turns each frame by a rotation vector omega_n,
d_n <- exp([omega_n]x) d_n, with omega from the KKT system

    [ H  C^T ] [ omega ]   [ -grad L ]
    [ C   0  ] [ dmu   ] = [ -c      ],

L = E + mu . c the Lagrangian of the chord constraint c(d) = sum_n w_n d3_n - chord,
grad_n L = sum_i d_{n,i} x g_{n,i} (g_i = dL/dd_i = 2 K_{a_i} d_i - b delta_i3 + w mu
delta_i3), C omega = sum_n w_n omega_n x d3_n, and H the Riemannian Hessian of L: the
second variation of analysis/second_variation.py with lambda_n = -g_n / w_n (at a solution
these are the Uzawa multipliers, and H is exactly the matrix of the stability test).

A step is taken only where H is positive definite on the constraint set (the inertia of
its factorisation, as in the stability test): Newton then heads for a local minimiser,
never a saddle. Otherwise, or when the steps stop shrinking, the attempt gives up and the
Uzawa iteration goes on from where it was. On success the state is handed back as a
fixed point of the Uzawa iteration: tau = d and lambda = -g / w. A linear-algebra
failure on the way (a state the steps cannot start from: a stretch k <= 0 or values that
are not finite; a factorisation that failed, whose solves give Inf; a Schur matrix,
gradient or step that is not finite; LAPACK's LinAlgError in a small dense solve or in
the inertia test's eigenvalues) ends the attempt as FAILED with the state as it was,
never the run: each such test is made on every rank and its verdict reduced, so that
every rank takes the same decision (LinearAlgebraFailure). Where the attempt's
steps converged on the whole problem its last step, measured as an iteration, may end
the step (``solved_norms``, controller.newton_converged); otherwise the next iteration,
whose tests then decide convergence, moves it only by the map's round-off.

On an extensible line (docs/method.md §12) the fields are g = (d1, d2, k d3), k = 1 + eps
the stretch of each node, and what the Uzawa fixed point is stationary for is

    F(d, k) = sum_i a_i g_i^T K g_i - b . g3 + sum_n w_n EA_n eps_n^2 / 2,

on sum_n w_n k_n d3_n = r(L) - r(0) when both ends are held: the global step gives
dE/dg = -w lambda, the local step's stationarity in k gives lambda3.d3 = EA eps, in the
rotation sum_i g_i x lambda_i = 0. So each node has 4 unknowns, (omega_n, delta k_n),
the frames turn as above and k <- k + delta k; the gradient in k is
d3 . g3-gradient of L + w EA eps (Term.add_strain_gradient), H that of
analysis/second_variation.py with its stretch rows, and the chord forms gain the columns
w_n d3_n. The hand-over is the same with tau = g (the stretched targets (tau1, tau2,
k tau3) the state keeps) and lambda = -g-gradient / w (without the axial term: the
tension is lambda3.d3 = EA eps at the solution). The stretch of a clamped node (the
force balance's, §12) and of a node with EA infinite is held.
"""

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.jacobian import NewtonJacobian
from petsc_rod.analysis.second_variation import skew, unit
from petsc_rod.frames import roll_between, rotations

EVENT = PETSc.Log.Event("rod_newton")

# At most this many Newton steps per attempt; a step whose largest turn is below
# STEP_TOLERANCE rad is the last (the error after it is about its square), and so is a
# chord step whose rest is (FROZEN_SHRINK, below).
MAX_STEPS = 8
STEP_TOLERANCE = 1e-10
# A step must shrink to at most this fraction of the previous one, or the attempt stops
# (Newton contracts quadratically near a regular minimiser). On a line whose energy
# reads its positions (the seabed) a step that does not shrink but turns no more than
# the one before it is taken where that one lowered |grad L| to at most this fraction,
# above FLOOR_TURN: the contact's active set moves with the steps (a semi-smooth
# Newton), and while it settles a step may turn about as much as the one before it
# (docs/method.md §11, "Terms of the positions"). The residual's fall at every such
# step, and MAX_STEPS, keep an attempt from cycling.
SHRINK = 0.5
# Steps stop shrinking at the round-off floor of the Newton system, about cond(H) eps
# (cond(H) grows like the square of the element count; docs/method.md §11). An
# attempt whose last step was below FLOOR_TURN rad when the next one
# stopped shrinking has reached that floor: its state is handed over, and the iteration,
# whose tests decide convergence, goes on from there.
FLOOR_TURN = 1e-7
# Near the solution a step of a problem whose steps solve with the Jacobian (a follower
# load, the friction: ``unsymmetric``) reuses the last exact step's matrices and factors
# (a chord step): where the previous step turned by at most FREEZE_TURN rad, J has
# changed since it was factored by about the turns since that exact step, and a step
# with it contracts the error by a factor of about as much, without H's and J's
# assembly, the LU and the inertia's LDL^T, and with one right-hand side: the chord
# forms' solves are the exact step's too (the KKT matrix frozen whole; docs/method.md
# §11, "Chord steps"). A chord step that does not shrink to
# FROZEN_SHRINK of the previous one is taken again with fresh factors (above FLOOR_TURN;
# at the floor the state is handed over, as after any step that does not shrink). Such a
# problem has no energy: the inertia test is its steps' safeguard, not a stability
# verdict, and it was passed at most about FREEZE_TURN + INERTIA_TURN rad from the
# result. A conservative problem's steps stay exact.
FREEZE_TURN = 1e-4
FROZEN_SHRINK = 0.1
# On such a problem an exact step after a step of at most INERTIA_TURN rad whose own H
# (not one with the iteration's curvature, nor with the roll held) passed the inertia
# test is taken without the test (no LDL^T of H: its solves are J's): the
# inertia on the constraint set changes between two states only where an eigenvalue
# crosses zero, and H's entries (smooth in the frames and the multipliers) move by about
# the turn times their derivatives between the two, so the test, like a chord step's
# reuse of the factors, is trusted at most about INERTIA_TURN rad from where it was made.
# The next exact step after a chord step or an untested one tests again. A conservative
# problem tests every exact step: its last test is the stability verdict (``verified``).
INERTIA_TURN = 1e-3
# A chord step converges linearly, by the factor theta = turn / previous turn (at most
# FROZEN_SHRINK): the error it leaves is about theta / (1 - theta) times its turn (the
# geometric rest), and a chord step whose rest is below STEP_TOLERANCE rad is the last
# (the stopping test of simplified Newton iterations, Hairer & Wanner, Solving Ordinary
# Differential Equations II, §IV.8), as an exact step below STEP_TOLERANCE is, whose rest
# is about its square (_chord_rest).

# A step with the Jacobian after one that turned by at most ROLL_TURN rad holds the free
# roll (__init__) by a constraint of the step (_newton_step): near a solution the roll is
# a near-null vector of J (its eigenvalue of the order of the residual), J's LU is not
# shifted, and the solves' component along it does not vanish with the residual, so
# that removing the mean roll afterwards (_without_roll) left steps that stopped
# shrinking. Farther (an attempt's first step, and a step after a turn above ROLL_TURN,
# such as the first one's from the iteration's curvature) J is regular along the roll
# and the constraint would change the step: there the mean roll is only removed
# (docs/method.md, "The free roll").
ROLL_TURN = 1e-2

# What an attempt ends with (NewtonSolver.run).
CONVERGED, INDEFINITE, FAILED = "converged", "indefinite", "failed"


class LinearAlgebraFailure(Exception):
    """A step's linear algebra failed on some rank, raised on every rank (the verdict
    reduced: NewtonSolver._agree); the attempt ends FAILED (module docstring)."""


def _chord_rest(turn, previous):
    """theta / (1 - theta) * turn, theta = turn / previous: the error left by a chord step
    that turned ``turn`` rad after one of ``previous`` rad (the comment above), inf where
    the steps did not contract."""
    theta = turn / previous
    return theta / (1.0 - theta) * turn if theta < 1.0 else np.inf


class NewtonSolver:
    """The Newton solver: the steps of the module docstring on a problem's state
    (problem/problem.py). Owns a work Vec for K d (the K are the global step's);
    ``destroy()`` frees it (the second variation is the problem's,
    ``RodProblem.second_variation``, updated at each step)."""

    def __init__(self, problem):
        self.problem = problem
        self._product = problem.field_stiffness(0)[1].createVecLeft()
        self._free = problem.free_nodes
        # a term reads the positions (the seabed, the friction): the first step's
        # curvature (_newton_step)
        self.reads_positions = any(term.position_components for term in problem.terms)
        # a term with unsymmetric entries (the drag, a load that follows the line; the
        # friction): the steps solve with the Jacobian (analysis/jacobian.py), and each
        # must lower |grad L| (no energy to descend)
        self.unsymmetric = any(term.unsymmetric for term in problem.terms)
        self._jacobian = None
        # whether the last step turned by at most ROLL_TURN (run): near the solution
        self._near = False
        # the last exact step's KKT pieces, for the chord steps (_keep_kkt)
        self._kkt = None
        # the next step is exact and taken without the inertia test (run, INERTIA_TURN)
        self._trusted = False
        self._own_test = False          # the last _newton_step passed its own H's test
        # the free roll: where K1 = K2 all along and no frame is clamped, turning every
        # cross-section by one angle about its own tangent changes nothing (a null vector
        # of the Newton system, which LU turns into a step of round-off's size); the
        # steps leave it out (_without_roll), those with the Jacobian by a constraint of
        # the step as well (_newton_step)
        stiffness = problem.scene.stiffness_values()
        self._free_roll = (bool(np.all(stiffness[:, 0] == stiffness[:, 1]))
                           and problem.mesh.global_min(int(np.all(self._free))) == 1)
        # an extensible line: the stretch k is an unknown of each node but where it is
        # held (a clamp's, from the force balance; EA infinite)
        self.stretch = getattr(problem, "axial", None) is not None
        self._held_stretch = (~self._free | ~np.isfinite(problem.axial)) if self.stretch \
            else None
        # whether a converged attempt's state is the step's result: not where a clamp's
        # stretch is held at the force balance's value of the last iteration (§12), nor
        # where a term's outputs are those of the last global step (Term
        # .outputs_of_state: the friction), which the iterations after the hand-over
        # bring up to date
        self._whole = all(term.outputs_of_state for term in problem.terms) and not (
            self.stretch and problem.mesh.global_max(
                int(np.any(~self._free & np.isfinite(problem.axial)))))
        # whether the last step's H was tested on the constraint set (decidable) and found
        # positive definite, with the state's own curvature: the stability test's verdict,
        # at 1e-10 rad from the result (a chord step, FREEZE_TURN, tests nothing, nor an
        # exact one after a small tested step, INERTIA_TURN)
        self.verified = False
        # the stopping quantities (state.Norms, §6) of the last step of an attempt whose
        # steps converged (below STEP_TOLERANCE) on the whole problem; None after any
        # other attempt (one handed over at the round-off floor included): the step's
        # convergence in Newton's terms (run)
        self.solved_norms = None

    @property
    def free_roll(self):
        """Whether every section is round and nothing is clamped: one roll of every
        section about its tangent is a null vector of H (the steps leave it out)."""
        return self._free_roll

    def _untwisting_roll(self, frames):
        """The roll (rad, (n_local_nodes,)) of each node's frame about its tangent that
        leaves no twist between neighbouring nodes (frames.roll_between of the rolled
        frames 0), the first node kept. Where every section is round and nothing is
        clamped (_free_roll) the torque m3 = K3 u3 is the same all along at equilibrium
        and zero at an end whose roll is free, so u3 = 0: the iteration spreads its twist
        only by diffusion over the line, and an attempt that starts with it turns the
        line about itself and finds H indefinite. Collective."""
        mesh = self.problem.mesh
        chain = frames
        following = mesh.first_of_next_rank(frames)
        if not mesh.on_upper_boundary:
            chain = np.concatenate([frames, following[None]])
        change = -roll_between(chain[:-1], chain[1:])     # two gaps per owned element
        vertex = mesh.prefix_sum(change[0::2] + change[1::2])
        angle = np.empty(mesh.n_local_nodes)
        angle[0::2] = vertex
        angle[1::2] = vertex[:mesh.n_local_elements] + change[0::2]
        return angle

    def run(self, record=None):
        """Newton steps from the state's current tau (rotations near the fields). Returns
        CONVERGED (to STEP_TOLERANCE, with ``solved_norms`` the last step's stopping
        quantities, or to the round-off floor of FLOOR_TURN; the state is then the Uzawa
        fixed point of the module docstring to that accuracy),
        INDEFINITE (H has a direction of negative curvature: near a saddle) or FAILED
        (the steps did not converge); in the last two cases the state is as it was.
        ``record(turn)`` is called after each step with its largest turn, rad."""
        problem = self.problem
        state = problem.state
        EVENT.begin()
        saved = state.snapshot()
        if self._free_roll:
            state.roll_nodes(self._untwisting_roll(state.tau))
        frames = state.tau.copy()
        start_lam = state.lam.copy()
        clamped = ~self._free
        self.solved_norms = None
        frames[clamped] = state.node_directors()[clamped]      # the prescribed frames
        mu = None
        previous = np.inf
        residual = np.inf                 # |grad L| of the last step's start (followers)
        start_norm = np.inf               # |grad L| of the last step's start (all)
        outcome = FAILED
        regularised = False
        tested = False                    # the last step passed the test of its own H
        curved = False                    # the last exact step took the iteration's curvature
        try:
            self._agree(self._usable(frames))
            for _ in range(MAX_STEPS):
                state.set_node_directors(frames)
                g = problem.energy_gradient(self._product)
                # the step before this one took the iteration's curvature (no chord step
                # follows such a step, so ``curved`` is still that step's)
                after_curvature = curved
                first = mu is None
                mu = self._least_squares_multiplier(frames, g) if mu is None else mu
                # the first step's curvature from the iteration's multipliers where the
                # heights enter (see _newton_step)
                curvature = start_lam if first and self.reads_positions else None
                # a chord step (FREEZE_TURN) from the last exact step's KKT matrix, not
                # from one made with the iteration's curvature: that matrix is not J, and
                # its chord steps left |grad L| where it was (docs/riser.md §3b)
                chord = (self.unsymmetric and previous <= FREEZE_TURN
                         and self._kkt is not None and not curved)
                self._near = previous <= ROLL_TURN
                # an exact step without the inertia test (INERTIA_TURN); a step taken
                # again below is tested
                self._trusted = (self.unsymmetric and not chord and tested
                                 and previous <= INERTIA_TURN)
                omega, dmu = self._newton_step(frames, g, mu, regularised, curvature, chord)
                tested = self._own_test
                self._trusted = False
                if (chord and previous > FLOOR_TURN
                        and not self._largest(omega) <= FROZEN_SHRINK * previous):
                    # a chord step that did not contract: fresh factors (at the round-off
                    # floor the shrink test below hands the state over instead)
                    chord = False
                    omega, dmu = self._newton_step(frames, g, mu, regularised, curvature)
                    tested = self._own_test
                if omega is None and curvature is None and self.reads_positions:
                    # H indefinite after a step on a line whose heights enter: the step
                    # again with the iteration's curvature, as the first (_newton_step),
                    # and like the first exempt from the residual's fall below
                    curvature = start_lam
                    chord = False
                    omega, dmu = self._newton_step(frames, g, mu, regularised, curvature)
                    tested = self._own_test
                if omega is None:
                    outcome = INDEFINITE
                    break
                if not chord:
                    curved = curvature is not None
                if self.unsymmetric:
                    # no energy to descend: the residual must fall at every step, but at
                    # the round-off floor (the last turn below FLOOR_TURN, as below);
                    # from the second step on where the first took the iteration's
                    # curvature: that step fixes the positions with another matrix than
                    # the exact one, and the residual after it may exceed the one before
                    # (docs/method.md §11)
                    norm = self._residual_norm
                    if not norm < residual:
                        if previous <= FLOOR_TURN:
                            self._hand_over(frames, mu)
                            return CONVERGED
                        break
                    residual = np.inf if curvature is not None else norm
                largest = self._largest(omega)
                # a step that turns no more than the last one, taken on a line whose
                # heights enter where the last step halved |grad L| (SHRINK), above the
                # round-off floor (at the first step start_norm is inf and previous too);
                # after a step with the iteration's curvature whatever its turn: that
                # step's turn is another matrix's, no Newton step's to contract, and the
                # fall of |grad L| is what says the attempt goes on (docs/method.md §11)
                settling = (self.reads_positions and previous > FLOOR_TURN
                            and (largest <= previous or after_curvature)
                            and self._residual_norm <= SHRINK * start_norm)
                start_norm = self._residual_norm
                if (self.stretch and not regularised and not settling
                        and np.isfinite(previous) and not largest <= SHRINK * previous):
                    # a zero mode whose pivot round-off left positive (the roll of
                    # K1 = K2 between pins): the step again with H + tolerance M, and so
                    # on to the end of the attempt (_positive_definite)
                    regularised = True
                    chord = False
                    omega, dmu = self._newton_step(frames, g, mu, regularised)
                    tested = self._own_test
                    if omega is None:
                        outcome = INDEFINITE
                        break
                    largest = self._largest(omega)
                if not np.isfinite(largest) or (largest > SHRINK * previous and not settling):
                    if np.isfinite(largest) and previous <= FLOOR_TURN:
                        self._hand_over(frames, mu)
                        return CONVERGED
                    break
                if self.stretch:
                    frames = self._stretched(frames, omega)
                    if frames is None:
                        break
                else:
                    # d_i <- R d_i for each row d_i: frames R^T, one batched product
                    frames = np.matmul(frames, rotations(omega).transpose(0, 2, 1))
                mu = mu + dmu
                # what is compared with STEP_TOLERANCE: an exact step's turn (the error
                # it leaves is about its square), a chord step's geometric rest
                rest = _chord_rest(largest, previous) if chord else largest
                previous = largest
                if record is not None:
                    record(largest)
                if rest < STEP_TOLERANCE:
                    self.solved_norms = self._hand_over(frames, mu, measured=self._whole)
                    return CONVERGED
            state.restore(saved)
            return outcome
        except (LinearAlgebraFailure, np.linalg.LinAlgError):
            # every rank here at once: the failures are agreed (_agree), and a LinAlgError
            # comes from LAPACK on numbers every rank holds alike (reductions)
            state.restore(saved)
            return FAILED
        finally:
            # the kept KKT pieces serve this attempt's chord steps only
            self._drop_kkt()
            self._trusted = False
            EVENT.end()

    # --- the pieces of a step ---------------------------------------------------------
    def _agree(self, ok):
        """Raise LinearAlgebraFailure on every rank where ``ok`` is False on any.
        Collective."""
        if not self.problem.mesh.global_min(int(bool(ok))):
            raise LinearAlgebraFailure

    def _usable(self, frames):
        """Whether the local ``frames`` (n_nodes, 3, 3) are a state the steps can start
        from: finite, and on an extensible line every stretch |d3| = k positive (the
        unit tangents d3 / k; the local step keeps k >= 0, and k = 0 is reached by a
        line soft enough to fold)."""
        if not np.all(np.isfinite(frames)):
            return False
        return not self.stretch or bool(np.all(np.einsum("nc,nc->n", frames[:, 2],
                                                         frames[:, 2]) > 0.0))

    def _stretched(self, frames, step):
        """Frames (rows d1, d2, k d3) turned by step[:, :3] and stretched by k += step[:, 3];
        None on every rank where a stretch would not stay positive on one (the attempt
        fails). Collective."""
        turned = np.einsum("nkl,nil->nik", rotations(step[:, :3]), frames)
        k = np.sqrt(np.einsum("nc,nc->n", turned[:, 2], turned[:, 2]))
        new = k + step[:, 3]
        if not self.problem.mesh.global_min(int(bool(np.all(new > 0)))):
            return None
        turned[:, 2] *= (new / k)[:, None]
        return turned

    def _strain_gradient(self, frames, g):
        """dL/dk at the nodes, (n_nodes,): d3 . g3-gradient (its chord share included) and
        the terms' (w EA eps), 0 where the stretch is held."""
        tangent = frames[:, 2]
        k = np.sqrt(np.einsum("nc,nc->n", tangent, tangent))
        gradient = np.einsum("nc,nc->n", tangent / k[:, None], g[:, 2])
        for term in self.problem.terms:
            term.add_strain_gradient(gradient, self.problem.state.node_weights, k - 1.0)
        gradient[self._held_stretch] = 0.0
        return gradient

    def _bordered(self):
        return self.problem.bordered

    def _least_squares_multiplier(self, frames, g):
        """The chord multiplier mu (3,) that makes grad L smallest (0 when the chord is
        free): sum_n |a_n + w_n d3_n x mu|^2 minimal, a_n = sum_i d_i x g_i, over the
        nodes that are not clamped."""
        if not self._bordered():
            return np.zeros(3)
        w = self.problem.state.node_weights
        a = np.cross(frames, g).sum(axis=1)
        A = w[:, None, None] * skew(frames[:, 2])          # w d3 x mu = A mu
        free = self._free
        if self.stretch:
            # the stretch's equations d3.(g3 + w mu) + w EA eps = 0 as well: they fix the
            # tangential part of mu that the rotations' leave free (a straight taut line)
            a = np.concatenate([a, self._strain_gradient(frames, g)[:, None]], axis=1)
            row = w[:, None] * unit(frames[:, 2])
            row[self._held_stretch] = 0.0
            A = np.concatenate([A, row[:, None, :]], axis=1)
        normal = np.einsum("nki,nkj->ij", A[free], A[free])
        right = -np.einsum("nki,nk->i", A[free], a[free])
        total = self.problem.mesh.global_sum(np.concatenate([normal.ravel(), right]))
        return self._small_solve(total[:9].reshape(3, 3), total[9:])

    def _small_solve(self, matrix, right):
        """The least-squares solution of a small dense system that every rank holds alike
        (reduced), (k,); LinearAlgebraFailure on every rank where it or the system is
        not finite or LAPACK fails on one. Collective.

        Solved as (D A D) y = D b, x = D y, D = |diag A|^(-1/2) (1 where the diagonal
        is 0): the Schur matrix C J^-1 C^T of a step that holds the free roll by a
        constraint (ROLL_TURN) has the roll's entry of the order of 1 / (J's eigenvalue
        along the roll), which falls with the residual: 7.9e14 against the chord's 0.67
        to 14 on a line on a seabed grid, where lstsq's cut-off (eps times the largest
        singular value) dropped the chord's smallest and the step left the chord
        unmet by 2.8e-8 m; scaled, every diagonal entry is 1 in size."""
        solution = None
        if np.all(np.isfinite(matrix)) and np.all(np.isfinite(right)):
            diagonal = np.abs(np.diag(matrix))
            scale = np.where(diagonal > 0, 1.0 / np.sqrt(np.where(diagonal > 0, diagonal,
                                                                  1.0)), 1.0)
            try:
                solution = scale * np.linalg.lstsq(scale[:, None] * matrix * scale,
                                                   scale * right, rcond=None)[0]
            except np.linalg.LinAlgError:
                pass
        self._agree(solution is not None and np.all(np.isfinite(solution)))
        return solution

    def _largest(self, step):
        """The largest |component| of ``step`` (n_nodes, 3 or 4) over the ranks, rad (not
        finite where a component is not). Collective."""
        return self.problem.mesh.global_max(float(np.abs(step).max(initial=0.0)))

    def _newton_step(self, frames, g, mu, regularised=False, curvature=None, frozen=False):
        """(omega (n_nodes, 3), dmu (3,)) of the KKT system, or (None, None) where H is
        not positive definite on the constraint set. ``curvature``: multipliers (n_nodes,
        3, 3) for H's curvature term in place of -g / w (the gradient stays the exact
        one). The first step of an attempt on a line whose heights enter the energy (the
        seabed) takes the iteration's: the heights are integrals of the frames over the
        whole line, so an iterate's small errors in angle are errors of metres in height,
        and -g / w there holds the seabed's answer to those (k times them, hundreds of
        times the weight on a cable), which makes H indefinite; the iteration's
        multipliers hold the forces of the state it is near. That step fixes the heights,
        and the next ones are exact Newton steps, but where H is indefinite after a step
        that left errors in height (a first turn of a hundredth of a radian,
        docs/method.md §11), which ``run`` takes again with the iteration's curvature.
        ``frozen``: a chord step, with the matrices and factors of the last exact step,
        and its chord forms' solves (FREEZE_TURN, _keep_kkt; ``run`` takes one only
        where they are kept). Where ``_trusted`` is set (``run``: INERTIA_TURN, a problem
        that solves with J) an exact step is taken without the inertia test."""
        gradient = self._gradient(frames, g, mu)
        self._residual_norm = np.sqrt(self.problem.mesh.global_sum(float(np.sum(gradient**2))))
        self._agree(np.isfinite(self._residual_norm))        # the same sum on every rank
        if curvature is not None:
            self.problem.state.lam[:] = curvature
        hessian = self._jacobian.hessian if frozen else self.problem.second_variation()
        if self._free_roll and not frozen:
            hessian.constrain_roll(frames[:, 2])
        vecs = []                   # every Vec made here, destroyed on the way out
        held = False
        try:
            self._own_test = False
            if self._trusted and not frozen:
                self.verified = False
            elif not frozen:
                if not self._positive_definite(hessian, regularised):
                    if not self._free_roll or (self.reads_positions and curvature is None):
                        # (where the heights enter, ``run`` first takes the step again
                        # with the iteration's curvature, and holds the roll there)
                        return None, None
                    # round sections, nothing clamped: the torque is zero at
                    # equilibrium and the sections' roll nearly free (GJ over the
                    # line), and an iterate's shear couples it to the bending; a step
                    # with each section's roll held, whose test is on the bending
                    # (SecondVariation.hold_roll; docs/stability.md, "The hanging
                    # chain")
                    hessian.hold_roll(frames[:, 2])
                    if not self._positive_definite(hessian, regularised):
                        return None, None
                    held = True
                # a verdict on the state's own H, not on one with another curvature nor
                # on one with the roll held (H itself was found indefinite: the
                # stability test decides)
                self.verified = hessian.decidable and curvature is None and not held
                # what a trusted step next to this one may lean on (INERTIA_TURN): the
                # test of the state's own H, not of one with the iteration's curvature
                # nor with the roll held
                self._own_test = curvature is None and not held
            # the Jacobian with the followers' linearisation, else H's factor
            solver = (self._jacobian if frozen else self._jacobian_of(hessian)) \
                if self.unsymmetric else hessian
            rhs = hessian.to_vec(-gradient)
            vecs.append(rhs)
            if frozen:
                # a chord step: the whole KKT matrix of the last exact step, its chord
                # forms and their solves included, so one right-hand side is solved
                columns, solved, schur = self._kkt
                direction = solver.solve_many([rhs])[0]
                vecs.append(direction)
            else:
                columns = hessian.chord_forms(frames[:, 2]) if self._bordered() else []
                if self._free_roll and self.unsymmetric and self._near:
                    # the roll held by a constraint of the step, its multiplier dropped
                    # (ROLL_TURN)
                    columns.append(hessian.roll_form(frames[:, 2]))
                vecs.extend(columns)
                if columns and hessian.decidable and not self.unsymmetric:
                    # the inertia test solved for a basis of the same forms
                    solved = [solver.solve(rhs)] + hessian.solve_in_constraint_span(columns)
                else:
                    # the step's right-hand side and the forms in one solve
                    solved = solver.solve_many([rhs] + columns)
                vecs.extend(solved)
                direction, solved = solved[0], solved[1:]
                schur = np.array([[c.dot(s) for s in solved] for c in columns])
                if self.unsymmetric:
                    # kept for the chord steps that follow (their Vecs leave ``vecs``)
                    self._keep_kkt(columns, solved, schur, vecs)
            dmu = np.zeros(3)
            if columns:
                # omega = H^-1 (-grad L - C^T dmu) with C omega = -c:
                # (C H^-1 C^T) dmu = c + C H^-1 (-grad L); the roll's c is 0
                residual = np.zeros(len(columns))
                if self._bordered():
                    residual[:3] = self._chord_residual(frames)
                right = residual + np.array([c.dot(direction) for c in columns])
                multipliers = self._small_solve(schur, right)
                direction.maxpy(-multipliers, solved)
                if self._bordered():
                    dmu = multipliers[:3]
            step = hessian.from_vec(direction)
            if self._free_roll:
                self._without_roll(step, frames)
            return step, dmu
        finally:
            for vec in vecs:
                vec.destroy()

    def _keep_kkt(self, columns, solved, schur, vecs):
        """Keep an exact step's chord forms C^T (k Vecs, one a row of C), their solves
        J^-1 C^T and the Schur matrix C J^-1 C^T (k, k) for the chord steps after it
        (_newton_step), the last ones freed; the kept Vecs are taken out of ``vecs``
        (the step's, freed after it)."""
        self._drop_kkt()
        kept = set(map(id, columns + solved))
        vecs[:] = [vec for vec in vecs if id(vec) not in kept]
        self._kkt = (list(columns), list(solved), schur)

    def _drop_kkt(self):
        """Free the kept KKT pieces (_keep_kkt): after an attempt, or for new ones."""
        if self._kkt is not None:
            for vec in self._kkt[0] + self._kkt[1]:
                vec.destroy()
        self._kkt = None

    def _without_roll(self, step, frames):
        """Remove from ``step`` (n_nodes, 3 or 4) its mean turn about the tangents (the
        free roll, __init__), weighted by the node weights: omega_n -= a d3_n with
        a = sum_n w_n omega_n.d3_n / sum_n w_n. Collective."""
        tangents = unit(frames[:, 2])
        w = self.problem.state.node_weights
        along, total = self.problem.mesh.global_sum(np.array([
            float(np.sum(w * np.einsum("nc,nc->n", step[:, :3], tangents))), float(w.sum())]))
        step[:, :3] -= (along / total) * tangents

    def _jacobian_of(self, hessian):
        """The NewtonJacobian at H's state, assembled and factored."""
        if self._jacobian is None:
            self._jacobian = NewtonJacobian(hessian)
        self._jacobian.assemble()
        return self._jacobian

    def _gradient(self, frames, g, mu):
        """grad L at ``frames`` (n_nodes, 3), or (n_nodes, 4) with d/dk on an extensible
        line, 0 where held, from the fields' gradient g (without the chord's share) and
        the chord multiplier mu; tau and lambda are set to the frames and -g / w, the
        state H is assembled at (_set_multipliers)."""
        g = self._set_multipliers(frames, g, mu)
        gradient = np.cross(frames, g).sum(axis=1)           # grad_n L, (n, 3)
        if self.stretch:                                     # (n, 4) with d/dk
            gradient = np.concatenate([gradient, self._strain_gradient(frames, g)[:, None]],
                                      axis=1)
        gradient[~self._free] = 0.0
        return gradient

    def lagrangian_gradient(self, frames, mu):
        """grad L of the module docstring at ``frames`` (rows d1, d2, k d3 at the owned
        nodes) and chord multiplier mu (3,) (ignored when the chord is free), as the
        Newton steps see it, with the state set there (fields, tau = frames, lambda =
        -g / w): ``problem.second_variation()`` then assembles H at the same point (the
        tests compare both with finite differences of the energy)."""
        self.problem.state.set_node_directors(frames)
        g = self.problem.energy_gradient(self._product)
        return self._gradient(frames, g, mu if self._bordered() else np.zeros(3))

    @staticmethod
    def _positive_definite(hessian, regularised=False):
        """Whether H is positive definite on the constraint set (its inertia, §10), with
        the matrix the solves use factored: H itself where its inertia shows no negative
        eigenvalue, so that the steps are exact Newton steps. Where it does, the test is
        made again at -tolerance, whose eigenvalues above are zero to round-off (a free
        roll), and then H + tolerance M is factored for the solves: a shift that would
        slow every step to the rate tolerance / (lowest eigenvalue + tolerance), and the
        tolerance grows like the square of the element count. An eigenvalue that is zero
        exactly (a rigid turn about the chord between pins) goes to the second test only
        where round-off makes its pivot negative; otherwise the unshifted H is used, the
        step's component along that symmetry only turns the rod rigidly, and a step that
        does not shrink ends the attempt. Where the chord forms are dependent (a taut,
        straight rod) H itself must be positive definite: a sufficient condition.
        ``regularised``: only the second test, and H + tolerance M for the solves (an
        extensible line's attempt whose step did not shrink, ``run``)."""
        shifts = (-hessian.tolerance(),) if regularised else (0.0, -hessian.tolerance())
        for shift in shifts:
            if hessian.decidable:
                negative = hessian.negative_directions(shift)
            else:
                hessian.factorise(shift)
                negative = hessian.negative_pivots()
            if negative == 0:
                return True
        return False

    def _chord_residual(self, frames):
        """c = sum_n w_n d3_n - (r(L) - r(0)), (3,)."""
        problem = self.problem
        local = problem.state.node_weights @ frames[:, 2]
        return (problem.mesh.global_sum(local)
                - (problem.end_state.position - problem.start_state.position))

    def _hand_over(self, frames, mu, measured=False):
        """The state as the Uzawa fixed point at ``frames``: fields, r, tau = d,
        lambda = -g / w (with the chord's share in lambda3; 0 at a clamped node) and the
        chord multiplier mu (the internal force n = force beyond - mu reads it), so that
        every output is the Newton state's. ``measured``: returns the stopping
        quantities of the step from the state's fields to ``frames`` (state.Norms, as
        §6 measures an iteration), else None. Collective."""
        problem = self.problem
        state = problem.state
        if measured:
            # the fields before the step, the reference of its change
            problem.global_step.integrate_slope(state)
            state.remember()
        state.set_node_directors(frames)
        problem.global_step.integrate_slope(state)
        if self._bordered():
            state.chord_multiplier = np.array(mu, dtype=float)
        self._set_multipliers(frames, problem.energy_gradient(self._product), mu)
        # a clamped frame is prescribed, not solved for: its multiplier is free, and 0
        # is one the local step keeps (P(R d) = d)
        state.lam[~self._free] = 0.0
        norms = None
        if measured:
            state.take_directors()
            norms = problem.norms()
        state.remember()
        return norms

    def _set_multipliers(self, frames, g, mu):
        """tau = frames and lambda = -g / w with g the gradient of L (the chord's mu w in
        its d3 rows); returns that g, (n_nodes, 3, 3). H is assembled from these."""
        state = self.problem.state
        w = state.node_weights
        g = g.copy()
        g[:, 2] += w[:, None] * mu
        state.tau[:] = frames
        state.lam[:] = -g / w[:, None, None]
        # a flex joint on an extensible end acts in the local step (§12): the Uzawa
        # multipliers leave its gradient out, and its Hessian block is its whole curvature
        for term in self.problem.terms:
            local_gradient = getattr(term, "local_gradient", None)
            if local_gradient is not None:
                local_gradient(state.lam, state, scale=1.0 / w)
        return g

    def least_penalty(self):
        """The R above which the handed-over state is a fixed point of the Uzawa map:
        the local step returns tau = P(R tau + lambda) = P(tau (R I + tau^T lambda))
        only if R I + tau^T lambda (symmetric at a solution) is positive definite at
        every node, i.e. R > the largest -eig(sym(tau_n^T lambda_n)), N.

        On an extensible line (tau rows d1, d2, k d3) the stretched local step's polar
        factor of (b1, b2, k b3) = (R diag(1, 1, k^2) + diag(1, 1, k) P) D, P_ij =
        lambda_i.d_j, is D if R diag(1, 1, k^2) + sym(diag(1, 1, k) P) is positive
        definite: R > -eig of that symmetric part scaled by diag(1, 1, 1/k) on both
        sides; its k is then the same (lambda3.d3 = EA eps)."""
        state = self.problem.state
        product = np.einsum("nik,nil->nkl", state.lam, state.tau)
        if self.stretch:
            k = np.sqrt(np.einsum("nc,nc->n", state.tau[:, 2], state.tau[:, 2]))
            frames = state.tau.copy()
            frames[:, 2] /= k[:, None]
            scale = np.ones((len(k), 3))
            scale[:, 2] = 1.0 / k
            product = np.einsum("nak,nkl,nbl->nab", frames, product, frames) \
                * scale[:, :, None] * scale[:, None, :]
        lowest = np.linalg.eigvalsh(0.5 * (product + product.transpose(0, 2, 1)))[:, 0]
        return self.problem.mesh.global_max(float(-lowest.min(initial=0.0)))

    def destroy(self):
        self._product.destroy()
        self._drop_kkt()
        if self._jacobian is not None:
            self._jacobian.destroy()
