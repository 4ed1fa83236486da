"""solve_system(system): a System (model/system.py, api/system.py) in its coupled static
equilibrium (system/equilibrium.SystemSolver) with every line a HeldLine
(system/held_line.py) on its group of ranks, each body's 6 x 6 mooring stiffness, every
line's results as a single line has them, the result file and the CSV tables: the one
path of a system's run, the Python API's and the command line's (cli_system.py).
What it returns holds numpy arrays only (SystemResults); the lines' PETSc objects are
made and destroyed here."""

import os
import time
from dataclasses import dataclass, field, replace

import numpy as np

from petsc_rod.analysis.mass import MassSettings
from petsc_rod.analysis.modes import (ModesFailed, ModesRefused, modes_count, start_slepc,
                                     solve_modes)
from petsc_rod.api.results import Results
from petsc_rod.api.system_sweeps import (Sweeps, check_sweeps, file_group, run_lines,
                                         run_sweeps, table_text)
from petsc_rod.cli.modes import check_subspace, modes_band, table_lines
from petsc_rod.cli.line_run import AgreedFailures, values_of
from petsc_rod.cli.options import BY_NAME
from petsc_rod.errors import (RodDivergedError, RodInputError, RodInterrupted,
                              RodNotConvergedError, on_every_rank)
from petsc_rod.io import line_table, outputs
from petsc_rod.io import results as io
from petsc_rod.io.system_results import SystemWriter
from petsc_rod.model.system_check import check_reach
from petsc_rod.quantities import riser_numbers
from petsc_rod.system.body_modes import (SystemModes, SystemModesRefused, check_line_masses,
                                         system_modes)
from petsc_rod.system.body_modes import table_lines as body_modes_lines
from petsc_rod.system.equilibrium import Settings, SystemSolver
from petsc_rod.system.held_line import friction_notes, held_lines

# The options of the system itself (not of its lines): the load continuation's first
# step is 1 / system_steps of the bodies' loads (Settings.load_steps); whether the first
# solve starts from the catenaries' equilibrium (Settings.predictor); the modes of the
# bodies and free points (system/body_modes.py), the lines' mass lumped at their ends.
SYSTEM_OPTIONS = ("system_steps", "system_predictor", "system_modes",
                  "system_modes_line_mass")
# The modes of each line with its ends held (docs/modes.md): their count and the mass's
# settings (every line the same), the option names without ``rod_`` and MassSettings'.
MODES_OPTIONS = {"modes": None, "modes_range": None, "modes_added_mass": "added_mass",
                 "modes_mass": "mass",
                 "modes_inertia": "inertia"}
# The options of a line that a system's lines take (every line the same): the
# iteration's tolerances and switches (-rod_al_*), the halvings of a line's walk.
LINE_OPTIONS = tuple(name.removeprefix("rod_") for name in BY_NAME
                     if name.startswith("rod_al_")) + ("max_halvings",)


@dataclass
class BodyResult:
    """A body at the equilibrium: ``position`` (6,) x, y, z (m), roll, pitch, yaw (rad);
    ``rotation`` (3, 3), body axes to global; its mooring ``stiffness`` (6, 6) about
    ``reference`` (3,), m (its reference point at the equilibrium), N/m, N, N m/rad, not
    symmetrised, with ``asymmetry`` |K - K^T|_F / |K|_F and the lines' ``moment`` (3,),
    N m, about the reference point, which is the rotational block's antisymmetric part
    (docs/systems.md)."""

    position: np.ndarray
    rotation: np.ndarray
    stiffness: np.ndarray
    reference: np.ndarray
    moment: np.ndarray
    asymmetry: float


@dataclass
class SystemResults:
    """A system's equilibrium (solve_system), numpy only, the same on every rank:
    ``points`` {name: (3,) m}; ``bodies`` {name: BodyResult}; ``end_forces`` {line:
    (2, 3) N}, the force each line exerts ON its start's and its end's point or body;
    ``end_tensions`` {line: (2,) N}, the end elements' tension along the line, n.t at
    S = 0 and S = L; ``lines_converged`` {line: bool} (whether the line's last solve,
    at the system's last evaluation, converged); ``lines`` {line: api.Results}
    (its arrays along S on this rank, none on a rank outside its group: along_line()
    gathers them, collectively on the system's communicator); ``converged`` (the load
    continuation complete and every line converged: the solve raises when it finds no
    equilibrium, so False only where a line's last re-solve failed),
    False too at a saddle of the system (``verdict``),
    ``iterations`` (Newton's), ``halvings`` (of the load continuation), ``residual``
    (the scaled norm), ``load_factor``; ``sweeps`` {'watch_circle': WatchCircle,
    'excursion': LoadExcursion} of those asked (api/system_sweeps.py), else {}, each
    case with the system's verdict (``stable``, ``saddles()``: a saddle at a case
    leaves ``converged``, the rest's, as it is; the command line exits 3); with
    modes asked, ``modes`` {line: analysis/modes.Modes or ModesRefused}, each line's
    modes about its equilibrium in the system with its ends held (line_modes: the numbers per mode on every rank, the
    shapes along the line on its group's ranks, zero rows on the others); with the
    system's modes asked, ``body_modes`` (system/body_modes.SystemModes of the bodies
    and free points, or SystemModesRefused), else None; ``verdict`` the system's own
    stability in its free unknowns (system/verdict.SystemVerdict: stable True, False a
    saddle of the system, None no verdict)."""

    points: dict
    bodies: dict
    end_forces: dict
    end_tensions: dict
    lines_converged: dict
    lines: dict
    converged: bool
    iterations: int
    halvings: int
    residual: float
    load_factor: float
    sweeps: dict = None
    modes: dict = field(default_factory=dict)
    body_modes: object = None
    verdict: object = None


