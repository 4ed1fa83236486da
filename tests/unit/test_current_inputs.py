"""The Python Current takes the command line's inputs (issue 24, point 8): rho, C_d, D
(Current.morison, Current.uniform) give the drag c = rho C_d D / 2 that -rod_drag gives,
and the dataclass's own c still works for the callers that have it."""

import numpy as np
import pytest

from petsc_rod.environment.current import Current

pytestmark = pytest.mark.unit


def test_morison_inputs_give_the_command_lines_drag():
    current = Current.morison([0.0, 100.0], [[1.0, 0.0, 0.0], [0.0, 0.5, 0.0]], 10.0,
                              1025.0, 1.2, 0.324)
    assert current.drag == 0.5 * 1025.0 * 1.2 * 0.324           # kg/m^2, as -rod_drag
    assert current.depths.shape == (2,) and current.velocities.shape == (2, 3)
    assert np.allclose(current.velocity([10.0, -40.0]), [[1.0, 0.0, 0.0], [0.5, 0.25, 0.0]])
    plain = Current(np.array([0.0, 100.0]),
                    np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.0]]), 10.0,
                    0.5 * 1025.0 * 1.2 * 0.324)
    assert plain.drag == current.drag        # the old form: c itself


def test_a_uniform_current_is_one_row():
    current = Current.uniform([0.5, 0.0, 0.0], 1025.0, 1.2, 0.1)
    assert current.depths.tolist() == [0.0] and current.velocities.tolist() == [[0.5, 0, 0]]
    assert current.largest_drag() == pytest.approx(0.5 * 1025.0 * 1.2 * 0.1 * 0.25, rel=1e-15)
