"""petsc_rod/api in the process, on the ranks pytest runs on: a small riser of two line
types with a flex joint, an attachment, a current profile and a seabed; the numbers the
same on one rank and on all, the arrays gathered in order, the units, the result file
written alongside with the same numbers, and a bad model refused as the command line
refuses it."""

import h5py
import numpy as np
import pytest
from petsc4py import PETSc

from petsc_rod.api import Attachment, End, Environment, Line, LineType, Model, solve
from petsc_rod.errors import RodInputError

pytestmark = pytest.mark.solver

PIPE = LineType("pipe", od=0.2, mass=60.0, ei=1e5, gj=8e4, cd=1.0)
FLOATY = LineType("floaty", od=0.5, mass=170.0, ei=1e5, gj=8e4, cd=1.0, drag_d=0.45)


def model(**change):
    line = Line([(PIPE, 60.0), (FLOATY, 30.0), (PIPE, 70.0)], element_length=2.0)
    sea = Environment(seabed=0.0, surface=60.0,
                      current=[[0.0, 0.4, 0.1, 0.0], [60.0, 0.1, 0.0, 0.0]])
    fields = dict(line=line, start=End.anchor((0.0, 0.0, 0.0)),
                  end=End.hang_off((100.0, 0.0, 55.0), flex_joint=1e4, axis=(0, 0, 1)),
                  environment=sea, attachments=(Attachment(100.0, mass=200.0, name="clump"),),
                  steps=2, initial_shape="straight")
    fields.update(change)
    return Model(**fields)


def test_one_rank_and_all_give_the_same_numbers():
    comm = PETSc.COMM_WORLD
    alone = solve(model(), comm=PETSc.COMM_SELF)
    together = solve(model(), comm=comm)
    assert alone.converged and together.converged
    for name in ("top_tension", "top_angle", "touchdown_S", "min_bend_radius",
                 "end_joint_angle"):
        assert together.scalars[name] == pytest.approx(alone.scalars[name], rel=1e-8), name
    assert alone.units["top_tension"] == "N" and alone.units["touchdown_S"] == "m"
    assert alone.units["effective_tension"] == "N" and alone.units["r"] == "m"
    line = together.along_line(["S", "r", "effective_tension"])
    assert line["S"].shape == (81,) and np.all(np.diff(line["S"]) > 0)
    assert line["r"][-1] == pytest.approx([100.0, 0.0, 55.0], abs=1e-6)
    # the current pushes the line along +y, the clump weighs on it
    assert line["r"][:, 1].max() > 0.1
    assert together.scalars["point_load_force"][0][2] == pytest.approx(
        -200.0 * 9.80665, rel=1e-12)
    local = alone.along_line()
    assert set(local) == set(alone.owned)
    assert "top tension" in alone.summary()[1]


def test_the_result_file_holds_the_same_numbers(tmp_path):
    comm = PETSc.COMM_WORLD
    folder = comm.tompi4py().bcast(str(tmp_path))
    path = f"{folder}/api.h5"
    results = solve(model(steps=1), comm=comm, output=path)
    with h5py.File(path, "r") as f:
        assert int(f.attrs["converged"]) == 1
        assert float(f.attrs["top_tension"]) == results.top_tension
        assert "floaty" in f["parameters"].attrs["line_types_table"]
        S = f["S"][:]
    assert S.shape == (81,)


def test_a_bad_model_is_refused_as_the_command_line_refuses_it():
    with pytest.raises(RodInputError, match="beyond the line"):
        solve(model(attachments=(Attachment(500.0, mass=1.0),)))
    bad = LineType("bad", od=0.2, mass=60.0, ei=-1.0, gj=8e4)
    with pytest.raises(RodInputError, match="must be positive"):
        solve(model(line=Line([(bad, 100.0)])))


