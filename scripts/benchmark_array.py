"""The array scene (options/array_10x10.dat, scripts/make_array.py: 100 free floaters,
300 lines, shared anchors) solved on 1 and on 2 ranks, in alternated pairs: the
issue's parallel target (2 ranks at least 1.7 times as fast as 1).

    python scripts/benchmark_array.py [pairs] [element_length] [file]

Each run is its own process (``python scripts/benchmark_array.py --run ...``, under
``mpiexec -n 2`` for two ranks) that reads the file (read_moordyn, element_length m
elements, 4 m by default: 104 a line), makes the SystemSolver with real lines
(system/held_line.held_lines; the lines dealt over the ranks by system/placement.py)
and solves the coupled equilibrium under the file's steady loads; the time is the
solver's making and its solve (the lines' first solves included; not the imports nor
the reading). Prints every run as it ends, with each rank's CPU time, then the medians,
the ratio of the medians and the load average before and after: the machine's other
work slows both; the CPU times' ratio it changes less (a rank waiting in MPI polls, so
its waits count as CPU time too).
"""

import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
FILE = os.path.join(HERE, os.pardir, "options", "array_10x10.dat")


def run(path, element_length):
    """One solve; prints a JSON line on rank 0. Collective."""
    from petsc4py import PETSc

    from petsc_rod.model.moordyn import read_moordyn
    from petsc_rod.system.equilibrium import SystemSolver
    from petsc_rod.system.held_line import held_lines
    system, _ = read_moordyn(path, element_length=element_length)
    PETSc.COMM_WORLD.barrier()
    clock, cpu = time.perf_counter(), time.process_time()
    solver = SystemSolver(system, held_lines(system), PETSc.COMM_WORLD)
    try:
        result = solver.solve()
    finally:
        solver.destroy()
    seconds = time.perf_counter() - clock
    cpus = PETSc.COMM_WORLD.tompi4py().gather(time.process_time() - cpu)
    offsets = np.array([result.bodies[b.name][0] - b.position[0] for b in system.bodies])
    if PETSc.COMM_WORLD.rank == 0:
        print(json.dumps({"ranks": PETSc.COMM_WORLD.size, "seconds": seconds, "cpu": cpus,
                          "iterations": result.iterations, "lines": len(system.lines),
                          "elements": int(sum(l.line.sections[0][2] for l in system.lines)),
                          "surge": [float(offsets.min()), float(offsets.max())],
                          "unstable": list(result.unstable)}), flush=True)


def launch(ranks, path, element_length):
    command = [sys.executable, os.path.abspath(__file__), "--run", path, str(element_length)]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks)] + command
    # one BLAS thread, as python -m petsc_rod runs: one rank does not borrow the second
    # core, and the dense Newton solve's round-off is the same on any number of ranks
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    out = subprocess.run(command, capture_output=True, text=True, check=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(pairs=2, element_length=4.0, path=FILE):
    before = os.getloadavg()
    print(f"{path}: load average {before[0]:.1f} {before[1]:.1f} {before[2]:.1f}, "
          f"{os.cpu_count()} cores", flush=True)
    times, cpus = {1: [], 2: []}, {1: [], 2: []}
    for pair in range(pairs):
        for ranks in ((1, 2) if pair % 2 == 0 else (2, 1)):
            result = launch(ranks, path, element_length)
            times[ranks].append(result["seconds"])
            cpus[ranks].append(max(result["cpu"]))
            print(f"  {ranks} rank(s): {result['seconds']:.1f} s (CPU of each rank "
                  f"{', '.join(f'{c:.1f}' for c in result['cpu'])} s), Newton "
                  f"{result['iterations']}, {result['lines']} lines, {result['elements']} "
                  f"elements, surge {result['surge'][0]:.4f}-{result['surge'][1]:.4f} m, "
                  f"unstable {result['unstable']}, load {os.getloadavg()[0]:.1f}", flush=True)
    one, two = np.median(times[1]), np.median(times[2])
    after = os.getloadavg()
    print(f"median 1 rank {one:.1f} s, 2 ranks {two:.1f} s: 2 ranks {one / two:.2f} times as "
          f"fast; load average after {after[0]:.1f} {after[1]:.1f} {after[2]:.1f}\n"
          f"CPU (the busiest rank's) median 1 rank {np.median(cpus[1]):.1f} s, 2 ranks "
          f"{np.median(cpus[2]):.1f} s: {np.median(cpus[1]) / np.median(cpus[2]):.2f} (what "
          "an idle machine's ratio would be near, were the ranks not waiting on each other)")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--run"]:
        run(sys.argv[2], float(sys.argv[3]))
    else:
        main(*(int(sys.argv[1]),) if len(sys.argv) > 1 else (),
             **({"element_length": float(sys.argv[2])} if len(sys.argv) > 2 else {}),
             **({"path": sys.argv[3]} if len(sys.argv) > 3 else {}))
