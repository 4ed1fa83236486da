"""A three-line spread held by HeldLine (petsc_rod/system/held_line.py): the time of
the lines' first solves, of the fairlead point's equilibrium under a horizontal load
by Newton's method on the lines' exact stiffness, and of the stiffness at the end.

    python scripts/benchmark_held_lines.py [elements]

Three 900 m lines of 800 N/m, EA 5e8 N, EI 1e4 N m^2, at 120 degrees, anchors on a
flat seabed 320 m down and 840 m out, fairleads 20 m out and 20 m below the surface on
one point (a body held in rotation and height, no hydrostatics): the point moves
until the lines' forces balance (200, 50, 0) kN, to 1e-7 of the load. A prototype of a
system's outer iteration (docs/method.md §13), not the system solver.
"""

import sys
import time

import numpy as np
from petsc4py import PETSc

from petsc_rod.api import End, Environment, Model, UniformLine
from petsc_rod.system.held_line import HeldLine


def main(elements=900):
    say = PETSc.Sys.Print
    clock = time.perf_counter()
    lines, ends = [], []
    for k in range(3):
        out = np.array([np.cos(2 * np.pi * k / 3), np.sin(2 * np.pi * k / 3), 0.0])
        anchor, fairlead = 840.0 * out - [0, 0, 320.0], 20.0 * out - [0, 0, 20.0]
        line = UniformLine(length=900.0, stiffness=(1e4, 1e4, 1e4), load=(0, 0, -800.0),
                           axial_stiffness=5e8, elements=elements)
        model = Model(line=line, start=End.anchor(tuple(anchor)),
                      end=End.anchor(tuple(fairlead)), environment=Environment(seabed=-320.0))
        lines.append(HeldLine(model, PETSc.COMM_WORLD))
        ends.append((anchor, fairlead))
        assert lines[-1].solve(anchor, fairlead)
    first = time.perf_counter()
    load, offset = np.array([2e5, 5e4, 0.0]), np.zeros(3)
    for outer in range(20):
        force = load + sum(line.end_forces()[1] for line in lines)
        say(f"outer {outer}: |net force| {np.linalg.norm(force[:2]):.3e} N, iterations "
            f"{[line.iterations for line in lines]}")
        if np.linalg.norm(force[:2]) < 1e-7 * np.linalg.norm(load):
            break
        stiffness = sum(line.stiffness()[3:, 3:] for line in lines)
        offset[:2] -= np.linalg.solve(stiffness[:2, :2], force[:2])
        for line, (anchor, fairlead) in zip(lines, ends):
            assert line.solve(anchor, fairlead + offset)
    balanced = time.perf_counter()
    restoring = -sum(line.stiffness()[3:, 3:] for line in lines)
    done = time.perf_counter()
    say(f"offset {np.round(offset, 4)} m; first solves {first - clock:.2f} s, equilibrium "
        f"{balanced - first:.2f} s, stiffness {done - balanced:.3f} s, in all "
        f"{done - clock:.2f} s\nrestoring stiffness of the point (N/m):\n"
        f"{np.array2string(restoring, precision=1)}")
    for line in lines:
        line.destroy()


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
