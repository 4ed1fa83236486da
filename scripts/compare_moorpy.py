"""petsc_rod against MoorPy (NREL's quasi-static mooring code, elastic catenaries) and
the published OC3-Hywind mooring stiffness, on the same MoorDyn file: the fairlead and
anchor tensions and the spar's 6 x 6 mooring stiffness about its reference point at
rest (docs/systems.md, "Comparison with MoorPy and published values").

    python scripts/compare_moorpy.py [deck] [element_length]

MoorPy is no dependency of petsc_rod: the script makes a virtual environment of its own
(~/.cache/petsc_rod/moorpy-venv, /usr/bin/python3 -m venv --system-site-packages),
pip-installs MoorPy there the first time, and runs MoorPy in it as a child process that
prints its numbers as JSON. The deck's coupled fairleads go on one body held at rest
(the spar: validation/oc3_hywind.py here; MoorPy's Body with the points attached
there); MoorPy's stiffness is its analytical one (Body.getStiffnessA, lines only), with
the water depth (320 m), density and gravity petsc_rod reads or takes. Prints a
markdown table.

    python scripts/compare_moorpy.py --modes [deck] [element_length]

the spar's natural periods on its moorings (docs/modes.md, "The coupled system's
modes"): the spar free, with the OC3 definition's mass properties and a strip-theory
added mass (validation/oc3_hywind.free_spar), petsc_rod's system modes
(system/body_modes.py) against the same eigenproblem with MoorPy's mooring stiffness
(the same mass and hydrostatics) and the published periods.
"""

import json
import os
import subprocess
import sys
import time

import numpy as np
from petsc4py import PETSc

from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.system.body_modes import rigid_mass, system_modes
from petsc_rod.system.equilibrium import SystemSolver, solve_system
from petsc_rod.system.held_line import held_lines
from petsc_rod.validation.oc3_hywind import (GRAVITY_DEPTH, PUBLISHED_FREQUENCIES, catenaries,
                                             free_spar, spar, spar_inertia)

HERE = os.path.dirname(os.path.abspath(__file__))
DECK = os.path.join(HERE, os.pardir, "tests", "data", "moordyn", "OC3Hywind_MoorDyn.dat")
VENV = os.path.join(os.path.expanduser("~"), ".cache", "petsc_rod", "moorpy-venv")
MOORPY = "MoorPy==1.3.0"

# Jonkman, Definition of the floating system for phase IV of OC3, NREL/TP-500-47566
# (2010), the linearised mooring stiffness at rest without the crow's foot's yaw spring,
# as quoted (docs/systems.md says where they were and were not checked).
PUBLISHED = {(0, 0): 41180.0, (1, 1): 41180.0, (2, 2): 11940.0, (3, 3): 311.1e6,
             (4, 4): 311.1e6, (5, 5): 11.56e6, (0, 4): -2.821e6, (1, 3): 2.821e6}

CHILD = r"""
import json, sys
import numpy as np
import moorpy as mp
deck, depth, rho, g = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
ms = mp.System(file=deck, depth=depth, rho=rho, g=g)
ms.addBody(-1, [0, 0, 0, 0, 0, 0])
for point in ms.pointList:
    if point.type == -1:                        # a coupled fairlead: on the body
        r = np.array(point.r, dtype=float)
        point.type = 1
        ms.bodyList[0].attachPoint(point.number, r)
ms.initialize()
ms.solveEquilibrium()
print(json.dumps({"fairlead": [float(l.TB) for l in ms.lineList],
                  "anchor": [float(l.TA) for l in ms.lineList],
                  "K": ms.bodyList[0].getStiffnessA(lines_only=True).tolist()}))
"""


def moorpy_python():
    """The venv's python, MoorPy installed in it (made the first time)."""
    python = os.path.join(VENV, "bin", "python")
    if not os.path.exists(python):
        subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", VENV],
                       check=True)
    if subprocess.run([python, "-c", "import moorpy"], capture_output=True).returncode:
        subprocess.run([python, "-m", "pip", "install", "-q", MOORPY], check=True)
    return python


