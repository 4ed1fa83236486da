"""The layout of a system's lines on the ranks (petsc_rod/system/placement.py): balanced
by element counts, several lines a rank or several ranks a line."""

import numpy as np

from petsc_rod.model.line import Line, UniformLine
from petsc_rod.model.line_type import LineType
from petsc_rod.model.system import Connection, SystemLine
from petsc_rod.system.placement import layout, line_elements


def test_more_lines_than_ranks_are_dealt_largest_first_to_the_least_loaded_rank():
    group, first = layout([100, 10, 10, 80, 20], 2)
    assert first.tolist() == [0, 1, 2]
    assert group.tolist() == [0, 0, 1, 1, 1]
    loads = np.bincount(group, weights=[100, 10, 10, 80, 20])
    assert loads.tolist() == [110.0, 110.0]
    group, first = layout([5, 5, 5], 3)
    assert sorted(group.tolist()) == [0, 1, 2]


def test_fewer_lines_than_ranks_share_the_ranks_by_size():
    group, first = layout([300, 100], 4)
    assert group.tolist() == [0, 1]
    assert first.tolist() == [0, 3, 4]                  # 3 ranks for the long line
    group, first = layout([10, 10, 1000], 8)
    assert np.diff(first).tolist() == [1, 1, 6]
    group, first = layout([7], 2)
    assert first.tolist() == [0, 2]
    group, first = layout([], 2)                        # no lines: one idle group
    assert group.size == 0 and first.tolist() == [0, 2]


def test_a_line_costs_its_element_count():
    chain = LineType("chain", od=0.1, mass=100.0, ei=1e3, gj=1e3, ea=1e9)
    ends = (Connection("a"), Connection("b"))
    assert line_elements(SystemLine("u", UniformLine(elements=37), *ends)) == 37
    assert line_elements(SystemLine("s", Line(((chain, 10.0, 4), (chain, 20.0, 6))),
                                    *ends)) == 10
