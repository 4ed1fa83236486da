"""``python -m petsc_rod -rod_system FILE``: a system of lines, points and bodies read
from a MoorDyn version 2 input file, solved on the path the Python API's solve_system
takes (api/system_run.py), with the command line's options, lines and exit codes
(docs/systems.md, "Running a system"; docs/errors.md: 0 converged, 2 bad input, 3 no
equilibrium found or a saddle of the system, at rest or at a case of a sweep (the file
written; at a sweep's case without an equilibrium, with the other cases), 4
non-finite numbers or a PETSc error, 5 the result could not be written).

Of the -rod_* options a system takes its own (-rod_system, -rod_system_element_length,
-rod_system_body_load, -rod_system_offset, -rod_system_line_length, -rod_system_steps,
-rod_system_predictor, -rod_system_watch_circle, -rod_system_excursion, -rod_system_modes,
-rod_system_modes_line_mass), the seabed's plane or profile (-rod_seabed_slope,
-rod_seabed_direction, -rod_seabed_origin, -rod_seabed_profile: a MoorDyn file carries
none), a current (-rod_current or -rod_current_profile: MoorDyn's Currents is not
read), the outputs (-rod_output, -rod_table), the modes of each line with its ends
held (-rod_modes N or -rod_modes_range, -rod_modes_added_mass, -rod_modes_mass,
-rod_modes_inertia) and the line solver's (-rod_al_*, -rod_max_halvings: every line the
same); every other -rod_* option describes a single line's scene or load path, which
the file gives, and is refused in one line naming them. It sits above system/ and cli/
(it needs both: the option table, and the system's run), run by __main__.py when
-rod_system is given."""

import dataclasses
import os
import sys

import numpy as np
from petsc4py import PETSc

from petsc_rod.api.system_run import (LINE_OPTIONS, MODES_OPTIONS, body_modes_request,
                                     modes_request, run_system, written_paths)
from petsc_rod.api.system_sweeps import parse_sweeps, sweep_gaps, sweep_saddles
from petsc_rod.cli.line_run import AgreedFailures, petsc_failure
from petsc_rod.cli.options import (BY_NAME, check_anderson_depth, check_same_on_every_rank,
                                   check_factor_switches, check_snes_type,
                                   help_text, read_options, unused_options, whole_values)
from petsc_rod.cli.options_files import every_options_file
from petsc_rod.cli.scene_options import current_from_options
from petsc_rod.cli.signals import Interrupts
from petsc_rod.environment.profiles import read_seabed_profile
from petsc_rod.errors import (RodDivergedError, RodError, RodInputError,
                              RodNotConvergedError, on_every_rank)
from petsc_rod.io.same_file import replaced_input
from petsc_rod.model.moordyn import read_moordyn
from petsc_rod.model.names import FIELD_NAMES, Names
from petsc_rod.model.system_check import check_reach
from petsc_rod.model.values import MAX_MAGNITUDE
from petsc_rod.system.body_modes import SystemModes
from petsc_rod.system.equilibrium import Settings
from petsc_rod.system.held_line import friction_notes, line_sea
from petsc_rod.tables import read_text

# What a system's run takes beside the line solver's options (LINE_OPTIONS).
SYSTEM_OPTIONS = ("rod_system", "rod_system_element_length", "rod_system_body_load",
                  "rod_system_offset", "rod_system_line_length", "rod_system_steps",
                  "rod_system_predictor", "rod_system_watch_circle", "rod_system_excursion",
                  "rod_system_modes", "rod_system_modes_line_mass",
                  "rod_output", "rod_table", *(f"rod_{name}" for name in MODES_OPTIONS))
# The single line's options of a sloping or profiled seabed a system file's sea takes: a
# MoorDyn file gives the seabed's depth (WtrDpth) only, which is the plane's height at
# its origin; a profile's rows give the heights themselves, in place of the depth.
SEABED_OPTIONS = ("rod_seabed_slope", "rod_seabed_direction", "rod_seabed_origin",
                  "rod_seabed_profile")
SEABED_NAMES = Names({**{name.removeprefix("rod_"): f"-{name}" for name in SEABED_OPTIONS},
                      "seabed": "seabed (the file's WtrDpth)"}, FIELD_NAMES.__getitem__)
