"""The figures of petsc_rod.plots from small synthetic result files (h5py and
matplotlib, no PETSc object, no solve): what the panels draw is the file's data, the
plan shows a line pushed sideways, the PNG has the sea surface's and the sections'
colours, a sweep overlays its cases, and the plain rod keeps its four panels."""

import os
import shutil
import tempfile

import h5py
import matplotlib
import matplotlib.image
import numpy as np
import pytest

from petsc_rod import plots
from petsc_rod.figures import along, style

L, SPAN, HEIGHT = 200.0, 150.0, 60.0


@pytest.fixture
def folder():
    """A folder of this rank's own (the tests also run under mpiexec -n 2)."""
    path = tempfile.mkdtemp(prefix="petsc_rod_figures_")
    yield path
    shutil.rmtree(path, ignore_errors=True)


def frame(tangent):
    """Directors (d1, d2, d3) with d3 the unit tangent and d1 horizontal."""
    d3 = along.unit(tangent)
    d1 = along.unit(np.cross([0.0, 0.0, 1.0], d3))
    return d1, np.cross(d3, d1), d3


def write_line(path, offset=0.0, riser=True, converged=1):
    """A result file of a line from an anchor at the origin to a hang-off at (SPAN, 0,
    HEIGHT), bowed sideways by ``offset`` m at mid-length; ``riser``: with the seabed,
    the sea surface, a current, two sections, an attachment and a touchdown."""
    S = np.linspace(0.0, L, 201)
    s = S / L
    r = np.column_stack([SPAN * s, offset * np.sin(np.pi * s), HEIGHT * s ** 2])
    tangent = np.column_stack([SPAN + 0 * s, offset * np.pi * np.cos(np.pi * s),
                               2 * HEIGHT * s]) / L
    d1, d2, d3 = frame(tangent)
    u = np.column_stack([0.01 * np.sin(2 * np.pi * s), 0.002 * s, 0 * s])
    tension = 1e5 * (1 + s)
    with h5py.File(path, "w") as f:
        for name, value in dict(S=S, r=r, d1=d1, d2=d2, d3=d3, u=u, m=1e4 * u,
                                n=tension[:, None] * d3).items():
            f[name] = value
        f.attrs.update(converged=converged, stop_reason="converged" if converged else "max_it",
                       energy=123.456)
        p = f.create_group("parameters")
        if not riser:
            return path
        f["effective_tension"] = tension
        f["wall_tension"] = tension + 3e4
        f["seabed_reaction"] = np.where(S < 10, 1e3, 0.0)
        p.attrs.update(seabed=-1.0, sea_surface=HEIGHT + 20, current=[0.0, 0.5, 0.0])
        f.attrs.update(top_tension=2e5, top_angle=12.5, touchdown_S=10.0,
                       touchdown_position=r[10], section_names=["pipe", "buoyancy"],
                       section_bounds=[[0.0, L / 2], [L / 2, L]], point_load_S=[150.0],
                       point_load_position=r[150][None, :], point_load_names="clump")
    return path


def axis_by_labels(figure, x, y):
    """The axes of ``figure`` whose labels are ``x`` and ``y``."""
    found = [a for a in figure.axes if (a.get_xlabel(), a.get_ylabel()) == (x, y)]
    assert len(found) == 1, [(a.get_xlabel(), a.get_ylabel()) for a in figure.axes]
    return found[0]


def test_the_panels_draw_the_files_data(folder):
    path = write_line(f"{folder}/side.h5", offset=30.0)
    figure = plots.result_figure(path)
    with h5py.File(path, "r") as f:
        r, S = f["r"][:], f["S"][:]
    plan = axis_by_labels(figure, "x (m)", "y (m)")
    ys = np.concatenate([line.get_ydata() for line in plan.lines if len(line.get_ydata()) > 5])
    assert ys.max() == pytest.approx(30.0, rel=1e-6)          # the sideways offset, in plan
    assert "largest offset from the plane of the ends 30 m" in plan.get_title()
    elevation = axis_by_labels(figure, "horizontal distance from the anchor (m)", "z (m)")
    drawn = [line for line in elevation.lines if line.get_label() == "pipe"][0]
    half = S <= L / 2
    # the true horizontal distance from the anchor, not the projection on the ends' plane
    np.testing.assert_allclose(drawn.get_xdata(), np.hypot(r[half, 0], r[half, 1]))
    labels = [line.get_label() for line in elevation.lines]
    assert "projected on the vertical plane of the ends" in labels
    assert any(label.startswith("touchdown, S = 10.0") for label in labels)
    assert "attachments: clump" in labels
    tension = axis_by_labels(figure, "S (m)", "tension (kN)")
    curves = {line.get_label(): line for line in tension.lines}
    assert {"effective tension", "wall tension"} <= set(curves)
    np.testing.assert_allclose(curves["effective tension"].get_ydata(), 100 * (1 + S / L))
    np.testing.assert_allclose(curves["wall tension"].get_ydata(), 130 + 100 * S / L)
    title = figure._suptitle.get_text()
    assert "side: converged" in title and "top tension 200 kN at 12.5°" in title
    assert "touchdown at S = 10.0 m" in title and "energy" not in title and " J" not in title
    matplotlib.pyplot.close(figure)


