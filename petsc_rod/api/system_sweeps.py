"""A system's sweeps after its equilibrium (docs/systems.md, "Excursions and the watch
circle", "Running a system"): the watch circle (-rod_system_watch_circle) and the
load-excursion curves (-rod_system_excursion) of system/excursions.py on the run's
solver, their groups of the result file (``system/watch_circle``,
``system/excursion``), their tables (FILE_watch_circle.csv, FILE_excursion.csv) and the
run's lines.

A case without an equilibrium is a gap: its row is left out of the file's group and
of the table (the file lists it in ``failed_heading``, ``failed_load`` and the
``failed`` attribute), so that no NaN is ever written as a result. The smallest
grounded length's columns are left out when no line has a seabed, the lowest
eigenvalue's when no case has one (a system that is not conservative); a case with an
equilibrium but without a lowest eigenvalue (its verdict none: a stiffness that is not
finite) keeps its row, NaN in the file's ``lowest_eigenvalue`` and an empty cell in the
table.

A sweep needs a body its load moves: one held wherever its headings push it (a
Coupled, CoupledPinned or Fixed body of a MoorDyn file) is refused in one line before
anything is solved (swept_body: the option named on the command line, parse_sweeps; the
``Sweeps`` field through the API, check_sweeps), as no offset but 0 m could come out.

Each case carries the system's verdict (system/excursions.py): the table's ``verdict``
(stable, saddle, none; the file's codes 1, 0, -1 of ``system_stable``) and
``lowest_eigenvalue``; a saddle's row is kept and marked, the group's ``converged`` is
0 where a case is a saddle (as the system group's at a saddle at rest) or has no
equilibrium, and the run says the verdicts in one line a sweep and exits 3 at a saddle
(cli_system.py)."""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.system.excursions import (TABLE_UNITS, VERDICT_WORDS, held_text,
                                         load_excursion, watch_circle)

# The watch circle's headings when none are given: every 15 degrees.
WATCH_HEADINGS = 24
# The load-excursion curves' loads when none are given: 0 to LOADMAX in this many steps.
EXCURSION_LOADS = 10
# The columns naming a line (written as its index into the file's ``line_names``).
LINE_COLUMNS = ("max_tension_line", "min_grounded_line")
# The file's codes of the table's ``verdict`` words (the system group's system_stable).
VERDICT_CODES = {word: code for code, word in VERDICT_WORDS.items()}
VERDICT_UNIT = "1 stable, 0 a saddle of the system, -1 no verdict (system_stable's codes)"
# The run's words of a sweep (run_lines) and what it counts.
SWEEP_WORDS = {"watch_circle": ("watch circle", "heading"),
               "excursion": ("load-excursion curves", "case")}


@dataclass(frozen=True)
class Sweeps:
    """What the run sweeps after the equilibrium: ``watch_circle`` (body, load N,
    headings (h,) deg) and ``excursion`` (body, loads (m,) N, headings (h,) deg), each
    or both None."""

    watch_circle: tuple = None
    excursion: tuple = None

    def __bool__(self):
        return self.watch_circle is not None or self.excursion is not None


def _fields(option, text, least, most):
    fields = [field.strip() for field in text.split(",")]
    if not least <= len(fields) <= most:
        raise RodInputError(f"-{option} {text!r}: expected {USAGE[option]}")
    return fields


def _finite(values, floor=None, strict=True):
    """Whether every one of ``values`` (a number or an array) is finite and, given a
    ``floor``, above it (``strict``) or not below it: the test of a sweep's numbers, the
    same on the command line's text (_number) and on the API's Sweeps (check_sweeps)."""
    values = np.asarray(values, dtype=float)
    return bool(np.all(np.isfinite(values)) and (
        floor is None or np.all(values > floor if strict else values >= floor)))


def _number(option, text, value, what, positive=True):
    try:
        number = float(value)
    except ValueError:
        number = np.nan
    if not _finite(number, 0.0 if positive else None):
        raise RodInputError(f"-{option} {text!r}: {value!r} is not {what}; expected "
                            f"{USAGE[option]}")
    return number


