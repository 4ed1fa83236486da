"""The summary table of a sweep (h5py and numpy only; serial): one row per case, from
the case's record (name, the options it varied, exit code, how it started) and its
result file's root attributes, written as CSV and Markdown with the units in the header.

The columns are the riser numbers where the file has them (quantities/riser_numbers.py,
quantities/line_results.py's end forces, quantities/module_bends.py's global and local bend
radii, quantities/pressures.py, quantities/section_numbers.py), then any other scalar root attribute
named ``max_*``, ``min_*`` or ``top_*``, or naming a utilisation, von Mises or stress
(what newer versions add: a utilisation, a von Mises stress; vectors such as the end
forces are not columns, their scalar parts are), so that the table shows what the files
hold. The sweep (sweep/runner.py) and the report (report/page.py) both make their tables
here.

Over the cases, two columns that no single file has (excursion_columns): the fairlead's
offset and the touchdown's excursion, both horizontal distances (m) along the direction
from the anchor to the fairlead of the first case with a file (the x axis where that
case has no anchor), from that case's fairlead and touchdown. Against the offset, the
fairlead's horizontal force is a mooring line's load-excursion curve, and the
touchdown's excursion is what an SCR's fatigue and a cable's abrasion check need.
"""

import csv
import html
import io
import json
import re
import signal

import h5py
import numpy as np

from petsc_rod.io.same_file import write_text_whole

# The columns every summary tries first: (column, root attribute, unit if the file
# gives none).
NUMBERS = [
    ("iterations", "total_iterations", "1"),
    ("top_tension", "top_tension", "N"),
    ("top_angle", "top_angle", "deg"),
    ("fairlead_tension", "fairlead_tension", "N"),
    ("fairlead_horizontal", "fairlead_horizontal", "N"),
    ("fairlead_vertical", "fairlead_vertical", "N"),
    ("fairlead_force_x", "fairlead_force_x", "N"),
    ("fairlead_force_y", "fairlead_force_y", "N"),
    ("fairlead_force_z", "fairlead_force_z", "N"),
    ("anchor_tension", "anchor_tension", "N"),
    ("anchor_horizontal", "anchor_horizontal", "N"),
    ("anchor_vertical", "anchor_vertical", "N"),
    ("anchor_uplift", "anchor_uplift", "1"),
    ("touchdown_S", "touchdown_S", "m"),
    ("touchdown_x", "touchdown_x", "m"),
    ("touchdown_y", "touchdown_y", "m"),
    ("grounded_length", "grounded_length", "m"),
    ("min_bend_radius", "min_bend_radius", "m"),
    ("min_bend_radius_S", "max_curvature_S", "m"),
    ("max_curvature", "max_curvature", "1/m"),
    ("module_pitch", "module_pitch", "m"),
    ("global_hog_bend_radius", "global_hog_bend_radius", "m"),
    ("local_hog_bend_radius", "local_hog_bend_radius", "m"),
    ("global_sag_bend_radius", "global_sag_bend_radius", "m"),
    ("local_sag_bend_radius", "local_sag_bend_radius", "m"),
    ("max_wall_tension", "max_wall_tension", "N"),
    ("max_wall_tension_S", "max_wall_tension_S", "m"),
    ("friction_stick_nodes", "friction_stick_nodes", "1"),
    ("friction_slide_nodes", "friction_slide_nodes", "1"),
    ("friction_stick_max_use", "friction_stick_max_use", "1"),
    ("friction_band", "friction_band", "m"),
]
# Other root attributes shown when present and scalar.
EXTRA_PREFIXES = ("max_", "min_", "top_")
# ... and any scalar attribute whose name says it is a stress check.
EXTRA_WORDS = ("utilisation", "utilization", "von_mises", "stress")
# Root attributes that are not results (a run's bookkeeping).
NOT_RESULTS = {"total_iterations", "total_halvings", "undone_iterations"}
# The first characters that make a spreadsheet read a CSV cell as a formula (OWASP, "CSV
# injection"): a text cell starting with one of them is written after a single quote.
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")
# Text that is numbers (an option's value such as -1157,0,1000): no formula can hide in
# it, so it stays as it is.
NUMBERS_TEXT = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?"
                          r"(,[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?)*$")
