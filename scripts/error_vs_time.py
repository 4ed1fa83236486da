"""Error against wall time over elements, penalty and stopping tolerances (docs/error_vs_time.md).

One command:
    python scripts/error_vs_time.py [--quick] [--out docs/error_vs_time]
runs the serial sweep in this process, then the same script under `mpiexec -n 2` for the
2-rank subset, and writes OUT/runs.csv, OUT/error_vs_time.png and OUT/summary.md (the
tables of docs/error_vs_time.md: discretisation errors, fitted orders, fastest runs per
target accuracy). `--summarise OUT/runs.csv` redraws the plot and tables only;
`--parallel-only` reruns the 2-rank subset into an existing OUT/runs.csv. Progress: one
line per run. `--quick` is a small setting that finishes in about a minute (the tests
run it); without it the serial sweep takes about half an hour and the 2-rank subset
about ten minutes on an idle 2-core machine.

Scenes and references:
- cantilever: P L^2/EI = 3, dead tip force; elliptic-integral elastica (closed_forms)
  for r and d, the collocation reference (reference.py) for the energy;
- twist: both ends clamped on the axis, end rolled by 1 rad; u3 = 1 / L exactly;
- paper: docs/method.md §8 at X_F = 16, K3 = 200; the collocation reference of the
  out-of-plane branch, compared with the nearer of the mirror pair (z -> -z).

What one run is: a mesh of N elements and a penalty R, solved as the CLI solves it (the
paper scene by 8 continuation steps at the paper's tolerances 1e-5 / 1e-3, then the last
step) and iterated on the last step until the tightest pair of TOLERANCES holds or the
iteration stalls. On the way, the state is recorded the first time each pair
(rtol, ctol = 100 rtol) holds: that is exactly the state, and the wall time, of a run
stopped by that pair (the time spent recording is subtracted). Should the iteration
stall (round-off on very fine meshes), the run stops once STALL_FACTOR times the
iterations of the last recorded pair (and at least STALL_MINIMUM) have passed without
reaching the next one. The tightest recorded state stands for the discrete solution of
that mesh: its error
against the reference is the discretisation error, and the distance of a recorded state
to it is the iteration error of that tolerance.
"""

import argparse
import csv
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from script_support import start_petsc  # noqa: E402  (scripts/ is sys.path[0])

TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
MAX_ITERATIONS = 40000
STALL_FACTOR = 1.0
STALL_MINIMUM = 8000
COLUMNS = ("scene", "ranks", "elements", "penalty", "rtol", "ctol", "iterations",
           "wall_time", "position_error", "director_error", "u3_error", "energy_error",
           "iteration_error", "discretisation_error", "tightest")

# (scene, elements, penalty factors R L^2 / max K); the middle factor is the default R.
FULL = {
    "cantilever": ((25, 50, 100, 200, 400, 800, 1600, 3200), (40.0, 400.0, 4000.0)),
    "twist": ((25, 50, 100, 200, 400, 800, 1600, 3200), (40.0, 400.0, 4000.0)),
    "paper": ((25, 50, 100, 200, 400, 800, 1600, 3200), (100.0, 400.0, 1600.0)),
}
# Larger meshes are run at the middle penalty only (a paper-scene run takes minutes).
ALL_PENALTIES_UP_TO = 400
QUICK = {"cantilever": ((25, 50), (400.0,)), "twist": ((25,), (400.0,)),
         "paper": ((25,), (400.0,))}
PARALLEL_ELEMENTS = (100, 400, 1600)     # the 2-rank subset, middle penalty
QUICK_PARALLEL_ELEMENTS = (25,)


def scene_definitions():
    """name -> (Scene kwargs, continuation steps, imperfection)."""
    return {
        "cantilever": (dict(length=1.0, stiffness=[1.0, 1.0, 1.0], start="clamp", end="free",
                            end_force=[0.0, -3.0, 0.0]), 1, 0.0),
        "twist": (dict(length=1.0, stiffness=[1.0, 1.0, 0.5], start="clamp", end="clamp",
                       end_twist=1.0), 1, 0.0),
        "paper": (dict(length=20.0, stiffness=[235.0, 360.0, 200.0], start="clamp",
                       end="pin", end_position=[16.0, 4.0, 0.0]), 8, 0.01),
    }


