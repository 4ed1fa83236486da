"""The report page of a system's result file (-rod_system ... -rod_output; serial; h5py,
numpy, matplotlib, never PETSc), as report/page.py's of a single line: one
self-contained HTML file with

1. the inputs: the MoorDyn file's text and the reader's notes;
2. the equilibrium: the bodies' poses, each body's 6 x 6 mooring stiffness about its
   stated reference point (not symmetrised: its asymmetry and the lines' moment, the
   rotational block's antisymmetric part, said), the points, and a row a line of its
   end tensions, end forces, largest tension, grounded length and stability;
3. the plan and the elevation of the whole system, and where the file holds them the
   watch circle and the load-excursion curves (figures/system.py) with their tables,
   and the bodies' and free points' natural modes (their periods and shares);
4. each line's own picture as a single line's page draws it (plots.riser_figure of the
   file's group ``lines/<name>``), for up to LINE_PICTURES lines; beyond, the lines are
   listed (their arrays are in the file).

Units: kN, kN m, m, degrees (the file keeps SI units)."""

import html
from datetime import datetime, timezone

import numpy as np

from petsc_rod.figures.read import read_result
from petsc_rod.figures.read_system import figures, names_of, read_system
from petsc_rod.figures.riser import riser_figure
from petsc_rod.report.page import CASE_DPI, STYLE, drawn_all, img, png
from petsc_rod.report.tables import number_text
from petsc_rod.sweep.summary import REPORT_MARK

UNITS = ("Units: forces kN, lengths m, angles degrees; stiffness N/m, N/rad, N m/rad "
         "(the result file keeps SI units: N, m, rad).")
# Lines drawn each in a picture of its own up to this many (a spread, a riser); an
# array's hundreds of lines are listed instead.
LINE_PICTURES = 10
DOFS = ("x", "y", "z", "roll", "pitch", "yaw")
STABLE = {1: "yes", 0: "SADDLE", -1: "-"}


def _table(table_id, head, rows):
    """An HTML table: ``head`` the header cells' texts, ``rows`` lists of cells (a str
    left-aligned, a number as number_text)."""
    def cell(value):
        if isinstance(value, str):
            return f"<td class=text>{html.escape(value)}</td>"
        return f"<td>{number_text(value + 0.0)}</td>"
    header = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    body = "".join("<tr>" + "".join(cell(v) for v in row) + "</tr>" for row in rows)
    return f'<div class="scroll"><table id="{table_id}"><tr>{header}</tr>{body}</table></div>'


def stiffness_html(body):
    """The body's 6 x 6 stiffness table and what it is about."""
    K = np.asarray(body["stiffness"])
    rows = [[f"{'F' if i < 3 else 'M'}{DOFS[i]}"] + [float(v) for v in K[i]]
            for i in range(6)]
    reference = ", ".join(f"{v:.4f}" for v in body["reference"])
    moment = ", ".join(f"{v:.6g}" for v in body["moment"])
    return (f"<h3>{html.escape(body['name'])}: mooring stiffness</h3><p>About the "
            f"reference point ({reference}) m at the equilibrium, global axes; rows the "
            "force and moment, columns the increments dX and dtheta (N/m, N, N/rad, "
            "N m/rad). Not symmetrised: its asymmetry |K - K<sup>T</sup>|/|K| is "
            f"<b>{body['asymmetry']:.3g}</b>, the rotational block's antisymmetric part "
            f"[M]<sub>x</sub> of the lines' moment M = ({moment}) N m about the "
            "reference point (a turned fairlead's arm turns the lines' force).</p>"
            + _table(f"stiffness_{body['name']}", ["", *(f"d{d}" for d in DOFS)], rows))