def test_the_allowable_bend_radius_is_drawn_against_the_curvature(folder):
    path = write_line(f"{folder}/line.h5")
    figure = plots.result_figure(path, min_bend_radius=80.0)
    curvature = axis_by_labels(figure, "S (m)", "curvature (1/m)")
    levels = {line.get_ydata()[0] for line in curvature.lines
              if line.get_label().startswith("allowable")}
    assert levels == {1 / 80.0}
    # the largest curvature is about 0.0102 1/m (98 m): above 80 m, below 120 m
    assert "BELOW THE ALLOWABLE" not in curvature.get_title()
    matplotlib.pyplot.close(figure)
    figure = plots.result_figure(path, min_bend_radius=120.0)
    assert "BELOW THE ALLOWABLE" in axis_by_labels(figure, "S (m)", "curvature (1/m)").get_title()
    matplotlib.pyplot.close(figure)


def plan_rows(png, figure):
    """The pixel rows of the plan panel of ``figure`` saved as ``png`` that hold the
    line's colours (the two sections')."""
    pixels = matplotlib.image.imread(png)[..., :3]
    plan = axis_by_labels(figure, "x (m)", "y (m)")
    box = plan.get_window_extent()
    top, bottom = pixels.shape[0] - int(box.y1), pixels.shape[0] - int(box.y0)
    region = pixels[top:bottom, int(box.x0):int(box.x1)]
    hit = np.zeros(region.shape[:2], bool)
    for colour in style.PALETTE[:2]:
        hit |= np.all(np.abs(region - colour) < 0.02, axis=-1)
    return np.nonzero(hit.any(axis=1))[0]


def test_the_png_shows_the_sea_the_sections_and_the_sideways_offset(folder):
    spreads = {}
    for offset in (0.0, 40.0):
        path = write_line(f"{folder}/line_{offset:g}.h5", offset=offset)
        figure = plots.result_figure(path)
        png = f"{folder}/line_{offset:g}.png"
        figure.savefig(png, dpi=plots.DPI)
        rows = plan_rows(png, figure)
        spreads[offset] = rows.max() - rows.min()
        pixels = matplotlib.image.imread(png)[..., :3]
        for colour in (style.SEA, *style.PALETTE[:2]):
            assert np.mean(np.all(np.abs(pixels - colour) < 0.02, axis=-1)) > 1e-4, colour
        matplotlib.pyplot.close(figure)
    assert spreads[0.0] < 6            # in the plane of the ends: a straight line in plan
    assert spreads[40.0] > 40          # pushed 40 m sideways: a bow across many rows


def test_a_sweep_overlays_its_cases_with_a_legend(folder):
    paths = [write_line(f"{folder}/a.h5"), write_line(f"{folder}/b.h5", offset=20.0),
             write_line(f"{folder}/c.h5", offset=-20.0, converged=0)]
    figure = plots.sweep_figure(paths, ["near", "cross", "far"])
    elevation = axis_by_labels(figure, "horizontal distance from the anchor (m)", "z (m)")
    legend = [t.get_text() for t in elevation.get_legend().get_texts()]
    assert legend == ["near", "cross", "far (NOT converged)"]
    plan = axis_by_labels(figure, "x (m)", "y (m)")
    colours = {line.get_color() for line in plan.lines if len(line.get_xdata()) > 5}
    assert colours == set(style.PALETTE[:3])
    tension = axis_by_labels(figure, "S (m)", "tension (kN)")
    cases = [line.get_label() for line in tension.lines if not line.get_label().startswith("_")]
    assert cases == ["near", "cross", "far (NOT converged)"]
    assert figure._suptitle.get_text() == "3 cases, 2 converged; NOT converged: far"
    matplotlib.pyplot.close(figure)
    with pytest.raises(ValueError):
        plots.sweep_figure(paths, ["one"])