class CantileverReference:
    def __init__(self):
        from petsc_rod.validation import reference
        bvp = reference.solve_cantilever_bvp(1.0, 1.0, 3.0, tol=1e-10)
        self.energy = reference.energy(bvp) + 3.0 * bvp.r[-1, 1]     # - F.r(L)
        self.u3 = 0.0

    def fields(self, S):
        from petsc_rod.validation.closed_forms import cantilever_shape
        theta, x, y = cantilever_shape(1.0, 1.0, 3.0, S)
        zero = 0 * S
        r = np.stack([x, y, zero], axis=1)
        d1 = np.stack([np.sin(theta), np.cos(theta), zero], axis=1)
        d2 = np.stack([zero, zero, zero + 1.0], axis=1)
        return [(r, d1, d2)]


class TwistReference:
    energy = 0.25          # K3 a^2 / (2 L), a = 1 rad the end roll
    u3 = 1.0

    def fields(self, S):
        zero = 0 * S
        r = np.stack([S, zero, zero], axis=1)
        d1 = np.stack([zero, np.cos(S), np.sin(S)], axis=1)
        d2 = np.stack([zero, -np.sin(S), np.cos(S)], axis=1)
        return [(r, d1, d2)]


class PaperReference:
    """The out-of-plane branch at X_F = 16 and its mirror image (z -> -z)."""

    def __init__(self):
        from petsc_rod.validation import reference
        guess = reference.shooting_guess(20.0, (235.0, 360.0, 200.0), (-11.6, -4.03, 2.30),
                                         (9.21, -36.8, -18.0))
        self.bvp = reference.solve_paper_scene(16.0, guess, tol=1e-10)
        assert self.bvp.status == 0, self.bvp.message
        self.energy = reference.energy(self.bvp)
        self.u3 = float(self.bvp.sample(np.zeros(1))["u"][0, 2])

    def fields(self, S):
        state = self.bvp.sample(S)
        mirror = np.array([1.0, 1.0, -1.0])
        branch = (state["r"], state["d1"], state["d2"])
        mirrored = (state["r"] * mirror, state["d1"] * mirror, -state["d2"] * mirror)
        return [branch, mirrored]


REFERENCES = {"cantilever": CantileverReference, "twist": TwistReference,
              "paper": PaperReference}


def snapshot(problem):
    """What the errors need, on this rank's vertices: S, r, d1, d2; u3(0); energy."""
    from petsc_rod.io.outputs import vertex_strains
    mesh = problem.mesh
    u = vertex_strains(problem)                # collective (ghost update): every rank
    u3 = u[0, 2] if mesh.on_lower_boundary else 0.0
    state = problem.state
    return {"S": mesh.vertex_S.copy(), "r": state.r.owned()[:, 0].copy(),
            "d1": state.d1.owned()[:, 0].copy(), "d2": state.d2.owned()[:, 0].copy(),
            "u3": mesh.global_sum(u3), "energy": problem.energy()}


def errors(mesh, state, reference, expected_fields):
    """Max vertex errors against the reference (the nearer mirror image for the paper)."""
    best = None
    for sign, (r, d1, d2) in zip((1.0, -1.0), expected_fields):
        position = mesh.global_max(np.abs(state["r"] - r).max(initial=0.0))
        director = mesh.global_max(max(np.abs(state["d1"] - d1).max(initial=0.0),
                                       np.abs(state["d2"] - d2).max(initial=0.0)))
        u3 = abs(state["u3"] - sign * reference.u3)
        if best is None or position < best[0]:
            best = (position, director, u3)
    return best + (abs(state["energy"] - reference.energy),)


def distance(mesh, state, final):
    return mesh.global_max(np.abs(state["r"] - final["r"]).max(initial=0.0))