def _count(option, text, value, what):
    number = _number(option, text, value, what)
    if number != int(number):
        raise RodInputError(f"-{option} {text!r}: {value!r} is not {what}; expected "
                            f"{USAGE[option]}")
    return int(number)


USAGE = {"rod_system_watch_circle": "BODY,LOAD[,N_HEADINGS] (a body's name, the load in "
         "N, positive, the number of headings, default 24)",
         "rod_system_excursion": "BODY,LOADMAX[,N_LOADS[,HEADING,...]] (a body's name, "
         "the largest load in N, positive, the number of load steps, default 10, the "
         "headings in degrees, default 0)"}


def swept_body(where, name, headings, system):
    """``name``, a body of ``system`` that a horizontal load along ``headings`` (deg)
    moves; else RodInputError in one line that starts with ``where`` (the option and its
    text, or the Sweeps field): no such body, or one held where the load pushes it
    (excursions.held_text)."""
    names = [body.name for body in system.bodies]
    if name not in names:
        raise RodInputError(f"{where}: no body {name!r} in the system; its bodies: "
                            f"{', '.join(names) or 'none'}")
    held = held_text(system.bodies[names.index(name)], headings)
    if held:
        raise RodInputError(f"{where}: {held}")
    return name


def parse_sweeps(watch_text, excursion_text, system):
    """The Sweeps of the options' texts (None: not asked) on ``system``; RodInputError
    in one line for a malformed one."""
    circle = excursion = None
    if watch_text:
        option = "rod_system_watch_circle"
        fields = _fields(option, watch_text, 2, 3)
        load = _number(option, watch_text, fields[1], "a positive load in N")
        count = (_count(option, watch_text, fields[2], "a whole number of headings")
                 if len(fields) > 2 else WATCH_HEADINGS)
        headings = 360.0 * np.arange(count) / count
        circle = (swept_body(f"-{option} {watch_text!r}", fields[0], headings, system),
                  load, headings)
    if excursion_text:
        option = "rod_system_excursion"
        fields = _fields(option, excursion_text, 2, 2 + 360)
        largest = _number(option, excursion_text, fields[1], "a positive load in N")
        count = (_count(option, excursion_text, fields[2], "a whole number of load steps")
                 if len(fields) > 2 else EXCURSION_LOADS)
        headings = np.array([_number(option, excursion_text, value, "a heading in degrees",
                                     positive=False) for value in fields[3:]] or [0.0])
        excursion = (swept_body(f"-{option} {excursion_text!r}", fields[0], headings,
                                system), largest * np.arange(count + 1) / count, headings)
    return Sweeps(circle, excursion)


# The API's form of each sweep (check_sweeps' refusal of another).
FORMS = {"watch_circle": "(body name, load N, headings deg): a finite positive load and "
                         "at least one finite heading",
         "excursion": "(body name, loads N, headings deg): at least one load, each finite "
                      "and not negative, and at least one finite heading"}


def check_sweeps(sweeps, system):
    """RodInputError in one line, naming the ``Sweeps`` field, for a sweep of ``sweeps``
    that ``system`` cannot run: not of its form (FORMS: the numbers the command line's
    parse_sweeps accepts), or of a body it does not have or holds wherever the load
    pushes it (swept_body); before anything is solved (api/system_run.run_system)."""
    for kind, form in FORMS.items():
        given = getattr(sweeps, kind, None)
        if given is None:
            continue
        try:
            body, loads, headings = given
            loads = np.asarray(loads, dtype=float)
            headings = np.asarray(headings, dtype=float)
        except (TypeError, ValueError):
            raise RodInputError(f"Sweeps.{kind}: expected {form}") from None
        circle = kind == "watch_circle"
        if (loads.ndim != (0 if circle else 1) or headings.ndim != 1 or not headings.size
                or not loads.size or not _finite(headings)
                or not _finite(loads, 0.0, strict=circle)):     # a load > 0; loads >= 0
            raise RodInputError(f"Sweeps.{kind}: expected {form}")
        swept_body(f"Sweeps.{kind}", body, headings, system)


