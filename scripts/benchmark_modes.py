"""The modes' benchmark (issue 50): the 20 lowest modes of options/riser_catenary.opts
at 18 000 elements, on 1 and 2 ranks.

    python scripts/benchmark_modes.py [--pairs P] [--elements N] [--modes M] [EXTRA ...]

Runs ``python -m petsc_rod -options_file options/riser_catenary.opts -rod_elements N
-rod_modes M`` (and EXTRA options, e.g. -rod_modes_eps_ncv 40) on 1 rank and on 2
ranks, alternated (P pairs, default 3: both see the shared machine in the same states),
and reads the time of the modes from the run's line (``modes: M lowest ... in T s``: the
operators, the factorisation, the eigensolver and the shapes, without the static
solve). Prints the best and the median of each, the median of the pairs' ratios, the
machine's load average before and after, and the lowest frequencies of each (the same
on 1 and 2 ranks). Targets: under 10 s on 1 rank, faster on 2.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TIME = re.compile(r"modes: (\d+) lowest about the static state in ([0-9.e+-]+) s")
ROW = re.compile(r"^\s+(\d+)\s+([0-9.e+-]+)\s+")


def run(ranks, elements, modes, extra):
    command = [sys.executable, "-m", "petsc_rod", "-options_file",
               os.path.join(ROOT, "options", "riser_catenary.opts"),
               "-rod_elements", str(elements), "-rod_modes", str(modes), *extra]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks), *command]
    out = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, check=True).stdout
    found = TIME.search(out)
    if not found:
        raise SystemExit(f"benchmark_modes: no modes' line in the output of {command}:\n{out}")
    after = out[found.end():]
    frequencies = [float(m.group(2)) for m in map(ROW.match, after.splitlines()) if m]
    return float(found.group(2)), frequencies[:modes]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--elements", type=int, default=18000)
    parser.add_argument("--modes", type=int, default=20)
    args, extra = parser.parse_known_args()
    load_before = os.getloadavg()
    times = {1: [], 2: []}
    frequencies = {}
    for _ in range(args.pairs):
        for ranks in (1, 2):
            seconds, frequencies[ranks] = run(ranks, args.elements, args.modes, extra)
            times[ranks].append(seconds)
    load_after = os.getloadavg()
    ratios = [a / b for a, b in zip(times[1], times[2])]
    print(f"riser_catenary, {args.elements} elements, {args.modes} modes, "
          f"{args.pairs} alternated pairs; load average {load_before[0]:.2f} before, "
          f"{load_after[0]:.2f} after")
    for ranks in (1, 2):
        print(f"  {ranks} rank{'s' if ranks > 1 else ''}: best {min(times[ranks]):.2f} s, "
              f"median {statistics.median(times[ranks]):.2f} s "
              f"({', '.join(f'{t:.2f}' for t in times[ranks])})")
    print(f"  speed-up on 2 ranks (median of the pairs' ratios): {statistics.median(ratios):.2f}")
    print(f"  lowest frequencies (Hz), 1 rank: {frequencies[1][:6]}")
    print(f"                             2 ranks: {frequencies[2][:6]}")


if __name__ == "__main__":
    main()