def body_modes_request(options, cli=False):
    """{'line_mass': bool} of the system's modes ``options`` asks for ('system_modes',
    'system_modes_line_mass'), None without 'system_modes'; the two taken out of
    ``options``. ``cli``: a refusal names the command line's options
    (-rod_system_modes 1), else the API's."""
    asked, lumped = (options.pop(name, False) for name in ("system_modes",
                                                           "system_modes_line_mass"))
    for name, value in (("system_modes", asked), ("system_modes_line_mass", lumped)):
        if not isinstance(value, (bool, np.bool_, int, np.integer)) or value not in (0, 1):
            raise RodInputError(f"{name} {value!r}: True or False")
    if lumped and not asked:
        needs = ("-rod_system_modes_line_mass needs -rod_system_modes 1" if cli else
                 "system_modes_line_mass needs system_modes")
        raise RodInputError(f"{needs} (the system's modes it lumps the lines' mass for)")
    return {"line_mass": bool(lumped)} if asked else None


def modes_request(options):
    """(count, MassSettings, band) of the modes ``options`` {name without ``rod_``:
    value} asks for (MODES_OPTIONS, parsed as the command line's -rod_modes*: the
    ``modes`` lowest, or every mode in the band ``modes_range`` 'FMIN,FMAX' Hz, band
    then (fmin, fmax), else None), None without either; the options taken out of
    ``options``."""
    texts = {name: options.pop(name) for name in list(options) if name in MODES_OPTIONS}
    values, _ = values_of(texts)
    band = modes_band(values["rod_modes_range"])
    if values["rod_modes"] and band is not None:
        raise RodInputError("modes and modes_range: give one (the N lowest modes, or "
                            "every mode in a band)")
    if not values["rod_modes"] and band is None:
        return None
    if values["rod_modes"]:
        check_subspace(values["rod_modes"])
    return values["rod_modes"], MassSettings(
        **{key: values[f"rod_{name}"] for name, key in MODES_OPTIONS.items() if key}), band


def split_options(options):
    """(system Settings, the lines' options, the modes' request (modes_request), the
    system's modes' request (body_modes_request)) of ``options`` {name without
    ``rod_``: value}; RodInputError naming one that none takes."""
    options = dict(options or {})
    taken = SYSTEM_OPTIONS + LINE_OPTIONS + tuple(MODES_OPTIONS)
    unknown = sorted(set(options) - set(taken))
    if unknown:
        raise RodInputError(f"system option {unknown[0]!r}: not an option of a system; "
                            f"its options: {', '.join(taken)}")
    modes = modes_request(options)
    body_modes = body_modes_request(options)
    steps = options.pop("system_steps", Settings().load_steps)
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 1:
        raise RodInputError(f"system_steps {steps!r}: a whole number of at least 1 (the "
                            "load continuation's first step is 1 / system_steps of the "
                            "loads)")
    predictor = options.pop("system_predictor", Settings().predictor)
    if not isinstance(predictor, (bool, np.bool_)):
        raise RodInputError(f"system_predictor {predictor!r}: True or False (whether the "
                            "first solve starts from the system's catenaries' equilibrium)")
    values_of(options)                      # a malformed value refused before any work
    return (Settings(load_steps=int(steps), predictor=bool(predictor)), options, modes,
            body_modes)


def check_line_counts(solver, count, settings):
    """RodInputError on every rank, in one line, where ``count`` modes are more than a
    line's discretisation has (analysis/modes.modes_count, one factorisation a line,
    counted only where ``count`` is above its element count: at least one mode an
    element), naming the first such line and its count: before any mode is solved
    and anything written. Collective."""
    mine = {k: modes_count(line.problem, settings) for k, line in solver.lines.items()
            if count > line.mesh.n_elements}
    short = sorted((k, n) for k, n in solver.placement.share(mine).items() if count > n)
    if short:
        k, available = short[0]
        raise RodInputError(f"-rod_modes {count}: line {solver.system.lines[k].name}'s "
                            f"discretisation has {available} modes; ask for at most "
                            f"{min(n for _, n in short)}, or for every mode in a band "
                            "with -rod_modes_range FMIN,FMAX (docs/modes.md)")


