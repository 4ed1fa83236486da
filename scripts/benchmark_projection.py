"""Micro-benchmark of the local step's projection onto SO(3) (projection.nearest_rotation).

    python scripts/benchmark_projection.py [--sizes 1e4,1e5,1e6] [--repeat N]
                                           [--kernel MODULE.FUNCTION]

For each input class and point count: points per second of the kernel and of the batched
SVD (projection.nearest_rotation_svd), best of a few runs on one core (--repeat N: of N
rounds over all the cases, against a machine shared with other jobs), and how far the
kernel's rotations are from the SVD's. Input classes (b = rows b_i, as the local step
gets them):
  near       R (Q + 0.05 G), Q a random rotation, G standard normal, R = 400: a running
             iteration's b = R d + lambda (singular values within about 15% of R)
  far        standard normal matrices with det > 0: a start far from any rotation
  singular   half rank 1 (x y^T), half rank 2 (Q diag(s1, s2, 0) P^T)
  reflected  Q diag(s1, s2, -s3) P^T, det < 0, s1 > s2 > s3 > 0 apart
"dev" is max |T - T_svd| over the points whose maximiser is unique (all but rank 1);
"objective" is the largest shortfall (f(T_svd) - f(T)) / |b|, f(T) = sum_i T_i . b_i,
over all points, rank 1 included; "eigen" the share of points that Newton leaves to the
eigen-solve (neither b nor projection.shifted(b) suited it). --kernel times another
function with the same signature (e.g. an older projection.py copied outside the
repository, on PYTHONPATH).
"""

import argparse
import importlib
import time

import numpy as np

from petsc_rod.local_step import projection
from petsc_rod.local_step.projection import nearest_rotation, nearest_rotation_svd

PENALTY = 400.0
CLASSES = ("near", "far", "singular", "reflected")
# seconds of timed runs aimed at per measurement (at least one run, at most MAX_RUNS)
BUDGET = 0.5
MAX_RUNS = 20


def random_rotations(rng, n):
    """n uniformly distributed rotations (from unit quaternions)."""
    w, x, y, z = rng.normal(size=(4, n))
    norm = np.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.stack([w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
                    axis=1).reshape(n, 3, 3)


def with_singular_values(rng, s):
    """Q diag(s) P^T for random rotations Q, P; s (n, 3)."""
    q, p = random_rotations(rng, len(s)), random_rotations(rng, len(s))
    return np.einsum("nij,nj,nkj->nik", q, s, p)


def inputs(name, n, rng):
    """(b (n, 3, 3), mask of the points whose maximiser is unique)."""
    unique = np.ones(n, dtype=bool)
    if name == "near":
        b = PENALTY * (random_rotations(rng, n) + 0.05 * rng.normal(size=(n, 3, 3)))
    elif name == "far":
        b = rng.normal(size=(n, 3, 3))
        b[np.linalg.det(b) < 0] *= -1.0
    elif name == "singular":
        half = n // 2
        x, y = rng.normal(size=(2, half, 3))
        s = np.stack([rng.uniform(1.5, 2.0, n - half), rng.uniform(0.5, 1.2, n - half),
                      np.zeros(n - half)], axis=1)
        b = np.concatenate([x[:, :, None] * y[:, None, :], with_singular_values(rng, s)])
        unique[:half] = False
    elif name == "reflected":
        s = np.stack([rng.uniform(1.5, 2.0, n), rng.uniform(0.9, 1.4, n),
                      -rng.uniform(0.1, 0.8, n)], axis=1)
        b = with_singular_values(rng, s)
    else:
        raise ValueError(name)
    return b, unique


def best_time(function, b):
    """(best seconds over the runs, last result)."""
    times = []
    while True:
        clock = time.perf_counter()
        result = function(b)
        times.append(time.perf_counter() - clock)
        if len(times) >= MAX_RUNS or sum(times) > BUDGET:
            return min(times), result


def eigen_share(b):
    """Share of the points of b that projection.nearest_rotation leaves to the eigen-solve:
    those Newton takes neither as they are nor shifted."""
    flat = b.reshape(-1, 3, 3)
    out = np.empty_like(flat)
    left = 0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for start in range(0, len(flat), projection.BLOCK):
            block = flat[start:start + projection.BLOCK]
            missed = projection.polar_newton(block, out[start:start + projection.BLOCK])
            if missed is not None:
                hard = block[missed]
                mask = projection.polar_newton(projection.shifted(hard), np.empty_like(hard))
                left += 0 if mask is None else np.count_nonzero(mask)
    return left / max(len(flat), 1)


def measure(kernel, name, n, rng, repeat):
    """Columns of one row: best kernel and SVD seconds, dev, objective, eigen share."""
    b, unique = inputs(name, n, rng)
    fast = slow = np.inf
    for _ in range(repeat):
        seconds, t = best_time(kernel, b)
        fast = min(fast, seconds)
        seconds, reference = best_time(nearest_rotation_svd, b)
        slow = min(slow, seconds)
    dev = np.abs(t - reference)[unique].max(initial=0.0)
    size = np.sqrt(np.einsum("nij,nij->n", b, b))
    size[size == 0] = 1.0
    shortfall = (np.einsum("nij,nij->n", reference - t, b) / size).max(initial=0.0)
    share = f"{eigen_share(b):.1%}" if kernel is nearest_rotation else "-"
    return fast, slow, dev, shortfall, share


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1e4,1e5,1e6", help="point counts (1e4,1e5,1e6)")
    parser.add_argument("--repeat", type=int, default=1,
                        help="rounds over all the cases, the best of each kept (1)")
    parser.add_argument("--kernel", default=None,
                        help="MODULE.FUNCTION to time instead of projection.nearest_rotation")
    args = parser.parse_args()
    kernel = nearest_rotation
    if args.kernel:
        module, function = args.kernel.rsplit(".", 1)
        kernel = getattr(importlib.import_module(module), function)
    sizes = [int(float(size)) for size in args.sizes.split(",")]
    rng = np.random.default_rng(0)
    kernel(inputs("near", 100, rng)[0])             # warm-up (work arrays, imports)
    print(f"numpy {np.__version__}, one core; kernel {kernel.__module__}.{kernel.__name__}")
    print("| input | points | kernel M/s | SVD M/s | speed-up | dev | objective | eigen |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    clock = time.perf_counter()
    for name in CLASSES:
        for n in sizes:
            fast, slow, dev, shortfall, share = measure(kernel, name, n, rng, args.repeat)
            print(f"| {name} | {n:.0e} | {n / fast / 1e6:.2f} | {n / slow / 1e6:.2f} | "
                  f"{slow / fast:.1f} | {dev:.1e} | {shortfall:.1e} | {share} |", flush=True)
    print(f"({time.perf_counter() - clock:.0f} s)")


if __name__ == "__main__":
    main()
