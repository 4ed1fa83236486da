"""The coupled equilibrium with real lines (system/held_line.py) end to end on
OC3-Hywind's MoorDyn deck (tests/data/moordyn/OC3Hywind_MoorDyn.dat, read_moordyn):
its three 902.2 m chains with the fairleads held where the deck puts them, and the spar
free on them (validation/oc3_hywind.py), against the elastic catenary on a rigid
frictionless seabed (validation/elastic_catenary.py). Serially and on 2 ranks."""

import os

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import REPO_ROOT
from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.system.equilibrium import SystemSolver, solve_system
from petsc_rod.system.held_line import held_lines
from petsc_rod.validation.oc3_hywind import catenaries, spar
from test_system_equilibrium import CatenaryLine, SpringLine, equilibrium, link, spread, spring

pytestmark = pytest.mark.solver

DECK = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "OC3Hywind_MoorDyn.dat")


def test_the_oc3_deck_with_its_fairleads_held_has_the_catenarys_tensions():
    """1 m elements: the fairlead tensions are the elastic catenary's to 3e-5 (the
    seabed's compliance, kBot x d, as for the single line: tests/solver/
    test_moordyn_line.py; measured 1.3e-5), the anchors' likewise (1.7e-5); every
    line stable."""
    deck, _ = read_moordyn(DECK)
    result, _ = solve_system(deck, held_lines(deck))
    tensions = np.linalg.norm(result.end_forces, axis=2)
    for k, catenary in enumerate(catenaries(deck)):
        top = catenary.at(catenary.length)[2]
        assert tensions[k, 1] == pytest.approx(top, rel=3e-5), k
        assert tensions[k, 0] == pytest.approx(catenary.H, rel=3e-5), k
    assert result.unstable == ()


def test_the_free_oc3_spar_floats_at_rest_and_has_the_catenarys_stiffness():
    """The spar free on its three lines (2 m elements) stays at rest (its mass balances
    the lines' pull), in few Newton iterations (the lines' end forces are converged to
    their own tolerance, below which Newton stops), and its 6 x 6 mooring stiffness is
    the elastic catenary's (the same spread held, central differences of the closed
    form): to 1 % on the diagonal (measured 0.08-0.2 %) and the surge-pitch coupling, the touchdown
    element's contact with the elastic seabed (a node in or out of contact is one
    element's share of the grounded length) and the seabed's compliance."""
    deck, _ = read_moordyn(DECK, element_length=2.0)
    system = spar(deck)
    solver = SystemSolver(system, held_lines(system))
    try:
        result = solver.solve()
        K = solver.body_stiffness("spar")
    finally:
        solver.destroy()
    assert np.abs(result.bodies["spar"][:3]).max() < 0.01            # m
    assert np.abs(result.bodies["spar"][3:]).max() < 1e-6            # rad
    assert result.iterations <= 3
    _, exact = solve_system(spar(deck, held=(True,) * 6), lambda line, comm: CatenaryLine(
        line.line.sections[0][1], 698.094, 384.243e6, seabed=-320.0))
    expected = exact["spar"].matrix
    for i, j in [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5), (0, 4), (1, 3)]:
        assert K.matrix[i, j] == pytest.approx(expected[i, j], rel=1e-2), (i, j)


class SaddleLine(SpringLine):
    """A spring that says its equilibrium is a saddle."""

    def stable(self):
        return False


def test_a_line_whose_equilibrium_is_a_saddle_is_reported():
    from petsc_rod.model.system import Point, System
    system = System(lines=(link("left", "a", "p", 3e4, 4.0), link("right", "p", "b", 5e4, 3.0)),
                    points=(Point("a", "fixed", (0, 0, 0)), Point("b", "fixed", (10, 0, 0)),
                            Point("p", "free", (6.0, 0.0, 0.0))))
    result, _ = solve_system(system, lambda line, comm: (
        SaddleLine if line.name == "right" else SpringLine)(line.line.stiffness[0],
                                                             line.line.length, comm))
    assert result.unstable == ("right",)
    result, _ = solve_system(system, spring)
    assert result.unstable == ()


class CreepingLine(SpringLine):
    """A spring whose end forces carry an error of 1e-7 of themselves that shrinks by
    5 % at each solve, as a real line's do when it is re-solved after a tiny move
    (one step of its own iteration, which converges linearly)."""

    def __init__(self, *args):
        super().__init__(*args)
        self.solves = 0

    def solve(self, start, end):
        self.solves += 1
        return super().solve(start, end)

    def end_forces(self):
        return super().end_forces() * (1.0 + 1e-7 * 0.95**self.solves)


def test_newton_stops_where_the_lines_forces_creep_below_the_floor():
    """Two Newton steps in a row that do not halve a residual below the floor end
    Newton (without that rule the creeping error takes some 80 steps to fall below rtol)."""
    system = spread(load=(1e6, 0, 0, 0, 0, 0))
    result, _ = solve_system(system, lambda line, comm: CreepingLine(
        line.line.stiffness[0], line.line.length, comm), PETSc.COMM_SELF)
    _, exact, _ = equilibrium(system)
    assert result.iterations <= 12 and result.halvings == 0         # measured 9
    assert result.residual < 1e-7
    assert result.bodies["floater"] == pytest.approx(exact.bodies["floater"], abs=1e-6)


def test_the_free_oc3_spar_under_thrust_goes_where_the_catenarys_spar_goes():
    """800 kN of surge force 90 m up (2 m elements): the spar goes where it goes on
    elastic catenaries (28.2 m downwind, 0.1 rad of pitch) to 1 mm and 1e-6 rad
    (measured 0.15 mm and 3e-8 rad: the seabed's compliance and the touchdown's
    discretisation), and its lines' horizontal pull balances the force to the
    residual's floor."""
    thrust = 8e5
    deck, _ = read_moordyn(DECK, element_length=2.0)
    system = spar(deck, load=(thrust, 0.0, 0.0, 0.0, 90.0 * thrust, 0.0))
    result, _ = solve_system(system, held_lines(system), stiffness=False)
    closed, _ = solve_system(system, lambda line, comm: CatenaryLine(
        line.line.sections[0][1], 698.094, 384.243e6, seabed=-320.0), stiffness=False)
    pose, expected = result.bodies["spar"], closed.bodies["spar"]
    assert expected[0] > 25.0 and expected[4] > 0.05
    assert pose[:3] == pytest.approx(expected[:3], abs=1e-3)
    assert pose[3:] == pytest.approx(expected[3:], abs=1e-6)
    pull = result.end_forces[:, 1, :2].sum(axis=0)
    assert pull == pytest.approx([-thrust, 0.0], abs=1e-7 * np.abs(result.end_forces).max())
