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


def profile_blocks_against_differences(seabed, x, y):
    """max |B_n - dG_n/dr_n by central differences (1e-6 m)| / max |B| of
    Seabed.profile_derivatives at nodes 1 to 10 cm below the seabed at (x, y), and B."""
    z = seabed.heights(x, y) - np.linspace(0.01, 0.1, x.size)
    r = np.stack([x, y, z], axis=1)
    weights = np.linspace(0.5, 1.5, x.size)
    _, B = seabed.profile_derivatives(r, weights)
    step, found = 1e-6, np.zeros_like(B)
    for j in range(3):                              # the three columns of every block
        move = np.zeros(3)
        move[j] = step
        found[:, :, j] = (seabed.profile_derivatives(r + move, weights)[0]
                          - seabed.profile_derivatives(r - move, weights)[0]) / (2 * step)
    return np.abs(B - found).max() / np.abs(B).max(), B


@pytest.mark.parametrize("near", [False, True], ids=["in the cells", "at grid lines"])
def test_a_grid_s_block_is_the_derivative_of_its_force(near):
    """On a grid (test_bathymetry.SLOPED_GRID: slopes in x and y) B_n = dG_n/dr_n with
    grad z_b, g and Dg vectors (Grid.slopes), against central differences of G; not
    symmetric near a grid line (g != grad z_b there), in a cell only by the terms of
    order p of its twist's turn of k_v."""
    from test_bathymetry import SLOPED_GRID, grid_points

    seabed = Seabed(0.0, 1e5, SLOPED_GRID)
    error, B = profile_blocks_against_differences(seabed, *grid_points(SLOPED_GRID, near))
    print(f"B against differences {error:.3g}")
    assert error < 1e-7
    asymmetry = np.abs(B - B.transpose(0, 2, 1)).max() / np.abs(B).max()
    print(f"B - B^T {asymmetry:.3g}")
    assert (asymmetry > 1e-3) if near else (1e-8 < asymmetry < 1e-3)


def test_a_profile_s_block_is_the_derivative_of_its_force():
    """A profile along (0.6, 0.8) with nodes within delta / 2 of a row and away from it:
    its B_n (Profile.slopes' z_b', g, g' as vectors in the plan) against central
    differences of G, as the grid's."""
    from petsc_rod.environment.bathymetry import Profile

    e = np.array([0.6, 0.8])
    profile = Profile(np.zeros(2), e, np.array([0.0, 10.0, 30.0]), np.array([1.0, 3.0, 2.0]))
    d = np.concatenate([10.0 + np.linspace(-0.45, 0.45, 6), np.linspace(2.0, 8.0, 5)])
    seabed = Seabed(0.0, 1e5, profile)
    error, _ = profile_blocks_against_differences(seabed, d * e[0] - 3.0 * e[1],
                                                  d * e[1] + 3.0 * e[0])
    print(f"B against differences {error:.3g}")
    assert error < 1e-7
