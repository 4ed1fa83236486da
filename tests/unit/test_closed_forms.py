"""Tests of petsc_rod.validation.closed_forms against independent numerical solutions.

The cantilever elastica (length L, bending stiffness EI, dead tip force
(0, -P, 0), clamped at s = 0) satisfies, with theta the tangent angle below
the x axis and kappa = theta',

    theta' = kappa,  kappa' = -(P/EI) cos(theta),  x' = cos(theta),  y' = -sin(theta),
    theta(0) = 0,  x(0) = y(0) = 0,  kappa(L) = 0.

The reference solution shoots on kappa(0) with DOP853 (rtol = atol = 1e-12)
and brentq on kappa(L) = 0; kappa(0) lies in (0, P L/EI] because
kappa(0) = (P/EI) int_0^L cos(theta) ds.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from petsc_rod.validation.closed_forms import cantilever_shape, cantilever_tip, twisted_rod

LENGTH = 2.0
BENDING_STIFFNESS = 3.0
LOAD_PARAMETERS = (0.1, 1.0, 3.0, 10.0)


def force_for(load_parameter, length=LENGTH, stiffness=BENDING_STIFFNESS):
    """Return P such that P L^2 / EI equals ``load_parameter``."""
    return load_parameter * stiffness / length**2


def elastica_rhs(_, state, load_over_stiffness):
    """Right-hand side of the planar Kirchhoff ODE for (theta, kappa, x, y)."""
    theta, kappa, _, _ = state
    return [kappa, -load_over_stiffness * np.cos(theta), np.cos(theta), -np.sin(theta)]


def integrate_from_clamp(kappa_at_clamp, length, load_over_stiffness, dense_output=False):
    """Integrate the ODE from s = 0 with theta = x = y = 0 and the given kappa(0)."""
    return solve_ivp(
        elastica_rhs,
        (0.0, length),
        [0.0, kappa_at_clamp, 0.0, 0.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        args=(load_over_stiffness,),
        dense_output=dense_output,
    )


def shooting_solution(length, stiffness, force):
    """Solve the cantilever BVP by shooting; return the solve_ivp result with dense output."""
    load_over_stiffness = force / stiffness

    def tip_curvature(kappa_at_clamp):
        return integrate_from_clamp(kappa_at_clamp, length, load_over_stiffness).y[1, -1]

    kappa_at_clamp = brentq(tip_curvature, 0.0, load_over_stiffness * length, xtol=1e-15, rtol=1e-15)
    return integrate_from_clamp(kappa_at_clamp, length, load_over_stiffness, dense_output=True)


@pytest.fixture(scope="module")
def shooting_solutions():
    """Shooting solutions for each load parameter, keyed by P L^2 / EI."""
    return {
        alpha: shooting_solution(LENGTH, BENDING_STIFFNESS, force_for(alpha)) for alpha in LOAD_PARAMETERS
    }


@pytest.mark.parametrize("load_parameter", LOAD_PARAMETERS)
def test_tip_matches_shooting_solution(load_parameter, shooting_solutions):
    ode = shooting_solutions[load_parameter]
    tip = cantilever_tip(LENGTH, BENDING_STIFFNESS, force_for(load_parameter))
    discrepancy = np.max(np.abs(tip - ode.y[2:, -1])) / LENGTH
    assert discrepancy < 1e-9


@pytest.mark.parametrize("load_parameter", LOAD_PARAMETERS)
def test_shape_matches_shooting_solution_along_the_rod(load_parameter, shooting_solutions):
    ode = shooting_solutions[load_parameter]
    s = np.linspace(0.0, LENGTH, 41)
    theta, x, y = cantilever_shape(LENGTH, BENDING_STIFFNESS, force_for(load_parameter), s)
    reference = ode.sol(s)
    assert np.max(np.abs(theta - reference[0])) < 1e-9
    assert np.max(np.abs(x - reference[2])) / LENGTH < 1e-9
    assert np.max(np.abs(y - reference[3])) / LENGTH < 1e-9


def test_small_load_matches_linear_beam_theory():
    load_parameter = 1e-4
    force = force_for(load_parameter)
    deflection = -cantilever_tip(LENGTH, BENDING_STIFFNESS, force)[1]
    linear_deflection = force * LENGTH**3 / (3.0 * BENDING_STIFFNESS)
    assert abs(deflection / linear_deflection - 1.0) < 1e-3


def relative_error_against_linear_theory(load_parameter):
    """Return delta / (P L^3 / 3 EI) - 1 for the closed-form tip deflection."""
    force = force_for(load_parameter)
    deflection = -cantilever_tip(LENGTH, BENDING_STIFFNESS, force)[1]
    return deflection / (force * LENGTH**3 / (3.0 * BENDING_STIFFNESS)) - 1.0


def test_small_load_error_is_quadratic_in_the_load():
    """delta = (alpha L / 3) (1 - 4 alpha^2 / 35 + O(alpha^4)), alpha = P L^2 / EI.

    Perturbation expansion theta = alpha theta_1 + alpha^3 theta_3 with
    theta_1 = s - s^2/2 (L = 1) and theta_3'' = theta_1^2 / 2,
    theta_3'(1) = 0, theta_3(0) = 0; delta = int_0^1 sin(theta) ds.  The
    deflection is odd in P, so halving the load divides the relative
    error by four.
    """
    load_parameter = 1e-2
    error = relative_error_against_linear_theory(load_parameter)
    error_at_half_load = relative_error_against_linear_theory(0.5 * load_parameter)
    assert error == pytest.approx(-4.0 / 35.0 * load_parameter**2, rel=1e-3)
    assert error / error_at_half_load == pytest.approx(4.0, rel=1e-3)


def test_small_load_horizontal_shortening():
    """L - x_tip = alpha^2 L / 15 + O(alpha^4), from x' = cos(theta) ~ 1 - theta_1^2 alpha^2 / 2."""
    load_parameter = 1e-2
    x_tip = cantilever_tip(LENGTH, BENDING_STIFFNESS, force_for(load_parameter))[0]
    assert (LENGTH - x_tip) / LENGTH == pytest.approx(load_parameter**2 / 15.0, rel=1e-3)


