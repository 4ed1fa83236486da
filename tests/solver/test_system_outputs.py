"""The engineer's outputs of a system (petsc_rod/system/outputs.py, excursions.py,
figures/system.py) on a small symmetric spread of real held lines (HeldLine): a
floater free in x, y and yaw on three lines of 40 elements at 120 degrees, partly on
an elastic seabed 30 m below the fairleads. Serially and under mpiexec -n 2 (the three
lines dealt over the ranks):

(a) each line's summary (largest tension and where, end tensions along the line and on
    the point, touchdown, grounded length) is the single-line solver's (api.solve of the
    same line with its ends held where the system put them);
(b) the watch circle turns with the spread: a heading 120 degrees further gives the
    positions turned by 120 degrees and the same tensions;
(c) the load-excursion curve's slope at rest is the inverse compliance of the body's
    mooring stiffness (SystemSolver.body_stiffness), and its restoring force the load;
(d) the figures are written, non-empty, of their size.
"""

import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.image  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from petsc_rod.api import End, Environment, Model, UniformLine, solve  # noqa: E402
from petsc_rod.figures import system as figures  # noqa: E402
from petsc_rod.model.system import Body, Connection, Point, System, SystemLine  # noqa: E402
from petsc_rod.system.equilibrium import SystemSolver  # noqa: E402
from petsc_rod.system.excursions import load_excursion, watch_circle  # noqa: E402
from petsc_rod.system.held_line import SUMMARY_UNITS, held_lines  # noqa: E402
from petsc_rod.system.outputs import line_summaries, picture, summary_table  # noqa: E402

pytestmark = pytest.mark.solver

TIGHT = {"al_rtol": 1e-12, "al_ctol": 1e-12}
SEABED = -35.0
FREE = [0, 1, 5]                        # x, y, yaw: z, roll and pitch held
DPI = 50
KEEP = os.environ.get("PETSC_ROD_KEEP_FIGURES")     # a folder to look at them in


def the_line(elements=40):
    return UniformLine(length=100.0, stiffness=(1e-2,) * 3, load=(0, 0, -10.0),
                       axial_stiffness=1e5, elements=elements)


def spread():
    """Anchors at 90 m radius on the seabed, fairleads at 5 m radius 5 m below the
    floater's reference point (at the surface)."""
    angle = np.radians([0.0, 120.0, 240.0])
    out = np.stack([np.cos(angle), np.sin(angle), np.zeros(3)], axis=1)
    points = tuple(Point(f"anchor{i}", "fixed", tuple(90.0 * out[i] + (0, 0, SEABED)))
                   for i in range(3))
    lines = tuple(SystemLine(f"line{i}", the_line(), Connection(f"anchor{i}"),
                             Connection("floater", tuple(5.0 * out[i] + (0, 0, -5.0))))
                  for i in range(3))
    body = Body("floater", mass=1e3, volume=1.0, held=(False, False, True, True, True, False))
    return System(lines=lines, points=points, bodies=(body,),
                  environment=Environment(seabed=SEABED))


@pytest.fixture(scope="module")
def solver():
    system = spread()
    solver = SystemSolver(system, held_lines(system, {**TIGHT, "al_stability": 0}),
                          PETSc.COMM_WORLD)
    solver.solve()
    yield solver
    solver.destroy()


def test_each_line_reports_what_the_single_line_solver_does(solver):
    """Under a load off the lines' headings every line stands differently; each line's
    summary against api.solve of the same line between the same held points."""
    base = solver.system
    from petsc_rod.system.excursions import loaded
    solver.solve(loaded(base, "floater", np.array([30.0, 12.0, 0.0])))
    try:
        summaries = line_summaries(solver)
        ends = solver.end_positions(solver.state)
    finally:
        solver.solve(base)
    assert len({round(s["max_tension"], 3) for s in summaries}) == 3
    for summary, (start, end) in zip(summaries, ends):
        assert set(summary) == set(SUMMARY_UNITS)
        model = Model(line=the_line(), start=End.anchor(tuple(start)),
                      end=End.anchor(tuple(end)), environment=Environment(seabed=SEABED),
                      options=TIGHT)
        single = solve(model, comm=PETSc.COMM_WORLD)
        tension = single.along_line(["effective_tension", "S"])
        k = int(np.argmax(tension["effective_tension"]))
        assert summary["max_tension"] == pytest.approx(tension["effective_tension"][k],
                                                       rel=1e-8)
        assert summary["max_tension_S"] == pytest.approx(tension["S"][k], abs=1e-9)
        assert summary["start_tension"] == pytest.approx(tension["effective_tension"][0],
                                                         rel=1e-8)
        assert summary["end_tension"] == pytest.approx(tension["effective_tension"][-1],
                                                       rel=1e-8)
        assert summary["start_force"] == pytest.approx(
            np.linalg.norm(single.scalars["start_force"]), rel=1e-8)
        assert summary["end_force"] == pytest.approx(
            np.linalg.norm(single.scalars["end_force"]), rel=1e-8)
        assert 40.0 < summary["grounded_length"] < 70.0             # partly grounded
        assert summary["grounded_length"] == pytest.approx(single.scalars["grounded_length"],
                                                           rel=1e-7)
        assert summary["touchdown_S"] == pytest.approx(single.scalars["touchdown_S"],
                                                       rel=1e-7)
        assert summary["touchdown_position"] == pytest.approx(
            single.scalars["touchdown_position"], abs=1e-6)
        assert summary["touchdown_position"][2] == pytest.approx(SEABED, abs=1e-6)
        # on a pinned end the tension along the line and the force on the point differ
        # only by the end element's shear: nothing here (EI is tiny)
        assert summary["end_force"] == pytest.approx(summary["end_tension"], rel=1e-6)
    table = summary_table(solver.system, summaries)
    assert list(table["line"]) == ["line0", "line1", "line2"]
    assert table["max_tension"] == pytest.approx([s["max_tension"] for s in summaries])


