"""The issue's speed target for a system (docs/systems.md, "Speed"): OC3-Hywind's
three-line spread in 320 m of water (tests/data/moordyn/OC3Hywind_MoorDyn.dat, its
902.2 m chains in 1 m elements, 903 each) on the spar (validation/oc3_hywind.py): the
coupled equilibrium and the spar's 6 x 6 mooring stiffness, from nothing (the lines'
first solves included, the deck read and the imports not), by
system/equilibrium.SystemSolver with real lines (system/held_line.held_lines).

    python scripts/benchmark_system.py [repeats] [element_length] [predictor]

Three cases, run one after the other in turn ``repeats`` times (so that a change of the
machine's load falls on all of them), each timed from the solver's making to its 6 x 6:
``held`` the spar held where the deck puts it (the deck's coupled fairleads: the lines'
equilibrium, then the 6 x 6); ``free`` the spar free on its lines at rest; ``thrust``
the spar free under 800 kN of surge force at 90 m above its reference point. Prints
each case's wall and CPU times, their median and lowest (on one rank the CPU time is
near what an idle machine's wall time would be), the Newton iterations, the offset, the
stiffness's main entries, the lines found unstable, the load average before and after.
``predictor``: ``on`` (the default: the solver's catenary predictor, system/predictor.py),
``off``, or ``both``: each case solved with and without it in turn (the order swapped
every repeat), their medians and the largest differences of the pose and of K.
"""

import os
import sys
import time

# one BLAS thread, as python -m petsc_rod runs: one rank does not borrow another core
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from petsc_rod.model.moordyn import read_moordyn  # noqa: E402
from petsc_rod.system.equilibrium import Settings, SystemSolver  # noqa: E402
from petsc_rod.system.held_line import held_lines  # noqa: E402
from petsc_rod.validation.oc3_hywind import spar  # noqa: E402

DECK = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "tests",
                    "data", "moordyn", "OC3Hywind_MoorDyn.dat")
THRUST = 8e5            # N, at 90 m above the reference point


def cases(deck):
    return {"held": spar(deck, held=(True,) * 6),
            "free": spar(deck),
            "thrust": spar(deck, load=(THRUST, 0.0, 0.0, 0.0, 90.0 * THRUST, 0.0))}


def run(system, predictor=True):
    """(seconds, this process's CPU seconds, Equilibrium, 6 x 6) of one solve from
    nothing. Collective."""
    PETSc.COMM_WORLD.barrier()
    clock, cpu = time.perf_counter(), time.process_time()
    solver = SystemSolver(system, held_lines(system), PETSc.COMM_WORLD,
                          settings=Settings(predictor=predictor))
    try:
        result = solver.solve()
        K = solver.body_stiffness("spar").matrix
    finally:
        solver.destroy()
    return time.perf_counter() - clock, time.process_time() - cpu, result, K


def main(repeats=3, element_length=1.0, predictor="on"):
    say = PETSc.Sys.Print
    deck, _ = read_moordyn(DECK, element_length=element_length)
    systems = cases(deck)
    elements = sum(int(np.sum(line.line.sections[0][2])) for line in deck.lines)
    load = os.getloadavg()
    say(f"OC3-Hywind spread, {elements} elements in all, {PETSc.COMM_WORLD.size} rank(s), "
        f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")
    ways = {"on": (True,), "off": (False,), "both": (True, False)}[predictor]
    runs = [(name, way) for name in systems for way in ways]
    times = {key: [] for key in runs}
    cpus = {key: [] for key in runs}
    last = {}
    for repeat in range(repeats):
        for name, system in systems.items():
            for way in ways[::(-1) ** repeat]:
                seconds, cpu, result, K = run(system, way)
                times[name, way].append(seconds)
                cpus[name, way].append(cpu)
                last[name, way] = (result.bodies["spar"], K)
                say(f"  {name:6s} {'with' if way else 'without'} the predictor "
                    f"{seconds:6.2f} s (CPU {cpu:5.2f} s)  Newton {result.iterations:2d}  pose "
                    f"{np.array2string(result.bodies['spar'], precision=4)}  K11 {K[0, 0]:.0f} "
                    f"K33 {K[2, 2]:.0f} K44 {K[3, 3]:.4g} K66 {K[5, 5]:.4g} "
                    f"K15 {K[0, 4]:.4g}  unstable {list(result.unstable)}")
    load = os.getloadavg()
    for (name, way), values in times.items():
        say(f"{name:6s} {'with' if way else 'without'} the predictor: median "
            f"{np.median(values):.2f} s, lowest {min(values):.2f} s "
            f"({', '.join(f'{v:.2f}' for v in values)}); CPU median "
            f"{np.median(cpus[name, way]):.2f} s, lowest {min(cpus[name, way]):.2f} s "
            f"({', '.join(f'{v:.2f}' for v in cpus[name, way])})")
    if predictor == "both":
        for name in systems:
            (pose, K), (plain, K_plain) = last[name, True], last[name, False]
            say(f"{name:6s}: with against without: pose {np.abs(pose - plain).max():.2g}, "
                f"K {np.abs(K - K_plain).max() / np.abs(K_plain).max():.2g} of its largest")
    say(f"load average after: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")


if __name__ == "__main__":
    main(*(int(sys.argv[1]),) if len(sys.argv) > 1 else (),
         **({"element_length": float(sys.argv[2])} if len(sys.argv) > 2 else {}),
         **({"predictor": sys.argv[3]} if len(sys.argv) > 3 else {}))
