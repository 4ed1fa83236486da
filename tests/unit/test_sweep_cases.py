"""The cases of a sweep (petsc_rod/sweep/cases.py, numpy only): the offset headings'
directions, the current headings, products, the nearest case, the case file."""

import numpy as np
import pytest

from petsc_rod.errors import RodInputError
from petsc_rod.sweep import cases

# the base values the generators read (cli.options.read_options' names)
RISER = {"rod_start": "pin", "rod_end": "pin", "rod_start_position": np.zeros(3),
         "rod_end_position": np.array([300.0, 400.0, 1000.0]), "rod_length": 1800.0,
         "rod_current": np.array([0.5, 0.0, 0.0]), "rod_current_profile": None,
         "rod_drag": np.array([1025.0, 1.2, 0.3])}


def position(case):
    return np.array([float(v) for v in case.options["rod_end_position"].split(",")])


def test_offsets_move_the_hang_off_along_the_headings():
    made = {c.name: c for c in cases.offset_cases((0.0, 50.0), ("near", "far", "cross"), RISER)}
    assert list(made) == ["offset0", "near50", "far50", "cross50"]
    top = RISER["rod_end_position"]
    far = np.array([0.6, 0.8, 0.0])                 # from the anchor to the hang-off
    assert np.allclose(position(made["offset0"]), top)
    assert np.allclose(position(made["far50"]), top + 50 * far)
    assert np.allclose(position(made["near50"]), top - 50 * far)
    # cross: far turned 90 degrees anticlockwise seen from above
    assert np.allclose(position(made["cross50"]), top + 50 * np.array([-0.8, 0.6, 0.0]))


def test_the_hang_off_is_the_higher_held_end():
    start_on_top = {**RISER, "rod_start_position": np.array([0.0, 0.0, 1000.0]),
                    "rod_end_position": np.array([1000.0, 0.0, 0.0])}
    made = cases.offset_cases((10.0,), ("far",), start_on_top)
    assert np.allclose([float(v) for v in made[0].options["rod_start_position"].split(",")],
                       [-10.0, 0.0, 1000.0])
    with pytest.raises(RodInputError, match="both ends held"):
        cases.offset_cases((10.0,), ("far",), {**RISER, "rod_end": "free"})


def test_current_headings_turn_the_base_speed():
    made = cases.current_cases((0.0, 90.0, 180.0), None, RISER)
    velocities = [np.array([float(v) for v in c.options["rod_current"].split(",")]) for c in made]
    assert np.allclose(velocities, [[0.5, 0, 0], [0, 0.5, 0], [-0.5, 0, 0]])
    with pytest.raises(RodInputError, match="-rod_drag"):
        cases.current_cases((0.0,), 1.0, {**RISER, "rod_drag": None})
    # a line of sections takes its drag from its line types (-rod_drag is refused there)
    made = cases.current_cases((90.0,), 1.0, {**RISER, "rod_drag": None,
                                              "rod_sections": "scr10:2400"})
    assert made[0].options["rod_current"] == "0,1,0"


def test_product_and_nearest():
    made = cases.product(cases.offset_cases((0.0, 50.0), ("near",), RISER),
                         cases.current_cases((0.0, 90.0), 1.0, RISER))
    assert [c.name for c in made] == ["offset0_current0", "offset0_current90",
                                      "near50_current0", "near50_current90"]
    values = [c.options for c in made]
    scales = cases.spreads(values)
    # near50 with the current at 90 is nearer near50 at 0 (one swept value) than offset0 at 90
    assert cases.nearest(values[3], values[:3], scales) in (1, 2)
    assert cases.nearest(values[3], [values[0], values[2]], scales) == 1
    assert cases.nearest(values[0], [], scales) is None


def test_read_cases(tmp_path):
    path = tmp_path / "cases.txt"
    path.write_text("# a comment\nname -rod_end_position rod_al_max_it\n"
                    "a 1,2,3 -   # as the base\n'b' 1,2,4 10\n")
    made = cases.read_cases(str(path), lambda name: name.startswith("rod_"))
    assert [(c.name, c.options) for c in made] == [
        ("a", {"rod_end_position": "1,2,3"}),
        ("b", {"rod_end_position": "1,2,4", "rod_al_max_it": "10"})]
    path.write_text("name rod_x\nbad/name 1\n")
    with pytest.raises(RodInputError, match="case name"):
        cases.read_cases(str(path), lambda name: True)


def test_an_option_set_by_two_sources_is_refused():
    """Review of issue 24: a case file's end position combined with -sweep_offsets was
    overwritten by the offsets' without a word."""
    listed = [cases.Case("far100", {"rod_end_position": "1700,0,1500"})]
    with pytest.raises(RodInputError, match="-rod_end_position is set by two sources"):
        cases.product(listed, cases.offset_cases((100.0,), ("near",), RISER))


def test_the_envelopes_leave_out_what_has_no_finite_value():
    """Review of issue 24: two straight cases (bend radius inf all along) crashed the
    report's range graphs; a line type without smys drew an empty utilisation panel."""
    from petsc_rod.report import envelopes
    S = np.linspace(0.0, 1.0, 5)
    straight = [{"S": S, "effective_tension": S + k, "bend_radius": np.full(5, np.inf),
                 "utilisation": np.full(5, np.nan)} for k in range(2)]
    S_out, result = envelopes.envelopes(straight)
    assert list(result) == ["effective_tension"]
