"""Run a sweep: every case in this process, on the ranks given, one after the other.

Each case is a whole run of the command line (cli.main.run builds, runs and destroys the
mesh, the problem and the solver) on the case's -rod_* options, the base options with
the case's own over them, handed to it as values (cli.main.run's ``texts``: parsed,
mapped to the model and compiled as the command line's), not written into PETSc's
options database; only a case's solver options (-rod_snes_*, -rod_slope_ksp_*, ...,
read by PETSc's objects from the database alone) are set there for the case, and the
database is put back as it was after it (options added removed, options changed
restored), so that nothing of one case reaches the next. A case starts
from the nearest converged case's result file (-rod_initial, walked in
-sweep_warm_steps steps from that case's scene to its own: docs/method.md §7; by
default not a case that starts from its catenary, which no neighbour beats; its seabed
friction's anchors laid as its own run lays them, -rod_initial_friction_anchors laid,
not on the neighbour's positions, so that its answer is the case's alone), and
again from its own start when that fails; a case that fails all the same is recorded
and the sweep goes on. After each case the summary (DIR/summary.csv, DIR/summary.md) and
the record DIR/sweep.json are rewritten on rank 0, so a sweep stopped part way keeps
the table of what ran.

Exit code: 0 when every case converged, 3 when some did not (the table says which and
why), 2 for bad sweep input before any run, 128 + n when a signal stopped a case (the
sweep stops there); a case whose record says the sweep ``stops`` (a system's case whose
lines' modes failed: sweep/system.py) ends it with that case's exit code, 4. A stopped
sweep's summary says so in its title and its record in ``stopped``.
"""

import difflib
import fcntl
import json
import os
import re
import sys
from dataclasses import dataclass

from petsc4py import PETSc

from petsc_rod.cli.line_run import abort_alone, every_rank_failed
from petsc_rod.cli.main import INPUT_FILE_OPTIONS, run
from petsc_rod.cli.options_files import every_options_file
from petsc_rod.cli.signals import Interrupts
from petsc_rod.cli.options import (BY_NAME, SOLVER_PREFIXES, check_same_on_every_rank, read_options,
                                   whole_values)
from petsc_rod.errors import RodError, RodInputError, RodNotConvergedError, on_every_rank
from petsc_rod.io.same_file import replaced_input
from petsc_rod.sweep import cases as sweep_cases
from petsc_rod.sweep import summary

# The options that decide the mesh: a case warm-starts only from a case with the same.
MESH_OPTIONS = ("rod_elements", "rod_length", "rod_mesh_grading", "rod_sections",
                "rod_line_types")
STARTS = ("auto", "nearest", "scene")
# With -sweep_start auto, the own starts that a neighbour's state does not beat
# (docs/sweeps.md, measured): the catenary of the case's own scene.
GOOD_OWN_STARTS = ("catenary",)


@dataclass(frozen=True)
class SweepSettings:
    """The -sweep_* options."""

    cases: str = ""              # -sweep_cases FILE
    output: str = ""             # -sweep_output DIR
    offsets: tuple = ()          # -sweep_offsets d1,d2,... (m)
    headings: tuple = sweep_cases.HEADINGS   # -sweep_headings near,far,cross
    current_headings: tuple = ()  # -sweep_current_headings deg,...
    current_speed: float = None  # -sweep_current_speed m/s
    start: str = "auto"          # -sweep_start auto|nearest|scene
    warm_steps: int = 1          # -sweep_warm_steps K
    retry: bool = True           # -sweep_retry: a failed warm start again from the scene
    offset_of: str = ""          # -sweep_offset_of NAME: a system's point or body offset


SWEEP_OPTIONS = {
    "sweep_cases": "FILE: a header row naming options (without '-'; optionally 'name'), one "
                   "row per case",
    "sweep_output": "DIR: DIR/<case>.h5, DIR/summary.csv, DIR/summary.md, DIR/sweep.json",
    "sweep_offsets": "d1,d2,...: vessel offsets of the hang-off, m",
    "sweep_headings": "near,far,cross: offset headings (near: toward the anchor; far: away; "
                      "cross: 90 deg anticlockwise from far seen from above)",
    "sweep_current_headings": "deg,...: headings of a uniform current, anticlockwise from +x",
    "sweep_current_speed": "m/s: their speed (default the base -rod_current's)",
    "sweep_start": "auto|nearest|scene: warm start from the nearest converged case, or "
                   "each case's own start; auto: nearest but for a case that starts from "
                   "its catenary (-rod_initial_shape catenary)",
    "sweep_warm_steps": "K: steps of the walk from the nearest case's scene (1)",
    "sweep_retry": "bool: a warm start that fails is run again from the case's own start "
                   "(true)",
    "sweep_offset_of": "NAME: with -rod_system, the point or held body the offsets move "
                       "(-sweep_headings then in deg anticlockwise from +x, default 0)",
}


