"""The seabed's shapes (environment/bathymetry.py) and the catenary on an incline
(validation/incline_catenary.py): numpy and scipy only."""

import numpy as np
import pytest

from petsc_rod.environment.bathymetry import Grid, Plane, Profile, unit_normal
from petsc_rod.environment.seabed import Seabed
from petsc_rod.scenes.touchdown import grounded_catenary
from petsc_rod.validation.incline_catenary import incline_catenary

POINTS = np.random.default_rng(3).uniform(-20.0, 20.0, size=(50, 2))


def test_a_plane_rises_at_its_slope_along_its_direction():
    e = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    plane = Plane.sloping(np.array([1.0, 2.0]), -5.0, 4.0, e)
    x, y = POINTS.T
    d = (x - 1.0) * e[0] + (y - 2.0) * e[1]
    assert np.abs(plane.height(x, y) - (-5.0 + np.tan(np.radians(4.0)) * d)).max() < 1e-13
    normal = plane.normal(x, y)
    assert np.abs(np.linalg.norm(normal, axis=1) - 1.0).max() < 1e-15
    # normal to the plane's own directions: along e rising tan(4 deg), across e level
    along = np.array([e[0], e[1], np.tan(np.radians(4.0))])
    across = np.array([-e[1], e[0], 0.0])
    assert np.abs(normal @ along).max() < 1e-15 and np.abs(normal @ across).max() < 1e-15
    assert np.degrees(np.arccos(normal[0, 2])) == pytest.approx(4.0, abs=1e-12)
    moved = plane.moved(np.array([10.0, -3.0, 7.0]))
    assert np.abs(moved.height(x - 10.0, y + 3.0) - (plane.height(x, y) - 7.0)).max() < 1e-12


def test_a_profile_is_its_rows_linear_in_between_and_level_beyond_its_slope_smoothed():
    e = np.array([0.6, 0.8])
    profile = Profile(np.zeros(2), e, np.array([0.0, 10.0, 30.0]), np.array([1.0, 3.0, 2.0]))
    d = np.array([-5.0, 0.0, 5.0, 10.0, 20.0, 30.0, 40.0])
    x, y = d * e[0] + 7.0 * e[1], d * e[1] - 7.0 * e[0]        # 7 m across the direction
    assert np.allclose(profile.height(x, y), [1.0, 1.0, 2.0, 3.0, 2.5, 2.0, 2.0],
                       rtol=0, atol=1e-14)
    # the segments' slopes away from the rows; about a row (SMOOTHING x 10 m = 1 m wide)
    # the secant turns from one to the next: halfway at the row itself
    slopes = profile.gradient(x, y) @ e
    assert np.allclose(slopes, [0.0, 0.1, 0.2, 0.075, -0.05, -0.025, 0.0], rtol=0,
                       atol=1e-15)
    d = np.linspace(-1.0, 1.0, 2001)                    # continuous across the row d = 0
    # a ramp of 0.2 over 1 m: 2e-4 per step of 1 mm
    assert np.abs(np.diff(profile.gradient(d * e[0], d * e[1]) @ e)).max() <= 2e-4 + 1e-15
    assert np.abs(profile.gradient(x, y) @ np.array([-e[1], e[0]])).max() < 1e-16
    assert list(profile.covers(x, y)) == [False] + [True] * 5 + [False]


def test_a_grid_is_bilinear_and_exact_on_a_plane():
    xs, ys = np.array([-20.0, -5.0, 3.0, 20.0]), np.array([-20.0, 0.0, 20.0])
    a, b = 0.07, -0.03
    grid = Grid(np.zeros(2), xs, ys, 1.0 + a * xs[:, None] + b * ys[None, :])
    x, y = 0.9 * POINTS.T       # inside: the secant of the gradient does not reach the edge
    assert np.abs(grid.height(x, y) - (1.0 + a * x + b * y)).max() < 1e-14
    assert np.abs(grid.gradient(x, y) - [a, b]).max() < 1e-13
    # across the edge x = 20 the slope along x turns to 0 over 0.8 m (SMOOTHING x 8 m)
    assert grid.gradient(20.0, 0.0)[0] == pytest.approx(a / 2, abs=1e-13)
    assert grid.gradient(20.5, 0.0)[0] == 0.0
    # in one cell, the bilinear form's cross term
    saddle = Grid(np.zeros(2), np.array([0.0, 1.0]), np.array([0.0, 1.0]),
                  np.array([[0.0, 0.0], [0.0, 1.0]]))
    assert saddle.height(0.5, 0.25) == pytest.approx(0.125, abs=1e-16)
    assert np.allclose(saddle.gradient(0.5, 0.25), [0.25, 0.5], rtol=0, atol=1e-15)
    assert not saddle.covers(1.5, 0.5) and saddle.covers(1.0, 0.0)


def test_the_seabed_pushes_normal_to_itself_with_k_times_the_normal_penetration():
    e = np.array([1.0, 0.0])
    seabed = Seabed(0.0, 1e4, Plane.sloping(np.zeros(2), 0.0, 10.0, e))
    r = np.array([[2.0, 1.0, 2.0 * np.tan(np.radians(10.0)) - 0.01], [2.0, 1.0, 5.0]])
    force = seabed.force(r)
    normal = seabed.shape.normal(r[:, 0], r[:, 1])
    depth = 0.01 * np.cos(np.radians(10.0))                   # the normal penetration
    assert np.allclose(force[0], 1e4 * depth * normal[0], rtol=1e-14, atol=0)
    assert seabed.reaction(r)[0] == pytest.approx(1e4 * depth, rel=1e-14)
    assert np.all(force[1] == 0) and seabed.reaction(r)[1] == 0
    flat = Seabed(0.0, 1e4)
    assert np.array_equal(flat.force(r)[:, 2], 1e4 * np.maximum(-r[:, 2], 0.0))


