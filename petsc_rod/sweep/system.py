"""A sweep of a system: ``python -m petsc_rod.sweep -rod_system FILE -sweep_output DIR
(-sweep_cases FILE | -sweep_offsets d1,... -sweep_offset_of NAME ...)`` (docs/sweeps.md,
"Sweeps of a system").

Each case is the system's run (api/system_run.run_system, the path of
``python -m petsc_rod -rod_system FILE``) with the base options and the case's own over
them (cli_system.changed: a case's loads and offsets add to the base's per name, its
lines' lengths replace the base's); a case sets what tells one load case of a system
from another (CASE_OPTIONS): the bodies' external loads (-rod_system_body_load), the
offsets of fixed or prescribed points and held bodies (-rod_system_offset;
-sweep_offsets makes them along headings) and the lines' lengths
(-rod_system_line_length). The cases run one after the other on
one SystemSolver: each is the solver's warm re-solve from the last converged case's
equilibrium (SystemSolver.replace: the held points and bodies walked, the loads
continued, every line warm from its own last state), or with -sweep_start scene, or
where the case's lines differ from the last case's (a length), a solver made afresh; a
warm case that fails runs again on a fresh solver (-sweep_retry). Each case writes DIR/<case>.h5 (the
system's result file); after each, DIR/summary.csv, DIR/summary.md and DIR/sweep.json
are rewritten on rank 0 with a row per case: the bodies' positions, each line's
fairlead tension and the largest tension over the lines.

A case whose lines' modes fail in their eigensolver (analysis/modes.ModesFailed: an
-rod_modes_eps_* or -rod_modes_st_* setting SLEPc refuses) stops the sweep there, after
its one line, exit 4 (runner.run_cases, as a stop signal): every case asks for the
same modes with the same options, so each later one would fail alike, each after a
failed PETSc solve whose state stays in the process; the summary keeps the cases run and
says that the sweep stopped and how many were not run.

Exit code as runner.run_sweep's: 0 every case converged, 3 some did not (a case whose
equilibrium, or a case of its watch circle or load-excursion curves, is a saddle of the
system is such a case: exit 3 as its run alone, cli_system.saddle_error, its file
written; so is one whose watch circle or curves left a case without an equilibrium,
cli_system.gap_error), 2 bad sweep input before any run, 4 a case whose lines' modes
failed (above: the sweep stops there), 128 + n a stop signal.
"""

import os
import sys

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.modes import ModesFailed
from petsc_rod.api.system_run import run_system
from petsc_rod.cli.options import check_same_on_every_rank, read_options, values_of
from petsc_rod.cli.options_files import every_options_file
from petsc_rod.cli_system import (check_movable, finished_error, laid_system, prepared,
                                  saddle_error)
from petsc_rod.errors import RodError, RodInputError, on_every_rank
from petsc_rod.sweep import cases as sweep_cases
from petsc_rod.sweep import summary
from petsc_rod.sweep.runner import (FAILED, Sweep, base_options, check_file_names,
                                    claim_folder, make_folder, read_settings, run_cases,
                                    run_sweep)
from petsc_rod.system.equilibrium import SystemSolver
from petsc_rod.system.held_line import held_lines

# What a case of a system's sweep may set: what SystemSolver.replace re-solves warm.
CASE_OPTIONS = ("rod_system_body_load", "rod_system_offset", "rod_system_line_length")


def known_case_option(name):
    """Whether ``name`` (without '-') is an option a system's case may set."""
    return name in CASE_OPTIONS


known_case_option.names = list(CASE_OPTIONS)


def offset_cases(offsets, headings, name):
    """The offsets of the point or body ``name``: for each heading h (deg, anticlockwise
    from +x seen from above) and offset d (m), -rod_system_offset NAME,d cos h,d sin h,0;
    an offset 0 is one case ("offset0", the file's position), whatever the headings."""
    cases = []
    if any(d == 0 for d in offsets):
        cases.append(sweep_cases.Case("offset0", {"rod_system_offset": f"{name},0,0,0"}))
    for heading in headings:
        angle = np.radians(heading)
        for d in offsets:
            if d != 0:
                move = d * np.array([np.cos(angle), np.sin(angle), 0.0])
                move[np.abs(move) < 1e-12 * abs(d)] = 0.0
                cases.append(sweep_cases.Case(f"heading{heading:g}_offset{d:g}",
                                              {"rod_system_offset":
                                               f"{name},{sweep_cases.fmt(move)}"}))
    sweep_cases.check_unique(cases, "-sweep_offsets")
    return cases


