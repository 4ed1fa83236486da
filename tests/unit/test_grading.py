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
