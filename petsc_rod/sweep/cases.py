"""The cases of a sweep (numpy only, no PETSc): a case is a name and the -rod_* options
it sets (names without the dash, values as the text PETSc would read), on top of the
base options (the options file and the command line).

* ``read_cases``: a case file, a header row naming options and one row per case;
* ``offset_cases``: the vessel offset analysis, the hang-off moved horizontally along a
  heading (near, far, cross) by given distances;
* ``current_cases``: a uniform current of one speed turned to given headings;
* ``product``: every combination of several such lists;
* ``nearest``: the converged case nearest to a case in the swept values (its warm start).

A bad case file or generator is a RodInputError (exit 2) before any run.
"""

import difflib
import re
import shlex
from dataclasses import dataclass, field

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.tables import check_input_file

# A case's name is its result file's name: DIR/<name>.h5.
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._+=-]*$")
# The options a sweep sets itself, per case: a case may not set them.
SWEEP_OWNED = ("rod_output", "rod_table")
# In a case file, the value that leaves an option as the base options give it.
AS_BASE = "-"
# The headings of the offset analysis.
HEADINGS = ("near", "far", "cross")


@dataclass
class Case:
    """One case: its name and the options it sets, {name without '-': text}."""

    name: str
    options: dict = field(default_factory=dict)


def check_name(name, where):
    """Refuse a case name that cannot be a file name (the case's DIR/<name>.h5)."""
    if not NAME.match(name) or name.endswith(".h5"):
        raise RodInputError(f"{where}: case name {name!r}: use letters, digits and . _ + = -"
                            " (it names the case's result file)")


def read_cases(path, known, what="a petsc_rod option; name options without the dash, "
                                  "e.g. rod_end_position"):
    """The cases of file ``path``: whitespace-separated columns (quotes group, '#' starts
    a comment), a header row naming options without the dash (``rod_end_position``) and
    optionally ``name``, then one row per case; a value ``-`` leaves that option as the
    base options give it. ``known(name)`` says whether an option name exists (a
    column it refuses is not ``what``)."""
    check_input_file(path, "-sweep_cases")
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as error:
        raise RodInputError(f"-sweep_cases {path}: cannot read it ({error.__class__.__name__}: "
                            f"{getattr(error, 'strerror', None) or error})") from None
    rows = []
    for number, line in enumerate(text.splitlines(), start=1):
        try:
            words = shlex.split(line, comments=True)
        except ValueError as error:
            raise RodInputError(f"-sweep_cases {path}, line {number}: {error}") from None
        if words:
            rows.append((number, words))
    if len(rows) < 2:
        raise RodInputError(f"-sweep_cases {path}: needs a header row naming options and at "
                            "least one case row")
    (_, header), body = rows[0], rows[1:]
    header = [word.removeprefix("-") for word in header]
    where = f"-sweep_cases {path}, line {rows[0][0]}"
    for column in header:
        if column == "name":
            continue
        if column in SWEEP_OWNED:
            raise RodInputError(f"{where}: column {column}: the sweep sets -{column} itself "
                                "(-sweep_output DIR: DIR/<name>.h5, and DIR/<name>.csv "
                                "when the base options ask for -rod_table)")
        if not known(column):
            close = difflib.get_close_matches(column, [o for o in known.names], n=1) \
                if hasattr(known, "names") else []
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise RodInputError(f"{where}: column {column} is not {what}{hint}")
    if len(set(header)) != len(header):
        raise RodInputError(f"{where}: a column is repeated")
    cases = []
    for number, words in body:
        if len(words) != len(header):
            raise RodInputError(f"-sweep_cases {path}, line {number}: {len(words)} value(s) "
                                f"for {len(header)} column(s)")
        row = dict(zip(header, words))
        name = row.pop("name", f"case{len(cases) + 1}")
        check_name(name, f"-sweep_cases {path}, line {number}")
        cases.append(Case(name, {k: v for k, v in row.items() if v != AS_BASE}))
    check_unique(cases, f"-sweep_cases {path}")
    return cases


def check_unique(cases, where):
    """Refuse two cases of one name (they would write one file)."""
    seen = set()
    for case in cases:
        if case.name in seen:
            raise RodInputError(f"{where}: two cases are named {case.name}")
        seen.add(case.name)


def numbers(text, option):
    """The comma-separated numbers of an option value, refused as bad sweep input when
    they do not parse."""
    try:
        values = np.array([float(v) for v in text.replace(" ", "").split(",") if v != ""])
    except ValueError:
        raise RodInputError(f"{option} {text}: expected comma-separated numbers") from None
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise RodInputError(f"{option} {text}: expected finite numbers")
    return values


def fmt(values):
    """Numbers as an option value."""
    return ",".join(f"{v:.12g}" for v in np.asarray(values, dtype=float).ravel())


def hang_off(values):
    """(the option that places the hang-off, its position, the unit horizontal direction
    from the other held end to it): the hang-off is the higher held end, as for the
    riser numbers' top (quantities/riser_numbers.py: S = L on a tie). ``values``: the base
    options' values (cli.options.read_options)."""
    held = ("clamp", "pin")
    start = np.asarray(values["rod_start_position"], dtype=float)
    end = values["rod_end_position"]
    end = start + [values["rod_length"], 0.0, 0.0] if end is None else np.asarray(end, float)
    if values["rod_start"] not in held or values["rod_end"] not in held:
        raise RodInputError("-sweep_offsets: the offset analysis needs both ends held "
                            "(-rod_start and -rod_end pin or clamp): the hang-off moves, the "
                            "anchor stays")
    if start[2] > end[2]:
        option, top, anchor = "rod_start_position", start, end
    else:
        option, top, anchor = "rod_end_position", end, start
    horizontal = (top - anchor)[:2]
    if np.linalg.norm(horizontal) == 0:
        raise RodInputError("-sweep_offsets: the hang-off is straight above the other end, "
                            "so near and far have no direction")
    return option, top, np.append(horizontal / np.linalg.norm(horizontal), 0.0)