def line_modes(solver, count, settings, band=None):
    """({line index: Modes or ModesRefused}, {line index: seconds}) on every rank: each
    line's ``count`` lowest modes (every mode in ``band``, Hz, where given) about its
    equilibrium with its ends held
    (analysis/modes.solve_modes on the HeldLine's problem, collective on its group's
    communicator: its ends are pinned there, so its modes are the held line's), the
    shapes on the line's own ranks, zero rows of them on the others. RodInputError
    (check_line_counts) where ``count`` is more than a line has; ModesFailed, the line
    named, on every rank where a line's eigensolver failed (on its own ranks: the
    others learn it from the lines' share, where they would otherwise wait). Collective."""
    if band is None:
        check_line_counts(solver, count, settings)
    start_slepc()               # on every rank, whatever its lines do (start_slepc)
    mine, seconds = {}, {}
    for k, line in solver.lines.items():
        start = time.perf_counter()
        try:
            mine[k] = solve_modes(line.problem, count, settings, band)
        except (ModesRefused, ModesFailed) as not_found:
            mine[k] = not_found
        seconds[k] = line.mesh.global_max(time.perf_counter() - start)

    def numbers(found):
        if isinstance(found, ModesFailed):
            return str(found)
        if isinstance(found, ModesRefused):
            return found.negative
        n = len(found.omega2)
        return replace(found, S=np.zeros(0), offset=np.zeros((n, 0, 3)),
                       rotation=np.zeros((n, 0, 3)), S_mid=np.zeros(0),
                       curvature=np.zeros((n, 0, 3)))
    shared = solver.placement.share({k: (numbers(m), seconds[k]) for k, m in mine.items()})
    failed = sorted((k, value) for k, (value, _) in shared.items()
                    if isinstance(value, str))
    if failed:
        k, text = failed[0]
        raise ModesFailed.of_line(solver.system.lines[k].name, text)
    found = {k: mine[k] if k in mine else
             ModesRefused(value) if isinstance(value, (int, np.integer)) else value
             for k, (value, _) in shared.items()}
    return found, {k: time_ for k, (_, time_) in shared.items()}


def modes_lines(system, modes, seconds):
    """The run's lines of each line's modes (cli/modes.table_lines), or their refusal."""
    lines = []
    for k, line in enumerate(system.lines):
        found = modes[k]
        if isinstance(found, ModesRefused):
            lines.append(f"line {line.name}: modes: refused: {found}")
            continue
        table = table_lines(found, seconds[k])
        lines.append(f"line {line.name} (ends held): {table[0]}")
        lines.extend(table[1:])
    return lines


def _end_values(mesh, values):
    """(values at vertex 0, values at the last vertex) of the owned ``values``, on every
    rank of the mesh. Collective on the mesh's communicator."""
    first = values[0] if mesh.on_lower_boundary else np.zeros(np.shape(values)[1:])
    last = values[-1] if mesh.on_upper_boundary else np.zeros(np.shape(values)[1:])
    return mesh.global_sum(np.asarray(first, float)), mesh.global_sum(np.asarray(last, float))


@dataclass
class LineRecord:
    """A converged line's last step as a single line's result file holds it: this
    rank's ``vertex`` datasets and restart ``state`` (outputs.restart_state), its
    ``attributes`` and ``units`` ({dataset: unit}, {attribute: unit}), its end
    ``tensions`` (2,), N (n.t at S = 0 and S = L), and its mesh's ``elements``."""

    vertex: dict
    state: dict
    attributes: dict
    units: tuple
    tensions: np.ndarray
    elements: int


def line_record(line, stable):
    """The LineRecord of a HeldLine (line_table.final_record: the terms' and reports'
    outputs, r absolute, the effective tension), with its converged (whether its last
    solve converged: the system's last evaluation may leave a line that did not),
    iterations, ``stable`` (the system's verdict, Equilibrium.stable: True, False or
    None), load factor and ranks. Collective on the line's communicator."""
    problem = line.problem
    vertex, attributes = line_table.final_record(problem)
    converged = bool(line.converged)
    attributes.update(converged=int(converged),
                      stop_reason="converged" if converged else "diverged",
                      iterations=line.iterations,
                      stable=-1 if stable is None else int(stable), load_factor=1.0,
                      energy=problem.energy(), ranks=line.comm.getSize())
    tensions = np.array(_end_values(problem.mesh, vertex["effective_tension"]))
    datasets, scalars = problem.units()
    # final_record adds the effective tension of a plain rod, with the riser numbers' unit
    datasets = {"effective_tension": riser_numbers.DATASET_UNITS["effective_tension"],
                **datasets}
    return LineRecord(vertex, outputs.restart_state(problem), attributes,
                      (datasets, scalars), tensions, problem.mesh.n_elements)


def _shapes(arrays):
    return {name: (np.shape(value)[1:], np.asarray(value).dtype.str)
            for name, value in arrays.items()}


def _empty(shapes):
    return {name: np.zeros((0,) + tuple(shape), dtype=dtype)
            for name, (shape, dtype) in shapes.items()}


def gathered_lines(solver, stable):
    """{line index: LineRecord} on every rank: this rank's own rows of its group's
    lines, zero rows of the others' (their names and shapes, attributes, units and
    tensions shared from the groups' roots); ``stable`` {line name: verdict}
    (Equilibrium.stable). Collective."""
    names = [line.name for line in solver.system.lines]
    mine = {k: line_record(line, stable[names[k]]) for k, line in solver.lines.items()}
    shared = solver.placement.share({k: replace(record, vertex=_shapes(record.vertex),
                                                state=_shapes(record.state))
                                     for k, record in mine.items()})
    return {k: mine[k] if k in mine else replace(record, vertex=_empty(record.vertex),
                                                 state=_empty(record.state))
            for k, record in shared.items()}


