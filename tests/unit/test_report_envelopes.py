"""The report's range graphs (report/envelopes.py; no PETSc): the envelope of cases of
different lengths spans every case's arc length, and a shorter case is not extended
past its own end."""

import os

import h5py
import matplotlib
import numpy as np
from matplotlib.figure import Figure

from petsc_rod.report import envelopes

matplotlib.use("Agg")


def write_case(path, length, elements, tension):
    """A result file of a straight line of ``length`` m, its effective tension
    ``tension(S)`` (N) and a bend radius of 100 m."""
    S = np.linspace(0.0, length, elements + 1)
    with h5py.File(path, "w") as f:
        f["S"] = S
        f["effective_tension"] = tension(S)
        f["u"] = np.column_stack([np.full_like(S, 0.01), np.zeros_like(S), np.zeros_like(S)])
    return str(path)


def test_the_envelope_spans_every_case(tmp_path):
    short = write_case(tmp_path / "short.h5", 100.0, 10, lambda S: 1000.0 + S)
    long = write_case(tmp_path / "long.h5", 250.0, 20, lambda S: 500.0 + 4.0 * S)
    for order in ([short, long], [long, short]):
        S, result = envelopes.envelopes([envelopes.along_line(p) for p in order])
        assert S[0] == 0.0 and S[-1] == 250.0
        stacked, least, largest = result["effective_tension"]
        beyond = S > 100.0
        # beyond the short case's end only the long case: 500 + 4 S, both sides
        np.testing.assert_allclose(largest[beyond], 500.0 + 4.0 * S[beyond])
        np.testing.assert_allclose(least[beyond], 500.0 + 4.0 * S[beyond])
        # within it, the larger and smaller of the two lines
        within = ~beyond
        np.testing.assert_allclose(largest[within], np.maximum(1000.0 + S[within],
                                                               500.0 + 4.0 * S[within]))
        np.testing.assert_allclose(least[within], np.minimum(1000.0 + S[within],
                                                             500.0 + 4.0 * S[within]))
        short_row = stacked[order.index(short)]
        assert np.all(np.isnan(short_row[beyond]))
        radius = result["bend_radius"]
        np.testing.assert_allclose(radius[1], 100.0)
        np.testing.assert_allclose(radius[2], 100.0)
        figure = Figure()
        envelopes.draw(figure, S, result, ["a", "b"])
        # the largest tension is the long case's end: 1500 N
        assert figure.axes[0].get_title() == "effective tension: max 1.5 kN"


def test_one_graph_a_quantity_names_the_governing_case_and_draws_the_limit(tmp_path):
    """draw_one: the title gives the extreme on the design side, in the unit shown, and
    the case and S where it is (the long case's end, 1.5 kN at S = 250 m); the bend
    radius's graph draws the allowable radius as a line at its value; a utilisation's
    title has no unit '1'. Before, one strip of panels titled 'max 1.2 1' naming no case."""
    short = write_case(tmp_path / "short.h5", 100.0, 10, lambda S: 1000.0 + S)
    long = write_case(tmp_path / "long.h5", 250.0, 20, lambda S: 500.0 + 4.0 * S)
    for path, scale in ((short, 0.4), (long, 1.2)):
        with h5py.File(path, "a") as f:
            f["utilisation"] = scale * f["S"][:] / f["S"][-1]
    S, result = envelopes.envelopes([envelopes.along_line(p) for p in (short, long)])
    figure = Figure()
    envelopes.draw_one(figure, S, "effective_tension", result["effective_tension"],
                       ["short", "long"])
    assert figure.axes[0].get_title() == ("effective tension: max 1.5 kN, case long at "
                                          "S = 250 m")
    figure = Figure()
    envelopes.draw_one(figure, S, "bend_radius", result["bend_radius"], ["short", "long"],
                       limit=30.0)
    limits = [line for line in figure.axes[0].lines if line.get_label() == "limit 30 m"]
    assert len(limits) == 1 and limits[0].get_ydata()[0] == 30.0
    assert figure.axes[0].get_ylim()[0] < 30.0              # the limit is in sight
    figure = Figure()
    envelopes.draw_one(figure, S, "utilisation", result["utilisation"], ["short", "long"],
                       limit=1.0)
    assert figure.axes[0].get_title() == "utilisation: max 1.2, case long at S = 250 m"
    assert figure.axes[0].get_ylabel() == "utilisation"


def _pid_of(k):
    """(k, the id of the process that ran it)."""
    return k, os.getpid()


def test_report_figures_are_drawn_by_a_pool_in_their_order(monkeypatch):
    """The page's figures are drawn by a pool of one process a CPU and come back in the
    order asked, whatever worker drew each."""
    from petsc_rod.report import page

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    drawn = page.drawn_all([(_pid_of, (k,)) for k in range(6)])
    assert [k for k, _ in drawn] == list(range(6))
    assert os.getpid() not in {pid for _, pid in drawn}
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    assert page.drawn_all([(_pid_of, (k,)) for k in range(3)]) == [
        (k, os.getpid()) for k in range(3)]
