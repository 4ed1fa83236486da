"""The elastic catenary closed form (validation/elastic_catenary.py) against the
inextensible forms as EA -> inf and against a quadrature of its own differential
equations: x' = H (1/EA + 1/T), z' = V (1/EA + 1/T), V' = w."""

import numpy as np
import pytest
from scipy.integrate import quad

from petsc_rod.scenes.catenary import catenary
from petsc_rod.scenes.touchdown import grounded_catenary
from petsc_rod.validation.elastic_catenary import elastic_catenary

pytestmark = pytest.mark.unit


def test_a_stiff_line_on_the_seabed_is_the_catenary_with_touchdown():
    S = np.linspace(0.0, 1800.0, 37)
    line = elastic_catenary(1800.0, 1200.0, 1e18, 1400.0, 1000.0)
    r, _, _, (_, touchdown) = grounded_catenary(1800.0, np.array([1400.0, 0.0, 1000.0]),
                                                1200.0, 0.0, S)
    x, z, _ = line.at(S)
    assert np.abs(r[:, 0] - x).max() < 1e-8 and np.abs(r[:, 2] - z).max() < 1e-8
    assert line.grounded == pytest.approx(touchdown, abs=1e-7)


def test_a_stiff_hanging_line_is_the_catenary():
    S = np.linspace(0.0, 100.0, 21)
    line = elastic_catenary(100.0, 10.0, 1e14, 80.0, 30.0, on_seabed=False)
    r, _, _ = catenary(100.0, np.array([80.0, 0.0, 30.0]), np.array([0.0, 0.0, -10.0]), S)
    x, z, _ = line.at(S)
    assert np.abs(r[:, 0] - x).max() < 1e-9 and np.abs(r[:, 2] - z).max() < 1e-9


@pytest.mark.parametrize("on_seabed, span, rise", [(True, 1400.0, 1000.0),
                                                   (False, 1700.0, 300.0)])
def test_the_closed_form_solves_its_equations(on_seabed, span, rise):
    """A soft line (EA = 2e7 N: 6 % stretch at the top): the end reached, tangent to the
    seabed at the touchdown, and x, z the quadratures of x', z' from the touchdown."""
    w, EA, L = 1200.0, 2e7, 1800.0
    line = elastic_catenary(L, w, EA, span, rise, on_seabed=on_seabed)
    assert np.allclose(line.end_point(), (span, rise), rtol=1e-12, atol=1e-9)
    start = line.grounded
    V = lambda s: line.V_A + w * (s - start)
    T = lambda s: np.hypot(line.H, V(s))
    for s in (0.5 * (start + L), L):
        dx = quad(lambda t: line.H * (1 / EA + 1 / T(t)), start, s, epsabs=0, epsrel=1e-13)[0]
        dz = quad(lambda t: V(t) * (1 / EA + 1 / T(t)), start, s, epsabs=0, epsrel=1e-13)[0]
        x, z, tension = line.at(s)
        x0 = start * (1 + line.H / EA)
        assert x == pytest.approx(x0 + dx, rel=1e-12) and z == pytest.approx(dz, rel=1e-11)
        assert tension == pytest.approx(T(s), rel=1e-14)
    if on_seabed:
        assert line.grounded > 0 and line.V_A == 0.0
        # the stretched grounded part carries H: x(L_B) = L_B (1 + H / EA)
        assert line.at(line.grounded)[0] == pytest.approx(line.grounded * (1 + line.H / EA))
