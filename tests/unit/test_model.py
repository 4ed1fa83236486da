"""The typed model (petsc_rod/model) and the Scene compiled from it (compile.py): the
checks name the model's fields, or the options a front end gives in their names; the
seabed, the current and the pipe's pressures are resolved in the compile, in the
solver's frame."""

import dataclasses
import warnings

import numpy as np
import pytest

from petsc_rod.compile import compile_scene
from petsc_rod.errors import RodInputError
from petsc_rod.model import End, Environment, Line, LineType, Model, UniformLine
from petsc_rod.model.names import Names

pytestmark = pytest.mark.unit

OPTIONS = Names({}, lambda key: f"-rod_{key}")
PIPE = LineType("pipe", od=0.2, mass=60.0, ei=1e5, gj=8e4, cd=1.0, id=0.15)


def riser(**change):
    fields = dict(line=Line([(PIPE, 160.0)], element_length=2.0),
                  start=End.anchor((10.0, 0.0, -100.0)),
                  end=End.hang_off((110.0, 0.0, -45.0)),
                  environment=Environment(seabed=-100.5, surface=0.0,
                                          current=[[0.0, 0.4, 0.0, 0.0],
                                                   [100.0, 0.1, 0.0, 0.0]]))
    fields.update(change)
    return Model(**fields)


def test_the_compiled_scene_holds_the_sea_in_the_solver_s_frame():
    scene = compile_scene(riser(line=Line([(PIPE, 160.0)], internal_pressure=1e6)))
    assert scene.length == 160.0 and np.array_equal(scene.start_position, [10, 0, -100])
    assert scene.end_position == pytest.approx([100.0, 0.0, 55.0], abs=0)
    assert scene.seabed.height == -0.5 and scene.seabed.flat
    assert scene.current.surface == 100.0 and scene.sea_surface == 100.0
    assert scene.internal_pressure == 1e6 and scene.design_factor == 2.0 / 3.0
    weight = (60.0 - 1025.0 * np.pi * 0.2**2 / 4) * 9.80665
    assert scene.load_values[0, 2] == -weight


@pytest.mark.parametrize("change, model_words, option_words", [
    (dict(end=End("free", frame=(0, 1, 0, 0, 0, 1, 1, 0, 0))),
     "Model.end.frame needs Model.end clamp", "-rod_end_frame needs -rod_end clamp"),
    (dict(start=End("clamp", twist=1.0)), "Model.start.twist: the roll of the clamped end",
     "-rod_start_twist: the roll"),
    (dict(environment=Environment(seabed_stiffness=1e5)),
     "Environment.seabed_stiffness needs Environment.seabed",
     "-rod_seabed_stiffness needs -rod_seabed"),
    (dict(line=Line([(PIPE, 160.0)], design_factor=0.8)),
     "Line.design_factor needs a line type with an smys column",
     "-rod_design_factor needs a line type with an smys column"),
    (dict(end=End.hang_off((300.0, 0.0, -45.0))), "Model.end.position: the ends are",
     "-rod_end_position: the ends are"),
    (dict(start=End.anchor((10.0, 0.0, -101.0))), "Model.start: the end is held at z = -101",
     "-rod_start: the end is held at z = -101"),
])
def test_a_refusal_names_the_fields_as_the_caller_gave_them(change, model_words,
                                                            option_words):
    for names, words in ((None, model_words), (OPTIONS, option_words)):
        with pytest.raises(RodInputError) as error:
            compile_scene(riser(**change), *(() if names is None else (names,)))
        assert words in str(error.value), str(error.value)


