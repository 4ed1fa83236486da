"""The pipe's stresses (quantities/stresses.py, docs/riser.md §2c), the angles of the line's
results (quantities/line_results.py) and the regions (quantities/regions.py) against hand
calculations."""

import numpy as np
import pytest

from petsc_rod.quantities.line_results import azimuth, declination
from petsc_rod.quantities.regions import region_bounds
from petsc_rod.quantities.stresses import lame_stresses, pipe_von_mises, von_mises

# The 10-inch riser of options/line_types/steel_riser.txt: od 273.1 mm, id 231.9 mm.
R_O, R_I = 0.2731 / 2, 0.2319 / 2


def test_lame_hoop_and_radial_stresses_by_hand():
    """Internal pressure only, p_i = 10 MPa, p_e = 0: at the bore
    s_h = p_i (r_o^2 + r_i^2) / (r_o^2 - r_i^2) = 1e7 (0.018646 + 0.013444) / 0.005202
    = 61.69 MPa and s_r = -p_i; at the outer fibre s_h = 2 p_i r_i^2 / (r_o^2 - r_i^2)
    = 51.69 MPa and s_r = 0. External pressure only, p_e = 15 MPa: at the outer fibre
    s_h = -p_e (r_o^2 + r_i^2) / (r_o^2 - r_i^2) = -92.54 MPa, s_r = -p_e. The thin-wall
    limit: r_i = 0.999 r_o gives the mean p D / 2 t within 0.1 %."""
    span = R_O**2 - R_I**2
    hoop, radial = lame_stresses(1e7, 0.0, R_I, R_O, R_I)
    assert hoop == pytest.approx(1e7 * (R_O**2 + R_I**2) / span, rel=1e-14)
    assert hoop == pytest.approx(61.69e6, rel=1e-3)
    assert radial == pytest.approx(-1e7, rel=1e-14)
    hoop, radial = lame_stresses(1e7, 0.0, R_I, R_O, R_O)
    assert hoop == pytest.approx(2e7 * R_I**2 / span, rel=1e-14)
    assert abs(radial) < 1e-6
    hoop, radial = lame_stresses(0.0, 15e6, R_I, R_O, R_O)
    assert hoop == pytest.approx(-15e6 * (R_O**2 + R_I**2) / span, rel=1e-14)
    assert hoop == pytest.approx(-92.54e6, rel=1e-3)
    assert radial == pytest.approx(-15e6, rel=1e-14)
    thin = 0.999
    hoop, _ = lame_stresses(1e6, 0.0, thin, 1.0, (1 + thin) / 2)
    assert hoop == pytest.approx(1e6 * 2 * thin / (2 * (1 - thin)), rel=1e-3)


def test_von_mises_by_hand():
    """Uniaxial: |s|. Pure shear: sqrt(3) tau. Equal biaxial s, s, 0: s. And the
    riser's top with T_w = 2.668 MN, p_i = 10 MPa, no moment: A = 0.016341 m^2, s_a =
    163.27 MPa; at the bore s_h = 61.69, s_r = -10 MPa: s_vm = sqrt(163.27^2 + 61.69^2 +
    10^2 - 163.27 61.69 + 61.69 10 + 10 163.27) = 150.8 MPa, above the outer fibre's
    sqrt(163.27^2 + 51.69^2 - 163.27 51.69) = 144.5 MPa."""
    assert von_mises(5.0, 0.0, 0.0, 0.0) == pytest.approx(5.0, rel=1e-15)
    assert von_mises(0.0, 0.0, 0.0, 2.0) == pytest.approx(2 * np.sqrt(3), rel=1e-15)
    assert von_mises(3.0, 3.0, 0.0, 0.0) == pytest.approx(3.0, rel=1e-15)
    wall, p_i = 2.668e6, 1e7
    area = np.pi * (R_O**2 - R_I**2)
    axial = wall / area
    assert axial == pytest.approx(163.27e6, rel=1e-3)
    hoop, radial = lame_stresses(p_i, 0.0, R_I, R_O, R_I)
    bore = np.sqrt(axial**2 + hoop**2 + radial**2 - axial * hoop - hoop * radial
                   - radial * axial)
    assert bore == pytest.approx(150.8e6, rel=1e-3)
    hoop, radial = lame_stresses(p_i, 0.0, R_I, R_O, R_O)
    assert von_mises(axial, hoop, radial, 0.0) == pytest.approx(144.5e6, rel=1e-3)
    got = pipe_von_mises(np.array([wall]), np.array([0.0]), np.array([0.0]),
                         np.array([p_i]), np.array([0.0]), np.array([2 * R_O]),
                         np.array([2 * R_I]))
    assert got[0] == pytest.approx(bore, rel=1e-14)