def test_a_model_written_as_options_reads_back_as_the_same_scene(tmp_path):
    """Model.write_options: the options file and its tables make, through the command
    line's own reading, the scene the model makes."""
    from petsc_rod.api import scene_of
    from petsc_rod.cli.options import parse_values
    from petsc_rod.cli.scene_options import scene_from_options

    path = tmp_path / "model.opts"
    model().write_options(path)
    texts = {}
    for line in path.read_text().splitlines():
        if line.startswith("-"):
            name, text = line[1:].split(" ", 1)
            texts[name] = text
    from_file = scene_from_options(parse_values(texts), set(texts))
    scene, _, _ = scene_of(model())
    assert from_file.length == scene.length and len(from_file.sections) == 3
    for a, b in zip(from_file.sections, scene.sections):
        assert (a.name, a.start, a.end, a.drag, a.od) == (b.name, b.start, b.end, b.drag, b.od)
        assert np.array_equal(a.weight, b.weight)
        assert np.array_equal(a.stiffness_start, b.stiffness_start)
    assert np.array_equal(from_file.point_load_forces, scene.point_load_forces)
    assert np.array_equal(from_file.current.velocities, scene.current.velocities)
    assert from_file.current.drag == scene.current.drag


def test_an_option_the_model_gives_is_refused_in_its_options():
    with pytest.raises(RodInputError, match="Model.options 'initial'"):
        model(options={"initial": "run.h5"}).option_texts()
    with pytest.raises(RodInputError, match="Model.options 'seabed'"):
        model(options={"seabed": 1.0}).option_texts()
    texts = model(options={"al_rtol": 1e-10, "al_stability": False}).option_texts()
    assert texts["rod_al_rtol"] == "1e-10" and texts["rod_al_stability"] == "0"


def test_the_seabed_friction_of_the_environment_reaches_the_options_and_the_line():
    """Environment.seabed_friction (one coefficient, or axial and lateral) and its stick
    stiffness become -rod_seabed_friction and -rod_seabed_friction_stiffness; solved, the
    grounded line's friction is reported (docs/riser.md §3b)."""
    sea = Environment(seabed=0.0, surface=60.0, current=[0.0, 0.3, 0.0],
                      seabed_friction=(0.4, 0.6), seabed_friction_stiffness=2e4)
    texts = model(environment=sea).option_texts()
    assert texts["rod_seabed_friction"] == "0.4,0.6"
    assert float(texts["rod_seabed_friction_stiffness"]) == 2e4
    results = solve(model(environment=sea),
                    comm=PETSc.COMM_WORLD)
    assert results.converged
    grounded = results.scalars["grounded_length"]
    assert grounded > 1.0
    assert (results.scalars["friction_stick_length"] + results.scalars["friction_slide_length"]
            == pytest.approx(grounded, abs=2 * 2.0))
    assert results.scalars["friction_max_use"] <= 1.0 + 1e-12
    assert results.units["friction_force"] == "N/m"


# --- hostile models (issue 47): one RodInputError, on every rank, before any work -------
NOT_A_MODEL = {
    "element length 0": lambda: model(line=Line([(PIPE, 160.0)], element_length=0)),
    "element length -5": lambda: model(line=Line([(PIPE, 160.0)], element_length=-5)),
    "element length nan": lambda: model(line=Line([(PIPE, 160.0)],
                                                  element_length=float("nan"))),
    "element length as text": lambda: model(line=Line([(PIPE, 160.0)], element_length="2")),
    "a section length as text": lambda: model(line=Line([(PIPE, "160")])),
    "a force of two numbers": lambda: model(attachments=(Attachment(50.0, force=(0, -1)),)),
    "an end force of two numbers": lambda: model(end=End("free", force=(1.0, 2.0))),
    "a nan position": lambda: model(end=End.hang_off((100.0, float("nan"), 55.0))),
    "an attachment at S given as text": lambda: model(attachments=(Attachment("50"),)),
    "a mass as text": lambda: model(line=Line([(LineType("p", od=0.2, mass="60", ei=1e5,
                                                          gj=8e4), 160.0)])),
    "a ragged current profile": lambda: model(environment=Environment(
        current=[[0.0, 0.4, 0.1, 0.0], [60.0, 0.1]])),
    "a misspelt option": lambda: model(options={"al_max_itt": 1}),
    "a solver option the API cannot set": lambda: model(options={"newton_pc_type": "lu"}),
    "steps as a fraction": lambda: model(steps=2.5),
    "a one-element mesh": lambda: model(line=Line([(PIPE, 60.0), (FLOATY, 30.0),
                                                   (PIPE, 70.0)], element_length=500.0)),
}
NOT_A_MODEL_WORDS = {"element length 0": "Line.element_length 0: must be a positive",
                     "element length -5": "Line.element_length -5: must be a positive",
                     "a force of two numbers": "Attachment.force (0, -1): expected 3",
                     "a misspelt option": "did you mean 'al_max_it'",
                     "a one-element mesh": "cannot represent the line"}


