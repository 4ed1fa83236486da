"""Taut and vertical lines in a system run (issue 49): a line held at least its length
apart has no catenary and starts straight along its chord (scenes/starts.chord_start);
its equilibrium against the closed forms of a straight elastic line. A vertical line
longer than its ends' distance is refused in one line naming it, not with a single
line's -rod_initial_shape message. A tension-leg platform (options/tlp.dat): tendons
shorter than their ends' distance to a free hull that pulls them, and refused where the
hull is heavier than its buoyancy.
"""

import os

import numpy as np
import h5py
import pytest

from helpers import REPO_ROOT, describe, run_petsc_rod
from test_system_cli import refused

EA, DIAMETER, WATER, GRAVITY = 384.243e6, 0.09, 1025.0, 9.80665
TYPES = """--------------------- MoorDyn Input File ------------------------------------
{title}
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
main       0.09    {mass}    384.243E6  -0.8        {ei}          1.6    1.0    0.1     0.0
"""
POINTS = """---------------------------- POINTS -----------------------------------------
ID    Attachment  X       Y        Z       Mass   Volume  CdA    Ca
(#)   (-)         (m)     (m)      (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed       0       0        -30     0      0       0      0
2     {kind}       {x}     0        -5      0      0       0      0
---------------------------- LINES ------------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  Outputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     main       1        2         {length}   10      -
---------------------------- OPTIONS ----------------------------------------
1025.0        WtrDnsty      water density (kg/m^3)
30            WtrDpth       water depth (m)
------------------------- need this line --------------------------------------
"""
CHAIN = 77.7066                                         # kg/m, OC3-Hywind's
NEUTRAL = WATER * np.pi * DIAMETER ** 2 / 4             # kg/m: no weight in water


def deck(tmp_path, length, x=0.0, mass=CHAIN, kind="Fixed", ei=0.0):
    path = tmp_path / "taut.dat"
    path.write_text(TYPES.format(title="a taut line between two points", mass=repr(mass),
                                 ei=ei)
                    + POINTS.format(kind=kind, x=x, length=repr(length)))
    return str(path)


def solved(tmp_path, args, ranks):
    out = tmp_path / "taut.h5"
    process = run_petsc_rod(args + ["-rod_output", str(out)], ranks, 120)
    assert process.returncode == 0, describe(process)
    with h5py.File(out, "r") as result:
        line = result["lines/Line1"]
        return line["S"][()], line["r"][()], line["axial_tension"][()]


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_vertical_tendon_has_its_tension_linear_in_height(tmp_path, ranks):
    """25 m between an anchor and a point right above it, 24.99 m of chain (698 N/m in
    water): T(S) = T_0 + w S from the anchor, T_0 = EA (c - L) / L - w L / 2, and
    z(S) = z_a + S + (T_0 S + w S^2 / 2) / EA: to 1e-7 of the largest tension (the ends'
    are 1e-8 off), 1e-9 of the length."""
    length, chord = 24.99, 25.0
    S, r, tension = solved(tmp_path, ["-rod_system", deck(tmp_path, length)], ranks)
    w = (CHAIN - NEUTRAL) * GRAVITY
    bottom = EA * (chord - length) / length - w * length / 2
    assert np.abs(tension - (bottom + w * S)).max() < 1e-7 * (bottom + w * length)
    assert np.abs(r[:, :2]).max() < 1e-12 * chord
    height = -30.0 + S + (bottom * S + w * S ** 2 / 2) / EA
    assert np.abs(r[:, 2] - height).max() < 1e-9 * chord


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_taut_weightless_line_stretches_by_tension_times_length_over_ea(tmp_path, ranks):
    """A line of (nearly: 1e-5 N/m) no weight in water held 0.1 % beyond its length, 20 m
    across and 25 m up: straight, of the one tension T = EA (c - L) / L, stretch =
    T L / EA."""
    chord = np.hypot(20.0, 25.0)
    length = chord / 1.001
    S, r, tension = solved(tmp_path, ["-rod_system", deck(tmp_path, length, x=20.0,
                                                         mass=NEUTRAL + 1e-6,
                                                         ei=100.0)],
                             ranks)
    expected = EA * (chord - length) / length
    assert np.abs(tension / expected - 1).max() < 1e-9
    along = np.array([20.0, 0.0, 25.0]) / chord
    assert np.abs(r - np.array([0.0, 0.0, -30.0]) - np.outer(S * chord / length, along)
                  ).max() < 1e-9 * chord