def run_sweeps(solver, sweeps):
    """{'watch_circle': WatchCircle, 'excursion': LoadExcursion} of those asked, on the
    solved ``solver`` (system/excursions: warm re-solves, the solver left at rest).
    Collective."""
    found = {}
    if sweeps.watch_circle is not None:
        body, load, headings = sweeps.watch_circle
        found["watch_circle"] = watch_circle(solver, body, load, headings)
    if sweeps.excursion is not None:
        body, loads, headings = sweeps.excursion
        found["excursion"] = load_excursion(solver, body, loads, headings)
    return found


def solved_rows(result):
    """{column: array} of ``result.table()`` with only the rows of the cases that
    have an equilibrium, the lines as indices into ``result.lines``, the verdicts as
    their codes (VERDICT_CODES), without the grounded length's columns where no line
    has a seabed and the lowest eigenvalue's where no case has one (NaN at a case
    without one); (columns, {column: unit})."""
    table = result.table()
    keep = np.isfinite(np.asarray(result.poses, float).reshape(-1, 6)[:, 0])
    index = {name: k for k, name in enumerate(result.lines)}
    columns = {}
    left_out = {"min_grounded": not np.any(np.isfinite(result.min_grounded)),
                "lowest_eigenvalue": not np.any(np.isfinite(
                    table["lowest_eigenvalue"][keep]))}
    for name, values in table.items():
        if any(name.startswith(prefix) and out for prefix, out in left_out.items()):
            continue
        values = np.asarray(values)[keep]
        if name in LINE_COLUMNS:
            values = np.array([index[v] for v in values], dtype=float)
        if name == "verdict":
            values = np.array([VERDICT_CODES[v] for v in values], dtype=float)
        columns[name] = np.asarray(values, dtype=float)
    units = {name: ("index into line_names" if name in LINE_COLUMNS else
                    VERDICT_UNIT if name == "verdict" else TABLE_UNITS[name])
             for name in columns}
    return columns, units


def file_group(result):
    """(datasets, attributes, units) of the result file's group of ``result`` (a
    WatchCircle or a LoadExcursion)."""
    data, units = solved_rows(result)
    failed = result.failed
    data["failed_heading"] = np.array([f[0] for f in failed], dtype=float)
    data["failed_load"] = np.array([f[1] for f in failed], dtype=float)
    units.update(failed_heading="deg", failed_load="N")
    tension, *_ = result.largest_tension
    saddles = len(result.saddles())
    attributes = {"body": result.body, "line_names": ",".join(result.lines),
                  "rest": np.asarray(result.rest, float),
                  "failed": "\n".join(f"heading {h:g} deg, load {f:g} N: {why}"
                                      for h, f, why in failed),
                  "rows": "a case with an equilibrium; the cases without one are left out "
                          "(failed_heading, failed_load, failed)",
                  "converged": int(saddles == 0 and not failed), "saddles": saddles,
                  "system_verdict": result.verdict_text()}
    units_of = {"body": "text", "line_names": "text", "rest": "m, m, m, rad, rad, rad",
                "failed": "text", "rows": "text", "converged": "1", "saddles": "1",
                "system_verdict": "text"}
    if np.isfinite(tension):
        attributes["largest_tension"] = tension
        units_of["largest_tension"] = "N"
    grounded, *_ = result.smallest_grounded
    if np.isfinite(grounded):
        attributes["smallest_grounded"] = grounded
        units_of["smallest_grounded"] = "m"
    if hasattr(result, "load"):
        attributes["load"] = result.load
        units_of["load"] = "N"
        if np.any(np.isfinite(result.offsets)):
            attributes["largest_offset"] = result.largest_offset
            units_of["largest_offset"] = "m"
    units.update(units_of)
    return data, attributes, units