# datasets along S where +inf is a value: the bend radius of a straight piece
# (quantities/line_results.bend_radius), a taut line's everywhere
UNBOUNDED = ("bend_radius",)


def check_finite(comm, results, records):
    """RodDivergedError unless every number of the equilibrium is finite, the lines'
    arrays along S (``records``' vertex datasets, on the ranks that hold them) too, +inf
    allowed in UNBOUNDED's: no NaN is ever written or returned as a result. Collective."""
    numbers = ([b.position for b in results.bodies.values()]
               + [b.stiffness for b in results.bodies.values()]
               + list(results.points.values()) + list(results.end_forces.values())
               + list(results.end_tensions.values()))
    along = [np.where(value == np.inf, 0.0, value) if name in UNBOUNDED else value
             for record in records.values() for name, value in record.vertex.items()
             if np.issubdtype(np.asarray(value).dtype, np.number)]
    if not all(comm.tompi4py().allgather(
            all(np.all(np.isfinite(value)) for value in numbers + along))):
        raise RodDivergedError("system: the equilibrium holds non-finite numbers (NaN or "
                               "inf); nothing is written")


# the system's tables that a run writes only when asked (write_tables, stale_paths)
OPTIONAL_TABLES = ("watch_circle", "excursion", "system_modes")


def table_paths(table, system, sweeps=Sweeps(), body_modes=False):
    """{line name, 'system', a sweep's name or 'system_modes': CSV path} of ``table``
    (FILE.csv -> FILE_<line>.csv, FILE_system.csv, FILE_watch_circle.csv and
    FILE_excursion.csv where ``sweeps`` asks for them, FILE_system_modes.csv where
    ``body_modes``)."""
    stem, extension = os.path.splitext(table)
    names = [line.name for line in system.lines] + ["system"] + [
        name for name in ("watch_circle", "excursion") if getattr(sweeps, name) is not None]
    names += ["system_modes"] if body_modes else []
    return {name: f"{stem}_{name}{extension or '.csv'}" for name in names}


def written_paths(system, output, table, sweeps=Sweeps(), body_modes=False):
    """[(what names it, path)] of every file the run writes: the result file, each
    line's table with its regions' and ends' tables, the system's and the sweeps'
    tables; what a check that no output replaces an input compares."""
    written = [("-rod_output", output)] if output else []
    if table:
        lines = {line.name for line in system.lines}
        for name, path in table_paths(table, system, sweeps, body_modes).items():
            written.append((f"-rod_table {table}'s table", path))
            if name in lines:
                written += [(f"-rod_table {table}'s table", line_table.regions_path(path)),
                            (f"-rod_table {table}'s table", line_table.ends_path(path))]
    return written


def check_outputs(comm, system, output, table, sweeps=Sweeps(), body_modes=False):
    """Refuse, before any work, a result file or a table that could not be written
    (io/results.check_output_path, line_table.check_table_path). Collective."""
    if output:
        io.check_output_path(output, comm)
    if table:
        for path in table_paths(table, system, sweeps, body_modes).values():
            line_table.check_table_path(path, output, comm)


def system_datasets(system, results):
    """({name: array}, {name: unit}) of the result file's ``system`` group."""
    bodies = list(results.bodies.values())
    lines = [line.name for line in system.lines]
    data = {
        "point_positions": np.array(list(results.points.values())).reshape(-1, 3),
        "body_positions": np.array([b.position for b in bodies]).reshape(-1, 6),
        "body_rotations": np.array([b.rotation for b in bodies]).reshape(-1, 3, 3),
        "body_stiffness": np.array([b.stiffness for b in bodies]).reshape(-1, 6, 6),
        "body_stiffness_reference": np.array([b.reference for b in bodies]).reshape(-1, 3),
        "body_stiffness_moment": np.array([b.moment for b in bodies]).reshape(-1, 3),
        "body_stiffness_asymmetry": np.array([b.asymmetry for b in bodies]),
        "end_forces": np.array([results.end_forces[n] for n in lines]).reshape(-1, 2, 3),
        "end_tensions": np.array([results.end_tensions[n] for n in lines]).reshape(-1, 2),
        "line_converged": np.array([results.lines_converged[n] for n in lines], dtype=float),
    }
    rows = system.environment.current_rows()
    if rows is not None:          # the current the run was in: a uniform one at depth 0
        data["current"] = np.column_stack(rows)
    units = {"current": "m, m/s, m/s, m/s (depth below z = 0, ux, uy, uz)",
             "point_positions": "m", "body_positions": "m, m, m, rad, rad, rad",
             "body_rotations": "1", "body_stiffness": "N/m, N, N m/rad (rows F, M; "
             "columns dX, dtheta)", "body_stiffness_reference": "m",
             "body_stiffness_moment": "N m", "body_stiffness_asymmetry": "1",
             "end_forces": "N", "end_tensions": "N", "line_converged": "1"}
    return data, units


