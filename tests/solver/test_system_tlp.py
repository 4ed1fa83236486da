"""A tension-leg platform (options/tlp.dat, docs/systems.md "A tension-leg platform"): a
free hull whose buoyancy B exceeds its weight W, held down by four vertical tendons
shorter than the distance from their anchors to its fairleads (check_reach: a taut line
to a free body starts straight along its chord), against the closed forms of a taut
string: heave where the tendons' top tensions add up to B - W, each tension linear in
height, the surge stiffness the tendons' pendulum stiffness, heave 4 EA / L; the 6 x 6
against central differences of the equilibrium re-solved under small loads. Serially
and under mpiexec -n 2 (the tendons split over the ranks)."""

import dataclasses
import os

import numpy as np
import pytest
from petsc4py import PETSc

from helpers import REPO_ROOT
from petsc_rod.api import read_moordyn, solve_system
from petsc_rod.cli_system import offsets
from petsc_rod.errors import RodInputError
from petsc_rod.system.bodies import log_rotation
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import held_lines

pytestmark = pytest.mark.solver

DECK = os.path.join(REPO_ROOT, "options", "tlp.dat")
TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
RHO, G = 1025.0, 9.80665
# the deck's numbers: hull, tendon type, geometry
MASS, VOLUME = 6.0e6, 8000.0
EA, MASS_PER_M, DIAMETER, LENGTH = 1.2e10, 450.0, 0.7, 94.96
ANCHOR_Z, FAIRLEAD_Z = -120.0, -25.0
NET = (RHO * VOLUME - MASS) * G                             # B - W, N
WET = (MASS_PER_M - RHO * np.pi * DIAMETER ** 2 / 4) * G    # N/m


def closed_form():
    """Each tendon's top and bottom tensions (N), the hull's heave (m) and the pendulum
    surge stiffness of the four (N/m) of an extensible string under its wet weight w:
    top T_1 = (B - W) / 4, bottom T_0 = T_1 - w L; stretched to the chord
    c = L + L (T_1 - w L / 2) / EA (the mean tension's stretch); a sideways force H on
    the top moves it by H (int dS / T + L / EA), int dS / T = ln(T_1 / T_0) / w."""
    top = NET / 4
    bottom = top - WET * LENGTH
    chord = LENGTH + LENGTH * (top - WET * LENGTH / 2) / EA
    surge = 4.0 / (np.log(top / bottom) / WET + LENGTH / EA)
    return top, bottom, ANCHOR_Z + chord - FAIRLEAD_Z, surge


def test_the_tlp_settles_where_its_tendons_hold_its_net_buoyancy():
    system, _ = read_moordyn(DECK)
    found = solve_system(system, options=TIGHT)
    top, bottom, heave, surge = closed_form()
    body = found.bodies["Body1"]
    assert body.position[2] == pytest.approx(heave, abs=1e-10)
    assert body.position[2] > 1e-3                  # the start was 2.5 mm too deep
    assert np.abs(body.position[[0, 1, 3, 4, 5]]).max() < 1e-9
    for name in ("Line1", "Line2", "Line3", "Line4"):
        assert found.end_tensions[name] == pytest.approx([bottom, top], rel=1e-9)
        along = found.lines[name].along_line(["S", "axial_tension", "r"])
        expected = top - WET * (LENGTH - along["S"])
        assert np.abs(along["axial_tension"] - expected).max() < 1e-8 * top
        assert np.abs(along["r"][:, :2] - along["r"][0, :2]).max() < 1e-9
    K = body.stiffness
    # the pendulum's (the string's, its tension varying along it; the tendons stay
    # straight, so their bending stiffness adds nothing); tension over length (T_total /
    # L, a weightless string's) only to 1 %
    assert K[0, 0] == pytest.approx(surge, rel=1e-9)
    assert K[1, 1] == pytest.approx(surge, rel=1e-9)
    assert K[0, 0] == pytest.approx(NET / LENGTH, rel=1e-2)
    assert K[0, 0] != pytest.approx(NET / LENGTH, rel=1e-3)
    assert K[2, 2] == pytest.approx(4 * EA / LENGTH, rel=1e-9)
    # the fairleads 25 m below the reference point and 15 m from its axis: surge-pitch
    # and sway-roll through that lever, yaw the pendulums' at 15 m
    arm = FAIRLEAD_Z
    assert K[0, 4] == pytest.approx(arm * surge, rel=1e-9)
    assert K[1, 3] == pytest.approx(-arm * surge, rel=1e-9)
    assert K[5, 5] == pytest.approx(15.0 ** 2 * surge, rel=1e-9)
    assert body.asymmetry < 1e-9