@pytest.mark.parametrize("case", list(NOT_A_MODEL))
def test_a_model_that_cannot_be_is_refused_with_rod_input_error(case):
    with pytest.raises(RodInputError) as error:
        solve(NOT_A_MODEL[case]())
    assert NOT_A_MODEL_WORDS.get(case, "") in str(error.value)


@pytest.mark.parametrize("change", ["element_length", "attachment", "option"])
def test_models_that_differ_between_ranks_are_refused_on_every_rank(change):
    """An answer of neither model (an attachment of another mass), or MPI_ABORT in the
    first collective call (other element lengths): now one RodInputError everywhere."""
    mpi = PETSc.COMM_WORLD.tompi4py()
    if mpi.Get_size() == 1:
        pytest.skip("needs 2 ranks")
    other = mpi.Get_rank() == mpi.Get_size() - 1
    fields = {"element_length": dict(line=Line([(PIPE, 60.0), (FLOATY, 30.0), (PIPE, 70.0)],
                                               element_length=3.0 if other else 2.0)),
              "attachment": dict(attachments=(Attachment(100.0, mass=300.0 if other
                                                         else 200.0),)),
              "option": dict(options={"al_rtol": 1e-9 if other else 1e-10})}[change]
    with pytest.raises(RodInputError, match=f"rank {mpi.Get_size() - 1} was given another "
                                            "model than rank 0"):
        solve(model(**fields))


@pytest.mark.parametrize("change, words", [
    (dict(line=Line([(PIPE, 160.0)], internal_pressure=1e6)),
     "Line.internal_pressure needs a line type with an id"),
    (dict(end=End.hang_off((300.0, 0.0, 55.0))), "Model.end.position: the ends are"),
    (dict(start=End.anchor((0.0, 0.0, -1.0))), "Model.start: the end is held at z = -1 m"),
    (dict(line=Line([(LineType("soft", od=0.2, mass=60.0, ei=1e-300, gj=8e4), 160.0)])),
     "the LineTypes: line type soft: ei 1e-300"),
])
def test_a_refusal_names_the_model_s_fields_not_options(change, words):
    """The model's checks are the command line's; their messages name what the caller
    gave (Line.internal_pressure), not options it never saw (-rod_internal_pressure)."""
    with pytest.raises(RodInputError) as error:
        solve(model(**change))
    assert words in str(error.value) and "-rod_" not in str(error.value), str(error.value)


def test_the_seabed_s_shape_is_the_environment_s_own_or_its_options():
    """Issue 48: the model's Environment holds the seabed's slope, direction and origin
    (they were only Model.options); either way the same scene."""
    from petsc_rod.api import scene_of
    by_options, _, _ = scene_of(model(environment=Environment(seabed=0.0, surface=60.0),
                                      options={"seabed_slope": 2.0,
                                               "seabed_direction": 30.0}))
    own, _, _ = scene_of(model(environment=Environment(
        seabed=0.0, surface=60.0, seabed_slope=2.0, seabed_direction=30.0)))
    assert not own.seabed.flat and own.seabed.height == by_options.seabed.height
    assert np.array_equal(own.seabed.shape.slope_vector, by_options.seabed.shape.slope_vector)
    assert own.seabed.shape.slope_vector[1] > 0
    with pytest.raises(RodInputError, match="Environment.seabed_slope 95.0: must lie"):
        scene_of(model(environment=Environment(seabed=0.0, seabed_slope=95.0)))
def test_a_stability_test_asked_with_a_current_is_refused():
    """Model.options al_stability True beside the model's current (a drag without an
    energy) is refused as the command line refuses -rod_al_stability 1 with it."""
    with pytest.raises(RodInputError, match="a current has none") as refused:
        solve(model(options={"al_stability": True}))
    assert "al_stability" in str(refused.value) and "Environment.current" in str(refused.value)


