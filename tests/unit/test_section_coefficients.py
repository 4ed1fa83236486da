"""The stiffness of the fields along a line of sections (global_step/coefficients.py,
elements.cut_gauss_rule, docs/method.md §2, §4), numpy only: the element matrices of a
stiffness linear along each section are exact, also with a section end inside an
element; the split and the matrices' split are pointwise; a line of one stiffness keeps
the constant triple's arithmetic; the default penalty and the axial symmetry read the
stiffness over the whole line."""

import numpy as np
import pytest

from petsc_rod.frames import split_coefficients
from petsc_rod.global_step.coefficients import ENERGY, LAGGED, FieldCoefficients
from petsc_rod.mesh.elements import (GAUSS_POINTS, cut_gauss_rule, p2_basis,
                                     p2_element_matrices, p2_stiffness_matrices)
from petsc_rod.problem.penalty import matrix_split, penalty_scales
from petsc_rod.model.line_type import Section
from petsc_rod.scenes.scene import Scene

# a bend stiffener tapering from 4 to 1 on [0, 0.4], then a line whose K3 exceeds K1 + K2
STIFFENER = Section("stiffener", 0.0, 0.4, (4.0, 4.0, 3.0), (1.0, 1.0, 0.75))
TORSION = Section("torsion", 0.4, 1.0, (0.5, 0.5, 1.5), (0.5, 0.5, 1.5))


def line(*sections, stiffness=(1.0, 1.0, 1.0)):
    return Scene(length=1.0, stiffness=stiffness, sections=tuple(sections))


def exact_matrices(a, h, coefficient, pieces=400):
    """int s(S) phi_k' phi_l' dS on [a, a + h] by a fine midpoint rule (reference)."""
    x = (np.arange(pieces) + 0.5) / pieces
    _, dphi = p2_basis(x, np.array([h]))
    s = coefficient(a + h * x)                                  # (pieces, m)
    return np.einsum("q,qf,qk,ql->fkl", np.full(pieces, h / pieces), s, dphi[0], dphi[0])


def test_a_break_inside_an_element_is_integrated_exactly():
    """A coefficient linear on either side of a jump inside the element, times two P2
    derivatives: exact by 3-point Gauss on the two pieces (a fine midpoint rule agrees
    to its own error, O(pieces^-2)); an element without a break keeps the plain rule."""
    S0, h = np.array([0.3, 0.7]), np.array([0.2, 0.1])
    xi, weights = cut_gauss_rule(S0, h, [0.37])
    assert xi.shape == weights.shape == (2, 6)
    assert np.allclose(weights.sum(axis=1), h, rtol=1e-15)
    assert np.array_equal(xi[1, :3], GAUSS_POINTS) and np.all(weights[1, 3:] == 0)

    def coefficient(S):
        S = np.asarray(S)
        return np.stack([np.where(S < 0.37, 2.0 + 5.0 * S, 7.0 - 3.0 * S), 0 * S + 1.0], -1)

    S = S0[:, None] + xi * h[:, None]
    ours = p2_stiffness_matrices(h, xi, weights, coefficient(S))       # (2, ne, 3, 3)
    for e in range(2):
        reference = exact_matrices(S0[e], h[e], coefficient, pieces=4000)
        assert np.abs(ours[:, e] - reference).max() < 1e-5 * np.abs(reference).max()
    # a constant coefficient: the plain element matrices
    unit = p2_element_matrices(h, 1.0, 0.0)
    assert np.abs(ours[1, :] - unit).max() < 1e-13 * np.abs(unit).max()


def test_a_break_at_a_vertex_cuts_nothing():
    """Section ends on the vertices (to round-off): one piece per element, the plain
    Gauss points and weights."""
    n = 10
    S0 = np.arange(n) / n
    xi, weights = cut_gauss_rule(S0, np.full(n, 0.1), [0.4, 0.1 + 0.2 + 0.1])
    assert xi.shape == (n, 3)
    assert np.array_equal(xi, np.broadcast_to(GAUSS_POINTS, (n, 3)))


def test_no_element_on_this_rank():
    xi, weights = cut_gauss_rule(np.zeros(0), np.zeros(0), [0.4])
    assert xi.shape == weights.shape == (0, 3)
    coefficients = FieldCoefficients(line(STIFFENER, TORSION), np.zeros(0), np.zeros(0),
                                     matrix_split)
    assert coefficients.global_step_matrices(0, 1.0).shape == (0, 3, 3)


def test_the_split_is_pointwise():
    k = np.array([[[235.0, 360.0, 100.0], [1.0, 1.0, 1.0]]])
    a = split_coefficients(k)
    assert a.shape == (1, 2, 3)
    assert np.array_equal(a[0, 0], split_coefficients(k[0, 0]))
    c = matrix_split(a)
    assert np.array_equal(c[0, 0], matrix_split(a[0, 0]))
    assert np.array_equal(c[0, 1], a[0, 1])
    assert c[0, 0, 1] == a[0, 0].max()


