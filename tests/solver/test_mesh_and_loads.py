"""Graded mesh and piecewise-constant loads (serial and mpiexec -n 2)."""

import numpy as np

from helpers import gather
from petsc_rod.global_step.matrices import load_ghosted
from petsc_rod.validation.closed_forms import cantilever_tip
from petsc_rod.mesh.fields import VectorField
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.io.outputs import vertex_fields
from petsc_rod.scenes.scene import Scene


def test_piecewise_load_is_integrated_exactly(comm):
    """Breaks inside elements: the theta load vector int F.g of F(S) = int_S^L f dS
    reproduces, for the P2 functions g = 1 and g = S (exact in P2), int F dS = int S f dS
    and int S F dS = int S^2/2 f dS exactly."""
    length = 3.0
    mesh = Mesh(comm, 7, length, grading=3.0)
    try:
        breaks = np.array([0.37, 1.1, 2.9])
        values = np.array([[1.0, -2.0, 0.5], [0.0, 3.0, 0.0], [-4.0, 1.0, 2.0], [2.0, 2.0, 2.0]])
        scene = Scene(length=length, stiffness=[1.0, 1.0, 1.0], load_values=values,
                      load_breaks=breaks)
        ends = scene.load_piece_ends
        load = VectorField(mesh, "load")
        load.add_ghosted(load_ghosted(mesh, lambda S: scene.load_beyond(S, 1.0), ends))
        owned = load.owned()
        load.destroy()
        n_local = mesh.n_local_elements
        owned_S = mesh.coordinates(np.arange(mesh.vertex_start, mesh.vertex_end))
        midpoint_S = (owned_S[:n_local] + mesh.coordinates(
            np.arange(mesh.vertex_start, mesh.vertex_start + n_local) + 1)) / 2
        total = mesh.global_sum(owned[:, 0].sum(axis=0) + owned[:n_local, 1].sum(axis=0))
        first_moment = mesh.global_sum((owned_S[:, None] * owned[:, 0]).sum(axis=0)
                                       + (midpoint_S[:, None] * owned[:n_local, 1]).sum(axis=0))
        assert np.abs(owned[n_local:, 1]).max(initial=0.0) == 0.0          # phantom slot
        expected_total = (np.diff(ends**2) / 2) @ values
        assert np.abs(total - expected_total).max() < 1e-13
        assert np.abs(first_moment - (np.diff(ends**3) / 6) @ values).max() < 1e-13
        assert np.abs(expected_total).max() > 1.0
    finally:
        mesh.destroy()


def test_cantilever_on_graded_mesh(comm):
    """The closed-form tip also on a mesh graded 4:1 towards both ends."""
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings
    scene = Scene(length=1.0, stiffness=[1.0, 1.0, 1.0], end="free", end_force=[0, -3.0, 0])
    mesh = Mesh(comm, 64, 1.0, grading=4.0)
    solver = solver_for(mesh, scene, Settings(asked_penalty=100.0, max_it=5000, rtol=1e-9,
                                               ctol=1e-5))
    try:
        solver.problem.state.set_straight()
        assert solver.solve_step(1.0).converged
        r = gather(comm, vertex_fields(solver.problem)["r"])
        assert np.abs(r[-1, :2] - cantilever_tip(1.0, 1.0, 3.0)).max() < 1e-6
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()