def test_a_stability_test_asked_on_a_sloping_seabed_names_the_apis_switch():
    """One check decides whether a stability verdict is possible: on a seabed profile
    without a current (its lagged contact force has no energy; a plane's has one) the
    API's refusal names the API's switch, as it names the current by the model's field."""
    rise = np.tan(np.radians(2.0))
    sea = Environment(surface=60.0, seabed_profile=((-1000.0, -1000.0 * rise),
                                                   (10000.0, 10000.0 * rise)))
    with pytest.raises(RodInputError, match="a seabed that is not flat") as refused:
        solve(model(environment=sea, options={"al_stability": True}))
    assert str(refused.value).startswith("Model.options['al_stability'] 1: ")
    assert "drop Model.options['al_stability']" in str(refused.value)


def test_a_uniform_line_is_a_model_too(tmp_path):
    """Issue 48: the API is the model, both its lines: a uniform cantilever (the command
    line's -rod_stiffness, -rod_load) solves to the small-deflection tip w L^4 / 8 EI, and
    its exported options make the command line's scene of it."""
    from petsc_rod.api import UniformLine, scene_of
    from petsc_rod.cli.options import parse_values
    from petsc_rod.cli.scene_options import scene_from_options
    cantilever = Model(UniformLine(length=1.0, stiffness=(1.0, 1.0, 1.0),
                                   load=((0.0, 0.0, -0.01),), elements=16),
                       start=End("clamp"), end=End("free"), initial_shape="straight")
    results = solve(cantilever, comm=PETSc.COMM_WORLD)
    assert results.converged
    tip = results.along_line(["r"])["r"][-1]
    assert tip[2] == pytest.approx(-0.01 / 8.0, rel=1e-3)
    folder = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path))
    path = f"{folder}/cantilever.opts"
    if PETSc.COMM_WORLD.getRank() == 0:
        cantilever.write_options(path)
    PETSc.COMM_WORLD.tompi4py().Barrier()
    texts = dict(line[1:].split(" ", 1) for line in open(path).read().splitlines()
                 if line.startswith("-"))
    from_file = scene_from_options(parse_values(texts), set(texts))
    scene, _, _ = scene_of(cantilever)
    assert from_file.length == scene.length and from_file.end == scene.end == "free"
    assert np.array_equal(from_file.load_values, scene.load_values)
    assert np.array_equal(from_file.stiffness, scene.stiffness)


@pytest.mark.parametrize("options, ends, words", [
    ({"end_twist": 0.5}, dict(end=End("pin", (100.0, 0.0, 55.0))),
     "Model.options['end_twist'] needs Model.end clamp"),
    ({"end_twist": "half a turn"}, {}, "Model.options['end_twist'] 'half a turn'"),
    ({"start_position": [0.0, 0.0, 1.0]}, dict(start=End("free")),
     "Model.options['start_position'] needs a held start"),
    ({"start_position": [0.0, 0.0, float("nan")]}, dict(start=End("pin")),
     "Model.options['start_position'] '0.0,0.0,nan'"),
    ({"end_force": [1.0, 0.0, 0.0]}, {}, "Model.options['end_force'] needs Model.end free"),
])
def test_a_bad_value_of_model_options_is_named_as_model_options(options, ends, words):
    """A value given through Model.options is refused naming that option
    (Model.options['end_twist']), not the model field it sets (Model.end.twist), which
    the caller never gave, nor the command line's -rod_end_twist."""
    with pytest.raises(RodInputError) as error:
        solve(model(options=options, **ends))
    message = str(error.value)
    assert words in message, message
    assert "-rod_" not in message and "Model.end.twist" not in message
    assert "Model.start.position" not in message and "Model.end.force" not in message