def picture_attributes(system):
    """The ``system`` group's attributes a picture needs beside the datasets
    (plots.py draws from the file alone): the points' kinds, each line's start's and
    end's point or body (in ``line_names``' order), the flat seabed's height (left out
    where there is none, or where it is sloped or profiled) and the sea surface's, m."""
    environment = system.environment
    found = {"point_kinds": ",".join(p.kind for p in system.points),
             "line_starts": ",".join(line.start.to for line in system.lines),
             "line_ends": ",".join(line.end.to for line in system.lines),
             "surface": float(environment.surface or 0.0)}
    if (environment.seabed is not None and not environment.seabed_slope
            and environment.seabed_profile is None):
        found["seabed"] = float(environment.seabed)
    return found


def write_file(comm, output, system, results, records, text, notes, failures):
    """The system's result file (io/system_results.py): a group per line, the group
    ``system`` (each line's group with its modes, ``lines/<name>/modes``, as a single
    line's file has them), the input file's text and the reader's notes. The open writer is
    ``failures.writer`` (cli/line_run.AgreedFailures) until it is finished: the caller
    aborts it once the ranks agree on a failure (its abort is collective), or a rank
    failing alone removes its partial file. Collective."""
    writer = failures.writer = SystemWriter(output, comm)
    for k, line in enumerate(system.lines):
        record = records[k]
        writer.write_line(line.name, record.vertex, record.state, record.attributes,
                          record.units)
        found = results.modes.get(line.name)
        if found is not None and not isinstance(found, ModesRefused):
            writer.write_modes(found, f"lines/{line.name}/modes")
    data, units = system_datasets(system, results)
    verdict = results.verdict
    attributes = {"converged": int(results.converged), "iterations": results.iterations,
                  "halvings": results.halvings, "residual": results.residual,
                  "load_factor": results.load_factor, "ranks": comm.getSize(),
                  "system_stable": -1 if verdict is None else verdict.code(),
                  "system_verdict": "" if verdict is None else verdict.text(),
                  "point_names": ",".join(results.points),
                  "body_names": ",".join(results.bodies),
                  "line_names": ",".join(line.name for line in system.lines),
                  "input_text": text or "", "notes": "\n".join(notes),
                  **picture_attributes(system)}
    units.update({"converged": "1", "iterations": "1", "halvings": "1",
                  "system_stable": "1", "system_verdict": "text",
                  "residual": "1", "load_factor": "1", "ranks": "1",
                  "point_names": "text", "body_names": "text", "line_names": "text",
                  "input_text": "text", "notes": "text", "written": "text",
                  "point_kinds": "text", "line_starts": "text", "line_ends": "text",
                  "seabed": "m", "surface": "m"})
    groups = {name: file_group(found) for name, found in results.sweeps.items()}
    if results.body_modes is not None:
        groups["modes"] = body_modes_group(results.body_modes)
    writer.finish_system(data, attributes, units, groups)
    failures.writer = None


def body_modes_group(found):
    """(datasets, attributes, units) of the result file's group ``system/modes``: the
    system's modes (system/body_modes.SystemModes), or the reason there are none."""
    if isinstance(found, SystemModesRefused):
        return {}, {"refused": str(found)}, {"refused": "text"}
    data = {"frequencies": found.frequencies, "periods": found.periods,
            "omega2": found.omega2, "modal_mass": found.modal_mass,
            "shapes": found.shapes, "shares": found.shares,
            "stiffness": found.stiffness, "mass": found.mass}
    attributes = {"dofs": ",".join(f"{n} {d}" for n, d in found.dofs),
                  "labels": ",".join(found.labels),
                  "condensed": found.condensed,
                  "line_mass": int(found.line_mass), "imaginary": found.imaginary,
                  "lines": "quasi-static: their static stiffness at the equilibrium"}
    units = {"frequencies": "Hz", "periods": "s", "omega2": "rad^2/s^2",
             "modal_mass": "kg (kg m^2 where the dominant unknown is a rotation)",
             "shapes": "m, rad (per unit dominant unknown; columns: dofs)",
             "shares": "1", "stiffness": "N/m, N, N m/rad (rows and columns: dofs)",
             "mass": "kg, kg m, kg m^2 (rows and columns: dofs)", "dofs": "text",
             "labels": "text", "condensed": "1", "line_mass": "1", "imaginary": "1",
             "lines": "text"}
    return data, attributes, units


def body_modes_table(found):
    """The text of FILE_system_modes.csv: a row per mode, its frequency, period,
    omega, modal mass, dominant unknown, then its shares and its shape per unknown."""
    columns = [f"{n}_{d}" for n, d in found.dofs]
    rows = [",".join(["mode", "frequency_Hz", "period_s", "omega_rad_s", "modal_mass",
                      "dominant"] + [f"share_{c}" for c in columns]
                     + [f"shape_{c}" for c in columns])]
    for k in range(len(found.omega2)):
        rows.append(",".join(
            [str(k + 1)] + [f"{v:.10g}" for v in (found.frequencies[k], found.periods[k],
                                                   np.sqrt(found.omega2[k]),
                                                   found.modal_mass[k])]
            + [found.labels[k].replace(" ", "_")]
            + [f"{v:.6f}" for v in found.shares[k]] + [f"{v:.10g}" for v in found.shapes[k]]))
    return "\n".join(rows) + "\n"


