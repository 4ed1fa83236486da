"""The report page (serial post-processing; h5py, numpy, matplotlib, never PETSc): one
self-contained HTML file, every figure a PNG embedded as base64 and the style inline,
that an engineer attaches to a design note:

1. the inputs an engineer gave (the file's ``options`` without the solver's; for a
   sweep, those of its first case and the options the cases vary), the line types'
   table when the file has one (``parameters/line_types_table``), every option in effect
   (``options_in_effect``) folded away;
2. the key results of each case in engineering units, a row a quantity (report/tables.py,
   from sweep/summary.py: the numbers of the sweep's summary.csv, read from the result
   files' attributes), the regions' extremes over the cases and the case that governs,
   and the whole summary table in SI units folded away;
3. for a sweep, the load-excursion and touchdown-excursion graphs (report/excursion.py)
   and one range graph along S a quantity (report/envelopes.py), the governing case
   named, the limits drawn (utilisation 1, the allowable bend radius when given);
4. the pictures of each case, as ``petsc_rod.plots.result_figure`` draws them.

A system's result file (-rod_system) has its own page (report/system_page.py).

Units: kN, kN m, MPa, degrees, m, said once at the top; the page fits a 1400 px window
(two range graphs a row, wide tables scroll inside their box).
"""

import base64
import html
import io
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from datetime import datetime, timezone

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from petsc_rod import plots  # noqa: E402
from petsc_rod.io.same_file import write_text_whole  # noqa: E402
from petsc_rod.report import envelopes, excursion, tables  # noqa: E402
from petsc_rod.sweep import summary  # noqa: E402

STYLE = """
* { box-sizing: border-box; }
body { font-family: sans-serif; margin: 1em auto; padding: 0 1em; color: #222;
       max-width: 1400px; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #aaa; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0; }
th, td { border: 1px solid #bbb; padding: 2px 6px; text-align: right; }
th { background: #eee; } td.text { text-align: left; }
tr.failed td { background: #fde0e0; }
pre { background: #f6f6f6; padding: 0.5em; font-size: 0.8em; overflow-x: auto; }
img { max-width: 100%; height: auto; border: 1px solid #ddd; }
.scroll { max-width: 100%; overflow-x: auto; }
.graphs { display: grid; grid-template-columns: repeat(2, minmax(0, 1fr)); gap: 8px; }
details { margin: 0.5em 0; } summary { cursor: pointer; color: #225; }
"""
# The units on the page, said once.
UNITS = ("Units: forces kN, moments kN m, stresses MPa, angles degrees, lengths m (the "
         "result files and summary.csv keep SI units: N, N m, Pa).")
# One range graph, inches at DPI: two side by side in a 1400 px window.
GRAPH_SIZE = (6.6, 3.6)
DPI = 100
# A case's picture (16 x 9.5 in): 1280 px wide, within a 1400 px window as drawn, and a
# third fewer bytes and less time than at DPI.
CASE_DPI = 80


def png(figure, dpi=DPI):
    """``figure`` as a base64 PNG at ``dpi`` (the figure closed)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    plt.close(figure)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def image(figure, alt, dpi=DPI):
    """An <img> of ``figure`` at ``dpi``, embedded."""
    return img(alt, png(figure, dpi))


def img(alt, encoded):
    """An <img> of the base64 PNG ``encoded``."""
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{encoded}">'


def range_png(S, name, entry, names, limit):
    """The base64 PNG of one range graph (report/envelopes.draw_one)."""
    figure = plt.figure(figsize=GRAPH_SIZE, layout="constrained")
    envelopes.draw_one(figure, S, name, entry, names, limit)
    return png(figure)


def case_png(path, min_bend_radius):
    """The base64 PNG of the picture of result file ``path`` at CASE_DPI."""
    return png(plots.result_figure(path, min_bend_radius), CASE_DPI)


def drawn_all(tasks):
    """The results of ``tasks`` ((function, arguments) pairs, each drawing one figure), in
    their order. Drawing a figure is serial matplotlib work of a few tenths of a second,
    independent of the others, so the figures are drawn by a pool of one process a CPU
    (forked: the workers inherit the imported matplotlib) and the page takes the time of
    the slowest worker's share rather than of all; one CPU or one task: drawn here."""
    workers = min(os.cpu_count() or 1, len(tasks))
    if workers < 2 or "fork" not in multiprocessing.get_all_start_methods():
        return [function(*arguments) for function, arguments in tasks]
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) as pool:
        futures = [pool.submit(function, *arguments) for function, arguments in tasks]
        return [future.result() for future in futures]


