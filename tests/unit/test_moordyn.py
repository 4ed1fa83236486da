"""MoorDyn version 2 files read as a System (petsc_rod/model/moordyn.py): two real files
(tests/data/moordyn/README.md) parse into their numbers, with the EI = 0 rule's
bending stiffness; bad files get one line each."""

import math
import os

import numpy as np
import pytest

from helpers import REPO_ROOT
from petsc_rod.errors import RodInputError
from petsc_rod.model.moordyn import parse_moordyn, read_moordyn
from petsc_rod.model.system_check import rotation

pytestmark = pytest.mark.unit

DATA = os.path.join(REPO_ROOT, "tests", "data", "moordyn")
OC3 = os.path.join(DATA, "OC3Hywind_MoorDyn.dat")
BODY = os.path.join(DATA, "lines_body.txt")
ANCHORS = ((853.87, 0.0, -320.0), (-426.94, 739.47, -320.0), (-426.94, -739.47, -320.0))
FAIRLEADS = ((5.2, 0.0, -70.0), (-2.6, 4.5, -70.0), (-2.6, -4.5, -70.0))


def oc3_bending():
    """The EI the rule gives OC3's chain: (0.1 h)^2 w D, h = 902.2 m / 903 elements,
    w its wet weight, D = 320 m."""
    weight = abs(77.7066 - 1025.0 * np.pi * 0.09 ** 2 / 4) * 9.80665
    return (0.1 * (902.2 / 903)) ** 2 * (weight * 320.0)


def test_the_oc3_hywind_deck_reads_into_its_points_lines_and_line_type():
    system, notes = read_moordyn(OC3)
    assert [p.name for p in system.points] == [f"Point{k}" for k in range(1, 7)]
    assert [p.kind for p in system.points] == ["fixed"] * 3 + ["prescribed"] * 3
    assert [p.position for p in system.points] == list(ANCHORS + FAIRLEADS)
    assert system.bodies == ()
    assert [(line.start.to, line.end.to) for line in system.lines] == [
        ("Point1", "Point4"), ("Point2", "Point5"), ("Point3", "Point6")]
    for line in system.lines:
        ((kind, length, elements),) = line.line.sections
        assert (length, elements) == (902.2, 903)       # max(NumSegs 20, 902.2 m / 1 m)
        assert (kind.od, kind.mass, kind.ea, kind.cd) == (0.09, 77.7066, 384.243e6, 1.6)
        assert kind.ei == pytest.approx(oc3_bending(), rel=1e-15)
        assert kind.gj == pytest.approx(kind.ei / 1.3, rel=1e-15)
    assert math.sqrt(oc3_bending() / (698.1 * 320.0)) == pytest.approx(0.1, rel=1e-3)
    sea = system.environment
    assert (sea.seabed, sea.surface, sea.water_density, sea.gravity) == (
        -320.0, 0.0, 1025.0, 9.80665)
    assert sea.seabed_stiffness == pytest.approx(3.0e6 * 0.09)
    assert notes[0].startswith("line type main: EI 0 in the file, given EI = 2230 N m^2")
    assert "the seabed is at the deepest anchor, z = -320 m" in " ".join(notes)
    assert "ignored: dtM, cbot, dtIC, TmaxIC, CdScaleIC, threshIC" in " ".join(notes)


def test_a_body_s_points_become_connections_at_its_local_coordinates():
    system, _ = read_moordyn(BODY)
    (body,) = system.bodies
    assert body.name == "Body1" and body.held == (True,) * 6
    assert body.position == (0.0, 0.0, -35.0, 0.0, 0.0, 0.0) and body.cog == (0, 0, -35.0)
    assert [p.name for p in system.points] == ["Point1", "Point2", "Point3"]
    assert [(line.end.to, line.end.local) for line in system.lines] == [
        ("Body1", f) for f in FAIRLEADS]
    assert system.environment.seabed == -320.0          # WtrDpth


