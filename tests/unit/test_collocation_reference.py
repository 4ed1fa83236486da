"""The collocation reference (petsc_rod/validation/reference.py): numpy/scipy only, no
PETSc, no MPI.

Under ``mpiexec -n 2`` every rank runs the same serial computations (nothing here is
collective). The paper scene's twisted branch is started from a shooting guess built from
six rounded clamp reactions (``TWISTED_CLAMP_FORCE`` in tests/helpers.py), so the tests need no data file;
the comparison with a petsc_rod result file runs only where that file exists.
"""

import os
import tempfile

import numpy as np
import pytest

from helpers import PAPER_END as END, PAPER_END_X, PAPER_LENGTH, PAPER_STIFFNESS, twisted_paper_reference
from petsc_rod.validation import reference as ref
from petsc_rod.validation.closed_forms import cantilever_shape, cantilever_tip

END_X = PAPER_END_X


@pytest.fixture(scope="module")
def twisted():
    return twisted_paper_reference()


@pytest.fixture(scope="module")
def planar():
    return ref.solve_paper_scene(END_X, ref.planar_guess(END_X), stiffness=PAPER_STIFFNESS,
                                 tol=1e-10)


@pytest.fixture(scope="module")
def cantilever():
    return ref.solve_cantilever_bvp(1.0, 1.0, 3.0, tol=1e-10)


def _moment_balance_error(result):
    """|m(0) - m(L) - r(L) x n(L)| / |m(0)| (docs/method.md §9, no distributed load)."""
    balance = result.m[-1] + np.cross(result.r[-1], result.n[-1])
    return np.linalg.norm(result.m[0] - balance) / np.linalg.norm(result.m[0])


