"""The paper's three figures, from petsc_rod solutions (docs/method.md §8; docs/paper.md).

    python scripts/paper_figures.py [--quick] [--out docs/paper]

Runs the paper's continuation, the pinned end moved along y = 20 - x from X_F = 20 down
to X_F = 2 in 0.5 m steps (36 steps), for both readings of the torsion stiffness:
- K3 = 200 on 80 elements, R = 400, rolled by 0.01 rad at each step (options/paper.opts);
- the same without the roll, the plain iteration and no stability test: the planar
  branch (u3 = 0; it does not depend on K3), which the plain iteration follows from a
  symmetric start while the default iteration leaves it (it is a saddle);
- K3 = 100 (non-convex split, docs/method.md §2) on 80 elements.
and writes into OUT: steps.csv (one row per run and step: X_F, converged, iterations,
wall time, u3(0), energy, max |z|, constraint residual, Newton steps among the
iterations), profiles.npz (r and u3 along
the cable at X_F = 19, 16 and 2) and three PNGs:
- projections.png: the cable on the planes xy, xz, yz at X_F = 19 and 16;
- twist_at_clamp.png: u3(0) against X_F, with the range where the rolled run leaves the
  plane (the planar state is then not the stable one) shaded;
- twist_along_cable.png: u3(S) at X_F = 16 and 2.
`--replot` redraws the PNGs from those two files.

The runs use the command line's continuation loop: a step that does not converge is
retried with half the increment (the sub-steps are rows of steps.csv too), and a run
that still fails ends there. Progress: one line per step. The whole run
takes about 10 s of CPU on one core (docs/paper.md); `--quick` (X_F = 20 to 19 in 2 steps, coarse
meshes) takes seconds and is what the tests run.
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from script_support import start_petsc  # noqa: E402  (scripts/ is sys.path[0])

LENGTH = 20.0
RTOL, CTOL, PENALTY = 1e-7, 1e-5, 400.0
MAX_ITERATIONS = 200000
PROFILE_X = (19.0, 16.0, 2.0)
# |z| above this (0.05% of L) on a rolled run means the cable has left the plane z = 0.
# On the planar side of the pitchfork the Newton steps take the roll of 0.01 rad put in
# at each step out to round-off (|z| below 1e-16 m, docs/paper.md); the last out-of-plane
# steps are far above it (|z| = 0.29 m at X_F = 5.5, K3 = 200; 0.028 m at 3.5, K3 = 100).
OUT_OF_PLANE = 1e-2

FULL = {"end_x": 2.0, "steps": 36,
        "runs": (("K3 = 200", 200.0, 80, 0.01), ("planar", 200.0, 80, 0.0),
                 ("K3 = 100", 100.0, 80, 0.01))}
QUICK = {"end_x": 19.0, "steps": 2,
         "runs": (("K3 = 200", 200.0, 20, 0.01), ("planar", 200.0, 20, 0.0),
                  ("K3 = 100", 100.0, 10, 0.01))}
STEP_COLUMNS = ("run", "K3", "elements", "penalty", "X_F", "converged", "iterations",
                "wall_time", "u3_clamp", "energy", "max_abs_z", "constraint_residual",
                "newton_steps")


def gather(comm, owned):
    parts = comm.tompi4py().allgather(np.asarray(owned))
    return np.concatenate(parts, axis=0)


def continuation_run(comm, label, k3, n_elements, imperfection, end_x, steps, say):
    """One continuation from X_F = 20 to ``end_x`` by the CLI's loop (a step that fails is
    halved, as on the command line), each step recorded from its event: (step rows,
    profiles by X_F)."""
    from petsc_rod.iteration import events
    from petsc_rod.iteration.continuation import PathSettings, continuation
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings
    from petsc_rod.io.outputs import vertex_fields
    from petsc_rod.mesh.mesh import Mesh
    from petsc_rod.scenes.scene import Scene

    from petsc4py import PETSc

    scene = Scene(length=LENGTH, stiffness=[235.0, 360.0, k3], start="clamp", end="pin",
                  end_position=[end_x, LENGTH - end_x, 0.0])
    mesh = Mesh(comm, n_elements, LENGTH)
    planar = label == "planar"
    database = PETSc.Options()
    if planar:          # the plain iteration, which keeps a symmetric state symmetric
        database.setValue("rod_snes_type", "nrichardson")
    try:
        solver = solver_for(mesh, scene, Settings(
            asked_penalty=PENALTY, max_it=MAX_ITERATIONS, rtol=RTOL, ctol=CTOL,
            check_stability=not planar))
    finally:
        if planar:
            database.delValue("rod_snes_type")
    rows, profiles = [], {}
    clock = time.perf_counter()

    def record(t, report):
        fields = {key: gather(comm, value) for key, value in vertex_fields(solver.problem).items()}
        x_f = LENGTH + t * (end_x - LENGTH)
        rows.append(dict(run=label, K3=k3, elements=n_elements,
                         penalty=solver.penalty, X_F=round(x_f, 6),
                         converged=int(report.converged), iterations=report.iterations,
                         wall_time=time.perf_counter() - clock,
                         u3_clamp=fields["u"][0, 2], energy=solver.problem.energy(),
                         max_abs_z=np.abs(fields["r"][:, 2]).max(),
                         constraint_residual=report.constraint_residual,
                         newton_steps=report.newton_steps))
        outcome = "converged" if report.converged else "NOT converged"
        say(f"{label:9s} X_F = {x_f:5.2f}: {outcome}"
            f" in {report.iterations:6d} its ({report.newton_steps} Newton), u3(0) = {fields['u'][0, 2]:+.5f} /m, "
            f"W = {rows[-1]['energy']:.4f} J, max|z| = {rows[-1]['max_abs_z']:.3g} m "
            f"({rows[-1]['wall_time']:.1f} s)")
        for x in PROFILE_X:
            if report.converged and abs(x_f - x) < 1e-9:
                profiles[x] = {"S": fields["S"], "r": fields["r"], "u3": fields["u"][:, 2]}

    try:
        solver.problem.state.set_straight()
        for event in continuation(solver, PathSettings(steps, imperfection)):
            if isinstance(event, events.StepEnded):
                record(event.t, event.report)
            elif isinstance(event, events.RunDiverged) or (
                    isinstance(event, events.RunFinished) and not event.converged):
                say(f"{label}: stopped, a step did not converge")
    finally:
        solver.destroy()
        solver.problem.destroy()
        mesh.destroy()
    return rows, profiles


def out_of_plane_range(rows):
    """(smallest, largest) X_F at which a rolled run is out of plane, or None."""
    x = [row["X_F"] for row in rows if row["max_abs_z"] > OUT_OF_PLANE and row["converged"]]
    return (min(x), max(x)) if x else None


def plot(rows, profiles, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"K3 = 200": "tab:blue", "K3 = 100": "tab:red", "planar": "0.4"}
    labels = [label for label in colours if any(row["run"] == label for row in rows)]

    figure, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    planes = (("x", "y", 0, 1), ("x", "z", 0, 2), ("y", "z", 1, 2))
    for axis, (a, b, i, j) in zip(axes, planes):
        for label in labels:
            for x, style in ((19.0, "--"), (16.0, "-")):
                if x in profiles.get(label, {}):
                    r = profiles[label][x]["r"]
                    axis.plot(r[:, i], r[:, j], style, color=colours[label],
                              label=f"{label}, X_F = {x:g}")
        axis.set_xlabel(f"{a} (m)")
        axis.set_ylabel(f"{b} (m)")
        axis.set_title(f"projection on the {a}{b} plane")
        axis.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(out / "projections.png", dpi=130)
    plt.close(figure)

    figure, axis = plt.subplots(figsize=(7, 4.5))
    for label in labels:
        mine = [row for row in rows if row["run"] == label and row["converged"]]
        axis.plot([row["X_F"] for row in mine], [row["u3_clamp"] for row in mine], "o-",
                  ms=3, color=colours[label], label=label)
        span = out_of_plane_range(mine) if label != "planar" else None
        if span:
            axis.axvspan(span[0], span[1], color=colours[label], alpha=0.08,
                         label=f"{label}: out of plane (planar not stable), "
                               f"X_F {span[0]:g} to {span[1]:g}")
    axis.invert_xaxis()
    axis.set_xlabel("X_F (m), the end moved from 20 towards 2")
    axis.set_ylabel("u3 at the clamp (rad/m)")
    axis.set_title("twist at the clamp along the paper's path")
    axis.grid(alpha=0.3)
    axis.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(out / "twist_at_clamp.png", dpi=130)
    plt.close(figure)

    figure, axis = plt.subplots(figsize=(7, 4.5))
    for label in labels:
        for x, style in ((16.0, "-"), (2.0, "--")):
            if x in profiles.get(label, {}):
                p = profiles[label][x]
                axis.plot(p["S"], p["u3"], style, color=colours[label],
                          label=f"{label}, X_F = {x:g}")
    axis.set_xlabel("S (m)")
    axis.set_ylabel("u3 (rad/m)")
    axis.set_title("twist along the cable")
    axis.grid(alpha=0.3)
    if axis.get_legend_handles_labels()[0]:
        axis.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(out / "twist_along_cable.png", dpi=130)
    plt.close(figure)


def read_results(out):
    """steps.csv and profiles.npz back into (rows, profiles) as main() built them."""
    with open(out / "steps.csv") as stream:
        rows = [{key: (value if key == "run" else float(value)) for key, value in row.items()}
                for row in csv.DictReader(stream)]
    profiles = {}
    with np.load(out / "profiles.npz") as data:
        for name in data.files:
            label, x, key = name.split("|")
            profiles.setdefault(label, {}).setdefault(float(x), {})[key] = data[name]
    return rows, profiles


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a small setting (tests)")
    parser.add_argument("--out", default=str(HERE.parent / "docs" / "paper"))
    parser.add_argument("--replot", action="store_true",
                        help="only redraw the PNGs from OUT/steps.csv and OUT/profiles.npz")
    args = parser.parse_args()
    if args.replot:
        out = Path(args.out)
        rows, profiles = read_results(out)
        plot(rows, profiles, out)
        return 0

    comm, say = start_petsc()
    plan = QUICK if args.quick else FULL
    rows, profiles = [], {}
    for label, k3, n_elements, imperfection in plan["runs"]:
        run_rows, run_profiles = continuation_run(comm, label, k3, n_elements, imperfection,
                                                  plan["end_x"], plan["steps"], say)
        rows += run_rows
        profiles[label] = run_profiles
    if comm.getRank() == 0:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        with open(out / "steps.csv", "w", newline="") as stream:
            writer = csv.DictWriter(stream, fieldnames=STEP_COLUMNS)
            writer.writeheader()
            writer.writerows(rows)
        np.savez(out / "profiles.npz", **{
            f"{label}|{x:g}|{key}": value for label, by_x in profiles.items()
            for x, fields in by_x.items() for key, value in fields.items()})
        plot(rows, profiles, out)
        for label in profiles:
            span = out_of_plane_range([row for row in rows if row["run"] == label])
            if label != "planar":
                say(f"{label}: out of plane for X_F in {span}" if span
                    else f"{label}: planar all along")
        say(f"paper_figures: {len(rows)} steps in {out / 'steps.csv'}; PNGs in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
