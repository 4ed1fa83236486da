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
     "line type main: 9 columns, a MoorDyn version 2 line type has 10 or more"),
    ("384.243E6", "ea_table.dat", "EA 'ea_table.dat': a nonlinear (tabulated) stiffness"),
    ("2             writeLog", "1             Currents",
     "OPTIONS: Currents 1: a current or a seabed read from MoorDyn's grid files is not "
     "read"),
    ("4     Body1", "4     Body2", "attachment Body2: no body 2 in BODIES"),
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