def turned(offset, degrees):
    angle = np.radians(degrees)
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]]) @ offset


@pytest.fixture(scope="module")
def circle(solver):
    return watch_circle(solver, "floater", 50.0, [10.0, 130.0, 250.0])


@pytest.fixture(scope="module")
def curves(solver):
    """0.05 N each way (1 mm of offset), then 20 and 40 N."""
    return load_excursion(solver, "floater", [0.05, 20.0, 40.0], headings=[0.0, 180.0])


def test_the_watch_circle_turns_with_the_spread(solver, circle):
    offsets = circle.offsets
    assert np.linalg.norm(offsets[0]) > 0.5                          # it moved
    assert circle.rest == pytest.approx(np.zeros(6), abs=1e-7)
    for k in (1, 2):
        assert np.abs(offsets[k] - turned(offsets[0], 120.0 * k)).max() < 1e-7
        assert circle.poses[k, 5] == pytest.approx(circle.poses[0, 5], abs=1e-10)
        assert circle.max_tension[k] == pytest.approx(circle.max_tension[0], rel=1e-9)
        assert circle.min_grounded[k] == pytest.approx(circle.min_grounded[0], rel=1e-8)
        # the line pulled hardest turns with the load
        assert circle.max_tension_line[k] == (circle.max_tension_line[0] + k) % 3
    tension, heading, line = circle.largest_tension
    assert tension == circle.max_tension.max() and line in circle.lines
    grounded, _, _ = circle.smallest_grounded
    assert 0.0 < grounded < 55.1
    assert circle.largest_offset == pytest.approx(np.linalg.norm(offsets[0]), rel=1e-7)
    table = circle.table()
    assert list(table) == ["heading", "load", "x_offset", "y_offset", "x", "y", "z", "roll",
                           "pitch", "yaw", "verdict", "lowest_eigenvalue", "max_tension",
                           "max_tension_line", "min_grounded", "min_grounded_line"]
    assert table["yaw"] == pytest.approx(circle.poses[:, 5])
    assert list(table["max_tension_line"]) == [circle.lines[k]
                                               for k in circle.max_tension_line]
    # the solver is left at rest
    assert solver.state.bodies.X[0] == pytest.approx(np.zeros(3), abs=1e-7)


def test_the_load_excursion_slope_at_rest_is_the_mooring_stiffness(solver, curves):
    """The central difference of the curves at 0.05 N each way against the inverse
    compliance of the free degrees of freedom, 1 / (K_ff^-1)_xx, at rest."""
    K = solver.body_stiffness("floater").matrix
    compliance = np.linalg.inv(K[np.ix_(FREE, FREE)])
    # the restoring force is the load, to the system's residual (1e-10 of the largest
    # line force, 470 N)
    assert curves.restoring == pytest.approx(np.tile(curves.loads, (2, 1)), abs=1e-6)
    slope = curves.restoring[:, 0].sum() / curves.offsets[:, 0].sum()
    assert slope == pytest.approx(1.0 / compliance[0, 0], rel=1e-6)
    # further out: the lines pull harder, the windward one lifts off the seabed
    assert np.all(np.diff(curves.offsets, axis=1) > 0)
    assert np.all(np.diff(curves.max_tension, axis=1) > 0)
    assert np.all(np.diff(curves.min_grounded, axis=1) < 0)
    tension, heading, load, line = curves.largest_tension
    assert (tension, load) == (curves.max_tension.max(), 40.0) and line in curves.lines
    grounded, heading, load, line = curves.smallest_grounded
    assert (grounded, load) == (np.nanmin(curves.min_grounded), 40.0)
    table = curves.table()
    assert list(table["heading"]) == [0.0] * 3 + [180.0] * 3
    assert list(table["load"]) == [0.05, 20.0, 40.0] * 2
    assert table["restoring"] == pytest.approx(curves.restoring.ravel())