def test_bisshopp_drucker_tabulated_value():
    """P L^2 / EI = 1: (L - x_tip)/L = 0.05643, delta/L = 0.30172 (Bisshopp & Drucker 1945)."""
    x_tip, y_tip = cantilever_tip(LENGTH, BENDING_STIFFNESS, force_for(1.0))
    assert abs((LENGTH - x_tip) / LENGTH - 0.05643) < 5e-6
    assert abs(-y_tip / LENGTH - 0.30172) < 5e-6


@pytest.mark.parametrize("load_parameter", (1e-4, *LOAD_PARAMETERS, 100.0))
def test_shape_at_the_tip_matches_cantilever_tip(load_parameter):
    force = force_for(load_parameter)
    tip = cantilever_tip(LENGTH, BENDING_STIFFNESS, force)
    theta, x, y = cantilever_shape(LENGTH, BENDING_STIFFNESS, force, np.array([0.0, LENGTH]))
    assert np.max(np.abs(np.array([x[-1], y[-1]]) - tip)) / LENGTH < 1e-12
    assert abs(theta[0]) < 1e-12
    assert abs(x[0]) < 1e-12 * LENGTH and abs(y[0]) < 1e-12 * LENGTH


@pytest.mark.parametrize("load_parameter", (1.0, 10.0))
def test_shape_is_arc_length_parametrised_with_free_tip(load_parameter):
    force = force_for(load_parameter)
    s, step = np.linspace(0.0, LENGTH, 20001, retstep=True)
    theta, x, y = cantilever_shape(LENGTH, BENDING_STIFFNESS, force, s)
    dx_ds = np.gradient(x, step, edge_order=2)
    dy_ds = np.gradient(y, step, edge_order=2)
    assert np.max(np.abs(np.hypot(dx_ds, dy_ds) - 1.0)) < 1e-7
    assert np.max(np.abs(dx_ds - np.cos(theta))) < 1e-7
    assert np.max(np.abs(dy_ds + np.sin(theta))) < 1e-7
    tip_curvature = (3.0 * theta[-1] - 4.0 * theta[-2] + theta[-3]) / (2.0 * step)
    clamp_curvature = (-3.0 * theta[0] + 4.0 * theta[1] - theta[2]) / (2.0 * step)
    assert abs(tip_curvature) < 1e-6 * force * LENGTH / BENDING_STIFFNESS
    first_integral_curvature = np.sqrt(2.0 * force / BENDING_STIFFNESS * np.sin(theta[-1]))
    assert clamp_curvature == pytest.approx(first_integral_curvature, rel=1e-6)


