"""The report page's tables in engineering units (serial; h5py, numpy): the key results
of each case (from the summary table, sweep/summary.py, so the same numbers as
summary.csv, converted), the regions over the cases (the files' region_* attributes),
and the inputs an engineer gave (the file's ``options``, without the solver's).

Units on the page: forces kN, moments kN m, stresses MPa, angles degrees, lengths m;
each table states its units once, in a column or a header.
"""

import html

import h5py
import numpy as np

# (summary column, label, factor to the unit shown, unit shown), in this order, where the
# summary has the column.
KEY_RESULTS = [
    ("top_tension (N)", "top tension", 1e-3, "kN"),
    ("top_angle (deg)", "top angle from the vertical", 1.0, "deg"),
    ("fairlead_horizontal (N)", "fairlead horizontal force H", 1e-3, "kN"),
    ("fairlead_vertical (N)", "fairlead vertical force V", 1e-3, "kN"),
    ("anchor_tension (N)", "anchor force", 1e-3, "kN"),
    ("anchor_vertical (N)", "anchor vertical force (up)", 1e-3, "kN"),
    ("anchor_uplift (1)", "anchor lifts off", None, ""),
    ("fairlead_offset (m)", "fairlead offset", 1.0, "m"),
    ("touchdown_S (m)", "touchdown S", 1.0, "m"),
    ("touchdown_excursion (m)", "touchdown excursion", 1.0, "m"),
    ("grounded_length (m)", "grounded length", 1.0, "m"),
    ("min_bend_radius (m)", "smallest bend radius", 1.0, "m"),
    ("global_hog_bend_radius (m)", "global hog bend radius (module pitch)", 1.0, "m"),
    ("global_sag_bend_radius (m)", "global sag bend radius (module pitch)", 1.0, "m"),
    ("max_wall_tension (N)", "largest wall tension", 1e-3, "kN"),
    ("max_von_mises (Pa)", "largest von Mises stress", 1e-6, "MPa"),
    ("max_utilisation (1)", "largest utilisation", 1.0, ""),
]
# Options that steer the solver, not the model: folded away on the page.
SOLVER_PREFIXES = ("rod_al_", "rod_d1_", "rod_d2_", "rod_slope_", "rod_z_", "sweep_",
                   "rod_output", "rod_table", "rod_steps", "rod_max_halvings",
                   "rod_initial_load_factor", "rod_initial_friction_anchors", "rod_track_link",
                   "rod_initial_shape", "rod_imperfection", "rod_mesh_grading", "options_file",
                   "log_view")
SOLVER_WORDS = ("_ksp_", "_pc_", "_snes_", "_mat_")


def number_text(value):
    """A number as an engineer reads it: at least 4 significant digits, no e-notation
    between 1e-4 and 1e12; '-' for NaN."""
    value = float(value)
    if not np.isfinite(value):
        return "-" if np.isnan(value) else ("inf" if value > 0 else "-inf")
    if abs(value) >= 1e4 and abs(value) < 1e12:
        return f"{value:.0f}"
    return f"{value:.4g}"


def key_results(header, rows, codes):
    """The key results' table (HTML): the options the cases vary and their status, then
    a row a quantity, its unit once, a column a case (a case that did not converge shows
    '-')."""
    where = {name: k for k, name in enumerate(header)}
    # first what the cases vary and how each ended, as the summary says them
    lines = [f"<tr><td class=text><code>{html.escape(name)}</code></td><td></td>"
             + "".join(f"<td>{html.escape(str(row[k]))}</td>" for row in rows) + "</tr>"
             for k, name in enumerate(header) if name.startswith("-") or name == "status"]
    for column, label, factor, unit in KEY_RESULTS:
        if column not in where:
            continue
        cells = []
        for row, code in zip(rows, codes):
            value = row[where[column]]
            if code or not isinstance(value, (int, float)):
                cells.append("-")
            elif factor is None:
                cells.append("yes" if value else "no")
            else:
                cells.append(number_text(value * factor))
        lines.append(f"<tr><td class=text>{html.escape(label)}</td><td class=text>"
                     f"{html.escape(unit)}</td>" + "".join(f"<td>{c}</td>" for c in cells)
                     + "</tr>")
    head = ("<tr><th>quantity</th><th>unit</th>"
            + "".join(f"<th>{html.escape(str(row[0]))}</th>" for row in rows) + "</tr>")
    return f'<table id="results">{head}{"".join(lines)}</table>'


def region_rows(paths, names):
    """[(region, S from, S to, (max tension N, case), (min bend radius m, case), (max
    moment N m, case))] over the result files ``paths`` (cases ``names``), regions in the
    order they first appear; [] where no file has regions."""
    found = {}
    for path, name in zip(paths, names):
        with h5py.File(path, "r") as f:
            if "region_names" not in f.attrs:
                continue
            a = f.attrs
            for k, region in enumerate(a["region_names"]):
                region = region.decode() if isinstance(region, bytes) else str(region)
                entry = found.setdefault(region, [np.inf, -np.inf, (-np.inf, ""),
                                                  (np.inf, ""), (-np.inf, "")])
                entry[0] = min(entry[0], float(a["region_bounds"][k][0]))
                entry[1] = max(entry[1], float(a["region_bounds"][k][1]))
                for slot, key, pick in ((2, "region_max_tension", max),
                                        (3, "region_min_bend_radius", min),
                                        (4, "region_max_bending_moment", max)):
                    entry[slot] = pick(entry[slot], (float(a[key][k]), name),
                                       key=lambda pair: pair[0])
    return [(region, *entry) for region, entry in found.items()]


def regions_html(rows):
    """The regions' table (HTML; '' without regions): each region's extremes over the
    cases and the case that governs each."""
    if not rows:
        return ""
    head = ("<tr><th>region</th><th>S from (m)</th><th>S to (m)</th>"
            "<th>max tension (kN)</th><th>case</th><th>min bend radius (m)</th><th>case</th>"
            "<th>max moment (kN m)</th><th>case</th></tr>")
    body = "".join(
        f"<tr><td class=text>{html.escape(region)}</td><td>{number_text(lo)}</td>"
        f"<td>{number_text(hi)}</td><td>{number_text(tension[0] / 1e3)}</td>"
        f"<td class=text>{html.escape(tension[1])}</td><td>{number_text(radius[0])}</td>"
        f"<td class=text>{html.escape(radius[1])}</td>"
        f"<td>{number_text(moment[0] / 1e3)}</td><td class=text>{html.escape(moment[1])}</td>"
        "</tr>" for region, lo, hi, tension, radius, moment in rows)
    return f'<table id="regions">{head}{body}</table>'


def given_options(path):
    """[(option, value)] an engineer gave (the file's ``options``: the command line and
    options files), without the solver's (SOLVER_PREFIXES, SOLVER_WORDS)."""
    with h5py.File(path, "r") as f:
        text = f.attrs.get("options", "")
    text = text.decode() if isinstance(text, bytes) else str(text)
    pairs = []
    for line in text.splitlines():
        name, _, value = line.strip().lstrip("-").partition(" ")
        if name and not name.startswith(SOLVER_PREFIXES) \
                and not any(word in name for word in SOLVER_WORDS):
            pairs.append((name, value.strip()))
    return pairs


def inputs_html(pairs):
    """The given inputs as a two-column table (HTML)."""
    body = "".join(f"<tr><td class=text><code>-{html.escape(name)}</code></td>"
                   f"<td class=text>{html.escape(value)}</td></tr>" for name, value in pairs)
    return f'<table id="inputs"><tr><th>option</th><th>value</th></tr>{body}</table>'
