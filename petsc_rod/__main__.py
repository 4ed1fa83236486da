"""``python -m petsc_rod -options_file options/<scene>.opts``."""

import ctypes
import os
import sys

# One BLAS thread per process unless the environment says otherwise, set before numpy
# loads OpenBLAS: the ranks are the parallelism, and Debian's threaded OpenBLAS makes its
# vector operations (PETSc's VecAXPY, numpy's dot) wait for threads whenever the cores
# are busy (docs/performance.md, "Per-iteration overhead").
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from petsc_rod.cli.options_files import (  # noqa: E402  (no PETSc)
    every_options_file, options_file_error)


# Open MPI's fastest start where it cannot change what the ranks can reach: one process
# alone (a singleton) or every rank on this node talks through shared memory (ob1 with
# the self and vader transports), and a singleton starts no helper daemon (isolated). A
# start without them probes the network transports (UCX) and, alone, forks an orted
# (docs/performance.md, "Where the remaining time goes").
TRANSPORT_DEFAULTS = {"pml": "ob1", "btl": "self,vader"}
SINGLETON_DEFAULTS = {"ess_singleton_isolated": "1"}
# What says a launcher started the process (Open MPI's mpiexec, PMIx or PMI as srun's
# or MPICH's): then it is no singleton, and its ranks may be on other nodes.
LAUNCHER_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "PMI_FD",
                      "SLURM_STEP_NUM_TASKS")


# The parameter files Open MPI reads unless OMPI_MCA_mca_base_param_files names others
# (`ompi_info --param mca base --level 9`): the user's, then the installation's.
SYSTEM_MCA_FILE = "/etc/openmpi/openmpi-mca-params.conf"


def user_mca_names(environ):
    """The MCA parameters the parameter files choose: 'name = value' lines of
    OMPI_MCA_mca_base_param_files (a ','-separated list; ':' taken too) or of
    $HOME/.openmpi/mca-params.conf and SYSTEM_MCA_FILE. A value there is the user's or
    the administrator's choice, which an environment variable would override; a value
    that only excludes components (``^ucx``) none of which TRANSPORT_DEFAULTS uses is
    no choice against them (Debian's own file excludes UCX and OFI so)."""
    own = os.path.join(environ.get("HOME", "~"), ".openmpi", "mca-params.conf")
    listed = environ.get("OMPI_MCA_mca_base_param_files")
    paths = listed.replace(":", ",").split(",") if listed else [own, SYSTEM_MCA_FILE]
    names = set()
    for path in paths:
        try:
            with open(os.path.expanduser(path.strip()), encoding="utf-8") as lines:
                settings = [line.split("=", 1) for line in lines
                            if "=" in line and not line.lstrip().startswith("#")]
        except OSError:
            continue
        names.update(name.strip() for name, value in settings
                     if not _excludes_none_of_ours(name.strip(), value.strip()))
    return names


def _excludes_none_of_ours(name, value):
    """Whether ``value`` of MCA parameter ``name`` only excludes components (^a,b) and
    none that TRANSPORT_DEFAULTS[name] uses."""
    if not value.startswith("^"):
        return False
    ours = set(TRANSPORT_DEFAULTS.get(name, "").split(","))
    return not ours & {part.strip() for part in value[1:].split(",")}


def open_mpi_defaults(environ):
    """{variable: value}: the OMPI_MCA_* settings to add to ``environ`` before MPI starts
    (TRANSPORT_DEFAULTS, SINGLETON_DEFAULTS). None where the user (the environment,
    mpiexec's --mca or -x, a parameter file) chose a transport (pml, btl or mtl) or the
    singleton's start; the transports only as a singleton or under Open MPI's mpiexec
    with every rank on this node (OMPI_COMM_WORLD_LOCAL_SIZE == OMPI_COMM_WORLD_SIZE),
    the isolated start only as a singleton."""
    chosen = user_mca_names(environ) | {name.removeprefix("OMPI_MCA_") for name in environ
                                        if name.startswith("OMPI_MCA_")}
    launched = any(name in environ for name in LAUNCHER_VARIABLES)
    size = environ.get("OMPI_COMM_WORLD_SIZE")
    one_node = not launched or (size is not None
                                and environ.get("OMPI_COMM_WORLD_LOCAL_SIZE") == size)
    defaults = {}
    if one_node and not chosen & {"pml", "btl", "mtl"}:
        defaults.update(TRANSPORT_DEFAULTS)
    if not launched and not chosen & set(SINGLETON_DEFAULTS):
        defaults.update(SINGLETON_DEFAULTS)
    return {f"OMPI_MCA_{name}": value for name, value in defaults.items()}


def may_write_a_result(argv, environ=None):
    """Whether the run may write a result file, whose record names the checkout's commit
    (io/provenance.py: git, run before MPI starts): an option with 'output' in its name
    where PETSc reads options (the command line, PETSC_OPTIONS, the options files). A run
    without one runs no git."""
    environ = os.environ if environ is None else environ
    texts = [" ".join(argv[1:]), environ.get("PETSC_OPTIONS", "")]
    for path in every_options_file(argv, environ):
        try:
            with open(path, encoding="utf-8", errors="replace") as handle:
                texts.append(handle.read())
        except OSError:
            return True
    return any("output" in text for text in texts)


