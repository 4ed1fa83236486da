"""Exceptions that end a run with a one-line message and a non-zero exit code, and the
agreement of all ranks on whether one was raised."""


def petsc_message(error):
    """The last line of a PETSc.Error's report (PETSc's own message), without its rank."""
    return str(error).strip().splitlines()[-1].split("] ", 1)[-1]


class RodError(Exception):
    """Base class: ``str(error)`` is the one-line message shown to the user."""

    exit_code = 1


class RodInputError(RodError):
    """Bad input: an option, a scene or a file that cannot describe a cable."""

    exit_code = 2


class NoCatenaryStart(RodInputError):
    """The catenary start (scenes/starts.py) cannot be drawn for this scene's loads and
    seabed (a grounded line too long to lie taut, pieces whose catenary has no solution
    or dips below the seabed, a load not straight down onto a seabed), though the scene
    itself is sound: the start falls back to the straight line and says why
    (cli/line_run.start_from). ``str(error)`` is the reason, without advice."""


class RodNotConvergedError(RodError):
    """The Uzawa iteration hit its cap; the result file (if any) says converged = 0."""

    exit_code = 3


class RodDivergedError(RodError):
    """NaN/Inf or a linear-solver failure; no result is written.

    ``iterations``: how many Uzawa iterations the step had made when it diverged (None
    when not known), so that a continuation that retries the step can count them."""

    exit_code = 4

    def __init__(self, message, iterations=None):
        super().__init__(message)
        self.iterations = iterations


class RodIterationDiverged(RodDivergedError):
    """The iteration's own norms left every meaningful state (stopping.diverged), as
    opposed to a linear solver that failed: a smaller step or a larger penalty helps
    (the command line says so, cli/messages.py)."""


class RodIOError(RodError):
    """The result file could not be written during the run (a full disk, a file system
    error); the partial file is removed."""

    exit_code = 5


class RodInterrupted(RodError):
    """A stop signal (cli/signals.py: SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2,
    SIGPIPE) ended the run; the exit code is the shell's 128 + the signal number (130,
    143, 129, 131, 138, 140, 141), and the partial file is removed."""

    def __init__(self, message, signal_number):
        super().__init__(message)
        self.signal_number = signal_number
        self.exit_code = 128 + signal_number

    def __reduce__(self):
        return type(self), (str(self), self.signal_number)


def on_every_rank(comm, action, *args):
    """``action(*args)`` on every rank of ``comm`` (PETSc or mpi4py); if it raised a
    RodError on any rank, the lowest such rank's error is raised on every rank, so that
    no rank goes on into a collective call that the others have left. Collective."""
    mpi = comm.tompi4py() if hasattr(comm, "tompi4py") else comm
    try:
        result, failure = action(*args), None
    except RodError as error:
        result, failure = None, error
    first = next((error for error in mpi.allgather(failure) if error is not None), None)
    if first is None:
        return result
    raise first from None