# The vector attributes read beside the scalars (positions, m, absolute).
POSITIONS = ("fairlead_position", "anchor_position", "touchdown_position")
# The columns computed over the cases (excursion_columns).
EXCURSION_COLUMNS = [("fairlead_offset", "m"), ("touchdown_excursion", "m")]
# What an exit code says, for a case without a result file.
EXIT_REASONS = {0: "converged", 2: "bad input", 3: "not converged", 4: "diverged",
                5: "result not written"}

# The mark in the head of a report page (report/page.py) by which a sweep knows the page of
# an earlier report in its folder as that folder's, to remove with the earlier sweep's
# files (sweep/runner.py claim_folder).
REPORT_MARK = '<meta name="generator" content="petsc_rod.report">'


def is_report_page(path):
    """Whether the file ``path`` is a report page (REPORT_MARK in its first KiB)."""
    try:
        with open(path, "rb") as page:
            return REPORT_MARK.encode() in page.read(1024)
    except OSError:
        return False


def exit_reason(code):
    """The words of a case's exit code (docs/errors.md)."""
    if code >= 128:
        try:
            return f"stopped by {signal.Signals(code - 128).name}"
        except ValueError:
            return f"stopped by signal {code - 128}"
    return EXIT_REASONS.get(code, f"exit {code}")


def file_numbers(path):
    """({attribute: value} of the scalar numeric root attributes, {attribute: unit}) of
    result file ``path``; ({}, {}) when there is no readable file."""
    try:
        with h5py.File(path, "r") as f:
            units = json.loads(f.attrs.get("attribute_units", "{}") or "{}")
            values = {}
            for key, value in f.attrs.items():
                value = np.asarray(value)
                if value.shape == () and np.issubdtype(value.dtype, np.number):
                    values[key] = value.item()
                elif key in POSITIONS and value.shape == (3,):
                    values[key] = value.astype(float)
                elif value.dtype.kind in "SUO" and value.shape == ():
                    values[key] = value.item().decode() if isinstance(value.item(), bytes) \
                        else str(value.item())
            return values, units
    except (OSError, ValueError, KeyError):
        return {}, {}


def number_columns(files):
    """[(column, attribute, unit)]: NUMBERS present in any of ``files`` ((values, units)
    pairs), then the other scalar max_/min_/top_ attributes present, sorted."""
    present = set().union(*(values for values, _ in files)) if files else set()
    units = {}
    for _, u in files:
        units.update(u)
    columns = [(c, a, units.get(a, unit)) for c, a, unit in NUMBERS if a in present]
    known = {a for _, a, _ in NUMBERS} | NOT_RESULTS
    for attribute in sorted(present - known):
        if attribute.startswith(EXTRA_PREFIXES) or any(w in attribute for w in EXTRA_WORDS):
            if all(isinstance(values.get(attribute, 0.0), (int, float)) for values, _ in files):
                columns.append((attribute, attribute, units.get(attribute, "")))
    return columns


def excursion_columns(files, codes):
    """[[fairlead_offset, touchdown_excursion]] (m, module docstring) of each case's
    (values, units) in ``files``, NaN where a case has no such position or did not
    converge (``codes``: the exit codes); None when no converged case has a fairlead."""
    converged = [values for (values, _), code in zip(files, codes)
                 if code == 0 and "fairlead_position" in values]
    if not converged:
        return None
    first = converged[0]
    direction = np.array([1.0, 0.0])
    if "anchor_position" in first:
        chord = first["fairlead_position"][:2] - first["anchor_position"][:2]
        if np.hypot(*chord) > 0.0:
            direction = chord / np.hypot(*chord)
    nan = np.full(3, np.nan)
    rows = []
    for (values, _), code in zip(files, codes):
        shown = values if code == 0 else {}
        rows.append([float((shown.get(key, nan)[:2] - first.get(key, nan)[:2]) @ direction)
                     for key in ("fairlead_position", "touchdown_position")])
    return rows


