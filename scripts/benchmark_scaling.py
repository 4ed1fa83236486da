"""Time per Uzawa iteration, where it goes, and the memory, against elements and ranks.

Run on 1 and 2 ranks (docs/performance.md has the tables this prints):
    python scripts/benchmark_scaling.py 10000 100000 1000000
    mpiexec -n 2 python scripts/benchmark_scaling.py 10000 100000 1000000

The scene is the paper's (clamp, pinned end at X_F = 16), scaled to a 20 km cable so that
the elements stay 0.02 m or longer; a fixed number of iterations is timed (convergence
is not the point here). Two drivers (--driver):

* ``map``: the map G of one iteration alone, solver.problem.iterate() + state.norms() (the plain
  iteration, -rod_snes_type nrichardson, less the SNES's own vector work);
* ``snes``: the default driver, solve_step through the SNES (Anderson mixing with the
  depth it picks, whose history is m vectors of 18 numbers per node), timed over the
  last iterations, once the history is full (--iterations counts those).

Each size is timed --repeat times and the fastest run is kept (the machine may be shared:
say the load average with the numbers). Per size, one line: elements, ranks, set-up
(assembly and factorisations, s), s per iteration, us per element and iteration, ms per
iteration of each phase (the -log_view events rod_rhs, rod_solve, rod_projection,
rod_multiplier, rod_norms, and the rest: "other", the SNES's vector work for ``snes``;
the largest over the ranks, like -log_view's Max), PETSc's MPI messages per iteration
and rank (the ghost updates), and the peak resident memory summed over the ranks, in
total and per element above the same processes before the first mesh. With --markdown
the same as table rows.
"""

import argparse
import os
import resource
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")     # as python -m petsc_rod runs
import numpy as np  # noqa: E402
import petsc4py

petsc4py.init(sys.argv[:1])
from petsc4py import PETSc  # noqa: E402

from petsc_rod.iteration.driver import solver_for, default_anderson_depth  # noqa: E402
from petsc_rod.iteration.stopping import Settings  # noqa: E402
from petsc_rod.mesh.mesh import Mesh  # noqa: E402
from petsc_rod.scenes.scene import Scene  # noqa: E402

PHASES = ("rhs", "solve", "projection", "multiplier", "norms")
EVENTS = {name: PETSc.Log.Event(f"rod_{name}") for name in PHASES}


def arguments():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("elements", type=int, nargs="*", default=[10000, 100000])
    parser.add_argument("--iterations", type=int, default=20, help="timed iterations")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs, the best kept")
    parser.add_argument("--driver", choices=("map", "snes"), default="map")
    parser.add_argument("--markdown", action="store_true", help="table rows")
    return parser.parse_args(sys.argv[1:])


