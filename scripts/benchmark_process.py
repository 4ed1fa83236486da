"""The whole command against its solve: what a user waits for beyond the iterations.

    python scripts/benchmark_process.py [SCENE ...] [--runs N] [--ranks R]
        [--tree DIR ...] [--args "-rod_output x.h5 ..."] [--breakdown]

Runs ``python -m petsc_rod -options_file options/SCENE.opts`` (``mpiexec -n R`` for R > 1)
N times (default 5) per scene (default cable_800m) as a user runs it, and prints for each
the median of the whole process's wall time, of the solve's (the run's own line
"converged, N iterations in X s": the continuation, without the start-up, the stability
test's last report, the output and the exit) and of their difference, with the load
average before and after. With several ``--tree`` checkouts (another commit's worktree,
say) their runs are alternated, so that each sees the shared machine in the same states:
the comparison of a change. ``--breakdown`` says where the difference goes, each the
median of N: the interpreter alone, with numpy, with MPI and PETSc started (with
``python -m petsc_rod``'s Open MPI defaults), and the run's ``-log_view`` stages (the
Main Stage: the imports after PETSc started, the options, the exit's share PETSc sees)
against its whole time. The environment is the caller's (run it after
``source scripts/setup.sh``), so the Open MPI defaults of ``python -m petsc_rod`` apply as
they do for a user (docs/performance.md, "Where the remaining time goes").
"""

import argparse
import os
import re
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SOLVE_LINE = re.compile(r"converged, \d+ iterations in ([0-9.eE+-]+) s")


def one_run(tree, scene, ranks, extra):
    """(whole wall time, solve time) of one run in checkout ``tree``, s."""
    command = [sys.executable, "-m", "petsc_rod", "-options_file",
               str(Path(tree) / "options" / f"{scene}.opts"), *extra]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), *command]
    started = time.perf_counter()
    done = subprocess.run(command, cwd=tree, capture_output=True, text=True, check=False)
    whole = time.perf_counter() - started
    found = SOLVE_LINE.findall(done.stdout)
    if done.returncode != 0 or not found:
        sys.exit(f"benchmark_process: {' '.join(command)} failed (exit {done.returncode}):\n"
                 f"{done.stdout[-2000:]}{done.stderr[-2000:]}")
    return whole, float(found[-1])


STAGE_LINE = re.compile(r"^ *\d+: +(.+?): +(\S+) ", re.MULTILINE)
STARTS = {"python": "pass", "python + numpy": "import numpy",
          "python + numpy + MPI + PETSc": "import petsc4py; petsc4py.init(); "
                                          "from petsc4py import PETSc"}


def wall(command, env=None):
    """Wall time of ``command`` (s) and its stdout."""
    started = time.perf_counter()
    done = subprocess.run(command, cwd=ROOT, env=env, capture_output=True, text=True,
                          check=True)
    return time.perf_counter() - started, done.stdout


def breakdown(scene, runs, extra):
    """Print the medians of the start-ups and of the run's -log_view stages."""
    sys.path.insert(0, str(ROOT))
    from petsc_rod.__main__ import open_mpi_defaults
    env = {**os.environ, **open_mpi_defaults(os.environ)}
    rows = {}
    for _ in range(runs):
        for name, code in STARTS.items():
            rows.setdefault(name, []).append(wall([sys.executable, "-c", code], env)[0])
        whole, out = wall([sys.executable, "-m", "petsc_rod", "-options_file",
                           str(ROOT / "options" / f"{scene}.opts"), "-log_view", *extra])
        rows.setdefault("whole command (-log_view)", []).append(whole)
        rows.setdefault("solve line", []).append(float(SOLVE_LINE.findall(out)[-1]))
        stages = dict(STAGE_LINE.findall(out))
        for name, seconds in stages.items():
            rows.setdefault(f"stage {name}", []).append(float(seconds))
        rows.setdefault("before and after PETSc's clock",
                        []).append(whole - sum(map(float, stages.values())))
    print(f"{scene}, medians of {runs} (load {os.getloadavg()[0]:.2f}):")
    for name, values in rows.items():
        print(f"  {name:<36} {statistics.median(values):7.3f} s")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="*", default=["cable_800m"])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--tree", action="append", default=None,
                        help="a checkout to run (repeatable: alternated); default this one")
    parser.add_argument("--args", default="", help="more options for every run")
    parser.add_argument("--breakdown", action="store_true",
                        help="the start-ups and -log_view's stages of this checkout")
    args = parser.parse_args()
    trees = [str(Path(tree).resolve()) for tree in (args.tree or [ROOT])]
    extra = shlex.split(args.args)
    if args.breakdown:
        for scene in args.scenes:
            breakdown(scene, args.runs, extra)
        return
    print(f"{'scene':<16} {'tree':<28} {'whole (s)':>9} {'solve (s)':>9} "
          f"{'whole - solve':>13} {'load before, after':>19}")
    for scene in args.scenes:
        times = {tree: [] for tree in trees}
        load_before = os.getloadavg()[0]
        for _ in range(args.runs):
            for tree in trees:
                times[tree].append(one_run(tree, scene, args.ranks, extra))
        load_after = os.getloadavg()[0]
        for tree, runs in times.items():
            whole = statistics.median(w for w, _ in runs)
            solve = statistics.median(s for _, s in runs)
            rest = statistics.median(w - s for w, s in runs)
            name = tree if len(tree) <= 28 else "..." + tree[-25:]
            print(f"{scene:<16} {name:<28} {whole:9.3f} {solve:9.3f} {rest:13.3f} "
                  f"{load_before:9.2f} {load_after:9.2f}", flush=True)


if __name__ == "__main__":
    main()
