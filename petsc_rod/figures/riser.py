"""The figure of a riser, a mooring line or a cable (a file with the riser datasets,
line types or attachments), and the overlay of several such files (a sweep): on top the
elevation and the plan, below the graphs against S (graphs.py)."""

import matplotlib.pyplot as plt

from petsc_rod.figures import graphs, scene, style
from petsc_rod.figures.titles import result_title, sweep_title


SIZE = (16, 9.5)
# The fixed layout's margins (in): the tick labels and axis label left of an axes, the
# height of a line of the suptitle below TOP, and the space of a one-line axes title.
LEFT, GAP, RIGHT, TOP, TITLE_LINE, TITLE = 0.72, 1.05, 0.15, 0.05, 0.2, 0.3


def layout(count, title_lines=None):
    """A figure with the elevation and the plan on top and ``count`` graphs below
    (sharing S): (figure, elevation, plan, graph axes). With ``title_lines`` (the
    suptitle's lines) the axes are placed at fixed margins in inches (LEFT, GAP, ...),
    which give the picture of constrained layout for tick labels of up to about six
    characters at a fraction of its drawing time (constrained layout measures every
    tick label of every axes several times); without, constrained layout."""
    if title_lines is None:
        figure = plt.figure(figsize=SIZE, layout="constrained")
        top, bottom = figure.subfigures(2, 1, height_ratios=[1.2, 1])
        elevation, plan = top.subplots(1, 2, width_ratios=[1.9, 1])
        along = bottom.subplots(1, count, sharex=True)
        return figure, elevation, plan, list(along)
    width, height = SIZE
    figure = plt.figure(figsize=SIZE)
    span = width - LEFT - RIGHT

    def row(columns, bottom, top, **kwargs):
        """A row of ``columns`` axes from ``bottom`` to ``top`` (in), GAP apart."""
        return figure.add_gridspec(
            1, columns, left=LEFT / width, right=1 - RIGHT / width, bottom=bottom / height,
            top=top / height, wspace=GAP * columns / (span - GAP * (columns - 1)), **kwargs)

    above = row(2, 4.51, height - TOP - TITLE_LINE * title_lines - TITLE, width_ratios=[1.9, 1])
    elevation, plan = figure.add_subplot(above[0]), figure.add_subplot(above[1])
    along = row(count, 0.44, 3.6).subplots(sharex=True, squeeze=False)[0]
    return figure, elevation, plan, list(along)


def riser_figure(result, min_bend_radius=None):
    """The figure of one ``Result``; ``min_bend_radius``: the allowable bend radius
    (m) drawn on the curvature graph. Laid out at fixed margins when every panel fits
    in them (``clear``), else drawn again with constrained layout."""
    figure, heading = drawn_figure(result, min_bend_radius, fixed=True)
    if clear(figure, heading):
        return figure
    plt.close(figure)
    return drawn_figure(result, min_bend_radius, fixed=False)[0]


def drawn_figure(result, min_bend_radius, fixed):
    """(figure, its suptitle's Text) of riser_figure at fixed margins (``fixed``) or
    with constrained layout."""
    drawn = graphs.graphs_for([result])
    title = result_title(result)
    figure, elevation, plan, axes = layout(len(drawn),
                                           title.count("\n") + 1 if fixed else None)
    scene.draw_elevation(elevation, result)
    scene.draw_water(elevation, result)
    elevation.set_title("elevation: height against the true horizontal distance "
                        "from the anchor", fontsize=10)
    elevation.legend(loc="upper left", fontsize=8, framealpha=0.9)
    scene.draw_plan(plan, result)
    for draw, axis in zip(drawn, axes):
        graphs.mark_along(axis, result, named=draw is graphs.draw_tension)
        if draw is graphs.draw_curvature:
            draw(axis, result, allowable=min_bend_radius)
        else:
            draw(axis, result)
        if len(axis.get_legend_handles_labels()[0]) > 1:
            axis.legend(fontsize=8, loc="best")
    if fixed:
        return figure, figure.suptitle(title, y=1 - TOP / SIZE[1])
    return figure, figure.suptitle(title)


def clear(figure, heading):
    """Whether every axes of ``figure``, its tick labels, axis labels and title
    included, lies inside the figure, clear of the others and of the suptitle
    ``heading`` (the Text figure.suptitle returned; the fixed layout fits: else
    constrained layout makes room)."""
    renderer = figure.canvas.get_renderer()
    boxes = [axis.get_tightbbox(renderer) for axis in figure.axes]
    boxes.append(heading.get_window_extent(renderer))
    inside = all(b.x0 >= 0 and b.y0 >= 0 and b.x1 <= figure.bbox.width
                 and b.y1 <= figure.bbox.height for b in boxes)
    return inside and not any(a.overlaps(b) for k, a in enumerate(boxes)
                              for b in boxes[k + 1:])


def sweep_overlay(results, labels, min_bend_radius=None):
    """The figure of several ``Result`` overlaid, a colour per case (``labels``): the
    elevations and plans, the graphs against S; the sea and seabed of the first."""
    drawn = graphs.graphs_for(results)
    figure, elevation, plan, axes = layout(len(drawn))
    for k, (result, label) in enumerate(zip(results, labels)):
        colour = style.case_colour(k)
        text = label if result.converged else f"{label} (NOT converged)"
        scene.draw_elevation(elevation, result, colour, text, single=False)
        scene.draw_plan(plan, result, colour, text, single=False)
        for draw, axis in zip(drawn, axes):
            graphs.mark_along(axis, result, colour)
            if draw is graphs.draw_curvature:
                draw(axis, result, colour, text, allowable=min_bend_radius)
            else:
                draw(axis, result, colour, text)
    scene.draw_water(elevation, results[0])
    elevation.set_title("elevation: height against the true horizontal distance "
                        "from the anchor (▼ touchdown, ■ anchor, ▲ hang-off)", fontsize=10)
    plan.set_title("plan", fontsize=10)
    elevation.legend(loc="upper left", fontsize=8, framealpha=0.9)
    figure.suptitle(sweep_title(results, labels))
    return figure