def peak_rss():
    """Peak resident memory of this process, bytes (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024.0


def counters():
    """Per event (the phases): (time, PETSc's MPI messages) of this rank so far (the
    collectives that go through mpi4py are not in PETSc's counts: docs/performance.md
    lists them)."""
    info = {name: event.getPerfInfo() for name, event in EVENTS.items()}
    return {name: np.array([i["time"], i["numMessages"]]) for name, i in info.items()}


def anderson_history(mesh):
    """The depth m of Anderson mixing the driver picks (-rod_snes_anderson_m, or
    driver.default_anderson_depth)."""
    given = PETSc.Options().getInt("rod_snes_anderson_m", 0)
    return given or default_anderson_depth(mesh)


def scene():
    scale = 1000.0
    return scale, Scene(length=20.0 * scale, stiffness=[235.0, 360.0, 200.0], start="clamp",
                        end="pin", end_position=[16.0 * scale, 4.0 * scale, 0.0])


def timed_map(solver, iterations):
    """Seconds of ``iterations`` evaluations of the map G (iterate + norms)."""
    clock = time.perf_counter()
    for _ in range(iterations):
        solver.problem.iterate()
        solver.problem.norms()
    return time.perf_counter() - clock


class Window:
    """An observer of solve_step that records the clock and the event counters at the
    start of the timed window (iteration ``first``) and at its end."""

    def __init__(self, first):
        self.first, self.start, self.counts = first, None, None

    def __call__(self, iteration, change, residual):
        if iteration == self.first:
            self.start, self.counts = time.perf_counter(), counters()
        return False


def measure(comm, n_elements, args):
    scale, rod = scene()
    clock = time.perf_counter()
    mesh = Mesh(comm, n_elements, rod.length)
    # the iteration alone: no Newton steps (their factorisations are not an iteration's)
    settings = Settings(asked_penalty=400.0 / scale**2, max_it=10**9, rtol=0.0, ctol=0.0,
                        adapt_penalty=False, check_stability=False, newton=False)
    solver = solver_for(mesh, rod, settings)
    solver.problem.state.set_straight()
    solver.problem.prepare(0.125)
    setup = time.perf_counter() - clock
    solver.problem.iterate()                      # a first iteration: caches, first touches
    best = None
    for _ in range(args.repeat):
        if args.driver == "map":
            before = counters()
            seconds = timed_map(solver, args.iterations)
            after = counters()
        else:
            depth = anderson_history(mesh)
            window = Window(depth + 1)
            settings.max_it = depth + 1 + args.iterations
            solver.problem.state.set_straight()
            solver.solve_step(0.125, observer=window)
            seconds = time.perf_counter() - window.start
            before, after = window.counts, counters()
        if best is None or seconds < best[0]:
            best = (seconds, {name: after[name] - before[name] for name in PHASES})
    seconds, phases = best
    solver.destroy()
    solver.problem.destroy()
    mesh.destroy()
    mpi = comm.tompi4py()
    per_iteration = mpi.allreduce(seconds, op=_max()) / args.iterations
    phase_time = {name: mpi.allreduce(phases[name][0], op=_max()) / args.iterations
                  for name in PHASES}
    other = mpi.allreduce(seconds - sum(phases[name][0] for name in PHASES),
                          op=_max()) / args.iterations
    messages = sum(phases[name][1] for name in PHASES) / args.iterations
    memory = mpi.allreduce(peak_rss())
    return dict(elements=n_elements, ranks=comm.getSize(), setup=setup, per_iteration=per_iteration,
                phases=phase_time, other=other, messages=mpi.allreduce(messages, op=_max()),
                memory=memory)


def _max():
    from mpi4py import MPI
    return MPI.MAX


def report(row, baseline, markdown):
    per_element_us = row["per_iteration"] / row["elements"] * 1e6
    phases = row["phases"]
    other = row["other"]
    memory_per_element = (row["memory"] - baseline) / row["elements"]
    cells = ([f"{row['elements']:.0e}".replace("e+0", "e"), f"{row['ranks']}",
              f"{row['setup']:.2f}", f"{1e3 * row['per_iteration']:.3g}",
              f"{per_element_us:.2f}"]
             + [f"{1e3 * phases[name]:.3g}" for name in PHASES] + [f"{1e3 * other:.2g}"]
             + [f"{row['messages']:.0f}", f"{row['memory'] / 2**20:.0f}",
                f"{memory_per_element / 1024:.2f}"])
    if markdown:
        return "| " + " | ".join(cells) + " |"
    names = (["elements", "ranks", "set-up s", "ms/it", "us/el/it"]
             + [f"{name} ms" for name in PHASES] + ["other ms", "PETSc msgs", "RSS MiB",
                                                     "KiB/el"])
    return "  ".join(f"{name} {cell}" for name, cell in zip(names, cells))


HEADER = ("| elements | ranks | set-up (s) | ms / iteration | µs / element / iteration | "
          + " | ".join(f"{name} (ms)" for name in PHASES)
          + " | other (ms) | PETSc messages | peak RSS, all ranks (MiB) | "
          "KiB / element |\n|" + "---:|" * (5 + len(PHASES) + 4))


def main():
    args = arguments()
    comm = PETSc.COMM_WORLD
    PETSc.Log.begin()
    baseline = comm.tompi4py().allreduce(peak_rss())
    say = PETSc.Sys.Print
    say(f"driver {args.driver}, {args.iterations} timed iterations, best of {args.repeat} "
        f"runs, {comm.getSize()} rank(s); load average before: "
        + " ".join(open("/proc/loadavg").read().split()[:3]))
    if args.markdown:
        say(HEADER)
    for size in sorted(args.elements):
        say(report(measure(comm, size, args), baseline, args.markdown))
    say("load average after: " + " ".join(open("/proc/loadavg").read().split()[:3]))


if __name__ == "__main__":
    main()
