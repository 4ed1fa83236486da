"""The seabed's contact law k (z_b - z)_+ as one object (environment/seabed.py Seabed):
its penetration, spring, derivatives and energy agree with each other, and on a slope
the reaction the global step's contact computes from its lagged k_v is the seabed's."""

import numpy as np
import pytest

from petsc_rod.environment.bathymetry import Plane, Profile
from petsc_rod.environment.seabed import Seabed

K = 1e4


def test_the_law_is_k_times_the_penetration_below_the_seabed_and_nothing_above():
    seabed = Seabed(-1.0, K)
    z = np.array([-1.5, -1.0, -0.5])
    assert np.array_equal(seabed.penetration(z), [0.5, 0.0, 0.0])
    assert np.array_equal(seabed.push(z), [0.5 * K, 0.0, 0.0])
    assert np.array_equal(seabed.in_contact(z), [True, False, False])
    # an explicit base and stiffness (the contact's lagged z_b and k_v at its nodes)
    assert np.array_equal(seabed.push(z, base=np.array([0.0, -2.0, 0.0]), stiffness=2.0),
                          [3.0, 0.0, 1.0])


def test_the_height_derivatives_are_those_of_the_energy():
    seabed = Seabed(-1.0, K)
    z = np.array([-1.3, -1.1, -0.9, -0.2])
    weights = np.array([0.1, 0.4, 0.2, 0.3])
    first, second = seabed.height_derivatives(z, weights)

    def energy(heights):
        r = np.zeros((heights.size, 3))
        r[:, 2] = heights
        return seabed.energy(r, weights)

    h = 1e-6
    for n in range(z.size):
        step = np.zeros_like(z)
        step[n] = h
        numeric = (energy(z + step) - energy(z - step)) / (2 * h)
        assert first[n] == pytest.approx(numeric, rel=1e-7, abs=1e-9)
    assert np.array_equal(second, K * weights * [1, 1, 0, 0])
    assert energy(z) == pytest.approx(0.5 * K * (0.1 * 0.3**2 + 0.4 * 0.1**2), rel=1e-14)


def test_on_a_slope_the_contact_s_reaction_from_its_lagged_spring_is_the_seabed_s():
    slope = np.radians(10.0)
    seabed = Seabed(0.0, K, Plane.sloping(np.zeros(2), 0.0, 10.0, np.array([1.0, 0.0])))
    x = np.array([1.0, 2.0, 3.0])
    base = seabed.heights(x, np.zeros(3))
    r = np.stack([x, np.zeros(3), base + np.array([-0.02, -0.01, 0.5])], axis=1)
    g = seabed.gradients(x, np.zeros(3))
    k_v = seabed.vertical_stiffness(g)
    assert k_v == pytest.approx(np.full(3, K * np.cos(slope)**2), rel=1e-14)
    push = seabed.push(r[:, 2], base, k_v)                  # what the contact carries
    assert np.allclose(seabed.normal_force(push, g), seabed.force(r), rtol=1e-14, atol=0)
    assert np.allclose(push * seabed.slope_factor(g), seabed.reaction(r), rtol=1e-14,
                       atol=0)
    assert seabed.reaction(r)[0] == pytest.approx(K * 0.02 * np.cos(slope), rel=1e-14)
    assert seabed.reaction(r)[2] == 0.0


@pytest.mark.parametrize("direction", [(1.0, 0.0), (0.6, -0.8)])
def test_on_a_profile_the_position_derivatives_are_those_of_the_energy(direction):
    """Seabed.position_derivatives on a profile (its height smoothed at the rows, the
    curvature's terms in the Hessian) against central differences of energy(); the
    force the seabed reports (the lagged push's law, normal_force with the bend) is
    minus the energy's gradient per metre, also where k_v changes along a row."""
    e = np.array(direction)
    profile = Profile(np.zeros(2), e, np.array([-10.0, 0.0, 10.0]),
                      np.array([0.0, 1.0, 4.0]))            # slope jump 0.2 at d = 0
    seabed = Seabed(0.0, K, profile)
    d = np.array([-0.3, -0.1, 0.05, 0.4, 3.0, 9.9, 10.2])  # within delta/2 = 0.5 of rows
    across = np.array([-e[1], e[0]]) * 2.0
    r = np.stack([d * e[0] + across[0], d * e[1] + across[1],
                  seabed.heights(d * e[0], d * e[1]) - 0.05], axis=1)
    r[-1, 2] += 0.5                                         # one node above the seabed
    weights = np.linspace(0.2, 0.5, d.size)
    first, second = seabed.position_derivatives(r, weights)
    assert np.any(np.abs(profile.curvature(r[:, 0], r[:, 1])) > 0.1)
    step = 1e-6
    for c in range(3):
        shift = np.zeros_like(r)
        shift[:, c] = step
        energies = [np.array([seabed.energy(r[n:n + 1] + s * shift[n:n + 1],
                                            weights[n:n + 1]) for n in range(d.size)])
                    for s in (1.0, -1.0)]
        numeric = (energies[0] - energies[1]) / (2 * step)
        assert np.allclose(first[:, c], numeric, rtol=1e-6, atol=1e-9 * K)
        grads = [seabed.position_derivatives(r + s * shift, weights)[0] for s in (1.0, -1.0)]
        assert np.allclose(second[:, :, c], (grads[0] - grads[1]) / (2 * step),
                           rtol=1e-6, atol=1e-7 * K)
    assert np.allclose(seabed.force(r) * weights[:, None], -first, rtol=1e-12,
                       atol=1e-12 * K)