def table(records, varied):
    """(header, rows) of the summary: case, the varied options, status, start, then the
    number columns. ``records``: dicts with name, options, code, file, start."""
    files = [file_numbers(r["file"]) if r.get("file") else ({}, {}) for r in records]
    columns = number_columns([f for f in files if f[0]])
    header = (["case"] + [f"-{name}" for name in varied] + ["exit", "status", "start"]
              + [f"{column} ({unit})" for column, _, unit in columns])
    rows = []
    for record, (values, _) in zip(records, files):
        status = exit_reason(record["code"])
        reason = values.get("stop_reason")
        if record["code"] == 3 and reason:
            status = f"not converged ({reason})"
        if record.get("error"):         # a run that raised (runner.Sweep._run)
            status = f"failed ({record['error']})"
        row = ([record["name"]] + [record["options"].get(name, "(base)") for name in varied]
               + [record["code"], status, record.get("start", "")])
        # a case that did not converge: its state is no equilibrium of the case, only
        # its iterations are shown
        shown = values if record["code"] == 0 else {"total_iterations":
                                                    values.get("total_iterations", "")}
        row += [shown.get(attribute, "") for _, attribute, _ in columns]
        rows.append(row)
    excursions = excursion_columns(files, [record["code"] for record in records])
    if excursions is not None:
        header += [f"{column} ({unit})" for column, unit in EXCURSION_COLUMNS]
        rows = [row + [value if value == value else "" for value in extra]
                for row, extra in zip(rows, excursions)]
    return header, rows


def cell(value):
    """A table cell as text: numbers to 6 significant digits, inf as 'inf'."""
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def csv_cell(value):
    """A CSV cell: a float at full precision (repr); a text cell that a spreadsheet would
    run as a formula (it starts with one of FORMULA_STARTS and is not numbers) after a
    single quote, which makes it text (OWASP's advice)."""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str) and value.startswith(FORMULA_STARTS) \
            and not NUMBERS_TEXT.match(value):
        return "'" + value
    return value


def markdown_cell(text):
    """``text`` safe in a Markdown table cell: &, <, > as HTML entities (a viewer shows
    them, runs no HTML), | escaped, line breaks as spaces."""
    text = html.escape(text, quote=False).replace("|", "\\|")
    return text.replace("\r", " ").replace("\n", " ")


def write_csv(path, header, rows):
    """The table as CSV, numbers at full precision, text cells kept from running as
    formulas (csv_cell)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(header)
    for row in rows:
        writer.writerow([csv_cell(v) for v in row])
    write_text_whole(path, buffer.getvalue())


def markdown(header, rows):
    """The table as Markdown text, every cell escaped (markdown_cell)."""
    lines = ["| " + " | ".join(markdown_cell(h) for h in header) + " |",
             "|" + "---|" * len(header)]
    for row in rows:
        lines.append("| " + " | ".join(markdown_cell(cell(v)) for v in row) + " |")
    return "\n".join(lines) + "\n"


def write_markdown(path, header, rows, title=None):
    """The table as a Markdown file (with a title line when given)."""
    write_text_whole(path, (f"# {markdown_cell(title)}\n\n" if title else "")
               + markdown(header, rows))


def read_record(path):
    """The sweep's record (DIR/sweep.json: the base options, the varied options, one
    entry per case)."""
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def write_record(path, record):
    """Write the sweep's record as JSON (write_text_whole: never half-written)."""
    write_text_whole(path, json.dumps(record, indent=1))
