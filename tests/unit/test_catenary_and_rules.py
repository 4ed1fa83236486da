"""The rules of the iteration and the catenary start, numpy only: the catenary closed
form and start, the default penalty's scales (the start's tension among them), the
stall projection, and when a penalty is too low."""

import numpy as np
import pytest

from petsc_rod.errors import RodInputError
from petsc_rod.problem.penalty import ADAPT_WINDOW, default_penalty, penalty_too_low
from petsc_rod.iteration.stopping import (STALL_MARGIN, STALL_WINDOW, remaining_iterations,
                                          stalled_projection)
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start, largest_tension
from petsc_rod.validation.closed_forms import catenary


LENGTH, CHORD, LOAD = 3000.0, np.array([2500.0, 0.0, 400.0]), np.array([0.0, 0.0, -1000.0])


def test_catenary_meets_its_ends_and_its_equations():
    """r(0) = 0, r(L) = chord, |r'| = 1, r' = dr/dS and n' = -f (centred differences,
    error O(h^2) with h = 0.03 m), n parallel to r'."""
    S = np.linspace(0.0, LENGTH, 100001)
    r, tangent, force = catenary(LENGTH, CHORD, LOAD, S)
    assert np.abs(r[0]).max() == 0.0
    assert np.abs(r[-1] - CHORD).max() < 1e-8 * LENGTH
    assert np.abs(np.linalg.norm(tangent, axis=1) - 1).max() < 1e-14
    h = S[1] - S[0]
    slope = (r[2:] - r[:-2]) / (2 * h)
    assert np.abs(slope - tangent[1:-1]).max() < 1e-9
    balance = (force[2:] - force[:-2]) / (2 * h) + LOAD
    assert np.abs(balance).max() < 1e-6 * np.abs(LOAD).max()
    assert np.abs(np.cross(force, tangent)).max() < 1e-9 * np.abs(force).max()


def test_catenary_tends_to_the_parabola_when_taut():
    """A nearly taut cable (L = 1.0001 span) sags like the parabola with the same
    length: sag d with L = s + 8 d^2 / 3s, to O(d^3/s^2) relative."""
    span = 100.0
    length = span * 1.0001
    S = np.linspace(0.0, length, 20001)
    r, _, _ = catenary(length, np.array([span, 0.0, 0.0]), LOAD, S)
    sag = -r[:, 2].min()
    parabola = np.sqrt(3 * span * (length - span) / 8)
    assert sag == pytest.approx(parabola, rel=1e-3)


def test_catenary_rejects_impossible_chords():
    with pytest.raises(ValueError):
        catenary(10.0, np.array([10.0, 0.0, 0.0]), LOAD, [0.0])
    with pytest.raises(ValueError):
        catenary(10.0, np.array([0.0, 0.0, 5.0]), LOAD, [0.0])


def test_catenary_start_frame_is_a_right_handed_rotation_with_d3_the_tangent():
    scene = Scene(length=LENGTH, stiffness=[1e5, 1e5, 7.5e4], start="pin", end="pin",
                  end_position=CHORD, load_values=[LOAD])
    S = np.linspace(0.0, LENGTH, 7)
    r, frame, force = catenary_start(scene, 1.0)(S)
    _, tangent, exact_force = catenary(LENGTH, CHORD, LOAD, S)
    assert np.allclose(frame @ np.swapaxes(frame, 1, 2), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(frame), 1.0)
    assert np.allclose(frame[:, 2], tangent)
    assert np.allclose(frame[:, 0], [0.0, 1.0, 0.0])     # normal to the x-z plane
    assert np.allclose(force, exact_force)


def test_catenary_start_needs_held_ends_and_a_load_it_can_hang_under():
    held = dict(length=10.0, stiffness=[1, 1, 1], start="pin", end="pin",
                end_position=[8.0, 0.0, 0.0])
    for scene in (Scene(**dict(held, end="free")),
                  Scene(**held),
                  Scene(**held, load_values=[[0, -1, 0], [0, 0, -2]], load_breaks=[5.0])):
        with pytest.raises(RodInputError):
            catenary_start(scene, 1.0)
    # vertical pieces: the catenary of the sections (section_catenary.py), through both ends
    pieces = Scene(**held, load_values=[[0, 0, -1], [0, 0, -2]], load_breaks=[5.0])
    r, frames, force = catenary_start(pieces, 1.0)(np.array([0.0, 10.0]))
    assert np.allclose(r, [[0.0, 0.0, 0.0], [8.0, 0.0, 0.0]], atol=1e-9)
    assert np.allclose(np.cross(frames[:, 2], force), 0.0, atol=1e-9)    # force along d3


