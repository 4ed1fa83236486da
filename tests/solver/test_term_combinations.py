"""Each combination of the riser's terms converges, with Newton steps taking over, and
gives the same answer on one rank and on all ranks.

A 100 m line of 100 N/m between pins 70 m apart and 40 m up, on a seabed of 1e5 N/m^2
(about 30 m grounded), from its catenary: the seabed alone, with Coulomb friction
(mu 0.5, stick stiffness 1e5 N/m^2), with a current of 1 m/s across the ends' plane
(a drag of 31 N/m), with axial stretch (EA 1e6 N), with an attachment (500 N up at
S = 60 m), with a flex joint at the hang-off (1e4 N m/rad about the vertical). Each is solved on PETSc.COMM_SELF (every rank its own serial solve) and
on PETSc.COMM_WORLD (under ``mpiexec -n 2`` the mesh split over two ranks, where the
Newton steps' factorisations are substructured: global_step/chain_factor.py); the
centreline, the tangents and the end force (the chord multiplier) agree to 1e-8 of
their size (measured: 1e-16 to 3e-13 of the length, 1e-11 of the force).

Newton takes over (the current's combinations without friction in 55 iterations or
fewer, measured): the line's sections are round (K1 = K2) between pins, so turning every
section about its tangent by one angle is a null vector of the Newton system, and at an
iterate a near-null one; the steps hold that roll by a constraint of the step
(iteration/newton.py), where removing the mean roll from a step of the nearly singular
system left steps that did not shrink (263 iterations with 13 Newton steps for the
seabed and the current, 237 with the attachment).
"""

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import gather
from petsc_rod.environment.current import Current
from petsc_rod.environment.seabed import Friction, Seabed
from petsc_rod.scenes.scene import Scene
from petsc_rod.scenes.starts import catenary_start

WEIGHT = 100.0
LINE = dict(length=100.0, stiffness=(1e3, 1e3, 1e3), start="pin", end="pin",
            end_position=(70.0, 0.0, 40.0), load_values=[[0.0, 0.0, -WEIGHT]])
SEABED = Seabed(0.0, 1e5, None, None)
FRICTION = Seabed(0.0, 1e5, None, Friction(0.5, 0.5, 1e5))
CURRENT = Current.uniform((0.0, 1.0, 0.0), 1025.0, 1.2, 0.05)
STRETCH = dict(axial_stiffness=1e6)
ATTACHMENT = dict(point_load_S=[60.0], point_load_forces=[[0.0, 0.0, 500.0]])
FLEX_JOINT = dict(end_rotational_stiffness=1e4, end_joint_axis=(0.0, 0.0, 1.0))
# (the scene's terms, the most iterations on one rank: measured counts times about 2,
# or None where the iteration's own slow convergence sets the count)
COMBINATIONS = {
    "seabed": (dict(seabed=SEABED), 100),
    "seabed, current": (dict(seabed=SEABED, current=CURRENT), 110),
    "seabed, current, stretch": (dict(seabed=SEABED, current=CURRENT, **STRETCH), 110),
    "seabed, current, attachment": (dict(seabed=SEABED, current=CURRENT, **ATTACHMENT),
                                    110),
    "seabed, current, flex joint": (dict(seabed=SEABED, current=CURRENT, **FLEX_JOINT),
                                    110),
    "seabed, friction": (dict(seabed=FRICTION), None),
    "seabed, friction, current": (dict(seabed=FRICTION, current=CURRENT), None),
}
PENALTY = 1e4
N_ELEMENTS = 40
MAX_IT = 5000
AGREEMENT = 1e-8


def solve(solver_factory, comm, terms):
    """The combination's scene solved on ``comm`` from its catenary: (report, the
    centreline's positions (n_vertices, 3), the tangents d3 at the nodes (n_nodes, 3),
    the end force (3,)), gathered on every rank."""
    scene = dict(LINE, **terms)
    mesh, solver = solver_factory(comm, N_ELEMENTS, scene, PENALTY, rtol=1e-10, ctol=1e-10,
                                  max_it=MAX_IT)
    shape = {key: value for key, value in scene.items()
             if key in ("length", "stiffness", "start", "end", "end_position", "load_values")}
    state = solver.problem.state
    state.set_from_curve(catenary_start(Scene(**shape), 1.0))
    report = solver.solve_step(1.0)
    return (report, gather(comm, state.r.owned())[:, 0], gather(comm, state.tau)[:, 2],
            np.array(state.chord_multiplier))


@pytest.mark.parametrize("name", list(COMBINATIONS))
def test_one_rank_and_all_ranks_agree(solver_factory, name):
    terms, most = COMBINATIONS[name]
    one, positions_one, tangents_one, force_one = solve(solver_factory, PETSc.COMM_SELF,
                                                        terms)
    many, positions_many, tangents_many, force_many = solve(solver_factory,
                                                            PETSc.COMM_WORLD, terms)
    assert one.converged and many.converged
    # the scene is the riser's: part of the line grounded, a lateral swing in a current
    assert np.sum(positions_one[:, 2] < 0.0) >= 5
    if "current" in terms:
        assert np.abs(positions_one[:, 1]).max() > 0.5
    if most is not None:
        assert one.iterations <= most
    assert np.abs(positions_one - positions_many).max() <= AGREEMENT * LINE["length"]
    assert np.abs(tangents_one - tangents_many).max() <= AGREEMENT
    assert np.abs(force_one - force_many).max() <= AGREEMENT * np.abs(force_one).max()
