"""Every scene of options/ on 1 and 2 ranks: is a second rank ever slower?

    python scripts/benchmark_scenes.py [--pairs P] [--only WORDS] [--fit] [--out FILE]

Each scene (``options/*.opts``; a system's, ``-rod_system``, is left out: its lines are
placed by system/placement.py) runs as a user runs it, ``python -m petsc_rod
-options_file options/X.opts`` and the same under ``mpiexec -n 2``, in P alternated
1-rank / 2-rank pairs (default 3; 10 to decide), so that both see the shared machine in
the same states. The time is the solve's as the run reports it (its line "converged, N
iterations in X s"). The table gives each scene's elements, where -rod_ranks_split auto
puts it on 2 ranks (mesh/ranks.choose), the median 1-rank and 2-rank times and the median
of the pairs' ratios (2 ranks over 1: above 1 a second rank loses), with the commit and
the machine's load (os.getloadavg) before and after.

``--fit`` measures the cost model of mesh/ranks.py: each pair also runs the scene split
over 2 ranks (-rod_ranks_split split, where auto does not already), and the time of an
iteration (solve time over iterations, the pairs' median) is fitted as a + b N over the
scenes without seabed friction (whose passes mesh/ranks.py models apart, PASS_WHOLE and
PASS_SPLIT: docs/performance.md), whole on 1 rank and split on 2 (least squares relative
to the time); the constants and the crossover N* are printed and written below the
table, to be put in mesh/ranks.py (WHOLE, SPLIT) from a run on a quiet machine.

Written as Markdown to FILE (default docs/scenes_benchmark.md, which
docs/performance.md links) unless --only is given.
"""

import argparse
import datetime
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from petsc_rod.mesh.ranks import IterationCost, choose, crossover, passes_of  # noqa: E402

PAIRS = 3
TIMEOUT = 600
SOLVED = re.compile(r"petsc_rod: converged, (\d+) iterations in ([0-9.eE+-]+) s")
ELEMENTS = re.compile(r"petsc_rod: (\d+) elements on (\d+) rank")


def scenes(only=None):
    """The options files of the single-line scenes, by name, sorted."""
    found = []
    for path in sorted((ROOT / "options").glob("*.opts")):
        text = path.read_text(encoding="utf-8")
        if re.search(r"^\s*-rod_system\b", text, re.M):
            continue
        if only and not any(word in path.stem for word in only):
            continue
        found.append(path)
    return found


def passes(path):
    """The friction's passes an iteration the model gives the scene (mesh/ranks.passes_of:
    its options file gives -rod_seabed_friction)."""
    text = path.read_text(encoding="utf-8")
    return passes_of(re.search(r"^\s*-rod_seabed_friction\s", text, re.M) is not None)


def command(path, ranks, split=None):
    words = [sys.executable, "-m", "petsc_rod", "-options_file",
             str(path.relative_to(ROOT))]
    if split:
        words += ["-rod_ranks_split", split]
    return (["mpiexec", "-n", str(ranks)] if ranks > 1 else []) + words


def run(path, ranks, split=None):
    """(solve seconds, iterations, elements) of one run (None where it did not say)."""
    try:
        done = subprocess.run(command(path, ranks, split), cwd=ROOT, capture_output=True,
                              text=True, timeout=TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        return None, None, None
    solved, elements = SOLVED.search(done.stdout), ELEMENTS.search(done.stdout)
    if solved is None:
        return None, None, int(elements.group(1)) if elements else None
    return float(solved.group(2)), int(solved.group(1)), int(elements.group(1))


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def measure(path, pairs, fit):
    """The scene's runs: 1 rank, 2 ranks (auto) and, with ``fit``, 2 ranks split where
    auto does not split, alternated ``pairs`` times."""
    runs = {"one": [], "two": [], "split": []}
    elements = None
    for _ in range(pairs):
        runs["one"].append(run(path, 1))
        elements = elements or runs["one"][-1][2]
        runs["two"].append(run(path, 2))
        if fit and elements and choose("auto", elements, 2, passes=passes(path)) != "split":
            runs["split"].append(run(path, 2, "split"))
    if fit and not runs["split"]:
        runs["split"] = runs["two"]
    return elements, runs


def ratio(pair):
    one, two = pair
    return two[0] / one[0] if one[0] and two[0] else None


def per_iteration(runs):
    return median([t / n for t, n, _ in runs if t and n])


def fit_line(elements, seconds):
    """IterationCost a + b N fitted to ``seconds`` against ``elements``, least squares
    relative to the time."""
    n, t = np.asarray(elements, float), np.asarray(seconds, float)
    matrix = np.column_stack([1.0 / t, n / t])
    (a, b), *_ = np.linalg.lstsq(matrix, np.ones_like(t), rcond=None)
    return IterationCost(float(a), float(b))


def commit():
    done = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                          capture_output=True, text=True, check=False)
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                           cwd=ROOT, capture_output=True, text=True, check=False).stdout
    return done.stdout.strip() + (" (modified)" if dirty.strip() else "")