def file_inputs(path):
    """(options in effect as text, the line types' table as text or None) of a result
    file."""
    with h5py.File(path, "r") as f:
        options = f.attrs.get("options_in_effect", "")
        options = options.decode() if isinstance(options, bytes) else str(options)
        types = None
        group = f.get("parameters")
        if group is not None and "line_types_table" in group.attrs:
            types = group.attrs["line_types_table"]
            types = types.decode() if isinstance(types, bytes) else str(types)
    return options, types


def line_types_html(text):
    """The line types' table (a header row and rows of words; '#' comments dropped)."""
    rows = [line.split("#", 1)[0].split() for line in text.splitlines()]
    rows = [row for row in rows if row]
    if not rows:
        return ""
    head = "".join(f"<th>{html.escape(w)}</th>" for w in rows[0])
    body = "".join("<tr>" + "".join(f"<td>{html.escape(w)}</td>" for w in row) + "</tr>"
                   for row in rows[1:])
    return f'<table id="line_types"><tr>{head}</tr>{body}</table>'


def table_html(header, rows, codes):
    """The summary table; rows of cases that did not converge shaded."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    lines = []
    for row, code in zip(rows, codes):
        cells = "".join(
            f'<td{"" if isinstance(v, (int, float)) else " class=text"}>'
            f"{html.escape(summary.cell(v))}</td>" for v in row)
        lines.append(f'<tr{" class=failed" if code else ""}>{cells}</tr>')
    return f'<table id="summary"><tr>{head}</tr>{"".join(lines)}</table>'


def single_record(path):
    """The summary record of a lone result file."""
    with h5py.File(path, "r") as f:
        converged = int(f.attrs.get("converged", 0))
    name = os.path.splitext(os.path.basename(path))[0]
    return {"name": name, "options": {}, "code": 0 if converged else 3, "start": "",
            "file": os.path.abspath(path)}


def sweep_records(folder):
    """(records, varied options) of a sweep's folder (its sweep.json); files looked up in
    the folder itself, so that a folder moved elsewhere still reports."""
    record = summary.read_record(os.path.join(folder, "sweep.json"))
    records = []
    for case in record["cases"]:
        local = os.path.join(folder, f"{case['name']}.h5")
        records.append({**case, "file": local if case.get("file") and os.path.exists(local)
                        else None})
    return records, record["varied"]


def range_tasks(done, min_bend_radius):
    """The drawing tasks (drawn_all) of the range graphs of the converged cases ``done``
    (records): one figure a quantity (report/envelopes.draw_one) with its limit line
    (utilisation 1, the allowable bend radius when given), and their alt texts; none for
    fewer than two cases."""
    if len(done) < 2:
        return [], []
    S, result = envelopes.envelopes([envelopes.along_line(r["file"]) for r in done])
    limits = {"utilisation": 1.0, "bend_radius": min_bend_radius}
    names = [r["name"] for r in done]
    tasks = [(range_png, (S, name, entry, names, limits.get(name)))
             for name, entry in result.items()]
    return tasks, [f"range graph: {envelopes.shown(name)[0]}" for name in result]


def range_graphs(images, min_bend_radius):
    """The range graphs' section of the <img> ``images``; '' for none."""
    if not images:
        return ""
    return ("<h2>Range graphs</h2><p>Along the line, every converged case and the envelope "
            "over them (shaded: least to largest; bold: the design side); each title names "
            "the case that governs; red dashed: the limit (utilisation 1"
            + (f", the allowable bend radius {min_bend_radius:.4g} m" if min_bend_radius
               else "") + ").</p>" + '<div class="graphs">' + "".join(images) + "</div>")


def summary_column(header, rows, attribute):
    """The numbers of the summary's column of ``attribute`` (its unit in the header),
    blanks left out; [] without that column."""
    column = next((k for k, name in enumerate(header)
                   if name.split(" (")[0] == attribute), None)
    if column is None:
        return []
    return [row[column] for row in rows if isinstance(row[column], (int, float))]