def lines_html(lines):
    """The table of every line's ends, largest tension and grounded length."""
    rows = []
    for line in lines:
        tension, force = line["end_tensions"], np.linalg.norm(line["end_forces"], axis=1)
        rows.append([line["name"], line["start"], line["end"], tension[0] / 1e3,
                     tension[1] / 1e3, force[0] / 1e3, force[1] / 1e3,
                     line["max_tension"] / 1e3, line["grounded_length"],
                     STABLE.get(line["stable"], "-")])
    return _table("lines", ["line", "start at", "end at", "start tension (kN)",
                            "end tension (kN)", "|F| on start (kN)", "|F| on end (kN)",
                            "largest tension (kN)", "grounded length (m)", "stable"], rows)


def sweep_html(kind, found):
    """The table of a sweep's cases (its rows with an equilibrium; the system's verdict
    at each, SADDLE in capitals, where the file has it) and its failed cases."""
    names = found["lines"]
    grounded = "min_grounded_line" in found
    verdicts = found.get("verdict")
    rows = []
    for k in range(found["heading"].size):
        row = [float(found["heading"][k]), float(found["load"][k]) / 1e3]
        row += ([float(found["x_offset"][k]), float(found["y_offset"][k])]
                if kind == "watch_circle" else
                [float(found["offset"][k]), float(found["restoring"][k]) / 1e3])
        row += [float(found["max_tension"][k]) / 1e3,
                names[int(found["max_tension_line"][k])]]
        if grounded:
            row += [float(found["min_grounded"][k]), names[int(found["min_grounded_line"][k])]]
        if verdicts is not None:
            row.append(STABLE.get(int(verdicts[k]), "-"))
        rows.append(row)
    head = ["heading (deg)", "load (kN)"] + (["x offset (m)", "y offset (m)"]
                                             if kind == "watch_circle" else
                                             ["offset (m)", "restoring (kN)"])
    head += ["largest tension (kN)", "line"] + (["smallest grounded (m)", "line"]
                                                 if grounded else [])
    head += ["stable"] if verdicts is not None else []
    failed = str(found.get("failed", ""))
    note = (f"<p>Cases without an equilibrium, left out: {html.escape(failed)}</p>"
            if failed else "")
    if "system_verdict" in found:
        note += (f"<p>The system's verdict at its cases: "
                 f"{html.escape(str(found['system_verdict']))} (a saddle: an equilibrium "
                 "that is not a minimiser, kept and marked).</p>")
    return _table(kind, head, rows) + note


def modes_html(modes):
    """The section of the bodies' and free points' modes (the file's system/modes): a
    row per mode, its frequency, period, dominant unknown and the shares over 0.05; or
    why they were refused."""
    head = ("<h2>Natural modes of the bodies and free points</h2><p>About the "
            "equilibrium, undamped, the lines quasi-static (their static stiffness; the "
            "lines' mass " + ("lumped half at each end" if int(modes.get("line_mass", 0))
                              else "left out") + "; their own dynamics in their modes "
            "with the ends held).</p>")
    if "refused" in modes:
        return head + f"<p id=\"modes_refused\">Refused: {html.escape(str(modes['refused']))}</p>"
    dofs, labels = names_of(modes["dofs"]), names_of(modes["labels"])
    rows = []
    for k, shares in enumerate(np.atleast_2d(modes["shares"])):
        big = [i for i in np.argsort(-shares) if shares[i] >= 0.05]
        rows.append([k + 1.0, float(modes["frequencies"][k]), float(modes["periods"][k]),
                     labels[k], ", ".join(f"{dofs[i]} {shares[i]:.2f}" for i in big)])
    return head + _table("modes", ["mode", "f (Hz)", "T (s)", "dominant",
                                   "shares of the kinetic energy"], rows)


def line_png(path, name, seabed, surface):
    """The base64 PNG of line ``name``'s picture (a single line's, of the file's group
    lines/<name>), with the system's flat ``seabed`` and sea ``surface`` (m): a line's
    group holds no sea of its own."""
    result = read_result(path, f"lines/{name}")
    result.sea_surface = surface
    if result.seabed is None:
        result.seabed = seabed
    return png(riser_figure(result), CASE_DPI)


