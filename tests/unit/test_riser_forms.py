"""The riser's numpy parts (petsc_rod/environment, physics, global_step): the catenary with
touchdown against its own equations, the Morison drag, the current profile and its file, the
Hermite slope map."""

import numpy as np
import pytest

from petsc_rod.environment.current import Current
from petsc_rod.environment.profiles import read_profile
from petsc_rod.environment.seabed import default_stiffness
from petsc_rod.errors import RodInputError
from petsc_rod.global_step.hermite import midpoint_values, slope_map
from petsc_rod.physics.drag import drag_jacobian, normal_drag
from petsc_rod.scenes.touchdown import grounded_catenary, touchdown_parameter

LENGTH, WEIGHT = 10.0, 2.0


@pytest.mark.parametrize("chord, seabed", [((7.0, 0.0, 4.0), 0.0), ((5.0, 4.0, 1.0), -1.5)],
                         ids=["anchor on the seabed", "both ends above it, skewed"])
def test_grounded_catenary_meets_its_ends_and_equations(chord, seabed):
    S = np.linspace(0.0, LENGTH, 20001)
    r, tangent, force, (g0, g1) = grounded_catenary(LENGTH, chord, WEIGHT, seabed, S)
    assert np.allclose(r[0], 0.0, atol=1e-12) and np.allclose(r[-1], chord, atol=1e-9)
    assert np.allclose(np.linalg.norm(tangent, axis=1), 1.0, atol=1e-14)
    # r' = tangent, n' + f = 0 with f = (0, 0, -w) off the seabed, n = T tangent (the
    # curvature jumps at the touchdown points: differences across them left out; central
    # differences err by dS^2 |r'''| / 6, below 1e-5 here)
    dS = S[1] - S[0]
    smooth = (np.abs(S - g0) > 2 * dS) & (np.abs(S - g1) > 2 * dS)
    assert np.abs(np.gradient(r, dS, axis=0) - tangent)[1:-1][smooth[1:-1]].max() < 1e-5
    suspended = (S < g0 - 1e-3) | (S > g1 + 1e-3)
    dn = np.gradient(force, dS, axis=0)[suspended][1:-1]
    assert np.abs(dn - [0.0, 0.0, WEIGHT]).max() < 1e-6
    assert np.allclose(np.cross(force, tangent), 0.0, atol=1e-12)
    # on the seabed: straight, at its height, horizontal; the horizontal tension the same
    grounded = (S > g0) & (S < g1)
    assert grounded.sum() > 100
    assert np.abs(r[grounded, 2] - seabed).max() < 1e-12
    assert np.abs(force[grounded, 2]).max() < 1e-12
    horizontal = np.linalg.norm(force[:, :2], axis=1)
    assert np.ptp(horizontal) < 1e-12 * horizontal.max()


def test_touchdown_parameter_is_refused_without_a_taut_grounded_line():
    with pytest.raises(ValueError):
        touchdown_parameter(LENGTH, 5.0, 0.0, 4.0)     # L - h0 - h1 = 6 > X: slack
    with pytest.raises(ValueError):
        touchdown_parameter(LENGTH, 10.0, 0.0, 4.0)    # X = L: cannot reach


def test_normal_drag_is_the_normal_component_squared():
    c, speed = 3.0, 2.0
    angles = np.linspace(0.0, np.pi, 7)
    tangent = np.stack([np.cos(angles), np.sin(angles), 0 * angles], axis=1)
    velocity = np.tile([speed, 0.0, 0.0], (angles.size, 1))
    f = normal_drag(2.5 * tangent, velocity, c)        # tangents need not be unit
    assert np.allclose(np.einsum("nc,nc->n", f, tangent), 0.0, atol=1e-12)
    assert np.allclose(np.linalg.norm(f, axis=1), c * speed**2 * np.sin(angles) ** 2)
    assert np.all(f[1:-1] @ np.array([1.0, 0.0, 0.0]) > 0)     # downstream


