"""``mpiexec -n 2 python -m petsc_rod.sweep -options_file options/<scene>.opts
-sweep_output DIR (-sweep_cases FILE | -sweep_offsets ... | -sweep_current_headings ...)``:
the start of petsc_rod's own entry (petsc_rod/__main__.py: the options files checked,
petsc4py found and started), then the sweep (sweep/runner.py; with -rod_system FILE a
system's, sweep/system.py)."""

import os
import sys

from petsc_rod import __main__ as entry


def main():
    os.environ.update(entry.open_mpi_defaults(os.environ))
    error = entry.options_file_error(sys.argv)
    if error:
        if entry.launcher_rank() == 0:
            sys.stderr.write(f"petsc_rod.sweep: error: {error}\n")
        return 2
    if not entry.find_petsc4py():
        sys.stderr.write("petsc_rod.sweep: error: petsc4py is not importable by this python "
                         f"({sys.executable}); run scripts/setup.sh once, then `source "
                         ".venv/bin/activate`\n")
        return 2
    from petsc_rod.io.provenance import commit
    commit()                          # git runs before MPI starts (provenance)
    error = entry.start_petsc(sys.argv)
    if error:
        sys.stderr.write(f"petsc_rod.sweep: error: {error}; an options file has one "
                         "'-name value' per line, '#' starts a comment\n")
        return 2
    from petsc4py import PETSc

    from petsc_rod.cli.signals import ignore_stop_signals
    from petsc_rod.sweep.runner import run_sweep
    from petsc_rod.sweep.system import run_system_sweep
    code = run_system_sweep() if PETSc.Options().hasName("rod_system") else run_sweep()
    ignore_stop_signals()
    return entry.end(code)


if __name__ == "__main__":
    sys.exit(main())