# The single line's options of a current a system's sea takes (a MoorDyn file's own,
# Currents and its grid files, are not read): uniform, or by depth below the system's
# sea surface, z = 0 (docs/systems.md, "The sea of a system's lines"); its drag on each
# line from the line type's Cd and Diam, on each free point from its CdA.
CURRENT_OPTIONS = ("rod_current", "rod_current_profile")
CURRENT_NAMES = Names({"current": "-rod_current", "current_profile": "-rod_current_profile",
                       "line_types": "the -rod_system file's LINE TYPES",
                       "sections": "the -rod_system file's LINES (UnstrLen)"},
                      FIELD_NAMES.__getitem__)


def refused_options(given):
    """The -rod_* options of ``given`` a system does not take (a single line's scene and
    load path), in the table's order."""
    taken = (set(SYSTEM_OPTIONS) | set(SEABED_OPTIONS) | set(CURRENT_OPTIONS)
             | {f"rod_{name}" for name in LINE_OPTIONS})
    return [name for name in BY_NAME if name in given and name not in taken]


def named_rows(option, text, names, fields):
    """[(name, numbers (n,))] of ``option``'s ``text``: NAME,v1,...,vn parts separated by
    ':', each NAME one of ``names`` (a dict or a list), n = len(``fields``) finite
    numbers (``fields``: the words of the numbers, 'fx in N'); RodInputError naming the
    part that is not, and a NAME given twice (whose parts would otherwise add or
    overwrite without a word)."""
    rows = []
    for part in text.split(":"):
        words = [word.strip() for word in part.split(",")]
        form = f"NAME,{','.join(f.split()[0] for f in fields)}"
        if len(words) != len(fields) + 1:
            raise RodInputError(f"-{option} {part!r}: expected {form} ({', '.join(fields)}), "
                                "several separated by ':'")
        if words[0] not in names:
            raise RodInputError(f"-{option} {part!r}: no {'/'.join(names.kinds)} "
                                f"{words[0]!r} in the system; its names: "
                                f"{', '.join(names) or 'none'}")
        try:
            values = np.array([float(v) for v in words[1:]])
        except ValueError:
            raise RodInputError(f"-{option} {part!r}: {len(fields)} numbers after the "
                                f"name ({', '.join(fields)})") from None
        if not np.all(np.isfinite(values)):
            raise RodInputError(f"-{option} {part!r}: finite numbers only")
        if words[0] in (name for name, _ in rows):
            raise RodInputError(f"-{option}: {words[0]} is given twice; give each "
                                f"{'/'.join(names.kinds)} once, its values in one part "
                                f"{form}")
        rows.append((words[0], values))
    return rows


class _Names(dict):
    """{name: item} that says what kinds of things it names (named_rows' message)."""

    def __init__(self, items, kinds):
        super().__init__((item.name, item) for item in items)
        self.kinds = kinds


def body_loads(text, system):
    """``system`` with the loads of -rod_system_body_load ``text`` (NAME,fx,fy,fz,mx,my,mz
    separated by ':') added to its bodies' own."""
    bodies = _Names(system.bodies, ("body",))
    for name, load in named_rows("rod_system_body_load", text, bodies,
                                 ("fx in N", "fy in N", "fz in N", "mx in N m", "my in N m",
                                  "mz in N m")):
        body = bodies[name]
        bodies[name] = dataclasses.replace(body, load=tuple(np.add(body.load, load)))
    return dataclasses.replace(system, bodies=tuple(bodies[b.name] for b in system.bodies))


def check_movable(node, move, option, hint):
    """Refuse to move the Point or Body ``node`` by ``move`` ((3,), m: the directions a
    sweep moves it in, or one offset) where its equilibrium decides where it is: a free
    point, or a body free in a moved direction; ``option`` names what moves it, ``hint``
    how else to move a free body (a load)."""
    if hasattr(node, "kind"):
        if node.kind == "free":
            raise RodInputError(f"{option} {node.name}: a free point, whose equilibrium "
                                "decides where it is; offset a fixed or prescribed point "
                                "or a held body")
        return
    free = [axis for axis, d, held in zip("xyz", move, node.held) if d != 0 and not held]
    if free:
        raise RodInputError(f"{option} {node.name}: body {node.name} is free in "
                            f"{', '.join(free)}, where its equilibrium decides where it "
                            "is; hold it there (Fixed or Coupled in the file) or move it "
                            f"by a load ({hint})")


