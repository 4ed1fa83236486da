"""SIGINT, SIGTERM, SIGHUP, SIGQUIT (Ctrl-\\), SIGUSR1, SIGUSR2 and SIGPIPE (the
output piped into a reader that has ended, such as head) end a run cleanly: the handler
only records the signal (it replaces PETSc's own, which PETSc installs at start-up for
SIGQUIT, SIGHUP and SIGPIPE and which would print its report and exit 59), and the
continuation asks after every iteration, all ranks together, whether any rank
received one, so that every rank stops at the same iteration and the result file is
closed and removed collectively (mpiexec forwards a signal to every rank as SIGTERM,
and kills them a second later)."""

import signal

from mpi4py import MPI

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1,
                signal.SIGUSR2, signal.SIGPIPE)


class Interrupts:
    """Within ``with Interrupts(comm) as interrupts:`` the stop signals are recorded;
    ``interrupts.received()`` (collective) gives the one any rank received, 0 if none.
    Later signals change nothing, also while the run stops (a second Ctrl-C): a
    terminal's Ctrl-C reaches mpiexec's ranks both directly and as mpiexec's SIGTERM.
    After a broken pipe (SIGPIPE) the writes to it fail without a signal."""

    def __init__(self, comm):
        self.comm = comm.tompi4py()
        self.signal_number = 0
        self._previous = {}

    def _record(self, number, frame):
        self.signal_number = self.signal_number or number

    def __enter__(self):
        self._previous = {stop: signal.signal(stop, self._record) for stop in STOP_SIGNALS}
        return self

    def __exit__(self, *exc):
        for stop, handler in self._previous.items():
            if handler is not None:         # None: a handler not set from Python
                signal.signal(stop, handler)
        return False

    def received(self, comm=None):
        """The stop signal a rank received (the largest number if several), else 0;
        collective on ``comm`` (a PETSc communicator: a system's line asks on its own,
        system/held_line.py), by default the run's."""
        on = self.comm if comm is None else comm.tompi4py()
        return on.allreduce(self.signal_number, op=MPI.MAX)

    @staticmethod
    def name(number):
        return signal.Signals(number).name


def ignore_stop_signals():
    """Ignore the stop signals from now on: called once the run has ended (its line said,
    its file finished or removed), so that a signal during the process's shutdown (a
    second Ctrl-C) cannot cut it short with a traceback or PETSc's report."""
    for stop in STOP_SIGNALS:
        signal.signal(stop, signal.SIG_IGN)