def test_the_tlp_stiffness_is_the_derivative_of_re_solved_equilibria():
    """K dq = dF: each column of K^-1 against the pose's central difference under loads
    +-dF_j on the hull (dF_j = K_jj h_j, h 1 mm and 1e-5 rad)."""
    system, _ = read_moordyn(DECK)
    solver = SystemSolver(system, held_lines(system, TIGHT), PETSc.COMM_WORLD)
    try:
        base = solver.solve()
        K = solver.body_stiffness("Body1").matrix
        X, R = base.bodies["Body1"][:3], base.rotations["Body1"]
        body = system.bodies[0]
        h = np.array([1e-3] * 3 + [1e-5] * 3)
        numeric = np.empty((6, 6))
        for j in range(6):
            poses = []
            for sign in (1.0, -1.0):
                load = np.zeros(6)
                load[j] = sign * K[j, j] * h[j]
                loaded = dataclasses.replace(system, bodies=(dataclasses.replace(
                    body, load=tuple(np.add(body.load, load))),))
                found = solver.solve(loaded)
                poses.append((found.bodies["Body1"][:3], found.rotations["Body1"]))
            (xp, Rp), (xm, Rm) = poses
            numeric[:3, j] = (xp - xm) / (2 * K[j, j] * h[j])
            numeric[3:, j] = log_rotation(Rp @ Rm.T) / (2 * K[j, j] * h[j])
    finally:
        solver.destroy()
    compliance = np.linalg.inv(K)
    for rows in (slice(0, 3), slice(3, 6)):
        for columns in (slice(0, 3), slice(3, 6)):
            block = compliance[rows, columns]
            scale = np.abs(compliance[rows, rows]).max() ** 0.5 * np.abs(
                compliance[columns, columns]).max() ** 0.5
            assert np.abs(numeric[rows, columns] - block).max() < 1e-6 * scale, (rows, columns)


def test_the_tlp_with_its_anchors_moved_converges_at_the_default_tolerances():
    """Each anchor 1 m further out: Newton's first step leaves a scaled residual of
    about 2e-7, the tendons' own error at the default -rod_al_rtol/-rod_al_ctol (EA
    1.2e10 N times a constraint residual of 1e-9 is 12 N a tendon on a force scale of
    8e7 N), which no line search step reduces; the lines are then taken to their
    stationary points and Newton goes on (it failed with "the line search found no
    decrease of the residual 2.28e-07"). It converges to 6.2e-13 in 5 iterations, its
    pose and tensions those of the tight tolerances' run to 2.1e-14 m and 3.7e-6 N of
    5.3e6 N (measured, the same on 1 and 2 ranks)."""
    system, _ = read_moordyn(DECK)
    moved = offsets("Point1,1,0,0:Point2,0,1,0:Point3,-1,0,0:Point4,0,-1,0", system)
    found = solve_system(moved)
    tight = solve_system(moved, options=TIGHT)
    assert found.converged and found.residual < Settings().floor
    assert np.abs(found.bodies["Body1"].position
                  - tight.bodies["Body1"].position).max() < 1e-11
    for name in ("Line1", "Line2", "Line3", "Line4"):
        assert found.end_tensions[name] == pytest.approx(tight.end_tensions[name],
                                                         rel=1e-10)


def test_the_api_refuses_a_tlp_heavier_than_its_buoyancy():
    """solve_system checks where the run starts as the command line does
    (system_check.check_reach): a hull of 5000 m^3, 8.58e6 N heavier than its buoyancy,
    on tendons all taut, is refused in one line naming its net force, before any solve
    (it returned the tendons in compression, -2.1 MN, at a saddle)."""
    system, _ = read_moordyn(DECK)
    heavy = dataclasses.replace(system, bodies=tuple(
        dataclasses.replace(body, volume=5000.0) for body in system.bodies))
    with pytest.raises(RodInputError) as refused:
        solve_system(heavy, options=TIGHT)
    message = str(refused.value)
    assert "\n" not in message
    assert message.startswith("line Line1: taut between Point1 and Body1 where the run "
                              "starts, as are all lines at Body1, and nothing pulls them: "
                              "Body1's buoyancy less weight and load, (0, 0, "
                              "-8.58082e+06) N")


def test_a_buoy_between_two_taut_lines_rises_where_their_tensions_hold_it():
    """tests/data/moordyn/buoy_level.dat: a buoy whose net buoyancy B - W = 90.7 kN
    pulls it along neither of its two level tendons where the run starts (its own force
    is across both), but it is held between them (system_check.balanced: their tensions
    balance): check_reach passes it (it refused it as tendons in compression), and it
    rises by h where the taut strings' closed form puts it: each tendon, its chord
    c = sqrt(50^2 + h^2) nearly level, sags by s = w c^2 / 8T under its wet weight w, so
    its stretched length L (1 + T / EA) is the chord and the sag's 8 s^2 / 3c (1.7e-4 m
    of the 12.7 mm stretch), and 2 T h / c = B - W - w L (the buoy carries half of each
    tendon's wet weight); the strings' neglected terms are of the order (w L / T)^2."""
    deck = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "buoy_level.dat")
    system, _ = read_moordyn(deck)
    found = solve_system(system, options=TIGHT)
    position = np.asarray(found.points["Point2"], dtype=float)
    net, length = (RHO * 10.0 - 1000.0) * G, 49.99

    def tension(chord):
        """T of the sagging string spanning ``chord`` (fixed point of the length's
        equation, from the straight string's)."""
        value = EA * (chord - length) / length
        for _ in range(50):
            value = EA * ((chord + WET ** 2 * chord ** 3 / (24 * value ** 2)) / length - 1)
        return value

    def unbalanced(h):
        chord = np.hypot(50.0, h)
        return 2 * tension(chord) * h / chord - (net - WET * length)

    low, high = 0.1, 1.0                    # bisection of the closed form's root
    for _ in range(100):
        middle = (low + high) / 2
        low, high = (low, middle) if unbalanced(middle) > 0 else (middle, high)
    assert position[2] + 50.0 == pytest.approx(low, rel=1e-4)
    assert abs(position[0] - 50.0) < 1e-9 and abs(position[1]) < 1e-9    # symmetric