def read_settings():
    """The -sweep_* options, refused (RodInputError) when unknown or malformed."""
    database = PETSc.Options()
    for name in database.getAll():
        if name.startswith("sweep_") and name not in SWEEP_OPTIONS:
            close = difflib.get_close_matches(name, list(SWEEP_OPTIONS), n=1)
            hint = f"; did you mean -{close[0]}?" if close else ""
            raise RodInputError(f"unknown option -{name}{hint}")

    whole = whole_values(database)

    def text(name):
        return whole[name] if database.hasName(name) else ""     # hasName marks it used

    def numbers(name):
        value = text(name)
        return tuple(sweep_cases.numbers(value, f"-{name}")) if value else ()

    output = text("sweep_output")
    if not output:
        raise RodInputError("-sweep_output DIR is needed: the folder of the cases' result "
                            "files and the summary")
    start = text("sweep_start") or "auto"
    if start not in STARTS:
        raise RodInputError(f"-sweep_start {start}: use auto, nearest or scene")
    steps = text("sweep_warm_steps") or "1"
    if not steps.isdigit() or int(steps) < 1:
        raise RodInputError(f"-sweep_warm_steps {steps}: a whole number of at least 1")
    speed = numbers("sweep_current_speed")
    if len(speed) > 1 or (speed and speed[0] < 0):
        raise RodInputError(f"-sweep_current_speed {text('sweep_current_speed')}: one speed "
                            "(m/s), not negative")
    headings = text("sweep_headings")
    retry = text("sweep_retry").lower() if database.hasName("sweep_retry") else "true"
    if retry not in ("", "1", "true", "yes", "on", "0", "false", "no", "off"):
        raise RodInputError(f"-sweep_retry {retry}: expected true or false")
    settings = SweepSettings(
        cases=text("sweep_cases"), output=output, offsets=numbers("sweep_offsets"),
        headings=tuple(h.strip() for h in headings.split(",")) if headings
        else sweep_cases.HEADINGS,
        current_headings=numbers("sweep_current_headings"),
        current_speed=speed[0] if speed else None, start=start, warm_steps=int(steps),
        retry=retry not in ("0", "false", "no", "off"), offset_of=text("sweep_offset_of"))
    if settings.offset_of and not database.hasName("rod_system"):
        raise RodInputError("-sweep_offset_of names a point or body of a system: give "
                            "-rod_system FILE, or drop it (a single line's offsets move its "
                            "hang-off)")
    if not (settings.cases or settings.offsets or settings.current_headings):
        raise RodInputError("a sweep needs cases: -sweep_cases FILE, -sweep_offsets d1,... "
                            "or -sweep_current_headings deg,...")
    return settings


def known_option(name):
    """Whether ``name`` (without '-') is an option a case may set."""
    return name in BY_NAME or name.startswith(SOLVER_PREFIXES)


known_option.names = list(BY_NAME)      # for the hint of the closest name


def make_cases(settings, values):
    """The sweep's cases: the product of the case file's rows, the offsets and the
    current headings (sweep/cases.py)."""
    listed = sweep_cases.read_cases(settings.cases, known_option) if settings.cases else None
    offsets = (sweep_cases.offset_cases(settings.offsets, settings.headings, values)
               if settings.offsets else None)
    currents = (sweep_cases.current_cases(settings.current_headings, settings.current_speed,
                                          values) if settings.current_headings else None)
    made = sweep_cases.product(listed, offsets, currents)
    sweep_cases.check_unique(made, "the sweep")
    return made


# The sweep's own files in its folder.
SWEEP_FILES = ("summary.csv", "summary.md", "sweep.json")


def case_files(name):
    """The files a case named ``name`` may leave in the sweep's folder: its result, the
    steps an interrupted run keeps (io.results.ResultWriter.kept_name), its -rod_table
    and the regions' and ends' tables beside it (io/line_table.py)."""
    return (f"{name}.h5", f"{name}.interrupted.h5", f"{name}.csv", f"{name}_regions.csv",
            f"{name}_ends.csv")