def test_a_point_compressed_to_nothing_takes_the_whole_current_as_normal():
    """A zero tangent (a node of an extensible line that the stretched local step
    compressed to k = 0) has no direction: its drag is c |v| v, finite, and its
    derivative in a turn 0; the other rows are unchanged."""
    tangents = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    velocity = np.array([[0.0, 1.0, 0.5], [0.0, 1.0, 0.5]])
    with np.errstate(all="raise"):
        drag = normal_drag(tangents, velocity, 2.0)
        jacobian = drag_jacobian(tangents, velocity, np.array([2.0, 2.0]))
    speed = np.linalg.norm(velocity[0])
    assert np.allclose(drag[0], 2.0 * speed * velocity[0], rtol=1e-15)
    assert np.allclose(drag[1], 2.0 * speed * velocity[1], rtol=1e-15)   # v normal to e_x
    assert np.all(jacobian[0] == 0.0)
    assert np.abs(jacobian[1]).max() > 1.0


def test_current_profile_is_linear_in_depth_and_constant_beyond():
    current = Current(np.array([0.0, 100.0]), np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.0]]),
                      surface=10.0, drag=1.0)
    z = np.array([20.0, 10.0, -40.0, -90.0, -500.0])
    expected = [[1, 0, 0], [1, 0, 0], [0.5, 0.25, 0], [0, 0.5, 0], [0, 0.5, 0]]
    assert np.allclose(current.velocity(z), expected)
    assert current.largest_drag() == 1.0
    # c max |v|^2 with c = 2 and a top speed of 3 m/s (the largest of two speeds)
    strong = Current(np.array([0.0, 100.0]), np.array([[3.0, 0.0, 0.0], [0.0, 2.0, 0.0]]),
                     surface=10.0, drag=2.0)
    assert strong.largest_drag() == pytest.approx(18.0)


@pytest.mark.parametrize("text, words", [
    (None, "no such file"),
    ("0 1 0 0\n50 1 0 0\n40 0 0 0\n", "increase strictly"),
    ("0 1 0\n", "rows of 4 numbers"),
    ("0 1 0 x\n", "rows of 4 numbers"),
    ("# nothing\n", "rows of 4 numbers"),
    ("0 nan 0 0\n", "not finite"),
    ("-30 0 0.3 0\n0 1 0 0\n", "row 1's depth -30 m is above the sea surface"),
], ids=["missing", "not monotone", "3 columns", "not a number", "empty", "nan", "heights"])
def test_a_bad_profile_file_is_refused_in_one_line(tmp_path, text, words):
    path = tmp_path / "profile.txt"
    if text is not None:
        path.write_text(text)
    with pytest.raises(RodInputError) as error:
        read_profile(str(path))
    assert str(error.value).startswith("-rod_current_profile") and words in str(error.value)
    assert "\n" not in str(error.value)


def test_a_profile_file_is_read_with_comments_and_commas(tmp_path):
    path = tmp_path / "profile.txt"
    path.write_text("# depth ux uy uz\n0 1 0 0  # at the surface\n\n100, 0, 0.5, 0\n")
    depths, velocities = read_profile(str(path))
    assert np.allclose(depths, [0, 100]) and np.allclose(velocities[1], [0, 0.5, 0])


def test_default_stiffness_presses_the_heaviest_piece_in_by_a_millimetre():
    loads = np.array([[0.0, 0.0, -300.0], [0.0, 0.0, 500.0], [10.0, 0.0, -1200.0]])
    assert default_stiffness(loads) == pytest.approx(1.2e6)
    assert default_stiffness(np.array([[0.0, 0.0, 5.0]])) is None


def test_slope_map_is_the_derivative_of_the_hermite_cubic():
    """theta = T y at (left, midpoint, right) and z at the midpoint, for a random cubic
    on elements of several lengths."""
    rng = np.random.default_rng(3)
    h = np.array([0.1, 1.0, 7.5])
    coefficients = rng.normal(size=(3, 4))                 # z(s) = sum c_k s^k, s from S_e

    def z(s, c):
        return c[:, 0] + c[:, 1] * s + c[:, 2] * s**2 + c[:, 3] * s**3

    def dz(s, c):
        return c[:, 1] + 2 * c[:, 2] * s + 3 * c[:, 3] * s**2

    y = np.stack([z(0, coefficients), dz(0, coefficients), z(h, coefficients),
                  dz(h, coefficients)], axis=1)
    slopes = np.einsum("ekl,el->ek", slope_map(h), y)
    assert np.allclose(slopes, np.stack([dz(0, coefficients), dz(h / 2, coefficients),
                                         dz(h, coefficients)], axis=1), rtol=1e-12)
    assert np.allclose(np.einsum("ek,ek->e", midpoint_values(h), y), z(h / 2, coefficients),
                       rtol=1e-12)