def make_cases(settings, system):
    """The cases of a system's sweep (``system``: the base System, whose names the
    offsets' point or body must be one of, a fixed or prescribed point or a body held
    in every direction the offsets move it: cli_system.check_movable): the product of
    the case file's rows and the offsets."""
    if settings.current_headings:
        raise RodInputError("-sweep_current_headings turns a single line's current; a "
                            "system's current is the base options' (-rod_current or "
                            "-rod_current_profile): give -sweep_cases or -sweep_offsets")
    if bool(settings.offsets) != bool(settings.offset_of):
        raise RodInputError("-sweep_offsets and -sweep_offset_of NAME go together with "
                            "-rod_system: the offsets move the point or held body NAME")
    offsets = None
    if settings.offsets:
        names = [item.name for item in (*system.points, *system.bodies)]
        if settings.offset_of not in names:
            raise RodInputError(f"-sweep_offset_of {settings.offset_of}: no point or body "
                                f"of that name; the system's: {', '.join(names)}")
        headings = (0.0,)
        if settings.headings != sweep_cases.HEADINGS:
            headings = tuple(sweep_cases.numbers(",".join(settings.headings),
                                                 "-sweep_headings (deg, with -rod_system)"))
        offsets = offset_cases(settings.offsets, headings, settings.offset_of)
        # the directions some case moves it in, as the cases give them
        moves = np.array([case.options["rod_system_offset"].split(",")[1:]
                          for case in offsets], dtype=float)
        check_movable(system.node(settings.offset_of), np.any(moves != 0, axis=0),
                      "-sweep_offset_of", "-sweep_cases of rod_system_body_load")
    listed = (sweep_cases.read_cases(
        settings.cases, known_case_option, "an option a system's case sets: "
        f"{', '.join(CASE_OPTIONS)}") if settings.cases else None)
    made = sweep_cases.product(listed, offsets)
    sweep_cases.check_unique(made, "the sweep")
    return made


def case_numbers(system, results):
    """[(column, value)] of a converged case's summary row: the Newton iterations and
    residual, each body's position (x, y, z in m; roll, pitch, yaw in deg), each line's
    fairlead tension (the riser numbers' top end, N), the largest tension over every
    line (its sections' largest effective tension, N) and the line that carries it."""
    row = [("iterations (1)", results.iterations), ("residual (1)", results.residual)]
    for name, body in results.bodies.items():
        x = body.position
        row += [(f"{name} {axis} (m)", float(v)) for axis, v in zip("xyz", x[:3])]
        row += [(f"{name} {angle} (deg)", float(np.degrees(v)))
                for angle, v in zip(("roll", "pitch", "yaw"), x[3:])]
    largest = {}
    for line in system.lines:
        scalars = results.lines[line.name].scalars
        row.append((f"{line.name} fairlead_tension (N)", float(scalars["fairlead_tension"])))
        largest[line.name] = float(np.max(scalars["section_max_tension"]))
    top = max(largest, key=largest.get)
    return row + [("max_tension (N)", largest[top]), ("max_tension_line", top)]


def table(records, varied):
    """(header, rows) of the summary: case, the varied options, exit, status, start, then
    the numbers of case_numbers (blank for a case that did not converge)."""
    columns = []
    for record in records:
        columns += [name for name, _ in record.get("numbers", ())
                    if name not in columns]
    header = (["case"] + [f"-{name}" for name in varied] + ["exit", "status", "start"]
              + columns)
    rows = []
    for record in records:
        status = summary.exit_reason(record["code"])
        if record.get("saddle"):
            status = "not converged (saddle)"
        if record.get("gaps"):
            status = "not converged (a sweep's case without an equilibrium)"
        if record.get("error"):
            status = f"failed ({record['error']})"
        numbers = dict(record.get("numbers", ()))
        rows.append([record["name"]] + [record["options"].get(n, "(base)") for n in varied]
                    + [record["code"], status, record.get("start", "")]
                    + [numbers.get(column, "") for column in columns])
    return header, rows