def test_a_uniform_line_compiles_to_its_own_values():
    model = Model(UniformLine(length=10.0, stiffness=(1.0, 2.0, 3.0),
                              load=((0.0, 0.0, -1.0), (0.0, 0.0, -2.0)), load_breaks=(4.0,)),
                  End("clamp"), End("free", force=(0.0, 0.0, 1.0)))
    scene = compile_scene(model)
    assert np.array_equal(scene.load_values, [[0, 0, -1], [0, 0, -2]])
    assert np.array_equal(scene.load_breaks, [4.0]) and np.array_equal(scene.end_force,
                                                                       [0, 0, 1])
    with pytest.raises(RodInputError, match="UniformLine.load_breaks: the breaks must"):
        compile_scene(Model(UniformLine(length=10.0, load=((0, 0, -1), (0, 0, -2)),
                                        load_breaks=(12.0,)), End("clamp"), End("free")))


def test_one_line_type_read_from_a_table_or_made_in_python():
    """Issue 48: two LineType classes (api/model.py, scenes/line.py); now one, which the
    table's reader makes and the API exports, giving the same section."""
    from petsc_rod.api import LineType as ApiLineType
    from petsc_rod.model import line_types_from_table
    assert ApiLineType is LineType
    table = {"name": ["pipe"], "od": np.array([0.2]), "mass": np.array([60.0]),
             "gj": np.array([8e4]), "ei": np.array([1e5]), "cd": np.array([1.0]),
             "id": np.array([0.15])}
    read = line_types_from_table(table, "-rod_line_types t.txt")["pipe"]
    a, b = read.section(0.0, 10.0, 1025.0, 9.80665), PIPE.section(0.0, 10.0, 1025.0, 9.80665)
    for name in ("stiffness_start", "stiffness_end", "weight", "drag", "od", "id"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_zero_pressures_and_a_zero_joint_stiffness_are_no_settings():
    """An explicit 0 is the default: a pipe's contents density and internal pressure of 0
    on line types without a bore, and an end stiffness of 0 on a clamp or a free end,
    are accepted (the API's Line and End took 0; a merge refused them), while a nonzero
    one still needs its partner."""
    bare = LineType("bare", od=0.2, mass=60.0, ei=1e5, gj=8e4, cd=1.0)
    scene = compile_scene(riser(line=Line([(bare, 160.0)], contents_density=0.0,
                                          internal_pressure=0.0)))
    assert scene.internal_pressure == 0.0 and scene.contents_density == 0.0
    with pytest.raises(RodInputError, match="Line.internal_pressure needs a line type"):
        compile_scene(riser(line=Line([(bare, 160.0)], internal_pressure=1.0)))
    for end in (End("clamp", (110.0, 0.0, -45.0), 0.0), End("free", None, 0.0)):
        compile_scene(riser(end=end))
    with pytest.raises(RodInputError, match="needs Model.end pin"):
        compile_scene(riser(end=End("clamp", (110.0, 0.0, -45.0), 1e4)))


FLOATY = LineType("floaty", od=0.2, mass=10.0, ei=1e5, gj=8e4, cd=1.0)
SMOOTH = LineType("smooth", od=0.2, mass=60.0, ei=1e5, gj=8e4)
ROPE = dict(length=100.0, stiffness=(1.0, 1.0, 1.0), load=(0.0, 0.0, -10.0))


@pytest.mark.parametrize("model, words", [
    (riser(end=End.hang_off((170.0, 0.0, -100.0))),
     "Model.end.position: the held ends are 160 m apart, the line's length 160 m"),
    (riser(line=Line([(FLOATY, 160.0)])),
     "Environment.seabed: no line type sinks (mass above the water displaced)"),
    (riser(environment=Environment(seabed=-100.5, seabed_stiffness=1e25)),
     "Environment.seabed_stiffness 1e+25: the largest accepted is"),
    (riser(line=Line([(SMOOTH, 160.0)])),
     "a current on Line.sections whose line types have no drag"),
    (Model(UniformLine(**ROPE, drag=(1025.0, 1.0, 0.1)), End.anchor((0.0, 0.0, 0.0)),
           End.anchor((60.0, 0.0, 30.0)),
           Environment(surface=10.0, current=[[0.0, 0.5, 0.0, 0.0], [50.0, 0.1, 0.0, 0.0]])),
     "Environment.surface 10: the held end at z = 30 m is above it"),
    (Model(UniformLine(**dict(ROPE, load=(0.0, 0.0, -1e29))), End.anchor((0.0, 0.0, 0.0)),
           End.anchor((60.0, 0.0, 30.0))),
     "UniformLine.load (with Line.length): the applied force"),
    (Model(UniformLine(**ROPE, axial_stiffness=100.0), End.anchor((0.0, 0.0, 0.0)),
           End.anchor((60.0, 0.0, 30.0))),
     "UniformLine.axial_stiffness 100: hanging in tension it stretches the line by about "
     "165 % or more"),
])
def test_the_model_refuses_the_loads_it_derives_before_a_scene_is_compiled(model, words):
    """Model.check holds the checks of the loads the model derives (model/derived.py):
    a taut line, a default seabed stiffness without a weight, a seabed too stiff, a
    current on line types without drag, a uniform line above the surface, an applied
    force beyond the bound of the model's numbers, a stretch beyond the model of
    stretch; the compile refuses them the same."""
    with pytest.raises(RodInputError) as refused:
        model.check()
    assert words in str(refused.value), str(refused.value)
    with pytest.raises(RodInputError) as compiled:
        compile_scene(model)
    assert str(compiled.value) == str(refused.value)


def test_a_seabed_under_a_line_with_no_load_is_not_bounded_by_its_load():
    """The seabed's largest stiffness is scaled by the line's load (model/sea.py): a
    line with no load has none, and was refused with 'the largest accepted is nan'."""
    model = Model(UniformLine(**dict(ROPE, load=(0.0, 0.0, 0.0))),
                  End.anchor((0.0, 0.0, -30.0)), End.anchor((60.0, 0.0, -10.0)),
                  Environment(seabed=-30.0, seabed_stiffness=1e4))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model.check()
    # the bound of the model's numbers still holds (its range check)
    with pytest.raises(RodInputError, match="seabed_stiffness 1e\\+300: out of range"):
        dataclasses.replace(model, environment=Environment(
            seabed=-30.0, seabed_stiffness=1e300)).check()
    with pytest.raises(RodInputError, match="the largest accepted is 100 N/m"):
        Model(UniformLine(**dict(ROPE, load=(0.0, 0.0, -1e-10))),
              End.anchor((0.0, 0.0, -30.0)), End.anchor((60.0, 0.0, -10.0)),
              Environment(seabed=-30.0, seabed_stiffness=1e4)).check()


def test_a_line_type_table_s_optional_ca():
    """The column ca (the modes' added-mass coefficient): given, blank ('-', NaN: None,
    -rod_modes_added_mass's) or absent (None); a negative one refused; the API's table
    export keeps it."""
    from petsc_rod.api.model import line_types_table
    from petsc_rod.model import line_types_from_table
    from petsc_rod.tables import read_table
    from petsc_rod.model.line_type import LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL
    base = {"name": ["a", "b"], "od": np.array([0.2, 0.3]), "mass": np.array([60.0, 70.0]),
            "gj": np.array([8e4, 8e4]), "ei": np.array([1e5, 1e5])}
    types = line_types_from_table(base, "t")
    assert types["a"].ca is None and np.isnan(types["a"].section(0, 1, 1025, 9.8).ca)
    types = line_types_from_table(dict(base, ca=np.array([0.7, np.nan])), "t")
    assert types["a"].ca == 0.7 and types["b"].ca is None
    assert types["a"].section(0, 1, 1025, 9.8).ca == 0.7
    with pytest.raises(RodInputError, match="line type a: ca -1 must be a finite"):
        line_types_from_table(dict(base, ca=np.array([-1.0, 1.0])), "t")
    text = line_types_table(list(types.values()))
    again = line_types_from_table(read_table(None, "t", LINE_TYPE_COLUMNS, LINE_TYPE_OPTIONAL,
                                             content=text), "t")
    assert again["a"].ca == 0.7 and again["b"].ca is None
