"""The command line's sweeps of a system (petsc_rod/api/system_sweeps.py): the options'
parsing and refusals, and a case without an equilibrium left out of the file's group and
of the table (no NaN written), listed with its reason; figures/read_system.sweep puts
the gap back in the curves' grid."""

import h5py
import numpy as np
import pytest

from petsc_rod.api.system_sweeps import file_group, parse_sweeps, run_lines, table_text
from petsc_rod.errors import RodInputError
from petsc_rod.figures.read_system import sweep
from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.system.excursions import UNITS, LoadExcursion, WatchCircle

LINES = ("Line1", "Line2", "Line3")


def worst(shape, failed_index):
    """Worst's arrays of ``shape``: NaN and -1 at the failed case ``failed_index``."""
    tension = np.arange(1.0, np.prod(shape) + 1).reshape(shape) * 1e3
    grounded = 50.0 - np.arange(np.prod(shape)).reshape(shape)
    line = np.arange(np.prod(shape)).reshape(shape) % 3
    tension[failed_index], grounded[failed_index] = np.nan, np.nan
    line = np.where(np.isnan(tension), -1, line)
    return dict(max_tension=tension, max_tension_line=line, min_grounded=grounded,
                min_grounded_line=line.copy(), rest=np.zeros(6), lines=LINES, units=UNITS)


def a_watch_circle():
    headings = np.array([0.0, 120.0, 240.0])
    poses = np.array([[2.0, 0, 0, 0, 0, 0], [np.nan] * 6, [-1.0, -1.7, 0, 0, 0, 0]])
    return WatchCircle(body="Body1", headings=headings, poses=poses,
                       failed=((120.0, 5e3, "line Line2 did not converge"),),
                       **worst((3,), 1), load=5e3, offsets=poses[:, :2])


def test_a_case_without_an_equilibrium_is_left_out_and_listed(tmp_path):
    circle = a_watch_circle()
    data, attributes, units = file_group(circle)
    assert data["heading"].tolist() == [0.0, 240.0]
    assert all(np.all(np.isfinite(value)) for value in data.values())
    assert data["failed_heading"].tolist() == [120.0]
    assert data["failed_load"].tolist() == [5e3]
    assert "Line2 did not converge" in attributes["failed"]
    # a sweep with a case left without an equilibrium did not converge as a whole
    assert attributes["converged"] == 0 and attributes["saddles"] == 0
    assert data["max_tension_line"].tolist() == [0.0, 2.0]
    assert attributes["largest_tension"] == 3e3 and attributes["smallest_grounded"] == 48.0
    assert attributes["largest_offset"] == 2.0         # heading 0 (1.97 m at 240)
    assert units["x_offset"] == "m" and units["max_tension"] == "N"
    rows = table_text(circle).splitlines()
    assert len(rows) == 3 and rows[2].startswith("240,5000,-1,-1.7,")
    assert rows[1].split(",")[-1] == "Line1" and "nan" not in table_text(circle).lower()
    said = run_lines({"watch_circle": circle})
    assert "largest tension 3000 N (heading 240 deg, Line3)" in said[0]
    assert said[1].startswith("petsc_rod: warning: watch circle: no equilibrium at heading "
                              "120 deg")


def test_the_curves_grid_gets_its_gap_back(tmp_path):
    headings, loads = np.array([0.0, 90.0]), np.array([0.0, 1e3, 2e3])
    poses = np.zeros((2, 3, 6))
    poses[1, 2] = np.nan
    offsets = np.array([[0.0, 1.0, 2.0], [0.0, 0.5, np.nan]])
    curves = LoadExcursion(body="Body1", headings=headings, poses=poses,
                           failed=((90.0, 2e3, "too far"),), **worst((2, 3), (1, 2)),
                           loads=loads, offsets=offsets, restoring=offsets * 1e3)
    data, attributes, units = file_group(curves)
    assert data["offset"].size == 5 and "largest_offset" not in attributes
    with h5py.File(tmp_path / "s.h5", "w") as f:
        group = f.create_group("excursion")
        for name, value in data.items():
            group.create_dataset(name, data=value)
        for name, value in attributes.items():
            group.attrs[name] = value
        found = sweep(group)
    assert np.array_equal(found["grid_offset"], offsets, equal_nan=True)
    assert found["grid_headings"].tolist() == [0.0, 90.0]