def test_the_command_line_draws_one_file_or_several(folder):
    one, two = write_line(f"{folder}/one.h5"), write_line(f"{folder}/two.h5", offset=10.0)
    assert plots.main(["plots", one, f"{folder}/one.png", "--min-bend-radius", "50"]) == 0
    assert plots.main(["plots", one, two, f"{folder}/both.png"]) == 0
    for name in ("one", "both"):
        pixels = matplotlib.image.imread(f"{folder}/{name}.png")
        assert pixels.shape[:2] == (int(9.5 * plots.DPI), 16 * plots.DPI)
    assert plots.main(["plots", one]) == 2
    before = open(two, "rb").read()
    assert plots.main(["plots", one, two]) == 2          # the last file is the figure:
    assert open(two, "rb").read() == before              # a result file is never overwritten


def test_the_plain_rod_keeps_its_four_panels_without_the_energy(folder):
    path = write_line(f"{folder}/rod.h5", riser=False)
    figure = plots.result_figure(path)
    assert len(figure.axes) == 4 and figure.axes[0].get_title() == "projection on the xy plane"
    assert figure._suptitle.get_text() == "rod: converged"
    matplotlib.pyplot.close(figure)


def test_the_curvature_in_the_vertical_plane_is_positive_in_a_sag_bend():
    """A circle of radius R concave up in the xz plane (a sag bend): +1/R in the vertical
    plane; a horizontal circle: 1/R lateral, none vertical; either way along S."""
    R, s = 50.0, np.linspace(0.0, 1.0, 11)
    tangent = np.column_stack([np.cos(s), 0 * s, np.sin(s)])
    d1, d2, d3 = frame(tangent)          # d1 = e_y: t x t' = -e_y / R = u1 d1
    u = np.column_stack([-np.ones_like(s) / R, 0 * s, 0 * s])
    np.testing.assert_allclose(along.curvature_components(u, d1, d2, d3),
                               np.column_stack([np.ones_like(s) / R, 0 * s]), atol=1e-15)
    # backwards: t and d1 change sign, t x t' too, so u1 keeps its value
    reverse = along.curvature_components(u[::-1], -d1[::-1], d2[::-1], -d3[::-1])
    np.testing.assert_allclose(reverse[:, 0], 1 / R)           # the same read backwards
    flat = np.column_stack([np.cos(s), np.sin(s), 0 * s])
    d1, d2, d3 = frame(flat)             # d1 = e_z x t: t x t' = e_z / R = -u2 d2
    u = np.column_stack([0 * s, -np.ones_like(s) / R, 0 * s])
    np.testing.assert_allclose(np.abs(along.curvature_components(u, d1, d2, d3)),
                               np.column_stack([0 * s, np.ones_like(s) / R]), atol=1e-15)


def test_a_line_of_load_pieces_is_drawn_in_pieces(folder):
    """A line given by -rod_load and -rod_load_breaks (options/cable_80m.opts) has no
    line types: its pieces are coloured and shaded by their load, one colour a load."""
    path = write_line(f"{folder}/pieces.h5")
    with h5py.File(path, "a") as f:
        for name in ("section_names", "section_bounds"):
            del f.attrs[name]
        f["parameters"].attrs.update(load=[[0, 0, -157.8], [0, 0, 80.15], [0, 0, -157.8]],
                                     load_breaks=[50.0, 100.0])
    figure = plots.result_figure(path)
    elevation = axis_by_labels(figure, "horizontal distance from the anchor (m)", "z (m)")
    pieces = [line for line in elevation.lines if line.get_label().startswith(("load", "_"))
              and len(line.get_xdata()) > 5]
    assert [line.get_label() for line in pieces][:2] == ["load fz = -157.8 N/m",
                                                        "load fz = 80.15 N/m"]
    assert pieces[0].get_color() == pieces[2].get_color() != pieces[1].get_color()
    matplotlib.pyplot.close(figure)