def build(source, min_bend_radius=None):
    """The HTML page of ``source``: a result file or a sweep's folder; ``min_bend_radius``
    (m): the allowable bend radius drawn as a limit."""
    if os.path.isdir(source):
        records, varied = sweep_records(source)
        title = f"Sweep {os.path.basename(os.path.normpath(source))}: {len(records)} case(s)"
    else:
        records, varied = [single_record(source)], []
        title = f"Result {os.path.basename(source)}"
    header, rows = summary.table(records, varied)
    codes = [r["code"] for r in records]
    done = [r for r in records if r["file"] and r["code"] == 0]
    first = next((r for r in records if r["file"]), None)
    parts = [f"<h1>{html.escape(title)}</h1>",
             f"<p>petsc_rod report, {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC; "
             f"{len(done)} of {len(records)} case(s) converged. {UNITS}</p>"]
    parts.append("<h2>Inputs</h2>")
    if first is not None:
        options, types = file_inputs(first["file"])
        if varied:
            parts.append(f"<p>The inputs of case <b>{html.escape(first['name'])}</b>; the "
                         "cases vary " + ", ".join(f"<code>-{html.escape(v)}</code>"
                                                   for v in varied)
                         + " (their values in the summary).</p>")
        parts.append(tables.inputs_html(tables.given_options(first["file"])))
        if types:
            parts.append("<h3>Line types</h3>" + line_types_html(types))
        parts.append("<details><summary>Every option in effect, the solver's included"
                     f'</summary><pre id="options">{html.escape(options)}</pre></details>')
    parts.append("<h2>Results</h2>")
    parts.append('<div class="scroll">' + tables.key_results(header, rows, codes) + "</div>")
    parts.append("<p>'-': a case that did not converge (its state is no equilibrium of the "
                 "case) or a number the case does not have.</p>")
    if any(value > 0 for value in summary_column(header, rows, "friction_stick_nodes")):
        parts.append("<p>Seabed friction: where grounded nodes stick "
                     "(<code>friction_stick_nodes</code>) the equilibrium depends on the load "
                     "path from the as-laid line (the run's start). A sticking node could "
                     "lie anywhere within <code>friction_band</code> (&mu;R / k<sub>s</sub>) "
                     "of its anchor after another path; "
                     "<code>friction_stick_max_use</code> is how much of its limit "
                     "&mu;R a sticking node uses (docs/riser.md &sect;3b).</p>")
    regions = tables.region_rows([r["file"] for r in done], [r["name"] for r in done])
    if regions:
        parts.append("<h3>Regions</h3><p>Each region's extremes over the converged cases "
                     "and the case that governs.</p>" + tables.regions_html(regions))
    parts.append("<details><summary>The summary table (SI units, the numbers of "
                 "summary.csv)</summary><div class=\"scroll\">"
                 + table_html(header, rows, codes) + "</div><p>Units in the header; a "
                 "shaded row is a case that did not converge (its numbers are left out: "
                 "its state is no equilibrium of the case).</p></details>")
    excursions = excursion.points(header, rows, codes)
    if excursions is not None:
        figure = plt.figure(figsize=(13, 3.8), layout="constrained")
        excursion.draw(figure, *excursions)
        parts.append("<h2>Load excursion and touchdown excursion</h2><p>Against the "
                     "fairlead's offset from the first case along the anchor-to-fairlead "
                     "direction (the summary's columns).</p>")
        parts.append(image(figure, "excursion graphs"))
    graph_tasks, graph_alts = range_tasks(done, min_bend_radius)
    drawn = [r for r in records if r["file"] is not None]
    encoded = iter(drawn_all(graph_tasks + [(case_png, (r["file"], min_bend_radius))
                                            for r in drawn]))
    parts.append(range_graphs([img(alt, next(encoded)) for alt in graph_alts],
                              min_bend_radius))
    parts.append("<h2>Cases</h2>")
    for record in records:
        parts.append(f"<h3>{html.escape(record['name'])}</h3>")
        if record["file"] is None:
            parts.append(f"<p>No result file: {html.escape(summary.exit_reason(record['code']))}"
                         ".</p>")
            continue
        parts.append(img(record["name"], next(encoded)))
    body = "\n".join(parts)
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">{summary.REPORT_MARK}"
            f"<title>"
            f"{html.escape(title)}</title><style>{STYLE}</style></head>\n<body>\n{body}\n"
            "</body></html>\n")


def write(source, output, min_bend_radius=None):
    """Write the page of ``source`` to ``output``, whole or not at all
    (io.same_file.write_text_whole); a system's result file has its own
    (report/system_page.py, chosen by report/__main__.py)."""
    write_text_whole(output, build(source, min_bend_radius))