def test_default_penalty_is_the_largest_of_bending_load_and_twist_scales():
    unloaded = Scene(length=20.0, stiffness=[235.0, 360.0, 200.0])
    assert default_penalty(unloaded) == pytest.approx(100 * np.sqrt(200 * 360) / 400)
    heavy = Scene(length=LENGTH, stiffness=[1e5, 1e5, 7.5e4], start="pin", end="pin",
                  end_position=CHORD, load_values=[LOAD])
    assert default_penalty(heavy) == pytest.approx(0.5 * 1000.0 * LENGTH)
    soft = Scene(length=2.0, stiffness=[1.0, 1.0, 0.01])
    assert default_penalty(soft) == pytest.approx(100 * 0.1 / 4)
    pulled = Scene(length=1.0, stiffness=[1, 1, 1], end_force=[0.0, 3e3, 4e3])
    assert default_penalty(pulled) == pytest.approx(2500.0)
    twisted = Scene(length=1.0, stiffness=[1, 1, 1], end="clamp",
                    end_position=[0.9, 0.1, 0.0], end_twist=4 * np.pi)
    assert default_penalty(twisted) == pytest.approx(2 * (4 * np.pi) ** 2)   # M = 4 pi N m
    one_radian = Scene(length=1.0, stiffness=[1, 1, 1], end="clamp", end_twist=1.0)
    assert default_penalty(one_radian) == pytest.approx(100.0)
    soft_torsion = Scene(length=1.0, stiffness=[1, 1, 0.01], end="clamp", end_twist=1.0)
    assert default_penalty(soft_torsion) == pytest.approx(10.0)     # M^2/K1 = 1e-4 N


def test_the_default_penalty_reaches_the_tension_of_a_catenary_start():
    """Ends level and s = 2000 m apart, L = 3000 m, w = 1000 N/m: the catenary's
    parameter a solves L = 2a sinh(s / 2a) (bisection here), its largest tension, at
    the ends, is w sqrt(a^2 + (L/2)^2) (T = w a cosh(x / a), sinh(s / 2a) = L / 2a).
    largest_tension gives it; the default penalty takes it where it is above the other
    scales (here above F / 2 = 1.5e6 N), and keeps F / 2 for a start below it."""
    span, weight = 2000.0, 1000.0
    scene = Scene(length=LENGTH, stiffness=[1e5, 1e5, 7.5e4], start="pin", end="pin",
                  end_position=[span, 0.0, 0.0], load_values=[[0.0, 0.0, -weight]])
    low, high = 1.0, 1e6                      # 2a sinh(s / 2a) falls from inf to s
    for _ in range(200):
        a = 0.5 * (low + high)
        low, high = (a, high) if 2 * a * np.sinh(span / (2 * a)) > LENGTH else (low, a)
    tension = weight * np.hypot(a, LENGTH / 2)
    assert tension > 0.5 * weight * LENGTH
    assert largest_tension(scene) == pytest.approx(tension, rel=1e-9)
    assert default_penalty(scene, largest_tension(scene)) == pytest.approx(tension, rel=1e-9)
    assert default_penalty(scene, 1.0) == pytest.approx(0.5 * weight * LENGTH)


def test_stall_projection():
    """Creeping by 0.1% per window stalls; halving per window does not, unless
    STALL_MARGIN times the budget is too small for the windows it needs; no progress
    stalls only over two windows in a row; already below target never stalls."""
    n = 3 * STALL_WINDOW
    creeping = list(4.6e-8 * (1 - 1e-6) ** np.arange(n))
    assert stalled_projection(creeping, 1e-8, budget=10**5)
    halving = list(1e-6 * 0.5 ** (np.arange(n) / STALL_WINDOW))
    needed = np.log2(1.25e-7 / 1e-8) * STALL_WINDOW          # 3.6 windows
    assert not stalled_projection(halving, 1e-8, budget=needed / STALL_MARGIN * 1.01)
    assert stalled_projection(halving, 1e-8, budget=needed / STALL_MARGIN * 0.99)
    assert not stalled_projection(halving, 1e-3, budget=1)
    assert not stalled_projection(creeping[:n - 1], 1e-8, budget=1)
    flat_then_falling = [1e-6] * (2 * STALL_WINDOW) + list(1e-6 * 0.5 ** (np.arange(
        STALL_WINDOW) / STALL_WINDOW))
    assert not stalled_projection(flat_then_falling, 1e-8, budget=10**6)
    assert stalled_projection([1e-6] * n, 1e-8, budget=10**6)


def test_remaining_iterations_of_a_geometric_decay():
    """Change and residual falling by 10 every 4 iterations from 1e-2 and 1e-3 (tests at
    1e-9): the distance to the tests, max(change / rtol, residual / ctol), is 1e7 at
    iteration 0, so 28 iterations are needed in all; after 16 rows, 12 remain. No fall,
    or too short a history, gives inf; a history that already meets both, 0."""
    rate = 10 ** (-1 / 4)
    history = [(1e-2 * rate**k, 1e-3 * rate**k, 0.0) for k in range(17)]
    assert remaining_iterations(history, 1e-9, 1e-9) == pytest.approx(12.0)
    assert remaining_iterations(history[:12], 1e-9, 1e-9) == np.inf
    flat = [(1e-3, 1e-3, 0.0)] * 20
    assert remaining_iterations(flat, 1e-9, 1e-9) == np.inf
    done = [(1e-10, 1e-10, 0.0)] * 20
    assert remaining_iterations(done, 1e-9, 1e-9) == 0.0


def test_penalty_too_low_needs_a_low_penalty_and_a_stuck_residual():
    stuck = [(1.0, 0.1 * 0.999**k, 0.0) for k in range(ADAPT_WINDOW + 1)]   # 0.82 per window
    falling = [(1.0, 0.1 * 0.99**k, 0.0) for k in range(ADAPT_WINDOW + 1)]  # 0.13 per window
    assert penalty_too_low(stuck, 1.0, 100.0)
    assert not penalty_too_low(falling, 1.0, 100.0)
    assert not penalty_too_low(stuck, 10.0, 100.0)          # a tenth of the scale: kept
    assert not penalty_too_low(stuck[:ADAPT_WINDOW], 1.0, 100.0)
