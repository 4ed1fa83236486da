"""Iterations per step and wall time: the plain iteration against the default one.

    python scripts/benchmark_iterations.py [--only WORDS] [--max-it N] [--out FILE]

Every shipped scene (options/*.opts) and one case of each group of the stability matrix
(scripts/stability_matrix.py) is run twice as a user runs it, in a child process on
1 rank: with ``-rod_snes_type nrichardson -rod_al_newton 0`` (the plain iteration,
x <- G(x)) and with the default (Anderson mixing, Newton steps near the solution, the
stability check). Both runs use the scene's own
tolerances, so they stop on the same tests. Printed side by side, and written as a
Markdown table to FILE (default docs/iterations.md): outcome, total iterations, the
largest and the mean iterations per step, wall time, and the energy. For the paper
scene the energy is also compared with the collocation reference.
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT))

import stability_matrix  # noqa: E402

PLAIN = ["-rod_snes_type", "nrichardson", "-rod_al_newton", "0"]
# The collocation reference of the paper scene at X_F = 16, K3 = 200
# (tests/unit/test_collocation_reference.py recomputes it:
# petsc_rod.validation.reference.solve_paper_scene).
PAPER_ENERGY = 40.5313519
TIMEOUT = 1800.0


def scenes():
    """(group, name, arguments) of every shipped scene."""
    return [("scene", path.stem, ["-options_file", str(path)])
            for path in sorted((ROOT / "options").glob("*.opts"))]


def matrix_representatives():
    """(group, name, arguments) of the first single-rank case of each matrix group, and
    of the anisotropic cases the iteration was slow on."""
    chosen, seen = [], set()
    for case in stability_matrix.cases():
        wanted = case.group not in seen or "K2/K1" in case.name or "K3/K1 = 10" in case.name
        if case.ranks == 1 and case.needs is None and wanted:
            seen.add(case.group)
            chosen.append((case.group, case.name, stability_matrix.option_list(case.options)))
    return chosen


def run_child(arguments, folder, ranks=1, timeout=TIMEOUT):
    """One child run of petsc_rod as a user runs it (``mpiexec -n ranks`` for ranks > 1)
    with its result written into ``folder``: (outcome, wall time of the process in s,
    the result file's path or None when there is none)."""
    output = os.path.join(folder, "result.h5")
    if os.path.exists(output):
        os.remove(output)
    command = [*stability_matrix.python_command(ranks), *arguments, "-rod_output", output]
    clock = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                              cwd=ROOT)
    except subprocess.TimeoutExpired:
        return "timeout", timeout, None
    wall = time.perf_counter() - clock
    outcome = {0: "converged", 3: "stopped", 4: "diverged"}.get(done.returncode,
                                                               f"exit {done.returncode}")
    return outcome, wall, output if os.path.exists(output) else None


def run(arguments, max_it, folder):
    """One child run; (outcome, per-step iterations, wall time, energy)."""
    outcome, wall, output = run_child(
        arguments + (["-rod_al_max_it", str(max_it)] if max_it else []), folder)
    if output is None:
        return outcome, [], wall, np.nan
    with h5py.File(output, "r") as f:
        steps = sorted(f["steps"], key=int)
        iterations = [int(f["steps"][k].attrs["iterations"]) for k in steps]
        energy = float(f.attrs["energy"])
    os.remove(output)
    return outcome, iterations, wall, energy


def row(group, name, plain, default):
    cells = [group, name]
    for outcome, iterations, wall, energy in (plain, default):
        total = sum(iterations)
        per_step = f"{max(iterations)} / {total / len(iterations):.0f}" if iterations else "-"
        cells += [outcome, str(total), per_step, f"{wall:.2f}", f"{energy:.10g}"]
    return cells


HEADER = ["group", "case",
          "plain", "iterations", "max / mean per step", "wall (s)", "energy (J)",
          "default", "iterations", "max / mean per step", "wall (s)", "energy (J)"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="comma-separated words of case names")
    parser.add_argument("--max-it", type=int, default=0,
                        help="cap -rod_al_max_it of every run (0: the case's own)")
    parser.add_argument("--out", default=str(ROOT / "docs" / "iterations.md"))
    args = parser.parse_args()
    words = [w for w in args.only.split(",") if w]
    selected = [c for c in scenes() + matrix_representatives()
                if not words or any(w in c[1] for w in words)]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for group, name, arguments in selected:
            plain = run(arguments + PLAIN, args.max_it, folder)
            default = run(arguments, args.max_it, folder)
            rows.append(row(group, name, plain, default))
            print(" | ".join(rows[-1]), flush=True)
            if name == "paper":
                print(f"paper: default energy - collocation reference = "
                      f"{default[3] - PAPER_ENERGY:.2e} J", flush=True)
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(cells) + " |" for cells in rows]
    if not words:
        command = " ".join(["python scripts/benchmark_iterations.py"] + sys.argv[1:])
        Path(args.out).write_text(
            f"# Iterations: plain against default\n\nWritten by `{command}` (1 rank; the "
            "scene's own tolerances and halvings; `iterations` counts every iteration of "
            "the accepted steps, `max / mean per step` over them; the plain iteration is "
            "`-rod_snes_type nrichardson -rod_al_newton 0`).\n\n" + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