def test_a_default_static_option_is_not_given():
    system, notes = parse_moordyn(text(lambda s: s.replace("320           WtrDpth",
                                                           "DEFAULT       WtrDpth")))
    assert system.environment.seabed == -320.0
    assert "the seabed is at the deepest anchor, z = -320 m" in " ".join(notes)


def test_a_finer_element_keeps_the_rule_at_its_fraction():
    coarse, _ = read_moordyn(OC3, element_length=10.0)
    ((kind, _, elements),) = coarse.lines[0].line.sections
    assert elements == 91
    weight = abs(77.7066 - 1025.0 * np.pi * 0.09 ** 2 / 4) * 9.80665
    assert kind.ei == pytest.approx((0.1 * 902.2 / 91) ** 2 * weight * 320.0, rel=1e-14)


def text(change=lambda s: s):
    with open(BODY, encoding="utf-8") as source:
        return change(source.read())


def refused(content):
    with pytest.raises(RodInputError) as error:
        parse_moordyn(content, "case.dat")
    message = str(error.value)
    assert "\n" not in message
    return message


def test_a_missing_section_header_is_refused():
    message = refused(text(lambda s: s.replace(
        "----------------------- LINE TYPES ------------------------------------------\n",
        "")))
    assert message == ("case.dat: no LINE TYPES section (a header line such as "
                       "'---------- LINE TYPES ----------' before its table)")


def test_a_line_naming_an_unknown_point_is_refused():
    message = refused(text(lambda s: s.replace("3     main       3        6",
                                               "3     main       3        9")))
    assert message == "case.dat:25: LINES: line 3: AttachB 9: no point 9 in POINTS"


def test_an_unknown_option_is_refused():
    message = refused(text(lambda s: s.replace("320           WtrDpth",
                                               "320           WtrDepth")))
    assert message.startswith("case.dat:32: OPTIONS: unknown option 'WtrDepth'; petsc_rod "
                              "reads WtrDpth, WtrDnsty, g, kBot")


def test_a_rod_is_refused():
    rods = ("---------------------- RODS ----------------------------------------\n"
            "ID   RodType  Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs  RodOutputs\n"
            "(#)  (name)   (word/ID)   (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)\n"
            "1      Can      Body1      0     0     2     0     0     15   8         p\n")
    message = refused(text(lambda s: s.replace(
        "---------------------- CONNECTION PROPERTIES", rods
        + "---------------------- CONNECTION PROPERTIES")))
    assert message == ("case.dat:14: RODS: rods (rigid cylinders) are not modelled; replace "
                       "a rod by a body, or a line of a stiff line type")
    assert "R1A: a rod's end; rods are not modelled" in refused(text(lambda s: s.replace(
        "1     main       1        4", "1     main       R1A      4")))


@pytest.mark.parametrize("old, new, words", [
    ("main       0.09    77.7066    384.243E6  -0.8        0          1.6    1.0    0.1     0.0",
     "main       0.09    77.7066    384.243E6  -0.8        1.6    1.0    0.1     0.0",
     "case.dat:6: LINE TYPES: line type main: 9 columns, a MoorDyn version 2 line type "
     "has 10 or more"),
    ("384.243E6", "ea_table.dat", "EA 'ea_table.dat': a nonlinear (tabulated) stiffness"),
    ("2             writeLog", "1             Currents",
     "OPTIONS: Currents 1: a current or a seabed read from MoorDyn's grid files is not "
     "read"),
    ("4     Body1", "4     Body2", "attachment Body2: no body 2 in BODIES"),
    ("main       0.09    77.7066    384.243E6  -0.8        0          1.6    1.0    0.1     0.0\n",
     "main       0.09    77.7066    384.243E6  -0.8        0          1.6    1.0    0.1     0.0\n"
     "main       0.09    77.7066    384.243E6  -0.8        0          1.6    1.0    0.1     0.0\n",
     "case.dat:7: LINE TYPES: a second line type main"),
    ("1     Fixed     853.87", "1     Anchored  853.87", "attachment 'Anchored': use Fixed"),
])
def test_bad_fields_are_refused_naming_them(old, new, words):
    assert words in refused(text(lambda s: s.replace(old, new)))