@pytest.mark.parametrize("kind, option", [("Fixed", []),
                                          ("Free", ["-rod_system_line_length", "Line1,26"])])
def test_a_vertical_line_longer_than_its_ends_distance_is_refused(tmp_path, kind, option):
    """Held or free (a free point's start above the anchor), a vertical line longer
    than its ends' distance has no catenary: refused naming the line, its length, the
    distance and what to change, not with -rod_initial_shape."""
    line = refused(tmp_path, ["-rod_system", deck(tmp_path, 26.0 if not option else 20.0,
                                                   kind=kind)] + option)
    made = " (-rod_system_line_length)" if option else ""
    assert line == (
        "petsc_rod: error: line Line1: its ends Point1 and Point2 lie on one vertical 25 m "
        f"apart where the run starts{made}, and its length 26 m is longer, so it has no "
        "catenary and would fold on itself; shorten it to at most their distance (a taut "
        "tendon) or move an end sideways")


TLP = os.path.join(REPO_ROOT, "options", "tlp.dat")


@pytest.mark.parametrize("ranks", [1, 2])
def test_the_tension_leg_platform_runs_from_its_file(tmp_path, ranks):
    """options/tlp.dat: a free hull, 2.2e6 kg of net buoyancy, on four 94.96 m tendons
    95 m long between anchor and fairlead (check_reach refused them: shorter than their
    ends' distance): the hull rises 2.48 mm to where each tendon's top tension is
    (B - W) / 4 (tests/solver/test_system_tlp.py's closed forms), the same on 1 and 2
    ranks."""
    out = tmp_path / "tlp.h5"
    process = run_petsc_rod(["-rod_system", TLP, "-rod_output", str(out)], ranks, 120)
    assert process.returncode == 0, describe(process)
    assert "petsc_rod: converged" in process.stdout and "warning" not in process.stdout
    net = (WATER * 8000.0 - 6.0e6) * GRAVITY
    wet = (450.0 - WATER * np.pi * 0.7 ** 2 / 4) * GRAVITY
    chord = 94.96 + 94.96 * (net / 4 - wet * 94.96 / 2) / 1.2e10
    with h5py.File(out, "r") as result:
        pose = result["system/body_positions"][0]
        assert pose[2] == pytest.approx(-120.0 + chord + 25.0, abs=1e-9)
        assert np.abs(pose[[0, 1, 3, 4, 5]]).max() < 1e-9
        # the command line's default line tolerances: the system's accuracy, 1e-7
        assert np.allclose(result["system/end_tensions"][:, 1], net / 4, rtol=1e-7)


def test_a_tension_leg_platform_heavier_than_its_buoyancy_is_refused(tmp_path):
    """Its tendons, all taut, would be in compression: one line naming the hull's net
    force, no file."""
    with open(TLP, encoding="utf-8") as source:
        text = source.read()
    heavy = tmp_path / "heavy.dat"
    heavy.write_text(text.replace("6.0E6   0        0        8000", "6.0E6   0        0        5000"))
    line = refused(tmp_path, ["-rod_system", str(heavy)])
    assert line.startswith("petsc_rod: error: line Line1: taut between Point1 and Body1 "
                           "where the run starts, as are all lines at Body1, and nothing "
                           "pulls them: Body1's buoyancy less weight and load, (0, 0, "
                           "-8.58082e+06) N")
