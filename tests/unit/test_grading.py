"""The graded mesh map (mesh/mesh.py graded_coordinates), numpy only."""

import numpy as np

from petsc_rod.mesh.mesh import graded_coordinates


def test_grading_ratio_and_ends():
    t = np.linspace(0.0, 1.0, 1001)
    for q in (1.0, 4.0, 100.0):
        S = graded_coordinates(t, q)
        h = np.diff(S)
        assert abs(S[0]) < 1e-15 and abs(S[-1] - 1.0) < 1e-15 and np.all(h > 0)
        assert abs(h.max() / h.min() - q) < 1e-3 * q


def test_a_mesh_has_the_asked_grading_to_round_off():
    """Issue 25: the built largest / smallest element is -rod_mesh_grading itself (the sine
    map's beta solved for the N elements, not for the density g'), for odd and even N,
    up to the largest grading the map can give N elements; the lengths add up to L and
    are the differences of the vertex coordinates."""
    from petsc_rod.mesh.mesh import element_lengths, largest_grading, vertex_coordinates
    for n in (3, 4, 5, 7, 16, 17, 64, 65, 300, 1001):
        for q in (1.0, 1.5, 3.0, 20.0, 77.0, 1e3, 1e5, largest_grading(n)):
            if q > largest_grading(n):
                continue
            h = element_lengths(np.arange(n), n, 2.5, q)
            S = vertex_coordinates(np.arange(n + 1), n, 2.5, q)
            assert np.all(h > 0) and abs(h.max() / h.min() - q) < 1e-12 * q, (n, q)
            assert abs(h.sum() - 2.5) < 1e-14 and np.abs(np.diff(S) - h).max() < 1e-14
            assert S[0] == 0.0 and abs(S[-1] - 2.5) < 1e-15


def test_the_largest_grading_of_few_elements():
    """1 and 2 elements cannot be graded (the map keeps them equal); 16 reach 77.4 (the
    ratio asked in issue 25 was 1e9); the limit grows like 3 N^2 / pi^2 and
    fewest_elements is the first N that reaches a ratio."""
    from petsc_rod.mesh.mesh import fewest_elements, largest_grading, mesh_beta
    assert largest_grading(1) == largest_grading(2) == 1.0
    assert mesh_beta(2, 2.0) is None and mesh_beta(16, 1e9) is None
    assert 77.0 < largest_grading(16) < 78.0
    assert abs(largest_grading(10000) / (3e8 / np.pi**2) - 1) < 1e-3
    for q in (1.5, 3.2, 77.5, 1e4):
        n = fewest_elements(q)
        assert largest_grading(n) >= q > largest_grading(n - 1)