def run_one(comm, name, n_elements, penalty, reference):
    """One mesh and penalty: a row for each tolerance pair the last step reached."""
    from petsc_rod.mesh.mesh import Mesh
    from petsc_rod.scenes.scene import Scene
    from petsc_rod.cli.session import run_continuation
    from petsc_rod.iteration.continuation import PathSettings
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings

    kwargs, steps, imperfection = scene_definitions()[name]
    scene = Scene(**kwargs)
    mesh = Mesh(comm, n_elements, scene.length)
    solver = solver_for(mesh, scene, Settings(asked_penalty=penalty, max_it=MAX_ITERATIONS,
                                               rtol=1e-5, ctol=1e-3))
    try:
        clock = time.perf_counter()
        solver.problem.state.set_straight()
        earlier = 0                 # iterations of the continuation steps before the last
        if steps > 1:
            before = run_continuation(solver, PathSettings(steps - 1, imperfection,
                                                           end=(steps - 1) / steps))
            if not before.converged:
                raise RuntimeError(f"{name}: the continuation to the last step did not "
                                   "converge")
            earlier = before.iterations
        solver.problem.state.roll_cross_sections(imperfection)
        solver.settings.rtol, solver.settings.ctol = TOLERANCES[-1], 100 * TOLERANCES[-1]
        pending = list(TOLERANCES)
        recorded = []
        spent = [0.0]

        def observer(iteration, change, residual):
            while pending and change <= pending[0] and residual <= 100 * pending[0]:
                start = time.perf_counter()
                recorded.append((pending.pop(0), earlier + iteration,
                                 start - clock - spent[0], snapshot(solver.problem)))
                spent[0] += time.perf_counter() - start
            last = recorded[-1][1] - earlier if recorded else 0
            return iteration - last > max(STALL_MINIMUM, STALL_FACTOR * last)

        report = solver.solve_step(1.0, observer=observer)
        if not recorded:
            raise RuntimeError(f"{name}: no tolerance reached in {report.iterations} its")
        final = recorded[-1][3]
        expected = reference.fields(final["S"])
        discretisation = errors(mesh, final, reference, expected)[0]
        rows = []
        for rtol, iterations, seconds, state in recorded:
            position, director, u3, energy = errors(mesh, state, reference, expected)
            rows.append(dict(scene=name, ranks=comm.getSize(), elements=n_elements,
                             penalty=penalty, rtol=rtol, ctol=100 * rtol,
                             iterations=iterations, wall_time=seconds,
                             position_error=position, director_error=director, u3_error=u3,
                             energy_error=energy, iteration_error=distance(mesh, state, final),
                             discretisation_error=discretisation,
                             tightest=int(rtol == recorded[-1][0])))
        return rows
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()


def sweep(comm, plan, say):
    """plan: list of (scene, elements, penalty factor). Rows of every run."""
    references, rows = {}, []
    for index, (name, n_elements, factor) in enumerate(plan, 1):
        if name not in references:
            references[name] = REFERENCES[name]()
        kwargs = scene_definitions()[name][0]
        penalty = factor * max(kwargs["stiffness"]) / kwargs["length"]**2
        clock = time.perf_counter()
        try:
            result = run_one(comm, name, n_elements, penalty, references[name])
        except RuntimeError as error:
            say(f"[{index}/{len(plan)}] {name:10s} {comm.getSize()} rank(s) N = "
                f"{n_elements:5d} R = {penalty:8.4g}: FAILED: {error}")
            continue
        final = result[-1]
        say(f"[{index}/{len(plan)}] {name:10s} {comm.getSize()} rank(s) N = {n_elements:5d} "
            f"R = {penalty:8.4g}: rtol {final['rtol']:g} in {final['iterations']:6.0f} its, "
            f"{final['wall_time']:7.2f} s, position error {final['position_error']:.2e}, "
            f"director error {final['director_error']:.2e} "
            f"(run {time.perf_counter() - clock:.1f} s)")
        rows.extend(result)
    return rows