def test_clamp_quaternion_and_frame_round_trip():
    q = ref.quaternion_from_frame(ref.PAPER_CLAMP_FRAME)
    assert np.allclose(q, 0.5, atol=1e-15)
    rng = np.random.default_rng(1)
    quaternions = rng.standard_normal((5, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    frames = ref.frame_from_quaternion(quaternions)
    assert np.allclose(np.einsum("kij,klj->kil", frames, frames), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(frames), 1.0, atol=1e-14)
    back = ref.quaternion_from_frame(frames)
    same = np.abs(np.sum(back * quaternions, axis=1))
    assert np.allclose(same, 1.0, atol=1e-14)


def test_cantilever_tip_matches_closed_form(cantilever):
    assert cantilever.status == 0, cantilever.message
    expected = cantilever_tip(1.0, 1.0, 3.0)
    assert np.max(np.abs(cantilever.r[-1, :2] - expected)) < 1e-8
    assert abs(cantilever.r[-1, 2]) < 1e-12
    assert np.allclose(cantilever.n[-1], [0.0, -3.0, 0.0], atol=1e-12)
    assert np.allclose(cantilever.m[-1], 0.0, atol=1e-12)


def test_cantilever_shape_matches_closed_form(cantilever):
    s = np.linspace(0.0, 1.0, 11)
    theta, x, y = cantilever_shape(1.0, 1.0, 3.0, s)
    state = cantilever.sample(s)
    assert np.max(np.abs(state["r"][:, 0] - x)) < 1e-8
    assert np.max(np.abs(state["r"][:, 1] - y)) < 1e-8
    tangent = np.stack([np.cos(theta), -np.sin(theta)], axis=1)
    assert np.max(np.abs(state["d3"][:, :2] - tangent)) < 1e-8


def test_cantilever_moment_balance(cantilever):
    assert _moment_balance_error(cantilever) < 1e-8


def test_paper_twisted_branch_converges_and_satisfies_boundary_conditions(twisted):
    assert twisted.status == 0, twisted.message
    assert twisted.max_residual <= 1e-10
    assert np.allclose(twisted.r[0], 0.0, atol=1e-12)
    clamp = np.stack([twisted.d1[0], twisted.d2[0], twisted.d3[0]])
    assert np.allclose(clamp, ref.PAPER_CLAMP_FRAME, atol=1e-12)
    assert np.allclose(twisted.r[-1], END, atol=1e-10)
    assert np.allclose(twisted.m[-1], 0.0, atol=1e-10)
    assert twisted.quaternion_norm_error < 1e-8
    # inextensible: |r'| = |d3| = 1 and r' = d3 along the interpolant
    s = np.linspace(0.0, PAPER_LENGTH, 401)
    state = twisted.sample(s)
    assert np.allclose(np.linalg.norm(state["d3"], axis=1), 1.0, atol=1e-14)
    assert np.allclose(twisted.sol(s, 1)[0:3].T, state["d3"], atol=1e-9)


def test_paper_twisted_branch_is_the_twisted_one(twisted):
    # petsc_rod (80 elements): u3(0) = 0.04605, W = 40.5314; mirror image allowed
    assert abs(abs(twisted.u[0, 2]) - 0.04605) < 2e-5
    assert np.max(np.abs(twisted.r[:, 2])) > 1.0
    assert abs(ref.energy(twisted) - 40.5314) < 1e-3


def test_paper_planar_branch_is_planar_and_has_higher_energy(twisted, planar):
    assert planar.status == 0, planar.message
    assert np.allclose(planar.r[-1], END, atol=1e-10)
    assert np.max(np.abs(planar.r[:, 2])) < 1e-12
    assert np.max(np.abs(planar.u[:, [0, 2]])) < 1e-12
    assert np.allclose(planar.d2, [0.0, 0.0, 1.0], atol=1e-12)
    assert ref.energy(twisted) < ref.energy(planar) - 5.0


def test_paper_moment_balance(twisted, planar):
    assert _moment_balance_error(twisted) < 1e-8
    assert _moment_balance_error(planar) < 1e-8


def test_energy_derivative_is_the_end_reaction(twisted):
    """dW/dX_F = n(L) . (1, -1, 0): the pinned end's reaction is the energy's gradient
    with respect to the end position, which ties the force n to the strains u
    independently of the moment balance (central difference, error O(h^2))."""
    h = 1e-2
    energies = [ref.energy(ref.solve_paper_scene(END_X + sign * h, twisted,
                                                 stiffness=PAPER_STIFFNESS, tol=1e-9))
                for sign in (1.0, -1.0)]
    slope = (energies[0] - energies[1]) / (2 * h)
    reaction = twisted.n[-1] @ np.array([1.0, -1.0, 0.0])
    assert abs(slope - reaction) < 1e-5 * abs(reaction)


def test_self_check_difference_is_below_1e_8(twisted):
    check = ref.self_check(twisted)
    assert check["coarse_status"] == 0 and check["fine_status"] == 0
    assert check["position"] < 1e-8
    assert check["frame"] < 1e-8
    assert check["end_force"] < 1e-8
    assert check["energy"] < 1e-8


def test_initial_guess_from_result_reads_a_result_file(twisted):
    h5py = pytest.importorskip("h5py")
    s = np.linspace(0.0, PAPER_LENGTH, 41)
    state = twisted.sample(s)
    with tempfile.TemporaryDirectory() as folder:  # one per process: no MPI coordination
        path = os.path.join(folder, "result.h5")
        with h5py.File(path, "w") as f:
            f["S"] = s
            for key in ("r", "d1", "d2", "d3", "u", "m", "n"):
                f[key] = state[key]
            f.attrs["energy"] = ref.energy(twisted)
            f.attrs["options"] = "-rod_length 20\n-rod_stiffness 235,360,200"
        guess = ref.initial_guess_from_result(path)
    assert np.allclose(guess["stiffness"], PAPER_STIFFNESS)
    assert np.allclose(guess["frames"][:, 2], state["d3"])
    result = ref.solve_rod_bvp(PAPER_LENGTH, guess["stiffness"], END, guess["S"], guess["r"],
                               guess["frames"], guess["n"], guess["m"], tol=1e-10)
    assert result.status == 0
    assert abs(result.u[0, 2] - twisted.u[0, 2]) < 1e-10
    # trapezoidal energy of the vertex samples: second order in h = 0.5
    assert abs(ref.energy(guess) - ref.energy(twisted)) < 0.1