def ends_rows(system, results):
    """The text of FILE_system.csv: a row per line end."""
    rows = ["line,end,to,force_x (N),force_y (N),force_z (N),tension (N)"]
    for line in system.lines:
        forces, tensions = results.end_forces[line.name], results.end_tensions[line.name]
        for j, (which, connection) in enumerate((("start", line.start), ("end", line.end))):
            rows.append(",".join([line.name, which, connection.to]
                                 + [f"{v:.12g}" for v in forces[j]]
                                 + [f"{tensions[j]:.12g}"]))
    return "\n".join(rows) + "\n"


def write_tables(comm, solver, table, system, results, records, sweeps=Sweeps()):
    """FILE_<line>.csv (a single line's table, written by the line's group) for every
    line, FILE_system.csv, the sweeps' FILE_watch_circle.csv, FILE_excursion.csv and
    the system's modes' FILE_system_modes.csv (rank 0; none where they were refused);
    an earlier run's optional tables that this run did not write removed (stale_paths).
    Collective on ``comm``."""
    paths = table_paths(table, system, sweeps, results.body_modes is not None)

    def write_all():
        for k, line in solver.lines.items():
            name = system.lines[k].name
            record = records[k]
            line_table.write_tables(paths[name], line.comm, record.vertex,
                                    record.attributes, record.units)
        if comm.getRank() == 0:
            partial = paths["system"] + ".partial"
            line_table._write(paths["system"], partial, ends_rows(system, results))
            for name, found in results.sweeps.items():
                line_table._write(paths[name], paths[name] + ".partial", table_text(found))
            if isinstance(results.body_modes, SystemModes):
                line_table._write(paths["system_modes"], paths["system_modes"] + ".partial",
                                  body_modes_table(results.body_modes))
            written = set(results.sweeps) | (
                {"system_modes"} if isinstance(results.body_modes, SystemModes) else set())
            for path in stale_paths(table, system, written):
                os.remove(path)
    on_every_rank(comm, write_all)


def stale_paths(table, system, written):
    """The existing FILE_watch_circle.csv, FILE_excursion.csv and FILE_system_modes.csv
    of ``table`` whose names are not in ``written`` (this run wrote no such table): an
    earlier run's, which would otherwise stand beside this run's tables as if its
    own."""
    every = table_paths(table, system, Sweeps(watch_circle=True, excursion=True), True)
    return [every[name] for name in OPTIONAL_TABLES
            if name not in written and os.path.exists(every[name])]


def report_lines(system, results, ranks):
    """The run's lines: the equilibrium's iterations and residual, a table of the
    bodies' poses, the lines' end tensions and stability (a saddle in capitals), each
    body's stiffness diagonal."""
    lines = [f"petsc_rod: system of {len(system.lines)} line(s), {len(system.points)} "
             f"point(s), {len(system.bodies)} body(ies) on {ranks} rank(s): equilibrium in "
             f"{results.iterations} Newton iteration(s) ({results.halvings} halving(s) of "
             f"the load step), scaled residual {results.residual:.3g}"]
    if results.bodies:
        lines.append(f"  {'body':<12} {'x (m)':>12} {'y (m)':>12} {'z (m)':>12} "
                     f"{'roll (deg)':>11} {'pitch (deg)':>11} {'yaw (deg)':>11}")
        for name, body in results.bodies.items():
            x = body.position
            angles = np.degrees(x[3:])
            lines.append(f"  {name:<12} {x[0]:12.4f} {x[1]:12.4f} {x[2]:12.4f} "
                         f"{angles[0]:11.5f} {angles[1]:11.5f} {angles[2]:11.5f}")
    free = [p.name for p in system.points if p.kind == "free"]
    for name in free:
        x = results.points[name]
        lines.append(f"  point {name}: ({x[0]:.4f}, {x[1]:.4f}, {x[2]:.4f}) m")
    lines.append(f"  {'line':<12} {'start':>10} {'T start (kN)':>13} {'end':>10} "
                 f"{'T end (kN)':>13} {'|F| end (kN)':>13} {'stable':>7}")
    verdicts = {1: "yes", 0: "SADDLE", -1: "-"}             # the file's stable codes
    for line in system.lines:
        tension = results.end_tensions[line.name] / 1e3
        force = np.linalg.norm(results.end_forces[line.name][1]) / 1e3
        stable = verdicts[int(results.lines[line.name].scalars["stable"])]
        lines.append(f"  {line.name:<12} {line.start.to:>10} {tension[0]:13.3f} "
                     f"{line.end.to:>10} {tension[1]:13.3f} {force:13.3f} {stable:>7}")
    for name, body in results.bodies.items():
        diagonal = ", ".join(f"{v:.6g}" for v in np.diag(body.stiffness))
        lines.append(f"  body {name}: stiffness diagonal (N/m x3, N m/rad x3) {diagonal}; "
                     f"asymmetry {body.asymmetry:.2g}")
    if results.verdict is not None:
        lines.append(f"  the system's equilibrium: {results.verdict.text()}")
    return lines


