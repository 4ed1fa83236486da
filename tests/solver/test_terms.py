"""Terms of physics plug in (physics/term.py): a scene builds only the terms it needs, a
term the core does not know changes the answer as its physics says, and a term that
contributes nothing changes nothing."""

import numpy as np
import pytest

from helpers import gather
from petsc_rod.environment.current import Current
from petsc_rod.environment.seabed import Seabed
from petsc_rod.global_step.nodal_loads import NodalLoad
from petsc_rod.iteration.driver import UzawaSolver
from petsc_rod.iteration.stopping import Settings
from petsc_rod.mesh.mesh import Mesh
from petsc_rod.physics.dead_loads import DeadLoads
from petsc_rod.physics.drag import DragTerm
from petsc_rod.physics.nodal_load import NodalLoadTerm
from petsc_rod.physics.seabed import SeabedTerm
from petsc_rod.physics.term import Term
from petsc_rod.problem.build import scene_reports, scene_terms
from petsc_rod.problem.problem import RodProblem
from petsc_rod.quantities.line_results import LineResults
from petsc_rod.quantities.regions import LineRegions
from petsc_rod.quantities.riser_numbers import RiserNumbers
from petsc_rod.scenes.scene import Scene

FORCE = np.array([0.0, -2.0, 1.0])          # N/m
BARE = dict(length=1.0, stiffness=(1.0, 1.0, 1.0), start="clamp", end="free")
LOADED = dict(BARE, load_values=[FORCE])
PENALTY = 50.0
ELEMENTS = 24


class NodalUniformLoad(NodalLoadTerm):
    """A uniform load f (N/m) given by its values at the P2 nodes and added to the
    slope's right-hand side every iteration, as a follower load would be: the core knows
    it only through the protocol. Its P2 interpolant is f itself, so it is the dead load
    f (global_step/nodal_loads.py), reached by another way."""

    conservative = in_newton = False        # no energy given

    def __init__(self, mesh, force):
        super().__init__(mesh, "uniform")
        self.force = np.asarray(force, dtype=float)
        self.load = NodalLoad(mesh, self._nodes)

    def node_loads(self, state):
        return np.tile(self.t * self.force, (self.mesh.n_local_nodes, 1))

    def add_iterate_load(self, rhs, state):
        self.load.set(self.node_loads(state))
        self.add_to_rhs(rhs, self.load)


def solve(comm, scene_kwargs, extra_terms=()):
    """(report, r, n, end reaction, energy) of one step to load factor 1 with the
    scene's terms plus ``extra_terms(mesh)``, no Newton and no stability test (a term
    without an energy allows neither)."""
    scene = Scene(**scene_kwargs)
    mesh = Mesh(comm, ELEMENTS, scene.length)
    terms = scene_terms(mesh, scene) + [make(mesh) for make in extra_terms]
    problem = RodProblem(mesh, scene, PENALTY, terms)
    solver = UzawaSolver(problem, Settings(asked_penalty=PENALTY, rtol=1e-12, ctol=1e-12,
                                           max_it=5000, newton=False, check_stability=False))
    try:
        problem.state.set_straight()
        report = solver.solve_step(1.0)
        r = gather(comm, problem.state.r.owned()[:, 0])
        n = gather(comm, problem.internal_force())
        return report, r, n, problem.end_reaction(), problem.energy()
    finally:
        solver.destroy()
        problem.destroy()
        mesh.destroy()


def test_a_term_the_core_does_not_know_gives_the_dead_load_answer(comm):
    dead = solve(comm, LOADED)
    nodal = solve(comm, BARE, [lambda mesh: NodalUniformLoad(mesh, FORCE)])
    assert dead[0].converged and nodal[0].converged
    assert np.abs(dead[1]).max() > 0.05                     # the load does bend it
    assert np.abs(nodal[1] - dead[1]).max() < 1e-10
    assert np.abs(nodal[2] - dead[2]).max() < 1e-10 * np.abs(dead[2]).max()
    assert np.allclose(nodal[3], dead[3], rtol=0, atol=1e-12)     # a free end: no force
    # n(0) is the clamp's share: the whole load
    assert np.allclose(nodal[2][0], FORCE, rtol=1e-10)


def test_a_term_that_contributes_nothing_changes_nothing(comm):
    plain = solve(comm, LOADED)
    with_nothing = solve(comm, LOADED, [lambda mesh: Term()])
    assert plain[0].iterations == with_nothing[0].iterations
    for a, b in zip(plain[1:], with_nothing[1:]):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("sea, expected", [
    ({}, [DeadLoads, LineResults]),
    ({"seabed": Seabed(-0.5, 1e3)}, [DeadLoads, SeabedTerm, RiserNumbers, LineResults,
                                      LineRegions]),
    ({"current": Current(np.zeros(1), np.array([[0.0, 1.0, 0.0]]), 0.0, 1.0)},
     [DeadLoads, DragTerm, RiserNumbers, LineResults, LineRegions]),
])
def test_a_scene_builds_only_the_terms_it_needs(comm, sea, expected):
    scene = Scene(**dict(BARE, start="pin", end="pin", end_position=[0.8, 0.0, 0.0]), **sea)
    mesh = Mesh(comm, 4, scene.length)
    terms = scene_terms(mesh, scene)
    try:
        assert [type(term) for term in terms + scene_reports(scene, terms)] == expected
    finally:
        for term in terms:
            term.destroy()
        mesh.destroy()