def test_a_system_check_refusal_comes_through_the_reader():
    # the anchor 2 km farther out: 2857 m to the fairlead, a strain of 217 % for 902.2 m
    message = refused(text(lambda s: s.replace("1     Fixed     853.87",
                                               "1     Fixed     2853.87")))
    assert message.startswith("line Line1: Point1 and Body1 are held 2856.77 m apart: its "
                              "length 902.2 m must stretch by 217 % or more")


SEMI = """--------------------- MoorDyn Input File ------------------------------------
A free semi on chain and chain-polyester lines, a clump weight at the joint
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.2     200        1.5e9      -1          0          2.4    1.0    1.15    1.0
poly       0.15    20         1.0e8|3e8  -1          100        1.2    1.0    0.01    0.0
---------------------- ROD TYPES ------------------------------------
TypeName      Diam     Mass/m    Cd     Ca      CdEnd    CaEnd
(name)        (m)      (kg/m)    (-)    (-)     (-)      (-)
Can           10       1.0e3     0.6    1.0     1.2      1.0
---------------------- BODIES ---------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*   I*      Volume   CdA*   Ca*
(#)   (word)     (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)  (kg-m^2)  (m^3)   (m^2)  (-)
1     free        0     0      -5     0       0      10    1e6  -2|0|-8  1e8   1100    0      0
---------------------- POINTS ---------------------------------------
ID  Attachment  X       Y     Z      Mass   Volume  CdA    Ca
(#)   (-)      (m)     (m)   (m)     (kg)   (m^3)   (m^2)  (-)
1   Fixed      -800     0     -200   0      0       0      0
2   Free       -300     0     -150   5000   0.5     1      0   ! the clump weight
3   Body1      -20      0     -10    100    0       0      0
4   Anchor      400   693     -200   0      0       0      0
5   Body1       10     17     -10    0      0       0      0
6   Fixed       400  -693     -200   0      0       0      0
7   Body1       10    -17     -10    0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain       1        2        520       20       -
2     poly        2        3        300       600      -
3     chain       4        5        800       40       -
4     chain       6        7        800       40       -
---------------------- OPTIONS -----------------------------------------
200      WtrDpth
1025     rho
9.81     g
1e6      kBot
0.5      FrictionCoefficient
---------------------- EXTERNAL LOADS --------------------------------
ID    Object          Fext             Blin          Bquad         CSys
(#)   (name)           (N)            (Ns/m)       (Ns^2/m^2)      (-)
1    Body1        1e5|0.0|0.0     0.0|0.0|0.0     0.0|0.0|0.0      G
------------------------- need this line --------------------------------------
"""


def test_a_free_body_a_clump_weight_and_two_line_types(tmp_path):
    path = tmp_path / "semi.dat"
    path.write_text(SEMI, encoding="utf-8")
    system, notes = read_moordyn(path)
    (body,) = system.bodies
    assert body.held == (False,) * 6 and body.volume == 1100.0
    assert body.position == (0.0, 0.0, -5.0, 0.0, 0.0, pytest.approx(np.radians(10.0)))
    assert body.mass == 1e6 + 100.0                       # the point's mass on the body
    assert body.cog == pytest.approx(((1e6 * -2.0 + 100.0 * -20.0) / (1e6 + 100.0), 0.0,
                                      (1e6 * -8.0 + 100.0 * -10.0) / (1e6 + 100.0)))
    assert body.load == (1e5, 0.0, 0.0, 0.0, 0.0, 0.0)
    clump = system.points[1]
    assert (clump.name, clump.kind, clump.mass, clump.volume, clump.cda) == (
        "Point2", "free", 5000.0, 0.5, 1.0)
    assert [p.kind for p in system.points] == ["fixed", "free", "fixed", "fixed"]
    counts = [line.line.sections[0][2] for line in system.lines]
    assert counts == [520, 600, 800, 800]                 # NumSegs 600 is kept
    chain, poly = system.lines[0].line.sections[0][0], system.lines[1].line.sections[0][0]
    assert (poly.ea, poly.ei, poly.gj) == (1.0e8, 100.0, 100.0 / 1.3)
    weight = abs(200.0 - 1025.0 * np.pi * 0.2 ** 2 / 4) * 9.81
    assert chain.ei == pytest.approx(0.01 * weight * 200.0, rel=1e-14)
    sea = system.environment
    assert (sea.seabed, sea.gravity, sea.seabed_friction) == (-200.0, 9.81, 0.5)
    assert sea.seabed_stiffness == pytest.approx(1e6 * 0.2)
    said = " ".join(notes)
    assert "EA 1.0e8|3e8: the static value 1e+08 is used" in said
    assert "times the line types' diameter 0.2 m (the largest)" in said
    assert "line type poly: EI" not in said               # given, not substituted