def test_the_fields_matrices_along_a_tapered_and_a_torsion_section():
    """The energy's K_{2 a_i}, the global step's K_{2 c_i} and the lagged part: c = a
    outside the torsion section, c3 = max a inside it; matrix - lagged = energy."""
    n = 10
    S0, h = np.arange(n) / n, np.full(n, 0.1)
    coefficients = FieldCoefficients(line(STIFFENER, TORSION), S0, h, matrix_split)
    assert not coefficients.uniform and coefficients.lagged_fields == (2,)
    energy = np.stack([coefficients.part(i, ENERGY)[2]() for i in range(3)])
    lagged = np.stack([coefficients.part(i, LAGGED)[2]() for i in range(3)])
    matrix = np.stack([coefficients.global_step_matrices(i, 0.0) for i in range(3)])
    assert np.abs(matrix - lagged - energy).max() < 1e-13 * np.abs(matrix).max()
    assert np.all(lagged[:2] == 0) and np.all(lagged[2, :4] == 0)
    # in the torsion section: a = (0.375, 0.375, -0.125), c3 = 0.375
    unit = p2_element_matrices(h[4:], 1.0, 0.0)
    assert np.abs(energy[2, 4:] - 2 * -0.125 * unit).max() < 1e-13
    assert np.abs(matrix[2, 4:] - 2 * 0.375 * unit).max() < 1e-13
    # the taper: the exact integral of the linear coefficient, against a fine rule (the
    # element's mean value times the unit K is off by 3e-2 to 7e-2 of it)
    for e in range(4):
        def coefficient(S):
            k = 4.0 - 3.0 * np.asarray(S) / 0.4
            return 2 * split_coefficients(np.stack([k, k, 0.75 * k], -1))
        reference = exact_matrices(S0[e], h[e], coefficient, pieces=4000)
        assert np.abs(energy[:, e] - reference).max() < 1e-6 * np.abs(reference).max()


def test_a_uniform_line_keeps_the_constant_triple():
    """No section, or sections of the scene's own stiffness: the constant a_i and the
    unit K, the same arithmetic as before sections existed."""
    h = np.full(4, 0.25)
    for scene in (Scene(length=1.0, stiffness=(235.0, 360.0, 100.0)),
                  line(Section("a", 0.0, 0.5, (235.0, 360.0, 100.0), (235.0, 360.0, 100.0)),
                       Section("b", 0.5, 1.0, (235.0, 360.0, 100.0), (235.0, 360.0, 100.0)),
                       stiffness=(235.0, 360.0, 100.0))):
        coefficients = FieldCoefficients(scene, np.arange(4) / 4, h, matrix_split)
        a = split_coefficients(scene.stiffness)
        assert coefficients.uniform and coefficients.lagged_fields == (1,)
        assert np.array_equal(coefficients.global_step_matrices(1, 3.0),
                              p2_element_matrices(h, 2 * matrix_split(a)[1], 3.0))
        factor, key, matrices = coefficients.part(1, LAGGED)
        assert key == "unit" and factor == 2 * (matrix_split(a)[1] - a[1])
        assert np.array_equal(matrices(), p2_element_matrices(h, 1.0, 0.0))


def test_the_default_penalty_reads_the_whole_line():
    """bending: min and max over the three stiffnesses and the line; twist: the end turn
    through the torsional springs in series, over the softest bending stiffness."""
    scene = line(STIFFENER, TORSION, stiffness=(1e6, 1e6, 1e6))
    scene.end = "clamp"
    scene.end_twist = 2.0
    scales = penalty_scales(scene)
    assert scales["bending"] == pytest.approx(100 * np.sqrt(0.5 * 4.0))
    compliance = 0.4 * np.log(0.75 / 3.0) / (0.75 - 3.0) + 0.6 / 1.5
    assert scales["twist"] == pytest.approx(2 * (2.0 / compliance) ** 2 / 0.5, rel=1e-14)
    uniform = Scene(length=1.0, stiffness=(1.5, 1.5, 1.5), end="clamp", end_twist=2.0)
    same = line(Section("a", 0.0, 0.3, (1.5,) * 3, (1.5,) * 3),
                Section("b", 0.3, 1.0, (1.5,) * 3, (1.5,) * 3))
    same.end, same.end_twist = "clamp", 2.0
    for key, value in penalty_scales(uniform).items():
        assert penalty_scales(same)[key] == pytest.approx(value, rel=1e-14)


def test_axial_symmetry_needs_k1_equal_k2_all_along():
    assert line(STIFFENER, TORSION).axially_symmetric
    flat = Section("flat", 0.4, 1.0, (2.0, 0.5, 0.4), (2.0, 0.5, 0.4))
    assert not line(STIFFENER, flat).axially_symmetric
    assert not Scene(length=1.0, stiffness=(1.0, 2.0, 1.0)).axially_symmetric


def test_one_sided_stiffness_at_a_section_end():
    scene = line(STIFFENER, TORSION)
    assert np.array_equal(scene.stiffness_at(0.4), [0.5, 0.5, 1.5])
    assert np.array_equal(scene.stiffness_at(0.4, inside=0.35), [1.0, 1.0, 0.75])
    assert np.array_equal(scene.stiffness_values()[:, 0], [4.0, 1.0, 0.5, 0.5])


def test_the_collocation_reference_refuses_a_line_of_sections(tmp_path):
    """validation/reference.py solves a line of one stiffness: a result file of a line
    of sections is refused in one line, not read with -rod_stiffness."""
    h5py = pytest.importorskip("h5py")
    from petsc_rod.validation.reference import initial_guess_from_result

    path = str(tmp_path / "sections.h5")
    with h5py.File(path, "w") as f:
        for key in ("S", "r", "d1", "d2", "d3", "u", "n", "m"):
            f[key] = np.zeros((2, 3)) if key != "S" else np.zeros(2)
        f.attrs["options"] = "-rod_stiffness 1,1,1\n-rod_sections a:0:0.4,b:0.4:1\n"
    with pytest.raises(ValueError, match="line of sections"):
        initial_guess_from_result(path)
