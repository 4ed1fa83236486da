"""A body's kinematics and own loads (petsc_rod/system/bodies.py): the rotation's
angles, exp and log, and the exact derivative of the weight, buoyancy and hydrostatic
restoring against central differences of the moved pose."""

import numpy as np
import pytest

from petsc_rod.model.system import Body
from petsc_rod.system.bodies import (Bodies, exp_rotation, log_jacobian,
                                     log_rotation, rotation, skew)
from petsc_rod.model.system_check import tait_bryan_zyx


def test_angles_exp_and_log_invert_each_other():
    R = rotation(0.3, -0.4, 2.5)
    assert tait_bryan_zyx(R) == pytest.approx([0.3, -0.4, 2.5], abs=1e-14)
    assert R @ R.T == pytest.approx(np.eye(3), abs=1e-15)
    theta = np.array([0.2, -1.1, 0.7])
    assert log_rotation(exp_rotation(theta)) == pytest.approx(theta, abs=1e-14)
    # over a leading axis, through the small angles' series
    thetas = np.array([theta, [1e-9, 0.0, 2e-9], [3e-5, -1e-5, 2e-5]])
    assert log_rotation(exp_rotation(thetas)) == pytest.approx(thetas, rel=1e-12, abs=1e-22)
    assert exp_rotation(thetas)[1] == pytest.approx(np.eye(3) + skew(thetas[1]), abs=1e-17)
    assert tait_bryan_zyx(rotation(*thetas.T)) == pytest.approx(thetas, rel=1e-12, abs=1e-22)
    # the log's derivative along a left increment
    h, J = 1e-6, np.empty((3, 3))
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        J[:, k] = (log_rotation(exp_rotation(step) @ exp_rotation(theta))
                   - log_rotation(exp_rotation(-step) @ exp_rotation(theta))) / (2 * h)
    assert log_jacobian(theta) == pytest.approx(J, abs=1e-8)


@pytest.mark.parametrize("given", [False, True])
def test_the_own_loads_jacobian_is_their_derivative(given):
    hydrostatic = (np.diag([0, 0, 1.2e6, 3e7, 4e7, 0]) + 1e5 * np.ones((6, 6))).ravel()
    body = Body("b", position=(1.0, -2.0, 0.5, 0.1, -0.05, 0.3), mass=2e6,
                cog=(0.5, -0.2, -8.0), volume=2.2e3, cob=(0.1, 0.3, -6.0),
                waterplane_area=120.0, waterplane_moments=(4e3, 5e3),
                hydrostatic=tuple(hydrostatic) if given else None,
                load=(1e5, 2e5, 0, 1e6, 0, 3e6))
    bodies = Bodies((body,), 1025.0, 9.81).moved(np.array([[0.3, -0.2, 0.4, 0.05, 0.08,
                                                             -0.2]]))
    load = np.array([body.load])
    J = bodies.own_loads(load)[1][0]
    h = np.array([1e-4] * 3 + [1e-7] * 3)
    numeric = np.empty((6, 6))
    for k in range(6):
        step = np.zeros((1, 6))
        step[0, k] = h[k]
        numeric[:, k] = (bodies.moved(step).own_loads(load)[0]
                         - bodies.moved(-step).own_loads(load)[0])[0] / (2 * h[k])
    assert np.abs(J - numeric).max() < 1e-6 * np.abs(J).max()
    # the weight's and buoyancy's lever arms make the rotational block unsymmetric
    assert np.abs(J[3:, 3:] - J[3:, 3:].T).max() > 1e3
