"""A system's lines on a sloping seabed (system/held_line.py: the plane's contact in each
line's Newton system, Seabed.position_derivatives): tests/data/moordyn/small_free_body.dat
(a free buoyant body on three 70 m chains) read by the API with its seabed turned into a
plane rising 2 degrees along +x under the anchor at x = 65 m (0.2 m below it; the
other two anchors 3.4 m above it), its chains grounded on it. The body's 6 x 6 against
central differences of the lines re-solved at moved and turned poses, serially and on
all ranks; a plane of slope zero (the plane's own path) gives the flat seabed's numbers
to the lines' accuracy."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import read_moordyn
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import held_lines

from helpers import zero_slope_planes
from test_system_clamped import COMMS
from test_system_environment import assert_exact_body_stiffness

pytestmark = pytest.mark.solver

DECK = Path(__file__).parents[1] / "data" / "moordyn" / "small_free_body.dat"
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}


def on_a_slope(slope, seabed=-30.2):
    """The deck's system with its seabed the plane through (65, 0, ``seabed``) rising
    ``slope`` degrees along +x (None: the deck's flat seabed at ``seabed``)."""
    system, _ = read_moordyn(str(DECK))
    environment = dataclasses.replace(system.environment, seabed=seabed)
    if slope is not None:
        environment = dataclasses.replace(environment, seabed_slope=slope,
                                          seabed_direction=0.0, seabed_origin=(65.0, 0.0))
    return dataclasses.replace(system, environment=environment)


@pytest.mark.parametrize("comm", list(COMMS))
def test_a_body_moored_on_a_slope_has_the_exact_stiffness(comm):
    system = on_a_slope(2.0)
    solver = assert_exact_body_stiffness(system, comm, held_lines(system, TIGHT),
                                         "Body1")
    try:
        # the slope pushes the grounded chains downhill: the body drifts to -x
        print("body", solver.state.bodies.X[0])
        assert solver.state.bodies.X[0][0] < -1.0
    finally:
        solver.destroy()


def test_a_plane_of_slope_zero_is_the_flat_seabed(monkeypatch):
    """The deck's system on a plane of slope 0 (zero_slope_planes: the plane's own path;
    compile.seabed_shape makes a slope of 0 the flat seabed itself) against the flat
    seabed: the body's pose, the lines' end forces and the body's stiffness to the
    lines' accuracy."""
    zero_slope_planes(monkeypatch)          # a slope of 0 only
    numbers = []
    for slope in (0.0, None):
        system = on_a_slope(slope)
        solver = SystemSolver(system, held_lines(system, TIGHT), PETSc.COMM_SELF,
                              settings=Settings(rtol=1e-12))
        try:
            assert solver.solve().load_factor == 1.0
            assert all(line.scene.seabed.plane is (slope is not None)
                       for line in solver.lines.values())
            ok, forces, _ = solver.evaluate(solver.state)
            assert ok
            numbers.append((solver.state.bodies.X[0].copy(), forces.copy(),
                            solver.body_stiffness("Body1").matrix.copy()))
        finally:
            solver.destroy()
    for plane, flat in zip(*numbers):
        assert np.abs(plane - flat).max() <= 1e-9 * np.abs(flat).max()