def discard_tables(comm, table, system, say, sweeps=Sweeps(), body_modes=False):
    """After a system that found no equilibrium: no table is written, and the tables an
    earlier run left at ``table``'s paths are removed (line_table.discard), said in one
    line. Collective."""
    paths = table_paths(table, system, sweeps, body_modes).values()
    found = [path for path in paths if os.path.exists(path)]
    for path in paths:
        line_table.discard(path, comm, lambda line: None)
    say(f"petsc_rod: no tables written (-rod_table {table}): no equilibrium"
        + (f"; removed {len(found)} table(s) of an earlier run" if found else ""))


def surfaced_points(system, points):
    """The notes on the free points with a volume that end above the sea surface
    (the Environment's surface, z = 0 where none) at ``points`` {name: (3,) m}: a
    point's volume buoys it wherever it is (rho_w V g, as in MoorDyn, whose points have
    no waterplane), so such a buoy's height is the lines' balance of its whole
    buoyancy, not a float's: worth the engineer's look."""
    surface = system.environment.surface or 0.0
    return [f"point {p.name} ends {points[p.name][2] - surface:.3g} m above the sea "
            f"surface, buoyed all the same by its {p.volume:g} m^3 (a point's volume is "
            "buoyant wherever it is, as in MoorDyn; a buoy that floats at the surface "
            "is a body with its waterplane)"
            for p in system.points
            if p.kind == "free" and p.volume > 0 and points[p.name][2] > surface]


def run_system(comm, system, settings, line_options, say, output=None, table=None,
               text=None, notes=(), interrupts=None, sweeps=Sweeps(), modes=None,
               body_modes=None, solver=None, line_mass_option="system_modes_line_mass",
               laid=None):
    """The system's run on ``comm`` (PETSc.Comm): its lines built on their groups, the
    equilibrium (SystemSolver.solve), each body's stiffness, each line's record, each
    line's modes with its ends held where ``modes`` (count, MassSettings) asks for
    them (line_modes), the bodies' and free points' modes where ``body_modes``
    ({'line_mass': bool}) asks for them (system/body_modes.system_modes), the result
    file and the tables when asked; the lines destroyed. ``interrupts``
    (cli/signals.Interrupts) asked before every iteration of the system's Newton (and
    so of its sweeps), once the equilibrium is found and again before the file is
    written: a stop signal then ends the run before anything is written
    (RodInterrupted). ``sweeps``
    (api/system_sweeps.Sweeps): the watch circle and the load-excursion curves run
    after the equilibrium, in the results, the file and the tables. Returns the
    SystemResults. ``solver``: a SystemSolver of a system that differs from ``system``
    only in what SystemSolver.replace takes (loads, held points' and bodies'
    positions), re-solved warm from where it stands and left to its caller (a sweep's
    cases); None: one made for the run and destroyed after it, its frictional lines
    laid where ``laid`` (a System: the file's, before the run's offsets) puts them
    (held_line.held_lines).
    RodInputError for a system the checks refuse (exit 2: System.check, and
    system_check.check_reach where the run starts: a line that cannot start, taut lines
    that nothing pulls) or a sweep it cannot run (api/system_sweeps.check_sweeps: a body
    held where the sweep's load pushes it),
    RodNotConvergedError when no equilibrium was found (exit 3: the coupled solver's
    RodDivergedError, its Newton or a line not converged after its halvings),
    RodDivergedError for non-finite numbers (exit 4); nothing is written then.
    Collective."""
    on_every_rank(comm, system.check)
    on_every_rank(comm, check_sweeps, sweeps, system)
    if solver is None:
        # every line able to start where the run starts (the command line checked it
        # first, naming the options that moved its ends; a sweep's cases, re-solved on
        # a kept solver, are checked by the command line alone)
        on_every_rank(comm, check_reach, system)
    if body_modes is not None and body_modes["line_mass"]:
        on_every_rank(comm, check_line_masses, system, line_mass_option)
    check_outputs(comm, system, output, table, sweeps, body_modes is not None)
    own = solver is None
    if own:
        solver = SystemSolver(system, held_lines(system, line_options, laid), comm,
                              settings=settings)
    else:
        on_every_rank(comm, solver.replace, system)
    solver.interrupts = interrupts
    failures = AgreedFailures(comm)
    try:
        # the ranks agree on a failure (one rank's alone ends every rank) before the
        # result file's collective abort and the lines' collective destroy
        with failures:
            return _solved(comm, solver, system, say, output, table, text, notes,
                           interrupts, sweeps, modes, failures, body_modes)
    finally:
        if failures.writer is not None:
            failures.writer.abort()
        if own:
            solver.destroy()


def stop_if_interrupted(interrupts, when):
    """RodInterrupted (exit 128 + the signal's number, nothing written) where a rank
    received a stop signal (cli/signals.Interrupts; None: no signals asked for), the
    message saying ``when``. Collective."""
    number = 0 if interrupts is None else interrupts.received()
    if number:
        raise RodInterrupted(f"stopped by {interrupts.name(number)} {when}; nothing "
                             "written", number)


