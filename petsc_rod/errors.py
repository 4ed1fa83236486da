"""Exceptions that end a run with a one-line message and a non-zero exit code."""


class RodError(Exception):
    """Base class: ``str(error)`` is the one-line message shown to the user."""

    exit_code = 1


class RodInputError(RodError):
    """Bad input: an option, a scene or a file that cannot describe a cable."""

    exit_code = 2


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
