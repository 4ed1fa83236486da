"""The Python API's system classes (petsc_rod/api/system.py): the system a script builds
and the one read from the same MoorDyn file are equal (dataclass equality)."""

import dataclasses
import os

import numpy as np
import pytest

from helpers import REPO_ROOT
from petsc_rod.api import (Body, Connection, Environment, Line, LineType, Point, System,
                           SystemLine, read_moordyn)

pytestmark = pytest.mark.unit

DATA = os.path.join(REPO_ROOT, "tests", "data", "moordyn")
ANCHORS = ((853.87, 0.0, -320.0), (-426.94, 739.47, -320.0), (-426.94, -739.47, -320.0))
FAIRLEADS = ((5.2, 0.0, -70.0), (-2.6, 4.5, -70.0), (-2.6, -4.5, -70.0))


def chain():
    """OC3-Hywind's line type, with the EI = 0 rule's bending stiffness (docs/systems.md):
    EI = (h / 10)^2 |w| D for 902.2 m in 903 elements of 1 m or less, D = 320 m, and
    GJ = EI / 1.3; the file's Ca 1 as its ca."""
    weight = abs(77.7066 - 1025.0 * np.pi * 0.09 ** 2 / 4) * 9.80665
    ei = (0.1 * (902.2 / 903)) ** 2 * (weight * 320.0)
    return LineType("main", od=0.09, mass=77.7066, ei=ei, gj=ei / 1.3, ea=384.243e6, cd=1.6,
                    ca=1.0)


def spar_on_a_body():
    """lines_body.txt as a script writes it: three anchors, a body held where the
    coupled code puts it, its fairleads in body axes."""
    return System(
        lines=tuple(SystemLine(f"Line{k}", Line([(chain(), 902.2, 903)]),
                               Connection(f"Point{k}"), Connection("Body1", FAIRLEADS[k - 1]))
                    for k in (1, 2, 3)),
        points=tuple(Point(f"Point{k}", "fixed", ANCHORS[k - 1]) for k in (1, 2, 3)),
        bodies=(Body("Body1", position=(0.0, 0.0, -35.0, 0.0, 0.0, 0.0),
                     cog=(0.0, 0.0, -35.0), held=(True,) * 6),),
        environment=Environment(seabed=-320.0, seabed_stiffness=3.0e6 * 0.09, surface=0.0))


def test_the_api_builds_the_system_the_moordyn_file_reads():
    read, notes = read_moordyn(os.path.join(DATA, "lines_body.txt"))
    built = spar_on_a_body()
    built.check()
    assert built == read
    assert len(notes) == 4
    moved = dataclasses.replace(built.lines[0], end=Connection("Body1", (5.3, 0.0, -70.0)))
    assert dataclasses.replace(built, lines=(moved,) + built.lines[1:]) != read


def test_the_api_builds_the_oc3_deck_with_prescribed_fairleads():
    read, _ = read_moordyn(os.path.join(DATA, "OC3Hywind_MoorDyn.dat"))
    built = System(
        lines=tuple(SystemLine(f"Line{k}", Line([(chain(), 902.2, 903)]),
                               Connection(f"Point{k}"), Connection(f"Point{k + 3}"))
                    for k in (1, 2, 3)),
        points=tuple(Point(f"Point{k}", "fixed", p) for k, p in enumerate(ANCHORS, 1))
        + tuple(Point(f"Point{k}", "prescribed", p) for k, p in enumerate(FAIRLEADS, 4)),
        environment=Environment(seabed=-320.0, seabed_stiffness=3.0e6 * 0.09, surface=0.0))
    assert built == read
