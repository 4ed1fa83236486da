"""The modes of a line on a seabed profile (analysis/modes.py, physics/seabed.py,
docs/modes.md): K holds the profile's contact stiffness along its normal (the symmetric
part of Seabed.profile_derivatives' block), so a profile whose rows lie far from the
grounded part has the modes of the plane it samples; a grounded node near a row where
the slope changes is said (Modes.symmetrised, the run's warning). Serial and under
mpiexec -n 2; small meshes."""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import destroy, make_solver
from petsc_rod.environment.bathymetry import Grid, Plane, Profile
from petsc_rod.environment.seabed import Seabed
from petsc_rod.problem.penalty import default_penalty
from petsc_rod.scenes.scene import Scene

pytest.importorskip("slepc4py")

# 10 m of line of 1 N/m, EI 0.1 N m^2, pinned on the seabed at the origin and 8 m away,
# 4 m up: about 4.9 m grounded on a 5 degree slope rising toward the top
DEG = 5.0
LINE = dict(length=10.0, stiffness=(0.1, 0.1, 0.1), start="pin", end="pin",
            load_values=[[0.0, 0.0, -1.0]], end_position=np.array([8.0, 0.0, 4.0]))
COUNT = 8
MASS = 0.1                                      # kg/m


def plane_profile(rows):
    """The profile of the 5 degree plane through the origin along +x, rows at ``rows``
    (m along x)."""
    d = np.asarray(rows, dtype=float)
    return Profile(np.zeros(2), np.array([1.0, 0.0]), d, d * np.tan(np.radians(DEG)))


def modes_on(shape, n_elements=16):
    """(Modes, the state's r at the owned nodes) of LINE on the seabed ``shape``."""
    from petsc_rod.analysis.mass import MassSettings
    from petsc_rod.analysis.modes import solve_modes
    scene = dict(LINE, seabed=Seabed(0.0, 1e6, shape))
    mesh, solver = make_solver(PETSc.COMM_WORLD, n_elements, scene,
                               default_penalty(Scene(**scene)), rtol=1e-11, ctol=1e-11,
                               max_it=20000)
    try:
        solver.problem.state.set_straight()
        assert solver.solve_step(1.0).converged
        return (solve_modes(solver.problem, COUNT, MassSettings(mass=MASS)),
                solver.problem.state.node_positions())
    finally:
        destroy(mesh, solver)


def test_a_profile_that_is_the_plane_has_the_planes_modes():
    """Rows at -5, 2 and 20 m on the plane, the one at 2 m under the grounded part (the
    slope the same on both sides: no turn): the COUNT lowest frequencies those of the
    plane to 1e-6, their classes too, and K exact (nothing symmetrised, no warning).
    The flat seabed's heights' curvature in their place gave the profile in-plane modes
    the plane has not (0.37 of the lowest frequency off)."""
    from petsc_rod.cli.modes import table_lines
    plane, _ = modes_on(Plane.sloping(np.zeros(2), 0.0, DEG, np.array([1.0, 0.0])))
    profile, _ = modes_on(plane_profile([-5.0, 2.0, 20.0]))
    assert len(plane.omega2) == len(profile.omega2) == COUNT
    assert np.abs(profile.frequencies / plane.frequencies - 1).max() < 1e-6
    assert profile.labels == plane.labels
    assert "in-plane" in plane.labels
    assert plane.symmetrised == (0, 0.0) and profile.symmetrised[0] == 0
    assert not any("warning" in line for line in table_lines(profile, 0.0))


def test_a_grid_that_is_the_plane_has_the_planes_modes():
    """A 3 x 3 grid of the plane's heights (bilinear: the plane itself), a grid line
    at x = 2 m under the grounded part: the COUNT lowest frequencies those of the plane
    to 1e-6 (the grid's contact linearised as a profile's, Grid.slopes)."""
    plane, _ = modes_on(Plane.sloping(np.zeros(2), 0.0, DEG, np.array([1.0, 0.0])))
    xs, ys = np.array([-5.0, 2.0, 20.0]), np.array([-3.0, 0.5, 3.0])
    heights = np.tan(np.radians(DEG)) * xs[:, None] + 0.0 * ys[None, :]
    grid, _ = modes_on(Grid(np.zeros(2), xs, ys, heights))
    assert len(grid.omega2) == COUNT
    assert np.abs(grid.frequencies / plane.frequencies - 1).max() < 1e-6
    assert grid.labels == plane.labels


def test_a_row_under_the_grounded_part_is_said():
    """A row at 2 m where the slope turns from 5 to 2 degrees, under the grounded part:
    K symmetrised at the grounded nodes within delta/2 of it, counted over the ranks
    and said in the run's warning."""
    from petsc_rod.cli.modes import table_lines
    t = np.tan(np.radians(DEG))
    kink = Profile(np.zeros(2), np.array([1.0, 0.0]), np.array([-5.0, 2.0, 20.0]),
                   np.array([-5.0 * t, 2.0 * t, 2.0 * t + 18.0 * np.tan(np.radians(2.0))]))
    modes, r = modes_on(kink)
    half = 0.05 * 7.0                   # delta / 2: SMOOTHING of the closest rows' 7 m
    near = (np.abs(r[:, 0] - 2.0) < half) & (kink.height(r[:, 0], r[:, 1]) > r[:, 2])
    expected = PETSc.COMM_WORLD.tompi4py().allreduce(int(near.sum()))
    count, ratio = modes.symmetrised
    assert count == expected > 0
    assert 1e-3 < ratio < 1.0
    lines = table_lines(modes, 0.0)
    assert lines[-1].startswith(f"modes: warning: K takes the symmetric part of the "
                                f"seabed contact's stiffness at {count} grounded node")
