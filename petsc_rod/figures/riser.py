"""The figure of a riser, a mooring line or a cable (a file with the riser datasets,
line types or attachments), and the overlay of several such files (a sweep): on top the
elevation and the plan, below the graphs against S (graphs.py)."""

import matplotlib.pyplot as plt

from petsc_rod.figures import graphs, scene, style
from petsc_rod.figures.titles import result_title, sweep_title


def layout(count):
    """A figure with the elevation and the plan on top and ``count`` graphs below
    (sharing S): (figure, elevation, plan, graph axes)."""
    figure = plt.figure(figsize=(16, 9.5), layout="constrained")
    top, bottom = figure.subfigures(2, 1, height_ratios=[1.2, 1])
    elevation, plan = top.subplots(1, 2, width_ratios=[1.9, 1])
    along = bottom.subplots(1, count, sharex=True)
    return figure, elevation, plan, list(along)


def riser_figure(result, min_bend_radius=None):
    """The figure of one ``Result``; ``min_bend_radius``: the allowable bend radius
    (m) drawn on the curvature graph."""
    drawn = graphs.graphs_for([result])
    figure, elevation, plan, axes = layout(len(drawn))
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
    figure.suptitle(result_title(result))
    return figure


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