def test_the_api_records_its_run_from_the_model_without_option_text(tmp_path, monkeypatch):
    """Issue 48, the API is the model: its run reads no option text (Model.option_texts,
    the export, is not called), and its result file records the whole model, here 80
    sections (a -rod_sections of more than 1023 characters, petsc4py's cut of an option's
    value) and 30 attachments."""
    def no_text(*args, **kwargs):
        raise AssertionError("the run read the model's option texts")

    monkeypatch.setattr(Model, "option_texts", no_text)
    lengths = 2.0 + 1e-3 * np.arange(80) / 7.0
    line = Line([(PIPE if k % 2 else FLOATY, length) for k, length in enumerate(lengths)],
                element_length=1.0)
    S = 2.5 + 5.0 * np.arange(30)
    attachments = tuple(Attachment(s, mass=10.0 + k, name=f"clump {k}")
                        for k, s in enumerate(S))
    comm = PETSc.COMM_WORLD
    path = f"{comm.tompi4py().bcast(str(tmp_path))}/long.h5"
    results = solve(model(line=line, attachments=attachments, steps=1), comm=comm,
                    output=path)
    assert results.converged and results.elements == 160
    with h5py.File(path, "r") as f:
        parameters = f["parameters"].attrs
        sections = str(parameters["sections"])
        table = np.asarray(parameters["point_loads_table"])
        assert int(parameters["elements"]) == 160
    assert len(sections) > 1023 and sections.count(",") == 79
    recorded = [float(entry.split(":")[1]) for entry in sections.split(",")]
    assert np.array_equal(recorded, lengths)
    assert table.shape[0] == 30 and np.array_equal(table[:, 0], S)
    assert table[-1, 3] == pytest.approx(-39.0 * 9.80665, rel=1e-12)


def test_the_api_returns_the_modes_the_command_line_tabulates(tmp_path):
    """Model.options['modes'] on a uniform cantilever: api.solve, with no result file,
    returns the modes (Results.modes) the command line's -rod_modes_table gives for the
    same line (frequencies, periods, modal masses to 10 digits, classes, shares), the
    lowest the closed form's beta^2 / (2 pi L^2) sqrt(EI / m); no refusal."""
    pytest.importorskip("slepc4py")
    from helpers import run_cli

    from petsc_rod.api import UniformLine
    EI, m = 2.0, 3.0
    cantilever = Model(UniformLine(length=1.0, stiffness=(EI, EI, EI), elements=16),
                       start=End("clamp"), end=End("free"), initial_shape="straight",
                       options={"modes": 4, "modes_mass": m})
    results = solve(cantilever, comm=PETSc.COMM_WORLD)
    modes = results.modes
    assert results.modes_refused is None and len(modes.frequencies) == 4
    folder = PETSc.COMM_WORLD.tompi4py().bcast(str(tmp_path))
    path = f"{folder}/modes.csv"
    assert run_cli({"rod_length": "1", "rod_stiffness": f"{EI},{EI},{EI}",
                    "rod_start": "clamp", "rod_end": "free", "rod_elements": "16",
                    "rod_modes": "4", "rod_modes_mass": str(m),
                    "rod_modes_table": path, "rod_ranks_split": "split"}) == 0
    table = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding=None)
    assert np.allclose(modes.frequencies, table["frequency_Hz"], rtol=1e-9)
    assert np.allclose(modes.periods, table["period_s"], rtol=1e-9)
    assert np.allclose(modes.modal_mass, table["modal_mass_kg"], rtol=1e-9)
    assert list(modes.labels) == list(table["class"])
    shares = np.column_stack([table[name] for name in table.dtype.names
                              if name.startswith("share_")])
    assert np.allclose(modes.shares, shares, atol=1e-6)
    assert modes.frequencies[0] == pytest.approx(
        1.8751040687**2 / (2 * np.pi) * np.sqrt(EI / m), rel=1e-4)
    assert modes.offset.shape == (4, len(results.owned["S"]), 3)


def test_the_api_returns_why_the_modes_were_refused(monkeypatch):
    """Modes refused (an unstable state, here its inertia's count stood in for): api.solve
    with no say returns the reason (Results.modes_refused) and no modes."""
    pytest.importorskip("slepc4py")
    from petsc_rod.analysis.modes import ModesRefused
    from petsc_rod.api import UniformLine
    from petsc_rod.cli import modes

    def refused(*args):
        raise ModesRefused(2)
    monkeypatch.setattr(modes, "solve_modes", refused)
    cantilever = Model(UniformLine(length=1.0, stiffness=(2.0, 2.0, 2.0), elements=8),
                       start=End("clamp"), end=End("free"), initial_shape="straight",
                       options={"modes": 2, "modes_mass": 3.0})
    results = solve(cantilever, comm=PETSc.COMM_WORLD)
    assert results.modes is None
    assert "unstable (2 negative eigenvalues" in results.modes_refused
