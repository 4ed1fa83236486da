"""How the seabed enters the iteration, measured (docs/riser.md, "The seabed in the global
step"): the implicit treatment of petsc_rod (the vertical slope in Hermite dofs with an
active-set loop in every global step, global_step/seabed_contact.py) against the obvious start, the
spring lagged by one iteration (its force from the last global step's heights, a nodal
load on the slope's right-hand side, as the drag is).

    python scripts/seabed_schemes.py [--quick]

Two scenes, each at several stiffnesses (factors of the default w / 1 mm), both SNES
types; prints one row per run (outcome, iterations, seconds, the amplification
k l^2 / R of the lagged spring with l the grounded length) as a Markdown table.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import petsc4py  # noqa: E402

petsc4py.init(sys.argv[:1])
from petsc4py import PETSc  # noqa: E402

from petsc_rod.environment.seabed import Seabed, default_stiffness  # noqa: E402
from petsc_rod.errors import RodDivergedError  # noqa: E402
from petsc_rod.global_step.nodal_loads import NodalLoad  # noqa: E402
from petsc_rod.iteration.driver import UzawaSolver  # noqa: E402
from petsc_rod.iteration.stopping import Settings  # noqa: E402
from petsc_rod.mesh.mesh import Mesh  # noqa: E402
from petsc_rod.physics.dead_loads import DeadLoads  # noqa: E402
from petsc_rod.physics.nodal_load import NodalLoadTerm  # noqa: E402
from petsc_rod.problem.penalty import default_penalty  # noqa: E402
from petsc_rod.problem.problem import RodProblem  # noqa: E402
from petsc_rod.scenes.scene import Scene  # noqa: E402
from petsc_rod.scenes.starts import catenary_start  # noqa: E402

SCENES = {
    # the grounded line of tests/solver/test_riser.py (5.5 m on the seabed)
    "grounded line, 80 el.": (dict(length=10.0, stiffness=(1e-3,) * 3, start="pin", end="pin",
                                   end_position=(7.0, 0.0, 4.0),
                                   load_values=[[0.0, 0.0, -1.0]]), 80, 5.5),
    # options/riser_catenary.opts without its current, coarser (546 m on the seabed)
    "SCR, 600 el.": (dict(length=1800.0, stiffness=(5.6e7, 5.6e7, 4.3e7), start="pin",
                          end="pin", end_position=(1157.0, 0.0, 1000.0),
                          load_values=[[0.0, 0.0, -1200.0]]), 600, 546.0),
}


class LaggedSeabed(NodalLoadTerm):
    """The seabed as a load lagged by one iteration: k (z_b - z)_+ at the nodes from the
    heights of the last global step, added to the slope's right-hand side like the drag
    (a term of physics, physics/term.py, in place of physics.seabed.SeabedTerm); no vertical
    problem, no energy."""

    conservative = in_newton = False

    def __init__(self, mesh, seabed):
        super().__init__(mesh, "lagged_seabed")
        self.seabed = seabed
        self.contact_load = NodalLoad(mesh, self._nodes)

    def pressure(self, z):
        return self.seabed.stiffness * np.maximum(self.seabed.height - z, 0.0)

    def node_loads(self, state):
        loads = np.zeros((self.mesh.n_local_nodes, 3))
        loads[:, 2] = self.pressure(state.node_positions()[:, 2])
        return loads

    def add_iterate_load(self, rhs, state):
        self.contact_load.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.contact_load)


def run(scene_kwargs, elements, factor, scheme, snes_type, max_it):
    """(outcome, iterations, seconds) of one step from the catenary with touchdown."""
    load = np.asarray(scene_kwargs["load_values"], dtype=float)
    scene = Scene(**scene_kwargs, seabed=Seabed(0.0, factor * default_stiffness(load)))
    database = PETSc.Options()
    database.setValue("rod_snes_type", snes_type)
    mesh = Mesh(PETSc.COMM_WORLD, elements, scene.length)
    penalty = default_penalty(scene)
    terms = None            # the scene's own: the implicit seabed
    if scheme == "lagged":
        terms = [DeadLoads(mesh, scene), LaggedSeabed(mesh, scene.seabed)]
    try:
        problem = RodProblem(mesh, scene, penalty, terms)
        solver = UzawaSolver(problem, Settings(asked_penalty=penalty, max_it=max_it,
                                               rtol=1e-9, ctol=1e-9, check_stability=False))
    finally:
        database.delValue("rod_snes_type")
    solver.problem.state.set_from_curve(catenary_start(scene, 1.0))
    clock = time.perf_counter()
    try:
        report = solver.solve_step(1.0)
        outcome = "converged" if report.converged else report.reason
        iterations = report.iterations
    except RodDivergedError as error:
        outcome, iterations = "diverged", error.iterations
    seconds = time.perf_counter() - clock
    solver.destroy()
    solver.problem.destroy()
    mesh.destroy()
    return outcome, iterations, seconds, penalty, scene.seabed.stiffness


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the grounded line only")
    args = parser.parse_args()
    factors = (1e-4, 1e-2, 1.0, 1e3)
    rows = ["| scene | k / default | k l^2 / R | scheme | SNES | outcome | iterations | s |",
            "|---|---|---|---|---|---|---|---|"]
    for name, (kwargs, elements, grounded) in SCENES.items():
        if args.quick and not name.startswith("grounded"):
            continue
        for factor in factors:
            for scheme in ("implicit", "lagged"):
                for snes_type in ("anderson", "nrichardson"):
                    outcome, its, seconds, penalty, k = run(kwargs, elements, factor, scheme,
                                                            snes_type, max_it=3000)
                    rows.append(f"| {name} | {factor:g} | {k * grounded**2 / penalty:.2g} | "
                                f"{scheme} | {snes_type} | {outcome} | {its} | "
                                f"{seconds:.2f} |")
                    PETSc.Sys.Print(rows[-1])
    PETSc.Sys.Print("\n".join(rows))


if __name__ == "__main__":
    main()
