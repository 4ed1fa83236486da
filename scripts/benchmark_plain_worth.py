"""The 18 000-element riser's solve and whole run in plain iterations' worth, for one or
more source trees in alternated rounds (issue 51's long-line targets).

    python scripts/benchmark_plain_worth.py [--rounds N] [--process-time] [TREE ...]

Each round runs, for each TREE in turn (default: this repository; the order reversed
every other round, so that the trees see the shared machine alike), the plain line of
scripts/benchmark_risers.py for 20 and for 100 iterations and the riser
(options/riser_catenary.opts -rod_elements 18000) with -log_view, each as
``python -m petsc_rod`` with a result file, the tree's own petsc_rod first on the path.
One plain iteration is the difference of the two plain solves over the difference of
their iterations (benchmark_risers.plain_iteration_time); the riser's solve (the result
file's wall_time) and its whole run (-log_view's total: from PETSc's start to its end,
set-up and output included) are given in those units, per round and as medians.

``--process-time``: the solve's clock (the continuation's) reads the process's CPU time
instead of the wall clock, and the whole run is the process's CPU time (the
interpreter's start included): on a machine loaded far beyond its cores the wall time
of one run moves by a factor of two, its CPU time by about a tenth. A TREE is a
directory holding petsc_rod (another worktree: ``git worktree add DIR COMMIT``).
"""

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from benchmark_risers import FINE, PLAIN_LONG, PLAIN_SHORT, RISER, plain_line  # noqa: E402

# python -m petsc_rod with the continuation's clock on the process's CPU time
PROCESS_CLOCK = """
import sys, time, types
import petsc_rod.__main__ as entry
start = entry.start_petsc
def clocked(*args, **kwargs):
    error = start(*args, **kwargs)
    from petsc_rod.iteration import continuation
    continuation.time = types.SimpleNamespace(perf_counter=time.process_time)
    return error
entry.start_petsc = clocked
sys.argv = ["petsc_rod"] + sys.argv[1:]
sys.exit(entry.main())
"""


def children_seconds():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(tree, arguments, folder, process_time, log=False):
    """(solve s, iterations, -log_view's total s or None, process s) of one run in
    ``tree``; process s is wall time, or CPU time with ``process_time``."""
    output = os.path.join(folder, "result.h5")
    if os.path.exists(output):
        os.remove(output)
    entry = ["-c", PROCESS_CLOCK] if process_time else ["-m", "petsc_rod"]
    command = [sys.executable, *entry, *arguments, "-rod_output", output] \
        + (["-log_view"] if log else [])
    environment = dict(os.environ, PYTHONPATH=str(tree),
                       OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS", "1"))
    cpu, clock = children_seconds(), os.times().elapsed
    done = subprocess.run(command, cwd=tree, capture_output=True, text=True,
                          env=environment)
    process = (children_seconds() - cpu) if process_time else (os.times().elapsed - clock)
    if done.returncode not in (0, 3):            # 3: stopped at -rod_al_max_it (the plain line)
        raise RuntimeError(f"{tree}: exit {done.returncode}: {done.stderr[-500:]}")
    with h5py.File(output, "r") as f:
        solve, iterations = float(f.attrs["wall_time"]), int(f.attrs["total_iterations"])
    os.remove(output)
    total = None
    if log:
        total = float(re.search(r"Time \(sec\):\s+(\S+)", done.stdout).group(1))
    return solve, iterations, total, process


def round_of(tree, folder, process_time):
    """(one plain iteration s, solve, -log_view total, process) of one round in ``tree``,
    the last three in plain iterations."""
    short, few, _, _ = run(tree, plain_line(PLAIN_SHORT), folder, process_time)
    riser = ["-options_file", str(RISER.relative_to(ROOT)), "-rod_elements", str(FINE)]
    solve, _, total, process = run(tree, riser, folder, process_time, log=True)
    long, many, _, _ = run(tree, plain_line(PLAIN_LONG), folder, process_time)
    per = (long - short) / (many - few)
    return per, solve / per, total / per, process / per


def describe(worths, process_time):
    """The solve's, the whole run's and the process's worth as words (the -log_view
    total is wall time: left out in process time)."""
    solve, total, process = worths
    run = "" if process_time else f", -log_view total {total:.0f}"
    return f"solve {solve:.0f}{run}, process {process:.0f} plain iterations"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trees", nargs="*", default=[str(ROOT)])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--process-time", action="store_true")
    args = parser.parse_args()
    trees = [Path(tree).resolve() for tree in args.trees]
    rows = {tree: [] for tree in trees}
    unit = "process time" if args.process_time else "wall time"
    with tempfile.TemporaryDirectory() as folder:
        for number in range(args.rounds):
            for tree in (trees if number % 2 == 0 else trees[::-1]):
                per, solve, total, process = round_of(tree, folder, args.process_time)
                rows[tree].append((per, solve, total, process))
                print(f"round {number} {tree}: plain iteration {1e3 * per:.1f} ms ({unit}); "
                      f"{describe((solve, total, process), args.process_time)}; "
                      f"load {os.getloadavg()[0]:.2f}", flush=True)
    for tree, values in rows.items():
        medians = [statistics.median(column) for column in zip(*values)]
        print(f"{tree}: medians of {len(values)} rounds: plain iteration "
              f"{1e3 * medians[0]:.1f} ms; {describe(medians[1:], args.process_time)}")


if __name__ == "__main__":
    main()