def serial_plan(quick):
    plan = []
    for name, (sizes, factors) in (QUICK if quick else FULL).items():
        for n in sizes:
            for factor in factors:
                if (n > ALL_PENALTIES_UP_TO
                        and factor != factors[len(factors) // 2]):
                    continue
                plan.append((name, n, factor))
    return plan


def parallel_plan(quick):
    sizes = QUICK_PARALLEL_ELEMENTS if quick else PARALLEL_ELEMENTS
    return [(name, n, 400.0) for name in FULL for n in sizes]


def write_csv(path, rows):
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def read_csv(path):
    with open(path) as stream:
        return [{key: (value if key == "scene" else float(value)) for key, value in row.items()}
                for row in csv.DictReader(stream)]


def pareto_front(points):
    """Indices of the points (time, error) that no other point beats in both."""
    order = np.lexsort((points[:, 1], points[:, 0]))
    front, best = [], np.inf
    for i in order:
        if points[i, 1] < best:
            front.append(i)
            best = points[i, 1]
    return front


PLOTTED_TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10)
# The field whose error is plotted: the twist keeps r exact, so its directors are shown.
PLOTTED_ERROR = {"cantilever": "position_error", "twist": "director_error",
                 "paper": "position_error"}


def plot(rows, path):
    """One panel per scene: position error against wall time, a curve per (ranks, R,
    tolerance) over the element counts; the Pareto front over all runs in black."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(FULL)
    figure, axes = plt.subplots(1, len(names), figsize=(6 * len(names), 5))
    styles = {tol: style for tol, style in zip(PLOTTED_TOLERANCES, ("o:", "s--", "^-.", "D-"))}
    for axis, name in zip(axes, names):
        key = PLOTTED_ERROR[name]
        mine = [row for row in rows if row["scene"] == name and row[key] > 0]
        if not mine:
            continue
        penalties = sorted({row["penalty"] for row in mine})
        colours = dict(zip(penalties, plt.cm.viridis(np.linspace(0, 0.85, len(penalties)))))
        for ranks in sorted({row["ranks"] for row in mine}):
            for penalty in penalties:
                for tol in PLOTTED_TOLERANCES:
                    curve = sorted((row["elements"], row["wall_time"], row[key])
                                   for row in mine if row["ranks"] == ranks
                                   and row["penalty"] == penalty and row["rtol"] == tol)
                    if len(curve) < 1:
                        continue
                    curve = np.array(curve)
                    label = f"{int(ranks)}r R={penalty:.3g} rtol {tol:g}"
                    axis.loglog(curve[:, 1], curve[:, 2], styles[tol], ms=4, lw=1,
                                color=colours[penalty], alpha=1.0 if ranks == 1 else 0.5,
                                label=label)
        points = np.array([(row["wall_time"], row[key]) for row in mine])
        front = points[pareto_front(points)]
        axis.loglog(front[:, 0], front[:, 1], "k-", lw=2.5, alpha=0.6, label="Pareto front")
        axis.set_title(f"{name}: {key.replace('_', ' ')} against wall time")
        axis.set_xlabel("wall time (s)")
        axis.set_ylabel(key.replace("_", " "))
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize=5, ncol=2)
    figure.tight_layout()
    figure.savefig(path, dpi=130)
    plt.close(figure)


FITTED = ("position_error", "director_error", "u3_error", "energy_error")
TARGETS = (1e-2, 1e-4, 1e-6)


def fitted_orders(rows, scene, ranks=1.0):
    """Observed order of each field: least-squares slope of log(error) against log(N),
    where the error at N is the smallest any run on that mesh reached (the iteration
    stalls at a constraint-residual floor, earlier at some R than at others, so the
    best state of any R is the closest estimate of the discrete solution), from the
    coarsest mesh up to the mesh where that error is smallest (beyond it round-off in
    the r solve, not the discretisation, sets the error; scripts/linear_solve_roundoff.py).
    Returns {field: (order, first N, last N)}."""
    mine = [row for row in rows if row["scene"] == scene and row["ranks"] == ranks]
    sizes = np.array(sorted({row["elements"] for row in mine}))
    orders = {}
    for column in FITTED:
        best = np.array([min(row[column] for row in mine if row["elements"] == n)
                         for n in sizes])
        if len(sizes) < 2 or not np.all(best > 0):
            continue
        last = int(np.argmin(best)) + 1
        if last < 2:
            continue
        slope = -np.polyfit(np.log(sizes[:last]), np.log(best[:last]), 1)[0]
        orders[column] = (slope, int(sizes[0]), int(sizes[last - 1]))
    return orders


def fastest_reaching(rows, scene, target, column="position_error", ranks=1.0):
    """The run (row) with the least wall time whose error is at most ``target``."""
    good = [row for row in rows if row["scene"] == scene and row["ranks"] == ranks
            and row[column] <= target]
    return min(good, key=lambda row: row["wall_time"]) if good else None


def summary(rows):
    """Markdown tables of the sweep: discrete solutions, fitted orders, fastest runs."""
    lines = []
    for scene in FULL:
        key = PLOTTED_ERROR[scene]
        lines += [f"### {scene}", "",
                  "Tightest tolerance reached by each run (1 rank): the discretisation error.",
                  "", "| N | R | rtol reached | iterations | wall (s) | position | director "
                  "| u3(0) | energy |", "|---|---|---|---|---|---|---|---|---|"]
        for row in sorted((row for row in rows if row["scene"] == scene and row["ranks"] == 1
                           and row["tightest"] == 1),
                          key=lambda row: (row["elements"], row["penalty"])):
            lines.append(f"| {row['elements']:.0f} | {row['penalty']:.4g} | {row['rtol']:.0e} "
                         f"| {row['iterations']:.0f} | {row['wall_time']:.3g} "
                         f"| {row['position_error']:.2e} | {row['director_error']:.2e} "
                         f"| {row['u3_error']:.2e} | {row['energy_error']:.2e} |")
        lines += ["", "Observed orders (slope of log error against log N; at each N the "
                  "smallest error any run reached):", ""]
        for column, (order, lo, hi) in fitted_orders(rows, scene).items():
            lines.append(f"- {column.replace('_', ' ')}: {order:.2f} (N = {lo} to {hi})")
        lines += ["", f"Fastest run reaching a {key.replace('_', ' ')} (1 rank):", "",
                  "| target | N | R | rtol | iterations | wall (s) | error |",
                  "|---|---|---|---|---|---|---|"]
        for target in TARGETS:
            row = fastest_reaching(rows, scene, target, key)
            lines.append(f"| {target:.0e} | " + (
                f"{row['elements']:.0f} | {row['penalty']:.4g} | {row['rtol']:.0e} | "
                f"{row['iterations']:.0f} | {row['wall_time']:.3g} | {row[key]:.2e} |"
                if row else "not reached | | | | | |"))
        lines.append("")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a small setting (tests)")
    parser.add_argument("--out", default=str(HERE.parent / "docs" / "error_vs_time"))
    parser.add_argument("--worker", help=argparse.SUPPRESS)    # CSV path of an mpiexec part
    parser.add_argument("--summarise", metavar="CSV",
                        help="only redraw the plot and summary.md from an existing runs.csv")
    parser.add_argument("--parallel-only", action="store_true",
                        help="rerun only the 2-rank subset, replacing its rows in OUT/runs.csv")
    args = parser.parse_args()
    out = Path(args.out)
    if args.summarise:
        rows = read_csv(args.summarise)
        plot(rows, out / "error_vs_time.png")
        (out / "summary.md").write_text(summary(rows))
        return 0

    comm, say = start_petsc()
    if args.worker:
        rows = sweep(comm, parallel_plan(args.quick), say)
        if comm.getRank() == 0:
            write_csv(args.worker, rows)
        return 0
    out.mkdir(parents=True, exist_ok=True)
    if args.parallel_only:
        rows = [row for row in read_csv(out / "runs.csv") if row["ranks"] == 1]
    else:
        rows = sweep(comm, serial_plan(args.quick), say)
        write_csv(out / "runs-1-rank.csv", rows)      # kept if the 2-rank part fails
    part = out / "runs-2-ranks.partial.csv"
    command = ["mpiexec", "-n", "2", sys.executable, __file__, "--worker", str(part)]
    if args.quick:
        command.append("--quick")
    say("error_vs_time: the 2-rank runs: " + " ".join(command))
    subprocess.run(command, check=True, env=os.environ)
    rows += read_csv(part)
    part.unlink()
    (out / "runs-1-rank.csv").unlink(missing_ok=True)
    write_csv(out / "runs.csv", rows)
    rows = read_csv(out / "runs.csv")             # the same numbers as the file holds
    plot(rows, out / "error_vs_time.png")
    (out / "summary.md").write_text(summary(rows))
    say(f"error_vs_time: {len(rows)} rows in {out / 'runs.csv'}, plot {out / 'error_vs_time.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
