"""Graded mesh and piecewise-constant loads (serial and mpiexec -n 2)."""

import numpy as np

from helpers import gather
from petsc_rod.assembly import load_ghosted
from petsc_rod.closed_forms import cantilever_tip
from petsc_rod.fields import VectorField
from petsc_rod.mesh import Mesh, graded_coordinates
from petsc_rod.outputs import vertex_fields
from petsc_rod.scene import Scene


def test_grading_ratio_and_ends():
    t = np.linspace(0.0, 1.0, 1001)
    for q in (1.0, 4.0, 100.0):
        S = graded_coordinates(t, q)
        h = np.diff(S)
        assert abs(S[0]) < 1e-15 and abs(S[-1] - 1.0) < 1e-15 and np.all(h > 0)
        assert abs(h.max() / h.min() - q) < 1e-3 * q


def test_piecewise_load_is_integrated_exactly(comm):
    """Breaks inside elements: the load vector reproduces int f dS and int S f dS exactly
    (Hermite value dofs sum to 1; p(S) = S has values S_i and slopes 1)."""
    length = 3.0
    mesh = Mesh(comm, 7, length, grading=3.0)
    try:
        breaks = np.array([0.37, 1.1, 2.9])
        values = np.array([[1.0, -2.0, 0.5], [0.0, 3.0, 0.0], [-4.0, 1.0, 2.0], [2.0, 2.0, 2.0]])
        ends = np.concatenate([[0.0], breaks, [length]])
        load = VectorField(mesh, "load")
        load.add_ghosted(load_ghosted(mesh, ends, values, np.zeros(3), np.zeros(3)))
        owned = load.owned()
        load.destroy()
        total = mesh.global_sum(owned[:, 0].sum(axis=0))
        first_moment = mesh.global_sum((mesh.vertex_S[:, None] * owned[:, 0]
                                        + owned[:, 1]).sum(axis=0))
        lengths = np.diff(ends)
        midpoints = (ends[1:] + ends[:-1]) / 2
        assert np.abs(total - lengths @ values).max() < 1e-13
        assert np.abs(first_moment - (lengths * midpoints) @ values).max() < 1e-13
    finally:
        mesh.destroy()


def test_cantilever_on_graded_mesh(comm):
    """The closed-form tip also on a mesh graded 4:1 towards both ends."""
    from petsc_rod.solver import Settings, UzawaSolver
    scene = Scene(length=1.0, stiffness=[1.0, 1.0, 1.0], end="free", end_force=[0, -3.0, 0])
    mesh = Mesh(comm, 64, 1.0, grading=4.0)
    solver = UzawaSolver(mesh, scene, Settings(penalty=100.0, max_it=5000, rtol=1e-9,
                                               ctol=1e-5))
    try:
        solver.set_straight()
        assert solver.solve_step(1.0).converged
        r = gather(comm, vertex_fields(solver, 1.0)["r"])
        assert np.abs(r[-1, :2] - cantilever_tip(1.0, 1.0, 3.0)).max() < 1e-6
    finally:
        solver.destroy()
        mesh.destroy()
