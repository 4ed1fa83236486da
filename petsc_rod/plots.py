"""Figures from result files (matplotlib only; never PETSc, never a running solve).

    python -m petsc_rod.plots RESULT.h5 FIGURE.png [--min-bend-radius R]
    python -m petsc_rod.plots A.h5 B.h5 ... FIGURE.png      (the cases overlaid)
    python -m petsc_rod.plots MODES.csv FIGURE.png           (-rod_modes_table's modes)
    python -m petsc_rod.plots SYSTEM.h5 FIGURE.png           (a system's file)

For a plain rod: the centreline projected on the xy, xz and yz planes and the strains
against S (the paper's Figures 1 and 3, docs/method.md §8). For a riser, a mooring line
or a cable (a file with a seabed, a current, line types or attachments): the elevation
and the plan with the sea surface, the seabed, the hang-off, the touchdown, the sections
and the attachments, and against S the tension, the signed curvature against the
allowable bend radius, the bending moment and the seabed reaction (petsc_rod/figures/,
docs/output.md "Figures"). For a system's file (-rod_system): the plan and the elevation
of the whole system to FIGURE.png and, where the file holds them, the watch circle to
FIGURE_watch_circle.png and the load-excursion curves to FIGURE_excursion.png
(figures/system.py, figures/read_system.py). Two entry points return a matplotlib Figure:
``result_figure(path)`` and ``sweep_figure(paths, labels)``.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from petsc_rod.figures.modes import modes_figure  # noqa: E402
from petsc_rod.figures.read import read_result  # noqa: E402
from petsc_rod.figures.read_system import figures, is_system_file, read_system  # noqa: E402
from petsc_rod.figures.riser import riser_figure, sweep_overlay  # noqa: E402
from petsc_rod.figures.rod import rod_figure  # noqa: E402
from petsc_rod.io.same_file import replaced_input, write_whole  # noqa: E402
from petsc_rod.tables import file_problem  # noqa: E402

DPI = 110


def result_figure(path, min_bend_radius=None):
    """The figure of result file ``path``; ``min_bend_radius``: the allowable bend
    radius (m) drawn against the curvature of a riser."""
    result = read_result(path)
    if result.riser:
        return riser_figure(result, min_bend_radius)
    return rod_figure(result)


def sweep_figure(paths, labels=None, min_bend_radius=None):
    """The result files ``paths`` overlaid, one colour per case named by ``labels``
    (default: the files' names): elevations, plans and the graphs against S."""
    results = [read_result(path) for path in paths]
    labels = list(labels) if labels is not None else [r.name for r in results]
    if len(labels) != len(results):
        raise ValueError(f"{len(paths)} result files but {len(labels)} labels")
    return sweep_overlay(results, labels, min_bend_radius)


def plot_result(path, output, min_bend_radius=None):
    """Write the figure of result file ``path`` to ``output`` (PNG)."""
    save(result_figure(path, min_bend_radius), output)


def plot_system(path, output):
    """Write the figures of system file ``path``: the plan and elevation to ``output``,
    the sweeps' beside it (OUT_watch_circle.png, OUT_excursion.png); returns the paths
    written."""
    stem, extension = os.path.splitext(output)
    written = []
    for suffix, figure in figures(read_system(path)).items():
        save(figure, f"{stem}{suffix}{extension}")
        written.append(f"{stem}{suffix}{extension}")
    return written


def save(figure, output):
    """Write ``figure`` to ``output`` (whole or not at all: io.same_file.write_whole) and
    close it."""
    try:
        write_whole(output, lambda partial: figure.savefig(partial, dpi=DPI))
    finally:
        plt.close(figure)


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose refusal is one line, ``petsc_rod.<module>: error:
    <message>; usage: ...``, and exit 2 (argparse's own prints the usage on a line of its own)."""

    def line(self, message):
        usage = self.format_usage().strip().removeprefix("usage: ")
        return f"{self.prog.removeprefix('python -m ')}: error: {message}; usage: {usage}\n"

    def refuse(self, message):
        """Say the line on stderr; returns the exit code 2."""
        sys.stderr.write(self.line(message))
        return 2

    def error(self, message):
        self.exit(2, self.line(message))


def main(argv):
    parser = OneLineParser(
        prog="python -m petsc_rod.plots",
        usage="python -m petsc_rod.plots RESULT.h5 [MORE.h5 ...] FIGURE.png "
              "[--min-bend-radius R] | MODES.csv FIGURE.png",
        description="Draw a result file, or several overlaid (a sweep), as a PNG.")
    parser.add_argument("files", nargs="+", metavar="FILE",
                        help="the result files, then the figure to write")
    parser.add_argument("--min-bend-radius", type=float, default=None, metavar="R",
                        help="allowable bend radius (m), drawn against the curvature")
    args = parser.parse_args(argv[1:])
    if len(args.files) < 2:
        return parser.refuse("give a result file and the figure to write")
    *inputs, output = args.files
    if output.lower().endswith((".h5", ".hdf5")):     # never write a figure over a result
        return parser.refuse(f"the last file is the figure to write, not a result: {output}")
    clash = replaced_input([("the figure", output)], [("result", path) for path in inputs])
    if clash:
        return parser.refuse(clash)
    if not os.path.isdir(os.path.dirname(os.path.abspath(output))):
        return parser.refuse(f"the figure {output}: its folder does not exist")
    radius = args.min_bend_radius
    if radius is not None and not (radius > 0 and radius < float("inf")):
        sys.stderr.write(f"petsc_rod.plots: error: --min-bend-radius {radius:g}: give the "
                         "allowable bend radius in m, positive and finite\n")
        return 2
    if len(inputs) == 1 and inputs[0].lower().endswith(".csv"):
        return drawn(lambda: save(modes_figure(inputs[0]), output), inputs,
                     "a table written with -rod_modes_table")
    for path in inputs:                 # a FIFO would block h5py for ever
        problem = file_problem(path)
        if problem:
            sys.stderr.write(f"petsc_rod.plots: error: {path}: {problem}\n")
            return 2

    if len(inputs) == 1 and _system(inputs[0]):
        stem, extension = os.path.splitext(output)
        clash = replaced_input([("the figure", f"{stem}{suffix}{extension}")
                                for suffix in ("_watch_circle", "_excursion")],
                               [("result", inputs[0])])
        if clash:
            return parser.refuse(clash)
        return drawn(lambda: plot_system(inputs[0], output), inputs,
                     "a system's result file written with -rod_system ... -rod_output")

    def draw():
        if len(inputs) == 1:
            plot_result(inputs[0], output, radius)
        else:
            labels = [os.path.basename(p).removesuffix(".h5") for p in inputs]
            save(sweep_figure(inputs, labels, radius), output)
    return drawn(draw, inputs, "result files written with -rod_output")


def _system(path):
    """Whether ``path`` is a system's result file (False for what h5py cannot open: the
    single line's path then says why)."""
    try:
        return is_system_file(path)
    except (OSError, KeyError, ValueError):
        return False


def drawn(draw, inputs, advice):
    """0 once ``draw()`` has written the figure; 2 with one line (the ``inputs`` cannot
    be drawn: give ``advice``) where reading or drawing them failed."""
    try:
        draw()
    except (OSError, KeyError, ValueError) as error:
        sys.stderr.write(f"petsc_rod.plots: error: {' '.join(inputs)}: cannot be drawn "
                         f"({error.__class__.__name__}: {error}); give {advice}\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