def png_size(path):
    """(width, height) in pixels of the PNG ``path``."""
    return matplotlib.image.imread(path).shape[1::-1]


def test_the_figures_are_written(solver, circle, curves, shared_tmp):
    drawn = picture(solver)
    curve = curves
    if PETSc.COMM_WORLD.rank != 0:
        assert drawn is None
        return
    assert set(drawn["lines"]) == {"line0", "line1", "line2"}
    for name, r in drawn["lines"].items():
        assert r.shape == (41, 3)
        assert r[0] == pytest.approx(solver.system.node(f"anchor{name[-1]}").position,
                                     abs=1e-9)
    assert drawn["bodies"][0][2].shape == (3, 3) and drawn["seabed"] == SEABED
    made = {"system": (figures.system_figure(**drawn), figures.SIZE),
            "circle": (figures.watch_circle_figure(circle.offsets, circle.headings,
                                                   circle.max_tension, circle.min_grounded,
                                                   circle.load, circle.body),
                       figures.CURVES_SIZE),
            "curves": (figures.excursion_figure(curve.offsets, curve.restoring,
                                                curve.headings, curve.max_tension,
                                                curve.min_grounded, curve.body),
                       figures.CURVES_SIZE)}
    for name, (figure, size) in made.items():
        path = f"{shared_tmp}/{name}.png"
        figure.savefig(path, dpi=DPI)
        if KEEP:
            figure.savefig(f"{KEEP}/{name}.png", dpi=110)
        plt.close(figure)
        assert png_size(path) == (round(size[0] * DPI), round(size[1] * DPI))
        pixels = matplotlib.image.imread(path)[..., :3]
        assert (pixels < 0.9).any(axis=2).mean() > 0.01             # something drawn


def test_a_line_without_a_seabed_reports_no_touchdown():
    """A line hanging between two pins: no touchdown, no grounded length; its largest
    tension at the higher end, the force there; its centreline gathered to the first
    rank of its communicator only."""
    from petsc_rod.system.held_line import HeldLine
    ends = (np.zeros(3), np.array([80.0, 0.0, 20.0]))
    model = Model(line=the_line(), start=End.anchor(tuple(ends[0])),
                  end=End.anchor(tuple(ends[1])), environment=Environment(), options=TIGHT)
    line = HeldLine(model, PETSc.COMM_WORLD, options=TIGHT)
    try:
        assert line.solve(*ends)
        summary = line.summary()
        assert np.isnan(summary["grounded_length"]) and np.isnan(summary["touchdown_S"])
        assert np.all(np.isnan(summary["touchdown_position"]))
        assert summary["max_tension_S"] == 100.0
        assert summary["max_tension_position"] == pytest.approx(ends[1], abs=1e-9)
        assert summary["max_tension"] == pytest.approx(summary["end_force"], rel=1e-6)
        assert summary["start_tension"] < summary["end_tension"] == summary["max_tension"]
        r = line.centreline()
        if PETSc.COMM_WORLD.rank == 0:
            assert r.shape == (41, 3)
            assert r[[0, -1]] == pytest.approx(np.array(ends), abs=1e-9)
            assert r[:, 2].min() < -5.0                                  # it sags
        else:
            assert r is None
    finally:
        line.destroy()


def test_a_heading_without_an_equilibrium_is_a_gap_in_the_circle():
    """Mock springs that fail beyond a span of 70.5 m (test_system_equilibrium.py): the
    headings that stretch one line alone past it fail, recorded with why, NaN in the
    arrays; the next heading is solved from the last equilibrium as if they had not
    been asked, and equals the circle without the limit. Lines without a summary
    report no tension."""
    from test_system_equilibrium import spread as spring_spread, spring
    from petsc_rod.system.equilibrium import Settings
    headings = [0.0, 60.0, 120.0, 180.0]
    circles = []
    for limit in (1e9, 70.5):
        mocks = SystemSolver(spring_spread(limit=limit), spring, PETSc.COMM_SELF,
                             settings=Settings(max_halvings=3))
        try:
            circles.append(watch_circle(mocks, "floater", 1e6, headings))
        finally:
            mocks.destroy()
    free, limited = circles
    assert free.failed == () and np.all(np.isfinite(free.offsets))
    assert [case[:2] for case in limited.failed] == [(60.0, 1e6), (180.0, 1e6)]
    assert "line line2 did not converge" in limited.failed[0][2]
    assert np.all(np.isnan(limited.offsets[[1, 3]]))
    assert limited.offsets[[0, 2]] == pytest.approx(free.offsets[[0, 2]], abs=1e-9)
    assert np.abs(free.offsets[2] - turned(free.offsets[0], 120.0)).max() < 1e-9
    assert limited.largest_offset == pytest.approx(np.linalg.norm(free.offsets[0]))
    assert np.all(np.isnan(free.max_tension)) and np.all(free.max_tension_line == -1)
    assert free.largest_tension[2] is None
    assert list(limited.table()["max_tension_line"]) == [""] * 4
