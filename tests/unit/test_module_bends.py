"""The global hog and sag bend radii over a module pitch (quantities/module_bends.py; no
PETSc): a line in the x-z plane made of straight pieces kinked every pitch p, the
tangent turning by p / R at each kink, a hog arc of R = 20 m then a sag arc of R = 35 m:
the turn over any window of length p is one kink's, so the global radii are 20 and 35 m,
while the local radius at a kink (the kink's own curvature, turned within 0.25 m) is
0.25 R / p: 2 m and 3.5 m."""

import numpy as np
import pytest

from petsc_rod.quantities.module_bends import bend_numbers, module_pitch, window_bend_radii

PITCH, HOG, SAG, KINK = 2.5, 20.0, 35.0, 0.25
S = np.linspace(0.0, 50.0, 2001)                 # h = 0.025 m
# the kinks between vertices, p (k + 1/2) + h / 2; a hog arc up to 25 m, then a sag arc
KINKS = PITCH * (np.arange(20) + 0.5) + 0.0125
TURNS = np.where(KINKS < 25.0, -PITCH / HOG, PITCH / SAG)


def line():
    """(S, unit tangents, u, d1, d2) of the kinked line: t = (cos phi, 0, sin phi),
    d1 = (-sin phi, 0, cos phi), d2 = (0, -1, 0), so dt/dS = phi' d1 (u2 = phi'); the
    kink's turn given to the two vertices around it as a curvature over KINK."""
    phi = 0.3 + (TURNS[None, :] * (S[:, None] > KINKS[None, :])).sum(axis=1)
    tangent = np.column_stack([np.cos(phi), np.zeros_like(phi), np.sin(phi)])
    d1 = np.column_stack([-np.sin(phi), np.zeros_like(phi), np.cos(phi)])
    d2 = np.tile([0.0, -1.0, 0.0], (S.size, 1))
    u = np.zeros((S.size, 3))
    nearest = np.searchsorted(S, KINKS)
    u[nearest, 1] = u[nearest - 1, 1] = TURNS / KINK
    return S, tangent, u, d1, d2


def test_the_pitch_is_the_median_spacing():
    assert module_pitch(np.array([1.0, 3.5, 6.0, 8.5, 20.0])) == 2.5
    assert np.isnan(module_pitch(np.array([4.0])))


def test_a_kinked_arc_has_its_arc_radius_over_a_pitch():
    S, tangent, u, d1, d2 = line()
    radius, side, centres = window_bend_radii(S, tangent, PITCH)
    hog = (centres > PITCH) & (centres < 25.0 - PITCH)
    sag = (centres > 25.0 + PITCH) & (centres < 50.0 - PITCH)
    np.testing.assert_allclose(radius[hog], HOG, rtol=1e-9)
    np.testing.assert_allclose(radius[sag], SAG, rtol=1e-9)
    assert np.all(side[hog] == -1) and np.all(side[sag] == 1)
    numbers = bend_numbers(S, tangent, u, d1, d2, PITCH)
    assert numbers["global_hog_bend_radius"] == pytest.approx(HOG, rel=1e-9)
    assert numbers["global_sag_bend_radius"] == pytest.approx(SAG, rel=1e-9)
    assert 1.25 <= numbers["global_hog_bend_radius_S"] <= 25.0
    assert 25.0 <= numbers["global_sag_bend_radius_S"] <= 48.75
    # the local radius, the kinks': 2 m in the hog, 3.5 m in the sag
    assert numbers["local_hog_bend_radius"] == pytest.approx(KINK * HOG / PITCH, rel=1e-12)
    assert numbers["local_sag_bend_radius"] == pytest.approx(KINK * SAG / PITCH, rel=1e-12)
    assert numbers["local_hog_bend_radius_S"] < 25.0 < numbers["local_sag_bend_radius_S"]


def test_a_straight_line_has_no_bend():
    tangent = np.tile([1.0, 0.0, 0.0], (S.size, 1))
    radius, side, _ = window_bend_radii(S, tangent, PITCH)
    assert np.all(np.isinf(radius)) and np.all(side == 0)
    numbers = bend_numbers(S, tangent, np.zeros((S.size, 3)), np.tile([0.0, 0, 1], (S.size, 1)),
                           np.tile([0.0, -1, 0], (S.size, 1)), PITCH)
    assert numbers["global_hog_bend_radius"] == np.inf
    assert np.isnan(numbers["global_sag_bend_radius_S"])
