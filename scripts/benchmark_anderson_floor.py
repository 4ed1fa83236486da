"""The least time Anderson mixing's history can cost per iteration, whatever the code.

    python scripts/benchmark_anderson_floor.py [elements] [--depth M] [--repeat K]

Anderson mixing of depth m keeps m residual differences and m iterate differences of
the SNES vector (18 numbers per P2 node, 2 N + 1 nodes for N elements). However it is
written, an iteration reads both histories once: the residuals for the new column of
their Gram matrix (with the right-hand side of the least-squares problem updated from
it, no further pass), the iterates for the combination. This script times those two
passes as single BLAS calls on contiguous (m, 18 (2N + 1)) arrays, one thread (as
``python -m petsc_rod`` runs), and prints them per element beside PETSc's Anderson,
which reads the residuals twice and the iterates once (docs/performance.md, "Anderson
mixing"). The best of --repeat runs is kept.
"""

import argparse
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")     # as python -m petsc_rod runs
import numpy as np  # noqa: E402

NUMBERS_PER_NODE = 18


def best_time(function, repeat):
    """The shortest of ``repeat`` calls of ``function``, s."""
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("elements", type=int, nargs="?", default=100000)
    parser.add_argument("--depth", type=int, default=30)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(sys.argv[1:])
    if args.elements < 1 or args.depth < 1 or args.repeat < 1:
        parser.error("elements, --depth and --repeat must be positive")
    size = NUMBERS_PER_NODE * (2 * args.elements + 1)
    rng = np.random.default_rng(0)
    residuals = rng.random((args.depth, size))
    iterates = rng.random((args.depth, size))
    new_residual, coefficients = rng.random(size), rng.random(args.depth)
    combination = np.empty(size)
    gram = best_time(lambda: residuals @ new_residual, args.repeat)
    combine = best_time(lambda: np.dot(coefficients, iterates, out=combination), args.repeat)
    history = residuals.nbytes
    per_element = 1e6 / args.elements
    print(f"{args.elements} elements, depth {args.depth}: each history "
          f"{history / 2**20:.0f} MiB")
    print(f"  Gram column (residuals once):  {1e3 * gram:7.1f} ms  "
          f"{history / gram / 1e9:5.1f} GB/s")
    print(f"  combination (iterates once):   {1e3 * combine:7.1f} ms  "
          f"{history / combine / 1e9:5.1f} GB/s")
    print(f"  floor, both passes:            {(gram + combine) * per_element:7.2f} us "
          f"per element and iteration")
    print(f"  PETSc's three passes at that speed: {(2 * gram + combine) * per_element:7.2f} us "
          f"per element and iteration (without its copies)")


if __name__ == "__main__":
    main()