def offsets(text, system):
    """``system`` with the offsets of -rod_system_offset ``text`` (NAME,dx,dy,dz separated
    by ':', m, global axes) added to the positions of its fixed or prescribed points and
    of its bodies in their held translations; RodInputError for a free point, or a body
    moved in a direction it is free in (check_movable)."""
    nodes = _Names((*system.points, *system.bodies), ("point", "body"))
    for name, move in named_rows("rod_system_offset", text, nodes,
                                 ("dx in m", "dy in m", "dz in m")):
        node = nodes[name]
        check_movable(node, move, "-rod_system_offset", "-rod_system_body_load")
        position = np.array(node.position, dtype=float)
        position[:3] += move
        nodes[name] = dataclasses.replace(node, position=tuple(position))
    return dataclasses.replace(
        system, points=tuple(nodes[p.name] for p in system.points),
        bodies=tuple(nodes[b.name] for b in system.bodies))


def line_lengths(text, system, element_length):
    """``system`` with the lengths of -rod_system_line_length ``text`` (NAME,L separated by
    ':', m): line NAME's sections scaled by L over its length, each meshed with its
    elements or more, none longer than ``element_length`` (m)."""
    lines = _Names(system.lines, ("line",))
    for name, (length,) in named_rows("rod_system_line_length", text, lines,
                                      ("L in m",)):
        if not length > 0:
            raise RodInputError(f"-rod_system_line_length {name},{length:g}: a positive "
                                "length (m)")
        line = lines[name]
        scale = length / float(np.sum(line.line.lengths))
        sections = [(entry[0], float(entry[1]) * scale,
                     max(int(entry[2]) if len(entry) > 2 else 1,
                         int(np.ceil(float(entry[1]) * scale / element_length))))
                    for entry in line.line.sections]
        lines[name] = dataclasses.replace(line, line=dataclasses.replace(
            line.line, sections=tuple(sections)))
    return dataclasses.replace(system, lines=tuple(lines[line.name] for line in system.lines))


def sloped(values, given, system):
    """``system`` with its seabed the plane of -rod_seabed_slope, -rod_seabed_direction
    and -rod_seabed_origin (``values`` of those ``given``; Environment.seabed_slope,
    seabed_direction, seabed_origin: through the file's seabed height at the origin),
    or the profile or grid of -rod_seabed_profile's rows (Environment.seabed_profile,
    along -rod_seabed_direction from -rod_seabed_origin; the file's depth dropped),
    checked again (System.check) with those options named in the refusals."""
    fields = {name.removeprefix("rod_"): values[name] for name in SEABED_OPTIONS
              if name in given}
    if not fields:
        return system
    if "seabed_profile" in fields:
        fields["seabed_profile"] = read_seabed_profile(fields["seabed_profile"],
                                                       MAX_MAGNITUDE)
        fields.setdefault("seabed", None)
    system = dataclasses.replace(system, environment=dataclasses.replace(
        system.environment, **fields))
    system.check(SEABED_NAMES)
    return system


def in_current(values, given, system):
    """``system`` in the current of -rod_current (ux,uy,uz, m/s, uniform) or of
    -rod_current_profile's rows (depth below the sea surface z = 0, m; ux, uy, uz, m/s),
    given in ``values`` (scene_options.current_from_options), the file's sea kept
    (Environment.current), checked again (System.check, those options and the file's
    columns named in its refusals: a current whose drag on a line or a free point is
    above the model's bound, system_check.check_lines and check_point_drag), and
    refused where it pushes nothing: no line of a line type with a Cd
    (held_line.line_sea) and no free point with a CdA (the drag's only other place);
    ``system`` itself where neither is given."""
    current = current_from_options(values, given)
    if current is None:
        return system
    system = dataclasses.replace(system, environment=dataclasses.replace(
        system.environment, current=current))
    system.check(CURRENT_NAMES)
    pushed = ([line.name for line in system.lines
               if line_sea(line, system.environment).current is not None]
              + [point.name for point in system.points
                 if point.kind == "free" and point.cda > 0])
    if not pushed:
        option = ("-rod_current_profile" if "rod_current_profile" in given
                  else "-rod_current")
        raise RodInputError(f"{option}: the current pushes nothing: every line type's Cd "
                            "is 0 (LINE TYPES) and no free point has a CdA (POINTS); give "
                            "them or drop the option")
    return system


def check_outputs_kept(values, comm, system, sweeps, body_modes=None):
    """Refuse an output that names an input (the system file, an options file), which
    writing it would replace: every file the run writes (written_paths: the result file,
    the lines', the system's and the sweeps' tables). Collective: rank 0 decides."""
    clash = None
    if comm.getRank() == 0:
        written = written_paths(system, values["rod_output"], values["rod_table"], sweeps,
                                body_modes is not None)
        read = [("-options_file", path) for path in every_options_file(sys.argv)]
        read.append(("-rod_system", values["rod_system"]))
        read += [(f"-{name}", values[name]) for name in ("rod_current_profile",
                                                         "rod_seabed_profile")
                 if values[name]]
        clash = replaced_input(written, read)
    clash = comm.tompi4py().bcast(clash, root=0)
    if clash:
        raise RodInputError(clash)


