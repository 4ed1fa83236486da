"""A line of a MoorDyn deck (tests/data/moordyn) solved as a single line: the OC3-Hywind
chain, given EI = 0 in the file, gets the EI rule's bending stiffness
(docs/systems.md), and the fairlead tension is the elastic catenary's to the seabed's
compliance, and does not change when that EI is a hundred times smaller: the
substituted stiffness does not matter."""

import dataclasses
import os

import numpy as np
import pytest

from helpers import REPO_ROOT
from petsc_rod.api import End, Line, Model, read_moordyn, solve
from petsc_rod.validation.elastic_catenary import elastic_catenary

pytestmark = pytest.mark.solver

DECK = os.path.join(REPO_ROOT, "tests", "data", "moordyn", "OC3Hywind_MoorDyn.dat")


def test_the_oc3_chain_with_the_substituted_ei_is_the_elastic_catenary():
    system, _ = read_moordyn(DECK)
    line = system.lines[0]
    ((kind, length, elements),) = line.line.sections
    anchor, fairlead = (np.array(system.node(end.to).position) for end in (line.start,
                                                                           line.end))
    sea = system.environment

    def top_tension(line_type):
        model = Model(Line([(line_type, length, elements)]), End.anchor(tuple(anchor)),
                      End.hang_off(tuple(fairlead)), sea)
        results = solve(model)
        assert results.converged
        return results.top_tension

    tension = top_tension(kind)
    softer = top_tension(dataclasses.replace(kind, ei=kind.ei / 100, gj=kind.gj / 100))
    weight = kind.submerged_weight(sea.water_density, sea.gravity)
    catenary = elastic_catenary(length, weight, kind.ea,
                                float(np.hypot(*(fairlead - anchor)[:2])),
                                float(fairlead[2] - anchor[2]))
    # measured: 911101.24 N against 911089.02 N (1.3e-5, the seabed's 2.6 mm
    # penetration under kBot), and 2e-8 between EI and EI / 100
    assert tension == pytest.approx(float(catenary.at(length)[2]), rel=3e-5)
    assert softer == pytest.approx(tension, rel=1e-7)