@pytest.mark.parametrize("old, new, words", [
    ("1    Body1        1e5|0.0|0.0     0.0|0.0|0.0     0.0|0.0|0.0      G",
     "1    Body1        1e5|0.0|0.0     0.0|0.0|0.0     0.0|0.0|0.0      L",
     "Body1: a force in body axes (CSys L) is not read"),
    ("1     free        0     0      -5", "1     floating    0     0      -5",
     "attachment 'floating': use one of"),
    ("200      WtrDpth", "bathymetry.txt WtrDpth",
     "OPTIONS: WtrDpth bathymetry.txt: a bathymetry file is not read"),
    ("2   Free       -300", "2   Body3      -300", "attachment Body3: no body 3 in BODIES"),
])
def test_bad_fields_of_the_semi_are_refused(old, new, words):
    assert old in SEMI
    assert words in refused(SEMI.replace(old, new))


def test_a_missing_file_is_refused_in_one_line(tmp_path):
    with pytest.raises(RodInputError) as error:
        read_moordyn(tmp_path / "absent.dat")
    assert str(error.value).startswith(f"MoorDyn file {tmp_path / 'absent.dat'}: ")


def test_the_older_option_names_kb_and_cb_are_read():
    system, notes = parse_moordyn(text(lambda s: s.replace("kBot", "kb").replace("cBot",
                                                                                  "cb")))
    assert system.environment.seabed_stiffness == pytest.approx(3.0e6 * 0.09)
    assert "ignored: writeLog, dtM, cb," in " ".join(notes)


def test_a_line_type_s_ca_is_its_added_mass_coefficient(tmp_path):
    """MoorDyn's Ca (the transverse added-mass coefficient) is the line type's ca, the
    modes' (analysis/mass.py); a negative one refused."""
    text = open(os.path.join(DATA, "small_free_body.dat")).read()
    path = tmp_path / "ca.dat"
    path.write_text(text.replace("1.6    1.0    0.1", "1.6    0.8    0.1"))
    system, _ = read_moordyn(str(path))
    assert {line.line.sections[0][0].ca for line in system.lines} == {0.8}
    path.write_text(text.replace("1.6    1.0    0.1", "1.6    -0.5   0.1"))
    with pytest.raises(RodInputError, match="EI, Cd and Ca must not be negative"):
        read_moordyn(str(path))


@pytest.mark.parametrize("depth", ["0", "-5"])
def test_a_water_depth_not_positive_is_refused_naming_it(depth):
    message = refused(text(lambda s: s.replace("320           WtrDpth",
                                               f"{depth}           WtrDpth")))
    assert message == (f"case.dat:32: OPTIONS: WtrDpth {depth}: the water depth (m, the "
                       "seabed at z = -WtrDpth) must be positive")


def test_a_numsegs_too_large_to_mesh_is_refused_naming_it():
    from petsc_rod.api import solve_system

    system, _ = parse_moordyn(text(lambda s: s.replace("902.2     20 ",
                                                       "902.2     4000000000 ")), "case.dat")
    with pytest.raises(RodInputError) as error:
        solve_system(system)
    message = str(error.value)
    assert message.startswith("line Line1: 4000000000 elements (its sections' counts: a "
                              "MoorDyn line's NumSegs"), message
    assert "-rod_elements" not in message


