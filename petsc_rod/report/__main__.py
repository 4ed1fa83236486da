"""``python -m petsc_rod.report RESULT.h5|SWEEP_DIR -o report.html [--min-bend-radius R]``:
the report page
of a result file or of a sweep's folder (report/page.py). Serial; no PETSc. Exit 0, or
2 with one line when the input is not a result file or a sweep's folder."""

import math
import os
import sys

from petsc_rod.io.same_file import replaced_input
from petsc_rod.plots import OneLineParser
from petsc_rod.tables import file_problem


def system_sweep(folder):
    """Whether the sweep in ``folder`` is a system's (its sweep.json says so:
    sweep/system.py); a record that cannot be read is left to the page's checks."""
    import json
    try:
        with open(os.path.join(folder, "sweep.json"), encoding="utf-8") as f:
            return json.load(f).get("system") is True
    except (OSError, ValueError, AttributeError):
        return False


def main(argv=None):
    parser = OneLineParser(prog="python -m petsc_rod.report",
                           description="one self-contained HTML page of a result file or a "
                                       "sweep's folder")
    parser.add_argument("source", help="a result file (HDF5) or a sweep's -sweep_output DIR")
    parser.add_argument("-o", "--output", default="report.html", help="the HTML file")
    parser.add_argument("--min-bend-radius", type=float, default=None, metavar="R",
                        help="the allowable bend radius, m, drawn as a limit")
    args = parser.parse_args(argv)
    source = args.source
    radius = args.min_bend_radius
    if radius is not None and not (math.isfinite(radius) and radius > 0):
        sys.stderr.write(f"petsc_rod.report: error: --min-bend-radius {radius:g}: the "
                         "allowable bend radius must be a positive number of metres\n")
        return 2
    if os.path.isdir(source) and not os.path.exists(os.path.join(source, "sweep.json")):
        sys.stderr.write(f"petsc_rod.report: error: {source}: a folder without sweep.json is "
                         "not a sweep's output (-sweep_output DIR)\n")
        return 2
    if not os.path.exists(source):
        sys.stderr.write(f"petsc_rod.report: error: {source}: no such file or folder\n")
        return 2
    if os.path.isdir(source) and system_sweep(source):
        sys.stderr.write(f"petsc_rod.report: error: {source}: a system's sweep, whose page "
                         "is not made yet: report one of its cases' files "
                         f"({os.path.join(source, '<case>.h5')}), or read its summary.md\n")
        return 2
    problem = "" if os.path.isdir(source) else file_problem(source)
    if problem:                         # a FIFO would block h5py for ever
        sys.stderr.write(f"petsc_rod.report: error: {source}: {problem}\n")
        return 2
    import h5py
    if not os.path.isdir(source) and not h5py.is_hdf5(source):
        sys.stderr.write(f"petsc_rod.report: error: {source}: not a result file (HDF5)\n")
        return 2
    # a sweep's folder: every file in it (its record, its cases' files, its summary) but
    # the page of an earlier report, which this one replaces
    read = ([("file of the sweep", os.path.join(source, name)) for name in os.listdir(source)
             if not name.endswith(".html")]
            if os.path.isdir(source) else [("result", source)])
    clash = replaced_input([("-o", args.output)], read)
    if not clash and not os.path.isdir(os.path.dirname(os.path.abspath(args.output))):
        clash = f"-o {args.output}: its folder does not exist"
    if clash:
        sys.stderr.write(f"petsc_rod.report: error: {clash}\n")
        return 2
    from petsc_rod.figures.read_system import is_system_file
    from petsc_rod.io.same_file import write_text_whole
    from petsc_rod.report import page, system_page
    try:
        if not os.path.isdir(source) and is_system_file(source):
            write_text_whole(args.output, system_page.build(source))
        else:
            page.write(source, args.output, args.min_bend_radius)
    except OSError as error:
        sys.stderr.write(f"petsc_rod.report: error: {args.output}: {error.strerror or error}\n")
        return 2
    except (KeyError, ValueError) as error:     # json.JSONDecodeError is a ValueError
        sys.stderr.write(f"petsc_rod.report: error: {source}: not a petsc_rod result file or "
                         f"sweep ({error.__class__.__name__}: {error}); give a file written "
                         "with -rod_output or a -sweep_output folder\n")
        return 2
    print(f"petsc_rod.report: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
