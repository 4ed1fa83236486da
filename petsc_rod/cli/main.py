"""Command line: read the -rod_* options, check them, map them to the model
(scene_options.model_from_options) and run it on the one path of a line's run
(line_run.plan_line, run_line), which the Python API takes too; report. Returns the
process exit code (docs/errors.md: 0 converged, 2 bad input, 3 not converged,
4 diverged or a PETSc error during the solve, 5 the result could not be written,
128 + n stopped by signal n)."""

import signal
import sys

from petsc4py import PETSc

from petsc_rod.cli.line_run import (AgreedFailures, petsc_failure, plan_line, run_line)
from petsc_rod.cli.options import (OPTIONS, check_anderson_depth, check_same_on_every_rank,
                                   check_factor_switches, check_snes_type,
                                   help_text, read_options, unused_options, values_of)
from petsc_rod.cli.options_files import every_options_file
from petsc_rod.cli.phases import SETUP
from petsc_rod.cli.ranks import run_placed
from petsc_rod.cli.scene_options import model_from_options
from petsc_rod.cli.signals import Interrupts
from petsc_rod.errors import RodDivergedError, RodError, RodInputError
from petsc_rod.figures.modes import shapes_path
from petsc_rod.io import line_table
from petsc_rod.io.same_file import replaced_input

# The options that name a file the run reads.
INPUT_FILE_OPTIONS = tuple(option.name for option in OPTIONS
                           if option.metavar == "FILE" and option.name != "rod_output")


def options_record(texts=None):
    """The whole options database, with ``texts`` {name: text} in place of its own
    where given, as '-name value' lines (the file's ``options``)."""
    options = {**PETSc.Options().getAll(), **(texts or {})}
    return "\n".join(f"-{k} {v}".rstrip() for k, v in sorted(options.items()))


def run(comm=None, texts=None):
    """The whole program on ``comm``; returns the exit code. ``texts`` {name: text}: the
    -rod_* options of the run (a sweep's case, sweep/runner.py), in place of those of
    PETSc's options database, which then gives the solvers' options (-rod_snes_*,
    -rod_slope_ksp_*, ...) alone. The run itself (its PETSc objects, the result file) is
    line_run.run_line's; errors become the one line and the exit code here."""
    comm = comm or PETSc.COMM_WORLD
    database = PETSc.Options()

    def say(text):
        PETSc.Sys.Print(text, comm=comm)

    def sections_named(pieces, elements):
        if pieces is None or "rod_elements" in given:
            return None
        return f"-rod_sections ({elements} elements in all)"

    with Interrupts(comm) as interrupts:
        try:
            # a rank that fails alone before the run (a numpy error reading a file, say)
            with AgreedFailures(comm):
                if texts is None:
                    check_same_on_every_rank(comm)
                    values, given = read_options()
                else:                       # the same on every rank: the sweep's
                    values, given = values_of(texts)
                check_system_options(given)
                check_anderson_depth()      # before any PETSc object is made
                check_snes_type()
                check_factor_switches()
                if database.hasName("help"):
                    for line in help_text():
                        say(line)
                with SETUP:
                    plan = plan_line(comm, model_from_options(values, given), values, given,
                                     mesh_named=sections_named)
                check_inputs_kept(values, comm)
                if database.hasName("help"):
                    run_line(comm, plan, say, check_only=True)
                    return 0
                code = run_placed(comm, plan, say, options=options_record(texts),
                                  interrupts=interrupts)
                for name in unused_options():
                    say(f"petsc_rod: warning: option -{name} was set but not used")
                return code
        except RodError as error:
            if getattr(error, "signal_number", 0) == signal.SIGPIPE:
                # the output is a pipe nobody reads any more: the line goes to stderr
                if comm.getRank() == 0:
                    sys.stderr.write(f"petsc_rod: error: {error}\n")
            else:
                say(f"petsc_rod: error: {error}")
            database.setValue("options_left", "0")
            return error.exit_code
        except PETSc.Error as error:        # inside a solve: the SNES's own options, say
            say(f"petsc_rod: error: {petsc_failure(error)}")
            database.setValue("options_left", "0")
            return RodDivergedError.exit_code


def check_system_options(given):
    """Refuse a system's option in a single line's run, where it would be silently
    unused: -rod_system itself (python -m petsc_rod hands a run with it to
    cli_system.py; a sweep's cases, which come here, are single lines) and the system's
    other options without it."""
    if "rod_system" in given:
        raise RodInputError("-rod_system: a system runs as python -m petsc_rod -rod_system "
                            "FILE; a sweep's cases are single lines: drop it here")
    orphans = [name for name in ("rod_system_element_length", "rod_system_body_load",
                                 "rod_system_offset", "rod_system_line_length",
                                 "rod_system_steps", "rod_system_predictor",
                                 "rod_system_watch_circle",
                                 "rod_system_excursion", "rod_system_modes",
                                 "rod_system_modes_line_mass") if name in given]
    if orphans:
        raise RodInputError(f"-{orphans[0]}: an option of a system, which needs "
                            "-rod_system FILE; drop it for a single line")


def check_inputs_kept(values, comm):
    """Refuse, before any work, an output (-rod_output, -rod_table and its regions'
    table, -rod_modes_table and its shapes') that names one of the run's inputs, which writing it would replace: an
    options file, or the file of an input option (-rod_initial, -rod_line_types,
    -rod_point_loads, the profiles: every option whose value is a FILE). Collective:
    rank 0 decides."""
    written = [("-rod_output", values["rod_output"])]
    if values["rod_table"]:
        written += [("-rod_table", values["rod_table"]),
                    ("the regions' table of -rod_table",
                     line_table.regions_path(values["rod_table"]))]
    if values["rod_modes_table"]:
        written += [("-rod_modes_table", values["rod_modes_table"]),
                    ("the shapes' table of -rod_modes_table",
                     shapes_path(values["rod_modes_table"]))]
    clash = None
    if comm.getRank() == 0:
        read = [("-options_file", path) for path in every_options_file(sys.argv)]
        read += [(f"-{name}", values[name]) for name in INPUT_FILE_OPTIONS]
        clash = replaced_input(written, read)
    clash = comm.tompi4py().bcast(clash, root=0)
    if clash:
        raise RodInputError(clash)