def test_a_body_turned_by_three_angles_is_placed_as_moordyn_places_it(tmp_path):
    """MoorDyn turns a body by R = R_x(r0) R_y(p0) R_z(y0) (rotations about X, the turned
    Y, the turned Z); the Body read must take its local points where that R does."""
    r0, p0, y0 = np.radians([10.0, 20.0, 30.0])
    c, s = np.cos, np.sin
    rx = np.array([[1, 0, 0], [0, c(r0), -s(r0)], [0, s(r0), c(r0)]])
    ry = np.array([[c(p0), 0, s(p0)], [0, 1, 0], [-s(p0), 0, c(p0)]])
    rz = np.array([[c(y0), -s(y0), 0], [s(y0), c(y0), 0], [0, 0, 1]])
    path = tmp_path / "turned.dat"
    path.write_text(SEMI.replace("0       0      10    1e6", "10      20     30    1e6"),
                    encoding="utf-8")
    (body,) = read_moordyn(path)[0].bodies
    turned = rotation(*body.position[3:])
    assert np.abs(turned - rx @ ry @ rz).max() < 1e-15
    assert np.abs(turned - rz @ ry @ rx).max() > 0.05     # not MoorPy's order


def test_one_angle_alone_is_read_as_given(tmp_path):
    path = tmp_path / "pitched.dat"
    path.write_text(SEMI.replace("0       0      10    1e6", "0       7      0     1e6"),
                    encoding="utf-8")
    (body,) = read_moordyn(path)[0].bodies
    assert body.position[3:] == pytest.approx((0.0, np.radians(7.0), 0.0), abs=1e-15)


def test_a_body_s_inertia_and_added_mass_are_read(tmp_path):
    """I about the cog (one number: all three), moved to the cog the body's point mass
    shifts (parallel axes), and Ca as rho V Ca in the translations, for the system's
    modes; a point's Ca."""
    path = tmp_path / "semi.dat"
    row = "1     free        0     0      -5     0       0      10    1e6  -2|0|-8  1e8   1100    0      0"
    assert row in SEMI
    path.write_text(SEMI.replace(row, row[:-1] + "0.5|0.5|1.0"), encoding="utf-8")
    system, _ = read_moordyn(path)
    (body,) = system.bodies
    cog = np.array(body.cog)
    d_body, d_point = np.array([-2.0, 0.0, -8.0]) - cog, np.array([-20.0, 0.0, -10.0]) - cog

    def moved(m, d):
        return m * (d @ d * np.eye(3) - np.outer(d, d))
    expected = 1e8 * np.eye(3) + moved(1e6, d_body) + moved(100.0, d_point)
    assert np.allclose(np.reshape(body.inertia, (3, 3)), expected, rtol=1e-13, atol=0)
    added = np.reshape(body.added_mass, (6, 6))
    assert np.allclose(np.diag(added), [1025.0 * 1100 * 0.5] * 2 + [1025.0 * 1100] + [0] * 3)
    assert np.count_nonzero(added - np.diag(np.diag(added))) == 0
    assert read_moordyn(os.path.join(REPO_ROOT, "tests", "data", "moordyn",
                                     "small_free_body.dat"))[0].bodies[0].inertia is None


def test_a_body_s_drag_area_is_said_not_read():
    """A body's CdA (MoorDyn's drag in a current) is not read: a note says so where it
    is not 0, none where it is."""
    with open(os.path.join(DATA, "small_free_body.dat"), encoding="utf-8") as source:
        deck = source.read()
    row = "20000 -2       0        30      0      0"
    assert row in deck
    _, notes = parse_moordyn(deck.replace(row, "20000 -2       0        30      10     0"))
    assert [n for n in notes if "CdA" in n] == [
        "body Body1: CdA 10 m^2 not read (a body takes no drag in a current: give that "
        "force as a load on the body)"]
    _, notes = parse_moordyn(deck)
    assert not [n for n in notes if "CdA" in n]