def _solved(comm, solver, system, say, output, table, text, notes, interrupts, sweeps,
            modes, failures, body_modes=None):
    """run_system's work once its lines are built: the equilibrium, the records, the
    lines' modes, the system's modes, the sweeps, the file and the tables;
    SystemResults. Collective."""
    try:
        found = solver.solve()
    except RodDivergedError as error:
        if table:
            discard_tables(comm, table, system, say, sweeps, body_modes is not None)
        # a Newton or a line that did not converge, the halvings spent: the single
        # line's exit 3, but no file (there is no equilibrium to write)
        raise RodNotConvergedError(str(error)) from None
    if solver.prediction is not None and not solver.prediction.startswith("not used"):
        # the first solve started from the catenaries' equilibrium (system/predictor.py)
        say(f"petsc_rod: note: the system's catenary predictor {solver.prediction}")
    for note in surfaced_points(system, found.points):
        say(f"petsc_rod: note: {note}")
    stop_if_interrupted(interrupts, "after the system's equilibrium was found")
    stiffness = {b.name: solver.body_stiffness(b.name) for b in system.bodies}
    # at the equilibrium, before the sweeps move the solver (numpy: every rank the same)
    coupled = None
    if body_modes is not None:
        try:
            coupled = system_modes(solver, **body_modes)
        except SystemModesRefused as refused:
            coupled = refused
    records = gathered_lines(solver, found.stable)
    mpi = comm.tompi4py()
    lines = {line.name: Results(records[k].vertex, records[k].attributes, True, mpi,
                                records[k].elements, records[k].units)
             for k, line in enumerate(system.lines)}
    bodies = {b.name: BodyResult(np.asarray(found.bodies[b.name]),
                                 np.asarray(found.rotations[b.name]),
                                 stiffness[b.name].matrix, stiffness[b.name].reference,
                                 stiffness[b.name].moment, stiffness[b.name].asymmetry)
              for b in system.bodies}
    names = [line.name for line in system.lines]
    results = SystemResults(
        dict(found.points), bodies,
        {n: found.end_forces[k] for k, n in enumerate(names)},
        {n: records[k].tensions for k, n in enumerate(names)},
        {n: bool(records[k].attributes["converged"]) for k, n in enumerate(names)},
        # a saddle of the system is not converged, as a single line's saddle is not
        lines, found.load_factor == 1.0 and all(
            bool(records[k].attributes["converged"]) for k in range(len(names)))
        and (found.verdict is None or found.verdict.stable is not False),
        found.iterations, found.halvings,
        found.residual, found.load_factor, verdict=found.verdict)
    check_finite(comm, results, records)
    for line in report_lines(system, results, comm.getSize()):
        say(line)
    if modes is not None:
        found, seconds = line_modes(solver, *modes)
        results.modes = {n: found[k] for k, n in enumerate(names)}
        for line in modes_lines(system, found, seconds):
            say(line)
    if coupled is not None:
        results.body_modes = coupled
        for line in (body_modes_lines(coupled) if isinstance(coupled, SystemModes) else
                     [f"system modes: refused: {coupled}"]):
            say(line)
    # after the records: the sweeps' warm re-solves leave the lines at rest again,
    # but the equilibrium's numbers are those found before them
    results.sweeps = run_sweeps(solver, sweeps) if sweeps else {}
    for line in run_lines(results.sweeps):
        say(line)
    # the stiffness, the modes and the sweeps take as long as the equilibrium, or longer
    stop_if_interrupted(interrupts, "before the system's results were written")
    if output:
        write_file(comm, output, system, results, records, text, notes, failures)
    if table:
        write_tables(comm, solver, table, system, results, records, sweeps)
    return results


def solve_system(system, comm=None, output=None, say=None, options=None, table=None,
                 notes=(), sweeps=None):
    """Solve ``system`` (api.System) on the ranks of ``comm`` (a PETSc communicator;
    default PETSc.COMM_WORLD), each line on its group of ranks; collective.
    ``output``: the system's result file (HDF5, docs/output.md) as -rod_output;
    ``table``: FILE.csv, the tables FILE_<line>.csv and FILE_system.csv as -rod_table;
    ``say(line)`` gets the command line's lines (None: silent), ``notes`` (the
    reader's, read_moordyn's second value) said first; ``options`` {name without
    ``rod_``: value}: 'system_steps' and every line's solver options (LINE_OPTIONS:
    {'al_rtol': 1e-10}); ``sweeps`` (api/system_sweeps.Sweeps: a watch circle, load-excursion
    curves) run after the equilibrium, in ``SystemResults.sweeps``, the file and the
    tables; the modes of each line with its ends held are asked in ``options``
    (MODES_OPTIONS: {'modes': 10, 'modes_added_mass': 1.0}), the bodies' and free
    points' modes too ({'system_modes': True, 'system_modes_line_mass': False}:
    SystemResults.body_modes). Returns a SystemResults."""
    from petsc4py import PETSc

    comm = comm or PETSc.COMM_WORLD
    say = say or (lambda line: None)
    settings, line_options, modes, body_modes = on_every_rank(comm, split_options, options)
    notes = tuple(notes) + friction_notes(system)
    for note in notes:
        say(f"petsc_rod: note: {note}")
    return run_system(comm, system, settings, line_options, say, output, table,
                      notes=notes, sweeps=sweeps or Sweeps(), modes=modes,
                      body_modes=body_modes)