def test_the_options_are_parsed_and_refused_in_one_line():
    system, _ = read_moordyn("tests/data/moordyn/small_free_body.dat")
    found = parse_sweeps("Body1,2e4", "Body1,3e4,3,0,90", system)
    body, load, headings = found.watch_circle
    assert (body, load, headings.size, headings[1]) == ("Body1", 2e4, 24, 15.0)
    body, loads, headings = found.excursion
    assert loads.tolist() == [0.0, 1e4, 2e4, 3e4] and headings.tolist() == [0.0, 90.0]
    assert not parse_sweeps(None, None, system)
    for circle, curves, word in (("Body2,1e3", None, "Body2"), ("Body1,0", None, "'0'"),
                                 ("Body1,1e3,0", None, "'0'"), ("Body1", None, "LOAD"),
                                 (None, "Body1,1e3,2,east", "'east'"),
                                 (None, "Body1,inf", "'inf'")):
        with pytest.raises(RodInputError, match=word):
            parse_sweeps(circle, curves, system)


def test_a_sweep_of_a_body_held_where_its_load_pushes_is_refused():
    """The coupled body of small_spread.dat: the options and the API's Sweeps refused in
    one line naming the body and the axes (a held body's offsets are all 0 m); a body
    held in x alone is swept along y (heading 90 deg: cos 90 deg, 6e-17, pushes nothing
    along x) and at 45 deg (it moves along y), refused at 0 and 180 deg alone; the free
    body of small_free_body.dat is swept."""
    import dataclasses
    from petsc_rod.api import Sweeps
    from petsc_rod.api.system_sweeps import check_sweeps
    from petsc_rod.system.excursions import held_text
    held, _ = read_moordyn("tests/data/moordyn/small_spread.dat")
    why = ("body Body1 is held in {} (Coupled, CoupledPinned or Fixed in a MoorDyn file; "
           "Body.held): its position there is imposed, so the load moves it at no heading "
           "and every offset would be 0 m; sweep a body free where the load pushes it (Free "
           "in the file)")
    with pytest.raises(RodInputError) as refused:
        parse_sweeps("Body1,1e5", None, held)
    assert str(refused.value) == ("-rod_system_watch_circle 'Body1,1e5': "
                                  + why.format("x and y"))
    with pytest.raises(RodInputError) as refused:
        parse_sweeps(None, "Body1,1e5,2,0", held)
    assert str(refused.value) == "-rod_system_excursion 'Body1,1e5,2,0': " + why.format("x")
    with pytest.raises(RodInputError) as refused:
        check_sweeps(Sweeps(excursion=("Body1", [0.0, 1e5], [0.0, 90.0])), held)
    assert str(refused.value) == "Sweeps.excursion: " + why.format("x and y")
    with pytest.raises(RodInputError, match="Sweeps.watch_circle: no body 'Body2'"):
        check_sweeps(Sweeps(watch_circle=("Body2", 1e5, [0.0])), held)
    with pytest.raises(RodInputError, match=r"Sweeps.watch_circle: expected \(body name"):
        check_sweeps(Sweeps(watch_circle=("Body1", 1e5)), held)
    free, _ = read_moordyn("tests/data/moordyn/small_free_body.dat")
    # the numbers parse_sweeps would refuse on the command line, refused by name
    for kind, bad in (("watch_circle", ("Body1", "big", [0.0])),
                      ("watch_circle", ("Body1", -1e5, [0.0])),
                      ("watch_circle", ("Body1", 1e5, None)),
                      ("watch_circle", ("Body1", 1e5, [np.nan])),
                      ("watch_circle", ("Body1", 1e5, 4)),
                      ("watch_circle", ("Body1", 1e5, [])),
                      ("excursion", ("Body1", [0.0, -1e5], [0.0])),
                      ("excursion", ("Body1", 1e5, [0.0])),
                      ("excursion", ("Body1", [0.0, np.inf], [0.0]))):
        with pytest.raises(RodInputError, match=rf"^Sweeps.{kind}: expected \(body name"):
            check_sweeps(Sweeps(**{kind: bad}), free)
    body = dataclasses.replace(held.bodies[0], held=(True,) + (False,) * 5)
    assert held_text(body, [90.0, 270.0]) == ""
    assert held_text(body, [90.0, 45.0]) == held_text(body, [0.0, 90.0]) == ""
    assert held_text(body, [0.0, 180.0]) == why.format("x")
    check_sweeps(Sweeps(watch_circle=("Body1", 1e5, np.arange(0.0, 360.0, 15.0))), free)
    assert parse_sweeps("Body1,1e5", "Body1,1e5", free)