def heading_direction(heading, far):
    """The unit horizontal vector of an offset heading: far = ``far`` (away from the
    anchor), near = -far (toward it), cross = far turned 90 degrees anticlockwise seen
    from above (to the left looking from the anchor to the vessel)."""
    if heading == "far":
        return far
    if heading == "near":
        return -far
    return np.array([-far[1], far[0], 0.0])


def offset_cases(offsets, headings, values):
    """The offset analysis: for each heading and offset d (m), the hang-off (hang_off)
    moved by d along the heading; an offset 0 is one case ("offset0", the base
    position), whatever the headings."""
    option, top, far = hang_off(values)
    for heading in headings:
        if heading not in HEADINGS:
            raise RodInputError(f"-sweep_headings {','.join(headings)}: unknown heading "
                                f"{heading}; use near, far, cross")
    cases = []
    if any(d == 0 for d in offsets):
        cases.append(Case("offset0", {option: fmt(top)}))
    for heading in headings:
        for d in offsets:
            if d != 0:
                position = top + d * heading_direction(heading, far)
                cases.append(Case(f"{heading}{d:g}", {option: fmt(position)}))
    check_unique(cases, "-sweep_offsets")
    return cases


def current_cases(headings, speed, values):
    """A uniform current of ``speed`` (m/s) for each heading (deg): the direction it
    flows toward, anticlockwise from the global x axis seen from above (0 along +x, 90
    along +y; OrcaFlex's convention). ``speed`` None: the base -rod_current's
    magnitude."""
    if values["rod_current_profile"]:
        raise RodInputError("-sweep_current_headings turns a uniform -rod_current; the base "
                            "options give -rod_current_profile (use a case file instead)")
    if speed is None:
        if values["rod_current"] is None:
            raise RodInputError("-sweep_current_headings needs -sweep_current_speed, or a "
                                "-rod_current in the base options to take the speed from")
        speed = float(np.linalg.norm(values["rod_current"]))
    if values["rod_drag"] is None and not values.get("rod_sections"):
        raise RodInputError("-sweep_current_headings: a current needs -rod_drag rho,Cd,D "
                            "in the base options (or -rod_sections, whose line types give "
                            "the drag)")
    cases = []
    for heading in headings:
        angle = np.radians(heading)
        velocity = speed * np.array([np.cos(angle), np.sin(angle), 0.0])
        velocity[np.abs(velocity) < 1e-12 * max(speed, 1e-300)] = 0.0
        cases.append(Case(f"current{heading:g}", {"rod_current": fmt(velocity)}))
    check_unique(cases, "-sweep_current_headings")
    return cases


def product(*lists):
    """Every combination of one case from each list, names joined by '_' and options
    merged; the lists that are None or empty are left out. An option set by two lists is
    refused (RodInputError): the later would silently overwrite the earlier."""
    lists = [cases for cases in lists if cases]
    combined = [Case("", {})]
    for k, cases in enumerate(lists):
        twice = set().union(*(c.options for c in cases)) & set().union(
            *(c.options for other in lists[:k] for c in other))
        if twice:
            raise RodInputError(
                f"-{sorted(twice)[0]} is set by two sources of cases (a case file and a "
                "generator, or two generators): the later would overwrite the earlier; give "
                "it in one of them")
        combined = [Case("_".join(filter(None, (a.name, b.name))), {**a.options, **b.options})
                    for a in combined for b in cases]
    return combined


def varied(cases):
    """The options some case sets, in the order they first appear."""
    names = []
    for case in cases:
        names += [name for name in case.options if name not in names]
    return names


def _as_numbers(text):
    """An option value as numbers, or None when it is not numbers."""
    try:
        values = np.array([float(v) for v in str(text).split(",") if v.strip() != ""])
    except ValueError:
        return None
    return values if values.size and np.all(np.isfinite(values)) else None


def distance(a, b, scales):
    """The distance of two cases' swept values ({option: text}): sqrt of the sum over
    options of (|a - b| / scale)^2, the difference of numbers (their Euclidean norm) over
    that option's spread in the sweep, or 1 for values that differ and are not numbers
    of one length."""
    total = 0.0
    for name, scale in scales.items():
        x, y = _as_numbers(a.get(name)), _as_numbers(b.get(name))
        if x is not None and y is not None and x.shape == y.shape:
            total += (np.linalg.norm(x - y) / scale) ** 2
        elif a.get(name) != b.get(name):
            total += 1.0
    return float(np.sqrt(total))


def spreads(values_of_cases):
    """{option: the norm of the componentwise range of its numbers over the cases} (1
    where it is 0 or not numbers): the scales of ``distance``."""
    names = varied([Case("", v) for v in values_of_cases])
    scales = {}
    for name in names:
        arrays = [_as_numbers(v.get(name)) for v in values_of_cases]
        shapes = {a.shape for a in arrays if a is not None}
        scale = 1.0
        if all(a is not None for a in arrays) and len(shapes) == 1:
            stacked = np.array(arrays)
            scale = float(np.linalg.norm(stacked.max(axis=0) - stacked.min(axis=0))) or 1.0
        scales[name] = scale
    return scales


def nearest(target, candidates, scales):
    """The index in ``candidates`` ({option: text} each) nearest to ``target`` by
    ``distance`` (the first of equals), or None when there is none."""
    if not candidates:
        return None
    gaps = [distance(target, c, scales) for c in candidates]
    return int(np.argmin(gaps))