def test_the_incline_catenary_is_the_catenary_with_touchdown_when_level():
    S = np.linspace(0.0, 10.0, 101)
    line = incline_catenary(10.0, 1.0, 0.0, 7.0, 4.0)
    x, z, n, _ = line.at(S)
    r, _, force, (_, touchdown) = grounded_catenary(10.0, [7.0, 0.0, 4.0], 1.0, 0.0, S)
    assert np.abs(x - r[:, 0]).max() < 1e-13 and np.abs(z - r[:, 2]).max() < 1e-13
    assert np.abs(n - force[:, [0, 2]]).max() < 1e-13
    assert line.grounded == pytest.approx(touchdown, abs=1e-12)


@pytest.mark.parametrize("deg, top", [(5.0, (8.0, 4.0)), (-10.0, (7.0, 4.0))])
def test_the_incline_catenary_reaches_its_top_and_balances_the_slope(deg, top):
    alpha = np.radians(deg)
    line = incline_catenary(10.0, 1.0, alpha, *top)
    x, z, n, T = line.at(np.array([0.0, line.grounded / 2, line.grounded, 10.0]))
    assert x[-1] == pytest.approx(top[0], abs=1e-12) and z[-1] == pytest.approx(top[1], abs=1e-12)
    assert z[1] == pytest.approx(x[1] * np.tan(alpha), abs=1e-14)       # on the incline
    # frictionless: the tension grows by w sin(alpha) per metre along the grounded part
    assert (T[2] - T[0]) / line.grounded == pytest.approx(np.sin(alpha), rel=1e-12)
    assert T[0] == pytest.approx(line.anchor_tension, rel=1e-12) and T[0] > 0
    # the suspended part leaves the seabed along it: n at the touchdown along (cos, sin)
    assert n[2, 1] / n[2, 0] == pytest.approx(np.tan(alpha), rel=1e-12)
    with pytest.raises(ValueError, match="taut"):
        incline_catenary(10.0, 1.0, np.radians(5.0), 7.0, 4.0)    # compressed at the anchor


# a grid of uneven spacing with heights sloping in x and y and a bilinear twist in
# every cell: the secant's half widths hx = 0.3 m, hy = 0.5 m
SLOPED_GRID = Grid(np.array([1.0, -2.0]), np.array([-20.0, -6.0, 0.0, 9.0, 20.0]),
                   np.array([-20.0, -5.0, 5.0, 20.0]),
                   np.random.default_rng(5).uniform(-0.8, 0.8, size=(5, 4))
                   + 0.05 * np.array([-20.0, -6.0, 0.0, 9.0, 20.0])[:, None]
                   - 0.03 * np.array([-20.0, -5.0, 5.0, 20.0])[None, :])


def grid_points(grid, near):
    """Points (x, y) of the grid's inside: ``near`` False in the cell 0 < x < 9,
    -5 < y < 5, farther than 0.1 m beyond the secant's reach from its grid lines; True
    within delta / 2 of the grid line x = 0 and of y = 5 (the secant turning there),
    away from the kinks of Dg."""
    rng = np.random.default_rng(11)
    hx, hy = grid._half_widths()
    if near:
        u = rng.uniform(-0.9 * hx, 0.9 * hx, 40)
        v = 5.0 + rng.uniform(-0.9 * hy, 0.9 * hy, 40)
        u, v = np.concatenate([u, u]), np.concatenate([v, rng.uniform(-3.0, 3.0, 40)])
    else:
        u, v = rng.uniform(0.5, 8.5, 40), rng.uniform(-4.3, 4.3, 40)
        assert np.all(np.abs(v) < 5.0 - hy - 0.1)
    return u + grid.origin[0], v + grid.origin[1]


@pytest.mark.parametrize("near", [False, True], ids=["in the cells", "at grid lines"])
def test_a_grid_s_slopes_are_the_differences_of_its_heights_and_its_secant(near):
    """Grid.slopes: grad z_b the interpolant's slope, g the secant gradient, Dg its
    derivative, each against central differences (1e-6 m) of what it is the slope of;
    away from the grid lines g = grad z_b, near one the secant turns (Dg's off the
    cell's own)."""
    grid = SLOPED_GRID
    x, y = grid_points(grid, near)
    rise, g, rate = grid.slopes(x, y)
    assert rise.shape == g.shape == (80 if near else 40, 2) and rate.shape == g.shape + (2,)
    step = 1e-6
    height = np.stack([(grid.height(x + step, y) - grid.height(x - step, y)),
                       (grid.height(x, y + step) - grid.height(x, y - step))], -1) / (2 * step)
    turn = np.stack([(grid.gradient(x + step, y) - grid.gradient(x - step, y)),
                     (grid.gradient(x, y + step) - grid.gradient(x, y - step))], -1) / (2 * step)
    assert np.abs(rise - height).max() < 1e-8
    assert np.array_equal(g, grid.gradient(x, y))
    assert np.abs(rate - turn).max() < 1e-7 * np.abs(rate).max()
    if near:
        assert np.abs(g - rise).max() > 1e-2                  # the secant turns there
        assert np.abs(rate[:, 0, 0]).max() > 1e-2 and np.abs(rate[:, 1, 1]).max() > 1e-2
    else:
        assert np.abs(g - rise).max() < 1e-12
        assert np.abs(rate[:, 0, 0]).max() < 1e-12 and np.abs(rate[:, 1, 0]).max() > 1e-3
    # beyond the edges level across them: the slope across an edge 0, along it the edge's
    beyond = grid.slopes(np.array([30.0]), np.array([0.0]))
    assert beyond[0][0, 0] == 0.0 and beyond[0][0, 1] != 0.0