def test_a_saddle_case_is_marked_in_the_file_the_figure_and_the_page(tmp_path):
    """The curves' case at heading 90 deg, 1 kN, a saddle of the system: kept in the
    file's group (verdict 0, converged 0), crossed in red on the restoring force's
    graph at its point, SADDLE in the report page's table, its words under it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from petsc_rod.figures.read_system import figures
    from petsc_rod.figures.read_system import SystemFile
    from petsc_rod.report.system_page import sweep_html

    headings, loads = np.array([0.0, 90.0]), np.array([0.0, 1e3, 2e3])
    poses = np.zeros((2, 3, 6))
    poses[1, 2] = np.nan
    offsets = np.array([[0.0, 1.0, 2.0], [0.0, 0.5, np.nan]])
    stable = np.array([[1, 1, 1], [1, 0, -1]])
    lowest = np.array([[9.0, 8.0, 7.0], [9.0, -2.0, np.nan]])
    curves = LoadExcursion(body="Body1", headings=headings, poses=poses,
                           failed=((90.0, 2e3, "too far"),), **worst((2, 3), (1, 2)),
                           loads=loads, offsets=offsets, restoring=offsets * 1e3,
                           stable=stable, lowest_eigenvalue=lowest)
    assert curves.saddles() == [(90.0, 1e3)]
    data, attributes, units = file_group(curves)
    assert data["verdict"].tolist() == [1, 1, 1, 1, 0]
    assert data["lowest_eigenvalue"].tolist() == [9.0, 8.0, 7.0, 9.0, -2.0]
    assert attributes["converged"] == 0 and attributes["saddles"] == 1
    assert attributes["system_verdict"] == ("1 saddle(s) of the system: heading 90 deg "
                                            "under 1000 N; 4 stable")
    rows = table_text(curves).splitlines()
    assert rows[5].split(",")[10:12] == ["saddle", "-2"]
    with h5py.File(tmp_path / "s.h5", "w") as f:
        group = f.create_group("excursion")
        group.attrs.update(attributes)
        for name, value in data.items():
            group[name] = value
        found = sweep(group)
    assert np.array_equal(found["grid_verdict"], [[1, 1, 1], [1, 0, np.nan]],
                          equal_nan=True)
    drawn = figures(SystemFile("s.h5", "s", {"lines": {}, "points": [], "bodies": [],
                                             "seabed": None, "surface": 0.0},
                               [], [], None, found, {}))
    marks = [line for line in drawn["_excursion"].axes[0].get_lines()
             if line.get_label() == "saddle of the system"]
    assert len(marks) == 1
    assert marks[0].get_xdata().tolist() == [0.5]
    assert marks[0].get_ydata().tolist() == [0.5]                      # kN
    for figure in drawn.values():
        plt.close(figure)
    page = sweep_html("excursion", found)
    assert "<th>stable</th>" in page and page.count("SADDLE") == 1
    assert "1 saddle(s) of the system: heading 90 deg under 1000 N" in page


def test_a_case_without_a_lowest_eigenvalue_keeps_the_column():
    """One case with an equilibrium but no lowest eigenvalue (its verdict none) among
    cases with one, and a case without an equilibrium: the column kept for every row,
    NaN in the file's dataset and an empty cell in the table at that case; left out
    only where no case has one."""
    circle = a_watch_circle()
    stable, lowest = np.array([1, -1, -1]), np.array([7.5, np.nan, np.nan])
    circle = WatchCircle(body="Body1", headings=circle.headings, poses=circle.poses,
                         failed=circle.failed, **worst((3,), 1), load=5e3,
                         offsets=circle.offsets, stable=stable, lowest_eigenvalue=lowest)
    data, _, units = file_group(circle)
    assert data["lowest_eigenvalue"][0] == 7.5 and np.isnan(data["lowest_eigenvalue"][1])
    assert units["lowest_eigenvalue"] == "N/m"
    rows = [row.split(",") for row in table_text(circle).splitlines()]
    column = rows[0].index("lowest_eigenvalue (N/m)")
    assert [row[column] for row in rows[1:]] == ["7.5", ""]
    assert [row[column - 1] for row in rows[1:]] == ["stable", "none"]
    none = WatchCircle(body="Body1", headings=circle.headings, poses=circle.poses,
                       failed=circle.failed, **worst((3,), 1), load=5e3,
                       offsets=circle.offsets)
    assert "lowest_eigenvalue" not in file_group(none)[0]


def test_a_sweep_with_a_case_without_an_equilibrium_exits_3():
    """The command line's end of a system's run (cli_system.finished_error): a watch
    circle with a heading left without an equilibrium is an incomplete result, exit 3
    (a system without an equilibrium at rest: RodNotConvergedError's) with the last
    line naming the case and the file; with a saddle as well, the saddle's line first,
    exit 3; complete and stable, 0. Before, such a run exited 0 with 'petsc_rod:
    converged'."""
    from types import SimpleNamespace

    from petsc_rod.cli_system import finished_error
    from petsc_rod.errors import RodNotConvergedError

    circle = a_watch_circle()
    said = []
    results = SimpleNamespace(verdict=None, sweeps={"watch_circle": circle})
    assert finished_error(results, said.append, "out.h5") == \
        RodNotConvergedError.exit_code == 3
    assert said == ["petsc_rod: error: the watch circle of Body1 has no equilibrium at 1 of "
                    "3 case(s): heading 120 deg: the sweep is incomplete (its other cases "
                    "written in out.h5, whose system/watch_circle lists the failed ones and "
                    "says converged = 0; a smaller load or more -rod_system_steps may "
                    "reach them)"]
    saddle = WatchCircle(body="Body1", headings=circle.headings, poses=circle.poses,
                         failed=circle.failed, **worst((3,), 1), load=5e3,
                         offsets=circle.offsets, stable=np.array([0, -1, 1]))
    said.clear()
    results = SimpleNamespace(verdict=None, sweeps={"watch_circle": saddle})
    assert finished_error(results, said.append) == 3
    assert len(said) == 2 and "saddle" in said[0] and "no equilibrium" in said[1]
    complete = WatchCircle(body="Body1", headings=circle.headings[[0, 2]],
                           poses=circle.poses[[0, 2]], failed=(), **worst((2,), 0),
                           load=5e3, offsets=circle.offsets[[0, 2]],
                           stable=np.array([1, 1]))
    said.clear()
    results = SimpleNamespace(verdict=None, sweeps={"watch_circle": complete})
    assert finished_error(results, said.append) == 0 and said == []