def table_text(result):
    """The CSV text of ``result``'s table: a row per case with an equilibrium, the
    lines by name, an empty cell where a case has no lowest eigenvalue."""
    data, units = solved_rows(result)
    header = ",".join(f"{name} ({units[name]})" if name not in (*LINE_COLUMNS, "verdict")
                      and units[name] else name for name in data)
    rows = [header]
    for k in range(len(next(iter(data.values())))):
        rows.append(",".join(result.lines[int(data[name][k])] if name in LINE_COLUMNS
                             else VERDICT_WORDS[int(data[name][k])] if name == "verdict"
                             else "" if np.isnan(data[name][k])
                             else f"{data[name][k] + 0.0:.12g}" for name in data))
    return "\n".join(rows) + "\n"


def run_lines(found):
    """The run's lines about the sweeps ``found``."""
    lines = []
    for kind, result in found.items():
        value, *where = result.largest_tension
        grounded, *at = result.smallest_grounded
        if kind == "watch_circle":
            head = (f"petsc_rod: watch circle of {result.body} under {result.load:.6g} N "
                    f"through {result.headings.size} heading(s)")
            if np.any(np.isfinite(result.offsets)):
                head += f": largest offset {result.largest_offset:.6g} m"
            place = "heading {:g} deg, {}"
        else:
            head = (f"petsc_rod: load-excursion curves of {result.body}, loads up to "
                    f"{result.loads.max():.6g} N in {result.loads.size - 1} step(s) at "
                    f"heading(s) {', '.join(f'{h:g}' for h in result.headings)} deg")
            place = "heading {:g} deg, load {:.6g} N, {}"
        if np.isfinite(value):
            head += f"; largest tension {value:.6g} N ({place.format(*where)})"
        if np.isfinite(grounded):
            head += f"; smallest grounded length {grounded:.6g} m ({place.format(*at)})"
        lines.append(head)
        for heading, load, why in result.failed:
            lines.append(f"petsc_rod: warning: {kind.replace('_', ' ')}: no equilibrium at "
                         f"heading {heading:g} deg, load {load:.6g} N (left out): {why}")
        what, unit = SWEEP_WORDS[kind]
        solved = int(np.count_nonzero(np.isfinite(result.poses.reshape(-1, 6)[:, 0])))
        total = result.poses.reshape(-1, 6).shape[0]
        lines.append(f"petsc_rod: {what}: {solved} {unit}(s)"
                     + (f" of {total} with an equilibrium" if solved < total else "")
                     + f", the system's verdict: {result.verdict_text()}")
    return lines


def sweep_saddles(found):
    """'the watch circle of Body1 has 2 saddle(s) of the system: headings 90, 105 deg'
    (the sweeps of ``found`` with a saddle, joined by '; '), '' where none has one:
    the command line's exit 3 (cli_system.py), as at a saddle at rest."""
    return "; ".join(f"the {SWEEP_WORDS[kind][0]} of {result.body} "
                     f"{'have' if kind == 'excursion' else 'has'} {len(saddles)} saddle(s) "
                     f"of the system: {result.where(saddles)}"
                     for kind, result in found.items() if (saddles := result.saddles()))


def sweep_gaps(found):
    """'the watch circle of Body1 has no equilibrium at 1 of its 24 cases: heading 120
    deg' (the sweeps of ``found`` with a case left without one, joined by '; '), ''
    where every case has one: the command line's exit 3 (cli_system.py), the result
    incomplete."""
    return "; ".join(f"the {SWEEP_WORDS[kind][0]} of {result.body} "
                     f"{'have' if kind == 'excursion' else 'has'} no equilibrium at "
                     f"{len(result.failed)} of {len(result.cases())} case(s): "
                     f"{result.where([(h, f) for h, f, _ in result.failed])}"
                     for kind, result in found.items() if result.failed)