class SystemSweep(Sweep):
    """The state of a running system sweep (runner.Sweep's, its cases run otherwise):
    the solver kept between the cases; ``interrupts`` (cli/signals.Interrupts) set by
    runner.run_cases."""

    of = " of a system"
    record_entries = {"system": True}

    def __init__(self, comm, settings, cases, base):
        super().__init__(comm, settings, cases, base)
        self.interrupts = None
        self.solver = None
        self._stops = None

    def drop_solver(self):
        if self.solver is not None:
            self.solver.destroy()
            self.solver = None

    def run_case(self, number, case):
        """Prepare and run one case (warm on the kept solver, then afresh if that fails
        and -sweep_retry); returns its record."""
        texts = {**self.base, **case.options}       # the summary's varied columns
        shown = " ".join(f"-{k} {v}" for k, v in case.options.items()) or "(the base options)"
        record = {"name": case.name, "options": {n: texts[n] for n in self.varied
                                                 if n in texts},
                  "set": case.options, "code": 2, "start": "", "file": None}
        try:
            made = on_every_rank(self.comm, lambda: prepared(*values_of(self.base),
                                                             case=case.options))
        except RodInputError as error:
            self.say(f"sweep: case {number}/{len(self.cases)} {case.name}: {shown}")
            self.say(f"petsc_rod: error: {error}")
            return record
        warm = self.solver is not None and self.settings.start != "scene"
        # other lines (a length) are a new solver's: the kept one re-solves loads and
        # held positions only (SystemSolver.replace)
        relined = warm and repr(made[0].lines) != repr(self.solver.system.lines)
        warm = warm and not relined
        self.say(f"sweep: case {number}/{len(self.cases)} {case.name}: {shown}"
                 + ("; warm from the last converged case" if warm else ""))
        if not warm:
            self.drop_solver()
        code, results = self._run(case, made)
        start = ("from the last case" if warm else
                 "own start (its lines differ)" if relined else "own start")
        if warm and code in (3, 4, FAILED) and self.settings.retry and not self._stops:
            self.say(f"sweep: case {case.name}: the warm start ended with exit {code}; "
                     "again from the case's own start")
            self.drop_solver()
            start = f"own start (warm: exit {code})"
            code, results = self._run(case, made)
        if self._stops:
            # the modes' options are every case's: no (further) retry, no next case
            self.drop_solver()
            record.update(code=code, start=start, error=self._error, stops=self._stops)
            return record
        if code != 0:
            self.drop_solver()
        record.update(code=code, start=start if code != 2 else "")
        if results is not None:
            # a saddle of the system's or an incomplete sweep's file is written,
            # converged = 0 there (a single line's exit 3 likewise:
            # runner.Sweep.run_case)
            record["file"] = os.path.abspath(self.file(case))
        if code == 0:
            record["numbers"] = case_numbers(made[0], results)
        elif code == 3 and results is not None:
            record["saddle" if saddle_error(results) else "gaps"] = True
        if code == FAILED and self._error:
            record["error"] = self._error
        return record

    def _run(self, case, made):
        """(exit code, SystemResults or None) of the system's run of ``case`` on the
        kept solver (made first where there is none); a ModesFailed (on every rank:
        api/system_run.line_modes shares it) sets ``_stops``, why the sweep ends after
        this case (module docstring). Collective."""
        system, notes, text, settings, options, sweeps, modes, body_modes = made
        self._error = self._stops = None
        try:
            if self.solver is None:
                laid = on_every_rank(self.comm, laid_system, values_of(self.base)[0],
                                     system)
                self.solver = SystemSolver(system, held_lines(system, options, laid),
                                           self.comm, settings=settings)
            results = run_system(self.comm, system, settings, options, self.say,
                                 self.file(case), None, text, notes, self.interrupts,
                                 sweeps, modes, body_modes, solver=self.solver)
            # a saddle or a sweep's gap: the case's run alone's exit 3 (cli_system.run),
            # its file kept
            return finished_error(results, self.say, self.file(case)), results
        except ModesFailed as error:
            self.say(f"petsc_rod: error: {error}")
            self._error = "the modes' eigensolver failed"
            self._stops = ("the lines' modes failed in their eigensolver, and every case "
                           "asks for the same modes with the same options (-rod_modes*): "
                           "each would fail alike")
            return error.exit_code, None
        except RodError as error:
            self.say(f"petsc_rod: error: {error}")
            return error.exit_code, None
        except PETSc.Error as error:
            self.say(f"petsc_rod: error: {error}")
            return 4, None
        except Exception as error:          # noqa: BLE001 (any failure is the case's)
            return self.failed(case, error), None

    def destroy(self):
        self.drop_solver()
        super().destroy()

    def table(self):
        return table(self.records, self.varied)


def _prepare(comm):
    """(settings, base texts, cases, the folder's lock) of the sweep, before any case
    runs; RodInputError for bad sweep input."""
    check_same_on_every_rank(comm)
    settings = read_settings()
    values, given = read_options()
    if "rod_table" in given:
        raise RodInputError("-rod_table: a system's sweep writes each case's result file "
                            "and the summary table; drop -rod_table")
    given.discard("rod_output")                 # the sweep sets each case's
    system = on_every_rank(comm, prepared, values, given)[0]
    made = make_cases(settings, system)
    check_file_names(made)
    make_folder(comm, settings.output)
    inputs = [("-options_file", path) for path in every_options_file(sys.argv)]
    inputs.append(("-rod_system", values["rod_system"]))
    if settings.cases:
        inputs.append(("-sweep_cases", settings.cases))
    lock = claim_folder(comm, settings.output, made, inputs)
    base = base_options()
    return settings, base, made, lock


def run_system_sweep(comm=None):
    """The whole sweep of a system on ``comm``; returns the exit code."""
    comm = comm or PETSc.COMM_WORLD
    database = PETSc.Options()
    if database.hasName("help"):
        return run_sweep(comm)

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    try:
        settings, base, made, lock = _prepare(comm)
    except RodError as error:
        say(f"petsc_rod.sweep: error: {error}")
        database.setValue("options_left", "0")
        return error.exit_code
    sweep = SystemSweep(comm, settings, made, base)
    say(f"petsc_rod.sweep: {len(made)} case(s) of the system {base['rod_system']} varying "
        f"{', '.join('-' + v for v in sweep.varied) or 'nothing'}, into {settings.output}")
    return run_cases(comm, sweep, settings, lock)