def build(path):
    """The HTML page of the system's result file ``path``."""
    found = read_system(path)
    a = found.attributes
    title = (f"System {found.name}: {len(found.lines)} line(s), "
             f"{len(found.picture['points'])} point(s), {len(found.bodies)} body(ies)")
    drawn = figures(found)
    pictured = [line["name"] for line in found.lines][:LINE_PICTURES] \
        if len(found.lines) <= LINE_PICTURES else []
    images = {suffix: png(figure) for suffix, figure in drawn.items()}
    encoded = drawn_all([(line_png, (path, name, found.picture["seabed"],
                                     found.picture["surface"]))
                         for name in pictured])
    parts = [f"<h1>{html.escape(title)}</h1>",
             f"<p>petsc_rod report, {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC. "
             f"{UNITS}</p>",
             "<h2>Inputs</h2><p>The MoorDyn file as given:</p>"
             f'<details><summary>The MoorDyn file</summary><pre id="input_text">'
             f"{html.escape(str(a.get('input_text', '')))}</pre></details>"]
    notes = [n for n in str(a.get("notes", "")).splitlines() if n]
    if notes:
        parts.append('<p>What the reader substituted or ignored:</p><ul id="notes">'
                     + "".join(f"<li>{html.escape(n)}</li>" for n in notes) + "</ul>")
    parts.append(f"<h2>Equilibrium</h2><p>{'Converged' if int(a['converged']) else 'NOT converged'}"
                 f" in {int(a['iterations'])} Newton iteration(s), "
                 f"{int(a['halvings'])} halving(s) of the load step, scaled residual "
                 f"{float(a['residual']):.3g}, on {int(a['ranks'])} rank(s).</p>")
    if found.bodies:
        parts.append(_table("bodies", ["body", "x (m)", "y (m)", "z (m)", "roll (deg)",
                                       "pitch (deg)", "yaw (deg)", "asymmetry"],
                            [[b["name"], *map(float, b["position"][:3]),
                              *map(float, np.degrees(b["position"][3:])), b["asymmetry"]]
                             for b in found.bodies]))
    parts.append("<h3>Points</h3>" + _table(
        "points", ["point", "kind", "x (m)", "y (m)", "z (m)"],
        [[name, kind, *map(float, x)] for name, kind, x in found.picture["points"]]))
    parts.append("<h3>Lines</h3><p>End tensions: the end elements' tension along the "
                 "line; |F|: the force on the point or body.</p>" + lines_html(found.lines))
    for body in found.bodies:
        parts.append(stiffness_html(body))
    parts.append("<h2>Plan and elevation</h2>" + img("plan and elevation", images[""]))
    for suffix, kind, heading in (("_watch_circle", "watch_circle", "Watch circle"),
                                  ("_excursion", "excursion", "Load-excursion curves")):
        sweep = getattr(found, kind)
        if sweep is None:
            continue
        parts.append(f"<h2>{heading} of {html.escape(str(sweep['body']))}</h2>")
        if suffix in images:
            parts.append(img(heading.lower(), images[suffix]))
        parts.append(sweep_html(kind, sweep))
    if found.modes is not None:
        parts.append(modes_html(found.modes))
    parts.append("<h2>Each line</h2>")
    if pictured:
        for name, encoded_line in zip(pictured, encoded):
            parts.append(f"<h3>{html.escape(name)}</h3>" + img(f"line {name}", encoded_line))
    else:
        parts.append(f"<p>{len(found.lines)} lines (more than {LINE_PICTURES}: not drawn "
                     "one by one; each line's arrays are in the file's group "
                     "lines/&lt;name&gt;):</p><ul id=\"line_list\">"
                     + "".join(f"<li>{html.escape(line['name'])}</li>"
                               for line in found.lines) + "</ul>")
    body = "\n".join(parts)
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">{REPORT_MARK}"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head>\n<body>\n"
            f"{body}\n</body></html>\n")