def load():
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def cell(value, form):
    return "-" if value is None else format(value, form)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=PAIRS)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--fit", action="store_true")
    parser.add_argument("--out", default=str(ROOT / "docs" / "scenes_benchmark.md"))
    arguments = parser.parse_args()
    before, started = load(), datetime.datetime.now(datetime.timezone.utc)
    measured = commit()                 # the code the runs import, at their start
    rows, fitted = [], []
    for path in scenes(arguments.only):
        elements, runs = measure(path, arguments.pairs, arguments.fit)
        ratios = [ratio(pair) for pair in zip(runs["one"], runs["two"])]
        row = [path.stem, cell(elements, "d"),
               choose("auto", elements, 2, passes=passes(path)) if elements else "-",
               cell(median([r[0] for r in runs["one"]]), ".3g"),
               cell(median([r[0] for r in runs["two"]]), ".3g"),
               cell(median(ratios), ".2f"),
               " / ".join(cell(median([r[1] for r in runs[k]]), ".0f") for k in ("one", "two"))]
        rows.append(row)
        print(" | ".join(row), flush=True)
        if arguments.fit and elements and not passes(path):     # friction: its passes' own fit
            fitted.append((elements, per_iteration(runs["one"]), per_iteration(runs["split"])))
    lines = [f"Measured {started:%Y-%m-%d %H:%M} UTC at commit {measured}, {arguments.pairs} "
             f"alternated pair(s) a scene; load average (1, 5, 15 min) {before} before, "
             f"{load()} after.", "",
             "| scene | elements | on 2 ranks (auto) | 1 rank (s) | 2 ranks (s) | "
             "2 ranks / 1 rank (median of pairs) | iterations (1 / 2) |",
             "|---|---:|---|---:|---:|---:|---:|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    if fitted:
        usable = [(n, a, b) for n, a, b in fitted if a and b]
        whole = fit_line([n for n, _, _ in usable], [a for _, a, _ in usable])
        split = fit_line([n for n, _, _ in usable], [b for _, _, b in usable])
        lines += ["", "Cost model (mesh/ranks.py), seconds an iteration, a + b N:", "",
                  "| scene elements | whole, 1 rank (ms / iteration) | split, 2 ranks "
                  "(ms / iteration) |", "|---:|---:|---:|"]
        lines += [f"| {n} | {cell(a and 1e3 * a, '.3g')} | {cell(b and 1e3 * b, '.3g')} |"
                  for n, a, b in fitted]
        lines += ["", f"WHOLE = IterationCost(fixed={whole.fixed:.3g}, "
                      f"per_element={whole.per_element:.3g}); SPLIT = IterationCost("
                      f"fixed={split.fixed:.3g}, per_element={split.per_element:.3g}): "
                      f"N* = {crossover(2, whole, split):.0f} elements on 2 ranks."]
    text = "\n".join(lines) + "\n"
    print(text)
    if not arguments.only:
        Path(arguments.out).write_text(
            "# Scenes on 1 and 2 ranks\n\n`python scripts/benchmark_scenes.py` "
            "(docs/performance.md, \"Two ranks or one\").\n\n" + text, encoding="utf-8")


if __name__ == "__main__":
    main()
