"""A three-fold symmetric spread's mooring stiffness (system/held_line.py's stiffness at
the lines' stationary points): tests/data/moordyn/small_free_body.dat (three 70 m
chains of small EI at 0, 120, 240 degrees) with its anchors and fairleads written
exactly, and the same deck turned by 30 degrees about the vertical:

(a) Kxx = Kyy and no coupling of the translations with the yaw (the spread's planar
    stiffness is isotropic for three equally spaced lines);
(b) turning the deck turns K: K' = T K T^T, T the turn of the translations and the
    rotations, the yaw stiffness and Kxx + Kyy unchanged;
(c) one of its lines held (HeldLine) and walked to its ends after a 0.1 mm move has
    the stiffness of the line solved there from its start.

A line walked to its ends by the iteration's tolerances after a small move of the body
was linearised short of its stationary point: its transverse stiffness 45 % off and
different for each line (docs/systems.md, "The stiffness at the lines' stationary points").
"""

from pathlib import Path

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api.system_run import solve_system
from petsc_rod.model.moordyn import parse_moordyn
from petsc_rod.system.held_line import HeldLine

pytestmark = pytest.mark.solver

DECK = Path(__file__).parents[1] / "data" / "moordyn" / "small_free_body.dat"


def turned_deck(degrees):
    """The deck's text with its anchors (65 m out) and fairleads (5 m out) at exactly
    0, 120, 240 degrees plus ``degrees`` (the fairleads through the body's yaw y0)."""
    turn = np.radians(degrees)
    rows = []
    for row in DECK.read_text().splitlines():
        fields = row.split()
        if len(fields) == 9 and fields[1] in ("Fixed", "Body1") and fields[0].isdigit():
            fixed = fields[1] == "Fixed"
            angle = np.radians(120 * ((int(fields[0]) - 1) % 3)) + (turn if fixed else 0)
            radius = 65.0 if fixed else 5.0
            fields[2:4] = repr(radius * np.cos(angle)), repr(radius * np.sin(angle))
            row = "  ".join(fields)
        elif len(fields) == 14 and fields[1] == "Free":
            fields[7] = repr(float(degrees))
            row = "  ".join(fields)
        rows.append(row)
    return "\n".join(rows) + "\n"


def stiffness(degrees):
    system, _ = parse_moordyn(turned_deck(degrees))
    return solve_system(system).bodies["Body1"].stiffness


@pytest.fixture(scope="module")
def stiffnesses():
    return stiffness(0.0), stiffness(30.0)


def test_symmetric_spread_is_isotropic(stiffnesses):
    K = stiffnesses[0]
    assert K[0, 0] == pytest.approx(9211.66, rel=1e-5)
    assert abs(K[0, 0] - K[1, 1]) < 1e-6 * K[0, 0]
    assert np.abs(K[:2, 5]).max() < 1e-6 * K[0, 0]
    assert np.abs(K[5, :2]).max() < 1e-6 * K[0, 0]


def test_turned_spread_turns_the_stiffness(stiffnesses):
    K, turned = stiffnesses
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    Q = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    T = np.kron(np.eye(2), Q)
    assert np.abs(turned - T @ K @ T.T).max() < 1e-6 * np.abs(K).max()
    assert turned[5, 5] == pytest.approx(K[5, 5], rel=1e-7)
    assert turned[0, 0] + turned[1, 1] == pytest.approx(K[0, 0] + K[1, 1], rel=1e-7)


def test_walked_line_has_the_fresh_stiffness():
    system, _ = parse_moordyn(turned_deck(0.0))
    anchor, fairlead = np.array([65.0, 0.0, -30.0]), np.array([5.0, 0.0, -3.35])
    moved = fairlead + [0.0, 0.0, -1e-4]
    lines = [HeldLine.of_system_line(system.lines[0], anchor, fairlead, PETSc.COMM_SELF,
                                     system.environment, {"al_stability": 0})
             for _ in range(2)]
    try:
        walked, fresh = lines
        assert walked.solve(anchor, fairlead) and walked.solve(anchor, moved)
        assert fresh.solve(anchor, moved)
        K, K_fresh = walked.stiffness(), fresh.stiffness()
        assert K_fresh[4, 4] == pytest.approx(-23893.9 / 60.0, rel=1e-3)   # T_h / span
        assert np.abs(K - K_fresh).max() < 1e-6 * np.abs(K_fresh).max()
    finally:
        for line in lines:
            line.destroy()