@pytest.mark.parametrize("tool", ["plots", "report"])
def test_a_result_that_is_a_fifo_is_refused_not_waited_for(tmp_path, capsys, tool):
    """h5py would block on a FIFO for ever (deaf to SIGTERM): the plots and the report
    refuse it at once."""
    import signal

    from petsc_rod import plots
    from petsc_rod.report import __main__ as report

    fifo = tmp_path / "run.h5"
    os.mkfifo(fifo)
    output = tmp_path / ("run.png" if tool == "plots" else "run.html")
    call = {"plots": lambda: plots.main(["plots", str(fifo), str(output)]),
            "report": lambda: report.main([str(fifo), "-o", str(output)])}[tool]

    def expire(*_):
        raise TimeoutError(f"{tool} blocked on the FIFO")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(10)
    try:
        code = call()
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert code == 2 and "not a regular file" in capsys.readouterr().err
    assert not output.exists()


def test_the_utilisation_panel_with_its_limit(folder):
    """A file with a utilisation (a line type with a yield stress) has a utilisation
    panel: the file's values, the limit 1 dashed, the largest and where in the title;
    a file without one has none. Before, no utilisation panel."""
    path = write_line(f"{folder}/u.h5")
    S = np.linspace(0.0, L, 201)
    with h5py.File(path, "a") as f:
        f["utilisation"] = 0.2 + 0.9 * np.sin(np.pi * S / L) ** 2
    figure = plots.result_figure(path)
    axis = axis_by_labels(figure, "S (m)", "utilisation")
    curves = {line.get_label(): line for line in axis.lines}
    drawn = [line for line in axis.lines if len(line.get_ydata()) == S.size]
    assert len(drawn) == 1
    np.testing.assert_allclose(drawn[0].get_ydata(), 0.2 + 0.9 * np.sin(np.pi * S / L) ** 2)
    assert list(curves["limit 1"].get_ydata()) == [1.0, 1.0]
    assert "largest 1.1 at S = 100 m  ABOVE 1" in axis.get_title()
    matplotlib.pyplot.close(figure)
    figure = plots.result_figure(write_line(f"{folder}/plain.h5"))
    assert not [a for a in figure.axes if a.get_ylabel() == "utilisation"]
    matplotlib.pyplot.close(figure)


def overlaps(figure):
    """The pairs of ``figure``'s axes (tick labels, axis labels and title included)
    and suptitle that overlap, and those not inside the figure."""
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    boxes = [axis.get_tightbbox(renderer) for axis in figure.axes]
    boxes.append(figure._suptitle.get_window_extent(renderer))
    outside = [k for k, b in enumerate(boxes) if b.x0 < 0 or b.y0 < 0
               or b.x1 > figure.bbox.width + 1 or b.y1 > figure.bbox.height]
    return outside + [(j, k) for j, a in enumerate(boxes) for k, b in enumerate(boxes)
                      if j < k and a.overlaps(b)]


def test_a_riser_picture_has_a_fixed_layout_without_overlaps(folder):
    """The picture of one riser is laid out at fixed margins (no layout engine: it
    measures every tick label several times, most of the drawing time of a report's
    pictures) when its panels fit in them: every panel inside the figure, clear of the
    others and of the suptitle; else with constrained layout (here five panels, long
    titles and tick labels seven characters wide)."""
    path = write_line(f"{folder}/plain.h5")
    with h5py.File(path, "a") as f:
        del f["wall_tension"]  # the tension panel's title on one short line
    figure = plots.result_figure(path)
    assert figure.get_layout_engine() is None
    assert overlaps(figure) == []
    matplotlib.pyplot.close(figure)
    path = write_line(f"{folder}/u.h5")
    S = np.linspace(0.0, L, 201)
    with h5py.File(path, "a") as f:
        f["utilisation"] = 0.00175 * np.sin(np.pi * S / L) ** 2
    figure = plots.result_figure(path)
    assert figure.get_layout_engine() is not None
    matplotlib.pyplot.close(figure)


def test_the_fixed_layout_measures_the_suptitle_it_was_given():
    """figures.riser.clear measures the suptitle's Text that figure.suptitle returned
    (no private attribute of the figure): clear of the axes it fits, over them not."""
    from petsc_rod.figures import riser
    figure = matplotlib.pyplot.figure(figsize=(4, 4))
    figure.add_axes([0.2, 0.2, 0.6, 0.5])
    assert riser.clear(figure, figure.suptitle("a title", y=0.97))
    assert not riser.clear(figure, figure.suptitle("a title", y=0.45))
    matplotlib.pyplot.close(figure)
