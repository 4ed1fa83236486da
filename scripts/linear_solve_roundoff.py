"""Round-off of one global-step solve against the element count.

    python scripts/linear_solve_roundoff.py [N ...]        (default 100 200 400 ... 6400)

For the cantilever scene (L = 1, K = 1, R = 400, clamp and free end) and the paper scene
(L = 20, K = 235, 360, 200, R = 400, clamp and pin: the bordered slope problem), it
prints two relative errors:

* r solve: the centreline solve of the run (the P2 matrix of the slope r',
  int 2 a3 r''.g' + R r'.g, the constraint int r' = r(L) - r(0) when both ends are
  held, and the integration of r' into r) for a right-hand side whose exact discrete solution is a
  known cubic centreline (petsc_rod.validation.roundoff): max |r - r*| / max |r*|;
* d1 solve: the d1 matrix (P2, int 2 a1 d'.g' + R d.g) times a known smooth vector x,
  solved again with the run's KSP: max |x_solved - x| / max |x|.

Both matrices are second-order operators, with condition numbers growing like N^2.
(The Hermite r matrix this replaced, fourth order, grew like N^4: 5.7e-5 at N = 3200.)
"""

import sys

import numpy as np

import petsc4py

petsc4py.init(sys.argv[:1])
from petsc4py import PETSc  # noqa: E402

from petsc_rod.mesh.mesh import Mesh  # noqa: E402
from petsc_rod.validation.roundoff import centreline_solve_error  # noqa: E402
from petsc_rod.scenes.scene import Scene  # noqa: E402
from petsc_rod.iteration.driver import solver_for  # noqa: E402
from petsc_rod.iteration.stopping import Settings  # noqa: E402

SCENES = {
    "cantilever": dict(length=1.0, stiffness=[1.0, 1.0, 1.0], start="clamp", end="free",
                       end_force=[0.0, -3.0, 0.0]),
    "paper": dict(length=20.0, stiffness=[235.0, 360.0, 200.0], start="clamp", end="pin",
                  end_position=[16.0, 4.0, 0.0]),
}


def relative_solve_error(problem, S):
    """max |A^-1 (A x) - x| / max |x| for x = sin(3 S / L) at every dof."""
    x = problem.constrained.createVecRight()
    b = x.duplicate()
    y = x.duplicate()
    try:
        x.getArray()[:] = np.sin(3.0 * S)
        problem.constrained.mult(x, b)
        problem.ksp.solve(b, y)
        y.axpy(-1.0, x)
        return y.norm(PETSc.NormType.INFINITY) / x.norm(PETSc.NormType.INFINITY)
    finally:
        for vec in (x, b, y):
            vec.destroy()


def main():
    sizes = [int(arg) for arg in sys.argv[1:]] or [100, 200, 400, 800, 1600, 3200, 6400]
    comm = PETSc.COMM_WORLD
    PETSc.Sys.Print("scene       elements  r-solve error  d1-solve error", comm=comm)
    for name, kwargs in SCENES.items():
        scene = Scene(**kwargs)
        for n in sizes:
            mesh = Mesh(comm, n, scene.length)
            solver = solver_for(mesh, scene, Settings(asked_penalty=400.0))
            owned = np.arange(mesh.vertex_start, mesh.vertex_end)
            S = np.repeat(mesh.coordinates(owned), 2) / scene.length
            d_error = relative_solve_error(solver.problem.global_step.problems[0], S)
            r_error = centreline_solve_error(solver.problem)
            PETSc.Sys.Print(f"{name:10s} {n:9d}  {r_error:13.2e}  {d_error:14.2e}", comm=comm)
            solver.destroy()
            solver.problem.destroy()
            mesh.destroy()


if __name__ == "__main__":
    main()
