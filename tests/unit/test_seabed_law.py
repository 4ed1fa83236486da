"""The seabed's contact law k (z_b - z)_+ as one object (environment/seabed.py Seabed):
its penetration, spring, derivatives and energy agree with each other, and on a slope
the reaction the global step's contact computes from its lagged k_v is the seabed's."""

import numpy as np
import pytest

from petsc_rod.environment.bathymetry import Plane
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