def moorpy(deck, sea):
    out = subprocess.run([moorpy_python(), "-c", CHILD, deck, str(-sea.seabed),
                          str(sea.water_density), str(sea.gravity)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def periods(K, M):
    """Sorted natural periods (s) of K x = omega^2 M x and each mode's largest-share
    degree of freedom (M's diagonal)."""
    values, vectors = np.linalg.eig(np.linalg.solve(M, K))
    order = np.argsort(values.real)
    shares = vectors.real[:, order] ** 2 * np.diag(M)[:, None]
    return 2 * np.pi / np.sqrt(values.real[order]), np.argmax(shares, axis=0)


def compare_modes(deck=DECK, element_length=1.0):
    say = PETSc.Sys.Print
    system, _ = read_moordyn(deck, element_length=element_length)
    free = free_spar(system)
    clock = time.perf_counter()
    solver = SystemSolver(free, held_lines(free))
    try:
        solver.solve()
        modes = system_modes(solver)
        own = -solver.own_part(solver.state, solver.loads)[1]
    finally:
        solver.destroy()
    seconds = time.perf_counter() - clock
    theirs = moorpy(deck, system.environment)
    body = free.bodies[0]
    M = rigid_mass(body.mass, body.cog, np.reshape(body.inertia, (3, 3)),
                   np.reshape(body.added_mass, (6, 6)), np.eye(3))
    T_mp, dof_mp = periods(np.array(theirs["K"]) + own, M)
    names = ("surge", "sway", "heave", "roll", "pitch", "yaw")
    mass, z, inertia = spar_inertia()
    say(f"OC3-Hywind free on {deck} ({element_length:g} m elements, {seconds:.1f} s): "
        f"mass {body.mass:.6g} kg (the definition's {mass:.6g}), cog {-GRAVITY_DEPTH} m "
        f"(the parts' {z:.2f} m), I_pitch {inertia[0, 0]:.4g} kg m^2 about it, strip "
        f"theory's A11 {body.added_mass[0]:.4g} kg, A33 {body.added_mass[14]:.4g} kg, "
        f"A55 {body.added_mass[28]:.4g} kg m^2, A15 {body.added_mass[4]:.4g} kg m\n")
    say("| mode | petsc_rod T (s) | MoorPy's K, T (s) | published T (s) | petsc_rod / MoorPy - 1 |")
    say("|---|---|---|---|---|")
    dof = [names[["x", "y", "z", "roll", "pitch", "yaw"].index(label.split()[1])]
           for label in modes.labels]
    for k, (T, name) in enumerate(zip(modes.periods, dof)):
        j = [i for i in range(6) if names[dof_mp[i]] == name]
        other = T_mp[j[0]] if j else np.nan
        published = PUBLISHED_FREQUENCIES.get(name)
        shown = f"{1 / published:.1f}" if published else ""
        say(f"| {k + 1} {name} | {T:.2f} | {other:.2f} | {shown} | {T / other - 1:.1e} |")


def main(deck=DECK, element_length=1.0):
    say = PETSc.Sys.Print
    system, _ = read_moordyn(deck, element_length=element_length)
    clock = time.perf_counter()
    held = spar(system, held=(True,) * 6)
    result, stiffness = solve_system(held, held_lines(held))
    seconds = time.perf_counter() - clock
    K = stiffness["spar"].matrix
    tensions = np.linalg.norm(result.end_forces, axis=2)
    theirs = moorpy(deck, system.environment)
    K_mp = np.array(theirs["K"])
    closed = catenaries(system)
    say(f"OC3-Hywind, {deck}: petsc_rod with {element_length:g} m elements ({seconds:.1f} s, "
        f"1 rank), MoorPy {MOORPY.split('==')[1]} (analytical stiffness), the elastic "
        "catenary on a rigid frictionless seabed (validation/elastic_catenary.py)\n")
    say("| quantity | petsc_rod | MoorPy | catenary | published | petsc_rod / MoorPy - 1 |")
    say("|---|---|---|---|---|---|")
    for k, line in enumerate(system.lines):
        c = closed[k]
        for which, end, value in (("fairlead", 1, float(c.at(c.length)[2])),
                                  ("anchor", 0, c.H)):
            ours, other = tensions[k, end], theirs[which][k]
            say(f"| {line.name} {which} tension (N) | {ours:.1f} | {other:.1f} | "
                f"{value:.1f} | | {ours / other - 1:.2e} |")
    names = {(0, 0): "K11", (1, 1): "K22", (2, 2): "K33", (3, 3): "K44", (4, 4): "K55",
             (5, 5): "K66", (0, 4): "K15", (1, 3): "K24"}
    for (i, j), name in names.items():
        say(f"| {name} | {K[i, j]:.6g} | {K_mp[i, j]:.6g} | | {PUBLISHED[i, j]:.4g} | "
            f"{K[i, j] / K_mp[i, j] - 1:.2e} |")
    say(f"\nlargest |K - K_MoorPy| / max |K_MoorPy| {np.abs(K - K_mp).max() / np.abs(K_mp).max():.2e}"
        f"; asymmetry |K - K^T| / |K| {stiffness['spar'].asymmetry:.1e}")


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a != "--modes"]
    run = compare_modes if "--modes" in sys.argv[1:] else main
    run(*arguments[:1], **({"element_length": float(arguments[1])} if len(arguments) > 1
                           else {}))