def check_file_names(cases):
    """Refuse a case whose files (case_files) would be the sweep's own or another case's:
    a case named ``summary`` would write its table to summary.csv, a case ``a_regions``
    its table to case ``a``'s regions' table."""
    owners = {name: "the sweep's own" for name in SWEEP_FILES}
    for case in cases:
        for name in case_files(case.name):
            if name in owners:
                raise RodInputError(
                    f"case {case.name}: its file {name} would also be {owners[name]}; rename "
                    f"the case (a case's files are <name>.h5, <name>.interrupted.h5, "
                    f"<name>.csv, <name>_regions.csv, <name>_ends.csv; the sweep's {', '.join(SWEEP_FILES)})")
            owners[name] = f"case {case.name}'s"


def input_files(settings, values, cases):
    """(what names it, path) of every file the sweep's cases read: the options files,
    the case file, each input file option of the base options and of every case."""
    read = [("-options_file", path) for path in every_options_file(sys.argv)]
    if settings.cases:
        read.append(("-sweep_cases", settings.cases))
    for name in INPUT_FILE_OPTIONS:
        read.append((f"-{name}", values[name]))
        read += [(f"-{name} of case {case.name}", case.options[name]) for case in cases
                 if name in case.options]
    return read


def previous_files(folder):
    """The files of the folder (names), and those of them a previous sweep wrote there:
    its own (SWEEP_FILES) and the files of the cases its sweep.json records; None for
    the latter when the folder holds no readable sweep.json."""
    entries = sorted(os.listdir(folder))
    if "sweep.json" not in entries:
        return entries, None
    try:
        with open(os.path.join(folder, "sweep.json"), encoding="utf-8") as f:
            names = [case["name"] for case in json.load(f)["cases"]]
    except (OSError, ValueError, KeyError, TypeError):
        return entries, None
    return entries, set(SWEEP_FILES).union(*(case_files(str(name)) for name in names))


# A run's partial file (io.results.partial_name: the file, rank 0's pid, a tag) and the
# temporary file of a summary being written whole (io.same_file.write_whole).
RUN_PARTIAL = re.compile(r"(?P<file>.+)\.(?P<pid>\d+)-[0-9a-f]{6}\.partial")
SUMMARY_PARTIAL = re.compile(r"\.(?P<file>.+)\.[^.]+\.partial\.(?:csv|md|json)")