def _names(text):
    """The NAMEs of an option's NAME,... parts separated by ':' (named_rows' form)."""
    return [part.split(",")[0].strip() for part in text.split(":")]


def changed(system, values, case):
    """``system`` (the file's) with the run's -rod_system_body_load, -rod_system_offset
    and -rod_system_line_length (``values``), then a sweep case's (``case``: {option
    name: text}) over them, as each option acts on the file's: a case's loads and
    offsets add to the base's, per name (each is a change: the base's of the file's, the
    case's of the base's); a case's lengths replace the base's for the lines it names,
    the base's others kept. Checked again where a point or body moved or a line's length
    changed (System.check: a line that cannot reach its held ends), and every line for
    its start (system_check.check_reach: longer than its ends' distance), the messages
    naming the option that moved or lengthened them."""
    element_length = values["rod_system_element_length"]
    for option, change in (("rod_system_body_load", body_loads),
                           ("rod_system_offset", offsets)):
        for text in (values[option], case.get(option)):
            if text:
                system = change(text, system)
    base, own = values["rod_system_line_length"], case.get("rod_system_line_length")
    if base and own:
        kept = set(_names(own))
        base = ":".join([part for part in base.split(":") if _names(part)[0] not in kept]
                        + [own])
    lengths = base or own
    if lengths:
        system = line_lengths(lengths, system, element_length)
    made_by = {("line", name): "-rod_system_line_length" for name in
               _names(lengths or "")}
    made_by.update({("node", name): "-rod_system_offset" for text in
                    (values["rod_system_offset"], case.get("rod_system_offset")) if text
                    for name in _names(text)})
    if made_by:
        system.check(made_by=made_by)
    check_reach(system, made_by)
    return system


def laid_system(values, system):
    """The System whose start positions lay ``system``'s frictional lines: the -rod_system
    file's, before the run's and a sweep case's offsets (held_line.held_lines), or None
    where its seabed has no friction."""
    if system.environment.seabed_friction is None:
        return None
    return read_moordyn(values["rod_system"], values["rod_system_element_length"])[0]


def prepared(values, given, case=None):
    """(System, notes, the file's text, Settings, the lines' options, the Sweeps, the
    modes' request: api/system_run.modes_request, the system's modes' request:
    body_modes_request) of the run's option ``values`` (a sweep's base options) with a
    sweep case's ``case`` ({option name: text} of sweep/system.CASE_OPTIONS) over them
    (changed); RodInputError for what a system cannot take."""
    refused = refused_options(given)
    if refused:
        raise RodInputError(f"{', '.join('-' + name for name in refused)}: option(s) of "
                            "a single line's scene or load path, not of a system (the "
                            f"-rod_system file {values['rod_system']} describes its lines); "
                            "drop them")
    path = values["rod_system"]
    system, notes = read_moordyn(path, values["rod_system_element_length"])
    system = changed(in_current(values, given, sloped(values, given, system)), values,
                     case or {})
    notes = tuple(notes) + friction_notes(system)
    settings = Settings(predictor=values["rod_system_predictor"],
                        **({} if values["rod_system_steps"] is None
                           else {"load_steps": values["rod_system_steps"]}))
    texts = whole_values()
    options = {name.removeprefix("rod_"): texts[name] for name in given
               if name.removeprefix("rod_") in LINE_OPTIONS}
    sweeps = parse_sweeps(values["rod_system_watch_circle"],
                          values["rod_system_excursion"], system)
    modes = modes_request({name.removeprefix("rod_"): texts[name] for name in given
                           if name.removeprefix("rod_") in MODES_OPTIONS})
    body_modes = body_modes_request({"system_modes": values["rod_system_modes"],
                                     "system_modes_line_mass":
                                         values["rod_system_modes_line_mass"]}, cli=True)
    return (system, notes, read_text(path, "-rod_system"), settings, options, sweeps, modes,
            body_modes)


