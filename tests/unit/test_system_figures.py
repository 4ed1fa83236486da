"""The figures of a system (petsc_rod/figures/system.py) from synthetic arrays: an
array of two floaters on twelve lines (one colour beyond ten), free and prescribed
points, no seabed; the curves' figures with no line on a seabed. Each PNG of its size,
its panels inside the figure and clear of each other and of the title at the fixed
margins (figures/riser.clear)."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.image  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from petsc_rod.figures import style  # noqa: E402
from petsc_rod.figures import system as figures  # noqa: E402
from petsc_rod.figures.riser import clear  # noqa: E402

pytestmark = pytest.mark.unit

DPI = 40


def catenary(start, end, n=30, sag=20.0):
    s = np.linspace(0.0, 1.0, n)[:, None]
    r = (1 - s) * np.asarray(start, float) + s * np.asarray(end, float)
    r[:, 2] -= sag * 4 * s[:, 0] * (1 - s[:, 0])
    return r


def array_of_floaters():
    lines, points, bodies = {}, [], []
    for b, centre in enumerate(((0.0, 0.0), (300.0, 0.0))):
        X = np.array([*centre, 0.0])
        fairleads = []
        for k in range(6):
            angle = np.radians(60.0 * k)
            out = np.array([np.cos(angle), np.sin(angle), 0.0])
            fairlead, anchor = X + 10 * out - (0, 0, 15), X + 150 * out - (0, 0, 100)
            fairleads.append(fairlead)
            lines[f"line{b}{k}"] = catenary(anchor, fairlead)
            points.append((f"anchor{b}{k}", "fixed", anchor))
        bodies.append((f"floater{b}", X, np.array(fairleads)))
    points += [("buoy", "free", np.array([150.0, 0.0, -40.0])),
               ("hull", "prescribed", np.array([150.0, 50.0, -5.0]))]
    return lines, points, bodies


def written(figure, size, path):
    figure.savefig(path, dpi=DPI)
    # the suptitle: the figure's topmost text
    fits = clear(figure, max(figure.texts, key=lambda text: text.get_position()[1]))
    plt.close(figure)
    assert matplotlib.image.imread(path).shape[1::-1] == (round(size[0] * DPI),
                                                         round(size[1] * DPI))
    return fits


def test_an_array_of_floaters_in_plan_and_elevation(tmp_path):
    lines, points, bodies = array_of_floaters()
    figure = figures.system_figure(lines, points, bodies, seabed=None, surface=0.0,
                                   title="two floaters")
    plan, elevation = figure.axes
    drawn = [line for line in plan.get_lines() if len(line.get_xdata()) == 30]
    assert len(drawn) == 12
    assert {line.get_color() for line in drawn} == {style.LINE}    # one colour
    assert plan.get_title() == "plan: 12 lines, 14 points, 2 bodies"
    assert elevation.get_ylim()[0] < -100.0 < 0.0 < elevation.get_ylim()[1]
    assert written(figure, figures.SIZE, tmp_path / "system.png")


def test_the_curves_without_a_seabed(tmp_path):
    headings = np.arange(0.0, 360.0, 30.0)
    angle = np.radians(headings)
    offsets = np.stack([12.0 * np.cos(angle), 9.0 * np.sin(angle)], axis=1)
    tension = 2.1e6 + 1e5 * np.cos(3 * angle)
    circle = figures.watch_circle_figure(offsets, headings, tension,
                                         np.full(headings.size, np.nan), 1.5e6, "hull")
    assert circle.axes[2].get_title() == "no line on a seabed"
    assert circle.axes[1].get_ylabel() == "largest tension (MN)"
    assert written(circle, figures.CURVES_SIZE, tmp_path / "circle.png")
    loads = np.array([0.0, 5e5, 1e6, 1.5e6])
    curve = figures.excursion_figure(np.outer([1.0, 1.2], loads / 1e5),
                                     np.outer([1.0, 1.0], loads), [0.0, 45.0],
                                     np.outer([1.0, 1.1], 2e6 + loads),
                                     np.full((2, 4), np.nan), "hull")
    assert curve.axes[0].get_ylabel() == "restoring force (MN)"
    assert written(curve, figures.CURVES_SIZE, tmp_path / "curves.png")
