"""Time per Uzawa iteration and peak memory against the element count.

Run on 1 and 2 ranks:
    python scripts/benchmark_scaling.py 10000 100000
    mpiexec -n 2 python scripts/benchmark_scaling.py 10000 100000
Prints one line per size: elements, ranks, set-up seconds (assembly + factorisation),
seconds per iteration (mean over the timed iterations), and the peak resident memory of
rank 0 (MiB). The scene is the paper's (clamp, pinned end at X_F = 16), scaled to a
20 km cable so that the elements stay 0.2 m or longer; a fixed number of iterations is
timed (convergence is not the point here).
"""

import resource
import sys
import time

import petsc4py

petsc4py.init(sys.argv[:1])
from petsc4py import PETSc  # noqa: E402

from petsc_rod.mesh.mesh import Mesh  # noqa: E402
from petsc_rod.scenes.scene import Scene  # noqa: E402
from petsc_rod.iteration.driver import UzawaSolver  # noqa: E402
from petsc_rod.iteration.stopping import Settings  # noqa: E402

ITERATIONS = 20


def measure(n_elements):
    comm = PETSc.COMM_WORLD
    scale = 1000.0
    scene = Scene(length=20.0 * scale, stiffness=[235.0, 360.0, 200.0], start="clamp",
                  end="pin", end_position=[16.0 * scale, 4.0 * scale, 0.0])
    clock = time.perf_counter()
    mesh = Mesh(comm, n_elements, scene.length)
    solver = UzawaSolver(mesh, scene, Settings(asked_penalty=400.0 / scale**2, max_it=ITERATIONS,
                                               rtol=0.0, ctol=0.0))
    solver.state.set_straight()
    solver.prepare_step(0.125)
    setup = time.perf_counter() - clock
    solver.iterate()                      # first solve includes the numeric factorisation
    clock = time.perf_counter()
    for _ in range(ITERATIONS):
        solver.iterate()
        solver.state.norms()
    per_iteration = (time.perf_counter() - clock) / ITERATIONS
    solver.destroy()
    mesh.destroy()
    memory = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    PETSc.Sys.Print(f"{n_elements:9d} elements  {comm.getSize()} rank(s)  set-up {setup:7.3f} s"
                    f"  {per_iteration:8.4f} s/iteration  peak RSS rank 0 {memory:8.1f} MiB")


if __name__ == "__main__":
    for size in [int(arg) for arg in sys.argv[1:]] or [10000, 100000]:
        measure(size)