def saddle_error(results, output=None):
    """The error line (without 'petsc_rod: error: ') of a system's run whose results
    (api/system_run.SystemResults) hold a saddle of the system, '' where none does:
    at rest (a single line's saddle: exit 3, the file written with converged = 0), or
    else at a case of its watch circle or load-excursion curves (the case kept and
    marked, the sweep's group converged = 0). ``output``: the result file, named."""
    if results.verdict is not None and results.verdict.stable is False:
        check = ("a line pushed into compression between its ends: check its length "
                 "against the loads" if results.verdict.lines else
                 "check the bodies' weight against their buoyancy and the loads")
        return (f"the system's equilibrium is {results.verdict.text()}: an equilibrium "
                f"that is not a minimiser ({check})"
                + (f"; result {output}, which says converged = 0" if output else ""))
    saddles = sweep_saddles(results.sweeps)
    if not saddles:
        return ""
    groups = ", ".join(f"system/{kind}" for kind, found in results.sweeps.items()
                       if found.saddles())
    return (f"{saddles}: equilibria that are not minimisers, kept and marked saddle "
            "(check the bodies' weight against their buoyancy, the lines' layout and the "
            "loads)" + (f"; result {output}, whose {groups} says converged = 0"
                        if output else ""))


def gap_error(results, output=None):
    """The error line (without 'petsc_rod: error: ') of a system's run whose watch circle
    or load-excursion curves left cases without an equilibrium (each solve's
    RodDivergedError: their rows left out, listed in the sweep's group), '' where
    none did: the result is incomplete, exit 3 as a system without an equilibrium at
    rest (api/system_run.run_system). ``output``: the result file, named."""
    gaps = sweep_gaps(results.sweeps)
    if not gaps:
        return ""
    groups = ", ".join(f"system/{kind}" for kind, found in results.sweeps.items()
                       if found.failed)
    return (f"{gaps}: the sweep is incomplete (its other cases written"
            + (f" in {output}, whose {groups} lists the failed ones and says converged = 0"
               if output else "") + "; a smaller load or more -rod_system_steps may "
            "reach them)")


def finished_error(results, say, output=None):
    """The exit code of a system's run with ``results`` after its saddles and gaps
    (saddle_error, gap_error) are said as its last lines, the saddle's first: 0 with
    neither, else RodNotConvergedError's 3 (its file written: converged = 0 in the
    system's or the sweep's group). Collective."""
    said = [line for line in (saddle_error(results, output), gap_error(results, output))
            if line]
    for line in said:
        say(f"petsc_rod: error: {line}")
    return RodNotConvergedError.exit_code if said else 0


def run(comm=None):
    """The system's run on ``comm`` (default PETSc.COMM_WORLD); returns the exit code."""
    comm = comm or PETSc.COMM_WORLD
    database = PETSc.Options()

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    try:
        with Interrupts(comm) as interrupts, AgreedFailures(comm):
            check_same_on_every_rank(comm)
            values, given = read_options()
            check_anderson_depth()
            check_snes_type()
            check_factor_switches()
            if database.hasName("help"):
                for line in help_text():
                    say(line)
            system, notes, text, settings, options, sweeps, modes, body_modes = on_every_rank(
                comm, prepared, values, given)
            check_outputs_kept(values, comm, system, sweeps, body_modes)
            if database.hasName("help"):
                return 0
            for note in notes:
                say(f"petsc_rod: note: {note}")
            output, table = values["rod_output"], values["rod_table"]
            results = run_system(comm, system, settings, options, say, output, table,
                                 text, notes, interrupts, sweeps, modes, body_modes,
                                 line_mass_option="-rod_system_modes_line_mass",
                                 laid=on_every_rank(comm, laid_system, values, system))
            written = [f"result {output}"] if output else []
            if table:
                stem, extension = os.path.splitext(table)
                written.append("tables " + ", ".join(
                    f"{stem}_{name}{extension or '.csv'}"
                    for name in ["<line>", "system", *results.sweeps,
                                 *(["system_modes"] if isinstance(results.body_modes,
                                                                  SystemModes) else [])]))
            code = finished_error(results, say, output)
            if code:
                return code
            say(f"petsc_rod: converged: the system's equilibrium in {results.iterations} "
                f"Newton iteration(s), residual {results.residual:.3g}"
                + (f"; {'; '.join(written)}" if written else ""))
            for name in unused_options():
                say(f"petsc_rod: warning: option -{name} was set but not used")
            return 0
    except RodError as error:
        say(f"petsc_rod: error: {error}")
        database.setValue("options_left", "0")
        return error.exit_code
    except PETSc.Error as error:
        say(f"petsc_rod: error: {petsc_failure(error)}")
        database.setValue("options_left", "0")
        return RodDivergedError.exit_code