def process_alive(pid):
    """Whether a process ``pid`` runs on this machine (one of another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def left_partials(entries, files):
    """(stale, live): the partial files among ``entries`` (names) of the sweep files
    ``files`` (its own and its cases' names, case_files), those a killed sweep or run
    left (its process gone: the folder's lock keeps every other sweep out) and those
    whose run's process still lives."""
    stale, live = [], []
    for entry in entries:
        run_partial = RUN_PARTIAL.fullmatch(entry)
        summary_partial = SUMMARY_PARTIAL.fullmatch(entry)
        if run_partial and run_partial["file"] in files:
            (live if process_alive(int(run_partial["pid"])) else stale).append(entry)
        elif summary_partial and summary_partial["file"] in SWEEP_FILES:
            stale.append(entry)
    return stale, live


def _claim_folder(folder, cases, inputs):
    """Rank 0's part of claim_folder; returns the locked descriptor of the folder."""
    where = f"-sweep_output {folder}"
    try:
        lock = os.open(folder, os.O_RDONLY)
    except OSError as error:
        raise RodInputError(f"{where}: cannot be read ({error.strerror}); choose another "
                            "folder") from None
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(lock)
        raise RodInputError(f"{where}: another sweep is writing into it; wait for it or "
                            "choose another folder") from None
    try:
        try:
            entries, ours = previous_files(folder)
        except OSError as error:
            raise RodInputError(f"{where}: cannot be listed ({error.strerror}); choose "
                                "another folder") from None
        # a killed sweep's partial files, by the names of its cases or of this sweep's
        stale, live = left_partials(entries, (ours or set()).union(
            SWEEP_FILES, *(case_files(case.name) for case in cases)))
        if live:
            raise RodInputError(
                f"{where}: holds {live[0]}, the partial file of a run that is still running "
                f"(process {RUN_PARTIAL.fullmatch(live[0])['pid']}); wait for it to end, or "
                "choose another folder")
        # the page of a report of the earlier sweep is stale with it
        strangers = [name for name in entries
                     if name not in stale and (ours is None or name not in ours)
                     and not (ours is not None and name.endswith(".html")
                              and summary.is_report_page(os.path.join(folder, name)))]
        if strangers:
            raise RodInputError(
                f"{where}: holds {strangers[0]}"
                + (f" and {len(strangers) - 1} more" if len(strangers) > 1 else "")
                + ", not a file of an earlier sweep into it (one its sweep.json lists); a "
                "sweep writes into a new or empty folder, or an earlier sweep's, whose files "
                "it removes first: choose another folder")
        names = (entries + list(SWEEP_FILES)
                 + [name for case in cases for name in case_files(case.name)])
        clash = replaced_input([("the sweep's file", os.path.join(folder, name))
                                for name in names], inputs,
                               "the sweep would remove or replace; choose another folder")
        if clash:
            raise RodInputError(f"{where}: {clash}")
        for name in entries:            # the earlier sweep's files, none an input
            try:
                os.remove(os.path.join(folder, name))
            except OSError as error:
                raise RodInputError(f"{where}: the earlier sweep's {name} cannot be "
                                    f"removed ({error.strerror}); remove it or choose "
                                    "another folder") from None
    except BaseException:
        os.close(lock)
        raise
    return lock


def claim_folder(comm, folder, cases, inputs):
    """Take the output folder for this sweep, before any case runs (docs/sweeps.md,
    "Output"): locked for the sweep (a second sweep into it is refused while this one
    runs: flock, released when the process ends); a folder that holds files is taken
    only when they are an earlier sweep's (its sweep.json's cases' files and its
    summary), which are then removed, so that every file in the folder is in this
    sweep's summary; no file removed or written may be an input (``inputs``:
    input_files). The partial files a killed sweep left, of its cases or of this sweep's
    (left_partials), are its files too. Collective; returns rank 0's lock (a descriptor
    to close), else None."""
    return on_every_rank(comm, _claim_folder if comm.getRank() == 0 else lambda *a: None,
                         folder, cases, inputs)


def make_folder(comm, path):
    """Create the output folder on rank 0; a folder that cannot be made is bad input on
    every rank."""
    problem = None
    if comm.getRank() == 0:
        try:
            os.makedirs(path, exist_ok=True)
            if not os.access(path, os.W_OK):
                problem = "cannot write in it"
        except OSError as error:
            problem = error.strerror or str(error)
    problem = comm.tompi4py().bcast(problem, root=0)
    if problem:
        raise RodInputError(f"-sweep_output {path}: {problem}")


def with_options(comm, options, action):
    """``action()`` with ``options`` ({name: text}) set in PETSc's options database, the
    database put back as it was afterwards: options added (by the case or by the run)
    removed, options changed restored."""
    database = PETSc.Options()
    before = database.getAll()
    for name, value in options.items():
        database.setValue(name, value)
    try:
        return action()
    finally:
        after = database.getAll()
        for name in after:
            if name not in before:
                database.delValue(name)
        for name, value in before.items():
            if after.get(name, object()) != value:
                database.setValue(name, "" if value is None else value)


# The exit code a case is recorded with where its run raised (Sweep._run): that of
# petsc_rod's RodError, of a failure that is none of the classes with a code of their own.
FAILED = RodError.exit_code


class Sweep:
    """The state of a running sweep: the cases, what has converged, the records."""

    def __init__(self, comm, settings, cases, base):
        self.comm, self.settings, self.cases = comm, settings, cases
        self.base = base                         # the base options database, {name: text}
        self.varied = sweep_cases.varied(cases)
        self.scales = sweep_cases.spreads([self.swept(c) for c in cases])
        self.records = []
        self.converged = []                      # (case, its file) of the converged cases
        self.stopped = ""                        # why the sweep ended before its last case
        # where the ranks agree on a case's failure (made now: creating it is collective)
        self._failures = comm.tompi4py().Dup()
        self._error = None                       # the last case's failure, its words

    def say(self, text):
        PETSc.Sys.Print(text, comm=self.comm)

    def file(self, case):
        return os.path.join(self.settings.output, f"{case.name}.h5")

    def value(self, case, name):
        """The text of option ``name`` in effect for ``case`` (its own or the base's)."""
        return case.options.get(name, self.base.get(name))

    def swept(self, case):
        return {name: self.value(case, name) for name in self.varied
                if self.value(case, name) is not None}

    def warm_start(self, case):
        """The converged case, of the same mesh, nearest to ``case``, or None."""
        if self.settings.start == "scene" or "rod_initial" in case.options:
            return None
        if (self.settings.start == "auto"
                and self.value(case, "rod_initial_shape") in GOOD_OWN_STARTS):
            return None
        same_mesh = [(c, f) for c, f in self.converged
                     if all(self.value(c, o) == self.value(case, o) for o in MESH_OPTIONS)]
        index = sweep_cases.nearest(self.swept(case), [self.swept(c) for c, _ in same_mesh],
                                    self.scales)
        return None if index is None else same_mesh[index]

    def run_case(self, number, case):
        """Run one case (a warm start, then its own start if that fails and -sweep_retry);
        returns its record."""
        options = {**case.options, "rod_output": self.file(case)}
        if self.base.get("rod_table"):          # the table of each case beside its file
            options["rod_table"] = self.file(case)[:-3] + ".csv"
        shown = " ".join(f"-{k} {v}" for k, v in case.options.items()) or "(the base options)"
        warm = self.warm_start(case)
        code = None
        start = "own start"
        if warm is not None:
            source, path = warm
            walk = {"rod_initial": path}
            if "rod_steps" not in case.options:
                walk["rod_steps"] = str(self.settings.warm_steps)
            if self.value(case, "rod_initial_friction_anchors") is None:
                # the case's seabed friction anchored as its own run's, not on its
                # neighbour's positions: its answer is not the sweep's order's
                walk["rod_initial_friction_anchors"] = "laid"
            self.say(f"sweep: case {number}/{len(self.cases)} {case.name}: {shown}; warm "
                     f"start from {source.name}")
            code = self._run(case, {**options, **walk})
            start = f"from {source.name}"
            if code in (3, 4, FAILED) and self.settings.retry:
                self.say(f"sweep: case {case.name}: the warm start from {source.name} ended "
                         f"with exit {code}; again from the case's own start")
                start = f"own start (from {source.name}: exit {code})"
                code = None
        if code is None:
            if warm is None:
                self.say(f"sweep: case {number}/{len(self.cases)} {case.name}: {shown}")
            code = self._run(case, options)
        if code == 0:
            self.converged.append((case, self.file(case)))
        if code == 2:                   # refused before it started
            start = ""
        written = code in (0, 3) and os.path.exists(self.file(case))
        record = {"name": case.name, "options": self.swept(case), "set": case.options,
                  "code": code, "start": start,
                  "file": os.path.abspath(self.file(case)) if written else None}
        if code == FAILED and self._error:
            record["error"] = self._error
        return record

    def _run(self, case, options):
        """petsc_rod's run of ``case`` with ``options`` {name: text} over the base ones
        (its solver options alone set in PETSc's database): its exit code, or FAILED
        where it raised (run turns petsc_rod's errors and PETSc's into codes; anything
        else, a LinAlgError say, is a failure of this case, not of the sweep), the
        error's words then kept for the record. Where only some ranks raised, the others
        wait in a collective call: the ranks meet on a communicator of their own
        (cli.line_run.every_rank_failed) and a rank that is alone ends the sweep, as a run
        ends (cli.line_run.abort_alone; the summary of the cases before it is written).
        Collective."""
        self._error = None
        texts = {**self.base, **options}
        if "rod_initial" not in texts:
            # where the restart's anchors come from means nothing to a case run from its
            # own start (the first, a retry, -sweep_start scene): not refused there
            texts.pop("rod_initial_friction_anchors", None)
        solvers = {name: text for name, text in options.items() if name not in BY_NAME}
        try:
            return with_options(self.comm, solvers, lambda: run(self.comm, texts))
        except Exception as error:          # noqa: BLE001 (any failure is the case's)
            return self.failed(case, error)

    def failed(self, case, error):
        """FAILED for ``case``, whose run raised ``error``, its words kept for the record,
        once every rank has failed (a rank failing alone ends the sweep: _run).
        Collective."""
        words = f"{type(error).__name__}: {error}".splitlines()[0]
        if not every_rank_failed(self._failures):
            abort_alone(self.comm, f"sweep case {case.name}: {words}")
        self.say(f"petsc_rod.sweep: case {case.name} failed: {words}")
        self._error = words
        return FAILED

    def destroy(self):
        self._failures.Free()

    # what the summary's title says the cases are of, and the record's own entries
    of = ""
    record_entries = {}

    def table(self):
        """(header, rows) of the summary (summary.table)."""
        return summary.table(self.records, self.varied)

    def write(self):
        """Rewrite the summary and the record (rank 0)."""
        if self.comm.getRank() != 0:
            return None
        header, rows = self.table()
        folder = self.settings.output
        # the title's last part and the record's "stopped", where the sweep stopped
        stopped = (f"stopped {self.stopped}; {len(self.cases) - len(self.records)} "
                   "case(s) not run" if self.stopped else "")
        summary.write_csv(os.path.join(folder, "summary.csv"), header, rows)
        title = f"Sweep of {len(self.cases)} case(s){self.of}"
        if stopped:
            title += f"; {stopped}"
        summary.write_markdown(os.path.join(folder, "summary.md"), header, rows, title=title)
        summary.write_record(os.path.join(folder, "sweep.json"), {
            "base_options": self.base, "varied": self.varied, "cases": self.records,
            **self.record_entries, **({"stopped": stopped} if stopped else {}),
            "settings": {k: list(v) if isinstance(v, tuple) else v
                         for k, v in vars(self.settings).items()}})
        return summary.markdown(header, rows)


def run_sweep(comm=None):
    """The whole sweep on ``comm``; returns the exit code."""
    comm = comm or PETSc.COMM_WORLD
    database = PETSc.Options()

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    if database.hasName("help"):
        say("petsc_rod.sweep options (docs/sweeps.md; every -rod_* option of petsc_rod is "
            "the base of the cases):")
        for name, meaning in SWEEP_OPTIONS.items():
            say(f"  -{name} {meaning}")
        return 0
    try:
        check_same_on_every_rank(comm)
        settings = read_settings()
        values, _ = read_options()
        made = make_cases(settings, values)
        check_file_names(made)
        make_folder(comm, settings.output)
        lock = claim_folder(comm, settings.output, made, input_files(settings, values, made))
    except RodError as error:
        say(f"petsc_rod.sweep: error: {error}")
        database.setValue("options_left", "0")
        return error.exit_code
    sweep = Sweep(comm, settings, made, base_options())
    say(f"petsc_rod.sweep: {len(made)} case(s) varying "
        f"{', '.join('-' + v for v in sweep.varied) or 'nothing'}, into {settings.output}")
    return run_cases(comm, sweep, settings, lock)


def base_options():
    """{name: text} of the -rod_* options of PETSc's database, the cases' base (the
    sweep sets each case's -rod_output)."""
    base = {name: ("" if value is None else value)
            for name, value in PETSc.Options().getAll().items() if name.startswith("rod_")}
    base.pop("rod_output", None)
    return base


def run_cases(comm, sweep, settings, lock):
    """Run ``sweep``'s cases in turn (a Sweep, or a system's: sweep/system.py; its
    ``interrupts`` set to the run's cli/signals.Interrupts), its summary written before
    the first and after each, its lines said; the folder's ``lock`` closed; returns the
    exit code (module docstring)."""
    made = sweep.cases

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    sweep.write()           # the folder is this sweep's from the start
    stop_code = None                # the exit code of a sweep that stopped
    # a stop signal between two cases (each run records its own: cli/signals.py) ends
    # the sweep before the next, as one during a case ends it after that one
    with Interrupts(comm) as interrupts:
        sweep.interrupts = interrupts
        for number, case in enumerate(made, start=1):
            received = interrupts.received()
            if received:
                sweep.stopped = f"by {Interrupts.name(received)} before case {case.name}"
                say(f"petsc_rod.sweep: stopped {sweep.stopped}")
                stop_code = 128 + received
                break
            record = sweep.run_case(number, case)
            sweep.records.append(record)
            if record["code"] >= 128 or record.get("stops"):
                sweep.stopped = (f"after case {case.name}: {record['stops']}"
                                 if record.get("stops") else
                                 f"by {Interrupts.name(record['code'] - 128)} during "
                                 f"case {case.name}")
                if record.get("stops"):
                    say(f"petsc_rod.sweep: stopped {sweep.stopped}")
                stop_code = record["code"]
            sweep.write()
            if stop_code is not None:
                break
    sweep.destroy()
    text = sweep.write()
    if text:
        say(text.rstrip())
    failed = [r["name"] for r in sweep.records if r["code"] != 0]
    say(f"petsc_rod.sweep: {len(sweep.records) - len(failed)} of {len(made)} case(s) "
        f"converged" + (f"; not: {', '.join(failed)}" if failed else "")
        + (f"; {len(made) - len(sweep.records)} not run" if stop_code is not None else "")
        + f"; summary in {os.path.join(settings.output, 'summary.md')}")
    PETSc.Options().setValue("options_left", "0")
    if lock is not None:    # else released when the process ends
        os.close(lock)
    if stop_code is not None:
        return stop_code
    return 0 if not failed else RodNotConvergedError.exit_code