def launcher_rank():
    """This process's rank as mpiexec's environment says it, before MPI starts (Open
    MPI's OMPI_COMM_WORLD_RANK, MPICH's PMI_RANK); 0 outside mpiexec."""
    for name in ("OMPI_COMM_WORLD_RANK", "PMI_RANK"):
        if os.environ.get(name, "").isdigit():
            return int(os.environ[name])
    return 0


def petsc_error(report):
    """The message of a PETSc error report (the line after the error class), or ''."""
    lines = [line.split("PETSC ERROR: ", 1)[1].strip() for line in report.splitlines()
             if "PETSC ERROR: " in line]
    headers = [k for k, line in enumerate(lines) if "Error Message" in line]
    if not headers:
        return ""
    # PETSc's warning of unused options comes between the message and its "See ..."
    message = [line for line in lines[headers[0] + 1:]
               if not line.startswith(("WARNING! There are option", "Option left:"))]
    message = [line for line in message[:3] if line and not line.startswith("See ")]
    return message[-1] if message else ""


def find_slepc4py():
    """Make slepc4py importable where it is installed (find_module: Debian's, found
    without SLEPC_DIR); without it the modes are refused when asked for (cli/modes.py).
    SLEPc itself starts only when the modes import it (analysis/modes.py), on PETSc's
    running options database: a run without modes does not load it."""
    find_module("slepc4py", DEBIAN_SLEPC4PY)


def start_petsc(argv):
    """Initialise PETSc with ``argv``; returns '' or, when PETSc refuses the options (a
    line of an options file it cannot parse), its message, instead of PETSc's own
    report and a traceback."""
    import petsc4py

    from petsc_rod.io.capture import stderr_captured
    find_slepc4py()
    with stderr_captured() as report:
        try:
            petsc4py.init(argv)         # PETSc starts and reads the options here
        except Exception:               # petsc4py.PETSc.Error, not importable before
            return petsc_error(report()) or "PETSc could not start with these options"
        printed = report()
    sys.stderr.write(printed)
    return ""


def end(code):
    """Exit with ``code``. After a failed HDF5 write the process ends at once, without
    the shutdown of HDF5 (and of MPI-IO, PETSc and MPI, which would close the file
    too), which would crash flushing the file it could not write (io.hdf5_failed)."""
    from petsc_rod.io import results as io
    if not io.hdf5_failed():
        return code
    sys.stdout.flush()
    sys.stderr.flush()
    ctypes.CDLL(None).fflush(None)      # C stdio (PETSc's output), which os._exit skips
    os._exit(code)


# Where Debian's python3-petsc4py and python3-slepc4py put the modules: under PETSC_DIR
# and SLEPC_DIR, which their own .pth files expect in the environment (or the
# /usr/lib/petsc and /usr/lib/slepc links of the -dev packages).
DEBIAN_PETSC4PY = "/usr/lib/petscdir/petsc3.*/*-real/lib/python3/dist-packages"
DEBIAN_SLEPC4PY = "/usr/lib/slepcdir/slepc3.*/*-real/lib/python3/dist-packages"


def find_module(name, pattern):
    """Whether module ``name`` imports, after adding the newest of Debian's folders
    matching ``pattern`` to the path when it does not on its own (a venv made by
    `pip install .`, no PETSC_DIR or SLEPC_DIR in the environment)."""
    import importlib
    try:
        importlib.import_module(name)
        return True
    except ImportError:
        pass
    import glob
    import re

    def version(path):
        return [int(part) for part in re.findall(r"\d+", path)]

    found = sorted(glob.glob(pattern), key=version)
    if not found:
        return False
    sys.path.append(found[-1])
    try:
        importlib.import_module(name)
        return True
    except ImportError:
        return False


def find_petsc4py():
    """Whether petsc4py imports (find_module: Debian's, found without PETSC_DIR)."""
    return find_module("petsc4py", DEBIAN_PETSC4PY)


def main():
    os.environ.update(open_mpi_defaults(os.environ))
    error = options_file_error(sys.argv)
    if error:
        if launcher_rank() == 0:        # one line, not one per rank
            sys.stderr.write(f"petsc_rod: error: {error}\n")
        return 2
    if not find_petsc4py():
        sys.stderr.write(
            "petsc_rod: error: petsc4py is not importable by this python "
            f"({sys.executable}); install Debian's python3-petsc4py (or run scripts/setup.sh "
            "once, then `source .venv/bin/activate`)\n")
        return 2
    if may_write_a_result(sys.argv):
        from petsc_rod.io.provenance import commit
        commit()                      # git runs before MPI starts (provenance)
    error = start_petsc(sys.argv)
    if error:
        sys.stderr.write(f"petsc_rod: error: {error}; an options file has one '-name value' "
                         "per line, '#' starts a comment\n")
        return 2
    from petsc4py import PETSc

    from petsc_rod.cli.signals import ignore_stop_signals
    if PETSc.Options().hasName("rod_system"):     # a system of lines (docs/systems.md)
        from petsc_rod.cli_system import run
    else:
        from petsc_rod.cli.main import run
    code = run()
    ignore_stop_signals()
    return end(code)


if __name__ == "__main__":
    sys.exit(main())