def test_bending_and_torsion_at_the_extreme_fibre():
    """No tension, no pressure: a moment M gives s_a = M r_o / I at the outer fibre
    (I = pi (r_o^4 - r_i^4) / 4), von Mises the same; a torque Q alone gives
    sqrt(3) Q r_o / J, J = 2 I. A pipe without a bore (id 0) has no stress: NaN."""
    second = np.pi * (R_O**4 - R_I**4) / 4
    one = np.ones(1)
    bent = pipe_von_mises(0 * one, 1e5 * one, 0 * one, 0 * one, 0 * one, 2 * R_O * one,
                          2 * R_I * one)
    assert bent[0] == pytest.approx(1e5 * R_O / second, rel=1e-14)
    twisted = pipe_von_mises(0 * one, 0 * one, 1e5 * one, 0 * one, 0 * one,
                             2 * R_O * one, 2 * R_I * one)
    assert twisted[0] == pytest.approx(np.sqrt(3) * 1e5 * R_O / (2 * second), rel=1e-14)
    solid = pipe_von_mises(one, one, one, one, one, one, 0 * one)
    assert np.isnan(solid[0])


def test_declination_and_azimuth_by_hand():
    """Up: 0 deg; horizontal: 90; down: 180. A tangent in the x-z plane toward +x has
    azimuth 0, toward -x 180; toward +y 90; a vertical one none (NaN)."""
    np.testing.assert_allclose(declination(np.array([[0, 0, 1.0], [1.0, 0, 0],
                                                     [0, 0, -1.0]])), [0, 90, 180],
                               atol=1e-12)
    assert declination(np.array([np.sin(0.3), 0, np.cos(0.3)])) == pytest.approx(
        np.degrees(0.3), rel=1e-13)
    assert azimuth(np.array([0.6, 0.0, 0.8])) == 0.0
    assert azimuth(np.array([-0.6, 0.0, 0.8])) == 180.0
    assert azimuth(np.array([-0.6, -0.0, 0.8])) == 180.0
    assert azimuth(np.array([0.0, 0.6, 0.8])) == pytest.approx(90.0, rel=1e-15)
    assert np.isnan(azimuth(np.array([0.0, 0.0, 1.0])))


def test_regions_of_a_catenary_riser_a_lazy_wave_and_a_line_without_seabed():
    """A catenary riser of 100 m, top at S = 100, touchdown at S = 40 (L_s = 60 m): the
    hang-off [97, 100] (5 % of 60 m), the sag bend the lower half of the suspended
    length [40, 70], the touchdown zone 40 +- 3, the grounded part [0, 40]. A lazy wave,
    from the top: a trough at S = 80 (z 10) and a crest at S = 60 (z 30), touchdown at
    S = 40 (L_s = 60): the sag bend from midway to the top to midway to the crest,
    [70, 90], the hog bend [50, 70]. A wiggle of 1 mm beside the touchdown point is no
    bend. A catenary between two pins (no seabed), top at S = 100, lowest point at
    S = 40: the sag bend [20, 70], no touchdown zone, no grounded part."""
    named = dict(region_bounds(100.0, 1, [], 50.0, 60.0, 0.0))
    assert list(named) == ["hang_off", "sag_bend", "touchdown_zone", "grounded"]
    np.testing.assert_allclose(named["hang_off"], (97, 100), rtol=1e-14)
    np.testing.assert_allclose(named["sag_bend"], (40, 70), rtol=1e-14)
    np.testing.assert_allclose(named["touchdown_zone"], (37, 43), rtol=1e-14)
    np.testing.assert_allclose(named["grounded"], (0, 40), atol=1e-14)
    waves = [(80.0, 10.0, -1), (60.0, 30.0, 1), (41.0, 0.001, 1), (41.5, 0.0005, -1),
             (20.0, 0.0, 1)]                           # the last one lies on the seabed
    named = dict(region_bounds(100.0, 1, waves, 50.0, 60.0, 0.0))
    assert list(named) == ["hang_off", "sag_bend", "hog_bend", "touchdown_zone",
                           "grounded"]
    np.testing.assert_allclose(named["sag_bend"], (70, 90), rtol=1e-14)
    np.testing.assert_allclose(named["hog_bend"], (50, 70), rtol=1e-14)
    named = dict(region_bounds(100.0, 1, [(40.0, -20.0, -1)], 50.0, np.nan, 0.0))
    assert list(named) == ["hang_off", "sag_bend"]
    np.testing.assert_allclose(named["hang_off"], (95, 100), rtol=1e-14)
    np.testing.assert_allclose(named["sag_bend"], (20, 70), rtol=1e-14)
    top_at_start = dict(region_bounds(100.0, 0, [], 50.0, 60.0, 0.0))
    np.testing.assert_allclose(top_at_start["sag_bend"], (30, 60), rtol=1e-14)
    np.testing.assert_allclose(top_at_start["grounded"], (60, 100), rtol=1e-14)