def test_shape_keeps_the_shape_of_s():
    s = np.linspace(0.0, LENGTH, 12).reshape(3, 4)
    theta, x, y = cantilever_shape(LENGTH, BENDING_STIFFNESS, force_for(1.0), s)
    assert theta.shape == x.shape == y.shape == (3, 4)
    theta_flat, x_flat, y_flat = cantilever_shape(LENGTH, BENDING_STIFFNESS, force_for(1.0), s.ravel())
    np.testing.assert_array_equal(theta.ravel(), theta_flat)
    np.testing.assert_array_equal(y.ravel(), y_flat)
    scalar = cantilever_shape(LENGTH, BENDING_STIFFNESS, force_for(1.0), 0.5 * LENGTH)
    one_element = cantilever_shape(LENGTH, BENDING_STIFFNESS, force_for(1.0), [0.5 * LENGTH])
    assert all(np.shape(value) == () for value in scalar)
    np.testing.assert_allclose(np.array(scalar), np.array(one_element)[:, 0], rtol=1e-15)


def test_zero_force_leaves_the_rod_straight():
    np.testing.assert_array_equal(cantilever_tip(LENGTH, BENDING_STIFFNESS, 0.0), [LENGTH, 0.0])
    s = np.linspace(0.0, LENGTH, 5)
    theta, x, y = cantilever_shape(LENGTH, BENDING_STIFFNESS, 0.0, s)
    np.testing.assert_array_equal(theta, 0.0)
    np.testing.assert_array_equal(x, s)
    np.testing.assert_array_equal(y, 0.0)


def test_twisted_rod_is_uniform_twist():
    result = twisted_rod(2.0, 5.0, 0.3)
    assert result["u3"] == pytest.approx(0.15, rel=1e-15)
    assert result["torque"] == pytest.approx(0.75, rel=1e-15)


@pytest.mark.parametrize(
    "arguments",
    [(0.0, 1.0, 1.0), (-1.0, 1.0, 1.0), (1.0, 0.0, 1.0), (1.0, -2.0, 1.0), (1.0, 1.0, -0.5), (np.nan, 1.0, 1.0)],
)
def test_cantilever_rejects_bad_input(arguments):
    with pytest.raises(ValueError):
        cantilever_tip(*arguments)
    with pytest.raises(ValueError):
        cantilever_shape(*arguments, [0.0])


def test_shape_rejects_arc_lengths_outside_the_rod():
    with pytest.raises(ValueError):
        cantilever_shape(1.0, 1.0, 1.0, [-0.1, 0.5])
    with pytest.raises(ValueError):
        cantilever_shape(1.0, 1.0, 1.0, [0.5, 1.1])


@pytest.mark.parametrize("arguments", [(0.0, 1.0, 0.1), (1.0, 0.0, 0.1), (1.0, -1.0, 0.1)])
def test_twisted_rod_rejects_bad_input(arguments):
    with pytest.raises(ValueError):
        twisted_rod(*arguments)
