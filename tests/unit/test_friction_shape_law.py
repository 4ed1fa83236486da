"""Seabed friction's law on a seabed profile or grid (physics/friction.py: the plane's law
with each node's secant gradient g(x), FrictionTerm._plane_law and _shape_rates): its
derivative in the node's position (x, y, z), the Newton steps' block, against central
differences of the law itself, at random grounded nodes, some within the secant's
turn of a row or grid line, sticking and sliding. On a grid whose cells twist
(z = 0.07 x + 0.05 y + 0.4 sin(x / 3) cos(y / 4) sampled every 5 m) and on a profile of
turning slopes. Measured: 1.6e-9 of the largest entry on the grid, 1.2e-9 on the
profile (the differences' round-off); with the turn of g left out (Dg = 0: the plane's
block with each node's g, what a held line on a grid lacked) 6.9e-2 and 3.4e-2."""

from types import SimpleNamespace

import numpy as np
import pytest

from petsc_rod.environment.bathymetry import Grid, Profile
from petsc_rod.environment.seabed import Friction, Seabed
from petsc_rod.physics.friction import FrictionTerm

XS, YS = np.linspace(-5.0, 15.0, 5), np.linspace(-10.0, 10.0, 5)
X, Y = np.meshgrid(XS, YS, indexing="ij")
SHAPES = {
    "grid": Grid(np.zeros(2), XS, YS,
                 0.07 * X + 0.05 * Y + 0.4 * np.sin(X / 3.0) * np.cos(Y / 4.0)),
    "profile": Profile(np.zeros(2), np.array([0.6, 0.8]), np.array([-20.0, 0.0, 2.0, 5.0, 30.0]),
                       np.array([0.0, 0.5, 0.6, 0.4, 1.0])),
}
FRICTION = Friction(0.5, 0.5, 1e2)


def law(shape, turn=True):
    """(nodes r (n, 3), the law F(r) -> (-w F, -w dF/dx, -w dF/dz)) at 400 random
    nodes up to 1 mm above and 2 mm below the seabed, their anchors 5 mm off (N(0, 5e-3)
    m), with unit weights; ``turn`` False: the plane's block with each node's g."""
    rng = np.random.default_rng(1)
    seabed = Seabed(0.0, 1e3, shape, FRICTION)
    n = 400
    x, y = rng.uniform(-3.0, 13.0, n), rng.uniform(-8.0, 8.0, n)
    # a quarter within 0.2 m of a grid line along x, a quarter along y (the turn's width
    # is 0.5 m about them)
    x[:100] = np.round(x[:100] / 5.0) * 5.0 + rng.uniform(-0.2, 0.2, 100)
    y[100:200] = np.round(y[100:200] / 5.0) * 5.0 + rng.uniform(-0.2, 0.2, 100)
    r = np.stack([x, y, seabed.heights(x, y) - rng.uniform(-1e-3, 2e-3, n)], axis=1)
    anchors = r[:, :2] + rng.normal(0.0, 5e-3, (n, 2))
    term = SimpleNamespace(seabed_term=SimpleNamespace(seabed=seabed), friction=FRICTION)
    if turn:
        term._shape_rates = lambda *args: FrictionTerm._shape_rates(term, *args)
    else:
        term._shape_rates = lambda r, d, g, cosine, metric: (g, np.zeros((len(g), 2, 2)),
                                                             metric)
    return r, lambda at: FrictionTerm._plane_law(term, at, at[:, :2] - anchors, np.ones(n))


def relative_error(shape, turn=True, step=1e-7):
    """max |dF/dr - central differences| over the largest entry, and how many nodes
    stick and slide (the law's block on z is 0 where a node sticks)."""
    r, at = law(shape, turn)
    _, in_x, in_z = at(r)
    exact = np.concatenate([in_x, in_z[:, :, None]], axis=2)
    numeric = np.zeros_like(exact)
    for j in range(3):
        move = np.zeros(3)
        move[j] = step
        numeric[:, :, j] = (at(r + move)[0] - at(r - move)[0]) / (2 * step)
    grounded = np.abs(exact).sum(axis=(1, 2)) > 0
    slide = np.abs(in_z).sum(axis=1) > 0
    return (np.abs(numeric - exact).max() / np.abs(exact).max(),
            np.count_nonzero(grounded & ~slide), np.count_nonzero(slide))


@pytest.mark.parametrize("shape", list(SHAPES))
def test_the_block_is_the_derivative_of_the_law(shape):
    error, stick, slide = relative_error(SHAPES[shape])
    assert stick > 20 and slide > 20
    assert error < 1e-8


@pytest.mark.parametrize("shape", list(SHAPES))
def test_the_turn_of_the_gradient_matters(shape):
    assert relative_error(SHAPES[shape], turn=False)[0] > 1e-2
